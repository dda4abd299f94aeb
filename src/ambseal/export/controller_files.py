"""Controllers to files a real-time target can run, and back: ``.json``, ``.npz``, ``.mat``.

Every file holds the same document (:func:`controller_document`):

* ``convention`` — ``i = −K y``: the target computes ``u[k] = C x[k] + D y[k]``,
  ``x[k+1] = A x[k] + B y[k]`` from the sensor displacements ``y`` (m, ``inputs``) and
  sets the current references ``i = −u`` (A, ``outputs``);
* ``A, B, C, D`` — the **discrete** controller that was judged
  (:mod:`ambseal.robust.digital`), ``Ts`` (s, MATLAB's name), ``sample_rate_hz``,
  ``delay_samples`` (the computation delay it was judged with), ``method`` and
  ``prewarp_hz`` (``NaN`` unless Tustin was pre-warped), ``removed_poles_hz``;
* ``A_c … D_c`` — the continuous design, ``A_r … D_r`` the continuous controller that was
  discretised (fast poles removed); ``synthesis_plant`` (a fixed controller's) —
  ``"continuous"``, or ``"sampled"`` for an H∞ or μ designed in the w-plane, whose
  ``A_c … D_c`` is the w-plane controller, no loop that runs: ambseal closes such a
  controller as it runs only (:attr:`~ambseal.robust.DigitalController.as_runs_only`); a
  file without it is read as ``"continuous"``;
* ``discretisation_json`` — the choice (candidates, their ``|z|``, the rise of γ/μ) and
  ``judged_json`` — the judged discrete margins per condition, as JSON text;
* ``loop_holds`` (``"yes"``, ``"no"``, ``"not judged"``), ``allow_unstable`` (``"yes"`` or
  ``"no"``: whether ``--allow-unstable`` was given) and ``verdict`` — whether the judged
  loop holds, where, and why not (:func:`loop_verdict`); the C header says the same.

A continuous controller alone (a ``control.StateSpace``, e.g. for ``ambseal campbell`` or
``sweep --controller FILE``) is written with ``kind = "continuous"``, ``A … D`` continuous
and ``Ts = 0`` (MATLAB's continuous time), and read back as that ``StateSpace``.

A scheduled controller adds ``kind = "scheduled"``, ``parameter`` (θ: ``"speed"`` or an
LFT parameter such as ``"seal.k"``), ``grid`` (n_t, θ of each table entry: rad/s for the
speed, else SI; a speed-scheduled one also as ``speeds_rad_s``) and ``interpolation`` (the
law, :func:`~ambseal.machine.scheduled_digital.interpolation_law`); its
matrices are stacks over the table, shape (n_t, …) in ``.npz``/``.json`` and (…, n_t) in
``.mat`` so that MATLAB's ``ss`` builds the model array directly.

MATLAB / Octave (``pkg load control`` first in Octave), one line::

    s = load('controller_hinf.mat'); K = ss(s.A, s.B, s.C, s.D, s.Ts, 'InputName', s.inputs, 'OutputName', s.outputs);

Files are written to a temporary name and renamed (:func:`ambseal.files.atomic_write`);
:func:`load_controller` reads any of them back to the object that was judged. The names a
file carries (``name``, ``inputs``, ``outputs``, ``parameter``, ``method``) reach reports
and generated C: a file whose names are not plain labels (:data:`LABEL`) is refused.
"""

from __future__ import annotations

import json
import math
import re
import warnings
import zipfile
from pathlib import Path

import control
import numpy as np
from scipy.io import savemat

from ambseal.config import MAX_DELAY_SAMPLES, MAX_FREQUENCY_HZ
from ambseal.errors import AmbsealError, DataError
from ambseal.files import atomic_write, input_file
from ambseal.identify import read_matlab
from ambseal.machine import SPEED, ScheduledDigital
from ambseal.robust import DigitalController, DiscreteController, discretize_as

__all__ = ["export_controller", "load_controller", "controller_document", "loop_verdict",
           "CONVENTION", "MATLAB_LINE", "LABEL"]

_FORMATS = (".npz", ".mat", ".json")
CONVENTION = ("i = -K y: u[k] = C x[k] + D y[k], x[k+1] = A x[k] + B y[k]; inputs y are "
              "sensor displacements (m), outputs u; the current references are i = -u (A)")
MATLAB_LINE = ("s = load('{name}'); K = ss(s.A, s.B, s.C, s.D, s.Ts, 'InputName', s.inputs, "
               "'OutputName', s.outputs);")
_ARRAYS = ("A", "B", "C", "D", "A_c", "B_c", "C_c", "D_c", "A_r", "B_r", "C_r", "D_r")
#: A name a controller file may carry: letters, digits and ``_ . + - [ ]``, at most 100
#: characters (``K_hinf``, ``y_A_zeta``, ``seal.k``, ``K_lpv_1e+03Hz``, ``sys[3]``).
LABEL = re.compile(r"[A-Za-z0-9_][A-Za-z0-9_.+\-\[\]]{0,99}")


def _names(value, key: str, path: Path) -> list[str]:
    """The names under ``key`` (one string or a list), each a :data:`LABEL`, else a
    DataError naming the file and the key."""
    names = [value] if isinstance(value, str) else value
    if not isinstance(names, (list, tuple)):
        raise DataError(f"{path}: {key}: expected a name or a list of names, got "
                        f"{type(value).__name__}")
    for v in names:
        if not (isinstance(v, str) and LABEL.fullmatch(v)):
            raise DataError(f"{path}: {key}: {str(v)[:60]!r} is not a plain name (expected "
                            "letters, digits and _ . + - [ ], at most 100 characters)")
    return names


def _name(value, key: str, path: Path) -> str:
    """One :data:`LABEL` under ``key``, else a DataError naming the file and the key."""
    if not isinstance(value, str):
        raise DataError(f"{path}: {key}: expected a name, got {type(value).__name__}")
    return _names(value, key, path)[0]


def _nan(x):
    return float("nan") if x is None else float(x)


def _continuous_document(K) -> dict:
    """The document of a continuous ``control.StateSpace`` (no sample time: ``Ts = 0``)."""
    if not hasattr(K, "A") or K.isdtime(strict=True):
        raise TypeError(f"export: expected a DigitalController, ScheduledDigital or a "
                        f"continuous control.StateSpace, got {type(K).__name__}")
    return {"convention": CONVENTION.split(":")[0] + " (continuous: dx/dt = A x + B y, "
            "u = C x + D y, i = -u)", "input_unit": "m", "output_unit": "A",
            "kind": "continuous", "name": str(K.name), "Ts": 0.0,
            "inputs": list(K.input_labels), "outputs": list(K.output_labels),
            **{k: np.asarray(getattr(K, k), float) for k in "ABCD"}}


def loop_verdict(judged=None, failure: str | None = None, allow_unstable: bool = False
                 ) -> dict:
    """What the files of an exported controller say of its judged loop: whether it holds,
    where it was judged, and whether ``--allow-unstable`` kept it.

    Parameters
    ----------
    judged : list of dict, optional
        The judged discrete loops, each with ``stable`` (bool; None where not judged) and
        its condition (``pressure_bar``, ``speed_hz``), as :func:`controller_document`
        stores them.
    failure : str, optional
        Why the controller failed its judgement elsewhere (the run's verdict, e.g. over the
        speed range); it then does not hold, whatever ``judged`` says.
    allow_unstable : bool
        Whether ``--allow-unstable`` was given.

    Returns
    -------
    dict
        ``loop_holds`` (True, False, or None when nothing was judged), ``allow_unstable``
        and ``verdict``: one line of text naming the conditions (bar, Hz).
    """
    rows = list(judged or [])
    where = [", ".join(f"{float(r[k]):g} {unit}" for k, unit in (("pressure_bar", "bar"),
                                                                  ("speed_hz", "Hz"))
                       if k in r) or "a judged condition" for r in rows]
    lost = [w for w, r in zip(where, rows) if r.get("stable") is False]
    if failure is not None or lost:
        text = "does NOT hold: " + (failure if failure is not None
                                    else "the loop as it runs is unstable at " + "; ".join(lost))
        holds = False
        text += "; exported as asked (--allow-unstable)" if allow_unstable else ""
    elif rows and all(r.get("stable") for r in rows):
        holds, text = True, (f"holds as it runs at every judged condition ({len(rows)}: "
                             + _span(rows) + ")")
    else:
        holds, text = None, "not judged"
    return {"loop_holds": holds, "allow_unstable": bool(allow_unstable), "verdict": text}


def _span(rows) -> str:
    """The judged conditions in few words: per pressure, the speed or the speeds' span."""
    by: dict = {}
    for r in rows:
        if "pressure_bar" in r and "speed_hz" in r:
            by.setdefault(float(r["pressure_bar"]), []).append(float(r["speed_hz"]))
    if not by:
        return "the judged conditions"
    return "; ".join(f"{p:g} bar, {min(f):g} Hz" if min(f) == max(f) else
                     f"{p:g} bar, {min(f):g}–{max(f):g} Hz" for p, f in by.items())


def controller_document(ctrl, judged=None, verdict: dict | None = None) -> dict:
    """The content of every export format: arrays and plain values (module docstring).

    Parameters
    ----------
    ctrl : DigitalController, ScheduledDigital or a continuous control.StateSpace
    judged : list of dict, optional
        The judged discrete margins (``metrics.json`` cases' ``discrete`` blocks with the
        condition), stored as ``judged_json``.
    verdict : dict, optional
        :func:`loop_verdict` (default: of ``judged`` alone), stored as ``loop_holds``
        (``"yes"``, ``"no"`` or ``"not judged"``), ``allow_unstable`` (``"yes"`` or
        ``"no"``) and ``verdict``.
    """
    if not isinstance(ctrl, (DigitalController, ScheduledDigital)):
        return _continuous_document(ctrl)
    v = verdict or loop_verdict(judged)
    doc: dict = {"convention": CONVENTION, "input_unit": "m", "output_unit": "A",
                 "Ts": ctrl.Ts, "sample_rate_hz": ctrl.sample_rate_hz,
                 "delay_samples": int(ctrl.delay_samples), "method": ctrl.method,
                 "prewarp_hz": _nan(ctrl.prewarp_hz),
                 "removed_poles_hz": np.asarray(ctrl.removed_poles_hz, float),
                 "discretisation_json": json.dumps(ctrl.to_dict(), allow_nan=False),
                 "judged_json": json.dumps(judged or [], allow_nan=False),
                 # text, the same in JSON, NumPy and MATLAB files (MATLAB has no null)
                 "loop_holds": {True: "yes", False: "no", None: "not judged"}[v["loop_holds"]],
                 "allow_unstable": "yes" if v["allow_unstable"] else "no",
                 "verdict": v["verdict"]}
    if isinstance(ctrl, ScheduledDigital):
        doc.update(kind="scheduled", name=ctrl.name, inputs=list(ctrl.inputs),
                   outputs=list(ctrl.outputs), parameter=ctrl.parameter,
                   grid=np.asarray(ctrl.grid), interpolation=ctrl.interpolation)
        if ctrl.parameter == SPEED:
            doc["speeds_rad_s"] = np.asarray(ctrl.grid)
        for suf, mats in (("", ctrl.discrete), ("_c", ctrl.continuous), ("_r", ctrl.reduced)):
            doc.update({f"{k}{suf}": np.asarray(X, float) for k, X in zip("ABCD", mats)})
        return doc
    d = ctrl.discrete
    doc.update(kind="fixed", name=str(ctrl.continuous.name), inputs=ctrl.inputs,
               outputs=ctrl.outputs, synthesis_plant=ctrl.synthesis_plant)
    for suf, sys in (("_c", ctrl.continuous), ("_r", ctrl.reduced)):
        doc.update({f"{k}{suf}": np.asarray(getattr(sys, k), float) for k in "ABCD"})
    doc.update({k: np.asarray(getattr(d, k), float) for k in "ABCD"})
    return doc


def export_controller(ctrl, path, judged=None, verdict: dict | None = None) -> Path:
    """Write a digital controller to ``path`` (``.json``, ``.npz`` or ``.mat``).

    Parameters
    ----------
    ctrl : DigitalController, ScheduledDigital or control.StateSpace
        The controller as judged (:func:`ambseal.robust.digital.digital_controller`,
        :func:`ambseal.machine.scheduled_digital.scheduled_digital`), or a continuous
        controller alone (``kind = "continuous"``).
    path : str or Path
        Destination; the suffix picks the format.
    judged : list of dict, optional
        The judged discrete margins written with it.
    verdict : dict, optional
        :func:`loop_verdict`, written with it (default: of ``judged`` alone).

    Returns
    -------
    Path

    Raises
    ------
    DataError
        Unknown suffix, or a NaN or inf among the numbers (nothing is written).
    TypeError
        Not a digital controller.
    """
    path = Path(path)
    suffix = path.suffix.lower()
    if suffix not in _FORMATS:
        raise DataError(f"{path}: unknown controller format {suffix!r}, expected one of "
                        f"{_FORMATS}")
    try:
        doc = controller_document(ctrl, judged, verdict)
    except ValueError:  # json.dumps of the choice or the margins, allow_nan=False
        raise DataError(f"{path}: the controller's discretisation or judged margins hold NaN "
                        "or inf; nothing was written") from None
    _finite_arrays({k: v for k, v in doc.items() if isinstance(v, np.ndarray)}, path)
    path.parent.mkdir(parents=True, exist_ok=True)
    if suffix == ".npz":
        arrays = {k: (np.array(v, dtype=str) if isinstance(v, (list, str)) else np.asarray(v))
                  for k, v in doc.items()}
        atomic_write(path, lambda fh: np.savez(fh, **arrays))
    elif suffix == ".mat":
        mdict = {}
        for k, v in doc.items():
            if isinstance(v, list):
                v = np.array(v, dtype=object)  # a cell array of names in MATLAB
            elif isinstance(v, np.ndarray) and v.ndim == 3:
                v = np.moveaxis(v, 0, -1)  # MATLAB's model arrays stack on the last axis
            mdict[k] = v
        mdict["matlab"] = MATLAB_LINE.format(name=path.name)
        atomic_write(path, lambda fh: savemat(fh, mdict, oned_as="row"))
    else:
        out = {k: (v.tolist() if isinstance(v, np.ndarray) else v) for k, v in doc.items()}
        out = {k: (None if isinstance(v, float) and not np.isfinite(v) else v)
               for k, v in out.items()}
        text = json.dumps(out, indent=1, allow_nan=False).encode()
        atomic_write(path, lambda fh: fh.write(text))
    return path


def _read(path: Path) -> dict:
    suffix = path.suffix.lower()
    if suffix not in _FORMATS:
        raise DataError(f"{path}: unknown controller format {suffix!r}, expected one of "
                        f"{_FORMATS}")
    try:  # a device, a FIFO or a file beyond any controller: refused before reading
        input_file(path, "controller file")
    except AmbsealError as exc:
        raise DataError(str(exc)) from None
    if suffix == ".mat":  # in a child process: scipy's reader can crash on a malformed file
        m = read_matlab(path, squeeze_me=False, chars_as_strings=True)
    try:
        if suffix == ".json":
            raw = json.loads(path.read_text(encoding="utf-8"))
        elif suffix == ".npz":
            with np.load(path, allow_pickle=False) as z:
                return {k: (z[k].tolist() if z[k].dtype.kind == "U" else z[k]) for k in z.files}
    except RecursionError:
        raise DataError(f"{path}: not a readable controller file (nested too deeply)") from None
    except (OSError, ValueError, KeyError, EOFError, zipfile.BadZipFile, TypeError) as exc:
        raise DataError(f"{path}: not a readable controller file ({exc})") from None
    if suffix == ".json":
        if not isinstance(raw, dict):
            raise DataError(f"{path}: expected a JSON object of keys (A, B, C, D, inputs, "
                            f"outputs, ...), got a JSON {type(raw).__name__}")
        return {k: (float("nan") if v is None else v) for k, v in raw.items()}
    out = {}
    for k, (kind, v) in m.items():
        if kind == "struct":  # ambseal writes plain variables
            raise DataError(f"{path}: {k}: a struct with fields {v}, expected a matrix, a "
                            "number or text (one variable per key, as ambseal writes them)")
        if kind == "cells":
            out[k] = v
        elif v.dtype.kind == "U":
            out[k] = str(np.ravel(v)[0]) if v.size else ""
        else:
            out[k] = np.moveaxis(v, -1, 0) if v.ndim == 3 else v
    return out


def _arrays(doc: dict, path: Path, stacked: bool) -> dict:
    """The matrices of a document, shape-checked: DataError naming the key."""
    out = {}
    try:
        for k in _ARRAYS:
            X = np.asarray(doc[k], float)
            out[k] = X.reshape((-1,) + X.shape[-2:]) if stacked else np.atleast_2d(X)
    except KeyError as exc:
        raise DataError(f"{path}: missing key {exc}") from None
    except (TypeError, ValueError) as exc:
        raise DataError(f"{path}: {k}: expected a matrix of numbers ({exc})") from None
    _finite_arrays(out, path)
    ny, nu = len(doc["inputs"]), len(doc["outputs"])
    for suf in ("", "_c", "_r"):
        A, B, C, D = (out[k + suf] for k in "ABCD")
        n = A.shape[-1]
        want = {"A": (n, n), "B": (n, ny), "C": (nu, n), "D": (nu, ny)}
        for k, X in zip("ABCD", (A, B, C, D)):
            if X.shape[-2:] != want[k] and not (n == 0 and X.size == 0 and k != "D"):
                raise DataError(f"{path}: {k}{suf} has shape {X.shape[-2:]}, expected "
                                f"{want[k]} ({nu} outputs, {ny} inputs, {n} states)")
        if n == 0:
            shape = A.shape[:-2]
            out["A" + suf] = np.zeros(shape + (0, 0))
            out["B" + suf] = np.zeros(shape + (0, ny))
            out["C" + suf] = np.zeros(shape + (nu, 0))
    return out


def _finite_arrays(arrays: dict, path: Path) -> None:
    """DataError naming the first matrix with a NaN or ±inf entry (a controller file holds
    none: every number of ambseal's is checked before it is written)."""
    for k, X in arrays.items():
        if not np.all(np.isfinite(X)):
            raise DataError(f"{path}: {k}: expected finite numbers, got NaN or inf")


def _continuous(doc: dict, path: Path, channels):
    """A continuous controller file back to a ``control.StateSpace``, shapes checked and
    wired to ``channels`` (:func:`_wiring`); without ``channels``, a file with neither
    ``inputs`` nor ``outputs`` gets python-control's ``u[i]``, ``y[i]`` and a warning that
    it will be connected by position."""

    ts = np.ravel(np.asarray(doc.get("Ts", 0.0), float))
    if ts.size != 1 or ts[0] != 0:
        raise DataError(f"{path}: kind 'continuous' with Ts = {ts.tolist()}: a continuous "
                        "controller has Ts = 0 (a discrete one is written with kind 'fixed' "
                        "or 'scheduled', its sample rate and method)")
    try:
        if "inputs" not in doc and "outputs" not in doc and channels is None:
            D = np.atleast_2d(np.asarray(doc["D"], float))
            doc = {**doc, "inputs": [f"u[{j}]" for j in range(D.shape[1])],
                   "outputs": [f"y[{j}]" for j in range(D.shape[0])]}
            warnings.warn(f"{path}: no signal names (inputs, outputs): the controller is "
                          "connected by position, input j to the plant's j-th sensor and "
                          "output j to its j-th current (the rig's [[amb]] order, zeta then "
                          "eta)", stacklevel=3)
        ins, outs = _names(doc["inputs"], "inputs", path), _names(doc["outputs"], "outputs", path)
        A, B, C, D = (np.atleast_2d(np.asarray(doc[k], float)) for k in "ABCD")
    except KeyError as exc:
        raise DataError(f"{path}: missing key {exc} (expected A, B, C, D, inputs, outputs "
                        "as written by ambseal)") from None
    except (TypeError, ValueError) as exc:
        raise DataError(f"{path}: {exc}") from None
    _finite_arrays(dict(zip("ABCD", (A, B, C, D))), path)
    n = A.shape[0] if A.size else 0
    want = {"A": (n, n), "B": (n, len(ins)), "C": (len(outs), n), "D": (len(outs), len(ins))}
    for k, X in zip("ABCD", (A, B, C, D)):
        if X.shape != want[k] and not (n == 0 and k != "D"):
            raise DataError(f"{path}: {k} has shape {X.shape}, expected {want[k]}")
    if n == 0:
        A, B, C = np.zeros((0, 0)), np.zeros((0, len(ins))), np.zeros((len(outs), 0))
    name = _name(doc.get("name", "K"), "name", path)
    if channels is not None:
        arr = _wired(dict(zip("ABCD", (A, B, C, D))), ("",), _wiring(ins, outs, channels, path))
        A, B, C, D = (arr[k] for k in "ABCD")
        ins, outs = _signals(channels)
    return control.ss(A, B, C, D, inputs=ins, outputs=outs, name=name)


def _signals(channels) -> tuple[list[str], list[str]]:
    """A rig controller's inputs (the sensors ``y_<channel>``) and outputs (the currents
    ``i_<channel>``), in the rig's channel order."""
    return [f"y_{c}" for c in channels], [f"i_{c}" for c in channels]


def _wiring(ins: list, outs: list, channels, path: Path) -> tuple[list[int], list[int]]:
    """The columns and rows that put a file's inputs and outputs in the order of the rig's
    ``channels``, matched by name; DataError naming the file and both sets of signals when
    they are not the same set (a missing, extra, repeated or renamed channel)."""
    want_in, want_out = _signals(channels)
    if sorted(ins) != sorted(want_in) or sorted(outs) != sorted(want_out):
        raise DataError(f"{path}: its channels are not the rig's (a controller file is wired "
                        f"by signal name): inputs {list(ins)}, outputs {list(outs)}; the rig "
                        f"has inputs {want_in}, outputs {want_out}")
    return [ins.index(n) for n in want_in], [outs.index(n) for n in want_out]


def _wired(arr: dict, suffixes, wiring) -> dict:
    """``arr``'s ``B, C, D`` (with each suffix; table stacks on the leading axis) with
    their columns and rows in the rig's order (:func:`_wiring`)."""
    i, o = wiring
    out = dict(arr)
    for suf in suffixes:
        out["B" + suf] = arr["B" + suf][..., :, i]
        out["C" + suf] = arr["C" + suf][..., o, :]
        out["D" + suf] = arr["D" + suf][..., o, :][..., :, i]
    return out


#: How closely a discrete controller's matrices must equal the discretisation its file
#: states (method, sample time, pre-warp) of its own continuous ``A_r … D_r``, relative to
#: the largest entry: the file holds them as written (JSON's shortest repr, .npz and .mat
#: doubles), so only the rounding of recomputing them separates the two.
_KIND_RTOL = 1e-6


def _check_kind(arr: dict, method: str, fs: float, prewarp_hz, ts, path: Path) -> None:
    """DataError unless the file's discrete ``A … D`` are the ``method`` discretisation at
    ``1/fs`` of its continuous ``A_r … D_r`` (entry by entry of a table), and its ``Ts``
    (when given) is ``1/fs``: a continuous controller marked discrete, or one discretised
    at another rate, is refused before it reaches a target."""
    T = 1.0 / fs
    if ts is not None and not math.isclose(ts, T, rel_tol=1e-9):
        raise DataError(f"{path}: Ts = {ts:.9g} s but sample_rate_hz = {fs:.9g} Hz (1/Ts = "
                        f"{1.0 / ts if ts else math.inf:.9g} Hz): expected Ts = 1/sample_rate_hz")
    stacked = arr["A"].ndim == 3
    cont = [tuple(arr[k + "_r"][j] if stacked else arr[k + "_r"] for k in "ABCD")
            for j in range(arr["A"].shape[0] if stacked else 1)]
    for j, mats in enumerate(cont):
        try:  # a static gain (no states) is its own discretisation by every method
            want = mats if mats[0].size == 0 else discretize_as(mats, T, method, prewarp_hz)
        except AmbsealError as exc:
            raise DataError(f"{path}: method: {exc}") from None
        got = [arr[k][j] if stacked else arr[k] for k in "ABCD"]
        scale = max([1.0] + [float(np.max(np.abs(X))) for X in want if X.size])
        worst = max((float(np.max(np.abs(g - w))) for g, w in zip(got, want) if w.size),
                    default=0.0)
        if worst > _KIND_RTOL * scale:
            rho = float(np.max(np.abs(np.linalg.eigvals(got[0])), initial=0.0))
            at = f" (table entry {j})" if stacked else ""
            raise DataError(f"{path}: its discrete A, B, C, D{at} are not the {method} "
                            f"discretisation at Ts = {T:.6g} s of its continuous A_r ... D_r "
                            f"(largest difference {worst:.3g}; spectral radius of A "
                            f"{rho:.4g}): the file's kind does not match its matrices (a "
                            "continuous controller marked discrete, or another sample rate?)")


def load_controller(path, channels=None):
    """Read a controller written by :func:`export_controller` (any format), check that its
    stated kind matches its matrices and, given the rig's ``channels``, wire it to them by
    signal name.

    Parameters
    ----------
    path : str or os.PathLike
        A ``.json``, ``.npz`` or ``.mat`` file; the suffix says which.
    channels : sequence of str, optional
        The rig's AMB channels in its order (:func:`ambseal.model.amb.channel_names`): the
        controller's inputs must be ``y_<channel>`` and its outputs ``i_<channel>``, in any
        order; they come back in the rig's order (columns and rows permuted). Without
        them the file's order is kept.

    Returns
    -------
    DigitalController, ScheduledDigital or control.StateSpace
        The object that was exported: the same matrices, method, sample time, delay and
        (scheduled) table and interpolation law; a continuous controller alone (or a file
        without ``kind``) as a ``control.StateSpace``.

    Raises
    ------
    DataError
        Whatever is wrong with the file, in every format, naming it and the problem: not
        readable (truncated, not UTF-8, nested too deeply, MATLAB v7.3), not a document of
        keys, a missing key, a value of the wrong type or shape (named), a NaN or inf;
        a kind its matrices contradict (a continuous controller marked discrete: its
        discrete matrices are not its stated discretisation of its continuous ones, or
        ``Ts`` is not ``1/sample_rate_hz``; or ``Ts`` ≠ 0 on a continuous one); signals
        that are not the rig's ``channels`` (the message lists both).
    """
    path = Path(path)
    try:
        return _load(path, None if channels is None else tuple(channels))
    except (TypeError, ValueError, KeyError, IndexError, AttributeError, OverflowError,
            RecursionError) as exc:  # a value of a type no check above foresaw
        if isinstance(exc, DataError):
            raise
        raise DataError(f"{path}: not a controller file of ambseal ({type(exc).__name__}: "
                        f"{exc})") from None


def _load(path: Path, channels):
    """:func:`load_controller` without its last net for unforeseen values."""

    doc = _read(path)
    if str(doc.get("kind", "continuous")) == "continuous":
        return _continuous(doc, path, channels)
    try:
        kind, name = str(doc["kind"]), _name(doc["name"], "name", path)
        ins, outs = _names(doc["inputs"], "inputs", path), _names(doc["outputs"], "outputs", path)
        fs, delay = float(np.ravel(doc["sample_rate_hz"])[0]), int(np.ravel(doc["delay_samples"])[0])
        method = _name(doc["method"], "method", path)
        pw = float(np.ravel(doc["prewarp_hz"])[0])
        removed = tuple(float(x) for x in np.ravel(doc["removed_poles_hz"]))
        meta = json.loads(str(doc["discretisation_json"]))
    except (KeyError, TypeError, ValueError, IndexError) as exc:
        raise DataError(f"{path}: not a controller file of ambseal ({exc!r})") from None
    doc["inputs"], doc["outputs"] = ins, outs
    if kind not in ("fixed", "scheduled"):
        raise DataError(f"{path}: kind: {kind[:60]!r}, expected 'continuous', 'fixed' or "
                        "'scheduled'")
    if not (0 < fs <= MAX_FREQUENCY_HZ) or not 0 <= delay <= MAX_DELAY_SAMPLES \
            or not isinstance(meta, dict):
        raise DataError(f"{path}: sample_rate_hz = {fs:.6g}, delay_samples = {delay:.6g}, "
                        f"discretisation_json a {type(meta).__name__}: expected a rate from 0 "
                        f"to {MAX_FREQUENCY_HZ:g} Hz, a delay from 0 to {MAX_DELAY_SAMPLES} "
                        "samples and a JSON object (the rig file's bounds)")
    pw = pw if np.isfinite(pw) else None
    cands = tuple(meta.get("candidates", ()))
    arr = _arrays(doc, path, stacked=(kind == "scheduled"))
    ts = float(np.ravel(doc["Ts"])[0]) if "Ts" in doc else None
    _check_kind(arr, method, fs, pw, ts, path)
    if channels is not None:
        arr = _wired(arr, ("", "_c", "_r"), _wiring(ins, outs, channels, path))
        ins, outs = _signals(channels)
    if kind == "scheduled":
        par = _name(doc.get("parameter", SPEED), "parameter", path)
        key = "grid" if "grid" in doc else "speeds_rad_s"
        W = np.ravel(np.asarray(doc.get(key, ()), float))
        _finite_arrays({key: W}, path)
        if arr["A"].shape[0] != W.size:
            raise DataError(f"{path}: A holds {arr['A'].shape[0]} table entries but "
                            f"{key} has {W.size}")
        tab = {suf: tuple(arr[k + suf] for k in "ABCD") for suf in ("", "_c", "_r")}
        return ScheduledDigital(W, tab["_c"], tab["_r"], tab[""], tuple(ins), tuple(outs),
                                method, pw, fs, delay, removed, cands, name, par,
                                choice=str(meta.get("choice", "")))

    def ss(suf, nm):
        return control.ss(*(arr[k + suf] for k in "ABCD"), inputs=ins, outputs=outs, name=nm)

    # files written before it was recorded held continuous designs only
    plant = _name(doc.get("synthesis_plant", "continuous"), "synthesis_plant", path)
    if plant not in ("continuous", "sampled") or (plant == "sampled" and method != "tustin"):
        raise DataError(f"{path}: synthesis_plant = {plant[:60]!r} with method {method!r}: "
                        "expected 'continuous', or 'sampled' (a w-plane design, discretised "
                        "by 'tustin')")
    desc = {"type": "state_space", "name": name, "discretisation": method}
    disc = DiscreteController(*(arr[k] for k in "ABCD"), 1.0 / fs, description=desc)
    return DigitalController(ss("_c", name), ss("_r", f"{name}_r"), disc, method, pw, fs,
                             delay, removed, meta.get("reduction"), cands,
                             str(meta.get("choice", "")), synthesis_plant=plant)
