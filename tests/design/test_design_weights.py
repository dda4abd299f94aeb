"""Weights of the robust designs (thesis P3 Eq. 11, P5 Eq. 7)."""

import numpy as np
import pytest
import control as ct

from ambseal.design.weights import (PEAK_DAMPING, Weights, check_weight, control_weight,
                                     diagonal_weight, peak_weight, performance_weight,
                                     wp_gain)


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


def test_the_synchronous_peak_is_h_at_its_frequency_and_one_away_from_it():
    """W_Ω = (s² + 2hζΩ₀s + Ω₀²)/(s² + 2ζΩ₀s + Ω₀²): the closed form
    |W_Ω(jω)| = √((Ω₀² − ω²)² + (2hζΩ₀ω)²) / √((Ω₀² − ω²)² + (2ζΩ₀ω)²), h at Ω₀, 1 at DC
    and at high frequency; on W_u it multiplies the control weight."""
    f0, h, z = 250.0, 6.0, PEAK_DAMPING
    W = peak_weight(f0, h)
    w0, w = 2 * np.pi * f0, 2 * np.pi * np.array([0.0, 25.0, 225.0, 250.0, 275.0, 2500.0])
    closed = np.hypot(w0**2 - w**2, 2 * h * z * w0 * w) / np.hypot(w0**2 - w**2, 2 * z * w0 * w)
    got = np.abs([complex(W(1j * x)) for x in w])
    assert np.allclose(got, closed, rtol=1e-12)
    assert got[3] == pytest.approx(h, rel=1e-12) and got[0] == pytest.approx(1.0)
    assert 1 < got[-1] < 1.03 and 1 < got[1] < 1.03
    assert np.all(np.real(W.poles()) < 0) and np.all(np.real(W.zeros()) < 0)
    base = Weights(wu_gain=0.2, wu_corner_hz=100.0, wu_hf_gain=2.0)
    peaked = Weights(wu_gain=0.2, wu_corner_hz=100.0, wu_hf_gain=2.0, wu_peak_hz=f0,
                     wu_peak_gain=h)
    s0 = 2j * np.pi * f0
    assert complex(peaked.Wu()(s0)) == pytest.approx(h * complex(base.Wu()(s0)), rel=1e-12)
    with pytest.raises(ValueError, match="gain"):
        peak_weight(f0, 0.5)


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


def test_gain_weight_is_the_inverse_pid_in_its_band():
    """μ's gain demand W_K (P5 Fig. 10) against a closed form written independently:
    |W_K(jω)| = D_u/(c·3·D_e·|K_PID(jω)|)·|H_2(jω)|·|B_4(jω)| with the P5 Eq. 6 PID and the
    Butterworth magnitudes 1/√(1 + (ω_l/ω)⁴) and 1/√(1 + (ω/ω_h)⁸); −3 dB at both corners."""
    from ambseal.design.weights import Weights
    from ambseal.errors import ConfigError

    kp, ti, td, eps, lo, hi = 1.6e4, 0.2, 1.25e-3, 0.1, 150.0, 210.0
    W = Weights(d_e=20e-6, d_u=1.0, gain_factor=2.0, gain_band_hz=(lo, hi),
                pid_reference=(kp, ti, td, eps)).Wk()
    f = np.array([10.0, 150.0, 180.0, 210.0, 1000.0])
    s = 2j * np.pi * f
    k_pid = np.abs(kp * (1 + 1 / (ti * s) + td * s / (eps * td * s + 1)))
    want = (1.0 / (6 * 20e-6 * k_pid) / np.sqrt(1 + (lo / f) ** 4)
            / np.sqrt(1 + (f / hi) ** 8))
    got = np.abs(np.array([complex(W(x)) for x in s]).ravel())
    np.testing.assert_allclose(got, want, rtol=1e-6)
    assert Weights().Wk() is None
    with pytest.raises(ConfigError, match="band"):
        Weights(gain_factor=2.0, gain_band_hz=(210.0, 150.0), pid_reference=(1, 1, 1, 1)).Wk()


def test_weight_whose_realisation_overflows_is_a_config_error():
    """W_p = (s/M + ω_B)/(s + ω_B A) with M = 1e308 (``--set design.hinf.M=1e308`` before
    the rig file bounded M): its numerator's coefficients lie 308 orders of magnitude apart
    and python-control's realisation raised numpy's LinAlgError; the weight's check names
    the weight instead."""
    from ambseal.design.weights import check_weight
    from ambseal.errors import ConfigError

    with pytest.raises(ConfigError, match="weight W_p: no state-space realisation"):
        check_weight(performance_weight(1e308, 5.0), "W_p")
