"""The rotor drop as an engineer reads it: at each touchdown plane the journal's orbit in
its clearance circle, and the contact force against time (:func:`drop_figure`); the
whirl's full spectrum against time at each plane — its waterfall, forward whirl above
zero, backward below — and the rings' and the rotor's speeds (:func:`drop_whirl_figure`).
Matplotlib, Agg canvas, written through :func:`ambseal.report.figures.save_figure`."""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np
from matplotlib.figure import Figure
from scipy.signal import spectrogram

from ambseal.report.figures import save_figure

__all__ = ["drop_figure", "drop_whirl_figure", "whirl_waterfall", "drop_current_figure"]

#: the share of the waterfall's energy inside the frequency band shown
SHOWN_ENERGY = 0.995


def _plane_title(result, p: int) -> str:
    """A plane's name, regime and whirl frequency."""
    regime, hz = result.regime(p)
    return f"{result.names[p]}: {regime}" + (f", {hz:.3g} Hz" if regime.endswith("whirl")
                                              else "")


def drop_figure(path: str | os.PathLike, result, clearances_m, *,
                title: str = "Rotor drop") -> Path:
    """Per touchdown plane its orbit (µm) inside the clearance circle, and the normal
    contact force (kN) of every plane against time (ms), its axial force dashed where it
    stopped the rotor axially.

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
    for p, ax in enumerate(axes[:-1]):
        c = 1e6 * clearances_m[p]
        ax.plot(c * np.cos(ring), c * np.sin(ring), "k-", lw=1.0, label="clearance")
        ax.plot(1e6 * result.orbit[p, :, 0], 1e6 * result.orbit[p, :, 1], lw=0.7,
                label="journal centre")
        ax.set_title(_plane_title(result, p), fontsize=9)
        ax.set_aspect("equal")
        lim = 1.2 * max(c, 1e6 * np.hypot(*result.orbit[p].T).max())
        ax.set_xlim(-lim, lim)
        ax.set_ylim(-lim, lim)
        ax.set_xlabel("x (µm)")
        ax.set_ylabel("y (µm)")
        ax.grid(alpha=0.3)
    ax = axes[-1]
    for p, name in enumerate(result.names):
        line, = ax.plot(1e3 * result.t, 1e-3 * result.force[p], lw=0.8, label=name)
        if result.axial_position is not None and result.axial_force[p].any():
            ax.plot(1e3 * result.t, 1e-3 * result.axial_force[p], lw=0.8, ls="--",
                    color=line.get_color(), label=f"{name} axial")
    ax.set_xlabel("time after the event (ms)")
    ax.set_ylabel("contact force (kN)")
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8)
    fig.suptitle(f"{title} at {60 * result.speed_rad_s / (2 * np.pi):.6g} rpm "
                 f"({result.n_modes} modes up to {result.modes_hz:.4g} Hz)", fontsize=10)
    return save_figure(fig, path)


def whirl_waterfall(t, orbit) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The full spectrum of an orbit against time: the magnitude of the spectrogram of
    x + j·y (Hann windows of an eighth of the record, 3/4 overlapping, each window's mean
    taken out, :func:`scipy.signal.spectrogram`), forward whirl at positive frequencies.

    Parameters
    ----------
    t : ndarray, shape (k,)
        Evenly spaced times (s).
    orbit : ndarray, shape (k, 2)
        x, y (m).

    Returns
    -------
    times : ndarray, shape (w,)
        The windows' centres (s).
    frequency_hz : ndarray, shape (f,)
        Ascending, negative (backward whirl) to positive (forward).
    amplitude_um : ndarray, shape (f, w)
        The whirl's amplitude (µm) at each frequency and time.
    """
    t = np.asarray(t, float)
    fs = (t.size - 1) / (t[-1] - t[0])
    seg = max(16, t.size // 8)
    z = orbit[:, 0] + 1j * orbit[:, 1]
    f, tw, S = spectrogram(z, fs=fs, window="hann", nperseg=seg, noverlap=3 * seg // 4,
                           detrend="constant", return_onesided=False, scaling="spectrum",
                           mode="magnitude")
    order = np.argsort(f)
    return tw + t[0], f[order], 1e6 * S[order]


def drop_whirl_figure(path: str | os.PathLike, result, *,
                      title: str = "Rotor drop: whirl") -> Path:
    """Per touchdown plane the full spectrum of its orbit against time
    (:func:`whirl_waterfall`), forward whirl at positive frequencies, backward at negative,
    the spin's frequency dashed; the band shown holds :data:`SHOWN_ENERGY` of it, at least
    ±1.5 × the spin. Beside them the rings' and the rotor's speeds (rpm) against time.

    Parameters
    ----------
    path : path-like
        The PNG to write.
    result : ambseal.analysis.drop.DropResult
        The simulated drop (evenly sampled).
    title : str
        The figure's title.

    Returns
    -------
    Path
        The PNG written.
    """
    n = len(result.names)
    fig = Figure(figsize=(4.6 * n + 5, 4.6), layout="constrained")
    axes = fig.subplots(1, n + 1, gridspec_kw={"width_ratios": [1] * n + [1.3]})
    spin_hz = float(np.abs(result.spin).max()) / (2 * np.pi)
    for p, ax in enumerate(axes[:-1]):
        t, f, S = whirl_waterfall(result.t, result.orbit[p])
        energy = (S ** 2).sum(axis=1)
        # the band round zero holding SHOWN_ENERGY of the energy, at least 1.5 × the spin
        span = np.abs(f)
        cum = np.array([energy[span <= a].sum() for a in np.unique(span)])
        inside = np.unique(span)[np.searchsorted(cum, SHOWN_ENERGY * energy.sum())
                                 .clip(max=cum.size - 1)]
        lim = max(float(inside), 1.5 * spin_hz, 10.0)
        mesh = ax.pcolormesh(1e3 * t, f, S, shading="nearest", cmap="viridis")
        fig.colorbar(mesh, ax=ax, label="orbit amplitude (µm)", fraction=0.06, pad=0.02)
        if spin_hz > 0:
            ax.axhline(spin_hz, color="w", ls="--", lw=0.8)
        ax.axhline(0.0, color="w", lw=0.4)
        ax.set_ylim(-lim, lim)
        ax.set_title(_plane_title(result, p), fontsize=9)
        ax.set_xlabel("time after the event (ms)")
        ax.set_ylabel("whirl frequency (Hz; backward < 0)")
    ax = axes[-1]
    rpm = 60.0 / (2 * np.pi)
    ax.plot(1e3 * result.t, rpm * result.spin, "k-", lw=1.0, label="rotor")
    for p, name in enumerate(result.names):
        if result.turning[p]:
            ax.plot(1e3 * result.t, rpm * result.race_speed[p], lw=0.8, label=f"ring {name}")
    ax.set_xlabel("time after the event (ms)")
    ax.set_ylabel("speed (rpm)")
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8)
    fig.suptitle(f"{title} at {rpm * result.speed_rad_s:.6g} rpm", fontsize=10)
    return save_figure(fig, path)


def drop_current_figure(path: str | os.PathLike, result, *,
                        title: str = "Rotor drop: AMB currents") -> Path:
    """Each AMB axis's coil current (A) against time: driven by its loop (solid) or
    decaying once its power was lost (dotted), each limit ±i_max dashed.

    Parameters
    ----------
    path : path-like
        The PNG to write.
    result : ambseal.analysis.drop.DropResult
        The simulated drop, with its ``channels`` and ``amb_current``.
    title : str
        The figure's title.

    Returns
    -------
    Path
        The PNG written.
    """
    fig = Figure(figsize=(8, 4.2), layout="constrained")
    ax = fig.subplots()
    limits = set()
    for name, i, lim in zip(result.channels, result.amb_current, result.current_limit):
        lost = name in result.failed
        ax.plot(1e3 * result.t, i, ls=":" if lost else "-", lw=1.0,
                label=f"{name} (lost)" if lost else name)
        if np.isfinite(lim):
            limits.add(float(lim))
    for lim in sorted(limits):
        for sign in (1, -1):
            ax.axhline(sign * lim, color="k", ls="--", lw=0.7)
    ax.set_xlabel("time after the event (ms)")
    ax.set_ylabel("coil current i_s + i (A)")
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8, ncol=2)
    ax.set_title(title, fontsize=10)
    return save_figure(fig, path)
