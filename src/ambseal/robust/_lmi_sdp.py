"""LMIs in symmetric matrix variables solved by CVXOPT with their Kronecker structure.

The LPV synthesis (:mod:`ambseal.robust._lpv_lmi`) has few unknowns — γ and the symmetric
N × N matrices R, S_i — and many dense LMIs of size ≈ N, each of the form

    s_j = H_j + γ Γ_j + Σ_t (P_t X_{v(t)} Q_tᵀ + Q_t X_{v(t)} P_tᵀ) ⪰ 0.

A general sparse-KKT solver (Clarabel) factorises a system with one dense block of
d(d+1)/2 rows per LMI of size d and pays for the fill between them; its time grows with the
LMIs, not with the unknowns (3–5 s per interior-point iteration on a 32-state plant). An
interior-point method for SDPs only needs the Schur complement

    H = Σ_j 𝒜_jᵀ (Z_j ⊗ Z_j) 𝒜_j,     Z_j = W_j⁻¹ W_j⁻ᵀ (the Nesterov–Todd scaling),

of order the number of unknowns (Vandenberghe, Balakrishnan, Wallin, Hansson & Roh 2005,
"Interior-point algorithms for semidefinite programming problems derived from the KYP
lemma": forming H is what an LMI solver's iteration costs). For the maps
X ↦ P X Qᵀ + Q X Pᵀ its blocks are sums of Kronecker products of n × n matrices,

    𝒜_tᵀ (Z ⊗ Z) 𝒜_u : X ↦ (P_tᵀZP_u) X (Q_uᵀZQ_t) + (P_tᵀZQ_u) X (P_uᵀZQ_t)
                            + (Q_tᵀZP_u) X (Q_uᵀZP_t) + (Q_tᵀZQ_u) X (P_uᵀZP_t),

formed with O(n⁴) operations (:func:`_schur`). CVXOPT's ``conelp`` runs the interior-point
method (its documented interface for a user KKT solver and a matrix-free G, "Exploiting
structure", Andersen, Dahl & Vandenberghe); :func:`solve_lmis` supplies G and the KKT
solver.

Where the problem is invariant under an orthogonal map T of the states with T² = −I that
pairs them with a sign (T e_i = s e_j, T e_j = −s e_i: a quarter turn of a plant
symmetric under rotation, in coordinates that keep it orthogonal), its feasible set and
cost are invariant under X ↦ Tᵀ X T, and so is its optimum where that is unique;
:func:`solve_lmis` given the pairing (:class:`StatePairing`) solves it on the invariant
matrices — per two pairs k ≠ l the block [[a, b], [−σb, σa]] (σ = s_k s_l), per pair
a·I: (n/2)² unknowns instead of n(n+1)/2, each two entries of vech(X) (the map E). The
Schur complement is then Eᵀ H E, formed from H's rows with their columns reduced by E,
and its Cholesky factorisation is an eighth of the work. Every point of the subspace is
one of the whole problem: what it certifies holds.

Storage follows CVXOPT: the 's' part of a vector is each d × d matrix in column-major
order, of which only the lower triangle is read (the upper triangle is written
symmetrically here). The unknowns are x = [γ, vech(X_0), vech(X_1), …] with vech the
lower-triangular entries (any linear parametrisation leaves the interior-point iterates
unchanged).
"""

from __future__ import annotations

from dataclasses import dataclass

import cvxopt
import numpy as np
import scipy.linalg as sla
from cvxopt import solvers

__all__ = ["LmiTerm", "Lmi", "SdpSolution", "StatePairing", "solve_lmis"]


@dataclass(frozen=True)
class LmiTerm:
    """``P X_var Qᵀ + Q X_var Pᵀ`` with P, Q of shape (d, n)."""

    var: int
    P: np.ndarray
    Q: np.ndarray


@dataclass(frozen=True)
class Lmi:
    """``const + γ·gamma + Σ terms ⪰ 0`` (``gamma`` None: γ does not enter); ``margin``: the
    strictness margin ``const`` carries (−margin·I, the LMI being a strict one ≻ 0)."""

    const: np.ndarray
    gamma: np.ndarray | None
    terms: tuple[LmiTerm, ...]
    margin: float = 0.0

    @property
    def size(self) -> int:
        return self.const.shape[0]


#: CVXOPT's own cap on the interior-point iterations (its ``maxiters``) where the options
#: do not set one.
CVXOPT_MAXITERS = 100


@dataclass(frozen=True)
class SdpSolution:
    """What :func:`solve_lmis` found: ``gamma`` (None without γ), the matrices ``X``, CVXOPT's
    ``status`` (``"optimal"`` or ``"unknown"``, and ``"infeasible"`` for a primal
    infeasibility certificate; ``"feasible"`` where CVXOPT stopped short of its tolerances,
    "unknown", on a point at which every LMI holds: :func:`holds`), ``iterations`` and
    ``max_iterations``, the cap it ran under (``iterations`` reaching it: stopped by the
    cap; short of it and not optimal: stalled)."""

    gamma: float | None
    X: list
    status: str
    iterations: int
    max_iterations: int = CVXOPT_MAXITERS


@dataclass(frozen=True)
class StatePairing:
    """The states' pairing by an orthogonal symmetry T of the problem, T² = −I:
    T e_i = s e_j and T e_j = −s e_i for each (i, j, s) of ``(first, second, sign)``
    (arrays of n/2 ints, ints, ±1.0), every state in one pair."""

    first: np.ndarray
    second: np.ndarray
    sign: np.ndarray

    def matrix(self, n: int) -> np.ndarray:
        """T (n × n)."""
        T = np.zeros((n, n))
        T[self.second, self.first] = self.sign
        T[self.first, self.second] = -self.sign
        return T


class _Reduced:
    """x = E x̃ on the matrices invariant under a pairing (module docstring): for each
    unknown of x̃, its one or two entries of x (``rows``, the second ``-1`` where there is
    none) and their coefficients (``vals``)."""

    def __init__(self, lay: "_Layout", n_vars: int, pairing: StatePairing):
        n = lay.n
        pos = np.full((n, n), -1, int)
        pos[lay.I, lay.J] = np.arange(lay.m)
        pos[lay.J, lay.I] = np.arange(lay.m)
        i, j, sg = (np.asarray(pairing.first, int), np.asarray(pairing.second, int),
                    np.asarray(pairing.sign, float))
        one = [(pos[i[k], i[k]], pos[j[k], j[k]], 1.0, 1.0) for k in range(i.size)]
        for k in range(i.size):
            for m in range(k + 1, i.size):
                sigma = sg[k] * sg[m]
                p, q = i[m], j[m]
                one.append((pos[i[k], p], pos[j[k], q], 1.0, sigma))  # a
                one.append((pos[i[k], q], pos[j[k], p], 1.0, -sigma))  # b
        per = np.array(one)
        r1, r2 = per[:, 0].astype(int), per[:, 1].astype(int)
        v1, v2 = per[:, 2], per[:, 3]
        rows1, rows2, vals1, vals2 = ([0], [-1], [1.0], [0.0]) if lay.with_gamma else \
            ([], [], [], [])
        for v in range(n_vars):
            rows1 += list(lay.off[v] + r1)
            rows2 += list(lay.off[v] + r2)
            vals1 += list(v1)
            vals2 += list(v2)
        self.rows1, self.rows2 = np.array(rows1, int), np.array(rows2, int)
        self.vals1, self.vals2 = np.array(vals1), np.array(vals2)
        self.two = self.rows2 >= 0
        self.size, self.full = self.rows1.size, lay.size
        # one variable's unknowns in its own vech (every variable alike), and where each
        # variable's unknowns start in x̃
        self.local = (r1, v1, r2, v2)
        self.per = r1.size
        self.start = [int(lay.with_gamma) + v * r1.size for v in range(n_vars)]

    def expand(self, xr: np.ndarray) -> np.ndarray:
        """E x̃."""
        x = np.zeros(self.full)
        x[self.rows1] += self.vals1 * xr
        x[self.rows2[self.two]] += self.vals2[self.two] * xr[self.two]
        return x

    def restrict(self, g: np.ndarray) -> np.ndarray:
        """Eᵀ g."""
        out = self.vals1 * g[self.rows1]
        out[self.two] += self.vals2[self.two] * g[self.rows2[self.two]]
        return out


class _Layout:
    """Offsets of γ and of each vech(X_v) in x, and the vech index arrays."""

    def __init__(self, n: int, n_vars: int, with_gamma: bool):
        self.n, self.with_gamma = n, with_gamma
        self.I, self.J = np.tril_indices(n)
        self.m = self.I.size
        self.off = [int(with_gamma) + v * self.m for v in range(n_vars)]
        self.size = int(with_gamma) + n_vars * self.m
        #: Dᵀ vec(Y) for symmetric Y: the diagonal once, each off-diagonal entry twice
        self.w = np.where(self.I == self.J, 1.0, 2.0)
        self.off_q = (self.I != self.J).astype(float)
        #: flat indices into an n × n matrix of the entries (I_q, J_q) and (J_q, I_q)
        self.at_ij = self.I * n + self.J
        self.at_ji = self.J * n + self.I

    def unpack(self, x: np.ndarray, v: int) -> np.ndarray:
        X = np.zeros((self.n, self.n))
        vals = x[self.off[v]:self.off[v] + self.m]
        X[self.I, self.J] = vals
        X[self.J, self.I] = vals
        return X

    def adjoint(self, Y: np.ndarray) -> np.ndarray:
        """Dᵀ vec(Y), Y symmetric: the gradient of tr(Y X) in vech(X)."""
        return self.w * Y[self.I, self.J]


def _sym_from_lower(a: np.ndarray, d: int) -> np.ndarray:
    L = np.tril(a.reshape(d, d, order="F"))
    return L + np.tril(L, -1).T


def _lin(lmi: Lmi, lay: _Layout, x: np.ndarray) -> np.ndarray:
    """The part of s_j linear in x (γ Γ + Σ terms)."""
    out = np.zeros_like(lmi.const)
    if lmi.gamma is not None:
        out += x[0] * lmi.gamma
    for t in lmi.terms:
        X = lay.unpack(x, t.var)
        PXQ = t.P @ X @ t.Q.T
        out += PXQ + PXQ.T
    return out


def _lin_adjoint(lmi: Lmi, lay: _Layout, Y: np.ndarray, out: np.ndarray) -> None:
    """out += 𝒜ᵀ(Y) for symmetric Y (trace inner product on s, Euclidean on x)."""
    if lmi.gamma is not None:
        out[0] += float(np.sum(lmi.gamma * Y))
    for t in lmi.terms:
        PYQ = t.P.T @ Y @ t.Q
        o = lay.off[t.var]
        out[o:o + lay.m] += lay.adjoint(PYQ + PYQ.T)


#: An LMI without a margin holds at x where its smallest eigenvalue is at least
#: −HOLD_RTOL times its largest magnitude: in the LPV synthesis those are the coupling
#: LMIs [[R, αI], [αI, S]] ⪰ 0, whose strictness is α > 1 (S R ⪰ α² I where the
#: reconstruction needs I − S R invertible: α² − 1 = 0.21 at the default 1.1), far above
#: this; the reconstruction's own check (its loss, RECONSTRUCTION_LOSS) follows.
HOLD_RTOL = 1e-9


def holds(lmis, lay: _Layout, x: np.ndarray) -> bool:
    """Whether every LMI holds at x, by its eigenvalues: the strict LMI it stands for with
    at least half its ``margin`` (smallest eigenvalue ≥ −margin/2), one without a margin
    to :data:`HOLD_RTOL`. Where CVXOPT stops short of its tolerances — on the same LMIs,
    by its BLAS's rounding, one build of CVXOPT ends "optimal" and another "unknown" after
    its iterations — the point it returns may still satisfy them, and then certifies as
    an optimal one does (less tightly: not the optimum)."""
    if not np.all(np.isfinite(x)):
        return False
    for lmi in lmis:
        S = lmi.const + _lin(lmi, lay, x)
        w = np.linalg.eigvalsh((S + S.T) / 2)
        floor = 0.5 * lmi.margin if lmi.margin > 0 else HOLD_RTOL * max(np.abs(w).max(),
                                                                         1e-300)
        if w[0] < -floor:
            return False
    return True


def _scaled(lmi: Lmi, rti: np.ndarray) -> Lmi:
    """The LMI seen through the scaling W⁻ᵀ(Y) = rtiᵀ Y rti: P̃ = rtiᵀP, Q̃ = rtiᵀQ,
    Γ̃ = rtiᵀΓ rti. Then Pᵀ Z Q = P̃ᵀ Q̃ with Z = rti rtiᵀ, a product of factors rather
    than of Z, whose condition number is the square of rti's (≈ 1e12 near the optimum)."""
    return Lmi(lmi.const, None if lmi.gamma is None else rti.T @ lmi.gamma @ rti,
               tuple(LmiTerm(t.var, rti.T @ t.P, rti.T @ t.Q) for t in lmi.terms))


#: Rows of a Schur block formed at a time (:func:`_schur`): their n × n slices of the
#: operator, 64·n²·8 bytes (1.4 MB at n = 52), stay in the cache while they are read.
_SCHUR_ROWS = 64


def _schur(scaled, lay: _Layout, red: "_Reduced | None" = None) -> np.ndarray:
    """H = Σ_j 𝒜_jᵀ (Z_j ⊗ Z_j) 𝒜_j in the vech coordinates (module docstring), from the
    scaled LMIs (:func:`_scaled`, Z = I); Fortran-ordered, as LAPACK factorises it.

    Each pair of terms (t on X_v, u on X_w) adds the operator X ↦ Σ_k L_k X R_k of the
    module docstring to the block (v, w), and its entries in the vech coordinates are

        [Dᵀ Op D]_pq = w_p (M_p[I_q, J_q] + [I_q ≠ J_q] M_p[J_q, I_q]),
        M_p[a, b] = Σ_k L_k[I_p, a] R_k[b, J_p],

    the n × n matrix M_p of row p being one product of the rows I_p of the L_k by the
    columns J_p of the R_k, summed over every LMI and pair of terms of the block. The
    rows are formed :data:`_SCHUR_ROWS` at a time: the n⁴ array of every row at once is
    written and read back from memory, which costs more than the products.

    With ``red``, Eᵀ H E on the invariant unknowns (module docstring): each block's rows
    with their columns reduced by E as they are formed, then its rows.
    """
    m, n = lay.m, lay.n
    H = np.zeros((lay.size, lay.size) if red is None else (red.size, red.size), order="F")
    factors: dict = {}
    for lmi in scaled:
        for a, ta in enumerate(lmi.terms):
            for tb in lmi.terms[a:]:
                # blocks (v, w) with v ≤ w only; (w, v) is added as the transpose
                pairs = [(ta, tb)] if ta is tb else [(ta, tb), (tb, ta)]
                for s, t in pairs:
                    if s.var > t.var:
                        continue
                    Ls, Rs = factors.setdefault((s.var, t.var), ([], []))
                    Ls += [s.P.T @ t.P, s.P.T @ t.Q, s.Q.T @ t.P, s.Q.T @ t.Q]
                    Rs += [t.Q.T @ s.Q, t.P.T @ s.Q, t.Q.T @ s.P, t.P.T @ s.P]
        if lmi.gamma is not None:
            H[0, 0] += float(np.sum(lmi.gamma * lmi.gamma))
            col = np.zeros(lay.size)
            _lin_adjoint(Lmi(lmi.const, None, lmi.terms), lay, lmi.gamma, col)
            if red is not None:
                col = red.restrict(col)
            H[0, :] += col
            H[1:, 0] += col[1:]
    for (v, w), (Ls, Rs) in factors.items():
        rows = np.stack(Ls)[:, lay.I, :].transpose(1, 2, 0)  # (m, n, K): L_k[I_p, :]
        cols = np.stack(Rs)[:, :, lay.J].transpose(2, 0, 1)  # (m, K, n): R_k[:, J_p]
        ov, ow = lay.off[v], lay.off[w]
        if red is not None:  # the block's rows with their columns reduced by E, then its rows
            r1, v1, r2, v2 = red.local
            out = np.empty((m, red.per))
        for p0 in range(0, m, _SCHUR_ROWS):
            p1 = min(p0 + _SCHUR_ROWS, m)
            M = np.matmul(rows[p0:p1], cols[p0:p1]).reshape(p1 - p0, n * n)
            blk = np.take(M, lay.at_ji, axis=1)
            blk *= lay.off_q
            blk += np.take(M, lay.at_ij, axis=1)
            blk *= lay.w[p0:p1, None]
            if red is not None:
                out[p0:p1] = np.take(blk, r1, axis=1) * v1 + np.take(blk, r2, axis=1) * v2
                continue
            H[ov + p0:ov + p1, ow:ow + m] += blk
            if v != w:
                H[ow:ow + m, ov + p0:ov + p1] += blk.T
        if red is not None:
            blk = v1[:, None] * np.take(out, r1, axis=0) + v2[:, None] * np.take(out, r2,
                                                                                 axis=0)
            sv, sw = red.start[v], red.start[w]
            H[sv:sv + red.per, sw:sw + red.per] += blk
            if v != w:
                H[sw:sw + red.per, sv:sv + red.per] += blk.T
    return H


def solve_lmis(lmis, n: int, n_vars: int, cost_gamma: float | None, cost_trace,
               options: dict, pairing: StatePairing | None = None) -> SdpSolution:
    """Minimise ``cost_gamma·γ + Σ_v cost_trace[v]·tr X_v`` subject to the LMIs ``s_j ⪰ 0``.

    Parameters
    ----------
    lmis : sequence of Lmi
    n : int
        Order of every matrix variable X_v.
    n_vars : int
    cost_gamma : float or None
        None: no γ variable (every ``Lmi.gamma`` must be None).
    cost_trace : sequence of float, length n_vars
    options : dict
        CVXOPT solver options (``abstol``, ``reltol``, ``feastol``, ``maxiters``,
        ``refinement``).
    pairing : StatePairing, optional
        A symmetry of the LMIs and the cost (module docstring): every X_v is sought among
        the matrices it leaves invariant. None: among all symmetric ones.

    Returns
    -------
    SdpSolution

    Raises
    ------
    ArithmeticError, ValueError
        From CVXOPT, on a singular scaling or KKT system (badly conditioned LMIs).
    """
    lay = _Layout(n, n_vars, cost_gamma is not None)
    dims = {"l": 0, "q": [], "s": [lmi.size for lmi in lmis]}
    offs = np.concatenate([[0], np.cumsum([d * d for d in dims["s"]])]).astype(int)
    c = np.zeros(lay.size)
    if cost_gamma is not None:
        c[0] = cost_gamma
    for v, ct in enumerate(cost_trace):
        c[lay.off[v]:lay.off[v] + lay.m] = ct * (lay.I == lay.J)
    h = np.concatenate([lmi.const.ravel(order="F") for lmi in lmis])
    red = None if pairing is None else _Reduced(lay, n_vars, pairing)
    expand = (lambda x: x) if red is None else red.expand
    restrict = (lambda g: g) if red is None else red.restrict
    c = restrict(c)

    def G(u, v, alpha=1.0, beta=0.0, trans="N"):
        un, vn = np.asarray(u)[:, 0], np.asarray(v)[:, 0]
        if trans == "N":  # G x = −(γ Γ + Σ terms): s = h − G x
            x = expand(un)
            gx = np.concatenate([-_lin(lmi, lay, x).ravel(order="F") for lmi in lmis])
        else:
            gx = np.zeros(lay.size)
            for j, lmi in enumerate(lmis):
                _lin_adjoint(lmi, lay, _sym_from_lower(un[offs[j]:offs[j + 1]], lmi.size),
                             gx)
            gx = -restrict(gx)
        vn *= beta
        vn += alpha * gx

    def kktsolver(W):
        rtis = [np.array(r) for r in W["rti"]]
        scaled = [_scaled(lmi, r) for lmi, r in zip(lmis, rtis)]
        try:
            # H is ours and Fortran-ordered: factorised where it lies, not copied
            cf = sla.cho_factor(_schur(scaled, lay, red), check_finite=False,
                                overwrite_a=True)
        except (np.linalg.LinAlgError, ValueError) as exc:
            raise ArithmeticError(str(exc)) from exc

        def f(x, y, z):
            xn, zn = np.asarray(x)[:, 0], np.asarray(z)[:, 0]
            Bz = [r.T @ _sym_from_lower(zn[offs[j]:offs[j + 1]], lmi.size) @ r
                  for j, (lmi, r) in enumerate(zip(lmis, rtis))]  # W⁻ᵀ bz
            g = np.zeros(lay.size)
            for lmi, B in zip(scaled, Bz):
                _lin_adjoint(lmi, lay, B, g)
            # H ux = bx + Gᵀ(WᵀW)⁻¹bz
            ux = sla.cho_solve(cf, xn - restrict(g), check_finite=False)
            xn[:] = ux
            ux = expand(ux)
            for j, (lmi, B) in enumerate(zip(scaled, Bz)):  # W uz = W⁻ᵀ(G ux − bz)
                zn[offs[j]:offs[j + 1]] = (-_lin(lmi, lay, ux) - B).ravel(order="F")
        return f

    opts = {"show_progress": False, **options}
    cap = int(opts.get("maxiters", solvers.options.get("maxiters", CVXOPT_MAXITERS)))
    res = solvers.conelp(cvxopt.matrix(c), G, cvxopt.matrix(h), dims,
                         kktsolver=kktsolver, options=opts)
    status = {"primal infeasible": "infeasible"}.get(res["status"], res["status"])
    x = expand(np.asarray(res["x"])[:, 0]) if res["x"] is not None else \
        np.full(lay.size, np.nan)
    if status == "unknown" and holds(lmis, lay, x):
        status = "feasible"
    X = [lay.unpack(x, v) for v in range(n_vars)]
    return SdpSolution(float(x[0]) if lay.with_gamma else None, X, status,
                       int(res.get("iterations", 0) or 0), cap)
