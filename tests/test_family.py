"""The seeded family of gyroscopic rigs of ``benchmarks/bench_family.py``, three seeds run
end to end as the benchmark runs them (``ambseal run --no-identify`` in a child process):
each rig is what the generator's docstring promises (Ip/It about the centre of mass from
ambseal's rigid-body inertia, the first free–free bending frequency against the top
speed, checked again here), the run writes its metrics, and at least one method is
delivered as it runs from standstill to the top speed, zone A or B on every axis
(:func:`bench_family.delivered`)."""

from __future__ import annotations

import sys
import tomllib

import pytest

from ambseal.config import parse_rig
from ambseal.model.modes import free_bending_hz

from .benchmark_module import bench_module


def _bench_family():
    return bench_module("bench_family")


def _run(bf, seed: int, tmp_path):
    """Seed ``seed``'s rig text and the metrics of its ``ambseal run --no-identify`` in a
    child process, as the benchmark runs it."""
    import json
    import subprocess

    text, _ = bf.family_rig(seed)
    rig = tmp_path / "rig.toml"
    rig.write_text(text, encoding="utf-8")
    cmd = [sys.executable, "-c", "import sys; from ambseal.cli import main; "
           "sys.exit(main(sys.argv[1:]))", "run", str(rig), "--no-identify",
           "--out", str(tmp_path / "run")]
    done = subprocess.run(cmd, capture_output=True, text=True, timeout=1800,
                          env=bf.child_env())
    assert done.returncode in (0, 1), done.stderr[-2000:]
    return text, json.loads((tmp_path / "run" / "metrics.json").read_text())


@pytest.mark.slow
@pytest.mark.parametrize("seed", [0, 1, 2])
def test_a_family_rig_runs_end_to_end_with_a_method_delivered(seed):
    bf = _bench_family()
    text, draw = bf.family_rig(seed)
    cfg = parse_rig(tomllib.loads(text))
    ip, it = bf._inertias(cfg)
    assert 0.5 <= ip / it <= 1.5 and ip / it == pytest.approx(draw["ip_over_it"], rel=1e-9)
    top_hz = cfg.operating.speed_rpm / 60
    assert 20000 <= cfg.operating.speed_rpm <= 100000
    ratio = free_bending_hz(cfg, 1)[0] / top_hz
    assert 1.2 * (1 - 1e-3) <= ratio <= 3.0 * (1 + 1e-3)
    assert cfg.operating.speed_range_hz == pytest.approx((top_hz / 3, top_hz))
    assert cfg.controller.sample_rate_hz in bf.RATES_HZ
    row = bf.run_rig({"text": text, "draw": draw}, timeout=1800.0)
    assert row.get("returncode") in (0, 1), row.get("error")
    assert any(row["delivered"].values()), row["failed"]


@pytest.mark.slow
def test_a_disc_like_rotor_switches_its_notch_on_where_it_needs_it(tmp_path):
    """Seed 2 (Ip/It 1.09, 191–574 Hz at 40 kHz): its LPV alone needs 1.14× the bias
    current's linear range at the top speed, so the run switches its unbalance force
    rejection on. On from the minimum continuous speed the notch leaves the rotor on the
    bearings' negative stiffness near the conical critical where (Ip − It)·Ω² equals the
    tilting stiffness they take away (163 Hz for the rigid rotor), and loses the loop at
    191 Hz; the run then switches it on where the controller alone last uses at most half
    of its amplifier below its saturation, and delivers the LPV with its notch from
    there."""
    bf = _bench_family()
    text, m = _run(bf, 2, tmp_path)
    assert bf.delivered(m)["lpv"], m["failed"].get("lpv")
    lo, top = parse_rig(tomllib.loads(text)).operating.speed_range_hz
    rej = m["controllers"]["lpv"]["rejection"]
    assert rej["stable"] and rej["beyond"] is None
    assert lo < rej["on_from_hz"] < top
    assert rej["first_start"]["on_from_hz"] == pytest.approx(lo)
    assert rej["first_start"]["why"].startswith("loses the loop at")
    assert m["controllers"]["lpv"]["capacity"]["rejection_automatic"]


# a whole family rig's run, six minutes on one CI core: behind `slow` with the other family
# runs, so that CI keeps within its 30 minutes; the default run checks the remedy's wiring
# (tests/test_remedies.py) and a design on the sampled plant closed as it runs
# (tests/analysis/test_judge_sampled_design.py, tests/design/test_design_margin.py)
@pytest.mark.slow
def test_a_design_lost_only_as_it_runs_is_designed_on_the_sampled_plant(tmp_path):
    """Seed 17 (10 kHz, one sample of delay): H∞ designed on the continuous plant holds its
    continuous loop everywhere but loses a 1.3 kHz bending mode as it runs (not delivered
    before the sampled design). The run designs it again on the sampled plant and delivers
    it; its exported discrete controller, with its delay, closed by python-control with the
    ZOH-sampled full-order plant at standstill and at the top speed, is stable there."""
    import control as ct
    import numpy as np

    from ambseal.model import build_plant

    bf = _bench_family()
    text, m = _run(bf, 17, tmp_path)
    h = m["controllers"]["hinf"]
    assert h["synthesis_plant"] == "sampled" and "sampled plant" in h["remedy"]
    assert h["discretisation"]["method"] == "tustin"
    assert bf.delivered(m)["hinf"], bf.why_not(m)["hinf"]
    z = np.load(tmp_path / "run" / "controllers" / "controller_hinf.npz", allow_pickle=False)
    T, nd = float(z["Ts"]), int(z["delay_samples"])
    assert str(z["synthesis_plant"]) == "sampled"  # what other commands close as it runs
    Kd = ct.ss(z["A"], z["B"], z["C"], z["D"], T)
    delay = ct.ss(np.zeros((4, 4)), np.eye(4), np.eye(4), np.zeros((4, 4)), T)  # z⁻¹
    assert nd == 1
    cfg = parse_rig(tomllib.loads(text))
    for speed_rpm in (0.0, cfg.operating.speed_rpm):
        pl = build_plant(cfg, pressure_bar=0.0, speed_rpm=speed_rpm)
        G = pl.select_inputs([pl.input_names[j] for j in pl.current_inputs()])
        assert [str(n) for n in z["inputs"]] == list(G.output_names)
        assert [str(n) for n in z["outputs"]] == list(G.input_names)
        Gd = ct.sample_system(ct.ss(G.A, G.B, G.C, G.D), T, method="zoh")
        loop = ct.feedback(Gd, delay * Kd)  # u = −K y, one sample late
        assert np.abs(loop.poles()).max() < 1.0


@pytest.mark.slow
def test_a_rig_no_fixed_mu_holds_gets_mu_and_hinf_scheduled_on_speed(tmp_path):
    """Seed 9 (Ip/It 1.43, 0–363 Hz at 10 kHz, no seal): every fixed μ over the speed range
    loses the rigid conical mode at standstill, and the fixed H∞ holds its loops but
    reaches ISO 14839-3 zone D on an axis as it runs. The run delivers μ scheduled on the
    spin speed (μ below 1 at every entry) and H∞ scheduled as its remedy; each exported
    table, closed by python-control with the ZOH-sampled full-order plant at 17 speeds
    and the judged ones, holds the rotor at zone B or better on every axis
    (:func:`tests.exported_files.runs_from_standstill_to_the_top_speed`)."""
    from .exported_files import runs_from_standstill_to_the_top_speed

    bf = _bench_family()
    _, m = _run(bf, 9, tmp_path)
    rig = tmp_path / "rig.toml"
    mu = m["controllers"]["mu"]
    assert mu["steps"][-1].startswith("mu: designed as a controller scheduled on the spin "
                                      "speed"), mu["steps"][-1]
    assert mu["mu"] < 1 and "scheduled on speed" in mu["verdict"]
    assert m["controllers"]["hinf"]["remedy"].startswith("designed scheduled on the spin "
                                                         "speed")
    assert bf.delivered(m)["mu"] and bf.delivered(m)["hinf"], bf.why_not(m)
    for method in ("mu", "hinf"):
        runs_from_standstill_to_the_top_speed(rig, m, tmp_path / "run", method)


@pytest.mark.slow
def test_a_fixed_mu_beyond_zone_b_as_it_runs_is_scheduled_on_speed(tmp_path):
    """Seed 10 (Ip/It 1.18, 0–360 Hz): a fixed μ over the speed range holds every loop but
    reaches σ̄(S_o) 5.8 on an axis at standstill (ISO 14839-3 zone D). The run designs μ
    again scheduled on the spin speed, which replaces it (its ``remedy`` says so) and is
    delivered; python-control holds the exported table at 17 speeds at zone B or better
    on every axis (:func:`tests.exported_files.runs_from_standstill_to_the_top_speed`)."""
    from .exported_files import runs_from_standstill_to_the_top_speed

    bf = _bench_family()
    _, m = _run(bf, 10, tmp_path)
    mu = m["controllers"]["mu"]
    assert mu["remedy"].startswith("designed scheduled on the spin speed: the fixed design "
                                   "over the speed range reaches ISO 14839-3 zone")
    assert mu["mu"] < 1 and bf.delivered(m)["mu"], bf.why_not(m)["mu"]
    runs_from_standstill_to_the_top_speed(tmp_path / "rig.toml", m, tmp_path / "run", "mu")


def test_every_method_not_delivered_says_why():
    """:func:`bench_family.why_not` on a run's metrics: a method not designed, one failed,
    one its target cannot run, one whose worst axis as it runs is at zone C (σ̄(S_o) 4 or
    more: ISO 14839-3's B/C limit) at a speed of the range between the judged ones, each
    with its reason, and one delivered (None)."""
    bf = _bench_family()

    def case(method, speed, peaks):
        return {"controller": method, "speed_hz": speed, "pressure_bar": 0.0,
                "sensitivity_peak_per_axis": {"A_zeta": 1.0, "A_eta": 1.0},
                "discrete": {"sensitivity_peak_per_axis": peaks}}

    metrics = {"controllers": {"pid": {}, "hinf": {}, "mu": {}, "lpv": {}},
               "failed": {"hinf": {"reason": "unstable at 0 Hz"}},
               "cannot_run": {"mu": "highest controller pole 7.9e+06 Hz"},
               "cases": [case("pid", 0.0, {"A_zeta": 2.5, "A_eta": 2.5}),
                         case("pid", 300.0, {"A_zeta": 2.5, "A_eta": 2.5}),
                         case("lpv", 300.0, {"A_zeta": 3.9, "A_eta": 2.0})],
               "stability": [case("pid", 150.0, {"A_zeta": 2.5, "A_eta": 4.2}),
                             case("lpv", 150.0, {"A_zeta": 3.9, "A_eta": 2.0})]}
    metrics["controllers"].pop("lpv")
    why = bf.why_not(metrics)
    assert why == {"pid": "zone C/D: σ̄(S_o) 4.2 on A_eta at 150 Hz, 0 bar",
                   "hinf": "failed: unstable at 0 Hz",
                   "mu": "cannot run: highest controller pole 7.9e+06 Hz",
                   "lpv": "not designed"}
    metrics["controllers"]["lpv"] = {}
    assert bf.why_not(metrics)["lpv"] is None
    assert bf.delivered(metrics) == {"pid": False, "hinf": False, "mu": False, "lpv": True}
