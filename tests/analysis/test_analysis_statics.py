"""The rotor held at rest as the machine stands: one rigid rotor on two AMBs, horizontal,
vertical and inclined, against the hand statics of a rigid body on two supports (the
reactions by the moment about each support; the current from f = Ki·i + Ks·s at s = 0)."""

from __future__ import annotations

import json
import math
import tomllib

import pytest

from ambseal.analysis import rotor_at_rest
from ambseal.analysis.signoff.unbalance_api617 import journal_load_rule, journal_loads
from ambseal.cli import main
from ambseal.config import dump_rig, parse_rig
from ambseal.errors import ConfigError
from ambseal.report import statics_section

from ..rigid_rotor import D, L, RHO, rotor_text

G0 = 9.80665  # standard gravity, m/s² (ISO 80000-3)
Z_DISK, M_DISK = 0.3, 20.0
Z_A, Z_B = 0.05, 0.35
KI_A, KI_B = 100.0, 150.0


def _rig(machine: str = "", signoff: str = "") -> dict:
    """A stiff uniform shaft (L × D) with a 20 kg disk off centre, on AMB A (axes turned
    45°, Ki 100 N/A) and AMB B (Ki 150 N/A), neither at the centre of mass."""
    text = rotor_text("rigid rotor on two AMBs", M_DISK, 0.1, 0.05, 8, Z_DISK) + f"""
[[amb]]
name = "A"
position = {Z_A}
sensor_position = {Z_A}
axes_angle_deg = 45.0
ki = {KI_A}
ks = 2.0e5
[[amb]]
name = "B"
position = {Z_B}
sensor_position = {Z_B}
ki = {KI_B}
ks = 3.0e5
[machine]
{machine}
[signoff]
{signoff}
"""
    return tomllib.loads(text)


def _hand() -> tuple[float, float, float]:
    """(m, R_A, R_B): the mass, and the supports' reactions to the weight m·g₀ by the
    moment about the other support (R_A = m g₀ (z_B − z_G)/(z_B − z_A))."""
    ms = RHO * math.pi / 4 * D**2 * L
    m = ms + M_DISK
    zg = (ms * L / 2 + M_DISK * Z_DISK) / m
    ra = m * G0 * (Z_B - zg) / (Z_B - Z_A)
    return m, ra, m * G0 - ra


def _flat(loads) -> list[float]:
    return [x for pair in loads for x in pair]


def test_horizontal_rotor_on_two_ambs_is_the_hand_statics():
    """Horizontal: A pushes the rotor up with R_A, B with R_B; A's axes turned 45° share
    it, i_ζ = i_η = R_A sin 45°/Ki_A; B's η axis (vertical) alone, i_η = R_B/Ki_B. The
    journal loads W are R/g₀ (kg); nothing axial."""
    m, ra, rb = _hand()
    st = rotor_at_rest(parse_rig(_rig()))
    a, b = st.ambs
    assert a.force_n == pytest.approx((0.0, ra), abs=1e-9 * m * G0)
    assert b.force_n == pytest.approx((0.0, rb), abs=1e-9 * m * G0)
    s45 = math.sqrt(0.5)
    assert a.current_a == pytest.approx((ra * s45 / KI_A, ra * s45 / KI_A), rel=1e-9)
    assert b.current_a == pytest.approx((0.0, rb / KI_B), abs=1e-9 * rb / KI_B)
    assert st.mass_kg == pytest.approx(m, rel=1e-12)
    assert st.axial_weight_n == 0.0 and st.axial_note is None
    assert _flat(journal_loads(parse_rig(_rig()))) == pytest.approx(
        [Z_A, ra / G0, Z_B, rb / G0], rel=1e-9)


def test_vertical_rotor_radial_ambs_carry_no_weight():
    """Vertical: gravity along −z; the radial AMBs need no static current, the axial
    weight m·g₀ goes to a thrust bearing the statics name; the sign-off's W (API 617
    U_r = 6350·W/N) stays the rotor's weight apportioned as if horizontal — the same R/g₀
    as the horizontal rotor — and the report says so."""
    m, ra, rb = _hand()
    cfg = parse_rig(_rig('orientation = "vertical"'))
    st = rotor_at_rest(cfg)
    for amb in st.ambs:
        assert amb.force_n == (0.0, 0.0) and amb.current_a == (0.0, 0.0)
    assert st.axial_weight_n == pytest.approx(-m * G0, rel=1e-12)
    assert "thrust" in st.axial_note and f"{m * G0:.4g} N" in st.axial_note
    assert _flat(journal_loads(cfg)) == pytest.approx([Z_A, ra / G0, Z_B, rb / G0],
                                                      rel=1e-9)
    assert "as if it lay horizontal" in journal_load_rule(cfg)
    acting = parse_rig(_rig('orientation = "vertical"', 'journal_load = "as_acting"'))
    with pytest.raises(ConfigError, match="journal_load"):
        journal_loads(acting)


def test_inclined_rotor_splits_its_weight():
    """Inclined 30° (+z rising): the lateral part g₀ cos 30° on the AMBs (currents cos 30°
    of the horizontal ones), m g₀ sin 30° down the axis; with ``journal_load =
    "as_acting"`` the journal loads are cos 30° of the horizontal ones."""
    m, ra, rb = _hand()
    c = math.cos(math.radians(30.0))
    machine = 'orientation = "inclined"\ninclination_deg = 30.0'
    st = rotor_at_rest(parse_rig(_rig(machine)))
    assert st.ambs[1].current_a[1] == pytest.approx(c * rb / KI_B, rel=1e-9)
    assert st.ambs[0].current_a[0] == pytest.approx(c * ra * math.sqrt(0.5) / KI_A,
                                                    rel=1e-9)
    assert st.axial_weight_n == pytest.approx(-0.5 * m * G0, rel=1e-12)
    acting = parse_rig(_rig(machine, 'journal_load = "as_acting"'))
    assert _flat(journal_loads(acting)) == pytest.approx(
        [Z_A, c * ra / G0, Z_B, c * rb / G0], rel=1e-9)


def test_a_rotor_on_one_bearing_plane_is_not_held_statically():
    """One AMB alone (or two at one position) leaves the weight's moment free: no static
    position, so no loads and no currents, said as such (not a singular solve's noise)."""
    one = _rig()
    one["amb"] = one["amb"][:1]
    st = rotor_at_rest(parse_rig(one))
    assert not st.held and st.ambs == () and st.bearing_loads_n == ()
    both = rotor_at_rest(parse_rig(_rig()))
    assert both.held and len(both.bearing_loads_n) == 2


@pytest.mark.parametrize("machine", ['orientation = "inclined"',
                                     'orientation = "vertical"\ninclination_deg = 90.0',
                                     'orientation = "sideways"'])
def test_orientation_refusals_name_the_key(machine):
    """An inclination without ``inclined``, ``inclined`` without one, or an unknown
    orientation: one error naming the key."""
    with pytest.raises(ConfigError, match="orientation|inclination_deg"):
        parse_rig(_rig(machine))


def test_validate_and_the_report_show_the_orientation(tmp_path, capsys):
    """``ambseal validate`` and the run report's statics section state the orientation,
    the AMBs' static currents (0 A on a vertical rotor) and the thrust bearing outside
    the model that carries the weight m·g₀."""
    m, _, _ = _hand()
    rig = tmp_path / "vertical.toml"
    rig.write_text(dump_rig(parse_rig(_rig('orientation = "vertical"'))))
    assert main(["validate", str(rig)]) == 0
    text = capsys.readouterr().out
    assert "vertical machine: gravity (0, 0, -9.807) m/s²" in text
    assert "AMB A holds the rotor at rest with zeta 0 A, eta 0 A" in text
    assert f"axis, {m * G0:.4g} N, is carried by an axial (thrust) bearing" in text
    assert main(["validate", str(rig), "--json"]) == 0
    st = json.loads(capsys.readouterr().out)["statics"]
    assert st["axial_weight_n"] == pytest.approx(-m * G0, rel=1e-12)
    section = statics_section(st)
    assert "A vertical machine" in section["html"] and "thrust" in section["html"]
