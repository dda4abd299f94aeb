"""Cross-axis gains of the reference PID (ambseal.design.pid.pid_controller) on a rigid
gyroscopic rotor.

Reference: Routh–Hurwitz for polynomials with complex coefficients (Frank 1946; e.g.
Bodson, *IEEE TAC* 1996): s² + (α₁ + jβ₁)s + (α₀ + jβ₀) has both roots in the left half
plane iff α₁ > 0 and α₁²α₀ + α₁β₁β₀ − β₀² > 0. A rigid symmetric rotor (mass m,
transverse and polar inertia I_t, I_p, spinning at Ω) on two identical AMBs at ±a from its
centre, sensors collocated, under the PD i_ζ = −(k_p y_ζ + k_d ẏ_ζ) − (k_cp y_η + k_cd ẏ_η),
i_η = −(k_p y_η + k_d ẏ_η) + (k_cp y_ζ + k_cd ẏ_ζ) — i = −(K − jK_c) r in r = ζ + jη — has,
with f = K_i i + K_s r, the modes (Genta, *Dynamics of Rotating Systems*, 2005, §4.4)

    cylindrical:  m s² + 2K_i(k_d − jk_cd) s + 2(K_i k_p − K_s) − 2jK_i k_cp = 0,
    conical:      I_t s² + (2a²K_i k_d − j(I_pΩ + 2a²K_i k_cd)) s
                  + 2a²(K_i k_p − K_s) − 2ja²K_i k_cp = 0,

so the loop holds while c²k + c(g + c_c)k_c − M k_c² > 0 for each (c the direct damping,
k the stiffness, g = I_pΩ on the conical mode, c_c and k_c the cross terms, M = m or I_t):
a band of the cross gain k_cp whose ends move with the speed.
"""

from __future__ import annotations

import math
import tomllib

import numpy as np
import pytest

from ambseal.config import parse_rig
from ambseal.design.pid import pid_controller
from ambseal.errors import ConfigError
from ambseal.lti import feedback_matrices
from ambseal.model import channel_names
from ambseal.model.rig import build_plant

from ..rigid_rotor import E_RIGID, L, inertia, rotor_text

DISK_M, DISK_IP, DISK_ID = 20.0, 0.9, 3.0
KI, KS = 100.0, 2.0e5
KP, KD, KCD = 4.0e3, 6.0, 1.5


def _rotor() -> str:
    text = rotor_text("rigid gyroscopic rotor on AMBs", DISK_M, DISK_IP, DISK_ID, 4) + f"""
[controller]
sample_rate_hz = 20000.0
delay_samples = 0
[controller.pid]
kp = {KP}
ti = 1.0
td = 1e-3
eps = 0.1
[operating]
speed_rpm = 0.0
"""
    for name, z in (("A", 0.0), ("B", L)):
        text += (f'[[amb]]\nname = "{name}"\nposition = {z}\nsensor_position = {z}\n'
                 f"ki = {KI}\nks = {KS}\nbias_current = 5.0\ncurrent_limit = 10.0\n")
    return text


def _stable(cfg, speed_hz: float, kcp: float) -> bool:
    """The continuous loop (no delay) of the full plant at ``speed_hz`` with a PD — the
    PID's integral and derivative filter pushed out of the band (T_i 1e4 s, ε T_d 1e-8 s)."""
    P = build_plant(cfg, speed_rpm=60.0 * speed_hz).to_statespace()
    K = pid_controller(KP, 1e4, KD / KP, 1e-8 / (KD / KP), channel_names(cfg),
                       cross_kp=kcp, cross_kd=KCD)
    mats = [tuple(np.asarray(getattr(S, m), float) for m in "ABCD") for S in (P, K)]
    lam = np.linalg.eigvals(feedback_matrices(*mats)[0])
    return bool(lam.real.max() < 0)


def _band(M: float, c: float, k: float, g: float, cc: float) -> tuple[float, float]:
    """The cross stiffness k_c of c²k + c(g + c_c)k_c − M k_c² > 0 (module docstring)."""
    b = c * (g + cc)
    r = math.sqrt(b * b + 4 * M * c * c * k)
    return (b - r) / (2 * M), (b + r) / (2 * M)


@pytest.mark.parametrize("speed_hz", [0.0, 150.0, 400.0])
def test_the_cross_gain_band_is_routh_hurwitz(speed_hz):
    """Both ends of the stable band of k_cp, found by bisection on the loop's eigenvalues,
    equal the intersection of the cylindrical and conical modes' Routh–Hurwitz bands to
    2e-3 (the PID's integral and filter and the shaft's flexibility are the difference):
    at standstill the conical mode decides both ends; spinning, the gyroscopic moment
    widens its band upwards and narrows it below (−404 A/m at standstill, −101 at 150 Hz,
    −40 at 400 Hz: a cross gain of that sign soon loses the rotor)."""
    cfg = parse_rig(tomllib.loads(_rotor()))
    m, it, ip = inertia(DISK_M, DISK_IP, DISK_ID)
    a = L / 2
    g = ip * 2 * math.pi * speed_hz
    cyl = [x / (2 * KI) for x in _band(m, 2 * KI * KD, 2 * (KI * KP - KS), 0.0, 2 * KI * KCD)]
    con = [x / (2 * a * a * KI) for x in _band(it, 2 * a * a * KI * KD,
                                               2 * a * a * (KI * KP - KS), g,
                                               2 * a * a * KI * KCD)]
    want = (max(cyl[0], con[0]), min(cyl[1], con[1]))
    assert want[0] == con[0]  # the conical mode, where the gyroscopic moment acts
    for edge, outside in zip(want, (2 * want[0], 2 * want[1])):
        inside, out = 0.0, outside
        assert _stable(cfg, speed_hz, inside) and not _stable(cfg, speed_hz, out)
        for _ in range(40):
            mid = 0.5 * (inside + out)
            inside, out = (mid, out) if _stable(cfg, speed_hz, mid) else (inside, mid)
        assert inside == pytest.approx(edge, rel=2e-3), (speed_hz, edge)


def test_cross_terms_pass_the_filters_and_refusals():
    """Reference: the transfer functions written out — with a lead and a notch in series
    (the commissioning engineer's filters), each entry of K(jω) at 1, 80 and 900 Hz is
    F(jω)·K_PID(jω) on the diagonal, +F(jω)·K_c(jω) at (ζ, η) and −F(jω)·K_c(jω) at
    (η, ζ), 0 between bearings, with K_c = k_cp + k_cd jω/(ε T_d jω + 1) and F the filters'
    formulas (:func:`pid_controller`), to 1e-9; a cross derivative without a derivative
    (td = 0) and channels without an η axis are refused."""
    ch = ("A_zeta", "A_eta", "B_zeta", "B_eta")
    kp, ti, td, eps, kcp, kcd = 1e4, 0.2, 3e-3, 0.1, 500.0, 0.7
    lead = {"kind": "lead", "frequency_hz": 300.0, "phase_deg": 30.0}
    notch = {"kind": "notch", "frequency_hz": 900.0, "width_hz": 100.0, "depth_db": 20.0}
    K = pid_controller(kp, ti, td, eps, ch, [lead, notch], cross_kp=kcp, cross_kd=kcd)
    A, B, C, Dm = (np.asarray(getattr(K, m), float) for m in "ABCD")
    for f in (1.0, 80.0, 900.0):
        s = 2j * math.pi * f
        Kw = C @ np.linalg.solve(s * np.eye(A.shape[0]) - A, B) + Dm
        sn = math.sin(math.radians(30.0))
        al = (1 + sn) / (1 - sn)
        wc = 2 * math.pi * 300.0
        wz, wp = wc / math.sqrt(al), wc * math.sqrt(al)
        F_lead = (wp / wz) * (s + wz) / (s + wp)  # (1 + s/ω_z)/(1 + s/ω_p)
        wn = 2 * math.pi * 900.0
        zp = 100.0 / (2 * 900.0)
        zz = zp * 10 ** (-20.0 / 20)
        F = F_lead * (s * s + 2 * zz * wn * s + wn * wn) / (s * s + 2 * zp * wn * s + wn * wn)
        direct = kp * (1 + 1 / (ti * s) + td * s / (eps * td * s + 1)) * F
        cross = (kcp + kcd * s / (eps * td * s + 1)) * F
        want = np.array([[direct, cross, 0, 0], [-cross, direct, 0, 0],
                         [0, 0, direct, cross], [0, 0, -cross, direct]])
        np.testing.assert_allclose(Kw, want, rtol=1e-9, atol=1e-9 * abs(direct))
    with pytest.raises(ConfigError, match="td > 0"):
        pid_controller(1e4, 0.2, 0.0, 0.1, ch, cross_kd=1.0)
    with pytest.raises(ConfigError, match="η axis"):
        pid_controller(1e4, 0.2, 3e-3, 0.1, ("A_zeta", "B_zeta"), cross_kp=1.0)


def test_the_rig_files_cross_gains_reach_the_pid_and_its_record():
    """``[controller.pid] cross_kp``, ``cross_kd`` are the reference PID's (its K_ζη, K_ηζ
    feedthrough ±(cross_kp + cross_kd/(ε T_d))), its description carries them, and a
    record's PID metadata rebuilds the same discrete controller; a cross derivative with
    ``td = 0`` is refused by the rig file, naming the key."""
    from ambseal.design import design
    from ambseal.design.pid import controller_from_metadata, pid_description, reference_pid
    from ambseal.robust import discrete_controller

    text = _rotor().replace("eps = 0.1\n", "eps = 0.1\ncross_kp = 300.0\ncross_kd = 0.2\n")
    cfg = parse_rig(tomllib.loads(text))
    K = design(cfg, "pid").K
    assert K.D[0, 1] == pytest.approx(300.0 + 0.2 / (0.1 * 1e-3))
    assert K.D[1, 0] == pytest.approx(-(300.0 + 0.2 / (0.1 * 1e-3)))
    desc = pid_description(reference_pid(cfg))
    assert (desc["cross_kp"], desc["cross_kd"]) == (300.0, 0.2)
    meta = {"sample_rate_hz": 20000.0, "controller": {"type": "pid", **desc}}
    got = controller_from_metadata(meta, channel_names(cfg))
    want = discrete_controller(K, 1 / 20000.0, "tustin")
    for m in "ABCD":
        np.testing.assert_allclose(getattr(got, m), getattr(want, m), rtol=1e-12, atol=1e-12)
    with pytest.raises(ConfigError, match="cross_kd"):
        parse_rig(tomllib.loads(text.replace("td = 1e-3", "td = 0.0")))


def _pd_band_top(speed_hz: float, kd: float, disk_id: float) -> float:
    """The upper end of the stable band of k_cp (no cross derivative) at ``speed_hz``: the
    conical and cylindrical modes' Routh–Hurwitz bands intersected (module docstring)."""
    m, it, ip = inertia(DISK_M, DISK_IP, disk_id)
    a = L / 2
    cyl = _band(m, 2 * KI * kd, 2 * (KI * KP - KS), 0.0, 0.0)[1] / (2 * KI)
    con = _band(it, 2 * a * a * KI * kd, 2 * a * a * (KI * KP - KS),
                ip * 2 * math.pi * speed_hz, 0.0)[1] / (2 * a * a * KI)
    return min(cyl, con)


def _scheduled(text: str, cross: str) -> str:
    """The rig ``text`` with the cross gains ``cross`` given at 400 Hz (24 000 rpm), run
    at 150 Hz over 100–400 Hz, and no integral (T_i 1e4 s: the precession, 2.6 Hz at
    150 Hz, would meet it)."""
    return text.replace("eps = 0.1\n", f"eps = 0.1\n{cross}cross_speed_rpm = 24000.0\n"
                        ).replace("[operating]\nspeed_rpm = 0.0",
                                  "[operating]\nspeed_rpm = 9000.0\n"
                                  "speed_range_hz = [100.0, 400.0]").replace(
        "ti = 1.0", "ti = 1e4")


def test_cross_gains_scheduled_on_speed_hold_where_constant_ones_do_not():
    """``cross_speed_rpm``: the cross gain given at 400 Hz (0.8 of the band's top there) and
    scaled ∝ Ω stays inside the Routh–Hurwitz band at every speed, so the PID frozen at
    0, 150 and 400 Hz holds the rotor; the same gain held constant is above the band's top
    at standstill (by the closed form) and loses it there. The scheduled PID at Ω is
    :func:`pid_controller` with the scaled gain, and between its two table entries (0 and
    the top speed) linear interpolation is that PID exactly."""
    from ambseal.design import design
    from ambseal.design.pid import ScheduledPid, reference_pid

    kd, disk_id = KP * 1e-3, 6.0  # the rig file's PID: kp·td; a long rotor: I_t ≫ m a²
    k_ref = 0.8 * _pd_band_top(400.0, kd, disk_id)
    assert k_ref > 1.25 * _pd_band_top(0.0, kd, disk_id)  # constant: above the band at rest
    cfg = parse_rig(tomllib.loads(_scheduled(
        _rotor().replace(f"Id = {DISK_ID}", f"Id = {disk_id}"), f"cross_kp = {k_ref}\n")))
    res = design(cfg, "pid")
    K = res.controller
    assert isinstance(K, ScheduledPid) and K.schedule == (0.0, 2 * math.pi * 400.0)
    assert reference_pid(cfg)["cross_kp"] == pytest.approx(k_ref * 150.0 / 400.0)
    ch = channel_names(cfg)

    def loop_stable(Kss, speed_hz):
        """The loop's modes below 50 kHz in the left half-plane (the 1e4-times-stiffer
        shaft's lossless bending modes, above 0.6 MHz, are not the rotor's)."""
        P = build_plant(cfg, speed_rpm=60.0 * speed_hz).to_statespace()
        mats = [tuple(np.asarray(getattr(S, m), float) for m in "ABCD") for S in (P, Kss)]
        lam = np.linalg.eigvals(feedback_matrices(*mats)[0])
        return bool(lam[np.abs(lam) < 2 * math.pi * 5e4].real.max() < 0)

    for f in (0.0, 150.0, 400.0):
        want = pid_controller(KP, 1e4, 1e-3, 0.1, ch, cross_kp=k_ref * f / 400.0)
        got = K.at(2 * math.pi * f)
        for m in "ABCD":
            np.testing.assert_allclose(getattr(got, m), getattr(want, m), rtol=1e-12,
                                       atol=1e-9)
        assert loop_stable(got, f), f
    assert not loop_stable(pid_controller(KP, 1e4, 1e-3, 0.1, ch, cross_kp=k_ref), 0.0)
    mid = K.matrices_at(2 * math.pi * 130.0)
    ends = [K.matrices_at(w) for w in K.table_theta]
    t = 130.0 / 400.0
    for x, a, b in zip(mid, *ends):
        np.testing.assert_allclose(x, (1 - t) * a + t * b, rtol=1e-12, atol=1e-9)
    with pytest.raises(ConfigError, match="cross_speed_rpm"):
        parse_rig(tomllib.loads(_rotor().replace("eps = 0.1\n",
                                                 "eps = 0.1\ncross_speed_rpm = 1000.0\n")))


def test_the_scheduled_pid_runs_as_a_table():
    """A PID with cross gains ∝ speed, on the rotor with a steel shaft (bending at a few
    kilohertz), runs as a discrete table on speed from standstill to the top speed
    (``ambseal.app.commands.digital_for``): each entry is python-control's
    ``sample_system`` of the frozen PID at that speed by the chosen method, and the loop
    of the table interpolated at speeds on and between its entries with the plant sampled
    by SciPy (ZOH) is stable, checked by python-control's poles."""
    import control
    from scipy.signal import cont2discrete

    from ambseal.analysis.judge import operating_points
    from ambseal.app.commands import digital_for
    from ambseal.design import design
    from ambseal.design.specs import design_spec
    from ambseal.machine import ScheduledDigital

    cfg = parse_rig(tomllib.loads(_scheduled(
        _rotor().replace(f"E = {E_RIGID}", "E = 2.1e11").replace(
            'rotor on AMBs"', 'rotor on AMBs"\nmodal_damping = 0.01'),
        "cross_kp = 150.0\ncross_kd = 0.05\n")))
    res = design(cfg, "pid")
    dig = digital_for(cfg, "pid", res.controller, res, operating_points(design_spec(cfg)))
    assert isinstance(dig, ScheduledDigital)
    np.testing.assert_allclose(dig.grid / (2 * math.pi), np.linspace(0.0, 400.0, 9))
    T = dig.Ts
    method = {"tustin": "tustin", "zoh": "zoh", "foh": "foh"}[dig.method]
    for j, w in enumerate(dig.grid):
        want = control.sample_system(res.controller.at(w), T, method)
        for m, X in zip("ABCD", dig.discrete):
            np.testing.assert_allclose(X[j], getattr(want, m), rtol=1e-9, atol=1e-9)
    for f in (0.0, 75.0, 150.0, 275.0, 400.0):
        P = build_plant(cfg, speed_rpm=60.0 * f).to_statespace()
        Gd = control.ss(*cont2discrete((P.A, P.B, P.C, P.D), T, method="zoh")[:4], T)
        Kd = dig.statespace_at(2 * math.pi * f, delayed=True)
        loop = control.feedback(Gd, Kd)  # i = −K y
        assert np.abs(loop.poles()).max() < 1.0, f
