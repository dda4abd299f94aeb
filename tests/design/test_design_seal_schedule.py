"""The controller scheduled on a seal coefficient and the one scheduled-
controller type it shares with the speed-scheduled LPV controller."""

import numpy as np
import pytest

from ambseal.machine.controller import ScheduledController, frozen, matrices_at
from ambseal.robust.lpv import LpvController
from ambseal.design.seal_schedule import SealScheduledDesign, design_seal_scheduled
from ambseal.design.weights import default_weights
from ambseal.errors import ModelError, SynthesisError


def _two_entry_design():
    """A 1-state, 1-input, 1-output table at θ = 0 and 2 MN/m (synthesis units)."""
    g = np.array([0.0, 2e6])
    K = LpvController(g, np.array([[[-100.0]], [[-300.0]]]), np.array([[[1.0]], [[3.0]]]),
                      np.array([[[2.0]], [[4.0]]]), np.array([[[0.5]], [[1.5]]]),
                      ("y_A_zeta",), ("u_A_zeta",))
    return SealScheduledDesign("seal.k", K, 1.0, 1.05, g, g, np.ones(2), 1e5,
                               default_weights("hinf"))


def test_scheduled_on_a_named_parameter_interpolates_and_refuses_a_missing_value():
    """Reference: linear interpolation by hand between the two table entries (θ = 0.5 MN/m
    is a quarter of the way: A = −150, B = 1.5, C = 2.5, D = 0.75 in synthesis units),
    and the physical conversion K = −(D_u/D_e) K_P of the H∞ weights (D_e = 20 µm, D_u =
    1 A). A controller scheduled on seal.k frozen without its value is refused, not
    silently frozen at a speed."""
    d = _two_entry_design()
    assert isinstance(d, ScheduledController)
    assert d.parameter == "seal.k" and d.schedule == (0.0, 2e6)
    A, B, C, D = matrices_at(d, values={"seal.k": 0.5e6})
    de, du = 20e-6, 1.0
    np.testing.assert_allclose(A, [[-150.0]])
    np.testing.assert_allclose(B, [[1.5]])
    np.testing.assert_allclose(C, [[-2.5 * du / de]])
    np.testing.assert_allclose(D, [[-0.75 * du / de]])
    K = frozen(d, values={"seal.k": 0.5e6})
    np.testing.assert_allclose(np.asarray(K.D), D)
    with pytest.raises(ModelError, match="seal.k"):
        frozen(d, 100.0)


def test_design_refuses_a_parameter_without_channel_and_a_one_point_grid(testrig_cfg):
    """Bad input: a name the rig has no LFT channel for, and a grid of one point."""
    with pytest.raises(ModelError, match="unknown parameter"):
        design_seal_scheduled(testrig_cfg, "seal.q")
    with pytest.raises(SynthesisError, match="n_grid"):
        design_seal_scheduled(testrig_cfg, n_grid=1)


@pytest.mark.slow
def test_tracked_design_stable_in_zone_a_on_the_full_order_plant(testrig_cfg, testrig_tracked):
    """At every frozen k of the controller table's size over 0–3× nominal (21 pressures), the scheduled controller frozen at k is stable on the
    full-order plant (every mode, the 557 Hz bending pair included) with σ̄(S_o) ≤ 3 per
    axis — the ISO 14839-3 zone-A limit (the reference)."""
    from ambseal.analysis.judge import judge_settings
    from ambseal.analysis.ramp import frozen_cases
    from ambseal.design.specs import design_spec

    d = testrig_tracked
    assert d.design_states == 12  # the specification's model keeps the bending pair
    cases = frozen_cases(testrig_cfg, d, settings=judge_settings(design_spec(testrig_cfg)))
    assert len(cases) == len(d.check_grid) == 21
    p0 = testrig_cfg.operating.pressure_bar
    assert cases[0]["pressure_bar"] == 0.0 and cases[-1]["pressure_bar"] == pytest.approx(3 * p0)
    assert all(c["stable"] for c in cases)
    worst = max(max(c["sensitivity_peak_per_axis"].values()) for c in cases)
    assert worst <= 3.0


@pytest.mark.slow
def test_tracked_digital_table_stable_with_the_target_delay(testrig_cfg, testrig_tracked):
    """Exported like every scheduled controller: the tracked controller's
    digital table (:func:`ambseal.app.commands.digital_for`: the method chosen on the sampled
    full-order loops with the target's delay at the judged pressures and between table
    entries). Reference: python-control, side by side — the full-order plant sampled by
    ``sample_system`` (ZOH) in negative feedback with the delayed, interpolated table at
    k = 0.3, 1.7 and 2.6× nominal (pressures the choice did not check): every closed-loop
    pole inside the unit circle, and every diagonal element of S_o = (I + G_d K_d)⁻¹ below
    ISO 14839-3's zone-A limit 3 (the table runs in zone A per axis), G_d and K_d at
    z = e^{jωT} (10 Hz to Nyquist) by a dense solve C (zI − A)⁻¹ B + D (numpy; python-
    control's own evaluation of the 320-state sampled plant is off by several % here)."""
    import control

    from ambseal.analysis.judge import operating_points
    from ambseal.app.commands import digital_for
    from ambseal.design.specs import design_spec
    from ambseal.model.rig import build_plant
    from ambseal.model.seal import pressure_for_k

    cfg, d = testrig_cfg, testrig_tracked
    sd = digital_for(cfg, "tracked", d, d, operating_points(design_spec(cfg)))
    assert sd.parameter == "seal.k" and sd.delay_samples == cfg.controller.delay_samples
    k_nom = d.grid[-1] / 3.0
    for f in (0.3, 1.7, 2.6):
        pl = build_plant(cfg, pressure_bar=pressure_for_k(cfg.seal, "seal.k", f * k_nom))
        G = pl.select_inputs([pl.input_names[j] for j in pl.current_inputs()]).to_statespace()
        Gd = control.sample_system(G, sd.Ts, method="zoh")
        loop = control.feedback(Gd, sd.statespace_at(f * k_nom, delayed=True))
        assert np.max(np.abs(loop.poles())) < 1.0, f
        z = np.exp(2j * np.pi * np.logspace(1, np.log10(0.999 / (2 * sd.Ts)), 300) * sd.Ts)
        L = _dense_response(Gd, z) @ _dense_response(sd.statespace_at(f * k_nom, True), z)
        So = np.linalg.inv(np.eye(L.shape[1]) + L)
        per_axis = np.abs(np.diagonal(So, axis1=1, axis2=2)).max(axis=0)
        assert np.all(per_axis < 3.0), (f, per_axis)


def _dense_response(sys, z):
    """C (zI − A)⁻¹ B + D at each z, shape (n_z, ny, nu), by dense solves."""
    A, B, C, D = (np.asarray(X, float) for X in (sys.A, sys.B, sys.C, sys.D))
    return np.stack([C @ np.linalg.solve(x * np.eye(A.shape[0]) - A, B) + D for x in z])


def _seal_table(d):
    """A ScheduledDigital on seal.k from ``d`` by hand: its physical matrices at θ = 0, 1,
    2 MN/m and their ZOH equivalents at 10 kHz (what ``scheduled_digital`` tabulates once it
    has chosen the method)."""
    from ambseal.robust.digital import discretize_as
    from ambseal.machine.scheduled_digital import ScheduledDigital

    g = np.array([0.0, 1e6, 2e6])
    cont = [d.matrices_at(t) for t in g]
    disc = [discretize_as(m, 1e-4, "zoh") for m in cont]
    st = [tuple(np.stack([m[i] for m in seq]) for i in range(4)) for seq in (cont, disc)]
    return ScheduledDigital(g, st[0], st[0], st[1], ("y_A_zeta",), ("i_A_zeta",), "zoh",
                            None, 1e4, 1, (), (), "K_tracked", "seal.k")


@pytest.mark.parametrize("suffix", [".json", ".npz", ".mat"])
def test_seal_scheduled_table_export_round_trip(tmp_path, suffix):
    """Reference: the design's own scheduling law (linear in θ between its entries, the
    hand-checked interpolation above) and the exported discrete table: read back by
    load_controller, the table is still scheduled on seal.k over the same grid, its
    continuous law equals the design at θ = 0.5 MN/m (between entries) and its discrete
    controller at θ equals the exported one entry by entry; the interpolation law written
    into the file names seal.k."""
    from ambseal.export.controller_files import export_controller, load_controller

    d = _two_entry_design()
    sd = _seal_table(d)
    back = load_controller(export_controller(sd, tmp_path / f"K{suffix}"))
    assert back.parameter == "seal.k" and back.schedule == (0.0, 2e6)
    assert "seal.k" in back.interpolation
    for X, Y in zip(back.matrices_at(0.5e6), d.matrices_at(0.5e6)):
        np.testing.assert_allclose(X, Y, rtol=1e-12)
    d0, d1 = back.discrete_at(1.3e6), sd.discrete_at(1.3e6)
    for k in "ABCD":
        np.testing.assert_array_equal(getattr(d0, k), getattr(d1, k))
    with pytest.raises(ModelError, match="seal.k"):
        frozen(back, 100.0)  # not silently frozen at a speed


def test_seal_scheduled_c_interpolates_on_theta_like_python(tmp_path):
    """Reference: ScheduledDigital.discrete_at run sample by sample while θ sweeps from
    below the table to above it (1 000 samples of a random sensor signal): the generated C
    module, called with θ in place of the speed, gives the same currents within 1e-9 of
    their peak."""
    from ambseal.export.codegen import write_c

    from tests.robust.test_robust_digital import _compile_and_run

    sd = _seal_table(_two_entry_design())
    n = 1000
    y = 1e-6 * np.random.default_rng(4).standard_normal((n, 1))
    theta = np.linspace(-0.2e6, 2.2e6, n)
    x, ref = np.zeros(1), np.empty((n, 1))
    for k in range(n):
        dk = sd.discrete_at(theta[k])
        ref[k] = -(dk.C @ x + dk.D @ y[k])
        x = dk.A @ x + dk.B @ y[k]
    files = write_c(sd, tmp_path / "c", "amb_tracked")
    assert "theta = seal.k" in files[0].read_text()
    got = _compile_and_run(tmp_path, files, "amb_tracked", y, "double", speeds=theta)
    assert np.max(np.abs(got - ref)) < 1e-9 * np.max(np.abs(ref))


class _Planted:
    """A pickle that, when loaded, creates the file ``marker`` (stands for any code)."""

    def __init__(self, marker):
        self.marker = str(marker)

    def __reduce__(self):
        import pathlib

        return (pathlib.Path.touch, (pathlib.Path(self.marker),))


def test_design_cache_is_data_never_code(testrig_cfg, tmp_path, monkeypatch):
    """A cache entry is plain JSON keyed by the inputs and the package version: a second
    call reads it back (the same table, no synthesis); a pickle planted under the former
    name or in place of the entry, a malformed entry and an entry of another version are
    never executed but ignored, and the design is recomputed. Reference: the marker file
    the planted pickle would create (it must not exist) and the design's own arrays."""
    import json
    import pickle

    import ambseal.design.seal_schedule as ss

    calls = []

    def fake_synthesis(cfg, plant, args, scale, dl, kw):
        calls.append(args)
        return _two_entry_design()

    monkeypatch.setattr(ss, "_synthesise", fake_synthesis)
    monkeypatch.delenv(ss.CACHE_ENV, raising=False)
    cache = tmp_path / "cache"
    first = design_seal_scheduled(testrig_cfg, cache_dir=cache)
    (entry,) = cache.iterdir()
    assert entry.suffix == ".json" and entry.name.startswith("seal_scheduled-")
    again = design_seal_scheduled(testrig_cfg, cache_dir=cache)
    assert len(calls) == 1
    for X, Y in zip(again.matrices_at(0.7e6), first.matrices_at(0.7e6)):
        np.testing.assert_array_equal(X, Y)
    assert again.weights == first.weights and again.parameter == "seal.k"

    marker = tmp_path / "executed"
    planted = pickle.dumps(_Planted(marker))
    entry.with_suffix(".pkl").write_bytes(planted)
    for bad in (planted, b"{not json", b"[]", b'{"key": 1}'):
        entry.write_bytes(bad)
        d = design_seal_scheduled(testrig_cfg, cache_dir=cache)
        assert not marker.exists()
        assert d.schedule == first.schedule
    assert len(calls) == 5
    doc = json.loads(entry.read_text())
    doc["ambseal_version"] = "0.0.0-other"
    entry.write_text(json.dumps(doc))
    design_seal_scheduled(testrig_cfg, cache_dir=cache)
    assert len(calls) == 6 and not marker.exists()


def test_a_cache_that_cannot_be_written_is_skipped(testrig_cfg, tmp_path, monkeypatch):
    """A cache folder the user cannot write (read-only, or a file in its place) is skipped
    with a warning naming it: the design is still returned, the same as without a cache.
    Reference: the design the synthesis returns."""
    import os

    import ambseal.design.seal_schedule as ss

    monkeypatch.setattr(ss, "_synthesise", lambda *a: _two_entry_design())
    ro = tmp_path / "ro"
    ro.mkdir()
    os.chmod(ro, 0o500)
    blocked = tmp_path / "file"
    blocked.write_text("not a folder")
    # an entry's name taken by a folder: the rename fails as in a read-only folder, also
    # for root (who writes anywhere)
    taken = tmp_path / "taken"
    design_seal_scheduled(testrig_cfg, cache_dir=taken)
    (entry,) = taken.iterdir()
    entry.unlink()
    entry.mkdir()
    try:
        for folder in (ro, blocked / "sub", taken):
            if folder == ro and os.access(ro, os.W_OK):  # root writes anywhere
                continue
            monkeypatch.setenv(ss.CACHE_ENV, str(folder))
            with pytest.warns(UserWarning, match="cache.*not kept") as rec:
                d = design_seal_scheduled(testrig_cfg)
            assert str(folder) in str(rec[0].message)
            assert d.schedule == _two_entry_design().schedule
    finally:
        os.chmod(ro, 0o700)
    assert list(ro.iterdir()) == [] and list(taken.iterdir()) == [entry]


def test_no_deserialisation_of_code_in_the_package():
    """Nothing ambseal reads from disk is unpickled: no pickle load, no
    ``allow_pickle=True`` and no ``eval`` in the source."""
    import re
    from pathlib import Path

    import ambseal

    src = Path(ambseal.__file__).parent
    bad = re.compile(r"pickle\.loads?\(|allow_pickle\s*=\s*True|\beval\(|marshal\.loads?\(")
    found = [f"{p.relative_to(src)}:{i}" for p in src.rglob("*.py")
             for i, line in enumerate(p.read_text(encoding="utf-8").splitlines(), 1)
             if bad.search(line)]
    assert not found, found


def test_a_seal_scheduled_controller_is_judged_over_its_whole_schedule(testrig_cfg):
    """Reference: the test rig's seal k = 1.1 MN/m per bar from 0 (rig file), so a schedule
    over k = 0–3× its value at the nominal 2.04 bar ends at 0 and 3 × 2.04 = 6.12 bar. The
    specification's judged pressures (0, 2.04, 4.08 bar) stay, 6.12 bar is added after
    them as a "high" condition; a fixed controller keeps the specification's points."""
    from ambseal.analysis.judge import operating_points, points_for
    from ambseal.design.specs import design_spec

    cfg = testrig_cfg
    points = operating_points(design_spec(cfg))
    assert [p.pressure_bar for p in points] == pytest.approx([0.0, 2.04, 4.08])
    k_nom = 1.1e6 * 2.04
    g = np.array([0.0, 3.0 * k_nom])
    K = LpvController(g, *(np.zeros((2, 1, 1)),) * 4, ("y_A_zeta",), ("u_A_zeta",))
    d = SealScheduledDesign(f"{cfg.seal[0].name}.k", K, 1.0, 1.05, g, g, np.ones(2), 1e5,
                            default_weights("hinf"))
    judged = points_for(d, points, cfg)
    assert [p.pressure_bar for p in judged] == pytest.approx([0.0, 2.04, 4.08, 6.12])
    assert judged[:3] == points
    assert (judged[3].label, judged[3].condition) == ("6.12 bar", "high")
    assert points_for(object(), points, cfg) == points
    # an end inside the judged pressures (k = 1.1 kN/m: 1 mbar) extends nothing: not added
    g = np.array([1.1e3, 3.0 * k_nom])
    inside = SealScheduledDesign(f"{cfg.seal[0].name}.k", K, 1.0, 1.05, g, g, np.ones(2),
                                 1e5, default_weights("hinf"))
    assert [p.pressure_bar for p in points_for(inside, points, cfg)] == pytest.approx(
        [0.0, 2.04, 4.08, 6.12])
