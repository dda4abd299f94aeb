"""API 617's unbalance response: U_r, A_vl and the separation margins against hand
calculations, and a rigid rotor on damped springs against its single-degree-of-freedom
closed form (AF = 1/(2ζ), the peak U·ω_n/c)."""

from __future__ import annotations

import math
import tomllib

import numpy as np
import pytest

from ambseal.analysis.signoff.unbalance_api617 import (
    amplification_factor,
    api617_unbalance,
    journal_loads,
    required_margin,
    unbalance_ur,
    vibration_limit_um,
)
from ambseal.config import parse_rig
from ambseal.errors import ConfigError

from .test_analysis_level1 import _rigid_rotor


def test_unbalance_ur_by_hand():
    """U_r = 6350·W/N g·mm: 100 kg at 10 000 rpm is 63.5 g·mm; in US units 4·W/N oz·in
    (W in lb): 220.46 lb → 0.088 oz·in = 63.5 g·mm (1 oz·in = 720.08 g·mm)."""
    assert unbalance_ur(100.0, 10000.0) == pytest.approx(63.5e-6)
    assert unbalance_ur(100.0, 10000.0) * 1e6 == pytest.approx(
        4 * 220.462 / 10000.0 * 720.078, rel=1e-3)
    # from 25 000 rpm on, W/3.937 g·mm (API 617 9th ed. 6.8.2.7, as ROSS 3.1)
    for rpm in (25000.0, 60000.0):
        assert unbalance_ur(100.0, rpm) == pytest.approx(100.0 / 3.937 * 1e-6, rel=1e-4)


@pytest.mark.parametrize("rpm, um", [(12000.0, 25.4), (3000.0, 25.4),
                                     (20000.0, 25.4 * math.sqrt(0.6))])
def test_vibration_limit_by_hand(rpm, um):
    assert vibration_limit_um(rpm) == pytest.approx(um)


@pytest.mark.parametrize("af, below, above", [
    (2.4, 0.0, 0.0), (4.0, 10.2, 20.2), (30.0, 16.0, 26.0),
])
def test_required_separation_margins_by_hand(af, below, above):
    """17(1 − 1/(AF − 1.5)) below the minimum speed (≤ 16 %), 10 more above the maximum
    (≤ 26 %); none under AF 2.5."""
    assert required_margin(af, True) == pytest.approx(below)
    assert required_margin(af, False) == pytest.approx(above)


def test_half_power_af_of_a_sampled_resonance():
    """A single-degree-of-freedom amplitude 1/|1 − r² + 2jζr| sampled finely: AF = 1/(2ζ)
    to the order ζ."""
    import numpy as np

    zeta = 0.02
    r = np.linspace(0.5, 1.5, 20001)
    amp = 1 / np.abs(1 - r**2 + 2j * zeta * r)
    af, n1, n2 = amplification_factor(r, amp, int(np.argmax(amp)))
    assert af == pytest.approx(1 / (2 * zeta), rel=2 * zeta) and n1 < 1 < n2


def test_journal_loads_with_cross_coupled_supports_are_the_statics():
    """Two supports with cross-coupled stiffness (kxy = kyx = 0.4 kyy, a tilting-pad
    bearing's) under the symmetric rotor: the weight sags it in x too, and each journal
    carries m/2 — the vertical force kyx·x + kyy·y (reading kyy·y alone had taken part of
    it for the x sag's)."""
    doc = tomllib.loads(_rigid_rotor(1e7, 2000.0, 4.5e4))
    for sp in doc["spring"]:
        sp["kxy"] = sp["kyx"] = 0.4 * sp["kyy"]
    m = math.pi / 4 * 0.2**2 * 0.4 * 7850.0
    assert [w for _, w in journal_loads(parse_rig(doc))] == pytest.approx([m / 2, m / 2],
                                                                          rel=1e-3)


def test_rigid_rotor_on_damped_springs_is_the_closed_form():
    """The rotor of the Level I test (m ≈ 98.6 kg on k = 1e7 N/m, c = 2000 N·s/m, 3000 rpm
    continuous): journal loads m/2; the mid-span case 2·U_r with W = m; its critical at
    ω_n = √(k/m) with AF = 1/(2ζ) within 1 %, the peak 2·U·ω_n/c peak-to-peak within 1 %;
    the separation margin 100·(N_c − N)/N against the required min(26, 10 + 17(1 −
    1/(AF − 1.5))); the vibration limit exceeded (133 µm > 25.4 µm)."""
    k, c = 1e7, 2000.0
    cfg = parse_rig(tomllib.loads(_rigid_rotor(k, c, 4.5e4)))
    m = math.pi / 4 * 0.2**2 * 0.4 * 7850.0
    loads = journal_loads(cfg)
    assert [w for _, w in loads] == pytest.approx([m / 2, m / 2], rel=1e-3)
    r = api617_unbalance(cfg)
    first = r.cases[0]
    (u,) = first.unbalances
    U = 2 * 6350e-6 * m / 3000.0
    assert u.position == pytest.approx(0.2) and u.amount == pytest.approx(U, rel=1e-3)
    (crit,) = first.criticals
    wn = math.sqrt(k / m)
    zeta = c / (2 * math.sqrt(k * m))
    assert crit.speed_hz == pytest.approx(wn / (2 * math.pi), rel=0.01)
    assert crit.af == pytest.approx(1 / (2 * zeta), rel=0.01)
    assert crit.amplitude_um == pytest.approx(2e6 * U * wn / c, rel=0.01)
    assert crit.actual_margin_pct == pytest.approx(100 * (crit.speed_hz - 50.0) / 50.0)
    assert crit.required_margin_pct == pytest.approx(required_margin(crit.af, False))
    assert not crit.passed and not r.separation_passed
    assert r.vibration_limit_um == 25.4 and not r.vibration_passed and not r.passed
    assert r.trip_hz == pytest.approx(1.05 * 50.0) and r.top_hz == pytest.approx(1.25 * 52.5)


@pytest.mark.parametrize("c", [2000.0, 500.0])
def test_the_critical_of_a_rigid_rotor_is_its_exact_closed_form(c):
    """The rotor of the test above with a shaft 1e4 times stiffer than steel (a rigid
    body to 1e-6): its mid-span unbalance U excites one degree of freedom, x = U ω²/(k −
    mω² + jωc). The critical's speed, its peak-to-peak amplitude and its half-power AF
    equal that closed form's, solved by SciPy (``minimize_scalar`` for the peak,
    ``brentq`` for the half-power speeds), to 1e-5; and AF = 1/(2ζ), the closed form's
    light-damping limit, within 0.1 % at ζ = 0.008 (c = 500 N·s/m; 0.4 % at ζ = 0.032,
    where the mass-excited peak moves by order ζ²). The sweep holds each speed once: the
    coarse grid's and the refinements' coinciding points (1.4e-16 apart) were both kept,
    and a peak sampled at such a twin was solved on one side only."""
    from scipy.optimize import brentq, minimize_scalar

    k = 1e7
    cfg = parse_rig(tomllib.loads(_rigid_rotor(k, c, 4.5e4).replace("E = 2.1e11",
                                                                     "E = 2.1e15")))
    r = api617_unbalance(cfg)
    sweep = r.cases[0].speed_hz
    assert np.all(np.diff(sweep) > 1e-9 * sweep[1:])
    (u,) = r.cases[0].unbalances
    m = math.pi / 4 * 0.2**2 * 0.4 * 7850.0
    wn, zeta = math.sqrt(k / m), c / (2 * math.sqrt(k * m))
    (crit,) = r.cases[0].criticals

    def amp(w):
        return abs(u.amount * w * w / (k - m * w * w + 1j * w * c))

    best = minimize_scalar(lambda w: -amp(w), bounds=(0.5 * wn, 1.5 * wn), method="bounded",
                           options={"xatol": 1e-10})
    wp, ap = best.x, amp(best.x)
    w1 = brentq(lambda w: amp(w) - ap / math.sqrt(2), 0.5 * wn, wp, xtol=1e-12)
    w2 = brentq(lambda w: amp(w) - ap / math.sqrt(2), wp, 2 * wn, xtol=1e-12)
    assert crit.speed_hz == pytest.approx(wp / (2 * math.pi), rel=1e-5)
    assert crit.amplitude_um == pytest.approx(2e6 * ap, rel=1e-5)
    assert crit.af == pytest.approx(wp / (w2 - w1), rel=1e-5)
    if zeta < 0.01:
        assert crit.af == pytest.approx(1 / (2 * zeta), rel=1e-3)


def test_close_clearance_is_the_scaled_response_against_its_fraction():
    """A seal of 0.3 mm radial clearance at mid-span of the same rotor: S_c = A_vl/A_1
    bounded to [0.5, 6] (A_1 the probes' largest amplitude to the trip speed), the seal's
    scaled response S_c × its own largest amplitude to the trip speed, allowed 75 % of
    the 0.6 mm diametral clearance."""
    import numpy as np

    doc = tomllib.loads(_rigid_rotor(1e8, 2.0e4, 4.5e4))
    doc["seal"] = [{"name": "eye", "position": 0.2, "clearance": 3e-4}]
    r = api617_unbalance(parse_rig(doc))
    c = r.cases[0]
    upto = c.speed_hz <= r.trip_hz + 1e-9
    a1 = c.probe_um[upto].max()
    sc = min(max(r.vibration_limit_um / a1, 0.5), 6.0)
    assert c.scale_factor == pytest.approx(sc)
    (k,) = c.clearances
    assert k.name == "eye" and k.diametral_um == pytest.approx(600.0)
    assert k.allowed_um == pytest.approx(450.0) and k.passed
    # at mid-span of the symmetric rotor the seal moves as much as the probes (rigid
    # cylindrical whirl far below its critical): its scaled response is S_c·A_1
    assert k.scaled_um == pytest.approx(sc * a1, rel=0.02)
    assert np.all(np.diff(c.speed_hz) > 0)


def test_scale_factor_over_the_continuous_range_without_a_floor_as_ross():
    """``[signoff] scale_factor_speeds = "continuous"`` and ``scale_factor_limits = [0,
    6]`` (ROSS 3.1's ``run_clearance_analysis``: A_1 from the minimum to the maximum
    continuous speed, no lower bound): on the rotor whose critical sits at its 3000 rpm
    (133 µm against A_vl 25.4 µm) S_c = A_vl/A_1 = 0.19, where the default (standstill to
    trip, at least 0.5) gives 0.5."""
    doc = tomllib.loads(_rigid_rotor(1e7, 2000.0, 4.5e4))
    doc["seal"] = [{"name": "eye", "position": 0.2, "clearance": 3e-4}]
    r = api617_unbalance(parse_rig(doc))
    assert r.cases[0].scale_factor == 0.5
    doc["signoff"] = {"scale_factor_speeds": "continuous", "scale_factor_limits": [0.0, 6.0]}
    r = api617_unbalance(parse_rig(doc))
    c = r.cases[0]
    cont = (c.speed_hz >= r.min_hz - 1e-9) & (c.speed_hz <= r.max_hz + 1e-9)
    want = r.vibration_limit_um / c.probe_um[cont].max()
    assert c.scale_factor == pytest.approx(want, rel=1e-12) and want < 0.25


def test_directional_probes_read_the_closed_form_of_anisotropic_supports(monkeypatch):
    """The symmetric rigid rotor on two springs of k_x = 5e6, k_y = 1e7 N/m and c = 1000
    N·s/m each, its unbalance U at mid-span: the translation only is excited, x =
    U ω²/(2k_x − mω² + 2jωc), y = −j U ω²/(2k_y − mω² + 2jωc) (the force U ω² e^{jωt}
    turning forward). ``[signoff] probes`` at mid-span read at 0°, 90° and 45° give 2|x|,
    2|y| and 2|x + y|/√2 peak to peak at every speed of the sweep, to 1e-5.

    Each critical's peak and half-power points are solved on the response itself, a speed
    at a time (``exact_half_power``: some 50 evaluations each); the rotor, its bearings and
    seals are assembled once for the sweep and once per case and probe whose peaks are
    searched: at most 1 + cases × 3 assemblies, against some 60 000 when every evaluation
    assembled the FE model (40 s of this test)."""
    from ambseal.analysis import synchronous

    # the shaft 1e4 times stiffer than steel: its bending adds below 1e-6 at mid-span
    doc = tomllib.loads(_rigid_rotor(1e7, 2000.0, 4.5e4).replace("E = 2.1e11", "E = 2.1e15"))
    for sp in doc["spring"]:
        sp["kyy"] = 1e7
    doc["signoff"] = {"probes": [{"position": 0.2, "angle_deg": a} for a in (0.0, 90.0,
                                                                             45.0)]}
    built = []
    real = synchronous.build_system
    monkeypatch.setattr(synchronous, "build_system",
                        lambda *a, **k: built.append(1) or real(*a, **k))
    r = api617_unbalance(parse_rig(doc))
    c = r.cases[0]  # one unbalance at mid-span
    (u,) = c.unbalances
    assert u.position == pytest.approx(0.2)
    m = math.pi / 4 * 0.2**2 * 0.4 * 7850.0
    w = 2 * np.pi * c.speed_hz
    x = u.amount * w**2 / (1e7 - m * w**2 + 2j * w * 1000.0)
    y = -1j * u.amount * w**2 / (2e7 - m * w**2 + 2j * w * 1000.0)
    want = 2e6 * np.column_stack([np.abs(x), np.abs(y), np.abs(x + y) / math.sqrt(2)])
    np.testing.assert_allclose(c.probe_um, want, rtol=1e-5)
    assert sum(len(k.criticals) for k in r.cases) >= 2
    assert len(built) <= 1 + len(r.cases) * 3, len(built)


def test_a_plain_bearings_clearance_is_a_close_clearance_too():
    """The same rotor's two supports as springs with a 0.15 mm radial clearance each (a
    plain bearing's, ``[[spring]] clearance``): each is judged as the seal is above, S_c
    times its own largest response to the trip speed against 75 % of its 0.3 mm diametral
    clearance; at the supports of the rigid rotor the response is the probes' (they are
    the probes), so the scaled response is S_c·A_1."""
    doc = tomllib.loads(_rigid_rotor(1e8, 2.0e4, 4.5e4))
    for sp in doc["spring"]:
        sp["clearance"] = 1.5e-4
    r = api617_unbalance(parse_rig(doc))
    c = r.cases[0]
    upto = c.speed_hz <= r.trip_hz + 1e-9
    a1 = c.probe_um[upto].max()
    assert len(c.clearances) == 2
    for k in c.clearances:
        assert k.diametral_um == pytest.approx(300.0) and k.allowed_um == pytest.approx(225.0)
        assert k.scaled_um == pytest.approx(c.scale_factor * a1, rel=1e-6)


def test_synchronous_response_with_the_loop_as_it_runs_is_the_judged_sampled_loop():
    """The overhung compressor's PID as it runs, a rotating unbalance at the impeller at
    100 Hz: the orbit at AMB A's sensor from the dynamic stiffness closed by
    K_d(e^{jΩT})·ZOH equals the one from the judged loop's path (the full-order plant
    sampled by a zero-order hold, the force sampled with it, S_o·G_f by python-control's
    frequency response of the controller) within 0.5 %."""
    import math

    import numpy as np

    from ambseal.analysis.judge import operating_points
    from ambseal.analysis.synchronous import (
        Unbalance,
        orbit_semi_major,
        synchronous_response,
    )
    from ambseal.app.commands import digital_for
    from ambseal.config import load_rig
    from ambseal.design import design, design_spec
    from ambseal.lti import freqresp_at, shared_ss, wired
    from ambseal.machine import controller_as_runs, judged_loop
    from ambseal.model import build_plant

    cfg = load_rig("examples/overhung_compressor.toml")
    spec = design_spec(cfg)
    res = design(cfg, "pid", spec=spec)
    K = digital_for(cfg, "pid", res.K, res, operating_points(spec))
    f, U, z = 100.0, 1e-4, 0.82
    w = 2 * math.pi * f
    ours = synchronous_response(cfg, K, [f], [[Unbalance(z, U)]],
                                [cfg.amb[0].sensor_position]).amplitude_m[0, 0, 0]
    plant = build_plant(cfg, speed_rpm=60 * f, force_positions=(z,))
    P = plant.to_statespace()
    cur = list(plant.current_inputs())
    Kd = controller_as_runs(K, w)
    judged = judged_loop(P, Kd, cur)
    Pw = judged.plant_response(np.array([w]))[0]
    G, Gf = Pw[:, cur], Pw[:, [j for j in range(P.ninputs) if j not in cur]]
    named = shared_ss(np.zeros((0, 0)), np.zeros((0, len(cur))),
                      np.zeros((P.noutputs, 0)), np.zeros((P.noutputs, len(cur))),
                      inputs=[P.input_labels[j] for j in cur], outputs=list(P.output_labels))
    Kw = freqresp_at(wired(named, Kd), [np.exp(1j * w * float(Kd.dt))])[0]
    So = np.linalg.inv(np.eye(G.shape[0]) + G @ Kw)
    y = So @ Gf @ (U * w**2 * np.array([1.0, -1j]))
    names = list(P.output_labels)
    a = f"y_{cfg.amb[0].name}"
    yz, ye = y[names.index(f"{a}_zeta")], y[names.index(f"{a}_eta")]
    assert ours == pytest.approx(float(orbit_semi_major(yz, ye)), rel=5e-3)
    # the coil currents i = H_a(jΩ)·(−K_r S_o G_f F) of the same path, per axis
    from ambseal.model import actuator_matrices
    hold = np.exp(-0.5j * w * float(Kd.dt)) * np.sinc(w * float(Kd.dt) / (2 * math.pi))
    r = synchronous_response(cfg, K, [f], [[Unbalance(z, U)]], [z])
    ha = freqresp_at(actuator_matrices(cfg.actuator), [1j * w])[0, 0, 0]
    coil = -ha * hold * (Kw @ y)
    np.testing.assert_allclose(r.current_a[0, 0], np.abs(coil), rtol=5e-3)
    assert r.axes == tuple(P.input_labels[j] for j in cur)


def test_synchronous_force_is_the_force_law_at_the_actuator():
    """With each sensor at its actuator (the same node and axes), the force an AMB axis
    transmits is the force law K_i·H_e·i + K_s·x with x the sensor's reading: from the
    response's own currents and the orbit's phasors read through python-control's
    frequency response of the loop (the judged path), to 0.5 %."""
    import math

    import numpy as np

    from ambseal.analysis.judge import operating_points
    from ambseal.analysis.synchronous import Unbalance, synchronous_response
    from ambseal.app.commands import digital_for
    from ambseal.config import load_rig
    from ambseal.design import design, design_spec
    from ambseal.lti import freqresp_at, shared_ss, wired
    from ambseal.machine import controller_as_runs, judged_loop
    from ambseal.model import actuator_matrices, amb_factors, build_plant, eddy_lag_matrices

    cfg = load_rig("examples/overhung_compressor.toml")
    # its PID, designed and discretised on the rig, then closed on the rig with each
    # sensor moved to its actuator: a frequency response needs no stable loop
    spec = design_spec(cfg)
    res = design(cfg, "pid", spec=spec)
    K = digital_for(cfg, "pid", res.K, res, operating_points(spec))
    cfg = cfg.model_copy(update={"amb": [a.model_copy(update={"sensor_position": a.position})
                                         for a in cfg.amb]})
    f, U, z = 100.0, 1e-4, 0.82
    w = 2 * math.pi * f
    r = synchronous_response(cfg, K, [f], [[Unbalance(z, U)]], [z])
    plant = build_plant(cfg, speed_rpm=60 * f, force_positions=(z,))
    P = plant.to_statespace()
    cur = list(plant.current_inputs())
    Kd = controller_as_runs(K, w)
    Pw = judged_loop(P, Kd, cur).plant_response(np.array([w]))[0]
    G, Gf = Pw[:, cur], Pw[:, [j for j in range(P.ninputs) if j not in cur]]
    named = shared_ss(np.zeros((0, 0)), np.zeros((0, len(cur))),
                      np.zeros((P.noutputs, 0)), np.zeros((P.noutputs, len(cur))),
                      inputs=[P.input_labels[j] for j in cur], outputs=list(P.output_labels))
    Kw = freqresp_at(wired(named, Kd), [np.exp(1j * w * float(Kd.dt))])[0]
    y = np.linalg.solve(np.eye(G.shape[0]) + G @ Kw, Gf @ (U * w**2 * np.array([1.0, -1j])))
    hold = np.exp(-0.5j * w * float(Kd.dt)) * np.sinc(w * float(Kd.dt) / (2 * math.pi))
    ha, he = (freqresp_at(m, [1j * w])[0, 0, 0] for m in (
        actuator_matrices(cfg.actuator), eddy_lag_matrices(cfg.actuator.eddy_time_constant)))
    coil = -ha * hold * (Kw @ y)
    for a, name in enumerate(r.axes):
        amb, ax = name.removeprefix("i_").rsplit("_", 1)
        (ki, ks) = (v[("zeta", "eta").index(ax)]
                    for v in amb_factors(next(b for b in cfg.amb if b.name == amb)))
        x = y[list(P.output_labels).index(f"y_{amb}_{ax}")]
        assert r.force_n[0, 0, a] == pytest.approx(abs(ki * he * coil[a] + ks * x), rel=5e-3)


@pytest.mark.parametrize("offset", [0.0, 0.001, 0.003, 0.005])
def test_exact_half_power_of_a_closed_form_resonance(offset):
    """A rotating unbalance on a single degree of freedom, X(r) = r²/|1 − r² + 2jζr|
    (ζ = 0.5 %), swept at 241 points from standstill to 1.5× its natural frequency (the
    sweep shifted by ``offset``, so that the sampled peak falls on either side of the true
    one and a half-power point within one step of it): the peak and half-power points
    solved on X itself (scipy's root finders on the closed form here) to 1e-6 — read off
    the sweep, AF was more than 1 % off."""
    import numpy as np
    from scipy.optimize import brentq, minimize_scalar

    from ambseal.analysis.signoff.unbalance_api617 import exact_half_power

    zeta = 0.005

    def x(r):
        return r**2 / abs(1 - r**2 + 2j * zeta * r)

    r = np.linspace(0.0, 1.5, 241) + offset
    amp = np.array([x(v) for v in r])
    i = int(np.argmax(amp))
    pk = minimize_scalar(lambda v: -x(v), bounds=(0.9, 1.1), method="bounded",
                         options={"xatol": 1e-12})
    rc, xc = float(pk.x), -float(pk.fun)
    n1 = brentq(lambda v: x(v) - xc / np.sqrt(2), 0.9, rc, xtol=1e-14)
    n2 = brentq(lambda v: x(v) - xc / np.sqrt(2), rc, 1.1, xtol=1e-14)
    nc, ac, af, m1, m2 = exact_half_power(x, r, amp, i)
    np.testing.assert_allclose([nc, ac, af, m1, m2], [rc, xc, rc / (n2 - n1), n1, n2],
                               rtol=1e-6)
    sampled, _, _ = amplification_factor(r, amp, i)
    assert abs(sampled / af - 1) > 1e-3


def test_the_criticals_are_the_responses_own_peaks():
    """The rigid rotor on lightly damped springs (c = 200 N·s/m, ζ 0.3 %): each critical
    of the sign-off is the peak of the synchronous response solved on that response
    (scipy's bounded Brent on the same case and probe, here), its amplitude and AF to
    1e-6, not the sweep's sample."""
    import numpy as np
    from scipy.optimize import brentq, minimize_scalar

    from ambseal.analysis import synchronous_response

    cfg = parse_rig(tomllib.loads(_rigid_rotor(1e7, 200.0, 4.5e4)))
    case = api617_unbalance(cfg).cases[0]
    (crit,) = case.criticals

    def x(f):
        r = synchronous_response(cfg, None, [f], [case.unbalances], [crit.probe_m])
        return 2e6 * float(r.amplitude_m[0, 0, 0])

    f0 = crit.speed_hz
    pk = minimize_scalar(lambda f: -x(f), bounds=(0.98 * f0, 1.02 * f0), method="bounded",
                         options={"xatol": 1e-9 * f0})
    fc, xc = float(pk.x), -float(pk.fun)
    n1 = brentq(lambda f: x(f) - xc / np.sqrt(2), 0.9 * fc, fc, xtol=1e-10 * fc)
    n2 = brentq(lambda f: x(f) - xc / np.sqrt(2), fc, 1.1 * fc, xtol=1e-10 * fc)
    np.testing.assert_allclose([crit.speed_hz, crit.amplitude_um, crit.af],
                               [fc, xc, fc / (n2 - n1)], rtol=1e-6)


def test_a_vertical_rotors_unbalance_is_apportioned_as_if_horizontal(tmp_path):
    """The rotor of the closed-form test stood on end: its journals carry no gravity
    load, yet by ``[signoff] journal_load = "as_horizontal"`` (the default) its journal
    loads and the mid-span unbalance are the horizontal rotor's by hand, W = m/2 each and
    2·6350·m/N at mid-span; the report's sign-off section states the rule. Asked for
    gravity as it acts, the sign-off refuses the vertical rotor by the key's name."""
    from ambseal.analysis import sign_off
    from ambseal.report import signoff_report

    m = math.pi / 4 * 0.2**2 * 0.4 * 7850.0
    doc = tomllib.loads(_rigid_rotor(1e7, 2000.0, 4.5e4))
    doc["machine"] = {"orientation": "vertical"}
    cfg = parse_rig(doc)
    assert [w for _, w in journal_loads(cfg)] == pytest.approx([m / 2, m / 2], rel=1e-3)
    r = api617_unbalance(cfg)
    (u,) = r.cases[0].unbalances
    assert u.amount == pytest.approx(2 * 6350e-6 * m / 3000.0, rel=1e-3)
    assert "as if it lay horizontal" in r.to_dict()["journal_load_rule"]
    _, sections = signoff_report(tmp_path, [sign_off(cfg, name="none")], "vertical")
    rule = "weight apportioned to its bearings by static equilibrium as if it lay horizontal"
    assert rule in sections[0]["html"]
    doc["signoff"] = {"journal_load": "as_acting"}
    with pytest.raises(ConfigError, match="journal_load"):
        sign_off(parse_rig(doc), name="none")
