"""Nonlinear least squares ended by its own tolerances, never by a count of evaluations.

``scipy.optimize.least_squares`` stops at the first of its tolerances (status 1 ``gtol``,
2 ``ftol``, 3 ``xtol``, 4 ``ftol`` and ``xtol`` at once) or when ``max_nfev`` evaluations are
spent (status 0; by default ``100·n`` for ``trf``). A fit ended by the count depends on
the count, and on every rounding that moves the path by an evaluation.
:func:`least_squares_converged` continues such a fit from where the count stopped it, a
round of SciPy's default count at a time, until a tolerance ends it, or until a whole
round lowers the cost by less than ``ftol`` of it: SciPy's ``ftol`` test, which it applies
to one step, applied to the round. The fit has then stalled, and more rounds would not
move it.

A caller that reads another number of the fit than its cost (a D-scale fit's order is
chosen by its largest weighted error, not by the sum of squares) gives that number as
``stall``: the round's test is then applied to it, with its own relative tolerance.
"""

from __future__ import annotations

import numpy as np
from scipy.optimize import OptimizeResult, least_squares

__all__ = ["least_squares_converged"]

#: SciPy's default ``ftol`` of ``least_squares``, the round test's when none is given.
DEFAULT_FTOL = 1e-8


def least_squares_converged(fun, x0, *, stall=None, stall_rtol: float | None = None,
                            **kwargs) -> OptimizeResult:
    """``scipy.optimize.least_squares(fun, x0, **kwargs)`` run until one of its tolerances,
    or the round's stall test, ends it (module docstring).

    Parameters
    ----------
    fun : callable
        ``fun(x) -> ndarray``, the residuals, as for ``scipy.optimize.least_squares``.
    x0 : array_like, shape (n,)
        The start.
    stall : callable, optional
        ``stall(x) -> float``, the non-negative number of the fit the caller reads; a round
        that lowers it by less than ``stall_rtol`` of it (or raises it) ends the fit. The
        cost by default.
    stall_rtol : float, optional
        The round test's relative tolerance; ``ftol`` (SciPy's default 1e-8 when none is
        given) by default.
    **kwargs
        As for ``scipy.optimize.least_squares``. ``max_nfev`` is refused, because this
        function exists to remove a count.

    Returns
    -------
    scipy.optimize.OptimizeResult
        The last round's result. Its ``nfev`` and ``njev`` are summed over every round, and
        ``rounds`` is their number. ``status`` is the tolerance that ended it (1–4). A fit
        ended by the round's stall test has ``status`` 2 (``ftol``) and a ``message`` that
        says so.

    Raises
    ------
    TypeError
        ``max_nfev`` given.
    """
    if "max_nfev" in kwargs:
        raise TypeError("least_squares_converged: max_nfev is not taken (it runs to tolerance)")
    rtol = stall_rtol if stall_rtol is not None else (kwargs.get("ftol") or DEFAULT_FTOL)
    what = "the cost" if stall is None else "the stall measure"

    def measure(r):
        return r.cost if stall is None else float(stall(r.x))

    res = least_squares(fun, x0, **kwargs)
    nfev, njev, rounds = res.nfev, res.njev or 0, 1
    while res.status == 0:
        before = measure(res)
        # trf takes only steps that lower the cost, so a round from res.x never raises it;
        # a stall measure other than the cost may rise, which ends the fit too
        res = least_squares(fun, res.x, **kwargs)
        nfev, njev, rounds = nfev + res.nfev, njev + (res.njev or 0), rounds + 1
        after = measure(res)
        if res.status == 0 and before - after <= rtol * max(after, np.finfo(float).tiny):
            res.status = 2
            res.message = (f"stalled: a round of {res.nfev} evaluations lowered {what} "
                           f"by less than {rtol:g} of it")
    res.nfev, res.njev, res.rounds = nfev, njev, rounds
    return res
