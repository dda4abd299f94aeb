"""Spin-up of the turboexpander with the LPV and the 140 Hz controllers (thesis P3 §4,
Figs. 11–12): alternating 100 N force and 2 µm output steps on A_x during a 20 → 300 Hz
ramp in 1 s; σ̄(S_o) at frozen speeds on the full-order plant.

References: P3 §3.1 (2 % settling within 20 ms, σ̄(S_o) ≤ 3, ISO 14839-3), P3 Figs. 11–12.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

pytest.importorskip("control")
pytest.importorskip("cvxpy")

from ambseal.config import load_rig  # noqa: E402
from ambseal.errors import ModelError  # noqa: E402

TURBO = Path(__file__).resolve().parents[2] / "examples" / "turboexpander.toml"


@pytest.fixture(scope="module")
def runs():
    from ambseal.analysis.spinup import frozen_sensitivity, spinup
    from ambseal.control.lpv_design import design_frozen, design_lpv
    from ambseal.control.lpv_plant import lpv_plant

    cfg = load_rig(TURBO)
    d = design_lpv(cfg, frozen_gamma=False)
    fz = design_frozen(cfg, 140.0)
    # simulation plant: rigid body + first bending pair, grid on the seal-table points
    grid = np.union1d(np.linspace(20.0, 300.0, 29), [50.0, 100.0, 150.0, 200.0, 250.0])
    L = lpv_plant(cfg, grid, states=12, force_positions=(cfg.amb[0].position,))
    sims = {"lpv": spinup(L, d, name="LPV"), "hinf140": spinup(L, fz.K, name="H∞ 140 Hz")}
    om = 2 * np.pi * np.logspace(0, np.log10(3000.0), 200)
    speeds = np.linspace(20.0, 300.0, 8)
    cache: dict = {}
    sens = {"lpv": frozen_sensitivity(cfg, d, speeds, name="LPV", omega=om, plants=cache),
            "hinf140": frozen_sensitivity(cfg, fz.K, speeds, name="H∞ 140 Hz", omega=om,
                                          plants=cache)}
    return L, d, fz, sims, sens


def test_output_steps_settle_within_20_ms_and_faster(runs):
    """P3 §3.1: 2 % settling within 20 ms — met by the LPV controller for every 2 µm
    output step over 20–300 Hz, each faster than the 140 Hz H∞ controller."""
    _, _, _, sims, _ = runs
    lpv = [s for s in sims["lpv"].steps if s.kind.startswith("output")]
    ref = [s for s in sims["hinf140"].steps if s.kind.startswith("output")]
    assert len(lpv) == 10
    assert max(s.settling_ms for s in lpv) < 20.0
    assert all(a.settling_ms < b.settling_ms for a, b in zip(lpv, ref))
    assert all(abs(s.peak_um - 2.0) < 0.05 for s in lpv)


def test_force_steps_peak_lower_but_slow_tail(runs):
    """The 100 N force steps: the LPV peak (≈ 2.05 µm) is below the 140 Hz controller's
    (≈ 2.55 µm) at every speed, but neither settles to 2 % within the 50 ms window — the
    integral action of W_p with A = 1e-2 (pole at ω_B A = 3.1 rad/s) leaves a slow tail.
    NOT the P3 §3.1 requirement: recorded as the current state."""
    _, _, _, sims, _ = runs
    lpv = [s for s in sims["lpv"].steps if s.kind.startswith("force")]
    ref = [s for s in sims["hinf140"].steps if s.kind.startswith("force")]
    assert all(a.peak_um < b.peak_um for a, b in zip(lpv, ref))
    assert all(s.settling_ms > 20.0 for s in lpv)
    assert np.max(np.abs(sims["lpv"].current_a)) < 5.0  # ±5 A current limit, P3 §3.1


def test_frozen_sensitivity_full_order(runs):
    """P3 Fig. 12 data: both controllers stabilise the full-order plant at every frozen
    speed; σ̄(S_o) ≤ 3 holds for the 140 Hz controller near 140 Hz and for the LPV one up to
    100 Hz, not over the whole range (2 kHz bending-mode spill-over; see the report)."""
    _, _, _, _, sens = runs
    for s in sens.values():
        assert s.stable.all()
        assert s.sigma.shape == (8, 200)
    lpv = sens["lpv"]
    assert np.all(lpv.peak[lpv.speeds_hz <= 100.0] < 3.0)


def test_figures(runs, tmp_path):
    """The two figures are written as PNG (P3 Figs. 11–12)."""
    from ambseal.report.lpv_figures import frozen_sensitivity_figure, spinup_figure

    _, _, _, sims, sens = runs
    p1 = spinup_figure(tmp_path / "spinup.png", list(sims.values()))
    p2 = frozen_sensitivity_figure(tmp_path / "so.png", list(sens.values()))
    assert p1.stat().st_size > 1000 and p2.stat().st_size > 1000


def test_spinup_bad_input(runs):
    """A plant without force inputs and an inconsistent time step are refused."""
    from ambseal.analysis.spinup import spinup
    from ambseal.control.lpv_plant import lpv_plant

    L, d, _, _, _ = runs
    with pytest.raises(ModelError, match="multiple of dt"):
        spinup(L, d, schedule_s=1.5e-3, dt=1e-3)
    bare = lpv_plant(load_rig(TURBO), [20.0, 300.0])
    with pytest.raises(ModelError, match="no force input"):
        spinup(bare, d)
