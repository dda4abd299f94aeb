"""MATLAB files (level 5 / v7) read where a malformed one cannot take ambseal down.

scipy's reader (:func:`scipy.io.loadmat`, compiled) ends the whole process with a
segmentation fault on some malformed files — a few bytes changed in a valid file were
enough (scipy 1.17: 6 of 300 files with random bytes spliced in or overwritten). So
:func:`read_matlab` runs it in a child process (forked on Linux: scipy is loaded already,
a few milliseconds) under a time limit, and hands back plain values only: numeric and
text arrays, and the field names of a struct or the text of a cell array — never an
object scipy built from the file. A crash, a hang or an unreadable file is one
:class:`~ambseal.errors.DataError` naming the file.

Records (:mod:`ambseal.identify.records.data`) and controller files (:mod:`ambseal.export.controller_files`)
read their ``.mat`` form through it.
"""

from __future__ import annotations

import faulthandler
import multiprocessing
import sys
from pathlib import Path

import numpy as np
import scipy.io

from ambseal.errors import AmbsealError, DataError
from ambseal.files import input_file

__all__ = ["read_matlab", "READ_TIMEOUT_S"]

#: The longest a MATLAB file may take to read (s): scipy reads ~100 MB/s, so a record of
#: hours at 10 kHz fits; beyond it the reader is taken to hang on a malformed file.
READ_TIMEOUT_S = 120.0


def _plain(v) -> tuple[str, object]:
    """One variable as ``("struct", field names)``, ``("cells", texts)`` or
    ``("array", ndarray)`` (numbers or text, a plain ndarray)."""
    if v.dtype.names is not None:
        return "struct", list(v.dtype.names)
    if v.dtype == object:
        return "cells", [str(np.ravel(x)[0]) if np.size(x) else "" for x in np.ravel(v)]
    return "array", np.array(v)


def _child(path: str, conn, kwargs: dict) -> None:

    faulthandler.disable()  # a crash is the parent's to report, in one line
    try:
        raw = scipy.io.loadmat(path, **kwargs)
        conn.send(("ok", {k: _plain(v) for k, v in raw.items() if not k.startswith("__")}))
    except NotImplementedError:
        conn.send(("v7.3", ""))
    except BaseException as exc:  # the parent reports it; the child only ends
        conn.send(("error", f"{type(exc).__name__}: {exc}"))
    finally:
        conn.close()


def read_matlab(path: str | Path, timeout_s: float = READ_TIMEOUT_S,
                **loadmat_kwargs) -> dict[str, tuple[str, object]]:
    """The variables of a MATLAB file, read by :func:`scipy.io.loadmat` in a child process.

    Parameters
    ----------
    path : str or Path
        A level 5 / v7 MAT file.
    timeout_s : float
        The longest the read may take (s).
    **loadmat_kwargs
        Passed to :func:`scipy.io.loadmat` (``squeeze_me``, ``chars_as_strings``, ...).

    Returns
    -------
    dict
        ``{name: (kind, value)}``: ``("array", ndarray)`` of numbers or text,
        ``("cells", list of str)`` for a cell array (the first element of each cell, as
        text) and ``("struct", list of field names)`` for a struct; MATLAB's own header
        entries (``__header__``, ...) left out.

    Raises
    ------
    DataError
        MATLAB v7.3 (HDF5), an unreadable or malformed file, not a regular file or one
        above :data:`ambseal.files.MAX_READ_BYTES`, or a reader that crashed or ran past
        ``timeout_s``; the message names the file.
    """

    try:  # a device, a FIFO or a file beyond any record: refused before the child reads it
        input_file(path, "MATLAB file")
    except AmbsealError as exc:
        raise DataError(str(exc)) from None
    method = "fork" if sys.platform.startswith("linux") else "spawn"  # fork is unsafe on macOS
    ctx = multiprocessing.get_context(method)
    recv, send = ctx.Pipe(duplex=False)
    proc = ctx.Process(target=_child, args=(str(path), send, loadmat_kwargs), daemon=True)
    proc.start()
    send.close()
    try:
        if not recv.poll(timeout_s):
            proc.kill()
            raise DataError(f"{path}: not a readable MATLAB file (reading took more than "
                            f"{timeout_s:g} s: malformed?)")
        kind, value = recv.recv()
    except (EOFError, ConnectionError):
        proc.join()
        raise DataError(f"{path}: not a readable MATLAB file (scipy's reader crashed on it, "
                        f"exit code {proc.exitcode}: malformed)") from None
    finally:
        recv.close()
        proc.join(timeout=5)
    if kind == "v7.3":
        raise DataError(f"{path}: MATLAB v7.3 (HDF5) files are not supported; save with -v7")
    if kind == "error":
        raise DataError(f"{path}: not a readable MATLAB file ({value})")
    return value
