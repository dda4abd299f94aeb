"""The generic core against SLICOT's documented examples (SLICOT-Reference,
``examples/data/*.dat`` and ``examples/results/*.res``): each case's data as published, its
result to the digits printed there."""

from __future__ import annotations

import numpy as np
import pytest
import control as ct

from ambseal.robust.hinf import hinfnorm, hinfsyn
from ambseal.robust.mu import mussv

#: SB10FD's example plant (6 states, 5 inputs, 5 outputs; 2 controls, 2 measurements)
_SB10FD_A = [[-1, 0, 4, 5, -3, -2], [-2, 4, -7, -2, 0, 3], [-6, 9, -5, 0, 2, -1],
             [-8, 4, 7, -1, -3, 0], [2, 5, 8, -9, 1, -4], [3, -5, 8, 0, 2, -6]]
_SB10FD_B = [[-3, -4, -2, 1, 0], [2, 0, 1, -5, 2], [-5, -7, 0, 7, -2], [4, -6, 1, 1, -2],
             [-3, 9, -8, 0, 5], [1, -2, 3, -6, -2]]
_SB10FD_C = [[1, -1, 2, -4, 0, -3], [-3, 0, 5, -1, 1, 1], [-7, 5, 0, -8, 2, -2],
             [9, -3, 4, 0, 3, 7], [0, 1, -2, 1, -6, -2]]
_SB10FD_D = [[1, -2, -3, 0, 0], [0, 4, 0, 1, 0], [5, -3, -4, 0, 1], [0, 1, 0, 1, -3],
             [0, 0, 1, 7, 1]]


def test_sb10fd_example_controller_at_gamma_15():
    """SLICOT SB10FD example (γ = 15): the controller A_K, B_K, C_K, D_K and the 12
    closed-loop poles as the example prints them (4 and 5 significant digits)."""
    P = ct.ss(*(np.array(M, float) for M in (_SB10FD_A, _SB10FD_B, _SB10FD_C, _SB10FD_D)))
    r = hinfsyn(P, 2, 2, gamma=15.0)
    AK = [[-2.8043, 14.7367, 4.6658, 8.1596, 0.0848, 2.5290],
          [4.6609, 3.2756, -3.5754, -2.8941, 0.2393, 8.2920],
          [-15.3127, 23.5592, -7.1229, 2.7599, 5.9775, -2.0285],
          [-22.0691, 16.4758, 12.5523, -16.3602, 4.4300, -3.3168],
          [30.6789, -3.9026, -1.3868, 26.2357, -8.8267, 10.4860],
          [-5.7429, 0.0577, 10.8216, -11.2275, 1.5074, -10.7244]]
    BK = [[-0.1581, -0.0793], [-0.9237, -0.5718], [0.7984, 0.6627], [0.1145, 0.1496],
          [-0.6743, -0.2376], [0.0196, -0.7598]]
    CK = [[-0.2480, -0.1713, -0.0880, 0.1534, 0.5016, -0.0730],
          [2.8810, -0.3658, 1.3007, 0.3945, 1.2244, 2.5690]]
    DK = [[0.0554, 0.1334], [-0.3195, 0.0333]]
    for got, published in ((r.K.A, AK), (r.K.B, BK), (r.K.C, CK), (r.K.D, DK)):
        np.testing.assert_allclose(got, published, atol=6e-5)
    re = [-0.10731e3, -0.66556e2, -0.38269e2, -0.38269e2, -0.20089e2, -0.62557e1, -0.62557e1,
          -0.32405e1, -0.32405e1, -0.17178e1, -0.41466e1, -0.76437e1]
    im = [0.0, 0.0, 0.13114e2, -0.13114e2, 0.0, 0.12961e2, -0.12961e2, 0.67998e1,
          -0.67998e1, 0.0, 0.0, 0.0]
    published = np.sort_complex(np.array(re) + 1j * np.array(im))
    got = np.sort_complex(np.linalg.eigvals(np.asarray(r.closed_loop.A)))
    np.testing.assert_allclose(got, published, rtol=5e-5, atol=5e-5)
    assert r.gamma < 15.0  # the verified norm of the loop built for γ = 15


def test_ab13dd_example_linf_norm_and_peak():
    """SLICOT AB13DD example: three lightly damped modes; the L∞ norm 0.5000000001·10⁶ at
    the peak frequency 1.414213562 rad/s (the system is stable, so it is the H∞ norm)."""
    A = np.zeros((6, 6))
    for i, (k, c) in enumerate(((0.5, 2e-4), (1.0, 2e-5), (2.0, 2e-6))):
        A[2 * i, 2 * i + 1] = 1.0
        A[2 * i + 1, 2 * i], A[2 * i + 1, 2 * i + 1] = -k, -c
    B = np.array([[1.0], [0.0], [1.0], [0.0], [1.0], [0.0]])
    C = np.array([[1.0, 0.0, 1.0, 0.0, 1.0, 0.0]])
    norm, w = hinfnorm(ct.ss(A, B, C, [[0.0]]))
    assert norm == pytest.approx(0.5000000001e6, rel=1e-9)
    assert w == pytest.approx(1.414213562, rel=1e-9)


def test_ab13md_example_mixed_mu():
    """SLICOT AB13MD example: a 6×6 complex matrix, blocks sizes (1, 1, 2, 1, 1) of types
    (real, real, complex, complex, complex); μ's upper bound 0.4174753408·10² (our bound:
    1e-6 relative, the D–G bound's own tolerance) and the lower bound not above it."""
    z = [(-1, 6), (2, -3), (3, 8), (3, 8), (-5, -9), (-6, 2), (4, 2), (-2, 5), (-6, -7),
         (-4, 11), (8, -7), (12, -1), (5, -4), (-4, -8), (1, -3), (-6, 14), (2, -5), (4, 16)]
    Z = np.array([complex(a, b) for a, b in z * 2]).reshape(6, 6)
    r = mussv(Z, [(-1, 0), (-1, 0), (2, 2), (1, 1), (1, 1)])
    assert float(r.upper) == pytest.approx(0.4174753408e2, rel=1e-6)
    assert float(r.lower) <= float(r.upper) * (1 + 1e-9)
    assert float(r.lower) == pytest.approx(0.4174753408e2, rel=1e-6)
