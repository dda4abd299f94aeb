"""The main job's report: its figures, the identification section and ``report.html``.

Everything here draws or formats results computed elsewhere (:mod:`ambseal.analysis.judge`,
:mod:`ambseal.identify.procedure`, :mod:`ambseal.identify.checks`); figures follow the
thesis's (P5 Figs. 10–15, P4 Figs. 9–12, P5 Fig. 7, P3 Figs. 11–12).
"""

from __future__ import annotations

import html
import math
from pathlib import Path

import numpy as np

__all__ = ["gains_figure", "spinup_figures", "identification_report", "write_run_report"]


def gains_figure(out: Path, controllers: list[tuple[str, object]]) -> tuple[str, Path]:
    """Direct and cross gains of physical controllers ``[(name, StateSpace)]`` (P5 Fig. 10),
    1 Hz – 2 kHz."""
    from ..lti.freqresp import freqresp
    from .figures import controller_gains_figure

    f = np.logspace(0, math.log10(2000.0), 300)
    rows = [(m, f, freqresp(K, 2 * np.pi * f)) for m, K in controllers]
    names = [n.removeprefix("y_") for n in controllers[0][1].input_labels]
    return ("Direct and cross gains of the controllers (P5 Fig. 10)",
            controller_gains_figure(out / "controller_gains.png", rows, names))


def spinup_figures(out: Path, sims: list, sens: list, speeds_hz: tuple[float, float]
                   ) -> list[tuple[str, Path]]:
    """The spin-up (P3 Fig. 11) and σ̄(S_o) at frozen speeds (P3 Fig. 12)."""
    from .lpv_figures import frozen_sensitivity_figure, spinup_figure

    lo, hi = speeds_hz
    return [(f"Spin-up {lo:g} → {hi:g} Hz in 1 s with 100 N force and 2 µm output steps on "
             "A_x (P3 Fig. 11)", spinup_figure(out / "spinup.png", sims)),
            ("σ̄(S_o) at frozen speeds with the ISO 14839-3 line (P3 Fig. 12)",
             frozen_sensitivity_figure(out / "frozen_sensitivity.png", sens))]


def _fmt(t) -> str:
    return "" if t is None else f"{t:.5g}"


def identification_report(out: Path, res, errors: dict, checks, truth, seal_name: str | None,
                          nominal_bar: float) -> tuple[list, list]:
    """Figures and the HTML section of the identification stage.

    Parameters
    ----------
    out : Path
        Folder of the figures.
    res : ProcedureResult
    errors : dict
        :func:`ambseal.identify.checks.truth_errors` of ``res``.
    checks : FrfChecks
    truth : TruthSection
    seal_name : str or None
    nominal_bar : float
        The rig's nominal pressure drop (bar), marked in the pressure figure.

    Returns
    -------
    (figures, sections)
        ``[(caption, png)]`` and ``[{"title", "html"}]`` for :func:`write_run_report`.
    """
    from ..identify.checks import true_line
    from .identify_figures import (correlation_figure, fit_timeseries_figure, frf_figure,
                                   residual_figure, seal_frequency_figure, seal_pressure_figure)

    a = res.amb
    figs = [("Identification (a): measured and simulated displacements, PRBS at 0 bar",
             fit_timeseries_figure(out / "ident_fit.png", a.time_s, a.y_meas, a.y_sim, a.axes,
                                   nrmse_pct=[a.nrmse_fit_pct[x] for x in a.axes])),
            ("Correlation of the AMB estimates (P4 Table 2)",
             correlation_figure(out / "ident_correlation.png", a.correlation, a.names))]
    if a.residuals is not None:
        figs.append(("Residuals of the joint AMB fit, first record: whiteness (informative) and "
                     "independence of the excitation (Ljung §16.6)",
                     residual_figure(out / "ident_residuals.png", a.residuals)))
    if res.seal_vs_frequency:
        curves = [(f"{p:g} bar", [f for f, _ in rows], np.array([r.estimate for _, r in rows]),
                   np.array([r.std_error for _, r in rows]))
                  for p, rows in res.seal_vs_frequency.items()]
        figs.append(("Seal coefficients by stepped sine (P4 Fig. 12)",
                     seal_frequency_figure(out / "ident_seal_frequency.png", curves)))
        coefs = list(res.regression)
        figs.append(("Seal coefficients by impulse against pressure drop (P5 Fig. 7)",
                     seal_pressure_figure(
                         out / "ident_seal_pressure.png", [p for p, _ in res.seal_vs_pressure],
                         np.array([r.estimate for _, r in res.seal_vs_pressure]),
                         np.array([r.std_error for _, r in res.seal_vs_pressure]),
                         [res.regression[c] for c in coefs], coefs,
                         truth=[true_line(truth, f"{seal_name}.{c}") for c in coefs],
                         nominal_bar=nominal_bar)))
    figs.append(("Closed-loop FRF from the ζ excitation on both bearings: chirp 1–150 Hz "
                 "against the identified model (P4 Fig. 9)",
                 frf_figure(out / "ident_frf.png", checks.closed_loop, checks.closed_loop_model)))
    figs.append(("The unstable plant from closed-loop data: T_ye·T_ie⁻¹ (PRBS, stage a) "
                 "against the identified model",
                 frf_figure(out / "ident_plant_frf.png", checks.plant, checks.plant_model,
                            pairs=list(checks.plant_pairs))))
    rows = []
    for n, e in errors.items():
        if "estimate" in e:
            lo, hi = (math.nan if v is None else v for v in e["ci95"])
            err = "" if e["error_pct"] is None else f"{e['error_pct']:+.2f} %"
            rows.append(f"<tr><td>{html.escape(n)}</td><td>{e['estimate']:.5g}</td>"
                        f"<td>{_fmt(e['truth'])}</td><td>[{lo:.5g}, {hi:.5g}]</td>"
                        f"<td>{err}</td></tr>")
        else:
            t = e["truth"]
            tl = f"{t['at_zero']:.4g} + {t['per_bar']:.4g}·p" if isinstance(t, dict) else str(t)
            rows.append(f"<tr><td>{html.escape(n)} (vs p, bar)</td><td>{e['intercept']:.4g} + "
                        f"{e['slope']:.4g}·p</td><td>{tl}</td><td>slope ± "
                        f"{1.96 * e['slope_se']:.3g}</td><td></td></tr>")
    fits = ", ".join(f"{k} {v:.1f} %" for k, v in a.nrmse_fit_pct.items())
    if a.residuals is not None:
        fits += f"; residual test: {a.residuals.to_dict()['verdict']}"
    section = {
        "title": "Identification on the virtual test facility",
        "html": ("<p>Records from the virtual facility (nonlinear AMB force law, full FE rotor, "
                 "noise, ADC), fitted by the output-error method of P2/P4. NRMSE fit of stage "
                 f"(a): {fits}. Identified rig: <code>identified_rig.toml</code>.</p>"
                 "<table><tr><th>parameter</th><th>identified</th><th>truth</th>"
                 "<th>95 % interval</th><th>error</th></tr>" + "".join(rows) + "</table>"),
    }
    return figs, [section]


def write_run_report(out: Path, title: str, meta: str, metrics: dict, curves: list,
                     extra_figures: list, extra_sections: list) -> Path:
    """``report.html`` of the main job: the metrics table, σ̄(S_o) with the ISO 14839-3
    zones, compliance, unbalance and impulse responses of every judged case
    (``curves = [(label, {"So", "compliance", "unbalance", "impulse"})]``), then the extra
    figures and sections."""
    from . import figures
    from .html import write_report

    figs = [("Output sensitivity σ̄(S_o) with the ISO 14839-3 zones",
             figures.sensitivity_figure(out / "sensitivity.png",
                                        [(lb, *c["So"]) for lb, c in curves if "So" in c]))]
    comp = [(lb, *c["compliance"]) for lb, c in curves if "compliance" in c]
    if comp:
        figs.append(("Compliance σ̄(S_o G_f) at the seal",
                     figures.compliance_figure(out / "compliance.png", comp)))
    unb = [(lb, *c["unbalance"]) for lb, c in curves if "unbalance" in c]
    if unb:
        grade = metrics["unbalance"]["grade_mm_s"]
        figs.append((f"Worst-case unbalance response, G{grade:g}",
                     figures.unbalance_figure(out / "unbalance.png", unb)))
    imp = [(lb, c["impulse"]) for lb, c in curves if "impulse" in c]
    if imp:
        first = imp[0][1]
        figs.append((
            f"Response to {first.amplitude_a:g} A for {first.duration_s * 1e3:g} ms on "
            f"{' and '.join(first.channels)}",
            figures.impulse_figure(
                out / "impulse.png", [(lb, r.time_ms, r.displacement_um) for lb, r in imp],
                first.output_names, currents=[(lb, r.time_ms, r.current_a) for lb, r in imp])))
    ol = metrics["open_loop"]
    sections = [{"title": "Open loop",
                 "text": (f"{len(ol['unstable_poles'])} unstable poles (rad/s): "
                          + ", ".join(f"{re:.1f}{im:+.1f}j" for re, im in ol["unstable_poles"])
                          + f"; {ol['n_states_full']} states in full order, "
                          f"{ol['n_states_reduced']} reduced.")}]
    return write_report(out / "report.html", title=title, metrics=metrics["cases"],
                        figures=figs + list(extra_figures),
                        sections=sections + list(extra_sections), meta=meta)
