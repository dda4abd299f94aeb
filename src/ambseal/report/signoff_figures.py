"""A machine's sign-off in the report: API 617's Level I screening and unbalance response
as figures (matplotlib, Agg canvas, written through
:func:`ambseal.report.figures.save_figure`) and a section that says the verdict first."""

from __future__ import annotations

import html
import os
import textwrap
from pathlib import Path

import numpy as np
from matplotlib.figure import Figure

from ambseal.analysis import verdict_line
from ambseal.config import Signoff
from ambseal.report.figures import save_figure

__all__ = ["level1_figure", "api617_unbalance_figure", "ucs_map_figure", "signoff_report"]


def level1_figure(path: str | os.PathLike, results, *,
                  title: str = "API 617 Level I screening", boundary=None) -> Path:
    """Log decrement of the screened forward mode against the applied cross-coupling Q, one
    line per controller, with Q_A, each Q_0 and the screening's δ = 0.1 and 0 lines; beside
    it the critical speed ratio against the average gas density with the Region A/B
    boundary (``boundary``: its points, ``[signoff] csr_boundary``).

    Parameters
    ----------
    path : path-like
        The PNG to write.
    results : sequence of ambseal.analysis.signoff.level1.Level1
        One per controller; Q in units of the common Q_A on the axis.
    title : str
        The figure's title.
    boundary : sequence of (float, float), optional
        The Region A/B boundary's points (kg/m³, CSR); default ``[signoff]``'s default.

    Returns
    -------
    Path
        The PNG written.
    """
    fig = Figure(figsize=(11, 4.8))
    ax, ax2 = fig.subplots(1, 2, gridspec_kw={"width_ratios": [3, 2]})
    for r in results:
        d = np.where(np.isfinite(r.log_dec), r.log_dec, np.nan)
        line, = ax.plot(r.Q / r.Q_A, d, "o-", ms=3, lw=1.2,
                        label=f"{r.controller}: {'passed' if r.passed else 'Level II'}")
        if r.Q_0 is not None:
            ax.axvline(r.Q_0 / r.Q_A, color=line.get_color(), ls=":", lw=1.0)
    ax.axvline(1.0, color="k", lw=1.0, label="Q_A (anticipated)")
    ax.axhline(0.1, color="k", ls="--", lw=1.0, label="δ = 0.1")
    ax.axhline(0.0, color="0.4", lw=0.8)
    ax.set_xlabel(f"applied cross-coupling Q / Q_A (Q_A = {results[0].Q_A:.4g} N/m)")
    ax.set_ylabel("log decrement δ of the screened forward mode (-)")
    ax.set_title(title, fontsize=10)
    ax.grid(True, alpha=0.3)
    ax.legend(fontsize=8)
    pts = np.array(boundary if boundary is not None else Signoff().csr_boundary, float)
    r0 = results[0]
    top = max(200.0, 1.5 * float(pts[-1, 0]), 1.5 * r0.rho_avg)
    rho = np.concatenate([[0.0], pts[:, 0], [top]])
    ax2.plot(rho, np.interp(rho, pts[:, 0], pts[:, 1]), "k-", lw=1.2,
             label="Region A/B boundary")
    ax2.plot([r0.rho_avg], [r0.csr], "ro", ms=7,
             label=f"machine: CSR {r0.csr:.3g}, Region {r0.region}")
    ax2.set_xlim(0.0, top)
    ax2.set_ylim(0.0, max(3.0, 1.2 * r0.csr))
    ax2.text(0.05 * top, 0.3, "Region A", fontsize=9)
    ax2.text(0.05 * top, max(3.0, 1.2 * r0.csr) * 0.9, "Region B", fontsize=9)
    ax2.set_xlabel("average gas density ρ_avg (kg/m³)")
    ax2.set_ylabel("critical speed ratio CSR (-)")
    ax2.set_title("critical speed ratio", fontsize=10)
    ax2.grid(True, alpha=0.3)
    ax2.legend(fontsize=8, loc="lower right")
    return save_figure(fig, path, tight=True)


def api617_unbalance_figure(path: str | os.PathLike, results, *,
                     title: str = "API 617 unbalance response") -> Path:
    """The probes' peak-to-peak response against speed: one panel per controller, one
    line per unbalance case (the largest probe), with A_vl, the minimum and maximum
    continuous and the trip speed, and each critical marked in its case's colour. Beside
    each panel its legend: every case's placement whole, wrapped, with the AF and speed of
    each of its criticals (labels on the curves would lie over each other where criticals
    crowd); each panel as tall as its legend needs.

    Parameters
    ----------
    path : path-like
        The PNG to write.
    results : sequence of ambseal.analysis.signoff.unbalance_api617.Api617Unbalance
        One per controller.
    title : str
        The figure's title.

    Returns
    -------
    Path
        The PNG written.
    """
    labels = [[_case_label(i, c) for i, c in enumerate(r.cases)] for r in results]
    # a legend of 7-point text: 8.5 pt a line, 3.5 pt between entries, 8 pt of border;
    # its entries are the cases and A_vl, the speed range and the trip speed (one line
    # each); each row also holds the panel's title and tick labels (0.6 in)
    heights = [max(2.2, (8.5 * (sum(t.count("\n") + 1 for t in ls) + 3)
                         + 3.5 * (len(ls) + 3) + 8.0) / 72.0 + 0.6) for ls in labels]
    fig = Figure(figsize=(13, 1.0 + sum(heights)))
    grid = fig.add_gridspec(len(results), 2, width_ratios=(3.0, 1.25), height_ratios=heights)
    axes = [fig.add_subplot(grid[k, 0]) for k in range(len(results))]
    for k, (ax, r, ls) in enumerate(zip(axes, results, labels)):
        for c, label in zip(r.cases, ls):
            line, = ax.semilogy(c.speed_hz * 60.0, c.probe_um.max(axis=1), lw=1.2,
                                label=label)
            for cr in c.criticals:
                ax.plot(cr.speed_hz * 60.0, cr.amplitude_um, "v", color=line.get_color(),
                        mec="k", mew=0.6, ms=6)
        ax.axhline(r.vibration_limit_um, color="r", ls="--", lw=1.0,
                   label=f"A_vl = {r.vibration_limit_um:.3g} µm p-p")
        ax.axvspan(60.0 * r.min_hz, 60.0 * r.max_hz, color="0.85", alpha=0.6,
                   label="continuous speed range")
        ax.axvline(60.0 * r.trip_hz, color="0.3", ls=":", lw=1.0, label="trip speed")
        ax.set_ylabel("probe response (µm p-p)")
        ax.set_title(f"{r.controller}: {'passed' if r.passed else 'NOT passed'}",
                     fontsize=9)
        ax.grid(True, which="both", alpha=0.3)
        side = fig.add_subplot(grid[k, 1])
        side.axis("off")
        side.legend(*ax.get_legend_handles_labels(), fontsize=7, loc="upper left",
                    borderaxespad=0.0)
    axes[-1].set_xlabel("speed (rpm)")
    fig.suptitle(title, fontsize=10)
    return save_figure(fig, path, tight=True)


#: Characters per line of the unbalance figure's legend entries
LEGEND_WRAP = 56


def _case_label(i: int, case) -> str:
    """A case's legend entry: its number and placement, then each critical's AF and speed
    (rpm), wrapped at :data:`LEGEND_WRAP` characters."""
    text = f"case {i + 1}: {case.placement}"
    if len(case.criticals):
        text += "; AF " + ", ".join(f"{k.af:.3g} at {60.0 * k.speed_hz:.0f} rpm"
                                    for k in case.criticals)
    return textwrap.fill(text, LEGEND_WRAP, subsequent_indent="  ")


def ucs_map_figure(path: str | os.PathLike, ucs, *, speeds_hz=None,
                   title: str = "Undamped critical speed map") -> Path:
    """API 684's undamped critical speed map: the rotor's critical speeds against the
    support stiffness (log–log), each controller's AMBs as curves k_eq(Ω) at 1× (a
    stiffness that is not positive leaves the axis), their undamped criticals marked, and
    the speed range shaded.

    Parameters
    ----------
    path : path-like
        The PNG to write.
    ucs : ambseal.analysis.signoff.ucs_map.UcsMap
        The map.
    speeds_hz : (float, float, float), optional
        (minimum continuous, maximum continuous, trip) speed (Hz), drawn when given.
    title : str
        The figure's title.

    Returns
    -------
    Path
        The PNG written.
    """
    fig = Figure(figsize=(8, 5.6))
    ax = fig.subplots()
    for j, row in enumerate(ucs.critical_hz):
        ax.loglog(ucs.stiffness, 60.0 * row, "k-", lw=1.4 if j == 0 else 1.0,
                  label="rotor's critical speeds" if j == 0 else None)
    styles = ["-", "--", ":", "-."]
    for c, color in zip(ucs.curves, ["C0", "C1", "C2", "C3", "C4", "C5"] * 4):
        for i, (amb, k) in enumerate(zip(c.ambs, c.k_eq)):
            ax.loglog(np.where(k > 0, k, np.nan), 60.0 * ucs.speeds_hz, color=color,
                      ls=styles[i % len(styles)], lw=1.2, label=f"{c.controller}: AMB {amb} "
                      "k_eq at 1×")
        for f in c.criticals_hz:
            ax.axhline(60.0 * f, color=color, lw=0.6, alpha=0.5)
            ax.annotate(f"{60.0 * f:.0f} rpm", (ucs.stiffness[0], 60.0 * f), fontsize=7,
                        color=color, textcoords="offset points", xytext=(2, 2))
    if speeds_hz is not None:
        lo, hi, trip = speeds_hz
        ax.axhspan(60.0 * lo, 60.0 * hi, color="0.85", alpha=0.6,
                   label="continuous speed range")
        ax.axhline(60.0 * trip, color="0.3", ls=":", lw=1.0, label="trip speed")
    ax.set_xlim(ucs.stiffness[0], ucs.stiffness[-1])
    ax.set_xlabel("support stiffness (N/m)")
    ax.set_ylabel("critical speed (rpm)")
    ax.set_title(title, fontsize=10)
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=7, loc="upper left")
    return save_figure(fig, path, tight=True)


def signoff_report(out: Path, results, rig_name: str, boundary=None) -> tuple[list, list]:
    """The run report's sign-off: the figures (``level1.png``, ``api617_unbalance.png`` in
    ``out``) and a section whose first line is the overall verdict, then per controller
    every criterion, its value, its limit, its source and pass/fail, and the Level II
    table.

    Parameters
    ----------
    out : Path
        The folder the figures go to.
    results : sequence of ambseal.analysis.signoff.SignOff
        One per controller.
    rig_name : str
        For the figures' titles.
    boundary : sequence of (float, float), optional
        The rig's ``[signoff] csr_boundary``.

    Returns
    -------
    (figures, sections)
        ``[(caption, png)]`` and ``[{"title", "html"}]`` for
        :func:`ambseal.report.run_report.write_run_report`.
    """
    esc = html.escape
    l1 = level1_figure(out / "level1.png", [r.level1 for r in results],
                       title=f"API 617 Level I — {rig_name}", boundary=boundary)
    # not unbalance.png: the run's worst-case unbalance figure is written there
    unb = api617_unbalance_figure(out / "api617_unbalance.png",
                                  [r.unbalance for r in results],
                                  title=f"API 617 unbalance response — {rig_name}")
    ok = all(r.passed for r in results)
    head = f"<p><b>{esc(verdict_line(results))}</b></p>"
    rows = []
    for r in results:
        for c in r.criteria:
            state = c.outcome
            rows.append(f"<tr><td>{esc(r.controller)}</td><td>{esc(c.name)}</td>"
                        f"<td class=\"text\">{esc(c.value)}</td><td class=\"text\">"
                        f"{esc(c.limit)}</td><td class=\"text\">{esc(c.source)}</td>"
                        f"<td>{state}</td></tr>")
    table = ("<table><tr><th>controller</th><th>criterion</th><th>value</th><th>limit</th>"
             "<th>source</th><th>outcome</th></tr>" + "".join(rows) + "</table>")
    l2 = "".join(
        f"<tr><td>{esc(r.controller)}</td><td>{esc(row.component)}</td>"
        f"<td>{row.frequency_hz:.4g}</td><td class=\"text\">{esc(row.kind)}</td>"
        f"<td>{row.log_dec:.3g}</td><td>{'yes' if row.stable else 'NO'}</td></tr>"
        for r in results for row in r.level2.rows)
    level2 = ("<p>API 617 Level II at the maximum continuous speed, component by "
              "component: the first forward resonant mode (AF ≥ 2.5), or the one the "
              "sources act on:</p><table><tr><th>controller</th>"
              "<th>loop with</th><th>f (Hz)</th><th>mode</th><th>δ</th><th>stable</th>"
              "</tr>" + l2 + "</table>")
    rule = results[0].unbalance.journal_load_rule if results else ""
    note = ("<p>Each controller as it runs (the discrete controller with its delay). "
            "Limits the standards' public text could not confirm are the rig file's "
            "<code>[signoff]</code> settings."
            + (f" The journal static loads W of U_r = 6350·W/N: {esc(rule)}." if rule
               else "") + "</p>")
    figures = [("API 617 Level I: log decrement of the screened forward mode against the "
                "applied cross-coupling Q/Q_A, per controller; the critical speed ratio "
                "against the average gas density with the Region A/B boundary", l1),
               ("API 617 unbalance response at the probes, per controller and case, with "
                "A_vl and the speed range", unb)]
    title = "Sign-off: API 617 and ISO 14839-2" + ("" if ok else " — NOT passed")
    return figures, [{"title": title, "html": head + table + level2 + note}]
