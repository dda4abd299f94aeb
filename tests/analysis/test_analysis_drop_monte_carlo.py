"""Monte-Carlo drops (ambseal.analysis.drop_monte_carlo): the Wilson interval against
Newcombe's published values, the draws reproducible by seed, serial and on Dask the same
rows, and the probability of backward whirl counted from the rows."""

from __future__ import annotations

import json

import numpy as np
import pytest

from ambseal.analysis import drop_scatter, wilson_interval
from ambseal.errors import ConfigError

from .test_analysis_drop import _rig


@pytest.mark.parametrize("k, n, lo, hi", [
    # Newcombe, Stat. Med. 17 (1998) 857–872, Table II, method 3 (score, no continuity
    # correction)
    (81, 263, 0.2553, 0.3662), (15, 148, 0.0624, 0.1605), (0, 20, 0.0, 0.1611),
    (1, 29, 0.0061, 0.1718)])
def test_the_wilson_interval_is_newcombes(k, n, lo, hi):
    got = wilson_interval(k, n)
    assert got == pytest.approx((lo, hi), abs=6e-5)


def test_the_wilson_interval_refuses_what_is_no_proportion():
    for k, n in ((3, 2), (-1, 4), (0, 0)):
        with pytest.raises(ValueError, match="k <= n"):
            wilson_interval(k, n)


def _spread(cfg, **kw):
    return drop_scatter(cfg, 4, seed=7, friction=(0.05, 0.3), clearance_tol_m=2e-5,
                        unbalance_kgm=(0.0, 1e-4), speed_rpm=3000.0, duration_s=0.02,
                        **kw)


def test_the_draws_are_the_seeds_and_the_rows_the_same_serial_or_on_dask():
    """Four drops of the rigid rotor: each draw within its range and the same for the same
    seed, another seed other draws; two local worker processes give the serial rows bit
    for bit, in draw order; the summary's counts are the rows'."""
    pytest.importorskip("distributed")
    cfg = _rig().model_copy(update={"touchdown": [
        t.model_copy(update={"restitution": 0.5}) for t in _rig().touchdown]})
    serial = _spread(cfg, workers=1)
    rows = serial["runs"]
    assert [r["run"] for r in rows] == [0, 1, 2, 3] and serial["n"] == 4
    for r in rows:
        for name in ("TA", "TB"):
            assert 0.05 <= r[f"{name}_friction"] <= 0.3
            assert abs(r[f"{name}_clearance_m"] - 2e-4) <= 2e-5
        assert 0.0 <= r["unbalance_kgm"] <= 1e-4
    assert len({r["TA_friction"] for r in rows}) == 4
    assert json.dumps(_spread(cfg, workers=1)) == json.dumps(serial)
    other = drop_scatter(cfg, 4, seed=8, friction=(0.05, 0.3), speed_rpm=3000.0,
                         duration_s=0.02, workers=1)
    assert other["runs"][0]["TA_friction"] != rows[0]["TA_friction"]
    assert json.dumps(_spread(cfg, workers=2)) == json.dumps(serial)
    whirl = sum(r["backward_whirl"] for r in rows)
    assert serial["backward_whirl"]["count"] == whirl
    assert serial["backward_whirl"]["interval"] == list(wilson_interval(whirl, 4))
    assert serial["failed"]["count"] == sum(not r["passed"] for r in rows)
    assert serial["peak_force_n"] == max(r[f"{n}_peak_force_n"] for r in rows
                                         for n in ("TA", "TB"))


def test_frictionless_rings_never_whirl_backward_and_bad_spreads_are_refused():
    """Without friction nothing drives a backward whirl: probability 0 over the draws of
    clearance and unbalance, its interval Wilson's [0, 1 − ...]. A range upside down, a
    tolerance as large as the clearance, no runs: refused by name."""
    cfg = _rig()
    out = drop_scatter(cfg, 3, seed=1, clearance_tol_m=5e-5, unbalance_kgm=(0.0, 1e-4),
                       speed_rpm=3000.0, duration_s=0.02, workers=1)
    assert out["backward_whirl"]["count"] == 0
    assert out["backward_whirl"]["interval"] == pytest.approx([0.0, 0.5615], abs=1e-4)
    assert np.all([r["TA_friction"] == 0.0 for r in out["runs"]])
    for kw, key in (({"friction": (0.3, 0.1)}, "friction"),
                    ({"clearance_tol_m": 2e-4}, "clearance tolerance"),
                    ({"unbalance_kgm": (-1.0, 1.0)}, "unbalance")):
        with pytest.raises(ConfigError, match=key):
            drop_scatter(cfg, 2, seed=1, **kw)
    with pytest.raises(ConfigError, match="runs"):
        drop_scatter(cfg, 0, seed=1)
