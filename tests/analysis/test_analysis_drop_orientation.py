"""The drop as the machine stands (ambseal.analysis.drop, ``[machine] orientation``): a
standing rotor falls along its axis onto its axial touchdown face and not onto its radial
rings; lying, it falls onto its rings; inclined, its AMBs hold the lateral part
of its weight as the statics share it."""

from __future__ import annotations

import math
import tomllib

import numpy as np
import pytest
from scipy.optimize import brentq

from ambseal.analysis.drop import GRAVITY, drop_model, drop_verdict, simulate_drop
from ambseal.analysis.statics import rotor_at_rest
from ambseal.config import parse_rig

from ..rigid_rotor import L, inertia, rotor_text

DISK = (20.0, 0.05, 0.1)
C_TD = 2.0e-4  # radial clearance (m)
C_AX = 1.0e-4  # the lower plane's axial clearance (m)
K_TD = 5.0e9  # N/m^1.5, radial (Hertz point contact)
K_AX = 5.0e10  # N/m^1.5, the lower plane's axial contact


def _rig(machine: str) -> object:
    """The rigid rotor of the axial drop tests (a shaft 1e4 times stiffer than steel) on
    two AMBs, its lower touchdown plane TA (z = 0, where a standing rotor's positions
    start) stopping it axially; undamped (restitution 1) and frictionless, no thrust."""
    text = rotor_text("rigid rotor standing on its axial touchdown face", *DISK, 4)
    for name, z in (("A", 0.1), ("B", L - 0.1)):
        text += (f'[[amb]]\nname = "{name}"\nposition = {z}\nsensor_position = {z}\n'
                 "ki = 100.0\nks = 2.0e5\nbias_current = 5.0\ncurrent_limit = 10.0\n")
    for name, z, axial in (("TA", 0.0, f"axial_clearance = {C_AX}\n"
                                       f"axial_contact_stiffness = {K_AX}\n"),
                           ("TB", L, "")):
        text += (f'[[touchdown]]\nname = "{name}"\nposition = {z}\n'
                 'kind = "angular_contact_pair"\n'
                 f"radial_clearance = {C_TD}\ncontact = \"point\"\n"
                 f"contact_stiffness = {K_TD}\nrestitution = 1.0\nfriction = 0.0\n{axial}")
    return parse_rig(tomllib.loads(text + f"[drop]\naxial_thrust = 0.0\n[machine]\n{machine}"))


def test_a_standing_rotor_lands_on_its_axial_face_only():
    """Vertical, at standstill, without unbalance or thrust: the weight m·g falls the
    rotor through the axial clearance c_a onto TA's face (the Hertz point contact
    F = K·δ^{3/2} of its ``axial_contact_stiffness``). Undamped (restitution 1: the law's
    damping factor is 0, so the first impact's peak is the energy balance's exactly), the
    deepest penetration solves (2/5)·K·δ^{5/2} = m·g·(c_a + δ) — the contact's stored
    energy against the weight's work through the fall and the penetration — and the peak
    force is K·δ^{3/2}: both within 1 %, the onset at the free fall's √(2 c_a/g). Nothing
    pulls the rotor across its axis: no radial force at all, no AMB force. Lying
    horizontal (today's drop) it reaches no axial face and falls onto its rings."""
    cfg = _rig('orientation = "vertical"\n')
    m = inertia(*DISK)[0]
    delta = brentq(lambda d: 0.4 * K_AX * d**2.5 - m * GRAVITY * (C_AX + d), 0.0, 1e-2)
    t_fall = math.sqrt(2 * C_AX / GRAVITY)
    r = simulate_drop(cfg, duration_s=1.5 * t_fall, samples=4001)
    d = r.to_dict()
    ta = d["planes"][0]
    assert ta["max_axial_penetration_m"] == pytest.approx(delta, rel=0.01)
    assert ta["peak_axial_force_n"] == pytest.approx(K_AX * delta**1.5, rel=0.01)
    assert r.t[np.argmax(r.axial_force[0] > 0)] == pytest.approx(t_fall, rel=0.01)
    assert d["max_axial_m"] == pytest.approx(C_AX + delta, rel=0.01)
    assert (r.force == 0).all() and (r.peak_force == 0).all()
    assert d["planes"][1]["peak_axial_force_n"] == 0.0
    assert d["orientation"] == "vertical"
    assert d["axial_weight_n"] == pytest.approx(-m * GRAVITY, rel=1e-9)
    line = drop_verdict(cfg, r)["orientation_note"]
    assert line.startswith("vertical machine") and "axial touchdown face" in line
    lying = simulate_drop(_rig(""), duration_s=1.5 * math.sqrt(2 * C_TD / GRAVITY),
                          samples=2001)
    assert (lying.peak_force > 0).all() and not lying.peak_axial_force.any()
    assert drop_verdict(_rig(""), lying)["orientation_note"].startswith("horizontal machine")


def test_a_standing_rotors_energy_counts_its_axial_weight():
    """Vertical and spinning, undamped and frictionless: the energy (the axial weight's
    potential −m·g_z·z with the motion's and the face's stored energy) less the work from
    outside stays within 1e-4 of m·g·c_a through the axial bounces."""
    cfg = _rig('orientation = "vertical"\n')
    m = inertia(*DISK)[0]
    r = simulate_drop(cfg, speed_rpm=3000.0, duration_s=0.02, samples=2001, rtol=1e-10)
    assert (r.axial_force[0] > 0).any()
    assert np.abs(r.energy - r.energy[0] - r.work).max() < 1e-4 * m * GRAVITY * C_AX


@pytest.mark.parametrize("theta", [30.0, -60.0])
def test_an_inclined_rotors_amb_forces_are_the_statics(theta):
    """Inclined at θ: the levitated AMBs hold the weight's lateral part as the statics
    share it (:func:`ambseal.analysis.statics.rotor_at_rest`) — by hand, on the symmetric
    rotor, m·g·cos θ / 2 each along +y — and the axial weight m·g·sin θ acts along −z."""
    cfg = _rig(f'orientation = "inclined"\ninclination_deg = {theta}\n')
    m = inertia(*DISK)[0]
    dm = drop_model(cfg)
    st = rotor_at_rest(cfg)
    assert dm.amb_force == pytest.approx(np.array([a.force_n for a in st.ambs]), rel=1e-9)
    assert dm.amb_force[:, 1] == pytest.approx(
        [0.5 * m * GRAVITY * math.cos(math.radians(theta))] * 2, rel=1e-6)
    assert dm.amb_force[:, 0] == pytest.approx([0.0, 0.0], abs=1e-9 * m * GRAVITY)
    assert dm.axial_weight == pytest.approx(-m * GRAVITY * math.sin(math.radians(theta)),
                                            rel=1e-9)
