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
import secrets
import shutil
import stat
import sys
import tempfile
import threading
import tomllib
import uuid
from pathlib import Path
from typing import Any, BinaryIO, Callable

from ambseal.errors import AmbsealError

__all__ = ["atomic_write", "writable_folder", "input_file", "MAX_READ_BYTES", "read_text",
           "load_toml", "write_text", "write_json", "RunFolder", "check_manifest",
           "write_manifest", "OwnedFolder", "foreign_entries", "changed_entries",
           "claim_file", "stamp_text",
           "stamp_holds", "STAMP_KEY"]


def atomic_write(path: str | os.PathLike, write: Callable[[BinaryIO], Any]) -> Path:
    """Call ``write(fh)`` on a temporary binary file beside ``path``, then rename it.

    The file gets the mode the user's umask gives a new file (0644 under the usual 022):
    it is created with 0666 and the kernel applies the umask, as for any file a program
    writes.

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
        fd, tmp = _new_file(path)
    except OSError as exc:
        raise AmbsealError(f"{path}: cannot write ({exc.strerror or exc})") from None
    try:
        with os.fdopen(fd, "wb") as fh:
            write(fh)
        _journal(path, tmp)
        os.replace(tmp, path)
    except BaseException as exc:
        if os.path.exists(tmp):
            os.unlink(tmp)
        if isinstance(exc, OSError):  # a full disk, a folder gone read-only
            raise AmbsealError(f"{path}: cannot write ({exc.strerror or exc})") from None
        raise
    return path


def _new_file(path: Path) -> tuple[int, str]:
    """A new file beside ``path`` under a random name, opened for writing: created with
    0666 so that the user's umask sets its mode (``tempfile.mkstemp`` creates 0600)."""
    flags = os.O_WRONLY | os.O_CREAT | os.O_EXCL | os.O_CLOEXEC | os.O_NOFOLLOW
    for _ in range(100):
        tmp = str(path.parent / f".{path.name}.{secrets.token_hex(4)}.tmp")
        try:
            return os.open(tmp, flags, 0o666), tmp
        except FileExistsError:
            continue
    raise FileExistsError(f"no free temporary name beside {path}")


#: The folders whose writes are being recorded (:class:`OwnedFolder`, innermost last):
#: what ambseal writes there is what their manifests list, with the hash it was written with
_RECORDING: list = []
_RECORDING_LOCK = threading.Lock()


def _journal(path: Path, tmp: str) -> None:
    """Record a file about to be renamed to ``path`` (its bytes in ``tmp``) in each
    recording folder that holds it: in its lock file first (the journal a next command reads
    when this one is killed), then in memory."""
    with _RECORDING_LOCK:
        if not _RECORDING:
            return
        real = Path(os.path.realpath(path.parent)) / path.name
        owners = [(f, rel) for f in _RECORDING
                  for rel in [_relative(real, f.out)] if rel is not None]
        if owners:
            digest = _file_hash(Path(tmp))
            for folder, rel in owners:
                folder.record(rel, digest)


def _relative(path: Path, folder: Path) -> str | None:
    """``path`` relative to ``folder`` (POSIX form), None when it is not inside it."""
    try:
        return path.relative_to(folder).as_posix()
    except ValueError:
        return None


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
#: The mark of a :class:`RunFolder`'s staging folder while the run writes it: a stale
#: ``.<out>.staging-<pid>`` is removed only when it holds the mark (or is a complete set).
STAGING_MARK = ".ambseal-staging"
_RENAME_EXCHANGE = 2  # linux/fs.h
_AT_FDCWD = -100


def _open_lock(path: Path, fail) -> int:
    """The lock file's descriptor, created exclusively or opened, never through a symbolic
    link; ``fail(what, exc)`` makes the error."""
    flags = os.O_RDWR | os.O_CLOEXEC | os.O_NOFOLLOW
    try:
        try:
            return os.open(path, flags | os.O_CREAT | os.O_EXCL, 0o666)  # the umask sets it
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


#: The temporary name of :func:`atomic_write` (8 random characters, as ``tempfile``'s):
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
                if (not rel and (e.name in (FOLDER_LOCK, STAGING_MARK)
                                 or e.name == MANIFEST and man)) or \
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


def changed_entries(folder: str | os.PathLike, journal: dict | None = None) -> list[str]:
    """The files of ``folder``'s manifest whose bytes are no longer those ambseal wrote
    (SHA-256 against the manifest, or against ``journal``'s ``{path: sha256}`` of a killed
    command's writes): edited since, and so the user's.

    Parameters
    ----------
    folder : path
        An existing folder.
    journal : dict, optional
        Hashes a killed command recorded for the files it wrote (they count as ambseal's).

    Returns
    -------
    list of str
        Paths relative to ``folder``, sorted.
    """
    folder = Path(folder)
    man = _read_manifest(folder)
    out = []
    for rel, digest in sorted((man or {"files": {}})["files"].items()):
        p = folder / rel
        if not p.is_file() or p.is_symlink():
            continue  # gone, or no longer a file: foreign_entries names what is there
        try:
            now = _file_hash(p)
        except OSError:
            now = None
        if now not in (digest, (journal or {}).get(rel)):
            out.append(rel)
    return out


def _not_ours(folder: Path, extra: list[str], changed: list[str] = ()) -> AmbsealError:
    def names(xs):
        return ", ".join(xs[:3]) + (f" and {len(xs) - 3} more" if len(xs) > 3 else "")
    if not extra:
        return AmbsealError(f"{folder}: {names(list(changed))}: changed since ambseal wrote "
                            f"{'them' if len(changed) > 1 else 'it'}, so the user's; move "
                            "them elsewhere, choose another --out, or pass --force to "
                            "replace them")
    return AmbsealError(f"{folder}: not an ambseal output folder, or it holds files ambseal "
                        f"did not write ({names(extra)}); ambseal replaces only the files "
                        f"its {MANIFEST} lists: move those elsewhere or choose an empty or "
                        "new --out")


def _file_hash(path: Path) -> str:
    h = hashlib.sha256()
    with open(path, "rb") as fh:
        for block in iter(lambda: fh.read(1 << 20), b""):
            h.update(block)
    return h.hexdigest()


def write_manifest(folder: Path, run_id: str, files: dict | None = None,
                   folders: list | None = None) -> Path:
    """Write ``manifest.json``: the run id, the SHA-256 of every file in ``folder`` and its
    sub-folders, and the sub-folders; or exactly ``files`` (``{path: sha256}``, the hashes
    the files were written with) and ``folders`` when given, those still there."""

    if files is None:
        paths = [p for p in sorted(folder.rglob("*"))
                 if p.name not in (MANIFEST, FOLDER_LOCK, STAGING_MARK)
                 and not _TEMPORARY.fullmatch(p.name) and not p.is_symlink()]
        files = {p.relative_to(folder).as_posix(): _file_hash(p) for p in paths
                 if p.is_file()}
        folders = [p.relative_to(folder).as_posix() for p in paths if p.is_dir()]
    else:
        files = {r: d for r, d in sorted(files.items())
                 if (folder / r).is_file() and not (folder / r).is_symlink()}
        folders = sorted(r for r in folders or ()
                         if (folder / r).is_dir() and not (folder / r).is_symlink())
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


def _made_here(folder: Path) -> bool:
    """A killed run's staging or former folder is ambseal's: it holds :data:`STAGING_MARK`
    (a staging folder being written) or is a complete output (:func:`check_manifest`)."""
    mark = folder / STAGING_MARK
    if mark.is_file() and not mark.is_symlink():
        return True
    try:
        check_manifest(folder)
    except (AmbsealError, OSError):
        return False
    return True


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
    nothing but the files of its manifest as ambseal wrote them (a file that appears there
    during the run is moved into the new set, not lost; a listed file edited since is the
    user's: refused unless ``force``). A stale staging or former folder of a killed run
    (``.<name>.staging-<pid>``, ``.<name>.old-<pid>``) is removed only when its mark
    (:data:`STAGING_MARK`) or its complete manifest says ambseal made it.

    Parameters
    ----------
    out : path
        The output folder.
    force : bool
        Replace the listed files the user changed since ambseal wrote them.

    Raises
    ------
    AmbsealError
        The folder cannot be created or written, the disk is full, another run holds the
        lock, or ``out`` holds files its manifest does not list (or, without ``force``,
        listed files changed since).
    """

    def __init__(self, out: str | os.PathLike, force: bool = False):
        self.force = bool(force)
        self.out = Path(out).absolute()
        name = self.out.name
        self.parent = self.out.parent
        self.lock_path = self.parent / f".{name}.lock"
        self.stage = self.parent / f".{name}.staging-{os.getpid()}"
        self.old = self.parent / f".{name}.old-{os.getpid()}"
        self._lock_fd: int | None = None
        self.stale_pid: int | None = None
        self._previous = b""  # the lock file as a killed owner left it (its journal)
        self._keep_journal = False  # leave the lock file: it holds a killed owner's journal

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
                owner = (os.pread(fd, 32, 0).decode("ascii", "replace").split()
                         or ["?"])[0]
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
        self._previous = os.pread(fd, min(os.fstat(fd).st_size, MAX_READ_BYTES), 0)
        previous = self._previous[:32].decode("ascii", "replace").split()
        self.stale_pid = int(previous[0]) if previous and previous[0].isdigit() \
            and int(previous[0]) != os.getpid() else None
        if self.stale_pid is not None:
            print(f"ambseal: note: {self.out}: took over the lock of pid {self.stale_pid}, "
                  "which is no longer running", file=sys.stderr)
        os.ftruncate(fd, 0)
        head = f"{os.getpid()}\n".encode()
        os.pwrite(fd, head, 0)
        self._journal_end = len(head)
        self._lock_fd = fd

    def _clean_stale(self) -> None:
        """Remove the staging and former folders killed runs left beside ``out`` — only
        those ambseal's mark or complete manifest proves its own (names compared as
        strings: ``out`` may hold glob characters)."""
        prefix = f".{self.out.name}."
        with os.scandir(self.parent) as entries:
            stale = [Path(e.path) for e in entries if e.name.startswith(prefix)
                     and e.is_dir(follow_symlinks=False)]
        for p in stale:
            kind, _, pid = p.name[len(prefix):].partition("-")
            if kind not in ("staging", "old") or not pid.isdigit() or not _made_here(p):
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
                (self.stage / STAGING_MARK).write_bytes(f"{os.getpid()}\n".encode())
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
                (self.stage / STAGING_MARK).unlink()  # a complete set from here on
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

    def _check_ours(self, adopted: frozenset = frozenset(), journal: dict | None = None
                    ) -> None:
        """AmbsealError unless ``out`` is new, or a folder of nothing but its manifest's
        files as ambseal wrote them (and the ``adopted`` entries; listed files changed
        since pass with ``force``, or when ``journal`` has their hash)."""
        if not os.path.lexists(self.out):
            return
        if self.out.is_symlink() or not self.out.is_dir():
            raise AmbsealError(f"{self.out}: exists and is not a folder; choose an empty or "
                               "new --out")
        try:
            extra = [e for e in foreign_entries(self.out) if e.rstrip("/") not in adopted]
            changed = [] if self.force else changed_entries(self.out, journal)
        except OSError as exc:
            raise self._fail("read the output folder", exc) from None
        if extra or changed:
            raise _not_ours(self.out, extra, changed)

    def _keep_foreign(self, moved: list) -> None:
        """Move what appeared in ``out`` during the run (not in its manifest) into the
        staging folder, so that replacing ``out`` loses none of it; ``moved`` gets each
        (source, destination) as it is moved."""
        if not self.out.is_dir():
            return
        # and a listed file the user edited during the run: theirs now
        edited = [] if self.force else changed_entries(self.out)
        moves = [(self.out / rel.rstrip("/"), self.stage / rel.rstrip("/"))
                 for rel in [*foreign_entries(self.out), *edited]]
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
                if not self._keep_journal and os.fstat(self._lock_fd).st_ino == os.stat(
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
    does not list, or (without ``force``) a listed file changed since ambseal wrote it,
    creates ``out`` if needed, takes the lock :data:`FOLDER_LOCK` inside it (a second
    command into the same folder is refused) and checks that a file can be written there,
    all before any work. While it is open, every file ambseal writes into it
    (:func:`atomic_write`) is recorded with the SHA-256 of its bytes, first in the lock
    file (a journal the next command reads if this one is killed) — so the manifest lists
    what ambseal wrote, with the hash it wrote, and never a file that appeared beside it
    meanwhile. On leaving (after an error too) the manifest lists what it listed before and
    is still there, and every file written during the command; nothing else in the folder
    is touched. A folder that was created and got nothing is removed again.

    Parameters
    ----------
    out : path
        The output folder.
    force : bool
        Replace listed files the user changed since ambseal wrote them.

    Raises
    ------
    AmbsealError
        The folder cannot be created or written, another command holds the lock, or the
        folder holds files its manifest does not list (or, without ``force``, listed files
        changed since).
    """

    def __init__(self, out: str | os.PathLike, force: bool = False):
        super().__init__(out, force)
        self.lock_path = self.out / FOLDER_LOCK
        self._written: dict[str, str] = {}

    def _entries(self) -> set[str]:
        return {p.relative_to(self.out).as_posix() for p in self.out.rglob("*")} - {
            FOLDER_LOCK}

    def record(self, rel: str, digest: str) -> None:
        """Note a file written into the folder (its path relative to it, the SHA-256 of its
        bytes): appended to the lock file's journal, then kept for the manifest."""
        line = f"{digest} {json.dumps(rel)}\n".encode()
        os.pwrite(self._lock_fd, line, self._journal_end)
        self._journal_end += len(line)
        self._written[rel] = digest

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
        journal: dict[str, str] = {}
        try:
            self.out = Path(os.path.realpath(self.out))  # as atomic_write's paths resolve
            journal = self._killed_journal()
            adopted = self._killed_outputs(journal)
            self._check_ours(adopted, journal)  # again, under the lock
            writable_folder(self.out)
            self._before = self._entries()
            man = _read_manifest(self.out) or {"files": {}, "folders": []}
            self._files = {**man["files"], **{r: d for r, d in journal.items()
                                                if (self.out / r).is_file()}}
            self._folders = set(man["folders"]) | {a for a in adopted
                                                   if (self.out / a).is_dir()}
            with _RECORDING_LOCK:
                _RECORDING.append(self)
        except BaseException:
            if journal:  # refused: the killed command's journal stays for the next one
                os.ftruncate(self._lock_fd, 0)
                os.pwrite(self._lock_fd, self._previous, 0)
                self._keep_journal = True
            self._release()
            raise
        return self.out

    def _killed_journal(self) -> dict[str, str]:
        """``{path: sha256}`` of the files a killed command recorded writing here (the
        journal in its lock, now taken over; empty when there was none)."""
        if self.stale_pid is None:
            return {}
        journal = {}
        for line in self._previous.decode("utf-8", "replace").splitlines()[1:]:
            digest, _, name = line.partition(" ")
            try:
                rel = json.loads(name)
            except ValueError:
                continue  # a line cut by the kill
            if isinstance(rel, str) and re.fullmatch(r"[0-9a-f]{64}", digest):
                journal[rel] = digest
        return journal

    def _killed_outputs(self, journal: dict[str, str]) -> frozenset:
        """The entries a killed command left here that its journal proves its own (files
        with the hash it recorded; folders holding only such files). They are ambseal's
        partial outputs, replaced by this command (noted on stderr); anything else not in
        the manifest is the user's."""
        if not journal:
            return frozenset()

        def written(p: Path) -> bool:
            rel = p.relative_to(self.out).as_posix()
            return (p.is_file() and not p.is_symlink() and rel in journal
                    and _file_hash(p) == journal[rel])
        try:
            out = set()
            for e in foreign_entries(self.out):
                p = self.out / e.rstrip("/")
                if e.endswith("/"):
                    inside = [q for q in p.rglob("*") if q.is_symlink() or not q.is_dir()]
                    if inside and all(map(written, inside)):
                        out.add(e.rstrip("/"))
                elif written(p):
                    out.add(e)
        except OSError:
            return frozenset()
        if out:
            print(f"ambseal: note: {self.out}: {', '.join(sorted(out))}: left by the killed "
                  f"command (pid {self.stale_pid}); taken as ambseal's", file=sys.stderr)
        return frozenset(out)

    def __exit__(self, kind, exc, tb) -> None:
        with _RECORDING_LOCK:
            if self in _RECORDING:
                _RECORDING.remove(self)
        try:
            files = {**self._files, **self._written}
            # the folders this command made that hold nothing but what it wrote
            new = {e for e in self._entries() - self._before if (self.out / e).is_dir()}
            made = {d for d in new if all(
                q.relative_to(self.out).as_posix() in files
                for q in (self.out / d).rglob("*") if q.is_symlink() or not q.is_dir())}
            if not (self._created and not self._entries()):
                write_manifest(self.out, uuid.uuid4().hex, files, sorted(self._folders | made))
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
