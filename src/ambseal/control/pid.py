"""The decentralised PID reference controller (thesis P5 Eq. 6, §4.2)."""

from __future__ import annotations

import numpy as np

__all__ = ["pid_controller"]


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
        outputs=[f"u_{c}" for c in channels],
        states=[f"pid_{c}_{k}" for c in channels for k in range(ns)],
    )
