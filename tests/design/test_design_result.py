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
    assert bool(d.verdict) == (d.method != "pid")  # the PID has no bound of its own
    assert d.full_order is None or isinstance(d.full_order["stable"], bool)
    run = Designed(d)  # what the main job carries: the design's own method and summary
    assert (run.method, run.controller, run.summary) == (d.method, K, summary)
