"""Results of expensive functions of large arrays, kept by the arrays' digest.

* :class:`ArrayMemo` — results of an expensive function of large arrays, kept for the last
  few distinct inputs (a large plant is decomposed once, not once per controller closed
  with it);
* :func:`array_digest` — the key they are kept under (SHA-256 of the arrays);
* :func:`freeze` — an array made read-only, its digest then computed once.

No python-control here: the model's lowest layers keep their results with it, and a command
that only computes modes loads nothing of the control numerics.
"""

from __future__ import annotations

import hashlib
import math
import weakref
from collections import OrderedDict
from typing import Any, Callable

import numpy as np

__all__ = ["ArrayMemo", "array_digest", "freeze"]


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


def _nbytes(value) -> float:
    """The bytes of a result's arrays: an array's or an object's ``nbytes``, a Python
    number's 8 (16 complex), a string's UTF-8 length, None's 0, or the sum over a tuple or
    list of them; infinite for anything else (its size unknown, it never exceeds
    ``keep``): a condition number or a list of signal names beside the arrays must not
    make the whole result unbounded."""
    if isinstance(value, (tuple, list)):
        return float(sum(_nbytes(v) for v in value))
    if value is None:
        return 0.0
    if isinstance(value, str):
        return float(len(value.encode()))
    if isinstance(value, (bool, int, float, complex)):
        return 16.0 if isinstance(value, complex) else 8.0
    size = getattr(value, "nbytes", None)
    return float(size) if isinstance(size, (int, np.integer)) else math.inf


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
    keep_bytes : int
        More than ``keep`` results are kept while the arrays of all of them (a result that
        is an array, has ``nbytes``, is a number, a string or None, or is a tuple or
        list of such; any other counts as unbounded) hold at most this many bytes: a
        sweep over more inputs than ``keep``, repeated for each controller, finds its
        results on a small model, where on a large one the ``keep`` bound holds.
    """

    def __init__(self, keep: int = 8, min_states: int = 64, keep_bytes: int = 0):
        self.keep, self.min_states, self.keep_bytes = keep, min_states, keep_bytes
        self._kept: OrderedDict = OrderedDict()
        self._bytes: dict = {}

    def get(self, arrays: tuple, extra: Any, compute: Callable[[], Any]) -> Any:
        """``compute()``, or its kept result for the same ``arrays`` and ``extra``."""
        if arrays[0].shape[0] < self.min_states:
            return compute()
        return self.get_digested(array_digest(arrays), extra, compute)

    def get_digested(self, digest: bytes | None, extra: Any, compute: Callable[[], Any]) -> Any:
        """As :meth:`get` for arrays whose :func:`array_digest` is ``digest`` (one digest
        for several lookups), or for any input a digest names (a configuration's, say);
        ``None`` (too small to keep) computes."""
        if digest is None:
            return compute()
        key = (digest, repr(extra))
        if key in self._kept:
            self._kept.move_to_end(key)
            return self._kept[key]
        value = self._kept[key] = compute()
        self._bytes[key] = _nbytes(value)
        while len(self._kept) > self.keep and sum(self._bytes.values()) > self.keep_bytes:
            self._bytes.pop(self._kept.popitem(last=False)[0])
        return value

    def digest(self, arrays: tuple) -> bytes | None:
        """:func:`array_digest` of ``arrays``, or ``None`` below ``min_states`` rows."""
        return array_digest(arrays) if arrays[0].shape[0] >= self.min_states else None
