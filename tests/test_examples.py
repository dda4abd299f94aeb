"""Every example rig end to end, and unusual rigs (a rig without a seal,
a rig with one AMB and one plain bearing): ``ambseal run --no-identify`` exits 0 and every
controller is stable on the full-order plant at every judged condition, as designed and as
it runs on the target — or the run states plainly which one cannot run and why.

The full runs are ``slow`` (15–50 s of CPU each). The default suite keeps the cheap
parts: the test rig and the turboexpander run end to end in tests/test_pipeline.py (with
the session's designs), and the part that broke the blower and the pump (their PID
derived from the rig could not run on the target; a controller that cannot run stopped
the run) is tests/design/test_design_pid_rule.py.
"""

from __future__ import annotations

import json
import re
from pathlib import Path

import control
import numpy as np
import pytest

from ambseal.cli import main
from ambseal.config import load_rig
from ambseal.design.recipes import ORDER_RISE
from ambseal.model import build_plant

from .exported_files import file_at, rejection_held_by_python_control
from .metrics_schema import validate_metrics
from .report_agreement import check_report_agrees

EXAMPLES = sorted((Path(__file__).resolve().parents[1] / "examples").glob("*.toml"))
TESTRIG = Path(__file__).resolve().parents[1] / "examples" / "testrig.toml"


#: Controllers that fail an example's speed range, measured: the flywheel's H∞ and μ, with
#: the spin speed uncertain over 0–1 000 Hz, lose its conical modes at standstill and
#: between (the LPV on speed holds it). The overhung compressor's H∞ (γ 1.03) and the
#: turboexpander-generator's μ (designed again with the spin speed uncertain from
#: standstill to 525 Hz, where at 525 Hz alone it lost a rigid conical mode near
#: standstill) hold every judged condition.
FAIL_BELOW_TOP = {"flywheel": {"hinf", "mu"}}

#: Rigs whose reference PID, derived from the rig, loses the rotor at the nominal
#: condition, measured: on the flywheel, with its integral below the precession, no
#: corner, lead, lag or notch keeps the first bending modes near 2.2 kHz damped through the
#: 2 kHz amplifier and the 75 µs hold + delay at every speed, and the notches that do at
#: standstill cost the nutation (0.44–1.02 kHz) its phase lead; cross-axis gains on each
#: bearing do not hold it (benchmarks/README.md). Reported, not counted in the exit
#: status; the LPV on speed holds it. On the turboexpander-generator the derived PID
#: loses the wheel's backward bending mode (~1.3 kHz at the top speed) to the target's lag.
PID_LOSES = {"flywheel", "expander_generator"}


def _lpv_holds_everywhere(metrics: dict) -> None:
    """The LPV on speed the run adds where a frozen design loses the rotor over the speed
    range: designed, exported, and stable at every judged pressure and stability speed,
    continuous and as it runs."""
    assert "lpv" in metrics["controllers"] and "lpv" not in metrics["failed"]
    rows = [c for c in metrics["stability"] if c["controller"] == "lpv"]
    assert {c["speed_hz"] for c in rows} == {c["speed_hz"] for c in metrics["stability"]}
    assert all(c["stable"] and c["discrete"]["stable"] for c in rows), rows


def _run(rig: Path, out: Path, capsys, failing: set = frozenset()) -> tuple[dict, str]:
    pid_loses = rig.stem in PID_LOSES
    code = main(["--quiet", "run", str(rig), "--no-identify", "--out", str(out)])
    err = capsys.readouterr().err
    assert code == (1 if failing else 0), err
    assert "Traceback" not in err
    metrics = json.loads((out / "metrics.json").read_text())
    failed = metrics["failed"]
    assert {m for m, f in failed.items() if f["designed"]} == set(failing), failed
    # the reference PID (given, not designed) may fail above the nominal pressure only, as
    # the thesis's does (P5 Fig. 13): reported, not counted in the exit status
    nominal = metrics["controllers"].get("pid", {}).get("pressure_bar", 0.0)
    for m, f in failed.items():
        if not f["designed"] and not pid_loses:
            assert all(c["pressure_bar"] > nominal + 1e-9 for c in metrics["cases"]
                       if c["controller"] == m and not c["stable"]), f
    speeds = [c["speed_hz"] for c in [*metrics["cases"], *metrics["stability"]]]
    top = max(speeds) if speeds else None
    for m in failing:  # only in the speed range, below the top speed
        assert all(c["speed_hz"] < top for c in metrics["stability"]
                   if c["controller"] == m and not c["stable"])
        assert all(c["stable"] for c in metrics["cases"] if c["controller"] == m)
    if failing:
        _lpv_holds_everywhere(metrics)
    check_report_agrees(out)
    return metrics, err


def _check_stable_or_stated(metrics: dict, err: str, pid_loses: bool = False) -> None:
    """H∞/μ/LPV: stable at every judged condition, continuous and as it runs; the PID at
    every condition up to the nominal pressure (above it the thesis's own finding is that
    the PID goes unstable, P5 Fig. 13, and the verdict says so). A controller that cannot
    run on the target is named in metrics' ``cannot_run`` and on stderr, judged
    continuous only."""
    cannot = metrics["cannot_run"]
    for reason in cannot.values():
        assert reason in err
    nominal = metrics["controllers"].get("pid", {}).get("pressure_bar", 0.0)
    for c in metrics["cases"]:
        name = c["controller"]
        if name == "pid" and (pid_loses or c["pressure_bar"] > nominal + 1e-9):
            continue
        assert c["stable"], (name, c["pressure_bar"], c["speed_hz"])
        if name in cannot:
            assert "discrete" not in c
        else:
            assert c["discrete"]["stable"], (name, c["pressure_bar"], c["speed_hz"])


@pytest.mark.slow
@pytest.mark.parametrize("rig", EXAMPLES, ids=lambda p: p.stem)
def test_every_example_runs_end_to_end(rig, tmp_path, capsys):
    """`ambseal run RIG --no-identify` on each example exits 0 with
    all three designs (PID, H∞, μ; LPV beside them on a speed-scheduled rig, or where a
    frozen design loses the rotor over the speed range), and every
    loop is stable on the full-order plant (or the run says why not) — from standstill to
    the top speed, but for the measured :data:`FAIL_BELOW_TOP`, which exit 1; and every
    delivered controller's exported file holds the sampled full-order plant at every
    judged condition by python-control (:func:`_held_by_python_control`)."""
    metrics, err = _run(rig, tmp_path / "out", capsys, FAIL_BELOW_TOP.get(rig.stem, set()))
    validate_metrics(metrics)
    _check_stable_or_stated(metrics, err, rig.stem in PID_LOSES)
    _held_by_python_control(rig, metrics, tmp_path / "out")
    assert {c["controller"] for c in metrics["cases"]} >= {"pid", "hinf", "mu"}
    # a rig with its stages is signed off (API 617, ISO 14839-2) with every delivered
    # controller, the verdict the criteria's
    if load_rig(rig).stage:
        delivered = set(metrics["controllers"]) - set(metrics["failed"])
        so = metrics["signoff"]["controllers"]
        assert set(so) == delivered and all(v["level1"]["Q_A"] > 0 for v in so.values())
        assert all(v["passed"] == all(c["passed"] for c in v["criteria"]
                                      if c["counts"] and c["graded"])
                   for v in so.values())
        assert metrics["signoff"]["passed"] == all(v["passed"] for v in so.values())
        assert metrics["signoff"]["verdict"].startswith("Sign-off ")
        assert all((tmp_path / "out" / n).is_file()
                   for n in ("unbalance.png", "level1.png", "api617_unbalance.png"))
    else:
        assert "signoff" not in metrics
    # μ: ISO 14839-3 zone A (σ̄(S_o) < 3 per axis) at every judged condition, and the
    # automatic order keeps the design's μ within ORDER_RISE of the full-order one
    for c in (c for c in metrics["cases"] if c["controller"] == "mu"):
        assert max(c["sensitivity_peak_per_axis"].values()) < 3.0, c
    red = metrics["controllers"]["mu"]["reduction"]
    assert red is None or red["mu"] <= (1 + ORDER_RISE) * red["mu_full"]
    # the unbalance force rejection, where the rig asks for it (every delivered controller
    # gets one) or where the run switched it on (a controller that alone saturates its
    # amplifier): its loops hold at every condition judged where it is on, and its
    # synchronous coil current is below 1 % of the controller's alone over the range
    delivered = set(metrics["controllers"]) - set(metrics["failed"]) \
        - set(metrics["cannot_run"])
    rejected = {m for m in delivered if "rejection" in metrics["controllers"][m]}
    if load_rig(rig).design.rejection.enabled:
        assert rejected == delivered
    for m in rejected:
        assert metrics["controllers"][m]["capacity"].get("rejection_automatic", False) \
            != load_rig(rig).design.rejection.enabled
    if rejected:
        for m in rejected:
            r = metrics["controllers"][m]["rejection"]
            assert r["files"] and r["stable"] and r["conditions"], (m, r["conditions"])
            assert r["current_ratio"] < 1e-2, (m, r["current_ratio"])
            assert r["facility"]["after_a"] < 1e-2 * r["facility"]["before_a"], m
            given = load_rig(rig).design.rejection.runout_um
            assert given is None or r["facility"]["runout_um"] == pytest.approx(given)
        # notch files only beside a delivered controller whose notched orbit fits the rig
        for m, summary in metrics["controllers"].items():
            r = summary.get("rejection") or {}
            if r.get("files"):
                assert m in delivered and r["beyond"] is None, (m, r.get("beyond"))
        assert not [f for f in (tmp_path / "out" / "controllers").glob("rejection_*")
                    if f.name.split(".")[0].removeprefix("rejection_") not in delivered]
        assert (tmp_path / "out" / "rejection.png").is_file()
        rejection_held_by_python_control(rig, metrics, tmp_path / "out")
    _every_file_through_every_command(rig, tmp_path / "out", tmp_path, capsys)


def _every_file_through_every_command(rig: Path, out: Path, tmp: Path, capsys) -> None:
    """What one command wrote, fed to every command that reads it: each controller file
    the run exported (every kind and format) through ``export``, and the JSON one through
    ``modes``, ``campbell`` and ``sweep`` at the nominal point (and ``signoff`` for a rig
    with stages, once): each exits 0 with a JSON line saying what it did, without a
    traceback. A controller whose files say its judged loop does not hold (the test rig's
    reference PID, lost at 4.08 bar) is refused by ``export`` in one line, and exported
    with ``--allow-unstable``."""
    cfg = load_rig(rig)
    p, f = cfg.operating.pressure_bar, abs(cfg.operating.speed_rpm) / 60.0
    files = sorted((out / "controllers").glob("controller_*.*"))
    assert files
    signed = False
    for path in files:
        doc = json.loads(path.with_suffix(".json").read_text())
        holds = doc["loop_holds"]
        # export judges the file's loop alone, as it runs: refused where that loop is lost
        v = doc["verdict"]
        if holds == "no" and ("full-order loop is unstable" in v or "the loop is unstable" in v
                              or "unstable at" in v and "Padé" not in v):
            code = main(["--quiet", "export", str(rig), "--out", str(tmp / "refused"),
                         "--controller", str(path)])
            err = capsys.readouterr().err.strip()
            assert code == 2 and "\n" not in err and "--allow-unstable" in err, err
        runs = [["export", rig, "--out", tmp / f"ex_{path.name}",
                 *(["--allow-unstable"] if holds == "no" else [])]]
        if path.suffix == ".json":
            runs += [["modes", rig, "--json", "--pressure-bar", p, "--speed-rpm", 60.0 * f],
                     ["campbell", rig, "--pressure-bar", p, "--speed-hz", f"0:{f:g}:2",
                      "--out", tmp / f"cb_{path.stem}"],
                     ["sweep", rig, "--pressure-bar", p, "--speed-hz", f, "--workers", "1",
                      "--out", tmp / f"sw_{path.stem}"]]
            if cfg.stage and not signed:
                runs.append(["signoff", rig, "--json", "--out", tmp / f"so_{path.stem}"])
                signed = True
        for argv in runs:
            code = main(["--quiet", *map(str, argv), "--controller", str(path)])
            cap = capsys.readouterr()
            assert "Traceback" not in cap.err, (argv[0], path.name, cap.err)
            assert code in ((0, 1) if argv[0] == "signoff" else (0,)), \
                (argv[0], path.name, cap.err)
            assert json.loads(cap.out), (argv[0], path.name)


def _held_by_python_control(rig: Path, metrics: dict, out: Path) -> None:
    """The independent check of what the run delivers: each delivered controller's
    exported discrete file (``controllers/controller_<m>.npz``, a scheduled one
    interpolated at each speed as the file says) with ambseal's full-order plant sampled
    by python-control (``sample_system``, zero-order hold), the file's computation delay
    as ``z⁻ᵈ``, closed ``i = −u`` by ``control.feedback``: every pole inside the unit circle
    at every pressure and speed the run judged stability at."""
    cfg = load_rig(rig)
    delivered = set(metrics["controllers"]) - set(metrics["failed"]) - set(metrics["cannot_run"])
    assert delivered, metrics["failed"]
    conditions = {(c["pressure_bar"], c["speed_hz"]) for c in metrics["stability"]}
    for m in sorted(delivered):
        f = np.load(out / "controllers" / f"controller_{m}.npz", allow_pickle=False)
        Ts, d = float(f["Ts"]), int(f["delay_samples"])
        for p, hz in sorted(conditions):
            K = control.ss(*file_at(f, hz), Ts) * control.tf([1], [1] + [0] * d, Ts)
            plant = build_plant(cfg, pressure_bar=p, speed_rpm=60.0 * hz)
            cur = plant.current_inputs()
            G = control.ss(plant.A, plant.B[:, cur], plant.C, plant.D[:, cur])
            z = control.feedback(control.sample_system(G, Ts, "zoh"), K).poles()
            assert np.abs(z).max() < 1, (rig.stem, m, p, hz, np.abs(z).max())


def _testrig_without(kind: str) -> str:
    """The test rig's text without its seal, or with AMB B replaced by a plain bearing."""
    text = TESTRIG.read_text()
    if kind == "seal":
        return re.sub(r"\n\[\[seal\]\]\n(?:[^\n\[#][^\n]*\n)*", "\n", text)
    block = re.search(r"\n\[\[amb\]\]\nname = \"B\"\n(?:[^\n\[#][^\n]*\n)*", text)
    pos = re.search(r"\nposition = ([0-9.]+)", block.group(0)).group(1)
    return text.replace(block.group(0), f"\n[[spring]]\nname = \"bearing_B\"\nposition = "
                                         f"{pos}\nkxx = 5.0e7\nkyy = 5.0e7\n")


@pytest.mark.slow
def test_a_rig_without_seal_runs_end_to_end_with_a_note(tmp_path, capsys):
    """No seal — H∞ and μ designed without seal uncertainty, the summary
    says so; every loop stable (the seal-less rig has nothing to destabilise at 2×)."""
    rig = tmp_path / "noseal.toml"
    rig.write_text(_testrig_without("seal"))
    metrics, err = _run(rig, tmp_path / "out", capsys)
    _check_stable_or_stated(metrics, err)
    notes = " ".join(metrics["controllers"]["mu"]["notes"])
    assert "seal" in notes
    assert metrics["controllers"]["mu"]["uncertainty"] == {}


@pytest.mark.slow
def test_a_rig_with_one_amb_and_a_plain_bearing_runs_or_is_refused_plainly(tmp_path, capsys):
    """One AMB (2 axes) and a stiff plain bearing (a 5e7 N/m spring) at AMB B's
    place: run end to end, or refused with one line (exit 2) naming the mode the design
    destabilised and what to do, or run with the controllers that fail named in
    ``failed`` with their conditions (exit 1). Measured: H∞, designed on the nominal
    plant, destabilises the 207 Hz mode at 0 bar (ζ −0.004)."""
    rig = tmp_path / "oneamb.toml"
    rig.write_text(_testrig_without("amb"))
    code = main(["--quiet", "run", str(rig), "--no-identify", "--out", str(tmp_path / "o")])
    err = capsys.readouterr().err
    assert "Traceback" not in err
    if code == 2:
        line, = err.strip().splitlines()
        assert re.search(r"the mode at [0-9.]+ Hz has damping ζ = -", line)
        assert "--allow-unstable" in line
        return
    metrics = json.loads((tmp_path / "o" / "metrics.json").read_text())
    designed_failed = {m for m, f in metrics["failed"].items() if f["designed"]}
    assert code == (1 if designed_failed else 0), err
    for m in designed_failed:  # named with the conditions its loops are unstable at
        f = metrics["failed"][m]
        assert f["conditions"] and f"ambseal: {f['reason']}" in err
    ok = {c["controller"] for c in metrics["cases"]} - set(metrics["failed"])
    _check_stable_or_stated({**metrics, "cases": [c for c in metrics["cases"]
                                                  if c["controller"] in ok]}, err)
    assert all(len(c["iso_zone_per_axis"]) == 2 for c in metrics["cases"] if c["stable"])


@pytest.mark.slow
def test_the_manuals_compressor_is_judged_from_standstill_to_the_top_speed(tmp_path, capsys):
    """The manual's compressor (docs/rigs/compressor.toml, 150 Hz, range 60–165 Hz): its μ,
    designed at the nominal pressure, robust to the seals' k but not to the piston's K,
    loses a rigid-body mode at 0 bar; the run's first remedy designs it at 0 bar, keeping
    the seal uncertainty at the width it spans at the nominal pressure (where k is 0, ±100 %
    of it has none: that retry had failed on the default it chose), and that μ holds at
    every judged pressure and speed, so nothing is failed and the run exits 0. H∞, designed
    at 30 bar, loses the rotor at 0 bar; redesigned there (the first remedy) with a damping
    margin on its 348 Hz mode, which the plain design loses at standstill, it holds
    everywhere. The LPV on speed holds everywhere. Every controller is closed at each judged
    pressure from 0 to 165 Hz in quarters."""
    rig = Path(__file__).resolve().parents[1] / "docs" / "rigs" / "compressor.toml"
    code = main(["--quiet", "run", str(rig), "--no-identify", "--out", str(tmp_path / "o")])
    err = capsys.readouterr().err
    assert code == 0 and "Traceback" not in err
    m = json.loads((tmp_path / "o" / "metrics.json").read_text())
    validate_metrics(m)
    speeds = {c["speed_hz"] for c in m["stability"]}
    assert speeds == {0.0, 41.25, 60.0, 82.5, 123.75, 165.0}
    assert m["failed"] == {}
    mu = m["controllers"]["mu"]
    assert mu["pressure_bar"] == 0.0 and mu["remedy"].startswith("designed at 0 bar: ")
    assert "lost the loop at 0 bar" in mu["remedy"]
    assert any("damping there lowered" in s for s in m["controllers"]["hinf"]["steps"])
    for method in ("mu", "hinf"):
        assert all(c["stable"] and c["discrete"]["stable"] for c in m["stability"]
                   if c["controller"] == method)
    _lpv_holds_everywhere(m)
