"""The LPV on speed has no pole its target cannot run: the example flywheel
(``examples/flywheel.toml``, Ip/It 1.18, 0–60 000 rpm) on a 10 kHz target, one sample of
delay. Synthesised, its H∞ LPV controller had a pair of poles at 51 MHz and others at 20
and 44 kHz, above the 5 kHz Nyquist frequency, where the sampled controller has no
counterpart; they are removed in the synthesis (``pole_bound`` of
:func:`ambseal.robust.lpv.lpvsyn`). The reference is python-control: the poles of the
exported continuous table, and the exported discrete table closed on the full-order plant
sampled by python-control at every judged speed and between them."""

from __future__ import annotations

import json
import re
from pathlib import Path

import numpy as np
import pytest

from ambseal.cli import main
from ambseal.config import load_rig

from ..exported_files import sampled_loop

EXAMPLE = Path(__file__).resolve().parents[2] / "examples" / "flywheel.toml"
RATE_HZ = 10_000.0


@pytest.fixture(scope="module")
def flywheel_at_10_khz(tmp_path_factory):
    """``(rig, out folder)`` of ``ambseal design --method lpv`` on the example flywheel with
    its sample rate set to 10 kHz (a copy; the example stays as it is)."""
    tmp = tmp_path_factory.mktemp("flywheel10k")
    text, n = re.subn(r"(?m)^sample_rate_hz\s*=.*$", f"sample_rate_hz = {RATE_HZ}",
                      EXAMPLE.read_text(encoding="utf-8"))
    assert n == 1
    rig = tmp / "flywheel_10k.toml"
    rig.write_text(text, encoding="utf-8")
    out = tmp / "out"
    assert main(["--quiet", "design", str(rig), "--method", "lpv", "--out", str(out)]) == 0
    return rig, out


def test_the_lpv_has_no_pole_above_nyquist_and_runs_at_every_speed(flywheel_at_10_khz):
    rig, out = flywheel_at_10_khz
    cfg = load_rig(rig)
    f = np.load(out / "controller_lpv.npz", allow_pickle=False)
    nyquist = np.pi * RATE_HZ
    for A in f["A_c"]:
        assert np.abs(np.linalg.eigvals(A)).max() < nyquist
    summary = json.loads((out / "design_lpv.json").read_text(encoding="utf-8"))
    bound = summary["pole_bound"]
    assert bound["reduced"] and bound["bound_hz"] == pytest.approx(RATE_HZ / 2)
    assert max(bound["above_hz"]) > RATE_HZ / 2, bound  # what the synthesis gave
    assert (f"(its {len(bound['above_hz'])} poles above the 5000 Hz Nyquist frequency "
            "removed)") in summary["verdict"]
    judged = [r["speed_hz"] for r in json.loads(str(f["judged_json"]))]
    top = cfg.operating.speed_rpm / 60.0
    for hz in sorted({*np.linspace(0.0, top, 17), *judged}):
        z = np.abs(sampled_loop(cfg, f, hz).poles()).max()
        assert z < 1, (hz, z)
