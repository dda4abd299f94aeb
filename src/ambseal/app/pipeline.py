"""The main job, stage by stage: rig → model → (identification →) controllers → judgement → report.

``ambseal run`` calls :func:`run`. It holds no numerics of its own: it wires
:mod:`ambseal.model`, :mod:`ambseal.design`, :mod:`ambseal.analysis.judge`,
:mod:`ambseal.identify` and :mod:`ambseal.report.run_report`, and writes every file through
a temporary name and a rename.
"""

from __future__ import annotations

import sys
from dataclasses import dataclass, field, replace
from pathlib import Path

from ambseal.analysis.cases import run_cases
from ambseal.analysis.delivery import (
    FailedController,
    also_failed,
    loop_failure,
    synthesis_failure,
)
from ambseal.analysis.judge import (
    frozen_at,
    judge_case,
    judge_jobs,
    judge_settings,
    judge_spinup,
    operating_points,
    speed_scheduled,
    unstable_open_loop_poles,
)
from ambseal.analysis.speed_range import stability_case, stability_points
from ambseal.app.commands import (
    Designed,
    digitals_for,
    export_all,
    facility_impulses,
    identification_stage,
)
from ambseal.app.metrics import SCHEMA_VERSION, ControllerSummary, OpenLoop, RunMetrics
from ambseal.app.remedies import remedy
from ambseal.app.tracked import tracked_designs, tracked_ramp
from ambseal.config import RigConfig, default_rig_path, load_rig, load_truth, method_names
from ambseal.design.lpv_design import design_frozen, design_lpv
from ambseal.design.recipes import design
from ambseal.design.specs import design_spec
from ambseal.errors import ConfigError, SynthesisError
from ambseal.files import RunFolder, write_json
from ambseal.model.rig import build_plant
from ambseal.report.progress import StageProgress
from ambseal.report.run_report import (
    gains_figure,
    judged_on,
    rig_clearances_um,
    spinup_figures,
    stamp,
    write_run_report,
)
from ambseal.threads import with_numerics_threads

__all__ = ["RunResult", "run", "default_truth_path", "EXIT_FAILED"]

#: ``ambseal run``'s exit status when the report is written but a designed controller
#: failed (not delivered); 2 stays for bad input.
EXIT_FAILED = 1


@dataclass(frozen=True)
class RunResult:
    """Where the main job wrote its results, and the metrics it wrote."""

    out_dir: Path
    metrics_path: Path
    report_path: Path
    metrics: dict
    #: controllers that failed (``metrics["failed"]``), by method
    failed: dict = field(default_factory=dict)
    #: the exit status ``ambseal run`` returns: 0, or :data:`EXIT_FAILED` when a designed
    #: controller failed (an unstable one kept with ``allow_unstable`` does not count)
    exit_status: int = 0


def _labelled(method: str, jobs: list, judged: list) -> list[tuple[dict, dict]]:
    """``method``'s judged cases as (case dict with its condition's ``label``, curves)."""
    return [({**case.to_dict(), "label": j["point"].label}, crv)
            for j, (case, crv) in zip(jobs, judged) if j["name"] == method]


def _speed_range(designs, digitals, spec, points, design_cfg, judge_cfg, stages, failed,
                 allow_unstable: bool) -> list:
    """Every design closed at each judged pressure and stability speed not judged in full
    (:mod:`ambseal.analysis.speed_range`); a loop unstable there fails its controller, its
    line naming those conditions after any found before (``failed`` is updated). Returns
    the stability cases."""
    spoints = stability_points(spec.pressures_bar, spec.stability_speeds_hz, points)
    if not spoints:
        return []
    stages.begin("speed-range", f"stability from standstill to "
                 f"{max(spec.stability_speeds_hz):g} Hz")
    jobs = judge_jobs(designs, digitals, spoints, design_cfg)
    done = run_cases(stability_case, jobs, shared={"cfg": judge_cfg}, workers=1,
                     raise_errors=True,
                     on_done=lambda i, r: stages.step(f"{jobs[i]['name']} at "
                                                      f"{jobs[i]['point'].label}"))
    for d in designs:
        f = loop_failure(d.method, _labelled(d.method, jobs, done),
                         designed=d.method != "pid", kept=allow_unstable)
        if f is not None:
            failed[d.method] = also_failed(failed.get(d.method), f)
    return [case for case, _ in done]


def default_truth_path() -> Path:
    """The virtual facility's truth for the embedded test rig (``data/testrig_truth.toml``)."""
    return Path(__file__).resolve().parents[1] / "data" / "testrig_truth.toml"


def _controllers(cfg: RigConfig, spec, say, failed: dict,
                 methods: tuple[str, ...] = ("pid", "hinf", "mu")) -> list[Designed]:
    """The designed controllers of the main job.

    Pressure-driven seals (the test rig): the reference PID, H∞ and μ (P5 §4), from the
    rig's design specification ``spec``. Speed-driven seals over a speed range (the
    turboexpander, P3 §4): the reference PID, H∞ and μ at the operating speed (P3 §3,
    Fig. 11) and the LPV controller scheduled on speed. Where H∞ or μ, designed at the
    operating speed, loses the rotor at another speed of the machine's range, the LPV on
    speed from standstill to the top speed joins them (:func:`_lost_over_speed`).
    ``say(message, steps)`` reports:
    one step per design, messages in between. ``methods`` limits the pressure-driven case
    (the PID alone before identification, H∞ and μ on the identified rig after it).

    Every design is kept whatever its own full-order check says (the judgement decides,
    :mod:`ambseal.analysis.delivery`); a design that raises a SynthesisError is left out
    and recorded in ``failed`` (method → :class:`FailedController`) so that the run goes
    on with the others.
    """

    def lti(res) -> Designed:
        return Designed(res.method, res.K, res.summary(), res)

    def guarded(m: str, make) -> list[Designed]:
        try:
            d = make()
        except SynthesisError as exc:
            failed[m] = synthesis_failure(m, str(exc))
            say(f"{m} failed", 1)
            return []
        say(f"{m} designed", 1)
        return [d]

    def robust(m: str) -> list[Designed]:
        say(f"designing {m}", 0)
        return guarded(m, lambda: lti(design(cfg, m, spec=spec, allow_unstable=True,
                                             progress=lambda msg: say(msg, 0))))

    if speed_scheduled(cfg):
        out = [lti(design(cfg, "pid"))]
        say("pid designed", 1)

        def frozen_hinf() -> Designed:
            fz = design_frozen(cfg, cfg.operating.speed_rpm / 60.0, allow_unstable=True,
                               spec=spec)
            return Designed("hinf", fz.K, fz.to_dict(), fz)

        def lpv() -> Designed:
            d = design_lpv(cfg, speeds_hz=cfg.operating.speed_range_hz, allow_unstable=True,
                           spec=spec)
            return Designed("lpv", d, d.to_dict(), d)

        return out + guarded("hinf", frozen_hinf) + robust("mu") + guarded("lpv", lpv)
    out = []
    for m in methods:
        if m in method_names(synthesised=True):
            out += robust(m)
        else:  # derived from the rig (the reference PID): no synthesis that can fail
            out.append(lti(design(cfg, m)))
            say(f"{m} designed", 1)
    lost = _lost_over_speed(cfg, out)
    if lost:
        top = max(spec.stability_speeds_hz)
        say(f"{' and '.join(lost)} designed at {cfg.operating.speed_rpm / 60.0:g} Hz lose the "
            f"rotor at other speeds: designing the LPV on speed, 0–{top:g} Hz", 0)

        def speed_lpv() -> Designed:
            d = design_lpv(cfg, speeds_hz=(0.0, top), states=spec.model_states,
                           allow_unstable=True, spec=spec)
            return Designed("lpv", d, d.to_dict(), d)

        out += guarded("lpv", speed_lpv)
    return out


def _lost_over_speed(cfg: RigConfig, designs: list[Designed]) -> list[str]:
    """The fixed designs (H∞, μ; designed at the operating speed) whose full-order loop is
    unstable at another speed of the machine's range, standstill to the top speed: where
    the gyroscopics move the modes out of what one frozen design holds. For them the main
    job adds the speed-scheduled LPV controller (:func:`ambseal.design.lpv_design.
    design_lpv`, thesis P3 §4) over standstill to the top speed, on the same design model
    (``[design] model_states``) — a rig with a speed range only."""
    if cfg.operating.speed_range_hz is None:
        return []
    f0 = cfg.operating.speed_rpm / 60.0
    out = []
    for d in designs:
        fo = getattr(d.result, "full_order", None)
        if d.method in ("hinf", "mu") and fo and not fo["stable"] \
                and abs(fo["speed_hz"] - f0) > 1e-9 * max(f0, 1.0):
            out.append(d.method)
    return out


@with_numerics_threads
def run(rig: str | Path | None = None, out_dir: str | Path = "ambseal-out",
        progress: bool = True, truth: str | Path | None = None,
        identification: bool = True, overrides: tuple[str, ...] = (),
        allow_unstable: bool = False, command: str | None = None) -> RunResult:
    """The main job: build and reduce the model, design, judge, identify, report.

    Parameters
    ----------
    rig : path, optional
        Rig file; the embedded thesis test facility when omitted.
    out_dir : path
        Output folder, created if needed, replaced as a whole at the end
        (:class:`ambseal.files.RunFolder`: a staging folder beside it, a lock against a
        second run, a manifest of the files written last).
    progress : bool
        Show a progress display on stderr when it is a terminal; stage lines go to the
        ``"ambseal"`` logger in any case (:mod:`ambseal.report.progress`).
    truth : path, optional
        Truth file of the virtual test facility; with it (and by default for the embedded
        rig) the run identifies the rig on the virtual facility by the thesis's procedure
        (:mod:`ambseal.identify.procedure`) with the reference PID, designs H∞ and μ on the
        identified rig (unless it equals the rig file within its intervals:
        :func:`ambseal.identify.design_model.design_rig`), judges every controller on the
        facility's full-order truth and runs their impulse responses on the facility
        beside the identified model (P5 §3, Figs. 15–16).
    identification : bool
        Set False to skip the identification stage.
    overrides : tuple of str
        ``design.<key>=<value>`` settings applied to the rig file before validation
        (:func:`ambseal.config.load_rig`).
    allow_unstable : bool
        Deliver (export) a designed controller whose judged loop is unstable at a judged
        condition; it stays marked in ``failed`` and the exit status is 0. Without it such a
        controller is judged and reported but not exported, and ``exit_status`` is
        :data:`EXIT_FAILED`.
    command : str, optional
        The command line, for the report's stamp.

    Returns
    -------
    RunResult
        With ``failed``: every controller whose judged loop is unstable at a judged
        condition, or whose design failed, with the reason
        (:mod:`ambseal.analysis.delivery`; also ``metrics["failed"]`` and the report's
        "Failed controllers" part). The run reports every controller it could design before
        it says so.

    Raises
    ------
    ConfigError
        A bad rig file, a rig without AMBs or without ``[controller.pid]``.
    """

    rig_path = Path(rig) if rig is not None else default_rig_path()
    cfg = load_rig(rig_path, overrides)
    if truth is None and rig is None:
        truth = default_truth_path()
    if not cfg.amb:
        raise ConfigError(f"{rig_path}: amb: the main job needs at least one [[amb]]")
    # the truth file is refused before any work
    truth_cfg = load_truth(truth) if identification and truth is not None else None
    spec = design_spec(cfg)
    points = operating_points(spec)
    settings = judge_settings(spec)
    final = Path(out_dir)
    lti_methods, synthesised = method_names(fixed=True), method_names(synthesised=True)
    n_designs = len(lti_methods) + int(speed_scheduled(cfg))  # and the LPV on speed
    n_tr = int(cfg.design.tracked)  # off by default: minutes of LMI synthesis
    totals = {"model": 1, "design": n_designs, "judge": (n_designs + n_tr) * len(points),
              "identification": None, "design (identified)": len(synthesised) + n_tr,
              "speed-range": None, "spin-up": 1, "ramp": 1, "report": 1}
    # one run = one folder: written into a staging folder that replaces out_dir at the end
    with RunFolder(final) as out, \
            StageProgress(totals, display=progress and sys.stderr.isatty()) as stages:
        (out / "controllers").mkdir()
        stages.begin("model", "full order and modal reduction")
        full = build_plant(cfg)
        n_reduced = build_plant(cfg, reduced=True).n_states
        unstable = unstable_open_loop_poles(full.A)
        stages.step()
        say = lambda msg, steps=0: stages.step(msg, steps)  # noqa: E731
        stages.begin("design")
        early = truth_cfg is not None and not speed_scheduled(cfg)  # P5 §3: identify first
        failed: dict[str, FailedController] = {}
        designs = _controllers(cfg, spec, say, failed,
                               tuple(m for m in lti_methods if m not in synthesised)
                               if early else lti_methods)
        digitals, cannot_run = digitals_for(cfg, designs, points, lambda m: stages.step(m, 0))
        ident, judge_cfg = None, cfg
        if truth_cfg is not None:
            if "pid" not in digitals:
                raise ConfigError("controller.pid: the virtual facility runs the reference "
                                  "PID during identification, and "
                                  + cannot_run.get("pid", "the rig has none"))
            stages.begin("identification")
            ident = identification_stage(cfg, truth_cfg, out, stages.step,
                                         digitals["pid"].discrete)
            judge_cfg = ident.truth_cfg
        if early:
            stages.begin("design (identified)", ident.summary["design"]["designed_on"])
            robust = _controllers(ident.design_cfg, spec, say, failed, synthesised)
            more, more_cannot = digitals_for(ident.design_cfg, robust, points,
                                             lambda m: stages.step(m, 0))
            digitals.update(more)
            cannot_run.update(more_cannot)
            designs += robust
            facility_impulses(cfg, truth_cfg, ident, digitals, out)
        design_cfg = cfg if ident is None else ident.design_cfg
        designs += tracked_designs(cfg, design_cfg, spec, points, say, digitals, cannot_run)
        stages.begin("judge")

        def judge_designs(ds, digs, steps=1):
            js = judge_jobs(ds, digs, points, design_cfg)
            return js, run_cases(judge_case, js, shared={"cfg": judge_cfg, "settings": settings},
                                 workers=1, raise_errors=True,
                                 on_done=lambda i, r: stages.step(
                                     f"{js[i]['name']} at {js[i]['point'].label}", steps))

        jobs, judged = judge_designs(designs, digitals)
        for d in designs:  # the judged loops decide (continuous with delay, and as it runs)
            f = loop_failure(d.method, _labelled(d.method, jobs, judged),
                             designed=d.method != "pid", kept=allow_unstable)
            if f is not None:
                failed[d.method] = f
        for m in [m for m, f in failed.items() if f.designed and f.judged
                  and m in synthesised and not speed_scheduled(cfg)]:
            fixed, failed[m] = remedy(
                m, failed[m], [c for c, _ in _labelled(m, jobs, judged)], design_cfg, spec,
                points, lambda ds, digs: judge_designs(ds, digs, 0), lambda s: say(s, 0))
            if fixed is not None:  # the remedied design replaces the failed one
                del failed[m]
                designs = [fixed.design if d.method == m else d for d in designs]
                digitals[m] = fixed.digital
                new = iter(zip(fixed.jobs, fixed.judged))
                jobs, judged = map(list, zip(*[next(new) if j["name"] == m else (j, r)
                                               for j, r in zip(jobs, judged)]))
        stability = _speed_range(designs, digitals, spec, points, design_cfg, judge_cfg, stages,
                                 failed, allow_unstable)
        if not speed_scheduled(cfg) and "lpv" in {d.method for d in designs} \
                and "lpv" not in failed:  # the controller for the speed range: say so
            for m in [m for m in ("hinf", "mu") if m in failed and failed[m].judged]:
                failed[m] = replace(failed[m], reason=f"{failed[m].reason}; the LPV on speed "
                                                       "holds the rotor over the speed range")
        cases = [case for case, _ in judged]
        case_dicts = [case.to_dict() for case in cases]
        curves = [(j["name"], j["point"], case, c)
                  for j, case, (_, c) in zip(jobs, case_dicts, judged)]
        # a failed design is judged and reported, not delivered (unless asked for)
        held = {m for m, f in failed.items() if f.designed and not allow_unstable}
        summaries = export_all(designs, {m: g for m, g in digitals.items() if m not in held},
                               case_dicts, out / "controllers")
        figs, sections = ([], []) if ident is None else (ident.figs, ident.sections)
        spinup = ramp = None
        if speed_scheduled(cfg):
            stages.begin("spin-up", "spin-up and frozen sensitivities")
            spinup, sims, sens = judge_spinup(  # LPV against μ: P3 Fig. 11
                cfg, {d.method: d.controller for d in designs if d.method in ("mu", "lpv")})
            figs += spinup_figures(out, sims, sens, cfg.operating.speed_range_hz)
            stages.step()
        if cfg.design.tracked and truth_cfg is not None:
            stages.begin("ramp", "0 → 3× nominal pressure on the virtual facility")
            ramp, fig = tracked_ramp(cfg, truth_cfg, designs, digitals, ident, settings, out,
                                     say)
            figs.append(fig)
        metrics = RunMetrics(
            schema_version=SCHEMA_VERSION, rig=str(rig_path), rig_name=cfg.rotor.name,
            open_loop=OpenLoop([[float(z.real), float(z.imag)] for z in unstable],
                               full.n_states, n_reduced),
            unbalance=settings.unbalance_dict(), design_spec=spec.to_dict(),
            controllers={m: ControllerSummary.from_dict(s) for m, s in summaries.items()},
            cannot_run=cannot_run, cases=cases, stability=stability, failed=failed,
            identification=None if ident is None else ident.summary, spinup=spinup,
            ramp=ramp).to_dict()
        stages.begin("report")
        write_json(out / "metrics.json", metrics)
        figs.append(gains_figure(out, [(d.method, frozen_at(d.controller, cfg.operating,
                                                            design_cfg)) for d in designs]))
        write_run_report(out, f"ambseal — {cfg.rotor.name}", stamp(rig_path, command),
                         metrics, curves, figs, sections, rig_clearances_um(cfg),
                         judged_on(cfg, truth_cfg if ident is not None else None, truth))
        stages.step()
    exit_status = EXIT_FAILED if any(f.designed and not (allow_unstable and f.judged)
                                     for f in failed.values()) else 0
    return RunResult(final, final / "metrics.json", final / "report.html", metrics,
                     failed=metrics["failed"], exit_status=exit_status)
