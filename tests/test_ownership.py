"""Nothing of the user's is overwritten, truncated or locked out.

The rule (:func:`ambseal.files.claim_file`, :class:`ambseal.files.OwnedFolder`): ambseal
writes a path that does not exist or that its own mark says it wrote (a manifest, a
record's sidecar, a rig's or a figure's hash), anything else only with ``--force``; it
never writes through a symbolic link, takes over the lock of a killed command and leaves
no lock behind. Each class of output is tried with a user's file and a link planted where
ambseal writes, the reference being the planted bytes: they must be there afterwards.
"""

from __future__ import annotations

import json
import os
import random
import signal
import subprocess
import sys
import textwrap
import time
from pathlib import Path

import pytest

from ambseal.cli import main
from ambseal.config import default_rig_path
from ambseal.errors import AmbsealError
from ambseal.files import FOLDER_LOCK, OwnedFolder, RunFolder, check_manifest

from .conftest import ROOT

RIG = str(default_rig_path())
TRUTH = str(Path(RIG).with_name("testrig_truth.toml"))
USER = b"a user's own bytes\n"


def _acquire(out: Path, *extra: str) -> list[str]:
    return ["acquire", RIG, "--truth", TRUTH, "--excitation", "prbs", "--pressure-bar", "0",
            "--duration-s", "0.02", "--out", str(out), *extra]


def _one_error(capsys, *words: str) -> str:
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and err[0].startswith("ambseal: error: "), err
    assert all(w in err[0] for w in words), err
    return err[0]


def _commands(tmp_path: Path) -> dict:
    """Each command that writes one named file: (its arguments for a target, the files it
    writes there)."""
    ross = str(ROOT / "tests" / "data" / "ross_rotor_example.toml")
    return {
        "acquire": (lambda t: _acquire(t), lambda t: [t, t.with_name(t.name + ".json")]),
        "modes --shapes": (lambda t: ["modes", "--n-modes", "2", "--shapes", str(t)],
                           lambda t: [t]),
        "import-ross": (lambda t: ["import-ross", ross, "--out", str(t)], lambda t: [t]),
    }


@pytest.mark.parametrize("command", ["acquire", "modes --shapes", "import-ross"])
def test_a_single_file_command_keeps_a_users_file_and_a_links_target(tmp_path, capsys,
                                                                     command):
    """A user's file where the command writes: exit 2, one line naming it and --force, the
    bytes kept. A link planted there: refused, its target untouched; with --force the link
    is replaced, never written through. The command's own unchanged output is replaced by
    a rerun without --force; once changed by the user it is theirs."""
    args, written = _commands(tmp_path)[command]
    suffix = {"acquire": ".csv", "modes --shapes": ".png", "import-ross": ".toml"}[command]
    target = tmp_path / f"out{suffix}"
    for path in written(target):  # the user's file at each path the command writes
        path.write_bytes(USER)
        assert main(args(target)) == 2
        _one_error(capsys, str(path.name), "--force")
        assert path.read_bytes() == USER
        path.unlink()
    doc = tmp_path / "document.txt"
    doc.write_bytes(USER)
    target.symlink_to(doc)
    assert main(args(target)) == 2
    _one_error(capsys, "symbolic link", "--force")
    assert main([*args(target), "--force"]) == 0
    capsys.readouterr()
    assert doc.read_bytes() == USER and not target.is_symlink()
    assert main(args(target)) == 0  # its own output, unchanged: replaced
    capsys.readouterr()
    if suffix == ".png":  # edited in an image program by the user: theirs now
        from PIL import Image

        with Image.open(target) as im:
            edited = im.convert("RGBA")
        edited.putpixel((0, 0), (1, 2, 3, 255))
        edited.save(target)
    else:  # changed by the user: theirs now
        with open(target, "ab") as fh:
            fh.write(b"\n")
    assert main(args(target)) == 2
    _one_error(capsys, str(target.name), "changed")


def test_c_export_through_dotdot_claims_the_folder_it_reaches(tmp_path, capsys):
    """``export --c out/../c``: the C folder is outside ``out`` once the path is resolved,
    so it is claimed on its own; a user's ambseal_pid.c there is refused, its bytes kept."""
    (tmp_path / "c").mkdir()
    user_c = tmp_path / "c" / "ambseal_pid.c"
    user_c.write_bytes(USER)
    out = tmp_path / "out"
    assert main(["export", RIG, "--method", "pid", "--allow-unstable", "--out", str(out),
                 "--c", str(out / ".." / "c")]) == 2
    _one_error(capsys, "ambseal_pid.c")
    assert user_c.read_bytes() == USER


@pytest.mark.parametrize("kind", [RunFolder, OwnedFolder])
def test_a_lock_planted_as_a_link_is_refused_and_its_target_kept(tmp_path, kind):
    """The lock file is never opened through a link (O_NOFOLLOW): the folder is refused
    with the lock named, the link's target keeps its bytes."""
    from ambseal.errors import AmbsealError

    out = tmp_path / "out"
    out.mkdir()
    doc = tmp_path / "document.txt"
    doc.write_bytes(USER)
    lock = (tmp_path / ".out.lock") if kind is RunFolder else (out / FOLDER_LOCK)
    lock.symlink_to(doc)
    with pytest.raises(AmbsealError, match="symbolic link"):
        with kind(out):
            pass
    assert doc.read_bytes() == USER and lock.is_symlink()


def test_no_lock_is_left_after_a_command(tmp_path):
    """An output folder and its parent hold no lock file once the command is done."""
    out = tmp_path / "out"
    with OwnedFolder(out) as folder:
        (folder / "a.txt").write_text("a")
    assert sorted(p.name for p in out.iterdir()) == ["a.txt", "manifest.json"]
    assert sorted(p.name for p in tmp_path.iterdir()) == ["out"]


# A command writing its files slowly into an OwnedFolder, killed part-way by the test
WRITER = textwrap.dedent("""
    import sys, time
    from ambseal.files import OwnedFolder, write_text
    with OwnedFolder(sys.argv[1]) as folder:
        print("started", flush=True)
        for i in range(int(sys.argv[2])):
            write_text(folder / f"part{i}.txt", "partial")
            time.sleep(0.02)
""")


def test_a_killed_command_is_recovered_by_the_next(tmp_path):
    """``kill -9`` at a random (seeded) moment of a command writing into its folder, twice:
    the rerun takes over the dead command's lock with a note, takes its partial outputs as
    ambseal's (listed in the manifest with their hashes, nothing else there) and leaves no
    lock behind."""
    out = tmp_path / "out"
    env = {**os.environ, "PYTHONPATH": os.pathsep.join(sys.path)}
    rng = random.Random(44)
    for _ in range(2):
        proc = subprocess.Popen([sys.executable, "-c", WRITER, str(out), "40"],
                                stdout=subprocess.PIPE, env=env)
        assert proc.stdout.readline().strip() == b"started"
        time.sleep(rng.uniform(0.05, 0.5))
        proc.send_signal(signal.SIGKILL)
        proc.wait()
        left = {p.name for p in out.iterdir()}
        assert FOLDER_LOCK in left  # what a kill leaves
        rerun = subprocess.run([sys.executable, "-c", WRITER, str(out), "3"],
                               capture_output=True, env=env, text=True)
        assert rerun.returncode == 0, rerun.stderr
        assert "took over the lock" in rerun.stderr
        assert FOLDER_LOCK not in {p.name for p in out.iterdir()}
        check_manifest(out)  # every file listed with its hash, nothing else there


def test_a_link_planted_in_an_output_folder_is_refused_and_its_target_kept(tmp_path,
                                                                         capsys):
    """A folder command (``campbell``) whose output folder holds a link where it writes a
    figure: the link is not the manifest's, so the folder is refused by name before any
    work, and the link's target keeps its bytes."""
    out = tmp_path / "out"
    out.mkdir()
    doc = tmp_path / "document.txt"
    doc.write_bytes(USER)
    (out / "campbell_pid.png").symlink_to(doc)
    assert main(["campbell", RIG, "--speed-hz", "0:10:2", "--out", str(out)]) == 2
    _one_error(capsys, "campbell_pid.png")
    assert doc.read_bytes() == USER and (out / "campbell_pid.png").is_symlink()


def test_a_file_saved_beside_a_command_stays_the_users(tmp_path):
    """A file the user saves into a folder while a command writes there is not listed in
    the folder's manifest (only what ambseal wrote, with the hash it wrote), so a later
    run into the folder refuses it by name instead of replacing it with the former set."""
    from ambseal.files import write_text

    out = tmp_path / "cb"
    with OwnedFolder(out) as folder:
        write_text(folder / "campbell.json", "{}")
        (out / "notes.txt").write_bytes(USER)
        write_text(folder / "campbell.csv", "speed_hz\n")
    listed = json.loads((out / "manifest.json").read_text())["files"]
    assert set(listed) == {"campbell.json", "campbell.csv"}
    with pytest.raises(AmbsealError, match="notes.txt"):
        with RunFolder(out):
            pass
    assert (out / "notes.txt").read_bytes() == USER


def test_a_killed_commands_folder_keeps_a_file_saved_meanwhile(tmp_path):
    """A command killed (SIGTERM, its lock left) while the user saved a file into its
    folder: the next command takes over the dead command's outputs — the files its journal
    names with their hashes — but refuses the user's file by name and keeps it."""
    out = tmp_path / "out"
    env = {**os.environ, "PYTHONPATH": os.pathsep.join(sys.path)}
    proc = subprocess.Popen([sys.executable, "-c", WRITER, str(out), "400"],
                            stdout=subprocess.PIPE, env=env)
    assert proc.stdout.readline().strip() == b"started"
    (out / "mine.txt").write_bytes(USER)
    time.sleep(0.1)
    proc.send_signal(signal.SIGTERM)
    proc.wait()
    assert FOLDER_LOCK in {p.name for p in out.iterdir()}
    rerun = subprocess.run([sys.executable, "-c", WRITER, str(out), "3"],
                           capture_output=True, env=env, text=True)
    assert rerun.returncode != 0 and "mine.txt" in rerun.stderr, rerun.stderr
    assert (out / "mine.txt").read_bytes() == USER
    (out / "mine.txt").unlink()
    rerun = subprocess.run([sys.executable, "-c", WRITER, str(out), "3"],
                           capture_output=True, env=env, text=True)
    assert rerun.returncode == 0 and "taken as ambseal's" in rerun.stderr, rerun.stderr
    check_manifest(out)


def test_an_edited_file_of_an_export_folder_is_the_users(tmp_path, capsys):
    """A re-export into a folder where the user edited one of ambseal's files (its hash no
    longer the manifest's) is refused by name and the edit kept, as a single file is;
    with --force the file is replaced."""
    from .test_run_folder import _small_controller_file

    K = _small_controller_file(tmp_path)
    out = tmp_path / "export"
    argv = ["export", RIG, "--controller", str(K), "--out", str(out),
            "--allow-unstable"]  # a small controller that levitates nothing
    assert main(argv) == 0
    source = out / "c" / "ambseal_K.c"
    written = source.read_bytes()
    source.write_bytes(written + b"/* tuned by hand */\n")
    capsys.readouterr()
    assert main(argv) == 2
    _one_error(capsys, "c/ambseal_K.c", "changed since ambseal wrote", "--force")
    assert source.read_bytes().endswith(b"/* tuned by hand */\n")
    assert main([*argv, "--force"]) == 0
    assert source.read_bytes() == written
    check_manifest(out)


def test_stale_folders_beside_a_run_are_removed_only_when_ambseals(tmp_path):
    """Beside ``out``: a user's folders named like a killed run's staging and former
    folders (no mark, no complete manifest) are kept; a killed run's own staging folder
    (its mark inside) is removed — also when ``out``'s name holds glob characters."""
    from ambseal.files import STAGING_MARK, write_text

    for name in ("out", "res[1]"):
        out = tmp_path / name
        with RunFolder(out) as stage:
            write_text(stage / "metrics.json", "{}")
        users = [tmp_path / f".{name}.staging-77", tmp_path / f".{name}.old-78"]
        for u in users:
            u.mkdir()
            (u / "mine.txt").write_bytes(USER)
        killed = tmp_path / f".{name}.staging-79"
        killed.mkdir()
        (killed / STAGING_MARK).write_text("79\n")
        write_text(killed / "metrics.json", "{}")
        with RunFolder(out) as stage:
            write_text(stage / "metrics.json", "{}")
        assert not killed.exists()
        assert all((u / "mine.txt").read_bytes() == USER for u in users)
        check_manifest(out)


@pytest.mark.parametrize("umask, mode", [(0o077, 0o600), (0o022, 0o644), (0o002, 0o664)])
def test_written_files_take_the_users_umask(tmp_path, umask, mode):
    """``ambseal modes --shapes`` (a figure) and any result file ambseal writes get the mode
    the user's umask gives a new file (created 0666 less the umask), as any program's:
    they had been forced to 0644 whatever the umask (a 077 user's results readable by
    all)."""
    import stat

    old = os.umask(umask)
    try:
        out = tmp_path / "shapes.png"
        assert main(["modes", str(ROOT / "examples" / "pump.toml"), "--shapes",
                     str(out)]) == 0
    finally:
        os.umask(old)
    assert stat.S_IMODE(out.stat().st_mode) == mode
