"""The ``ambseal`` command line: thin wiring of the stages, no numerics.

Commands
--------
``ambseal run [RIG] [--out DIR]``
    The main job on a rig (default: the embedded thesis test facility).
``ambseal modes RIG [--speed-rpm N] [--pressure-bar P] [--json] [--free | --no-amb]``
    Damped natural frequencies, damping ratios and unstable poles of the full model.

Any error on bad input prints one line on stderr and exits with status 2.
"""

from __future__ import annotations

import argparse
import json
import sys

from .errors import AmbsealError

__all__ = ["main"]


def _parser() -> argparse.ArgumentParser:
    p = argparse.ArgumentParser(
        prog="ambseal",
        description="Rotors on active magnetic bearings with destabilising seal forces.",
    )
    sub = p.add_subparsers(dest="command", required=True)

    run = sub.add_parser("run", help="the main job: model, PID loop, judgement, report")
    run.add_argument("rig", nargs="?", help="rig file (TOML); default: the thesis test rig")
    run.add_argument("--out", default="ambseal-out", help="output folder (default ./ambseal-out)")

    m = sub.add_parser("modes", help="natural frequencies, damping and unstable poles")
    m.add_argument("rig", help="rig file (TOML)")
    m.add_argument("--speed-rpm", type=float, default=None, help="spin speed (rpm)")
    m.add_argument("--pressure-bar", type=float, default=None, help="seal pressure drop (bar)")
    m.add_argument("--json", action="store_true", help="print JSON instead of a table")
    g = m.add_mutually_exclusive_group()
    g.add_argument("--free", action="store_true", help="bare rotor: shaft and disks only")
    g.add_argument("--no-amb", action="store_true", help="leave the AMBs out")
    return p


def _modes(args: argparse.Namespace) -> int:
    from .config import load_rig
    from .model.modes import modes
    from .model.rig import build_system

    cfg = load_rig(args.rig)
    sys_ = build_system(
        cfg,
        speed_rpm=args.speed_rpm,
        pressure_bar=args.pressure_bar,
        include_amb=not (args.free or args.no_amb),
        include_seals=not args.free,
        include_springs=not args.free,
    )
    res = modes(sys_)
    if args.json:
        print(json.dumps(res.to_dict(), indent=2))
        return 0
    print(f"{'mode':>4}  {'f_d [Hz]':>12}  {'zeta [-]':>10}")
    for i, (f, z) in enumerate(zip(res.natural_frequencies_hz, res.damping_ratios), 1):
        print(f"{i:>4}  {f:>12.3f}  {z:>10.4f}")
    if res.unstable_poles:
        print("unstable poles [rad/s]:")
        for re, im in res.unstable_poles:
            print(f"  {re:+.4g} {im:+.4g}j")
    else:
        print("no unstable poles")
    return 0


def _run(args: argparse.Namespace) -> int:
    from .pipeline import run

    result = run(args.rig, args.out)
    print(json.dumps({"out": str(result.out_dir), "metrics": str(result.metrics_path)}))
    return 0


def main(argv: list[str] | None = None) -> int:
    """Entry point of the ``ambseal`` console script; returns the exit status."""
    args = _parser().parse_args(argv)
    try:
        if args.command == "modes":
            return _modes(args)
        return _run(args)
    except AmbsealError as exc:
        print(f"ambseal: error: {exc}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        print("ambseal: interrupted", file=sys.stderr)
        return 130


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
