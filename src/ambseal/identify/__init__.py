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
  seal forces (Ch. 7 §7.4).

The names load on first use (PEP 562 ``__getattr__``, the lazy loading of scientific
Python's SPEC 1), because importing any module of this package runs this file first and
:mod:`ambseal.identify.signals` and :mod:`ambseal.identify.measurement` are light on
purpose: they load neither python-control nor scipy nor cvxopt
(``tests/identify/test_identify_signals.py``), which an eager face would, with the fit.
"""

import importlib

#: Each public name (``__all__``) and the module that defines it.
_FROM = {
    "Excitation": "signals", "chirp": "signals", "impulse": "signals", "prbs": "signals",
    "stepped_sine": "signals",
    "Measurement": "measurement", "validate_measurement": "measurement",
    "load_measurement": "data", "save_measurement": "data",
    "FacilityRecord": "rig_sim", "prepare_facility": "rig_sim",
    "simulate_facility": "rig_sim",
    "acquire": "stages", "identify": "stages",
    "FitResult": "fit", "fit_parameters": "fit",
    "ResidualTests": "residuals", "residual_tests": "residuals",
    "uncertainty_from_fit": "intervals",
    "ProcedureResult": "procedure", "thesis_procedure": "procedure",
    "StaticLoadResult": "static_load", "static_ki": "static_load",
    "seal_frequency_test": "seal_test",
    "FRF": "frf", "estimate_frf": "frf", "model_frf": "frf", "plant_frf": "frf",
    "CoprimeFactors": "coprime", "coprime_factors": "coprime",
    "YoulaResult": "youla", "identify_youla": "youla",
    "OnlineTracker": "tracking", "TrackingResult": "tracking",
    "TrackingSettings": "tracking", "track": "tracking",
}

__all__ = ["CoprimeFactors", "Excitation", "FRF", "FacilityRecord", "FitResult", "Measurement",
           "OnlineTracker", "ProcedureResult", "ResidualTests", "StaticLoadResult",
           "TrackingResult", "TrackingSettings", "YoulaResult", "acquire", "chirp",
           "coprime_factors", "estimate_frf", "fit_parameters", "identify", "identify_youla",
           "impulse", "load_measurement", "model_frf", "plant_frf", "prbs", "prepare_facility",
           "residual_tests", "save_measurement", "seal_frequency_test", "simulate_facility",
           "static_ki", "stepped_sine", "thesis_procedure", "track", "uncertainty_from_fit",
           "validate_measurement"]


def __getattr__(name: str):
    """Import a public name from its module on first use (PEP 562)."""
    if name not in _FROM:
        raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
    value = getattr(importlib.import_module(f"{__name__}.{_FROM[name]}"), name)
    globals()[name] = value
    return value


def __dir__() -> list[str]:
    """The module's names, the lazily loaded ones included."""
    return sorted(set(globals()) | set(__all__))
