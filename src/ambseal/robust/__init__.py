"""ambseal.robust: robust-control synthesis and analysis for any python-control plant.

Nothing here knows the machine it is used on: every function takes and returns
``control.StateSpace`` (or plain matrices) with python-control's signal names, so a control
engineer can use it on a distillation column as well as on an aircraft or a compressor.

Synthesis (each returns the controller, the closed loop, the bound and a result record):

* :func:`hinfsyn` — H∞ synthesis of a generalised plant ``P(nmeas, ncon)``;
  :func:`hinfnorm` the H∞ norm;
* :func:`musyn` — μ-synthesis by complex D–K iteration; :func:`musyn_dgk` — by D–G–K
  iteration for mixed real/complex uncertainty;
* :func:`lpvsyn` — gridded H∞ LPV synthesis by LMIs (CVXOPT, structured);
* :func:`reduce_controller`, :func:`balred_controller` — order reduction with its cost.

Analysis: :func:`mussv` — μ upper and lower bounds for mixed real/complex block structures.

The controller that runs on a target: :func:`digital_controller` (fast poles removed, the
discretisation chosen by the sampled loop), :class:`DiscreteController` and the
sample-and-hold delay a synthesis model carries (:func:`design_delay`). Its steps, for a
caller that discretises a family of controllers (a scheduled one): :func:`check_rate`,
:func:`split_fast`, :func:`hold_keeps`, :func:`residualize`, :func:`discretize_as`,
:func:`with_delay`, :func:`prewarp_frequency_hz`, :func:`sampled_plants`,
:func:`choose_method`, :func:`chosen_error`, :func:`peak_difference` and their constants;
:func:`closed_loop_matrices` — the sampled loop as it runs.

The one stability rule: :func:`is_stable`, :func:`unstable_poles`, :func:`decay_rate`.

Sign conventions. The synthesis functions and :func:`lft_lower` work on the lower LFT
``F_l(P, K)``: their controllers close ``u = K y`` (positive feedback), as python-control's
``hinfsyn`` and MATLAB's ``lft`` do. The controllers that run on a target —
:class:`DigitalController`, :class:`DiscreteController` — map measurements to actuator
commands with negative feedback, ``u = −K y``; the caller converts one into the other
(the layer that knows which signals are measurements and which are commands).
"""

from ambseal.robust.delay import DesignDelay, design_delay, loop_delay
from ambseal.robust.dgk import musyn_dgk
from ambseal.robust.digital import (
    DISCRETISATIONS,
    FAST_FRACTION,
    HOLDS,
    KEPT,
    PEAK_TOLERANCE,
    DigitalController,
    check_rate,
    choose_method,
    chosen_error,
    digital_controller,
    discretize_as,
    hold_keeps,
    peak_difference,
    prewarp_frequency_hz,
    residualize,
    sampled_plants,
    split_fast,
    with_delay,
)
from ambseal.robust.digital_loop import (
    DiscreteController,
    closed_loop_matrices,
    discrete_controller,
)
from ambseal.robust.dk import MusynResult, design_omega, fit_magnitude, musyn
from ambseal.robust.hinf import HinfResult, hinfnorm, hinfsyn, lft_lower
from ambseal.robust.lpv import LpvController, LpvSynResult, lpvsyn
from ambseal.robust.mu import MuResult, mussv
from ambseal.robust.order import ReductionResult, balred_controller, reduce_controller
from ambseal.robust.stability import decay_rate, is_stable, unstable_poles

__all__ = ["DISCRETISATIONS", "FAST_FRACTION", "HOLDS", "KEPT", "PEAK_TOLERANCE",
           "DesignDelay", "DigitalController", "DiscreteController", "HinfResult",
           "LpvController", "LpvSynResult", "MuResult", "MusynResult", "ReductionResult",
           "balred_controller", "check_rate", "choose_method",
           "chosen_error", "closed_loop_matrices", "decay_rate", "design_delay",
           "design_omega", "digital_controller", "discrete_controller", "discretize_as",
           "fit_magnitude", "hinfnorm", "hinfsyn", "hold_keeps", "is_stable", "lft_lower",
           "loop_delay", "lpvsyn", "musyn", "musyn_dgk", "mussv", "peak_difference",
           "prewarp_frequency_hz", "reduce_controller", "residualize", "sampled_plants",
           "split_fast", "unstable_poles", "with_delay"]
