"""The performance level a robustness requirement leaves (:mod:`ambseal.robust.level`),
on a static plant whose scaled bound is known in closed form."""

from __future__ import annotations

from types import SimpleNamespace

import control
import numpy as np
import pytest

from ambseal.errors import ConfigError
from ambseal.robust import LEVEL_RTOL, performance_level, scaled_performance

#: One uncertainty channel (gain 0.5), one performance channel (gain 4), one measurement
#: and one control: [z_Δ, z_p, y] = D [w_Δ, w_p, u].
D = np.array([[0.5, 0.0, 0.0], [0.0, 4.0, 0.0], [0.0, 0.0, 1.0]])
BLOCKS = [(-1, 0), (1, 1)]


def _gain(P):
    """With u = 0 the closed loop is diagonal: its norm at the best constant scaling of
    the uncertainty channel is max(|D_ΔΔ|, |D_pp|)."""
    d = np.asarray(P.D)
    return SimpleNamespace(gamma=max(abs(d[0, 0]), abs(d[1, 1])))


def test_the_level_is_the_largest_one_whose_bound_is_below_one():
    """Closed form: at level α the bound is max(0.5, 4α), so the largest certified level
    is 1/4, found within the bisection's tolerance, with its bound below 1; a level the
    caller already found refused is the bracket's top and is not evaluated again."""
    found = performance_level(control.ss([], [], [], D), BLOCKS, 1, 1, _gain)
    assert 0.25 / (1 + LEVEL_RTOL) <= found.level < 0.25
    assert found.tried[0] == (1.0, 4.0)
    assert found.gamma == pytest.approx(max(0.5, 4 * found.level)) and found.gamma < 1
    again = performance_level(control.ss([], [], [], D), BLOCKS, 1, 1, _gain, refused=0.5)
    assert 0.25 / (1 + LEVEL_RTOL) <= again.level < 0.25
    assert 0.5 not in [a for a, _ in again.tried]


def test_the_weights_as_given_and_no_level_at_all():
    """A bound below 1 at α = 1 keeps the weights (one evaluation); an uncertainty
    channel that alone exceeds 1 is certified at no level (None)."""
    easy = D.copy()
    easy[1, 1] = 0.9
    found = performance_level(control.ss([], [], [], easy), BLOCKS, 1, 1, _gain)
    assert found.level == 1.0 and len(found.tried) == 1
    hard = D.copy()
    hard[0, 0] = 1.5
    found = performance_level(control.ss([], [], [], hard), BLOCKS, 1, 1, _gain)
    assert found.level is None and found.result is None


def test_the_plant_at_a_level_scales_its_performance_rows_only():
    P = scaled_performance(control.ss([], [], [], D), BLOCKS, 1, 1, 0.25)
    np.testing.assert_allclose(np.asarray(P.D), np.diag([0.5, 1.0, 1.0]))


def test_bad_arguments_are_refused():
    P = control.ss([], [], [], D)
    with pytest.raises(ConfigError, match="rtol"):
        performance_level(P, BLOCKS, 1, 1, _gain, rtol=0.0)
    with pytest.raises(ConfigError, match="refused"):
        performance_level(P, BLOCKS, 1, 1, _gain, refused=1e-4)
    with pytest.raises(ConfigError, match="no uncertainty block"):
        performance_level(P, [(2, 2)], 1, 1, _gain)
    with pytest.raises(ConfigError, match="level"):
        scaled_performance(P, BLOCKS, 1, 1, 0.0)
