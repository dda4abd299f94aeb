"""CLI: `ambseal export` — bad input ends with one line on stderr and exit 2."""

import json
import re
from pathlib import Path

from ambseal.cli import main

ROOT = Path(__file__).resolve().parents[1]


def _rig(tmp_path, controller_lines: str) -> Path:
    """The embedded rig with its ``[controller]`` table replaced."""
    text = (ROOT / "examples" / "testrig.toml").read_text()
    text = re.sub(r"\[controller\.pid\]", controller_lines + "\n\n[controller.pid]", text, count=1)
    path = tmp_path / "rig.toml"
    path.write_text(text)
    return path


def _one_line_exit_2(capsys, argv, *words):
    code = main(argv)
    err = capsys.readouterr().err.strip()
    assert code == 2 and "\n" not in err and "Traceback" not in err, err
    for w in words:
        assert w in err, err
    return err


def test_negative_delay_is_refused(tmp_path, capsys):
    """Reference: the rig-file contract — ``[controller] delay_samples`` is a whole number
    of samples >= 0; -1 is named with its key."""
    rig = _rig(tmp_path, "[controller]\ndelay_samples = -1")
    _one_line_exit_2(capsys, ["export", str(rig), "--method", "pid", "--out",
                              str(tmp_path / "out")], "delay_samples")


def test_sample_rate_below_twice_the_controller_pole_is_refused(tmp_path, capsys):
    """Reference: sampling theorem — the reference PID's derivative filter has its poles at
    1/(ε T_d) = 1/(0.1·3.5 ms) = 2857 rad/s = 455 Hz (P5 Eq. 6), so 800 Hz is below twice
    them; the message names the key, the pole and the rate needed."""
    rig = _rig(tmp_path, "[controller]\nsample_rate_hz = 800.0")
    err = _one_line_exit_2(capsys, ["export", str(rig), "--method", "pid", "--out",
                                    str(tmp_path / "out")], "sample_rate_hz", "800")
    assert "455" in err or "454" in err


def test_controller_file_with_wrong_shapes_is_refused(tmp_path, capsys, testrig_digital):
    """Reference: the export format — B must be (states × inputs); a file whose B lost a
    column is refused naming B and the shape expected."""
    from ambseal.export.controller_files import export_controller

    path = export_controller(testrig_digital["pid"], tmp_path / "K.json")
    doc = json.loads(path.read_text())
    doc["B"] = [row[:-1] for row in doc["B"]]
    path.write_text(json.dumps(doc))
    _one_line_exit_2(capsys, ["export", RIG, "--controller", str(path), "--c",
                              str(tmp_path / "c")], "B has shape", "expected")


def test_export_c_from_a_controller_file(tmp_path, capsys, testrig_digital):
    """Reference: the C module declares the controller's dimensions (4 sensor inputs,
    4 current outputs, its states) and sample time, as written in the file."""
    from ambseal.export.controller_files import export_controller

    path = export_controller(testrig_digital["mu"], tmp_path / "K_mu.npz")
    assert main(["export", RIG, "--controller", str(path), "--c", str(tmp_path / "c")]) == 0
    files = json.loads(capsys.readouterr().out)["files"]
    header = Path(files[0]).read_text()
    n = testrig_digital["mu"].discrete.A.shape[0]
    assert f"_NX {n}" in header and "_NY 4" in header and "_TS 0.0001" in header


#: A name that closes a C comment and adds statements (a newline, a trigraph for '\', a
#: line splice and non-ASCII text too).
INJECTED = '*/ int ambseal_injected(void) { return system("x"); } /*\n#define X ??/\n\\ é'


#: The embedded rig's AMB channels, as a controller file for it names its signals.
CHANNELS = ("A_zeta", "A_eta", "B_zeta", "B_eta")
RIG = str(ROOT / "examples" / "testrig.toml")


def _small_digital(name: str, inputs=None, outputs=None):
    """A one-state digital controller (the exported object) named ``name``, for the
    embedded rig's channels unless ``inputs``/``outputs`` are given: its discrete matrices
    are the ZOH discretisation of its continuous ones at 10 kHz, as the file states."""
    import control
    import numpy as np

    from ambseal.robust.digital import DigitalController, discretize_as
    from ambseal.robust.digital_loop import DiscreteController

    inputs = list(inputs or [f"y_{c}" for c in CHANNELS])
    outputs = list(outputs or [f"i_{c}" for c in CHANNELS])
    ny, nu = len(inputs), len(outputs)
    mats = (np.array([[-100.0]]), np.ones((1, ny)), 2.0 * np.ones((nu, 1)),
            0.5 * np.eye(nu, ny))
    K = control.ss(*mats, inputs=inputs, outputs=outputs, name=name)
    disc = DiscreteController(*discretize_as(mats, 1e-4, "zoh"), 1e-4, description={})
    return DigitalController(K, K, disc, "zoh", None, 1e4, 1, (), None, (), "zoh")


def test_injected_names_never_reach_the_c_compiler(tmp_path):
    """Reference: the C preprocessor's own output (``cc -E -P``, comments removed) of the
    generated module holds no injected statement, the module compiles with -Werror
    -pedantic, and a program printing ``<PREFIX>_NAME`` prints the controller's name exactly
    as given (the string literal escapes it)."""
    import shutil
    import subprocess

    from ambseal.export.codegen import write_c

    cc = shutil.which("cc") or shutil.which("gcc")
    ctrl = _small_digital(INJECTED, inputs=["*/ y_A; /*"], outputs=["i_A??/"])
    files = write_c(ctrl, tmp_path / "c", "amb_k")
    pre = subprocess.run([cc or "cpp", "-E", "-P", "-std=c99", str(files[1])],
                         capture_output=True, text=True, check=True).stdout
    assert "ambseal_injected" not in pre and "system" not in pre
    if cc is None:
        return
    main_c = tmp_path / "main.c"
    main_c.write_text('#include <stdio.h>\n#include "amb_k.h"\n'
                      'int main(void) { fputs(AMB_K_NAME, stdout); return 0; }\n')
    exe = tmp_path / "run"
    subprocess.run([cc, "-std=c99", "-Wall", "-Werror", "-pedantic",
                    f"-I{files[0].parent}", "-o", str(exe), str(main_c), str(files[1])],
                   check=True)
    out = subprocess.run([str(exe)], capture_output=True, check=True).stdout
    assert out.decode("utf-8") == INJECTED


def test_controller_file_with_an_injected_name_is_refused(tmp_path, capsys):
    """Reference: the controller-file contract — names are plain labels. A file whose
    ``name`` or input name carries C is refused at load (one line naming the key, exit 2,
    no C written); a file name that is no C identifier is mapped to one."""
    from ambseal.export.controller_files import export_controller

    good = export_controller(_small_digital("K_small"), tmp_path / "K-1 v2.json")
    assert main(["export", RIG, "--controller", str(good), "--c",  # it levitates nothing
                 str(tmp_path / "ok"), "--allow-unstable"]) == 0
    files = json.loads(capsys.readouterr().out)["files"]
    assert [Path(f).name for f in files] == ["ambseal_K_1_v2.h", "ambseal_K_1_v2.c"]
    for key, value in (("name", INJECTED), ("inputs", ['y_A"; system("x"); /*'])):
        doc = json.loads(good.read_text())
        doc[key] = value
        bad = tmp_path / "K.json"
        bad.write_text(json.dumps(doc))
        _one_line_exit_2(capsys, ["export", RIG, "--controller", str(bad), "--c",
                                  str(tmp_path / "c")], str(bad), key, "not a plain name")
        assert not (tmp_path / "c").exists()


def test_an_unstable_pid_is_not_exported_quietly(tmp_path, capsys):
    """Reference: thesis P5 §4 — the reference PID loses the test rig between nominal and
    twice nominal pressure drop (4.08 bar), a judged condition. `export --method pid` refuses
    it in one line naming the condition; with --allow-unstable it exports, warns on stderr
    and marks the design file."""
    rig = str(ROOT / "examples" / "testrig.toml")
    _one_line_exit_2(capsys, ["export", rig, "--method", "pid", "--out", str(tmp_path / "a")],
                     "pid", "unstable at 4.08 bar", "--allow-unstable")
    assert not (tmp_path / "a" / "controller_pid.json").exists()
    out = tmp_path / "b"
    assert main(["export", rig, "--method", "pid", "--out", str(out), "--allow-unstable"]) == 0
    assert "warning" in capsys.readouterr().err
    design = json.loads((out / "design_pid.json").read_text())
    assert design["full_order"]["stable"] is False and design["kept_unstable"] is True
    # every file says so: the controller's JSON, NumPy and MATLAB documents and the C
    _says_it_does_not_hold(out / "controller_pid", "4.08 bar")
    header = (out / "c" / "ambseal_pid.h").read_text()
    assert "AMBSEAL_PID_JUDGED_HOLDS 0" in header and "--allow-unstable" in header
    assert "4.08 bar" in header

    # the same file handed to export: judged on the rig before its C is written
    path = str(out / "controller_pid.json")
    _one_line_exit_2(capsys, ["export", rig, "--controller", path, "--c",
                              str(tmp_path / "c1")], path, "4.08 bar", "--allow-unstable")
    assert not (tmp_path / "c1").exists()
    assert main(["export", rig, "--controller", path, "--c", str(tmp_path / "c2"),
                 "--allow-unstable"]) == 0
    captured = capsys.readouterr()
    assert "warning" in captured.err and "4.08 bar" in captured.err
    loop = json.loads(captured.out)["loop"]
    assert loop["loop_holds"] is False and loop["allow_unstable"] is True
    header = (tmp_path / "c2" / "ambseal_controller_pid.h").read_text()
    assert "_JUDGED_HOLDS 0" in header and "4.08 bar" in header


def _says_it_does_not_hold(stem: Path, where: str) -> None:
    """The exported documents of a controller whose loop does not hold say so, and where."""
    import numpy as np
    from scipy.io import loadmat

    doc = json.loads(stem.with_suffix(".json").read_text())
    with np.load(stem.with_suffix(".npz"), allow_pickle=False) as z:
        npz = {k: str(z[k]) for k in ("loop_holds", "allow_unstable", "verdict")}
    mat = {k: str(np.ravel(v)[0]) for k, v in loadmat(stem.with_suffix(".mat")).items()
           if k in ("loop_holds", "allow_unstable", "verdict")}
    for d in (doc, npz, mat):
        assert d["loop_holds"] == "no" and d["allow_unstable"] == "yes", d
        assert "does NOT hold" in d["verdict"] and where in d["verdict"], d


def test_a_controller_file_that_holds_says_so(tmp_path, capsys, testrig_digital):
    """Reference: the μ controller holds the test rig at every judged condition (its own
    judgement, ``testrig_designs``); exported from its file, the C header says where it
    was judged and defines its verdict 1."""
    from ambseal.export.controller_files import export_controller

    path = export_controller(testrig_digital["mu"], tmp_path / "K_mu.json")
    assert main(["export", RIG, "--controller", str(path), "--c", str(tmp_path / "c")]) == 0
    loop = json.loads(capsys.readouterr().out)["loop"]
    assert loop["loop_holds"] is True and loop["allow_unstable"] is False
    assert "4.08 bar" in loop["verdict"] and "0 Hz" in loop["verdict"]
    header = (tmp_path / "c" / "ambseal_K_mu.h").read_text()
    assert "AMBSEAL_K_MU_JUDGED_HOLDS 1" in header and "holds as it runs" in header
