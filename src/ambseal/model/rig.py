"""The whole machine: rotor, AMBs, seals and springs as a second-order system and a plant.

M q̈ + (C + Ω G) q̇ + K q = B_u i + B_f f, y = C_q q, with q the node DOFs of
:mod:`ambseal.model.rotor`. The rotor comes from :mod:`ambseal.model.rotor`; each component
is an element that owns its matrices and parameter channels, and this module only
assembles them:

- AMB (thesis P2 Eq. 1): :class:`ambseal.model.amb.AmbElement`.
- Seal (Childs' convention, P4 Eq. 3): :class:`ambseal.model.seal.SealElement`.
- Spring (the flexible coupling, P4 Eq. 4, or a plain bearing):
  :class:`ambseal.model.spring.SpringElement`.

The state is x = [q; q̇]; A = [[0, I], [−M⁻¹K, −M⁻¹(C + ΩG)]].
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
import scipy.linalg as sla

from ambseal.config import RigConfig
from ambseal.errors import ModelError
from ambseal.lti import ArrayMemo
from ambseal.model.amb import AXES, AmbElement, actuator_matrices, eddy_lag_matrices
from ambseal.model.lft import Channel, Parameter, Plant
from ambseal.model.reduction import modal_reduction
from ambseal.model.rotor import (Mesh, X, Y, assemble_rotor, build_mesh,
                                  supported_modal_damping)
from ambseal.model.seal import SealElement
from ambseal.model.spring import SpringElement

__all__ = ["SecondOrderSystem", "build_system", "mechanical_plant", "build_plant", "AXES"]


@dataclass(frozen=True)
class SecondOrderSystem:
    """M q̈ + D q̇ + K q = B u, y = C_q q with D = C + Ω G.

    Attributes
    ----------
    mesh : Mesh
        The rotor's nodes and beam elements; q holds ``[x, y, α, β]`` per node.
    M, C, G, K : ndarray, shape (n_dof, n_dof)
        Mass, damping, gyroscopic (per rad/s) and stiffness matrices (SI).
    B : ndarray, shape (n_dof, n_inputs)
        Input matrix: currents (A → N through Ki) then extra forces (N).
    Cq : ndarray, shape (n_outputs, n_dof)
        Sensor displacement outputs (m).
    speed : float
        Spin speed Ω (rad/s).
    input_names : tuple of str
        ``i_<amb>_<zeta|eta>`` (A), then ``F<k>_<x|y>`` (N).
    output_names : tuple of str
        ``y_<amb>_<zeta|eta>`` (m).
    changes : tuple of Channel
        Every named physical parameter as a low-rank change of K, C or B (thesis P1
        Eqs. 48–50), from the AMBs, seals and springs.
    housing_names : tuple of str
        ``<spring>_housing_<x|y>``: the DOFs after the shaft's (``mesh.n_dof`` on), those
        of the springs' housings.
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
    changes: tuple[Channel, ...] = field(default=())
    housing_names: tuple[str, ...] = field(default=())

    @property
    def n_dof(self) -> int:
        return self.M.shape[0]

    def mass_factor(self):
        """A factor of M for :meth:`mass_solve`: Cholesky where M is symmetric, else LU (a
        spring's cross added mass, mxy ≠ myx, as ROSS's hole-pattern seals carry);
        ModelError if M's symmetric part is not positive definite (e.g. a negative seal
        mass coefficient)."""
        sym = (self.M + self.M.T) / 2
        try:
            chol = sla.cho_factor(sym)
        except np.linalg.LinAlgError:
            raise ModelError("the mass matrix is not positive definite (check disk masses "
                             "and the seals' M coefficients)") from None
        if np.array_equal(sym, self.M):
            return "cholesky", chol
        return "lu", sla.lu_factor(self.M)

    def mass_solve(self, X: np.ndarray, factor=None) -> np.ndarray:
        """M⁻¹ X, by :meth:`mass_factor` (or the ``factor`` it returned)."""
        kind, f = factor if factor is not None else self.mass_factor()
        return sla.cho_solve(f, X) if kind == "cholesky" else sla.lu_solve(f, X)

    def state_matrices(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(A, B, C) of the first-order form x = [q; q̇]."""
        n = self.n_dof
        lu = self.mass_factor()
        MiK = self.mass_solve(self.K, lu)
        MiD = self.mass_solve(self.C + self.speed * self.G, lu)
        MiB = self.mass_solve(self.B, lu)
        A = np.block([[np.zeros((n, n)), np.eye(n)], [-MiK, -MiD]])
        B = np.vstack([np.zeros_like(self.B), MiB])
        C = np.hstack([self.Cq, np.zeros_like(self.Cq)])
        return A, B, C

    def poles(self) -> np.ndarray:
        """Eigenvalues (rad/s) of the first-order form, sorted by |λ|."""
        # numpy's eigvals: the same LAPACK dgeev as scipy's (the same numbers) without
        # holding the GIL, so that `ambseal modes` computes the lowest modes meanwhile
        lam = np.linalg.eigvals(self.state_matrices()[0])
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
        With inputs ``i_{AMB}_{zeta|eta}`` (A) and ``F{k}_{x|y}`` (N), outputs
        ``y_{AMB}_{zeta|eta}`` (m) when AMBs are included.
    """
    p = cfg.operating.pressure_bar if pressure_bar is None else pressure_bar
    speed = cfg.speed if speed_rpm is None else speed_rpm * 2 * np.pi / 60
    f_seal = seal_frequency_hz if seal_frequency_hz is not None else speed / (2 * np.pi)
    mesh = build_mesh(cfg, tuple(force_positions))
    rot = assemble_rotor(cfg, mesh)
    springs = _springs(cfg, mesh, speed / (2 * np.pi)) if include_springs else []
    # the housings' DOFs (x, y each) after the shaft's
    n = mesh.n_dof + 2 * sum(s.housing is not None for s in springs)
    M, C, K, G = (_padded(X, n) for X in (rot.M, rot.C, rot.K, rot.G))
    ambs = [AmbElement.from_config(a, mesh) for a in cfg.amb] if include_amb else []
    others = [SealElement.from_config(s, mesh, p, f_seal)
              for s in (cfg.seal if include_seals else [])]
    others += springs
    names: list[str] = []
    b_cols: list[np.ndarray] = []
    c_rows: list[np.ndarray] = []
    changes: list[Channel] = []
    for amb in ambs:
        amb.assemble(M, C, K)
        changes += amb.channels(n, first_input=len(names))
        names += [f"i_{a}" for a in amb.signal_names]
        b_cols += amb.input_columns(n)
        c_rows += amb.sensor_rows(n)
    for el in others:
        el.assemble(M, C, K)
        changes += el.channels(n)
    if cfg.rotor.supported_modal_damping is not None:
        # the shaft's block where the springs, and so their housings, are left out
        C += _supported_damping(cfg, mesh, rot)[:n, :n]
    out_names = tuple(f"y_{a[2:]}" for a in names)
    for k_i, z in enumerate(force_positions):
        i = mesh.node_at(z)
        for axis, d in (("x", X), ("y", Y)):
            names.append(f"F{k_i}_{axis}")
            b_cols.append(np.zeros(n))
            b_cols[-1][4 * i + d] = 1.0
    B = np.column_stack(b_cols) if b_cols else np.zeros((n, 0))
    Cq = np.vstack(c_rows) if c_rows else np.zeros((0, n))
    housings = tuple(f"{s.label}_housing_{a}" for s in springs if s.housing is not None
                     for a in ("x", "y"))
    return SecondOrderSystem(
        mesh=mesh, M=M, C=C, G=G, K=K, B=B, Cq=Cq, speed=speed,
        input_names=tuple(names), output_names=out_names, changes=tuple(changes),
        housing_names=housings,
    )


def _springs(cfg: RigConfig, mesh: Mesh, frequency_hz: float) -> list[SpringElement]:
    """The rig's springs, each housing given its two DOFs after the shaft's in order, their
    tabulated coefficients at the synchronous frequency ``frequency_hz`` (Hz)."""
    out, next_dof = [], mesh.n_dof
    for i, s in enumerate(cfg.spring):
        out.append(SpringElement.from_config(s, mesh, i, None if s.housing is None
                                             else next_dof, frequency_hz))
        next_dof += 0 if s.housing is None else 2
    return out


def _padded(X: np.ndarray, n: int) -> np.ndarray:
    """X (the shaft's DOFs) in an n × n matrix whose further DOFs are the housings'."""
    out = np.zeros((n, n))
    out[:X.shape[0], :X.shape[1]] = X
    return out


def _supported_damping(cfg: RigConfig, mesh: Mesh, rot) -> np.ndarray:
    """``[rotor.supported_modal_damping]`` as a damping matrix: on the modes of the rotor
    on its springs and seals at standstill — their stiffness and mass at 0 Hz and the
    [operating] pressure, so that the rotor's damping is one matrix at every speed and
    pressure, as ROSS 3's (its bearings at frequency 0); the AMBs are left out, their
    stiffness being the loop's."""
    springs = _springs(cfg, mesh, 0.0)
    n = mesh.n_dof + 2 * sum(s.housing is not None for s in springs)
    M, K, C = _padded(rot.M, n), _padded(rot.K, n), np.zeros((n, n))
    for s in cfg.seal:
        SealElement.from_config(s, mesh, cfg.operating.pressure_bar, 0.0).assemble(M, C, K)
    for el in springs:
        el.assemble(M, C, K)
    spec = cfg.rotor.supported_modal_damping
    return supported_modal_damping(M, K, spec.ratios, spec.others)


def mechanical_plant(sys: SecondOrderSystem) -> Plant:
    """The full-order first-order plant of a second-order system, with its LFT channels.

    A stiffness change θ U Vᵀ gives B_θ = [0; −M⁻¹U], C_θ = [Vᵀ, 0]; a damping change
    C_θ = [0, Vᵀ]; a force-factor change B_θ = [0; M⁻¹U], D_θ = e_jᵀ (thesis P1 Eqs. 48–50).

    Parameters
    ----------
    sys : SecondOrderSystem
        The assembled model (:func:`build_system`) with its parameter changes.

    Returns
    -------
    Plant
        State ``[q; q̇]`` (``2 n_dof`` states), the inputs and outputs of ``sys``
        (``input_names``, ``output_names``; no actuator dynamics), one :class:`Parameter`
        per change of ``sys``.
    """
    A, B, C = sys.state_matrices()
    n, m = sys.n_dof, B.shape[1]
    lu = sys.mass_factor()
    params: dict[str, Parameter] = {}
    for ch in sys.changes:
        MiU = sys.mass_solve(ch.U, lu)
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
    qn = [f"{d}{k}" for k in range(sys.mesh.n_nodes) for d in dofs] + list(sys.housing_names)
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

    Parameters
    ----------
    cfg : RigConfig
        The rig.
    reduced : bool
        Reduce to the lowest modes (thesis P1 §III.4–6) before adding the actuator.
    pressure_bar : float, optional
        Pressure drop across the seals (bar); ``[operating] pressure_bar`` if omitted.
    speed_rpm : float, optional
        Spin speed (rpm); ``[operating] speed_rpm`` if omitted.
    force_positions : tuple of float
        Positions (m) of extra force inputs, named ``F{k}_x``, ``F{k}_y`` (N).
    states : int, optional
        States kept by the reduction (with ``reduced``; this or ``cutoff_hz``, not both).
    cutoff_hz : float, optional
        Keep every mode with |λ|/2π below this frequency (Hz) instead.

    Returns
    -------
    Plant
        Inputs ``i_<axis>`` (A) and ``F{k}_{x|y}`` (N), outputs ``y_<axis>`` (m), the
        physical parameters as LFT channels; the eddy-current lag and the ``[actuator]``
        states appended after the mechanical (or modal) states.

    Raises
    ------
    ModelError
        A non-positive-definite mass matrix, a component or force position without a node,
        or a reduction that cannot be made (:func:`~ambseal.model.reduction.modal_reduction`).
    """

    pressure_bar = cfg.operating.pressure_bar if pressure_bar is None else float(pressure_bar)
    speed_rpm = cfg.operating.speed_rpm if speed_rpm is None else float(speed_rpm)
    force_positions = tuple(float(z) for z in force_positions)
    # the rig by the digest of its validated form, the arguments as the memo's extra key
    rig = cfg.digest()
    return _PLANTS.get_digested(
        rig, (reduced, pressure_bar, speed_rpm, force_positions, states, cutoff_hz),
        lambda: _build_plant(cfg, reduced, pressure_bar, speed_rpm, force_positions, states,
                             cutoff_hz))


#: The last plants built, by rig and arguments: a run asks for the same few plants (its
#: judged pressures, with and without force inputs) in every design's check, digital
#: choice and judgement — 22 builds of 8 plants on the test facility, 0.2 s each at 1 888
#: states — and the API 617 sweeps one plant per cross-coupling for every controller: at
#: least 4, and as many as 64 MB hold. A plant is immutable (its arrays are frozen), so one
#: is handed to every caller.
_PLANTS = ArrayMemo(keep=4, keep_bytes=64 * 2**20)


def reduction_size(cfg: RigConfig, states: int | None = None,
                   cutoff_hz: float | None = None) -> dict:
    """The modal reduction's size as :func:`build_plant` takes it.

    Parameters
    ----------
    cfg : RigConfig
        The rig (its ``[reduction]``).
    states : int, optional
        States to keep.
    cutoff_hz : float, optional
        Keep every mode below this frequency (Hz) instead.

    Returns
    -------
    dict
        ``{"states": ..., "cutoff_hz": ...}``, keyword arguments of
        :func:`ambseal.model.reduction.modal_reduction`: those given, else
        ``[reduction]``'s, else 8 states (the rigid-body modes, thesis P3 §2.2).
    """
    if states is None and cutoff_hz is None:
        states, cutoff_hz = cfg.reduction.states, cfg.reduction.cutoff_hz
        if states is None and cutoff_hz is None:
            states = 8
    return {"states": states, "cutoff_hz": cutoff_hz}


def _build_plant(cfg, reduced, pressure_bar, speed_rpm, force_positions, states, cutoff_hz):
    sys = build_system(cfg, pressure_bar=pressure_bar, speed_rpm=speed_rpm,
                       force_positions=force_positions)
    plant = mechanical_plant(sys)
    if reduced:
        plant = modal_reduction(plant, **reduction_size(cfg, states, cutoff_hz)).plant
    n_cur = 2 * len(cfg.amb)
    if cfg.actuator.eddy_time_constant > 0 and n_cur:
        plant = plant.series_actuator(*eddy_lag_matrices(cfg.actuator.eddy_time_constant),
                                      inputs=list(range(n_cur)), label="eddy")
    if cfg.actuator.model != "none" and n_cur:
        plant = plant.series_actuator(*actuator_matrices(cfg.actuator), inputs=list(range(n_cur)))
    return plant
