"""The AMB loop inside the drop (ambseal.analysis.drop_loop) on the rigid symmetric rotor of
test_analysis_drop: a lost axis against the one-degree-of-freedom fall under its decaying
magnets, the running loop against its linear unbalance orbit, and the statics of one
axis lost and of an overload within and beyond the AMBs' capacity."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.integrate import solve_ivp
from scipy.optimize import brentq

from ambseal.analysis.drop import GRAVITY, drop_model, drop_verdict, simulate_drop
from ambseal.analysis.drop_levitated import levitated_state
from ambseal.analysis.drop_loop import amb_loop
from ambseal.design import pid_controller
from ambseal.errors import ConfigError
from ambseal.model import channel_names

from ..rigid_rotor import L, inertia
from .test_analysis_drop import C_TD, DISK, K_TD, _rig

KI, KS, I_MAX = 100.0, 2.0e5, 5.0  # the rig's Ki, Ks and its bias current (< its limit)
Z_AMB = (0.1, L - 0.1)


def _damped():
    """The rig with contacts that settle (Flores, e = 0.5) rather than bounce for ever."""
    base = _rig()
    return base.model_copy(update={"touchdown": [
        t.model_copy(update={"restitution": 0.5}) for t in base.touchdown]})


def _pid(cfg, ti: float = 0.2):
    return pid_controller(1e4, ti, 3e-3, 0.1, channel_names(cfg))


def test_a_lost_amb_lets_go_with_the_square_of_its_decaying_current():
    """Both AMBs lose power at rest, their coils' L/R = 2 ms: the rotor falls straight,
    m ÿ = −m g + e^{−2t/τ}(m g + 2 Ks y) (the force ∝ i², Ks with the bias), integrated
    apart as one degree of freedom — the drop's centre within 1e-6 of the clearance of
    it until the first contact."""
    base = _rig()
    cfg = base.model_copy(update={"amb": [a.model_copy(update={"inductance": 0.02,
                                                                "resistance": 10.0})
                                          for a in base.amb]})
    m, tau = inertia(*DISK)[0], 0.002

    def fall(t, s):
        return [s[1], -GRAVITY + math.exp(-2 * t / tau) * (GRAVITY + 2 * KS * s[0] / m)]

    r = simulate_drop(cfg, duration_s=0.012, samples=1201, rtol=1e-10)
    first = np.flatnonzero(r.force.max(axis=0) > 0)[0]
    ref = solve_ivp(fall, (0, r.t[first]), [0.0, 0.0], method="DOP853", rtol=1e-11,
                    atol=1e-15, dense_output=True)
    y = 0.5 * (r.watched["amb:A"][:first, 1] + r.watched["amb:B"][:first, 1])
    y = y - y[0]
    np.testing.assert_allclose(y, ref.sol(r.t[:first])[0], rtol=0, atol=1e-6 * C_TD)
    assert ref.sol(r.t[first])[0] < -C_TD < ref.sol(r.t[first - 1])[0]
    assert r.failed == ("A_zeta", "A_eta", "B_zeta", "B_eta")


SEAL = {"K": 2e5, "k": 1.5e5, "C": 300.0, "c": 80.0, "M": 3.0}  # at mid-span


W_RUN, U_RUN = 100 * math.pi, 1e-4  # the running loops' 3000 rpm and unbalance (kg·m)


def _running(cfg, ti: float, duration_s: float):
    """No axis lost, U_RUN at 3000 rpm from the PID loop's levitated orbit: the drop, the
    orbit at A's node less its levitated sag (x + jy), and the PID's K(jΩ)."""
    dm = drop_model(cfg)
    loop = amb_loop(cfg, dm, controller=_pid(cfg, ti=ti))
    eta, deta, x0 = levitated_state(cfg, dm, 3000.0, U_RUN, loop=loop)
    r = simulate_drop(cfg, speed_rpm=3000.0, duration_s=duration_s,
                      samples=int(round(1e4 * duration_s)) + 1, model=dm, loop=loop,
                      loop_state=x0, failed=(), unbalance_kgm=U_RUN, rtol=1e-10,
                      initial=(dm.phi @ eta, dm.phi @ deta))
    a = int(np.argmin(np.abs(dm.z - Z_AMB[0])))
    got = r.watched["amb:A"] - (dm.phi @ dm.q0)[[4 * a, 4 * a + 1]]
    s = 1j * W_RUN
    return r, got[:, 0] + 1j * got[:, 1], 1e4 * (1 + 1 / (s * ti)
                                                  + s * 3e-3 / (s * 0.1 * 3e-3 + 1))


def test_a_spring_on_a_housing_runs_in_the_loops_orbit():
    """A plain bearing k_b = 2e5 N/m at mid-span on a housing (m_h = 2 kg, k_h = 1e5 N/m,
    c_h = 2000 N·s/m to ground), no axis lost, U = 1e-4 kg·m at 3000 rpm, a PD loop (the
    integral's corner far below, so nothing slow is left of the start): the rotor sees
    the two in series, Z = k_b (k_h + jΩc_h − m_hΩ²)/(k_b + k_h + jΩc_h − m_hΩ²), and
    runs in X = U Ω²/(2(Ki K(jΩ) − Ks) + Z − mΩ²); the housing starts at rest, and once
    its start has died away (the last 20 ms of 100) the orbit is X within 1e-4."""
    from ambseal.config import Spring
    from ambseal.config.rig import SpringHousing

    kb, mh, kh, ch = 2e5, 2.0, 1e5, 2000.0
    cfg = _rig().model_copy(update={"spring": [Spring(
        name="pedestal", position=L / 2, kxx=kb, kyy=kb,
        housing=SpringHousing(mass=mh, kxx=kh, kyy=kh, cxx=ch, cyy=ch))]})
    r, got, Kc = _running(cfg, ti=100.0, duration_s=0.1)
    W, m = W_RUN, inertia(*DISK)[0]
    ground = kh + 1j * W * ch - mh * W ** 2
    Z = kb * ground / (kb + ground)
    X = U_RUN * W ** 2 / (2 * (KI * Kc - KS) + Z - m * W ** 2)
    late = r.t >= 0.08
    np.testing.assert_allclose(got[late], (X * np.exp(1j * W * r.t))[late], rtol=0,
                               atol=1e-4 * abs(X))


@pytest.mark.parametrize("sealed", [False, True])
def test_the_running_loop_holds_its_levitated_unbalance_orbit(sealed):
    """No axis lost, U = 1e-4 kg·m at 3000 rpm: the nonlinear drop with the PID loop
    inside runs on in the linear loop's steady orbit — the forward whirl
    X = U Ω²/(2(Ki K(jΩ) − Ks) + (K − jk) + jΩ(C − jc) − (m + M)Ω²), with a seal of
    Childs' K, k, C, c, M at mid-span (thesis P4 Eq. 3; its force on x + jy is
    −(K − jk) z − (C − jc) ż − M z̈) or without — at the start (the levitated state) and
    throughout, within 1e-6 of |X|, never touching, the currents the static one and the
    PID's, −K(jΩ) X, within 1e-6 of its amplitude."""
    from ambseal.config import Seal

    cfg = _rig()
    if sealed:
        cfg = cfg.model_copy(update={"seal": [Seal(name="mid", position=L / 2, **SEAL)]})
    seal = SEAL if sealed else dict.fromkeys(SEAL, 0.0)
    r, got, Kc = _running(cfg, ti=0.2, duration_s=0.04)
    W, U, m = W_RUN, U_RUN, inertia(*DISK)[0]
    X = U * W ** 2 / (2 * (KI * Kc - KS) + seal["K"] - 1j * seal["k"]
                      + 1j * W * (seal["C"] - 1j * seal["c"]) - (m + seal["M"]) * W ** 2)
    orbit = X * np.exp(1j * W * r.t)
    np.testing.assert_allclose(got, orbit, rtol=0, atol=1e-6 * abs(X))
    assert r.impacts == 0 and r.force.max() == 0
    i_s = m * GRAVITY / 2 / KI
    np.testing.assert_allclose(r.amb_current[1], i_s - (Kc * orbit).imag, rtol=0,
                               atol=1e-6 * abs(Kc * X))


def test_one_axis_lost_lands_that_end_and_the_other_amb_holds_the_rest():
    """At rest the vertical axis of AMB A fails at once: the rotor tips onto the ring at
    A's end (z = 0) about B, whose loop holds it; statics: the ring carries
    N = m g (z_B − L/2)/z_B and B's coil, its sensor brought back by the integral action,
    carries (m g − N)/Ki — both within 1 % once settled. The other end's ring is not
    touched."""
    cfg = _damped()
    dm = drop_model(cfg)
    loop = amb_loop(cfg, dm, controller=_pid(cfg, ti=0.02))
    m = inertia(*DISK)[0]
    r = simulate_drop(cfg, duration_s=0.6, samples=601, model=dm, loop=loop,
                      failed=("A_eta",))
    N = m * GRAVITY * (Z_AMB[1] - L / 2) / Z_AMB[1]
    assert r.force[0, -1] == pytest.approx(N, rel=0.01)
    assert r.force[1].max() == 0
    assert r.amb_current[3, -1] == pytest.approx((m * GRAVITY - N) / KI, rel=0.01)
    assert r.amb_current[1, -1] == 0  # A's lost axis: at once, without L and R


@pytest.mark.parametrize("overload_n", [200.0, 1000.0])
def test_an_overload_within_the_capacity_is_held_and_beyond_it_lands(overload_n):
    """A step force F down at the centre from rest. Within the AMBs' capacity (F = 200 N:
    each coil's current i_s + F/(2 Ki) below its bias, the linear range) the loop holds
    it: no contact, the currents that much up within 1e-3. Beyond it (F = 1000 N) the
    currents clip at the bias and the rotor lands on both rings: each carries
    N = (m g + F)/2 − Ki i_max + Ks (c + δ), δ = (N/K)^{2/3} (the magnets pulling it
    down), within 1 %, and the drop says they saturated."""
    cfg = _damped()
    dm = drop_model(cfg)
    loop = amb_loop(cfg, dm, controller=_pid(cfg, ti=0.02))
    m = inertia(*DISK)[0]
    r = simulate_drop(cfg, duration_s=0.4, samples=401, model=dm, loop=loop, failed=(),
                      overload=(L / 2, (0.0, -overload_n)))
    per = (m * GRAVITY + overload_n) / 2
    amb = r.to_dict()["amb"]
    if per < KI * I_MAX:
        assert r.force.max() == 0
        np.testing.assert_allclose(r.amb_current[[1, 3], -1], per / KI, rtol=1e-3)
        assert not any(a["saturated"] for a in amb)
        return
    N = brentq(lambda n: n - (per - KI * I_MAX + KS * (C_TD + (n / K_TD) ** (2 / 3))),
               0.0, 10 * per)
    np.testing.assert_allclose(r.force[:, -1], N, rtol=0.01)
    np.testing.assert_allclose(r.amb_current[[1, 3], -1], I_MAX, rtol=1e-9)
    assert [a["saturated"] for a in amb] == [False, True, False, True]


def test_the_loop_refuses_what_it_cannot_run():
    """A channel the rig has not, axes left running without a controller and an overload
    off the rotor are refused, each naming what was expected."""
    cfg = _rig()
    dm = drop_model(cfg)
    with pytest.raises(ConfigError, match=r"failed: C_eta: expected AMB channels"):
        simulate_drop(cfg, duration_s=0.01, model=dm, failed=("C_eta",),
                      loop=amb_loop(cfg, dm, controller=_pid(cfg)))
    with pytest.raises(ConfigError, match="run on need a controller"):
        simulate_drop(cfg, duration_s=0.01, model=dm, failed=("A_eta",),
                      loop=amb_loop(cfg, dm, controller="none"))
    with pytest.raises(ConfigError, match="overload: expected a position on the rotor"):
        simulate_drop(cfg, duration_s=0.01, model=dm, overload=(2 * L, (0.0, -1.0)))


def _digital_pid(cfg, fs: float = 5000.0, delay: int = 1):
    """The PID of :func:`_pid` (Ti = 0.02 s) as a target runs it: Tustin at ``fs`` with
    ``delay`` samples of computation."""
    import control

    from ambseal.robust import with_delay

    Kd = control.sample_system(_pid(cfg, ti=0.02), 1 / fs, method="tustin")
    return control.ss(*with_delay((Kd.A, Kd.B, Kd.C, Kd.D), delay), 1 / fs)


def test_a_digital_controller_runs_sampled_with_its_delay():
    """A step force F = 200 N down at the centre from rest, the PID digital at 5 kHz with
    one sample of delay: the rotor translates, m ÿ = 2 Ks y + 2 Ki i − F with i held
    between samples, i_k = −u_k of the discrete PID (delay included) on the sampled y_k.
    That recursion on the exactly sampled plant (Φ = e^{AT}, Γ by the augmented
    exponential) gives the sensors' samples: the drop's within 1e-6 of their largest."""
    from scipy.linalg import expm

    cfg = _damped()
    dm = drop_model(cfg)
    K = _digital_pid(cfg)
    loop = amb_loop(cfg, dm, controller=K)
    assert loop.sampled is not None and loop.n_sampled == K.A.shape[0]
    m, F, Ts, n = inertia(*DISK)[0], 200.0, 1 / 5000.0, 200
    r = simulate_drop(cfg, duration_s=n * Ts, samples=n + 1, model=dm, loop=loop,
                      failed=(), overload=(L / 2, (0.0, -F)), rtol=1e-10)
    A = np.array([[0.0, 1.0], [2 * KS / m, 0.0]])
    aug = np.zeros((4, 4))
    aug[:2, :2], aug[:2, 2:] = A * Ts, np.array([[0.0, 0.0], [2 * KI / m, -1.0 / m]]) * Ts
    E = expm(aug)
    x, xd, ys = np.zeros(2), np.zeros(K.A.shape[0]), []
    for _ in range(n + 1):
        y = x[0]
        ys.append(y)
        i = -(K.C[1] @ xd + K.D[1, 1] * y)  # the vertical axis of AMB A: channel 1
        xd = K.A @ xd + K.B[:, 1] * y + K.B[:, 3] * y  # B's vertical sensor reads the same
        x = E[:2, :2] @ x + E[:2, 2:] @ np.array([i, F])
    got = r.watched["amb:A"][:, 1] - r.watched["amb:A"][0, 1]
    np.testing.assert_allclose(got, ys, rtol=0, atol=1e-6 * np.abs(ys).max())
    assert np.abs(ys).max() > 1e-5  # it moved


def test_the_digital_loops_levitated_orbit_is_its_sampled_steady_state():
    """U = 1e-4 kg·m at 3000 rpm under the digital PID: the drop from the sampled loop's
    steady orbit (the plant sampled exactly with the force's own response between
    samples) runs on in it — at every sample instant k T_s the centre is the orbit at
    t = 0 turned by Ω k T_s, within 1e-6 of its radius; a digital loop that is unstable is
    refused, naming its pole's |z|."""
    import control

    cfg = _damped()
    dm = drop_model(cfg)
    K = _digital_pid(cfg)
    loop = amb_loop(cfg, dm, controller=K)
    W, U, Ts, n = 100 * math.pi, 1e-4, 1 / 5000.0, 100
    eta, deta, x0 = levitated_state(cfg, dm, 3000.0, U, loop=loop)
    r = simulate_drop(cfg, speed_rpm=3000.0, duration_s=n * Ts, samples=n + 1, model=dm,
                      loop=loop, loop_state=x0, failed=(), unbalance_kgm=U, rtol=1e-10,
                      initial=(dm.phi @ eta, dm.phi @ deta))
    a = int(np.argmin(np.abs(dm.z - Z_AMB[0])))
    sag = (dm.phi @ dm.q0)[[4 * a, 4 * a + 1]]
    z = (r.watched["amb:A"] - sag) @ np.array([1.0, 1j])
    np.testing.assert_allclose(z, z[0] * np.exp(1j * W * r.t), rtol=0, atol=1e-6 * abs(z[0]))
    assert abs(z[0]) > 1e-7
    wrong = control.ss(-K.A, K.B, K.C, -K.D, Ts)  # an unstable, mis-signed controller
    with pytest.raises(ConfigError, match=r"digital controller as it runs is unstable"):
        levitated_state(cfg, dm, 3000.0, U, loop=amb_loop(cfg, dm, controller=wrong))


def test_a_coupling_holds_its_end_of_the_falling_rotor():
    """A coupling spring k (P4 Eq. 4) at z = 0, where ring A also sits, ring B at L,
    every AMB lost: the rotor settles on both rings, the coupling's force on its node's
    deflection from the levitated equilibrium. Statics, within 1 %: moments about z = 0
    give ring B m g/2, and ring A with the coupling, k (c + δ_A), carry the other half.
    Without the coupling each ring carries m g/2. A coupling with a clearance (0.1 mm,
    under the rings' 0.2 mm) fails the verdict against it. On a housing (1 kg held by
    k_h = k to ground) the coupling and the housing's spring hold the end in series,
    k k_h/(k + k_h): the same statics with that stiffness, and the coupling's excursion,
    judged against its clearance, is the node's less the housing's."""
    from ambseal.config import Spring
    from ambseal.config.rig import SpringHousing

    base = _damped()
    m = inertia(*DISK)[0]
    k = 0.25 * m * GRAVITY / C_TD  # alone it would hold its half 2 c down: ring A lands
    coupled = base.model_copy(update={"spring": [Spring(name="coupling", position=0.0,
                                                       kxx=k, kyy=k, clearance=1e-4)]})
    r = simulate_drop(coupled, duration_s=0.3, samples=301)
    N = r.force[:, -1]
    delta = (N / K_TD) ** (2 / 3)
    assert N.sum() + k * (C_TD + delta[0]) == pytest.approx(m * GRAVITY, rel=0.01)
    assert N[1] * L == pytest.approx(m * GRAVITY * L / 2, rel=0.01)
    judged = {c["name"]: c for c in drop_verdict(coupled, r)["criteria"]}
    assert judged["no contact at coupling (clearance)"]["outcome"] == "FAILED"
    free = simulate_drop(base, duration_s=0.3, samples=301)
    np.testing.assert_allclose(free.force[:, -1], m * GRAVITY / 2, rtol=0.01)
    housed = coupled.model_copy(update={"spring": [coupled.spring[0].model_copy(
        update={"housing": SpringHousing(mass=1.0, kxx=k, kyy=k, cxx=50.0, cyy=50.0)})]})
    r = simulate_drop(housed, duration_s=0.3, samples=301)
    N = r.force[:, -1]
    delta = (N / K_TD) ** (2 / 3)
    series = k * k / (k + k)
    assert N.sum() + series * (C_TD + delta[0]) == pytest.approx(m * GRAVITY, rel=0.01)
    assert N[1] * L == pytest.approx(m * GRAVITY * L / 2, rel=0.01)
    # the housing takes half the end's fall: the coupling deflects by the other half
    assert np.hypot(*r.watched["spring:coupling"][-1]) == pytest.approx(
        0.5 * (C_TD + delta[0]), rel=0.01)


def test_a_seal_the_rotor_runs_offset_in_loads_the_ambs_and_narrows_its_clearance():
    """A seal (K = 2e5, k = 1e5 N/m) at z_s = 0.15 m whose centre the rotor runs
    e = 0.1 mm above (its ``static_eccentricity``, the rotor low in it): its static
    force −[[K, k], [−k, K]]·(0, −e) = (k e, K e) is held by the AMBs, whose x and y
    forces are the lever rule's on the weight less that load (closed form, 1e-9); the
    running loop holds that equilibrium with the seal pushing (the rotor moves under
    1 nm in 50 ms); the drop's excursion at the seal is counted from the seal's centre,
    e at the start, so a 0.25 mm seal clearance that the rotor's fall onto its 0.2 mm
    rings clears without the offset is touched with it."""
    from ambseal.config.rig import Seal

    e, K, k, z_s = 1e-4, 2e5, 1e5, 0.15
    base = _damped()
    seal = Seal(name="S", position=z_s, K=K, k=k, clearance=2.5e-4, static_eccentricity=e)
    cfg = base.model_copy(update={"seal": [seal]})
    dm = drop_model(cfg)
    m = inertia(*DISK)[0]
    (z_a, z_b), F = Z_AMB, np.array([k * e, K * e])
    for j, load in enumerate((np.zeros(2), np.array([0.0, m * GRAVITY]))):
        # f_A + f_B = W_j − F_j, f_A z_A + f_B z_B = W_j L/2 − F_j z_s
        f_b = (load[j] * L / 2 - F[j] * z_s - (load[j] - F[j]) * z_a) / (z_b - z_a)
        np.testing.assert_allclose(dm.amb_force[:, j], [load[j] - F[j] - f_b, f_b],
                                   rtol=1e-9, atol=1e-9 * m * GRAVITY)
    loop = amb_loop(cfg, dm, controller=_pid(cfg, ti=0.02))
    held = simulate_drop(cfg, duration_s=0.05, samples=51, model=dm, loop=loop, failed=())
    start = held.watched["seal:S"][0]
    assert np.hypot(*start) == pytest.approx(e, rel=1e-6)
    assert np.abs(held.watched["seal:S"] - start).max() < 1e-9
    assert held.force.max() == 0
    fell = drop_verdict(cfg, simulate_drop(cfg, duration_s=0.2, samples=201))
    row = {c["name"]: c for c in fell["criteria"]}["no contact at S (clearance)"]
    assert row["outcome"] == "FAILED"
    plain = cfg.model_copy(update={"seal": [seal.model_copy(update={
        "static_eccentricity": 0.0})]})
    row = {c["name"]: c for c in drop_verdict(plain, simulate_drop(plain, duration_s=0.2,
                                                                     samples=201))["criteria"]}
    assert row["no contact at S (clearance)"]["outcome"] == "passed"
