"""Writing result files so that nothing already written is lost.

Every file ambseal writes goes to a temporary name in the target folder and is renamed
into place (``os.replace``, atomic on POSIX): a killed run leaves either the old file or
the new one, never half of one.
"""

from __future__ import annotations

import json
import os
import tempfile
from pathlib import Path
from typing import Any, BinaryIO, Callable

from .errors import AmbsealError

__all__ = ["atomic_write", "write_text", "write_json"]


def atomic_write(path: str | os.PathLike, write: Callable[[BinaryIO], Any]) -> Path:
    """Call ``write(fh)`` on a temporary binary file beside ``path``, then rename it.

    The file gets mode 0644 (results are meant to be shared).

    Raises
    ------
    AmbsealError
        If the folder does not exist.
    """
    path = Path(path)
    if not path.parent.is_dir():
        raise AmbsealError(f"{path}: folder {str(path.parent)!r} does not exist")
    fd, tmp = tempfile.mkstemp(prefix=f".{path.name}.", suffix=".tmp", dir=path.parent)
    try:
        with os.fdopen(fd, "wb") as fh:
            write(fh)
        os.chmod(tmp, 0o644)
        os.replace(tmp, path)
    except BaseException:
        if os.path.exists(tmp):
            os.unlink(tmp)
        raise
    return path


def write_text(path: str | os.PathLike, text: str) -> Path:
    """Write UTF-8 text atomically."""
    return atomic_write(path, lambda fh: fh.write(text.encode("utf-8")))


def write_json(path: str | os.PathLike, data: Any) -> Path:
    """Write JSON (indented, no NaN or inf allowed) atomically."""
    return write_text(path, json.dumps(data, indent=2, allow_nan=False) + "\n")
