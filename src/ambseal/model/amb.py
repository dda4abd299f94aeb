"""Active magnetic bearings: actuator axes, linearised force law and actuator dynamics.

Force per actuator axis (thesis P2 Eq. 1, P5 Eq. 1): f = Ki·i + Ks·s, with Ks > 0 the
destabilising (negative) bearing stiffness. The actuator axes ζ, η are x, y rotated by
``axes_angle_deg`` about z (45° on the thesis test facility, P2 Fig. 1b):
[ζ, η]ᵀ = R [x, y]ᵀ, R = [[cos φ, sin φ], [−sin φ, cos φ]].
"""

from __future__ import annotations

import math

import numpy as np

from ..config import Actuator

__all__ = ["axes_rotation", "actuator_matrices", "eddy_lag_matrices", "channel_names", "AXES"]


def axes_rotation(angle_deg: float) -> np.ndarray:
    """R (2, 2) with [ζ, η]ᵀ = R [x, y]ᵀ for axes rotated by ``angle_deg`` from x, y."""
    c, s = math.cos(math.radians(angle_deg)), math.sin(math.radians(angle_deg))
    return np.array([[c, s], [-s, c]])


def actuator_matrices(act: Actuator) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """State-space (A, B, C, D) of one actuator axis: current reference → coil current.

    - ``none``: a unit gain (no states).
    - ``first_order``: ω_c/(s + ω_c), ω_c = 2π·cutoff_hz (thesis P3 Eq. 2).
    - ``second_order``: ω_n²/(s² + 2ζω_n s + ω_n²) (thesis P4 Eq. 2, P5 Eq. 2; the printed
      equation drops the 2 and a square, the standard form is meant: ω_n = 1360 rad/s,
      ζ = 0.9 give the 216 Hz, well-damped amplifier the papers describe).

    Returns arrays of shapes (n, n), (n, 1), (1, n), (1, 1) with unit DC gain.
    """
    if act.model == "none":
        return np.zeros((0, 0)), np.zeros((0, 1)), np.zeros((1, 0)), np.ones((1, 1))
    if act.model == "first_order":
        wc = 2 * math.pi * act.cutoff_hz
        return np.array([[-wc]]), np.array([[wc]]), np.array([[1.0]]), np.zeros((1, 1))
    wn, z = act.natural_frequency, act.damping_ratio
    A = np.array([[0.0, 1.0], [-(wn**2), -2 * z * wn]])
    return A, np.array([[0.0], [wn**2]]), np.array([[1.0, 0.0]]), np.zeros((1, 1))


def eddy_lag_matrices(tau_e: float) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """(A, B, C, D) of the eddy-current lag 1/(τ_e s + 1) between coil current and force
    (thesis P2 §4, Fig. 2, "unknown actuator dynamics"); a unit gain for τ_e = 0."""
    if tau_e <= 0:
        return np.zeros((0, 0)), np.zeros((0, 1)), np.zeros((1, 0)), np.ones((1, 1))
    return np.array([[-1.0 / tau_e]]), np.array([[1.0 / tau_e]]), np.ones((1, 1)), np.zeros((1, 1))


#: The two actuator axes of every AMB (ζ, η: x, y rotated by ``axes_angle_deg``).
AXES = ("zeta", "eta")


def channel_names(cfg) -> tuple[str, ...]:
    """The AMB channels of a rig in the model's order, ``<amb>_zeta``, ``<amb>_eta`` per AMB
    (the plant's current inputs and displacement outputs; e.g. ``A_zeta … B_eta``)."""
    return tuple(f"{a.name}_{x}" for a in cfg.amb for x in AXES)
