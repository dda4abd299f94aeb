"""Lower bound of μ: the mixed power algorithm behind :func:`ambseal.robust.mu.mussv`.

Private module. For a structure Δ of real scalars, complex scalars and full complex blocks,
μ_Δ(M) = max over Q in the unit structure of ρ_R(M Q), the largest real eigenvalue
(Young & Doyle 1990, 1997; for complex structures ρ and the power iteration of Packard &
Doyle 1993 §9). Every bound returned is ``|λ| / σ̄(Q)`` for a structured Q and a *real*
eigenvalue λ of M Q, so that Δ = Q/λ is structured, has ``σ̄(Δ) = 1/bound`` and makes
``I − M Δ`` singular: a certificate, whatever the iteration did.

1. Power iteration (vectorised over the stack and over several starts: the right singular
   vector of M, the worst direction of the D–G upper bound, and seeded random vectors)::

       a ∝ M b,   w ∝ Mᴴ z,   b = Q a,   z = Qᴴ w,

   with complex scalars ``q = ∠(aᴴ w)``, full blocks ``Q_j = w_j a_jᴴ / (|w_j| |a_j|)``
   and real scalars moved by ``Re(w_jᴴ a_j) / (|w_j| |a_j|)``, the derivative of λ with
   respect to q_j (Young & Doyle 1997, lower-bound equations), then clipped to [−1, 1]:
   interior values, which the sign projection of the complex iteration cannot reach, are
   where the mixed optimum often lies. Each start iterates until its best candidate, taken
   every :data:`CHECK_EVERY` steps, stops rising (:func:`_candidates`).
2. Refinement of the best candidates per matrix: gradient projection on
   ``max |λ|  s.t.  Im λ = 0`` over the real scalars and the phases of the complex
   blocks, with the eigenvalue derivatives ``dλ = yᴴ M dQ x / (yᴴ x)`` (x, y right and left
   eigenvectors); a Newton step restores ``Im λ = 0`` and the gradient is projected onto its
   tangent. Computed on ``Vᴴ M Q V`` (rank of Q) rather than on M Q. It ends at its stall
   (:func:`_refine`).

Both stages end by their own rules, not after a count: on rank-one matrices, whose μ has a
closed form (Young 1994), 20 power iterations and 25 refinement steps had left bounds 4 %
below μ, where the stall rules end within 0.5 % of it (benchmarks/README.md, "μ's lower
bound ends by its own rules").
"""

from __future__ import annotations

import itertools

import numpy as np

__all__ = ["lower_bound"]

_EPS = 1e-300
#: Power-iteration steps between two checkpoints of a start's candidate.
CHECK_EVERY = 10
#: A start's power iteration ends at the first checkpoint that raises its best score by no
#: more than this share of it (its stall rule).
POWER_RTOL = 1e-3
#: A refinement makes progress when it raises its bound by more than this share of the
#: bound at its last progress.
REFINE_RTOL = 1e-3
#: Steps in a row without progress after which a refinement ends (a step off the manifold
#: and three Newton steps back onto it take four).
PATIENCE = 8
#: Steps a candidate not yet on the manifold Im λ = 0 has to reach it before its patience
#: counts (its Newton steps can zigzag near |Im λ| / |λ| of 0.1–0.5 before they converge).
REACH_STEPS = 25


def _ct(X):
    return np.conj(np.swapaxes(X, -1, -2))


def _unit(v):
    return v / np.maximum(np.linalg.norm(v, axis=-1), _EPS)[..., None]


class _Structure:
    """Block offsets of a parsed structure for a stack M (F, n, m)."""

    def __init__(self, blks, n, m):
        self.blks, self.n, self.m = blks, n, m
        self.ro = np.cumsum([0] + [b.c for b in blks])  # rows of M (a, z)
        self.co = np.cumsum([0] + [b.r for b in blks])  # columns of M (b, w)
        self.real = np.array([b.kind == "real" for b in blks])
        self.has_real = bool(self.real.any())
        self.rank = sum(b.r if b.kind != "full" else 1 for b in blks)

    def sl(self, j):
        return slice(self.co[j], self.co[j + 1]), slice(self.ro[j], self.ro[j + 1])


class _PowerIteration:
    """One step of the mixed power iteration on a stack M (F, n, m) (module docstring)."""

    def __init__(self, M, st: _Structure, as_complex):
        self.M, self.MH, self.st = M, _ct(M), st
        self.F = M.shape[0]
        self.as_complex = as_complex  # (F,) rows whose real blocks iterate as complex ones

    def update_q(self, a, w, q):
        """Scalar-block values from the current a (rows) and w (columns)."""
        q = q.copy()
        for j, bl in enumerate(self.st.blks):
            if bl.kind == "full":
                continue
            rs, cs = self.st.sl(j)
            ip = np.einsum("fi,fi->f", np.conj(w[:, rs]), a[:, cs])  # wᴴ a
            phase = np.conj(ip) / np.maximum(np.abs(ip), _EPS)
            if bl.kind == "real":
                nrm = np.linalg.norm(w[:, rs], axis=1) * np.linalg.norm(a[:, cs], axis=1)
                qr = np.clip(q[:, j].real + ip.real / np.maximum(nrm, _EPS), -1.0, 1.0)
                q[:, j] = np.where(self.as_complex, phase, qr)
            else:
                q[:, j] = phase
        return q

    def _apply(self, a, w, q, adjoint):
        st = self.st
        out = np.zeros((self.F, st.n if adjoint else st.m), complex)
        for j, bl in enumerate(st.blks):
            rs, cs = st.sl(j)
            if bl.kind == "full":
                na = np.linalg.norm(a[:, cs], axis=1)
                nw = np.linalg.norm(w[:, rs], axis=1)
                if adjoint:  # z_j = Q_jᴴ w_j = (|w_j| / |a_j|) a_j
                    out[:, cs] = (nw / np.maximum(na, _EPS))[:, None] * a[:, cs]
                else:  # b_j = Q_j a_j = (|a_j| / |w_j|) w_j
                    out[:, rs] = (na / np.maximum(nw, _EPS))[:, None] * w[:, rs]
            elif adjoint:
                out[:, cs] = np.conj(q[:, j])[:, None] * w[:, rs]
            else:
                out[:, rs] = q[:, j][:, None] * a[:, cs]
        return out

    def step(self, b, w, q):
        a = _unit((self.M @ b[:, :, None])[:, :, 0])
        q = self.update_q(a, w, q)
        w = _unit((self.MH @ self._apply(a, w, q, True)[:, :, None])[:, :, 0])
        q = self.update_q(a, w, q)
        return a, w, _unit(self._apply(a, w, q, False)), q

    def build_Q(self, a, w, q):
        """The structured Q (F, m, n) and an orthonormal V (F, n, rank) with Q = Q V Vᴴ."""
        st = self.st
        Q = np.zeros((self.F, st.m, st.n), complex)
        V = np.zeros((self.F, st.n, st.rank), complex)
        k = 0
        for j, bl in enumerate(st.blks):
            rs, cs = st.sl(j)
            if bl.kind == "full":
                au, wu = _unit(a[:, cs]), _unit(w[:, rs])
                Q[:, rs, cs] = wu[:, :, None] * np.conj(au[:, None, :])
                V[:, cs, k] = au
                k += 1
            else:  # complexified rows: a real block's phase projected on the real axis
                qj = q[:, j].real if bl.kind == "real" else q[:, j]
                Q[:, rs, cs] = qj[:, None, None] * np.eye(bl.r)
                V[:, cs, k:k + bl.r] = np.eye(bl.r)
                k += bl.r
        return Q, V


def _small(M, Q, V):
    """Vᴴ M Q V (F, r, r) and B = M Q V (F, n, r): M Q has the nonzero eigenvalues of the former."""
    B = M @ (Q @ V)
    return _ct(V) @ B, B


def _score(M, Q, V, has_real):
    """A cheap rank of candidates and their eigenvalue: the largest |λ| of M Q, for real
    structures weighted by exp(−4·angle to the real axis)."""
    ev = np.linalg.eigvals(_small(M, Q, V)[0])
    wgt = np.abs(ev)
    if has_real:
        ang = np.abs(np.angle(ev))
        wgt = wgt * np.exp(-4.0 * np.minimum(ang, np.pi - ang))
    k = np.argmax(wgt, axis=1)
    idx = np.arange(ev.shape[0])
    return wgt[idx, k], ev[idx, k]


def _eig_track(S, B, V, lam):
    """The eigenvalue of the small matrix S nearest lam, with M Q's right and left eigenvectors."""
    F = S.shape[0]
    ev, U = np.linalg.eig(S)
    k = np.argmin(np.abs(ev - lam[:, None]), axis=1)
    lam = ev[np.arange(F), k]
    u = U[np.arange(F), :, k]
    v = np.conj(np.linalg.inv(U)[np.arange(F), k, :])  # left: row k of U⁻¹
    x = np.einsum("fij,fj->fi", B, u)  # M Q x = λ x
    y = np.einsum("fij,fj->fi", V, v)  # yᴴ M Q = λ yᴴ
    return lam, x, y


def _newton(gi, im, qv, real):
    """Least-norm step onto Im λ = 0 (linearised) that no real scalar at ±1 leaves [−1, 1]."""
    use = np.ones(gi.shape, bool)
    for _ in range(2):
        G = gi * use
        dn = -(im / np.maximum(np.sum(G**2, axis=1), _EPS))[:, None] * G
        out = real[None, :] & (((qv >= 1 - 1e-12) & (dn > 0)) | ((qv <= -1 + 1e-12) & (dn < 0)))
        use &= ~out
    return dn * np.minimum(1.0, 0.3 / np.maximum(np.linalg.norm(dn, axis=1), _EPS))[:, None]


def _gradients(M, Q, x, y, st: _Structure):
    """dλ/dθ (F, nblocks) for θ = real scalars and phases of the complex blocks, and the
    real scalars' values (F, nblocks), from ``dλ = yᴴ M dQ x / (yᴴ x)``."""
    F, nb = M.shape[0], len(st.blks)
    yx = np.einsum("fi,fi->f", np.conj(y), x)
    yx = np.where(np.abs(yx) > _EPS, yx, _EPS)
    yM = np.einsum("fi,fij->fj", np.conj(y), M)
    g = np.empty((F, nb), complex)
    qv = np.zeros((F, nb))
    for j, bl in enumerate(st.blks):
        rs, cs = st.sl(j)
        if bl.kind == "real":  # dQ_j = I on the block
            g[:, j] = np.einsum("fi,fi->f", yM[:, rs], x[:, cs]) / yx
            qv[:, j] = Q[:, st.co[j], st.ro[j]].real
        else:  # dQ_j = j Q_j (phase)
            g[:, j] = 1j * np.einsum("fi,fik,fk->f", yM[:, rs], Q[:, rs, cs], x[:, cs]) / yx
    return g, qv


def _norm_Q(Q, st: _Structure):
    """σ̄(Q) from the structure: 1 with a full block, else the largest |q_j|."""
    out = np.ones(Q.shape[0]) if not all(b.kind != "full" for b in st.blks) \
        else np.zeros(Q.shape[0])
    for j, bl in enumerate(st.blks):
        if bl.kind != "full":
            out = np.maximum(out, np.abs(Q[:, st.co[j], st.ro[j]]))
    return out


def _step(Q, st, lam, g, qv, t, on):
    """Newton step onto Im λ = 0 plus the ascent step of length t along it, applied to Q."""
    s = np.where(lam.real < 0, -1.0, 1.0)
    gr = s[:, None] * g.real
    real = st.real[None, :]
    free = ~(real & (((qv >= 1 - 1e-12) & (gr > 0)) | ((qv <= -1 + 1e-12) & (gr < 0))))
    dn = _newton(g.imag, lam.imag, qv, st.real)
    Gi, Gr = g.imag * free, gr * free
    n2 = np.maximum(np.sum(Gi**2, axis=1), _EPS)
    dg = Gr - (np.sum(Gr * Gi, axis=1) / n2)[:, None] * Gi  # ascent along the manifold
    ng = np.maximum(np.linalg.norm(dg, axis=1), _EPS)
    step = dn + ((t / ng) * on)[:, None] * dg
    Q = Q.copy()
    for j, bl in enumerate(st.blks):
        rs, cs = st.sl(j)
        if bl.kind == "real":
            Q[:, rs, cs] = np.clip(qv[:, j] + step[:, j], -1.0, 1.0)[:, None, None] * np.eye(bl.r)
        else:
            Q[:, rs, cs] = Q[:, rs, cs] * np.exp(1j * step[:, j])[:, None, None]
    return Q


def _refine(M, Q, V, lam, st: _Structure, upper=None):
    """Gradient projection on max |λ| s.t. Im λ = 0 (module docstring, step 2), on an
    active set. A matrix leaves the set after :data:`PATIENCE` steps in a row without
    progress, or when its bound is within 1e-5 of ``upper``. Once it has a bound, progress
    is a rise of the bound by more than :data:`REFINE_RTOL` of the bound at the last
    progress; before, any of its first :data:`REACH_STEPS` steps, or a halving of the
    least ``|Im λ| / |λ|`` seen (the Newton steps converging onto the manifold, on it at
    1e-9). Each can happen only finitely often (the bound never exceeds σ̄(M)), so the
    refinement ends: at a stall of the ascent, which can zigzag on and off the manifold,
    gaining a little every few steps.

    Returns the best certified bound (F,), its Q and its real eigenvalue.
    """
    F = M.shape[0]
    best = np.zeros(F)
    bestQ, bestlam = Q.copy(), np.ones(F, complex)
    t = np.full(F, 0.05)
    calm = np.zeros(F, int)
    ref = np.zeros(F)  # the bound at the last progress
    least = np.full(F, np.inf)  # the least |Im λ| / |λ| seen
    act = np.arange(F)
    Q = Q.copy()
    for it in itertools.count():
        Ma, Qa, Va = M[act], Q[act], V[act]
        S, B = _small(Ma, Qa, Va)
        la, x, y = _eig_track(S, B, Va, lam[act])
        lam[act] = la
        ratio = np.abs(la.imag) / np.maximum(np.abs(la), _EPS)
        on = ratio <= 1e-9
        val = np.where(on, np.abs(la) / np.maximum(_norm_Q(Qa, st), _EPS), 0.0)
        gain = val - best[act]
        up = gain > 0
        best[act] = np.where(up, val, best[act])
        progress = np.where(ref[act] > 0, best[act] > (1 + REFINE_RTOL) * ref[act],
                            (best[act] > 0) | (ratio < 0.5 * least[act])
                            | (it < REACH_STEPS))
        least[act] = np.minimum(least[act], ratio)
        ref[act] = np.where(progress, best[act], ref[act])
        calm[act] = np.where(progress, 0, calm[act] + 1)
        bestQ[act] = np.where(up[:, None, None], Qa, bestQ[act])
        bestlam[act] = np.where(up, la.real + 0j, bestlam[act])
        keep = calm[act] < PATIENCE
        if upper is not None:
            keep &= best[act] < (1 - 1e-5) * upper[act]
        if not keep.any():
            break
        # on the manifold without gain: back to the best point with half the step
        back = on & ~up & (it > 0)
        t[act] = np.where(back, 0.5 * t[act], np.where(on, np.minimum(1.5 * t[act], 0.3), t[act]))
        Qa = np.where(back[:, None, None], bestQ[act], Qa)
        if back.any():
            S, B = _small(Ma[back], Qa[back], Va[back])
            lb, xb, yb = _eig_track(S, B, Va[back], bestlam[act][back])
            la[back], x[back], y[back] = lb, xb, yb
        g, qv = _gradients(Ma, Qa, x, y, st)
        Q[act] = _step(Qa, st, la, g, qv, t[act], on)
        act = act[keep]
    return best, bestQ, bestlam


def lower_bound(M, blks, n_iter: int | None, rng, *, starts=(), n_random: int = 1,
                n_refine: int = 3, upper=None, tight: float = 0.99):
    """Lower bound of μ on a stack M (F, n, m) and its worst-case Δ (F, m, n).

    Parameters
    ----------
    M : ndarray, shape (F, n, m)
    blks : tuple of _Block
    n_iter : int or None
        A cap on the power iterations per start; None: each start's iteration ends by its
        stall rule (:func:`_candidates`).
    rng : numpy.random.Generator
        Seeded generator for the random starts.
    starts : sequence of (b, w)
        Extra start vectors, each (F, m) (e.g. the upper bound's worst direction).
    n_random : int
        Random starts in addition to M's top right singular vector and ``starts``.
    n_refine : int
        Candidates per matrix refined (step 2 of the module docstring), best first; with
        ``upper`` the next one only where the bound is below ``tight·upper``.
    upper : ndarray (F,), optional
        Upper bounds of μ (stop refining where the lower bound is within ``tight``).

    Returns
    -------
    lower : ndarray (F,)
    delta : ndarray (F, m, n), structured, ``σ̄(Δ) = 1/lower``, ``I − M Δ`` singular
        (zero where the bound is zero).
    """
    F, n, m = M.shape
    st = _Structure(blks, n, m)
    _, _, vh = np.linalg.svd(M)
    svd = np.conj(vh[:, 0, :])
    first = [(svd, svd)] + [tuple(s) for s in starts]
    second = [tuple(rng.standard_normal((F, m)) + 1j * rng.standard_normal((F, m))
                    for _ in range(2)) for _ in range(n_random)]
    n_cplx = len(first) if st.has_real else 0  # complex iteration, phases projected
    lower, lam = np.zeros(F), np.ones(F, complex)
    Qbest = np.zeros((F, m, n), complex)
    todo = np.arange(F)
    # first the deterministic starts; the others only where the bound is not yet tight
    for group, ncx in ((first, 0), (second + first[:n_cplx], n_cplx)):
        if not group or todo.size == 0:
            continue
        score, cQ, cV, clam = _candidates(M[todo], st, [(b[todo], w[todo]) for b, w in group],
                                          ncx, n_iter)
        order = np.argsort(-score, axis=0)
        for r in range(min(n_refine, len(group))):
            pick = order[r], np.arange(todo.size)
            val, Qb, lamb = _certify(M[todo], cQ[pick], cV[pick], clam[pick], st,
                                     None if upper is None else upper[todo])
            up = val > lower[todo]
            lower[todo[up]], lam[todo[up]], Qbest[todo[up]] = val[up], lamb[up], Qb[up]
            if upper is not None:
                keep = lower[todo] < tight * upper[todo]
                todo, score, cQ, cV, clam = todo[keep], score[:, keep], cQ[:, keep], \
                    cV[:, keep], clam[:, keep]
                order = order[:, keep]
            if todo.size == 0:
                break
    lam = np.where(lower > 0, lam, 1.0)
    delta = np.where((lower > 0)[:, None, None], Qbest / lam[:, None, None], 0.0)
    return lower, delta


def _candidates(M, st, starts, n_cplx, n_iter):
    """Power iteration from each start (b, w) (the last ``n_cplx`` with real blocks iterated
    as complex ones); per start the best candidate at the checkpoints, every
    :data:`CHECK_EVERY` steps.

    A start's iteration ends at the first checkpoint that raises its best score by no more
    than :data:`POWER_RTOL` of it: the iteration has converged, or it cycles (the mixed
    iteration need not converge; Young & Doyle 1997) without finding a better candidate.
    The score is bounded by σ̄(M), so it ends. ``n_iter`` is a caller's cap on the steps
    (None: none).

    Returns score (ns, F), Q (ns, F, m, n), V (ns, F, n, rank), λ (ns, F).
    """
    F, n, m = M.shape
    ns = len(starts)
    Ms = np.concatenate([M] * ns)
    b = _unit(np.concatenate([s[0] for s in starts]))
    w = _unit(np.concatenate([s[1] for s in starts]))
    q = np.zeros((F * ns, len(st.blks)), complex)
    as_complex = np.arange(F * ns) >= F * (ns - n_cplx)
    score = np.full(F * ns, -1.0)
    cQ = np.zeros((F * ns, m, n), complex)
    cV = np.zeros((F * ns, n, st.rank), complex)
    clam = np.zeros(F * ns, complex)
    act = np.arange(F * ns)
    done = 0
    while act.size and (n_iter is None or done < n_iter):
        pi = _PowerIteration(Ms[act], st, as_complex[act])
        ba, wa, qa = b[act], w[act], q[act]
        steps = CHECK_EVERY if n_iter is None else min(CHECK_EVERY, n_iter - done)
        for _ in range(steps):
            a, wa, ba, qa = pi.step(ba, wa, qa)
        done += steps
        b[act], w[act], q[act] = ba, wa, qa
        Q, V = pi.build_Q(a, wa, qa)
        sc, lam = _score(Ms[act], Q, V, st.has_real)
        rise = sc > score[act] + POWER_RTOL * np.abs(score[act])
        up = sc > score[act]
        score[act] = np.where(up, sc, score[act])
        cQ[act] = np.where(up[:, None, None], Q, cQ[act])
        cV[act] = np.where(up[:, None, None], V, cV[act])
        clam[act] = np.where(up, lam, clam[act])
        act = act[rise]
    return (score.reshape(ns, F), cQ.reshape(ns, F, m, n), cV.reshape(ns, F, n, st.rank),
            clam.reshape(ns, F))


def _certify(M, Q, V, lam, st, upper=None):
    """Certified bounds of candidates: refined (real structures) or the largest |λ|
    (complex structures: any eigenvalue is made real by a common phase of Q)."""
    if st.has_real:
        return _refine(M, Q, V, lam, st, upper)
    ev = np.linalg.eigvals(_small(M, Q, V)[0])
    lamb = ev[np.arange(ev.shape[0]), np.argmax(np.abs(ev), axis=1)]
    return np.abs(lamb) / np.maximum(_norm_Q(Q, st), _EPS), Q, lamb
