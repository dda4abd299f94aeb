"""A fit ends at its own tolerances, never at a count of evaluations
(:mod:`ambseal.lti.least_squares`)."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.optimize import least_squares

import ambseal.lti.least_squares as converged
from ambseal.lti.least_squares import least_squares_converged


def rosenbrock(x):
    """Rosenbrock's valley as residuals; closed-form minimum 0 at (1, 1)."""
    return np.array([10.0 * (x[1] - x[0] ** 2), 1.0 - x[0]])


def cut_rounds(monkeypatch, nfev):
    """SciPy's count cut to ``nfev`` evaluations a round, so that every fit meets it."""
    def cut(fun, x0, **kw):
        return least_squares(fun, x0, max_nfev=nfev, **kw)

    monkeypatch.setattr(converged, "least_squares", cut)


def test_a_fit_the_count_stops_is_continued_to_its_tolerance(monkeypatch):
    """Reference: Rosenbrock's closed-form minimum (1, 1). Cut at 4 evaluations SciPy ends
    short of it (status 0); continued round by round the fit reaches it, ended by a
    tolerance."""
    short = least_squares(rosenbrock, [-1.2, 1.0], max_nfev=4)
    assert short.status == 0 and np.max(np.abs(short.x - 1.0)) > 0.1
    cut_rounds(monkeypatch, 4)
    res = least_squares_converged(rosenbrock, [-1.2, 1.0])
    assert res.status > 0 and res.rounds > 1
    np.testing.assert_allclose(res.x, [1.0, 1.0], atol=1e-7)


def test_a_round_that_does_not_lower_the_cost_ends_the_fit(monkeypatch):
    """A cost the fit cannot lower (a constant) ends after one continued round, by the
    round's ftol test, not after more counts."""
    cut_rounds(monkeypatch, 1)
    res = least_squares_converged(lambda x: np.array([1.0, 1.0 + 0.0 * x[0]]), [0.5],
                                  gtol=None, xtol=None)
    assert res.status == 2 and res.rounds == 2 and "stalled" in res.message


def test_a_round_that_does_not_lower_the_callers_measure_ends_the_fit(monkeypatch):
    """The caller's stall measure, not the cost, is tested: Rosenbrock's cost falls in every
    round cut at 4 evaluations, but a measure that stays at 1 ends the fit after one
    continued round; one that keeps falling lets it reach the minimum (1, 1)."""
    cut_rounds(monkeypatch, 4)
    res = least_squares_converged(rosenbrock, [-1.2, 1.0], stall=lambda x: 1.0,
                                  stall_rtol=0.01)
    assert res.status == 2 and res.rounds == 2 and "stall measure" in res.message
    assert np.max(np.abs(res.x - 1.0)) > 1e-3
    res = least_squares_converged(rosenbrock, [-1.2, 1.0],
                                  stall=lambda x: float(np.sum(rosenbrock(x) ** 2)),
                                  stall_rtol=0.01)
    np.testing.assert_allclose(res.x, [1.0, 1.0], atol=1e-6)


def test_a_count_is_refused():
    with pytest.raises(TypeError, match="max_nfev"):
        least_squares_converged(rosenbrock, [0.0, 0.0], max_nfev=10)
