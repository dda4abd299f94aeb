"""ambseal.control: robust-control core for generalised plants.

Public functions are imported on first use (module-level ``__getattr__``), so
``import ambseal.control`` stays light:

* :func:`hinfsyn`, :func:`hinfnorm`, :func:`lft_lower` — ``control/hinf.py``
* :func:`mussv` — ``control/mu.py``
* :func:`musyn`, :func:`fit_magnitude` — ``control/dk.py``
* :func:`reduce_controller`, :func:`balred_controller` — ``control/order.py``
* :func:`digital_controller`, :class:`DigitalController` — ``control/digital.py`` (the
  controller that runs on the target: fast poles removed, discretisation chosen);
  :func:`scheduled_digital`, :class:`ScheduledDigital` — ``control/scheduled_digital.py``
* :func:`export_controller`, :func:`load_controller` — ``control/export.py``;
  :func:`write_c` — ``control/codegen.py`` (C99 module)
* :func:`pid_controller` — ``control/pid.py``
* :class:`Weights`, :func:`default_weights` — ``control/weights.py`` (the one weight class)
* :func:`generalized_plant`, :func:`physical_controller` — ``control/plant.py``
* :func:`design` — ``control/recipes.py`` (the thesis's PID, H∞ and μ designs of a rig)
* :func:`lpvsyn` — ``control/lpv.py`` (SDPs in ``lpv_lmi.py``, reconstruction in
  ``lpv_reconstruct.py``); :func:`design_lpv`, :func:`design_frozen` —
  ``control/lpv_design.py``
"""

from __future__ import annotations

import importlib

_LAZY = {
    "hinfsyn": "hinf", "hinfnorm": "hinf", "lft_lower": "hinf", "HinfResult": "hinf",
    "mussv": "mu", "MuResult": "mu",
    "musyn": "dk", "MusynResult": "dk", "fit_magnitude": "dk",
    "reduce_controller": "order", "balred_controller": "order", "ReductionResult": "order",
    "export_controller": "export", "load_controller": "export",
    "digital_controller": "digital", "DigitalController": "digital",
    "scheduled_digital": "scheduled_digital", "ScheduledDigital": "scheduled_digital",
    "write_c": "codegen",
    "pid_controller": "pid", "design": "recipes", "DesignResult": "recipes",
    "lpvsyn": "lpv", "design_lpv": "lpv_design", "design_frozen": "lpv_design",
    "Weights": "weights", "default_weights": "weights",
    "generalized_plant": "plant", "physical_controller": "plant",
}

__all__ = sorted(_LAZY)


def __getattr__(name: str):
    mod = _LAZY.get(name)
    if mod is None:
        raise AttributeError(f"module 'ambseal.control' has no attribute {name!r}")
    value = getattr(importlib.import_module(f"ambseal.control.{mod}"), name)
    globals()[name] = value
    return value


def __dir__():
    return sorted(set(globals()) | set(_LAZY))
