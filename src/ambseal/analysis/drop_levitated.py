"""The levitated state a drop starts from: the rotor held by its AMB loop at the operating
speed, whirling in its unbalance orbit, at the instant the AMBs let go.

The loop is the drop's own rotor (:class:`~ambseal.analysis.drop.DropModel`: the free
FE rotor in its modes kept, gyroscopics at the spin Ω) held by the AMB loop of
:mod:`ambseal.analysis.drop_loop` (each axis's −Ks and Ki·i, the sensors, the amplifiers
and eddy-current lags, the controller in negative feedback i = −K y: the rig's reference
PID at that speed, :func:`ambseal.design.reference_pid`, P5 Eq. 6, unless one is given,
in continuous time), linear: the orbit's currents are not clipped, and the seals at the
speed and pressure drop, and the springs (:func:`ambseal.analysis.drop.support_matrices`),
as in the drop.

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
from scipy.linalg import eigvals, expm

from ambseal.analysis.drop import support_matrices
from ambseal.analysis.drop_loop import amb_loop
from ambseal.errors import ConfigError
from ambseal.lti import feedback_matrices

__all__ = ["levitated_loop", "levitated_state"]


def levitated_loop(cfg, dm, speed_rpm: float, controller=None, loop=None, supports=True,
                   pressure_bar: float | None = None):
    """The closed AMB loop of the drop's rotor (module docstring) in state space, linear
    (no current clipped), the states the modes, their rates, the amplifiers' and lags'
    and the controller's.

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
    loop : AmbLoop, optional
        The loop's pieces (:func:`ambseal.analysis.drop_loop.amb_loop`), built from
        ``controller`` if omitted.
    supports : bool, optional
        The seals' and springs' forces on the rotor
        (:func:`ambseal.analysis.drop.support_matrices`).
    pressure_bar : float, optional
        Their pressure drop (bar); ``[operating] pressure_bar`` if omitted.

    Returns
    -------
    A : ndarray, shape (n, n)
        The closed loop's state matrix; its first 2m states are the modes and their
        rates, then the springs' housings' x, y and their rates (2·2h), the rest the
        loop's (:attr:`AmbLoop.n_states`: the coil's, the controller's).
    B_u : ndarray, shape (n, 2)
        The input of a force (N) at the node nearest the centre of mass, x and y.
    """
    L = loop or amb_loop(cfg, dm, speed_rpm, controller)
    G, Bf = _open_loop(cfg, dm, speed_rpm, L, supports, pressure_bar)
    A_cl, B_cl, _, _ = feedback_matrices(G, L.controller, (Bf, np.zeros((L.ki.size, 2))))
    return A_cl, B_cl[:, -2:]  # the inputs [d, f]: the force last


def _open_loop(cfg, dm, speed_rpm: float, L, supports: bool, pressure_bar):
    """The rotor with its seals and springs, −Ks and the coil, current references →
    sensors: (A, B, C, D), the states the modes' deviation from the levitated equilibrium,
    their rates, the springs' housings' x, y and their rates
    (:func:`ambseal.analysis.drop.support_matrices`) and the coil's; and the input of a
    force (N) at the centre of mass."""
    W = 2 * np.pi * speed_rpm / 60.0
    m = dm.phi.shape[1]
    K_s, C_s, M_s = (support_matrices(cfg, dm, speed_rpm, pressure_bar) if supports
                     else (np.zeros((m, m)),) * 3)
    n = K_s.shape[0]
    nh = n - m  # the housings' x, y
    M_inv = np.linalg.inv(np.diag(np.r_[np.ones(m), np.zeros(nh)]) + M_s)
    K_r = np.zeros((n, n))
    K_r[:m, :m] = dm.K - L.axis.T @ (L.ks[:, None] * L.axis)
    C_r = np.zeros((n, n))
    C_r[:m, :m] = dm.C + W * dm.G
    A_r = np.block([[np.zeros((n, n)), np.eye(n)],
                    [-M_inv @ (K_r + K_s), -M_inv @ (C_r + C_s)]])
    B_r = np.vstack([np.zeros((n, L.ki.size)),
                     M_inv @ np.vstack([L.axis.T * L.ki, np.zeros((nh, L.ki.size))])])
    Aa, Ba, Ca, Da = L.coil
    na = Aa.shape[0]
    # the coil in front of the rotor's current inputs: its states after the rotor's
    A = np.block([[A_r, B_r @ Ca], [np.zeros((na, 2 * n)), Aa]])
    G = (A, np.vstack([B_r @ Da, Ba]),
         np.hstack([L.sensor, np.zeros((L.ki.size, nh + n + na))]),
         np.zeros((L.ki.size,) * 2))
    # the states [Δη, h, η̇, ḣ, coil] put as [Δη, η̇, h, ḣ, coil]: the modes first
    order = np.r_[np.arange(m), n + np.arange(m), m + np.arange(nh), n + m + np.arange(nh),
                  2 * n + np.arange(na)]
    A, B, C, D = G
    Bf = np.vstack([np.zeros((n, 2)), M_inv @ np.vstack([dm.cg_rows.T, np.zeros((nh, 2))]),
                    np.zeros((na, 2))])
    return (A[np.ix_(order, order)], B[order], C[:, order], D), Bf[order]


def _sampled_orbit(G, Bf, sampled, W: float, force: np.ndarray):
    """The steady orbit of the rotor under a digital controller (:mod:`ambseal.analysis.
    drop_loop`) and the force Re(F e^{jΩt}), at the sample instant t = 0: the plant
    sampled exactly, x_{k+1} = Φ x_k + Γ i_k + (z I − Φ)(jΩ I − A)⁻¹ B_f F z^k with
    z = e^{jΩT_s} (the force's own response between the samples, Franklin, Powell &
    Workman §4.3), closed with x_{d,k+1} = A_d x_d + B_d y_k, i_k = −(C_d x_d + D_d y_k):
    the orbit X z^k, X_d z^k solves the loop's equations at z. Returns (X, X_d) and the
    lifted loop's largest eigenvalue."""
    A, B, C, _ = G
    A_d, B_d, C_d, D_d, Ts = sampled
    n, nu, nd = A.shape[0], B.shape[1], A_d.shape[0]
    aug = np.zeros((n + nu, n + nu))
    aug[:n, :n], aug[:n, n:] = A * Ts, B * Ts
    E = expm(aug)
    Phi, Gam = E[:n, :n], E[:n, n:]
    lifted = np.block([[Phi - Gam @ D_d @ C, -Gam @ C_d], [B_d @ C, A_d]])
    z = np.exp(1j * W * Ts)
    rhs = np.zeros(n + nd, complex)
    if np.any(force):
        rhs[:n] = (z * np.eye(n) - Phi) @ np.linalg.solve(1j * W * np.eye(n) - A, Bf @ force)
    X = np.linalg.solve(z * np.eye(n + nd) - lifted, rhs)
    poles = eigvals(lifted)
    return X[:n], X[n:], poles[np.argmax(np.abs(poles))]


def levitated_state(cfg, dm, speed_rpm: float, unbalance_kgm: float, controller=None,
                    loop=None, supports=True, pressure_bar: float | None = None):
    """The modal state at the drop (module docstring), the loop's states with it.

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
    loop : AmbLoop, optional
        As :func:`levitated_loop`.
    supports : bool, optional
        As :func:`levitated_loop`.
    pressure_bar : float, optional
        As :func:`levitated_loop`.

    Returns
    -------
    eta, deta : ndarray, shape (m,)
        The modal coordinates and their rates: the levitated equilibrium ``dm.q0`` and
        the unbalance orbit at t = 0 (a spring's housing moves in the orbit too; the drop
        starts it at rest in its equilibrium).
    x_loop : ndarray, shape (n_loop,)
        The loop's states at t = 0: the coil's and a continuous controller's
        (:attr:`AmbLoop.n_states`), or the coil's and a digital controller's before its
        update at t = 0 (:attr:`AmbLoop.n_sampled`), the orbit then the sampled loop's
        (:func:`_sampled_orbit`).

    Raises
    ------
    ConfigError
        A rig without AMBs, or a loop that is not stable at that speed.
    """
    if not cfg.amb:
        raise ConfigError("drop: levitated start: the rig has no [[amb]] to levitate it")
    W = 2 * np.pi * speed_rpm / 60.0
    m = dm.phi.shape[1]
    force = unbalance_kgm * W * W * np.array([1.0, -1.0j])
    L = loop or amb_loop(cfg, dm, speed_rpm, controller)
    if L.sampled is not None:
        X, X_d, worst = _sampled_orbit(*_open_loop(cfg, dm, speed_rpm, L, supports,
                                                   pressure_bar), L.sampled, W, force)
        if abs(worst) >= 1:
            raise ConfigError(
                f"drop: levitated start: the AMB loop with the digital controller as it "
                f"runs is unstable at {speed_rpm:g} rpm (a pole at |z| = {abs(worst):.6g}): "
                "the rotor has no levitated orbit there; start the drop at rest")
        return (dm.q0 + X[:m].real, X[m:2 * m].real,
                np.concatenate([X[X.size - L.coil[0].shape[0]:].real, X_d.real]))
    A, B_u = levitated_loop(cfg, dm, speed_rpm, controller, L, supports, pressure_bar)
    poles = eigvals(A)
    worst = poles[np.argmax(poles.real)]
    if worst.real >= 0:
        raise ConfigError(
            f"drop: levitated start: the AMB loop with the "
            f"{'reference PID' if controller is None else 'controller'} is unstable at "
            f"{speed_rpm:g} rpm (a pole at {worst.real:.4g} ± {abs(worst.imag):.4g}j "
            "rad/s): the rotor has no levitated orbit there; start the drop at rest")
    X = np.linalg.solve(1j * W * np.eye(A.shape[0]) - A, B_u @ force)
    # the loop's states last (the housings' before them are not a start)
    return dm.q0 + X[:m].real, (1j * W * X[:m]).real, X[X.size - L.n_states:].real

