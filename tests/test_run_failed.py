"""``ambseal run`` when a controller fails: every controller judged and reported, the failed
ones marked with the reason (metrics.json, report, stderr), exit status 1 after the report."""

import json
import math

import numpy as np
import pytest

from ambseal.analysis.delivery import also_failed, loop_failure
from ambseal.analysis.speed_range import SampledStability, StabilityCase
from ambseal.cli import main
from ambseal.config import default_rig_path

from .metrics_schema import validate_metrics
from .report_agreement import check_report_agrees

#: the embedded rig's seal cross-coupling slope (N/m per bar), as its rig file states it
K_SLOPE = "k = { at_zero = 0.0, per_bar = 1.1e6 }"


def _strong_seal_rig(tmp_path, factor: float):
    """The embedded test rig with the seal's cross-coupling per bar multiplied by factor;
    its μ takes two D–K iterations (robust on it all the same: 12 → 18 s of design
    otherwise)."""
    text = default_rig_path().read_text()
    assert text.count(K_SLOPE) == 1 and "[design.mu]" not in text
    rig = tmp_path / "strong_seal.toml"
    rig.write_text(text.replace(K_SLOPE, f"k = {{ at_zero = 0.0, per_bar = {1.1e6 * factor} }}")
                   + "\n[design.mu]\nmax_iter = 2\n")
    return rig


def _run_failing(rig, out, capsys) -> tuple[dict, str]:
    """``ambseal run RIG --no-identify`` that must exit 1: its checked metrics.json and
    stderr."""
    code = main(["run", str(rig), "--no-identify", "--out", str(out)])
    err = capsys.readouterr().err
    assert code == 1, err
    m = json.loads((out / "metrics.json").read_text())
    validate_metrics(m)
    return m, err


def _case(p_bar, stable, label="", max_real_pole=None, discrete=None):
    """A judged condition's stability (the cases the main job's judgements make)."""
    return StabilityCase("hinf", label, p_bar, 0.0, stable,
                         max_real_pole if max_real_pole is not None else (0.7 if not stable
                                                                          else -3.0),
                         discrete)


def test_loop_failure_names_the_least_stable_mode():
    """The reason names the condition and the mode with the largest real part: a 557 Hz
    pair with σ = +0.7 1/s has ζ = −σ/|λ| = −0.7/(2π·557) = −2.0e-4 (closed form); a
    stable case is not named; a case unstable only as it runs names max |z|."""
    w = 2 * math.pi * 557.0
    bad = np.array([-5 + 2j * math.pi * 50, -5 - 2j * math.pi * 50, 0.7 + 1j * w, 0.7 - 1j * w])
    ok = np.array([-3 + 1j, -3 - 1j])
    dt = 1e-4
    zdisc = np.exp(np.array([0.2 + 2j * math.pi * 900, -1.0]) * dt)  # growing 900 Hz
    cases = [(_case(0.0, True), {"poles": ok}),
             (_case(4.08, False, "4.08 bar"), {"poles": bad}),
             (_case(2.04, True, discrete=SampledStability(False, float(abs(zdisc[0])), 1 / dt)),
              {"poles": ok, "discrete": {"poles": zdisc}})]
    f = loop_failure("hinf", cases, designed=True)
    assert f.reason.startswith("H∞: not delivered — the full-order loop is unstable at 4.08 bar")
    assert "mode at 557 Hz, ζ = −0.0002" in f.reason
    assert "as it runs on the target (sampled, delayed) the loop is unstable at 2.04 bar " \
           "(mode at 900 Hz" in f.reason
    assert f.conditions == ["4.08 bar", "2.04 bar"] and f.designed and f.judged
    assert loop_failure("mu", cases[:1], designed=True) is None
    pid = loop_failure("pid", cases[1:2], designed=False)
    assert pid.reason.startswith("PID (reference, given by the rig file)") and not pid.designed
    derived = loop_failure("pid", cases[1:2], designed=False, derived=True)
    assert derived.reason.startswith("PID (reference, derived from the rig): fails — ")


def test_a_loop_lost_only_to_the_delays_pade_approximation_says_so():
    """A condition whose continuous loop (the delay as its Padé approximation) loses a mode
    that the loop as it runs keeps is still a failure, worded as what was found: the Padé
    loop unstable there, the sampled one holding — not "the full-order loop is unstable",
    which ``export --controller`` (judging the file as it runs) would then contradict."""
    w = 2 * math.pi * 1323.0
    bad = np.array([0.3 + 1j * w, 0.3 - 1j * w])
    held = SampledStability(True, 0.9994, 1e4)
    f = loop_failure("pid", [(_case(0.0, False, "0 bar", discrete=held), {"poles": bad})],
                     designed=False, derived=True)
    zeta = f"{-0.3 / abs(bad[0]):.2g}".replace("-", "−")
    assert f.reason == ("PID (reference, derived from the rig): fails — the full-order loop "
                        "with the delay as its Padé approximation is unstable at 0 bar (mode "
                        f"at 1323 Hz, ζ = {zeta}), though as it runs on the target (sampled, "
                        "delayed) it holds there")
    assert f.conditions == ["0 bar"]
    # lost as it runs too: the full-order loop is unstable
    lost = SampledStability(False, 1.0003, 1e4)
    g = loop_failure("pid", [(_case(0.0, False, "0 bar", discrete=lost), {"poles": bad})],
                     designed=False, derived=True)
    assert "fails — the full-order loop is unstable at 0 bar (mode at 1323 Hz" in g.reason


def test_a_loop_judged_as_it_runs_alone_is_said_lost_as_it_runs():
    """A design on the sampled plant is judged as it runs alone (its case's loop and its
    discrete block the same sampled loop): its loss is said as the loop as it runs, with
    its largest |z| and the mode ln z / T gives (900 Hz, growing at 0.2 1/s)."""
    dt = 1e-4
    z = np.exp(np.array([0.2 + 2j * math.pi * 900, 0.2 - 2j * math.pi * 900, -1.0]) * dt)
    runs = SampledStability(False, float(abs(z[0])), 1 / dt)
    case = _case(0.0, False, "0 bar", max_real_pole=0.2, discrete=runs)
    curves = {"poles": np.log(z) / dt, "discrete": {"poles": z}}
    f = loop_failure("mu", [(case, curves)], designed=True, as_runs_only=True)
    assert f.reason.startswith("μ: not delivered — as it runs on the target (sampled, "
                               "delayed) the loop is unstable at 0 bar (mode at 900 Hz")
    assert f"max |z| = {abs(z[0]):.5f}" in f.reason and "full-order" not in f.reason
    assert f.conditions == ["0 bar"]
    # the same case of a design on the continuous plant: its continuous loop is lost
    assert loop_failure("mu", [(case, curves)], designed=True).reason.startswith(
        "μ: not delivered — the full-order loop is unstable at 0 bar (mode at 900 Hz")


def test_a_point_judged_at_one_speed_is_named_with_its_speed_beside_the_speed_range():
    """A rig judged in full at one speed (305.185 Hz) labels that point by its pressure
    alone; where the run also judges the speed range, its failure had read "unstable at
    0 bar (…); … unstable at 0 bar, 0 Hz", not saying at which speed the first was lost.
    With ``speed_in_labels`` the line names it "0 bar, 305.185 Hz", a label that already
    has its speed stays as it is, and the failure's conditions keep the cases' labels."""
    w = 2 * math.pi * 557.0
    bad = {"poles": np.array([0.7 + 1j * w, 0.7 - 1j * w])}
    judged = StabilityCase("hinf", "0 bar", 0.0, 305.185, False, 0.7, None)
    ranged = StabilityCase("hinf", "0 bar, 98.66 Hz", 0.0, 98.66, False, 0.7, None)
    f = loop_failure("hinf", [(judged, bad), (ranged, bad)], designed=True,
                     speed_in_labels=True)
    assert f.reason.startswith("H∞: not delivered — the full-order loop is unstable at "
                               "0 bar, 305.185 Hz (mode at 557 Hz")
    assert "and 0 bar, 98.66 Hz (mode at 557 Hz" in f.reason
    assert f.conditions == ["0 bar", "0 bar, 98.66 Hz"]
    alone = loop_failure("hinf", [(judged, bad)], designed=True)
    assert alone.reason.startswith("H∞: not delivered — the full-order loop is unstable at "
                                   "0 bar (mode")


def test_many_unstable_conditions_are_listed_with_the_least_stable_mode():
    """Beyond four unstable conditions the line lists them and names the mode of the one
    with the rightmost pole (σ = 2 of 0.1–2 here: a 50 Hz pair, ζ = −2/|λ|, closed form)."""
    cases = []
    for k, sigma in enumerate((0.1, 0.5, 2.0, 0.3, 0.2)):
        lam = sigma + 2j * math.pi * (50.0 if sigma == 2.0 else 80.0)
        cases.append((_case(0.0, False, f"0 bar, {10 * k} Hz", sigma),
                      {"poles": np.array([lam, lam.conjugate()])}))
    f = loop_failure("mu", cases, designed=True)
    zeta = -2.0 / abs(2.0 + 2j * math.pi * 50.0)
    assert ("unstable at 5 conditions: 0 bar, 0 Hz; 0 bar, 10 Hz; 0 bar, 20 Hz; "
            "0 bar, 30 Hz; 0 bar, 40 Hz (the least stable 0 bar, 20 Hz: mode at 50 Hz, "
            f"ζ = {zeta:.2g})").replace("-", "−") in f.reason
    assert f.conditions == [f"0 bar, {10 * k} Hz" for k in range(5)]


def test_a_failure_found_later_adds_its_conditions():
    """A controller that failed at a judged condition (with the remedies tried in its
    reason) and fails again from standstill to the top speed: one line, the first reason
    whole, then the new conditions without a second head; the conditions of both."""
    w = 2 * math.pi * 300.0
    up = np.array([0.5 + 1j * w, 0.5 - 1j * w])
    first = loop_failure("hinf", [(_case(4.08, False, "4.08 bar"), {"poles": up})],
                         designed=True)
    first = type(first)(first.reason + ". Tried: designed at 4.08 bar (still unstable)",
                        first.designed, first.judged, first.conditions)
    more = loop_failure("hinf", [(_case(0.0, False, "0 bar, 0 Hz"), {"poles": up})],
                        designed=True)
    both = also_failed(first, more)
    assert both.reason.startswith(first.reason + "; the full-order loop is unstable at "
                                  "0 bar, 0 Hz (mode at 300 Hz")
    assert both.reason.count("not delivered") == 1
    assert both.conditions == ["4.08 bar", "0 bar, 0 Hz"]
    assert also_failed(None, more) is more


@pytest.mark.heavy
def test_run_with_a_failing_controller_writes_the_report_and_exits_1(tmp_path, capsys):
    """The embedded rig with the seal's cross-coupling per bar tripled: H∞, designed on the
    nominal plant, loses the loop at 0 and 4.08 bar (a plant three times as far from its
    design point). The run still judges and reports all three controllers, marks H∞ with
    the conditions its judged cases are unstable at, exports no H∞ files, names it on
    stderr and exits 1; μ, robust to the seal's k over 0–2× nominal, is stable at every
    judged condition and delivered."""
    rig = _strong_seal_rig(tmp_path, 3.0)
    out = tmp_path / "run"
    m, err = _run_failing(rig, out, capsys)
    by = {}
    for c in m["cases"]:
        by.setdefault(c["controller"], []).append(c)
    assert set(by) == {"pid", "hinf", "mu"}  # every controller judged
    assert all(c["stable"] and c["discrete"]["stable"] for c in by["mu"])
    assert "mu" not in m["failed"]
    f = m["failed"]["hinf"]
    unstable = [f"{c['pressure_bar']:g} bar" for c in by["hinf"]
                if not (c["stable"] and c["discrete"]["stable"])]
    assert unstable and f["conditions"] == unstable and f["designed"] and f["judged"]
    assert f["reason"].startswith("H∞: not delivered — the full-order loop is unstable at ")
    # before that, the remedies: designed at the least stable failing condition, then with
    # the performance bandwidth halved there; neither holds on this rig
    worst = max((c for c in by["hinf"] if not c["stable"]), key=lambda c: c["max_real_pole"])
    assert f"Tried: designed at {worst['pressure_bar']:g} bar (still unstable at " in f["reason"]
    assert "designed there with ω_B × 0.5" in f["reason"]
    assert f["reason"].endswith("μ is the robust controller")
    assert f"ambseal: {f['reason']}" in err
    # the reference PID fails too (unstable from 2.04 bar) but is the user's: marked only
    assert not m["failed"]["pid"]["designed"]
    files = {p.name for p in (out / "controllers").iterdir()}
    assert "controller_mu.json" in files and not any("hinf" in n for n in files)
    # the files say which loop holds: the failed reference with the run's reason
    pid = json.loads((out / "controllers" / "controller_pid.json").read_text())
    assert pid["loop_holds"] == "no" and pid["allow_unstable"] == "no"
    assert pid["verdict"] == "does NOT hold: " + m["failed"]["pid"]["reason"]
    assert "AMBSEAL_PID_JUDGED_HOLDS 0" in (out / "controllers" / "ambseal_pid.h").read_text()
    mu = json.loads((out / "controllers" / "controller_mu.json").read_text())
    assert mu["loop_holds"] == "yes" and mu["verdict"].startswith("holds as it runs at every")
    assert "AMBSEAL_MU_JUDGED_HOLDS 1" in (out / "controllers" / "ambseal_mu.h").read_text()
    html = (out / "report.html").read_text()
    assert "Failed controllers" in html and html.index("Failed controllers") < html.index(
        "Verdict") and "H∞: not delivered" in html
    check_report_agrees(out)


@pytest.mark.slow
def test_run_allow_unstable_delivers_the_failed_controller_marked(tmp_path, capsys):
    """With --allow-unstable the unstable H∞ is exported, still marked, and the exit status
    is 0."""
    rig = _strong_seal_rig(tmp_path, 3.0)
    out = tmp_path / "run"
    assert main(["run", str(rig), "--no-identify", "--allow-unstable", "--out", str(out)]) == 0
    m = json.loads((out / "metrics.json").read_text())
    assert m["failed"]["hinf"]["designed"]
    hinf = json.loads((out / "controllers" / "controller_hinf.json").read_text())
    assert hinf["loop_holds"] == "no" and hinf["allow_unstable"] == "yes"
    assert "H∞: delivered as asked (allow_unstable) but fails" in capsys.readouterr().err


#: example rigs with their seals' cross-coupling slopes, tripled in the strengthened runs
STRONGER = {"pump.toml": ("k = { at_zero = 0.0, per_bar = 4.0e4 }",
                          "k = { at_zero = 0.0, per_bar = 1.0e4 }"),
            "blower.toml": ("k = { at_zero = 0.0, per_bar = 3.0e4 }",)}


@pytest.mark.slow
@pytest.mark.parametrize("example", sorted(STRONGER))
def test_run_on_a_stronger_seal_reports_every_controller(example, tmp_path, capsys):
    """An example rig with its seals' cross-coupling per bar tripled: the run writes its
    report; μ (robust to every seal's k over 0–2× nominal, which a tripled slope keeps
    covering since k is proportional to the pressure drop) is stable at every judged
    condition, continuous and as it runs; every other controller is either stable there
    and from standstill to the top speed, or listed in ``failed`` with exactly the
    conditions its loops are unstable at."""
    from .conftest import ROOT

    text = (ROOT / "examples" / example).read_text()
    for line in STRONGER[example]:
        assert text.count(line) == 1
        slope = float(line.split("per_bar = ")[1].rstrip(" }"))
        text = text.replace(line, line.replace(line.split("per_bar = ")[1].rstrip(" }"),
                                               repr(3 * slope)))
    rig = tmp_path / example
    rig.write_text(text)
    out = tmp_path / "run"
    code = main(["run", str(rig), "--no-identify", "--out", str(out)])
    err = capsys.readouterr().err
    m = json.loads((out / "metrics.json").read_text())
    assert (out / "report.html").is_file()
    designed_failed = [k for k, f in m["failed"].items() if f["designed"]]
    assert code == (1 if designed_failed else 0), err
    by = {}
    for c in m["cases"]:
        by.setdefault(c["controller"], []).append(c)
    assert all(c["stable"] and c["discrete"]["stable"] for c in by["mu"])
    for name, cases in by.items():
        # unstable at a judged condition, or where the machine runs up (stability cases)
        checked = cases + [c for c in m["stability"] if c["controller"] == name]
        bad = [c for c in checked if not (c["stable"] and (c.get("discrete") or {}).get(
            "stable", True))]
        assert (name in m["failed"]) == bool(bad)
        if bad:
            assert len(m["failed"][name]["conditions"]) == len(bad)
            assert f"ambseal: {m['failed'][name]['reason']}" in err


@pytest.mark.heavy
def test_a_controller_whose_amplifier_saturates_is_not_delivered(tmp_path, capsys, request,
                                                                 design_cache_for):
    """The embedded rig with a 1 V supply and 10 mH coils (R = 0): holding the judged
    unbalance needs about 2.7 V (|jΩL|·i near the top of the unbalance band), so H∞ and μ,
    stable everywhere, fail on their amplifiers: marked with the condition, the speed and
    the axis, not exported, exit 1; the fraction in metrics.json is the one the reason
    names."""
    text = default_rig_path().read_text()
    assert text.count("current_limit = 6.0\n") == 2
    rig = tmp_path / "weak_amplifier.toml"
    rig.write_text(text.replace("current_limit = 6.0\n", "current_limit = 6.0\n"
                                "supply_voltage = 1.0\ninductance = 0.01\n"))
    out = tmp_path / "run"
    cache = design_cache_for(request)
    with cache.patched("testrig"):  # the designs do not read the amplifier's limits
        m, err = _run_failing(rig, out, capsys)
    assert {"design:hinf", "design:mu"} <= set(cache.hits)
    for name in ("hinf", "mu"):
        cap = m["controllers"][name]["capacity"]
        assert cap["voltage_used"] > 1 and cap["current_used"] < 1
        w = cap["worst"]["voltage_used"]
        f = m["failed"][name]
        assert f["designed"] and f["judged"] and f["conditions"] == [w["condition"]]
        assert (f"the amplifier saturates holding the unbalance: it needs "
                f"{cap['voltage_used']:.3g}× the supply voltage") in f["reason"]
        assert f"{60 * w['speed_hz']:,.0f} rpm".replace(",", " ") in f["reason"]
        assert f"ambseal: {f['reason']}" in err
    assert not any("hinf" in p.name or "mu" in p.name for p in (out / "controllers").iterdir())
    check_report_agrees(out)
