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
``−tr(Y⁻¹ Y_i)`` and Hessian ``tr(Y⁻¹ Y_i Y⁻¹ Y_j)``. For ``L`` the derivatives are
rank-two updates per scaling entry (:func:`_lmi_term`), so its Hessian is formed from
products of ``L⁻¹`` with M, not from p dense N × N derivative matrices: with a 10 × 10
repeated real block (p = 200 on a 22 × 22 M) that and LAPACK's batched solve of the Newton
systems made the Newton steps 2.6 times cheaper (benchmarks/README.md).
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
def _project(Hr, Hi, tr, pos, tp, tu, tv, i0, i1, sign, g, H):
    """Adds ``−sign·Re Σ_u T[i, u] tr_u`` to g_i and ``Re (T Hel Tᵀ)_ij`` to H_ij for the
    coordinates i0…i1−1, with ``Hel = Hr + j Hi`` over the m entries that ``pos`` numbers
    (−1: an entry outside this term). T is sparse by rows: row i holds
    ``tv[tp[i]:tp[i+1]]`` at ``tu[…]``. ``T Hel`` is formed in real and imaginary parts
    apart, whose row updates compile to vector instructions: a tenth of the time of the
    same updates in complex numbers, where the trace-free D directions' rows hold every
    diagonal entry."""
    m = Hr.shape[0]
    q = i1 - i0
    THr = np.zeros((q, m))
    THi = np.zeros((q, m))
    for i in range(q):
        gi = 0.0
        for k in range(tp[i0 + i], tp[i0 + i + 1]):
            w = pos[tu[k]]
            if w < 0:
                continue
            c = tv[k]
            gi += (c * tr[w]).real
            cr, ci = c.real, c.imag
            for v in range(m):
                THr[i, v] += cr * Hr[w, v] - ci * Hi[w, v]
                THi[i, v] += cr * Hi[w, v] + ci * Hr[w, v]
        g[i0 + i] -= sign * gi
    for i in range(q):  # T Hel Tᵀ is symmetric as Hel is
        for j in range(i, q):
            acc = 0.0
            for k in range(tp[i0 + j], tp[i0 + j + 1]):
                w = pos[tu[k]]
                if w >= 0:
                    acc += THr[i, w] * tv[k].real - THi[i, w] * tv[k].imag
            H[i0 + i, i0 + j] += acc
            if j != i:
                H[i0 + j, i0 + i] += acc


@cached_njit()
def _entry_term(Yinv, la, lb, tp, tu, tv, i0, i1, sign, g, H):
    """Gradient and Hessian of −log det Y for the coordinates i0…i1−1, whose directions
    in Y are ``sign·B_i``, ``B_i = Σ_u T[i, u] e_{la_u} e_{lb_u}ᵀ`` (entries with
    ``la_u < 0`` lie outside Y); adds into g and H.

    ``tr(Y⁻¹ e_a e_bᵀ Y⁻¹ e_c e_dᵀ) = Y⁻¹[b, c] Y⁻¹[d, a]``, so with m entries in Y the
    Hessian ``H_ij = Re tr(Y⁻¹B_i Y⁻¹B_j)`` takes O(m² + nnz(T)·m) operations
    (:func:`_project`), not the O(q²n²) of products of q dense n × n directions."""
    r = la.size
    pos = np.full(r, -1, np.int64)
    m = 0
    for u in range(r):
        if la[u] >= 0:
            pos[u] = m
            m += 1
    ua = np.empty(m, np.int64)
    ub = np.empty(m, np.int64)
    for u in range(r):
        if pos[u] >= 0:
            ua[pos[u]] = la[u]
            ub[pos[u]] = lb[u]
    Hr = np.empty((m, m))
    Hi = np.empty((m, m))
    tr = np.empty(m, np.complex128)
    for u in range(m):
        tr[u] = Yinv[ub[u], ua[u]]
        for v in range(u, m):
            h = Yinv[ub[u], ua[v]] * Yinv[ub[v], ua[u]]
            Hr[u, v] = Hr[v, u] = h.real
            Hi[u, v] = Hi[v, u] = h.imag
    _project(Hr, Hi, tr, pos, tp, tu, tv, i0, i1, sign, g, H)


@cached_njit()
def _lmi_term(Yinv, M, t, tp, tu, tv, ekind, ea, eb, g, H):
    """Gradient and Hessian of −log det L, ``L = t D − A``, from the rank-two form of its
    derivatives; adds into g (p,) and H (p, p).

    Coordinate i moves L along ``L_i = Σ_u T[i, u] Λ_u`` (T sparse: row i holds
    ``tv[tp[i]:tp[i+1]]`` at ``tu[…]``), one elementary direction per scaling entry
    (a, b) (:class:`ambseal.robust._mu_upper._Problem`): a D entry moves
    ``Λ = t e_a e_bᵀ − (Mᴴe_a)(e_bᵀM)``, a G entry ``Λ = −j e_a (e_bᵀM) + j (Mᴴe_a) e_bᵀ``.
    Each is two rank-one terms x yᵀ, and ``tr(Y⁻¹ x yᵀ Y⁻¹ x' y'ᵀ) = (yᵀY⁻¹x')(y'ᵀY⁻¹x)``,
    so with the 2N × 2N matrix ``W = [[Y⁻¹, Y⁻¹Mᴴ], [MY⁻¹, MY⁻¹Mᴴ]]`` (a term's y picks
    its row, x its column) the Hessian ``H_ij = Re tr(Y⁻¹L_i Y⁻¹L_j)`` takes
    O(r² + nnz(T)·r) operations (r entries, :func:`_project`), not the O(p²N²) of dense
    derivative matrices — the same numbers to rounding (the dense form is the test's
    reference)."""
    N = M.shape[0]
    p = tp.size - 1
    r = ekind.size
    # W (loops: N is small, and a compiled complex matmul costs seconds to compile)
    W = np.zeros((2 * N, 2 * N), np.complex128)
    for a in range(N):
        for b in range(N):
            W[a, b] = Yinv[a, b]
            yh = 0.0j
            my = 0.0j
            for k in range(N):
                yh += Yinv[a, k] * np.conj(M[b, k])
                my += M[a, k] * Yinv[k, b]
            W[a, N + b] = yh
            W[N + a, b] = my
    for a in range(N):
        for b in range(N):
            acc = 0.0j
            for k in range(N):
                acc += W[N + a, k] * np.conj(M[b, k])
            W[N + a, N + b] = acc
    # each entry's two terms s·x yᵀ: x = e_a or Mᴴe_a picks W's column ka, yᵀ = e_bᵀ or
    # e_bᵀM its row rb
    s0 = np.empty(r, np.complex128)
    s1 = np.empty(r, np.complex128)
    rb0 = np.empty(r, np.int64)
    rb1 = np.empty(r, np.int64)
    ka0 = np.empty(r, np.int64)
    ka1 = np.empty(r, np.int64)
    for u in range(r):
        if ekind[u] == 0:
            s0[u], rb0[u], ka0[u] = t, eb[u], ea[u]
            s1[u], rb1[u], ka1[u] = -1.0, N + eb[u], N + ea[u]
        else:
            s0[u], rb0[u], ka0[u] = -1j, N + eb[u], ea[u]
            s1[u], rb1[u], ka1[u] = 1j, eb[u], N + ea[u]
    tr = np.empty(r, np.complex128)
    pos = np.empty(r, np.int64)
    for u in range(r):
        tr[u] = s0[u] * W[rb0[u], ka0[u]] + s1[u] * W[rb1[u], ka1[u]]
        pos[u] = u
    # tr(Y⁻¹Λ_u Y⁻¹Λ_v) = tr(Y⁻¹Λ_v Y⁻¹Λ_u) (the trace is cyclic): Hel is symmetric, each
    # pair is formed once
    Hr = np.empty((r, r))
    Hi = np.empty((r, r))
    for u in range(r):
        bu0, bu1, au0, au1, su0, su1 = rb0[u], rb1[u], ka0[u], ka1[u], s0[u], s1[u]
        for v in range(u, r):
            bv0, bv1, av0, av1 = rb0[v], rb1[v], ka0[v], ka1[v]
            h = (su0 * (s0[v] * W[bu0, av0] * W[bv0, au0] + s1[v] * W[bu0, av1] * W[bv1, au0])
                 + su1 * (s0[v] * W[bu1, av0] * W[bv0, au1]
                          + s1[v] * W[bu1, av1] * W[bv1, au1]))
            Hr[u, v] = Hr[v, u] = h.real
            Hi[u, v] = Hi[v, u] = h.imag
    _project(Hr, Hi, tr, pos, tp, tu, tv, 0, p, 1.0, g, H)


@cached_njit()
def _derivs(L1, D, Gr, M, t, tp, tu, tv, ekind, ea, eb, loc_a, loc_b, BD, BGr, offs, full,
            gmax, pD):
    """Gradient (p,) and Hessian (p, p) of the barrier at one matrix's current point, and
    whether the point is inside the barrier's domain (every matrix positive definite)."""
    p = tp.size - 1
    g = np.zeros(p)
    H = np.zeros((p, p))
    o = offs[0]  # = 0, typed int64 (a literal 0 would compile _entry_term twice)
    Yinv, inside = _inv(L1)
    if not inside:
        return g, H, False
    _lmi_term(Yinv, M, t, tp, tu, tv, ekind, ea, eb, g, H)
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
            _entry_term(Yinv, loc_a[k], loc_b[k], tp, tu, tv, o, pD, 1.0, g, H)
    if BGr.shape[0]:  # gmax I ∓ G: derivatives ∓B_i, on the real blocks' rows
        la, lb = loc_a[offs.size - 1], loc_b[offs.size - 1]
        Yinv, ok = _inv(_shift(Gr, -1.0, gmax))
        inside = inside and ok
        _entry_term(Yinv, la, lb, tp, tu, tv, pD, p, -1.0, g, H)
        Yinv, ok = _inv(_shift(Gr, 1.0, gmax))
        inside = inside and ok
        _entry_term(Yinv, la, lb, tp, tu, tv, pD, p, 1.0, g, H)
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
def _feasible(L1, D, Gr, gmax):
    if not (_pd(L1) and _pd(D)):
        return False
    if Gr.shape[0] == 0:
        return True
    return _pd(_shift(Gr, -1.0, gmax)) and _pd(_shift(Gr, 1.0, gmax))


def newton_steps(L1, D, Gr, za, Lder, U, BD, BGr, offs, full, gmax, pD, n_newton, dec_tol,
                 M, t, tp, tu, tv, ekind, ea, eb, loc_a, loc_b):
    """Up to ``n_newton`` damped Newton steps on every matrix of the stack; in place.

    The barrier's derivatives and the damped steps are compiled (one matrix at a time); the
    Newton systems, p × p for p scaling coordinates (200 for a 10 × 10 repeated real
    block), are solved by LAPACK at once for the stack (:func:`numpy.linalg.solve`).

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
    M : (F, N, N) complex, the matrices; t : (F,) float, their levels
    tp, tu, tv : the sparse map from coordinates to scaling entries, row i of T at
        ``tu[tp[i]:tp[i+1]]`` with values ``tv[…]`` (complex)
    ekind, ea, eb : (r,) int, each scaling entry's kind (0: D, 1: G) and position (a, b)
    loc_a, loc_b : (nblocks + 1, r) int, each entry's position inside D's block k (row k)
        and inside gmax I ∓ G on the real rows (the last row); -1 outside

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
    for _k in range(n_newton):
        g, H, inside = _stack_derivs(L1, D, Gr, M, t, tp, tu, tv, ekind, ea, eb, loc_a,
                                     loc_b, BD, BGr, offs, full, gmax, pD, lost)
        lost |= ~inside
        dz, dec = np.zeros((F, p)), np.zeros(F)
        ok = np.flatnonzero(~lost)
        if ok.size:
            dz[ok], dec[ok] = _newton_direction(g[ok], H[ok])
        centred = lost | (dec < dec_tol)
        if centred.all():
            break
        _damped_steps(L1, D, Gr, za, Lder, U, BGr, dz, dec, pD, gmax)
    return centred, lost


@cached_njit()
def _stack_derivs(L1, D, Gr, M, t, tp, tu, tv, ekind, ea, eb, loc_a, loc_b, BD, BGr, offs,
                  full, gmax, pD, skip):
    """:func:`_derivs` of every matrix not in ``skip``: g (F, p), H (F, p, p), inside (F,)."""
    F, p = L1.shape[0], tp.size - 1
    g = np.zeros((F, p))
    H = np.zeros((F, p, p))
    inside = np.ones(F, np.bool_)
    for f in range(F):
        if skip[f]:
            continue
        gf, Hf, inside[f] = _derivs(L1[f], D[f], Gr[f], M[f], t[f], tp, tu, tv, ekind, ea,
                                    eb, loc_a, loc_b, BD, BGr, offs, full, gmax, pD)
        for i in range(p):  # (loops: a slice assignment costs seconds to compile)
            g[f, i] = gf[i]
            for j in range(p):
                H[f, i, j] = Hf[i, j]
    return g, H, inside


def _newton_direction(g, H):
    """The Newton directions −H⁻¹g (F, p) (each H regularised by 1e-12 of its mean
    diagonal) and the Newton decrements √(gᵀH⁻¹g) (F,)."""
    p = g.shape[1]
    k = np.arange(p)
    H[:, k, k] += (1e-12 / p) * np.trace(H, axis1=1, axis2=2)[:, None]
    try:
        d = np.linalg.solve(H, g[..., None])[..., 0]
    except np.linalg.LinAlgError:  # a singular H (rounding): the least-squares direction
        d = np.stack([np.linalg.lstsq(Hf, gf, rcond=None)[0] for Hf, gf in zip(H, g)])
    return -d, np.sqrt(np.maximum(np.einsum("fi,fi->f", g, d), 0.0))


@cached_njit()
def _damped_steps(L1, D, Gr, za, Lder, U, BGr, dz, dec, pD, gmax):
    """:func:`_damped_step` on every matrix of the stack; in place."""
    for f in range(L1.shape[0]):
        _damped_step(L1[f], D[f], Gr[f], za[f], Lder[f], U, BGr, dz[f], dec[f], pD, gmax)


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
