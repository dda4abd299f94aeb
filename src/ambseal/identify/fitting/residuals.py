"""Residual analysis of a closed-loop output-error fit (Ljung, *System Identification*,
2nd ed., §16.6).

Two tests per displacement channel, each a χ² statistic against its 99 % quantile:

- **whiteness**: ζ_w = N Σ_{τ=1..M} ρ_ε(τ)², ρ_ε the residual's normalised
  autocorrelation; χ²(M) when ε is white.
- **independence of the excitation**: the residual is first prewhitened by an AR(n_a) filter
  A(q) fitted to it (least squares), the excitation of every axis filtered by the same A(q);
  then ζ_u = N r̂ᵀ R̂_φ⁻¹ r̂ / λ̂ with φ(t) the filtered excitations at lags 0..M−1, r̂ their
  cross-covariance with the whitened residual and λ̂ its variance — χ²(rank R̂_φ) when ε is
  independent of the excitation (Ljung Eq. 16.66 on prewhitened signals). It equals
  N·R² of the regression of the whitened residual on the lagged excitations.

What a failure means here: the model is an *output-error* model and the loop is closed, so
even a correct model leaves ε = S_o n — the sensor noise coloured by the output sensitivity —
and the whiteness test is expected to fail; it is reported, and the model is not judged by it
(Ljung §16.6: with no noise model estimated, the independence test is the relevant one). The
excitation is the only signal independent of the noise, so residuals correlated with it mean
dynamics the model does not reproduce: "model mismatch: intervals understate the
uncertainty". With a correct model, a channel fails at the 1 % level by chance.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.signal import lfilter
from scipy.stats import chi2

__all__ = ["ResidualTests", "residual_tests", "MISMATCH"]

MISMATCH = "model mismatch: intervals understate the uncertainty"


@dataclass(frozen=True)
class ResidualTests:
    """Per-channel residual statistics of a fit.

    Attributes
    ----------
    channels : tuple of str
    whiteness, whiteness_limit : ndarray (c,)
        ζ_w and its χ²(M) 99 % quantile (summed over records).
    independence, independence_limit : ndarray (c,)
        ζ_u and its χ² 99 % quantile.
    lags : int
        M.
    ar_order : int
        n_a of the prewhitening filter.
    autocorrelation : ndarray (c, M + 1)
        ρ_ε(τ), τ = 0..M, of the first record (for the figure).
    cross_correlation : ndarray (c, 2M + 1)
        Normalised cross-correlation of the whitened residual of channel c with the filtered
        excitation of the same axis, τ = −M..M (first record).
    band : float
        The 99 % band ±2.58/√N of the correlations (first record).
    block : int
        Samples per block d of the first record (lags count blocks).
    """

    channels: tuple[str, ...]
    whiteness: np.ndarray
    whiteness_limit: np.ndarray
    independence: np.ndarray
    independence_limit: np.ndarray
    lags: int
    ar_order: int
    autocorrelation: np.ndarray
    cross_correlation: np.ndarray
    band: float
    block: int = 1

    @property
    def failed(self) -> list[str]:
        """Channels whose residuals correlate with the excitation."""
        return [c for c, z, lim in zip(self.channels, self.independence,
                                       self.independence_limit) if z > lim]

    @property
    def mismatch(self) -> bool:
        return bool(self.failed)

    def to_dict(self) -> dict:
        return {
            "test": "Ljung §16.6, χ² at 99 %; whiteness informative only (output-error model "
                    "in closed loop), independence of the excitation decides",
            "lags": self.lags, "ar_order": self.ar_order, "block_samples": self.block,
            "channels": {c: {"whiteness": float(w), "whiteness_limit": float(wl),
                             "white": bool(w <= wl),
                             "independence": float(z), "independence_limit": float(zl),
                             "independent": bool(z <= zl)}
                         for c, w, wl, z, zl in zip(self.channels, self.whiteness,
                                                    self.whiteness_limit, self.independence,
                                                    self.independence_limit)},
            "mismatch": self.mismatch,
            "verdict": MISMATCH if self.mismatch else "residuals independent of the excitation",
        }


def _autocorr(x: np.ndarray, m: int) -> np.ndarray:
    x = x - x.mean()
    n = x.size
    f = np.fft.rfft(x, 2 * n)
    r = np.fft.irfft(f * f.conj())[: m + 1]
    return r / r[0] if r[0] > 0 else np.zeros(m + 1)


def _ar_filter(x: np.ndarray, na: int) -> np.ndarray:
    """Coefficients [1, a_1..a_na] of the least-squares AR(na) whitening filter of ``x``."""
    n = x.size
    X = np.column_stack([x[na - j - 1:n - j - 1] for j in range(na)])
    a = np.linalg.lstsq(X, -x[na:], rcond=None)[0]
    return np.concatenate([[1.0], a])


def _lagged(U: np.ndarray, m: int) -> np.ndarray:
    """Rows t = m−1..N−1 of [u_j(t − τ)] for every column j and τ = 0..m−1."""
    n = U.shape[0]
    return np.column_stack([U[m - 1 - tau:n - tau, j] for j in range(U.shape[1])
                            for tau in range(m)])


def _one_record(eps: np.ndarray, U: np.ndarray, m: int, na: int):
    """(ζ_w, M, ζ_u, dof, ρ_ε, ρ_εu) of one channel of one record."""

    n = eps.size
    rho = _autocorr(eps, m)
    zw = n * float(np.sum(rho[1:] ** 2))
    a = _ar_filter(eps - eps.mean(), na)
    ew = lfilter(a, [1.0], eps - eps.mean())[na:]
    Uw = lfilter(a, [1.0], U - U.mean(axis=0), axis=0)[na:]
    Phi = _lagged(Uw, m)
    y = ew[m - 1:]
    coef, _, rank, _ = np.linalg.lstsq(Phi, y, rcond=None)
    fitted = Phi @ coef
    zu = y.size * float(fitted @ fitted) / float(y @ y) if y @ y > 0 else 0.0
    return zw, zu, int(rank), rho, ew, Uw


def _xcorr(a: np.ndarray, b: np.ndarray, m: int) -> np.ndarray:
    """ρ_ab(τ) = Σ a(t) b(t−τ) / (N σ_a σ_b), τ = −m..m."""
    a, b = a - a.mean(), b - b.mean()
    n = a.size
    full = np.correlate(a, b, mode="full")[n - 1 - m:n + m]
    den = n * a.std() * b.std()
    return full / den if den > 0 else np.zeros(2 * m + 1)


def _correlation_length(E: np.ndarray, cap: int) -> int:
    """First lag where the excited axes' mean normalised autocorrelation is below 0.1,
    within [1, cap]."""
    cap = max(int(cap), 1)
    rows = [_autocorr(E[:, j], cap) for j in range(E.shape[1]) if np.ptp(E[:, j]) > 0]
    if not rows:
        return 1
    rho = np.mean(rows, axis=0)
    below = np.flatnonzero(rho < 0.1)
    return int(min(below[0] if below.size else cap, cap)) or 1


def _block_mean(X: np.ndarray, d: int) -> np.ndarray:
    """Means of consecutive blocks of ``d`` rows (d = 1: ``X``)."""
    if d <= 1:
        return X
    n = X.shape[0] // d
    return X[: n * d].reshape(n, d, X.shape[1]).mean(axis=1)


def residual_tests(residuals: list[np.ndarray], excitations: list[np.ndarray],
                   channels: tuple[str, ...], *, lags: int = 25, ar_order: int = 10,
                   level: float = 0.99, decimate: int | None = None) -> ResidualTests:
    """Whiteness and independence tests of a fit's residuals (module docstring).

    Parameters
    ----------
    residuals : list of ndarray (N_r, c)
        Displacement residuals y − ŷ of each record (any scaling per channel).
    excitations : list of ndarray (N_r, k)
        The excitation of each record over the same samples (A).
    channels : tuple of str
        Names of the c residual channels.
    lags : int
        M, the lags of both tests (Ljung's default 25).
    ar_order : int
        Order of the prewhitening filter of the independence test.
    level : float
        Quantile of the thresholds.
    decimate : int, optional
        Block length d: both tests run on means over blocks of d samples, so that M lags
        span the time over which the excitation can show a model error. Default: the
        excitation's correlation length (the first lag where its normalised autocorrelation,
        mean over the excited axes, falls below 0.1; 10 samples for a PRBS clocked at a
        tenth of the sample rate), at most N/(4(kM + n_a)) so the regression stays
        well-determined.

    Returns
    -------
    ResidualTests
        ζ_w and ζ_u per channel (summed over records) with their χ² limits at ``level``,
        and the first usable record's autocorrelations and cross-correlations for figures.
        A record too short for the tests (or without excitation) adds nothing.
    """
    c = len(channels)
    zw, dfw, zu, dfu = np.zeros(c), np.zeros(c), np.zeros(c), np.zeros(c)
    auto, cross, band, block = None, None, np.nan, 1
    for R, E in zip(residuals, excitations):
        R, E = np.asarray(R, float)[:, :c], np.asarray(E, float)
        d = decimate or _correlation_length(E, R.shape[0] // (4 * (E.shape[1] * lags
                                                                   + ar_order)))
        R, E = _block_mean(R, d), _block_mean(E, d)
        keep = np.ptp(E, axis=0) > 0  # unexcited axes carry no information
        if R.shape[0] <= 4 * (lags + ar_order) or not keep.any():
            continue
        rows_a, rows_x = [], []
        for j in range(c):
            w, u, rank, rho, ew, Uw = _one_record(R[:, j], E[:, keep], lags, ar_order)
            zw[j] += w
            dfw[j] += lags
            zu[j] += u
            dfu[j] += rank
            rows_a.append(rho)
            excited = list(np.flatnonzero(keep))
            own = Uw[:, excited.index(j) if j in excited else 0]  # the same axis if excited
            rows_x.append(_xcorr(ew, own, lags))
        if auto is None:
            auto, cross = np.array(rows_a), np.array(rows_x)
            band, block = 2.576 / np.sqrt(R.shape[0]), d
    lim_w = np.where(dfw > 0, chi2.ppf(level, np.maximum(dfw, 1)), np.inf)
    lim_u = np.where(dfu > 0, chi2.ppf(level, np.maximum(dfu, 1)), np.inf)
    if auto is None:
        auto, cross = np.zeros((c, lags + 1)), np.zeros((c, 2 * lags + 1))
    return ResidualTests(tuple(channels), zw, lim_w, zu, lim_u, lags, ar_order, auto, cross,
                         float(band), int(block))
