"""The unbalance force rejection (design/synchronous_rejection.py) on the turboexpander's
full-order plant, judged by python-control: its own sampling of the plant (c2d, ZOH), its
own interconnection of the loop and its poles; responses by dense solves
(:mod:`tests.freq_at`)."""

import math

import control as ct
import numpy as np
import pytest

from ambseal.design.synchronous_rejection import design_rejection
from ambseal.errors import ConfigError
from ambseal.model import build_plant
from ambseal.robust import loop_delay

from ..freq_at import at


@pytest.fixture
def rejection(turbo_rejection):
    return turbo_rejection


def _loop(P, K, cur, delay=None):
    """python-control's loop: K on P's current inputs (``i = −K y``, by name), the other
    inputs (forces at the bearings, N) external, the currents out; ``delay`` a SISO lag in
    front of each current input."""
    G = ct.ss(P.A, P.B, P.C, P.D, P.dt, inputs=list(P.input_labels),
              outputs=list(P.output_labels), name="G")
    Kc = ct.ss(K.A, K.B, K.C, K.D, K.dt, inputs=list(K.input_labels),
               outputs=list(K.output_labels), name="K")
    frc = [n for j, n in enumerate(P.input_labels) if j not in cur]
    blocks, conn = [G, Kc], []
    for n in Kc.output_labels:
        if delay is None:
            conn.append([f"G.{n}", f"-K.{n}"])
        else:
            lag = ct.ss(delay.A, delay.B, delay.C, delay.D, inputs=["u"], outputs=["v"],
                        name=f"lag_{n}")
            blocks.append(lag)
            conn += [[f"lag_{n}.u", f"-K.{n}"], [f"G.{n}", f"lag_{n}.v"]]
    conn += [[f"K.{n}", f"G.{n}"] for n in Kc.input_labels]
    return ct.interconnect(blocks, connections=conn, inplist=[f"G.{n}" for n in frc],
                           inputs=frc, outlist=[f"K.{n}" for n in Kc.output_labels],
                           outputs=list(Kc.output_labels))


def test_rejection_takes_the_synchronous_current_out_at_every_speed(
        turbo_cfg, turbo_frozen, turbo_hinf_digital, rejection):
    """At constant speeds over the range — table speeds and between them — the loop as it
    runs (the plant sampled by python-control's ZOH, the discrete controller with its
    delay and notch) and the continuous loop (the judgement's delay lag) are stable, their
    current at the rotational frequency from forces at the bearings is below 1 % of the
    feedback-only loop's."""
    cfg = turbo_cfg
    fs = cfg.controller.sample_rate_hz
    lag = loop_delay(fs, cfg.controller.delay_samples).system
    table = rejection.speeds_hz
    k = table.size // 2
    for f in (table[0], 0.5 * (table[k - 1] + table[k]), table[-1]):
        w = 2 * math.pi * f
        pl = build_plant(cfg, pressure_bar=cfg.operating.pressure_bar, speed_rpm=60 * f,
                         force_positions=tuple(a.position for a in cfg.amb))
        P, cur = pl.to_statespace(), pl.current_inputs()
        Pd = ct.c2d(ct.ss(P.A, P.B, P.C, P.D), 1 / fs, "zoh")
        Pd = ct.ss(Pd.A, Pd.B, Pd.C, Pd.D, 1 / fs, inputs=list(P.input_labels),
                   outputs=list(P.output_labels))
        z = np.exp(1j * w / fs)
        runs = {k: _loop(Pd, K, cur) for k, K in (
            ("off", turbo_hinf_digital.statespace(delayed=True)),
            ("on", rejection.digital.statespace_at(w, delayed=True)))}
        assert np.abs(runs["on"].poles()).max() < 1
        assert np.abs(at(runs["on"], z)).max() < 1e-2 * np.abs(at(runs["off"], z)).max()
        cont = {k: _loop(P, K, cur, lag) for k, K in (
            ("off", turbo_frozen.K), ("on", rejection.controller.at(w)))}
        assert cont["on"].poles().real.max() < 0
        assert np.abs(at(cont["on"], 1j * w)).max() < 1e-2 * np.abs(
            at(cont["off"], 1j * w)).max()


def test_notch_poles_sit_where_the_inverse_sensitivity_puts_them(turbo_cfg, turbo_frozen,
                                                                turbo_hinf_digital):
    """Herzog et al.'s first-order placement: with T = S_o⁻¹ the notch's poles lie at
    e^{jΩT_s}(1 − εT_s/2), one per channel, whatever the plant — exact as ε → 0: at
    ε = 0.005 Ω within 1 % of their distance from the unit circle (python-control's poles
    of the sampled loop at a table speed and at the range's ends)."""
    cfg = turbo_cfg
    fs = cfg.controller.sample_rate_hz
    narrow = design_rejection(cfg, turbo_frozen.K, turbo_hinf_digital,
                              rate_fraction=0.005)
    for f in narrow.speeds_hz[[0, narrow.speeds_hz.size // 2, -1]]:
        w = 2 * math.pi * f
        pl = build_plant(cfg, pressure_bar=cfg.operating.pressure_bar, speed_rpm=60 * f)
        P, cur = pl.to_statespace(), pl.current_inputs()
        Pd = ct.c2d(ct.ss(P.A, P.B, P.C, P.D), 1 / fs, "zoh")
        Pd = ct.ss(Pd.A, Pd.B, Pd.C, Pd.D, 1 / fs, inputs=list(P.input_labels),
                   outputs=list(P.output_labels))
        A = _loop(Pd, narrow.digital.statespace_at(w, delayed=True), cur).A
        shift = 0.5 * 0.005 * w / fs
        predicted = np.exp(1j * w / fs) * (1 - shift)
        near = np.sort(np.abs(np.linalg.eigvals(A) - predicted))[:4]  # one per channel
        assert near.max() < 0.01 * shift


def test_rejection_is_off_below_the_speed_range_and_needs_a_turning_rotor(
        turbo_cfg, turbo_frozen, testrig_cfg, testrig_designs, rejection):
    """Below the minimum continuous speed the controller runs without the notch; a rig at
    standstill has nothing to reject: refused with the keys that would give it a speed."""
    lo = turbo_cfg.operating.continuous_hz[0]
    assert rejection.to_dict()["on_from_hz"] == pytest.approx(lo)
    K = rejection.controller.at(2 * math.pi * 0.9 * lo)
    assert K.nstates == turbo_frozen.K.nstates
    assert rejection.controller.at(2 * math.pi * lo).nstates == turbo_frozen.K.nstates + 8
    with pytest.raises(ConfigError, match="speed_range_hz"):
        design_rejection(testrig_cfg, testrig_designs["hinf"].K)


def test_a_second_table_on_the_same_speeds_builds_no_plant(turbo_cfg, turbo_frozen,
                                                           turbo_hinf_digital, monkeypatch):
    """The plant at a table's speed does not depend on the controller: a second table at
    the same speeds and pressure drop (another run's controller, another rate) builds and
    evaluates no plant, and its gains are those of a table made from fresh plants, to the
    bit."""
    import ambseal.design.synchronous_rejection as sr

    design_rejection(turbo_cfg, turbo_frozen.K, turbo_hinf_digital, rate_fraction=0.01)
    built, real = [], sr.build_plant
    monkeypatch.setattr(sr, "build_plant", lambda *a, **k: built.append(k) or real(*a, **k))
    again = design_rejection(turbo_cfg, turbo_frozen.K, turbo_hinf_digital,
                             rate_fraction=0.02)
    assert built == []
    monkeypatch.setattr(sr, "_PLANT_AT", sr.ArrayMemo(keep=256))
    fresh = design_rejection(turbo_cfg, turbo_frozen.K, turbo_hinf_digital,
                             rate_fraction=0.02)
    assert len(built) == again.speeds_hz.size
    for a, b in ((again.controller.notch, fresh.controller.notch),
                 (again.digital.notch, fresh.digital.notch)):
        assert np.array_equal(a.gain_re, b.gain_re) and np.array_equal(a.gain_im, b.gain_im)
        assert a.gain_re.shape[0] == again.speeds_hz.size


def test_tables_that_start_at_other_speeds_share_the_plants_above(turbo_cfg, turbo_frozen,
                                                                 turbo_hinf_digital,
                                                                 monkeypatch):
    """Each controller's table starts at its own switch-on speed (the amplifier's, below
    the continuous range) and splits at the dyadic speeds f_top·k/2^j of the range's top,
    so a second table from a start 1.25 % higher samples the plant at its start alone and
    takes every other speed, and its plant, from the first table. Reference: the rule
    itself — every inner speed of the first table is such a speed."""
    import ambseal.design.synchronous_rejection as sr

    lo, hi = turbo_cfg.operating.continuous_hz
    first = design_rejection(turbo_cfg, turbo_frozen.K, turbo_hinf_digital,
                             speeds_hz=(0.8 * lo, hi))
    built, real = [], sr.build_plant
    monkeypatch.setattr(sr, "build_plant", lambda *a, **k: built.append(k) or real(*a, **k))
    second = design_rejection(turbo_cfg, turbo_frozen.K, turbo_hinf_digital,
                              speeds_hz=(0.81 * lo, hi))
    assert [k["speed_rpm"] / 60.0 for k in built] == [pytest.approx(0.81 * lo)]
    assert set(second.speeds_hz[1:].tolist()) <= set(first.speeds_hz.tolist())
    for f in first.speeds_hz[1:-1]:
        assert any(abs(f / hi * 2**j - round(f / hi * 2**j)) < 1e-9 for j in range(30))


def test_a_split_is_the_coarsest_dyadic_speed_inside_also_from_a_dyadic_end():
    """:func:`dyadic_split` against the rule by enumeration: of the speeds
    ``ldexp(top·k, −j)`` (k = 1 … 2^j − 1, the tables' own rounding of top·k/2^j) strictly
    inside (a, b), the one of the smallest j — one speed there, never two. Seeded tops,
    and intervals whose lower end is itself such a speed, as an earlier split made it:
    there ``a/top`` can round below k/2^j (about 4 % of these draws), which must not make
    the lower end its own split, nor loop on it."""
    from ambseal.design.synchronous_rejection import dyadic_split

    rng = np.random.default_rng(7)
    for _ in range(500):
        top = float(rng.uniform(50.0, 2000.0))
        j0 = int(rng.integers(1, 8))
        a = math.ldexp(top * int(rng.integers(1, 2**j0)), -j0)
        b = a + float(rng.uniform(0.02, 1.0)) * (top - a)
        inside, j = [], 0
        while not inside:
            inside = [s for s in (math.ldexp(top * k, -j) for k in range(1, 2**j)) if a < s < b]
            j += 1
        assert len(inside) == 1 and dyadic_split(a, b, top) == inside[0]


def test_the_table_interpolates_the_gain_between_its_speeds(turbo_cfg, turbo_frozen,
                                                            turbo_hinf_digital, rejection):
    """Midway between every two neighbouring speeds of the table (speeds it never
    evaluated), its interpolated gain T̃ holds the notch's poles to their placement:
    ‖(T̃ − T) T⁻¹‖₂ ≤ INTERP_RTOL against T = I + G K made by python-control, continuous
    (the plant with the judgement's delay lag, the frozen H∞) and as it runs (the plant
    sampled by its ZOH, the discrete controller with its delay). The turboexpander's gain
    swings most at its lowest speeds (20–60 Hz of 20–300 Hz); 16 evenly spaced speeds
    miss it there by 0.3, the bisection puts its speeds where it swings."""
    from ambseal.design.synchronous_rejection import INTERP_RTOL

    cfg = turbo_cfg
    fs = cfg.controller.sample_rate_hz
    lag = loop_delay(fs, cfg.controller.delay_samples).system
    Kd = turbo_hinf_digital.statespace(delayed=True)
    table, worst = rejection.speeds_hz, 0.0
    assert table[0] == cfg.operating.continuous_hz[0] and table[-1] == \
        cfg.operating.continuous_hz[1]
    for f in 0.5 * (table[1:] + table[:-1]):
        w = 2 * math.pi * f
        pl = build_plant(cfg, pressure_bar=cfg.operating.pressure_bar, speed_rpm=60 * f)
        P, cur = pl.to_statespace(), pl.current_inputs()
        Pd = ct.c2d(ct.ss(P.A, P.B, P.C, P.D), 1 / fs, "zoh")
        for notch, K, G, x, delay in (
                (rejection.controller.notch, turbo_frozen.K, ct.ss(P.A, P.B, P.C, P.D),
                 1j * w, at(ct.ss(lag.A, lag.B, lag.C, lag.D), 1j * w)[0, 0]),
                (rejection.digital.notch, Kd, Pd, np.exp(1j * w / fs), 1.0)):
            rows = [list(P.output_labels).index(n) for n in K.input_labels]
            cols = [list(P.input_labels).index(n) for n in K.output_labels]
            T = np.eye(len(rows)) + at(G, x)[np.ix_(rows, cols)] * delay @ at(K, x)
            E = np.linalg.solve(T.T, (notch.gain_at(w) - T).T).T
            worst = max(worst, np.linalg.norm(E, 2))
    assert worst <= INTERP_RTOL
