"""The rotor drop (ambseal.analysis.drop) on a rigid symmetric rotor: the first impact
against the exact energy balance, energy conservation without damping or friction, and a
ring spun up by friction against its closed form."""

from __future__ import annotations

import math
import tomllib

import numpy as np
import pytest

from ambseal.analysis.drop import (
    GRAVITY,
    drop_model,
    drop_verdict,
    journal_radius,
    simulate_drop,
)
from ambseal.config import parse_rig
from ambseal.errors import ConfigError
from ambseal.model import hertz_impact

from ..rigid_rotor import D, L, inertia, rotor_text

DISK = (20.0, 0.05, 0.1)  # a short stiff rotor: disk mass (kg), I_p, I_d (kg·m²)
C_TD = 2.0e-4  # the touchdown bearings' radial clearance (m)
K_TD = 5.0e9  # N/m^1.5


def _rig(touchdown: str = "", amb: str = "") -> dict:
    text = rotor_text("rigid rotor on touchdown bearings", *DISK, 4)
    for name, z in (("A", 0.1), ("B", L - 0.1)):
        text += (f'[[amb]]\nname = "{name}"\nposition = {z}\nsensor_position = {z}\n'
                 f"ki = 100.0\nks = 2.0e5\nbias_current = 5.0\ncurrent_limit = 10.0\n{amb}")
    for name, z in (("TA", 0.0), ("TB", L)):
        text += (f'[[touchdown]]\nname = "{name}"\nposition = {z}\n'
                 f"radial_clearance = {C_TD}\ncontact = \"point\"\n"
                 f"contact_stiffness = {K_TD}\nrestitution = 1.0\nfriction = 0.0\n"
                 f"{touchdown}")
    return parse_rig(tomllib.loads(text))


def test_the_first_impact_is_the_energy_balance():
    """Released at standstill without damping, the rotor (centre of mass mid-way between
    two alike planes) falls straight: at the first impact's deepest point each plane has
    stored the fall of half the rotor, (2/5)·K·δ^{5/2} = (m/2)·g·(c + δ) — δ by Brent's
    method, the peak force K·δ^{3/2}: both within 1 % of the simulated ones."""
    from scipy.optimize import brentq

    cfg = _rig()
    m = inertia(*DISK)[0]
    delta = brentq(lambda d: 0.4 * K_TD * d**2.5 - 0.5 * m * GRAVITY * (C_TD + d),
                   0.0, C_TD)
    fall = math.sqrt(2 * C_TD / GRAVITY)
    _, t_c = hertz_impact(0.5 * m, GRAVITY * fall, K_TD)  # the contact's length, about
    r = simulate_drop(cfg, duration_s=fall + 1.5 * t_c, samples=20001)
    first = r.t <= fall + 1.2 * t_c
    for p in range(2):
        assert r.penetration[p, first].max() == pytest.approx(delta, rel=0.01)
        assert r.force[p, first].max() == pytest.approx(K_TD * delta**1.5, rel=0.01)
    assert r.impacts >= 2  # both planes
    # it falls straight down
    assert np.abs(r.orbit[:, :, 0]).max() < 1e-9


def test_the_first_bounce_rises_e_squared_times_the_clearance():
    """Damped (a measured e = 0.9), each half of the rotor strikes its ring at
    v₀ = √(2 g c) and leaves it at e_a·v₀, e_a the restitution of that impact — the
    contact law on half the mass under gravity, integrated apart as one degree of freedom
    (gravity acting through the contact lowers it from the law's 0.9) — and rises e_a²·c
    above the rings, within 1 %."""
    from scipy.integrate import solve_ivp

    from ambseal.model import ContactLaw

    base = _rig()
    cfg = base.model_copy(update={"touchdown": [
        t.model_copy(update={"restitution": 0.9}) for t in base.touchdown]})
    m = inertia(*DISK)[0]
    v0 = math.sqrt(2 * GRAVITY * C_TD)
    law = ContactLaw.of(cfg.touchdown[0])
    _, t_c = hertz_impact(0.5 * m, v0, K_TD)

    def rhs(t, s):  # s[0]: the penetration, downwards
        return [s[1], GRAVITY - float(law.force(s[0], s[1], v0)) / (0.5 * m)]

    one = solve_ivp(rhs, (0, 3 * t_c), [0.0, v0], method="DOP853", rtol=1e-11,
                    atol=1e-16, max_step=t_c / 400)
    e_a = -one.y[1][np.argmax(one.y[0] < 0)] / v0
    assert 0.7 < e_a < 0.9
    fall = math.sqrt(2 * C_TD / GRAVITY)
    r = simulate_drop(cfg, duration_s=fall + 2 * t_c + 2 * e_a * fall, samples=20001)
    after = r.t > fall + 1.5 * t_c
    rise = C_TD + r.orbit[0, after, 1].max()
    assert rise == pytest.approx(e_a**2 * C_TD, rel=0.01)


def test_energy_is_kept_without_damping_or_friction():
    """Spinning at 3000 rpm (the gyroscopic moments do no work), undamped contacts,
    no friction, no structural damping: through the bounces the rotor's energy with the
    contacts' stored energy stays within 1e-4 of the energy of the fall m·g·c."""
    cfg = _rig()
    m = inertia(*DISK)[0]
    r = simulate_drop(cfg, speed_rpm=3000.0, duration_s=0.05, samples=5001, rtol=1e-10)
    assert r.impacts >= 4
    assert np.abs(r.energy - r.energy[0]).max() < 1e-4 * m * GRAVITY * C_TD
    # the AMBs' forces decaying through L/R = 2 ms hold the rotor back as it falls: the
    # energy falls short of the fall's by their work, which the drop counts (their law:
    # test_analysis_drop_loop)
    slow = cfg.model_copy(update={"amb": [a.model_copy(update={"inductance": 0.02,
                                                                "resistance": 10.0})
                                          for a in cfg.amb]})
    r = simulate_drop(slow, speed_rpm=3000.0, duration_s=0.05, samples=5001, rtol=1e-10)
    assert r.work[-1] < 0
    assert np.abs(r.energy - r.energy[0] - r.work).max() < 1e-4 * m * GRAVITY * C_TD


def test_a_ring_spun_up_by_friction():
    """The rotor spinning at 6000 rpm settles (1 µm clearance, e = 0.3) on rings of
    inertia J: the journal slides, climbing each ring until the friction μN balances the
    weight's share along it (tan φ = μ, N = (m/2)·g·cos φ), and μN at the ring's radius
    R_r spins the ring up at the rate μ N R_r/J to the journal's surface speed,
    ω_r = Ω R_j/R_r (no slip), in t = J Ω R_j/(μ N R_r²): the rate between 20 and 80 %
    and the time to 99 % within 2 %, the final speed within 1 %."""
    J, mu = 2e-4, 0.2
    base = _rig()
    cfg = base.model_copy(update={"touchdown": [
        t.model_copy(update={"radial_clearance": 1e-6, "restitution": 0.3, "friction": mu,
                             "race_inertia": J, "contact_stiffness": 5e8})
        for t in base.touchdown]})
    W = 2 * math.pi * 100.0
    m = inertia(*DISK)[0]
    R_j = journal_radius(cfg, 0.0)
    R_r = R_j + 1e-6
    N = 0.5 * m * GRAVITY * math.cos(math.atan(mu))
    t_spin = J * W * R_j / (mu * N * R_r**2)
    r = simulate_drop(cfg, speed_rpm=6000.0, duration_s=1.2 * t_spin, samples=4001)
    target = W * R_j / R_r
    for p in range(2):
        w = r.race_speed[p]
        t20, t80, t99 = (r.t[np.argmax(w >= f * target)] for f in (0.2, 0.8, 0.99))
        assert 0.6 * target / (t80 - t20) == pytest.approx(mu * N * R_r / J, rel=0.02)
        first = r.t[np.argmax(r.force[p] > 0)]
        assert t99 - first == pytest.approx(0.99 * t_spin, rel=0.02)
        assert r.spin_up_s(p, 0.99) == pytest.approx(0.99 * t_spin, rel=0.02)
        assert r.to_dict()["planes"][p]["race_spin_up_s"] == pytest.approx(0.9 * t_spin,
                                                                         rel=0.02)
        assert w[-1] == pytest.approx(target, rel=0.01)
    # a ring dragged up to speed by a slipping contact at a held surface speed: the drive
    # does twice the ring's final kinetic energy in work, and friction dissipates half
    # (the fall through 1 µm adds 2e-5 of it)
    ring = 2 * 0.5 * J * target ** 2
    d = r.to_dict()
    assert d["external_work_j"] == pytest.approx(2 * ring, rel=0.02)
    assert d["energy_dissipated_j"] == pytest.approx(ring, rel=0.02)


def test_the_verdict_grades_what_the_rig_gives():
    """The rotor falls through the rings' 0.2 mm at its AMBs too: an AMB air gap of
    0.15 mm is touched (FAILED), 0.5 mm is not; the peak force against C₀ passes or fails
    by ``[drop] force_ratio``; without a C₀ or a gap the criterion is not graded and the
    verdict says so; bouncing is no backward whirl."""
    plain = _rig()
    fall = math.sqrt(2 * C_TD / GRAVITY)
    r = simulate_drop(plain, duration_s=2 * fall, samples=4001)
    v = drop_verdict(plain, r)
    assert v["passed"] and v["verdict"].startswith("Drop PASSED on what was graded")
    assert {c["outcome"] for c in v["criteria"]} == {"passed", "not graded"}
    # no air_gap given: the AMB's is its linearisation's Ki·i0/Ks = 100·5/2e5 = 2.5 mm, and
    # a Ks that puts it at 0.15 mm, inside the fall through the rings, is touched
    gap = {c["name"]: c for c in v["criteria"]}["no contact at A (air gap)"]
    assert gap["outcome"] == "passed" and gap["limit"] == "2500 µm"
    stiff = plain.model_copy(update={"amb": [a.model_copy(update={"ks": 100.0 * 5.0 / 1.5e-4})
                                             for a in plain.amb]})
    gap = {c["name"]: c for c in drop_verdict(stiff, r)["criteria"]}["no contact at A (air gap)"]
    assert gap["outcome"] == "FAILED" and gap["limit"] == "150 µm"
    peak = r.force.max()
    for gap, c0, ratio, ok in ((5e-4, 2 * peak, 1.0, True), (1.5e-4, 2 * peak, 1.0, False),
                               (5e-4, 0.9 * peak, 1.0, False), (5e-4, 0.9 * peak, 1.2, True)):
        cfg = plain.model_copy(update={
            "amb": [a.model_copy(update={"air_gap": gap}) for a in plain.amb],
            "touchdown": [t.model_copy(update={"static_rating": c0})
                          for t in plain.touchdown],
            "drop": plain.drop.model_copy(update={"force_ratio": ratio})})
        v = drop_verdict(cfg, r)
        assert v["passed"] is ok, v
        # the most loaded ball's stress: ISO 76's 4 200 MPa at C₀, as the load^(1/3)
        row = {c["name"]: c for c in v["criteria"]}["peak force at TA"]
        mpa = 4200.0 * (r.peak_force[0] / c0) ** (1 / 3)
        assert f"{mpa:.4g} MPa at the most loaded ball" in row["value"]
        assert v["verdict"] == "Drop PASSED" if ok else v["verdict"].startswith("Drop FAILED")
        assert all(c["outcome"] != "not graded" for c in v["criteria"])


def test_a_rotor_settled_on_its_rings_is_resting_not_whirling():
    """A damped drop (e = 0.3, friction 0.1) at standstill settles at the bottom of the
    rings: over the last half its regime is resting, not a whirl, and it stays in
    contact with the plane's weight share."""
    base = _rig()
    cfg = base.model_copy(update={"touchdown": [
        t.model_copy(update={"restitution": 0.3, "friction": 0.1, "contact_stiffness": 5e8})
        for t in base.touchdown]})
    r = simulate_drop(cfg, duration_s=0.1, samples=2001)
    m = inertia(*DISK)[0]
    for p in range(2):
        assert r.regime(p) == ("resting", 0.0)
        assert r.force[p, -1] == pytest.approx(0.5 * m * GRAVITY, rel=0.02)


def test_peaks_are_read_between_the_samples_and_slow_onsets_are_not_overdamped():
    """With two output samples only, the first impact's peak force and penetration are
    still the energy balance's (2 %): read at the integrator's steps. On soft-mounted
    rings (0.5 kg on 5e6 N/m) the journal and a ring meet again and again at small
    relative speeds; damped as the free fall over the clearance would be, the peak force
    stays within twice the elastic force of the deepest penetration — with the damping
    of a near-zero onset speed, D ∝ 1/v₀, it had been many times it."""
    from scipy.optimize import brentq

    cfg = _rig()
    m = inertia(*DISK)[0]
    delta = brentq(lambda d: 0.4 * K_TD * d**2.5 - 0.5 * m * GRAVITY * (C_TD + d),
                   0.0, C_TD)
    fall = math.sqrt(2 * C_TD / GRAVITY)
    _, t_c = hertz_impact(0.5 * m, GRAVITY * fall, K_TD)
    r = simulate_drop(cfg, duration_s=fall + 0.7 * t_c, samples=2)
    assert r.peak_penetration == pytest.approx([delta] * 2, rel=0.02)
    assert r.peak_force == pytest.approx([K_TD * delta**1.5] * 2, rel=0.02)
    soft = cfg.model_copy(update={"touchdown": [
        t.model_copy(update={"restitution": 0.5, "support_stiffness": 5e6,
                             "support_mass": 0.5, "support_damping": 2000.0})
        for t in cfg.touchdown]})
    r = simulate_drop(soft, duration_s=0.05, samples=2001)
    assert r.impacts > 2
    elastic = K_TD * r.peak_penetration**1.5
    assert np.all(r.peak_force < 2 * elastic), (r.peak_force, elastic)


def test_a_coasting_rotor_slows_under_the_rings_friction():
    """The drive lets go too: resting on fixed rings (1 µm clearance, e = 0.3), the journal
    slides at both planes with μN, N = (m/2)·g·cos(atan μ), and the spin slows at
    2 μ N R_j/I_p, less a drag torque T_d/I_p: the slope within 2 %; with no friction and
    no drag the spin is kept (1e-9)."""
    mu, drag = 0.2, 0.5
    base = _rig()
    cfg = base.model_copy(update={"touchdown": [
        t.model_copy(update={"radial_clearance": 1e-6, "restitution": 0.3, "friction": mu,
                             "contact_stiffness": 5e8}) for t in base.touchdown]})
    m, _, ip = inertia(*DISK)
    R_j = journal_radius(cfg, 0.0)
    N = 0.5 * m * GRAVITY * math.cos(math.atan(mu))
    r = simulate_drop(cfg, speed_rpm=3000.0, duration_s=0.2, samples=401, coast_down=True,
                      drag_torque=drag)
    late = r.t >= 0.05
    slope = np.polyfit(r.t[late], r.spin[late], 1)[0]
    assert slope == pytest.approx(-(2 * mu * N * R_j + drag) / ip, rel=0.02)
    # at that constant deceleration the rotor stops W0/|slope| after the drop: the
    # coast-down time extrapolated from the drop's last half
    stop, extrapolated = r.coast_down_s()
    assert extrapolated and stop == pytest.approx(100 * math.pi * ip / (2 * mu * N * R_j
                                                                        + drag), rel=0.02)
    assert r.to_dict()["coast_down_s"] == pytest.approx(stop)
    free = simulate_drop(_rig(), speed_rpm=3000.0, duration_s=0.02, samples=101,
                         coast_down=True)
    assert free.spin == pytest.approx(100 * math.pi, rel=1e-9)
    assert free.coast_down_s() == (None, False)


def test_the_drop_needs_its_bearings():
    """No touchdown bearing or no AMB: refused by name; the journal radius is the
    shaft's. (A flexible support without its mass the rig file refuses when it is read.)"""
    cfg = _rig()
    assert journal_radius(cfg, 0.2) == pytest.approx(D / 2)
    with pytest.raises(ConfigError, match="touchdown"):
        drop_model(cfg.model_copy(update={"touchdown": []}))
    with pytest.raises(ConfigError, match=r"\[\[amb\]\]"):
        drop_model(cfg.model_copy(update={"amb": []}))


def test_a_whirl_in_rolling_contact_meets_the_no_slip_kinematics():
    """The rotor started whirling forward at ω₀ = 2000 rad/s round its rings (1 mm
    clearance, stiff point contacts), spinning at Ω = 3000 rpm, the free rings at rest:
    friction at the slip Ω R_j + r ω − ω_r R_r turns the rings and brakes the whirl until
    the journal rolls on each ring: r ω + Ω R_j = ω_r R_r (within 2 %). Friction is
    internal to the rotor and its rings, so the whirl's angular momentum about the ring's
    centre with the rings' (carried to the contact's radius) is kept:
    (m/2) r² ω + J ω_r r/R_r is the same at the end (within 2 %)."""
    c, J, W, w0 = 1e-3, 1e-3, 100 * math.pi, 2000.0
    base = _rig()
    cfg = base.model_copy(update={"touchdown": [
        t.model_copy(update={"radial_clearance": c, "restitution": 0.5, "friction": 0.2,
                             "friction_velocity": 0.1, "race_inertia": J,
                             "contact_stiffness": 1e12})
        for t in base.touchdown]})
    dm = drop_model(cfg)
    m = inertia(*DISK)[0]
    # the start: each plane's half of the centripetal force m ω₀² r carried by its contact
    r0 = c
    for _ in range(50):
        r0 = c + (0.5 * m * w0 ** 2 * r0 / 1e12) ** (2 / 3)
    u, v = np.zeros(4 * dm.z.size), np.zeros(4 * dm.z.size)
    u[0::4], v[1::4] = r0, w0 * r0
    r = simulate_drop(cfg, speed_rpm=3000.0, duration_s=0.012, samples=4001, model=dm,
                      initial=(u, v))
    R_j = journal_radius(cfg, 0.0)
    R_r = R_j + c
    late = r.t >= 0.75 * r.t[-1]
    for p in range(2):
        x, y = r.orbit[p, late].T
        radius = float(np.hypot(x, y).mean())
        ang = np.unwrap(np.arctan2(y, x))
        w = float(np.polyfit(r.t[late], ang, 1)[0])
        w_r = float(r.race_speed[p, -1])
        assert abs(w_r) > 100.0 and w < 0.9 * w0  # the rings turned, the whirl braked
        assert radius * w + W * R_j == pytest.approx(w_r * R_r, rel=0.02)
        # whirling in contact from the start, its rings turning at once
        assert r.regime(p)[0] == "forward whirl" and r.onset_s(p) == 0.0
        assert r.spin_up_s(p) < 1e-3
        start = 0.5 * m * r0 ** 2 * w0
        end = 0.5 * m * radius ** 2 * w + J * w_r * radius / R_r
        assert end == pytest.approx(start, rel=0.02)


@pytest.mark.parametrize("name", ["flywheel", "expander_generator"])
def test_the_default_modes_hold_the_first_impact_to_two_per_cent(name):
    """The modes kept by default reach MODES_PER_CONTACT/t_c, the contact time of the fall
    onto the stiffest ring with the rotor's share and the ring's support mass as the two
    bodies: twice as many hertz moves each plane's first impact peak by under 2 % — on
    the flywheel (rigid mounts, its overhung bending modes) and on the expander (rings of
    0.5 kg on soft mounts, whose contact is far shorter than the rotor's share gives).
    Both lying horizontal: the rule is the radial fall's, and the flywheel, standing,
    falls onto its axial face instead."""
    from pathlib import Path

    from ambseal.config import load_rig

    cfg = load_rig(Path(__file__).resolve().parents[2] / "examples" / f"{name}.toml")
    cfg = cfg.model_copy(update={"machine": cfg.machine.model_copy(
        update={"orientation": "horizontal", "inclination_deg": None})})
    dm = drop_model(cfg)
    runs = [simulate_drop(cfg, speed_rpm=cfg.operating.speed_rpm, duration_s=0.03, model=m)
            for m in (dm, drop_model(cfg, 2 * dm.modes_hz))]
    assert runs[1].n_modes > runs[0].n_modes
    assert np.all(runs[0].first_peak_force > 0)
    np.testing.assert_allclose(runs[0].first_peak_force, runs[1].first_peak_force, rtol=0.02)


def test_an_unbalance_fifty_times_the_weight_whirls_the_rotor_round_its_rings():
    """A static unbalance U with U·Ω² = 50 m·g at the centre of a rigid symmetric rotor on
    frictionless rings (1e11 N/m^1.5): it lands into synchronous forward whirl pressed on
    both rings, which carry U·Ω² and the centripetal force m·Ω²·r of the whirl of radius
    r (−m Ω² r = U Ω² − N), half each: the penetration
    δ = (N/K)^(2/3) over the last half within 2 % (the weight's ±2 % ripple in N averages
    out), the whirl at the spin's frequency within 1 %."""
    base = _rig()
    k = 1e11
    cfg = base.model_copy(update={"touchdown": [
        t.model_copy(update={"restitution": 0.5, "contact_stiffness": k})
        for t in base.touchdown]})
    m = inertia(*DISK)[0]
    W = 100 * math.pi
    U = 50 * m * GRAVITY / W ** 2
    r = simulate_drop(cfg, speed_rpm=3000.0, duration_s=0.2, samples=8001, unbalance_kgm=U)
    late = r.t >= 0.1
    for p in range(2):
        radius = float(np.hypot(*r.orbit[p, late].T).mean())
        N = 0.5 * (U + m * radius) * W ** 2
        assert float(r.penetration[p, late].mean()) == pytest.approx((N / k) ** (2 / 3),
                                                                     rel=0.02)
        regime, hz = r.regime(p)
        assert regime == "forward whirl" and hz == pytest.approx(50.0, rel=0.01)


def test_a_ring_rolling_without_slip_hands_the_drop_to_the_stiff_method():
    """Light rings (J = 1e-6 kg·m²) spun up by μ = 0.3 at the default regularisation
    v_r = 1 mm/s: once a ring rolls on the journal the friction's slope μN/v_r on its
    inertia is a time constant of nanoseconds, and DOP853 hands over to LSODA, counted in
    evaluations; the drop then equals LSODA's from the start (rings' final speed 1e-6,
    peak forces 1e-3). A drop without friction stays with DOP853 to its end."""
    base = _rig()
    cfg = base.model_copy(update={"touchdown": [
        t.model_copy(update={"radial_clearance": 1e-6, "restitution": 0.3, "friction": 0.3,
                             "race_inertia": 1e-6, "contact_stiffness": 5e8})
        for t in base.touchdown]})
    fast = simulate_drop(cfg, speed_rpm=3000.0, duration_s=0.05, samples=501)
    assert fast.integrator.startswith("DOP853 → LSODA from ")
    stiff = simulate_drop(cfg, speed_rpm=3000.0, duration_s=0.05, samples=501,
                          method="LSODA")
    assert stiff.integrator == "LSODA"
    np.testing.assert_allclose(fast.race_speed[:, -1], stiff.race_speed[:, -1], rtol=1e-6)
    np.testing.assert_allclose(fast.peak_force, stiff.peak_force, rtol=1e-3)
    plain = simulate_drop(_rig(), speed_rpm=3000.0, duration_s=0.02, samples=201)
    assert plain.integrator == "DOP853"


@pytest.mark.parametrize("cutoff_hz", [None, 200.0])
def test_the_levitated_start_is_the_pid_loops_unbalance_orbit(cutoff_hz):
    """The rigid symmetric rotor held by a PID on two collocated AMBs, without and with a
    first-order amplifier G_a = ω_c/(s + ω_c), spinning at 3000 rpm with U = 1e-4 kg·m at
    its centre: its cylindrical whirl is the closed form
    X = U Ω²/(2(Ki·G_a(jΩ)·K(jΩ) − Ks) − m Ω²), K(jΩ) = Kp(1 + 1/(jΩ Ti) +
    jΩ Td/(jΩ ε Td + 1)) (P5 Eq. 6); at t = 0 the centre sits at (Re X, Im X) moving at
    Ω (−Im X, Re X): within 1e-6. A PID of the wrong sign is refused, naming the pole."""
    from ambseal.analysis.drop_levitated import levitated_state
    from ambseal.design import pid_controller
    from ambseal.model import channel_names

    cfg = _rig()
    if cutoff_hz:
        cfg = cfg.model_copy(update={"actuator": cfg.actuator.model_copy(update={
            "model": "first_order", "cutoff_hz": cutoff_hz})})
    dm = drop_model(cfg)
    m = inertia(*DISK)[0]
    kp, ti, td, eps = 1e4, 0.2, 3e-3, 0.1
    K = pid_controller(kp, ti, td, eps, channel_names(cfg))
    W, U = 100 * math.pi, 1e-4
    eta, deta, _ = levitated_state(cfg, dm, 3000.0, U, controller=K)
    u, v = dm.phi @ eta, dm.phi @ deta
    s = 1j * W
    Kc = kp * (1 + 1 / (s * ti) + s * td / (s * eps * td + 1))
    Ga = 1.0 if not cutoff_hz else 2 * math.pi * cutoff_hz / (s + 2 * math.pi * cutoff_hz)
    X = U * W ** 2 / (2 * (100.0 * Ga * Kc - 2e5) - m * W ** 2)
    g = int(np.argmin(np.abs(dm.z - L / 2)))
    sag = dm.phi @ dm.q0
    np.testing.assert_allclose(u[4 * g:4 * g + 2] - sag[4 * g:4 * g + 2],
                               [X.real, X.imag], rtol=1e-6, atol=1e-6 * abs(X))
    np.testing.assert_allclose(v[4 * g:4 * g + 2], [-W * X.imag, W * X.real], rtol=1e-6,
                               atol=1e-6 * W * abs(X))
    with pytest.raises(ConfigError, match=r"unstable at 3000 rpm \(a pole at"):
        levitated_state(cfg, dm, 3000.0, U,
                        controller=pid_controller(-kp, ti, td, eps, channel_names(cfg)))


def test_the_sensor_gaps_and_the_disks_clearance_are_judged():
    """The rotor falls through the rings' 0.2 mm: at standstill the disk (mid-span) and
    the sensors (at the AMBs) move about as much; a sensor gap or a disk clearance of
    0.15 mm is closed (FAILED), 0.5 mm is not, each row named for its gap; without the
    keys there is no such row."""
    plain = _rig()
    r = simulate_drop(plain, duration_s=0.02, samples=401)
    names = {c["name"] for c in drop_verdict(plain, r)["criteria"]}
    assert not any("sensor gap" in n or "disk" in n for n in names)
    for gap, outcome in ((1.5e-4, "FAILED"), (5e-4, "passed")):
        cfg = plain.model_copy(update={
            "amb": [a.model_copy(update={"sensor_gap": gap}) for a in plain.amb],
            "disk": [d.model_copy(update={"clearance": gap, "name": "wheel"})
                     for d in plain.disk]})
        r = simulate_drop(cfg, duration_s=0.02, samples=401)
        rows = {c["name"]: c for c in drop_verdict(cfg, r)["criteria"]}
        for name in ("no contact at A (sensor gap)", "no contact at B (sensor gap)",
                     "no contact at wheel (clearance)"):
            assert rows[name]["outcome"] == outcome and rows[name]["limit"] == \
                f"{1e6 * gap:.4g} µm"
        # the disk's excursion is the rotor's at mid-span: its fall through the rings
        assert np.hypot(*r.watched["disk:wheel"].T).max() == pytest.approx(
            C_TD + r.peak_penetration.max(), rel=0.05)


def test_a_drop_beyond_the_contact_laws_range_says_so_where_and_when():
    """Dry whip: at 6000 rpm on rings that do not turn, with friction 0.5, the journal
    rolls round its ring backwards and the whirl's centripetal force presses it in far
    past an elastic contact (0.86 × the 0.2 mm clearance within 23 ms, short of the 1 %
    of the radius that ends a drop). The verdict does not pass: it says first that each
    ring left the contact law's range, how deep (the drop's deepest penetration) and from
    when (the first output sample past ``[drop] penetration_ratio`` × the clearance, 0.5
    by default); with the share raised above the depth it says nothing of the range. An
    AMB air gap of 0.15 mm, inside the fall through the rings' 0.2 mm, is a gap the rotor
    goes through, no earlier than a free fall through it."""
    base = _rig()
    cfg = base.model_copy(update={"touchdown": [
        t.model_copy(update={"restitution": 0.5, "friction": 0.5}) for t in base.touchdown]})
    assert cfg.drop.penetration_ratio == 0.5
    r = simulate_drop(cfg, speed_rpm=6000.0, duration_s=0.023, samples=2001)
    assert r.regime(0)[0] == "backward whirl"
    deep = r.peak_penetration / C_TD
    assert (deep > 0.6).all()
    v = drop_verdict(cfg, r)
    assert not v["passed"] and "PASSED" not in v["verdict"]
    assert v["verdict"].startswith("Drop FAILED, beyond the drop model's range: TA's ring")
    rows = {c["name"]: c for c in v["criteria"]}
    for p, name in enumerate(("TA", "TB")):
        row = rows[f"penetration within the contact law's range at {name}"]
        when = 1e3 * r.t[np.argmax(r.penetration[p] > 0.5 * C_TD)]
        text = (f"{name}'s ring pressed {1e6 * r.peak_penetration[p]:.4g} µm deep "
                f"({deep[p]:.3g} × its 200 µm clearance) from t = {when:.4g} ms")
        assert row["outcome"] == "FAILED" and row["limit"].startswith("0.5 × the clearance")
        assert any(b.startswith(text) for b in v["beyond_range"]) and text in v["verdict"]
    loose = cfg.model_copy(update={"drop": cfg.drop.model_copy(
        update={"penetration_ratio": 1.01 * deep.max()})})
    v = drop_verdict(loose, r)
    assert v["beyond_range"] == [] and "range" not in v["verdict"]
    assert v["verdict"].startswith("Drop FAILED: no backward whirl")
    tight = cfg.model_copy(update={"amb": [a.model_copy(update={"air_gap": 1.5e-4})
                                          for a in cfg.amb]})
    v = drop_verdict(tight, r)
    through = [b for b in v["beyond_range"] if "air gap at A" in b]
    t_gap = float(through[0].split("from t = ")[1].split(" ms")[0])
    assert t_gap >= 1e3 * math.sqrt(2 * 1.5e-4 / GRAVITY)
    assert "through the gap from t =" in {c["name"]: c for c in v["criteria"]}[
        "no contact at A (air gap)"]["value"]
