"""Checks and conversions of state-space data shared by every module.

* :func:`ss_matrices` — ``(A, B, C, D)`` as float arrays from a ``control.StateSpace`` (or
  anything python-control converts) or a tuple;
* :func:`as_omega` — a checked frequency grid in rad/s;
* :func:`labels` — signal names of a python-control system, or generated ones;
* :class:`ArrayMemo` — results of an expensive function of large arrays, kept for the last
  few distinct inputs (a large plant is decomposed once, not once per controller closed
  with it).
"""

from __future__ import annotations

import hashlib
import weakref
from collections import OrderedDict
from typing import Any, Callable

import control
import numpy as np

from ambseal.errors import ModelError

__all__ = ["as_omega", "ss_matrices", "labels", "ArrayMemo", "array_digest", "freeze"]


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


def ss_matrices(sys: Any, *, name: str = "sys",
                allow_discrete: bool = False) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
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

    Returns
    -------
    A, B, C, D : numpy.ndarray of float
        Shapes ``(n, n)``, ``(n, m)``, ``(p, n)`` and ``(p, m)``.

    Raises
    ------
    ModelError
        If the system is discrete-time (unless ``allow_discrete``) or the shapes disagree.
    """
    if isinstance(sys, tuple) and len(sys) == 4:
        A, B, C, D = (np.atleast_2d(np.asarray(m, dtype=float)) for m in sys)
    else:
        if not isinstance(sys, control.StateSpace):
            try:
                sys = control.ss(sys)
            except Exception as exc:  # pragma: no cover - message only
                raise ModelError(f"{name}: cannot convert {type(sys).__name__} to state space: {exc}") from exc
        if sys.dt not in (0, None) and not allow_discrete:
            raise ModelError(f"{name}: expected a continuous-time system (dt=0), got dt={sys.dt}")
        A, B, C, D = (np.asarray(m, dtype=float) for m in (sys.A, sys.B, sys.C, sys.D))
    n = A.shape[0]
    if A.shape != (n, n) or B.shape[0] != n or C.shape[1] != n or D.shape != (C.shape[0], B.shape[1]):
        raise ModelError(
            f"{name}: inconsistent state-space shapes A{A.shape} B{B.shape} C{C.shape} D{D.shape}"
        )
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


def freeze(a: np.ndarray) -> np.ndarray:
    """``a`` made read-only, with every array its memory comes from (its ``base`` chain).

    A frozen array's digest (:func:`array_digest`) is computed once and kept by the
    identity of the memory's owner: the memos look up a large plant's state matrix dozens
    of times (its loops' poles, its responses, its sampled form), and each digest of it
    hashes 28 MB at 1 888 states. Numpy lets an owner be made writeable again; ambseal never
    does that to an array it froze.

    Parameters
    ----------
    a : numpy.ndarray
        Any array; its flags (and its bases') are changed in place.

    Returns
    -------
    numpy.ndarray
        ``a`` itself.
    """
    x = a
    while isinstance(x, np.ndarray):
        x.flags.writeable = False
        x = x.base
    return a


#: Arrays from this size on have their digest kept while they are frozen (:func:`freeze`)
_KEPT_DIGEST_BYTES = 2**20
#: (owner's id, data address, shape, strides, dtype) → (weak reference to the owner, digest)
_DIGESTS: dict[tuple, tuple[weakref.ref, bytes]] = {}


def _frozen_owner(a: np.ndarray) -> np.ndarray | None:
    """The array owning ``a``'s memory if neither it nor any array between them may be
    written (so the bytes cannot change while it lives), else None."""
    x = a
    while not x.flags.writeable:
        if x.base is None:
            return x
        if not isinstance(x.base, np.ndarray):
            return None
        x = x.base
    return None


def _digest_of(a: np.ndarray) -> bytes:
    """SHA-256 of one array's bytes, kept for large frozen arrays."""
    owner = _frozen_owner(a) if a.nbytes >= _KEPT_DIGEST_BYTES else None
    if owner is None:
        return hashlib.sha256(np.ascontiguousarray(a).data).digest()
    key = (id(owner), a.__array_interface__["data"][0], a.shape, a.strides, a.dtype.str)
    kept = _DIGESTS.get(key)
    if kept is not None and kept[0]() is owner:
        return kept[1]
    digest = hashlib.sha256(np.ascontiguousarray(a).data).digest()
    _DIGESTS[key] = (weakref.ref(owner, lambda _, key=key: _DIGESTS.pop(key, None)), digest)
    return digest


def array_digest(arrays: tuple) -> bytes:
    """SHA-256 of the arrays' shapes, dtypes and the SHA-256 of their bytes: the key
    :class:`ArrayMemo` keeps results under; a large frozen array's digest is computed once
    (:func:`freeze`). SHA-256 rather than BLAKE2b: processors with SHA extensions (x86
    since 2017, ARMv8) hash a 28 MB matrix (1 888 states) in 19 ms against BLAKE2b's 49 ms."""
    h = hashlib.sha256()
    for a in arrays:
        a = np.asarray(a)
        h.update(f"{a.shape}{a.dtype.str}".encode())
        h.update(_digest_of(a))
    return h.digest()


class ArrayMemo:
    """Results of ``compute()`` kept for the last ``keep`` distinct inputs, keyed by a digest
    (:func:`array_digest`) of the input arrays plus ``extra``.

    Used where one large matrix is decomposed again and again with the same content (the
    large plant closed with one controller after another): hashing a
    320 × 320 matrix costs about 1 ms, its eigendecomposition about 60 ms. Only inputs
    with at least ``min_states`` rows are kept (small systems are cheaper to recompute
    than to hash). Cached results are shared: callers must not modify them in place.

    Parameters
    ----------
    keep : int
        How many distinct inputs' results are kept (the least recently used goes first).
    min_states : int
        Inputs whose first array has fewer rows are computed every time, not kept.
    """

    def __init__(self, keep: int = 8, min_states: int = 64):
        self.keep, self.min_states = keep, min_states
        self._kept: OrderedDict = OrderedDict()

    def get(self, arrays: tuple, extra: Any, compute: Callable[[], Any]) -> Any:
        """``compute()``, or its kept result for the same ``arrays`` and ``extra``."""
        if arrays[0].shape[0] < self.min_states:
            return compute()
        return self.get_digested(array_digest(arrays), extra, compute)

    def get_digested(self, digest: bytes | None, extra: Any, compute: Callable[[], Any]) -> Any:
        """As :meth:`get` for arrays whose :func:`array_digest` is ``digest`` (one digest
        for several lookups); ``None`` (too small to keep) computes."""
        if digest is None:
            return compute()
        key = (digest, repr(extra))
        if key in self._kept:
            self._kept.move_to_end(key)
            return self._kept[key]
        value = self._kept[key] = compute()
        if len(self._kept) > self.keep:
            self._kept.popitem(last=False)
        return value

    def digest(self, arrays: tuple) -> bytes | None:
        """:func:`array_digest` of ``arrays``, or ``None`` below ``min_states`` rows."""
        return array_digest(arrays) if arrays[0].shape[0] >= self.min_states else None
