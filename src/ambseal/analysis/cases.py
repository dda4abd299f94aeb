"""The one executor of every multi-case analysis, serial or on Dask.

:func:`run_cases` runs a pure function ``fn(case, **shared)`` over a list of cases (the
sweeps' grid points, the Campbell diagram's speeds, ``ambseal run``'s judged operating
points), serially or on ``dask.distributed`` (a local cluster of processes with one BLAS
thread each, or a running scheduler by address). ``shared`` is sent to each worker once
(``Client.scatter``, broadcast) and the function is pickled by reference, so a worker
imports ambseal once, not per case. The local cluster is private to the process that
starts it: TLS with temporary credentials of its own (``LocalCluster(security=True)``: a
client without them, another local user's included, cannot connect to run code in it),
its workers' scratch folder a fresh 0700 one (``tempfile.mkdtemp``: a folder on a shared,
predictable path such as ``$TMPDIR/dask-scratch-space`` could be created first by another
user and planted with modules the workers import), no HTTP server left listening (no
dashboard, metrics or proxy routes, the servers stopped once the cluster is up). A
scheduler given by address is the user's and trusted: whoever can reach it runs code in
its workers. Results come back in input order; a case that raises is
recorded as a :class:`CaseError` with its message and the others go on. A progress bar
(rich, on stderr) counts cases as they finish.
"""

from __future__ import annotations

import asyncio
import multiprocessing
import os
import shutil
import sys
import tempfile
from dataclasses import dataclass
from typing import Callable, Sequence

from rich.console import Console
from rich.progress import Progress

from ambseal.errors import AmbsealError, ConfigError
from ambseal.threads import with_numerics_threads

__all__ = ["CaseError", "run_cases", "dask_available", "SERIAL_BELOW", "SCHEDULER_TIMEOUT_S",
           "probe_scheduler"]

#: Sweeps with fewer cases than this run serially when no workers or scheduler are given:
#: a local cluster costs a few seconds to start, about 20 cases of the embedded rig.
SERIAL_BELOW = 64
#: The longest a Dask scheduler given by address may take to connect and to answer an
#: ``identity`` request (s): a scheduler answers in milliseconds, a remote one across a
#: slow link in well under a second; anything that accepts a connection and stays silent
#: (a wrong port, a stalled host) is refused after this instead of waiting forever.
SCHEDULER_TIMEOUT_S = 10.0


@dataclass(frozen=True)
class CaseError:
    """A case that failed: the case and the error's one-line message.

    Attributes
    ----------
    case : dict
        The case as given to :func:`run_cases`.
    error : str
        ``"<ExceptionType>: <message>"`` of what it raised.
    """

    case: dict
    error: str


def dask_available() -> bool:
    """Whether ``dask.distributed`` can be imported (the ``[dask]`` extra).

    Returns
    -------
    bool
    """
    try:
        import distributed  # noqa: F401  (optional: the [dask] extra)
    except ImportError:
        return False
    return True


@with_numerics_threads
def _call(case: dict, fn: Callable, shared: dict):
    try:
        return fn(case, **shared)
    except Exception as exc:  # a failed case is recorded, not lost
        return CaseError(dict(case), f"{type(exc).__name__}: {exc}")


def run_cases(fn: Callable, cases: Sequence[dict], *, shared: dict | None = None,
              workers: int | None = None, scheduler: str | None = None,
              progress: bool = False, description: str = "cases",
              raise_errors: bool = False, on_done: Callable | None = None) -> list:
    """Run ``fn(case, **shared)`` for every case, serially or on Dask, in input order.

    Parameters
    ----------
    fn : callable
        A module-level (picklable) pure function.
    cases : sequence of dict
        One dict per case, the first argument of ``fn`` (picklable for Dask).
    shared : dict, optional
        Keyword arguments common to every case (sent once per worker).
    workers : int, optional
        Local Dask worker processes (one thread, one BLAS thread each); ``1`` runs serially.
        Default: serial below :data:`SERIAL_BELOW` cases or without dask, else one worker
        per core.
    scheduler : str, optional
        Address of a running Dask scheduler (``tcp://host:8786``); wins over ``workers``.
        Trusted: the cases run in its workers, and whoever can connect to it can run code
        there (secure it as Dask's documentation says, e.g. TLS).
    progress : bool
        A progress bar over the cases on stderr.
    description : str
        The bar's label.
    raise_errors : bool
        Re-raise the first failed case's error (as :class:`AmbsealError`) instead of
        recording it.
    on_done : callable, optional
        Called with ``(index, result)`` as each case finishes (serial: in order).

    Returns
    -------
    list
        One result per case, in input order; a :class:`CaseError` for a case that raised.

    Raises
    ------
    ConfigError
        ``scheduler`` or ``workers > 1`` without dask installed, or a scheduler that cannot
        be reached or does not answer within :data:`SCHEDULER_TIMEOUT_S`.
    """

    shared = dict(shared or {})
    cases = list(cases)
    distributed = scheduler is not None or (workers is not None and workers > 1) or (
        workers is None and len(cases) >= SERIAL_BELOW and dask_available()
        and (os.cpu_count() or 1) > 1)
    if distributed and not dask_available():
        raise ConfigError("dask.distributed is not installed (pip install 'ambseal[dask]'); "
                          "leave out --scheduler/--workers to run serially")
    console = Console(stderr=True)
    # a bar is for a terminal: elsewhere rich leaves a blank line before the next message
    with Progress(console=console, disable=not (progress and console.is_terminal),
                  transient=True) as bar:
        task = bar.add_task(description, total=len(cases))

        def done(i: int, r) -> None:
            if raise_errors and isinstance(r, CaseError):
                raise AmbsealError(f"{description}: case {r.case}: {r.error}")
            bar.advance(task)
            if on_done is not None:
                on_done(i, r)

        if not distributed:
            out = []
            for i, case in enumerate(cases):
                out.append(_call(case, fn, shared))
                done(i, out[-1])
            return out
        return _run_dask(fn, cases, shared, workers, scheduler, done)


def probe_scheduler(address: str, timeout_s: float | None = None) -> None:
    """Check that a Dask scheduler at ``address`` connects and answers an ``identity``
    request within ``timeout_s`` (distributed's ``Client`` waits without end for the
    handshake of a peer that accepts a connection and never answers).

    Parameters
    ----------
    address : str
        The scheduler's address, e.g. ``tcp://host:8786``.
    timeout_s : float, optional
        The deadline of connecting and answering together (s); default
        :data:`SCHEDULER_TIMEOUT_S`.

    Raises
    ------
    ConfigError
        dask.distributed is not installed, or the address cannot be reached, does not
        answer in time or is no Dask scheduler; the message names the address.
    """
    if not dask_available():
        raise ConfigError("dask.distributed is not installed (pip install 'ambseal[dask]'); "
                          "leave out --scheduler to run serially")
    timeout_s = SCHEDULER_TIMEOUT_S if timeout_s is None else float(timeout_s)
    try:
        answer = asyncio.run(asyncio.wait_for(_identity(address, timeout_s), timeout_s))
    except (TimeoutError, asyncio.TimeoutError):
        raise ConfigError(f"dask scheduler {address!r}: no answer within {timeout_s:g} s "
                          "(is a Dask scheduler listening there?)") from None
    except Exception as exc:  # refused, unreachable, not an address, not Dask's protocol
        msg = str(exc).splitlines()[0] if str(exc) else type(exc).__name__
        raise ConfigError(f"dask scheduler {address!r}: cannot connect ({msg})") from None
    if not (isinstance(answer, dict) and answer.get("type") == "Scheduler"):
        raise ConfigError(f"dask scheduler {address!r}: the peer is not a Dask scheduler "
                          f"(it answered {str(answer)[:80]!r})")


async def _identity(address: str, timeout_s: float):
    """The answer of the peer at ``address`` to an ``identity`` request."""
    from distributed.comm import connect  # optional: the [dask] extra

    comm = await connect(address, timeout=timeout_s)
    try:
        await comm.write({"op": "identity", "reply": True})
        return await comm.read()
    finally:
        comm.abort()


def _run_dask(fn, cases, shared, workers, scheduler, done) -> list:
    """The Dask path of :func:`run_cases`: futures, as completed, gathered in input order."""
    import dask  # optional: the [dask] extra
    from distributed import Client, LocalCluster, as_completed  # optional, as above

    cluster = scratch = None
    try:
        if scheduler is not None:
            probe_scheduler(scheduler)
            deadline = f"{SCHEDULER_TIMEOUT_S:g}s"  # distributed's own, for what follows
            with dask.config.set({"distributed.comm.timeouts.connect": deadline}):
                client = Client(scheduler, timeout=deadline)
        else:
            n = workers or (os.cpu_count() or 1)
            # Linux: workers forked by a fork server, a single-threaded process that has
            # imported ambseal's numerics once (spawned workers import them each: about
            # 3 s of a 2-core machine per worker before the first case). Not forked from
            # this process: it runs threads (Dask's, a caller's), and a fork that catches
            # one holding a lock (a logging stream's) hangs the worker for good.
            # Elsewhere dask's default (spawn).
            method = "forkserver" if sys.platform.startswith("linux") else "spawn"
            if method == "forkserver":
                multiprocessing.get_context("forkserver").set_forkserver_preload(
                    ["ambseal.analysis.cases"])
            scratch = tempfile.mkdtemp(prefix="ambseal-dask-")  # 0700, a fresh name
            with dask.config.set({"distributed.worker.multiprocessing-method": method,
                                  "distributed.scheduler.http.routes": [],
                                  "distributed.worker.http.routes": []}):
                cluster = LocalCluster(
                    n_workers=n, threads_per_worker=1, processes=True, security=True,
                    dashboard_address=None, local_directory=scratch,
                    scheduler_kwargs={"dashboard_address": "127.0.0.1:0"},
                    env={v: "1" for v in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS",
                                          "MKL_NUM_THREADS")})
            cluster.scheduler.http_server.stop()  # Dask starts one even without a dashboard
            client = Client(cluster)
            client.run(_stop_http)
    except OSError as exc:
        raise ConfigError(f"dask scheduler {scheduler!r}: cannot connect ({exc})") from None
    try:
        # nothing to send: Dask's scatter of an empty dict fails
        shared_f = client.scatter(shared, broadcast=True) if shared else {}
        futures = client.map(_call, cases, fn=fn, shared=shared_f, pure=False)
        index = {f.key: i for i, f in enumerate(futures)}
        for f in as_completed(futures):
            done(index[f.key], f.result())
        return client.gather(futures)
    finally:
        client.close()
        if cluster is not None:
            cluster.close()
        if scratch is not None:
            shutil.rmtree(scratch, ignore_errors=True)


def _stop_http(dask_worker) -> None:
    """Stop a worker's HTTP server (it serves no routes: nothing to listen for)."""
    dask_worker.http_server.stop()
