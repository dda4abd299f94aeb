"""The speeds an LPV controller is scheduled over: one rule for ``ambseal run`` and
``ambseal design --method lpv`` (ambseal.design.lpv_design.lpv_schedule).

Reference: the rule as written — a rig whose seals follow the speed over its stated
range (the thesis's turboexpander, P3 §4: 20–300 Hz) on the rigid-body design model; any
other from standstill to its top speed (the largest stability speed) on its design model's
states; a rig at standstill has nothing to schedule on."""

from __future__ import annotations

from pathlib import Path

import pytest

from ambseal.app import commands
from ambseal.config import load_rig
from ambseal.design import design_spec, lpv_schedule
from ambseal.errors import ConfigError

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"


def test_the_schedule_follows_the_rule():
    turbo = load_rig(EXAMPLES / "turboexpander.toml")
    assert lpv_schedule(turbo, design_spec(turbo))[:2] == ((20.0, 300.0), 8)
    oh = load_rig(EXAMPLES / "overhung_compressor.toml")
    spec = design_spec(oh)
    speeds, states, rule = lpv_schedule(oh, spec)
    assert speeds == (0.0, max(spec.stability_speeds_hz)) == (0.0, 305.0)
    assert states == spec.model_states and "standstill" in rule
    rig = load_rig(EXAMPLES / "testrig.toml")
    with pytest.raises(ConfigError, match="standstill"):
        lpv_schedule(rig, design_spec(rig))


def test_design_lpv_designs_what_run_designs(monkeypatch, tmp_path):
    """``ambseal design --method lpv`` on a rig whose seals do not follow the speed (it has
    no frequency-dependent seal) is scheduled from standstill to the top speed on the
    design model's states, as ``run``'s LPV is — not over ``speed_range_hz`` alone."""
    seen = {}

    class Stop(Exception):
        pass

    def fake(cfg, **kw):
        seen.update(kw)
        raise Stop

    monkeypatch.setattr(commands, "design_lpv", fake)
    rig = EXAMPLES / "overhung_compressor.toml"
    with pytest.raises(Stop):
        commands.design_files(rig, "lpv", tmp_path / "out")
    spec = design_spec(load_rig(rig))
    assert seen["speeds_hz"] == (0.0, 305.0) and seen["states"] == spec.model_states
