"""The controllers a machine runs, and their sign convention.

**Convention** (thesis P5 Fig. 8): a controller that runs on a machine maps its
measurements ``y`` to its actuator commands ``u`` with **negative feedback**, ``u = −K y``;
its inputs are named ``y_<channel>`` and its outputs ``i_<channel>``, the reverse of the
plant's (inputs ``i_<channel>``, outputs ``y_<channel>``). This is not the convention of
the synthesis functions (:func:`~ambseal.robust.hinf.hinfsyn` and the others return
controllers for the lower LFT F_l(P, K), u = K y); the layers that design for a machine
convert one into the other. In ambseal's rotor layers a channel is an AMB actuator axis
(``A_zeta``), ``y`` the displacements (m) and ``u`` the current references ``i`` (A). The
loop closes by name in python-control with the sign written into the connection::

    loop = control.interconnect(
        [G, K], connections=[[f"G.i_{a}", f"-K.i_{a}"] for a in axes]
        + [[f"K.y_{a}", f"G.y_{a}"] for a in axes], outlist=list(G.output_labels))

(with ``G`` and ``K`` given ``name="G"``/``name="K"``, ``axes = plant.axes``).

* A **fixed** controller is a continuous ``control.StateSpace`` with that convention.
* A **scheduled** controller is a :class:`ScheduledController` scheduled on one named
  parameter θ in its own unit: :data:`SPEED` (a rotor speed Ω in rad/s; the LPV controller
  of P3) or any other named parameter (e.g. ``"seal.k"`` in N/m, the controller scheduled
  on a tracked seal coefficient). ``at(θ)`` gives the frozen fixed controller at θ inside
  ``schedule``.

Analyses take either through :func:`frozen` and :func:`matrices_at`.
"""

from __future__ import annotations

from abc import ABC, abstractmethod
from typing import Mapping

import numpy as np

from ambseal.errors import ConfigError, ModelError

__all__ = ["ScheduledController", "frozen", "matrices_at", "controller_as_runs", "SPEED"]

#: The name of the rotor speed as a scheduling parameter (Ω, rad/s).
SPEED = "speed"


class ScheduledController(ABC):
    """A controller scheduled on one parameter θ, ``i = −K(θ) y``.

    ``parameter`` names θ: :data:`SPEED` (the rotor speed Ω, rad/s) or an LFT parameter of
    the rig (``"<element>.<coefficient>"``, SI units); ``schedule`` is the interval
    (θ_min, θ_max) the schedule covers (held at its ends outside it).
    """

    #: The scheduling parameter: "speed" (Ω, rad/s) or an LFT parameter name (SI); set by
    #: every subclass (a class variable for the speed-scheduled ones).
    parameter: str

    @property
    @abstractmethod
    def schedule(self) -> tuple[float, float]:
        """(θ_min, θ_max), the values of ``parameter`` (SI) the schedule covers."""

    @abstractmethod
    def matrices_at(self, value: float) -> tuple[np.ndarray, ...]:
        """Physical ``(A_K, B_K, C_K, D_K)`` at θ = ``value`` (SI),
        ``i = −(C_K x_K + D_K y)``."""

    @abstractmethod
    def at(self, value: float, name: str = "K"):
        """The frozen controller at θ = ``value`` (SI): a ``control.StateSpace``, m → A,
        named signals, ``i = −K y``."""

    def theta_at(self, speed_rad_s: float | None = None,
                 values: Mapping[str, float] | None = None) -> float:
        """θ at a condition: the speed Ω for a speed-scheduled controller, else the
        condition's value of ``parameter``.

        Parameters
        ----------
        speed_rad_s : float, optional
            The rotor speed Ω (rad/s).
        values : mapping of str to float, optional
            ``{parameter: value}`` (SI) at the condition, e.g.
            :func:`ambseal.model.seal.seal_values` at the pressure drop.

        Returns
        -------
        float
            θ (rad/s for the speed, else SI).

        Raises
        ------
        ModelError
            The condition does not give the parameter's value.
        """
        if self.parameter == SPEED and speed_rad_s is not None:
            return float(speed_rad_s)
        if values is not None and self.parameter in values:
            return float(values[self.parameter])
        raise ModelError(f"a controller scheduled on {self.parameter!r} needs its value at "
                         "the condition (values={...})")


def frozen(K, speed_rad_s: float | None = None, values: Mapping[str, float] | None = None):
    """The fixed controller that runs at a condition: ``K`` itself, or a scheduled one
    frozen at the condition's value of its parameter.

    Parameters
    ----------
    K : control.StateSpace or ScheduledController
        The controller, displacements (m) → currents (A), ``i = −K y``.
    speed_rad_s : float, optional
        The rotor speed Ω (rad/s): θ of a speed-scheduled controller.
    values : mapping, optional
        ``{parameter: value}`` (SI): θ of a controller scheduled on another parameter.

    Returns
    -------
    control.StateSpace

    Raises
    ------
    ModelError
        A scheduled controller whose parameter has no value given.
    """
    if isinstance(K, ScheduledController):
        return K.at(K.theta_at(speed_rad_s, values))
    return K


def matrices_at(K, speed_rad_s: float | None = None,
                values: Mapping[str, float] | None = None) -> tuple[np.ndarray, ...]:
    """Physical ``(A_K, B_K, C_K, D_K)`` of a fixed or scheduled controller at a condition.

    Parameters
    ----------
    K : control.StateSpace or ScheduledController
        The controller, displacements (m) → currents (A), ``i = −K y``.
    speed_rad_s : float, optional
        The rotor speed Ω (rad/s): θ of a speed-scheduled controller.
    values : mapping, optional
        ``{parameter: value}`` (SI): θ of a controller scheduled on another parameter.

    Returns
    -------
    tuple of ndarray
        ``(A_K, B_K, C_K, D_K)`` as float arrays, shapes ``(n_K, n_K)``, ``(n_K, p)``,
        ``(m, n_K)``, ``(m, p)`` for ``p`` displacements and ``m`` currents.

    Raises
    ------
    ModelError
        A scheduled controller whose parameter has no value given.
    """
    if isinstance(K, ScheduledController):
        return K.matrices_at(K.theta_at(speed_rad_s, values))
    return tuple(np.asarray(M, float) for M in (K.A, K.B, K.C, K.D))


def controller_as_runs(controller, speed_rad_s: float,
                       values: Mapping[str, float] | None = None):
    """The controller as it runs at a condition: a discrete ``control.StateSpace`` with
    its computation delay (a scheduled table at the condition's value of its parameter).

    Parameters
    ----------
    controller : DigitalController or ScheduledDigital
        A digital controller (``statespace(delayed=True)``) or a scheduled table
        (``statespace_at``, on the speed or on ``controller.parameter``).
    speed_rad_s : float
        The speed (rad/s): θ of a table scheduled on speed.
    values : mapping, optional
        ``{parameter: value}`` (SI) at the condition, e.g.
        :func:`ambseal.model.seal.seal_values`: θ of a table scheduled on a seal
        coefficient.

    Returns
    -------
    control.StateSpace
        Discrete, its delay among its states.

    Raises
    ------
    ConfigError
        A controller that is not a digital one as it runs.
    ModelError
        A table scheduled on a parameter ``values`` does not give.
    """
    if hasattr(controller, "statespace_at"):
        return controller.statespace_at(controller.theta_at(speed_rad_s, values),
                                        delayed=True)
    if hasattr(controller, "statespace") and hasattr(controller, "discrete"):
        return controller.statespace(delayed=True)
    raise ConfigError("the sign-off judges a digital controller as it runs (a "
                      "DigitalController or a scheduled table, e.g. an exported file of "
                      "ambseal design); a continuous controller is not judged here")
