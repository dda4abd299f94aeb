"""The main job on the embedded thesis test facility."""

import copy
import json
import re

import jsonschema
import numpy as np
import pytest

from ambseal.cli import main

from .browser import chromium, probe
from .metrics_schema import validate_metrics
from .report_agreement import check_report_agrees

# with every other reader of the session's embedded run (conftest.terminal_run): one worker
pytestmark = pytest.mark.xdist_group("terminal_run")

#: ISO 14839-3:2006 zone A/B boundary of the sensitivity peak (3, i.e. 9.5 dB; P5 §4.1).
ISO_ZONE_A_LIMIT = 3.0
#: Thesis demand on the worst-case G2.5 unbalance orbit up to 200 Hz (P5 §4.4.1): 8 µm.
ORBIT_DEMAND_UM = 8.0

KEYS = {
    "controller", "pressure_bar", "stable", "max_real_pole", "sensitivity_peak",
    "sensitivity_peak_per_axis", "iso_zone", "iso_zone_per_axis", "compliance_peak_m_per_n",
    "unbalance_peak_um", "impulse_peak_um", "impulse_settling_s",
}


@pytest.fixture(scope="module")
def metrics(terminal_run):
    """(output folder, metrics.json) of :func:`terminal_run`."""
    return terminal_run[:2]


def test_metrics_json_fits_the_shipped_schema(metrics):
    """Reference: JSON Schema 2020-12 — the embedded run's document validates; the same
    document with a case's ``stable`` renamed, a wrong type, or another version does not."""
    _, m = metrics
    validate_metrics(m)
    for break_it in (lambda d: d["cases"][0].update(ok=d["cases"][0].pop("stable")),
                     lambda d: d["cases"][0].update(sensitivity_peak="high"),
                     lambda d: d.update(schema_version="0.9.0"),
                     lambda d: d["controllers"]["mu"].pop("order")):
        broken = copy.deepcopy(m)
        break_it(broken)
        with pytest.raises(jsonschema.ValidationError):
            validate_metrics(broken)


def test_the_report_says_what_the_loops_were_judged_on(metrics):
    """The embedded run judges on the virtual facility's truth, not the rig file: the
    report's header says so, lists where the truth differs (its parameters and its
    eddy-current lag) and links the manual's section that explains it."""
    out, _ = metrics
    page = (out / "report.html").read_text(encoding="utf-8")
    line = page.split('<p class="judged">', 1)[1].split("</p>", 1)[0]
    assert "virtual facility&#x27;s truth" in line and "testrig_truth.toml" in line
    assert "τ_e" in line and "seal" in line
    assert 'href="' in line and "getting-started.md#what-it-judged-on" in line


def test_run_on_a_terminal_ends_with_the_verdict_and_the_report_path(terminal_run):
    """On a terminal (a pseudo-terminal here) the run shows its stages with their times,
    ends with the verdict table (the report's first screen in text) and the path of
    report.html, and stdout's last line is still the one JSON line."""
    import re

    out, m, screen = terminal_run
    text = re.sub(r"\x1b\[[0-9;?]*[A-Za-z]", "", screen)  # ANSI styles and cursor moves
    for stage in ("model", "design", "judge", "identification", "report"):
        assert stage in text
    assert "Verdict" in text and "Not acceptable" in text  # the PID at 4.08 bar
    assert f"report: {(out / 'report.html').resolve()}" in text.replace("\r", "")
    last = [ln for ln in text.replace("\r", "\n").splitlines() if ln.strip()][-1]
    assert json.loads(last)["report"] == str(out / "report.html")


def test_every_report_verdict_agrees_with_metrics_json(metrics, turbo_run):
    """Every verdict of report.html read back (the verdict and detail tables' zones and
    words, the speed-range table) against metrics.json's numbers graded by ISO
    14839-3:2006's limits: the embedded rig (its PID lost at 4.08 bar) and the
    turboexpander (four controllers over 20–300 Hz)."""
    for out in (metrics[0], turbo_run):
        check_report_agrees(out)


def test_run_writes_the_contract(metrics):
    """metrics.json keys of its schema, the figures and a self-contained report, and no
    temporary file left behind (writes go through a rename)."""
    out, m = metrics
    assert {"rig", "open_loop", "cases"} <= set(m)
    assert set(m["open_loop"]) == {"unstable_poles", "n_states_full", "n_states_reduced"}
    from ambseal.config import load_rig
    from ambseal.model.rotor import build_mesh

    n_nodes = build_mesh(load_rig()).n_nodes
    # [q; q̇] with 4 DOF per node, plus 2 states of each of the 4 second-order actuators
    assert m["open_loop"]["n_states_full"] == 8 * n_nodes + 8
    for case in m["cases"]:
        assert KEYS <= set(case)
        # the discrete block: the same keys for the controller that runs
        assert KEYS - {"controller", "pressure_bar"} | {"max_abs_pole_z"} <= set(case["discrete"])
        if case["stable"]:  # every recommended controller runs stably where it was designed to
            assert case["discrete"]["stable"] and case["discrete"]["max_abs_pole_z"] < 1.0
    files = {p.name for p in (out / "controllers").iterdir()}
    for meth in ("pid", "hinf", "mu"):
        assert {f"controller_{meth}{e}" for e in (".json", ".npz", ".mat")} <= files
        assert {f"ambseal_{meth}.h", f"ambseal_{meth}.c"} <= files
    names = {p.name for p in out.iterdir()}
    assert {"metrics.json", "report.html", "sensitivity.png", "compliance.png",
            "unbalance.png", "impulse.png", "controller_gains.png", "identification.json",
            "identified_rig.toml", "ident_fit.png", "ident_correlation.png",
            "ident_seal_frequency.png", "ident_seal_pressure.png", "ident_frf.png",
            "ident_plant_frf.png", "facility_impulse.png", "controllers"} <= names
    assert not [n for n in names if n.endswith(".tmp")]
    html = (out / "report.html").read_text()
    assert "data:image/png;base64," in html and "<img src=\"http" not in html


def test_run_reproduces_the_thesis_findings(metrics):
    """Open loop unstable; PID stable at 0 and 2.04 bar, unstable at 4.08 bar
    (P5 §4.4.2, Fig. 13); reduced model of 8 rigid-body states plus the actuators."""
    _, m = metrics
    assert len(m["open_loop"]["unstable_poles"]) >= 2
    assert m["open_loop"]["n_states_reduced"] == 8 + 2 * 4
    by_p = {c["pressure_bar"]: c for c in m["cases"] if c["controller"] == "pid"}
    assert sorted(by_p) == [0.0, 2.04, 4.08]
    assert by_p[0.0]["stable"] and by_p[2.04]["stable"] and not by_p[4.08]["stable"]
    assert by_p[4.08]["iso_zone"] == "D" and by_p[4.08]["sensitivity_peak"] is None
    # the seal degrades the loop: higher sensitivity peak and compliance at nominal pressure
    assert by_p[2.04]["sensitivity_peak"] > by_p[0.0]["sensitivity_peak"]
    assert by_p[2.04]["compliance_peak_m_per_n"] > by_p[0.0]["compliance_peak_m_per_n"]
    assert 0 < by_p[0.0]["impulse_settling_s"] < 0.3


def test_run_bad_rig_exits_2(tmp_path, capsys):
    """A bad rig: one line on stderr, exit 2."""
    rig = tmp_path / "bad.toml"
    rig.write_text("[[shaft]]\nlength = 1\n")
    assert main(["run", str(rig), "--out", str(tmp_path / "o")]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "bad.toml" in err[0]


def test_run_identifies_the_virtual_facility(metrics):
    """The identification stage (P2, P4, P5 procedure) on the embedded rig's virtual
    facility: every AMB factor within 2 %, τ_e within 10 %, the coupling within 5 % of the
    packaged truth, and the identified rig file loads (issue acceptance, seed fixed); the
    seal damping the joint AMB fit holds at the rig file's values (the truth's differ) is
    disputed by its model check. The seal's impulse run at 2.5 bar is skipped: the
    reference PID does not hold the facility's rotor there ("the rotor-bearing-seal system
    with PID controller turns unstable for high pressures", P5 §5.1; the facility's loop
    poles are checked against the fit model's in tests/identify/test_identify_facility.py)."""
    from ambseal.config import load_rig

    out, m = metrics
    ident = m["identification"]["parameters"]
    for name, row in ident.items():
        if name.split(".")[-1].startswith(("Ki_", "Ks_")):
            assert abs(row["error_pct"]) < 2.0, name
        elif name == "tau_e":
            assert abs(row["error_pct"]) < 10.0
        elif name.startswith("coupling."):
            assert abs(row["error_pct"]) < 5.0, name
    k = ident["seal.k"]
    assert k["slope"] == pytest.approx(k["truth"]["per_bar"], rel=0.05)
    # stages (a)+(b) hold the seal's 0-bar damping at the rig file's C = 100, c = 300 N·s/m;
    # the truth has 150 and 250: the model check names both, and the report says so
    check = m["identification"]["model_check"]
    assert check["mismatch"] and set(check["disputed"]) == {"seal.C", "seal.c"}
    assert "seal.C: the data suggest +" in (out / "report.html").read_text(encoding="utf-8")
    rig = load_rig(out / "identified_rig.toml")
    assert rig.seal[0].k.per_bar == pytest.approx(k["slope"])
    runs = json.loads((out / "identification.json").read_text(encoding="utf-8"))
    # a quarter to 1.25× the nominal 2.04 bar (the thesis's 0.5–2.5 bar within 2 %)
    assert [r["pressure_bar"] for r in runs["seal_vs_pressure"]] == pytest.approx(
        [0.51, 1.02, 1.53, 2.04])
    assert [r["pressure_bar"] for r in runs["seal_pressures_skipped"]] == pytest.approx([2.55])


def test_run_sets_its_intervals_against_the_facilitys_truth(metrics):
    """Reference: the packaged truth file. Each scalar interval's ``covered`` flag is
    ``lo ≤ truth ≤ hi`` recounted here, each seal line's is both coefficients within 1.96
    standard errors of the true line; the interval check counts them. A truth moved just
    outside one interval is one miss in fifteen (chance: a binomial tail of 54 % at a 5 %
    miss rate); three such misses (tail 3.6 %) or one by three interval widths are called a
    mismatch, with the name, the estimate, the interval and the truth in the verdict."""
    from ambseal.identify.fitting.checks import interval_check

    _, m = metrics
    errors = m["identification"]["parameters"]
    n = 0
    for name, e in errors.items():
        t = e["truth"]
        if "ci95" in e and isinstance(t, float):
            assert e["covered"] == (e["ci95"][0] <= t <= e["ci95"][1]), name
            n += 1
        elif isinstance(t, dict):
            assert e["covered"] == (abs(e["intercept"] - t["at_zero"]) <= 1.96 * e["intercept_se"]
                                    and abs(e["slope"] - t["per_bar"]) <= 1.96 * e["slope_se"])
            n += 1
    check = m["identification"]["interval_check"]
    assert check["checked"] == n and check == interval_check(errors)
    ki = dict(errors["A.Ki_zeta"])
    lo, hi = ki["ci95"]
    near = {**errors, "A.Ki_zeta": {**ki, "truth": hi + 0.01 * (hi - lo), "covered": False}}
    assert not interval_check(near)["mismatch"]
    three = dict(near)
    for name in ("A.Ks_zeta", "B.Ki_eta"):
        e = errors[name]
        three[name] = {**e, "truth": e["ci95"][0] - 0.01 * (e["ci95"][1] - e["ci95"][0]),
                       "covered": False}
    assert interval_check(three)["mismatch"] and len(interval_check(three)["missed"]) == 3
    far = {**errors, "A.Ki_zeta": {**ki, "truth": hi + 3 * (hi - lo), "covered": False}}
    verdict = interval_check(far)
    assert verdict["mismatch"] and verdict["missed"][-1] == "A.Ki_zeta"
    assert "A.Ki_zeta" in verdict["verdict"] and "understate" in verdict["verdict"]


def test_run_explains_every_target_difference_above_10_percent(metrics):
    """On the embedded rig each controller's discrete σ̄(S_o) peak is
    within 10 % of its continuous one (the continuous loop with the controller's delay), or
    the run's summary explains the difference: ``peak_difference`` of every controller is
    the largest difference of its judged cases, carries an ``explanation`` exactly when it
    exceeds 10 %, and the report's verdict and its "On the target" section say so. The PID
    and μ loops (the μ design carries the delay) stay within 2 %, as measured."""
    import html as _html

    out, m = metrics
    text = _html.unescape((out / "report.html").read_text())
    for name, ctrl in m["controllers"].items():
        cases = [c for c in m["cases"] if c["controller"] == name
                 and c["sensitivity_peak"] and c["discrete"]["sensitivity_peak"]]
        worst = max(abs(c["discrete"]["sensitivity_peak"] / c["sensitivity_peak"] - 1)
                    for c in cases)
        pd = ctrl["discretisation"]["peak_difference"]
        assert pd["relative"] == pytest.approx(worst, rel=1e-12)
        assert ("explanation" in pd) == (worst > 0.10) == (not pd["within_tolerance"])
        if worst > 0.10:
            assert pd["explanation"] in text
            assert f"differs from the continuous one by {100 * worst:.0f} %" in text
    for name in ("pid", "mu"):
        assert m["controllers"][name]["discretisation"]["peak_difference"]["relative"] < 0.02


def test_run_judges_hinf_and_mu_as_the_thesis_found(metrics):
    """P5 §4.4, §5, judged on the virtual facility's truth: on the full-order plant the H∞ controller designed at nominal pressure
    has a lower σ̄(S_o) peak than the PID there; the μ controller is stable from 0 to 2×
    nominal with σ̄(S_o) of every control axis in ISO 14839-3 zone A (< 3; the standard
    judges the sensitivity axis by axis; the MIMO σ̄ of the loop with the controller's
    delay, on the truth, is stated in metrics.json and may exceed it); "both the H∞ and μ controllers ensure
    an orbit below 8 µm over the 200 Hz frequency range" (§4.4.1, G2.5 at 500 Hz, ISO
    21940-11 law); at 0 bar the μ controller settles the impulse no slower than the H∞
    ("an improvement in terms of settling time", §5.2 item 3)."""
    _, m = metrics
    case = {(c["controller"], c["pressure_bar"]): c for c in m["cases"]}
    assert case[("hinf", 2.04)]["stable"]
    assert case[("hinf", 2.04)]["sensitivity_peak"] < case[("pid", 2.04)]["sensitivity_peak"]
    for p in (0.0, 2.04, 4.08):
        mu = case[("mu", p)]
        assert mu["stable"] and max(mu["sensitivity_peak_per_axis"].values()) < ISO_ZONE_A_LIMIT
        assert set(mu["iso_zone_per_axis"].values()) == {"A"}
        assert mu["unbalance_peak_um"] < ORBIT_DEMAND_UM
        assert case[("hinf", p)]["unbalance_peak_um"] < ORBIT_DEMAND_UM
    assert m["unbalance"]["law"] == "iso21940" and m["unbalance"]["max_speed_hz"] == 500.0
    assert case[("mu", 0.0)]["impulse_settling_s"] <= case[("hinf", 0.0)]["impulse_settling_s"]
    assert set(m["controllers"]) == {"pid", "hinf", "mu"}


def test_run_designs_from_the_identified_rig(metrics):
    """P5 §3, Figs. 15–16: H∞ and μ designed on the identified rig (the truth
    file's Ki differ from the rig file's by ~3 %, far beyond the intervals), judged on the
    facility's truth, and their impulse responses on the facility matched by the identified
    model ("the experimental and simulated responses match well": NRMSE fit above 90 % on
    the excited axes A_ζ, B_η and above 80 % on the smaller cross-coupled ones, each peak
    within 10 %)."""
    out, m = metrics
    ident = m["identification"]
    assert ident["design"]["designed_on"] == "identified rig"
    assert "A.Ki_zeta" in ident["design"]["outside_intervals"]
    assert "truth" in ident["judged_on"]
    runs = {(c["controller"], c["pressure_bar"]): c for c in ident["facility_impulse"]}
    assert {(c, p) for c in ("pid", "hinf", "mu") for p in (0.0, 2.04)} <= set(runs)
    for key in [(c, p) for c in ("hinf", "mu") for p in (0.0, 2.04)]:
        r = runs[key]
        fit = r["nrmse_fit_pct"]
        assert fit["A_zeta"] > 90.0 and fit["B_eta"] > 90.0, key
        assert min(fit.values()) > 80.0, key
        assert r["peak_model_um"] == pytest.approx(r["peak_facility_um"], rel=0.1), key
    assert "facility" in (out / "report.html").read_text()


@pytest.mark.slow
def test_run_with_the_tracked_controller(tmp_path, request, design_cache_for):
    """``[design] tracked = true`` adds the controller scheduled on the
    tracked seal k — judged over its schedule, 0–3× nominal (the judged pressures and 3×;
    continuous, and as it runs: its digital table with the target's delay), exported as a
    table on seal.k, and run on the 0 → 3× nominal pressure ramp. References: the tracked
    scheme's acceptance (as it runs on the facility's truth, every case stable with σ̄(S_o) ≤ 3 per
    axis, ISO 14839-3's zone-A limit, and ≤ 3.2 overall; the estimate within 10 % of the
    nominal k after 1 s, its 95 % interval covering the truth ≥ 90 % of the time; the
    tracked scheme keeps the rotor to 3×) and the frozen continuous loops of the
    reference PID (unstable from 1.5× nominal: lost on the ramp before 3×)."""
    from ambseal.export.controller_files import load_controller
    from ambseal.app.pipeline import run

    out = tmp_path / "run"
    with design_cache_for(request).patched("testrig"):
        m = run(out_dir=out, progress=False, overrides=("design.tracked=true",)).metrics
    cases = [c for c in m["cases"] if c["controller"] == "tracked"]
    # 3× nominal k on the identified rig: 3 × 2.04 bar up to its fitted k at 0 bar
    assert sorted(c["pressure_bar"] for c in cases) == pytest.approx([0.0, 2.04, 4.08, 6.12],
                                                                      abs=0.05)
    assert all(c["stable"] and c["discrete"]["stable"] for c in cases)
    assert max(max(c["discrete"]["sensitivity_peak_per_axis"].values()) for c in cases) <= 3.0
    assert max(c["discrete"]["sensitivity_peak"] for c in cases) <= 3.2
    assert sorted(c["pressure_bar"] for c in m["cases"] if c["controller"] == "pid") == [
        0.0, 2.04, 4.08]
    assert "tracked" not in m["cannot_run"]
    assert load_controller(out / "controllers" / "controller_tracked.npz").parameter == "seal.k"
    ramp = m["ramp"]
    assert ramp["runs"]["tracked"]["lost_at_s"] is None
    assert ramp["runs"]["pid"]["lost_at_s"] is not None
    assert ramp["tracking"]["max_error_rel"] < 0.10 and ramp["tracking"]["coverage"] >= 0.90
    assert (out / "ramp.png").stat().st_size > 0
    validate_metrics(m)  # the tracked summary carries every key the schema asks of one


def test_run_separates_the_seal_coefficients_and_static_ki(metrics):
    """At the nominal 2.04 bar and 40 Hz the stepped-sine seal fit's K–c and C–k
    correlations (Jacobian, P4 Table 4) are below 0.5; every seal fit carries its
    reliability; the static-load Ki (P2 §5) of every axis is within 2 % of the truth file's
    and joining it with the closed-loop fit brings every Ki–Ks correlation below 0.9 (the
    programme repeated at least P2's five times, until the static Ki is twice as precise)."""
    out, _ = metrics
    ident = json.loads((out / "identification.json").read_text())
    rows = {r["frequency_hz"]: r for r in ident["seal_vs_frequency"]["2.04"]}
    c = rows[40.0]["correlation_jacobian"]
    names = list(rows[40.0]["parameters"])
    K, k, C, cc = (names.index(f"seal.{x}") for x in "KkCc")
    assert abs(c[K][cc]) < 0.5 and abs(c[C][k]) < 0.5
    assert all(isinstance(r["unreliable"], list) for r in rows.values())
    static = ident["static_load"]
    for n, row in static["parameters"].items():
        t = ident["truth"][n]
        assert abs(row["estimate"] - t) < 0.02 * t, n
    assert all(abs(v) < 0.9 for v in static["ki_ks_correlation_joined"].values())
    assert static["repeats"] >= 5
    assert max(abs(v) for v in static["ki_ks_correlation_dynamic"].values()) > max(
        abs(v) for v in static["ki_ks_correlation_joined"].values())


@pytest.fixture(scope="module")
def turbo_run(tmp_path_factory, request, design_cache_for):
    """``ambseal run examples/turboexpander.toml`` with the session's LPV and 140 Hz designs
    (the same calls ``run`` makes; tests/conftest.py)."""
    from pathlib import Path

    rig = Path(__file__).resolve().parents[1] / "examples" / "turboexpander.toml"
    import io
    import sys

    out = tmp_path_factory.mktemp("turbo")
    cache = design_cache_for(request)
    old, sys.stderr = sys.stderr, io.StringIO()  # not a terminal: plain stage lines
    try:
        with cache.patched("turbo"):
            assert main(["run", str(rig), "--out", str(out)]) == 0
        log = sys.stderr.getvalue()
    finally:
        sys.stderr = old
    assert {"design_lpv", "design_frozen"} <= set(cache.hits)
    (out / "stderr.log").write_text(log)
    return out


def test_run_not_on_a_terminal_logs_one_line_per_stage(turbo_run):
    """`ambseal run 2>log`: one plain line per stage with its time, its CPU time and the
    elapsed time, in the order of the job, no terminal control characters; the stages'
    wall times add up to the elapsed time."""
    import re

    lines = (turbo_run / "stderr.log").read_text().splitlines()
    stages = [re.match(r"ambseal: ([a-z-]+): done in ([0-9.]+) s \(([0-9.]+) s CPU\), "
                       r"elapsed ([0-9.]+) s$", ln) for ln in lines]
    assert all(stages), lines
    assert [m.group(1) for m in stages] == ["specification", "model", "design", "judge",
                                           "speed-range", "spin-up", "report"]
    elapsed = [float(m.group(4)) for m in stages]
    assert elapsed == sorted(elapsed)
    walls = [float(m.group(2)) for m in stages]
    assert sum(walls) == pytest.approx(elapsed[-1], abs=0.05 * len(walls) + 0.5)
    assert "\x1b" not in "".join(lines)


def test_run_on_the_turboexpander_judges_lpv(turbo_run):
    """`ambseal run examples/turboexpander.toml`: the PID derived from
    the rig, H∞ and μ at 140 Hz and the LPV controller judged at frozen speeds over
    20–300 Hz, every loop stable (continuous and as it runs), the spin-up and
    frozen-sensitivity comparison of LPV and μ (P3 Figs. 11–12) in metrics and report, the
    LPV table exported. The LPV and 140 Hz H∞ designs are the session's (the same calls
    ``run`` makes; tests/conftest.py)."""
    tmp_path = turbo_run
    m = json.loads((tmp_path / "metrics.json").read_text())
    validate_metrics(m)
    got = {(c["controller"], c["speed_hz"]) for c in m["cases"]}
    assert got == {(c, f) for c in ("pid", "hinf", "mu", "lpv") for f in (20.0, 140.0, 300.0)}
    assert all(c["stable"] and c["discrete"]["stable"] for c in m["cases"])
    # from standstill to the top speed (300 Hz in quarters), where it is not judged in full
    st = {(c["controller"], c["speed_hz"]): c for c in m["stability"]}
    assert set(st) == {(c, f) for c in ("pid", "hinf", "mu", "lpv")
                       for f in (0.0, 75.0, 150.0, 225.0)}
    unstable = {c for (c, _), v in st.items()
                if not v["stable"] or not v["discrete"]["stable"]}
    assert unstable == set(m["failed"]), (unstable, m["failed"])
    assert set(m["spinup"]) == {"mu", "lpv"}
    for name in ("spinup.png", "frozen_sensitivity.png", "report.html"):
        assert (tmp_path / name).exists()
    from ambseal.export import load_controller
    from ambseal.machine import ScheduledDigital

    for ext in (".json", ".npz", ".mat"):
        K = load_controller(tmp_path / "controllers" / f"controller_lpv{ext}")
        assert isinstance(K, ScheduledDigital)
    assert (tmp_path / "controllers" / "ambseal_lpv.c").exists()
    assert "identification" not in m  # no truth file for this rig


def test_exported_hinf_closes_the_loop_by_name_in_python_control(metrics):
    """Reference: python-control's own ``interconnect`` (a peer library), wiring the
    exported H∞ controller (``controllers/controller_hinf.json``) to the full-order plant
    purely by signal names (plant i_<axis> → y_<axis>, controller y_<axis> → i_<axis>, the
    sign of i = −K y in the connection) through python-control's own Padé lag of the
    case's ``delay`` (``control.pade``, the digital controller's hold + computation delay)
    on each axis; its closed-loop poles give the same largest real part as
    ``max_real_pole`` in metrics.json at every judged pressure (to 1e-5: python-control's
    companion form of the lag costs digits), on the plant the run judges on: the virtual
    facility's truth."""
    import control
    import numpy as np

    from ambseal.config import load_rig, load_truth
    from ambseal.identify.facility.design_model import truth_rig
    from ambseal.model.rig import build_plant
    from ambseal.app.pipeline import default_truth_path

    out, m = metrics
    doc = json.loads((out / "controllers" / "controller_hinf.json").read_text())
    K = control.ss(doc["A_c"], doc["B_c"], doc["C_c"], doc["D_c"], inputs=doc["inputs"],
                   outputs=doc["outputs"], name="K")  # the continuous design
    cfg = truth_rig(load_rig(), load_truth(default_truth_path()))
    for case in (c for c in m["cases"] if c["controller"] == "hinf"):
        plant = build_plant(cfg, pressure_bar=case["pressure_bar"])
        G = control.ss(plant.to_statespace(), name="G")
        axes = plant.axes
        assert set(K.output_labels) == set(G.input_labels)
        assert set(K.input_labels) == set(G.output_labels)
        dl = case["delay"]
        lag = control.ss(control.tf(*control.pade(dl["delay_s"], dl["pade_order"])))
        lags = [control.ss(lag, inputs="u", outputs="v", name=f"L_{a}") for a in axes]
        loop = control.interconnect(
            [G, K, *lags], connections=[[f"L_{a}.u", f"-K.i_{a}"] for a in axes]
            + [[f"G.i_{a}", f"L_{a}.v"] for a in axes]
            + [[f"K.y_{a}", f"G.y_{a}"] for a in axes], outlist=list(G.output_labels))
        assert loop.nstates == G.nstates + K.nstates + 4 * dl["pade_order"]
        worst = float(np.max(np.linalg.eigvals(loop.A).real))
        assert worst == pytest.approx(case["max_real_pole"], rel=1e-5, abs=1e-6)
        assert (worst < 0) == case["stable"]


@pytest.mark.browser
@pytest.mark.skipif(chromium() is None, reason="no Chromium installed (Debian: apt-get install "
                    "chromium; .ci/run installs it where it can)")
@pytest.mark.parametrize("which", ["testrig", "turbo"])
def test_report_in_a_real_browser(which, request, tmp_path):
    """The report as a reader sees it, in headless Chromium at 1280 × 900 CSS px: the page
    loads without console errors, every image decodes, nothing overflows horizontally
    (document width ≤ viewport width), the verdict table is on the first screen, and the
    HTML holds no Python repr (``{'``, ``None``). A screenshot is kept beside the report."""
    out = request.getfixturevalue("metrics")[0] if which == "testrig" else \
        request.getfixturevalue("turbo_run")
    report = out / "report.html"
    html = report.read_text(encoding="utf-8")
    text = re.sub(r"base64,[A-Za-z0-9+/=]+", "base64,", html)  # 'None' can occur in image data
    assert "{'" not in text and "None" not in text
    png = out / "report_screenshot.png"
    got = probe(report, screenshot=png)
    assert got["errors"] == []
    assert got["images"] >= 5 and got["bad_images"] == []
    assert got["doc_width"] <= got["view_width"] == 1280
    assert got["verdict"] and got["verdict_bottom"] <= got["view_height"]
    assert png.read_bytes().startswith(b"\x89PNG")


def test_a_notch_that_holds_but_leaves_the_amplifier_saturated_says_so():
    """The supercritical example passes its bending critical (~106 Hz) below its speed
    range (from 120 Hz), where the run's automatic unbalance force rejection is off: the
    notch holds every loop and its orbit, yet the amplifier saturates there with it on as
    well. The failure's words say that (they had ended the run in a TypeError, reading a
    clearance the notch did not exceed), with the speed the notch is on from."""
    from types import SimpleNamespace

    from ambseal.app.pipeline import _Notch, _why_not_notched

    notch = SimpleNamespace(on_rad_s=2 * np.pi * 120.0)
    n = _Notch(SimpleNamespace(controller=SimpleNamespace(notch=notch)), [], [], {}, None)
    assert n.holds
    assert _why_not_notched(n) == (
        "its unbalance force rejection, switched on by the run, holds, but the amplifier "
        "saturates with it on as well: below 120 Hz, where it is off, or in the impulse "
        "response")
    lost = _Notch(n.rejection, [], ["0 bar, 191 Hz"], {}, None)
    assert _why_not_notched(lost).endswith("loses the loop at 0 bar, 191 Hz")
    # conditions hold commas themselves: two are told apart by "; "
    two = _Notch(n.rejection, [], ["0 bar, 305.185 Hz", "0 bar, 295.987 Hz"], {}, None)
    assert _why_not_notched(two).endswith(
        "loses the loop at 0 bar, 305.185 Hz; 0 bar, 295.987 Hz")
