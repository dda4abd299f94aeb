"""The γ search of :func:`ambseal.control.hinf.hinfsyn` (private module).

:func:`game_riccati` solves one H∞ game Riccati equation (Glover & Doyle 1988, general D11
form) from its Hamiltonian; :func:`search_gamma` brackets γ_opt from a cheap lower bound
and closes in by Brent's method on a γ margin.
"""

from __future__ import annotations

import numpy as np
import scipy.linalg as sla

from ambseal.errors import SynthesisError

__all__ = ["game_riccati", "search_gamma"]


def game_riccati(A, B, C1, D1, nw: int, g: float):
    """Stabilising solution X ⪰ 0 of the H∞ game Riccati equation
    ``AᵀX + XA − (XB + C1ᵀD1) R⁻¹ (BᵀX + D1ᵀC1) + C1ᵀC1 = 0``, ``R = D1ᵀD1 − diag(γ²I_nw, 0)``
    (Glover & Doyle 1988), from the stable invariant subspace of its Hamiltonian (LAPACK
    DGEES with the stable eigenvalues ordered first); None if the Hamiltonian has
    imaginary-axis eigenvalues, the subspace is not a graph or X ⋡ 0."""
    from scipy.linalg.lapack import dgees

    n = A.shape[0]
    if n == 0:
        return np.zeros((0, 0))
    R = D1.T @ D1
    R[np.arange(nw), np.arange(nw)] -= g * g
    try:
        S = np.linalg.solve(R, np.hstack([D1.T @ C1, B.T]))
    except np.linalg.LinAlgError:
        return None
    RiDC, RiBt = S[:, :n], S[:, n:]
    Ah = A - B @ RiDC
    H = np.block([[Ah, -B @ RiBt], [C1.T @ (D1 @ RiDC - C1), -Ah.T]])
    if not np.all(np.isfinite(H)):
        return None
    _, sdim, wr, wi, Z, _, info = dgees(lambda x, y: x < 0.0, H, sort_t=1)
    if info or sdim != n:  # (info = n+1, n+2: eigenvalues on the axis to rounding)
        return None
    if np.min(np.abs(wr[:n])) <= 1e-12 * max(1.0, float(np.max(np.hypot(wr, wi)))):
        return None
    U1, U2 = Z[:n, :n], Z[n:, :n]
    sv = np.linalg.svd(U1, compute_uv=False)
    if sv[-1] < 1e-12 * sv[0]:
        return None
    X = np.linalg.solve(U1.T, U2.T).T
    X = 0.5 * (X + X.T)
    if np.min(np.linalg.eigvalsh(X)) < -1e-9 * max(1.0, float(np.max(np.abs(X)))):
        return None
    return X


def search_gamma(margin, lo: float, rtol: float, seen: dict | None = None):
    """γ_opt from a γ test ``margin(γ) < 0 ⇔ admissible``: a ladder of factors 4 from the
    cheap lower bound ``lo`` (or 1 in hinfsyn's scaled coordinates) to the first
    change of admissibility, then Brent's method (:func:`scipy.optimize.brentq`: secant
    steps where the margin is smooth, bisection where it jumps) to ``hi/lo ≤ 1 + rtol``.
    ``seen`` holds margins already known. Returns ``(hi, lo, tests)``: smallest admissible
    and largest inadmissible γ tried, and the number of new margins computed."""
    from scipy.optimize import brentq

    seen = dict(seen or {})
    known = len(seen)

    def m(g):
        if g not in seen:
            seen[g] = margin(g)
        return seen[g]

    g, hi, found_lo = max(1.5 * lo, 1.0), None, False
    while True:
        if m(g) < 0:
            hi = g
            if found_lo or g / 4.0 <= max(lo, 1e-12):
                break
            g /= 4.0
        else:
            lo, found_lo = g, True
            if hi is not None:
                break
            g *= 4.0
            if g > 1e100:
                raise SynthesisError("hinfsyn: no admissible γ up to 1e100")
    if not found_lo and lo <= 0:  # admissible down to the ladder's end: halve towards 0
        while hi > 1e-12 and m(0.5 * hi) < 0:
            hi *= 0.5
        lo = 0.5 * hi
    if hi / lo > 1.0 + rtol and m(lo) >= 0:  # (the Parrott bound has margin +1 there)
        brentq(m, lo, hi, xtol=0.25 * rtol * lo, rtol=1e-15, maxiter=200)
    ok = [x for x, v in seen.items() if v < 0]
    bad = [x for x, v in seen.items() if v >= 0 and x < min(ok)]
    hi = min(ok)
    lo = max(bad + [lo])
    if hi / lo > 1.0 + rtol and m(lo * (1.0 + rtol)) < 0:  # Brent's last step on the bad side
        hi = lo * (1.0 + rtol)
    return float(hi), float(lo), len(seen) - known
