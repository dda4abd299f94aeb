"""The main job, stage by stage: rig → model → controller → judgement → report.

``ambseal run`` calls :func:`run`. It holds no numerics of its own: it wires the stages of
:mod:`ambseal.model`, :mod:`ambseal.control`, :mod:`ambseal.analysis` and
:mod:`ambseal.report`, and writes every file through a temporary name and a rename.
"""

from __future__ import annotations

import json
import math
import os
import tempfile
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from .config import RigConfig, default_rig_path, load_rig
from .errors import ConfigError

__all__ = ["RunResult", "run", "judge", "write_json"]

#: Frequency grid of the loop analysis (Hz): past the first bending mode of the test rig.
FREQ_HZ = (0.5, 2000.0, 1200)
#: Worst-case unbalance: balance grade (mm/s) and speed range (Hz), thesis P5 §4.4.1.
UNBALANCE_GRADE_MM_S = 2.5
UNBALANCE_RANGE_HZ = (1.0, 200.0)


@dataclass(frozen=True)
class RunResult:
    """Where the main job wrote its results, and the metrics it wrote."""

    out_dir: Path
    metrics_path: Path
    report_path: Path
    metrics: dict


def write_json(path: Path, data: dict) -> Path:
    """Write JSON through a temporary file in the same folder and an atomic rename."""
    fd, tmp = tempfile.mkstemp(dir=path.parent, prefix=f".{path.name}.", suffix=".tmp")
    try:
        with os.fdopen(fd, "w", encoding="utf-8") as fh:
            json.dump(data, fh, indent=2, allow_nan=False)
            fh.write("\n")
        os.chmod(tmp, 0o644)
        os.replace(tmp, path)
    except BaseException:
        if os.path.exists(tmp):
            os.unlink(tmp)
        raise
    return path


def _finite(x: float) -> float | None:
    return float(x) if math.isfinite(x) else None


def _force_position(cfg: RigConfig) -> float:
    """Where compliance and unbalance forces act: the first seal, else mid-span."""
    return cfg.seal[0].position if cfg.seal else cfg.length / 2


def _impulse_channels(names: tuple[str, ...]) -> tuple[str, str]:
    """The thesis's impulse axes A_ζ and B_η (P5 §5.1): first AMB's ζ, last AMB's η."""
    return names[0], names[-1]


def judge(cfg: RigConfig, controller, name: str, pressure_bar: float) -> tuple[dict, dict]:
    """Judge one controller on the full-order plant at one pressure drop.

    Returns the ``metrics.json`` case and the curves for the figures (frequencies in Hz).
    Controllers are judged on the full-order plant, flexible modes included, whatever
    model they were designed on.
    """
    from .analysis.iso import iso_assessment
    from .analysis.loops import closed_loop, compliance, loop_responses, sigma_max
    from .analysis.response import impulse_response_of
    from .analysis.unbalance import unbalance_from_compliance
    from .model.rig import build_plant
    from .model.rotor import assemble_rotor

    plant = build_plant(cfg, pressure_bar=pressure_bar, force_positions=(_force_position(cfg),))
    n_cur = 2 * len(cfg.amb)
    G = plant.select_inputs(plant.input_names[:n_cur]).to_statespace()
    Gf = plant.select_inputs(plant.input_names[n_cur:]).to_statespace()
    loop = closed_loop(G, controller, Gf)
    case = {"controller": name, "pressure_bar": pressure_bar, "stable": loop.stable,
            "max_real_pole": loop.max_real_pole}
    curves: dict = {}
    w = 2 * np.pi * np.logspace(math.log10(FREQ_HZ[0]), math.log10(FREQ_HZ[1]), FREQ_HZ[2])
    resp = loop_responses(G, controller, w)
    iso = iso_assessment(resp.peaks("So"), stable=loop.stable)
    curves["So"] = (w / (2 * np.pi), sigma_max(resp.So))
    case.update(
        sensitivity_peak=_finite(iso.sigma_max_peak),
        sensitivity_peak_per_axis={ax: (p.value if loop.stable else None)
                                   for ax, p in zip(G.output_labels, resp.peaks("So").diagonal)},
        iso_zone=iso.zone_sigma_max,
        iso_zone_per_axis=dict(iso.zones_per_axis),
    )
    if not loop.stable:
        case.update(compliance_peak_m_per_n=None, unbalance_peak_um=None,
                    impulse_peak_um=None, impulse_settling_s=None)
        return case, curves
    comp = compliance(G, controller, Gf, w)
    curves["compliance"] = (w / (2 * np.pi), comp.sigma_max_m_per_n)
    wu = 2 * np.pi * np.linspace(*UNBALANCE_RANGE_HZ, 400)
    unb = unbalance_from_compliance(compliance(G, controller, Gf, wu),
                                    mass_kg=assemble_rotor(cfg).mass,
                                    grade_mm_s=UNBALANCE_GRADE_MM_S)
    curves["unbalance"] = (unb.speed_hz, unb.response_um)
    imp = impulse_response_of(loop, channels=_impulse_channels(G.input_labels),
                              t_impulse_s=0.05, t_end_s=0.35, dt_s=5e-5)
    curves["impulse"] = imp
    case.update(
        compliance_peak_m_per_n=comp.peak.value,
        unbalance_peak_um=unb.peak_um,
        impulse_peak_um=imp.peak_displacement_um,
        impulse_settling_s=_finite(imp.settling_time_s),
    )
    return case, curves


def _controllers(cfg: RigConfig, channels: tuple[str, ...]) -> list[tuple[str, object]]:
    from .control.pid import pid_controller

    if cfg.controller.pid is None:
        raise ConfigError("controller.pid: the main job needs the reference PID ([controller.pid])")
    p = cfg.controller.pid
    return [("pid", pid_controller(p.kp, p.ti, p.td, p.eps, channels))]


def run(rig: str | Path | None = None, out_dir: str | Path = "ambseal-out",
        progress: bool = True) -> RunResult:
    """The main job: build and reduce the model, close the loops, judge, report.

    Parameters
    ----------
    rig : path, optional
        Rig file; the embedded thesis test facility when omitted.
    out_dir : path
        Output folder, created if needed.
    progress : bool
        Show a progress display on stderr.

    Returns
    -------
    RunResult

    Raises
    ------
    ConfigError
        A bad rig file, a rig without AMBs or without ``[controller.pid]``.
    """
    from rich.console import Console
    from rich.progress import Progress

    from .model.rig import build_plant

    rig_path = Path(rig) if rig is not None else default_rig_path()
    cfg = load_rig(rig_path)
    if not cfg.amb:
        raise ConfigError(f"{rig_path}: amb: the main job needs at least one [[amb]]")
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    nominal = cfg.operating.pressure_bar
    pressures = [0.0, nominal, 2 * nominal] if nominal > 0 else [0.0]

    console = Console(stderr=True)
    with Progress(console=console, disable=not progress, transient=True) as bar:
        total = 2 + 3 * len(pressures) + 1
        task = bar.add_task("ambseal run", total=total)
        bar.update(task, description="model: full order and modal reduction")
        full = build_plant(cfg)
        reduced = build_plant(cfg, reduced=True)
        unstable = np.linalg.eigvals(full.A)
        unstable = unstable[unstable.real > 1e-9 * np.abs(unstable).max()]
        unstable = unstable[np.argsort(-unstable.real)]
        bar.advance(task)
        controllers = _controllers(cfg, full.input_names)
        bar.advance(task)
        cases, curves = [], []
        for cname, K in controllers:
            for p in pressures:
                bar.update(task, description=f"judging {cname} at {p:g} bar")
                case, c = judge(cfg, K, cname, p)
                cases.append(case)
                curves.append((f"{cname}, {p:g} bar", c))
                bar.advance(task, 3)
        metrics = {
            "rig": str(rig_path),
            "rig_name": cfg.rotor.name,
            "open_loop": {
                "unstable_poles": [[float(z.real), float(z.imag)] for z in unstable],
                "n_states_full": full.n_states,
                "n_states_reduced": reduced.n_states,
            },
            "unbalance": {"grade_mm_s": UNBALANCE_GRADE_MM_S, "range_hz": list(UNBALANCE_RANGE_HZ)},
            "cases": cases,
        }
        bar.update(task, description="report")
        metrics_path = write_json(out / "metrics.json", metrics)
        report_path = _report(out, cfg, rig_path, metrics, curves)
        bar.advance(task)
    return RunResult(out, metrics_path, report_path, metrics)


def _report(out: Path, cfg: RigConfig, rig_path: Path, metrics: dict, curves: list) -> Path:
    from .report import figures
    from .report.html import write_report

    figs = []
    so = [(label, c["So"][0], c["So"][1]) for label, c in curves if "So" in c]
    figs.append(("Output sensitivity σ̄(S_o) with the ISO 14839-3 zones",
                 figures.sensitivity_figure(out / "sensitivity.png", so)))
    comp = [(label, c["compliance"][0], c["compliance"][1]) for label, c in curves
            if "compliance" in c]
    if comp:
        figs.append(("Compliance σ̄(S_o G_f) at the seal",
                     figures.compliance_figure(out / "compliance.png", comp)))
    unb = [(label, c["unbalance"][0], c["unbalance"][1]) for label, c in curves
           if "unbalance" in c]
    if unb:
        figs.append((f"Worst-case unbalance response, G{UNBALANCE_GRADE_MM_S:g}",
                     figures.unbalance_figure(out / "unbalance.png", unb)))
    imp = [(label, c["impulse"]) for label, c in curves if "impulse" in c]
    if imp:
        first = imp[0][1]
        figs.append((
            f"Response to 0.05 A for 10 ms on {' and '.join(first.channels)}",
            figures.impulse_figure(
                out / "impulse.png",
                [(label, r.time_ms, r.displacement_um) for label, r in imp],
                first.output_names,
                currents=[(label, r.time_ms, r.current_a) for label, r in imp],
            ),
        ))
    unstable = metrics["open_loop"]["unstable_poles"]
    sections = [{
        "title": "Open loop",
        "text": (f"{len(unstable)} unstable poles (rad/s): "
                 + ", ".join(f"{re:.1f}{im:+.1f}j" for re, im in unstable)
                 + f"; {metrics['open_loop']['n_states_full']} states in full order, "
                 f"{metrics['open_loop']['n_states_reduced']} reduced."),
    }]
    return write_report(out / "report.html", title=f"ambseal — {cfg.rotor.name}",
                        metrics=metrics["cases"], figures=figs, sections=sections,
                        meta=f"rig: {rig_path}")
