"""API 617 Level I screening (:mod:`ambseal.analysis.signoff.level1`) against hand calculations and
the closed form of a rigid rotor on damped isotropic supports."""

from __future__ import annotations

import math
from types import SimpleNamespace

import numpy as np
import pytest

from ambseal.analysis.signoff.level1 import level1_screening, stage_cross_coupling
from ambseal.config import parse_rig
from ambseal.design.pid import pid_controller
from ambseal.errors import ConfigError
from ambseal.model import channel_names
from ambseal.robust import discrete_controller
from ambseal.robust.digital import DigitalController

from ..rigid_rotor import L

#: N/m per klbf/in: 1000 lbf (4448.2216 N) per inch (0.0254 m)
KLBF_PER_IN = 4448.2216152605 / 0.0254
HP = 745.69987158227  # W per mechanical horsepower
INCH = 0.0254


def test_anticipated_cross_coupling_by_hand_in_both_unit_systems():
    """A 1 MW compressor impeller at 10 000 rpm, D_c = 400 mm, H_c = 20 mm, density ratio
    1.5: by hand q_A = 3·(1e6/(2π·10000/60))·1.5/(0.4·0.02) = 5.3715e5 N/m; the US form
    HP·B·C·(ρ_d/ρ_s)/(D_c·H_c·N) with C = 63 (klbf/in) gives it to the 0.04 % of 63 against
    63 025/1000. A turbine stage (B = 1.5, no density ratio) is a third of it here."""
    st = SimpleNamespace(power=1e6, impeller_diameter=0.4, discharge_width=0.02,
                         suction_density=20.0, discharge_density=30.0)
    w = 2 * math.pi * 10000 / 60
    q = stage_cross_coupling(st, "compressor", w)
    assert q == pytest.approx(3 * (1e6 / w) * 1.5 / (0.4 * 0.02), rel=1e-12)
    assert q == pytest.approx(5.3715e5, rel=1e-4)
    us = (1e6 / HP) * 3 * 63 * 1.5 / ((0.4 / INCH) * (0.02 / INCH) * 10000)  # klbf/in
    assert q == pytest.approx(us * KLBF_PER_IN, rel=1e-3)
    assert stage_cross_coupling(st, "turbine", w) == pytest.approx(q / 3, rel=1e-12)
    with pytest.raises(ConfigError, match="speed"):
        stage_cross_coupling(st, "compressor", 0.0)


def _rigid_rotor(k: float, c: float, power: float) -> str:
    """A short thick steel rotor (0.4 m × 200 mm, 98.6 kg; its first bending mode in the
    kHz) on two isotropic springs with dampers, k/2 and c/2 each, one stage at mid-span."""
    return f"""
[rotor]
name = "rigid rotor on damped springs"
[materials.steel]
E = 2.1e11
rho = 7850.0
nu = 0.3
[[shaft]]
length = 0.4
outer_diameter = 0.2
material = "steel"
elements = 8
[[spring]]
name = "left"
position = 0.0
kxx = {k / 2}
kyy = {k / 2}
cxx = {c / 2}
cyy = {c / 2}
[[spring]]
name = "right"
position = 0.4
kxx = {k / 2}
kyy = {k / 2}
cxx = {c / 2}
cyy = {c / 2}
[[stage]]
position = 0.2
power = {power}
impeller_diameter = 0.3
discharge_width = 0.02
suction_density = 10.0
discharge_density = 15.0
[operating]
speed_rpm = 3000.0
"""


def test_q0_of_a_rigid_rotor_on_damped_supports_is_the_closed_form():
    """m z̈ + c ż + k z − jQ z = 0 (z = x + jy, the cross-coupling k_xy = Q, k_yx = −Q at
    mid-span of a rotor symmetric about it): forward whirl at ω = √(k/m) loses its damping
    at Q_0 = c·√(k/m). The screening's Q_0 (no AMB: the rig as it is) within 1 % (API 617's
    check of the screening on a closed form; the shaft's own flexibility and mass move it by
    0.2 %), δ(0) of
    the cylindrical mode 2πζ/√(1 − ζ²) with ζ = c/(2√(km)); with a Q_A of about Q_0/6
    (Q_0/Q_A between 2 and 10) the CSR region decides: this short stiff rotor's CSR lies
    far below the default boundary (Region A, passed), and above a boundary set below it
    (Region B, Level II required)."""
    import tomllib

    k, c = 1e7, 2000.0
    cfg = parse_rig(tomllib.loads(_rigid_rotor(k, c, 4.5e4)))
    m = math.pi / 4 * 0.2**2 * 0.4 * 7850.0
    r = level1_screening(cfg)
    q0 = c * math.sqrt(k / m)
    assert r.Q_0 == pytest.approx(q0, rel=0.01)
    zeta = c / (2 * math.sqrt(k * m))
    assert r.log_dec[0] == pytest.approx(2 * math.pi * zeta / math.sqrt(1 - zeta**2),
                                         rel=0.02)
    assert r.frequency_hz[0] == pytest.approx(math.sqrt(k / m) / (2 * math.pi), rel=0.02)
    assert r.converged and 2 < r.ratio < 10
    assert r.rho_avg == pytest.approx(0.5 * (10.0 + 15.0)) and r.csr_boundary == 2.5
    assert r.region == "A" and r.passed and "Region A" in r.rule
    low = parse_rig({**tomllib.loads(_rigid_rotor(k, c, 4.5e4)),
                     "signoff": {"csr_boundary": [[0.0, r.csr / 2]]}})
    b = level1_screening(low)
    assert b.Q_0 == pytest.approx(r.Q_0) and b.csr_boundary == pytest.approx(r.csr / 2)
    assert b.region == "B" and not b.passed and "Level II" in b.rule
    assert r.where_m == ((pytest.approx(0.2), 1.0),)
    # δ falls with Q through the found zero
    assert np.all(np.diff(r.log_dec) < 0)


def test_q_applied_off_mid_span_where_the_rig_file_says():
    """``[signoff] level1_position_m`` moves the whole Q: on the rigid rotor of the test
    above the cylindrical mode moves every station alike, so Q a quarter-length from
    mid-span still loses it at Q_0 = c·√(k/m) (within 1 %, the closed form), now from
    there; off the rotor the key is refused by name."""
    import tomllib

    k, c = 1e7, 2000.0
    doc = tomllib.loads(_rigid_rotor(k, c, 4.5e4))
    m = math.pi / 4 * 0.2**2 * 0.4 * 7850.0
    at = level1_screening(parse_rig({**doc, "signoff": {"level1_position_m": 0.1}}))
    assert at.where_m == ((0.1, 1.0),)
    assert at.Q_0 == pytest.approx(c * math.sqrt(k / m), rel=0.01)
    with pytest.raises(ConfigError, match=r"signoff.level1_position_m: position 9.0 m lies "
                                          r"outside the shaft"):
        parse_rig({**doc, "signoff": {"level1_position_m": 9.0}})


def test_screening_outcomes_by_their_rules():
    """The same rotor with a stage about four times larger (Q_0/Q_A = 1.3, δ_A below 0.1)
    fails; one about a sixth of it passes (Q_0 beyond 10·Q_A). Nothing passes without its
    rule."""
    import tomllib

    k, c = 1e7, 2000.0
    big = level1_screening(parse_rig(tomllib.loads(_rigid_rotor(k, c, 2.0e5))))
    assert not big.passed and big.ratio < 2 and ("δ_A" in big.rule or "Q_0/Q_A" in big.rule)
    small = level1_screening(parse_rig(tomllib.loads(_rigid_rotor(k, c, 8.0e3))))
    assert small.passed and small.Q_0 is None and small.log_dec_A >= 0.1
    assert "passed" in small.rule


def test_a_rig_without_stages_is_refused_by_name():
    import tomllib

    text = (_rigid_rotor(1e7, 2000.0, 1e5).split("[[stage]]")[0]
            + "[operating]\nspeed_rpm = 3000.0\n")
    with pytest.raises(ConfigError, match=r"\[\[stage\]\]"):
        level1_screening(parse_rig(tomllib.loads(text)))


def _rigid_rotor_on_ambs(ki: float, ks: float, pid: dict) -> str:
    """The rotor of :func:`_rigid_rotor` (1 % modal damping) on two AMBs at its ends
    (sensors collocated), with the PID of ``pid`` at 50 kHz and no computation delay."""
    text = _rigid_rotor(1.0, 0.0, 4.5e4).split("[[spring]]")[0].replace(
        'name = "rigid rotor on damped springs"', 'name = "rigid rotor on AMBs"\n'
        "modal_damping = 0.01")  # the kHz bending modes, which the sampling reaches
    for name, z in (("A", 0.0), ("B", 0.4)):
        text += (f'[[amb]]\nname = "{name}"\nposition = {z}\nsensor_position = {z}\n'
                 f"ki = {ki}\nks = {ks}\nbias_current = 5.0\ncurrent_limit = 10.0\n")
    text += ("[controller]\nsample_rate_hz = 50000.0\ndelay_samples = 0\n"
             "[controller.pid]\n" + "".join(f"{k} = {v}\n" for k, v in pid.items()))
    return text + ("[[stage]]\nposition = 0.2\npower = 4.5e4\nimpeller_diameter = 0.3\n"
                   "discharge_width = 0.02\nsuction_density = 10.0\n"
                   "discharge_density = 15.0\n[operating]\nspeed_rpm = 3000.0\n")


def test_q0_with_a_pd_acting_amb_is_the_closed_form_of_its_equivalent_support():
    """Two AMBs under a PID that acts as a PD at the ~50 Hz whirl (T_i = 100 s, the
    derivative filter at 7 kHz) on the same rigid rotor, the controller as it runs at
    50 kHz: each AMB is a support of stiffness k_eq = K_i K_p − K_s and damping
    c_eq = K_i K_p T_d, and the zero-order hold a lag of half a sample T/2, whose phase
    ωT/2 takes k_eq·T/2 from the damping (the force −(k_eq + jωc_eq)e^{−jωT/2}): so
    Q_0 = c·√(k/m) with k = 2 k_eq, c = 2 (c_eq − k_eq T/2), to 2 % (the PID's integral
    and derivative filter are the difference; without the hold's term it is 4.6 % off)."""
    import tomllib

    from ambseal.analysis import operating_points
    from ambseal.app.commands import digital_for
    from ambseal.design import design, design_spec

    ki, ks, kp, td = 100.0, 2.0e6, 7.0e4, 2.24e-4
    cfg = parse_rig(tomllib.loads(_rigid_rotor_on_ambs(
        ki, ks, {"kp": kp, "ti": 100.0, "td": td, "eps": 0.1})))
    res = design(cfg, "pid")
    digital = digital_for(cfg, "pid", res.K, res, operating_points(design_spec(cfg)))
    r = level1_screening(cfg, digital, name="pid")
    m = math.pi / 4 * 0.2**2 * 0.4 * 7850.0
    T = 1.0 / 50000.0
    k, c = 2 * (ki * kp - ks), 2 * (ki * kp * td - (ki * kp - ks) * T / 2)
    assert r.Q_0 == pytest.approx(c * math.sqrt(k / m), rel=0.02)
    assert r.converged and r.frequency_hz[0] == pytest.approx(
        math.sqrt(k / m) / (2 * math.pi), rel=0.03)
    # Q_0 is refined on the loop's eigenvalues alone: the poles of the modes as run
    from ambseal.analysis.campbell import modes_as_run, poles_as_run

    for ctrl in (digital, None):
        at = {"speed_hz": 50.0, "max_hz": 2.0e4}
        modes = modes_as_run(cfg, ctrl, **at)
        assert modes.poles.size >= 2
        np.testing.assert_allclose(poles_as_run(cfg, ctrl, **at), modes.poles, rtol=1e-9)


def test_csr_boundary_is_linear_between_its_points_and_flat_beyond():
    """The default boundary: 2.5 up to 16.53 kg/m³, 2.0 from 60 kg/m³, linear between
    (2.5 − 0.5·(ρ − 16.53)/43.47)."""
    from ambseal.analysis.signoff.level1 import csr_boundary
    from ambseal.config.rig import Signoff

    pts = Signoff().csr_boundary
    assert csr_boundary(pts, 5.0) == 2.5 and csr_boundary(pts, 200.0) == 2.0
    assert csr_boundary(pts, 30.0) == pytest.approx(2.5 - 0.5 * (30.0 - 16.53) / 43.47)


def test_the_csr_takes_the_rigid_support_critical_at_standstill():
    """API 617's critical speed ratio divides the maximum continuous speed by the first
    critical speed on rigid supports, a standstill property of the rotor. The overhung
    compressor pinned at its bearings: 329.5 Hz in ROSS 3.1 at standstill (its
    ``run_critical_speed``, measured beside ambseal and stored here), CSR 305/329.5 = 0.93;
    built at the operating speed the gyroscopic moments of the impeller pull the backward
    whirl down to 269.7 Hz (CSR 1.13)."""
    from pathlib import Path

    from ambseal.config import load_rig

    cfg = load_rig(Path(__file__).resolve().parents[2] / "examples" / "overhung_compressor.toml")
    r = level1_screening(cfg, None, points=3)
    assert r.rigid_critical_hz == pytest.approx(329.5, abs=0.05)
    assert r.csr == pytest.approx(r.speed_hz / r.rigid_critical_hz, rel=1e-12)
    assert r.csr == pytest.approx(0.93, abs=0.005)


def test_level1_screens_the_first_forward_mode_not_the_mesh_modes(tmp_path):
    """ROSS's own ``compressor_example`` (saved by ROSS 2.3, ``tests/data``; no structural
    damping) with six stages: its FE mesh modes far above the model's bending band (21–106
    kHz) are lossless, so the loop without cross-coupling is not asymptotically stable by
    ambseal's rule — the screening was "lost at Q = 0". API 617 screens the first forward
    mode the cross-coupling acts on: the mesh modes are reported apart, the screened
    mode at Q = 0 is the rotor's 103.43 Hz mode on its two bearings (its seals left out,
    the balance piston among them) — ROSS 3.1's ``run_modal`` of the same rotor on
    Bearing 0 and Bearing 13 alone at 4 000 rpm gives 103.429084 Hz and δ 0.464951
    (measured beside ambseal, stored here) — and Q_0, where that mode loses its damping,
    is found (0.64·Q_A with these stages)."""
    from pathlib import Path

    from ambseal.config import load_rig
    from ambseal.io import import_ross_file

    src = Path(__file__).resolve().parents[1] / "data" / "ross_compressor_example.toml"
    rig = tmp_path / "compressor.toml"
    import_ross_file(src, rig)
    rig.write_text(rig.read_text().replace("\n[machine]", "".join(
        f'\n[[stage]]\ndisk = "Disk {i}"\npower = 1.0e6\nimpeller_diameter = 0.35\n'
        f"discharge_width = 0.012\nsuction_density = {10.0 + 2 * i}\n"
        f"discharge_density = {12.0 + 2 * i}\n" for i in range(1, 7)) + "\n[machine]", 1))
    r = level1_screening(load_rig(rig), None)
    assert r.frequency_hz[0] == pytest.approx(103.429084, rel=1e-5)
    assert r.log_dec[0] == pytest.approx(0.464951, rel=1e-4)
    assert r.Q_0 is not None and r.Q_0 > 0 and r.converged  # not lost at Q = 0
    for mesh_hz in (62.79e3, 105.7e3):  # two of the lossless mesh modes
        assert any(abs(f / mesh_hz - 1) < 2e-3 for f in r.apart_hz), r.apart_hz
    assert "not screened" in r.rule


def test_a_seal_given_as_a_spring_is_no_bearing(tmp_path):
    """ROSS's ``compressor_example`` has a balance-piston seal (``SealElement`` "Seal 1",
    kxy = kyx: no Childs form) that ``import-ross`` writes as a ``[[spring]]``; it was
    pinned for the CSR, given a journal load and made a probe. As ``kind = "seal"`` it is
    none of those: the journal loads are the two-support statics of ROSS 2.3's own mass
    and centre of mass (246.870 kg at 0.82764 m; bearings at 0.2355 and 1.4255 m),
    W_A = m (z_B − z_G)/(z_B − z_A), to 1e-4, and Level II lists the seal as a source."""
    from pathlib import Path

    from ambseal.analysis.signoff.level1 import bearing_positions
    from ambseal.analysis.signoff.level2 import level2_analysis
    from ambseal.analysis.signoff.unbalance_api617 import journal_loads
    from ambseal.config import load_rig
    from ambseal.io import import_ross_file

    src = Path(__file__).resolve().parents[1] / "data" / "ross_compressor_example.toml"
    rig = tmp_path / "compressor.toml"
    import_ross_file(src, rig)
    cfg = load_rig(rig)
    seals = [s for s in cfg.spring if s.kind == "seal"]
    assert len(seals) == 1 and seals[0].kxy == pytest.approx(seals[0].kyx)
    assert bearing_positions(cfg) == pytest.approx([0.2355, 1.4255])
    m, zg, (za, zb) = 246.87036435603625, 0.8276413453580715, (0.2355, 1.4255)
    loads = journal_loads(cfg)
    assert [z for z, _ in loads] == pytest.approx([za, zb])
    np.testing.assert_allclose([w for _, w in loads],
                               [m * (zb - zg) / (zb - za), m * (zg - za) / (zb - za)],
                               rtol=1e-4)
    rows = [r.component for r in level2_analysis(cfg.model_copy(update={"stage": []}),
                                                 None).rows]
    assert f"+ seal {seals[0].name}" in rows and rows[0] == "rotor and supports"


def test_level1_screens_a_resonance_not_an_overdamped_pole():
    """The gyroscopic rigid rotor on its PID of the Level II test (cylindrical mode at
    ζ = 0.95, the nutation resonant at 200 Hz), a small stage at mid-span: up to 10·Q_A
    no mode loses its damping, and Q, at mid-span of a symmetric rotor, takes damping
    from the cylindrical whirl (δ 21 → 16) and moves the overdamped poles of the rigid
    shaft's bending, aliased by the sampling (δ in the thousands): their δ falls by more
    than the nutation's whole δ. Level I screens the mode that is a resonance (AF =
    π/δ ≥ 2.5, API 684's critical speed) — the nutation, which Q leaves alone — and its
    δ_A and frequency at Q_A are those of the lowest forward resonant eigenvalue of an
    independent eigen-analysis of the same sampled loop with jQ_A r at mid-span in
    complex coordinates (to 1e-3 and 1e-4); the cylindrical whirl stays overdamped
    there (ζ > 0.5)."""
    # here, not at the top: test_analysis_level2 imports this module
    from .test_analysis_level2 import FS, _complex_sampled_loop, _gyroscopic_rig_and_pid

    stage = (f"[[stage]]\nposition = {L / 2}\npower = 3000.0\nimpeller_diameter = 0.3\n"
             "discharge_width = 0.02\nsuction_density = 10.0\ndischarge_density = 15.0\n")
    cfg, p = _gyroscopic_rig_and_pid(stage)
    K = pid_controller(*p, channel_names(cfg))
    dc = DigitalController(K, K, discrete_controller(K, 1 / FS, "tustin"), "tustin", None,
                           FS, 1)
    r = level1_screening(cfg, dc)
    assert r.Q_0 is None and r.passed
    lam = _complex_sampled_loop(*p, q=r.Q_A)
    fwd = lam[lam.imag > 2 * math.pi * 0.1]
    fwd = fwd[np.argsort(fwd.imag)]
    delta = -2 * math.pi * fwd.real / fwd.imag
    sharp = np.flatnonzero(math.pi / delta >= 2.5)
    assert sharp[0] > 0 and -fwd[0].real / abs(fwd[0]) > 0.5  # the cylindrical, below
    iA = int(np.argmin(np.abs(r.Q - r.Q_A)))
    assert r.log_dec_A == pytest.approx(delta[sharp[0]], rel=1e-3)
    assert r.frequency_hz[iA] == pytest.approx(fwd[sharp[0]].imag / (2 * math.pi), rel=1e-4)
