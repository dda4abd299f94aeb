"""The γ test of :func:`ambseal.robust.hinf.hinfsyn` for small plants, compiled (numba).

On a plant of a few states the γ test in Python is mostly call overhead (two Schur forms
and ~15 numpy calls: 0.3–0.4 ms on 3 states, more than SLICOT SB10AD's own test), so
:meth:`ambseal.robust.hinf._Sb10.riccati_margin` takes this compiled form for plants of at
most ``_SMALL_STATES`` states (about 0.06 ms on 3 states). The Riccati solutions come from
the eigenvectors of the Hamiltonian's stable eigenvalues (Laub's eigenvector method, Laub
1979, IEEE TAC 24(6)), which is accurate for the well-separated spectra of small plants;
larger plants keep the ordered Schur form of :func:`ambseal.robust._hinf_gamma.game_riccati`.
The refusal rules are the same as there.

Reference: Glover & Doyle (1988), Thm 3.1 (general D11 form); Zhou, Doyle & Glover (1996)
§16–17.
"""

from __future__ import annotations

import numpy as np

from ambseal.lti import cached_njit

__all__ = ["small_margin"]


#: The eigenvectors of the stable eigenvalues are trusted as a basis of the stable subspace
#: while the condition number of their matrix is below this; above it (repeated or nearly
#: defective eigenvalues, e.g. identical channels) the margin is NaN: not decided here.
_MAX_BASIS_COND = 1e6


@cached_njit()
def _game_riccati(A, B, C1, D1, nw, g):
    """``(X, status)``: the stabilising X ⪰ 0 of the H∞ game Riccati equation (as
    :func:`ambseal.robust._hinf_gamma.game_riccati`) from the Hamiltonian's stable
    eigenvectors; status 0: X found; 1: refused (eigenvalues on the imaginary axis to 1e-12
    of the spectral radius, the subspace not a graph, or X ⋡ 0); 2: not decided (the
    eigenvectors are an ill-conditioned basis, ``_MAX_BASIS_COND``)."""
    n = A.shape[0]
    X = np.zeros((n, n))
    # every product of C-ordered operands (numba compiles one per layout pair, each ~0.5 s)
    # and inv rather than solve (compiled in a tenth of the time)
    D1t, C1t, Bt = D1.T.copy(), C1.T.copy(), B.T.copy()
    R = D1t @ D1
    for i in range(nw):
        R[i, i] -= g * g
    Ri = np.linalg.inv(R)
    RiDC, RiBt = Ri @ (D1t @ C1), Ri @ Bt
    Ah = A - B @ RiDC
    H = np.empty((2 * n, 2 * n))
    H[:n, :n] = Ah
    H[:n, n:] = -(B @ RiBt)
    H[n:, :n] = C1t @ (D1 @ RiDC - C1)
    H[n:, n:] = -Ah.T
    if not np.all(np.isfinite(H)):
        return X, 1
    lam, V = np.linalg.eig(H.astype(np.complex128))
    tiny = 1e-12 * max(1.0, np.max(np.abs(lam)))
    stable = np.empty(n, np.int64)
    k = 0
    for i in range(2 * n):
        if lam[i].real < 0.0:
            if k == n or -lam[i].real <= tiny:
                return X, 1
            stable[k] = i
            k += 1
    if k != n:
        return X, 1
    U = np.ascontiguousarray(V[:, stable])
    sv = np.linalg.svd(U)[1]
    if sv[-1] * _MAX_BASIS_COND < sv[0]:
        return X, 2
    U1, U2 = np.ascontiguousarray(U[:n]), np.ascontiguousarray(U[n:])
    sv = np.linalg.svd(U1)[1]
    if sv[-1] < 1e-12 * sv[0]:
        return X, 1
    Xr = (U2 @ np.linalg.inv(U1)).real
    X = 0.5 * (Xr + Xr.T)
    if np.linalg.eigvalsh(X)[0] < -1e-9 * max(1.0, np.max(np.abs(X))):
        return X, 1
    return X, 0


@cached_njit()
def small_margin(A, B, C, D, nw, nz, g):
    """``ρ(X∞Y∞)/γ² − 1`` (< 0: γ admissible), +1 when X∞ ⪰ 0 or Y∞ ⪰ 0 does not exist,
    NaN when the eigenvector method cannot decide (:func:`_game_riccati`, status 2):
    :meth:`ambseal.robust.hinf._Sb10.riccati_margin` for float64 C-ordered
    ``(A, B, C, D)`` with ``nw`` disturbance inputs and ``nz`` performance outputs."""
    if A.shape[0] == 0:
        return -1.0
    X, status = _game_riccati(A, B, np.ascontiguousarray(C[:nz]),
                              np.ascontiguousarray(D[:nz]), nw, g)
    if status:
        return 1.0 if status == 1 else np.nan
    Y, status = _game_riccati(A.T.copy(), C.T.copy(), B[:, :nw].T.copy(),
                              D[:, :nw].T.copy(), nz, g)
    if status:
        return 1.0 if status == 1 else np.nan
    rho = np.max(np.abs(np.linalg.eigvals((X @ Y).astype(np.complex128))))
    return rho / (g * g) - 1.0
