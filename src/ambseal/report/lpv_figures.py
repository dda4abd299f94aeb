"""Figures of the speed-scheduled (LPV) design: spin-up responses (P3 Fig. 11) and σ̄(S_o)
at frozen speeds with the ISO 14839-3 line at 3 (P3 Fig. 12).

Matplotlib ``Figure`` objects on the Agg canvas only (no pyplot), written with
:func:`ambseal.report.figures.save_figure`. The functions take result objects of
:mod:`ambseal.analysis.spinup` (duck-typed: only their arrays are read).
"""

from __future__ import annotations

import os
from pathlib import Path
from typing import Mapping, Sequence

import numpy as np
from matplotlib.figure import Figure

from ambseal.analysis import ZONE_LIMITS, zone_limit_db
from ambseal.report.figures import save_figure

__all__ = ["spinup_figure", "frozen_sensitivity_figure"]


def spinup_figure(path: str | os.PathLike, results: Sequence, *, channel: int = 0,
                  title: str = "Spin-up 20 → 300 Hz: alternating 100 N / 2 µm steps on A_x",
                  colours: Mapping[str, str] | None = None) -> Path:
    """Measured A_x displacement (µm) and current (A) against time for each controller.

    Parameters
    ----------
    path : path-like
        PNG file to write.
    results : sequence of SpinupResult
        One per controller (``t_s``, ``y_m``, ``current_a``, ``speed_hz``, ``name``).
    channel : int
        Measurement/current channel shown.
    colours : mapping, optional
        Controller name → colour (the report's one colour per controller).

    Returns
    -------
    pathlib.Path
    """
    fig = Figure(figsize=(9, 6))
    ax1, ax2 = fig.subplots(2, 1, sharex=True)
    for r in results:
        c = (colours or {}).get(r.name)
        ax1.plot(r.t_s * 1e3, r.y_m[:, channel] * 1e6, lw=0.8, label=r.name, color=c)
        ax2.plot(r.t_s * 1e3, r.current_a[:, channel], lw=0.8, label=r.name, color=c)
    ax1.set_ylabel("y A_x (µm)")
    ax2.set_ylabel("i A_x (A)")
    ax2.set_xlabel("Time (ms)")
    if results:
        sp = results[0].speed_hz
        top = ax1.secondary_xaxis("top", functions=(
            lambda t: np.interp(t, results[0].t_s * 1e3, sp),
            lambda f: np.interp(f, sp, results[0].t_s * 1e3)))
        top.set_xlabel("Speed (Hz)")
        ax1.legend(fontsize=8)
    for ax in (ax1, ax2):
        ax.grid(True, alpha=0.3)
    ax1.set_title(title, fontsize=10)
    return save_figure(fig, path, tight=True)


def frozen_sensitivity_figure(path: str | os.PathLike, results: Sequence, *,
                              speeds_hz: Sequence[float] | None = None,
                              title: str = "σ̄(S_o) at frozen speeds (full-order plant)"
                              ) -> Path:
    """σ̄(S_o) against frequency at several speeds, one panel per controller, with the
    ISO 14839-3 zone A/B line at 3.

    Parameters
    ----------
    path : path-like
    results : sequence of FrozenSensitivity
        ``name``, ``speeds_hz``, ``frequency_hz``, ``sigma`` (n_s, n_w).
    speeds_hz : sequence of float, optional
        Speeds drawn (nearest computed ones); default at most 6 spread over the range.

    Returns
    -------
    pathlib.Path
    """

    n = max(len(results), 1)
    fig = Figure(figsize=(5 * n, 4.2))
    axes = np.atleast_1d(fig.subplots(1, n, sharey=True))
    for ax, r in zip(axes, results):
        fs = np.asarray(r.speeds_hz)
        idx = (np.unique(np.linspace(0, fs.size - 1, min(6, fs.size)).round().astype(int))
               if speeds_hz is None else
               np.unique([int(np.argmin(np.abs(fs - f))) for f in speeds_hz]))
        for i in idx:
            ax.loglog(r.frequency_hz, r.sigma[i], lw=0.9, label=f"{fs[i]:.0f} Hz")
        ax.axhline(ZONE_LIMITS[0], color="k", ls="--", lw=0.8)
        ax.text(0.01, 1.03 * ZONE_LIMITS[0],
                f"ISO 14839-3 A/B: {ZONE_LIMITS[0]:g} ({zone_limit_db()[0]:.1f} dB)",
                transform=ax.get_yaxis_transform(), fontsize=8)
        ax.set_title(f"{r.name}: peak {np.max(r.peak):.2f}", fontsize=10)
        ax.set_xlabel("Frequency (Hz)")
        ax.grid(True, which="both", alpha=0.3)
        ax.legend(fontsize=7)
    axes[0].set_ylabel("σ̄(S_o) (–, absolute gain)")
    fig.suptitle(title, fontsize=10)
    return save_figure(fig, path, tight=True)
