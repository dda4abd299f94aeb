"""The rotor drop as an engineer reads it: at each touchdown plane the journal's orbit in
its clearance circle, and the contact force against time (matplotlib, Agg canvas, written
through :func:`ambseal.report.figures.save_figure`)."""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np
from matplotlib.figure import Figure

from ambseal.report.figures import save_figure

__all__ = ["drop_figure"]


def drop_figure(path: str | os.PathLike, result, clearances_m, *,
                title: str = "Rotor drop") -> Path:
    """Per touchdown plane its orbit (µm) inside the clearance circle, and the normal
    contact force (kN) of every plane against time (ms).

    Parameters
    ----------
    path : path-like
        The PNG to write.
    result : ambseal.analysis.drop.DropResult
        The simulated drop.
    clearances_m : sequence of float
        Each plane's radial clearance (m), in the result's order.
    title : str
        The figure's title.

    Returns
    -------
    Path
        The PNG written.
    """
    n = len(result.names)
    fig = Figure(figsize=(4 * n + 5, 4.4))
    axes = fig.subplots(1, n + 1, gridspec_kw={"width_ratios": [1] * n + [1.6]})
    ring = np.linspace(0, 2 * np.pi, 361)
    for p, (ax, name) in enumerate(zip(axes[:-1], result.names)):
        c = 1e6 * clearances_m[p]
        ax.plot(c * np.cos(ring), c * np.sin(ring), "k-", lw=1.0, label="clearance")
        ax.plot(1e6 * result.orbit[p, :, 0], 1e6 * result.orbit[p, :, 1], lw=0.7,
                label="journal centre")
        regime, hz = result.regime(p)
        ax.set_title(f"{name}: {regime}" + (f", {hz:.3g} Hz" if regime.endswith("whirl")
                                            else ""), fontsize=9)
        ax.set_aspect("equal")
        lim = 1.2 * max(c, 1e6 * np.hypot(*result.orbit[p].T).max())
        ax.set_xlim(-lim, lim)
        ax.set_ylim(-lim, lim)
        ax.set_xlabel("x (µm)")
        ax.set_ylabel("y (µm)")
        ax.grid(alpha=0.3)
    ax = axes[-1]
    for p, name in enumerate(result.names):
        ax.plot(1e3 * result.t, 1e-3 * result.force[p], lw=0.8, label=name)
    ax.set_xlabel("time after the AMBs let go (ms)")
    ax.set_ylabel("contact force (kN)")
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8)
    fig.suptitle(f"{title} at {60 * result.speed_rad_s / (2 * np.pi):.6g} rpm "
                 f"({result.n_modes} modes up to {result.modes_hz:.4g} Hz)", fontsize=10)
    return save_figure(fig, path)
