"""ambseal.analysis: judge a closed loop of a plant and a controller, whatever made them.

Every analysis closes the one loop of :mod:`ambseal.robust` (``u = −K y``, continuous or
sampled with its delay) on the full-order plant:

* :func:`judge_settings`, :func:`operating_points`, :func:`judge_case` →
  :class:`JudgedCase` — one controller at one operating point: stability, sensitivities,
  ISO zone, unbalance, impulse response (:func:`ambseal.analysis.judge.judge`); the main
  job's cases (:func:`judge_jobs`, :func:`points_for`, :func:`frozen_at`,
  :func:`speed_scheduled`, :func:`judge_spinup`, :func:`unstable_open_loop_poles`) and its
  verdict on a controller that failed (:class:`FailedController`,
  :func:`synthesis_failure`, :func:`loop_failure`, :func:`also_failed`, its conditions
  named by :func:`case_label`; an unbalance orbit
  beyond the rig's clearances, :func:`clearance_failure` on :func:`rig_clearances_um`;
  the failing mode named by its kind, :func:`failing_mode_kind`, :func:`mode_kind` on
  :func:`support_span_m`);
* :func:`loop_responses`, :func:`sensitivity_peaks`, :func:`compliance` — S_o, S_i, T_o,
  K S_o and the compliance;
* :func:`iso_assessment` → :class:`IsoAssessment` — ISO 14839-3 zones from the sensitivity
  peaks (thesis P5 §4.4.1; :data:`ZONES`, :data:`ZONE_LIMITS`, :func:`zone_limit_db`);
* :func:`first_largest`, :func:`beyond` — what rounding may not decide: ties broken by the
  order given (:data:`TIE_RTOL`; :mod:`ambseal.analysis.tolerance`);
* :func:`unbalance_force`, :func:`unbalance_response` — ISO 21940-11 unbalance and its
  response bound; :func:`running_unbalance` on :func:`running_plant` (→ :class:`RunningPlant`)
  — the bound with the plant at the running speed;
* :func:`impulse_response` → :class:`ImpulseResponse` — the current-impulse response
  (P5 §5.1);
* :func:`closed_loop_modes` → :class:`ClosedLoopModes`, :func:`log_decrement` — closed-loop
  modes and log decrements (API 684; :func:`open_loop_modes`, :data:`OVERDAMPED_ZETA`,
  :data:`AF_CRITICAL`), the Campbell diagram (:func:`ambseal.analysis.campbell.campbell`
  → :class:`Campbell`);
* the sign-off, in one subpackage read in the order a rig goes through it
  (:mod:`ambseal.analysis.signoff`): :func:`sign_off` → :class:`SignOff`,
  :func:`verdict_line` — every criterion of API 617 and ISO 14839-2 per controller as it
  runs; :func:`level1_screening` → :class:`Level1`, :func:`stage_cross_coupling` — API
  617's Level I; :func:`level2_analysis` → :class:`Level2` — Level II, source by source;
  :func:`api617_unbalance` → :class:`Api617Unbalance` — the unbalance response, separation
  margins and close clearances, on :func:`synchronous_response` (rotating
  :class:`Unbalance` with the loop as it runs); :func:`iso14839_2_zones` →
  :class:`IsoVibration`;
* :func:`rotor_at_rest` → :class:`Statics` (:class:`AmbStatic`), :func:`support_forces` —
  the rotor held at rest under gravity as the machine stands: each bearing's load, each
  AMB's static currents, the axial weight;
* :func:`stability_boundary`, :func:`refine_boundary` — on the rows of
  :func:`ambseal.analysis.sweep.sweep` (:func:`parse_range`, :func:`check_cases`);
  :func:`stability_case`, :func:`stability_points` → :class:`StabilityCase` (with a
  :class:`SampledStability`) — the stability of the loops over the speed range;
* :func:`frozen_sensitivity` → :class:`FrozenSensitivity`, :class:`SpinupResult` — a
  speed-scheduled rotor spinning up (P3 §4, Figs. 11–12;
  :func:`ambseal.analysis.spinup.spinup`);
* :func:`pressure_ramp`, :func:`ramp_simulation` → :class:`RampResult` — a seal pressure
  ramp;
* :func:`simulate_drop` → :class:`DropResult` — the rotor dropped onto its touchdown
  bearings when its AMBs let go (:func:`drop_model`; :mod:`ambseal.analysis.drop`), and
  :func:`drop_verdict`, its pass criteria; :func:`support_matrices`, the seals and springs in it;
  :func:`drop_scatter`, Monte-Carlo drops over friction, clearance, support damping and
  unbalance, serial or on Dask
  (:mod:`ambseal.analysis.drop_monte_carlo`, :func:`wilson_interval`);
  :func:`levitated_state`, the AMB loop's unbalance orbit a drop starts from
  (:mod:`ambseal.analysis.drop_levitated`); :func:`amb_loop` → :class:`AmbLoop`, the AMB
  loop that runs inside the drop, :func:`drop_event`, the event that lands the rotor, and
  :func:`lost_at_rest`, whether a controller acts on it (:mod:`ambseal.analysis.drop_loop`);
* :func:`run_cases` — every multi-case analysis, serial or on Dask (:func:`dask_available`,
  :func:`probe_scheduler`).

``judge``, ``campbell``, ``sweep`` and ``spinup`` are not re-exported: each shares its
module's name, and re-exporting it would hide the module (``from ambseal.analysis import
judge`` would give the function, and the manual's module pages would document it instead).

Each name loads its module on first use (PEP 562 ``__getattr__``,
:func:`ambseal.lazy.lazy_face`): ``ambseal modes`` of the open loop loads its modes, not the
judgement's python-control loops.

Conventions: rad/s inside, Hz at the edges (``*_hz``); results are frozen dataclasses with
``to_dict()`` (JSON-safe, ``inf`` → ``"inf"``, ``NaN`` → ``None``).
"""

from ambseal.analysis.signoff import _FROM as _SIGNOFF
from ambseal.lazy import lazy_face

#: Each public name (``__all__``) and the module that defines it.
_FROM = {
    "DropResult": "drop", "simulate_drop": "drop", "drop_model": "drop",
    "drop_verdict": "drop", "support_matrices": "drop", "drop_scatter": "drop_monte_carlo",
    "wilson_interval": "drop_monte_carlo", "levitated_state": "drop_levitated",
    "AmbLoop": "drop_loop", "amb_loop": "drop_loop", "drop_event": "drop_loop",
    "lost_at_rest": "drop_loop",
    "capacity_block": "amplifier", "capacity_words": "amplifier", "force_demand": "amplifier",
    "saturates": "amplifier", "unbalance_currents": "amplifier", "notched_currents": "amplifier",
    "used_by_speed": "amplifier", "switch_on_hz": "amplifier",
    "later_switch_on_hz": "amplifier",
    "rejection_effect": "rejection", "rejection_stability": "rejection",
    "lost_conditions": "rejection",
    "facility_rejection": "rejection", "FacilityRejection": "rejection",
    "facility_speed_step": "rejection", "SpeedStep": "rejection",
    "closed_loop_modes": "campbell", "log_decrement": "campbell", "modes_as_run": "campbell",
    "poles_as_run": "campbell",
    "open_loop_modes": "campbell", "Campbell": "campbell", "ClosedLoopModes": "campbell",
    "OVERDAMPED_ZETA": "campbell", "AF_CRITICAL": "campbell", "dask_available": "cases",
    "probe_scheduler": "cases",
    "run_cases": "cases", "CaseError": "cases", "also_failed": "delivery",
    "case_label": "delivery", "loop_failure": "delivery", "saturation_failure": "delivery",
    "synthesis_failure": "delivery", "rig_clearances_um": "delivery",
    "worst_orbit_um": "delivery", "notched_orbit_um": "delivery",
    "clearance_exceeded": "delivery",
    "clearance_failure": "delivery", "CLEARANCE_WORDS": "delivery",
    "FailedController": "delivery", "iso_assessment": "iso", "zone_limit_db": "iso",
    "IsoAssessment": "iso", "ZONES": "iso", "ZONE_LIMITS": "iso", "ZONE_RTOL": "iso",
    "ZONE_SCALE": "iso", "graded_zone": "iso", "worst_zone": "iso", "zone_sides": "iso",
    "boundary_note": "iso", "zone_words": "iso", "first_largest": "tolerance",
    "beyond": "tolerance", "side_of": "tolerance", "TIE_RTOL": "tolerance",
    "SEPARATION_RTOL": "tolerance",
    "frozen_at": "judge",
    "judge_case": "judge", "judge_jobs": "judge", "judge_settings": "judge",
    "judge_spinup": "judge", "operating_points": "judge", "points_for": "judge",
    # the sign-off's names, as its own face lists them
    **{name: f"signoff.{module}" for name, module in _SIGNOFF.items()},
    "synchronous_response": "synchronous", "Unbalance": "synchronous",
    "speed_scheduled": "judge", "unstable_open_loop_poles": "judge", "JudgeJob": "judge",
    "JudgeSettings": "judge", "JudgedCase": "judge", "LoopJudgement": "judge",
    "OperatingPoint": "judge", "compliance": "loops", "loop_responses": "loops",
    "sensitivity_peaks": "loops", "ComplianceResponse": "loops", "LoopResponse": "loops",
    "SensitivityPeaks": "loops", "pressure_ramp": "ramp", "ramp_simulation": "ramp",
    "RampResult": "ramp", "impulse_response": "response", "ImpulseResponse": "response",
    "stability_case": "speed_range", "stability_points": "speed_range",
    "SampledStability": "speed_range", "StabilityCase": "speed_range",
    "frozen_sensitivity": "spinup", "FrozenSensitivity": "spinup", "SpinupResult": "spinup",
    "check_cases": "sweep", "parse_range": "sweep", "refine_boundary": "sweep",
    "stability_boundary": "sweep", "unbalance_force": "unbalance",
    "unbalance_response": "unbalance", "UnbalanceResponse": "unbalance",
    "running_unbalance": "unbalance",
    "running_plant": "synchronous", "RunningPlant": "synchronous",
    "mode_kind": "mode_naming", "failing_mode_kind": "mode_naming",
    "support_span_m": "mode_naming",
    "Statics": "statics", "AmbStatic": "statics", "support_forces": "statics",
    "rotor_at_rest": "statics",
}

__all__ = sorted(_FROM)

__getattr__, __dir__ = lazy_face(__name__, _FROM)
