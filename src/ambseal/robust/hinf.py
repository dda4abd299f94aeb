"""H∞ synthesis and the H∞ norm for a generalised plant.

The generalised plant ``P`` is a :class:`control.StateSpace` whose inputs are ordered
``[w, u]`` (exogenous, control) and outputs ``[z, y]`` (performance, measurement); in the
robust-control setting ``w = [w_Δ, w_perf]`` and ``z = [z_Δ, z_perf]``. The controller
``u = K y`` closes the lower loop and the design goal is (Zhou, Doyle & Glover 1996,
ch. 14)::

    γ = ‖F_l(P, K)‖_∞

Synthesis uses SLICOT's Riccati-based solver SB10AD (Glover & Doyle 1988 formulas, via
slycot). Three traps are handled here rather than left to the user:

* the controller at exactly the optimal γ can be unstable or ill-conditioned, so the
  controller is built at a small back-off ``backoff·γ_opt`` and the closed-loop poles are
  checked (the back-off grows until they are stable);
* SB10AD's γ can be below the true closed-loop norm when ``D11 ≠ 0``; every γ reported here
  is the norm of the closed loop recomputed by :func:`hinfnorm` (SLICOT AB13DD through
  python-control, Bruinsma & Steinbuch 1990);
* SB10AD's check of γ against its lower bound reads a bound LAPACK has overwritten (67 on
  some plants whose γ_opt is 2.3): above Parrott's bound its refusal is set aside
  (:meth:`_Sb10.sb10ad`).

References: Skogestad & Postlethwaite (2005) ch. 9; Zhou, Doyle & Glover (1996) ch. 14–17;
Boyd, Balakrishnan & Kabamba (1989); Bruinsma & Steinbuch (1990).
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass, field
from typing import Any

import control as ct
import numpy as np
import scipy.linalg as sla
from slycot import ab13dd
from slycot.exceptions import SlycotArithmeticError

from ambseal.errors import ConfigError, ModelError, SynthesisError
from ambseal.lti import lft_lower, lft_lower_matrices, ss_matrices
from ambseal.robust._hinf_gamma import backoff_ladder as _backoff_ladder
from ambseal.robust._hinf_gamma import game_riccati as _game_riccati
from ambseal.robust._hinf_gamma import gamma_search as _gamma_search
from ambseal.robust._hinf_gamma import hamiltonian_level as _hamiltonian_level
from ambseal.robust._hinf_gamma import sb10ad as _sb10ad
from ambseal.robust._hinf_gamma import search_gamma as _search_gamma
from ambseal.robust._hinf_small import small_margin
from ambseal.robust.stability import is_stable, unstable_poles
from ambseal.threads import with_numerics_threads

__all__ = ["HinfResult", "hinfsyn", "hinf_gamma_opt", "hinfnorm", "lft_lower", "check_plant",
           "regularise_plant"]

#: Plants with at most this many states take the compiled eigenvector form of the Riccati
#: γ test (:mod:`ambseal.robust._hinf_small`; measured on 3 states: 0.06 ms against 0.4 ms
#: for the Schur form in Python and 0.2 ms for SB10AD's test).
_SMALL_STATES = 6

#: The ladder's factor of a γ search started near γ_opt (``near``): a D–K step moves γ by a
#: few %, so the bracket closes in a few steps where a factor of 4 from γ = 1 leaves
#: Brent's method a bracket of 4 to close (benchmarks/README.md).
NEAR_FACTOR = 1.05

_SB10AD_INFO = {
    1: "[A - jωI, B2; C1, D12] loses column rank on the imaginary axis (P12 has a jω zero)",
    2: "[A - jωI, B1; C2, D21] loses row rank on the imaginary axis (P21 has a jω zero)",
    3: "D12 has not full column rank",
    4: "D21 has not full row rank",
    5: "the SVD inside SB10AD did not converge",
    6: "γ is too small: the controller is not admissible",
    7: "the X-Riccati equation could not be solved",
    8: "the Y-Riccati equation could not be solved",
    9: "det(I + Tu·D11hat·Ty·D22) is zero",
    10: "singular values of D11 partitions could not be estimated",
    11: "I - D22·Dk is singular to working precision",
    12: "no stabilising controller could be found",
}


# --------------------------------------------------------------------------- norm
@with_numerics_threads
def hinfnorm(sys, rtol: float = 1e-10) -> tuple[float, float]:
    """H∞ norm of a continuous-time LTI system and the frequency of its peak.

    The L∞ norm of python-control (``control.linfnorm``: SLICOT AB13DD through slycot,
    the two-step Hamiltonian algorithm of Bruinsma & Steinbuch 1990), made an H∞ norm by
    refusing unstable systems. Measured against a Hamiltonian bisection (closed loops of
    48 and 66 states, and random 30-state systems): the same norm to 5e-10 relative,
    2.5–4× faster.

    Parameters
    ----------
    sys : control.StateSpace or control.TransferFunction
        Continuous-time system, ``p`` outputs and ``m`` inputs.
    rtol : float
        Relative accuracy of the norm (AB13DD's ``tol``).

    Returns
    -------
    gamma : float
        ``sup_ω σ̄(G(jω))``; ``inf`` if ``sys`` has a pole with ``Re ≥ 0``
        (a pole on or right of the imaginary axis: the closed loop is not stable).
    omega_peak : float
        Frequency of the peak in rad/s (``0`` for a static gain or a peak at infinite
        frequency, ``nan`` if unstable).

    Raises
    ------
    ModelError
        If ``sys`` is discrete-time or has a NaN or infinite entry.
    ConfigError
        ``rtol`` not in (0, 1).
    SynthesisError
        If SLICOT AB13DD does not converge on ``sys`` or on its balanced realisation.

    Examples
    --------
    >>> import control as ct
    >>> g, w = hinfnorm(ct.tf([1], [1, 0.2, 1]))   # 1/(2ζ√(1-ζ²)) at ω = √(1-2ζ²)
    >>> round(g, 4), round(w, 4)
    (5.0252, 0.9899)
    """
    sys = ct.ss(*ss_matrices(sys, name="hinfnorm: sys", allow_discrete=True),
                getattr(sys, "dt", 0) or 0)
    if sys.isdtime(strict=True):
        raise ModelError("hinfnorm: only continuous-time systems are supported")
    if not all(np.all(np.isfinite(np.asarray(M, float))) for M in (sys.A, sys.B, sys.C, sys.D)):
        raise ModelError("hinfnorm: sys has non-finite entries (NaN or inf)")
    if not (isinstance(rtol, (int, float, np.floating)) and 0.0 < rtol < 1.0):
        raise ConfigError(f"hinfnorm: rtol={rtol!r}, expected a relative accuracy in (0, 1)")
    A = np.asarray(sys.A, float)
    if sys.ninputs == 0 or sys.noutputs == 0:
        return 0.0, 0.0
    if A.shape[0]:
        if not is_stable(np.linalg.eigvals(A)):
            return float("inf"), float("nan")
    return _linfnorm_matrices(A, *(np.asarray(M, float) for M in (sys.B, sys.C, sys.D)),
                              rtol)


def _linfnorm_matrices(A, B, C, D, rtol: float = 1e-10) -> tuple[float, float]:
    """L∞ norm and peak frequency of a continuous (A, B, C, D): SLICOT AB13DD through
    slycot, as ``control.linfnorm`` calls it, without building a system object.

    Where AB13DD's QR iteration does not converge (a badly scaled realisation), the norm,
    a similarity invariant, is that of the realisation balanced by
    ``scipy.linalg.matrix_balance`` (powers of 2, no permutation: exact). SynthesisError if AB13DD fails on that one too."""

    n, m, p = A.shape[0], B.shape[1], C.shape[0]
    if n == 0:
        return float(np.linalg.norm(D, 2)) if D.size else 0.0, 0.0
    jobd = "D" if np.any(D) else "Z"
    try:
        gamma, w_pk = ab13dd("C", "I", "S", jobd, n, m, p, A, np.eye(n), B, C, D, rtol)
    except SlycotArithmeticError:
        Ab, (sc, _) = sla.matrix_balance(A, permute=False, separate=True)
        try:
            gamma, w_pk = ab13dd("C", "I", "S", jobd, n, m, p, Ab, np.eye(n),
                                 B / sc[:, None], C * sc[None, :], D, rtol)
        except SlycotArithmeticError as exc:
            raise SynthesisError(f"L∞ norm of a {n}-state system: SLICOT AB13DD did not "
                                 "converge, on the system or its balanced form") from exc
    w_pk = float(w_pk)
    return float(gamma), (w_pk if np.isfinite(w_pk) else 0.0)


# --------------------------------------------------------------------------- checks
#: A mode is lost to the control inputs (or the measurements) when the PBH matrix's
#: σ_min is at most this fraction of its σ_max and the cosine between the mode's eigenvector
#: and every input column (output row) is at most this too.
PBH_RTOL = 1e-9


def _pbh_fails(A, X, rows, eigs):
    """The eigenvalues ``eigs`` of A that are not stable (:func:`~ambseal.robust.stability.
    unstable_poles`) at which [A - λI, X] (or its dual) loses rank and which the mode's
    eigenvector confirms (:func:`_modal_cosine`): the rank test alone is relative to the
    PBH matrix's σ_max, which fast stable modes (a D–G scaling's poles) set, so a mode the
    inputs reach with a small cosine falls below it, and SB10AD stabilises it all the
    same."""
    n = A.shape[0]
    bad = []
    for lam in unstable_poles(eigs):
        Mx = np.hstack([A - lam * np.eye(n), X]) if rows else np.vstack([A - lam * np.eye(n), X])
        s = np.linalg.svd(Mx, compute_uv=False)
        smin = s[n - 1] if s.size >= n else 0.0
        if smin <= PBH_RTOL * max(1.0, s[0]) and _modal_cosine(A, X, lam, rows) <= PBH_RTOL:
            bad.append(complex(lam))
    return bad


def _modal_cosine(A, X, lam, rows) -> float:
    """The largest cosine between the eigenvector of A at λ and X's columns (``rows``:
    the left eigenvector w, |wᴴ x_k|/‖x_k‖) or X's rows (the right one v, |x_k v|/‖x_k‖):
    Hamdan & Nayfeh's measure of modal controllability (observability), 0 exactly when
    the mode is lost to X (J. Guid. Control Dyn. 12 (1989) 421–428). The eigenvector is
    the singular vector of A − λI's smallest singular value."""
    M = A - lam * np.eye(A.shape[0])
    v = np.linalg.svd(M.conj().T if rows else M)[2][-1].conj()
    Y = X if rows else X.T
    norms = np.linalg.norm(Y, axis=0)
    keep = norms > 0
    if not keep.any():
        return 0.0
    return float(np.max(np.abs(v.conj() @ Y[:, keep] if rows else Y[:, keep].T @ v)
                        / norms[keep]))


def _check_counts(nmeas, ncon) -> None:
    """ModelError unless both channel counts are whole numbers (not bools)."""
    for name, v in (("nmeas", nmeas), ("ncon", ncon)):
        if isinstance(v, bool) or not isinstance(v, (int, np.integer)):
            raise ModelError(f"{name}={v!r}: expected a whole number of channels")


def check_plant(P, nmeas: int, ncon: int) -> None:
    """Check that ``P`` meets the assumptions of H∞ synthesis (Zhou et al. 1996, §17.1).

    Raises
    ------
    ModelError
        If ``P`` is not a continuous-time state-space system or the channel counts do not fit.
    SynthesisError
        If ``(A, B2)`` is not stabilisable, ``(C2, A)`` not detectable, ``D12`` lacks full
        column rank or ``D21`` lacks full row rank; the message names the cause.
    """
    if not isinstance(P, ct.StateSpace):
        raise ModelError(f"P must be a control.StateSpace, got {type(P).__name__}")
    if P.isdtime(strict=True):
        raise ModelError("P must be continuous-time (dt = 0)")
    nin, nout = P.ninputs, P.noutputs
    _check_counts(nmeas, ncon)
    if not (0 < ncon < nin):
        raise ModelError(f"ncon={ncon} must be between 1 and the number of inputs - 1 ({nin - 1})")
    if not (0 < nmeas < nout):
        raise ModelError(f"nmeas={nmeas} must be between 1 and the number of outputs - 1 ({nout - 1})")
    A, B, C, D = (np.asarray(M, float) for M in (P.A, P.B, P.C, P.D))
    if not np.all(np.isfinite(A)) or not np.all(np.isfinite(B)) or not np.all(np.isfinite(C)) \
            or not np.all(np.isfinite(D)):
        raise ModelError("P has non-finite entries")
    nw, nz = nin - ncon, nout - nmeas
    B2, C2 = B[:, nw:], C[nz:]
    D12, D21 = D[:nz, nw:], D[nz:, :nw]
    if nz < ncon or np.linalg.matrix_rank(D12, tol=1e-10 * max(1.0, np.abs(D12).max())) < ncon:
        raise SynthesisError(
            f"D12 (z ← u, {nz}×{ncon}) has not full column rank: every control input must be "
            "penalised directly in z (add a control-effort weight)")
    if nw < nmeas or np.linalg.matrix_rank(D21, tol=1e-10 * max(1.0, np.abs(D21).max())) < nmeas:
        raise SynthesisError(
            f"D21 (y ← w, {nmeas}×{nw}) has not full row rank: every measurement must see "
            "exogenous noise directly (add a sensor-noise input)")
    if A.shape[0]:
        eigs = np.linalg.eigvals(A)
        if _pbh_fails(A, B2, True, eigs) or _pbh_fails(A, C2, False, eigs):
            # the rank tests are not scale-invariant (a 104-state D–G–K plant: σ_min/σ_max
            # 2.9e-10 unbalanced at its unstable modes): judge on the balanced plant
            A, B, C, *_ = _scale(A, B, C, D, nw, nz)
            bad = _pbh_fails(A, B[:, nw:], True, eigs)
            if bad:
                raise SynthesisError(
                    f"(A, B2) is not stabilisable: mode(s) {np.round(bad, 6).tolist()} cannot "
                    "be moved by the control inputs")
            bad = _pbh_fails(A, C[nz:], False, eigs)
            if bad:
                raise SynthesisError(
                    f"(C2, A) is not detectable: mode(s) {np.round(bad, 6).tolist()} are not "
                    "seen by the measurements")


#: ε of :func:`regularise_plant` relative to the size of the channels it joins
REGULARISE_REL = 1e-4


def regularise_plant(P, nmeas: int, ncon: int, rel: float = REGULARISE_REL):
    """``P`` with a rank-deficient ``D12`` or ``D21`` made full rank by ε-channels, the
    standard regularisation (Zhou, Doyle & Glover 1996 §17.1; Skogestad & Postlethwaite
    §9.3.2: a small control-effort output and sensor-noise input).

    ``D12`` without full column rank: the outputs ``z_reg_u<j> = ε_u·u_j`` are appended to
    z, ε_u = ``rel``·max(σ̄(C1), σ̄[D11 D12]) (the size of the other performance outputs).
    ``D21`` without full row rank: the inputs ``w_reg_y<j>`` are appended to w, entering
    the measurements as ε_w·w, ε_w = ``rel``·max(σ̄(B1), σ̄[D11; D21]). The regularised
    plant's γ_opt bounds the given one's from above, and the gap closes as ε → 0 (with
    controller gains growing like 1/ε).

    Parameters
    ----------
    P : control.StateSpace
        Generalised plant, inputs ``[w, u]``, outputs ``[z, y]``.
    nmeas, ncon : int
        Measurements and controls.
    rel : float
        ε relative to the channels' size (> 0).

    Returns
    -------
    (control.StateSpace, dict or None)
        The plant (``P`` itself when both have full rank) and ``{"D12": ε_u, "D21": ε_w}``
        (None for a full-rank one), or None when nothing was added.
    """
    A, B, C, D = (np.asarray(M, float) for M in (P.A, P.B, P.C, P.D))
    nw, nz = B.shape[1] - ncon, C.shape[0] - nmeas

    def deficient(M, k):
        return M.shape[0 if k == M.shape[1] else 1] < k or np.linalg.matrix_rank(
            M, tol=1e-10 * max(1.0, np.abs(M).max() if M.size else 1.0)) < k

    def size(*Ms):
        return max([np.linalg.norm(M, 2) for M in Ms if M.size] + [1e-300])

    reg12 = deficient(D[:nz, nw:], ncon)
    reg21 = deficient(D[nz:, :nw], nmeas)
    if not (reg12 or reg21):
        return P, None
    ins, outs = list(P.input_labels), list(P.output_labels)
    eps_u = float(rel * size(C[:nz], D[:nz])) if reg12 else None
    eps_w = float(rel * size(B[:, :nw], D[:, :nw])) if reg21 else None
    if reg12:  # z ← [z; ε_u u]
        C = np.vstack([C[:nz], np.zeros((ncon, C.shape[1])), C[nz:]])
        Dz = np.hstack([np.zeros((ncon, nw)), eps_u * np.eye(ncon)])
        D = np.vstack([D[:nz], Dz, D[nz:]])
        outs = outs[:nz] + [f"z_reg_u{j}" for j in range(ncon)] + outs[nz:]
        nz += ncon
    if reg21:  # w ← [w; w_reg], y += ε_w w_reg
        B = np.hstack([B[:, :nw], np.zeros((B.shape[0], nmeas)), B[:, nw:]])
        Dw = np.vstack([np.zeros((nz, nmeas)), eps_w * np.eye(nmeas)])
        D = np.hstack([D[:, :nw], Dw, D[:, nw:]])
        ins = ins[:nw] + [f"w_reg_y{j}" for j in range(nmeas)] + ins[nw:]
    return (ct.ss(A, B, C, D, inputs=ins, outputs=outs, name=P.name),
            {"D12": eps_u, "D21": eps_w})


# --------------------------------------------------------------------------- synthesis
@dataclass(frozen=True)
class HinfResult:
    """Result of :func:`hinfsyn`.

    Attributes
    ----------
    K : control.StateSpace
        Controller ``u = K y`` (inputs named after P's measurements, outputs after P's
        control inputs).
    gamma : float
        Verified closed-loop norm ``‖F_l(P, K)‖_∞``, dimensionless.
    gamma_opt : float
        SB10AD's estimate of the optimal γ (may be below ``gamma`` when ``D11 ≠ 0``).
    gamma_design : float
        The γ at which the controller was built (``backoff·gamma_opt`` or larger).
    omega_peak : float
        Frequency of the closed-loop peak, rad/s.
    closed_loop : control.StateSpace
        ``F_l(P, K)`` from ``w`` to ``z``.
    rcond : tuple of float
        SB10AD reciprocal condition numbers (control/measurement transforms, X and Y
        Riccati equations) at ``gamma_design``.
    gamma_lower : float
        Largest γ found inadmissible in the search (a lower bound of γ_opt; the Parrott bound
        if every γ tried was admissible; nan for a given ``gamma``).
    iterations : int
        SB10AD calls: γ tests of the search plus controllers built.
    on_target : bool
        Whether ``gamma`` is within the back-off of the γ claimed: ``gamma ≤
        max_backoff·gamma_opt·(1 + 1e-3)`` after a search, ``gamma ≤ γ·(1 + 1e-3)`` for a
        given γ. False when SB10AD's controllers near that γ miss the γ they were built for
        (D–G-scaled plants: built for 0.93, norm 30.9) and the controller returned is the
        best one the upward search verified: a valid controller, far from the optimum.
        Reported rather than raised: D–G–K then tries the controller at its own level.
    regularisation : dict or None
        ``{"D12": ε_u, "D21": ε_w}`` (None entries where the plant had full rank) when the
        synthesis ran on the regularised plant (:func:`regularise_plant`): ``gamma_opt``,
        ``gamma_design`` and ``gamma_lower`` are then that plant's, ``gamma`` and
        ``closed_loop`` the given plant's.
    """

    K: Any
    gamma: float
    gamma_opt: float
    gamma_design: float
    omega_peak: float
    closed_loop: Any = field(repr=False)
    rcond: tuple = ()
    gamma_lower: float = float("nan")
    iterations: int = 0
    on_target: bool = True
    regularisation: dict | None = None

    @property
    def order(self) -> int:
        """Number of controller states."""
        return int(self.K.nstates)

    def __iter__(self):
        """``K, CL, gamma, info = hinfsyn(P, nmeas, ncon)``, as python-control's
        ``hinfsyn`` returns (controller, closed loop, γ, and this result for the rest)."""
        return iter((self.K, self.closed_loop, self.gamma, self))

    def to_dict(self) -> dict:
        """JSON-ready summary (matrices as nested lists)."""
        K = self.K
        return {
            "gamma": self.gamma, "gamma_opt": self.gamma_opt, "gamma_design": self.gamma_design,
            "gamma_lower": self.gamma_lower, "iterations": self.iterations,
            "on_target": self.on_target, "regularisation": self.regularisation,
            "omega_peak_rad_s": self.omega_peak, "order": self.order,
            "rcond": list(self.rcond),
            "K": {"A": np.asarray(K.A).tolist(), "B": np.asarray(K.B).tolist(),
                  "C": np.asarray(K.C).tolist(), "D": np.asarray(K.D).tolist(),
                  "inputs": list(K.input_labels), "outputs": list(K.output_labels)},
        }


def _scale(A, B, C, D, nw, nz):
    """State balancing and control/measurement normalisation (norm-preserving for w → z).

    Returns scaled matrices and (t, su, sy): x = diag(t) x̃, u = diag(su) ũ, ỹ = diag(sy) y.
    """
    n = A.shape[0]
    if n:
        # balance A together with the magnitude of the B rows and C columns
        Mbal = np.zeros((n + 1, n + 1))
        Mbal[:n, :n] = np.abs(A)
        Mbal[:n, n] = np.abs(B).sum(1)
        Mbal[n, :n] = np.abs(C).sum(0)
        _, (t, _) = sla.matrix_balance(Mbal, permute=False, separate=True)
        t = t[:n] / t[n]
    else:
        t = np.ones(0)
    A = A * (1.0 / t)[:, None] * t[None, :]
    B = B / t[:, None]
    C = C * t[None, :]
    # control inputs: unit norm columns of [B2; D12]
    cu = np.linalg.norm(np.vstack([B[:, nw:], D[:nz, nw:]]), axis=0)
    su = 1.0 / np.where(cu > 0, cu, 1.0)
    ry = np.linalg.norm(np.hstack([C[nz:], D[nz:, :nw]]), axis=1)
    sy = 1.0 / np.where(ry > 0, ry, 1.0)
    B = B.copy(); C = C.copy(); D = D.copy()
    B[:, nw:] *= su
    D[:, nw:] *= su
    C[nz:] *= sy[:, None]
    D[nz:] *= sy[:, None]
    return A, B, C, D, t, su, sy


@with_numerics_threads
def hinfsyn(P, nmeas: int, ncon: int, *, backoff: float = 1.01, gamma: float | None = None,
            max_backoff: float = 4.0, rtol: float = 1e-6,
            regularise: float | None = REGULARISE_REL, near: float | None = None
            ) -> HinfResult:
    """H∞ controller for a generalised plant (Glover & Doyle 1988; Zhou, Doyle & Glover
    1996, ch. 14).

    Brackets the optimal γ between cheap bounds — Parrott's bound on the feedthrough, then
    a ladder of factors 4 to the first change of admissibility — and closes in by Brent's
    method on the Riccati γ margin ρ(X∞Y∞)/γ² − 1 (Glover & Doyle 1988; compiled for plants
    of at most 6 states), to a relative tolerance ``rtol``; where the margin is undefined
    (e.g. repeated Hamiltonian eigenvalues) SLICOT SB10AD's own bisection takes over; where
    SB10AD and the margin disagree, a controller's closed loop decides.
    python-control's ``hinfsyn`` starts SB10AD's bisection and scan at γ = 1e100 instead.
    Then it builds the controller at ``backoff·γ_opt`` and checks that the closed loop is
    stable and keeps that γ; the back-off grows (×1.01 … ×``max_backoff``) until it does.
    The reported γ is the recomputed norm of ``F_l(P, K)``. A static plant (no state) is
    given one decoupled state at −1 rad/s for SB10AD, which needs one; γ is unchanged.

    Parameters
    ----------
    P : control.StateSpace
        Continuous-time generalised plant with ``n`` states, inputs ``[w, u]`` and outputs
        ``[z, y]``.
    nmeas : int
        Number of measurements ``y`` (last outputs of ``P``).
    ncon : int
        Number of control inputs ``u`` (last inputs of ``P``).
    backoff : float
        Relative back-off from the optimal γ (≥ 1; default 1.01).
    gamma : float, optional
        Build the controller at this γ instead (suboptimal design); it must be admissible.
    max_backoff : float
        Largest back-off tried before giving up.
    rtol : float
        Relative tolerance of γ_opt (the search stops at ``hi/lo ≤ 1 + rtol``).
    regularise : float or None
        A ``D12`` or ``D21`` without full rank is made full rank by ε-channels of this
        relative size (:func:`regularise_plant`; stated in ``HinfResult.regularisation``);
        None refuses such a plant instead.
    near : float, optional
        A γ expected within a few % of γ_opt (a D–K iteration's previous γ_opt): the
        search starts there (:meth:`_Sb10.gamma_opt`); the same γ_opt to ``rtol``, fewer
        γ tests.

    Returns
    -------
    HinfResult
        Controller (``n`` states), verified γ, γ_opt and the closed loop. Where a
        controller's verified norm lies below a γ the search found inadmissible (SB10AD's
        test at a γ_opt of 0, to rounding), the closed loop decides: ``gamma_opt`` is that
        norm and ``gamma_lower`` Parrott's bound.

    Raises
    ------
    ModelError, ConfigError
        Wrong system type, a NaN or infinite entry or channel counts (ModelError); a
        back-off that is not finite and ≥ 1, ``rtol`` outside (0, 1) or a ``gamma`` that is
        not finite and > 0 (ConfigError).
    SynthesisError
        Plant not stabilisable/detectable, ``D12``/``D21`` rank deficient, jω-axis zeros,
        inadmissible ``gamma`` or no stabilising controller found. A verified norm far
        above the γ claimed is reported instead (``HinfResult.on_target`` False).

    Examples
    --------
    Minimum ‖KS‖∞ for the unstable plant G = 1/(s - 1) (optimum 2, Glover 1986):

    >>> import control as ct
    >>> P = ct.ss([[1.]], [[0., 1.]], [[0.], [1.]], [[0., 1.], [1., 0.]])
    >>> r = hinfsyn(P, nmeas=1, ncon=1)
    >>> 2.0 <= r.gamma <= 2.05
    True
    """
    given, reg = P, None
    _check_counts(nmeas, ncon)
    if regularise is not None and isinstance(P, ct.StateSpace) and 0 < ncon < P.ninputs \
            and 0 < nmeas < P.noutputs:
        P, reg = regularise_plant(P, nmeas, ncon, regularise)
    check_plant(P, nmeas, ncon)
    if not (math.isfinite(backoff) and backoff >= 1.0):
        raise ConfigError(f"backoff={backoff} must be a finite number ≥ 1")
    if not (isinstance(rtol, (int, float)) and 0.0 < rtol < 1.0):
        raise ConfigError(f"hinfsyn: rtol={rtol!r}, expected a relative tolerance in (0, 1)")
    if gamma is not None and not (isinstance(gamma, (int, float)) and math.isfinite(gamma)
                                  and gamma > 0):
        raise ConfigError(f"hinfsyn: gamma={gamma!r}, expected a finite γ > 0")
    if P.nstates == 0:
        # SLICOT SB10AD needs a state: one decoupled at −1 rad/s changes neither γ nor any
        # transfer function (stable, neither controllable nor observable)
        P = ct.ss(-np.eye(1), np.zeros((1, P.ninputs)), np.zeros((P.noutputs, 1)), P.D,
                  inputs=P.input_labels, outputs=P.output_labels)
    sb = _Sb10(P, nmeas, ncon)
    if gamma is None:
        gamma_opt, gamma_lower, tests = sb.gamma_opt(rtol, confirm=False, near=near)
        base_g, factors = gamma_opt, _backoff_ladder(backoff, max_backoff)
    else:
        gamma_opt, gamma_lower, tests = float("nan"), float("nan"), 0
        base_g, factors = float(gamma), [1.0]
    tried, last_err = [], [None]

    def attempt(g):
        """Controller at γ = g with its verified closed-loop norm (recorded), or None."""
        try:
            res = sb.controller(g)
        except SynthesisError as exc:
            last_err[0] = exc
            return None
        tried.append(res)
        return res

    chosen = _gamma_search(attempt, base_g, factors, backoff, fixed=gamma is not None)
    if tried and gamma is None:
        # every γ reported is a verified norm: keep the controller with the smallest one
        chosen = min(tried, key=lambda r: r.gamma)
    if chosen is None:
        raise SynthesisError(
            f"hinfsyn: no stabilising controller found from γ={base_g:.6g} upwards "
            f"({last_err[0]})")
    if gamma is None and chosen.gamma < gamma_lower * (1.0 - 1e-6):
        # a controller beats a γ the search found inadmissible (SB10AD's test at a γ_opt of
        # 0, to rounding): the closed loop decides. Its verified norm bounds γ_opt from
        # above; below, only Parrott's bound is certain.
        gamma_opt, gamma_lower = float(chosen.gamma), sb.parrott_bound
    claimed = max_backoff * gamma_opt if gamma is None else float(gamma)
    ylab, ulab = list(P.output_labels)[sb.nz:], list(P.input_labels)[sb.nw:]
    K = ct.ss(*chosen.K, inputs=ylab, outputs=ulab, name="K",
              states=[f"xK{i}" for i in range(chosen.K[0].shape[0])])
    cl = ct.ss(*chosen.closed_loop, inputs=list(P.input_labels)[:sb.nw],
               outputs=list(P.output_labels)[:sb.nz], name="closed_loop")
    achieved, w_peak = float(chosen.gamma), float(chosen.omega)
    if reg is not None:  # the given plant's loop, without the ε-channels
        nw0, nz0 = given.ninputs - ncon, given.noutputs - nmeas
        cl = ct.ss(*lft_lower_matrices(tuple(np.asarray(M, float) for M in
                                             (given.A, given.B, given.C, given.D)),
                                       chosen.K, nmeas, ncon),
                   inputs=list(given.input_labels)[:nw0],
                   outputs=list(given.output_labels)[:nz0], name="closed_loop")
        achieved, w_peak = (float(v) for v in hinfnorm(cl))
    return HinfResult(K=K, gamma=achieved, gamma_opt=gamma_opt,
                      gamma_design=float(chosen.gamma_design), omega_peak=w_peak,
                      closed_loop=cl, rcond=chosen.rcond,
                      gamma_lower=gamma_lower, iterations=tests + len(tried),
                      on_target=bool(chosen.gamma <= claimed * (1.0 + 1e-3)),
                      regularisation=reg)


def hinf_gamma_opt(P, nmeas: int, ncon: int, *, rtol: float = 1e-6,
                   near: float | None = None) -> float:
    """γ_opt of the H∞ problem of ``P`` (inputs ``[w, u]``, outputs ``[z, y]``; ``nmeas``
    measurements, ``ncon`` controls) to relative tolerance ``rtol``, without a controller:
    the γ search of :func:`hinfsyn` alone, for callers that compare many plants (the D-scale
    search of :func:`ambseal.robust.dk.musyn`). ``near``: a γ expected within a few % of
    γ_opt; the search then starts there with steps of :data:`NEAR_FACTOR` and uses the
    Riccati margin alone (no SB10AD cross-check). Raises as :func:`hinfsyn` (ModelError,
    SynthesisError)."""
    check_plant(P, nmeas, ncon)
    sb = _Sb10(P, nmeas, ncon)
    if near is None:
        return float(sb.gamma_opt(rtol)[0])
    return float(sb.search(rtol, start=near, factor=NEAR_FACTOR)[0])


@dataclass(frozen=True)
class _Attempt:
    """A controller built at ``gamma_design`` (``K`` and ``closed_loop`` = F_l(P, K) as
    matrices ``(A, B, C, D)``) and its verified closed-loop norm ``gamma``."""

    gamma_design: float
    K: tuple
    closed_loop: tuple
    rcond: tuple
    gamma: float
    omega: float

    @property
    def consistent(self) -> bool:
        """The verified norm does not exceed the γ the controller was built for."""
        return self.gamma <= self.gamma_design * (1.0 + 1e-3)


class _Sb10:
    """SB10AD on the scaled plant (:func:`_scale`): γ_opt, and controllers at a given γ."""

    def __init__(self, P, nmeas: int, ncon: int):
        A0, B0, C0, D0 = (np.asarray(M, float) for M in (P.A, P.B, P.C, P.D))
        self.P0, self.nmeas, self.ncon = (A0, B0, C0, D0), nmeas, ncon
        self.nw, self.nz = B0.shape[1] - ncon, C0.shape[0] - nmeas
        A, B, C, D, self.t, self.su, self.sy = _scale(A0, B0, C0, D0, self.nw, self.nz)
        self.A, self.B, self.C, self.D = (np.ascontiguousarray(M) for M in (A, B, C, D))
        #: smallest γ not refused by SB10AD's lower-bound check so far (:meth:`sb10ad`)
        self._bound_above = np.inf
        # the γ search tests a γ (SB10AD job 4) whose controller it then builds, and checks
        # a margin it has computed: both kept, SB10AD's last job-4 call alone (a
        # controller of the full order)
        self._last_job4: tuple | None = None
        self._margins: dict = {}
        #: the game Riccati equation (X∞ or Y∞) :meth:`riccati_margin` solves first
        self._fails_first = "X"
        #: :meth:`hamiltonian_levels` per tolerance
        self._levels: dict = {}

    def sb10ad(self, g: float, job: int, gtol: float = 1e-6):
        """SLICOT SB10AD on the scaled plant at γ = g (job 4: test and controller at g; job
        1: bisection below g to ``gtol``), past SB10AD's wrong lower bound of γ.

        SB10AD first refuses (info 6) every γ at or below its bound
        ``max(σ̄[D1111, D1112], σ̄[D1111ᵀ, D1121ᵀ])``, but in SLICOT 5.8 (SB10AD, "Workspace
        usage 2") the workspace of the second singular value decomposition starts inside
        the first one's result, so the bound it compares with is whatever LAPACK left there:
        with 3 performance outputs, 2 exogenous inputs, 1 control and 1 measurement,
        DGESVD's optimal workspace size (67 with this LAPACK) — every γ ≤ 67 refused
        whatever the plant. Its
        true value is Parrott's bound (:meth:`parrott`), so an info 6 above that bound is
        this defect, and SB10AD is asked again from ``g0 = g·2^K`` with K large enough that
        ``g0 − bound`` rounds to ``g0``: its bisection (job 1) then halves exactly down the
        ladder g0, g0/2, … to g (job 4: stopping there, ``gtol = 1.5·g``; a γ of the ladder
        refused leaves it above g, and g is refused) or on below g to ``gtol`` (job 1).
        python-control's ``hinfsyn`` gets past the bound the same way, from γ = 1e100.
        """
        key = (float(g), int(job), float(gtol))
        if self._last_job4 is not None and self._last_job4[0] == key:
            return self._last_job4[1]
        result = self._sb10ad_past_bound(g, job, gtol)
        if job == 4:
            self._last_job4 = (key, result)
        return result

    def _sb10ad_past_bound(self, g: float, job: int, gtol: float):
        """:meth:`sb10ad` computed (its docstring)."""
        args = (self.A, self.B, self.C, self.D, self.ncon, self.nmeas)
        out, info = _sb10ad(*args, g, job, gtol)
        if info != 6:
            self._bound_above = min(self._bound_above, g)
            return out, info
        if g <= self.parrott_bound * (1.0 + 1e-9):
            return out, info
        top = self._bound_above
        up = 256.0
        while top == np.inf:  # find a γ above SB10AD's bound: a ladder of factors 2^8
            if g * up > 1e100:
                return out, info
            if _sb10ad(*args, g * up, 4)[1] != 6:
                top = self._bound_above = g * up
            up *= 256.0
        K = int(np.ceil(np.log2(top / g))) + 56
        g0 = float(np.ldexp(g, K))
        if g0 > 1e100:  # (γ² must not overflow inside SB10AD)
            return out, info
        out2, info2 = _sb10ad(*args, g0, 1, 1.5 * g if job == 4 else gtol)
        if job == 4 and not info2 and out2[0] != g:
            return out, 12  # the ladder was left above g: g is not admissible
        return out2, info2

    def call(self, g: float, job: int):
        out, info = self.sb10ad(g, job)
        if info:
            raise SynthesisError(f"hinfsyn: SB10AD failed at γ={g:.6g}: "
                                 f"{_SB10AD_INFO.get(info, 'argument error')} (info={info})")
        return out

    def admissible(self, g: float) -> bool:
        """SB10AD's γ test (job 4: the Riccati conditions of Glover & Doyle 1988 at γ)."""
        info = self.sb10ad(g, 4)[1]
        if info in (6, 7, 8, 12):
            return False
        if info:
            self.call(g, 4)  # raises SynthesisError naming the cause
        return True

    @functools.cached_property
    def parrott_bound(self) -> float:
        """:meth:`parrott`, computed once."""
        return self.parrott()

    def parrott(self) -> float:
        """Cheap lower bound of γ_opt from the feedthrough (Parrott's theorem; Zhou, Doyle &
        Glover 1996 §17.3): no controller makes ‖F_l(P, K)(j∞)‖ smaller than
        ``max(σ̄(U⊥ᵀ D11), σ̄(D11 V⊥))`` with U⊥, V⊥ the complements of range D12 and of the
        row space of D21."""
        nz, nw, D = self.nz, self.nw, self.D
        D11, D12, D21 = D[:nz, :nw], D[:nz, nw:], D[nz:, :nw]
        if D11.size == 0 or not np.any(D11):
            return 0.0
        # complements from full SVDs (D12 and D21 have full rank: check_plant)
        U = np.linalg.svd(D12)[0][:, D12.shape[1]:]
        V = np.linalg.svd(D21)[2][D21.shape[0]:].T
        a = np.linalg.svd(U.T @ D11, compute_uv=False)[0] if U.size else 0.0
        b = np.linalg.svd(D11 @ V, compute_uv=False)[0] if V.size else 0.0
        return float(max(a, b))

    def search(self, rtol: float, seen: dict | None = None, *, start: float | None = None,
               factor: float = 4.0) -> tuple[float, float, int]:
        """γ_opt to ``rtol``, ``(hi, lo, tests)`` as :func:`_search_gamma`: where the γ at
        which a game Hamiltonian meets the imaginary axis (:meth:`hamiltonian_levels`)
        decides γ_opt — the margin (:meth:`riccati_margin`) admits that level × (1 +
        rtol/2) — that γ and the level × (1 − rtol/4), below which no controller exists
        (Glover & Doyle 1988, Thm 3.1: X∞ and Y∞ need Hamiltonians without imaginary
        eigenvalues); else :func:`_search_gamma` on the margin from the Parrott bound (a
        ladder from ``start`` by ``factor``, ``seen`` the margins known).

        Where the level decides, the margin jumps from below 0 to +1 there, and Brent's
        method bisected some 25 margins to a tolerance of 1e-8 — to where rounding in the
        Schur form of a Hamiltonian with two nearly equal eigenvalues on the imaginary axis
        stopped reading them as such, 1e-8 to 2e-7 below the level on a 122-state plant's
        D search, and not monotonically, so each bracket's bisection ended elsewhere in
        that band (benchmarks/README.md, "γ_opt where a Hamiltonian meets the
        imaginary axis"). The level is a singular value at one frequency, which rounding
        moves by about ε."""
        level = self.hamiltonian_levels(rtol)
        if level is not None and level > self.parrott_bound * (1.0 + 1e-9):
            hi = level * (1.0 + 0.5 * rtol)
            if self.riccati_margin(hi) < 0:
                return hi, level * (1.0 - 0.25 * rtol), 1
        return _search_gamma(self.riccati_margin, self.parrott_bound, rtol, seen,
                             start=start, factor=factor)

    def hamiltonian_levels(self, rtol: float) -> float | None:
        """The larger of the levels at which the X∞ and the Y∞ game Hamiltonians of the
        scaled plant meet the imaginary axis as γ falls (:func:`_hamiltonian_level`, to
        ``rtol``): a lower bound of γ_opt. None where either is not determined."""
        if rtol not in self._levels:
            nz, nw, A, B, C, D = self.nz, self.nw, self.A, self.B, self.C, self.D
            x = _hamiltonian_level(A, B, C[:nz], D[:nz], nw, rtol)
            y = None if x is None else _hamiltonian_level(A.T, C.T, B[:, :nw].T,
                                                          D[:, :nw].T, nz, rtol)
            self._levels[rtol] = None if y is None else max(x, y)
        return self._levels[rtol]

    def riccati_margin(self, g: float) -> float:
        """The γ test of Glover & Doyle (1988), Thm 3.1, on the scaled plant, as a number:
        ``ρ(X∞Y∞)/γ² − 1`` (< 0: γ admissible) when the stabilising X∞ ⪰ 0 and Y∞ ⪰ 0 of the
        two game Riccati equations exist (the general D11 form, R = D1•ᵀD1• − diag(γ²I, 0);
        D22 does not matter), else +1 (also at or below the Parrott bound). Two Hamiltonian
        Schur forms instead of SB10AD's controller; on plants of at most ``_SMALL_STATES``
        states their compiled eigenvector form (:mod:`ambseal.robust._hinf_small`)."""
        g = float(g)
        if g not in self._margins:
            self._margins[g] = self._riccati_margin(g)
        return self._margins[g]

    def _riccati_margin(self, g: float) -> float:
        """:meth:`riccati_margin` computed."""
        nz, nw, A, B, C, D = self.nz, self.nw, self.A, self.B, self.C, self.D
        if g <= self.parrott_bound * (1 + 1e-9):
            return 1.0
        m = self._small_margin(g)
        if not np.isnan(m):
            return m
        # the equation that failed last is solved first: below γ_opt the search's γ mostly
        # fail on one of the two (the one whose Hamiltonian meets the imaginary axis at
        # γ_opt), and then the other is not needed. Either order gives the same margin
        # (benchmarks/README.md, "The γ test solves first the equation that failed").
        equations = {"X": (A, B, C[:nz], D[:nz], nw), "Y": (A.T, C.T, B[:, :nw].T,
                                                          D[:, :nw].T, nz)}
        sol = {}
        for k in sorted(equations, key=lambda k: k != self._fails_first):
            sol[k] = _game_riccati(*equations[k], g)
            if sol[k] is None:
                self._fails_first = k
                return 1.0
        X, Y = sol["X"], sol["Y"]
        rho = np.max(np.abs(np.linalg.eigvals(X @ Y))) if X.size else 0.0
        return float(rho / (g * g) - 1.0)

    def _small_margin(self, g: float) -> float:
        """:meth:`riccati_margin` in compiled form on plants of at most ``_SMALL_STATES``
        states; NaN where that form cannot decide (:mod:`ambseal.robust._hinf_small`) or
        the plant is larger."""
        if self.A.shape[0] > _SMALL_STATES:
            return float("nan")
        try:
            return float(small_margin(self.A, self.B, self.C, self.D, self.nw, self.nz,
                                      float(g)))
        except np.linalg.LinAlgError:  # a singular pencil (e.g. γ_opt = 0): not decided
            return float("nan")

    def gamma_opt(self, rtol: float = 1e-6, confirm: bool = True,
                  near: float | None = None) -> tuple[float, float, int]:
        """γ_opt by a search between cheap bounds (:func:`_search_gamma`).

        The γ test is the Riccati margin (:meth:`riccati_margin`, a number, so the search
        takes secant steps where SB10AD's job 1 halves from γ = 0: 15 margins of 0.06 ms
        against 23 halvings of 0.1 ms on SGC97's 3 states), checked by SB10AD at the
        ladder's first γ where the margin refuses it and confirmed by SB10AD at the end, at
        the top of the tolerance band ``lo·(1 + rtol)`` if SB10AD (testing the stability of
        its closed loop) refuses Brent's last step within rounding of the root (a 92-state
        D–K plant: margin −3e-11). Otherwise, where SB10AD disagrees, or on a small plant whose
        compiled margin cannot decide at the first γ (e.g. identical channels: the Schur
        form there costs more than SB10AD's test), :meth:`_ladder_job1`.

        Where SB10AD admits a γ that the margin refuses (the first γ, or the search's
        lower end), the closed loop decides: SB10AD's test passes some γ just below γ_opt
        (its Riccati solutions near singular there; a 106-state D–G–K plant: 0.99957 where
        controllers reach no norm below 1.00001), and a controller built at such a γ has a
        closed-loop norm above it. Only a controller that keeps its γ
        (:meth:`_keeps_gamma`) sends the search to :meth:`_ladder_job1`; otherwise the
        margin's result stands.

        ``confirm=False`` leaves out SB10AD's confirmation at the end, for a caller that
        builds a controller near the result and checks its closed loop itself
        (:func:`hinfsyn`). ``near``: a γ expected within a few % of γ_opt (the previous
        D–K step's); on plants above ``_SMALL_STATES`` states the margin's search starts
        there with steps of :data:`NEAR_FACTOR` instead of the ladder of 4 from γ = 1,
        without SB10AD's test of that first γ (the checks at the search's lower end and
        the confirmation stay): the same γ_opt to ``rtol`` in fewer margins.

        Returns ``(hi, lo, tests)``: the smallest admissible γ found, the largest
        inadmissible one (a lower bound of γ_opt; the Parrott bound if none was tried) and
        the number of γ tests (SB10AD calls, Riccati margins and controllers).
        """
        lo0 = self.parrott_bound
        g0 = max(1.5 * lo0, 1.0)
        if near is not None and self.A.shape[0] > _SMALL_STATES:
            sb0 = None
            hi, lo, tests = self.search(rtol, start=near, factor=NEAR_FACTOR)
        else:
            ric0, tests, sb0 = self._small_margin(g0), 1, None  # (g0 > the Parrott bound)
            if np.isnan(ric0):
                if self.A.shape[0] <= _SMALL_STATES:
                    return self._ladder_job1(lo0, g0, None, rtol, tests)
                ric0 = self.riccati_margin(g0)
            if ric0 >= 0:
                sb0, tests = (-1.0 if self.admissible(g0) else 1.0), tests + 1
                if sb0 < 0:
                    tests += 1
                    if self._keeps_gamma(g0):
                        return self._ladder_job1(lo0, g0, sb0, rtol, tests)
                    sb0 = 1.0
            hi, lo, more = self.search(rtol, {g0: ric0})
            tests += more
        if lo > lo0 * (1.0 + 1e-9) and self.riccati_margin(lo) >= 1.0:
            # the margin refused lo for want of a stabilising X∞ ⪰ 0 or Y∞ ⪰ 0 — which a
            # Hamiltonian with eigenvalues near the imaginary axis (a weight's pole near zero) also
            # makes — rather than by ρ(X∞Y∞) ≥ γ²: the search jumped, it did not cross a
            # root. SB10AD's own test decides there (S&P Ex. 2.11, design 2: the margin
            # refused 2.5 where SB10AD and a controller of norm 2.46 admit it).
            tests += 2
            if self.admissible(lo) and self._keeps_gamma(lo):
                return self._ladder_job1(lo0, g0, sb0, rtol, tests + 1)
        if not confirm:  # (hi is a γ the margin admits: _search_gamma)
            return hi, lo, tests
        for g in (hi, lo * (1.0 + rtol)) if lo * (1.0 + rtol) > hi else (hi,):
            tests += 1
            if self.admissible(g):
                return g, lo, tests
        return self._ladder_job1(lo0, g0, sb0, rtol, tests)

    def _keeps_gamma(self, g: float) -> bool:
        """The closed loop's word on a γ that SB10AD admits and the margin refuses: a
        controller built at γ = g has a stable closed loop of norm at most g (the central
        controller of an admissible γ keeps ‖F_l(P, K)‖∞ < γ; Glover & Doyle 1988, Thm
        3.1). No slack: below γ_opt, where SB10AD's test can still pass, the norm lies
        above g, however little."""
        try:
            return self.controller(g).gamma <= g
        except SynthesisError:
            return False

    def _ladder_job1(self, lo0: float, g0: float, sb0: float | None, rtol: float, tests: int):
        """γ_opt with SB10AD only: a ladder of factors 4 from ``g0`` (SB10AD's γ test
        ``sb0`` there, None if not made) to the first change of admissibility, then SB10AD's
        bisection (job 1) from the ladder's admissible top in one call (job 1 bisects from 0
        to the given γ, admissible or not, so the top is tested first). SB10AD's GTOL is
        absolute in γ (measured: job 1's error stays below GTOL whatever the scale of
        γ_opt): ``rtol·lo``, with lo ≤ γ_opt, keeps the relative tolerance ``rtol``."""
        if sb0 is None:
            sb0, tests = (-1.0 if self.admissible(g0) else 1.0), tests + 1
        hi, lo, more = _search_gamma(lambda g: -1.0 if self.admissible(g) else 1.0,
                                     lo0, 3.0, {g0: sb0})
        out, info = self.sb10ad(hi, 1, gtol=rtol * lo)
        g = hi if info else float(out[0])  # on failure keep the bracket's admissible top
        return (g if lo < g <= hi else hi), lo, tests + more + 1

    def controller(self, g: float) -> _Attempt:
        """The controller at γ = g, unscaled, with its closed loop checked stable and its
        norm recomputed (AB13DD, as :func:`hinfnorm`); SynthesisError if SB10AD fails or
        the loop is unstable."""
        out = self.call(g, 4)
        Ak, Bk, Ck, Dk = out[1:5]
        su, sy = self.su, self.sy
        # undo the scaling: u = su ũ, ỹ = sy y
        Ks = (Ak, Bk * sy[None, :], Ck * su[:, None], (Dk * sy[None, :]) * su[:, None])
        try:
            cl = lft_lower_matrices(self.P0, Ks, self.nmeas, self.ncon)
        except ModelError as exc:
            raise SynthesisError(f"hinfsyn: {exc} at γ={g:.6g}") from exc
        if not is_stable(np.linalg.eigvals(cl[0])):
            raise SynthesisError(f"hinfsyn: closed loop unstable at γ={g:.6g}")
        gam, wpk = _linfnorm_matrices(*cl)
        return _Attempt(g, Ks, cl, tuple(float(x) for x in out[9]), gam, wpk)
