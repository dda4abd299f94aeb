"""Ki by static loading (thesis P2 §5) and its join with the closed-loop fit.

References: the truth file of the virtual facility (whose FE statics make the loads'
currents), the thesis's rigid-body balance (P2 §5: four equilibrium equations per load step),
the stacked least-squares solution of a linear problem with a prior measurement (Bard,
*Nonlinear Parameter Estimation*, 1974, §7-5), and the spread of the estimates over repeated
load programmes (Monte Carlo).
"""

from __future__ import annotations

import json

import numpy as np
import pytest

from ambseal.config import load_truth
from ambseal.errors import DataError
from ambseal.identify.fitting.fit import FitResult
from ambseal.identify.fitting.static_load import (join_static, load_static_record, programme_repeats,
                                          save_static_record, static_ki, virtual_static_load,
                                          StaticLoadResult)
from ambseal.model.amb import amb_factors
from ambseal.app.pipeline import default_truth_path


@pytest.fixture(scope="module")
def loads(testrig_cfg):
    return virtual_static_load(testrig_cfg, load_truth(default_truth_path()), seed=3)


def test_static_ki_within_two_percent_of_the_truth(testrig_cfg, loads):
    """Static-load Ki of every axis within 2 % of the truth file's value (issue acceptance;
    0.1 % here), the truth inside its 95 % interval, with the rig file's Ks (not the truth's)
    for the small bearing motion under load."""
    truth = load_truth(default_truth_path())
    res = static_ki(testrig_cfg, *loads)
    for n, e, s in zip(res.names, res.estimate, res.std_error):
        t = truth.parameters[n]
        assert abs(e - t) < 0.02 * t, n
        assert abs(e - t) < 1.96 * s + 0.002 * t, n  # + the rig file's Ks error in the model


def test_static_ki_is_the_rigid_body_balance_for_a_rigid_rotor(testrig_cfg, loads):
    """With the shaft stiffened 1000-fold the FE statics reduce to the thesis's rigid-body
    force and moment balance (P2 §5), solved here in closed form per axis pair."""
    from ambseal.model.amb import axes_rotation

    data = testrig_cfg.model_dump()
    for m in data["materials"].values():
        m["E"] = m["E"] * 1e3
    stiff = type(testrig_cfg).model_validate(data)
    z, F, i = loads
    res = static_ki(stiff, z, F, i)
    za, zb = (a.position for a in testrig_cfg.amb)
    R = axes_rotation(testrig_cfg.amb[0].axes_angle_deg)
    Fzn = F @ R.T  # forces along ζ, η
    for a in range(2):  # Ki_A i_A + Ki_B i_B = -F, za Ki_A i_A + zb Ki_B i_B = -z F
        A = np.vstack([np.column_stack([i[:, a], i[:, 2 + a]]),
                       np.column_stack([za * i[:, a], zb * i[:, 2 + a]])])
        b = -np.concatenate([Fzn[:, a], z * Fzn[:, a]])
        ki = np.linalg.lstsq(A, b, rcond=None)[0]
        assert res.estimate[[a, 2 + a]] == pytest.approx(ki, rel=2e-3)


def test_record_round_trip_and_bad_column(testrig_cfg, loads, tmp_path):
    path = save_static_record(tmp_path / "static.csv", testrig_cfg, *loads)
    back = load_static_record(path, testrig_cfg)
    for x, y in zip(back, loads):
        assert np.allclose(x, y, rtol=1e-9)
    bad = tmp_path / "bad.csv"
    bad.write_text(path.read_text().replace("current_B_eta_a", "current_B_x_a"))
    with pytest.raises(DataError, match="current_B_eta_a"):
        load_static_record(bad, testrig_cfg)


def test_join_is_the_stacked_least_squares():
    """A linear model y = X θ + e fitted alone, joined with a direct measurement of θ_0,
    equals the least-squares fit of the stacked problem [X; e_0ᵀ·σ/σ_s] (Bard §7-5)."""
    rng = np.random.default_rng(0)
    X = rng.standard_normal((200, 2)) @ np.array([[1.0, 0.97], [0.0, 0.25]])
    sigma, sigma_s, theta = 0.1, 0.004, np.array([2.0, -1.0])
    y = X @ theta + sigma * rng.standard_normal(200)
    est = np.linalg.lstsq(X, y, rcond=None)[0]
    cov = sigma**2 * np.linalg.inv(X.T @ X)
    se = np.sqrt(np.diag(cov))
    dyn = FitResult(("A.Ki_zeta", "A.Ks_zeta"), est, est, se, est - 2 * se, est + 2 * se,
                    cov / np.outer(se, se), {}, True, "", 1, 0.0, np.zeros(1), np.zeros((1, 1)),
                    np.zeros((1, 1)), ("A_zeta",))
    k_s = 2.003
    stat = StaticLoadResult(("A.Ki_zeta",), np.array([k_s]), np.array([sigma_s]),
                            np.eye(1), 0.0, 1)
    joined = join_static(dyn, stat)
    Xs = np.vstack([X, [sigma / sigma_s, 0.0]])
    ys = np.concatenate([y, [k_s * sigma / sigma_s]])
    ref = np.linalg.lstsq(Xs, ys, rcond=None)[0]
    cref = sigma**2 * np.linalg.inv(Xs.T @ Xs)
    assert joined.estimate == pytest.approx(ref, rel=1e-10)
    assert joined.std_error == pytest.approx(np.sqrt(np.diag(cref)), rel=1e-10)
    assert abs(joined.correlation[0, 1]) < abs(dyn.correlation[0, 1])


def test_static_interval_is_the_spread_over_repeated_programmes(testrig_cfg):
    """The static Ki's standard errors and correlations are those of the estimates over 30
    independent programmes (3 steps per direction, 2 repeats each): a load-cell error scales
    every Ki its step loads alike, so the four Ki move together (correlation ≈ 1) and A's
    error is about as large as B's relative to Ki. Independent equations (σ̂²(AᵀA)⁻¹) gave
    A's error half the spread and ζ–η correlation 0."""
    truth = load_truth(default_truth_path())
    runs = [static_ki(testrig_cfg, *virtual_static_load(testrig_cfg, truth, seed=s,
                                                        steps_per_direction=3, repeats=2))
            for s in range(30)]
    est = np.array([r.estimate for r in runs])
    spread = est.std(axis=0, ddof=1)
    reported = np.sqrt(np.mean([r.std_error**2 for r in runs], axis=0))
    assert reported == pytest.approx(spread, rel=0.3)
    assert np.corrcoef(est.T).min() > 0.95
    assert np.mean([r.correlation for r in runs], axis=0).min() > 0.95


def test_join_with_a_singular_static_covariance_is_the_constrained_fit():
    """A static result that fixes the ratio of two Ki exactly and their common scale with
    an error (rank-1 covariance, as the noise-free currents of the virtual facility give):
    the join equals the least-squares fit of the stacked problem with that scale measurement
    and a heavily weighted ratio equation (penalty method, weight 1e9)."""
    rng = np.random.default_rng(1)
    X = rng.standard_normal((300, 3)) @ np.array([[1.0, 0.9, 0.2], [0, 0.3, 0.1], [0, 0, 1.0]])
    sigma, theta = 0.1, np.array([2.0, 3.0, -1.0])
    y = X @ theta + sigma * rng.standard_normal(300)
    est = np.linalg.lstsq(X, y, rcond=None)[0]
    cov = sigma**2 * np.linalg.inv(X.T @ X)
    se = np.sqrt(np.diag(cov))
    dyn = FitResult(("A.Ki_zeta", "B.Ki_zeta", "A.Ks_zeta"), est, est, se, est - 2 * se,
                    est + 2 * se, cov / np.outer(se, se), {}, True, "", 1, 0.0, np.zeros(1),
                    np.zeros((1, 1)), np.zeros((1, 1)), ("A_zeta",))
    k_s, rel = np.array([2.01, 3.015]), 0.002  # ratio exact, scale 0.5 % high, 0.2 % error
    cs = rel**2 * np.outer(k_s, k_s)
    stat = StaticLoadResult(("A.Ki_zeta", "B.Ki_zeta"), k_s, np.sqrt(np.diag(cs)),
                            np.ones((2, 2)), 0.0, 2)
    joined = join_static(dyn, stat)
    u = k_s / np.linalg.norm(k_s)  # the scale direction; its orthogonal one is exact
    w = np.array([u[1], -u[0]])
    s_scale = rel * np.linalg.norm(k_s)
    Xs = np.vstack([X, sigma / s_scale * np.r_[u, 0.0], 1e9 * np.r_[w, 0.0]])
    ys = np.concatenate([y, [sigma / s_scale * u @ k_s, 1e9 * w @ k_s]])
    ref = np.linalg.lstsq(Xs, ys, rcond=None)[0]
    assert joined.estimate == pytest.approx(ref, rel=1e-7)
    assert joined.estimate[1] / joined.estimate[0] == pytest.approx(k_s[1] / k_s[0], rel=1e-9)


def test_programme_repeats_reaches_twice_the_fit_precision():
    """Errors fall as 1/√repeats: a static Ki error of 0.1 after 5 programmes against the
    fit's 0.08 needs 5·(2·0.1/0.08)² = 31.25 → 32 programmes; a static test already twice
    as precise needs no more; the cap holds."""
    names = ("A.Ki_zeta", "A.Ks_zeta")
    fit = FitResult(names, np.ones(2), np.ones(2), np.array([0.08, 1.0]), np.zeros(2),
                    np.ones(2), np.eye(2), {}, True, "", 1, 0.0, np.zeros(1), np.zeros((1, 1)),
                    np.zeros((1, 1)), ("A_zeta",))
    stat = lambda se: StaticLoadResult(("A.Ki_zeta",), np.ones(1), np.array([se]),  # noqa: E731
                                       np.eye(1), 0.0, 1)
    assert programme_repeats(fit, stat(0.1), 5) == 32
    assert programme_repeats(fit, stat(0.04), 5) == 5
    assert programme_repeats(fit, stat(1.0), 5, max_repeats=100) == 100
