"""The one stability rule of ambseal: when a set of poles is asymptotically stable.

Every verdict of the package — a judged closed loop, a synthesised controller's loop, a
sampled loop, a frozen point of a scheduled controller, a weight or a controller part that
must be stable — is taken by :func:`is_stable` on the poles, so a borderline design cannot
be "stable" for one caller and "unstable" for another.

**The rule.** Poles ``p`` of a continuous system (rad/s), or ``z`` of a discrete one of
sample time ``dt`` mapped to the same rates by ``s = ln z / dt``, are stable when

    max Re(s)  <  −RTOL · max(1 rad/s, max |s|),      RTOL = 1000 ε ≈ 2.2e-13,

ε the machine epsilon: every mode decays, by more than rounding can fake. The dense QR
eigenvalues of a state matrix whose largest |λ| is ω_max move by about ε·ω_max (a balanced
state matrix has a norm of that order); on the FE models and loops it was measured on the
real parts moved by up to 100 ε·ω_max, and RTOL keeps a margin of 10 over that. A loop with
an undamped mode (a lossless resonance that nothing damps) is therefore not stable. A
discrete pole at ``z = 0`` (a pure delay) has ``Re(s) = −∞`` and counts as stable.

:func:`decay_rate` gives the same quantity as a number: the largest real part of the
rates (1/s), as the cases of ``metrics.json`` report it (``max_real_pole``).
"""

from __future__ import annotations

import numpy as np

__all__ = ["RTOL", "decay_rate", "is_stable", "stability_tolerance", "unstable_poles"]

#: Relative tolerance of the rule: the eigenvalue solver's rounding level with a margin
#: (module docstring).
RTOL = 1e3 * float(np.finfo(float).eps)


def _rates(poles, dt: float) -> np.ndarray:
    """Poles as continuous rates (rad/s): ``poles``, or ``ln z / dt`` of a discrete system."""
    p = np.asarray(poles, dtype=complex).ravel()
    if not dt:
        return p
    s = np.empty_like(p)
    with np.errstate(divide="ignore"):  # z = 0: Re s = -inf
        s.real = np.log(np.abs(p)) / float(dt)
    s.imag = np.angle(p) / float(dt)
    return s


def stability_tolerance(poles, dt: float = 0.0) -> float:
    """The margin of the rule (1/s): ``RTOL · max(1, max |s|)`` over the finite rates; the
    rounding level below which a real part cannot be told from zero."""
    s = _rates(poles, dt)
    mag = np.abs(s[np.isfinite(s)])
    return RTOL * max(1.0, float(mag.max()) if mag.size else 1.0)


def decay_rate(poles, dt: float = 0.0) -> float:
    """Largest real part of the poles as continuous rates (1/s): ``max Re(p)``, or
    ``ln max|z| / dt`` of a discrete system; ``-inf`` without poles.

    Parameters
    ----------
    poles : array_like of complex
        Eigenvalues of a state matrix (rad/s), or ``z`` of a discrete one.
    dt : float
        Sample time (s) of a discrete system; 0 for a continuous one.

    Returns
    -------
    float
    """
    s = _rates(poles, dt)
    return float(s.real.max()) if s.size else float("-inf")


def is_stable(poles, dt: float = 0.0) -> bool:
    """Whether the poles are asymptotically stable by the rule of the module docstring.

    Parameters
    ----------
    poles : array_like of complex
        Eigenvalues of a state matrix (rad/s), or ``z`` of a discrete one; none is stable.
    dt : float
        Sample time (s) of a discrete system; 0 for a continuous one.

    Returns
    -------
    bool

    Examples
    --------
    >>> is_stable([-1 + 10j, -1 - 10j])
    True
    >>> is_stable([0j, -5 + 0j])            # a pole on the imaginary axis: not stable
    False
    >>> is_stable([0.5, 0.0], dt=1e-3)       # discrete: |z| < 1
    True
    """
    s = _rates(poles, dt)
    if not s.size:
        return True
    return bool(s.real.max() < -stability_tolerance(s))


def unstable_poles(poles, dt: float = 0.0) -> np.ndarray:
    """The poles that break the rule (as given: rad/s, or z), largest real rate first.

    Parameters
    ----------
    poles : array_like of complex
        Eigenvalues of a state matrix (rad/s), or ``z`` of a discrete one.
    dt : float
        Sample time (s) of a discrete system; 0 for a continuous one.

    Returns
    -------
    numpy.ndarray of complex
        The poles that are not stable by :func:`is_stable`'s rule; empty if none.
    """
    p = np.asarray(poles, dtype=complex).ravel()
    s = _rates(p, dt)
    bad = s.real >= -stability_tolerance(s)
    return p[bad][np.argsort(-s.real[bad], kind="stable")]
