"""ambseal's thread policy: its numerics run on one BLAS thread unless the user says otherwise.

ambseal's numerics are many small dense problems (Riccati equations, eigenvalues and
solves of 10–200 states, one per frequency, iteration or case). Multi-threaded BLAS
(OpenBLAS, MKL, BLIS) splits each of them across threads that spin waiting for work; on a
shared machine they burn the time instead (`benchmarks/bench_threads.py`). So every
command and every heavy entry point of the API runs inside :func:`numerics_threads`, which
sets the BLAS and OpenMP thread pools of this process to the policy's count with
threadpoolctl and restores them afterwards, and sets the standard variables
(``OPENBLAS_NUM_THREADS``, ``OMP_NUM_THREADS``, …) for the processes started meanwhile
(Dask workers, readers), so that they inherit the policy. One thread also makes the numbers
independent of the machine: a BLAS's summation order depends on its thread count.

The policy is the environment variable ``AMBSEAL_BLAS_THREADS`` (the CLI's
``--blas-threads`` sets it for one command): a whole number ≥ 1 of threads, or
``inherit`` to leave the thread pools as the environment set them. Default: 1.
"""

from __future__ import annotations

import functools
import os
import sys
import threading
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from typing import TypeVar

from ambseal.errors import ConfigError

__all__ = ["ENV_VAR", "DEFAULT_THREADS", "blas_threads", "numerics_threads",
           "with_numerics_threads"]

#: The environment variable that sets the policy.
ENV_VAR = "AMBSEAL_BLAS_THREADS"
#: Threads when ``AMBSEAL_BLAS_THREADS`` is not set.
DEFAULT_THREADS = 1
#: The variables that thread pools read when a process starts, set for child processes.
_CHILD_VARS = ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS",
               "BLIS_NUM_THREADS", "VECLIB_MAXIMUM_THREADS", "NUMEXPR_NUM_THREADS")

_lock = threading.RLock()
_depth = 0
_active: tuple | None = None  # (threadpoolctl limiter, the environment it replaced)
_controller: tuple | None = None  # (number of modules when made, ThreadpoolController)

F = TypeVar("F", bound=Callable)


def blas_threads(value: str | int | None = None) -> int | None:
    """The policy's thread count.

    Parameters
    ----------
    value : str or int, optional
        A whole number ≥ 1 or ``"inherit"``; default: the environment variable
        ``AMBSEAL_BLAS_THREADS``, or :data:`DEFAULT_THREADS` when it is not set.

    Returns
    -------
    int or None
        Threads for BLAS and OpenMP; None for ``inherit`` (leave them as they are).

    Raises
    ------
    ConfigError
        A value that is neither a whole number ≥ 1 nor ``inherit``; the message names
        ``AMBSEAL_BLAS_THREADS`` when the value came from it.
    """
    source = "--blas-threads"
    if value is None:
        value, source = os.environ.get(ENV_VAR, ""), ENV_VAR
        if not value.strip():
            return DEFAULT_THREADS
    text = str(value).strip()
    if text.lower() == "inherit":
        return None
    try:
        n = int(text)
    except ValueError:
        n = 0
    if n < 1 or str(n) != text.lstrip("+"):
        raise ConfigError(f"{source}={value!r}: expected a whole number of threads ≥ 1 or "
                          f"'inherit'")
    return n


def _threadpools():
    """threadpoolctl's controller of the loaded BLAS/OpenMP libraries, made again when a
    module has been imported since (a new module may have loaded another BLAS:
    slycot and cvxopt carry their own)."""
    global _controller
    # threadpoolctl is imported here: its import scans the loaded libraries, and a
    # process that never enters the numerics (--help, a rejected argument) need not pay it
    from threadpoolctl import ThreadpoolController

    n = len(sys.modules)
    if _controller is None or _controller[0] != n:
        _controller = (n, ThreadpoolController())
    return _controller[1]


@contextmanager
def numerics_threads(threads: str | int | None = None) -> Iterator[int | None]:
    """Run the enclosed numerics with the policy's BLAS and OpenMP threads.

    Nested and concurrent uses share the outermost one's setting; the last to leave
    restores the thread pools and the environment as they were.

    Parameters
    ----------
    threads : str or int, optional
        As :func:`blas_threads` (default: the environment's policy).

    Yields
    ------
    int or None
        The threads in force (None: ``inherit``, nothing changed).

    Raises
    ------
    ConfigError
        A bad ``threads`` or ``AMBSEAL_BLAS_THREADS`` (:func:`blas_threads`).
    """
    global _depth, _active
    n = blas_threads(threads)
    if n is None:
        yield None
        return
    with _lock:
        if _depth == 0:
            before = {v: os.environ.get(v) for v in _CHILD_VARS}
            limiter = _threadpools().limit(limits=n)
            os.environ.update({v: str(n) for v in _CHILD_VARS})
            _active = (limiter, before)
        _depth += 1
    try:
        yield n
    finally:
        with _lock:
            _depth -= 1
            if _depth == 0 and _active is not None:
                limiter, before = _active
                _active = None
                limiter.restore_original_limits()
                for v, old in before.items():
                    if old is None:
                        os.environ.pop(v, None)
                    else:
                        os.environ[v] = old


def with_numerics_threads(func: F) -> F:
    """Decorate a heavy entry point: it runs inside :func:`numerics_threads`.

    Parameters
    ----------
    func : callable
        The entry point.

    Returns
    -------
    callable
        ``func`` run under the thread policy, with its name and docstring.
    """

    @functools.wraps(func)
    def inner(*args, **kwargs):
        with numerics_threads():
            return func(*args, **kwargs)

    return inner  # type: ignore[return-value]
