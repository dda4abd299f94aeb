"""μ-synthesis by D–K iteration (complex D–K).

The classical μ-synthesis: H∞ synthesis on ``D P D⁻¹`` (K-step), then frequency-wise D scales
from the μ upper bound of the closed loop (D-step), fitted by stable, minimum-phase rational
functions and absorbed into the plant. References: Balas, Doyle, Glover, Packard & Smith
(μ-Analysis and Synthesis Toolbox, 1993); Skogestad & Postlethwaite (2005) §8.12;
Zhou, Doyle & Glover (1996) ch. 11.

When the iterations stop, a direct search over the fitted D
scales' parameters for the smallest γ_opt of ``D P D⁻¹`` (``musyn(search=…)``): D–K stalls
where each D-step's pointwise-optimal D of the current K is not the best D for the next
K-step. The μ reported is the upper bound of the kept controller re-checked between the grid
points around its peaks (:func:`~ambseal.robust.mu.mu_peak`), and the result names that grid.

Every stop is decided by tolerances and counts, never by a clock: the iterations end by
their stall rule (``rtol``, ``patience``; an iteration cap only where the caller sets
``max_iter``), the search by its γ evaluations and its work in γ evaluations × states³. The
same problem gives the same controller on every machine, quiet or loaded;
``MusynResult.stopping`` says which rule ended each phase.

Simplifications (documented limits): real blocks are treated as complex and repeated scalars
as independent scalars in the D-step (so D is diagonal, one scalar per channel group); the
reported μ is computed with the structure as given (mixed, repeated), which is never larger.
"""

from __future__ import annotations

import itertools
import time
from dataclasses import dataclass, field, replace
from typing import Any, Sequence

import control as ct
import numpy as np
from rich.console import Console

from ambseal.errors import ConfigError, ModelError, SynthesisError
from ambseal.lti import least_squares_converged
from ambseal.robust._dscale import (
    FIT_STALL_RTOL,
    _balance_channels,
    _d_logmag_jac,
    _d_sections,
    _d_theta,
    _logmag,
    _logmag_jac,
    _scaled_plant,
    _search_evals,
    _search_step,
    _start_evals,
    _theta_to_tf,
    _unbalanced_fit,
    untied,
)
from ambseal.robust.hinf import check_plant, hinfsyn, lft_lower
from ambseal.robust.mu import _complexify, check_blocks, mu_peak, upper_on_grid
from ambseal.threads import with_numerics_threads

__all__ = ["MusynResult", "musyn", "fit_magnitude", "fit_dscale", "default_omega",
           "design_omega", "ScaledHinfResult", "scaled_hinfsyn", "dscaled_plant",
           "result_scalings"]


# --------------------------------------------------------------------------- D fitting
def fit_magnitude(omega, mag, order: int):
    """Stable, minimum-phase, biproper W(s) with |W(jω)| ≈ mag (log-magnitude least squares).

    W = k·Π N_i(s)/Π D_i(s) with first/second-order sections whose coefficients are kept
    positive (exp-parametrised), so every pole and zero is in the open left half plane: the
    "reflect to the LHP" step is built into the parametrisation.

    Parameters
    ----------
    omega : array_like
        Frequencies in rad/s (> 0).
    mag : array_like
        Positive magnitudes (dimensionless D scales).
    order : int
        Order of numerator and denominator, 0–4.

    Returns
    -------
    control.TransferFunction
        The fit (a constant for ``order = 0``).

    Raises
    ------
    ConfigError
        Order outside 0–4, non-positive magnitudes or frequencies, length mismatch.
    """
    w = np.asarray(omega, float)
    d = np.asarray(mag, float)
    if not (isinstance(order, (int, np.integer)) and 0 <= order <= 4):
        raise ConfigError(f"order={order!r}: the D-scale fit order must be an integer 0–4")
    if w.shape != d.shape or w.ndim != 1 or w.size == 0:
        raise ConfigError("fit_magnitude: omega and mag must be 1-D arrays of equal length")
    if np.any(w <= 0) or np.any(~np.isfinite(d)) or np.any(d <= 0):
        raise ConfigError("fit_magnitude: frequencies and magnitudes must be positive and finite")
    y = np.log(np.clip(d, 1e-8, 1e8))
    if order == 0:
        return ct.tf([float(np.exp(np.mean(y)))], [1.0])
    lw = np.log(w)
    n2, n1 = divmod(order, 2)
    best = None
    for spread in (1.0, 0.5):
        # roots log-spaced across the grid; zeros and poles interleaved
        cen = np.linspace(lw.min(), lw.max(), 2 * (n2 + n1) + 2)[1:-1]
        cen = lw.mean() + spread * (cen - lw.mean())
        zc, pc = cen[0::2], cen[1::2]
        th = [0.0]
        for cs in (zc, pc):
            for i in range(n2):
                wn = np.exp(cs[i])
                th += [np.log(wn**2), np.log(1.4 * wn)]
            for i in range(n1):
                th += [cs[n2 + i] if n2 + i < cs.size else cs[-1]]
        th = np.array(th)
        th[0] = np.mean(y - _logmag(th, w, order))
        res = least_squares_converged(
            lambda t: _logmag(t, w, order) - y, th, method="trf",
            jac=lambda t: _logmag_jac(t, w, order)[1],
            bounds=(np.r_[-60.0, np.full(th.size - 1, lw.min() - 12)],
                    np.r_[60.0, np.full(th.size - 1, 2 * lw.max() + 12)]))
        if best is None or res.cost < best.cost:
            best = res
    num, den = _theta_to_tf(best.x, order)
    return ct.tf(num, den)


def _fit_weighted(w, y, order, wgt, starts):
    """Weighted log-magnitude least squares of one order from several starts; pole and zero
    frequencies kept within a decade of the grid, second-order sections' damping ζ within
    0.05 … 2. ``starts``: ``(centre, spread)`` of the roots' log-frequencies, or an
    earlier fit's x (:func:`_fit_from`). Returns (x, weighted max |error|) of the best;
    θ of :func:`_logmag` is ``_d_theta(x, order)``."""
    lw = np.log(w)
    n2, n1 = divmod(order, 2)
    best, best_err = None, np.inf
    for start in starts:
        fresh = not isinstance(start, np.ndarray)
        if not fresh:
            x = start
        else:
            cen0, spread = start
            cen = np.linspace(lw.min(), lw.max(), 2 * (n2 + n1) + 2)[1:-1]
            cen = cen0 + spread * (cen - lw.mean())
            zc, pc = cen[0::2], cen[1::2]
            x = [0.0]
            for cs in (zc, pc):
                x += [v for i in range(n2) for v in (2 * cs[i], np.log(1.4))]
                x += [cs[n2 + i] if n2 + i < cs.size else cs[-1] for i in range(n1)]
            x = np.array(x)
        x, err = _fit_from(w, y, order, wgt, x, fresh=fresh)
        if err < best_err:
            best, best_err = x, err
    return best, best_err


def _fit_from(w, y, order, wgt, x, fresh: bool = True):
    """One bounded fit of :func:`_fit_weighted` from x (per second-order section log ω_n²,
    log 2ζ; per first-order one log a; x[0] the gain), clipped into the bounds; ``fresh``:
    x[0] set to the weighted mean offset first (a start from the grid, not an earlier
    fit). Returns (x, weighted max |error|)."""
    lw = np.log(w)
    n2, n1 = divmod(order, 2)
    lo_b, hi_b = lw.min() - np.log(10.0), lw.max() + np.log(10.0)
    sq = np.sqrt(wgt)

    def theta(t):
        # x: per second-order section (log ωn², log 2ζ); θ of _logmag: (log ωn², log 2ζωn)
        return _d_theta(t, order)

    sec = [(2 * lo_b, 2 * hi_b), (np.log(0.1), np.log(4.0))] * n2 + [(lo_b, hi_b)] * n1
    lb, ub = np.array([-60.0] + [b[0] for b in sec] * 2), \
        np.array([60.0] + [b[1] for b in sec] * 2)
    x = np.clip(np.array(x, float), lb + 1e-6, ub - 1e-6)
    if fresh:
        x[0] = np.average(y - _logmag(theta(x), w, order), weights=wgt)

    def largest(t):
        return float(np.max(np.abs(_logmag(theta(t), w, order) - y) * wgt / wgt.max()))

    res = least_squares_converged(lambda t: sq * (_logmag(theta(t), w, order) - y), x,
                                  jac=lambda t: sq[:, None] * _d_logmag_jac(t, w, order)[1],
                                  method="trf", bounds=(lb, ub), stall=largest,
                                  stall_rtol=FIT_STALL_RTOL)
    return res.x, largest(res.x)


def fit_dscale(omega, mag, weight=None, *, max_order: int = 4, tol: float = 0.05):
    """D-scale fit with automatic order: the lowest order (0 … ``max_order``) whose weighted
    largest log-magnitude error is below ``log(1 + tol)``, as MATLAB's ``musyn`` selects its
    fit orders; the best order if none is.

    Each order is fitted by :func:`fit_magnitude`'s stable, minimum-phase parametrisation
    (weighted log-magnitude least squares, several starts, poles and zeros within a decade
    of the grid).

    Parameters
    ----------
    omega, mag : array_like, shape (F,)
        Frequencies (rad/s, > 0) and D-scale magnitudes (> 0).
    weight : array_like, shape (F,), optional
        Non-negative weights; :func:`musyn` weights by ``(μ(ω)/max μ)⁴`` so that the fit is
        good where μ peaks. Uniform by default.
    max_order : int
        Highest order tried (0–4).
    tol : float
        Relative magnitude tolerance.

    Returns
    -------
    fit : control.TransferFunction
    order : int
    error : float
        Weighted largest |log-magnitude error| of the fit.

    Raises
    ------
    ConfigError
        Non-positive or non-finite data, or ``max_order`` outside 0–4.
    """
    return _fit_dscale(omega, mag, weight, max_order=max_order, tol=tol)[:3]


def _fit_dscale(omega, mag, weight=None, *, max_order: int = 4, tol: float = 0.05,
                start=None):
    """:func:`fit_dscale`, returning ``(fit, order, error, (x, order))``: x the fit's
    coordinates (:func:`_fit_from`). ``start``, such a ``(x, order)`` of an earlier fit of
    the same D under other weights (D–G–K's reweighting rounds,
    :func:`ambseal.robust.dgk._dg_step_scalings`): one fit at its order from it, in place
    of the orders and starts — the continuation of that fit as its weights move."""
    w, d = np.asarray(omega, float), np.asarray(mag, float)
    if not (isinstance(max_order, (int, np.integer)) and 0 <= max_order <= 4):
        raise ConfigError(f"max_order={max_order!r}: the D-scale fit order must be 0–4")
    if w.shape != d.shape or w.ndim != 1 or np.any(w <= 0) or np.any(~np.isfinite(d)) \
            or np.any(d <= 0):
        raise ConfigError("fit_dscale: omega and mag must be positive, finite, equal-length")
    wgt = np.ones_like(w) if weight is None else np.maximum(np.asarray(weight, float), 1e-6)
    y = np.log(np.clip(d, 1e-8, 1e8))
    lw = np.log(w)
    best = None
    orders = range(max_order + 1) if start is None else (start[1],)
    for order in orders:
        if order == 0:
            x = np.array([np.average(y, weights=wgt)])
            err = float(np.max(np.abs(x[0] - y) * wgt / wgt.max()))
        elif start is None:
            x, err = _fit_weighted(w, y, order, wgt, [
                (lw.mean(), 1.0), (lw.mean(), 0.5), (lw.mean() - 1.5, 1.0),
                (lw.mean() + 1.5, 1.0)])
        else:  # the numerator's and the denominator's sections, each interchangeable
            sec, _ = _d_sections(order)
            num, den = np.split(sec, 2)
            x, err = _fit_weighted(w, y, order, wgt, [untied(
                start[0], [[[i, i + 1] for i in half] for half in (num, den)])])
        if best is None or err < best[2] * 0.9:
            best = (x, order, err)
        if err <= np.log1p(tol):
            break
    x, order, err = best
    if order == 0:
        return ct.tf([float(np.exp(x[0]))], [1.0]), 0, err, (x, 0)
    num, den = _theta_to_tf(_d_theta(x, order), order)
    return ct.tf(num, den), order, err, (x, order)


def default_omega(P, n: int = 120) -> np.ndarray:
    """Log-spaced grid (rad/s) two decades around the plant's pole magnitudes."""
    poles = np.abs(np.linalg.eigvals(np.asarray(P.A, float))) if P.nstates else np.array([1.0])
    poles = poles[poles > 1e-9]
    lo = poles.min() / 100 if poles.size else 1e-2
    hi = poles.max() * 100 if poles.size else 1e2
    return np.logspace(np.log10(lo), np.log10(hi), n)


def design_omega(f_min_hz: float, f_max_hz: float, n: int = 60) -> np.ndarray:
    """A μ design grid (rad/s): ``n`` points log-spaced over f_min … f_max (Hz), the
    synthesis band (the D-step, the μ peak and an order reduction's check); 60 points
    (≈ 18 per decade over 3.3 decades) resolve the D scales, which vary slowly, and keep a
    D–K iteration at seconds. A lightly damped peak between grid points is missed by the μ
    peak on the grid: a design is to be judged afterwards on a dense grid.

    Parameters
    ----------
    f_min_hz, f_max_hz : float
        The band (Hz).
    n : int, optional
        Points of the grid.

    Returns
    -------
    numpy.ndarray of float, shape (n,)
        The grid (rad/s).

    Raises
    ------
    ConfigError
        ``0 < f_min_hz < f_max_hz`` and ``n ≥ 2`` not met.
    """
    if not (np.isfinite(f_min_hz) and np.isfinite(f_max_hz) and 0 < f_min_hz < f_max_hz) \
            or int(n) < 2:
        raise ConfigError(f"design_omega: need 0 < f_min_hz < f_max_hz and n ≥ 2, got "
                          f"{f_min_hz}, {f_max_hz}, {n}")
    return 2 * np.pi * np.logspace(np.log10(f_min_hz), np.log10(f_max_hz), int(n))


# --------------------------------------------------------------------------- result
@dataclass(frozen=True)
class MusynResult:
    """Result of :func:`musyn`.

    Attributes
    ----------
    K : control.StateSpace
        Best controller found (lowest peak μ), named after P's measurement/control channels.
    mu : float
        Peak μ upper bound of ``F_l(P, K)`` with the given block structure, over ``omega``
        and the points added around the curve's peaks (``check_omega``): a value an
        independent check on a finer grid reproduces, not the grid's.
    mu_omega : float
        Frequency (rad/s) of that peak.
    mu_curve : ndarray, shape (len(omega),)
        μ upper bound over ``omega`` for ``K``.
    omega : ndarray
        Frequency grid in rad/s.
    gamma : float
        Verified H∞ norm of the D-scaled closed loop of the best iteration.
    history : tuple of dict
        Per iteration: ``iteration``, ``gamma`` (K-step), ``mu`` (peak upper bound),
        ``order`` (controller states); the D search's entry also ``step = "D search"`` and
        ``evaluations`` (γ evaluations).
    best_iteration : int
        Index into ``history`` of ``K``.
    scalings : tuple
        Fitted D scales (``control.TransferFunction``) used for the best K, one per block
        of the complexified structure except the last (performance) block.
    alternatives : tuple of dict
        Other candidate controllers worth keeping (D–G–K: the best complex D–K controller,
        when it is not ``K``), each ``{"step", "K", "mu", "gamma"}``: an order reduction
        may favour one of them.
    mu_grid : float
        Peak μ upper bound of ``K`` on ``omega`` alone (``mu ≥ mu_grid``).
    check_omega : ndarray
        The frequencies (rad/s) ``mu`` is the largest upper bound over: ``omega`` and the
        points added around its local maxima (:func:`~ambseal.robust.mu.mu_peak`).
    check_mu : ndarray
        The upper bound at ``check_omega``.
    check : str
        One line naming that grid.
    elapsed_s : float
        CPU time of the synthesis (s, this process): a measurement, never a stopping rule.
    stopping : dict
        Why each phase ended: ``start`` ``{"scales", "evaluations", "rule"}`` (the constant
        D of the uncertainty channels D–K starts from, one per scale, in ``P``'s units),
        ``dk`` (and with D–G–K ``dgk``) ``{"iterations", "rule"}``, ``search``
        ``{"granted", "evaluations", "rule"}`` (γ evaluations allowed and made).
    closed_loop : control.StateSpace
        ``F_l(P, K)`` from the exogenous inputs to the exogenous outputs.
    """

    K: Any
    mu: float
    mu_omega: float
    mu_curve: np.ndarray = field(repr=False)
    omega: np.ndarray = field(repr=False)
    gamma: float = float("nan")
    history: tuple = ()
    best_iteration: int = 0
    scalings: tuple = field(default=(), repr=False)
    alternatives: tuple = field(default=(), repr=False)
    mu_grid: float = float("nan")
    check_omega: np.ndarray | None = field(default=None, repr=False)
    check_mu: np.ndarray | None = field(default=None, repr=False)
    check: str = ""
    elapsed_s: float = float("nan")
    stopping: dict = field(default_factory=dict)
    closed_loop: Any = field(default=None, repr=False)

    @property
    def order(self) -> int:
        """Number of controller states."""
        return int(self.K.nstates)

    def __iter__(self):
        """``K, CL, mu, info = musyn(P, blocks, nmeas, ncon)``: controller, closed loop,
        μ and this result, in the order of python-control's synthesis functions."""
        return iter((self.K, self.closed_loop, self.mu, self))

    def to_dict(self) -> dict:
        """JSON-ready summary."""
        return {"mu": self.mu, "mu_omega_rad_s": self.mu_omega, "mu_grid": self.mu_grid,
                "mu_check": self.check, "gamma": self.gamma,
                "order": self.order, "best_iteration": self.best_iteration,
                "history": [dict(h) for h in self.history],
                "omega_rad_s": np.asarray(self.omega).tolist(),
                "mu_curve": np.asarray(self.mu_curve).tolist(),
                "check_omega_rad_s": (None if self.check_omega is None
                                      else np.asarray(self.check_omega).tolist()),
                "elapsed_s": self.elapsed_s, "stopping": self.stopping}


# --------------------------------------------------------------------------- D–K
def _check_counts(**values) -> None:
    """The stopping rules' counts and tolerances: ``max_iter`` (or None) and ``patience``
    whole numbers ≥ 1, ``rtol`` ≥ 0, ``backoff`` ≥ 1 and ``fit_tol`` > 0, all finite
    (ConfigError)."""
    for name, x in values.items():
        if name == "max_iter" and x is None:
            continue
        if name in ("max_iter", "patience"):
            ok = isinstance(x, (int, np.integer)) and not isinstance(x, bool) and x >= 1
            want = "a whole number ≥ 1"
        else:
            low = {"rtol": 0.0, "backoff": 1.0}.get(name)
            ok = isinstance(x, (int, float, np.floating)) and np.isfinite(x) and (
                x >= low if low is not None else x > 0)
            want = f"a finite number ≥ {low:g}" if low is not None else "a finite number > 0"
        if not ok:
            raise ConfigError(f"{name}={x!r}: expected {want}")


def _check(P, K, blocks, nmeas, ncon, w, upper):
    """μ of ``F_l(P, K)`` re-checked between the grid points around its peaks
    (:func:`~ambseal.robust.mu.mu_peak`)."""
    return mu_peak(lft_lower(P, K, nmeas, ncon), blocks, w, upper)


def progress_printer(progress) -> Any:
    """Where the μ syntheses' iteration lines go: ``None`` (false), an object whose
    ``print(line)`` calls ``progress(line)`` (a callable, e.g. the main job's logger), or
    rich's stderr console (true)."""
    if not progress:
        return None
    if callable(progress):
        return _Lines(progress)
    return Console(stderr=True)


@dataclass(frozen=True)
class _Lines:
    """``print(line)`` → ``say(line)``."""

    say: Any

    def print(self, line: str) -> None:
        self.say(line)


@with_numerics_threads
def musyn(P, blocks: Sequence[Sequence[int]], nmeas: int, ncon: int, omega=None, *,
          order: int | str = "auto", max_iter: int | None = None, rtol: float = 1e-2,
          patience: int = 2, backoff: float = 1.01, fit_tol: float = 0.05,
          search: int | str = "auto", search_backoff: float = 1.001,
          progress: Any = False) -> MusynResult:
    """μ-synthesis by complex D–K iteration (Balas et al. 1993), then a
    direct search over the D scales.

    The uncertainty channels are first balanced (and the result says so in
    ``stopping["start"]``): μ does not change under a constant D that commutes with Δ,
    but D–K, a local method, ends where its start leads it, and MATLAB's start D = I
    lies wherever the user's units put it (Skogestad & Postlethwaite's column with
    w_Δ × 1e5, z_Δ ÷ 1e5: μ 1.34 instead of 0.98). D–K starts instead from the constant
    D of :func:`~ambseal.robust._dscale._balance_channels` — an RMS balance of each
    block's rows and columns, then Nelder–Mead for the D of the smallest γ_opt
    (started when its estimated work, ``START_EVALS_PER_SCALE`` γ evaluations per scale,
    is within ``START_WORK``, and ended where its simplex has converged or by the D
    search's stall rule; none with ``search=0``) — the same plant in any units of the
    channels, so μ and the controller are too (to rounding; tests: 12 decades).

    The steps, after Balas et al. (1993) and MATLAB's ``musyn`` (D-K Iteration Process,
    Robust Control Toolbox documentation): a K-step (H∞ synthesis on ``D P D⁻¹`` at
    ``backoff·γ_opt``), the μ upper bound of the closed loop on ``omega``, a D-step (the
    bound's scalings fitted by stable, minimum-phase functions of automatically chosen
    order), until μ stops improving; the best iterate is kept, not the last. A K-step that
    fails on dynamic fits (a scaled plant no controller is found for) is redone once with
    the same D-step's constant scalings before the iterations end. D–K then often
    stalls a few per cent above the μ-optimum: each D-step fits the D that is optimal for the
    *current* K, not the D whose K-step is best. So a direct search over the fitted
    scales' parameters for the smallest γ_opt of ``D P D⁻¹`` follows
    (:func:`~ambseal.robust._dscale._search_dscales`, Nelder–Mead with restarts). Finally
    μ of the kept controller is re-checked between the grid points around the curve's
    peaks (:func:`~ambseal.robust.mu.mu_peak`): the reported μ is that value, and the
    result names the frequencies it was computed at.

    Parameters
    ----------
    P : control.StateSpace
        Generalised plant, inputs ``[w_Δ, w, u]``, outputs ``[z_Δ, z, y]``.
    blocks : sequence of (int, int)
        MATLAB-style structure covering all exogenous channels (Σc = number of z outputs,
        Σr = number of w inputs); the last block is the fictitious performance block.
    nmeas, ncon : int
        Number of measurements and control inputs.
    omega : array_like, optional
        Frequency grid in rad/s for the D-step and μ (default: :func:`default_omega`).
    order : int or "auto"
        Order (0–4) of each fitted D scale; ``"auto"``: per scale and iteration the lowest
        order whose fit, weighted by ``(μ(ω)/max μ)⁴``, is within ``fit_tol``
        (:func:`fit_dscale`; MATLAB ``musyn`` also chooses its fit orders by the fit's
        error).
    max_iter : int, optional
        A cap on the number of D–K iterations (the first is plain H∞), for a caller who
        wants one. None (default): the iterations end by the stall rule (``rtol``,
        ``patience``) alone, which always ends them: μ is bounded below, and each
        ``patience`` iterations must lower the best μ by the factor ``1 − rtol``.
    rtol : float
        Relative improvement of peak μ below which an iteration counts as no progress.
    patience : int
        Stop after this many iterations without progress.
    backoff : float
        K-step: the controller is built at ``backoff·γ_opt``, γ_opt found to 1e-6 relative
        by :func:`~ambseal.robust.hinf.hinfsyn` (e.g. 1.001: within 0.1 % of the optimum).
    fit_tol : float
        Relative magnitude tolerance of the automatic D-scale fit order.
    search : int or "auto"
        The D search after the iterations. ``"auto"`` (default): started when its
        estimated work, ``SEARCH_EVALS_PER_PARAMETER`` (50) γ evaluations per parameter of
        the fitted scales × n³ with n the states of the scaled plant, is within
        ``SEARCH_WORK`` (10⁸), a decision by the problem's size that is the same on every
        machine; it then ends by its stall rule (the best γ_opt must fall by 0.1 % within
        30 evaluations per parameter) or when a restart of its simplex gains less than
        0.01 %. A number caps it (and the best-constant-D start) at that many γ
        evaluations; 0: none. Its controller (at ``search_backoff``) is kept when its μ is
        lower, recorded in ``history`` with ``step = "D search"``. On Skogestad &
        Postlethwaite's distillation problem (§8.12.4) D–K stalls at μ 1.10 and the search
        ends below the published μ-optimal 0.974 (benchmarks/bench_dk.py); on plants of
        80 states or more it is not started.
    search_backoff : float
        The controller of the D found by the search is built at ``search_backoff·γ_opt``:
        the search minimised γ_opt, and a controller ``backoff`` (1 %) above it gives back
        much of the gain (Mackenroth's aircraft, ``benchmarks/bench_dk.py``: μ 0.985 at
        1.01·γ_opt, 0.978 at 1.001·γ_opt). :func:`~ambseal.robust.hinf.hinfsyn` raises it
        when the closed loop is not stable.
    progress : bool or callable
        One line per iteration: printed on stderr (rich) if true, or passed to
        ``progress(line)`` (:func:`progress_printer`).

    Returns
    -------
    MusynResult
        The best controller (not the last); ``mu`` its μ re-checked around the peaks,
        ``check_omega`` the frequencies of that check, ``mu_grid`` the peak on ``omega``
        alone, ``stopping`` the rule that ended the iterations and the search.

    Raises
    ------
    ModelError, ConfigError
        Blocks that do not match P's exogenous channels (ModelError); bad order, grid,
        counts or tolerances (ConfigError).
    SynthesisError
        If the first K-step fails (plant assumptions violated).

    References
    ----------
    Balas, Doyle, Glover, Packard & Smith, μ-Analysis and Synthesis Toolbox (1993);
    Skogestad & Postlethwaite, Multivariable Feedback Control (2005) §8.12; Lagarias, Reeds,
    Wright & Wright, SIAM J. Optim. 9 (1998) 112–147 (Nelder–Mead); Kelley, Iterative
    Methods for Optimization (1999) §8.1 (restarts).
    """
    t0 = time.process_time()
    cblocks, unchecked = _structure(P, blocks, nmeas, ncon, "musyn")
    _check_settings(order, search, search_backoff)
    _check_counts(max_iter=max_iter, patience=patience, rtol=rtol, backoff=backoff,
                  fit_tol=fit_tol)
    P_user, w = P, _grid(P, omega, "musyn")
    console = progress_printer(progress)
    P, (bal, n_start, start_rule) = _balanced_start(P, cblocks, unchecked, nmeas, ncon, w,
                                                    search)

    history, best = [], None
    fits: list = []
    stall, rule = 0, f"max_iter={max_iter}"
    last = None  # the previous complexified μ, for a D-step redone with static fits
    near = None  # the last K-step's γ_opt
    for it in (itertools.count() if max_iter is None else range(max_iter)):
        Ps = _scaled_plant(P, cblocks, fits, nmeas, ncon) if fits else P
        try:
            # the last K-step's γ_opt starts the search: a D-step moves it by a few %
            hr = hinfsyn(Ps, nmeas, ncon, backoff=backoff, near=near)
        except SynthesisError as exc:
            if it == 0:
                raise
            # a dynamic fit can make the scaled plant one no controller is found for (jω
            # zeros, rank loss) where its static scalings are not: redo the D-step with
            # constant fits before ending the iterations
            static = _d_step(w, last, 0, fit_tol) if order != 0 else None
            try:
                if static is None:
                    raise exc
                hr = hinfsyn(_scaled_plant(P, cblocks, static, nmeas, ncon), nmeas, ncon,
                             backoff=backoff)
            except SynthesisError as again:
                rule = f"K-step {it} failed ({again})"
                break
            fits = static
            if console is not None:
                console.print(f"D-K {it}: the K-step failed on the fitted scalings ({exc}); "
                              "static scalings taken")
        near = hr.gamma_opt
        cl = lft_lower(P, hr.K, nmeas, ncon)
        mu_c, curve = _mu_step(cl, blocks, w)
        peak = float(np.max(curve))
        history.append({"iteration": it, "gamma": hr.gamma, "mu": peak, "order": hr.order})
        if console is not None:
            console.print(f"D-K {it}: γ = {hr.gamma:.4g}, μ = {peak:.4g}, order {hr.order}")
        if best is None or peak < best[0] * (1 - rtol):
            stall = 0
        else:
            stall += 1
        if best is None or peak < best[0]:
            best = (peak, it, hr, curve, tuple(fits))
        if stall >= patience:
            rule = f"patience={patience}: {stall} iterations without a μ gain of rtol={rtol:g}"
            break
        last = mu_c
        fits = _d_step(w, mu_c, order, fit_tol)
    finalists = [_finalist(best)]
    n_scaled = _scaled_plant(P, cblocks, best[4], nmeas, ncon).nstates if best[4] else 0
    evals, granted = _search_evals(search, best[4], n_scaled)
    stopping = {"start": {"scales": bal, "evaluations": n_start, "rule": start_rule},
                "dk": {"iterations": len(history), "rule": rule},
                "search": {"granted": evals, "evaluations": 0, "rule": granted}}
    if evals != 0:
        found, done = _search_step(P, blocks, cblocks, nmeas, ncon, w, best, evals,
                                   search_backoff, history, console)
        stopping["search"].update(done, rule=f"{granted}; {done['rule']}")
        if found is not None:
            finalists.append(_finalist(found))
    finalists = [f[:5] + (tuple(map(_unbalanced_fit, f[5], bal)),) for f in finalists]
    # μ re-checked on the balanced loop (the same μ, better conditioned); the closed loop
    # returned in the user's units
    r = _result(P, blocks, nmeas, ncon, w, finalists, history, t0, stopping=stopping)
    return replace(r, closed_loop=lft_lower(P_user, r.K, nmeas, ncon))


def result_scalings(r: MusynResult) -> tuple:
    """The D scales a :func:`musyn` result's controller was designed with, in its plant's
    units: its fitted ``scalings``, or where the best iteration was the first (no fit
    yet), the constant D of the uncertainty channels D–K started from
    (``stopping["start"]["scales"]``).

    Parameters
    ----------
    r : MusynResult
        A :func:`musyn` result.

    Returns
    -------
    tuple of control.TransferFunction
        One D scale per uncertainty block of the complexified structure
        (:func:`dscaled_plant`'s ``scalings``).
    """
    if r.scalings:
        return tuple(r.scalings)
    return tuple(ct.tf([float(b)], [1.0]) for b in r.stopping["start"]["scales"])


def dscaled_plant(P, blocks: Sequence[Sequence[int]], scalings, nmeas: int, ncon: int):
    """``diag(D, I) · P · diag(D⁻¹, I)``: a generalised plant with its uncertainty channels
    scaled by D–K's D scales (the K-step's plant, Zhou, Doyle & Glover 1996 §11.3).

    Parameters
    ----------
    P : control.StateSpace
        Generalised plant, inputs ``[w_Δ, w_p, u]``, outputs ``[z_Δ, z_p, y]``.
    blocks : sequence of (int, int)
        Its structure (MATLAB ``mussv`` notation), the last block the performance block.
    scalings : sequence
        One D scale per block of the complexified structure but the last
        (:func:`result_scalings` of a :func:`musyn` result on a plant of the same
        structure): a ``control.TransferFunction``, stable and minimum phase.
    nmeas, ncon : int
        Measurements and controls.

    Returns
    -------
    control.StateSpace
        The scaled plant, ``P``'s channels and names; the D scales' states after ``P``'s.

    Raises
    ------
    ModelError
        Blocks that do not match ``P``, or not one scale per uncertainty block.
    """
    cblocks, _ = _structure(P, blocks, nmeas, ncon, "dscaled_plant")
    if len(scalings) != len(cblocks) - 1:
        raise ModelError(f"dscaled_plant: {len(scalings)} D scales for "
                         f"{len(cblocks) - 1} uncertainty blocks")
    return _scaled_plant(P, cblocks, list(scalings), nmeas, ncon)


def _grid(P, omega, who: str) -> np.ndarray:
    """The frequency grid (rad/s): ``omega`` checked, or :func:`default_omega`."""
    w = default_omega(P) if omega is None else np.asarray(omega, float)
    if w.ndim != 1 or w.size < 2 or np.any(w <= 0) or not np.all(np.isfinite(w)):
        raise ConfigError(f"{who}: omega must be a 1-D grid of positive rad/s values")
    return w


def _structure(P, blocks, nmeas, ncon, who: str):
    """The plant and its blocks checked (ModelError; SynthesisError): ``(cblocks,
    unchecked)``, the complexified structure and whether the plant's assumptions are left
    to check on the balanced plant (they fail only in the Δ channels' units)."""
    try:
        check_plant(P, nmeas, ncon)
        unchecked = False
    except SynthesisError:  # its rank tests depend on the Δ channels' units: judged balanced
        unchecked = True
    blks = check_blocks(P, blocks, nmeas, ncon)
    if blks[-1].kind != "full":
        raise ModelError(f"{who}: the last block must be the full complex performance block")
    return _complexify(blks), unchecked


def _balanced_start(P, cblocks, unchecked, nmeas, ncon, w, search):
    """D–K's start: ``(P_b, (scales, evaluations, rule))``, the plant with its uncertainty
    channels at the constant D of :func:`_balance_channels`, and its assumptions checked
    there where :func:`_structure` left them (SynthesisError)."""
    start = _start_evals(search, cblocks, P.nstates)
    P, *rest = _balance_channels(P, cblocks, nmeas, ncon, w, start)
    if unchecked:
        check_plant(P, nmeas, ncon)
    return P, tuple(rest)


@dataclass(frozen=True)
class ScaledHinfResult:
    """Result of :func:`scaled_hinfsyn`.

    Attributes
    ----------
    K : control.StateSpace
        Controller ``u = K y`` (the same ``u`` and ``y`` as ``P``'s).
    gamma : float
        ``‖D F_l(P, K) D⁻¹‖_∞`` at the constant scalings D: below 1, it certifies every
        Δ of the structure with σ̄(Δ) ≤ 1 by the small-gain theorem.
    gamma_opt : float
        γ_opt of the scaled plant.
    stopping : dict
        ``start`` ``{"scales", "evaluations", "rule"}`` (as :class:`MusynResult`'s).
    elapsed_s : float
        CPU time (s, this process): a measurement.
    """

    K: Any
    gamma: float
    gamma_opt: float
    stopping: dict = field(default_factory=dict)
    elapsed_s: float = float("nan")


@with_numerics_threads
def scaled_hinfsyn(P, blocks: Sequence[Sequence[int]], nmeas: int, ncon: int, omega=None,
                   *, backoff: float = 1.01, search: int | str = "auto") -> ScaledHinfResult:
    """H∞ synthesis at D–K's starting constant scalings (the RMS balance of the uncertainty
    channels, then the smallest γ_opt where ``search`` allows): :func:`musyn`'s start and
    first K-step, without its μ analysis (Zhou, Doyle & Glover, *Robust and Optimal
    Control*, 1996, §11.3: scaled H∞).

    The same controller and γ as ``musyn(P, blocks, nmeas, ncon, omega, order=0,
    max_iter=1, backoff=backoff, search=search)``, whose μ of the closed loop (the D–G
    upper bound over ``omega`` and its re-check around the peaks) a caller that wants the
    certificate of γ alone does not need.

    Parameters
    ----------
    P : control.StateSpace
        Generalised plant, inputs ``[w_Δ, w, u]``, outputs ``[z_Δ, z, y]``.
    blocks : sequence of (int, int)
        The structure (:func:`musyn`'s); the last block is the performance block.
    nmeas, ncon : int
        Number of measurements and control inputs.
    omega : array_like, optional
        Frequency grid in rad/s of the channels' RMS balance (default:
        :func:`default_omega`).
    backoff : float
        The controller is built at ``backoff·γ_opt`` (:func:`~ambseal.robust.hinf.hinfsyn`).
    search : int or "auto"
        The search for the constant D (:func:`musyn`'s ``search``, which also caps it).

    Returns
    -------
    ScaledHinfResult

    Raises
    ------
    ModelError, ConfigError
        Blocks that do not match P's exogenous channels, a bad grid or setting.
    SynthesisError
        No controller for the scaled plant (plant assumptions violated).
    """
    t0 = time.process_time()
    cblocks, unchecked = _structure(P, blocks, nmeas, ncon, "scaled_hinfsyn")
    _check_settings(0, search, 1.0)
    _check_counts(backoff=backoff)
    w = _grid(P, omega, "scaled_hinfsyn")
    Pb, (bal, n_start, start_rule) = _balanced_start(P, cblocks, unchecked, nmeas, ncon, w,
                                                     search)
    hr = hinfsyn(Pb, nmeas, ncon, backoff=backoff)
    return ScaledHinfResult(
        K=hr.K, gamma=float(hr.gamma), gamma_opt=float(hr.gamma_opt),
        stopping={"start": {"scales": bal, "evaluations": n_start, "rule": start_rule}},
        elapsed_s=time.process_time() - t0)


def _check_settings(order, search, search_backoff) -> None:
    """:func:`musyn`'s D-scale order, search and search back-off; ConfigError if bad."""
    if order != "auto" and not (isinstance(order, (int, np.integer)) and 0 <= order <= 4):
        raise ConfigError(f"order={order!r}: the D-scale fit order must be 0–4 or 'auto'")
    if not (search == "auto" or (isinstance(search, (int, np.integer)) and search >= 0)):
        raise ConfigError(f"search={search!r}: expected a number of γ evaluations ≥ 0 or "
                          f"'auto'")
    if not (isinstance(search_backoff, (int, float)) and search_backoff >= 1):
        raise ConfigError(f"search_backoff={search_backoff!r}: expected a number ≥ 1")


def _mu_step(cl, blocks, w):
    """The μ-step on the closed loop ``cl``: the complexified structure's bound (whose
    scalings the D-step fits) and the upper bound of the structure as given on ``w``
    (:func:`~ambseal.robust.mu.upper_on_grid`)."""
    return upper_on_grid(cl, blocks, w)


def _d_step(w, mu_c, order, fit_tol) -> list:
    """The D-step from the complexified structure's bound ``mu_c`` on ``w``: the D scales'
    fits, one per block but the last (weighted by μ⁴ towards its peak with
    ``order="auto"``)."""
    ds = np.asarray(mu_c.dscale)  # (F, nblocks), last block = 1
    if order == "auto":
        wgt = (mu_c.upper / np.max(mu_c.upper)) ** 4
        return [fit_dscale(w, ds[:, j], wgt, tol=fit_tol)[0] for j in range(ds.shape[1] - 1)]
    return [fit_magnitude(w, ds[:, j], order) for j in range(ds.shape[1] - 1)]


def _finalist(entry):
    """``(μ on the grid, index, K, γ, μ curve, fits)`` of a ``(μ, index, HinfResult,
    μ curve, fits)`` iterate."""
    peak, it, hr, curve, fits = entry
    return (peak, it, hr.K, float(hr.gamma), curve, fits)


def _result(P, blocks, nmeas, ncon, w, finalists, history, t0, alternatives=(),
            stopping=None):
    """The finalist ``(μ on the grid, index, K, γ, μ curve on w, fits)`` with the lowest μ
    re-checked around its peaks (:func:`_check`), as a MusynResult."""
    checked = [(_check(P, f[2], blocks, nmeas, ncon, w, f[4]), f) for f in finalists]
    pk, (_, it, K, gamma, curve, fits) = min(checked, key=lambda c: c[0].peak)
    return MusynResult(K=K, mu=pk.peak, mu_omega=pk.omega_peak, mu_curve=curve, omega=w,
                       gamma=gamma, history=tuple(history), best_iteration=it,
                       scalings=fits, alternatives=tuple(alternatives), mu_grid=pk.grid_peak,
                       check_omega=pk.omega, check_mu=pk.upper, check=pk.describe(),
                       elapsed_s=time.process_time() - t0, stopping=dict(stopping or {}),
                       closed_loop=lft_lower(P, K, nmeas, ncon))
