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


def test_a_remedy_at_zero_pressure_keeps_the_seal_uncertainty_it_was_given(monkeypatch):
    """The test rig's seal has k = 1.1 MN/m per bar from 0 (rig file), so at 0 bar the
    specification's default, k ± 100 % (P5 §4.1), has no width. The μ remedy designed at
    a failing 0 bar condition is given the range that default spans at the nominal
    2.04 bar instead, [0, 2 × 1.1e6 × 2.04] N/m, and the design's own check of it
    (``generalized_plant``'s) passes, where it had refused the remedy's own default."""
    import ambseal.app.remedies as rem
    from ambseal.design.plant import _ranges
    from ambseal.model import build_plant

    cfg = load_rig()
    spec = design_spec(cfg)
    points = operating_points(spec)
    zero = min(points, key=lambda p: p.pressure_bar)
    assert zero.pressure_bar == 0.0 and dict(spec.uncertainty) == {"seal.k": 1.0}
    given = []

    def fake_design(cfg_, method, *, pressure_bar, uncertainty=None, spec=None, **kw):
        given.append(uncertainty if uncertainty is not None else spec.uncertainty)
        _ranges(build_plant(cfg_, pressure_bar=pressure_bar), given[-1])  # the check
        raise rem.SynthesisError("stop here")

    monkeypatch.setattr(rem, "design", fake_design)
    failure = FailedController("μ: not delivered — ...", True, True, [zero.label])
    cases = [_case(p.pressure_bar, p is not zero, 1.0 if p is zero else -5.0, label=p.label)
             for p in points]
    _, f = remedy("mu", failure, cases, cfg, spec, points, None, lambda line: None)
    assert len(given) == 2 and "zero width" not in f.reason
    assert given[0]["seal.k"] == pytest.approx((0.0, 2 * 1.1e6 * 2.04), rel=1e-12)
    assert f.reason.count("the design failed: stop here") == 2
