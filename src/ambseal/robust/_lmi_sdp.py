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

formed in O(n⁴) per pair of terms. CVXOPT's ``conelp`` runs the interior-point method (its
documented interface for a user KKT solver and a matrix-free G, "Exploiting structure",
Andersen, Dahl & Vandenberghe); :func:`solve_lmis` supplies G and the KKT solver.

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

__all__ = ["LmiTerm", "Lmi", "SdpSolution", "solve_lmis"]


@dataclass(frozen=True)
class LmiTerm:
    """``P X_var Qᵀ + Q X_var Pᵀ`` with P, Q of shape (d, n)."""

    var: int
    P: np.ndarray
    Q: np.ndarray


@dataclass(frozen=True)
class Lmi:
    """``const + γ·gamma + Σ terms ⪰ 0`` (``gamma`` None: γ does not enter)."""

    const: np.ndarray
    gamma: np.ndarray | None
    terms: tuple[LmiTerm, ...]

    @property
    def size(self) -> int:
        return self.const.shape[0]


@dataclass(frozen=True)
class SdpSolution:
    """What :func:`solve_lmis` found: ``gamma`` (None without γ), the matrices ``X``, CVXOPT's
    ``status`` (``"optimal"`` or ``"unknown"``, and ``"infeasible"`` for a primal
    infeasibility certificate) and ``iterations``."""

    gamma: float | None
    X: list
    status: str
    iterations: int


class _Layout:
    """Offsets of γ and of each vech(X_v) in x, and the vech index arrays."""

    def __init__(self, n: int, n_vars: int, with_gamma: bool):
        self.n, self.n_vars, self.with_gamma = n, n_vars, with_gamma
        self.I, self.J = np.tril_indices(n)
        self.m = self.I.size
        self.off = [int(with_gamma) + v * self.m for v in range(n_vars)]
        self.size = int(with_gamma) + n_vars * self.m
        #: Dᵀ vec(Y) for symmetric Y: the diagonal once, each off-diagonal entry twice
        self.w = np.where(self.I == self.J, 1.0, 2.0)
        self.off_q = (self.I != self.J).astype(float)

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


def _scaled(lmi: Lmi, rti: np.ndarray) -> Lmi:
    """The LMI seen through the scaling W⁻ᵀ(Y) = rtiᵀ Y rti: P̃ = rtiᵀP, Q̃ = rtiᵀQ,
    Γ̃ = rtiᵀΓ rti. Then Pᵀ Z Q = P̃ᵀ Q̃ with Z = rti rtiᵀ, a product of factors rather
    than of Z, whose condition number is the square of rti's (≈ 1e12 near the optimum)."""
    return Lmi(lmi.const, None if lmi.gamma is None else rti.T @ lmi.gamma @ rti,
               tuple(LmiTerm(t.var, rti.T @ t.P, rti.T @ t.Q) for t in lmi.terms))


def _schur(scaled, lay: _Layout) -> np.ndarray:
    """H = Σ_j 𝒜_jᵀ (Z_j ⊗ Z_j) 𝒜_j in the vech coordinates (module docstring), from the
    scaled LMIs (:func:`_scaled`, Z = I)."""
    H = np.zeros((lay.size, lay.size))
    I, J, w, offq, m = lay.I, lay.J, lay.w, lay.off_q, lay.m
    for lmi in scaled:
        for a, ta in enumerate(lmi.terms):
            for b in range(a, len(lmi.terms)):
                tb = lmi.terms[b]
                # Op(X) = Σ_k L_k X R_k with (L_k, R_k) from the module docstring
                pairs = ((ta.P.T @ tb.P, tb.Q.T @ ta.Q), (ta.P.T @ tb.Q, tb.P.T @ ta.Q),
                         (ta.Q.T @ tb.P, tb.Q.T @ ta.P), (ta.Q.T @ tb.Q, tb.P.T @ ta.P))
                blk = np.zeros((m, m))
                for L, Rm in pairs:
                    # [Dᵀ Op D]_{pq}: Op(E_q + E_qᵀ) read at (I_p, J_p), weighted by w_p
                    blk += L[np.ix_(I, I)] * Rm[np.ix_(J, J)].T
                    blk += offq[None, :] * (L[np.ix_(I, J)] * Rm[np.ix_(I, J)].T)
                blk *= w[:, None]
                oa, ob = lay.off[ta.var], lay.off[tb.var]
                H[oa:oa + m, ob:ob + m] += blk
                if b != a:
                    H[ob:ob + m, oa:oa + m] += blk.T
        if lmi.gamma is not None:
            H[0, 0] += float(np.sum(lmi.gamma * lmi.gamma))
            col = np.zeros(lay.size)
            _lin_adjoint(Lmi(lmi.const, None, lmi.terms), lay, lmi.gamma, col)
            H[0, :] += col
            H[1:, 0] += col[1:]
    return H


def solve_lmis(lmis, n: int, n_vars: int, cost_gamma: float | None, cost_trace,
               options: dict) -> SdpSolution:
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

    def G(u, v, alpha=1.0, beta=0.0, trans="N"):
        un, vn = np.asarray(u)[:, 0], np.asarray(v)[:, 0]
        if trans == "N":  # G x = −(γ Γ + Σ terms): s = h − G x
            gx = np.concatenate([-_lin(lmi, lay, un).ravel(order="F") for lmi in lmis])
        else:
            gx = np.zeros(lay.size)
            for j, lmi in enumerate(lmis):
                _lin_adjoint(lmi, lay, _sym_from_lower(un[offs[j]:offs[j + 1]], lmi.size),
                             gx)
            gx = -gx
        vn *= beta
        vn += alpha * gx

    def kktsolver(W):
        rtis = [np.array(r) for r in W["rti"]]
        scaled = [_scaled(lmi, r) for lmi, r in zip(lmis, rtis)]
        try:
            cf = sla.cho_factor(_schur(scaled, lay), check_finite=False)
        except (np.linalg.LinAlgError, ValueError) as exc:
            raise ArithmeticError(str(exc)) from exc

        def f(x, y, z):
            xn, zn = np.asarray(x)[:, 0], np.asarray(z)[:, 0]
            Bz = [r.T @ _sym_from_lower(zn[offs[j]:offs[j + 1]], lmi.size) @ r
                  for j, (lmi, r) in enumerate(zip(lmis, rtis))]  # W⁻ᵀ bz
            g = np.zeros(lay.size)
            for lmi, B in zip(scaled, Bz):
                _lin_adjoint(lmi, lay, B, g)
            ux = sla.cho_solve(cf, xn - g, check_finite=False)  # H ux = bx + Gᵀ(WᵀW)⁻¹bz
            xn[:] = ux
            for j, (lmi, B) in enumerate(zip(scaled, Bz)):  # W uz = W⁻ᵀ(G ux − bz)
                zn[offs[j]:offs[j + 1]] = (-_lin(lmi, lay, ux) - B).ravel(order="F")
        return f

    opts = {"show_progress": False, **options}
    res = solvers.conelp(cvxopt.matrix(c), G, cvxopt.matrix(h), dims,
                         kktsolver=kktsolver, options=opts)
    status = {"primal infeasible": "infeasible"}.get(res["status"], res["status"])
    x = np.asarray(res["x"])[:, 0] if res["x"] is not None else np.full(lay.size, np.nan)
    X = [lay.unpack(x, v) for v in range(n_vars)]
    return SdpSolution(float(x[0]) if lay.with_gamma else None, X, status,
                       int(res.get("iterations", 0) or 0))
