"""Whether an identification is physically plausible: estimates and intervals a real
machine can have, judged against the rig file that was fitted.

A fit can converge on records that do not hold what their columns say — displacements
recorded in millimetres (a factor 1000), a channel swapped, a wrong sensor gain — and
report estimates and intervals that are numbers but describe no bearing. The rules, per
kind of parameter:

* **every parameter**: a finite estimate and a finite 95 % interval.
* **AMB force factors** ``<amb>.Ki_<axis>`` (N/A) and ``<amb>.Ks_<axis>`` (N/m), and the
  **direct terms of a support** ``<spring>.kxx``, ``kyy``, ``cxx``, ``cyy``: the estimate
  within :data:`RATIO` (10×) of the rig file's value either way, with its sign — the rig
  file's values come from the bearing's geometry, its data sheet or a static test, which
  a real machine does not miss by an order of magnitude, while a unit slip (mm for m,
  mA for A) does; and a 95 % interval narrower than the estimate (width below
  |estimate|: the records fix the value to better than ±50 %; wider, they do not
  determine it at all). A rig-file value of 0 (an AMB without bias flux, a support
  without damping) gives no scale: finiteness only.
* **seal coefficients** ``<seal>.K``, ``k``, ``C``, ``c``, **cross-coupled support
  terms** ``kxy``, ``kyx``, and the lags ``tau_e``, ``tau_s``: zero and (but for the lags)
  either sign are physical values and the rig file's value is a prediction the test is
  there to replace, so no ratio and no interval rule; finiteness only.

``ambseal identify`` reports a fit that breaks a rule as a failed identification: the
reasons go into ``fit.json``, and no ``identified.toml`` is written unless
``--accept-implausible``.
"""

from __future__ import annotations

import math

import numpy as np

from ambseal.errors import IdentificationError
from ambseal.model import amb_factors

__all__ = ["RATIO", "implausible", "fit_failure", "first_nonfinite", "require_finite"]

#: How far (either way) an estimate of a force factor or a direct support coefficient may
#: lie from the rig file's value.
RATIO = 10.0
_DIRECT = ("kxx", "kyy", "cxx", "cyy")
_AXES = ("zeta", "eta")


def _rig_value(cfg, name: str) -> float | None:
    """The rig file's value of a force factor or direct support term; None for the other
    kinds (no scale of their own)."""
    owner, _, key = name.rpartition(".")
    for a in cfg.amb:
        if a.name == owner and key[:3] in ("Ki_", "Ks_") and key[3:] in _AXES:
            ki, ks = amb_factors(a)
            return float((ki if key[:2] == "Ki" else ks)[_AXES.index(key[3:])])
    for i, s in enumerate(cfg.spring):
        if (s.name or f"spring{i}") == owner and key in _DIRECT:
            v = getattr(s, key)  # a table over speed has no one scale
            return float(v) if isinstance(v, (int, float)) else None
    return None


def implausible(cfg, names, estimate, low, high) -> list[str]:
    """The rules (module docstring) an identification breaks, one sentence each.

    Parameters
    ----------
    cfg : RigConfig
        The rig that was fitted (its values are the scale of each rule).
    names : sequence of str
        The fitted parameters.
    estimate, low, high : array_like, shape (len(names),)
        Estimates and the ends of their 95 % intervals (SI).

    Returns
    -------
    list of str
        Empty for a plausible identification.

    Examples
    --------
    >>> from ambseal.config import load_rig
    >>> print(*implausible(load_rig(), ["A.Ki_zeta"], [2.1e5], [1.9e5], [2.3e5]))
    A.Ki_zeta: estimate 210000 is 1054× the rig file's 199.2 (expected within 10× either way: records in other units?)
    """
    out = []
    for n, v, lo, hi in zip(names, *(np.asarray(x, float) for x in (estimate, low, high))):
        if not all(math.isfinite(x) for x in (v, lo, hi)):
            out.append(f"{n}: estimate {v:g} with interval [{lo:g}, {hi:g}] is not finite")
            continue
        ref = _rig_value(cfg, n)
        if not ref:
            continue
        if not 1 / RATIO <= v / ref <= RATIO:
            out.append(f"{n}: estimate {v:g} is {v / ref:.4g}× the rig file's {ref:g} "
                       f"(expected within {RATIO:g}× either way: records in other units?)")
        elif hi - lo >= abs(v):
            out.append(f"{n}: the 95 % interval [{lo:g}, {hi:g}] is wider than the estimate "
                       f"{v:g} (the records do not determine it)")
    return out


def fit_failure(res, reasons: list[str], accept_unconverged: bool = False,
                accept_implausible: bool = False) -> tuple[str, str] | None:
    """Why a fit counts as failed and the flag that accepts it; None when it does not.

    Parameters
    ----------
    res : FitResult
        The fit (``converged``, ``message``).
    reasons : list of str
        Its broken rules (:func:`implausible`).
    accept_unconverged, accept_implausible : bool
        The command line's ``--accept-unconverged`` and ``--accept-implausible``.

    Returns
    -------
    (str, str) or None
        The reason and the flag.
    """
    if not res.converged and not accept_unconverged:
        return f"the fit failed ({res.message})", "--accept-unconverged"
    if reasons and not accept_implausible:
        return f"implausible identification: {'; '.join(reasons)}", "--accept-implausible"
    return None


def require_finite(tree, what: str):
    """``tree`` itself when it holds no NaN or ±inf (:func:`first_nonfinite`), else
    IdentificationError naming ``what`` and the key: checked before anything is written,
    as JSON has no non-finite numbers.

    Parameters
    ----------
    tree : dict or list
        A JSON-ready document.
    what : str
        What it is, at the front of the message.

    Returns
    -------
    dict or list
        ``tree`` itself.

    Raises
    ------
    IdentificationError
        A non-finite number in ``tree``.
    """
    bad = first_nonfinite(tree)
    if bad is not None:
        raise IdentificationError(f"{what}: {bad} is not a finite number (records of "
                                  "implausible values?); nothing was written")
    return tree


def first_nonfinite(tree, path: str = "") -> str | None:
    """The key path of the first NaN or ±inf in a JSON-ready tree, else None.

    Parameters
    ----------
    tree : dict, list, tuple or scalar
        What is about to be written as JSON.
    path : str
        The path of ``tree`` itself, put in front of the result.

    Examples
    --------
    >>> first_nonfinite({"a": [1.0, {"b": float("nan")}]})
    'a[1].b'
    """
    if isinstance(tree, float):
        return None if math.isfinite(tree) else (path or "(top level)")
    if isinstance(tree, dict):
        items = ((f"{path}.{k}" if path else str(k), v) for k, v in tree.items())
    elif isinstance(tree, (list, tuple)):
        items = ((f"{path}[{i}]", v) for i, v in enumerate(tree))
    else:
        return None
    for p, v in items:
        found = first_nonfinite(v, p)
        if found is not None:
            return found
    return None
