"""A design on the sampled plant is judged as it runs alone: its case's loop, at every
judged condition and speed of the range, is the Tustin transform of its w-plane controller,
one sample late, on the ZOH-sampled full-order plant — python-control's loop built by
``sample_system`` and ``feedback`` — not the w-plane controller closed in continuous time
with the delay's Padé lag."""

from __future__ import annotations

import json
from pathlib import Path

import control
import numpy as np
import pytest

from ambseal.analysis.campbell import closed_loop_modes
from ambseal.analysis.judge import judge_case, judge_jobs, judge_settings, operating_points
from ambseal.analysis.speed_range import stability_case, stability_points
from ambseal.analysis.sweep import refine_boundary, sweep
from ambseal.app.commands import Designed, digital_for
from ambseal.app.controllers import controller_for
from ambseal.config import load_rig
from ambseal.design import design_spec
from ambseal.design.recipes import design
from ambseal.errors import DataError, SynthesisError
from ambseal.export import export_controller, load_controller
from ambseal.model import build_plant

SUPERCRITICAL = Path(__file__).resolve().parents[2] / "examples" / "supercritical_rotor.toml"


#: A speed (Hz) between the crossings of the w-plane controller closed in continuous time
#: (unstable below 133.8 Hz) and of the loop as it runs (below 130.8 Hz): the two part
#: there, the loop as it runs holding.
_PARTED_HZ = 132.0


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
    return float(np.abs(_poles_of_python_control(cfg, K, p_bar, speed_hz)).max())


def _poles_of_python_control(cfg, K, p_bar, speed_hz) -> np.ndarray:
    """The poles z of :func:`_z_of_python_control`'s loop."""
    T = 1.0 / cfg.controller.sample_rate_hz
    Kd = control.sample_system(control.ss(K.A, K.B, K.C, K.D), T, method="tustin")
    n = Kd.noutputs
    late = control.ss(np.zeros((n, n)), np.eye(n), np.eye(n), np.zeros((n, n)), T)  # z⁻¹
    for _ in range(cfg.controller.delay_samples):
        Kd = late * Kd
    pl = build_plant(cfg, pressure_bar=p_bar, speed_rpm=60.0 * speed_hz)
    G = pl.select_inputs([pl.input_names[j] for j in pl.current_inputs()])
    Gd = control.sample_system(control.ss(G.A, G.B, G.C, G.D), T, method="zoh")
    return control.feedback(Gd, Kd).poles()


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


@pytest.mark.parametrize("suffix", [".json", ".npz", ".mat"])
def test_a_sampled_designs_file_says_so_and_its_modes_are_as_it_runs(sampled_hinf, tmp_path,
                                                                     suffix):
    """A controller file of a design on the sampled plant records it, and ``modes``,
    ``campbell`` and ``sweep --controller FILE`` close it as it runs: its modes are the
    python-control loop's poles ln z / T, not the w-plane controller's in continuous
    time."""
    cfg, d, spec, points, digital = sampled_hinf
    path = export_controller(digital, tmp_path / f"controller_hinf{suffix}")
    assert load_controller(path).synthesis_plant == "sampled"
    K = controller_for(cfg, str(path))
    assert K.as_runs_only
    T = 1.0 / cfg.controller.sample_rate_hz
    p = cfg.operating.pressure_bar
    z = _poles_of_python_control(cfg, d.controller, p, _PARTED_HZ)
    assert np.abs(z).max() < 1.0  # the loop as it runs holds there
    m = closed_loop_modes(cfg, K, speed_hz=_PARTED_HZ, pressure_bar=p)
    assert m.poles.size and m.stable
    # its w-plane form closed in continuous time, what these commands closed before, does not
    assert not closed_loop_modes(cfg, d.controller, speed_hz=_PARTED_HZ, pressure_bar=p).stable
    assert np.abs(m.poles.imag).max() < np.pi / T  # below Nyquist: no aliased mode listed
    # compared where both were computed, in z: a cluster of poles near z = 1 (here two
    # about 40 rad/s, 0.4 rad/s apart) is accurate to about √ε there, not to ε|λ| in
    # λ = ln z / T, and python-control's z moves by 5e-9 between BLAS kernel sets
    z_ref = z[np.abs(z) > 1e-12]
    for lam in m.poles:
        assert np.abs(z_ref - np.exp(lam * T)).min() == pytest.approx(0.0, abs=1e-7)


def test_a_file_without_synthesis_plant_is_a_continuous_design(sampled_hinf, tmp_path):
    """A file written before the key existed holds a continuous design; a value other than
    the two known ones is refused, naming the file and the key."""
    cfg, d, spec, points, digital = sampled_hinf
    path = export_controller(digital, tmp_path / "controller_hinf.json")
    doc = json.loads(path.read_text())
    doc.pop("synthesis_plant")
    path.write_text(json.dumps(doc))
    assert load_controller(path).synthesis_plant == "continuous"
    assert not controller_for(cfg, str(path)).dt  # its continuous design
    doc["synthesis_plant"] = "analog"
    path.write_text(json.dumps(doc))
    with pytest.raises(DataError, match=r"controller_hinf\.json: synthesis_plant = 'analog'"):
        load_controller(path)


def test_a_sweep_judges_a_sampled_design_as_it_runs_alone(sampled_hinf):
    """Every column of a sweep row, and the stability boundary's bisection, is the loop as
    it runs (python-control's max |z|), for a design that exists only as it runs."""
    cfg, d, spec, points, digital = sampled_hinf
    T = 1.0 / cfg.controller.sample_rate_hz
    p = cfg.operating.pressure_bar
    rows = sweep(cfg, {"hinf": digital}, [p], [0.0, _PARTED_HZ],
                 settings=judge_settings(spec, cfg), digitals={"hinf": digital})
    for r in rows:
        z = _z_of_python_control(cfg, d.controller, r["pressure_bar"], r["speed_hz"])
        assert r["stable"] == (z < 1.0) == r["stable_as_runs"]
        assert np.exp(r["max_real_pole"] * T) == pytest.approx(z, rel=1e-6)
        assert r["sensitivity_peak"] == r["sensitivity_peak_as_runs"]
    assert [r["stable"] for r in rows] == [False, True]
    # a bracket bisected on the loop as it runs, which holds at every pressure there (the
    # rig has no seal): the boundary goes to the bracket's unstable end
    edge = refine_boundary(cfg, {"hinf": digital}, [
        {"controller": "hinf", "speed_hz": _PARTED_HZ, "last_stable_bar": 0.0,
         "first_unstable_bar": 40.0, "boundary_pressure_bar": 40.0}], tol_bar=1.0)[0]
    assert edge["boundary_pressure_bar"] > 39.0


def test_a_sampled_design_is_never_refused_for_parting_from_its_w_plane_form(sampled_hinf):
    """At 475 Hz, far above the range, the w-plane controller closed in continuous time
    without the delay holds and the loop as it runs does not (python-control's max |z|
    above 1): a design on the continuous plant would be refused there ("cannot run"),
    but the sampled loop is the one this design foresaw, so its discrete controller — its
    Tustin transform, exactly — is returned for the judgement to find the loss."""
    from ambseal.robust import digital_controller

    cfg, d, spec, points, _ = sampled_hinf
    fs, delay = cfg.controller.sample_rate_hz, cfg.controller.delay_samples
    p = cfg.operating.pressure_bar
    assert _z_of_python_control(cfg, d.controller, p, 475.0) > 1.0
    pl = build_plant(cfg, pressure_bar=p, speed_rpm=60.0 * 475.0)
    G = pl.select_inputs([pl.input_names[j] for j in pl.current_inputs()])
    plants = [tuple(np.asarray(X, float) for X in (G.A, G.B, G.C, G.D))]
    assert control.feedback(control.ss(*plants[0]), d.controller).poles().real.max() < 0
    dc = digital_controller(d.controller, fs, plants, delay_samples=delay, w_plane=True)
    assert dc.method == "tustin" and dc.as_runs_only
    ref = control.sample_system(control.ss(d.controller.A, d.controller.B, d.controller.C,
                                           d.controller.D), 1.0 / fs, method="tustin")
    assert np.allclose(dc.discrete.A, ref.A) and np.allclose(dc.discrete.D, ref.D)
    with pytest.raises(SynthesisError, match="cannot run|stable"):
        digital_controller(d.controller, fs, plants, delay_samples=delay,
                           methods=("tustin",))


def test_a_sampled_designs_failing_mode_is_named_on_its_loop_as_it_runs(sampled_hinf):
    """The mode a lost loop's line names is the one of the loop as it runs nearest the
    failing pole (python-control's ln z / T), its kind that mode's shape's."""
    from ambseal.analysis.campbell import modes_as_run
    from ambseal.analysis.mode_naming import failing_mode_kind, mode_kind, support_span_m

    cfg, d, spec, points, digital = sampled_hinf
    T = 1.0 / cfg.controller.sample_rate_hz
    p = cfg.operating.pressure_bar
    z = _poles_of_python_control(cfg, d.controller, p, 0.0)
    lost = np.log(complex(z[np.argmax(np.abs(z))])) / T
    assert lost.real > 0 and lost.imag != 0  # an oscillating mode lost at standstill
    kind = failing_mode_kind(cfg, digital, pressure_bar=p, speed_hz=0.0, pole=lost)
    m = modes_as_run(cfg, digital, speed_hz=0.0, pressure_bar=p,
                     max_hz=1.5 * abs(lost.imag) / (2 * np.pi) + 10.0)
    k = int(np.argmin(np.abs(m.poles - complex(lost.real, abs(lost.imag)))))
    assert m.poles[k] == pytest.approx(complex(lost.real, abs(lost.imag)), rel=1e-6)
    assert kind == mode_kind(m.shapes[k], m.node_z_m, support_span_m(cfg), m.whirl[k], 0.0)
    assert kind is not None


def test_the_cli_closes_a_method_designed_on_the_sampled_plant_as_it_runs(tmp_path, capsys):
    """``ambseal modes RIG --controller hinf`` on a rig whose ``[design]`` designs on the
    sampled plant designs, discretises and closes the loop as it runs: every mode it lists
    is a pole ln z / T of python-control's sampled loop of the same design (its Tustin
    transform, one sample late, on the ZOH-sampled plant), not one of its w-plane form
    closed in continuous time."""
    from ambseal.cli import main

    rig = tmp_path / "sampled.toml"
    rig.write_text(SUPERCRITICAL.read_text()
                   + '\n[design]\nsynthesis_plant = "sampled"\none_speed = true\n')
    cfg = load_rig(rig)
    K = design(cfg, "hinf").K  # the design the command makes
    p = cfg.operating.pressure_bar
    T = 1.0 / cfg.controller.sample_rate_hz
    z = _poles_of_python_control(cfg, K, p, _PARTED_HZ)
    assert np.abs(z).max() < 1.0
    cont = closed_loop_modes(cfg, K, speed_hz=_PARTED_HZ, pressure_bar=p).poles
    ref = np.log(z[np.abs(z) > 1e-12].astype(complex)) / T
    ref = ref[ref.imag > 0]
    assert main(["modes", str(rig), "--controller", "hinf", "--speed-rpm",
                 f"{60.0 * _PARTED_HZ:g}", "--max-hz", "2000", "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert out["unstable_poles"] == []
    listed = [(f, zeta) for f, zeta in zip(out["natural_frequencies_hz"],
                                           out["damping_ratios"])]
    assert len(listed) > 20
    for f, zeta in listed:
        k = int(np.argmin(np.abs(ref.imag / (2 * np.pi) - f)))
        assert ref[k].imag / (2 * np.pi) == pytest.approx(f, rel=1e-6)
        assert -ref[k].real / abs(ref[k]) == pytest.approx(zeta, rel=1e-5, abs=1e-8)
    apart = [min(abs(cont - ref[int(np.argmin(np.abs(ref.imag / (2 * np.pi) - f)))]))
             / (2 * np.pi * f) for f, _ in listed]
    assert max(apart) > 1e-2  # what the commands closed before lists other modes
