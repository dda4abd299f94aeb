"""The derived PID's integral on a gyroscopic rotor (design.pid.pid_from_rig): the
precession of the rigid rotor on its AMBs against its closed form, and the flywheel's
precession kept by the integral time set on it."""

from __future__ import annotations

import math
import tomllib
from pathlib import Path

import numpy as np
import pytest

from ambseal.config import load_rig, parse_rig
from ambseal.design.pid import (
    K_EQ_PER_KS,
    TI_PER_OMEGA_N,
    gyroscopic_cancellation,
    pid_from_rig,
    pid_of,
    precession_rad_s,
)
from ambseal.lti import feedback_matrices
from ambseal.model import channel_names
from ambseal.model.rig import build_plant

from ..rigid_rotor import L, inertia, rotor_text

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"
DISK_M, DISK_IP, DISK_ID = 20.0, 0.9, 0.5
K_SPRING = 1.0e5


def _rigid_rig():
    text = rotor_text("disc-like rigid rotor", DISK_M, DISK_IP, DISK_ID, 4)
    for name, z in (("A", 0.0), ("B", L)):
        text += (f'[[amb]]\nname = "{name}"\nposition = {z}\nsensor_position = {z}\n'
                 "ki = 100.0\nks = 2.0e5\nbias_current = 5.0\ncurrent_limit = 10.0\n")
    return parse_rig(tomllib.loads(text))


@pytest.mark.parametrize("speed_hz", [0.0, 50.0, 300.0, 1000.0])
def test_precession_is_the_rigid_rotors_closed_form(speed_hz):
    """Symmetric rotor, centre of mass at mid-span, springs k at ±l = ±L/2: the conical
    modes solve I_t ω² ∓ I_p Ω ω − 2 k l² = 0, the cylindrical ones ω² = 2k/m (Genta,
    *Dynamics of Rotating Systems*, 2005, §4.6); the lowest is the backward conical root
    (−I_p Ω + √((I_p Ω)² + 8 I_t k l²))/(2 I_t) once it is below √(2k/m)."""
    m, it, ip = inertia(DISK_M, DISK_IP, DISK_ID)
    W, l = 2 * math.pi * speed_hz, L / 2
    backward = (-ip * W + math.sqrt((ip * W) ** 2 + 8 * it * K_SPRING * l**2)) / (2 * it)
    want = min(backward, math.sqrt(2 * K_SPRING / m))
    got = precession_rad_s(_rigid_rig(), K_SPRING, W)
    assert got == pytest.approx(want, rel=1e-9)


def _loop_poles(cfg, p: dict, speed_hz: float) -> np.ndarray:
    """The poles of the continuous loop (no delay) of the full-order plant at
    ``speed_hz`` with the PID ``p``."""
    pl = build_plant(cfg, speed_rpm=60.0 * speed_hz)
    cur = pl.current_inputs()
    K = pid_of(p, channel_names(cfg))
    mats = ((pl.A, pl.B[:, cur], pl.C, pl.D[:, cur]),
            tuple(np.asarray(X, float) for X in (K.A, K.B, K.C, K.D)))
    return np.linalg.eigvals(feedback_matrices(*mats)[0])


def _oscillating_poles(cfg, p: dict, speed_hz: float) -> np.ndarray:
    """The loop's poles with 1 < ω < 2π·500 rad/s, upper half."""
    lam = _loop_poles(cfg, p, speed_hz)
    return np.sort_complex(lam[(lam.imag > 1) & (np.abs(lam) < 2 * math.pi * 500)])


def test_the_gyroscopic_cancellation_removes_the_conical_split():
    """I_p/(K_i Σ l²) of the symmetric rigid rotor (AMBs at ±L/2 from its centre of mass)
    by hand to 1e-9; and a PD with that cross-axis derivative times −Ω on each bearing
    cancels the gyroscopic moments of the tilt (Brown et al., NASA/TM-2006-214027): at
    200 Hz the conical pair is back at its standstill frequency (97.09 rad/s) within 1e-4
    — the derivative filter's lag is the rest — where without it the rotor's gyroscopics
    split it by an order of magnitude."""
    cfg = _rigid_rig()
    _, _, ip = inertia(DISK_M, DISK_IP, DISK_ID)
    g = gyroscopic_cancellation(cfg)
    assert g == pytest.approx(ip / (100.0 * 2 * (L / 2) ** 2), rel=1e-9)
    pd = {"kp": 3000.0, "ti": 1e6, "td": 5e-4, "eps": 1e-3}
    still = _oscillating_poles(cfg, pd, 0.0)
    assert still.size == 4  # the cylindrical and the conical pair, x and y alike
    W = 2 * math.pi * 200.0
    cancelled = _oscillating_poles(cfg, dict(pd, cross_kd=-g * W), 200.0)
    conical = cancelled[np.abs(cancelled.imag - still.imag.max()) < 1.0]
    assert conical.size == 2
    np.testing.assert_allclose(conical.imag, still.imag.max(), rtol=1e-4)
    free = _oscillating_poles(cfg, pd, 200.0)
    assert not np.any(np.abs(free.imag - still.imag.max()) < 1.0)


@pytest.fixture(scope="module")
def flywheel():
    cfg = load_rig(EXAMPLES / "flywheel.toml")
    return cfg, pid_from_rig(cfg)


def _low_poles(cfg, p: dict, speed_hz: float) -> np.ndarray:
    """The loop's poles below 20 Hz."""
    lam = _loop_poles(cfg, p, speed_hz)
    return lam[np.abs(lam) < 2 * math.pi * 20.0]


def test_the_flywheels_integral_keeps_its_precession(flywheel):
    """At 333 Hz the flywheel's precession is near 2 Hz: with Ti = 50/ω_n (ω_n the rigid
    mode at standstill) the integral gives it negative damping; Ti = 50/ω_p, ω_p the
    precession at the top speed, keeps every pole below 20 Hz in the left half-plane."""
    cfg, p = flywheel
    ks = cfg.amb[0].ks
    w_p = precession_rad_s(cfg, K_EQ_PER_KS * ks, 2 * math.pi * 1000.0)
    assert p["ti"] == pytest.approx(TI_PER_OMEGA_N / w_p, rel=1e-12)
    assert "the precession" in p["rule"]
    # no cross gains derived; the rule names the cancellation's scale at the top speed
    assert not p.get("cross_kd") and not p.get("cross_kp")
    full = 2 * math.pi * 1000.0 * gyroscopic_cancellation(cfg)
    assert f"no cross-axis gains (the gyroscopic cancellation Ω I_p/(K_i Σ l²) is {full:.4g}" \
        in p["rule"]
    assert _low_poles(cfg, p, 333.33).real.max() < 0
    m_b = sum(d.mass for d in cfg.disk) / 2  # a lower bound of half the rotor's mass
    w_n = math.sqrt(K_EQ_PER_KS * ks / m_b)
    old = dict(p, ti=TI_PER_OMEGA_N / w_n)
    assert _low_poles(cfg, old, 333.33).real.max() > 0


def test_the_flywheels_corner_holds_its_loop_as_designed(flywheel):
    """No corner keeps the flywheel's bending modes damped as it runs at its top speed; the
    one chosen is then the best that holds the loop as designed (continuous, no delay) at
    standstill and the top speed — not f_s/14, which loses its 2.4 kHz bending mode
    designed and so counted nothing."""
    cfg, p = flywheel
    assert p["corner_hz"] == pytest.approx(2000.0)
    for f in (0.0, 1000.0):
        assert _loop_poles(cfg, p, f).real.max() < 0, f
