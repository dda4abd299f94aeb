"""Figures of a machine's sign-off: API 617's Level I screening (matplotlib, Agg canvas,
written through :func:`ambseal.report.figures.save_figure`)."""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np
from matplotlib.figure import Figure

from ambseal.report.figures import save_figure

__all__ = ["level1_figure"]


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
