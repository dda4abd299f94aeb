"""Gridded H∞ LPV synthesis by LMIs, scheduled on one measured parameter θ.

θ is whatever the plants are gridded on, in its own unit (an angular velocity in rad/s, a
stiffness in N/m, …); nothing here knows which.

Two Lyapunov functions: a constant one (Apkarian & Adams 1998: stability and performance
under arbitrarily fast parameter changes) and a parameter-dependent one with a bound on
|θ̇| (Wu, Yang, Packard & Becker 1996; Apkarian & Adams 1998 §3):

Generalised plant P(θ) (inputs [w, u], outputs [z, y], as :func:`ambseal.robust.hinfsyn`)
with A(θ) varying and B, C, D constant (true where θ enters through stiffness- and
damping-like terms of the state equation only), D22 = 0. Find γ, R(θ) = Σ_j g_j(θ) R_j and
S(θ) = Σ_i f_i(θ) S_i (``"constant"``: R_0 or S_0 only; R is constant by default) such that
on every grid point θ_k and for θ̇ = ±ν (``rate_bound``)::

    N_Rᵀ [A R + R Aᵀ ∓ ν ∂R/∂θ,  R C1ᵀ,  B1;  C1 R, −γI, D11;  B1ᵀ, D11ᵀ, −γI] N_R ≺ 0
    N_Sᵀ [Aᵀ S + S A ± ν ∂S/∂θ,  S B1,  C1ᵀ;  B1ᵀ S, −γI, D11ᵀ;  C1, D11, −γI] N_S ≺ 0
    [R, I; I, S] ⪰ 0

with N_R = diag(null[B2ᵀ D12ᵀ], I), N_S = diag(null[C2 D21], I) (the projected, or
elimination, conditions of Gahinet & Apkarian 1994; Wu et al. 1996 Theorem 4.2 with both
matrices parameter-dependent). Keeping R constant makes the controller independent of θ̇
(Apkarian & Adams 1998 §3.2); with R(θ) it takes θ̇, as Wu et al.'s and LPVTools' do.

Controller reconstruction at any θ: with M = I, N(θ) = I − S(θ) R the linearising change of
variables (Scherer, Gahinet & Chilali 1997) turns the closed-loop bounded-real inequality
into an LMI in (Â, B̂, Ĉ) (D_K = 0); its minimum-norm solution at a γ slightly above the
design γ gives B_K = N⁻¹B̂, C_K = Ĉ, A_K = N⁻¹(Â − B̂ C2 R − S B2 Ĉ − S A R). Controllers
are reconstructed on a table ``check_density`` times denser than the design grid (5; 1 on
a vertex grid with a constant S, where the linear interpolation meets the same γ),
checked there (each frozen closed loop stable, its H∞ norm reported) and interpolated
linearly in between.

Code: validation and orchestration here (:func:`lpvsyn`, ``_validate``, ``_check_table``);
scaling and the SDPs in :mod:`ambseal.robust._lpv_lmi`; the controller reconstruction in
:mod:`ambseal.robust._lpv_reconstruct`.

Numerics: the plants are balanced with one diagonal state scaling for the whole grid, time
is scaled by ω₀ (norm-preserving), and controls/measurements are normalised, before the
SDPs are solved by CVXOPT with a Schur complement formed from the LMIs' Kronecker structure
(:mod:`ambseal.robust._lmi_sdp`). A solver status other than ``optimal`` raises
:class:`~ambseal.errors.SynthesisError` (badly scaled LMIs fail silently, and a controller
from an inaccurate solution is refused), but for ``feasible``: CVXOPT stopped short of its
tolerances, at its iteration cap or stalled, on a point where every LMI holds. γ is then a
bound those LMIs certify, not the optimum, and the controller is the one where the solver
stopped — another machine's rounding stops it elsewhere. So the synthesis keeps a solve
that ended ``optimal`` before one with a lower γ that did not: between the trace term's
continuation steps, the rebalanced scaling and the Riccati or diagonal scaling. Where
none ended optimal the result says so: :attr:`LpvSynResult.sdp_status`, the status each
stage ended on, and :attr:`LpvSynResult.sdp_shortfall` in words.
"""
from __future__ import annotations

import time
from dataclasses import dataclass, field, replace
from typing import Any, NamedTuple, Sequence

import control
import control as ct
import numpy as np

from ambseal.errors import ModelError, SynthesisError
from ambseal.lti import interp_table, json_float, lft_lower_matrices
from ambseal.robust._lpv_lmi import (
    BASES,
    DEFAULT_TOL,
    PENALTY_SHARE,
    GammaStage,
    LmiInfeasible,
    SOLVER_KEYS,
    SolverReport,
    gamma_stage,
    is_constant,
    lmi_blocks,
    rebalanced,
    scale_grid,
    sdp_shortfall,
    sdp_status,
)
from ambseal.robust._lpv_frozen import frozen_reference, quadratic_gamma
from ambseal.robust._lpv_reconstruct import interp_A, reconstruct_table
from ambseal.robust.digital import residualize, split_fast
from ambseal.robust.hinf import hinfnorm
from ambseal.robust.stability import is_stable
from ambseal.threads import with_numerics_threads

__all__ = ["FrozenClosedLoop", "LpvController", "LpvSynResult", "lpvsyn", "SolverReport",
           "sdp_status", "sdp_shortfall"]


@dataclass(frozen=True, eq=False)
class LpvController:
    """A controller scheduled on a parameter θ, tabulated and interpolated linearly between
    entries.

    ``u = K(θ) y`` in the generalised plant's convention (the lower LFT F_l(P, K),
    positive feedback); θ is whatever the plants were gridded on, in its own unit (an
    angular velocity in rad/s, a stiffness in N/m, …). A controller of a
    parameter-dependent R also takes θ̇: A_K(θ, θ̇) = AK(θ) + θ̇·AK_rate(θ).

    Attributes
    ----------
    theta : ndarray, shape (n_t,)
        Table values of θ, where the controller was reconstructed exactly.
    AK, BK, CK, DK : ndarray, shapes (n_t, n_K, n_K), (n_t, n_K, ny), (n_t, nu, n_K), (n_t, nu, ny)
    input_names, output_names : tuple of str
    AK_rate : ndarray, shape (n_t, n_K, n_K), or None
        ∂A_K/∂θ̇ (seconds per unit of θ); None when the controller does not take θ̇.
    """

    theta: np.ndarray
    AK: np.ndarray = field(repr=False)
    BK: np.ndarray = field(repr=False)
    CK: np.ndarray = field(repr=False)
    DK: np.ndarray = field(repr=False)
    input_names: tuple[str, ...] = ()
    output_names: tuple[str, ...] = ()
    AK_rate: np.ndarray | None = field(default=None, repr=False)

    @property
    def order(self) -> int:
        return self.AK.shape[1]

    @property
    def takes_rate(self) -> bool:
        """Whether A_K depends on θ̇ (a parameter-dependent R in :func:`lpvsyn`)."""
        return self.AK_rate is not None and bool(np.any(self.AK_rate))

    def matrices(self, theta: float, theta_dot: float = 0.0) -> tuple[np.ndarray, ...]:
        """(A_K, B_K, C_K, D_K) at θ and θ̇ (θ's unit per second; it enters only where
        :attr:`takes_rate`), linear between table values, held at the ends."""

        A, B, C, D = (interp_table(float(theta), self.theta, X)
                      for X in (self.AK, self.BK, self.CK, self.DK))
        if theta_dot and self.takes_rate:
            A = A + float(theta_dot) * interp_table(float(theta), self.theta, self.AK_rate)
        return A, B, C, D

    def at(self, theta: float, theta_dot: float = 0.0, *, name: str = "K_lpv"):
        """The frozen controller at θ (and θ̇) as a named ``control.StateSpace`` (the
        generalised plant's signals and convention)."""

        A, B, C, D = self.matrices(theta, theta_dot)
        return control.ss(A, B, C, D,
                          inputs=list(self.input_names), outputs=list(self.output_names),
                          states=[f"xK{i}" for i in range(A.shape[0])], name=name)


@dataclass(frozen=True, eq=False)
class FrozenClosedLoop:
    """θ ↦ F_l(P(θ), K(θ)) of an LPV design: the plant's A interpolated between the grid
    plants as :func:`lpvsyn` does (cubic Hermite with the slopes dA/dθ where the data are
    smooth, linear at kinks), the controller interpolated from its table.

    Calling it with θ gives a ``control.StateSpace`` with the plant's ``w`` inputs
    and ``z`` outputs and their names.
    """

    grid: np.ndarray = field(repr=False)
    A: np.ndarray = field(repr=False)
    dA: np.ndarray = field(repr=False)
    B: np.ndarray = field(repr=False)
    C: np.ndarray = field(repr=False)
    D: np.ndarray = field(repr=False)
    K: LpvController = field(repr=False)
    nmeas: int = 0
    ncon: int = 0
    inputs: tuple = ()
    outputs: tuple = ()

    def __call__(self, theta: float):
        th = float(theta)
        A = interp_A(self.A, self.dA, self.grid)(th)
        Acl, Bcl, Ccl, Dcl = lft_lower_matrices((A, self.B, self.C, self.D),
                                                self.K.matrices(th), self.nmeas, self.ncon)
        return ct.ss(Acl, Bcl, Ccl, Dcl, inputs=list(self.inputs) or None,
                     outputs=list(self.outputs) or None, name="CL")


@dataclass(frozen=True, eq=False)
class LpvSynResult:
    """Result of :func:`lpvsyn`.

    Attributes
    ----------
    K : LpvController
        The scheduled controller (table on the check grid).
    gamma : float
        Optimal γ of the LMIs (upper bound of the L2 gain of the LPV closed loop for all
        parameter trajectories in the grid range with |θ̇| ≤ ν; ν = ∞ for ``"constant"``).
    gamma_design : float
        Backed-off γ at which R, S and the controllers were computed.
    lyapunov, lyapunov_r : str or callable
        The bases of S(θ) and R(θ) as given (``"constant"``, ``"affine"``,
        ``"quadratic"`` or a user's callable).
    rate_bound : float or None
        ν (θ's unit per second).
    grid : ndarray
        Design grid.
    check_grid : ndarray
        Check grid (= controller table).
    check_gamma : ndarray
        H∞ norm of each frozen closed loop on the check grid (inf if unstable).
    check_stable : bool
        Every frozen closed loop on the check grid (and at the table midpoints, with the
        interpolated controller) is stable.
    reports : tuple of SolverReport
    time_s : float
        Total wall time (s).
    closed_loop : FrozenClosedLoop
        θ ↦ the frozen closed loop F_l(P(θ), K(θ)) as a named ``control.StateSpace``: the
        LPV closed loop depends on the parameter, so it is a function, not one system.
    scaling : str
        The state scaling the SDPs ran with (``"riccati"`` or ``"diagonal"``).
    frozen_best_gamma : float
        The best frozen-point design's worst γ on the check grid: the H∞ controller of
        one grid point (the one at ``frozen_best_theta``) closed with the plant at every
        check-grid θ (``nan`` when not computed, ``inf`` when none holds the whole grid).
    frozen_best_theta : float
        The grid point of that design.
    kind : str
        ``"lpv"``: the scheduled controller of the LMIs; ``"frozen"``: that design,
        better at every frozen θ and no worse under a varying one, delivered in its place
        as a constant table with ``gamma`` its quadratic-performance bound over the check
        grid.
    penalty_share : float
        The trace term's share of the γ stage's cost at its last solve, relative to γ
        (1 % or less unless the SDP could not be solved with a smaller weight): how much
        of ``gamma`` may be the price of bounded R and S rather than of the plant.
    pole_bound : dict or None
        With ``pole_bound`` given (:func:`lpvsyn`): ``bound_rad_s``, ``above_rad_s`` (the
        moduli of the poles above it, of the table's middle entry as synthesised),
        ``check_gamma`` (the reduced table's frozen H∞ norms, ``None`` where not
        computed), ``reduced`` (whether :attr:`K` is the reduced controller, those poles
        removed) and ``note`` (why not, in words; ``""`` where reduced or no pole was
        above the bound). ``None`` without a bound.

    Notes
    -----
    ``K, CL, gamma, info = lpvsyn(...)`` unpacks as :func:`~ambseal.robust.hinf.hinfsyn`
    does, with ``CL`` the function :attr:`closed_loop` (``CL(θ)``).
    """

    K: LpvController
    gamma: float
    gamma_design: float
    lyapunov: Any
    rate_bound: float | None
    grid: np.ndarray = field(repr=False)
    check_grid: np.ndarray = field(repr=False)
    check_gamma: np.ndarray = field(repr=False)
    check_stable: bool = False
    reports: tuple = ()
    time_s: float = 0.0
    closed_loop: Any = field(default=None, repr=False)
    scaling: str = "riccati"
    frozen_best_gamma: float = float("nan")
    frozen_best_theta: float = float("nan")
    kind: str = "lpv"
    penalty_share: float = 0.0
    lyapunov_r: Any = "constant"
    pole_bound: dict | None = None

    def __iter__(self):
        """``K, CL, gamma, info = lpvsyn(...)``: the scheduled controller, θ ↦ the frozen
        closed loop, γ, and this result for the rest."""
        return iter((self.K, self.closed_loop, self.gamma, self))

    @property
    def iterations(self) -> int:
        """Interior-point iterations of the γ stage (all its solves)."""
        return sum(r.iterations for r in self.reports if r.stage == "gamma")

    @property
    def sdp_status(self) -> dict:
        """The status each SDP stage ended on, ``{"gamma": "optimal", …}``: that of the
        solve the controller was built from (:func:`sdp_status`)."""
        return sdp_status(self.reports)

    @property
    def sdp_shortfall(self) -> str:
        """The stages that ended short of ``optimal`` in words, ``""`` where none did
        (:func:`sdp_shortfall`)."""
        return sdp_shortfall(self.reports)

    def to_dict(self) -> dict:
        return {"gamma": self.gamma, "gamma_design": self.gamma_design,
                "lyapunov": _basis_name(self.lyapunov),
                "lyapunov_r": _basis_name(self.lyapunov_r),
                "controller_takes_rate": self.K.takes_rate,
                "rate_bound_rad_s2": self.rate_bound,
                "grid": self.grid.tolist(), "check_grid": self.check_grid.tolist(),
                "check_gamma": [float(g) if np.isfinite(g) else None for g in self.check_gamma],
                "check_gamma_max": float(np.max(self.check_gamma)),
                "check_stable": self.check_stable, "controller_order": self.K.order,
                "scaling": self.scaling, "kind": self.kind,
                "frozen_best_gamma": json_float(self.frozen_best_gamma),
                "frozen_best_theta": json_float(self.frozen_best_theta),
                "penalty_share": self.penalty_share, "sdp_status": self.sdp_status,
                "pole_bound": self.pole_bound,
                "reports": [r.to_dict() for r in self.reports], "time_s": self.time_s}


# --------------------------------------------------------------------------- synthesis
@with_numerics_threads
def lpvsyn(plants: Sequence[Any], theta, nmeas: int, ncon: int, *,
           dA: Sequence[np.ndarray] | None = None, lyapunov="constant",
           lyapunov_r="constant", rate_bound: float | None = None, backoff: float = 1.05,
           check_density: int = 5, solver_options: dict | None = None,
           margin: float = 1e-6, scaling: str = "auto", penalty: float = 1e-4,
           coupling_ratio: float = 1.1, centre: bool = False,
           frozen_check: bool = True, pole_bound: float | None = None,
           rotation=None) -> LpvSynResult:
    """Gridded H∞ LPV controller (Apkarian & Adams 1998; Wu et al. 1996).

    Stages, the first two SDPs solved by CVXOPT and required to end ``optimal``:

    1. ``"gamma"``: minimise γ + penalty·(tr R + mean_k tr S(θ_k))/N subject to the
       projected LMIs and [R, αI; αI, S(θ_k)] ⪰ 0 with α = ``coupling_ratio`` > 1, i.e.
       S R ⪰ α² I: I − S R then has its eigenvalues at distance ≥ α² − 1 from 0 and the
       controller reconstruction is well conditioned, at a slightly higher γ (still a valid
       upper bound). The small trace term keeps the SDP bounded near the optimum, where R
       or S would otherwise grow without limit (a hard cap on R, S sits on the cap and
       stalls the interior point). Where that term takes more than 1 % of the cost (R, S
       must be large: then it would raise γ), its weight is lowered to half that share and
       the SDP solved again, up to three times while γ falls and the solve ends
       ``optimal`` (``penalty_share`` says where it ended).
    2. ``"centre"`` (only with ``centre=True``): stage 1 with α = 1, then at
       γ_d = backoff·γ minimise tr R + mean_k tr S(θ_k) with α = ``coupling_ratio``
       (lowered towards 1 if infeasible). Gives the least conservative γ. This second
       SDP often ends short of its tolerances, stalled or at CVXOPT's cap, on a point where
       its LMIs hold: that point certifies γ_d all the same and is kept
       (:func:`sdp_shortfall` does not count it); ``design_lpv`` centres by default.
    3. ``"reconstruct"``: the controller on the 5× denser table, in closed form
       (central solutions of the reconstruction LMIs, ``robust/_lpv_reconstruct.py``).

    Parameters
    ----------
    plants : sequence of control.StateSpace, length n_p
        Frozen generalised plants P(θ_k), inputs ``[w, u]``, outputs ``[z, y]``, one state
        basis; only A may differ between them; D22 = 0.
    theta : array_like, shape (n_p,)
        The grid θ_k (θ's unit), strictly increasing, n_p ≥ 2.
    nmeas, ncon : int
        Measurements (last outputs) and controls (last inputs).
    dA : sequence of ndarray (n_p, N, N), optional
        dA/dθ at the grid points (1/s per unit of θ); needed for a rate bound with a
        parameter-dependent S. Default: finite differences of the grid.
    lyapunov : {"constant", "affine", "quadratic"} or callable
        The basis of S(θ): S_0, S_0 + p S_1, or S_0 + p S_1 + p² S_2 with
        p = (θ − θ_mid)/θ_half ∈ [−1, 1]; or a user's basis, a callable
        θ ↦ (f(θ), df/dθ(θ)) returning two arrays of length n_b (e.g.
        ``lambda t: ([1, cos t, sin t], [0, -sin t, cos t])``, LPVTools' ``basis``),
        linearly independent over the grid.
    lyapunov_r : str or callable
        The basis of R(θ), as ``lyapunov`` (default ``"constant"``). A parameter-dependent
        R gives a controller that takes θ̇ (:attr:`LpvController.AK_rate`); with R
        constant it does not.
    rate_bound : float, optional
        ν ≥ |θ̇| (θ's unit per second); required for, and only allowed with, a
        parameter-dependent S or R.
    backoff : float
        R, S and controllers are computed at ``backoff·γ`` (≥ 1).
    check_density : int
        The controller table (and check grid) has ``check_density·(n_p − 1) + 1`` values.
    solver_options : dict, optional
        CVXOPT's ``abstol``, ``reltol``, ``feastol``, ``maxiters``, ``refinement``
        (e.g. ``{"maxiters": 200}``), each replacing its default
        (:data:`ambseal.robust._lpv_lmi.DEFAULT_TOL`: gaps 1e-7 absolute and 1e-4
        relative, residuals 1e-5, two refinement steps, where every SDP stage of the
        examples' LPV designs ends "optimal"; CVXOPT's own cap of 100 iterations).
    margin : float
        Strictness margin of the LMIs (scaled units).
    scaling : {"auto", "riccati", "diagonal"}
        State scaling before the SDPs: ``"riccati"`` balances the H2 Riccati solutions of
        the centre plant (``lpv_lmi._riccati_balance``) after a diagonal balancing and the
        time scale; ``"diagonal"`` stops after the diagonal balancing. ``"auto"``
        (default): ``"riccati"``, and where it fails (the SDP solver stops, or a
        reconstructed loop is unstable: small plants whose balancing is near singular)
        ``"diagonal"``, also where the Riccati scaling's γ stays held up by the trace
        term (``penalty_share`` above its bound) and the diagonal one reaches a lower γ;
        the result says which (``scaling``). When both fail, the error is
        the diagonal scaling's if it is the solver's certificate that the LMIs are
        infeasible (true in any state basis), else the Riccati scaling's. A centring
        SDP whose outcome cannot change the result is not solved (where the diagonal
        scaling ends optimal below every γ the Riccati one may keep, the Riccati
        rebalanced scaling's centring; where no γ stage of the diagonal scaling is below
        an optimal Riccati result's γ, the diagonal scaling's centring and table): the
        controller is the same, and ``reports`` lists the solves that ran.
    penalty : float
        Starting weight of the trace term in stage 1 (scaled units; ≥ 0).
    coupling_ratio : float
        α of the coupling LMI (> 1).
    centre : bool
        Two-stage γ / centring instead of one stage with α in it.
    frozen_check : bool
        Compare with the best frozen-point design (:mod:`ambseal.robust._lpv_frozen`):
        the H∞ controller of each grid point closed with the plant on the whole check grid.
        Where the scheduled controller's worst frozen γ is higher than that design's and
        that design's quadratic-performance γ (one Lyapunov matrix over the check grid,
        a bound under any trajectory of θ) is not above the scheduled one's, the design is
        delivered instead (``kind = "frozen"``). Costs one H∞ synthesis per grid point and
        one norm per grid point and check-grid value (``benchmarks/README.md``).
    pole_bound : float, optional
        The largest controller pole modulus the target can run (rad/s; the design layer
        gives the Nyquist frequency π·f_s). The controller's poles above it are removed by
        singular perturbation (their static gain kept; Skogestad & Postlethwaite Eq.
        11.26) in one state basis over the table (the slow/fast split of its middle
        entry, so that the reduced entries still interpolate), and the reduced table is
        checked as the synthesised one is: every frozen loop on the table and at its
        midpoints stable, and the H∞ norm of each on the table within ``BOUND_RISE``
        (1 %) of the synthesised controller's. Where it passes the reduced controller is
        delivered, else the synthesised one, with the reason
        (:attr:`LpvSynResult.pole_bound`); ``gamma`` remains the synthesised controller's
        LMI bound. Chilali & Gahinet's (1996) pole region would put a disk |λ| ≤ bound on
        the closed loop in the SDP, with the controller's variables in it: N² more
        unknowns at every grid point of an SDP that is already the synthesis's cost.
    rotation : (ndarray, ndarray), optional
        ``(T_u, T_y)``: orthogonal maps of the plants' inputs ``[w, u]`` and outputs
        ``[z, y]`` under which every plant of the grid is invariant with some map of its
        states — a plant symmetric under rotation, turned a quarter turn (each pair of
        signals (a, b) to (−b, a)). Then the SDPs' feasible set and cost are invariant,
        and where the states' pairing it implies holds in the scaled coordinates
        (:func:`ambseal.robust._lpv_lmi.state_pairing`) R and S are sought among the
        invariant matrices: half the unknowns, the same optimum within the SDPs'
        tolerances (``benchmarks/README.md``, "The LPV's LMIs keep a rotation
        symmetry"). None: R and S among all symmetric matrices.

    Returns
    -------
    LpvSynResult
        Unpacks as ``K, CL, gamma, info`` (python-control's ``hinfsyn`` order), ``CL`` the
        frozen closed loop as a function of θ (:class:`FrozenClosedLoop`).

    Raises
    ------
    ModelError
        Bad input, refused before any synthesis (as :func:`hinfsyn` and :func:`musyn`
        refuse theirs): one grid point, a grid not finite or not increasing, plants that
        are not state-space systems, have a NaN or infinite entry, differ in size or in B,
        C or D, D22 ≠ 0, an unknown ``lyapunov``, ``lyapunov_r``, ``scaling`` or key in
        ``solver_options`` (or a basis whose values are not two finite arrays of one length
        or are dependent over the grid or not finite somewhere on the controller's table),
        a rate bound with both constant (or none with a parameter-dependent S or R),
        ``nmeas``, ``ncon`` or ``check_density`` not a whole number ≥ 1, ``margin`` not a
        finite number > 0, ``backoff`` not a finite number ≥ 1, ``coupling_ratio`` not a
        number > 1, ``penalty`` not a number ≥ 0 or ``pole_bound`` not a finite number
        > 0, or a ``rotation`` whose maps are not orthogonal matrices of the plants'
        input and output counts.
    SynthesisError
        Infeasible LMIs, a solver status other than ``optimal``, or a reconstructed frozen
        closed loop that is unstable.

    Examples
    --------
    >>> import control as ct, numpy as np
    >>> P = [ct.ss([[a]], [[0., 1.]], [[0.], [1.]], [[0., 1.], [1., 0.]]) for a in (1., 2.)]
    >>> r = lpvsyn(P, [1.0, 2.0], 1, 1)
    >>> 2.0 <= r.gamma < 4.5 and r.check_stable
    True
    """

    t_start = time.perf_counter()
    grid, As, dAs, B, C, D, nw, nz = _validate(plants, theta, nmeas, ncon, dA,
                                               (lyapunov, lyapunov_r), rate_bound, backoff,
                                               coupling_ratio, penalty, check_density, margin)
    unknown = sorted(set(solver_options or {}) - set(SOLVER_KEYS))
    if unknown:
        raise ModelError(f"lpvsyn: solver_options {unknown} unknown; expected some of "
                             f"{', '.join(SOLVER_KEYS)} (CVXOPT's options)")
    if pole_bound is not None and not (
            isinstance(pole_bound, (int, float, np.integer, np.floating))
            and not isinstance(pole_bound, bool) and np.isfinite(pole_bound)
            and pole_bound > 0):
        raise ModelError(f"lpvsyn: pole_bound={pole_bound!r}; expected a finite number > 0 "
                         "(rad/s)")
    if scaling not in ("auto", "riccati", "diagonal"):
        raise ModelError(f"lpvsyn: scaling={scaling!r}; expected 'auto', 'riccati' or "
                             "'diagonal'")
    if rotation is not None:
        rotation = tuple(np.asarray(T, float) for T in rotation)
        sizes = (B.shape[1], C.shape[0])
        if len(rotation) != 2 or any(
                T.shape != (k, k) or not np.allclose(T.T @ T, np.eye(k), atol=1e-12)
                for T, k in zip(rotation, sizes)):
            raise ModelError(f"lpvsyn: rotation, expected orthogonal maps of the {sizes[0]} "
                             f"inputs and the {sizes[1]} outputs")
    solver_options = {**DEFAULT_TOL, **(solver_options or {})}
    data = (plants, grid, As, dAs, B, C, D, nw, nz, nmeas, ncon)
    settings = dict(lyapunov=lyapunov, lyapunov_r=lyapunov_r, rate_bound=rate_bound,
                    backoff=backoff,
                    check_density=check_density, solver_options=solver_options,
                    margin=margin, penalty=penalty, coupling_ratio=coupling_ratio,
                    centre=centre, rotation=rotation)
    r = (_synthesise(data, scaling, **settings) if scaling != "auto"
         else _either_scaling(data, settings))
    if frozen_check:
        r = _against_frozen(r, data, solver_options, margin)
    if pole_bound is not None:
        r = _within_bound(r, data, float(pole_bound))
    return replace(r, time_s=time.perf_counter() - t_start)


def _either_scaling(data, settings: dict) -> LpvSynResult:
    """``scaling="auto"`` of :func:`lpvsyn`: the Riccati scaling's synthesis, and the
    diagonal scaling's where the Riccati one fails, its γ is held up by the trace term or
    an SDP stopped short of optimal; of the two, an optimal solve is kept before a lower
    γ. Where the diagonal scaling is tried whichever Riccati solve is kept, and its
    optimal γ is below every one's, it is delivered without the Riccati rebalanced
    scaling's centring (:class:`_Scaling`), whose outcome cannot change it. Likewise the
    diagonal scaling's centrings and controller table are made only where one of its γ
    stages lies below the γ it would have to beat: its result's γ is one of them."""
    diagonal: dict = {}

    def diagonal_result(below: float | None = None):
        """The diagonal scaling's result, each part made once; None where it fails, or
        where none of its γ stages is below ``below``."""
        if "solve" not in diagonal:
            try:
                diagonal["solve"] = _Scaling.solve(data, "diagonal", **settings)
            except SynthesisError as exc:
                diagonal["solve"], diagonal["error"] = None, exc
        sc = diagonal["solve"]
        if sc is None or (below is not None and min(sc.reachable_gammas) >= below):
            return None
        if "r" not in diagonal:
            try:
                diagonal["r"] = sc.result()
            except SynthesisError as exc:
                diagonal["r"], diagonal["error"] = None, exc
        return diagonal["r"]

    try:
        riccati = _Scaling.solve(data, "riccati", **settings)
        if riccati.open and riccati.certainly_short_or_held:
            alt = diagonal_result(below=min(riccati.gammas))
            if alt is not None and _optimal(alt) and all(alt.gamma < g
                                                         for g in riccati.gammas):
                return alt
        r = riccati.result()
        if r.penalty_share > PENALTY_SHARE or not _optimal(r):
            alt = diagonal_result(below=r.gamma if _optimal(r) else None)
            if alt is not None and (not _optimal(alt), alt.gamma) < (not _optimal(r),
                                                                      r.gamma):
                r = alt
        return r
    except SynthesisError as first:  # a plant the balancing does not suit
        alt = diagonal_result()
        if alt is not None:
            return alt
        if isinstance(diagonal["error"], LmiInfeasible):  # it holds in every state basis
            raise diagonal["error"] from None
        raise first from None


def _optimal(r: LpvSynResult) -> bool:
    """Whether every SDP stage the controller was built from ended ``optimal``."""
    return not _short(r.reports)


def _short(reports) -> bool:
    """Whether an SDP stage the controller would be built from stopped short of
    ``optimal``: a solution where CVXOPT stopped follows the machine's rounding, an optimum
    does not, so between two solves an optimal one is kept before a lower γ."""
    return any(v != "optimal" for v in sdp_status(reports).values())


#: How much a frozen loop's H∞ norm may rise, at any table entry, when the controller's
#: poles above ``pole_bound`` are removed (:func:`_within_bound`). On the five designs of
#: benchmarks/README.md ("The LPV's poles against the target's Nyquist frequency") no
#: norm rose by more than 3e-4 at any entry.
BOUND_RISE = 1e-2


def _within_bound(r: LpvSynResult, data, bound: float) -> LpvSynResult:
    """``r`` with its controller's poles above ``bound`` (rad/s) removed where the reduced
    table keeps every frozen loop (``pole_bound`` of :func:`lpvsyn`), its record in
    :attr:`LpvSynResult.pole_bound` either way."""
    plants, grid, As, dAs, B, C, D, nw, nz, nmeas, ncon = data
    K = r.K
    V, k, fast = split_fast(K.AK[K.theta.size // 2], bound / (2 * np.pi))
    record = {"bound_rad_s": bound, "above_rad_s": sorted(float(abs(p)) for p in fast),
              "check_gamma": None, "reduced": False, "note": ""}

    def kept(note: str) -> LpvSynResult:
        return replace(r, pole_bound={**record, "note": note})

    if not any(np.abs(np.linalg.eigvals(A)).max(initial=0.0) > bound for A in K.AK):
        return kept("")
    if K.takes_rate:
        return kept("the controller takes θ̇ (a parameter-dependent R), which the "
                    "reduction does not carry")
    if not fast.size:
        return kept("the table's middle entry has no pole above the bound to split off")
    if not k:
        return kept("every pole of the controller is above the bound")
    A22 = [np.linalg.solve(V, A @ V)[k:, k:] for A in K.AK]
    if not all(is_stable(np.linalg.eigvals(X)) for X in A22):
        return kept("the part above the bound is unstable at a table entry")
    table = [residualize((K.AK[j], K.BK[j], K.CK[j], K.DK[j]), V, k)
             for j in range(K.theta.size)]
    if any(np.abs(np.linalg.eigvals(t[0])).max(initial=0.0) > bound for t in table):
        return kept("the reduced controller still has a pole above the bound (the split "
                    "of the middle entry does not hold over the table)")
    Kr = LpvController(K.theta, *(np.array([t[i] for t in table]) for i in range(4)),
                       K.input_names, K.output_names)
    try:
        check_g = _check_table(Kr, interp_A(As, dAs, grid), B, C, D, nmeas, ncon)
    except SynthesisError:
        return kept("the reduced controller loses a frozen loop on the table")
    record["check_gamma"] = [json_float(g) for g in check_g]
    rise = float(np.max(check_g / r.check_gamma)) - 1.0
    if rise > BOUND_RISE:
        return kept(f"removing them raises a frozen loop's H∞ norm by {100 * rise:.3g} % "
                    f"(more than {100 * BOUND_RISE:g} %)")
    return replace(r, K=Kr, check_gamma=check_g, closed_loop=replace(r.closed_loop, K=Kr),
                   pole_bound={**record, "reduced": True})


#: Relative margin by which the best frozen-point design must beat the scheduled
#: controller's worst frozen γ before it is delivered instead.
FROZEN_RTOL = 1e-3


def _against_frozen(r: LpvSynResult, data, solver_options, margin) -> LpvSynResult:
    """``r`` with the best frozen-point design's worst γ recorded, or that design in its
    place where it is better (``frozen_check`` of :func:`lpvsyn`)."""
    plants, grid, As, dAs, B, C, D, nw, nz, nmeas, ncon = data
    A_of = interp_A(As, dAs, grid)
    try:
        ref = frozen_reference(plants, grid, r.check_grid, A_of, B, C, D, nmeas, ncon)
    except SynthesisError:  # no grid point has an H∞ controller: nothing to compare with
        return r
    r = replace(r, frozen_best_gamma=ref.gamma, frozen_best_theta=ref.theta)
    if not ref.gamma < float(np.max(r.check_gamma)) * (1.0 - FROZEN_RTOL):
        return r
    loops = [lft_lower_matrices((A_of(t), B, C, D), ref.K, nmeas, ncon) for t in r.check_grid]
    try:
        g = quadratic_gamma(loops, solver_options, level=ref.gamma, margin=margin)
    except SynthesisError:
        return r  # no bound for every trajectory: the scheduled controller keeps its own
    if g > r.gamma:  # better at every frozen θ, worse for a varying one: a trade, not a gain
        return r
    n_t = r.check_grid.size
    K = LpvController(r.check_grid, *(np.repeat(X[None], n_t, axis=0) for X in ref.K),
                      r.K.input_names, r.K.output_names)
    CL = replace(r.closed_loop, K=K)
    return replace(r, K=K, gamma=g, gamma_design=g, check_gamma=ref.check_gamma,
                   closed_loop=CL, kind="frozen")


def _synthesise(data, scaling: str, **settings) -> LpvSynResult:
    """Stages 1–3 of :func:`lpvsyn` with one state scaling; SynthesisError as there."""
    return _Scaling.solve(data, scaling, **settings).result()


class _Rebalanced(NamedTuple):
    """The rebalanced scaling and its stage 1 (its centring not yet run)."""

    sc: Any
    blocks: tuple
    stage: GammaStage


@dataclass
class _Scaling:
    """One state scaling's synthesis (:func:`_synthesise`) with the rebalanced scaling's
    centring not yet run.

    Stage 1 and its centring in the scaling, then, where the trace term held γ up
    (``penalty_share`` above :data:`PENALTY_SHARE`), stage 1 again in the rebalanced
    scaling (:func:`~ambseal.robust._lpv_lmi.rebalanced`, from the centred R and S). The
    rebalanced solve is kept where (stopped short, γ) is lower than the first's, which
    for its centring's status needs that centring: where it cannot be lower even with
    an optimal centring, the centring is never run (:attr:`open` false), and
    :func:`lpvsyn` runs it only where its outcome can change what is delivered. Which
    solves are run does not change the result: each is one deterministic solve, the
    same whenever it runs.
    """

    data: tuple
    settings: dict
    sc: Any
    blocks: tuple
    nu_s: float
    first: GammaStage  # centred where a centring was asked for
    rebalanced: _Rebalanced | None

    @classmethod
    def solve(cls, data, scaling: str, *, lyapunov, lyapunov_r, rate_bound, backoff,
              check_density, solver_options, margin, penalty, coupling_ratio,
              centre, rotation=None) -> "_Scaling":
        plants, grid, As, dAs, B, C, D, nw, nz, nmeas, ncon = data
        settings = dict(lyapunov=lyapunov, lyapunov_r=lyapunov_r, rate_bound=rate_bound,
                        check_density=check_density, margin=margin)
        sc = scale_grid(As, dAs, B, C, D, grid, nw, nz, ncon, nmeas, scaling, rotation)
        nu_s = 0.0 if rate_bound is None else float(rate_bound) / sc.w0 * sc.dp_dtheta
        lmi_kw = dict(backoff=backoff, margin=margin, penalty=penalty,
                      coupling_ratio=coupling_ratio, centre=centre,
                      solver_options=solver_options, lyapunov_r=lyapunov_r)
        blocks = lmi_blocks(sc, nw, nz, ncon, nmeas)
        first = gamma_stage(sc, blocks, grid, lyapunov, nu_s, **lmi_kw).centred()
        again = None
        if first.share > PENALTY_SHARE:  # γ held up by the trace term: R and S of one size
            sc2 = rebalanced(sc, first.R, first.S, grid, lyapunov, lyapunov_r)
            blocks2 = lmi_blocks(sc2, nw, nz, ncon, nmeas)
            try:
                again = _Rebalanced(sc2, blocks2, gamma_stage(sc2, blocks2, grid, lyapunov,
                                                              nu_s, **lmi_kw))
            except SynthesisError:
                again = None
        return cls(data, {**settings, "scaling": scaling}, sc, blocks, nu_s, first, again)

    def _may_win(self) -> bool:
        """Whether the rebalanced solve is kept with an optimal centring (else it is not
        kept whatever its centring)."""
        st = self.rebalanced.stage
        return (_short(st.reports), st.gamma) < (_short(self.first.reports), self.first.gamma)

    @property
    def open(self) -> bool:
        """Which solve is kept waits on the rebalanced scaling's centring."""
        return (self.rebalanced is not None and self.rebalanced.stage.centre is not None
                and self._may_win())

    @property
    def gammas(self) -> tuple[float, ...]:
        """The γ of each solve that may be kept."""
        return (self.first.gamma,) + ((self.rebalanced.stage.gamma,) if self.open else ())

    @property
    def reachable_gammas(self) -> tuple[float, ...]:
        """The γ of each solve :meth:`result` may keep, whatever its centrings end on:
        its result's γ is one of them."""
        return (self.first.gamma,) + ((self.rebalanced.stage.gamma,)
                                      if self.rebalanced is not None else ())

    @property
    def certainly_short_or_held(self) -> bool:
        """Whether whichever solve is kept has γ held up by the trace term or stopped
        short of optimal (:func:`lpvsyn` then tries the diagonal scaling)."""
        kept = [self.first.share > PENALTY_SHARE or _short(self.first.reports)]
        if self.open:
            st = self.rebalanced.stage
            kept.append(st.share > PENALTY_SHARE or _short(st.reports))
        return all(kept)

    def result(self) -> LpvSynResult:
        """The kept solve's controller table, checked (runs the rebalanced scaling's
        centring where it is needed)."""
        sc, blocks, kept = self.sc, self.blocks, self.first
        reports = kept.reports
        if self.rebalanced is not None and (self.rebalanced.stage.centre is None
                                            or self._may_win()):
            sc2, blocks2, st = self.rebalanced
            try:
                st = st.centred()
            except SynthesisError:
                st = None
            if st is not None and (_short(st.reports), st.gamma) < (_short(reports),
                                                                    kept.gamma):
                sc, blocks, kept = sc2, blocks2, st
                reports = [replace(r, used=False) for r in reports] + st.reports
        return self._table(sc, blocks, kept.gamma, kept.gamma_d, kept.R, kept.S,
                           list(reports), kept.share)

    def _table(self, sc, blocks, gamma, gamma_d, R, S, reports, share) -> LpvSynResult:
        plants, grid, As, dAs, B, C, D, nw, nz, nmeas, ncon = self.data
        st = self.settings
        lyapunov, lyapunov_r, rate_bound = st["lyapunov"], st["lyapunov_r"], st["rate_bound"]
        check_density, scaling, margin = st["check_density"], st["scaling"], st["margin"]
        # controller table on the check grid
        dens = max(int(check_density), 1)
        table = np.concatenate([np.linspace(grid[j], grid[j + 1], dens + 1)[:-1]
                                for j in range(grid.size - 1)] + [grid[-1:]])
        A_of = interp_A(As, dAs, grid)
        AK, AK_rate, BK, CK, DK, rep = reconstruct_table(sc, blocks, table, A_of, R, S,
                                                         lyapunov, self.nu_s,
                                                         gamma_d * 1.02, margin, lyapunov_r)
        reports.append(rep)
        in_names = tuple(list(getattr(plants[0], "output_labels", []))[nz:]) or \
            tuple(f"y{i}" for i in range(nmeas))
        out_names = tuple(list(getattr(plants[0], "input_labels", []))[nw:]) or \
            tuple(f"u{i}" for i in range(ncon))
        K = LpvController(table, AK, BK, CK, DK, in_names, out_names,
                          None if is_constant(lyapunov_r) else AK_rate)
        check_g = _check_table(K, A_of, B, C, D, nmeas, ncon)
        names = (list(getattr(plants[0], "input_labels", []))[:nw],
                 list(getattr(plants[0], "output_labels", []))[:nz])
        CL = FrozenClosedLoop(grid, As, dAs, B, C, D, K, nmeas, ncon, *map(tuple, names))
        return LpvSynResult(K=K, gamma=gamma, gamma_design=gamma_d, lyapunov=lyapunov,
                            lyapunov_r=lyapunov_r,
                            rate_bound=None if rate_bound is None else float(rate_bound),
                            grid=grid, check_grid=table, check_gamma=check_g,
                            check_stable=True, reports=tuple(reports), closed_loop=CL,
                            scaling=scaling, penalty_share=share)


def _basis_name(kind) -> str:
    """A Lyapunov basis for JSON: its name, or a user's callable's."""
    return kind if isinstance(kind, str) else f"user: {getattr(kind, '__name__', 'basis')}"


def _validate(plants, theta, nmeas, ncon, dA, bases, rate_bound, backoff,
              coupling_ratio, penalty, check_density, margin):
    """Checked grid and plant data of :func:`lpvsyn`: (grid, A stack, dA stack, B, C, D,
    n_w, n_z); raises ModelError as documented there."""
    for name, v in (("nmeas", nmeas), ("ncon", ncon), ("check_density", check_density)):
        if isinstance(v, bool) or not isinstance(v, (int, np.integer)) or v < 1:
            raise ModelError(f"lpvsyn: {name}={v!r}; expected a whole number ≥ 1")
    if not (isinstance(margin, (int, float)) and np.isfinite(margin) and margin > 0):
        raise ModelError(f"lpvsyn: margin={margin!r}; expected a finite number > 0")
    try:
        plants = list(plants)
        grid = np.asarray(theta, float).ravel()
    except (TypeError, ValueError) as exc:
        raise ModelError(f"lpvsyn: plants and theta must be a sequence of systems and "
                             f"an array of numbers ({exc})") from None
    for k, P in enumerate(plants):
        try:
            parts = [np.asarray(getattr(P, m), float) for m in "ABCD"]
        except (AttributeError, TypeError, ValueError):
            raise ModelError(f"lpvsyn: plants[{k}] is a {type(P).__name__}, not a "
                                 "state-space system (A, B, C, D)") from None
        if not all(np.all(np.isfinite(X)) for X in parts):
            raise ModelError(f"lpvsyn: plants[{k}] has a NaN or infinite entry")
    if grid.size < 2 or len(plants) != grid.size:
        raise ModelError(f"lpvsyn: the θ grid needs at least 2 points with one plant "
                             f"each; got {grid.size} values and {len(plants)} plants")
    if np.any(np.diff(grid) <= 0) or not np.all(np.isfinite(grid)):
        raise ModelError("lpvsyn: theta must be finite and strictly increasing")
    # the basis is evaluated where the controller is: on the table between the grid points
    table = np.concatenate([np.linspace(a, b, check_density + 1)[:-1]
                            for a, b in zip(grid[:-1], grid[1:])] + [grid[-1:]])
    for name, kind in zip(("lyapunov", "lyapunov_r"), bases):
        _validate_basis(name, kind, grid, table)
    _validate_settings(bases, rate_bound, backoff, coupling_ratio, penalty)
    sizes = {np.shape(P.A) for P in plants}
    if len(sizes) > 1:
        raise ModelError(f"lpvsyn: the plants differ in their number of states "
                         f"({sorted(s[0] for s in sizes)}); one family has one state basis")
    As = np.array([np.asarray(P.A, float) for P in plants])
    B = np.asarray(plants[0].B, float)
    C = np.asarray(plants[0].C, float)
    D = np.asarray(plants[0].D, float)
    for k, P in enumerate(plants[1:], 1):
        for nm, X, Y in (("B", B, P.B), ("C", C, P.C), ("D", D, P.D)):
            atol = 1e-12 * max(1.0, np.abs(X).max())
            if np.shape(Y) != X.shape or not np.allclose(np.asarray(Y, float), X, rtol=1e-9,
                                                         atol=atol):
                raise ModelError(f"lpvsyn: plant {k} differs from plant 0 in {nm}; only A "
                                     "may depend on θ (one state basis)")
    nw, nz = B.shape[1] - ncon, C.shape[0] - nmeas
    if nw <= 0 or nz <= 0 or ncon <= 0 or nmeas <= 0:
        raise ModelError(f"lpvsyn: bad channel counts (nw={nw}, nz={nz}, ncon={ncon}, "
                             f"nmeas={nmeas})")
    if np.any(D[nz:, nw:] != 0):
        raise ModelError("lpvsyn: D22 must be zero")
    if dA is None:
        dAs = np.gradient(As, grid, axis=0)
    else:
        dAs = np.array([np.asarray(X, float) for X in dA])
        if dAs.shape != As.shape:
            raise ModelError(f"lpvsyn: dA has shape {dAs.shape}, expected {As.shape}")
    return grid, As, dAs, B, C, D, nw, nz


def _validate_basis(name: str, kind, grid: np.ndarray, table: np.ndarray) -> None:
    """A Lyapunov basis of :func:`lpvsyn`: a name of ``BASES``, or a callable whose values
    on the controller's ``table`` are two finite arrays of one length, linearly
    independent over the grid."""
    if isinstance(kind, str):
        if kind not in BASES:
            raise ModelError(f"lpvsyn: {name}={kind!r}; expected one of {sorted(BASES)} "
                                 "or a callable θ ↦ (f(θ), df/dθ(θ))")
        return
    if not callable(kind):
        raise ModelError(f"lpvsyn: {name}={kind!r}; expected one of {sorted(BASES)} or a "
                             "callable θ ↦ (f(θ), df/dθ(θ))")
    rows = []
    for th in table:
        try:
            f, df = (np.asarray(v, float).ravel() for v in kind(float(th)))
        except (TypeError, ValueError) as exc:
            raise ModelError(f"lpvsyn: {name} at θ = {th:g} did not return two arrays "
                                 f"(f, df/dθ): {exc}") from None
        if f.size == 0 or f.shape != df.shape or not np.all(np.isfinite(f)) \
                or not np.all(np.isfinite(df)):
            raise ModelError(f"lpvsyn: {name} at θ = {th:g} gave f of shape {f.shape} "
                                 f"and df/dθ of shape {df.shape}; expected two finite arrays "
                                 "of one length")
        if rows and f.size != rows[0].size:
            raise ModelError(f"lpvsyn: {name} has {f.size} functions at θ = {th:g} and "
                                 f"{rows[0].size} at θ = {grid[0]:g}")
        rows.append(f)
    F = np.array(rows)[np.isin(table, grid)]
    if np.linalg.matrix_rank(F) < F.shape[1]:
        raise ModelError(f"lpvsyn: {name}'s {F.shape[1]} functions are linearly dependent "
                             f"on the grid (rank {np.linalg.matrix_rank(F)}); the LMIs "
                             "would not determine their matrices")


def _validate_settings(bases, rate_bound, backoff, coupling_ratio, penalty) -> None:
    """:func:`lpvsyn`'s settings; raises ModelError as documented there."""
    dependent = not all(is_constant(kind) for kind in bases)
    if not dependent and rate_bound is not None:
        raise ModelError(
            "lpvsyn: a rate bound needs a parameter-dependent Lyapunov function "
            "(lyapunov or lyapunov_r 'affine', 'quadratic' or a basis); constant ones "
            "already allow arbitrarily fast parameter changes")
    rate_ok = isinstance(rate_bound, (int, float, np.integer, np.floating)) \
        and not isinstance(rate_bound, bool) and bool(np.isfinite(rate_bound)) \
        and rate_bound >= 0
    if dependent and not rate_ok:
        raise ModelError(f"lpvsyn: a parameter-dependent Lyapunov function "
                             f"(lyapunov={_basis_name(bases[0])!r}, "
                             f"lyapunov_r={_basis_name(bases[1])!r}) needs a finite "
                             f"rate_bound ≥ 0 (θ's unit per second), got {rate_bound!r}")
    for name, v, low, strict in (("backoff", backoff, 1.0, False),
                                 ("coupling_ratio", coupling_ratio, 1.0, True),
                                 ("penalty", penalty, 0.0, False)):
        number = isinstance(v, (int, float, np.integer, np.floating)) \
            and not isinstance(v, bool) and bool(np.isfinite(v))
        if not number or (v <= low if strict else v < low):
            raise ModelError(f"lpvsyn: {name}={v!r}; expected a finite number "
                             f"{'>' if strict else '≥'} {low:g}")


def _check_table(K: LpvController, A_of, B, C, D, nmeas: int, ncon: int) -> np.ndarray:
    """H∞ norms of the frozen closed loops at the table values (checked stable there and at
    the table midpoints, with the interpolated controller).

    Raises
    ------
    SynthesisError
        If one of these frozen closed loops is unstable.
    """

    table = K.theta
    check_g, stable = [], True
    for th in table:
        Acl, Bcl, Ccl, Dcl = lft_lower_matrices((A_of(th), B, C, D), K.matrices(th), nmeas, ncon)
        if not is_stable(np.linalg.eigvals(Acl)):
            check_g.append(np.inf)
            stable = False
            continue
        check_g.append(hinfnorm(ct.ss(Acl, Bcl, Ccl, Dcl))[0])
    for th in 0.5 * (table[1:] + table[:-1]):
        Acl = lft_lower_matrices((A_of(th), B, C, D), K.matrices(th), nmeas, ncon)[0]
        stable &= is_stable(np.linalg.eigvals(Acl))
    if not stable:
        raise SynthesisError(
            "lpvsyn: a reconstructed frozen closed loop on the check grid is unstable; "
            "refine the design grid")
    return np.array(check_g)
