"""Closed-loop modes, log decrement, whirl and the Campbell diagram (analysis/campbell.py)."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
from scipy.optimize import brentq

from ambseal.analysis.campbell import campbell, closed_loop_modes, log_decrement

# A rigid rotor (shaft 10⁵ times stiffer than its supports) with a central disk on two AMBs
# at its ends, each closed by a proportional gain into an isotropic support stiffness
# k = Ki·kp − Ks, and two dampers c at the same places.
L, D, RHO, E = 0.4, 0.05, 7850.0, 2e16
MD, ID, IP = 10.0, 0.10, 0.05
KI, KS, K, C = 100.0, 1e5, 1e6, 300.0


def _rig() -> dict:
    return {"materials": {"m": {"E": E, "rho": RHO, "nu": 0.3}},
            "shaft": [{"length": L, "outer_diameter": D, "material": "m", "elements": 2}],
            "disk": [{"position": L / 2, "mass": MD, "Ip": IP, "Id": ID}],
            "amb": [{"name": n, "position": z, "sensor_position": z, "axes_angle_deg": 45.0,
                     "ki": KI, "ks": KS} for n, z in (("A", 0.0), ("B", L))],
            "spring": [{"position": z, "kxx": 0.0, "kyy": 0.0, "cxx": C, "cyy": C}
                       for z in (0.0, L)]}


@pytest.fixture(scope="module")
def rigid():
    import control

    from ambseal.config import parse_rig

    from ambseal.model.amb import channel_names

    cfg = parse_rig(_rig())
    ch = channel_names(cfg)  # named as a controller file for the rig must be
    return cfg, control.ss([], [], [], (K + KS) / KI * np.eye(4), inputs=[f"y_{c}" for c in ch],
                           outputs=[f"i_{c}" for c in ch])


def _closed_form(speed_hz: float) -> tuple[np.ndarray, np.ndarray]:
    """Eigenvalues (Im > 0, ascending) of the rigid rotor: translation m s² + 2c s + 2k = 0
    (twice) and the conical modes I_d s² + (2ca² ± jI_pΩ) s + 2ka² = 0, a = L/2, with the
    shaft's mass and inertia added to the disk's (Friswell et al. 2010, §3.5, Eqs. 3.63–3.67).
    Returns (poles, forward mask)."""
    ms, i2 = RHO * np.pi * D**2 / 4 * L, np.pi * D**4 / 64
    m, Id, Ip = MD + ms, ID + ms * L**2 / 12 + RHO * i2 * L, IP + 2 * RHO * i2 * L
    a, w = L / 2, 2 * np.pi * speed_hz
    tr = np.roots([m, 2 * C, 2 * K])
    con = np.concatenate([np.roots([Id, 2 * C * a * a + s * 1j * Ip * w, 2 * K * a * a])
                          for s in (1, -1)])
    lam = np.concatenate([tr, tr, con])
    lam = lam[lam.imag > 0]
    return lam[np.argsort(lam.imag)]


@pytest.mark.parametrize("speed_hz", [0.0, 100.0, 300.0])
def test_rigid_rotor_modes_match_the_closed_form(rigid, speed_hz):
    """Frequencies, damping ratios and log decrements of the closed loop equal the closed
    form of a rigid rotor on isotropic damped supports with gyroscopics (Friswell et al.
    2010, §3.5) to 1e-6; at speed the upper conical mode whirls forward, the lower backward,
    and δ = 2πζ/√(1−ζ²) (API 684)."""
    cfg, Kp = rigid
    m = closed_loop_modes(cfg, Kp, speed_hz=speed_hz, max_hz=1e4, delay=False)
    ref = _closed_form(speed_hz)
    got = m.poles[:4]
    assert got.imag == pytest.approx(ref.imag, rel=1e-6)
    assert got.real == pytest.approx(ref.real, rel=1e-6)
    zeta = -ref.real / np.abs(ref)
    assert m.damping_ratio[:4] == pytest.approx(zeta, rel=1e-6)
    assert m.log_decrement[:4] == pytest.approx(2 * np.pi * zeta / np.sqrt(1 - zeta**2),
                                                rel=1e-6)
    if speed_hz > 0:
        assert m.whirl[2:4] == ("backward", "forward")
        assert m.kappa[2:4] == pytest.approx([-1.0, 1.0], abs=1e-6)  # circular orbits
    assert m.stable


def test_repeated_pairs_at_standstill_whirl_backward_then_forward(rigid):
    """At standstill the isotropic rotor's x and y modes are one repeated eigenvalue, whose
    eigenvectors are any basis of its plane; each pair is read in the circular basis, the
    limit of the split pair as the speed rises from 0 (the closed form at 0⁺: the lower
    conical mode backward, κ = −1, the upper forward, κ = +1), the same at every call. A
    pair split by anisotropic supports keeps its own (planar) shapes."""
    cfg, Kp = rigid
    for _ in range(3):
        m = closed_loop_modes(cfg, Kp, speed_hz=0.0, max_hz=1e4, delay=False)
        assert m.whirl[:4] == ("backward", "forward") * 2
        assert m.kappa[:4] == pytest.approx([-1.0, 1.0] * 2, abs=1e-9)
    from ambseal.config import parse_rig

    rig = _rig()
    for sp in rig["spring"]:
        sp["kyy"] = 1e5  # y stiffer than x: two planar modes per pair
    m = closed_loop_modes(parse_rig(rig), Kp, speed_hz=0.0, max_hz=1e4, delay=False)
    assert m.whirl[:4] == ("planar",) * 4


def test_campbell_crossings_match_the_closed_form(rigid):
    """The 1× crossings of the tracked lines: the translation at its (speed-independent)
    damped frequency, the conical modes where the closed-form frequency equals the speed
    (root of Im λ(Ω)/2π − Ω/2π); linear interpolation on a 5 Hz grid: 1e-3."""
    cfg, Kp = rigid
    c = campbell(cfg, Kp, np.linspace(0.0, 200.0, 41), max_hz=1e4, delay=False)
    fwd = brentq(lambda f: _closed_form(f)[3].imag / (2 * np.pi) - f, 1.0, 200.0)
    bwd = brentq(lambda f: _closed_form(f)[2].imag / (2 * np.pi) - f, 1.0, 200.0)
    tr = _closed_form(0.0)[0].imag / (2 * np.pi)
    got = sorted((x.speed_hz, x.whirl) for x in c.crossings)
    assert len(got) == 4
    assert [s for s, _ in got] == pytest.approx(sorted([tr, tr, bwd, fwd]), rel=1e-3)
    assert dict((round(s), w) for s, w in got)[round(fwd)] == "forward"
    assert all(x.critical for x in c.crossings)  # lightly damped: AF = π/δ > 2.5
    assert c.flagged() == []  # every δ above API 684's 0.1


def test_closed_loop_with_controller_states_matches_python_control(testrig_cfg):
    """The PID loop of the embedded rig (controller and actuator states included) at 50 Hz,
    without the target's delay: every kept pole is a pole of python-control's
    ``feedback(G, K)`` (peer library) to 1e-8 (with the delay: tests/test_verdicts.py)."""
    import control

    from ambseal.design.recipes import design
    from ambseal.model.rig import build_plant

    Kpid = design(testrig_cfg, "pid").K
    m = closed_loop_modes(testrig_cfg, Kpid, speed_hz=50.0, pressure_bar=2.04, delay=False)
    plant = build_plant(testrig_cfg, pressure_bar=2.04, speed_rpm=3000.0)
    G = plant.select_inputs(plant.input_names[:4]).to_statespace()
    ref = control.feedback(G, Kpid, sign=-1).poles()
    assert len(m.poles) >= 8
    for lam in m.poles:
        assert np.min(np.abs(ref - lam)) <= 1e-8 * abs(lam)
    assert np.all(log_decrement(m.poles) == m.log_decrement)


def _write_rig(path, data: dict) -> None:
    from ambseal.config import dump_rig, parse_rig

    path.write_text(dump_rig(parse_rig(data)))


def test_cli_campbell_modes_and_bad_range(tmp_path, rigid, capsys):
    """``ambseal campbell`` with a controller file (written by export_controller) writes the
    figure, JSON and CSV, and its crossings are those of :func:`campbell`; ``modes --shapes
    --controller FILE`` states speed, pressure, log decrement and whirl and writes the
    figure; a bad ``--speed-hz`` is one line on stderr and exit 2."""
    from ambseal.cli import main
    from ambseal.export.controller_files import export_controller

    cfg, Kp = rigid
    rig = tmp_path / "rigid.toml"
    _write_rig(rig, _rig())
    kfile = export_controller(Kp, tmp_path / "Kp.json")
    out = tmp_path / "camp"
    assert main(["campbell", str(rig), "--controller", str(kfile), "--speed-hz", "0:200:11",
                 "--max-hz", "1e4", "--out", str(out)]) == 0
    summary = json.loads(capsys.readouterr().out)
    ref = campbell(cfg, Kp, np.linspace(0.0, 200.0, 11), max_hz=1e4)
    assert [x["speed_hz"] for x in summary["crossings"]] == pytest.approx(
        [x.speed_hz for x in ref.crossings], rel=1e-12)
    assert all(Path(f).exists() for f in summary["files"])
    assert (out / "campbell_Kp.png").stat().st_size > 10_000
    assert (out / "campbell_Kp.csv").read_text().startswith("speed_hz,line,frequency_hz")
    png = tmp_path / "shapes.png"
    assert main(["modes", str(rig), "--controller", str(kfile), "--speed-rpm", "6000",
                 "--max-hz", "1e4", "--shapes", str(png), "--json"]) == 0
    got = json.loads(capsys.readouterr().out)
    assert got["speed_hz"] == 100.0 and got["whirl"][2:4] == ["backward", "forward"]
    assert got["log_decrements"][:4] == pytest.approx(
        list(closed_loop_modes(cfg, Kp, speed_hz=100.0, max_hz=1e4).log_decrement[:4]))
    assert png.stat().st_size > 10_000
    assert main(["campbell", str(rig), "--speed-hz", "0:200", "--out", str(out)]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "--speed-hz" in err


def test_overdamped_lines_cross_apart():
    """Two lines over 0–100 Hz: a lightly damped mode at 50 Hz (ζ = 0.05, log decrement
    2πζ/√(1−ζ²)) and a heavily damped controller pole whose damped frequency rises from 20
    to 80 Hz (ζ = 0.95). Both meet the 1× line at 50 Hz, a grid speed (counted once); only
    the first is a crossing with a resonance, the second is listed apart (ζ ≥ 1/√2: no
    resonance peak)."""
    from types import SimpleNamespace

    from ambseal.analysis.campbell import OVERDAMPED_ZETA, Campbell, _crossings

    speeds = np.linspace(0.0, 100.0, 11)
    z1, z2 = 0.05, 0.95
    pts = tuple(SimpleNamespace(
        frequency_hz=np.array([50.0, 20.0 + 0.6 * s]), damping_ratio=np.array([z1, z2]),
        log_decrement=2 * np.pi * np.array([z1, z2]) / np.sqrt(1 - np.array([z1, z2]) ** 2),
        whirl=("forward", "backward")) for s in speeds)
    c = Campbell(speeds, pts, np.tile([0, 1], (11, 1)), ())
    crossings, over = _crossings(c)
    assert [(x.track, x.speed_hz) for x in crossings] == [(0, 50.0)]
    assert [(x.track, x.speed_hz) for x in over] == [(1, 50.0)]
    assert z2 >= OVERDAMPED_ZETA > z1


def test_campbell_rings_a_low_log_decrement_where_the_mode_is_drawn(tmp_path, monkeypatch):
    """Over 0–100 Hz a mode at 150 Hz (ζ = 0.05) sets the frequency panel's range (to
    1.15 × 150 Hz); a mode at 900 Hz with δ ≈ 0.03 < 0.1 lies above it. Its low log
    decrement is ringed in the δ panel, with the legend there, and the frequency panel's
    legend has no "log dec < 0.1" entry for a ring it does not draw."""
    from types import SimpleNamespace

    import ambseal.report.modal_figures as mf
    from ambseal.analysis.campbell import Campbell

    speeds = np.linspace(0.0, 100.0, 5)
    zeta = np.array([0.05, 0.005])
    pts = tuple(SimpleNamespace(
        speed_hz=sp, max_hz=1e3, frequency_hz=np.array([150.0, 900.0]), damping_ratio=zeta,
        log_decrement=2 * np.pi * zeta / np.sqrt(1 - zeta**2), whirl=("forward",) * 2)
        for sp in speeds)
    c = Campbell(speeds, pts, np.tile([0, 1], (5, 1)), ())
    figs = []
    monkeypatch.setattr(mf, "save_figure", lambda fig, path, **kw: figs.append(fig) or path)
    mf.campbell_figure(tmp_path / "c.png", c)
    top, bottom = figs[0].axes[:2]
    assert top.get_ylim()[1] == pytest.approx(1.15 * 150.0)
    assert not any("log dec" in t.get_text() for t in top.get_legend().get_texts())
    assert [t.get_text() for t in bottom.get_legend().get_texts()] == ["log dec < 0.1"]
    rings = [col for col in bottom.collections if col.get_label() == "log dec < 0.1"]
    assert len(rings) == 1 and len(rings[0].get_offsets()) == len(speeds)


def test_campbell_figure_draws_only_modes_with_a_resonance(tmp_path, monkeypatch):
    """Three lines over 0–100 Hz: a lightly damped mode at 50 Hz (ζ = 0.05: AF = π/δ ≈ 10,
    a critical speed by API 684), a well damped one at 70 Hz (ζ = 0.3: AF ≈ 1.6 < 2.5) and
    a controller pole damped at ζ = 0.95 whose frequency rises from 20 to 80 Hz. The
    frequency panel draws the first in full colour, the second faint, the third not at all
    (ζ ≥ 1/√2: no resonance to meet the 1× line); the δ panel holds all three."""
    from types import SimpleNamespace

    import ambseal.report.modal_figures as mf
    from ambseal.analysis.campbell import Campbell, _crossings

    speeds = np.linspace(0.0, 100.0, 11)
    zeta = np.array([0.05, 0.3, 0.95])
    pts = tuple(SimpleNamespace(
        speed_hz=s, max_hz=1e3, frequency_hz=np.array([50.0, 70.0, 20.0 + 0.6 * s]),
        damping_ratio=zeta, log_decrement=2 * np.pi * zeta / np.sqrt(1 - zeta**2),
        whirl=("forward",) * 3) for s in speeds)
    c = Campbell(speeds, pts, np.tile([0, 1, 2], (11, 1)), ())
    c = Campbell(speeds, pts, c.tracks, *_crossings(c)[:1])
    figs = []
    monkeypatch.setattr(mf, "save_figure", lambda fig, path, **kw: figs.append(fig) or path)
    mf.campbell_figure(tmp_path / "c.png", c)
    top, bottom = figs[0].axes[:2]
    drawn = [(col.get_alpha(), {float(y) for y in col.get_offsets()[:, 1]})
             for col in top.collections if len(col.get_offsets())]
    assert (None, {50.0}) in drawn and (0.25, {70.0}) in drawn
    assert not any(y < 50.0 or 70.0 < y for _, ys in drawn for y in ys)  # the pole left out
    assert sum(len(col.get_offsets()) for col in bottom.collections) == 3 * len(speeds)
    assert [(x.track, x.critical) for x in c.crossings] == [(0, True), (1, False)]
