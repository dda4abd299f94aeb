"""Tests of ambseal.control.dk: D-scale fitting and D–K iteration."""

from __future__ import annotations

import numpy as np
import pytest
import control as ct

from ambseal.control.dk import fit_dscale, fit_magnitude, musyn
from ambseal.control.hinf import hinfsyn


def rp_plant():
    """Robust-performance plant of Skogestad & Postlethwaite (2005) §8.12.4 (SISO, input
    multiplicative uncertainty W_I, performance weight W_P, with a small leak instead of the
    pure integrator). Inputs [w_Δ, w, u], outputs [z_Δ, e, y]."""
    G = ct.ss(ct.tf([-6, 3], [50, 15, 1]), inputs=["up"], outputs=["yp"], name="G")
    WI = ct.ss(ct.tf([1, 0.2], [0.5, 1]), inputs=["u"], outputs=["zd"], name="WI")
    WP = ct.ss(ct.tf([0.5, 0.05], [1, 0.0005]), inputs=["v"], outputs=["e"], name="WP")
    s1 = ct.summing_junction(inputs=["u", "wd"], output="up", name="s1")
    s2 = ct.summing_junction(inputs=["yp", "w"], output="v", name="s2")
    neg = ct.ss([], [], [], [[-1.0]], inputs=["v"], outputs=["y"], name="neg")
    return ct.interconnect([G, WI, WP, s1, s2, neg], inplist=["wd", "w", "u"],
                           outlist=["zd", "e", "y"], name="P")


def test_fit_magnitude_recovers_minimum_phase_scale():
    """Reference: a known stable minimum-phase D(s) = 2 (s+1)(s+10)/((s+3)(s+30)); its
    magnitude is reproduced and all poles/zeros of the fit lie in the open LHP."""
    D = ct.tf([2, 22, 20], [1, 33, 90])
    w = np.logspace(-2, 3, 150)
    mag = np.abs(D(1j * w))
    fit = fit_magnitude(w, mag, 2)
    np.testing.assert_allclose(np.abs(fit(1j * w)), mag, rtol=1e-3)
    assert np.all(np.real(fit.poles()) < 0) and np.all(np.real(fit.zeros()) < 0)
    c = fit_magnitude(w, np.full(w.size, 3.0), 0)
    assert float(np.real(c(1j))) == pytest.approx(3.0)
    with pytest.raises(ValueError, match="0–4"):
        fit_magnitude(w, mag, 5)


def test_fit_dscale_selects_the_lowest_sufficient_order():
    """Reference: known stable minimum-phase scales. A constant needs order 0; the
    second-order D(s) = 2 (s+1)(s+10)/((s+3)(s+30)) is reproduced within the tolerance by an
    order ≤ 2 fit (MATLAB musyn's rule: the lowest order whose fit error is below a
    tolerance), with every pole and zero in the open LHP."""
    w = np.logspace(-2, 3, 80)
    f0, o0, _ = fit_dscale(w, np.full(w.size, 0.3))
    assert o0 == 0 and float(np.real(f0(1j))) == pytest.approx(0.3)
    D = ct.tf([2, 22, 20], [1, 33, 90])
    mag = np.abs(D(1j * w))
    fit, order, err = fit_dscale(w, mag, tol=0.02)
    assert 1 <= order <= 2 and err <= np.log1p(0.02)
    np.testing.assert_allclose(np.abs(fit(1j * w)), mag, rtol=0.03)
    assert np.all(np.real(fit.poles()) < 0) and np.all(np.real(fit.zeros()) < 0)


def _mu_ab13md(cl, omega):
    """Peak over ``omega`` of slycot AB13MD's μ upper bound for two 1×1 complex blocks,
    on python-control's frequency response of ``cl``."""
    from slycot import ab13md

    H = np.moveaxis(ct.frequency_response(cl, omega, squeeze=False).complex, 2, 0)
    return max(ab13md(Hk, np.array([1, 1]), np.array([2, 2]))[0] for Hk in H)


def test_dk_improves_on_hinf_and_records_history():
    """Reference: μ ≤ σ̄ with D = I (Packard & Doyle 1993), so D–K can only improve on the H∞
    γ of the unscaled problem; for this two-block problem μ = inf_D σ̄(DMD⁻¹) and D–K from
    γ ≈ 1.17 gets below 0.85 of it. The reported μ's (final and first iteration) are checked
    side by side against slycot AB13MD on python-control's F_l (P.lft) of the same
    controllers on the same grid; the final closed loop is stable (python-control poles)."""
    P = rp_plant()
    blocks = [(1, 1), (1, 1)]
    h = hinfsyn(P, 1, 1)
    r = musyn(P, blocks, 1, 1, order=2, max_iter=3)
    assert r.mu <= h.gamma * (1 + 1e-3)
    assert r.mu < 0.85 * h.gamma
    assert 2 <= len(r.history) <= 3
    assert all({"iteration", "gamma", "mu", "order"} <= set(hh) for hh in r.history)
    cl = P.lft(r.K, 1, 1)
    assert np.all(cl.poles().real < 0)
    assert r.mu == pytest.approx(_mu_ab13md(cl, r.omega), rel=5e-3)
    assert r.history[0]["mu"] == pytest.approx(_mu_ab13md(P.lft(h.K, 1, 1), r.omega),
                                               rel=2e-2)
    assert r.order == r.K.nstates and r.to_dict()["order"] == r.order


def test_musyn_rejects_mismatched_blocks():
    """Reference: the blocks must cover P's exogenous channels (2 inputs × 2 outputs here)."""
    P = rp_plant()
    with pytest.raises(ValueError, match="exogenous"):
        musyn(P, [(1, 1), (2, 1)], 1, 1)
    with pytest.raises(ValueError, match="performance"):
        musyn(P, [(1, 1), (1, 0)], 1, 1)
    with pytest.raises(ValueError, match="0–4"):
        musyn(P, [(1, 1), (1, 1)], 1, 1, order=7)
