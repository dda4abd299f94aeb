"""The timing of a controller as it runs on its target: a sample rate and a computation
delay in whole samples, checked before any discretisation or delay model is built.

Light on purpose (no python-control): configuration schemas take the bound from here.
"""

from __future__ import annotations

import math

from ambseal.errors import ConfigError

__all__ = ["MAX_DELAY_SAMPLES", "check_timing"]

#: A computation delay (controller samples): each sample adds a state per controller output
#: to every sampled loop; real-time targets delay by one or two samples, so 100 is ample.
MAX_DELAY_SAMPLES = 100


def check_timing(sample_rate_hz: float, delay_samples) -> None:
    """A finite rate > 0 Hz and a whole delay of 0 to :data:`MAX_DELAY_SAMPLES` samples.

    Parameters
    ----------
    sample_rate_hz : float
        The controller's sample rate (Hz).
    delay_samples : int
        The computation delay (samples).

    Raises
    ------
    ConfigError
        Either outside its range, naming the setting.
    """
    try:
        rate = float(sample_rate_hz)
        whole = int(delay_samples) == delay_samples
    except (TypeError, ValueError, OverflowError):
        rate, whole = math.nan, False
    if not (math.isfinite(rate) and rate > 0):
        raise ConfigError(f"controller.sample_rate_hz: {sample_rate_hz!r}, expected a "
                          "finite rate > 0 Hz")
    if not whole or not 0 <= delay_samples <= MAX_DELAY_SAMPLES:
        raise ConfigError(f"controller.delay_samples: {delay_samples!r}, expected a whole "
                          f"number of samples from 0 to {MAX_DELAY_SAMPLES}")
