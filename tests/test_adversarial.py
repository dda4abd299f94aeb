"""Adversarial inputs, each in its own folder and its own ``ambseal`` process under a
deadline: every one ends in exit status 2 with exactly one line on stderr naming what was
wrong, or in the right result — never a hang, a traceback, a position-wired controller,
unbounded memory or planted code run.

The classes: controller files (channels not the rig's, a continuous controller marked
discrete, a device instead of a file, a rig that does not exist); options and values
(a negative tolerance, too many workers, an unknown parameter, a ``--set`` value with a
newline); input sizes (2 000 disks, a mesh split past the element bound, a FIFO or a
device as an input file); a library planted where ``import-ross`` runs; a read-only
installation (numba without a cache). The reference is the CLI's promise (ambseal.cli):
one line on stderr and status 2. (A Dask scheduler that accepts and never answers is
tests/analysis/test_analysis_sweep.py's, at a deadline of 1 s instead of the probe's 10.)
"""

from __future__ import annotations

import copy
import json
import multiprocessing
import os
import shutil
import subprocess
import sys
import tomllib
from pathlib import Path

import control
import numpy as np
import pytest

from ambseal.config import MAX_COMPONENTS, MAX_ELEMENTS, default_rig_path
from ambseal.export.controller_files import export_controller

from .conftest import ROOT
from .test_cli_export import CHANNELS, _small_digital
from .toml_text import dump

#: The longest one case may take (s) before it counts as a hang: the slowest imports ROSS
#: (10–20 s on 2 idle cores); ten times that, so a loaded machine (two CPU hogs beside the
#: suite) never breaks it.
DEADLINE_S = 300
RIG = str(default_rig_path())
BASE = tomllib.loads((ROOT / "examples" / "testrig.toml").read_text())


#: Each case runs in a process of its own, forked from a single-threaded server that has
#: the CLI's modules imported already (an interpreter starting ``ambseal`` spends 2–5 s
#: on imports per case; a fork of the server none, and no thread of pytest's is copied).
_PROCS = multiprocessing.get_context("forkserver")
_PROCS.set_forkserver_preload(["ambseal.cli", "ambseal.app.handlers"])


def _main_in(folder: str, argv: list, streams: str) -> None:
    """The child of :func:`_ambseal`: ``main(argv)`` in ``folder``, its stdout and stderr
    (Python's and the file descriptors) in ``streams``; exits with its status."""
    from ambseal.cli import main

    os.chdir(folder)
    for fd, name in ((1, "stdout"), (2, "stderr")):
        f = os.open(os.path.join(streams, name), os.O_WRONLY | os.O_CREAT | os.O_TRUNC)
        os.dup2(f, fd)
        os.close(f)
    sys.stdout = open(1, "w", encoding="utf-8", closefd=False)
    sys.stderr = open(2, "w", encoding="utf-8", closefd=False)
    try:
        code = main([str(a) for a in argv])
    except SystemExit as exc:  # argparse's errors
        code = exc.code if isinstance(exc.code, int) else 1
    sys.stdout.flush()
    sys.stderr.flush()
    os._exit(code)


def _ambseal(folder: Path, argv) -> subprocess.CompletedProcess:
    """``ambseal ARGV`` in a process of its own working in ``folder``, under the deadline
    (a hang fails the test)."""
    streams = folder.parent / f"{folder.name}.streams"
    streams.mkdir()
    proc = _PROCS.Process(target=_main_in, args=(str(folder), [str(a) for a in argv],
                                                 str(streams)))
    proc.start()
    proc.join(DEADLINE_S)
    if proc.is_alive():
        proc.kill()
        proc.join()
        pytest.fail(f"ambseal {argv[0]}: still running after {DEADLINE_S} s")
    out, err = ((streams / n).read_text(errors="replace") for n in ("stdout", "stderr"))
    return subprocess.CompletedProcess(argv, proc.exitcode, out, err)


def _refused(proc: subprocess.CompletedProcess, *words: str) -> str:
    lines = proc.stderr.strip().splitlines()
    assert proc.returncode == 2 and len(lines) == 1, proc.stderr[-3000:]
    assert lines[0].startswith("ambseal: error: ") and "Traceback" not in lines[0]
    assert all(w in lines[0] for w in words), lines[0]
    return lines[0]


def _rig(folder: Path, edit) -> Path:
    data = copy.deepcopy(BASE)
    edit(data)
    path = folder / "rig.toml"
    path.write_text(dump(data))
    return path


def _disks(n: int):
    def edit(d):
        length = sum(s["length"] for s in d["shaft"])
        d["disk"] += [{"name": f"d{i}", "position": length * (i + 0.5) / n, "mass": 0.01}
                      for i in range(n)]
    return edit


def _gain_file(folder: Path, inputs, outputs) -> Path:
    """A continuous static-gain controller file with the given signal names."""
    K = control.ss([], [], [], 2e4 * np.eye(len(outputs), len(inputs)), inputs=list(inputs),
                   outputs=list(outputs), name="K")
    return export_controller(K, folder / "K.json")


def _marked_discrete(folder: Path) -> Path:
    """A discrete controller file whose step matrices are its continuous ones."""
    path = export_controller(_small_digital("K"), folder / "K.json")
    doc = json.loads(path.read_text())
    doc.update({k: doc[k + "_r"] for k in "ABCD"})
    path.write_text(json.dumps(doc))
    return path


def _json_list(folder):
    """A JSON file holding a list where an identification's fit (an object) belongs."""
    path = folder / "list.json"
    path.write_text("[1, 2]")
    return path


def _fifo(folder: Path) -> Path:
    path = folder / "rig.toml"
    os.mkfifo(path)  # reading it would block until a writer comes: never
    return path


def _device_controller(folder: Path) -> Path:
    path = folder / "K.json"
    path.symlink_to("/dev/zero")
    return path


_Y = [f"y_{c}" for c in CHANNELS]
_I = [f"i_{c}" for c in CHANNELS]

#: (id, argv from the case's folder, the words of the one line)
REFUSED = [
    ("negative tolerance", lambda f: ["sweep", RIG, "--pressure-bar", "0:4:3", "--tol-bar",
                                      "-1", "--out", f / "o"], ("--tol-bar", "> 0")),
    ("a million workers", lambda f: ["sweep", RIG, "--pressure-bar", "0:4:3", "--workers",
                                     "1000000", "--out", f / "o"], ("--workers", "per core")),
    ("unknown parameter", lambda f: ["sweep", RIG, "--pressure-bar", "0:4:3", "--param",
                                     "seal.kk=0:1e6:3", "--out", f / "o"],
     ("unknown parameter 'seal.kk'", "seal.k")),
    ("newline in --set", lambda f: ["design", RIG, "--method", "pid", "--set",
                                    "design.band_hz=[1, 3000]\ndesign.tracked=true",
                                    "--out", f / "o"], ("--set", "one line")),
    ("2000 disks", lambda f: ["validate", _rig(f, _disks(2000))],
     ("disk", f"at most {MAX_COMPONENTS}")),
    ("mesh split past its bound", lambda f: ["validate", _rig(f, _disks(MAX_ELEMENTS - 10))],
     ("shaft", f"more than {MAX_ELEMENTS} beam elements")),
    ("a FIFO as the rig", lambda f: ["validate", _fifo(f)], ("rig.toml", "not a regular file")),
    ("/dev/zero as identification", lambda f: [
        "design", _rig(f, lambda d: d.setdefault("design", {}).update(
            uncertainty_from_identification="/dev/zero")), "--show-defaults"],
     ("uncertainty_from_identification", "/dev/zero", "not a regular file")),
    ("a JSON list as identification", lambda f: [
        "design", _rig(f, lambda d: d.setdefault("design", {}).update(
            uncertainty_from_identification=str(_json_list(f)))), "--show-defaults"],
     ("uncertainty_from_identification", "list.json", "expected the table")),
    ("/dev/zero as controller", lambda f: ["export", RIG, "--controller",
                                           _device_controller(f), "--c", f / "c"],
     ("K.json", "not a regular file")),
    ("controller of other channels", lambda f: [
        "export", RIG, "--controller", _gain_file(f, _Y[:3] + ["y_C_eta"], _I),
        "--c", f / "c"], ("K.json", "not the rig's", "y_C_eta", "y_B_eta")),
    ("continuous marked discrete", lambda f: ["export", RIG, "--controller",
                                              _marked_discrete(f), "--c", f / "c"],
     ("K.json", "discretisation", "spectral radius")),
    ("export without its rig", lambda f: ["export", f / "missing.toml", "--controller",
                                          _gain_file(f, _Y, _I), "--c", f / "c"],
     ("missing.toml",)),
]


@pytest.mark.parametrize("make, words", [c[1:] for c in REFUSED], ids=[c[0] for c in REFUSED])
def test_refused_in_one_line(tmp_path, make, words):
    """Each adversarial input ends in exit 2 and one line naming it, writing nothing."""
    proc = _ambseal(tmp_path, make(tmp_path))
    _refused(proc, *words)
    assert not (tmp_path / "o").exists() and not (tmp_path / "c").exists()


def test_a_read_only_installation_runs(tmp_path):
    """numba with no writable cache folder (its one locator below a regular file, which
    not even root can create a folder in): ``validate`` gives its summary, exit 0."""
    (tmp_path / "file").write_text("")
    env = {**os.environ, "OPENBLAS_NUM_THREADS": "1",  # a fresh interpreter: its imports
           "NUMBA_CACHE_DIR": str(tmp_path / "file" / "cache"),
           "NUMBA_CACHE_LOCATOR_CLASSES": "UserProvidedCacheLocator"}
    proc = subprocess.run([sys.executable, "-m", "ambseal.cli", "validate", RIG, "--json"],
                          cwd=tmp_path, capture_output=True, text=True, env=env,
                          timeout=DEADLINE_S)
    assert proc.returncode == 0 and "Traceback" not in proc.stderr, proc.stderr[-3000:]
    assert json.loads(proc.stdout)["axes"] == list(CHANNELS)


_PLANTED_C = """#include <stdio.h>
__attribute__((constructor)) static void planted(void) {
    FILE *f = fopen(MARK, "w");
    if (f) { fputs("planted code ran", f); fclose(f); }
}
"""


def test_import_ross_loads_no_library_planted_beside_the_user(tmp_path):
    """Importing ROSS imports ccp, which loads REFPROP's ``librefprop.so`` from the working
    directory. A shared object of that name whose constructor writes a marker file (any
    C compiler; else a file of garbage bytes, which a load would fail on), planted in the
    working directory and beside the ROSS file (ROSS 2.3's own ``rotor_example``, saved
    by ``Rotor.save``): ``ambseal import-ross`` run there writes the rig, stdout holds
    its JSON summary alone, and the marker never appears — nothing there was loaded."""
    import ctypes

    pytest.importorskip("ross", reason="ross-rotordynamics (the 'ross' extra) is not "
                                       "installed")
    work, data = tmp_path / "work", tmp_path / "data"
    work.mkdir()
    data.mkdir()
    marker = tmp_path / "MARKER"
    cc = shutil.which("cc") or shutil.which("gcc")
    for folder in (work, data):
        lib = folder / "librefprop.so"
        if cc is None:
            lib.write_bytes(b"\x7fELF planted, not a library")
            continue
        (folder / "planted.c").write_text(_PLANTED_C)
        subprocess.run([cc, "-shared", "-fPIC", f'-DMARK="{marker}"', "-o", str(lib),
                        str(folder / "planted.c")], check=True, timeout=DEADLINE_S)
    if cc is not None:  # the planted library is live: loading it writes the marker
        ctypes.CDLL(str(data / "librefprop.so"))
        assert marker.read_text() == "planted code ran"
        marker.unlink()
    src = data / "rotor.toml"
    shutil.copy(ROOT / "tests" / "data" / "ross_rotor_example.toml", src)
    proc = _ambseal(work, ["import-ross", src, "--out", "rig.toml"])
    assert proc.returncode == 0, proc.stderr[-3000:]
    summary = json.loads(proc.stdout)  # the whole of stdout
    assert summary["shaft_elements"] == 6 and summary["disks"] == 2
    assert (work / "rig.toml").is_file() and not marker.exists()
