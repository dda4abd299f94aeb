"""The rotor held at rest under gravity: what each bearing carries, and the AMBs' static
currents.

Gravity acts as the machine stands (``[machine] orientation``,
:mod:`ambseal.model.gravity`). Its lateral part loads the rotor's lateral model, held by
its bearings: each AMB holds its journal at the set point (a rigid pin: the controller's
integral action brings the position to zero), every spring (a coupling, a plain bearing)
is as stiff as it is at the running speed, and the seals take none of it (a seal carries no
weight; :func:`support_forces`). Each AMB's force on the rotor is the pin's reaction; its
static control current per actuator axis follows from ``f = Ki·i + Ks·s`` at ``s = 0``
(:mod:`ambseal.model.amb`): ``i_a = (R f)_a / Ki_a``, R the rotation to the AMB's axes.

The axial part, ``m g_z``, has no degree of freedom in the lateral model: a vertical
rotor's radial AMBs carry none of its weight and an axial bearing carries it all. ambseal
models no axial AMB, so the statics say that a thrust bearing outside the model carries it
(:attr:`Statics.axial_note`).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ambseal.config import Spring
from ambseal.model import (
    AXES,
    SpringElement,
    amb_factors,
    assemble_rotor,
    axes_rotation,
    axial_weight,
    build_system,
    gravity_load,
    gravity_vector,
    inclination,
    spring_at,
    spring_label,
)

__all__ = ["RIGID_SUPPORT", "support_forces", "AmbStatic", "Statics", "rotor_at_rest"]

#: A rigid support's stiffness (N/m): the AMBs' pins of the statics and the sign-off's
#: rigid supports, stiff against any rotor's bending (a 1 m steel shaft's is ~1e8 N/m).
RIGID_SUPPORT = 1e11


def support_forces(cfg, g_xyz) -> tuple[dict[float, np.ndarray], np.ndarray]:
    """The force of the rotor on each of its bearings under a gravity (module docstring).

    Parameters
    ----------
    cfg : RigConfig
        The rig: its AMBs (pinned), else its springs, are the bearings; springs beside AMBs
        carry their share as they are (at ``[operating] speed_rpm``: a bearing's table has
        no standstill value); seals and springs of ``kind = "seal"`` carry none.
    g_xyz : array_like, shape (3,)
        Gravity in the rotor's frame (m/s², :func:`ambseal.model.gravity_vector`); only its
        lateral part counts here.

    Returns
    -------
    loads : dict
        Bearing position (m, ascending; the AMBs', or the springs' on a rig without AMBs)
        → its load (N, shape (2,), x and y; opposite to the bearing's force on the rotor).
    applied : ndarray, shape (2,)
        The lateral gravity load in all (N, x and y): the model's mass, a spring's added
        mass at its journal included, times (g_x, g_y); what the loads sum to where the
        bearings hold the rotor.
    """
    zs = sorted({a.position for a in cfg.amb}
                or {s.position for s in cfg.spring if s.kind != "seal"})
    pins = [Spring(position=z, kxx=RIGID_SUPPORT, kyy=RIGID_SUPPORT, name=f"pin{i}")
            for i, z in enumerate(zs)] if cfg.amb else []
    f_run = cfg.operating.speed_rpm / 60.0
    kept = [spring_at(s, f_run) for s in cfg.spring if s.kind != "seal"]
    rig = cfg.model_copy(update={"seal": [], "amb": [], "spring": [*kept, *pins]})
    sys = build_system(rig, speed_rpm=0.0)
    F = gravity_load(sys.M, sys.mesh.n_dof, g_xyz)
    q = np.linalg.solve(sys.K, F)
    force = {z: np.zeros(2) for z in zs}
    # with AMBs, their pins (appended after the rig's springs) carry the journals
    for i, s in list(enumerate(rig.spring))[len(kept) if cfg.amb else 0:]:
        if s.position in force:
            force[s.position] += _spring_load(sys, q, s, i)
    return force, np.array([F[0:sys.mesh.n_dof:4].sum(), F[1:sys.mesh.n_dof:4].sum()])


def _spring_load(sys, q: np.ndarray, s: Spring, index: int) -> np.ndarray:
    """A spring's load (N, x and y): its stiffness (cross terms and axes included) on the
    journal's deflection, less its housing's."""
    node = sys.mesh.node_at(s.position)
    d = np.array([q[4 * node], q[4 * node + 1]])
    if s.housing is not None:
        h = sys.mesh.n_dof + sys.housing_names.index(f"{spring_label(s, index)}_housing_x")
        d = d - q[h:h + 2]
    K2 = SpringElement.from_config(s.model_copy(update={"housing": None}), sys.mesh,
                                   index).matrices()[0]
    return K2 @ d


@dataclass(frozen=True)
class AmbStatic:
    """One AMB holding the rotor at rest (module docstring).

    Attributes
    ----------
    name : str
        The AMB.
    position_m : float
        Its axial position (m).
    force_n : tuple of float
        Its force on the rotor (N, x and y).
    current_a : tuple of (float or None)
        The static control current of each actuator axis (A, ζ and η): ``(R f)_a / Ki_a``;
        None for an axis without Ki.
    """

    name: str
    position_m: float
    force_n: tuple[float, float]
    current_a: tuple[float | None, float | None]

    def to_dict(self) -> dict:
        return {"name": self.name, "position_m": self.position_m,
                "force_n": list(self.force_n),
                "current_a": dict(zip(AXES, self.current_a))}


@dataclass(frozen=True)
class Statics:
    """The rotor held at rest as the machine stands (module docstring).

    Attributes
    ----------
    orientation : str
        ``[machine] orientation``.
    inclination_deg : float
        The rotor axis above the horizontal (deg).
    gravity_m_s2 : tuple of float
        Gravity in the rotor's frame (x, y, z).
    mass_kg : float
        The rotor's mass.
    axial_weight_n : float
        The weight along the rotor axis, ``m g_z`` (N, +z positive).
    bearing_loads_n : tuple of (float, float, float)
        Per bearing (the AMBs', else the springs' positions): ``(z m, F_x N, F_y N)``, the
        rotor's load on it.
    ambs : tuple of AmbStatic
        Each AMB's force and static currents.
    held : bool
        The bearings hold the rotor statically (False: none, or one bearing plane, which
        leaves the weight's moment free; then no loads and no AMB currents).
    """

    orientation: str
    inclination_deg: float
    gravity_m_s2: tuple[float, float, float]
    mass_kg: float
    axial_weight_n: float
    bearing_loads_n: tuple[tuple[float, float, float], ...]
    ambs: tuple[AmbStatic, ...]
    held: bool = True

    @property
    def axial_note(self) -> str | None:
        """Who carries the axial weight: a thrust bearing the model does not include (None
        when the rotor lies horizontal)."""
        if self.axial_weight_n == 0.0:
            return None
        return (f"the rotor's weight along its axis, {abs(self.axial_weight_n):.4g} N, is "
                "carried by an axial (thrust) bearing or axial AMB the model does not "
                "include; the radial AMBs carry only the lateral part")

    def to_dict(self) -> dict:
        return {"orientation": self.orientation, "inclination_deg": self.inclination_deg,
                "gravity_m_s2": list(self.gravity_m_s2), "mass_kg": self.mass_kg,
                "axial_weight_n": self.axial_weight_n, "axial_note": self.axial_note,
                "bearing_loads_n": [{"position_m": z, "x": fx, "y": fy}
                                    for z, fx, fy in self.bearing_loads_n],
                "ambs": [a.to_dict() for a in self.ambs], "held": self.held}


def rotor_at_rest(cfg) -> Statics:
    """The rotor of a rig held at rest under gravity as the machine stands (module
    docstring).

    Parameters
    ----------
    cfg : RigConfig
        The rig (its ``[machine]``, ``[[amb]]`` and ``[[spring]]``).

    Returns
    -------
    Statics
        On a rig with neither AMBs nor bearing springs, or whose bearings do not hold
        the rotor statically (one bearing plane: nothing takes the weight's moment), no
        bearing loads and no AMB currents.
    """
    g = gravity_vector(cfg.machine)
    mass = assemble_rotor(cfg).mass
    has_bearing = cfg.amb or any(s.kind != "seal" for s in cfg.spring)
    loads = _held(cfg, g) if has_bearing else {}
    ambs = []
    for a in cfg.amb if loads else ():
        share = [b for b in cfg.amb if b.position == a.position]
        f = -loads[a.position] / len(share) + 0.0  # on the rotor (+0.0: no signed zero)
        ki, _ = amb_factors(a)
        fa = axes_rotation(a.axes_angle_deg) @ f
        ambs.append(AmbStatic(a.name, float(a.position), (float(f[0]), float(f[1])),
                              tuple(float(fa[k] / ki[k]) if ki[k] else None
                                    for k in range(2))))
    return Statics(cfg.machine.orientation, inclination(cfg.machine),
                   tuple(float(x) for x in g), float(mass), axial_weight(mass, g),
                   tuple((float(z), float(F[0]), float(F[1])) for z, F in loads.items()),
                   tuple(ambs), bool(loads))


def _held(cfg, g) -> dict:
    """:func:`support_forces`' loads where the bearings hold the rotor (their loads sum to
    the weight's lateral part within 1e-6 of it), else none."""
    try:
        loads, applied = support_forces(cfg, g)
    except np.linalg.LinAlgError:  # a rotor free to tilt or slide: no static position
        return {}
    total = sum(loads.values(), np.zeros(2))
    scale = max(float(np.abs(applied).max()), 1.0)
    return loads if float(np.abs(total - applied).max()) <= 1e-6 * scale else {}
