"""The eigenvalues of smallest |λ| of a large state matrix, with their eigenvectors.

A modal reduction keeps the lowest modes of a model (modal truncation; Gawronski, *Dynamics
and Control of Structures: A Modal Approach*, 1998) and needs only
their right and left eigenvectors, not all of them: for the state matrix of a fine FE mesh
(1 880 states for 230 beam elements) a dense ``scipy.linalg.eig`` with both sets of
eigenvectors took 7–10 s on one core, shift-invert Arnoldi (ARPACK through
``scipy.sparse.linalg.eigs``: one LU and a few hundred triangular solves) 0.8–1.5 s.
Small matrices keep the dense eig (``DENSE_STATES``).
"""

from __future__ import annotations

import numpy as np
import scipy.linalg as sla
import scipy.sparse.linalg as spla
from scipy.optimize import linear_sum_assignment

from ambseal.errors import ModelError
from ambseal.lti.memo import ArrayMemo

__all__ = ["DENSE_STATES", "lowest_eigenpairs"]

#: States up to which every eigenvalue is taken densely (LAPACK geev): measured on one core
#: 0.2 s for the eigenvalues of 840 states (100 beam elements) and 0.5 s at 1 240, growing
#: with states³ (1.6 s at 1 880, 9–11 s at 3 240; about twice that with eigenvectors),
#: against 0.015–0.07 s for the shift-invert path. Up to here the dense solve is cheap,
#: needs no iteration that could fail to converge, and keeps the numbers small models
#: always had.
DENSE_STATES = 1000
# The shift σ = −SHIFT_FRACTION·‖Â‖₁ (lowest_eigenpairs). Eigenvalues asked of ARPACK
# beyond what the caller needs, at first; doubled until the disk holds what is asked.
# Arnoldi basis ncv = 2k + NCV_EXTRA (ARPACK: ncv ≥ 2k + 1).
SHIFT_FRACTION = 1e-3
EXTRA = 10
NCV_EXTRA = 20
#: The last sparse results, by matrix and request: a plant with and without force inputs
#: (one state matrix) is reduced twice by a design. Shared arrays: not to be modified.
_LOWEST = ArrayMemo(keep=4, min_states=DENSE_STATES)


def lowest_eigenpairs(A: np.ndarray, *, count: int = 0, radius: float = 0.0,
                      left: bool = False):
    """Every eigenvalue of ``A`` inside a disk |λ| < r around 0 that holds at least
    ``count`` eigenvalues and every eigenvalue with |λ| ≤ ``radius`` and at least one
    beyond it; with the right (and left) eigenvectors.

    Up to ``DENSE_STATES`` states every eigenvalue (``scipy.linalg.eig``; the disk is then
    the whole plane). Above, shift-invert Arnoldi (ARPACK through
    ``scipy.sparse.linalg.eigs``; Saad, *Numerical Methods for Large Eigenvalue Problems*,
    2nd ed., 2011, §7.3) on the balanced matrix Â = S⁻¹AS (``scipy.linalg.matrix_balance``,
    diagonal S, as LAPACK balances before its dense eig) at the real shift
    σ = −``SHIFT_FRACTION``·‖Â‖₁: ARPACK's k eigenvalues μ of largest |μ| of (Â − σI)⁻¹
    are the k eigenvalues λ = σ + 1/μ nearest σ, so with r the largest |λ − σ| among them
    every eigenvalue with |λ| < r − |σ| is among them; k is doubled until that disk holds
    what is asked. Why not σ = 0: the state matrix of a second-order model
    [[0, I], [−M⁻¹K, −M⁻¹D]] is inverted through K, whose condition number is
    (ω_max/ω_min)², 1e9 for a 230-element FE model, and the lowest modes then had
    backward errors of 1e-14 on the quadratic pencil; at 10⁻³ of the spectrum's size
    (Tisseur & Meerbergen, "The quadratic eigenvalue problem", SIAM Review 43 (2001), §5)
    the shifted matrix is conditioned near 10⁶ and the backward errors were 6e-17, as
    the dense eig's (measured 7e-15 at 10⁻⁵, 8e-17 at 10⁻⁴). The price: every eigenvalue
    within about |σ| of 0 is computed too. The left eigenvectors come from a second run
    on (Â − σI)⁻ᵀ with the same LU, each matched to the right one of the nearest
    eigenvalue (a one-to-one assignment, so both twins of a double eigenvalue get one).
    k reaching ARPACK's limit n − 1, or a shift on an eigenvalue, falls back to the
    dense eig.

    Parameters
    ----------
    A : ndarray, shape (n, n)
        Real state matrix.
    count : int
        Eigenvalues the disk holds at least.
    radius : float
        The disk holds every eigenvalue with |λ| ≤ ``radius`` and at least one beyond it
        (units of A, e.g. rad/s).
    left : bool
        Also return the left eigenvectors.

    Returns
    -------
    lam : ndarray of complex, shape (k,)
        The eigenvalues, sorted by |λ|.
    V : ndarray of complex, shape (n, k)
        Right eigenvectors, A V = V diag(lam).
    W : ndarray of complex, shape (n, k), or None
        Left eigenvectors, Wᴴ A = diag(lam) Wᴴ (conjugated as ``scipy.linalg.eig`` returns
        them), when ``left``.
    scale : float
        The size of A's spectrum for rounding tolerances: the largest |λ| (dense), or the
        1-norm of the balanced matrix, an upper bound of it (sparse). The sparse path's
        arrays are kept for the last matrices and requests, shared: do not modify them.

    Raises
    ------
    ModelError
        ARPACK fails to converge, or the left eigenvalues do not match the right ones.
    """
    A = np.asarray(A, dtype=float)
    n = A.shape[0]
    if n > DENSE_STATES:
        got = _LOWEST.get((A,), (count, radius, left), lambda: _arnoldi(A, count, radius, left))
        if got is not None:
            return got
    if left:
        lam, W, V = sla.eig(A, left=True, right=True)
    else:
        (lam, V), W = sla.eig(A), None
    order = np.argsort(np.abs(lam), kind="stable")
    return (lam[order], V[:, order], None if W is None else W[:, order],
            float(max(np.abs(lam).max(initial=0.0), 1.0)))


def _arnoldi(A: np.ndarray, count: int, radius: float, left: bool):
    """The sparse path of :func:`lowest_eigenpairs`; None where it must go dense."""
    n = A.shape[0]
    Ab, (s, _) = sla.matrix_balance(A, permute=False, separate=True)
    scale = float(max(np.linalg.norm(Ab, 1), 1.0))
    sigma = -SHIFT_FRACTION * scale
    lu = sla.lu_factor(Ab - sigma * np.eye(n), check_finite=False)
    if np.any(np.diag(lu[0]) == 0.0):  # σ is an eigenvalue
        return None
    k = count + EXTRA
    while k < n - 1:
        lam, V = _run(lu, n, k, sigma, trans=0)
        inside = np.abs(lam) < np.max(np.abs(lam - sigma)) - abs(sigma)
        lam, V = lam[inside], V[:, inside]
        if lam.size >= count and np.count_nonzero(np.abs(lam) > radius) >= 1:
            break
        k *= 2
    else:
        return None
    order = np.argsort(np.abs(lam), kind="stable")
    lam, V = lam[order], s[:, None] * V[:, order]
    W = None
    if left:
        lam_left, Wb = _run(lu, n, k, sigma, trans=1)
        cost = np.abs(lam[:, None] - lam_left[None, :])
        rows, cols = linear_sum_assignment(cost)
        # both runs invert the same shifted matrix: their eigenvalues agree to rounding
        # relative to |λ − σ| (a zero eigenvalue's twins differ by ~ε|σ|)
        tol = 1e-6 * (np.abs(lam[rows]) + abs(sigma))
        if rows.size != lam.size or np.any(cost[rows, cols] > tol):
            raise ModelError(f"the left eigenvectors of the {lam.size} lowest modes do not "
                             "match the right ones (eigenvalues differ by more than 1e-6)")
        W = np.empty_like(V)
        W[:, rows] = Wb[:, cols].conj() / s[:, None]
    return lam, V, W, scale


def _run(lu, n: int, k: int, sigma: float, trans: int):
    """ARPACK's k eigenpairs of largest |μ| of (LU)⁻¹ (``trans`` 1: of its transpose),
    returned as λ = σ + 1/μ."""
    op = spla.LinearOperator((n, n), dtype=float,
                             matvec=lambda x: sla.lu_solve(lu, x, trans=trans,
                                                           check_finite=False))
    try:
        mu, X = spla.eigs(op, k=k, which="LM", v0=np.ones(n), ncv=min(n, 2 * k + NCV_EXTRA))
    except spla.ArpackError as exc:  # includes ArpackNoConvergence
        raise ModelError(f"ARPACK did not converge for the {k} lowest eigenvalues ({exc})"
                         ) from None
    return sigma + 1.0 / mu, X
