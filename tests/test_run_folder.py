"""One output folder = one run (issue 15 §1): a run replaces its folder as a whole, a second
run into the same folder is refused, a killed run leaves the former complete set.

The reference is the manifest's SHA-256 list (:func:`ambseal.files.check_manifest`): a
folder mixing two runs fails it."""

import os
import random
import signal
import subprocess
import sys
import textwrap
import time

import pytest

from ambseal.cli import main
from ambseal.errors import AmbsealError
from ambseal.files import RunFolder, check_manifest, write_text

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
    assert sorted(p.name for p in tmp_path.iterdir()) == [".out.lock", "out"]


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
    assert sorted(p.name for p in tmp_path.iterdir()) == [".out.lock", "out"]
