"""The lowest eigenpairs of a large state matrix (``ambseal.lti.lowest``) against matrices
with known eigenvalues and against the dense ``scipy.linalg.eig``."""

from __future__ import annotations

import numpy as np
import pytest
import scipy.linalg as sla

import ambseal.lti.lowest as low


def _known(n_pairs: int, seed: int = 3, double: bool = False):
    """A real A = T Λ_r T⁻¹ with known eigenvalues: lightly damped pairs (ζ 1e-3…0.1) at
    ω_k ∝ (2k + 1)², k = 0…n_pairs − 1, from 11 to 1e6 rad/s (a beam's bending modes: few
    low ones, most near the top), in real 2×2 blocks mixed by a random well-conditioned T.
    ``double``: every pair twice, exactly (an axisymmetric rotor's x–z and y–z planes)."""
    rng = np.random.default_rng(seed)
    k = np.arange(n_pairs // 2 if double else n_pairs)
    w = 1e6 * ((2 * k + 1) / (2 * k[-1] + 1)) ** 2
    z = rng.uniform(1e-3, 0.1, k.size)
    if double:
        w, z = np.repeat(w, 2), np.repeat(z, 2)
    lam = -z * w + 1j * w * np.sqrt(1 - z**2)
    blocks = [np.array([[x.real, x.imag], [-x.imag, x.real]]) for x in lam]
    n = 2 * len(lam)
    T = np.eye(n) + 0.3 * rng.standard_normal((n, n)) / np.sqrt(n)
    A = T @ sla.block_diag(*blocks) @ np.linalg.inv(T)
    ref = np.concatenate([lam, lam.conj()])
    return A, ref[np.argsort(np.abs(ref), kind="stable")]


def _check_pairs(A, lam, V, W):
    """Right and left eigenvector residuals relative to ‖A‖ (backward stable: ~1e-12)."""
    nA = np.linalg.norm(A, 1)
    r = np.linalg.norm(A @ V - V * lam, axis=0) / np.linalg.norm(V, axis=0)
    l = np.linalg.norm(W.conj().T @ A - lam[:, None] * W.conj().T, axis=1) \
        / np.linalg.norm(W, axis=0)
    assert r.max() < 1e-10 * nA and l.max() < 1e-10 * nA


@pytest.fixture
def sparse_path(monkeypatch):
    """The shift-invert path on a matrix small enough to check against dense eig."""
    monkeypatch.setattr(low, "DENSE_STATES", 10)


def test_lowest_count_and_radius_against_known_eigenvalues(sparse_path):
    """``count``: the lowest eigenvalues by |λ| equal the known ones (1e-10 relative, the
    pairs spread over five decades); ``radius``: every known eigenvalue with |λ| ≤ radius
    and one beyond; right and left eigenvectors of A."""
    A, ref = _known(150)
    lam, V, W, scale = low.lowest_eigenpairs(A, count=12, left=True)
    assert 12 <= lam.size < A.shape[0] - 1  # the sparse path, not the dense fallback
    assert np.all(np.abs(np.abs(lam) - np.abs(ref[: lam.size])) <= 1e-10 * np.abs(lam))
    for x in lam:
        assert np.min(np.abs(ref - x)) <= 1e-10 * abs(x)
    _check_pairs(A, lam, V, W)
    assert scale >= np.abs(ref).max()  # an upper bound of the spectrum's size
    r = 2e4
    lam, V, _, _ = low.lowest_eigenpairs(A, radius=r)
    want = ref[np.abs(ref) <= r]
    assert np.count_nonzero(np.abs(lam) > r) >= 1 and lam.size < A.shape[0] - 1
    assert all(np.min(np.abs(lam - x)) <= 1e-10 * abs(x) for x in want)


def test_double_eigenvalues_get_a_left_vector_each(sparse_path):
    """Exactly repeated pairs: each twin is returned with its own left eigenvector, so the
    kept left and right subspaces pair (Wᴴ V well conditioned, as for dense eig)."""
    A, ref = _known(120, double=True)
    lam, V, W, _ = low.lowest_eigenpairs(A, count=16, left=True)
    _check_pairs(A, lam, V, W)
    k = 16
    assert np.linalg.cond(W[:, :k].conj().T @ V[:, :k]) < 1e6


def test_zero_eigenvalue_and_the_dense_fallback(sparse_path):
    """A singular A (an integrator, a free–free rotor's rigid body) is no trouble for the
    shifted factorisation; asking for (nearly) every eigenvalue gives the dense eig's."""
    A, _ = _known(60)
    n = A.shape[0]
    A = sla.block_diag(A, [[0.0]])
    lam, V, W, _ = low.lowest_eigenpairs(A, count=5, left=True)
    assert abs(lam[0]) < 1e-9 * np.linalg.norm(A, 1) and lam.size < n
    _check_pairs(A, lam, V, W)
    full = low.lowest_eigenpairs(A, count=n + 1)[0]
    dense = sla.eigvals(A)
    assert full.size == n + 1
    np.testing.assert_array_equal(full, dense[np.argsort(np.abs(dense), kind="stable")])
