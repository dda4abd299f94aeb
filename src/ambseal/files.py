"""Writing result files so that nothing already written is lost.

Every file ambseal writes goes to a temporary name in the target folder and is renamed
into place (``os.replace``, atomic on POSIX): a killed run leaves either the old file or
the new one, never half of one.

An output folder (``--out``) is ambseal's only as far as its ``manifest.json`` says: the
manifest lists the files (and folders) ambseal made there. A command writes into a folder
that is new, empty, or holds nothing but what its manifest lists; a folder with anything
else in it (a user's notes beside an earlier ``metrics.json``, a folder that never was an
output) is refused before any work, and nothing that is not listed is ever replaced or
removed (:class:`RunFolder`, :class:`OwnedFolder`).
"""

from __future__ import annotations

import ctypes
import datetime
import fcntl
import hashlib
import json
import os
import re
import shutil
import stat
import sys
import tempfile
import tomllib
import uuid
from pathlib import Path
from typing import Any, BinaryIO, Callable

from ambseal.errors import AmbsealError

__all__ = ["atomic_write", "writable_folder", "input_file", "MAX_READ_BYTES", "read_text",
           "load_toml", "write_text", "write_json", "RunFolder", "check_manifest",
           "write_manifest", "OwnedFolder", "foreign_entries", "claim_file", "stamp_text",
           "stamp_holds", "STAMP_KEY"]


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


#: The largest file ambseal reads (bytes): a record of the most samples an excitation may
#: have (``ambseal.identify.excitation.signals.MAX_SAMPLES``, 2e6) with 16 columns of 25 characters
#: is 0.8 GB of CSV; anything larger is no input of ambseal's and would only exhaust memory.
MAX_READ_BYTES = 2**30


def input_file(path: str | os.PathLike, what: str = "file") -> Path:
    """``path`` checked before it is read: a regular file (not a device such as
    ``/dev/zero``, a FIFO or a folder) of at most :data:`MAX_READ_BYTES`.

    Parameters
    ----------
    path : str or os.PathLike
        The file to read.
    what : str
        What it is, for the message ("rig file", "identification").

    Returns
    -------
    Path

    Raises
    ------
    AmbsealError
        One line naming the file: missing, not a regular file, or too large.
    """
    path = Path(path)
    try:
        st = path.stat()
    except OSError as exc:
        raise AmbsealError(f"{path}: cannot read {what} ({exc.strerror or exc})") from None
    if not stat.S_ISREG(st.st_mode):
        raise AmbsealError(f"{path}: {what}: not a regular file (a device, a pipe or a "
                           "folder is not read)")
    if st.st_size > MAX_READ_BYTES:
        raise AmbsealError(f"{path}: {what}: {st.st_size} bytes, expected at most "
                           f"{MAX_READ_BYTES} bytes")
    return path


def read_text(path: str | os.PathLike, what: str = "file") -> str:
    """The UTF-8 text of ``path`` (a byte-order mark is dropped), checked by
    :func:`input_file` before it is read.

    Raises
    ------
    AmbsealError
        One line naming the file: it cannot be read, is not a regular file, is larger
        than :data:`MAX_READ_BYTES`, or is not UTF-8 text.
    """
    path = input_file(path, what)
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


# --- one output file ------------------------------------------------------------------

#: ambseal's mark on a file it writes on its own, beside the SHA-256 of what it wrote: the
#: first line of a text file (a rig from ``import-ross``: ``<comment> ambseal-sha256:
#: <hash of the lines below>``), a record's sidecar key, a figure's PNG text key.
STAMP_KEY = "ambseal-sha256"
_STAMP = re.compile(rb"^\S{1,3} " + STAMP_KEY.encode() + rb": ([0-9a-f]{64})[^\n]*\n")


def stamp_text(text: str, comment: str = "#") -> str:
    """``text`` after a first line ``<comment> ambseal-sha256: <hex>``, the SHA-256 of the
    UTF-8 ``text``: the mark by which ambseal knows the file as its own and unchanged
    (:func:`stamp_holds`)."""
    digest = hashlib.sha256(text.encode("utf-8")).hexdigest()
    return f"{comment} {STAMP_KEY}: {digest}\n{text}"


def stamp_holds(path: str | os.PathLike) -> bool:
    """True if ``path`` is a regular file that :func:`stamp_text` made and nobody changed
    since (its first line's hash is the hash of the rest)."""
    try:
        data = input_file(path).read_bytes()
    except (AmbsealError, OSError):
        return False
    m = _STAMP.match(data)
    return m is not None and hashlib.sha256(data[m.end():]).hexdigest() == m.group(1).decode()


def claim_file(path: str | os.PathLike, *, force: bool = False,
               ours: Callable[[Path], bool] = stamp_holds) -> Path:
    """``path`` checked before a command writes it as one file (a rig, a record, a figure).

    The rule of every output of ambseal: it writes a path that does not exist, or one that
    it wrote itself and nobody changed since (``ours(path)``: the file's own mark — the
    stamp of :func:`stamp_text`, a record's sidecar, a figure's PNG text), or any regular
    file or symbolic link when the user passes ``--force`` (a link is then replaced, never
    written through: :func:`atomic_write` renames over it).

    Parameters
    ----------
    path : str or os.PathLike
        The file to write.
    force : bool
        The user's ``--force``.
    ours : callable
        ``ours(path) → bool``, whether ambseal wrote the existing file (default
        :func:`stamp_holds`).

    Returns
    -------
    Path

    Raises
    ------
    AmbsealError
        One line naming the path and the way out: it exists and is not ambseal's (or was
        changed), it is a symbolic link, or it is a folder or another non-file.
    """
    path = Path(path)
    if not os.path.lexists(path):
        return path
    if path.is_symlink():
        if force:
            return path
        raise AmbsealError(f"{path}: is a symbolic link; ambseal does not write through "
                           "links: choose a new name, or pass --force to replace the link "
                           "(not its target)")
    if not path.is_file():
        raise AmbsealError(f"{path}: exists and is not a file; choose a new name")
    if force or ours(path):
        return path
    raise AmbsealError(f"{path}: exists and ambseal did not write it (or it was changed "
                       "since); choose a new name, or pass --force to replace it")


# --- one output folder = one run -------------------------------------------------------

#: Free space (bytes) a run needs in its output folder's file system, checked before any
#: work: the test rig's complete output (figures, controllers, report) is about 4 MB; 50 MB
#: leaves room for larger rigs and the staging copy beside the old output.
MIN_FREE_BYTES = 50 * 2**20
MANIFEST = "manifest.json"
#: The lock of an :class:`OwnedFolder`, inside it (ambseal's, never listed or refused).
FOLDER_LOCK = ".ambseal.lock"
_RENAME_EXCHANGE = 2  # linux/fs.h
_AT_FDCWD = -100


def _open_lock(path: Path, fail) -> int:
    """The lock file's descriptor, created exclusively or opened, never through a symbolic
    link; ``fail(what, exc)`` makes the error."""
    flags = os.O_RDWR | os.O_CLOEXEC | os.O_NOFOLLOW
    try:
        try:
            return os.open(path, flags | os.O_CREAT | os.O_EXCL, 0o644)
        except FileExistsError:
            return os.open(path, flags)
    except OSError as exc:
        if os.path.islink(path):
            raise AmbsealError(f"{path}: the lock file is a symbolic link; ambseal does not "
                               "write through links: remove it") from None
        raise fail("create its lock", exc) from None


def _exchange(a: Path, b: Path) -> bool:
    """Swap two directories atomically (Linux renameat2 RENAME_EXCHANGE); False if the
    system cannot."""

    try:
        fn = ctypes.CDLL(None, use_errno=True).renameat2
    except (AttributeError, OSError):
        return False
    fn.argtypes = [ctypes.c_int, ctypes.c_char_p, ctypes.c_int, ctypes.c_char_p, ctypes.c_uint]
    return fn(_AT_FDCWD, os.fsencode(a), _AT_FDCWD, os.fsencode(b), _RENAME_EXCHANGE) == 0


#: The temporary name of :func:`atomic_write` (``tempfile.mkstemp``'s 8 random characters):
#: a write killed half-way leaves one; it is ambseal's, not a user's file.
_TEMPORARY = re.compile(r"\..+\.[a-z0-9_]{8}\.tmp")


def _read_manifest(folder: Path) -> dict | None:
    """The manifest of ``folder``: ``{"files": {path: sha256}, "folders": [path]}``, or None
    when there is none or it is not one ambseal wrote."""
    try:
        man = json.loads((folder / MANIFEST).read_text(encoding="utf-8"))
        files, folders = man["files"], man.get("folders", [])
    except (OSError, ValueError, KeyError, TypeError, AttributeError, RecursionError):
        return None
    if not (isinstance(files, dict) and isinstance(folders, list)
            and all(isinstance(k, str) for k in [*files, *folders])):
        return None
    return {"files": files, "folders": folders}


def _listed(man: dict | None) -> tuple[set[str], set[str]]:
    """(files, folders) a manifest lists; the folders holding a listed file included."""
    if man is None:
        return set(), set()
    files, folders = set(man["files"]), set(man["folders"])
    for f in files:
        parts = f.split("/")[:-1]
        folders.update("/".join(parts[:i]) for i in range(1, len(parts) + 1))
    return files, folders


def foreign_entries(folder: str | os.PathLike) -> list[str]:
    """What ``folder`` holds that its manifest does not list (folders end in ``/``).

    A folder without a valid ``manifest.json`` owns nothing: everything in it is foreign
    (the manifest too). Temporary files of a killed write are not counted. Folders that are
    not listed are not searched further.

    Parameters
    ----------
    folder : path
        An existing folder.

    Returns
    -------
    list of str
        Paths relative to ``folder``, sorted; empty when ambseal may write there.
    """
    folder = Path(folder)
    man = _read_manifest(folder)
    files, folders = _listed(man)
    out: list[str] = []

    def walk(path: str, rel: str) -> None:
        with os.scandir(path) as entries:
            for e in sorted(entries, key=lambda e: e.name):
                r = rel + e.name
                if (not rel and (e.name == FOLDER_LOCK or e.name == MANIFEST and man)) or \
                        _TEMPORARY.fullmatch(e.name):
                    continue
                if e.is_dir(follow_symlinks=False):
                    if r in folders:
                        walk(e.path, r + "/")
                    else:
                        out.append(r + "/")
                elif not (r in files and e.is_file(follow_symlinks=False)):
                    out.append(r)

    walk(str(folder), "")
    return out


def _not_ours(folder: Path, extra: list[str]) -> AmbsealError:
    names = ", ".join(extra[:3]) + (f" and {len(extra) - 3} more" if len(extra) > 3 else "")
    return AmbsealError(f"{folder}: not an ambseal output folder, or it holds files ambseal "
                        f"did not write ({names}); ambseal replaces only the files its "
                        f"{MANIFEST} lists: move those elsewhere or choose an empty or new "
                        "--out")


def _file_hash(path: Path) -> str:
    h = hashlib.sha256()
    with open(path, "rb") as fh:
        for block in iter(lambda: fh.read(1 << 20), b""):
            h.update(block)
    return h.hexdigest()


def write_manifest(folder: Path, run_id: str, keep=None) -> Path:
    """Write ``manifest.json``: the run id, the SHA-256 of every file in ``folder`` and its
    sub-folders, and the sub-folders (only the paths that ``keep(relative_path)`` accepts,
    when given)."""

    paths = [p for p in sorted(folder.rglob("*")) if p.name not in (MANIFEST, FOLDER_LOCK)
             and not _TEMPORARY.fullmatch(p.name) and not p.is_symlink()
             and (keep is None or keep(p.relative_to(folder).as_posix()))]
    files = {p.relative_to(folder).as_posix(): _file_hash(p) for p in paths if p.is_file()}
    folders = [p.relative_to(folder).as_posix() for p in paths if p.is_dir()]
    stamp = datetime.datetime.now(datetime.timezone.utc).isoformat(timespec="seconds")
    return write_json(folder / MANIFEST, {"run_id": run_id, "finished_utc": stamp,
                                          "files": files, "folders": folders})


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
    present = {p.relative_to(folder).as_posix() for p in folder.rglob("*") if p.is_file()
               and p.name not in (MANIFEST, FOLDER_LOCK) and not _TEMPORARY.fullmatch(p.name)}
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
    ``out`` keeps the former run's complete set. ``out`` may be replaced only when it holds
    nothing but the files of its manifest (a file that appears there during the run is
    moved into the new set, not lost).

    Raises
    ------
    AmbsealError
        The folder cannot be created or written, the disk is full, another run holds the
        lock, or ``out`` holds files its manifest does not list.
    """

    def __init__(self, out: str | os.PathLike):
        self.out = Path(out).absolute()
        name = self.out.name
        self.parent = self.out.parent
        self.lock_path = self.parent / f".{name}.lock"
        self.stage = self.parent / f".{name}.staging-{os.getpid()}"
        self.old = self.parent / f".{name}.old-{os.getpid()}"
        self._lock_fd: int | None = None
        self.stale_pid: int | None = None
        self.stale_since = 0.0

    def _fail(self, what: str, exc: OSError) -> AmbsealError:
        return AmbsealError(f"{self.out}: cannot {what} ({exc.strerror or exc})")

    def _lock(self) -> None:
        """Take the lock file: created or opened without following a symbolic link
        (``O_NOFOLLOW``: a link planted there is refused, its target never touched), then
        ``flock``; a lock left by a process that is gone (``kill -9``) is taken over with a
        note on stderr. The lock file holds the owner's pid and is removed on release."""
        try:
            self.parent.mkdir(parents=True, exist_ok=True)
        except OSError as exc:
            raise self._fail("create the output folder", exc) from None
        for _ in range(8):  # the file may be removed by its owner between open and flock
            fd = _open_lock(self.lock_path, self._fail)
            try:
                fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
            except OSError:
                owner = os.pread(fd, 32, 0).decode("ascii", "replace").strip() or "?"
                os.close(fd)
                raise AmbsealError(f"{self.out}: another ambseal run (pid {owner}) is writing "
                                   "this folder; wait for it or choose another --out") from None
            try:
                same = os.fstat(fd).st_ino == os.stat(self.lock_path,
                                                      follow_symlinks=False).st_ino
            except OSError:
                same = False
            if same:
                break
            os.close(fd)  # locked a file its owner had just removed: take the new one
        else:
            raise AmbsealError(f"{self.lock_path}: the lock keeps changing hands; try again")
        previous = os.pread(fd, 32, 0).decode("ascii", "replace").split()
        self.stale_since = os.fstat(fd).st_mtime  # when the former owner took it
        self.stale_pid = int(previous[0]) if previous and previous[0].isdigit() \
            and int(previous[0]) != os.getpid() else None
        if self.stale_pid is not None:
            print(f"ambseal: note: {self.out}: took over the lock of pid {self.stale_pid}, "
                  "which is no longer running", file=sys.stderr)
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
            self._check_ours()
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
            moved: list = []
            try:
                write_manifest(self.stage, uuid.uuid4().hex)
                self._keep_foreign(moved)
                if not self.out.exists():
                    os.rename(self.stage, self.out)
                elif _exchange(self.stage, self.out):
                    shutil.rmtree(self.stage, ignore_errors=True)
                else:
                    os.rename(self.out, self.old)
                    os.rename(self.stage, self.out)
                    shutil.rmtree(self.old, ignore_errors=True)
            except (OSError, AmbsealError) as exc:
                for src, dst in reversed(moved):  # the user's files back where they were
                    os.rename(dst, src)
                shutil.rmtree(self.stage, ignore_errors=True)
                if isinstance(exc, AmbsealError):
                    raise
                raise self._fail("replace the output folder", exc) from None
        finally:
            self._unlock()

    def _check_ours(self, adopted: frozenset = frozenset()) -> None:
        """AmbsealError unless ``out`` is new, or a folder of nothing but its manifest's
        (and the ``adopted`` entries)."""
        if not os.path.lexists(self.out):
            return
        if self.out.is_symlink() or not self.out.is_dir():
            raise AmbsealError(f"{self.out}: exists and is not a folder; choose an empty or "
                               "new --out")
        try:
            extra = [e for e in foreign_entries(self.out) if e.rstrip("/") not in adopted]
        except OSError as exc:
            raise self._fail("read the output folder", exc) from None
        if extra:
            raise _not_ours(self.out, extra)

    def _keep_foreign(self, moved: list) -> None:
        """Move what appeared in ``out`` during the run (not in its manifest) into the
        staging folder, so that replacing ``out`` loses none of it; ``moved`` gets each
        (source, destination) as it is moved."""
        if not self.out.is_dir():
            return
        moves = [(self.out / rel.rstrip("/"), self.stage / rel.rstrip("/"))
                 for rel in foreign_entries(self.out)]
        for src, dst in moves:  # all checked before the first is moved
            if os.path.lexists(dst):
                raise AmbsealError(f"{src}: appeared during the run and has the name of one "
                                   f"of its files; {self.out} keeps the former output")
        for src, dst in moves:
            dst.parent.mkdir(parents=True, exist_ok=True)
            os.rename(src, dst)
            moved.append((src, dst))

    def _unlock(self) -> None:
        """Release the lock and remove its file (while holding it, and only the file this
        process locked): nothing is left beside or in the output."""
        if self._lock_fd is not None:
            try:
                if os.fstat(self._lock_fd).st_ino == os.stat(
                        self.lock_path, follow_symlinks=False).st_ino:
                    os.unlink(self.lock_path)
            except OSError:
                pass
            os.close(self._lock_fd)
            self._lock_fd = None


class OwnedFolder(RunFolder):
    """An output folder that a command writes file by file (``design``, ``export``,
    ``identify``, ``track``, ``campbell``, ``sweep``).

    ``with OwnedFolder(out) as folder:`` refuses a folder that holds anything its manifest
    does not list, creates ``out`` if needed, takes the lock :data:`FOLDER_LOCK` inside it
    (a second command into the same folder is refused) and checks that a file can be
    written there, all before any work. On leaving (after an error too) the manifest lists
    what it listed before and is still there, and every file made during the command;
    nothing else in the folder is touched. A folder that was created and got nothing is
    removed again.

    Raises
    ------
    AmbsealError
        The folder cannot be created or written, another command holds the lock, or the
        folder holds files its manifest does not list.
    """

    def __init__(self, out: str | os.PathLike):
        super().__init__(out)
        self.lock_path = self.out / FOLDER_LOCK

    def _entries(self) -> set[str]:
        return {p.relative_to(self.out).as_posix() for p in self.out.rglob("*")} - {
            FOLDER_LOCK}

    def __enter__(self) -> Path:
        # with a lock left there, perhaps a killed command's (see below); a link is refused
        if self.out.is_symlink() or not os.path.lexists(self.lock_path):
            self._check_ours()
        self._created = not self.out.exists()
        try:
            self.out.mkdir(parents=True, exist_ok=True)
        except OSError as exc:
            raise self._fail("create the output folder", exc) from None
        self._lock()
        try:
            adopted = self._killed_outputs()
            self._check_ours(adopted)  # again, under the lock
            writable_folder(self.out)
            self._before = self._entries()
            self._listed = set().union(*_listed(_read_manifest(self.out))) | adopted
        except BaseException:
            self._release()
            raise
        return self.out

    def _killed_outputs(self) -> frozenset:
        """The entries a command killed in this folder left (its lock, now taken over, was
        still there): those not in the manifest that changed after it took the lock. They
        are ambseal's partial outputs, replaced by this command (noted on stderr)."""
        if self.stale_pid is None:
            return frozenset()
        try:
            rel = [e.rstrip("/") for e in foreign_entries(self.out)]
            out = frozenset(e for e in rel if os.lstat(self.out / e).st_mtime
                            >= self.stale_since - 1.0)
        except OSError:
            return frozenset()
        if out:
            print(f"ambseal: note: {self.out}: {', '.join(sorted(out))}: left by the killed "
                  f"command (pid {self.stale_pid}); taken as ambseal's", file=sys.stderr)
        return out

    def __exit__(self, kind, exc, tb) -> None:

        try:
            mine = self._listed | (self._entries() - self._before)
            if not (self._created and not self._entries()):
                write_manifest(self.out, uuid.uuid4().hex, keep=mine.__contains__)
        except OSError as exc:
            if kind is None:
                raise self._fail("write its manifest", exc) from None
        finally:
            self._release()

    def _release(self) -> None:
        """Unlock; a folder made for nothing is removed again, with its lock."""
        try:
            empty = self._created and not self._entries()
        except OSError:
            empty = False
        self._unlock()  # removes the lock file too
        if empty:
            try:
                self.out.rmdir()
            except OSError:  # something appeared meanwhile: left as it is
                pass
