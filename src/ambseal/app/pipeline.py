"""The main job, stage by stage: rig → model → (identification →) controllers → judgement → report.

``ambseal run`` calls :func:`run`. It holds no numerics of its own: it wires
:mod:`ambseal.model`, :mod:`ambseal.design`, :mod:`ambseal.analysis.judge`,
:mod:`ambseal.identify` and :mod:`ambseal.report.run_report`, and writes every file through
a temporary name and a rename.
"""

from __future__ import annotations

import sys
import time
from dataclasses import dataclass, field, replace
from pathlib import Path

import numpy as np

from ambseal.analysis import (
    ZONE_SCALE,
    FailedController,
    JudgeSettings,
    OperatingPoint,
    also_failed,
    CLEARANCE_WORDS,
    capacity_block,
    capacity_words,
    clearance_exceeded,
    clearance_failure,
    facility_rejection,
    facility_speed_step,
    failing_mode_kind,
    frozen_at,
    judge_case,
    judge_jobs,
    judge_settings,
    judge_spinup,
    later_switch_on_hz,
    loop_failure,
    lost_conditions,
    notched_currents,
    notched_orbit_um,
    operating_points,
    rejection_effect,
    rig_clearances_um,
    rejection_stability,
    rotor_at_rest,
    run_cases,
    saturates,
    saturation_failure,
    sign_off,
    speed_scheduled,
    stability_case,
    stability_points,
    switch_on_hz,
    synthesis_failure,
    unstable_open_loop_poles,
    used_by_speed,
    verdict_line,
    worst_orbit_um,
)
from ambseal.app.commands import (
    Designed,
    Identified,
    check_reference_rate,
    digitals_for,
    export_all,
    facility_controller,
    facility_impulses,
    identification_stage,
)
from ambseal.app.metrics import (
    SCHEMA_VERSION,
    ControllerSummary,
    OpenLoop,
    RunMetrics,
    Signoff,
)
from ambseal.app.remedies import (
    on_the_sampled_plant,
    remedy,
    scheduled_on_speed,
    within_the_amplifier,
    worst_zone_as_runs,
)
from ambseal.app.tracked import tracked_designs, tracked_ramp
from ambseal.config import (
    RigConfig,
    TruthSection,
    default_rig_path,
    load_rig,
    load_truth,
    method_label,
    method_names,
)
from ambseal.design import (
    DesignSpec,
    design,
    design_frozen,
    design_lpv,
    design_rejection,
    design_spec,
    lpv_schedule,
    on_sampled_plant,
)
from ambseal.errors import ConfigError, ModelError, SynthesisError
from ambseal.export import export_notch, write_notch_c
from ambseal.files import RunFolder, write_json
from ambseal.machine import SPEED, ScheduledDigital
from ambseal.model import build_plant
from ambseal.report import (
    StageProgress,
    capacity_figure,
    gains_figure,
    judged_on,
    rejection_figure,
    signoff_report,
    spinup_figures,
    stamp,
    statics_section,
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


def _closed_as(d, digitals: dict):
    """The controller design ``d``'s loops are closed with: for a design on the sampled
    plant its digital controller, which exists only as it runs
    (:attr:`~ambseal.robust.DigitalController.as_runs_only`), else (or where it cannot
    run) the design's own."""
    return (digitals[d.method] if d.synthesis_plant == "sampled" and d.method in digitals
            else d.controller)


def kind_of(cfg, controller):
    """``kind_of`` of :func:`~ambseal.analysis.loop_failure` for one controller on the rig:
    the failing mode's kind (:func:`~ambseal.analysis.failing_mode_kind`) at the case's
    condition, or None where its shape cannot be taken (named in the line without it)."""
    def kind(case, pole):
        try:
            return failing_mode_kind(cfg, controller, pressure_bar=case.pressure_bar,
                                     speed_hz=case.speed_hz, pole=pole)
        except (ModelError, ValueError, np.linalg.LinAlgError):
            return None
    return kind


def _judged_of(method: str, jobs: list, judged: list) -> list[tuple]:
    """``method``'s judged cases with their curves."""
    return [done for j, done in zip(jobs, judged) if j.name == method]


def _speed_range(designs, digitals, spec, points, design_cfg, judge_cfg, stages, failed,
                 allow_unstable: bool) -> list:
    """Every design closed at each judged pressure and stability speed not judged in full
    (:mod:`ambseal.analysis.speed_range`); a loop unstable there fails its controller, its
    line naming those conditions after any found before (``failed`` is updated). Returns
    the stability cases."""
    if not stability_points(spec.pressures_bar, spec.stability_speeds_hz, points):
        return []
    stages.begin("speed-range", f"stability from standstill to "
                 f"{max(spec.stability_speeds_hz):g} Hz")
    jobs, done = _stability_cases(designs, digitals, spec, points, design_cfg, judge_cfg,
                                  lambda job: stages.step(f"{job.name} at {job.point.label}"))
    for d in designs:
        f = loop_failure(d.method, _judged_of(d.method, jobs, done),
                         designed=d.method != "pid", kept=allow_unstable,
                         derived=design_cfg.controller.pid is None,
                         kind_of=kind_of(judge_cfg, _closed_as(d, digitals)),
                         as_runs_only=d.synthesis_plant == "sampled")
        if f is not None:
            failed[d.method] = also_failed(failed.get(d.method), f)
    return [case for case, _ in done]


def _stability_cases(designs, digitals, spec, points, design_cfg, judge_cfg, on_done
                     ) -> tuple[list, list]:
    """Every design closed at each judged pressure and stability speed not judged in full:
    ``(jobs, [(case, curves)])``, ``on_done(job)`` after each (none where there are no
    such conditions)."""
    spoints = stability_points(spec.pressures_bar, spec.stability_speeds_hz, points)
    if not spoints:
        return [], []
    jobs = judge_jobs(designs, digitals, spoints, design_cfg)
    return jobs, _by_condition(stability_case, jobs,
                               {"cfg": judge_cfg, "settings": judge_settings(spec, judge_cfg)},
                               lambda i, r: on_done(jobs[i]))


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

    def guarded(m: str, make) -> list[Designed]:
        try:
            d = make()
        except SynthesisError as exc:
            failed[m] = synthesis_failure(m, str(exc))
            say(f"{m} failed", 1)
            return []
        say(f"{m} designed", 1)
        return [d]

    # the H∞ designs over the speed range that H∞'s design tries, μ's tries again
    trials: dict = {}

    def robust(m: str) -> list[Designed]:
        say(f"designing {m}", 0)
        return guarded(m, lambda: Designed(design(cfg, m, spec=spec, allow_unstable=True,
                                             progress=lambda msg: say(msg, 0),
                                             trials=trials)))

    if speed_scheduled(cfg):
        out = [Designed(design(cfg, "pid"))]
        say("pid designed", 1)

        def frozen_hinf() -> Designed:
            fz = design_frozen(cfg, cfg.operating.speed_rpm / 60.0, allow_unstable=True,
                               spec=spec)
            return Designed(fz)

        def lpv() -> Designed:
            speeds, states, _ = lpv_schedule(cfg, spec)
            d = design_lpv(cfg, speeds_hz=speeds, states=states, allow_unstable=True,
                           spec=spec)
            return Designed(d)

        return out + guarded("hinf", frozen_hinf) + robust("mu") + guarded("lpv", lpv)
    out = []
    for m in methods:
        if m in method_names(synthesised=True):
            out += robust(m)
        else:  # derived from the rig (the reference PID): no synthesis that can fail
            out.append(Designed(design(cfg, m)))
            say(f"{m} designed", 1)
    lost = _lost_over_speed(cfg, out)
    if lost:
        speeds, states, _ = lpv_schedule(cfg, spec)
        say(f"{' and '.join(lost)} designed at {cfg.operating.speed_rpm / 60.0:g} Hz lose the "
            f"rotor at other speeds: designing the LPV on speed, {speeds[0]:g}–{speeds[1]:g} "
            "Hz", 0)

        def speed_lpv() -> Designed:
            d = design_lpv(cfg, speeds_hz=speeds, states=states, allow_unstable=True,
                           spec=spec)
            return Designed(d)

        out += guarded("lpv", speed_lpv)
    return out


def _lost_over_speed(cfg: RigConfig, designs: list[Designed]) -> list[str]:
    """The fixed designs (H∞, μ; designed at the operating speed) whose full-order loop is
    unstable at another speed of the machine's range, standstill to the top speed: where
    the gyroscopics move the modes out of what one frozen design holds — also where the
    design over the speed range then found another design speed whose loop holds
    (``design_speed_hz``), or the design with the speed uncertain over the range
    (``speed_range_hz``): that design is stable, but one fixed controller spans the whole
    range and may stand in a poorer zone than the LPV, the controller scheduled on it,
    which the run then offers beside it. For them the main
    job adds the speed-scheduled LPV controller (:func:`ambseal.design.lpv_design.
    design_lpv`, thesis P3 §4) over standstill to the top speed, on the same design model
    (``[design] model_states``) — a rig with a speed range only."""
    if cfg.operating.speed_range_hz is None:
        return []
    f0 = cfg.operating.speed_rpm / 60.0
    out = []
    for d in designs:
        fo = d.result.full_order
        moved = (getattr(d.result, "design_speed_hz", None) is not None
                 or getattr(d.result, "speed_range_hz", None) is not None)
        if d.method in method_names(synthesised=True) and fo and (moved or (
                not fo["stable"] and abs(fo["speed_hz"] - f0) > 1e-9 * max(f0, 1.0))):
            out.append(d.method)
    return out


@with_numerics_threads
def run(rig: str | Path | None = None, out_dir: str | Path = "ambseal-out",
        progress: bool = True, truth: str | Path | None = None,
        identification: bool = True, overrides: tuple[str, ...] = (),
        allow_unstable: bool = False, command: str | None = None,
        force: bool = False) -> RunResult:
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
        (:mod:`ambseal.identify.fitting.procedure`) with the reference PID, designs H∞ and μ on the
        identified rig (unless it equals the rig file within its intervals:
        :func:`ambseal.identify.facility.design_model.design_rig`), judges every controller on the
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
    force : bool
        Replace the former run's files in ``out_dir`` that were changed since ambseal wrote
        them (without it they are the user's and the folder is refused).

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
    # the specification is the run's first stage, timed as the others are: its derived
    # defaults (the reference PID's corner and filters among them) judge loops too
    begun = ("specification", time.perf_counter(), time.process_time())
    spec = design_spec(cfg)
    points = operating_points(spec)
    final = Path(out_dir)
    # one run = one folder: written into a staging folder that replaces out_dir at the end
    with RunFolder(final, force) as out, \
            StageProgress(_stage_totals(cfg, points), display=progress and sys.stderr.isatty(),
                          begun=begun) as stages:
        (out / "controllers").mkdir()
        check_reference_rate(cfg, rig_path)  # before any stage, as validate refuses it
        st = _RunState(cfg, spec, points, judge_settings(spec, cfg), out, stages, allow_unstable,
                       truth_cfg)
        model = _model_stage(st)
        _design_stage(st)
        _judge_stage(st)
        stability = _speed_range(st.designs, st.digitals, spec, points, st.design_cfg,
                                 st.judge_cfg, stages, st.failed, allow_unstable)
        stability = _sampled_remedies(st, stability)
        stability = _scheduled_remedies(st, stability)
        stability = _amplifier_remedies(st, stability)
        _note_speed_lpv(st)
        metrics = _deliver_and_report(st, model, stability, rig_path, truth, command)
    exit_status = EXIT_FAILED if any(f.designed and not (allow_unstable and f.judged)
                                     for f in st.failed.values()) else 0
    return RunResult(final, final / "metrics.json", final / "report.html", metrics,
                     failed=metrics["failed"], exit_status=exit_status)


def _stage_totals(cfg: RigConfig, points: list[OperatingPoint]) -> dict[str, int | None]:
    """Steps per stage of the progress display (None: counted as they come)."""
    n_designs = len(method_names(fixed=True)) + int(speed_scheduled(cfg))  # and the LPV
    n_tr = int(cfg.design.tracked)  # off by default: minutes of LMI synthesis
    return {"model": 1, "design": n_designs, "judge": (n_designs + n_tr) * len(points),
            "identification": None,
            "design (identified)": len(method_names(synthesised=True)) + n_tr,
            "speed-range": None, "spin-up": 1, "signoff": 1, "ramp": 1, "report": 1}


@dataclass
class _RunState:
    """What the main job's stages hand on: the rig, its specification and judged
    conditions, and what each stage has made so far."""

    cfg: RigConfig
    spec: DesignSpec
    points: list[OperatingPoint]
    settings: JudgeSettings
    out: Path
    stages: StageProgress
    allow_unstable: bool
    truth_cfg: TruthSection | None
    failed: dict[str, FailedController] = field(default_factory=dict)
    designs: list[Designed] = field(default_factory=list)
    #: method → its digital controller (:func:`ambseal.app.commands.digitals_for`)
    digitals: dict = field(default_factory=dict)
    #: method → why it has no digital controller
    cannot_run: dict[str, str] = field(default_factory=dict)
    #: method → what its redesigns within the amplifier tried, where none was kept
    amplifier_tried: dict[str, str] = field(default_factory=dict)
    ident: Identified | None = None
    #: the judged cases: one job per design and condition, and its (case, curves)
    jobs: list[dict] = field(default_factory=list)
    judged: list[tuple] = field(default_factory=list)

    @property
    def design_cfg(self) -> RigConfig:
        """The rig the controllers are designed on: the identified one after identification."""
        return self.cfg if self.ident is None else self.ident.design_cfg

    @property
    def judge_cfg(self) -> RigConfig:
        """The rig the loops are judged on: the facility's truth after identification."""
        return self.cfg if self.ident is None else self.ident.truth_cfg

    def say(self, msg: str, steps: int = 0) -> None:
        self.stages.step(msg, steps)


@dataclass(frozen=True)
class _Model:
    n_states: int
    n_reduced: int
    unstable: list


def _model_stage(st: _RunState) -> _Model:
    st.stages.begin("model", "full order and modal reduction")
    full = build_plant(st.cfg)
    model = _Model(full.n_states, build_plant(st.cfg, reduced=True).n_states,
                   unstable_open_loop_poles(full.A, full.C))
    st.stages.step()
    return model


def _design_stage(st: _RunState) -> None:
    """The controllers; with a truth file the reference PID first, the identification on
    the virtual facility with it, then the synthesised designs on the identified rig
    (P5 §3)."""
    cfg, spec, points = st.cfg, st.spec, st.points
    lti_methods, synthesised = method_names(fixed=True), method_names(synthesised=True)
    st.stages.begin("design")
    early = st.truth_cfg is not None and not speed_scheduled(cfg)  # P5 §3: identify first
    st.designs = _controllers(cfg, spec, st.say, st.failed,
                              tuple(m for m in lti_methods if m not in synthesised)
                              if early else lti_methods)
    st.digitals, st.cannot_run = digitals_for(cfg, st.designs, points,
                                              lambda m: st.stages.step(m, 0))
    if st.truth_cfg is not None:
        if "pid" not in st.digitals:
            raise ConfigError("controller.pid: the virtual facility runs the reference "
                              "PID during identification, and "
                              + st.cannot_run.get("pid", "the rig has none"))
        st.stages.begin("identification")
        pid = st.digitals["pid"]  # a PID scheduled on speed: as it runs at the records' speed
        pid = (pid.discrete_at(2 * np.pi * cfg.operating.speed_rpm / 60.0)
               if isinstance(pid, ScheduledDigital) else pid.discrete)
        levitating, note = facility_controller(cfg, st.truth_cfg, pid)
        if note:
            st.say(note)
        st.ident = identification_stage(cfg, st.truth_cfg, st.out, st.stages.step, levitating,
                                        note)
    if early:
        st.stages.begin("design (identified)", st.ident.summary["design"]["designed_on"])
        robust = _controllers(st.ident.design_cfg, spec, st.say, st.failed, synthesised)
        more, more_cannot = digitals_for(st.ident.design_cfg, robust, points,
                                         lambda m: st.stages.step(m, 0))
        st.digitals.update(more)
        st.cannot_run.update(more_cannot)
        st.designs += robust
        facility_impulses(cfg, st.truth_cfg, st.ident, st.digitals, st.out)
    st.designs += tracked_designs(cfg, st.design_cfg, spec, points, st.say, st.digitals,
                                  st.cannot_run)


def _judge_designs(st: _RunState, designs, digitals, steps: int = 1):
    """Each design closed at each judged condition: (jobs, [(case, curves)])."""
    js = judge_jobs(designs, digitals, st.points, st.design_cfg)
    return js, _by_condition(judge_case, js, {"cfg": st.judge_cfg, "settings": st.settings},
                             lambda i, r: st.stages.step(f"{js[i].name} at {js[i].point.label}",
                                                         steps))


def _by_condition(fn, jobs, shared: dict, on_done) -> list:
    """``run_cases(fn, jobs)`` taken condition by condition, every controller at one
    condition in turn, results in the jobs' order: the condition's full-order plant and its
    sampled form are then built once and found in their memos by the next controllers
    (:func:`ambseal.model.build_plant`, :func:`ambseal.lti.discrete.zoh`), instead of
    once per controller."""
    order = sorted(range(len(jobs)), key=lambda i: (jobs[i].point.pressure_bar,
                                                    jobs[i].point.speed_rpm))
    done = run_cases(fn, [jobs[i] for i in order], shared=shared, workers=1,
                     raise_errors=True, on_done=lambda k, r: on_done(order[k], r))
    out = [None] * len(jobs)
    for k, i in enumerate(order):
        out[i] = done[k]
    return out


def _judge_stage(st: _RunState) -> None:
    """The judged loops decide (continuous with delay, and as it runs); a synthesised
    design that fails its judgement is remedied where it can be (:mod:`ambseal.app.
    remedies`), the remedied design replacing it."""
    st.stages.begin("judge")
    st.jobs, st.judged = _judge_designs(st, st.designs, st.digitals)
    # where the speed range is judged as well, a failure names the speed of every condition
    with_speed = bool(stability_points(st.spec.pressures_bar, st.spec.stability_speeds_hz,
                                       st.points))
    for d in st.designs:
        f = loop_failure(d.method, _judged_of(d.method, st.jobs, st.judged),
                         designed=d.method != "pid", kept=st.allow_unstable,
                         derived=st.cfg.controller.pid is None,
                         kind_of=kind_of(st.cfg, _closed_as(d, st.digitals)),
                         speed_in_labels=with_speed,
                         as_runs_only=d.synthesis_plant == "sampled")
        if f is not None:
            st.failed[d.method] = f
    if speed_scheduled(st.cfg):
        return
    for m in [m for m, f in st.failed.items() if f.designed and f.judged
              and m in method_names(synthesised=True)]:
        fixed, st.failed[m] = remedy(
            m, st.failed[m], [c for c, _ in _judged_of(m, st.jobs, st.judged)],
            st.design_cfg, st.spec, st.points,
            lambda ds, digs: _judge_designs(st, ds, digs, 0), lambda s: st.say(s, 0),
            speed_in_labels=with_speed)
        if fixed is not None:  # the remedied design replaces the failed one
            del st.failed[m]
            st.designs = [fixed.design if d.method == m else d for d in st.designs]
            st.digitals[m] = fixed.digital
            st.cannot_run.pop(m, None)  # the redesign runs on the target: it has a digital
            new = iter(zip(fixed.jobs, fixed.judged))
            st.jobs, st.judged = map(list, zip(*[next(new) if j.name == m else (j, r)
                                                 for j, r in zip(st.jobs, st.judged)]))


def _sampled_remedies(st: _RunState, stability: list) -> list:
    """Each H∞ or μ design whose loop is lost only as it runs (its continuous loop with
    the delay stable at every judged condition and stability speed), or that cannot run on
    the target, designed again on the sampled plant
    (:func:`ambseal.app.remedies.on_the_sampled_plant`): where that design holds, it
    replaces the first, its cases theirs; else the failure says what was tried. Returns
    the stability cases."""
    if speed_scheduled(st.cfg) or on_sampled_plant(st.design_cfg):
        return stability
    def speed_range(ds, digs) -> list:
        return _stability_cases(ds, digs, st.spec, st.points, st.design_cfg, st.judge_cfg,
                                lambda job: None)[1]

    begun = False
    for m in [d.method for d in st.designs if d.method in method_names(synthesised=True)]:
        if m in st.cannot_run:
            why = "the design on the continuous plant cannot run on the target"
        elif m in st.failed and st.failed[m].designed and st.failed[m].judged and all(
                c.stable for c in [c for c, _ in _judged_of(m, st.jobs, st.judged)]
                + [c for c in stability if c.controller == m]):
            why = "the design on the continuous plant lost the loop as it runs"
        else:
            continue
        if not begun:  # timed apart: a w-plane μ can take minutes
            st.stages.begin("sampled-redesign", "H∞ and μ lost only as they run")
            begun = True
        fixed, cases, tried = on_the_sampled_plant(
            m, why, st.design_cfg, st.spec, st.points,
            lambda ds, digs: _judge_designs(st, ds, digs, 0), speed_range,
            lambda line: st.say(line, 0))
        if fixed is None:
            if m in st.failed:
                st.failed[m] = replace(st.failed[m], reason=f"{st.failed[m].reason}. "
                                                            f"Tried: {tried}")
            else:
                st.cannot_run[m] = f"{st.cannot_run[m]}. Tried: {tried}"
            continue
        st.failed.pop(m, None)
        st.cannot_run.pop(m, None)
        stability = _replaced(st, fixed, stability, cases)
    return stability


def _scheduled_remedies(st: _RunState, stability: list) -> list:
    """An H∞ or μ over the speed range (on the continuous plant, or its redesign on the
    sampled plant, :func:`_sampled_remedies`) whose loops all hold but whose worst ISO
    14839-3 grade as it runs is beyond zone B, designed again scheduled on the spin speed
    (:func:`ambseal.app.remedies.scheduled_on_speed`): where that design holds at a
    better grade, it replaces the first, its cases theirs; else the first stays and its
    notes say what was tried. Returns the stability cases."""
    cfg = st.design_cfg
    if speed_scheduled(st.cfg) or on_sampled_plant(cfg) or cfg.design.one_speed \
            or cfg.operating.speed_range_hz is None:
        return stability
    for d in [d for d in st.designs if d.method in ("hinf", "mu")]:
        m = d.method
        if m in st.failed or m in st.cannot_run or d.result.scheduled is not None:
            continue
        zone = worst_zone_as_runs([c for c, _ in _judged_of(m, st.jobs, st.judged)]
                                  + [c for c in stability if c.controller == m])
        if zone is None or ZONE_SCALE.index(zone) <= ZONE_SCALE.index("B"):
            continue
        st.stages.begin("scheduled-redesign",
                        f"{method_label(m)} beyond zone B over the speed range")
        got = scheduled_on_speed(m, zone, cfg, st.spec, st.points, *_judging(st),
                                 lambda line: st.say(line, 0))
        stability = _kept(st, d, got, stability)
    return stability


def _judging(st: _RunState) -> tuple:
    """How a redesign is judged, as the run judged the first: its judged conditions and
    its stability speeds (``judge`` and ``stability`` of :mod:`ambseal.app.remedies`)."""
    return (lambda ds, digs: _judge_designs(st, ds, digs, 0),
            lambda ds, digs: _stability_cases(ds, digs, st.spec, st.points, st.design_cfg,
                                              st.judge_cfg, lambda job: None)[1])


def _kept(st: _RunState, first, got: tuple, stability: list) -> list:
    """A remedy's ``(Remedied or None, stability cases, what was tried)``: the redesign in
    place of ``first`` (:func:`_replaced`), or ``first`` kept with what was tried in its
    notes. Returns the stability cases."""
    fixed, cases, tried = got
    if fixed is None:
        first.summary["notes"] = [*first.summary.get("notes", []), f"Tried: {tried}"]
        return stability
    return _replaced(st, fixed, stability, cases)


def _amplifier_remedies(st: _RunState, stability: list) -> list:
    """An H∞ or μ whose loops all hold but whose unbalance current exceeds its amplifier
    at a continuous speed or above (:func:`~ambseal.analysis.amplifier.used_by_speed`
    above 1), on a rig whose own ``[design.rejection]`` is off, designed again
    with the amplifier's limit in its control weight
    (:func:`ambseal.app.remedies.within_the_amplifier`): where the current then fits and
    the loops hold, it replaces the first, its cases theirs; else the first stays and its
    notes say what was tried. Returns the stability cases."""
    cfg = st.design_cfg
    # with the rig's own unbalance force rejection on, the notch holds the unbalance where
    # it is on and the amplifier is judged with it (ambseal.analysis.amplifier)
    if speed_scheduled(st.cfg) or not cfg.amb or cfg.design.rejection.enabled \
            or any(a.bias_current is None for a in cfg.amb):
        return stability
    lo = cfg.operating.continuous_hz[0]
    clearances = rig_clearances_um(st.judge_cfg)
    def amplifier(method, jobs, judged):
        # from the minimum continuous speed up: below it (through a critical speed) the
        # bearings must balance the mode's share of the unbalance whatever the controller,
        # and the run's notch switches on there (switch_on_hz)
        speeds, used = used_by_speed(st.judge_cfg, _unbalance_currents(method, jobs, judged))
        return speeds[speeds >= lo], used[speeds >= lo]

    def fails(method, jobs, judged) -> str | None:
        # less current at Ω is a larger orbit where the bearings carried the unbalance; and
        # a softer loop may need more of its amplifier in the current impulse
        over = clearance_exceeded(worst_orbit_um([c.to_dict() for c, _ in judged]),
                                  clearances)
        if over is not None:
            return (f"its unbalance orbit exceeds {CLEARANCE_WORDS.get(over[0], over[0])} "
                    f"({over[1]:.3g} µm)")
        block = capacity_block(st.judge_cfg, [], _impulses(method, jobs, judged))
        return capacity_words(block) if saturates(block) else None

    for d in [d for d in st.designs if d.method in ("hinf", "mu")]:
        m = d.method
        if m in st.failed or m in st.cannot_run:
            continue
        used = amplifier(m, st.jobs, st.judged)
        if not used[1].size or not np.max(used[1]) > 1:
            continue
        zone = worst_zone_as_runs([c for c, _ in _judged_of(m, st.jobs, st.judged)]
                                  + [c for c in stability if c.controller == m])
        st.stages.begin("amplifier-redesign",
                        f"{method_label(m)} beyond its amplifier holding the unbalance")
        got = within_the_amplifier(
            d, used, zone, cfg, st.spec, st.points, *_judging(st),
            lambda jobs, judged, m=m: amplifier(m, jobs, judged),
            lambda jobs, judged, m=m: fails(m, jobs, judged),
            lambda line: st.say(line, 0))
        if got[0] is None:
            st.amplifier_tried[m] = got[2]
        stability = _kept(st, d, got, stability)
    return stability


def _replaced(st: _RunState, fixed, stability: list, cases: list) -> list:
    """A remedied design (:class:`ambseal.app.remedies.Remedied`) in place of its method's
    first: its design, digital controller and judged cases in ``st``; returns the
    stability cases with ``cases`` in place of the first's."""
    m = fixed.design.method
    st.designs = [fixed.design if d.method == m else d for d in st.designs]
    st.digitals[m] = fixed.digital
    new = iter(zip(fixed.jobs, fixed.judged))
    st.jobs, st.judged = map(list, zip(*[next(new) if j.name == m else (j, r)
                                         for j, r in zip(st.jobs, st.judged)]))
    return [c for c in stability if c.controller != m] + cases


def _note_speed_lpv(st: _RunState) -> None:
    """Where the LPV on speed holds the rotor over the speed range that a fixed design
    lost, that design's failure says so."""
    if speed_scheduled(st.cfg) or "lpv" not in {d.method for d in st.designs} \
            or "lpv" in st.failed:
        return
    for m in [m for m in method_names(synthesised=True)
              if m in st.failed and st.failed[m].judged]:
        st.failed[m] = replace(st.failed[m], reason=f"{st.failed[m].reason}; the LPV on "
                                                     "speed holds the rotor over the speed "
                                                     "range")


def _unbalance_currents(method: str, jobs, judged):
    """The unbalance's current references of ``method``'s stable judged loops, as it runs
    where it runs sampled: ``(condition, speeds Hz, currents, axes, static currents by
    axis or None)`` for :func:`~ambseal.analysis.amplifier.capacity_block`."""
    for job, (case, curves) in zip(jobs, judged):
        c = curves.get("discrete", curves)
        if job.name == method and "unbalance_current" in c:
            yield (case.label, *c["unbalance_current"], _static(c))


def _unbalance_orbits(method: str, jobs, judged):
    """The unbalance orbits of ``method``'s judged loops that hold, continuous and as it
    runs: ``(speeds Hz, worst orbit µm)`` each, as :func:`~ambseal.analysis.delivery.
    worst_orbit_um` counts them."""
    for job, (_, curves) in zip(jobs, judged):
        for c in (curves, curves.get("discrete") or {}):  # (a lost loop has none)
            if job.name == method and "unbalance" in c:
                yield c["unbalance"]


def _impulses(method: str, jobs, judged):
    """The current-impulse responses of ``method``'s stable judged loops, as it runs
    where it runs sampled: ``(condition, speed Hz, response, static currents by axis or
    None)`` for :func:`~ambseal.analysis.amplifier.capacity_block`."""
    for job, (case, curves) in zip(jobs, judged):
        c = curves.get("discrete", curves)
        if job.name == method and c.get("impulse") is not None:
            yield case.label, case.speed_hz, c["impulse"], _static(c)


def _static(curves: dict) -> dict | None:
    """A judged loop's static currents by axis (its seals' static load), or None."""
    static = curves.get("static_current")
    return None if static is None else dict(zip(static[1], static[0]))


@dataclass(frozen=True)
class _Notch:
    """A controller's unbalance force rejection, judged: the notch
    (:class:`~ambseal.design.synchronous_rejection.SynchronousRejection`), its loops at
    every condition judged where it is on (:func:`~ambseal.analysis.rejection.
    rejection_stability`), the conditions where one is lost, its effect over the speed
    range (:func:`~ambseal.analysis.rejection.rejection_effect`) and the clearance its
    orbit exceeds (``(name, µm)``, or None); ``first``, the notch from the earlier start
    that did not hold, where this one switches on later (:func:`_notches`)."""

    rejection: object
    rows: list
    lost: list
    effect: dict
    beyond: tuple | None
    first: "_Notch | None" = None

    @property
    def holds(self) -> bool:
        """Every loop with the notch holds and its orbit fits the rig's clearances."""
        return not self.lost and self.beyond is None

    @property
    def on_hz(self) -> float:
        """The speed (Hz) the notch is on from."""
        return self.rejection.controller.notch.on_rad_s / (2 * np.pi)

    def later_words(self) -> str:
        """Where the notch is on from a later start (else ""): from where, and why not
        from the first start."""
        if self.first is None:
            return ""
        return (f" from {self.on_hz:.4g} Hz (the controller alone holds the unbalance "
                f"below it): on from {self.first.on_hz:.4g} Hz it "
                f"{_why_not_notched(self.first).removeprefix(NOTCH_HEAD)}")


#: How :func:`_why_not_notched` begins.
NOTCH_HEAD = "its unbalance force rejection, switched on by the run, "


def _why_not_notched(n: _Notch) -> str:
    """Why a controller's unbalance force rejection, switched on by the run, does not
    hold it: the conditions where a loop is lost, the clearance its orbit exceeds, or,
    where it holds, that the amplifier saturates with it on as well (below the speed it
    is on from, as through a critical speed under the speed range, or in the impulse
    response, neither of which a notch at the rotational frequency reaches)."""
    head = NOTCH_HEAD
    if n.lost:
        return head + f"loses the loop at {'; '.join(n.lost)}"
    if n.beyond is None:
        return (head + "holds, but the amplifier saturates with it on as well: below "
                f"{n.on_hz:.4g} Hz, where it is off, or in the impulse response")
    name, clearance_um = n.beyond
    orbit = float(np.max(n.effect["orbit_um"]["with"]))
    return (head + f"whirls the rotor about its axis of inertia by {orbit:.3g} µm, beyond "
            f"{CLEARANCE_WORDS.get(name, name)} ({clearance_um:.3g} µm)")


def _notches(st: _RunState, methods=None, starts=None, used=None) -> dict[str, _Notch]:
    """Each controller's unbalance force rejection
    (:func:`~ambseal.design.synchronous_rejection.design_rejection` on the design rig) but
    those that cannot run on the target or are scheduled on another parameter, judged at
    every condition the run judges its controller at, in full and over the speed range,
    and shown against the controller alone on the judged rig: method → :class:`_Notch`.
    ``methods`` limits it to those controllers (all if None); ``starts`` gives, by method,
    the speed (Hz) its notch switches on at (:func:`~ambseal.analysis.amplifier.
    switch_on_hz`; the minimum continuous speed where not given). ``used`` gives, by
    method, the controller alone's :func:`~ambseal.analysis.amplifier.used_by_speed`: a
    notch that does not hold from its start is designed again from the later speed
    :func:`~ambseal.analysis.amplifier.later_switch_on_hz` finds, and kept where it holds
    from there (``_Notch.first`` then says why the first did not)."""
    st.stages.begin("rejection", "unbalance force rejection")
    r = st.cfg.design.rejection
    kw = {k: v for k, v in (("rate_fraction", r.rate_fraction), ("points", r.points))
          if v is not None}
    speeds = stability_points(st.spec.pressures_bar, st.spec.stability_speeds_hz, st.points)
    clearances = rig_clearances_um(st.cfg)
    out = {}
    for d in st.designs:
        g = st.digitals.get(d.method)
        if g is None or getattr(g, "parameter", SPEED) != SPEED \
                or (methods is not None and d.method not in methods):
            continue
        def notch(on):
            rej = design_rejection(st.design_cfg, d.controller, g, **kw, **(
                {} if on is None else {"speeds_hz": (on, st.cfg.operating.continuous_hz[1])}))
            rows = rejection_stability(st.judge_cfg, rej, [j.point for j in st.jobs
                                                           if j.name == d.method] + speeds,
                                       as_runs_only=d.synthesis_plant == "sampled")
            lost = lost_conditions(rows)
            effect = rejection_effect(st.judge_cfg, g, rej, st.settings)
            beyond = clearance_exceeded(float(np.max(effect["orbit_um"]["with"])), clearances)
            return _Notch(rej, rows, lost, effect, beyond)

        n = notch((starts or {}).get(d.method))
        if not n.holds and d.method in (used or {}):
            later = later_switch_on_hz(*used[d.method], n.on_hz)
            if later is not None:
                again = notch(later)
                n = replace(again, first=n) if again.holds else n
        out[d.method] = n
        st.stages.step()
    return out


def _rejections(st: _RunState, summaries: dict, notches: dict[str, _Notch]) -> dict:
    """Each delivered controller's unbalance force rejection (:func:`_notches`), switched
    on, then through a speed step, under a sensor runout on the virtual facility
    (:mod:`ambseal.analysis.rejection`): its ``rejection`` block in ``summaries``, and for
    the figures ``{"effects": method → the effect's curves, "facility": method →
    FacilityRejection, "speed_step": method → SpeedStep}``. A notch that loses a loop, or
    whose orbit exceeds a clearance of the rig
    (:func:`ambseal.analysis.delivery.clearance_exceeded`: ``beyond`` in the block), is
    said so on stderr and in the block, not exported; the controller alone is delivered
    still. A controller not delivered gets no notch files."""
    r = st.cfg.design.rejection
    effects, facility, steps = {}, {}, {}
    for m, n in notches.items():
        if m not in summaries:
            continue
        rej, e, lost, beyond, g = n.rejection, n.effect, n.lost, n.beyond, st.digitals[m]
        effects[m] = e
        orbit = float(np.max(e["orbit_um"]["with"]))
        summaries[m]["rejection"] = {
            **rej.to_dict(), "stable": not lost, "conditions": n.rows,
            **{q: {k: float(np.max(v)) for k, v in e[q].items()}
               for q in ("current_a", "force_n", "orbit_um")},
            "current_ratio": float(np.max(e["current_a"]["with"]
                                          / np.maximum(e["current_a"]["without"], 1e-300))),
            "beyond": None if beyond is None else {"clearance": beyond[0],
                                                   "clearance_um": beyond[1],
                                                   "orbit_um": orbit},
            "first_start": None if n.first is None else {
                "on_from_hz": n.first.on_hz,
                "why": _why_not_notched(n.first).removeprefix(NOTCH_HEAD)}}
        delivered = summaries[m].get("discretisation") is not None
        if lost:  # said, not delivered
            st.say(f"{m}: its unbalance force rejection loses the loop at {'; '.join(lost)}")
        elif beyond is not None:
            st.say(f"{m}: with its unbalance force rejection the orbit, {orbit:.3g} µm, "
                   f"exceeds {CLEARANCE_WORDS.get(beyond[0], beyond[0])} ({beyond[1]:.3g} µm):"
                   " not exported")
        elif delivered:  # on the facility at the top speed (the most synchronous current), then
            # beside the controller's files: its notch as a file and as C
            lo, top = float(rej.speeds_hz[0]), float(rej.speeds_hz[-1])
            # what runs: the controller alone below its notch, the notch from there up
            summaries[m]["rejection"]["orbit_delivered_um"] = notched_orbit_um(
                _unbalance_orbits(m, st.jobs, st.judged), lo, orbit)
            runout = None if r.runout_um is None else 1e-6 * r.runout_um
            fac = facility_rejection(st.judge_cfg, g, rej, top, runout_m=runout)
            # and a speed step to the top from 10 % below it (within the range)
            step = facility_speed_step(st.judge_cfg, g, rej, max(lo, 0.9 * top), top,
                                       runout_m=runout)
            summaries[m]["rejection"]["facility"] = {**fac.to_dict(),
                                                     "speed_step": step.to_dict()}
            facility[m] = fac
            steps[m] = step
            if not fac.after_a < 1e-2 * fac.before_a:
                st.say(f"{m}: on the virtual facility at {top:g} Hz its notch leaves "
                       f"{fac.after_a:.3g} A of synchronous current of {fac.before_a:.3g} A")
            folder = st.out / "controllers"
            files = [export_notch(rej.digital.notch, folder / f"rejection_{m}.json", m),
                     *write_notch_c(rej.digital.notch, folder, f"ambseal_{m}_rejection")]
            summaries[m]["rejection"]["files"] = [
                f.relative_to(st.out).as_posix() for f in files]
    return {"effects": effects, "facility": facility, "speed_step": steps}


def _deliver_and_report(st: _RunState, model: _Model, stability: list, rig_path: Path,
                        truth, command: str | None) -> dict:
    """Export the delivered controllers, run the speed-scheduled and tracked extras, write
    metrics.json and the report; returns the metrics as written."""
    cfg, out, stages = st.cfg, st.out, st.stages
    cases = [case for case, _ in st.judged]
    case_dicts = [case.to_dict() for case in cases]
    curves = [(j.name, j.point, case, c)
              for j, case, (_, c) in zip(st.jobs, case_dicts, st.judged)]
    currents = {d.method: list(_unbalance_currents(d.method, st.jobs, st.judged))
                for d in st.designs}
    automatic: set[str] = set()
    lo = cfg.operating.continuous_hz[0]
    # on below the continuous speeds where the controller alone saturates the amplifier on
    # the way up to them (switch_on_hz: through a critical speed)
    used = {m: used_by_speed(cfg, entries) for m, entries in currents.items()
            if lo > 0 and cfg.amb and all(a.bias_current is not None for a in cfg.amb)}
    starts = {m: switch_on_hz(*u, lo) for m, u in used.items()}
    if cfg.design.rejection.enabled:
        notches = _notches(st, starts=starts, used=used)
        for m, n in notches.items():
            if n.first is not None:
                st.say(f"{m}: its unbalance force rejection is on{n.later_words()}")
    else:
        # the amplifier's limit is part of the design: a controller whose loops hold but
        # which alone cannot hold the unbalance (a fraction above 1 in the unbalance
        # response, the impulse left out: no notch helps it) runs with its unbalance force
        # rejection, switched on by the run (Herzog, Bühler, Gähler & Larsonneur 1996)
        # and said so in its verdict
        # (a notch at the rotational frequency needs a rotor that turns)
        turns = max((cfg.operating.speed_rpm / 60.0, *(cfg.operating.speed_range_hz or ()))) > 0
        automatic = {m for m, entries in currents.items() if turns
                     and m not in st.failed and saturates(capacity_block(cfg, entries))}
        notches = _notches(st, automatic, starts, used) if automatic else {}
        for m in sorted(automatic):
            below = (f" from {starts[m]:.4g} Hz, below the minimum continuous speed"
                     if starts.get(m, lo) < lo else "")
            if m in notches and notches[m].first is not None:
                below = notches[m].later_words()
            st.say(f"{m}: the amplifier cannot hold the unbalance with the controller alone; "
                   f"its unbalance force rejection is switched on{below}")
    alone = {}
    for m, n in notches.items():  # a notch that holds runs with its controller
        if n.holds:
            alone[m] = capacity_block(cfg, currents[m], _impulses(m, st.jobs, st.judged))
            currents[m] = list(notched_currents(
                currents[m], n.rejection.controller.notch.on_rad_s / (2 * np.pi),
                float(np.max(n.effect["current_a"]["with"]))))
    capacity = {m: capacity_block(cfg, entries, _impulses(m, st.jobs, st.judged))
                for m, entries in currents.items()}
    for m, block in alone.items():
        if block is not None and capacity[m] is not None:
            capacity[m]["without_rejection"] = {q: v for q, v in block.items()
                                                if q.endswith("_used")}
            capacity[m]["rejection_automatic"] = m in automatic
    for m, block in capacity.items():  # an amplifier that saturates fails its controller
        f = saturation_failure(m, block, designed=m != "pid", kept=st.allow_unstable,
                               derived=cfg.controller.pid is None)
        if f is not None and m in st.amplifier_tried:
            f = replace(f, reason=f"{f.reason}; designed again with the amplifier's limit in "
                                  f"its control weight: {st.amplifier_tried[m]}")
        if f is not None and m in automatic and m in notches:
            f = replace(f, reason=f"{f.reason}; {_why_not_notched(notches[m])}")
        if f is not None:
            st.failed[m] = also_failed(st.failed.get(m), f)
    clearances = rig_clearances_um(cfg)
    for m in capacity:  # an orbit beyond a clearance runs the rotor on its backup bearings
        f = clearance_failure(m, [c for j, c in zip(st.jobs, case_dicts) if j.name == m],
                              clearances, designed=m != "pid", kept=st.allow_unstable,
                              derived=cfg.controller.pid is None)
        if f is not None:
            st.failed[m] = also_failed(st.failed.get(m), f)
    # a failed design is judged and reported, not delivered (unless asked for)
    held = {m for m, f in st.failed.items() if f.designed and not st.allow_unstable}
    summaries = export_all(st.designs, {m: g for m, g in st.digitals.items() if m not in held},
                           case_dicts, out / "controllers", st.failed, st.allow_unstable,
                           [s.to_dict() for s in stability])
    for m, summary in summaries.items():
        summary["capacity"] = capacity.get(m)
    rejections = _rejections(st, summaries, notches) if notches else {}
    ident = st.ident
    figs, sections = ([], []) if ident is None else (ident.figs, ident.sections)
    spinup = ramp = None
    if speed_scheduled(cfg):
        stages.begin("spin-up", "spin-up and frozen sensitivities")
        spinup, sims, sens = judge_spinup(  # LPV against μ: P3 Fig. 11
            cfg, {d.method: d.controller for d in st.designs if d.method in ("mu", "lpv")})
        figs += spinup_figures(out, sims, sens, cfg.operating.speed_range_hz)
        stages.step()
    signoff = None
    if cfg.stage:  # the machine's stages are given: its sign-off, as it runs
        stages.begin("signoff", "API 617 and ISO 14839-2")
        results = [sign_off(cfg, g, name=m, progress=lambda s: st.say(s, 0))
                   for m, g in st.digitals.items()
                   if m not in held and m not in st.cannot_run
                   and getattr(g, "parameter", SPEED) == SPEED]
        if results:
            signoff = Signoff.of(results, verdict_line(results))
            more_figs, more_sections = signoff_report(out, results, cfg.rotor.name,
                                                      cfg.signoff.csr_boundary)
            figs, sections = figs + more_figs, more_sections + sections
        stages.step()
    if cfg.design.tracked and st.truth_cfg is not None:
        stages.begin("ramp", "0 → 3× nominal pressure on the virtual facility")
        ramp, fig = tracked_ramp(cfg, st.truth_cfg, st.designs, st.digitals, ident,
                                 st.settings, out, st.say)
        figs.append(fig)
    metrics = RunMetrics(
        schema_version=SCHEMA_VERSION, rig=str(rig_path), rig_name=cfg.rotor.name,
        open_loop=OpenLoop([[float(z.real), float(z.imag)] for z in model.unstable],
                           model.n_states, model.n_reduced),
        unbalance=st.settings.unbalance_dict(), design_spec=st.spec.to_dict(),
        controllers={m: ControllerSummary.from_dict(s) for m, s in summaries.items()},
        cannot_run=st.cannot_run, cases=cases, stability=stability, failed=st.failed,
        identification=None if ident is None else ident.summary, spinup=spinup,
        ramp=ramp, signoff=signoff).to_dict()
    stages.begin("report")
    write_json(out / "metrics.json", metrics)
    # a design on the sampled plant as it runs: its w-plane form's gains are warped
    figs.append(gains_figure(out, [(d.method, K.statespace() if K is not d.controller
                                    else frozen_at(K, cfg.operating, st.design_cfg))
                                   for d in st.designs
                                   for K in [_closed_as(d, st.digitals)]]))
    figs += capacity_figure(out, cfg, currents)
    figs += rejection_figure(out, rejections)
    sections.append(statics_section(rotor_at_rest(cfg).to_dict()))
    write_run_report(out, f"ambseal — {cfg.rotor.name}", stamp(rig_path, command),
                     metrics, curves, figs, sections, clearances,
                     judged_on(cfg, st.truth_cfg if ident is not None else None, truth))
    stages.step()
    return metrics
