"""Tables against one parameter: linear interpolation, held constant outside the table.

One rule for every tabulated quantity of ambseal — coefficients against frequency, and the
state-space matrices of scheduled controllers against their parameter.
"""

from __future__ import annotations

import numpy as np

__all__ = ["interp_table"]


def interp_table(x: float, grid, values):
    """Linear interpolation in a table, held constant outside it.

    Parameters
    ----------
    x : float
        Where to evaluate, in the unit of ``grid``.
    grid : array_like, shape (n,)
        Strictly increasing abscissae (n ≥ 1).
    values : array_like, shape (n,) or (n, ...)
        Tabulated scalars, or a stack of arrays (e.g. matrices) stacked along the first dimension.

    Returns
    -------
    float or ndarray
        A float for scalar tables (exactly ``numpy.interp``); for stacks
        (1 − t)·values[j] + t·values[j+1] with t = (x − grid[j])/(grid[j+1] − grid[j]),
        shape ``values.shape[1:]``.
    """
    g = np.asarray(grid, float)
    v = np.asarray(values, float)
    if v.ndim == 1:
        return float(np.interp(x, g, v))
    if g.size == 1 or x <= g[0]:
        return v[0].copy()
    if x >= g[-1]:
        return v[-1].copy()
    j = int(np.clip(np.searchsorted(g, x) - 1, 0, g.size - 2))
    t = (x - g[j]) / (g[j + 1] - g[j])
    return (1 - t) * v[j] + t * v[j + 1]
