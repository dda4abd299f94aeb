"""A closed-loop record in memory and the checks of its values.

:class:`Measurement` holds the columns of one record (thesis P2 §5: excitation, current
reference, coil current and displacement per actuator axis) with its metadata;
:func:`validate_measurement` checks the sample values. Files are read and written by
:mod:`ambseal.identify.records.data`, whose docstring gives the format and the checks.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any, Mapping, Sequence

import numpy as np

from ambseal.config import MAX_CURRENT_A, MAX_GAP_M
from ambseal.errors import DataError
from ambseal.lti import finite_or_none

__all__ = ["FORMAT_TAG", "CLIP_RUN", "CLIP_RTOL", "TIME_RTOL", "CHANNELS", "Measurement", "column_names",
           "validate_measurement"]

FORMAT_TAG = "ambseal-measurement/1"
#: Consecutive samples at the current limit that count as clipping.
CLIP_RUN = 3
#: Relative closeness to the current limit that counts as "at the limit".
CLIP_RTOL = 1e-3
#: Default relative tolerance of each time step against the mean step.
TIME_RTOL = 1e-6
#: (field of :class:`Measurement`, column prefix, unit suffix) of the per-axis channels.
CHANNELS: tuple[tuple[str, str, str], ...] = (
    ("excitation_a", "excitation", "a"),
    ("current_ref_a", "current_ref", "a"),
    ("current_a", "current", "a"),
    ("displacement_m", "displacement", "m"),
)
_RESERVED = ("format", "axes")
_RATE_RTOL = 1e-6  # metadata sample_rate_hz against the time column


def column_names(axes: Sequence[str]) -> list[str]:
    """Column names of a file for ``axes``: ``time_s`` then the four channels per axis."""
    cols = ["time_s"]
    for a in axes:
        cols += [f"{prefix}_{a}_{unit}" for _, prefix, unit in CHANNELS]
    return cols


# --------------------------------------------------------------------------- result
@dataclass(frozen=True, eq=False)
class Measurement:
    """One identification run: excitation, currents and displacements per actuator axis.

    Attributes
    ----------
    time_s : ndarray, shape (n,)
        Sample times (s).
    excitation_a : ndarray, shape (n, k)
        Excitation current added to the current reference (A).
    current_ref_a : ndarray, shape (n, k)
        Current reference, controller output plus excitation (A).
    current_a : ndarray, shape (n, k)
        Measured coil current (A).
    displacement_m : ndarray, shape (n, k)
        Displacement per axis (m).
    axes : tuple of str, length k
        Actuator axis names, column ``j`` of every array belongs to ``axes[j]``.
    metadata : dict
        JSON-safe run description (see the module docstring for the recommended keys);
        must not contain the reserved keys ``format`` and ``axes``.

    Raises
    ------
    DataError
        If the shapes disagree, axis names repeat or are not usable in column names, or the
        metadata uses a reserved key. (Value checks are in :func:`validate_measurement`.)

    Notes
    -----
    The arrays are copied and made read-only.
    """

    time_s: np.ndarray
    excitation_a: np.ndarray
    current_ref_a: np.ndarray
    current_a: np.ndarray
    displacement_m: np.ndarray
    axes: tuple[str, ...]
    metadata: dict = field(default_factory=dict)

    def __post_init__(self) -> None:
        if isinstance(self.axes, str):
            raise DataError(f"axes: expected a sequence of axis names, got the string {self.axes!r}")
        axes = tuple(str(a) for a in self.axes)
        if not axes or len(set(axes)) != len(axes):
            raise DataError(f"axes: expected unique axis names, got {axes}")
        for a in axes:
            if not a or not all(c.isalnum() or c == "_" for c in a) or not a[0].isalpha():
                raise DataError(f"axes: {a!r} must start with a letter and hold only letters, digits, '_'")
        t = np.array(self.time_s, dtype=float)
        if t.ndim != 1:
            raise DataError(f"time_s: expected shape (n,), got {t.shape}")
        t.setflags(write=False)
        object.__setattr__(self, "time_s", t)
        for name, _, _ in CHANNELS:
            v = np.array(getattr(self, name), dtype=float)
            if v.ndim == 1 and len(axes) == 1:
                v = v[:, None]
            if v.shape != (t.size, len(axes)):
                raise DataError(f"{name}: expected shape ({t.size}, {len(axes)}), got {v.shape}")
            v.setflags(write=False)
            object.__setattr__(self, name, v)
        object.__setattr__(self, "axes", axes)
        if not isinstance(self.metadata, Mapping):
            raise DataError(f"metadata: expected a dict, got {type(self.metadata).__name__}")
        meta = dict(self.metadata)
        bad = [k for k in _RESERVED if k in meta]
        if bad:
            raise DataError(f"metadata: keys {bad} are reserved for the file format")
        object.__setattr__(self, "metadata", meta)

    @property
    def n_samples(self) -> int:
        """Number of samples ``n``."""
        return int(self.time_s.size)

    @property
    def sample_rate_hz(self) -> float:
        """``(n − 1) / (t[-1] − t[0])`` (Hz); ``nan`` with fewer than two samples."""
        if self.time_s.size < 2 or self.time_s[-1] == self.time_s[0]:
            return float("nan")
        return float((self.time_s.size - 1) / (self.time_s[-1] - self.time_s[0]))

    def channel(self, name: str) -> np.ndarray:
        """One column by its file name, e.g. ``"displacement_A_zeta_m"`` or ``"time_s"``.

        Raises
        ------
        KeyError
            If no column has that name.
        """
        if name == "time_s":
            return self.time_s
        for fld, prefix, unit in CHANNELS:
            for j, a in enumerate(self.axes):
                if name == f"{prefix}_{a}_{unit}":
                    return getattr(self, fld)[:, j]
        raise KeyError(f"no column {name!r}; columns are {column_names(self.axes)}")

    def table(self) -> np.ndarray:
        """All columns as one array, shape (n, 1 + 4k), in :func:`column_names` order."""
        cols = [self.time_s[:, None]]
        for j in range(len(self.axes)):
            cols += [getattr(self, fld)[:, j : j + 1] for fld, _, _ in CHANNELS]
        return np.hstack(cols)

    def to_dict(self, *, include_samples: bool = False) -> dict:
        """JSON-safe summary (axes, counts, rate, metadata); the columns only on request."""
        out: dict[str, Any] = {
            "format": FORMAT_TAG,
            "axes": list(self.axes),
            "n_samples": self.n_samples,
            "sample_rate_hz": finite_or_none(self.sample_rate_hz),
            "metadata": _json_safe(self.metadata, "metadata"),
        }
        if include_samples:
            tab = self.table()
            out["columns"] = {c: tab[:, i].tolist() for i, c in enumerate(column_names(self.axes))}
        return out


# --------------------------------------------------------------------------- helpers

def _json_safe(obj: Any, where: str) -> Any:
    """Convert numpy values to Python ones; reject NaN/inf and unknown objects."""
    if isinstance(obj, Mapping):
        return {str(k): _json_safe(v, f"{where}.{k}") for k, v in obj.items()}
    if isinstance(obj, (list, tuple)):
        return [_json_safe(v, f"{where}[{i}]") for i, v in enumerate(obj)]
    if isinstance(obj, np.ndarray):
        return _json_safe(obj.tolist(), where)
    if obj is None or isinstance(obj, (bool, str)):
        return obj
    if isinstance(obj, np.bool_):
        return bool(obj)
    if isinstance(obj, (int, np.integer)):
        return int(obj)
    if isinstance(obj, (float, np.floating)):
        if not math.isfinite(float(obj)):
            raise DataError(f"{where}: {obj!r} is not allowed in JSON metadata")
        return float(obj)
    raise DataError(f"{where}: {type(obj).__name__} is not JSON-serialisable")


# --------------------------------------------------------------------------- validate
def validate_measurement(
    meas: Measurement,
    *,
    source: str = "<measurement>",
    axes: Sequence[str] | None = None,
    min_samples: int | None = None,
    current_limit_a: float | None = None,
    time_rtol: float = TIME_RTOL,
) -> Measurement:
    """Check sample values of a measurement (also usable on an in-memory one).

    Parameters
    ----------
    meas : Measurement
        The record to check.
    source : str
        Name put at the front of every message (the file name when loading).
    axes : sequence of str, optional
        The rig's actuator axes; the record must have exactly these, in this order.
    min_samples : int, optional
        Fewest acceptable samples (at least 2 are always required).
    current_limit_a : float, optional
        Amplifier current limit (A) for the clipping check; no check when omitted.
    time_rtol : float
        Accepted relative deviation of each time step from the mean step.

    Returns
    -------
    Measurement
        ``meas`` itself.

    Raises
    ------
    DataError
        On the first failure, naming ``source``, the column and the 1-based row.
    """
    n = meas.n_samples
    if axes is not None and tuple(axes) != meas.axes:
        raise DataError(f"{source}: column axes: measurement has {list(meas.axes)}, expected {list(axes)}")
    need = 2 if min_samples is None else max(2, int(min_samples))
    if n < need:
        raise DataError(f"{source}: column 'time_s': {n} samples (rows), expected at least {need}")
    names = column_names(meas.axes)
    table = meas.table()
    bad = ~np.isfinite(table)
    if bad.any():
        r, c = np.argwhere(bad)[0]
        raise DataError(f"{source}: column {names[c]!r}, row {r + 1}: {float(table[r, c])!r} is not a finite number")
    limit = np.array([np.inf] + [MAX_GAP_M if unit == "m" else MAX_CURRENT_A
                                 for _ in meas.axes for _, _, unit in CHANNELS])
    over = np.abs(table) > limit
    if over.any():  # no rotor moves further in its bearing, nor draws more current
        r, c = np.argwhere(over)[0]
        unit = "m (an air gap's bound" if names[c].endswith("_m") else "A (a current's bound"
        raise DataError(f"{source}: column {names[c]!r}, row {r + 1}: {float(table[r, c]):g} "
                        f"is beyond ±{limit[c]:g} {unit} in a rig file)")
    t = meas.time_s
    dt = np.diff(t)
    step = (t[-1] - t[0]) / (n - 1)
    if not step > 0:
        raise DataError(f"{source}: column 'time_s', row 2: time does not increase")
    dev = np.abs(dt - step) > time_rtol * step
    if dev.any():
        i = int(np.argmax(dev))
        what = "time does not increase" if dt[i] <= 0 else "time step is not uniform"
        raise DataError(
            f"{source}: column 'time_s', row {i + 2}: {what} (step {dt[i]:.9g} s, "
            f"mean step {step:.9g} s, tolerance {time_rtol:g} relative)"
        )
    fs_meta = meas.metadata.get("sample_rate_hz")
    if fs_meta is not None:
        fs = 1.0 / step
        if not isinstance(fs_meta, (int, float)) or abs(float(fs_meta) - fs) > max(time_rtol, _RATE_RTOL) * fs:
            raise DataError(
                f"{source}: column 'time_s', row 1: metadata sample_rate_hz={fs_meta!r} disagrees "
                f"with the time step ({fs:.9g} Hz)"
            )
    if current_limit_a is not None:
        try:
            lim = float(current_limit_a)
        except (TypeError, ValueError):
            raise DataError(f"{source}: current_limit_a must be a number, got {current_limit_a!r}") from None
        if not lim > 0 or not math.isfinite(lim):
            raise DataError(f"{source}: current_limit_a must be finite and > 0, got {current_limit_a!r}")
        at = (1.0 - CLIP_RTOL) * lim
        for fld in ("current_ref_a", "current_a"):
            prefix = {"current_ref_a": "current_ref", "current_a": "current"}[fld]
            arr = getattr(meas, fld)
            for j, a in enumerate(meas.axes):
                row = _first_run(np.abs(arr[:, j]) >= at, CLIP_RUN)
                if row is not None:
                    raise DataError(
                        f"{source}: column '{prefix}_{a}_a', row {row + 1}: current clipped at the "
                        f"limit ±{lim:g} A ({CLIP_RUN} or more consecutive samples within "
                        f"{CLIP_RTOL:.1%} of it)"
                    )
    return meas


def _first_run(mask: np.ndarray, length: int) -> int | None:
    """Index of the first sample of the first run of ``length`` True values, or None."""
    if mask.size < length or not mask.any():
        return None
    c = np.convolve(mask.astype(np.int64), np.ones(length, dtype=np.int64), mode="valid")
    hits = np.flatnonzero(c == length)
    return int(hits[0]) if hits.size else None
