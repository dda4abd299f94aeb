"""Weighting functions for the H∞ / μ designs (thesis P3 Eq. 11, P5 Eq. 7, §4.3).

* Performance weight on the (scaled) displacement error, Skogestad & Postlethwaite (2005)
  Eq. 2.105 with n = 1::

      W_p(s) = (s/M + ω_B) / (s + ω_B A)

  ``|W_p(0)| = 1/A`` (steady-state error A, integral action; thesis: A = 1/1000),
  ``|W_p(j∞)| = 1/M`` (sensitivity peak M; thesis: M chosen for a peak below 3, ISO 14839-3
  zone A), crossover of ``1/|W_p|`` through 1 near ω_B (the closed-loop bandwidth).
  Requiring ``‖W_p S‖∞ < 1`` bounds ``|S(jω)| < 1/|W_p(jω)|``.
* Control weight on the (scaled) current: a constant (P5 §4.3) or a first-order high-pass
  (P3 §3.3: crossover 1.4 kHz) that rolls the controller off above the rigid-body band::

      W_u(s) = k (1 + s/ω_z) / (1 + s/ω_p),   ω_p > ω_z,

  low-frequency gain ``k``, high-frequency gain ``k ω_p/ω_z``. It must be biproper so that
  ``D12`` of the generalised plant has full column rank.

All frequencies in rad/s unless the name says ``_hz``.
"""

from __future__ import annotations

import numpy as np

__all__ = ["performance_weight", "control_weight", "check_weight", "diagonal_weight",
           "wp_gain"]


def performance_weight(M: float, omega_b: float, A: float = 1e-3):
    """Performance weight ``W_p = (s/M + ω_B)/(s + ω_B A)`` (thesis P3 Eq. 11, P5 Eq. 7).

    Parameters
    ----------
    M : float
        Allowed high-frequency sensitivity bound, ``1/|W_p(j∞)|`` (-), > 1 in practice
        (thesis: tuned so that the σ̄(S_o) peak stays below 3).
    omega_b : float
        Bandwidth ω_B (rad/s), > 0.
    A : float
        Steady-state error, ``1/|W_p(0)|`` (-); thesis value 1/1000. ``0 < A < 1``.

    Returns
    -------
    control.TransferFunction
        SISO, first order, stable, biproper.

    Raises
    ------
    ValueError
        If a parameter is non-finite or out of range (named in the message).

    Examples
    --------
    >>> W = performance_weight(2.0, 200.0)
    >>> round(abs(W(0)), 3), round(abs(W(1e9j)), 3)
    (1000.0, 0.5)
    """
    import control

    for name, v in (("M", M), ("omega_b", omega_b), ("A", A)):
        if not (np.isfinite(v) and v > 0):
            raise ValueError(f"performance_weight: {name}={v!r} must be finite and > 0")
    if not A < 1:
        raise ValueError(f"performance_weight: A={A!r} (steady-state error) must be < 1")
    return control.tf([1.0 / M, omega_b], [1.0, omega_b * A])


def wp_gain(omega, M: float, omega_b: float, A: float = 1e-3) -> np.ndarray:
    """Closed form ``|W_p(jω)| = √((ω/M)² + ω_B²) / √(ω² + (ω_B A)²)`` (-), any array shape."""
    w = np.asarray(omega, float)
    return np.sqrt((w / M) ** 2 + omega_b**2) / np.sqrt(w**2 + (omega_b * A) ** 2)


def control_weight(gain: float, *, corner_hz: float | None = None,
                   hf_gain: float | None = None):
    """Control-effort weight ``W_u``: a constant, or a biproper first-order high-pass.

    Parameters
    ----------
    gain : float
        Low-frequency gain k (-, on the scaled current u/D_u), > 0.
    corner_hz : float, optional
        Frequency (Hz) where ``|W_u|`` has risen to about √2·k (the zero ω_z = 2π·corner).
        Without it ``W_u = k``.
    hf_gain : float, optional
        High-frequency gain ``k ω_p/ω_z`` (> ``gain``); required with ``corner_hz``.

    Returns
    -------
    control.TransferFunction
        SISO, stable, biproper (a static gain when ``corner_hz`` is None).

    Raises
    ------
    ValueError
        Non-positive gains or corner, ``hf_gain <= gain``, or ``hf_gain`` without corner.

    Examples
    --------
    >>> W = control_weight(0.5, corner_hz=100.0, hf_gain=5.0)
    >>> round(abs(W(0)), 3), round(abs(W(1e9j)), 3)
    (0.5, 5.0)
    """
    import control

    if not (np.isfinite(gain) and gain > 0):
        raise ValueError(f"control_weight: gain={gain!r} must be finite and > 0")
    if corner_hz is None:
        if hf_gain is not None:
            raise ValueError("control_weight: hf_gain needs corner_hz")
        return control.tf([float(gain)], [1.0])
    if not (np.isfinite(corner_hz) and corner_hz > 0):
        raise ValueError(f"control_weight: corner_hz={corner_hz!r} must be finite and > 0")
    if hf_gain is None or not (np.isfinite(hf_gain) and hf_gain > gain):
        raise ValueError(f"control_weight: hf_gain={hf_gain!r} must be finite and > gain={gain}")
    wz = 2 * np.pi * corner_hz
    wp = wz * hf_gain / gain
    return control.tf([gain / wz, gain], [1.0 / wp, 1.0])


def check_weight(W, name: str, *, biproper: bool = False):
    """Validate a SISO weight and return it as a ``control.StateSpace``.

    Parameters
    ----------
    W : control.TransferFunction, control.StateSpace or float
        The weight.
    name : str
        Its name for the message (``"W_p"``, ``"W_u"``).
    biproper : bool
        Also require a non-zero direct term (needed for ``W_u``: ``D12`` full rank).

    Returns
    -------
    control.StateSpace
        The weight, 1 input, 1 output.

    Raises
    ------
    ValueError
        If the weight is not SISO, not proper (more zeros than poles), discrete-time, has
        a pole with ``Re ≥ 0``, non-finite coefficients, or (``biproper``) ``D = 0``.
    """
    import control

    if np.isscalar(W):
        if not (np.isfinite(W) and W != 0):
            raise ValueError(f"weight {name}: a constant weight must be finite and non-zero, got {W!r}")
        return control.ss([], [], [], [[float(W)]])
    if isinstance(W, control.TransferFunction):
        if W.ninputs != 1 or W.noutputs != 1:
            raise ValueError(f"weight {name}: must be SISO, got {W.noutputs}×{W.ninputs}")
        num = np.trim_zeros(np.atleast_1d(np.asarray(W.num[0][0], float)), "f")
        den = np.trim_zeros(np.atleast_1d(np.asarray(W.den[0][0], float)), "f")
        if num.size > den.size:
            raise ValueError(
                f"weight {name} is not proper: numerator degree {num.size - 1} > denominator "
                f"degree {den.size - 1}; add a high-frequency pole")
    elif not isinstance(W, control.StateSpace):
        raise ValueError(f"weight {name}: expected a TransferFunction, StateSpace or number, "
                         f"got {type(W).__name__}")
    if W.isdtime(strict=True):
        raise ValueError(f"weight {name}: must be continuous-time")
    S = control.ss(W)
    if S.ninputs != 1 or S.noutputs != 1:
        raise ValueError(f"weight {name}: must be SISO, got {S.noutputs}×{S.ninputs}")
    mats = [np.asarray(m, float) for m in (S.A, S.B, S.C, S.D)]
    if not all(np.all(np.isfinite(m)) for m in mats):
        raise ValueError(f"weight {name}: non-finite coefficients")
    if S.nstates and np.max(np.linalg.eigvals(mats[0]).real) >= 0:
        raise ValueError(f"weight {name}: has a pole with Re ≥ 0; weights must be stable")
    if biproper and abs(float(mats[3][0, 0])) == 0.0:
        raise ValueError(f"weight {name}: must be biproper (non-zero gain at high frequency)")
    return S


def diagonal_weight(W, n: int, name: str, *, biproper: bool = False):
    """``diag(W, …, W)`` (n copies) of a SISO weight as a ``control.StateSpace``.

    Raises ValueError as :func:`check_weight`.
    """
    import control

    S = check_weight(W, name, biproper=biproper)
    eye = np.eye(n)
    A, B, C, D = (np.kron(eye, np.asarray(m, float).reshape(np.shape(m) or (1, 1)))
                  for m in (S.A, S.B, S.C, S.D))
    if S.nstates == 0:
        A, B, C = np.zeros((0, 0)), np.zeros((0, n)), np.zeros((n, 0))
    return control.ss(A, B, C, D)
