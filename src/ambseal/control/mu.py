"""Structured singular value μ: upper and lower bounds for mixed real/complex structures.

Block structures follow MATLAB's ``mussv`` notation: a list of pairs ``(r, c)``

* ``(-k, 0)``: repeated real scalar ``δ I_k``, ``δ ∈ ℝ``;
* ``(k, 0)``: repeated complex scalar ``δ I_k``, ``δ ∈ ℂ``;
* ``(r, c)`` with ``c > 0``: full complex ``r × c`` block.

Δ = blockdiag(Δ_1, …) is ``m × n`` for ``M`` of shape ``n × m``: block ``j`` reads ``c_j``
rows of ``M`` (its outputs) and drives ``r_j`` columns (its inputs), so ``Σ c_j = n`` and
``Σ r_j = m``; scalar blocks count ``k`` for both. μ_Δ(M) = 1 / min{σ̄(Δ) : det(I − MΔ) = 0}.
In the thesis (Paper 3 §3.4, Paper 5 §4.3) Δ̂ = diag(Δ, Δ_P) collects the seal uncertainty and
the fictitious performance block; robust performance holds when sup_ω μ < 1.

Upper bound
    The D–G bound of Fan, Tits & Doyle (1991) (Young, Newlin & Doyle 1995): μ ≤ β if there
    are D ≻ 0 and G = Gᴴ commuting with the structure such that
    ``Mᴴ D M + j(G M − Mᴴ G) − β² D ⪯ 0``. Non-square full blocks are padded to square ones
    (μ unchanged), D has a full Hermitian block for each repeated scalar, G lives on real
    blocks only. The generalised-eigenvalue problem in (D, G) is solved by the method of
    centres (Boyd & El Ghaoui 1993) with damped Newton steps, vectorised over the stack.
    The returned bound is the generalised eigenvalue at the returned (D, G): a certificate,
    whatever the solver's accuracy.
Lower bound
    Power iteration (Packard & Doyle 1993, §9; real blocks projected to ±1 as in Young &
    Doyle 1997), the bound being 1/σ̄(Δ) for a Δ that is checked to make I − MΔ singular.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Sequence

import numpy as np
import scipy.linalg as sla

__all__ = ["MuResult", "mussv", "parse_blocks", "freqresp"]


# --------------------------------------------------------------------------- blocks
@dataclass(frozen=True)
class _Block:
    kind: str  # "real", "complex" (repeated scalars) or "full"
    r: int  # columns of M driven (Δ rows)
    c: int  # rows of M read (Δ columns)

    @property
    def size(self) -> int:
        return max(self.r, self.c)


def parse_blocks(blocks: Sequence[Sequence[int]]) -> tuple[_Block, ...]:
    """Validate a MATLAB-style block structure.

    Parameters
    ----------
    blocks : sequence of (int, int)
        ``(-k, 0)`` repeated real, ``(k, 0)`` repeated complex, ``(r, c)`` full complex.

    Returns
    -------
    tuple of _Block

    Raises
    ------
    ValueError
        Empty structure, non-integer entries, ``k = 0``, a negative size in a full block.
    """
    if blocks is None or len(blocks) == 0:
        raise ValueError("blocks: empty block structure")
    out = []
    for i, b in enumerate(blocks):
        try:
            r, c = (int(v) for v in b)
            if any(float(v) != int(v) for v in b) or len(b) != 2:
                raise ValueError
        except (TypeError, ValueError):
            raise ValueError(f"blocks[{i}]={b!r}: expected a pair of integers (r, c)") from None
        if c == 0:
            if r == 0:
                raise ValueError(f"blocks[{i}]=(0, 0): a block needs a non-zero size")
            out.append(_Block("real" if r < 0 else "complex", abs(r), abs(r)))
        else:
            if r <= 0 or c < 0:
                raise ValueError(f"blocks[{i}]=({r}, {c}): a full block needs r > 0 and c > 0")
            out.append(_Block("full", r, c))
    return tuple(out)


def _dims(blks):
    return sum(b.c for b in blks), sum(b.r for b in blks)


# --------------------------------------------------------------------------- result
@dataclass(frozen=True)
class MuResult:
    """Bounds on μ over a stack of matrices (or over frequency).

    Attributes
    ----------
    upper, lower : ndarray, shape ``stack``
        Upper and lower bounds of μ (dimensionless); ``lower ≤ upper``.
    Dl : ndarray, shape ``stack + (n, n)``
        Left (output-side) scaling, Hermitian positive definite.
    Dr : ndarray, shape ``stack + (m, m)``
        Right (input-side) scaling, with the same block values as ``Dl``; for purely complex
        structures ``σ̄(Dl M Dr⁻¹) ≤ upper``.
    G : ndarray, shape ``stack + (m, n)``
        Real-block scaling: ``Mᴴ Dl² M + j(G M − Mᴴ Gᴴ) ⪯ upper² Dr²`` (zero without real
        blocks).
    dscale : ndarray, shape ``stack + (nblocks,)``
        Scalar D per block (``Dl = blockdiag(dscale_j I)`` for full and 1×1 blocks;
        ``sqrt(tr D_j² / k)`` for repeated scalars), normalised so the last block is 1.
    delta : ndarray, shape ``stack + (m, n)``
        Worst-case perturbation from the lower bound: structured, ``σ̄(Δ) = 1/lower`` and
        ``I − MΔ`` singular (zero where the lower bound is 0).
    omega : ndarray or None
        Frequencies in rad/s when computed over frequency.
    blocks : tuple
        The block structure as given.
    """

    upper: np.ndarray
    lower: np.ndarray
    Dl: np.ndarray = field(repr=False)
    Dr: np.ndarray = field(repr=False)
    G: np.ndarray = field(repr=False)
    dscale: np.ndarray = field(repr=False)
    delta: np.ndarray = field(repr=False)
    omega: np.ndarray | None = None
    blocks: tuple = ()

    @property
    def peak_upper(self) -> float:
        """Largest upper bound over the stack."""
        return float(np.max(self.upper))

    @property
    def peak_omega(self) -> float | None:
        """Frequency (rad/s) of the peak upper bound, or None for a matrix stack."""
        if self.omega is None:
            return None
        return float(self.omega[np.argmax(self.upper)])

    def to_dict(self) -> dict:
        """JSON-ready bounds (scalings left out)."""
        return {
            "upper": np.asarray(self.upper).tolist(), "lower": np.asarray(self.lower).tolist(),
            "peak_upper": self.peak_upper,
            "omega_rad_s": None if self.omega is None else np.asarray(self.omega).tolist(),
            "blocks": [list(b) for b in self.blocks],
        }


# --------------------------------------------------------------------------- helpers
def freqresp(sys, omega) -> np.ndarray:
    """Frequency response of a state-space system, shape ``(len(omega), p, m)``.

    Parameters
    ----------
    sys : control.StateSpace
        Continuous-time system.
    omega : array_like
        Frequencies in rad/s.
    """
    return _freqresp(*(np.asarray(X, float) for X in (sys.A, sys.B, sys.C, sys.D)), omega)


def _freqresp(A, B, C, D, omega):
    w = np.atleast_1d(np.asarray(omega, float))
    if A.shape[0] == 0:
        return np.broadcast_to(D.astype(complex), (w.size,) + D.shape).copy()
    # orthogonal Hessenberg reduction first (balances the batched solves)
    H, Q = sla.hessenberg(A, calc_q=True)
    Bq, Cq = Q.T @ B, C @ Q
    X = np.linalg.solve(1j * w[:, None, None] * np.eye(A.shape[0]) - H,
                        np.broadcast_to(Bq, (w.size,) + Bq.shape))
    return Cq @ X + D


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


def _structure(blks) -> _Basis:
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


def _pad(M, blks):
    """Embed M (…, n, m) into the padded square matrix (…, N, N)."""
    N = sum(b.size for b in blks)
    Mp = np.zeros(M.shape[:-2] + (N, N), complex)
    rows, cols = [], []
    o = 0
    for b in blks:
        rows.extend(range(o, o + b.c))
        cols.extend(range(o, o + b.r))
        o += b.size
    rows, cols = np.array(rows, int), np.array(cols, int)
    Mp[..., rows[:, None], cols[None, :]] = M
    return Mp, rows, cols


# --------------------------------------------------------------------------- upper bound
def _scatter(vals, a, b, N, base=None):
    """Matrices with vals (F, r) placed at the (unique) positions (a_u, b_u), plus base."""
    F = vals.shape[0]
    out = np.zeros((F, N, N), complex) if base is None else np.broadcast_to(base, (F, N, N)).astype(complex)
    out[:, a, b] += vals
    return out


def _quad(T1, K, T2):
    return np.real(T1 @ K @ T2.T)


def _pd(L):
    """Boolean mask of positive-definite matrices in a stack."""
    try:
        np.linalg.cholesky(L)
        return np.ones(L.shape[0], bool)
    except np.linalg.LinAlgError:
        return np.linalg.eigvalsh(L)[:, 0] > 0


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


def _upper(Mp, blks, tol, max_iter, gmax, theta=0.25, n_newton=5, dec_tol=0.5, t0_factor=1.2):
    """Method-of-centres D–G upper bound on the padded stack Mp (F, N, N).

    Minimises the generalised eigenvalue λ_max(A(D, G), D) with
    A = Mᴴ D M + j(G M − Mᴴ G) over D = I + Σ z_i B_i (tr D = N) and G (Boyd & El Ghaoui
    1993): for the current level t the analytic centre of {t D − A ≻ 0, D ≻ 0,
    gmax I ± G ≻ 0} is approached by damped Newton steps (self-concordant, so the damped
    step stays feasible), then t ← λ + θ (t − λ).
    """
    F = Mp.shape[0]
    S = _structure(blks)
    N = S.N
    pD, pG = S.TD.shape[0], S.TG.shape[0]
    p = pD + pG
    eye = np.eye(N)
    nrm = np.linalg.norm(Mp, ord=2, axis=(-2, -1))
    nrm = np.where(nrm > 0, nrm, 1.0)
    M = Mp / nrm[:, None, None]
    nr = S.realidx.size
    ri = S.realidx
    z = np.zeros((F, p))
    Dblocks = [(int(S.offs[j]), int(S.offs[j + 1]), b.kind == "full") for j, b in enumerate(blks)]

    def mats(Ma, MaH, za, base=True):
        D = _scatter(za[:, :pD] @ S.TD, S.aD, S.bD, N, eye if base else None)
        if pG:
            G = _scatter(za[:, pD:] @ S.TG, S.aG, S.bG, N)
            GM = G[:, :, ri] @ Ma[:, ri, :] if nr < N else G @ Ma
            A = MaH @ D @ Ma + 1j * (GM - _ct(GM))
        else:
            G = None
            A = MaH @ D @ Ma
        return D, G, _herm(A)

    def dinv(D):
        X2 = np.zeros_like(D)
        for o0, o1, full in Dblocks:
            if full:
                X2[:, o0:o1, o0:o1] = np.eye(o1 - o0) / D[:, o0:o0 + 1, o0:o0 + 1].real
            else:
                X2[:, o0:o1, o0:o1] = np.linalg.inv(D[:, o0:o1, o0:o1])
        return X2

    def gevp(D, A):
        Lc = np.linalg.cholesky(D)
        X = np.linalg.solve(Lc, A)
        X = np.linalg.solve(Lc, _ct(X))
        return np.linalg.eigvalsh(_herm(X))[:, -1]

    if pD:
        z[:, :pD] = _osborne_init(M, blks, S)
    D0, _, A0 = mats(M, _ct(M), z)
    lam = gevp(D0, A0)
    t = lam * t0_factor + 1e-12
    best_lam, best_z = lam.copy(), z.copy()
    active = np.arange(F) if p else np.arange(0)
    for _ in range(max_iter):
        if active.size == 0:
            break
        Ma, za, ta = M[active], z[active], t[active]
        Fa = active.size
        MaH = _ct(Ma)
        tt = ta[:, None, None]
        centred = np.zeros(Fa, bool)
        D, G, A = mats(Ma, MaH, za)
        L1 = tt * D - A
        for _newton in range(n_newton):
            X = np.linalg.inv(L1)
            Zm = Ma @ X
            ZH = _ct(Zm)
            Y = _herm(Zm @ MaH)
            X2 = dinv(D)
            gD = -np.real((tt[:, :, 0] * X[:, S.bD, S.aD] - Y[:, S.bD, S.aD] + X2[:, S.bD, S.aD]) @ S.TD.T)
            # L_i = Σ α_s U_sᴴ B_i V_s; D: (t, I, I), (−1, M, M); G: (−j, I, M), (+j, M, I).
            # tr(X L_i X L_j) = Σ α_s α_s' tr(B_i P B_j Q), P = V_s X U_s'ᴴ, Q = V_s' X U_sᴴ,
            # with I X Iᴴ = X, M X = Z, X Mᴴ = Zᴴ, M X Mᴴ = Y; tr(B_i P B_j Q) = T_i K T_jᵀ
            # with K[u, v] = P[b_u, a_v] Q[b_v, a_u] (gathered once for the whole stack).
            St = np.stack([X, Zm, ZH, Y, X2])
            gd = St[:, :, S.bD[:, None], S.aD[None, :]]
            gdT = np.swapaxes(gd, -1, -2)
            KDD = (tt**2 * gd[0] * gdT[0] - tt * (gd[2] * gdT[1] + gd[1] * gdT[2])
                   + gd[3] * gdT[3] + gd[4] * gdT[4])
            HDD = _quad(S.TD, KDD, S.TD)
            if pG:
                Gr = G[:, ri[:, None], ri[None, :]]
                X3 = np.linalg.inv(gmax * np.eye(nr) - Gr)
                X4 = np.linalg.inv(gmax * np.eye(nr) + Gr)
                gG = np.real((1j * (Zm[:, S.bG, S.aG] - ZH[:, S.bG, S.aG])
                              + X3[:, S.bGl, S.aGl] - X4[:, S.bGl, S.aGl]) @ S.TG.T)
                # DG: P[bD_u, aG_v] Q[bG_v, aD_u]
                p1 = St[:4, :, S.bD[:, None], S.aG[None, :]]
                q1 = np.swapaxes(St[:4, :, S.bG[:, None], S.aD[None, :]], -1, -2)
                X_, Z_, ZH_, Y_ = 0, 1, 2, 3
                KDG = (tt * (-1j) * p1[X_] * q1[Z_] + tt * 1j * p1[ZH_] * q1[X_]
                       + 1j * p1[Z_] * q1[Y_] - 1j * p1[Y_] * q1[ZH_])
                gg = St[:4, :, S.bG[:, None], S.aG[None, :]]
                ggT = np.swapaxes(gg, -1, -2)
                S34 = np.stack([X3, X4])[:, :, S.bGl[:, None], S.aGl[None, :]]
                KGG = (-gg[Z_] * ggT[Z_] + gg[Y_] * ggT[X_] + gg[X_] * ggT[Y_] - gg[ZH_] * ggT[ZH_]
                       + S34[0] * np.swapaxes(S34[0], -1, -2) + S34[1] * np.swapaxes(S34[1], -1, -2))
                HDG = _quad(S.TD, KDG, S.TG)
                HGG = _quad(S.TG, KGG, S.TG)
                g = np.concatenate([gD, gG], axis=1)
                H = np.concatenate([np.concatenate([HDD, HDG], axis=2),
                                    np.concatenate([np.swapaxes(HDG, 1, 2), HGG], axis=2)], axis=1)
            else:
                g, H = gD, HDD
            H = 0.5 * (H + np.swapaxes(H, 1, 2))
            H = H + 1e-12 * (np.trace(H, axis1=1, axis2=2) / p)[:, None, None] * np.eye(p)
            dz = -np.linalg.solve(H, g[..., None])[..., 0]
            dec = np.sqrt(np.maximum(-np.einsum("fi,fi->f", g, dz), 0.0))
            centred = dec < dec_tol
            if centred.all():
                break
            step = np.where(dec < 0.25, 1.0, 1.0 / (1.0 + dec))
            dD, dG, dA = mats(Ma, MaH, dz, base=False)
            dL1 = tt * dD - dA
            for _bt in range(12):
                sc = step[:, None, None]
                ok = _pd(L1 + sc * dL1) & _pd(D + sc * dD)
                if pG:
                    Gn = (G + sc * dG)[:, ri[:, None], ri[None, :]]
                    ok &= _pd(gmax * np.eye(nr) - Gn) & _pd(gmax * np.eye(nr) + Gn)
                if ok.all():
                    break
                step = np.where(ok, step, 0.5 * step)
            step = np.where(ok, step, 0.0)
            sc = step[:, None, None]
            za = za + step[:, None] * dz
            D, L1, A = D + sc * dD, L1 + sc * dL1, A + sc * dA
            if pG:
                G = G + sc * dG
        lam_a = gevp(D, A)
        better = lam_a < best_lam[active]
        best_lam[active[better]] = lam_a[better]
        best_z[active[better]] = za[better]
        z[active] = za
        gap = ta - lam_a
        t[active] = lam_a + theta * gap
        done = centred & (gap <= tol * np.maximum(lam_a, 1e-300) + 1e-14)
        active = active[~done]
    # the returned bound is the generalised eigenvalue at the returned scalings
    D, G, A = mats(M, _ct(M), best_z)
    upper = np.sqrt(np.maximum(gevp(D, A), 0.0)) * nrm
    # the LMI is homogeneous in (D, G); M was divided by nrm, so G scales with nrm
    G = np.zeros((F, N, N), complex) if G is None else G * nrm[:, None, None]
    return upper, _herm(D), _herm(G), S.offs


# --------------------------------------------------------------------------- lower bound
def _lower(M, blks, n_iter, rng):
    """Power iteration lower bound (Packard & Doyle 1993; Young & Doyle 1997) on M (F, n, m)."""
    F, n, m = M.shape
    MH = _ct(M)
    ro = np.cumsum([0] + [b.c for b in blks])  # row offsets (a, z)
    co = np.cumsum([0] + [b.r for b in blks])  # column offsets (b, w)
    _, _, vh = np.linalg.svd(M)
    b = np.conj(vh[:, 0, :])
    w = b.copy()
    eps = 1e-300

    def phase(x):
        return x / np.maximum(np.abs(x), eps)

    def qfor(a, w):
        q = np.zeros((F, len(blks)), complex)
        for j, bl in enumerate(blks):
            if bl.kind == "full":
                continue
            ip = np.einsum("fi,fi->f", np.conj(a[:, ro[j]:ro[j + 1]]), w[:, co[j]:co[j + 1]])
            q[:, j] = np.sign(ip.real) + (ip.real == 0) if bl.kind == "real" else phase(ip)
        return q

    def build_Q(a, w, q):
        Q = np.zeros((F, m, n), complex)
        for j, bl in enumerate(blks):
            rs, cs = slice(co[j], co[j + 1]), slice(ro[j], ro[j + 1])
            if bl.kind == "full":
                wj, aj = w[:, rs], a[:, cs]
                nw = np.linalg.norm(wj, axis=1)[:, None, None]
                na = np.linalg.norm(aj, axis=1)[:, None, None]
                Q[:, rs, cs] = wj[:, :, None] * np.conj(aj[:, None, :]) / np.maximum(nw * na, eps)
            else:
                Q[:, rs, cs] = q[:, j, None, None] * np.eye(bl.r)
        return Q

    def evaluate(Q):
        lamv = np.linalg.eigvals(M @ Q)  # (F, n)
        has_real = any(bl.kind == "real" for bl in blks)
        if not has_real:
            k = np.argmax(np.abs(lamv), axis=1)
            return np.abs(lamv[np.arange(F), k]), lamv[np.arange(F), k], Q
        realmask = np.abs(lamv.imag) <= 1e-9 * np.maximum(np.abs(lamv), 1e-300)
        mag = np.where(realmask, np.abs(lamv), 0.0)
        k = np.argmax(mag, axis=1)
        lb, lam = mag[np.arange(F), k], lamv[np.arange(F), k].real + 0j
        # alternative: real blocks set to zero, complex blocks absorb the phase
        if any(bl.kind != "real" for bl in blks):
            Qc = Q.copy()
            for j, bl in enumerate(blks):
                if bl.kind == "real":
                    Qc[:, co[j]:co[j + 1], ro[j]:ro[j + 1]] = 0.0
            lv = np.linalg.eigvals(M @ Qc)
            kc = np.argmax(np.abs(lv), axis=1)
            lbc = np.abs(lv[np.arange(F), kc])
            use = lbc > lb
            lb = np.where(use, lbc, lb)
            lam = np.where(use, lv[np.arange(F), kc], lam)
            Q = np.where(use[:, None, None], Qc, Q)
        return lb, lam, Q

    best = np.zeros(F)
    best_delta = np.zeros((F, m, n), complex)
    checks = {max(n_iter // 2, 1), n_iter}
    for it in range(1, n_iter + 1):
        a = np.einsum("fij,fj->fi", M, b)
        a = a / np.maximum(np.linalg.norm(a, axis=1), eps)[:, None]
        q = qfor(a, w)
        zv = np.zeros((F, n), complex)
        for j, bl in enumerate(blks):
            rs, cs = slice(co[j], co[j + 1]), slice(ro[j], ro[j + 1])
            if bl.kind == "full":
                ratio = np.linalg.norm(w[:, rs], axis=1) / np.maximum(np.linalg.norm(a[:, cs], axis=1), eps)
                zv[:, cs] = ratio[:, None] * a[:, cs]
            else:
                zv[:, cs] = np.conj(q[:, j])[:, None] * w[:, rs]
        w = np.einsum("fij,fj->fi", MH, zv)
        w = w / np.maximum(np.linalg.norm(w, axis=1), eps)[:, None]
        q = qfor(a, w)
        bn = np.zeros((F, m), complex)
        for j, bl in enumerate(blks):
            rs, cs = slice(co[j], co[j + 1]), slice(ro[j], ro[j + 1])
            if bl.kind == "full":
                ratio = np.linalg.norm(a[:, cs], axis=1) / np.maximum(np.linalg.norm(w[:, rs], axis=1), eps)
                bn[:, rs] = ratio[:, None] * w[:, rs]
            else:
                bn[:, rs] = q[:, j][:, None] * a[:, cs]
        nb = np.linalg.norm(bn, axis=1)
        # restart dead directions at random
        dead = nb < 1e-12
        if dead.any():
            bn[dead] = rng.standard_normal((dead.sum(), m)) + 1j * rng.standard_normal((dead.sum(), m))
            nb = np.linalg.norm(bn, axis=1)
        b = bn / nb[:, None]
        if it in checks:
            lb, lam, Q = evaluate(build_Q(a, w, qfor(a, w)))
            up = lb > best
            best = np.where(up, lb, best)
            safe = np.where(np.abs(lam) > 0, lam, 1.0)
            best_delta = np.where(up[:, None, None], Q / safe[:, None, None], best_delta)
    return best, best_delta


# --------------------------------------------------------------------------- public
def mussv(M, blocks, omega=None, *, tol: float = 1e-3, max_iter: int = 200,
          lower_iter: int = 30, gmax: float = 1e3, seed: int = 0) -> MuResult:
    """Upper and lower bounds of the structured singular value μ_Δ(M).

    Parameters
    ----------
    M : array_like, shape (..., n, m), or control.StateSpace
        A complex matrix or a stack of them; or a continuous-time system evaluated at
        ``s = jω`` for each ``ω`` in ``omega``.
    blocks : sequence of (int, int)
        MATLAB ``mussv`` block structure (see module docstring); ``Σ c_j = n``, ``Σ r_j = m``.
    omega : array_like, optional
        Frequencies in rad/s; required when ``M`` is a state-space system.
    tol : float
        Relative stopping tolerance on ``upper²`` (method-of-centres gap); the bound is a
        certificate either way, ``tol`` only sets how close it gets to the optimal D–G bound
        (about ``tol/2`` relative in practice).
    max_iter : int
        Outer iterations of the upper-bound solver.
    lower_iter : int
        Power iterations for the lower bound.
    gmax : float
        Bound on ‖G‖ relative to the normalised problem (real blocks only).
    seed : int
        Seed for restarts of the power iteration.

    Returns
    -------
    MuResult
        ``upper``/``lower`` with shape ``M.shape[:-2]`` (or ``(len(omega),)``), scalings and
        worst-case perturbation.

    Raises
    ------
    ValueError
        Malformed blocks, dimensions that do not match ``M``, missing ``omega``, non-finite
        entries.

    Notes
    -----
    For one full complex block the upper bound is σ̄(M); for a single repeated complex
    scalar it is ρ(M) (reached in the limit for defective M); for a single repeated real
    scalar it is the largest |real eigenvalue| (Packard & Doyle 1993; Young 1993).

    Examples
    --------
    >>> import numpy as np
    >>> M = np.outer([1, 2j], [3, -1])       # rank one: μ = Σ|a_i||b_i| = 5
    >>> r = mussv(M, [(1, 0), (1, 0)])
    >>> round(float(r.upper), 3), round(float(r.lower), 3)
    (5.0, 5.0)
    """
    blks = parse_blocks(blocks)
    w = None
    if hasattr(M, "A") and hasattr(M, "B"):
        if omega is None:
            raise ValueError("mussv: a state-space M needs a frequency grid omega (rad/s)")
        if getattr(M, "dt", 0) not in (0, None):
            raise ValueError("mussv: only continuous-time systems (dt = 0) are supported")
        w = np.atleast_1d(np.asarray(omega, float))
        if w.ndim != 1 or w.size == 0 or not np.all(np.isfinite(w)):
            raise ValueError("mussv: omega must be a non-empty 1-D array of finite rad/s values")
        Marr = freqresp(M, w)
    else:
        Marr = np.asarray(M, complex)
        if omega is not None:
            raise ValueError("mussv: omega is only used with a state-space M")
    if Marr.ndim < 2:
        raise ValueError(f"mussv: M must be (..., n, m), got shape {Marr.shape}")
    n, m = _dims(blks)
    if Marr.shape[-2:] != (n, m):
        raise ValueError(
            f"mussv: blocks {list(blocks)} need M of shape (..., {n}, {m}) "
            f"(Σc = {n} rows, Σr = {m} columns), got {Marr.shape[-2:]}")
    if not np.all(np.isfinite(Marr)):
        raise ValueError("mussv: M has non-finite entries")
    stack = Marr.shape[:-2]
    Mf = Marr.reshape((-1, n, m))
    F = Mf.shape[0]
    Mp, rows, cols = _pad(Mf, blks)
    upper, D, Gp, offs = _upper(Mp, blks, tol, max_iter, gmax)
    rng = np.random.default_rng(seed)
    lower, delta = _lower(Mf, blks, lower_iter, rng)

    # scalings back in unpadded coordinates
    w_, V = np.linalg.eigh(D)
    Dh = (V * np.sqrt(np.maximum(w_, 0.0))[:, None, :]) @ _ct(V)
    Dl = Dh[:, rows][:, :, rows]
    Dr = Dh[:, cols][:, :, cols]
    G = Gp[:, cols][:, :, rows]
    ds = np.empty((F, len(blks)))
    for j, b in enumerate(blks):
        blkD = D[:, offs[j]:offs[j + 1], offs[j]:offs[j + 1]]
        ds[:, j] = np.sqrt(np.real(np.trace(blkD, axis1=1, axis2=2)) / b.size)
    ds = ds / ds[:, -1:]
    return MuResult(
        upper=upper.reshape(stack), lower=lower.reshape(stack),
        Dl=Dl.reshape(stack + (n, n)), Dr=Dr.reshape(stack + (m, m)), G=G.reshape(stack + (m, n)),
        dscale=ds.reshape(stack + (len(blks),)), delta=delta.reshape(stack + (m, n)),
        omega=w, blocks=tuple(tuple(int(v) for v in b) for b in blocks))
