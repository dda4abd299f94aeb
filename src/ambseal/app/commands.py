"""The ``design``, ``identify``, ``validate`` and ``track`` commands: load, call the stage,
write the files.

Wiring only, like :mod:`ambseal.app.pipeline`: every number comes from :mod:`ambseal.design`
and :mod:`ambseal.identify`, every figure from :mod:`ambseal.report`, every file through a
temporary name and a rename (:mod:`ambseal.files`).
"""

from __future__ import annotations

import hashlib
import logging
import math
import sys
from dataclasses import asdict, dataclass, field, replace
from pathlib import Path

import control
import numpy as np

from ambseal.analysis import judge_settings, modes_as_run, operating_points, rotor_at_rest
from ambseal.config import default_rig_path, dump_rig, load_rig, method_names, rig_with_values
from ambseal.design import (
    Design,
    controller_from_metadata,
    design,
    design_lpv,
    design_rise,
    design_spec,
    full_order_check,
    full_order_words,
    lpv_schedule,
    pid_description,
    reference_pid,
)
from ambseal.errors import (ConfigError, DataError, IdentificationError, SynthesisError,
                            with_source)
from ambseal.export import export_controller, load_controller, loop_verdict, write_c
from ambseal.files import writable_folder, write_json, write_text
from ambseal.identify import (
    MISMATCH,
    TrackingSettings,
    advice,
    at_speed,
    check_excitation,
    check_record_metadata,
    design_rig,
    fit_failure,
    frf_checks,
    identify,
    implausible,
    impulse_checks,
    interval_check,
    load_measurement,
    prepare_facility,
    record_spread,
    require_finite,
    thesis_procedure,
    track,
    truth_errors,
    truth_rig,
    with_static_record,
)
from ambseal.lti import finite_or_none
from ambseal.machine import (
    SPEED,
    ScheduledController,
    ScheduledDigital,
    scheduled_digital,
    table_grid,
)
from ambseal.model import (
    assemble_rotor,
    build_mesh,
    build_plant,
    build_system,
    channel_names,
    pressure_for_k,
    seal_values,
)
from ambseal.model.modes import modes
from ambseal.report import (
    correlation_figure,
    error_budget_figure,
    facility_impulse_report,
    fit_timeseries_figure,
    identification_report,
    residual_figure,
    target_difference,
    tracking_figure,
)
from ambseal.robust import (
    check_rate,
    digital_controller,
    is_stable,
    peak_difference,
    sampled_plants,
    unstable_poles,
)

__all__ = ["Designed", "Identified", "identification_stage", "facility_impulses", "design_files",
           "identify_files", "export_design", "show_defaults",
           "validate_summary", "track_files", "export_all", "digital_for", "choice_margins",
           "judged_margins", "digitals_for", "target_pid", "facility_controller"]


@dataclass(frozen=True)
class Designed:
    """A controller of the main job: its design and the summary ``metrics.json`` gives it
    (by default the design's own, :meth:`~ambseal.design.Design.summary`; the run adds
    to it where it says more: a remedy, this run's design time)."""

    result: Design
    summary: dict | None = None

    def __post_init__(self):
        if self.summary is None:
            object.__setattr__(self, "summary", self.result.summary())

    @property
    def method(self) -> str:
        """The design's method (:data:`ambseal.config.METHODS`)."""
        return self.result.method

    @property
    def controller(self) -> control.StateSpace | ScheduledController:
        """The controller that runs (:attr:`ambseal.design.Design.controller`)."""
        return self.result.controller

    @property
    def synthesis_plant(self) -> str:
        """``"sampled"`` for an H∞ or μ synthesised on the sampled plant (``[design]
        synthesis_plant``, :mod:`ambseal.robust.w_plane`), else ``"continuous"``."""
        return getattr(self.result, "synthesis_plant", "continuous")


def digital_for(cfg, method: str, controller, result, points, cache: dict | None = None
                ) -> object:
    """The digital controller of a design, its discretisation chosen on the full-order
    plants at the judged conditions (:mod:`ambseal.robust.digital`): a
    :class:`~ambseal.robust.digital.DigitalController`, or for a scheduled controller a
    :class:`~ambseal.machine.scheduled_digital.ScheduledDigital` whose interpolation is
    also checked between table entries (at speeds, or at the pressures that give the seal
    coefficient it is scheduled on). ``cache`` (a dict kept by the caller) shares the
    sampled plants between the controllers of one rig."""

    fs, delay = cfg.controller.sample_rate_hz, cfg.controller.delay_samples
    conds = _conditions(cfg, points)

    def plant(p_bar, rpm):
        pl = build_plant(cfg, pressure_bar=p_bar, speed_rpm=rpm)
        G = pl.select_inputs([pl.input_names[j] for j in pl.current_inputs()])
        return tuple(np.asarray(X, float) for X in (G.A, G.B, G.C, G.D))

    if not isinstance(controller, ScheduledController):
        cache = {} if cache is None else cache
        rise = ((lambda Kr: design_rise(result, Kr, getattr(result, "omega", None), fs / 2))
                if method in method_names(synthesised=True) else None)
        # a design on the sampled plant: its Tustin transform is the discrete design
        w_plane = getattr(result, "synthesis_plant", "continuous") == "sampled"
        try:  # before the plants
            if not w_plane:
                check_rate(controller, fs, delay, removable=rise is not None)
        except ConfigError as exc:
            if method != "pid" or written_pid(cfg):
                raise
            # ambseal's own PID: the user's rig is not wrong, the derived controller fails
            raise SynthesisError(f"the PID derived from the rig cannot run at the target's "
                                 f"rate ({exc}); set [controller.pid] or "
                                 "[[controller.filter]]") from None
        if "plants" not in cache:
            cache["plants"] = sampled_plants([plant(*c) for c in conds], fs,
                                             delay_samples=delay)
        try:
            return digital_controller(controller, fs, cache["plants"],
                                      delay_samples=delay, rise=rise, w_plane=w_plane)
        except SynthesisError as exc:
            if method != "pid" or written_pid(cfg):
                raise
            # the user's remedy for ambseal's own PID is their own, not another rate
            raise SynthesisError(f"{exc}; this PID is the one ambseal derives from the rig: "
                                 "set [controller.pid] (and [[controller.filter]]) to run "
                                 "your own") from None

    W = table_grid(controller.table_theta)  # the table's θ (speeds or SI), made denser
    # between table entries at 1/8, 3/8, 5/8, 7/8 of the table: the interpolation judged
    mids = [(W[j] + W[j + 1]) / 2 for j in (np.arange(1, 8, 2) * (W.size - 1)) // 8]
    if controller.parameter == SPEED:
        speeds = [2 * math.pi * c[1] / 60.0 for c in conds] + mids
        plants = [(w, plant(cfg.operating.pressure_bar, 60.0 * w / (2 * math.pi)))
                  for w in speeds]
    else:  # a seal's k: the judged pressures and those that give the θ between entries
        if pressure_for_k(cfg.seal, controller.parameter, 0.0) is None:
            raise ConfigError(f"{method}: no digital table for a controller scheduled on "
                              f"{controller.parameter!r}: only on a seal's k affine in the "
                              "pressure drop")
        conds = [(p, cfg.operating.speed_rpm) for p in dict.fromkeys(
            [c[0] for c in conds] + [pressure_for_k(cfg.seal, controller.parameter, th)
                                     for th in mids])]
        plants = [(seal_values(cfg.seal, p)[controller.parameter], plant(p, rpm))
                  for p, rpm in conds]
    return scheduled_digital(controller, W, fs, plants, delay_samples=delay,
                             name=f"K_{method}")


def digitals_for(cfg, designs, points, say=None) -> tuple[dict, dict]:
    """:func:`digital_for` of each of ``ambseal run``'s designs, sharing the sampled plants.

    A controller that cannot run on the target (no discretisation keeps its sampled,
    delayed loop stable where the continuous loop is, or an unstable pole too fast for the
    rate: :class:`~ambseal.errors.SynthesisError`) is left out, the others go on;
    ``say(line)``, if given, is called with the reason.

    Returns
    -------
    (digitals, cannot_run)
        ``{method: DigitalController}`` and ``{method: one line saying which controller
        cannot run and why}``.
    """

    cache: dict = {}
    digitals, cannot_run = {}, {}
    for d in designs:
        try:
            digitals[d.method] = digital_for(cfg, d.method, d.controller, d.result, points,
                                             cache)
        except SynthesisError as exc:
            cannot_run[d.method] = (f"{d.method} cannot run on the target, judged as designed "
                                    f"(continuous) only: {exc}")
            if say is not None:
                say(cannot_run[d.method])
    return digitals, cannot_run


def target_pid(cfg):
    """The rig's reference PID (``[controller.pid]``, else derived from the rig) as it runs
    on the target: the discrete controller :func:`digital_for` chooses and ``ambseal run``
    exports and judges (:class:`~ambseal.robust.digital_loop.DiscreteController`, with its
    discretisation in ``description``) — the one that levitates the virtual facility in
    ``ambseal acquire`` and the main job's identification."""

    res = design(cfg, "pid")
    dc = digital_for(cfg, "pid", res.K, res, operating_points(design_spec(cfg)))
    return replace(dc.discrete, description={"type": "pid", **pid_description(reference_pid(cfg)),
                                             "discretisation": dc.method,
                                             "prewarp_hz": dc.prewarp_hz})


def facility_controller(cfg, truth, pid):
    """The controller that levitates the virtual facility while it is identified, and a
    note when it is not the rig's reference PID.

    A commissioning engineer levitates a new machine first at standstill without pressure
    (where the identification's first records are taken, P2 §3, P4 §3.2) with a
    controller that holds it there. The rig's reference PID as it runs (``pid``, from
    ``[controller.pid]``) is that controller where it stabilises the facility's loop
    there; where it does not and the rig file gives its own PID (or filters), the PID
    derived from the rig with its flexible-mode filters
    (:func:`ambseal.design.pid.pid_from_rig`) is tried, as it will run (:func:`target_pid`).
    Where neither holds, ``pid`` is returned and the acquisition refuses it, naming the
    pole.

    Parameters
    ----------
    cfg : RigConfig
        The rig file.
    truth : TruthSection
        The facility's truth.
    pid : DiscreteController
        The reference PID as it runs on the target.

    Returns
    -------
    (DiscreteController, str or None)
    """
    fs = cfg.controller.sample_rate_hz
    fac = prepare_facility(at_speed(cfg, 0.0), truth, fs, pressure_bar=0.0)
    z = fac.loop_poles(pid)
    own = cfg.controller.pid is not None or cfg.controller.filter is not None
    if is_stable(z, fac.T) or not own:
        return pid, None
    derived = cfg.model_copy(update={"controller": cfg.controller.model_copy(
        update={"pid": None, "filter": None})})
    alt = target_pid(derived)
    if not is_stable(fac.loop_poles(alt), fac.T):
        return pid, None
    worst = complex(unstable_poles(z, fac.T)[0])
    f_hz = abs(np.angle(worst)) * fs / (2 * np.pi)
    return alt, (f"the rig file's PID does not hold the virtual facility at standstill, "
                 f"0 bar (a sampled-loop pole |z| = {abs(worst):.5f} at {f_hz:.4g} Hz): the "
                 "identification levitates it with the PID derived from the rig (kp "
                 f"{alt.description['kp']:.3g} A/m, {len(alt.description.get('filters', []))}"
                 " filter(s))")


def _conditions(cfg, points) -> list[tuple[float, float]]:
    """(pressure bar, speed rpm) of the judged points, the nominal one first."""
    nominal = (cfg.operating.pressure_bar, cfg.operating.speed_rpm)
    return sorted({(p.pressure_bar, p.speed_rpm) for p in points}, key=lambda c: c != nominal)


def choice_margins(cfg, points, digital) -> list[dict]:
    """The discrete margins the choice of discretisation judged (:mod:`ambseal.robust.
    digital`): per condition the largest ``|z|`` and the σ̄(S_o) peaks of the chosen
    candidate (``choice``: with ``+fast`` when its fast poles were kept, the controller
    exported), with the loop's delay, on the sampled full-order plant."""
    chosen = getattr(digital, "choice", "") or digital.method
    c = next(c for c in digital.candidates if c["method"] == chosen)
    if "speeds_hz" in c:  # scheduled: the judged speeds and between table entries
        speeds = c["speeds_hz"]
        pressures = [cfg.operating.pressure_bar] * len(speeds)
    else:
        pressures, rpms = zip(*_conditions(cfg, points))
        speeds = [r / 60.0 for r in rpms]
    return [{"pressure_bar": p, "speed_hz": f, "stable": z < 1, "max_abs_pole_z": z,
             "sensitivity_peak": sd, "sensitivity_peak_continuous": sc}
            for p, f, z, sd, sc in zip(pressures, speeds, c["max_abs_z"],
                                       c["sensitivity_peak"],
                                       c["sensitivity_peak_continuous"])]


def judged_as_runs(cfg, ctrl) -> list[dict]:
    """The loop of a discrete controller as it runs (the sampled full-order plant, its
    delay; :func:`ambseal.analysis.campbell.modes_as_run`) at the conditions a run judges:
    the judged points and the stability speeds from standstill to the top speed at the
    nominal pressure. Per condition ``pressure_bar``, ``speed_hz`` and ``stable``."""
    spec = design_spec(cfg)
    conditions = sorted({(p, rpm / 60.0) for p, rpm in _conditions(cfg, operating_points(spec))}
                        | {(cfg.operating.pressure_bar, float(f))
                           for f in spec.stability_speeds_hz})
    top = 0.99 * 0.5 * float(ctrl.sample_rate_hz)  # the modes below Nyquist
    return [{"pressure_bar": p, "speed_hz": f,
             "stable": bool(modes_as_run(cfg, ctrl, speed_hz=f, max_hz=top,
                                         pressure_bar=p).stable)}
            for p, f in conditions]


def warn_unheld(name: str, verdict: dict) -> None:
    """One line on stderr for an exported controller whose judged loop does not hold."""
    if verdict["loop_holds"] is False:
        print(f"ambseal: warning: {name}: the judged loop {verdict['verdict']}",
              file=sys.stderr)


def export_design(method: str, digital, summary_dict: dict, out: Path, judged=None,
                  verdict: dict | None = None) -> list[Path]:
    """Write a designed controller as it runs (``controller_<method>.json/.npz/.mat``,
    :func:`ambseal.export.controller_files.export_controller`) with the judged discrete
    margins and the verdict on its loop (:func:`~ambseal.export.controller_files.
    loop_verdict`), and its design summary with the discretisation
    (``design_<method>.json``)."""

    files = [export_controller(digital, out / f"controller_{method}{ext}", judged, verdict)
             for ext in (".json", ".npz", ".mat")]
    files.append(write_json(out / f"design_{method}.json",
                            {**summary_dict, "discretisation": digital.to_dict()}))
    return files


def show_defaults(rig: str | Path, overrides=()) -> str:
    """``ambseal design RIG --show-defaults``: the rig's resolved ``[design]`` part as TOML
    with the rule behind each value (:meth:`ambseal.design.specs.DesignSpec.to_toml`)."""

    cfg = load_rig(rig, overrides)
    return f"# {cfg.rotor.name}: resolved design specification\n" + design_spec(cfg).to_toml()


def export_all(designs, digitals: dict, cases: list[dict], out: Path,
               failed: dict | None = None, allow_unstable: bool = False,
               speed_range: list[dict] = ()) -> dict:
    """``ambseal run``'s controllers: each as it runs (:func:`export_design` with its judged
    discrete margins and the run's verdict: ``failed``'s reason, by method, and where its
    loop was judged, the ``speed_range`` cases included) and as C
    (:func:`ambseal.export.codegen.write_c`); returns the design summaries with their
    ``discretisation`` for ``metrics.json`` (``None`` for a controller without a digital
    one in ``digitals``: nothing of it is exported)."""

    summaries = {}
    for d in designs:
        digital = digitals.get(d.method)
        if digital is None:  # cannot run on the target (metrics' "cannot_run"): no export
            summaries[d.method] = {**d.summary, "discretisation": None}
            continue
        judged = judged_margins(cases, d.method)
        failure = (failed or {}).get(d.method)
        verdict = loop_verdict(judged + judged_margins(list(speed_range), d.method),
                               None if failure is None else failure.reason, allow_unstable)
        export_design(d.method, digital, d.result.to_dict(), out, judged, verdict)
        write_c(digital, out, f"ambseal_{d.method}", verdict=verdict)
        disc = digital.to_dict()  # the difference as judged (grids refined at the peaks)
        disc["peak_difference"] = peak_difference(
            target_difference([c for c in cases if c["controller"] == d.method]),
            digital.method, digital.removed_poles_hz)
        summaries[d.method] = {**d.summary, "discretisation": disc}
    return summaries


def judged_margins(cases: list[dict], method: str) -> list[dict]:
    """The discrete blocks of one controller's cases, with their conditions."""
    return [{"pressure_bar": c["pressure_bar"], "speed_hz": c["speed_hz"], **c["discrete"]}
            for c in cases if c["controller"] == method and c.get("discrete")]


@dataclass
class Identified:
    """The identification stage of the main job: ``summary`` for ``metrics.json``, its
    figures and report sections, the procedure's ``result``, the rig the robust controllers
    are designed on (``design_cfg``, :func:`ambseal.identify.facility.design_model.design_rig`) and
    the truth they are judged on (``truth_cfg``)."""

    summary: dict
    figs: list
    sections: list
    result: object
    design_cfg: object
    truth_cfg: object
    extra: dict = field(default_factory=dict)


def identification_stage(cfg, truth, out: Path, say, controller,
                         levitated_by: str | None = None) -> Identified:
    """The thesis's identification procedure on the virtual facility, its files, the FRF
    checks of the identified model, its figures and report section, and the rig to design
    on. ``controller`` is the exported, judged discrete reference PID (the facility runs
    exactly that object), or the one :func:`facility_controller` chose instead, with
    ``levitated_by`` saying why."""

    res = thesis_procedure(cfg, truth, controller, progress=say)
    write_json(out / "identification.json", res.to_dict())
    write_text(out / "identified_rig.toml",
               dump_rig(res.identified, "Identified by `ambseal run` from the virtual test "
                        "facility (thesis P2, P4, P5 procedure)"))
    say("identification: chirp FRF check of the identified model")
    checks = frf_checks(cfg, truth, res, controller)
    seal = cfg.seal[0].name if cfg.seal else None
    errors = truth_errors(res, seal)
    figs, sections = identification_report(out, res, errors, checks, truth, seal,
                                           cfg.operating.pressure_bar, levitated_by)
    a = res.amb
    design_cfg, note = design_rig(cfg, res)
    summary = {"parameters": errors, "converged": bool(a.converged),
               "model_check": a.model_check(), "interval_check": interval_check(errors),
               "nrmse_fit_pct": {k: (float(v) if math.isfinite(v) else None)
                                 for k, v in a.nrmse_fit_pct.items()},
               "design": note, "judged_on": "virtual facility (truth file, full order)",
               **({"levitated_by": levitated_by} if levitated_by else {})}
    return Identified(summary, figs, sections, res, design_cfg, truth_rig(cfg, truth))


def discrete_as_runs(cfg, digital, speed_rad_s: float, pressure_bar: float):
    """The discrete controller a digital one runs as at a speed and pressure drop: a fixed
    one's own, a scheduled table's entry at the speed or at the seal coefficient of that
    pressure drop (:meth:`~ambseal.machine.ScheduledDigital.discrete_at`)."""
    if not isinstance(digital, ScheduledDigital):
        return digital.discrete
    return digital.discrete_at(digital.theta_at(speed_rad_s,
                                                seal_values(cfg.seal, pressure_bar)))


def levitating_controller(cfg, path, speed_hz: float | None, pressure_bar: float):
    """The controller of a file ambseal wrote (:func:`ambseal.export.load_controller`) as
    it runs on the virtual facility at a speed (Hz; default the operating speed) and
    pressure drop (bar): ``acquire --controller`` levitates a rig with it where the
    reference PID cannot (a continuous file is discretised for the rig's target first, as
    ``design`` does).

    Raises
    ------
    DataError, ConfigError
        A file that is not this rig's controller, or one the target cannot run."""
    ctrl = load_controller(path, channel_names(cfg))
    if not hasattr(ctrl, "discrete"):
        try:
            ctrl = digital_for(cfg, "file", ctrl, None, operating_points(design_spec(cfg)))
        except ConfigError as exc:
            raise ConfigError(f"{path} holds a continuous controller, which acquire "
                              f"discretises for the rig's target: {exc}") from None
    f = abs(cfg.operating.speed_rpm) / 60.0 if speed_hz is None else float(speed_hz)
    return discrete_as_runs(cfg, ctrl, 2 * math.pi * f, pressure_bar)


def facility_impulses(cfg, truth, ident: Identified, digitals: dict, out: Path) -> None:
    """Each digital controller on the virtual facility and on the identified model: impulse
    responses at 0 bar and the nominal pressure drop (P5 Figs. 15–16), into ``ident``'s
    summary, figures and report sections."""

    w = 2 * math.pi * cfg.operating.speed_rpm / 60.0

    def as_runs(d):
        """The discrete controller at a pressure drop (:func:`discrete_as_runs`)."""
        if not isinstance(d, ScheduledDigital):
            return d.discrete
        return lambda p: discrete_as_runs(cfg, d, w, p)

    ctrls = {m: as_runs(d) for m, d in digitals.items()}
    checks = impulse_checks(cfg, ident.result.identified, truth, ctrls,
                            sorted({0.0, cfg.operating.pressure_bar}))
    ident.summary["facility_impulse"] = [c.to_dict() for c in checks]
    figs, sections = facility_impulse_report(out, checks, ident.summary["design"])
    ident.figs += figs
    ident.sections += sections


def design_files(rig: str | Path, method: str, out_dir: str | Path, *,
                 pressure_bar: float | None = None, overrides=(),
                 allow_unstable: bool = False, c_dir: str | Path | None = None,
                 precision: str = "double") -> dict:
    """``ambseal design``: design one controller and write it with its summary.

    Files: ``controller_<method>.json``, ``.npz`` and ``.mat`` — the discrete controller
    that runs at ``[controller] sample_rate_hz`` with ``delay_samples`` (discretisation
    chosen and judged, :mod:`ambseal.robust.digital`; for ``lpv`` the scheduled table and
    its interpolation law), the continuous design, channels with units and the judged
    discrete margins (:mod:`ambseal.export.controller_files`) — and ``design_<method>.json``
    (summary, weights, D–K history, discretisation). With ``c_dir`` also the C99 module
    (:mod:`ambseal.export.codegen`) in ``precision`` ("double" or "float").

    Raises
    ------
    ConfigError
        A bad rig, a bad sample rate or delay, or ``lpv`` on a rig at standstill.
    SynthesisError
        No discretisation keeps the sampled loop stable (the reason named).
    """

    cfg = load_rig(rig, overrides)
    out = writable_folder(out_dir)  # before the design, not after it
    spec = design_spec(cfg)  # judged at the rig's conditions, whatever the design pressure
    if method == "lpv":  # what ambseal run designs (the one rule)
        try:
            speeds, states, _ = lpv_schedule(cfg, spec)
        except ConfigError as exc:
            raise ConfigError(f"{rig}: {exc}") from None
        res = design_lpv(cfg, speeds_hz=speeds, states=states,
                         allow_unstable=allow_unstable, spec=spec)
        K, summary = res, res.to_dict()
    else:
        # another design pressure is another specification (its uncertainty is the seal's
        # there)
        res = design(cfg, method, pressure_bar=pressure_bar, allow_unstable=allow_unstable,
                     spec=spec if pressure_bar is None else design_spec(cfg, pressure_bar),
                     progress=logging.getLogger("ambseal").info)  # -q silences it
        K, summary = res.controller, res.to_dict()  # scheduled on speed where it is

    points = operating_points(spec)
    digital = digital_for(cfg, method, K, res, points)
    if summary.get("full_order") is None:
        # the reference PID is given, not designed: judged here before it is handed over,
        # and its verdict says so as a design's does
        check = full_order_check(cfg, K, [(q.pressure_bar, q.speed_rpm / 60.0) for q in points])
        summary.update(full_order=check, kept_unstable=not check["stable"],
                       verdict=f"{summary['verdict']}; {full_order_words(check)}")
    check = summary.get("full_order")
    failure = None if check is None or check["stable"] else (
        f"the full-order loop is unstable at {check['pressure_bar']:g} bar, "
        f"{check['speed_hz']:g} Hz (the mode at {check['mode_hz']:.4g} Hz has ζ = "
        f"{check['damping']:.3g})")
    if failure is not None and not allow_unstable:
        raise SynthesisError(f"{method}: {failure}; nothing exported. Pass --allow-unstable "
                             "to export it anyway (marked in every file)")
    judged = choice_margins(cfg, points, digital)
    verdict = loop_verdict(judged, failure, allow_unstable)
    summary["loop"] = verdict
    warn_unheld(method, verdict)
    files = export_design(method, digital, summary, out, judged, verdict)
    if c_dir is not None:
        files += write_c(digital, c_dir, f"ambseal_{method}", precision=precision,
                         verdict=verdict)
    short = res.summary() if hasattr(res, "summary") else summary
    # the verdict of a check made here, as design_<method>.json has it
    short = {**short, **{k: summary[k] for k in ("full_order", "kept_unstable", "loop",
                                                 "verdict") if k in summary}}
    return {**short, "discretisation": digital.to_dict(),
            "files": [str(f) for f in files]}


def _record_hash(meas) -> str:
    """SHA-256 of a record's samples (time, excitation, currents, displacements)."""

    h = hashlib.sha256()
    for a in (meas.time_s, meas.excitation_a, meas.current_ref_a, meas.current_a,
              meas.displacement_m):
        h.update(a.tobytes())
    return h.hexdigest()


def _check_records(records: list, paths: list[str]) -> None:
    """Refuse a record given twice (same samples: it would narrow the intervals by √2) and
    a record without excitation (nothing to identify)."""

    seen: dict[str, str] = {}
    for meas, path in zip(records, paths):
        digest = _record_hash(meas)
        if digest in seen:
            raise DataError(f"{path}: the same samples as {seen[digest]} (a record counts "
                            "once; a copy would narrow the confidence intervals by √2)")
        seen[digest] = str(path)
        if not np.any(meas.excitation_a):
            raise DataError(f"{path}: excitation_a: zero on every axis; a record without "
                            "excitation identifies nothing")


def identify_files(rig: str | Path, data: list[str], names: list[str], out_dir: str | Path, *,
                   current_weight: float = 0.0, refine: bool = True,
                   accept_unconverged: bool = False, static_load: str | None = None,
                   accept_implausible: bool = False) -> dict:
    """``ambseal identify``: fit ``names`` to recorded files; write the fit, its figures and
    the identified rig to ``out_dir``. Returns a JSON-safe summary.

    With ``static_load`` (a load-step CSV, :mod:`ambseal.identify.fitting.static_load`), Ki is also
    found by static loading (P2 §5, its own interval, in ``fit.json`` as ``static_load``)
    and joined with the fitted Ki's: the estimates, intervals and correlations written are
    the joined ones, and ``static_load`` gives the Ki–Ks correlations before and after.

    The intervals include the error budget of every parameter held fixed
    (:mod:`ambseal.identify.fitting.budget`); the residuals are tested for independence of the
    excitation (:mod:`ambseal.identify.fitting.residuals`); with several records of one condition,
    each is also fitted alone and the spread of those estimates (RSD, thesis P2 Table 2)
    is reported beside the pooled fit. ``warnings`` in the summary say which fixed values
    dominate, whether seal coefficients are held at a non-zero pressure and whether the
    model fails the residual test.

    A fit that failed (not converged, singular Jacobian, an estimate at its bound, an NRMSE
    fit below the floor of :func:`ambseal.identify.fitting.fit.fit_parameters`) writes ``fit.json``
    for diagnosis but no figures and no ``identified.toml``, and raises, unless
    ``accept_unconverged``; so does an implausible fit (:mod:`ambseal.identify.fitting.plausibility`)
    unless ``accept_implausible``. Non-finite results are refused before anything is written.

    Raises
    ------
    ConfigError, DataError, IdentificationError
        A bad rig, a bad, duplicate, unexcited or mismatched record, a fit that cannot
        start, or (unless accepted) a fit that failed or is implausible.
    """

    cfg = load_rig(rig)
    out = writable_folder(out_dir)  # before the fit, not after it
    axes = channel_names(cfg)
    records, controllers = [], []
    for path in data:
        meas = load_measurement(path, axes=axes, min_samples=max(100, 10 * len(names)))
        other = meas.metadata.get("rig")
        if other is not None and other != cfg.rotor.name:
            raise DataError(f"{path}: metadata.rig: recorded on {other!r}, but the rig is "
                            f"{cfg.rotor.name!r}")
        check_record_metadata(dict(meas.metadata), str(path))
        records.append(meas)
        controllers.append(controller_from_metadata(dict(meas.metadata), axes, str(path)))
    _check_records(records, data)
    sources = [str(d) for d in data]
    try:  # the fit's errors name the records it was made from
        return _identify_and_write(cfg, records, controllers, names, sources, out,
                                   current_weight, refine, accept_unconverged, static_load,
                                   accept_implausible)
    except IdentificationError as exc:
        raise with_source(exc, [*sources, out], ", ".join(sources)) from None


def _identify_and_write(cfg, records, controllers, names, sources, out, current_weight,
                        refine, accept_unconverged, static_load, accept_implausible) -> dict:
    """The fit of :func:`identify_files` and its files (``sources``: the records' paths)."""
    res = identify(cfg, records, names, current_weight=current_weight, refine=refine,
                   controllers=controllers, budget=True, sources=sources)
    spread = record_spread(cfg, records, names, res, controllers=controllers,
                           sources=sources) if len(records) > 1 else None
    pressures = sorted({float(m.metadata.get("pressure_drop_pa", 0.0)) / 1e5 for m in records})
    warnings = advice(res.budget, cfg, names, pressures)
    static = with_static_record(cfg, res, static_load) if static_load else None
    if static is not None:
        res, static = static
    if res.residuals.failed:  # a disputed fixed value is told by advice() already
        warnings.append(f"{MISMATCH} (residuals correlate with the excitation on "
                        f"{', '.join(res.residuals.failed)})")
    if res.sensor_lag and res.sensor_lag["flagged"]:
        warnings.append(f"{MISMATCH} (the data ask for a sensor lag of "
                        f"{res.sensor_lag['suggested_tau_s'] * 1e6:.3g} µs the model lacks: "
                        + ("a wrong held value can also make it; fit the disputed values "
                           "first, then tau_s if it remains)" if res.model_check()["disputed"]
                           else "fit tau_s beside tau_e; Ki, Ks then hold, read "
                           "tau_e + tau_s)"))
    reasons = implausible(cfg, res.names, res.estimate, res.ci95_low, res.ci95_high)
    write_json(out / "fit.json", require_finite({**res.to_dict(), "warnings": warnings + reasons,
                                                 **({"per_record": spread} if spread else {}),
                                                 **({"static_load": static} if static else {})},
                                                "identify: the fit"))
    failed = fit_failure(res, reasons, accept_unconverged, accept_implausible)
    if failed:
        (out / "identified.toml").unlink(missing_ok=True)  # an earlier fit's: not this one's
        raise IdentificationError(f"identify: {failed[0]}; {out / 'fit.json'} has the details, "
                                  f"no identified rig was written ({failed[1]} writes it anyway)")
    fit_timeseries_figure(out / "fit_timeseries.png", res.time_s, res.y_meas, res.y_sim,
                          res.axes, nrmse_pct=[res.nrmse_fit_pct[a] for a in res.axes])
    correlation_figure(out / "correlation.png", res.correlation, res.names)
    residual_figure(out / "residuals.png", res.residuals)
    error_budget_figure(out / "error_budget.png", res.names, res.estimate, res.std_error_noise,
                        res.budget)
    est = dict(zip(res.names, res.estimate))
    lag = est.pop("tau_s", None)  # the sensors' lag: no rig-file value, told in the header
    identified = rig_with_values(cfg, est)
    header = (f"Identified by ambseal from {', '.join(sources)}\n"
              f"parameters: {', '.join(res.names)}; converged: {res.converged}\n"
              + (f"sensor lag tau_s = {lag:.4g} s (fitted; the rig file has no key for it: "
                 "the model the controllers are designed on leaves it out)\n"
                 if lag is not None else "") +
              f"seal coefficients, if fitted, hold at the recorded pressure drop(s) "
              f"{pressures} bar")
    write_text(out / "identified.toml", dump_rig(identified, header))
    return {"out": str(out), "converged": res.converged, "message": res.message,
            "parameters": {
                n: {"estimate": float(v), "ci95": [finite_or_none(lo), finite_or_none(hi)],
                    **({"rsd_pct": spread[n]["rsd_pct"]} if spread else {})}
                for n, v, lo, hi in zip(res.names, res.estimate, res.ci95_low, res.ci95_high)},
            "nrmse_fit_pct": {k: finite_or_none(v) for k, v in res.nrmse_fit_pct.items()},
            "residual_test": res.residuals.to_dict()["verdict"],
            "model_check": res.model_check()["verdict"],
            **({"static_load": static} if static else {}),
            "warnings": warnings + reasons}


def written_pid(cfg) -> bool:
    """Whether the rig file writes any part of its reference PID (``[controller.pid]`` or
    ``[[controller.filter]]``); otherwise ambseal derives it
    (:func:`ambseal.design.pid.pid_from_rig`)."""
    return cfg.controller.pid is not None or cfg.controller.filter is not None


def check_reference_rate(cfg, where) -> None:
    """Refuse, before any design, a target that cannot run the reference PID the rig file
    writes (:func:`ambseal.robust.digital.check_rate` on it, as :func:`digital_for` checks
    it after the designs): ``validate`` and ``run`` refuse the same rig with the same line.
    A PID that ambseal derives is not the user's input: it is never refused here (its rule
    fits its filters to the rate, and one that still cannot run is a failed controller of
    the run, :func:`digital_for`).

    Raises
    ------
    ConfigError
        ``where: controller.sample_rate_hz …``."""
    if not written_pid(cfg):
        return
    K = design(cfg, "pid").K
    try:
        check_rate(K, cfg.controller.sample_rate_hz, cfg.controller.delay_samples,
                   removable=isinstance(K, ScheduledController))
    except ConfigError as exc:
        raise ConfigError(f"{where}: {exc}") from None


def validate_summary(rig: str | Path | None = None, overrides=()) -> dict:
    """``ambseal validate``: parse and check a rig file; its model and the defaults a run takes.

    Returns a JSON-ready dict: ``rig``, ``name``, ``mass_kg``, ``nodes``, ``axes``;
    ``statics``, the rotor held at rest as the machine stands (``[machine] orientation``:
    :meth:`ambseal.analysis.statics.Statics.to_dict`, each AMB's static currents); the modes
    of the full model at the nominal condition below the controller's Nyquist frequency
    (``modes_below_hz``, ``modes`` as [f_Hz, ζ]); ``unstable_poles`` ([Re, Im] rad/s); and
    ``defaults``: the reduced model's order, the judged conditions, the controller's sample
    rate, the reference PID (the file's ``[controller.pid]``, else the one a run derives,
    with ``derived`` true, its ``filters`` and its ``rule``) and the judgement's grids and
    disturbances (on a rig without
    AMBs none: no controller to design or judge). ``overrides`` are ``design.KEY=VALUE``
    settings, as ``run`` takes them (:func:`ambseal.config.apply_overrides`).

    Raises
    ------
    ConfigError
        The rig file does not parse or check, or holds what ``run`` would refuse before
        its designs (a target that cannot run the reference PID the file writes).
    """

    cfg = load_rig(rig, overrides)
    # a rig without AMBs (a rotor on plain bearings, as import-ross writes it) has no
    # controller to design or judge: its modes, model and sign-off still are
    spec = design_spec(cfg) if cfg.amb else None
    if cfg.amb:
        check_reference_rate(cfg, rig if rig is not None else default_rig_path())
    limit = cfg.controller.sample_rate_hz / 2
    res = modes(build_system(cfg))
    rows = [[f, z] for f, z in zip(res.natural_frequencies_hz, res.damping_ratios) if f < limit]
    pid = cfg.controller.pid
    return {
        "rig": str(rig if rig is not None else default_rig_path()),
        "name": cfg.rotor.name, "mass_kg": assemble_rotor(cfg).mass,
        "nodes": build_mesh(cfg).n_nodes, "axes": list(channel_names(cfg)),
        "modes_below_hz": limit, "modes": rows,
        "unstable_poles": [list(p) for p in res.unstable_poles],
        "statics": rotor_at_rest(cfg).to_dict(),
        "defaults": {
            "reduced_states": build_plant(cfg, reduced=True).n_states,
            "judged_conditions": [p.label for p in operating_points(spec)] if spec else [],
            "nominal_pressure_bar": cfg.operating.pressure_bar,
            "nominal_speed_rpm": cfg.operating.speed_rpm,
            "controller_sample_rate_hz": cfg.controller.sample_rate_hz,
            # the PID a run designs: the file's, else the derived one with its rule
            "pid": (None if not cfg.amb else pid.model_dump() if pid is not None
                    else {"derived": True, **reference_pid(cfg)}),
            "judgement": asdict(judge_settings(spec, cfg)) if spec else None,
        },
    }


def track_files(rig: str | Path, data: list[str], names: list[str], out_dir: str | Path, *,
                rate_per_s: float | None = None) -> dict:
    """``ambseal track``: track ``names`` through each recorded file
    (:func:`ambseal.identify.tracking.track`); write ``track.json`` (summary),
    ``track_<i>.csv`` (time, estimate, 95 % interval per parameter, decimated to ≤ 1 kHz)
    and ``track_<i>.png`` per record. Returns a JSON-safe summary.

    Raises
    ------
    ConfigError, DataError, IdentificationError
        A bad rig; a bad record, one whose excitation exceeds the current limit, or one too
        short; a name without an LFT channel.
    """

    cfg = load_rig(rig)
    axes = channel_names(cfg)
    settings = TrackingSettings() if rate_per_s is None else TrackingSettings(
        rate_per_s=rate_per_s)
    out = writable_folder(out_dir)  # before the work, not after it
    records = []
    for path in data:
        meas = load_measurement(path, axes=axes, min_samples=3)
        check_excitation(cfg, meas, str(path))
        # the model needs the controller only to be built (the tracker cuts the loop at the
        # DAC); a real rig's PID description becomes its matrices as in `identify`
        records.append((meas, controller_from_metadata(dict(meas.metadata), axes, str(path))))
    summary = []
    for i, (path, (meas, ctrl)) in enumerate(zip(data, records)):
        res = track(cfg, meas, names, settings, source=str(path), controller=ctrl)
        lo, hi = res.ci95()
        step = max(1, int(round(1e-3 / (res.time_s[1] - res.time_s[0]))))
        cols = [res.time_s[::step]] + [a[::step, j] for j in range(len(names))
                                       for a in (res.estimate, lo, hi)]
        head = ",".join(["time_s"] + [f"{n}{s}" for n in names for s in ("", "_ci95_low",
                                                                         "_ci95_high")])
        csv = "\n".join([head] + [",".join(f"{v:.9g}" for v in row)
                                  for row in np.column_stack(cols)]) + "\n"
        write_text(out / f"track_{i + 1}.csv", csv)
        tracking_figure(out / f"track_{i + 1}.png", res.time_s, names, res.estimate, lo, hi,
                        units=res.units, title=f"Tracked parameters: {Path(path).name}")
        summary.append({"data": str(path), "csv": str(out / f"track_{i + 1}.csv"),
                        "figure": str(out / f"track_{i + 1}.png"),
                        "final": {n: {"estimate": float(res.estimate[-1, j]),
                                      "std_error": float(res.std_error[-1, j]),
                                      "ci95": [float(lo[-1, j]), float(hi[-1, j])]}
                                  for j, n in enumerate(names)},
                        "n_states": res.n_states, "flops_per_sample": res.flops_per_sample,
                        "realtime_factor": res.realtime_factor})
    result = {"out": str(out), "parameters": list(names), "records": summary}
    write_json(out / "track.json", result)
    return result
