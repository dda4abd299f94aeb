"""The whole machine: rotor, AMBs, seals and springs as a second-order system and a plant.

M q̈ + (C + Ω G) q̇ + K q = B_u i + B_f f, y = C_q q, with q the node DOFs of
:mod:`ambseal.model.rotor`. Components:

- AMB (thesis P2 Eq. 1): f_ζη = Ki i + Ks s at the bearing node in actuator axes, so
  K gets −Rᵀ diag(Ks) R and B_u gets Rᵀ diag(Ki); the sensor reads R [x, y] at the
  sensor node.
- Seal (Childs' convention, P4 Eq. 3): −f = [K k; −k K] q + [C c; −c C] q̇ + M q̈.
- Spring (the flexible coupling, P4 Eq. 4, or a plain bearing): −f = Rᵀ[kxx kxy; kyx kyy]R q
  + Rᵀ diag(cxx, cyy) R q̇ in its own axes rotated by ``axes_angle_deg``.

The state is x = [q; q̇]; A = [[0, I], [−M⁻¹K, −M⁻¹(C + ΩG)]].
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
import scipy.linalg as sla

from ..config import RigConfig
from ..errors import ModelError
from .amb import actuator_matrices, axes_rotation, eddy_lag_matrices
from .lft import Parameter, Plant
from .rotor import X, Y, Mesh, assemble_rotor, build_mesh

__all__ = ["SecondOrderSystem", "build_system", "mechanical_plant", "build_plant", "AXES"]

AXES = ("zeta", "eta")


@dataclass(frozen=True)
class _Change:
    """A parameter as a low-rank change of K, C or B_u: ΔX = θ U Vᵀ (or θ U e_iᵀ)."""

    name: str
    nominal: float
    unit: str
    kind: str  # "K", "C" or "B"
    U: np.ndarray  # (n_dof, r)
    V: np.ndarray  # (n_dof, r) for K/C; (n_inputs, r) input selector for B


@dataclass(frozen=True)
class SecondOrderSystem:
    """M q̈ + D q̇ + K q = B u, y = C_q q with D = C + Ω G.

    Attributes
    ----------
    M, C, G, K : ndarray, shape (n_dof, n_dof)
        Mass, damping, gyroscopic (per rad/s) and stiffness matrices (SI).
    B : ndarray, shape (n_dof, n_inputs)
        Input matrix: currents (A → N through Ki) then extra forces (N).
    Cq : ndarray, shape (n_outputs, n_dof)
        Sensor displacement outputs (m).
    speed : float
        Spin speed Ω (rad/s).
    """

    mesh: Mesh
    M: np.ndarray
    C: np.ndarray
    G: np.ndarray
    K: np.ndarray
    B: np.ndarray
    Cq: np.ndarray
    speed: float
    input_names: tuple[str, ...]
    output_names: tuple[str, ...]
    changes: tuple[_Change, ...] = field(default=())

    @property
    def n_dof(self) -> int:
        return self.M.shape[0]

    def mass_factor(self):
        """Cholesky factor of M; ModelError if M is not positive definite (e.g. a negative
        seal mass coefficient)."""
        try:
            return sla.cho_factor(self.M)
        except np.linalg.LinAlgError:
            raise ModelError("the mass matrix is not positive definite (check disk masses "
                             "and the seals' M coefficients)") from None

    def state_matrices(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(A, B, C) of the first-order form x = [q; q̇]."""
        n = self.n_dof
        lu = self.mass_factor()
        MiK = sla.cho_solve(lu, self.K)
        MiD = sla.cho_solve(lu, self.C + self.speed * self.G)
        MiB = sla.cho_solve(lu, self.B)
        A = np.block([[np.zeros((n, n)), np.eye(n)], [-MiK, -MiD]])
        B = np.vstack([np.zeros_like(self.B), MiB])
        C = np.hstack([self.Cq, np.zeros_like(self.Cq)])
        return A, B, C

    def poles(self) -> np.ndarray:
        """Eigenvalues (rad/s) of the first-order form, sorted by |λ|."""
        lam = sla.eigvals(self.state_matrices()[0])
        return lam[np.argsort(np.abs(lam), kind="stable")]


def build_system(
    cfg: RigConfig,
    *,
    pressure_bar: float | None = None,
    speed_rpm: float | None = None,
    include_amb: bool = True,
    include_seals: bool = True,
    include_springs: bool = True,
    force_positions: tuple[float, ...] = (),
    seal_frequency_hz: float | None = None,
) -> SecondOrderSystem:
    """Assemble the rig as a second-order system.

    Parameters
    ----------
    cfg : RigConfig
        The rig.
    pressure_bar : float, optional
        Pressure drop across the seals (bar); ``[operating] pressure_bar`` if omitted.
    speed_rpm : float, optional
        Spin speed (rpm); ``[operating] speed_rpm`` if omitted.
    include_amb, include_seals, include_springs : bool
        Leave components out (``modes --no-amb``, ``--free``).
    force_positions : tuple of float
        Positions (m) of extra force inputs, named ``F{k}_x``, ``F{k}_y`` (N).
    seal_frequency_hz : float, optional
        Frequency (Hz) at which frequency-tabulated seal coefficients are taken; by default
        the synchronous frequency Ω/2π (thesis P3 §4's assumption).

    Returns
    -------
    SecondOrderSystem
        With inputs ``{AMB}_{zeta|eta}`` (A) and ``F{k}_{x|y}`` (N), outputs
        ``{AMB}_{zeta|eta}`` (m) when AMBs are included.
    """
    p = cfg.operating.pressure_bar if pressure_bar is None else pressure_bar
    speed = cfg.speed if speed_rpm is None else speed_rpm * 2 * np.pi / 60
    mesh = build_mesh(cfg, tuple(force_positions))
    rot = assemble_rotor(cfg, mesh)
    n = mesh.n_dof
    M, K, G = rot.M.copy(), rot.K.copy(), rot.G
    C = rot.C.copy()
    changes: list[_Change] = []

    def xy(node: int) -> np.ndarray:
        return np.array([4 * node + X, 4 * node + Y])

    def unit(node: int, direction: np.ndarray) -> np.ndarray:
        v = np.zeros(n)
        v[xy(node)] = direction
        return v

    in_names: list[str] = []
    out_names: list[str] = []
    b_cols: list[np.ndarray] = []
    c_rows: list[np.ndarray] = []

    if include_amb:
        for amb in cfg.amb:
            R = axes_rotation(amb.axes_angle_deg)
            nb, ns = mesh.node_at(amb.position), mesh.node_at(amb.sensor_position)
            ki, ks = amb.factors()
            for a, axis in enumerate(AXES):
                r = R[a]  # direction of the axis in x, y
                rb = unit(nb, r)
                K -= ks[a] * np.outer(rb, rb)
                j = len(in_names)
                name = f"{amb.name}_{axis}"
                in_names.append(name)
                out_names.append(name)
                b_cols.append(ki[a] * rb)
                c_rows.append(unit(ns, r))
                changes.append(_Change(f"{amb.name}.Ks_{axis}", ks[a], "N/m", "K",
                                       -rb[:, None], rb[:, None]))
                changes.append(_Change(f"{amb.name}.Ki_{axis}", ki[a], "N/A", "B",
                                       rb[:, None], np.array([[j]])))

    if include_seals:
        for seal in cfg.seal:
            node = mesh.node_at(seal.position)
            f_seal = seal_frequency_hz if seal_frequency_hz is not None else speed / (2 * np.pi)
            v = seal.at(p, f_seal if seal.frequency_dependent else None)
            i = xy(node)
            ex, ey = unit(node, np.array([1.0, 0.0])), unit(node, np.array([0.0, 1.0]))
            skew = np.array([[0.0, 1.0], [-1.0, 0.0]])
            K[np.ix_(i, i)] += v["K"] * np.eye(2) + v["k"] * skew
            C[np.ix_(i, i)] += v["C"] * np.eye(2) + v["c"] * skew
            M[np.ix_(i, i)] += v["M"] * np.eye(2)
            eye2 = np.column_stack([ex, ey])
            rot90 = np.column_stack([ey, -ex])
            changes += [
                _Change(f"{seal.name}.K", v["K"], "N/m", "K", eye2, eye2),
                _Change(f"{seal.name}.k", v["k"], "N/m", "K", eye2, rot90),
                _Change(f"{seal.name}.C", v["C"], "N*s/m", "C", eye2, eye2),
                _Change(f"{seal.name}.c", v["c"], "N*s/m", "C", eye2, rot90),
            ]

    if include_springs:
        for s_i, spring in enumerate(cfg.spring):
            node = mesh.node_at(spring.position)
            R = axes_rotation(spring.axes_angle_deg)
            i = xy(node)
            ks = np.array([[spring.kxx, spring.kxy], [spring.kyx, spring.kyy]])
            cs = np.diag([spring.cxx, spring.cyy])
            K[np.ix_(i, i)] += R.T @ ks @ R
            C[np.ix_(i, i)] += R.T @ cs @ R
            label = spring.name or f"spring{s_i}"
            d = [unit(node, R[0]), unit(node, R[1])]
            for key, (a, b), kind in [
                ("kxx", (0, 0), "K"), ("kyy", (1, 1), "K"), ("kxy", (0, 1), "K"),
                ("kyx", (1, 0), "K"), ("cxx", (0, 0), "C"), ("cyy", (1, 1), "C"),
            ]:
                changes.append(_Change(f"{label}.{key}", getattr(spring, key),
                                       "N/m" if kind == "K" else "N*s/m", kind,
                                       d[a][:, None], d[b][:, None]))

    for k_i, z in enumerate(force_positions):
        node = mesh.node_at(z)
        for a, axis in enumerate(("x", "y")):
            in_names.append(f"F{k_i}_{axis}")
            b_cols.append(unit(node, np.eye(2)[a]))

    B = np.column_stack(b_cols) if b_cols else np.zeros((n, 0))
    Cq = np.vstack(c_rows) if c_rows else np.zeros((0, n))
    return SecondOrderSystem(
        mesh=mesh, M=M, C=C, G=G, K=K, B=B, Cq=Cq, speed=speed,
        input_names=tuple(in_names), output_names=tuple(out_names), changes=tuple(changes),
    )


def mechanical_plant(sys: SecondOrderSystem) -> Plant:
    """The full-order first-order plant of a second-order system, with its LFT channels.

    A stiffness change θ U Vᵀ gives B_θ = [0; −M⁻¹U], C_θ = [Vᵀ, 0]; a damping change
    C_θ = [0, Vᵀ]; a force-factor change B_θ = [0; M⁻¹U], D_θ = e_jᵀ (thesis P1 Eqs. 48–50).
    """
    A, B, C = sys.state_matrices()
    n, m = sys.n_dof, B.shape[1]
    lu = sys.mass_factor()
    params: dict[str, Parameter] = {}
    for ch in sys.changes:
        MiU = sla.cho_solve(lu, ch.U)
        r = ch.U.shape[1]
        zero = np.zeros((n, r))
        if ch.kind == "B":
            Bt = np.vstack([zero, MiU])
            Ct = np.zeros((r, 2 * n))
            Dt = np.zeros((r, m))
            Dt[np.arange(r), ch.V[:, 0].astype(int)] = 1.0
        else:
            Bt = np.vstack([zero, -MiU])
            Ct = np.hstack([ch.V.T, zero.T]) if ch.kind == "K" else np.hstack([zero.T, ch.V.T])
            Dt = np.zeros((r, m))
        params[ch.name] = Parameter(ch.name, float(ch.nominal), ch.unit, Bt, Ct, Dt)
    dofs = ("x", "y", "alpha", "beta")
    qn = [f"{d}{k}" for k in range(sys.mesh.n_nodes) for d in dofs]
    states = tuple(qn + [f"d{s}" for s in qn])
    return Plant(
        A=A, B=B, C=C, D=np.zeros((C.shape[0], m)),
        input_names=sys.input_names, output_names=sys.output_names,
        state_names=states, parameters=params,
    )


def build_plant(
    cfg: RigConfig,
    *,
    reduced: bool = False,
    pressure_bar: float | None = None,
    speed_rpm: float | None = None,
    force_positions: tuple[float, ...] = (),
    states: int | None = None,
    cutoff_hz: float | None = None,
) -> Plant:
    """The rig's plant from current references (and forces) to sensor displacements.

    Full order (every FE mode) or, with ``reduced``, the modal reduction of
    :func:`ambseal.model.reduction.modal_reduction` (``states`` or ``cutoff_hz``, defaults
    from ``[reduction]``, else 8 states). The actuator model of ``[actuator]`` is put in
    series with the current inputs after the reduction, as in thesis P5 Fig. 8.
    """
    from .reduction import modal_reduction

    sys = build_system(cfg, pressure_bar=pressure_bar, speed_rpm=speed_rpm,
                       force_positions=force_positions)
    plant = mechanical_plant(sys)
    if reduced:
        if states is None and cutoff_hz is None:
            states, cutoff_hz = cfg.reduction.states, cfg.reduction.cutoff_hz
            if states is None and cutoff_hz is None:
                states = 8
        plant = modal_reduction(plant, states=states, cutoff_hz=cutoff_hz).plant
    n_cur = 2 * len(cfg.amb)
    if cfg.actuator.eddy_time_constant > 0 and n_cur:
        plant = plant.series_actuator(*eddy_lag_matrices(cfg.actuator.eddy_time_constant),
                                      inputs=list(range(n_cur)), label="eddy")
    if cfg.actuator.model != "none" and n_cur:
        plant = plant.series_actuator(*actuator_matrices(cfg.actuator), inputs=list(range(n_cur)))
    return plant
