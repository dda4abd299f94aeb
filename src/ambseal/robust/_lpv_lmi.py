"""The LMI part of the gridded LPV synthesis (:func:`ambseal.robust.lpv.lpvsyn`).

Scaling of the plant grid (one diagonal state scaling, a time scale ω₀, LQG balancing of the
centre plant, unit-norm controls and measurements) and the SDPs in γ, R and S(θ): the
projected LMIs of Gahinet & Apkarian (1994) on every grid point, with a constant or
parameter-dependent Lyapunov function (Apkarian & Adams 1998; Wu et al. 1996). The
equations are in :mod:`ambseal.robust.lpv`. The SDPs are solved by CVXOPT with a KKT solver
that forms their Schur complement from the LMIs' Kronecker structure
(:mod:`ambseal.robust._lmi_sdp`); a status other than ``optimal`` or ``feasible`` (CVXOPT
stopped short of its tolerances, at its iteration cap or stalled, on a point where every
LMI holds) raises :class:`~ambseal.errors.SynthesisError`. Each solve is reported
(:class:`SolverReport`), those the controller was built from marked ``used``: the status
each stage ended on (:func:`sdp_status`) and, where it is not ``optimal``, in words
(:func:`sdp_shortfall`) — γ is then a bound the LMIs certify, not the optimum, and the
controller is the one where the solver stopped, which another machine's rounding moves.
"""

from __future__ import annotations

import time
from dataclasses import dataclass, replace
from typing import Any

import numpy as np
import scipy.linalg as sla

from ambseal.errors import SynthesisError
from ambseal.robust import _lmi_sdp as _sdp

__all__ = ["LmiInfeasible", "SolverReport", "Scaled", "scale_grid", "lmi_blocks", "solve_lmis",
           "GammaStage", "gamma_stage",
           "basis", "basis_at", "is_constant", "rebalanced", "BASES", "sdp_status",
           "sdp_shortfall", "state_pairing", "PAIRING_RTOL"]

BASES = {"constant": 1, "affine": 2, "quadratic": 3}
#: The largest share of stage 1's cost the trace term may take before its weight is
#: lowered, and how many times it is (:func:`solve_lmis`)
PENALTY_SHARE = 1e-2
PENALTY_STEPS = 3
#: A step of that continuation is kept only while rounding leaves the controller's
#: reconstruction digits: ε ‖S(θ)‖ ‖R(θ)‖ / σ_min(I − S(θ) R(θ)), the relative error with
#: which R and S rounded to double determine the inverse of I − S R that the
#: reconstruction takes, at most this at every grid point. Without it the continuation
#: went on as long as CVXOPT returned "optimal", which depends on its BLAS's rounding: on
#: Wu et al.'s rotation one machine stopped at ‖R‖‖S‖ = 8e10 (γ 12.0), another went on to
#: 7e14 (γ 0.93, a loss of 0.4), whose controller fails the bounded-real lemma.
RECONSTRUCTION_LOSS = 1e-4
#: CVXOPT's options for the γ and centring SDPs (:mod:`ambseal.robust._lmi_sdp`), their
#: own stopping criterion: the relative duality gap (γ, or the centring's trace, to
#: 0.01 %), the relative residuals, and two steps of iterative refinement of each KKT
#: solve. At CVXOPT's defaults (gap 1e-6, residuals 1e-7, one refinement step) these SDPs
#: ended short of their tolerances: the dual residual stalls between 1e-4 and 3e-2 while γ
#: agrees to five digits, and CVXOPT ran to its cap of 100 iterations or a singular KKT
#: system, where each BLAS's rounding stopped it elsewhere: the flywheel example's LPV
#: was built from solves that ended "feasible" (at 10 kHz "NOT SOLVED TO OPTIMALITY"),
#: and its controllers under Haswell and SkylakeX kernels differed by 6.5 % of their gain
#: and in order (24 against 26). With these, each of its γ and centring solves ends
#: "optimal" in 22–45 iterations under both, and the controllers agree to 0.1 %
#: (benchmarks/README.md, "The LPV's SDPs end at their own tolerance"); with one
#: refinement step, or gap and residuals ten times tighter, most still stall; residuals
#: of 1e-4 with one refinement step made CVXOPT report spurious infeasibility
#: certificates, so that tolerance is only a further solve's, whose certificates are not
#: taken (:data:`STALL_RETRIES`).
DEFAULT_TOL = {"abstol": 1e-7, "reltol": 1e-4, "feastol": 1e-5, "refinement": 2}
#: The further solves an SDP gets where it stopped short of its own tolerance
#: (:func:`_solve_sdp`), in order, each replacing those keys of its options; the first
#: that ends ``optimal`` is kept, and none other. The dual residual can pass its minimum
#: within a few percent of ``feastol`` and then stall, where each BLAS kernel set's
#: rounding falls either side:
#:
#: - residuals of 1e-4 with a third refinement step of each KKT solve: a centring solve
#:   that stalled at 1e-5 (71–100 iterations) ends "optimal" in 22 under both kernel
#:   sets, its trace within 1e-5 of the stalled point's; another at 10 kHz under NumPy 2.4
#:   ended "optimal" at 22 iterations under Haswell (dual residual just within 1e-5) and
#:   at the cap under SkylakeX, and ends "optimal" under both at this tolerance;
#: - a third refinement step at the same tolerances, where the looser solve stopped short
#:   too or gave a certificate of infeasibility (which can be spurious, so is not taken
#:   from a further solve): on the flywheel example at 10 kHz under NumPy 2.5 a centring
#:   solve ran 48 iterations under Haswell kernels and to the cap under SkylakeX, ends
#:   "optimal" in 32 under both with it, and got such a certificate at 1e-4.
#:
#: In that order because the looser solve ends "optimal" more often and sooner: on 39
#: measured LPV syntheses (benchmarks/README.md, "The LPV's stalled solves: the looser
#: one first") the third step alone ended 4 of 39 stalled solves "optimal" and ran 35 to
#: a stall or to CVXOPT's cap (1 657 iterations), the looser solve after it 20 of those
#: 35, in 20–35 iterations.
#: A kept solve's LMIs are met to its ``feastol`` of the data's norm, and the frozen loops
#: are checked after the synthesis as always.
STALL_RETRIES = ({"refinement": 3, "feastol": 1e-4}, {"refinement": 3})
SOLVER_KEYS = ("abstol", "reltol", "feastol", "maxiters", "refinement")


class LmiInfeasible(SynthesisError):
    """The SDP solver's certificate that the LMIs have no solution. Unlike a stalled solve it
    does not depend on the state basis the LMIs were written in."""


@dataclass(frozen=True)
class SolverReport:
    """What the SDP solver said.

    Attributes
    ----------
    stage : str
        ``"gamma"`` (minimise γ), ``"centre"`` (re-solve at the backed-off γ for a
        well-conditioned R, S) or ``"reconstruct"`` (all controller reconstructions).
    status : str
        The SDP's status: ``"optimal"``, or ``"feasible"`` where CVXOPT stopped short of
        its tolerances on a point where every LMI holds (:class:`~ambseal.robust._lmi_sdp.
        SdpSolution`); for the reconstruction, ``"optimal"`` or at how many table points θ
        its LMIs hold.
    iterations : int
        Interior-point iterations (0 for the closed-form reconstruction).
    time_s : float
        Wall time of setup and solve (s).
    solver : str
        ``"CVXOPT"`` or ``"closed form"``.
    max_iterations : int or None
        CVXOPT's cap on the iterations (``maxiters``) the solve ran under; None for the
        closed form.
    used : bool
        The controller was built from this solve (False for a solve the synthesis went
        past: a step of the trace weight's continuation it did not keep, the first scaling
        where the rebalanced one was better).
    """

    stage: str
    status: str
    iterations: int
    time_s: float
    solver: str = "CVXOPT"
    max_iterations: int | None = None
    used: bool = True

    @property
    def capped(self) -> bool:
        """The SDP stopped at CVXOPT's iteration cap, not optimal."""
        return (self.status != "optimal" and self.max_iterations is not None
                and self.iterations >= self.max_iterations)

    def to_dict(self) -> dict:
        return {"stage": self.stage, "status": self.status, "iterations": self.iterations,
                "time_s": self.time_s, "solver": self.solver,
                "max_iterations": self.max_iterations, "capped": self.capped,
                "used": self.used}


#: How :func:`sdp_shortfall` names each SDP stage.
_STAGE_WORDS = {"gamma": "the γ stage's SDP", "centre": "the centring SDP"}


def sdp_status(reports) -> dict:
    """The status each SDP stage ended on: that of the solve the controller was built from.

    Parameters
    ----------
    reports : sequence of SolverReport
        The synthesis's reports, in order.

    Returns
    -------
    dict of str to str
        Stage (``"gamma"``, ``"centre"``) → status (``"optimal"``, ``"feasible"``), the
        CVXOPT solves marked ``used``.
    """
    return {r.stage: r.status for r in reports if r.used and r.solver == "CVXOPT"}


def sdp_shortfall(reports) -> str:
    """The SDP stages that ended short of ``optimal``, in words; ``""`` where every one the
    controller was built from is optimal. The words do not say how many iterations it took
    or whether the cap or a stall stopped it (the reports do): those follow the machine's
    rounding, the shortfall not.

    The centring stage's ``"feasible"`` is one too, though a point where its LMIs hold
    certifies γ_d as its optimum would: the controller is where CVXOPT stopped, which
    the rounding moves. At :data:`DEFAULT_TOL` it ends ``optimal`` where it converges.

    Parameters
    ----------
    reports : sequence of SolverReport
        The synthesis's reports.

    Returns
    -------
    str
        E.g. ``"the γ stage's SDP ended “feasible”, not optimal (CVXOPT stopped short of
        its tolerances)"``; stages joined by ``" and "``.
    """
    parts = [f"{_STAGE_WORDS.get(r.stage, r.stage)} ended “{r.status}”, not optimal (CVXOPT "
             "stopped short of its tolerances)"
             for r in reports if r.used and r.solver == "CVXOPT" and r.status != "optimal"]
    return " and ".join(parts)


def _null(M: np.ndarray, tol: float = 1e-10) -> np.ndarray:
    """Orthonormal basis of the null space of M (columns)."""
    u, s, vh = np.linalg.svd(M)
    rank = int(np.sum(s > tol * max(s[0] if s.size else 0.0, 1.0)))
    return vh[rank:].T.conj()


def _sym(X):
    return 0.5 * (X + X.T)


def basis(kind: str, p: float) -> tuple[np.ndarray, np.ndarray]:
    """Basis values f_i(p) and derivatives df_i/dp of a built-in basis, p ∈ [−1, 1].

    ``"affine"``: the two hat functions (1 − p)/2 and (1 + p)/2, so S₀ and S₁ are the
    Lyapunov matrices at the range's ends, S(p) = (1 − p)/2 S₀ + (1 + p)/2 S₁ — the same
    family as S₀ + p S₁, but an LMI at one end holds only that end's matrix. With the
    monomials every LMI held both, and Clarabel's factorisation of the SDP's KKT system
    joined the fronts of all of them (:func:`solve_lmis`). ``"quadratic"``: 1, p, p².
    """
    nb = BASES[kind]
    if kind == "affine":
        return np.array([(1.0 - p) / 2, (1.0 + p) / 2]), np.array([-0.5, 0.5])
    f = np.array([p**i for i in range(nb)], float)
    df = np.array([i * p ** (i - 1) if i else 0.0 for i in range(nb)], float)
    return f, df


def is_constant(kind) -> bool:
    """Whether a Lyapunov basis (a name of :data:`BASES` or a user's callable) is the
    constant one."""
    return isinstance(kind, str) and kind == "constant"


def basis_at(kind, theta: float, sc: Scaled) -> tuple[np.ndarray, np.ndarray]:
    """Basis values f_i and derivatives df_i/dp at θ (θ's unit), p the scaled parameter.

    ``kind`` is a name of :data:`BASES` (functions of p) or a user's callable
    θ ↦ (f(θ), df/dθ(θ)) (:func:`ambseal.robust.lpv.lpvsyn`), whose derivatives are
    converted to p by dθ/dp.
    """
    if callable(kind):
        f, df = kind(float(theta))
        return np.asarray(f, float).ravel(), np.asarray(df, float).ravel() / sc.dp_dtheta
    return basis(kind, float(sc.p_of(theta)))


def _convex_in_p(kind) -> bool:
    """Whether the basis is affine in p: an LMI affine in the basis that holds at the
    range's ends then holds between them."""
    return isinstance(kind, str) and kind in ("constant", "affine")


@dataclass(frozen=True)
class Scaled:
    A: np.ndarray  # (n_p, N, N)
    dA: np.ndarray  # (n_p, N, N), per unit p
    B: np.ndarray
    C: np.ndarray
    D: np.ndarray
    T: np.ndarray  # x = T x̃ (after the time scale)
    su: np.ndarray
    sy: np.ndarray
    w0: float
    p_of: Any  # θ (its own unit) → p ∈ [−1, 1]
    dp_dtheta: float
    sigma: np.ndarray  # balanced Riccati values (1 for diagonal scaling)
    #: the inputs' and outputs' maps (T_u, T_y) of a rotation symmetry, in these
    #: coordinates, and the states' pairing that goes with them here (:func:`state_pairing`)
    rotation: Any = None
    pairing: Any = None

    def to_scaled_A(self, A: np.ndarray) -> np.ndarray:
        """A frozen physical A(θ) in the scaled coordinates of the LMIs."""
        return np.linalg.solve(self.T, A @ self.T) / self.w0


#: A rotation's pairing of the scaled states is used where it commutes with every grid
#: plant (A, its slope, B, C, D) to this fraction of each matrix's norm: the SDPs' own
#: relative gap (:data:`DEFAULT_TOL`), below which the invariant optimum cannot be told
#: from the whole problem's. Measured on rotation-symmetric plants: 2e-7 to 2e-5,
#: the LQG balancing's Riccati solutions' rounding (benchmarks/README.md, "The LPV's
#: LMIs keep a rotation symmetry").
PAIRING_RTOL = 1e-4


def state_pairing(sc: "Scaled") -> "_sdp.StatePairing | None":
    """The states' pairing of a rotation symmetry in ``sc``'s coordinates, or None.

    In LQG-balanced coordinates (:func:`_riccati_balance`) an orthogonal symmetry T
    commutes with Σ, so where the balanced values come in equal pairs, in order, it maps
    each pair's two states onto each other with a sign (the 2 × 2 orthogonal blocks with
    T² = −I are ±[[0, −1], [1, 0]] in any basis of the pair). The signs are read from B's
    rows (T B = B T_u); the pairing is kept where it commutes with the whole grid to
    :data:`PAIRING_RTOL` (module _lmi_sdp: the SDPs are then solved on the invariant R
    and S), else None: no rotation given, an odd order, a plant not symmetric, the
    diagonal scaling's coordinates.
    """
    if sc.rotation is None:
        return None
    Tu, Ty = sc.rotation
    n = sc.A.shape[1]
    if n % 2 or n == 0:
        return None
    first, second = np.arange(0, n, 2), np.arange(1, n, 2)
    BT = sc.B @ Tu
    # (T B)_j = s B_i and (T B)_i = −s B_j for the pair (i, j)
    fit = [np.linalg.norm(sc.B[first] - BT[second], axis=1)
           + np.linalg.norm(sc.B[second] + BT[first], axis=1),
           np.linalg.norm(sc.B[first] + BT[second], axis=1)
           + np.linalg.norm(sc.B[second] - BT[first], axis=1)]
    sign = np.where(fit[0] <= fit[1], 1.0, -1.0)
    pair = _sdp.StatePairing(first, second, sign)
    T = pair.matrix(n)

    def off(a, b) -> bool:
        return bool(np.linalg.norm(a - b) > PAIRING_RTOL * max(np.linalg.norm(a),
                                                               np.linalg.norm(b)))

    if any(off(T @ A, A @ T) for A in (*sc.A, *sc.dA)) or off(T @ sc.B, BT) \
            or off(sc.C @ T, Ty @ sc.C) or off(sc.D @ Tu, Ty @ sc.D):
        return None
    return pair


def _riccati_balance(A, B1, B2, C1, C2, D12, D21) -> tuple[np.ndarray, np.ndarray]:
    """Similarity T balancing the H2 (LQG) Riccati solutions of one frozen plant.

    X (control, from (A, B2) with cost C1, D12) and Y (filter, from (A, C2) with noise B1,
    D21) are the limits of the H∞ Riccati solutions X∞, Y∞ for γ → ∞; the LMI variables
    S and R behave like γX∞ and γY∞. With T from the balancing of the pair (Jonckheere &
    Silverman 1983 "LQG balancing"), TᵀXT = T⁻¹YT⁻ᵀ = Σ, both LMI variables are of the
    order of Σ in the new coordinates, so neither a slow weight pole (large X) nor the fast
    actuator states (large Y) dominate the conditioning of the SDP.
    """
    n = A.shape[0]
    X = sla.solve_continuous_are(A, B2, C1.T @ C1, D12.T @ D12, s=C1.T @ D12)
    Y = sla.solve_continuous_are(A.T, C2.T, B1 @ B1.T, D21 @ D21.T, s=B1 @ D21.T)
    X, Y = _sym(X), _sym(Y)

    def chol(M):
        reg = 1e-12 * max(np.trace(M) / n, 1e-300)
        w, V = np.linalg.eigh(M)
        return V * np.sqrt(np.maximum(w, reg))[None, :]

    Lx, Ly = chol(X), chol(Y)
    U, sig, Vt = np.linalg.svd(Lx.T @ Ly)
    T = Ly @ Vt.T / np.sqrt(sig)[None, :]
    return T, sig


def scale_grid(As, dAs, B, C, D, grid, nw, nz, ncon, nmeas, scaling: str = "riccati",
               rotation=None) -> Scaled:
    """State, time and signal scaling for the whole grid (norm-preserving for w → z).

    1. one diagonal state scaling balancing the envelope of |A(θ_k)| against B and C;
    2. the time scale t' = ω₀ t with ω₀ the geometric mean of the pole magnitudes;
    3. ``scaling="riccati"``: the LQG-balancing similarity of the centre grid plant
       (:func:`_riccati_balance`), which makes R and S of the order of its Σ (skipped, Σ
       reported as NaN, when the centre plant has no stabilising Riccati solution — then
       the LMIs are infeasible anyway and the solver says so);
    4. controls and measurements to unit-norm columns/rows of [B2; D12] and [C2, D21].

    ``rotation``: (T_u, T_y), orthogonal maps of the inputs and outputs under which the
    plant is invariant with some map of its states (a quarter turn), or None; the
    states' pairing it implies in the scaled coordinates is looked for (:func:`state_pairing`).
    """
    n = As.shape[1]
    env = np.max(np.abs(As), axis=0)
    Mbal = np.zeros((n + 1, n + 1))
    Mbal[:n, :n] = env
    Mbal[:n, n] = np.abs(B).sum(1)
    Mbal[n, :n] = np.abs(C).sum(0)
    _, (t, _) = sla.matrix_balance(Mbal, permute=False, separate=True)
    t = t[:n] / t[n]
    lam = np.concatenate([np.abs(np.linalg.eigvals(A)) for A in As])
    lam = lam[lam > 1e-9 * max(lam.max(), 1.0)]
    w0 = float(np.sqrt(lam.min() * lam.max())) if lam.size else 1.0
    T = np.diag(t)
    Ds = D.copy()
    Bs = B / t[:, None] / np.sqrt(w0)
    Cs = C * t[None, :] / np.sqrt(w0)
    cu = np.linalg.norm(np.vstack([Bs[:, nw:], Ds[:nz, nw:]]), axis=0)
    su = 1.0 / np.where(cu > 0, cu, 1.0)
    ry = np.linalg.norm(np.hstack([Cs[nz:], Ds[nz:, :nw]]), axis=1)
    sy = 1.0 / np.where(ry > 0, ry, 1.0)
    Bs[:, nw:] *= su
    Ds[:, nw:] *= su
    Cs[nz:] *= sy[:, None]
    Ds[nz:] *= sy[:, None]
    sig = np.ones(n)
    if scaling == "riccati":
        kc = len(As) // 2
        Ac = As[kc] * (1.0 / t)[:, None] * t[None, :] / w0
        try:
            Tr, sig = _riccati_balance(Ac, Bs[:, :nw], Bs[:, nw:], Cs[:nz], Cs[nz:],
                                       Ds[:nz, nw:], Ds[nz:, :nw])
            ok = bool(np.all(np.isfinite(Tr)) and np.linalg.cond(Tr) < 1e12)
        except (np.linalg.LinAlgError, ValueError):
            ok = False  # not stabilisable/detectable there: the SDP will tell (infeasible)
        if ok:
            T = T @ Tr
            Bs = np.linalg.solve(Tr, Bs)
            Cs = Cs @ Tr
        else:
            sig = np.full(n, np.nan)
    elif scaling != "diagonal":
        raise SynthesisError(f"lpvsyn: scaling={scaling!r}; expected 'riccati' or 'diagonal'")
    Tinv = np.linalg.inv(T)
    As_s = np.einsum("ij,kjl,lm->kim", Tinv, As, T) / w0
    half = 0.5 * (grid[-1] - grid[0])
    mid = 0.5 * (grid[-1] + grid[0])
    dAs_s = np.einsum("ij,kjl,lm->kim", Tinv, dAs, T) / w0 * half  # per unit p
    rot = None
    if rotation is not None:  # in the scaled signals: u_s = u/su, y_s = sy·y
        fu, fy = np.concatenate([np.ones(nw), su]), np.concatenate([np.ones(nz), sy])
        rot = ((1.0 / fu)[:, None] * np.asarray(rotation[0], float) * fu[None, :],
               fy[:, None] * np.asarray(rotation[1], float) / fy[None, :])
    sc = Scaled(As_s, dAs_s, Bs, Cs, Ds, T, su, sy, w0,
                lambda th: (np.asarray(th, float) - mid) / half, 1.0 / half, sig, rot)
    return replace(sc, pairing=state_pairing(sc))


def rebalanced(sc: Scaled, R: list, S: list, grid: np.ndarray, lyapunov,
               lyapunov_r) -> Scaled:
    """``sc`` in the diagonal state scaling that equalises the diagonals of a solution's R
    and S: x̃ = D⁻¹x with d_i = (r_i/s_i)^¼, r and s the diagonals of R(θ_k) and S(θ_k)
    averaged over the grid, so that R̃ = D⁻¹RD⁻¹ and S̃ = DSD have the diagonal √(r s).

    Where R must be large in some directions (the range of B2 under a cheap control
    weight) and S small in them, the trace term pays for r + s; in the new coordinates
    for 2√(r s), and the SDP's γ is no longer held up by it (:func:`solve_lmis`).
    """
    def diag_mean(X, kind):
        return np.mean([np.diag(sum(f * Xi for f, Xi in zip(basis_at(kind, th, sc)[0], X)))
                        for th in grid], axis=0)

    r, s = diag_mean(R, lyapunov_r), diag_mean(S, lyapunov)
    d = (np.maximum(r, 1e-300) / np.maximum(s, 1e-300)) ** 0.25
    d = d / np.exp(np.mean(np.log(d)))  # the overall size is the time scale's business
    out = replace(sc, A=sc.A * d[None, None, :] / d[None, :, None],
                  dA=sc.dA * d[None, None, :] / d[None, :, None], B=sc.B / d[:, None],
                  C=sc.C * d[None, :], T=sc.T * d[None, :])
    return replace(out, pairing=state_pairing(out))


def lmi_blocks(sc: Scaled, nw, nz, ncon, nmeas):
    B1, B2 = sc.B[:, :nw], sc.B[:, nw:]
    C1, C2 = sc.C[:nz], sc.C[nz:]
    D11, D12, D21 = sc.D[:nz, :nw], sc.D[:nz, nw:], sc.D[nz:, :nw]
    return B1, B2, C1, C2, D11, D12, D21


def _affine_in_p(As: np.ndarray, ps: np.ndarray, rtol: float = 1e-9) -> bool:
    """Whether every A(p_k) of the grid lies on the line through the two ends' (to
    ``rtol`` of the largest entry)."""
    lo, hi = As[0], As[-1]
    line = [(1 - p) / 2 * lo + (1 + p) / 2 * hi for p in ps]
    scale = max(float(np.max(np.abs(As))), 1e-300)
    return bool(np.max(np.abs(As - np.array(line))) <= rtol * scale)


def solve_lmis(sc: Scaled, blocks, grid: np.ndarray, lyapunov, nu_s: float, *,
               centre: bool, **kw):
    """The SDP stages of :func:`ambseal.robust.lpv.lpvsyn` on the scaled grid: the γ
    stage (:func:`gamma_stage`, whose parameters ``kw`` are) and, with ``centre``, its
    centring.

    Returns
    -------
    gamma, gamma_design, R, S, reports, penalty_share
        As :class:`GammaStage`, R and S the centred ones with ``centre``, the centring's
        report appended.

    Raises
    ------
    SynthesisError
        As :func:`gamma_stage` and :attr:`GammaStage.centre`.
    """
    st = gamma_stage(sc, blocks, grid, lyapunov, nu_s, centre=centre, **kw).centred()
    return st.gamma, st.gamma_d, st.R, st.S, st.reports, st.share


@dataclass(frozen=True)
class GammaStage:
    """Stage 1 of :func:`solve_lmis` (minimise γ), and its centring to be run.

    Attributes
    ----------
    gamma : float
        Optimal γ.
    gamma_d : float
        ``backoff·γ``.
    R, S : list of ndarray, shape (N, N)
        The γ stage's coefficients of R(θ) and S(θ).
    reports : list of SolverReport
        Every γ solve, those the result was not built from ``used=False``.
    share : float
        The trace term's share of the cost at its last solve (relative to γ).
    centre : callable or None
        ``centre() -> (R, S, reports)``: stage 2, R and S centred at γ_d with
        S R ⪰ α² I, and its report; raises :class:`~ambseal.errors.SynthesisError` where
        it is infeasible at every α it tries or its solve fails. Run only where its
        outcome is needed (:func:`ambseal.robust.lpv.lpvsyn`). None for a γ stage
        solved without a centring to follow.
    """

    gamma: float
    gamma_d: float
    R: list
    S: list
    reports: list
    share: float
    centre: Any

    def centred(self) -> "GammaStage":
        """This stage with its centring run: R and S the centred ones, the centring's
        reports appended, no centring left; itself where it has none. Raises
        :class:`~ambseal.errors.SynthesisError` as :attr:`centre`."""
        if self.centre is None:
            return self
        R, S, more = self.centre()
        return replace(self, R=R, S=S, reports=self.reports + more, centre=None)


def gamma_stage(sc: Scaled, blocks, grid: np.ndarray, lyapunov, nu_s: float, *,
                backoff: float, margin: float, penalty: float, coupling_ratio: float,
                centre: bool, solver_options: dict, lyapunov_r="constant") -> GammaStage:
    """Stage 1 of :func:`solve_lmis`: γ minimised with the trace term's continuation.

    Parameters
    ----------
    sc : Scaled
        The scaled plant grid (:func:`scale_grid`).
    blocks : tuple of ndarray
        ``(B1, B2, C1, C2, D11, D12, D21)`` of the scaled plant (:func:`lmi_blocks`).
    grid : ndarray, shape (n_p,)
        The grid θ_k (θ's unit), strictly increasing.
    lyapunov, lyapunov_r : str or callable
        The bases of S(θ) and R(θ) (:func:`basis_at`).
    nu_s : float
        Rate bound in scaled units (dp/dt'), 0 without one.
    backoff, margin, penalty, coupling_ratio, centre
        As in :func:`ambseal.robust.lpv.lpvsyn`: with ``centre`` the γ stage's coupling
        LMI is [[R, I], [I, S]] ⪰ 0 and ``coupling_ratio`` the α of its centring
        (:attr:`GammaStage.centre`), without it α is the γ stage's.
    solver_options : dict
        CVXOPT options, complete (:data:`DEFAULT_TOL` and the user's).

    Returns
    -------
    GammaStage
        R_j, S_i the coefficients of R(θ) = Σ g_j(θ) R_j and S(θ) = Σ f_i(θ) S_i.

    Raises
    ------
    SynthesisError
        Infeasible LMIs or a solver status other than ``optimal`` or ``feasible``.
    """

    B1, B2, C1, C2, D11, D12, D21 = blocks
    N, nw, nz = B1.shape[0], B1.shape[1], C1.shape[0]
    NR = sla.block_diag(_null(np.hstack([B2.T, D12.T])), np.eye(nw))
    NS = sla.block_diag(_null(np.hstack([C2, D21])), np.eye(nz))
    at = [(basis_at(lyapunov_r, th, sc), basis_at(lyapunov, th, sc)) for th in grid]
    nbR, nbS = at[0][0][0].size, at[0][1][0].size
    r_const, s_const = is_constant(lyapunov_r), is_constant(lyapunov)
    # LMIs affine in p that hold at both ends of the range hold between them (a convex
    # combination): the coupling LMI of affine R and S always, the R-LMI of a constant R
    # when A(p) is affine over the grid (a parameter entering through an LFT channel, or
    # linearly in A). Inner grid points keep the S-LMIs (R-LMIs) of a parameter-dependent
    # S (R), which are quadratic in p (A(p)ᵀS(p)); with a constant S and an affine A(p)
    # they go too.
    a_affine = _affine_in_p(sc.A, sc.p_of(grid))
    coupling_convex = _convex_in_p(lyapunov) and _convex_in_p(lyapunov_r)
    Z = np.zeros
    # rows [x; z; w] of the R-LMI and [x; w; z] of the S-LMI; the variable X enters as
    # J X Uᵀ + U X Jᵀ (module _lmi_sdp), negated as s = −εI − (…) ⪰ 0; variables
    # R_0 … R_{nbR−1}, S_0 … S_{nbS−1}
    JR = NR.T @ np.vstack([np.eye(N), Z((nz + nw, N))])
    JS = NS.T @ np.vstack([np.eye(N), Z((nw + nz, N))])
    cR = NR.T @ np.block([[Z((N, N)), Z((N, nz)), B1], [Z((nz, N)), Z((nz, nz)), D11],
                          [B1.T, D11.T, Z((nw, nw))]]) @ NR
    cS = NS.T @ np.block([[Z((N, N)), Z((N, nw)), C1.T], [Z((nw, N)), Z((nw, nw)), D11.T],
                          [C1, D11, Z((nz, nz))]]) @ NS
    gR = NR.T @ sla.block_diag(Z((N, N)), np.eye(nz + nw)) @ NR
    gS = NS.T @ sla.block_diag(Z((N, N)), np.eye(nw + nz)) @ NS
    E1 = np.vstack([np.eye(N), Z((N, N))])
    E2 = np.vstack([Z((N, N)), np.eye(N)])

    def projected(J, U, f, df, first, const, skip):
        """The projected LMI at one grid point for each sign of θ̇ (±ν; the derivative
        term ±ν Σ df_i X_i enters as ν df_i J X_i Jᵀ, both signs required)."""
        if skip:
            return []
        signs = (1.0, -1.0) if (not const and nu_s > 0) else (0.0,)
        return [[_sdp.LmiTerm(first + i, J, -(f[i] * U + 0.5 * sgn * nu_s * df[i] * J))
                 for i in range(f.size) if f[i] != 0 or (sgn and df[i] != 0)]
                for sgn in signs]

    def build(gamma_fixed: float | None, alpha: float):
        lmis = []

        def add(const, gam, terms, strict=0.0):
            if gamma_fixed is not None and gam is not None:
                const, gam = const + gamma_fixed * gam, None
            lmis.append(_sdp.Lmi(const, gam, tuple(terms), strict))

        for k in range(grid.size):
            A = sc.A[k]
            inner = 0 < k < grid.size - 1
            (fR, dfR), (fS, dfS) = at[k]
            UR = NR.T @ np.vstack([A, C1, Z((nw, N))])
            for terms in projected(JR, UR, fR, dfR, 0, r_const, r_const and inner and a_affine):
                add(-margin * np.eye(JR.shape[0]) - cR, gR, terms, margin)
            US = NS.T @ np.vstack([A.T, B1.T, Z((nz, N))])
            for terms in projected(JS, US, fS, dfS, nbR, s_const,
                                   s_const and inner and a_affine):
                add(-margin * np.eye(JS.shape[0]) - cS, gS, terms, margin)
            if k == 0 or not (r_const and s_const) and not (coupling_convex and inner):
                terms = [_sdp.LmiTerm(j, E1, 0.5 * fR[j] * E1) for j in range(nbR) if fR[j]]
                terms += [_sdp.LmiTerm(nbR + i, E2, 0.5 * fS[i] * E2) for i in range(nbS)
                          if fS[i]]
                add(alpha * np.block([[Z((N, N)), np.eye(N)], [np.eye(N), Z((N, N))]]),
                    None, terms)
        # the trace term: tr R(θ) + tr S(θ) averaged over the grid
        mean = np.mean([np.concatenate([fR, fS]) for (fR, _), (fS, _) in at], axis=0)
        return lmis, mean / N

    reports = []
    n_vars = nbR + nbS
    lmis, tr = build(None, float(coupling_ratio) if not centre else 1.0)
    sol = _solve_sdp(lmis, N, n_vars, 1.0, penalty * tr, solver_options, "gamma", reports,
                     sc.pairing)
    kept = len(reports) - 1  # the γ solve the controller is built from
    # The trace term keeps R and S bounded, but where they must grow large it also buys a
    # smaller trace with a larger γ: while its share of the cost exceeds PENALTY_SHARE the
    # weight is lowered to half that share and the SDP solved again (at most
    # PENALTY_STEPS times; a solve that fails, stops short of optimal (its solution is
    # where CVXOPT stopped, which the machine's rounding moves; the optimum it left is
    # not), does not lower γ or leaves R and S too large for the controller's
    # reconstruction, RECONSTRUCTION_LOSS, ends the continuation).
    def share_of(sol, weight):
        return weight * float(tr @ [np.trace(X) for X in sol.X]) / max(float(sol.gamma),
                                                                       1e-300)

    weight = penalty
    share = share_of(sol, weight)
    for _ in range(PENALTY_STEPS):
        if share <= PENALTY_SHARE:
            break
        lower_weight = weight * 0.5 * PENALTY_SHARE / share  # aim inside the bound
        try:
            lower = _solve_sdp(lmis, N, n_vars, 1.0, lower_weight * tr, solver_options,
                               "gamma", reports, sc.pairing)
        except SynthesisError:
            break
        if lower.status != "optimal" or not float(lower.gamma) < float(sol.gamma) or \
                _reconstruction_loss(lower.X[:nbR], lower.X[nbR:], at) > RECONSTRUCTION_LOSS:
            break
        sol, weight, kept = lower, lower_weight, len(reports) - 1
        share = share_of(sol, weight)
    reports[:] = [r if r.stage != "gamma" or k == kept else replace(r, used=False)
                  for k, r in enumerate(reports)]
    gamma = float(sol.gamma)
    gamma_d = backoff * gamma

    def centring():
        # stage 2: centre R, S at the backed-off γ with S R ⪰ α² I
        alpha, last, more = float(coupling_ratio), None, []
        for _ in range(4):
            lmis, tr = build(gamma_d, alpha)
            try:
                centred = _solve_sdp(lmis, N, n_vars, None, tr, solver_options, "centre",
                                     more, sc.pairing)
                break
            except SynthesisError as exc:
                last = exc
                alpha = 1.0 + 0.5 * (alpha - 1.0)
        else:
            raise last
        X = [_sym(X) for X in centred.X]
        return X[:nbR], X[nbR:], more

    X = [_sym(X) for X in sol.X]
    return GammaStage(gamma, gamma_d, X[:nbR], X[nbR:], reports, share,
                      centring if centre else None)


def _reconstruction_loss(R, S, at) -> float:
    """The largest ε ‖S‖ ‖R‖ / σ_min(I − S R) over the grid (:data:`RECONSTRUCTION_LOSS`);
    ``at`` holds each grid point's basis values ``((f_R, df_R), (f_S, df_S))``."""
    eps, worst = np.finfo(float).eps, 0.0
    for (fR, _), (fS, _) in at:
        Rt = _sym(sum(f * X for f, X in zip(fR, R)))
        St = _sym(sum(f * X for f, X in zip(fS, S)))
        smin = np.linalg.svd(np.eye(Rt.shape[0]) - St @ Rt, compute_uv=False)[-1]
        loss = eps * np.linalg.norm(St, 2) * np.linalg.norm(Rt, 2) / smin if smin > 0 \
            else np.inf
        worst = max(worst, float(loss))
    return worst


def _solve_sdp(lmis, N, n_vars, cost_gamma, cost_trace, options, stage, reports,
               pairing=None):
    """One SDP stage by :func:`ambseal.robust._lmi_sdp.solve_lmis` (on the matrices the
    states' ``pairing`` leaves invariant, where given); its report appended.
    Where it stops short of its tolerance, it is solved again under each option set of
    :data:`STALL_RETRIES` that does not tighten ``feastol``, and the first that ends
    ``optimal`` is kept."""
    t0 = time.perf_counter()
    try:
        sol = _sdp.solve_lmis(lmis, N, n_vars, cost_gamma, cost_trace, options, pairing)
    except (ArithmeticError, ValueError) as exc:  # CVXOPT: a singular scaling or KKT system
        raise SynthesisError(
            f"lpvsyn ({stage}): CVXOPT stopped on a singular system ({exc!r}): the LMIs are "
            "badly conditioned; check the scaling of the plant and weights") from exc
    for step in STALL_RETRIES if sol.status in ("feasible", "unknown") else ():
        retry = {**options, **step}
        if retry == options or retry["feastol"] < options.get("feastol", 0.0):
            continue
        try:
            again = _sdp.solve_lmis(lmis, N, n_vars, cost_gamma, cost_trace, retry, pairing)
        except (ArithmeticError, ValueError):
            continue
        if again.status == "optimal":
            sol = again
            break
    rep = SolverReport(stage, sol.status, sol.iterations, time.perf_counter() - t0, "CVXOPT",
                       sol.max_iterations)
    if sol.status == "infeasible":
        raise LmiInfeasible(
            f"lpvsyn ({stage}): the LMIs are infeasible (CVXOPT: primal infeasibility "
            "certificate): no controller with this Lyapunov structure exists for the plant "
            "and weights; relax the weights, the rate bound or the grid range")
    if sol.status not in ("optimal", "feasible"):
        raise SynthesisError(
            f"lpvsyn ({stage}): solver status {sol.status!r} after {sol.iterations} "
            "iterations — the solution is not accurate enough to build a controller from; "
            "check the scaling of the plant and weights")
    reports.append(rep)
    return sol
