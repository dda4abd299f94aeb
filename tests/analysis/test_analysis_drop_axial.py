"""The rotor drop along its axis (ambseal.analysis.drop): the thrust bearing lets go with
the AMBs and the residual thrust drives the rotor onto a touchdown bearing's axial stop —
the first axial impact against the exact energy balance and the time of the fall, energy
kept with the thrust's work, a ring spun up by the face's friction and the heat that
costs, and the verdict by ISO 76's static equivalent load and the ring's temperature
rise."""

from __future__ import annotations

import math
import tomllib

import numpy as np
import pytest
from scipy.optimize import brentq

from ambseal.analysis.drop import GRAVITY, drop_verdict, journal_radius, simulate_drop
from ambseal.config import parse_rig
from ambseal.errors import ConfigError

from ..rigid_rotor import L, inertia, rotor_text

DISK = (20.0, 0.05, 0.1)
C_TD = 2.0e-4  # radial clearance (m)
C_AX = 1.0e-4  # axial clearance of the stopping plane (m)
K_TD = 5.0e9  # N/m^1.5, radial
K_AX = 5.0e10  # N/m^1.5, the stop's axial contact
THRUST = 3000.0  # N, towards +z: onto TB's stop


def _rig(stop: str = "", kind: str = "angular_contact_pair", drop: str = "") -> object:
    text = rotor_text("rigid rotor with an axial stop", *DISK, 4)
    for name, z in (("A", 0.1), ("B", L - 0.1)):
        text += (f'[[amb]]\nname = "{name}"\nposition = {z}\nsensor_position = {z}\n'
                 "ki = 100.0\nks = 2.0e5\nbias_current = 5.0\ncurrent_limit = 10.0\n")
    for name, z, axial in (("TA", 0.0, ""),
                           ("TB", L, f"axial_clearance = {C_AX}\n"
                                     f"axial_contact_stiffness = {K_AX}\n{stop}")):
        text += (f'[[touchdown]]\nname = "{name}"\nposition = {z}\nkind = "{kind}"\n'
                 f"radial_clearance = {C_TD}\ncontact = \"point\"\n"
                 f"contact_stiffness = {K_TD}\nrestitution = 1.0\nfriction = 0.0\n{axial}")
    text += f"[drop]\naxial_thrust = {THRUST}\n{drop}"
    return parse_rig(tomllib.loads(text))


def test_the_first_axial_impact_is_the_energy_balance():
    """Undamped, the thrust F drives the rotor (mass m) through the axial clearance c_a
    in √(2 m c_a/F) and into the stop (its own K) until (2/5)·K·δ^{5/2} = F·(c_a + δ):
    the time of
    contact, the deepest penetration and the peak force K·δ^{3/2} within 1 %; the other
    plane, without an axial clearance, takes no axial force."""
    cfg = _rig()
    m = inertia(*DISK)[0]
    delta = brentq(lambda d: 0.4 * K_AX * d**2.5 - THRUST * (C_AX + d), 0.0, 1e-2)
    t_fall = math.sqrt(2 * m * C_AX / THRUST)
    r = simulate_drop(cfg, duration_s=3 * t_fall, samples=20001)
    d = r.to_dict()
    tb = d["planes"][1]
    assert tb["max_axial_penetration_m"] == pytest.approx(delta, rel=0.01)
    assert tb["peak_axial_force_n"] == pytest.approx(K_AX * delta**1.5, rel=0.01)
    onset = r.t[np.argmax(r.axial_force[1] > 0)]
    assert onset == pytest.approx(t_fall, rel=0.01)
    assert d["planes"][0]["peak_axial_force_n"] == 0.0
    assert d["max_axial_m"] == pytest.approx(C_AX + delta, rel=0.01)
    assert d["axial_thrust_n"] == THRUST
    # one axis lost: the thrust bearing holds, nothing moves axially
    held = simulate_drop(cfg, duration_s=0.002, samples=101, failed=r.channels[:1])
    assert held.axial_position is None and held.to_dict()["max_axial_m"] is None
    assert not held.peak_axial_force.any()


def test_energy_with_the_thrust_is_kept_without_damping_or_friction():
    """Spinning, undamped, frictionless: the energy (with the axial motion's and the
    stop's stored energy) less the work of the thrust (and the AMBs' decaying forces)
    stays within 1e-4 of the energy put in, m·g·c + F·c_a, through the radial and axial
    bounces."""
    cfg = _rig()
    m = inertia(*DISK)[0]
    r = simulate_drop(cfg, speed_rpm=3000.0, duration_s=0.03, samples=3001, rtol=1e-10)
    assert (r.axial_force[1] > 0).any() and r.impacts >= 4
    scale = m * GRAVITY * C_TD + THRUST * C_AX
    assert np.abs(r.energy - r.energy[0] - r.work).max() < 1e-4 * scale
    assert r.work[-1] > 0.5 * THRUST * C_AX  # the thrust's work is counted


def test_the_face_spins_the_ring_up_and_the_heat_is_its_kinetic_energy():
    """The rotor at 6000 rpm, held by its drive, settles on the stop (e = 0.3) before it
    reaches the rings radially (1 mm radial clearance): the face's friction spins the
    ring (inertia J) up to the spin, ω_r → Ω, and a slipping contact at a held speed
    dissipates what it gives the ring, ½·J·Ω², within 2 %; with the ring's mass that
    heat is its temperature rise, graded against ``[drop] race_temperature_rise``."""
    J, mu, W = 2e-5, 0.2, 2 * math.pi * 100.0
    cfg = _rig(f"race_inertia = {J}\nrace_mass = 0.1\n", drop="race_temperature_rise = 5.0\n")
    cfg = cfg.model_copy(update={"touchdown": [
        t.model_copy(update={"radial_clearance": 1e-3, "restitution": 0.3, "friction": mu})
        for t in cfg.touchdown]})
    R_r = journal_radius(cfg, L) + 1e-3
    t_spin = J * W / (mu * THRUST * R_r)
    t_fall = math.sqrt(2 * inertia(*DISK)[0] * C_AX / THRUST)
    r = simulate_drop(cfg, speed_rpm=6000.0, duration_s=t_fall + 5 * t_spin, samples=4001)
    assert (r.force == 0).all()  # no radial contact
    assert r.race_speed[1, -1] == pytest.approx(W, rel=1e-3)
    heat = 0.5 * J * W**2
    assert r.friction_heat[1, -1] == pytest.approx(heat, rel=0.02)
    assert r.friction_heat[0, -1] == 0.0
    rise = heat / (0.1 * 475.0)
    row = {c["name"]: c for c in drop_verdict(cfg, r)["criteria"]}
    assert row["ring temperature rise at TB"]["value"].startswith(f"{rise:.3g} K")
    assert row["ring temperature rise at TB"]["outcome"] == ("passed" if rise <= 5 else
                                                              "FAILED")
    assert "ring temperature rise at TA" not in row  # no race_mass


@pytest.mark.parametrize("kind, factors", [("deep_groove", (0.6, 0.5)),
                                           ("angular_contact_pair", (1.0, 0.52)),
                                           ("full_complement", None)])
def test_the_peak_force_is_graded_as_iso_76s_static_equivalent_load(kind, factors):
    """Where a plane stopped the rotor axially, its peak force is ISO 76's static
    equivalent load P₀ = max(F_r, X₀F_r + Y₀F_a) with the kind's X₀, Y₀ (0.6, 0.5 deep
    groove; 1, 0.52 a 40° angular-contact pair) against C₀; a kind without them leaves
    it not graded, saying why."""
    cfg = _rig(kind=kind)
    t_fall = math.sqrt(2 * C_TD / GRAVITY)
    r = simulate_drop(cfg, duration_s=1.2 * t_fall, samples=4001)
    f_r, f_a = float(r.peak_force[1]), float(r.peak_axial_force[1])
    assert f_r > 0 and f_a > 0
    c0 = 3 * f_a
    rated = cfg.model_copy(update={"touchdown": [t.model_copy(update={"static_rating": c0})
                                                 for t in cfg.touchdown]})
    row = {c["name"]: c for c in drop_verdict(rated, r)["criteria"]}["peak force at TB"]
    if factors is None:
        assert row["outcome"] == "not graded"
        assert "no static_factors" in row["limit"]
        given = rated.model_copy(update={"touchdown": [
            t.model_copy(update={"static_factors": (1.0, 0.44)}) for t in rated.touchdown]})
        row = {c["name"]: c for c in drop_verdict(given, r)["criteria"]}["peak force at TB"]
        factors = (1.0, 0.44)
    p0 = max(f_r, factors[0] * f_r + factors[1] * f_a)
    assert f"P₀ = {p0:.4g} N" in row["value"]
    assert row["outcome"] == ("passed" if p0 <= c0 else "FAILED")


def test_the_axial_keys_are_checked():
    """An axial contact stiffness without the clearance it closes at, and X₀, Y₀ out of
    range, are refused naming the key; a thrust that is not finite, by the drop."""
    with pytest.raises(ValueError, match="axial_contact_stiffness"):
        _rig().touchdown[0].model_validate(
            {**_rig().touchdown[0].model_dump(), "axial_contact_stiffness": 1e9})
    with pytest.raises(ValueError, match="static_factors"):
        _rig("static_factors = [0.6, -0.5]\n")
    with pytest.raises(ConfigError, match="axial thrust"):
        simulate_drop(_rig(), duration_s=1e-3, samples=11, axial_thrust=float("nan"))
