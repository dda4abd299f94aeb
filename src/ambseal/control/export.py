"""Controllers to files: continuous and discrete state space in .npz, .mat and JSON.

The discrete forms are Tustin (bilinear) and zero-order-hold equivalents at the given sample
rate (Franklin, Powell & Workman, *Digital Control of Dynamic Systems*, ch. 6), computed by
:func:`ambseal.lti.discrete.discretize`. Each file carries the channel names so a controller can be
wired to the right AMB axes (``A_zeta``, ``A_eta``, ``B_zeta``, ``B_eta``) on the target.

Files are written to a temporary name in the destination folder and moved into place with
:func:`os.replace`, so a reader never sees half a file.
"""

from __future__ import annotations

import json
from pathlib import Path
from typing import Sequence

import numpy as np

from ..files import atomic_write
from ..lti.discrete import discretize as _discretize

__all__ = ["discretize", "controller_arrays", "export_controller", "load_controller"]

_METHODS = ("tustin", "zoh")
_FORMATS = (".npz", ".mat", ".json")


def discretize(K, fs_hz: float, method: str = "tustin"):
    """Discrete-time equivalent of a continuous controller at a sample rate (Hz).

    :func:`ambseal.lti.discrete.discretize` at ``dt = 1/fs_hz``.

    Raises
    ------
    ValueError
        Non-positive or non-finite sample rate, unknown method, discrete input.
    """
    if not (np.isfinite(fs_hz) and fs_hz > 0):
        raise ValueError(f"fs_hz={fs_hz!r}: the sample rate must be a positive number of Hz")
    return _discretize(K, 1.0 / fs_hz, method)


def controller_arrays(K, fs_hz: float | None = None,
                      methods: Sequence[str] = _METHODS) -> dict:
    """Plain arrays and names describing a controller (the content of every export format).

    Returns
    -------
    dict
        ``A, B, C, D`` (continuous, s⁻¹ time base), for each method ``A_<m>`` … ``D_<m>``
        (discrete), ``inputs``, ``outputs``, ``states`` (lists of str), ``fs_hz`` and
        ``dt_s`` (``nan`` when no sample rate is given).
    """
    out: dict = {
        "A": np.asarray(K.A, float), "B": np.asarray(K.B, float),
        "C": np.asarray(K.C, float), "D": np.asarray(K.D, float),
        "inputs": list(K.input_labels), "outputs": list(K.output_labels),
        "states": list(K.state_labels),
        "fs_hz": float("nan") if fs_hz is None else float(fs_hz),
        "dt_s": float("nan") if fs_hz is None else 1.0 / float(fs_hz),
    }
    if fs_hz is not None:
        for m in methods:
            Kd = discretize(K, fs_hz, m)
            for key, X in zip("ABCD", (Kd.A, Kd.B, Kd.C, Kd.D)):
                out[f"{key}_{m}"] = np.asarray(X, float)
    return out


def _atomic_write(path: Path, write) -> None:
    path.parent.mkdir(parents=True, exist_ok=True)
    atomic_write(path, write)


def export_controller(K, path, fs_hz: float | None = None,
                      methods: Sequence[str] = _METHODS) -> Path:
    """Write a controller as continuous (and discrete) state space.

    Parameters
    ----------
    K : control.StateSpace
        Continuous-time controller; its input/output/state names are stored.
    path : str or Path
        Destination; the suffix picks the format: ``.npz`` (NumPy), ``.mat`` (MATLAB,
        via :func:`scipy.io.savemat`) or ``.json``.
    fs_hz : float, optional
        Sample rate in Hz; when given, Tustin and ZOH equivalents are added as
        ``A_tustin`` … ``D_zoh``.
    methods : sequence of str
        Discretisation methods to include (subset of ``("tustin", "zoh")``).

    Returns
    -------
    Path
        The written file.

    Raises
    ------
    ValueError
        Unknown suffix, bad sample rate or method.

    Examples
    --------
    >>> import control as ct, tempfile, pathlib
    >>> K = ct.ss([[-100.]], [[1.]], [[50.]], [[2.]], inputs=["y"], outputs=["u"])
    >>> d = pathlib.Path(tempfile.mkdtemp())
    >>> export_controller(K, d / "K.json", fs_hz=10e3).name
    'K.json'
    """
    path = Path(path)
    suffix = path.suffix.lower()
    if suffix not in _FORMATS:
        raise ValueError(f"{path}: unknown controller format {suffix!r}, expected one of {_FORMATS}")
    data = controller_arrays(K, fs_hz, methods)
    if suffix == ".npz":
        arrays = {k: (np.array(v, dtype=str) if isinstance(v, list) else np.asarray(v))
                  for k, v in data.items()}
        _atomic_write(path, lambda fh: np.savez(fh, **arrays))
    elif suffix == ".mat":
        from scipy.io import savemat

        mdict = {}
        for k, v in data.items():
            mdict[k] = np.array(v, dtype=object) if isinstance(v, list) else np.asarray(v)
        _atomic_write(path, lambda fh: savemat(fh, mdict, oned_as="column"))
    else:
        doc = {k: (v.tolist() if isinstance(v, np.ndarray) else v) for k, v in data.items()}
        for k in ("fs_hz", "dt_s"):
            if not np.isfinite(doc[k]):
                doc[k] = None
        doc["units"] = {"time": "s", "fs": "Hz"}
        text = json.dumps(doc, indent=1).encode()
        _atomic_write(path, lambda fh: fh.write(text))
    return path


def load_controller(path):
    """Read back the continuous controller of a file written by :func:`export_controller`.

    Parameters
    ----------
    path : str or Path
        ``.json``, ``.npz`` or ``.mat`` with ``A``, ``B``, ``C``, ``D`` (continuous) and the
        channel names ``inputs`` / ``outputs``.

    Returns
    -------
    control.StateSpace
        Displacements (m) → current references (A), ``i = −K y``.

    Raises
    ------
    DataError
        A missing or unreadable file, an unknown suffix, missing or inconsistent matrices.
    """
    import control

    from ..errors import DataError

    path = Path(path)
    suffix = path.suffix.lower()
    try:
        if suffix == ".json":
            doc = json.loads(path.read_text(encoding="utf-8"))
        elif suffix == ".npz":
            with np.load(path, allow_pickle=False) as z:
                doc = {k: z[k] for k in z.files}
        elif suffix == ".mat":
            from scipy.io import loadmat

            doc = loadmat(path, squeeze_me=False)
        else:
            raise DataError(f"{path}: unknown controller format {suffix!r}, expected one "
                            f"of {_FORMATS}")
    except (OSError, ValueError) as exc:
        raise DataError(f"{path}: cannot read controller ({exc})") from None
    try:
        A, B, C, D = (np.atleast_2d(np.asarray(doc[k], float)) for k in "ABCD")
        names = {k: [str(x).strip() for x in np.ravel(doc[k])] for k in ("inputs", "outputs")}
        n = A.shape[0] if A.size else 0
        A, B = A.reshape(n, n), B.reshape(n, -1) if n else np.zeros((0, D.shape[1]))
        C = C.reshape(-1, n) if n else np.zeros((D.shape[0], 0))
        return control.ss(A, B, C, D, inputs=names["inputs"], outputs=names["outputs"])
    except KeyError as exc:
        raise DataError(f"{path}: missing key {exc.args[0]!r} (expected A, B, C, D, inputs, "
                        "outputs as written by ambseal design)") from None
    except (ValueError, TypeError) as exc:
        raise DataError(f"{path}: inconsistent controller matrices ({exc})") from None
