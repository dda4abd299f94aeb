"""ambseal.design: the rig's design policy — what its controllers are asked for, and how.

* :func:`design_spec` → :class:`DesignSpec` — the specification built once from the rig and
  its ``[design]`` part, every missing key derived from the machine by a stated rule
  (:mod:`ambseal.design.specs`), from the facts :func:`machine` → :class:`Machine` gives;
* :class:`Weights`, :func:`default_weights` — the performance and uncertainty weights
  (thesis P5 Eq. 7, P3 Eq. 11);
* :func:`generalized_plant`, :func:`physical_controller` — the generalised plant of the
  robust designs (P5 §4.3, Figs. 8–9);
* :func:`design` — the recipes: the reference PID (P5 Eq. 6; :func:`reference_pid`,
  :func:`controller_from_metadata` for the one a record names; :class:`ScheduledPid` where
  its cross gains are scheduled on speed), nominal H∞ and robust μ;
  :func:`full_order_check` — a design closed with the full-order plant, and
  :func:`full_order_words` — its result in a verdict's words; :func:`on_sampled_plant` —
  whether H∞ and μ are synthesised on the sampled plant (``[design] synthesis_plant``);
  :func:`design_rise` — what the removal of fast poles costs a design;
* :class:`Design` — what every design result offers (:class:`DesignResult` and the
  scheduled designs below alike);
* :func:`design_lpv`, :func:`design_frozen` — controllers scheduled on the speed (P3 §4),
  over the speeds :func:`lpv_schedule` gives,
  on the gridded plant of :func:`ambseal.design.lpv_plant.lpv_plant` (not re-exported: it
  shares its module's name) at the speeds of :func:`vertex_grid_hz`;
  :func:`design_seal_scheduled` — scheduled on the tracked seal coefficient (Ch. 7);
* :func:`design_rejection` → :class:`SynchronousRejection` — a controller's unbalance
  force rejection, a generalised notch filter scheduled on speed (Herzog et al. 1996).

The synthesis itself is :mod:`ambseal.robust`'s, which knows nothing of rotors.
"""

from ambseal.design.fast_poles import design_rise
from ambseal.design.lpv_design import design_frozen, design_lpv, lpv_schedule
from ambseal.design.lpv_plant import vertex_grid_hz
from ambseal.design.pid import (
    ScheduledPid,
    controller_from_metadata,
    pid_controller,
    pid_description,
    reference_pid,
)
from ambseal.design.plant import generalized_plant, physical_controller, uncertainty_at
from ambseal.design.recipes import (
    DesignResult,
    design,
    full_order_check,
    full_order_words,
    on_sampled_plant,
)
from ambseal.design.result import Design
from ambseal.design.seal_schedule import design_seal_scheduled
from ambseal.design.specs import (
    RIGID_STATES,
    DesignSpec,
    Machine,
    air_gaps,
    design_spec,
    machine,
)
from ambseal.design.synchronous_rejection import SynchronousRejection, design_rejection
from ambseal.design.weights import Weights, default_weights

__all__ = ["RIGID_STATES", "Design", "DesignResult", "DesignSpec", "Machine", "Weights",
           "ScheduledPid", "air_gaps",
           "controller_from_metadata", "default_weights", "design", "design_frozen",
           "design_lpv", "lpv_schedule", "design_rise", "design_seal_scheduled", "design_spec",
           "full_order_check", "full_order_words", "generalized_plant", "machine",
           "on_sampled_plant",
           "uncertainty_at",
           "physical_controller", "pid_controller", "pid_description", "reference_pid",
           "vertex_grid_hz", "SynchronousRejection", "design_rejection"]
