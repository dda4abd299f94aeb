"""ambseal.analysis: judge a closed loop of a plant and a controller, whatever made them.

Every analysis closes the one loop of :mod:`ambseal.robust` (``u = −K y``, continuous or
sampled with its delay) on the full-order plant:

* :func:`judge_settings`, :func:`operating_points`, :func:`judge_case` →
  :class:`JudgedCase` — one controller at one operating point: stability, sensitivities,
  ISO zone, unbalance, impulse response (:func:`ambseal.analysis.judge.judge`);
* :func:`loop_responses`, :func:`sensitivity_peaks`, :func:`compliance` — S_o, S_i, T_o,
  K S_o and the compliance;
* :func:`iso_assessment` → :class:`IsoAssessment` — ISO 14839-3 zones from the sensitivity
  peaks (thesis P5 §4.4.1);
* :func:`unbalance_force`, :func:`unbalance_response` — ISO 21940-11 unbalance and its
  response bound;
* :func:`impulse_response` → :class:`ImpulseResponse` — the current-impulse response
  (P5 §5.1);
* :func:`closed_loop_modes` → :class:`ClosedLoopModes`, :func:`log_decrement` — closed-loop
  modes and log decrements (API 684), the Campbell diagram
  (:func:`ambseal.analysis.campbell.campbell` → :class:`Campbell`);
* :func:`stability_boundary`, :func:`refine_boundary` — on the rows of
  :func:`ambseal.analysis.sweep.sweep`;
* :func:`frozen_sensitivity` → :class:`FrozenSensitivity`, :class:`SpinupResult` — a
  speed-scheduled rotor spinning up (P3 §4, Figs. 11–12;
  :func:`ambseal.analysis.spinup.spinup`);
* :func:`pressure_ramp` → :class:`RampResult` — a seal pressure ramp;
* :func:`run_cases` — every multi-case analysis, serial or on Dask.

``judge``, ``campbell``, ``sweep`` and ``spinup`` are not re-exported: each shares its
module's name, and re-exporting it would hide the module (``from ambseal.analysis import
judge`` would give the function, and the manual's module pages would document it instead).

Conventions: rad/s inside, Hz at the edges (``*_hz``); results are frozen dataclasses with
``to_dict()`` (JSON-safe, ``inf`` → ``"inf"``, ``NaN`` → ``None``).
"""

from ambseal.analysis.campbell import Campbell, ClosedLoopModes, closed_loop_modes, log_decrement
from ambseal.analysis.cases import CaseError, run_cases
from ambseal.analysis.iso import IsoAssessment, iso_assessment
from ambseal.analysis.judge import (
    JudgedCase,
    JudgeSettings,
    LoopJudgement,
    OperatingPoint,
    judge_case,
    judge_settings,
    operating_points,
)
from ambseal.analysis.loops import (
    ComplianceResponse,
    LoopResponse,
    SensitivityPeaks,
    compliance,
    loop_responses,
    sensitivity_peaks,
)
from ambseal.analysis.ramp import RampResult, pressure_ramp
from ambseal.analysis.response import ImpulseResponse, impulse_response
from ambseal.analysis.spinup import FrozenSensitivity, SpinupResult, frozen_sensitivity
from ambseal.analysis.sweep import refine_boundary, stability_boundary
from ambseal.analysis.unbalance import UnbalanceResponse, unbalance_force, unbalance_response

__all__ = ["Campbell", "CaseError", "ClosedLoopModes", "ComplianceResponse",
           "FrozenSensitivity", "ImpulseResponse", "IsoAssessment", "JudgeSettings",
           "JudgedCase", "LoopJudgement", "LoopResponse", "OperatingPoint", "RampResult",
           "SensitivityPeaks", "SpinupResult", "UnbalanceResponse", "closed_loop_modes",
           "compliance", "frozen_sensitivity", "impulse_response", "iso_assessment",
           "judge_case", "judge_settings", "log_decrement", "loop_responses",
           "operating_points", "pressure_ramp", "refine_boundary", "run_cases",
           "sensitivity_peaks", "stability_boundary", "unbalance_force",
           "unbalance_response"]
