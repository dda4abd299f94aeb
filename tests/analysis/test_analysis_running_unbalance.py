"""The unbalance response at the running speed (ambseal.analysis.synchronous.running_plant,
ambseal.analysis.unbalance.running_unbalance) against a closed form and python-control.

References: the synchronous response of a rigid symmetric rotor on isotropic springs with
gyroscopics (4 DOF): its translation ``(2k + 2jΩc − mΩ²) X = F`` and its tilt, whirling
forward with the shaft, ``(2ka² + 2jΩca² − (I_t − I_p)Ω²) Ψ = M`` (Childs, *Turbomachinery
Rotordynamics*, 1993, §3.3; Genta, *Dynamics of Rotating Systems*, 2005, §4.4); and
python-control's full-order plant built at each speed (its matrices, by dense solves:
python-control's own evaluation, slycot's TB05AD, is off by 4e-5 on these 260-state
plants), closed by hand with the controller.
"""

from __future__ import annotations

import dataclasses
import math
import tomllib

import control
import numpy as np
import pytest
from scipy.optimize import minimize_scalar
from scipy.signal import find_peaks

from ambseal.analysis.judge import OperatingPoint, judge, judge_settings
from ambseal.analysis.synchronous import Unbalance, running_plant, synchronous_response
from ambseal.analysis.unbalance import forward_forces, worst_orbit
from ambseal.config import load_rig, parse_rig
from ambseal.design import design, design_spec
from ambseal.model.rig import build_plant
from ambseal.robust import loop_delay

from ..coil_rig import COIL_RIG
from ..rigid_rotor import L, inertia, rotor_text


def _at(sys, s: complex) -> np.ndarray:
    """``C (sI − A)⁻¹ B + D`` of a python-control system by a dense solve."""
    A, B, C, D = (np.asarray(m, float) for m in (sys.A, sys.B, sys.C, sys.D))
    if A.size == 0:
        return D.astype(complex)
    return C @ np.linalg.solve(s * np.eye(A.shape[0]) - A, B) + D


K_SIDE, C_SIDE = 2.0e5, 40.0
DISK_M, DISK_IP, DISK_ID = 20.0, 0.5, 0.3


def _rigid_rotor() -> str:
    return rotor_text("rigid gyroscopic rotor", DISK_M, DISK_IP, DISK_ID, 8) + f"""
[[spring]]
name = "left"
position = 0.0
kxx = {K_SIDE}
kyy = {K_SIDE}
cxx = {C_SIDE}
cyy = {C_SIDE}
[[spring]]
name = "right"
position = {L}
kxx = {K_SIDE}
kyy = {K_SIDE}
cxx = {C_SIDE}
cyy = {C_SIDE}
[operating]
speed_rpm = 3000.0
"""


def test_rigid_gyroscopic_rotor_on_isotropic_springs_is_the_closed_form():
    """An unbalance U at 0.1 m from the centre of mass: force F = UΩ² and moment
    M = 0.1·UΩ²; the orbit at z from the centre is |X + zΨ| (circular, forward), with m,
    I_t = m(3r² + L²)/12 + I_d and I_p = m r²/2 + I_p,disk of the shaft and disk — to 1e-6
    at speeds below, near and above the forward conical critical √(2ka²/(I_t − I_p))."""
    cfg = parse_rig(tomllib.loads(_rigid_rotor()))
    m, it, ip = inertia(DISK_M, DISK_IP, DISK_ID)
    a, k, c = L / 2, K_SIDE, C_SIDE
    assert it > ip  # a forward conical critical exists
    w_con = math.sqrt(2 * k * a**2 / (it - ip))
    U, zu = 1e-4, 0.1
    speeds = np.array([0.3, 0.9, 1.0, 1.1, 1.6]) * w_con / (2 * math.pi)
    zs = np.array([0.0, L, 0.35])
    r = synchronous_response(cfg, None, speeds, [[Unbalance(a + zu, U)]], zs)
    for j, f in enumerate(speeds):
        w = 2 * math.pi * f
        X = U * w**2 / (2 * k + 2j * w * c - m * w**2)
        Psi = zu * U * w**2 / (2 * k * a**2 + 2j * w * c * a**2 - (it - ip) * w**2)
        want = np.abs(X + (zs - a) * Psi)
        assert r.amplitude_m[0, j] == pytest.approx(want, rel=1e-6), f


def test_worst_orbit_over_forward_forces_is_the_brute_force_maximum():
    """The semi-major axis max over real unit directions d and unit force patterns c of
    |dᵀ M c| (every direction in 0.01° steps; for each d the best c is Mᴴd/‖Mᴴd‖), against
    :func:`worst_orbit`'s √λ_max(Re(M Mᴴ)), on random complex responses of two planes."""
    rng = np.random.default_rng(7)
    H = rng.normal(size=(5, 4, 3)) + 1j * rng.normal(size=(5, 4, 3))
    names = ("y_A_zeta", "y_A_eta", "y_B_zeta", "y_B_eta")
    th = np.linspace(0.0, math.pi, 18001)
    d = np.stack([np.cos(th), np.sin(th)])
    want = np.array([max(np.linalg.norm(d.T @ Hw[rows], axis=1).max()
                         for rows in ([0, 1], [2, 3])) for Hw in H])
    assert worst_orbit(H, names) == pytest.approx(want, rel=1e-7)
    T = forward_forces(("F0_x", "F0_y", "F1_x", "F1_y"))
    assert T.tolist() == [[1, 0], [-1j, 0], [0, 1], [0, -1j]]


@pytest.fixture(scope="module")
def overhung():
    """The overhung compressor (a heavy wheel on an overhang: gyroscopic) with its PID."""
    cfg = load_rig("examples/overhung_compressor.toml")
    return cfg, design(cfg, "pid").controller


@pytest.mark.parametrize("rig, speeds, pressure", [
    ("overhung_compressor", (40.0, 180.0, 305.0), 1.0),  # gyroscopic, constant seal
    ("overhung_compressor", (40.0, 180.0, 305.0), 2.0),  # its seal at twice the pressure
    ("turboexpander", (35.0, 130.0, 265.0), 1.0),  # seals tabulated over frequency
    ("b2b_compressor", (20.0, 115.0, 185.0), 0.0),  # two seals, at no pressure drop
])
def test_running_plant_is_python_controls_plant_built_at_each_speed(rig, speeds, pressure):
    """The open loop at the running speed equals the frequency response of the full-order
    plant :func:`build_plant` makes at that speed and pressure drop (python-control's state
    space, solved densely at jΩ; its seal tables taken at Ω/2π): current inputs and forces
    at the bearings, to 1e-7 — on a gyroscopic machine, on one whose seal coefficients
    follow the whirl frequency, where the per-speed seals are what differs, and at pressure
    drops other than the operating one (reached from it through the seals' DOFs)."""
    cfg = load_rig(f"examples/{rig}.toml")
    assert (rig == "turboexpander") == any(sl.frequency_dependent for sl in cfg.seal)
    zs = tuple(a.position for a in cfg.amb)
    speeds = np.array(speeds)
    p = pressure * cfg.operating.pressure_bar
    rp = running_plant(cfg, speeds, zs, pressure_bar=p)
    for k, f in enumerate(speeds):
        P = build_plant(cfg, speed_rpm=60.0 * f, force_positions=zs,
                        pressure_bar=p).to_statespace()
        H = _at(P, 2j * math.pi * f)
        nu = rp.Gu.shape[2]
        assert P.output_labels == list(rp.outputs)
        scale = np.abs(H).max()
        np.testing.assert_allclose(rp.Gu[k], H[:, :nu], atol=1e-7 * scale)
        np.testing.assert_allclose(rp.Gf[k], H[:, nu:], atol=1e-7 * scale)


def test_running_plant_solves_each_speed_once_for_every_pressure_drop(monkeypatch):
    """Each speed's n-DOF dynamic stiffness is solved once for all pressure drops: the
    judged conditions at three pressures share one initial sweep. Where the Woodbury
    identity's small system is too ill-conditioned (forced here with a limit of 0), the
    speed is solved densely at its pressure drop, to the same numbers (1e-9). No speed
    gives empty arrays of the loop's shape."""
    from ambseal.analysis import synchronous as syn
    from ambseal.lti import ArrayMemo

    cfg = load_rig("examples/b2b_compressor.toml")
    zs = tuple(a.position for a in cfg.amb)
    p0 = cfg.operating.pressure_bar
    formed = []
    real = syn._running_system

    def counted(cfg, where, p):
        base, stiffness = real(cfg, where, p)
        return base, lambda f: formed.append(f) or stiffness(f)

    monkeypatch.setattr(syn, "_running_system", counted)
    monkeypatch.setattr(syn, "_RUNNING", ArrayMemo(keep=8))
    monkeypatch.setattr(syn, "_REFERENCE", ArrayMemo(keep=4), raising=False)
    speeds = np.array([20.0, 115.0, 185.0])
    shared = [running_plant(cfg, speeds, zs, pressure_bar=p) for p in (0.0, p0, 2 * p0)]
    assert sorted(formed) == speeds.tolist()
    monkeypatch.setattr(syn, "_RUNNING", ArrayMemo(keep=8))
    monkeypatch.setattr(syn, "_WOODBURY_COND", 0.0)
    dense = running_plant(cfg, speeds, zs, pressure_bar=2 * p0)
    assert sorted(formed) == sorted(2 * speeds.tolist())
    scale = np.abs(dense.Gf).max()
    np.testing.assert_allclose(shared[2].Gf, dense.Gf, rtol=0, atol=1e-9 * scale)
    np.testing.assert_allclose(shared[2].Gu, dense.Gu, rtol=0,
                               atol=1e-9 * np.abs(dense.Gu).max())
    assert not np.allclose(shared[2].Gf, shared[0].Gf, rtol=1e-3, atol=0)  # seals matter
    none = running_plant(cfg, [], zs, pressure_bar=0.0)  # a refinement with no speed left
    assert none.Gu.shape == (0, 4, 4) and none.Gf.shape == (0, 4, 4)


def test_judged_orbit_is_the_loop_closed_on_the_plant_at_that_speed(overhung):
    """The judged unbalance peak (continuous loop, the target's delay as its Padé lag)
    equals, at the speed it names, the forward-force orbit bound of python-control's
    full-order plant built at that speed closed by hand with the PID and the lag
    (S_o G_f T, T the forward forces of the bearing planes), times the ISO 21940-11
    force, to 1e-6; the frozen plant (the thesis's option) gives another number on this
    gyroscopic machine."""
    cfg, K = overhung
    s = judge_settings(design_spec(cfg))
    pt = OperatingPoint(cfg.operating.pressure_bar, cfg.operating.speed_rpm, "x")
    case, curves = judge(cfg, K, "pid", pt, s, impulse=False)
    f = curves["unbalance"][0][np.argmax(curves["unbalance"][1])]
    w = 2 * math.pi * f
    zs = tuple(s.force_positions_m)
    P = build_plant(cfg, speed_rpm=60.0 * f, force_positions=zs).to_statespace()
    H = _at(P, 1j * w)
    nu = len(cfg.amb) * 2
    lag = _at(loop_delay(cfg.controller.sample_rate_hz, cfg.controller.delay_samples).system,
              1j * w)[0, 0]
    Kw = lag * _at(K, 1j * w)  # K's signals are the plant's, in order
    assert list(K.input_labels) == P.output_labels
    cl = np.linalg.solve(np.eye(H.shape[0]) + H[:, :nu] @ Kw, H[:, nu:] @ forward_forces(
        P.input_labels[nu:]))
    orbit = max(np.sqrt(np.linalg.eigvalsh((cl[r] @ cl[r].conj().T).real)[-1])
                for r in ([0, 1], [2, 3]))
    F = s.unbalance_mass_kg * s.unbalance_grade_mm_s * 1e-3 * w**2 / (
        2 * math.pi * s.unbalance_max_speed_hz)
    assert case.unbalance_peak_um == pytest.approx(1e6 * orbit * F, rel=1e-6)
    frozen = judge(cfg, K, "pid", pt, dataclasses.replace(s, unbalance_plant="frozen"),
                   impulse=False)[0]
    assert abs(frozen.unbalance_peak_um / case.unbalance_peak_um - 1) > 0.2


def test_the_worst_orbit_is_over_every_speed_to_the_trip_speed():
    """Reference: an independent sweep — python-control's full-order plant built at each
    speed (:func:`build_plant`, solved densely at jΩ), closed by hand with the PID and the
    target's delay lag under the bearing planes' forward forces, times the ISO 21940-11
    force — over every speed the machine passes, standstill to its trip speed (API 617's
    range for the close clearances; 1.05 × 600 Hz by default): 40 speeds from 1 % of the
    maximum continuous speed, the best refined by bounded scalar maximisation. The judged
    worst orbit equals its largest to 1e-4, at a speed below the 400–600 Hz continuous range
    (the rotor passes it on every run-up; over 10 % above the largest orbit in the range),
    and metrics.json states those speeds (``range_hz`` [6, 630])."""
    cfg = parse_rig(tomllib.loads(COIL_RIG))
    K = design(cfg, "pid").controller
    s = judge_settings(design_spec(cfg))
    assert s.unbalance_range_hz == (400.0, 600.0)  # the band: [operating] speed_range_hz
    assert judge_settings(design_spec(cfg), cfg).unbalance_dict()["range_hz"] == [6.0, 630.0]
    pt = OperatingPoint(0.0, cfg.operating.speed_rpm, "x")
    case, _ = judge(cfg, K, "pid", pt, s, impulse=False)
    zs = tuple(s.force_positions_m)
    lag = loop_delay(cfg.controller.sample_rate_hz, cfg.controller.delay_samples).system

    def orbit_um(f):
        w = 2 * math.pi * f
        P = build_plant(cfg, speed_rpm=60.0 * f, force_positions=zs).to_statespace()
        H, nu = _at(P, 1j * w), 2 * len(cfg.amb)
        Kw = _at(lag, 1j * w)[0, 0] * _at(K, 1j * w)
        cl = np.linalg.solve(np.eye(H.shape[0]) + H[:, :nu] @ Kw,
                             H[:, nu:] @ forward_forces(P.input_labels[nu:]))
        o = max(np.sqrt(np.linalg.eigvalsh((cl[r] @ cl[r].conj().T).real)[-1])
                for r in ([0, 1], [2, 3]))
        F = s.unbalance_mass_kg * s.unbalance_grade_mm_s * 1e-3 * w**2 / (
            2 * math.pi * s.unbalance_max_speed_hz)
        return 1e6 * o * F

    grid = np.linspace(6.0, 630.0, 40)
    k = int(np.argmax([orbit_um(f) for f in grid]))
    best = minimize_scalar(lambda f: -orbit_um(f), bounds=(grid[max(k - 1, 0)], grid[k + 1]),
                           method="bounded", options={"xatol": 1e-3})
    assert case.unbalance_peak_um == pytest.approx(-best.fun, rel=1e-4)
    assert best.x < 400.0 and -best.fun > 1.1 * max(orbit_um(f) for f in (400.0, 500.0))


def test_a_speed_scheduled_controller_is_taken_at_each_speed(overhung):
    """A controller scheduled on speed whose gain is the PID's times (1 + Ω/1000 rad/s):
    at each speed the loop closed for the running unbalance has that speed's gain — the
    PID's response times the factor at Ω, to 1e-12 (frozen at one speed it would not)."""
    from ambseal.analysis.judge import _controller_at_speed
    from ambseal.machine import SPEED, ScheduledController

    cfg, K = overhung

    class Scaled(ScheduledController):
        parameter = SPEED
        schedule = (0.0, 1e4)

        def matrices_at(self, value):
            return tuple(np.asarray(M, float) * (1 + value / 1000.0 if i >= 2 else 1.0)
                         for i, M in enumerate((K.A, K.B, K.C, K.D)))

        def at(self, value, name="K"):
            A, B, C, D = self.matrices_at(value)
            return control.ss(A, B, C, D, inputs=K.input_labels, outputs=K.output_labels)

    w = 2 * math.pi * np.array([30.0, 150.0, 300.0])
    G = control.ss([], [], [], np.zeros((4, 4)), inputs=K.output_labels,
                   outputs=K.input_labels)  # the plant's signals: what K is wired to
    fixed = _controller_at_speed(G, K, None, None)(w)[0]
    sched = _controller_at_speed(G, K, Scaled(), None)(w)[0]
    np.testing.assert_allclose(sched, fixed * (1 + w / 1000.0)[:, None, None], rtol=1e-12)


@pytest.mark.parametrize("f_range, zeta, where", [
    ((90.0, 110.0), 0.05, "inside"),   # AF 10 inside the range
    ((50.0, 85.0), 0.05, "above"),     # 17 % above, 10 + 17(1 − 1/8.5) = 25 % required
    ((50.0, 75.0), 0.05, None),        # 33 % above: separated
    ((115.0, 150.0), 0.05, "below"),   # 13 % below, min(16, 17(1 − 1/8.5)) = 15 % required
    ((120.0, 150.0), 0.05, None),      # 17 % below: separated
    ((90.0, 110.0), 0.3, None),        # AF 1.7: no critical speed
    ((90.0, 110.0), "ripple", None),   # never falls to half power: no resonance
])
def test_critical_speeds_are_the_api_617_separation_check(f_range, zeta, where):
    """Reference: a single-degree-of-freedom resonance 1/|1 − r² + 2jζr| at 100 Hz (its
    peak at N = 100 √(1 − 2ζ²) Hz, AF = 1/(2ζ) by half power to the order ζ) against API
    617's separation margins by hand: 100 (N − f_max)/f_max above the continuous range
    against 10 + 17(1 − 1/(AF − 1.5)) % (at most 26), 100 (f_min − N)/f_min below it
    against 17(1 − 1/(AF − 1.5)) % (at most 16), 0 inside it; a critical speed separated
    by its margin is not named, nor is a resonance with AF < 2.5."""
    from ambseal.analysis.judge import critical_speeds
    from ambseal.analysis.unbalance import UnbalanceResponse

    f = np.linspace(40.0, 160.0, 24001)
    r = f / 100.0
    if zeta == "ripple":  # a broad response with a 1 % ripple
        amp = 1e-5 * (1 + 0.01 * np.sin(2 * np.pi * f / 7.0))
    else:
        amp = 1e-5 / np.abs(1 - r**2 + 2j * zeta * r)
    unb = UnbalanceResponse(2 * np.pi * f, np.ones_like(f), amp, 0.0, 0.0, 1.0, 1.0)
    got = critical_speeds(unb, *f_range)
    if where is None:
        assert got == []
        return
    (c,) = got
    n = 100.0 * math.sqrt(1 - 2 * zeta**2)
    af = 1 / (2 * zeta)
    m = 17 * (1 - 1 / (af - 1.5))
    lo, hi = f_range
    margin, need = {"inside": (0.0, min(26.0, 10 + m)), "above": (100 * (n - hi) / hi,
                                                                 min(26.0, 10 + m)),
                    "below": (100 * (lo - n) / lo, min(16.0, m))}[where]
    assert c["speed_hz"] == pytest.approx(n, rel=1e-4)
    assert c["af"] == pytest.approx(af, rel=2 * zeta)
    assert c["margin_pct"] == pytest.approx(margin, rel=1e-3, abs=1e-9)
    assert c["required_pct"] == pytest.approx(need, rel=0.01)


def test_one_resonance_is_one_critical_speed_however_its_top_is_rounded():
    """Reference: two single-degree-of-freedom resonances 1/|1 − r² + 2jζr|, ζ 0.05 (AF =
    1/(2ζ) = 10 to the order ζ), as the worst orbit over two planes sees them (their
    larger): at 100 and 100.3 Hz, the second 1e-4 lower, the response has two maxima
    0.3 Hz apart on one flat top and never falls to half power between them — one
    resonance, one critical speed at the higher maximum (API 684's half-power band holds
    both). At 100 and 130 Hz the response falls below half power between them: two."""
    from ambseal.analysis.judge import critical_speeds
    from ambseal.analysis.unbalance import UnbalanceResponse

    f = np.linspace(40.0, 160.0, 24001)

    def sdof(fn, scale=1.0):
        r = f / fn
        return scale * 1e-5 / np.abs(1 - r**2 + 2j * 0.05 * r)

    def criticals(amp):
        unb = UnbalanceResponse(2 * np.pi * f, np.ones_like(f), amp, 0.0, 0.0, 1.0, 1.0)
        return critical_speeds(unb, 90.0, 140.0)

    twin = np.maximum(sdof(100.0), sdof(100.3, 1 - 1e-4))
    assert len(find_peaks(twin)[0]) == 2  # the rounding this guards against
    (c,) = criticals(twin)
    assert c["speed_hz"] == pytest.approx(100.0 * math.sqrt(1 - 2 * 0.05**2), abs=0.01)
    assert c["af"] == pytest.approx(10.0, rel=0.1)
    pair = criticals(np.maximum(sdof(100.0), sdof(130.0)))
    assert [round(c["speed_hz"]) for c in pair] == [100, 130]
    assert all(c["af"] == pytest.approx(10.0, rel=0.1) for c in pair)


def test_a_separation_margin_on_its_requirement_is_named_on_the_boundary():
    """Reference: a single-degree-of-freedom resonance 1/|1 − r² + 2jζr| at 100 Hz, ζ 0.05
    (AF = 1/(2ζ) = 10 to the order ζ), against API 617's margin above the continuous range
    by hand, 10 + 17(1 − 1/(AF − 1.5)) % = 25 %. With the range's top set so that the
    critical's margin is the requirement ×(1 ± 5e-4) — within the 0.1 % to which the
    judgement resolves the two — it is named, and the verdict says it lies on the
    boundary, met or not; ×(1 + 2e-3) it is separated and not named, ×(1 − 2e-3) it is
    short and named as short."""
    from ambseal.analysis.judge import critical_speeds
    from ambseal.analysis.unbalance import UnbalanceResponse
    from ambseal.report.verdict import verdicts

    f = np.linspace(40.0, 160.0, 24001)
    r = f / 100.0
    amp = 1e-5 / np.abs(1 - r**2 + 2j * 0.05 * r)
    unb = UnbalanceResponse(2 * np.pi * f, np.ones_like(f), amp, 0.0, 0.0, 1.0, 1.0)
    (inside,) = critical_speeds(unb, 90.0, 110.0)
    need, n = inside["required_pct"], inside["speed_hz"]
    assert need == pytest.approx(10 + 17 * (1 - 1 / (10 - 1.5)), rel=0.01)

    def at(factor):
        return critical_speeds(unb, 50.0, n / (1 + need * factor / 100))

    assert at(1 + 2e-3) == []
    base = {"controller": "LPV", "pressure_bar": 0.0, "speed_hz": 60.0, "stable": True,
            "sensitivity_peak": 2.0, "sensitivity_peak_per_axis": {"A_zeta": 2.0},
            "iso_zone": "A", "iso_zone_per_axis": {"A_zeta": "A"}}
    for factor in (1 + 5e-4, 1 - 5e-4):
        (c,) = at(factor)
        assert c["margin_pct"] == pytest.approx(need * factor, rel=1e-9)
        words = verdicts([dict(base, critical_speeds=[c])])[0].words()
        assert (f"{c['margin_pct']:.4g} % from the continuous speed range, on the boundary "
                f"of the {need:.4g} % API 617 requires") in words, words
    (short,) = at(1 - 2e-3)
    words = verdicts([dict(base, critical_speeds=[short])])[0].words()
    assert "where API 617 requires 25 %" in words and "boundary" not in words
