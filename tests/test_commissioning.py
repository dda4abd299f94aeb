"""The controller that levitates the virtual facility for the identification
(:func:`ambseal.app.commands.facility_controller`): a rig file whose own PID does not hold
the facility is identified with the PID derived from the rig, as a commissioning engineer
would levitate a new machine, instead of stopping the run."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from ambseal.app.commands import facility_controller, target_pid
from ambseal.app.pipeline import default_truth_path
from ambseal.cli import main
from ambseal.config import load_rig, load_truth
from ambseal.design import machine
from ambseal.errors import ModelError
from ambseal.identify import simulate_facility

TESTRIG = Path(__file__).resolve().parents[1] / "examples" / "testrig.toml"


def _weak_pid_rig(tmp_path) -> Path:
    """The test rig with Kp = 8000 A/m: Ki·Kp below Ks, the rotor's negative stiffness wins
    (the thesis's 1.6e4 gives Ki·Kp ≈ 1.3 Ks)."""
    rig = tmp_path / "weak_pid.toml"
    rig.write_text(TESTRIG.read_text().replace("\nkp = 1.6e4\n", "\nkp = 8000.0\n"))
    return rig


def test_a_pid_that_loses_the_facility_is_replaced_by_the_derived_one(tmp_path):
    """Reference: the facility's own simulation. The rig file's weak PID is refused before
    the run, as losing the rig file's own model (not blamed on the truth's τ_e and
    parameters); with the controller chosen the same excitation runs to the end with the
    rotor within a tenth of the gap, and the note names the pole that lost it."""
    cfg = load_rig(_weak_pid_rig(tmp_path))
    truth = load_truth(default_truth_path())
    weak = target_pid(cfg)
    chosen, note = facility_controller(cfg, truth, weak)
    assert chosen is not weak and chosen.description["kp"] > 1.5e4
    assert note.startswith("the rig file's PID does not hold the virtual facility") \
        and "|z| = 1.0" in note
    fs = cfg.controller.sample_rate_hz
    e = 0.02 * np.random.default_rng(1).choice([-1.0, 1.0], size=(int(0.2 * fs), 4))
    # refused before the run, the fault named: the rig file's own model is lost too
    with pytest.raises(ModelError, match="loses the rig file's own model there too"):
        simulate_facility(cfg, truth, e, fs, weak, pressure_bar=0.0)
    rec = simulate_facility(cfg, truth, e, fs, chosen, pressure_bar=0.0)
    assert np.abs(rec.displacement_m).max() < 0.1 * machine(cfg).air_gap_m


def test_a_pid_that_holds_the_facility_is_kept(tmp_path):
    cfg = load_rig(TESTRIG)
    pid = target_pid(cfg)
    assert facility_controller(cfg, load_truth(default_truth_path()), pid) == (pid, None)


@pytest.mark.slow
def test_run_identifies_a_rig_whose_own_pid_loses_the_facility(tmp_path, capsys):
    """`ambseal run` on the weak-PID rig with the test rig's truth: the identification
    runs with the derived PID (said in metrics' identification block and first in the
    report's identification section), every 95 % interval holds the true value, and only
    the rig file's PID is reported failing."""
    out = tmp_path / "o"
    main(["--quiet", "run", str(_weak_pid_rig(tmp_path)), "--truth",
          str(default_truth_path()), "--out", str(out)])
    assert "Traceback" not in capsys.readouterr().err
    m = json.loads((out / "metrics.json").read_text())
    ident = m["identification"]
    assert ident["levitated_by"].startswith("the rig file's PID does not hold")
    assert ident["converged"] and not ident["interval_check"]["missed"]
    assert set(m["failed"]) == {"pid"}
    assert "PID does not hold the virtual facility" in (out / "report.html").read_text()
