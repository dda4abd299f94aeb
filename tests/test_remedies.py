"""The remedies ``ambseal run`` tries before it reports a designed controller failed:
which condition is the worst, and that a design which then holds replaces the failed one."""

import pytest

from ambseal.analysis.delivery import FailedController
from ambseal.analysis.judge import JudgeJob, operating_points
from ambseal.analysis.speed_range import SampledStability, StabilityCase
from ambseal.app.remedies import Remedied, remedy, worst_case, worst_zone_as_runs
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


def test_the_zone_as_it_runs_is_the_worst_axis_of_the_loop_that_runs():
    """ISO 14839-3 grades each control axis: a loop whose σ̄(S_o) over all axes is 5.8
    (coupled axes, family seed 17's sampled-plant H∞) but 2.1 on its worst axis is zone
    A; the sampled loop, where judged, is the one graded, not the continuous one."""
    def run(peak, axes):
        return SampledStability(True, 0.99, 1e4, peak, dict.fromkeys(axes, 2.1),
                                "D" if peak >= 5 else "A", axes)
    coupled = run(5.8, {"A_zeta": "A", "B_eta": "A"})
    assert worst_zone_as_runs([_case(0.0, True, -1.0, coupled)]) == "A"
    lost = StabilityCase("hinf", "", 0.0, 0.0, True, -1.0, run(4.2, {"A_zeta": "A",
                                                                      "B_eta": "C"}),
                         2.1, None, "A", {"A_zeta": "A", "B_eta": "A"})
    assert worst_zone_as_runs([_case(0.0, True, -1.0, coupled), lost]) == "C"
    # without per-axis grades, the grade of the whole loop
    assert worst_zone_as_runs([_case(0.0, True, -1.0, run(5.8, {}))]) == "D"
    assert worst_zone_as_runs([]) is None


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


def test_a_remedy_beside_the_speed_range_names_each_condition_by_its_speed(monkeypatch):
    """A rig judged at its operating point (labelled by its pressure drop alone, "0 bar",
    at the operating speed) and over the speed range ("0 bar, 0 Hz", …): a remedy whose
    design still loses the loop at the operating point and at standstill says so as
    "0 bar, <f0> Hz; 0 bar, 0 Hz", not "0 bar, 0 bar, 0 Hz", and its first attempt is
    named by the pressure it is designed at (0 bar), not by standstill, the speed of the
    worst condition, at which it is not designed. Without the speed range the words are
    the cases' labels."""
    import ambseal.app.remedies as rem

    cfg = load_rig()
    spec = design_spec(cfg)
    f0 = cfg.operating.speed_rpm / 60.0
    at_point = StabilityCase("hinf", "0 bar", 0.0, f0, False, 1.0)
    standstill = StabilityCase("hinf", "0 bar, 0 Hz", 0.0, 0.0, False, 2.0)
    held = StabilityCase("hinf", "0 bar, 100 Hz", 0.0, 100.0, True, -5.0)
    cases = [at_point, standstill, held]

    class Result:
        method = "hinf"

        def summary(self):
            return {"pressure_bar": 0.0}

    designed_at = []

    def fake_design(cfg_, method, *, pressure_bar, **kw):
        designed_at.append(pressure_bar)
        return Result()

    monkeypatch.setattr(rem, "design", fake_design)
    monkeypatch.setattr(rem, "digitals_for", lambda c, ds, pts: ({"hinf": object()}, {}))

    def judge(designs, digitals):
        return [None] * len(cases), [(c, {}) for c in cases]

    failure = FailedController("H∞: not delivered — ...", True, True,
                               ["0 bar", "0 bar, 0 Hz"])
    words = {}
    for with_speed in (True, False):
        _, f = remedy("hinf", failure, cases, cfg, spec, [], judge, lambda line: None,
                      speed_in_labels=with_speed)
        words[with_speed] = f.reason.split(". Tried: ")[1]
    assert designed_at == [0.0] * 4
    assert words[True].startswith(
        f"designed at 0 bar (still unstable at 0 bar, {f0:g} Hz; 0 bar, 0 Hz); designed "
        f"there with ω_B × {rem.OMEGA_B_FACTOR:g} (")
    assert words[True].count(f"(still unstable at 0 bar, {f0:g} Hz; 0 bar, 0 Hz)") == 2
    assert words[False].startswith("designed at 0 bar (still unstable at 0 bar; 0 bar, "
                                   "0 Hz)")
    # a remedy that holds says where the first design lost the loop, named the same way
    fixed, _ = remedy("hinf", failure, cases, cfg, spec, [],
                      lambda ds, digs: ([None], [(held, {})]), lambda line: None,
                      speed_in_labels=True)
    assert fixed.design.summary["remedy"] == (
        f"designed at 0 bar: the design at the operating point lost the loop at 0 bar, "
        f"{f0:g} Hz; 0 bar, 0 Hz")


def test_a_design_beyond_its_amplifier_is_designed_again_with_its_limit_in_w_u(monkeypatch):
    """A design whose loops hold but that needs 1.2× its amplifier at 400 Hz is designed
    again with W_u peaked there (by the route it took: scheduled on the spin speed), the
    peak raised by the fraction used over 0.8 and at least fourfold: 4, then 4 × 4 after
    a redesign that needs 1.1×; the one within its amplifier replaces it. A design that
    needs 4× starts at 4/0.8 = 5. A redesign that lowers the current by less than
    5 % ends the attempts; one beyond zone B (the first at A), or that fails what else
    the run delivers on (an orbit beyond a clearance), is refused. A first design that
    came by a remedy keeps that remedy's words ahead of this one's."""
    import numpy as np

    import ambseal.app.remedies as rem
    from ambseal.app.commands import Designed
    cfg = load_rig()
    spec = design_spec(cfg)

    class Result:
        method = "hinf"
        synthesis_plant = "continuous"
        scheduled = object()

        def summary(self):
            return {}

    class MuResult(Result):
        method = "mu"

    asked, iterations = [], []

    def fake_design(cfg_, method, *, spec=None, scheduled_on_speed=False, **kw):
        w = spec.weights[method]
        asked.append((w.wu_peak_hz, w.wu_peak_gain, w.wu_gain, scheduled_on_speed, kw))
        iterations.append((method, spec.mu_iteration))
        return Result() if method == "hinf" else MuResult()

    monkeypatch.setattr(rem, "design", fake_design)
    monkeypatch.setattr(rem, "digitals_for",
                        lambda c, ds, pts: ({ds[0].method: object()}, {}))

    def graded(zone):
        run = SampledStability(True, 0.5, 1e4, 2.0, {"A_zeta": 2.0}, zone, {"A_zeta": zone})
        return lambda ds, digs: ([None], [(_case(0.0, True, -5.0, run), {})])

    def fractions(*values):
        it = iter(values)
        return lambda jobs, judged: (np.array([400.0]), np.array([next(it)]))

    used = (np.array([300.0, 400.0, 420.0]), np.array([0.5, 1.2, 1.1]))
    first, lines = Designed(Result()), []
    fixed, cases, tried = rem.within_the_amplifier(
        first, used, "A", cfg, spec, [], graded("A"), lambda ds, digs: [],
        fractions(1.1, 0.7), lambda jobs, judged: None, lines.append)
    assert isinstance(fixed, Remedied) and cases == [] and tried == ""
    # the specification's weights with the peak (the recipe adds what it adds to its own)
    gain = spec.weights["hinf"].wu_gain
    assert asked == [(400.0, pytest.approx(4.0), gain, True, {}),
                     (400.0, pytest.approx(16.0), gain, True, {})]
    assert fixed.design.summary["remedy"].endswith(
        "it needs 1.2× its amplifier to hold the unbalance at 400 Hz")
    assert "within its amplifier (0.7× at most), zone A" in lines[-1]
    # a first design that came by a remedy keeps its story
    came = Designed(Result(), {"remedy": "designed on the sampled plant: lost as it runs"})
    fixed, _, _ = rem.within_the_amplifier(
        came, used, "A", cfg, spec, [], graded("A"), lambda ds, digs: [], fractions(0.7),
        lambda jobs, judged: None, lines.append)
    assert fixed.design.summary["remedy"].startswith(
        "designed on the sampled plant: lost as it runs; then designed with W_u × 4 at 400 Hz")
    asked.clear()
    fixed, _, tried = rem.within_the_amplifier(
        first, (used[0], used[1] * 4 / 1.2), "A", cfg, spec, [], graded("A"),
        lambda ds, digs: [], fractions(3.9), lambda jobs, judged: None, lines.append)
    assert fixed is None and tried.endswith("3.9× its amplifier (no lower)")
    assert [a[1] for a in asked] == [pytest.approx(5.0)]
    fixed, _, tried = rem.within_the_amplifier(
        first, used, "A", cfg, spec, [], graded("C"), lambda ds, digs: [],
        fractions(0.5), lambda jobs, judged: None, lines.append)
    assert fixed is None and tried.endswith("zone C as it runs")
    # less current where the bearings carried the unbalance is a larger orbit
    fixed, _, tried = rem.within_the_amplifier(
        first, used, "A", cfg, spec, [], graded("A"), lambda ds, digs: [],
        fractions(0.5), lambda jobs, judged: "its orbit exceeds the air gap", lines.append)
    assert fixed is None
    assert tried == "designed with W_u × 4 at 400 Hz: its orbit exceeds the air gap"
    # H∞ by its own iteration; μ by complex D–K, whose μ under the peak's demand beyond
    # the specification is not lifted into D–G–K's steps
    assert set(iterations) == {("hinf", spec.mu_iteration)} and spec.mu_iteration == "dgk"
    iterations.clear()
    fixed, _, _ = rem.within_the_amplifier(
        Designed(MuResult()), used, "A", cfg, spec, [], graded("A"), lambda ds, digs: [],
        fractions(0.7), lambda jobs, judged: None, lines.append)
    assert isinstance(fixed, Remedied) and iterations == [("mu", "dk")]
    assert fixed.design.summary["remedy"].startswith(
        "designed with W_u × 4 at 400 Hz by complex D–K: it needs 1.2×")
    with pytest.raises(ValueError):
        rem.within_the_amplifier(first, (np.array([1.0]), np.array([0.9])), "A", cfg, spec,
                                 [], None, None, None, None, None)


def test_a_design_lost_only_as_it_runs_is_designed_again_on_the_sampled_plant(monkeypatch):
    """The redesign is made on the sampled plant (``[design] synthesis_plant =
    "sampled"``, the rest of the rig as it was) with its unstable loops kept for the
    judgement, and judged as it runs alone: a loop lost there fails it though its
    continuous loop holds, in that loop's own words; where every loop as it runs holds it
    replaces the first, its remedy naming why."""
    import ambseal.app.remedies as rem
    from ambseal.app.commands import Designed

    cfg = load_rig()
    spec = design_spec(cfg)

    class Result:
        method = "hinf"
        synthesis_plant = "sampled"

        def summary(self):
            return {}

    asked = []

    def fake_design(cfg_, method, *, spec=None, **kw):
        asked.append((cfg_.design.synthesis_plant, cfg_.model_copy(update={
            "design": cfg.design}) == cfg, spec, kw))
        return Result()

    monkeypatch.setattr(rem, "design", fake_design)
    monkeypatch.setattr(rem, "digitals_for",
                        lambda c, ds, pts: ({ds[0].method: object()}, {}))
    lost = SampledStability(False, 1.02, 1e4)
    held = SampledStability(True, 0.98, 1e4)

    def judge(discrete, continuous=True):  # the loop as it runs, as given
        return lambda ds, digs: ([None], [(_case(0.0, continuous, -5.0 if continuous else 1.0,
                                                 discrete, "0 bar"), {})])

    fixed, cases, words = rem.on_the_sampled_plant(
        "hinf", "lost as it runs", cfg, spec, [], judge(lost), lambda ds, digs: [],
        lambda line: None)
    assert fixed is None and cases == []
    assert words.startswith("designed on the sampled plant (w-plane, its Tustin transform "
                            "the discrete design): ") and "0 bar" in words
    assert asked == [("sampled", True, spec, {"allow_unstable": True})]
    fixed, cases, words = rem.on_the_sampled_plant(
        "hinf", "lost as it runs", cfg, spec, [], judge(held), lambda ds, digs: [],
        lambda line: None)
    assert isinstance(fixed, Remedied) and words == ""
    assert isinstance(fixed.design, Designed)
    assert fixed.design.summary["remedy"] == (
        "designed on the sampled plant (w-plane, its Tustin transform the discrete "
        "design): lost as it runs")
    # its w-plane form closed in continuous time is not a loop that runs
    fixed, _, words = rem.on_the_sampled_plant(
        "hinf", "lost as it runs", cfg, spec, [], judge(held, continuous=False),
        lambda ds, digs: [], lambda line: None)
    assert isinstance(fixed, Remedied) and words == ""
