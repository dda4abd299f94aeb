"""Discretisation and simulation of linear time-invariant systems.

* :func:`zoh` — the exact zero-order-hold equivalent of ``(A, B)`` (Franklin, Powell &
  Workman, *Digital Control of Dynamic Systems*, 3rd ed., §6.3): one ``expm`` of the
  augmented matrix ``[[A, B], [0, 0]]·dt``, balanced first;
* :func:`discretize` — a continuous ``control.StateSpace`` at a sample time, by ZOH
  (:func:`zoh`) or Tustin (``control.sample_system``), names kept;
* :func:`simulate_lti` — ``z_{k+1} = A z_k + B u_k`` from rest, an exact block recursion
  vectorised over the record.

A continuous system driven by a piecewise-constant input is simulated exactly by
``simulate_lti(*zoh(A, B, dt), ...)``: every time response of ambseal (impulse responses,
digital closed loops, filtered signals) runs through these two.
"""

from __future__ import annotations

from functools import lru_cache
from typing import Any

import control
import numpy as np
import scipy.linalg as sla

from ambseal.errors import ModelError
from ambseal.lti.compiled import cached_njit
from ambseal.lti.memo import ArrayMemo

__all__ = ["zoh", "discretize", "simulate_lti", "simulate_modal_loop"]

_METHODS = ("tustin", "zoh")
#: The last large (A, B, dt) sampled: at least 8, and as many as 64 MB hold — the API 617
#: Level I sweep samples one plant per cross-coupling (11 and more) and repeats the sweep
#: for each controller (a 392-state plant's e^{AT} is 1.2 MB, a 1 888-state one's 28 MB).
_ZOH = ArrayMemo(keep_bytes=64 * 2**20)


def zoh(A: np.ndarray, B: np.ndarray, dt: float, *, keep: bool = True
        ) -> tuple[np.ndarray, np.ndarray]:
    """Exact zero-order-hold discretisation ``(e^{A dt}, ∫₀^dt e^{Aτ} dτ B)``.

    Parameters
    ----------
    A : ndarray, shape (n, n)
        Continuous state matrix (1/s).
    B : ndarray, shape (n, m)
        Continuous input matrix (state unit per input unit and second).
    dt : float
        Sample time (s), > 0.
    keep : bool
        Keep the result for the next call with the same arrays (set False for a system
        sampled once, e.g. a closed loop simulated once: it would push a plant out).

    Returns
    -------
    A_d : ndarray, shape (n, n)
        ``e^{A dt}``.
    B_d : ndarray, shape (n, m)
        ``∫₀^dt e^{Aτ} dτ B``: the input held constant over each sample.

    Notes
    -----
    Franklin, Powell & Workman, *Digital Control of Dynamic Systems*, 3rd ed., §6.3: one
    ``expm`` of ``[[A, B], [0, 0]]·dt``, after a diagonal balancing of ``A``. The result for
    the last few large ``(A, B, dt)`` is kept (:class:`~ambseal.lti.memo.ArrayMemo`):
    a large plant is sampled once for every controller closed with it.
    """
    if not keep:
        return _zoh(A, B, dt)
    Ad, Bd = _ZOH.get((np.asarray(A, float), np.asarray(B, float)), float(dt),
                      lambda: _zoh(A, B, dt))
    return Ad.copy(), Bd.copy()


def _zoh(A, B, dt):
    # a diagonal similarity first (Parlett & Reinsch 1969): controllers from H∞ synthesis
    # mix entries from 1 to 1e9, and expm of the unbalanced matrix loses up to 7 digits
    # (an impulse response moved by 5e-5 for a 1e-12 change of A_K; balanced, by 1e-12)
    A, (sc, _) = sla.matrix_balance(A, permute=False, separate=True)
    n, m = B.shape
    M = np.zeros((n + m, n + m))
    M[:n, :n] = A * dt
    M[:n, n:] = B / sc[:, None] * dt
    E = sla.expm(M)
    return E[:n, :n] * (sc[:, None] / sc[None, :]), E[:n, n:] * sc[:, None]


def discretize(sys: Any, dt_s: float, method: str = "tustin"):
    """Discrete-time equivalent of a continuous ``control.StateSpace``.

    Parameters
    ----------
    sys : control.StateSpace
        Continuous-time system.
    dt_s : float
        Sample time (s), positive and finite.
    method : {"tustin", "zoh"}
        Bilinear transform (``control.sample_system``) or the exact zero-order-hold
        equivalent (:func:`zoh`).

    Returns
    -------
    control.StateSpace
        ``dt = dt_s``, with ``sys``'s signal names.

    Raises
    ------
    ModelError
        A bad sample time, an unknown method or a discrete-time input.
    """

    if not (np.isfinite(dt_s) and dt_s > 0):
        raise ModelError(f"dt_s={dt_s!r}: the sample time must be a positive number of seconds")
    if method not in _METHODS:
        raise ModelError(f"method={method!r}: expected one of {_METHODS}")
    if sys.isdtime(strict=True):
        raise ModelError("discretize: the system is already discrete-time")
    A, B, C, D = (np.asarray(X, float) for X in (sys.A, sys.B, sys.C, sys.D))
    if method == "zoh":
        Ad, Bd = zoh(A, B, dt_s)
        Cd, Dd = C, D
    else:
        d = control.sample_system(control.ss(A, B, C, D), dt_s, method=method)
        Ad, Bd, Cd, Dd = (np.asarray(X, float) for X in (d.A, d.B, d.C, d.D))
    return control.ss(Ad, Bd, Cd, Dd, dt_s, inputs=list(sys.input_labels),
                      outputs=list(sys.output_labels), name=f"{sys.name}_{method}")


def simulate_lti(A: np.ndarray, B: np.ndarray, Cs: list[np.ndarray], u: np.ndarray,
                 block: int = 32, start: int = 0) -> list[np.ndarray]:
    """Simulate ``z_{k+1} = A z_k + B u_k`` from ``z_0 = 0``; return ``[C z_k for C in Cs]``
    for the samples ``k ≥ start``.

    Exact block recursion, vectorised over the record: with blocks of L samples,
    ``z_{(b+1)L} = A^L z_{bL} + [A^{L−1}B … B] u_block``, and inside a block
    ``y_{bL+j} = C A^j z_{bL} + Σ_{i<j} C A^{j−1−i} B u_{bL+i}`` (Markov parameters in a
    block-Toeplitz matrix). Only the N/L block starts run in a Python loop; no
    eigendecomposition, so repeated or defective modes are no problem. A diverging system
    gives ``inf``/``nan`` samples, no error.

    Parameters
    ----------
    A : ndarray, shape (n, n)
        Discrete state matrix (e.g. ``A_d`` of :func:`zoh`).
    B : ndarray, shape (n, m)
        Discrete input matrix.
    Cs : list of ndarray, shapes (p_i, n)
        Output matrices; one output array is returned for each.
    u : ndarray, shape (N, m)
        Input samples ``u_0 … u_{N−1}``, one row per sample.
    block : int
        Block length L.
    start : int
        First sample returned. The state still runs from sample 0, but the outputs — most
        of the arithmetic — are formed only from the block holding ``start`` on (an
        output-error fit on the end of a long record pays for its window only).

    Returns
    -------
    list of ndarray, shapes (N − start, p_i)
        ``C_i z_k`` for ``k = start … N − 1``, one array per matrix of ``Cs``.
    """
    N, m = u.shape
    n = A.shape[0]
    C = np.vstack(Cs)
    p = C.shape[0]
    L = max(1, min(block, N))
    # C A^j and A^j B for j < L by products with the small side (p·n² and n²·m flops a
    # step, not n³), and A^L by repeated squaring
    CA, AB = _powers(*(np.ascontiguousarray(X, dtype=float) for X in (A, B, C)), L)
    O = CA.reshape(L * p, n)
    markov = np.zeros((L, p, m))  # by lag: C A^(j−1) B, none (zero) at lag 0
    markov[1:] = CA[:-1] @ B
    T = markov[_lags(L)]  # (L, L, p, m): [j, i] → lag j − i, lags ≤ 0 the zero one
    T = T.transpose(0, 2, 1, 3).reshape(L * p, L * m)
    G = AB[::-1].transpose(1, 0, 2).reshape(n, L * m)  # [A^(L−1) B … B]
    nb = -(-N // L)
    U = np.zeros((nb * L, m))
    U[:N] = u
    Ub = U.reshape(nb, L * m)
    drive = Ub @ G.T  # (nb, n)
    AL = np.linalg.matrix_power(A, L)
    with np.errstate(over="ignore", invalid="ignore"):
        b0 = min(max(start, 0), N) // L
        Z = _block_states(np.ascontiguousarray(AL), np.ascontiguousarray(drive), b0)
        Y = (Z @ O.T + Ub[b0:] @ T.T).reshape((nb - b0) * L, p)
        Y = Y[start - b0 * L:N - b0 * L]
    out, row = [], 0
    for Ci in Cs:
        out.append(Y[:, row:row + Ci.shape[0]])
        row += Ci.shape[0]
    return out


def simulate_modal_loop(mu: np.ndarray, Bz: np.ndarray, Cm: np.ndarray, K, d: np.ndarray
                        ) -> np.ndarray:
    """Simulate, from rest, a discrete loop whose real plant is given in modal form:
    ``O(n m)`` a step, no ``n × n`` matrix.

    Plant ``x_{k+1} = diag(μ) x_k + B_z u_k``, ``y_k = C_m x_k`` (the complex modal form of
    a real plant: :func:`ambseal.lti.freqresp.sampled_modal_form`); controller
    ``x_{K,k+1} = A_K x_{K,k} + B_K y_k``, ``i_k = −(C_K x_{K,k} + D_K y_k)``;
    ``u_k = i_k + d_k``. The real system is stepped, not its complex copy: one mode of
    each conjugate pair (``Im μ > 0``, its output counted twice, ``y = Re(…)``) and the
    real modes with real rows and columns. Stepping every complex mode and dropping
    ``Im y`` would leave the part where partners drift from conjugacy without feedback,
    and an open-loop unstable mode grows there until its rounding reaches the output. The same samples as :func:`simulate_lti` of the loop's
    dense state space with ``A_d = V diag(μ) V⁻¹``, exactly in exact arithmetic. A
    diverging loop gives ``inf``/``nan`` samples, no error.

    Parameters
    ----------
    mu : numpy.ndarray of complex, shape (n,)
        The sampled plant's poles ``e^{λ dt}``, in conjugate pairs and real values.
    Bz : numpy.ndarray of complex, shape (n, nu)
        Its modal input rows.
    Cm : numpy.ndarray of complex, shape (ny, n)
        Its modal output columns (the plant has no feedthrough).
    K : (A_K, B_K, C_K, D_K)
        Discrete controller on the plant's sample time, ``ny`` inputs → ``nu`` outputs.
    d : numpy.ndarray, shape (N, nu)
        The disturbances added to the controller's output, one row per sample.

    Returns
    -------
    numpy.ndarray, shape (N, ny + nu)
        ``[y_k, i_k]`` for ``k = 0 … N − 1``.

    Raises
    ------
    ModelError
        If ``mu`` is not closed under conjugation (not a real plant's form).
    """
    pos, real = mu.imag > 0, mu.imag == 0
    if np.count_nonzero(pos) != np.count_nonzero(mu.imag < 0) or not np.array_equal(
            np.sort_complex(mu[pos]), np.sort_complex(np.conj(mu[mu.imag < 0]))):
        raise ModelError("simulate_modal_loop: the poles are not in conjugate pairs "
                         "(not the modal form of a real plant)")
    mu = np.concatenate([mu[pos], mu[real].real])
    Bz = np.concatenate([Bz[pos], Bz[real].real])
    Cm = np.concatenate([2 * Cm[:, pos], Cm[:, real].real], axis=1)
    Ak, Bk, Ck, Dk = (np.atleast_2d(np.asarray(X, float)) for X in K)
    nk = Bk.shape[0] if Bk.size else 0
    Ak, Bk, Ck = Ak.reshape(nk, nk), Bk.reshape(nk, -1), Ck.reshape(-1, nk)
    ny = Cm.shape[0]
    N = d.shape[0]
    out = np.empty((N, ny + Dk.shape[0]))
    x, xk = np.zeros(mu.size, complex), np.zeros(nk)
    with np.errstate(over="ignore", invalid="ignore"):
        for k in range(N):
            y = (Cm @ x).real
            i = -(Ck @ xk + Dk @ y)
            out[k, :ny], out[k, ny:] = y, i
            x = mu * x + Bz @ (i + d[k])
            xk = Ak @ xk + Bk @ y
    return out


@lru_cache(maxsize=8)
def _lags(L: int) -> np.ndarray:
    """``max(j − i, 0)`` for j, i < L: the Markov parameter of each block-Toeplitz entry."""
    lag = np.subtract.outer(np.arange(L), np.arange(L))
    lag[lag < 0] = 0
    lag.flags.writeable = False
    return lag


def _powers(A: np.ndarray, B: np.ndarray, C: np.ndarray, L: int):
    """``C A^j`` (L, p, n) and ``A^j B`` (L, n, m) for j < L, each from the previous by one
    BLAS product into its slot. Not compiled: numba's ``np.dot`` with an output argument
    took seconds to compile on a command's first run, and saved about 40 µs a call."""
    CA = np.empty((L, C.shape[0], A.shape[0]))
    AB = np.empty((L, A.shape[0], B.shape[1]))
    CA[0] = C
    AB[0] = B
    for j in range(1, L):
        np.dot(CA[j - 1], A, out=CA[j])
        np.dot(A, AB[j - 1], out=AB[j])
    return CA, AB


@cached_njit(nogil=True)
def _block_states(AL: np.ndarray, drive: np.ndarray, b0: int) -> np.ndarray:  # pragma: no cover - compiled
    """States at the block starts ``b ≥ b0``, ``Z[b+1] = AL Z[b] + drive[b]`` from
    ``Z[0] = 0``: the one sequential part of :func:`simulate_lti`, compiled (numba) because
    a Python loop over the blocks of a long record cost more than the vectorised rest."""
    nb, n = drive.shape
    Z = np.empty((nb - b0, n))
    z = np.zeros(n)
    t = np.empty(n)
    for b in range(nb):
        if b >= b0:
            Z[b - b0] = z
        np.dot(AL, z, t)  # the BLAS product of ``AL @ z``, into a buffer
        for i in range(n):
            z[i] = t[i] + drive[b, i]
    return Z
