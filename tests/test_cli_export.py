"""CLI: `ambseal export` — bad input ends with one line on stderr and exit 2."""

import json
import re
from pathlib import Path

from ambseal.cli import main

ROOT = Path(__file__).resolve().parents[1]


def _rig(tmp_path, controller_lines: str) -> Path:
    """The embedded rig with its ``[controller]`` table replaced."""
    text = (ROOT / "examples" / "testrig.toml").read_text()
    text = re.sub(r"\[controller\.pid\]", controller_lines + "\n\n[controller.pid]", text, 1)
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
    _one_line_exit_2(capsys, ["export", str(rig), "--method", "pid", "--out", str(tmp_path)],
                     "delay_samples")


def test_sample_rate_below_twice_the_controller_pole_is_refused(tmp_path, capsys):
    """Reference: sampling theorem — the reference PID's derivative filter has its poles at
    1/(ε T_d) = 1/(0.1·3.5 ms) = 2857 rad/s = 455 Hz (P5 Eq. 6), so 800 Hz is below twice
    them; the message names the key, the pole and the rate needed."""
    rig = _rig(tmp_path, "[controller]\nsample_rate_hz = 800.0")
    err = _one_line_exit_2(capsys, ["export", str(rig), "--method", "pid", "--out",
                                    str(tmp_path)], "sample_rate_hz", "800")
    assert "455" in err or "454" in err


def test_controller_file_with_wrong_shapes_is_refused(tmp_path, capsys, testrig_digital):
    """Reference: the export format — B must be (states × inputs); a file whose B lost a
    column is refused naming B and the shape expected."""
    from ambseal.export.controller_files import export_controller

    path = export_controller(testrig_digital["pid"], tmp_path / "K.json")
    doc = json.loads(path.read_text())
    doc["B"] = [row[:-1] for row in doc["B"]]
    path.write_text(json.dumps(doc))
    _one_line_exit_2(capsys, ["export", "x.toml", "--controller", str(path), "--c",
                              str(tmp_path / "c")], "B has shape", "expected")


def test_export_c_from_a_controller_file(tmp_path, capsys, testrig_digital):
    """Reference: the C module declares the controller's dimensions (4 sensor inputs,
    4 current outputs, its states) and sample time, as written in the file."""
    from ambseal.export.controller_files import export_controller

    path = export_controller(testrig_digital["mu"], tmp_path / "K_mu.npz")
    assert main(["export", "x.toml", "--controller", str(path), "--c", str(tmp_path / "c")]) == 0
    files = json.loads(capsys.readouterr().out)["files"]
    header = Path(files[0]).read_text()
    n = testrig_digital["mu"].discrete.A.shape[0]
    assert f"_NX {n}" in header and "_NY 4" in header and "_TS 0.0001" in header
