"""Active magnetic bearings: the AMB element, its linearisation and actuator dynamics.

Force per actuator axis (thesis P2 Eq. 1, P5 Eq. 1): f = Ki·i + Ks·s, with Ks > 0 the
destabilising (negative) bearing stiffness. The actuator axes ζ, η are x, y rotated by
``axes_angle_deg`` about z (45° on the thesis test facility, P2 Fig. 1b):
[ζ, η]ᵀ = R [x, y]ᵀ, R = [[cos φ, sin φ], [−sin φ, cos φ]].

So an AMB adds −Rᵀ diag(Ks) R to K at its bearing node, the input columns Rᵀ diag(Ki)
(one per axis, current in A) and the sensor rows R [x, y] at its sensor node (m). Its
signals are ``{name}_{axis}`` (:func:`channel_names`), its parameters
``{name}.Ks_{axis}`` and ``{name}.Ki_{axis}``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ambseal.config import Actuator, Amb, AxisPair, RigConfig
from ambseal.model.lft import Channel
from ambseal.model.rotor import Mesh, X, Y

__all__ = ["AXES", "MU0", "axes_rotation", "axis_label", "channel_names", "bias_currents", "bias_current",
           "amb_factors_from_geometry",
           "amb_factors", "AmbElement", "actuator_matrices", "eddy_lag_matrices"]

AXES = ("zeta", "eta")
"""The actuator axes ζ, η of every AMB, in channel order."""

MU0 = 4e-7 * math.pi
"""Vacuum permeability (H/m) as used in the AMB linearisation."""


def axes_rotation(angle_deg: float) -> np.ndarray:
    """R (2, 2) with [ζ, η]ᵀ = R [x, y]ᵀ for axes rotated by ``angle_deg`` from x, y.

    Parameters
    ----------
    angle_deg : float
        Rotation of the axes about z (deg), positive from x towards y.

    Returns
    -------
    ndarray, shape (2, 2)
        R = [[cos φ, sin φ], [−sin φ, cos φ]].
    """
    c, s = math.cos(math.radians(angle_deg)), math.sin(math.radians(angle_deg))
    return np.array([[c, s], [-s, c]])


def axis_label(axis: str) -> str:
    """An actuator axis as people write it: ``"A_zeta"`` → ``"A ζ"``.

    Parameters
    ----------
    axis : str
        ``{amb}_zeta`` or ``{amb}_eta`` (:func:`channel_names`).

    Returns
    -------
    str
    """
    return axis.replace("_zeta", " ζ").replace("_eta", " η")


def channel_names(cfg: RigConfig) -> tuple[str, ...]:
    """Names ``{amb}_{axis}`` of the AMB actuator axes (current inputs ``i_<axis>`` and sensor
    outputs ``y_<axis>`` of the plant), in the order of the plant's channels: every AMB of
    the rig file, ζ then η; e.g. ``("A_zeta", "A_eta", "B_zeta", "B_eta")`` for the thesis
    test facility.

    Parameters
    ----------
    cfg : RigConfig
        The rig; its AMBs in file order.

    Returns
    -------
    tuple of str
        Two names per AMB.
    """
    return tuple(f"{a.name}_{axis}" for a in cfg.amb for axis in AXES)


def bias_currents(cfg: RigConfig) -> list[float | None]:
    """Each AMB's bias current i0 (A): its ``bias_current``, else half its
    ``current_limit`` (a coil current i0 ± i_c within [0, limit] then swings the control
    current i_c furthest both ways), else None.

    Parameters
    ----------
    cfg : RigConfig
        The rig; its AMBs in file order.

    Returns
    -------
    list of float or None
        One per AMB, in file order.
    """
    return [a.bias_current or (a.current_limit / 2 if a.current_limit else None)
            for a in cfg.amb]


def bias_current(cfg: RigConfig) -> float | None:
    """The rig's bias current i0 (A): the smallest of :func:`bias_currents`, or None when
    an AMB gives neither a bias current nor a current limit (or the rig has no AMB). The
    design's scalings and the excitation amplitudes scale with it (thesis test rig: 6 A).

    Parameters
    ----------
    cfg : RigConfig
        The rig.

    Returns
    -------
    float or None
    """
    biases = bias_currents(cfg)
    return min(biases) if biases and None not in biases else None


def amb_factors_from_geometry(
    turns: float, pole_area: float, air_gap: float, bias_current: float, pole_angle_deg: float
) -> tuple[float, float]:
    """Force/current and force/displacement factors of a differentially driven AMB axis.

    Parameters
    ----------
    turns : float
        Turns N per pole coil.
    pole_area : float
        Pole face area A (m²).
    air_gap : float
        Nominal air gap s0 (m).
    bias_current : float
        Bias current i0 (A).
    pole_angle_deg : float
        Angle α between a pole and the actuator axis (deg); 22.5° in an 8-pole bearing.

    Returns
    -------
    ki, ks : float
        Ki = μ0 N² A i0 cos α / s0² (N/A) and Ks = μ0 N² A i0² cos α / s0³ (N/m), the
        linearisation of f = k[(i0+i)²/(s0−x)² − (i0−i)²/(s0+x)²] with k = μ0 N² A cos α / 4
        (Schweitzer & Maslen 2009, Eqs. 3.27–3.30).
    """
    k = MU0 * turns**2 * pole_area * math.cos(math.radians(pole_angle_deg))
    return k * bias_current / air_gap**2, k * bias_current**2 / air_gap**3


def amb_factors(amb: Amb) -> tuple[tuple[float, float], tuple[float, float]]:
    """(Ki_ζ, Ki_η) in N/A and (Ks_ζ, Ks_η) in N/m of a rig file's AMB.

    Each factor of each axis given explicitly (``ki``, ``ks``: a number or per axis) wins;
    the others come from the geometry through :func:`amb_factors_from_geometry`
    (Schweitzer & Maslen 2009, Eqs. 3.27–3.30), the same for both axes.

    Parameters
    ----------
    amb : Amb
        One ``[[amb]]`` of the rig file.

    Returns
    -------
    ki : (float or None, float or None)
        (Ki_ζ, Ki_η), N/A; ``None`` for an axis given neither a factor nor the geometry.
    ks : (float or None, float or None)
        (Ks_ζ, Ks_η), N/m; likewise.
    """
    geo = (None, None)
    if None not in (amb.turns, amb.pole_area, amb.air_gap, amb.bias_current):
        geo = amb_factors_from_geometry(amb.turns, amb.pole_area, amb.air_gap,
                                        amb.bias_current, amb.pole_angle_deg)
    return _pair(amb.ki, geo[0]), _pair(amb.ks, geo[1])


def _pair(v: float | AxisPair | None, default: float | None) -> tuple[float, float]:
    if isinstance(v, AxisPair):
        return tuple(float(x) if x is not None else default for x in (v.zeta, v.eta))
    return (default, default) if v is None else (float(v), float(v))


@dataclass(frozen=True)
class AmbElement:
    """One AMB in the mesh: bearing and sensor node, actuator axes and factors.

    Attributes
    ----------
    name : str
        The AMB's name.
    bearing_node, sensor_node : int
        Mesh nodes of the actuator and of the displacement sensor.
    R : ndarray, shape (2, 2)
        [ζ, η]ᵀ = R [x, y]ᵀ (:func:`axes_rotation`).
    ki : tuple of float
        (Ki_ζ, Ki_η) in N/A.
    ks : tuple of float
        (Ks_ζ, Ks_η) in N/m.
    """

    name: str
    bearing_node: int
    sensor_node: int
    R: np.ndarray
    ki: tuple[float, float]
    ks: tuple[float, float]

    @classmethod
    def from_config(cls, amb: Amb, mesh: Mesh) -> "AmbElement":
        """The element of a rig file's ``[[amb]]`` (factors from :func:`amb_factors`)."""
        ki, ks = amb_factors(amb)
        return cls(amb.name, mesh.node_at(amb.position), mesh.node_at(amb.sensor_position),
                   axes_rotation(amb.axes_angle_deg), ki, ks)

    @property
    def signal_names(self) -> tuple[str, ...]:
        """``{name}_zeta``, ``{name}_eta``: its actuator axes (the plant names its current
        inputs ``i_<axis>`` and sensor outputs ``y_<axis>``)."""
        return tuple(f"{self.name}_{axis}" for axis in AXES)

    def stiffness(self) -> np.ndarray:
        """(2, 2) on [x, y] of the bearing node: −Rᵀ diag(Ks) R."""
        t0, t1 = self._terms()
        return -t0 - t1

    def assemble(self, M: np.ndarray, C: np.ndarray, K: np.ndarray) -> None:
        """Add the negative bearing stiffness to K (n_dof, n_dof), in place."""
        i = np.ix_(_xy(self.bearing_node), _xy(self.bearing_node))
        for t in self._terms():
            K[i] -= t

    def _terms(self) -> list[np.ndarray]:
        return [self.ks[a] * np.outer(self.R[a], self.R[a]) for a in range(2)]

    def input_columns(self, n_dof: int) -> list[np.ndarray]:
        """Force per unit current of each axis, Ki r_a at the bearing node, shape (n_dof,)."""
        return [self.ki[a] * self._at(self.bearing_node, a, n_dof) for a in range(2)]

    def sensor_rows(self, n_dof: int) -> list[np.ndarray]:
        """Displacement along each axis at the sensor node, r_aᵀ, shape (n_dof,)."""
        return [self._at(self.sensor_node, a, n_dof) for a in range(2)]

    def channels(self, n_dof: int, first_input: int) -> list[Channel]:
        """``{name}.Ks_{axis}`` (ΔK = −θ r rᵀ) and ``{name}.Ki_{axis}`` (ΔB = θ r e_jᵀ, j its
        current input, counted from ``first_input``), per axis, Ks first."""
        out = []
        for a, axis in enumerate(AXES):
            rb = self._at(self.bearing_node, a, n_dof)[:, None]
            out.append(Channel(f"{self.name}.Ks_{axis}", self.ks[a], "N/m", "K", -rb, rb))
            out.append(Channel(f"{self.name}.Ki_{axis}", self.ki[a], "N/A", "B", rb,
                               np.array([[first_input + a]])))
        return out

    def _at(self, node: int, a: int, n_dof: int) -> np.ndarray:
        v = np.zeros(n_dof)
        v[_xy(node)] = self.R[a]
        return v


def _xy(node: int) -> list[int]:
    return [4 * node + X, 4 * node + Y]


def actuator_matrices(act: Actuator) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """State-space (A, B, C, D) of one actuator axis: current reference → coil current.

    - ``none``: a unit gain (no states).
    - ``first_order``: ω_c/(s + ω_c), ω_c = 2π·cutoff_hz (thesis P3 Eq. 2).
    - ``second_order``: ω_n²/(s² + 2ζω_n s + ω_n²) (thesis P4 Eq. 2, P5 Eq. 2; the printed
      equation drops the 2 and a square, the standard form is meant: ω_n = 1360 rad/s,
      ζ = 0.9 give the 216 Hz, well-damped amplifier the papers describe).

    Parameters
    ----------
    act : Actuator
        The rig file's ``actuator`` of an AMB (model, cutoff, natural frequency, damping).

    Returns
    -------
    (A, B, C, D)
        Shapes (n, n), (n, 1), (1, n), (1, 1), n = 0, 1 or 2, with unit DC gain.
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
    (thesis P2 §4, Fig. 2, "unknown actuator dynamics"); a unit gain for τ_e = 0.

    Parameters
    ----------
    tau_e : float
        The lag's time constant (s), ≥ 0.

    Returns
    -------
    (A, B, C, D)
        Shapes (1, 1), (1, 1), (1, 1), (1, 1); for τ_e = 0, (0, 0), (0, 1), (1, 0), (1, 1).
    """
    if tau_e <= 0:
        return np.zeros((0, 0)), np.zeros((0, 1)), np.zeros((1, 0)), np.ones((1, 1))
    return np.array([[-1.0 / tau_e]]), np.array([[1.0 / tau_e]]), np.ones((1, 1)), np.zeros((1, 1))

