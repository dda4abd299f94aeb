"""The rotordynamicist's commands: ``modes``, ``campbell``, ``sweep``, ``signoff`` and
``import-ross``.

Wiring only, like :mod:`ambseal.app.commands`: the numbers come from
:mod:`ambseal.analysis.campbell`, :mod:`ambseal.analysis.sweep`,
:mod:`ambseal.analysis.signoff.level1` and :mod:`ambseal.io.ross`, the figures from
:mod:`ambseal.report.modal_figures` and :mod:`ambseal.report.signoff_figures`, and every
file is written through a
temporary name and a rename (:mod:`ambseal.files`). The CLI (:mod:`ambseal.cli`) parses these
subcommands and runs them with :data:`HANDLERS`; ``modes`` lives in
:mod:`ambseal.app.modes`, which the CLI loads alone.
"""

from __future__ import annotations

import argparse
import csv
import io
import json
import logging
import math
import sys
from pathlib import Path

import control

from ambseal.analysis import (
    amb_loop,
    check_cases,
    dask_available,
    drop_event,
    drop_model,
    drop_scatter,
    drop_verdict,
    judge_settings,
    levitated_state,
    lost_at_rest,
    operating_points,
    parse_range,
    probe_scheduler,
    refine_boundary,
    sign_off,
    simulate_drop,
    stability_boundary,
    ucs_map,
    verdict_line,
)
from ambseal.analysis.campbell import campbell
from ambseal.analysis.sweep import sweep
from ambseal.app.commands import digital_for, discrete_as_runs
from ambseal.app.controllers import controller_for, runs_as
from ambseal.app.modes import mode_positions, modes_command
from ambseal.config import (
    MAX_COEFFICIENT,
    MAX_PRESSURE_BAR,
    MAX_SPEED_HZ,
    MAX_SPEED_RPM,
    check_below_trip,
    check_operating,
    drop_limits_with,
    load_rig,
    method_names,
    rig_parameter_names,
)
from ambseal.design import design, design_spec
from ambseal.errors import ConfigError
from ambseal.export import load_controller
from ambseal.files import OwnedFolder, atomic_write, write_json, write_text
from ambseal.io import import_ross_file
from ambseal.machine import frozen
from ambseal.model import channel_names, inclination
from ambseal.report import (
    api617_unbalance_figure,
    campbell_figure,
    drop_current_figure,
    drop_figure,
    drop_whirl_figure,
    level1_figure,
    mode_shapes_figure,
    stability_map_figure,
    stamp,
    ucs_map_figure,
    write_drop_report,
)
from ambseal.robust import with_delay

__all__ = ["HANDLERS", "write_table"]


def write_table(path: Path, rows: list[dict]) -> list[Path]:
    """Rows as CSV (columns: the union of keys, in first-seen order), and as Parquet beside
    it when pyarrow is installed. Returns the files written."""
    cols = list(dict.fromkeys(k for r in rows for k in r))
    buf = io.StringIO()
    w = csv.DictWriter(buf, fieldnames=cols, lineterminator="\n")
    w.writeheader()
    w.writerows(rows)
    files = [write_text(path, buf.getvalue())]
    try:
        import pyarrow as pa  # optional: Parquet tables where pyarrow is installed
        import pyarrow.parquet as pq  # optional, as above
    except ImportError:
        return files

    table = pa.Table.from_pylist([{c: r.get(c) for c in cols} for r in rows])
    pq_path = path.with_suffix(".parquet")
    atomic_write(pq_path, lambda fh: pq.write_table(table, fh))
    return files + [pq_path]


def _range(text: str | None, name: str, low: float, high: float, rule: str):
    """The points of ``a:b:n`` (:func:`~ambseal.analysis.sweep.parse_range`), each within
    [low, high] by the rig file's ``rule``; None for None."""
    if text is None:
        return None
    points = parse_range(text, name)
    if not all(low <= x <= high for x in points):
        raise ConfigError(f"{name}: expected values from {low:g} to {high:g} ({rule}), got "
                          f"{text!r}")
    return points


#: The bounds of the ranges, by the rig file's rules (ambseal.config._checks).
_SPEEDS = (-MAX_SPEED_HZ, MAX_SPEED_HZ,
           f"{MAX_SPEED_RPM:g} rpm, the bound of [operating] speed_rpm and speed_range_hz")
_PRESSURES = (0.0, MAX_PRESSURE_BAR, "the rule of [operating] pressure_bar")


def _owns_out(handler):
    """``handler`` with its ``--out`` folder claimed before any work
    (:class:`ambseal.files.OwnedFolder`)."""
    def run(args: argparse.Namespace) -> int:
        with OwnedFolder(args.out, args.force):
            return handler(args)
    return run


@_owns_out
def _campbell(args: argparse.Namespace) -> int:
    cfg = load_rig(args.rig)
    p = cfg.operating.pressure_bar if args.pressure_bar is None else args.pressure_bar
    speeds = _range(args.speed_hz, "--speed-hz", *_SPEEDS)
    spec = args.controller or ("pid" if cfg.controller.pid is not None and cfg.amb else
                               "hinf" if cfg.amb else None)
    if args.scheduler is not None:  # before any design: an address that never answers
        probe_scheduler(args.scheduler)
    K = controller_for(cfg, spec, p)
    c = campbell(cfg, K, speeds, pressure_bar=p,
                 max_hz=args.max_hz, log_dec_limit=args.log_dec_limit, workers=args.workers,
                 scheduler=args.scheduler, progress=True)
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    tag = Path(spec).stem if spec else "open_loop"
    title = f"{cfg.rotor.name}: {tag}, {p:g} bar"
    files = [campbell_figure(out / f"campbell_{tag}.png", c, title=f"Campbell — {title}"),
             mode_shapes_figure(out / f"mode_shapes_{tag}.png", c.points[0], mode_positions(cfg),
                                title=f"Mode shapes — {cfg.rotor.name}: {tag}"),
             write_json(out / f"campbell_{tag}.json",
                        {"rig": str(args.rig), "controller": spec or "none",
                         "pressure_bar": p, **c.to_dict()})]
    files += write_table(out / f"campbell_{tag}.csv", c.rows())
    print(json.dumps({"controller": spec or "none", "pressure_bar": p,
                      "speeds_hz": [float(c.speeds_hz[0]), float(c.speeds_hz[-1]),
                                    len(c.speeds_hz)],
                      "stable_at_all_speeds": all(pt.stable for pt in c.points),
                      "crossings": [x.to_dict() for x in c.crossings],
                      "overdamped_crossings": len(c.overdamped),
                      "flagged_modes": len(c.flagged()), "log_dec_limit": c.log_dec_limit,
                      "files": [str(f) for f in files]}))
    return 0


@_owns_out
def _sweep(args: argparse.Namespace) -> int:
    cfg = load_rig(args.rig)
    pressures = (_range(args.pressure_bar, "--pressure-bar", *_PRESSURES)
                 if args.pressure_bar is not None else [cfg.operating.pressure_bar])
    spec = design_spec(cfg)
    speeds = (_range(args.speed_hz, "--speed-hz", *_SPEEDS) if args.speed_hz is not None
              else list(spec.stability_speeds_hz))
    specs = (args.controller or "pid").split(",")
    params, known = {}, rig_parameter_names(cfg)
    for text in args.param or []:
        name, sep, rng = text.partition("=")
        if not sep:
            raise ConfigError(f"--param: expected NAME=a:b:n, got {text!r}")
        name = name.strip()
        if name not in known:  # before any design: a misspelt name would fail every case
            raise ConfigError(f"--param: unknown parameter {name!r}; the rig's parameters "
                              f"are {', '.join(known)}")
        params[name] = _range(rng, f"--param {name}", -MAX_COEFFICIENT,
                              MAX_COEFFICIENT, "the bound of a force coefficient")
    check_cases(len(specs) * len(pressures) * len(speeds)
                * math.prod(len(v) for v in params.values()), "sweep")  # before any design
    if args.scheduler is not None:  # likewise: an address that never answers
        probe_scheduler(args.scheduler)
    ctrl = {Path(s).stem: controller_for(cfg, s, cfg.operating.pressure_bar) for s in specs}
    if any(K is None for K in ctrl.values()):
        raise ConfigError("sweep: every --controller must be a controller (pid, hinf, mu or "
                          "a file), not none")
    workers = args.workers
    if workers is None and args.scheduler is None and not dask_available():
        print("ambseal: note: dask is not installed; the sweep runs serially",
              file=sys.stderr)
        workers = 1
    # a controller file runs on a target: judged as it runs too (the *_as_runs columns)
    digitals = {Path(s).stem: g for s in specs if (g := runs_as(cfg, s)) is not None}
    rows = sweep(cfg, ctrl, pressures, speeds, params, settings=judge_settings(spec, cfg),
                 max_hz=args.max_hz, workers=workers, scheduler=args.scheduler, progress=True,
                 digitals=digitals)
    edge = refine_boundary(cfg, ctrl, stability_boundary(rows), tol_bar=args.tol_bar,
                           workers=workers, scheduler=args.scheduler, progress=True)
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    files = write_table(out / "sweep.csv", rows)
    files.append(write_json(out / "stability_boundary.json", edge))
    if not params:
        files.append(stability_map_figure(out / "stability_map.png", rows, edge,
                                          title=cfg.rotor.name))
    print(json.dumps({"cases": len(rows), "failed": sum(r.get("error") is not None
                                                         for r in rows),
                      "log_dec_below_min": sum(r.get("log_dec_ok") is False for r in rows),
                      "log_dec_min": cfg.signoff.log_dec_min,
                      "boundary": edge, "files": [str(f) for f in files]}))
    return 0


def _signoff_controllers(cfg, args) -> list[tuple[str, object]]:
    """(name, controller as it runs) of ``--controller FILE`` or each ``--method`` (default
    the reference PID on a rig with AMBs, else ``none``): a method is designed and
    discretised as ``ambseal design`` does (:func:`ambseal.app.commands.digital_for`)."""
    if args.controller is not None:
        K = load_controller(args.controller, channel_names(cfg))
        if not hasattr(K, "delay_samples"):
            raise ConfigError(f"--controller: {args.controller} holds a continuous "
                              "controller; the sign-off judges the discrete one as it runs "
                              "(export it with ambseal design or ambseal export)")
        return [(Path(args.controller).stem, K)]
    methods = (args.method or ("pid" if cfg.amb else "none")).split(",")
    allowed = ("none", *method_names(fixed=True))
    bad = [m for m in methods if m not in allowed]
    if bad:
        raise ConfigError(f"--method: {bad[0]!r}; expected {', '.join(allowed)} (comma "
                          "separated), or --controller FILE")
    out, spec = [], None
    for m in methods:
        if m == "none" or not cfg.amb:
            out.append((m, None))
            continue
        spec = spec or design_spec(cfg)
        res = design(cfg, m, spec=spec, progress=logging.getLogger("ambseal").info)
        out.append((m, digital_for(cfg, m, res.K, res, operating_points(spec))))
    return out


def _signoff(args: argparse.Namespace) -> int:
    if (Path(args.out) / "metrics.json").is_file():  # before the folder is claimed
        # the run's report and metrics describe its own level1.png and api617_unbalance.png
        raise ConfigError(f"--out {args.out}: holds the results of `ambseal run` "
                          "(metrics.json), whose report describes the level1.png and "
                          "api617_unbalance.png a sign-off would replace; sign off into "
                          "another folder (the run signs its delivered controllers off "
                          "itself)")
    return _signoff_into(args)


@_owns_out
def _signoff_into(args: argparse.Namespace) -> int:
    cfg = load_rig(args.rig)
    say = logging.getLogger("ambseal").info
    controllers = _signoff_controllers(cfg, args)
    results = [sign_off(cfg, K, name=name, progress=say) for name, K in controllers]
    ucs = ucs_map(cfg, controllers)  # API 684's map: informative, no criterion
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    doc = {"rig": str(args.rig), "machine": cfg.machine.kind,
           "orientation": cfg.machine.orientation,
           "inclination_deg": inclination(cfg.machine),
           "passed": all(r.passed for r in results), "verdict": verdict_line(results),
           "controllers": {r.controller: r.to_dict() for r in results},
           "ucs_map": ucs.to_dict()}
    files = [write_json(out / "signoff.json", doc),
             *([level1_figure(out / "level1.png", [r.level1 for r in results],
                              title=f"API 617 Level I — {cfg.rotor.name}",
                              boundary=cfg.signoff.csr_boundary)] if cfg.stage else []),
             api617_unbalance_figure(out / "api617_unbalance.png",
                                     [r.unbalance for r in results],
                                     title=f"API 617 unbalance response — {cfg.rotor.name}"),
             ucs_map_figure(out / "ucs_map.png", ucs, speeds_hz=(*cfg.operating.continuous_hz,
                                                                 cfg.operating.trip_hz),
                            title=f"API 684 undamped critical speed map — {cfg.rotor.name}")]
    if args.json:
        print(json.dumps({**doc, "files": [str(f) for f in files]}))
    else:
        print(doc["verdict"])
        if results:  # what the unbalance's W stands on: the machine as it stands
            print(f"journal static loads W: {results[0].unbalance.journal_load_rule}")
        for r in results:
            for c in r.criteria:
                print(f"{r.controller}: {c.name}: {c.outcome} — {c.value} (limit {c.limit}; "
                      f"{c.source})")
        print(f"files: {', '.join(str(f) for f in files)}")
    return 0 if doc["passed"] else 1


@_owns_out
def _drop(args: argparse.Namespace) -> int:
    cfg = load_rig(args.rig)
    if cfg.machine.orientation != "horizontal" and all(
            t.axial_clearance is None for t in cfg.touchdown):
        # the weight along the axis has nowhere to land: said, so that the verdict is not
        # read as that of the rotor's axial landing
        logging.getLogger("ambseal").warning(
            "drop: [machine] orientation = \"%s\", yet no [[touchdown]] has an "
            "axial_clearance: the rotor's weight along its axis stays on the thrust "
            "bearing, and its landing on an axial face is not modelled",
            cfg.machine.orientation)
    if args.speed_hz is not None:  # it stands for [operating] speed_rpm, as --speed-rpm
        check_operating({"speed_rpm": 60.0 * args.speed_hz},
                        {"speed_rpm": f"--speed-hz {args.speed_hz:g} "
                                      f"(= {60.0 * args.speed_hz:g} rpm)"})
    # a negative speed turns the rotor the other way (about −z), as everywhere in the rig
    # file: the named speeds keep the rig's sense of rotation (--speed-rpm was checked by
    # the rule of [operating] speed_rpm, ambseal.cli)
    sense = -1.0 if cfg.operating.speed_rpm < 0 else 1.0
    named = {"standstill": 0.0,
             "max-continuous": sense * 60.0 * cfg.operating.continuous_hz[1],
             "trip": sense * 60.0 * cfg.operating.trip_hz}
    rpm = (60.0 * args.speed_hz if args.speed_hz is not None else
           args.speed_rpm if args.speed_rpm is not None else
           named[args.at] if args.at is not None else cfg.operating.speed_rpm)
    if args.speed_hz is not None or args.speed_rpm is not None:  # the rig's own: ≤ trip
        check_below_trip(cfg.operating, rpm, f"--speed-hz {args.speed_hz:g}"
                         if args.speed_hz is not None else f"--speed-rpm {args.speed_rpm:g}")
    # steps within the drop are DEBUG records, as a stage's steps are (StageProgress):
    # shown with --verbose, so that a drop the contact ends (crushed rings) says one line
    step = logging.getLogger("ambseal").debug
    shown = [0]

    def progress(t: float) -> None:  # a line per tenth of the drop, not per contact
        tenth = int(10 * t / args.duration_s)
        if tenth > shown[0]:
            shown[0] = tenth
            step(f"drop: {1e3 * t:.4g} ms of {1e3 * args.duration_s:.4g} ms")

    if args.pressure_bar is not None:  # checked as the rig file's key is, before here
        # the seals' pressure through the drop, the Monte-Carlo runs' too
        cfg = cfg.model_copy(update={"operating": cfg.operating.model_copy(
            update={"pressure_bar": float(args.pressure_bar)})})
    if args.axial_thrust_n is not None:  # the Monte-Carlo runs' too
        if args.event != "loss":
            raise ConfigError(f"--axial-thrust-n: the thrust bearing lets go with every AMB "
                              f"axis (--event loss); with --event {args.event} it holds")
        if not abs(args.axial_thrust_n) <= 1e8:
            raise ConfigError(f"--axial-thrust-n: expected -1e8 to 1e8 N, got "
                              f"{args.axial_thrust_n:g}")
        cfg = cfg.model_copy(update={"drop": cfg.drop.model_copy(
            update={"axial_thrust": float(args.axial_thrust_n)})})
    if args.penetration_ratio is not None:  # the Monte-Carlo runs' too
        cfg = cfg.model_copy(update={"drop": drop_limits_with(
            cfg.drop, "penetration_ratio", args.penetration_ratio,
            f"--penetration-ratio {args.penetration_ratio:g}")})
    if args.drag_torque and not args.coast_down:
        raise ConfigError("--drag-torque: slows a coasting rotor; add --coast-down (the "
                          "drive holds the speed otherwise)")
    if args.runs is not None:
        if args.controller is not None:
            raise ConfigError("--controller: Monte-Carlo drops run the reference PID; drop "
                              "without --runs for another controller")
        return _drop_scatter(args, cfg, rpm)
    for name in ("friction", "clearance_tol_um", "support_damping", "workers", "scheduler"):
        if getattr(args, name) is not None:
            raise ConfigError(f"--{name.replace('_', '-')}: draws or spreads Monte-Carlo "
                              "drops; add --runs N")
    unbalance = args.unbalance_kgm or (0.0, 0.0)
    if unbalance[0] != unbalance[1]:
        raise ConfigError("--unbalance-kgm: a range LO:HI is drawn per run; add --runs N, "
                          "or give one value")
    dm = drop_model(cfg, args.modes_hz)
    controller = controller_for(cfg, args.controller) if args.controller else None
    controller = frozen(controller, 2 * math.pi * rpm / 60.0)  # scheduled: where it drops
    digital = runs_as(cfg, args.controller) if args.controller else None
    if digital is None and getattr(controller, "as_runs_only", False):
        digital = controller
    if digital is not None:  # a digital controller's file: as it runs on the target
        d = discrete_as_runs(cfg, digital, 2 * math.pi * rpm / 60.0,
                             cfg.operating.pressure_bar)
        controller = control.ss(*with_delay((d.A, d.B, d.C, d.D), digital.delay_samples),
                                d.dt)
    # a controller the user names runs on whatever the drop
    idle = args.controller is None and lost_at_rest(args.event, args.start, unbalance[0])
    loop = amb_loop(cfg, dm, rpm, "none" if idle else controller)
    event = drop_event(cfg, dm, loop, args.event, args.axis, args.overload_n,
                       args.overload_at, args.surge_bar)
    start = x0 = None
    # a loop that runs on is checked for stability at the speed, as the orbit needs it
    if args.start == "levitated" and (unbalance[0] > 0 or event["failed"] != loop.names):
        eta, deta, x0 = levitated_state(cfg, dm, rpm, unbalance[0], loop=loop)
        start = (dm.phi @ eta, dm.phi @ deta)
    res = simulate_drop(cfg, speed_rpm=rpm, duration_s=args.duration_s, model=dm,
                        coast_down=args.coast_down, drag_torque=args.drag_torque,
                        unbalance_kgm=unbalance[0], initial=start, loop=loop,
                        loop_state=x0, failed=event["failed"], overload=event["overload"],
                        pressure_bar=event["pressure_bar"], progress=progress)
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    judged = drop_verdict(cfg, res)
    doc = {"rig": str(args.rig), "speed_rpm": rpm, "unbalance_kgm": unbalance[0],
           "start": args.start, "event": args.event, "event_summary": event["summary"],
           "pressure_bar": cfg.operating.pressure_bar,
           "controller": args.controller or ("none: every axis lost at rest" if idle
                                             else "reference PID"),
           "controller_runs": (None if idle else "continuous" if digital is None else
                               f"digital at {1 / loop.sampled[4]:g} Hz, "
                               f"{digital.delay_samples} sample(s) of computation delay"),
           **judged, **res.to_dict()}
    for plane, td in zip(doc["planes"], cfg.touchdown):
        plane["radial_clearance_m"] = td.radial_clearance
    title = f"Rotor drop — {cfg.rotor.name}"
    figures = [("Orbits in the clearance and contact forces",
                drop_figure(out / "drop.png", res, [t.radial_clearance for t in cfg.touchdown],
                            title=title)),
               ("Whirl waterfall and speeds", drop_whirl_figure(out / "drop_whirl.png", res,
                                                                title=title)),
               ("AMB coil currents", drop_current_figure(out / "drop_currents.png", res,
                                                         title=title))]
    files = [write_json(out / "drop.json", doc), *(png for _, png in figures),
             write_drop_report(out / "drop.html", doc, figures, title=title,
                               meta=stamp(args.rig, args.command_line))]
    if args.json:
        print(json.dumps({**doc, "files": [str(f) for f in files]}))
    else:
        print(doc["verdict"])
        print(doc["orientation_note"])
        for c in doc["criteria"]:
            print(f"{c['name']}: {c['outcome']} — {c['value']} (limit {c['limit']})")
        for p in doc["planes"]:
            onset, spin_up = p["whirl_onset_s"], p["race_spin_up_s"]
            print(f"{p['name']}: {p['regime']}"
                  + (f" at {p['whirl_hz']:.4g} Hz from {1e3 * onset:.4g} ms"
                     if onset is not None else "")
                  + (f"; ring spun up in {1e3 * spin_up:.4g} ms" if spin_up else ""))
        for a in doc["amb"]:
            if a["saturated"]:
                print(f"{a['channel']}: current saturated at {a['current_limit_a']:.4g} A")
        print(f"files: {', '.join(str(f) for f in files)}")
    return 0 if doc["passed"] else 1


def _drop_scatter(args: argparse.Namespace, cfg, rpm: float) -> int:
    """``ambseal drop --runs N``: Monte-Carlo drops (:func:`drop_scatter`)."""
    if args.scheduler is not None:
        probe_scheduler(args.scheduler)
    tol = None if args.clearance_tol_um is None else 1e-6 * args.clearance_tol_um
    doc = drop_scatter(cfg, args.runs, seed=args.seed, friction=args.friction,
                       clearance_tol_m=tol, support_damping=args.support_damping,
                       unbalance_kgm=args.unbalance_kgm, speed_rpm=rpm,
                       duration_s=args.duration_s, modes_hz=args.modes_hz,
                       coast_down=args.coast_down, drag_torque=args.drag_torque,
                       start=args.start, workers=args.workers, scheduler=args.scheduler,
                       event={"event": args.event, "axis": args.axis,
                              "overload_n": args.overload_n,
                              "overload_at": args.overload_at, "surge_bar": args.surge_bar},
                       progress=True)
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    doc = {"rig": str(args.rig), "speed_rpm": rpm, "event": args.event, **doc}
    files = [*write_table(out / "drop_scatter.csv", doc["runs"]),
             write_json(out / "drop_scatter.json", doc)]
    failed = doc["failed"]["count"]
    if args.json:
        print(json.dumps({**{k: v for k, v in doc.items() if k != "runs"},
                          "files": [str(f) for f in files]}))
    else:
        for key, what in (("backward_whirl", "backward whirl"), ("failed", "failed verdict")):
            s = doc[key]
            lo, hi = s["interval"]
            print(f"{what}: {s['count']} of {doc['n']} drops, p = {s['probability']:.3g} "
                  f"(95 % interval {lo:.3g}–{hi:.3g})")
        print(f"largest peak force: {doc['peak_force_n']:.4g} N")
        print(f"files: {', '.join(str(f) for f in files)}")
    return 1 if failed else 0


def _import_ross(args: argparse.Namespace) -> int:
    res = import_ross_file(args.file, args.out, speed_rpm=args.speed_rpm, force=args.force)
    for line in [f"not imported: {n}" for n in res["unmapped"]] + [
            f"taken: {n}" for n in res["notes"]]:
        print(f"ambseal: {line}", file=sys.stderr)
    print(json.dumps(res))
    return 0


HANDLERS = {"modes": modes_command, "campbell": _campbell, "sweep": _sweep,
            "signoff": _signoff, "import-ross": _import_ross, "drop": _drop}
