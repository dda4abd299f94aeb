"""Stability and performance maps over pressure × speed × parameters, serial or on Dask.

The cases run on :func:`ambseal.analysis.cases.run_cases` (serial or Dask).

* :func:`sweep` — the map: per (controller, pressure, speed, parameter values) case the
  judgement of :func:`ambseal.analysis.judge.judge` without the impulse response (closed-loop
  max real pole, σ̄(S_o) peak, ISO 14839-3 zone overall and per axis, unbalance peak) and the
  lowest log decrement of :mod:`ambseal.analysis.campbell`, as plain rows for a table;
  :func:`stability_boundary`, the pressure where the loop turns unstable per (controller,
  speed, parameters), bracketed by the grid and interpolated, and :func:`refine_boundary`,
  the same bisected on the closed-loop poles to a stated tolerance.

Inputs of a sweep case are plain and picklable: the rig as a dict (``RigConfig.model_dump``),
each fixed controller as its ``(A, B, C, D)`` arrays and signal names, a scheduled one as its
table (:class:`~ambseal.machine.ScheduledDigital`, frozen at each case's speed or seal
coefficient).

A controller that runs on a target (a controller file of ``ambseal design``: its
:class:`~ambseal.robust.DigitalController` or table) is judged as it runs too, the discrete
controller with its computation delay on the plant sampled at its rate, as ``ambseal run``
judges it: the row's ``*_as_runs`` columns (``stable_as_runs``, ``max_abs_pole_z``,
``sensitivity_peak_as_runs``, ``iso_zone_as_runs`` and per axis, ``unbalance_peak_um_as_runs``).
A controller that exists only as it runs (an H∞ or μ designed on the sampled plant,
:attr:`~ambseal.robust.DigitalController.as_runs_only`: its continuous form is the w-plane
controller, no loop that runs) is judged as it runs alone: every column, and the stability
boundary's bisection, is its loop as it runs (``max_real_pole`` is ln max|z| / T).
"""

from __future__ import annotations

import itertools
import math

import control
import numpy as np

from ambseal.analysis.campbell import (closed_loop_state_matrix, lowest_log_decrement,
                                       state_matrix_as_run)
from ambseal.analysis.cases import CaseError, run_cases
from ambseal.analysis.judge import (JudgeSettings, OperatingPoint, frozen_at, frozen_discrete,
                                   judge)
from ambseal.config import parse_rig, rig_with_values
from ambseal.errors import ConfigError
from ambseal.lti import json_float
from ambseal.machine import SPEED, ScheduledController
from ambseal.model import bending_limit_hz
from ambseal.robust import is_stable

__all__ = ["MAX_RANGE_POINTS", "sweep", "sweep_case", "check_cases", "stability_boundary",
           "refine_boundary", "boundary_case", "parse_range"]

#: The most points a range ``a:b:n`` of the command line may ask for (:func:`parse_range`):
#: each point of a Campbell diagram or a sweep is an eigen-decomposition or a judgement of
#: the full model (tens of milliseconds to seconds), so 10 000 points are hours of work.
MAX_RANGE_POINTS = 10000

def parse_range(text: str, name: str) -> np.ndarray:
    """``a:b:n`` → n points from a to b; a single number → one point.

    ``a`` and ``b`` are finite numbers below 1e12 in size (the command line's rule for
    every number); ``n`` is a whole number from 1 to :data:`MAX_RANGE_POINTS`.

    Parameters
    ----------
    text : str
        The range as given on the command line.
    name : str
        The argument's name, for the error message.

    Returns
    -------
    numpy.ndarray
        The points, shape (n,).

    Raises
    ------
    ConfigError
        Anything else (names ``name`` and what was expected), before any work.

    Examples
    --------
    >>> parse_range("0:4:5", "--pressure-bar")
    array([0., 1., 2., 3., 4.])
    """
    parts = text.split(":")
    try:
        ends = [float(p) for p in (parts[:1] if len(parts) == 1 else parts[:2])]
        count = 1 if len(parts) == 1 else int(parts[2]) if len(parts) == 3 else None
    except ValueError:
        count = None
    if count is None:
        raise ConfigError(f"{name}: expected a number or start:stop:count (e.g. 0:4.08:9), "
                          f"got {text!r}")
    if not all(np.isfinite(x) and abs(x) < 1e12 for x in ends):
        raise ConfigError(f"{name}: expected finite numbers below 1e12 in size, got {text!r}")
    if not 1 <= count <= MAX_RANGE_POINTS:
        raise ConfigError(f"{name}: expected a count from 1 to {MAX_RANGE_POINTS}, got "
                          f"{text!r}")
    return np.linspace(ends[0], ends[-1], count)


def sweep_case(case: dict, rig: dict, controllers: dict, max_hz: float,
               settings: JudgeSettings, digitals: dict | None = None) -> dict:
    """One map point: the judgement without impulse and the lowest log decrement.

    Parameters
    ----------
    case : dict
        ``controller`` (a key of ``controllers``), ``pressure_bar``, ``speed_hz`` and
        ``params`` (``{name: value}`` of :func:`ambseal.config.rig_with_values`).
    rig : dict
        The rig (``RigConfig.model_dump()``).
    controllers : dict
        ``{name: (A, B, C, D, inputs, outputs)}``, displacement (m) → current (A),
        ``i = −K y``, wired to the plant by its signal names; ``(A, B, C, D)`` alone is
        taken in the plant's channel order; or ``{name: ScheduledController}`` (a controller
        file's table, :class:`~ambseal.machine.ScheduledDigital`), frozen at the case's
        speed or at the nominal rig's seal coefficient at the case's pressure
        (:func:`ambseal.analysis.judge.frozen_at`, as ``run`` judges it); or ``{name:
        DigitalController}`` that exists only as it runs, judged as it runs alone
        (module docstring).
    max_hz : float
        Highest frequency (Hz) of the modes the lowest log decrement is taken over.
    settings : JudgeSettings
        The nominal rig's :func:`~ambseal.analysis.judge.judge_settings`.
    digitals : dict, optional
        ``{name: DigitalController or ScheduledDigital}``: the controllers that run on a
        target, judged as they run too (module docstring).

    Returns
    -------
    dict
        The case, ``stable``, ``max_real_pole`` (1/s), ``lowest_log_dec`` and its
        ``lowest_log_dec_hz``, ``log_dec_ok`` (no mode's log decrement below the rig's
        ``[signoff] log_dec_min``, the sign-off's limit, 0.1 by default: a stable loop
        with a zone A σ̄(S_o) may still have a mode too lightly damped to pass),
        ``sensitivity_peak`` (σ̄(S_o), -), ``iso_zone`` and ``iso_zone_<axis>``,
        ``unbalance_peak_um``; for a controller of ``digitals`` the same as it runs
        (module docstring).
    """

    nominal, cfg = _case_rig(rig, case.get("params"))
    point = OperatingPoint(case["pressure_bar"], 60.0 * case["speed_hz"], "")
    entry = controllers[case["controller"]]
    K = _controller(entry, point, nominal)
    g = (digitals or {}).get(case["controller"])
    on_speed = getattr(g, "parameter", None) == SPEED  # the running unbalance at each speed
    res, curves = judge(cfg, K, case["controller"], point, settings, impulse=False,
                        # one that exists only as it runs: its loop judged once, as it runs
                        discrete=K if _as_runs_only(entry) else frozen_discrete(g, point,
                                                                                 nominal),
                        schedule=entry if on_speed else None,
                        schedule_discrete=g if on_speed else None)
    dec, dec_hz = lowest_log_decrement(curves["poles"], max_hz)
    row = {"controller": case["controller"], "pressure_bar": case["pressure_bar"],
           "speed_hz": case["speed_hz"], **(case.get("params") or {}),
           "stable": res.stable, "max_real_pole": json_float(res.max_real_pole),
           "lowest_log_dec": dec, "lowest_log_dec_hz": dec_hz,
           "log_dec_ok": bool(not dec < cfg.signoff.log_dec_min),  # NaN: no mode
           "sensitivity_peak": res.sensitivity_peak, "iso_zone": res.iso_zone}
    row.update({f"iso_zone_{ax}": z for ax, z in res.iso_zone_per_axis.items()})
    row["unbalance_peak_um"] = res.unbalance_peak_um
    d = res.discrete
    if d is not None:
        row.update({"stable_as_runs": d.stable, "max_abs_pole_z": d.max_abs_pole_z,
                    "sensitivity_peak_as_runs": d.sensitivity_peak,
                    "iso_zone_as_runs": d.iso_zone,
                    **{f"iso_zone_{ax}_as_runs": z for ax, z in d.iso_zone_per_axis.items()},
                    "unbalance_peak_um_as_runs": d.unbalance_peak_um})
    return row


def _case_rig(rig: dict, params: dict | None):
    """(the nominal rig, the case's rig with ``params``)."""
    cfg = parse_rig(rig, "<sweep rig>")
    return cfg, (rig_with_values(cfg, params) if params else cfg)


def _shared(cfg, controllers: dict) -> dict:
    """The plain, picklable inputs every case of a sweep shares; each controller keeps its
    signal names, so that the case wires it to the plant by name (a scheduled table is
    plain already)."""
    return {"rig": cfg.model_dump(exclude_none=True),
            "controllers": {n: K if isinstance(K, ScheduledController) or _as_runs_only(K) else
                            (*(np.asarray(M, float) for M in (K.A, K.B, K.C, K.D)),
                             list(K.input_labels), list(K.output_labels))
                            for n, K in controllers.items()}}


def _as_runs_only(K) -> bool:
    """Whether ``K`` exists only as it runs (a design on the sampled plant,
    :attr:`~ambseal.robust.DigitalController.as_runs_only`)."""
    return bool(getattr(K, "as_runs_only", False))


def _controller(entry, point: OperatingPoint, nominal):
    """A case's controller at ``point`` as a StateSpace: ``(A, B, C, D[, inputs,
    outputs])``, a scheduled one frozen there on the ``nominal`` rig, or one that exists
    only as it runs, its delayed discrete controller."""
    if _as_runs_only(entry):
        return frozen_discrete(entry, point, nominal)
    if isinstance(entry, ScheduledController):
        return frozen_at(entry, point, nominal)
    mats, names = entry[:4], entry[4:]
    return control.ss(*mats, **dict(zip(("inputs", "outputs"), names)))


def check_cases(n: int, what: str) -> None:
    """Refuse a map of more than :data:`MAX_RANGE_POINTS` cases before any work.

    Parameters
    ----------
    n : int
        Cases asked for (the product of the ranges and the controllers).
    what : str
        The command, for the message.

    Raises
    ------
    ConfigError
        ``n`` above :data:`MAX_RANGE_POINTS`.
    """
    if n > MAX_RANGE_POINTS:
        raise ConfigError(f"{what}: {n} cases (the product of the ranges and controllers); "
                          f"expected at most {MAX_RANGE_POINTS}: use fewer points per range")


def sweep(cfg, controllers: dict, pressures_bar, speeds_hz, params: dict | None = None, *,
          settings: JudgeSettings, max_hz: float | None = None, workers: int | None = None,
          scheduler: str | None = None, progress: bool = False,
          digitals: dict | None = None) -> list[dict]:
    """The map over every (controller, pressure, speed, parameter values) combination.

    Parameters
    ----------
    cfg : RigConfig
    controllers : dict
        ``{name: control.StateSpace}`` (fixed controllers), ``{name:
        ScheduledController}`` (frozen at each case as :func:`sweep_case` says), or ``{name:
        DigitalController}`` for one that exists only as it runs (module docstring).
    pressures_bar, speeds_hz : array_like
    params : dict, optional
        ``{name: values}`` of rig parameters (:func:`ambseal.config.rig_with_values` names).
    settings : JudgeSettings
        The nominal rig's :func:`~ambseal.analysis.judge.judge_settings`: every case is
        judged on the same grids and disturbances, also when ``params`` change the rig.
    max_hz : float, optional
        Modes of the lowest log decrement; default
        :func:`ambseal.model.modes.bending_limit_hz`.
    workers, scheduler, progress
        As in :func:`run_cases`.
    digitals : dict, optional
        ``{name: DigitalController or ScheduledDigital}``: those of ``controllers`` that
        run on a target, judged as they run too (:func:`sweep_case`).

    Returns
    -------
    list of dict
        One row per case in input order (controller outermost, then pressure, speed,
        parameters); a failed case has its inputs and ``error``.
    """

    params = params or {}
    names = list(params)
    check_cases(len(controllers) * len(pressures_bar) * len(speeds_hz)
                * math.prod(len(params[n]) for n in names), "sweep")
    cases = [{"controller": c, "pressure_bar": float(p), "speed_hz": float(s),
              "params": dict(zip(names, (float(x) for x in vals)))}
             for c in controllers for p in pressures_bar for s in speeds_hz
             for vals in itertools.product(*(params[n] for n in names))]

    shared = {**_shared(cfg, controllers), "settings": settings,
              "max_hz": bending_limit_hz(cfg) if max_hz is None else float(max_hz),
              "digitals": dict(digitals or {})}
    out = run_cases(sweep_case, cases, shared=shared, workers=workers, scheduler=scheduler,
                    progress=progress, description="sweep")
    return [{**{k: v for k, v in r.case.items() if k != "params"}, **r.case["params"],
             "error": r.error} if isinstance(r, CaseError) else r for r in out]


def stability_boundary(rows: list[dict]) -> list[dict]:
    """Per (controller, speed, parameter values): the pressure drop (bar) where the loop
    loses stability, linearly interpolated in the max real pole between the last stable
    and the first unstable pressure; ``None`` if stable over the whole range, the lowest
    pressure if unstable throughout.

    Parameters
    ----------
    rows : list of dict
        Rows of :func:`sweep` (``pressure_bar``, ``max_real_pole`` in rad/s, ...); rows
        with an ``error`` are left out.

    Returns
    -------
    list of dict
        One row per group: its inputs, ``boundary_pressure_bar``, ``last_stable_bar`` and
        ``first_unstable_bar`` (bar, or None).
    """
    groups: dict[tuple, list[dict]] = {}
    for r in rows:
        if r.get("error") is None:
            key = tuple((k, v) for k, v in r.items()
                        if not _is_result(k) and k != "pressure_bar")
            groups.setdefault(key, []).append(r)
    out = []
    for key, rs in groups.items():
        rs = sorted(rs, key=lambda r: r["pressure_bar"])
        p = np.array([r["pressure_bar"] for r in rs])
        m = np.array([r["max_real_pole"] for r in rs])
        bad = np.flatnonzero(m >= 0)
        if bad.size == 0:
            edge = None
        elif bad[0] == 0:
            edge = float(p[0])
        else:
            i = bad[0]
            edge = float(p[i - 1] + (p[i] - p[i - 1]) * (-m[i - 1]) / (m[i] - m[i - 1]))
        out.append({**dict(key), "boundary_pressure_bar": edge,
                    "last_stable_bar": float(p[bad[0] - 1]) if bad.size and bad[0] > 0
                    else (float(p[-1]) if bad.size == 0 else None),
                    "first_unstable_bar": float(p[bad[0]]) if bad.size else None})
    return out


def boundary_case(case: dict, rig: dict, controllers: dict, tol_bar: float) -> float:
    """Bisect one bracket ``case = {controller, speed_hz, params, last_stable_bar,
    first_unstable_bar}`` of the stability boundary to ``tol_bar`` (bar) on the max real
    part of the closed-loop poles (the loop of :func:`sweep_case`)."""

    nominal, cfg = _case_rig(rig, case.get("params"))
    entry = controllers[case["controller"]]
    lo, hi = case["last_stable_bar"], case["first_unstable_bar"]
    while hi - lo > tol_bar:
        mid = 0.5 * (lo + hi)
        if not lo < mid < hi:  # the bracket is two adjacent floats: no narrower one exists
            break
        if _as_runs_only(entry):  # its loop as it runs: stable inside the unit circle
            A, _ = state_matrix_as_run(cfg, entry, speed_hz=case["speed_hz"],
                                       pressure_bar=mid)
            stable = bool(np.abs(np.linalg.eigvals(A)).max(initial=0.0) < 1.0)
        else:
            K = _controller(entry, OperatingPoint(mid, 60.0 * case["speed_hz"], ""), nominal)
            A, _ = closed_loop_state_matrix(cfg, K,
                                            speed_hz=case["speed_hz"], pressure_bar=mid,
                                            delay=True)  # the loop judge() judges
            stable = is_stable(np.linalg.eigvals(A))
        lo, hi = (mid, hi) if stable else (lo, mid)
    return 0.5 * (lo + hi)


def refine_boundary(cfg, controllers: dict, edges: list[dict], *, tol_bar: float = 0.01,
                    workers: int | None = None, scheduler: str | None = None,
                    progress: bool = False) -> list[dict]:
    """The edges of :func:`stability_boundary` with ``boundary_pressure_bar`` bisected
    between the grid's last stable and first unstable pressure to ``tol_bar`` (bar), each
    bracket a case of :func:`run_cases`; edges without a bracket are returned as they are,
    a failed bisection keeps the interpolated value and gets an ``error``.

    Parameters
    ----------
    cfg : RigConfig
        The rig the sweep was made on.
    controllers : dict
        The sweep's controllers (:func:`sweep`).
    edges : list of dict
        Rows of :func:`stability_boundary`.
    tol_bar : float
        Width (bar) of the final bracket; the boundary is its middle.
    workers : int, optional
        As in :func:`run_cases`.
    scheduler : str, optional
        As in :func:`run_cases`.
    progress : bool
        As in :func:`run_cases`.

    Returns
    -------
    list of dict
        Copies of ``edges``; bisected ones with ``boundary_pressure_bar`` and
        ``boundary_tolerance_bar`` (bar).

    Raises
    ------
    ConfigError
        ``tol_bar`` not a finite number above 0, or a Dask ``scheduler`` or ``workers``
        that cannot be used (:func:`run_cases`).
    """
    if not (math.isfinite(tol_bar) and tol_bar > 0):
        raise ConfigError(f"tol_bar: expected a finite pressure above 0 bar, got {tol_bar!r}")
    todo = [i for i, e in enumerate(edges)
            if e["last_stable_bar"] is not None and e["first_unstable_bar"] is not None]
    cases = [{k: v for k, v in edges[i].items() if k != "boundary_pressure_bar"}
             for i in todo]
    for c in cases:
        c["params"] = {k: v for k, v in c.items() if k not in _BRACKET}
    res = run_cases(boundary_case, cases, shared={**_shared(cfg, controllers),
                                                   "tol_bar": tol_bar},
                    workers=workers, scheduler=scheduler, progress=progress,
                    description="stability boundary")
    out = [dict(e) for e in edges]
    for i, r in zip(todo, res):
        if isinstance(r, CaseError):
            out[i]["error"] = r.error
        else:
            out[i].update(boundary_pressure_bar=r, boundary_tolerance_bar=tol_bar)
    return out


_BRACKET = {"controller", "speed_hz", "last_stable_bar", "first_unstable_bar", "params"}
_RESULTS = {"stable", "max_real_pole", "lowest_log_dec", "lowest_log_dec_hz", "log_dec_ok",
            "sensitivity_peak", "iso_zone", "unbalance_peak_um", "error"}


def _is_result(key: str) -> bool:
    # the loop as it runs (*_as_runs, max |z|) is a result too, not a parameter of the map
    return (key in _RESULTS or key.startswith("iso_zone_") or key.endswith("_as_runs")
            or key == "max_abs_pole_z")
