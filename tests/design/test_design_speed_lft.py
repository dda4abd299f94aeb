"""The spin speed as a real LFT parameter of the design model
(:mod:`ambseal.design.speed_lft`), against the LPV model of the same rig."""

from __future__ import annotations

import tomllib

import numpy as np
import pytest

from ambseal.config import parse_rig
from ambseal.design.lpv_plant import lpv_plant
from ambseal.design.speed_lft import SPEED, with_speed
from ambseal.errors import ModelError
from ambseal.model import build_plant

from ..rigid_rotor import L, rotor_text


def _rig():
    """A rigid rotor, disk Ip/It 0.79, on two AMBs (their negative stiffness: the open
    loop's rigid modes are real pairs ±, the conical ones split by the spin)."""
    text = rotor_text("rigid gyroscopic rotor", 20.0, 0.4, 0.2, 4, modal_damping=0.01)
    for name, z in (("A", 0.05), ("B", L - 0.05)):
        text += (f'[[amb]]\nname = "{name}"\nposition = {z}\nsensor_position = {z}\n'
                 "ki = 200.0\nks = 1.0e6\n")
    text += "[operating]\nspeed_rpm = 24000.0\n"
    return parse_rig(tomllib.loads(text))


def test_the_speed_channel_gives_the_lpv_model_at_every_speed_of_the_range():
    """Reference: the LPV model of the same rig (:func:`ambseal.design.lpv_plant.lpv_plant`,
    thesis P3 Eqs. 4–10: its own reduction at the design speed, the gyroscopic term
    −M⁻¹G projected once, no rebuilt plant, no factorisation). Closing the speed channel of
    the 8-state design model, built at 400 Hz, at Ω gives that model's eigenvalues to
    1e-8 relative from standstill to 400 Hz and beyond (the channel is affine in Ω, exact
    where the rotor has no tabulated seal); its rank is that of the projected gyroscopic
    term: 2, the conical pair."""
    cfg = _rig()
    plant = build_plant(cfg, reduced=True, states=8)
    with_, ranges = with_speed(plant, cfg, range_hz=(0.0, 400.0), states=8,
                               pressure_bar=0.0)
    assert ranges == {SPEED: (0.0, pytest.approx(2 * np.pi * 400.0))}
    par = with_.parameter(SPEED)
    assert par.unit == "rad/s" and par.nominal == pytest.approx(2 * np.pi * 400.0)
    assert par.repeats == 2
    lpv = lpv_plant(cfg, [0.0, 600.0], reference_speed_hz=400.0, states=8)
    for f in (0.0, 130.0, 400.0, 600.0):
        lam = np.sort_complex(np.linalg.eigvals(with_.with_values({SPEED: 2 * np.pi * f}).A))
        ref = np.sort_complex(np.linalg.eigvals(lpv.A_at(2 * np.pi * f)))
        np.testing.assert_allclose(lam, ref, rtol=1e-8, atol=1e-8 * np.abs(ref).max())
    # the conical pair does move with speed: the channel is not a no-op
    lo, hi = (np.sort_complex(np.linalg.eigvals(with_.with_values({SPEED: w}).A))
              for w in (0.0, 2 * np.pi * 400.0))
    assert np.max(np.abs(hi - lo)) > 10.0


def test_a_plant_built_otherwise_is_refused():
    """The channel is projected with the rig's own reduction: a plant in another basis (a
    reduction at another speed) is refused, not given a wrong channel."""
    cfg = _rig()
    other = build_plant(cfg, reduced=True, states=8, speed_rpm=6000.0)
    with pytest.raises(ModelError, match="not the rig's modal reduction"):
        with_speed(other, cfg, range_hz=(0.0, 400.0), states=8, pressure_bar=0.0)
    with pytest.raises(ModelError, match="expected 0 ≤ low < high"):
        with_speed(build_plant(cfg, reduced=True, states=8), cfg, range_hz=(400.0, 0.0),
                   states=8, pressure_bar=0.0)
