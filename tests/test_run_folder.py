"""One output folder = one run: a run replaces its folder as a whole, a second
run into the same folder is refused, a killed run leaves the former complete set.

The reference is the manifest's SHA-256 list (:func:`ambseal.files.check_manifest`): a
folder mixing two runs fails it."""

import json
import os
import random
import signal
import subprocess
import sys
import textwrap
import time

import pytest

from ambseal.cli import main
from ambseal.config import default_rig_path
from ambseal.errors import AmbsealError
from ambseal.files import RunFolder, check_manifest, write_text

from .conftest import ROOT

# A stand-in for `ambseal run` that writes its files slowly into a RunFolder, so that a kill
# lands in the middle of the writing (the real run: `test_killed_ambseal_run`, -m slow).
WRITER = textwrap.dedent("""
    import sys, time
    from ambseal.files import RunFolder, write_text
    tag, n = sys.argv[2], int(sys.argv[3])
    with RunFolder(sys.argv[1]) as stage:
        print("started", flush=True)
        for i in range(n):
            write_text(stage / f"f{i}.txt", tag)
            time.sleep(0.01)
""")


def _write(out, tag, n=5):
    with RunFolder(out) as stage:
        (stage / "sub").mkdir()
        for i in range(n):
            write_text(stage / f"f{i}.txt", tag)
        write_text(stage / "sub" / "x.txt", tag)
        write_text(stage / "metrics.json", "{}")


def _tags(out) -> set[str]:
    return {p.read_text() for p in out.rglob("f*.txt")}


def test_rerun_replaces_the_folder_as_a_whole(tmp_path):
    """A second run with fewer files leaves none of the first run's files behind; the
    manifest names the run; no staging folder or temporary file is left."""
    out = tmp_path / "out"
    _write(out, "old", n=5)
    first = check_manifest(out)
    _write(out, "new", n=2)
    assert check_manifest(out) != first
    assert _tags(out) == {"new"} and not (out / "f4.txt").exists()
    assert sorted(p.name for p in tmp_path.iterdir()) == ["out"]  # no lock left


def test_failed_run_keeps_the_former_set(tmp_path):
    out = tmp_path / "out"
    _write(out, "old")
    with pytest.raises(RuntimeError):
        with RunFolder(out) as stage:
            write_text(stage / "f0.txt", "new")
            raise RuntimeError("boom")
    check_manifest(out)
    assert _tags(out) == {"old"}


def test_second_concurrent_run_is_refused(tmp_path, capsys):
    """Two runs into one folder: the second is refused with the owner's pid, exit 2."""
    out = tmp_path / "out"
    with RunFolder(out):
        with pytest.raises(AmbsealError, match=f"pid {os.getpid()}"):
            RunFolder(out).__enter__()
        assert main(["run", "--no-identify", "--out", str(out)]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "another ambseal run" in err[0]


def test_refuses_a_folder_of_other_files(tmp_path):
    """--out pointing at a folder of the user's own files is never replaced."""
    (tmp_path / "thesis.tex").write_text("x")
    with pytest.raises(AmbsealError, match="not an ambseal output folder"):
        RunFolder(tmp_path).__enter__()
    assert (tmp_path / "thesis.tex").exists()


def test_unwritable_folder_refused_before_work(tmp_path):
    if os.geteuid() == 0:
        pytest.skip("root writes into read-only folders")
    ro = tmp_path / "ro"
    ro.mkdir()
    ro.chmod(0o500)
    try:
        with pytest.raises(AmbsealError, match="cannot"):
            RunFolder(ro / "out").__enter__()
    finally:
        ro.chmod(0o700)


def test_killed_runs_never_leave_a_mix(tmp_path):
    """Runs killed (SIGKILL) at random moments: the folder is always the former complete
    set or the new one (manifest check), and the next run removes the stale staging."""
    out = tmp_path / "out"
    _write(out, "old", n=20)
    env = {**os.environ, "PYTHONPATH": os.pathsep.join(sys.path)}
    rng = random.Random(15)
    for k in range(3):
        proc = subprocess.Popen([sys.executable, "-c", WRITER, str(out), f"new{k}", "20"],
                                stdout=subprocess.PIPE, env=env)
        assert proc.stdout.readline().strip() == b"started"
        time.sleep(rng.uniform(0.0, 0.25))
        proc.send_signal(signal.SIGKILL)
        proc.wait()
        check_manifest(out)
        assert len(_tags(out)) == 1
    _write(out, "last", n=1)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["out"]  # no lock left


def test_full_disk_refused_before_work(tmp_path, capsys, monkeypatch):
    """A run into a file system with less than MIN_FREE_BYTES free is refused at once with
    the free space (the disk is made to look full: shutil.disk_usage reports 1 MB)."""
    import shutil

    usage = shutil.disk_usage(tmp_path)
    monkeypatch.setattr(shutil, "disk_usage", lambda p: usage._replace(free=2**20))
    assert main(["run", "--no-identify", "--out", str(tmp_path / "o")]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "1.0 MB free" in err[0]
    assert not (tmp_path / "o").exists()


@pytest.mark.parametrize("command", ["run", "identify", "design", "acquire"])
def test_unwritable_output_refused_before_work(tmp_path, capsys, monkeypatch, command):
    """An output below a regular file cannot be created (ENOTDIR, as a read-only or missing
    mount would): one line naming it, exit 2, before any work."""
    from ambseal.app.pipeline import default_truth_path

    (tmp_path / "file").write_text("x")
    out = tmp_path / "file" / "out"
    args = {"run": ["run", "--out", str(out)],
            "identify": ["identify", str(default_truth_path().with_name("testrig.toml")),
                         "x.csv", "--params", "A.Ki_zeta", "--out", str(out)],
            "design": ["design", str(default_truth_path().with_name("testrig.toml")),
                       "--method", "pid", "--out", str(out)],
            "acquire": ["acquire", str(default_truth_path().with_name("testrig.toml")),
                        "--truth", str(default_truth_path()), "--excitation", "prbs",
                        "--pressure-bar", "0", "--out", str(out / "r.csv")]}[command]
    import ambseal.app.commands as commands
    import ambseal.app.pipeline as pipeline

    def no_work(*a, **k):
        raise AssertionError("designing before the output was checked")

    for module in (pipeline, commands):
        monkeypatch.setattr(module, "design", no_work)
    assert main(args) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and str(tmp_path / "file") in err[0], err


@pytest.mark.slow
def test_killed_ambseal_run(tmp_path):
    """The real `ambseal run` (turboexpander rig: its own designs, a few minutes) killed at a
    random moment of a rerun: the folder is the first run's complete set (its manifest
    and run id), or the rerun's; a last run cleans up after the killed one."""
    rig = str(ROOT / "examples" / "turboexpander.toml")
    out = tmp_path / "out"
    env = {**os.environ, "PYTHONPATH": os.pathsep.join(sys.path)}
    cmd = [sys.executable, "-m", "ambseal.cli", "run", rig, "--out", str(out)]
    t0 = time.perf_counter()
    subprocess.run(cmd, env=env, check=True, capture_output=True)
    first, duration = check_manifest(out), time.perf_counter() - t0
    proc = subprocess.Popen(cmd, env=env, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    time.sleep(random.Random().uniform(0.2, duration))
    proc.send_signal(signal.SIGKILL)
    proc.wait()
    check_manifest(out)  # a complete set, of either run (raises on a mix)
    assert (out / "metrics.json").exists() and (out / "report.html").exists()
    subprocess.run(cmd, env=env, check=True, capture_output=True)
    assert check_manifest(out) != first
    assert sorted(p.name for p in tmp_path.iterdir()) == ["out"]  # no lock left


def test_run_refuses_a_folder_with_a_users_notes_beside_metrics(tmp_path, capsys):
    """A folder holding an earlier metrics.json (no manifest: ambseal cannot tell what it
    made) and the user's notes: `ambseal run --out` on it is refused with one line naming
    the notes, exit 2, and both files are kept as they were."""
    out = tmp_path / "results"
    out.mkdir()
    (out / "metrics.json").write_text("{}")
    (out / "notes.txt").write_text("my notes")
    assert main(["run", "--no-identify", "--out", str(out)]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "notes.txt" in err[0] and "--out" in err[0], err
    assert (out / "notes.txt").read_text() == "my notes"
    assert sorted(p.name for p in out.iterdir()) == ["metrics.json", "notes.txt"]


def test_rerun_refuses_a_former_run_with_a_users_file(tmp_path):
    """A former run's complete output (its manifest) plus a file the user put there, at the
    top or in one of the run's folders: the rerun is refused before any work and the file
    is kept; without it the rerun replaces the run's files."""
    out = tmp_path / "out"
    _write(out, "old")
    for extra in (out / "notes.txt", out / "sub" / "mine.txt"):
        extra.write_text("mine")
        with pytest.raises(AmbsealError, match=extra.name):
            _write(out, "new")
        assert extra.read_text() == "mine" and _tags(out) == {"old"}
        extra.unlink()
    _write(out, "new")
    assert _tags(out) == {"new"}


def test_a_file_made_during_the_run_is_kept(tmp_path):
    """A file the user saves into the output folder while a run writes its new set is not
    lost with the former set: it is in the folder after the run, not in its manifest."""
    out = tmp_path / "out"
    _write(out, "old")
    with RunFolder(out) as stage:
        write_text(stage / "f0.txt", "new")
        (out / "notes.txt").write_text("mine")
    assert (out / "notes.txt").read_text() == "mine" and _tags(out) == {"new"}
    with pytest.raises(AmbsealError, match="notes.txt"):
        check_manifest(out)


def _small_controller_file(tmp_path):
    from ambseal.export.controller_files import export_controller

    from .test_cli_export import _small_digital

    return export_controller(_small_digital("K"), tmp_path / "K.json")


def test_folder_commands_write_only_beside_their_own_files(tmp_path, capsys):
    """`export --controller` writes its C module into --out and lists it in the folder's
    manifest; a rerun replaces its files; a user's file there (at the top or in the C
    folder) makes the next run refuse the folder (one line naming it, exit 2) and is kept;
    removed, the rerun works again."""
    K = _small_controller_file(tmp_path)
    out = tmp_path / "export"
    argv = ["export", str(default_rig_path()), "--controller", str(K), "--out", str(out),
            "--allow-unstable"]  # a small controller that levitates nothing
    assert main(argv) == 0 and main(argv) == 0
    assert {"c/ambseal_K.h", "c/ambseal_K.c"} <= set(
        json.loads((out / "manifest.json").read_text())["files"])
    check_manifest(out)
    capsys.readouterr()
    for extra in (out / "notes.txt", out / "c" / "mine.h"):
        extra.write_text("mine")
        assert main(argv) == 2
        err = capsys.readouterr().err.strip().splitlines()
        assert len(err) == 1 and extra.name in err[0], err
        assert extra.read_text() == "mine"
        extra.unlink()
    assert main(argv) == 0


@pytest.mark.parametrize("command", ["design", "export", "identify", "track", "campbell",
                                     "sweep"])
def test_every_folder_command_refuses_a_users_folder(tmp_path, capsys, monkeypatch, command):
    """Each command that writes a folder refuses one holding a file it did not write,
    before any work (the design would fail the test), one line naming the file, exit 2."""
    import ambseal.app.commands as commands
    import ambseal.app.controllers as controllers

    def no_work(*a, **k):
        raise AssertionError("working before the output folder was checked")

    for module in (commands, controllers):  # they hold the design function by name
        monkeypatch.setattr(module, "design", no_work)
    rig = str(ROOT / "examples" / "testrig.toml")
    out = tmp_path / "mine"
    out.mkdir()
    (out / "notes.txt").write_text("mine")
    argv = {"design": ["design", rig, "--method", "pid"],
            "export": ["export", rig, "--method", "pid"],
            "identify": ["identify", rig, "x.csv", "--params", "A.Ki_zeta"],
            "track": ["track", rig, "x.csv", "--params", "seal.k"],
            "campbell": ["campbell", rig, "--controller", "pid", "--speed-hz", "0:10:2"],
            "sweep": ["sweep", rig, "--pressure-bar", "0:1:2"]}[command]
    assert main(argv + ["--out", str(out)]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "notes.txt" in err[0], err
    assert sorted(p.name for p in out.iterdir()) == ["notes.txt"]
