"""Modal analysis of the rig model: damped natural frequencies, damping, unstable poles.

Two paths, one result type:

- ``modes(sys)`` — every eigenvalue, by a dense ``scipy.linalg.eig`` of the first-order
  state matrix. Use it when the whole spectrum matters (stability of a model whose unstable
  pole could be anywhere, Campbell data of every mode) or the model is small.
- ``modes(sys, n_modes=n)`` — only the ``n`` lowest modes, by ARPACK
  (``scipy.sparse.linalg.eigs``) in shift-invert mode on the quadratic pencil. Use it when
  only the first few modes are wanted (critical speeds, a Campbell diagram of the lowest
  modes, benchmarks): one LU of the n_dof × n_dof dynamic stiffness (sparse, or dense when
  modal damping fills C) and about 4n + 40 solves (the Arnoldi basis) instead of the QR
  iteration on the whole state matrix. It sees only the eigenvalues nearest zero, so an
  unstable pole beyond them is not reported.

``poles_near_zero(sys, ...)`` gives the eigenvalues (and, if asked, the mode shapes) inside a
disk around 0 that holds what the caller needs — a count, a radius, some oscillating modes —
for the lowest modes of a fine mesh (the design model's size, the modes a command lists):
dense up to :data:`ambseal.lti.lowest.DENSE_STATES` states, the shift-invert path above.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.linalg as sla
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from ambseal.errors import ModelError
from ambseal.lti import DENSE_STATES
from ambseal.model.rig import SecondOrderSystem, build_system

__all__ = ["Modes", "modes", "modes_from_poles", "lowest_eigenvalues", "PoleDisk",
           "poles_near_zero", "free_bending_hz", "bending_limit_hz", "classify_poles",
           "RIGID_BODY_RAD_S", "STABILITY_FLOOR_RAD_S"]

# Thresholds on the physics, not on the stiffest DOF. A computed eigenvalue with
# |λ| below RIGID_BODY_RAD_S = 2π·0.1 Hz is a rigid-body mode (λ = 0): a mode of interest of
# a rotor on bearings, seals and springs lies well above 0.1 Hz (a 70-kg rotor would need a
# support of 28 N/m to sit there). A pole is unstable when Re λ exceeds
# STABILITY_FLOOR_RAD_S = 1e-6 rad/s (an e-folding time of 12 days: neutral for any
# machine) and the rounding level of the eigenvalue solver (below).
RIGID_BODY_RAD_S = 2 * np.pi * 0.1
STABILITY_FLOOR_RAD_S = 1e-6
# Rounding levels of the dense QR eigenvalues of a model whose largest |λ| is ω_max
# (ε = machine epsilon): a simple eigenvalue moves by about ε·ω_max (the balanced state
# matrix has a norm of order ω_max), measured up to 100 ε·ω_max on the test rig's variants;
# a double zero eigenvalue (a rigid-body mode, a Jordan block of λ²) splits by √ε·ω_max
# (Moro, Burke & Overton, SIAM J. Matrix Anal. Appl. 18 (1997)), measured up to 0.3 √ε·ω_max.
# The factors below give a margin of 10 and 3 over those measurements.
REAL_PART_ROUNDING = 1e3
ZERO_ROUNDING = 1.0

# The shift-invert shift is σ = −SHIFT_FRACTION · ω_ref (see ``lowest_eigenvalues``).
SHIFT_FRACTION = 1e-3
# Eigenvalues asked of ARPACK beyond 2n at first: a free–free lateral rotor has 8 rigid-body
# eigenvalues at 0 (x, y, α, β, each a double root of λ²), and one more pair decides
# where the complete disk ends.
EXTRA_EIGENVALUES = 10
# Factor the shifted dynamic stiffness with a sparse LU below this fill (nonzeros / n²);
# above it (e.g. with modal damping, whose C is full) a dense LU is faster.
SPARSE_FILL = 0.1
# Arnoldi basis size ncv = 2k + NCV_EXTRA (ARPACK's rule is ncv ≥ 2k + 1; a few more
# vectors save restarts: measured fastest over the bench rotor, the test rig and the
# turboexpander, free and supported).
NCV_EXTRA = 20
# Arnoldi restarts ARPACK may take before the dense eigenvalues are taken instead: at most
# 3.2 on every example rig, free and supported (measured); a shift that cannot separate
# the wanted eigenvalues (a mesh with µm elements, whose stiffness scale sets σ millions of
# rad/s away from the low modes) took 643 restarts for 22 of them, then failed at 44.
ARNOLDI_RESTARTS = 30


@dataclass(frozen=True)
class Modes:
    """Eigenvalues of a second-order system in the terms a rotordynamicist reads.

    Attributes
    ----------
    natural_frequencies_hz : tuple of float
        Damped natural frequencies Im(λ)/2π (Hz) of the oscillating modes (Im λ at least
        ``RIGID_BODY_RAD_S``: slower motion is no oscillation of interest), ascending;
        rigid-body (λ ≈ 0) and non-oscillating modes are left out.
    damping_ratios : tuple of float
        −Re(λ)/|λ| of the same modes.
    unstable_poles : tuple of (float, float)
        [Re λ, Im λ] (rad/s) of every eigenvalue unstable by :func:`classify_poles` among
        those computed (all of them in the dense path).
    poles : ndarray
        The eigenvalues computed (rad/s), sorted by |λ|: all of them in the dense path,
        those inside the complete disk in the ``n_modes`` path.
    """

    natural_frequencies_hz: tuple[float, ...]
    damping_ratios: tuple[float, ...]
    unstable_poles: tuple[tuple[float, float], ...]
    poles: np.ndarray

    def to_dict(self) -> dict:
        return {
            "natural_frequencies_hz": list(self.natural_frequencies_hz),
            "damping_ratios": list(self.damping_ratios),
            "unstable_poles": [list(p) for p in self.unstable_poles],
        }


def modes(sys: SecondOrderSystem, n_modes: int | None = None) -> Modes:
    """Damped natural frequencies, damping ratios and unstable poles of ``sys``.

    The eigenvalues λ of the first-order form x = [q; q̇] (Friswell et al. 2010, §3.6):
    a mode oscillates at Im λ/2π Hz with damping ratio −Re λ/|λ|. Rigid-body modes and
    unstable poles by :func:`classify_poles` (absolute thresholds in rad/s, a model too
    badly conditioned to tell is refused); its ω_max is the largest |λ| in the dense path
    and ω_ref of :func:`lowest_eigenvalues` in the ``n_modes`` path. In the dense path a
    marginal pole (0 < Re λ < :data:`MARGINAL`·|λ|) whose real part lies within its own
    rounding error (:func:`_real_part_rounding`: an ill-conditioned gyroscopic pole of a
    conservative rotor) is neutral: its real part is taken as 0.

    Parameters
    ----------
    sys : SecondOrderSystem
        The model (n_dof DOFs).
    n_modes : int, optional
        Compute only the ``n_modes`` lowest oscillating modes (by |λ|, i.e. the undamped
        natural frequency; for lightly damped modes the same as the lowest damped ones)
        with :func:`lowest_eigenvalues`. Omitted: every eigenvalue, dense.

    Returns
    -------
    Modes
        With ``n_modes``: at most ``n_modes`` frequencies (fewer only if the model has
        fewer oscillating modes), equal to the dense path's for the same modes to
        rounding (both solve the same pencil: 1e-8 relative or better, except for
        ill-conditioned eigenvalues such as the gyroscopic forward whirl of a free–free
        rotor at speed, where two stable solvers may differ by κ·u; see the tests), and
        ``poles`` / ``unstable_poles`` up to the n-th mode's |λ| only.

    Raises
    ------
    ModelError
        The mass matrix is not positive definite, ``n_modes`` < 1, or the model's
        conditioning makes the rigid-body modes or the stability doubtful.
    """
    if n_modes is not None and (int(n_modes) != n_modes or n_modes < 1):
        raise ModelError(f"n_modes must be a positive integer, got {n_modes!r}")
    try:
        if n_modes is None:
            lam = sys.poles()
            w_max = float(np.abs(lam).max())
            unstable = classify_poles(lam, w_max)[1]
            marginal = unstable & (lam.real < MARGINAL * np.abs(lam))
            if np.any(marginal):  # a neutral pole's rounding may lie above the floor
                neutral = np.zeros(lam.shape, bool)
                neutral[marginal] = lam.real[marginal] <= _real_part_rounding(
                    sys.state_matrices()[0], lam[marginal])
                lam = np.where(neutral, 1j * lam.imag, lam)
            return modes_from_poles(lam, w_max)
        lam, w_ref = lowest_eigenvalues(sys, int(n_modes))
        return modes_from_poles(lam, max(w_ref, float(np.abs(lam).max(initial=0.0))),
                                int(n_modes))
    except ModelError as exc:
        raise ModelError(f"{exc}{_shortest_element(sys)}") from None


#: A pole is marginal when 0 < Re λ < MARGINAL·|λ| (a negative damping ratio below 1e-4,
#: an e-folding over 1 600 periods): only there is its rounding error weighed.
MARGINAL = 1e-4
#: Margin of :func:`real_part_rounding` over the first-order bound.
ROUNDING_MARGIN = 10.0


def _real_part_rounding(A: np.ndarray, lam: np.ndarray) -> np.ndarray:
    """How far rounding may have moved each computed eigenvalue ``lam`` of ``A``:
    ``ROUNDING_MARGIN``·ε·‖B‖_F·κ(λ), B the balanced A (as LAPACK's ``dgeev`` balances
    it) and κ(λ) = ‖x‖‖y‖/|yᴴx| its condition number from the right and left eigenvectors
    (first-order perturbation bound, Wilkinson 1965; Golub & Van Loan 2013, §7.2.2).

    A conservative rotor at speed has its poles on the imaginary axis; near a double zero
    (a free–free rotor's rigid-body modes) its slow gyroscopic poles are ill conditioned
    (κ ~ 3e5 measured) and are computed with real parts of 1e-6 rad/s either sign: a real
    part within this bound is neutral, not a growth.

    Parameters
    ----------
    A : ndarray, shape (n, n)
        The state matrix.
    lam : ndarray of complex
        Eigenvalues of ``A`` (rad/s), as computed.

    Returns
    -------
    ndarray of float
        The bound per eigenvalue (rad/s).
    """
    B = sla.matrix_balance(A, permute=True)[0]
    w, left, right = sla.eig(B, left=True, right=True)
    kappa = (np.linalg.norm(left, axis=0) * np.linalg.norm(right, axis=0)
             / np.maximum(np.abs(np.sum(left.conj() * right, axis=0)), np.finfo(float).tiny))
    nearest = np.argmin(np.abs(np.asarray(lam)[:, None] - w[None, :]), axis=1)
    return ROUNDING_MARGIN * np.finfo(float).eps * np.linalg.norm(B) * kappa[nearest]


def _shortest_element(sys: SecondOrderSystem) -> str:
    """Where the mesh's shortest beam element lies, for a message on the conditioning."""
    z = getattr(getattr(sys, "mesh", None), "z", None)
    if z is None or len(z) < 2:
        return ""
    e = int(np.argmin(np.diff(z)))
    return (f"; the shortest beam element is {z[e + 1] - z[e]:.3g} m long, at z = "
            f"{z[e]:.6g}–{z[e + 1]:.6g} m")


def classify_poles(lam: np.ndarray, w_max: float | None = None,
                   where: str = "model") -> tuple[np.ndarray, np.ndarray]:
    """Which eigenvalues are rigid-body modes (λ = 0) and which are unstable.

    On the physics, not relative to the stiffest DOF: rigid when |λ| < ``RIGID_BODY_RAD_S``
    (2π·0.1 Hz); unstable when Re λ > max(``STABILITY_FLOOR_RAD_S``, 1e3·ε·ω_max), the
    second term the rounding level of the solver on a model whose largest |λ| is ω_max
    (see the constants of this module for the measurements behind the factors).

    Parameters
    ----------
    lam : ndarray of complex
        Eigenvalues (rad/s).
    w_max : float, optional
        The largest |λ| of the model (rad/s); default max |lam|.
    where : str
        Named in the error message.

    Returns
    -------
    rigid, unstable : ndarray of bool
        Masks over ``lam``.

    Raises
    ------
    ModelError
        The model's conditioning makes the answer doubtful: a rigid-body mode cannot be told
        from a mode below √ε·ω_max, or a real part from zero within 1e3·ε·ω_max while that
        level is above 1e-3 rad/s (a stiff DOF — e.g. a 1e16 N/m spring, a micrometre-long
        element — spreads the model over too many decades).
    """
    lam = np.asarray(lam, dtype=complex)
    size = np.abs(lam)
    w_max = float(size.max(initial=0.0)) if w_max is None else float(w_max)
    eps = np.finfo(float).eps
    zero_noise = ZERO_ROUNDING * np.sqrt(eps) * w_max
    re_noise = REAL_PART_ROUNDING * eps * w_max
    rigid = size < RIGID_BODY_RAD_S
    doubtful = (size >= RIGID_BODY_RAD_S) & (size < zero_noise)
    if np.any(doubtful):
        raise ModelError(
            f"{where}: eigenvalue {_fmt(lam[doubtful][0])} rad/s cannot be told from a "
            f"rigid-body mode: the largest |λ| is {w_max:.3g} rad/s, so eigenvalues near "
            f"zero are uncertain by {zero_noise:.3g} rad/s (a very stiff spring or a very "
            "short shaft element; soften or remove it)")
    unsure = ~rigid & (np.abs(lam.real) <= re_noise) & (re_noise > 1e-3)
    if np.any(unsure):
        raise ModelError(
            f"{where}: the stability of the pole {_fmt(lam[unsure][0])} rad/s cannot be "
            f"decided: its real part is below the rounding level {re_noise:.3g} rad/s of a "
            f"model whose largest |λ| is {w_max:.3g} rad/s (a very stiff spring or a very "
            "short shaft element; soften or remove it)")
    unstable = ~rigid & (lam.real > max(STABILITY_FLOOR_RAD_S, re_noise))
    return rigid, unstable


def _fmt(z: complex) -> str:
    return f"{z.real:.4g}{z.imag:+.4g}j"


def modes_from_poles(lam: np.ndarray, w_max: float, n_modes: int | None = None) -> Modes:
    """:class:`Modes` from eigenvalues of a second-order system, e.g. a
    :class:`PoleDisk`'s (what :func:`modes` returns for the eigenvalues it computes).

    Parameters
    ----------
    lam : ndarray of complex
        Eigenvalues (rad/s): all of them, or every one inside a disk around 0.
    w_max : float
        The largest |λ| of the model (rad/s), the scale of :func:`classify_poles`.
    n_modes : int, optional
        Keep the first ``n_modes`` oscillating modes by |λ| and the poles up to them.

    Returns
    -------
    Modes

    Raises
    ------
    ModelError
        The conditioning makes the rigid-body modes or the stability doubtful
        (:func:`classify_poles`).
    """
    lam = lam[np.argsort(np.abs(lam), kind="stable")]
    rigid, unstable = classify_poles(lam, w_max)
    osc = lam[(lam.imag >= RIGID_BODY_RAD_S) & ~rigid]
    if n_modes is not None and osc.size > n_modes:
        keep = np.abs(lam) <= np.abs(osc[n_modes - 1])
        lam, unstable, osc = lam[keep], unstable[keep], osc[:n_modes]
    osc = osc[np.argsort(osc.imag)]
    unstable = lam[unstable]
    unstable = unstable[np.argsort(-unstable.real)]
    return Modes(
        natural_frequencies_hz=tuple(float(x) for x in osc.imag / (2 * np.pi)),
        damping_ratios=tuple(float(x) for x in -osc.real / np.abs(osc)),
        unstable_poles=tuple((float(p.real), float(p.imag)) for p in unstable),
        poles=lam,
    )


def lowest_eigenvalues(sys: SecondOrderSystem, n_modes: int) -> tuple[np.ndarray, float]:
    """Every eigenvalue of M λ²q + (C + ΩG) λq + K q = 0 inside a disk around 0 that
    holds at least ``n_modes`` oscillating modes.

    Shift-invert Arnoldi (ARPACK via ``scipy.sparse.linalg.eigs``) on the first-order
    pencil A x = λ B x, A = [[0, I], [−K, −D]], B = diag(I, M), D = C + ΩG, with the
    operator (A − σB)⁻¹B applied through the n_dof × n_dof dynamic stiffness
    K + σD + σ²M only (the companion linearisation and shift-and-invert transformation of
    Tisseur & Meerbergen, "The quadratic eigenvalue problem", SIAM Review 43 (2001)):
    for x = [x₁; x₂], (K + σD + σ²M) z₁ = −M x₂ − (D + σM) x₁ and z₂ = x₁ + σ z₁;
    then λ = σ + 1/μ for each eigenvalue μ of the operator.

    The shift σ = −10⁻³ ω_ref is real and negative, with ω_ref = sqrt(max_i |K_ii|/M_ii)
    the largest diagonal Rayleigh quotient of (K, M) (by Rayleigh's principle a lower
    bound of the highest undamped natural frequency). A free–free rotor has rigid-body
    eigenvalues at exactly 0 (defective: λ² = 0), where K + σD + σ²M is singular; at
    this σ, σ²M is 10⁻⁶ of the stiffest diagonal term, so the shifted dynamic stiffness
    keeps a condition number near 10⁶ and the solves about ten digits. Smaller shifts
    cost accuracy on free–free rotors (measured: backward error 5e-12 at 10⁻⁴ ω_ref
    against 5e-15 at 10⁻³ on the turboexpander); larger ones need more eigenvalues for
    the same complete disk. ARPACK orders eigenvalues by |λ − σ|, this function by |λ|,
    hence the disk below.

    Completeness: ARPACK returns the k eigenvalues nearest σ; with r the largest distance
    |λ − σ| among them, every eigenvalue with |λ| < r − |σ| is among them. The call
    asks for k = 2 n_modes + 10 and doubles k until that disk holds ``n_modes``
    oscillating modes and is at least 1.5 times the largest of their |λ|, so a mode left
    out has |λ| above 1.5× the returned ones. When k would reach n_state − 1 (ARPACK's
    limit) the dense eigenvalues are used.

    Parameters
    ----------
    sys : SecondOrderSystem
        The model.
    n_modes : int
        Oscillating modes wanted (each a conjugate pair).

    Returns
    -------
    lam : ndarray of complex
        The eigenvalues (rad/s) inside the complete disk, sorted by |λ|.
    w_ref : float
        ω_ref (rad/s), the scale for the tolerances of :func:`modes`.

    Raises
    ------
    ModelError
        The mass matrix is not positive definite, or ARPACK fails (not for want of
        convergence: the dense eigenvalues are then taken).
    """
    sys.mass_factor()  # ModelError unless M is positive definite, as in the dense path
    w_ref = _w_ref(sys)

    def enough(lam: np.ndarray, radius: float) -> bool:
        osc = np.sort(np.abs(lam[lam.imag >= RIGID_BODY_RAD_S]))
        return osc.size >= n_modes and radius >= 1.5 * osc[n_modes - 1]

    got = _arnoldi_disk(sys, w_ref, 2 * n_modes + EXTRA_EIGENVALUES, enough, vectors=False)
    return (sys.poles(), w_ref) if got is None else (got[0], w_ref)


@dataclass(frozen=True)
class PoleDisk:
    """Every eigenvalue of a second-order system inside a disk |λ| < ``radius_rad_s``.

    Attributes
    ----------
    poles : ndarray of complex, shape (k,)
        The eigenvalues (rad/s), sorted by |λ|.
    shapes : ndarray of complex, shape (n_dof, k), or None
        The displacement part q of each eigenvector (x = [q; λq]), if asked for.
    radius_rad_s : float
        Radius of the disk (rad/s); ``inf`` when every eigenvalue was computed (dense).
    w_max : float
        The scale (rad/s) for :func:`classify_poles`: the largest |λ| when dense, else
        ω_ref of :func:`lowest_eigenvalues`.
    """

    poles: np.ndarray
    shapes: np.ndarray | None
    radius_rad_s: float
    w_max: float


def poles_near_zero(sys: SecondOrderSystem, *, count: int = 0, radius_rad_s: float = 0.0,
                    oscillating: int = 0, vectors: bool = False) -> PoleDisk:
    """Every eigenvalue of M λ²q + (C + ΩG) λq + K q = 0 inside a disk around 0 that holds
    at least ``count`` eigenvalues, at least ``oscillating`` oscillating modes
    (Im λ ≥ ``RIGID_BODY_RAD_S``) and every eigenvalue with |λ| < ``radius_rad_s``.

    Up to :data:`ambseal.lti.lowest.DENSE_STATES` states (2·n_dof; 1 000, where the dense
    eigenvalues take 0.3 s) every eigenvalue, by a dense eig of the state matrix (the disk
    is then the whole plane); above, the shift-invert Arnoldi iteration of
    :func:`lowest_eigenvalues` on the quadratic pencil (Tisseur & Meerbergen 2001), whose
    k eigenvalues nearest σ hold every eigenvalue with |λ| < r − |σ| (r the largest
    |λ − σ| among them), k doubled until that disk holds what is asked; the dense eig when
    k would reach ARPACK's limit n_state − 1. Eigenvectors of the shifted-and-inverted
    operator are those of the pencil, x = [q; λq].

    Parameters
    ----------
    sys : SecondOrderSystem
        The model (n_dof DOFs).
    count : int
        Eigenvalues the disk holds at least (the lowest ``count`` by |λ| are then exact).
    radius_rad_s : float
        Radius (rad/s) the disk has at least.
    oscillating : int
        Oscillating modes (each a conjugate pair) the disk holds at least.
    vectors : bool
        Also return the displacement part of each eigenvector.

    Returns
    -------
    PoleDisk
        The eigenvalues sorted by |λ| (and the shapes, columns in the same order).

    Raises
    ------
    ModelError
        The mass matrix is not positive definite, or ARPACK fails (not for want of
        convergence: the dense eigenvalues are then taken).
    """
    if 2 * sys.n_dof > DENSE_STATES:
        sys.mass_factor()  # ModelError unless M is positive definite, as in the dense path
        w_ref = _w_ref(sys)

        def enough(lam: np.ndarray, radius: float) -> bool:
            n_osc = np.count_nonzero(lam.imag >= RIGID_BODY_RAD_S)
            return lam.size >= count and n_osc >= oscillating and radius > radius_rad_s

        k = max(count, 2 * oscillating) + EXTRA_EIGENVALUES
        got = _arnoldi_disk(sys, w_ref, k, enough, vectors)
        if got is not None:
            return PoleDisk(got[0], got[1], got[2], w_ref)
    A = sys.state_matrices()[0]
    if vectors:
        lam, X = sla.eig(A)
    else:
        lam, X = sla.eigvals(A), None
    order = np.argsort(np.abs(lam), kind="stable")
    return PoleDisk(lam[order], None if X is None else X[:sys.n_dof, order], np.inf,
                    float(np.abs(lam).max(initial=0.0)))


def _w_ref(sys: SecondOrderSystem) -> float:
    """ω_ref = sqrt(max_i |K_ii|/M_ii) (rad/s), the scale of the shift (``lowest_eigenvalues``)."""
    return float(np.sqrt(np.max(np.abs(np.diag(sys.K)) / np.diag(sys.M))))


def _arnoldi_disk(sys: SecondOrderSystem, w_ref: float, k: int, enough, vectors: bool):
    """``(lam, Q, radius)``: the eigenvalues inside the complete disk |λ| < radius of the
    k nearest σ = −``SHIFT_FRACTION``·ω_ref, sorted by |λ|, with the displacement parts Q
    of their eigenvectors (or None), k doubled until ``enough(lam, radius)``; None when k
    would reach n_state − 1 or ARPACK does not converge in :data:`ARNOLDI_RESTARTS`
    restarts (the caller goes dense)."""
    M, K = sys.M, sys.K
    D = sys.C + sys.speed * sys.G
    n = sys.n_dof
    sigma = -SHIFT_FRACTION * w_ref
    op = None
    while k < 2 * n - 1:
        if op is None:
            op = _shift_invert_operator(M, D, K, sigma)
        try:
            out = spla.eigs(op, k=k, which="LM", v0=np.ones(2 * n),
                            ncv=min(2 * n, 2 * k + NCV_EXTRA), return_eigenvectors=vectors,
                            maxiter=ARNOLDI_RESTARTS)
        except spla.ArpackNoConvergence:
            return None  # the dense eigenvalues: what the model's size costs
        except spla.ArpackError as exc:
            raise ModelError(f"ARPACK failed for the {k} eigenvalues nearest "
                             f"σ = {sigma:.3g} rad/s ({exc})") from None
        mu, X = out if vectors else (out, None)
        lam = sigma + 1.0 / mu
        radius = float(np.max(np.abs(lam - sigma)) - abs(sigma))
        inside = np.abs(lam) < radius
        lam = lam[inside]
        if enough(lam, radius):
            order = np.argsort(np.abs(lam), kind="stable")
            return lam[order], (None if X is None else X[:n][:, inside][:, order]), radius
        k *= 2
    return None


def _shift_invert_operator(M: np.ndarray, D: np.ndarray, K: np.ndarray,
                           sigma: float) -> spla.LinearOperator:
    """x ↦ (A − σB)⁻¹ B x for the pencil of :func:`lowest_eigenvalues`, as a LinearOperator."""
    n = M.shape[0]
    Z = K + sigma * D + sigma**2 * M
    R = -np.hstack([D + sigma * M, M])  # right-hand side −(D + σM) x₁ − M x₂ = R x
    if np.count_nonzero(Z) < SPARSE_FILL * n * n:
        solve = spla.splu(sp.csc_array(Z)).solve
        R = sp.csr_array(R)
    else:
        fac = sla.lu_factor(Z, check_finite=False)
        solve = lambda b: sla.lu_solve(fac, b, check_finite=False)  # noqa: E731

    def matvec(x: np.ndarray) -> np.ndarray:
        x = np.asarray(x).reshape(-1)
        z1 = solve(R @ x)
        return np.concatenate([z1, x[:n] + sigma * z1])

    return spla.LinearOperator((2 * n, 2 * n), matvec=matvec, dtype=float)


#: Bending modes a default modal analysis covers ("a few"), and the margin above the last.
BENDING_MODES = 3
BENDING_MARGIN = 1.25


def free_bending_hz(cfg, n_bending: int = BENDING_MODES) -> tuple[float, ...]:
    """The ``n_bending`` lowest bending frequencies (Hz) of the free–free rotor (shaft and
    disks only, standstill).

    A free–free lateral rotor's bending modes come in pairs (the x–z and y–z planes, equal
    at standstill), so the k-th bending frequency is the 2k-th oscillating mode.

    Parameters
    ----------
    cfg : RigConfig
        The rig; only its shaft, materials and disks are used.
    n_bending : int
        How many bending frequencies (≥ 1).

    Returns
    -------
    tuple of float
        The bending frequencies (Hz), ascending.

    Raises
    ------
    ModelError
        The rotor cannot be built.
    """
    free = build_system(cfg, speed_rpm=0.0, include_amb=False, include_seals=False,
                        include_springs=False)
    f = modes(free, n_modes=2 * n_bending).natural_frequencies_hz
    return tuple(float(x) for x in f[1::2][:n_bending])


def bending_limit_hz(cfg, n_bending: int = BENDING_MODES) -> float:
    """Default upper frequency (Hz) of a modal analysis: ``BENDING_MARGIN`` (1.25) × the
    ``n_bending``-th free–free bending frequency (:func:`free_bending_hz`).

    The limit keeps the rigid-body, actuator and controller modes of a closed loop and a
    few bending modes, not the whole FE spectrum.

    Parameters
    ----------
    cfg : RigConfig
        The rig; only its shaft, materials and disks are used.
    n_bending : int
        The bending mode whose frequency sets the limit (≥ 1).

    Returns
    -------
    float
        The limit (Hz).

    Raises
    ------
    ModelError
        The rotor cannot be built.
    """
    return BENDING_MARGIN * free_bending_hz(cfg, n_bending)[-1]
