"""The sandwich covariance of a closed-loop output-error fit and its score tests.

Closed-loop residuals are coloured (sensor noise runs through the loop), so the covariance
of θ̂ is the sandwich (JᵀJ)⁻¹ S (JᵀJ)⁻¹ with S = Var(Jᵀr) from the residuals' cross-spectrum
(:func:`_long_run_covariance`, leverage-corrected), the 95 % intervals take Student's t with
the Satterthwaite degrees of freedom (:func:`_covariance`, :func:`_t_quantile`), and the
score test of a value the fit did not free uses the same long-run variance
(:func:`_score_test`). Used by :mod:`ambseal.identify.fitting.fit` (module docstring there).
"""

from __future__ import annotations

import numpy as np
from scipy.stats import t


def _long_run_covariance(J: np.ndarray, R: np.ndarray, smooth: int = 2,
                         Hinv: np.ndarray | None = None):
    """Var(Σ_t J_tᵀ r_t) for residuals r that are a stationary coloured process.

    Frequency-domain form of the sandwich's middle term (Ljung, *System Identification*,
    2nd ed., §9.3): Σ_f J(f)ᴴ Φ_r(f) J(f) / L with Φ_r the residuals' cross-spectral
    matrix across channels, estimated by the periodogram R(f)R(f)ᴴ/N averaged over
    2·``smooth``+1 neighbouring bins (Daniell window), and L = 2N (zero padding, no wrap).
    Closed-loop residuals ring at the loop's lightly damped resonances, where the Jacobian
    is also largest; a lag-window (Newey–West) estimate smooths those peaks away and
    understates the variance, this one keeps them.

    With ``Hinv`` = (JᵀJ)⁻¹ of the whole fit, the periodogram is first corrected for the
    fit's leverage: the residuals are orthogonal to J, so R(f) lacks about h(f) = w J(f)
    (JᵀJ)⁻¹ J(f)ᴴ / L of the noise where J is large (Σ_f tr h = p); P ← (I − h)⁻¹ P (I − h)⁻ᴴ,
    the HC3 form (MacKinnon & White, J. Econometrics 29, 1985; Long & Ervin, Am. Stat. 54,
    2000, recommend it for small samples), eigenvalues of I − h floored at 0.1.

    Parameters
    ----------
    J : ndarray (N, c, p)
        Jacobian per sample and channel.
    R : ndarray (N, c)
        Residuals.
    Hinv : ndarray (p, p), optional
        (JᵀJ)⁻¹ of the fit (all records).

    Returns
    -------
    S : ndarray (p, p)
        Without ``Hinv``.
    (S, b) : with ``Hinv``, also b (F, p): each frequency bin's share of the variance of
        (JᵀJ)⁻¹Jᵀr per parameter, spread by the smoothing window (for the effective
        degrees of freedom, :func:`_covariance`).
    """
    N, c, p = J.shape
    L = 2 * N
    # no demeaning: a correct model leaves zero-mean residuals, and removing the mean would
    # zero the DC bin where slow (e.g. impulse-response) sensitivities have their weight
    Rf = np.fft.rfft(R, n=L, axis=0)  # (F, c)
    Jf = np.fft.rfft(J, n=L, axis=0)  # (F, c, p)
    P = Rf[:, :, None] * Rf[:, None, :].conj() / N  # (F, c, c) periodogram
    w = np.full(P.shape[0], 2.0)
    w[0] = 1.0
    w[-1] = 1.0
    JfH = np.conj(np.swapaxes(Jf, 1, 2))  # (F, p, c)
    # contractions as batched matrix products (a 4-operand einsum loops naively)
    if Hinv is not None:
        G = Jf @ Hinv  # (F, c, p): each parameter's combination of the Jacobian's columns
        h = (w / L)[:, None, None] * (G @ JfH)
        lam, V = np.linalg.eigh(np.eye(c) - h)
        M = (V / np.clip(lam, 0.1, None)[:, None, :]) @ np.conj(np.swapaxes(V, 1, 2))
        P = M @ P @ np.conj(np.swapaxes(M, 1, 2))
    kernel = np.ones(2 * smooth + 1) / (2 * smooth + 1)
    if smooth > 0:
        flat = P.reshape(P.shape[0], -1)
        pad = np.concatenate([flat[smooth:0:-1].conj(), flat, flat[-2:-smooth - 2:-1].conj()])
        flat = np.apply_along_axis(lambda x: np.convolve(x, kernel, mode="valid"), 0, pad)
        P = flat.reshape(P.shape)
    S = np.real(np.sum(w[:, None, None] * (JfH @ (P @ Jf)), axis=0)) / L
    if Hinv is None:
        return S
    q = w[:, None] * np.real(np.sum(G.conj() * (P @ G), axis=1)) / L
    return S, np.apply_along_axis(lambda x: np.convolve(x, kernel, mode="same"), 0, q)

def _t_quantile(var_noise, var_total, dof_noise) -> np.ndarray:
    """Student's t 97.5 % quantile of each interval: the noise variance has ``dof_noise``
    degrees of freedom, the budget's part is taken as known, so ν = v_total² / (v_noise² /
    ν_noise) (Satterthwaite); 1.96 where ν is not finite."""

    with np.errstate(invalid="ignore", divide="ignore"):
        nu = np.asarray(var_total) ** 2 / (np.asarray(var_noise) ** 2 / np.asarray(dof_noise))
    ok = np.isfinite(nu) & (nu > 0)
    return np.where(ok, t.ppf(0.975, np.where(ok, nu, 1.0)), 1.96)

def _split(M: np.ndarray, blocks_at_optimum: list) -> list:
    """Rows of a stacked (n, m) array per record as (N, c, m) arrays (sample-major)."""
    out, off = [], 0
    for R in blocks_at_optimum:
        n_s, c = R.shape
        out.append(M[off:off + n_s * c].reshape(n_s, c, M.shape[1]))
        off += n_s * c
    return out

def _score_test(J, Jf, r, blocks_at_optimum):
    """Score (Lagrange-multiplier) test of each fixed value against the data: the cost's
    gradient in φ_j/φ_j0 at the optimum, with θ free (J_φ projected off J), over its
    standard deviation from the residuals' long-run covariance (as the sandwich's middle
    term); N(0, 1) when the fixed value is right (Rao's score test; Ljung §16.6 relates it
    to testing an extended model structure without fitting it). Returns (z, one-step
    estimate of the relative offset φ/φ0 − 1 the data suggest, its standard error)."""
    Jp = Jf - J @ np.linalg.lstsq(J, Jf, rcond=None)[0]
    g = Jp.T @ r
    V = sum(_long_run_covariance(Jb, rb[..., 0]) for Jb, rb in
            zip(_split(Jp, blocks_at_optimum), _split(r[:, None], blocks_at_optimum)))
    sd = np.sqrt(np.clip(np.diag(V), 0, None))
    h = np.einsum("ij,ij->j", Jp, Jp)
    with np.errstate(invalid="ignore", divide="ignore"):
        return g / sd, -g / h, sd / h

def _covariance(J: np.ndarray, r: np.ndarray, blocks_at_optimum: list, p: int
                ) -> tuple[np.ndarray, np.ndarray]:
    """Sandwich covariance of the scaled estimate, (JᵀJ)⁻¹ S (JᵀJ)⁻¹ with S the residuals'
    long-run covariance per record, leverage-corrected (:func:`_long_run_covariance`), and
    each parameter's effective degrees of freedom ν = (Σ b)² / Σ b² over the frequency bins
    of every record (Satterthwaite, *Biometrics Bull.* 2, 1946: S is a weighted sum of
    periodogram ordinates, each complex ordinate χ²₂ and two bins of the 2N-point transform
    per independent one); ``inf`` covariance and NaN ν when JᵀJ is singular. Rows of the
    stacked residual vector are sample-major per record."""
    blocks = list(zip(_split(J, blocks_at_optimum),
                      [b[..., 0] for b in _split(r[:, None], blocks_at_optimum)]))
    H = J.T @ J
    try:
        if np.linalg.cond(H) > 1e14:
            raise np.linalg.LinAlgError
        Hinv = np.linalg.inv(H)
        parts = [_long_run_covariance(Jb, rb, Hinv=Hinv) for Jb, rb in blocks]
        cov = Hinv @ sum(S for S, _ in parts) @ Hinv
        b = np.concatenate([b for _, b in parts])
        with np.errstate(invalid="ignore", divide="ignore"):
            dof = b.sum(axis=0) ** 2 / (b**2).sum(axis=0)
    except np.linalg.LinAlgError:
        cov, dof = np.full((p, p), np.inf), np.full(p, np.nan)
    return cov, dof
