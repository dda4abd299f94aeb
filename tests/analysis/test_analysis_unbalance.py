"""Tests of ambseal.analysis.unbalance: ISO 21940-11 force and the σ̄·F response bound.

The force is checked against the definition F = m·e·Ω² with the permissible eccentricity
e = G/Ω_max of ISO 21940-11, evaluated by hand for a few rotors (values written out below, not
recomputed from the implementation's formula), and the response against a direct frequency
response of the closed loop built by python-control and against the rotordynamic limit of a
rotor spinning far above its resonances (orbit → eccentricity).
"""

from __future__ import annotations

import json

import control
import numpy as np
import pytest

from ambseal.analysis import loops, unbalance
from ambseal.errors import ModelError

from .amb_test_plants import mass_1dof, rigid_rotor

# (mass kg, grade mm/s, speed rad/s, eccentricity e = G/Ω in m, force m·e·Ω² in N), by hand:
HAND = [
    # P5 §4.4.1: G2.5, 69 kg, 500 Hz (Ω = 3141.593 rad/s): e = 2.5e-3/3141.593 = 0.7958 µm,
    # F = 69 · 0.7958e-6 · 3141.593² = 541.9 N ("541 N" in the thesis)
    (69.0, 2.5, 3141.593, 0.7958e-6, 541.9),
    # ISO 21940-11 chart: G2.5 at 3000 rpm (314.16 rad/s) permits e ≈ 8 µm (7.958 µm);
    # F = 1 kg · 7.958e-6 · 314.16² = 0.7854 N
    (1.0, 2.5, 314.16, 7.958e-6, 0.7854),
    # G6.3 at 1000 rad/s: e = 6.3 µm; 10 kg: F = 10 · 6.3e-6 · 1e6 = 63 N
    (10.0, 6.3, 1000.0, 6.3e-6, 63.0),
    # G1 at 100 rad/s: e = 10 µm; 2 kg: F = 2 · 1e-5 · 1e4 = 0.2 N
    (2.0, 1.0, 100.0, 10e-6, 0.2),
]


@pytest.mark.parametrize("m, grade, w, e, force", HAND)
def test_force_is_m_e_omega_squared_by_hand(m, grade, w, e, force):
    """Reference: ISO 21940-11 — permissible eccentricity e = G/Ω and F = m·e·Ω², with the
    hand values of HAND (P5 §4.4.1: 541 N for G2.5 on the 69 kg rotor at 500 Hz; the ISO
    chart's ≈ 8 µm for G2.5 at 3000 rpm)."""
    assert grade * 1e-3 / w == pytest.approx(e, rel=2e-4)  # the table itself is consistent
    assert float(unbalance.unbalance_force(m, grade, w, max_speed_rad_s=w)) == pytest.approx(
        force, rel=2e-4)
    # at Ω_max the constant-velocity option gives the same force
    assert float(unbalance.unbalance_force(m, grade, w, law="constant_velocity")) == \
        pytest.approx(force, rel=2e-4)


def test_thesis_rig_force_below_the_balance_speed():
    """Reference: P5 §4.4.1 — G2.5 at 500 Hz on the 69 kg rotor gives 541.9 N at 500 Hz;
    with the residual unbalance U = m·G/Ω_max fixed (ISO 21940-11) the force scales as Ω²:
    541.9·(200/500)² = 86.70 N at 200 Hz (2.5× less than m·G·Ω = 216.8 N) and
    541.9·(40/500)² = 3.468 N at 40 Hz (12.5× less than 43.35 N); hand values."""
    w = 2 * np.pi * np.array([500.0, 200.0, 40.0])
    F = unbalance.unbalance_force(69.0, 2.5, w, max_speed_rad_s=w[0])
    np.testing.assert_allclose(F, [541.9, 86.70, 3.468], rtol=2e-4)
    Fc = unbalance.unbalance_force(69.0, 2.5, w, law="constant_velocity")
    np.testing.assert_allclose(Fc, [541.9, 216.8, 43.35], rtol=2e-4)


def test_force_balanced_for_max_speed_by_hand():
    """Reference: ISO 21940-11 with the rotor balanced once for Ω_max = 1000 rad/s at G1:
    e = 1e-3/1000 = 1 µm fixed, so for 1 kg F = e·Ω² = 0, 0.25, 1 N at Ω = 0, 500, 1000
    rad/s (hand values); at Ω_max it equals the grade-at-every-speed force."""
    F = unbalance.unbalance_force(1.0, 1.0, [0.0, 500.0, 1000.0], max_speed_rad_s=1000.0)
    np.testing.assert_allclose(F, [0.0, 0.25, 1.0], rtol=1e-12)
    assert float(unbalance.unbalance_force(1.0, 1.0, 1000.0, law="constant_velocity")) == \
        pytest.approx(1.0, rel=1e-12)


@pytest.mark.parametrize("args", [(0.0, 2.5, 1.0), (69.0, -1.0, 1.0), (69.0, 2.5, -1.0),
                                  (69.0, float("nan"), 1.0)])
def test_force_rejects_bad_input(args):
    """Reference: ISO 21940-11 quantities are positive and finite; bad values raise
    ModelError."""
    with pytest.raises(ModelError):
        unbalance.unbalance_force(*args, max_speed_rad_s=1.0)


@pytest.mark.parametrize("kw, word", [({}, "max_speed_rad_s"), ({"max_speed_rad_s": 0.0}, "max_speed"),
                                      ({"law": "iso1940", "max_speed_rad_s": 1.0}, "law")])
def test_force_rejects_missing_speed_or_unknown_law(kw, word):
    """Reference: the ISO 21940-11 law needs the maximum service speed Ω_max > 0; an unknown
    law is refused, naming what was expected."""
    with pytest.raises(ModelError, match=word):
        unbalance.unbalance_force(69.0, 2.5, 1.0, **kw)


def test_response_siso_closed_form():
    """Reference: closed form for a SISO loop with the force at the actuator (Gf = G/ki):
    response = |G(jΩ)/(1 + G K)|/ki · F with G, K polynomials in jΩ and the hand force
    F = m·e·Ω², e = G/Ω (P5 §4.4.1, Fig. 12)."""
    G, K, (nG, dG), (nK, dK) = mass_1dof()
    ki = 100.0
    w = 2 * np.pi * np.linspace(1.0, 200.0, 300)
    r = unbalance.unbalance_response(G, K, G * (1.0 / ki), w, mass_kg=10.0, grade_mm_s=6.3,
                                     law="constant_velocity")
    s = 1j * w
    Gs = np.polyval(nG, s) / np.polyval(dG, s)
    Ks = np.polyval(nK, s) / np.polyval(dK, s)
    force = 10.0 * (6.3e-3 / w) * w**2
    ref = np.abs(Gs / ki / (1 + Gs * Ks)) * force
    np.testing.assert_allclose(r.response_m, ref, rtol=1e-8)
    np.testing.assert_allclose(r.force_n, force, rtol=1e-12)
    k = int(np.argmax(ref))
    assert r.peak_um == pytest.approx(ref[k] * 1e6, rel=1e-8)
    assert r.peak_speed_hz == pytest.approx(w[k] / (2 * np.pi), rel=1e-12)


def test_orbit_tends_to_eccentricity_above_resonances():
    """Reference: rotordynamics of a rigid rotor far above its resonances — it spins about
    its centre of mass, so the orbit equals the eccentricity (compliance 1/(mΩ²) times
    m·e·Ω²; the self-centring Jeffcott rotor, Genta 2005, Dynamics of Rotating Systems): the
    fixed e = G/Ω_max of the ISO law, G/Ω of the constant-velocity one. The 1-DOF axis with
    PD control (closed-loop poles below 200 Hz) at 5 and 10 kHz: orbit within 2 % of e."""
    G, K, _, _ = mass_1dof()
    w = 2 * np.pi * np.array([5000.0, 10000.0])
    r = unbalance.unbalance_response(G, K, G * (1.0 / 100.0), w, mass_kg=10.0, grade_mm_s=6.3,
                                     max_speed_rad_s=w[1])
    np.testing.assert_allclose(r.response_m, 6.3e-3 / w[1], rtol=0.02)
    r = unbalance.unbalance_response(G, K, G * (1.0 / 100.0), w, mass_kg=10.0, grade_mm_s=6.3,
                                     law="constant_velocity")
    np.testing.assert_allclose(r.response_m, 6.3e-3 / w, rtol=0.02)


def test_response_is_sigma_of_direct_frequency_response_times_force():
    """Reference: python-control side by side — the closed loop from the mid-span forces to
    the displacements built as feedback(I, G K)·Gf and evaluated by
    control.frequency_response; its largest singular value (numpy SVD) times the hand force
    m·(G/Ω_max)·Ω² (Ω_max = 2π·500 rad/s) is the worst-case orbit (P5 §4.4.1, Fig. 12). Rigid rotor on two AMBs with a
    cross-coupled seal; the result survives a JSON round trip."""
    G, Gf, K = rigid_rotor()
    w = 2 * np.pi * np.linspace(1.0, 200.0, 200)
    I4 = control.ss(np.zeros((0, 0)), np.zeros((0, 4)), np.zeros((4, 0)), np.eye(4))
    H = control.frequency_response(control.feedback(I4, G * K) * Gf, w, squeeze=False).complex
    sig = np.linalg.svd(np.moveaxis(H, 2, 0), compute_uv=False)[:, 0]
    wmax = 2 * np.pi * 500.0
    ref = sig * 69.0 * (2.5e-3 / wmax) * w**2
    r = unbalance.unbalance_from_compliance(loops.compliance(G, K, Gf, w), mass_kg=69.0,
                                            grade_mm_s=2.5, max_speed_rad_s=wmax)
    np.testing.assert_allclose(r.response_m, ref, rtol=1e-6)
    r2 = unbalance.unbalance_response(G, K, Gf, w, mass_kg=69.0, grade_mm_s=2.5,
                                      max_speed_rad_s=wmax)
    np.testing.assert_allclose(r2.response_m, ref, rtol=1e-6)
    d = json.loads(json.dumps(r.to_dict()))
    assert d["peak_um"] == pytest.approx(ref.max() * 1e6, rel=1e-6)
    assert d["peak_speed_hz"] == pytest.approx(w[np.argmax(ref)] / (2 * np.pi), rel=1e-9)
    assert d["law"] == "iso21940" and d["max_speed_hz"] == pytest.approx(500.0, rel=1e-12)
