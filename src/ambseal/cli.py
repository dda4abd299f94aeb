"""The ``ambseal`` command line: thin wiring of the stages, no numerics.

Commands
--------
``ambseal [--version] [-q | -v] COMMAND``
    ``--quiet``/``--verbose`` set the 'ambseal' logger (stage lines on stderr).
``ambseal run [RIG] [--out DIR]``
    The main job on a rig (default: the embedded thesis test facility).
``ambseal validate [RIG] [--json]``
    Parse and check a rig file; print its model summary and the defaults a run takes.
``ambseal modes [RIG] [--speed-rpm N] [--pressure-bar P] [--json] [--n-modes N] [--max-hz F]
[--controller C] [--shapes [PNG]] [--free | --no-amb]``
    Damped natural frequencies, damping ratios, log decrements, whirl and unstable poles of
    the full model (or of the closed loop), and the mode shapes.
``ambseal campbell RIG [--controller pid|hinf|mu|FILE] [--speed-hz a:b:n] [--pressure-bar P]``
    Closed-loop Campbell diagram with log decrements (API 684 limit flagged): PNG, JSON, CSV.
``ambseal sweep RIG --pressure-bar a:b:n [--speed-hz a:b:n] [--controller ...]
[--param NAME=a:b:n] [--scheduler ADDRESS | --workers N]``
    Stability and performance map; serial or on Dask.
``ambseal import-ross FILE --out RIG``
    A ROSS rotor file as an ambseal rig file.
``ambseal acquire RIG --truth TRUTH --excitation prbs|sine|chirp|impulse --pressure-bar P --out FILE``
    A record from the virtual test facility (CSV + JSON sidecar, or .mat).
``ambseal design [RIG] --method pid|hinf|mu|lpv [--out DIR] [--set design.KEY=VALUE ...]``
    Design a controller on the rig's reduced model; write it (continuous, Tustin and ZOH at
    the controller's sample rate) as .json, .npz and .mat, with a summary.
    ``--show-defaults`` prints the rig's resolved ``[design]`` part instead; ``--set``
    overrides a ``[design]`` key (also on ``run``); ``--allow-unstable`` keeps a controller
    whose full-order loop is unstable (marked in every output).
``ambseal export RIG --method pid|hinf|mu|lpv [--c DIR] [--precision double|float] [--out DIR]``
    Design a controller, choose and judge its discretisation for the target, and write it
    (.json, .npz, .mat) and as a C99 module (``--c``, default ``OUT/c``); with
    ``--controller FILE`` instead of ``--method``, the C module of an exported controller.
``ambseal identify RIG DATA... --params NAME,... --out DIR``
    Output-error fit of named parameters to closed-loop records; writes the fit, its
    figures and the identified rig.
``ambseal track RIG DATA... --params NAME,... --out DIR [--rate-per-s R]``
    On-line (recursive) tracking of named parameters through records: the estimate over
    time with its 95 % interval (CSV, JSON summary, figure).

Any error on bad input prints one line on stderr and exits with status 2.
"""

from __future__ import annotations

import argparse
import json
import math
import os
import shlex
import sys
from pathlib import Path

from .errors import AmbsealError

__all__ = ["main"]


class _Parser(argparse.ArgumentParser):
    """argparse with the project's error form: one line on stderr, exit status 2."""

    def error(self, message: str):  # noqa: D102 (argparse's hook)
        print(f"ambseal: error: {message}", file=sys.stderr)
        sys.exit(2)


def _finite(text: str) -> float:
    """A finite number of plausible size (|x| < 1e12: no argument of ambseal is larger in
    the units of its name)."""
    try:
        x = float(text)
    except ValueError:
        x = math.nan
    if not (math.isfinite(x) and abs(x) < 1e12):
        raise argparse.ArgumentTypeError(f"expected a finite number below 1e12, got {text!r}")
    return x


def _nonnegative(text: str) -> float:
    x = _finite(text)
    if x < 0:
        raise argparse.ArgumentTypeError(f"expected a number >= 0, got {text!r}")
    return x


def _whole(text: str, low: int) -> int:
    try:
        n = int(text)
    except ValueError:
        n = low - 1
    if not low <= n <= 10**6:
        raise argparse.ArgumentTypeError(f"expected a whole number from {low} to 1000000, "
                                         f"got {text!r}")
    return n


def _positive_int(text: str) -> int:
    return _whole(text, 1)


def _natural(text: str) -> int:
    return _whole(text, 0)


_RIG_HELP = "rig file (TOML); default: the embedded thesis test facility"
_RUN_TEXT = """The main job. Builds the rig's full FE model and its modal reduction; designs the
reference PID, an H∞ and a μ controller (thesis P5) — or, on a rig whose seals change with
speed over [operating] speed_range_hz, an H∞ controller at the operating speed and the LPV
controller scheduled on speed (P3) — and exports them; judges each on the full-order plant
at 0, nominal and 2× nominal pressure drop (or the ends and middle of the speed range):
stability, σ̄(S_o) and ISO 14839-3 zones per axis, compliance, worst-case unbalance orbit,
current-impulse response; for the embedded rig (or with --truth) identifies the rig on the
virtual test facility; writes metrics.json, figures and report.html (verdict first) to
--out. Progress on stderr (bars on a terminal, one line per stage otherwise); stdout gets
one JSON line with the output paths."""


class _Help(argparse.RawDescriptionHelpFormatter, argparse.ArgumentDefaultsHelpFormatter):
    """Help with each option's default, unless the default is 'none' (said in words)."""

    def _get_help_string(self, action):
        if action.default in (None, False) or action.default is argparse.SUPPRESS:
            return action.help
        return super()._get_help_string(action)


def _parser() -> argparse.ArgumentParser:
    from . import __version__

    p = _Parser(
        prog="ambseal",
        description="Rotors on active magnetic bearings with destabilising seal forces.",
        formatter_class=_Help,
    )
    p.add_argument("--version", action="version", version=f"ambseal {__version__}")
    loud = p.add_mutually_exclusive_group()
    loud.add_argument("-q", "--quiet", action="store_true",
                      help="no progress and no stage lines; errors only (stdout unchanged)")
    loud.add_argument("-v", "--verbose", action="store_true",
                      help="log every step (DEBUG on the 'ambseal' logger) instead of bars")
    sub = p.add_subparsers(dest="command", required=True)

    run = sub.add_parser("run", help="the main job: model, designs, judgement, "
                         "identification, report", description=_RUN_TEXT)
    run.add_argument("rig", nargs="?", help=_RIG_HELP)
    run.add_argument("--out", default="ambseal-out", help="output folder")
    run.add_argument("--truth", default=None,
                     help="truth file of the virtual facility: adds the identification stage "
                          "(the embedded rig uses its packaged truth)")
    run.add_argument("--no-identify", action="store_true", help="skip the identification stage")
    _design_options(run)

    v = sub.add_parser("validate", help="check a rig file; print its model and the defaults "
                       "a run takes")
    v.add_argument("rig", nargs="?", help=_RIG_HELP)
    v.add_argument("--json", action="store_true", help="print JSON instead of text")

    a = sub.add_parser("acquire", help="record a run of the virtual test facility")
    a.add_argument("rig", help="rig file (TOML)")
    a.add_argument("--truth", required=True, help="truth file of the virtual facility (TOML)")
    a.add_argument("--excitation", required=True,
                   choices=["prbs", "sine", "chirp", "impulse", "static"],
                   help="excitation signal; static: known static loads (P2 §5), written as "
                        "the load-step CSV that identify --static-load reads")
    a.add_argument("--pressure-bar", type=_finite, required=True, help="seal pressure drop (bar)")
    a.add_argument("--out", required=True, help="record file: .csv (+ .csv.json) or .mat")
    a.add_argument("--amplitude-a", type=_finite, default=0.05, help="excitation amplitude (A)")
    a.add_argument("--duration-s", type=_finite, default=1.0, help="record length (s)")
    a.add_argument("--axes", default=None, help="excited axes, e.g. A_zeta,B_zeta (default all)")
    a.add_argument("--clock-period-s", type=_finite, default=1e-3, help="PRBS clock period (s)")
    a.add_argument("--frequencies-hz", default="10,30,50,70,90,110,130,150,170,190",
                   help="stepped-sine frequencies (Hz), comma separated")
    a.add_argument("--cycles", type=_positive_int, default=10,
                   help="stepped sine: cycles per step")
    a.add_argument("--settling-cycles", type=_natural, default=5,
                   help="stepped sine: settling cycles")
    a.add_argument("--f0-hz", type=_finite, default=1.0, help="chirp start frequency (Hz)")
    a.add_argument("--f1-hz", type=_finite, default=150.0, help="chirp end frequency (Hz)")
    a.add_argument("--chirp", choices=["linear", "logarithmic"], default="linear",
                   help="chirp frequency sweep")
    a.add_argument("--width-s", type=_finite, default=0.01, help="impulse width (s)")
    a.add_argument("--start-s", type=_finite, default=0.05, help="impulse start (s)")
    a.add_argument("--seed", type=_natural, default=0, help="seed of excitation and noise")

    d = sub.add_parser("design", help="design a controller (pid, hinf, mu, lpv) and export it")
    d.add_argument("rig", nargs="?", help=_RIG_HELP)
    d.add_argument("--method", choices=["pid", "hinf", "mu", "lpv"],
                   help="the method (required unless --show-defaults)")
    d.add_argument("--show-defaults", action="store_true",
                   help="print the rig's resolved [design] part (values and their rules) "
                        "as TOML and exit")
    _design_options(d)
    d.add_argument("--pressure-bar", type=_finite, default=None,
                   help="design pressure drop (bar); default [operating] pressure_bar")
    d.add_argument("--out", default="ambseal-design", help="output folder")

    e = sub.add_parser("export", help="a controller for the real-time target: files and C code")
    e.add_argument("rig", help="rig file (TOML)")
    e.add_argument("--method", choices=["pid", "hinf", "mu", "lpv"],
                   help="design this controller (or give --controller)")
    e.add_argument("--controller", default=None,
                   help="a controller file written by ambseal (.json/.npz/.mat) to export "
                        "as C instead of designing one")
    e.add_argument("--pressure-bar", type=float, default=None,
                   help="design pressure drop (bar); default [operating] pressure_bar")
    e.add_argument("--out", default="ambseal-export", help="folder of the controller files")
    e.add_argument("--c", dest="c_dir", default=None, help="write the C99 module to this folder")
    e.add_argument("--precision", choices=["double", "float"], default="double",
                   help="floating-point type of the C module (default double)")

    i = sub.add_parser("identify", help="fit model parameters to closed-loop records")
    i.add_argument("rig", help="rig file (TOML)")
    i.add_argument("data", nargs="+", help="record files (.csv with sidecar, or .mat)")
    i.add_argument("--params", required=True,
                   help="parameters, e.g. A.Ki_zeta,A.Ks_zeta,tau_e,coupling.kxx,seal.k")
    i.add_argument("--out", required=True, help="output folder")
    i.add_argument("--current-weight", type=_nonnegative, default=0.0,
                   help="weight of the coil-current residuals (0: displacements only)")
    i.add_argument("--accept-unconverged", action="store_true",
                   help="write the identified rig even when the fit failed or is not "
                        "identifiable (the exit status is then 0)")
    i.add_argument("--accept-implausible", action="store_true",
                   help="write the identified rig even when the estimates or intervals are "
                        "implausible for the rig file (e.g. Ki or Ks 10x off: records in "
                        "other units?); the exit status is then 0")
    i.add_argument("--no-refine", action="store_true",
                   help="skip the second pass on a model re-reduced at the estimate")
    i.add_argument("--static-load", default=None, metavar="CSV",
                   help="static load steps (P2 §5: position_m, force_x_n, force_y_n, "
                        "current_<axis>_a): Ki by static loading, joined with the fit")
    tr = sub.add_parser("track", help="track parameters on line through closed-loop records")
    tr.add_argument("rig", help="rig file (TOML)")
    tr.add_argument("data", nargs="+", help="record files (.csv with sidecar, or .mat)")
    tr.add_argument("--params", required=True, help="LFT parameters, e.g. seal.k,seal.K")
    tr.add_argument("--out", default="ambseal-track", help="output folder")
    tr.add_argument("--rate-per-s", type=float, default=None,
                    help="expected drift per second as a fraction of each parameter's scale "
                         "(default 0.1)")
    from .rotordynamics import add_parsers

    add_parsers(sub, _positive_int)  # modes, campbell, sweep, import-ross
    _checked_numbers(p)
    for parser in sub.choices.values():  # every command's help names its defaults
        parser.formatter_class = _Help
    return p


def _checked_numbers(parser: argparse.ArgumentParser) -> None:
    """Every ``type=float`` argument of every command is finite and below 1e12 and every
    ``type=int`` one a whole number from 1 to 1e6 (whoever declared it)."""
    for action in parser._actions:
        if action.type is float:
            action.type = _finite
        elif action.type is int:
            action.type = _positive_int
        for sub in (action.choices or {}).values() if isinstance(action.choices, dict) else ():
            _checked_numbers(sub)


def _check_operating(args: argparse.Namespace) -> None:
    """The operating values given on the command line, by the rig file's rules."""
    from .config import check_operating

    values = {k: getattr(args, k, None) for k in ("pressure_bar", "speed_rpm")}
    check_operating({k: v for k, v in values.items() if isinstance(v, float)},
                    {"pressure_bar": "--pressure-bar", "speed_rpm": "--speed-rpm"})


def _design_options(p: argparse.ArgumentParser) -> None:
    p.add_argument("--set", action="append", default=[], metavar="design.KEY=VALUE",
                   dest="overrides",
                   help="override a [design] key of the rig file (a TOML value), e.g. "
                        "design.mu.orbit_um=8; repeatable")
    p.add_argument("--allow-unstable", action="store_true",
                   help="keep a controller whose full-order loop is unstable at a judged "
                        "condition (marked in every output) instead of stopping")


def _acquire(args: argparse.Namespace) -> int:
    from .config import load_rig, load_truth
    from .errors import ConfigError
    from .files import writable_folder
    from .identify import signals
    from .identify.data import save_measurement
    from .commands import target_pid
    from .identify.stages import acquire
    from .model.amb import channel_names

    cfg = load_rig(args.rig)
    truth = load_truth(args.truth)
    writable_folder(Path(args.out).parent)  # before the simulation
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
        from .identify.static_load import save_static_record, virtual_static_load

        z, F, cur = virtual_static_load(cfg, truth, seed=args.seed)
        path = save_static_record(args.out, cfg, z, F, cur)
        print(json.dumps({"out": str(path), "load_steps": int(z.size)}))
        return 0
    common = dict(sample_rate_hz=fs, axes=axes, excited=excited)
    try:
        if args.excitation == "prbs":
            ex = signals.prbs(amplitude_a=args.amplitude_a, clock_period_s=args.clock_period_s,
                              duration_s=args.duration_s, seed=args.seed, **common)
        elif args.excitation == "sine":
            freqs = [float(f) for f in args.frequencies_hz.split(",")]
            ex = signals.stepped_sine(frequencies_hz=freqs, amplitude_a=args.amplitude_a,
                                      cycles=args.cycles, settling_cycles=args.settling_cycles,
                                      **common)
        elif args.excitation == "chirp":
            ex = signals.chirp(f0_hz=args.f0_hz, f1_hz=args.f1_hz, duration_s=args.duration_s,
                               amplitude_a=args.amplitude_a, method=args.chirp, **common)
        else:
            ex = signals.impulse(amplitude_a=args.amplitude_a, width_s=args.width_s,
                                 start_s=args.start_s, duration_s=args.duration_s, **common)
    except ValueError as exc:
        raise ConfigError(f"acquire: {exc}") from None
    try:
        meas = acquire(cfg, truth, ex, controller=target_pid(cfg),
                       pressure_bar=args.pressure_bar, seed=args.seed)
    except AmbsealError as exc:  # the simulation runs on the truth file's values
        raise _named(exc, [args.truth], f"{args.truth} (with {args.rig})") from None
    path = save_measurement(meas, args.out)
    print(json.dumps({"out": str(path), "samples": meas.n_samples,
                      "sample_rate_hz": fs}))
    return 0


def _design(args: argparse.Namespace) -> int:
    from .commands import design_files, show_defaults
    from .config import default_rig_path

    rig = args.rig if args.rig is not None else default_rig_path()

    if args.show_defaults:
        print(show_defaults(rig, args.overrides), end="")
        return 0
    if args.method is None:
        from .errors import ConfigError

        raise ConfigError("design: --method is required (pid, hinf, mu or lpv) unless "
                          "--show-defaults")
    print(json.dumps(design_files(rig, args.method, args.out,
                                  pressure_bar=args.pressure_bar, overrides=args.overrides,
                                  allow_unstable=args.allow_unstable)))
    return 0


def _export(args: argparse.Namespace) -> int:
    from .commands import design_files
    from .errors import ConfigError

    if (args.method is None) == (args.controller is None):
        raise ConfigError("export: give exactly one of --method and --controller")
    if args.controller is not None:
        from .control.codegen import write_c
        from .control.export import load_controller

        ctrl = load_controller(args.controller)
        files = write_c(ctrl, args.c_dir or Path(args.out) / "c",
                        f"ambseal_{Path(args.controller).stem}", precision=args.precision)
        print(json.dumps({"files": [str(f) for f in files]}))
        return 0
    print(json.dumps(design_files(args.rig, args.method, args.out,
                                  pressure_bar=args.pressure_bar,
                                  c_dir=args.c_dir or Path(args.out) / "c",
                                  precision=args.precision)))
    return 0


def _identify(args: argparse.Namespace) -> int:
    from .commands import identify_files

    summary = identify_files(args.rig, args.data, args.params.split(","), args.out,
                             current_weight=args.current_weight, refine=not args.no_refine,
                             accept_unconverged=args.accept_unconverged,
                             static_load=args.static_load,
                             accept_implausible=args.accept_implausible)
    print(json.dumps(summary))
    return 0


def _track(args: argparse.Namespace) -> int:
    from .commands import track_files

    summary = track_files(args.rig, args.data, args.params.split(","), args.out,
                          rate_per_s=args.rate_per_s)
    print(json.dumps(summary))
    return 0


def _run(args: argparse.Namespace) -> int:
    from .pipeline import run

    result = run(args.rig, args.out, truth=args.truth, identification=not args.no_identify,
                 overrides=tuple(args.overrides), allow_unstable=args.allow_unstable,
                 command=args.command_line, progress=not (args.quiet or args.verbose))
    for reason in result.metrics.get("cannot_run", {}).values():
        print(f"ambseal: {reason}", file=sys.stderr)
    if sys.stderr.isatty() and not args.quiet:
        from rich.console import Console

        from .config import load_rig
        from .report.run_report import rig_clearances_um
        from .report.verdict import verdict_table_rich, verdicts

        console = Console(stderr=True)
        clear = rig_clearances_um(load_rig(args.rig))
        console.print(verdict_table_rich(verdicts(result.metrics["cases"], clear)))
        console.print(f"report: {result.report_path.resolve()}")
    print(json.dumps({"out": str(result.out_dir), "metrics": str(result.metrics_path),
                      "report": str(result.report_path)}))
    return 0


def _plain(x) -> str:
    """A value of ``validate``'s defaults as text: dicts as ``key value``, pairs as ranges."""
    if isinstance(x, dict):
        return ", ".join(f"{k} {_plain(w)}" for k, w in x.items())
    if isinstance(x, (list, tuple)):
        pair = len(x) == 2 and all(isinstance(y, (int, float)) for y in x)
        return "–".join(map(_plain, x)) if pair else ", ".join(map(_plain, x))
    return "none" if x is None else f"{x:g}" if isinstance(x, float) else str(x)


def _validate(args: argparse.Namespace) -> int:
    from .commands import validate_summary

    v = validate_summary(args.rig)
    if args.json:
        print(json.dumps(v, indent=2))
        return 0
    print(f"{v['rig']}: valid — {v['name']}")
    print(f"  rotor mass {v['mass_kg']:.4g} kg, {v['nodes']} nodes, AMB axes "
          f"{', '.join(v['axes'])}")
    print(f"  modes below {v['modes_below_hz']:g} Hz (controller Nyquist): "
          + ", ".join(f"{f:.4g} Hz (ζ {z:.3g})" for f, z in v["modes"]))
    poles = v["unstable_poles"]
    print(f"  {len(poles)} unstable open-loop poles"
          + (": " + ", ".join(f"{re:.4g}{im:+.4g}j rad/s" for re, im in poles) if poles else ""))
    print("  defaults a run takes:")
    for key, val in v["defaults"].items():
        print(f"    {key}: {_plain(val)}")
    return 0


def _logging(args: argparse.Namespace) -> None:
    """Stage lines of the 'ambseal' logger to stderr: INFO by default, WARNING with
    --quiet, DEBUG with --verbose (a library user routes the logger as they like)."""
    import logging

    log = logging.getLogger("ambseal")
    handler = logging.StreamHandler(sys.stderr)
    handler.setFormatter(logging.Formatter("ambseal: %(message)s"))
    log.handlers[:] = [handler]
    log.propagate = False
    level = (logging.WARNING if args.quiet else
             logging.DEBUG if args.verbose else logging.INFO)
    if level == logging.INFO and sys.stderr.isatty():
        level = logging.WARNING  # on a terminal the progress bars say it
    log.setLevel(level)


def _named(exc: AmbsealError, files: list, source: str) -> AmbsealError:
    """``exc`` with ``source: `` in front unless its message names one of ``files``."""
    msg = str(exc)
    if any(str(f) in msg for f in files if f):
        return exc
    return type(exc)(f"{source}: {msg}")


def _inputs(args: argparse.Namespace) -> tuple[list, str]:
    """The files a command reads and writes, and the one an unnamed error comes from."""
    from .config import default_rig_path

    rig = getattr(args, "rig", None) or default_rig_path()
    ctrl = getattr(args, "controller", None)  # a file, or a method's name (pid, hinf, ...)
    files = [rig, getattr(args, "truth", None), getattr(args, "out", None),
             *(getattr(args, "data", None) or []),
             ctrl if ctrl and Path(ctrl).suffix.lower() in (".json", ".npz", ".mat") else None]
    return files, str(rig)


def main(argv: list[str] | None = None) -> int:
    """Entry point of the ``ambseal`` console script; returns the exit status.

    Warnings raised on the way (numpy's, say) are shown after a successful command and
    dropped when the command ends in the one error line."""
    import warnings

    args = _parser().parse_args(argv)
    args.command_line = shlex.join(["ambseal", *(sys.argv[1:] if argv is None else argv)])
    _logging(args)
    from .rotordynamics import HANDLERS

    handler = {"acquire": _acquire, "identify": _identify, "design": _design,
               "track": _track, "export": _export, "run": _run, "validate": _validate, **HANDLERS}[args.command]
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("default")
        try:
            _check_operating(args)
            code = handler(args)
        except AmbsealError as exc:
            print(f"ambseal: error: {_named(exc, *_inputs(args))}", file=sys.stderr)
            return 2
        except MemoryError:
            print(f"ambseal: error: {args.command}: not enough memory for this input",
                  file=sys.stderr)
            return 2
        except KeyboardInterrupt:
            print("ambseal: interrupted", file=sys.stderr)
            return 130
        except BrokenPipeError:  # e.g. `ambseal modes rig.toml | head`
            sys.stdout = open(os.devnull, "w")
            return 0
    for w in caught:
        warnings.showwarning(w.message, w.category, w.filename, w.lineno)
    return code


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
