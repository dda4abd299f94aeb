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
