"""One verdict: the main job, export, sweep and campbell judge a borderline loop alike.

Every command that says "stable" takes it of the same loop (the controller as it runs,
:func:`ambseal.machine.loop.judged_loop`) by the same rule
(:func:`ambseal.robust.stability.is_stable`). Reference: the stability boundary of the
test rig's reference PID between nominal and twice nominal pressure drop (thesis P5 §4:
stable at 2.04 bar, unstable at 4.08 bar), bisected to 1e-4 bar; just below it every
command must say stable, just above it every command unstable.
"""

import numpy as np

from ambseal.analysis.campbell import closed_loop_modes
from ambseal.analysis.judge import OperatingPoint, judge, judge_settings
from ambseal.analysis.sweep import boundary_case, sweep_case
from ambseal.design.recipes import full_order_check
from ambseal.design.specs import design_spec
from ambseal.model.modes import bending_limit_hz


def test_commands_agree_on_either_side_of_the_stability_boundary(testrig_cfg,
                                                                 testrig_designs):
    cfg, K = testrig_cfg, testrig_designs["pid"].K
    f = cfg.operating.speed_rpm / 60.0
    p0 = cfg.operating.pressure_bar
    rig = cfg.model_dump(exclude_none=True)
    ctrls = {"pid": tuple(np.asarray(M, float) for M in (K.A, K.B, K.C, K.D))}
    edge = boundary_case({"controller": "pid", "speed_hz": f, "params": None,
                          "last_stable_bar": p0, "first_unstable_bar": 2 * p0},
                         rig, ctrls, tol_bar=1e-4)
    assert p0 < edge < 2 * p0
    settings = judge_settings(design_spec(cfg))
    for p, stable in ((edge - 1e-3, True), (edge + 1e-3, False)):
        verdicts = {
            "run": judge(cfg, K, "pid", OperatingPoint(p, 60.0 * f, ""), settings,
                         impulse=False)[0].stable,
            "export": full_order_check(cfg, K, [(p, f)])["stable"],
            "sweep": sweep_case({"controller": "pid", "pressure_bar": p, "speed_hz": f},
                                rig, ctrls, bending_limit_hz(cfg), settings)["stable"],
            "campbell": closed_loop_modes(cfg, K, speed_hz=f, pressure_bar=p).stable,
        }
        assert verdicts == dict.fromkeys(verdicts, stable), (p, verdicts)


def test_modes_and_campbell_report_the_log_decrements_of_the_judged_loop(testrig_cfg,
                                                                         testrig_designs):
    """Reference: python-control's poles of the loop every command judges — the full-order
    plant behind the target's hold and computation delay, python-control's own order-4
    Padé lag of (delay + ½) samples on each current (``control.pade``), closed with the
    reference PID. Each mode ``modes``/``campbell`` report at the nominal pressure drop
    is one of those poles (1e-6), its log decrement theirs: the delay is not left out (it
    moves the least damped mode's log decrement measurably: here from 0.008 to 0.013)."""
    import control

    from ambseal.model.rig import build_plant

    cfg, K = testrig_cfg, testrig_designs["pid"].K
    p, f = cfg.operating.pressure_bar, cfg.operating.speed_rpm / 60.0
    fs, nd = cfg.controller.sample_rate_hz, cfg.controller.delay_samples
    L = control.append(*[control.ss(control.tf(*control.pade((nd + 0.5) / fs, 4)))] * 4)
    plant = build_plant(cfg, pressure_bar=p)
    G = plant.select_inputs(plant.input_names[:4]).to_statespace()
    ref = control.feedback(control.series(L, G), K, sign=-1).poles()
    m = closed_loop_modes(cfg, K, speed_hz=f, pressure_bar=p)
    assert m.poles.size >= 4
    for z in m.poles:
        assert np.min(np.abs(ref - z)) <= 1e-6 * abs(z), z
    undelayed = control.feedback(G, K, sign=-1).poles()
    near = undelayed[np.argmin(np.abs(undelayed - m.poles[np.argmin(m.log_decrement)]))]
    assert abs(-2 * np.pi * near.real / abs(near.imag) - np.min(m.log_decrement)) > 1e-3
