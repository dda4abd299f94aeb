"""The controller scheduled on a seal coefficient (issue 14 §2) and the one scheduled-
controller type it shares with the speed-scheduled LPV controller."""

import numpy as np
import pytest

from ambseal.control.controller import ScheduledController, frozen, matrices_at
from ambseal.control.lpv import LpvController
from ambseal.control.seal_schedule import SealScheduledDesign, design_seal_scheduled
from ambseal.control.weights import default_weights
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
    """Issue 14 acceptance (§2): at every frozen k on a grid 5× denser than the design grid
    over 0–3× nominal (21 pressures), the scheduled controller frozen at k is stable on the
    full-order plant (every mode, the 557 Hz bending pair included) with σ̄(S_o) ≤ 3 per
    axis — the ISO 14839-3 zone-A limit (the reference)."""
    from ambseal.analysis.ramp import frozen_cases

    d = testrig_tracked
    assert d.design_states == 12  # the specification's model keeps the bending pair
    cases = frozen_cases(testrig_cfg, d)
    assert len(cases) == 5 * (len(d.grid) - 1) + 1
    p0 = testrig_cfg.operating.pressure_bar
    assert cases[0]["pressure_bar"] == 0.0 and cases[-1]["pressure_bar"] == pytest.approx(3 * p0)
    assert all(c["stable"] for c in cases)
    worst = max(max(c["sensitivity_peak_per_axis"].values()) for c in cases)
    assert worst <= 3.0
