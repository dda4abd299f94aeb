"""The seeded family of gyroscopic rigs of ``benchmarks/bench_family.py``, three seeds run
end to end as the benchmark runs them (``ambseal run --no-identify`` in a child process):
each rig is what the generator's docstring promises (Ip/It about the centre of mass from
ambseal's rigid-body inertia, the first free–free bending frequency against the top
speed, checked again here), the run writes its metrics, and at least one method is
delivered as it runs from standstill to the top speed, zone A or B on every axis
(:func:`bench_family.delivered`)."""

from __future__ import annotations

import importlib.util
import sys
import tomllib
from pathlib import Path

import pytest

from ambseal.config import parse_rig
from ambseal.model.modes import free_bending_hz

BENCH = Path(__file__).resolve().parents[1] / "benchmarks"


def _bench_family():
    sys.path.insert(0, str(BENCH))  # its sibling bench_suite
    spec = importlib.util.spec_from_file_location("bench_family", BENCH / "bench_family.py")
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


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
