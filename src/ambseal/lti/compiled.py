"""numba kernels compiled once and cached on disk where a cache can be written.

``numba.njit(cache=True)`` looks for a writable cache folder when a module is imported
(``NUMBA_CACHE_DIR``, then the source's ``__pycache__``, then the user's cache folder) and
raises if none is — a read-only installation (a system package, a container image, a
shared read-only environment) without a writable home would end every command in a
traceback. :func:`cached_njit` compiles without the disk cache there instead: the same
machine code, compiled again in each process.
"""

from __future__ import annotations

from typing import Callable

from numba import njit

__all__ = ["cached_njit"]


def cached_njit(**options) -> Callable:
    """``numba.njit(cache=True, **options)``, or without the disk cache when no cache
    folder is writable.

    Parameters
    ----------
    **options
        numba's compile options (``nogil``, ``fastmath``, ...); ``cache`` is chosen here.

    Returns
    -------
    callable
        A decorator of the kernel.

    Examples
    --------
    >>> @cached_njit(nogil=True)
    ... def twice(x):
    ...     return 2.0 * x
    >>> twice(1.5)
    3.0
    """

    def decorate(fn: Callable) -> Callable:
        try:
            return njit(cache=True, **options)(fn)
        except RuntimeError:  # numba: "cannot cache function ...: no locator available"
            return njit(cache=False, **options)(fn)

    return decorate
