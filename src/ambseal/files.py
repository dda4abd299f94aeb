"""Writing result files so that nothing already written is lost.

Every file ambseal writes goes to a temporary name in the target folder and is renamed
into place (``os.replace``, atomic on POSIX): a killed run leaves either the old file or
the new one, never half of one.
"""

from __future__ import annotations

import ctypes
import datetime
import fcntl
import hashlib
import json
import os
import shutil
import tempfile
import tomllib
import uuid
from pathlib import Path
from typing import Any, BinaryIO, Callable

from ambseal.errors import AmbsealError

__all__ = ["atomic_write", "writable_folder", "read_text", "load_toml", "write_text", "write_json", "RunFolder", "check_manifest",
           "write_manifest"]


def atomic_write(path: str | os.PathLike, write: Callable[[BinaryIO], Any]) -> Path:
    """Call ``write(fh)`` on a temporary binary file beside ``path``, then rename it.

    The file gets mode 0644 (results are meant to be shared).

    Raises
    ------
    AmbsealError
        If the folder does not exist or the file cannot be written (no permission, disk
        full); the former file is kept.
    """
    path = Path(path)
    if not path.parent.is_dir():
        raise AmbsealError(f"{path}: folder {str(path.parent)!r} does not exist")
    try:
        fd, tmp = tempfile.mkstemp(prefix=f".{path.name}.", suffix=".tmp", dir=path.parent)
    except OSError as exc:
        raise AmbsealError(f"{path}: cannot write ({exc.strerror or exc})") from None
    try:
        with os.fdopen(fd, "wb") as fh:
            write(fh)
        os.chmod(tmp, 0o644)
        os.replace(tmp, path)
    except BaseException as exc:
        if os.path.exists(tmp):
            os.unlink(tmp)
        if isinstance(exc, OSError):  # a full disk, a folder gone read-only
            raise AmbsealError(f"{path}: cannot write ({exc.strerror or exc})") from None
        raise
    return path


def writable_folder(folder: str | os.PathLike) -> Path:
    """Create ``folder`` if needed and check that a file can be written there, before any
    work is done; AmbsealError (one line naming the folder) otherwise."""
    folder = Path(folder)
    try:
        folder.mkdir(parents=True, exist_ok=True)
        fd, probe = tempfile.mkstemp(prefix=".ambseal-probe.", dir=folder)
        os.close(fd)
        os.unlink(probe)
    except OSError as exc:
        raise AmbsealError(f"{folder}: cannot write there ({exc.strerror or exc})") from None
    return folder


def read_text(path: str | os.PathLike, what: str = "file") -> str:
    """The UTF-8 text of ``path`` (a byte-order mark is dropped).

    Raises
    ------
    AmbsealError
        One line naming the file: it cannot be read, or is not UTF-8 text.
    """
    path = Path(path)
    try:
        return path.read_text(encoding="utf-8-sig")
    except UnicodeDecodeError as exc:
        raise AmbsealError(f"{path}: not UTF-8 text ({exc.reason} at byte {exc.start}); "
                           f"save the {what} as UTF-8") from None
    except OSError as exc:
        raise AmbsealError(f"{path}: cannot read {what} ({exc.strerror or exc})") from None


def load_toml(path: str | os.PathLike, what: str = "file") -> dict:
    """Parse a TOML file read by :func:`read_text`; AmbsealError (one line naming the
    file) if it is not valid TOML or nested too deeply to read."""

    text = read_text(path, what)
    try:
        return tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise AmbsealError(f"{path}: not valid TOML ({exc})") from None
    except RecursionError:
        raise AmbsealError(f"{path}: not a {what}: values nested too deeply") from None


def write_text(path: str | os.PathLike, text: str) -> Path:
    """Write UTF-8 text atomically."""
    return atomic_write(path, lambda fh: fh.write(text.encode("utf-8")))


def write_json(path: str | os.PathLike, data: Any) -> Path:
    """Write JSON (indented, no NaN or inf allowed) atomically."""
    return write_text(path, json.dumps(data, indent=2, allow_nan=False) + "\n")


# --- one output folder = one run -------------------------------------------------------

#: Free space (bytes) a run needs in its output folder's file system, checked before any
#: work: the test rig's complete output (figures, controllers, report) is about 4 MB; 50 MB
#: leaves room for larger rigs and the staging copy beside the old output.
MIN_FREE_BYTES = 50 * 2**20
MANIFEST = "manifest.json"
_RENAME_EXCHANGE = 2  # linux/fs.h
_AT_FDCWD = -100


def _pid_alive(pid: int) -> bool:
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:
        return True
    return True


def _exchange(a: Path, b: Path) -> bool:
    """Swap two directories atomically (Linux renameat2 RENAME_EXCHANGE); False if the
    system cannot."""

    try:
        fn = ctypes.CDLL(None, use_errno=True).renameat2
    except (AttributeError, OSError):
        return False
    fn.argtypes = [ctypes.c_int, ctypes.c_char_p, ctypes.c_int, ctypes.c_char_p, ctypes.c_uint]
    return fn(_AT_FDCWD, os.fsencode(a), _AT_FDCWD, os.fsencode(b), _RENAME_EXCHANGE) == 0


def _is_run_output(folder: Path) -> bool:
    """Whether ``folder`` is empty or holds a former run's output (its manifest or
    metrics.json), i.e. may be replaced as a whole."""
    names = {p.name for p in folder.iterdir()}
    return not names or MANIFEST in names or "metrics.json" in names


def _file_hash(path: Path) -> str:
    h = hashlib.sha256()
    with open(path, "rb") as fh:
        for block in iter(lambda: fh.read(1 << 20), b""):
            h.update(block)
    return h.hexdigest()


def write_manifest(folder: Path, run_id: str) -> Path:
    """Write ``manifest.json``: the run id and the SHA-256 of every file in ``folder``."""

    files = {p.relative_to(folder).as_posix(): _file_hash(p)
             for p in sorted(folder.rglob("*")) if p.is_file() and p.name != MANIFEST}
    stamp = datetime.datetime.now(datetime.timezone.utc).isoformat(timespec="seconds")
    return write_json(folder / MANIFEST, {"run_id": run_id, "finished_utc": stamp,
                                          "files": files})


def check_manifest(folder: str | os.PathLike) -> str:
    """The run id of a complete output folder.

    Raises
    ------
    AmbsealError
        No manifest, a file missing, changed or not listed (a mix of runs).
    """
    folder = Path(folder)
    try:
        man = json.loads((folder / MANIFEST).read_text(encoding="utf-8"))
        listed = dict(man["files"])
    except (OSError, ValueError, KeyError, TypeError) as exc:
        raise AmbsealError(f"{folder / MANIFEST}: not a complete run output ({exc})") from None
    present = {p.relative_to(folder).as_posix() for p in folder.rglob("*")
               if p.is_file() and p.name != MANIFEST}
    if present != set(listed):
        odd = sorted(present ^ set(listed))[0]
        raise AmbsealError(f"{folder}: {odd}: not part of run {man.get('run_id')}")
    for name, digest in listed.items():
        if _file_hash(folder / name) != digest:
            raise AmbsealError(f"{folder / name}: changed since run {man.get('run_id')}")
    return str(man["run_id"])


class RunFolder:
    """The output folder of one run, written as one unit.

    ``with RunFolder(out) as stage:`` takes the lock ``.<name>.lock`` beside ``out``
    (``flock``, holding the owner's pid; a second run into the same folder is refused),
    removes stale staging folders of killed runs, checks that the folder's file system is
    writable and has ``MIN_FREE_BYTES`` free, and gives a fresh staging folder beside
    ``out``. On success the manifest is written last and the staging folder replaces
    ``out`` by one atomic exchange of the two directories (Linux ``renameat2``; elsewhere
    two renames, and a run killed between them is repaired by the next); on error or kill
    ``out`` keeps the former run's complete set.

    Raises
    ------
    AmbsealError
        The folder cannot be created or written, the disk is full, another run holds the
        lock, or ``out`` holds files that are not an ambseal run's output.
    """

    def __init__(self, out: str | os.PathLike):
        self.out = Path(out).absolute()
        name = self.out.name
        self.parent = self.out.parent
        self.lock_path = self.parent / f".{name}.lock"
        self.stage = self.parent / f".{name}.staging-{os.getpid()}"
        self.old = self.parent / f".{name}.old-{os.getpid()}"
        self._lock_fd: int | None = None

    def _fail(self, what: str, exc: OSError) -> AmbsealError:
        return AmbsealError(f"{self.out}: cannot {what} ({exc.strerror or exc})")

    def _lock(self) -> None:
        try:
            self.parent.mkdir(parents=True, exist_ok=True)
            fd = os.open(self.lock_path, os.O_RDWR | os.O_CREAT, 0o644)
        except OSError as exc:
            raise self._fail("create the output folder", exc) from None
        try:
            fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except OSError:
            owner = os.pread(fd, 32, 0).decode("ascii", "replace").strip() or "?"
            os.close(fd)
            raise AmbsealError(f"{self.out}: another ambseal run (pid {owner}) is writing "
                               "this folder; wait for it or choose another --out") from None
        os.ftruncate(fd, 0)
        os.pwrite(fd, f"{os.getpid()}\n".encode(), 0)
        self._lock_fd = fd

    def _clean_stale(self) -> None:
        prefix = f".{self.out.name}."
        for p in self.parent.glob(prefix + "*"):
            kind, _, pid = p.name[len(prefix):].partition("-")
            if kind not in ("staging", "old") or not pid.isdigit() or not p.is_dir():
                continue
            if kind == "old" and not self.out.exists():
                os.rename(p, self.out)  # killed between the two renames: keep the old set
            else:
                shutil.rmtree(p, ignore_errors=True)

    def __enter__(self) -> Path:
        self._lock()
        try:
            self._clean_stale()
            if self.out.exists() and not (self.out.is_dir() and _is_run_output(self.out)):
                raise AmbsealError(f"{self.out}: exists and is not an ambseal output folder "
                                   "(no metrics.json or manifest.json); choose an empty or "
                                   "new --out")
            try:
                self.stage.mkdir()
                (self.stage / ".probe").write_bytes(b"0" * 4096)
                (self.stage / ".probe").unlink()
                free = shutil.disk_usage(self.stage).free
            except OSError as exc:
                shutil.rmtree(self.stage, ignore_errors=True)
                raise self._fail("write there", exc) from None
            if free < MIN_FREE_BYTES:
                shutil.rmtree(self.stage, ignore_errors=True)
                raise AmbsealError(f"{self.out}: only {free / 2**20:.1f} MB free on its disk; "
                                   f"a run needs about {MIN_FREE_BYTES / 2**20:.0f} MB")
        except BaseException:
            self._unlock()
            raise
        return self.stage

    def __exit__(self, kind, exc, tb) -> None:
        try:
            if kind is not None:
                shutil.rmtree(self.stage, ignore_errors=True)
                return
            try:
                write_manifest(self.stage, uuid.uuid4().hex)
                if not self.out.exists():
                    os.rename(self.stage, self.out)
                elif _exchange(self.stage, self.out):
                    shutil.rmtree(self.stage, ignore_errors=True)
                else:
                    os.rename(self.out, self.old)
                    os.rename(self.stage, self.out)
                    shutil.rmtree(self.old, ignore_errors=True)
            except OSError as exc:
                shutil.rmtree(self.stage, ignore_errors=True)
                raise self._fail("replace the output folder", exc) from None
        finally:
            self._unlock()

    def _unlock(self) -> None:
        if self._lock_fd is not None:
            os.close(self._lock_fd)
            self._lock_fd = None
