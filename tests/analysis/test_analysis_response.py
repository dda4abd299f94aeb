"""Tests of ambseal.analysis.response: the P5 §5.1 current impulse, exact ZOH simulation."""

from __future__ import annotations

import json
import math

import control
import numpy as np
import pytest

from ambseal.analysis import loops, response
from ambseal.machine.loop import closed_loop
from ambseal.errors import ModelError

from .amb_test_plants import NAMES, mass_1dof, rigid_rotor


def _first_order(a=100.0, b=1000.0, kp=1.0):
    G = control.ss([[a]], [[b]], [[1.0]], [[0.0]], inputs=["A_zeta"], outputs=["A_zeta"])
    K = control.ss(np.zeros((0, 0)), np.zeros((0, 1)), np.zeros((1, 0)), [[kp]],
                   inputs=["A_zeta"], outputs=["A_zeta"])
    return G, K, b * kp - a


@pytest.mark.parametrize("t_imp", [0.0, 0.05])
def test_first_order_peak_and_settling_closed_form(t_imp):
    """Reference: closed form for ẋ = a x + b(−kp x + d), p = b kp − a, pulse A0 for T:
    peak x(T) = b A0 (1 − e^{−pT}) / p, and the 2 % settling time from the pulse start is
    T + ln(50)/p (x decays as x(T) e^{−p(t−T)} after the pulse)."""
    G, K, p = _first_order()
    A0, T = 0.05, 0.01
    r = response.impulse_response(G, K, channels=["A_zeta"], amplitude_a=A0, duration_s=T,
                                  t_impulse_s=t_imp, t_end_s=t_imp + 0.05)
    xT = 1000.0 * A0 * (1 - math.exp(-p * T)) / p
    assert r.peak_displacement_um == pytest.approx(xT * 1e6, rel=1e-9)
    assert r.settling_time_s == pytest.approx(T + math.log(50.0) / p, abs=1e-7)
    assert r.settled and r.stable
    k = np.searchsorted(r.time_s, t_imp + 0.004 - 1e-12)
    x_ref = 1000.0 * A0 * (1 - math.exp(-p * 0.004)) / p  # during the pulse, exact at samples
    assert r.displacement_m[k, 0] == pytest.approx(x_ref, rel=1e-9)
    np.testing.assert_allclose(r.current_a[:, 0], -r.displacement_m[:, 0])  # i = −kp y, kp = 1


@pytest.mark.parametrize(("kp", "t_end_s", "beyond"), [(0.105, 0.05, True),
                                                        (1.0, 0.012, False)])
def test_a_response_that_does_not_settle_says_why(kp, t_end_s, beyond):
    """Reference: the closed form of the first-order loop above — its one pole at
    −p = a − b kp, the 2 % settling time T + ln(50)/p after a pulse of length T. Where that
    lies beyond the simulated window the settling time is inf, and the note names the
    window and the pole with its own 2 % decay time ln(50)/p, "beyond that window" when
    that alone exceeds the window (p = 5 rad/s: 782 ms in 50 ms; p = 900 rad/s: 4.35 ms
    after a 10 ms pulse, in 12 ms); a response that settles has no note."""
    G, K, p = _first_order(kp=kp)
    r = response.impulse_response(G, K, channels=["A_zeta"], amplitude_a=0.05, duration_s=0.01,
                                  t_impulse_s=0.0, t_end_s=t_end_s)
    assert 0.01 + math.log(50.0) / p > t_end_s  # the closed form settles after the window
    assert r.stable and not r.settled and r.settling_time_s == math.inf
    decay = math.log(50.0) / p
    pole = (f"its slowest pole, at −{p:.3g} rad/s, decays to 2 % in "
            f"{decay * 1e3:.3g} ms")
    window = f"not settled within the {t_end_s * 1e3:.3g} ms simulated after the impulse"
    assert r.settling_note == (f"{window}: {pole}, beyond that window" if beyond
                               else f"{window} ({pole})")
    longer = response.impulse_response(G, K, channels=["A_zeta"], amplitude_a=0.05,
                                       duration_s=0.01, t_impulse_s=0.0, t_end_s=1.0)
    assert longer.settling_time_s == pytest.approx(0.01 + decay, abs=1e-7)
    assert longer.settling_note is None


def test_the_judged_case_says_why_its_response_did_not_settle():
    """Reference: python-control's closed loop of the rig's full-order plant (at the
    judged condition) with the PID and the target's delay lag — its slowest pole is the
    one the case's note names. A PID with T_i = 0.3 s on the coil rig, judged with a 1 ms
    impulse (the window 30 impulse lengths: 30 ms after it): its response has not settled
    when the window ends; metrics.json's case keeps no settling time and says why."""
    import tomllib

    from ambseal.analysis.judge import OperatingPoint, judge, judge_settings
    from ambseal.config import parse_rig
    from ambseal.design import design, design_spec
    from ambseal.model.rig import build_plant
    from ambseal.robust import loop_delay

    from ..coil_rig import COIL_RIG

    doc = tomllib.loads(COIL_RIG)
    doc["controller"] = {"pid": {"kp": 9000.0, "ti": 0.3, "td": 0.0039, "eps": 0.115},
                         "filter": [{"kind": "notch", "frequency_hz": 1266.44,
                                     "width_hz": 126.644, "depth_db": 20.0}]}
    doc["design"] = {"impulse": {"duration_s": 1e-3}}
    cfg = parse_rig(doc)
    K = design(cfg, "pid").controller
    case, curves = judge(cfg, K, "pid", OperatingPoint(0.0, 30000.0, "0 bar"),
                         judge_settings(design_spec(cfg)))
    P = build_plant(cfg, speed_rpm=30000.0).to_statespace()
    cur = [n for n in P.input_labels if n.startswith("i_")]
    lag = loop_delay(cfg.controller.sample_rate_hz, cfg.controller.delay_samples).system
    G = P[list(P.output_labels), cur]
    L = control.append(*[lag] * len(cur)) * K[cur, list(P.output_labels)]
    sigma = control.feedback(G, L).poles().real.max()
    assert case.stable and case.impulse_settling_s is None
    decay = math.log(50.0) / -sigma
    assert case.impulse_settling_note == (
        f"not settled within the 30 ms simulated after the impulse: its slowest pole, at "
        f"−{-sigma:.3g} rad/s, decays to 2 % in {decay * 1e3:.3g} ms, beyond that window")
    assert case.to_dict()["impulse_settling_note"] == case.impulse_settling_note
    assert curves["impulse"].settling_note == case.impulse_settling_note


def test_1dof_pd_matches_python_control_forced_response():
    """Reference: control.forced_response run side by side on control.feedback(G, K) with the
    same pulse (P5 §5.1: 0.05 A, 10 ms); python-control interpolates the input linearly between
    samples, so the pulse edges differ by one step: agreement to 0.3 % of the peak."""
    G, K, _, _ = mass_1dof()
    r = response.impulse_response(G, K, channels=["A_zeta"], t_end_s=0.06)
    t = r.time_s
    d = np.where(t < 0.01 - 1e-12, 0.05, 0.0)
    ref = control.forced_response(control.feedback(G, K, sign=-1), t, d).outputs
    assert np.max(np.abs(r.displacement_m[:, 0] - ref)) < 3e-3 * np.max(np.abs(ref))


def test_rigid_rotor_thesis_impulse_channels_and_json():
    """Reference: P5 §5.1 / Fig. 14 set-up — 0.05 A for 10 ms on A_ζ and B_η at once; the
    disturbance record and channel names follow the plant's; cross-checked peak against
    control.forced_response on the closed loop (1 % of peak, edge interpolation)."""
    G, Gf, K = rigid_rotor()
    r = response.impulse_response(G, K, channels=("A_zeta", "B_eta"), t_end_s=0.1)
    assert r.channels == ("A_zeta", "B_eta")
    assert r.output_names == tuple(NAMES) and r.input_names == tuple(NAMES)
    assert r.disturbance_a[:1000, 0].max() == 0.05 and r.disturbance_a[:, 1].max() == 0.0
    assert r.displacement_m.shape == (10001, 4) and r.current_a.shape == (10001, 4)
    cl = closed_loop(G, K)
    d = np.zeros((4, r.time_s.size))
    d[[0, 3], :] = np.where(r.time_s < 0.01 - 1e-12, 0.05, 0.0)
    ref = control.forced_response(control.feedback(G, K, sign=-1), r.time_s, d).outputs
    assert r.peak_displacement_um == pytest.approx(np.abs(ref).max() * 1e6, rel=1e-2)
    assert r.stable and r.settled and 0.01 < r.settling_time_s < 0.1
    assert r.max_real_pole == pytest.approx(cl.max_real_pole)
    dd = json.loads(json.dumps(r.to_dict()))
    assert set(dd["settling_per_channel_s"]) == set(NAMES)


def test_unstable_loop_is_flagged_not_crashed():
    """Reference: kp ki < ks gives a positive real pole (see loops tests); the result must carry
    stable=False, settling inf ("inf" in JSON), and a finite-or-NaN record without raising."""
    G, K, _, _ = mass_1dof(kp_factor=0.5)
    r = response.impulse_response(G, K, channels=["A_zeta"], t_end_s=0.5)
    assert not r.stable and not r.settled and math.isinf(r.settling_time_s)
    assert r.to_dict()["settling_time_s"] == "inf"
    json.dumps(r.to_dict())


def test_settling_time_helper():
    """Reference: closed form — y = e^{−t} leaves the 2 % band at ln 50; never-leaving → 0;
    outside at the end → inf."""
    t = np.linspace(0.0, 10.0, 100001)
    assert response.settling_time(t, np.exp(-t)) == pytest.approx(math.log(50.0), abs=1e-6)
    assert response.settling_time(t, np.zeros_like(t)) == 0.0
    assert math.isinf(response.settling_time(t, np.exp(-t / 10)))


def test_bad_arguments_raise():
    """Reference: interface contract — pulse times must be multiples of dt and fit the window;
    channels must be plant inputs."""
    G, K, _ = _first_order()
    with pytest.raises(ModelError):
        response.impulse_response(G, K, channels=["A_zeta"], dt_s=3e-5)
    with pytest.raises(ModelError):
        response.impulse_response(G, K, channels=["B_eta"])
    with pytest.raises(ModelError):
        response.impulse_response(G, K, channels=["A_zeta"], t_end_s=0.005)
