"""The identification's test conditions come from the rig, and a non-physical seal fit is
never designed on (ambseal.identify.fitting.procedure.seal_test_pressures,
ambseal.identify.facility.design_model.non_physical / design_rig, rig_sim.facility_bias_current).

References: the rules as written; the thesis's own test pressures (0.5–2.5 bar at a nominal
2.04 bar, P5 §3.3) as the case the rule reproduces to 2 %; a linear regression of
``ambseal.identify.fitting.stats.linear_regression`` through chosen points as the seal fit."""

from __future__ import annotations

from pathlib import Path
from types import SimpleNamespace

import pytest

from ambseal.config import Affine, TruthSection, default_rig_path, load_rig, rig_with_values
from ambseal.errors import ConfigError
from ambseal.identify.facility.design_model import design_rig, non_physical
from ambseal.identify.fitting.procedure import seal_test_pressures
from ambseal.identify.facility.rig_sim import facility_bias_current
from ambseal.identify.fitting.stats import linear_regression

ROOT = Path(__file__).resolve().parents[2]


def test_seal_test_pressures_scale_with_the_rig():
    """A quarter to 1.25× the nominal pressure drop in quarters: the embedded rig's are the
    thesis's 0.5–2.5 bar within 2 %; the manual's 30-bar compressor is tested at 7.5–37.5
    bar, not at the thesis's 0.5–2.5; a rig at 0 bar and no judged pressure is refused."""
    rig = load_rig(default_rig_path())
    got = seal_test_pressures(rig)
    assert got == pytest.approx((0.51, 1.02, 1.53, 2.04, 2.55))
    assert got == pytest.approx((0.5, 1.0, 1.5, 2.0, 2.5), rel=0.021)
    comp = load_rig(ROOT / "docs" / "rigs" / "compressor.toml")
    assert seal_test_pressures(comp) == pytest.approx((7.5, 15.0, 22.5, 30.0, 37.5))
    none = load_rig(default_rig_path(), ("design.pressures_bar=[0.0]",))
    none = none.model_copy(update={"operating": none.operating.model_copy(
        update={"pressure_bar": 0.0})})
    with pytest.raises(ConfigError, match="pressure_bar"):
        seal_test_pressures(none)


def test_facility_bias_current_is_the_truths_else_the_rigs():
    """The pump's AMBs are biased at 5 A: a truth file that does not say otherwise gets
    5 A, not the thesis rig's 6 A; one that says 4 A gets 4 A."""
    pump = load_rig(ROOT / "examples" / "pump.toml")
    assert facility_bias_current(pump, TruthSection()) == 5.0
    assert facility_bias_current(pump, TruthSection(bias_current=4.0)) == 4.0


def _result(cfg, c_points):
    """A procedure result whose seal C regression runs through ``c_points`` [(bar, N·s/m)]
    and whose other fits hold the rig file's values (so only the seal decides)."""
    x, y = zip(*c_points)
    reg = linear_regression(list(x), list(y), [1.0] * len(x))
    return SimpleNamespace(regression={"C": reg}, amb=None, coupling=None,
                           identified=cfg)


def test_a_seal_damping_line_that_turns_negative_is_not_designed_on():
    """The compressor case of the field: C = 294 − 121·p from tests at 0.5–2.5 bar is
    −3 350 N·s/m at 30 bar — energy fed by direct damping, which no annular seal does. It
    is named, and the rig designed on keeps the rig file's C (one identified value outside
    its interval makes the identified rig the design rig)."""
    comp = load_rig(ROOT / "docs" / "rigs" / "compressor.toml")
    seal = comp.seal[0].name
    bad = _result(comp, [(0.5, 294 - 121 * 0.5), (1.5, 294 - 121 * 1.5), (2.5, 294 - 121 * 2.5)])
    assert non_physical(comp, bad) == [f"{seal}.C"]
    good = _result(comp, [(7.5, 300.0), (22.5, 420.0), (37.5, 540.0)])
    assert non_physical(comp, good) == []
    identified = rig_with_values(comp, {f"{seal}.C": Affine(at_zero=294.0, per_bar=-121.0)})
    rig, note = design_rig(comp, replace_identified(bad, identified))
    assert note["designed_on"] == "identified rig" and note["non_physical"] == [f"{seal}.C"]
    assert f"{seal}.C.at_zero" in note["outside_intervals"]
    assert rig.seal[0].C == comp.seal[0].C != identified.seal[0].C


def replace_identified(res, identified):
    res.identified = identified
    return res


def test_stepped_sine_follows_the_rig():
    """The balanced-whirl stepped sine: f_top/20, then f_top/10 … f_top, f_top the larger of
    the PRBS's flat band (sample rate / 50) and 1.1× the top speed. The embedded rig (at rest,
    10 kHz) gets the thesis procedure's 10, 20, 40, …, 200 Hz (P4 §3.5.1: 5–200 Hz); the
    blower (20 kHz, to 600 Hz) reaches 660 Hz, past its top synchronous whirl."""
    from ambseal.identify.excitation.plan import excitation_plan

    assert excitation_plan(load_rig(default_rig_path())).sine_hz == (
        10.0, 20.0, 40.0, 60.0, 80.0, 100.0, 120.0, 140.0, 160.0, 180.0, 200.0)
    blower = excitation_plan(load_rig(ROOT / "examples" / "blower.toml")).sine_hz
    assert blower[0] == pytest.approx(33.0) and blower[-1] == pytest.approx(660.0)
    assert blower[1:] == pytest.approx([66.0 * k for k in range(1, 11)])


def test_records_at_the_speeds_the_rig_runs():
    """Reference: gyroscopic coupling. On the pump at 0 bar, a noise-free facility excited
    in ζ only: at rest the η axes do not move (the rotor and AMBs are axisymmetric, no seal
    force at 0 bar), at speed they do, first order in Ω (the η peak at 110 Hz is twice
    that at 55 Hz within 5 %). Each record carries its speed; a speed above the top of the
    rig's range is refused before any simulation."""
    import numpy as np

    from ambseal.app.commands import target_pid
    from ambseal.config import load_truth
    from ambseal.identify.excitation import signals
    from ambseal.identify.excitation.plan import excitation_plan
    from ambseal.identify.fitting.stages import acquire
    from ambseal.model.amb import channel_names

    cfg = load_rig(ROOT / "examples" / "pump.toml")
    quiet = load_truth(ROOT / "tests" / "data" / "pump_truth.toml").model_copy(
        update={"sensor_noise_m": 0.0, "noise_fraction": 0.0, "current_noise_a": 0.0,
                "adc_bits": None})
    plan, axes = excitation_plan(cfg), channel_names(cfg)
    ex = signals.impulse(amplitude_a=plan.amplitude_a, width_s=plan.impulse_s,
                         start_s=plan.impulse_start_s, duration_s=plan.impulse_record_s,
                         sample_rate_hz=cfg.controller.sample_rate_hz, axes=axes,
                         excited={"A_zeta": 1.0, "B_zeta": 1.0})
    K = target_pid(cfg)
    eta = [axes.index("A_eta"), axes.index("B_eta")]
    peaks = {}
    for f in (0.0, 55.0, 110.0):
        m = acquire(cfg, quiet, ex, controller=K, pressure_bar=0.0, speed_hz=f)
        assert m.metadata["speed_rad_s"] == pytest.approx(2 * np.pi * f)
        y = np.abs(np.asarray(m.displacement_m))
        peaks[f] = y[:, eta].max(axis=0)
        zeta_peak = y[:, axes.index("A_zeta")].max()
    assert np.all(peaks[0.0] < 1e-9 * zeta_peak)
    assert np.all(peaks[110.0] > 1e-3 * zeta_peak)
    assert peaks[110.0] / peaks[55.0] == pytest.approx([2.0, 2.0], rel=0.05)
    with pytest.raises(ConfigError, match="standstill to 110 Hz"):
        acquire(cfg, quiet, ex, controller=K, pressure_bar=0.0, speed_hz=500.0)
