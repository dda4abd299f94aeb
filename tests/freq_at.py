"""A state space's transfer matrix at complex points by dense solves,
``C (xI − A)⁻¹ B + D`` (numpy's LU), for the tests' references.

python-control 0.10.2's own evaluation (``sys(x)``, ``frequency_response``: slycot's
TB05AD) was found off by up to an order of magnitude on a delayed discrete H∞ controller
of the turboexpander at 300 Hz (against its steady-state time response by
``forced_response`` and against the virtual facility), so references take this instead.
"""

import numpy as np


def at(sys, x):
    """``sys`` (a python-control StateSpace) at the complex point ``x`` (s, or z of a
    discrete system): an ndarray of shape (ny, nu)."""
    A, B, C, D = (np.asarray(getattr(sys, m), dtype=complex) for m in "ABCD")
    if A.shape[0] == 0:
        return D
    return C @ np.linalg.solve(x * np.eye(A.shape[0]) - A, B) + D
