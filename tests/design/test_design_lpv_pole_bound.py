"""The LPV on speed has no pole its target cannot run: the example flywheel
(``examples/flywheel.toml``, Ip/It 1.18, 0–60 000 rpm) on a 10 kHz target, one sample of
delay. Synthesised, its H∞ LPV controller has poles above the 5 kHz Nyquist frequency,
where the sampled controller has no counterpart (on this machine's Python 3.11 with
Haswell kernels: a pair at 51 MHz and others at 20 and 44 kHz; their number and place
follow the machine's rounding); they are removed in the synthesis (``pole_bound`` of
:func:`ambseal.robust.lpv.lpvsyn`). The reference is python-control: the poles of the
controller at each entry of its table."""

from __future__ import annotations

import re
import tomllib
from pathlib import Path

import numpy as np
import pytest

from ambseal.config import parse_rig
from ambseal.design import design_spec
from ambseal.design.lpv_design import design_lpv, lpv_schedule

EXAMPLE = Path(__file__).resolve().parents[2] / "examples" / "flywheel.toml"
RATE_HZ = 10_000.0


def test_the_flywheels_lpv_at_10_khz_has_no_pole_above_nyquist():
    text, n = re.subn(r"(?m)^sample_rate_hz\s*=.*$", f"sample_rate_hz = {RATE_HZ}",
                      EXAMPLE.read_text(encoding="utf-8"))
    assert n == 1
    cfg = parse_rig(tomllib.loads(text))
    spec = design_spec(cfg)
    speeds, states, _ = lpv_schedule(cfg, spec)
    d = design_lpv(cfg, speeds_hz=speeds, states=states, allow_unstable=True, spec=spec)
    bound = d.pole_bound
    assert bound["reduced"] and bound["bound_hz"] == pytest.approx(RATE_HZ / 2)
    assert max(bound["above_hz"]) > RATE_HZ / 2, bound  # what the synthesis gave
    assert (f"(its {len(bound['above_hz'])} poles above the 5000 Hz Nyquist frequency "
            "removed)") in d.verdict
    for w in d.table_theta:
        poles = d.at(float(w)).poles()
        assert np.abs(poles).max() < np.pi * RATE_HZ, (w, np.abs(poles).max())
