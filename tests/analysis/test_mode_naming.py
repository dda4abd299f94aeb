"""A mode named by its kind (:mod:`ambseal.analysis.mode_naming`): closed-form shapes of a
rigid rotor and of a free–free beam, and the flywheel's gyroscopic modes against the
rigid rotor's bound on the nutation frequency."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from ambseal.analysis import closed_loop_modes, mode_kind, support_span_m
from ambseal.config import load_rig
from ambseal.design.recipes import design

Z = np.linspace(0.0, 1.0, 21)
SPAN = (0.1, 0.9)


def _circular(u: np.ndarray, forward: bool) -> np.ndarray:
    """X = u, Y = ∓j u: a circular whirl (x = u cos ωt, y = ±u sin ωt)."""
    return np.column_stack([u, (-1j if forward else 1j) * u])


def test_rigid_shapes_by_the_bearing_span():
    """Translation (cylindrical) and tilt about the span's middle (conical); a tilt about a
    point outside the span moves its ends in phase, a cylindrical mode of an overhung
    rotor; at speed a forward conical mode is the nutation, a backward one the precession;
    at standstill no whirl is named."""
    assert mode_kind(_circular(np.ones_like(Z), True), Z, SPAN, "forward", 100.0) == \
        "rigid cylindrical, forward whirl"
    tilt = _circular(Z - 0.5, False)
    assert mode_kind(tilt, Z, SPAN, "backward", 100.0) == \
        "rigid conical, backward whirl: the precession"
    assert mode_kind(_circular(Z - 0.5, True), Z, SPAN, "forward", 100.0) == \
        "rigid conical, forward whirl: the nutation"
    assert mode_kind(tilt, Z, SPAN, "backward", 0.0) == "rigid conical"
    assert mode_kind(_circular(Z + 0.5, True), Z, SPAN, "forward", 100.0) == \
        "rigid cylindrical, forward whirl"
    with pytest.raises(ValueError, match="does not move"):
        mode_kind(np.zeros((Z.size, 2)), Z, SPAN)


def test_a_free_free_beams_first_bending_mode_is_bending():
    """The first free–free Euler–Bernoulli mode, φ = cosh βz + cos βz − σ (sinh βz +
    sin βz) with βL = 4.7300, σ = 0.9825 (Blevins, Table 8-1), is bending; the same shape
    with a rigid translation ten times its size is a rigid mode with a bent shaft."""
    b, sigma = 4.7300, 0.9825
    phi = np.cosh(b * Z) + np.cos(b * Z) - sigma * (np.sinh(b * Z) + np.sin(b * Z))
    assert mode_kind(_circular(phi, True), Z, SPAN, "forward", 50.0) == \
        "bending, forward whirl"
    stiff = 10 * np.abs(phi).max() + phi
    assert mode_kind(_circular(stiff, True), Z, SPAN, "forward", 50.0).startswith(
        "rigid cylindrical")


def test_the_flywheels_nutation_lies_above_the_rigid_rotors_bound():
    """The flywheel's derived PID at 500 Hz: the mode named the nutation lies above
    Ω·Ip/It of the whole rotor (a rigid rotor's forward conical mode on positive tilt
    stiffness, It ω² − Ip Ω ω − k = 0: ω > Ω Ip/It; Genta 2005 §4.6) — Ip, It by hand
    from the rig file's disks and its hollow shaft about the centre of mass — and the one
    named the precession well below Ω."""
    rig = Path(__file__).resolve().parents[2] / "examples" / "flywheel.toml"
    cfg = load_rig(rig)
    sh = cfg.shaft[0]
    rho = cfg.materials[sh.material].rho
    ro, ri, L = sh.outer_diameter / 2, sh.inner_diameter / 2, sh.length
    m_s = rho * math.pi * (ro**2 - ri**2) * L
    parts = [(m_s, L / 2, m_s * (ro**2 + ri**2) / 2,
              m_s * (3 * (ro**2 + ri**2) + L**2) / 12)]
    parts += [(d.mass, d.position, d.Ip, d.Id) for d in cfg.disk]
    mass = sum(p[0] for p in parts)
    zg = sum(p[0] * p[1] for p in parts) / mass
    ip = sum(p[2] for p in parts)
    it = sum(p[3] + p[0] * (p[1] - zg) ** 2 for p in parts)
    assert ip / it == pytest.approx(1.18, abs=0.01)  # the rig file's stated ratio
    speed = 500.0
    m = closed_loop_modes(cfg, design(cfg, "pid").K, speed_hz=speed, max_hz=1500.0)
    names = [mode_kind(s, m.node_z_m, support_span_m(cfg), w, speed)
             for s, w in zip(m.shapes, m.whirl)]
    nut = [f for f, n in zip(m.frequency_hz, names) if n.endswith("the nutation")]
    pre = [f for f, n in zip(m.frequency_hz, names) if n.endswith("the precession")]
    assert nut and pre, names
    assert max(nut) > speed * ip / it
    assert min(pre) < 0.2 * speed
