"""Weights of the robust designs (thesis P3 Eq. 11, P5 Eq. 7)."""

import numpy as np
import pytest
import control as ct

from ambseal.control.weights import (check_weight, control_weight, diagonal_weight,
                                     performance_weight, wp_gain)


def test_wp_low_high_and_bandwidth_values():
    """|W_p(0)| = 1/A, |W_p(j∞)| = 1/M, |W_p(jω)| = √((ω/M)²+ω_B²)/√(ω²+(ω_B A)²) (P5 Eq. 7)."""
    M, wb, A = 2.5, 30.0, 1e-3
    W = performance_weight(M, wb, A)
    assert abs(W(0)) == pytest.approx(1 / A, rel=1e-12)
    assert abs(W(1e12j)) == pytest.approx(1 / M, rel=1e-6)
    w = np.logspace(-3, 5, 50)
    got = np.abs(W(1j * w))
    assert np.allclose(got, wp_gain(w, M, wb, A), rtol=1e-12)
    # the bound 1/|W_p| on |S| peaks at M (approached from below) and is A at DC
    assert np.max(1 / got) < M and np.max(1 / got) > 0.99 * M


def test_wp_crossover_near_bandwidth():
    """1/|W_p| crosses 1 near ω_B (S&P 2005 Eq. 2.105: ω_B is the bandwidth requirement)."""
    M, wb = 2.5, 30.0
    w = np.logspace(-1, 4, 20001)
    inv = 1 / wp_gain(w, M, wb)
    wc = w[np.argmin(np.abs(inv - 1))]
    # closed form: (ω/M)² + ω_B² = ω² (A → 0)  →  ω = ω_B / √(1 − 1/M²)
    assert wc == pytest.approx(wb / np.sqrt(1 - 1 / M**2), rel=1e-2)


def test_wu_high_pass_gains():
    """W_u = k(1 + s/ω_z)/(1 + s/ω_p): low gain k, high gain k ω_p/ω_z (P3 §3.3)."""
    W = control_weight(0.2, corner_hz=300.0, hf_gain=4.0)
    assert abs(W(0)) == pytest.approx(0.2)
    assert abs(W(1e12j)) == pytest.approx(4.0, rel=1e-6)
    assert abs(control_weight(0.3)(1j)) == pytest.approx(0.3)


def test_improper_weight_raises_naming_it():
    """An improper weight (s + 1) is rejected with its name in the message."""
    with pytest.raises(ValueError, match="W_p is not proper"):
        check_weight(ct.tf([1, 1], [1]), "W_p")
    with pytest.raises(ValueError, match="W_u"):
        check_weight(ct.tf([1], [1, -1]), "W_u")  # unstable
    with pytest.raises(ValueError, match="biproper"):
        check_weight(ct.tf([1], [1, 1]), "W_u", biproper=True)
    with pytest.raises(ValueError, match="M="):
        performance_weight(-1.0, 10.0)
    with pytest.raises(ValueError, match="hf_gain"):
        control_weight(1.0, corner_hz=10.0, hf_gain=0.5)


def test_diagonal_weight_is_block_diagonal():
    """diag(W, W, W) evaluated at a frequency equals W(jω)·I."""
    W = performance_weight(2.0, 100.0)
    D = diagonal_weight(W, 3, "W_p")
    val = D(5j)
    assert np.allclose(val, W(5j) * np.eye(3))
