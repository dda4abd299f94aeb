"""``ambseal modes``: the rig's modes at one operating point, and every unstable pole.

Wiring only, like :mod:`ambseal.app.rotordynamics` (whose ``HANDLERS`` list it too): the numbers
come from :func:`ambseal.model.modes.modes` and :mod:`ambseal.analysis.campbell`, the figure
from :mod:`ambseal.report.modal_figures`.

A quick look at a model, so this module imports the model and its modal analysis only: a
controller (``--controller``) loads the designs and python-control, the mode shapes
(``--shapes``) matplotlib, each where it is asked for. Their 1.8 s of start-up would be a
third of ``modes`` on a 230-element rotor (benchmarks/README.md).
"""

from __future__ import annotations

import argparse
import json
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

from ambseal.analysis import OVERDAMPED_ZETA, closed_loop_modes, open_loop_modes
from ambseal.config import load_rig
from ambseal.errors import ConfigError
from ambseal.files import claim_file
from ambseal.model import bending_limit_hz, build_system
from ambseal.model.modes import modes
from ambseal.robust import unstable_poles

__all__ = ["modes_command", "mode_positions"]


def mode_positions(cfg) -> dict[str, list[float]]:
    """The axial positions (m) a mode-shape figure marks: AMBs, sensors, seals, disks."""
    return {"AMB": [a.position for a in cfg.amb], "sensor": [a.sensor_position for a in cfg.amb],
            "seal": [s.position for s in cfg.seal], "disk": [d.position for d in cfg.disk]}


def modes_command(args: argparse.Namespace) -> int:
    """Run ``ambseal modes``: its table (or ``--json``) on stdout.

    Parameters
    ----------
    args : argparse.Namespace
        The command line as :mod:`ambseal.cli` parsed it (``rig``, ``speed_rpm``,
        ``pressure_bar``, ``controller``, ``n_modes``, ``max_hz``, ``free``, ``no_amb``,
        ``shapes``, ``force``, ``json``).

    Returns
    -------
    int
        The exit status, 0.

    Raises
    ------
    AmbsealError
        A bad rig file or option (the CLI prints it and exits 2).
    """
    cfg = load_rig(args.rig)
    if args.shapes is not None:  # before any work
        from ambseal.report import figure_is_ours  # matplotlib: see the module docstring

        claim_file(args.shapes, force=args.force, ours=figure_is_ours)
    p = cfg.operating.pressure_bar if args.pressure_bar is None else args.pressure_bar
    rpm = cfg.operating.speed_rpm if args.speed_rpm is None else args.speed_rpm
    if args.controller is not None and (args.free or args.no_amb):
        raise ConfigError("modes: --controller closes the loop over the AMBs; it cannot be "
                          "combined with --free or --no-amb")
    sys_ = build_system(cfg, speed_rpm=rpm, pressure_bar=p,
                        include_amb=not (args.free or args.no_amb), include_seals=not args.free,
                        include_springs=not args.free)
    with ThreadPoolExecutor(max_workers=1) as pool:
        # every pole (a dense eig of the state matrix without --n-modes: seconds on a fine
        # mesh, LAPACK releases the GIL) beside the rest, which needs it last: the same
        # numbers, the wall time of the longer part
        every = pool.submit(modes, sys_, n_modes=args.n_modes)
        f_max = args.max_hz if args.max_hz is not None else (
            max(every.result().natural_frequencies_hz, default=0.0) if args.n_modes
            else bending_limit_hz(cfg))
        K = None
        if args.controller is not None:
            # python-control and the designs: see the module docstring
            from ambseal.app.controllers import controller_for

            K = controller_for(cfg, args.controller, p)
            if getattr(K, "as_runs_only", False):  # closed as it runs: aliased above Nyquist
                f_max = min(f_max, 0.5 * K.sample_rate_hz)
        # --n-modes: the N-th frequency comes from another eigen-solve than the modes listed,
        # so it may lie a rounding below theirs (the solvers agree to 1e-8, model.modes.modes)
        keep_hz = f_max * (1 + 1e-8) if args.n_modes and args.max_hz is None else f_max
        if K is None:  # shapes from the lowest eigenpairs; the verdict from every pole computed
            m = open_loop_modes(sys_, speed_hz=rpm / 60.0, pressure_bar=p, max_hz=keep_hz,
                                judged_poles=lambda: every.result().poles)
        else:
            m = closed_loop_modes(cfg, K, speed_hz=rpm / 60.0, pressure_bar=p, max_hz=keep_hz)
        res = every.result()
    unstable = res.unstable_poles if K is None else [
        (float(z.real), float(z.imag)) for z in unstable_poles(m.poles)]
    out = {"speed_hz": rpm / 60.0, "pressure_bar": p, "max_hz": f_max,
           "controller": args.controller or "none", **_mode_lists(m),
           "unstable_poles": [list(z) for z in unstable]}
    if args.shapes is not None:
        from ambseal.report import mode_shapes_figure  # matplotlib: see the module docstring

        out["shapes"] = str(mode_shapes_figure(Path(args.shapes), m, mode_positions(cfg)))
    if args.json:
        print(json.dumps(out, indent=2))
    else:
        _print_modes(out, rpm)
    return 0


def _mode_lists(m) -> dict:
    """The modes' frequencies, damping, log decrements and whirl, the overdamped ones
    apart: a pair damped at ζ ≥ 1/√2 has no resonance (|H(jω)| of its mode falls
    monotonically), no natural frequency to avoid, listed apart as `campbell` lists its
    crossings."""
    over = m.damping_ratio >= OVERDAMPED_ZETA
    resonant = ~over
    return {"natural_frequencies_hz": [float(x) for x in m.frequency_hz[resonant]],
            "damping_ratios": [float(x) for x in m.damping_ratio[resonant]],
            "log_decrements": [float(x) for x in m.log_decrement[resonant]],
            "whirl": [w for w, r in zip(m.whirl, resonant) if r],
            "overdamped": [{"frequency_hz": float(f), "damping_ratio": float(z), "whirl": w}
                           for f, z, w, o in zip(m.frequency_hz, m.damping_ratio, m.whirl,
                                                 over) if o]}


def _print_modes(out: dict, rpm: float) -> None:
    """``ambseal modes``' table (``out`` as its JSON) on stdout."""
    print(f"speed {rpm / 60.0:g} Hz ({rpm:g} rpm), pressure drop {out['pressure_bar']:g} bar, "
          f"controller {out['controller']}, modes up to {out['max_hz']:.4g} Hz")
    print(f"{'mode':>4}  {'f_d [Hz]':>12}  {'zeta [-]':>10}  {'log dec':>9}  whirl")
    for i, (f, z, d, w) in enumerate(zip(out["natural_frequencies_hz"], out["damping_ratios"],
                                         out["log_decrements"], out["whirl"]), 1):
        print(f"{i:>4}  {f:>12.3f}  {z:>10.4f}  {d:>9.4f}  {w}")
    if out["overdamped"]:
        print(f"overdamped (zeta >= {OVERDAMPED_ZETA:.3f}, no resonance): "
              + ", ".join(f"{o['frequency_hz']:.4g} Hz (zeta {o['damping_ratio']:.3f})"
                          for o in out["overdamped"]))
    if out["unstable_poles"]:
        print("unstable poles [rad/s]:")
        for re, im in out["unstable_poles"]:
            print(f"  {re:+.4g} {im:+.4g}j")
    else:
        print("no unstable poles")
    if "shapes" in out:
        print(f"mode shapes: {out['shapes']}")
