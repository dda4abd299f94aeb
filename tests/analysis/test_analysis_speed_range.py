"""Stability from standstill to the top speed (ambseal.analysis.speed_range and the rule of
ambseal.design.conditions.stability_speeds).

References: the rule as written (standstill, the operating speed, the range's ends, the top
in quarters), and python-control's own closed loop of the same plant and controller
(``control.feedback`` of the delayed plant; its poles by numpy) beside ours."""

from __future__ import annotations

from pathlib import Path

import control
import numpy as np
import pytest

from ambseal.analysis.judge import JudgeJob, OperatingPoint
from ambseal.analysis.speed_range import stability_case, stability_points
from ambseal.config import load_rig
from ambseal.design.conditions import STABILITY_STEPS, stability_speeds
from ambseal.design import design
from ambseal.model.rig import build_plant
from ambseal.robust.delay import loop_delay

ROOT = Path(__file__).resolve().parents[2]


def test_stability_speeds_follow_the_rule():
    """Standstill always; the compressor of the manual (9000 rpm, range 60–165 Hz): the
    operating speed, the range's ends and 165 Hz in quarters; a rig file's own list wins."""
    cfg = load_rig(ROOT / "docs" / "rigs" / "compressor.toml")
    speeds, rule = stability_speeds(cfg)
    top = 165.0
    want = {0.0, 150.0, 60.0, *(top * k / STABILITY_STEPS for k in range(1, STABILITY_STEPS + 1))}
    assert speeds == tuple(sorted(want)) and "standstill" in rule
    cfg = load_rig(ROOT / "docs" / "rigs" / "compressor.toml",
                   ("design.stability_speeds_hz=[0, 50]",))
    assert stability_speeds(cfg) == ((0.0, 50.0), "set")
    rig = load_rig(ROOT / "examples" / "testrig.toml")  # runs at standstill: nothing more
    assert stability_speeds(rig)[0] == (0.0,)


def test_stability_points_leave_out_the_judged_conditions():
    judged = [OperatingPoint(q, 60.0 * 150.0, f"{q:g} bar") for q in (0.0, 30.0)]
    pts = stability_points((0.0, 30.0), (0.0, 150.0, 165.0), judged)
    assert [(p.pressure_bar, p.speed_rpm / 60.0) for p in pts] == [
        (0.0, 0.0), (30.0, 0.0), (0.0, 165.0), (30.0, 165.0)]
    assert pts[1].label == "30 bar, 0 Hz"


@pytest.mark.parametrize("speed_hz", [0.0, 150.0])
def test_stability_case_is_python_controls_closed_loop(speed_hz):
    """The compressor's PID closed on its full-order plant with the target's delay: our
    verdict and rightmost pole are those of ``control.feedback`` on the same delayed plant
    (negative feedback, ``i = −K y``)."""
    cfg = load_rig(ROOT / "docs" / "rigs" / "compressor.toml")
    K = design(cfg, "pid").K
    point = OperatingPoint(30.0, 60.0 * speed_hz, "")
    case, curves = stability_case(JudgeJob("pid", point, K), cfg)
    plant = build_plant(cfg, pressure_bar=30.0, speed_rpm=60.0 * speed_hz)
    P = plant.to_statespace()
    lag = loop_delay(cfg.controller.sample_rate_hz, cfg.controller.delay_samples).system
    n = P.ninputs
    Lag = control.append(*([control.ss(lag)] * n))
    G = control.series(Lag, P)
    # K's inputs are y_<axis> in the plant's output order (both from the rig's AMBs)
    cl = control.feedback(G, control.ss(K.A, K.B, K.C, K.D))
    ref = np.linalg.eigvals(cl.A)
    assert case.stable == bool(np.all(ref.real < 0))
    assert case.max_real_pole == pytest.approx(ref.real.max(), rel=1e-6, abs=1e-6)
    assert curves["poles"].size == ref.size and case.discrete is None
    assert case.speed_hz == speed_hz and case.pressure_bar == 30.0


def test_speed_range_loops_are_graded_as_the_judged_ones(testrig_cfg):
    """Reference: the judgement at the same condition — a speed-range loop graded
    (:func:`stability_case` with the judgement's settings) has the σ̄(S_o) peak, per-axis
    peaks and zones :func:`judge` gives there, continuous and as it runs (the discrete
    controller with its delay on the sampled plant): the one rule, to 1e-9."""
    from ambseal.analysis.judge import judge, judge_settings
    from ambseal.app.commands import digital_for
    from ambseal.design import design_spec

    cfg, res = testrig_cfg, design(testrig_cfg, "pid")
    K = res.K
    spec = design_spec(cfg)
    s = judge_settings(spec)
    point = OperatingPoint(cfg.operating.pressure_bar, 60.0 * 50.0, "x")
    digital = digital_for(cfg, "pid", K, res, [point])
    Kd = digital.statespace(delayed=True)
    case, _ = stability_case(JudgeJob("pid", point, K, Kd), cfg, s)
    ref, _ = judge(cfg, K, "pid", point, s, impulse=False, discrete=Kd)
    for got, want in ((case.to_dict(), ref.to_dict()),
                      (case.to_dict()["discrete"], ref.to_dict()["discrete"])):
        assert got["iso_zone"] == want["iso_zone"] and got["iso_zone"] in "ABCD"
        assert got["iso_zone_per_axis"] == want["iso_zone_per_axis"]
        assert got["sensitivity_peak"] == pytest.approx(want["sensitivity_peak"], rel=1e-9)
        for ax, pk in want["sensitivity_peak_per_axis"].items():
            assert got["sensitivity_peak_per_axis"][ax] == pytest.approx(pk, rel=1e-9)
