"""Gridded H∞ LPV synthesis by LMIs, scheduled on one parameter (the spin speed Ω).

Thesis P3 §4 designs an LPV controller with the LMIs of Apkarian & Adams (1998) and a
constant Lyapunov function (stability and performance under arbitrarily fast speed
changes); its conclusion suggests a parameter-dependent Lyapunov function with a bound on
|Ω̇|. Both are here (Wu, Yang, Packard & Becker 1996; Apkarian & Adams 1998 §3):

Generalised plant P(Ω) (inputs [w, u], outputs [z, y], as :func:`ambseal.control.hinfsyn`)
with A(Ω) varying and B, C, D constant (true for the rig: Ω enters through stiffness,
damping and gyroscopic terms only), D22 = 0. Find γ, R = Rᵀ (constant) and
S(Ω) = Σ_i f_i(Ω) S_i (f_0 = 1; ``"constant"``: S_0 only) such that on every grid point Ω_k
and for Ω̇ = ±ν (``rate_bound``)::

    N_Rᵀ [A R + R Aᵀ,  R C1ᵀ,  B1;  C1 R, −γI, D11;  B1ᵀ, D11ᵀ, −γI] N_R ≺ 0
    N_Sᵀ [Aᵀ S + S A ± ν ∂S/∂Ω,  S B1,  C1ᵀ;  B1ᵀ S, −γI, D11ᵀ;  C1, D11, −γI] N_S ≺ 0
    [R, I; I, S] ⪰ 0

with N_R = diag(null[B2ᵀ D12ᵀ], I), N_S = diag(null[C2 D21], I) (the projected, or
elimination, conditions of Gahinet & Apkarian 1994). Keeping R constant makes the controller
independent of Ω̇ (Apkarian & Adams 1998 §3.2).

Controller reconstruction at any Ω: with M = I, N(Ω) = I − S(Ω) R the linearising change of
variables (Scherer, Gahinet & Chilali 1997) turns the closed-loop bounded-real inequality
into an LMI in (Â, B̂, Ĉ) (D_K = 0); its minimum-norm solution at a γ slightly above the
design γ gives B_K = N⁻¹B̂, C_K = Ĉ, A_K = N⁻¹(Â − B̂ C2 R − S B2 Ĉ − S A R). Controllers
are reconstructed on a table five times denser than the design grid, checked there (each
frozen closed loop stable, its H∞ norm reported) and interpolated linearly in between.

Numerics: the plants are balanced with one diagonal state scaling for the whole grid, time
is scaled by ω₀ (norm-preserving), and controls/measurements are normalised, before the
SDPs are solved with Clarabel through cvxpy (imported inside the functions). A solver status
other than ``optimal`` raises :class:`~ambseal.errors.SynthesisError`: badly scaled LMIs
fail silently, and a controller from an inaccurate solution is refused.
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field
from typing import Any, Sequence

import numpy as np
import scipy.linalg as sla

from ..errors import SynthesisError
from ..lti.interconnect import lft_lower_matrices

__all__ = ["LpvController", "LpvSynResult", "lpvsyn", "SolverReport"]

_BASES = {"constant": 1, "affine": 2, "quadratic": 3}
#: Clarabel tolerances: a relative duality gap of 1e-6 (Clarabel's default 1e-8 stalls on
#: these LMIs near 1e-7, and is then reported as "almost solved", i.e. inaccurate).
_DEFAULT_TOL = {"tol_gap_abs": 1e-6, "tol_gap_rel": 1e-6, "tol_feas": 1e-8,
                #: the projected LMIs are dense (the null-space bases mix every entry of
                #: R, S): Clarabel's chordal decomposition only splits them into
                #: overlapping cones and stalls ("almost solved") on the turboexpander
                "chordal_decomposition_enable": False}


# --------------------------------------------------------------------------- results
@dataclass(frozen=True)
class SolverReport:
    """What the SDP solver said.

    Attributes
    ----------
    stage : str
        ``"gamma"`` (minimise γ), ``"centre"`` (re-solve at the backed-off γ for a
        well-conditioned R, S) or ``"reconstruct"`` (all controller reconstructions).
    status : str
        cvxpy status (``"optimal"`` is the only one accepted).
    iterations : int
        Interior-point iterations (summed over reconstructions).
    time_s : float
        Wall time of setup and solve (s).
    solver : str
    """

    stage: str
    status: str
    iterations: int
    time_s: float
    solver: str = "CLARABEL"

    def to_dict(self) -> dict:
        return {"stage": self.stage, "status": self.status, "iterations": self.iterations,
                "time_s": self.time_s, "solver": self.solver}


@dataclass(frozen=True, eq=False)
class LpvController:
    """A controller scheduled on Ω, tabulated and interpolated linearly between entries.

    ``u = K(Ω) y`` in the generalised plant's convention (positive feedback, synthesis
    units); :func:`ambseal.control.lpv_design.design_lpv` wraps it in physical units.

    Attributes
    ----------
    speeds_rad_s : ndarray, shape (n_t,)
        Table speeds Ω (rad/s), where the controller was reconstructed exactly.
    AK, BK, CK, DK : ndarray, shapes (n_t, n_K, n_K), (n_t, n_K, ny), (n_t, nu, n_K), (n_t, nu, ny)
    input_names, output_names : tuple of str
    """

    speeds_rad_s: np.ndarray
    AK: np.ndarray = field(repr=False)
    BK: np.ndarray = field(repr=False)
    CK: np.ndarray = field(repr=False)
    DK: np.ndarray = field(repr=False)
    input_names: tuple[str, ...] = ()
    output_names: tuple[str, ...] = ()

    @property
    def order(self) -> int:
        return self.AK.shape[1]

    def matrices(self, speed_rad_s: float) -> tuple[np.ndarray, ...]:
        """(A_K, B_K, C_K, D_K) at Ω (rad/s), linear between table speeds, held at the ends."""
        from ..model.seal import interp_table

        return tuple(interp_table(float(speed_rad_s), self.speeds_rad_s, X)
                     for X in (self.AK, self.BK, self.CK, self.DK))

    def at(self, speed_rad_s: float, *, scale_output: float = 1.0, name: str = "K_lpv"):
        """The frozen controller at Ω (rad/s) as a named ``control.StateSpace``.

        ``scale_output`` multiplies C_K and D_K (e.g. −D_u/D_e for the physical AMB
        controller of :meth:`ambseal.control.plant.GeneralizedPlant.physical_controller`).
        """
        import control

        A, B, C, D = self.matrices(speed_rad_s)
        return control.ss(A, B, scale_output * C, scale_output * D,
                          inputs=list(self.input_names), outputs=list(self.output_names),
                          states=[f"xK{i}" for i in range(A.shape[0])], name=name)

    def at_hz(self, speed_hz: float, **kw):
        """:meth:`at` with the speed in Hz."""
        return self.at(2 * np.pi * speed_hz, **kw)


@dataclass(frozen=True, eq=False)
class LpvSynResult:
    """Result of :func:`lpvsyn`.

    Attributes
    ----------
    K : LpvController
        The scheduled controller (table on the check grid).
    gamma : float
        Optimal γ of the LMIs (upper bound of the L2 gain of the LPV closed loop for all
        speed trajectories in the grid range with |Ω̇| ≤ ν; ν = ∞ for ``"constant"``).
    gamma_design : float
        Backed-off γ at which R, S and the controllers were computed.
    lyapunov : str
        ``"constant"``, ``"affine"`` or ``"quadratic"`` S(Ω).
    rate_bound : float or None
        ν (rad/s²).
    grid_rad_s : ndarray
        Design grid.
    check_rad_s : ndarray
        Check grid (= controller table).
    check_gamma : ndarray
        H∞ norm of each frozen closed loop on the check grid (inf if unstable).
    check_stable : bool
        Every frozen closed loop on the check grid (and at the table midpoints, with the
        interpolated controller) is stable.
    reports : tuple of SolverReport
    time_s : float
        Total wall time (s).
    """

    K: LpvController
    gamma: float
    gamma_design: float
    lyapunov: str
    rate_bound: float | None
    grid_rad_s: np.ndarray = field(repr=False)
    check_rad_s: np.ndarray = field(repr=False)
    check_gamma: np.ndarray = field(repr=False)
    check_stable: bool = False
    reports: tuple = ()
    time_s: float = 0.0

    @property
    def iterations(self) -> int:
        """Interior-point iterations of the γ stage."""
        return self.reports[0].iterations if self.reports else 0

    def to_dict(self) -> dict:
        return {"gamma": self.gamma, "gamma_design": self.gamma_design,
                "lyapunov": self.lyapunov, "rate_bound_rad_s2": self.rate_bound,
                "grid_hz": (self.grid_rad_s / (2 * np.pi)).tolist(),
                "check_hz": (self.check_rad_s / (2 * np.pi)).tolist(),
                "check_gamma": [float(g) if np.isfinite(g) else None for g in self.check_gamma],
                "check_gamma_max": float(np.max(self.check_gamma)),
                "check_stable": self.check_stable, "controller_order": self.K.order,
                "reports": [r.to_dict() for r in self.reports], "time_s": self.time_s}


# --------------------------------------------------------------------------- helpers
def _null(M: np.ndarray, tol: float = 1e-10) -> np.ndarray:
    """Orthonormal basis of the null space of M (columns)."""
    u, s, vh = np.linalg.svd(M)
    rank = int(np.sum(s > tol * max(s[0] if s.size else 0.0, 1.0)))
    return vh[rank:].T.conj()


def _sym(X):
    return 0.5 * (X + X.T)


def _basis(kind: str, p: float) -> tuple[np.ndarray, np.ndarray]:
    """Basis values f_i(p) and derivatives df_i/dp for p ∈ [−1, 1]."""
    nb = _BASES[kind]
    f = np.array([p**i for i in range(nb)], float)
    df = np.array([i * p ** (i - 1) if i else 0.0 for i in range(nb)], float)
    return f, df


def _check_status(prob, stage: str, t0: float) -> SolverReport:
    status = str(prob.status)
    stats = prob.solver_stats
    it = int(getattr(stats, "num_iters", 0) or 0)
    rep = SolverReport(stage, status, it, time.perf_counter() - t0)
    if status in ("infeasible", "infeasible_inaccurate"):
        raise SynthesisError(
            f"lpvsyn ({stage}): the LMIs are infeasible (solver status {status!r}): no "
            "controller with this Lyapunov structure exists for the plant and weights; relax "
            "the weights, the rate bound or the grid range")
    if status != "optimal":
        raise SynthesisError(
            f"lpvsyn ({stage}): solver status {status!r} after {it} iterations — the solution "
            "is not accurate enough to build a controller from; check the scaling of the "
            "plant and weights or raise the iteration limit")
    return rep


def _solve(prob, stage: str, solver_options: dict):

    t0 = time.perf_counter()
    _solve_quiet(prob, stage, dict(solver_options))
    return _check_status(prob, stage, t0)


@dataclass(frozen=True)
class _Scaled:
    A: np.ndarray  # (n_p, N, N)
    dA: np.ndarray  # (n_p, N, N), per unit p
    B: np.ndarray
    C: np.ndarray
    D: np.ndarray
    T: np.ndarray  # x = T x̃ (after the time scale)
    su: np.ndarray
    sy: np.ndarray
    w0: float
    p_of: Any  # Ω (rad/s) → p ∈ [−1, 1]
    dp_dW: float
    sigma: np.ndarray  # balanced Riccati values (1 for diagonal scaling)

    def to_scaled_A(self, A: np.ndarray) -> np.ndarray:
        """A frozen physical A(Ω) in the scaled coordinates of the LMIs."""
        return np.linalg.solve(self.T, A @ self.T) / self.w0


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


def _scale(As, dAs, B, C, D, grid, nw, nz, ncon, nmeas, scaling: str = "riccati") -> _Scaled:
    """State, time and signal scaling for the whole grid (norm-preserving for w → z).

    1. one diagonal state scaling balancing the envelope of |A(Ω_k)| against B and C;
    2. the time scale t' = ω₀ t with ω₀ the geometric mean of the pole magnitudes;
    3. ``scaling="riccati"``: the LQG-balancing similarity of the centre grid plant
       (:func:`_riccati_balance`), which makes R and S of the order of its Σ (skipped, Σ
       reported as NaN, when the centre plant has no stabilising Riccati solution — then
       the LMIs are infeasible anyway and the solver says so);
    4. controls and measurements to unit-norm columns/rows of [B2; D12] and [C2, D21].
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
    return _Scaled(As_s, dAs_s, Bs, Cs, Ds, T, su, sy, w0,
                   lambda W: (np.asarray(W, float) - mid) / half, 1.0 / half, sig)


def _lmi_blocks(sc: _Scaled, nw, nz, ncon, nmeas):
    B1, B2 = sc.B[:, :nw], sc.B[:, nw:]
    C1, C2 = sc.C[:nz], sc.C[nz:]
    D11, D12, D21 = sc.D[:nz, :nw], sc.D[:nz, nw:], sc.D[nz:, :nw]
    return B1, B2, C1, C2, D11, D12, D21


# --------------------------------------------------------------------------- synthesis
def lpvsyn(plants: Sequence[Any], speeds_rad_s, nmeas: int, ncon: int, *,
           dA: Sequence[np.ndarray] | None = None, lyapunov: str = "constant",
           rate_bound: float | None = None, backoff: float = 1.05,
           check_density: int = 5, solver_options: dict | None = None,
           margin: float = 1e-6, scaling: str = "riccati", penalty: float = 1e-4,
           coupling_ratio: float = 1.1, centre: bool = False) -> LpvSynResult:
    """Gridded H∞ LPV controller (Apkarian & Adams 1998; Wu et al. 1996; thesis P3 §4).

    Stages, each an SDP solved by Clarabel and each required to end ``optimal``:

    1. ``"gamma"``: minimise γ + penalty·(tr R + mean_k tr S(Ω_k))/N subject to the
       projected LMIs and [R, αI; αI, S(Ω_k)] ⪰ 0 with α = ``coupling_ratio`` > 1, i.e.
       S R ⪰ α² I: I − S R then has its eigenvalues at distance ≥ α² − 1 from 0 and the
       controller reconstruction is well conditioned, at a slightly higher γ (still a valid
       upper bound). The small trace term keeps the SDP bounded near the optimum, where R
       or S would otherwise grow without limit (a hard cap on R, S sits on the cap and
       stalls the interior point).
    2. ``"centre"`` (only with ``centre=True``): stage 1 with α = 1, then at
       γ_d = backoff·γ minimise tr R + mean_k tr S(Ω_k) with α = ``coupling_ratio``
       (lowered towards 1 if infeasible). Gives the least conservative γ, but on the
       turboexpander with a dynamic W_u this second SDP ends "almost solved" (refused).
    3. ``"reconstruct"``: the controller on the 5× denser table.

    Parameters
    ----------
    plants : sequence of control.StateSpace, length n_p
        Frozen generalised plants P(Ω_k), inputs ``[w, u]``, outputs ``[z, y]``, one state
        basis; only A may differ between them; D22 = 0.
    speeds_rad_s : array_like, shape (n_p,)
        The grid Ω_k (rad/s), strictly increasing, n_p ≥ 2.
    nmeas, ncon : int
        Measurements (last outputs) and controls (last inputs).
    dA : sequence of ndarray (n_p, N, N), optional
        dA/dΩ at the grid points (1/s per rad/s); needed for a rate bound with a
        parameter-dependent S. Default: finite differences of the grid.
    lyapunov : {"constant", "affine", "quadratic"}
        S(Ω) = S_0 (thesis P3), S_0 + p S_1, or S_0 + p S_1 + p² S_2 with
        p = (Ω − Ω_mid)/Ω_half ∈ [−1, 1]. R is always constant.
    rate_bound : float, optional
        ν ≥ |Ω̇| (rad/s²); required for, and only allowed with, a parameter-dependent S.
    backoff : float
        R, S and controllers are computed at ``backoff·γ`` (≥ 1).
    check_density : int
        The controller table (and check grid) has ``check_density·(n_p − 1) + 1`` speeds.
    solver_options : dict, optional
        Passed to Clarabel (e.g. ``{"max_iter": 200}``); defaults: relative gap 1e-6,
        feasibility 1e-8.
    margin : float
        Strictness margin of the LMIs (scaled units).
    scaling : {"riccati", "diagonal"}
        State scaling before the SDPs: ``"riccati"`` (default) balances the H2 Riccati
        solutions of the centre plant (:func:`_riccati_balance`) after a diagonal balancing
        and the time scale; ``"diagonal"`` stops after the diagonal balancing.
    penalty : float
        Weight of the trace term in stage 1 (scaled units; ≥ 0).
    coupling_ratio : float
        α of the coupling LMI (> 1).
    centre : bool
        Two-stage γ / centring instead of one stage with α in it.

    Returns
    -------
    LpvSynResult

    Raises
    ------
    SynthesisError
        One grid point, a grid not increasing, plants that differ in B, C or D, D22 ≠ 0,
        an unknown ``lyapunov``, a rate bound with ``"constant"`` (or none with a
        parameter-dependent S), infeasible LMIs, a solver status other than ``optimal``,
        or a reconstructed frozen closed loop that is unstable.

    Examples
    --------
    >>> import control as ct, numpy as np
    >>> P = [ct.ss([[a]], [[0., 1.]], [[0.], [1.]], [[0., 1.], [1., 0.]]) for a in (1., 2.)]
    >>> r = lpvsyn(P, [1.0, 2.0], 1, 1)
    >>> 2.0 <= r.gamma < 4.5 and r.check_stable
    True
    """
    import cvxpy as cp

    t_start = time.perf_counter()
    grid = np.asarray(speeds_rad_s, float).ravel()
    if grid.size < 2 or len(plants) != grid.size:
        raise SynthesisError(f"lpvsyn: the speed grid needs at least 2 points with one plant "
                             f"each; got {grid.size} speeds and {len(plants)} plants")
    if np.any(np.diff(grid) <= 0) or not np.all(np.isfinite(grid)):
        raise SynthesisError("lpvsyn: speeds_rad_s must be finite and strictly increasing")
    if lyapunov not in _BASES:
        raise SynthesisError(f"lpvsyn: lyapunov={lyapunov!r}; expected one of {sorted(_BASES)}")
    if lyapunov == "constant" and rate_bound is not None:
        raise SynthesisError(
            "lpvsyn: a rate bound needs a parameter-dependent Lyapunov function "
            "(lyapunov='affine' or 'quadratic'); a constant one already allows arbitrarily "
            "fast speed changes")
    if lyapunov != "constant" and (rate_bound is None or not np.isfinite(rate_bound)
                                   or rate_bound < 0):
        raise SynthesisError(f"lpvsyn: lyapunov={lyapunov!r} needs a finite rate_bound ≥ 0 "
                             f"(rad/s²), got {rate_bound!r}")
    if backoff < 1.0:
        raise SynthesisError(f"lpvsyn: backoff={backoff} must be ≥ 1")
    As = np.array([np.asarray(P.A, float) for P in plants])
    B = np.asarray(plants[0].B, float)
    C = np.asarray(plants[0].C, float)
    D = np.asarray(plants[0].D, float)
    for k, P in enumerate(plants[1:], 1):
        for nm, X, Y in (("B", B, P.B), ("C", C, P.C), ("D", D, P.D)):
            if np.shape(Y) != X.shape or not np.allclose(np.asarray(Y, float), X,
                                                         rtol=1e-9, atol=1e-12 * max(1.0, np.abs(X).max())):
                raise SynthesisError(f"lpvsyn: plant {k} differs from plant 0 in {nm}; only A "
                                     "may depend on the speed (one state basis)")
    N = As.shape[1]
    nw, nz = B.shape[1] - ncon, C.shape[0] - nmeas
    if nw <= 0 or nz <= 0 or ncon <= 0 or nmeas <= 0:
        raise SynthesisError(f"lpvsyn: bad channel counts (nw={nw}, nz={nz}, ncon={ncon}, "
                             f"nmeas={nmeas})")
    if np.any(D[nz:, nw:] != 0):
        raise SynthesisError("lpvsyn: D22 must be zero")
    if dA is None:
        dAs = np.gradient(As, grid, axis=0)
    else:
        dAs = np.array([np.asarray(X, float) for X in dA])
        if dAs.shape != As.shape:
            raise SynthesisError(f"lpvsyn: dA has shape {dAs.shape}, expected {As.shape}")
    if not coupling_ratio > 1.0:
        raise SynthesisError(f"lpvsyn: coupling_ratio={coupling_ratio} must be > 1")
    if not penalty >= 0.0:
        raise SynthesisError(f"lpvsyn: penalty={penalty} must be ≥ 0")
    sc = _scale(As, dAs, B, C, D, grid, nw, nz, ncon, nmeas, scaling)
    B1, B2, C1, C2, D11, D12, D21 = _lmi_blocks(sc, nw, nz, ncon, nmeas)
    NR = sla.block_diag(_null(np.hstack([B2.T, D12.T])), np.eye(nw))
    NS = sla.block_diag(_null(np.hstack([C2, D21])), np.eye(nz))
    nb = _BASES[lyapunov]
    nu_s = 0.0 if rate_bound is None else float(rate_bound) / sc.w0 * sc.dp_dW  # dp/dt'
    ps = sc.p_of(grid)
    solver_options = {**_DEFAULT_TOL, **(solver_options or {})}
    I_N = np.eye(N)

    def build(gamma_fixed: float | None, alpha: float):
        R = cp.Variable((N, N), symmetric=True)
        Ss = [cp.Variable((N, N), symmetric=True) for _ in range(nb)]
        g = cp.Variable(nonneg=True) if gamma_fixed is None else gamma_fixed
        cons, trS = [], 0
        eps = margin
        for k in range(grid.size):
            A = sc.A[k]
            f, df = _basis(lyapunov, float(ps[k]))
            S = sum(fi * Si for fi, Si in zip(f, Ss))
            dS = sum(dfi * Si for dfi, Si in zip(df, Ss)) if nb > 1 else None
            MR = cp.bmat([[A @ R + R @ A.T, R @ C1.T, B1],
                          [C1 @ R, -g * np.eye(nz), D11],
                          [B1.T, D11.T, -g * np.eye(nw)]])
            cons.append(_sym_expr(NR.T @ MR @ NR) << -eps * np.eye(NR.shape[1]))
            signs = (1.0, -1.0) if (dS is not None and nu_s > 0) else (0.0,)
            for sgn in signs:
                top = A.T @ S + S @ A + (sgn * nu_s * dS if sgn else 0)
                MS = cp.bmat([[top, S @ B1, C1.T],
                              [B1.T @ S, -g * np.eye(nw), D11.T],
                              [C1, D11, -g * np.eye(nz)]])
                cons.append(_sym_expr(NS.T @ MS @ NS) << -eps * np.eye(NS.shape[1]))
            if nb > 1 or k == 0:  # one coupling LMI suffices for a constant S
                cons.append(_sym_expr(cp.bmat([[R, alpha * I_N], [alpha * I_N, S]])) >> 0)
                trS = trS + cp.trace(S) / (grid.size if nb > 1 else 1)
        return R, Ss, g, cons, cp.trace(R) + trS

    reports = []
    R, Ss, g, cons, tr = build(None, float(coupling_ratio) if not centre else 1.0)
    prob = cp.Problem(cp.Minimize(g + penalty * tr / N), cons)
    reports.append(_solve(prob, "gamma", solver_options))
    gamma = float(g.value)
    gamma_d = backoff * gamma
    if centre:
        # stage 2: centre R, S at the backed-off γ with S R ⪰ α² I
        alpha, last = float(coupling_ratio), None
        for _ in range(4):
            R, Ss, _, cons, tr = build(gamma_d, alpha)
            prob = cp.Problem(cp.Minimize(tr / N), cons)
            try:
                rep = _solve(prob, "centre", solver_options)
                break
            except SynthesisError as exc:
                last = exc
                alpha = 1.0 + 0.5 * (alpha - 1.0)
        else:
            raise last
        reports.append(rep)
    Rv = _sym(np.asarray(R.value))
    Sv = [_sym(np.asarray(S.value)) for S in Ss]

    # controller table on the check grid
    dens = max(int(check_density), 1)
    table = np.concatenate([np.linspace(grid[j], grid[j + 1], dens + 1)[:-1]
                            for j in range(grid.size - 1)] + [grid[-1:]])
    Aint = _interp_A(As, dAs, grid)
    AKs, BKs, CKs, DKs = [], [], [], []
    it_sum, t_rec, status = 0, time.perf_counter(), "optimal"
    rec = _Reconstructor(B1, B2, C1, C2, D11, D12, D21, Rv, gamma_d * 1.02, margin,
                         2 if (nb > 1 and nu_s > 0) else 1, solver_options)
    for W in table:
        A_s = sc.to_scaled_A(Aint(W))
        p = float(sc.p_of(W))
        f, df = _basis(lyapunov, p)
        S = sum(fi * Si for fi, Si in zip(f, Sv))
        dS = sum(dfi * Si for dfi, Si in zip(df, Sv)) if nb > 1 else None
        Ak, Bk, Ck, it = rec(A_s, S, dS, nu_s)
        it_sum += it
        # undo the scalings: ũ = K̃ ỹ with u = su ũ, ỹ = sy y; time scale ω₀
        AKs.append(sc.w0 * Ak)
        BKs.append(np.sqrt(sc.w0) * Bk * sc.sy[None, :])
        CKs.append(np.sqrt(sc.w0) * sc.su[:, None] * Ck)
        DKs.append(np.zeros((ncon, nmeas)))
    reports.append(SolverReport("reconstruct", status, it_sum, time.perf_counter() - t_rec))
    in_names = tuple(list(getattr(plants[0], "output_labels", []))[nz:]) or \
        tuple(f"y{i}" for i in range(nmeas))
    out_names = tuple(list(getattr(plants[0], "input_labels", []))[nw:]) or \
        tuple(f"u{i}" for i in range(ncon))
    K = LpvController(table, np.array(AKs), np.array(BKs), np.array(CKs), np.array(DKs),
                      in_names, out_names)
    # check: frozen closed loops on the table and at its midpoints (interpolated K)
    from .hinf import hinfnorm

    check_g = []
    stable = True
    for W in table:
        Acl, Bcl, Ccl, Dcl = lft_lower_matrices((Aint(W), B, C, D), K.matrices(W), C.shape[0] - nz, B.shape[1] - nw)
        if np.max(np.linalg.eigvals(Acl).real) >= 0:
            check_g.append(np.inf)
            stable = False
            continue
        import control as ct

        check_g.append(hinfnorm(ct.ss(Acl, Bcl, Ccl, Dcl))[0])
    mids = 0.5 * (table[1:] + table[:-1])
    for W in mids:
        Acl = lft_lower_matrices((Aint(W), B, C, D), K.matrices(W), C.shape[0] - nz, B.shape[1] - nw)[0]
        stable &= bool(np.max(np.linalg.eigvals(Acl).real) < 0)
    if not stable:
        raise SynthesisError(
            "lpvsyn: a reconstructed frozen closed loop on the check grid is unstable; "
            "refine the design grid")
    return LpvSynResult(K=K, gamma=gamma, gamma_design=gamma_d, lyapunov=lyapunov,
                        rate_bound=None if rate_bound is None else float(rate_bound),
                        grid_rad_s=grid, check_rad_s=table, check_gamma=np.array(check_g),
                        check_stable=stable, reports=tuple(reports),
                        time_s=time.perf_counter() - t_start)


def _sym_expr(X):
    return 0.5 * (X + X.T)


def _interp_A(As, dAs, grid):
    """A(Ω) between grid points: cubic Hermite with the given slopes (exact for affine A)."""
    def f(W: float) -> np.ndarray:
        j = int(np.clip(np.searchsorted(grid, W) - 1, 0, len(grid) - 2))
        h = grid[j + 1] - grid[j]
        t = (W - grid[j]) / h
        if t <= 1e-12:
            return As[j]
        if t >= 1 - 1e-12:
            return As[j + 1]
        h00, h10 = 2 * t**3 - 3 * t**2 + 1, t**3 - 2 * t**2 + t
        h01, h11 = -2 * t**3 + 3 * t**2, t**3 - t**2
        lin = (1 - t) * As[j] + t * As[j + 1]
        herm = h00 * As[j] + h10 * h * dAs[j] + h01 * As[j + 1] + h11 * h * dAs[j + 1]
        # piecewise-linear tables make the Hermite overshoot at kinks: use it only when the
        # end slopes agree with the chord (smooth data), else the linear interpolant
        chord = (As[j + 1] - As[j]) / h
        ok = (np.linalg.norm(dAs[j] - chord) + np.linalg.norm(dAs[j + 1] - chord)
              <= 1e-6 * max(np.linalg.norm(chord), 1e-300))
        return herm if ok else lin
    return f


class _Reconstructor:
    """Controller at one speed from R, S(Ω) (Scherer, Gahinet & Chilali 1997; D_K = 0,
    M = I, N = I − S R), with Â eliminated in closed form.

    The linearised closed-loop bounded-real LMI in (Â, B̂, Ĉ) has rows [x_R; x_S; w; z];
    Â enters only its (x_S, x_R) block, as Â + Aᵀ. With the rows split as 1 = x_R,
    2 = x_S, 3 = (w, z), choosing ``Â + Aᵀ = P23 P33⁻¹ P13ᵀ`` makes the Schur complement
    with respect to P33 ≺ 0 block diagonal, so the LMI holds iff the two small LMIs in
    rows {1, 3} (Ĉ: a state-feedback H∞ LMI with R fixed) and rows {2, 3} (B̂: the
    filter LMI with S(Ω) fixed, for Ṡ = ±ν ∂S/∂Ω) hold — the feasibility of which is what
    the projected LMIs guarantee (Gahinet & Apkarian 1994, elimination lemma). Two SDPs of
    size N + n_w + n_z with N·n_u and N·n_y unknowns replace one of size 2N + n_w + n_z
    with N² more unknowns; and since the w row of the first and the z row of the second
    are constant, their Schur complements (−γI ≺ 0) are taken in closed form, leaving
    exactly equivalent LMIs of size N + n_z and N + n_w (a PSD cone of 406 instead of 666
    entries on the turboexpander: ~3× faster interior-point steps).

    Each minimises the Frobenius norm of its unknown (moderate controller gains) as a
    second-order cone, ‖·‖_F, not as its square: with a dynamic (high-pass) W_u the scaled
    D12 is small (≈ 0.01 of B2, whose weight-state rows carry the control) and the
    minimum-norm Ĉ is ~1e5, so ‖Ĉ‖²_F ~ 1e10 — Clarabel then stops with a false
    "infeasible" certificate although the LMI is feasible (the elimination lemma guarantees
    it; with ‖Ĉ‖_F as objective the same LMI solves "optimal", same minimiser).

    The two SDPs are built once, with the speed-dependent data (A R + R Aᵀ, S A + Aᵀ S
    ± ν ∂S/∂Ω, S B1) as cvxpy parameters entering affinely (DPP): each table speed then
    only re-solves, without re-compiling (the compilation was ~¾ of the reconstruction).
    """

    def __init__(self, B1, B2, C1, C2, D11, D12, D21, R, gamma, margin, n_signs,
                 solver_options):
        import cvxpy as cp

        N = B1.shape[0]
        nw, nz = B1.shape[1], C1.shape[0]
        nu, ny = B2.shape[1], C2.shape[0]
        self.B1, self.B2, self.C1, self.C2 = B1, B2, C1, C2
        self.D11, self.D12, self.D21, self.R = D11, D12, D21, R
        self.n_signs, self.solver_options = n_signs, solver_options
        self.P33 = np.block([[-gamma * np.eye(nw), D11.T], [D11, -gamma * np.eye(nz)]])
        # Ĉ: rows {x_R, w, z}
        self.AR = cp.Parameter((N, N), symmetric=True)
        self.Ch = cp.Variable((nu, N))
        CR = C1 @ R + D12 @ self.Ch
        g = float(gamma)
        # the w row is free of Ĉ: its Schur complement (−γI ≺ 0) is taken in closed form
        M1 = cp.bmat([[self.AR + B2 @ self.Ch + self.Ch.T @ B2.T + B1 @ B1.T / g,
                       CR.T + B1 @ D11.T / g],
                      [CR + D11 @ B1.T / g, -g * np.eye(nz) + D11 @ D11.T / g]])
        self.p1 = cp.Problem(cp.Minimize(cp.norm(self.Ch, "fro")),
                             [_sym_expr(M1) << -margin * np.eye(M1.shape[0])])
        # B̂: rows {x_S, w, z}, for Ṡ = ±ν ∂S/∂Ω
        self.S22 = [cp.Parameter((N, N), symmetric=True) for _ in range(n_signs)]
        self.SB1 = cp.Parameter((N, nw))
        self.Bh = cp.Variable((N, ny))
        SB = self.SB1 + self.Bh @ D21
        cons = []
        for P in self.S22:  # the z row is free of B̂: Schur complement in closed form
            M2 = cp.bmat([[P + self.Bh @ C2 + C2.T @ self.Bh.T + C1.T @ C1 / g,
                           SB + C1.T @ D11 / g],
                          [SB.T + D11.T @ C1 / g, -g * np.eye(nw) + D11.T @ D11 / g]])
            cons.append(_sym_expr(M2) << -margin * np.eye(M2.shape[0]))
        self.p2 = cp.Problem(cp.Minimize(cp.norm(self.Bh, "fro")), cons)

    def __call__(self, A, S, dS, nu_s):
        """(A_K, B_K, C_K, interior-point iterations) at one speed (scaled units)."""
        R, B1, B2, C1, C2, D12, D21 = (self.R, self.B1, self.B2, self.C1, self.C2,
                                       self.D12, self.D21)
        N = A.shape[0]
        its = 0
        self.AR.value = _sym(A @ R + R @ A.T)
        t0 = time.perf_counter()
        _solve_quiet(self.p1, "reconstruct", self.solver_options)
        its += _check_status(self.p1, "reconstruct", t0).iterations
        base = S @ A + A.T @ S
        sgns = (1.0, -1.0) if self.n_signs == 2 else (0.0,)
        for P, sgn in zip(self.S22, sgns):
            P.value = _sym(base + (sgn * nu_s * dS if sgn else 0.0))
        self.SB1.value = S @ B1
        t0 = time.perf_counter()
        _solve_quiet(self.p2, "reconstruct", self.solver_options)
        its += _check_status(self.p2, "reconstruct", t0).iterations
        Chv, Bhv = np.asarray(self.Ch.value), np.asarray(self.Bh.value)
        P13 = np.hstack([B1, (C1 @ R + D12 @ Chv).T])
        P23 = np.hstack([S @ B1 + Bhv @ D21, C1.T])
        Ahv = -A.T + P23 @ np.linalg.solve(self.P33, P13.T)
        Nm = np.eye(N) - S @ R
        if np.linalg.cond(Nm) > 1e12:
            raise SynthesisError("lpvsyn (reconstruct): I − S R is singular; raise the "
                                 "back-off")
        BK = np.linalg.solve(Nm, Bhv)
        CK = Chv
        AK = np.linalg.solve(Nm, Ahv - Bhv @ C2 @ R - S @ B2 @ Chv - S @ A @ R)
        return AK, BK, CK, its


def _solve_quiet(prob, stage: str, solver_options: dict) -> None:
    import warnings

    import cvxpy as cp

    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", UserWarning)  # status is checked by the caller
            prob.solve(solver=cp.CLARABEL, **solver_options)
    except cp.error.SolverError as exc:
        raise SynthesisError(f"lpvsyn ({stage}): Clarabel failed: {exc}") from exc
