"""H∞ and μ over the speed range on gyroscopic rotors nobody tuned: a rigid rotor (4 DOF)
and a wheel of the class ``benchmarks/bench_family.py`` generates
(``tests/data/gyro_wheel_rig.toml``, Ip/It 0.54). Designed at the top speed, each leans on
the gyroscopic stiffening of its conical mode and loses it at standstill; the rule
(:func:`ambseal.design.recipes.design`) designs it again with the spin speed a real
parameter of the LFT, uncertain from standstill to the top speed
(:mod:`ambseal.design.speed_lft`), and keeps that design where it holds every judged
speed; on a disc-like rigid rotor, at the largest level of the performance weights that
certifies the speed range (:func:`ambseal.robust.performance_level`)."""

from __future__ import annotations

import tomllib
from pathlib import Path

import control
import numpy as np
import pytest

from ambseal.config import load_rig, parse_rig
from ambseal.design import design, design_spec
from ambseal.errors import SynthesisError
from ambseal.model import build_plant
from ambseal.robust import LEVEL_FLOOR

from ..benchmark_module import bench_module
from ..rigid_rotor import inertia, rigid_amb_rig

FAMILY_RIG = Path(__file__).resolve().parents[1] / "data" / "gyro_wheel_rig.toml"


def _held_as_it_runs(cfg, K, speeds_hz) -> list[bool]:
    """python-control: per speed, the full-order plant sampled by its hold, the controller
    by Tustin with the target's delay, closed ``i = −K y``: every pole inside the unit
    circle."""
    T, d = 1 / cfg.controller.sample_rate_hz, cfg.controller.delay_samples
    Kd = control.sample_system(control.ss(K.A, K.B, K.C, K.D), T, "tustin") \
        * control.ss([], [], [], np.eye(K.noutputs), T) * control.tf([1], [1] + [0] * d, T)
    out = []
    for f in speeds_hz:
        pl = build_plant(cfg, speed_rpm=60.0 * f)
        cur = pl.current_inputs()
        G = control.ss(pl.A, pl.B[:, cur], pl.C, pl.D[:, cur])
        Gd = control.sample_system(G, T, "zoh")
        out.append(bool(np.abs(control.feedback(Gd, Kd).poles()).max() < 1))
    return out


def _held_with_delay(cfg, K, speeds_hz) -> list[bool]:
    """python-control: per speed, the full-order plant in continuous time, closed
    ``i = −K y`` through the delay τ = (n_d + 1/2)/f_s as a 6th-order Padé approximant on
    each channel: every pole in the open left half-plane."""
    tau = (cfg.controller.delay_samples + 0.5) / cfg.controller.sample_rate_hz
    num, den = control.pade(tau, 6)
    lag = control.append(*[control.ss(control.tf(num, den))] * K.noutputs)
    Kc = lag * control.ss(K.A, K.B, K.C, K.D)
    out = []
    for f in speeds_hz:
        pl = build_plant(cfg, speed_rpm=60.0 * f)
        cur = pl.current_inputs()
        G = control.ss(pl.A, pl.B[:, cur], pl.C, pl.D[:, cur])
        out.append(bool(control.feedback(G, Kc).poles().real.max() < 0))
    return out


#: Speeds between and beside the judged ones (Hz): the design over the range holds the
#: plant at every speed of it, not only at the speeds it was checked at.
BETWEEN_HZ = (0.0, 25.0, 60.0, 110.0, 170.0, 230.0, 290.0, 350.0, 400.0)


def _held_where_one_speed_is_not(rig: Path, method: str, held=None):
    """The rule's design of ``rig`` by ``method`` (``held`` where it is made already),
    after checking (python-control's poles of the sampled, delayed loop on the full-order
    plant) that the design at the top speed alone (``[design] one_speed``) loses the rotor
    at standstill and that the rule's holds it at every speed of :data:`BETWEEN_HZ`,
    designed over 0–400 Hz."""
    one = load_rig(rig, ("design.one_speed=true",))
    frozen = design(one, method, allow_unstable=True)
    assert not _held_as_it_runs(one, frozen.K, [0.0])[0]
    cfg = load_rig(rig)
    held = design(cfg, method) if held is None else held
    assert all(_held_as_it_runs(cfg, held.K, BETWEEN_HZ))
    assert held.design_speed_hz is None and held.speed_range_hz == (0.0, 400.0)
    return held


@pytest.fixture(scope="module")
def rigid_mu(tmp_path_factory):
    """``(rig path, the rule's μ design of the rigid rotor, the methods it synthesised)``:
    designed alone, no trials shared (about a minute of CPU, which two tests share)."""
    import ambseal.design.recipes as recipes

    rig = rigid_amb_rig(tmp_path_factory.mktemp("rigid"))
    made, real = [], recipes._synthesise_enlarging

    def counted(c, method, *args):
        made.append(method)
        return real(c, method, *args)

    with pytest.MonkeyPatch.context() as mp:
        mp.setattr(recipes, "_synthesise_enlarging", counted)
        held = design(load_rig(rig), "mu")
    return rig, held, made


@pytest.mark.heavy
@pytest.mark.xdist_group("rigid_mu")
@pytest.mark.parametrize("method", ["hinf", "mu"])
def test_a_rigid_gyroscopic_rotor_is_held_from_standstill_to_the_top_speed(
        tmp_path, method, request):
    """Designed at the top speed alone the loop is unstable at standstill; the design with
    the speed uncertain over 0–400 Hz holds at every speed of :data:`BETWEEN_HZ`
    (:func:`_held_where_one_speed_is_not`), and its steps say how it was designed."""
    rig, held = rigid_amb_rig(tmp_path), None
    if method == "mu":
        rig, held, _ = request.getfixturevalue("rigid_mu")
    held = _held_where_one_speed_is_not(rig, method, held)
    assert held.steps[-1].startswith(f"{method}: designed with the spin speed uncertain "
                                     "over 0–400 Hz (a real LFT parameter)")
    assert "rotor.speed" in held.uncertainty


@pytest.mark.heavy
def test_hinf_designed_over_the_speed_range_holds_from_standstill_to_the_top_speed():
    """Reference: python-control's poles of the sampled, delayed loop on the full-order
    plant at every stability speed (standstill to the top speed). The one-speed design
    (``[design] one_speed``) at the top speed loses the rotor at standstill; the design the
    rule delivers holds at every one of those speeds, designed with the speed uncertain."""
    one = load_rig(FAMILY_RIG, ("design.one_speed=true",))
    speeds = design_spec(one).stability_speeds_hz
    assert speeds[0] == 0.0 and speeds[-1] == pytest.approx(one.operating.speed_rpm / 60)
    frozen = design(one, "hinf", allow_unstable=True)
    assert not frozen.full_order["stable"] and frozen.full_order["speed_hz"] == 0.0
    assert not _held_as_it_runs(one, frozen.K, [0.0])[0]
    cfg = load_rig(FAMILY_RIG)
    held = design(cfg, "hinf")
    assert all(_held_as_it_runs(cfg, held.K, speeds))
    assert frozen.design_speed_hz is None and held.design_speed_hz is None
    assert "hinf: designed with the spin speed uncertain over 0–" in held.steps[-1]


def test_a_design_refused_over_the_speed_range_checks_what_lost_it_once(tmp_path, monkeypatch):
    """Where no design over the speed range holds, the design at the top speed is refused,
    and the refusal says the speed lost the rotor (at standstill, the conical mode, which
    the gyroscopic moments move). Whether the speed or the pressure lost it costs two
    full-order checks; they are made once, by the rule that decides whether to design over
    the speed range, and its answer is what the refusal says. Every design over the speed
    range (its schedule on speed too) is stubbed to hold nothing: only the top speed's H∞
    is synthesised."""
    import ambseal.design.recipes as recipes

    monkeypatch.setattr(recipes, "_held_over_speed", lambda *a, **k: None)
    monkeypatch.setattr(recipes, "_first_held", lambda *a, **k: None)
    monkeypatch.setattr(recipes, "_scheduled_over_speed", lambda *a, **k: None)
    asked, real = [], recipes._lost_by

    def counted(*args):
        asked.append(args[-1])
        return real(*args)

    monkeypatch.setattr(recipes, "_lost_by", counted)
    with pytest.raises(SynthesisError) as refused:
        design(load_rig(rigid_amb_rig(tmp_path)), "hinf")
    assert len(asked) == 1
    message = str(refused.value)
    assert "0 bar, 0 Hz" in message and "the gyroscopic moments move it" in message, message


@pytest.mark.heavy
@pytest.mark.parametrize("method", ["hinf", "mu"])
def test_a_disc_like_rigid_rotor_is_held_at_the_performance_level_the_speed_range_leaves(
        tmp_path, method, monkeypatch):
    """A disc-like rigid rotor (Ip/It 1.2) over 0–400 Hz: at the weights as given the H∞
    with the speed uncertain is not certified (scaled γ 2.5, measured) and loses the rotor
    at standstill, as the one-speed design does. The design at the largest performance
    level that certifies the speed range holds the rotor at every speed of
    :data:`BETWEEN_HZ` (:func:`_held_where_one_speed_is_not`), and its step names the
    level. H∞'s trials of the levels make no μ analysis: only their scaled γ is used."""
    import ambseal.robust.dk as dk
    import ambseal.robust.mu as mu

    analyses, real = [], mu.mussv

    def counted(*args, **kw):
        analyses.append(1)
        return real(*args, **kw)

    monkeypatch.setattr(mu, "mussv", counted)
    monkeypatch.setattr(dk, "mussv", counted, raising=False)
    _, it, ip = inertia(20.0, 0.622, 0.2)
    assert ip / it == pytest.approx(1.2, abs=0.01)
    held = _held_where_one_speed_is_not(rigid_amb_rig(tmp_path, 0.622), method)
    assert (len(analyses) == 0) == (method == "hinf")
    level = held.stopping["performance_level"]
    assert LEVEL_FLOOR < level["level"] < 1
    if method == "hinf":
        assert held.gamma < 1
    assert f"at {100 * level['level']:.2g} % of the performance weights" in held.steps[-1]


@pytest.mark.heavy
@pytest.mark.xdist_group("rigid_mu")
def test_mu_takes_the_speed_range_hinf_designs_that_hinf_tried_before(rigid_mu, monkeypatch):
    """One run's designs share their trials over the speed range: μ tries H∞ with the speed
    uncertain before its own, and H∞'s design has made that one. Given H∞'s trials, μ's
    design makes no H∞ synthesis of its own; without them (``rigid_mu``) it makes it again
    (``_synthesise_enlarging`` counted), and the two μ controllers are the same matrices:
    reusing a trial changes nothing but the work."""
    import ambseal.design.recipes as recipes

    rig, alone, made_alone = rigid_mu
    cfg = load_rig(rig)
    sp, trials = design_spec(cfg), {}
    design(cfg, "hinf", spec=sp, trials=trials)
    made, real = [], recipes._synthesise_enlarging

    def counted(c, method, *args):
        made.append(method)
        return real(c, method, *args)

    monkeypatch.setattr(recipes, "_synthesise_enlarging", counted)
    shared = design(cfg, "mu", spec=sp, trials=trials)
    assert "hinf" not in made and "mu" in made
    assert shared.speed_range_hz == (0.0, 400.0)
    assert "hinf" in made_alone
    for a, b in zip((shared.K.A, shared.K.B, shared.K.C, shared.K.D),
                    (alone.K.A, alone.K.B, alone.K.C, alone.K.D)):
        np.testing.assert_array_equal(a, b)


@pytest.mark.heavy
def test_a_rotor_whose_operating_count_splits_a_whirl_pair_is_held_on_whole_pairs():
    """A rig of the family (``bench_family.family_rig(7)``: Ip/It 0.89, 10 kHz, vertical,
    collocated) whose design model at the top speed (every mode below 2.5 kHz: 18
    states) keeps a flexible pair's backward whirl and not its forward one. Designed with
    the speed uncertain on those 18 states, at the weights as given or at a level of them,
    the rotor is lost; on the 16 states of whole pairs
    (:func:`ambseal.design.speed_lft.whole_pair_states`) the design holds, where the one
    designed at the top speed alone loses the rotor at standstill. Reference:
    python-control's poles of the loop on the full-order plant at every stability speed,
    standstill to the top speed, in continuous time with the computation delay and the
    hold's half sample as a Padé approximant (the loop the design is checked on; the
    controller as it runs is the run's to choose and judge: ``bench_family.py`` measures
    it)."""
    text, _ = bench_module("bench_family").family_rig(7)
    cfg = parse_rig(tomllib.loads(text))
    assert design_spec(cfg).model_states == 18
    one = cfg.model_copy(update={"design": cfg.design.model_copy(update={"one_speed": True})})
    assert not _held_with_delay(one, design(one, "hinf", allow_unstable=True).K, [0.0])[0]
    held = design(cfg, "hinf")
    assert held.speed_range_hz is not None and held.speed_range_hz[0] == 0.0
    assert "on 16 states (the 18 of the operating speed split a whirl pair)" in held.steps[-1]
    assert all(_held_with_delay(cfg, held.K, design_spec(cfg).stability_speeds_hz))


def test_hinf_scheduled_on_speed_holds_a_rigid_rotor_no_fixed_design_holds(tmp_path,
                                                                        monkeypatch):
    """The disc-like rigid rotor (Ip/It 1.2) with every fixed design over the speed range
    stubbed to hold nothing: the rule ends with H∞ scheduled on the spin speed, whose
    controller frozen at each speed of :data:`BETWEEN_HZ` and half way between the judged
    speeds — at table entries and between them — holds the loop as it runs
    (python-control's poles of the sampled, delayed loop on the full-order plant), where
    the design at the top speed alone loses the rotor at standstill. The judged speeds'
    controllers interpolated alone lose it at 250 Hz: the rule made that speed an entry.
    Its nutation is damped (ζ > 0.1), not cancelled."""
    import ambseal.design.recipes as recipes
    from ambseal.design.speed_schedule import SpeedScheduledHinf

    monkeypatch.setattr(recipes, "_held_over_speed", lambda *a, **k: None)
    monkeypatch.setattr(recipes, "_first_held", lambda *a, **k: None)
    rig = rigid_amb_rig(tmp_path, 0.622)
    one = load_rig(rig, ("design.one_speed=true",))
    assert not _held_as_it_runs(one, design(one, "hinf", allow_unstable=True).K, [0.0])[0]
    held = design(load_rig(rig), "hinf")
    K = held.controller
    assert isinstance(K, SpeedScheduledHinf) and held.speed_range_hz == (0.0, 400.0)
    table = set(np.round(K.speeds_hz, 6))
    judged = sorted(set(np.round(design_spec(load_rig(rig)).stability_speeds_hz, 6)) | {400.0})
    added = table - set(judged)
    assert added == set(held.stopping["hinf"]["added_speeds_hz"])
    assert any(f not in table for f in BETWEEN_HZ)
    cfg = load_rig(rig)
    # between the entries and half way between the judged speeds: the linear
    # interpolation of the judged speeds' controllers alone loses the loop at 250 Hz,
    # which became an entry
    halves = [(a + b) / 2 for a, b in zip(judged[:-1], judged[1:])]
    assert all(_held_as_it_runs(cfg, K.at(2 * np.pi * f), [f])[0]
               for f in sorted({*BETWEEN_HZ, *halves}))
    assert held.steps[-1].startswith("hinf: designed as a controller scheduled on the spin "
                                     "speed over 0–400 Hz (the central H∞ controllers with an "
                                     "unbalance-orbit demand of 10 µm")
    assert (f"{len(judged)} judged speeds and {len(added)} between them where the "
            "interpolated loop was lost" in held.steps[-1]) == bool(added)
    # the nutation (forward, near Ω Ip/It) damped where it runs, not cancelled
    assert min(_nutation_damping(cfg, K, f) for f in (350.0, 400.0)) > 0.1
    assert held.verdict.startswith(f"H∞ γ = {K.gamma:.3g} on the design model frozen at each "
                                   f"of its {len(table)} table speeds")
    # its frozen controller at the operating speed is the delivered K
    np.testing.assert_array_equal(held.K.A, K.at(2 * np.pi * 400.0).A)


def test_mu_scheduled_on_speed_is_the_k_step_on_each_frozen_plant(tmp_path):
    """μ asked for scheduled on the spin speed on the disc-like rigid rotor (Ip/It 1.2, no
    seal: the spin speed is its only uncertainty, so the frozen structure is the
    performance block alone and each entry's μ is the H∞ norm of its frozen loop). Each
    entry's reported μ is that norm by slycot AB13DD (python-control ``norm``), the
    design's μ the largest; the controller frozen at each speed of :data:`BETWEEN_HZ`
    and half way between the table's speeds holds the loop as it runs (python-control's
    poles of the sampled, delayed loop on the full-order plant)."""
    from ambseal.design.speed_lft import at_speed

    cfg = load_rig(rigid_amb_rig(tmp_path, 0.622))
    held = design(cfg, "mu", scheduled_on_speed=True)
    K, stop = held.controller, held.stopping["mu"]
    assert held.speed_range_hz == (0.0, 400.0) and stop["d_scales"] == 0
    assert len(held.plant.blocks) == 2  # the speed's, then the performance block
    for th, mu in zip(K.table_theta, stop["mu_by_speed"]):
        Kf = control.ss(*K.K.matrices(float(th)))
        norm = control.norm(at_speed(held.plant, th).lft(Kf, 4, 4), p="inf")
        assert norm * (1 - 1e-2) <= mu <= norm * (1 + 1e-3), (th, mu, norm)
    assert held.mu == max(stop["mu_by_speed"]) < 1
    speeds = list(K.speeds_hz)
    halves = [(a + b) / 2 for a, b in zip(speeds[:-1], speeds[1:])]
    assert all(_held_as_it_runs(cfg, K.at(2 * np.pi * f), [f])[0]
               for f in sorted({*BETWEEN_HZ, *halves}))
    assert held.steps[-1].startswith("mu: designed as a controller scheduled on the spin "
                                     "speed over 0–400 Hz (the central H∞ controllers of μ's "
                                     "weights with an unbalance-orbit demand of")
    assert held.verdict.startswith(f"robust performance met: μ = {held.mu:.3g} ≤ 1 on the "
                                   f"design model frozen at each of its {len(speeds)} table "
                                   "speeds, scheduled on speed")


def _nutation_damping(cfg, K, speed_hz: float) -> float:
    """python-control: the least damping ratio of the continuous full-order loop's poles
    between 0.5 and 3× the spin speed, where the rigid disc's nutation lies (Ω Ip/It)."""
    pl = build_plant(cfg, speed_rpm=60.0 * speed_hz)
    cur = pl.current_inputs()
    Kf = K.at(2 * np.pi * speed_hz)
    p = control.feedback(control.ss(pl.A, pl.B[:, cur], pl.C, pl.D[:, cur]),
                         control.ss(Kf.A, Kf.B, Kf.C, Kf.D)).poles()
    w = 2 * np.pi * speed_hz
    p = p[(np.abs(p) > 0.5 * w) & (np.abs(p) < 3 * w)]
    return float(np.min(-p.real / np.abs(p)))


def test_hinf_scheduled_on_speed_without_the_orbit_demand_cancels_the_nutation(tmp_path,
                                                                               monkeypatch):
    """With ``design.hinf.orbit_um = 0`` (the demand switched off) the schedule is designed
    as set, on S_o and K S_o alone: its central controllers cancel the nutation rather
    than damp it (ζ below 0.01 at the top speed, python-control's loop poles), which is
    why the rule gives the schedule μ's orbit demand."""
    import ambseal.design.recipes as recipes

    monkeypatch.setattr(recipes, "_held_over_speed", lambda *a, **k: None)
    monkeypatch.setattr(recipes, "_first_held", lambda *a, **k: None)
    cfg = load_rig(rigid_amb_rig(tmp_path, 0.622), ("design.hinf.orbit_um=0",))
    held = design(cfg, "hinf")
    assert "orbit demand" not in held.steps[-1]
    assert _nutation_damping(cfg, held.controller, 400.0) < 0.01


def test_ambseal_design_exports_the_hinf_scheduled_on_speed(tmp_path, monkeypatch, capsys):
    """``ambseal design --method hinf`` of a rig whose H∞ is scheduled on speed exports the
    schedule, not its frozen controller at the operating speed: the file's discrete table
    at standstill is python-control's transform of the design frozen there by the method
    chosen (no pole removed on this rig), in frequency response."""
    import json

    import ambseal.design.recipes as recipes
    from ambseal.cli import main
    from ambseal.export import load_controller

    monkeypatch.setattr(recipes, "_held_over_speed", lambda *a, **k: None)
    monkeypatch.setattr(recipes, "_first_held", lambda *a, **k: None)
    rig = rigid_amb_rig(tmp_path, 0.622)
    assert main(["design", str(rig), "--method", "hinf", "--out", str(tmp_path / "d")]) == 0
    out = json.loads(capsys.readouterr().out)
    method = out["discretisation"]["method"]
    assert out["loop"]["loop_holds"] and not out["discretisation"]["removed_poles_hz"]
    K = design(load_rig(rig), "hinf").controller
    T = 1.0 / load_rig(rig).controller.sample_rate_hz
    table = load_controller(tmp_path / "d" / "controller_hinf.npz")
    assert hasattr(table, "statespace_at")
    ref = control.sample_system(K.at(0.0), T, method=method)
    got = table.statespace_at(0.0)
    z = np.exp(1j * 2 * np.pi * np.logspace(0, np.log10(0.45 / T), 40) * T)
    np.testing.assert_allclose(got(z), ref(z), rtol=1e-7, atol=1e-7 * np.abs(ref(z)).max())
    # and not the controller at the operating speed (400 Hz)
    top = control.sample_system(K.at(2 * np.pi * 400.0), T, method=method)
    assert np.abs(top(z) - ref(z)).max() > 1e-3 * np.abs(ref(z)).max()


def test_only_hinf_and_mu_on_the_continuous_plant_are_asked_for_scheduled(tmp_path):
    """The direct route to the schedule (the run's remedy for a fixed H∞ beyond zone B as
    it runs, tests/test_rejection_through_critical.py) is for the synthesised methods on
    a rig with a speed range and the continuous synthesis plant."""
    from ambseal.errors import ConfigError

    cfg = load_rig(rigid_amb_rig(tmp_path, 0.4))
    with pytest.raises(ConfigError, match="scheduled_on_speed"):
        design(cfg, "pid", scheduled_on_speed=True)
    sampled = cfg.model_copy(update={"design": cfg.design.model_copy(
        update={"synthesis_plant": "sampled"})})
    with pytest.raises(ConfigError, match="scheduled_on_speed"):
        design(sampled, "hinf", scheduled_on_speed=True)
