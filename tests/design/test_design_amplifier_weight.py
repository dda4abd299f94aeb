"""The amplifier's limit inside the design: a synchronous peak on the control weight W_u
(:func:`ambseal.design.weights.peak_weight`) bounds ``|K S_o|`` at the rotational
frequency where the unbalance needs more current than the amplifier has; the synchronous
current is ``K S_o G_f F_u`` (Schweitzer & Maslen, *Magnetic Bearings*, 2009, ch. 15)."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest

from ambseal.config import load_rig
from ambseal.design import design
from ambseal.model import build_plant

from ..rigid_rotor import rigid_amb_rig


def _ks(cfg, K, f_hz: float) -> float:
    """σ̄(K S_o)(j2πf) (A/m) of the full-order plant at speed f, by dense solves."""
    pl = build_plant(cfg, speed_rpm=60.0 * f_hz)
    cur = pl.current_inputs()
    s = 2j * np.pi * f_hz
    G = pl.C @ np.linalg.solve(s * np.eye(pl.A.shape[0]) - pl.A, pl.B[:, cur]) + pl.D[:, cur]
    Kj = K.C @ np.linalg.solve(s * np.eye(K.A.shape[0]) - K.A, K.B) + K.D
    return float(np.linalg.svd(Kj @ np.linalg.inv(np.eye(len(G)) + G @ Kj),
                               compute_uv=False)[0])


@pytest.mark.parametrize("height", [4.0, 8.0])
def test_a_peak_on_w_u_at_the_top_speed_lowers_the_synchronous_gain_there(tmp_path, height):
    """The rigid gyroscopic rotor's H∞ at its top speed (400 Hz): with W_u h times higher
    at 400 Hz, σ̄(K S_o) there falls by at least h/2 (the synthesis's own bound moves by
    h; the rest of the loop takes a share of it), and an octave below, where the rigid
    modes need the gain, it falls by less than a third as much."""
    cfg = load_rig(rigid_amb_rig(tmp_path), ("design.one_speed=true",))
    first = design(cfg, "hinf", allow_unstable=True)
    peaked = design(cfg, "hinf", allow_unstable=True, weights=replace(
        first.weights, wu_peak_hz=400.0, wu_peak_gain=height))
    assert peaked.weights.wu_peak_gain == height
    at = _ks(cfg, first.K, 400.0) / _ks(cfg, peaked.K, 400.0)
    octave = _ks(cfg, first.K, 200.0) / _ks(cfg, peaked.K, 200.0)
    assert at >= height / 2
    assert octave - 1 < (at - 1) / 3
