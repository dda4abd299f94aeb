"""The drop's model of a rig: its modal rotor, contacts and supports (the package's
docstring, :mod:`ambseal.analysis.drop`)."""

from __future__ import annotations

import math
from dataclasses import dataclass, field, replace

import numpy as np
from scipy.constants import g as GRAVITY
from scipy.linalg import eigh

from ambseal.analysis.judge import seal_static_load
from ambseal.analysis.statics import support_forces
from ambseal.errors import ConfigError
from ambseal.model import (
    ContactLaw,
    SealElement,
    SpringElement,
    assemble_rotor,
    build_mesh,
    gravity_load,
    gravity_vector,
    hertz_impact,
    spring_label,
)

#: the modes kept reach this many times the contact's own frequency 1/t_c
MODES_PER_CONTACT = 4.0


def journal_radius(cfg, z: float) -> float:
    """The shaft's outer radius (m) at ``z`` (m): the larger of two sections meeting there,
    a tapered section's radius interpolated, a layer (sleeve) over it included."""
    r, z0 = 0.0, 0.0
    tol = 1e-9 * max(cfg.length, 1.0)
    for s in cfg.shaft:
        z1 = z0 + s.length
        if z0 - tol <= z <= z1 + tol:
            right = s.outer_diameter_right or s.outer_diameter
            f = min(max((z - z0) / s.length, 0.0), 1.0)
            r = max(r, 0.5 * ((1 - f) * s.outer_diameter + f * right),
                    *(0.5 * layer.outer_diameter for layer in s.layers))
        z0 = z1
    return r


@dataclass(frozen=True)
class DropModel:
    """The drop's equations (the package's docstring): the modal rotor and its contacts.

    Attributes
    ----------
    phi : ndarray, shape (n_dof, m)
        Mass-normalised free–free modes kept.
    frequency_hz : ndarray, shape (m,)
        Their natural frequencies (rigid-body modes 0).
    K, C, G : ndarray, shape (m, m)
        Φᵀ K Φ, Φᵀ C Φ, Φᵀ G Φ.
    gravity : ndarray, shape (m,)
        Φᵀ of the lateral part of the rotor's weight as the machine stands
        (:func:`ambseal.model.gravity_load`; zero for a vertical rotor).
    planes : tuple of ndarray, shape (2, m)
        Each touchdown plane's x, y rows of Φ.
    laws : tuple of ContactLaw
    clearance, journal, race_inertia, drag : ndarray, shape (p,)
        Per plane: radial clearance c (m), journal radius R_j (m), ring inertia (kg·m²,
        0: it stands still), drag torque (N·m).
    support : tuple of (float, float, float) or None
        Per plane: the support's mass, stiffness and damping, None where rigid.
    amb_force : ndarray, shape (a, 2)
        Each AMB's static force (N, x and y) in the levitated equilibrium: the lateral
        part of the weight, as the statics share it among the AMBs
        (:func:`ambseal.analysis.statics.support_forces`, the AMBs alone holding the
        rotor), and the static loads of the seals the rotor runs offset in, at the
        operating pressure drop (a seal's ``static_eccentricity`` taken downward: the
        rotor low in it).
    q0 : ndarray, shape (m,)
        The levitated equilibrium (the bending under gravity and the AMBs' forces).
    mass : float
        The rotor's mass (kg).
    polar_inertia : float
        The rotor's polar moment of inertia I_p (kg·m²).
    names : tuple of str
        The touchdown planes' names.
    modes_hz : float
        The modes kept are those below this (Hz).
    node_rows : dict
        ``{"amb:NAME", "seal:NAME", "spring:NAME", "sensor:NAME" or "disk:NAME": ndarray
        (2, m)}``: the x, y rows of Φ at each AMB, seal, ``[[spring]]`` with a
        ``clearance``, AMB sensor with a ``sensor_gap`` and disk with a ``clearance``,
        whose excursions the verdict sets against their gaps.
    z : ndarray, shape (n_nodes,)
        The FE nodes' positions (m); node k's DOFs are x, y, θx, θy at 4k … 4k + 3.
    projector : ndarray, shape (m, n_dof)
        ΦᵀM: the modal coordinates of a nodal displacement or velocity (exact within the
        modes kept, their mass-weighted least squares otherwise).
    cg_rows : ndarray, shape (2, m)
        The x, y rows of Φ at the node nearest the rotor's centre of mass, where an
        unbalance acts.
    z_cg : float
        The rotor's centre of mass (m).
    axial_clearance : ndarray, shape (p,)
        Per plane: the axial clearance (m) at which it stops the rotor axially, inf where
        it does not.
    axial_laws : tuple of ContactLaw or None
        Per plane: the axial contact's law (the radial one with
        ``axial_contact_stiffness``), None where it does not stop the rotor axially.
    g_xyz : ndarray, shape (3,)
        Gravity in the rotor's frame (m/s², :func:`ambseal.model.gravity_vector`): its
        x, y part in ``gravity``, its z part the axial weight m·g_z on the rotor once the
        thrust bearing lets go.
    orientation : str
        ``[machine] orientation``.
    """

    phi: np.ndarray
    frequency_hz: np.ndarray
    K: np.ndarray
    C: np.ndarray
    G: np.ndarray
    gravity: np.ndarray
    planes: tuple
    laws: tuple
    clearance: np.ndarray
    journal: np.ndarray
    race_inertia: np.ndarray
    drag: np.ndarray
    support: tuple
    amb_force: np.ndarray
    q0: np.ndarray
    mass: float
    polar_inertia: float
    names: tuple
    modes_hz: float
    node_rows: dict = field(default_factory=dict, repr=False)
    z: np.ndarray = field(default=None, repr=False)
    projector: np.ndarray = field(default=None, repr=False)
    cg_rows: np.ndarray = field(default=None, repr=False)
    z_cg: float = 0.0
    axial_clearance: np.ndarray = field(default=None, repr=False)
    axial_laws: tuple = ()
    g_xyz: np.ndarray = field(default_factory=lambda: np.array([0.0, -GRAVITY, 0.0]),
                              repr=False)
    orientation: str = "horizontal"

    @property
    def axial_weight(self) -> float:
        """The rotor's weight along its axis, m·g_z (N, +z positive; 0 lying
        horizontal)."""
        return float(self.mass * self.g_xyz[2])

    @property
    def lateral_gravity(self) -> float:
        """The magnitude of gravity across the axis, √(g_x² + g_y²) (m/s²; 0 standing
        vertical)."""
        return float(math.hypot(self.g_xyz[0], self.g_xyz[1]))


def _disk_label(disk, i: int) -> str:
    """A disk's name in the drop's outputs: its ``name``, else ``disk[i]``."""
    return disk.name or f"disk[{i}]"


def _seal_offset(seal) -> np.ndarray:
    """The rotor's static offset (m, x/y) from a seal's centre in the drop: its
    ``static_eccentricity`` taken downward, the rotor low in the seal — the direction
    in which the rotor falls closest to the seal's wall (the judgement's static currents
    take the worst direction instead, :func:`ambseal.analysis.judge.static_currents`)."""
    return np.array([0.0, -float(seal.static_eccentricity)])


def _seal_offset_forces(cfg, pressure_bar: float) -> list[tuple[float, np.ndarray]]:
    """Each offset seal's position (m) and static force on the rotor (N, x/y) at the
    pressure drop: −[[K, k], [−k, K]]·e at zero frequency
    (:func:`ambseal.analysis.judge.seal_static_load`), e its ``_seal_offset``."""
    return [(s.position, seal_static_load(s, pressure_bar)[0] @ _seal_offset(s))
            for s in cfg.seal if s.static_eccentricity > 0]


def _amb_static_forces(cfg, g_xyz, loads=()) -> np.ndarray:
    """The AMBs' forces (N, shape (a, 2): x, y) that hold the lateral part of the rotor's
    weight and the static ``loads`` ((z, F_xy) pairs).

    The weight's share is the statics' (:func:`ambseal.analysis.statics.support_forces`
    on the rig without its springs: in the drop the AMBs hold the levitated rotor alone,
    the springs acting on its excursions from there), split evenly among AMBs at one
    position; the loads' is the net force and moment in each direction (the least-norm
    split beyond two AMB positions).
    """
    z = np.array([a.position for a in cfg.amb], float)
    out = np.zeros((z.size, 2))
    if np.any(np.asarray(g_xyz[:2]) != 0.0):
        try:
            held, applied = support_forces(cfg.model_copy(update={"spring": []}), g_xyz)
            total = sum(held.values(), np.zeros(2))
            ok = np.abs(total - applied).max() <= 1e-6 * np.abs(applied).max()
        except np.linalg.LinAlgError:  # one AMB plane: nothing holds the weight's moment
            ok = False
        if not ok:
            raise ConfigError("drop: the AMBs cannot hold the rotor's weight (one AMB "
                              "plane: nothing holds the weight's moment)")
        for k, a in enumerate(cfg.amb):
            out[k] = -held[a.position] / int(np.sum(z == a.position))
    A = np.vstack([np.ones_like(z), z])
    for j in range(2):
        b = np.zeros(2)
        for zs, F in loads:
            b -= F[j] * np.array([1.0, zs])
        if not b.any():
            continue
        f, *_ = np.linalg.lstsq(A, b, rcond=None)
        if not np.allclose(A @ f, b, rtol=1e-9, atol=1e-9 * max(abs(b).max(), 1e-300)):
            raise ConfigError("drop: the AMBs cannot hold the rotor's weight and the seals' "
                              "static loads (one AMB away from the centre of mass)")
        out[:, j] += f
    return out


def drop_model(cfg, modes_hz: float | None = None) -> DropModel:
    """The drop's modal rotor and contacts of a rig (the package's docstring).

    Parameters
    ----------
    cfg : RigConfig
        With ``[[amb]]`` and ``[[touchdown]]`` tables.
    modes_hz : float, optional
        Keep the free–free modes below this (Hz); default: the package docstring's rule.

    Returns
    -------
    DropModel

    Raises
    ------
    ConfigError
        A rig without AMBs or touchdown bearings.
    """
    if not cfg.touchdown:
        raise ConfigError("drop: the rig has no [[touchdown]] bearing to land on")
    if not cfg.amb:
        raise ConfigError("drop: the rig has no [[amb]]: nothing lets the rotor go")
    mesh = build_mesh(cfg, extra_positions=tuple(t.position for t in cfg.touchdown))
    rotor = assemble_rotor(cfg, mesh)
    Mr, Gr, _ = rotor.rigid()
    mass, z_g = float(Mr[0, 0]), float(Mr[0, 2] / Mr[0, 0])
    laws = tuple(ContactLaw.of(t) for t in cfg.touchdown)
    c = np.array([t.radial_clearance for t in cfg.touchdown])
    if modes_hz is None:
        share = mass / len(cfg.touchdown)
        v0 = math.sqrt(2 * GRAVITY * c.min())
        # the impact's two bodies: the rotor's share and the ring's support mass, if any
        masses = [share * t.support_mass / (share + t.support_mass) if t.support_mass > 0
                  else share for t in cfg.touchdown]
        t_c = min(hertz_impact(mm, v0, law.stiffness, law.exponent)[1]
                  for mm, law in zip(masses, laws))
        modes_hz = MODES_PER_CONTACT / t_c
    w2, vec = eigh(0.5 * (rotor.K + rotor.K.T), rotor.M)
    f = np.sqrt(np.clip(w2, 0.0, None)) / (2 * np.pi)
    keep = f <= modes_hz
    keep[:4] = True  # the rigid-body modes, whatever the rounding
    phi = vec[:, keep]
    f = np.where(np.arange(f.size)[keep] < 4, 0.0, f[keep])
    rows = {}

    def xy(z: float) -> np.ndarray:
        n = mesh.node_at(z)
        return phi[[4 * n, 4 * n + 1], :]

    g_xyz = gravity_vector(cfg.machine)
    gravity = phi.T @ gravity_load(rotor.M, mesh.n_dof, g_xyz)
    offsets = _seal_offset_forces(cfg, cfg.operating.pressure_bar)
    amb_force = _amb_static_forces(cfg, g_xyz, offsets)
    Km = phi.T @ rotor.K @ phi
    # levitated: the flexible modes bent by gravity, the AMBs and the offset seals (the
    # rigid ones balanced)
    load = gravity + sum((xy(a.position).T @ f for a, f in zip(cfg.amb, amb_force)),
                         np.zeros(phi.shape[1]))
    load = load + sum((xy(zs).T @ F for zs, F in offsets), np.zeros(phi.shape[1]))
    flex = f > 0
    scale = float(np.abs(gravity).max(initial=0.0)) + sum(
        float(np.abs(F).max()) for _, F in offsets)
    if np.abs(load[~flex]).max(initial=0.0) > 1e-6 * max(scale, 1e-300):
        raise ConfigError("drop: the AMBs cannot hold the rotor's weight and the seals' "
                          "static loads (one AMB away from the centre of mass)")
    q0 = np.zeros(phi.shape[1])
    q0[flex] = np.linalg.solve(Km[np.ix_(flex, flex)], load[flex])
    g_node = int(np.argmin(np.abs(mesh.z - z_g)))
    rows.update({f"amb:{a.name}": xy(a.position) for a in cfg.amb})
    rows.update({f"seal:{s.name}": xy(s.position) for s in cfg.seal})
    rows.update({f"spring:{spring_label(s, i)}": xy(s.position)
                 for i, s in enumerate(cfg.spring) if s.clearance is not None})
    rows.update({f"sensor:{a.name}": xy(a.sensor_position) for a in cfg.amb
                 if a.sensor_gap is not None})
    rows.update({f"disk:{_disk_label(d, i)}": xy(d.position) for i, d in enumerate(cfg.disk)
                 if d.clearance is not None})
    return DropModel(
        phi=phi, frequency_hz=f, K=Km, C=phi.T @ rotor.C @ phi, G=phi.T @ rotor.G @ phi,
        gravity=gravity, planes=tuple(xy(t.position) for t in cfg.touchdown), laws=laws,
        clearance=c, journal=np.array([journal_radius(cfg, t.position)
                                       for t in cfg.touchdown]),
        race_inertia=np.array([t.race_inertia or 0.0 for t in cfg.touchdown]),
        drag=np.array([t.race_drag_torque for t in cfg.touchdown]),
        support=tuple((t.support_mass, t.support_stiffness, t.support_damping)
                      if t.support_mass > 0 else None for t in cfg.touchdown),
        amb_force=amb_force, q0=q0, mass=mass,
        polar_inertia=float(abs(Gr[2, 3])),
        names=tuple(t.name for t in cfg.touchdown), modes_hz=float(modes_hz),
        node_rows=rows, z=np.asarray(mesh.z, float), projector=phi.T @ rotor.M,
        cg_rows=phi[[4 * g_node, 4 * g_node + 1], :], z_cg=z_g,
        axial_clearance=np.array([np.inf if t.axial_clearance is None else t.axial_clearance
                                  for t in cfg.touchdown]),
        axial_laws=tuple(None if t.axial_clearance is None else
                         law if t.axial_contact_stiffness is None else
                         replace(law, stiffness=float(t.axial_contact_stiffness))
                         for t, law in zip(cfg.touchdown, laws)),
        g_xyz=g_xyz, orientation=cfg.machine.orientation)


def support_matrices(cfg, dm: DropModel, speed_rpm: float,
                     pressure_bar: float | None = None
                     ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """What holds the rotor besides its AMBs, on the drop's modes: each seal's Childs force
    −[K k; −k K] s − [C c; −c C] ṡ − M s̈ (thesis P4 Eq. 3) and each ``[[spring]]``'s
    (a coupling, P4 Eq. 4; a plain bearing, a balance piston) on the node's displacement s
    from the levitated equilibrium, at the pressure drop and, for tabulated coefficients,
    the synchronous frequency of ``speed_rpm`` (as :func:`ambseal.model.build_plant`
    takes them), held through the drop. A spring on a ``housing`` joins its node to the
    housing's mass, held to ground by its own springs and dampers (ROSS's bearing on a
    pedestal): the housings' x, y follow the modes, in the rig's order, as further
    coordinates of these matrices (their mass in M).

    Parameters
    ----------
    cfg : RigConfig
        The rig and its ``[[seal]]`` and ``[[spring]]`` tables.
    dm : DropModel
        Its drop model.
    speed_rpm : float
        The spin speed (rpm) at the drop.
    pressure_bar : float, optional
        The pressure drop across the seals (bar); ``[operating] pressure_bar`` if omitted.

    Returns
    -------
    K, C, M : ndarray, shape (m + 2h, m + 2h)
        Tᵀ K T, Tᵀ C T, Tᵀ M T of the seals and springs (zero without them) on the modes
        and the h housings' x, y, T = diag(Φ, I).
    """
    p = cfg.operating.pressure_bar if pressure_bar is None else pressure_bar
    f = abs(speed_rpm) / 60.0
    mesh = build_mesh(cfg, extra_positions=tuple(t.position for t in cfg.touchdown))
    nh = 2 * _housings(cfg)
    n = mesh.n_dof + nh
    K, C, M = (np.zeros((n, n)) for _ in range(3))
    for seal in cfg.seal:
        SealElement.from_config(seal, mesh, p, f).assemble(M, C, K)
    dof = mesh.n_dof  # each housing's x, y after the shaft's, in order
    for i, spring in enumerate(cfg.spring):
        SpringElement.from_config(spring, mesh, i, None if spring.housing is None else dof,
                                  f).assemble(M, C, K)
        dof += 0 if spring.housing is None else 2
    m = dm.phi.shape[1]
    T = np.zeros((n, m + nh))
    T[:mesh.n_dof, :m] = dm.phi
    T[mesh.n_dof:, m:] = np.eye(nh)
    return T.T @ K @ T, T.T @ C @ T, T.T @ M @ T


def _housings(cfg) -> int:
    """The ``[[spring]]`` housings of a rig: each two coordinates (x, y) of the drop after
    the modes (:func:`support_matrices`)."""
    return sum(s.housing is not None for s in cfg.spring)
