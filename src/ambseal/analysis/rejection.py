"""The unbalance force rejection judged: its loops at every judged condition and what it
does to the synchronous response over the speed range
(:mod:`ambseal.design.synchronous_rejection`, Herzog et al., IEEE TCST 4(5), 1996).

- **Stability**: at each judged condition where the notch is on (its speed at or above
  the notch's ``on`` speed), the full-order plant closed by the controller with its notch
  at that speed, continuous (with the judgement's delay lag) and as it runs (the plant
  sampled by a zero-order hold, the discrete controller with its delay and notch)
  (:func:`ambseal.machine.judged_loop`); below it the controller runs alone, judged as
  such by :func:`ambseal.analysis.judge.judge`.
- **Effect**: the synchronous response (:func:`ambseal.analysis.synchronous.
  synchronous_response`) over the speed range with and without the notch, as the
  controller runs: each AMB axis's coil current and transmitted force, and the orbit at
  the sensors, the largest over the axes (positions) and two unbalance distributions over
  the judgement's force planes (the bearings by default) — in phase (static) and in
  alternating phase (couple) — of the ISO 21940-11 permissible residual unbalance
  U = m·G/Ω_max of the judged grade.
"""

from __future__ import annotations

import math

import numpy as np

from ambseal.analysis.synchronous import Unbalance, synchronous_response
from ambseal.machine import judged_loop
from ambseal.model import build_plant
from ambseal.robust import loop_delay

__all__ = ["rejection_stability", "rejection_effect", "EFFECT_SPEEDS"]

#: Speeds of the synchronous response over the speed range.
EFFECT_SPEEDS = 61


def rejection_stability(cfg, rejection, points) -> list[dict]:
    """The loops of a controller with its notch at the judged conditions (module
    docstring).

    Parameters
    ----------
    cfg : RigConfig
        The rig.
    rejection : SynchronousRejection
        The controller with its notch (:func:`ambseal.design.design_rejection`); its
        ``digital`` is judged as it runs where given.
    points : iterable of OperatingPoint
        The judged conditions.

    Returns
    -------
    list of dict
        Per condition where the notch is on: ``condition``, ``speed_hz``, ``pressure_bar``,
        ``stable`` and ``max_real_pole`` (1/s) of the continuous loop, and
        ``stable_as_runs`` and ``max_abs_pole_z`` of the sampled one (None without a
        digital controller).
    """
    fs, nd = cfg.controller.sample_rate_hz, cfg.controller.delay_samples
    lag = loop_delay(fs, nd).system
    out = []
    for pt in points:
        w = 2 * math.pi * pt.speed_rpm / 60.0
        if not rejection.controller.notch.is_on(w):
            continue
        plant = build_plant(cfg, pressure_bar=pt.pressure_bar, speed_rpm=pt.speed_rpm)
        P, cur = plant.to_statespace(), plant.current_inputs()
        cont = judged_loop(P, rejection.controller.at(w), cur, delay=lag).loop
        row = {"condition": pt.label, "speed_hz": pt.speed_rpm / 60.0,
               "pressure_bar": float(pt.pressure_bar), "stable": bool(cont.stable),
               "max_real_pole": float(cont.max_real_pole), "stable_as_runs": None,
               "max_abs_pole_z": None}
        if rejection.digital is not None:
            runs = judged_loop(P, rejection.digital.statespace_at(w, delayed=True), cur).loop
            row.update(stable_as_runs=bool(runs.stable),
                       max_abs_pole_z=float(np.abs(runs.poles).max()))
        out.append(row)
    return out


def rejection_effect(cfg, digital, rejection, settings, *, pressure_bar=None) -> dict:
    """The synchronous response with and without the notch over the speed range (module
    docstring).

    Parameters
    ----------
    cfg : RigConfig
        The rig.
    digital : DigitalController or ScheduledDigital
        The controller as it runs, alone.
    rejection : SynchronousRejection
        The same with its notch (its ``digital``).
    settings : JudgeSettings
        The judgement's unbalance: grade, mass, Ω_max and force planes.
    pressure_bar : float, optional
        The seals' pressure drop (default: the one the notch was made at).

    Returns
    -------
    dict
        ``speed_hz`` (shape (S,), the notch's table range), and per quantity
        ``current_a``, ``force_n``, ``orbit_um`` a dict ``{"without", "with"}`` of arrays of
        shape (S,): the largest coil current amplitude (A), transmitted force (N) and orbit
        semi-major axis at the sensors (µm) over the axes and the two distributions.
    """
    lo, hi = (float(f) for f in rejection.speeds_hz[[0, -1]])
    speeds = np.linspace(lo, hi, EFFECT_SPEEDS) if hi > lo else np.array([lo])
    s = settings
    U = s.unbalance_mass_kg * s.unbalance_grade_mm_s * 1e-3 / (
        2 * math.pi * s.unbalance_max_speed_hz)
    planes = tuple(s.force_positions_m)
    per = U / len(planes)
    cases = [[Unbalance(z, per) for z in planes],
             [Unbalance(z, per, 180.0 * (k % 2)) for k, z in enumerate(planes)]]
    sensors = sorted({a.sensor_position for a in cfg.amb})
    p = rejection.pressure_bar if pressure_bar is None else float(pressure_bar)
    out: dict = {"speed_hz": speeds, "current_a": {}, "force_n": {}, "orbit_um": {}}
    for key, K in (("without", digital), ("with", rejection.digital)):
        r = synchronous_response(cfg, K, speeds, cases, sensors, pressure_bar=p)
        out["current_a"][key] = r.current_a.max(axis=(0, 2))
        out["force_n"][key] = r.force_n.max(axis=(0, 2))
        out["orbit_um"][key] = 1e6 * r.amplitude_m.max(axis=(0, 2))
    return out
