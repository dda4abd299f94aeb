"""The sample-and-hold and computation delay of the digital controller, for the design model.

A controller that runs at ``f_s`` with ``n_d`` samples of computation delay
(``sample_rate_hz``, ``delay_samples``) acts on the plant through a
zero-order hold, whose phase is that of a delay of half a sample, and through the
computation delay itself: in total, up to the Nyquist frequency, nearly a pure delay ::

    τ = (n_d + 1/2) / f_s          (e.g. 1.5 samples at 10 kHz = 150 µs)

(Franklin, Powell & Workman, *Digital Control of Dynamic Systems*, 3rd ed. 1998, §5.3.1:
the ZOH is ``e^{−sT/2}·sinc(ωT/2)``; the sinc's gain loss, 1 − 2/π ≈ 36 % at Nyquist,
is left out). A design puts this delay into the actuator path of its generalised plant
as a Padé approximation ``e^{−sτ} ≈ N(−sτ)/N(sτ)`` (``control.pade``), so that the
continuous design already pays the phase the sampled loop will lose: without it the
discrete σ̄(S_o) peaks of H∞/μ designs with lightly damped modes at 40–130 Hz were up to
49 % above the continuous ones (2–7° of phase move such a peak a lot;
``benchmarks/README.md``).

A continuous analysis closes its loop with the same delay, up to the Nyquist frequency
(:func:`loop_delay`; at 10 kHz with 1.5 samples: order 4, within 1.3° up to 5 kHz): a
PID's continuous σ̄(S_o) peaks then equal those of the exactly sampled loop to 0.1 %.

Order rule: the smallest Padé order (1 … :data:`MAX_ORDER`) whose phase error stays
below :data:`PHASE_TOLERANCE_DEG` up to the top of the design band (150 µs up to 2 kHz, ωτ = 1.9: order 1 errs 21.5°, order 2 1.5° → order 2; its zeros lie at
|s| = √12/τ ≈ 3.7 kHz, above the band).
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass
from typing import Any

import control
import numpy as np

from ambseal.errors import ConfigError
from ambseal.lti.freqresp import freqresp
from ambseal.robust.timing import check_timing

__all__ = ["DesignDelay", "design_delay", "loop_delay", "PHASE_TOLERANCE_DEG",
           "MAX_ORDER"]

#: largest phase error (deg) of the Padé approximation allowed up to the design band's top
PHASE_TOLERANCE_DEG = 5.0
#: highest Padé order tried (order states per actuator channel join the synthesis model)
MAX_ORDER = 4


@dataclass(frozen=True, eq=False)
class DesignDelay:
    """The delay of the digital controller as the design model carries it.

    Attributes
    ----------
    delay_s : float
        τ = (delay_samples + 1/2) / sample_rate_hz (s).
    order : int
        Padé order (≥ 1).
    phase_error_deg : float
        Largest phase error of the approximation up to ``band_top_hz`` (deg).
    band_top_hz : float
        Top of the design band the order was chosen for (Hz).
    system : control.StateSpace
        SISO ``e^{−sτ}`` approximation, ``order`` states, unit DC gain, all-pass.
    """

    delay_s: float
    order: int
    phase_error_deg: float
    band_top_hz: float
    system: Any

    def to_dict(self) -> dict:
        """JSON-ready description (no matrices)."""
        return {"delay_s": self.delay_s, "pade_order": self.order,
                "phase_error_deg": self.phase_error_deg, "band_top_hz": self.band_top_hz}


@functools.lru_cache(maxsize=8)  # asked for at every judged loop; the result is immutable
def loop_delay(sample_rate_hz: float, delay_samples: int) -> DesignDelay:
    """The delay the continuous analyses put in every loop: :func:`design_delay` checked
    up to 0.999 of the Nyquist frequency (Hz).

    Parameters
    ----------
    sample_rate_hz : float
        Controller sample rate f_s (Hz), > 0.
    delay_samples : int
        Computation delay n_d (samples), ≥ 0.

    Returns
    -------
    DesignDelay
        τ = (n_d + 1/2)/f_s as a Padé system whose phase is checked up to 0.999·f_s/2.

    Raises
    ------
    ConfigError
        A non-positive or non-finite ``sample_rate_hz``, a negative or fractional
        ``delay_samples`` (named).
    """
    return design_delay(sample_rate_hz, delay_samples, 0.999 * float(sample_rate_hz) / 2)


def _pade_ss(tau: float, n: int):
    """The order-n Padé approximation of e^{−sτ} as a StateSpace realised in s·τ (entries
    of order one: A = A₁/τ, B = B₁/τ for the realisation (A₁, B₁, C₁, D) of N(−p)/N(p))."""

    num, den = control.pade(1.0, n)
    A1, B1, C1, D1 = (np.asarray(m, float) for m in control.ssdata(control.tf(num, den)))
    return control.ss(A1 / tau, B1 / tau, C1, D1)


def design_delay(sample_rate_hz: float, delay_samples: int, band_top_hz: float, *,
                 max_order: int = MAX_ORDER) -> DesignDelay:
    """The controller's hold + computation delay as a Padé system (module docstring).

    Parameters
    ----------
    sample_rate_hz : float
        Controller sample rate f_s (Hz), > 0.
    delay_samples : int
        Computation delay n_d (samples), ≥ 0.
    band_top_hz : float
        Top of the design band (Hz), > 0: the approximation's phase is checked up to it.
    max_order : int
        Highest Padé order tried (default :data:`MAX_ORDER`); returned when no lower order
        meets the tolerance.

    Returns
    -------
    DesignDelay
        τ = (n_d + 1/2)/f_s and the lowest Padé order within
        :data:`PHASE_TOLERANCE_DEG` up to ``band_top_hz`` (:data:`MAX_ORDER` if none is).

    Raises
    ------
    ConfigError
        Non-positive or non-finite ``sample_rate_hz`` or ``band_top_hz``, a negative or
        fractional ``delay_samples`` (named).

    Examples
    --------
    >>> d = design_delay(10e3, 1, 2000.0)
    >>> round(d.delay_s * 1e6, 3), d.order
    (150.0, 2)
    """
    check_timing(sample_rate_hz, delay_samples)
    fs, top = float(sample_rate_hz), float(band_top_hz)
    if not (math.isfinite(top) and top > 0):
        raise ConfigError(f"design band top: {band_top_hz!r}, expected a finite frequency > 0 Hz")
    tau = (int(delay_samples) + 0.5) / fs
    w = 2 * np.pi * np.linspace(0.0, top, 200)
    exact = -w * tau
    for n in range(1, int(max_order) + 1):
        sys = _pade_ss(tau, n)
        h = freqresp(sys, w)[:, 0, 0]
        err = float(np.max(np.abs(np.degrees(np.unwrap(np.angle(h)) - exact))))
        if err <= PHASE_TOLERANCE_DEG or n == int(max_order):
            return DesignDelay(tau, n, err, top, sys)
    raise AssertionError("unreachable")  # pragma: no cover
