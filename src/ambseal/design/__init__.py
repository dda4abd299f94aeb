"""ambseal.design: the rig's design policy — what its controllers are asked for, and how.

* :func:`design_spec` → :class:`DesignSpec` — the specification built once from the rig and
  its ``[design]`` part, every missing key derived from the machine by a stated rule
  (:mod:`ambseal.design.specs`);
* :class:`Weights`, :func:`default_weights` — the performance and uncertainty weights
  (thesis P5 Eq. 7, P3 Eq. 11);
* :func:`generalized_plant`, :func:`physical_controller` — the generalised plant of the
  robust designs (P5 §4.3, Figs. 8–9);
* :func:`design` — the recipes: the reference PID (P5 Eq. 6), nominal H∞ and robust μ;
* :class:`Design` — what every design result offers (:class:`DesignResult` and the
  scheduled designs below alike);
* :func:`design_lpv`, :func:`design_frozen` — controllers scheduled on the speed (P3 §4);
  :func:`design_seal_scheduled` — scheduled on the tracked seal coefficient (Ch. 7).

The synthesis itself is :mod:`ambseal.robust`'s, which knows nothing of rotors.
"""

from ambseal.design.lpv_design import design_frozen, design_lpv
from ambseal.design.pid import pid_controller
from ambseal.design.plant import generalized_plant, physical_controller
from ambseal.design.recipes import DesignResult, design
from ambseal.design.result import Design
from ambseal.design.seal_schedule import design_seal_scheduled
from ambseal.design.specs import DesignSpec, design_spec
from ambseal.design.weights import Weights, default_weights

__all__ = ["Design", "DesignResult", "DesignSpec", "Weights", "default_weights", "design",
           "design_frozen", "design_lpv", "design_seal_scheduled", "design_spec",
           "generalized_plant", "physical_controller", "pid_controller"]
