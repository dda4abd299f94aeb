"""What the judged unbalance asks of the amplifiers (analysis/amplifier.py), against
python-control's frequency responses of the same loop and the closed forms of the limits."""

import math

import control as ct
import numpy as np
import pytest

from ambseal.analysis.amplifier import (SWITCH_ON_FRACTION, capacity_block, capacity_words,
                                        force_demand, later_switch_on_hz, notched_currents,
                                        switch_on_hz,
                                        used_by_speed)
from ambseal.analysis.judge import OperatingPoint, judge, judge_settings
from ambseal.analysis.unbalance import forward_forces, unbalance_force
from ambseal.design.specs import design_spec
from ambseal.model import amb_factors
from ambseal.model.rig import build_plant


@pytest.fixture(scope="module")
def judged(testrig_cfg, testrig_designs):
    """The embedded rig's H∞ controller judged at 0 bar (continuous, with its delay)."""
    s = judge_settings(design_spec(testrig_cfg))
    K = testrig_designs["hinf"].K
    case, curves = judge(testrig_cfg, K, "hinf", OperatingPoint(0.0, 0.0, "0 bar"), s)
    return s, K, case, curves


def test_unbalance_current_is_the_controller_on_the_compliance(testrig_cfg, judged):
    """Reference: python-control's responses of the same loop at the axis's worst speed —
    the plant built at that speed from the currents and from the forces at the bearings,
    the controller with its hold and computation delay as e^{−jΩτ} (τ = (n_d + ½)/f_s,
    exact, where the judge takes its Padé system) — i = K (I + G K)⁻¹ G_f T c over every
    forward-turning force of amplitude F_u (T the bearing planes' forward forces, ISO
    21940-11 at that speed): its largest value on an axis is the row's Euclidean norm
    times F_u. To 1 %."""
    s, K, case, curves = judged
    speeds, current, names = curves["unbalance_current"]
    assert current.shape == (speeds.size, 4) and names[0].startswith("i_")
    tau = (testrig_cfg.controller.delay_samples + 0.5) / testrig_cfg.controller.sample_rate_hz
    for a in (0, 3):
        k = int(np.argmax(current[:, a]))
        P = build_plant(testrig_cfg, pressure_bar=0.0, speed_rpm=60.0 * speeds[k],
                        force_positions=tuple(s.force_positions_m)).to_statespace()
        cur = [j for j, n in enumerate(P.input_labels) if n.startswith("i_")]
        frc = [j for j in range(P.ninputs) if j not in cur]
        w = 2 * math.pi * speeds[k]
        H = ct.frequency_response(P, [w], squeeze=False).complex[:, :, 0]
        Kf = ct.frequency_response(K, [w], squeeze=False).complex[:, :, 0]
        # the controller's channels in the plant's order, by name
        Kw = Kf[[list(K.output_labels).index(P.input_labels[j]) for j in cur]][
            :, [list(K.input_labels).index(n) for n in P.output_labels]] * np.exp(-1j * w * tau)
        G, Gf = H[:, cur], H[:, frc] @ forward_forces([P.input_labels[j] for j in frc])
        T = Kw @ np.linalg.solve(np.eye(G.shape[0]) + G @ Kw, Gf)
        F = unbalance_force(s.unbalance_mass_kg, s.unbalance_grade_mm_s, [w],
                            max_speed_rad_s=2 * math.pi * s.unbalance_max_speed_hz,
                            law=s.unbalance_law)[0]
        assert P.input_labels[cur[a]] == names[a]
        assert current[k, a] == pytest.approx(np.linalg.norm(T[a]) * F, rel=1e-2)


def test_capacity_block_names_the_limit_and_where(testrig_cfg, judged):
    """Reference: the closed forms of the limits on the judged currents. The rig's
    ``current_limit`` (6 A, the bias) used as i_c/6 at the worst axis and speed; a supply
    voltage set to half of what the worst point needs (R = 0, L given: |jΩL|·|H_a|·i over
    the speeds, H_a the rig's second-order amplifier) is used 2× — reported above 1 with the
    speed and the axis where it happens; a rig without voltage or inductance gets None. The
    sizing per AMB is the largest current and ωL·i_c of its axes, and an amplifier of that
    size is used exactly to its limits."""
    _, _, case, curves = judged
    speeds, current, names = curves["unbalance_current"]
    entries = [("0 bar", speeds, current, names, None)]
    block = capacity_block(testrig_cfg, entries)
    wn, zeta = testrig_cfg.actuator.natural_frequency, testrig_cfg.actuator.damping_ratio
    sw = 2j * math.pi * speeds
    ha = np.abs(wn ** 2 / (sw ** 2 + 2 * zeta * wn * sw + wn ** 2))
    coil = ha[:, None] * current
    assert block["current_a"] == pytest.approx(coil.max(), rel=1e-9)
    assert block["current_used"] == pytest.approx(coil.max() / 6.0, rel=1e-9)
    assert block["voltage_used"] is None
    k, a = np.unravel_index(np.argmax(coil), coil.shape)
    for amb in testrig_cfg.amb:  # each bearing's margin: the largest of its own axes
        own = [j for j, n in enumerate(names) if n.startswith(f"i_{amb.name}_")]
        assert block["per_amb"][amb.name]["current_used"] == pytest.approx(
            coil[:, own].max() / 6.0, rel=1e-9)
    assert block["worst"]["current_used"] == {"condition": "0 bar",
                                              "speed_hz": pytest.approx(speeds[k]),
                                              "axis": names[a].removeprefix("i_"),
                                              "response": "unbalance"}
    L = 0.01
    need = 2 * math.pi * speeds[:, None] * L * coil
    v = float(need.max()) / 2
    ambs = [a.model_copy(update={"supply_voltage": v, "inductance": L})
            for a in testrig_cfg.amb]
    low = capacity_block(testrig_cfg.model_copy(update={"amb": ambs}), entries)
    assert low["voltage_used"] == pytest.approx(2.0, rel=1e-9)
    k, a = np.unravel_index(np.argmax(need), need.shape)
    assert low["worst"]["voltage_used"]["speed_hz"] == pytest.approx(speeds[k])
    assert low["worst"]["voltage_used"]["axis"] == names[a].removeprefix("i_")
    # sizing: per AMB the largest coil current of its axes and the largest ωL·i_c (R = 0);
    # an amplifier of exactly that size is used to 1 of its current and its voltage
    for amb in testrig_cfg.amb:
        own = [j for j, n in enumerate(names) if n.startswith(f"i_{amb.name}_")]
        assert low["sizing"][amb.name]["current_limit_a"] == \
            pytest.approx(coil[:, own].max(), rel=1e-12)
        assert low["sizing"][amb.name]["supply_voltage_v"] == \
            pytest.approx(need[:, own].max(), rel=1e-12)
    sized = [a.model_copy(update={"current_limit": low["sizing"][a.name]["current_limit_a"],
                                  "supply_voltage": low["sizing"][a.name]["supply_voltage_v"]})
             for a in ambs]
    fit = capacity_block(testrig_cfg.model_copy(update={"amb": sized}), entries)
    assert fit["current_used"] == pytest.approx(1.0, rel=1e-12)
    assert fit["voltage_used"] == pytest.approx(1.0, rel=1e-12)


def test_a_dash_for_the_voltage_says_why_and_only_where_there_is_one(testrig_cfg, judged):
    """Reference: the coil's inductance L = μ0 N² A/(2 s0) (Schweitzer & Maslen 2009, Eqs.
    3.27–3.30) and the voltage of the unbalance's current, |R + jΩL|·i_c + R i0. A rig
    that gives the coil — its inductance, its geometry, or both — is sized with that
    voltage, and the report's sizing text has no dash to explain; one that gives neither
    has no voltage, and the text says that for its AMBs; one whose only judged response is
    the impulse on an ideal current loop has none either, and says that instead."""
    from ambseal.analysis.amplifier import IDEAL_LOOP, NO_COIL
    from ambseal.model.amb import MU0
    from ambseal.report.run_report import _sizing_section

    _, _, case, curves = judged
    speeds, current, names = curves["unbalance_current"]
    entries = [("0 bar", speeds, current, names, None)]
    wn, zeta = testrig_cfg.actuator.natural_frequency, testrig_cfg.actuator.damping_ratio
    sw = 2j * math.pi * speeds
    coil = np.abs(wn ** 2 / (sw ** 2 + 2 * zeta * wn * sw + wn ** 2))[:, None] * current
    N, A, s0, R, i0 = 36, 5.5e-3, 5e-4, 0.3, 6.0
    L = MU0 * N ** 2 * A / (2 * s0)
    need = R * i0 + np.hypot(R, 2 * math.pi * speeds[:, None] * L) * coil

    def text(cfg):
        block = capacity_block(cfg, entries)
        sec = _sizing_section({"controllers": {"hinf": {"capacity": block}}, "failed": {}})
        return block["sizing"], sec[0]["text"]

    geometry = {"turns": N, "pole_area": A, "air_gap": s0, "resistance": R}
    for coil_keys in ({"inductance": L, "resistance": R}, geometry, {**geometry, "inductance": L}):
        ambs = [a.model_copy(update=coil_keys) for a in testrig_cfg.amb]
        sizing, words = text(testrig_cfg.model_copy(update={"amb": ambs}))
        for amb in testrig_cfg.amb:
            own = [j for j, n in enumerate(names) if n.startswith(f"i_{amb.name}_")]
            assert sizing[amb.name]["supply_voltage_v"] == pytest.approx(
                need[:, own].max(), rel=1e-9)
            assert "supply_voltage_note" not in sizing[amb.name]
        assert "dash" not in words and "inductance" not in words, words
    sizing, words = text(testrig_cfg)  # the embedded rig gives no coil
    assert {n: r["supply_voltage_v"] for n, r in sizing.items()} == {"A": None, "B": None}
    assert words.endswith(f" A dash for the voltage of AMB A, B: {NO_COIL}.")
    # an ideal current loop's impulse alone: the coil is known, its step has no voltage
    ideal = testrig_cfg.model_copy(update={
        "amb": [a.model_copy(update={"inductance": L}) for a in testrig_cfg.amb],
        "actuator": testrig_cfg.actuator.model_copy(update={"model": "none"})})
    block = capacity_block(ideal, [], [("0 bar", 0.0, curves["impulse"], None)])
    assert {r["supply_voltage_note"] for r in block["sizing"].values()} == {IDEAL_LOOP}


def test_a_notch_that_holds_leaves_the_amplifier_what_it_leaves(testrig_cfg, judged):
    """With an unbalance force rejection on from the middle of the judged speeds, the
    amplifier holds the unbalance with the current the notch leaves there and the
    controller's alone below it: the block is the closed form of the controller alone
    restricted to the speeds below the notch (its left current far below), and its words
    say the rejection is on and what the controller alone would take."""
    _, _, _, curves = judged
    speeds, current, names = curves["unbalance_current"]
    on = float(speeds[speeds.size // 2])
    entries = [("0 bar", speeds, current, names, None)]
    notched = list(notched_currents(entries, on, 1e-12))
    assert np.array_equal(notched[0][2][speeds < on], current[speeds < on])
    assert np.all(notched[0][2][speeds >= on] == 1e-12)
    assert np.array_equal(entries[0][2], current)  # the controller alone's are kept
    below = capacity_block(testrig_cfg, [("0 bar", speeds[speeds < on], current[speeds < on],
                                          names, None)])
    block = capacity_block(testrig_cfg, notched)
    alone = capacity_block(testrig_cfg, entries)
    assert block["current_used"] == pytest.approx(below["current_used"], rel=1e-12)
    assert block["current_used"] < alone["current_used"]
    assert block["worst"]["current_used"]["speed_hz"] < on
    block["without_rejection"] = {q: v for q, v in alone.items() if q.endswith("_used")}
    words = capacity_words(block)
    assert words.startswith("holding the unbalance (its unbalance force rejection on) it uses")
    assert words.endswith(f"; without its unbalance force rejection, holding the unbalance "
                          f"would take {alone['current_used']:.3g}× the current limit")
    # switched on by the run where the file leaves it off: the words say why
    block["rejection_automatic"] = True
    assert capacity_words(block).startswith(
        "holding the unbalance (its unbalance force rejection on, switched on by the run: "
        "the controller alone saturates the amplifier) it uses")


def test_the_fraction_used_speed_by_speed_is_the_closed_form_of_the_limits(testrig_cfg,
                                                                          judged):
    """Reference: the closed forms, as above, speed by speed: the coil current
    |H_a(jΩ)|·i over the rig's 6 A current limit and over its bias's linear range, the
    larger at each speed and over the axes; two conditions on speeds that partly coincide
    give the larger at each speed. Its largest value is the block's."""
    _, _, _, curves = judged
    speeds, current, names = curves["unbalance_current"]
    wn, zeta = testrig_cfg.actuator.natural_frequency, testrig_cfg.actuator.damping_ratio
    sw = 2j * math.pi * speeds
    coil = np.abs(wn ** 2 / (sw ** 2 + 2 * zeta * wn * sw + wn ** 2))[:, None] * current
    i0 = np.array([next(a.bias_current for a in testrig_cfg.amb
                        if n.startswith(f"i_{a.name}_")) for n in names])
    expected = np.maximum(coil / 6.0, coil / i0).max(axis=1)
    f, used = used_by_speed(testrig_cfg, [("0 bar", speeds, current, names, None)])
    np.testing.assert_array_equal(f, np.sort(speeds))
    np.testing.assert_allclose(used, expected[np.argsort(speeds)], rtol=1e-12)
    half = [("a", speeds, current, names, None), ("b", speeds[::2], 2 * current[::2], names, None)]
    f2, used2 = used_by_speed(testrig_cfg, half)
    np.testing.assert_allclose(used2[::2], 2 * expected[::2], rtol=1e-12)
    np.testing.assert_allclose(used2[1::2], expected[1::2], rtol=1e-12)
    block = capacity_block(testrig_cfg, [("0 bar", speeds, current, names, None)])
    assert used.max() == pytest.approx(max(block["current_used"], block["bias_used"]),
                                       rel=1e-12)


def test_the_notch_switches_on_below_the_continuous_speeds_only_through_a_saturation():
    """switch_on_hz: a controller alone that saturates its amplifier at a critical below
    the continuous speeds (1.34× at 106 Hz, as the supercritical example) gets its notch on
    from the highest speed below the critical where it uses at most half of it; one that
    saturates only within the continuous speeds, or nowhere, at the minimum continuous
    speed; one that is never that quiet below the critical, from the lowest turning
    speed."""
    f = np.linspace(0.0, 180.0, 181)
    critical = 0.06 + 1.28 / (1.0 + ((f - 106.0) / 2.0) ** 2)  # a resonance peaking at 1.34
    on = switch_on_hz(f, critical, 120.0)
    assert critical[f == on][0] <= SWITCH_ON_FRACTION < critical[f == on + 1][0]
    assert 100.0 < on < 106.0
    assert switch_on_hz(f, np.where(f > 130.0, 1.2, 0.3), 120.0) == 120.0
    assert switch_on_hz(f, np.full(f.size, 0.9), 120.0) == 120.0
    loud = np.where(f > 0, 0.8 + 0.6 * (f > 90.0), 0.0)
    assert switch_on_hz(f, loud, 120.0) == 1.0


def test_a_notch_that_cannot_run_from_its_start_switches_on_where_it_is_needed():
    """later_switch_on_hz: the synchronous current of a rigid support grows as Ω² (the
    unbalance force m·e·Ω²), u = 1.14·(f/574)² as the generated rotor whose notch lost its
    loop at the bottom of its 191–574 Hz range: on again from the highest speed where
    u ≤ ½, 574·√(0.5/1.14) = 380.1 Hz, below the first saturated one, 574/√1.14 = 537.6 Hz;
    none where no speed above the first start is that quiet, or where the controller
    alone saturates nowhere above it."""
    f = np.arange(0.0, 575.0)
    u = 1.14 * (f / 574.0) ** 2
    assert later_switch_on_hz(f, u, 191.0) == 380.0
    assert u[f == 380.0][0] <= SWITCH_ON_FRACTION < u[f == 381.0][0]
    assert later_switch_on_hz(f, u, 400.0) is None
    assert later_switch_on_hz(f, 0.9 * u / u.max(), 191.0) is None
    assert later_switch_on_hz(f, u, 0.0) == switch_on_hz(f, u, 600.0) == 380.0


def test_impulse_voltage_is_the_coil_driven_through_the_amplifier(testrig_cfg, judged):
    """Reference: python-control's zero-order-hold discretisation of the rig's amplifier
    H_a (second order) and of s·H_a, driven by the judged impulse response's current
    reference (−K y plus the injected impulse) held over each step, give the coil current
    and its rate; the coils need R i0 + |R i + L di/dt|. A supply voltage of half the
    largest need is used 2× in the impulse, named with its axis and "in the current
    impulse"; the current limit is used as max |i| / limit."""
    _, _, case, curves = judged
    imp = curves["impulse"]
    wn, zeta = testrig_cfg.actuator.natural_frequency, testrig_cfg.actuator.damping_ratio
    den = [1.0, 2 * zeta * wn, wn ** 2]
    ref = imp.current_a + imp.disturbance_a
    t = np.arange(ref.shape[0]) * imp.dt_s
    i, di = (np.array([ct.forced_response(ct.c2d(ct.tf(num, den), imp.dt_s, "zoh"), t,
                                          ref[:, j]).outputs for j in range(ref.shape[1])])
             for num in ([wn ** 2], [wn ** 2, 0.0]))
    R, L, i0 = 0.2, 0.05, testrig_cfg.amb[0].bias_current
    need = R * i0 + np.abs(R * i + L * di)  # (axes, time)
    v = float(need.max()) / 2
    ambs = [a.model_copy(update={"supply_voltage": v, "inductance": L, "resistance": R})
            for a in testrig_cfg.amb]
    block = capacity_block(testrig_cfg.model_copy(update={"amb": ambs}), [],
                           [("0 bar", 0.0, imp, None)])
    assert block["voltage_used"] == pytest.approx(2.0, rel=1e-6)
    a = int(np.unravel_index(np.argmax(need), need.shape)[0])
    assert block["worst"]["voltage_used"] == {"condition": "0 bar", "speed_hz": 0.0,
                                              "axis": imp.input_names[a].removeprefix("i_"),
                                              "response": "impulse"}
    assert block["current_used"] == pytest.approx(np.abs(i).max() / 6.0, rel=1e-6)
    assert capacity_words(block).startswith("the amplifier saturates in the current "
                                            "impulse: it needs 2× the supply voltage")
    for amb in testrig_cfg.amb:
        own = [j for j, n in enumerate(imp.input_names) if n.startswith(f"i_{amb.name}_")]
        assert block["sizing"][amb.name]["supply_voltage_v"] == \
            pytest.approx(need[own].max(), rel=1e-6)


def test_force_demand_is_ki_times_the_coil_current(testrig_cfg, judged):
    """Reference: the closed form Ki·|H_a(jΩ)|·i_ref per axis (H_a the rig's second-order
    amplifier, Ki each AMB's from the geometry), the largest of the AMB's axes; a second
    condition asking twice the current on a coarser grid of speeds raises the envelope to
    twice the first, interpolated linearly on the union of the grids."""
    _, _, case, curves = judged
    speeds, current, names = curves["unbalance_current"]
    wn, zeta = testrig_cfg.actuator.natural_frequency, testrig_cfg.actuator.damping_ratio
    sw = 2j * math.pi * speeds
    ha = np.abs(wn ** 2 / (sw ** 2 + 2 * zeta * wn * sw + wn ** 2))
    one = force_demand(testrig_cfg, [("0 bar", speeds, current, names)])
    assert set(one) == {a.name for a in testrig_cfg.amb}
    for amb in testrig_cfg.amb:
        ki = amb_factors(amb)[0]
        own = [(j, ki[("zeta", "eta").index(n.rsplit("_", 1)[1])])
               for j, n in enumerate(names) if n.startswith(f"i_{amb.name}_")]
        ref = np.max([k * ha * current[:, j] for j, k in own], axis=0)
        f, force = one[amb.name]
        np.testing.assert_allclose(f, speeds)
        np.testing.assert_allclose(force, ref, rtol=1e-12)
    coarse = speeds[::7]
    two = force_demand(testrig_cfg, [("0 bar", speeds, current, names),
                                     ("hi", coarse, 2 * current[::7], names)])
    f, force = two[testrig_cfg.amb[0].name]
    np.testing.assert_allclose(f, np.union1d(speeds, coarse))
    np.testing.assert_allclose(force[np.isin(f, coarse)],
                               2 * one[testrig_cfg.amb[0].name][1][::7], rtol=1e-12)


def test_static_current_holds_the_seal_offset_at_every_direction(testrig_cfg, testrig_designs):
    """Reference: python-control's interconnection of the embedded rig's full-order plant
    (a force input at the seal), its delay lag and its PID, the closed loop's static gain
    from the seal force to the current references by a dense solve at s = 0 (the PID
    integrates: its gain is infinite there, the loop's is not); the seal's force
    −[K k; −k K] e at 2.04 bar for an offset e = 50 µm turned through 3600 directions:
    the largest current of each axis is the judgement's static current to 1e-6. And the
    amplifier carries it: the capacity block with it uses (|i_s| + i_c)/i0 of the bias."""
    import control as ct

    from ambseal.analysis.judge import seal_static_load
    from ambseal.robust import loop_delay

    from ..freq_at import at

    seal = testrig_cfg.seal[0]
    cfg = testrig_cfg.model_copy(update={"seal": [seal.model_copy(
        update={"static_eccentricity": 5e-5})]})
    s = judge_settings(design_spec(cfg))
    K = testrig_designs["pid"].K
    p = 2.04
    _, curves = judge(cfg, K, "pid", OperatingPoint(p, 0.0, "2.04 bar"), s, impulse=False)
    i_s, names = curves["static_current"]
    pl = build_plant(cfg, pressure_bar=p, force_positions=(seal.position,))
    P = pl.to_statespace()
    cur = list(pl.current_inputs())
    G = ct.ss(P.A, P.B, P.C, P.D, inputs=list(P.input_labels),
              outputs=list(P.output_labels), name="G")
    lag = loop_delay(cfg.controller.sample_rate_hz, cfg.controller.delay_samples).system
    blocks, conn = [G, ct.ss(K, name="K")], []
    for n in K.output_labels:
        blocks.append(ct.ss(lag.A, lag.B, lag.C, lag.D, inputs=["u"], outputs=["v"],
                            name=f"lag_{n}"))
        conn += [[f"lag_{n}.u", f"-K.{n}"], [f"G.{n}", f"lag_{n}.v"]]
    conn += [[f"K.{n}", f"G.{n}"] for n in K.input_labels]
    frc = [n for j, n in enumerate(P.input_labels) if j not in cur]
    loop = ct.interconnect(blocks, connections=conn, inplist=[f"G.{n}" for n in frc],
                           inputs=frc, outlist=[f"K.{n}" for n in K.output_labels],
                           outputs=list(K.output_labels))
    M = -at(loop, 0.0).real  # current references i = −K y per unit seal force (x, y)
    F, e = seal_static_load(cfg.seal[0], p)
    theta = np.linspace(0, 2 * math.pi, 3600, endpoint=False)
    currents = M @ F @ (e * np.vstack([np.cos(theta), np.sin(theta)]))
    worst = np.abs(currents).max(axis=1)
    order = [list(K.output_labels).index(n) for n in names]
    np.testing.assert_allclose(i_s, worst[order], rtol=1e-6)
    assert i_s.max() > 0
    speeds, current, unames = curves["unbalance_current"]
    block = capacity_block(cfg, [("2.04 bar", speeds, current, unames,
                                  dict(zip(names, i_s)))])
    wn, zeta = cfg.actuator.natural_frequency, cfg.actuator.damping_ratio
    sw = 2j * math.pi * speeds
    ha = np.abs(wn ** 2 / (sw ** 2 + 2 * zeta * wn * sw + wn ** 2))
    ref = max((i_s[names.index(n)] + ha * current[:, a]).max() for a, n in enumerate(unames))
    assert block["bias_used"] == pytest.approx(ref / cfg.amb[0].bias_current, rel=1e-9)
    assert block["static_a"] == pytest.approx(i_s.max())
    assert "and the seals' static load" in capacity_words(block)


def test_the_axis_named_of_a_tie_is_the_first_in_the_rigs_channel_order(testrig_cfg):
    """Reference: the rig's limits in closed form (the coil current through the
    second-order amplifier, over the 6 A current limit). The two axes of a symmetric
    bearing need one current by symmetry; whether the tie is exact or rounding (1e-12 or
    2e-8 relative, as another machine's BLAS kernels give it through the synthesis) makes
    η's larger, the axis named is the first in the rig's channel order, A ζ; a real
    difference (1e-4) names the larger."""
    speeds = np.linspace(20.0, 200.0, 37)
    names = ["i_A_zeta", "i_A_eta", "i_B_zeta", "i_B_eta"]
    shape = 0.5 + 0.3 * np.sin(speeds / 40.0)

    def named(eta_factor):
        current = np.column_stack([shape, shape * eta_factor, 0.5 * shape, 0.5 * shape])
        block = capacity_block(testrig_cfg, [("0 bar", speeds, current, names, None)])
        return block["worst"]["current_used"]["axis"], block["current_used"]

    wn, zeta = testrig_cfg.actuator.natural_frequency, testrig_cfg.actuator.damping_ratio
    sw = 2j * math.pi * speeds
    coil = np.abs(wn ** 2 / (sw ** 2 + 2 * zeta * wn * sw + wn ** 2)) * shape
    exact, used = named(1.0)
    assert used == pytest.approx(coil.max() / 6.0, rel=1e-9)
    assert exact == "A_zeta"
    assert named(1 + 1e-12)[0] == "A_zeta"
    assert named(1 + 2e-8)[0] == "A_zeta"
    assert named(1 + 1e-4)[0] == "A_eta"
