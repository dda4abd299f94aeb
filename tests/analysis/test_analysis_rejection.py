"""The unbalance force rejection judged (analysis/rejection.py) on the turboexpander: its
loops at the judged conditions and its synchronous response against the controller
alone."""

import numpy as np
import pytest

from ambseal.analysis.judge import OperatingPoint, judge_settings
from ambseal.analysis.rejection import rejection_effect, rejection_stability
from ambseal.design import design_rejection, design_spec


@pytest.fixture(scope="module")
def rejection(turbo_cfg, turbo_frozen, turbo_digital):
    return design_rejection(turbo_cfg, turbo_frozen.K, turbo_digital["hinf"])


def test_rejection_stability_judges_where_the_notch_is_on(turbo_cfg, rejection):
    """Conditions below the minimum continuous speed are left to the controller alone;
    at the others both loops are judged: stable, continuous and as it runs."""
    lo, hi = turbo_cfg.operating.continuous_hz
    p = turbo_cfg.operating.pressure_bar
    points = [OperatingPoint(p, 60 * f, f"{f:g} Hz") for f in (0.0, 0.5 * lo, lo, hi)]
    rows = rejection_stability(turbo_cfg, rejection, points)
    assert [r["condition"] for r in rows] == [f"{lo:g} Hz", f"{hi:g} Hz"]
    for r in rows:
        assert r["stable"] and r["stable_as_runs"] and r["max_abs_pole_z"] < 1
        assert r["max_real_pole"] < 0


def test_rejection_effect_takes_out_the_synchronous_current(turbo_cfg, turbo_digital,
                                                            rejection):
    """Over the speed range (its ends the notch's table's) the largest synchronous coil
    current with the notch is below 1 % of the controller's alone at every speed, while
    the bearings still transmit a force (their negative stiffness's) and the rotor
    still has an orbit."""
    s = judge_settings(design_spec(turbo_cfg))
    e = rejection_effect(turbo_cfg, turbo_digital["hinf"], rejection, s)
    lo, hi = turbo_cfg.operating.continuous_hz
    assert e["speed_hz"][0] == pytest.approx(lo) and e["speed_hz"][-1] == pytest.approx(hi)
    assert np.all(e["current_a"]["with"] < 1e-2 * e["current_a"]["without"])
    assert np.all(e["current_a"]["without"] > 0)
    assert np.all(e["force_n"]["with"] > 0) and np.all(e["orbit_um"]["with"] > 0)
