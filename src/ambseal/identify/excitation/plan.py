"""The excitations of the identification experiment, derived from the rig.

The thesis identified its test rig (6 A bias, 10 kHz controller) with 0.05 A signals: PRBS
runs (P2 §4.2, P4 §3.4), 10 ms impulses (P5 §3.3) and a 0–150 Hz chirp (P4 §3.4, Figs.
9–10). On another rig those numbers mean something else — 0.05 A is noise on a 50 A bias
and saturates a 0.5 A one; a 1 ms clock is two samples at 2 kHz — so every setting below
follows from the rig by the rule beside it, each reproducing the thesis rig's value:

* **Amplitude** of every excitation (PRBS, impulse, chirp, the stepped sine's larger whirl):
  ``[design.impulse] amplitude_a``, else the bias current i0 / 120
  (:func:`ambseal.model.amb.bias_current`; 0.05 A, P5 §3.3 and §5.1). The same key and rule
  give the design judgement's impulse (:mod:`ambseal.design.specs`).
* **Impulse**: ``[design.impulse] duration_s``, else :data:`SAMPLES_PER_IMPULSE` controller
  samples (10 ms); it starts after :data:`IMPULSE_LEAD` impulse lengths at rest (0.05 s) and
  the record lasts :data:`IMPULSE_RECORD` impulse lengths (0.4 s; the facility check of the
  designed controllers :data:`CHECK_RECORD`, 0.25 s, P5 Fig. 15).
* **PRBS**: clock period :data:`PRBS_CLOCK_SAMPLES` controller samples (1 ms), so its
  spectrum, sinc²(f T_c), is flat within 0.6 dB up to f_P = 0.2 / T_c = f_s / 50 (200 Hz,
  the top of the thesis's stepped sines, P4 §3.5.1); :data:`PRBS_CLOCKS` clock periods long
  (1 s), so its frequency resolution is f_r = 1 / (1000 T_c) (1 Hz).
* **Chirp** (linear): from f_r to :data:`CHIRP_TOP` · f_P (1–150 Hz: the thesis's 150 Hz
  as a fraction of the band the PRBS covers, the DC end lifted to the PRBS's resolution),
  :data:`CHIRP_RECORDS` PRBS records long (4 s).
* **Stepped sine** of the seal's frequency test (P4 §3.5.1, balanced whirl): up to f_top,
  the larger of the PRBS's flat band f_P and :data:`SYNC_MARGIN` times the top speed's
  synchronous frequency, in :data:`SINE_STEPS` steps of f_top / 10 from f_top / 10 with
  f_top / 20 before them (10, 20, 40, …, 200 Hz at rest: the thesis's 5–200 Hz in 10–20 Hz
  steps), so the seal's coefficients are seen over the band the other runs identify the
  rig in and at every synchronous whirl the machine runs.
* **FRF checks**: the chirp's closed loop over 2 f_r … :data:`CHECK_TOP` · f_P (2–140 Hz:
  the sweep's ends, where the response has not built up, left out); the plant from the PRBS
  record over 2 f_r … f_P (2–200 Hz, where the PRBS is flat).
* **Welch segments** (:func:`welch_segment`): the largest power of two within a quarter of
  the record (2048 of the PRBS's 10 000 samples, 8192 of the chirp's 40 000), so every
  estimate averages at least seven half-overlapping segments.

Everything timed in controller samples scales with the sample rate, everything in current
with the bias: on a rig with twice the bias and half the sample rate the amplitudes double
and the clock doubles in seconds.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from ambseal.config import RigConfig
from ambseal.errors import ConfigError
from ambseal.model import bias_current

__all__ = ["ExcitationPlan", "excitation_plan", "impulse_amplitude", "impulse_length",
           "welch_segment", "SAMPLES_PER_IMPULSE", "PRBS_CLOCK_SAMPLES"]

#: the excitation amplitude as a fraction of the bias current (0.05 A of 6 A, P5 §3.3)
BIAS_PER_AMPLITUDE = 120
#: the impulse's length in controller samples (10 ms at 10 kHz, P5 §3.3 and §5.1)
SAMPLES_PER_IMPULSE = 100
#: rest before the impulse, the identification record and the facility check's record, in
#: impulse lengths (0.05 s, 0.4 s and 0.25 s on the thesis rig)
IMPULSE_LEAD, IMPULSE_RECORD, CHECK_RECORD = 5, 40, 25
#: PRBS clock period in controller samples (1 ms at 10 kHz; the tracker's too,
#: :func:`ambseal.identify.tracking.tracking_excitation`) and record length in clock periods
PRBS_CLOCK_SAMPLES, PRBS_CLOCKS = 10, 1000
#: top of the PRBS's flat band f_P in units of its clock rate 1/T_c: sinc²(0.2) = −0.58 dB
PRBS_FLAT = 0.2
#: the chirp's top and the closed-loop check's top as fractions of f_P, and the chirp's
#: length in PRBS records (150 Hz, 140 Hz and 4 s on the thesis rig, P4 §3.4)
CHIRP_TOP, CHECK_TOP, CHIRP_RECORDS = 0.75, 0.7, 4
#: the stepped sine's steps of f_top / SINE_STEPS up to f_top, after one at half a step,
#: and f_top's margin above the top speed's synchronous frequency
SINE_STEPS, SYNC_MARGIN = 10, 1.1


@dataclass(frozen=True)
class ExcitationPlan:
    """The identification experiment's excitation settings (module docstring for the rules).

    Attributes
    ----------
    amplitude_a : float
        Amplitude of every excitation (A).
    impulse_s, impulse_start_s, impulse_record_s, check_record_s : float
        Impulse length, its start, the identification record and the facility check's
        record (s).
    prbs_clock_s, prbs_duration_s : float
        PRBS clock period and record length (s).
    chirp_hz : (float, float)
        The linear chirp's start and end frequency (Hz).
    chirp_s : float
        The chirp's length (s).
    closed_loop_band_hz, plant_band_hz : (float, float)
        The bands of the closed-loop (chirp) and plant (PRBS) FRF checks (Hz).
    sine_hz : tuple of float
        The stepped sine's frequencies (Hz).
    """

    amplitude_a: float
    impulse_s: float
    impulse_start_s: float
    impulse_record_s: float
    check_record_s: float
    prbs_clock_s: float
    prbs_duration_s: float
    chirp_hz: tuple[float, float]
    chirp_s: float
    closed_loop_band_hz: tuple[float, float]
    plant_band_hz: tuple[float, float]
    sine_hz: tuple[float, ...] = ()


def impulse_amplitude(cfg: RigConfig) -> float | None:
    """The rig's excitation and impulse amplitude (A): ``[design.impulse] amplitude_a``, else
    the bias current / 120 (module docstring), else None (no bias current, no limit).

    Parameters
    ----------
    cfg : RigConfig
        The rig (its ``[design.impulse]`` and AMBs).

    Returns
    -------
    float or None
        Thesis test rig: 6 A / 120 = 0.05 A (P5 §3.3).
    """
    i0 = bias_current(cfg)
    return cfg.design.impulse.amplitude_a or (i0 / BIAS_PER_AMPLITUDE if i0 else None)


def impulse_length(cfg: RigConfig) -> float:
    """The rig's current impulse length (s): ``[design.impulse] duration_s``, else
    :data:`SAMPLES_PER_IMPULSE` controller samples.

    Parameters
    ----------
    cfg : RigConfig
        The rig (its ``[design.impulse]`` and controller sample rate).

    Returns
    -------
    float
        Thesis test rig: 100 samples at 10 kHz = 10 ms (P5 §3.3).
    """
    return cfg.design.impulse.duration_s or SAMPLES_PER_IMPULSE / cfg.controller.sample_rate_hz


def welch_segment(n_samples: int) -> int:
    """Welch segment length for a record of ``n_samples``: the largest power of two within
    a quarter of it (at least 8), so the estimate averages at least seven half-overlapping
    segments.

    Parameters
    ----------
    n_samples : int
        Record length (samples).

    Returns
    -------
    int
        E.g. 2048 for 10 000 samples, 8192 for 40 000.
    """
    return 2 ** max(3, int(math.floor(math.log2(max(n_samples, 1) / 4))))


def excitation_plan(cfg: RigConfig, *, amplitude_a: float | None = None) -> ExcitationPlan:
    """The identification excitations of ``cfg`` (module docstring for the rules).

    Parameters
    ----------
    cfg : RigConfig
        The rig: its AMBs' bias currents (or current limits), its controller's sample rate
        and its ``[design.impulse]`` keys.
    amplitude_a : float, optional
        The amplitude (A) instead of the rig's (a command-line option).

    Returns
    -------
    ExcitationPlan
        Thesis test rig: 0.05 A; impulse 10 ms from 0.05 s in 0.4 s; PRBS clock 1 ms for
        1 s; chirp 1–150 Hz in 4 s; checks 2–140 Hz and 2–200 Hz; stepped sine at 10, 20,
        40, …, 200 Hz.

    Raises
    ------
    ConfigError
        No amplitude: none given, no ``[design.impulse] amplitude_a`` and no AMB bias
        current or current limit to derive it from.
    """
    amplitude = amplitude_a if amplitude_a is not None else impulse_amplitude(cfg)
    if amplitude is None:
        raise ConfigError("design.impulse.amplitude_a: the identification excitation's "
                          "amplitude cannot be derived (no [[amb]] bias_current or "
                          "current_limit); set it in [design.impulse] or with "
                          "--set design.impulse.amplitude_a=...")
    fs = cfg.controller.sample_rate_hz
    width = impulse_length(cfg)
    clock = PRBS_CLOCK_SAMPLES / fs
    prbs_s = PRBS_CLOCKS * clock
    flat = PRBS_FLAT / clock
    resolution = 1.0 / prbs_s
    op = cfg.operating
    top_speed_hz = op.speed_range_hz[1] if op.speed_range_hz else abs(op.speed_rpm) / 60.0
    top = max(flat, SYNC_MARGIN * top_speed_hz)
    return ExcitationPlan(
        amplitude_a=float(amplitude), impulse_s=float(width),
        impulse_start_s=IMPULSE_LEAD * width, impulse_record_s=IMPULSE_RECORD * width,
        check_record_s=CHECK_RECORD * width, prbs_clock_s=clock, prbs_duration_s=prbs_s,
        chirp_hz=(resolution, CHIRP_TOP * flat), chirp_s=CHIRP_RECORDS * prbs_s,
        closed_loop_band_hz=(2 * resolution, CHECK_TOP * flat),
        plant_band_hz=(2 * resolution, flat),
        # rounded to 1e-9 Hz: f_top / 10 · k in floating point, not a step off the rule
        sine_hz=tuple(round(f, 9) for f in
                      [top / (2 * SINE_STEPS)] + [top * k / SINE_STEPS
                                                  for k in range(1, SINE_STEPS + 1)]))
