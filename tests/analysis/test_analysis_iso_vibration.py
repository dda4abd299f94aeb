"""ISO 14839-2 zones: boundaries as fractions of C_min, a value on a boundary in the upper
zone, and the sensors of an AMB rig graded against their backup clearance."""

from __future__ import annotations

import pytest

from ambseal.analysis.signoff.iso_vibration import vibration_zone


@pytest.mark.parametrize("d_um, zone", [(0.0, "A"), (29.9, "A"), (30.0, "B"), (39.0, "B"),
                                        (40.0, "C"), (50.0, "D"), (120.0, "D")])
def test_zones_at_0_3_0_4_0_5_of_c_min(d_um, zone):
    assert vibration_zone(d_um * 1e-6, 100e-6, (0.3, 0.4, 0.5)) == zone


def test_an_amb_rig_is_graded_at_its_sensors(tmp_path):
    """The overhung compressor with its PID as it runs: one zone per AMB, D_max the
    probes' largest p-p amplitude over the continuous speed range halved, against the
    backup clearance; without a backup clearance the AMB is not graded."""
    from ambseal.analysis import api617_unbalance, iso14839_2_zones
    from ambseal.analysis.judge import operating_points
    from ambseal.app.commands import digital_for
    from ambseal.config import load_rig
    from ambseal.design import design, design_spec

    cfg = load_rig("examples/overhung_compressor.toml")
    spec = design_spec(cfg)
    res = design(cfg, "pid", spec=spec)
    K = digital_for(cfg, "pid", res.K, res, operating_points(spec))
    unb = api617_unbalance(cfg, K, name="pid")
    iso = iso14839_2_zones(cfg, unb)
    assert [s.amb for s in iso.sensors] == [a.name for a in cfg.amb]
    for s, a in zip(iso.sensors, cfg.amb):
        d = max(0.5e-6 * c.probe_um[(c.speed_hz >= unb.min_hz) & (c.speed_hz <= unb.max_hz),
                                    list(c.probe_m).index(a.sensor_position)].max()
                for c in unb.cases)
        # C_min: the touchdown bearing beside the AMB (the rig's TA, TB)
        td = min(cfg.touchdown, key=lambda t: abs(t.position - a.position))
        assert s.d_max_m == pytest.approx(d) and s.c_min_m == td.radial_clearance
        assert s.zone == vibration_zone(d, td.radial_clearance, (0.3, 0.4, 0.5))
    bare = cfg.model_copy(update={"touchdown": []})
    none = iso14839_2_zones(bare, unb)
    assert not none.graded and none.zone is None and none.passed
