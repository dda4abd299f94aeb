"""API 617 Level II: the table of a rigid rotor on damped springs with a seal and a
stage against the closed form of its cylindrical whirl, m s² + c s + k − jQ = 0."""

from __future__ import annotations

import math
import tomllib

import numpy as np
import pytest

from ambseal.analysis.signoff.level1 import stage_cross_coupling
from ambseal.analysis.signoff.level2 import level2_analysis
from ambseal.config import parse_rig

from .test_analysis_level1 import _rigid_rotor


def _log_dec(m, c, k, Q):
    lam = np.roots([m, c, k - 1j * Q])
    lam = lam[lam.imag > 0][0]
    return -2 * math.pi * lam.real / lam.imag


@pytest.mark.parametrize("seal_k, passed", [(2e5, True), (8e5, False)])
def test_level2_rows_are_the_closed_form(seal_k, passed):
    """Rotor alone, + the seal (k, C at mid-span), + Q_A at the stage, all: each row's δ
    the forward root of m s² + c s + k − jQ (Q and c summed at mid-span) within 1 %; the
    verdict δ ≥ 0.1 with every source."""
    k, c, c_seal = 1e7, 2000.0, 100.0
    doc = tomllib.loads(_rigid_rotor(k, c, 4.5e4))
    doc["seal"] = [{"name": "eye", "position": 0.2, "k": seal_k, "C": c_seal}]
    cfg = parse_rig(doc)
    r = level2_analysis(cfg)
    m = math.pi / 4 * 0.2**2 * 0.4 * 7850.0
    qa = stage_cross_coupling(cfg.stage[0], "compressor", 2 * math.pi * 50.0)
    want = [_log_dec(m, c, k, 0.0), _log_dec(m, c + c_seal, k, seal_k),
            _log_dec(m, c, k, qa), _log_dec(m, c + c_seal, k, seal_k + qa)]
    assert [row.component for row in r.rows] == ["rotor and supports", "+ seal eye",
                                                 "+ Q_A at the stages", "all sources"]
    assert [row.log_dec for row in r.rows] == pytest.approx(want, rel=0.01)
    assert r.log_dec == r.rows[-1].log_dec and r.limit == 0.1
    assert r.passed is passed and bool(want[-1] >= 0.1) is passed
    assert r.to_dict()["table"][1]["component"] == "+ seal eye"


def test_level2_judges_the_mode_the_sources_act_on():
    """Without modal damping the shaft's bending modes keep δ ≈ 0.0002 whatever the
    sources do: Level II follows the cylindrical whirl Q_A takes damping from (50 Hz,
    δ = 0.166 by the closed form), not them."""
    doc = tomllib.loads(_rigid_rotor(1e7, 2000.0, 4.5e4))
    cfg = parse_rig(doc)
    r = level2_analysis(cfg)
    m = math.pi / 4 * 0.2**2 * 0.4 * 7850.0
    qa = stage_cross_coupling(cfg.stage[0], "compressor", 2 * math.pi * 50.0)
    assert r.log_dec == pytest.approx(_log_dec(m, 2000.0, 1e7, qa), rel=0.01)
    assert r.rows[-1].frequency_hz == pytest.approx(math.sqrt(1e7 / m) / (2 * math.pi),
                                                    rel=0.01) and r.passed
