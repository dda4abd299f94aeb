"""The LPV on speed runs on its target: the example flywheel (``examples/flywheel.toml``,
Ip/It 1.18, 0–60 000 rpm) on a 10 kHz target, one sample of delay. Synthesised, its H∞ LPV
controller has poles above the 5 kHz Nyquist frequency (up to a pair near 0.8 MHz), where
the sampled controller has no counterpart; they are removed in the synthesis
(``pole_bound`` of :func:`ambseal.robust.lpv.lpvsyn`), and R and S are centred at the
backed-off γ so that the controller does not follow the machine's rounding: uncentred,
SkylakeX kernels give another controller, whose sampled loop no discretisation holds. The
reference is python-control: the poles of the exported continuous table, and the exported
discrete table closed on the full-order plant sampled by python-control with a zero-order
hold, the delay after the controller, at every judged speed and between them."""

from __future__ import annotations

import json

import control
import numpy as np
import pytest

from ambseal.config import load_rig
from ambseal.model import build_plant

from ..exported_files import file_at

RATE_HZ = 10_000.0


@pytest.mark.heavy
@pytest.mark.xdist_group("flywheel_10k_lpv")  # the session's design, made once
def test_the_lpv_has_no_pole_above_nyquist_and_runs_at_every_speed(flywheel_10k_lpv):
    rig, outs = flywheel_10k_lpv
    out = next(iter(outs.values()))
    cfg = load_rig(rig)
    f = np.load(out / "controller_lpv.npz", allow_pickle=False)
    for A in f["A_c"]:
        assert np.abs(np.linalg.eigvals(A)).max() < np.pi * RATE_HZ
    summary = json.loads((out / "design_lpv.json").read_text(encoding="utf-8"))
    bound = summary["pole_bound"]
    assert bound["reduced"] and bound["bound_hz"] == pytest.approx(RATE_HZ / 2)
    assert max(bound["above_hz"]) > RATE_HZ / 2, bound  # what the synthesis gave
    assert (f"(its {len(bound['above_hz'])} poles above the 5000 Hz Nyquist frequency "
            "removed)") in summary["verdict"]
    Ts, d = float(f["Ts"]), int(f["delay_samples"])
    judged = [r["speed_hz"] for r in json.loads(str(f["judged_json"]))]
    top = cfg.operating.speed_rpm / 60.0
    for hz in sorted({*np.linspace(0.0, top, 17), *judged}):
        K = control.ss(*file_at(f, hz), Ts) * control.tf([1], [1] + [0] * d, Ts)
        plant = build_plant(cfg, speed_rpm=60.0 * hz)
        cur = plant.current_inputs()
        G = control.sample_system(control.ss(plant.A, plant.B[:, cur], plant.C,
                                             plant.D[:, cur]), Ts, "zoh")
        z = np.abs(control.feedback(G, K).poles()).max()
        assert z < 1, (hz, z)
