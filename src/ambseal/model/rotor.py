"""Mesh and assembly of the rotor: shaft elements and disks.

DOF map
-------
Node ``n`` (0-based, left to right along the rotor axis z) owns the global DOFs
``4n + 0`` (x, m), ``4n + 1`` (y, m), ``4n + 2`` (α, rotation about x, rad) and
``4n + 3`` (β, rotation about y, rad). The assembled matrices satisfy
M q̈ + (C + Ω G) q̇ + K q = f (Friswell et al. 2010, Eq. 5.95), with C and the
bearing/seal/spring terms added by :mod:`ambseal.model.rig`.

The mesh puts a node at every section boundary and at every component position (disks,
AMBs, sensors, seals, springs); each ``[[shaft]]`` section is first divided into its
``elements`` equal elements and those are split where a component falls inside one; the
parts of a tapered section are conical elements with the section's diameters at their ends.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.linalg as sla

from ambseal.config import MAX_ELEMENTS, RigConfig, node_tolerance
from ambseal.errors import ConfigError, ModelError
from ambseal.lti import ArrayMemo
from ambseal.model.fe import BeamElement, CouplingElement, DiskElement, LayeredBeam

__all__ = ["Mesh", "build_mesh", "RotorMatrices", "assemble_rotor", "dof",
           "supported_modal_damping", "RIGID_BELOW_RAD_S", "rigid_basis"]

X, Y, ALPHA, BETA = 0, 1, 2, 3


def dof(node: int, direction: int) -> int:
    """Global DOF index of ``direction`` (0 x, 1 y, 2 α, 3 β) at ``node``."""
    return 4 * node + direction


@dataclass(frozen=True)
class Mesh:
    """Node positions and the elements between them.

    Attributes
    ----------
    z : ndarray, shape (n_nodes,)
        Node positions (m) from the shaft's left end.
    elements : tuple of BeamElement, LayeredBeam or CouplingElement
        ``elements[e]`` joins nodes ``e`` and ``e + 1`` (a section with ``layers``: all its
        tubes; a ``coupling`` section: the coupling).
    """

    z: np.ndarray
    elements: tuple[BeamElement | LayeredBeam | CouplingElement, ...]

    @property
    def n_nodes(self) -> int:
        return len(self.z)

    @property
    def n_dof(self) -> int:
        return 4 * len(self.z)

    def node_at(self, position: float) -> int:
        """Index of the node at ``position`` (m); raises ModelError if there is none."""
        i = int(np.argmin(np.abs(self.z - position)))
        if abs(self.z[i] - position) > _snap(self.z[-1]):
            raise ModelError(f"no node at z = {position} m")
        return i


def _snap(length: float) -> float:
    """Tolerance (m) within which a component is put on an existing node (the rig file's
    rule, :func:`ambseal.config.node_tolerance`, by which two touchdown planes on one node
    are refused)."""
    return node_tolerance(length)


def _piece(tube, a: float, b: float) -> dict:
    """The diameters of the part ξ ∈ [a, b] of a (possibly tapered) tube, ξ = z/length
    along its section: a tapered tube's diameters are linear in z, so every part of it is
    a conical element of its own, with no stepping."""
    do_r = tube.outer_diameter if tube.outer_diameter_right is None else (
        tube.outer_diameter_right)
    di_r = tube.inner_diameter if tube.inner_diameter_right is None else (
        tube.inner_diameter_right)
    if do_r == tube.outer_diameter and di_r == tube.inner_diameter:
        return {"outer_diameter": tube.outer_diameter, "inner_diameter": tube.inner_diameter}

    def at(left, right, x):
        return left + (right - left) * x

    return {"outer_diameter": at(tube.outer_diameter, do_r, a),
            "inner_diameter": at(tube.inner_diameter, di_r, a),
            "outer_diameter_right": at(tube.outer_diameter, do_r, b),
            "inner_diameter_right": at(tube.inner_diameter, di_r, b)}


def build_mesh(cfg: RigConfig, extra_positions: tuple[float, ...] = ()) -> Mesh:
    """Mesh the shaft of a rig.

    Parameters
    ----------
    cfg : RigConfig
        The rig.
    extra_positions : tuple of float
        More positions (m) that need a node (e.g. extra force inputs).

    Returns
    -------
    Mesh
        A node at every section boundary and component position; each section divided into
        its ``elements`` equal elements, split where a component falls inside one; a
        section with ``layers`` gives :class:`LayeredBeam` elements.
    """
    beam_tim = cfg.rotor.beam == "timoshenko"
    positions = [d.position for d in cfg.disk]
    positions += [s.position for s in cfg.seal] + [s.position for s in cfg.spring]
    for a in cfg.amb:
        positions += [a.position, a.sensor_position]
    positions += list(extra_positions)
    length = cfg.length
    tol = _snap(length)

    z_nodes = [0.0]
    elements: list[BeamElement | LayeredBeam | CouplingElement] = []
    z0 = 0.0
    for i, sec in enumerate(cfg.shaft):
        z1 = z0 + sec.length
        cuts = set(np.linspace(z0, z1, sec.elements + 1)[1:-1].tolist())
        cuts |= {p for p in positions if z0 + tol < p < z1 - tol}
        if sec.coupling is not None:
            if cuts:  # its two halves sit on its end nodes: nothing lies between them
                raise ConfigError(f"shaft[{i}].coupling: a component at z = {min(cuts):g} m "
                                  f"lies inside the coupling ({z0:g}–{z1:g} m); place it on "
                                  "a shaft section")
            elements.append(CouplingElement(length=sec.length, **sec.coupling.model_dump()))
            z_nodes.append(z1)
            z0 = z1
            continue
        left = z0
        for p in sorted(cuts) + [z1]:
            if p - left < tol or (p < z1 and z1 - p < tol):
                continue
            tubes = tuple(
                BeamElement(
                    length=p - left,
                    **_piece(t, (left - z0) / sec.length, (p - z0) / sec.length),
                    E=cfg.materials[t.material].E,
                    shear_modulus=cfg.materials[t.material].shear_modulus,
                    rho=cfg.materials[t.material].rho,
                    timoshenko=beam_tim,
                    rotary_inertia=t.rotary_inertia,
                    gyroscopic=t.gyroscopic,
                    axial_force=t.axial_force,
                    torque=t.torque,
                    rayleigh_alpha=t.rayleigh_alpha,
                    rayleigh_beta=t.rayleigh_beta,
                )
                for t in (sec, *sec.layers)
            )
            elements.append(tubes[0] if len(tubes) == 1 else LayeredBeam(tubes))
            z_nodes.append(p)
            left = p
        z0 = z1
        if len(elements) > MAX_ELEMENTS:  # before any matrix: a dense model would not fit
            raise ConfigError(
                f"shaft: the mesh has more than {MAX_ELEMENTS} beam elements (the sections' "
                f"{sum(s.elements for s in cfg.shaft)} elements, split at each of "
                f"{len(set(positions))} component positions): at most {MAX_ELEMENTS}, the "
                "rig file's bound; use fewer elements or place components on element "
                "boundaries")
    return Mesh(z=np.asarray(z_nodes), elements=tuple(elements))


def rigid_basis(mesh: Mesh) -> np.ndarray:
    """The rigid-body motions of the rotor in its DOFs: x and y translations, and tilts
    about the shaft's left end (x = z·t with β = t; y = z·t with α = −t, the slopes of this
    DOF map).

    Parameters
    ----------
    mesh : Mesh
        The rotor's nodes (their positions z, m).

    Returns
    -------
    ndarray, shape (n_dof, 4)
        Columns: x translation, y translation, tilt in the x–z plane, tilt in the y–z
        plane; the free–free stiffness maps each to zero.
    """
    phi = np.zeros((mesh.n_dof, 4))
    phi[X::4, 0] = 1.0
    phi[Y::4, 1] = 1.0
    phi[X::4, 2], phi[BETA::4, 2] = mesh.z, 1.0
    phi[Y::4, 3], phi[ALPHA::4, 3] = mesh.z, -1.0
    return phi


@dataclass(frozen=True)
class RotorMatrices:
    """Assembled shaft-and-disk matrices, each (n_dof, n_dof).

    M q̈ + (C + Ω G) q̇ + K q = f (Friswell et al. 2010, Eq. 5.95), q the node DOFs
    ``[x, y, α, β]`` of ``mesh``.

    Attributes
    ----------
    mesh : Mesh
        The nodes and elements; ``n_dof = 4·n_nodes``.
    M : ndarray, shape (n_dof, n_dof)
        Mass matrix (kg, kg·m²).
    K : ndarray, shape (n_dof, n_dof)
        Stiffness matrix (N/m, N·m/rad); not symmetric where a section carries torque.
    C : ndarray, shape (n_dof, n_dof)
        Structural damping (N·s/m): the rotor's ``modal_damping`` on every free–free
        elastic mode, plus the rotor's Rayleigh damping ``rayleigh_alpha``·M +
        ``rayleigh_beta``·K and each shaft tube's own (:meth:`BeamElement.C`).
    G : ndarray, shape (n_dof, n_dof)
        Gyroscopic matrix per unit spin speed (multiplied by Ω in rad/s).
    """

    mesh: Mesh
    M: np.ndarray
    K: np.ndarray
    C: np.ndarray
    G: np.ndarray

    def rigid(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """The rotor as a rigid body: its mass and gyroscopic matrices on
        :func:`rigid_basis` (Friswell et al. 2010, §3.5: m, m, I_t and I_p about the
        centre of mass after a change of origin).

        Returns
        -------
        (M_r, G_r, Phi) : ndarray
            Shapes (4, 4), (4, 4) (per unit spin speed, rad/s) and (n_dof, 4).
        """
        phi = rigid_basis(self.mesh)
        return phi.T @ self.M @ phi, phi.T @ self.G @ phi, phi

    @property
    def mass(self) -> float:
        """Total rotor mass (kg): shaft plus disks."""
        ones = np.zeros(self.M.shape[0])
        ones[X::4] = 1.0
        return float(ones @ self.M @ ones)


def assemble_rotor(cfg: RigConfig, mesh: Mesh | None = None) -> RotorMatrices:
    """Assemble the free–free rotor (shaft elements and disks) of a rig.

    Parameters
    ----------
    cfg : RigConfig
        The rig: shaft, materials, disks and the rotor's modal damping.
    mesh : Mesh, optional
        The mesh to assemble on; :func:`build_mesh` of ``cfg`` if omitted.

    Returns
    -------
    RotorMatrices
        M, K, C and G of shaft and disks; no bearings, seals or springs (those are added by
        :mod:`ambseal.model.rig`).

    Raises
    ------
    ModelError
        A disk whose position has no node in ``mesh``.
    """
    mesh = mesh or build_mesh(cfg)
    n = mesh.n_dof
    M = np.zeros((n, n))
    K = np.zeros((n, n))
    G = np.zeros((n, n))
    C_shaft = np.zeros((n, n))
    for e, el in enumerate(mesh.elements):
        s = slice(4 * e, 4 * e + 8)
        M[s, s] += el.M()
        K[s, s] += el.K()
        G[s, s] += el.G()
        C_shaft[s, s] += el.C()
    for d in cfg.disk:
        de = DiskElement(d.mass, d.Ip, d.Id)
        s = slice(4 * mesh.node_at(d.position), 4 * mesh.node_at(d.position) + 4)
        M[s, s] += de.M()
        G[s, s] += de.G()
    # a torque's stiffness has a circulatory (skew) part: the free–free modes that the
    # structural damping is set on are those of the conservative part
    C = modal_damping(M, (K + K.T) / 2, cfg.rotor.modal_damping)
    alpha, beta = cfg.rotor.rayleigh_alpha, cfg.rotor.rayleigh_beta
    if alpha or beta or np.any(C_shaft):
        # the rotor's Rayleigh damping is of shaft and disks, as ROSS 3's Rotor(alpha, beta)
        C = C + C_shaft + alpha * M + beta * K
    return RotorMatrices(mesh=mesh, M=M, K=K, C=C, G=G)


#: The damping matrices of the last rotors: every plant of a rig (each speed, pressure and
#: set of force inputs) is assembled on one or two meshes, and the generalised eigenproblem
#: of a 230-element rotor costs 0.4 s, its digest 15 ms.
_DAMPING = ArrayMemo(keep=4)


def modal_damping(M: np.ndarray, K: np.ndarray, zeta: float) -> np.ndarray:
    """Damping matrix giving every free–free elastic mode the damping ratio ``zeta``.

    C = M Φ diag(2ζω_r) Φᵀ M with Φ the mass-normalised modes of (K, M); rigid-body modes
    (ω ≈ 0) get none (Craig & Kurdila, *Fundamentals of Structural Dynamics*, 2006, §10.2).

    Parameters
    ----------
    M, K : numpy.ndarray, shape (n, n)
        Symmetric mass (positive definite) and stiffness matrices.
    zeta : float
        Modal damping ratio.

    Returns
    -------
    numpy.ndarray, shape (n, n)
        Read-only (kept for the last rotors: copy it to change it).
    """
    return _DAMPING.get((M, K), float(zeta), lambda: _modal_damping(M, K, zeta))


def _modal_damping(M: np.ndarray, K: np.ndarray, zeta: float) -> np.ndarray:
    n = M.shape[0]
    if zeta == 0.0:
        return _read_only(np.zeros((n, n)))
    w2, phi = sla.eigh(K, M)
    w = np.sqrt(np.clip(w2, 0.0, None))
    w[w < 1e-6 * max(w.max(), 1.0)] = 0.0
    Mphi = M @ phi
    return _read_only((Mphi * (2 * zeta * w)) @ Mphi.T)


#: Modes below this (rad/s, 1 rpm) are rigid-body modes of the supported rotor: ROSS 3's
#: rule (``Rotor._compute_modal_damping``), which :func:`supported_modal_damping` follows.
RIGID_BELOW_RAD_S = 2 * np.pi / 60


def supported_modal_damping(M: np.ndarray, K: np.ndarray, ratios, others: float = 0.0
                            ) -> np.ndarray:
    """Damping matrix giving the modes of (K, M) — a rotor on its supports — the damping
    ratios ``ratios`` in ascending frequency and ``others`` above them.

    C = M Φ diag(2ζ_r ω_r) Φᵀ M with Φ the mass-normalised modes (Craig & Kurdila,
    *Fundamentals of Structural Dynamics*, 2006, §10.2), as ROSS 3's
    ``Rotor(modal_damping_ratio=ratios, default_damping_ratio=others)``: modes below
    :data:`RIGID_BELOW_RAD_S` (rigid-body) and modes of negative stiffness get none and are
    not counted; a stiffness with a circulatory part (torque) sets the modes of its
    symmetric part.

    Parameters
    ----------
    M, K : numpy.ndarray, shape (n, n)
        Mass (symmetric, positive definite) and stiffness matrices of the supported rotor.
    ratios : sequence of float
        ζ of the lowest modes that are not rigid-body modes, ascending.
    others : float
        ζ of every mode above them.

    Returns
    -------
    numpy.ndarray, shape (n, n)
        Read-only (kept for the last rotors: copy it to change it).
    """
    zeta = tuple(float(z) for z in ratios)
    return _DAMPING.get((M, K), ("supported", zeta, float(others)),
                        lambda: _supported(M, (K + K.T) / 2, zeta, float(others)))


def _supported(M: np.ndarray, K: np.ndarray, ratios: tuple, others: float) -> np.ndarray:
    w2, phi = sla.eigh(K, M)  # ascending, M-normalised
    w = np.sqrt(np.clip(w2, 0.0, None))
    flexible = np.flatnonzero(w2 >= RIGID_BELOW_RAD_S ** 2)
    zeta = np.zeros(len(w))
    zeta[flexible] = others
    first = flexible[:len(ratios)]
    zeta[first] = ratios[:len(first)]
    Mphi = M @ phi
    return _read_only((Mphi * (2 * zeta * w)) @ Mphi.T)


def _read_only(a: np.ndarray) -> np.ndarray:
    a.setflags(write=False)
    return a
