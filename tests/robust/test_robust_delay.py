"""Tests of ambseal.robust.delay (the digital controller's hold + computation delay as the
design model and the continuous judgement carry it) and of its use in the designs."""

from __future__ import annotations

import numpy as np
import pytest

from ambseal.robust.delay import design_delay
from ambseal.errors import ConfigError
from ambseal.lti.freqresp import freqresp


def test_pade_equals_its_closed_form_and_the_order_follows_the_rule():
    """Reference: the Padé approximants of e^{−sτ} in closed form (Golub & Van Loan §11.3;
    Franklin, Powell & Workman §5.3): order 1 ``(1 − sτ/2)/(1 + sτ/2)``, order 2
    ``(12 − 6sτ + s²τ²)/(12 + 6sτ + s²τ²)``, phase ``−2 atan(ωτ/2)`` for order 1. At
    10 kHz with one sample of delay τ = 1.5/10 kHz = 150 µs; up to 2 kHz order 1 errs
    2 atan(0.94) − 1.885 rad = 21.5° (> 5°), so order 2 is taken; up to 500 Hz order 1
    errs 0.48°."""
    d = design_delay(10e3, 1, 2000.0)
    tau = 150e-6
    assert d.delay_s == pytest.approx(tau, rel=1e-15) and d.order == 2
    w = 2 * np.pi * np.array([10.0, 557.0, 2000.0, 8000.0])
    s = 1j * w
    ref = (12 - 6 * s * tau + (s * tau) ** 2) / (12 + 6 * s * tau + (s * tau) ** 2)
    np.testing.assert_allclose(freqresp(d.system, w)[:, 0, 0], ref, rtol=1e-12)
    assert d.phase_error_deg == pytest.approx(1.51, abs=0.01)
    d1 = design_delay(10e3, 1, 500.0)
    assert d1.order == 1
    x = 2 * np.pi * 500.0 * tau
    assert d1.phase_error_deg == pytest.approx(np.degrees(x - 2 * np.arctan(x / 2)), rel=1e-6)
    one = design_delay(10e3, 1, 2000.0, max_order=1)
    assert one.order == 1 and one.phase_error_deg == pytest.approx(
        np.degrees(2 * np.pi * 2000 * tau - 2 * np.arctan(np.pi * 2000 * tau)), rel=1e-4)
    # the hold alone (no computation delay) is half a sample
    assert design_delay(20e3, 0, 1000.0).delay_s == pytest.approx(25e-6, rel=1e-15)


@pytest.mark.parametrize("args", [(0.0, 1, 1e3), (1e4, -1, 1e3), (1e4, 1.5, 1e3),
                                  (1e4, 1, float("nan"))])
def test_bad_delay_inputs_are_refused(args):
    """A non-positive rate, a negative or fractional delay, a non-finite band: ConfigError
    naming the key."""
    with pytest.raises(ConfigError, match="controller|band"):
        design_delay(*args)


def test_generalized_plant_puts_the_delay_on_the_control_input_only(testrig_cfg):
    """Reference: the series interconnection ``i = D_u (L u + W_1 d_i)``, ``z_u = W_u u``
    (design/plant.py): the plant-side rows (z_p, y) of the columns from u equal L(jω)
    times those without the delay, the W_u rows and the disturbance columns are unchanged;
    the delay's states join P."""
    from ambseal.design.plant import generalized_plant
    from ambseal.design.weights import control_weight, performance_weight

    Wp, Wu = performance_weight(2.5, 2 * np.pi * 60.0), control_weight(1.0)
    d = design_delay(10e3, 1, 2000.0, max_order=1)
    g0 = generalized_plant(testrig_cfg, Wp, Wu)
    g1 = generalized_plant(testrig_cfg, Wp, Wu, actuator_delay=d.system)
    assert g1.P_nominal.nstates == g0.P_nominal.nstates + 4 * d.order
    w = 2 * np.pi * np.array([30.0, 557.0, 1500.0])
    H0, H1 = freqresp(g0.P_nominal, w), freqresp(g1.P_nominal, w)
    L = freqresp(d.system, w)[:, 0, 0]
    nu = g0.ncon
    zu = [i for i, lab in enumerate(g0.P_nominal.output_labels) if lab.startswith("zu_")]
    rest = [i for i in range(H0.shape[1]) if i not in zu]
    tol = dict(rtol=1e-8, atol=1e-10 * np.abs(H0).max())
    np.testing.assert_allclose(H1[:, rest, -nu:], H0[:, rest, -nu:] * L[:, None, None], **tol)
    np.testing.assert_allclose(H1[:, zu, -nu:], H0[:, zu, -nu:], **tol)
    np.testing.assert_allclose(H1[:, :, :-nu], H0[:, :, :-nu], **tol)


def test_continuous_judgement_with_the_delay_predicts_the_sampled_loop(testrig_digital,
                                                                      testrig_designs):
    """Reference: the exact ZOH sampling of the full-order plant with the discrete
    controller delayed by one sample (ambseal.robust.digital). With the hold +
    computation delay as a Padé lag in the continuous loop, the PID's continuous σ̄(S_o)
    peaks equal the sampled loop's to 1 % (13.36 vs 13.37 at 2.04 bar; without the delay
    they differed by 43–51 %), and the μ design, which carries the delay in its design
    model, to 2 %. The H∞ and μ designs record the delay they were made for: 150 µs."""
    for m, tol in (("pid", 0.01), ("mu", 0.02)):
        dc = testrig_digital[m]
        chosen = next(c for c in dc.candidates if c["method"] == dc.choice)
        assert chosen["sensitivity_peak_error"] < tol, (m, chosen["sensitivity_peak_error"])
    for m in ("hinf", "mu"):
        assert testrig_designs[m].delay["delay_s"] == pytest.approx(150e-6, rel=1e-12)
        assert testrig_designs[m].delay["pade_order"] == 1
