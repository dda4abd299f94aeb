"""Poles and time response of a loop closed around a large plant given in modal form,
without a dense eigenvalue problem or ``expm`` of the whole loop.

The plant ``G(p) = Σ_i c_i b_iᵀ / (p − λ_i)`` (``λ`` its poles, ``b_iᵀ`` the rows of
``V⁻¹B``, ``c_i`` the columns of ``CV``; ``p = s``, or ``z`` of a sampled plant) is closed
with a small controller ``K`` as ``u = −K y``. A large lightly damped model has thousands
of modes of which the controller moves a few: the others lie far above its bandwidth and
couple to it through tiny residues. The modes are split on that measure — mode ``i`` is
*weak* when ``‖b_i‖ ‖K(λ_i)‖ ‖c_i‖``, the size of its first-order shift, is below ``WEAK``
times its distance to the stability boundary — and the loop's poles are found in two
parts, each from an exact (Schur complement) equation solved by fixed-point iteration:

* the **strong part**: the controller and the strong modes closed as a small dense loop
  ``M_R`` (eigenvalues ``μ``, eigenvectors ``X``), with the weak modes' static part
  ``G_T(a)`` as the plant's feedthrough (``a = 0``, or ``z = 1``: their residual
  flexibility, first order in the strong poles). The rest, ``G_T(p) − G_T(a)``, is
  evaluated at the pole itself: ``p ∈ spec S(p)``, ``S`` the state matrix of the small
  loop with feedthrough ``G_T(p)``. Each cluster of ``μ`` is iterated on its invariant
  subspace, ``p ∈ spec(X_c⁻¹ S(p) X_c)``; where the second-order term this projection
  neglects (bounded from the coupling and the separation) exceeds the tolerance, on
  ``S(p)`` itself;
* each **weak mode** (or cluster of nearly equal ones, such as the repeated poles of a
  system symmetric in two planes) sees the rest of the loop as a controller:
  ``p ∈ spec(Λ_c − B_c Q(p) C_c)``, ``Q = (I + K G_rest)⁻¹ K``.

The iterations stop when a step moves no pole by more than the rounding level of a dense
QR of the loop, ``4ε`` times the larger of its largest |pole| and the balanced strong
loop's norm. Two checks make the result a certificate:

* **nothing missed on the unstable side.** On a boundary — the line ``Re s = α`` or the
  circle ``|z| = ρ`` between the weak modes and the stability boundary — the small-gain
  bound ``‖G_T(p) − G_T(a)‖ ‖Q_R(p)‖ < 1/2`` (``Q_R = (I + K G_R)⁻¹ K`` of the strong
  part) is proved band by band with bounds by the triangle inequality on the poles'
  residues (``‖G_T(p) − G_T(a)‖ ≤ Σ ‖c_i‖ ‖b_i‖ |p − a| / (|λ_i − a| |p − λ_i|)``, the
  same for ``Q_R`` over ``μ``, and its Neumann expansion at high frequency), bands bisected
  where the bound is too coarse. Scaling the weak modes' coupling from 0 to 1 then moves
  no pole across the boundary (``det(I + t (G_T − G_T(a)) Q_R) ≠ 0`` on it), so the loop
  has as many poles beyond it as ``M_R`` — the homotopy argument of the small-gain
  theorem (Zhou, Doyle & Glover, *Robust and Optimal Control*, 1996, Thm 9.1);
* **nothing lost or counted twice.** The poles' sum equals the loop's trace (from the
  modal form, O(n)) to rounding, and the poles found beyond the boundary are as many as
  ``M_R``'s.

When any part fails (a modal form too ill-conditioned, too many strong modes, an
iteration that does not settle, a bound that does not prove) :func:`modal_loop_poles`
returns ``None`` and the caller takes the dense eigenvalues. Measured against the roots
of ``det(I + K G) = 0`` refined by Newton with dense solves of the plant, these poles are
within 1e-8 where the dense QR eigenvalues of the same loop are off by up to 2e-6
(relative; tests/lti/test_modal_loop.py).

The same split gives the loop's time response (:func:`modal_loop_response`): the weak
poles by their spectral projectors, the strong part as one small matrix on its invariant
subspace, certified by the split's transfer function against the loop's.
"""

from __future__ import annotations

import warnings
from typing import NamedTuple

import numpy as np
import scipy.linalg
from scipy.spatial import cKDTree

from ambseal.lti.memo import ArrayMemo

__all__ = ["WEAK", "modal_loop_poles", "modal_loop_response"]

#: A mode is weak when its first-order shift is at most this fraction of its distance to
#: the stability boundary: the neglected second-order terms of the projection are then
#: far below rounding, and the small-gain bound is met with a wide margin.
WEAK = 1e-6
_EPS = float(np.finfo(float).eps)
#: The strong part is solved densely and refined cluster by cluster, a factorisation of
#: its order S per cluster and iteration (measured: ≈ 8.3e-9·S^3.2 s against the dense
#: eigenvalues' ≈ 3.9e-10·N³ s of the whole loop, one thread): above this fraction of the
#: loop's order N the structured path is not taken. The fraction is where the two meet,
#: 0.27 N at 600 states, 0.24 N at 900, 0.19 N at 1 900 (benchmarks/README.md, "The
#: 540-state back-to-back compressor"); it picked the cheaper path on each of 215 loops
#: on three plants of 540, 840 and 1 888 states. At 0.5 the 540-state plant's loops,
#: strong parts of 190–290, took the structured path at 2–3 times the dense cost.
_MAX_STRONG_FRACTION = 0.25
#: The fixed-point iterations of the strong and weak poles (:meth:`_StrongPart.refine`,
#: :func:`_weak_poles`) contract by about the weak modes' relative shift (at most
#: ``WEAK``), so each settles to its rounding-level tolerance in a few steps (measured:
#: within three on each of the 18 loops of tests/lti/test_modal_loop.py, strong part and
#: weak modes alike). One that has not settled after this many circles at rounding
#: level: the loop's poles then come from the dense eigenvalues (``None``). A choice
#: between two paths that both meet the tolerance, not an answer cut short.
_MAX_ITER = 30
#: The split of the last loops (:class:`_Solved`, no n × n array: 0.6 MB at 1 888
#: states): a loop's poles and its time response share one, also when the design's check
#: of a loop comes many loops before its judgement (as many as the loops' poles kept).
_SOLVED = ArrayMemo(keep=64)
#: Initial bands of the certificate's curve (per side of the line; the circle has twice
#: as many), each bisected up to ``_BISECTIONS`` times where its bound is too coarse: the
#: finest band is 1/2¹⁷ of a first one. Few first bands, since on the loops of fine FE
#: meshes every first band is proved at once.
_BANDS = 256
_BISECTIONS = 17
#: The certificate gives up (and the caller takes the dense eigenvalues) once its bands have
#: cost what a dense eigenvalue problem of the loop costs: about 10 N³ flops for N states
#: (Golub & Van Loan, *Matrix Computations*, 4th ed., §7.5.6: Hessenberg QR, eigenvalues
#: only), against about this many flops per band and point of the bound. A count of work,
#: not a clock: the same loops take the same path on every machine. Without it a bound
#: that no bisection proves (a weak mode close to a strong pole) doubled its bands 17
#: times, minutes to hours, where the dense eigenvalues of 550 states take 0.2 s.
_FLOPS_PER_BAND_POINT = 40
_DENSE_FLOPS_PER_N3 = 10


def modal_loop_poles(lam, Bm, Cm, K, *, discrete: bool = False) -> np.ndarray | None:
    """All poles of the plant in modal form closed with ``K`` as ``u = −K y``, certified
    (module docstring), or ``None`` where the structured path cannot certify them.

    Parameters
    ----------
    lam : numpy.ndarray of complex, shape (n,)
        The plant's poles (rad/s, or z of a sampled plant).
    Bm : numpy.ndarray of complex, shape (n, m)
        ``V⁻¹ B``, the modes' input rows.
    Cm : numpy.ndarray of complex, shape (p, n)
        ``C V``, the modes' output columns (the plant has no feedthrough).
    K : (A_K, B_K, C_K, D_K)
        Controller, ``n_K`` states, ``p`` inputs → ``m`` outputs, continuous or on the
        plant's sample time.
    discrete : bool
        ``lam`` and ``K`` are discrete (stability boundary ``|z| = 1``).

    Returns
    -------
    numpy.ndarray of complex, shape (n + n_K,), or None
        The closed-loop poles, in no particular order; ``None`` when not certified.
    """
    solved = _solve(lam, Bm, Cm, K, discrete)
    return None if solved is None else solved.poles


class _Solved(NamedTuple):
    """What :func:`modal_loop_poles` certified: the poles, and how they were found."""

    poles: np.ndarray
    part: "_StrongPart"
    p_strong: np.ndarray  # the strong part's poles, in the order of part.mu
    strong: np.ndarray  # plant modes of the strong part
    groups: list  # plant modes of each weak cluster
    p_groups: list  # their poles


def _solve(lam, Bm, Cm, K, discrete) -> _Solved | None:
    """The split and the certified poles of :func:`modal_loop_poles` (kept: :data:`_SOLVED`)."""
    arrays = tuple(np.asarray(X, complex) for X in (lam, Bm, Cm)) + \
        tuple(np.atleast_2d(np.asarray(X, float)) for X in K)
    return _SOLVED.get(arrays, bool(discrete), lambda: _split(lam, Bm, Cm, K, discrete))


def _split(lam, Bm, Cm, K, discrete) -> _Solved | None:
    lam = np.asarray(lam, complex)
    Bm, Cm = np.asarray(Bm, complex), np.asarray(Cm, complex)
    Ak, Bk, Ck, Dk = (np.atleast_2d(np.asarray(X, float)) for X in K)
    Ak = Ak.reshape(Bk.shape[0], Bk.shape[0]) if Bk.size else np.zeros((0, 0))
    n, nk = lam.size, Ak.shape[0]
    if not n or not (np.all(np.isfinite(Bm)) and np.all(np.isfinite(Cm))):
        return None
    b = np.linalg.norm(Bm, axis=1)
    c = np.linalg.norm(Cm, axis=0)
    gap = 1.0 - np.abs(lam) if discrete else -lam.real  # to the stability boundary, > 0 inside
    with np.errstate(divide="ignore", invalid="ignore"):
        shift = b * c * np.linalg.norm(_K_at(K, lam), ord=2, axis=(1, 2))
        weak = (gap > 0) & (shift <= WEAK * gap)
    strong = np.flatnonzero(~weak)
    weak = np.flatnonzero(weak)
    if strong.size + nk > _MAX_STRONG_FRACTION * (n + nk) or not weak.size:
        return None
    # the weak modes' static part G_T(0) (z = 1) is the strong loop's feedthrough (their
    # residual flexibility: first order in the strong poles); what the iterations and the
    # certificate treat is G_T − G_T(0)
    WT = (Cm[:, weak].T[:, :, None] * Bm[weak][:, None, :]).reshape(weak.size, -1)
    D0 = _sums_at(np.ones(1, complex) if discrete else np.zeros(1, complex), lam[weak],
                  WT).reshape(Cm.shape[0], Bm.shape[1])
    part = _StrongPart(lam[strong], Bm[strong], Cm[:, strong], (Ak, Bk, Ck, Dk), D0)
    if part.X is None:
        return None
    # the rounding level of a dense QR of the loop: ε times its balanced norm
    scale = max(1.0, float(np.abs(lam).max()), part.norm)
    tol = 4 * _EPS * scale
    lamT, BT, CT = lam[weak], Bm[weak], Cm[:, weak]
    boundary = _Boundary.between(part.mu, lamT, discrete)
    if boundary is None or not _certified(boundary, part, lamT, b[weak] * c[weak]):
        return None
    p_strong = part.refine(lamT, BT, CT, tol)
    found = _weak_poles(lam, Bm, Cm, weak, (Ak, Bk, Ck, Dk), tol)
    if p_strong is None or found is None:
        return None
    p_weak, groups, p_groups = found
    poles = np.concatenate([p_strong, p_weak])
    if not np.all(np.isfinite(poles)):
        return None
    trace = lam.sum() - np.einsum("im,mp,pi->", Bm, Dk, Cm) + np.trace(Ak)
    if abs(poles.sum() - trace) > 1e3 * _EPS * float(np.abs(poles).sum()):
        return None
    beyond = boundary.beyond
    if np.count_nonzero(beyond(p_strong)) != np.count_nonzero(beyond(part.mu)) \
            or np.any(beyond(p_weak)):
        return None
    return _Solved(poles, part, p_strong, strong, groups, p_groups)


#: Largest first-order bound on the relative error of ``K(p)`` from the controller's modal
#: form (:func:`_K_at`) where it is used instead of a solve: a weak mode's pole moves by its
#: shift (at most ``WEAK`` times its distance to the stability boundary) times that error,
#: far below the iterations' tolerance.
_K_MODAL_RTOL = 1e-10


def _K_at(K, p):
    """``K(p)`` at each point, shape (n_p, m, p_out). From the balanced controller's modal
    form ``C_K V diag(1/(p − μ)) V⁻¹ B_K + D_K`` (O(n_K) a point) where its first-order error
    bound ``ε ‖A_K‖ cond(V) / min|p − μ|`` is at most :data:`_K_MODAL_RTOL`; elsewhere by
    solves of ``(pI − A_K) X = B_K``, stacked (O(n_K³) a point)."""
    Ak, Bk, Ck, Dk = K
    p = np.atleast_1d(p)
    out = np.empty((p.size,) + Dk.shape, complex)
    if not Ak.size:
        out[:] = Dk
        return out
    solve = np.ones(p.size, bool)
    Ab, (sc, _) = scipy.linalg.matrix_balance(Ak, permute=False, separate=True)
    mu, V = np.linalg.eig(Ab)
    cond = np.linalg.cond(V)
    if np.isfinite(cond):
        with np.errstate(divide="ignore"):
            dist = np.min(np.abs(p[:, None] - mu[None, :]), axis=1)
            solve = _EPS * np.linalg.norm(Ab, 2) * cond / dist > _K_MODAL_RTOL
        fast = np.flatnonzero(~solve)
        if fast.size:
            Cv, Vb = (Ck * sc) @ V, np.linalg.solve(V, Bk / sc[:, None])
            W = (Cv.T[:, :, None] * Vb[:, None, :]).reshape(mu.size, -1)
            out[fast] = (1.0 / (p[fast, None] - mu[None, :]) @ W).reshape(
                -1, Dk.shape[0], Dk.shape[1]) + Dk
    eye = np.eye(Ak.shape[0])
    slow = np.flatnonzero(solve)
    for k in range(0, slow.size, 512):
        s = p[slow[k:k + 512]]
        X = np.linalg.solve(s[:, None, None] * eye - Ak, np.broadcast_to(Bk, (s.size,) + Bk.shape))
        out[slow[k:k + 512]] = Ck @ X + Dk
    return out


#: Bytes of the reciprocals ``1/(p − λ)`` formed at once by :func:`_sums_at`: at a thousand
#: points, the 1 888 poles of a 230-element plant give 30 MB, whose first touch costs more
#: than the arithmetic; a few rows at a time stay in cache.
_CHUNK_BYTES = 2**21


def _sums_at(points, lam, W, drop=(np.zeros(0, int), np.zeros(0, int)), square=False):
    """``Σ_j W_j / (p_k − λ_j)`` at each point ``p_k``, shape (n_p, W.shape[1]) — with
    ``square`` also ``Σ_j W_j / (p_k − λ_j)²`` — without the terms ``(k, j)`` of the pairs
    ``drop = (k's, j's)`` (a mode's own term at its own pole)."""
    rows, cols = drop
    out = np.empty((points.size, W.shape[1]), complex)
    out2 = np.empty_like(out) if square else None
    step = max(1, _CHUNK_BYTES // (16 * max(lam.size, 1)))
    for k0 in range(0, points.size, step):
        k1 = min(k0 + step, points.size)
        with np.errstate(divide="ignore", invalid="ignore"):
            r = 1.0 / (points[k0:k1, None] - lam[None, :])
        here = (rows >= k0) & (rows < k1)
        r[rows[here] - k0, cols[here]] = 0.0
        out[k0:k1] = r @ W
        if square:
            np.multiply(r, r, out=r)
            out2[k0:k1] = r @ W
    return (out, out2) if square else out


class _StrongPart:
    """The controller and the strong modes closed as one small dense loop ``M_R``; its
    eigendecomposition, and the state matrix ``S(p)`` with the weak modes as feedthrough.

    With plant feedthrough ``D_T`` the small loop's state matrix is
    ``[[Λ_R, −B_R C_K], [0, A_K]] + U F(D_T) [C_R, −D_T C_K]``, ``U = [−B_R D_K; B_K]``,
    ``F(D_T) = (I + D_T D_K)⁻¹``: a change of ``D_T`` changes it by ``U`` times a
    ``p_out``-row matrix (:meth:`coupling`), so ``S(p) − M_R`` on the eigenvectors costs
    O(n²), not a product of three n × n matrices."""

    def __init__(self, lam, Bm, Cm, K, D0):
        self.lam, self.Bm, self.Cm, self.K = lam, Bm, Cm, K
        self.M = self.state_matrix(D0)
        # the small-gain loop: from a signal added to y to −u (module docstring), the
        # plant's feedthrough D0 included: y = F (C x − D0 C_K x_K + w)
        _, Bk, Ck, Dk = K
        F = np.linalg.inv(np.eye(D0.shape[0]) + D0 @ Dk)
        self.Bq = np.vstack([-Bm @ Dk @ F, Bk @ F])
        self.Cq = np.hstack([Dk @ F @ Cm, Ck - Dk @ F @ D0 @ Ck])
        self.Dq = Dk @ F
        self.U = np.vstack([-Bm @ Dk, Bk])
        self.V0 = self.coupling(D0)
        # balanced first: modal and controller coordinates differ in scale by decades
        # (cond X 4e11 unbalanced, 1.4e2 balanced on a 230-element plant's strong part)
        Mb, (sc, _) = scipy.linalg.matrix_balance(self.M, permute=False, separate=True)
        self.sc = sc
        self.norm = float(np.linalg.norm(Mb, 1))
        self.mu, Xb = np.linalg.eig(Mb)
        self.X = self.Xi = None
        if np.linalg.cond(Xb) < 1e8:
            self.X, self.Xi = sc[:, None] * Xb, np.linalg.inv(Xb) / sc[None, :]
            self.XiU = self.Xi @ self.U

    def coupling(self, DT):
        """``F(D_T) [C_R, −D_T C_K]`` (p_out × n): what of the state matrix depends on the
        plant's feedthrough ``D_T`` (class docstring)."""
        _, _, Ck, Dk = self.K
        F = np.linalg.inv(np.eye(DT.shape[0]) + DT @ Dk)
        return F @ np.hstack([self.Cm, -DT @ Ck])

    def state_matrix(self, DT):
        """State matrix of the small loop with plant feedthrough ``DT`` (p_out × m)."""
        Ak, Bk, Ck, Dk = self.K
        lam, Bm, Cm = self.lam, self.Bm, self.Cm
        nr = lam.size
        F = np.linalg.inv(np.eye(DT.shape[0]) + DT @ Dk)  # y = F (C x − DT Ck xk)
        yx, yk = F @ Cm, -F @ DT @ Ck
        M = np.empty((nr + Ak.shape[0],) * 2, complex)
        M[:nr, :nr] = np.diag(lam) - Bm @ Dk @ yx
        M[:nr, nr:] = -Bm @ (Ck + Dk @ yk)
        M[nr:, :nr] = Bk @ yx
        M[nr:, nr:] = Ak + Bk @ yk
        return M

    def refine(self, lamT, BT, CT, tol):
        """The strong poles with the weak modes' feedthrough at each pole: each cluster of
        ``μ`` on its invariant subspace, ``p ∈ spec(X_c⁻¹ S(p) X_c)``, or, where the
        second-order term that projection neglects exceeds ``tol``, ``p ∈ spec S(p)``
        itself (the nearest eigenvalues); ``None`` if an iteration does not settle."""
        out = np.empty_like(self.mu)
        WT = (CT.T[:, :, None] * BT[:, None, :]).reshape(lamT.size, -1)
        shape = (CT.shape[0], BT.shape[1])

        def feedthrough(p):  # the weak modes' G_T(p)
            return _sums_at(np.atleast_1d(p), lamT, WT).reshape(shape)

        for idx in _clusters(self.mu, tol):
            p = self._projected(idx, feedthrough, tol)
            if p is None:
                p = self._exact(idx, feedthrough, tol)
            if p is None:
                return None
            out[idx] = p
        return out

    def _projected(self, idx, feedthrough, tol):
        mu, X, XiU = self.mu, self.X, self.XiU
        p = mu[idx].copy()
        for _ in range(_MAX_ITER):
            dV = self.coupling(feedthrough(p.mean())) - self.V0  # S(p) − M_R = U dV
            dVx = dV @ X[:, idx]
            new = _matched(np.linalg.eigvals(np.diag(mu[idx]) + XiU[idx] @ dVx), p)
            done = np.max(np.abs(new - p)) <= tol
            p = new
            if done:
                break
        else:
            return None
        rest = np.ones(mu.size, bool)
        rest[idx] = False
        if rest.any():
            # E = X⁻¹ (S(p) − M_R) X off the cluster's diagonal block
            sep = float(np.min(np.abs(mu[rest][:, None] - p[None, :])))
            second = (np.linalg.norm(XiU[idx] @ (dV @ X[:, rest]), 2)
                      * np.linalg.norm(XiU[rest] @ dVx, 2) / max(sep, tol))
            if second > tol:
                return None
        return p

    def _exact(self, idx, feedthrough, tol):
        p = self.mu[idx].copy()
        sc = self.sc  # balanced as M_R: S(p) differs by the weak modes' feedthrough
        for _ in range(_MAX_ITER):
            S = self.state_matrix(feedthrough(p.mean())) * (1.0 / sc)[:, None] * sc[None, :]
            new = _matched(_nearest_eigenvalues(S, p.mean(), idx.size), p)
            done = np.max(np.abs(new - p)) <= tol
            p = new
            if done:
                return p
        return None


def _matched(new, old):
    """``new`` reordered to follow ``old`` (nearest first, greedily; clusters are small)."""
    new, out = list(new), np.empty_like(old)
    for j in np.argsort(-np.abs(old)):
        k = min(range(len(new)), key=lambda i: abs(new[i] - old[j]))
        out[j] = new.pop(k)
    return out


def _clusters(p, tol):
    """Index groups of poles closer than ``sqrt(tol · scale)`` to a neighbour (chains):
    nearly equal poles are iterated together."""
    order = np.lexsort((p.imag, p.real))
    radius = np.sqrt(tol * max(1.0, float(np.abs(p).max(initial=1.0))))
    groups, cur = [], [order[0]] if order.size else []
    for i in order[1:]:
        if min(abs(p[i] - p[j]) for j in cur[-4:]) <= radius:
            cur.append(i)
        else:
            groups.append(np.array(cur))
            cur = [i]
    if cur:
        groups.append(np.array(cur))
    return groups


def _weak_poles(lam, Bm, Cm, weak, K, tol):
    """Each weak mode's (or cluster's) pole from ``p ∈ spec(Λ_c − B_c Q(p) C_c)``,
    ``Q = (I + K G_rest)⁻¹ K`` with the rest of the plant: (the poles in the order of
    ``weak``, the clusters' plant modes, their poles); ``None`` if it does not settle."""
    groups = [weak[g] for g in _clusters(lam[weak], tol)]
    single = np.array([g.size == 1 for g in groups])
    first = np.array([g[0] for g in groups])  # a single mode's index
    cur = lam.copy()  # each weak mode's pole as found so far
    W = (Cm.T[:, :, None] * Bm[:, None, :]).reshape(lam.size, -1)
    pending = np.arange(len(groups))
    for _ in range(_MAX_ITER):
        if not pending.size:
            break
        ones = single[pending]
        k1, kn = np.flatnonzero(ones), np.flatnonzero(~ones)
        i1 = first[pending[k1]]
        centres = np.empty(pending.size, complex)
        centres[k1] = cur[i1]
        centres[kn] = [cur[groups[g]].mean() for g in pending[kn]]
        # the rest of the plant: without the cluster
        drop = [(k1, i1)] + [(np.full(groups[g].size, k), groups[g])
                             for k, g in zip(kn, pending[kn])]
        drop = tuple(np.concatenate(x) for x in zip(*drop))
        G = _sums_at(centres, lam, W, drop).reshape(-1, Cm.shape[0], Bm.shape[1])
        Kp = _K_at(K, centres)
        # Q = (I + K G_rest)⁻¹ K at each centre: one LAPACK call for the stack
        Q = np.linalg.solve(np.eye(Kp.shape[1]) + Kp @ G, Kp)
        moved = np.empty(pending.size)
        new = lam[i1] - np.einsum("km,kmp,pk->k", Bm[i1], Q[k1], Cm[:, i1])
        moved[k1] = np.abs(new - cur[i1])
        cur[i1] = new
        for k in kn:
            idx = groups[pending[k]]
            P = np.diag(lam[idx]) - Bm[idx] @ Q[k] @ Cm[:, idx]
            new = _matched(np.linalg.eigvals(P), cur[idx])
            moved[k] = np.max(np.abs(new - cur[idx]))
            cur[idx] = new
        pending = pending[~(moved <= tol)]  # nan: not settled
    if pending.size:
        return None
    return cur[weak], groups, [cur[idx] for idx in groups]


class _Boundary:
    """The curve of the certificate, between the weak modes and the stability boundary:
    the line ``Re s = α`` (continuous) or the circle ``|z| = ρ`` (discrete), parametrised
    by ``Im s`` or ``arg z``; ``anchor`` is the point where the weak modes' part is taken
    as static (``s = 0``, ``z = 1``)."""

    def __init__(self, value: float, discrete: bool):
        self.value, self.discrete = value, discrete
        self.anchor = 1.0 if discrete else 0.0

    @classmethod
    def between(cls, mu, lamT, discrete):
        """The curve as far from the strong poles as five candidates between the weak
        modes and the stability boundary go; ``None`` if a weak mode is not strictly stable."""
        worst = float(np.abs(lamT).max() if discrete else lamT.real.max())
        edge = 1.0 if discrete else 0.0
        if worst >= edge:
            return None
        cands = worst + (edge - worst) * np.array([0.5, 0.75, 0.25, 0.875, 0.125])
        at = np.abs(mu) if discrete else mu.real
        dist = [np.min(np.abs(at - v), initial=np.inf) for v in cands]
        return cls(float(cands[int(np.argmax(dist))]), discrete)

    def beyond(self, p):
        """Whether each point lies on the unstable side of the curve (or on it)."""
        return np.abs(p) >= self.value if self.discrete else p.real >= self.value

    def bands(self, points):
        """The initial bands (lo, hi) of the parameter, and the curve's ends outside them
        (rays of the line; none for the circle)."""
        if self.discrete:
            edges = np.linspace(-np.pi, np.pi, 2 * _BANDS + 1)
            return edges[:-1], edges[1:], None
        top = 10.0 * float(np.abs(points).max(initial=1.0))
        low = max(1e-3, 1e-3 * float(np.abs(points).min(initial=1.0)))
        pos = np.concatenate([[0.0], np.geomspace(low, top, _BANDS)])
        edges = np.concatenate([-pos[:0:-1], pos])
        return edges[:-1], edges[1:], (np.array([edges[-1], -np.inf]), np.array([np.inf, edges[0]]))

    def dist(self, points, lo, hi):
        """Distance from each point to each band, shape (n_bands, n_points)."""
        if self.discrete:
            th = np.angle(points)[None, :]
            on = (th >= lo[:, None]) & (th <= hi[:, None])
            ends = np.minimum(np.abs(points[None, :] - self.value * np.exp(1j * lo[:, None])),
                              np.abs(points[None, :] - self.value * np.exp(1j * hi[:, None])))
            return np.where(on, np.abs(np.abs(points) - self.value)[None, :], ends)
        y = points.imag[None, :]
        dy = np.where(y < lo[:, None], lo[:, None] - y,
                      np.where(y > hi[:, None], y - hi[:, None], 0.0))
        return np.hypot(points.real[None, :] - self.value, dy)

    def farthest(self, lo, hi):
        """The largest distance from ``anchor`` to a point of each band (``inf`` on a ray)."""
        if self.discrete:  # |ρ e^{jθ} − 1| grows with |θ| on [0, π]
            return np.abs(self.value * np.exp(1j * np.maximum(np.abs(lo), np.abs(hi))) - 1.0)
        return np.hypot(self.value, np.maximum(np.abs(lo), np.abs(hi)))


def _certified(boundary, part, lamT, aT) -> bool:
    """Whether ``‖G_T − G_T(anchor)‖ ‖Q_R‖ < 1/2`` is proved on every band of the
    boundary, bands bisected where the bound is too coarse (module docstring)."""
    mu, X, Xi = part.mu, part.X, part.Xi
    XiBq = Xi @ part.Bq
    terms = [np.linalg.norm(part.Cq @ X, axis=0) * np.linalg.norm(XiBq, axis=1)]
    dq = float(np.linalg.norm(part.Dq, 2)) if part.Dq.size else 0.0
    heads = []
    if not boundary.discrete:
        # Neumann expansion at large |s|: Q = D + Σ_(k<N) C Aᵏ B / s^(k+1) + C Aᴺ (s−A)⁻¹ B / sᴺ
        CA = part.Cq
        for _ in range(3):
            heads.append(float(np.linalg.norm(CA @ part.Bq, 2)))
            CA = CA @ part.M
            terms.append(np.linalg.norm(CA @ X, axis=0) * np.linalg.norm(XiBq, axis=1))
    args = (boundary, mu, terms, heads, dq, lamT, aT)
    lo, hi, ends = boundary.bands(np.concatenate([lamT, mu]))
    if ends is not None and not _bands_ok(*ends, *args).all():
        return False
    # the dense eigenvalue problem of the loop that the caller falls back to, in band points
    points = lamT.size + mu.size * len(terms)
    budget = _DENSE_FLOPS_PER_N3 * float(lamT.size + mu.size) ** 3 / _FLOPS_PER_BAND_POINT
    spent = 0.0
    for _ in range(_BISECTIONS + 1):
        spent += lo.size * points
        if spent > budget:
            return False
        bad = ~_bands_ok(lo, hi, *args)
        if not bad.any():
            return True
        mid = 0.5 * (lo[bad] + hi[bad])
        lo, hi = np.concatenate([lo[bad], mid]), np.concatenate([mid, hi[bad]])
    return False


def _bands_ok(lo, hi, boundary, mu, terms, heads, dq, lamT, aT):
    ok = np.empty(lo.size, bool)
    step = max(1, 2**22 // max(1, lamT.size))
    off = np.abs(lamT - boundary.anchor)[None, :]
    for k in range(0, lo.size, step):
        sl = slice(k, k + step)
        with np.errstate(divide="ignore"):
            # ‖G_T(p) − G_T(a)‖ ≤ Σ a_i |p − a| / (|λ_i − a| |p − λ_i|)
            #                  ≤ Σ a_i (1/|p − λ_i| + 1/|λ_i − a|)
            dT = boundary.dist(lamT, lo[sl], hi[sl])
            far = boundary.farthest(lo[sl], hi[sl])[:, None]
            g = (aT[None, :] * np.minimum(far / (off * dT), 1.0 / dT + 1.0 / off)).sum(axis=1)
            dR = boundary.dist(mu, lo[sl], hi[sl])
            q = (terms[0][None, :] / dR).sum(axis=1)
            if heads:  # the smallest |s| on the band: its distance to the origin
                smin = boundary.dist(np.zeros(1, complex), lo[sl], hi[sl])[:, 0]
                for N in range(1, len(heads) + 1):
                    head = sum(h / smin ** (j + 1) for j, h in enumerate(heads[:N]))
                    q = np.minimum(q, head + (terms[N][None, :] / dR).sum(axis=1) / smin ** N)
        ok[sl] = np.nan_to_num(g * (q + dq), nan=np.inf) < 0.5
    return ok


def modal_loop_response(lam, Bm, Cm, K, E, Z, d: np.ndarray, h: float) -> np.ndarray | None:
    """The sampled response, from rest, of a continuous loop closed around a plant in modal
    form, without ``expm`` of the loop, or ``None`` where it is not certified.

    The loop: plant ``ẋ = diag(λ) x + B_m u``, ``y = C_m x``; controller ``ẋ_K = A_K x_K +
    B_K y + E_x d``, ``u = −(C_K x_K + D_K y) + E_u d``; outputs ``[y, F x_K + G y]``; the
    disturbances ``d`` held over each step of ``h`` (a zero-order hold, as
    :func:`ambseal.lti.discrete.zoh` of the loop). The loop is split along its invariant
    subspaces as :func:`modal_loop_poles` splits its poles:

    * each **weak** pole (or cluster of nearly equal ones — the repeated modes of a system
      symmetric in two planes) by its spectral projector ``V (WᵀV)⁻¹ Wᵀ``: exact right and
      left eigenvectors of the loop from its Schur complement ``Λ_c − B_c Q(p) C_c``, the
      eliminated components included in ``WᵀV``; these poles are far from one another
      relative to their coupling, so the projectors are well conditioned;
    * the **strong** part as one small matrix on its invariant subspace,
      ``M_S = A_SS + E_S Y`` (``A_SS`` the strong modes and the controller closed without
      the weak modes, ``Y`` the weak modes' share of that subspace seen at ``y``, from the
      strong poles' eigenvectors of the small loop ``S(p)``), stepped exactly by the
      ``expm`` of that small matrix — not diagonalised: nearly defective pairs there (two
      planes split by a small cross-coupling) lose digits in per-pole residues; its input
      is the disturbance minus the weak projectors' part.

    Certificate: the split's transfer function equals the loop's own (from ``G(s)`` and
    ``K(s)``) at probe points on the imaginary axis (the strong poles' frequencies and a
    grid over the plant's band) within 1e-9 of the largest value there, and ``M_S``'s
    eigenvalues and the weak poles are :func:`modal_loop_poles`'s.

    Parameters
    ----------
    lam, Bm, Cm : numpy.ndarray of complex
        The plant's modal form, shapes (n,), (n, m), (p, n) (a real plant: conjugate
        pairs), no feedthrough.
    K : (A_K, B_K, C_K, D_K)
        Continuous controller, ``n_K`` states, ``p`` inputs → ``m`` outputs.
    E : (E_x, E_u)
        Where the disturbances enter: shapes (n_K, m_d) and (m, m_d).
    Z : (F, G)
        The outputs after ``y``: shapes (q, n_K) and (q, p).
    d : numpy.ndarray, shape (N, m_d)
        The disturbance samples.
    h : float
        The step (s).

    Returns
    -------
    numpy.ndarray, shape (N, p + q), or None
        ``[y, F x_K + G y]`` at ``t = k h``, ``k = 0 … N − 1`` (before ``d_k`` acts).
    """
    solved = _solve(lam, Bm, Cm, K, False)
    if solved is None:
        return None
    lam, Bm, Cm = (np.asarray(X, complex) for X in (lam, Bm, Cm))
    Ak, Bk, Ck, Dk = (np.atleast_2d(np.asarray(X, float)) for X in K)
    Ak = Ak.reshape(Bk.shape[0], Bk.shape[0]) if Bk.size else np.zeros((0, 0))
    loop = _Loop(lam, Bm, Cm, (Ak, Bk, Ck, Dk), *(np.atleast_2d(np.asarray(X, float))
                                                   for X in (*E, *Z)))
    ones = [k for k, idx in enumerate(solved.groups) if idx.size == 1]
    weak = [loop.weak_group(idx, p, solved.strong)
            for idx, p in zip(solved.groups, solved.p_groups) if idx.size > 1]
    if ones:
        weak.append(loop.weak_singles(np.array([solved.groups[k][0] for k in ones]),
                                      np.array([solved.p_groups[k][0] for k in ones]),
                                      solved.strong))
    strong = loop.strong_block(solved)
    if strong is None or any(x is None for x in weak):
        return None
    mu, out, inp, V1 = (np.concatenate([x[k] for x in weak]) for k in range(4))
    M, C1 = strong
    B1 = loop.input_block(solved.strong) - V1.T @ inp
    scale = max(1.0, float(np.abs(solved.poles).max()))
    found = np.concatenate([np.linalg.eigvals(M), mu])
    near, _ = cKDTree(np.c_[solved.poles.real, solved.poles.imag]).query(
        np.c_[found.real, found.imag])
    if found.size != solved.poles.size or np.max(near) > 1e-9 * scale:
        return None
    if not loop.certified((M, C1, B1), (mu, out, inp), solved):
        return None
    return _held(M, C1, B1, d, h) + _stepped(mu, out, inp, d, h)


class _Loop:
    """The loop of :func:`modal_loop_response` and the parts of its split."""

    def __init__(self, lam, Bm, Cm, K, Ex, Eu, F, G):
        self.lam, self.Bm, self.Cm, self.K = lam, Bm, Cm, K
        self.Ex, self.Eu, self.F, self.G = Ex, Eu, F, G
        self.W = (Cm.T[:, :, None] * Bm[:, None, :]).reshape(lam.size, -1)

    def _sums(self, p, skip):
        """``Σ c bᵀ/(p − λ)`` and ``Σ c bᵀ/(p − λ)²`` over the modes not in ``skip``."""
        skip = np.asarray(skip, int)
        G, G2 = _sums_at(np.array([p], complex), self.lam, self.W,
                         (np.zeros(skip.size, int), skip), square=True)
        shape = (self.Cm.shape[0], self.Bm.shape[1])
        return G.reshape(shape), G2.reshape(shape)

    def _controller(self, p):
        """``(pI − A_K)⁻¹ B_K``, ``(pI − A_K)⁻¹ E_x`` and ``K(p)``."""
        Ak, Bk, Ck, Dk = self.K
        if not Ak.size:
            return (np.zeros((0, Bk.shape[1])), np.zeros((0, self.Ex.shape[1])),
                    Dk.astype(complex))
        R = np.linalg.solve(p * np.eye(Ak.shape[0]) - Ak, np.hstack([Bk, self.Ex]))
        RB, RE = R[:, :Bk.shape[1]], R[:, Bk.shape[1]:]
        return RB, RE, Ck @ RB + Dk

    def weak_group(self, idx, p_group, strong):
        """A weak cluster (plant modes ``idx``): its poles, ``C V`` and ``(WᵀV)⁻¹ WᵀB``
        (rows, one per pole), and its right eigenvectors' components on the strong part
        (the strong modes, then the controller; rows)."""
        p = complex(np.mean(p_group))
        Gr, G2 = self._sums(p, idx)
        RB, RE, Kp = self._controller(p)
        Ak, Bk, Ck, Dk = self.K
        Be, Ce = self.Bm[idx], self.Cm[:, idx]
        M = np.linalg.inv(np.eye(Gr.shape[0]) + Gr @ Kp)  # y = M C_E ξ
        P = np.diag(self.lam[idx]) - Be @ Kp @ M @ Ce
        if idx.size == 1:
            mu, vr, eta = P[0], np.ones((1, 1)), np.ones((1, 1))
        else:
            mu, vl, vr = scipy.linalg.eig(P, left=True, right=True)
            eta = vl.conj()  # ηᵀ P = μ ηᵀ
        y = M @ Ce @ vr
        u = -Kp @ y
        xk = RB @ y
        nu_l = np.linalg.solve((np.eye(Kp.shape[0]) + Kp @ Gr).T, Be.T @ eta)
        zeta = -Kp.T @ nu_l
        wk = -np.linalg.solve((p * np.eye(Ak.shape[0]) - Ak).T, Ck.T @ nu_l) if Ak.size \
            else np.zeros((0, mu.size))
        WV = eta.T @ vr + zeta.T @ G2 @ u + wk.T @ xk
        if np.linalg.cond(WV) > 1e8:
            return None
        WB = nu_l.T @ self.Eu + wk.T @ self.Ex
        out = np.vstack([y, self.F @ xk + self.G @ y]).T
        xs = (self.Bm[strong] @ u) / (p - self.lam[strong])[:, None]
        return mu, out, np.linalg.solve(WV, WB), np.vstack([xs, xk]).T

    def weak_singles(self, modes, poles, strong, chunk: int = 256):
        """:meth:`weak_group` of every weak pole that is a cluster of one plant mode
        (``modes``, their poles ``poles``) at once: the same algebra with the Schur
        complement 1 × 1 (its eigenvector 1), stacked over the poles in chunks (the
        controller's resolvents are ``chunk`` n_K × n_K matrices); ``None`` where a pole's
        left and right eigenvectors are orthogonal (not a simple pole)."""
        parts = [self._singles(modes[k:k + chunk], poles[k:k + chunk], strong)
                 for k in range(0, modes.size, chunk)]
        if any(x is None for x in parts):
            return None
        return tuple(np.concatenate([x[k] for x in parts]) for k in range(4))

    def _singles(self, modes, poles, strong):
        Ak, Bk, Ck, Dk = self.K
        nk, ny, nu = Ak.shape[0], self.Cm.shape[0], self.Bm.shape[1]
        T = lambda Z: np.swapaxes(Z, 1, 2)  # noqa: E731  (transpose of each matrix)
        Gr, G2 = (G.reshape(-1, ny, nu) for G in _sums_at(
            poles, self.lam, self.W, (np.arange(modes.size), modes), square=True))
        if nk:
            resolvent = poles[:, None, None] * np.eye(nk) - Ak
            RB = np.linalg.solve(resolvent, np.broadcast_to(Bk, (poles.size, nk, ny)))
            Kp = Ck @ RB + Dk
        else:
            RB = np.zeros((poles.size, 0, ny))
            Kp = np.broadcast_to(Dk.astype(complex), (poles.size, nu, ny))
        ce = self.Cm.T[modes][:, :, None]  # (k, ny, 1)
        be = self.Bm[modes][:, None, :]  # (k, 1, nu)
        y = np.linalg.solve(np.eye(ny) + Gr @ Kp, ce)  # y = (I + G_rest K)⁻¹ C_E ξ
        mu = self.lam[modes] - (be @ Kp @ y)[:, 0, 0]
        u = -Kp @ y
        xk = RB @ y
        nu_l = np.linalg.solve(T(np.eye(nu) + Kp @ Gr), T(be))
        zeta = -T(Kp) @ nu_l
        wk = -np.linalg.solve(T(resolvent), Ck.T @ nu_l) if nk else np.zeros((poles.size, 0, 1))
        WV = (1.0 + T(zeta) @ G2 @ u + T(wk) @ xk)[:, 0, 0]
        if not np.all(np.abs(WV) > 0):
            return None
        WB = (T(nu_l) @ self.Eu + T(wk) @ self.Ex)[:, 0, :]
        out = np.concatenate([y, self.F @ xk + self.G @ y], axis=1)[:, :, 0]
        xs = (self.Bm[strong] @ u[:, :, 0].T) / (poles[None, :] - self.lam[strong][:, None])
        return mu, out, WB / WV[:, None], np.vstack([xs, xk[:, :, 0].T]).T

    def strong_block(self, solved):
        """``(M_S, C_S)``: the strong part's matrix on its invariant subspace (the strong
        modes, then the controller) and its outputs there; ``None`` if its eigenvectors
        do not span it well."""
        part, strong = solved.part, solved.strong
        ns = part.lam.size
        Q = np.empty((part.mu.size,) * 2, complex)
        Yq = np.empty((self.Cm.shape[0], part.mu.size), complex)
        k = 0
        Ak, Bk, Ck, Dk = self.K
        for g in _clusters(solved.p_strong, _cluster_tol(solved)):
            p = complex(np.mean(solved.p_strong[g]))
            GT, _ = self._sums(p, strong)  # the weak modes' transfer at p
            # balanced first, by the strong part's own balancing: S(p) is M_R but for the
            # weak modes' small feedthrough
            sc = part.sc
            Sb = part.state_matrix(GT) * (1.0 / sc)[:, None] * sc[None, :]
            q = sc[:, None] * _nearest_subspace(Sb, p, g.size)
            xk = q[ns:]
            Fy = np.linalg.inv(np.eye(GT.shape[0]) + GT @ Dk)
            y = Fy @ (part.Cm @ q[:ns] - GT @ Ck @ xk)
            Q[:, k:k + g.size], Yq[:, k:k + g.size] = q, y - part.Cm @ q[:ns]
            k += g.size
        # conditioned as scaled: the rows mix modal and controller coordinates
        Qs = Q / np.abs(Q).max(axis=1, keepdims=True)
        if k != Q.shape[0] or np.linalg.cond(Qs / np.linalg.norm(Qs, axis=0)) > 1e8:
            return None
        Y = np.linalg.solve(Q.T, Yq.T).T  # the weak modes at y, per strong coordinate
        Es = np.vstack([-part.Bm @ Dk, Bk])
        M = part.state_matrix(np.zeros_like(Y @ Es)) + Es @ Y
        Cy = np.hstack([part.Cm, np.zeros((part.Cm.shape[0], Ak.shape[0]))]) + Y
        Fx = np.hstack([np.zeros((self.F.shape[0], ns)), self.F])
        return M, np.vstack([Cy, self.G @ Cy + Fx])

    def input_block(self, strong):
        """The disturbances' input to the strong modes and the controller."""
        return np.vstack([self.Bm[strong] @ self.Eu, self.Ex])

    def transfer(self, s):
        """The loop's transfer ``d → [y, F x_K + G y]`` at ``s`` from ``G(s)``, ``K(s)``."""
        Gs, _ = self._sums(s, np.zeros(0, int))
        RB, RE, Ks = self._controller(s)
        Kd = self.Eu - self.K[2] @ RE
        y = np.linalg.solve(np.eye(Gs.shape[0]) + Gs @ Ks, Gs @ Kd)
        return np.vstack([y, self.F @ (RB @ y + RE) + self.G @ y])

    def certified(self, block, weak, solved) -> bool:
        """Whether the split's transfer is the loop's at the probes (module docstring)."""
        M, C1, B1 = block
        mu, out, inp = weak
        ps = solved.p_strong
        lo, hi = np.abs(self.lam).min(), np.abs(self.lam).max()
        probes = 1j * np.concatenate([np.sort(np.abs(ps.imag[ps.imag > 0]))[:8],
                                      np.geomspace(max(lo, 1e-3), hi, 8)])
        eye = np.eye(M.shape[0])
        T = np.array([self.transfer(s) for s in probes])
        R = np.array([C1 @ np.linalg.solve(s * eye - M, B1) + (out.T / (s - mu)) @ inp
                      for s in probes])
        return bool(np.max(np.abs(R - T)) <= 1e-9 * np.max(np.abs(T)))


#: Steps of :func:`_inverse_iteration` before ``eig`` is taken instead
_INVERSE_STEPS = 4


def _inverse_iteration(S: np.ndarray, p: complex, k: int) -> np.ndarray | None:
    """An orthonormal basis (columns) of the invariant subspace of ``S``'s ``k``
    eigenvalues nearest ``p`` (``S`` balanced: the residual test below is relative to its
    norm), or ``None``: block inverse iteration with the shift ``p`` from a seeded start,
    orthonormalised each step (Golub & Van Loan, *Matrix Computations*, 4th ed., §7.6.1),
    until the residual ``‖S X − X (Xᴴ S X)‖₁`` is ``eig``'s backward error,
    ``64 ε ‖S‖₁``. ``p`` lies on the cluster (its mean), so a step or two suffice: one LU
    of ``S − pI`` instead of the whole eigendecomposition."""
    n = S.shape[0]
    norm = np.linalg.norm(S, 1)
    rng = np.random.default_rng(0)
    X = rng.standard_normal((n, k)) + 1j * rng.standard_normal((n, k))
    with np.errstate(all="ignore"), warnings.catch_warnings():
        warnings.simplefilter("ignore", scipy.linalg.LinAlgWarning)
        lu = scipy.linalg.lu_factor(S - p * np.eye(n), check_finite=False)
        for _ in range(_INVERSE_STEPS):
            Y = scipy.linalg.lu_solve(lu, X, check_finite=False)
            if not np.all(np.isfinite(Y)):  # p an eigenvalue to the last bit
                return None
            X, _ = np.linalg.qr(Y)
            SX = S @ X
            if np.linalg.norm(SX - X @ (X.conj().T @ SX), 1) <= 64 * _EPS * norm:
                return X
    return None


def _nearest_subspace(S: np.ndarray, p: complex, k: int) -> np.ndarray:
    """A basis (columns) of the invariant subspace of ``S``'s ``k`` eigenvalues nearest
    ``p`` (``S`` balanced): :func:`_inverse_iteration`'s, else the eigenvectors of ``eig``."""
    X = _inverse_iteration(S, p, k)
    if X is not None:
        return X
    ev, vr = scipy.linalg.eig(S)
    return vr[:, np.argsort(np.abs(ev - p))[:k]]


def _nearest_eigenvalues(S: np.ndarray, p: complex, k: int) -> np.ndarray:
    """The ``k`` eigenvalues of ``S`` nearest ``p`` (``S`` balanced): those of ``Xᴴ S X``
    on :func:`_inverse_iteration`'s subspace (exact eigenvalues of a matrix within
    ``64 ε ‖S‖₁`` of ``S``), else ``eig``'s."""
    X = _inverse_iteration(S, p, k)
    if X is not None:
        return np.linalg.eigvals(X.conj().T @ S @ X)
    ev = np.linalg.eigvals(S)
    return ev[np.argsort(np.abs(ev - p))[:k]]


def _cluster_tol(solved):
    return 4 * _EPS * max(1.0, float(np.abs(solved.poles).max()), solved.part.norm)


def _held(M, C, B, d, h):
    """``Re C z_k`` of ``ż = M z + B d`` with ``d`` held over each step ``h``, from rest:
    the exact hold of the small matrix (``expm`` of ``[[M, B], [0, 0]] h``, balanced)."""
    q, md = B.shape
    aug = np.zeros((q + md, q + md), complex)
    aug[:q, :q], aug[:q, q:] = M * h, B * h
    ab, (sc, _) = scipy.linalg.matrix_balance(aug, permute=False, separate=True)
    Ed = sc[:, None] * scipy.linalg.expm(ab) / sc[None, :]
    A1, G1 = Ed[:q, :q], Ed[:q, q:]
    drive = d @ G1.T
    Y = np.empty((d.shape[0], C.shape[0]))
    z = np.zeros(q, complex)
    for k in range(d.shape[0]):
        Y[k] = (C @ z).real
        z = A1 @ z + drive[k]
    return Y


def _stepped(mu, out, inp, d, h, block: int = 256):
    """``Re Σ_k out_k ξ_k`` at each step, ``ξ_{j+1} = e^{μh} ξ_j + φ(μ) inp d_j`` (the exact
    hold of each pole's first-order part). A block of steps without disturbance is the
    closed form ``ξ_{j+i} = e^{μhi} ξ_j`` (one product for the block)."""
    with np.errstate(divide="ignore", invalid="ignore"):
        phi = np.where(mu == 0, h, np.expm1(mu * h) / mu)
    e = np.exp(mu * h)
    with np.errstate(over="ignore", invalid="ignore"):
        powers = e[None, :] ** np.arange(block)[:, None]  # (block, n_poles)
    Y = np.empty((d.shape[0], out.shape[1]))
    xi = np.zeros(mu.size, complex)
    outT = np.ascontiguousarray(out.T)
    with np.errstate(over="ignore", invalid="ignore"):
        for k0 in range(0, d.shape[0], block):
            dk = d[k0:k0 + block]
            if not np.any(dk):
                X = powers[:dk.shape[0]] * xi
                Y[k0:k0 + dk.shape[0]] = (X @ out).real
                xi = X[-1] * e
                continue
            for k, row in enumerate(dk, start=k0):
                Y[k] = (outT @ xi).real
                xi = e * xi + phi * (inp @ row)
    return Y
