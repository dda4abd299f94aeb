"""The γ search of :func:`ambseal.robust.hinf.hinfsyn` (private module).

:func:`game_riccati` solves one H∞ game Riccati equation (Glover & Doyle 1988, general D11
form) from its Hamiltonian; :func:`search_gamma` brackets γ_opt from a cheap lower bound
and closes in by Brent's method on a γ margin; :func:`sb10ad` calls SLICOT SB10AD;
:func:`gamma_search` finds the γ whose controller is built (the back-off from γ_opt,
:func:`backoff_ladder`).
"""

from __future__ import annotations

import numpy as np
from scipy.linalg.lapack import dgees
from scipy.optimize import brentq
from slycot import _wrapper

from ambseal.errors import SynthesisError

__all__ = ["backoff_ladder", "game_hamiltonian", "game_riccati", "gamma_search",
           "hamiltonian_level", "sb10ad", "search_gamma"]


def game_hamiltonian(A, B, C1, D1, nw: int, g: float):
    """The Hamiltonian of :func:`game_riccati`'s equation at γ = g, ``(2n, 2n)``; None where
    ``R = D1ᵀD1 − diag(γ²I_nw, 0)`` is singular or the matrix is not finite."""
    n = A.shape[0]
    R = D1.T @ D1
    R[np.arange(nw), np.arange(nw)] -= g * g
    try:
        S = np.linalg.solve(R, np.hstack([D1.T @ C1, B.T]))
    except np.linalg.LinAlgError:
        return None
    RiDC, RiBt = S[:, :n], S[:, n:]
    Ah = A - B @ RiDC
    H = np.block([[Ah, -B @ RiBt], [C1.T @ (D1 @ RiDC - C1), -Ah.T]])
    return H if np.all(np.isfinite(H)) else None


def game_riccati(A, B, C1, D1, nw: int, g: float):
    """Stabilising solution X ⪰ 0 of the H∞ game Riccati equation
    ``AᵀX + XA − (XB + C1ᵀD1) R⁻¹ (BᵀX + D1ᵀC1) + C1ᵀC1 = 0``, ``R = D1ᵀD1 − diag(γ²I_nw, 0)``
    (Glover & Doyle 1988), from the stable invariant subspace of its Hamiltonian (LAPACK
    DGEES with the stable eigenvalues ordered first); None if the Hamiltonian has
    imaginary-axis eigenvalues, the subspace is not a graph or X ⋡ 0."""

    n = A.shape[0]
    if n == 0:
        return np.zeros((0, 0))
    H = game_hamiltonian(A, B, C1, D1, nw, g)
    if H is None:
        return None
    _, sdim, wr, wi, Z, _, info = dgees(lambda x, y: x < 0.0, H, sort_t=1)
    if info or sdim != n:  # (info = n+1, n+2: eigenvalues on the imaginary axis to rounding)
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


#: Relative real part (of the largest |λ|) below which :func:`hamiltonian_level` reads a
#: Hamiltonian eigenvalue as on the imaginary axis. Looser than :func:`game_riccati`'s
#: 1e-12: near the level sought two imaginary eigenvalues nearly coincide, and a double
#: eigenvalue is computed to about √ε (Bruinsma & Steinbuch 1990 §4). An eigenvalue near
#: the imaginary axis read as on it costs one more evaluation, and what the level says is
#: checked by the Riccati margin anyway.
IMAGINARY_RTOL = 1e-8


def hamiltonian_level(A, B, C1, D1, nw: int, rtol: float):
    """The level γ_h at which :func:`game_riccati`'s Hamiltonian acquires imaginary-axis
    eigenvalues as γ falls: below it the stabilising X∞ does not exist, so γ_opt ≥ γ_h.

    The Hamiltonian has an eigenvalue jω exactly where the Popov function
    ``G(jω)ᴴG(jω) − diag(γ²I_nw, 0)`` (``G = C1 (sI − A)⁻¹ B + D1``, inputs ``[w, u]``) is
    singular, that is where γ is a singular value of ``Π⊥ G_w(jω)``, the w columns seen
    past the range of the u columns (a Schur complement of the Popov function; Zhou, Doyle
    & Glover 1996 §13.2 for the Hamiltonian, §17.3 for the projection). So γ_h is the
    L∞ norm of that projected function, found as Bruinsma & Steinbuch (1990, Syst. Control
    Lett. 14, 287–293) find an H∞ norm: from a lower bound (the largest σ̄ at ω = 0 and
    at A's damped natural frequencies), the Hamiltonian at the bound × (1 + rtol/4)
    either has no imaginary eigenvalue — the bound is within that of γ_h — or its
    imaginary eigenvalues bracket the frequencies where the norm lies higher, and the
    largest σ̄ at their midpoints is the next bound. It ends there, or where a bound no
    longer rises by rtol/4 (rounding).

    Parameters
    ----------
    A, B, C1, D1 : numpy.ndarray
        The equation's system, as :func:`game_riccati` (``nw`` first columns of B and D1:
        the exogenous inputs).
    nw : int
    rtol : float
        Relative tolerance of the level.

    Returns
    -------
    float or None
        The largest lower bound found (γ_h to ``rtol``); None where it is not determined:
        no states, no exogenous input, a singular frequency response or u columns that
        lose rank on the imaginary axis, or a Hamiltonian not formed.
    """
    n = A.shape[0]
    if n == 0 or nw == 0 or not np.all(np.isfinite(A)):
        return None
    eye = np.eye(n)

    def levels(ws) -> np.ndarray:
        # σ̄ of the projected function at each frequency, the stack solved at once (the
        # same LAPACK calls per frequency as one at a time, without their Python overhead)
        ws = np.asarray(ws, float)
        try:
            G = C1 @ np.linalg.solve(1j * ws[:, None, None] * eye - A,
                                     np.broadcast_to(B, (ws.size, *B.shape))) + D1
        except np.linalg.LinAlgError:
            return np.full(ws.size, np.nan)
        Gw, Gu = G[:, :, :nw], G[:, :, nw:]
        if Gu.shape[2]:
            Q, R = np.linalg.qr(Gu)
            d = np.abs(np.diagonal(R, axis1=1, axis2=2))
            if not np.all(d.min(axis=1) > 1e-12 * np.maximum(d.max(axis=1),
                                                              np.finfo(float).tiny)):
                return np.full(ws.size, np.nan)
            Gw = Gw - Q @ (np.conj(np.swapaxes(Q, 1, 2)) @ Gw)
        return np.linalg.svd(Gw, compute_uv=False)[:, 0]

    lam = np.linalg.eigvals(A)
    start = levels([0.0, *np.abs(lam.imag[lam.imag > 0])])
    if np.any(np.isnan(start)):
        return None
    lb = max(start)
    while True:
        H = game_hamiltonian(A, B, C1, D1, nw, lb * (1.0 + 0.25 * rtol))
        if H is None:
            return None
        ev = np.linalg.eigvals(H)
        on_jw = np.abs(ev.real) <= IMAGINARY_RTOL * max(1.0, float(np.max(np.abs(ev))))
        w = np.sort(np.abs(ev.imag[on_jw]))
        if not w.size:
            return lb
        up = levels([*w, *(0.5 * (w[1:] + w[:-1]))])
        if np.any(np.isnan(up)):
            return None
        if not max(up) > lb * (1.0 + 0.25 * rtol):
            return lb
        lb = max(up)


def search_gamma(margin, lo: float, rtol: float, seen: dict | None = None, *,
                 start: float | None = None, factor: float = 4.0):
    """γ_opt from a γ test ``margin(γ) < 0 ⇔ admissible``: a ladder of ``factor`` from
    ``start`` (default: the cheap lower bound ``lo`` × 1.5, at least 1 in hinfsyn's scaled
    coordinates) to the first change of admissibility, then Brent's method
    (:func:`scipy.optimize.brentq`: secant steps where the margin is smooth, bisection
    where it jumps) to ``hi/lo ≤ 1 + rtol``.
    ``seen`` holds margins already known. Returns ``(hi, lo, tests)``: smallest admissible
    and largest inadmissible γ tried, and the number of new margins computed."""

    seen = dict(seen or {})
    known = len(seen)

    def m(g):
        if g not in seen:
            seen[g] = margin(g)
        return seen[g]

    g = max(1.5 * lo, 1.0) if start is None else max(float(start), lo * (1 + rtol))
    hi, found_lo = None, False
    while True:
        if m(g) < 0:
            hi = g
            if found_lo or g / factor <= max(lo, 1e-12):
                break
            g /= factor
        else:
            lo, found_lo = g, True
            if hi is not None:
                break
            g *= factor
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


def _sb10ad_workspace(n, m, p, ncon, nmeas):
    """(liwork, ldwork) of SLICOT SB10AD: the minimal sizes of its documentation (SLICOT
    5.x, SB10AD, arguments LIWORK and LDWORK), as slycot's wrapper computes them."""
    m2, np2 = ncon, nmeas
    m1, np1 = m - m2, p - np2
    nd1, nd2 = np1 - m2, m1 - np2
    lw1 = n * m + p * n + p * m + m2 * m2 + np2 * np2
    lw2 = max((n + np1 + 1) * (n + m2) + max(3 * (n + m2) + n + np1, 5 * (n + m2)),
              (n + np2) * (n + m1 + 1) + max(3 * (n + np2) + n + m1, 5 * (n + np2)),
              m2 + np1 * np1 + max(np1 * max(n, m1), 3 * m2 + np1, 5 * m2),
              np2 + m1 * m1 + max(max(n, np1) * m1, 3 * np2 + m1, 5 * np2))
    lw3 = max(nd1 * m1 + max(4 * min(nd1, m1) + max(nd1, m1), 6 * min(nd1, m1)),
              np1 * nd2 + max(4 * min(np1, nd2) + max(np1, nd2), 6 * min(np1, nd2)))
    lw4 = 2 * m * m + p * p + 2 * m * n + m * p + 2 * n * p
    lw5 = 2 * n * n + m * n + n * p
    lw6 = max(m * m + max(2 * m1, 3 * n * n + max(n * m, 10 * n * n + 12 * n + 5)),
              p * p + max(2 * np1, 3 * n * n + max(n * p, 10 * n * n + 12 * n + 5)))
    lw7 = m2 * np2 + np2 * np2 + m2 * m2 + max(
        nd1 * nd1 + max(2 * nd1, (nd1 + nd2) * np2), nd2 * nd2 + max(2 * nd2, nd2 * m2), 3 * n,
        n * (2 * np2 + m2) + max(2 * n * m2, m2 * np2 + max(m2 * m2 + 3 * m2,
                                                            np2 * (2 * np2 + m2 + max(np2, n)))))
    liwork = max(2 * max(n, m1, np1, ncon, nmeas), n * n)
    return liwork, lw1 + max(1, lw2, lw3, lw4, lw5 + max(lw6, lw7))


def sb10ad(A, B, C, D, ncon, nmeas, gamma, job, gtol=1e-6):
    """SLICOT SB10AD through slycot's compiled wrapper: ``(outputs, info)``.

    slycot's Python function turns every ``info ≠ 0`` into an exception whose message it
    builds by parsing the routine's docstring (about 1 ms, more than SB10AD itself on a
    small plant, and an inadmissible γ is half of a γ search); the wrapper returns ``info``.
    job 1: bisection only (the scan of job 2/3 can take seconds and adds nothing here,
    since every γ is verified afterwards), to an absolute tolerance ``gtol`` in γ; job 4:
    the γ test and controller at ``gamma``.
    """

    n, m, p = A.shape[0], B.shape[1], C.shape[0]
    liwork, ldwork = _sb10ad_workspace(n, m, p, ncon, nmeas)
    out = _wrapper.sb10ad(job, n, m, p, ncon, nmeas, gamma, A, B, C, D, gtol, 0.0,
                          liwork, ldwork)
    return out[:-1], int(out[-1])


def backoff_ladder(backoff: float, max_backoff: float) -> list[float]:
    """Back-off factors tried in turn: ``backoff``, then doubling its excess up to the cap."""
    factors, f = [backoff], backoff
    while f < max_backoff:
        f = 1.0 + (f - 1.0) * 2.0 if f > 1.0 else 1.01
        factors.append(min(f, max_backoff))
    return factors


def gamma_search(attempt, base_g: float, factors, backoff: float, *, fixed: bool):
    """The γ search of :func:`ambseal.robust.hinf.hinfsyn`, apart from the controller
    construction.

    ``attempt(g)`` builds the controller at γ = g (an ``hinf._Attempt``, or None when
    SB10AD fails or the loop is unstable). Tries ``factors·base_g`` in turn and returns the
    first consistent attempt (verified norm ≤ the γ it was built for; with ``fixed`` any
    attempt). If none is: SB10AD's γ_opt can be wrong when D11 ≠ 0 — the controller built
    at γ then has a closed-loop norm above γ — so search for the smallest γ whose
    controller achieves ‖F_l(P, K)‖∞ ≤ γ, by doubling and then bisection on the verified
    norm. Returns None if nothing was found.
    """
    for f in factors:
        res = attempt(f * base_g)
        if res is not None and (res.consistent or fixed):
            return res
    if fixed:
        return None
    lo, hi, res_hi = base_g * factors[-1], None, None
    g = lo
    for _ in range(60):
        g *= 2.0
        res = attempt(g)
        if res is not None and res.consistent:
            hi, res_hi = g, res
            break
        lo = g
    if res_hi is None:
        return None
    for _ in range(40):
        if hi / lo <= 1.0 + 0.5 * (backoff - 1.0) + 1e-6:
            break
        mid = np.sqrt(lo * hi)
        res = attempt(mid)
        if res is not None and res.consistent:
            hi, res_hi = mid, res
        else:
            lo = mid
    return res_hi
