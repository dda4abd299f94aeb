"""The decentralised PID reference controller (thesis P5 Eq. 6, §4.2)."""

from __future__ import annotations

from dataclasses import replace

import numpy as np

__all__ = ["pid_controller", "reference_controller", "controller_from_metadata"]


def pid_controller(
    kp: float, ti: float, td: float, eps: float, channels: list[str] | tuple[str, ...]
):
    """Decentralised PID, the same on every actuator axis.

    K_PID(s) = Kp (1 + 1/(Ti s) + Td s/(ε Td s + 1))   (thesis P5 Eq. 6)

    Parameters
    ----------
    kp : float
        Proportional gain Kp (A/m).
    ti, td : float
        Integral and derivative times (s); ``td = 0`` drops the derivative.
    eps : float
        Derivative filter factor ε (-).
    channels : sequence of str
        Axis names, e.g. ``("A_zeta", "A_eta", "B_zeta", "B_eta")``: inputs are the
        displacements (m), outputs the current references (A) of the same axes.

    Returns
    -------
    control.StateSpace
        Diagonal controller with 2 states per axis (integrator, derivative filter), used in
        negative feedback u = −K y.
    """
    import control

    from ..lti.pickling import picklable

    picklable()
    # one axis: x1 integrator of e, x2 derivative filter state
    if td > 0:
        tf = eps * td
        a = np.array([[0.0, 0.0], [0.0, -1.0 / tf]])
        b = np.array([[1.0], [1.0]])
        c = np.array([[kp / ti, -kp * td / tf**2]])
        d = np.array([[kp * (1 + td / tf)]])
    else:
        a, b = np.zeros((1, 1)), np.ones((1, 1))
        c, d = np.array([[kp / ti]]), np.array([[kp]])
    n = len(channels)
    eye = np.eye(n)
    A, B, C, D = (np.kron(eye, m) for m in (a, b, c, d))
    ns = a.shape[0]
    return control.ss(
        A, B, C, D,
        inputs=[f"y_{c}" for c in channels],
        outputs=[f"i_{c}" for c in channels],
        states=[f"pid_{c}_{k}" for c in channels for k in range(ns)],
    )


def reference_controller(cfg, method: str = "tustin"):
    """The rig's reference PID (``[controller.pid]``) as the digital controller that runs
    at ``[controller] sample_rate_hz`` (Tustin by default), described by its parameters.

    Parameters
    ----------
    cfg : RigConfig
    method : {"tustin", "zoh"}

    Returns
    -------
    ambseal.identify.loop.DiscreteController
        With ``description = {"type": "pid", kp, ti, td, eps, "discretisation"}``.

    Raises
    ------
    DataError
        The rig has no ``[controller.pid]``.
    """
    from ..errors import DataError
    from ..identify.loop import discrete_controller
    from ..model.amb import channel_names

    p = cfg.controller.pid
    if p is None:
        raise DataError("controller.pid: the rig has no reference PID to run the acquisition")
    K = pid_controller(p.kp, p.ti, p.td, p.eps, channel_names(cfg))
    ctrl = discrete_controller(K, 1.0 / cfg.controller.sample_rate_hz, method)
    return replace(ctrl, description={"type": "pid", "kp": p.kp, "ti": p.ti, "td": p.td,
                                      "eps": p.eps, "discretisation": method})


def controller_from_metadata(meta: dict, axes: tuple[str, ...], source: str = "<data>"):
    """The digital controller that ran, from a record's ``controller`` metadata, a PID
    description included.

    ``{"type": "pid", kp, ti, td, eps, "discretisation": "tustin"|"zoh"}`` (P5 Eq. 6 at the
    record's sample rate) is discretised here; anything else is read by
    :func:`ambseal.identify.stages.controller_from_metadata`.

    Raises
    ------
    DataError
        Missing or malformed controller metadata, naming the file.
    """
    from ..errors import DataError
    from ..identify import stages
    from ..identify.loop import discrete_controller

    c = meta.get("controller")
    if not (isinstance(c, dict) and c.get("type") == "pid" and "state_space" not in c):
        return stages.controller_from_metadata(meta, axes, source)
    fs = stages.sample_rate_of(meta, source)
    try:
        kp, ti, td, eps = (float(c[k]) for k in ("kp", "ti", "td", "eps"))
        if not (kp > 0 and ti > 0 and td >= 0 and eps > 0):
            raise ValueError("expected kp > 0, ti > 0, td >= 0, eps > 0")
        method = c.get("discretisation", "tustin")
        ctrl = discrete_controller(pid_controller(kp, ti, td, eps, axes), 1.0 / fs, method)
    except (KeyError, TypeError, ValueError) as exc:
        raise DataError(f"{source}: metadata.controller: {exc}") from None
    return stages.check_controller(replace(ctrl, description=dict(c)), axes, fs, source)
