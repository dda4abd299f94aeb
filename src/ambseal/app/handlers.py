"""The command line's commands: each takes the parsed arguments, calls the stages and prints
one JSON line (or a table) on stdout.

Wiring only: the parser is :mod:`ambseal.cli`'s, which imports this module once a command
runs (start-up cost); the files are written by :mod:`ambseal.app.commands` and
:mod:`ambseal.app.pipeline`, the rotordynamicist's commands live in
:mod:`ambseal.app.rotordynamics`.
"""

from __future__ import annotations

import argparse
import json
import sys
from contextlib import ExitStack
from pathlib import Path

from rich.console import Console

from ambseal.analysis import operating_points, rig_clearances_um
from ambseal.app import rotordynamics
from ambseal.app.commands import (
    design_files,
    digital_for,
    identify_files,
    judged_as_runs,
    levitating_controller,
    show_defaults,
    target_pid,
    track_files,
    validate_summary,
    warn_unheld,
)
from ambseal.app.pipeline import run
from ambseal.config import default_rig_path, load_rig, load_truth, method_names
from ambseal.design import design_spec
from ambseal.errors import AmbsealError, ConfigError, SynthesisError, with_source
from ambseal.export import c_identifier, load_controller, loop_verdict, write_c
from ambseal.files import OwnedFolder, claim_file, writable_folder
from ambseal.identify import (
    IMPULSE_LEAD,
    acquire,
    at_speed,
    chirp,
    excitation_plan,
    impulse,
    prbs,
    record_is_ours,
    save_measurement,
    save_static_record,
    stepped_sine,
    virtual_static_load,
)
from ambseal.model import channel_names
from ambseal.report import verdict_table_rich, verdicts

__all__ = ["HANDLERS"]


def _acquire_cmd(args: argparse.Namespace) -> int:
    cfg = load_rig(args.rig)
    truth = load_truth(args.truth)
    if args.speed_hz is not None and args.excitation == "static":
        raise ConfigError("--speed-hz: static loads are applied at rest; leave it out with "
                          "--excitation static")
    at_speed(cfg, args.speed_hz, "--speed-hz")  # a speed the rig runs, before any work
    out = Path(args.out)
    writable_folder(out.parent)  # before the simulation
    if args.excitation == "static":  # a load-step table carries no mark: new, or --force
        claim_file(out, force=args.force)
    else:  # a record and its sidecar as a pair: each new, or the pair ambseal wrote
        claim_file(out, force=args.force, ours=record_is_ours)
        if out.suffix.lower() == ".csv":
            claim_file(out.with_name(out.name + ".json"), force=args.force,
                       ours=record_is_ours)
    axes = channel_names(cfg)
    if not axes:
        raise ConfigError(f"{args.rig}: amb: acquisition needs at least one [[amb]]")
    excited = None
    if args.axes is not None:
        excited = [a.strip() for a in args.axes.split(",")]
        if not all(excited):
            raise ConfigError(f"--axes: expected axis names separated by commas, e.g. "
                              f"{','.join(axes[:2])}; got {args.axes!r}")
    fs = cfg.controller.sample_rate_hz
    if args.excitation == "static":
        z, F, cur = virtual_static_load(cfg, truth, seed=args.seed)
        path = save_static_record(args.out, cfg, z, F, cur)
        print(json.dumps({"out": str(path), "load_steps": int(z.size)}))
        return 0
    common = dict(sample_rate_hz=fs, axes=axes, excited=excited)
    # defaults from the rig (ambseal.identify.excitation.plan); an option given replaces one
    plan = excitation_plan(cfg, amplitude_a=args.amplitude_a)
    given = (lambda value, default: default if value is None else value)  # noqa: E731
    amplitude, duration = plan.amplitude_a, given(args.duration_s, plan.prbs_duration_s)
    try:
        if args.excitation == "prbs":
            ex = prbs(amplitude_a=amplitude,
                      clock_period_s=given(args.clock_period_s, plan.prbs_clock_s),
                      duration_s=duration, seed=args.seed, **common)
        elif args.excitation == "sine":
            freqs = (list(plan.sine_hz) if args.frequencies_hz is None
                     else [float(f) for f in args.frequencies_hz.split(",")])
            ex = stepped_sine(frequencies_hz=freqs, amplitude_a=amplitude,
                              cycles=args.cycles, settling_cycles=args.settling_cycles,
                              **common)
        elif args.excitation == "chirp":
            f0, f1 = plan.chirp_hz
            ex = chirp(f0_hz=given(args.f0_hz, f0), f1_hz=given(args.f1_hz, f1),
                       duration_s=duration, amplitude_a=amplitude, method=args.chirp,
                       **common)
        else:
            width = given(args.width_s, plan.impulse_s)
            ex = impulse(amplitude_a=amplitude, width_s=width,
                         start_s=given(args.start_s, IMPULSE_LEAD * width),
                         duration_s=duration, **common)
    except ValueError as exc:
        raise ConfigError(f"acquire: {exc}") from None
    # a controller file's errors name the file; the reference PID's, the truth file's run
    levitating = None if args.controller is None else levitating_controller(
        cfg, args.controller, args.speed_hz, args.pressure_bar)
    try:
        meas = acquire(cfg, truth, ex, controller=levitating or target_pid(cfg),
                       pressure_bar=args.pressure_bar, seed=args.seed,
                       speed_hz=args.speed_hz)
    except AmbsealError as exc:  # the simulation runs on the truth file's values
        raise with_source(exc, [args.truth], f"{args.truth} (with {args.rig})") from None
    path = save_measurement(meas, args.out)
    print(json.dumps({"out": str(path), "samples": meas.n_samples,
                      "sample_rate_hz": fs}))
    return 0


def _design(args: argparse.Namespace) -> int:
    rig = args.rig if args.rig is not None else default_rig_path()

    if args.show_defaults:
        print(show_defaults(rig, args.overrides), end="")
        return 0
    if args.method is None:
        raise ConfigError(f"design: --method is required "
                          f"({', '.join(method_names(option=True))}) unless --show-defaults")
    with _owned(args.out, force=args.force):
        summary = design_files(rig, args.method, args.out, pressure_bar=args.pressure_bar,
                               overrides=args.overrides, allow_unstable=args.allow_unstable)
    print(json.dumps(summary))
    return 0


def _owned(out, c_dir=None, force=False):
    """The folders a command writes, each claimed (:class:`ambseal.files.OwnedFolder`:
    refused if it holds files ambseal did not write, or without ``force`` files it wrote
    that were changed since; its manifest updated at the end); ``c_dir`` only when it is
    not inside ``out`` (paths resolved first: ``out/../x`` is not inside ``out``)."""
    inside = None not in (out, c_dir) and Path(c_dir).resolve().is_relative_to(
        Path(out).resolve())
    with ExitStack() as claims:
        for folder in (out, None if inside else c_dir):
            if folder is not None:
                claims.enter_context(OwnedFolder(folder, force))
        return claims.pop_all()  # open for the command's with block, which closes them


def _export(args: argparse.Namespace) -> int:
    if (args.method is None) == (args.controller is None):
        raise ConfigError("export: give exactly one of --method and --controller")
    if args.controller is not None:
        # the rig is read first: the file must be this rig's controller, wired by name
        cfg = load_rig(args.rig)
        ctrl = load_controller(args.controller, channel_names(cfg))
        done = {}
        if not hasattr(ctrl, "discrete"):  # a continuous file: discretised as design does
            try:
                ctrl = digital_for(cfg, "file", ctrl, None, operating_points(design_spec(cfg)))
            except ConfigError as exc:
                raise ConfigError(f"{args.controller} holds a continuous controller, which "
                                  f"export discretises for the rig's target: {exc}") from None
            done["discretised"] = {"method": ctrl.method, "sample_rate_hz": ctrl.sample_rate_hz,
                                   "delay_samples": ctrl.delay_samples}
        with _owned(None if args.c_dir else args.out, args.c_dir, args.force):
            # judged on this rig as it runs before it is handed over, as design judges its
            # own (the output folder checked first)
            verdict = loop_verdict(judged_as_runs(cfg, ctrl), None, args.allow_unstable)
            if verdict["loop_holds"] is False and not args.allow_unstable:
                raise SynthesisError(f"{args.controller}: on {args.rig}, the judged loop "
                                     f"{verdict['verdict']}; nothing exported. Pass "
                                     "--allow-unstable to export it anyway (marked in the "
                                     "C header)")
            warn_unheld(Path(args.controller).name, verdict)
            files = write_c(ctrl, args.c_dir or Path(args.out) / "c",  # file name as C names
                            f"ambseal_{c_identifier(Path(args.controller).stem)}",
                            precision=args.precision, verdict=verdict)
        print(json.dumps({"files": [str(f) for f in files], "loop": verdict, **done}))
        return 0
    with _owned(args.out, args.c_dir, args.force):
        summary = design_files(args.rig, args.method, args.out,
                               pressure_bar=args.pressure_bar,
                               c_dir=args.c_dir or Path(args.out) / "c",
                               precision=args.precision, allow_unstable=args.allow_unstable)
    print(json.dumps(summary))
    return 0


def _identify(args: argparse.Namespace) -> int:
    with _owned(args.out, force=args.force):
        summary = identify_files(args.rig, args.data, args.params.split(","), args.out,
                                 current_weight=args.current_weight, refine=not args.no_refine,
                                 accept_unconverged=args.accept_unconverged,
                                 static_load=args.static_load,
                                 accept_implausible=args.accept_implausible)
    print(json.dumps(summary))
    return 0


def _track(args: argparse.Namespace) -> int:
    with _owned(args.out, force=args.force):
        summary = track_files(args.rig, args.data, args.params.split(","), args.out,
                              rate_per_s=args.rate_per_s)
    print(json.dumps(summary))
    return 0


def _run(args: argparse.Namespace) -> int:
    result = run(args.rig, args.out, truth=args.truth, identification=not args.no_identify,
                 overrides=tuple(args.overrides), allow_unstable=args.allow_unstable,
                 command=args.command_line, progress=not (args.quiet or args.verbose),
                 force=args.force)
    for reason in result.metrics.get("cannot_run", {}).values():
        print(f"ambseal: {reason}", file=sys.stderr)
    if sys.stderr.isatty() and not args.quiet:
        console = Console(stderr=True)
        clear = rig_clearances_um(load_rig(args.rig))
        console.print(verdict_table_rich(verdicts(result.metrics["cases"], clear,
                                                     result.metrics.get("stability", ()),
                                                     result.metrics["controllers"])))
        console.print(f"report: {result.report_path.resolve()}")
    for f in result.failed.values():  # after the report is written: name each and why
        print(f"ambseal: {f['reason']}", file=sys.stderr)
    print(json.dumps({"out": str(result.out_dir), "metrics": str(result.metrics_path),
                      "report": str(result.report_path)}))
    return result.exit_status


def _plain(x) -> str:
    """A value of ``validate``'s defaults as text: dicts as ``key value``, pairs as ranges."""
    if isinstance(x, dict):
        return ", ".join(f"{k} {_plain(w)}" for k, w in x.items())
    if isinstance(x, (list, tuple)):
        pair = len(x) == 2 and all(isinstance(y, (int, float)) for y in x)
        return "–".join(map(_plain, x)) if pair else ", ".join(map(_plain, x))
    return "none" if x is None else f"{x:g}" if isinstance(x, float) else str(x)


def _statics_lines(st: dict) -> list[str]:
    """``validate``'s statics (:meth:`ambseal.analysis.statics.Statics.to_dict`) as text:
    the orientation, each AMB's static currents, who carries the axial weight."""
    tilt = (f" ({st['inclination_deg']:g}° above the horizontal)"
            if st["orientation"] == "inclined" else "")
    out = [f"{st['orientation']} machine{tilt}: gravity "
           + "(" + ", ".join(f"{g:.4g}" for g in st["gravity_m_s2"]) + ") m/s² on x, y, z"]
    for a in st["ambs"]:
        cur = ", ".join(f"{axis} {'?' if i is None else f'{i:.4g}'} A"
                        for axis, i in a["current_a"].items())
        out.append(f"AMB {a['name']} holds the rotor at rest with {cur} "
                   f"(force {a['force_n'][0]:.4g}, {a['force_n'][1]:.4g} N on x, y)")
    if not st["held"]:
        out.append("the bearings do not hold the rotor statically (one bearing plane: "
                   "nothing takes the weight's moment): no static currents")
    if st["axial_note"]:
        out.append(st["axial_note"])
    return out


def _validate(args: argparse.Namespace) -> int:
    v = validate_summary(args.rig, tuple(args.overrides))
    if args.json:
        print(json.dumps(v, indent=2))
        return 0
    print(f"{v['rig']}: valid — {v['name']}")
    print(f"  rotor mass {v['mass_kg']:.4g} kg, {v['nodes']} nodes, AMB axes "
          f"{', '.join(v['axes']) or 'none'}")
    print(f"  modes below {v['modes_below_hz']:g} Hz (controller Nyquist): "
          + ", ".join(f"{f:.4g} Hz (ζ {z:.3g})" for f, z in v["modes"]))
    poles = v["unstable_poles"]
    print(f"  {len(poles)} unstable open-loop poles"
          + (": " + ", ".join(f"{re:.4g}{im:+.4g}j rad/s" for re, im in poles) if poles else ""))
    for line in _statics_lines(v["statics"]):
        print("  " + line)
    print("  defaults a run takes:")
    for key, val in v["defaults"].items():
        if key == "judged_conditions" and not val:
            val = "none (no AMB: no controller to design or judge)"
        print(f"    {key}: {_plain(val)}")
    return 0


#: The command name → its handler (``args`` → exit status).
HANDLERS = {"acquire": _acquire_cmd, "identify": _identify, "design": _design, "track": _track,
            "export": _export, "run": _run, "validate": _validate, **rotordynamics.HANDLERS}
