"""``ambseal signoff``: API 617 Level I on the command line — its JSON, files and exit
status; a rig without stages refused with exit status 2."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest

from ambseal.cli import main

from .analysis.test_analysis_level1 import _rigid_rotor


def test_signoff_json_files_and_exit_status(tmp_path, capsys):
    """A rotor on damped springs (no AMB: controller ``none``), Q_0/Q_A between 2 and 10
    and its CSR above a boundary set low (Region B): Level II required, exit status 1; the JSON holds the level1 block with Q_A, Q_0
    (Q_0 = c√(k/m) within 2 %), δ_A, CSR and passed, and the files it names exist; the
    undamped critical speed map, its first critical on soft springs √(2k/m)."""
    rig = tmp_path / "rigid.toml"
    rig.write_text(_rigid_rotor(1e7, 2000.0, 4.5e4)
                   + "[signoff]\ncsr_boundary = [[0.0, 0.001]]\n")
    code = main(["signoff", str(rig), "--json", "--out", str(tmp_path / "so")])
    out, err = capsys.readouterr()
    assert code == 1 and "Traceback" not in err
    doc = json.loads(out)
    lv = doc["controllers"]["none"]["level1"]
    assert set(lv) >= {"Q_A", "Q_0", "log_dec_A", "CSR", "passed", "rule"}
    block = doc["controllers"]["none"]
    assert set(block) >= {"passed", "criteria", "level2", "unbalance", "iso14839_2"}
    assert doc["verdict"].startswith("Sign-off NOT passed") and not block["passed"]
    names = [c["criterion"] for c in block["criteria"]]
    assert names == ["stability, Level I", "stability, Level II", "separation margins",
                     "vibration at the probes", "close clearances", "vibration zone"]
    assert all(c["source"] for c in block["criteria"])
    m = math.pi / 4 * 0.2**2 * 0.4 * 7850.0
    assert lv["Q_0"] == pytest.approx(2000.0 * math.sqrt(1e7 / m), rel=0.02)
    assert lv["passed"] is False and doc["passed"] is False and "Level II" in lv["rule"]
    assert all((tmp_path / "so" / n).is_file()
               for n in ("signoff.json", "level1.png", "api617_unbalance.png", "ucs_map.png"))
    assert json.loads((tmp_path / "so" / "signoff.json").read_text())["controllers"] == \
        doc["controllers"]
    # API 684's map: ±3 decades around the springs' 5e6 N/m; on the softest the rotor
    # moves as a rigid body, its cylindrical critical √(2k/m) (its shaft bends by 1e-7)
    ucs = doc["ucs_map"]
    k0 = ucs["stiffness_n_per_m"][0]
    assert k0 == pytest.approx(1e3) and ucs["stiffness_n_per_m"][-1] == pytest.approx(1e9)
    assert ucs["critical_speeds_hz"][0][0] == pytest.approx(
        math.sqrt(2 * k0 / m) / (2 * math.pi), rel=1e-6)
    assert ucs["controllers"] == []  # on springs alone: no AMB to draw


def test_signoff_passes_with_exit_status_0(tmp_path, capsys):
    """Supports ten times stiffer and damped at ζ ≈ 0.1: the critical far above the trip
    speed, the response at the probes a micrometre, Q_0 beyond 10·Q_A: every criterion
    passed, the verdict first."""
    rig = tmp_path / "rigid.toml"
    rig.write_text(_rigid_rotor(1e8, 2.0e4, 8.0e3))
    code = main(["signoff", str(rig), "--out", str(tmp_path / "so")])
    out, _ = capsys.readouterr()
    lines = out.splitlines()
    assert code == 0 and lines[0].startswith("Sign-off PASSED")
    # the rule the journal loads W follow, then the criteria
    assert lines[1].startswith("journal static loads W: the rotor's weight on its bearings")
    assert lines[2].startswith("none: stability, Level I: passed")


def test_a_rotor_its_own_seal_makes_unstable_is_not_signed_off(tmp_path, capsys):
    """The passing rotor above with a seal at mid-span whose cross-coupled stiffness
    k = 5e7 N/m drives its forward cylindrical mode: closed form of the rigid rotor,
    m s² + c s + K − j k = 0 (z = x + jy; Childs' sign convention), a root at
    Re s = +144 rad/s. Level I leaves the seals out and passes; Level II with every source
    finds the loop unstable and now counts, so the machine is not signed off (exit 1),
    and the unbalance criteria, which have no steady response on an unstable loop, are
    not graded — none is called passed."""
    m = math.pi / 4 * 0.2**2 * 0.4 * 7850.0
    s = np.roots([m, 2.0e4, 1e8 - 1j * 5e7])
    assert s.real.max() == pytest.approx(144.3, abs=0.1)
    rig = tmp_path / "sealed.toml"
    rig.write_text(_rigid_rotor(1e8, 2.0e4, 8.0e3) + "[[seal]]\nname = \"piston\"\n"
                   "position = 0.2\nk = { at_zero = 5e7, per_bar = 0.0 }\n")
    code = main(["signoff", str(rig), "--json", "--out", str(tmp_path / "so")])
    out, err = capsys.readouterr()
    assert code == 1 and "Traceback" not in err
    doc = json.loads(out)
    assert doc["verdict"] == "Sign-off NOT passed — none: stability, Level II"
    crit = {c["criterion"]: c for c in doc["controllers"]["none"]["criteria"]}
    assert crit["stability, Level I"]["outcome"] == "passed"
    lv2 = crit["stability, Level II"]
    assert lv2["outcome"] == "FAILED" and lv2["counts"] and "UNSTABLE" in lv2["value"]
    for name in ("separation margins", "vibration at the probes", "close clearances",
                 "vibration zone"):
        c = crit[name]
        assert (c["outcome"], c["passed"], c["graded"]) == ("not graded", False, False)
        assert "unstable" in c["value"]


def test_criteria_not_evaluated_are_not_graded_and_the_verdict_says_so(tmp_path, capsys):
    """A rotor on springs (no AMB, no seal clearance): its close clearances and ISO 14839-2
    zone cannot be graded; they say so instead of "passed", and the verdict line names
    them."""
    rig = tmp_path / "rigid.toml"
    rig.write_text(_rigid_rotor(1e8, 2.0e4, 8.0e3))
    assert main(["signoff", str(rig), "--out", str(tmp_path / "so")]) == 0
    lines = capsys.readouterr().out.splitlines()
    assert lines[0].endswith("(not graded: close clearances, vibration zone)")
    assert "none: close clearances: not graded — no close clearance given" in lines[6]
    assert ("none: vibration zone: not graded — no backup clearance given ([[touchdown]] "
            "radial_clearance)") in lines[7]


def test_signoff_refuses_plainly(tmp_path, capsys):
    rig = tmp_path / "rigid.toml"
    rig.write_text(_rigid_rotor(1e7, 2000.0, 8.0e3))
    code = main(["signoff", str(rig), "--out", str(tmp_path / "so"), "--method", "lqr"])
    err = capsys.readouterr().err
    assert code == 2 and "--method" in err and "Traceback" not in err


def test_a_machine_without_stages_is_signed_off_on_its_own_sources(tmp_path, capsys):
    """A rotor without [[stage]] (a flywheel, a motor, a pump) was refused; API 617's
    Level I (an impeller's anticipated cross-coupling) does not apply, and says so, not
    graded; Level II, on the rig's own sources (none here: the rotor on its supports),
    decides; the unbalance response is judged. The rotor on stiff damped supports passes:
    its forward mode's δ by hand, m s² + c s + k = 0, δ = 2π ζ/√(1 − ζ²) with
    ζ = c/(2√(k m)), within 2 %; no level1.png is written."""
    rig = tmp_path / "nostage.toml"
    rig.write_text(_rigid_rotor(1e8, 2.0e4, 8.0e3).split("[[stage]]")[0]
                   + "[operating]\nspeed_rpm = 3000.0\n")
    code = main(["signoff", str(rig), "--json", "--out", str(tmp_path / "so")])
    out, err = capsys.readouterr()
    assert code == 0 and "Traceback" not in err
    doc = json.loads(out)
    block = doc["controllers"]["none"]
    assert block["level1"] is None
    crit = {c["criterion"]: c for c in block["criteria"]}
    assert crit["stability, Level I"]["outcome"] == "not graded"
    assert crit["stability, Level I"]["value"].startswith("not applicable: no [[stage]]")
    assert crit["stability, Level II"]["outcome"] == "passed"
    assert [r["component"] for r in block["level2"]["table"]] == ["rotor and supports",
                                                                  "all sources"]
    m = math.pi / 4 * 0.2**2 * 0.4 * 7850.0
    zeta = 2.0e4 / (2 * math.sqrt(1e8 * m))
    assert block["level2"]["log_dec"] == pytest.approx(
        2 * math.pi * zeta / math.sqrt(1 - zeta**2), rel=0.02)
    assert crit["vibration at the probes"]["outcome"] == "passed"
    assert not (tmp_path / "so" / "level1.png").exists()


def _edit(text: str, *pairs) -> str:
    for old, new in pairs:
        assert old in text
        text = text.replace(old, new)
    return text


@pytest.mark.parametrize("edits, says", [
    # a wheel and a passage of 1e-300 m: q_A divided by zero
    ((("impeller_diameter = 0.3", "impeller_diameter = 1e-300"),
      ("discharge_width = 0.02", "discharge_width = 1e-300")),
     "stage[0].impeller_diameter: expected a value >= 0.01"),
    # within every key's bounds, a q_A whose sweep no support can be given
    ((("impeller_diameter = 0.3", "impeller_diameter = 0.01"),
      ("discharge_width = 0.02", "discharge_width = 1e-4"), ("power = 8000.0", "power = 1e8"),
      ("suction_density = 10.0", "suction_density = 1e-6"),
      ("discharge_density = 15.0", "discharge_density = 2000.0")),
     "stage at 0.2 m: q_A = 1.91e+21 N/m"),
    # a compressor stage whose densities are swapped: Q_A 0.44× the right way round
    ((("suction_density = 10.0", "suction_density = 20.0"),),
     "stage[0]: discharge_density 15 kg/m³ below suction_density 20 kg/m³"),
    # the stage on a disk name two disks carry
    ((("[[stage]]\nposition = 0.2", "[[disk]]\nname = \"wheel\"\nposition = 0.1\nmass = 1.0\n"
       "Ip = 0.01\nId = 0.005\n[[disk]]\nname = \"wheel\"\nposition = 0.3\nmass = 1.0\n"
       "Ip = 0.01\nId = 0.005\n[[stage]]\ndisk = \"wheel\""),),
     "stage[0].disk: 'wheel' names 2 disks"),
    # a rotor on one support: its journal load was a singular solve's
    ((("[[spring]]\nname = \"right\"", "[[seal]]\nname = \"right\""),
      ("kxx = 50000000.0\nkyy = 50000000.0\ncxx = 10000.0\ncyy = 10000.0\n[[stage]]",
       "K = { at_zero = 0.0, per_bar = 0.0 }\n[[stage]]")),
     "need the rotor held at two bearings at least"),
])
def test_signoffs_held_out_probes_are_refused_by_name(tmp_path, capsys, edits, says):
    """Inputs a new user tried, each answered with exit status 2 and one line naming the
    key or what is missing, where they gave a ZeroDivisionError or a pydantic traceback
    or a silently wrong Q_A or journal load."""
    rig = tmp_path / "probe.toml"
    rig.write_text(_edit(_rigid_rotor(1e8, 2.0e4, 8.0e3), *edits))
    code = main(["--quiet", "signoff", str(rig), "--out", str(tmp_path / "so")])
    err = capsys.readouterr().err
    assert code == 2 and says in err and "Traceback" not in err, err
    assert len(err.strip().splitlines()) == 1, err


def test_the_reports_signoff_section_says_the_verdict_first(tmp_path):
    """The run report's section: the overall verdict before the table, one row per
    controller and criterion with its source; the Level II table; both figures."""
    import tomllib

    from ambseal.analysis import sign_off
    from ambseal.config import parse_rig
    from ambseal.report import signoff_report

    ok = sign_off(parse_rig(tomllib.loads(_rigid_rotor(1e8, 2.0e4, 8.0e3))), name="a")
    bad = sign_off(parse_rig(tomllib.loads(_rigid_rotor(1e7, 2000.0, 2.0e5))), name="b")
    assert ok.passed and not bad.passed
    figs, sections = signoff_report(tmp_path, [ok, bad], "rigid")
    text = sections[0]["html"]
    assert text.index("Sign-off NOT passed — b: ") < text.index("<table>")
    assert text.count("<tr><td>") == 2 * 6 + 2 * 3  # criteria, then Level II rows
    assert "API 617 (8th ed., 2014) Part 1 §4.8.2, A_vl" in text
    assert all(png.is_file() for _, png in figs) and len(figs) == 2
    # beside, not over, the run's own figures (its worst-case unbalance.png)
    assert {png.name for _, png in figs} == {"level1.png", "api617_unbalance.png"}
    _, passed = signoff_report(tmp_path, [ok], "rigid")
    assert "Sign-off PASSED" in passed[0]["html"]


def test_a_critical_seen_at_two_probes_and_two_placements_is_counted_once():
    """The peaks every probe and unbalance case found are grouped by speed (within 1 %):
    four sightings of a 100 Hz resonance and two of one at 250 Hz are two critical
    speeds, where the line said "6 critical(s)"."""
    from types import SimpleNamespace

    from ambseal.analysis import critical_speeds_hz

    seen = [SimpleNamespace(speed_hz=f) for f in (250.0, 100.0, 100.4, 251.0, 100.2, 99.8)]
    assert critical_speeds_hz(seen) == pytest.approx([100.1, 250.5])
    assert critical_speeds_hz([]) == []


@pytest.mark.xdist_group("terminal_run")  # the session's run, made once on that worker
def test_signoff_into_a_runs_folder_is_refused(terminal_run, tmp_path, capsys):
    """`ambseal run R --out D` then `ambseal signoff R --out D` replaced the run's
    level1.png and api617_unbalance.png by the sign-off's while metrics.json and
    report.html still described the run's: refused, by name, with nothing changed."""
    import hashlib
    import shutil

    from ambseal.config import default_rig_path

    run = tmp_path / "run"
    shutil.copytree(terminal_run[0], run)
    before = {p.name: hashlib.sha256(p.read_bytes()).hexdigest()
              for p in run.iterdir() if p.is_file()}
    code = main(["--quiet", "signoff", str(default_rig_path()), "--out", str(run)])
    err = capsys.readouterr().err
    assert code == 2 and "holds the results of `ambseal run`" in err, err
    assert "Traceback" not in err and len(err.strip().splitlines()) == 1
    assert before == {p.name: hashlib.sha256(p.read_bytes()).hexdigest()
                      for p in run.iterdir() if p.is_file()}
