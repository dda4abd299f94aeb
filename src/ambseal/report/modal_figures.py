"""Figures of the closed-loop modal analyses and of the sweeps: the Campbell diagram with log
decrements, the mode shapes, and stability maps over pressure × speed (matplotlib, Agg
canvas, written through :func:`ambseal.report.figures.save_figure`).

Each function takes a result of :mod:`ambseal.analysis.campbell` or the rows of
:mod:`ambseal.analysis.sweep` and a path, and returns the path.
"""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np
from matplotlib.colors import TwoSlopeNorm
from matplotlib.figure import Figure

from ambseal.analysis import AF_CRITICAL, OVERDAMPED_ZETA
from ambseal.report.figures import save_figure

__all__ = ["campbell_figure", "mode_shapes_figure", "stability_map_figure"]

_WHIRL_STYLE = {"forward": ("tab:red", "^"), "backward": ("tab:blue", "v"),
                "mixed": ("tab:purple", "d"), "planar": ("tab:gray", "o")}


def campbell_figure(path: str | os.PathLike, c, *, title: str = "Closed-loop Campbell diagram"
                    ) -> Path:
    """Damped natural frequency and log decrement of every closed-loop mode against speed.

    Top: the frequencies of the modes with a resonance (ζ < 1/√2,
    :data:`~ambseal.analysis.campbell.OVERDAMPED_ZETA`; markers by whirl: ▲ forward,
    ▼ backward, ◆ mixed, ● planar, faint where the mode is too well damped to be a critical
    speed, AF = π/δ < 2.5 as API 684 counts them; a black ring on modes below the
    log-decrement limit), their lines, the 1× line and the crossings (×, bold where API 684
    counts them critical). A controller's or an eddy-current pole damped at ζ ≥ 1/√2 has no
    resonance to meet the 1× line and is left out there. Bottom: the log decrements of every
    mode with the limit (API 684: 0.1), a black ring on each below it (those above the
    frequency panel's range are ringed here only).

    Parameters
    ----------
    path : path-like
        The PNG to write.
    c : ambseal.analysis.campbell.Campbell
        The Campbell diagram's data.
    title : str
        The figure's title.

    Returns
    -------
    Path
        The PNG written.
    """
    fig = Figure(figsize=(8, 7.5))
    ax, axd = fig.subplots(2, 1, sharex=True, gridspec_kw={"height_ratios": [3, 2]})
    s = c.speeds_hz
    for j in range(c.tracks.shape[1]):
        f = c.line(j)
        ax.plot(s, np.where(c.line(j, "damping_ratio") < OVERDAMPED_ZETA, f, np.nan),
                color="0.75", lw=0.8, zorder=1)
        d = c.line(j, "log_decrement")
        axd.plot(s, np.clip(d, -1.0, 10.0), color="0.75", lw=0.8, zorder=1)
    sharp_delta = np.pi / AF_CRITICAL  # δ at AF = 2.5
    for whirl, (col, mk) in _WHIRL_STYLE.items():
        xs, fs, ds, zs = [], [], [], []
        for p in c.points:
            sel = [k for k, w in enumerate(p.whirl) if w == whirl]
            xs += [p.speed_hz] * len(sel)
            fs += list(p.frequency_hz[sel])
            ds += list(p.log_decrement[sel])
            zs += list(p.damping_ratio[sel])
        if not xs:
            continue
        xs, fs, ds, zs = map(np.asarray, (xs, fs, ds, zs))
        sharp = ds <= sharp_delta
        damped = ~sharp & (zs < OVERDAMPED_ZETA)
        if np.any(sharp):
            ax.scatter(xs[sharp], fs[sharp], s=14, color=col, marker=mk, label=whirl,
                       zorder=3)
        if np.any(damped):
            ax.scatter(xs[damped], fs[damped], s=10, color=col, marker=mk, alpha=0.25,
                       zorder=2, label=None if np.any(sharp) else whirl)
        axd.scatter(xs, np.clip(ds, -1.0, 10.0), s=14, color=col, marker=mk, zorder=3)
    # up to the first resonant mode above the speed range (the modes that can meet 1× and
    # the next)
    f_all = np.concatenate([p.frequency_hz[p.damping_ratio < OVERDAMPED_ZETA]
                            for p in c.points])
    above = f_all[f_all > s.max()]
    top = max(float(s.max()), float(above.min()) if above.size else float(f_all.max(initial=1.0)))
    low = c.flagged()
    ring = {"s": 60, "facecolors": "none", "edgecolors": "k", "lw": 1.0, "zorder": 4,
            "label": f"log dec < {c.log_dec_limit:g}"}
    shown = [r for r in low if r["frequency_hz"] <= 1.15 * top]
    if shown:  # (a ring in the legend only where one is drawn in this panel)
        ax.scatter([r["speed_hz"] for r in shown], [r["frequency_hz"] for r in shown], **ring)
    if low:
        axd.scatter([r["speed_hz"] for r in low],
                    np.clip([r["log_decrement"] for r in low], -1.0, 10.0), **ring)
        axd.legend(fontsize=8, loc="upper left")
    ax.plot(s, s, "k--", lw=1.0, label="1× (synchronous)")
    for x in c.crossings:  # API 684 critical (AF ≥ 2.5) bold, the others small
        ax.plot(x.speed_hz, x.speed_hz, "x", color="k" if x.critical else "0.5",
                ms=9 if x.critical else 5, mew=2 if x.critical else 1, zorder=5)
    if c.crossings:
        ax.plot([], [], "x", color="k", ms=7, mew=1.5,
                label=f"1× crossing (bold: critical, AF ≥ {AF_CRITICAL:g})")
    if any(np.any((p.log_decrement > sharp_delta) & (p.damping_ratio < OVERDAMPED_ZETA))
           for p in c.points):
        ax.scatter([], [], s=10, color="0.3", alpha=0.25,
                   label=f"faint: AF < {AF_CRITICAL:g}, no critical speed")
    ax.set_ylim(0, 1.15 * top)
    if np.any(f_all > 1.15 * top):
        title += (f"\n(modes to {max(p.max_hz for p in c.points):.0f} Hz in the δ panel; "
                  f"above {1.15 * top:.0f} Hz not drawn here)")
    ax.set_ylabel("damped natural frequency (Hz)")
    ax.set_title(title, fontsize=10)
    ax.grid(True, alpha=0.3)
    ax.legend(fontsize=8, loc="upper left")
    axd.axhline(c.log_dec_limit, color="k", ls="--", lw=1.0)
    axd.set_yscale("symlog", linthresh=0.01)
    axd.set_xlabel("speed (Hz)")
    axd.set_ylabel("log decrement δ (-)")
    axd.grid(True, alpha=0.3)
    return save_figure(fig, path, tight=True)


def mode_shapes_figure(path: str | os.PathLike, m, positions: dict[str, list[float]], *,
                       n_modes: int = 8, title: str = "Closed-loop mode shapes") -> Path:
    """The lowest resonant modes' shapes along the shaft with the positions of AMBs, sensors,
    seals and disks: x and y at the phase of the largest amplitude, and the orbit size
    √(|X|² + |Y|²) shaded (normalised to 1).

    Modes with ζ ≥ 1/√2 (no resonance peak) are left out.

    Parameters
    ----------
    path : path-like
        The PNG to write.
    m : ambseal.analysis.campbell.ClosedLoopModes
        The closed-loop modes with their shapes.
    positions : dict
        ``{"AMB": [z, ...], "sensor": [...], "seal": [...], "disk": [...]}`` (m).
    n_modes : int
        Modes drawn (the lowest; one panel each).
    title : str
        The figure's title.

    Returns
    -------
    Path
        The PNG written.
    """
    idx = [i for i, z in enumerate(m.damping_ratio) if z < 2**-0.5][:n_modes]
    k = len(idx)
    cols = 2
    rows = max(1, (k + 1) // 2)
    fig = Figure(figsize=(9, 2.1 * rows + 0.6))
    axes = np.atleast_1d(fig.subplots(rows, cols, sharex=True)).ravel()
    z = m.node_z_m
    marks = {"AMB": ("tab:green", "-"), "sensor": ("tab:olive", ":"),
             "seal": ("tab:red", "-."), "disk": ("0.5", "--")}
    for i, ax in enumerate(axes):
        if i >= k:
            ax.set_visible(False)
            continue
        mode = idx[i]
        sh = m.shapes[mode]
        # the planar shape at the phase of the largest amplitude, and the orbit envelope
        ref = sh.ravel()[np.argmax(np.abs(sh.ravel()))]
        ph = np.conj(ref) / abs(ref)
        ax.plot(z, np.real(sh[:, 0] * ph), color="tab:blue", label="x")
        ax.plot(z, np.real(sh[:, 1] * ph), color="tab:orange", label="y")
        amp = np.sqrt((np.abs(sh) ** 2).sum(axis=1))
        ax.fill_between(z, -amp, amp, color="0.9", zorder=0)
        for name, (col, ls) in marks.items():
            for j, zz in enumerate(positions.get(name, [])):
                ax.axvline(zz, color=col, ls=ls, lw=1.0, label=name if j == 0 and i == 0 else None)
        ax.set_ylim(-1.1, 1.1)
        ax.set_title(f"{m.frequency_hz[mode]:.1f} Hz, δ = {m.log_decrement[mode]:.3g}, "
                     f"{m.whirl[mode]}", fontsize=9)
        ax.grid(True, alpha=0.3)
    axes[0].legend(fontsize=7, ncol=3, loc="lower left")
    for ax in axes[-cols:]:
        ax.set_xlabel("axial position z (m)")
    fig.suptitle(f"{title} — {m.speed_hz:g} Hz, {m.pressure_bar:g} bar", fontsize=11)
    return save_figure(fig, path, tight=True)


def stability_map_figure(path: str | os.PathLike, rows: list[dict], boundary: list[dict], *,
                         title: str = "Stability map") -> Path:
    """Per controller: the closed-loop max real pole over pressure × speed (colour, red
    unstable) with the stability boundary (the interpolated pressure where it turns
    unstable) as a curve; failed cases as black crosses.

    Parameters
    ----------
    path : path-like
        The PNG to write.
    rows : list of dict
        Rows of :func:`ambseal.analysis.sweep.sweep` (one parameter set).
    boundary : list of dict
        :func:`ambseal.analysis.sweep.stability_boundary` of the same rows.
    title : str
        The figure's title.

    Returns
    -------
    Path
        The PNG written.
    """

    names = list(dict.fromkeys(r["controller"] for r in rows))
    fig = Figure(figsize=(5.2 * len(names), 4.4))
    axes = np.atleast_1d(fig.subplots(1, len(names), squeeze=False)).ravel()
    for ax, name in zip(axes, names):
        rs = [r for r in rows if r["controller"] == name]
        p = np.array(sorted({r["pressure_bar"] for r in rs}))
        s = np.array(sorted({r["speed_hz"] for r in rs}))
        grid = np.full((len(s), len(p)), np.nan)
        for r in rs:
            if r.get("error") is None:
                grid[np.searchsorted(s, r["speed_hz"]), np.searchsorted(p, r["pressure_bar"])] \
                    = r["max_real_pole"]
        fin = grid[np.isfinite(grid)]
        lim = max(float(np.abs(fin).max()) if fin.size else 1.0, 1e-9)
        norm = TwoSlopeNorm(vcenter=0.0, vmin=-lim, vmax=lim)
        if len(p) > 1 and len(s) > 1:
            im = ax.pcolormesh(p, s, grid, shading="nearest", cmap="RdBu_r", norm=norm)
        else:
            pp, ss = np.meshgrid(p, s)
            im = ax.scatter(pp.ravel(), ss.ravel(), c=grid.ravel(), cmap="RdBu_r", norm=norm,
                            s=80, marker="s")
        fig.colorbar(im, ax=ax, label="max real pole (1/s)")
        b = sorted((x for x in boundary if x["controller"] == name), key=lambda x: x["speed_hz"])
        bx = [x["boundary_pressure_bar"] for x in b]
        if any(v is not None for v in bx):
            ax.plot([np.nan if v is None else v for v in bx], [x["speed_hz"] for x in b],
                    "k-o", ms=3, label="stability boundary")
            ax.legend(fontsize=8, loc="upper right")
        bad = [r for r in rs if r.get("error") is not None]
        if bad:
            ax.plot([r["pressure_bar"] for r in bad], [r["speed_hz"] for r in bad], "kx")
        ax.set_xlabel("pressure drop (bar)")
        ax.set_ylabel("speed (Hz)")
        ax.set_title(f"{title}: {name}")
    return save_figure(fig, path, tight=True)
