"""Tests of ambseal.control.order: balanced truncation of controllers."""

from __future__ import annotations

import numpy as np
import pytest
import control as ct

from ambseal.control.hinf import hinfnorm, hinfsyn, lft_lower
from ambseal.control.order import balred_controller, reduce_controller


def test_balanced_truncation_error_bound():
    """Reference: Zhou, Doyle & Glover (1996) Thm 7.9 — ‖K − K_r‖∞ ≤ 2 Σ discarded Hankel
    singular values for a stable K; and the bound is not loose by orders of magnitude."""
    np.random.seed(4)
    K = ct.rss(10, 2, 2)
    Kr, hsv = balred_controller(K, 4)
    err, _ = hinfnorm(ct.ss(K) - Kr)
    bound = 2 * np.sum(hsv[4:])
    assert Kr.nstates == 4
    assert err <= bound * (1 + 1e-6)
    assert err >= hsv[4] * (1 - 1e-6)  # ‖K − K_r‖∞ ≥ σ_{r+1} for any order-r K_r


def test_unstable_part_is_kept():
    """Reference: AB09MD splits off the unstable part and keeps it exactly (Varga 1991)."""
    np.random.seed(6)
    S = ct.rss(6, 1, 1)
    U = ct.tf([1], [1, 0]) * ct.tf([1], [1, -2])  # integrator and unstable pole at 2
    K = ct.ss(S + ct.ss(U))
    Kr, _ = balred_controller(K, 4)
    pr = np.sort_complex(Kr.poles())
    assert np.min(np.abs(pr - 2.0)) < 1e-8 and np.min(np.abs(pr)) < 1e-8
    with pytest.raises(ValueError, match="unstable"):
        balred_controller(K, 1)


def test_reduce_controller_reports_gamma_before_after():
    """Reference: the reported γ's equal ‖F_l(P, K)‖∞ recomputed by hinfnorm for the full and
    reduced controllers (definition), for an H∞ design on a mixed-sensitivity problem."""
    s = ct.tf("s")
    G = ct.tf([200], [10, 1]) * ct.tf([1], [0.05, 1]) ** 2
    P = ct.augw(ct.ss(G), w1=(s / 1.5 + 10) / (s + 1e-3), w2=ct.tf([0.1], [1]))
    h = hinfsyn(P, 1, 1)
    res = reduce_controller(P, h.K, h.order - 1, 1, 1)
    assert res.order == h.order - 1 and res.order_full == h.order
    assert res.gamma_full == pytest.approx(h.gamma, rel=1e-6)
    assert res.gamma == pytest.approx(hinfnorm(lft_lower(P, res.K, 1, 1))[0], rel=1e-9)
    assert res.gamma_rise == pytest.approx(res.gamma / res.gamma_full - 1)
    assert list(res.K.input_labels) == list(h.K.input_labels)
