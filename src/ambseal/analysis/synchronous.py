"""Synchronous (unbalance) response of the rotor with its AMB loop as it runs.

A rotating unbalance ``U = m·e`` (kg·m) at axial position z and phase φ is the force
``F_x = U Ω² e^{jφ}``, ``F_y = −j U Ω² e^{jφ}`` (phasors of ``x = Re{X e^{jΩt}}``: a
force turning with the shaft, forward). At each speed Ω the rotor's second-order model
(:func:`ambseal.model.build_system`: gyroscopics ``ΩG``, the seals at the synchronous
frequency, the AMBs' negative stiffness K_s and force factor K_i) is closed by the
controller through the actuator's response ``H_a(jΩ)`` (the ``[actuator]`` model and the
eddy-current lag):

    (K − Ω²M + jΩ(C + ΩG) + B_i H_a(jΩ) K_r(Ω) C_s) q = F_u ,

with ``q`` every node's ``x, y, α, β`` and ``C_s`` the sensors. The controller as it runs
is the discrete one with its computation delay, whose fundamental harmonic through the
sampler and the zero-order hold is ``K_r(Ω) = K_d(e^{jΩT}) · (1 − e^{−jΩT})/(jΩT)``
(Franklin, Powell & Workman, *Digital Control of Dynamic Systems*, 3rd ed., §6.3: the
ZOH's frequency response); the aliases at ``Ω ± 2πk/T`` are left out, a fraction
``(ΩT/2π)²`` of the response at speeds far below the sample rate, as every AMB machine
runs. A continuous controller is evaluated at ``jΩ``; ``None`` leaves the supports to
the rig's springs.

Every node's displacement amplitude is the orbit's semi-major axis
``√((|X|² + |Y|² + |X² + Y²|)/2)`` — what a probe in the worst direction reads, half of
its peak-to-peak value. With a controller, each AMB axis's coil current
``i = H_a(jΩ) i_ref``, ``i_ref = −K_r(Ω) C_s q``, and the force it transmits,
``f = K_i H_e(jΩ) i + K_s x`` (``H_e`` the eddy-current lag, ``x`` the shaft's
displacement along the axis at the actuator: the force law f = K_i i + K_s x), are
amplitudes of one sinusoid each.
"""

from __future__ import annotations

import hashlib
import math
from dataclasses import dataclass

import numpy as np

from ambseal.errors import ModelError
from ambseal.lti import ArrayMemo, freqresp_at, shared_ss, wired
from ambseal.machine import controller_as_runs
from ambseal.model import (
    AXES,
    SealElement,
    SpringElement,
    actuator_matrices,
    amb_factors,
    build_system,
    eddy_lag_matrices,
    seal_values,
)

__all__ = ["Unbalance", "SynchronousResponse", "synchronous_response",
           "synchronous_evaluator", "orbit_semi_major",
           "RunningPlant", "running_plant", "hold_fundamental", "amb_dynamic_stiffness"]


@dataclass(frozen=True)
class Unbalance:
    """One rotating unbalance.

    Parameters
    ----------
    position : float
        Axial position (m).
    amount : float
        U = m·e (kg·m).
    phase_deg : float
        Its angle on the rotor (°), against the other unbalances of a case.
    """

    position: float
    amount: float
    phase_deg: float = 0.0


@dataclass(frozen=True)
class SynchronousResponse:
    """Synchronous response amplitudes over speed, per unbalance case.

    Attributes
    ----------
    speed_hz : ndarray, shape (n_s,)
        Spin speeds (Hz).
    positions_m : ndarray, shape (n_z,)
        Where the amplitude is taken (m).
    amplitude_m : ndarray, shape (n_c, n_s, n_z)
        The orbit's semi-major axis (m, zero-to-peak) per case, speed and position; where
        a probe's direction θ was given, |x cos θ + y sin θ|.
    current_a, force_n : ndarray, shape (n_c, n_s, nu), or None
        Per AMB axis the coil current (A) and the force it transmits (N), amplitudes
        (module docstring); None without a controller.
    axes : tuple of str
        The AMB axes of ``current_a`` and ``force_n`` (``i_<amb>_<axis>``).
    """

    speed_hz: np.ndarray
    positions_m: np.ndarray
    amplitude_m: np.ndarray
    current_a: np.ndarray | None = None
    force_n: np.ndarray | None = None
    axes: tuple = ()


def orbit_semi_major(X: np.ndarray, Y: np.ndarray) -> np.ndarray:
    """Semi-major axis of the ellipse ``(Re{X e^{jθ}}, Re{Y e^{jθ}})`` (module docstring);
    same shape as ``X`` and ``Y``."""
    return np.sqrt(0.5 * (np.abs(X) ** 2 + np.abs(Y) ** 2 + np.abs(X ** 2 + Y ** 2)))


def _siso_at(mats, s: complex) -> complex:
    A, B, C, D = mats
    if A.size == 0:
        return complex(D[0, 0])
    return complex((C @ np.linalg.solve(s * np.eye(A.shape[0]) - A, B) + D)[0, 0])


def hold_fundamental(w: np.ndarray, dt: float) -> np.ndarray:
    """The zero-order hold's fundamental ``(1 − e^{−jΩT})/(jΩT) = e^{−jΩT/2} sinc(ΩT/2π)``
    (module docstring; 1 at standstill), shape of ``w`` (rad/s); ``dt`` the sample time (s)."""
    w = np.asarray(w, float)
    return np.exp(-0.5j * w * dt) * np.sinc(w * dt / (2 * math.pi))


def _controller_at(controller, out_names, in_names, omegas: np.ndarray,
                   values: dict) -> np.ndarray:
    """``K_r(Ω)`` at each speed (n_s × nu × ny, the plant's input × output order; module
    docstring); a scheduled table taken at each speed (a table scheduled on a seal
    coefficient at its value in ``values``), any other controller once."""
    # the plant's channels by name, as every loop is wired (no states: names only)
    names = shared_ss(np.zeros((0, 0)), np.zeros((0, len(in_names))),
                      np.zeros((len(out_names), 0)), np.zeros((len(out_names), len(in_names))),
                      inputs=list(in_names), outputs=list(out_names))

    def at(K, w):
        K = wired(names, K)
        dt = float(K.dt)
        Kw = freqresp_at(K, np.exp(1j * w * dt))
        return Kw * hold_fundamental(w, dt)[:, None, None]

    if hasattr(controller, "statespace_at"):
        return np.concatenate([at(controller_as_runs(controller, w, values), np.array([w]))
                               for w in omegas])
    return at(controller_as_runs(controller, 0.0), omegas)


def amb_dynamic_stiffness(cfg, controller, speeds_hz, *, pressure_bar: float | None = None
                          ) -> tuple[tuple[str, ...], np.ndarray]:
    """Each AMB axis's dynamic stiffness at 1× with the controller as it runs: the force
    per displacement it transmits to a synchronous whirl of its own sensor's reading,

        D(Ω) = K_i H_a(jΩ) H_e(jΩ) K_r,jj(Ω) − K_s ,

    ``K_r`` the controller's fundamental through the sampler and the hold (module
    docstring: the discrete controller with its computation delay), ``jj`` its direct
    term (the axis's current per the axis's own sensor), ``H_a`` the amplifier and ``H_e``
    the eddy-current lag (``[actuator]``); the equivalent stiffness is Re D, the
    equivalent damping Im D/Ω (Schweitzer & Maslen, *Magnetic Bearings*, 2009, §7.2:
    k_eq = K_i Re K − K_s). For a decentralised controller (a PID) this is the AMB's own
    support; a centralised one (H∞, μ) couples the axes, and the direct term is the part
    a support map can draw. A sensor away from its actuator reads another displacement:
    D then relates the force to the sensor's reading.

    Parameters
    ----------
    cfg : RigConfig
        The rig, with ``[[amb]]``.
    controller : DigitalController or ScheduledDigital
        As it runs (a scheduled table at each speed).
    speeds_hz : array_like, shape (n_s,)
        Speeds (Hz), ≥ 0.
    pressure_bar : float, optional
        The seals' pressure drop, for a table scheduled on a seal coefficient (default
        ``[operating] pressure_bar``).

    Returns
    -------
    axes : tuple of str
        ``<amb>_<axis>`` per column (:func:`ambseal.model.channel_names`' order).
    D : ndarray of complex, shape (n_s, n_axes)
        N/m.

    Raises
    ------
    ModelError
        A controller whose signals are not the rig's AMB axes.
    """
    speeds = np.atleast_1d(np.asarray(speeds_hz, dtype=float))
    p = cfg.operating.pressure_bar if pressure_bar is None else float(pressure_bar)
    names = [(amb, ax, ki, ks) for amb in cfg.amb
             for ax, ki, ks in zip(AXES, *amb_factors(amb))]
    axes = tuple(f"{a.name}_{ax}" for a, ax, _, _ in names)
    Kr = _controller_at(controller, [f"y_{n}" for n in axes], [f"i_{n}" for n in axes],
                        2 * math.pi * speeds, seal_values(cfg.seal, p))
    act = (actuator_matrices(cfg.actuator), eddy_lag_matrices(cfg.actuator.eddy_time_constant))
    h = np.array([_siso_at(act[0], 1j * w) * _siso_at(act[1], 1j * w)
                  for w in 2 * math.pi * speeds])
    ki = np.array([k for _, _, k, _ in names])
    ks = np.array([k for _, _, _, k in names])
    direct = np.diagonal(Kr, axis1=1, axis2=2)  # (n_s, n_axes): current per own reading
    return axes, ki[None, :] * h[:, None] * direct - ks[None, :]


def synchronous_response(cfg, controller, speeds_hz, cases, positions_m, *,
                         pressure_bar: float | None = None,
                         angles_deg=None) -> SynchronousResponse:
    """The loop's response to rotating unbalances over speed (module docstring):
    :func:`synchronous_evaluator` of the same arguments at ``speeds_hz``.

    Parameters
    ----------
    cfg : RigConfig
        The rig.
    controller : DigitalController, ScheduledDigital or None
        The controller as it runs; None for a rig on springs alone.
    speeds_hz : array_like, shape (n_s,)
        Spin speeds (Hz), ≥ 0.
    cases : sequence of sequence of Unbalance
        The unbalance cases, ``n_c`` of them; the unbalances of one case act together.
    positions_m : array_like, shape (n_z,)
        Where the amplitude is read (m): each gets a node.
    pressure_bar : float, optional
        The seals' pressure drop (``[operating] pressure_bar`` if omitted).
    angles_deg : sequence of (float or None), optional
        Per position, the direction a probe reads there (° from x towards y): the
        amplitude is then |x cos θ + y sin θ| (a proximity probe), else (None, or the
        argument left out) the orbit's semi-major axis.

    Returns
    -------
    SynchronousResponse

    Raises
    ------
    ModelError
        A controller whose signals are not the rig's (:func:`ambseal.lti.wired`), or a
        singular dynamic stiffness (a
        loop with an undamped mode exactly at a speed).
    """
    return synchronous_evaluator(cfg, controller, cases, positions_m,
                                 pressure_bar=pressure_bar, angles_deg=angles_deg)(speeds_hz)


def synchronous_evaluator(cfg, controller, cases, positions_m, *,
                          pressure_bar: float | None = None, angles_deg=None):
    """:func:`synchronous_response` with the rotor, its bearings and its seals assembled
    once, for any speeds: a search that asks for one speed at a time (a peak, its
    half-power points) then costs a solve per speed, not an FE assembly.

    Parameters
    ----------
    cfg, controller, cases, positions_m, pressure_bar, angles_deg
        As :func:`synchronous_response`.

    Returns
    -------
    callable
        ``evaluate(speeds_hz) → SynchronousResponse``, ``speeds_hz`` array_like of shape
        (n_s,) in Hz, ≥ 0; the same numbers as :func:`synchronous_response` at those
        speeds.

    Raises
    ------
    ModelError
        As :func:`synchronous_response`: probe angles that do not match the positions here,
        a controller not wired to the rig or a singular dynamic stiffness when evaluated.
    """
    zs = np.atleast_1d(np.asarray(positions_m, dtype=float))
    where = tuple(sorted({*(u.position for c in cases for u in c), *map(float, zs)}))
    act = (actuator_matrices(cfg.actuator), eddy_lag_matrices(cfg.actuator.eddy_time_constant))
    p = cfg.operating.pressure_bar if pressure_bar is None else float(pressure_bar)
    base, stiffness = _running_system(cfg, where, p)
    mesh, n = base.mesh, base.n_dof
    F1 = np.zeros((n, len(cases)), dtype=complex)  # per unit Ω²
    for c, case in enumerate(cases):
        for u in case:
            i = mesh.node_at(u.position)
            Fu = u.amount * np.exp(1j * math.radians(u.phase_deg))
            F1[4 * i, c] += Fu
            F1[4 * i + 1, c] += -1j * Fu
    nodes = [mesh.node_at(z) for z in zs]
    rows_x, rows_y = [4 * i for i in nodes], [4 * i + 1 for i in nodes]
    angles = [None] * zs.size if angles_deg is None else list(angles_deg)
    if len(angles) != zs.size:
        raise ModelError(f"synchronous response: {len(angles)} probe angles for "
                         f"{zs.size} positions")
    directional = [j for j, a in enumerate(angles) if a is not None]
    n_cur = len(base.output_names)
    closed = controller is not None and n_cur > 0
    if closed:
        Bi = base.B[:, :n_cur]
        ki = np.linalg.norm(Bi, axis=0)  # each column is Ki along the axis at its node
        ks = np.array([_ks(cfg, name) for name in base.input_names[:n_cur]])
    return _Evaluator(controller, base, stiffness, act, seal_values(cfg.seal, p), F1, zs,
                      rows_x, rows_y, angles, directional,
                      (Bi, ki, ks) if closed else None)


@dataclass(frozen=True)
class _Evaluator:
    """:func:`synchronous_evaluator`'s callable: what it assembled once, and the response
    at any speeds."""
    controller: object
    base: object  # the rotor, AMBs and springs (``_running_system``)
    stiffness: object  # f_hz ↦ its dynamic stiffness with the seals
    act: tuple  # the amplifier's and the eddy-current lag's matrices
    seals: object  # the seals' values the controller is scheduled on
    F1: np.ndarray  # the cases' forces per unit Ω², (n_dof, n_c)
    zs: np.ndarray
    rows_x: list
    rows_y: list
    angles: list
    directional: list
    coils: tuple | None  # (B_i, Ki, Ks) of the current inputs; None: no loop closed

    def __call__(self, speeds_hz) -> SynchronousResponse:
        return _evaluate(self, np.atleast_1d(np.asarray(speeds_hz, dtype=float)))


def _evaluate(e: _Evaluator, speeds: np.ndarray) -> SynchronousResponse:
    """``e``'s response at ``speeds`` (Hz): a solve of the dynamic stiffness per speed."""
    base, F1, zs, rows_x, rows_y = e.base, e.F1, e.zs, e.rows_x, e.rows_y
    cases = F1.shape[1]
    closed = e.coils is not None
    if closed:
        Bi, ki, ks = e.coils
        n_cur = Bi.shape[1]
        Krs = _controller_at(e.controller, base.output_names, base.input_names[:n_cur],
                             2 * math.pi * speeds, e.seals)
        current = np.empty((cases, speeds.size, n_cur))
        force = np.empty_like(current)
    amp = np.empty((cases, speeds.size, zs.size))
    act, angles, directional, stiffness = e.act, e.angles, e.directional, e.stiffness
    for k, f in enumerate(speeds):
        omega = 2 * math.pi * f
        Z = stiffness(f)
        if closed:
            h_amp, h_eddy = (_siso_at(m, 1j * omega) for m in act)
            Z = Z + (Bi * (h_amp * h_eddy)) @ Krs[k] @ base.Cq
        try:
            q = np.linalg.solve(Z, omega ** 2 * F1)
        except np.linalg.LinAlgError:
            raise ModelError(f"synchronous response: the dynamic stiffness is singular at "
                             f"{f:g} Hz (an undamped mode at that speed)") from None
        amp[:, k, :] = orbit_semi_major(q[rows_x], q[rows_y]).T
        for j in directional:
            th = math.radians(angles[j])
            amp[:, k, j] = np.abs(q[rows_x[j]] * math.cos(th) + q[rows_y[j]] * math.sin(th))
        if closed:
            coil = -h_amp * (Krs[k] @ (base.Cq @ q))  # (nu, n_c)
            x = (Bi / ki).T @ q
            current[:, k, :] = np.abs(coil).T
            force[:, k, :] = np.abs(ki[:, None] * h_eddy * coil + ks[:, None] * x).T
    if not closed:
        return SynchronousResponse(speed_hz=speeds, positions_m=zs, amplitude_m=amp)
    return SynchronousResponse(speed_hz=speeds, positions_m=zs, amplitude_m=amp,
                               current_a=current, force_n=force,
                               axes=tuple(base.input_names[:n_cur]))


def _running_system(cfg, where: tuple, p: float):
    """The rotor, AMBs and springs with force inputs at ``where`` (m), and the dynamic
    stiffness at a speed ``f`` (Hz) for whirl at that speed: ``K − Ω²M + jΩ(C + ΩG)`` with
    the seals at pressure drop ``p`` (bar) and the springs' tables at the synchronous
    frequency (P3 §4; a bearing's coefficients over speed), assembled once where no table
    follows the frequency."""
    # the rotor, AMBs and springs once; the seals and the tabulated springs per speed where
    # a table follows the synchronous frequency (P3 §4), else once
    base = build_system(cfg, speed_rpm=0.0, include_seals=False, force_positions=where)
    mesh, n = base.mesh, base.n_dof
    tables = [(i, s) for i, s in enumerate(cfg.spring) if s.tabulated]
    follow = any(s.frequency_dependent for s in cfg.seal) or bool(tables)

    # the tabulated springs as ``base`` holds them (at 0 Hz): what each speed replaces
    at_rest = [np.zeros((n, n)) for _ in range(3)]
    for i, s in tables:
        SpringElement.from_config(s, mesh, i, None, 0.0).assemble(*at_rest)

    def seals(f_hz: float):
        """The seals at ``f_hz``, and the tabulated springs' change from their values at 0
        Hz, which ``base`` holds (a spring with a table has no housing)."""
        M, C, K = (-X for X in at_rest)
        for s in cfg.seal:
            SealElement.from_config(s, mesh, p, f_hz).assemble(M, C, K)
        for i, s in tables:
            SpringElement.from_config(s, mesh, i, None, f_hz).assemble(M, C, K)
        return M, C, K

    def summed(f_hz: float):
        Ms, Cs, Ks = seals(f_hz)
        return base.K + Ks, base.M + Ms, base.C + Cs

    fixed = None if follow else summed(0.0)

    def stiffness(f_hz: float) -> np.ndarray:
        # written into one complex array, real and imaginary parts apart: the same bits as
        # K − Ω²M + jΩ(C + ΩG) formed whole, without its four n × n temporaries (a third
        # of a speed's cost on a fine mesh)
        omega = 2 * math.pi * f_hz
        K, M, C = fixed if fixed is not None else summed(f_hz)
        Z = np.empty(K.shape, dtype=complex)
        np.multiply(M, -(omega ** 2), out=Z.real)
        Z.real += K
        np.multiply(base.G, omega, out=Z.imag)
        Z.imag += C
        Z.imag *= omega
        return Z

    return base, stiffness


@dataclass(frozen=True)
class RunningPlant:
    """The open loop at the running speed: at each speed Ω the plant built at Ω (its
    gyroscopics, its seals at the synchronous frequency) evaluated at ``jΩ``.

    Attributes
    ----------
    speed_hz : ndarray, shape (n_s,)
        The speeds (Hz), each the forcing frequency too.
    Gu : ndarray of complex, shape (n_s, ny, nu)
        Sensors (m) per current reference (A), through the amplifier's current loop and the
        eddy-current lag (``[actuator]``): the plant ``build_plant`` makes, at ``jΩ`` and Ω.
    Gf : ndarray of complex, shape (n_s, ny, nf)
        Sensors (m) per force (N) at each force position, x then y.
    inputs, outputs, forces : tuple of str
        The current inputs ``i_<amb>_<axis>``, sensors ``y_<amb>_<axis>`` and forces
        ``F<k>_<x|y>``, in the order of the arrays' axes.
    """

    speed_hz: np.ndarray
    Gu: np.ndarray
    Gf: np.ndarray
    inputs: tuple
    outputs: tuple
    forces: tuple

    @property
    def nbytes(self) -> int:
        """The arrays' bytes (for :class:`ambseal.lti.ArrayMemo`'s budget)."""
        return int(self.speed_hz.nbytes + self.Gu.nbytes + self.Gf.nbytes)


def running_plant(cfg, speeds_hz, force_positions, *, pressure_bar: float | None = None
                  ) -> RunningPlant:
    """The plant at each speed for forcing at that speed (:class:`RunningPlant`): every
    response to a synchronous force takes the plant at its speed, not the plant frozen at
    one speed with the forcing frequency swept.

    Parameters
    ----------
    cfg : RigConfig
        The rig (with AMBs).
    speeds_hz : array_like, shape (n_s,)
        Speeds (Hz), > 0 (each is the forcing frequency).
    force_positions : sequence of float
        Where the forces act (m).
    pressure_bar : float, optional
        The seals' pressure drop (``[operating] pressure_bar`` if omitted).

    Returns
    -------
    RunningPlant
        Kept for the last few rigs, pressures and grids (the controllers judged at one
        condition close the same open loop).

    Raises
    ------
    ModelError
        A singular dynamic stiffness (an undamped open-loop mode exactly at a speed), or a
        rig without AMBs.

    Notes
    -----
    The seals act on their nodes' x and y alone, so the dynamic stiffness at a pressure
    drop p is the one at the rig's operating pressure drop plus a change of rank two per
    seal: each speed is solved densely once, at the operating pressure drop, and every
    other pressure drop follows by the Sherman–Morrison–Woodbury identity (Golub & Van
    Loan, *Matrix Computations*, 4th ed., §2.1.4) on the seals' DOFs. Where that small
    system's condition number exceeds 1/√ε (6.7e7; the seals then move a mode near the
    speed by more than rounding lets the identity cancel), the speed is solved densely at
    p instead.
    """
    speeds = np.array(np.atleast_1d(np.asarray(speeds_hz, dtype=float)))
    where = tuple(float(z) for z in force_positions)
    p = cfg.operating.pressure_bar if pressure_bar is None else float(pressure_bar)
    rig = cfg.digest()
    key = hashlib.sha256(rig + speeds.tobytes()).digest()
    return _RUNNING.get_digested(key, (p, where),
                                 lambda: _running_plant(cfg, rig, speeds, where, p))


#: The open loops at the running speed of the last conditions: each judged condition's
#: controllers (continuous and as they run) close the same one.
_RUNNING = ArrayMemo(keep=8, keep_bytes=16 * 2**20)

#: The largest condition number of the Woodbury identity's small system (I + ΔZ W) taken:
#: 1/√ε of double precision, so that at least half the digits survive its cancellation;
#: beyond it the speed is solved densely.
_WOODBURY_COND = 1.0 / math.sqrt(np.finfo(float).eps)


class _AtReference:
    """Each speed's dense solve at the rig's operating pressure drop, for one rig and set
    of force positions, kept speed by speed for every pressure drop (:func:`running_plant`'s
    notes): per speed ``(Cq X, Cq X_s, E X, E X_s)`` with ``X`` the solve of the inputs'
    columns, ``X_s`` of the seals' DOFs and ``E`` those DOFs' rows; None where the dynamic
    stiffness there is singular."""

    def __init__(self, cfg, system: "_Running"):
        base = system.base
        self.p, self.mesh, self.n_cur = system.p, base.mesh, system.n_cur
        self.names = (tuple(base.input_names), tuple(base.output_names))
        nodes = sorted({base.mesh.node_at(sl.position) for sl in cfg.seal})
        self.dofs = [4 * i + ax for i in nodes for ax in (0, 1)]
        self.rows: dict[float, tuple | None] = {}

    def solve(self, system: "_Running", speeds) -> None:
        """Solve the speeds not kept yet with ``system`` (at the operating pressure drop)."""
        E = np.zeros((system.base.n_dof, len(self.dofs)))
        E[self.dofs, range(len(self.dofs))] = 1.0
        for f in speeds:
            try:
                X = system.solve(f, E)
            except np.linalg.LinAlgError:
                self.rows[f] = None
                continue
            m = X.shape[1] - E.shape[1]
            CX, EX = system.base.Cq @ X, X[self.dofs]
            self.rows[f] = (CX[:, :m], CX[:, m:], EX[:, :m], EX[:, m:])


class _Running:
    """The open loop's dynamic stiffness at one pressure drop and its input columns."""

    def __init__(self, cfg, where: tuple, p: float):
        self.p = p
        self.base, self.stiffness = _running_system(cfg, where, p)
        self.n_cur = len(self.base.output_names)
        if self.n_cur == 0:
            raise ModelError("the running plant needs AMBs: the rig has none")
        self.act = (actuator_matrices(cfg.actuator),
                    eddy_lag_matrices(cfg.actuator.eddy_time_constant))

    def solve(self, f: float, extra: np.ndarray | None = None) -> np.ndarray:
        """``Z(f)⁻¹ [B_i H_a(jΩ) H_e(jΩ), B_f, extra]`` (raises LinAlgError if singular)."""
        base, n_cur = self.base, self.n_cur
        h_amp, h_eddy = (_siso_at(m, 2j * math.pi * f) for m in self.act)
        cols = [base.B[:, :n_cur] * (h_amp * h_eddy), base.B[:, n_cur:]]
        return np.linalg.solve(self.stiffness(f), np.hstack(cols + ([] if extra is None
                                                                    else [extra])))


def _seal_change(cfg, mesh, dofs: list, p: float, p_ref: float, f: float) -> np.ndarray:
    """The seals' dynamic stiffness at ``p`` less that at ``p_ref`` (bar), whirl at ``f``
    (Hz), on ``dofs`` (their nodes' x and y): ``ΔK − Ω²ΔM + jΩΔC``."""
    omega = 2 * math.pi * f
    D = np.zeros((len(dofs), len(dofs)), complex)
    for sl in cfg.seal:
        at = dofs.index(4 * mesh.node_at(sl.position))
        K1, C1, M1 = SealElement.from_config(sl, mesh, p, f).matrices()
        K0, C0, M0 = SealElement.from_config(sl, mesh, p_ref, f).matrices()
        D[at:at + 2, at:at + 2] += (K1 - K0) - omega ** 2 * (M1 - M0) + 1j * omega * (C1 - C0)
    return D


#: Each rig's and force positions' solves at its operating pressure drop, speed by speed
_REFERENCE = ArrayMemo(keep=4)


def _running_plant(cfg, rig: bytes, speeds: np.ndarray, where: tuple, p: float
                   ) -> RunningPlant:
    made: dict[float, _Running] = {}

    def at(q: float) -> _Running:
        """The system at pressure drop ``q``, built where a speed needs a dense solve."""
        if q not in made:
            made[q] = _Running(cfg, where, q)
        return made[q]

    ref = _REFERENCE.get_digested(
        rig, where, lambda: _AtReference(cfg, at(cfg.operating.pressure_bar)))
    todo = sorted({float(f) for f in speeds} - ref.rows.keys())
    if todo:
        ref.solve(at(ref.p), todo)
    rows = []
    for f in speeds:
        kept = ref.rows[float(f)]
        if kept is not None and (p == ref.p or not ref.dofs):
            rows.append(kept[0])
            continue
        if kept is not None:
            A, Bs, Wr, W = kept
            D = _seal_change(cfg, ref.mesh, ref.dofs, p, ref.p, f)
            cap = np.eye(len(ref.dofs)) + D @ W
            if np.linalg.cond(cap) <= _WOODBURY_COND:
                rows.append(A - Bs @ np.linalg.solve(cap, D @ Wr))
                continue
        try:
            rows.append(at(p).base.Cq @ at(p).solve(f))
        except np.linalg.LinAlgError:
            raise ModelError(f"running plant: the dynamic stiffness is singular at {f:g} Hz "
                             "(an undamped mode at that speed)") from None
    (inputs, outputs), n_cur = ref.names, ref.n_cur
    Y = np.array(rows, dtype=complex).reshape((speeds.size, len(outputs), len(inputs)))
    return RunningPlant(speeds, Y[:, :, :n_cur], Y[:, :, n_cur:], inputs[:n_cur], outputs,
                        inputs[n_cur:])


def _ks(cfg, input_name: str) -> float:
    """K_s (N/m) of the AMB axis ``i_<amb>_<axis>``."""
    for amb in cfg.amb:
        for ax, ks in zip(AXES, amb_factors(amb)[1]):
            if input_name == f"i_{amb.name}_{ax}":
                return float(ks)
    raise ModelError(f"synchronous response: no AMB axis {input_name!r}")
