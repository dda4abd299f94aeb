"""PNG figures of the analysis results (matplotlib, Agg canvas only).

This is the only module of ambseal that imports matplotlib. It never touches pyplot or the
global backend: each figure is a ``matplotlib.figure.Figure`` on its own Agg canvas, written
to a temporary file in the target folder and moved into place with ``os.replace``.

Every function takes plain arrays (or results' arrays) and a path, and returns the path.
A *curve* is a tuple ``(label, x, y)`` of a legend label and two 1-D arrays of equal length;
one curve per (controller, pressure) case, as in the thesis figures (P5 Fig. 11–14).
"""

from __future__ import annotations

import hashlib
import os
from pathlib import Path
from typing import Mapping, Sequence

import numpy as np
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.collections import LineCollection
from matplotlib.figure import Figure
from matplotlib.image import imsave
from matplotlib.text import Text
from matplotlib.ticker import LogLocator, NullFormatter, NullLocator, ScalarFormatter
from PIL import Image, UnidentifiedImageError

from ambseal.analysis import ZONE_LIMITS, ZONES, zone_limit_db
from ambseal.config import METHODS
from ambseal.errors import AmbsealError
from ambseal.files import STAMP_KEY, atomic_write, input_file

__all__ = [
    "controller_gains_figure",
    "Curve",
    "sensitivity_figure",
    "compliance_figure",
    "unbalance_figure",
    "impulse_figure",
    "force_capacity_figure",
    "panels_figure",
    "decay_figure",
    "save_figure",
    "CONDITION_STYLES",
    "controller_colours",
    "case_style",
]

Curve = tuple[str, Sequence[float], Sequence[float]]

#: Line style of each judged condition, as thesis P5 Figs. 11–13: nominal solid, high
#: (pressure or speed) dashed, low dash-dot.
CONDITION_STYLES = {"nominal": "-", "high": "--", "low": "-."}
#: Colours given to controllers in order of appearance (matplotlib's tab10 cycle; the
#: methods' own, :data:`ambseal.config.METHODS`, are its first).
_PALETTE = ("#1f77b4", "#d62728", "#2ca02c", "#9467bd", "#ff7f0e", "#8c564b", "#e377c2",
            "#17becf")


#: The methods' own colours, the same in every report; other names take the palette's rest.
_METHOD_COLOURS = {m.name: m.colour for m in METHODS if m.colour is not None}


def controller_colours(names: Sequence[str]) -> dict[str, str]:
    """One colour per controller name, the same in every figure (and, for a method with
    its own colour, :data:`ambseal.config.METHODS`, in every report)."""
    uniq = list(dict.fromkeys(names))
    spare = [c for c in _PALETTE if c not in _METHOD_COLOURS.values()]
    others = [n for n in uniq if n not in _METHOD_COLOURS]
    out = {n: spare[i % len(spare)] for i, n in enumerate(others)}
    return {n: _METHOD_COLOURS.get(n, out.get(n)) for n in uniq}


def case_style(colour: str, condition: str = "nominal") -> dict:
    """matplotlib keywords of one (controller, condition) curve."""
    return {"color": colour, "ls": CONDITION_STYLES.get(condition, "-"), "lw": 1.4}


def save_figure(fig: Figure, path: str | os.PathLike, *, dpi: int = 120,
                tight: bool = False) -> Path:
    """Write ``fig`` as PNG to ``path`` atomically (temporary file + ``os.replace``).

    Titles, axis labels, legends and annotations are drawn as written (matplotlib's
    mathtext off: a rig, AMB or controller named ``$\\alpha$`` keeps its dollars and
    backslash); tick labels keep mathtext (the powers of ten of logarithmic axes). The
    minor ticks of logarithmic axes are replaced by their grid lines drawn as one line
    collection (:func:`_light_log_axes`) before the layout; ``tight=True`` then applies
    ``tight_layout`` (figures made with ``layout="constrained"`` lay out while drawing).
    The figure is drawn once at ``dpi`` and its canvas written as PNG the way
    ``Figure.savefig`` writes it (``matplotlib.image.imsave``): ``savefig`` draws a figure
    with a layout engine twice, once without rendering to lay it out and once to render
    it, each draw running the layout again (the same bytes, about 20 % more time). The PNG
    is compressed at zlib level 3, not Pillow's 6: the same pixels, files about 5 % larger,
    their encoding about 40 % faster.

    Raises
    ------
    AmbsealError
        If the folder does not exist or is not writable.
    """
    path = Path(path)
    if not path.parent.is_dir():
        raise AmbsealError(f"figure folder {str(path.parent)!r} does not exist")
    canvas = FigureCanvasAgg(fig)
    _light_log_axes(fig)
    _literal_texts(fig)
    if tight:
        fig.tight_layout()
    fig.set_dpi(dpi)
    canvas.draw()
    rgba = canvas.buffer_rgba()
    mark = {FIGURE_MARK: hashlib.sha256(bytes(rgba)).hexdigest()}
    atomic_write(path, lambda fh: imsave(fh, rgba, format="png", origin="upper", dpi=dpi,
                                         metadata=mark, pil_kwargs={"compress_level": 3}))
    return path


def _literal_texts(fig: Figure) -> None:
    """Mathtext off in every text of ``fig`` but the axes' tick labels and offsets: the
    texts that carry users' names (ambseal's own labels use Unicode, never mathtext)."""
    ticks = set()
    for ax in fig.axes:
        for axis in (ax.xaxis, ax.yaxis):
            ticks.add(axis.offsetText)
            for tick in (*axis.get_major_ticks(), *axis.get_minor_ticks()):
                ticks.update(tick.findobj(Text))
    for t in fig.findobj(Text):
        if t not in ticks:
            t.set_parse_math(False)


#: The PNG text key of a figure ambseal drew (ambseal's file mark): the SHA-256 of its RGBA
#: pixels
FIGURE_MARK = STAMP_KEY


def figure_is_ours(path: str | os.PathLike) -> bool:
    """True if ``path`` is a PNG that :func:`save_figure` wrote and nobody changed since
    (its ``ambseal-sha256`` text is the hash of its pixels): the ownership mark by which a
    command may replace it (:func:`ambseal.files.claim_file`).

    Parameters
    ----------
    path : str or os.PathLike
        Any file; a missing or unreadable one, or not a PNG, is not ours.

    Returns
    -------
    bool
    """
    try:
        with Image.open(input_file(path, "figure")) as im:
            mark = getattr(im, "text", {}).get(FIGURE_MARK)
            return mark is not None and mark == hashlib.sha256(
                im.convert("RGBA").tobytes()).hexdigest()
    except (AmbsealError, OSError, UnidentifiedImageError, ValueError):
        return False


def _light_log_axes(fig: Figure) -> None:
    """Minor grid lines of log axes as one ``LineCollection`` per axis, minor ticks off.

    matplotlib makes one ``Tick`` (two marks, a grid line, two labels) per minor tick at
    2…9 × 10ᵏ, laid out on every draw; on the Bode-style figures of a report that was half
    of the drawing time. The lines are the same (positions, colour, width, style, alpha);
    only the short minor tick marks on the spines go (axes spanning under a decade keep
    matplotlib's minor ticks, which carry labels there). Axes shared with others are handled
    together (they share their locator)."""
    todo = []
    for ax in fig.axes:
        for axis, vertical in ((ax.xaxis, True), (ax.yaxis, False)):
            if axis.get_scale() != "log" or not isinstance(axis.get_minor_locator(), LogLocator):
                continue
            line = axis.get_minor_ticks(1)[0].gridline
            lo, hi = sorted(ax.get_xlim() if vertical else ax.get_ylim())
            if not (lo > 0 and hi >= 10 * lo):  # under a decade matplotlib labels the minor
                continue                          # ticks: they stay
            todo.append((ax, axis, vertical, lo, hi, line.get_visible() and ax.get_visible(),
                         {"colors": line.get_color(), "linewidths": line.get_linewidth(),
                          "linestyles": line.get_linestyle(), "alpha": line.get_alpha()}))
    for ax, axis, vertical, lo, hi, grid, style in todo:
        axis.set_minor_locator(NullLocator())
        if not grid:
            continue
        k = np.arange(np.floor(np.log10(lo)), np.ceil(np.log10(hi)) + 1)
        v = (np.arange(2, 10)[None, :] * 10.0 ** k[:, None]).ravel()
        v = v[(v > lo) & (v < hi)]
        segs = [[(x, 0), (x, 1)] if vertical else [(0, x), (1, x)] for x in v]
        tr = ax.get_xaxis_transform() if vertical else ax.get_yaxis_transform()
        ax.add_collection(LineCollection(segs, transform=tr, zorder=0.5, **style),
                          autolim=False)


def _curves(curves: Sequence[Curve]) -> list[tuple[str, np.ndarray, np.ndarray]]:
    out = []
    for i, c in enumerate(curves):
        try:
            label, x, y = c
        except (TypeError, ValueError) as exc:
            raise AmbsealError(f"curve {i}: expected (label, x, y), got {type(c).__name__}") from exc
        x, y = np.asarray(x, dtype=float), np.asarray(y, dtype=float)
        if x.shape != y.shape or x.ndim != 1:
            raise AmbsealError(f"curve {i} ({label!r}): x and y must be 1-D of equal length, got {x.shape}, {y.shape}")
        out.append((str(label), x, y))
    return out


def _finite_max(curves: list[tuple[str, np.ndarray, np.ndarray]]) -> float:
    vals = [np.nanmax(y[np.isfinite(y)]) for _, _, y in curves if np.isfinite(y).any()]
    return float(max(vals)) if vals else 1.0


def _unstable_entries(ax, unstable: Mapping[str, dict]) -> None:
    """Legend entries (no curve) for loops that are unstable and so not drawn."""
    for label, st in unstable.items():
        ax.plot([], [], ls="none", marker="x", color=st.get("color", "k"),
                label=f"{label}: unstable, not drawn")


def _curve_figure(path, curves: Sequence[Curve], kind: str, xlabel: str, ylabel: str,
                  title: str, decorate=None, styles: Mapping[str, dict] | None = None,
                  unstable: Mapping[str, dict] | None = None) -> Path:
    """One axes of labelled curves (``kind``: ``"loglog"`` or ``"plot"``), a grid, a legend.

    ``styles`` maps a label to matplotlib keywords (:func:`case_style`); ``unstable`` maps
    the labels of loops not drawn to theirs, listed in the legend as unstable."""
    cs = _curves(curves)
    styles = styles or {}
    fig = Figure(figsize=(8, 4.5))
    ax = fig.add_subplot()
    for label, x, y in cs:
        getattr(ax, kind)(x, y, label=label, **styles.get(label, {}))
    _unstable_entries(ax, unstable or {})
    if decorate is not None:
        decorate(ax, cs)
    ax.set_xlabel(xlabel)
    ax.set_ylabel(ylabel)
    ax.set_title(title)
    ax.grid(True, which="both" if kind == "loglog" else "major", alpha=0.3)
    if cs or unstable:
        ax.legend(fontsize=8, ncols=2 if len(cs) + len(unstable or {}) > 6 else 1)
    return save_figure(fig, path, tight=True)


def sensitivity_figure(
    path: str | os.PathLike, curves: Sequence[Curve], *, title: str = "Output sensitivity σ̄(S_o)",
    styles: Mapping[str, dict] | None = None, unstable: Mapping[str, dict] | None = None,
) -> Path:
    """σ̄ of S_o against frequency with the ISO 14839-3 zone lines (P5 Fig. 13).

    Parameters
    ----------
    path : path-like
        PNG file to write.
    curves : sequence of (label, frequency_hz, gain)
        Frequencies in Hz (log axis) and absolute gain (not dB), one curve per case.
    title : str
        Axes title.
    styles, unstable : mapping of label → matplotlib keywords, optional
        Style of each curve (:func:`case_style`); loops not drawn, listed as unstable.

    Returns
    -------
    pathlib.Path
    """

    def zones(ax, cs):
        top = max(_finite_max(cs) * 1.5, 1.6 * ZONE_LIMITS[-1])
        ax.set_ylim(min(0.1, ax.get_ylim()[0]), top)
        # boundaries labelled side by side (staggered along x: on a log axis they are close)
        for k, (lim, db, (a, b)) in enumerate(zip(ZONE_LIMITS, zone_limit_db(),
                                                   zip(ZONES, ZONES[1:]))):
            ax.axhline(lim, color="0.35", lw=0.8, ls=":")
            ax.text(0.005 + 0.16 * k, lim * 1.02, f"{a}/{b}: {lim:g} ({db:.1f} dB)",
                    transform=ax.get_yaxis_transform(), va="bottom", ha="left", fontsize=7,
                    color="0.25")
        # zone letters between the lines (A below the first, D above the last)
        edges = (0.5 * ZONE_LIMITS[0],) + tuple(
            0.5 * (a + b) for a, b in zip(ZONE_LIMITS, ZONE_LIMITS[1:])) + (1.2 * ZONE_LIMITS[-1],)
        for zone, yz in zip(ZONES, edges):
            ax.text(1.01, yz, zone, transform=ax.get_yaxis_transform(), va="center", ha="left",
                    fontsize=9)
        ax.yaxis.set_major_formatter(ScalarFormatter())
        ax.yaxis.set_minor_formatter(NullFormatter())

    return _curve_figure(path, curves, "loglog", "Frequency (Hz)", "σ̄(S_o) (–, absolute gain)",
                         title, decorate=zones, styles=styles, unstable=unstable)


def compliance_figure(
    path: str | os.PathLike, curves: Sequence[Curve], *, title: str = "Compliance σ̄(S_o G_f)",
    styles: Mapping[str, dict] | None = None, unstable: Mapping[str, dict] | None = None,
) -> Path:
    """σ̄ of the compliance against frequency (P5 Fig. 11).

    Parameters
    ----------
    path : path-like
    curves : sequence of (label, frequency_hz, compliance_m_per_n)
        Frequencies in Hz; compliance in m/N (plotted in µm/N on a log axis).
    title : str

    Returns
    -------
    pathlib.Path
    """
    return _curve_figure(path, [(lb, x, np.asarray(y) * 1e6) for lb, x, y in curves], "loglog",
                         "Frequency (Hz)", "σ̄ compliance (µm/N)", title, styles=styles,
                         unstable=unstable)


def unbalance_figure(
    path: str | os.PathLike, curves: Sequence[Curve], *, title: str = "Worst-case unbalance response",
    styles: Mapping[str, dict] | None = None, unstable: Mapping[str, dict] | None = None,
) -> Path:
    """Worst-case unbalance response against speed (P5 Fig. 12).

    Parameters
    ----------
    path : path-like
    curves : sequence of (label, speed_hz, response_um)
        Speed (= excitation frequency) in Hz, response in µm (linear axes).
    title : str

    Returns
    -------
    pathlib.Path
    """
    return _curve_figure(path, curves, "plot", "Speed (Hz)", "Displacement bound (µm)", title,
                         decorate=lambda ax, cs: ax.set_ylim(bottom=0), styles=styles,
                         unstable=unstable)


def impulse_figure(
    path: str | os.PathLike,
    cases: Sequence[tuple[str, Sequence[float], np.ndarray]],
    channel_names: Sequence[str],
    *,
    currents: Sequence[tuple[str, Sequence[float], np.ndarray]] | None = None,
    title: str = "Impulse response",
    styles: Mapping[str, dict] | None = None,
) -> Path:
    """Impulse responses per output channel (P5 Fig. 14), optionally with controller currents.

    Parameters
    ----------
    path : path-like
    cases : sequence of (label, time_ms, displacement_um)
        ``time_ms`` shape (n_t,), ``displacement_um`` shape (n_t, n_ch); one curve per case in
        each channel's panel.
    channel_names : sequence of str
        Panel titles, length ``n_ch``.
    currents : sequence of (label, time_ms, current_a), optional
        Controller currents (A), shape (n_t, n_ch); drawn as a second row of panels.
    title : str

    Returns
    -------
    pathlib.Path

    Raises
    ------
    AmbsealError
        If array shapes do not match the channel names.
    """
    names = [str(n) for n in channel_names]
    nch = len(names)
    rows = [("Displacement (µm)", cases)] + ([("Current (A)", currents)] if currents else [])
    fig = Figure(figsize=(3.2 * max(nch, 1), 2.8 * len(rows) + 0.6))
    axes = fig.subplots(len(rows), max(nch, 1), squeeze=False, sharex=True)
    for r, (ylabel, data) in enumerate(rows):
        for label, t, Y in data:
            t = np.asarray(t, dtype=float)
            Y = np.asarray(Y, dtype=float).reshape(t.size, -1)
            if Y.shape[1] != nch:
                raise AmbsealError(f"impulse_figure: case {label!r} has {Y.shape[1]} channels, expected {nch}")
            for j in range(nch):
                axes[r, j].plot(t, Y[:, j], label=str(label),
                                **{"lw": 1, **(styles or {}).get(label, {})})
        for j in range(nch):
            ax = axes[r, j]
            ax.grid(True, alpha=0.3)
            if r == 0:
                ax.set_title(names[j])
            if j == 0:
                ax.set_ylabel(ylabel)
            if r == len(rows) - 1:
                ax.set_xlabel("Time (ms)")
    if cases:
        axes[0, 0].legend(fontsize=7)
    fig.suptitle(title)
    return save_figure(fig, path, tight=True)


def force_capacity_figure(
    path: str | os.PathLike,
    bearings: Sequence[tuple[str, Sequence[float], np.ndarray]],
    demands: Mapping[str, Sequence[Curve]],
    *,
    static_n: Mapping[str, float | None] | None = None,
    title: str = "Force capacity and the force the controllers ask for",
    styles: Mapping[str, dict] | None = None,
) -> Path:
    """Per AMB, the largest force amplitude it can deliver against frequency (the current
    limit, then the amplifier's slew rate K_i V/(L ω)) with the force each controller asks
    of it to hold the unbalance; one panel per AMB, log axes.

    Parameters
    ----------
    path : path-like
    bearings : sequence of (name, frequency_hz, capacity_n)
        Per AMB, frequencies (Hz, shape (F,)) and the force capacity of its axes (N, shape
        (F,) or (F, 2): ζ and η, drawn apart where they differ).
    demands : mapping of str → sequence of (label, speed_hz, force_n)
        Per AMB name, each controller's force amplitude (N) against speed (Hz).
    static_n : mapping of str → float or None, optional
        Per AMB name, its static load capacity (N), a dashed line.
    title : str
    styles : mapping of label → matplotlib keywords, optional
        Style of each controller's curve (:func:`case_style`).

    Returns
    -------
    pathlib.Path
    """
    n = max(len(bearings), 1)
    fig = Figure(figsize=(4.6 * n, 4.2))
    axes = fig.subplots(1, n, squeeze=False, sharey=True)[0]
    for ax, (name, f, cap) in zip(axes, bearings):
        f, cap = np.asarray(f, float), np.asarray(cap, float).reshape(len(f), -1)
        same = np.allclose(cap, cap[:, :1], rtol=1e-9)
        for j in range(1 if same else cap.shape[1]):
            ax.loglog(f, cap[:, j], color="k", lw=2, ls="-" if j == 0 else ":",
                      label="capacity" if same else f"capacity {('ζ', 'η')[j]}")
        if (static_n or {}).get(name):
            ax.axhline(static_n[name], color="0.45", ls="--", lw=1,
                       label="static load capacity")
        for label, x, y in _curves(demands.get(name, ())):
            ax.loglog(x, y, label=label, **{"lw": 1.2, **(styles or {}).get(label, {})})
        ax.set_title(f"AMB {name}")
        ax.xaxis.set_major_formatter(ScalarFormatter())
        ax.xaxis.set_minor_formatter(NullFormatter())
        ax.set_xlabel("Frequency, speed (Hz)")
        ax.grid(True, which="both", alpha=0.3)
        ax.legend(fontsize=7)
    axes[0].set_ylabel("Force amplitude (N)")
    fig.suptitle(title)
    return save_figure(fig, path, tight=True)


def panels_figure(
    path: str | os.PathLike,
    panels: Sequence[tuple[str, str]],
    curves: Mapping[str, Sequence[Curve]],
    *,
    xlabel: str,
    title: str = "",
    styles: Mapping[str, dict] | None = None,
) -> Path:
    """Panels side by side sharing the x axis, each its own quantity against one
    variable (linear axes, from 0).

    Parameters
    ----------
    path : path-like
    panels : sequence of (key, ylabel)
        One panel per key of ``curves``, left to right.
    curves : mapping of str → sequence of (label, x, y)
        Each panel's curves; the legend is the first panel's.
    xlabel, title : str
    styles : mapping of label → matplotlib keywords, optional

    Returns
    -------
    pathlib.Path
    """
    fig = Figure(figsize=(4.2 * max(len(panels), 1), 4.0))
    axes = fig.subplots(1, max(len(panels), 1), squeeze=False)[0]
    for ax, (key, ylabel) in zip(axes, panels):
        for label, x, y in _curves(curves.get(key, ())):
            ax.plot(x, y, label=label, **{"lw": 1.2, **(styles or {}).get(label, {})})
        ax.set_ylim(bottom=0)
        ax.set_xlabel(xlabel)
        ax.set_ylabel(ylabel)
        ax.grid(True, alpha=0.3)
    if panels and curves.get(panels[0][0]):
        axes[0].legend(fontsize=7)
    fig.suptitle(title)
    return save_figure(fig, path, tight=True)


def decay_figure(
    path: str | os.PathLike,
    curves: Sequence[Curve],
    *,
    ylabel: str,
    title: str = "",
    marks: Mapping[str, float] | None = None,
    styles: Mapping[str, dict] | None = None,
) -> Path:
    """Amplitudes against time on a log axis (a decay), with labelled vertical marks.

    Parameters
    ----------
    path : path-like
    curves : sequence of (label, time_s, amplitude)
        Time (s) and a positive amplitude (zeros are not drawn).
    ylabel, title : str
    marks : mapping of str → float, optional
        Vertical dashed lines at these times (s), labelled.
    styles : mapping of label → matplotlib keywords, optional

    Returns
    -------
    pathlib.Path
    """
    def decorate(ax, cs):
        for label, t in (marks or {}).items():
            ax.axvline(t, color="0.4", ls=":", lw=1)
            ax.text(t, 0.98, f" {label}", transform=ax.get_xaxis_transform(), va="top",
                    fontsize=8, color="0.25")

    positive = [(lb, x, np.where(np.asarray(y, float) > 0, y, np.nan)) for lb, x, y in curves]
    return _curve_figure(path, positive, "semilogy", "Time (s)", ylabel, title,
                         decorate=decorate, styles=styles)


def controller_gains_figure(
    path: str | os.PathLike,
    controllers: Sequence[tuple[str, Sequence[float], np.ndarray]],
    channel_names: Sequence[str],
    *,
    pairs: Sequence[tuple[int, int]] = ((0, 0), (2, 2), (0, 1), (0, 2)),
    title: str = "Controller gains",
    styles: Mapping[str, dict] | None = None,
) -> Path:
    """Direct and cross gains |K_ij(jω)| (A/m) of several controllers (P5 Fig. 10).

    ``controllers``: (label, frequency_hz (n,), K (n, nu, ny) complex); ``pairs`` are
    (output i, input j) indices, 0-based, those the controllers have (a rig with one AMB
    has a 2 × 2 K); panel titles use ``channel_names``.
    """
    nu, ny = np.asarray(controllers[0][2]).shape[1:]
    pairs = [(i, j) for i, j in pairs if i < nu and j < ny] or [(0, 0)]
    fig = Figure(figsize=(10, 6), layout="constrained")
    axes = np.atleast_1d(fig.subplots(2, (len(pairs) + 1) // 2) if len(pairs) > 1
                         else fig.subplots(1, 1)).ravel()
    for ax in axes[len(pairs):]:
        ax.set_visible(False)
    for ax, (i, j) in zip(axes, pairs):
        for label, f, K in controllers:
            ax.loglog(np.asarray(f, float), np.abs(np.asarray(K)[:, i, j]), label=label,
                      **(styles or {}).get(label, {}))
        ax.set_title(f"K[{i + 1},{j + 1}]: {channel_names[j]} → {channel_names[i]}", fontsize=9)
        ax.set_xlabel("Frequency (Hz)")
        ax.set_ylabel("|K| (A/m)")
        ax.grid(alpha=0.3, which="both")
    axes[0].legend(fontsize=8)
    fig.suptitle(title)
    return save_figure(fig, path)
