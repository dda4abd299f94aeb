"""The remedies ``ambseal run`` tries before it reports a designed controller failed:
which condition is the worst, and that a design which then holds replaces the failed one."""

import pytest

from ambseal.analysis.delivery import FailedController
from ambseal.analysis.judge import operating_points
from ambseal.app.remedies import Remedied, remedy, worst_case
from ambseal.config import load_rig
from ambseal.design.specs import design_spec


def test_worst_case_is_the_least_stable_failing_condition():
    """Continuous instability first (largest real part), else the largest |z| as it runs."""
    ok = {"stable": True, "max_real_pole": -1.0, "discrete": {"stable": True,
                                                             "max_abs_pole_z": 0.99}}
    a = {"stable": False, "max_real_pole": 0.5, "pressure_bar": 0.0}
    b = {"stable": False, "max_real_pole": 2.0, "pressure_bar": 4.08}
    za = {"stable": True, "max_real_pole": -1.0, "pressure_bar": 1.0,
          "discrete": {"stable": False, "max_abs_pole_z": 1.001}}
    zb = {**za, "pressure_bar": 3.0, "discrete": {"stable": False, "max_abs_pole_z": 1.02}}
    assert worst_case([ok, a, b, zb]) is b
    assert worst_case([ok, za, zb]) is zb
    with pytest.raises(ValueError):
        worst_case([ok])


class _Stable:
    def __init__(self, point):
        self.point = point

    def to_dict(self):
        return {"stable": True, "pressure_bar": self.point.pressure_bar,
                "discrete": {"stable": True}}


def test_a_design_that_holds_after_the_first_remedy_replaces_the_failed_one():
    """H∞ failing at the top judged pressure is redesigned at that pressure (the summary
    says so); the judgement (here: every case stable) accepts the first attempt."""
    cfg = load_rig()
    spec = design_spec(cfg)
    points = operating_points(spec)
    top = max(points, key=lambda p: p.pressure_bar)
    cases = [{"stable": p is not top, "max_real_pole": 1.0 if p is top else -5.0,
              "pressure_bar": p.pressure_bar, "label": p.label} for p in points]
    failure = FailedController("H∞: not delivered — ...", True, True, [top.label])
    seen, lines = [], []

    def judge(designs, digitals):
        seen.append((designs[0].summary["pressure_bar"], set(digitals)))
        jobs = [{"name": "hinf", "point": p} for p in points]
        return jobs, [(_Stable(p), {}) for p in points]

    fixed, f = remedy("hinf", failure, cases, cfg, spec, points, judge, lines.append)
    assert isinstance(fixed, Remedied) and f is failure
    assert seen == [(pytest.approx(top.pressure_bar), {"hinf"})]
    assert fixed.design.summary["pressure_bar"] == pytest.approx(top.pressure_bar)
    assert fixed.design.summary["remedy"].startswith(f"designed at {top.label}: ")
    assert top.label in fixed.design.summary["remedy"].split("lost the loop at ")[1]
    assert len(fixed.jobs) == len(points) and lines[-1].endswith("holds at every judged "
                                                                  "condition")
