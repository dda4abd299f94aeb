"""Excitation signals added to the current reference of chosen AMB actuator axes.

Closed-loop identification (thesis P2 §4.2, P4 §3.3) perturbs the levitated rotor with an
excitation current ``i_e`` added to the controller output of one or more actuator axes while
the rig records currents and displacements. This module builds those signals, sampled at the
rig's rate, for every axis of the rig — an axis that is not excited carries zeros, so the
array can be written straight into a measurement file (:mod:`ambseal.identify.records.data`).

Four kinds, one result type (:class:`Excitation`):

* :func:`prbs` — pseudo-random binary sequence, ``±amplitude``, held for one clock period,
  an independent sequence per excited axis (P2 §4.2 and P4 §3.4: "two PRBS identification
  signals have been simultaneously applied, one for each actuator direction");
* :func:`stepped_sine` — a sine per frequency, each step ``settling_cycles + cycles`` long,
  with the analysis window of each step returned separately (P4 §3.5.1: 5–200 Hz in 10 Hz
  steps, one seal-coefficient fit per frequency);
* :func:`chirp` — linear or logarithmic swept sine (P4 §3.4, Figs. 9–10: 0–150 Hz linear);
* :func:`impulse` — rectangular current pulse (P5 §3.3: 0.05 A for 10 ms, 0.05 s to 0.06 s,
  on both bearings in the ζ direction at once).

Which axes are excited is given by ``excited``: a sequence of axis names (gain 1 each) or a
mapping ``{axis: gain}`` — e.g. ``{"A_zeta": 1.0, "B_zeta": 1.0}`` for the parallel motion
of P4 §3.4 or ``{"A_zeta": 1.0, "B_zeta": -1.0}`` for a conical one. ``None`` excites all
axes with gain 1. The deterministic signals (stepped sine, chirp, impulse) put the same
waveform, times the gain, on every excited axis; the PRBS draws an independent sequence per
axis (the gain only scales it).

Time grid: ``time_s = arange(n) / sample_rate_hz`` with ``n = round(duration_s ·
sample_rate_hz)`` (``stepped_sine``: the sum of its steps). All amplitudes in ampere, times
in seconds, frequencies in hertz (the quantities a test engineer types). Invalid arguments
raise ``ValueError`` naming the argument.

Example
-------
>>> from ambseal.identify.excitation.signals import prbs
>>> ex = prbs(amplitude_a=0.1, clock_period_s=1e-3, duration_s=1.0, sample_rate_hz=5000.0,
...           excited=("A_zeta", "B_zeta"), seed=1)
>>> ex.values_a.shape, ex.axes
((5000, 4), ('A_zeta', 'A_eta', 'B_zeta', 'B_eta'))
>>> sorted(set(ex.values_a[:, 0].tolist())), float(abs(ex.values_a[:, 1]).max())
([-0.1, 0.1], 0.0)
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any, Mapping, Sequence

import numpy as np

__all__ = [
    "DEFAULT_AXES",
    "Excitation",
    "prbs",
    "stepped_sine",
    "chirp",
    "impulse",
]

#: Actuator axes of the thesis test facility (P2 Fig. 1(b)): bearing A/B, axis ζ/η.
DEFAULT_AXES: tuple[str, ...] = ("A_zeta", "A_eta", "B_zeta", "B_eta")

_KINDS = ("prbs", "stepped_sine", "chirp", "impulse")


# --------------------------------------------------------------------------- result
@dataclass(frozen=True, eq=False)
class Excitation:
    """An excitation current for every actuator axis of a rig.

    Attributes
    ----------
    time_s : ndarray, shape (n,)
        Sample times (s), ``arange(n) / sample_rate_hz``.
    values_a : ndarray, shape (n, n_axes)
        Excitation current (A) added to the current reference of each axis; column ``j``
        belongs to ``axes[j]``; zeros on axes not excited.
    axes : tuple of str, length n_axes
        Axis names, e.g. ``("A_zeta", "A_eta", "B_zeta", "B_eta")``.
    sample_rate_hz : float
        Sampling rate (Hz).
    kind : str
        ``"prbs"``, ``"stepped_sine"``, ``"chirp"`` or ``"impulse"``.
    params : dict
        JSON-safe description (kind, sample rate, axes, excited axes with gains and every
        argument of the generator), stored as ``metadata["excitation"]`` of a measurement.
    windows : tuple of (float, int, int), or None
        Stepped sine only: ``(frequency_hz, start, stop)`` per step, the analysis window as a
        Python slice ``values_a[start:stop]`` (the settling cycles before ``start`` are
        excitation too, but excluded). ``None`` for other kinds.

    Notes
    -----
    The arrays are made read-only. ``eq=False``: compare the arrays yourself.
    """

    time_s: np.ndarray
    values_a: np.ndarray
    axes: tuple[str, ...]
    sample_rate_hz: float
    kind: str
    params: dict = field(default_factory=dict)
    windows: tuple[tuple[float, int, int], ...] | None = None

    def __post_init__(self) -> None:
        t = np.asarray(self.time_s, dtype=float)
        v = np.asarray(self.values_a, dtype=float)
        axes = tuple(str(a) for a in self.axes)
        if t.ndim != 1:
            raise ValueError(f"time_s: expected shape (n,), got {t.shape}")
        if v.shape != (t.size, len(axes)):
            raise ValueError(f"values_a: expected shape ({t.size}, {len(axes)}), got {v.shape}")
        if self.kind not in _KINDS:
            raise ValueError(f"kind: expected one of {_KINDS}, got {self.kind!r}")
        t = t.copy()
        v = v.copy()
        t.setflags(write=False)
        v.setflags(write=False)
        object.__setattr__(self, "time_s", t)
        object.__setattr__(self, "values_a", v)
        object.__setattr__(self, "axes", axes)
        object.__setattr__(self, "sample_rate_hz", float(self.sample_rate_hz))
        if self.windows is not None:
            object.__setattr__(
                self, "windows", tuple((float(f), int(a), int(b)) for f, a, b in self.windows)
            )

    @property
    def n_samples(self) -> int:
        """Number of samples ``n``."""
        return int(self.time_s.size)

    @property
    def duration_s(self) -> float:
        """Record length ``n / sample_rate_hz`` (s)."""
        return self.n_samples / self.sample_rate_hz

    def column(self, axis: str) -> np.ndarray:
        """Excitation of one axis, shape (n,) (A).

        Raises
        ------
        KeyError
            If ``axis`` is not one of :attr:`axes`.
        """
        try:
            j = self.axes.index(axis)
        except ValueError:
            raise KeyError(f"axis {axis!r} not in {self.axes}") from None
        return self.values_a[:, j]

    def to_dict(self, *, include_samples: bool = False) -> dict:
        """JSON-safe summary; the sample arrays only when ``include_samples``."""
        out: dict[str, Any] = {
            "kind": self.kind,
            "axes": list(self.axes),
            "sample_rate_hz": self.sample_rate_hz,
            "n_samples": self.n_samples,
            "params": dict(self.params),
            "windows": None if self.windows is None else [list(w) for w in self.windows],
        }
        if include_samples:
            out["time_s"] = self.time_s.tolist()
            out["values_a"] = self.values_a.tolist()
        return out


# --------------------------------------------------------------------------- checks
def _number(name: str, value: Any, *, allow_zero: bool) -> float:
    """A finite number > 0 (>= 0 with ``allow_zero``), or a ValueError naming ``name``."""
    try:
        x = float(value)
    except (TypeError, ValueError):
        raise ValueError(f"{name}: expected a number, got {value!r}") from None
    if not math.isfinite(x) or x < 0 or (x == 0 and not allow_zero):
        raise ValueError(f"{name}: expected a finite number {'>=' if allow_zero else '>'} 0, "
                         f"got {value!r}")
    return x


def _positive(name: str, value: Any) -> float:
    return _number(name, value, allow_zero=False)


def _nonnegative(name: str, value: Any) -> float:
    return _number(name, value, allow_zero=True)


def _axes_and_gains(
    axes: Sequence[str], excited: Sequence[str] | Mapping[str, float] | None
) -> tuple[tuple[str, ...], np.ndarray, dict[str, float]]:
    if isinstance(axes, str):
        raise ValueError(f"axes: expected a sequence of axis names, got the string {axes!r}")
    names = tuple(str(a) for a in axes)
    if not names:
        raise ValueError("axes: expected at least one axis name")
    if len(set(names)) != len(names):
        raise ValueError(f"axes: names must be unique, got {names}")
    if excited is None:
        gains = {a: 1.0 for a in names}
    elif isinstance(excited, Mapping):
        gains = {}
        for a, g in excited.items():
            try:
                gf = float(g)
            except (TypeError, ValueError):
                raise ValueError(f"excited: gain of {a!r} must be a number, got {g!r}") from None
            if not math.isfinite(gf):
                raise ValueError(f"excited: gain of {a!r} must be finite, got {g!r}")
            gains[str(a)] = gf
    elif isinstance(excited, str):
        gains = {excited: 1.0}
    else:
        gains = {str(a): 1.0 for a in excited}
    if not gains:
        raise ValueError("excited: expected at least one axis to excite")
    unknown = [a for a in gains if a not in names]
    if unknown:
        raise ValueError(f"excited: axes {unknown} are not among axes {names}")
    g = np.array([gains.get(a, 0.0) for a in names])
    return names, g, gains


#: The longest excitation: 2·10⁶ samples (200 s at 10 kHz); a record of it on 4 axes holds
#: 16 columns of 8-byte samples, 256 MB, and its simulation and fit take minutes.
MAX_SAMPLES = 2_000_000


def _n_samples(duration_s: float, fs: float, name: str = "duration_s") -> int:
    n = int(round(duration_s * fs))
    if n > MAX_SAMPLES:
        raise ValueError(f"{name}: {duration_s:g} s at {fs:g} Hz gives {n} samples, more than "
                         f"{MAX_SAMPLES} (a record of 4 axes would need "
                         f"{n * 16 * 8 / 2**30:.3g} GB)")
    if n < 2:
        raise ValueError(f"{name}: {duration_s} s at {fs} Hz gives {n} samples, expected >= 2")
    return n


def _base_params(kind: str, fs: float, names: tuple[str, ...], gains: dict[str, float]) -> dict:
    return {"kind": kind, "sample_rate_hz": fs, "axes": list(names), "excited": dict(gains)}


# --------------------------------------------------------------------------- PRBS
def prbs(
    *,
    amplitude_a: float,
    clock_period_s: float,
    duration_s: float,
    sample_rate_hz: float,
    axes: Sequence[str] = DEFAULT_AXES,
    excited: Sequence[str] | Mapping[str, float] | None = None,
    seed: int = 0,
    method: str = "random",
) -> Excitation:
    """Pseudo-random binary sequence, ``±amplitude_a``, one independent sequence per axis.

    The level is drawn once per clock period and held: sample ``k`` takes the level of
    clock interval ``floor(k / (clock_period_s · sample_rate_hz))``, so level changes occur
    only at multiples of the clock period (rounded to the sample grid). The spectrum is
    nearly flat up to about ``0.44 / clock_period_s`` Hz (first null at ``1/clock_period_s``).

    Parameters
    ----------
    amplitude_a : float
        Level (A), > 0; the signal takes the values ``+amplitude_a`` and ``-amplitude_a``
        (P2 Fig. 5: 0.1 A).
    clock_period_s : float
        Clock period (s), at least one sample period.
    duration_s : float
        Record length (s).
    sample_rate_hz : float
        Sampling rate (Hz).
    axes : sequence of str
        All actuator axes of the rig (columns of ``values_a``).
    excited : sequence of str, mapping {axis: gain} or None
        Axes that carry a sequence (gain scales it); ``None`` = all.
    seed : int
        ``method="random"``: seed of :class:`numpy.random.SeedSequence`, spawned into one
        child generator per axis of ``axes`` (so axis ``j`` always gets the same sequence for
        a seed, whichever other axes are excited). ``method="mls"``: offset (in clock periods)
        of the first axis into the maximal-length sequence.
    method : {"random", "mls"}
        ``"random"`` (default): independent fair coin flips per clock interval from
        :func:`numpy.random.default_rng` children — zero mean in expectation, sequences of
        different axes statistically independent. ``"mls"``: one maximal-length LFSR
        sequence (:func:`scipy.signal.max_len_seq`, shortest register whose period
        ``N = 2^m − 1`` covers the record) mapped to ±1, and axis ``j`` of the rig uses it
        circularly shifted by ``seed + j·⌊N/n_axes⌋`` clock periods — the distinct seeds of
        the LFSR. Its mean over a full period is ``amplitude_a / N`` and the cross-correlation
        of two axes is ``−1/N`` for lags shorter than ``⌊N/n_axes⌋`` clock periods.

    Returns
    -------
    Excitation
        ``kind="prbs"``.

    Raises
    ------
    ValueError
        On a non-positive amplitude, clock period, duration or rate, a clock period shorter
        than one sample, an unknown axis or method.

    Examples
    --------
    >>> ex = prbs(amplitude_a=0.05, clock_period_s=2e-3, duration_s=0.1, sample_rate_hz=1e4)
    >>> bool(set(abs(ex.values_a).ravel().round(12)) == {0.05})
    True
    """
    amp = _positive("amplitude_a", amplitude_a)
    fs = _positive("sample_rate_hz", sample_rate_hz)
    clk = _positive("clock_period_s", clock_period_s)
    dur = _positive("duration_s", duration_s)
    if clk * fs < 1.0 - 1e-9:
        raise ValueError(f"clock_period_s: {clk} s is shorter than one sample period (1/{fs} s)")
    if method not in ("random", "mls"):
        raise ValueError(f"method: expected 'random' or 'mls', got {method!r}")
    if isinstance(seed, bool) or not isinstance(seed, (int, np.integer)) or seed < 0:
        raise ValueError(f"seed: expected a non-negative integer, got {seed!r}")
    names, g, gains = _axes_and_gains(axes, excited)
    n = _n_samples(dur, fs)
    spc = clk * fs  # samples per clock
    k = np.arange(n)
    clock_index = np.floor(k / spc + 1e-9).astype(np.int64)
    n_clk = int(clock_index[-1]) + 1
    levels = np.empty((n_clk, len(names)))
    params = _base_params("prbs", fs, names, gains)
    params.update(
        amplitude_a=amp, clock_period_s=clk, duration_s=dur, seed=int(seed), method=method
    )
    if method == "random":
        children = np.random.SeedSequence(int(seed)).spawn(len(names))
        for j, ss in enumerate(children):
            levels[:, j] = np.where(np.random.default_rng(ss).integers(0, 2, n_clk) == 1, 1.0, -1.0)
    else:
        # numpy alone for the excitation module on a rig's own PC; scipy.signal costs
        # 0.6 s of import and only the m-sequence and the chirp need it
        import scipy.signal

        nbits = max(2, int(math.ceil(math.log2(n_clk + 1))))
        if nbits > 32:
            raise ValueError(f"duration_s: {n_clk} clock periods exceed the longest LFSR (2^32 − 1)")
        seq = scipy.signal.max_len_seq(nbits)[0].astype(float) * 2.0 - 1.0
        period = seq.size
        spacing = period // len(names)
        for j in range(len(names)):
            shift = (int(seed) + j * spacing) % period
            idx = (np.arange(n_clk) + shift) % period
            levels[:, j] = seq[idx]
        params.update(lfsr_bits=nbits, lfsr_period=period, lfsr_shift_spacing=spacing)
    values = amp * levels[clock_index] * g
    return Excitation(k / fs, values, names, fs, "prbs", params)


# --------------------------------------------------------------------------- stepped sine
def stepped_sine(
    *,
    frequencies_hz: Sequence[float],
    amplitude_a: float,
    cycles: int,
    settling_cycles: int,
    sample_rate_hz: float,
    axes: Sequence[str] = DEFAULT_AXES,
    excited: Sequence[str] | Mapping[str, float] | None = None,
) -> Excitation:
    """Stepped sine: ``settling_cycles + cycles`` periods of a sine per frequency, in order.

    Step ``m`` at frequency ``f_m`` is ``amplitude_a · sin(2π f_m (t − t_m))`` with ``t_m``
    the step's first sample: ``round(settling_cycles · fs / f_m)`` settling samples, then the
    analysis window of ``round(cycles · fs / f_m)`` samples, which runs to the step's end.
    The window thus holds ``cycles`` whole periods to within half a sample (exactly when
    ``cycles · fs / f_m`` is an integer), every step starts at zero phase, and the signal is
    continuous at the step boundaries to within the rounding of a sample. The settling part lets the closed-loop transient die out (thesis P4 §3.5.1
    runs 5–200 Hz in 10 Hz steps and fits the seal coefficients per frequency).

    Parameters
    ----------
    frequencies_hz : sequence of float
        Step frequencies (Hz), each ``> 0`` and below ``sample_rate_hz / 2``; any order.
    amplitude_a : float
        Sine amplitude (A), > 0.
    cycles : int
        Periods per step in the analysis window, >= 1.
    settling_cycles : int
        Periods per step before the window, >= 0.
    sample_rate_hz : float
        Sampling rate (Hz).
    axes : sequence of str
        All actuator axes of the rig (columns of ``values_a``), as in :func:`prbs`.
    excited : sequence of str, mapping {axis: gain} or None
        Axes that carry the signal, as in :func:`prbs`: the same sine (times the gain) on every
        excited axis; ``None`` = all.

    Returns
    -------
    Excitation
        ``kind="stepped_sine"`` with ``windows`` ``((f_m, start_m, stop_m), ...)``, sample
        indices as slice bounds into ``time_s``/``values_a``.

    Raises
    ------
    ValueError
        On an empty or invalid frequency list, a frequency at or above Nyquist, fewer than
        4 samples per period, non-integer or negative cycle counts.

    Examples
    --------
    >>> ex = stepped_sine(frequencies_hz=[5.0, 15.0], amplitude_a=0.1, cycles=4,
    ...                   settling_cycles=2, sample_rate_hz=3000.0, excited=["A_zeta"])
    >>> ex.windows
    ((5.0, 1200, 3600), (15.0, 4000, 4800))
    """
    amp = _positive("amplitude_a", amplitude_a)
    fs = _positive("sample_rate_hz", sample_rate_hz)
    for nm, c, lo in (("cycles", cycles, 1), ("settling_cycles", settling_cycles, 0)):
        if isinstance(c, bool) or not isinstance(c, (int, np.integer)) or c < lo:
            raise ValueError(f"{nm}: expected an integer >= {lo}, got {c!r}")
    try:
        freqs = [float(f) for f in frequencies_hz]
    except (TypeError, ValueError):
        raise ValueError(f"frequencies_hz: expected a sequence of numbers, got {frequencies_hz!r}") from None
    if not freqs:
        raise ValueError("frequencies_hz: expected at least one frequency")
    for f in freqs:
        if not math.isfinite(f) or f <= 0:
            raise ValueError(f"frequencies_hz: each frequency must be finite and > 0, got {f!r}")
        if f > fs / 4.0:
            raise ValueError(
                f"frequencies_hz: {f} Hz leaves fewer than 4 samples per period at {fs} Hz"
            )
    names, g, gains = _axes_and_gains(axes, excited)
    chunks, windows, start = [], [], 0
    for f in freqs:
        n_settle = int(round(settling_cycles * fs / f))
        n_step = n_settle + int(round(cycles * fs / f))
        k = np.arange(n_step)
        chunks.append(np.sin(2.0 * np.pi * f * k / fs))
        windows.append((f, start + n_settle, start + n_step))
        start += n_step
    wave = amp * np.concatenate(chunks)
    n = wave.size
    params = _base_params("stepped_sine", fs, names, gains)
    params.update(
        frequencies_hz=freqs, amplitude_a=amp, cycles=int(cycles), settling_cycles=int(settling_cycles),
        windows=[list(w) for w in windows],
    )
    return Excitation(np.arange(n) / fs, wave[:, None] * g, names, fs, "stepped_sine", params, tuple(windows))


# --------------------------------------------------------------------------- chirp
def chirp(
    *,
    f0_hz: float,
    f1_hz: float,
    duration_s: float,
    amplitude_a: float,
    sample_rate_hz: float,
    method: str = "linear",
    axes: Sequence[str] = DEFAULT_AXES,
    excited: Sequence[str] | Mapping[str, float] | None = None,
) -> Excitation:
    """Swept sine from ``f0_hz`` to ``f1_hz`` over ``duration_s`` (:func:`scipy.signal.chirp`).

    ``amplitude_a · sin(φ(t))`` with instantaneous frequency ``φ'(t)/2π``

    * linear: ``f0 + (f1 − f0) t / T``;
    * logarithmic: ``f0 (f1/f0)^(t/T)`` (both frequencies > 0);

    ``T = duration_s``; the sine starts at zero (``scipy.signal.chirp(..., phi=-90)``).
    Thesis P4 §3.4 (Figs. 9–10) uses a linear 0–150 Hz chirp.

    Parameters
    ----------
    f0_hz, f1_hz : float
        Start and end frequency (Hz), ``>= 0`` (``> 0`` for logarithmic), below Nyquist;
        ``f1_hz < f0_hz`` sweeps downwards.
    duration_s : float
        Record length (s).
    amplitude_a : float
        Amplitude (A), > 0.
    sample_rate_hz : float
        Sampling rate (Hz).
    method : {"linear", "logarithmic"}
        Sweep law.
    axes : sequence of str
        All actuator axes of the rig (columns of ``values_a``), as in :func:`prbs`.
    excited : sequence of str, mapping {axis: gain} or None
        Axes that carry the signal, as in :func:`prbs`: the same chirp (times the gain) on every
        excited axis; ``None`` = all.

    Returns
    -------
    Excitation
        ``kind="chirp"``.

    Raises
    ------
    ValueError
        On invalid frequencies (negative, at/above Nyquist, zero for a logarithmic sweep,
        equal for a logarithmic sweep), method, amplitude, duration or rate.
    """
    import scipy.signal  # start-up cost, as in prbs

    fs = _positive("sample_rate_hz", sample_rate_hz)
    amp = _positive("amplitude_a", amplitude_a)
    dur = _positive("duration_s", duration_s)
    if method not in ("linear", "logarithmic"):
        raise ValueError(f"method: expected 'linear' or 'logarithmic', got {method!r}")
    f0 = _nonnegative("f0_hz", f0_hz)
    f1 = _nonnegative("f1_hz", f1_hz)
    for nm, f in (("f0_hz", f0), ("f1_hz", f1)):
        if f >= fs / 2.0:
            raise ValueError(f"{nm}: {f} Hz is at or above the Nyquist frequency {fs / 2} Hz")
        if method == "logarithmic" and f == 0:
            raise ValueError(f"{nm}: a logarithmic chirp needs a frequency > 0")
    if method == "logarithmic" and f0 == f1:
        raise ValueError("f1_hz: a logarithmic chirp needs f1_hz != f0_hz")
    names, g, gains = _axes_and_gains(axes, excited)
    n = _n_samples(dur, fs)
    t = np.arange(n) / fs
    wave = amp * scipy.signal.chirp(t, f0=f0, t1=dur, f1=f1, method=method, phi=-90.0)
    params = _base_params("chirp", fs, names, gains)
    params.update(f0_hz=f0, f1_hz=f1, duration_s=dur, amplitude_a=amp, method=method)
    return Excitation(t, wave[:, None] * g, names, fs, "chirp", params)


# --------------------------------------------------------------------------- impulse
def impulse(
    *,
    amplitude_a: float,
    width_s: float,
    start_s: float,
    duration_s: float,
    sample_rate_hz: float,
    axes: Sequence[str] = DEFAULT_AXES,
    excited: Sequence[str] | Mapping[str, float] | None = None,
) -> Excitation:
    """Rectangular current pulse of ``amplitude_a`` for ``width_s`` from ``start_s``.

    Samples ``i0 ≤ k < i0 + w`` carry ``amplitude_a`` with ``i0 = round(start_s · fs)`` and
    ``w = width_s · fs`` (must be a whole number of samples, so the area
    ``Σ values · Δt = amplitude_a · width_s`` holds exactly). Thesis P5 §3.3: 0.05 A for
    10 ms from 0.05 s, on both bearings in ζ (``excited=("A_zeta", "B_zeta")``).

    Parameters
    ----------
    amplitude_a : float
        Pulse height (A), non-zero (negative pushes the other way).
    width_s : float
        Pulse duration (s), a whole number (>= 1) of sample periods.
    start_s : float
        Pulse start (s), ``>= 0``; rounded to the nearest sample.
    duration_s : float
        Record length (s); the pulse must end within it.
    sample_rate_hz : float
        Sampling rate (Hz).
    axes : sequence of str
        All actuator axes of the rig (columns of ``values_a``), as in :func:`prbs`.
    excited : sequence of str, mapping {axis: gain} or None
        Axes that carry the pulse (times the gain), as in :func:`prbs`; ``None`` = all.

    Returns
    -------
    Excitation
        ``kind="impulse"``.

    Raises
    ------
    ValueError
        On a zero/non-finite amplitude, a width that is not a whole number of samples, a
        pulse that does not fit in the record, or invalid axes.

    Examples
    --------
    >>> ex = impulse(amplitude_a=0.05, width_s=0.01, start_s=0.05, duration_s=0.3,
    ...              sample_rate_hz=1e4, excited=("A_zeta", "B_zeta"))
    >>> round(float(ex.values_a[:, 0].sum() / ex.sample_rate_hz), 12)
    0.0005
    """
    try:
        amp = float(amplitude_a)
    except (TypeError, ValueError):
        raise ValueError(f"amplitude_a: expected a number, got {amplitude_a!r}") from None
    if not math.isfinite(amp) or amp == 0:
        raise ValueError(f"amplitude_a: expected a finite non-zero number, got {amplitude_a!r}")
    fs = _positive("sample_rate_hz", sample_rate_hz)
    width = _positive("width_s", width_s)
    start = _nonnegative("start_s", start_s)
    dur = _positive("duration_s", duration_s)
    w_f = width * fs
    w = int(round(w_f))
    if w < 1 or abs(w_f - w) > 1e-6 * max(1.0, w_f):
        raise ValueError(
            f"width_s: {width} s is {w_f:g} samples at {fs} Hz, expected a whole number >= 1"
        )
    names, g, gains = _axes_and_gains(axes, excited)
    n = _n_samples(dur, fs)
    i0 = int(round(start * fs))
    if i0 + w > n:
        raise ValueError(f"start_s: a pulse from {start} s for {width} s does not end within duration_s={dur} s")
    wave = np.zeros(n)
    wave[i0 : i0 + w] = amp
    params = _base_params("impulse", fs, names, gains)
    params.update(amplitude_a=amp, width_s=width, start_s=start, duration_s=dur)
    return Excitation(np.arange(n) / fs, wave[:, None] * g, names, fs, "impulse", params)
