"""Tests of ambseal.report.html: a self-contained, escaped report page."""

from __future__ import annotations

import base64
import re
import subprocess
import sys

import numpy as np
import pytest

from ambseal.errors import AmbsealError
from ambseal.report import capacity_figure, figures, html


def _metrics():
    axes = ("A_zeta", "B_eta")
    return [
        {"controller": "PID <b>", "pressure_bar": 2.04, "speed_hz": 0.0, "stable": True,
         "max_real_pole": -12.5, "sensitivity_peak": 3.5,
         "sensitivity_peak_per_axis": dict(zip(axes, (2.9, 3.1))), "iso_zone": "B",
         "iso_zone_per_axis": dict(zip(axes, "AB")), "compliance_peak_m_per_n": 2.1e-7,
         "unbalance_peak_um": 7.9, "impulse_peak_um": 12.3, "impulse_settling_s": 0.03},
        {"controller": "PID <b>", "pressure_bar": 4.08, "speed_hz": 0.0, "stable": False,
         "max_real_pole": 3.2, "sensitivity_peak": None,
         "sensitivity_peak_per_axis": dict.fromkeys(axes), "iso_zone": "D",
         "iso_zone_per_axis": dict(zip(axes, "DD")), "compliance_peak_m_per_n": None,
         "unbalance_peak_um": None, "impulse_peak_um": None, "impulse_settling_s": None},
    ]


def test_report_is_self_contained_and_escaped(tmp_path):
    """Reference: self-containment by construction — no external src/href (every <img> is a
    data:image/png;base64 URI whose bytes decode to the written PNG); HTML escaping of user text
    (html.escape, WHATWG HTML §13.1.2) — a '<b>' in a controller name must not become markup."""
    f = np.logspace(0, 3, 50)
    png = figures.sensitivity_figure(tmp_path / "s.png", [("PID", f, 1 + 0 * f)])
    png2 = figures.unbalance_figure(tmp_path / "u.png", [("PID", f, f / 100)])
    out = html.write_report(
        tmp_path / "report.html", title="Seal <test>", metrics=_metrics(),
        figures=[("Sensitivity", png)],
        sections=[{"title": "Notes & caveats", "text": "<script>alert(1)</script>"},
                  {"title": "Unbalance", "figure": png2, "caption": "G2.5, 69 kg"},
                  {"title": "Raw", "html": "<p id='raw'>ok</p>"}],
        meta="rig=testrig.toml",
    )
    text = out.read_text(encoding="utf-8")
    assert text.startswith("<!DOCTYPE html>")
    assert "<script>" not in text and "&lt;script&gt;" in text
    assert "PID &lt;b&gt;" in text and "Seal &lt;test&gt;" in text
    assert "<p id='raw'>ok</p>" in text
    refs = re.findall(r"""(?:src|href)\s*=\s*["']?([^"'\s>]*)""", text, flags=re.I)
    assert refs and all(r.startswith("data:image/png;base64,") for r in refs)
    assert "<link" not in text and "@import" not in text and "url(" not in text
    srcs = re.findall(r'<img src="data:image/png;base64,([^"]+)"', text)
    assert len(srcs) == 2
    assert base64.b64decode(srcs[0]) == png.read_bytes()
    # verdict: header + 1 controller; detail: 2 header rows + 2 cases
    assert text.count("<tr") == 2 + 4 and 'class="unstable"' in text
    assert "None" not in text and "{'" not in text
    assert not [p for p in tmp_path.iterdir() if p.name.endswith(".tmp")]


def test_numbers_for_people():
    """Reference: the report's table conventions: 3 significant figures by
    default, yes/no, — for missing, ∞ for inf, powers of ten written out."""
    from ambseal.report.verdict import sig

    assert sig(0.0123456) == "0.0123" and sig(-14.0723, 4) == "-14.07"
    assert sig(True) == "yes" and sig(None) == "—" and sig(float("nan")) == "—"
    assert sig(float("inf")) == "∞" and sig(2.1e-7) == "2.1·10^-7"


def test_verdict_grades_each_axis_as_iso_14839_3_does():
    """Reference: ISO 14839-3 grades the sensitivity of each axis; an unstable loop is not
    acceptable whatever its other conditions (P5 §4.4.2: the PID at 4.08 bar)."""
    from ambseal.report.verdict import verdicts

    cases = _metrics()
    stable_only = verdicts(cases[:1], {"air gap": 500.0})[0]
    assert stable_only.zone_axis == "B" and stable_only.zone_sigma == "B"
    # the axes differ (A ζ zone A, B η zone B): the zone is the worst axis's, named
    assert stable_only.worst_axis == "B η at 2.04 bar" and not stable_only.axes_alike
    assert stable_only.words().startswith(
        "Zone B on its worst axis (B η at 2.04 bar) over 2.04 bar: fit for unrestricted")
    alike = dict(cases[0], iso_zone_per_axis={"A_zeta": "B", "B_eta": "B"})
    assert verdicts([alike])[0].words().startswith("Zone B on every axis over 2.04 bar: fit")
    assert stable_only.orbit_text() == "7.9 µm (1.6 % of the air gap)"
    both = verdicts(cases)[0]
    assert both.zone_axis == "D" and both.unstable_at == ("4.08 bar",)
    assert both.stable_range == "2.04 bar"
    assert both.words().startswith("Not acceptable: the loop is unstable at 4.08 bar")
    spiky = dict(cases[0], iso_zone="D", sensitivity_peak=5.5)
    v = verdicts([spiky])[0]
    # σ̄(S_o) in zone D: the sentence must not call the loop fit for long-term operation
    assert v.zone_axis == "B" and v.zone_sigma == "D"
    assert ("but σ̄(S_o) over all axes reaches zone D (peak 5.5): not acceptable (damage "
            "likely)") in v.words() and "unrestricted" not in v.words()


def test_verdict_holds_only_where_the_machine_runs_up_too():
    """A controller stable and zone B at its judged condition but unstable at standstill
    (a ``metrics["stability"]`` case) is not acceptable, zone D, its speed-range failures
    counted and named (the discrete loop's too); stable over the whole speed range, the
    sentence says so and keeps the judged zone."""
    from ambseal.report.verdict import verdicts

    case = _metrics()[0]
    ok = {"controller": case["controller"], "stable": True,
          "discrete": {"stable": True}}
    st = [dict(ok, label="2.04 bar, 0 Hz", speed_hz=0.0, stable=False),
          dict(ok, label="2.04 bar, 50 Hz", speed_hz=50.0, discrete={"stable": False}),
          dict(ok, label="2.04 bar, 100 Hz", speed_hz=100.0)]
    v = verdicts([case], None, st)[0]
    # both zone cells of the row: a loop lost in the speed range is zone D for σ̄ too
    assert v.zone_axis == "D" and v.zone_sigma == "D" and v.speed_checked == 3
    assert v.speed_unstable == ("2.04 bar, 0 Hz", "2.04 bar, 50 Hz")
    assert v.stable_range == "2.04 bar; unstable at 2 of 3 speed-range conditions"
    assert v.words() == ("Not acceptable: the loop is unstable at 2.04 bar, 0 Hz; "
                         "2.04 bar, 50 Hz (where the machine runs up).")
    # lost at its judged condition too: "none" of those, and the speed range still counted
    lost = verdicts([dict(case, stable=False)], None, st)[0]
    assert lost.stable_range == "none; unstable at 2 of 3 speed-range conditions"
    # its judged condition named with its speed beside the speed range's (at 140 Hz here):
    # "unstable at 2.04 bar; 2.04 bar, 0 Hz" would not say where the first was lost
    at_speed = verdicts([dict(case, stable=False, speed_hz=140.0)], None, st)[0]
    assert at_speed.unstable_at == ("2.04 bar, 140 Hz",)
    assert at_speed.words().startswith("Not acceptable: the loop is unstable at 2.04 bar, "
                                       "140 Hz; 2.04 bar, 0 Hz; 2.04 bar, 50 Hz (where")
    # lost at its judged condition only: not "none" alone, the range that holds named
    held = verdicts([dict(case, stable=False)], None, st[2:])[0]
    assert held.stable_range == ("none; stable at the 1 speed-range condition "
                                 "(100–100 Hz (standstill not judged))")
    fine = [dict(s, stable=True, discrete={"stable": True}) for s in st]
    both = verdicts([dict(case, stable=False)], None, fine)[0]
    assert both.stable_range == ("none; stable at its 3 speed-range conditions "
                                 "(standstill to 100 Hz)")
    good = verdicts([case], None, st[2:])[0]
    assert good.zone_sigma == case["iso_zone"]
    assert good.zone_axis == "B" and good.stable_range == "2.04 bar, standstill to 100 Hz"
    assert good.words().startswith("Zone B on its worst axis (B η at 2.04 bar) over 2.04 "
                                   "bar: fit for")
    assert "stable from standstill to 100 Hz" in good.words()


def test_verdict_grades_every_speed_as_it_runs_and_names_the_worst():
    """A controller zone B at its judged condition whose loop as it runs at 500 Hz, a
    speed-range condition, reaches zone C on B η (peak 3.8): the row's zone is C and the
    sentence names that axis, speed and loop; σ̄(S_o) follows the worst graded loop too."""
    from ambseal.report.verdict import verdicts

    case = _metrics()[0]
    axes = ("A_zeta", "B_eta")
    ok = {"controller": case["controller"], "stable": True, "label": "2.04 bar, 500 Hz",
          "speed_hz": 500.0, "sensitivity_peak": 3.2, "iso_zone": "B",
          "sensitivity_peak_per_axis": dict(zip(axes, (2.9, 3.0))),
          "iso_zone_per_axis": dict(zip(axes, "AB")),
          "discrete": {"stable": True, "sensitivity_peak": 3.9, "iso_zone": "C",
                       "sensitivity_peak_per_axis": dict(zip(axes, (2.9, 3.8))),
                       "iso_zone_per_axis": dict(zip(axes, "AC"))}}
    v = verdicts([case], None, [ok])[0]
    assert v.zone_axis == "C" and v.zone_sigma == "C" and v.sigma_peak == 3.9
    assert v.worst_axis == "B η at 2.04 bar, 500 Hz, as it runs"
    assert v.words().startswith("Zone C on its worst axis (B η at 2.04 bar, 500 Hz, as it "
                                "runs) over 2.04 bar and standstill to 500 Hz: fit for "
                                "limited-term operation only")


def test_a_rig_judged_at_speeds_names_its_graded_span_once():
    """A rig judged at speeds (20–300 Hz) whose speed range from standstill was graded:
    the zone is over "standstill to 300 Hz", not "20–300 Hz and standstill to 300 Hz"."""
    from ambseal.report.verdict import verdicts

    base = _metrics()[0]
    cases = [dict(base, speed_hz=f, label=f"{f:g} Hz") for f in (20.0, 140.0, 300.0)]
    st = [{"controller": base["controller"], "stable": True, "label": "2.04 bar, 0 Hz",
           "speed_hz": 0.0, "sensitivity_peak": 2.0, "iso_zone": "A",
           "sensitivity_peak_per_axis": {"A_zeta": 1.5}, "iso_zone_per_axis": {"A_zeta": "A"},
           "discrete": {"stable": True}}]
    words = verdicts(cases, None, st)[0].words()
    assert " over standstill to 300 Hz:" in words and "20–300 Hz and" not in words


def test_verdict_claims_standstill_only_where_it_was_judged():
    """Reference: what was judged — a controller stable at every stability speed given as
    333.33–1000 Hz (``[design] stability_speeds_hz`` without 0) and at its judged condition
    (0 Hz in the test data, left out here by moving it to 500 Hz) was not judged at
    standstill: neither the range nor the sentence may say "standstill"; with 0 Hz among
    the speeds they say "standstill to 1000 Hz"."""
    from ambseal.report.verdict import verdicts

    case = dict(_metrics()[0], speed_hz=500.0)
    ok = {"controller": case["controller"], "stable": True, "discrete": {"stable": True}}
    st = [dict(ok, label=f"2.04 bar, {f:g} Hz", speed_hz=f)
          for f in (333.33, 666.667, 750.0, 1000.0)]
    v = verdicts([case], None, st)[0]
    assert "standstill" not in v.words().replace("standstill not judged", "")
    assert v.stable_range == "2.04 bar, 333.33–1000 Hz (standstill not judged)"
    assert "stable at every judged speed, 333.33–1000 Hz (standstill not judged)" in v.words()
    st0 = [dict(ok, label="2.04 bar, 0 Hz", speed_hz=0.0), *st]
    v0 = verdicts([case], None, st0)[0]
    assert v0.stable_range == "2.04 bar, standstill to 1000 Hz"
    assert "stable from standstill to 1000 Hz" in v0.words()


def test_an_orbit_beyond_the_backup_clearance_fails():
    """Reference: the rig's clearances — a worst unbalance orbit of 1800 µm (3.6× a 500 µm
    air gap) with 250 µm backup bearings runs the rotor on them: not acceptable, in numbers,
    and the controller fails (:func:`ambseal.analysis.delivery.clearance_failure`), its
    discrete loop's orbit counted too; 200 µm passes and says which share of the backup
    clearance it uses (80 %); an orbit below half of it says nothing."""
    from ambseal.analysis import clearance_failure
    from ambseal.report.verdict import verdicts

    clear = {"air gap": 500.0, "backup bearing": 250.0}
    base = dict(_metrics()[0], label="2.04 bar")
    big = dict(base, unbalance_peak_um=120.0, discrete={"stable": True, "unbalance_peak_um": 1800.0})
    v = verdicts([big], clear)[0]
    assert v.orbit_um == 1800.0
    assert v.words() == ("Not acceptable: the worst unbalance orbit, 1.8·10^3 µm, exceeds the "
                         "backup bearing's clearance (250 µm).")
    f = clearance_failure("hinf", [big], clear, designed=True)
    assert f is not None and f.conditions == ["2.04 bar"]
    assert f.reason == ("H∞: not delivered — the worst unbalance orbit, 1.8e+03 µm, exceeds "
                        "the backup bearing's clearance (250 µm)")
    # no backup bearing given: the air gap is the clearance
    assert "exceeds the air gap (500 µm)" in verdicts([big], {"air gap": 500.0})[0].words()
    mid = dict(base, unbalance_peak_um=200.0)
    assert clearance_failure("hinf", [mid], clear, designed=True) is None
    words = verdicts([mid], clear)[0].words()
    assert words.startswith("Zone B") and ("the unbalance orbit, 200 µm, uses 80 % of the "
                                           "backup bearing's clearance (250 µm)") in words
    assert "orbit" not in verdicts([dict(base, unbalance_peak_um=100.0)], clear)[0].words()


def test_verdict_names_the_critical_speeds_near_the_running_range():
    """A case whose loop, as it runs, has the nutation mode's 1× crossing at 1007 Hz with
    AF 4.1, 0.7 % above a continuous range whose margin for that AF is 20.2 %, and one at
    950 Hz inside it (continuous loop, AF 12; the same speed as it runs to 3 digits, AF 11:
    once, the larger AF): the sentence names both, by speed."""
    from ambseal.report.verdict import verdicts

    crit = [{"speed_hz": 950.2, "af": 12.0, "margin_pct": 0.0, "required_pct": 25.0}]
    case = dict(_metrics()[0], critical_speeds=crit,
                discrete={"stable": True, "critical_speeds": [
                    {"speed_hz": 1007.0, "af": 4.1, "margin_pct": 0.7, "required_pct": 20.2},
                    {"speed_hz": 950.4, "af": 11.0, "margin_pct": 0.0, "required_pct": 24.0}]})
    words = verdicts([case])[0].words()
    assert ("but critical speeds (1× crossing, AF ≥ 2.5) at 950.2 Hz (AF 12) inside the "
            "continuous speed range; 1007 Hz (AF 4.1) 0.7 % from the continuous speed "
            "range where API 617 requires 20 %") in words
    assert "critical" not in verdicts([_metrics()[0]])[0].words()


def test_a_response_that_does_not_settle_shows_why_not_a_bare_dash():
    """Reference: the cases' own ``impulse_settling_note`` (metrics.json). A stable case
    whose impulse response did not settle within the simulated window has no settling
    time: the verdict takes it as the worst (not the other condition's 30 ms), says why in
    its sentence, and the tables show "not settled" with the reason under the detail
    table; a case that settled shows its time, and the verdict no note."""
    from ambseal.report.verdict import detail_table_html, verdict_table_html, verdicts

    note = ("not settled within the 350 ms simulated after the impulse: its slowest pole, "
            "at −0.19 rad/s, decays to 2 % in 20.6 s, beyond that window")
    settled = dict(_metrics()[0], controller="pid")
    slow = dict(settled, pressure_bar=4.08, impulse_settling_s=None,
                impulse_settling_note=note)
    v = verdicts([settled, slow])[0]
    assert v.impulse_settling_s is None
    assert v.impulse_settling_note == f"{note} (at 4.08 bar)"
    assert f"; its impulse response is {note} (at 4.08 bar)" in v.words()
    assert ">not settled</td>" in verdict_table_html([v])
    detail = detail_table_html([settled, slow])
    assert "<td>30</td>" in detail and "<td>not settled</td>" in detail
    assert f"<p>pid at 4.08 bar: the impulse response is {note}.</p>" in detail
    alone = verdicts([settled])[0]
    assert alone.impulse_settling_s == 0.03 and alone.impulse_settling_note is None
    assert "impulse" not in alone.words()


def test_verdict_says_what_the_unbalance_asks_of_the_amplifier():
    """The design summary's ``capacity`` block in words: the larger of the voltage and
    current fractions, with the axis, the speed in rpm and the condition; above 1 the
    amplifier saturates, the controller is not acceptable and the sentence says by how
    much; no limits, no words."""
    from ambseal.report.verdict import verdicts

    case = _metrics()[0]
    where = {"condition": "2.04 bar", "speed_hz": 183.3, "axis": "A_zeta"}
    cap = {"current_used": 0.31, "voltage_used": 0.64, "bias_used": 0.31, "current_a": 1.9,
           "worst": {"current_used": dict(where, axis="B_eta"), "voltage_used": where}}
    v = verdicts([case], None, (), {case["controller"]: {"capacity": cap}})[0]
    assert v.amplifier_text() == ("holding the unbalance it uses 64 % of the supply voltage "
                                  "(A ζ at 10 998 rpm, 2.04 bar)")
    assert "; holding the unbalance it uses 64 %" in v.words()
    hot = dict(cap, current_used=1.5)
    v = verdicts([case], None, (), {case["controller"]: {"capacity": hot}})[0]
    assert v.amplifier_text() == ("the amplifier saturates holding the unbalance: it needs "
                                  "1.5× the current limit (B η at 10 998 rpm, 2.04 bar)")
    assert v.words() == f"Not acceptable: {v.amplifier_text()}."
    bare = dict(cap, current_used=None, voltage_used=None)
    assert verdicts([case], None, (), {case["controller"]: {"capacity": bare}}
                    )[0].amplifier_text() == ""
    assert verdicts([case])[0].amplifier_text() == ""


def test_bad_inputs_raise(tmp_path):
    """Reference: interface contract — a non-PNG figure or an empty section raises AmbsealError."""
    bad = tmp_path / "x.png"
    bad.write_bytes(b"not a png")
    with pytest.raises(AmbsealError):
        html.write_report(tmp_path / "r.html", figures=[("x", bad)])
    with pytest.raises(AmbsealError):
        html.write_report(tmp_path / "r.html", sections=[{"title": "empty"}])
    assert not (tmp_path / "r.html").exists()


def test_the_command_line_starts_light():
    """Reference: DESIGN.md 'Imports at the top' (a function-level import only for a
    measured start-up cost) — ``ambseal`` and its command line load neither python-control
    nor matplotlib until a command runs, so ``ambseal --help`` and argument errors answer at
    once; checked on sys.modules of a subprocess."""
    code = ("import sys, ambseal, ambseal.cli\n"
            "heavy = [m for m in ('matplotlib', 'control', 'scipy.signal')\n"
            "         if any(k == m or k.startswith(m + '.') for k in sys.modules)]\n"
            "assert not heavy, heavy\n")
    subprocess.run([sys.executable, "-c", code], check=True)


def test_orbit_against_the_rigs_clearances():
    """Reference: the thesis rig's nominal radial air gap, 0.5 mm (P2 Table 1), and the
    backup-bearing clearance its touchdown bearings give (0.25 mm, the rig file's
    choice); the orbit is set against the smaller of each kind, in per cent (7.9 µm of
    500 µm is 1.58 %). Without touchdown bearings, an ``[[amb]] backup_clearance``."""
    from ambseal.config import load_rig
    from ambseal.analysis.delivery import rig_clearances_um
    from ambseal.report.verdict import verdicts

    cfg = load_rig()
    clear = rig_clearances_um(cfg)
    assert clear == pytest.approx({"air gap": 500.0, "backup bearing": 250.0}, rel=1e-3)
    bare = cfg.model_copy(update={"touchdown": []})
    assert rig_clearances_um(bare) == pytest.approx({"air gap": 500.0}, rel=1e-3)
    given = bare.model_copy(update={"amb": [a.model_copy(update={"backup_clearance": 3e-4})
                                            for a in bare.amb]})
    assert rig_clearances_um(given)["backup bearing"] == pytest.approx(300.0)
    v = verdicts(_metrics()[:1], clear)[0]
    assert v.orbit_text() == "7.9 µm (1.6 % of the air gap; 3.2 % of the backup bearing)"


def test_on_the_target_names_only_what_metrics_records():
    """Reference: metrics.json's ``discretisation`` blocks. A case run on the target whose
    controller has its discretisation recorded is named with its method and delay; one
    whose controller has none recorded (not exported) is named by its rate alone — no
    "?" placeholders."""
    from ambseal.report.run_report import _discrete_section

    disc = {"stable": True, "max_abs_pole_z": 0.99, "sensitivity_peak": 2.0,
            "iso_zone": "A", "sample_rate_hz": 10000.0}
    case = {"pressure_bar": 0.0, "speed_hz": 50.0, "sensitivity_peak": 1.9, "discrete": disc}
    metrics = {"cases": [{**case, "controller": "pid"}, {**case, "controller": "hinf"}],
               "controllers": {"pid": {"discretisation": {"method": "tustin",
                                                          "delay_samples": 1}},
                               "hinf": {"discretisation": None}}}
    sec = _discrete_section(metrics)[0]
    assert "?" not in sec["text"] + sec["html"]
    rows = [re.findall(r"<td[^>]*>([^<]*)</td>", r) for r in sec["html"].split("</tr>")]
    assert [r for r in rows if r] == [
        ["pid", "0 bar, 50 Hz", "stable", "0.99000", "2.00", "1.90", "A",
         "tustin at 10000 Hz, 1 sample(s) delay"],
        ["hinf", "0 bar, 50 Hz", "stable", "0.99000", "2.00", "1.90", "A", "at 10000 Hz"]]


def test_amplifier_sizing_is_tabled_per_controller_and_amb():
    """Reference: metrics.json's ``capacity.sizing`` blocks. A row per delivered controller
    with sizing, a column per AMB, the current limit and supply voltage at three
    significant digits ("—" where no voltage could be derived); a failed controller and
    one without a capacity block get no row; none at all, no section."""
    from ambseal.report.run_report import _sizing_section

    sized = {"A": {"current_limit_a": 0.48291, "supply_voltage_v": None},
             "B": {"current_limit_a": 1.2345, "supply_voltage_v": 36.24}}
    metrics = {"controllers": {"pid": {"capacity": {"sizing": sized}},
                               "hinf": {"capacity": {"sizing": sized}},
                               "mu": {"capacity": None}},
               "failed": {"hinf": "unstable at 0 bar, 0 Hz"}}
    (sec,) = _sizing_section(metrics)
    assert sec["title"] == "Amplifier sizing"
    table = sec["html"]
    assert table.count("<tr>") == 2 and "<th>AMB A</th><th>AMB B</th>" in table
    assert "<td>0.483 A, — V</td><td>1.23 A, 36.2 V</td>" in table
    assert "H∞" not in table and "μ" not in table
    assert _sizing_section({"controllers": {"mu": {"capacity": None}}}) == []


def test_capacity_figure_draws_each_amb_or_nothing(tmp_path, testrig_cfg):
    """A PNG with a panel per AMB from the judged unbalance currents; nothing for a rig
    whose AMBs give no bias current (no capacity to draw) or no stable loop (no demand)."""
    f = np.linspace(10.0, 100.0, 30)
    names = [f"i_{a.name}_{ax}" for a in testrig_cfg.amb for ax in ("zeta", "eta")]
    entries = [("0 bar", f, np.full((f.size, len(names)), 0.5), names)]
    (caption, png), = capacity_figure(tmp_path, testrig_cfg, {"pid": entries, "hinf": entries})
    assert png == tmp_path / "force_capacity.png" and png.read_bytes()[:4] == b"\x89PNG"
    assert "slew rate" in caption
    assert capacity_figure(tmp_path, testrig_cfg, {"pid": []}) == []
    bare = [a.model_copy(update={"bias_current": None, "ki": 50.0, "ks": 1e5})
            for a in testrig_cfg.amb]
    assert capacity_figure(tmp_path, testrig_cfg.model_copy(update={"amb": bare}),
                           {"pid": entries}) == []


def test_the_worst_axis_of_a_tie_is_the_first_in_the_rigs_channel_order():
    """Reference: by symmetry the ζ and η axes of an isotropic bearing have one sensitivity
    peak; two machines' rounding makes either larger (b2b_compressor's PID by 8e-11, its
    H∞ design by 1.7e-8, A ζ larger with one BLAS kernel and A η with another). The worst
    axis the verdict names must be the same whether the tie is exact or η is larger by
    1e-12 or 2e-8 relative — the first in the rig's channel order — while a difference
    that is one (1e-4) still names the larger axis."""
    from ambseal.report.verdict import verdicts

    base = _metrics()[0]

    def worst(order, peaks):
        case = dict(base, sensitivity_peak_per_axis=dict(zip(order, peaks)),
                    iso_zone_per_axis=dict(zip(order, "BBAA")))
        return verdicts([case])[0].worst_axis

    axes = ("A_zeta", "A_eta", "B_zeta", "B_eta")
    p = 3.4631249311503693
    assert worst(axes, (p, p, 1.7, 1.7)) == "A ζ at 2.04 bar"
    assert worst(axes, (p, p * (1 + 1e-12), 1.7, 1.7)) == "A ζ at 2.04 bar"
    assert worst(axes, (p * (1 + 1e-12), p, 1.7, 1.7)) == "A ζ at 2.04 bar"
    assert worst(axes, (p, p * (1 + 2e-8), 1.7, 1.7)) == "A ζ at 2.04 bar"
    assert worst(axes, (p, p * (1 + 1e-4), 1.7, 1.7)) == "A η at 2.04 bar"
    # the order decides, not the name: a rig listing η first names η
    flipped = ("A_eta", "A_zeta", "B_eta", "B_zeta")
    assert worst(flipped, (p, p, 1.7, 1.7)) == "A η at 2.04 bar"
    assert worst(flipped, (p, p * (1 + 1e-12), 1.7, 1.7)) == "A η at 2.04 bar"


def _graded_case(sigma: float, axes: tuple[float, float]) -> dict:
    """A stable judged case whose zones are graded from its peaks by
    :func:`ambseal.analysis.iso.iso_assessment`, as the judgement grades them."""
    from ambseal.analysis.iso import iso_assessment
    from ambseal.analysis.loops import Peak, SensitivityPeaks

    names = ("A_zeta", "B_eta")
    a = iso_assessment(SensitivityPeaks(Peak(sigma, 80.0), tuple(
        Peak(v, 80.0, n) for n, v in zip(names, axes))))
    return dict(_metrics()[0], sensitivity_peak=sigma, iso_zone=a.zone_sigma_max,
                sensitivity_peak_per_axis=dict(zip(names, axes)),
                iso_zone_per_axis=dict(a.zones_per_axis))


def test_a_zone_on_its_limit_names_both_sides_in_the_verdict():
    """Reference: ISO 14839-3:2006's A/B limit 3 on σ̄(S_o) and on each axis's peak, known to
    0.1 %. Just below (2.99) the verdict says zone A, just above (3.01) zone B; on the
    limit (3.0004 on the worst axis, or the σ̄ peak 2.9997 over axes in A) it names both
    zones and the number and the limit, whichever side of 3 rounding put the number —
    so a machine that rounds 3.0004 to 2.9996 says the same words."""
    from ambseal.report.verdict import verdicts

    def words(sigma, axes):
        return verdicts([_graded_case(sigma, axes)])[0].words()

    assert words(2.99, (2.95, 2.99)).startswith(
        "Zone A on every axis over 2.04 bar: as good as newly commissioned")
    assert words(3.01, (2.95, 3.01)).startswith(
        "Zone B on its worst axis (B η at 2.04 bar) over 2.04 bar: fit for unrestricted")
    on = ("Zone A/B (on the boundary: |S_o| 3.0004 against 3.0) on its worst axis (B η at "
          "2.04 bar) over 2.04 bar: on the boundary of A (as good as newly commissioned) "
          "and B (fit for unrestricted long-term operation)")
    assert words(3.0004, (2.95, 3.0004)).startswith(on)
    assert words(2.9996, (2.95, 2.9996)).startswith(on.replace("3.0004", "2.9996"))
    v = verdicts([_graded_case(2.9997, (2.5, 2.6))])[0]
    assert (v.zone_axis, v.zone_sigma) == ("A", "A/B")
    assert ("Zone A on every axis over 2.04 bar, but σ̄(S_o) over all axes reaches zone A/B "
            "(on the boundary: σ̄ 2.9997 against 3.0): on the boundary of A") in v.words()
    # the cells of the table carry both zones' colours
    table = html.verdict_table_html([verdicts([_graded_case(3.0004, (2.95, 3.0004))])[0]])
    assert "linear-gradient(90deg,#1a9850 50%,#91cf60 50%)" in table and ">A/B<" in table


def test_an_lpv_design_whose_sdp_stopped_at_its_cap_is_marked_where_it_is_delivered():
    """Reference: CVXOPT's iteration count and cap (``maxiters`` 8 on a toy whose γ SDP
    converges in 10; tests/robust/test_robust_lpv.py). The LPV design built from that
    synthesis names the stage that stopped short of optimal in its summary (``sdp_status``,
    ``sdp_shortfall``) and in its bound's words; the run's verdict on it, its design-bound
    cell and the report's section on the syntheses say NOT SOLVED TO OPTIMALITY. The same
    synthesis without the cap ends "optimal", and none of them says so."""
    import dataclasses

    from ambseal.design.lpv_design import LpvDesign
    from ambseal.report.run_report import _synthesis_section
    from ambseal.report.verdict import verdicts
    from ambseal.robust import lpvsyn
    from tests.robust.test_robust_lpv import _toy

    grid = np.linspace(0.0, 40.0, 5)
    plants = [_toy(p) for p in grid]

    def delivered(options):
        r = lpvsyn(plants, grid, 2, 2, frozen_check=False, solver_options=options)
        d = LpvDesign(K=r.K, gamma=r.gamma, gamma_design=r.gamma_design,
                      frozen_gamma=np.full(grid.size, np.nan), check_gamma=r.check_gamma,
                      speeds_hz=grid / (2 * np.pi), check_speeds_hz=r.check_grid / (2 * np.pi),
                      reports=r.reports, kind=r.kind)
        summary = d.to_dict()
        case = dict(_metrics()[0], controller="lpv")
        v = verdicts([case], None, (), {"lpv": summary})[0]
        text = " ".join(sec["text"] for sec in _synthesis_section({"controllers": {
            "lpv": summary}}))
        return d, summary, v, text

    d, summary, v, text = delivered({"maxiters": 8})
    assert summary["sdp_status"] == {"gamma": "feasible"}
    short = ("the γ stage's SDP ended “feasible”, not optimal (CVXOPT stopped short of its "
             "tolerances)")
    assert summary["sdp_shortfall"] == short
    assert f"NOT SOLVED TO OPTIMALITY: {short}" in d.verdict
    assert f"NOT SOLVED TO OPTIMALITY: {short}" in v.design_bound
    assert v.words().endswith("; NOT SOLVED TO OPTIMALITY: its numbers may differ on "
                              "another machine.")
    assert "NOT SOLVED TO OPTIMALITY" in text and "γ stage feasible after 8 of at most 8 " \
        "interior-point iterations (stopped by the cap)" in text
    # the frozen-point design delivered in its place is not built from the SDPs
    assert dataclasses.replace(d, kind="frozen").sdp_shortfall == ""
    d, summary, v, text = delivered(None)
    assert summary["sdp_status"] == {"gamma": "optimal"} and summary["sdp_shortfall"] == ""
    assert "OPTIMALITY" not in d.verdict + v.words() + text
    assert "γ stage optimal after 10 of at most 100 interior-point iterations" in text


def test_the_speed_range_table_says_where_sigma_over_all_axes_is_worse():
    """A generated compressor's H∞ (seed 0): zone B on its worst axis at 43.5 Hz but σ̄(S_o)
    over all axes 9.12 there, which the verdict counts ("reaches zone D (peak 9.12)"). The
    speed-range table names that zone and peak in the speed's cell, graded by ISO
    14839-3's limit of 5; at a speed where σ̄(S_o) is no worse than its axes, the cell
    says only the axes' zone."""
    from ambseal.report.run_report import _speed_range_section

    axes = ("A_zeta", "B_eta")

    def case(f, sigma, per_axis, disc_sigma):
        return {"controller": "hinf", "pressure_bar": 0.0, "speed_hz": f, "stable": True,
                "label": f"0 bar, {f:g} Hz", "sensitivity_peak": sigma,
                "iso_zone": "D" if sigma >= 5 else "A",
                "sensitivity_peak_per_axis": dict(zip(axes, per_axis)),
                "iso_zone_per_axis": dict(zip(axes, ("B" if x >= 3 else "A"
                                                     for x in per_axis))),
                "discrete": {"stable": True, "sensitivity_peak": disc_sigma,
                             "iso_zone": "D" if disc_sigma >= 5 else "A",
                             "iso_zone_per_axis": dict.fromkeys(axes, "A")}}

    metrics = {"stability": [case(43.5318, 9.12, (3.2, 2.1), 7.99),
                             case(174.127, 2.72, (2.1, 2.0), 2.72)]}
    table = _speed_range_section(metrics)[0]["html"]
    cells = re.findall(r"<td>([^<]*)</td>", table)
    assert cells == ["hinf", "stable, zone B; σ̄(S_o) zone D (9.12)", "stable, zone A"]
