"""ambseal.analysis: judge a closed loop of a plant and a controller, whatever made them.

Every analysis closes the one loop of :mod:`ambseal.robust` (``u = −K y``, continuous or
sampled with its delay) on the full-order plant:

* :func:`judge_settings`, :func:`operating_points`, :func:`judge_case` →
  :class:`JudgedCase` — one controller at one operating point: stability, sensitivities,
  ISO zone, unbalance, impulse response (:func:`ambseal.analysis.judge.judge`); the main
  job's cases (:func:`judge_jobs`, :func:`points_for`, :func:`frozen_at`,
  :func:`speed_scheduled`, :func:`judge_spinup`, :func:`unstable_open_loop_poles`) and its
  verdict on a controller that failed (:class:`FailedController`,
  :func:`synthesis_failure`, :func:`loop_failure`, :func:`also_failed`);
* :func:`loop_responses`, :func:`sensitivity_peaks`, :func:`compliance` — S_o, S_i, T_o,
  K S_o and the compliance;
* :func:`iso_assessment` → :class:`IsoAssessment` — ISO 14839-3 zones from the sensitivity
  peaks (thesis P5 §4.4.1; :data:`ZONES`, :data:`ZONE_LIMITS`, :func:`zone_limit_db`);
* :func:`unbalance_force`, :func:`unbalance_response` — ISO 21940-11 unbalance and its
  response bound;
* :func:`impulse_response` → :class:`ImpulseResponse` — the current-impulse response
  (P5 §5.1);
* :func:`closed_loop_modes` → :class:`ClosedLoopModes`, :func:`log_decrement` — closed-loop
  modes and log decrements (API 684; :func:`open_loop_modes`, :data:`OVERDAMPED_ZETA`), the
  Campbell diagram
  (:func:`ambseal.analysis.campbell.campbell` → :class:`Campbell`);
* :func:`stability_boundary`, :func:`refine_boundary` — on the rows of
  :func:`ambseal.analysis.sweep.sweep` (:func:`parse_range`, :func:`check_cases`);
  :func:`stability_case`, :func:`stability_points` → :class:`StabilityCase` (with a
  :class:`SampledStability`) — the stability of the loops over the speed range;
* :func:`frozen_sensitivity` → :class:`FrozenSensitivity`, :class:`SpinupResult` — a
  speed-scheduled rotor spinning up (P3 §4, Figs. 11–12;
  :func:`ambseal.analysis.spinup.spinup`);
* :func:`pressure_ramp`, :func:`ramp_simulation` → :class:`RampResult` — a seal pressure
  ramp;
* :func:`run_cases` — every multi-case analysis, serial or on Dask (:func:`dask_available`,
  :func:`probe_scheduler`).

``judge``, ``campbell``, ``sweep`` and ``spinup`` are not re-exported: each shares its
module's name, and re-exporting it would hide the module (``from ambseal.analysis import
judge`` would give the function, and the manual's module pages would document it instead).

Conventions: rad/s inside, Hz at the edges (``*_hz``); results are frozen dataclasses with
``to_dict()`` (JSON-safe, ``inf`` → ``"inf"``, ``NaN`` → ``None``).
"""

from ambseal.analysis.campbell import (
    OVERDAMPED_ZETA,
    Campbell,
    ClosedLoopModes,
    closed_loop_modes,
    log_decrement,
    open_loop_modes,
)
from ambseal.analysis.cases import CaseError, dask_available, probe_scheduler, run_cases
from ambseal.analysis.delivery import (
    FailedController,
    also_failed,
    loop_failure,
    synthesis_failure,
)
from ambseal.analysis.iso import ZONE_LIMITS, ZONES, IsoAssessment, iso_assessment, zone_limit_db
from ambseal.analysis.judge import (
    JudgedCase,
    JudgeJob,
    JudgeSettings,
    LoopJudgement,
    OperatingPoint,
    frozen_at,
    judge_case,
    judge_jobs,
    judge_settings,
    judge_spinup,
    operating_points,
    points_for,
    speed_scheduled,
    unstable_open_loop_poles,
)
from ambseal.analysis.loops import (
    ComplianceResponse,
    LoopResponse,
    SensitivityPeaks,
    compliance,
    loop_responses,
    sensitivity_peaks,
)
from ambseal.analysis.ramp import RampResult, pressure_ramp, ramp_simulation
from ambseal.analysis.response import ImpulseResponse, impulse_response
from ambseal.analysis.speed_range import (
    SampledStability,
    StabilityCase,
    stability_case,
    stability_points,
)
from ambseal.analysis.spinup import FrozenSensitivity, SpinupResult, frozen_sensitivity
from ambseal.analysis.sweep import check_cases, parse_range, refine_boundary, stability_boundary
from ambseal.analysis.unbalance import UnbalanceResponse, unbalance_force, unbalance_response

__all__ = ["OVERDAMPED_ZETA", "ZONES", "ZONE_LIMITS", "Campbell", "CaseError",
           "ClosedLoopModes", "ComplianceResponse", "FailedController", "FrozenSensitivity",
           "ImpulseResponse", "IsoAssessment", "JudgeJob", "JudgeSettings", "JudgedCase",
           "LoopJudgement", "LoopResponse", "OperatingPoint", "RampResult", "SensitivityPeaks",
           "SpinupResult", "SampledStability", "StabilityCase", "UnbalanceResponse",
           "also_failed", "check_cases", "closed_loop_modes", "compliance", "dask_available",
           "frozen_at",
           "frozen_sensitivity", "impulse_response", "iso_assessment", "judge_case",
           "judge_jobs", "judge_settings", "judge_spinup", "log_decrement", "loop_failure",
           "loop_responses", "open_loop_modes", "operating_points", "parse_range",
           "points_for", "pressure_ramp", "probe_scheduler", "ramp_simulation",
           "refine_boundary", "run_cases", "sensitivity_peaks", "speed_scheduled",
           "stability_boundary", "stability_case", "stability_points", "synthesis_failure",
           "unbalance_force", "unbalance_response", "unstable_open_loop_poles",
           "zone_limit_db"]
