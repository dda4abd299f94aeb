"""D–G upper bound of μ: the generalised-eigenvalue solver behind :func:`ambseal.robust.mu.mussv`.

Private module. The bound of Fan, Tits & Doyle (1991): μ ≤ β if there are D ≻ 0 and
G = Gᴴ commuting with the (padded, square) structure such that
``Mᴴ D M + j(G M − Mᴴ G) − β² D ⪯ 0``. The generalised-eigenvalue problem in (D, G) is solved
by the method of centres (Boyd & El Ghaoui 1993) with damped Newton steps (compiled, one
matrix at a time: ``robust/_mu_newton.py``). Over a frequency grid the solver runs coarse to
fine: a cold solve on every ``stride``-th frequency, then each finer level starts from the
scalings of its solved neighbours (μ and the optimal scalings vary smoothly with ω), which
needs a few Newton steps instead of a few dozen. The returned bound is always the generalised
eigenvalue at the returned (D, G): a certificate, whatever the solver's accuracy or starting
point.
"""

from __future__ import annotations

import itertools
from dataclasses import dataclass

import numpy as np

from ambseal.robust._mu_newton import gevp, newton_steps

__all__ = ["structure", "upper_bound"]


def _herm(X):
    return 0.5 * (X + np.conj(np.swapaxes(X, -1, -2)))


def _ct(X):
    return np.conj(np.swapaxes(X, -1, -2))


def _hermitian_basis(k):
    """Real basis of k×k Hermitian matrices as (coefficients, pairs (i, j))."""
    pairs = [(i, j) for i in range(k) for j in range(k)]
    idx = {pq: n for n, pq in enumerate(pairs)}
    out = []
    for i in range(k):
        v = np.zeros(k * k, complex)
        v[idx[i, i]] = 1.0
        out.append(v)
    for i in range(k):
        for j in range(i + 1, k):
            v = np.zeros(k * k, complex)
            v[idx[i, j]] = v[idx[j, i]] = 1.0
            out.append(v)
            v = np.zeros(k * k, complex)
            v[idx[i, j]], v[idx[j, i]] = 1j, -1j
            out.append(v)
    return np.array(out), pairs


@dataclass(frozen=True)
class _Basis:
    """Sparse bases of D and G: B_i = Σ_u T[i, u] e_{a_u} e_{b_u}ᵀ in padded coordinates."""

    N: int
    offs: np.ndarray
    TD: np.ndarray  # (pD, rD) trace-free D directions
    aD: np.ndarray
    bD: np.ndarray
    TG: np.ndarray  # (pG, rG)
    aG: np.ndarray
    bG: np.ndarray
    realidx: np.ndarray  # padded indices of real-block rows
    aGl: np.ndarray  # G pairs in local (real-row) coordinates
    bGl: np.ndarray


def structure(blks) -> _Basis:
    """Bases of the D and G scalings for a parsed block structure (padded coordinates)."""
    N = sum(b.size for b in blks)
    offs = np.cumsum([0] + [b.size for b in blks])
    Dcoef, Dpairs, Gcoef, Gpairs = [], [], [], []
    for b, o in zip(blks, offs[:-1]):
        if b.kind == "full":
            base = len(Dpairs)
            Dpairs.extend((o + i, o + i) for i in range(b.size))
            Dcoef.append((base, np.ones(b.size, complex)))
        else:
            coef, pairs = _hermitian_basis(b.size)
            base = len(Dpairs)
            Dpairs.extend((o + i, o + j) for i, j in pairs)
            Dcoef.extend((base, c) for c in coef)
            if b.kind == "real":
                gb = len(Gpairs)
                Gpairs.extend((o + i, o + j) for i, j in pairs)
                Gcoef.extend((gb, c) for c in coef)

    def dense(coefs, npairs):
        T = np.zeros((len(coefs), npairs), complex)
        for i, (base, c) in enumerate(coefs):
            T[i, base:base + c.size] = c
        return T

    TDf = dense(Dcoef, len(Dpairs))
    aD = np.array([q[0] for q in Dpairs], int)
    bD = np.array([q[1] for q in Dpairs], int)
    # trace-free subspace: D = I + Σ z_i B_i keeps tr D = N
    tr = np.real(TDf[:, aD == bD].sum(axis=1))
    _, _, vt = np.linalg.svd(tr[None, :])
    TD = vt[1:] @ TDf
    TG = dense(Gcoef, len(Gpairs)) if Gcoef else np.zeros((0, 0), complex)
    aG = np.array([q[0] for q in Gpairs], int)
    bG = np.array([q[1] for q in Gpairs], int)
    realidx = np.concatenate([np.arange(o, o + b.size) for b, o in zip(blks, offs[:-1])
                              if b.kind == "real"] or [np.zeros(0, int)]).astype(int)
    loc = {g: i for i, g in enumerate(realidx)}
    aGl = np.array([loc[v] for v in aG], int)
    bGl = np.array([loc[v] for v in bG], int)
    return _Basis(N, offs, TD, aD, bD, TG, aG, bG, realidx, aGl, bGl)


def _scatter(vals, a, b, N, base=None):
    """Matrices with vals (F, r) placed at the (unique) positions (a_u, b_u), plus base."""
    F = vals.shape[0]
    out = np.zeros((F, N, N), complex) if base is None else np.broadcast_to(base, (F, N, N)).astype(complex)
    out[:, a, b] += vals
    return out


#: A matrix whose Osborne D spans more than this (a matrix in other units) is solved
#: balanced too, and the lower bound kept: the cold solve starts from Osborne's D clipped
#: to 1e-4 … 1e4 and moves an affine D, and from a start that far off its bound ended
#: 9 % high where D spanned 1e10 (93 065 instead of 3.2468 at 1e24); up to 1e8 it stays
#: within 2e-6, so 1e4 leaves the well-scaled matrices of typical μ designs as they were.
WIDE_SPREAD = 1e4


def _balancing(M, blks, S, sweeps=8):
    """Per-index scalings t (F, N) balancing M (Osborne 1960 on the norms of the groups one
    real scalar may scale: each full block, and each row of a repeated scalar block — any T
    commutes with δI), and which matrices need them (Osborne's D spanning more than
    :data:`WIDE_SPREAD`)."""
    cuts = [0]
    for b, o in zip(blks, S.offs[:-1]):
        cuts += list(range(o + 1, o + b.size + 1)) if b.kind != "full" else [o + b.size]
    cuts = np.asarray(cuts)
    F, ng = M.shape[0], len(cuts) - 1
    Bn = np.empty((F, ng, ng))
    for j in range(ng):
        for k in range(ng):
            Bn[:, j, k] = np.sum(np.abs(M[:, cuts[j]:cuts[j + 1], cuts[k]:cuts[k + 1]]) ** 2,
                                 axis=(1, 2))
    Bn[:, np.arange(ng), np.arange(ng)] = 0.0
    Bn = Bn + 1e-300
    d = np.ones((F, ng))
    for _ in range(sweeps):
        d = np.sqrt(np.einsum("fkj,fk->fj", Bn, d) / np.einsum("fjk,fk->fj", Bn, 1.0 / d))
        d = d / np.exp(np.mean(np.log(d), axis=1, keepdims=True))
    wide = d.max(axis=1) > WIDE_SPREAD * d.min(axis=1)
    return np.repeat(np.sqrt(d), np.diff(cuts), axis=1), wide


def _osborne_init(M, blks, S, sweeps=8):
    """Trace-free coordinates of a diagonal D from Osborne balancing of block norms.

    Minimises ‖D^½ M D^-½‖_F over one scalar per block (Osborne 1960), a cheap start
    for the D–G solver.
    """
    F, N = M.shape[0], S.N
    nb = len(blks)
    offs = S.offs
    Bn = np.empty((F, nb, nb))
    for j in range(nb):
        for k in range(nb):
            Bn[:, j, k] = np.sum(np.abs(M[:, offs[j]:offs[j + 1], offs[k]:offs[k + 1]]) ** 2, axis=(1, 2))
    Bn[:, np.arange(nb), np.arange(nb)] = 0.0
    Bn = Bn + 1e-30
    d = np.ones((F, nb))  # d_j = D entries (squares of the σ̄-form scalings)
    for _ in range(sweeps):
        num = np.einsum("fkj,fk->fj", Bn, d)
        den = np.einsum("fjk,fk->fj", Bn, 1.0 / d)
        d = np.sqrt(num / den)
        d = d / np.exp(np.mean(np.log(d), axis=1, keepdims=True))
        d = np.clip(d, 1e-4, 1e4)
    sizes = np.array([b.size for b in blks])
    d = d * N / (d @ sizes)[:, None]
    diag = np.repeat(d, sizes, axis=1)  # (F, N)
    target = np.zeros((F, S.aD.size))
    on = S.aD == S.bD
    target[:, on] = diag[:, S.aD[on]] - 1.0
    # imaginary (off-diagonal) directions have zero real part and get z = 0
    z, *_ = np.linalg.lstsq(S.TD.T.real, target.T, rcond=None)
    return z.T


class _Problem:
    """The normalised stack M (F, N, N) and its affine scalings.

    With coordinates z = (z_D, z_G): ``D = I + Σ z_i U_i``, ``A = A_0 + Σ z_i V_i`` with
    ``A_0 = Mᴴ M``, ``V_i = Mᴴ U_i M`` for D directions and ``V_i = j(U^G_i M − Mᴴ U^G_i)`` for G
    directions (``U_i = 0`` there), so ``t D − A`` is affine in z with derivative
    ``t U_i − V_i``.
    """

    def __init__(self, M, blks, S, gmax):
        N = S.N
        self.M, self.S, self.gmax = M, S, gmax
        self.pD, self.pG = S.TD.shape[0], S.TG.shape[0]
        self.p = p = self.pD + self.pG
        self.BD = _scatter(S.TD, S.aD, S.bD, N) if self.pD else np.zeros((0, N, N), complex)
        self.BG = _scatter(S.TG, S.aG, S.bG, N) if self.pG else np.zeros((0, N, N), complex)
        self.U = np.concatenate([self.BD, np.zeros_like(self.BG)])
        self.Uf = self.U.reshape(p, N * N)
        ri = S.realidx
        self.BGr = np.ascontiguousarray(self.BG[:, ri[:, None], ri[None, :]])
        self.BGrf = self.BGr.reshape(self.pG, ri.size ** 2)
        # blocks for the barrier −Σ log det D_k (full blocks: scalar multiples of I)
        self.offs = np.asarray(S.offs, np.int64)
        # the coordinates' map to the scaling entries (D's, then G's), sparse by rows: the
        # Newton steps' Hessian of −log det(t D − A) is formed from it (_mu_newton._lmi_term)
        T = np.zeros((p, S.TD.shape[1] + S.TG.shape[1]), complex)
        T[:self.pD, :S.TD.shape[1]] = S.TD
        T[self.pD:, S.TD.shape[1]:] = S.TG
        rows, cols = np.nonzero(T)
        self.tp = np.searchsorted(rows, np.arange(p + 1)).astype(np.int64)
        self.tu, self.tv = cols.astype(np.int64), np.ascontiguousarray(T[rows, cols])
        self.ekind = np.r_[np.zeros(S.aD.size, np.int64), np.ones(S.aG.size, np.int64)]
        self.ea = np.r_[S.aD, S.aG].astype(np.int64)
        self.eb = np.r_[S.bD, S.bG].astype(np.int64)
        self.full = np.array([b.kind == "full" for b in blks], np.bool_)
        # each entry's position inside the barrier matrix it lies in (-1: another one): row
        # k for D's block k, the last row for gmax I ∓ G on the real rows (_mu_newton._derivs)
        r, nb = self.ea.size, len(blks)
        self.loc_a = np.full((nb + 1, r), -1, np.int64)
        self.loc_b = np.full((nb + 1, r), -1, np.int64)
        for k, (o0, o1) in enumerate(zip(self.offs[:-1], self.offs[1:])):
            inb = (self.ekind == 0) & (self.ea >= o0) & (self.ea < o1)
            self.loc_a[k, inb], self.loc_b[k, inb] = self.ea[inb] - o0, self.eb[inb] - o0
        self.loc_a[nb, S.aD.size:], self.loc_b[nb, S.aD.size:] = S.aGl, S.bGl

    def affine(self, idx):
        """A_0 (F, N, N) and V (F, p, N, N) for the matrices M[idx]."""
        M = self.M[idx]
        MH = _ct(M)
        V = np.empty(M.shape[:1] + (self.p,) + M.shape[1:], complex)
        if self.pD:
            V[:, :self.pD] = MH[:, None] @ self.BD[None] @ M[:, None]
        if self.pG:
            V[:, self.pD:] = 1j * (self.BG[None] @ M[:, None] - MH[:, None] @ self.BG[None])
        return _herm(MH @ M), _herm(V)

    def _mats(self, z, A0, V):
        F, N = z.shape[0], self.S.N
        D = np.eye(N) + (z @ self.Uf).reshape(F, N, N)
        A = A0 + (z[:, None, :] @ V.reshape(F, self.p, N * N)).reshape(F, N, N)
        return D, A

    def G(self, z):
        N = self.S.N
        return (z[:, self.pD:] @ self.BG.reshape(self.pG, N * N)).reshape(-1, N, N)

    def direct(self, z, idx):
        """D and A at coordinates z for the matrices M[idx] (without the V stack)."""
        N = self.S.N
        M = self.M[idx]
        D = np.eye(N) + (z @ self.Uf).reshape(-1, N, N)
        A = _ct(M) @ D @ M
        if self.pG:
            GM = self.G(z) @ M
            A = A + 1j * (GM - _ct(GM))
        return D, _herm(A)

    def lam(self, z, idx):
        """λ_max(D⁻¹ A) at z; +inf where D is not positive definite."""
        return _gevp(*self.direct(z, idx))


def _gevp(D, A):
    """λ_max(D⁻¹ A) (F,) for Hermitian stacks; +inf where D is not positive definite."""
    return gevp(np.ascontiguousarray(D, complex), np.ascontiguousarray(A, complex))


def _pd_all(*stacks):
    """True where every matrix of every stack (same leading length F) is positive definite."""
    F = stacks[0].shape[0]
    ok = np.ones(F, bool)
    for L in stacks:
        try:
            np.linalg.cholesky(L)
        except np.linalg.LinAlgError:
            ok &= np.linalg.eigvalsh(L)[:, 0] > 0
    return ok


#: Levels of the method of centres over which a matrix's best λ must fall by ``tol`` of
#: itself, or its solve has stalled and ends (:func:`_centres_chunk`). A centred solve
#: shrinks the gap by θ = 1/4 a level, so it meets a tolerance of 1e-9 within 15 levels;
#: one that centres slowly goes longer between falls and still converges. 100 is about
#: three times the longest such run on published μ-synthesis problems (benchmarks/README.md,
#: "μ's upper bound ends by its own rules"), where a rule at 30 cut converging solves short.
STALL_LEVELS = 100

_CHUNK_ELEMS = 2_000_000  # complex entries of the (F, p, N, N) derivative stack per chunk


def _centres(P, z, t, tol, max_iter, idx, **kw):
    """Method of centres on M[idx] in chunks that keep the derivative stack small."""
    idx = np.asarray(idx)
    chunk = max(8, _CHUNK_ELEMS // max(P.p * P.S.N ** 2, 1))
    if idx.size <= chunk:
        return _centres_chunk(P, z, t, tol, max_iter, idx, **kw)
    parts = [_centres_chunk(P, z[s], t[s], tol, max_iter, idx[s], **kw)
             for s in (slice(i, i + chunk) for i in range(0, idx.size, chunk))]
    return np.concatenate([q[0] for q in parts]), np.concatenate([q[1] for q in parts])


def _centres_chunk(P, z, t, tol, max_iter, idx, theta=0.25, n_newton=5, dec_tol=0.5):
    """Method of centres for the matrices M[idx] from coordinates z (F, p) at levels t > λ(z).

    For the current level t the analytic centre of {t D − A ≻ 0, D ≻ 0, gmax I ± G ≻ 0}
    is approached by damped Newton steps (self-concordant, so the damped step stays
    feasible), then t ← λ + θ (t − λ). A matrix's solve ends at its own criterion: centred
    with the gap t − λ within ``tol`` of λ, the interior lost to rounding, or a stall (its
    best λ fell by less than ``tol`` of itself over :data:`STALL_LEVELS` levels); never at
    a count unless ``max_iter`` (levels) is given. Returns the best λ and its coordinates.
    """
    pD, pG, p, gmax = P.pD, P.pG, P.p, P.gmax
    F, N = z.shape[0], P.S.N
    idx = np.asarray(idx)
    A0all, Vall = P.affine(idx)
    Mall = np.ascontiguousarray(P.M[idx], complex)
    z, t = z.copy(), t.copy()
    best_lam = _gevp(*P._mats(z, A0all, Vall))
    best_z = z.copy()
    eyeN = np.eye(N)
    nr = P.S.realidx.size
    active = np.arange(F) if p else np.arange(0)
    ref, still = best_lam.copy(), np.zeros(F, int)  # stall test: λ at the last fall, levels since
    for _ in (itertools.count() if max_iter is None else range(max_iter)):
        if active.size == 0:
            break
        Fa = active.size
        A0, V, za, ta = A0all[active], Vall[active], z[active], t[active]
        Lder = ta[:, None, None, None] * P.U[None] - V  # (Fa, p, N, N)
        Lderf = Lder.reshape(Fa, p, N * N)
        L0 = ta[:, None, None] * eyeN - A0
        L1 = L0 + (za[:, None, :] @ Lderf).reshape(Fa, N, N)
        D = eyeN + (za @ P.Uf).reshape(Fa, N, N)
        Gr = (za[:, pD:] @ P.BGrf).reshape(Fa, nr, nr) if pG else None
        bad = ~_pd_all(L1)
        if bad.any():  # lost interior (rounding): keep the best scalings found so far
            keep = ~bad
            active, A0, V, za, ta = active[keep], A0[keep], V[keep], za[keep], ta[keep]
            Lder, Lderf, L1, D = Lder[keep], Lderf[keep], L1[keep], D[keep]
            Gr = Gr[keep] if pG else None
            Fa = active.size
            if Fa == 0:
                break
        # damped Newton steps towards the centre (in place; see newton_steps)
        centred, lost = newton_steps(L1, D, Gr if pG else np.zeros((Fa, 0, 0), complex), za,
                                     Lder, P.U, P.BD, P.BGr, P.offs, P.full, float(gmax), pD,
                                     n_newton, dec_tol, Mall[active], ta, P.tp, P.tu, P.tv,
                                     P.ekind, P.ea, P.eb, P.loc_a, P.loc_b)
        lam_a = _gevp(D, ta[:, None, None] * D - L1)
        better = lam_a < best_lam[active]
        best_lam[active[better]] = lam_a[better]
        best_z[active[better]] = za[better]
        fell = best_lam[active] < (1.0 - tol) * ref[active]
        ref[active[fell]] = best_lam[active[fell]]
        still[active] = np.where(fell, 0, still[active] + 1)
        z[active] = za
        gap = ta - lam_a
        t[active] = lam_a + theta * gap
        # lost: rounding left the interior (t D − A singular to working precision), so
        # the level cannot come closer to λ; the best scalings found so far stand
        done = lost | (centred & (gap <= tol * np.maximum(lam_a, 1e-300) + 1e-14)) \
            | (still[active] >= STALL_LEVELS)
        active = active[~done]
    return best_lam, best_z


def _continuation(P, z, tol, max_iter, stride, t0_factor, warm_factor):
    """Coarse-to-fine solve over an ordered stack: cold on every stride-th, then bisect."""
    F = z.shape[0]
    solved = np.zeros(F, bool)
    idx = np.unique(np.r_[np.arange(0, F, stride), F - 1])
    best_z = z.copy()
    lam0 = P.lam(z[idx], idx)
    _, best_z[idx] = _centres(P, z[idx], lam0 * t0_factor + 1e-12, tol, max_iter, idx)
    solved[idx] = True
    while not solved.all():
        s_idx = np.flatnonzero(solved)
        lo, hi = s_idx[:-1], s_idx[1:]
        gap = hi - lo
        sel = gap > 1
        lo, hi = lo[sel], hi[sel]
        new = (lo + hi) // 2
        wgt = ((new - lo) / (hi - lo))[:, None]
        cands = [best_z[lo], best_z[hi], (1 - wgt) * best_z[lo] + wgt * best_z[hi]]
        lams = np.stack([P.lam(c, new) for c in cands])
        k = np.argmin(lams, axis=0)
        z0 = np.stack(cands)[k, np.arange(new.size)]
        lam0 = lams[k, np.arange(new.size)]
        _, best_z[new] = _centres(P, z0, lam0 * warm_factor + 1e-12, tol, max_iter, new)
        solved[new] = True
    return best_z


def _refine_peak(P, best_z, nrm, tol, peak_tol, max_iter, batch=16):
    """Continue the method of centres to ``peak_tol`` on the stack's largest bounds (the
    reported μ) from their scalings; in place. The bounds within ``2·tol`` of the peak (at
    most ``batch``, largest first) are refined at once, from the level ``(1 + 2·tol)·λ``
    (their scalings are already optimal to about ``tol``); then, while the largest bound is
    not a refined one, the unrefined bounds above the largest refined one (``batch`` at a
    time, largest first). The reported peak is then a refined bound, and no other matrix's
    optimal bound can exceed it: each round refines at least one more matrix, so the loop
    ends by that rule, within the stack's size.
    ``nrm``: the stack's normalisation (the bound of matrix k is sqrt(λ_k)·nrm_k)."""
    F = best_z.shape[0]
    lam = _gevp(*P.direct(best_z, np.arange(F)))
    mu2 = lam * nrm ** 2
    order = np.argsort(-mu2)[:batch]
    todo = order[mu2[order] >= (1.0 - 2.0 * tol) * mu2[order[0]]]
    done = np.zeros(F, bool)
    while todo.size:
        lam_k, z_k = _centres(P, best_z[todo], lam[todo] * (1.0 + 2.0 * tol) + 1e-12,
                              peak_tol, max_iter, todo)
        better = lam_k < lam[todo]
        lam[todo[better]], best_z[todo[better]] = lam_k[better], z_k[better]
        done[todo] = True
        mu2 = lam * nrm ** 2
        above = np.flatnonzero(~done & (mu2 > mu2[done].max()))
        todo = above[np.argsort(-mu2[above])][:batch]


def upper_bound(Mp, blks, tol, max_iter, gmax, *, stride=0, t0_factor=1.2, warm_factor=None,
                peak_tol=None, balance=True):
    """D–G upper bound on the padded stack Mp (F, N, N).

    Parameters
    ----------
    Mp : ndarray, shape (F, N, N)
        Padded matrices (non-square full blocks embedded in square ones).
    blks : tuple of _Block
    tol, max_iter, gmax
        As in :func:`ambseal.robust.mu.mussv`.
    stride : int
        0: every matrix solved cold from Osborne balancing. ``stride > 1``: the stack is an
        ordered, smooth family (a frequency grid); every ``stride``-th matrix is solved cold,
        then levels of halved spacing start from their solved neighbours' scalings.
    t0_factor : float
        Cold solves start at the level ``t0_factor·λ`` of their starting scalings.
    warm_factor : float, optional
        Warm starts begin at the level ``warm_factor·λ`` of the best neighbour-based
        scalings; default ``1 + tol/2``: where the centre at that level lowers λ by less than
        ``tol/2`` the solve stops after one centring (a 108-state loop, 500 frequencies:
        about 5 Newton steps per frequency instead of 10, and no larger error against a
        ``tol = 1e-6`` solve: 7.4e-4 vs 9.8e-4 with ``1 + 2·tol``).
    peak_tol : float, optional
        The bounds within ``2·tol`` of the largest one are refined further, to this
        tolerance (:func:`_refine_peak`); default ``tol·1e-3``.
    balance : bool
        Solve the matrices whose Osborne balancing spans more than :data:`WIDE_SPREAD`
        balanced too, keeping the lower bound (:func:`_balancing`).

    Returns
    -------
    upper : (F,) the bound, ``sqrt(λ_max(D⁻¹ A))`` at the returned scalings
    D : (F, N, N) Hermitian positive definite (tr D = N)
    G : (F, N, N) Hermitian, zero outside real blocks
    offs : block offsets in padded coordinates
    """
    F = Mp.shape[0]
    peak_tol = 1e-3 * tol if peak_tol is None else peak_tol
    S = structure(blks)
    nrm = np.linalg.norm(Mp, ord=2, axis=(-2, -1))
    nrm = np.where(nrm > 0, nrm, 1.0)
    M = Mp / nrm[:, None, None]
    P = _Problem(M, blks, S, gmax)
    z = np.zeros((F, P.p))
    if P.pD:
        z[:, :P.pD] = _osborne_init(M, blks, S)
    if P.p == 0:
        best_z = z
    elif stride <= 1 or F <= 2 * stride:
        idx = np.arange(F)
        lam0 = P.lam(z, idx)
        _, best_z = _centres(P, z, lam0 * t0_factor + 1e-12, tol, max_iter, idx)
    else:
        best_z = _continuation(P, z, tol, max_iter, stride, t0_factor,
                               1.0 + 0.5 * tol if warm_factor is None else warm_factor)
    if P.p and peak_tol < tol:
        _refine_peak(P, best_z, nrm, tol, peak_tol, max_iter)
    # the returned bound is the generalised eigenvalue at the returned scalings
    D, A = P.direct(best_z, np.arange(F))
    upper = np.sqrt(np.maximum(_gevp(D, A), 0.0)) * nrm
    # the LMI is homogeneous in (D, G); M was divided by nrm, so G scales with nrm
    G = P.G(best_z) * nrm[:, None, None]
    t, wide = _balancing(Mp, blks, S) if balance else (None, np.zeros(F, bool))
    if np.any(wide):
        # a matrix in other units: its bound solved balanced too (M_b = T M T⁻¹, the bound
        # invariant, the solver's conditioning not) and the lower one kept — with its
        # certificate mapped back, D = T D_b T, G = T G_b T, renormalised to tr D = N
        idx = np.flatnonzero(wide)
        Mb = t[idx, :, None] * Mp[idx] / t[idx, None, :]
        ub, Db, Gb, _ = upper_bound(Mb, blks, tol, max_iter, gmax, peak_tol=peak_tol,
                                    balance=False)
        lower_ = ub < upper[idx] * (1.0 - tol)
        for j, k in zip(np.flatnonzero(lower_), idx[lower_]):
            Dk, Gk = (t[k][:, None] * X * t[k][None, :] for X in (Db[j], Gb[j]))
            c = S.N / np.real(np.trace(Dk))
            upper[k], D[k], G[k] = ub[j], Dk * c, Gk * c
    return upper, _herm(D), _herm(G), S.offs
