"""ambseal.identify: closed-loop identification of a rig on site (thesis P1, P2, P4, P5 §3).

* :func:`load_measurement`, :func:`save_measurement` → :class:`Measurement` — the record
  format (:mod:`ambseal.identify.records.data`); :func:`validate_measurement` its checks;
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
:mod:`ambseal.identify.excitation.signals` and :mod:`ambseal.identify.records.measurement` are light on
purpose: they load neither python-control nor scipy nor cvxopt
(``tests/identify/test_identify_signals.py``), which an eager face would, with the fit.
"""

from ambseal.lazy import lazy_face

#: Each public name (``__all__``) and the module that defines it.
_FROM = {
    "Excitation": "excitation.signals", "chirp": "excitation.signals",
    "impulse": "excitation.signals", "prbs": "excitation.signals",
    "stepped_sine": "excitation.signals",
    "Measurement": "records.measurement", "validate_measurement": "records.measurement",
    "load_measurement": "records.data", "record_is_ours": "records.data",
    "save_measurement": "records.data",
    "read_matlab": "records.matlab_file",
    "BIAS_PER_AMPLITUDE": "excitation.plan", "IMPULSE_LEAD": "excitation.plan",
    "SAMPLES_PER_IMPULSE": "excitation.plan", "excitation_plan": "excitation.plan",
    "impulse_amplitude": "excitation.plan", "impulse_length": "excitation.plan",
    "FacilityRecord": "facility.rig_sim", "prepare_facility": "facility.rig_sim",
    "pressure_values": "facility.rig_sim", "reduced_plant": "facility.rig_sim",
    "simulate_facility": "facility.rig_sim", "true_rig": "facility.rig_sim",
    "acquire": "fitting.stages", "at_speed": "fitting.stages",
    "check_controller": "fitting.stages", "check_record_metadata": "fitting.stages",
    "identify": "fitting.stages", "record_spread": "fitting.stages",
    "sample_rate_of": "fitting.stages", "state_space_from_metadata": "fitting.stages",
    "ClosedLoopModel": "fitting.fit", "FitResult": "fitting.fit",
    "fit_parameters": "fitting.fit",
    "MISMATCH": "fitting.residuals", "ResidualTests": "fitting.residuals",
    "residual_tests": "fitting.residuals",
    "uncertainty_from_fit": "fitting.intervals",
    "advice": "fitting.budget",
    "frf_checks": "fitting.checks", "interval_check": "fitting.checks",
    "true_line": "fitting.checks", "truth_errors": "fitting.checks",
    "fit_failure": "fitting.plausibility", "implausible": "fitting.plausibility",
    "require_finite": "fitting.plausibility",
    "ProcedureResult": "fitting.procedure", "thesis_procedure": "fitting.procedure",
    "design_rig": "facility.design_model", "impulse_checks": "facility.design_model",
    "truth_rig": "facility.design_model",
    "StaticLoadResult": "fitting.static_load", "save_static_record": "fitting.static_load",
    "static_ki": "fitting.static_load", "virtual_static_load": "fitting.static_load",
    "with_static_record": "fitting.static_load",
    "MIN_FIT_PCT": "fitting.seal_test", "fit_reliability": "fitting.seal_test",
    "seal_frequency_test": "fitting.seal_test",
    "FRF": "fitting.frf", "estimate_frf": "fitting.frf", "model_frf": "fitting.frf",
    "plant_frf": "fitting.frf",
    "CoprimeFactors": "fitting.coprime", "coprime_factors": "fitting.coprime",
    "YoulaResult": "fitting.youla", "identify_youla": "fitting.youla",
    "OnlineTracker": "tracking", "TrackingResult": "tracking", "TrackingSettings": "tracking",
    "check_excitation": "tracking", "track": "tracking", "tracking_excitation": "tracking",
}

__all__ = sorted(_FROM)

__getattr__, __dir__ = lazy_face(__name__, _FROM)
