"""The main job, stage by stage: rig → model → controller → judgement → report.

``ambseal run`` calls :func:`run`. It holds no numerics of its own: it wires the stages of
:mod:`ambseal.model`, :mod:`ambseal.control`, :mod:`ambseal.analysis` and
:mod:`ambseal.report`, and writes every file through a temporary name and a rename.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from .config import RigConfig, default_rig_path, load_rig
from .errors import ConfigError
from .files import write_json, write_text

__all__ = ["RunResult", "run", "judge", "identify_files", "design_files", "default_truth_path"]

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


def default_truth_path() -> Path:
    """The virtual facility's truth for the embedded test rig (``data/testrig_truth.toml``)."""
    return Path(__file__).parent / "data" / "testrig_truth.toml"


def identify_files(rig: str | Path, data: list[str], names: list[str], out_dir: str | Path, *,
                   current_weight: float = 0.0, refine: bool = True) -> dict:
    """``ambseal identify``: fit ``names`` to recorded files; write the fit, its figures and
    the identified rig to ``out_dir``. Returns a JSON-safe summary.

    Raises
    ------
    ConfigError, DataError, IdentificationError
        A bad rig, a bad or mismatched record, or a fit that cannot start.
    """
    from .config import dump_rig, rig_with_values
    from .errors import DataError
    from .identify.data import load_measurement
    from .identify.stages import identify
    from .report.identify_figures import correlation_figure, fit_timeseries_figure

    cfg = load_rig(rig)
    axes = tuple(f"{m.name}_{x}" for m in cfg.amb for x in ("zeta", "eta"))
    records = []
    for path in data:
        meas = load_measurement(path, axes=axes, min_samples=max(100, 10 * len(names)))
        other = meas.metadata.get("rig")
        if other is not None and other != cfg.rotor.name:
            raise DataError(f"{path}: metadata.rig: recorded on {other!r}, but the rig is "
                            f"{cfg.rotor.name!r}")
        records.append(meas)
    res = identify(cfg, records, names, current_weight=current_weight, refine=refine)
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    write_json(out / "fit.json", res.to_dict())
    fit_timeseries_figure(out / "fit_timeseries.png", res.time_s, res.y_meas, res.y_sim,
                          res.axes, nrmse_pct=[res.nrmse_fit_pct[a] for a in res.axes])
    correlation_figure(out / "correlation.png", res.correlation, res.names)
    pressures = sorted({float(m.metadata.get("pressure_drop_pa", 0.0)) / 1e5 for m in records})
    identified = rig_with_values(cfg, dict(zip(res.names, res.estimate)))
    header = (f"Identified by ambseal from {', '.join(str(d) for d in data)}\n"
              f"parameters: {', '.join(res.names)}; converged: {res.converged}\n"
              f"seal coefficients, if fitted, hold at the recorded pressure drop(s) "
              f"{pressures} bar")
    write_text(out / "identified.toml", dump_rig(identified, header))
    return {"out": str(out), "converged": res.converged, "message": res.message,
            "parameters": {
                n: {"estimate": float(v), "ci95": [_finite(lo), _finite(hi)]}
                for n, v, lo, hi in zip(res.names, res.estimate, res.ci95_low, res.ci95_high)},
            "nrmse_fit_pct": {k: _finite(v) for k, v in res.nrmse_fit_pct.items()}}


def _finite(x: float) -> float | None:
    return float(x) if math.isfinite(x) else None


def _force_position(cfg: RigConfig) -> float:
    """Where compliance and unbalance forces act: the first seal, else mid-span."""
    return cfg.seal[0].position if cfg.seal else cfg.length / 2


def _impulse_channels(names: tuple[str, ...]) -> tuple[str, str]:
    """The thesis's impulse axes A_ζ and B_η (P5 §5.1): first AMB's ζ, last AMB's η."""
    return names[0], names[-1]


def judge(cfg: RigConfig, controller, name: str, pressure_bar: float,
          speed_rpm: float | None = None) -> tuple[dict, dict]:
    """Judge one controller on the full-order plant at one pressure drop (and speed).

    Returns the ``metrics.json`` case and the curves for the figures (frequencies in Hz).
    Controllers are judged on the full-order plant, flexible modes included, whatever
    model they were designed on.
    """
    from .analysis.iso import iso_assessment
    from .analysis.loops import (closed_loop, compliance, loop_responses, resolved_grid,
                                 sigma_max)
    from .analysis.response import impulse_response_of
    from .analysis.unbalance import unbalance_from_compliance
    from .model.rig import build_plant
    from .model.rotor import assemble_rotor

    plant = build_plant(cfg, pressure_bar=pressure_bar, speed_rpm=speed_rpm,
                        force_positions=(_force_position(cfg),))
    n_cur = 2 * len(cfg.amb)
    G = plant.select_inputs(plant.input_names[:n_cur]).to_statespace()
    Gf = plant.select_inputs(plant.input_names[n_cur:]).to_statespace()
    loop = closed_loop(G, controller, Gf)
    speed = cfg.operating.speed_rpm if speed_rpm is None else speed_rpm
    case = {"controller": name, "pressure_bar": pressure_bar, "speed_hz": speed / 60.0,
            "stable": loop.stable, "max_real_pole": loop.max_real_pole}
    curves: dict = {}
    w = 2 * np.pi * np.logspace(math.log10(FREQ_HZ[0]), math.log10(FREQ_HZ[1]), FREQ_HZ[2])
    w = resolved_grid(w, loop.poles)  # the 0.5 %-damped bending mode must not slip through
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
    wu = resolved_grid(2 * np.pi * np.linspace(*UNBALANCE_RANGE_HZ, 400), loop.poles)
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


def design_files(rig: str | Path, method: str, out_dir: str | Path, *,
                 pressure_bar: float | None = None) -> dict:
    """``ambseal design``: design one controller and write it with its summary.

    Files: ``controller_<method>.json``, ``.npz`` and ``.mat`` (continuous, Tustin and ZOH
    at ``[controller] sample_rate_hz``, with the channel names) and ``design_<method>.json``
    (summary, weights, D–K history). ``lpv`` (a rig with ``[operating] speed_range_hz``):
    the frozen controllers on the design grid, ``controller_lpv_<f>Hz.npz``.
    """
    from .control.design import design

    cfg = load_rig(rig)
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    fs = cfg.controller.sample_rate_hz
    if method == "lpv":
        from .control.lpv_design import design_lpv

        if cfg.operating.speed_range_hz is None:
            raise ConfigError(f"{rig}: operating.speed_range_hz: an LPV design needs the "
                              "speed range it is scheduled over, e.g. [20.0, 300.0]")
        lpv = design_lpv(cfg, speeds_hz=cfg.operating.speed_range_hz)
        j = _Judged("lpv", lpv.controller_at, lpv.to_dict(), lpv)
        files = _export_judged(j, out, fs, [float(f) for f in lpv.speeds_hz])
        return {**lpv.to_dict(), "files": [str(f) for f in files]}
    res = design(cfg, method, pressure_bar=pressure_bar)
    files = _export(res, out, fs)
    return {**res.summary(), "files": [str(f) for f in files]}


def _export(res, out: Path, fs_hz: float) -> list[Path]:
    """The controller as .json/.npz/.mat (continuous, Tustin, ZOH) and its design summary."""
    from .control.export import export_controller

    files = [export_controller(res.K, out / f"controller_{res.method}{ext}", fs_hz=fs_hz)
             for ext in (".json", ".npz", ".mat")]
    files.append(write_json(out / f"design_{res.method}.json", res.to_dict()))
    return files


def _export_judged(j: _Judged, out: Path, fs_hz: float, speeds_hz) -> list[Path]:
    """Export a main-job controller (continuous, Tustin, ZOH; .json/.npz/.mat) and its
    design (``design_<method>.json``); a scheduled one as its frozen controllers at the
    judged speeds (``controller_lpv_<f>Hz.npz``), the table a real-time target
    interpolates."""
    from .control.export import export_controller

    if j.method == "lpv":
        files = [export_controller(j.at(f), out / f"controller_lpv_{f:g}Hz.npz", fs_hz=fs_hz)
                 for f in speeds_hz]
    else:
        files = [export_controller(j.at(None), out / f"controller_{j.method}{ext}",
                                   fs_hz=fs_hz) for ext in (".json", ".npz", ".mat")]
    files.append(write_json(out / f"design_{j.method}.json", j.result.to_dict()))
    return files


def _speed_scheduled(cfg: RigConfig) -> bool:
    """Whether the rig's seals change with speed over a stated speed range (P3 §4): its
    controllers are then judged at frozen speeds rather than at pressure drops."""
    return cfg.operating.speed_range_hz is not None and any(
        s.frequency_dependent for s in cfg.seal)


@dataclass(frozen=True)
class _Judged:
    """A designed controller as the main job judges and exports it: ``at(speed_hz)`` gives
    the (frozen) physical controller, ``summary`` its design summary."""

    method: str
    at: object
    summary: dict
    result: object


def _controllers(cfg: RigConfig) -> list[_Judged]:
    """The designed controllers of the main job.

    Pressure-driven seals (the test rig): the reference PID, H∞ and μ (P5 §4). Speed-driven
    seals over a speed range (the turboexpander, P3 §4): the PID if the rig has one, an
    H∞ controller designed at the operating speed (the LTI comparison of P3 Fig. 11) and the
    LPV controller scheduled on speed.
    """
    from .control.design import design

    if _speed_scheduled(cfg):
        from .control.lpv_design import design_frozen, design_lpv

        out = [_lti(design(cfg, "pid"))] if cfg.controller.pid else []
        fz = design_frozen(cfg, cfg.operating.speed_rpm / 60.0)
        out.append(_Judged("hinf", lambda _f, K=fz.K: K, fz.to_dict(), fz))
        lpv = design_lpv(cfg, speeds_hz=cfg.operating.speed_range_hz)
        out.append(_Judged("lpv", lpv.controller_at, lpv.to_dict(), lpv))
        return out
    if cfg.controller.pid is None:
        raise ConfigError("controller.pid: the main job needs the reference PID "
                          "([controller.pid])")
    return [_lti(design(cfg, m)) for m in ("pid", "hinf", "mu")]


def _lti(res) -> _Judged:
    return _Judged(res.method, lambda _f, K=res.K: K, res.summary(), res)


def _operating_points(cfg: RigConfig) -> list[tuple[float, float, str]]:
    """(pressure_bar, speed_rpm, label) at which every controller is judged: 0, nominal
    and 2× nominal pressure drop, or the ends and the middle of the speed range."""
    p, rpm = cfg.operating.pressure_bar, cfg.operating.speed_rpm
    if _speed_scheduled(cfg):
        lo, hi = cfg.operating.speed_range_hz
        speeds = sorted({lo, rpm / 60.0, hi})
        return [(p, f * 60.0, f"{f:g} Hz") for f in speeds]
    pressures = [0.0, p, 2 * p] if p > 0 else [0.0]
    return [(q, rpm, f"{q:g} bar") for q in pressures]


def run(rig: str | Path | None = None, out_dir: str | Path = "ambseal-out",
        progress: bool = True, truth: str | Path | None = None,
        identification: bool = True) -> RunResult:
    """The main job: build and reduce the model, close the loops, judge, identify, report.

    Parameters
    ----------
    rig : path, optional
        Rig file; the embedded thesis test facility when omitted.
    out_dir : path
        Output folder, created if needed.
    progress : bool
        Show a progress display on stderr.
    truth : path, optional
        Truth file of the virtual test facility; with it (and by default for the embedded
        rig) the run also acquires records from the virtual facility and identifies the rig
        by the thesis's procedure (:mod:`ambseal.identify.procedure`).
    identification : bool
        Set False to skip the identification stage.

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
    if truth is None and rig is None:
        truth = default_truth_path()
    if not cfg.amb:
        raise ConfigError(f"{rig_path}: amb: the main job needs at least one [[amb]]")
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    points = _operating_points(cfg)

    console = Console(stderr=True)
    with Progress(console=console, disable=not progress, transient=True) as bar:
        total = 2 + 3 * 3 * len(points) + 1
        task = bar.add_task("ambseal run", total=total)
        bar.update(task, description="model: full order and modal reduction")
        full = build_plant(cfg)
        reduced = build_plant(cfg, reduced=True)
        unstable = np.linalg.eigvals(full.A)
        unstable = unstable[unstable.real > 1e-9 * np.abs(unstable).max()]
        unstable = unstable[np.argsort(-unstable.real)]
        bar.advance(task)
        bar.update(task, description="designing the controllers")
        designs = _controllers(cfg)
        (out / "controllers").mkdir(exist_ok=True)
        for j in designs:
            _export_judged(j, out / "controllers", cfg.controller.sample_rate_hz,
                           [rpm / 60.0 for _, rpm, _ in points])
        bar.advance(task)
        cases, curves = [], []
        for j in designs:
            cname = j.method
            for p, rpm, label in points:
                bar.update(task, description=f"judging {cname} at {label}")
                case, c = judge(cfg, j.at(rpm / 60.0), cname, p, rpm)
                cases.append(case)
                curves.append((f"{cname}, {label}", c))
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
            "controllers": {j.method: j.summary for j in designs},
            "cases": cases,
        }
        extra: tuple[list, list] = ([], [])
        if identification and truth is not None:
            from .config import load_truth

            truth_cfg = load_truth(truth)
            bar.update(task, total=total + 8)

            def say(msg: str) -> None:
                bar.update(task, description=msg)
                bar.advance(task)

            metrics["identification"], extra = _identification(cfg, truth_cfg, out, say)
        if _speed_scheduled(cfg):
            bar.update(task, description="spin-up 20 → 300 Hz and frozen sensitivities")
            metrics["spinup"], figs = _spinup(cfg, designs, out)
            extra[0].extend(figs)
        bar.update(task, description="report")
        metrics_path = write_json(out / "metrics.json", metrics)
        extra[0].append(_gains_figure(out, designs, cfg.operating.speed_rpm / 60.0))
        report_path = _report(out, cfg, rig_path, metrics, curves, extra)
        bar.advance(task)
    return RunResult(out, metrics_path, report_path, metrics)


def _gains_figure(out: Path, designs: list, speed_hz: float) -> tuple[str, Path]:
    """Direct and cross gains of the designed controllers (P5 Fig. 10), at the operating
    speed for scheduled ones."""
    from .lti.freqresp import freqresp
    from .report.figures import controller_gains_figure

    f = np.logspace(0, math.log10(2000.0), 300)
    Ks = [(j.method, j.at(speed_hz)) for j in designs]
    rows = [(m, f, freqresp(K, 2 * np.pi * f)) for m, K in Ks]
    names = [n.removeprefix("y_") for n in Ks[0][1].input_labels]
    return ("Direct and cross gains of the controllers (P5 Fig. 10)",
            controller_gains_figure(out / "controller_gains.png", rows, names))


def _spinup(cfg: RigConfig, designs: list, out: Path) -> tuple[dict, list]:
    """P3 §4: spin-up 20 → 300 Hz with alternating force and output steps on A_x, and
    σ̄(S_o) at frozen speeds, for the scheduled controller and the LTI ones."""
    from .analysis.spinup import frozen_sensitivity, spinup
    from .control.lpv_plant import lpv_plant
    from .report.lpv_figures import frozen_sensitivity_figure, spinup_figure

    lo, hi = cfg.operating.speed_range_hz
    grid = np.linspace(lo, hi, 29)
    L = lpv_plant(cfg, grid, states=12, force_positions=(cfg.amb[0].position,))
    sims, sens, cache = [], [], {}
    speeds = np.linspace(lo, hi, 8)
    for j in designs:
        ctrl = j.result if j.method == "lpv" else j.at(None)
        sims.append(spinup(L, ctrl, name=j.method, speeds_hz=(lo, hi)))
        sens.append(frozen_sensitivity(cfg, ctrl, speeds, name=j.method, plants=cache))
    figs = [("Spin-up 20 → 300 Hz in 1 s with 100 N force and 2 µm output steps on A_x "
             "(P3 Fig. 11)", spinup_figure(out / "spinup.png", sims)),
            ("σ̄(S_o) at frozen speeds with the ISO 14839-3 line (P3 Fig. 12)",
             frozen_sensitivity_figure(out / "frozen_sensitivity.png", sens))]
    return {j.method: {**s.to_dict(), "frozen_sensitivity": fs.to_dict()}
            for j, s, fs in zip(designs, sims, sens)}, figs


def _identification(cfg: RigConfig, truth, out: Path, say) -> tuple[dict, tuple[list, list]]:
    """The identification stage: the thesis's procedure on the virtual facility, its files
    and figures, and a FRF check of the identified model (P4 Figs. 9–10)."""
    from .config import Affine, dump_rig
    from .identify.frf import closed_loop_frf, model_frf, plant_frf
    from .model.rig import build_plant
    from .identify.procedure import thesis_procedure
    from .identify.signals import chirp
    from .identify.stages import acquire, build_models
    from .report.identify_figures import (correlation_figure, fit_timeseries_figure,
                                          frf_figure, seal_frequency_figure,
                                          seal_pressure_figure)

    res = thesis_procedure(cfg, truth, progress=say)
    write_json(out / "identification.json", res.to_dict())
    write_text(out / "identified_rig.toml",
               dump_rig(res.identified, "Identified by `ambseal run` from the virtual test "
                        "facility (thesis P2, P4, P5 procedure)"))
    figs, sections = [], []
    a = res.amb
    figs.append(("Identification (a): measured and simulated displacements, PRBS at 0 bar",
                 fit_timeseries_figure(out / "ident_fit.png", a.time_s, a.y_meas, a.y_sim,
                                       a.axes, nrmse_pct=[a.nrmse_fit_pct[x] for x in a.axes])))
    figs.append(("Correlation of the AMB estimates (P4 Table 2)",
                 correlation_figure(out / "ident_correlation.png", a.correlation, a.names)))
    if res.seal_vs_frequency:
        curves = []
        for p, rows in res.seal_vs_frequency.items():
            curves.append((f"{p:g} bar", [f for f, _ in rows],
                           np.array([r.estimate for _, r in rows]),
                           np.array([r.std_error for _, r in rows])))
        figs.append(("Seal coefficients by stepped sine (P4 Fig. 12)",
                     seal_frequency_figure(out / "ident_seal_frequency.png", curves)))
        ps = [p for p, _ in res.seal_vs_pressure]
        est = np.array([r.estimate for _, r in res.seal_vs_pressure])
        se = np.array([r.std_error for _, r in res.seal_vs_pressure])
        coefs = list(res.regression)
        seal = cfg.seal[0].name

        def true_line(c):
            v = truth.parameters.get(f"{seal}.{c}")
            if v is None:
                return None
            return (lambda p: v.at_zero + v.per_bar * p) if isinstance(v, Affine) else (
                lambda p: float(v))

        figs.append(("Seal coefficients by impulse against pressure drop (P5 Fig. 7)",
                     seal_pressure_figure(out / "ident_seal_pressure.png", ps, est, se,
                                          [res.regression[c] for c in coefs], coefs,
                                          truth=[true_line(c) for c in coefs],
                                          nominal_bar=cfg.operating.pressure_bar)))
    # frequency-domain check of the identified model with a chirp at 0 bar
    say("identification: chirp FRF check of the identified model")
    axes = a.axes
    fs = cfg.controller.sample_rate_hz
    ex = chirp(f0_hz=1.0, f1_hz=150.0, duration_s=4.0, amplitude_a=0.05, sample_rate_hz=fs,
               axes=axes, excited={axes[0]: 1.0, axes[-2]: 1.0})
    rec = acquire(cfg, truth, ex, pressure_bar=0.0, seed=99)
    measured = closed_loop_frf(rec, nperseg=8192, inputs=[axes[0]])
    model = build_models(res.identified, [rec])[0].statespace({}, axes)
    fgrid = measured.band(2.0, 140.0).frequency_hz
    mf = model_frf(model[:, [0]] + model[:, [len(axes) - 2]], fgrid,
                   input_names=measured.input_names, output_names=measured.output_names)
    figs.append(("Closed-loop FRF from the ζ excitation on both bearings: chirp 1–150 Hz "
                 "against the identified model (P4 Fig. 9)",
                 frf_figure(out / "ident_frf.png", measured.band(2.0, 140.0), mf)))

    # the unstable plant itself: T_ye T_ie⁻¹ from the PRBS record of stage (a), whose four
    # axes carry independent sequences (MIMO H1), against the identified plant from coil
    # current to displacement (eddy lag, Ki, rotor; no amplifier)
    rec_a = res.records["a"]
    T_ye = closed_loop_frf(rec_a, nperseg=2048, method="mimo")
    T_ie = closed_loop_frf(rec_a, nperseg=2048, method="mimo", response="current")
    G = plant_frf(T_ye, T_ie).band(2.0, 200.0)
    bare = res.identified.model_copy(
        update={"actuator": res.identified.actuator.model_copy(update={"model": "none"})})
    Gm = model_frf(build_plant(bare, reduced=True, pressure_bar=0.0).to_statespace(),
                   G.frequency_hz, input_names=G.input_names, output_names=G.output_names)
    pairs = [(G.output_names[0], G.input_names[0]), (G.output_names[-1], G.input_names[-1]),
             (G.output_names[0], G.input_names[-2])]
    figs.append(("The unstable plant from closed-loop data: T_ye·T_ie⁻¹ (PRBS, stage a) "
                 "against the identified model",
                 frf_figure(out / "ident_plant_frf.png", G, Gm, pairs=pairs)))

    rows = []
    summary = {}
    for r in [a] + ([res.coupling] if res.coupling else []):
        for i, n in enumerate(r.names):
            t = res.truth.get(n)
            err = None if not isinstance(t, float) or t == 0 else 100 * (r.estimate[i] / t - 1)
            summary[n] = {"estimate": float(r.estimate[i]), "truth": t,
                          "ci95": [_finite(r.ci95_low[i]), _finite(r.ci95_high[i])],
                          "error_pct": err}
            rows.append(f"<tr><td>{n}</td><td>{r.estimate[i]:.5g}</td><td>{t if t is None else f'{t:.5g}'}"
                        f"</td><td>[{r.ci95_low[i]:.5g}, {r.ci95_high[i]:.5g}]</td>"
                        f"<td>{'' if err is None else f'{err:+.2f} %'}</td></tr>")
    for c, reg in res.regression.items():
        t = res.truth.get(f"{cfg.seal[0].name}.{c}")
        tl = f"{t['at_zero']:.4g} + {t['per_bar']:.4g}·p" if isinstance(t, dict) else str(t)
        summary[f"{cfg.seal[0].name}.{c}"] = {**reg.to_dict(), "truth": t}
        rows.append(f"<tr><td>{cfg.seal[0].name}.{c} (vs p, bar)</td><td>{reg.intercept:.4g} + "
                    f"{reg.slope:.4g}·p</td><td>{tl}</td><td>slope ± {1.96 * reg.slope_se:.3g}"
                    f"</td><td></td></tr>")
    fits = ", ".join(f"{k} {v:.1f} %" for k, v in a.nrmse_fit_pct.items())
    sections.append({
        "title": "Identification on the virtual test facility",
        "html": ("<p>Records from the virtual facility (nonlinear AMB force law, full FE rotor, "
                 "noise, ADC), fitted by the output-error method of P2/P4. NRMSE fit of stage "
                 f"(a): {fits}. Identified rig: <code>identified_rig.toml</code>.</p>"
                 "<table><tr><th>parameter</th><th>identified</th><th>truth</th>"
                 "<th>95 % interval</th><th>error</th></tr>" + "".join(rows) + "</table>"),
    })
    return {"parameters": summary, "converged": bool(a.converged),
            "nrmse_fit_pct": {k: _finite(v) for k, v in a.nrmse_fit_pct.items()}}, (figs, sections)


def _report(out: Path, cfg: RigConfig, rig_path: Path, metrics: dict, curves: list,
            extra: tuple[list, list] = ([], [])) -> Path:
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
    figs += extra[0]
    sections += extra[1]
    return write_report(out / "report.html", title=f"ambseal — {cfg.rotor.name}",
                        metrics=metrics["cases"], figures=figs, sections=sections,
                        meta=f"rig: {rig_path}")
