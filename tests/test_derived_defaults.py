"""ambseal's derived defaults never refuse a user's rig: the reference PID it derives for
a rig without ``[controller.pid]`` fits the rig's sample rate (every filter pole below
the Nyquist frequency), ``validate`` shows it with its rule, and a derived PID that still
cannot run on the target is a failed controller of the run, not a refused rig.

The rig: the G2-class flywheel of ``examples/flywheel.toml`` as a user might write a
variant of it, with a slimmer shaft (45/30 mm), sensors collocated with the actuators, no
``[design.rejection]``, at the example's 20 kHz. Its 1.85 kHz collocated bending mode
needs +135° of phase: a rule free to take any lead would take a 75° one, whose pole lies
at f_c·√α = 7.6 f_c = 14 kHz, above the 10 kHz Nyquist frequency, and the PID's rate check
would then refuse the rig."""

from __future__ import annotations

import json
from pathlib import Path

import control
import numpy as np
import pytest

from ambseal.cli import main
from ambseal.config import load_rig
from ambseal.design import design, reference_pid
from ambseal.design.pid import filter_matrices

EXAMPLE = Path(__file__).resolve().parents[1] / "examples" / "flywheel.toml"
EDITS = (("outer_diameter = 0.055", "outer_diameter = 0.045"),
         ("inner_diameter = 0.035", "inner_diameter = 0.03"),
         ("sensor_position = 0.015", "sensor_position = 0.04"),
         ("sensor_position = 0.245", "sensor_position = 0.22"))


@pytest.fixture(scope="module")
def slim_rig(tmp_path_factory) -> Path:
    text = EXAMPLE.read_text(encoding="utf-8")
    text = text[:text.index("[design.rejection]")]
    for old, new in EDITS:
        assert text.count(old) == 1
        text = text.replace(old, new)
    rig = tmp_path_factory.mktemp("slim") / "slim_flywheel.toml"
    rig.write_text(text, encoding="utf-8")
    return rig


def test_a_derived_lead_above_nyquist_leaves_the_rig_valid(slim_rig, capsys):
    """``validate`` exits 0 and shows the derived PID: its filters' poles (python-control's,
    of each filter's state space) lie below the Nyquist frequency, and its rule names the
    75° lead it left out, with that lead's pole (f_c·√α, α = (1 + sin 75°)/(1 − sin 75°))
    above Nyquist. The run reports the same rule among the PID's design notes."""
    assert main(["validate", str(slim_rig), "--json"]) == 0
    pid = json.loads(capsys.readouterr().out)["defaults"]["pid"]
    cfg = load_rig(slim_rig)
    nyquist = cfg.controller.sample_rate_hz / 2
    assert pid["derived"] is True and pid["filters"]
    for f in pid["filters"]:
        assert np.abs(control.ss(*filter_matrices(f)).poles()).max() / (2 * np.pi) < nyquist
    assert "(left out: lead 75°" in pid["rule"]
    at = float(pid["rule"].split("(left out: lead 75° at ")[1].split(" Hz")[0])
    s = np.sin(np.radians(75.0))
    pole = at * np.sqrt((1 + s) / (1 - s))
    assert pole > nyquist
    assert f"its pole at {pole:.4g} Hz above the Nyquist frequency {nyquist:.4g} Hz" \
        in pid["rule"]
    assert pid["rule"] == reference_pid(cfg)["rule"]
    assert any(pid["rule"] in n for n in design(cfg, "pid").notes)


def test_a_written_pid_the_target_cannot_run_is_still_refused(slim_rig, tmp_path, capsys):
    """What the user writes is still checked: the same rig with a 75° lead at 1.85 kHz
    written in ``[[controller.filter]]`` is refused by ``validate`` (exit 2) naming the
    sample rate and the PID's highest pole."""
    text = slim_rig.read_text(encoding="utf-8") + (
        '\n[[controller.filter]]\nkind = "lead"\nfrequency_hz = 1850.0\nphase_deg = 75.0\n')
    rig = tmp_path / "written.toml"
    rig.write_text(text, encoding="utf-8")
    assert main(["validate", str(rig)]) == 2
    err = capsys.readouterr().err
    assert "controller.sample_rate_hz = 20000 Hz is below twice the highest pole" in err


@pytest.mark.slow
def test_the_run_reports_the_pid_and_the_notch_it_tried(slim_rig, tmp_path):
    """``ambseal run --no-identify`` on the same rig (2 min of CPU): the run is not refused;
    the derived PID's notes in ``metrics.json`` name the lead left out; the derived PID,
    which as it runs leaves a bending mode unstable at the top speed, is reported unable
    to run on the target with the reason, and the run goes on with the other controllers.
    The LPV alone would need more than the bias current's linear range to hold the G2.5
    unbalance: the run switched its unbalance force rejection on by itself, and with it the
    rotor whirls about its axis of inertia by more than the backup clearance, which the
    failure says, with the clearance checked against the rig file."""
    out = tmp_path / "out"
    code = main(["--quiet", "run", str(slim_rig), "--no-identify", "--out", str(out)])
    assert code in (0, 1)
    m = json.loads((out / "metrics.json").read_text())
    assert any("(left out: lead" in n for n in m["controllers"]["pid"]["notes"])
    assert "pid cannot run on the target" in m["cannot_run"]["pid"]
    assert m["cannot_run"]["pid"].endswith("this PID is the one ambseal derives from the "
                                           "rig: set [controller.pid] (and "
                                           "[[controller.filter]]) to run your own")
    lpv = m["controllers"]["lpv"]
    assert lpv["capacity"]["bias_used"] > 1 and "rejection" in lpv
    backup_um = 1e6 * min(map(load_rig(slim_rig).backup_clearance, load_rig(slim_rig).amb))
    beyond = lpv["rejection"]["beyond"]
    assert beyond["clearance_um"] == pytest.approx(backup_um)
    assert beyond["orbit_um"] > backup_um
    assert ("its unbalance force rejection, switched on by the run, whirls the rotor about "
            f"its axis of inertia by {beyond['orbit_um']:.3g} µm, beyond the backup "
            f"bearing's clearance ({backup_um:.3g} µm)") in m["failed"]["lpv"]["reason"]

