"""Tests of the structured LMI solver (robust/_lmi_sdp.py) against closed forms and against
CVXOPT's own dense KKT solver.

References: the Lyapunov inequality AᵀX + XA + Q ⪯ 0 of a stable A has its least solution
at the Lyapunov equation's (any feasible X minus it solves AᵀΔ + ΔA ⪯ 0, so Δ ⪰ 0);
the bounded-real lemma (Boyd, El Ghaoui, Feron & Balakrishnan 1994, §2.7.3): the least γ
with X ≻ 0 and [AᵀX + XA, XB, Cᵀ; BᵀX, −γI, Dᵀ; C, D, −γI] ⪯ 0 is ‖G‖∞ (SLICOT AB13DD
through python-control).
"""

from __future__ import annotations

import cvxopt
import numpy as np
import pytest
import scipy.linalg as sla
from cvxopt import solvers

from ambseal.robust import _lmi_sdp as sdp

ct = pytest.importorskip("control")


def _stable(n, rng):
    A = rng.standard_normal((n, n))
    return A - (np.abs(np.linalg.eigvals(A)).max() + 0.5) * np.eye(n)


def test_lyapunov_inequality_reaches_the_lyapunov_solution():
    rng = np.random.default_rng(1)
    n = 6
    A = _stable(n, rng)
    M = rng.standard_normal((n, n))
    Q = M @ M.T + np.eye(n)
    lmi = sdp.Lmi(-Q, None, (sdp.LmiTerm(0, A.T, -np.eye(n)),))  # −(AᵀX + XA + Q) ⪰ 0
    sol = sdp.solve_lmis([lmi], n, 1, None, [1.0], {"reltol": 1e-8, "abstol": 1e-9})
    X_lyap = sla.solve_continuous_lyapunov(A.T, -Q)
    assert sol.status == "optimal"
    np.testing.assert_allclose(sol.X[0], X_lyap, rtol=1e-5, atol=1e-6 * np.abs(X_lyap).max())


def test_bounded_real_lemma_gives_the_hinf_norm():
    rng = np.random.default_rng(2)
    n, m, p = 5, 2, 3
    A = _stable(n, rng)
    B, C = rng.standard_normal((n, m)), rng.standard_normal((p, n))
    D = 0.1 * rng.standard_normal((p, m))
    d = n + m + p
    Z = np.zeros
    J = np.vstack([np.eye(n), Z((m + p, n))])
    U = np.vstack([A.T, B.T, Z((p, n))])
    const = -np.block([[Z((n, n)), Z((n, m)), C.T], [Z((m, n)), Z((m, m)), D.T],
                       [C, D, Z((p, p))]])
    gam = sla.block_diag(Z((n, n)), np.eye(m + p))
    lmis = [sdp.Lmi(const, gam, (sdp.LmiTerm(0, J, -U),)),
            sdp.Lmi(Z((n, n)), None, (sdp.LmiTerm(0, np.eye(n), 0.5 * np.eye(n)),))]
    sol = sdp.solve_lmis(lmis, n, 1, 1.0, [0.0], {"reltol": 1e-8, "abstol": 1e-9})
    ref = ct.norm(ct.ss(A, B, C, D), "inf")
    assert sol.status == "optimal" and d == lmis[0].size
    assert sol.gamma == pytest.approx(ref, rel=1e-5)


def test_same_optimum_as_cvxopts_dense_solver():
    """Two matrix variables, γ, terms with P ≠ Q, a coupling LMI: the structured Schur
    complement and CVXOPT's default KKT solver on the explicit G matrix agree."""
    rng = np.random.default_rng(3)
    n, d = 3, 5

    def sym(k):
        M = rng.standard_normal((k, k))
        return M + M.T

    lmis = [sdp.Lmi(sym(d) + 20 * np.eye(d), np.eye(d),
                    (sdp.LmiTerm(0, rng.standard_normal((d, n)), rng.standard_normal((d, n))),
                     sdp.LmiTerm(1, rng.standard_normal((d, n)), rng.standard_normal((d, n))))),
            sdp.Lmi(sym(4) + 20 * np.eye(4), None,
                    (sdp.LmiTerm(1, rng.standard_normal((4, n)), rng.standard_normal((4, n))),)),
            sdp.Lmi(np.zeros((2 * n, 2 * n)), None,
                    (sdp.LmiTerm(0, np.eye(2 * n)[:, :n], 0.5 * np.eye(2 * n)[:, :n]),
                     sdp.LmiTerm(1, np.eye(2 * n)[:, n:], 0.5 * np.eye(2 * n)[:, n:])))]
    cost = [0.3, 0.2]
    sol = sdp.solve_lmis(lmis, n, 2, 1.0, cost, {"reltol": 1e-8, "abstol": 1e-9})
    # the same program written out: x = [γ, vech X0, vech X1], G columns from unit vectors
    I, J = np.tril_indices(n)
    m = I.size

    def unit_matrix(k):
        E = np.zeros((n, n))
        E[I[k], J[k]] = E[J[k], I[k]] = 1.0
        return E

    cols = []
    for k in range(1 + 2 * m):
        col = []
        for lmi in lmis:
            S = np.zeros((lmi.size, lmi.size))
            if k == 0 and lmi.gamma is not None:
                S = lmi.gamma.copy()
            for t in lmi.terms:
                if k > 0 and (k - 1) // m == t.var:
                    X = unit_matrix((k - 1) % m)
                    S += t.P @ X @ t.Q.T + t.Q @ X @ t.P.T
            col.append(-S.ravel(order="F"))
        cols.append(np.concatenate(col))
    c = np.concatenate([[1.0], cost[0] * (I == J), cost[1] * (I == J)])
    h = np.concatenate([lmi.const.ravel(order="F") for lmi in lmis])
    ref = solvers.conelp(cvxopt.matrix(c), cvxopt.matrix(np.array(cols).T), cvxopt.matrix(h),
                         {"l": 0, "q": [], "s": [lmi.size for lmi in lmis]},
                         options={"show_progress": False, "reltol": 1e-8, "abstol": 1e-9})
    assert sol.status == ref["status"] == "optimal"
    x = np.asarray(ref["x"])[:, 0]
    assert sol.gamma == pytest.approx(x[0], rel=1e-6, abs=1e-6)
    for v in range(2):
        Xr = np.zeros((n, n))
        Xr[I, J] = Xr[J, I] = x[1 + v * m:1 + (v + 1) * m]
        np.testing.assert_allclose(sol.X[v], Xr, rtol=1e-5, atol=1e-5 * np.abs(Xr).max())


@pytest.mark.parametrize("rows", [64, 3])
def test_schur_complement_is_its_definition(monkeypatch, rows):
    """H = Σ_j 𝒜_jᵀ 𝒜_j (scaled LMIs, Z = I) entry by entry from unit vectors: terms on
    three variables in any order, one variable twice in an LMI, LMIs with and without γ;
    its vech rows formed all at once or a few at a time. H is Fortran-ordered: LAPACK
    factorises it where it lies."""
    monkeypatch.setattr(sdp, "_SCHUR_ROWS", rows)
    rng = np.random.default_rng(4)
    n = 4

    def sym(k):
        M = rng.standard_normal((k, k))
        return M + M.T

    def term(v, d):
        return sdp.LmiTerm(v, rng.standard_normal((d, n)), rng.standard_normal((d, n)))

    lmis = [sdp.Lmi(sym(5), sym(5), (term(0, 5), term(1, 5), term(2, 5))),
            sdp.Lmi(sym(6), None, (term(2, 6), term(1, 6), term(1, 6))),
            sdp.Lmi(sym(3), sym(3), (term(1, 3), term(0, 3)))]
    lay = sdp._Layout(n, 3, True)
    E = np.eye(lay.size)
    ref = np.array([[sum(np.sum(sdp._lin(lmi, lay, E[i]) * sdp._lin(lmi, lay, E[k]))
                         for lmi in lmis) for k in range(lay.size)] for i in range(lay.size)])
    H = sdp._schur(lmis, lay)
    np.testing.assert_allclose(H, ref, rtol=1e-12, atol=1e-12 * np.abs(ref).max())
    assert H.flags.f_contiguous
    # on the matrices a pairing leaves invariant, x = E x̃: Eᵀ H E, whatever the LMIs
    red = sdp._Reduced(lay, 3, sdp.StatePairing(np.array([0, 2]), np.array([1, 3]),
                                                np.array([1.0, -1.0])))
    E = np.stack([red.expand(e) for e in np.eye(red.size)], axis=1)
    Hr = sdp._schur(lmis, lay, red)
    np.testing.assert_allclose(Hr, E.T @ ref @ E, rtol=1e-12,
                               atol=1e-12 * np.abs(ref).max())
    assert Hr.flags.f_contiguous and Hr.shape == (1 + 3 * 4,) * 2  # (n/2)² per matrix


def test_an_invariant_sdp_is_solved_on_its_invariant_matrices():
    """Reference: the same SDP on all symmetric matrices. LMIs and cost invariant under
    X ↦ TᵀXT for the pairing's T (orthogonal, T² = −I; A commuting with T): a Lyapunov
    inequality, γI ⪰ X and Y ⪰ 2X, minimising γ + tr X + tr Y. The invariant unknowns,
    (n/2)² per matrix against n(n+1)/2, give the same optimum, and every matrix of them
    is invariant."""
    rng = np.random.default_rng(0)
    n = 8
    pairing = sdp.StatePairing(np.arange(0, n, 2), np.arange(1, n, 2),
                               np.array([1.0, -1.0, 1.0, -1.0]))
    T = pairing.matrix(n)
    np.testing.assert_array_equal(T.T @ T, np.eye(n))
    np.testing.assert_array_equal(T @ T, -np.eye(n))
    M = rng.standard_normal((n, n)) - 3 * np.eye(n)
    A = 0.5 * (M + T.T @ M @ T)  # commutes with T
    eye = np.eye(n)
    lmis = [sdp.Lmi(-eye, None, (sdp.LmiTerm(0, eye, -A.T),)),
            sdp.Lmi(np.zeros((n, n)), eye, (sdp.LmiTerm(0, eye, -0.5 * eye),)),
            sdp.Lmi(np.zeros((n, n)), None, (sdp.LmiTerm(1, eye, 0.5 * eye),
                                             sdp.LmiTerm(0, eye, -eye)))]
    opts = {"abstol": 1e-9, "reltol": 1e-9, "feastol": 1e-9, "refinement": 2}
    whole = sdp.solve_lmis(lmis, n, 2, 1.0, [1.0, 1.0], opts)
    inv = sdp.solve_lmis(lmis, n, 2, 1.0, [1.0, 1.0], opts, pairing)
    assert whole.status == inv.status == "optimal"
    assert inv.gamma == pytest.approx(whole.gamma, rel=1e-9)
    for Xw, Xi in zip(whole.X, inv.X):
        np.testing.assert_allclose(Xi, Xw, rtol=1e-6, atol=1e-8 * np.abs(Xw).max())
        np.testing.assert_allclose(T.T @ Xi @ T, Xi, rtol=0, atol=1e-12 * np.abs(Xi).max())


def test_infeasible_lmis_are_reported():
    """X ⪯ −I and X ⪰ 0 together: CVXOPT's primal infeasibility certificate."""
    n = 2
    lmis = [sdp.Lmi(-np.eye(n), None, (sdp.LmiTerm(0, np.eye(n), -0.5 * np.eye(n)),)),
            sdp.Lmi(np.zeros((n, n)), None, (sdp.LmiTerm(0, np.eye(n), 0.5 * np.eye(n)),))]
    sol = sdp.solve_lmis(lmis, n, 1, None, [1.0], {})
    assert sol.status == "infeasible"


def test_a_point_where_the_lmis_hold_certifies_without_the_solvers_optimal():
    """An LMI holds where its smallest eigenvalue is at least −margin/2 (the strict LMI it
    stands for keeps half its margin) or, without a margin, −1e-9 of its largest; on the
    Lyapunov inequality with its solver stopped one iteration short of "optimal" (CVXOPT:
    "unknown", as its 3.12 build ends on the LPV SDPs), with lpvsyn's margin, the point
    returned satisfies the LMI and the status is "feasible", its X within 1e-3 of the
    optimum's."""
    lay = sdp._Layout(2, 1, False)
    x = np.zeros(lay.size)  # X = 0: each LMI is its constant
    for margin, low, ok in ((1e-6, -0.4e-6, True), (1e-6, -0.6e-6, False),
                            (0.0, -0.5e-9, True), (0.0, -2e-9, False)):
        lmi = sdp.Lmi(np.diag([1.0, low]), None, (sdp.LmiTerm(0, np.eye(2), np.eye(2)),),
                      margin)
        assert sdp.holds([lmi], lay, x) is ok
    rng = np.random.default_rng(1)
    n = 6
    A = _stable(n, rng)
    M = rng.standard_normal((n, n))
    margin = 1e-6  # lpvsyn's default
    lmi = sdp.Lmi(-(M @ M.T + np.eye(n)) - margin * np.eye(n), None,
                  (sdp.LmiTerm(0, A.T, -np.eye(n)),), margin)
    opts = {"reltol": 1e-8, "abstol": 1e-9}
    best = sdp.solve_lmis([lmi], n, 1, None, [1.0], opts)
    assert best.status == "optimal" and best.iterations > 2
    short = sdp.solve_lmis([lmi], n, 1, None, [1.0], opts | {"maxiters": best.iterations - 1})
    assert short.status == "feasible" and short.iterations == best.iterations - 1
    np.testing.assert_allclose(short.X[0], best.X[0], rtol=1e-3,
                               atol=1e-3 * np.abs(best.X[0]).max())
