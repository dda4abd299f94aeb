"""The levitated state a drop starts from: the rotor held by its AMB loop at the operating
speed, whirling in its unbalance orbit, at the instant the AMBs let go.

The loop is the drop's own rotor (:class:`~ambseal.analysis.drop.DropModel`: the free
FE rotor in its modes kept, gyroscopics at the spin Ω) with each AMB's negative stiffness
−Ks at its bearing node and its force Ki·i along its actuator axes ζ, η
(:class:`ambseal.model.AmbElement`), the displacement read at its sensor, the amplifier
(:func:`ambseal.model.actuator_matrices`) and the eddy-current lag
(:func:`ambseal.model.eddy_lag_matrices`) between the current reference and the force,
and the controller in negative feedback i = −K y: the rig's reference PID at that speed
(:func:`ambseal.design.reference_pid`, P5 Eq. 6) unless one is given, in continuous
time. The seals are not in the drop's rotor, nor in this loop.

The unbalance U (kg·m) at the node nearest the centre of mass is the force
U Ω² (cos Ωt, sin Ωt) = Re(U Ω² (1, −j) e^{jΩt}) that :func:`~ambseal.analysis.drop.
simulate_drop` applies with ``unbalance_kgm``; the loop's steady response to it is
X e^{jΩt}, X = (jΩ I − A_cl)⁻¹ B_u U Ω² (1, −j), and the state at t = 0 is Re(X) for the
modes and Re(jΩ X) for their rates, on top of the static sag the drop model's levitated
equilibrium already holds. A loop that is not stable at that speed has no such orbit:
it is refused, naming its least damped pole.
"""

from __future__ import annotations

import numpy as np
from scipy.linalg import eigvals

from ambseal.design import pid_controller, reference_pid
from ambseal.errors import ConfigError
from ambseal.lti import feedback_matrices, series_inputs
from ambseal.model import (
    AmbElement,
    actuator_matrices,
    build_mesh,
    channel_names,
    eddy_lag_matrices,
)

__all__ = ["levitated_loop", "levitated_start"]


def levitated_loop(cfg, dm, speed_rpm: float, controller=None):
    """The closed AMB loop of the drop's rotor (module docstring) in state space, the
    states the modes, their rates, the amplifiers' and the controller's.

    Parameters
    ----------
    cfg : RigConfig
        The rig, with its ``[[amb]]`` tables.
    dm : DropModel
        Its drop model (:func:`ambseal.analysis.drop.drop_model`).
    speed_rpm : float
        The spin speed (rpm).
    controller : control.StateSpace, optional
        Continuous, sensor displacements (m) → current references (A) of the rig's
        channels (:func:`ambseal.model.channel_names`), i = −K y; default the reference
        PID at that speed.

    Returns
    -------
    A : ndarray, shape (n, n)
        The closed loop's state matrix; its first 2m states are the modes and their
        rates.
    B_u : ndarray, shape (n, 2)
        The input of a force (N) at the node nearest the centre of mass, x and y.
    """
    W = 2 * np.pi * speed_rpm / 60.0
    mesh = build_mesh(cfg, extra_positions=tuple(t.position for t in cfg.touchdown))
    n_dof, m = mesh.n_dof, dm.phi.shape[1]
    els = [AmbElement.from_config(a, mesh) for a in cfg.amb]
    K_amb = np.zeros((n_dof, n_dof))
    for el in els:
        el.assemble(np.zeros_like(K_amb), np.zeros_like(K_amb), K_amb)
    phi = dm.phi
    B_ri = np.vstack([np.zeros((m, 2 * len(els))), phi.T @ np.column_stack(
        [c for el in els for c in el.input_columns(n_dof)])])
    B_rf = np.vstack([np.zeros((m, 2)), dm.cg_rows.T])
    C_r = np.hstack([np.vstack([r for el in els for r in el.sensor_rows(n_dof)]) @ phi,
                     np.zeros((2 * len(els), m))])
    A_r = np.block([[np.zeros((m, m)), np.eye(m)],
                    [-(dm.K + phi.T @ K_amb @ phi), -(dm.C + W * dm.G)]])
    if controller is None:
        g = reference_pid(cfg, speed_rpm)
        controller = pid_controller(g["kp"], g["ti"], g["td"], g["eps"], channel_names(cfg),
                                    g.get("filters", ()), g.get("cross_kp", 0.0),
                                    g.get("cross_kd", 0.0))
    G = (A_r, B_ri, C_r, np.zeros((C_r.shape[0], B_ri.shape[1])))
    # the eddy-current lag next to the rotor, the amplifier before it (as build_plant)
    act = cfg.actuator
    for on, block in ((act.eddy_time_constant > 0, eddy_lag_matrices(act.eddy_time_constant)),
                      (act.model != "none", actuator_matrices(act))):
        if on:
            G = series_inputs(G, block)[:4]
    Bf = np.vstack([B_rf, np.zeros((G[0].shape[0] - B_rf.shape[0], 2))])
    K = tuple(np.asarray(x, float) for x in (controller.A, controller.B, controller.C,
                                             controller.D))
    A, B, _, _ = feedback_matrices(G, K, (Bf, np.zeros((G[2].shape[0], 2))))
    return A, B[:, -2:]  # the inputs [d, f]: the force last


def levitated_start(cfg, dm, speed_rpm: float, unbalance_kgm: float, controller=None):
    """The nodal state at the drop (module docstring): for
    :func:`~ambseal.analysis.drop.simulate_drop`'s ``initial``.

    Parameters
    ----------
    cfg : RigConfig
        The rig.
    dm : DropModel
        Its drop model.
    speed_rpm : float
        The spin speed (rpm).
    unbalance_kgm : float
        The static unbalance U (kg·m) at the centre of mass, ≥ 0.
    controller : control.StateSpace, optional
        As :func:`levitated_loop`.

    Returns
    -------
    u, v : ndarray, shape (n_dof,)
        Nodal displacement (m, rad) and velocity (m/s, rad/s): the static sag and the
        unbalance orbit at t = 0.

    Raises
    ------
    ConfigError
        A rig without AMBs, or a loop that is not stable at that speed.
    """
    if not cfg.amb:
        raise ConfigError("drop: levitated start: the rig has no [[amb]] to levitate it")
    A, B_u = levitated_loop(cfg, dm, speed_rpm, controller)
    poles = eigvals(A)
    worst = poles[np.argmax(poles.real)]
    if worst.real >= 0:
        raise ConfigError(
            f"drop: levitated start: the AMB loop with the "
            f"{'reference PID' if controller is None else 'controller'} is unstable at "
            f"{speed_rpm:g} rpm (a pole at {worst.real:.4g} ± {abs(worst.imag):.4g}j "
            "rad/s): the rotor has no levitated orbit there; start the drop at rest")
    W = 2 * np.pi * speed_rpm / 60.0
    m = dm.phi.shape[1]
    force = unbalance_kgm * W * W * np.array([1.0, -1.0j])
    X = np.linalg.solve(1j * W * np.eye(A.shape[0]) - A, B_u @ force)
    eta, deta = dm.q0 + X[:m].real, (1j * W * X[:m]).real
    return dm.phi @ eta, dm.phi @ deta
