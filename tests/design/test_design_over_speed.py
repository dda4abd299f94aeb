"""H∞ over the speed range on a gyroscopic rotor nobody tuned, of the class
``benchmarks/bench_family.py`` generates (``tests/data/gyro_wheel_rig.toml``, Ip/It
0.54): designed at
the top speed it leans on the gyroscopic stiffening of its conical mode and loses it at
standstill; the rule (:func:`ambseal.design.recipes.design`) designs it again from
standstill up and keeps the first design that holds every judged speed."""

from __future__ import annotations

from pathlib import Path

import control
import numpy as np
import pytest

from ambseal.config import load_rig
from ambseal.design import design, design_spec
from ambseal.model import build_plant

FAMILY_RIG = Path(__file__).resolve().parents[1] / "data" / "gyro_wheel_rig.toml"


def _held_as_it_runs(cfg, K, speeds_hz) -> list[bool]:
    """python-control: per speed, the full-order plant sampled by its hold, the controller
    by Tustin with the target's delay, closed ``i = −K y``: every pole inside the unit
    circle."""
    T, d = 1 / cfg.controller.sample_rate_hz, cfg.controller.delay_samples
    Kd = control.sample_system(control.ss(K.A, K.B, K.C, K.D), T, "tustin") \
        * control.ss([], [], [], np.eye(K.noutputs), T) * control.tf([1], [1] + [0] * d, T)
    out = []
    for f in speeds_hz:
        pl = build_plant(cfg, speed_rpm=60.0 * f)
        cur = pl.current_inputs()
        G = control.ss(pl.A, pl.B[:, cur], pl.C, pl.D[:, cur])
        Gd = control.sample_system(G, T, "zoh")
        out.append(bool(np.abs(control.feedback(Gd, Kd).poles()).max() < 1))
    return out


def test_hinf_designed_over_the_speed_range_holds_from_standstill_to_the_top_speed():
    """Reference: python-control's poles of the sampled, delayed loop on the full-order
    plant at every stability speed (standstill to the top speed). The one-speed design
    (``[design] one_speed``) at the top speed loses the rotor at standstill; the design the
    rule delivers holds at every one of those speeds, and its steps name the speed it was
    designed at."""
    one = load_rig(FAMILY_RIG, ("design.one_speed=true",))
    speeds = design_spec(one).stability_speeds_hz
    assert speeds[0] == 0.0 and speeds[-1] == pytest.approx(one.operating.speed_rpm / 60)
    frozen = design(one, "hinf", allow_unstable=True)
    assert not frozen.full_order["stable"] and frozen.full_order["speed_hz"] == 0.0
    assert not _held_as_it_runs(one, frozen.K, [0.0])[0]
    cfg = load_rig(FAMILY_RIG)
    held = design(cfg, "hinf")
    assert all(_held_as_it_runs(cfg, held.K, speeds))
    assert frozen.design_speed_hz is None and held.design_speed_hz in speeds[:-1]
    assert f"hinf: designed at {held.design_speed_hz:g} Hz" in held.steps[-1]
