"""PNG figures of the identification results (matplotlib, Agg canvas only).

Same house rules as :mod:`ambseal.report.figures`: a ``matplotlib.figure.Figure`` on its own
Agg canvas, no pyplot, written atomically by :func:`ambseal.report.figures.save_figure`.

The FRF objects are taken by duck typing (anything with ``frequency_hz``, ``H``,
``coherence``, ``input_names``, ``output_names`` and optionally ``units``, e.g.
:class:`ambseal.identify.fitting.frf.FRF`), so this module does not import the identification code.
"""

from __future__ import annotations

import os
from pathlib import Path
from typing import Any, Sequence

import numpy as np
from matplotlib.figure import Figure

from ambseal.errors import AmbsealError
from ambseal.report.figures import save_figure

__all__ = ["frf_figure", "fit_timeseries_figure", "correlation_figure", "seal_frequency_figure",
           "seal_pressure_figure", "residual_figure", "error_budget_figure",
           "facility_impulse_figure"]


def _check(frf: Any, what: str) -> tuple[np.ndarray, np.ndarray]:
    try:
        f = np.asarray(frf.frequency_hz, dtype=float)
        H = np.asarray(frf.H, dtype=complex)
        frf.input_names, frf.output_names  # noqa: B018 - presence check
    except AttributeError as exc:
        raise AmbsealError(f"frf_figure: {what} is not an FRF ({exc})") from None
    if f.ndim != 1 or H.ndim != 3 or H.shape[0] != f.size:
        raise AmbsealError(f"frf_figure: {what}.H has shape {H.shape}, expected ({f.size}, ny, nu)")
    return f, H


def frf_figure(
    path: str | os.PathLike,
    measured: Any,
    model: Any = None,
    *,
    pairs: Sequence[tuple[str, str]] | None = None,
    magnitude: str = "log",
    fmin_hz: float | None = None,
    fmax_hz: float | None = None,
    title: str = "Frequency response",
    unwrap_phase: bool = False,
) -> Path:
    """Measured FRF against a model: magnitude, phase and coherence (thesis P4 Figs. 9–10, 13–15).

    One column of panels per input; rows magnitude, phase (degrees) and — when the
    measured FRF has one — coherence γ². Each (output, input) pair is a solid curve; the
    model's same pair is dashed in the same colour.

    Parameters
    ----------
    path : path-like
        PNG file to write.
    measured : FRF-like
        ``frequency_hz (n_f,)``, ``H (n_f, ny, nu)``, ``coherence (n_f, ny, nu)`` or None,
        ``input_names``, ``output_names``, optional ``units`` (str).
    model : FRF-like, optional
        Model FRF with the same input and output names (pairs missing from it are skipped).
    pairs : sequence of (output_name, input_name), optional
        Pairs to draw; default all of ``measured``.
    magnitude : {"log", "db"}
        ``|H|`` on a log axis, or ``20 log10 |H|`` in dB.
    fmin_hz, fmax_hz : float, optional
        Frequency range shown (Hz); default the measured grid without 0 Hz (log axis).
    title : str
        Figure title.
    unwrap_phase : bool
        Unwrap the phase along frequency; default wrapped to (−180°, 180°], which keeps
        low-coherence (noisy) pairs readable.

    Returns
    -------
    pathlib.Path

    Raises
    ------
    AmbsealError
        If an argument is not FRF-like, a pair is unknown, ``magnitude`` is invalid, or the
        folder does not exist.
    """
    if magnitude not in ("log", "db"):
        raise AmbsealError(f"frf_figure: magnitude must be 'log' or 'db', got {magnitude!r}")
    f, H = _check(measured, "measured")
    outs, ins = list(measured.output_names), list(measured.input_names)
    sel = _pairs(pairs, outs, ins)
    if model is not None:
        fm, Hm = _check(model, "model")
        m_outs, m_ins = list(model.output_names), list(model.input_names)
    col_inputs = [i for i in ins if any(p[1] == i for p in sel)]
    coh = getattr(measured, "coherence", None)
    rows = 3 if coh is not None else 2
    ncol = max(len(col_inputs), 1)
    fig = Figure(figsize=(4.2 * ncol, 2.4 * rows + 0.8))
    axes = fig.subplots(rows, ncol, squeeze=False, sharex=True)
    lo = fmin_hz if fmin_hz is not None else (f[f > 0].min() if np.any(f > 0) else 1.0)
    hi = fmax_hz if fmax_hz is not None else f.max()
    mask = (f >= lo) & (f <= hi) & (f > 0)
    units = str(getattr(measured, "units", "") or "")
    colours = [f"C{k % 10}" for k in range(len(outs))]

    for c, inp in enumerate(col_inputs):
        j = ins.index(inp)
        for o, i in sel:
            if i != inp:
                continue
            k = outs.index(o)
            colour = colours[k]
            h = H[mask, k, j]
            axes[0, c].plot(f[mask], _magnitude(h, magnitude), color=colour, lw=1,
                            label=f"{o} (measured)")
            axes[1, c].plot(f[mask], _phase_deg(h, unwrap_phase), color=colour, lw=1)
            if coh is not None:
                axes[2, c].plot(f[mask], np.asarray(coh)[mask, k, j], color=colour, lw=1)
            if model is not None and o in m_outs and inp in m_ins:
                mm = (fm >= lo) & (fm <= hi) & (fm > 0)
                hm = Hm[mm, m_outs.index(o), m_ins.index(inp)]
                axes[0, c].plot(fm[mm], _magnitude(hm, magnitude), color=colour, lw=1.2,
                                ls="--", label=f"{o} (model)")
                axes[1, c].plot(fm[mm], _phase_deg(hm, unwrap_phase), color=colour, lw=1.2,
                                ls="--")
        axes[0, c].set_title(f"from {inp}", fontsize=10)
        if magnitude == "log":
            axes[0, c].set_yscale("log")
        for r in range(rows):
            axes[r, c].set_xscale("log")
            axes[r, c].grid(True, which="both", alpha=0.3)
        axes[-1, c].set_xlabel("Frequency (Hz)")
        axes[0, c].legend(fontsize=7)
    _frf_labels(axes, units, magnitude, unwrap_phase, coh is not None)
    fig.suptitle(title)
    return save_figure(fig, path, tight=True)


def _pairs(pairs, outs: list, ins: list) -> list[tuple[str, str]]:
    """The (output, input) pairs to draw, every one by default; an unknown one refused."""
    if pairs is None:
        return [(o, i) for i in ins for o in outs]
    for o, i in pairs:
        if o not in outs or i not in ins:
            raise AmbsealError(f"frf_figure: pair ({o!r}, {i!r}) not in measured outputs "
                               f"{outs} × inputs {ins}")
    return [(o, i) for o, i in pairs]


def _magnitude(h: np.ndarray, magnitude: str) -> np.ndarray:
    """|H|, or 20 log10 |H| for ``magnitude="db"``."""
    a = np.abs(h)
    if magnitude == "db":
        with np.errstate(divide="ignore"):
            return 20.0 * np.log10(a)
    return a


def _phase_deg(h: np.ndarray, unwrap: bool) -> np.ndarray:
    """Phase in degrees, NaN where H is zero or not finite (its phase means nothing)."""
    ok = np.isfinite(h) & (h != 0)
    out = np.full(h.shape, np.nan)
    if ok.any():
        ph = np.angle(h[ok])
        out[ok] = np.degrees(np.unwrap(ph) if unwrap else ph)
    return out


def _frf_labels(axes, units: str, magnitude: str, unwrap_phase: bool, coherence: bool) -> None:
    """The rows' labels and the phase and coherence axes' limits."""
    unit_label = f" ({units})" if units else ""
    axes[0, 0].set_ylabel(f"|H|{unit_label}" if magnitude == "log"
                          else f"|H| (dB re 1 {units or 'unit'})")
    axes[1, 0].set_ylabel("Phase (deg)")
    ncol = axes.shape[1]
    if not unwrap_phase:
        for c in range(ncol):
            axes[1, c].set_ylim(-200, 200)
            axes[1, c].set_yticks([-180, -90, 0, 90, 180])
    if coherence:
        axes[2, 0].set_ylabel("Coherence γ² (-)")
        for c in range(ncol):
            axes[2, c].set_ylim(0, 1.05)


def fit_timeseries_figure(path: str | os.PathLike, time_s: Sequence[float], y_meas: np.ndarray,
                          y_sim: np.ndarray, channel_names: Sequence[str], *,
                          nrmse_pct: Sequence[float] | None = None,
                          title: str = "Measured and simulated displacements") -> Path:
    """Measured (solid) against simulated (dashed) displacement per channel, in µm against
    s (thesis P2 Fig. 5, P4 Fig. 8), with the NRMSE fit in each panel's title.

    Parameters
    ----------
    path : str or os.PathLike
        The PNG to write.
    time_s : sequence of float, length N
        Sample times (s).
    y_meas, y_sim : numpy.ndarray, shape (N, k)
        Measured and simulated displacements (m).
    channel_names : sequence of str
        The ``k`` channels.
    nrmse_pct : sequence of float, optional
        The NRMSE fit (%) of each channel.
    title : str, optional
        The figure's title.

    Returns
    -------
    Path
        The PNG written.
    """
    t = np.asarray(time_s, float)
    ym, ys = np.asarray(y_meas, float) * 1e6, np.asarray(y_sim, float) * 1e6
    k = ym.shape[1]
    fig = Figure(figsize=(10, 1.9 * k + 0.6), layout="constrained")
    axes = fig.subplots(k, 1, sharex=True, squeeze=False)[:, 0]
    for j, ax in enumerate(axes):
        ax.plot(t, ym[:, j], lw=0.8, label="measured")
        ax.plot(t, ys[:, j], lw=0.8, ls="--", label="simulated")
        name = channel_names[j]
        ax.set_title(name if nrmse_pct is None else f"{name}: fit {nrmse_pct[j]:.1f} %",
                     fontsize=9)
        ax.set_ylabel("µm")
        ax.grid(alpha=0.3)
    axes[0].legend(fontsize=8, loc="upper right")
    axes[-1].set_xlabel("Time (s)")
    fig.suptitle(title)
    return save_figure(fig, path)


def correlation_figure(path: str | os.PathLike, correlation: np.ndarray,
                       names: Sequence[str], *, title: str = "Parameter correlation") -> Path:
    """The correlation matrix of the estimates with its values (thesis P4 Tables 2, 4).

    Parameters
    ----------
    path : str or os.PathLike
        The PNG to write.
    correlation : numpy.ndarray, shape (p, p)
        The estimates' correlation matrix.
    names : sequence of str
        The ``p`` parameter names.
    title : str, optional
        The figure's title.

    Returns
    -------
    Path
        The PNG written.
    """
    R = np.asarray(correlation, float)
    n = R.shape[0]
    fig = Figure(figsize=(1.0 + 0.75 * n, 0.8 + 0.7 * n), layout="constrained")
    ax = fig.subplots()
    im = ax.imshow(R, vmin=-1, vmax=1, cmap="RdBu_r")
    ax.set_xticks(range(n), names, rotation=60, ha="right", fontsize=8)
    ax.set_yticks(range(n), names, fontsize=8)
    for i in range(n):
        for j in range(n):
            ax.text(j, i, f"{R[i, j]:.2f}", ha="center", va="center", fontsize=7,
                    color="white" if abs(R[i, j]) > 0.6 else "black")
    fig.colorbar(im, ax=ax, shrink=0.8)
    ax.set_title(title)
    return save_figure(fig, path)


def residual_figure(path: str | os.PathLike, tests: Any, *,
                    title: str = "Residual analysis (Ljung §16.6)") -> Path:
    """Per channel: the residual's autocorrelation (left) and the cross-correlation of the
    prewhitened residual with the same axis's excitation (right), with the 99 % band; the
    χ² statistics against their limits in the titles.

    Parameters
    ----------
    path : str or os.PathLike
        The PNG to write.
    tests : ResidualTests
        :func:`ambseal.identify.fitting.residuals.residual_tests` of a fit.
    title : str, optional
        The figure's title.

    Returns
    -------
    Path
        The PNG written.
    """
    ch = list(tests.channels)
    m = tests.lags
    fig = Figure(figsize=(10, 1.8 * len(ch) + 0.6), layout="constrained")
    axes = fig.subplots(len(ch), 2, sharex="col", squeeze=False)
    for j, name in enumerate(ch):
        a, b = axes[j]
        a.stem(np.arange(m + 1), tests.autocorrelation[j], basefmt=" ")
        b.stem(np.arange(-m, m + 1), tests.cross_correlation[j], basefmt=" ")
        for ax in (a, b):
            ax.axhspan(-tests.band, tests.band, color="0.85", zorder=0)
            ax.grid(alpha=0.3)
        a.set_title(f"{name}: whiteness {tests.whiteness[j]:.0f} "
                    f"(limit {tests.whiteness_limit[j]:.0f}, informative)", fontsize=9)
        ok = tests.independence[j] <= tests.independence_limit[j]
        b.set_title(f"{name}: independence {tests.independence[j]:.0f} (limit "
                    f"{tests.independence_limit[j]:.0f}) {'pass' if ok else 'FAIL'}", fontsize=9)
    d = getattr(tests, "block", 1)
    axes[-1, 0].set_xlabel(f"Lag (blocks of {d} samples)")
    axes[-1, 1].set_xlabel(f"Lag (blocks of {d} samples), residual after excitation")
    fig.suptitle(title)
    return save_figure(fig, path)


def error_budget_figure(path: str | os.PathLike, names: Sequence[str], estimate: Any,
                        std_error_noise: Any, budget: Any, *, top: int = 5,
                        title: str = "Error budget: 1σ per source, % of the estimate") -> Path:
    """Horizontal stacked variance bars per estimate: the noise part and each fixed
    parameter's (the ``top`` largest named, the rest summed), in % of the estimate's 1σ²
    expressed as σ (bar length = total 1σ in % of the estimate).

    Parameters
    ----------
    path : str or os.PathLike
        The PNG to write.
    names : sequence of str
        The ``p`` fitted parameters.
    estimate : array_like, shape (p,)
        Their estimates (SI).
    std_error_noise : array_like, shape (p,)
        Their standard errors from the noise alone (SI).
    budget : ErrorBudget or None
        The fixed parameters' contributions (:class:`ambseal.identify.fitting.budget.ErrorBudget`);
        None draws the noise part alone.
    top : int, optional
        Fixed parameters named; the others are summed.
    title : str, optional
        The figure's title.

    Returns
    -------
    Path
        The PNG written.
    """
    est = np.abs(np.asarray(estimate, float))
    noise = np.asarray(std_error_noise, float)
    parts = [("noise", noise ** 2)]
    if budget is not None:
        c2 = budget.contribution() ** 2
        order = np.argsort(-c2.sum(axis=0))
        for j in order[:top]:
            parts.append((budget.fixed[j], c2[:, j]))
        if len(order) > top:
            parts.append(("other fixed", c2[:, order[top:]].sum(axis=1)))
    total = sum(v for _, v in parts)
    sigma_pct = 100 * np.sqrt(total) / np.where(est > 0, est, np.nan)
    fig = Figure(figsize=(9, 0.45 * len(names) + 1.4), layout="constrained")
    ax = fig.subplots()
    left = np.zeros(len(names))
    y = np.arange(len(names))
    for label, v in parts:  # each source's share of the variance, scaled to the total σ
        w = sigma_pct * v / np.where(total > 0, total, 1.0)
        ax.barh(y, w, left=left, label=label)
        left += w
    ax.set_yticks(y, names, fontsize=8)
    ax.invert_yaxis()
    ax.set_xlabel("1σ (% of the estimate), split by share of the variance")
    ax.legend(fontsize=7, loc="lower right")
    ax.grid(alpha=0.3, axis="x")
    ax.set_title(title)
    return save_figure(fig, path)


_SEAL_UNITS = {"K": "N/m", "k": "N/m", "C": "N·s/m", "c": "N·s/m"}


def seal_frequency_figure(path: str | os.PathLike, curves: Sequence[tuple],
                          coefficients: Sequence[str] = ("K", "k", "C", "c"), *,
                          valid_below_hz: float | None = 100.0,
                          title: str = "Seal coefficients against excitation frequency"
                          ) -> Path:
    """Identified seal coefficients with ±1.96σ bars against frequency, one curve per
    pressure (thesis P4 Fig. 12). ``curves``: (label, frequency_hz (n,), estimate (n, 4),
    std_error (n, 4)[, unreliable (n,) bool]); unreliable fits are drawn as open markers
    without bars (:func:`ambseal.identify.fitting.seal_test.fit_reliability`)."""
    fig = Figure(figsize=(10, 6), layout="constrained")
    axes = fig.subplots(2, 2).ravel()
    for label, f, est, se, *rest in curves:
        f, est, se = np.asarray(f, float), np.asarray(est, float), np.asarray(se, float)
        bad = np.asarray(rest[0], bool) if rest else np.zeros(f.size, bool)
        for j, ax in enumerate(axes[: len(coefficients)]):
            line = ax.errorbar(f[~bad], est[~bad, j], yerr=1.96 * se[~bad, j], marker="o",
                               ms=3, capsize=2, lw=1, label=label)
            if bad.any():
                ax.plot(f[bad], est[bad, j], "o", mfc="none", ms=5,
                        color=line[0].get_color(),
                        label=f"{label}, unreliable" if j == 0 else None)
    for j, ax in enumerate(axes[: len(coefficients)]):
        c = coefficients[j]
        ax.set_title(c)
        ax.set_ylabel(_SEAL_UNITS.get(c, ""))
        ax.set_xlabel("Excitation frequency (Hz)")
        ax.grid(alpha=0.3)
        if valid_below_hz:
            ax.axvline(valid_below_hz, color="k", ls="--", lw=0.8)
    axes[0].legend(fontsize=8)
    fig.suptitle(title)
    return save_figure(fig, path)


def seal_pressure_figure(path: str | os.PathLike, pressure_bar: Sequence[float], estimate: Any,
                         std_error: Any, regressions: Sequence[Any],
                         coefficients: Sequence[str] = ("K", "k", "C", "c"), *,
                         truth: Sequence[Any] | None = None, nominal_bar: float | None = None,
                         title: str = "Seal coefficients against pressure drop") -> Path:
    """Identified coefficients (±1.96σ) against pressure drop with regression lines and
    their 95 % band (thesis P5 Fig. 7). ``regressions`` have ``predict(x) -> (ŷ, se)``;
    ``truth`` optional callables p -> value per coefficient."""
    p = np.asarray(pressure_bar, float)
    est, se = np.asarray(estimate, float), np.asarray(std_error, float)
    grid = np.linspace(0.0, max(p.max(), nominal_bar or 0) * 1.05, 100)
    fig = Figure(figsize=(10, 6), layout="constrained")
    axes = fig.subplots(2, 2).ravel()
    for j, ax in enumerate(axes[: len(coefficients)]):
        ax.errorbar(p, est[:, j], yerr=1.96 * se[:, j], fmt="x", capsize=3, label="identified")
        yhat, yse = regressions[j].predict(grid)
        ax.plot(grid, yhat, lw=1.2, label="regression")
        ax.fill_between(grid, yhat - 1.96 * yse, yhat + 1.96 * yse, alpha=0.2)
        if truth is not None and truth[j] is not None:
            ax.plot(grid, [truth[j](x) for x in grid], "k:", lw=1, label="truth")
        if nominal_bar is not None:
            ax.axvline(nominal_bar, color="k", ls="--", lw=0.8)
        ax.set_title(coefficients[j])
        ax.set_ylabel(_SEAL_UNITS.get(coefficients[j], ""))
        ax.set_xlabel("Pressure drop (bar)")
        ax.grid(alpha=0.3)
    axes[0].legend(fontsize=8)
    fig.suptitle(title)
    return save_figure(fig, path)


def facility_impulse_figure(path: str | os.PathLike, checks: Sequence[Any],
                            title: str = "Impulse responses: virtual facility against the "
                                         "identified model") -> Path:
    """P5 Figs. 15–16: per controller (columns) and pressure drop (rows), the displacement
    of each excited axis on the facility (dashed, "experimental") and in the identified
    model (solid, "simulated"), µm against s. ``checks``: objects with ``controller``,
    ``pressure_bar``, ``time_s``, ``excitation_a``, ``facility_m``, ``model_m``, ``axes``,
    ``nrmse_fit_pct`` and ``error`` (:class:`ambseal.identify.facility.design_model.ImpulseCheck`)."""
    names = list(dict.fromkeys(c.controller for c in checks))
    pressures = sorted({c.pressure_bar for c in checks})
    fig = Figure(figsize=(3.6 * len(names) + 0.6, 2.6 * len(pressures) + 0.6),
                 layout="constrained")
    grid = fig.subplots(len(pressures), len(names), squeeze=False, sharex=True)
    for c in checks:
        ax = grid[pressures.index(c.pressure_bar), names.index(c.controller)]
        ax.set_title(f"{c.controller}, {c.pressure_bar:g} bar", fontsize=9)
        ax.grid(alpha=0.3)
        if c.error is not None:
            ax.text(0.5, 0.5, "unstable on the facility", ha="center", va="center",
                    transform=ax.transAxes, color="C3")
            continue
        excited = [j for j in range(len(c.axes)) if np.any(c.excitation_a[:, j])]
        for n, j in enumerate(excited):
            ax.plot(c.time_s, 1e6 * c.model_m[:, j], lw=0.9, color=f"C{n}",
                    label=f"{c.axes[j]} model (fit {c.nrmse_fit_pct[c.axes[j]]:.0f} %)")
            ax.plot(c.time_s, 1e6 * c.facility_m[:, j], lw=0.9, ls="--", color=f"C{n}",
                    label=f"{c.axes[j]} facility")
        ax.legend(fontsize=6, loc="upper right")
    for ax in grid[:, 0]:
        ax.set_ylabel("µm")
    for ax in grid[-1]:
        ax.set_xlabel("Time (s)")
    fig.suptitle(title)
    return save_figure(fig, path)
