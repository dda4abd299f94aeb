"""The JSON conventions of every result's ``to_dict`` (``metrics.json`` and the other files).

* finite floats stay floats;
* ``+inf`` becomes the string ``"inf"`` and ``-inf`` the string ``"-inf"``;
* ``NaN`` becomes ``None``;
* numpy scalars and arrays become Python ``float``/``int``/``bool`` and lists;
* a quantity that has no value where it is not finite (the σ̄ peak or the settling time of
  an unstable loop, an interval bound that could not be computed) becomes ``None`` there
  (:func:`finite_or_none`; through a whole record, :func:`finite_or_none_tree`), not
  ``"inf"``.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np


def json_float(x: float | None) -> float | str | None:
    """Map a float to a JSON-safe value (``inf`` -> ``"inf"``, ``NaN`` -> ``None``).

    Parameters
    ----------
    x : float or None
        Any real number (a numpy scalar too); ``None`` stays ``None``.

    Returns
    -------
    float, str or None
        ``float(x)`` if finite, ``"inf"`` or ``"-inf"``, or ``None`` for NaN and ``None``.
    """
    if x is None:
        return None
    x = float(x)
    if math.isnan(x):
        return None
    if math.isinf(x):
        return "inf" if x > 0 else "-inf"
    return x


def finite_or_none(x: float) -> float | None:
    """``float(x)``, or ``None`` where ``x`` is not finite (the module's last rule).

    Parameters
    ----------
    x : float
        Any real number (a numpy scalar too).

    Returns
    -------
    float or None
    """
    x = float(x)
    return x if math.isfinite(x) else None


def finite_or_none_tree(x: Any) -> Any:
    """``x`` with :func:`finite_or_none` applied to every float in it, walking dicts, lists
    and tuples (tuples become lists); other values unchanged.

    Parameters
    ----------
    x : object
        A float, or a dict, list or tuple nesting them (a record's ``to_dict()``).

    Returns
    -------
    object
        The same structure, every non-finite float replaced by ``None``.
    """
    if isinstance(x, dict):
        return {k: finite_or_none_tree(v) for k, v in x.items()}
    if isinstance(x, (list, tuple)):
        return [finite_or_none_tree(v) for v in x]
    if isinstance(x, (float, np.floating)):
        return finite_or_none(x)
    return x


def json_list(a: Any) -> list:
    """Map a real array to a (nested) list of JSON-safe values.

    Parameters
    ----------
    a : array_like of float
        Any shape; a scalar gives a list of one.

    Returns
    -------
    list
        Nested as the array's dimensions, each value as :func:`json_float` maps it.
    """
    arr = np.asarray(a, dtype=float)
    if arr.ndim == 0:
        return [json_float(arr)]
    if arr.ndim == 1:
        return [json_float(v) for v in arr]
    return [json_list(row) for row in arr]
