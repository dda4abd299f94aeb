"""API 617 unbalance response analysis with the AMB loop as it runs.

API 617 (8th ed., 2014), Part 1, the lateral analysis's unbalance response (its rules
as ROSS's API report tool implements them, after API 684 (2nd ed., 2005) §SP6.8; where
the public text could not confirm a number it is a ``[signoff]`` setting, its default
stated):

* **The unbalance.** ``U = f_U · U_r`` with ``U_r = 6350 · W / N`` (g·mm; W the journal
  static load in kg, N the maximum continuous speed in rpm; from 25 000 rpm on
  ``U_r = W / 3.937``, the value at 25 000 rpm, API 617 9th ed. 6.8.2.7 as ROSS 3.1
  takes it) and ``f_U`` = ``[signoff] unbalance_factor`` (2: API 617 9th ed. 6.8.2.7,
  ``U = 2 U_r``, as ROSS 3.1's ``api617_unbalance``; an edition that asks for another
  multiple sets it there; 6350·W/N g·mm is 4·W/N oz·in). The journal static loads
  are the reactions of the rotor on rigid supports at every AMB and spring under
  gravity (:func:`ambseal.analysis.statics.support_forces`). A machine that does not
  lie horizontal (``[machine] orientation``) takes, by ``[signoff] journal_load``
  (:func:`journal_gravity`), its weight apportioned to its bearings by static
  equilibrium as if it lay horizontal (``"as_horizontal"``, the default: a vertical
  rotor's journals carry no gravity load, yet its unbalance still scales with the mass
  each bearing holds; API 684 2nd ed.'s reading for vertical machines as we have it,
  which the public text could not confirm), or the lateral part of gravity as it acts
  (``"as_acting"``: an inclined rotor's cos θ of it; refused on a vertical rotor).
* **Where, per mode.** The first and second rigid-body shapes always: one unbalance at
  mid-span between the outermost supports (W the sum of the journal loads) and two at
  those supports 180° apart (each W its journal's load), and one at each impeller
  outboard of them (below); an AMB loop may damp every mode beyond resonance, and the
  probes and clearances are judged on these. Then for each forward mode of the loop at
  the maximum continuous speed whose frequency lies below the analysed top speed and
  that resonates (ζ below 1/√2, :data:`ambseal.analysis.campbell.OVERDAMPED_ZETA`), at
  the antinodes of its shape as API 617 (9th ed., 6.8.2.7 and Fig. 2) places them and
  ROSS 3.1's ``api617_unbalance`` reads it, for any mode shape: the shape's amplitude
  along the rotor (the orbit's semi-major axis) signed by the phase of its projection on
  the largest orbit's major axis; lobes of one sign (nodes below :data:`LOBE_FLOOR` of
  the largest not splitting them), an antinode at each lobe's largest amplitude; taken
  between the outermost supports when at least :data:`INBOARD_SHARE` of the largest,
  outboard when the largest or at least :data:`OUTBOARD_SHARE` of it; the phase 0° or
  180° by the lobe's sign against the largest; W the sum of the journal loads for a
  single antinode between the supports, the nearest journal's load for one of several,
  and the rotor's mass outboard of the adjacent support (its shaft elements and disks
  beyond it) for one outboard. Cases with the same unbalances are analysed once.
* **The response** at the probes (``[signoff] probes``, each reading x cos θ + y sin θ
  at its position; left out, the orbit's semi-major axis at the AMB sensors, or at the
  springs of a rig without AMBs),
  from standstill to ``[signoff] analysis_top_ratio`` (1.25) × the trip speed
  (:func:`ambseal.analysis.synchronous.synchronous_response`), as peak-to-peak
  amplitude (twice the orbit's semi-major axis).
* **Criticals and margins.** A peak of a probe's response that rises at least 3 dB
  above its surroundings (its prominence ≥ 1 − 1/√2 of its height) is a critical speed
  N_c; its amplification factor by the half-power method ``AF = N_c / (N_2 − N_1)``, the
  speeds where the response is 1/√2 of the peak. The peak and those speeds are solved on
  the response itself, not read off the sweep (:func:`exact_half_power`: the peak by
  Brent's method between its neighbours of the sweep, N_1 and N_2 by Brent's root finder
  between the sweep's points that bracket them, each to 1e-9 of the speed). AF < 2.5: no
  separation margin is required. Else a critical below the minimum continuous speed
  needs ``SM = min(16, 17 (1 − 1/(AF − 1.5)))`` %, one above the maximum continuous
  speed ``SM = min(26, 10 + 17 (1 − 1/(AF − 1.5)))`` %; the actual margins are
  ``100 (N_min − N_c)/N_min`` and ``100 (N_c − N_max)/N_max``, a critical inside the
  range a negative one (its distance into the range, the nearer end's rule).
* **Vibration limit.** ``A_vl = 25.4 √(12000/N)`` µm peak-to-peak, at most ``[signoff]
  vibration_limit_cap_um`` (25.4 µm: API 617 9th ed. 6.8.2.10,
  ``A_vl = min(25.4, 25.4 √(12000/N))``, as ROSS 3.1's ``run_clearance_analysis``); the
  probes' largest amplitude from the minimum continuous to the trip speed must not
  exceed it.
* **Close clearances.** The scale factor ``S_c = A_vl / A_1`` (A_1 the probes' largest
  amplitude over ``[signoff] scale_factor_speeds``: ``"to_trip"``, standstill to the
  trip speed, by default; ``"continuous"``, the minimum to the maximum continuous speed,
  as ROSS 3.1's ``run_clearance_analysis`` takes it), bounded to ``[signoff]
  scale_factor_limits`` ([0.5, 6]; ROSS 3.1 has no lower bound: ``[0, 6]``). API 617
  (8th ed., 2014) Part 1 §4.8.2.11 defines S_c and its bounds; the speed range of A_1
  is not in the public text, and both readings are settings. The response at every
  close clearance (a seal's or a spring's ``clearance``, a backup bearing's
  clearance at its AMB, :meth:`~ambseal.config.RigConfig.backup_clearance`), times
  S_c, from standstill to the trip speed, must stay within ``[signoff]
  clearance_fraction`` (75 %) of the diametral clearance.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy.constants import g as GRAVITY  # standard gravity (m/s²), ISO 80000-3
from scipy.optimize import brentq, minimize_scalar
from scipy.signal import find_peaks

from ambseal.analysis.campbell import AF_CRITICAL, OVERDAMPED_ZETA, modes_as_run
from ambseal.analysis.signoff.level1 import (
    bearing_positions,
    stage_position,
    without_seals,
)
from ambseal.analysis.statics import support_forces
from ambseal.analysis.synchronous import (
    Unbalance, orbit_semi_major, synchronous_evaluator, synchronous_response,
)
from ambseal.errors import ConfigError
from ambseal.lti import json_float
from ambseal.model import (
    bending_limit_hz,
    build_mesh,
    gravity_vector,
    inclination,
)

__all__ = ["unbalance_ur", "vibration_limit_um", "amplification_factor", "exact_half_power",
           "required_margin", "journal_loads", "journal_gravity", "journal_load_rule",
           "Critical", "Clearance", "UnbalanceCase",
           "Api617Unbalance", "api617_unbalance", "antinode_unbalances"]

#: API 617 placement (module docstring; ROSS 3.1's ``api617_unbalance``): nodes below
#: LOBE_FLOOR of the largest amplitude do not split a lobe; an antinode between the
#: supports counts from INBOARD_SHARE of the largest, one outboard from OUTBOARD_SHARE
LOBE_FLOOR, INBOARD_SHARE, OUTBOARD_SHARE = 0.02, 0.1, 0.5
#: two probes' peaks this close (relative) are one critical speed
SAME_CRITICAL = 1e-4
#: a probe's amplitude below this share of the analysis's largest is rounding
NOISE_SHARE = 1e-9
#: Speeds of the coarse sweep; each critical is refined with :data:`REFINE` more.
SPEEDS = 241
REFINE = 41
#: Speeds of the sweep closer than this (relative) are one speed: rounding apart.
TWIN = 1e-12


def unbalance_ur(load_kg: float, speed_rpm: float) -> float:
    """API 617's U_r = 6350·W/N (g·mm) as kg·m, N at most 25 000 rpm (above it W/3.937,
    API 617 9th ed. 6.8.2.7, as ROSS 3.1).

    Parameters
    ----------
    load_kg : float
        W, the journal static load (kg), > 0.
    speed_rpm : float
        N, the maximum continuous speed (rpm), > 0.

    Returns
    -------
    float
        U_r (kg·m); 6350 g·mm·rpm/kg = 6.35e-3 kg·m·rpm/kg.

    Raises
    ------
    ConfigError
        A load or speed that is not positive.
    """
    if not (load_kg > 0 and speed_rpm > 0):
        raise ConfigError(f"API 617 U_r: the load ({load_kg:g} kg) and the maximum "
                          f"continuous speed ({speed_rpm:g} rpm) must be > 0")
    return 6350e-6 * load_kg / min(speed_rpm, 25000.0)


def vibration_limit_um(speed_rpm: float, cap_um: float = 25.4) -> float:
    """API 617's A_vl = 25.4·√(12000/N) µm peak-to-peak, at most ``cap_um``."""
    return min(25.4 * math.sqrt(12000.0 / speed_rpm), cap_um)


def amplification_factor(speed_hz: np.ndarray, amp: np.ndarray, i: int
                         ) -> tuple[float, float, float]:
    """Half-power amplification factor of the peak ``amp[i]``: ``(AF, N_1, N_2)`` with
    ``N_1 < speed_hz[i] < N_2`` where ``amp`` falls to ``amp[i]/√2`` (interpolated
    linearly; NaN where it does not, on that side).

    Parameters
    ----------
    speed_hz, amp : ndarray, shape (n,)
        Speeds (ascending) and response amplitudes.
    i : int
        The peak's index.
    """
    half = amp[i] / math.sqrt(2.0)

    def cross(idx):
        for a, b in zip(idx[:-1], idx[1:]):
            if amp[b] <= half:
                t = (amp[a] - half) / (amp[a] - amp[b])
                return float(speed_hz[a] + t * (speed_hz[b] - speed_hz[a]))
        return math.nan

    n1 = cross(list(range(i, -1, -1)))
    n2 = cross(list(range(i, amp.size)))
    return float(speed_hz[i] / (n2 - n1)), n1, n2


def exact_half_power(response, speed_hz: np.ndarray, amp: np.ndarray, i: int
                     ) -> tuple[float, float, float, float, float]:
    """The peak near ``amp[i]`` and its half-power points solved on ``response`` itself:
    ``(N_c, A_c, AF, N_1, N_2)``.

    Parameters
    ----------
    response : callable
        ``response(speed_hz) → amplitude`` (a float), the function sampled as ``amp``.
    speed_hz, amp : ndarray, shape (n,)
        The sweep (ascending) and its samples.
    i : int
        The sampled peak's index (0 < i < n − 1).

    Returns
    -------
    tuple of float
        The peak's speed and amplitude, ``AF = N_c/(N_2 − N_1)`` and the half-power speeds
        (NaN on a side where the response does not fall to A_c/√2 within the sweep).
    """
    lo, hi = float(speed_hz[max(i - 1, 0)]), float(speed_hz[min(i + 1, amp.size - 1)])
    tol = 1e-9 * float(speed_hz[i])
    best = minimize_scalar(lambda s: -response(s), bounds=(lo, hi), method="bounded",
                           options={"xatol": tol, "maxiter": 200})
    n_c, a_c = float(best.x), float(-best.fun)
    if a_c < amp[i]:  # the sampled point is the better peak
        n_c, a_c = float(speed_hz[i]), float(amp[i])
    half = a_c / math.sqrt(2.0)

    def side(idx):
        for a, b in zip(idx[:-1], idx[1:]):
            if amp[b] <= half:
                # beside the peak the bracket's inner end is the solved peak (above half
                # wherever it lies; the sampled one may fall below it)
                inner = n_c if a == i else float(speed_hz[a])
                x0, x1 = sorted((inner, float(speed_hz[b])))
                return float(brentq(lambda s: response(s) - half, x0, x1, xtol=tol))
        return math.nan

    n1 = side(list(range(i, -1, -1)))
    n2 = side(list(range(i, amp.size)))
    return n_c, a_c, n_c / (n2 - n1), n1, n2


def required_margin(af: float, below: bool) -> float:
    """API 617's required separation margin (%) of a critical with amplification factor
    ``af`` below the minimum (``below``) or above the maximum continuous speed: 0 for
    AF < 2.5 (module docstring)."""
    if not af >= AF_CRITICAL:
        return 0.0
    m = 17.0 * (1.0 - 1.0 / (af - 1.5))
    return min(16.0, m) if below else min(26.0, 10.0 + m)


def journal_loads(cfg) -> tuple[tuple[float, float], ...]:
    """The journal static loads: ``((position m, load kg), …)`` per bearing (the AMBs,
    else the springs), the rotor's reactions under the sign-off's gravity
    (:func:`journal_gravity`) with each AMB holding its journal (a rigid pin: the
    controller keeps the set point) and every spring as stiff as it is
    (:func:`ambseal.analysis.statics.support_forces`). A bearing that holds the rotor down
    carries the magnitude of its reaction; a load is in kg as API 617's W (the force over
    standard gravity).

    Raises
    ------
    ConfigError
        A rig without a bearing, or whose bearings carry no load, or do not hold the
        rotor's weight (one support: nothing takes its moment), or a vertical rotor whose
        ``[signoff] journal_load`` asks for the gravity as it acts (none is lateral).
    """
    zs = bearing_positions(cfg)
    if len(set(zs)) < 2:
        raise ConfigError(f"API 617 unbalance response: the journal static loads need the "
                          f"rotor held at two bearings at least, got {len(set(zs))} "
                          "([[amb]] or [[spring]] positions): on one, nothing takes the "
                          "weight's moment")
    g = journal_gravity(cfg)
    # the bearings carry the weight: a seal (also one given as a spring) takes none
    force, applied = support_forces(without_seals(cfg), g)
    loads = tuple((z, abs(float(force[z][1]) / GRAVITY)) for z in zs)
    if not sum(w for _, w in loads) > 0:
        raise ConfigError("API 617 unbalance response: the bearings carry no static load "
                          "(a rotor without mass?)")
    mass = float(applied[1] / g[1])
    held = sum(float(f[1]) for f in force.values()) / g[1]
    if not abs(held - mass) <= 1e-3 * mass:
        raise ConfigError(f"API 617 unbalance response: the bearings hold {held:.4g} kg of "
                          f"the rotor's {mass:.4g} kg: its supports do not carry it "
                          "statically (check the [[spring]] stiffnesses and positions)")
    return loads


def journal_gravity(cfg) -> np.ndarray:
    """The gravity (m/s², x y z in the rotor's frame) the journal static loads take, by
    ``[signoff] journal_load`` (module docstring): ``"as_horizontal"``, −y whatever the
    machine's orientation; ``"as_acting"``, the lateral part of the machine's own
    (:func:`ambseal.model.gravity_vector`).

    Raises
    ------
    ConfigError
        ``"as_acting"`` on a vertical rotor: its journals carry no gravity load.
    """
    if cfg.signoff.journal_load == "as_horizontal":
        return np.array([0.0, -GRAVITY, 0.0])
    g = gravity_vector(cfg.machine)
    if not abs(g[1]) > 1e-9 * GRAVITY:
        raise ConfigError("[signoff] journal_load = \"as_acting\": a vertical rotor's "
                          "journals carry no gravity load, and API 617's U_r = 6350·W/N "
                          "needs W > 0; expected \"as_horizontal\" (the rotor's weight "
                          "apportioned to its bearings as if it lay horizontal)")
    return np.array([0.0, g[1], 0.0])


def journal_load_rule(cfg) -> str:
    """The rule the journal static loads W follow, in words (for the report)."""
    if cfg.machine.orientation == "horizontal":
        return "the rotor's weight on its bearings (static equilibrium)"
    if cfg.signoff.journal_load == "as_horizontal":
        return (f"{cfg.machine.orientation} machine: the rotor's weight apportioned to its "
                "bearings by static equilibrium as if it lay horizontal ([signoff] "
                "journal_load = \"as_horizontal\"; API 684 2nd ed. on vertical machines, "
                "not confirmed in the public text)")
    return (f"inclined machine ({inclination(cfg.machine):g}°): the lateral part of its "
            "weight on its bearings ([signoff] journal_load = \"as_acting\")")


@dataclass(frozen=True)
class Critical:
    """A critical speed found in a probe's response (module docstring)."""

    speed_hz: float
    probe_m: float
    amplitude_um: float
    af: float
    required_margin_pct: float
    actual_margin_pct: float

    @property
    def passed(self) -> bool:
        """No margin required (AF < 2.5), or the actual one at least the required."""
        return not self.af >= AF_CRITICAL or self.actual_margin_pct >= self.required_margin_pct

    def to_dict(self) -> dict:
        return {"speed_hz": self.speed_hz, "probe_m": self.probe_m,
                "amplitude_um_pp": self.amplitude_um, "AF": json_float(self.af),
                "required_margin_pct": self.required_margin_pct,
                "actual_margin_pct": self.actual_margin_pct, "passed": self.passed}


@dataclass(frozen=True)
class Clearance:
    """One close clearance against the scaled response."""

    name: str
    position_m: float
    diametral_um: float
    allowed_um: float
    scaled_um: float

    @property
    def passed(self) -> bool:
        return self.scaled_um <= self.allowed_um

    def to_dict(self) -> dict:
        return {"name": self.name, "position_m": self.position_m,
                "diametral_clearance_um": self.diametral_um, "allowed_um_pp": self.allowed_um,
                "scaled_response_um_pp": self.scaled_um, "passed": self.passed}


@dataclass(frozen=True)
class UnbalanceCase:
    """One mode's unbalance and what its response shows.

    Attributes
    ----------
    mode_hz : float
        The damped frequency of the mode it excites (Hz, at the maximum continuous speed);
        NaN for the rigid-body shapes placed whatever the modes.
    placement : str
        The rule that placed it, in words.
    unbalances : tuple of Unbalance
    speed_hz : ndarray, shape (n,)
        The analysed speeds (Hz).
    probe_m : tuple of float
        Probe positions (m).
    probe_um : ndarray, shape (n, n_probes)
        Peak-to-peak amplitude at each probe (µm).
    criticals : tuple of Critical
    probe_max_um : float
        The probes' largest amplitude from the minimum continuous to the trip speed (µm
        p-p).
    scale_factor : float
        S_c.
    clearances : tuple of Clearance
    """

    mode_hz: float
    placement: str
    unbalances: tuple
    speed_hz: np.ndarray
    probe_m: tuple
    probe_um: np.ndarray
    criticals: tuple
    probe_max_um: float
    scale_factor: float
    clearances: tuple

    def to_dict(self) -> dict:
        return {"mode_hz": json_float(self.mode_hz), "placement": self.placement,
                "unbalances": [{"position_m": u.position, "amount_kg_m": u.amount,
                                "amount_g_mm": u.amount * 1e6, "phase_deg": u.phase_deg}
                               for u in self.unbalances],
                "criticals": [c.to_dict() for c in self.criticals],
                "probe_max_um_pp": self.probe_max_um, "scale_factor": self.scale_factor,
                "clearances": [c.to_dict() for c in self.clearances]}


@dataclass(frozen=True)
class Api617Unbalance:
    """The API 617 unbalance response analysis of one controller (module docstring).

    Attributes
    ----------
    controller : str
    min_hz, max_hz, trip_hz, top_hz : float
        Minimum and maximum continuous, trip and analysed top speed (Hz).
    journal_loads : tuple of (float, float)
        (position m, static load kg) per support.
    vibration_limit_um : float
        A_vl (µm p-p).
    cases : tuple of UnbalanceCase
    loop_stable : bool
        The loop the responses are taken on (the rig, its seals at ``[operating]
        pressure_bar``, the controller as it runs) is stable at the maximum continuous
        speed: where it is not, a steady unbalance response does not exist and none of
        these criteria is graded (:mod:`ambseal.analysis.signoff`).
    journal_load_rule : str
        The rule the journal loads follow, in words (:func:`journal_load_rule`: the
        machine's orientation and ``[signoff] journal_load``).
    """

    controller: str
    min_hz: float
    max_hz: float
    trip_hz: float
    top_hz: float
    journal_loads: tuple
    vibration_limit_um: float
    cases: tuple
    loop_stable: bool = True
    journal_load_rule: str = ""

    @property
    def probe_max_um(self) -> float:
        return max((c.probe_max_um for c in self.cases), default=0.0)

    @property
    def separation_passed(self) -> bool:
        return all(k.passed for c in self.cases for k in c.criticals)

    @property
    def vibration_passed(self) -> bool:
        return self.probe_max_um <= self.vibration_limit_um

    @property
    def clearance_passed(self) -> bool:
        return all(k.passed for c in self.cases for k in c.clearances)

    @property
    def passed(self) -> bool:
        return self.separation_passed and self.vibration_passed and self.clearance_passed

    def to_dict(self) -> dict:
        """The ``unbalance`` block: SI at the core, µm and % where the standard reads so."""
        return {"min_continuous_hz": self.min_hz, "max_continuous_hz": self.max_hz,
                "trip_hz": self.trip_hz, "analysed_to_hz": self.top_hz,
                "journal_loads": [{"position_m": z, "load_kg": w}
                                  for z, w in self.journal_loads],
                "journal_load_rule": self.journal_load_rule,
                "vibration_limit_um_pp": self.vibration_limit_um,
                "probe_max_um_pp": self.probe_max_um,
                "separation_passed": self.separation_passed,
                "vibration_passed": self.vibration_passed,
                "clearance_passed": self.clearance_passed, "passed": self.passed,
                "loop_stable": self.loop_stable,
                "cases": [c.to_dict() for c in self.cases]}


def _placements(cfg, modes, loads, factor: float, n_rpm: float) -> list[tuple]:
    """``(mode_hz, rule, unbalances)`` per forward mode (module docstring), distinct."""
    zs = [z for z, _ in loads]
    lo, hi = min(zs), max(zs)
    z_nodes = modes.node_z_m
    # an outboard W is its mass's load under the journal loads' gravity (as_acting: the
    # lateral part only)
    share = abs(float(journal_gravity(cfg)[1])) / GRAVITY
    outboard_mass = {side: share * _outboard_mass(cfg, z, side)
                     for side, z in (("left", lo), ("right", hi))}
    total = sum(w for _, w in loads)
    # a journal that carries (almost) nothing gets the mean load: U_r needs W > 0
    loads = tuple((z, w if w > 1e-6 * total else total / len(loads)) for z, w in loads)
    # the impellers (the stages; without stages, the disks) outboard of the supports
    heavy = ([stage_position(cfg, st) for st in cfg.stage] if cfg.stage
             else [d.position for d in cfg.disk])
    outboard = [z for z in heavy if z < lo - 1e-9 or z > hi + 1e-9]
    out, seen = [], set()

    def add(f_hz, rule, unb):
        key = tuple((round(u.position, 9), u.phase_deg) for u in unb)
        if key not in seen:
            seen.add(key)
            out.append((f_hz, rule, unb))

    def overhung(f_hz, zu):
        """One unbalance at the impeller ``zu``, W the mass outboard of its support."""
        w = outboard_mass["left" if zu < lo else "right"]
        add(f_hz, f"overhung: at {zu:.3g} m, W = {w:.4g} kg outboard of the support",
            (Unbalance(zu, factor * unbalance_ur(w, n_rpm)),))

    # the first and second rigid-body shapes, whatever the loop's modes (an AMB loop may
    # damp them all beyond resonance): the probes and clearances are judged on them
    mid = float(z_nodes[int(np.argmin(np.abs(z_nodes - 0.5 * (lo + hi))))])
    add(math.nan, f"first mode, at mid-span {mid:.3g} m, W = {total:.4g} kg (every "
        "journal)", (Unbalance(mid, factor * unbalance_ur(total, n_rpm)),))
    add(math.nan, f"second mode, at the journals {lo:.3g} m and {hi:.3g} m, 180° apart, "
        "W each journal's load", tuple(
            Unbalance(z, factor * unbalance_ur(dict(loads)[z], n_rpm), ph)
            for z, ph in ((lo, 0.0), (hi, 180.0))))
    for zu in outboard:
        overhung(math.nan, zu)
    for k in range(modes.poles.size):
        if modes.whirl[k] == "backward" or modes.damping_ratio[k] >= OVERDAMPED_ZETA:
            continue
        rule, unb = antinode_unbalances(modes.shapes[k, :, 0], modes.shapes[k, :, 1],
                                        z_nodes, loads, outboard_mass, factor, n_rpm)
        add(float(modes.frequency_hz[k]), rule, unb)
    return out


def _outboard_mass(cfg, z_b: float, side: str) -> float:
    """The rotor's mass outboard of a support at ``z_b`` (m) on ``side`` ("left" or
    "right"): its shaft elements wholly beyond it and its disks strictly beyond it, as
    ROSS 3.1's ``_overhung_mass``."""
    mesh = build_mesh(cfg)
    t = np.zeros(8)
    t[[0, 4]] = 1.0  # a rigid translation of an element's two nodes
    beyond = (lambda a, b: b <= z_b + 1e-12) if side == "left" else (
        lambda a, b: a >= z_b - 1e-12)
    shaft = sum(float(t @ el.M() @ t) for e, el in enumerate(mesh.elements)
                if beyond(mesh.z[e], mesh.z[e + 1]))
    disks = sum(d.mass for d in cfg.disk
                if (d.position < z_b - 1e-12 if side == "left" else d.position > z_b + 1e-12))
    return float(shaft + disks)


def antinode_unbalances(X, Y, z_nodes, loads, outboard_mass, factor: float,
                        n_rpm: float) -> tuple[str, tuple]:
    """API 617's unbalances for one mode shape (module docstring; API 617 9th ed. 6.8.2.7
    and Fig. 2 as ROSS 3.1's ``api617_unbalance`` reads them).

    Parameters
    ----------
    X, Y : ndarray of complex, shape (n,)
        The mode's x and y displacements at the nodes.
    z_nodes : ndarray, shape (n,)
        The nodes' positions (m), increasing.
    loads : sequence of (float, float)
        ``(z, W)``: each journal's position (m) and static load (kg).
    outboard_mass : dict
        ``{"left": kg, "right": kg}``: the rotor's mass outboard of the outermost supports.
    factor : float
        ``[signoff] unbalance_factor`` (U = factor · U_r).
    n_rpm : float
        The maximum continuous speed (rpm).

    Returns
    -------
    (str, tuple of Unbalance)
        The rule in words, and the unbalances.
    """
    X, Y = np.asarray(X, complex), np.asarray(Y, complex)
    z_nodes = np.asarray(z_nodes, float)
    a = orbit_semi_major(X, Y)
    ref = int(np.argmax(a))
    # the largest orbit's major axis: r(t) = Re([X, Y] e^{jt}) longest at
    # t = −arg(X² + Y²)/2
    t = -0.5 * np.angle(X[ref] ** 2 + Y[ref] ** 2)
    d = np.real(np.array([X[ref], Y[ref]]) * np.exp(1j * t))
    theta = math.atan2(d[1], d[0])
    proj = X * math.cos(theta) + Y * math.sin(theta)
    sign = np.sign(np.real(proj * np.conj(proj[ref])))
    sign[sign == 0] = 1.0
    lobes, current, cur = [], [], None
    for i in range(a.size):
        s_i = sign[i] if a[i] >= LOBE_FLOOR * a.max() else None
        if cur is not None and s_i is not None and s_i != cur:
            lobes.append(current)
            current = []
        current.append(i)
        if s_i is not None:
            cur = s_i
    lobes.append(current)
    zs = [z for z, _ in loads]
    lo, hi = min(zs), max(zs)
    picks = []
    for lobe in lobes:
        i = lobe[int(np.argmax(a[lobe]))]
        inboard = lo - 1e-9 <= z_nodes[i] <= hi + 1e-9
        if (a[i] >= INBOARD_SHARE * a[ref]) if inboard else (
                i == ref or a[i] >= OUTBOARD_SHARE * a[ref]):
            picks.append((i, inboard))
    n_in = sum(inb for _, inb in picks)
    total = sum(w for _, w in loads)
    unb, words = [], []
    for i, inboard in picks:
        z = float(z_nodes[i])
        if inboard and n_in == 1:
            w, why = total, "every journal"
        elif inboard:
            zj, w = min(loads, key=lambda zw: abs(zw[0] - z))
            why = f"the journal at {zj:.3g} m"
        else:
            w = outboard_mass["left" if z < lo else "right"]
            why = "outboard of the support"
        ph = 0.0 if sign[i] == sign[ref] else 180.0
        unb.append(Unbalance(z, factor * unbalance_ur(w, n_rpm), ph))
        words.append(f"{z:.3g} m at {ph:.0f}° (W = {w:.4g} kg, {why})")
    rule = (f"{len(unb)} antinode(s): " if len(unb) > 1 else "its antinode: ") + "; ".join(
        words)
    return rule, tuple(unb)


def _close_clearances(cfg) -> list[tuple[str, float, float]]:
    """(name, position m, radial clearance m) of each seal and spring (a plain bearing, a
    seal without Childs form) with a ``clearance`` and each backup bearing (at its AMB)."""
    out = [(s.name, s.position, s.clearance) for s in cfg.seal if s.clearance is not None]
    out += [(s.name or f"spring{i}", s.position, s.clearance)
            for i, s in enumerate(cfg.spring) if s.clearance is not None]
    out += [(f"backup bearing {a.name}", a.position, cfg.backup_clearance(a))
            for a in cfg.amb if cfg.backup_clearance(a) is not None]
    return out


def _criticals(speed, probe_um, probes, f_min, f_max, response=None, floor: float = 0.0
               ) -> list[Critical]:
    """The criticals of one case (module docstring); ``response(speed_hz, p)``, the
    probe ``p``'s amplitude at any speed, solves each peak and its half-power points
    (:func:`exact_half_power`), else they are read off the sweep; peaks below ``floor``
    (µm) are rounding (a probe on a node of the excited shape: the case's wiggles there are
    no critical)."""
    out = []
    for p, z in enumerate(probes):
        amp = probe_um[:, p]
        if not np.any(amp > floor):
            continue
        idx, _ = find_peaks(amp, prominence=(1 - 1 / math.sqrt(2)) * amp, height=floor)
        for i in idx:
            if response is None:
                af, _, _ = amplification_factor(speed, amp, int(i))
                nc, a_c = float(speed[i]), float(amp[i])
            else:
                nc, a_c, af, _, _ = exact_half_power(lambda s, p=p: response(s, p), speed,
                                                     amp, int(i))
            if nc < f_min:
                req, act = required_margin(af, True), 100 * (f_min - nc) / f_min
            elif nc > f_max:
                req, act = required_margin(af, False), 100 * (nc - f_max) / f_max
            else:
                near_low = nc - f_min <= f_max - nc
                req = required_margin(af, near_low)
                act = -100 * min(nc - f_min, f_max - nc) / f_max
            out.append(Critical(nc, float(z), a_c, af, req, act))
    # one critical per speed: the solved peaks of two probes agree to the flat top's
    # conditioning (a rigid rotor's two supports: 2.6e-6 apart), the probe that shows it
    # largest
    best: list[Critical] = []
    for c in sorted(out, key=lambda c: c.speed_hz):
        if best and c.speed_hz - best[-1].speed_hz <= SAME_CRITICAL * c.speed_hz:
            if c.amplitude_um > best[-1].amplitude_um:
                best[-1] = c
        else:
            best.append(c)
    return best


def api617_unbalance(cfg, controller=None, *, name: str = "none",
                     progress=None) -> Api617Unbalance:
    """API 617's unbalance response analysis of a rig with one controller as it runs
    (module docstring).

    Parameters
    ----------
    cfg : RigConfig
        The rig; its speeds from ``[operating]`` (``speed_range_hz``, ``trip_speed_hz``),
        its limits from ``[signoff]``.
    controller : DigitalController or ScheduledDigital, optional
        As it runs; None for a rig on springs alone.
    name : str
        The controller's name in the result.
    progress : callable, optional
        Called with one line per unbalance case.

    Returns
    -------
    Api617Unbalance

    Raises
    ------
    ConfigError
        A rig without supports or a maximum continuous speed of 0.
    """
    so = cfg.signoff
    f_min, f_max = cfg.operating.continuous_hz
    if not f_max > 0:
        raise ConfigError("API 617 unbalance response: the maximum continuous speed must be "
                          "> 0 (set [operating] speed_rpm or speed_range_hz)")
    trip = cfg.operating.trip_hz
    top = so.analysis_top_ratio * trip
    n_rpm = 60.0 * f_max
    loads = journal_loads(cfg)
    max_hz = min(top, bending_limit_hz(cfg))
    if controller is not None and cfg.amb:
        max_hz = min(max_hz, 0.45 * cfg.controller.sample_rate_hz)
    modes = modes_as_run(cfg, controller, speed_hz=f_max, max_hz=max_hz)
    cases = _placements(cfg, modes, loads, so.unbalance_factor, n_rpm)
    if so.probes:  # directional probes where the rig file puts them
        probes = tuple(float(pr.position) for pr in so.probes)
        angles = [float(pr.angle_deg) for pr in so.probes]
    else:
        probes = tuple(sorted({a.sensor_position for a in cfg.amb}) if cfg.amb
                       else [z for z, _ in loads])
        angles = [None] * len(probes)
    close = _close_clearances(cfg)
    where = [*probes, *(z for _, z, _ in close)]
    where_angles = [*angles, *(None for _ in close)]
    a_vl = vibration_limit_um(n_rpm, so.vibration_limit_cap_um)
    # from standstill: the first speed a step above it (a controller's integrator has no
    # response at zero frequency)
    coarse = np.unique(np.concatenate([np.linspace(top / SPEEDS, top, SPEEDS),
                                       [f_min, f_max, trip]]))

    def response(speeds):
        r = synchronous_response(cfg, controller, speeds, [u for _, _, u in cases], where,
                                 angles_deg=where_angles)
        return 2e6 * r.amplitude_m  # µm peak-to-peak

    amp = response(coarse)
    # each peak refined between its neighbours of the coarse sweep
    extra = []
    for c in range(len(cases)):
        for p in range(len(probes)):
            for i in find_peaks(amp[c, :, p])[0]:
                extra.append(np.linspace(coarse[i - 1], coarse[i + 1], REFINE)[1:-1])
    speed = coarse
    if extra:
        # the refinements of neighbouring peaks, and each one's midpoint and the coarse
        # point it refines, coincide up to rounding: one speed of each (a twin beside the
        # sampled peak leaves the bracket of its exact peak empty on that side)
        fine = np.unique(np.concatenate(extra))
        fine = fine[np.concatenate([[True], np.diff(fine) > TWIN * fine[1:]])]
        fine = fine[np.min(np.abs(fine[:, None] - coarse[None, :]), axis=1) > TWIN * fine]
        speed = np.concatenate([coarse, fine])
        order = np.argsort(speed)
        speed, amp = speed[order], np.concatenate([amp, response(fine)], axis=1)[:, order]
    lo_, hi_ = (speed >= f_min - 1e-9) & (speed <= trip + 1e-9), speed <= trip + 1e-9
    floor = NOISE_SHARE * float(amp[:, :, :len(probes)].max(initial=0.0))
    s_lo, s_hi = so.scale_factor_limits
    a1_speeds = (((speed >= f_min - 1e-9) & (speed <= f_max + 1e-9))
                 if so.scale_factor_speeds == "continuous" else hi_)
    out = []
    for c, (f_mode, rule, unb) in enumerate(cases):
        pr = amp[c, :, :len(probes)]

        built: dict = {}  # per probe, the loop assembled once for the searches

        def at(s, p, unb=unb, built=built):  # this case's probe p at one speed
            if p not in built:
                built[p] = synchronous_evaluator(cfg, controller, [unb], [probes[p]],
                                                 angles_deg=[angles[p]])
            return 2e6 * float(built[p]([s]).amplitude_m[0, 0, 0])

        crit = _criticals(speed, pr, probes, f_min, f_max, at, floor)
        a1 = float(pr[a1_speeds].max())
        sc = float(np.clip(a_vl / a1, s_lo, s_hi)) if a1 > 0 else s_hi
        clear = tuple(Clearance(n, float(z), 2e6 * rc, so.clearance_fraction * 2e6 * rc,
                                float(sc * amp[c, hi_, len(probes) + j].max()))
                      for j, (n, z, rc) in enumerate(close))
        out.append(UnbalanceCase(f_mode, rule, unb, speed, probes, pr, tuple(crit),
                                 float(pr[lo_].max()), sc, clear))
        if progress:
            progress(f"{name}: unbalance {c + 1}/{len(cases)} ({rule}): "
                     f"{len(crit)} critical(s), probes ≤ {out[-1].probe_max_um:.3g} µm p-p")
    return Api617Unbalance(name, f_min, f_max, trip, top, loads, a_vl, tuple(out),
                           bool(modes.stable), journal_load_rule(cfg))
