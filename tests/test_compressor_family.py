"""The seeded family of flexible compressors of ``benchmarks/bench_compressors.py``: each
rig is what the generator's docstring promises, checked on ambseal's own model of the
written file (its states, the free–free bending frequency against the top speed, the
rotor's mass, the AMBs' load capacity and the seals' cross-coupling at the judged map's
highest pressure drop), and one seed runs end to end as the benchmark runs it."""

from __future__ import annotations

import math
import tomllib

import pytest

from ambseal.config import parse_rig
from ambseal.model import build_plant
from ambseal.model.modes import free_bending_hz
from ambseal.model.rotor import assemble_rotor

from .benchmark_module import bench_module

GRAVITY = 9.81


def _bench():
    return bench_module("bench_compressors")


@pytest.mark.parametrize("seed", [0, 1, 4, 5])
def test_a_compressor_rig_is_what_its_draw_says(seed):
    bc = _bench()
    text, draw = bc.compressor_rig(seed)
    cfg = parse_rig(tomllib.loads(text))
    assert 40 <= sum(s.elements for s in cfg.shaft) <= 60
    assert 400 <= build_plant(cfg).A.shape[0] <= 600
    top_hz = cfg.operating.speed_rpm / 60
    assert cfg.operating.speed_rpm == pytest.approx(
        60 * draw["tip_speed_m_s"] / (math.pi * draw["impeller_m"]), rel=1e-12)
    ratio = free_bending_hz(cfg, 1)[0] / top_hz
    assert 1.2 * (1 - 2e-3) <= ratio <= 2.0 * (1 + 2e-3)
    assert ratio == pytest.approx(draw["bending_per_top"], rel=1e-12)
    M, _, _ = assemble_rotor(cfg).rigid()
    mass = M[0, 0]
    assert mass == pytest.approx(draw["mass_kg"], rel=1e-3)
    for amb in cfg.amb:
        # the bias current's linear range holds the drawn multiple of half the weight
        share = amb.ki * amb.bias_current / (mass * GRAVITY / 2)
        assert 3.0 * (1 - 1e-3) <= share <= 5.0 * (1 + 1e-3)
        assert amb.ks == pytest.approx(amb.ki * amb.bias_current / amb.air_gap, rel=1e-12)
    p_top = 2 * cfg.operating.pressure_bar
    assert 60 <= p_top <= 120
    main = cfg.seal[0]
    k_top = main.k.at_zero + main.k.per_bar * p_top
    assert 0.3 <= k_top / cfg.amb[0].ks <= 1.0
    c_top = main.C.at_zero + main.C.per_bar * p_top
    # whirl-frequency ratio k/(C·Ω) of 0.5 at the top speed (the C at zero pressure aside)
    assert k_top / ((c_top - main.C.at_zero) * 2 * math.pi * top_hz) == pytest.approx(0.5)
    assert len(cfg.stage) == draw["impellers"]
    assert cfg.controller.sample_rate_hz in bc.RATES_HZ


@pytest.mark.slow
def test_a_compressor_rig_runs_end_to_end_with_a_method_delivered():
    text, draw = _bench().compressor_rig(0)
    row = bench_module("bench_family").run_rig({"text": text, "draw": draw}, timeout=1800.0)
    assert row.get("returncode") in (0, 1), row.get("error")
    assert any(row["delivered"].values()), row["failed"]
