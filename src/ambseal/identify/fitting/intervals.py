"""Identified intervals as the uncertainty of a robust design (thesis P5 §4.1: μ-synthesis
over the parameter ranges the identification leaves).

``ambseal identify`` writes ``fit.json`` with a 95 % interval per parameter that includes
the error budget of the values it held fixed (:mod:`ambseal.identify.fitting.budget`);
:func:`uncertainty_from_fit` reads those intervals into the ``{parameter: (low, high)}``
ranges (SI) that :func:`ambseal.design.plant.generalized_plant` and
:func:`ambseal.design.recipes.design` take as ``uncertainty``. Design on the identified
rig (``identified.toml``), whose nominal values are the estimates the intervals surround.
"""

from __future__ import annotations

import json
import math
from pathlib import Path

from ambseal.errors import AmbsealError, DataError
from ambseal.files import read_text

__all__ = ["uncertainty_from_fit"]


def uncertainty_from_fit(path: str | Path, names=None) -> dict[str, tuple[float, float]]:
    """The 95 % intervals of an identification's ``fit.json`` as μ uncertainty ranges.

    Parameters
    ----------
    path : str or Path
        ``fit.json`` written by ``ambseal identify``.
    names : iterable of str, optional
        The parameters to take; default every fitted model parameter (``tau_e``, a lag in
        series with the actuator rather than a plant parameter, is left out).

    Returns
    -------
    dict
        ``{name: (low, high)}`` in SI.

    Raises
    ------
    DataError
        An unreadable file, no ``parameters`` table, a requested name it does not hold, or
        an interval that is missing or not finite (a fit whose covariance failed), naming
        the file and the parameter. A fit whose intervals understate the uncertainty is
        refused too: residuals that correlate with the excitation, a sensor lag the data
        ask for (:mod:`ambseal.identify.fitting.sensor_lag`), or a fixed value the data dispute
        by more than the 95 % band of its stated uncertainty (the offset the score test
        suggests beyond 1.96 σ: the budget in the intervals does not cover it).
    """
    p = Path(path)
    try:
        fit = json.loads(read_text(p, "identification"))
    except AmbsealError as exc:  # missing, not a regular file, too large, not UTF-8
        raise DataError(str(exc)) from None
    except json.JSONDecodeError as exc:
        raise DataError(f"{p}: not valid JSON ({exc.msg}, line {exc.lineno})") from None
    params = fit.get("parameters") if isinstance(fit, dict) else None
    if not isinstance(params, dict) or not params:
        raise DataError(f"{p}: parameters: expected the table of an `ambseal identify` fit")
    if (fit.get("residual_tests") or {}).get("mismatch"):
        raise DataError(f"{p}: residual_tests: model mismatch — its intervals understate the "
                        "uncertainty; fix the model (see the fit's warnings) before designing "
                        "on them")
    if ((fit.get("model_check") or {}).get("sensor_lag")
            or (fit.get("sensor_lag_test") or {}).get("flagged")):
        raise DataError(f"{p}: sensor_lag_test: model mismatch — the data ask for a sensor "
                        "lag the model lacks, so its intervals understate the uncertainty; "
                        "fit tau_s (see the fit's warnings) before designing on them")
    beyond = _disputed_beyond_budget(fit)
    if beyond:
        raise DataError(f"{p}: error_budget.disputed: model mismatch — the data put "
                        f"{', '.join(beyond)} outside the uncertainty the intervals carry for "
                        "it; fit it (see the fit's warnings) before designing on them")
    wanted = [n for n in params if n != "tau_e"] if names is None else list(names)
    out = {}
    for n in wanted:
        if n not in params:
            raise DataError(f"{p}: parameters.{n}: not in this identification (it holds "
                            f"{', '.join(params)})")
        ci = params[n].get("ci95") if isinstance(params[n], dict) else None
        if (not isinstance(ci, list) or len(ci) != 2 or
                not all(isinstance(v, (int, float)) and math.isfinite(v) for v in ci)
                or not ci[0] < ci[1]):
            raise DataError(f"{p}: parameters.{n}.ci95: expected [low, high], finite with "
                            f"low < high, got {ci!r}")
        out[n] = (float(ci[0]), float(ci[1]))
    return out


def _disputed_beyond_budget(fit: dict) -> list[str]:
    """Disputed fixed values of a fit.json whose suggested offset exceeds 1.96 σ_stated."""
    budget = fit.get("error_budget") or {}
    tests, fixed = budget.get("score_test") or {}, budget.get("fixed") or {}
    out = []
    for n in budget.get("disputed") or []:
        try:
            off, sig = float(tests[n]["offset_rel"]), float(fixed[n]["sigma_rel"])
        except (KeyError, TypeError, ValueError):
            out.append(n)
            continue
        if not abs(off) <= 1.96 * sig:
            out.append(n)
    return out
