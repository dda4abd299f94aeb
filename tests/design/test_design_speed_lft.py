"""The spin speed as a real LFT parameter of the design model
(:mod:`ambseal.design.speed_lft`), against the LPV model of the same rig."""

from __future__ import annotations

import tomllib
from pathlib import Path

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


def test_the_speed_range_model_keeps_each_whirl_pair_whole():
    """Reference: dense eigenvalues and eigenvectors of the example flywheel's state matrix
    (140 states) at standstill and at its 1 000 Hz design speed. There the 18 states below
    its 5 kHz cut-off end with a mode at 4.75 kHz whose orbit at the sensors whirls
    opposite to the next mode's, at 5.11 kHz, above the cut-off; at standstill the two are
    one repeated pair (equal |λ| to 1e-9) and no other mode lies between them. So 18 states
    keep one branch of a whirl pair, and the count of whole pairs is two states fewer;
    a count that splits nothing (16, or 20 with both branches) is kept."""
    import scipy.linalg as sla

    from ambseal.config import load_rig
    from ambseal.design import design_spec
    from ambseal.design.speed_lft import whole_pair_states
    from ambseal.model import build_system

    cfg = load_rig(Path(__file__).resolve().parents[2] / "examples" / "flywheel.toml")
    sp = design_spec(cfg)
    f0, cut = cfg.operating.speed_rpm / 60.0, sp.model_cutoff_hz

    def eig(f):
        s = build_system(cfg, speed_rpm=60.0 * f)
        lam, X = sla.eig(s.state_matrices()[0])
        order = np.argsort(np.abs(lam))
        return lam[order], s.Cq @ X[:s.n_dof, order]

    lam, Y = eig(f0)
    hz = np.abs(lam) / (2 * np.pi)
    assert f0 == 1000.0 and cut == 5000.0 and np.sum(hz < cut) == sp.model_states == 18
    kept, left = 17, 18  # the 18th state's mode, the first above the cut-off
    assert 4700 < hz[kept] < cut < hz[left] < 5200

    def whirl(k):  # the sign of the orbit's turning at the sensors, for Im λ > 0
        y = Y[:, k] if lam[k].imag > 0 else np.conj(Y[:, k])
        return np.sign(np.sum(np.imag(np.conj(y[0::2]) * y[1::2])))

    assert whirl(kept) == -whirl(left) != 0
    lam0, _ = eig(0.0)
    hz0 = np.abs(lam0) / (2 * np.pi)
    inside = hz0[(hz0 > hz[kept]) & (hz0 < hz[left])]
    assert inside.size == 4 and np.ptp(inside) < 1e-9 * inside[0]
    assert whole_pair_states(cfg, 18, pressure_bar=0.0) == 16
    assert whole_pair_states(cfg, 16, pressure_bar=0.0) == 16
    assert whole_pair_states(cfg, 20, pressure_bar=0.0) == 20


def test_the_speed_is_frozen_wherever_its_channels_lie():
    """:func:`at_speed` on a plant whose spin speed is its second LFT parameter (μ's plant:
    a seal coefficient first). Reference: the upper LFT ``P_oo + P_os δ (I − δ P_ss)⁻¹ P_so``
    of the plant's own frequency response (python-control, dense), at δ the speed's
    normalised value; the other parameter's channels stay, with their names."""
    from types import SimpleNamespace

    import control

    from ambseal.design.plant import UncertainParameter
    from ambseal.design.speed_lft import at_speed

    rng = np.random.default_rng(3)
    n, seal, spin, rest = 6, 2, 3, 2
    A = rng.standard_normal((n, n)) - 4 * n * np.eye(n)
    m = seal + spin + rest
    P = control.ss(A, rng.standard_normal((n, m)), rng.standard_normal((m, n)),
                   0.3 * rng.standard_normal((m, m)),
                   inputs=[f"w{i}" for i in range(m)], outputs=[f"z{i}" for i in range(m)])
    params = [UncertainParameter("seal.k", 1.0, 0.5, 1.5, seal),
              UncertainParameter(SPEED, 100.0, 0.0, 400.0, spin)]
    frozen = at_speed(SimpleNamespace(P=P, parameters=params), 300.0)
    d = params[1].delta(300.0)
    s_, o_ = np.arange(seal, seal + spin), np.r_[np.arange(seal), np.arange(seal + spin, m)]
    assert frozen.input_labels == [f"w{i}" for i in o_]
    for s in (0.5j, 3.0 + 40j, 700j):
        G = P(s)
        ref = G[np.ix_(o_, o_)] + G[np.ix_(o_, s_)] @ (
            d * np.linalg.solve(np.eye(spin) - d * G[np.ix_(s_, s_)], G[np.ix_(s_, o_)]))
        np.testing.assert_allclose(frozen(s), ref, rtol=1e-9, atol=1e-12)
    with pytest.raises(ModelError, match="outside the speed range"):
        at_speed(SimpleNamespace(P=P, parameters=params), 500.0)
