"""The rotor drop over the scatter of what nobody knows to the last digit: Monte-Carlo
drops of one rig with the touchdown bearings' friction, their clearance within its
tolerance, their supports' damping and the rotor's unbalance drawn at random, and the
probability of what an engineer fears from a drop — a backward whirl, a failed verdict.

Each run is :func:`ambseal.analysis.drop.simulate_drop` of the rig with that run's draw,
validated as a rig file is (:func:`ambseal.config.parse_rig`; the ends of each range
are, before any run), on the nominal rig's modal basis (its ``modes_hz``, so that every
run keeps the same modes), judged by :func:`~ambseal.analysis.drop.drop_verdict`. The
draws are uniform, independent per bearing, and made before any run from
``numpy.random.default_rng(seed)`` in a fixed order (run, then friction, clearance,
support damping per bearing, then the unbalance): the same seed gives the same runs
serially or on Dask
(:func:`ambseal.analysis.cases.run_cases`), one BLAS thread per worker.

The probability p of an outcome seen in k of n runs is reported with its Wilson score
interval at 95 % (Wilson, J. Am. Stat. Assoc. 22, 1927; Agresti & Coull, Am. Stat. 52,
1998): (p̂ + z²/2n ± z √(p̂(1 − p̂)/n + z²/4n²)) / (1 + z²/n), z = 1.959964, which
keeps its coverage near 0 and 1 where the normal approximation's interval does not.
"""

from __future__ import annotations

import copy
import math

import numpy as np

from ambseal.analysis.cases import CaseError, run_cases
from ambseal.analysis.drop import drop_model, drop_verdict, simulate_drop
from ambseal.analysis.drop_levitated import levitated_state
from ambseal.analysis.drop_loop import amb_loop, drop_event, lost_at_rest
from ambseal.config import parse_rig
from ambseal.errors import ConfigError
from ambseal.lti import json_float

__all__ = ["MAX_DROP_RUNS", "drop_scatter", "drop_run", "wilson_interval"]

#: the most Monte-Carlo drops one call may ask for: each is seconds to a minute of CPU
MAX_DROP_RUNS = 10000
#: the standard normal quantile of a two-sided 95 % interval
Z95 = 1.959963984540054


def wilson_interval(k: int, n: int, z: float = Z95) -> tuple[float, float]:
    """The Wilson score interval (module docstring) of a proportion seen k times in n.

    Parameters
    ----------
    k, n : int
        Successes and trials, 0 ≤ k ≤ n, n ≥ 1.
    z : float
        The normal quantile (default: 95 %, two-sided).

    Returns
    -------
    (float, float)
        Lower and upper bound, within [0, 1].

    Raises
    ------
    ValueError
        k or n out of range.
    """
    if not (n >= 1 and 0 <= k <= n):
        raise ValueError(f"wilson_interval: expected 0 <= k <= n, n >= 1; got k={k}, n={n}")
    p = k / n
    centre = (p + z * z / (2 * n)) / (1 + z * z / n)
    half = z * math.sqrt(p * (1 - p) / n + z * z / (4 * n * n)) / (1 + z * z / n)
    return max(0.0, centre - half), min(1.0, centre + half)


def _range(name: str, value) -> tuple[float, float] | None:
    if value is None:
        return None
    lo, hi = (float(x) for x in value)
    if not (math.isfinite(lo) and math.isfinite(hi) and 0 <= lo <= hi):
        raise ConfigError(f"drop scatter: {name}: expected 0 <= low <= high, got {value!r}")
    return lo, hi


def _drawn(rig: dict, friction, clearance_m, support_damping) -> dict:
    """The rig (a ``RigConfig.model_dump()``) with each touchdown bearing's friction,
    radial clearance and support damping as drawn (lists in the rig's order), as a rig
    file's document: :func:`~ambseal.config.parse_rig` validates it by the file's rules."""
    doc = copy.deepcopy(rig)
    for td, mu, c, d in zip(doc["touchdown"], friction, clearance_m, support_damping):
        td.update({"friction": mu, "radial_clearance": c, "support_damping": d})
    return doc


def _check_ends(cfg, ranges: dict) -> None:
    """Refuse a range whose draws the rig file would refuse, before any run: the rig with
    every bearing at each end of each range (``{option text: (friction, clearance_m,
    support_damping) per end}``) is validated by its rules (the bounds are intervals, so
    a draw between two valid ends is valid; each run validates its own draw again)."""
    rig = cfg.model_dump()
    for option, ends in ranges.items():
        for end in ends:
            parse_rig(_drawn(rig, *end), option)


def drop_run(case: dict, rig: dict, speed_rpm: float, duration_s: float, modes_hz: float,
             coast_down: bool, drag_torque: float, start: str = "levitated",
             event: dict | None = None) -> dict:
    """One Monte-Carlo drop (module docstring): the rig with the case's friction,
    clearance and support damping per touchdown bearing, dropped with its unbalance by
    the event.

    Parameters
    ----------
    case : dict
        ``run``, and per bearing ``friction`` (μ), ``clearance_m`` (m) and
        ``support_damping`` (N·s/m), lists in the rig's order; ``unbalance_kgm`` (kg·m).
    rig : dict
        The rig (``RigConfig.model_dump()``).
    speed_rpm, duration_s, modes_hz, coast_down, drag_torque
        As :func:`~ambseal.analysis.drop.simulate_drop`.
    start : {"levitated", "rest"}
        With an unbalance, or an event that leaves the loop running, the drop starts from
        the reference PID loop's orbit
        (:func:`~ambseal.analysis.drop_levitated.levitated_state`) or at rest.
    event : dict, optional
        The keywords of :func:`~ambseal.analysis.drop_loop.drop_event` (``event``,
        ``axis``, ``overload_n``, ``overload_at``, ``surge_bar``); default every axis
        lost. The axes that run on run the reference PID.

    Returns
    -------
    dict
        The case, ``passed`` and ``failed`` (the verdict's failed criteria, "; "-joined),
        ``backward_whirl`` (any bearing), and per bearing NAME ``NAME_regime``,
        ``NAME_whirl_hz``, ``NAME_peak_force_n``, ``NAME_first_impact_peak_n``.
    """
    cfg = parse_rig(_drawn(rig, case["friction"], case["clearance_m"],
                           case["support_damping"]), f"drop scatter run {case['run']}")
    dm = drop_model(cfg, modes_hz)
    u = case["unbalance_kgm"]
    initial = x0 = None
    ev = event or {}
    idle = lost_at_rest(ev.get("event", "loss"), start, u)
    loop = amb_loop(cfg, dm, speed_rpm, "none" if idle else None)
    what = drop_event(cfg, dm, loop, **ev)
    # the orbit and the currents the coils carry at the drop, as ``ambseal drop`` starts
    if start == "levitated" and (u or what["failed"] != loop.names):
        eta, deta, x0 = levitated_state(cfg, dm, speed_rpm, u, loop=loop)
        initial = (dm.phi @ eta, dm.phi @ deta)
    res = simulate_drop(cfg, speed_rpm=speed_rpm, duration_s=duration_s, samples=2001,
                        model=dm, coast_down=coast_down, drag_torque=drag_torque,
                        unbalance_kgm=u, initial=initial, loop=loop, loop_state=x0,
                        failed=what["failed"], overload=what["overload"],
                        pressure_bar=what["pressure_bar"])
    judged = drop_verdict(cfg, res)
    row = {"run": case["run"], "passed": judged["passed"],
           "failed": "; ".join(c["name"] for c in judged["criteria"]
                               if c["outcome"] == "FAILED"),
           "unbalance_kgm": case["unbalance_kgm"]}
    whirl = False
    for p, td in enumerate(cfg.touchdown):
        regime, hz = res.regime(p)
        whirl |= regime == "backward whirl"
        row.update({f"{td.name}_friction": td.friction,
                    f"{td.name}_clearance_m": td.radial_clearance,
                    f"{td.name}_support_damping": td.support_damping,
                    f"{td.name}_regime": regime, f"{td.name}_whirl_hz": json_float(hz),
                    f"{td.name}_peak_force_n": json_float(float(res.peak_force[p])),
                    f"{td.name}_first_impact_peak_n": json_float(
                        float(res.first_peak_force[p]))})
    row["backward_whirl"] = whirl
    return row


def drop_scatter(cfg, runs: int, *, seed: int, friction=None, clearance_tol_m=None,
                 support_damping=None, unbalance_kgm=None, speed_rpm: float = 0.0,
                 duration_s: float = 0.5, modes_hz: float | None = None,
                 coast_down: bool = False, drag_torque: float = 0.0,
                 start: str = "levitated", event: dict | None = None,
                 workers: int | None = None, scheduler: str | None = None,
                 progress: bool = False) -> dict:
    """Monte-Carlo drops of a rig (module docstring).

    Parameters
    ----------
    cfg : RigConfig
        With ``[[amb]]`` and ``[[touchdown]]`` tables.
    runs : int
        Drops, 1 to :data:`MAX_DROP_RUNS`.
    seed : int
        The generator's seed (≥ 0).
    friction : (float, float), optional
        μ drawn in [low, high] per bearing; default each bearing's own.
    clearance_tol_m : float, optional
        Each bearing's radial clearance drawn within ± this (m) of its own.
    support_damping : (float, float), optional
        A factor in [low, high] on each flexible support's ``support_damping``.
    unbalance_kgm : (float, float), optional
        The static unbalance (kg·m) drawn in [low, high]; default none.
    speed_rpm : float, optional
        Spin speed (rpm), as :func:`~ambseal.analysis.drop.simulate_drop`.
    duration_s : float, optional
        Each drop's simulated time (s).
    modes_hz : float, optional
        The modal basis of every run; default the nominal rig's
        (:func:`~ambseal.analysis.drop.drop_model`).
    coast_down : bool, optional
        The drive lets go too (:func:`~ambseal.analysis.drop.simulate_drop`).
    drag_torque : float, optional
        The torque against the spin when it coasts (N·m).
    start : {"levitated", "rest"}, optional
        As :func:`drop_run`.
    event : dict, optional
        As :func:`drop_run`: the event of every run, checked on the nominal rig first.
    workers : int, optional
        Local Dask worker processes (:func:`ambseal.analysis.cases.run_cases`).
    scheduler : str, optional
        A running Dask scheduler's address.
    progress : bool, optional
        A progress bar over the drops on stderr.

    Returns
    -------
    dict
        ``runs`` (one row per drop, :func:`drop_run`, in draw order; a failed run has its
        ``error``), ``seed``, ``n`` (the runs that finished), and for ``backward_whirl``
        and ``failed`` their count, probability and its 95 % Wilson interval
        (``{"count", "probability", "interval"}``), and ``peak_force_n`` (the largest over
        the runs and bearings).

    Raises
    ------
    ConfigError
        Runs or a range out of bounds, a clearance tolerance as large as a clearance, a
        range whose ends the rig file's rules refuse (a friction beyond ``[[touchdown]]
        friction``'s bound, a clearance not below an air gap: named by its option), a
        rig the drop refuses (:func:`~ambseal.analysis.drop.drop_model`), or no run that
        finished.
    """
    if not (isinstance(runs, int) and 1 <= runs <= MAX_DROP_RUNS):
        raise ConfigError(f"drop scatter: runs: expected 1 to {MAX_DROP_RUNS}, got {runs!r}")
    if not (isinstance(seed, int) and seed >= 0):
        raise ConfigError(f"drop scatter: seed: expected an integer >= 0, got {seed!r}")
    mu, damp, unb = (_range(n, v) for n, v in (("friction", friction),
                                               ("support damping", support_damping),
                                               ("unbalance", unbalance_kgm)))
    base = drop_model(cfg, modes_hz)
    # a bad event is refused once, here, not in every run
    drop_event(cfg, base, amb_loop(cfg, base, speed_rpm, "none"), **(event or {}))
    c0 = np.array([t.radial_clearance for t in cfg.touchdown])
    tol = 0.0 if clearance_tol_m is None else float(clearance_tol_m)
    if not (math.isfinite(tol) and 0 <= tol < c0.min()):
        raise ConfigError(f"drop scatter: clearance tolerance: expected 0 <= tol < the "
                          f"smallest clearance {c0.min():g} m, got {clearance_tol_m!r}")
    nominal = [[t.friction for t in cfg.touchdown], c0.tolist(),
               [t.support_damping for t in cfg.touchdown]]
    ranges = {}
    if mu:
        ranges[f"--friction {mu[0]:g}:{mu[1]:g}"] = [
            [[x] * len(c0), *nominal[1:]] for x in mu]
    if tol:
        ranges[f"--clearance-tol-um {1e6 * tol:g}"] = [
            [nominal[0], (c0 + x).tolist(), nominal[2]] for x in (-tol, tol)]
    if damp:
        ranges[f"--support-damping {damp[0]:g}:{damp[1]:g}"] = [
            [*nominal[:2], [x * t.support_damping for t in cfg.touchdown]] for x in damp]
    _check_ends(cfg, ranges)
    rng = np.random.default_rng(seed)
    cases = []
    for run in range(runs):
        f, c, d = [], [], []
        for t, cn in zip(cfg.touchdown, c0):
            f.append(float(rng.uniform(*mu)) if mu else t.friction)
            c.append(float(cn + rng.uniform(-tol, tol)) if tol else float(cn))
            d.append(float(t.support_damping * rng.uniform(*damp)) if damp
                     else t.support_damping)
        cases.append({"run": run, "friction": f, "clearance_m": c, "support_damping": d,
                      "unbalance_kgm": float(rng.uniform(*unb)) if unb else 0.0})
    shared = {"rig": cfg.model_dump(), "speed_rpm": float(speed_rpm),
              "duration_s": float(duration_s), "modes_hz": base.modes_hz,
              "coast_down": bool(coast_down), "drag_torque": float(drag_torque),
              "start": start, "event": dict(event or {})}
    out = run_cases(drop_run, cases, shared=shared, workers=workers, scheduler=scheduler,
                    progress=progress, description="drops")
    rows = [{"run": r.case["run"], "error": r.error} if isinstance(r, CaseError) else r
            for r in out]
    done = [r for r in rows if "error" not in r]
    if not done:
        raise ConfigError(f"drop scatter: no drop finished (the first: {rows[0]['error']})")

    def share(key: str, pick) -> dict:
        k = sum(1 for r in done if pick(r[key]))
        return {"count": k, "probability": k / len(done),
                "interval": list(wilson_interval(k, len(done)))}

    peaks = [r[k] for r in done for k in r if k.endswith("_peak_force_n")]
    return {"seed": seed, "n": len(done), "runs": rows,
            "backward_whirl": share("backward_whirl", bool),
            "failed": share("passed", lambda ok: not ok),
            "peak_force_n": json_float(max(peaks))}
