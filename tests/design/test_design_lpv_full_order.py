"""The speed-scheduled designs (LPV, frozen H∞) closed with the full-order plant at every
judged condition before they are delivered, as H∞ and μ are."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from ambseal.design.lpv_design import check_full_order
from ambseal.design.specs import design_spec
from ambseal.errors import SynthesisError
from ambseal.model.rig import build_plant


def _max_real_pole(cfg, K, p_bar: float, f_hz: float) -> float:
    """python-control's closed loop (negative feedback i = −K y) of the full-order plant."""
    import control

    pl = build_plant(cfg, pressure_bar=p_bar, speed_rpm=60.0 * f_hz)
    G = pl.select_inputs([pl.input_names[j] for j in pl.current_inputs()]).to_statespace()
    return float(control.feedback(G, K).poles().real.max())


def test_lpv_and_frozen_designs_carry_their_full_order_check(turbo_cfg, turbo_lpv,
                                                             turbo_frozen):
    """Reference: python-control's feedback poles at each judged speed (20, 140, 300 Hz
    at the nominal pressure) and wherever the machine runs, standstill to the top speed:
    the LPV controller frozen at that speed, and the 140 Hz H∞ controller, both stable;
    their ``full_order`` blocks say stable and name the least damped mode of those loops."""
    sp = design_spec(turbo_cfg)
    conds = [(p, f) for p in sp.pressures_bar
             for f in sorted({*sp.speeds_hz, *sp.stability_speeds_hz})]
    assert {f for _, f in conds} >= {0.0, 20.0, 140.0, 300.0}
    frozen_at = lambda f: turbo_frozen.K  # noqa: E731 — one controller at every speed
    for d, K_at in ((turbo_lpv, turbo_lpv.controller_at), (turbo_frozen, frozen_at)):
        assert d.full_order["stable"] and d.to_dict()["full_order"] == d.full_order
        assert all(_max_real_pole(turbo_cfg, K_at(f), p, f) < 0 for p, f in conds)
        assert (d.full_order["pressure_bar"], d.full_order["speed_hz"]) in conds


def test_an_unstable_scheduled_loop_is_refused_with_its_mode(turbo_cfg, turbo_frozen):
    """Reference: python-control's feedback poles — the frozen controller with its sign
    flipped (positive feedback) is unstable at every speed; the check refuses it naming
    the condition, the mode's frequency and damping, and keeps it on request."""
    import control

    flipped = -1.0 * turbo_frozen.K
    f = 140.0
    assert _max_real_pole(turbo_cfg, flipped, turbo_cfg.operating.pressure_bar, f) > 0
    with pytest.raises(SynthesisError, match=r"unstable at .* bar, .* Hz: the mode at .* "
                                             r"Hz has ζ = -"):
        check_full_order(turbo_cfg, design_spec(turbo_cfg), lambda _: flipped, "flipped")
    kept = check_full_order(turbo_cfg, design_spec(turbo_cfg), lambda _: flipped, "flipped",
                            allow_unstable=True)
    assert not kept["stable"] and kept["damping"] < 0
    assert np.isfinite(kept["mode_hz"]) and isinstance(flipped, control.StateSpace)


@pytest.mark.heavy
def test_the_lpv_on_speed_holds_the_blower_from_standstill_to_its_top_speed():
    """Reference: python-control's feedback poles of the full-order plant at every judged
    pressure and stability speed of ``examples/blower.toml`` (0–600 Hz, where the
    gyroscopic moments split the first bending mode at ~930 Hz): the LPV controller
    scheduled on speed over standstill to 600 Hz holds the rotor at every condition — as
    the main job delivers it where a frozen design loses it. ``design_lpv``'s defaults are
    that job's schedule (:func:`~ambseal.design.lpv_design.lpv_schedule`), not the
    rig's ``speed_range_hz`` of 100–600 Hz on the rigid-body modes alone."""
    from ambseal.config import load_rig
    from ambseal.design.lpv_design import design_lpv

    cfg = load_rig(Path(__file__).resolve().parents[2] / "examples" / "blower.toml")
    sp = design_spec(cfg)
    conds = [(p, f) for p in sp.pressures_bar for f in sp.stability_speeds_hz]
    lpv = design_lpv(cfg, allow_unstable=True, spec=sp)
    assert (lpv.speeds_hz[0], lpv.speeds_hz[-1]) == (0.0, 600.0)
    mechanical = [n for n in lpv.plant.state_names if not n.startswith("act_")]
    assert len(mechanical) == sp.model_states == 24  # the actuators' states besides
    assert lpv.full_order["stable"]
    assert all(_max_real_pole(cfg, lpv.controller_at(f), p, f) < 0 for p, f in conds)


def test_a_check_for_a_correction_stops_at_the_farthest_speed_that_loses_a_mode(
        turbo_cfg, turbo_frozen):
    """Reference: python-control's feedback poles. The frozen controller with its sign
    flipped loses the loop everywhere: ``first_loss`` checks the speed farthest from the
    design speed (300 Hz from 140 Hz, not standstill) at every pressure and stops there,
    with the same lost modes there as the whole check; the stable controller is checked
    at every condition either way, with the same result."""
    from ambseal.design.recipes import full_order_check

    sp = design_spec(turbo_cfg)
    conds = [(p, f) for p in sp.pressures_bar
             for f in sorted({*sp.speeds_hz, *sp.stability_speeds_hz})]
    flipped = -1.0 * turbo_frozen.K
    whole = full_order_check(turbo_cfg, flipped, conds)
    first = full_order_check(turbo_cfg, flipped, conds, first_loss=True)
    assert whole["checked"] == len(conds) and first["checked"] == len(sp.pressures_bar)
    assert not first["stable"] and first["speed_hz"] == 300.0
    assert all(_max_real_pole(turbo_cfg, flipped, p, 300.0) > 0 for p in sp.pressures_bar)
    assert first["unstable"] == [c for c in whole["unstable"] if c["speed_hz"] == 300.0]
    held = full_order_check(turbo_cfg, turbo_frozen.K, conds, first_loss=True)
    assert held == full_order_check(turbo_cfg, turbo_frozen.K, conds)
    assert held["stable"] and held["checked"] == len(conds)
