"""Damped Newton steps of the D–G upper bound's method of centres and its generalised
eigenvalue λ_max(D⁻¹A), compiled with numba.

Private module behind :mod:`ambseal.robust._mu_upper`. The same algorithm as the batched
numpy form it replaced (Boyd & El Ghaoui 1993; Nesterov & Nemirovskii 1994 §2.1 for the
damped step), one matrix at a time: the stacks it runs on are mostly a few matrices (the
finer levels of the frequency continuation and the last unconverged frequencies), where
numpy's per-call overhead, not the 14 × 14 arithmetic, set the time. Compiled on first use
and cached on disk where a cache folder is writable (:mod:`ambseal.lti.compiled`).

The barrier of the level t is
``φ(z) = −log det L(z) − Σ_blocks log det D_k(z) − log det(gmax I − G) − log det(gmax I + G)``
with ``L = t D − A`` affine in z; a term ``−log det Y`` with derivatives ``Y_i`` has gradient
``−tr(Y⁻¹ Y_i)`` and Hessian ``tr(Y⁻¹ Y_i Y⁻¹ Y_j)``.
"""

from __future__ import annotations

import numpy as np

from ambseal.lti import cached_njit

__all__ = ["gevp", "newton_steps"]


@cached_njit()
def _chol(Y):
    """Lower Cholesky factor of the Hermitian Y and whether Y is positive definite."""
    n = Y.shape[0]
    C = np.zeros((n, n), np.complex128)
    for j in range(n):
        s = Y[j, j].real
        for k in range(j):
            s -= C[j, k].real ** 2 + C[j, k].imag ** 2
        if not s > 0.0:
            return C, False
        d = np.sqrt(s)
        C[j, j] = d
        for i in range(j + 1, n):
            v = Y[i, j]
            for k in range(j):
                v -= C[i, k] * np.conj(C[j, k])
            C[i, j] = v / d
    return C, True


@cached_njit()
def _pd(Y):
    """True if the Hermitian matrix Y is positive definite (Cholesky pivots > 0)."""
    return _chol(Y)[1]


@cached_njit()
def _tril_inv(C):
    """Inverse of a lower-triangular matrix (forward substitution)."""
    n = C.shape[0]
    Ci = np.zeros((n, n), np.complex128)
    for j in range(n):
        Ci[j, j] = 1.0 / C[j, j]
        for i in range(j + 1, n):
            v = 0.0j
            for k in range(j, i):
                v -= C[i, k] * Ci[k, j]
            Ci[i, j] = v / C[i, i]
    return Ci


def gevp(D, A):
    """λ_max(D⁻¹ A) (F,) for Hermitian stacks D, A (F, N, N); +inf where D is not positive
    definite. With D = C Cᴴ: the largest eigenvalue of C⁻¹ A C⁻ᴴ (the whitening compiled,
    the eigenvalues by numpy's batched LAPACK: numba's ``eigvalsh`` took seconds to compile
    on a command's first run)."""
    X, ok = _whiten(D, A)
    out = np.full(D.shape[0], np.inf)
    if ok.any():
        out[ok] = np.linalg.eigvalsh(X[ok])[:, -1]
    return out


@cached_njit()
def _whiten(D, A):
    """C⁻¹ A C⁻ᴴ (Hermitian part) per matrix with D = C Cᴴ, and whether D is positive
    definite (where it is not, the matrix is left zero)."""
    F, n = D.shape[0], D.shape[1]
    X = np.zeros((F, n, n), np.complex128)
    ok = np.zeros(F, np.bool_)
    for f in range(F):
        C, pd = _chol(D[f])
        if not pd:
            continue
        ok[f] = True
        Ci = _tril_inv(C)
        CiH = np.empty((n, n), np.complex128)
        for a in range(n):
            for b in range(n):
                CiH[a, b] = np.conj(Ci[b, a])
        Y = Ci @ np.ascontiguousarray(A[f]) @ CiH
        for a in range(n):
            for b in range(n):
                X[f, a, b] = 0.5 * (Y[a, b] + np.conj(Y[b, a]))
    return X, ok


@cached_njit()
def _inv(Y):
    """Inverse of a Hermitian positive definite Y (barrier matrices at feasible points),
    Y⁻¹ = C⁻ᴴ C⁻¹ from its Cholesky factor Y = C Cᴴ, and whether Y is positive definite
    (where rounding has taken a point to the boundary it is not; the inverse is then
    zero)."""
    n = Y.shape[0]
    C, ok = _chol(Y)
    if not ok:
        return np.zeros((n, n), np.complex128), False
    Ci = _tril_inv(C)
    X = np.zeros((n, n), np.complex128)
    for a in range(n):
        for b in range(n):
            v = 0.0j
            for k in range(max(a, b), n):
                v += np.conj(Ci[k, a]) * Ci[k, b]
            X[a, b] = v
    return X, True


@cached_njit()
def _add_term(Yinv, B, off, sign, g, H):
    """Gradient and Hessian of −log det Y for directions B (q, n, n), coordinates off…off+q:
    with R_i = Y⁻¹ B_i, g_i −= sign·tr R_i and H_ij += Re tr(R_i R_j) (sign −1: Y's
    derivatives are −B_i)."""
    q = B.shape[0]
    n = Yinv.shape[0]
    # R_i = RR[:, i n:(i + 1) n]: one product Y⁻¹ [B_0 … B_q-1] (loops for tiny blocks)
    Bh = np.empty((n, q * n), np.complex128)
    for i in range(q):
        for a in range(n):
            for b in range(n):
                Bh[a, i * n + b] = B[i, a, b]
    if n > 4:
        RR = Yinv @ Bh
    else:
        RR = np.zeros((n, q * n), np.complex128)
        for a in range(n):
            for k in range(n):
                y = Yinv[a, k]
                for c in range(q * n):
                    RR[a, c] += y * Bh[k, c]
    # rows: Re and Im of R_i (P) and of R_iᵀ with the sign of Im flipped (Q): H = P Qᵀ
    nn = n * n
    P = np.empty((q, 2 * nn))
    Q = np.empty((q, 2 * nn))
    for i in range(q):
        tr = 0.0
        for a in range(n):
            tr += RR[a, i * n + a].real
            for b in range(n):
                r = RR[a, i * n + b]
                P[i, a * n + b] = r.real
                P[i, nn + a * n + b] = r.imag
                Q[i, b * n + a] = r.real
                Q[i, nn + b * n + a] = -r.imag
        g[off + i] -= sign * tr
    Hq = P @ Q.T
    for i in range(q):
        for j in range(q):
            H[off + i, off + j] += Hq[i, j]


@cached_njit()
def _derivs(L1, D, Gr, Lder, BD, BGr, offs, full, gmax, pD):
    """Gradient (p,) and Hessian (p, p) of the barrier at one matrix's current point, and
    whether the point is inside the barrier's domain (every matrix positive definite)."""
    p = Lder.shape[0]
    g = np.zeros(p)
    H = np.zeros((p, p))
    o = offs[0]  # = 0, typed int64 (a literal 0 would compile _add_term twice)
    Yinv, inside = _inv(L1)
    if not inside:
        return g, H, False
    _add_term(Yinv, Lder, o, 1.0, g, H)
    for k in range(offs.size - 1):
        o0, o1 = offs[k], offs[k + 1]
        if full[k]:  # D block d·I: −k log d
            dinv = 1.0 / D[o0, o0].real
            m = o1 - o0
            for i in range(pD):
                ci = BD[i, o0, o0].real
                g[i] -= m * dinv * ci
                for j in range(pD):
                    H[i, j] += m * dinv * dinv * ci * BD[j, o0, o0].real
        else:
            Yinv, ok = _inv(np.ascontiguousarray(D[o0:o1, o0:o1]))
            inside = inside and ok
            _add_term(Yinv, np.ascontiguousarray(BD[:, o0:o1, o0:o1]), o, 1.0, g, H)
    if BGr.shape[0]:  # gmax I ∓ G: derivatives ∓B_i
        Yinv, ok = _inv(_shift(Gr, -1.0, gmax))
        inside = inside and ok
        _add_term(Yinv, BGr, pD, -1.0, g, H)
        Yinv, ok = _inv(_shift(Gr, 1.0, gmax))
        inside = inside and ok
        _add_term(Yinv, BGr, pD, 1.0, g, H)
    return g, H, inside


@cached_njit()
def _shift(X, s, c):
    """c I + s X."""
    n = X.shape[0]
    Y = np.empty((n, n), np.complex128)
    for a in range(n):
        for b in range(n):
            Y[a, b] = s * X[a, b]
        Y[a, a] += c
    return Y


@cached_njit()
def _axpy(X, s, dX):
    """X + s dX."""
    n = X.shape[0]
    Y = np.empty((n, n), np.complex128)
    for a in range(n):
        for b in range(n):
            Y[a, b] = X[a, b] + s * dX[a, b]
    return Y


@cached_njit()
def _solve(H, g):
    """H⁻¹ g for a small real H (destroyed) by Gaussian elimination with partial pivoting
    (LAPACK's getrf/getrs algorithm, in loops: numba's np.linalg.solve costs seconds to
    compile)."""
    n = H.shape[0]
    x = g.copy()
    for k in range(n):
        piv = k
        for i in range(k + 1, n):
            if abs(H[i, k]) > abs(H[piv, k]):
                piv = i
        if piv != k:
            for j in range(n):
                H[k, j], H[piv, j] = H[piv, j], H[k, j]
            x[k], x[piv] = x[piv], x[k]
        for i in range(k + 1, n):
            m = H[i, k] / H[k, k]
            for j in range(k + 1, n):
                H[i, j] -= m * H[k, j]
            x[i] -= m * x[k]
    for k in range(n - 1, -1, -1):
        v = x[k]
        for j in range(k + 1, n):
            v -= H[k, j] * x[j]
        x[k] = v / H[k, k]
    return x


@cached_njit()
def _feasible(L1, D, Gr, gmax):
    if not (_pd(L1) and _pd(D)):
        return False
    if Gr.shape[0] == 0:
        return True
    return _pd(_shift(Gr, -1.0, gmax)) and _pd(_shift(Gr, 1.0, gmax))


@cached_njit()
def _all(x):
    for v in x:
        if not v:
            return False
    return True


@cached_njit()
def newton_steps(L1, D, Gr, za, Lder, U, BD, BGr, offs, full, gmax, pD, n_newton, dec_tol):
    """Up to ``n_newton`` damped Newton steps on every matrix of the stack; in place.

    Parameters
    ----------
    L1 : (F, N, N) complex, ``t D − A`` at the current point
    D : (F, N, N) complex
    Gr : (F, nr, nr) complex, G on the real blocks' rows (nr = 0 without real blocks)
    za : (F, p) float, coordinates
    Lder : (F, p, N, N) complex, derivatives of L
    U : (p, N, N) complex, derivatives of D (zero for G coordinates)
    BD : (pD, N, N) complex, D basis; BGr : (pG, nr, nr) complex, G basis on the real rows
    offs : (nblocks + 1,) int, block offsets; full : (nblocks,) bool, full complex blocks
    gmax : float; pD : int, number of D coordinates
    n_newton : int; dec_tol : float

    Returns
    -------
    centred : (F,) bool, Newton decrement below ``dec_tol`` at the last step. As the batched
        form: every matrix steps until all are centred or ``n_newton`` steps are done.
    lost : (F,) bool, rounding has taken the point out of the barrier's domain (a matrix
        no longer positive definite; near a level t just above a λ of zero, t D − A is
        singular to working precision): it stays where it is, counted as centred, for the
        caller to stop at its best scalings.
    """
    F, p = za.shape
    centred = np.zeros(F, np.bool_)
    lost = np.zeros(F, np.bool_)
    dz = np.empty((F, p))
    dec = np.empty(F)
    for _k in range(n_newton):
        for f in range(F):
            g, H, inside = _derivs(L1[f], D[f], Gr[f], Lder[f], BD, BGr, offs, full, gmax,
                                   pD)
            if lost[f] or not inside:
                lost[f] = True
                centred[f] = True
                dec[f] = 0.0
                for i in range(p):
                    dz[f, i] = 0.0
                continue
            dec[f] = _newton_direction(g, H, dz[f])
            centred[f] = dec[f] < dec_tol
        if _all(centred):
            break
        for f in range(F):
            _damped_step(L1[f], D[f], Gr[f], za[f], Lder[f], U, BGr, dz[f], dec[f], pD, gmax)
    return centred, lost


@cached_njit()
def _newton_direction(g, H, dz):
    """The Newton direction −H⁻¹g into ``dz`` (H regularised by 1e-12 of its mean diagonal)
    and the Newton decrement √(gᵀH⁻¹g)."""
    p = g.shape[0]
    tr = 0.0
    for i in range(p):
        tr += H[i, i]
    for i in range(p):
        H[i, i] += 1e-12 * tr / p
    d = _solve(H, g)
    gd = 0.0
    for i in range(p):
        dz[i] = -d[i]
        gd += g[i] * d[i]
    return np.sqrt(max(gd, 0.0))


@cached_njit()
def _damped_step(L1, D, Gr, za, Lder, U, BGr, dz, dec, pD, gmax):
    """One damped Newton step of one matrix along ``dz``, in place.

    Inside the Dikin ellipsoid (r = step·dec < 1) the point stays feasible: each barrier
    matrix L has ‖L^-½ dL L^-½‖ ≤ r (its term's local norm is at most the Newton
    decrement's), so L + dL ⪰ (1 − r)·L (Nesterov & Nemirovskii 1994 §2.1). With r ≤ 1/2 it
    keeps half its smallest eigenvalue, so only the longer steps are checked, against
    rounding, and halved (up to 12 times) where they fail."""
    N = L1.shape[0]
    nr = Gr.shape[0]
    p = dz.shape[0]
    step = 1.0 if dec < 0.25 else 1.0 / (1.0 + dec)
    dL1 = np.zeros((N, N), np.complex128)
    dD = np.zeros((N, N), np.complex128)
    dGr = np.zeros((nr, nr), np.complex128)
    for i in range(p):
        c = dz[i]
        for a in range(N):
            for b in range(N):
                dL1[a, b] += c * Lder[i, a, b]
        if i < pD:
            for a in range(N):
                for b in range(N):
                    dD[a, b] += c * U[i, a, b]
        else:
            for a in range(nr):
                for b in range(nr):
                    dGr[a, b] += c * BGr[i - pD, a, b]
    if step * dec > 0.5:
        ok = False
        for _bt in range(12):
            if _feasible(_axpy(L1, step, dL1), _axpy(D, step, dD), _axpy(Gr, step, dGr),
                         gmax):
                ok = True
                break
            step *= 0.5
        if not ok:
            step = 0.0
    for a in range(N):
        for b in range(N):
            L1[a, b] += step * dL1[a, b]
            D[a, b] += step * dD[a, b]
    for a in range(nr):
        for b in range(nr):
            Gr[a, b] += step * dGr[a, b]
    for i in range(p):
        za[i] += step * dz[i]
