"""The main job's report: its figures, the identification section and ``report.html``.

Everything here draws or formats results computed elsewhere (:mod:`ambseal.analysis.judge`,
:mod:`ambseal.identify.fitting.procedure`, :mod:`ambseal.identify.fitting.checks`); figures follow the
thesis's (P5 Figs. 10–15, P4 Figs. 9–12, P5 Fig. 7, P3 Figs. 11–12).
"""

from __future__ import annotations

import datetime
import hashlib
import html
import math
from pathlib import Path

import numpy as np

from ambseal import __version__
from ambseal.analysis import force_demand, lost_conditions, worst_zone
from ambseal.config import method_label
from ambseal.identify import MIN_FIT_PCT, fit_reliability, interval_check, true_line
from ambseal.lti import freqresp_at
from ambseal.lti.freqresp import freqresp
from ambseal.model import amb_factors, force_capacity, load_capacity
from ambseal.report import figures
from ambseal.report.figures import case_style, controller_colours, controller_gains_figure
from ambseal.report.html import write_report
from ambseal.report.identify_figures import (
    correlation_figure,
    facility_impulse_figure,
    fit_timeseries_figure,
    frf_figure,
    residual_figure,
    seal_frequency_figure,
    seal_pressure_figure,
)
from ambseal.report.lpv_figures import frozen_sensitivity_figure, spinup_figure
from ambseal.report.verdict import axis_label, sig

__all__ = ["gains_figure", "capacity_figure", "rejection_figure", "spinup_figures",
           "identification_report", "write_run_report", "stamp", "statics_section"]


def stamp(rig_path: str | Path, command: str | None = None) -> str:
    """The report's stamp: ambseal version, date (UTC), rig file, its SHA-256 and the command.

    Parameters
    ----------
    rig_path : str or Path
        The rig file (read for its hash).
    command : str, optional
        The command line that ran.

    Returns
    -------
    str
        One line.
    """

    rig_path = Path(rig_path)
    digest = hashlib.sha256(rig_path.read_bytes()).hexdigest()[:16]
    when = datetime.datetime.now(datetime.timezone.utc).strftime("%Y-%m-%d %H:%M UTC")
    return (f"ambseal {__version__} · {when} · rig {rig_path.name} (sha256 {digest}…) · "
            f"command: {command or 'ambseal.app.pipeline.run()'}")


#: The manual's section on what the main job judges on (docs/getting-started.md).
MANUAL_JUDGED_ON = "getting-started.md#what-it-judged-on"


def judged_on(cfg, truth=None, truth_path: str | Path | None = None) -> tuple[str, str]:
    """The report's "Judged on" line and its link into the manual.

    Parameters
    ----------
    cfg : RigConfig
        The rig file's configuration.
    truth : TruthSection, optional
        The virtual facility's truth, when the loops were judged on it.
    truth_path : str or Path, optional
        Its file, named in the line.

    Returns
    -------
    (str, str)
        The line, and the manual page's address: the source tree's
        ``docs/getting-started.md`` as a ``file:`` URI where it exists beside the package,
        else its path in the manual.
    """
    docs = Path(__file__).resolve().parents[3] / "docs" / MANUAL_JUDGED_ON.split("#")[0]
    href = (docs.as_uri() + "#" + MANUAL_JUDGED_ON.split("#")[1] if docs.is_file()
            else "docs/" + MANUAL_JUDGED_ON)
    if truth is None:
        return ("the rig file's full-order model, each controller with the target's hold and "
                "computation delay, and as it runs (sampled, delayed)", href)
    diff = sorted(truth.parameters)
    if truth.tau_e != cfg.actuator.eddy_time_constant:
        diff.append(f"eddy-current lag τ_e {truth.tau_e * 1e3:.3g} ms (rig file "
                    f"{cfg.actuator.eddy_time_constant * 1e3:.3g} ms)")
    if truth.sensor_filter_hz is not None:
        diff.append(f"a sensor low-pass at {truth.sensor_filter_hz:g} Hz")
    if truth.beam is not None:
        diff.append(f"{truth.beam} beams")
    if truth.mesh_factor != 1.0:
        diff.append(f"a mesh {truth.mesh_factor:g}× as fine")
    if truth.modal_damping is not None:
        diff.append(f"modal damping {truth.modal_damping:g}")
    name = Path(truth_path).name if truth_path is not None else "its truth file"
    return (f"the virtual facility's truth ({name}, full order), not the rig file; it "
            f"differs from the rig file in: {', '.join(diff) or 'nothing'}", href)


def gains_figure(out: Path, controllers: list[tuple[str, object]]) -> tuple[str, Path]:
    """Direct and cross gains of physical controllers ``[(name, StateSpace)]`` (P5 Fig. 10),
    1 Hz – 2 kHz.

    Parameters
    ----------
    out : Path
        Folder of the figure (``controller_gains.png``).
    controllers : list of (str, control.StateSpace)
        Method and physical controller (``i = −K y``), one input per measurement: a
        continuous one at s = jω, a discrete one (``dt`` > 0, e.g. a design on the
        sampled plant, which has no continuous form) at z = e^{jωT}, below the Nyquist
        frequency.

    Returns
    -------
    (str, Path)
        The caption and the PNG written.
    """

    def gains(K):
        if not K.dt:
            return f, freqresp(K, 2 * np.pi * f)
        fd = f[f < 0.5 / K.dt]  # aliased above
        return fd, freqresp_at(K, np.exp(2j * np.pi * fd * K.dt))

    f = np.logspace(0, math.log10(2000.0), 300)
    rows = [(m, *gains(K)) for m, K in controllers]
    names = [axis_label(n.removeprefix("y_")) for n in controllers[0][1].input_labels]
    colours = controller_colours([m for m, _ in controllers])
    return ("Direct and cross gains of the controllers (P5 Fig. 10)",
            controller_gains_figure(out / "controller_gains.png", rows, names,
                                    styles={m: case_style(c) for m, c in colours.items()}))


def capacity_figure(out: Path, cfg, currents: dict[str, list]) -> list[tuple[str, Path]]:
    """The force each AMB can deliver against frequency and the force each controller asks
    of it to hold the judged unbalance (:func:`ambseal.model.capacity.force_capacity`,
    :func:`ambseal.analysis.amplifier.force_demand`), one panel per AMB.

    Parameters
    ----------
    out : Path
        Folder of the figure (``force_capacity.png``).
    cfg : RigConfig
        The rig (its ``[[amb]]`` limits and ``[actuator]``).
    currents : dict
        Method → its judged conditions' unbalance currents, the entries of
        :func:`ambseal.analysis.amplifier.capacity_block`.

    Returns
    -------
    list of (str, Path)
        The caption and PNG; empty when no AMB gives its bias current and Ki or no loop
        was judged stable.
    """
    ambs = [a for a in cfg.amb if a.bias_current is not None and None not in amb_factors(a)[0]]
    demands = {m: force_demand(cfg, entries) for m, entries in currents.items()}
    speeds = np.concatenate([f for d in demands.values() for f, _ in d.values()] or [[]])
    speeds = speeds[speeds > 0]
    if not ambs or not speeds.size:
        return []
    # the judged speeds and an octave either side: where the slew rate starts to bind shows
    f = np.logspace(math.log10(speeds.min() / 2), math.log10(2 * speeds.max()), 300)
    bearings = [(a.name, f, force_capacity(a, 2 * np.pi * f)) for a in ambs]
    by_amb = {a.name: [(method_label(m), *d[a.name]) for m, d in demands.items()
                       if a.name in d] for a in ambs}
    colours = controller_colours(list(demands))
    return [("Force capacity of each AMB (current limit, bias, the supply voltage's slew rate "
             "Ki·V/(Lω)) and the force each controller asks of it for the unbalance",
             figures.force_capacity_figure(
                 out / "force_capacity.png", bearings, by_amb,
                 static_n={a.name: load_capacity(a) for a in ambs},
                 styles={method_label(m): case_style(c) for m, c in colours.items()}))]


def rejection_figure(out: Path, rejections: dict) -> list[tuple[str, Path]]:
    """The unbalance force rejection's figures (:mod:`ambseal.analysis.rejection`): the
    synchronous coil current, transmitted force and orbit over the speed range with each
    controller alone (dashed) and with its rejection (solid); and the synchronous coil
    current on the virtual facility under a sensor runout, the notch switched on.

    Parameters
    ----------
    out : Path
        Folder of the figures (``rejection.png``, ``rejection_facility.png``,
        ``rejection_speed_step.png``).
    rejections : dict
        ``effects`` (method → :func:`~ambseal.analysis.rejection.rejection_effect`) and
        ``facility`` (method → :class:`~ambseal.analysis.rejection.FacilityRejection`)
        and ``speed_step`` (method → :class:`~ambseal.analysis.rejection.SpeedStep`).

    Returns
    -------
    list of (str, Path)
        Captions and PNGs; empty without any rejection.
    """
    effects, facility = (rejections or {}).get("effects"), (rejections or {}).get("facility")
    if not effects:
        return []
    colours = controller_colours(list(effects))
    panels = [("current_a", "Coil current (A)"), ("force_n", "Transmitted force (N)"),
              ("orbit_um", "Orbit at the sensors (µm)")]
    curves = {q: [] for q, _ in panels}
    styles = {}
    for m, e in effects.items():
        for key, ls in (("without", "--"), ("with", "-")):
            label = f"{method_label(m)}, {key} rejection"
            styles[label] = {**case_style(colours[m]), "ls": ls}
            for q, _ in panels:
                curves[q].append((label, e["speed_hz"], e[q][key]))
    figs = [("Unbalance force rejection (Herzog et al. 1996): synchronous coil current, "
             "transmitted force and orbit, each controller alone (dashed) and with it "
             "(solid)",
             figures.panels_figure(out / "rejection.png", panels, curves,
                                   xlabel="Speed (Hz)", styles=styles,
                                   title="Unbalance force rejection"))]
    if facility:
        first = next(iter(facility.values()))
        figs.append((
            f"Virtual facility at {first.speed_hz:g} Hz, a sensor runout of "
            f"{first.runout_m * 1e6:.3g} µm: synchronous coil current, each controller "
            "alone until its loop has settled, then with its notch switched on (time 0)",
            figures.decay_figure(
                out / "rejection_facility.png",
                [(method_label(m), r.time_s - r.on_s, r.current_a)
                 for m, r in facility.items()],
                ylabel="Synchronous coil current (A)", marks={"notch on": 0.0},
                styles={method_label(m): case_style(colours[m]) for m in facility},
                title="Runout rejection on the virtual facility")))
    steps = (rejections or {}).get("speed_step")
    if steps:
        first = next(iter(steps.values()))
        curves = {"current_a": [], "orbit_um": []}
        styles = {}
        for m, r in steps.items():
            for key, ls in (("without", "--"), ("with", "-")):
                label = f"{method_label(m)}, {key} rejection"
                styles[label] = {**case_style(colours[m]), "ls": ls}
                curves["current_a"].append((label, r.time_s - r.step_s, r.current_a[key]))
                curves["orbit_um"].append((label, r.time_s - r.step_s, 1e6 * r.orbit_m[key]))
        figs.append((
            f"Virtual facility, a speed step {first.from_hz:g} → {first.to_hz:g} Hz at time "
            f"0 under the sensor runout: synchronous coil current and orbit (the shaft at "
            "the sensors) per revolution, each controller alone (dashed) and with its "
            "notch (solid)",
            figures.panels_figure(
                out / "rejection_speed_step.png",
                [("current_a", "Synchronous coil current (A)"),
                 ("orbit_um", "Synchronous orbit (µm)")], curves,
                xlabel="Time from the speed step (s)", styles=styles,
                title="Speed step on the virtual facility")))
    return figs


def spinup_figures(out: Path, sims: list, sens: list, speeds_hz: tuple[float, float]
                   ) -> list[tuple[str, Path]]:
    """The spin-up (P3 Fig. 11) and σ̄(S_o) at frozen speeds (P3 Fig. 12).

    Parameters
    ----------
    out : Path
        Folder of the figures (``spinup.png``, ``frozen_sensitivity.png``).
    sims : list of SpinupResult
        One spin-up per controller.
    sens : list of FrozenSensitivity
        σ̄(S_o) at frozen speeds, one per controller.
    speeds_hz : (float, float)
        The spin-up's start and end speeds (Hz), for the caption.

    Returns
    -------
    list of (str, Path)
        Caption and PNG of each figure.
    """

    lo, hi = speeds_hz
    colours = controller_colours([r.name for r in sims])
    return [(f"Spin-up {lo:g} → {hi:g} Hz in 1 s with 100 N force and 2 µm output steps on "
             "A_x (P3 Fig. 11)", spinup_figure(out / "spinup.png", sims, colours=colours)),
            ("σ̄(S_o) at frozen speeds with the ISO 14839-3 line (P3 Fig. 12)",
             frozen_sensitivity_figure(out / "frozen_sensitivity.png", sens))]


def identification_report(out: Path, res, errors: dict, checks, truth, seal_name: str | None,
                          nominal_bar: float, levitated_by: str | None = None
                          ) -> tuple[list, list]:
    """Figures and the HTML section of the identification stage.

    Parameters
    ----------
    out : Path
        Folder of the figures.
    res : ProcedureResult
        The identification.
    errors : dict
        :func:`ambseal.identify.fitting.checks.truth_errors` of ``res``.
    checks : FrfChecks
        The frequency-response checks of the identified model.
    truth : TruthSection
        The facility's truth, drawn beside the estimates.
    seal_name : str or None
        The seal whose coefficients are drawn against pressure; None for none.
    nominal_bar : float
        The rig's nominal pressure drop (bar), marked in the pressure figure.
    levitated_by : str, optional
        Why the facility was levitated by another controller than the rig file's PID
        (:func:`ambseal.app.commands.facility_controller`), said first.

    Returns
    -------
    (figures, sections)
        ``[(caption, png)]`` and ``[{"title", "html"}]`` for :func:`write_run_report`.
    """

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
                   np.array([r.std_error for _, r in rows]),
                   [bool(fit_reliability(r)) for _, r in rows])
                  for p, rows in res.seal_vs_frequency.items()]
        figs.append(("Seal coefficients by a stepped sine of balanced forward and backward "
                     "whirl (P4 Fig. 12); open markers: unreliable fits (NRMSE below "
                     f"{MIN_FIT_PCT:g} %, residuals correlated with the excitation, or not "
                     "converged)",
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
    rows = [_truth_row(n, e) for n, e in errors.items()]
    fits = ", ".join(f"{k} {v:.1f} %" for k, v in a.nrmse_fit_pct.items())
    if a.residuals is not None:
        fits += f". Model check of stage (a)+(b): {_model_check_text(a, errors)}"
    truth_check = interval_check(errors)
    if truth_check["checked"]:
        fits += (". Against the facility's truth: "
                 + ("<b>" if truth_check["mismatch"] else "")
                 + html.escape(truth_check["verdict"])
                 + ("</b>" if truth_check["mismatch"] else ""))
    for p, why in res.skipped:
        fits += f". Seal impulse at {p:g} bar skipped: {html.escape(why)}"
    section = {
        "title": "Identification on the virtual test facility",
        "html": ((f"<p><b>{html.escape(levitated_by[0].upper() + levitated_by[1:])}.</b></p>"
                  if levitated_by else "")
                 + "<p>Records from the virtual facility (nonlinear AMB force law, full FE rotor, "
                 "noise, ADC), fitted by the output-error method of P2/P4. NRMSE fit of stage "
                 f"(a): {fits}. Identified rig: <code>identified_rig.toml</code>.</p>"
                 "<table><tr><th>parameter</th><th>identified</th><th>truth</th>"
                 "<th>95 % interval</th><th>error</th></tr>" + "".join(rows) + "</table>"
                 + _seal_table(res)),
    }
    return figs, [section]


def _truth_row(name: str, e: dict) -> str:
    """One row of the identified-against-truth table: an estimate with its interval, or a
    regression on pressure."""
    if "estimate" in e:
        lo, hi = (math.nan if v is None else v for v in e["ci95"])
        err = "" if e["error_pct"] is None else f"{e['error_pct']:+.2f} %"
        return (f"<tr><td class=\"text\">{html.escape(name)}</td>"
                f"<td>{sig(e['estimate'], 4)}</td><td>{sig(e['truth'], 4)}</td>"
                f"<td>[{sig(lo, 4)}, {sig(hi, 4)}]</td><td>{err}</td></tr>")
    t = e["truth"]
    tl = f"{t['at_zero']:.4g} + {t['per_bar']:.4g}·p" if isinstance(t, dict) else str(t)
    return (f"<tr><td>{html.escape(name)} (vs p, bar)</td><td>{e['intercept']:.4g} + "
            f"{e['slope']:.4g}·p</td><td>{tl}</td><td>slope ± "
            f"{1.96 * e['slope_se']:.3g}</td><td></td></tr>")


def _model_check_text(fit, errors: dict) -> str:
    """The verdict of a procedure fit's model check, with what each disputed fixed value
    is: the offset the data suggest, the uncertainty the intervals carry for it and, for a
    seal coefficient, stage (c)'s estimate at 0 bar; a sensor lag the data ask for as well
    is named after them (wrong held values can make it too)."""
    check = fit.model_check()
    if not check["disputed"]:
        return html.escape(check["verdict"])
    b = fit.budget
    parts = []
    for n in check["disputed"]:
        j = b.fixed.index(n)
        later = errors.get(n, {})
        seen = (f"; stage (c) finds {sig(later['intercept'], 3)} ± "
                f"{sig(1.96 * later['intercept_se'], 2)} at 0 bar" if "intercept" in later else "")
        parts.append(f"{html.escape(n)}: the data suggest {100 * b.offset_rel[j]:+.0f} ± "
                     f"{100 * 1.96 * b.offset_rel_se[j]:.0f} % from the value held "
                     f"({html.escape(b.source[j])}, σ = {100 * b.sigma_rel[j]:.3g} % in the "
                     f"intervals){seen}")
    failed = check["residuals_correlated"]
    lag = ""
    if check["sensor_lag"]:
        tau, se = (1e6 * fit.sensor_lag[k] for k in ("suggested_tau_s", "suggested_tau_s_se"))
        lag = (f"; the data also ask for a sensor lag of {tau:.3g} ± {se:.2g} µs, which the "
               "wrong held values can make as well: fit them first")
    return ("model mismatch — the stage holds values the data dispute (score test): "
            + "; ".join(parts) + ". Its intervals carry those values' stated uncertainty "
            "(error budget); the estimates are biased by what the held values are off"
            + (f"; the residuals correlate with the excitation on {', '.join(failed)}, as "
               "a wrong held value makes them" if failed else "") + lag)


def facility_impulse_report(out: Path, checks: list, design_note: dict
                            ) -> tuple[list, list]:
    """Figure and section: impulse responses on the virtual facility beside the identified
    model's (P5 Figs. 15–16), and which rig the robust controllers were designed on.

    Parameters
    ----------
    out : Path
        Folder of the figure.
    checks : list of ImpulseCheck
        :func:`ambseal.identify.facility.design_model.impulse_checks`.
    design_note : dict
        The rig the designs took and why (:func:`ambseal.identify.facility.design_model.design_rig`).

    Returns
    -------
    (figures, sections)
        ``[(caption, png)]`` and ``[{"title", "html"}]`` for :func:`write_run_report`.
    """

    figs = [("Impulse responses, 0.05 A for 10 ms on the first bearing's ζ and the last "
             "bearing's η: virtual facility (dashed) against the identified model (solid), "
             "P5 Fig. 15", facility_impulse_figure(out / "facility_impulse.png", checks))]
    rows = []
    for c in checks:
        if c.error is not None:
            rows.append(f"<tr><td>{html.escape(c.controller)}</td><td>{c.pressure_bar:g}</td>"
                        f"<td class=\"text\" colspan=\"3\">{html.escape(c.error)}</td></tr>")
            continue
        d = c.to_dict()
        fit = min(c.nrmse_fit_pct.values())
        rows.append(f"<tr><td>{html.escape(c.controller)}</td><td>{c.pressure_bar:g}</td>"
                    f"<td>{d['peak_facility_um']:.2f}</td><td>{d['peak_model_um']:.2f}</td>"
                    f"<td>{fit:.1f} %</td></tr>")
    why = html.escape(design_note["reason"])
    section = {"title": "Design from the identified model, run on the facility",
               "html": (f"<p>H∞ and μ designed on the {html.escape(design_note['designed_on'])}"
                        f" ({why}); every controller judged on the virtual facility's "
                        "full-order model with the truth file's values, and run on the "
                        "facility beside the identified model (P5 §5.2: \"the experimental "
                        "and simulated responses match well\").</p><table><tr><th>controller"
                        "</th><th>pressure (bar)</th><th>peak, facility (µm)</th><th>peak, "
                        "model (µm)</th><th>worst NRMSE fit</th></tr>" + "".join(rows)
                        + "</table>")}
    return figs, [section]


def _seal_table(res) -> str:
    """The stepped-sine seal fits per pressure and frequency: the K–c and C–k correlations
    (Jacobian, as P4 Table 4), the NRMSE fit and why a fit is unreliable."""

    rows = []
    for p, fits in res.seal_vs_frequency.items():
        for f, r in fits:
            c = r.correlation_jacobian if r.correlation_jacobian is not None else r.correlation
            n = list(r.names)
            kc = c[n.index(next(x for x in n if x.endswith(".K"))),
                   n.index(next(x for x in n if x.endswith(".c")))]
            ck = c[n.index(next(x for x in n if x.endswith(".C"))),
                   n.index(next(x for x in n if x.endswith(".k")))]
            why = "; ".join(fit_reliability(r)) or "reliable"
            fit = min(v for k, v in r.nrmse_fit_pct.items() if not k.startswith("current_"))
            rows.append(f"<tr><td>{p:g}</td><td>{f:g}</td><td>{kc:+.2f}</td><td>{ck:+.2f}</td>"
                        f"<td>{fit:.1f} %</td><td class=\"text\">{html.escape(why)}</td></tr>")
    if not rows:
        return ""
    return ("<p>Stepped-sine seal fits (balanced forward and backward whirl on both axes of "
            "both bearings): correlations from the Jacobian, as P4 Table 4 (all below 0.04 "
            "at 40 Hz there).</p><table><tr><th>pressure (bar)</th><th>frequency (Hz)</th>"
            "<th>K–c</th><th>C–k</th><th>worst NRMSE fit</th><th>reliability</th></tr>"
            + "".join(rows) + "</table>")


def _styles(curves: list) -> tuple[dict, dict]:
    """Label → style of every case (one colour per controller, one line style per condition),
    and label → style of the unstable ones (not drawn)."""

    colours = controller_colours([m for m, _, _, _ in curves])
    styles = {f"{m}, {p.label}": case_style(colours[m], p.condition) for m, p, _, _ in curves}
    unstable = {f"{m}, {p.label}": styles[f"{m}, {p.label}"] for m, p, case, _ in curves
                if not case.get("stable")}
    return styles, unstable


def _discrete_section(metrics: dict) -> list[dict]:
    """A row per judged case: the controller as it runs on the target beside the continuous
    design (the ``discrete`` blocks of ``metrics.json``), in a table, and the explanations
    of the differences above the tolerance before it."""
    rows = []
    for c in metrics["cases"]:
        d = c.get("discrete")
        if d is None:
            continue
        disc = metrics["controllers"].get(c["controller"], {}).get("discretisation") or {}
        peak = lambda x: "–" if x is None else f"{x:.2f}"  # noqa: E731
        # the discretisation as metrics.json records it; a controller without one there
        # (not exported) is named by its rate alone, never by a placeholder
        how = (f"{disc['method']} at {d['sample_rate_hz']:g} Hz, {disc['delay_samples']} "
               "sample(s) delay" if {"method", "delay_samples"} <= disc.keys()
               else f"at {d['sample_rate_hz']:g} Hz")
        cells = (c["controller"], f"{c['pressure_bar']:g} bar, {c['speed_hz']:g} Hz",
                 "stable" if d["stable"] else "UNSTABLE", f"{d['max_abs_pole_z']:.5f}",
                 peak(d["sensitivity_peak"]), peak(c["sensitivity_peak"]),
                 str(d["iso_zone"]), how)
        rows.append(("<tr>" if d["stable"] else '<tr class="unstable">')
                    + "".join(f'<td class="text">{html.escape(x)}</td>' if i in (0, 1, 7)
                              else f"<td>{html.escape(x)}</td>" for i, x in enumerate(cells))
                    + "</tr>")
    if not rows:
        return []
    why = [f"{m}: {d['peak_difference']['explanation']}" for m, c in metrics["controllers"].items()
           for d in [c.get("discretisation") or {}]
           if (d.get("peak_difference") or {}).get("explanation")]
    text = (". ".join(why) + ". " if why else "") + (
        "Each judged condition with the controller as it runs: the plant sampled by the "
        "hold, the discrete controller and its computation delay, beside the continuous "
        "loop with the target's delay.")
    head = "".join(f"<th>{h}</th>" for h in (
        "Controller", "Condition", "As it runs", "max |z|", "σ̄(S_o) peak as it runs",
        "σ̄(S_o) peak continuous", "ISO 14839-3 zone as it runs", "Discretisation"))
    table = (f'<div class="scroll"><table><tr>{head}</tr>{"".join(rows)}</table></div>')
    return [{"title": "On the target (discrete judgement)", "text": text, "html": table}]


def _speed_range_section(metrics: dict) -> list[dict]:
    """A table of ``metrics["stability"]``: a row per controller, a column per speed; a cell
    says "stable" and the worst ISO 14839-3 zone of any axis (continuous and as it runs,
    every judged pressure) when the loop is stable at every judged pressure there, else the
    pressures where it is not."""
    cases = metrics.get("stability") or []
    if not cases:
        return []
    speeds = sorted({c["speed_hz"] for c in cases})
    names = list(dict.fromkeys(c["controller"] for c in cases))
    rows = []
    for n in names:
        cells = []
        for f in speeds:
            at = [c for c in cases if c["controller"] == n and c["speed_hz"] == f]
            bad = [c["pressure_bar"] for c in at if not c["stable"]
                   or not (c.get("discrete") or {}).get("stable", True)]
            zones = [z for c in at for b in (c, c.get("discrete") or {})
                     for z in (b.get("iso_zone_per_axis") or {}).values()]
            zone = worst_zone(zones)
            ok = "stable" + (f", zone {zone}" if zone else "")
            # σ̄(S_o) over all axes, where its zone is worse than every axis's: the verdict
            # counts it, so the table says where
            loops = [b for c in at for b in (c, c.get("discrete") or {})]
            mimo = worst_zone([b.get("iso_zone") for b in loops])
            top = max((b["sensitivity_peak"] for b in loops
                       if b.get("sensitivity_peak") is not None), default=None)
            if zone and mimo and top is not None and worst_zone([zone, mimo]) != zone:
                ok += f"; σ̄(S_o) zone {mimo} ({sig(top)})"
            cells.append('<td>—</td>' if not at else f'<td>{ok}</td>' if not bad else
                         '<td class="unstable">unstable at '
                         + html.escape(", ".join(f"{q:g}" for q in bad)) + " bar</td>")
        rows.append(f"<tr><td>{html.escape(n)}</td>{''.join(cells)}</tr>")
    head = "".join(f"<th>{f:g} Hz</th>" for f in speeds)
    table = (f'<div class="scroll"><table><tr><th>Controller</th>{head}</tr>'
             f"{''.join(rows)}</table></div>")
    text = ("Every controller closed on the full-order plant at each judged pressure and "
            "each speed from standstill to the top speed that is not a judged condition, "
            "continuous with the target's delay and as it runs (sampled): its stability, "
            "the worst ISO 14839-3 zone of any axis there and, where σ̄(S_o) over all axes "
            "is in a worse zone, that zone and its largest peak (the verdict counts both).")
    return [{"title": "From standstill to the top speed", "text": text, "html": table}]


def statics_section(st: dict) -> dict:
    """The report's section on the rotor held at rest as the machine stands: its
    orientation and gravity, each bearing's load, each AMB's static current per axis and
    who carries the axial weight.

    Parameters
    ----------
    st : dict
        :meth:`ambseal.analysis.statics.Statics.to_dict`.

    Returns
    -------
    dict
        ``{"title", "html"}`` for :func:`write_run_report`.
    """
    esc = html.escape
    tilt = (f", the rotor axis {sig(st['inclination_deg'])}° above the horizontal"
            if st["orientation"] == "inclined" else "")
    g = ", ".join(sig(x) for x in st["gravity_m_s2"])
    head = (f"<p>A {esc(st['orientation'])} machine{tilt}: gravity ({g}) m/s² on x, y, z "
            f"(<code>[machine] orientation</code>); rotor mass {sig(st['mass_kg'])} kg. "
            "Each AMB holds its journal at the set point: its static current is its "
            "force over Ki (f = Ki·i + Ks·s at s = 0).</p>")
    rows = "".join(
        f"<tr><td>{esc(a['name'])}</td><td>{sig(a['position_m'])}</td>"
        f"<td>{sig(a['force_n'][0])}</td><td>{sig(a['force_n'][1])}</td>"
        + "".join(f"<td>{'—' if i is None else sig(i)}</td>"
                  for i in a["current_a"].values()) + "</tr>"
        for a in st["ambs"])
    table = ("<table><tr><th>AMB</th><th>z (m)</th><th>F_x (N)</th><th>F_y (N)</th>"
             "<th>i_ζ (A)</th><th>i_η (A)</th></tr>" + rows + "</table>") if rows else ""
    axial = f"<p>{esc(st['axial_note'])}.</p>" if st["axial_note"] else ""
    if not st["held"]:
        axial = ("<p>The bearings do not hold the rotor statically (one bearing plane: "
                 "nothing takes the weight's moment): no static currents.</p>" + axial)
    return {"title": "Statics: the rotor at rest as the machine stands",
            "html": head + table + axial}


def write_run_report(out: Path, title: str, meta: str, metrics: dict, curves: list,
                     extra_figures: list, extra_sections: list,
                     clearances_um: dict | None = None,
                     judged_on: tuple[str, str] | None = None) -> Path:
    """``report.html`` of the main job: the verdict per controller and the table of every
    case (:mod:`ambseal.report.verdict`), σ̄(S_o) with the ISO 14839-3 zones, compliance,
    unbalance and impulse responses, then the extra figures and sections.

    ``curves = [(method, OperatingPoint, case, {"So", "compliance", "unbalance",
    "impulse"})]`` in the order of ``metrics["cases"]``; a case whose loop is unstable is
    listed in each figure's legend, not drawn. The controllers of ``metrics["failed"]``
    are listed first with their reasons.

    Parameters
    ----------
    out : Path
        The run's folder: ``report.html`` and its figures.
    title : str
        The page's title.
    meta : str
        The stamp (:func:`stamp`).
    metrics : dict
        The run's ``metrics.json`` document (``cases``, ``failed``, ``stability``,
        ``controllers``).
    curves : list
        ``(method, OperatingPoint, case, {"So", "compliance", "unbalance", "impulse"})``
        per case, in the order of ``metrics["cases"]``.
    extra_figures : list of (str, Path)
        Caption and PNG of each further figure.
    extra_sections : list of dict
        ``{"title", "html"}`` of each further section.
    clearances_um : dict, optional
        :func:`ambseal.analysis.delivery.rig_clearances_um` of the rig, for the unbalance orbit.
    judged_on : (str, str), optional
        :func:`judged_on`'s line and link.

    Returns
    -------
    Path
        ``report.html``.
    """
    return write_report(out / "report.html", title=title, metrics=metrics["cases"],
                        figures=_run_figures(out, metrics, curves) + list(extra_figures),
                        sections=_run_sections(metrics) + list(extra_sections), meta=meta,
                        clearances_um=clearances_um, judged_on=judged_on,
                        failed=[f["reason"] for f in (metrics.get("failed") or {}).values()],
                        stability=metrics.get("stability") or (),
                        designs=metrics.get("controllers"))


def _run_figures(out: Path, metrics: dict, curves: list) -> list:
    """The main job's figures, (caption, path): σ̄(S_o) continuous and as it runs,
    compliance, unbalance and impulse responses of every stable judged loop."""
    styles, unstable = _styles(curves)
    kw = dict(styles=styles, unstable=unstable)
    drawn = [(f"{m}, {p.label}", c) for m, p, case, c in curves if case.get("stable")]
    figs = [("Output sensitivity σ̄(S_o) with the ISO 14839-3 zones (P5 Fig. 13)",
             figures.sensitivity_figure(out / "sensitivity.png",
                                        [(lb, *c["So"]) for lb, c in drawn if "So" in c], **kw))]
    comp = [(lb, *c["compliance"]) for lb, c in drawn if "compliance" in c]
    figs += _discrete_figure(out, curves, styles)
    if comp:
        at = (metrics.get("design_spec") or {}).get("force_at") or "the bearings"
        figs.append((f"Compliance σ̄(S_o G_f), forces at {at} (P5 Fig. 11)",
                     figures.compliance_figure(out / "compliance.png", comp, **kw)))
    unb = [(lb, *c["unbalance"]) for lb, c in drawn if "unbalance" in c]
    if unb:
        grade = metrics["unbalance"]["grade_mm_s"]
        figs.append((f"Worst-case unbalance response, G{grade:g} (P5 Fig. 12)",
                     figures.unbalance_figure(out / "unbalance.png", unb, **kw)))
    return figs + _impulse_figure(out, [(lb, c["impulse"]) for lb, c in drawn
                                        if "impulse" in c], styles)


def _discrete_figure(out: Path, curves: list, styles: dict) -> list:
    """σ̄(S_o) of the loops as they run, in the continuous loops' colours and line styles;
    an unstable one listed only (none drawn: no figure)."""
    dstable = {f"{m}, {p.label}": bool((case.get("discrete") or {}).get("stable"))
               for m, p, case, c in curves if "discrete" in c}
    disc = [(lb, *c["discrete"]["So"]) for lb, c in
            ((f"{m}, {p.label}", c) for m, p, _, c in curves) if dstable.get(lb)]
    if not disc:
        return []
    return [("σ̄(S_o) of the controllers as they run: sampled plant, discrete "
             "controller and its computation delay, up to Nyquist",
             figures.sensitivity_figure(
                 out / "sensitivity_discrete.png", disc, styles=styles,
                 unstable={lb: styles[lb] for lb, ok in dstable.items() if not ok}))]


def _impulse_figure(out: Path, imp: list, styles: dict) -> list:
    """The impulse responses ``imp = [(label, response)]`` (none: no figure)."""
    if not imp:
        return []
    first = imp[0][1]
    names = [axis_label(n.removeprefix("y_")) for n in first.output_names]
    return [(
        f"Response to {first.amplitude_a:g} A for {first.duration_s * 1e3:g} ms on "
        f"{' and '.join(axis_label(c.removeprefix('i_')) for c in first.channels)} "
        "(P5 Fig. 14)",
        figures.impulse_figure(
            out / "impulse.png", [(lb, r.time_ms, r.displacement_um) for lb, r in imp],
            names, currents=[(lb, r.time_ms, r.current_a) for lb, r in imp],
            styles=styles))]


def _sizing_section(metrics: dict) -> list[dict]:
    """A table of each delivered controller's ``capacity.sizing``
    (:func:`ambseal.analysis.amplifier.capacity_block`): per AMB the smallest current limit
    and supply voltage of an amplifier that holds every judged condition's unbalance."""
    rows = {m: s["capacity"]["sizing"] for m, s in metrics["controllers"].items()
            if m not in (metrics.get("failed") or {})
            and (s.get("capacity") or {}).get("sizing")}
    if not rows:
        return []
    ambs = list(dict.fromkeys(a for sizing in rows.values() for a in sizing))

    def cell(need: dict | None) -> str:
        if need is None:
            return "<td>—</td>"
        volts = need.get("supply_voltage_v")
        return (f"<td>{sig(need['current_limit_a'])} A, "
                + (f"{sig(volts)} V" if volts is not None else "— V") + "</td>")

    body = "".join(f"<tr><td>{html.escape(method_label(m))}</td>"
                   + "".join(cell(sizing.get(a)) for a in ambs) + "</tr>"
                   for m, sizing in rows.items())
    head = "".join(f"<th>AMB {html.escape(a)}</th>" for a in ambs)
    table = (f'<div class="scroll"><table><tr><th>Controller</th>{head}</tr>{body}'
             "</table></div>")
    text = ("The smallest amplifier that holds the judged worst-case unbalance and the "
            "current impulse at every judged condition, as each controller runs, per AMB "
            "and for both of its axes: its control-current limit (zero-to-peak) and supply "
            "voltage — R·i0 + |R + jωL| times the unbalance's current, R·i0 + "
            "|R i + L di/dt| in the impulse, each on top of the static current that holds "
            "the seals' static load where the rig file gives one." + _dash_reasons(rows))
    return [{"title": "Amplifier sizing", "text": text, "html": table}]


def _dash_reasons(rows: dict) -> str:
    """`` A dash for the voltage of AMB A: <why>.`` for the AMBs whose sizing has no supply
    voltage, each reason once with its AMBs (the sizing's ``supply_voltage_note``); ``""``
    where every voltage was computed."""
    why: dict = {}
    for sizing in rows.values():
        for amb, need in sizing.items():
            if need is not None and need.get("supply_voltage_v") is None:
                note = need.get("supply_voltage_note") or "no voltage was computed"
                why.setdefault(note, []).append(amb)
    return "".join(f" A dash for the voltage of AMB {', '.join(dict.fromkeys(ambs))}: {note}."
                   for note, ambs in why.items())


def _rejection_section(metrics: dict) -> list[dict]:
    """A table of each controller's unbalance force rejection (its ``rejection`` block,
    :mod:`ambseal.analysis.rejection`): where it is on, whether its loops hold at the
    judged conditions, and the synchronous current, force and orbit without and with it."""
    rows = {m: s["rejection"] for m, s in metrics["controllers"].items() if s.get("rejection")}
    if not rows:
        return []

    def pair(r: dict, q: str, unit: str) -> str:
        return f"<td>{sig(r[q]['without'])} → {sig(r[q]['with'])} {unit}</td>"

    def held(r: dict) -> str:
        if r["stable"]:
            return f"yes, at {len(r['conditions'])} conditions"
        return "<b>no</b>: loses the loop at " + html.escape(
            "; ".join(lost_conditions(r["conditions"])))

    body = "".join(
        f"<tr><td>{html.escape(method_label(m))}</td><td>{sig(r['on_from_hz'])} Hz</td>"
        f"<td>{sig(r['rate_fraction'])}</td><td>{held(r)}</td>"
        + pair(r, "current_a", "A") + pair(r, "force_n", "N") + pair(r, "orbit_um", "µm")
        + "</tr>" for m, r in rows.items())
    table = ('<div class="scroll"><table><tr><th>Controller</th><th>On from</th>'
             "<th>ε/Ω</th><th>Loops hold (continuous and as it runs)</th>"
             "<th>Coil current</th><th>Transmitted force</th><th>Orbit</th></tr>"
             f"{body}</table></div>")
    text = ("A generalised notch filter at the rotational frequency in each controller's "
            "input (Herzog et al., IEEE TCST 1996), scheduled on speed: the controller "
            "commands no synchronous current, so the rotor turns about its axis of inertia "
            "and each bearing transmits its negative stiffness's force alone. The largest "
            "synchronous amplitudes over the speed range (of the AMB axes, and of the "
            "orbit at the sensors; the ISO 21940-11 residual unbalance of the judged grade "
            "at the bearings, in phase and in opposite phase), without → with it. Each "
            "notch whose loops hold is exported beside its controller: "
            "controllers/rejection_<controller>.json and the C module "
            "ambseal_<controller>_rejection, whose output the controller reads in "
            "place of the displacements.")
    return [{"title": "Unbalance force rejection", "text": text, "html": table}]


#: How :func:`_synthesis_section` names the stages of an SDP synthesis.
_STAGES = {"gamma": "γ stage", "centre": "centring", "reconstruct": "reconstruction"}


def _synthesis_section(metrics: dict) -> list[dict]:
    """How each synthesis by SDPs ended (a design summary's ``reports``, the LPV's): per
    stage the status of the solve its controller was built from, its iterations against
    CVXOPT's cap, and the solves the synthesis went past; a design whose SDP ended short of
    optimal says so first."""
    lines = []
    for m, summary in metrics["controllers"].items():
        reports = summary.get("reports") or []
        if not any(r.get("solver") == "CVXOPT" for r in reports):
            continue
        used = [r for r in reports if r.get("used", True)]
        stages = "; ".join(
            f"{_STAGES.get(r['stage'], r['stage'])} {r['status']}"
            + (f" after {r['iterations']} of at most {r['max_iterations']} interior-point "
               "iterations" + (" (stopped by the cap)" if r.get("capped") else "")
               if r.get("max_iterations") else f" ({r['solver']})")
            for r in used)
        past = len(reports) - len(used)
        head = (f"NOT SOLVED TO OPTIMALITY: {summary['sdp_shortfall']}; γ is a bound its "
                "LMIs certify, and the controller is where the solver stopped, which "
                "another machine's rounding moves. " if summary.get("sdp_shortfall") else "")
        lines.append(f"{method_label(m)}: {head}Built from: {stages}"
                     + (f"; {past} further solve{'s' if past > 1 else ''} the synthesis "
                        "went past (continuation steps not kept, a scaling it replaced)"
                        if past else "") + ".")
    if not lines:
        return []
    return [{"title": "How the LMI syntheses ended", "text": " ".join(lines)}]


def _run_sections(metrics: dict) -> list[dict]:
    """The main job's text sections: the speed range, redesigns, what cannot run on the
    target, the open loop, the discretisations, the amplifiers, the unbalance rejection
    and how the LMI syntheses ended."""
    ol = metrics["open_loop"]
    sections = [{"title": "Open loop",
                 "text": (f"{len(ol['unstable_poles'])} unstable poles (rad/s): "
                          + ", ".join(f"{re:.1f}{im:+.1f}j" for re, im in ol["unstable_poles"])
                          + f"; {ol['n_states_full']} states in full order, "
                          f"{ol['n_states_reduced']} reduced.")}]
    sections = [{"title": "Cannot run on the target", "text": reason}
                for reason in (metrics.get("cannot_run") or {}).values()] + sections
    sections = [{"title": f"{method_label(m)}: redesigned", "text": (
        f"{s['remedy']}; the new design holds at every judged condition.")}
        for m, s in metrics["controllers"].items() if s.get("remedy")] + sections
    return (_speed_range_section(metrics) + sections + _discrete_section(metrics)
            + _sizing_section(metrics) + _rejection_section(metrics)
            + _synthesis_section(metrics))
