"""Comparisons that rounding may not decide: ties, and a number against its limit.

A number ambseal computes differs between machines in its last digits (the BLAS kernels a
machine runs, its thread count) and is known only to the accuracy of the method that
computes it. Where a report turns such numbers into words — which axis is the worst, which
side of a limit a number lies on — the words must be the same on every machine:

* **ties**: values within :data:`TIE_RTOL` of the largest count as equal, and among equals
  the first in the order given wins (:func:`first_largest`; the rig's channel order for
  axes). The ζ and η axes of a symmetric bearing have the same sensitivity peak by
  symmetry, equal to rounding, and the worst axis is then the ζ one on every machine;
* **limits**: a value within a stated relative tolerance of its limit lies *on* the
  boundary (:func:`side_of`), and the words name both sides. Each number states its
  tolerance beside the rule it is graded by (ISO 14839-3's zones:
  :data:`ambseal.analysis.iso.ZONE_RTOL`; API 617's separation margins:
  :data:`SEPARATION_RTOL`; a design's μ against 1:
  :data:`ambseal.design.recipes.MU_BOUNDARY_RTOL`): the accuracy to which the number is
  computed, which exceeds the spread of one loop's number between machines. A value on
  the boundary on one machine is then on it or on the side it leans to on another, never
  on the far side.
"""

from __future__ import annotations

import math
from typing import Callable, Iterable, TypeVar

__all__ = ["TIE_RTOL", "SEPARATION_RTOL", "BELOW", "ON", "ABOVE", "first_largest",
           "beyond", "side_of"]

T = TypeVar("T")

#: Relative tolerance within which two values are the same value (:func:`first_largest`).
#: Values equal by symmetry (the ζ and η axes of one bearing) differ by rounding carried
#: through the synthesis of the controller, far below it; values that differ in fact (a
#: design's own asymmetry, two bearings) differ by more. The measurements are in
#: benchmarks/README.md ("What rounding may not decide").
TIE_RTOL = 1e-6

#: Relative tolerance within which a critical speed's separation margin lies on the
#: boundary of the margin API 617 requires of it (:func:`side_of` on the margin and the
#: requirement, both %). Both come from the running unbalance sweep
#: (:func:`ambseal.analysis.unbalance.running_unbalance`): the critical speed from a peak
#: refined to ~1e-4 of its speed, the requirement from the amplification factor's
#: half-power points, interpolated between the first sweep's speeds; 1e-3 of the
#: requirement is what the two resolve (benchmarks/README.md, "What rounding may not
#: decide").
SEPARATION_RTOL = 1e-3

#: The sides :func:`side_of` names.
BELOW, ON, ABOVE = "below", "on", "above"


def first_largest(items: Iterable[T], key: Callable[[T], float],
                  rtol: float = TIE_RTOL) -> T | None:
    """The first item whose value is within ``rtol`` of the largest.

    Parameters
    ----------
    items : iterable
        The candidates, in the order that breaks ties (for axes: the rig's channel order).
    key : callable
        ``key(item) → float``, the value compared (no NaN).
    rtol : float
        Relative tolerance (-) within which values count as equal: :data:`TIE_RTOL` by
        default.

    Returns
    -------
    item or None
        The first of the items tied with the largest; None without items.

    Examples
    --------
    >>> first_largest([("A_zeta", 1.7347937050777), ("A_eta", 1.7347937050780)],
    ...               key=lambda x: x[1])[0]
    'A_zeta'
    """
    pairs = [(item, float(key(item))) for item in items]
    if not pairs:
        return None
    top = max(v for _, v in pairs)
    floor = top - rtol * abs(top) if math.isfinite(top) else top
    return next(item for item, v in pairs if v >= floor)


def beyond(value: float, than: float, rtol: float = TIE_RTOL) -> bool:
    """Whether ``value`` is larger than ``than`` by more than a tie: the test by which a
    running maximum is replaced only by a larger value, never by an equal one that
    rounding made larger (:func:`first_largest`, one value at a time).

    Parameters
    ----------
    value, than : float
        The candidate and the largest so far.
    rtol : float
        Relative tolerance (-) within which they count as equal: :data:`TIE_RTOL` by
        default.

    Returns
    -------
    bool
    """
    return value > than + rtol * abs(than)


def side_of(value: float, limit: float, rtol: float) -> str:
    """Which side of ``limit`` a value lies on, to ``rtol``.

    Parameters
    ----------
    value, limit : float
        The number and its limit, in one unit.
    rtol : float
        Relative tolerance (-) of the value: within ``rtol·|limit|`` of the limit it is on
        the boundary.

    Returns
    -------
    str
        :data:`BELOW`, :data:`ON` or :data:`ABOVE`.

    Examples
    --------
    >>> side_of(2.9, 3.0, 1e-3), side_of(3.0004, 3.0, 1e-3), side_of(3.1, 3.0, 1e-3)
    ('below', 'on', 'above')
    """
    if abs(value - limit) <= rtol * abs(limit):
        return ON
    return BELOW if value < limit else ABOVE
