"""Modal reduction to a small real model (thesis P1 §III.4–6, P2 Eq. 3, P4 Eq. 6).

The right and left eigenvectors of the full A_f (P1 Eqs. 18–19) are sorted by |λ| (the
undamped natural frequency) and a set of modes is kept: the lowest ``states`` states, or
every mode with |λ| below a cut-off. P1 writes the kept complex modes in real form
(complex separation, Eqs. 28–34) and then removes the uncontrollable half (Eqs. 35–42);
the result is the real basis of the right invariant subspace of the kept modes,
T_R = [Re v, Im v, ...], and the matching rows T_L from the left eigenvectors, normalised
so that T_L T_R = I. Both are built here directly:

    T_R = [Re v_1, Im v_1, ..., v_real, ...],   W = [Re w_1, Im w_1, ...],
    T_L = (Wᵀ T_R)⁻¹ Wᵀ,

so A = T_L A_f T_R is block diagonal with the real 2×2 blocks [[σ, ω], [−ω, σ]] of P1
Eq. 32 and has exactly the kept eigenvalues; B = T_L B_f, C = C_f T_R (Eqs. 43–45).

A complex pair is told by its conjugate twin, however small its imaginary part. Where the
kept eigenvectors cannot be paired (Wᵀ T_R singular to working precision, or a pair's
Re v and Im v nearly one line: a defective or nearly defective eigenvalue, whose
eigenvectors are not a basis of its invariant subspace) the same invariant subspace is
taken from the ordered real Schur form A_f = Q T Qᵀ, the kept eigenvalues first (Golub &
Van Loan, Matrix Computations, 4th ed., §7.6.2 and §7.6.3): T_R = Q₁ and T_L = Q₁ᵀ − Y Q₂ᵀ
with T₁₁ Y − Y T₂₂ = −T₁₂, the spectral projector's block diagonalisation. T_L T_R = I
again and A = T₁₁ (quasi-triangular, the kept eigenvalues on its diagonal blocks); the
states are named ``schur<k>``.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.linalg as sla

from ambseal.errors import ModelError
from ambseal.lti import lowest_eigenpairs
from ambseal.model.lft import Plant

__all__ = ["ModalReduction", "modal_reduction"]


@dataclass(frozen=True)
class ModalReduction:
    """A reduced plant and its transformation.

    Attributes
    ----------
    plant : Plant
        The reduced plant, x_r = T_L x_f, with its LFT channels transformed.
    T_L : ndarray, shape (n_r, n_f)
    T_R : ndarray, shape (n_f, n_r)
    poles : ndarray, shape (n_r,)
        The kept eigenvalues of A_f (rad/s), sorted by |λ|.
    """

    plant: Plant
    T_L: np.ndarray
    T_R: np.ndarray
    poles: np.ndarray


#: A complex pair's real basis (Re v, Im v) conditioned beyond this is nearly one line: a
#: nearly defective eigenvalue (a Jordan block's twins, split by rounding), whose
#: eigenvectors are no basis of its invariant subspace; the Schur form is taken. A whirl
#: of a rotor symmetric about its axis is circular (Re v ⊥ Im v, of equal lengths: 1),
#: and the ζ and η twins that rounding gives as a conjugate pair are a few units
#: (benchmarks/README.md, "A complex pair told by its twin"). The number is the same for
#: every phase of v (a phase turns (Re v, Im v) by an orthogonal 2 × 2 matrix); the limit
#: is the square root of the whole basis's (1e12).
PAIR_COND = 1e6


def _has_conjugate(lam: np.ndarray, j: int) -> bool:
    """Whether ``lam[j]``, not real, has its conjugate among the other ``lam``: a complex
    pair, however small its imaginary part against the spectrum's size.

    A real matrix's eigensolvers (LAPACK's real QR algorithm, ARPACK's real Arnoldi) give
    a complex pair as exact conjugates and a real eigenvalue with no imaginary part, so a
    pair is told by its twin, not by a tolerance. Taken for two real eigenvalues, a pair
    gives its one real line twice, no basis of its plane (Wᵀ T_R singular), and the
    reduction fell back to the Schur form, whose design model keeps a symmetric rotor's
    ζ/η symmetry less well (benchmarks/README.md, "A complex pair told by its twin": the
    flywheel example's whirls meshed 1.3× finer, and its twins at standstill)."""
    lj = lam[j]
    if lj.imag == 0:
        return False
    d = np.abs(lam - np.conj(lj))
    d[j] = np.inf
    return bool(d.min() <= 1e-12 * abs(lj))


def _real_phase(v: np.ndarray) -> np.ndarray:
    """A real vector spanning the same line as an eigenvector of a real eigenvalue."""
    k = int(np.argmax(np.abs(v)))
    return np.real(v * np.exp(-1j * np.angle(v[k])))


def modal_reduction(
    plant: Plant, *, states: int | None = None, cutoff_hz: float | None = None
) -> ModalReduction:
    """Reduce a full-order plant to its lowest modes.

    Parameters
    ----------
    plant : Plant
        Full-order plant (e.g. :func:`ambseal.model.rig.mechanical_plant`).
    states : int, optional
        Number of states to keep (the lowest modes by |λ|; 8 keeps the rigid-body modes of
        a rotor on two radial AMBs).
    cutoff_hz : float, optional
        Keep every mode with |λ| / 2π below this frequency (Hz).

    Returns
    -------
    ModalReduction
        The reduced plant (real modal coordinates, thesis P1 Eqs. 28–45) with its channels
        transformed, T_L, T_R and the kept poles.

    Raises
    ------
    ModelError
        Neither or both of ``states`` and ``cutoff_hz``; a count that splits a complex pair
        or a repeated eigenvalue; kept eigenvalues the ordered Schur form cannot separate
        from the others.
    """
    if (states is None) == (cutoff_hz is None):
        raise ModelError("modal reduction expects exactly one of states or cutoff_hz")
    n_full = plant.A.shape[0]
    if states is not None and not 1 <= states <= n_full:
        raise ModelError(f"states = {states}: expected 1 to {n_full}")
    lam, V, W, scale = lowest_eigenpairs(
        plant.A, count=0 if states is None else states + 1,
        radius=0.0 if cutoff_hz is None else 2 * np.pi * cutoff_hz, left=True)
    if states is not None:
        n_keep = states
    else:
        n_keep = int(np.sum(np.abs(lam) <= 2 * np.pi * cutoff_hz))
        if n_keep == 0:
            raise ModelError(f"cutoff_hz = {cutoff_hz}: no mode lies below it")
    if n_keep < len(lam):
        gap = abs(abs(lam[n_keep]) - abs(lam[n_keep - 1]))
        if gap <= 1e-9 * scale:
            raise ModelError(
                f"keeping {n_keep} states splits modes of equal |λ| = {abs(lam[n_keep]):.6g} "
                "rad/s (a complex pair or a repeated mode); keep one state more or less"
            )
    kept = lam[:n_keep]
    tol = 1e-9 * scale
    cols_r, cols_l, names, flat = [], [], [], 1.0
    for j, lj in enumerate(kept):
        if abs(lj.imag) <= tol and not _has_conjugate(kept, j):
            cols_r.append(_real_phase(V[:, j]))
            cols_l.append(_real_phase(W[:, j]))
            names.append(f"mode{len(names)}")
        elif lj.imag > 0:
            v = V[:, j] / np.linalg.norm(V[:, j])
            w = W[:, j] / np.linalg.norm(W[:, j])
            flat = max(flat, np.linalg.cond(np.column_stack([v.real, v.imag])))
            cols_r += [v.real, v.imag]
            cols_l += [w.real, w.imag]
            names += [f"mode{len(names)}_re", f"mode{len(names)}_im"]
    if len(cols_r) != n_keep:
        raise ModelError(
            f"keeping {n_keep} states splits a complex-conjugate pair; keep one state more or less"
        )
    T_R = np.column_stack(cols_r)
    Wr = np.column_stack(cols_l)
    P = Wr.T @ T_R
    if np.linalg.cond(P) > 1e12 or flat > PAIR_COND:
        # no eigenvector basis: the invariant subspace itself
        T_L, T_R = _schur_subspace(np.asarray(plant.A, float), n_keep)
        names = [f"schur{k}" for k in range(n_keep)]
    else:
        T_L = np.linalg.solve(P, Wr.T)
    reduced = plant.transformed(T_L, T_R, tuple(names))
    return ModalReduction(plant=reduced, T_L=T_L, T_R=T_R, poles=kept)


def _schur_subspace(A: np.ndarray, n_keep: int) -> tuple[np.ndarray, np.ndarray]:
    """(T_L, T_R) of the invariant subspace of the ``n_keep`` eigenvalues of smallest |λ|
    from the ordered real Schur form (module docstring)."""
    n = A.shape[0]
    if n_keep == n:
        return np.eye(n), np.eye(n)
    # the radius between the kept eigenvalues and the next: the Schur form's sort
    size = np.sort(np.abs(np.linalg.eigvals(A)))
    r = 0.5 * (size[n_keep - 1] + size[n_keep])
    T, Q, sdim = sla.schur(A, output="real", sort=lambda re, im: np.hypot(re, im) < r)
    if sdim != n_keep:
        raise ModelError(f"the ordered Schur form keeps {sdim} eigenvalues below "
                         f"|λ| = {r:.6g} rad/s where {n_keep} were asked for: keep one "
                         "state more or less")
    k = n_keep
    Y = sla.solve_sylvester(T[:k, :k], -T[k:, k:], -T[:k, k:])
    return Q[:, :k].T - Y @ Q[:, k:].T, Q[:, :k]
