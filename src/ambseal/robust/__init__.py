"""ambseal.robust: robust-control synthesis and analysis for any python-control plant.

Nothing here knows the machine it is used on: every function takes and returns
``control.StateSpace`` (or plain matrices) with python-control's signal names, so a control
engineer can use it on a distillation column as well as on an aircraft or a compressor.

Synthesis (each returns the controller, the closed loop, the bound and a result record):

* :func:`hinfsyn` — H∞ synthesis of a generalised plant ``P(nmeas, ncon)``;
  :func:`hinfnorm` the H∞ norm;
* :func:`musyn` — μ-synthesis by complex D–K iteration; :func:`musyn_dgk` — by D–G–K
  iteration for mixed real/complex uncertainty;
* :func:`lpvsyn` — gridded H∞ LPV synthesis by LMIs (CVXOPT, structured); the status each
  of its SDP stages ended on, :func:`sdp_status`, and any short of optimal in words,
  :func:`sdp_shortfall`;
* :func:`hinf_scheduled` — central H∞ controllers of a table of frozen plants at one γ,
  in their common state basis, as a controller scheduled on the table's parameter;
* :func:`performance_level` — the largest level of the performance weights at which a
  scaled-H∞ bound certifies the uncertainty (a wide interval of a real parameter), and
  :func:`scaled_performance` the plant at that level;
* :func:`reduce_controller`, :func:`balred_controller` — order reduction with its cost.

Analysis: :func:`mussv` — μ upper and lower bounds for mixed real/complex block structures.

The controller that runs on a target: :func:`digital_controller` (fast poles removed, the
discretisation chosen by the sampled loop), :class:`DiscreteController` and the
sample-and-hold delay a synthesis model carries (:func:`design_delay`; the timing's
bounds: :func:`check_timing`, :data:`MAX_DELAY_SAMPLES`). Its steps, for a caller that
discretises a family of controllers (a scheduled one): :func:`check_rate`,
:func:`split_fast`, :func:`hold_keeps`, :func:`residualize`, :func:`discretize_as`,
:func:`with_delay`, :func:`prewarp_frequency_hz`, :func:`sampled_plants`,
:func:`choose_method`, :func:`chosen_error`, :func:`peak_difference` and their constants;
:func:`closed_loop_matrices` — the sampled loop as it runs. A synthesis on the sampled,
delayed plant itself: :func:`w_plane_plant`, the plant's w-plane image, whose controller's
Tustin transform is the discrete design.

The one stability rule: :func:`is_stable`, :func:`unstable_poles`, :func:`decay_rate`.

Sign conventions. The synthesis functions and :func:`lft_lower` work on the lower LFT
``F_l(P, K)``: their controllers close ``u = K y`` (positive feedback), as python-control's
``hinfsyn`` and MATLAB's ``lft`` do. The controllers that run on a target —
:class:`DigitalController`, :class:`DiscreteController` — map measurements to actuator
commands with negative feedback, ``u = −K y``; the caller converts one into the other
(the layer that knows which signals are measurements and which are commands).

Each name loads its module on first use (PEP 562 ``__getattr__``,
:func:`ambseal.lazy.lazy_face`): the stability rule needs neither python-control nor the
SDP solver.
"""

from ambseal.lazy import lazy_face

#: Each public name (``__all__``) and the module that defines it.
_FROM = {
    "design_delay": "delay", "loop_delay": "delay", "DesignDelay": "delay",
    "musyn_dgk": "dgk", "check_rate": "digital", "choose_method": "digital",
    "chosen_error": "digital", "digital_controller": "digital", "discretize_as": "digital",
    "hold_keeps": "digital", "peak_difference": "digital",
    "prewarp_frequency_hz": "digital", "residualize": "digital",
    "sampled_plants": "digital", "split_fast": "digital", "with_delay": "digital",
    "DISCRETISATIONS": "digital", "DigitalController": "digital",
    "FAST_FRACTION": "digital", "HOLDS": "digital", "KEPT": "digital",
    "PEAK_TOLERANCE": "digital", "closed_loop_matrices": "digital_loop",
    "discrete_controller": "digital_loop", "DiscreteController": "digital_loop",
    "design_omega": "dk", "fit_magnitude": "dk", "musyn": "dk", "MusynResult": "dk",
    "dscaled_plant": "dk", "result_scalings": "dk",
    "scaled_hinfsyn": "dk", "ScaledHinfResult": "dk",
    "hinfnorm": "hinf", "hinfsyn": "hinf", "lft_lower": "hinf", "HinfResult": "hinf",
    "performance_level": "level", "scaled_performance": "level", "LevelResult": "level",
    "LEVEL_FLOOR": "level", "LEVEL_RTOL": "level",
    "lpvsyn": "lpv", "LpvController": "lpv", "LpvSynResult": "lpv", "sdp_status": "lpv",
    "sdp_shortfall": "lpv", "mussv": "mu", "mu_peak": "mu", "MuPeak": "mu",
    "MuResult": "mu", "balred_controller": "order", "reduce_controller": "order",
    "ReductionResult": "order", "decay_rate": "stability", "is_stable": "stability",
    "unstable_poles": "stability", "MAX_DELAY_SAMPLES": "timing", "check_timing": "timing",
    "w_plane_plant": "w_plane", "hinf_scheduled": "scheduled_hinf",
    "ScheduledHinfResult": "scheduled_hinf",
}

__all__ = sorted(_FROM)

__getattr__, __dir__ = lazy_face(__name__, _FROM)
