"""Identified intervals as the uncertainty of a robust design (thesis P5 §4.1: μ-synthesis
over the parameter ranges the identification leaves).

``ambseal identify`` writes ``fit.json`` with a 95 % interval per parameter that includes
the error budget of the values it held fixed (:mod:`ambseal.identify.fitting.budget`);
:func:`uncertainty_from_fit` reads those intervals into the ``{parameter: (low, high)}``
ranges (SI) that :func:`ambseal.design.plant.generalized_plant` and
:func:`ambseal.design.recipes.design` take as ``uncertainty``. Design on the identified
rig (``identified.toml``), whose nominal values are the estimates the intervals surround.

The reader checks the type of every field it reads against :class:`_FitFile` (a file may
be edited by hand): a wrong type anywhere is one :class:`~ambseal.errors.DataError` naming
the file and the field; the fields it does not read are left as they are.
"""

from __future__ import annotations

import json
import math
from pathlib import Path

from pydantic import BaseModel, ConfigDict, ValidationError

from ambseal.errors import PRIMITIVE_TAGS, AmbsealError, DataError, describe_validation_error
from ambseal.files import read_text

__all__ = ["uncertainty_from_fit"]


class _Fields(BaseModel):
    """A table of fit.json: the keys the reader uses typed strictly (``true`` is no number,
    ``"1"`` no boolean), the others kept unread."""

    model_config = ConfigDict(strict=True, extra="allow", frozen=True)


class _Parameter(_Fields):
    # None entries: a fit whose covariance failed writes its interval's ends as null
    ci95: list[float | None] | None = None


class _Flag(_Fields):
    mismatch: bool = False


class _ModelCheck(_Fields):
    sensor_lag: bool = False


class _SensorLag(_Fields):
    flagged: bool = False


class _Fixed(_Fields):
    sigma_rel: float | None = None


class _Score(_Fields):
    offset_rel: float | None = None


class _Budget(_Fields):
    fixed: dict[str, _Fixed] | None = None
    score_test: dict[str, _Score] | None = None
    disputed: list[str] | None = None


class _FitFile(_Fields):
    """The fields of ``fit.json`` (:meth:`ambseal.identify.fitting.fit.FitResult.to_dict`)
    that decide whether its intervals may be designed on, and the intervals."""

    parameters: dict[str, _Parameter]
    residual_tests: _Flag | None = None
    model_check: _ModelCheck | None = None
    sensor_lag_test: _SensorLag | None = None
    error_budget: _Budget | None = None


#: The names pydantic puts into an error's location besides the keys.
_TAGS = PRIMITIVE_TAGS | {c.__name__ for c in (_Fields, *_Fields.__subclasses__())}


def _read(p: Path) -> _FitFile:
    """The fit of ``p``, every field the reader uses of the right type, else DataError
    naming ``p`` and the field."""
    try:
        doc = json.loads(read_text(p, "identification"))
    except AmbsealError as exc:  # missing, not a regular file, too large, not UTF-8
        raise DataError(str(exc)) from None
    except json.JSONDecodeError as exc:
        raise DataError(f"{p}: not valid JSON ({exc.msg}, line {exc.lineno})") from None
    except RecursionError:
        raise DataError(f"{p}: not valid JSON (nested too deeply)") from None
    params = doc.get("parameters") if isinstance(doc, dict) else None
    if not isinstance(params, dict) or not params:
        raise DataError(f"{p}: parameters: expected the table of an `ambseal identify` fit")
    try:
        return _FitFile.model_validate(doc)
    except ValidationError as exc:
        raise DataError(f"{p}: {describe_validation_error(exc, _TAGS)}") from None


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
        An unreadable file, no ``parameters`` table, a field of the wrong type (a list
        where a table belongs, a string where a number or true/false does: every field
        the reader uses is checked), a requested name it does not hold, or an interval
        that is missing or not finite (a fit whose covariance failed), naming the file and
        the field. A fit whose intervals understate the uncertainty is refused too:
        residuals that correlate with the excitation, a sensor lag the data ask for
        (:mod:`ambseal.identify.fitting.sensor_lag`), or a fixed value the data dispute by
        more than the 95 % band of its stated uncertainty (the offset the score test
        suggests beyond 1.96 σ: the budget in the intervals does not cover it).
    """
    p = Path(path)
    fit = _read(p)
    params = fit.parameters
    if fit.residual_tests is not None and fit.residual_tests.mismatch:
        raise DataError(f"{p}: residual_tests: model mismatch — its intervals understate the "
                        "uncertainty; fix the model (see the fit's warnings) before designing "
                        "on them")
    if ((fit.model_check is not None and fit.model_check.sensor_lag)
            or (fit.sensor_lag_test is not None and fit.sensor_lag_test.flagged)):
        raise DataError(f"{p}: sensor_lag_test: model mismatch — the data ask for a sensor "
                        "lag the model lacks, so its intervals understate the uncertainty; "
                        "fit tau_s (see the fit's warnings) before designing on them")
    beyond = _disputed_beyond_budget(fit.error_budget)
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
        ci = params[n].ci95
        if (ci is None or len(ci) != 2 or not all(v is not None and math.isfinite(v)
                                                  for v in ci) or not ci[0] < ci[1]):
            raise DataError(f"{p}: parameters.{n}.ci95: expected [low, high], finite with "
                            f"low < high, got {ci!r}")
        out[n] = (float(ci[0]), float(ci[1]))
    return out


def _disputed_beyond_budget(budget: _Budget | None) -> list[str]:
    """Disputed fixed values of a fit whose suggested offset exceeds 1.96 σ_stated (a
    disputed value without its offset or its σ counts as beyond)."""
    if budget is None:
        return []
    tests, fixed = budget.score_test or {}, budget.fixed or {}
    out = []
    for n in budget.disputed or []:
        off = tests[n].offset_rel if n in tests else None
        sig = fixed[n].sigma_rel if n in fixed else None
        if off is None or sig is None or not abs(off) <= 1.96 * sig:
            out.append(n)
    return out
