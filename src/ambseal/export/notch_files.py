"""The unbalance force rejection's notch to a file a real-time target can run, and back.

A JSON document (:func:`export_notch`) beside the controller file it belongs to:

* ``convention`` — the target computes, every sample, with the measured speed Ω (rad/s)
  and ε = ``rate_fraction`` · Ω: ``q = y − a``; then
  ``[a; b] ← R(Ω T_s) ([a; b] + ε T_s [T_re; T_im](Ω) q)`` (R the rotation by ΩT_s of each
  (a_r, b_r) pair), and feeds ``q`` to the controller in place of ``y``; below
  ``on_rad_s`` it sets ``a = b = 0`` and ``q = y``
  (:class:`~ambseal.machine.synchronous_notch.SynchronousNotch`, Herzog et al., IEEE TCST
  1996);
* ``speeds_rad_s`` (n_t) and ``gain_re``, ``gain_im`` (n_t, p, p) — the gain table,
  ``interpolation`` its law (linear in Ω between entries, held at the ends);
* ``inputs`` — the sensor displacements (m) in the order of the gains' rows and columns;
  ``Ts`` (s), ``rate_fraction``, ``on_rad_s``, ``controller`` (the controller's name).

Written to a temporary name and renamed (:func:`ambseal.files.atomic_write`); read back
(:func:`load_notch`) with each key checked and named when it is wrong.
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np

from ambseal.errors import AmbsealError, DataError, ModelError
from ambseal.export.controller_files import LABEL
from ambseal.files import atomic_write, input_file
from ambseal.machine import SynchronousNotch

__all__ = ["export_notch", "load_notch", "NOTCH_CONVENTION"]

NOTCH_CONVENTION = (
    "every sample, with the measured speed W (rad/s) and eps = rate_fraction * W: q = y - a; "
    "[a; b] <- R(W Ts) ([a; b] + eps Ts [T_re; T_im](W) q), R rotating each (a_r, b_r) by "
    "W Ts; the controller reads q in place of y. Below on_rad_s: a = b = 0 and q = y.")
_INTERPOLATION = ("linear in the rotor speed (rad/s) between the table's speeds, held at "
                  "its ends")


def export_notch(notch: SynchronousNotch, path, controller: str = "") -> Path:
    """Write a discrete notch to ``path`` (``.json``; module docstring).

    Parameters
    ----------
    notch : SynchronousNotch
        The discrete notch as judged (``dt`` > 0).
    path : str or Path
        Destination, ``.json``.
    controller : str
        The name of the controller it belongs to.

    Returns
    -------
    Path

    Raises
    ------
    DataError
        Another suffix, a continuous notch or a non-finite number (nothing is written).
    """
    path = Path(path)
    if path.suffix.lower() != ".json":
        raise DataError(f"{path}: a notch is written as .json")
    if not notch.dt > 0:
        raise DataError(f"{path}: a continuous notch does not run on a target (dt = 0)")
    arrays = (notch.speeds_rad_s, notch.gain_re, notch.gain_im)
    if not all(np.all(np.isfinite(a)) for a in arrays):
        raise DataError(f"{path}: the notch's table holds NaN or inf; nothing was written")
    doc = {"kind": "synchronous_notch", "convention": NOTCH_CONVENTION,
           "interpolation": _INTERPOLATION, "controller": str(controller),
           "inputs": list(notch.inputs), "Ts": float(notch.dt),
           "rate_fraction": float(notch.rate_fraction), "on_rad_s": float(notch.on_rad_s),
           "speeds_rad_s": np.asarray(notch.speeds_rad_s, float).tolist(),
           "gain_re": np.asarray(notch.gain_re, float).tolist(),
           "gain_im": np.asarray(notch.gain_im, float).tolist()}
    text = json.dumps(doc, indent=1, allow_nan=False).encode()
    path.parent.mkdir(parents=True, exist_ok=True)
    atomic_write(path, lambda fh: fh.write(text))
    return path


def load_notch(path) -> SynchronousNotch:
    """Read a notch written by :func:`export_notch`.

    Parameters
    ----------
    path : str or Path
        The ``.json`` file.

    Returns
    -------
    SynchronousNotch

    Raises
    ------
    DataError
        A file that is not such a document: the key that is missing or wrong named, with
        what was expected (a table whose rows differ in length: the first such row, e.g.
        ``gain_re[2][1]``).
    """
    path = Path(path)
    try:
        input_file(path, "notch file")
        doc = json.loads(path.read_text(encoding="utf-8"))
    except AmbsealError as exc:
        raise DataError(str(exc)) from None
    except (OSError, ValueError, RecursionError) as exc:
        raise DataError(f"{path}: not a readable notch file ({exc})") from None
    if not isinstance(doc, dict) or doc.get("kind") != "synchronous_notch":
        raise DataError(f"{path}: expected a JSON object with kind = \"synchronous_notch\"")
    inputs = doc.get("inputs")
    if not isinstance(inputs, list) or not inputs or not all(
            isinstance(n, str) and LABEL.fullmatch(n) for n in inputs):
        raise DataError(f"{path}: inputs: expected a list of signal names (letters, digits, "
                        "_ . + - [ ])")
    p = len(inputs)

    def number(key):
        v = doc.get(key)
        if isinstance(v, bool) or not isinstance(v, (int, float)) or not np.isfinite(v):
            raise DataError(f"{path}: {key}: expected a finite number, got {v!r}")
        return float(v)

    def array(key, shape):
        v = doc.get(key)
        if not _numbers(v):  # NumPy would read "1.5" and true as numbers
            raise DataError(f"{path}: {key}: expected an array of numbers (not strings or "
                            "true/false)")
        uneven = _uneven(v, shape)  # NumPy refuses ragged rows with its own ValueError
        if uneven is not None:
            raise DataError(f"{path}: {key}{uneven}")
        a = np.asarray(v, dtype=float)
        if not np.all(np.isfinite(a)):
            raise DataError(f"{path}: {key}: expected finite numbers of shape {shape}, got "
                            "NaN or inf")
        return a

    speeds = doc.get("speeds_rad_s")
    n = len(speeds) if isinstance(speeds, list) else 0
    w = array("speeds_rad_s", (n,))
    if not number("Ts") > 0:
        raise DataError(f"{path}: Ts: expected the sample time (s), > 0")
    try:
        return SynchronousNotch(w, array("gain_re", (n, p, p)), array("gain_im", (n, p, p)),
                                number("rate_fraction"), number("on_rad_s"), tuple(inputs),
                                number("Ts"))
    except ModelError as exc:
        raise DataError(f"{path}: {exc}") from None


def _uneven(v, shape: tuple, at: str = "") -> str | None:
    """Where nested lists ``v`` depart from ``shape`` — ``"[0][1]: expected 4 numbers, got
    3"`` (a row of another length: a ragged table), or ``": expected an array of shape (3,
    4, 4), got 2 rows"`` at the top — else None."""
    if not shape:
        return None if not isinstance(v, list) else f"{at}: expected a number, got a list"
    where = at or ""
    if not isinstance(v, list):
        return f"{where}: expected a list of {shape[0]}, got a number"
    if len(v) != shape[0]:
        what = "numbers" if len(shape) == 1 else "rows"
        whole = "" if at else f" (shape {shape})"
        return f"{where}: expected {shape[0]} {what}{whole}, got {len(v)}"
    for i, x in enumerate(v):
        found = _uneven(x, shape[1:], f"{at}[{i}]")
        if found is not None:
            return found
    return None


def _numbers(v, depth: int = 0) -> bool:
    """Whether ``v`` is a number (not a bool) or nested lists of them (3 levels at most)."""
    if isinstance(v, list):
        return depth < 3 and all(_numbers(x, depth + 1) for x in v)
    return isinstance(v, (int, float)) and not isinstance(v, bool)
