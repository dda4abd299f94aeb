"""The CLI: one clear line and exit status 2 on every bad rig file, JSON from ``modes``."""

import json
import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from ambseal.cli import main

GOOD = """
[materials.steel]
E = 2.1e11
rho = 7850.0
nu = 0.3

[[shaft]]
length = 0.5
outer_diameter = 0.05
material = "steel"
elements = 10

[[disk]]
position = 0.25
mass = 5.0
Ip = 0.01
Id = 0.006

[[amb]]
name = "A"
position = 0.05
sensor_position = 0.02
ki = 100.0
ks = 2.0e5

[[amb]]
name = "B"
position = 0.45
sensor_position = 0.48
ki = 100.0
ks = 2.0e5
"""


def run(tmp_path, text, *args):
    rig = tmp_path / "rig.toml"
    rig.write_text(text)
    return rig, main(["modes", str(rig), *args])


BAD = [
    ("missing key", GOOD.replace('material = "steel"\n', ""), "shaft[0].material", "missing"),
    ("wrong type", GOOD.replace("elements = 10", 'elements = "ten"'), "shaft[0].elements",
     "integer"),
    ("negative length", GOOD.replace("length = 0.5", "length = -0.5"), "shaft[0].length",
     "expected a value >="),
    ("negative diameter", GOOD.replace("outer_diameter = 0.05", "outer_diameter = -0.05"),
     "shaft[0].outer_diameter", "expected a value >="),
    ("unknown material", GOOD.replace('material = "steel"', 'material = "steal"'),
     "shaft[0].material", "unknown material 'steal'"),
    ("outside the shaft", GOOD.replace("position = 0.25", "position = 0.75"),
     "disk[0].position", "outside the shaft"),
    ("AMB without ki/ks or geometry", GOOD.replace("ki = 100.0\nks = 2.0e5\n", "", 1),
     "amb[0]", "expected either the geometry"),
    ("not TOML", "this is = = not toml", "", "not valid TOML"),
    ("nan", GOOD.replace("mass = 5.0", "mass = nan"), "disk[0].mass", "finite"),
    ("unknown key", GOOD.replace("mass = 5.0", "mass = 5.0\nmas = 5.0"), "disk[0].mas",
     "unknown key"),
]


@pytest.mark.parametrize("label,text,key,expected", BAD, ids=[b[0] for b in BAD])
def test_bad_rig_file_one_line_exit_2(tmp_path, capsys, label, text, key, expected):
    """Each bad rig file of a user's kind: exit 2, one stderr line with file, key, what."""
    rig, code = run(tmp_path, text)
    err = capsys.readouterr().err
    assert code == 2
    lines = err.strip().splitlines()
    assert len(lines) == 1, err
    assert str(rig) in lines[0] and key in lines[0] and expected in lines[0], lines[0]
    assert "Traceback" not in err


def test_cli_no_traceback_in_a_real_process(tmp_path):
    """The console entry point, in its own process: exit 2 and no traceback."""
    rig = tmp_path / "rig.toml"
    rig.write_text(GOOD.replace("length = 0.5", "length = -0.5"))
    proc = subprocess.run([sys.executable, "-m", "ambseal.cli", "modes", str(rig)],
                          capture_output=True, text=True)
    assert proc.returncode == 2
    assert "Traceback" not in proc.stderr and "shaft[0].length" in proc.stderr


def test_a_dependencys_deprecation_notices_are_not_shown(tmp_path, capsys, monkeypatch):
    """A command's warnings are shown after it, except a dependency's deprecation notices
    (python-control's on NumPy 2.5 filled a plain ``ambseal run``'s stderr): those of
    ambseal's own modules and any other warning still are."""
    import warnings

    import ambseal.app

    def handler(args):
        for module, category in (("control.statesp", DeprecationWarning),
                                 ("numpy.linalg", FutureWarning),
                                 ("ambseal.robust.hinf", DeprecationWarning)):
            warnings.warn_explicit(f"{category.__name__} from {module}", category,
                                   f"{module.replace('.', '/')}.py", 1, module=module)
        warnings.warn("a RuntimeWarning of a solver", RuntimeWarning)
        return 0

    monkeypatch.setitem(ambseal.app.HANDLERS, "validate", handler)
    rig = tmp_path / "rig.toml"
    rig.write_text(GOOD)
    assert main(["validate", str(rig)]) == 0
    assert sorted(capsys.readouterr().err.splitlines()) == [
        "ambseal: warning: DeprecationWarning from ambseal.robust.hinf (DeprecationWarning)",
        "ambseal: warning: a RuntimeWarning of a solver (RuntimeWarning)"]


def _keep_design(folder: str) -> None:
    """A library function that warns as the design cache does when it cannot keep a design
    (ambseal.design.seal_schedule): a UserWarning naming the folder, pointing at its
    caller's line."""
    import warnings

    warnings.warn(f"design cache {folder!r}: the design is not kept ([Errno 30] Read-only "
                  f"file system: {folder + '/x.json'!r})", stacklevel=2)


def test_a_warning_reaches_the_user_as_one_line(tmp_path, capsys, monkeypatch):
    """Reference: the command line's promise (ambseal.cli) — a warning reaches the user of
    the command as one line, ``ambseal: warning: <message>``, without Python's file, line
    and source line (``…/app/tracked.py:66: UserWarning: …`` and the line of code); a
    message of several lines becomes one; a category other than UserWarning is named.
    A library user keeps Python's warnings: ``warnings.showwarning`` is Python's again
    after the command, and the library function still warns as Python does."""
    import warnings

    import ambseal.app

    def handler(args):
        _keep_design(str(tmp_path / "ro_cache"))
        warnings.warn("a solver's notice\n  over two lines", RuntimeWarning)
        return 0

    shown = warnings.showwarning
    monkeypatch.setitem(ambseal.app.HANDLERS, "validate", handler)
    rig = tmp_path / "rig.toml"
    rig.write_text(GOOD)
    assert main(["validate", str(rig)]) == 0
    cache = tmp_path / "ro_cache"
    assert capsys.readouterr().err.splitlines() == [
        f"ambseal: warning: design cache '{cache}': the design is not kept ([Errno 30] "
        f"Read-only file system: '{cache}/x.json')",
        "ambseal: warning: a solver's notice over two lines (RuntimeWarning)"]
    assert warnings.showwarning is shown
    with pytest.warns(UserWarning, match="the design is not kept"):
        _keep_design(str(cache))


def test_the_console_ignores_the_environments_matplotlib_backend(tmp_path):
    """ambseal draws on Agg canvases, never through pyplot: a backend matplotlib cannot
    load (MPLBACKEND named by a shell, a notebook kernel or a typo) stopped its import with
    a traceback; the figure is written all the same."""
    rig = tmp_path / "rig.toml"
    rig.write_text(GOOD)
    env = dict(os.environ, MPLBACKEND="no_such_backend")
    proc = subprocess.run([sys.executable, "-m", "ambseal.cli", "modes", str(rig), "--shapes"],
                          capture_output=True, text=True, cwd=tmp_path, env=env)
    assert proc.returncode == 0, proc.stderr
    assert "Traceback" not in proc.stderr
    assert (tmp_path / "mode_shapes.png").stat().st_size > 0


def test_the_console_runs_with_stdout_or_stderr_closed(tmp_path):
    """A shell's ``2>&-`` or ``>&-``: Python starts with None for that stream, and the first
    message (rich's isatty) ended in exit 1 and nothing said. The exit status is the
    command's: 2 for a bad rig, 0 for a good one."""
    bad, good = tmp_path / "bad.toml", tmp_path / "good.toml"
    bad.write_text(GOOD.replace("length = 0.5", "length = -0.5"))
    good.write_text(GOOD)
    script = "import sys; from ambseal.cli import main; sys.exit(main())"
    for fd in (1, 2):
        for rig, code in ((bad, 2), (good, 0)):
            proc = subprocess.run([sys.executable, "-c", script, "validate", str(rig)],
                                  preexec_fn=lambda fd=fd: os.close(fd),
                                  stdout=subprocess.DEVNULL if fd == 2 else None,
                                  stderr=subprocess.DEVNULL if fd == 1 else None)
            assert proc.returncode == code, (fd, rig.name)
    # a wrapper script (pyenv's shim) run with `2>&-` leaves its own file open for reading
    # on descriptor 2 of the interpreter it starts: `python -m ambseal.cli` exited 1
    with open(good, "rb") as read_only:
        for rig, code in ((bad, 2), (good, 0)):
            proc = subprocess.run([sys.executable, "-m", "ambseal.cli", "validate", str(rig)],
                                  stdout=subprocess.DEVNULL, stderr=read_only)
            assert proc.returncode == code, ("read-only stderr", rig.name)


def test_modes_json_keys_and_unstable_poles(tmp_path, capsys):
    """``modes --json``: its documented keys; AMB negative stiffness gives real unstable poles
    of √(Ks_total/m) for the translation (closed form, rigid rotor), and --no-amb has none."""
    _, code = run(tmp_path, GOOD, "--json")
    out = json.loads(capsys.readouterr().out)
    assert code == 0
    assert {"natural_frequencies_hz", "damping_ratios", "unstable_poles", "log_decrements",
            "whirl", "speed_hz", "pressure_bar", "max_hz"} <= set(out)
    assert len(out["unstable_poles"]) == 4  # translation and tilt in two planes
    _, code = run(tmp_path, GOOD, "--json", "--no-amb")
    assert json.loads(capsys.readouterr().out)["unstable_poles"] == []


def test_modes_of_the_open_loop_loads_no_control_numerics():
    """``ambseal modes`` without ``--controller`` or ``--shapes`` loads neither
    python-control, numba, matplotlib nor CVXOPT (1.8 s of start-up: a third of ``modes`` on
    a 230-element rotor); checked on ``sys.modules`` of a subprocess, and with
    ``--controller pid`` python-control is loaded (so the check can fail)."""
    code = ("import sys\nfrom ambseal.cli import main\n"
            "assert main(['modes', '--json'] + sys.argv[1:]) == 0\n"
            "print([m for m in ('control', 'numba', 'matplotlib', 'cvxopt')\n"
            "       if m in sys.modules])\n")
    run_ = [sys.executable, "-c", code]
    lean = subprocess.run(run_, capture_output=True, text=True, check=True)
    assert lean.stdout.strip().splitlines()[-1] == "[]"
    closed = subprocess.run(run_ + ["--controller", "pid"], capture_output=True, text=True,
                            check=True)
    assert "'control'" in closed.stdout.strip().splitlines()[-1]


def test_plain_bearing_rig_is_valid_for_modes(tmp_path, capsys):
    """A rotor on two plain bearings (springs, no AMB): a valid rig; its first mode is the
    rigid translation at √(2k/m)/2π for stiff shafts (closed form)."""
    text = GOOD.split("[[amb]]")[0] + """
[[spring]]
position = 0.0
kxx = 1.0e5
kyy = 1.0e5

[[spring]]
position = 0.5
kxx = 1.0e5
kyy = 1.0e5
"""
    _, code = run(tmp_path, text, "--json")
    out = json.loads(capsys.readouterr().out)
    assert code == 0
    m = 7850.0 * 3.141592653589793 * 0.05**2 / 4 * 0.5 + 5.0
    f_ref = (2 * 1.0e5 / m) ** 0.5 / (2 * 3.141592653589793)
    assert out["natural_frequencies_hz"][0] == pytest.approx(f_ref, rel=0.01)


def test_modes_free_lists_bending_modes(capsys):
    """``--free`` on the embedded rig: the first bending mode of the bare rotor within ±10 %
    of the 550 Hz of the thesis's rig data (P2 rig data, P4 Table 1: "1st rotor bending
    mode @ 550 Hz"; the tolerance is for the FE model, not for our own value)."""
    from ambseal.config import default_rig_path

    assert main(["modes", str(default_rig_path()), "--free", "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert out["natural_frequencies_hz"][0] == pytest.approx(550.0, rel=0.10)
    assert out["unstable_poles"] == []


def test_modes_n_lowest_equal_the_dense_ones(capsys):
    """``--n-modes 4`` (sparse shift-invert) prints the dense path's 4 lowest damped
    frequencies of the free rotor (same pencil, 1e-8), and 0 is refused with exit 2."""
    rig = str(Path(__file__).resolve().parents[1] / "examples" / "testrig.toml")
    assert main(["modes", rig, "--free", "--json"]) == 0
    dense = json.loads(capsys.readouterr().out)["natural_frequencies_hz"]
    assert main(["modes", rig, "--free", "--json", "--n-modes", "4"]) == 0
    sparse = json.loads(capsys.readouterr().out)["natural_frequencies_hz"]
    assert len(sparse) == 4
    assert sparse == pytest.approx(dense[:4], rel=1e-8)
    with pytest.raises(SystemExit) as exc:
        main(["modes", rig, "--n-modes", "0"])
    assert exc.value.code == 2


@pytest.mark.parametrize("n", [4, 6, 10])
def test_modes_n_lists_n_modes_on_the_supported_rig(capsys, n):
    """``--n-modes N`` on the embedded rig (AMBs, seal, coupling): exactly the N lowest
    modes, the damped frequencies of the dense path's (1e-8) — the N-th mode is listed
    although its frequency is the limit taken from another eigen-solve."""
    assert main(["modes", "--json"]) == 0
    dense = json.loads(capsys.readouterr().out)
    assert main(["modes", "--json", "--n-modes", str(n)]) == 0
    out = json.loads(capsys.readouterr().out)
    def every(d):  # the natural frequencies and the overdamped pairs listed apart
        return sorted(d["natural_frequencies_hz"] + [o["frequency_hz"] for o in d["overdamped"]])

    assert len(every(out)) == n
    assert every(out) == pytest.approx(every(dense)[:n], rel=1e-8)
    assert out["max_hz"] == pytest.approx(every(out)[-1], rel=1e-8)


def test_design_show_defaults_prints_a_design_part_that_reads_back(capsys):
    """``design --show-defaults``: TOML whose [design] table the schema accepts, with the
    test rig's P5 §3.1.4 scalings; ``--set`` changes the value shown."""
    import tomllib

    from ambseal.config import default_rig_path, load_rig

    rig = str(default_rig_path())
    assert main(["design", rig, "--show-defaults", "--set", "design.mu.orbit_um=8"]) == 0
    shown = tomllib.loads(capsys.readouterr().out)["design"]
    assert shown["d_e_um"] == 20 and shown["d_u_a"] == 1 and shown["mu"]["orbit_um"] == 8
    cfg = load_rig(rig, [f"design.mu.wf_rolloff_hz={shown['mu']['wf_rolloff_hz']}"])
    assert cfg.design.mu.wf_rolloff_hz == 260


def test_show_defaults_writes_names_with_quotes_and_backslashes_as_toml(tmp_path, capsys):
    """A disk named ``Impeller "A" C:\\stage`` as ``force_at``: ``--show-defaults`` writes
    it as a TOML string that reads back to the same name (it had printed the quotes and
    the backslash bare, which does not parse)."""
    import tomllib

    name = 'Impeller "A" C:\\stage'
    text = (Path(__file__).resolve().parents[1] / "examples" / "overhung_compressor.toml"
            ).read_text().replace('name = "impeller"', f"name = {json.dumps(name)}").replace(
        'disk = "impeller"', f"disk = {json.dumps(name)}")
    rig = tmp_path / "rig.toml"
    rig.write_text(text + f"\n[design.unbalance]\nforce_at = {json.dumps(name)}\n")
    assert main(["design", str(rig), "--show-defaults"]) == 0
    shown = tomllib.loads(capsys.readouterr().out)["design"]
    assert shown["unbalance"]["force_at"] == name


@pytest.mark.parametrize("args, words", [
    (["--show-defaults", "--set", "design.mu.orbit_um=-1"], "design.mu.orbit_um"),
    (["--show-defaults", "--set", "orbit_um=8"], "design.<key>=<value>"),
    (["--method", "hinf", "--set", "design.unbalance.force_at=\"gland\""], "force_at"),
    ([], "--method is required"),
])
def test_design_bad_overrides_exit_2_with_one_line(capsys, args, words):
    from ambseal.config import default_rig_path

    assert main(["design", str(default_rig_path()), *args]) == 2
    err = capsys.readouterr().err.strip()
    assert words in err and "\n" not in err and "Traceback" not in err


def test_negative_ks_exits_2_naming_the_convention(tmp_path, capsys):
    rig, code = run(tmp_path, GOOD.replace("ks = 2.0e5", "ks = -2.0e5", 1))
    err = capsys.readouterr().err
    assert code == 2 and "amb[0]" in err and "Ks > 0" in err


def test_version_and_helps_with_defaults(capsys):
    """``--version`` prints the package version; every command's help names its options'
    defaults (argparse's own rendering) and ``run --help`` says what the run does."""
    import ambseal

    with pytest.raises(SystemExit) as exc:
        main(["--version"])
    assert exc.value.code == 0 and capsys.readouterr().out.strip() == f"ambseal {ambseal.__version__}"
    with pytest.raises(SystemExit):
        main(["run", "--help"])
    text = " ".join(capsys.readouterr().out.split())
    assert "(default: ambseal-out)" in text and "identifies the rig" in text
    assert "report.html (verdict first)" in text
    with pytest.raises(SystemExit):
        main(["acquire", "--help"])
    assert "(A; default [design.impulse] amplitude_a, else bias current / 120)" in " ".join(
        capsys.readouterr().out.split())


def test_validate_and_modes_default_to_the_embedded_rig(capsys):
    """``validate`` without RIG checks the embedded test facility: its rotor mass is the
    thesis's 69 kg (P5 §4.4.1, ±5 % for the FE mesh), the open loop has unstable poles
    (negative AMB stiffness, P5 §2), and the modes below the controller's Nyquist frequency
    include the first bending pair near 550 Hz (P4 Table 1, ±10 %); ``modes`` without RIG
    prints the same modes."""
    assert main(["validate", "--json"]) == 0
    v = json.loads(capsys.readouterr().out)
    assert v["mass_kg"] == pytest.approx(69.0, rel=0.05)
    assert len(v["unstable_poles"]) >= 2
    freqs = [f for f, _ in v["modes"]]
    assert all(f < v["modes_below_hz"] for f in freqs)
    assert any(f == pytest.approx(550.0, rel=0.10) for f in freqs)
    assert v["defaults"]["judged_conditions"] == ["0 bar", "2.04 bar", "4.08 bar"]
    assert main(["modes", "--json"]) == 0
    m = json.loads(capsys.readouterr().out)
    # modes lists the pairs damped at ζ ≥ 1/√2 (no resonance) apart from the natural
    # frequencies; validate lists every pair with its ζ
    shown = [(f, z) for f, z in v["modes"] if f <= m["max_hz"]]
    assert m["natural_frequencies_hz"] == pytest.approx(
        [f for f, z in shown if z < 2 ** -0.5], rel=1e-6)
    assert [o["frequency_hz"] for o in m["overdamped"]] == pytest.approx(
        [f for f, z in shown if z >= 2 ** -0.5], rel=1e-6)
    assert all(o["damping_ratio"] >= 2 ** -0.5 for o in m["overdamped"])
    assert main(["validate"]) == 0
    text = capsys.readouterr().out
    assert "valid" in text and "unstable open-loop poles" in text and "None" not in text


def test_tracked_without_a_pressure_driven_seal_k_exits_2_with_one_line(capsys):
    """``[design] tracked`` schedules on a seal's k affine in the pressure drop; the
    turboexpander's seal coefficients are tables against frequency: refused on reading."""
    assert main(["design", "examples/turboexpander.toml", "--show-defaults", "--set",
                 "design.tracked=true"]) == 2
    err = capsys.readouterr().err.strip()
    assert "design.tracked" in err and "per_bar" in err and "\n" not in err


def test_validate_takes_a_rotor_on_plain_bearings(tmp_path, capsys):
    """ROSS's ``rotor_example`` as ``import-ross`` writes it (two plain bearings, no AMB):
    ``validate`` exited 2 ("controller.pid: cannot be derived") where ``modes`` and
    ``signoff`` work on it. Its modes, with no controller to design or judge: no judged
    condition, no judgement; the same first natural frequencies as ``modes`` lists."""
    from ambseal.io import import_ross_file

    src = Path(__file__).resolve().parent / "data" / "ross_rotor_example.toml"
    rig = tmp_path / "plain.toml"
    import_ross_file(src, rig)
    assert main(["validate", str(rig), "--json"]) == 0
    v = json.loads(capsys.readouterr().out)
    assert v["axes"] == [] and v["defaults"]["judged_conditions"] == []
    assert v["defaults"]["judgement"] is None and v["defaults"]["pid"] is None
    assert main(["modes", str(rig), "--json"]) == 0
    m = json.loads(capsys.readouterr().out)
    first = [f for f, _ in v["modes"]][:2]
    np.testing.assert_allclose(first, m["natural_frequencies_hz"][:2], rtol=1e-9)
    assert main(["validate", str(rig)]) == 0
    out = capsys.readouterr().out
    assert "AMB axes none" in out and "judged_conditions: none (no AMB" in out
