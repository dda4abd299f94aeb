"""Stability from standstill to the top speed: where the machine runs, not only where it is
judged.

A rotor on AMBs is levitated at standstill and run up through every speed to its top, so a
controller judged at the operating point alone can still lose the rotor on the way (the
gyroscopic splitting of the modes moves them against the controller's phase). ``ambseal
run`` therefore closes every controller on the full-order plant at each judged pressure and
each of the specification's stability speeds (:func:`ambseal.design.conditions.stability_speeds`:
standstill to the top speed) that is not already a judged condition, in the same loop as the
judgement (:func:`ambseal.machine.loop.judged_loop`): continuous with the target's hold and
computation delay, and the discrete controller as it runs on the plant sampled at its rate.
An unstable loop at any of those conditions fails the controller like one at a judged
condition (:func:`ambseal.analysis.delivery.loop_failure`); a stable one is graded by ISO
14839-3 as at a judged condition (σ̄(S_o) and each axis's peak,
:func:`ambseal.analysis.judge.sensitivity_grades`), continuous and as it runs, so that the
verdict's zone is the worst from standstill to the top speed and names where.
"""

from __future__ import annotations

from dataclasses import dataclass

from ambseal.analysis.judge import JudgeJob, JudgeSettings, OperatingPoint, sensitivity_grades
from ambseal.lti import json_float
from ambseal.machine import judged_loop
from ambseal.model import build_plant
from ambseal.robust import loop_delay

__all__ = ["SampledStability", "StabilityCase", "stability_points", "stability_case"]

#: The ISO 14839-3 grades a speed-range loop carries (:func:`ambseal.analysis.judge.
#: sensitivity_grades`), as a judged case names them.
GRADES = ("sensitivity_peak", "sensitivity_peak_per_axis", "iso_zone", "iso_zone_per_axis")


@dataclass(frozen=True)
class StabilityCase:
    """One controller's loop at one condition of the speed range: stability only.

    Attributes
    ----------
    controller : str
        The controller's name (its method).
    label : str
        The condition as reports name it (``"<p> bar, <f> Hz"``).
    pressure_bar, speed_hz : float
        The condition: seal pressure drop (bar) and spin speed (Hz).
    stable : bool
        The continuous loop with the target's delay is stable.
    max_real_pole : float or None
        Its rightmost pole's real part (1/s).
    discrete : SampledStability or None
        The loop of the discrete controller as it runs; None for a controller that cannot
        run on the target.
    sensitivity_peak, sensitivity_peak_per_axis, iso_zone, iso_zone_per_axis
        ISO 14839-3's grades of the continuous loop
        (:func:`ambseal.analysis.judge.sensitivity_grades`: σ̄(S_o)'s peak (-) and zone,
        each axis's peak and zone); None where not graded.
    """

    controller: str
    label: str
    pressure_bar: float
    speed_hz: float
    stable: bool
    max_real_pole: float | None
    discrete: SampledStability | None = None
    sensitivity_peak: float | None = None
    sensitivity_peak_per_axis: dict[str, float | None] | None = None
    iso_zone: str | None = None
    iso_zone_per_axis: dict[str, str] | None = None

    def to_dict(self) -> dict:
        """The ``metrics.json`` form."""
        return {"controller": self.controller, "label": self.label,
                "pressure_bar": self.pressure_bar, "speed_hz": self.speed_hz,
                "stable": self.stable, "max_real_pole": self.max_real_pole,
                **{k: getattr(self, k) for k in GRADES},
                "discrete": None if self.discrete is None else self.discrete.to_dict()}


@dataclass(frozen=True)
class SampledStability:
    """The stability of a discrete controller's loop as it runs (sampled plant, delay).

    Attributes
    ----------
    stable : bool
        Every pole inside the unit circle (:func:`ambseal.robust.is_stable`).
    max_abs_pole_z : float
        The largest pole modulus |z|.
    sample_rate_hz : float
        The controller's sample rate (Hz).
    sensitivity_peak, sensitivity_peak_per_axis, iso_zone, iso_zone_per_axis
        ISO 14839-3's grades of the loop as it runs (as :class:`StabilityCase`'s).
    """

    stable: bool
    max_abs_pole_z: float
    sample_rate_hz: float
    sensitivity_peak: float | None = None
    sensitivity_peak_per_axis: dict[str, float | None] | None = None
    iso_zone: str | None = None
    iso_zone_per_axis: dict[str, str] | None = None

    def to_dict(self) -> dict:
        """The ``metrics.json`` form."""
        return {"stable": self.stable, "max_abs_pole_z": self.max_abs_pole_z,
                "sample_rate_hz": self.sample_rate_hz,
                **{k: getattr(self, k) for k in GRADES}}


def stability_points(pressures_bar, speeds_hz, judged) -> list[OperatingPoint]:
    """The conditions of the speed range not already judged: every pressure (bar) at every
    speed (Hz), less the ``judged`` operating points.

    Parameters
    ----------
    pressures_bar : sequence of float
        Judged seal pressure drops (bar).
    speeds_hz : sequence of float
        Stability speeds (Hz), standstill to the top.
    judged : sequence of OperatingPoint
        The conditions the run judges in full.

    Returns
    -------
    list of OperatingPoint
        Speeds outermost, labelled ``"<p> bar, <f> Hz"``.
    """
    done = {(round(p.pressure_bar, 12), round(p.speed_rpm / 60.0, 9)) for p in judged}
    return [OperatingPoint(q, 60.0 * f, f"{q:g} bar, {f:g} Hz",
                           "low" if f < max(speeds_hz) else "high")
            for f in speeds_hz for q in pressures_bar
            if (round(q, 12), round(f, 9)) not in done]


def stability_case(case: JudgeJob, cfg, settings: JudgeSettings | None = None
                   ) -> tuple[StabilityCase, dict]:
    """Close one controller on the full-order plant at one condition, continuous with the
    target's delay and, when it runs there, discrete as it runs; stability only.

    Parameters
    ----------
    case : JudgeJob
        A job of :func:`ambseal.analysis.judge.judge_jobs`: the controller, its name and
        point, and the discrete controller that runs (or None).
    cfg : RigConfig
        The rig judged on.
    settings : JudgeSettings, optional
        The judgement's grid (:func:`ambseal.analysis.judge.judge_settings`): with it,
        each loop is graded by ISO 14839-3 too.

    Returns
    -------
    case : StabilityCase
    curves : dict
        ``poles`` (rad/s) of the continuous loop and ``discrete.poles`` (z) of the sampled
        one, for :func:`ambseal.analysis.delivery.loop_failure`.
    """
    point = case.point
    plant = build_plant(cfg, pressure_bar=point.pressure_bar, speed_rpm=point.speed_rpm)
    P, cur = plant.to_statespace(), plant.current_inputs()
    dl = loop_delay(cfg.controller.sample_rate_hz, cfg.controller.delay_samples)
    judged = judged_loop(P, case.controller, cur, delay=dl.system)
    loop = judged.loop

    def grades(j, K) -> dict:
        return {} if settings is None else sensitivity_grades(j, K, cur, settings.freq_hz)

    curves: dict = {"poles": loop.s_poles}
    disc, graded = None, grades(judged, case.controller)
    if case.discrete is case.controller:  # judged as it runs alone (judge_jobs): once
        disc = SampledStability(bool(loop.stable), float(loop.max_abs_pole), 1.0 / loop.dt,
                                **graded)
        curves["discrete"] = {"poles": loop.poles}
    elif case.discrete is not None:
        djudged = judged_loop(P, case.discrete, cur)
        dloop = djudged.loop
        disc = SampledStability(bool(dloop.stable), float(dloop.max_abs_pole), 1.0 / dloop.dt,
                                **grades(djudged, case.discrete))
        curves["discrete"] = {"poles": dloop.poles}
    return StabilityCase(case.name, point.label, float(point.pressure_bar),
                         float(point.speed_rpm) / 60.0, bool(loop.stable),
                         json_float(loop.max_real_pole), disc, **graded), curves
