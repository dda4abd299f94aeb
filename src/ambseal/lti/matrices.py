"""Checks and conversions of state-space data shared by every module.

* :func:`ss_matrices` — ``(A, B, C, D)`` as float arrays from a ``control.StateSpace`` (or
  anything python-control converts) or a tuple;
* :func:`as_omega` — a checked frequency grid in rad/s;
* :func:`labels` — signal names of a python-control system, or generated ones;

The results kept by the digest of their input arrays are :mod:`ambseal.lti.memo`'s.
"""

from __future__ import annotations

from typing import Any

import control
import numpy as np

from ambseal.errors import ModelError

__all__ = ["as_omega", "ss_matrices", "labels"]


def as_omega(omega: Any, *, name: str = "omega") -> np.ndarray:
    """Check and return a 1-D float frequency grid in rad/s.

    Parameters
    ----------
    omega : float or array_like
        Frequencies, rad/s (a scalar is a grid of one).
    name : str, optional
        What the error message calls the grid.

    Returns
    -------
    numpy.ndarray of float, shape (n,)
        The grid, rad/s.

    Raises
    ------
    ModelError
        If the grid is not 1-D, empty, or holds non-finite or negative values.
    """
    w = np.atleast_1d(np.asarray(omega, dtype=float))
    if w.ndim != 1 or w.size == 0:
        raise ModelError(f"{name}: expected a non-empty 1-D frequency grid in rad/s, got shape {w.shape}")
    if not np.all(np.isfinite(w)) or np.any(w < 0):
        raise ModelError(f"{name}: frequencies must be finite and >= 0 rad/s")
    return w


def ss_matrices(sys: Any, *, name: str = "sys", allow_discrete: bool = False,
                finite: bool = False) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Return (A, B, C, D) as float arrays of an LTI system.

    Accepts a ``control.StateSpace`` (or anything python-control converts to one, e.g. a
    transfer function) or a tuple ``(A, B, C, D)``.

    Parameters
    ----------
    sys : control.StateSpace or (A, B, C, D)
        The system; a tuple's entries are made 2-D float arrays.
    name : str, optional
        What the error messages call the system.
    allow_discrete : bool, optional
        Accept a discrete-time system (its matrices are returned as they are).
    finite : bool, optional
        Refuse a NaN or infinite entry.

    Returns
    -------
    A, B, C, D : numpy.ndarray of float
        Shapes ``(n, n)``, ``(n, m)``, ``(p, n)`` and ``(p, m)``.

    Raises
    ------
    ModelError
        If the system is discrete-time (unless ``allow_discrete``), the shapes disagree, it
        is no system or (with ``finite``) an entry is NaN or infinite.
    """
    if isinstance(sys, tuple) and len(sys) == 4:
        try:
            A, B, C, D = (np.atleast_2d(np.asarray(m, dtype=float)) for m in sys)
        except (TypeError, ValueError) as exc:
            raise ModelError(f"{name}: (A, B, C, D) must be arrays of numbers ({exc})") from None
    else:
        if not isinstance(sys, control.StateSpace):
            try:
                sys = control.ss(sys)
            except Exception as exc:  # python-control's own errors: named here, one line
                raise ModelError(f"{name}: cannot convert {type(sys).__name__} to state "
                                 f"space: {exc}") from None
        if sys.dt not in (0, None) and not allow_discrete:
            raise ModelError(f"{name}: expected a continuous-time system (dt=0), got dt={sys.dt}")
        A, B, C, D = (np.asarray(m, dtype=float) for m in (sys.A, sys.B, sys.C, sys.D))
    n = A.shape[0]
    if A.shape != (n, n) or B.shape[0] != n or C.shape[1] != n or D.shape != (C.shape[0], B.shape[1]):
        raise ModelError(
            f"{name}: inconsistent state-space shapes A{A.shape} B{B.shape} C{C.shape} D{D.shape}"
        )
    if finite and not all(np.all(np.isfinite(X)) for X in (A, B, C, D)):
        raise ModelError(f"{name}: a NaN or infinite entry in its matrices")
    return A, B, C, D


def shared_ss(A: np.ndarray, B: np.ndarray, C: np.ndarray, D: np.ndarray, dt: float = 0,
              **names: Any) -> Any:
    """``control.ss(A, B, C, D, dt, **names)`` whose ``A`` is ``A`` itself, not a copy.

    ``control.ss`` copies every matrix it is given: the systems made from one large plant
    (its selections of inputs, one per loop and judged condition) would each hold an
    n × n copy of its state matrix (28 MB at 1 888 states) for as long as they live.

    Parameters
    ----------
    A, B, C, D : numpy.ndarray
        State-space matrices, shapes ``(n, n)``, ``(n, m)``, ``(p, n)``, ``(p, m)``.
    dt : float
        Sample time (s); 0 for a continuous system.
    **names
        ``inputs``, ``outputs``, ``states``, ``name`` as for ``control.ss``.

    Returns
    -------
    control.StateSpace
        Its ``A`` a read-only view of ``A`` (as float): neither may be written into while
        the other is in use.
    """
    sys = control.ss(A, B, C, D, dt, **names)
    shared = np.asarray(A, float).view()
    shared.flags.writeable = False
    sys.A = shared
    return sys


def select_inputs(sys: Any, idx: Any) -> Any:
    """``sys`` with only the inputs ``idx``, its state matrix shared (:func:`shared_ss`).

    Parameters
    ----------
    sys : control.StateSpace
        The system, ``n`` states, ``m`` inputs, ``p`` outputs.
    idx : sequence of int
        The inputs kept, in this order.

    Returns
    -------
    control.StateSpace
        The same time base, states and output names; the inputs ``idx`` under their names;
        ``A`` a read-only view of ``sys.A``.
    """
    idx = list(idx)
    return shared_ss(sys.A, np.asarray(sys.B)[:, idx], sys.C, np.asarray(sys.D)[:, idx],
                     sys.dt, inputs=[sys.input_labels[j] for j in idx],
                     outputs=list(sys.output_labels), states=list(sys.state_labels))


def labels(sys: Any, kind: str, count: int, prefix: str) -> tuple[str, ...]:
    """Input or output labels of a python-control system, or generated ones.

    Parameters
    ----------
    sys : object
        A python-control system, or anything without ``<kind>_labels`` (a tuple of
        matrices).
    kind : {"input", "output"}
        Which labels.
    count : int
        How many signals there are; the system's labels are used only if it has this many.
    prefix : str
        The generated labels' stem: ``prefix[0]``, ``prefix[1]``, ….

    Returns
    -------
    tuple of str, length ``count``
    """
    names = getattr(sys, f"{kind}_labels", None)
    if names is not None and len(names) == count:
        return tuple(str(s) for s in names)
    return tuple(f"{prefix}[{i}]" for i in range(count))
