"""The remedies ``ambseal run`` tries before it reports a designed controller failed:
which condition is the worst, and that a design which then holds replaces the failed one."""

import pytest

from ambseal.analysis.delivery import FailedController
from ambseal.analysis.judge import JudgeJob, operating_points
from ambseal.analysis.speed_range import SampledStability, StabilityCase
from ambseal.app.remedies import Remedied, remedy, worst_case
from ambseal.config import load_rig
from ambseal.design.specs import design_spec


def _case(p_bar, stable, max_real_pole, discrete=None, label=""):
    return StabilityCase("hinf", label, p_bar, 0.0, stable, max_real_pole, discrete)


def test_worst_case_is_the_least_stable_failing_condition():
    """Continuous instability first (largest real part), else the largest |z| as it runs."""
    ok = _case(2.04, True, -1.0, SampledStability(True, 0.99, 1e4))
    a = _case(0.0, False, 0.5)
    b = _case(4.08, False, 2.0)
    za = _case(1.0, True, -1.0, SampledStability(False, 1.001, 1e4))
    zb = _case(3.0, True, -1.0, SampledStability(False, 1.02, 1e4))
    assert worst_case([ok, a, b, zb]) is b
    assert worst_case([ok, za, zb]) is zb
    with pytest.raises(ValueError):
        worst_case([ok])


def test_a_design_that_holds_after_the_first_remedy_replaces_the_failed_one():
    """H∞ failing at the top judged pressure is redesigned at that pressure (the summary
    says so); the judgement (here: every case stable) accepts the first attempt."""
    cfg = load_rig()
    spec = design_spec(cfg)
    points = operating_points(spec)
    top = max(points, key=lambda p: p.pressure_bar)
    cases = [_case(p.pressure_bar, p is not top, 1.0 if p is top else -5.0, label=p.label)
             for p in points]
    failure = FailedController("H∞: not delivered — ...", True, True, [top.label])
    seen, lines = [], []

    def judge(designs, digitals):
        seen.append((designs[0].summary["pressure_bar"], set(digitals)))
        jobs = [JudgeJob("hinf", p, None) for p in points]
        return jobs, [(_case(p.pressure_bar, True, -5.0, SampledStability(True, 0.5, 1e4),
                             p.label), {}) for p in points]

    fixed, f = remedy("hinf", failure, cases, cfg, spec, points, judge, lines.append)
    assert isinstance(fixed, Remedied) and f is failure
    assert seen == [(pytest.approx(top.pressure_bar), {"hinf"})]
    assert fixed.design.summary["pressure_bar"] == pytest.approx(top.pressure_bar)
    assert fixed.design.summary["remedy"].startswith(f"designed at {top.label}: ")
    assert top.label in fixed.design.summary["remedy"].split("lost the loop at ")[1]
    assert len(fixed.jobs) == len(points) and lines[-1].endswith("holds at every judged "
                                                                  "condition")
