"""The drop's event and its settings, one object: what lands the rotor, at what speed,
from which state, and how long and how finely the drop is integrated (the package's
docstring, :mod:`ambseal.analysis.drop`)."""

from __future__ import annotations

import math
from dataclasses import dataclass

from ambseal.errors import ConfigError


@dataclass(frozen=True)
class DropEvent:
    """A drop's event and settings (:func:`ambseal.analysis.drop.simulate_drop` names
    each the same).

    Attributes
    ----------
    speed_rpm : float
        Spin speed (rpm) at the drop: held by the drive, or the start of a coast-down;
        negative, the rotor turns the other way (about −z).
    duration_s : float
        Simulated time after the AMBs let go (s), > 0.
    samples : int
        Output samples, evenly spaced over the drop, ≥ 2.
    modes_hz : float or None
        Modes kept (:func:`~ambseal.analysis.drop.drop_model`).
    rtol : float
        ``solve_ivp``'s relative tolerance.
    method : str
        ``solve_ivp``'s method (an explicit one gives way to the stiff one where it
        crawls).
    coast_down : bool
        The drive lets go too: the spin slows under the rings' friction and
        ``drag_torque`` (N·m, ≥ 0).
    drag_torque : float
    initial : tuple of two ndarray or None
        The rotor's nodal displacement and velocity when the AMBs let go.
    unbalance_kgm : float
        A static unbalance (kg·m, ≥ 0) at the node nearest the centre of mass.
    loop_state : ndarray or None
        The AMB loop's states at t = 0.
    failed : tuple of str or None
        The AMB channels whose power is lost at t = 0 (None: every one).
    overload : tuple (float, array_like of 2 float) or None
        A step force from t = 0: its position z (m) and its x, y components (N).
    supports : bool
        The seals' and springs' forces on the rotor.
    pressure_bar : float or None
        The seals' pressure drop (bar); the rig's if None.
    axial_thrust : float or None
        The residual thrust (N, +z) once the thrust bearing lets go; the rig's
        ``[drop] axial_thrust`` if None.
    """

    speed_rpm: float = 0.0
    duration_s: float = 0.5
    samples: int = 4001
    modes_hz: float | None = None
    rtol: float = 1e-8
    method: str = "DOP853"
    coast_down: bool = False
    drag_torque: float = 0.0
    initial: tuple | None = None
    unbalance_kgm: float = 0.0
    loop_state: object = None
    failed: tuple | None = None
    overload: tuple | None = None
    supports: bool = True
    pressure_bar: float | None = None
    axial_thrust: float | None = None

    def __post_init__(self):
        if not (self.duration_s > 0 and math.isfinite(self.duration_s)):
            raise ConfigError(f"drop: duration: expected > 0 s, got {self.duration_s!r}")
        if not self.samples >= 2:
            raise ConfigError(f"drop: samples: expected at least 2, got {self.samples!r}")
        if not (self.drag_torque >= 0 and math.isfinite(self.drag_torque)):
            raise ConfigError(f"drop: drag torque: expected >= 0 N·m, got "
                              f"{self.drag_torque!r}")
        if not (self.unbalance_kgm >= 0 and math.isfinite(self.unbalance_kgm)):
            raise ConfigError(f"drop: unbalance: expected >= 0 kg·m, got "
                              f"{self.unbalance_kgm!r}")

    @property
    def speed_rad_s(self) -> float:
        """The spin speed at the drop (rad/s)."""
        return 2 * math.pi * self.speed_rpm / 60.0
