"""Tests of ambseal.robust.order: balanced truncation of controllers.

References outside the module: the balanced-truncation error bounds (Zhou, Doyle & Glover
1996, Thm 7.9), python-control run side by side (``control.balred``, ``control.hsvd``,
``StateSpace.lft`` with Skogestad & Postlethwaite's positive-feedback F_l, and
``control.norm(·, 'inf')``, i.e. slycot AB13DD).
"""

from __future__ import annotations

import numpy as np
import pytest
import control as ct

from ambseal.robust.hinf import hinfsyn
from ambseal.robust.mu import mussv
from ambseal.robust.order import balred_controller, reduce_controller


def _fresp(sys, w):
    return np.moveaxis(ct.frequency_response(sys, w, squeeze=False).complex, 2, 0)


def test_balanced_truncation_error_bound():
    """Reference: Zhou, Doyle & Glover (1996) Thm 7.9 — σ_{r+1} ≤ ‖K − K_r‖∞ ≤ 2 Σ discarded
    Hankel singular values for a stable K, the norm by control.norm (slycot AB13DD); the
    Hankel singular values equal python-control's control.hsvd, and the reduced controller
    has python-control's control.balred frequency response."""
    np.random.seed(4)
    K = ct.rss(10, 2, 2)
    Kr, hsv = balred_controller(K, 4)
    np.testing.assert_allclose(hsv, ct.hsvd(K), rtol=1e-6)
    err = ct.norm(ct.ss(K) - Kr, "inf")
    bound = 2 * np.sum(hsv[4:])
    assert Kr.nstates == 4
    assert hsv[4] * (1 - 1e-6) <= err <= bound * (1 + 1e-6)
    w = np.logspace(-2, 3, 60)
    ref = _fresp(ct.balred(K, 4), w)
    np.testing.assert_allclose(_fresp(Kr, w), ref, rtol=1e-8, atol=1e-10 * np.abs(ref).max())
    assert list(Kr.input_labels) == list(K.input_labels)


def test_unstable_part_is_kept():
    """Reference: AB09MD splits off the unstable part and keeps it exactly (Varga 1991): the
    integrator and the pole at +2 of K = S + 1/(s(s−2)) survive the reduction to 4 states,
    and the result matches python-control's control.balred on the same K; an order below
    the two unstable/marginal poles is refused."""
    np.random.seed(6)
    S = ct.rss(6, 1, 1)
    U = ct.tf([1], [1, 0]) * ct.tf([1], [1, -2])  # integrator and unstable pole at 2
    K = ct.ss(S + ct.ss(U))
    Kr, _ = balred_controller(K, 4)
    pr = np.sort_complex(Kr.poles())
    assert np.min(np.abs(pr - 2.0)) < 1e-8 and np.min(np.abs(pr)) < 1e-8
    w = np.logspace(-1, 3, 60)
    ref = _fresp(ct.balred(K, 4), w)
    np.testing.assert_allclose(_fresp(Kr, w), ref, rtol=1e-8, atol=1e-10 * np.abs(ref).max())
    with pytest.raises(ValueError, match="unstable"):
        balred_controller(K, 1)


def test_reduce_controller_reports_gamma_before_after():
    """Reference: python-control side by side — the reported γ's equal
    control.norm(P.lft(K), 'inf') (Skogestad & Postlethwaite's positive-feedback F_l, norm by
    slycot AB13DD) for the full and the reduced (5 → 3 states) controller of an H∞ design on
    a mixed-sensitivity problem with a proper W_2 (the reduced loop stays stable there);
    the full-order γ is the synthesis γ."""
    s = ct.tf("s")
    G = ct.tf([200], [10, 1]) * ct.tf([1], [0.05, 1]) ** 2
    P = ct.augw(ct.ss(G), w1=0.5 * (s + 10) / (s + 0.1), w2=0.01 * (s + 1) / (s / 100 + 1))
    h = hinfsyn(P, 1, 1)
    assert h.order == 5
    res = reduce_controller(P, h.K, 3, 1, 1)
    assert res.order == 3 and res.order_full == 5
    assert res.gamma_full == pytest.approx(ct.norm(P.lft(h.K, 1, 1), "inf"), rel=1e-6)
    assert res.gamma_full == pytest.approx(h.gamma, rel=1e-6)
    cl = P.lft(res.K, 1, 1)
    assert np.all(cl.poles().real < 0)
    assert res.gamma == pytest.approx(ct.norm(cl, "inf"), rel=1e-6)
    assert res.gamma > res.gamma_full  # truncation costs something here (0.79 vs 0.75)
    assert list(res.K.input_labels) == list(h.K.input_labels)


def test_reduction_that_destabilises_reports_infinite_gamma():
    """Reference: definition — an unstable closed loop has no finite H∞ norm. Reducing the
    4-state H∞ controller of a mixed-sensitivity problem with a near-integrator W_1 to 3
    states leaves python-control's F_l (P.lft) with a pole at ≈ +2.5; γ must be inf, not
    the L∞ norm on the imaginary axis that control.norm returns for it (≈ 1.19)."""
    s = ct.tf("s")
    G = ct.tf([200], [10, 1]) * ct.tf([1], [0.05, 1]) ** 2
    P = ct.augw(ct.ss(G), w1=(s / 1.5 + 10) / (s + 1e-3), w2=ct.tf([0.1], [1]))
    h = hinfsyn(P, 1, 1)
    res = reduce_controller(P, h.K, h.order - 1, 1, 1)
    assert P.lft(res.K, 1, 1).poles().real.max() > 1.0
    assert np.isinf(res.gamma) and np.isfinite(res.gamma_full)


def _mixed_problem(seed: int):
    """A stable 12-state plant with three real scalars and a complex 2 × 2 block (five
    exogenous channels, one measurement, one control), a stable 6-state controller, a
    60-point grid and the structure: ``(P, K, omega, blocks)``."""
    rng = np.random.default_rng(seed)
    n = 12
    A = rng.normal(size=(n, n))
    A -= (np.abs(np.linalg.eigvals(A)).max() + 0.3) * np.eye(n)
    P = ct.ss(A, rng.normal(size=(n, 6)), rng.normal(size=(6, n)),
              0.2 * rng.normal(size=(6, 6)))
    P.D[5, 5] = 0.0
    Ak = rng.normal(size=(6, 6))
    Ak -= (np.abs(np.linalg.eigvals(Ak)).max() + 0.5) * np.eye(6)
    K = ct.ss(Ak, rng.normal(size=(6, 1)), 0.02 * rng.normal(size=(1, 6)), 0.0)
    return P, K, np.logspace(-1, 2, 60), [(-1, 0), (-1, 0), (-1, 0), (2, 2)]


def _count_mixed_solves(monkeypatch, blocks) -> list:
    """Every call of mussv on the structure ``blocks`` from here on, as the number of
    frequencies it solved (the list returned fills as they happen)."""
    import ambseal.robust.mu as mu
    import ambseal.robust.order as order

    solved, real = [], mu.mussv

    def counted(M, b, om=None, **kw):
        if list(map(tuple, b)) == blocks:
            solved.append(np.size(om))
        return real(M, b, om, **kw)

    monkeypatch.setattr(mu, "mussv", counted)
    monkeypatch.setattr(order, "mussv", counted, raising=False)  # if imported by name
    return solved


@pytest.mark.parametrize("seed", [3, 4])
def test_reduce_controller_solves_a_mixed_structure_only_where_it_reaches_its_peak(
        seed, monkeypatch):
    """Reference: mussv's bound of the structure as given on the whole grid. A stable
    12-state plant with three real scalars and a complex 2 × 2 block (five exogenous
    channels, one measurement, one control) and a small 6-state controller reduced to
    3 states, on a 60-point grid: the reported μ, full and reduced, is the whole grid's
    peak (1e-6, the peak's tolerance tol·1e-3), but the mixed structure is solved at under
    60 % of the frequencies (the complexified bound covers the rest, as in D–K's
    μ-step). Solving it at every frequency was most of the expander-generator's order
    search."""
    P, K, w, blocks = _mixed_problem(seed)
    ref = [float(np.max(mussv(P.lft(k, 1, 1), blocks, w, lower=False, peak=False).upper))
           for k in (K, balred_controller(K, 3)[0])]
    solved = _count_mixed_solves(monkeypatch, blocks)
    res = reduce_controller(P, K, 3, 1, 1, blocks=blocks, omega=w)
    assert np.isfinite(res.gamma)
    assert res.mu_full == pytest.approx(ref[0], rel=1e-6)
    assert res.mu == pytest.approx(ref[1], rel=1e-6)
    assert 0 < sum(solved) < 2 * 0.6 * w.size


@pytest.mark.parametrize("seed", [3, 4])
def test_a_reduced_loop_known_above_a_level_is_not_solved_for_its_upper_bound(
        seed, monkeypatch):
    """Reference: mussv's upper bound of the structure as given on the whole grid, for the
    plant and reduced controller of the test above. Asked only whether the reduced loop's
    μ exceeds a level below its peak, ``reduce_controller`` answers from a certified lower
    bound: ``mu_is_lower``, ``mu`` above the level and at most the whole grid's upper
    bound, and the mixed structure solved at no frequency. Asked about a level above the
    peak it reports the peak as without the level."""
    P, K, w, blocks = _mixed_problem(seed)
    peak = float(np.max(mussv(P.lft(balred_controller(K, 3)[0], 1, 1), blocks, w,
                              lower=False, peak=False).upper))
    solved = _count_mixed_solves(monkeypatch, blocks)
    below = reduce_controller(P, K, 3, 1, 1, blocks=blocks, omega=w, full=(None, 1.0),
                              mu_above=0.9 * peak)
    assert below.mu_is_lower and 0.9 * peak < below.mu <= peak * (1 + 1e-9)
    assert not solved
    above = reduce_controller(P, K, 3, 1, 1, blocks=blocks, omega=w, full=(None, 1.0),
                              mu_above=1.1 * peak)
    assert not above.mu_is_lower and above.mu == pytest.approx(peak, rel=1e-6)
    assert solved
