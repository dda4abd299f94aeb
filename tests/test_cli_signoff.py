"""``ambseal signoff``: API 617 Level I on the command line — its JSON, files and exit
status; a rig without stages refused with exit status 2."""

from __future__ import annotations

import json
import math

import pytest

from ambseal.cli import main

from .analysis.test_analysis_level1 import _rigid_rotor


def test_signoff_json_files_and_exit_status(tmp_path, capsys):
    """A rotor on damped springs (no AMB: controller ``none``), Q_0/Q_A between 2 and 10
    and its CSR above a boundary set low (Region B): Level II required, exit status 1; the JSON holds the level1 block with Q_A, Q_0
    (Q_0 = c√(k/m) within 2 %), δ_A, CSR and passed, and the files it names exist."""
    rig = tmp_path / "rigid.toml"
    rig.write_text(_rigid_rotor(1e7, 2000.0, 4.5e4)
                   + "[signoff]\ncsr_boundary = [[0.0, 0.001]]\n")
    code = main(["signoff", str(rig), "--json", "--out", str(tmp_path / "so")])
    out, err = capsys.readouterr()
    assert code == 1 and "Traceback" not in err
    doc = json.loads(out)
    lv = doc["controllers"]["none"]["level1"]
    assert set(lv) >= {"Q_A", "Q_0", "log_dec_A", "CSR", "passed", "rule"}
    m = math.pi / 4 * 0.2**2 * 0.4 * 7850.0
    assert lv["Q_0"] == pytest.approx(2000.0 * math.sqrt(1e7 / m), rel=0.02)
    assert lv["passed"] is False and doc["passed"] is False and "Level II" in lv["rule"]
    assert all((tmp_path / "so" / n).is_file() for n in ("signoff.json", "level1.png"))
    assert json.loads((tmp_path / "so" / "signoff.json").read_text())["controllers"] == \
        doc["controllers"]


def test_signoff_passes_with_exit_status_0(tmp_path, capsys):
    rig = tmp_path / "rigid.toml"
    rig.write_text(_rigid_rotor(1e7, 2000.0, 8.0e3))
    code = main(["signoff", str(rig), "--out", str(tmp_path / "so")])
    out, _ = capsys.readouterr()
    assert code == 0 and out.startswith("none: Level I passed")


@pytest.mark.parametrize("args, says", [
    ([], "[[stage]]"), (["--method", "lqr"], "--method"),
])
def test_signoff_refuses_plainly(tmp_path, capsys, args, says):
    rig = tmp_path / "rigid.toml"
    text = _rigid_rotor(1e7, 2000.0, 8.0e3)
    if not args:
        text = text.split("[[stage]]")[0] + "[operating]\nspeed_rpm = 3000.0\n"
    rig.write_text(text)
    code = main(["signoff", str(rig), "--out", str(tmp_path / "so"), *args])
    err = capsys.readouterr().err
    assert code == 2 and says in err and "Traceback" not in err


def test_the_reports_signoff_section_says_the_verdict_first(tmp_path):
    """The run report's section: the overall verdict before the table, one row per
    controller with its rule; the figure is written."""
    import tomllib

    from ambseal.analysis import level1_screening
    from ambseal.config import parse_rig
    from ambseal.report import signoff_report

    ok = level1_screening(parse_rig(tomllib.loads(_rigid_rotor(1e7, 2000.0, 8.0e3))),
                          name="a")
    bad = level1_screening(parse_rig(tomllib.loads(_rigid_rotor(1e7, 2000.0, 2.0e5))),
                           name="b")
    figs, sections = signoff_report(tmp_path, [ok, bad], "rigid")
    text = sections[0]["html"]
    assert text.index("NOT passed") < text.index("<table>") and "b require" in text
    assert text.count("<tr><td>") == 2 and "δ_A = 0.0497 &lt; 0.1: Level II required" in text
    assert figs[0][1].is_file()
    _, passed = signoff_report(tmp_path, [ok], "rigid")
    assert "passed by every controller" in passed[0]["html"]
