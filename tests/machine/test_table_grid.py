"""The discrete table of a scheduled controller is at least MIN_TABLE_INTERVALS intervals
long and keeps every entry of the continuous one (:func:`ambseal.machine.table_grid`)."""

from __future__ import annotations

import numpy as np

from ambseal.machine import table_grid
from ambseal.machine.scheduled_digital import MIN_TABLE_INTERVALS


def test_two_entries_become_eight_even_intervals():
    np.testing.assert_allclose(table_grid([0.0, 1000.0]), np.linspace(0.0, 1000.0, 9),
                               rtol=0, atol=1e-12)


def test_uneven_entries_are_kept_and_each_interval_split_alike():
    theta = np.array([20.0, 50.0, 100.0, 150.0, 200.0, 250.0, 300.0])
    g = table_grid(theta)
    assert np.all(np.isin(theta, g)) and np.all(np.diff(g) > 0)
    assert g.size - 1 == 2 * (theta.size - 1) >= MIN_TABLE_INTERVALS
    np.testing.assert_allclose(g[1::2], (theta[:-1] + theta[1:]) / 2)
    dense = np.linspace(0.0, 1.0, 12)
    np.testing.assert_array_equal(table_grid(dense), dense)
