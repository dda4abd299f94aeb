"""Pickling of python-control state-space systems, so results travel to worker processes.

python-control 0.10 builds each ``StateSpace`` with two lambdas (its nonlinear-system
update and output functions), which the standard :mod:`pickle` refuses. :func:`picklable`
registers, once per process, a :mod:`copyreg` reducer that stores a system as its
matrices, time base, signal and state names and name, and rebuilds it with
``control.ss``. It is called by the functions that hand out ambseal's state-space objects
(the plant and controller constructors of the layers above), so every system made
through ambseal pickles with the standard library; unpickling imports this module and
registers it there too. An interconnected system (``LinearICSystem``) comes back as a plain
``StateSpace`` with the same matrices and names.
"""

from __future__ import annotations

import copyreg

import control

__all__ = ["picklable"]

_DONE = False


def _rebuild(A, B, C, D, dt, inputs, outputs, states, name):
    picklable()
    return control.ss(A, B, C, D, dt, inputs=inputs, outputs=outputs, states=states, name=name)


def _reduce(sys):
    return _rebuild, (sys.A, sys.B, sys.C, sys.D, sys.dt, list(sys.input_labels),
                      list(sys.output_labels), list(sys.state_labels), sys.name)


def picklable() -> None:
    """Register the reducer for ``control.StateSpace`` (and ``LinearICSystem``); idempotent.

    Imports python-control, so call it where a state-space system is made anyway.
    """
    global _DONE
    if _DONE:
        return

    for cls in (control.StateSpace, getattr(control, "LinearICSystem", None)):
        if cls is not None:
            copyreg.pickle(cls, _reduce)
    _DONE = True
