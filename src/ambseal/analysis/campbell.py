"""Closed-loop modes against speed: Campbell diagram, log decrement, whirl and mode shapes.

The modes of the *closed loop* — rotor, AMBs, seals and springs of the full-order plant with
the actuator states, closed by the controller (its states included) exactly as the judgement
closes it (:func:`ambseal.analysis.loops.closed_loop`, ``u = −K y``) — not of a rotor on
equivalent bearing coefficients taken at one frequency.

For an eigenvalue λ = σ + jω_d of the closed-loop state matrix (ω_d > 0):

* damped natural frequency f_d = ω_d / 2π (Hz);
* damping ratio ζ = −σ / |λ|;
* logarithmic decrement δ = −2π σ / ω_d = 2πζ / √(1 − ζ²) (API 684, §1.3; Friswell et al.,
  *Dynamics of Rotating Machines*, 2010, §3.6): the log of the ratio of successive peaks of a
  free decay; API 684's level-I screening asks δ ≥ 0.1 (:data:`API684_LOG_DEC`).

Whirl from the mode shape (Friswell et al. 2010, §3.6.2): at a node with complex lateral
amplitudes (X, Y) the orbit x = Re(X e^{jω_d t}), y = Re(Y e^{jω_d t}) turns in the sense of
spin (x towards y, forward) when κ = 2 Im(X Ȳ)/(|X|² + |Y|²) > 0 and against it (backward)
when κ < 0; |κ| = 1 is a circle, 0 a line. A mode is *forward* or *backward* when every node
that moves (amplitude above 1 % of the largest) turns that way, *planar* when none turns
(|κ| < 0.01 everywhere), else *mixed*.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import scipy.linalg as sla
from scipy.optimize import linear_sum_assignment

from ambseal.analysis.cases import run_cases
from ambseal.lti import json_float, json_list
from ambseal.model import (
    RIGID_BODY_RAD_S,
    bending_limit_hz,
    build_mesh,
    build_plant,
    classify_poles,
    free_bending_hz,
    poles_near_zero,
    seal_values,
)
from ambseal.robust import decay_rate, is_stable, unstable_poles

__all__ = ["AF_CRITICAL", "API684_LOG_DEC", "OVERDAMPED_ZETA", "ClosedLoopModes", "Crossing",
           "Campbell", "log_decrement", "amplification_factor", "resonant",
           "lowest_log_decrement", "whirl_of",
           "closed_loop_state_matrix", "state_matrix_as_run", "closed_loop_modes", "modes_as_run",
           "poles_as_run",
           "modes_of_state_matrix", "modes_of_sampled_loop", "track_modes", "open_loop_modes",
           "campbell"]

#: API 684 (2nd ed., 2005) level-I stability screening: log decrement of every mode ≥ 0.1.
API684_LOG_DEC = 0.1
#: A mode damped at ζ ≥ 1/√2 has no resonance peak (its second-order response falls
#: monotonically with frequency): its 1× crossing is no critical speed and is listed apart.
OVERDAMPED_ZETA = 1.0 / math.sqrt(2.0)
#: API 684 (2nd ed., 2005) counts a resonance as a critical speed when its amplification
#: factor AF ≈ π/δ is at least 2.5 (δ ≤ 1.26); API 617 asks no separation margin of one
#: below it.
AF_CRITICAL = 2.5
#: A node counts in the whirl classification when it moves more than this share of the
#: largest node amplitude of the mode.
_MOVING = 0.01
#: |κ| below this is no turning at all (a line orbit).
_PLANAR = 0.01


def log_decrement(poles: np.ndarray) -> np.ndarray:
    """δ = −2π Re λ / Im λ of eigenvalues λ (rad/s) with Im λ > 0 (API 684; Friswell §3.6).

    Parameters
    ----------
    poles : array_like of complex
        Eigenvalues λ (rad/s), any shape; those with Im λ ≤ 0 give no meaningful δ.

    Returns
    -------
    ndarray of float
        δ for each pole, the shape of ``poles`` (positive: decaying).
    """
    p = np.asarray(poles, complex)
    return -2 * np.pi * p.real / p.imag


def amplification_factor(log_dec) -> np.ndarray:
    """API 684's amplification factor of a mode from its log decrement, AF ≈ π/δ (API 684
    §1.3.3: AF = N_c/(N_2 − N_1), the half-power bandwidth, ≈ 1/(2ζ) ≈ π/δ at light
    damping); inf for δ ≤ 0.

    Parameters
    ----------
    log_dec : array_like of float
        Log decrements δ (-), any shape.

    Returns
    -------
    ndarray of float
        AF, the shape of ``log_dec``.
    """
    d = np.asarray(log_dec, float)
    with np.errstate(divide="ignore"):
        return np.where(d > 0, np.pi / np.where(d > 0, d, 1.0), np.inf)


def resonant(log_dec) -> np.ndarray:
    """Whether a mode is a resonance in API 684's sense: its amplification factor
    (:func:`amplification_factor`, π/δ) is at least :data:`AF_CRITICAL` (2.5), the factor
    from which API 684 and API 617 count a resonance as a critical speed. That is
    δ ≤ π/2.5 = 1.257, ζ ≤ 0.196 (ζ ≤ 0.2 by the half-power AF = 1/(2ζ)); a mode damped
    more — an AMB controller's overdamped rigid-body pole with a small imaginary part, at
    ζ ≈ 1 — has no resonance to speak of. A mode with δ ≤ 0 is resonant.

    Parameters
    ----------
    log_dec : array_like of float
        Log decrements δ (-), any shape; NaN is not resonant.

    Returns
    -------
    ndarray of bool
        The shape of ``log_dec``.
    """
    return amplification_factor(log_dec) >= AF_CRITICAL


def lowest_log_decrement(poles: np.ndarray, max_hz: float) -> tuple[float, float]:
    """(δ, f_d in Hz) of the least damped oscillating pole with f_d ≤ ``max_hz``, by log
    decrement; (nan, nan) when there is none."""

    p = np.asarray(poles, complex)
    p = p[(p.imag >= RIGID_BODY_RAD_S) & (p.imag <= 2 * np.pi * max_hz)]
    if p.size == 0:
        return float("nan"), float("nan")
    d = log_decrement(p)
    k = int(np.argmin(d))
    return float(d[k]), float(p[k].imag / (2 * np.pi))


def whirl_of(shape_xy: np.ndarray) -> tuple[str, float]:
    """Whirl direction of one mode from its lateral amplitudes (module docstring).

    Parameters
    ----------
    shape_xy : ndarray of complex, shape (n_nodes, 2)
        X and Y amplitude at each node.

    Returns
    -------
    (direction, kappa)
        ``"forward"``, ``"backward"``, ``"mixed"`` or ``"planar"``; and the amplitude-weighted
        mean of κ over the nodes (−1 … 1; +1 a circular forward whirl).
    """
    X, Y = shape_xy[:, 0], shape_xy[:, 1]
    amp = np.abs(X) ** 2 + np.abs(Y) ** 2
    if amp.max(initial=0.0) == 0.0:
        return "planar", 0.0
    moving = amp > _MOVING**2 * amp.max()
    kappa = 2 * np.imag(X[moving] * np.conj(Y[moving])) / amp[moving]
    mean = float(np.sum(kappa * amp[moving]) / np.sum(amp[moving]))
    if np.all(kappa > _PLANAR):
        return "forward", mean
    if np.all(kappa < -_PLANAR):
        return "backward", mean
    if np.all(np.abs(kappa) <= _PLANAR):
        return "planar", mean
    return "mixed", mean


@dataclass(frozen=True, eq=False)
class ClosedLoopModes:
    """The oscillating closed-loop modes at one speed and pressure drop, up to ``max_hz``.

    Attributes
    ----------
    speed_hz, pressure_bar, max_hz : float
        Where the modes were taken and the highest damped frequency kept (Hz).
    poles : ndarray of complex, shape (k,)
        The kept eigenvalues (rad/s), Im λ > 0, ascending in frequency.
    frequency_hz, damping_ratio, log_decrement : ndarray, shape (k,)
    whirl : tuple of str
        ``forward`` / ``backward`` / ``mixed`` / ``planar`` per mode.
    kappa : ndarray, shape (k,)
        Amplitude-weighted whirl measure κ (+1 circular forward, −1 circular backward).
    shapes : ndarray of complex, shape (k, n_nodes, 2)
        Lateral amplitudes X, Y (m, scaled to a largest node amplitude of 1) per mode.
    node_z_m : ndarray, shape (n_nodes,)
        Node positions (m).
    max_real_pole : float
        Largest real part of *all* poles of the judged loop (1/s), whatever their frequency:
        the loop as it runs (:func:`ambseal.machine.loop.judged_loop`, the controller's
        delay included), the loop whose modes these are without a controller.
    stable : bool
        The judged loop's verdict (:func:`ambseal.robust.stability.is_stable`).
    unstable : ndarray of complex
        The judged loop's poles that break that rule (rad/s), whatever their frequency.
    """

    speed_hz: float
    pressure_bar: float
    max_hz: float
    poles: np.ndarray
    frequency_hz: np.ndarray
    damping_ratio: np.ndarray
    log_decrement: np.ndarray
    whirl: tuple[str, ...]
    kappa: np.ndarray
    shapes: np.ndarray
    node_z_m: np.ndarray
    max_real_pole: float
    stable: bool
    unstable: np.ndarray

    def deciding(self) -> np.ndarray:
        """The poles of :attr:`unstable` that decide a stability screening (API 617 Level
        I and II): those within the modes' band, |Im λ| ≤ 2π ``max_hz`` (the real ones
        included), where the model and the screening read the rotor's modes. A lossless
        mesh mode far above it — ROSS's ``compressor_example``, without structural
        damping, has them at 21–105 kHz — breaks the rule at Q = 0 because nothing damps
        it, and any cross-coupling at a stage drives it; it is no mode API 617 screens
        (the first forward mode, the one the stage cross-coupling destabilises), and a
        screening reports it apart.

        Returns
        -------
        ndarray of complex
            The deciding poles (rad/s).
        """
        u = np.asarray(self.unstable, complex)
        return u[np.abs(u.imag) <= 2 * np.pi * self.max_hz]

    def to_dict(self) -> dict:
        return {"speed_hz": self.speed_hz, "pressure_bar": self.pressure_bar,
                "max_hz": self.max_hz, "stable": self.stable,
                "max_real_pole": json_float(self.max_real_pole),
                "modes": [{"frequency_hz": json_float(f), "damping_ratio": json_float(z),
                           "log_decrement": json_float(d), "whirl": w, "kappa": json_float(k)}
                          for f, z, d, w, k in zip(self.frequency_hz, self.damping_ratio,
                                                   self.log_decrement, self.whirl, self.kappa)]}


def closed_loop_state_matrix(cfg, controller=None, *, speed_hz: float,
                             pressure_bar: float | None = None, delay: bool = False):
    """The state matrix of the full-order loop and the rig's mesh: ``(A_cl, mesh)``, states
    ``[q; q̇; actuator; controller]``; with ``delay`` ``[q; q̇; actuator; delay;
    controller]``, the loop of :func:`ambseal.analysis.judge.judge` (the digital
    controller's hold + computation delay as a Padé lag,
    :func:`ambseal.robust.delay.loop_delay`).

    Without a controller (or a rig without AMBs) the open-loop plant's A; a scheduled
    controller is frozen at the speed, or at its seal coefficient's value at the pressure
    drop.
    """

    p = cfg.operating.pressure_bar if pressure_bar is None else float(pressure_bar)
    plant = build_plant(cfg, pressure_bar=p, speed_rpm=60.0 * speed_hz)
    mesh = build_mesh(cfg)
    if controller is None or not cfg.amb:
        return plant.A, mesh
    # imported here: the open loop's modes (``ambseal modes``) need none of the loop's
    # python-control machinery, which costs 1 s of start-up
    from ambseal.machine import frozen, judged_loop
    from ambseal.robust import loop_delay  # python-control, as above

    G = plant.select_inputs([plant.input_names[j] for j in plant.current_inputs()]
                            ).to_statespace()
    L = loop_delay(cfg.controller.sample_rate_hz, cfg.controller.delay_samples).system
    K = frozen(controller, 2 * math.pi * speed_hz, seal_values(cfg.seal, p))
    return np.asarray(judged_loop(G, K, delay=L if delay else None).loop.system.A), mesh


def closed_loop_modes(cfg, controller=None, *, speed_hz: float = 0.0,
                      pressure_bar: float | None = None,
                      max_hz: float | None = None, delay: bool = True) -> ClosedLoopModes:
    """Damped frequencies, damping, log decrement, whirl and shapes of the closed loop: by
    default the loop the main job judges (:func:`closed_loop_state_matrix` with ``delay``:
    the continuous controller behind the target's hold and computation delay), so that
    every command reports the log decrements of one loop. The lag's own poles lie at the
    Padé approximant's frequencies, well above the rotor's modes kept here.

    Parameters
    ----------
    cfg : RigConfig
        The rig, at full order.
    controller : StateSpace, ScheduledController or DigitalController, optional
        Displacement (m) → current (A), ``i = −K y``; omitted: the open-loop rig. A
        digital controller designed on the sampled plant, which has no continuous form
        that runs (:attr:`~ambseal.robust.DigitalController.as_runs_only`), is closed as
        it runs (:func:`modes_as_run`, ``delay`` ignored), its modes kept below the
        Nyquist frequency.
    speed_hz : float
        Spin speed (Hz).
    pressure_bar : float, optional
        Seal pressure drop (bar); default ``[operating] pressure_bar``.
    max_hz : float, optional
        Highest damped frequency kept (Hz); default
        :func:`ambseal.model.modes.bending_limit_hz` (a few bending modes).
    delay : bool
        With the target's hold and computation delay (default); False: the continuous
        design's own loop (e.g. against a closed form).

    Returns
    -------
    ClosedLoopModes

    Raises
    ------
    ModelError
        A model that cannot be built, or a controller of the wrong size.
    """

    p = cfg.operating.pressure_bar if pressure_bar is None else float(pressure_bar)
    f_max = bending_limit_hz(cfg) if max_hz is None else float(max_hz)
    if getattr(controller, "as_runs_only", False):  # a sampled loop aliases above Nyquist
        return modes_as_run(cfg, controller, speed_hz=speed_hz, pressure_bar=p,
                            max_hz=min(f_max, 0.5 * controller.sample_rate_hz))
    # the loop the run judges, its delay included: the modes' log decrements are those of
    # the loop that runs, not of a better-damped one without the target's lag
    A, mesh = closed_loop_state_matrix(cfg, controller, speed_hz=speed_hz, pressure_bar=p,
                                       delay=delay)
    return modes_of_state_matrix(A, mesh, speed_hz=speed_hz, pressure_bar=p, max_hz=f_max)


def modes_as_run(cfg, controller=None, *, speed_hz: float, max_hz: float,
                 pressure_bar: float | None = None) -> ClosedLoopModes:
    """The loop's oscillating modes with the controller as it runs: the discrete
    controller with its computation delay on the plant sampled by a zero-order hold
    (:func:`modes_of_sampled_loop`), or the rig alone (``controller`` None, or no AMB).

    Parameters
    ----------
    cfg : RigConfig
        The rig, its plant built at ``speed_hz`` and ``pressure_bar``.
    controller : DigitalController or ScheduledDigital, optional
        As it runs (:func:`ambseal.machine.controller_as_runs`).
    speed_hz, max_hz : float
        Spin speed and highest damped frequency kept (Hz; below Nyquist for a sampled
        loop).
    pressure_bar : float, optional
        The seals' pressure drop; default ``[operating] pressure_bar``.

    Returns
    -------
    ClosedLoopModes

    Raises
    ------
    ConfigError
        A controller that is not a digital one as it runs.
    """
    p = cfg.operating.pressure_bar if pressure_bar is None else float(pressure_bar)
    A, dt = state_matrix_as_run(cfg, controller, speed_hz=speed_hz, pressure_bar=p)
    mesh = build_mesh(cfg)
    if dt is None:
        return modes_of_state_matrix(A, mesh, speed_hz=speed_hz, pressure_bar=p,
                                     max_hz=max_hz)
    return modes_of_sampled_loop(A, dt, mesh, speed_hz=speed_hz, pressure_bar=p,
                                 max_hz=max_hz)


def poles_as_run(cfg, controller=None, *, speed_hz: float, max_hz: float,
                 pressure_bar: float | None = None) -> np.ndarray:
    """The poles of :func:`modes_as_run`'s modes from the loop's eigenvalues alone: no
    eigenvectors, so no shapes or whirl, at about a third of the cost of a dense
    eigendecomposition with vectors. For callers that follow a pole, such as a root
    search on it (API 617 Level I's Q_0, :mod:`ambseal.analysis.signoff.level1`).

    Parameters
    ----------
    cfg : RigConfig
        The rig, its plant built at ``speed_hz`` and ``pressure_bar``.
    controller : DigitalController or ScheduledDigital, optional
        As it runs (:func:`ambseal.machine.controller_as_runs`); None: the rig alone.
    speed_hz, max_hz : float
        Spin speed and highest damped frequency kept (Hz; below Nyquist for a sampled
        loop).
    pressure_bar : float, optional
        The seals' pressure drop; default ``[operating] pressure_bar``.

    Returns
    -------
    ndarray of complex, shape (k,)
        :func:`modes_as_run`'s ``poles`` (rad/s): Im λ > 0 up to ``max_hz``, rigid-body
        modes left out, ascending in frequency.

    Raises
    ------
    ConfigError
        A controller that is not a digital one as it runs.
    """
    p = cfg.operating.pressure_bar if pressure_bar is None else float(pressure_bar)
    A, dt = state_matrix_as_run(cfg, controller, speed_hz=speed_hz, pressure_bar=p)
    lam = sla.eigvals(A)
    if dt is not None:
        lam = np.log(lam[np.abs(lam) > 1e-12].astype(complex)) / dt
    return lam[_kept(lam, float(np.abs(lam).max(initial=0.0)), max_hz)]


def state_matrix_as_run(cfg, controller=None, *, speed_hz: float, pressure_bar: float):
    """The state matrix of the loop as it runs (:func:`modes_as_run`).

    Parameters
    ----------
    cfg : RigConfig
        The rig, its plant built at ``speed_hz`` and ``pressure_bar``.
    controller : DigitalController or ScheduledDigital, optional
        As it runs (:func:`ambseal.machine.controller_as_runs`); None: the rig alone.
    speed_hz, pressure_bar : float
        Spin speed (Hz) and the seals' pressure drop (bar).

    Returns
    -------
    A : ndarray, shape (n, n)
        The sampled loop's state matrix (the full-order plant sampled by a zero-order
        hold, the discrete controller and its computation delay), or the rig's own plant's.
    dt : float or None
        The sample time (s); None for the rig's own plant (no controller, or no AMB).
    """
    p = float(pressure_bar)
    plant = build_plant(cfg, speed_rpm=60.0 * speed_hz, pressure_bar=p)
    if controller is None or not cfg.amb:
        return np.asarray(plant.A), None
    # python-control: loaded when a controller is closed, not for the open loop's modes
    from ambseal.machine import controller_as_runs, sampled_loop_matrix

    G = plant.select_inputs([plant.input_names[j] for j in plant.current_inputs()]
                            ).to_statespace()
    Kd = controller_as_runs(controller, 2 * math.pi * speed_hz, seal_values(cfg.seal, p))
    # the matrix alone: its eigenvectors give the modes and its eigenvalues the verdict
    return sampled_loop_matrix(G, Kd), float(Kd.dt)


def modes_of_state_matrix(A: np.ndarray, mesh, *, speed_hz: float, pressure_bar: float,
                          max_hz: float, judged_poles=None) -> ClosedLoopModes:
    """:class:`ClosedLoopModes` of a state matrix whose first ``mesh.n_dof`` states are the
    rotor's node DOFs q (any plant of :mod:`ambseal.model.rig`, open or closed loop).

    ``stable`` and ``max_real_pole`` are those of ``judged_poles`` when given (the poles of
    the loop as it runs, :func:`ambseal.machine.loop.judged_loop`: the controller's delay
    included), else of ``A``'s eigenvalues.

    Rigid-body modes and oscillating ones as in :func:`ambseal.model.modes.modes`
    (:func:`~ambseal.model.modes.classify_poles`: absolute thresholds in rad/s; ModelError
    when the conditioning makes them doubtful).
    """

    lam, V = sla.eig(A)
    return _modes_of_pairs(lam, V[:mesh.n_dof], mesh, speed_hz=speed_hz,
                           pressure_bar=pressure_bar, max_hz=max_hz,
                           verdict=lam if judged_poles is None else judged_poles,
                           w_max=float(np.abs(lam).max(initial=0.0)))


def modes_of_sampled_loop(A_d: np.ndarray, dt: float, mesh, *, speed_hz: float,
                          pressure_bar: float, max_hz: float) -> ClosedLoopModes:
    """:class:`ClosedLoopModes` of a sampled loop's state matrix (the discrete controller
    as it runs, its delay among its states) whose first ``mesh.n_dof`` states are the
    rotor's node DOFs q at the sampling instants (a zero-order-hold sampled plant keeps
    the continuous plant's coordinates).

    Each pole z maps to λ = ln z / dt (the principal branch: |Im λ| < π/dt, so keep
    ``max_hz`` below the Nyquist frequency); the delay's poles at z = 0 are no modes and
    are left out. Stability is that of every pole: |z| < 1 ⇔ Re λ < 0.

    Parameters
    ----------
    A_d : ndarray, shape (n, n)
        The sampled closed loop's state matrix.
    dt : float
        Sample time (s), > 0.
    mesh
        The rotor's mesh (:func:`ambseal.model.build_mesh`).
    speed_hz, pressure_bar, max_hz : float
        As :func:`modes_of_state_matrix`.

    Returns
    -------
    ClosedLoopModes
    """

    z, V = sla.eig(A_d)
    keep = np.abs(z) > 1e-12
    lam = np.log(z[keep].astype(complex)) / float(dt)
    return _modes_of_pairs(lam, V[:mesh.n_dof, keep], mesh, speed_hz=speed_hz,
                           pressure_bar=pressure_bar, max_hz=max_hz, verdict=lam,
                           w_max=float(np.abs(lam).max(initial=0.0)))


def open_loop_modes(sys, *, speed_hz: float, pressure_bar: float, max_hz: float,
                    judged_poles=None) -> ClosedLoopModes:
    """:class:`ClosedLoopModes` of a second-order system itself (rotor, AMBs without a
    controller, seals, springs: ``ambseal modes`` without ``--controller``), the modes and
    shapes from its lowest eigenpairs only (:func:`ambseal.model.modes.poles_near_zero`).

    The disk holds every eigenvalue with |λ| ≤ 2π·``max_hz`` and every oscillating one of
    ``judged_poles`` up to ``max_hz``, so a heavily damped mode below ``max_hz`` (|λ| above
    2π·``max_hz``) is listed when ``judged_poles`` hold it. On a fine mesh this takes one
    shift-invert factorisation of the n_dof dynamic stiffness instead of a dense eig with
    eigenvectors of the 2·n_dof state matrix (measured on the test rig at 230 elements,
    1 880 states: 0.13 s against 2.9 s); small models take the dense eig.

    Parameters
    ----------
    sys : SecondOrderSystem
        The model (:func:`ambseal.model.rig.build_system`).
    speed_hz, pressure_bar : float
        Where the model was taken (recorded in the result).
    max_hz : float
        Highest damped frequency kept (Hz).
    judged_poles : array_like of complex, or callable, optional
        Eigenvalues (rad/s) that decide ``stable`` and ``max_real_pole``, e.g. every pole of
        the model (:meth:`~ambseal.model.rig.SecondOrderSystem.poles`); default those
        computed here (the disk only, on a fine mesh). A callable returning them is called
        once the disk is computed: a dense eig running in another thread meanwhile
        (``ambseal modes``) takes the wall time of the longer of the two, and the result
        is the same as with the array.

    Returns
    -------
    ClosedLoopModes

    Raises
    ------
    ModelError
        The mass matrix is not positive definite, ARPACK fails to converge, or the model's
        conditioning makes the rigid-body modes doubtful
        (:func:`~ambseal.model.modes.classify_poles`).
    """

    radius = 2 * np.pi * float(max_hz)
    disk = poles_near_zero(sys, radius_rad_s=radius * (1 + 1e-6), vectors=True)
    w_max = None
    if callable(judged_poles):
        judged_poles = judged_poles()
    if judged_poles is not None:
        judged_poles = np.asarray(judged_poles, dtype=complex)
        w_max = float(np.abs(judged_poles).max(initial=0.0))
        osc = judged_poles[(judged_poles.imag >= RIGID_BODY_RAD_S)
                           & (judged_poles.imag <= radius)]
        radius = max(radius, float(np.abs(osc).max(initial=0.0)))
        if not disk.radius_rad_s > radius * (1 + 1e-6):
            # a larger disk; the one above stopped at the first k whose disk held the
            # smaller radius, so asking the larger one first would give the same eigenpairs
            disk = poles_near_zero(sys, radius_rad_s=radius * (1 + 1e-6), vectors=True)
    return _modes_of_pairs(disk.poles, disk.shapes, sys.mesh, speed_hz=speed_hz,
                           pressure_bar=pressure_bar, max_hz=max_hz,
                           verdict=disk.poles if judged_poles is None else judged_poles,
                           w_max=disk.w_max if w_max is None else max(w_max, disk.w_max))


def _modes_of_pairs(lam, Q, mesh, *, speed_hz, pressure_bar, max_hz, verdict,
                    w_max) -> ClosedLoopModes:
    """:class:`ClosedLoopModes` from eigenvalues ``lam`` and the node-DOF part ``Q``
    (n_dof × len(lam)) of their eigenvectors; ``verdict`` decides stability, ``w_max`` is
    the scale of :func:`~ambseal.model.modes.classify_poles`."""

    keep = _kept(lam, w_max, max_hz)
    n = mesh.n_dof
    shapes = _circular_pairs(lam[keep], np.stack([Q[0:n:4, keep], Q[1:n:4, keep]],
                                                 axis=-1).transpose(1, 0, 2))
    size = np.sqrt((np.abs(shapes) ** 2).sum(axis=2)).max(axis=1)
    shapes = shapes / np.where(size > 0, size, 1.0)[:, None, None]
    whirls = [whirl_of(s) for s in shapes]
    z = lam[keep]
    return ClosedLoopModes(
        speed_hz=float(speed_hz), pressure_bar=float(pressure_bar), max_hz=float(max_hz),
        poles=z, frequency_hz=z.imag / (2 * np.pi), damping_ratio=-z.real / np.abs(z),
        log_decrement=log_decrement(z), whirl=tuple(w for w, _ in whirls),
        kappa=np.array([k for _, k in whirls]), shapes=shapes, node_z_m=np.asarray(mesh.z),
        max_real_pole=decay_rate(verdict), stable=is_stable(verdict),
        unstable=unstable_poles(verdict))


def _kept(lam: np.ndarray, w_max: float, max_hz: float) -> np.ndarray:
    """Indices of the oscillating modes of ``lam`` (rad/s) that :class:`ClosedLoopModes`
    keeps: Im λ from :data:`RIGID_BODY_RAD_S` to 2π·``max_hz``, no rigid-body mode
    (:func:`~ambseal.model.modes.classify_poles` at the scale ``w_max``), ascending in
    frequency."""
    rigid, _ = classify_poles(lam, w_max, where="closed-loop modes")
    keep = np.flatnonzero((lam.imag >= RIGID_BODY_RAD_S) & ~rigid
                          & (lam.imag <= 2 * np.pi * max_hz))
    return keep[np.argsort(lam.imag[keep])]


#: Eigenvalues closer than this (relative) are one repeated eigenvalue: an isotropic
#: rotor's x and y modes at standstill agree to rounding (measured up to 3e-8 on a damped
#: closed loop: a double eigenvalue splits by about √ε); a split by the speed or by the
#: supports' anisotropy is far larger (a rigid rotor's conical pair at 0.1 Hz: ~5e-4).
REPEATED = 1e-6


def _circular_pairs(z: np.ndarray, shapes: np.ndarray) -> np.ndarray:
    """``shapes`` (k, n_nodes, 2) with each repeated pair's two shapes replaced by the
    backward and the forward whirl of their plane (the least and the largest amplitude-
    weighted κ, a 2×2 Hermitian eigenproblem): a repeated eigenvalue's eigenvectors are any
    basis of that plane, so its whirl would be read at random; the circular basis is the
    limit of the pair as the speed rises from 0 (backward first, as below it)."""
    out = shapes.copy()
    i = 0
    while i + 1 < len(z):
        if abs(z[i + 1] - z[i]) > REPEATED * abs(z[i]):
            i += 1
            continue
        S = shapes[i:i + 2].reshape(2, -1).T  # columns: the two shapes, [X1, Y1, X2, …]
        X, Y = S[0::2], S[1::2]
        whirl = 1j * (X.conj().T @ Y - Y.conj().T @ X)  # c^H W c = Σ 2 Im(X conj Y)
        c = sla.eigh(0.5 * (whirl + whirl.conj().T), S.conj().T @ S)[1]
        out[i:i + 2] = (S @ c).T.reshape(2, -1, 2)  # ascending κ: backward, then forward
        i += 2
    return out


@dataclass(frozen=True)
class Crossing:
    """A mode line meeting the synchronous (1×) line.

    ``amplification_factor`` ≈ π/δ (API 684 §1.3.3, light damping); API 684 counts the
    crossing as a critical speed (``critical``) when it is at least 2.5.
    """

    track: int
    speed_hz: float
    log_decrement: float
    whirl: str

    @property
    def amplification_factor(self) -> float:
        return float(amplification_factor(self.log_decrement))

    @property
    def critical(self) -> bool:
        return bool(resonant(self.log_decrement))

    def to_dict(self) -> dict:
        return {"track": self.track, "speed_hz": self.speed_hz,
                "log_decrement": json_float(self.log_decrement), "whirl": self.whirl,
                "amplification_factor": json_float(self.amplification_factor),
                "critical": self.critical}


@dataclass(frozen=True, eq=False)
class Campbell:
    """Closed-loop modes over speed, tracked into lines.

    Attributes
    ----------
    speeds_hz : ndarray, shape (n_s,)
    points : tuple of ClosedLoopModes
        One per speed.
    tracks : ndarray of int, shape (n_s, k_max)
        ``tracks[i, j]`` the index into ``points[i]``'s modes of line ``j`` (−1 where the line
        has no mode at that speed), lines followed by nearest eigenvalue.
    crossings : tuple of Crossing
        Where a line meets f = speed (linear interpolation between grid speeds), of modes
        with a resonance: damping ratio below :data:`OVERDAMPED_ZETA`.
    log_dec_limit : float
        The limit below which a mode is flagged (API 684: 0.1).
    overdamped : tuple of Crossing
        The crossings of lines damped at ζ ≥ :data:`OVERDAMPED_ZETA` there (a controller's
        or an eddy-current pole with a small imaginary part): no resonance, listed apart.
    """

    speeds_hz: np.ndarray
    points: tuple[ClosedLoopModes, ...]
    tracks: np.ndarray
    crossings: tuple[Crossing, ...]
    log_dec_limit: float = API684_LOG_DEC
    overdamped: tuple[Crossing, ...] = ()

    def line(self, j: int, field: str = "frequency_hz") -> np.ndarray:
        """Values of ``field`` along line ``j`` (nan where absent), shape (n_s,)."""
        return np.array([getattr(p, field)[k] if k >= 0 else np.nan
                         for p, k in zip(self.points, self.tracks[:, j])])

    def flagged(self) -> list[dict]:
        """Every (speed, mode) with a log decrement below the limit."""
        return [{"speed_hz": p.speed_hz, "frequency_hz": float(f), "log_decrement": float(d),
                 "whirl": w}
                for p in self.points
                for f, d, w in zip(p.frequency_hz, p.log_decrement, p.whirl)
                if d < self.log_dec_limit]

    def rows(self) -> list[dict]:
        """One row per (speed, mode) for a CSV table."""
        out = []
        for i, p in enumerate(self.points):
            line_of = {int(k): j for j, k in enumerate(self.tracks[i]) if k >= 0}
            for k in range(len(p.frequency_hz)):
                out.append({"speed_hz": p.speed_hz, "line": line_of.get(k, -1),
                            "frequency_hz": float(p.frequency_hz[k]),
                            "damping_ratio": float(p.damping_ratio[k]),
                            "log_decrement": float(p.log_decrement[k]), "whirl": p.whirl[k],
                            "flagged": bool(p.log_decrement[k] < self.log_dec_limit)})
        return out

    def to_dict(self) -> dict:
        return {"speeds_hz": json_list(self.speeds_hz), "log_dec_limit": self.log_dec_limit,
                "stable": [p.stable for p in self.points],
                "max_real_pole": [json_float(p.max_real_pole) for p in self.points],
                "crossings": [c.to_dict() for c in self.crossings],
                "overdamped_crossings": [c.to_dict() for c in self.overdamped],
                "flagged": self.flagged(), "points": [p.to_dict() for p in self.points]}


def track_modes(points) -> np.ndarray:
    """Follow modes from point to point (speeds, or any parameter) by the assignment of
    least total |Δλ|.

    Parameters
    ----------
    points : sequence of ClosedLoopModes
        The modes at each point, in order.

    Returns
    -------
    ndarray of int, shape (n_points, n_lines)
        ``[i, j]`` the index into ``points[i].poles`` of line ``j``, −1 where the line has
        no mode at that point.
    """
    lines: list[list[int]] = [[k] for k in range(len(points[0].poles))]
    for i in range(1, len(points)):
        prev = [(j, ln[-1]) for j, ln in enumerate(lines) if ln[-1] >= 0]
        for ln in lines:
            ln.append(-1)
        new = points[i].poles
        if prev and new.size:
            old = np.array([points[i - 1].poles[k] for _, k in prev])
            rows, cols = linear_sum_assignment(np.abs(old[:, None] - new[None, :]))
            for r, c in zip(rows, cols):
                lines[prev[r][0]][-1] = int(c)
        taken = {ln[-1] for ln in lines}
        for c in range(new.size):
            if c not in taken:
                lines.append([-1] * i + [c])
    return np.array(lines, dtype=int).T.reshape(len(points), len(lines))


def _crossings(c: Campbell) -> tuple[tuple[Crossing, ...], tuple[Crossing, ...]]:
    """The 1× crossings of the lines: (those with a resonance, the overdamped ones)."""
    out, over = [], []
    s = c.speeds_hz
    for j in range(c.tracks.shape[1]):
        f, d, z = c.line(j), c.line(j, "log_decrement"), c.line(j, "damping_ratio")
        g = f - s
        for i in range(len(s) - 1):
            # a line through a grid speed meets it at the start of one interval only
            ends_on_it = g[i + 1] == 0 and i + 2 < len(s)
            if np.isfinite(g[i]) and np.isfinite(g[i + 1]) and g[i] * g[i + 1] <= 0 \
                    and g[i] != g[i + 1] and not ends_on_it:
                t = g[i] / (g[i] - g[i + 1])
                k = c.tracks[i + (t > 0.5), j]
                x = Crossing(j, float(s[i] + t * (s[i + 1] - s[i])),
                             float(d[i] + t * (d[i + 1] - d[i])),
                             c.points[i + (t > 0.5)].whirl[k])
                (over if z[i] + t * (z[i + 1] - z[i]) >= OVERDAMPED_ZETA else out).append(x)
    return (tuple(sorted(out, key=lambda x: x.speed_hz)),
            tuple(sorted(over, key=lambda x: x.speed_hz)))


def campbell(cfg, controller=None, speeds_hz=None, *, pressure_bar: float | None = None,
             max_hz: float | None = None, log_dec_limit: float = API684_LOG_DEC,
             workers: int | None = None, scheduler: str | None = None,
             progress: bool = False, delay: bool = True) -> Campbell:
    """The closed-loop Campbell diagram: :func:`closed_loop_modes` at every speed.

    Parameters
    ----------
    cfg : RigConfig
    controller : StateSpace, ScheduledController or DigitalController, optional
        As in :func:`closed_loop_modes`: one designed on the sampled plant is closed as
        it runs.
    speeds_hz : array_like, optional
        Speeds (Hz); default 31 points from 0 to 1.2× the upper end of ``[operating]
        speed_range_hz``, else of the operating speed, else of the first free–free bending
        frequency (:func:`ambseal.model.modes.free_bending_hz`: the rigid-body modes' and
        the first bending mode's 1× crossings on the plot).
    pressure_bar, max_hz : float, optional
        As in :func:`closed_loop_modes` (``max_hz`` is fixed once, at standstill).
    delay : bool
        As in :func:`closed_loop_modes`: the judged loop, with the target's delay.
    log_dec_limit : float
        Modes below it are flagged (API 684: 0.1).
    workers, scheduler, progress
        Run the speeds through :func:`ambseal.analysis.cases.run_cases` (serial by default).

    Returns
    -------
    Campbell
    """

    f_max = bending_limit_hz(cfg) if max_hz is None else float(max_hz)
    if speeds_hz is None:
        r = cfg.operating.speed_range_hz
        top = (r[1] if r is not None else cfg.operating.speed_rpm / 60.0
               if cfg.operating.speed_rpm > 0 else free_bending_hz(cfg, 1)[0])
        speeds_hz = np.linspace(0.0, 1.2 * top, 31)
    s = np.asarray(speeds_hz, float)
    cases = [dict(speed_hz=float(v)) for v in s]
    results = run_cases(_modes_case, cases, shared=dict(cfg=cfg, controller=controller,
                                                        pressure_bar=pressure_bar,
                                                        max_hz=f_max, delay=delay),
                        workers=workers, scheduler=scheduler, progress=progress,
                        description="campbell", raise_errors=True)
    pts = list(results)
    c = Campbell(s, tuple(pts), track_modes(pts), (), log_dec_limit)
    crossings, overdamped = _crossings(c)
    return Campbell(s, c.points, c.tracks, crossings, log_dec_limit, overdamped)


def _modes_case(case: dict, cfg, controller, pressure_bar, max_hz, delay) -> ClosedLoopModes:
    return closed_loop_modes(cfg, controller, speed_hz=case["speed_hz"],
                             pressure_bar=pressure_bar, max_hz=max_hz, delay=delay)
