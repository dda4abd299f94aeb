"""Every design result offers the one protocol the layers above read
(:class:`ambseal.design.Design`): the PID, H∞ and μ of the test rig, the H∞ at one speed and
the LPV on speed of the turboexpander, and the controller tracked on the seal's k."""

from __future__ import annotations

import json

import control
import numpy as np
import pytest

from ambseal.app.commands import Designed
from ambseal.config import method, method_names
from ambseal.design import Design
from ambseal.machine import ScheduledController


@pytest.mark.parametrize("fixture, key", [
    ("testrig_designs", "pid"), ("testrig_designs", "hinf"), ("testrig_designs", "mu"),
    ("turbo_frozen", None), ("turbo_lpv", None),
    pytest.param("testrig_tracked", None, marks=pytest.mark.slow)])
def test_every_design_result_offers_the_design_protocol(request, fixture, key):
    d = request.getfixturevalue(fixture)
    d = d[key] if key else d
    assert isinstance(d, Design)
    assert d.method in method_names()
    K = d.controller
    if method(d.method).fixed:  # one LTI controller, m → A
        assert isinstance(K, control.StateSpace) and K.dt == 0
        assert [n.removeprefix("y_") for n in K.input_labels] == \
            [n.removeprefix("i_") for n in K.output_labels]
    else:  # scheduled: the fixed controller at each value of its parameter
        assert isinstance(K, ScheduledController)
        lo, hi = K.schedule
        for theta in (lo, 0.5 * (lo + hi), hi):
            Ka = K.at(theta)
            assert isinstance(Ka, control.StateSpace)
            assert np.all(np.isfinite(Ka.A)) and Ka.ninputs == Ka.noutputs
    summary = d.summary()
    assert summary["method"] == d.method
    json.dumps(summary)  # JSON-ready: numbers and names, no matrices
    assert isinstance(d.verdict, str)
    assert d.verdict  # never empty: the PID's says it has no bound of its own
    if d.method == "pid":
        assert "no design bound" in d.verdict
    assert d.full_order is None or isinstance(d.full_order["stable"], bool)
    run = Designed(d)  # what the main job carries: the design's own method and summary
    assert (run.method, run.controller, run.summary) == (d.method, K, summary)


def test_the_pids_verdict_says_it_has_no_bound_and_how_its_loop_holds(tmp_path, capsys):
    """Reference: the design's own full-order check (``full_order`` in design_pid.json).
    A verdict is never empty: the PID's says it has no design bound — derived from the
    rig by its rule, or the rig's [controller.pid] given — and ``ambseal design`` adds
    what its full-order check found, in the words of the synthesised designs' verdicts."""
    import tomllib

    from ambseal.cli import main
    from ambseal.config import parse_rig
    from ambseal.design import design, full_order_words

    from ..coil_rig import COIL_RIG
    from ..toml_text import dump

    doc = tomllib.loads(COIL_RIG)
    derived = design(parse_rig(doc), "pid").verdict
    assert derived == ("no design bound (γ, μ): a PID derived from the rig by its rule (no "
                       "[controller.pid]), not synthesised against one")
    doc["controller"] = {"pid": {"kp": 9000.0, "ti": 0.3, "td": 0.0039, "eps": 0.115},
                         "filter": [{"kind": "notch", "frequency_hz": 1266.44,
                                     "width_hz": 126.644, "depth_db": 20.0}]}
    rig = tmp_path / "rig.toml"
    rig.write_text(dump(doc))
    assert main(["design", str(rig), "--method", "pid", "--out", str(tmp_path / "o")]) == 0
    summary = json.loads(capsys.readouterr().out)
    written = json.loads((tmp_path / "o" / "design_pid.json").read_text())
    given = ("no design bound (γ, μ): the rig's reference PID ([controller.pid], P5 Eq. 6), "
             "given, not synthesised against one")
    for d in (summary, written):
        assert d["verdict"] == f"{given}; {full_order_words(d['full_order'])}"
    assert written["full_order"]["stable"] and summary["verdict"].endswith(
        "full-order loop stable at every judged condition")
