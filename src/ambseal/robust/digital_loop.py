"""The digital closed loop of a sampled plant and a discrete controller, as it runs.

Timing (one sample of the controller, period T = 1/f_s): at sample k the sensors
give y_k; the controller computes u_k = C_c x_c,k + D_c y_k; the command
i_ref,k = −u_k + e_k (e an excitation added to it) is held over [kT, (k+1)T)
(zero-order hold, the DAC); x_c,k+1 = A_c x_c,k + B_c y_k.

A plant discretised exactly with a zero-order hold then gives the closed loop

    [x; x_c]_{k+1} = [[A_d − B_d D_c C, −B_d C_c], [B_c C, A_c]] [x; x_c]_k + [B_d; 0] e_k,

which :func:`ambseal.lti.discrete.simulate_lti` runs as an exact block recursion.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, replace

import numpy as np

from ambseal.lti import discretize, feedback_matrices

__all__ = ["DiscreteController", "discrete_controller", "closed_loop_matrices"]


@dataclass(frozen=True)
class DiscreteController:
    """x_c,k+1 = A x_c,k + B y_k, u_k = C x_c,k + D y_k at ``dt`` (s); i_ref = −u + e.

    Attributes
    ----------
    A : ndarray, shape (n_c, n_c)
        State matrix of the discrete controller.
    B : ndarray, shape (n_c, p)
        Input matrix; the inputs are the ``p`` measurements ``y_k``.
    C : ndarray, shape (m, n_c)
        Output matrix; the outputs are the ``m`` controls ``u_k`` (command ``−u_k``).
    D : ndarray, shape (m, p)
        Feedthrough (command unit per measurement unit).
    dt : float
        Sample time (s), > 0.
    description : dict or None
        What the matrices are, e.g. the PID parameters they were discretised from; written
        with them into a record's metadata, not compared.
    """

    A: np.ndarray
    B: np.ndarray
    C: np.ndarray
    D: np.ndarray
    dt: float
    description: dict | None = field(default=None, compare=False)

    def to_dict(self) -> dict:
        """``{"type": "state_space", dt, A, B, C, D}``, or the description with these
        under ``"state_space"``."""
        ss = {"type": "state_space", "dt": self.dt,
              **{k: getattr(self, k).tolist() for k in "ABCD"}}
        return {**self.description, "state_space": ss} if self.description else ss

    @classmethod
    def from_dict(cls, d: dict) -> "DiscreteController":
        """From ``to_dict()`` output; raises ValueError on a malformed dict."""
        if isinstance(d.get("state_space"), dict):
            desc = {k: v for k, v in d.items() if k != "state_space"}
            return replace(cls.from_dict(d["state_space"]), description=desc)
        try:
            mats = [np.atleast_2d(np.asarray(d[k], dtype=float)) for k in "ABCD"]
            dt = float(d["dt"])
        except (KeyError, TypeError, ValueError) as exc:
            raise ValueError(f"controller: expected keys A, B, C, D, dt ({exc})") from None
        A, B, C, D = mats
        if A.size == 0:
            A = np.zeros((0, 0))
            B = np.zeros((0, D.shape[1]))
            C = np.zeros((D.shape[0], 0))
        n, (p, m) = A.shape[0], D.shape
        want = {"A": (n, n), "B": (n, m), "C": (p, n), "D": (p, m)}
        for k, M in zip("ABCD", (A, B, C, D)):
            if M.ndim != 2 or M.shape != want[k]:
                raise ValueError(f"controller: {k} has shape {M.shape}, expected {want[k]} "
                                 f"(A n×n, B n×m, C p×n, D p×m from A {A.shape} and "
                                 f"D {D.shape})")
            if not np.all(np.isfinite(M)):
                raise ValueError(f"controller: {k} holds a value that is not finite")
        if not (math.isfinite(dt) and dt > 0):
            raise ValueError(f"controller: dt: expected a sampling period > 0 (s), got {dt!r}")
        return cls(A, B, C, D, dt)


def discrete_controller(K, dt: float, method: str = "tustin") -> DiscreteController:
    """Discretise a continuous ``control.StateSpace`` controller at ``dt`` (s).

    Parameters
    ----------
    K : control.StateSpace
        Continuous controller from measurements to controls, ``u = K y``.
    dt : float
        Sample time (s), positive and finite.
    method : {"tustin", "zoh"}
        By :func:`ambseal.lti.discrete.discretize`: Tustin, the usual choice for a digital
        PID, or the zero-order-hold equivalent.

    Returns
    -------
    DiscreteController
        The matrices at ``dt``, no description.

    Raises
    ------
    ModelError
        A bad sample time, an unknown method or a discrete-time ``K``.
    """
    Kd = discretize(K, dt, method)
    return DiscreteController(np.asarray(Kd.A), np.asarray(Kd.B), np.asarray(Kd.C),
                              np.asarray(Kd.D), dt)


def closed_loop_matrices(Ad, Bd, C, ctrl: DiscreteController):
    """The discrete closed loop from e (an excitation added to the command) to the plant state.

    :func:`ambseal.lti.interconnect.feedback_matrices` of the sampled plant and the
    controller, with the excitation as the loop's input disturbance.

    Parameters
    ----------
    Ad : ndarray, shape (n, n)
        The sampled plant's state matrix.
    Bd : ndarray, shape (n, m)
        Its input matrix (``m`` current references).
    C : ndarray, shape (k, n)
        Its output matrix (``k`` measurements; no feedthrough).
    ctrl : DiscreteController
        The controller at the plant's sample time.

    Returns
    -------
    (A_cl, B_cl, C_y, C_iref, D_iref)
        State ``z = [x; x_c]``, input ``e``: ``y = C_y z``,
        ``i_ref = C_iref z + D_iref e``.
    """
    k = C.shape[0]
    Acl, Bcl, Ccl, Dcl = feedback_matrices((Ad, Bd, C, np.zeros((k, Bd.shape[1]))),
                                           (ctrl.A, ctrl.B, ctrl.C, ctrl.D))
    m = Bd.shape[1]
    return Acl, Bcl, Ccl[:k], Ccl[k:], Dcl[k:] + np.eye(m)
