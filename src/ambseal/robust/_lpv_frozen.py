"""The best frozen-point design of a gridded LPV problem: the reference and the fallback of
:func:`ambseal.robust.lpv.lpvsyn` (private module).

A parameter-independent controller is an LPV controller too. The H∞ controller designed at
one grid point θ_k (:func:`~ambseal.robust.hinf.hinfsyn`) and closed with the plant at every
θ of the check table gives that design's worst frozen γ; the best of them over the grid
points is the reference no scheduled controller should fall behind (on an LTI family it is
the H∞ optimum itself). Where the LMI synthesis, conservative with its common R and S(θ),
does fall behind, lpvsyn delivers that controller instead, with a γ it can state for every
parameter trajectory: the bounded-real lemma with one Lyapunov matrix X over the whole
table (quadratic performance, Becker & Packard 1994; Apkarian, Gahinet & Becker 1995),
solved by :func:`ambseal.robust._lmi_sdp.solve_lmis`.
"""

from __future__ import annotations

from dataclasses import dataclass

import control as ct
import numpy as np
import scipy.linalg as sla

from ambseal.errors import SynthesisError
from ambseal.lti import lft_lower_matrices
from ambseal.robust._lmi_sdp import Lmi, LmiTerm, solve_lmis
from ambseal.robust.hinf import hinfnorm, hinfsyn
from ambseal.robust.stability import is_stable

__all__ = ["FrozenReference", "frozen_reference", "quadratic_gamma"]


@dataclass(frozen=True)
class FrozenReference:
    """The best frozen-point design: ``theta`` the grid point it was designed at, ``K`` its
    ``(A_K, B_K, C_K, D_K)``, ``check_gamma`` its frozen closed-loop norms on the table
    (``inf`` where unstable) and ``gamma`` their largest value; ``inf`` when no grid
    point's design holds the whole table."""

    theta: float
    K: tuple
    check_gamma: np.ndarray
    gamma: float


def frozen_reference(plants, grid, table, A_of, B, C, D, nmeas: int, ncon: int
                     ) -> FrozenReference:
    """The H∞ design (:func:`hinfsyn`, its defaults) at each grid point, each closed with
    the plants ``(A_of(θ), B, C, D)`` at every θ of ``table``; the one whose worst frozen
    closed-loop norm is the smallest. A grid point whose synthesis fails is skipped."""
    best = None
    for theta, P in zip(grid, plants):
        try:
            r = hinfsyn(P, nmeas, ncon)
        except SynthesisError:
            continue
        K = tuple(np.asarray(getattr(r.K, m), float) for m in ("A", "B", "C", "D"))
        g = np.array([_norm(lft_lower_matrices((A_of(t), B, C, D), K, nmeas, ncon))
                      for t in table])
        if best is None or g.max() < best.gamma:
            best = FrozenReference(float(theta), K, g, float(g.max()))
    if best is None:
        raise SynthesisError("lpvsyn: no grid point has an H∞ controller")
    return best


def _norm(cl) -> float:
    A, B, C, D = cl
    if not is_stable(np.linalg.eigvals(A)):
        return float("inf")
    return float(hinfnorm(ct.ss(A, B, C, D))[0])


def quadratic_gamma(loops, options: dict, level: float = 1.0, margin: float = 1e-7) -> float:
    """Smallest γ with one X ≻ 0 such that every closed loop ``(A, B, C, D)`` of ``loops``
    meets the bounded-real inequality [AᵀX + XA, XB, Cᵀ; BᵀX, −γI, Dᵀ; C, D, −γI] ≺ 0: a
    bound of the L2 gain under any trajectory of the parameter over the table's loops (at
    values between the entries only where the loop matrices are affine in θ, which keeps
    them in the loops' convex hull).

    The loops are scaled first: time by the largest eigenvalue modulus ω₀ (A/ω₀, B and C
    by 1/√ω₀; norm-preserving), the states by one diagonal balancing of Σ|A_i|, and the
    gain by ``level`` (an estimate of the result, e.g. the largest frozen norm), so that the
    SDP's γ is near 1.

    Returns the SDP's γ raised by ``CERTIFY_RTOL``, at which its X is checked by the
    eigenvalues of each inequality (:func:`_certified`).

    Raises
    ------
    SynthesisError
        No X certified: the SDP found none, or its X fails an inequality at that γ.
    """
    loops = [tuple(np.asarray(M, float) for M in L) for L in loops]
    w0 = max(float(np.max(np.abs(np.linalg.eigvals(L[0])))) for L in loops) or 1.0
    _, (sc, _) = sla.matrix_balance(sum(np.abs(L[0]) for L in loops) / w0, permute=False,
                                    separate=True)
    s, g = 1.0 / np.sqrt(w0), 1.0 / np.sqrt(level)
    loops = [((A / sc[:, None]) * sc[None, :] / w0, B / sc[:, None] * (s * g),
              C * sc[None, :] * (s * g), D / level) for A, B, C, D in loops]
    n, nw, nz = loops[0][0].shape[0], loops[0][1].shape[1], loops[0][2].shape[0]
    d = n + nw + nz
    E = np.zeros((d, n))
    E[:n] = np.eye(n)
    gam = np.diag(np.r_[np.zeros(n), np.ones(nw + nz)])
    lmis = []
    for A, B, C, D in loops:
        H = np.zeros((d, d))
        H[n + nw:, :n], H[n + nw:, n:n + nw] = -C, -D
        H = H + H.T - margin * np.eye(d)
        F = np.zeros((d, n))
        F[:n], F[n:n + nw] = A.T, B.T
        lmis.append(Lmi(H, gam, (LmiTerm(0, -E, F),)))
    lmis.append(Lmi(-margin * np.eye(n), None, (LmiTerm(0, 0.5 * np.eye(n), np.eye(n)),)))
    sol = solve_lmis(lmis, n, 1, 1.0, [0.0], options)
    # the certificate decides, not the solver's status: at the optimum X is near singular
    # and CVXOPT may stop short of its tolerances ("unknown") on a γ that holds
    g = None if sol.gamma is None else float(sol.gamma) * (1.0 + CERTIFY_RTOL)
    if g is None or not np.isfinite(g) or not _certified(sol.X[0], g, loops):
        raise SynthesisError(f"lpvsyn: no common Lyapunov matrix for the frozen design's "
                             f"loops (CVXOPT: {sol.status})")
    return g * level


#: The relative back-off of the SDP's γ at which its X is checked (:func:`_certified`).
CERTIFY_RTOL = 1e-5


def _certified(X: np.ndarray, g: float, loops) -> bool:
    """X ≻ 0 and the bounded-real inequality at γ = g strictly negative for every loop,
    by the eigenvalues (the certificate, whatever the solver reported)."""
    if not np.all(np.isfinite(X)) or np.linalg.eigvalsh(X)[0] <= 0:
        return False
    for A, B, C, D in loops:
        nw, nz = B.shape[1], C.shape[0]
        M = np.block([[A.T @ X + X @ A, X @ B, C.T],
                      [B.T @ X, -g * np.eye(nw), D.T],
                      [C, D, -g * np.eye(nz)]])
        if np.linalg.eigvalsh(0.5 * (M + M.T))[-1] >= 0:
            return False
    return True
