"""The digital closed loop shared by the virtual test facility and the output-error fit.

Timing (one sample of the rig's controller, period T = 1/f_s): at sample k the sensors
give y_k; the controller computes u_k = C_c x_c,k + D_c y_k; the current reference
i_ref,k = −u_k + e_k (e the excitation, thesis P2 Fig. 2) is held over [kT, (k+1)T)
(zero-order hold, the DAC); x_c,k+1 = A_c x_c,k + B_c y_k.

A plant discretised exactly with a zero-order hold then gives the closed loop

    [x; x_c]_{k+1} = [[A_d − B_d D_c C, −B_d C_c], [B_c C, A_c]] [x; x_c]_k + [B_d; 0] e_k,

which :func:`simulate_lti` runs as an exact block recursion, vectorised over the record.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.linalg as sla

__all__ = ["DiscreteController", "discrete_controller", "zoh", "closed_loop_matrices",
           "simulate_lti"]


@dataclass(frozen=True)
class DiscreteController:
    """x_c,k+1 = A x_c,k + B y_k, u_k = C x_c,k + D y_k at ``dt`` (s); i_ref = −u + e."""

    A: np.ndarray
    B: np.ndarray
    C: np.ndarray
    D: np.ndarray
    dt: float

    def to_dict(self) -> dict:
        return {"type": "state_space", "dt": self.dt,
                **{k: getattr(self, k).tolist() for k in "ABCD"}}

    @classmethod
    def from_dict(cls, d: dict) -> "DiscreteController":
        """From ``to_dict()`` output; raises ValueError on a malformed dict."""
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
        return cls(A, B, C, D, dt)


def discrete_controller(K, dt: float, method: str = "tustin") -> DiscreteController:
    """Discretise a continuous ``control.StateSpace`` controller at ``dt`` (s).

    ``method`` is ``"tustin"`` (bilinear, the usual choice for a digital PID) or ``"zoh"``.
    """
    import control

    Kd = control.sample_system(control.ss(K.A, K.B, K.C, K.D), dt, method=method)
    return DiscreteController(np.asarray(Kd.A), np.asarray(Kd.B), np.asarray(Kd.C),
                              np.asarray(Kd.D), dt)


def zoh(A: np.ndarray, B: np.ndarray, dt: float) -> tuple[np.ndarray, np.ndarray]:
    """Exact zero-order-hold discretisation: (e^{A dt}, ∫₀^dt e^{Aτ} dτ B)."""
    n, m = B.shape
    M = np.zeros((n + m, n + m))
    M[:n, :n] = A * dt
    M[:n, n:] = B * dt
    E = sla.expm(M)
    return E[:n, :n], E[:n, n:]


def closed_loop_matrices(Ad, Bd, C, ctrl: DiscreteController):
    """The discrete closed loop from e (current excitation) to the plant state.

    Returns (A_cl, B_cl, C_y, C_iref, D_iref): state [x; x_c]; y = C_y z;
    i_ref = C_iref z + D_iref e.
    """
    n, m = Bd.shape
    nc = ctrl.A.shape[0]
    Acl = np.block([[Ad - Bd @ ctrl.D @ C, -Bd @ ctrl.C], [ctrl.B @ C, ctrl.A]])
    Bcl = np.vstack([Bd, np.zeros((nc, m))])
    Cy = np.hstack([C, np.zeros((C.shape[0], nc))])
    Ci = -np.hstack([ctrl.D @ C, ctrl.C])
    return Acl, Bcl, Cy, Ci, np.eye(m)


def simulate_lti(A: np.ndarray, B: np.ndarray, Cs: list[np.ndarray], u: np.ndarray,
                 block: int = 32) -> list[np.ndarray]:
    """Simulate z_{k+1} = A z_k + B u_k from z_0 = 0; return [C z_k for C in Cs].

    Exact block recursion, vectorised over the record: with blocks of L samples,
    z_{(b+1)L} = A^L z_{bL} + [A^{L−1}B … B] u_block, and inside a block
    y_{bL+j} = C A^j z_{bL} + Σ_{i<j} C A^{j−1−i} B u_{bL+i} (Markov parameters in a
    block-Toeplitz matrix). Only the N/L block starts run in a Python loop; no
    eigendecomposition, so repeated or defective closed-loop modes are no problem.

    Parameters
    ----------
    A : ndarray (n, n); B : ndarray (n, m); Cs : list of ndarray (p_i, n)
    u : ndarray (N, m)
    block : int
        Block length L.

    Returns
    -------
    list of ndarray (N, p_i)
    """
    N, m = u.shape
    n = A.shape[0]
    C = np.vstack(Cs)
    p = C.shape[0]
    L = max(1, min(block, N))
    powers = [np.eye(n)]
    for _ in range(L):
        powers.append(A @ powers[-1])
    O = np.vstack([C @ powers[j] for j in range(L)])  # (L p, n)
    markov = [np.zeros((p, m))] + [C @ powers[j - 1] @ B for j in range(1, L)]
    T = np.zeros((L, p, L, m))
    for j in range(1, L):
        for i in range(j):
            T[j, :, i, :] = markov[j - i]
    T = T.reshape(L * p, L * m)
    G = np.hstack([powers[L - 1 - i] @ B for i in range(L)])  # (n, L m)
    nb = -(-N // L)
    U = np.zeros((nb * L, m))
    U[:N] = u
    Ub = U.reshape(nb, L * m)
    drive = Ub @ G.T  # (nb, n)
    AL = powers[L]
    Z = np.empty((nb, n))
    z = np.zeros(n)
    with np.errstate(over="ignore", invalid="ignore"):
        for b in range(nb):
            Z[b] = z
            z = AL @ z + drive[b]
        Y = (Z @ O.T + Ub @ T.T).reshape(nb * L, p)[:N]
    out, row = [], 0
    for Ci in Cs:
        out.append(Y[:, row:row + Ci.shape[0]])
        row += Ci.shape[0]
    return out
