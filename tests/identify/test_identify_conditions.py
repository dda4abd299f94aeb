"""The identification's test conditions come from the rig, and a non-physical seal fit is
never designed on (ambseal.identify.procedure.seal_test_pressures,
ambseal.identify.design_model.non_physical / design_rig, rig_sim.facility_bias_current).

References: the rules as written; the thesis's own test pressures (0.5–2.5 bar at a nominal
2.04 bar, P5 §3.3) as the case the rule reproduces to 2 %; a linear regression of
``ambseal.identify.stats.linear_regression`` through chosen points as the seal fit."""

from __future__ import annotations

from pathlib import Path
from types import SimpleNamespace

import pytest

from ambseal.config import Affine, TruthSection, default_rig_path, load_rig, rig_with_values
from ambseal.errors import ConfigError
from ambseal.identify.design_model import design_rig, non_physical
from ambseal.identify.procedure import seal_test_pressures
from ambseal.identify.rig_sim import facility_bias_current
from ambseal.identify.stats import linear_regression

ROOT = Path(__file__).resolve().parents[2]


def test_seal_test_pressures_scale_with_the_rig():
    """A quarter to 1.25× the nominal pressure drop in quarters: the embedded rig's are the
    thesis's 0.5–2.5 bar within 2 %; the manual's 30-bar compressor is tested at 7.5–37.5
    bar, not at the thesis's 0.5–2.5; a rig at 0 bar and no judged pressure is refused."""
    rig = load_rig(default_rig_path())
    got = seal_test_pressures(rig)
    assert got == pytest.approx((0.51, 1.02, 1.53, 2.04, 2.55))
    assert got == pytest.approx((0.5, 1.0, 1.5, 2.0, 2.5), rel=0.021)
    comp = load_rig(ROOT / "docs" / "rigs" / "compressor.toml")
    assert seal_test_pressures(comp) == pytest.approx((7.5, 15.0, 22.5, 30.0, 37.5))
    none = load_rig(default_rig_path(), ("design.pressures_bar=[0.0]",))
    none = none.model_copy(update={"operating": none.operating.model_copy(
        update={"pressure_bar": 0.0})})
    with pytest.raises(ConfigError, match="pressure_bar"):
        seal_test_pressures(none)


def test_facility_bias_current_is_the_truths_else_the_rigs():
    """The pump's AMBs are biased at 5 A: a truth file that does not say otherwise gets
    5 A, not the thesis rig's 6 A; one that says 4 A gets 4 A."""
    pump = load_rig(ROOT / "examples" / "pump.toml")
    assert facility_bias_current(pump, TruthSection()) == 5.0
    assert facility_bias_current(pump, TruthSection(bias_current=4.0)) == 4.0


def _result(cfg, c_points):
    """A procedure result whose seal C regression runs through ``c_points`` [(bar, N·s/m)]
    and whose other fits hold the rig file's values (so only the seal decides)."""
    x, y = zip(*c_points)
    reg = linear_regression(list(x), list(y), [1.0] * len(x))
    return SimpleNamespace(regression={"C": reg}, amb=None, coupling=None,
                           identified=cfg)


def test_a_seal_damping_line_that_turns_negative_is_not_designed_on():
    """The compressor case of the field: C = 294 − 121·p from tests at 0.5–2.5 bar is
    −3 350 N·s/m at 30 bar — energy fed by direct damping, which no annular seal does. It
    is named, and the rig designed on keeps the rig file's C (one identified value outside
    its interval makes the identified rig the design rig)."""
    comp = load_rig(ROOT / "docs" / "rigs" / "compressor.toml")
    seal = comp.seal[0].name
    bad = _result(comp, [(0.5, 294 - 121 * 0.5), (1.5, 294 - 121 * 1.5), (2.5, 294 - 121 * 2.5)])
    assert non_physical(comp, bad) == [f"{seal}.C"]
    good = _result(comp, [(7.5, 300.0), (22.5, 420.0), (37.5, 540.0)])
    assert non_physical(comp, good) == []
    identified = rig_with_values(comp, {f"{seal}.C": Affine(at_zero=294.0, per_bar=-121.0)})
    rig, note = design_rig(comp, replace_identified(bad, identified))
    assert note["designed_on"] == "identified rig" and note["non_physical"] == [f"{seal}.C"]
    assert f"{seal}.C.at_zero" in note["outside_intervals"]
    assert rig.seal[0].C == comp.seal[0].C != identified.seal[0].C


def replace_identified(res, identified):
    res.identified = identified
    return res
