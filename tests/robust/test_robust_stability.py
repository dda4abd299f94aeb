"""The package's one stability rule (ambseal.robust.stability), against closed forms."""

import numpy as np
import pytest

from ambseal.robust.stability import RTOL, decay_rate, is_stable, unstable_poles


def test_a_damped_oscillator_is_stable_an_undamped_one_is_not():
    """Reference: the poles of m ẍ + c ẋ + k x = 0, −ζω ± jω√(1−ζ²) (closed form)."""
    w = 2 * np.pi * 500.0
    for zeta, stable in ((1e-3, True), (0.0, False), (-1e-3, False)):
        p = w * (-zeta + np.array([1j, -1j]) * np.sqrt(1 - zeta**2))
        assert is_stable(p) is stable
        assert decay_rate(p) == pytest.approx(-zeta * w, abs=1e-12)


def test_the_tolerance_is_relative_to_the_fastest_pole():
    """A real part inside the rounding level RTOL·max|s| is not told from zero; twice that
    margin is stable."""
    fast = 1e5
    tol = RTOL * fast
    assert not is_stable([-0.5 * tol + 10j, -fast])
    assert is_stable([-2 * tol + 10j, -fast])


def test_discrete_poles_map_to_rates():
    """Reference: s = ln z / dt; |z| < 1 decays, z on the unit circle does not, z = 0 (a pure
    delay) is stable."""
    dt = 1e-4
    z = np.exp((-3.0 + 2j * np.pi * 100) * dt)
    assert is_stable([z, np.conj(z), 0.0], dt)
    assert decay_rate([z, 0.0], dt) == pytest.approx(-3.0, rel=1e-9)
    assert not is_stable([np.exp(2j * np.pi * 100 * dt)], dt)
    np.testing.assert_array_equal(unstable_poles([0.0, 1.001, 0.5], dt), [1.001])
    assert is_stable([])
