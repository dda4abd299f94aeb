"""Measurement files: what a rig records during an identification run, and how it is read.

A real rig and the virtual one (:mod:`ambseal.identify.facility.rig_sim`) write the same format, so the
identification (:mod:`ambseal.identify.fitting.fit`, :mod:`ambseal.identify.fitting.frf`) cannot tell them
apart. This docstring is the user-facing specification of that format.

Content
-------
For ``n`` samples and ``k`` actuator axes (e.g. ``A_zeta, A_eta, B_zeta, B_eta``, thesis P2
Fig. 1(b)), one run holds:

==============================  ====  ================================================
column                          unit  meaning
==============================  ====  ================================================
``time_s``                      s     sample time, uniform step, increasing
``excitation_<axis>_a``         A     excitation current ``i_e`` added to the reference
``current_ref_<axis>_a``        A     current reference = controller output + ``i_e``
``current_<axis>_a``            A     measured coil (control) current
``displacement_<axis>_m``       m     displacement sensor reading of that axis
==============================  ====  ================================================

The four channel columns repeat for every axis; columns may come in any order, but every
column listed above must be present and no other column is allowed.

Metadata (a JSON object) — reserved keys ``format`` (must be ``"ambseal-measurement/1"``)
and ``axes`` (the list of axis names, defining ``k`` and the column names).

Required by ``ambseal identify`` (the fit simulates the loop that ran, so it must know it):

* ``sample_rate_hz`` — the controller's and the acquisition's rate (Hz); checked against the
  time column;
* ``controller`` — the digital controller that ran: ``{"type": "state_space", "A", "B",
  "C", "D", "dt"}`` (``dt`` = 1/``sample_rate_hz``, one input and output per axis), or
  ``{"type": "pid", "kp", "ti", "td", "eps"}`` per axis as the rig file's
  ``[controller.pid]`` (discretised by ambseal at ``sample_rate_hz``), or any description
  carrying the first form under ``"state_space"`` (what ``ambseal acquire`` writes).

The timing these stand for (:mod:`ambseal.robust.digital_loop`): at sample k the sensors give
y_k, the controller computes u_k = C x_c,k + D y_k in the same sample (no extra delay; a
rig with a one-sample computation delay states it as a controller state), and the current
reference ``current_ref`` = −u_k + ``excitation`` is held over the sample (zero-order hold)
— the controller's sign convention is i = −K y.

Recommended, all SI:

* ``rig`` — rig name (str); when present it must be the rig file's ``[rotor] name``;
* ``bias_current_a`` — bias current (A), a number or ``{axis: number}``;
* ``pressure_drop_pa`` — pressure drop across the seal (Pa; default 0);
* ``speed_rad_s`` — rotor speed (rad/s; default the rig's ``[operating]`` speed);
* ``excitation`` — :attr:`ambseal.identify.excitation.signals.Excitation.params`;
* ``current_limit_a`` — amplifier current limit (A), used for the clipping check.

Any other JSON value may be added.

File forms
----------
CSV (``*.csv``)
    A header row of column names, then one row per sample, comma separated, numbers in any
    form Python's ``float`` reads (written with 17 significant digits). The metadata lives in
    a JSON sidecar next to it named ``<file>.json`` — the full file name plus ``.json``, e.g.
    ``run1.csv`` → ``run1.csv.json`` — whose top-level object is the metadata together with
    ``"format"`` and ``"axes"``.
MATLAB (``*.mat``, level 5 / v7, not v7.3)
    One variable per column, named as the column, a column vector of doubles (``n × 1``;
    a row vector is accepted), plus ``metadata_json``, a char array holding the same JSON
    object as the sidecar. Read with :func:`scipy.io.loadmat` in a child process
    (:mod:`ambseal.identify.records.matlab_file`); nothing read from a file is ever unpickled.

Validation (:func:`load_measurement`)
-------------------------------------
Each failure raises one :class:`~ambseal.errors.DataError` whose message names the file, the
column and — for sample values — the 1-based data row (row 1 is the first sample; in a CSV
file it is the line after the header):

* missing sidecar, unreadable JSON, missing or wrong ``format`` tag, missing ``axes``;
* missing, unexpected or duplicate column, a CSV row with the wrong number of fields or a
  cell that is not a number;
* axes other than the rig's (``axes=`` argument): wrong count or names;
* fewer than ``min_samples`` samples (and always fewer than 2);
* NaN or ±inf in any column; a displacement beyond ±0.1 m or a current beyond ±1e4 A (the
  rig file's bounds of an air gap and of a current: no rotor moves or draws more);
* time not increasing or not uniform: every step within ``time_rtol`` (relative) of the
  mean step; ``sample_rate_hz`` in the metadata disagreeing with it;
* clipped currents: a run of at least :data:`CLIP_RUN` consecutive samples of a current
  column (``current_ref_*`` or ``current_*``) with ``|i| >= (1 − CLIP_RTOL) · limit``,
  the limit being ``current_limit_a`` (argument, else metadata; no check without one).

Example
-------
>>> import numpy as np, tempfile, pathlib
>>> t = np.arange(100) / 1000.0
>>> z = np.zeros((100, 1))
>>> m = Measurement(t, z, z, z, z, ("A_zeta",), {"rig": "demo"})
>>> with tempfile.TemporaryDirectory() as folder:
...     p = pathlib.Path(folder) / "run.csv"
...     _ = save_measurement(m, p)
...     load_measurement(p, axes=("A_zeta",)).metadata["sample_rate_hz"]
1000.0
"""

from __future__ import annotations

import csv
import hashlib
import io
import json
import math
import os
import warnings
from pathlib import Path
from typing import Sequence

import numpy as np
import scipy.io

from ambseal.errors import AmbsealError, DataError
from ambseal.files import STAMP_KEY, atomic_write, input_file, read_text
from ambseal.identify.records.matlab_file import read_matlab
from ambseal.identify.records.measurement import (
    _RATE_RTOL,
    _RESERVED,
    CHANNELS,
    CLIP_RTOL,
    CLIP_RUN,
    FORMAT_TAG,
    TIME_RTOL,
    Measurement,
    _json_safe,
    column_names,
    validate_measurement,
)

__all__ = [
    "FORMAT_TAG",
    "CLIP_RUN",
    "CLIP_RTOL",
    "TIME_RTOL",
    "CHANNELS",
    "Measurement",
    "column_names",
    "save_measurement",
    "load_measurement",
    "validate_measurement",
    "record_is_ours",
    "RECORD_MARK",
]

def _atomic_write(path: Path, write) -> None:
    if not path.parent.is_dir():
        raise DataError(f"{path}: folder {str(path.parent)!r} does not exist")
    atomic_write(path, write)


def _sidecar(path: Path) -> Path:
    return path.with_name(path.name + ".json")


#: The sidecar key holding the SHA-256 of the CSV table ambseal wrote with it (ambseal's
#: file mark)
RECORD_MARK = STAMP_KEY


def record_is_ours(path: str | os.PathLike) -> bool:
    """True if ``path`` (a ``.csv`` record, or its ``.csv.json`` sidecar) is a record that
    :func:`save_measurement` wrote and nobody changed since: the sidecar's
    ``ambseal-sha256`` is the hash of the table. A ``.mat`` record carries no such mark.

    Parameters
    ----------
    path : str or os.PathLike
        The table or its sidecar.

    Returns
    -------
    bool
    """
    path = Path(path)
    table = path.with_name(path.name[:-len(".json")]) if path.name.endswith(".csv.json") \
        else path
    if table.suffix.lower() != ".csv":
        return False
    try:
        header = json.loads(read_text(_sidecar(table), "sidecar"))
        mark = header.get(RECORD_MARK) if isinstance(header, dict) else None
        return (header.get("format") == FORMAT_TAG and isinstance(mark, str)
                and hashlib.sha256(input_file(table, "record").read_bytes()).hexdigest()
                == mark)
    except (AmbsealError, OSError, ValueError, RecursionError):
        return False


def _header(meas: Measurement, path: Path) -> dict:
    meta = _json_safe(meas.metadata, f"{path}: metadata")
    fs = meas.sample_rate_hz
    if "sample_rate_hz" in meta and math.isfinite(fs):
        given = meta["sample_rate_hz"]
        if not isinstance(given, (int, float)) or abs(float(given) - fs) > _RATE_RTOL * fs:
            raise DataError(
                f"{path}: metadata sample_rate_hz={given!r} disagrees with column time_s ({fs:.9g} Hz)"
            )
    elif math.isfinite(fs):
        meta["sample_rate_hz"] = fs
    return {"format": FORMAT_TAG, "axes": list(meas.axes), **meta}


# --------------------------------------------------------------------------- save
def save_measurement(meas: Measurement, path: str | os.PathLike) -> Path:
    """Write a measurement as CSV + JSON sidecar or as MATLAB ``.mat``, chosen by suffix.

    Each file is written to a temporary name in the target folder and moved into place with
    ``os.replace`` (for CSV the sidecar first, then the table). ``sample_rate_hz`` is added
    to the metadata from the time column when absent.

    Parameters
    ----------
    meas : Measurement
        The record: time, excitation, current reference, current and displacement per axis,
        with its metadata.
    path : path-like
        ``*.csv`` or ``*.mat`` (case-insensitive).

    Returns
    -------
    pathlib.Path
        The table file (``.csv``/``.mat``) written.

    Raises
    ------
    DataError
        On another suffix, a missing folder, metadata that is not JSON-safe (NaN, objects)
        or whose ``sample_rate_hz`` disagrees with the time column.
    """
    path = Path(path)
    suffix = path.suffix.lower()
    if suffix not in (".csv", ".mat"):
        raise DataError(f"{path}: unknown measurement file type {path.suffix!r}, expected .csv or .mat")
    header = _header(meas, path)
    cols = column_names(meas.axes)
    table = meas.table()
    if suffix == ".csv":
        buf = io.StringIO()
        np.savetxt(buf, table, fmt="%.17g", delimiter=",", header=",".join(cols), comments="")
        data = buf.getvalue().encode("ascii")
        # the table's hash in the sidecar: the mark by which ambseal knows the pair as its
        # own and unchanged (record_is_ours)
        header[RECORD_MARK] = hashlib.sha256(data).hexdigest()
        text = json.dumps(header, indent=2, allow_nan=False) + "\n"
        _atomic_write(_sidecar(path), lambda fh: fh.write(text.encode("utf-8")))
        _atomic_write(path, lambda fh: fh.write(data))
    else:
        mdict = {c: table[:, i].reshape(-1, 1) for i, c in enumerate(cols)}
        mdict["metadata_json"] = json.dumps(header, allow_nan=False)
        _atomic_write(
            path, lambda fh: scipy.io.savemat(fh, mdict, format="5", do_compression=True, oned_as="column")
        )
    return path


# --------------------------------------------------------------------------- load
def _no_constant(name: str):
    raise ValueError(f"{name} is not a number JSON allows")


def _read_header_json(text: str, where: str) -> dict:
    try:
        obj = json.loads(text, parse_constant=_no_constant)
    except (ValueError, RecursionError) as exc:  # JSONDecodeError is a ValueError
        raise DataError(f"{where}: not valid JSON ({str(exc) or 'nested too deeply'})") from None
    if not isinstance(obj, dict):
        raise DataError(f"{where}: expected a JSON object, got {type(obj).__name__}")
    if "format" not in obj:
        raise DataError(f"{where}: missing key 'format' (expected {FORMAT_TAG!r})")
    if obj["format"] != FORMAT_TAG:
        raise DataError(f"{where}: format {obj['format']!r} is not {FORMAT_TAG!r}")
    axes = obj.get("axes")
    if not isinstance(axes, list) or not axes or not all(isinstance(a, str) for a in axes):
        raise DataError(f"{where}: key 'axes' must be a non-empty list of axis names, got {axes!r}")
    return obj


def _read(path: Path, what: str) -> str:
    try:
        return read_text(path, what)
    except AmbsealError as exc:
        raise DataError(str(exc)) from None


def _read_csv(path: Path) -> tuple[list[str], np.ndarray]:
    text = _read(path, "record")
    lines = text.splitlines()
    if not lines or not lines[0].strip():
        raise DataError(f"{path}: empty file, expected a header row of column names")
    header = [h.strip() for h in next(csv.reader([lines[0]]))]
    body = [ln for ln in lines[1:]]
    while body and not body[-1].strip():
        body.pop()
    ncol = len(header)
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")  # "input contained no data" on an empty body
            data = np.loadtxt(io.StringIO("\n".join(body)), delimiter=",", dtype=float, ndmin=2)
        if data.size == 0:
            data = np.empty((0, ncol))
        if data.shape[1] != ncol:
            raise ValueError("column count")
        return header, data
    except ValueError:
        pass
    # slow path: find the offending row and column
    rows = []
    for r, fields in enumerate(csv.reader(body), start=1):
        if len(fields) != ncol:
            raise DataError(f"{path}: row {r} has {len(fields)} fields, expected {ncol} (one per column of the header)")
        vals = []
        for c, cell in enumerate(fields):
            try:
                vals.append(float(cell))
            except ValueError:
                raise DataError(f"{path}: column {header[c]!r}, row {r}: {cell!r} is not a number") from None
        rows.append(vals)
    return header, np.array(rows, dtype=float).reshape(-1, ncol)


def _read_mat(path: Path) -> tuple[dict, dict[str, np.ndarray]]:
    # in a child process: scipy's reader can crash on a malformed file (matlab_file)
    raw = read_matlab(path, squeeze_me=False, mat_dtype=False, chars_as_strings=True)
    if "metadata_json" not in raw:
        raise DataError(f"{path}: missing variable 'metadata_json' (the JSON metadata)")
    kind, mj = raw["metadata_json"]
    if kind != "array" or mj.dtype.kind != "U" or mj.size != 1:
        raise DataError(f"{path}: variable 'metadata_json' must be a char row vector")
    header = _read_header_json(str(mj.reshape(-1)[0]), f"{path}: variable 'metadata_json'")
    cols = {}
    for name, (kind, arr) in raw.items():
        if name == "metadata_json":
            continue
        if kind != "array":
            raise DataError(f"{path}: column {name!r}: expected a numeric vector, got a "
                            f"{'struct' if kind == 'struct' else 'cell array'}")
        if arr.dtype.kind not in "fiub" or arr.ndim != 2 or min(arr.shape) > 1:
            raise DataError(f"{path}: column {name!r}: expected a numeric vector, got {arr.dtype} {arr.shape}")
        cols[name] = arr.astype(float).reshape(-1)
    return header, cols


def load_measurement(
    path: str | os.PathLike,
    *,
    axes: Sequence[str] | None = None,
    min_samples: int | None = None,
    current_limit_a: float | None = None,
    time_rtol: float = TIME_RTOL,
) -> Measurement:
    """Read and validate a measurement file (format in the module docstring).

    Parameters
    ----------
    path : path-like
        ``*.csv`` (with its ``<file>.json`` sidecar) or ``*.mat``.
    axes : sequence of str, optional
        The rig's actuator axes; the file must have exactly these (any order in the file;
        the result follows this order).
    min_samples : int, optional
        Fewest acceptable samples (at least 2 are always required).
    current_limit_a : float, optional
        Amplifier current limit (A) for the clipping check; defaults to the metadata's
        ``current_limit_a``; no check when neither is given.
    time_rtol : float
        Accepted relative deviation of each time step from the mean step.

    Returns
    -------
    Measurement
        With ``metadata`` = the file's metadata without ``format`` and ``axes``.

    Raises
    ------
    DataError
        On the first failed check (see the module docstring), naming the file, the column and
        the 1-based data row where one applies.
    """
    path = Path(path)
    suffix = path.suffix.lower()
    if suffix not in (".csv", ".mat"):
        raise DataError(f"{path}: unknown measurement file type {path.suffix!r}, expected .csv or .mat")
    if not path.is_file():
        raise DataError(f"{path}: file not found")
    header, cols = _read_csv_with_sidecar(path) if suffix == ".csv" else _read_mat(path)
    file_axes = _file_axes(path, tuple(header["axes"]), axes)
    _check_columns(path, cols, column_names(file_axes), file_axes)
    n = cols["time_s"].size
    meta = {k: v for k, v in header.items() if k not in _RESERVED}
    try:
        meas = Measurement(
            cols["time_s"],
            *[
                np.column_stack([cols[f"{prefix}_{a}_{unit}"] for a in file_axes])
                if n
                else np.empty((0, len(file_axes)))
                for _, prefix, unit in CHANNELS
            ],
            axes=file_axes,
            metadata=meta,
        )
    except DataError as exc:
        raise DataError(f"{path}: {exc}") from None
    if current_limit_a is None and meta.get("current_limit_a") is not None:
        current_limit_a = meta["current_limit_a"]
    return validate_measurement(
        meas, source=str(path), min_samples=min_samples, current_limit_a=current_limit_a, time_rtol=time_rtol
    )


def _read_csv_with_sidecar(path: Path) -> tuple[dict, dict]:
    """(header, columns) of a CSV record and its JSON sidecar; a column named twice is
    refused."""
    side = _sidecar(path)
    if not side.is_file():
        raise DataError(f"{path}: missing metadata sidecar {side.name!r}")
    header = _read_header_json(_read(side, "sidecar"), str(side))
    names, data = _read_csv(path)
    seen = set()
    for c in names:
        if c in seen:
            raise DataError(f"{path}: column {c!r} appears twice in the header")
        seen.add(c)
    return header, {c: data[:, i] for i, c in enumerate(names)}


def _file_axes(path: Path, file_axes: tuple, axes: Sequence[str] | None) -> tuple:
    """The record's axes in the rig's order (``axes``), which the file must have exactly."""
    if axes is None:
        return file_axes
    want = tuple(str(a) for a in axes)
    if len(file_axes) != len(want) or set(file_axes) != set(want):
        raise DataError(
            f"{path}: column axes: file has {len(file_axes)} axes {list(file_axes)}, "
            f"the rig expects {len(want)} {list(want)}"
        )
    return want


def _check_columns(path: Path, cols: dict, expected: list, file_axes: tuple) -> None:
    """Exactly the ``expected`` columns, each as long as ``time_s``."""
    for c in expected:
        if c not in cols:
            raise DataError(f"{path}: missing column {c!r}")
    for c in cols:
        if c not in expected:
            raise DataError(f"{path}: column {c!r} is unexpected for axes {list(file_axes)}")
    n = cols["time_s"].size
    for c in expected:
        if cols[c].size != n:
            raise DataError(f"{path}: column {c!r} has {cols[c].size} samples, time_s has {n}")
