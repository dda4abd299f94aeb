"""ambseal.identify: closed-loop identification of a rig on site (thesis P1, P2, P4, P5 §3).

* :func:`load_measurement`, :func:`save_measurement` → :class:`Measurement` — the record
  format (:mod:`ambseal.identify.data`); :func:`validate_measurement` its checks;
* :func:`prbs`, :func:`stepped_sine`, :func:`chirp`, :func:`impulse` → :class:`Excitation`
  — excitation currents (P2 §4.2, P4 §3.3–3.5, P5 §3.3);
* :func:`prepare_facility`, :func:`simulate_facility` → :class:`FacilityRecord`,
  :func:`acquire` — the virtual test facility whose truth is known;
* :func:`identify` → :class:`FitResult` — the output-error fit of named parameters with
  intervals (P2 Eqs. 9–10, P4 Eq. 14; :func:`fit_parameters` underneath),
  :func:`residual_tests` (Ljung §16.6), :func:`uncertainty_from_fit` — the intervals as a
  robust design's uncertainty (P5 §4.1);
* :func:`thesis_procedure` → :class:`ProcedureResult` — stages (a)–(d) of the thesis;
  :func:`static_ki` — Ki by static loading (P2 §5); :func:`seal_frequency_test` — balanced
  stepped-sine seal tests (P4 §3.5);
* :func:`estimate_frf`, :func:`plant_frf`, :func:`model_frf` → :class:`FRF` — frequency-
  domain checks (P4 §3.4–3.5);
* :func:`coprime_factors`, :func:`identify_youla` — the Youla (Hansen) scheme (P1 Eqs. 1–3,
  13–15);
* :func:`track` → :class:`TrackingResult`, :class:`OnlineTracker` — on-line tracking of the
  seal forces (Ch. 7 §7.4), :func:`tracking_excitation` and :func:`check_excitation`;
* what the commands wire around these: a record's metadata (:func:`sample_rate_of`,
  :func:`check_record_metadata`, :func:`state_space_from_metadata`,
  :func:`check_controller`, :func:`record_is_ours`, :func:`read_matlab`), the rig's
  excitation (:func:`excitation_plan`, :func:`impulse_amplitude`, :func:`impulse_length`),
  the facility (:func:`true_rig`, :func:`truth_rig`, :func:`reduced_plant`,
  :func:`pressure_values`, :func:`virtual_static_load`), the checks of a fit
  (:func:`truth_errors`, :func:`true_line`, :func:`frf_checks`, :func:`interval_check`,
  :func:`fit_reliability`, :func:`record_spread`, :func:`advice`, :func:`fit_failure`,
  :func:`implausible`, :func:`require_finite`), the rig a design takes
  (:func:`design_rig`, :func:`impulse_checks`) and the static-load records
  (:func:`save_static_record`, :func:`with_static_record`).

The names load on first use (PEP 562 ``__getattr__``, the lazy loading of scientific
Python's SPEC 1), because importing any module of this package runs this file first and
:mod:`ambseal.identify.signals` and :mod:`ambseal.identify.measurement` are light on
purpose: they load neither python-control nor scipy nor cvxopt
(``tests/identify/test_identify_signals.py``), which an eager face would, with the fit.
"""

from ambseal.lazy import lazy_face

#: Each public name (``__all__``) and the module that defines it.
_FROM = {
    "Excitation": "signals", "chirp": "signals", "impulse": "signals", "prbs": "signals",
    "stepped_sine": "signals",
    "Measurement": "measurement", "validate_measurement": "measurement",
    "load_measurement": "data", "record_is_ours": "data", "save_measurement": "data",
    "read_matlab": "matlab_file",
    "BIAS_PER_AMPLITUDE": "excitation", "IMPULSE_LEAD": "excitation",
    "SAMPLES_PER_IMPULSE": "excitation", "excitation_plan": "excitation",
    "impulse_amplitude": "excitation", "impulse_length": "excitation",
    "FacilityRecord": "rig_sim", "prepare_facility": "rig_sim",
    "pressure_values": "rig_sim", "reduced_plant": "rig_sim", "simulate_facility": "rig_sim",
    "true_rig": "rig_sim",
    "acquire": "stages", "at_speed": "stages", "check_controller": "stages",
    "check_record_metadata": "stages", "identify": "stages", "record_spread": "stages",
    "sample_rate_of": "stages", "state_space_from_metadata": "stages",
    "ClosedLoopModel": "fit", "FitResult": "fit", "fit_parameters": "fit",
    "MISMATCH": "residuals", "ResidualTests": "residuals", "residual_tests": "residuals",
    "uncertainty_from_fit": "intervals",
    "advice": "budget",
    "frf_checks": "checks", "interval_check": "checks", "true_line": "checks",
    "truth_errors": "checks",
    "fit_failure": "plausibility", "implausible": "plausibility",
    "require_finite": "plausibility",
    "ProcedureResult": "procedure", "thesis_procedure": "procedure",
    "design_rig": "design_model", "impulse_checks": "design_model", "truth_rig": "design_model",
    "StaticLoadResult": "static_load", "save_static_record": "static_load",
    "static_ki": "static_load", "virtual_static_load": "static_load",
    "with_static_record": "static_load",
    "MIN_FIT_PCT": "seal_test", "fit_reliability": "seal_test",
    "seal_frequency_test": "seal_test",
    "FRF": "frf", "estimate_frf": "frf", "model_frf": "frf", "plant_frf": "frf",
    "CoprimeFactors": "coprime", "coprime_factors": "coprime",
    "YoulaResult": "youla", "identify_youla": "youla",
    "OnlineTracker": "tracking", "TrackingResult": "tracking",
    "TrackingSettings": "tracking", "check_excitation": "tracking", "track": "tracking",
    "tracking_excitation": "tracking",
}

__all__ = sorted(_FROM)

__getattr__, __dir__ = lazy_face(__name__, _FROM)
