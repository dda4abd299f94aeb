"""A machine's sign-off in the report: API 617's Level I screening as a figure (matplotlib,
Agg canvas, written through :func:`ambseal.report.figures.save_figure`) and a section."""

from __future__ import annotations

import html
import os
from pathlib import Path

import numpy as np
from matplotlib.figure import Figure

from ambseal.report.figures import save_figure

__all__ = ["level1_figure", "signoff_report"]


def level1_figure(path: str | os.PathLike, results, *,
                  title: str = "API 617 Level I screening") -> Path:
    """Log decrement of the screened forward mode against the applied cross-coupling Q, one
    line per controller, with Q_A, each Q_0 and the screening's δ = 0.1 and 0 lines.

    Parameters
    ----------
    path : path-like
        The PNG to write.
    results : sequence of ambseal.analysis.level1.Level1
        One per controller; Q in units of the common Q_A on the axis.
    title : str
        The figure's title.

    Returns
    -------
    Path
        The PNG written.
    """
    fig = Figure(figsize=(8, 4.8))
    ax = fig.subplots()
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
    return save_figure(fig, path, tight=True)


def signoff_report(out: Path, results, rig_name: str) -> tuple[list, list]:
    """The run report's sign-off: the Level I figure (``level1.png`` in ``out``) and a
    section whose first line is the overall verdict, then per controller each criterion,
    its value, its limit and the rule that decided.

    Parameters
    ----------
    out : Path
        The run's folder.
    results : sequence of ambseal.analysis.level1.Level1
        One per delivered controller.
    rig_name : str
        For the figure's title.

    Returns
    -------
    (figures, sections)
        ``[(caption, png)]`` and ``[{"title", "html"}]`` for
        :func:`ambseal.report.run_report.write_run_report`.
    """
    png = level1_figure(out / "level1.png", results, title=f"API 617 Level I — {rig_name}")
    ok = all(r.passed for r in results)
    head = ("<p><b>API 617 Level I: passed by every controller</b> — no Level II analysis "
            "required.</p>" if ok else
            "<p><b>API 617 Level I: NOT passed</b> — " + html.escape(", ".join(
                r.controller for r in results if not r.passed)) + " require(s) Level II.</p>")
    rows = []
    for r in results:
        q0 = f"{r.Q_0:.4g}" if r.Q_0 is not None else f"&gt; {r.Q[-1]:.4g}"
        rows.append(
            f"<tr><td>{html.escape(r.controller)}</td><td>{r.Q_A:.4g}</td>"
            f"<td>{r.log_dec_A:.3g} (≥ 0.1)</td><td>{q0}</td>"
            f"<td>{r.ratio:.3g} (≥ 2; ≥ 10 passes)</td><td>{r.csr:.3g}</td>"
            f"<td>{'passed' if r.passed else 'Level II'}</td>"
            f"<td class=\"text\">{html.escape(r.rule)}</td></tr>")
    table = ("<table><tr><th>controller</th><th>Q_A (N/m)</th><th>δ_A</th>"
             "<th>Q_0 (N/m)</th><th>Q_0/Q_A</th><th>CSR</th><th>outcome</th>"
             "<th>rule</th></tr>" + "".join(rows) + "</table>")
    note = ("<p>API 617 (8th ed., 2014) Level I: anticipated cross-coupling Q_A from the "
            "rig's stages, applied cross-coupling swept to 10·Q_A at the maximum "
            "continuous speed with the seals left out, each controller as it runs. The "
            "critical speed ratio's Region A/B is not evaluated: 2 ≤ Q_0/Q_A &lt; 10 "
            "requires Level II.</p>")
    caption = ("API 617 Level I: log decrement of the screened forward mode against the "
               "applied cross-coupling Q/Q_A, per controller")
    return [(caption, png)], [{"title": "Sign-off: API 617 Level I stability",
                               "html": head + note + table}]
