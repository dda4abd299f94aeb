"""Where gravity acts on the rotor: the machine's orientation as a vector and as a load.

The rig's ``[machine] orientation`` places the rotor axis z in the earth's frame, the y axis
in the vertical plane through it (:class:`ambseal.config.Machine`):

* ``"horizontal"``: gravity along −y, ``g = (0, −g₀, 0)``;
* ``"vertical"``: along −z, ``g = (0, 0, −g₀)`` — the left end, where positions start,
  at the bottom;
* ``"inclined"`` at θ = ``inclination_deg`` above the horizontal (+z rising):
  ``g = g₀ (0, −cos θ, −sin θ)``; 0° is horizontal, 90° vertical.

g₀ is standard gravity (ISO 80000-3, ``scipy.constants.g``). The lateral model (DOFs
``[x, y, α, β]`` per node) takes the lateral part as a load ``F = M t`` with ``t`` the
rigid translation by (g_x, g_y) at every rotor node (:func:`gravity_load`: the consistent
load of a uniform acceleration, shaft and disks alike; a housing's own weight goes
straight to its support, not through the rotor). The axial part ``m g_z`` has no DOF in the
lateral model: an axial bearing carries it (:func:`axial_weight`).
"""

from __future__ import annotations

import math

import numpy as np
from scipy.constants import g as STANDARD_GRAVITY  # m/s², ISO 80000-3

from ambseal.config import Machine
from ambseal.model.rotor import X, Y

__all__ = ["STANDARD_GRAVITY", "inclination", "gravity_vector", "gravity_load",
           "axial_weight"]

#: Each named orientation's inclination of the rotor axis above the horizontal (deg).
_INCLINATION_DEG = {"horizontal": 0.0, "vertical": 90.0}


def inclination(machine: Machine) -> float:
    """The rotor axis's angle above the horizontal (deg): 0 horizontal, 90 vertical, the
    rig's ``inclination_deg`` when inclined.

    Parameters
    ----------
    machine : Machine
        The rig file's ``[machine]``.

    Returns
    -------
    float
        θ in degrees, −90 to 90 (+z rising).
    """
    if machine.orientation == "inclined":
        return float(machine.inclination_deg)
    return _INCLINATION_DEG[machine.orientation]


def gravity_vector(machine: Machine) -> np.ndarray:
    """Gravity in the rotor's frame (x, y, z), m/s² (module docstring).

    Parameters
    ----------
    machine : Machine
        The rig file's ``[machine]``.

    Returns
    -------
    ndarray, shape (3,)
        ``g₀ (0, −cos θ, −sin θ)``; exactly ``(0, −g₀, 0)`` horizontal and ``(0, 0, −g₀)``
        vertical (no rounding of cos 90°).
    """
    if machine.orientation == "horizontal":
        return np.array([0.0, -STANDARD_GRAVITY, 0.0])
    if machine.orientation == "vertical":
        return np.array([0.0, 0.0, -STANDARD_GRAVITY])
    t = math.radians(inclination(machine))
    return STANDARD_GRAVITY * np.array([0.0, -math.cos(t), -math.sin(t)])


def gravity_load(M: np.ndarray, n_rotor_dof: int, g_xyz) -> np.ndarray:
    """The lateral load of gravity on the model's DOFs: ``F = M t`` (N), ``t`` the rigid
    translation by the lateral part (g_x, g_y) at every rotor node.

    Parameters
    ----------
    M : ndarray, shape (n, n)
        The model's mass matrix (the rotor's DOFs first, as
        :class:`~ambseal.model.SecondOrderSystem` orders them).
    n_rotor_dof : int
        The rotor's DOFs (``mesh.n_dof``); those after it (housings) get no load.
    g_xyz : array_like, shape (3,)
        Gravity in the rotor's frame (m/s², :func:`gravity_vector`); its z part has no DOF
        here (:func:`axial_weight`).

    Returns
    -------
    ndarray, shape (n,)
        The load vector (N at translations, N·m at rotations: a disk's offset centre of
        mass is not modelled, so a uniform translation puts none there).
    """
    t = np.zeros(M.shape[0])
    t[X:n_rotor_dof:4] = g_xyz[0]
    t[Y:n_rotor_dof:4] = g_xyz[1]
    return M @ t


def axial_weight(mass_kg: float, g_xyz) -> float:
    """The rotor's weight along its axis, ``m g_z`` (N; negative towards the left end),
    which the lateral model cannot carry: a thrust bearing or an axial AMB does.

    Parameters
    ----------
    mass_kg : float
        The rotor's mass (kg).
    g_xyz : array_like, shape (3,)
        Gravity in the rotor's frame (m/s², :func:`gravity_vector`).

    Returns
    -------
    float
        The axial force of gravity on the rotor (N, +z positive).
    """
    return float(mass_kg * g_xyz[2])
