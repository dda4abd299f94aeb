"""The controller types of ambseal and their one sign convention.

**Convention** (thesis P5 Fig. 8, stated here once): a controller maps the sensor
displacements ``y`` (m) to the current references ``i`` (A) with **negative feedback**,
``i = −K y``; its inputs are named ``y_<axis>`` and its outputs ``i_<axis>``
(``<axis>`` an AMB actuator axis such as ``A_zeta``), the reverse of the plant's
(:class:`ambseal.model.lft.Plant`: inputs ``i_<axis>``, outputs ``y_<axis>``). The loop
closes by name in python-control with the sign written into the connection::

    loop = control.interconnect(
        [G, K], connections=[[f"G.i_{a}", f"-K.i_{a}"] for a in axes]
        + [[f"K.y_{a}", f"G.y_{a}"] for a in axes], outlist=list(G.output_labels))

(with ``G`` and ``K`` given ``name="G"``/``name="K"``, ``axes = plant.axes``).

* A **fixed** controller is a continuous ``control.StateSpace`` with that convention.
* A **scheduled** controller (the LPV controller of P3, and later others) is a
  :class:`ScheduledController`: ``at(speed_rad_s)`` gives the frozen fixed controller at a
  rotor speed inside ``schedule_rad_s``.

Analyses take either through :func:`frozen` and :func:`matrices_at`.
"""

from __future__ import annotations

from abc import ABC, abstractmethod

import numpy as np

__all__ = ["ScheduledController", "frozen", "matrices_at"]


class ScheduledController(ABC):
    """A controller scheduled on the rotor speed Ω (rad/s), ``i = −K(Ω) y``."""

    #: (Ω_min, Ω_max), the speeds (rad/s) the schedule covers.
    schedule_rad_s: tuple[float, float]

    @abstractmethod
    def matrices_at(self, speed_rad_s: float) -> tuple[np.ndarray, ...]:
        """Physical ``(A_K, B_K, C_K, D_K)`` at Ω (rad/s), ``i = −(C_K x_K + D_K y)``."""

    @abstractmethod
    def at(self, speed_rad_s: float, name: str = "K"):
        """The frozen controller at Ω (rad/s): a ``control.StateSpace``, m → A, named
        signals, ``i = −K y``."""


def frozen(K, speed_rad_s: float):
    """The fixed controller that runs at Ω (rad/s): ``K`` itself, or a scheduled one frozen.

    Parameters
    ----------
    K : control.StateSpace or ScheduledController
    speed_rad_s : float

    Returns
    -------
    control.StateSpace
    """
    return K.at(speed_rad_s) if isinstance(K, ScheduledController) else K


def matrices_at(K, speed_rad_s: float) -> tuple[np.ndarray, ...]:
    """Physical ``(A_K, B_K, C_K, D_K)`` of a fixed or scheduled controller at Ω (rad/s)."""
    if isinstance(K, ScheduledController):
        return K.matrices_at(speed_rad_s)
    return tuple(np.asarray(M, float) for M in (K.A, K.B, K.C, K.D))
