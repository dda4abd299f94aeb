"""The ``ambseal`` command line: thin wiring of the stages, no numerics.

Commands
--------
``ambseal [--version] [-q | -v] COMMAND``
    ``--quiet``/``--verbose`` set the 'ambseal' logger (stage lines on stderr).
``ambseal run [RIG] [--out DIR]``
    The main job on a rig (default: the embedded thesis test facility). Exit status 1: the
    report is written but a designed controller failed (named on stderr).
``ambseal validate [RIG] [--json] [--set design.KEY=VALUE ...]``
    Parse and check a rig file; print its model summary and the defaults a run takes.
``ambseal modes [RIG] [--speed-rpm N] [--pressure-bar P] [--json] [--n-modes N] [--max-hz F]
[--controller C] [--shapes [PNG]] [--free | --no-amb]``
    Damped natural frequencies, damping ratios, log decrements, whirl and unstable poles of
    the full model (or of the closed loop), and the mode shapes.
``ambseal campbell RIG [--controller pid|hinf|mu|FILE] [--speed-hz a:b:n] [--pressure-bar P]``
    Closed-loop Campbell diagram with log decrements (API 684 limit flagged): PNG, JSON, CSV.
``ambseal sweep RIG [--pressure-bar a:b:n] [--speed-hz a:b:n] [--controller ...]
[--param NAME=a:b:n] [--scheduler ADDRESS | --workers N]``
    Stability and performance map; serial or on Dask.
``ambseal import-ross FILE --out RIG [--speed-rpm N]``
    A ROSS rotor file as an ambseal rig file.
``ambseal acquire RIG --truth TRUTH --excitation prbs|sine|chirp|impulse --pressure-bar P --out FILE
[--controller C]``
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

Any error on bad input prints one line on stderr and exits with status 2; ``run`` exits
with status 1 when it wrote its report but a designed controller failed.
"""

from __future__ import annotations

import argparse
import logging
import math
import os
import shlex
import sys
import warnings
from pathlib import Path

from ambseal import __version__
from ambseal.config import check_operating, default_rig_path, method_names
from ambseal.errors import AmbsealError, with_source
from ambseal.threads import DEFAULT_THREADS, ENV_VAR, blas_threads, numerics_threads

__all__ = ["main"]


class _Parser(argparse.ArgumentParser):
    """argparse with the project's error form: one line on stderr, exit status 2."""

    def error(self, message: str):  # noqa: D102 (argparse's hook)
        print(f"ambseal: error: {message}", file=sys.stderr)
        sys.exit(2)


def _folder_force(parser) -> None:
    """``--force`` of a command writing an output folder (:mod:`ambseal.files`)."""
    parser.add_argument("--force", action="store_true",
                        help="replace files ambseal wrote into --out that were changed since "
                             "(without it they are the user's and the folder is refused); "
                             "files ambseal did not write are never replaced")


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


def _span(text: str) -> tuple[float, float]:
    """``X`` or ``LO:HI``, finite, 0 ≤ LO ≤ HI: a value, or a range to draw from."""
    parts = text.split(":")
    if len(parts) > 2:
        raise argparse.ArgumentTypeError(f"expected X or LO:HI, got {text!r}")
    lo, hi = (_finite(p) for p in (parts * 2)[:2])
    if not 0 <= lo <= hi:
        raise argparse.ArgumentTypeError(f"expected 0 <= LO <= HI, got {text!r}")
    return lo, hi


def _positive(text: str) -> float:
    """A finite number above 0 (a tolerance, a frequency limit, a duration)."""
    x = _finite(text)
    if x <= 0:
        raise argparse.ArgumentTypeError(f"expected a number > 0, got {text!r}")
    return x


#: Local Dask worker processes per core at most: each is a Python process with ambseal,
#: numpy and scipy loaded (about 150 MB) running one case at a time on one BLAS thread, so
#: more than a few per core only add start-up time and memory.
WORKERS_PER_CORE = 4


def _workers(text: str) -> int:
    """A count of local worker processes: 1 to :data:`WORKERS_PER_CORE` per core."""
    most = WORKERS_PER_CORE * (os.cpu_count() or 1)
    n = _whole(text, 1) if text.strip().lstrip("+").isdigit() else 0
    if not 1 <= n <= most:
        raise argparse.ArgumentTypeError(f"expected a whole number from 1 to {most} "
                                         f"({WORKERS_PER_CORE} per core), got {text!r}")
    return n


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
one JSON line with the output paths.

A controller whose loop is unstable at a judged condition, or whose design failed, does not
stop the run: every controller is judged and reported, the failed ones marked (metrics.json
"failed", the report's "Failed controllers" part) and named with the reason on stderr; a failed
designed controller is not exported. Exit status: 0 all delivered; 1 the report is written
but a designed controller failed (with --allow-unstable an unstable one is exported, still
marked, and does not count); 2 bad input (nothing written). The reference PID of the rig
file is marked the same way but never changes the status."""


class _Help(argparse.RawDescriptionHelpFormatter, argparse.ArgumentDefaultsHelpFormatter):
    """Help with each option's default, unless the default is 'none' (said in words)."""

    def _get_help_string(self, action):
        if action.default in (None, False) or action.default is argparse.SUPPRESS:
            return action.help
        return super()._get_help_string(action)


def _parser() -> argparse.ArgumentParser:
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
    p.add_argument("--blas-threads", default=None, metavar="N",
                   help="BLAS/OpenMP threads of the numerics: a whole number or 'inherit' "
                        f"(leave them as the environment sets them); default "
                        f"${ENV_VAR}, else {DEFAULT_THREADS} (fastest for ambseal's many "
                        f"small matrices)")
    sub = p.add_subparsers(dest="command", required=True)

    run = sub.add_parser("run", help="the main job: model, designs, judgement, "
                         "identification, report", description=_RUN_TEXT)
    run.add_argument("rig", nargs="?", help=_RIG_HELP)
    run.add_argument("--out", default="ambseal-out", help="output folder")
    _folder_force(run)
    run.add_argument("--truth", default=None,
                     help="truth file of the virtual facility: adds the identification stage "
                          "(the embedded rig uses its packaged truth)")
    run.add_argument("--no-identify", action="store_true", help="skip the identification stage")
    _design_options(run)

    v = sub.add_parser("validate", help="check a rig file; print its model and the defaults "
                       "a run takes")
    v.add_argument("rig", nargs="?", help=_RIG_HELP)
    v.add_argument("--json", action="store_true", help="print JSON instead of text")
    v.add_argument("--set", action="append", default=[], metavar="design.KEY=VALUE",
                   dest="overrides",
                   help="check the rig with a [design] key overridden, as run and design "
                        "take it (a TOML value); repeatable")

    a = sub.add_parser("acquire", help="record a run of the virtual test facility")
    a.add_argument("rig", help="rig file (TOML)")
    a.add_argument("--truth", required=True, help="truth file of the virtual facility (TOML)")
    a.add_argument("--excitation", required=True,
                   choices=["prbs", "sine", "chirp", "impulse", "static"],
                   help="excitation signal; static: known static loads (P2 §5), written as "
                        "the load-step CSV that identify --static-load reads")
    a.add_argument("--pressure-bar", type=_finite, required=True, help="seal pressure drop (bar)")
    a.add_argument("--out", required=True, help="record file: .csv (+ .csv.json) or .mat")
    a.add_argument("--force", action="store_true",
                   help="replace --out (and its sidecar) even if ambseal did not write them "
                        "(a link is replaced, never written through)")
    # the excitation defaults follow from the rig (ambseal.identify.excitation.plan)
    a.add_argument("--amplitude-a", type=_positive, default=None,
                   help="excitation amplitude (A; default [design.impulse] amplitude_a, else "
                        "bias current / 120)")
    a.add_argument("--duration-s", type=_positive, default=None,
                   help="record length (s; default 1000 PRBS clock periods)")
    a.add_argument("--axes", default=None, help="excited axes, e.g. A_zeta,B_zeta (default all)")
    a.add_argument("--clock-period-s", type=_positive, default=None,
                   help="PRBS clock period (s; default 10 controller samples)")
    a.add_argument("--controller", default=None,
                   help="levitate the facility with this controller file (written by "
                        "ambseal; as it runs at the record's speed and pressure) instead of "
                        "the rig's reference PID, e.g. where that PID cannot run")
    a.add_argument("--speed-hz", type=_finite, default=None,
                   help="spin speed of the run (Hz; default the rig's operating speed; "
                        "standstill up to the top of [operating] speed_range_hz)")
    a.add_argument("--frequencies-hz", default=None,
                   help="stepped-sine frequencies (Hz), comma separated (default: f_top/20, "
                        "then f_top/10 to f_top in 10 steps; f_top the larger of the "
                        "sample rate/50 and 1.1x the top speed)")
    a.add_argument("--cycles", type=_positive_int, default=10,
                   help="stepped sine: cycles per step")
    a.add_argument("--settling-cycles", type=_natural, default=5,
                   help="stepped sine: settling cycles")
    a.add_argument("--f0-hz", type=_finite, default=None,
                   help="chirp start frequency (Hz; default 1 / (1000 PRBS clock periods))")
    a.add_argument("--f1-hz", type=_finite, default=None,
                   help="chirp end frequency (Hz; default 0.75 × sample rate / 50)")
    a.add_argument("--chirp", choices=["linear", "logarithmic"], default="linear",
                   help="chirp frequency sweep")
    a.add_argument("--width-s", type=_positive, default=None,
                   help="impulse width (s; default [design.impulse] duration_s, else 100 "
                        "controller samples)")
    a.add_argument("--start-s", type=_finite, default=None,
                   help="impulse start (s; default 5 impulse widths)")
    a.add_argument("--seed", type=_natural, default=0, help="seed of excitation and noise")

    options = list(method_names(option=True))
    d = sub.add_parser("design", help=f"design a controller ({', '.join(options)}) and export it")
    d.add_argument("rig", nargs="?", help=_RIG_HELP)
    d.add_argument("--method", choices=options,
                   help="the method (required unless --show-defaults)")
    d.add_argument("--show-defaults", action="store_true",
                   help="print the rig's resolved [design] part (values and their rules) "
                        "as TOML and exit")
    _design_options(d)
    d.add_argument("--pressure-bar", type=_finite, default=None,
                   help="design pressure drop (bar); default [operating] pressure_bar")
    d.add_argument("--out", default="ambseal-design", help="output folder")
    _folder_force(d)

    e = sub.add_parser("export", help="a controller for the real-time target: files and C code")
    e.add_argument("rig", help="rig file (TOML)")
    e.add_argument("--method", choices=options,
                   help="design this controller (or give --controller)")
    e.add_argument("--controller", default=None,
                   help="a controller file written by ambseal (.json/.npz/.mat) to export "
                        "as C instead of designing one (a continuous one is discretised for "
                        "the rig's target first, as design does)")
    e.add_argument("--pressure-bar", type=float, default=None,
                   help="design pressure drop (bar); default [operating] pressure_bar")
    e.add_argument("--out", default="ambseal-export", help="folder of the controller files")
    _folder_force(e)
    e.add_argument("--c", dest="c_dir", default=None, help="write the C99 module to this folder")
    e.add_argument("--precision", choices=["double", "float"], default="double",
                   help="floating-point type of the C module (default double)")
    e.add_argument("--allow-unstable", action="store_true",
                   help="export a controller whose full-order loop is unstable at a judged "
                        "condition (marked in every file) instead of refusing it")

    i = sub.add_parser("identify", help="fit model parameters to closed-loop records")
    i.add_argument("rig", help="rig file (TOML)")
    i.add_argument("data", nargs="+", help="record files (.csv with sidecar, or .mat)")
    i.add_argument("--params", required=True,
                   help="parameters, e.g. A.Ki_zeta,A.Ks_zeta,tau_e,coupling.kxx,seal.k")
    i.add_argument("--out", required=True, help="output folder")
    _folder_force(i)
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
    _folder_force(tr)
    tr.add_argument("--rate-per-s", type=_positive, default=None,
                    help="expected drift per second as a fraction of each parameter's scale "
                         "(default 0.1)")

    _rotordynamics_parsers(sub)
    _checked_numbers(p)
    for parser in sub.choices.values():  # every command's help names its defaults
        parser.formatter_class = _Help
    return p


def _rotordynamics_parsers(sub) -> None:
    """Add ``modes``, ``campbell``, ``sweep`` and ``import-ross`` to the CLI's subparsers."""
    m = sub.add_parser("modes", help="natural frequencies, damping, log decrement, whirl, "
                                     "unstable poles and mode shapes")
    m.add_argument("rig", nargs="?", help="rig file (TOML); default: the embedded thesis test "
                                          "facility")
    m.add_argument("--speed-rpm", type=float, default=None, help="spin speed (rpm)")
    m.add_argument("--pressure-bar", type=float, default=None, help="seal pressure drop (bar)")
    m.add_argument("--json", action="store_true", help="print JSON instead of a table")
    m.add_argument("--n-modes", type=_positive_int, default=None,
                   help="only the N lowest modes (sparse shift-invert; unstable poles up to "
                        "the N-th mode only)")
    m.add_argument("--max-hz", type=_positive, default=None,
                   help="modes up to this frequency (Hz); default 1.25x the third free-free "
                        "bending frequency")
    m.add_argument("--controller", default=None,
                   help="close the loop: pid, hinf, mu or a controller file (default: the "
                        "open-loop model)")
    m.add_argument("--shapes", nargs="?", const="mode_shapes.png", default=None,
                   metavar="PNG", help="plot the mode shapes (default file mode_shapes.png)")
    m.add_argument("--force", action="store_true",
                   help="replace the --shapes file even if ambseal did not write it (a link "
                        "is replaced, never written through)")
    g = m.add_mutually_exclusive_group()
    g.add_argument("--free", action="store_true", help="bare rotor: shaft and disks only")
    g.add_argument("--no-amb", action="store_true", help="leave the AMBs out")

    c = sub.add_parser("campbell", help="closed-loop Campbell diagram and log decrements")
    c.add_argument("rig", help="rig file (TOML)")
    c.add_argument("--controller", default=None,
                   help="pid, hinf, mu, none or a controller file (default pid, else hinf)")
    c.add_argument("--speed-hz", default=None, help="speeds a:b:n (Hz); default 0 to 1.2x "
                   "the top speed (or the first free-free bending frequency), 31 points")
    c.add_argument("--pressure-bar", type=float, default=None,
                   help="seal pressure drop (bar); default [operating] pressure_bar")
    c.add_argument("--max-hz", type=_positive, default=None, help="highest mode frequency (Hz)")
    c.add_argument("--log-dec-limit", type=float, default=0.1,
                   help="flag modes below this log decrement (API 684: 0.1)")
    c.add_argument("--out", default="ambseal-campbell", help="output folder")
    _folder_force(c)
    _executor_args(c)

    s = sub.add_parser("sweep", help="stability and performance map over pressure x speed")
    s.add_argument("rig", help="rig file (TOML)")
    s.add_argument("--pressure-bar", default=None,
                   help="pressure drops a:b:n (bar); default the rig's [operating] "
                        "pressure_bar, the one pressure")
    s.add_argument("--speed-hz", default=None,
                   help="speeds a:b:n (Hz); default the rig's [design] stability_speeds_hz "
                        "(standstill to the top speed, as `run` checks)")
    s.add_argument("--controller", default=None,
                   help="pid, hinf, mu or controller files, comma separated (default pid)")
    s.add_argument("--param", action="append", metavar="NAME=a:b:n",
                   help="a rig parameter to sweep too, e.g. seal.k=0:2e6:5 (repeatable)")
    s.add_argument("--max-hz", type=_positive, default=None,
                   help="modes of the lowest log decrement up to this frequency (Hz)")
    s.add_argument("--tol-bar", type=_positive, default=0.01,
                   help="the stability boundary is bisected to this pressure (bar)")
    s.add_argument("--out", default="ambseal-sweep", help="output folder")
    _folder_force(s)
    _executor_args(s)

    so = sub.add_parser("signoff", help="sign a machine off: API 617 stability (Level I "
                                        "and II) and unbalance response, ISO 14839-2 "
                                        "zones, with each controller as it runs")
    so.add_argument("rig", help="rig file (TOML) with its [[stage]] tables")
    sg = so.add_mutually_exclusive_group()
    sg.add_argument("--method", default=None,
                    help="pid, hinf, mu or none, comma separated: designed and discretised "
                         "as ambseal design does (default pid, or none on a rig without "
                         "AMBs)")
    sg.add_argument("--controller", default=None,
                    help="a controller file of ambseal design (.json, .npz, .mat)")
    so.add_argument("--out", default="ambseal-signoff", help="output folder")
    _folder_force(so)
    so.add_argument("--json", action="store_true",
                    help="print one JSON object (per controller its criteria and the "
                         "level1, level2, unbalance and iso14839_2 blocks)")

    dr = sub.add_parser("drop", help="drop the rotor onto its touchdown bearings: every "
                                     "AMB lets go at the operating speed")
    dr.add_argument("rig", help="rig file (TOML) with its [[touchdown]] tables")
    dg = dr.add_mutually_exclusive_group()
    dg.add_argument("--speed-rpm", type=_finite, default=None,
                    help="spin speed (rpm), held, negative turning the other way (as "
                         "[operating] speed_rpm, its default), up to the trip speed")
    dg.add_argument("--speed-hz", type=_finite, default=None,
                    help="spin speed (Hz), held; the rule of --speed-rpm")
    dg.add_argument("--at", choices=("standstill", "max-continuous", "trip"), default=None,
                    help="the spin speed by name: 0, the top of [operating] speed_range_hz "
                         "(else speed_rpm), or trip_speed_hz (else 1.05 × that), in the "
                         "sense of rotation of speed_rpm")
    dr.add_argument("--event", choices=("loss", "one-axis", "overload"), default="loss",
                    help="what lands the rotor: every AMB loses power (default), one axis "
                         "does (--axis) while the others run on, or an overload: a step "
                         "force (--overload-n), a seal surge (--surge-bar) or both")
    dr.add_argument("--axis", default=None,
                    help="--event one-axis: the axis lost, AMB_zeta or AMB_eta (default "
                         "the one carrying the most static load)")
    dr.add_argument("--overload-n", type=_positive, default=None,
                    help="--event overload: the step force (N), downward")
    dr.add_argument("--overload-at", default=None,
                    help="--event overload: a seal, AMB, touchdown bearing or named disk "
                         "where it acts (default the centre of mass)")
    dr.add_argument("--surge-bar", type=_finite, default=None,
                    help="--event overload: a seal surge, the seals' pressure drop stepping "
                         "to this (bar) at the event")
    dr.add_argument("--controller", default=None,
                    help="the AMB loop's controller: pid, hinf, mu (designed here, run in "
                         "continuous time) or a controller file (a digital one runs as on "
                         "the target: sampled, with its delay); default the rig's "
                         "reference PID")
    dr.add_argument("--pressure-bar", type=_finite, default=None,
                    help="the seals' pressure drop (bar) through the drop; default "
                         "[operating] pressure_bar")
    dr.add_argument("--axial-thrust-n", type=_finite, default=None,
                    help="--event loss: the residual thrust on the rotor (N, +z towards "
                         "its far end) when the thrust bearing lets go with the AMBs; "
                         "default [drop] axial_thrust")
    dr.add_argument("--penetration-ratio", type=_finite, default=None,
                    help="the deepest penetration of a ring, over its clearance, within "
                         "which the contact law holds; beyond it the verdict says the "
                         "drop left its model's range (default [drop] penetration_ratio)")
    dr.add_argument("--duration-s", type=_positive, default=0.5,
                    help="time simulated after the AMBs let go (s; default 0.5)")
    dr.add_argument("--coast-down", action="store_true",
                    help="the drive lets go too: the spin slows under the rings' friction "
                         "and --drag-torque (default: the speed is held)")
    dr.add_argument("--drag-torque", type=_finite, default=0.0,
                    help="process and windage torque against the spin (N·m; with "
                         "--coast-down)")
    dr.add_argument("--modes-hz", type=_positive, default=None,
                    help="keep the free rotor's modes below this (Hz); default four times "
                         "the contact's own frequency")
    dr.add_argument("--unbalance-kgm", type=_span, default=None,
                    help="static unbalance at the centre of mass (kg·m): X, or LO:HI drawn "
                         "per run with --runs")
    dr.add_argument("--start", choices=("levitated", "rest"), default="levitated",
                    help="the state the AMBs let go of: levitated, the unbalance orbit of "
                         "the reference PID's loop at the speed (default), or at rest in "
                         "the levitated equilibrium")
    dr.add_argument("--runs", type=int, default=None,
                    help="Monte-Carlo drops over the scatter below (drop_scatter.csv, "
                         ".json: the probability of backward whirl and of a failed verdict; "
                         "exit 1 if any run fails)")
    dr.add_argument("--seed", type=int, default=1, help="the Monte-Carlo draws' seed")
    dr.add_argument("--friction", type=_span, default=None,
                    help="LO:HI: each touchdown bearing's friction drawn per run")
    dr.add_argument("--clearance-tol-um", type=_positive, default=None,
                    help="each touchdown bearing's radial clearance drawn within ± this (µm)")
    dr.add_argument("--support-damping", type=_span, default=None,
                    help="LO:HI: a factor on each support's damping, drawn per run")
    _executor_args(dr)
    dr.add_argument("--out", default="ambseal-drop", help="output folder")
    _folder_force(dr)
    dr.add_argument("--json", action="store_true", help="print one JSON object")

    r = sub.add_parser("import-ross", help="a ROSS rotor file (.toml/.json) as an ambseal rig")
    r.add_argument("file", help="ROSS rotor file saved by ross.Rotor.save")
    r.add_argument("--out", required=True, help="rig file to write (TOML)")
    r.add_argument("--force", action="store_true",
                   help="replace --out even if ambseal did not write it (a link is "
                        "replaced, never written through)")
    r.add_argument("--speed-rpm", type=float, default=None,
                   help="take frequency-dependent bearing coefficients at this speed's "
                        "synchronous frequency, as ROSS's run_modal(speed) does, and make it "
                        "the rig's operating speed (default: the lowest frequency of ROSS's "
                        "tables)")


def _executor_args(p) -> None:
    g = p.add_mutually_exclusive_group()
    g.add_argument("--workers", type=_workers, default=None,
                   help="local Dask worker processes (1: serial; default: serial for small "
                        "runs, one per core for large ones)")
    g.add_argument("--scheduler", default=None,
                   help="address of a running Dask scheduler (trusted: whoever can reach it "
                        "runs code in its workers)")


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


def _logging(args: argparse.Namespace) -> None:
    """Stage lines of the 'ambseal' logger to stderr: INFO by default, WARNING with
    --quiet, DEBUG with --verbose (a library user routes the logger as they like)."""

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


def _inputs(args: argparse.Namespace) -> tuple[list, str]:
    """The files a command reads and writes, and the one an unnamed error comes from."""

    # a command's own input (a rig, or import-ross's ROSS file) is the source to name
    rig = getattr(args, "rig", None) or getattr(args, "file", None) or default_rig_path()
    ctrl = getattr(args, "controller", None)  # a file, or a method's name (pid, hinf, ...)
    files = [rig, getattr(args, "truth", None), getattr(args, "out", None),
             getattr(args, "shapes", None), getattr(args, "c_dir", None),
             *(getattr(args, "data", None) or []),
             ctrl if ctrl and Path(ctrl).suffix.lower() in (".json", ".npz", ".mat") else None]
    return files, str(rig)


def _open_stream(stream) -> bool:
    """False for a standard stream that is missing, or whose descriptor is closed or open
    for reading only (a wrapper script run with `2>&-` leaves its own file on descriptor 2
    for the interpreter it starts); an in-memory one (no descriptor: a test's capture) is
    open."""
    if stream is None:
        return False
    try:
        fd = stream.fileno()
    except (AttributeError, ValueError, OSError):  # io.UnsupportedOperation is an OSError
        return True
    try:
        # POSIX only; elsewhere an open descriptor is taken as writable
        import fcntl
    except ImportError:
        fcntl = None
    try:
        os.fstat(fd)
        if fcntl is not None:
            return fcntl.fcntl(fd, fcntl.F_GETFL) & os.O_ACCMODE != os.O_RDONLY
    except OSError:
        return False
    return True


def main(argv: list[str] | None = None) -> int:
    """Entry point of the ``ambseal`` console script; returns the exit status.

    Warnings raised on the way (ambseal's own, numpy's) are shown after a successful
    command, one line each (``ambseal: warning: …``, :func:`_warning_line`), and dropped
    when the command ends in the one error line. A library user keeps Python's own
    warnings: only the command line formats them."""

    # a shell may start us with stdout or stderr closed (`2>&-`): Python has None there (the
    # console script) or a stream on the closed descriptor (`python -m`), and the first
    # message (or rich's isatty) would fail with exit 1; they go nowhere instead, and the
    # exit status is the command's
    for stream in ("stdout", "stderr"):
        if not _open_stream(getattr(sys, stream)):
            setattr(sys, stream, open(os.devnull, "w", encoding="utf-8"))
    parser = _parser()
    args = parser.parse_args(argv)
    if argv is None:
        # the console script's own process draws on Agg canvases and never through pyplot:
        # the environment's MPLBACKEND (a Jupyter kernel's inline backend under `!ambseal`,
        # or one that does not exist, which stops matplotlib's import) is not ours to load
        os.environ.pop("MPLBACKEND", None)
    try:
        blas_threads(args.blas_threads)
    except AmbsealError as exc:
        parser.error(str(exc))
    if args.blas_threads is not None:  # the policy of this command and of its children
        os.environ[ENV_VAR] = args.blas_threads
    args.command_line = shlex.join(["ambseal", *(sys.argv[1:] if argv is None else argv)])
    _logging(args)

    # The commands' code loads python-control, scipy.signal and matplotlib (1.6 s of a
    # 1.8 s start on a 2-core machine): imported once a command runs, so that --help and
    # argument errors answer at once; `modes`, a quick look at a model, loads its own
    # module only (ambseal.app.modes).
    if args.command == "modes":
        from ambseal.app import modes_command as handler  # start-up, as above
    else:
        from ambseal.app import HANDLERS  # start-up, as above

        handler = HANDLERS[args.command]
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("default")
        # a dependency's notice to its own users' code (python-control on NumPy 2.5: "Setting
        # the shape on a NumPy array has been deprecated") is nothing a user of ambseal can
        # act on; ambseal's own are shown
        for category in (DeprecationWarning, PendingDeprecationWarning, FutureWarning):
            warnings.filterwarnings("ignore", category=category)
            warnings.filterwarnings("default", category=category, module=r"ambseal(\.|$)")
        try:
            _check_operating(args)
            with numerics_threads():
                code = handler(args)
        except AmbsealError as exc:
            print(f"ambseal: error: {with_source(exc, *_inputs(args))}", file=sys.stderr)
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
        print(_warning_line(w.message, w.category), file=sys.stderr)
    return code


def _warning_line(message: Warning | str, category: type[Warning]) -> str:
    """A warning as the command line shows it: ``ambseal: warning: <message>`` on one line
    (Python's form names our source file and line, of no use to a user of the command;
    the category is named unless it is the plain UserWarning, as ambseal's own are)."""
    text = " ".join(str(message).split())
    kind = "" if category is UserWarning else f" ({category.__name__})"
    return f"ambseal: warning: {text}{kind}"


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
