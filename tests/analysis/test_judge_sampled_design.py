"""A design on the sampled plant is judged as it runs alone: its case's loop, at every
judged condition and speed of the range, is the Tustin transform of its w-plane controller,
one sample late, on the ZOH-sampled full-order plant — python-control's loop built by
``sample_system`` and ``feedback`` — not the w-plane controller closed in continuous time
with the delay's Padé lag."""

from __future__ import annotations

from pathlib import Path

import control
import numpy as np
import pytest

from ambseal.analysis.judge import judge_case, judge_jobs, judge_settings, operating_points
from ambseal.analysis.speed_range import stability_case, stability_points
from ambseal.app.commands import Designed, digital_for
from ambseal.config import load_rig
from ambseal.design import design_spec
from ambseal.design.recipes import design
from ambseal.model import build_plant

SUPERCRITICAL = Path(__file__).resolve().parents[2] / "examples" / "supercritical_rotor.toml"


@pytest.fixture(scope="module")
def sampled_hinf():
    cfg = load_rig(SUPERCRITICAL, ("design.synthesis_plant=sampled", "design.one_speed=true"))
    d = Designed(design(cfg, "hinf", enlarge=0, allow_unstable=True))
    spec = design_spec(cfg)
    points = operating_points(spec)
    return cfg, d, spec, points, digital_for(cfg, "hinf", d.controller, d.result, points)


def _z_of_python_control(cfg, K, p_bar, speed_hz) -> float:
    """Largest |z| of the loop as it runs, built by python-control: the Tustin transform
    of ``K`` ``delay_samples`` late on the ZOH-sampled plant."""
    T = 1.0 / cfg.controller.sample_rate_hz
    Kd = control.sample_system(control.ss(K.A, K.B, K.C, K.D), T, method="tustin")
    n = Kd.noutputs
    late = control.ss(np.zeros((n, n)), np.eye(n), np.eye(n), np.zeros((n, n)), T)  # z⁻¹
    for _ in range(cfg.controller.delay_samples):
        Kd = late * Kd
    pl = build_plant(cfg, pressure_bar=p_bar, speed_rpm=60.0 * speed_hz)
    G = pl.select_inputs([pl.input_names[j] for j in pl.current_inputs()])
    Gd = control.sample_system(control.ss(G.A, G.B, G.C, G.D), T, method="zoh")
    return float(np.abs(control.feedback(Gd, Kd).poles()).max())


def test_a_sampled_design_is_judged_on_its_loop_as_it_runs(sampled_hinf):
    cfg, d, spec, points, digital = sampled_hinf
    assert d.synthesis_plant == "sampled" and digital.method == "tustin"
    T = 1.0 / cfg.controller.sample_rate_hz
    jobs = judge_jobs([d], {"hinf": digital}, points, cfg)
    for job in jobs:
        case, curves = judge_case(job, cfg, judge_settings(spec, cfg))
        z = _z_of_python_control(cfg, d.controller, job.point.pressure_bar,
                                 job.point.speed_rpm / 60.0)
        # the case's own loop is the one as it runs, its decay rate ln max|z| / T
        assert case.stable == (z < 1.0) == case.discrete.stable
        assert np.exp(case.max_real_pole * T) == pytest.approx(z, rel=1e-6)
        assert case.sensitivity_peak == case.discrete.sensitivity_peak
        # its poles as rates (rad/s), as every case's, and as z in its discrete block
        s = np.asarray(curves["poles"])
        assert np.exp(s[np.isfinite(s.real)].real.max() * T) == pytest.approx(z, rel=1e-6)
        assert np.abs(curves["discrete"]["poles"]).max() == pytest.approx(z, rel=1e-6)


def test_a_sampled_design_is_judged_as_it_runs_over_the_speed_range(sampled_hinf):
    cfg, d, spec, points, digital = sampled_hinf
    T = 1.0 / cfg.controller.sample_rate_hz
    spoints = stability_points(spec.pressures_bar, spec.stability_speeds_hz, points)
    assert spoints
    for job in judge_jobs([d], {"hinf": digital}, spoints, cfg):
        case, curves = stability_case(job, cfg, judge_settings(spec, cfg))
        z = _z_of_python_control(cfg, d.controller, job.point.pressure_bar,
                                 job.point.speed_rpm / 60.0)
        assert case.stable == (z < 1.0) == case.discrete.stable
        assert np.exp(case.max_real_pole * T) == pytest.approx(z, rel=1e-6)
        assert case.discrete.max_abs_pole_z == pytest.approx(z, rel=1e-6)
        # graded once, the same loop: its zones are the loop's as it runs
        assert case.sensitivity_peak_per_axis == case.discrete.sensitivity_peak_per_axis
        s = np.asarray(curves["poles"])
        assert np.exp(s[np.isfinite(s.real)].real.max() * T) == pytest.approx(z, rel=1e-6)


def test_a_design_on_the_continuous_plant_keeps_its_continuous_loop(sampled_hinf):
    """The same controller, taken as designed on the continuous plant: its job closes the
    continuous controller (with the delay's Padé lag), the discrete one beside it."""
    cfg, d, spec, points, digital = sampled_hinf

    class Continuous:  # the design's method and controller, no synthesis_plant
        method, controller = d.method, d.controller

    for job in judge_jobs([Continuous()], {"hinf": digital}, points, cfg):
        assert not job.controller.dt and job.discrete.dt


def test_a_sampled_design_that_cannot_run_keeps_its_w_plane_form(sampled_hinf):
    """Without a digital controller there is no loop as it runs: the w-plane controller
    closed in continuous time is what is left to judge."""
    cfg, d, spec, points, _ = sampled_hinf
    jobs = judge_jobs([d], {}, points, cfg)
    assert all(j.discrete is None and not j.controller.dt for j in jobs)


def test_a_sampled_designs_notch_is_judged_as_it_runs(sampled_hinf):
    """The unbalance force rejection of a design on the sampled plant: each condition's
    loop with the notch is the one as it runs (its rate ln max|z| / T), not the w-plane
    controller and its notch closed in continuous time."""
    from ambseal.analysis.rejection import rejection_stability
    from ambseal.design import design_rejection

    cfg, d, spec, points, digital = sampled_hinf
    T = 1.0 / cfg.controller.sample_rate_hz
    lo, hi = cfg.operating.continuous_hz
    rej = design_rejection(cfg, d.controller, digital, speeds_hz=(lo, hi), points=2)
    rows = rejection_stability(cfg, rej, points, as_runs_only=True)
    assert rows
    for r in rows:
        assert r["stable"] == r["stable_as_runs"]
        assert np.exp(r["max_real_pole"] * T) == pytest.approx(r["max_abs_pole_z"], rel=1e-9)
    cont = rejection_stability(cfg, rej, points)
    assert [np.exp(r["max_real_pole"] * T) for r in cont] != pytest.approx(
        [r["max_abs_pole_z"] for r in cont], rel=1e-6)
