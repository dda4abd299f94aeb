"""PNG figure of on-line parameter tracking (matplotlib, Agg canvas only; house rules of
:mod:`ambseal.report.figures`)."""

from __future__ import annotations

import os
from pathlib import Path
from typing import Sequence

import numpy as np
from matplotlib.figure import Figure

from ambseal.report.figures import save_figure

__all__ = ["tracking_figure"]


def tracking_figure(path: str | os.PathLike, time_s: Sequence[float], names: Sequence[str],
                    estimate: np.ndarray, low: np.ndarray, high: np.ndarray, *,
                    reference: np.ndarray | None = None, reference_label: str = "truth",
                    units: Sequence[str] | None = None,
                    title: str = "Tracked parameters") -> Path:
    """The estimate of each parameter (SI) over time with its 95 % interval as a band, and
    an optional reference (e.g. the facility's true value), one panel per parameter.

    Parameters
    ----------
    time_s : (N,)
    estimate, low, high : (N, p)
    reference : (N, p), optional
    units : sequence of str, optional
        The SI unit of each parameter, for the axis labels.

    The vertical range follows the estimate after its first 5 % (the initial transient
    from the starting value is drawn but does not set the scale).
    """
    t = np.asarray(time_s, float)
    est, lo, hi = (np.asarray(a, float) for a in (estimate, low, high))
    p = est.shape[1]
    step = max(1, len(t) // 4000)  # a few thousand points per curve are enough to see
    fig = Figure(figsize=(10, 2.4 * p + 0.6), layout="constrained")
    axes = fig.subplots(p, 1, sharex=True, squeeze=False)[:, 0]
    for j, ax in enumerate(axes):
        ax.fill_between(t[::step], lo[::step, j], hi[::step, j], alpha=0.3, lw=0,
                        label="95 % interval")
        ax.plot(t[::step], est[::step, j], lw=0.9, label="estimate")
        if reference is not None:
            ax.plot(t[::step], np.asarray(reference, float)[::step, j], "k--", lw=0.9,
                    label=reference_label)
        ax.set_title(names[j], fontsize=9)
        ax.set_ylabel(units[j] if units else "SI")
        tail = slice(len(t) // 20, None)
        a, b = float(np.min(lo[tail, j])), float(np.max(hi[tail, j]))
        if np.isfinite(a) and np.isfinite(b) and b > a:
            ax.set_ylim(a - 0.1 * (b - a), b + 0.1 * (b - a))
        ax.grid(alpha=0.3)
    axes[0].legend(fontsize=8, loc="best")
    axes[-1].set_xlabel("Time (s)")
    fig.suptitle(title)
    return save_figure(fig, path)
