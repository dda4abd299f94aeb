"""The AMB loop inside the drop: what each axis of each magnetic bearing does to the falling
rotor while its loop runs, once its power is lost, and where its current saturates.

Each AMB axis j (a channel, :func:`ambseal.model.channel_names`) pushes the rotor along
its actuator axis r_j at the bearing node with

    f_j = F_j + Ki_j i_j + Ks_j s_j

linearised about the levitated equilibrium q0 of the drop model
(:class:`~ambseal.analysis.drop.DropModel`): F_j the static force it carries there (the
AMBs' share of the weight along r_j), s_j = r_jᵀ(u − u0) the bearing node's displacement
from it along the axis, i_j the control current as the force sees it. The loop: the
sensors read y = r_jᵀ(u − u0) at the sensor nodes, the controller gives the current
reference i_ref = −K y (negative feedback; its states x_K), the reference is clipped so
the coil's total current i_s + i_ref, i_s = F_j/Ki_j, stays within ±i_max, and the
amplifier (:func:`ambseal.model.actuator_matrices`) and the eddy-current lag
(:func:`ambseal.model.eddy_lag_matrices`) carry it to i_j (their states x_a). i_max is the
smaller of the axis's ``current_limit`` (the amplifier's limit on the control current)
and its bias current i0 (:func:`ambseal.model.bias_currents`: beyond i0 one magnet of the
differential pair is off and the force leaves the linear law), the control current's
bounds of :mod:`ambseal.model.capacity`; unbounded where the rig gives neither.

An axis whose power is lost at t = 0 is no longer driven: both coils' currents decay
through the coil, e^{−t R/L} (``inductance`` and ``resistance`` of its ``[[amb]]``; at
once where the rig gives neither), from the currents they carried at that instant, and
the force, quadratic in the currents (f ∝ i², Schweitzer & Maslen, *Magnetic Bearings*,
2009, Eq. 3.30), with their square:

    f_j(t) = e^{−2t R/L} (F_j + Ki_j i_j(0) + Ks_j s_j(t)),

its negative stiffness Ks ∝ i0² going with its bias. The loop's other axes run on.

A digital controller runs as it does on the target: sampled every T_s from t = 0, its
discrete state x_{k+1} = A x_k + B y_k updated and its output u_k = C x_k + D y_k (the
computation delay among its states) held by the DAC, i_ref = −u_k clipped, until the next
sample (zero-order hold; Franklin, Powell & Workman, *Digital Control of Dynamic
Systems*, 3rd ed., §4.3); the amplifier and the rotor run on in continuous time between.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ambseal.config import check_operating
from ambseal.design import pid_controller, reference_pid
from ambseal.errors import ConfigError
from ambseal.lti import series_inputs
from ambseal.model import (
    AmbElement,
    actuator_matrices,
    bias_currents,
    build_mesh,
    channel_names,
    eddy_lag_matrices,
)

__all__ = ["AmbLoop", "amb_loop", "drop_event", "lost_at_rest", "EVENTS"]

#: the events that land a rotor (ISO 14839-4's causes of contact): every AMB's power
#: lost, one axis's, or a step force beyond what the loop holds
EVENTS = ("loss", "one-axis", "overload")


@dataclass(frozen=True)
class AmbLoop:
    """The drop's AMB loop (module docstring), c channels, in the drop model's m modes.

    Attributes
    ----------
    names : tuple of str
        The channels, ``{amb}_{axis}`` (:func:`ambseal.model.channel_names`).
    sensor : ndarray, shape (c, m)
        Each sensor's reading along its axis per modal coordinate.
    axis : ndarray, shape (c, m)
        The bearing node's displacement along each axis per modal coordinate; its
        transpose maps the axes' forces (N) to modal forces.
    ki, ks : ndarray, shape (c,)
        Ki (N/A) and Ks (N/m) of each axis.
    static : ndarray, shape (c,)
        F_j: each axis's force (N) in the levitated equilibrium.
    limit : ndarray, shape (c,)
        i_max: the largest total current |i_s + i_ref| (A); inf where unbounded.
    tau : ndarray, shape (c,)
        The coil's L/R (s) once the axis loses power; 0: at once.
    controller : tuple of ndarray
        (A_K, B_K, C_K, D_K): y (m) → current reference, i_ref = −(C_K x_K + D_K y);
        no states and D_K = 0 for a loop without a controller (every axis then fails).
    coil : tuple of ndarray
        (A_a, B_a, C_a, D_a): the amplifiers and eddy-current lags, i_ref → i, c × c.
    sampled : tuple or None
        (A, B, C, D, T_s) of a digital controller as it runs (module docstring; the
        computation delay among its states), y_k → u_k, i_ref = −u_k held; then
        ``controller`` has no states and no gain. None: the controller runs in continuous
        time.
    """

    names: tuple
    sensor: np.ndarray
    axis: np.ndarray
    ki: np.ndarray
    ks: np.ndarray
    static: np.ndarray
    limit: np.ndarray
    tau: np.ndarray
    controller: tuple
    coil: tuple
    sampled: tuple | None = None

    @property
    def has_controller(self) -> bool:
        """Whether a controller runs the loop (digital, or with states or a gain)."""
        K = self.controller
        return self.sampled is not None or K[0].shape[0] > 0 or bool(K[3].any())

    @property
    def n_states(self) -> int:
        """The loop's states in continuous time: the coil's then the controller's."""
        return self.coil[0].shape[0] + self.controller[0].shape[0]

    @property
    def n_sampled(self) -> int:
        """The digital controller's states (0 for a continuous one)."""
        return 0 if self.sampled is None else self.sampled[0].shape[0]

    def clip(self, i_ref: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """``i_ref`` (A, shape (c,)) clipped so the coil's total current stays within
        ±i_max (module docstring), and the axes it was clipped on."""
        total = self.static / self.ki + i_ref
        return (np.clip(total, -self.limit, self.limit) - self.static / self.ki,
                np.abs(total) > self.limit)

    def reference(self, y: np.ndarray, x_k: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """The current reference (A), shape (c,), clipped (module docstring), for the
        sensors' readings ``y`` (m, shape (c,)) and the controller's states ``x_k``; and
        which axes it was clipped on (bool, shape (c,))."""
        Ak, Bk, Ck, Dk = self.controller
        return self.clip(-(Ck @ x_k + Dk @ y))


def _coil(cfg, c: int) -> tuple:
    """The amplifiers and eddy-current lags of c channels, i_ref → i: the lag next to the
    rotor, the amplifier before it (as :func:`ambseal.design.build_plant` orders them)."""
    chain = (np.zeros((0, 0)), np.zeros((0, c)), np.zeros((c, 0)), np.eye(c))
    act = cfg.actuator
    for on, block in ((act.eddy_time_constant > 0, eddy_lag_matrices(act.eddy_time_constant)),
                      (act.model != "none", actuator_matrices(act))):
        if on:
            chain = series_inputs(chain, block)[:4]
    return chain


def amb_loop(cfg, dm, speed_rpm: float | None = None, controller=None) -> AmbLoop:
    """The AMB loop of a rig's drop model (module docstring).

    Parameters
    ----------
    cfg : RigConfig
        The rig, with its ``[[amb]]`` tables.
    dm : DropModel
        Its drop model (:func:`ambseal.analysis.drop.drop_model`).
    speed_rpm : float, optional
        The speed (rpm) at which the reference PID acts (its cross gains may be scheduled
        on it); ``[operating] speed_rpm`` if omitted.
    controller : control.StateSpace or "none", optional
        The rig's sensor displacements (m) → current references (A) in
        :func:`ambseal.model.channel_names`'s order, i = −K y: continuous, or discrete
        (``dt`` > 0, the computation delay among its states) for a digital controller as
        it runs (module docstring); default the reference PID
        (:func:`ambseal.design.reference_pid`, P5 Eq. 6) in continuous time; ``"none"``
        for a loop no controller runs (every axis loses power at once).

    Returns
    -------
    AmbLoop

    Raises
    ------
    ConfigError
        A rig without AMBs; a controller of the wrong size.
    """
    if not cfg.amb:
        raise ConfigError("drop: the rig has no [[amb]]: no AMB loop")
    mesh = build_mesh(cfg, extra_positions=tuple(t.position for t in cfg.touchdown))
    n_dof, phi = mesh.n_dof, dm.phi
    els = [AmbElement.from_config(a, mesh) for a in cfg.amb]
    names = channel_names(cfg)
    c = len(names)
    ki = np.array([k for el in els for k in el.ki], float)
    ks = np.array([k for el in els for k in el.ks], float)
    axis = np.vstack([col / k for el in els for col, k in zip(el.input_columns(n_dof), el.ki)])
    sensor = np.vstack([r for el in els for r in el.sensor_rows(n_dof)])
    # the static force of AMB a (x, y): along axis r_j its component r_j·f
    static = np.array([el.R[j] @ f for el, f in zip(els, dm.amb_force) for j in range(2)])
    limit = []
    for a, i0 in zip(cfg.amb, bias_currents(cfg)):
        given = [x for x in (a.current_limit, i0) if x]
        limit += [min(given) if given else np.inf] * 2
    tau = np.repeat([(a.inductance / a.resistance) if (a.inductance and a.resistance)
                     else 0.0 for a in cfg.amb], 2)
    none = (np.zeros((0, 0)), np.zeros((0, c)), np.zeros((c, 0)), np.zeros((c, c)))
    sampled = None
    if isinstance(controller, str) and controller == "none":
        K = none
    else:
        if controller is None:
            g = reference_pid(cfg, speed_rpm)
            controller = pid_controller(g["kp"], g["ti"], g["td"], g["eps"], names,
                                        g.get("filters", ()), g.get("cross_kp", 0.0),
                                        g.get("cross_kd", 0.0))
        K = tuple(np.asarray(x, float) for x in (controller.A, controller.B, controller.C,
                                                 controller.D))
        if K[3].shape != (c, c):
            raise ConfigError(f"drop: the controller maps {K[3].shape[1]} sensors to "
                              f"{K[3].shape[0]} currents; the rig has {c} channels "
                              f"({', '.join(names)})")
        dt = getattr(controller, "dt", 0)
        if dt and dt is not True:  # a digital controller as it runs
            sampled, K = (*K, float(dt)), none
    return AmbLoop(names=names, sensor=sensor @ phi, axis=axis @ phi, ki=ki, ks=ks,
                   static=static, limit=np.array(limit, float), tau=tau, controller=K,
                   coil=_coil(cfg, c), sampled=sampled)


def lost_at_rest(event: str, start: str, unbalance_kgm: float) -> bool:
    """Whether no controller acts on a drop: every AMB loses power (``event`` "loss") with
    the rotor at its levitated equilibrium — started from rest, or levitated without an
    unbalance (no orbit to start from). The coils then carry their static currents alone
    as they decay, and no controller need be derived (:func:`amb_loop` with ``"none"``).

    Parameters
    ----------
    event : str
        One of :data:`EVENTS`.
    start : str
        ``"rest"`` or ``"levitated"``.
    unbalance_kgm : float
        The rotor's unbalance (kg·m).

    Returns
    -------
    bool
    """
    return event == "loss" and (start == "rest" or not unbalance_kgm)


def drop_event(cfg, dm, loop: AmbLoop, event: str = "loss", axis: str | None = None,
               overload_n: float | None = None, overload_at: str | None = None,
               surge_bar: float | None = None) -> dict:
    """What :func:`~ambseal.analysis.drop.simulate_drop` is given for an event.

    - ``loss``: every axis loses power.
    - ``one-axis``: the axis ``axis`` does; default the one carrying the largest static
      force (the weight's share: its loss drops the most), the first of equals.
    - ``overload``: a step force of ``overload_n`` downward, the way the weight acts, at
      ``overload_at`` (a seal, AMB or touchdown bearing by name, or a disk's position
      given as its name; default the centre of mass), or a seal surge: the seals' pressure
      drop stepping from the operating one to ``surge_bar`` (their coefficients with it,
      :func:`ambseal.analysis.drop.support_matrices`), or both; every axis runs on.

    Parameters
    ----------
    cfg : RigConfig
        The rig.
    dm : DropModel
        Its drop model.
    loop : AmbLoop
        Its AMB loop.
    event : {"loss", "one-axis", "overload"}
        The event.
    axis : str, optional
        ``one-axis``: a channel of ``loop.names``.
    overload_n : float, optional
        ``overload``: the force (N), > 0; required there.
    overload_at : str, optional
        ``overload``: where it acts.
    surge_bar : float, optional
        ``overload``: the seals' pressure drop (bar) from t = 0, by the rule of
        ``[operating] pressure_bar`` (:func:`ambseal.config.check_operating`).

    Returns
    -------
    dict
        ``failed`` (tuple of channel names), ``overload`` (None or (z m, (F_x, F_y) N)),
        ``pressure_bar`` (the seals' through the drop; None: the operating one) and
        ``summary`` (one line for the report).

    Raises
    ------
    ConfigError
        An unknown event, axis or place; an axis, force or surge given to an event that
        takes none; an overload without a force or a surge, or with a surge the rule of
        ``[operating] pressure_bar`` refuses.
    """
    if event not in EVENTS:
        raise ConfigError(f"drop: event: expected one of {', '.join(EVENTS)}, got {event!r}")
    if axis is not None and event != "one-axis":
        raise ConfigError("--axis: names the axis of --event one-axis")
    if (overload_n is not None or overload_at is not None or surge_bar is not None) \
            and event != "overload":
        raise ConfigError("--overload-n, --overload-at, --surge-bar: the overload of "
                          "--event overload")
    if event == "loss":
        return {"failed": loop.names, "overload": None, "pressure_bar": None,
                "summary": "every AMB loses power"}
    if event == "one-axis":
        if axis is None:
            # the first of the most loaded: AMBs loaded alike within rounding tie
            load = np.abs(loop.static)
            axis = loop.names[int(np.flatnonzero(load >= (1 - 1e-9) * load.max())[0])]
        if axis not in loop.names:
            raise ConfigError(f"--axis: expected one of {', '.join(loop.names)}, got {axis!r}")
        return {"failed": (axis,), "overload": None, "pressure_bar": None,
                "summary": f"AMB axis {axis} loses power, the others run on"}
    if surge_bar is not None:  # a pressure drop of the seals: the rig file's rule of one
        check_operating({"pressure_bar": surge_bar}, {"pressure_bar": "--surge-bar"})
    surge = ("" if surge_bar is None else
             f"the seals' pressure drop surging from {cfg.operating.pressure_bar:g} to "
             f"{surge_bar:g} bar")
    if overload_n is None and surge_bar is not None and overload_at is None:
        return {"failed": (), "overload": None, "pressure_bar": surge_bar,
                "summary": surge}
    if overload_n is None or not (overload_n > 0 and np.isfinite(overload_n)):
        raise ConfigError(f"--overload-n: expected the step force (N, > 0) of --event "
                          f"overload (or --surge-bar alone), got {overload_n!r}")
    places = {"centre of mass": dm.z_cg}
    for kind in (cfg.seal, cfg.amb, cfg.touchdown, cfg.disk):
        places.update({x.name: x.position for x in kind if getattr(x, "name", None)})
    at = overload_at or "centre of mass"
    if at not in places:
        raise ConfigError(f"--overload-at: expected a seal, AMB, touchdown bearing or disk "
                          f"of the rig ({', '.join(sorted(places))}), got {at!r}")
    return {"failed": (), "overload": (places[at], (0.0, -float(overload_n))),
            "pressure_bar": surge_bar,
            "summary": f"a step force of {overload_n:g} N downward at {at} "
                       f"(z = {places[at]:.4g} m)" + (f" and {surge}" if surge else "")}
