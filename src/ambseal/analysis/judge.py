"""Judge one controller on the full-order plant at one operating point: the main job's case.

What ``ambseal run`` reports per (controller, operating point), thesis P5 §4–5:
closed-loop stability, σ̄(S_o) with the ISO 14839-3 zones (overall and per axis),
compliance at the bearings, the worst-case unbalance response and the current-impulse response.
Every number is taken on the full-order plant (flexible modes included), whatever model
the controller was designed on; peaks on frequency grids refined around the lightly damped
closed-loop poles (:func:`ambseal.analysis.loops.resolved_grid`).

**The controller's delay is part of the loop.** A digital controller acts through its
zero-order hold and ``[controller] delay_samples`` of computation: about
τ = (delay_samples + ½)/sample_rate_hz of pure delay (:mod:`ambseal.robust.delay`). The
continuous loop is judged with that delay as a Padé lag in every current input of the plant
(:func:`ambseal.robust.delay.loop_delay`: the lowest order within 5° of phase up to
Nyquist; test rig 150 µs, order 4), so that its numbers are those of the controller as it
will act; the case records it as ``delay`` (``delay_s``, ``pade_order``,
``phase_error_deg``, ``band_top_hz``). On the test rig the PID's continuous σ̄(S_o) peaks
then equal the sampled loop's to 0.1 % (13.36 against 13.37 at 2.04 bar, 7.43 against 7.43
at 0 bar; without the delay they were 9.36 and 4.94). The closed-loop modes of
:mod:`ambseal.analysis.campbell` (``modes``, ``campbell``) are this loop's too, their log
decrements and stability verdict alike (:func:`ambseal.machine.loop.judged_loop`).

**What runs is judged too**: given the discrete controller of the target (with its
computation delay, :class:`ambseal.robust.digital.DigitalController`), the same numbers are
taken on the loop of that controller with the full-order plant sampled exactly (zero-order
hold, the DAC) at its sample time — stability by ``|z| < 1``, σ̄(S_o) on a grid up to
Nyquist, compliance and unbalance for a force held over each sample, the impulse response
stepped at the sample time — and reported as the case's ``discrete`` block, with the same
keys plus ``max_abs_pole_z`` and ``sample_rate_hz``.

The operating points (:func:`operating_points`) and the grids and disturbances
(:func:`judge_settings`) are those of the rig's design specification
(:func:`ambseal.design.specs.design_spec`): by default 0, nominal and 2× nominal pressure
drop for pressure-driven seals, or the ends and the middle of the speed range for rigs whose
seals change with speed over a stated range (P3 §4); the band, the unbalance and the
impulse are derived from the machine by the rules written there.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, fields, replace
from typing import Any

import control
import numpy as np
from scipy.signal import find_peaks

from ambseal.analysis.campbell import AF_CRITICAL
from ambseal.analysis.iso import iso_assessment
from ambseal.analysis.loops import (
    compliance_from,
    loop_responses_from,
    resolved_grid,
    resolved_peaks,
    response_points,
    sigma_max,
)
from ambseal.analysis.response import impulse_response_of
from ambseal.analysis.spinup import frozen_sensitivity, spinup
from ambseal.analysis.amplifier import unbalance_currents
from ambseal.analysis.synchronous import hold_fundamental, running_plant
from ambseal.analysis.unbalance import (UnbalanceResponse, running_unbalance,
                                        unbalance_from_compliance)
from ambseal.analysis.signoff.unbalance_api617 import amplification_factor, required_margin
from ambseal.analysis.tolerance import ABOVE, SEPARATION_RTOL, side_of
from ambseal.design import RIGID_STATES, vertex_grid_hz
from ambseal.design.lpv_plant import lpv_plant
from ambseal.lti import eigenvalues, finite_or_none, freqresp_at, json_float, wired
from ambseal.machine import (
    SPEED,
    JudgedLoop,
    ScheduledController,
    controller_as_runs,
    frozen,
    judged_loop,
)
from ambseal.model import (build_plant, classify_poles, coefficient_value, pressure_for_k,
                           seal_values)
from ambseal.robust import loop_delay

__all__ = ["JudgeSettings", "OperatingPoint", "LoopJudgement", "JudgedCase", "JudgeJob", "judge", "judge_case", "judge_spinup",
           "operating_points", "speed_scheduled",
           "judge_settings", "unstable_open_loop_poles", "condition_values", "frozen_at",
           "frozen_discrete", "judge_jobs", "points_for", "sensitivity_grades",
           "critical_speeds", "resonance_tops", "unbalance_speeds_hz"]

#: Where a loop's static response is taken (rad/s): far below any AMB loop's dynamics (the
#: plant there equals its static response to ~1e-8), and not zero, where an integrating
#: controller's gain is infinite — the loop's response is finite and exact to that order.
STATIC_RAD_S = 1e-4


@dataclass(frozen=True)
class JudgeSettings:
    """Grids and disturbances of the judgement (:func:`judge_settings` derives them).

    Attributes
    ----------
    freq_hz : (float, float, int)
        Log grid of the loop analysis (Hz): start, end, points; refined around every lightly
        damped closed-loop pole.
    unbalance_grade_mm_s : float
        Balance grade G (mm/s) of the worst-case unbalance, thesis P5 §4.4.1.
    unbalance_range_hz : (float, float)
        Speed range (Hz) of the unbalance response (400 points, refined).
    unbalance_mass_kg : float
        Mass m (kg) of the force law.
    unbalance_law : str
        ``"iso21940"`` (F_u = m·G·Ω²/Ω_max) or ``"constant_velocity"`` (m·G·Ω),
        :func:`ambseal.analysis.unbalance.unbalance_force`.
    unbalance_max_speed_hz : float
        Ω_max/2π (Hz) of the ISO law.
    force_positions_m : tuple of float
        Where compliance and unbalance forces act (m): the bearings by default.
    impulse_a, impulse_s : float
        The current impulse (P5 §5.1): amplitude (A) and length (s), started at
        ``impulse_start_s`` in a window of ``impulse_end_s`` sampled every ``impulse_dt_s``.
        No amplitude (None): no impulse response.
    impulse_start_s, impulse_end_s, impulse_dt_s : float
        Start of the impulse, end of the simulated window and sample time of the response
        (s).
    unbalance_plant : {"running", "frozen"}
        The unbalance response's plant (:mod:`ambseal.analysis.unbalance`): at each speed
        the one built at that speed (with the controller as it acts there), or frozen at
        the judged condition (the thesis's simplification).
    """

    freq_hz: tuple[float, float, int]
    unbalance_grade_mm_s: float
    unbalance_range_hz: tuple[float, float]
    unbalance_mass_kg: float
    unbalance_law: str
    unbalance_max_speed_hz: float
    force_positions_m: tuple
    impulse_a: float | None
    impulse_s: float
    impulse_start_s: float
    impulse_end_s: float
    impulse_dt_s: float
    unbalance_plant: str = "running"

    def unbalance_dict(self) -> dict:
        """The unbalance settings as ``metrics.json`` states them (grade, law, Ω_max/2π, speeds)."""
        return {"grade_mm_s": self.unbalance_grade_mm_s, "law": self.unbalance_law,
                "max_speed_hz": self.unbalance_max_speed_hz,
                "range_hz": list(self.unbalance_range_hz), "plant": self.unbalance_plant}


#: points of the judgement's log grid (before the refinement around lightly damped poles)
GRID_POINTS = 1200


#: A number in ``metrics.json``: finite, or ``"inf"``/``"-inf"`` (:mod:`ambseal.lti.json_safe`).
JsonFloat = float | str


@dataclass(frozen=True)
class LoopJudgement:
    """The numbers of one judged loop, continuous or discrete (thesis P5 §4–5).

    Attributes
    ----------
    stable : bool
        The loop's verdict (:func:`ambseal.robust.stability.is_stable`).
    max_real_pole : float
        Decay rate of its slowest pole (1/s; ``ln max|z| / dt`` for a discrete loop).
    sensitivity_peak : float or None
        Peak of σ̄(S_o) (-); None for an unstable loop.
    sensitivity_peak_per_axis : dict of str to float or None
        Peak of each diagonal element of S_o, by AMB axis (ISO 14839-3 grades these).
    iso_zone : str
        ISO 14839-3 zone of σ̄(S_o): ``"A"``–``"D"``, or ``"A/B"``, ``"B/C"``, ``"C/D"`` for
        a peak on the boundary of two zones (within 0.1 % of their limit,
        :func:`ambseal.analysis.iso.graded_zone`).
    iso_zone_per_axis : dict of str to str
        Each axis's zone from its |S_o| peak, graded the same way.
    compliance_peak_m_per_n : float or None
        Peak of σ̄ of the compliance at the unbalance force positions (m/N).
    unbalance_peak_um : float or None
        Worst-case unbalance response (µm) over the unbalance band (ISO 21940-11 grade).
    impulse_peak_um, impulse_settling_s : float or None
        The current-impulse response's peak displacement (µm) and settling time (s).
    max_abs_pole_z, sample_rate_hz : float or None
        Of a discrete loop only: its largest ``|z|`` and sample rate (Hz).
    critical_speeds : list of dict or None
        The loop's critical speeds (1× crossings of the unbalance orbit at the running
        speed with AF ≥ 2.5) inside the continuous speed range or within the separation
        margin API 617 (8th ed., §2.6.2.10; API 684 §2.8) requires of them, or on its
        boundary (:func:`critical_speeds`): ``speed_hz``, ``af``, ``margin_pct`` (the
        separation from the continuous range, % of its nearer end; 0 inside it) and
        ``required_pct``; None where not judged (the frozen plant, an
        unstable loop, a rig without a running speed).
    impulse_settling_note : str or None
        Why a judged impulse response has no settling time, in words
        (:attr:`ambseal.analysis.response.ImpulseResponse.settling_note`: not settled
        within the simulated window, with the window and the loop's slowest pole); None
        where it settled or no impulse was judged.
    """

    stable: bool
    max_real_pole: JsonFloat
    sensitivity_peak: float | None
    sensitivity_peak_per_axis: dict[str, float | None]
    iso_zone: str
    iso_zone_per_axis: dict[str, str]
    compliance_peak_m_per_n: float | None
    unbalance_peak_um: float | None
    impulse_peak_um: float | None
    impulse_settling_s: float | None
    max_abs_pole_z: float | None = None
    sample_rate_hz: float | None = None
    critical_speeds: list[dict[str, JsonFloat]] | None = None
    impulse_settling_note: str | None = None

    def to_dict(self) -> dict:
        """The ``metrics.json`` form (a discrete loop's two extra keys only when set)."""
        d = {f.name: getattr(self, f.name) for f in fields(self)}
        d["max_real_pole"] = json_float(self.max_real_pole)
        if self.sample_rate_hz is None:
            del d["max_abs_pole_z"], d["sample_rate_hz"]
        return d


@dataclass(frozen=True)
class JudgedCase(LoopJudgement):
    """One controller judged at one operating point: the main job's case.

    The continuous loop's numbers (:class:`LoopJudgement`, the controller with its delay
    lag), the condition, the delay model and, when the discrete controller that runs was
    judged too, its loop's numbers (``discrete``).

    Attributes
    ----------
    controller : str
    pressure_bar, speed_hz : float
        The condition (bar, Hz).
    label : str
        The condition as reports name it (:attr:`OperatingPoint.label`).
    delay : dict
        The delay lag judged with (:meth:`ambseal.robust.delay.DesignDelay.to_dict`).
    discrete : LoopJudgement or None
    """

    controller: str = ""
    pressure_bar: float = 0.0
    speed_hz: float = 0.0
    label: str = ""
    delay: dict | None = None
    discrete: LoopJudgement | None = None

    def to_dict(self) -> dict:
        """The ``metrics.json`` case."""
        d = {"controller": self.controller, "pressure_bar": self.pressure_bar,
             "speed_hz": self.speed_hz, "label": self.label, **LoopJudgement.to_dict(self),
             "delay": self.delay}
        if self.discrete is not None:
            d["discrete"] = self.discrete.to_dict()
        return d


def judge_settings(spec, cfg=None) -> JudgeSettings:
    """The judgement's grids and disturbances from the rig's design specification.

    The band, unbalance and impulse of :func:`ambseal.design.specs.design_spec`; the
    impulse starts after 5 impulse lengths and the window ends 30 lengths later, sampled at
    twice the controller's rate (test rig: 0.05 A for 10 ms at 0.05 s in 0.35 s, every
    50 µs, P5 §5.1).

    Parameters
    ----------
    spec : DesignSpec
        The rig's design specification (:func:`~ambseal.design.specs.design_spec`, built
        once per rig by the caller); its machine's sample rate sets the impulse response's
        sampling.
    cfg : RigConfig, optional
        The rig: with it ``unbalance_range_hz`` are the speeds :func:`judge` takes the
        worst orbit over (:func:`unbalance_speeds_hz`), as ``metrics.json`` states them;
        without it the unbalance band (:func:`judge` widens it the same way).

    Returns
    -------
    JudgeSettings
        The log frequency grid (1200 points over the band), the unbalance and the impulse.
    """

    sp = spec
    t = sp.impulse_s
    return JudgeSettings(
        freq_hz=(sp.band_hz[0], sp.band_hz[1], GRID_POINTS),
        unbalance_grade_mm_s=sp.unbalance_grade_mm_s,
        unbalance_range_hz=(sp.unbalance_range_hz if cfg is None
                            else unbalance_speeds_hz(cfg, sp.unbalance_range_hz)),
        unbalance_mass_kg=sp.unbalance_mass_kg, unbalance_law=sp.unbalance_law,
        unbalance_max_speed_hz=sp.unbalance_max_speed_hz, force_positions_m=sp.force_positions_m,
        impulse_a=sp.impulse_a, impulse_s=t, impulse_start_s=5 * t, impulse_end_s=35 * t,
        impulse_dt_s=0.5 / sp.machine.sample_rate_hz, unbalance_plant=sp.unbalance_plant)


@dataclass(frozen=True)
class OperatingPoint:
    """A judged condition of the rig.

    Attributes
    ----------
    pressure_bar : float
        Pressure drop across the seals (bar).
    speed_rpm : float
        Spin speed (rpm).
    label : str
        How reports name it, e.g. ``"2.04 bar"`` or ``"140 Hz"``.
    condition : str
        ``"nominal"`` (the rig's operating point), or ``"low"`` / ``"high"`` below or above
        it (in speed when the speed varies, else in pressure drop).
    """

    pressure_bar: float
    speed_rpm: float
    label: str
    condition: str = "nominal"


def speed_scheduled(cfg) -> bool:
    """Whether the rig's seals change with speed over a stated speed range (P3 §4): its
    controllers are then judged at frozen speeds rather than at pressure drops.

    Parameters
    ----------
    cfg : RigConfig
        The rig (its ``[operating] speed_range_hz`` and seals).

    Returns
    -------
    bool
    """
    return cfg.operating.speed_range_hz is not None and any(
        s.frequency_dependent for s in cfg.seal)


def operating_points(spec) -> list[OperatingPoint]:
    """Where every controller is judged: the design specification's pressures × speeds
    (:func:`ambseal.design.specs.design_spec`; by default 0, nominal and 2× nominal
    pressure drop, P5 §4, or the ends and the middle of the speed range of a rig whose
    seals change with speed, P3 §4, at the nominal pressure).

    Parameters
    ----------
    spec : DesignSpec
        The rig's design specification (:func:`~ambseal.design.specs.design_spec`, built
        once per rig by the caller); its nominal pressure and speed (the rig's
        ``[operating]`` point) name each condition low, nominal or high.

    Returns
    -------
    list of OperatingPoint
        Every pressure at each speed, speeds outermost.
    """

    sp = spec
    ps, fs = sp.pressures_bar, sp.speeds_hz

    def label(q, f):
        return ", ".join(([f"{q:g} bar"] if len(ps) > 1 or len(fs) == 1 else [])
                         + ([f"{f:g} Hz"] if len(fs) > 1 else []))

    p0, f0 = sp.nominal_pressure_bar, sp.nominal_speed_hz

    def side(q, f):  # against the nominal of what varies (speed when it does)
        x, x0 = (f, f0) if len(fs) > 1 else (q, p0)
        return "nominal" if x == x0 else ("low" if x < x0 else "high")

    return [OperatingPoint(q, f * 60.0, label(q, f), side(q, f)) for f in fs for q in ps]


def points_for(controller, points, design_cfg) -> list[OperatingPoint]:
    """Where ``controller`` is judged: ``points`` (:func:`operating_points`), and for a
    controller scheduled on a seal's k affine in the pressure drop also the pressure drops
    that give the ends of its schedule on the design rig
    (:func:`ambseal.model.seal.pressure_for_k`) that lie outside the judged pressures, so
    that it is judged over the whole range it was designed for and not only at the
    specification's pressures (the tracked controller, k over 0–3× nominal: 0, 1×, 2× and
    3× nominal pressure on the test rig).

    Parameters
    ----------
    controller : control.StateSpace or ScheduledController
        The physical controller (``i = −K y``), fixed or scheduled.
    points : list of OperatingPoint
        The rig's judged conditions, one of them ``"nominal"``.
    design_cfg : RigConfig
        The rig the controller was designed on (its seals map k to a pressure drop).

    Returns
    -------
    list of OperatingPoint
        ``points`` for a fixed or speed-scheduled controller; else every pressure of
        ``points`` and the schedule's ends at each speed, pressures ascending, labelled and
        named low/nominal/high as :func:`operating_points` does.
    """

    if not isinstance(controller, ScheduledController) or controller.parameter == SPEED:
        return list(points)
    ends = [pressure_for_k(design_cfg.seal, controller.parameter, th)
            for th in controller.schedule]
    pressures = sorted({p.pressure_bar for p in points})
    lo, hi = pressures[0], pressures[-1]
    # an end inside the judged pressures adds nothing to the range judged (on an identified
    # rig k is not exactly 0 at 0 bar: its k = 0 end sits a hair above 0 bar)
    for q in ends:  # 12 digits: 3 × 2.04 bar is 6.12 bar, not 6.120000000000001
        if q is not None and q >= 0.0 and (q > hi or q < lo) and not any(
                math.isclose(q, x, abs_tol=1e-9) for x in pressures):
            pressures.append(float(f"{q:.12g}"))
    if len(pressures) == len({p.pressure_bar for p in points}):
        return list(points)
    speeds = list(dict.fromkeys(p.speed_rpm for p in points))
    nominal = next((p for p in points if p.condition == "nominal"), points[0])
    by_speed = len(speeds) > 1

    def point(q, rpm):
        label = f"{q:.4g} bar" + (f", {rpm / 60.0:g} Hz" if by_speed else "")
        x, x0 = (rpm, nominal.speed_rpm) if by_speed else (q, nominal.pressure_bar)
        side = "nominal" if x == x0 else ("low" if x < x0 else "high")
        return OperatingPoint(q, rpm, label, side)

    return [point(q, rpm) for rpm in speeds for q in sorted(pressures)]


def unstable_open_loop_poles(A: np.ndarray, C: np.ndarray | None = None) -> np.ndarray:
    """Eigenvalues of ``A`` with a positive real part, most unstable first (rad/s).

    Unstable and refused as doubtful by :func:`ambseal.model.modes.classify_poles`
    (absolute thresholds in rad/s, not relative to the stiffest mode).

    Parameters
    ----------
    A : numpy.ndarray, shape (n, n)
        An open-loop plant's state matrix.
    C : numpy.ndarray, shape (p, n), optional
        Its output matrix: a large plant's eigendecomposition is then kept for its
        responses and loops (:func:`ambseal.lti.eigenvalues`).

    Returns
    -------
    numpy.ndarray of complex
        The unstable eigenvalues (rad/s); empty for a stable plant.

    Raises
    ------
    ModelError
        The model's conditioning makes the stability doubtful.
    """

    lam = eigenvalues(A, C)
    lam = lam[classify_poles(lam, where="open-loop plant")[1]]
    return lam[np.argsort(-lam.real)]


def judge(cfg, controller, name: str, point: OperatingPoint,
          settings: JudgeSettings, *, impulse: bool = True,
          discrete=None, schedule=None, schedule_discrete=None) -> tuple[JudgedCase, dict]:
    """Judge one physical controller on the full-order plant at one operating point.

    Parameters
    ----------
    cfg : RigConfig
    controller : control.StateSpace
        Displacement (m) → current reference (A), negative feedback ``i = −K y``; or
        ``discrete`` itself, for a controller judged as it runs alone (:func:`judge_jobs`).
    name : str
        The controller's name in the case.
    point : OperatingPoint
    settings : JudgeSettings
        The judgement's grids and disturbances (:func:`judge_settings` of the rig's design
        specification).
    impulse : bool
        Set False to leave out the impulse response (the sweeps of
        :mod:`ambseal.analysis.sweep`); ``impulse_*`` are then ``None``.
    discrete : control.StateSpace, optional
        The controller that runs on the target, discrete (``dt`` its sample time) with its
        computation delay included
        (:meth:`ambseal.robust.digital.DigitalController.statespace` ``(delayed=True)``):
        judged the same way on the plant sampled at ``dt`` (module docstring).
    schedule, schedule_discrete : ScheduledController, ScheduledDigital, optional
        A controller scheduled on speed, continuous and as it runs, of which ``controller``
        and ``discrete`` are the frozen ones at ``point``: the unbalance response at the
        running speed (``settings.unbalance_plant``) takes it at each speed.

    Returns
    -------
    case : JudgedCase
        The case (values an unstable loop does not have are ``None``); with ``discrete``,
        its loop's numbers in ``case.discrete`` (plus ``max_abs_pole_z`` and
        ``sample_rate_hz``). ``case.to_dict()`` is the ``metrics.json`` form.
    curves : dict
        ``So``, ``compliance``, ``unbalance`` (frequency Hz, values),
        ``unbalance_current`` (speeds Hz, the current references per axis in A,
        :func:`~ambseal.analysis.amplifier.unbalance_currents`, the axes' names) and ``impulse``
        (:class:`~ambseal.analysis.response.ImpulseResponse`) for the figures, and
        ``poles`` (the closed-loop poles, rad/s); the discrete loop's under
        ``curves["discrete"]`` (its ``poles`` are z).
    """

    # the worst orbit over every speed the machine passes, not the band alone
    s = replace(settings, unbalance_range_hz=unbalance_speeds_hz(
        cfg, settings.unbalance_range_hz))
    # the seals the rotor is offset in carry a static load: a force input at each, after
    # the judgement's own
    offset = [sl for sl in cfg.seal if sl.static_eccentricity > 0]
    plant = build_plant(cfg, pressure_bar=point.pressure_bar, speed_rpm=point.speed_rpm,
                        force_positions=tuple(s.force_positions_m)
                        + tuple(sl.position for sl in offset))
    cur = plant.current_inputs()
    rest = [j for j in range(len(plant.input_names)) if j not in cur]
    force = rest[:2 * len(s.force_positions_m)]
    static = (rest[len(force):], [seal_static_load(sl, point.pressure_bar) for sl in offset])
    P = plant.to_statespace()
    dl = loop_delay(cfg.controller.sample_rate_hz, cfg.controller.delay_samples)

    def running(sched):
        """The unbalance response with the plant at each speed, for one loop: the controller
        as the loop has it (wired, continuous or discrete) or scheduled on speed."""
        if s.unbalance_plant != "running":
            return None
        positions = tuple(s.force_positions_m)

        def plant_at(speeds):
            return running_plant(cfg, speeds, positions, pressure_bar=point.pressure_bar)

        lo, hi = s.unbalance_range_hz
        f_min, f_max = cfg.operating.continuous_hz
        # the sweep reaches past the continuous range by the largest separation margins API
        # 617 can require, so that a critical just outside it is seen
        top = max(hi, (1 + MAX_MARGIN_ABOVE) * f_max)
        bottom = min(lo, (1 - MAX_MARGIN_BELOW) * f_min) if f_min > 0 else lo

        def judged(G, K):
            unb, current, axes = running_unbalance(
                plant_at, _controller_at_speed(G, K, sched, dl.system), (bottom, top),
                mass_kg=s.unbalance_mass_kg, grade_mm_s=s.unbalance_grade_mm_s,
                law=s.unbalance_law, max_speed_rad_s=2 * math.pi * s.unbalance_max_speed_hz)
            crit = critical_speeds(unb, f_min, f_max) if f_max > 0 else None
            keep = (unb.speed_hz >= lo * (1 - 1e-12)) & (unb.speed_hz <= hi * (1 + 1e-12))
            return _within(unb, keep), current[keep], axes, crit
        return judged

    body, curves = _judge_loop(judged_loop(P, controller, cur, delay=dl.system), cur, force,
                               controller, s, impulse, static,
                               running(schedule_discrete if discrete is controller
                                       else schedule))
    disc = None
    if discrete is controller:  # judged as it runs alone (:func:`judge_jobs`): once
        disc, curves["discrete"] = body, dict(curves)  # its poles z, as a discrete block's
        with np.errstate(divide="ignore"):  # the case's own as rates, ln z / dt (rad/s)
            curves["poles"] = np.log(np.asarray(curves["poles"], complex)) / discrete.dt
    elif discrete is not None:
        disc, curves["discrete"] = _judge_loop(judged_loop(P, discrete, cur), cur, force,
                                               discrete, s, impulse, static,
                                               running(schedule_discrete))
    case = JudgedCase(**vars(body), controller=name, pressure_bar=point.pressure_bar,
                      speed_hz=point.speed_rpm / 60.0, label=point.label, delay=dl.to_dict(),
                      discrete=disc)
    return case, curves


def unbalance_speeds_hz(cfg, band_hz) -> tuple[float, float]:
    """The speeds (Hz) over which the worst-case unbalance orbit is judged: the unbalance
    band (``[design.unbalance] range_hz``, or its rule), widened on a machine that runs to
    every speed it passes, from standstill to its trip speed (``[operating]
    trip_speed_hz``, :attr:`~ambseal.config.Operating.trip_hz`) — the speeds over which API
    617 holds the response at the close clearances (8th ed., Part 1 §4.8.2.11; as
    :mod:`ambseal.analysis.signoff.unbalance_api617` takes them), and the orbit is set
    against the air gap and the backup clearance. The rotor passes a critical speed below
    its minimum continuous speed on every run-up. Standstill is taken as 1 % of the
    maximum continuous speed: the plant at the running speed needs one, and the unbalance
    force there is 1e-4 of its top (ISO 21940-11 law; 1e-2 at a constant velocity).

    Parameters
    ----------
    cfg : RigConfig
        The rig: its ``[operating]`` speeds.
    band_hz : (float, float)
        The unbalance band (Hz), ``0 < low < high``.

    Returns
    -------
    (float, float)
        ``(low, high)`` (Hz): the band, and on a rig with a running speed at most 1 % of the
        maximum continuous speed to at least the trip speed. Applied twice, the same.
    """
    lo, hi = (float(x) for x in band_hz)
    f_max = cfg.operating.continuous_hz[1]
    if not f_max > 0:  # a rig at standstill: its band as set or derived
        return lo, hi
    return min(lo, f_max / 100.0), max(hi, float(cfg.operating.trip_hz))


#: API 617's largest separation margin above the maximum continuous speed (26 %) and below
#: the minimum (16 %), as fractions
#: (:func:`ambseal.analysis.signoff.unbalance_api617.required_margin`)
MAX_MARGIN_ABOVE, MAX_MARGIN_BELOW = 0.26, 0.16


def critical_speeds(unb: UnbalanceResponse, f_min: float, f_max: float) -> list[dict]:
    """The critical speeds of an unbalance response at the running speed that lie inside
    the continuous speed range or within the separation margin API 617 requires of them, or
    on its boundary: a margin within :data:`ambseal.analysis.tolerance.SEPARATION_RTOL` of
    the requirement is not known to meet it or not (:func:`ambseal.analysis.tolerance.
    side_of`), and is listed for the words to say so.

    The running sweep reaches 16 % below the minimum and 26 % above the maximum continuous
    speed for it. A critical speed is a local maximum of the orbit over speed (a closed-loop mode's 1×
    crossing) with a half-power amplification factor AF ≥ 2.5 (API 684 §2.8; where the
    sweep ends before the orbit falls to half power on one side, the other side's
    half-width is taken for both; a peak that falls to half power on neither side within
    the sweep is no resonance — a ripple of a broad response — and is left out; maxima
    with no half-power dip between them are one resonance, one critical speed,
    :func:`resonance_tops`); its separation margin from the continuous range
    [f_min, f_max] is
    ``100 (f_min − N)/f_min`` below it and ``100 (N − f_max)/f_max`` above it, and API 617
    (8th ed., §2.6.2.10) requires ``min(16, 17(1 − 1/(AF − 1.5)))`` % below and
    ``min(26, 10 + 17(1 − 1/(AF − 1.5)))`` % above
    (:func:`ambseal.analysis.signoff.unbalance_api617.required_margin`).

    Parameters
    ----------
    unb : UnbalanceResponse
        The orbit over speed (:func:`ambseal.analysis.unbalance.running_unbalance`).
    f_min, f_max : float
        The continuous speed range (Hz).

    Returns
    -------
    list of dict
        ``speed_hz``, ``af``, ``margin_pct`` (0 inside the range) and ``required_pct`` of
        each, by speed.
    """
    f, a = unb.speed_hz, unb.response_m
    out = []
    for i in resonance_tops(a):
        af, n1, n2 = amplification_factor(f, a, int(i))
        n = float(f[i])
        if np.isnan(af):  # one side (or none) within the sweep
            if not np.isfinite([n1, n2]).any():
                continue
            af = n / (2 * np.nanmax([n - n1, n2 - n]))
        if af < AF_CRITICAL:
            continue
        below = n < f_min
        margin = (100 * (f_min - n) / f_min if below else
                  100 * (n - f_max) / f_max if n > f_max else 0.0)
        need = required_margin(af, below)
        if side_of(margin, need, SEPARATION_RTOL) != ABOVE:
            out.append({"speed_hz": n, "af": json_float(af), "margin_pct": margin,
                        "required_pct": need})
    return out


def resonance_tops(amp) -> np.ndarray:
    """The local maxima of a response over speed that each top a resonance of their own.

    A local maximum from which a higher one (or an equal one at a lower speed) is reached
    without the response falling to half power, ``amp[i]/√2``, lies on that one's flank or
    flat top: the same resonance, whose half-power band (API 684 §2.8) holds both, and it
    is left out: else a flat top on which rounding leaves a second maximum beside the
    first is one critical speed or two as the BLAS's kernels and threads round
    (benchmarks/README.md). The sign-off's criticals ask for the same half-power dip, on
    both sides, as a prominence (:mod:`ambseal.analysis.signoff.unbalance_api617`).

    Parameters
    ----------
    amp : array_like, shape (n,)
        The response at ascending speeds.

    Returns
    -------
    ndarray of int
        The kept maxima's indices, ascending.
    """
    a = np.asarray(amp, float)
    idx = find_peaks(a)[0]
    keep = []
    for i in idx:
        half = a[i] / math.sqrt(2.0)
        top = True
        for j in idx:
            if a[j] > a[i] or (a[j] == a[i] and j < i):
                lo, hi = sorted((int(i), int(j)))
                if a[lo:hi + 1].min() > half:  # no half-power dip between them
                    top = False
                    break
        if top:
            keep.append(int(i))
    return np.asarray(keep, dtype=int)


def _within(unb: UnbalanceResponse, keep: np.ndarray) -> UnbalanceResponse:
    """``unb`` on the speeds ``keep`` selects, its peak taken there."""
    w, resp = unb.omega_rad_s[keep], unb.response_m[keep]
    k = int(np.argmax(resp))
    return UnbalanceResponse(w, unb.force_n[keep], resp, float(resp[k] * 1e6),
                             float(w[k] / (2 * math.pi)), unb.mass_kg, unb.grade_mm_s,
                             unb.law, unb.max_speed_rad_s)


def _controller_at_speed(G, K, schedule, delay):
    """``controller_at(Ω)`` of :func:`ambseal.analysis.unbalance.running_unbalance` for the
    controller ``K`` wired to ``G``: continuous, ``K(jΩ)`` behind the judged loop's delay
    lag (its current reference the same, |lag| = 1); discrete, ``K_d(e^{jΩT})`` times the
    hold's fundamental in the loop and at the samples for the current. A controller
    scheduled on speed (``schedule``) is taken at each speed Ω."""
    dt = float(K.dt or 0.0)

    def at(Kx, w):
        if dt:
            Kw = freqresp_at(Kx, np.exp(1j * w * dt))
            return Kw * hold_fundamental(w, dt)[:, None, None], Kw
        Kw = freqresp_at(Kx, 1j * w)
        if delay is not None:
            Kw = Kw * freqresp_at(delay, 1j * w)[:, :1, :1]
        return Kw, Kw

    if schedule is None:
        return lambda w: at(K, w)

    def scheduled(w):
        parts = [at(wired(G, frozen(schedule, x) if not dt else
                          controller_as_runs(schedule, x)), np.array([x])) for x in w]
        return tuple(np.concatenate([p[i] for p in parts]) for i in (0, 1))
    return scheduled


def _sensitivity_grid(loop, freq_hz) -> np.ndarray:
    """The judged loop's grid (rad/s): :func:`_log_grid` refined around its lightly damped
    poles."""
    # a 0.5 %-damped bending mode must not slip through
    return resolved_grid(_log_grid(loop, freq_hz), loop.s_poles)


def _log_grid(loop, freq_hz) -> np.ndarray:
    """``freq_hz``'s log grid (rad/s), up to Nyquist for a discrete loop."""
    dt = loop.dt
    f_hi = 0.999 * 0.5 / dt if dt else freq_hz[1]  # discrete: up to Nyquist
    return 2 * np.pi * np.logspace(math.log10(freq_hz[0]), math.log10(f_hi), freq_hz[2])


def _grades(resp, ny_names, stable: bool) -> tuple[dict, np.ndarray]:
    """The ISO 14839-3 grades of one loop's responses (σ̄(S_o) and per axis) as a case
    states them, and σ̄(S_o) on the grid."""
    so = sigma_max(resp.So)  # once, for the peaks, the zone and the figure
    so_peaks = resp.peaks("So", sigma=so)
    iso = iso_assessment(so_peaks, stable=stable)
    return {"sensitivity_peak": finite_or_none(iso.sigma_max_peak),
            "sensitivity_peak_per_axis": {ax.removeprefix("y_"): (p.value if stable else None)
                                          for ax, p in zip(ny_names, so_peaks.diagonal)},
            "iso_zone": iso.zone_sigma_max,
            "iso_zone_per_axis": {ax.removeprefix("y_"): z for ax, z in iso.zones_per_axis}}, so


def sensitivity_grades(judged: JudgedLoop, controller, cur, freq_hz) -> dict:
    """ISO 14839-3's grades of a judged loop, continuous or as it runs, as :func:`judge`
    takes them: σ̄(S_o) and each axis's |S_o| peak on the judgement's grid.

    Parameters
    ----------
    judged : JudgedLoop
        The loop (:func:`ambseal.machine.loop.judged_loop`).
    controller : control.StateSpace
        Its controller (continuous or discrete), wired by signal names.
    cur : sequence of int
        The plant's current inputs.
    freq_hz : (float, float, int)
        :attr:`JudgeSettings.freq_hz`.

    Returns
    -------
    dict
        ``sensitivity_peak`` (None where unstable), ``sensitivity_peak_per_axis``,
        ``iso_zone``, ``iso_zone_per_axis`` (an unstable loop is zone D).
    """
    loop = judged.loop
    G = _signals(judged.source, cur)
    base = _log_grid(loop, freq_hz)
    # the controller (a few states, kept by no memo) once on every frequency either pass
    # may ask for: each pass's frequencies are a subset of the resolved grid
    grid = resolved_grid(base, loop.s_poles)
    Kgrid = freqresp_at(wired(G, controller), response_points(grid, loop.dt)[0])

    def responses(w):  # w too, so that a non-finite response names its frequency
        return judged.plant_response(w)[:, :, list(cur)], Kgrid[np.searchsorted(grid, w)], w

    def gains(Gw, Kw, w):
        So = loop_responses_from(Gw, Kw, w, G.output_labels, G.input_labels).So
        return np.column_stack([sigma_max(So), np.abs(np.diagonal(So, axis1=1, axis2=2))])

    # only the peaks are graded: the resolved grid where they can lie
    w, (Gw, Kw, _) = resolved_peaks(base, loop.s_poles, responses, gains)
    resp = loop_responses_from(Gw, Kw, w, G.output_labels, G.input_labels)
    return _grades(resp, G.output_labels, loop.stable)[0]


def _judge_loop(judged: JudgedLoop, cur, force, controller, s: JudgeSettings, impulse: bool,
                static=((), ()), running=None) -> tuple[LoopJudgement, dict]:
    """The case's numbers for one judged loop, continuous or discrete: its plant with
    current inputs ``cur``, force inputs ``force`` and the seals' static loads ``static``
    (their x/y force inputs, and per seal the 2 × 2 force per unit offset and the offset,
    :func:`seal_static_load`). ``running(G, K)`` gives the unbalance response at the
    running speed; None takes it from the plant frozen at the condition."""

    # signal names from the continuous plant: a sampled one is not formed (its modal
    # form serves the responses, the poles and the impulse response)
    P, loop = judged.source, judged.loop
    G, Gf = _signals(P, cur), _signals(P, force)
    controller = wired(G, controller)  # by signal names, in the plant's order
    dt = loop.dt
    case = {"stable": loop.stable, "max_real_pole": loop.max_real_pole}
    if dt:
        case.update(max_abs_pole_z=loop.max_abs_pole, sample_rate_hz=1.0 / dt)
    w = _sensitivity_grid(loop, s.freq_hz)
    # the frozen plant's unbalance grid (the running plant's is its own)
    wu = (resolved_grid(2 * np.pi * np.linspace(*s.unbalance_range_hz, 400), loop.s_poles)
          if running is None else np.empty(0))
    # the plant (currents and force share its A) and the controller evaluated once, on both
    # grids: from the continuous plant's modal form, shared by every controller judged there
    ww = np.concatenate([w, wu])
    pts, _ = response_points(ww, dt)  # (refuses a grid above Nyquist)
    Pw, Kw = judged.plant_response(ww), freqresp_at(controller, pts)
    Gw, Gfw = Pw[:, :, cur], Pw[:, :, force]
    ny_names, nu_names, f_names = G.output_labels, G.input_labels, Gf.input_labels
    resp = loop_responses_from(Gw[:w.size], Kw[:w.size], w, ny_names, nu_names)
    grade, so = _grades(resp, ny_names, loop.stable)
    curves: dict = {"So": (w / (2 * np.pi), so), "poles": loop.poles}
    case.update(grade)
    if not loop.stable:
        case.update(compliance_peak_m_per_n=None, unbalance_peak_um=None,
                    impulse_peak_um=None, impulse_settling_s=None)
        return LoopJudgement(**case), curves
    c = compliance_from(Gw[:w.size], Kw[:w.size], Gfw[:w.size], w, ny_names, f_names)
    curves["compliance"] = (w / (2 * np.pi), c.sigma_max_m_per_n)
    if running is None:
        cu = compliance_from(Gw[w.size:], Kw[w.size:], Gfw[w.size:], wu, ny_names, f_names)
        unb = unbalance_from_compliance(cu, mass_kg=s.unbalance_mass_kg,
                                        grade_mm_s=s.unbalance_grade_mm_s, law=s.unbalance_law,
                                        max_speed_rad_s=2 * math.pi * s.unbalance_max_speed_hz)
        # the current references that hold it, per axis (ambseal.analysis.amplifier)
        held = unbalance_currents(Kw[w.size:], cu.H_m_per_n, unb.force_n), tuple(nu_names)
    else:
        unb, *held, case["critical_speeds"] = running(G, controller)
    curves["unbalance"] = (unb.speed_hz, unb.response_um)
    curves["unbalance_current"] = (unb.speed_hz, *held)
    case.update(compliance_peak_m_per_n=c.peak.value, unbalance_peak_um=unb.peak_um)
    if static[0]:
        curves["static_current"] = static_currents(judged, controller, cur, *static)
    if not impulse or s.impulse_a is None:
        case.update(impulse_peak_um=None, impulse_settling_s=None)
        return LoopJudgement(**case), curves
    # the thesis's impulse axes A_ζ and B_η (P5 §5.1): first AMB's ζ, last AMB's η
    channels = (G.input_labels[0], G.input_labels[-1])
    step = dt or s.impulse_dt_s  # a discrete loop steps at its sample time
    on_grid = [round(t / step) * step for t in (s.impulse_s, s.impulse_start_s, s.impulse_end_s)]
    imp = impulse_response_of(loop, channels=channels, amplitude_a=s.impulse_a,
                              duration_s=on_grid[0], t_impulse_s=on_grid[1],
                              t_end_s=on_grid[2], dt_s=step)
    curves["impulse"] = imp
    case.update(
        impulse_peak_um=imp.peak_displacement_um,
        impulse_settling_s=finite_or_none(imp.settling_time_s),
        impulse_settling_note=imp.settling_note,
    )
    return LoopJudgement(**case), curves


def seal_static_load(seal, pressure_bar: float) -> tuple[np.ndarray, float]:
    """A seal's static load on the rotor per unit offset and the offset: the force
    ``f = −[[K, k], [−k, K]] e`` (N, x/y) of its direct and cross-coupled stiffness at
    zero frequency at the pressure drop, and its ``static_eccentricity`` |e| (m).

    Parameters
    ----------
    seal : Seal
        A ``[[seal]]`` of the rig file.
    pressure_bar : float
        Pressure drop (bar).

    Returns
    -------
    (ndarray, float)
        The 2 × 2 matrix (N/m) and |e| (m).
    """
    K, k = (coefficient_value(getattr(seal, n), pressure_bar, 0.0) for n in ("K", "k"))
    return -np.array([[K, k], [-k, K]]), float(seal.static_eccentricity)


def static_currents(judged: JudgedLoop, controller, cur, inputs, loads) -> tuple:
    """The static control current of each axis that holds the seals' static loads, the
    worst over each seal's offset direction (module docstring of
    :mod:`ambseal.analysis.amplifier`): the loop's response at :data:`STATIC_RAD_S`,
    ``i = −K (I + G K)⁻¹ G_s f``, and per axis Σ_seals |e| ‖(M F)_a,:‖₂ (M the current per
    unit seal force, F the seal's force per unit offset).

    Parameters
    ----------
    judged : JudgedLoop
        The judged loop (its plant with the seals' force inputs).
    controller : control.StateSpace
        Its controller, wired in the plant's order.
    cur : sequence of int
        The plant's current inputs.
    inputs : sequence of int
        The seals' force inputs, x and y per seal.
    loads : sequence of (ndarray, float)
        Per seal :func:`seal_static_load`.

    Returns
    -------
    (ndarray, tuple of str)
        The static currents (A, shape (nu,)) and the axes' input names.
    """
    w = np.array([STATIC_RAD_S])
    pts, _ = response_points(w, judged.loop.dt)
    H = judged.plant_response(w)[0]
    G = _signals(judged.source, cur)
    Kw = freqresp_at(wired(G, controller), pts)[0]
    M = -Kw @ np.linalg.solve(np.eye(H.shape[0]) + H[:, cur] @ Kw, H[:, list(inputs)])
    i_s = sum(e * np.linalg.norm((M[:, 2 * j:2 * j + 2] @ F).real, axis=1)
              for j, (F, e) in enumerate(loads))
    return np.asarray(i_s, float), tuple(G.input_labels)


def _signals(P, idx):
    """``P``'s inputs ``idx`` as a system of its signal names and feedthrough only (no
    states): what the wiring and the case's names need, without a copy of ``P``'s state
    matrix (``P[:, idx]`` copies it: 28 MB at 1 888 states)."""
    return control.ss([], [], [], np.asarray(P.D)[:, idx], P.dt,
                      inputs=[P.input_labels[j] for j in idx], outputs=list(P.output_labels))


def condition_values(point, design_cfg) -> tuple[float, dict]:
    """(Ω in rad/s, every seal coefficient of the design rig by LFT name, SI) at ``point``
    (with ``speed_rpm`` and ``pressure_bar``: an OperatingPoint, or the rig's
    ``[operating]``): the values a scheduled controller is frozen at there."""

    return (2 * math.pi * point.speed_rpm / 60.0,
            seal_values(design_cfg.seal, point.pressure_bar))


def frozen_at(K, point, design_cfg):
    """The fixed controller that runs at ``point``: ``K``, a speed-scheduled one at the
    speed, or one scheduled on a seal coefficient at the design rig's value at the pressure
    drop (:func:`ambseal.machine.controller.frozen`, :func:`condition_values`).

    Parameters
    ----------
    K : control.StateSpace or ScheduledController
        The physical controller (``i = −K y``).
    point : OperatingPoint
        Where it runs (its ``speed_rpm`` and ``pressure_bar``).
    design_cfg : RigConfig
        The rig the controller was designed on (its seals give the coefficient values).

    Returns
    -------
    control.StateSpace
        ``K`` itself when fixed, else frozen at the point.
    """

    return frozen(K, *condition_values(point, design_cfg))


def judge_jobs(designs, digitals: dict, points, design_cfg) -> list[dict]:
    """``ambseal run``'s cases: every design at each of its judged points
    (:func:`points_for`: ``points``, over its schedule for one scheduled on a seal's k),
    frozen there (:func:`frozen_at`), with the delayed discrete controller that runs
    (:func:`frozen_discrete`), for :func:`judge_case`.

    **A design on the sampled plant is judged as it runs alone.** An H∞ or μ synthesised
    in the w-plane (``synthesis_plant == "sampled"``, :mod:`ambseal.robust.w_plane`) is
    its discrete controller, the Tustin transform of the w-plane one, exactly; the
    w-plane controller closed with the continuous plant and the delay's Padé lag is no
    loop that runs, and parts from the sampled loop towards Nyquist (the bilinear map
    warps frequency, w = (2/T)·tan(ωT/2)): on family seed 10 it loses a 1.4 kHz mode
    at 10 kHz where the sampled loop holds (benchmarks/README.md, "A design on the
    sampled plant judged as it runs"). Its job's ``controller`` is then the discrete
    one, so that the case's loop, its stability, zones and responses are the loop as it
    runs (:func:`judge`), and so is its ``discrete`` block. A design that cannot run
    (no digital controller) keeps its w-plane form, the only loop there is to judge.

    Parameters
    ----------
    designs : iterable of DesignResult
        The run's designs (their ``method``, ``controller`` and, for H∞ and μ,
        ``synthesis_plant``).
    digitals : dict
        Method → the digital controller that runs (:class:`~ambseal.robust.DigitalController`
        or :class:`~ambseal.machine.ScheduledDigital`); a missing one judges the continuous
        loop alone.
    points : list of OperatingPoint
        The rig's judged conditions (:func:`operating_points`).
    design_cfg : RigConfig
        The rig the controllers were designed on.

    Returns
    -------
    list of JudgeJob
        One job per design and point.
    """
    jobs = []
    for d in designs:
        digital = digitals.get(d.method)
        runs_only = (getattr(d, "synthesis_plant", "continuous") == "sampled"
                     and digital is not None)
        for p in points_for(d.controller, points, design_cfg):
            discrete = frozen_discrete(digital, p, design_cfg)
            jobs.append(JudgeJob(d.method, p,
                                 discrete if runs_only else frozen_at(d.controller, p,
                                                                      design_cfg),
                                 discrete, *_on_speed(d.controller, digital)))
    return jobs


def _on_speed(K, digital) -> tuple:
    """(continuous, as it runs) of a controller scheduled on speed, for the unbalance
    response at the running speed; (None, None) for any other."""
    if not (isinstance(K, ScheduledController) and K.parameter == SPEED):
        return None, None
    return K, (digital if getattr(digital, "parameter", None) == SPEED else None)


@dataclass(frozen=True)
class JudgeJob:
    """One case of the main job to judge (:func:`judge_jobs`): a controller, fixed at one
    operating point.

    Attributes
    ----------
    name : str
        The controller's name (its method).
    point : OperatingPoint
        Where it is judged.
    controller : control.StateSpace
        The continuous controller that runs there, m → A, ``i = −K y``; for a design on
        the sampled plant, ``discrete`` itself (:func:`judge_jobs`).
    discrete : control.StateSpace or None
        The delayed discrete controller that runs there (its sample time ``dt``); None for
        a controller that cannot run on the target.
    schedule, schedule_discrete : ScheduledController, ScheduledDigital or None
        A controller scheduled on speed, continuous and as it runs (the unbalance response
        takes it at each speed, :func:`judge`); None for any other.
    """

    name: str
    point: OperatingPoint
    controller: Any
    discrete: Any = None
    schedule: Any = None
    schedule_discrete: Any = None


def frozen_discrete(digital, point, design_cfg):
    """The discrete controller (delay included) that runs at ``point`` (a table at θ there,
    :func:`condition_values`), for the judgement; ``None`` for a controller that cannot run
    (``digital`` None)."""

    if digital is None:
        return None
    return controller_as_runs(digital, *condition_values(point, design_cfg))


def judge_case(case: JudgeJob, cfg, settings: JudgeSettings) -> tuple[JudgedCase, dict]:
    """:func:`judge` of one job of :func:`judge_jobs`: the main job's cases as run by
    :func:`ambseal.analysis.cases.run_cases`.

    Parameters
    ----------
    case : JudgeJob
        The controller, its name and point, and the discrete controller that runs.
    cfg : RigConfig
        The rig.
    settings : JudgeSettings
        :func:`judge_settings` of the rig's design specification.

    Returns
    -------
    case : JudgedCase
        The judged case (:func:`judge`).
    curves : dict
        The curves for the figures (:func:`judge`).
    """
    return judge(cfg, case.controller, case.name, case.point, settings,
                 discrete=case.discrete, schedule=case.schedule,
                 schedule_discrete=case.schedule_discrete)


def judge_spinup(cfg, controllers: dict) -> tuple[dict, list, list]:
    """The speed-scheduled rig's time and frequency judgement (P3 §4, Figs. 11–12).

    A spin-up over ``[operating] speed_range_hz`` in 1 s with alternating 100 N force and
    2 µm output steps on the first actuator axis, on the LPV model (grid speeds: the
    vertex grid, :func:`ambseal.design.lpv_plant.vertex_grid_hz`, between which it is
    exact; the rigid-body modes and the first bending pair; the force at the first AMB),
    and σ̄(S_o) on the full-order plant at 8 frozen speeds across the range
    (turboexpander: 7 grid speeds over 20–300 Hz, 12 states).

    Parameters
    ----------
    cfg : RigConfig
        A rig with ``[operating] speed_range_hz``.
    controllers : dict
        ``{name: control.StateSpace or ScheduledController}``.

    Returns
    -------
    (summary, spin-ups, frozen sensitivities)
        ``{name: {...spin-up, "frozen_sensitivity": {...}}}`` for ``metrics.json``, and the
        :class:`~ambseal.analysis.spinup.SpinupResult` and
        :class:`~ambseal.analysis.spinup.FrozenSensitivity` of each controller in order.
    """

    lo, hi = cfg.operating.speed_range_hz
    # A(Ω) is affine between the vertex grid's speeds: the plant is exact along the ramp
    L = lpv_plant(cfg, vertex_grid_hz(cfg, (lo, hi)), states=RIGID_STATES + 4,
                  force_positions=(cfg.amb[0].position,))
    speeds = np.linspace(lo, hi, 8)
    cache: dict = {}
    sims = [spinup(L, K, name=n, speeds_hz=(lo, hi)) for n, K in controllers.items()]
    sens = [frozen_sensitivity(cfg, K, speeds, name=n, plants=cache)
            for n, K in controllers.items()]
    summary = {n: {**s.to_dict(), "frozen_sensitivity": f.to_dict()}
               for n, s, f in zip(controllers, sims, sens)}
    return summary, sims, sens
