"""PNG figure of on-line parameter tracking (matplotlib, Agg canvas only; house rules of
:mod:`ambseal.report.figures`)."""

from __future__ import annotations

import os
from pathlib import Path
from typing import Sequence

import numpy as np
from matplotlib.figure import Figure

from ambseal.report.figures import controller_colours, save_figure

__all__ = ["tracking_figure", "ramp_figure"]


def tracking_figure(path: str | os.PathLike, time_s: Sequence[float], names: Sequence[str],
                    estimate: np.ndarray, low: np.ndarray, high: np.ndarray, *,
                    reference: np.ndarray | None = None, reference_label: str = "truth",
                    units: Sequence[str] | None = None,
                    title: str = "Tracked parameters") -> Path:
    """The estimate of each parameter (SI) over time with its 95 % interval as a band, and
    an optional reference (e.g. the facility's true value), one panel per parameter.

    The vertical range follows the estimate after its first 5 % (the initial transient
    from the starting value is drawn but does not set the scale).

    Parameters
    ----------
    path : str or os.PathLike
        The PNG to write.
    time_s : sequence of float, shape (N,)
        Times (s).
    names : sequence of str
        The ``p`` parameters.
    estimate, low, high : numpy.ndarray, shape (N, p)
        The estimate and its 95 % interval (SI).
    reference : numpy.ndarray, shape (N, p), optional
        A reference value of each parameter (SI).
    reference_label : str, optional
        The reference's legend label.
    units : sequence of str, optional
        The SI unit of each parameter, for the axis labels.
    title : str, optional
        The figure's title.

    Returns
    -------
    Path
        The PNG written.
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


def ramp_figure(path: str | os.PathLike, ramp, *, axis: int = 0) -> Path:
    """The closed-loop pressure ramp (:func:`ambseal.analysis.ramp.ramp_simulation`): the
    true and the estimated seal coefficient with its 95 % interval and the pressure drop;
    the displacement and the current reference on the impulse axis for every controller
    (a loss of the rotor marked ×); the impulse peaks along the ramp with their settling
    times written next to them.

    Parameters
    ----------
    path : str or os.PathLike
        The PNG to write.
    ramp : RampResult
        The ramp's runs.
    axis : int, optional
        The actuator axis drawn (index into the rig's axes).

    Returns
    -------
    Path
        The PNG written.
    """
    t = np.asarray(ramp.time_s, float)
    names = list(ramp.runs)
    col = controller_colours(names)
    fig = Figure(figsize=(10, 11), layout="constrained")
    ax_k, ax_y, ax_i, ax_p = fig.subplots(4, 1, sharex=True)
    ax_k.plot(t, ramp.k_true / 1e6, "k--", lw=1.0, label=f"true {ramp.parameter}")
    tr = ramp.runs.get("tracked")
    if tr is not None and tr.estimate is not None:
        ax_k.fill_between(t, tr.ci95_low / 1e6, tr.ci95_high / 1e6, color=col["tracked"],
                          alpha=0.25, lw=0, label="95 % interval")
        ax_k.plot(t, tr.estimate / 1e6, color=col["tracked"], lw=0.9, label="estimate")
        top = 1.3 * float(np.nanmax(np.abs(ramp.k_true))) / 1e6
        ax_k.set_ylim(-0.2 * top, top)
    ax_k.set_ylabel(f"{ramp.parameter} (MN/m)")
    twin = ax_k.twinx()
    twin.plot(t, ramp.pressure_bar, color="0.6", lw=0.8)
    twin.set_ylabel("pressure drop (bar)", color="0.4")
    ax_k.legend(fontsize=8, loc="upper left")
    for n, r in ramp.runs.items():
        ax_y.plot(t, r.displacement_um[:, axis], color=col[n], lw=0.5, label=n)
        ax_i.plot(t, r.current_a[:, axis], color=col[n], lw=0.5, label=n)
        if r.lost_at_s is not None:
            ax_y.axvline(r.lost_at_s, color=col[n], ls=":", lw=1.0)
            ax_y.plot([r.lost_at_s], [0.0], "x", color=col[n], ms=9, mew=2)
        seen = r.impulse_above_background or [True] * len(r.impulse_peak_um)
        pk = [(ti, v, s_ if ok else "n/a") for ti, v, s_, ok in zip(
            ramp.impulse_times_s, r.impulse_peak_um, r.impulse_settling_s, seen)
            if v is not None]
        if pk:
            ax_p.plot([a for a, _, _ in pk], [b for _, b, _ in pk], "o-", color=col[n],
                      ms=4, lw=0.8, label=n)
            for a, b, c in pk[::max(1, len(pk) // 5)]:
                ax_p.annotate(c if isinstance(c, str) else "—" if c is None
                              else f"{1e3 * c:.0f} ms", (a, b), fontsize=6,
                              color=col[n], xytext=(2, 3), textcoords="offset points")
    ax_y.set_ylabel(f"y {ramp.axes[axis]} (µm)")
    ax_i.set_ylabel(f"i_ref {ramp.axes[axis]} (A)")
    ax_p.set_ylabel("impulse peak (µm)")
    ax_p.set_xlabel("Time (s)")
    for ax in (ax_y, ax_i, ax_p):
        if ax.get_legend_handles_labels()[0]:
            ax.legend(fontsize=8, loc="upper left", ncol=len(names))
        ax.grid(alpha=0.3)
    ax_k.grid(alpha=0.3)
    fig.suptitle(f"Pressure ramp 0 → {float(np.max(ramp.pressure_bar)):.3g} bar: "
                 "fixed controllers and the tracked scheme (× = rotor lost)")
    return save_figure(fig, path)
