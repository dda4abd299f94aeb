"""The rotor drop: the FE rotor released by its AMBs onto its touchdown bearings.

ISO 14839-5:2022 asks for the analysis of the events that land a rotor on its touch-down
bearings. Here the events are the loss of AMB axes — every one, or some while the loop
runs the others — and a step force, from the levitated state at the operating speed: the
AMB loop runs inside the drop (:mod:`ambseal.analysis.drop_loop`: each axis's force
linearised about the levitated equilibrium, its current reference clipped at its limit,
a lost axis's force decaying with the square of its coil's current, e^{−2t R/L}), and the
rotor falls through the clearance onto the rings. Where every axis is lost the thrust
bearing lets go too: the rotor, rigid along its axis (its axial modes lie far above the
drop's), moves under the residual thrust (``[drop] axial_thrust``) onto the planes with an
``axial_clearance``, m z̈ = F_a − Σ sign(z)·N_a(|z| − c_a), N_a the plane's contact law
(its own K with ``axial_contact_stiffness``) damped as the radial one by the onset's
axial speed, at least that of a fall through c_a under the thrust or the weight; its
friction μN_a·tanh(v_s/v_r) at the ring's bore radius R_r against the slip
(Ω − ω_r)·R_r brakes the spin and spins the ring up. Each plane's friction heat
∫F_t v_s dt, radial and axial, is kept.

The rotor: the free FE rotor of the rig (:func:`ambseal.model.assemble_rotor`, a node at
every touchdown plane) in the mass-normalised real modes of its free–free
non-rotating form up to ``modes_hz`` (rigid-body modes included), M q̈ + (C + ΩG) q̇ + K q
= f at the spin speed Ω, held by the drive or coasting down under the rings' friction
and a drag torque (``coast_down``), the gyroscopic moments at the instantaneous speed;
the seals' and springs' forces (:func:`support_matrices`) at the drop's speed and pressure
drop.
The default ``modes_hz`` is :data:`MODES_PER_CONTACT` (4) times the contact's own
frequency 1/t_c (:func:`ambseal.model.hertz_impact`) for a fall through the smallest
clearance, the shortest over the planes, each an impact of the rotor's mass shared among
the touchdown planes on the ring's support mass where it has one (their reduced mass: a
light ring on a soft mount makes the contact far shorter than the rotor's share does).
Twice as many hertz moves the first impact's peak force by under 2 % on the example rigs
(benchmarks/README.md); the later impacts of a drop depend on its whole history, and
their peaks do not converge as the first does.

Each touchdown plane (:class:`ambseal.config.Touchdown`; :class:`ambseal.model.
ContactLaw`): the journal's centre r relative to the ring's (the ring on its support
where ``support_mass`` is given), penetration δ = |r| − c, normal n = r/|r|, tangent
t = ẑ × n. The normal force N on δ and δ̇ with the damping of the impact's normal speed
v₀ at the contact's onset, at least the free-fall speed over the clearance √(2 g c): a
slower onset — a grazing contact, or the ring's support meeting the journal — is damped
as a fall through the clearance would be, not by the D ∝ 1/v₀ a near-zero v₀ would give
(which would put a damping force many times the elastic one into a slow contact);
friction μN·tanh(v_s/v_r) against
the slip v_s = t·ṙ + Ω R_j − ω_r R_r of the journal's surface on the ring's (R_j the
shaft's outer radius there, R_r = R_j + c); a ring with ``race_inertia`` J spins up,
J ω̇_r = F_t R_r − T_d·tanh(ω_r/ω_d), ω_d = v_r/R_r; without it the ring stands still.

Integration: scipy's ``solve_ivp`` from event to event (each plane's contact onset and
end are events that end a segment: the onset sets v₀), to relative tolerance ``rtol``,
by DOP853 (explicit: an impact's and the flexible modes' oscillations at the least cost)
until it crawls: a ring rolling on the journal without slip meets the friction's
regularised slope μN/v_r on the ring's small inertia, a time constant of nanoseconds, and
where a segment advances less than one period of the highest mode kept per
:data:`CYCLE_EVALUATIONS` evaluations (judged past :data:`CRAWL_EVALUATIONS`) the drop
goes on with LSODA, which switches to its stiff method there. A plane pressed deeper
than :data:`CRUSHED` (1 %) of its journal's radius (radially, or axially on a stop) ends
the drop with a refusal: the contact laws are those of a contact small against the
bodies (a drop presses a few micrometres), and a load that crushes the rings — a seal
surge of thousands of bar, say, whose cross-coupled stiffness drives a whirl growing at
thousands per second into the rings with meganewtons — has no answer in them (and such a
contact's friction makes the drop crawl even with LSODA: the test rig's seal surging to
1e4 bar had not dropped 10 ms in 200 s). On the expander-generator
example DOP853 takes a 1 s drop in 40 s and LSODA in 190 s; on the flywheel rolling
on its rings DOP853 does not finish 0.1 s in ten minutes and LSODA takes 11 s
(benchmarks/README.md). The switch counts evaluations, not time: the same drop switches
at the same point on every machine.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, replace

import numpy as np
from scipy.constants import g as GRAVITY
from scipy.integrate import solve_ivp
from scipy.linalg import eigh

from ambseal.analysis.drop_loop import AmbLoop, amb_loop
from ambseal.analysis.judge import seal_static_load
from ambseal.design import air_gaps
from ambseal.errors import ConfigError
from ambseal.lti import json_float
from ambseal.model import (
    ContactLaw,
    SealElement,
    SpringElement,
    assemble_rotor,
    build_mesh,
    friction_force,
    hertz_impact,
    normal_force,
    rated_contact_stress,
    spring_label,
)

class _Crawling(Exception):
    """An explicit integration step size collapsed (the friction's stick is stiff)."""


__all__ = ["GRAVITY", "DropModel", "DropResult", "drop_model", "simulate_drop",
           "journal_radius", "drop_verdict", "support_matrices"]

#: the modes kept reach this many times the contact's own frequency 1/t_c
MODES_PER_CONTACT = 4.0
#: regimes: the share of the last half of the drop in contact below which it bounces
BOUNCING_BELOW = 0.5
#: integration segments (one per contact onset or end) after which a drop is refused:
#: a contact chattering at the integrator's resolution
MAX_SEGMENTS = 100_000
#: an explicit method gives way to STIFF_METHOD for the rest of the drop when a segment,
#: past CRAWL_EVALUATIONS right-hand sides, advances less than one period of the highest
#: mode kept per CYCLE_EVALUATIONS of them (module docstring)
EXPLICIT = ("RK23", "RK45", "DOP853")
STIFF_METHOD = "LSODA"
CRAWL_EVALUATIONS = 20_000
CYCLE_EVALUATIONS = 1000
#: the points in each integrator step at which the peak force and penetration are read
PEAK_POINTS = 8
#: the penetration, as a fraction of the journal's radius, that ends a drop with a
#: refusal (module docstring): Hertz's and Palmgren's laws are those of a contact small
#: against the bodies' radii (Johnson, Contact Mechanics, 1985, §4.2: the half-space
#: premise), and a penetration δ = a²/R of 1 % of the radius is a contact a tenth as wide
#: as the radius, where the premise ends (steel yields far earlier: ISO 76's C₀)
CRUSHED = 0.01


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
    """The drop's equations (module docstring): the modal rotor and its contacts.

    Attributes
    ----------
    phi : ndarray, shape (n_dof, m)
        Mass-normalised free–free modes kept.
    frequency_hz : ndarray, shape (m,)
        Their natural frequencies (rigid-body modes 0).
    K, C, G : ndarray, shape (m, m)
        Φᵀ K Φ, Φᵀ C Φ, Φᵀ G Φ.
    gravity : ndarray, shape (m,)
        Φᵀ of the rotor's weight (−y).
    planes : tuple of ndarray, shape (2, m)
        Each touchdown plane's x, y rows of Φ.
    laws : tuple of ContactLaw
    clearance, journal, race_inertia, drag : ndarray, shape (p,)
        Per plane: radial clearance c (m), journal radius R_j (m), ring inertia (kg·m²,
        0: it stands still), drag torque (N·m).
    support : tuple of (float, float, float) or None
        Per plane: the support's mass, stiffness and damping, None where rigid.
    amb_force : ndarray, shape (a, 2)
        Each AMB's static force (N, x and y) in the levitated equilibrium: the weight and
        the static loads of the seals the rotor runs offset in, at the operating pressure
        drop (a seal's ``static_eccentricity`` taken downward: the rotor low in it).
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


def _amb_static_forces(cfg, mass: float, z_g: float, loads=()) -> np.ndarray:
    """The AMBs' forces (N, shape (a, 2): x, y) that hold the rotor's weight and the
    static ``loads`` ((z, F_xy) pairs): net force and moment in each direction (the
    least-norm split beyond two AMBs)."""
    z = np.array([a.position for a in cfg.amb], float)
    A = np.vstack([np.ones_like(z), z])
    out = np.zeros((z.size, 2))
    for j in range(2):
        b = np.array([mass * GRAVITY * (j == 1), mass * GRAVITY * z_g * (j == 1)])
        for zs, F in loads:
            b -= F[j] * np.array([1.0, zs])
        f, *_ = np.linalg.lstsq(A, b, rcond=None)
        if not np.allclose(A @ f, b, rtol=1e-9, atol=1e-9 * max(abs(b).max(), 1e-300)):
            raise ConfigError("drop: the AMBs cannot hold the rotor's weight and the seals' "
                              "static loads (one AMB away from the centre of mass)")
        out[:, j] = f
    return out


def drop_model(cfg, modes_hz: float | None = None) -> DropModel:
    """The drop's modal rotor and contacts of a rig (module docstring).

    Parameters
    ----------
    cfg : RigConfig
        With ``[[amb]]`` and ``[[touchdown]]`` tables.
    modes_hz : float, optional
        Keep the free–free modes below this (Hz); default: the module docstring's rule.

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

    t_y = np.zeros(mesh.n_dof)
    t_y[1::4] = 1.0
    gravity = -GRAVITY * phi.T @ (rotor.M @ t_y)
    offsets = _seal_offset_forces(cfg, cfg.operating.pressure_bar)
    amb_force = _amb_static_forces(cfg, mass, z_g, offsets)
    Km = phi.T @ rotor.K @ phi
    # levitated: the flexible modes bent by gravity, the AMBs and the offset seals (the
    # rigid ones balanced)
    load = gravity + sum((xy(a.position).T @ f for a, f in zip(cfg.amb, amb_force)),
                         np.zeros(phi.shape[1]))
    load = load + sum((xy(zs).T @ F for zs, F in offsets), np.zeros(phi.shape[1]))
    q0 = np.zeros(phi.shape[1])
    flex = f > 0
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
                         for t, law in zip(cfg.touchdown, laws)))


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


@dataclass(frozen=True)
class DropResult:
    """A simulated drop (module docstring).

    Attributes
    ----------
    t : ndarray, shape (k,)
        Sample times (s).
    orbit : ndarray, shape (p, k, 2)
        Each touchdown plane's journal centre relative to its ring (m).
    force : ndarray, shape (p, k)
        Normal contact force (N).
    penetration : ndarray, shape (p, k)
        δ (m; negative out of contact).
    race_speed : ndarray, shape (p, k)
        Ring speed (rad/s).
    energy : ndarray, shape (k,)
        The rotor's mechanical energy with the contacts' stored energy (J; the weight's
        potential from the levitated position), the rings', the supports' and, coasting,
        the spin's.
    work : ndarray, shape (k,)
        The work done on it from outside since the drop (J): by the drive holding the
        spin against the rings' friction, by the AMBs' forces, the seals', the unbalance
        and the overload. What the contacts' damping and friction, the drag and the
        structural damping took is ``energy[0] + work − energy``.
    watched : dict
        ``{name: ndarray (k, 2)}``: the rotor's centre at each plane of
        :attr:`DropModel.node_rows` (m).
    impacts : int
        Contact onsets counted.
    names : tuple of str
    speed_rad_s : float
    modes_hz : float
    n_modes : int
    peak_force, peak_penetration : ndarray, shape (p,)
        Each plane's largest normal force (N) and penetration (m), over the output's
        samples and the integrator's own steps.
    first_peak_force : ndarray, shape (p,)
        Each plane's largest normal force in its first contact (N; 0 where it never
        touched): the impact of the fall itself, before the history of the bounces that
        follow (which a drop's later, larger impacts depend on).
    spin : ndarray, shape (k,)
        The rotor's spin speed (rad/s): ``speed_rad_s`` throughout unless it coasts down.
    journal, clearance : ndarray, shape (p,)
        Each plane's journal radius R_j and radial clearance c (m).
    turning : ndarray of bool, shape (p,)
        The planes whose ring turns (a ``race_inertia``).
    integrator : str
        The ``solve_ivp`` method, and where it gave way to the stiff one
        (``"DOP853 → LSODA from 0.0123 s"``).
    channels : tuple of str
        The AMB axes (:attr:`AmbLoop.names`).
    failed : tuple of str
        Those that lost power at t = 0.
    amb_current : ndarray, shape (c, k)
        Each axis's coil current i_s + i (A): driven by the loop, or decaying once its
        power is lost (:mod:`ambseal.analysis.drop_loop`).
    current_limit : ndarray, shape (c,)
        Each axis's largest current i_max (A; inf: unbounded).
    saturated : ndarray of bool, shape (c,)
        The axes that ran on whose current reference was clipped at i_max at an output
        sample.
    axial_position : ndarray, shape (k,), or None
        The rotor's axial displacement (m, +z) where the thrust bearing let go and a plane
        stops it axially; None where it held.
    axial_force : ndarray, shape (p, k)
        Each plane's axial contact force (N).
    peak_axial_force, peak_axial_penetration : ndarray, shape (p,)
        Each plane's largest axial force (N) and penetration (m), read as the radial ones.
    axial_thrust : float
        The thrust (N) on the rotor once the thrust bearing let go.
    friction_heat : ndarray, shape (p, k)
        The heat (J) each plane's friction made since the drop, radial and axial:
        ∫ F_t·v_s dt.
    """

    t: np.ndarray
    orbit: np.ndarray
    force: np.ndarray
    penetration: np.ndarray
    race_speed: np.ndarray
    energy: np.ndarray
    work: np.ndarray
    watched: dict
    impacts: int
    names: tuple
    speed_rad_s: float
    modes_hz: float
    n_modes: int
    peak_force: np.ndarray
    peak_penetration: np.ndarray
    first_peak_force: np.ndarray
    spin: np.ndarray
    journal: np.ndarray
    clearance: np.ndarray
    turning: np.ndarray
    integrator: str
    channels: tuple = ()
    failed: tuple = ()
    amb_current: np.ndarray = field(default=None, repr=False)
    current_limit: np.ndarray = field(default=None, repr=False)
    saturated: np.ndarray = field(default=None, repr=False)
    axial_position: np.ndarray | None = field(default=None, repr=False)
    axial_force: np.ndarray = field(default=None, repr=False)
    peak_axial_force: np.ndarray = field(default=None, repr=False)
    peak_axial_penetration: np.ndarray = field(default=None, repr=False)
    axial_thrust: float = 0.0
    friction_heat: np.ndarray = field(default=None, repr=False)

    def regime(self, p: int) -> tuple[str, float]:
        """The plane's regime over the last half of the drop: ``"no contact"`` (never
        touched), ``"bouncing"`` (in contact less than half that time), ``"resting"`` (in
        contact, its orbit going less than once round the ring: settled or sliding to and
        fro at the bottom), else
        ``"forward whirl"`` or ``"backward whirl"`` by the orbit's mean angular speed
        against the spin; and the whirl frequency (Hz) at the end, the orbit's mean
        angular speed over the last quarter (a whirl that grew in the last half is not
        averaged with its start)."""

        def turned(since: float) -> tuple[float, float]:
            keep = self.t >= since * self.t[-1]
            ang = np.unwrap(np.arctan2(self.orbit[p, keep, 1], self.orbit[p, keep, 0]))
            span = self.t[keep][-1] - self.t[keep][0]
            return float(ang[-1] - ang[0]), float(span)

        if not (self.force[p] > 0).any():
            return "no contact", 0.0
        half = self.t >= 0.5 * self.t[-1]
        contact = float(np.mean(self.force[p, half] > 0))
        angle, _ = turned(0.5)
        end, span = turned(0.75)
        hz = abs(end / span) / (2 * np.pi) if span > 0 else 0.0
        if contact < BOUNCING_BELOW:
            return "bouncing", hz
        if abs(angle) < 2 * np.pi:
            return "resting", 0.0
        forward = angle * (self.speed_rad_s or 1.0) >= 0
        return ("forward whirl" if forward else "backward whirl"), hz

    def onset_s(self, p: int) -> float | None:
        """When the plane's whirl began (s): the onset of the contact that lasts to the
        end of the drop, for a plane that ends whirling; None otherwise."""
        if not self.regime(p)[0].endswith("whirl"):
            return None
        free = np.flatnonzero(self.force[p] <= 0)
        if free.size and free[-1] == self.t.size - 1:
            return None  # out of contact at the end: no contact lasts to it
        return float(self.t[free[-1] + 1]) if free.size else 0.0

    def spin_up_s(self, p: int, fraction: float = 0.9) -> float | None:
        """The ring's spin-up time (s): from the plane's first contact until the ring
        turns at ``fraction`` of the speed at which it rolls on the journal without slip,
        Ω R_j/(R_j + c) at that instant; None for a ring that stands still, a plane never
        touched, or a ring not yet there."""
        touched = np.flatnonzero(self.force[p] > 0)
        if not self.turning[p] or not touched.size:
            return None
        rolling = self.spin * self.journal[p] / (self.journal[p] + self.clearance[p])
        there = np.flatnonzero((self.race_speed[p] * np.sign(rolling)
                                >= fraction * np.abs(rolling))
                               & (np.arange(self.t.size) >= touched[0]) & (rolling != 0))
        return float(self.t[there[0]] - self.t[touched[0]]) if there.size else None

    def coast_down_s(self) -> tuple[float | None, bool]:
        """The time (s) from the drop to standstill and whether it is extrapolated: when
        the spin reached zero in the drop, else the spin at the end over the mean
        deceleration of the drop's last half; (None, False) for a spin held by the
        drive, not slowing, or a drop at standstill. A rotor turning the other way
        (negative speed) slows towards zero from below alike."""
        if self.speed_rad_s == 0:
            return None, False
        spin = np.sign(self.speed_rad_s) * self.spin  # in the sense the rotor turned
        stopped = np.flatnonzero(spin <= 0)
        if stopped.size:
            return float(self.t[stopped[0]]), False
        half = self.t >= 0.5 * self.t[-1]
        span = self.t[half][-1] - self.t[half][0]
        rate = (spin[half][0] - spin[half][-1]) / span if span > 0 else 0.0
        if rate <= 0:
            return None, False
        return float(self.t[-1] + spin[-1] / rate), True

    def to_dict(self) -> dict:
        """The summary an engineer judges, JSON-safe: per plane the peak force, the
        deepest penetration, the largest orbit, the regime, whirl frequency and onset
        (:meth:`onset_s`), the ring's spin-up time (:meth:`spin_up_s`) and final speed;
        the largest excursion at each watched plane, the energy the drop dissipated and
        the work done on the rotor from outside (:attr:`work`), the coast-down time
        (:meth:`coast_down_s`); per plane the peak axial force and penetration and the
        friction heat, and the rotor's largest axial excursion (None where the thrust
        bearing held)."""
        planes = []
        for p, name in enumerate(self.names):
            regime, hz = self.regime(p)
            planes.append({
                "name": name, "peak_force_n": json_float(float(self.peak_force[p])),
                "peak_axial_force_n": json_float(float(self.peak_axial_force[p])),
                "max_axial_penetration_m": json_float(
                    float(max(self.peak_axial_penetration[p], 0.0))),
                "friction_heat_j": json_float(float(self.friction_heat[p, -1])),
                "first_impact_peak_n": json_float(float(self.first_peak_force[p])),
                "max_penetration_m": json_float(float(self.peak_penetration[p])),
                "max_orbit_m": json_float(float(np.hypot(*self.orbit[p].T).max())),
                "regime": regime, "whirl_hz": json_float(hz),
                "whirl_onset_s": self.onset_s(p), "race_spin_up_s": self.spin_up_s(p),
                "final_race_speed_rad_s": json_float(float(self.race_speed[p, -1]))})
        stop, extrapolated = self.coast_down_s()
        return {"duration_s": json_float(float(self.t[-1])),
                "speed_rad_s": json_float(self.speed_rad_s), "modes_hz": self.modes_hz,
                "n_modes": self.n_modes, "impacts": self.impacts, "planes": planes,
                "integrator": self.integrator,
                "watched_max_m": {k: json_float(float(np.hypot(*v.T).max()))
                                  for k, v in self.watched.items()},
                "energy_dissipated_j": json_float(float(self.energy[0] + self.work[-1]
                                                        - self.energy[-1])),
                "external_work_j": json_float(float(self.work[-1])),
                "final_speed_rad_s": json_float(float(self.spin[-1])),
                "amb": [{"channel": name, "failed": name in self.failed,
                         "peak_current_a": json_float(float(np.abs(i).max())),
                         "current_limit_a": json_float(float(lim)),
                         "saturated": bool(sat)}
                        for name, i, lim, sat in zip(self.channels, self.amb_current,
                                                     self.current_limit, self.saturated)],
                "coast_down_s": None if stop is None else json_float(stop),
                "coast_down_extrapolated": extrapolated,
                "axial_thrust_n": json_float(self.axial_thrust),
                "max_axial_m": (None if self.axial_position is None else
                                json_float(float(np.abs(self.axial_position).max())))}


def simulate_drop(cfg, *, speed_rpm: float = 0.0, duration_s: float = 0.5,
                  samples: int = 4001, modes_hz: float | None = None, rtol: float = 1e-8,
                  method: str = "DOP853", model: DropModel | None = None,
                  coast_down: bool = False, drag_torque: float = 0.0,
                  initial: tuple | None = None, unbalance_kgm: float = 0.0,
                  loop: AmbLoop | None = None, loop_state=None, failed=None,
                  overload: tuple | None = None, supports: bool = True,
                  pressure_bar: float | None = None, axial_thrust: float | None = None,
                  progress=None) -> DropResult:
    """Drop the rotor of ``cfg`` onto its touchdown bearings (module docstring).

    Parameters
    ----------
    cfg : RigConfig
        With ``[[amb]]`` and ``[[touchdown]]`` tables.
    speed_rpm : float, optional
        Spin speed (rpm) at the drop: held by the drive, or the start of a coast-down;
        negative, the rotor turns the other way (about −z), as ``[operating] speed_rpm``.
    duration_s : float, optional
        Simulated time after the AMBs let go (s), > 0.
    samples : int, optional
        Output samples, evenly spaced over the drop.
    modes_hz : float, optional
        Modes kept (:func:`drop_model`).
    rtol : float, optional
        ``solve_ivp``'s relative tolerance (its absolute one: ``rtol`` times the smallest
        clearance, and that over 1 ms for the speeds).
    method : str, optional
        ``solve_ivp``'s method.
    model : DropModel, optional
        Built by :func:`drop_model` if omitted.
    coast_down : bool, optional
        The drive lets go too: the spin slows under the rings' friction at the journal
        radii and ``drag_torque``, I_p Ω̇ = −Σ F_t R_j − T_d·tanh(Ω/ω_d) (ω_d = 0.1 rad/s),
        the gyroscopic moments at the instantaneous speed.
    drag_torque : float, optional
        The process and windage torque T_d against the spin (N·m), ≥ 0.
    initial : tuple of two ndarray, shape (n_dof,), optional
        The rotor's nodal displacement (m, rad) and velocity (m/s, rad/s) in the drop
        model's DOFs (:attr:`DropModel.z`) when the AMBs let go, projected on the modes
        kept (:attr:`DropModel.projector`); default the levitated equilibrium at rest.
    unbalance_kgm : float, optional
        A static unbalance U (kg·m, ≥ 0) at the node nearest the centre of mass
        (:attr:`DropModel.cg_rows`): the force U·Ω²·(cos θ, sin θ) turning with the spin's
        angle θ (θ = Ω t held; ∫Ω dt coasting, the spin's own slowing by it left out). Its
        work is counted as work from outside (:attr:`DropResult.work`).
    loop : AmbLoop, optional
        The AMB loop (:func:`ambseal.analysis.drop_loop.amb_loop`); default one without a
        controller where every axis fails, else the reference PID's at ``speed_rpm``. A
        digital controller (``loop.sampled``) is updated at t = 0, T_s, 2 T_s, … (each
        sample ends an integration segment) and its output held between.
    loop_state : ndarray, shape (loop.n_states + loop.n_sampled,), optional
        The loop's states at t = 0 (:func:`ambseal.analysis.drop_levitated.
        levitated_state`); default zero, the loop at rest in the levitated equilibrium.
    failed : sequence of str, optional
        The channels (``loop.names``) whose power is lost at t = 0; default every one
        (the AMBs let go). The others run on under the loop's controller.
    overload : tuple (float, array_like of 2 float), optional
        A step force from t = 0: its position z (m; at the nearest node) and its x, y
        components (N). Its work is counted as work from outside.
    supports : bool, optional
        The seals' and springs' forces on the rotor (:func:`support_matrices`: at the
        drop's speed and pressure, held through it); their work is counted as work from
        outside.
    pressure_bar : float, optional
        The pressure drop across the seals (bar); ``[operating] pressure_bar`` if omitted.
    axial_thrust : float, optional
        The residual thrust (N, +z towards the rotor's far end) on the rotor once the
        thrust bearing lets go, with every AMB axis (``failed`` all of them); default
        ``[drop] axial_thrust``. The rotor then moves axially as a rigid body onto the
        planes with an ``axial_clearance`` (module docstring); otherwise the thrust bearing
        holds it.
    progress : callable, optional
        ``progress(t_s)`` after each segment.

    Returns
    -------
    DropResult

    Raises
    ------
    ConfigError
        As :func:`drop_model`; a duration or sample count out of range; an ``initial``
        or ``loop_state`` of the wrong shape or not finite; a negative or non-finite
        unbalance; a ``failed`` channel the rig does not have, or axes left running
        without a controller; an overload off the rotor or not finite; a thrust not
        finite; a plane pressed deeper than :data:`CRUSHED` of its journal's radius
        (module docstring).
    """
    if not (duration_s > 0 and math.isfinite(duration_s)):
        raise ConfigError(f"drop: duration: expected > 0 s, got {duration_s!r}")
    if not samples >= 2:
        raise ConfigError(f"drop: samples: expected at least 2, got {samples!r}")
    if not (drag_torque >= 0 and math.isfinite(drag_torque)):
        raise ConfigError(f"drop: drag torque: expected >= 0 N·m, got {drag_torque!r}")
    if not (unbalance_kgm >= 0 and math.isfinite(unbalance_kgm)):
        raise ConfigError(f"drop: unbalance: expected >= 0 kg·m, got {unbalance_kgm!r}")
    dm = model or drop_model(cfg, modes_hz)
    m, P = dm.phi.shape[1], len(dm.laws)
    W0 = 2 * np.pi * speed_rpm / 60.0
    if loop is None:
        loop = amb_loop(cfg, dm, speed_rpm, None if failed is not None else "none")
    names = loop.names
    failed = names if failed is None else tuple(failed)
    unknown = [n for n in failed if n not in names]
    if unknown:
        raise ConfigError(f"drop: failed: {', '.join(unknown)}: expected AMB channels of "
                          f"the rig ({', '.join(names)})")
    down = np.array([n in failed for n in names])
    thrust = float(cfg.drop.axial_thrust if axial_thrust is None else axial_thrust)
    if not math.isfinite(thrust):
        raise ConfigError(f"drop: axial thrust: expected a finite force in N, got "
                          f"{axial_thrust!r}")
    stops = [p for p, law in enumerate(dm.axial_laws) if law is not None]
    # the thrust bearing lets go with the radial axes: the rotor then moves axially
    axial = bool(stops) and bool(down.all())
    if not down.all() and not loop.has_controller:
        raise ConfigError("drop: the AMB axes that run on need a controller (the loop "
                          "has none)")
    f_over = np.zeros(m)
    if overload is not None:
        z_o, F_o = float(overload[0]), np.asarray(overload[1], float)
        if F_o.shape != (2,) or not np.isfinite(F_o).all() or not (
                dm.z[0] <= z_o <= dm.z[-1]):
            raise ConfigError(f"drop: overload: expected a position on the rotor "
                              f"({dm.z[0]:g} to {dm.z[-1]:g} m) and a finite force (x, y) "
                              f"in N, got {overload!r}")
        n_o = int(np.argmin(np.abs(dm.z - z_o)))
        over_rows = dm.phi[[4 * n_o, 4 * n_o + 1], :]
        f_over = over_rows.T @ F_o
    Aa, Ba, Ca, Da = loop.coil
    Ak, Bk, Ck, Dk = loop.controller
    na, n_loop = Aa.shape[0], loop.n_states
    i_s = loop.static / loop.ki
    sealed = bool(supports and (cfg.seal or cfg.spring))
    nh = 2 * _housings(cfg) if sealed else 0
    if sealed:
        K_s, C_s, M_s = support_matrices(cfg, dm, speed_rpm, pressure_bar)
        # the modes' unit mass and the housings' own (in M_s)
        M_inv = np.linalg.inv(np.diag(np.r_[np.ones(m), np.zeros(nh)]) + M_s)
        # the offset seals' static loads at the drop's pressure (the AMBs held them at the
        # operating one): on the rotor as the overload is, their work from outside
        for zs, F in _seal_offset_forces(cfg, cfg.operating.pressure_bar
                                        if pressure_bar is None else pressure_bar):
            n_s = int(np.argmin(np.abs(dm.z - zs)))
            f_over = f_over + dm.phi[[4 * n_s, 4 * n_s + 1], :].T @ F
    races = np.flatnonzero(dm.race_inertia > 0)
    sup = [p for p in range(P) if dm.support[p] is not None]
    # the states: modes and their rates, the turning rings, the supports, the AMB loop's
    # (the coil's, the controller's), the spin and its angle when it coasts, the rotor's
    # axial position and speed where it moves axially, each plane's friction heat (J),
    # the housings' x, y and rates, and last the work done on the rotor from outside (J):
    # by the drive holding the spin against the rings' friction, the AMBs' and the
    # seals' forces, the thrust, the unbalance and the overload
    i_loop = 2 * m + races.size + 4 * len(sup)
    i_spin = i_loop + n_loop
    i_ax = i_spin + (2 if coast_down else 0)
    i_heat = i_ax + (2 if axial else 0)
    i_house = i_heat + P  # the housings' x, y, then their rates
    n_y = i_house + 2 * nh + 1
    floor = np.sqrt(2 * GRAVITY * dm.clearance)  # the slowest impact the damping takes
    v0 = floor.copy()
    # axially, a fall through the axial clearance under the thrust (or the weight's
    # acceleration, if larger)
    c_ax = dm.axial_clearance if stops else np.full(P, np.inf)
    floor_ax = np.sqrt(2 * max(abs(thrust) / dm.mass, GRAVITY)
                       * np.where(np.isfinite(c_ax), c_ax, 0.0))
    v0_ax = floor_ax.copy()
    ring = dm.journal + dm.clearance

    def unpack(y):
        eta, deta = y[:m], y[m:2 * m]
        wr = np.zeros(P)
        wr[races] = y[2 * m:2 * m + races.size]
        s = np.zeros((P, 2))
        ds = np.zeros((P, 2))
        base = 2 * m + races.size
        for k, p in enumerate(sup):
            s[p] = y[base + 4 * k:base + 4 * k + 2]
            ds[p] = y[base + 4 * k + 2:base + 4 * k + 4]
        return eta, deta, wr, s, ds

    def spin(y) -> float:
        return float(y[i_spin]) if coast_down else W0

    def angle(t, y) -> float:
        return float(y[i_spin + 1]) if coast_down else W0 * t

    def contacts(t, y, parts=None):
        """Per plane: relative position, δ, normal force, friction, n, t, slip speed
        (``parts``: ``unpack(y)`` where the caller has it)."""
        eta, deta, wr, s, ds = unpack(y) if parts is None else parts
        out = []
        for p in range(P):
            r = dm.planes[p] @ eta - s[p]
            v = dm.planes[p] @ deta - ds[p]
            d = math.hypot(r[0], r[1])
            delta = d - dm.clearance[p]
            if delta <= 0.0 or d == 0.0:
                out.append((r, delta, 0.0, 0.0, None, None, 0.0))
                continue
            n = r / d
            tang = np.array([-n[1], n[0]])
            N = float(dm.laws[p].force(delta, float(n @ v), v0[p]))
            slip = float(tang @ v) + spin(y) * dm.journal[p] - wr[p] * ring[p]
            law = dm.laws[p]
            Ft = float(friction_force(law.friction, N, slip, law.friction_velocity))
            out.append((r, delta, N, Ft, n, tang, slip))
        return out

    def axial_contacts(y, wr):
        """Per plane in axial contact: (plane, δ_a, normal force, friction, slip speed) of
        the rotor's shoulder on the ring's face at the ring's bore radius, the slip that
        of the spin against the ring's."""
        if not axial:
            return []
        z, vz = float(y[i_ax]), float(y[i_ax + 1])
        out = []
        for p in stops:
            delta = abs(z) - c_ax[p]
            if delta <= 0.0:
                continue
            law = dm.axial_laws[p]
            N = float(law.force(delta, vz if z >= 0 else -vz, v0_ax[p]))  # δ̇ = sign(z)·ż
            slip = (spin(y) - wr[p]) * ring[p]
            Ft = float(friction_force(law.friction, N, slip, law.friction_velocity))
            out.append((p, delta, N, Ft, slip))
        return out

    def fade(t):
        """Each failed axis's force's share left at t (module docstring of
        :mod:`ambseal.analysis.drop_loop`): e^{−2t R/L}, 0 at once."""
        tau = np.where(loop.tau > 0, loop.tau, 1.0)
        return np.where(loop.tau > 0, np.exp(-2.0 * t / tau), 0.0)

    def amb(t, y, hold=None):
        """The axes' forces (N), the loop's state derivative, the currents (A) and where
        the loop's reference was clipped; a digital controller's reference is the one
        held (``hold``: (i_ref, clipped), default the last update's). With every axis
        lost the loop drives nothing: its states are held, and the forces are the fading
        ones alone (none where every coil lets go at once)."""
        if all_down:
            if not fading:
                return no_force, no_loop, no_force, no_clip
            b2 = fade(t)
            pull = loop.ks * (loop.axis @ (y[:m] - dm.q0))
            return (b2 * (loop.static + loop.ki * i_fail + pull), no_loop,
                    np.sqrt(b2) * (i_s + i_fail), no_clip)
        dev = y[:m] - dm.q0
        x_a, x_k = y[i_loop:i_loop + na], y[i_loop + na:i_spin]
        sensed = loop.sensor @ dev
        if digital:
            i_ref, clipped = held[-1][1:] if hold is None else hold
        else:
            i_ref, clipped = loop.reference(sensed, x_k)
        i_e = Ca @ x_a + Da @ i_ref
        pull = loop.ks * (loop.axis @ dev)
        fch = loop.static + loop.ki * i_e + pull
        b2 = fade(t)
        fch[down] = (b2 * (loop.static + loop.ki * i_fail + pull))[down]
        current = np.where(down, np.sqrt(b2) * (i_s + i_fail), i_s + i_e)
        return (fch, np.concatenate([Aa @ x_a + Ba @ i_ref, Ak @ x_k + Bk @ sensed]),
                current, clipped & ~down)

    digital = loop.sampled is not None
    held = []  # a digital controller's updates: (t, i_ref, clipped)
    all_down, fading = bool(down.all()), bool((loop.tau > 0).any())
    no_force, no_loop = np.zeros(len(names)), np.zeros(n_loop)
    no_clip = np.zeros(len(names), bool)

    def sample(t, y):
        """The digital controller's update at the sample instant t (module docstring of
        :mod:`ambseal.analysis.drop_loop`): its output held from t."""
        nonlocal x_d
        A_d, B_d, C_d, D_d, _ = loop.sampled
        y_k = loop.sensor @ (y[:m] - dm.q0)
        u = C_d @ x_d + D_d @ y_k
        x_d = A_d @ x_d + B_d @ y_k
        held.append((t, *loop.clip(-u)))

    def rhs(t, y):
        parts = unpack(y)
        eta, deta, wr, s, ds = parts
        f = dm.gravity + f_over
        power = float(f_over @ deta)
        fch, dloop, _, _ = amb(t, y)
        if fch is not no_force:
            f += loop.axis.T @ fch
            power += float(fch @ (loop.axis @ deta))
        if unbalance_kgm:
            W, th = spin(y), angle(t, y)
            fu = unbalance_kgm * W * W * np.array([math.cos(th), math.sin(th)])
            f += dm.cg_rows.T @ fu
            power += float(fu @ (dm.cg_rows @ deta))
        dy = np.empty_like(y)
        dwr = np.zeros(P)
        dsup = {}
        heat = np.zeros(P)  # each plane's friction power (W)
        torque = 0.0
        for p, (r, delta, N, Ft, n, tang, slip) in enumerate(contacts(t, y, parts)):
            F = np.zeros(2) if n is None else -N * n - Ft * tang
            if n is not None:
                f += dm.planes[p].T @ F
            torque -= Ft * dm.journal[p]
            heat[p] = Ft * slip
            if dm.race_inertia[p] > 0:
                w_d = dm.laws[p].friction_velocity / ring[p]
                dwr[p] = (Ft * ring[p] - dm.drag[p] * math.tanh(wr[p] / w_d)) \
                    / dm.race_inertia[p]
            if dm.support[p] is not None:
                ms, ks, cs = dm.support[p]
                dsup[p] = (-F - ks * s[p] - cs * ds[p]) / ms
        if axial:  # the rotor as a rigid body along its axis, on the thrust and the faces
            f_ax = thrust
            for p, _, N, Ft, slip in axial_contacts(y, wr):
                f_ax -= math.copysign(N, y[i_ax])
                torque -= Ft * ring[p]
                heat[p] += Ft * slip
                if dm.race_inertia[p] > 0:
                    dwr[p] += Ft * ring[p] / dm.race_inertia[p]
            dy[i_ax], dy[i_ax + 1] = y[i_ax + 1], f_ax / dm.mass
            power += thrust * float(y[i_ax + 1])
        dy[i_heat:i_heat + P] = heat
        W = spin(y)
        dy[:m] = deta
        acc = f - (C_held if not coast_down else dm.C + W * dm.G) @ deta - dm.K @ eta
        if sealed:  # (I + M_s) η̈ = the rest − K_s Δη − C_s η̇: the seals' force as work
            h, dh = y[i_house:i_house + nh], y[i_house + nh:i_house + 2 * nh]
            pushed = -K_s @ np.r_[eta - dm.q0, h] - C_s @ np.r_[deta, dh]
            both = M_inv @ (np.r_[acc, np.zeros(nh)] + pushed)
            acc = both[:m]
            power += float((pushed[:m] - M_s[:m] @ both) @ deta)
            dy[i_house:i_house + nh], dy[i_house + nh:i_house + 2 * nh] = dh, both[m:]
        dy[m:2 * m] = acc
        if coast_down:
            dy[i_spin] = (torque - drag_torque * math.tanh(W / 0.1)) / dm.polar_inertia
            dy[i_spin + 1] = W
        else:  # the drive supplies the friction's torque
            power -= torque * W
        dy[-1] = power
        dy[i_loop:i_spin] = dloop
        dy[2 * m:2 * m + races.size] = dwr[races]
        base = 2 * m + races.size
        for k, p in enumerate(sup):
            dy[base + 4 * k:base + 4 * k + 2] = ds[p]
            dy[base + 4 * k + 2:base + 4 * k + 4] = dsup[p]
        return dy

    C_held = dm.C + W0 * dm.G  # the damping and gyroscopics at a held speed
    pace = 1.0 / (CYCLE_EVALUATIONS * dm.modes_hz)  # the slowest progress per evaluation

    def paced(fn, start: float):
        """``fn``, counting its evaluations: past CRAWL_EVALUATIONS, a segment advancing
        less than ``pace`` per evaluation raises _Crawling."""
        count = [0]

        def f(t, y):
            count[0] += 1
            if count[0] > CRAWL_EVALUATIONS and t - start < pace * count[0]:
                raise _Crawling
            return fn(t, y)
        return f

    def events(touching):
        """Each plane's radial contact onset or end, then each axial stop's (touching:
        the radial planes' flags, then the stops'), then each plane's and stop's
        penetration reaching CRUSHED of its journal's radius (the drop's end)."""
        evs = []
        for deep in (0.0, CRUSHED):
            for p in range(P):
                def g(t, y, p=p, deep=deep):
                    eta, _, _, s, _ = unpack(y)
                    r = dm.planes[p] @ eta - s[p]
                    return math.hypot(r[0], r[1]) - dm.clearance[p] - deep * dm.journal[p]
                g.terminal = True
                g.direction = -1.0 if not deep and touching[p] else 1.0
                evs.append(g)
            for k, p in enumerate(stops if axial else ()):
                def g(t, y, p=p, deep=deep):
                    return abs(y[i_ax]) - c_ax[p] - deep * dm.journal[p]
                g.terminal = True
                g.direction = -1.0 if not deep and touching[P + k] else 1.0
                evs.append(g)
        return evs

    def crushed(t: float, k: int) -> ConfigError:
        """The refusal of a drop whose plane (radial k < P, else the k − P-th axial stop)
        was pressed :data:`CRUSHED` × its journal's radius deep at t."""
        p, law, how = ((k, dm.laws[k], "") if k < P else
                       (stops[k - P], dm.axial_laws[stops[k - P]], "axial "))
        delta = CRUSHED * dm.journal[p]
        return ConfigError(
            f"drop: at t = {1e3 * t:.4g} ms the journal is pressed {1e6 * delta:.4g} µm "
            f"into the {how}ring of {dm.names[p]} ({100 * CRUSHED:g} % of its "
            f"{1e3 * dm.journal[p]:.4g} mm radius) under "
            f"{law.stiffness * delta ** law.exponent:.3g} N, where the elastic contact "
            "law ends (a contact a tenth as wide as the radius) and long after steel "
            "yields: loads that crush the rings — a seal surge, an overload, the thrust — "
            "leave no drop to simulate")

    y = np.zeros(n_y)
    y[:m] = dm.q0
    if initial is not None:
        u0, du0 = (np.asarray(a, float) for a in initial)
        n_dof = dm.projector.shape[1]
        if u0.shape != (n_dof,) or du0.shape != (n_dof,) or not (
                np.isfinite(u0).all() and np.isfinite(du0).all()):
            raise ConfigError(f"drop: initial: expected a finite displacement and velocity "
                              f"of {n_dof} DOFs each, got shapes {u0.shape}, {du0.shape}")
        y[:m], y[m:2 * m] = dm.projector @ u0, dm.projector @ du0
    n_d = loop.n_sampled
    x_d = np.zeros(n_d)  # a digital controller's state, before its update at t = 0
    if loop_state is not None:
        x0 = np.asarray(loop_state, float)
        if x0.shape != (n_loop + n_d,) or not np.isfinite(x0).all():
            raise ConfigError(f"drop: loop_state: expected {n_loop + n_d} finite states, "
                              f"got shape {x0.shape}")
        y[i_loop:i_spin], x_d = x0[:n_loop], x0[n_loop:].copy()
    if digital:
        sample(0.0, y)
    # what the failed axes' coils carry at the instant they lose power
    x_k0 = y[i_loop + na:i_spin]
    i_ref0 = held[-1][1] if digital else loop.reference(loop.sensor @ (y[:m] - dm.q0),
                                                        x_k0)[0]
    i_fail = Ca @ y[i_loop:i_loop + na] + Da @ i_ref0
    if coast_down:
        y[i_spin] = W0
    grid = np.linspace(0.0, duration_s, samples)
    # absolute tolerances by the state's scale: positions the clearance, speeds that
    # over 1 ms, ring speeds the journal's surface speed over the ring's radius
    c_min = dm.clearance.min()
    atol = np.full(n_y, rtol * c_min / 1e-3)
    atol[:m] = rtol * c_min
    atol[2 * m:2 * m + races.size] = rtol * (abs(W0) * dm.journal[races] / ring[races] + 1.0)
    if coast_down:
        atol[i_spin] = rtol * (abs(W0) + 1.0)
        atol[i_spin + 1] = rtol
    atol[-1] = rtol * dm.mass * GRAVITY * c_min  # the work: the energy of the fall
    atol[i_heat:i_heat + P] = atol[-1]
    atol[i_house:i_house + nh] = rtol * c_min
    if axial:
        atol[i_ax] = rtol * float(c_ax[stops].min())
    # the loop's states by what they add to a current: of the order of the static
    # currents, the limit or 1 mA, whichever is largest
    i_scale = max(float(np.abs(i_s).max(initial=0.0)),
                  float(loop.limit[np.isfinite(loop.limit)].min(initial=0.0)), 1e-3)
    gain = np.abs(np.hstack([Ca, Ck])).max(axis=0, initial=0.0)
    for j in range(n_loop):
        atol[i_loop + j] = rtol * i_scale / (gain[j] if gain[j] > 0 else 1.0)
    for k in range(len(sup)):
        atol[2 * m + races.size + 4 * k:2 * m + races.size + 4 * k + 2] = rtol * c_min
    # a start in contact (an ``initial`` state on a ring) waits for the contact's end
    touching = [c[1] > 0 for c in contacts(0.0, y)] + [False] * (len(stops) if axial else 0)
    for p, c in enumerate(contacts(0.0, y)):
        if c[1] >= CRUSHED * dm.journal[p]:
            raise crushed(0.0, p)
    ts, ys = [0.0], [y.copy()]
    peak_force, peak_delta, first_peak = np.zeros(P), np.zeros(P), np.zeros(P)
    peak_ax_force, peak_ax_delta = np.zeros(P), np.zeros(P)
    first_over = [False] * P  # each plane's first contact ended
    t0, impacts, segments = 0.0, 0, 0
    integrator = method
    n_sample = 1  # the next sample of a digital controller
    while t0 < duration_s:
        if segments > MAX_SEGMENTS:
            raise ConfigError(f"drop: more than {MAX_SEGMENTS} contact onsets and ends by "
                              f"t = {t0:.6g} s (a contact chattering); lower rtol")
        # a digital controller's segments end at its samples
        t_end = min(duration_s, n_sample * loop.sampled[4]) if digital else duration_s
        # a trial step far too long may overflow in the contact's power law; the
        # integrator rejects it (its error estimate is not finite) and halves the step
        with np.errstate(over="ignore", invalid="ignore"):
            try:
                r = solve_ivp(paced(rhs, t0) if method in EXPLICIT else rhs,
                              (t0, t_end), y, method=method, dense_output=True,
                              events=events(touching), rtol=rtol, atol=atol)
            except _Crawling:  # stiff: from here on, the stiff method (module docstring)
                method = STIFF_METHOD
                integrator += f" → {method} from {t0:.6g} s"
                r = solve_ivp(rhs, (t0, t_end), y, method=method, dense_output=True,
                              events=events(touching), rtol=rtol, atol=atol)
        if not r.success or not np.isfinite(r.y).all():
            raise ConfigError(f"drop: the integration failed at t = {r.t[-1]:.6g} s "
                              f"({r.message}); lower rtol or modes_hz")
        sel = grid[(grid > t0) & (grid <= r.t[-1])]
        if sel.size:
            ts.extend(sel.tolist())
            ys.extend(np.asarray(r.sol(sel)).T)
        # the peaks between the integrator's own steps (PEAK_POINTS in each, from its
        # dense output): a contact shorter than the output's sampling is not missed
        steps = np.asarray(r.t, float)
        frac = np.linspace(0.0, 1.0, PEAK_POINTS + 1)[:-1]
        tf = np.append((steps[:-1, None] + np.diff(steps)[:, None] * frac).ravel(),
                       steps[-1])
        Yf = np.asarray(r.sol(tf)).reshape(n_y, -1)
        for p in range(P):
            rel = dm.planes[p] @ Yf[:m]
            vel = dm.planes[p] @ Yf[m:2 * m]
            if p in sup:
                k = 2 * m + races.size + 4 * sup.index(p)
                rel, vel = rel - Yf[k:k + 2], vel - Yf[k + 2:k + 4]
            d = np.hypot(rel[0], rel[1])
            delta = d - dm.clearance[p]
            rate = np.einsum("ij,ij->j", rel, vel) / np.where(d > 0, d, 1.0)
            law = dm.laws[p]
            N = normal_force(delta, rate, law.stiffness, law.exponent, law.damping(v0[p]))
            peak_force[p] = max(peak_force[p], float(N.max()))
            if touching[p] and not first_over[p]:
                first_peak[p] = max(first_peak[p], float(N.max()))
            peak_delta[p] = max(peak_delta[p], float(delta.max()))
        for p in stops if axial else ():
            d_ax = np.abs(Yf[i_ax]) - c_ax[p]
            law = dm.axial_laws[p]
            N = normal_force(d_ax, np.sign(Yf[i_ax]) * Yf[i_ax + 1], law.stiffness,
                             law.exponent, law.damping(v0_ax[p]))
            peak_ax_force[p] = max(peak_ax_force[p], float(N.max()))
            peak_ax_delta[p] = max(peak_ax_delta[p], float(d_ax.max()))
        hit = [k for k, te in enumerate(r.t_events) if te.size]
        if not hit:
            if t_end >= duration_s:
                break
            t0, y = t_end, r.y[:, -1].copy()  # a sample instant
            sample(t0, y)
            n_sample += 1
            continue
        segments += 1
        k = min(hit, key=lambda k: r.t_events[k][0])
        t0 = float(r.t_events[k][0])
        if k >= len(touching):
            raise crushed(t0, k - len(touching))
        y = r.y_events[k][0].copy()
        touching[k] = not touching[k]
        if k >= P:  # an axial stop
            if touching[k]:
                impacts += 1
                v0_ax[stops[k - P]] = max(abs(float(y[i_ax + 1])), floor_ax[stops[k - P]])
            if progress is not None:
                progress(t0)
            continue
        first_over[k] = first_over[k] or not touching[k]
        if touching[k]:
            impacts += 1
            eta, deta, _, s, ds = unpack(y)
            rel = dm.planes[k] @ eta - s[k]
            n = rel / max(math.hypot(*rel), 1e-300)
            v0[k] = max(float(n @ (dm.planes[k] @ deta - ds[k])), floor[k])
        if progress is not None:
            progress(t0)
    t = np.array(ts)
    Y = np.array(ys)
    keep = np.concatenate([[True], np.diff(t) > 0])
    t, Y = t[keep], Y[keep]
    orbit = np.zeros((P, t.size, 2))
    force = np.zeros((P, t.size))
    pen = np.zeros((P, t.size))
    race = np.zeros((P, t.size))
    energy = np.zeros(t.size)
    axial_force = np.zeros((P, t.size))
    for j, yj in enumerate(Y):
        eta, deta, wr, s, ds = unpack(yj)
        e = 0.5 * deta @ deta + 0.5 * eta @ dm.K @ eta - dm.gravity @ eta
        for p, (rel, delta, N, _, _, _, _) in enumerate(contacts(t[j], yj)):
            orbit[p, j], pen[p, j], force[p, j], race[p, j] = rel, delta, N, wr[p]
            law = dm.laws[p]
            if delta > 0:
                e += law.stiffness * delta ** (law.exponent + 1) / (law.exponent + 1)
            if dm.support[p] is not None:
                ms, ks, _ = dm.support[p]
                e += 0.5 * ms * ds[p] @ ds[p] + 0.5 * ks * s[p] @ s[p]
            if dm.race_inertia[p] > 0:
                e += 0.5 * dm.race_inertia[p] * wr[p] ** 2
        if coast_down:  # the spin's energy, which the drive no longer holds
            e += 0.5 * dm.polar_inertia * spin(yj) ** 2
        if axial:
            e += 0.5 * dm.mass * yj[i_ax + 1] ** 2
            for p, delta, N, _, _ in axial_contacts(yj, wr):
                law = dm.axial_laws[p]
                e += law.stiffness * delta ** (law.exponent + 1) / (law.exponent + 1)
                axial_force[p, j] = N
        energy[j] = e
    # a seal's excursion from its own centre: the rotor sits its offset from it
    centre = {f"seal:{s.name}": _seal_offset(s) for s in cfg.seal}
    watched = {k: np.einsum("ij,kj->ki", rows, Y[:, :m]) + centre.get(k, 0.0)
               for k, rows in dm.node_rows.items()}
    j = 0  # a spring on a housing: its clearance is to the housing, which moves
    for i, spr in enumerate(cfg.spring if nh else ()):
        if spr.housing is not None:
            key = f"spring:{spring_label(spr, i)}"
            if key in watched:
                watched[key] = watched[key] - Y[:, i_house + j:i_house + j + 2]
            j += 2
    if digital:  # the reference each output sample saw: the last update's at or before it
        last = np.searchsorted([h[0] for h in held], t, side="right") - 1
        at = [amb(tj, yj, held[j][1:]) for tj, yj, j in zip(t, Y, last)]
    else:
        at = [amb(tj, yj) for tj, yj in zip(t, Y)]
    currents = np.array([a[2] for a in at]).T
    return DropResult(t=t, orbit=orbit, force=force, penetration=pen, race_speed=race,
                      energy=energy, work=Y[:, -1].copy(), watched=watched,
                      impacts=impacts, names=dm.names,
                      speed_rad_s=W0, modes_hz=dm.modes_hz, n_modes=m,
                      spin=np.array([spin(yj) for yj in Y]),
                      peak_force=np.maximum(peak_force, force.max(axis=1)),
                      peak_penetration=np.maximum(peak_delta, pen.max(axis=1).clip(0)),
                      first_peak_force=first_peak, integrator=integrator,
                      journal=dm.journal.copy(), clearance=dm.clearance.copy(),
                      turning=dm.race_inertia > 0, channels=names, failed=failed,
                      amb_current=currents, current_limit=loop.limit.copy(),
                      saturated=np.array([a[3] for a in at]).any(axis=0),
                      axial_position=Y[:, i_ax].copy() if axial else None,
                      axial_force=axial_force,
                      peak_axial_force=np.maximum(peak_ax_force, axial_force.max(axis=1)),
                      peak_axial_penetration=peak_ax_delta, axial_thrust=thrust,
                      friction_heat=Y[:, i_heat:i_heat + P].T.copy())


def drop_verdict(cfg, result: DropResult) -> dict:
    """The drop judged, verdict first: each criterion passed, FAILED, or not graded (with
    why) — no contact outside the touchdown bearings (the largest excursion at each AMB
    against its air gap, :func:`ambseal.design.air_gaps`, at each seal, each
    ``[[spring]]`` and each disk with a ``clearance`` against it, at each AMB's sensor
    with a ``sensor_gap`` against it), each touchdown
    bearing's peak force against ``[drop] force_ratio`` × its ``static_rating`` C₀ (with
    the most loaded ball's contact stress that force gives in a rolling bearing,
    :func:`ambseal.model.rated_contact_stress`: the rig's kinds are ball bearings) — where
    it also stopped the rotor axially, ISO 76's static equivalent load of the peak radial
    and axial forces, P₀ = max(F_r, X₀F_r + Y₀F_a) (:attr:`ambseal.config.Touchdown.
    iso76_factors`; the two peaks combined whether or not they coincide, an upper bound),
    not graded without X₀, Y₀ —, each ring's temperature rise from the friction heat,
    all of it taken into the ring (an upper bound: none into the journal, none conducted
    away), against ``[drop] race_temperature_rise`` where the ring's ``race_mass`` is
    given, each ring's deepest penetration (radial, and axial where it stopped the rotor)
    within ``[drop] penetration_ratio`` × its clearance, and no backward whirl sustained
    over the last half of the drop. A penetration beyond that share, or the rotor through
    a gap where the drop has no contact, leaves the drop model's range: the verdict says
    so first, with where and from when (the first output sample past it), and fails.

    Parameters
    ----------
    cfg : RigConfig
        The rig dropped.
    result : DropResult
        Its drop.

    Returns
    -------
    dict
        ``passed`` (bool: nothing failed), ``verdict`` (one line), ``beyond_range``
        (where and when the drop left its model's range, one line each), ``criteria``
        (``name``, ``outcome`` — ``"passed"``, ``"FAILED"`` or ``"not graded"`` —,
        ``value``, ``limit``) and ``gaps_m`` (each watched plane's gap, m, as
        :attr:`DropResult.watched` names it; None where none is given).
    """
    rows = []

    def row(name, ok, value, limit):
        rows.append({"name": name, "outcome": ("not graded" if ok is None else
                                               "passed" if ok else "FAILED"),
                     "value": value, "limit": limit})

    gaps = {f"amb:{a.name}": s0 for a, s0 in zip(cfg.amb, air_gaps(cfg))}
    gaps.update({f"seal:{s.name}": s.clearance for s in cfg.seal})
    gaps.update({f"spring:{spring_label(s, i)}": s.clearance
                 for i, s in enumerate(cfg.spring) if s.clearance is not None})
    gaps.update({f"sensor:{a.name}": a.sensor_gap for a in cfg.amb
                 if a.sensor_gap is not None})
    gaps.update({f"disk:{_disk_label(d, i)}": d.clearance for i, d in enumerate(cfg.disk)
                 if d.clearance is not None})
    beyond = []  # where and when the drop left its model's range
    for key, gap in gaps.items():
        radius = np.hypot(*result.watched[key].T)
        worst = float(radius.max())
        what = {"amb": "air gap", "sensor": "sensor gap"}.get(key.split(":")[0],
                                                             "clearance")
        where = key.split(":", 1)[1]
        value = f"{1e6 * worst:.4g} µm"
        if gap is not None and worst >= gap:
            when = _first_time(result.t, radius >= gap)
            value += f", through the gap from {when}"
            beyond.append(f"the rotor through the {what} at {where} from {when}, where "
                          "the drop has no contact")
        row(f"no contact at {where} ({what})",
            None if gap is None else worst < gap, value,
            f"{1e6 * gap:.4g} µm" if gap else f"no {what} given")
    share = cfg.drop.penetration_ratio
    for p, td in enumerate(cfg.touchdown):
        for how, c, deepest, depth in (
                ("", td.radial_clearance, float(result.peak_penetration[p]),
                 result.penetration[p]),
                ("axial ", td.axial_clearance, float(result.peak_axial_penetration[p]),
                 None if result.axial_position is None else
                 np.abs(result.axial_position) - (td.axial_clearance or 0.0))):
            if c is None or (how and not deepest > 0):
                continue
            ok = deepest <= share * c
            value = f"{1e6 * deepest:.4g} µm ({deepest / c:.3g} × the clearance)"
            if not ok:
                when = _first_time(result.t, np.asarray(depth) > share * c)
                value += f", beyond from {when}"
                beyond.append(f"{td.name}'s {how}ring pressed {1e6 * deepest:.4g} µm deep "
                              f"({deepest / c:.3g} × its {1e6 * c:.4g} µm {how}clearance) "
                              f"from {when}, where the Hertz contact law no longer holds")
            row(f"{how}penetration within the contact law's range at {td.name}", ok, value,
                f"{share:g} × the {how}clearance = {1e6 * share * c:.4g} µm "
                "([drop] penetration_ratio)")
    ratio, rise_limit = cfg.drop.force_ratio, cfg.drop.race_temperature_rise
    for p, td in enumerate(cfg.touchdown):
        peak = f_r = float(result.peak_force[p])
        f_a = float(result.peak_axial_force[p])
        c0, factors = td.static_rating, td.iso76_factors
        text = f"{f_r:.4g} N"
        if f_a > 0:
            text = f"radial {f_r:.4g} N, axial {f_a:.4g} N"
            if factors is not None:
                peak = max(f_r, factors[0] * f_r + factors[1] * f_a)
                text += f": P₀ = {peak:.4g} N (X₀ {factors[0]:g}, Y₀ {factors[1]:g})"
        axial_open = f_a > 0 and factors is None
        stress = ""
        if c0 and td.kind != "sleeve" and not axial_open:
            stress = (f", {1e-6 * float(rated_contact_stress(peak, c0, 'ball')):.4g} MPa "
                      "at the most loaded ball")
        row(f"peak force at {td.name}",
            None if c0 is None or axial_open else peak <= ratio * c0,
            text + (f" ({peak / c0:.3g} C₀{stress})" if c0 and not axial_open else ""),
            (f"no static_factors (X₀, Y₀) for a {td.kind} bearing's axial force"
             if c0 and axial_open else
             f"{ratio:g} C₀ = {ratio * c0:.4g} N" if c0 else "no static_rating given"))
        if td.race_mass is not None:
            rise = float(result.friction_heat[p, -1]) / (td.race_mass * td.race_specific_heat)
            row(f"ring temperature rise at {td.name}",
                None if rise_limit is None else rise <= rise_limit,
                f"{rise:.3g} K ({float(result.friction_heat[p, -1]):.4g} J of friction heat, "
                "all into the ring)",
                f"{rise_limit:g} K" if rise_limit is not None
                else "no [drop] race_temperature_rise given")
        regime, hz = result.regime(p)
        row(f"no backward whirl at {td.name}", regime != "backward whirl",
            f"{regime}" + (f" at {hz:.3g} Hz" if regime.endswith("whirl") else ""),
            "no sustained backward whirl")
    failed = [r["name"] for r in rows if r["outcome"] == "FAILED"]
    skipped = [r["name"] for r in rows if r["outcome"] == "not graded"]
    line = (f"Drop FAILED: {'; '.join(failed)}" if failed else
            "Drop PASSED" + (f" on what was graded (not graded: {'; '.join(skipped)})"
                             if skipped else ""))
    if beyond:  # its forces past that point are not the machine's: said first
        line = (f"Drop FAILED, beyond the drop model's range: {'; '.join(beyond)} — its "
                f"results from then on do not describe the machine ({line})")
    return {"passed": not failed, "verdict": line, "criteria": rows, "beyond_range": beyond,
            "gaps_m": {k: json_float(g) if g is not None else None for k, g in gaps.items()}}


def _first_time(t: np.ndarray, over: np.ndarray) -> str:
    """``"t = 12.3 ms"``: the first output sample where ``over`` holds, or where none does
    (a peak read between the samples), ``"between the output samples"``."""
    k = np.flatnonzero(over)
    return f"t = {1e3 * float(t[k[0]]):.4g} ms" if k.size else "between the output samples"
