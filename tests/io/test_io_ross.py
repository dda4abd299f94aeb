"""ROSS rotors in (io/ross.py), side by side with ROSS 2.3 (ross-rotordynamics, the ``ross``
extra), on ROSS's own examples saved with ``Rotor.save``. ROSS's eigenvalues are those of
``Rotor._eigen(speed, sparse=False)``, the dense solve whose |λ| ``run_modal(speed).wn``
reports (``run_modal`` itself adds a numba-compiled orbit post-processing that takes a
minute to compile on first call); like ``run_modal(speed)`` it takes frequency-dependent
bearing coefficients at the frequency ``speed``."""

from __future__ import annotations

import contextlib
import ctypes
import inspect
import json
import os
import subprocess
import sys
import tomllib
import warnings

import numpy as np
import pytest
import scipy.linalg as sla

with contextlib.redirect_stdout(sys.stderr), warnings.catch_warnings():
    warnings.simplefilter("ignore")
    rs = pytest.importorskip("ross", reason="ross-rotordynamics (the 'ross' extra) is not "
                                            "installed")

from ambseal.analysis.campbell import closed_loop_modes  # noqa: E402
from ambseal.config import dump_rig, parse_rig  # noqa: E402
from ambseal.design.pid import pid_controller  # noqa: E402
from ambseal.errors import ConfigError  # noqa: E402
from ambseal.io.ross import _stdout_to_stderr, from_ross, load_ross  # noqa: E402
from ambseal.model.amb import AmbElement, amb_factors, channel_names  # noqa: E402
from ambseal.model.rotor import build_mesh  # noqa: E402
from ambseal.model.rig import build_system  # noqa: E402


def _quiet(f, *args, **kw):
    with contextlib.redirect_stdout(sys.stderr), warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return f(*args, **kw)

from ..finemesh import fine_bearing_data, fine_ross_rotor  # noqa: E402
from ..toml_text import dump  # noqa: E402


def _ross_eigenvalues(rotor, speed_rad_s: float) -> np.ndarray:
    lam, _ = _quiet(rotor._eigen, speed_rad_s, sparse=False)
    return np.asarray(lam)


def _ross_lateral_count(rotor, speed_rad_s: float, max_hz: float) -> int:
    """How many of ROSS's eigenvalues at ``speed_rad_s`` with 1 rad/s < Im λ < ``max_hz``
    are lateral modes: most of their eigenvector's position part in x, y, α, β (ROSS's six
    DOFs per node add axial and torsional modes, which ambseal does not model)."""
    lam, V = _quiet(rotor._eigen, speed_rad_s, sparse=False)
    lam, V = np.asarray(lam), np.asarray(V)
    per = int(getattr(rotor, "number_dof", 4))
    q = np.abs(V[:rotor.ndof]) ** 2
    lateral = q[[i for i in range(rotor.ndof) if i % per in (0, 1, 3, 4)]].sum(axis=0)
    band = (lam.imag > 1.0) & (lam.imag < 2 * np.pi * max_hz)
    return int(np.sum(band & (lateral > 0.5 * q.sum(axis=0))))


def _assert_modes_equal_ross(rig, rotor, speed_rad_s: float, max_hz: float, n: int) -> None:
    """Every lateral mode of ``rig`` up to ``max_hz`` equals one of ROSS's eigenvalues of
    ``rotor`` at the same speed, and its |λ| (ROSS's ``wn``), to 1e-6 relative."""
    ref = _ross_eigenvalues(rotor, speed_rad_s)
    m = closed_loop_modes(rig, None, speed_hz=speed_rad_s / (2 * np.pi), max_hz=max_hz)
    assert len(m.poles) == n
    for lam in m.poles:
        j = np.argmin(np.abs(ref - lam))
        assert abs(ref[j] - lam) <= 1e-6 * abs(lam)
        assert abs(lam) == pytest.approx(abs(ref[j]), rel=1e-6)


@pytest.fixture(scope="module")
def examples(tmp_path_factory):
    """ROSS's three examples, in memory and saved by ``Rotor.save`` (as a user has them)."""
    folder = tmp_path_factory.mktemp("ross")
    out = {}
    for name in ("rotor_example", "compressor_example", "rotor_amb_example"):
        rotor = _quiet(_amb_example if name == "rotor_amb_example" else getattr(rs, name))
        _quiet(rotor.save, folder / f"{name}.toml")
        out[name] = (rotor, folder / f"{name}.toml")
    return out


def _amb_example():
    """ROSS's AMB test rig (Mendes 2015, doi.org/10.14393/ufu.di.2015.186): ROSS 2.3's
    ``rotor_amb_example``, in ROSS 3 ``rotor_example_amb_general_controllers()`` of
    ``ross.bearings.magnetic.amb_models`` (the same rotor, AMBs and PD controller)."""
    if hasattr(rs, "rotor_amb_example"):
        return rs.rotor_amb_example()
    from ross.bearings.magnetic.amb_models import rotor_example_amb_general_controllers
    return rotor_example_amb_general_controllers()



def _bearing_rotor():
    """ROSS's ``rotor_example`` (6 Timoshenko elements, two disks) on two anisotropic,
    damped plain bearings, so that the log decrements are not zero."""
    ex = rs.rotor_example()
    b = [rs.BearingElement(n, kxx=1e6, kyy=0.8e6, cxx=150.0, cyy=90.0, tag=f"B{n}")
         for n in (0, 6)]
    return rs.Rotor(ex.shaft_elements, ex.disk_elements, b)


@pytest.mark.parametrize("speed_rpm", [0.0, 4000.0])
def test_bearing_rotor_modes_equal_ross(speed_rpm):
    """Every lateral mode of the imported rotor up to 500 Hz (damped frequency and log
    decrement) equals one of ROSS's eigenvalues of the same rotor to 1e-6 relative, at
    standstill and at 4000 rpm (ROSS 2.3 side by side)."""
    rotor = _bearing_rotor()
    imp = from_ross(rotor)
    assert imp.unmapped == () and len(imp.rig.shaft) == 6 and len(imp.rig.spring) == 2
    _assert_log_decrements_equal_ross(imp.rig, rotor, speed_rpm)


def _assert_log_decrements_equal_ross(rig, rotor, speed_rpm: float, max_hz: float = 500.0,
                                      n: int = 12) -> None:
    """The ``n`` lateral modes of ``rig`` up to ``max_hz`` each equal one of ROSS's
    eigenvalues of ``rotor`` at ``speed_rpm`` to 1e-6 relative, and their log decrements
    ROSS's."""
    ref = _ross_eigenvalues(rotor, speed_rpm * np.pi / 30)
    m = closed_loop_modes(rig, None, speed_hz=speed_rpm / 60, max_hz=max_hz)
    assert len(m.poles) == n
    for lam, dec in zip(m.poles, m.log_decrement):
        j = np.argmin(np.abs(ref - lam))
        assert abs(ref[j] - lam) <= 1e-6 * abs(lam)
        assert dec == pytest.approx(-2 * np.pi * ref[j].real / ref[j].imag, rel=1e-6)


def _takes(cls, argument: str) -> bool:
    """Whether this ROSS's ``cls`` takes ``argument`` (ROSS 3 added some)."""
    return argument in inspect.signature(cls.__init__).parameters


@pytest.mark.skipif(not _takes(rs.Rotor, "alpha"),
                    reason="ROSS < 3: a Rotor has no damping of its own (alpha, beta)")
def test_rotor_rayleigh_damping_equals_ross(tmp_path):
    """A ROSS 3 rotor with its own Rayleigh damping (``Rotor(alpha=3, beta=2e-5)``, of
    shaft and disks), saved and imported: ``[rotor] rayleigh_alpha``, ``rayleigh_beta``, and
    every lateral mode up to 500 Hz (damped frequency and log decrement) equal to one of
    ROSS's eigenvalues to 1e-6 at 0 and 4000 rpm."""
    ex = _bearing_rotor()
    rotor = _quiet(rs.Rotor, ex.shaft_elements, ex.disk_elements, ex.bearing_elements,
                   alpha=3.0, beta=2e-5)
    path = tmp_path / "damped.toml"
    _quiet(rotor.save, path)
    imp = from_ross(load_ross(path), where=str(path))
    assert (imp.rig.rotor.rayleigh_alpha, imp.rig.rotor.rayleigh_beta) == (3.0, 2e-5)
    for speed_rpm in (0.0, 4000.0):
        _assert_log_decrements_equal_ross(imp.rig, rotor, speed_rpm)


def _modal_damping_rotor(stiffness_y=0.8e6, **damping):
    """ROSS 3.1's ``test_modal_damping`` rotor: six Timoshenko elements, two disks, plain
    bearings of 1e6 N/m in x and ``stiffness_y`` in y without damping."""
    shaft = [rs.ShaftElement(0.25, 0, 0.05, material=rs.materials.steel, shear_effects=True,
                             rotary_inertia=True, gyroscopic=True) for _ in range(6)]
    disks = [rs.DiskElement.from_geometry(2, rs.materials.steel, 0.07, 0.05, 0.28),
             rs.DiskElement.from_geometry(4, rs.materials.steel, 0.07, 0.05, 0.35)]
    bearings = [rs.BearingElement(n, kxx=1e6, kyy=stiffness_y, cxx=0) for n in (0, 6)]
    return _quiet(rs.Rotor, shaft, disks, bearings, **damping)


def _assert_receptance_equals(rig, amp, phase) -> None:
    """The receptance x/F_x at node 2 (ROSS's DOF 12 of ``test_modal_damping``'s rotor)
    at 200, 400, ... rpm, the frequency following the speed as in ROSS's
    ``run_freq_response(speed_range=...)``, equal to ROSS's asserted amplitude (rtol 1e-5;
    ROSS's test 1e-6, on its values printed to 7 digits) and phase (atol 1e-5)."""
    z = float(build_mesh(rig).z[2])
    for k, (a, ph) in enumerate(zip(amp, phase), start=1):
        w = k * 200 * np.pi / 30
        sys2 = build_system(rig, speed_rpm=k * 200.0, force_positions=(z,))
        f = sys2.B[:, sys2.input_names.index("F0_x")]
        x = np.linalg.solve(sys2.K - w**2 * sys2.M + 1j * w * (sys2.C + w * sys2.G), f)
        assert abs(x @ f) == pytest.approx(a, rel=1e-5)
        assert np.angle(x @ f) == pytest.approx(ph, rel=1e-5, abs=1e-5)


@pytest.mark.skipif(not _takes(rs.Rotor, "alpha"),
                    reason="ROSS < 3: a Rotor has no damping of its own (alpha, beta)")
def test_ross_proportional_damping_rotor_receptance(tmp_path):
    """ROSS 3.1's ``test_proportional_damping`` rotor (``Rotor(alpha=1.6, beta=1.7e-7)``),
    saved and imported: its receptance equals the values ROSS's test asserts."""
    rotor = _modal_damping_rotor(alpha=1.6, beta=1.7e-7)
    path = tmp_path / "rayleigh.toml"
    _quiet(rotor.save, path)
    imp = from_ross(load_ross(path), where=str(path))
    assert (imp.rig.rotor.rayleigh_alpha, imp.rig.rotor.rayleigh_beta) == (1.6, 1.7e-7)
    _assert_receptance_equals(
        imp.rig, [1.495063e-06, 1.803282e-06, 2.818322e-06, 1.854149e-05, 2.545901e-06,
                  9.415274e-07, 4.557404e-07],
        [-0.004284, -0.010686, -0.026649, -0.268325, -3.089441, -3.111475, -3.114635])


@pytest.mark.skipif(not _takes(rs.Rotor, "modal_damping_ratio"),
                    reason="ROSS < 3: a Rotor has no modal damping ratios")
def test_rotor_modal_damping_equals_ross(tmp_path):
    """ROSS 3.1's ``test_modal_damping`` rotor (``modal_damping_ratio=[0.001, 0.001]``,
    ``default_damping_ratio=0.01``), saved and imported: ``[rotor.supported_modal_damping]``
    with ROSS's ratios on the two lowest lateral modes (ROSS's axial and torsional modes
    lie above them), every lateral mode up to 500 Hz (damped frequency and log decrement)
    equal to one of ROSS's eigenvalues to 1e-6 at 0 and 4000 rpm, and the receptance at
    the first disk equal to the values ROSS's test asserts (rtol 1e-6 there; 1e-5 here).
    Ratios that differ within an isotropic rotor's repeated x/y mode are refused, and so
    are ratios beside ROSS's rotor Rayleigh damping named as ROSS drops them."""
    rotor = _modal_damping_rotor(modal_damping_ratio=[0.001, 0.001],
                                 default_damping_ratio=0.01)
    path = tmp_path / "modal.toml"
    _quiet(rotor.save, path)
    imp = from_ross(load_ross(path), where=str(path))
    spec = imp.rig.rotor.supported_modal_damping
    assert (spec.ratios, spec.others) == ([0.001, 0.001], 0.01) and imp.unmapped == ()
    for speed_rpm in (0.0, 4000.0):
        _assert_log_decrements_equal_ross(imp.rig, rotor, speed_rpm)
    _assert_receptance_equals(
        imp.rig, [1.495079e-06, 1.803400e-06, 2.819422e-06, 1.914051e-05, 2.548842e-06,
                  9.418038e-07, 4.558292e-07],
        [-6.188289e-04, -1.423301e-03, -3.157592e-03, -3.001839e-02, -3.135327e00,
         -3.135999e00, -3.131778e00])
    split = _modal_damping_rotor(stiffness_y=1e6, modal_damping_ratio=[0.01, 0.02])
    with pytest.raises(ConfigError, match="differ within a repeated mode"):
        from_ross(split, where="split.toml")
    both = _modal_damping_rotor(modal_damping_ratio=[0.01], alpha=3.0)
    imp = from_ross(both)
    assert imp.rig.rotor.supported_modal_damping is None
    assert imp.rig.rotor.rayleigh_alpha == 3.0
    assert any("modal_damping_ratio=[0.01]" in u and "alpha, beta win" in u
               for u in imp.unmapped)


def test_rotor_example_file_modes_equal_ross(examples):
    """ROSS's ``rotor_example`` as saved (bearings tagged "Bearing 0", "Bearing 1", with a
    space): its 12 lateral modes up to 500 Hz at 0 and 3000 rpm equal ROSS's to 1e-6."""
    rotor, path = examples["rotor_example"]
    imp = from_ross(load_ross(path), where=str(path))
    assert [s.name for s in imp.rig.spring] == ["Bearing_0", "Bearing_1"]
    for w in (0.0, 100 * np.pi):
        _assert_modes_equal_ross(imp.rig, rotor, w, 500.0, 12)


def test_compressor_example_layers_and_frequency_dependent_bearings(examples):
    """ROSS's ``compressor_example``: 91 shaft elements on 55 node pairs (36 of them a
    shaft and a sleeve of E = 1 psi in parallel) → 55 sections with 36 layers; its two
    tilting-pad bearings and the anisotropic ``Seal 1`` (coefficients against frequency,
    with cross-coupled damping) → springs with tables over the synchronous frequency; the
    11 isotropic skew seals → seal tables; the operating speed the lowest their tables
    cover (418.9 rad/s = 4000 rpm, ROSS's first table point). At 4000 rpm, at another
    point of the springs' tables from the same rig (the springs taken there: a rig frozen
    at 4000 rpm would not be), and at 4500 rpm between the tables' points (imported there)
    every lateral mode up to 2 kHz equals ROSS's to 1e-6."""
    rotor, path = examples["compressor_example"]
    loaded = load_ross(path)
    imp = from_ross(loaded, where=str(path))
    cfg = imp.rig
    assert (len(cfg.shaft), sum(len(s.layers) for s in cfg.shaft)) == (55, 36)
    assert (len(cfg.spring), len(cfg.seal), len(cfg.disk)) == (3, 11, 7)
    table_start = max(min(b.frequency if getattr(b, "speed", None) is None else b.speed)
                      for b in rotor.bearing_elements  # (ROSS 3 tables against speed)
                      if b.tag in ("Bearing 0", "Bearing 13", "Seal 1"))
    assert cfg.operating.speed_rpm == pytest.approx(table_start * 30 / np.pi, rel=1e-12)
    assert cfg.operating.speed_rpm == pytest.approx(4000.0, rel=1e-9)
    tabulated = [sp for sp in cfg.spring if sp.tabulated]
    assert len(tabulated) == 3
    _assert_modes_equal_ross(cfg, rotor, cfg.speed, 2000.0, 12)
    common = set.intersection(*(set(sp.kxx.frequency_hz) for sp in tabulated))
    other = min(f for f in common if f > 70.0)  # a point of every table above 4000 rpm
    w = 2 * np.pi * other
    _assert_modes_equal_ross(cfg, rotor, w, 2000.0, _ross_lateral_count(rotor, w, 2000.0))
    at = from_ross(loaded, where=str(path), speed_rpm=4500.0).rig
    assert at.operating.speed_rpm == 4500.0
    _assert_modes_equal_ross(at, rotor, at.speed, 2000.0, 12)


def test_compressor_unbalance_response_with_its_bearing_tables_equals_ross(examples):
    """ROSS's ``compressor_example`` imported once, an unbalance of 2.6e-4 kg·m at its
    mid-span node 31: ambseal's synchronous response (its bearings' and seals' tables
    taken at each speed) against ROSS's ``run_unbalance_response`` — the orbit's
    semi-major axis there (ROSS's x and y amplitudes, the largest of the ellipse by
    brute force over a turn) equal to 1e-6 at the points of every bearing's table
    (418.9–1047.2 rad/s), where ROSS 2.3's smoothing spline and 3's pchip agree with the
    points; with ROSS 3 (its pchip reproduced) also on a fine grid across the first
    critical, whose speed and half-power amplification factor then agree within 0.5 %
    (sampled alike). Taken at one frequency (the rig frozen at 4000 rpm) the bearings
    gave AF 188 where ROSS has 29."""
    from ambseal.analysis.synchronous import Unbalance, synchronous_response
    from ambseal.analysis.signoff.unbalance_api617 import amplification_factor

    rotor, path = examples["compressor_example"]
    cfg = from_ross(load_ross(path), where=str(path)).rig
    node, amount = 31, 2.6e-4
    z = float(rotor.nodes_pos[node])

    def ross(w):
        r = _quiet(rotor.run_unbalance_response, [node], [amount], [0.0], np.asarray(w))
        x = np.asarray(r.forced_resp)[rotor.number_dof * node]
        y = np.asarray(r.forced_resp)[rotor.number_dof * node + 1]
        t = np.linspace(0, 2 * np.pi, 3601)[:, None]
        return np.hypot((x * np.exp(1j * t)).real, (y * np.exp(1j * t)).real).max(axis=0)

    def ours(w):
        r = synchronous_response(cfg, None, np.asarray(w) / (2 * np.pi),
                                 [[Unbalance(z, amount, 0.0)]], [z])
        return r.amplitude_m[0, :, 0]

    points = np.array([4000.0, 6000.0, 8000.0, 10000.0]) * np.pi / 30  # rad/s
    np.testing.assert_allclose(ours(points), ross(points), rtol=1e-6)
    if int(rs.__version__.split(".")[0]) < 3:
        return
    w = np.linspace(900.0, 1300.0, 801)
    a, b = ours(w), ross(w)
    np.testing.assert_allclose(a, b, rtol=1e-6)
    i, j = int(np.argmax(a)), int(np.argmax(b))
    assert w[i] == pytest.approx(w[j], rel=5e-3)
    assert amplification_factor(w, a, i)[0] == pytest.approx(
        amplification_factor(w, b, j)[0], rel=5e-3)


@pytest.mark.parametrize("name", ["rotor_example", "compressor_example"])
def test_journal_loads_are_ross_31s(name):
    """The journal static loads of ROSS's examples equal ROSS 3.1's ``run_static``
    reactions over g (stored by ``tests/data/ross3/make.py``) to 1e-9: both hold the rotor
    at its bearings alone, the compressor's twelve seals carrying no load."""
    from pathlib import Path

    from ambseal.analysis.signoff.unbalance_api617 import journal_loads

    ref = json.loads((Path(__file__).resolve().parents[1] / "data" / "ross3"
                      / "api617_unbalance.json").read_text())["journal_loads"][name]
    cfg = from_ross(_quiet(getattr(rs, name)), where=name, speed_rpm=9000.0).rig
    loads = journal_loads(cfg)
    assert [z for z, _ in loads] == pytest.approx([z for z, _ in ref], abs=1e-12)
    assert [w for _, w in loads] == pytest.approx([w for _, w in ref], rel=1e-9)


@pytest.mark.parametrize("name", ["rotor_example", "compressor_example"])
def test_api617_unbalance_placement_is_ross_31s(name):
    """API 617's unbalance for any mode shape (9th ed. 6.8.2.7), against ROSS 3.1's
    ``api617_unbalance`` of its own examples at their maximum continuous speed
    (``tests/data/ross3/api617_unbalance.json``, written by ``make.py``): for the first
    three forward modes — one antinode, two at the journals 180° apart, three (the 139 Hz
    mode of ``rotor_example``, where a single unbalance at the largest antinode had given
    203 µm where ROSS's three give 127 µm), and the compressor's overhung ends — the same
    positions, the same phases relative to one another, and the same magnitudes: exact on
    ``rotor_example`` and on the compressor. The compressor's bearing tables end below
    12 000 rpm: ROSS 2.3's,
    without ROSS 3's law, are held there and move its modes up to 0.8 %, so it is checked
    with ROSS 3 (the Python 3.13 suite)."""
    import math
    from pathlib import Path

    from ambseal.analysis.campbell import modes_as_run
    from ambseal.analysis.signoff.unbalance_api617 import (
        _outboard_mass,
        antinode_unbalances,
        journal_loads,
    )

    ref = json.loads((Path(__file__).resolve().parents[1] / "data" / "ross3"
                      / "api617_unbalance.json").read_text())
    rpm = {"rotor_example": 9000.0, "compressor_example": 12000.0}[name]
    if name == "compressor_example" and int(rs.__version__.split(".")[0]) < 3:
        pytest.skip("ROSS 2.3's compressor tables are held beyond 12 000 rpm (docstring)")
    rotor = _quiet(getattr(rs, name))
    cfg = from_ross(rotor, where=name, speed_rpm=rpm).rig
    loads = journal_loads(cfg)
    zs = [z for z, _ in loads]
    outboard = {"left": _outboard_mass(cfg, min(zs), "left"),
                "right": _outboard_mass(cfg, max(zs), "right")}
    m = modes_as_run(cfg, None, speed_hz=rpm / 60.0, max_hz=1000.0)
    for want in ref[name]:
        k = int(np.argmin(np.abs(m.frequency_hz - want["mode_frequency"] / (2 * math.pi))))
        assert m.frequency_hz[k] == pytest.approx(want["mode_frequency"] / (2 * math.pi),
                                                  rel=1e-6)
        _, unb = antinode_unbalances(m.shapes[k, :, 0], m.shapes[k, :, 1], m.node_z_m,
                                     loads, outboard, 2.0, rpm)
        assert [u.position for u in unb] == pytest.approx(want["position"], abs=1e-9)
        assert [u.amount for u in unb] == pytest.approx(want["magnitude"], rel=1e-9)
        rel = [(u.phase_deg - unb[0].phase_deg) % 360 for u in unb]
        assert rel == pytest.approx([math.degrees(p - want["phase"][0]) % 360
                                     for p in want["phase"]], abs=1e-9)


def _amb_rotor(ki_pid: float):
    """ROSS's ``rotor_amb_example`` with the integral gain ``ki_pid`` in both AMBs' PID
    (ROSS's own has none)."""
    ex = _quiet(_amb_example)
    mbs = [_quiet(rs.MagneticBearingElement, n=b.n, g0=float(b.g0), i0=float(b.i0),
                  ag=float(b.ag), nw=float(b.nw), alpha=float(b.alpha),
                  kp_pid=float(b.kp_pid), kd_pid=float(b.kd_pid), ki_pid=ki_pid,
                  n_f=float(b.n_f), k_amp=float(b.k_amp), k_sense=float(b.k_sense),
                  sensors_axis_rotation=float(b.sensors_axis_rotation), tag=b.tag)
           for b in ex.bearing_elements]
    return _quiet(rs.Rotor, ex.shaft_elements, ex.disk_elements, mbs)


@pytest.mark.parametrize("ki_pid", [0.0, 2.0e4])
def test_amb_example_equivalent_bearings_equal_ross(examples, tmp_path, ki_pid):
    """ROSS's ``rotor_amb_example`` (ki_pid = 0, as ROSS has it) and the same with integral
    action, each saved and imported: the AMBs come back as [[amb]] with Ki = ROSS's ki and
    Ks = −ROSS's ks. ROSS folds an AMB into bearing coefficients at one frequency ω,
    k + jωc = ks + ki k_amp k_sense C(jω); comparable with ambseal is that equivalent
    bearing: the imported rig with each AMB replaced by Ki·K(jω) − Ks — K being the
    imported [controller.pid] when ROSS's PID has integral action (which must then equal
    ROSS's own C(s)·k_amp·k_sense at every frequency, 1e-12), ROSS's C(s) otherwise — has
    ROSS's modes with that AMB model at ω = 1000 rad/s to 1e-6, ROSS's Rayleigh damping of
    the shaft elements (α = 2.5 1/s) imported with them."""
    rotor, path = examples["rotor_amb_example"]
    if ki_pid:
        rotor = _amb_rotor(ki_pid)
        path = tmp_path / "amb.toml"
        _quiet(rotor.save, path)
    imp = from_ross(load_ross(path), where=str(path))
    cfg, mbs = imp.rig, rotor.bearing_elements
    for a, mb in zip(cfg.amb, mbs):
        ki, ks = amb_factors(a)
        assert ki == pytest.approx((mb.ki, mb.ki), rel=1e-12)
        assert ks == pytest.approx((-mb.ks, -mb.ks), rel=1e-12) and ks[0] > 0
    assert {(t.rayleigh_alpha, t.rayleigh_beta) for t in cfg.shaft} == {(2.5, 0.0)}
    assert not any("Rayleigh" in n for n in imp.unmapped + imp.notes)
    ross_c = mbs[0].get_analog_controller() * float(mbs[0].k_amp * mbs[0].k_sense)
    if ki_pid:
        p = cfg.controller.pid
        K = pid_controller(p.kp, p.ti, p.td, p.eps, ["a"])
        w = np.logspace(0, 4, 9)
        assert (np.squeeze(K(1j * w)) == pytest.approx(np.squeeze(ross_c(1j * w)), rel=1e-12))
    else:
        assert cfg.controller.pid is None
        assert any("integral action" in n and "kp=1000 A/m" in n for n in imp.unmapped)
        K = ross_c
    w0 = 1000.0
    kc = [complex(np.squeeze(K(1j * w0))) * amb_factors(a)[0][0] - amb_factors(a)[1][0]
          for a in cfg.amb]
    data = cfg.model_dump(exclude_none=True)
    data["amb"], data["actuator"] = [], {"model": "none"}
    data["spring"] = [{"position": a.position, "kxx": k.real, "kyy": k.real,
                       "cxx": k.imag / w0, "cyy": k.imag / w0} for a, k in zip(cfg.amb, kc)]
    data.get("controller", {}).pop("pid", None)
    ross_eq = [_quiet(rs.MagneticBearingElement, n=b.n, g0=float(b.g0), i0=float(b.i0),
                      ag=float(b.ag), nw=float(b.nw), alpha=float(b.alpha),
                      kp_pid=float(b.kp_pid), kd_pid=float(b.kd_pid),
                      ki_pid=float(b.ki_pid), n_f=float(b.n_f), k_amp=float(b.k_amp),
                      k_sense=float(b.k_sense),
                      sensors_axis_rotation=float(b.sensors_axis_rotation),
                      frequency=np.array([w0, 2 * w0]))  # ROSS's formula at w0 exactly
               for b in mbs]
    reference = _quiet(rs.Rotor, rotor.shaft_elements, rotor.disk_elements, ross_eq)
    _assert_modes_equal_ross(parse_rig(data), reference, w0, 1500.0, 12)


def test_amb_rotor_open_loop_unstable_poles_equal_ross():
    """ROSS's AMB test rig (``rotor_amb_example``, in memory): the open-loop unstable poles
    (the AMBs' negative stiffness alone) equal ROSS's frequency-domain AMB model with the
    controller term at zero — ROSS bearings of stiffness ks — on the same rotor, its
    shaft's Rayleigh damping included, to 1e-6."""
    amb = _quiet(_amb_example)
    imp = from_ross(amb)
    mbs = amb.bearing_elements
    assert sum("controller" in n for n in imp.unmapped) == 2  # the k(ω) model, the PID
    springs = [rs.BearingElement(mb.n, kxx=mb.ks, kyy=mb.ks, cxx=0.0) for mb in mbs]
    ref = _ross_eigenvalues(rs.Rotor(amb.shaft_elements, amb.disk_elements, springs), 0.0)
    ref = np.sort(ref[ref.real > 1e-6].real)
    lam = build_system(imp.rig, speed_rpm=0.0).poles()
    got = np.sort(lam[lam.real > 1e-6].real)
    assert len(got) == 4 and np.all(np.abs(lam[lam.real > 1e-6].imag) < 1e-6 * got.max())
    assert got == pytest.approx(ref, rel=1e-6)
    assert channel_names(imp.rig) == ("Magnetic_Bearing_0_zeta", "Magnetic_Bearing_0_eta",
                                      "Magnetic_Bearing_1_zeta", "Magnetic_Bearing_1_eta")


def test_import_ross_cli_round_trip_and_bad_files(tmp_path, capsys):
    """``ambseal import-ross`` on ROSS's own saved file writes a rig that loads back to the
    same modes as :func:`from_ross`; a shaft element with Hutchinson's shear coefficient
    (unsupported), a shaft element
    without its material and a file that is no ROSS rotor each give one line on stderr,
    naming the user's file first (not the embedded rig's), and exit status 2."""
    from ambseal.cli import main
    from ambseal.config import load_rig

    rotor = _bearing_rotor()
    src = tmp_path / "rotor.toml"
    rotor.save(src)
    out = tmp_path / "rig.toml"
    assert main(["import-ross", str(src), "--out", str(out)]) == 0
    summary = json.loads(capsys.readouterr().out)
    assert summary["shaft_elements"] == 6 and summary["springs"] == 2
    a = closed_loop_modes(load_rig(out), None, speed_hz=50.0, max_hz=500.0)
    b = closed_loop_modes(from_ross(rotor).rig, None, speed_hz=50.0, max_hz=500.0)
    assert a.poles == pytest.approx(b.poles, rel=1e-12)

    ex = rs.rotor_example()
    e0 = ex.shaft_elements[0]
    hutchinson = [rs.ShaftElement(L=e0.L, idl=0.0, odl=0.05, material=e0.material,
                                  shear_method_calc="hutchinson")] + ex.shaft_elements[1:]
    rs.Rotor(hutchinson, ex.disk_elements, ex.bearing_elements).save(tmp_path / "hut.toml")
    lines = src.read_text().splitlines()  # drop the first shaft element's material table
    i = next(k for k, ln in enumerate(lines) if ln.endswith('Element 0".material]'))
    j = next(k for k in range(i + 1, len(lines)) if lines[k].startswith("["))
    (tmp_path / "nomat.toml").write_text("\n".join(lines[:i] + lines[j:]))
    (tmp_path / "junk.json").write_text('{"parameters": 1}')
    for name, key in (("hut.toml", "hutchinson"), ("nomat.toml", "material"),
                      ("junk.json", "not a ROSS rotor")):
        assert main(["import-ross", str(tmp_path / name), "--out", str(out)]) == 2
        err = capsys.readouterr().err
        assert err.count("\n") == 1 and key in err and "Traceback" not in err
        assert err.startswith(f"ambseal: error: {tmp_path / name}: ")
        assert "testrig" not in err
    # an error that names no file (a bad option) is put on the user's file, too
    assert main(["import-ross", str(src), "--out", str(out), "--speed-rpm", "1e9"]) == 2
    err = capsys.readouterr().err
    assert err.startswith(f"ambseal: error: {src}: --speed-rpm") and "testrig" not in err


def test_a_file_of_a_newer_ross_is_refused_naming_both_versions(examples, tmp_path, capsys):
    """A rotor file written by a newer ROSS major than the one installed (here ROSS's own
    ``rotor_example`` file with its ``ross_version`` a major up, and past 3, which
    ambseal reads without ROSS): ``import-ross`` exits 2 naming both versions and what to install,
    instead of ROSS's own error on the newer keys ("not a ROSS rotor file (TypeError:
    Rotor.__init__() got an unexpected keyword argument 'default_damping_ratio')")."""
    from ambseal.cli import main

    # one major up, and past ROSS 3, whose files ambseal also reads without ROSS
    newer = f"{max(int(rs.__version__.split('.')[0]) + 1, 4)}.0.0"
    text = examples["rotor_example"][1].read_text()
    assert f'ross_version = "{rs.__version__}"' in text
    src = tmp_path / "newer.toml"
    src.write_text(text.replace(f'ross_version = "{rs.__version__}"',
                                f'ross_version = "{newer}"'))
    assert main(["import-ross", str(src), "--out", str(tmp_path / "rig.toml")]) == 2
    err = capsys.readouterr().err
    assert err == (f"ambseal: error: {src}: saved by ROSS {newer}, which the installed ROSS "
                   f"{rs.__version__} cannot read: install ROSS {newer.split('.')[0]} (ROSS 3 needs "
                   "Python 3.12 or newer; ambseal's 'ross' extra picks the ROSS of its "
                   "Python) and import again\n")


def test_import_chatter_goes_to_stderr(capfd):
    """What a library writes to stdout while ROSS is imported — from Python, at the file
    descriptor, or through C's buffered stdio as CoolProp's REFPROP banner does — ends up
    on stderr; stdout works afterwards."""
    libc = ctypes.CDLL(None)
    c_stdout = ctypes.c_void_p.in_dll(libc, "stdout")  # glibc's, as on the CI machines
    unbuffered = bool(os.environ.get("PYTHONUNBUFFERED")) or "-u" in sys.orig_argv
    buf = ctypes.create_string_buffer(4096)
    if unbuffered:  # python -u leaves C's stdio unbuffered; a user's python does not
        libc.setvbuf(c_stdout, buf, 0, len(buf))  # _IOFBF
    try:
        with _stdout_to_stderr():
            print("python chatter")
            os.write(1, b"fd chatter\n")
            libc.printf(b"C chatter\n")  # left in C's buffer: flushed by the guard
        print("result")
    finally:
        if unbuffered:
            libc.fflush(c_stdout)
            libc.setvbuf(c_stdout, None, 2, 0)  # _IONBF, as it was
    out, err = capfd.readouterr()
    assert out == "result\n"
    assert all(s in err for s in ("python chatter", "fd chatter", "C chatter"))


@pytest.mark.slow  # a fresh interpreter importing ROSS: 10-20 s on 2 cores
def test_import_ross_stdout_is_the_json_only(examples, tmp_path):
    """In a fresh interpreter (where importing ROSS imports ccp, whose CoolProp prints a
    REFPROP banner from C on stdout), ``ambseal import-ross`` of the AMB example writes
    nothing but its JSON summary to stdout; the notes (what was left out, what was taken)
    go to stderr and into the rig file's header."""
    _, path = examples["rotor_amb_example"]
    out = tmp_path / "rig.toml"
    proc = subprocess.run([sys.executable, "-m", "ambseal.cli", "import-ross", str(path),
                           "--out", str(out)], capture_output=True, text=True,
                          timeout=120)
    assert proc.returncode == 0, proc.stderr
    summary = json.loads(proc.stdout)  # the whole of stdout is one JSON document
    assert summary["ambs"] == 2 and summary["controller_pid"] is False
    assert "ambseal: not imported: ROSS's AMB controllers" in proc.stderr
    assert "# not imported: ROSS's AMB controllers" in out.read_text()




def test_ross_is_imported_with_refprop_away_from_the_working_directory(monkeypatch):
    """In this process too (:func:`load_ross`; ``import-ross`` runs ROSS in a child
    process, tests/test_adversarial.py plants a library for it): while ROSS (ccp) is
    imported without a user's ``RPPREFIX``, ``RPPREFIX`` names an empty folder that is not the working
    directory, and is unset again afterwards; a user's own ``RPPREFIX`` is kept."""
    from ambseal.io.ross import _no_refprop_from_cwd

    monkeypatch.delenv("RPPREFIX", raising=False)
    monkeypatch.delitem(sys.modules, "ccp", raising=False)
    with _no_refprop_from_cwd():
        folder = os.environ["RPPREFIX"]
        assert os.listdir(folder) == [] and os.path.abspath(folder) != os.getcwd()
    assert "RPPREFIX" not in os.environ
    monkeypatch.setenv("RPPREFIX", "/opt/refprop")
    with _no_refprop_from_cwd():
        assert os.environ["RPPREFIX"] == "/opt/refprop"

def _fine_bearing_rig(path, total: int):
    """:func:`fine_bearing_data` written to ``path`` and loaded."""
    from ambseal.config import load_rig

    path.write_text(dump(fine_bearing_data(total)), encoding="utf-8")
    return load_rig(path)


@pytest.mark.slow
def test_fine_mesh_modes_equal_ross_on_the_same_mesh(tmp_path, capsys):
    """``ambseal modes`` on the embedded rotor meshed with 230 beam elements (the old bound
    was 150) on plain bearings, at standstill and at 6000 rpm (gyroscopic split): the
    first six modes — eigenvalues from damped frequency and log decrement — equal ROSS
    2.3's of the same rotor on the same mesh to 1e-6 of |λ| (so the log decrements to
    2π·1e-6: the bending pair's δ ≈ 6e-4 is a real part 1e-4 of |λ|, where ROSS's
    unshifted ARPACK carries 4e-9 of |λ|). ROSS by its ARPACK path
    (``_eigen(speed, num_modes, sparse=True)``: its dense eig of 2 800 states takes a
    minute); its axial and torsional modes lie above 1.5 kHz, beyond these six."""
    from ambseal.cli import main

    rig = tmp_path / "fine_bearings.toml"
    cfg = _fine_bearing_rig(rig, 230)
    rotor, n_el = fine_ross_rotor(rs, cfg)
    assert sum(s.elements for s in cfg.shaft) == 230 and n_el >= 230
    for rpm in (0.0, 6000.0):
        assert main(["modes", str(rig), "--json", "--speed-rpm", str(rpm)]) == 0
        out = json.loads(capsys.readouterr().out)
        f = np.asarray(out["natural_frequencies_hz"][:6])
        dec = np.asarray(out["log_decrements"][:6])
        assert len(f) == 6 and f[-1] > 500.0  # the bearing modes and the bending pair
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            ref, _ = rotor._eigen(rpm * np.pi / 30, num_modes=12, sparse=True)
        ref = np.asarray(ref)
        lam = -dec * f + 2j * np.pi * f  # δ = −2π Re λ / Im λ
        near = ref[np.abs(ref[None, :] - lam[:, None]).argmin(axis=1)]
        err = np.abs(lam - near) / np.abs(near)
        assert np.all(err <= 1e-6), (rpm, err)


def _coaxial_rotor():
    """ROSS's co-axial rotor as ROSS's tests build it (``test_rotor_assembly.coaxrotor``):
    two shafts, four disks, three bearings to ground and one linking the shafts."""
    steel = rs.materials.steel
    inner = [rs.ShaftElement(0.25, 0.0, 0.05, material=steel) for _ in range(10)]
    outer = [rs.ShaftElement(0.25, 0.25, 0.30, material=steel) for _ in range(6)]
    disks = [rs.DiskElement.from_geometry(n=n, material=steel, width=0.07, i_d=i, o_d=o)
             for n, i, o in ((1, 0.05, 0.28), (9, 0.05, 0.28), (13, 0.20, 0.48),
                             (15, 0.20, 0.48))]
    bearings = [rs.BearingElement(0, kxx=1e6, kyy=1e6, cxx=0),
                rs.BearingElement(10, kxx=1e6, kyy=1e6, cxx=0),
                rs.BearingElement(11, kxx=1e6, kyy=1e6, cxx=0),
                rs.BearingElement(8, n_link=17, kxx=1e6, kyy=1e6, cxx=0)]
    return _quiet(rs.CoAxialRotor, [inner, outer], disks, bearings)


@pytest.mark.skipif(not hasattr(rs, "CoAxialRotor"), reason="ROSS 3 has no CoAxialRotor "
                    "(its several-shaft rotor is the MultiRotor, tested below)")
def test_coaxial_rotor_is_refused_naming_its_shafts(tmp_path, capsys):
    """ROSS's co-axial rotor, saved by ROSS (whose own loader fails on it with "10 is not
    in list"): ``import-ross`` exits 2 with one line that names the file and says that its
    two shafts are not supported; :func:`from_ross` on the rotor in memory says the same."""
    from ambseal.cli import main
    from ambseal.errors import ConfigError

    rotor = _coaxial_rotor()
    src = tmp_path / "coaxial.toml"
    _quiet(rotor.save, src)
    assert main(["import-ross", str(src), "--out", str(tmp_path / "rig.toml")]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "Traceback" not in err
    assert err.startswith(f"ambseal: error: {src}: 2 shafts (nodes 0–10, nodes 11–17")
    assert "several shafts are not supported" in err and "not in list" not in err
    assert not (tmp_path / "rig.toml").exists()
    with pytest.raises(ConfigError, match="2 shafts .*several shafts are not supported"):
        from_ross(rotor)


def _geared_rotors():
    """The two rotors of ROSS 3's ``MultiRotor`` docstring example (a generator and a
    turbine joined by a gear pair), each on its bearings."""
    steel = rs.materials.steel
    shaft1 = [rs.ShaftElement(L=x, idl=0.0, odl=d, material=steel)
              for x, d in zip([0.1, 4.24, 1.16, 0.3], [0.3, 0.3, 0.22, 0.22])]
    gear1 = rs.GearElement(n=4, m=726.4, Id=56.95, Ip=113.9, n_teeth=328,
                           pitch_diameter=1.1, pr_angle=rs.Q_(22.5, "deg"))
    rotor1 = _quiet(rs.Rotor, shaft1, [rs.DiskElement(n=1, m=525.7, Id=16.1, Ip=32.2),
                                       rs.DiskElement(n=2, m=116.04, Id=3.115, Ip=6.23),
                                       gear1],
                    [rs.BearingElement(n=n, kxx=183.9e6, kyy=200.4e6, cxx=3e3)
                     for n in (0, 3)])
    shaft2 = [rs.ShaftElement(L=x, idl=0.0, odl=0.15, material=steel) for x in [0.3, 5, 0.1]]
    gear2 = rs.GearElement(n=0, m=5, Id=0.002, Ip=0.004, n_teeth=23,
                           base_diameter=0.03567 * 2, pr_angle=rs.Q_(22.5, "deg"))
    rotor2 = _quiet(rs.Rotor, shaft2, [gear2, rs.DiskElement(n=2, m=7.45, Id=0.0745,
                                                             Ip=0.149)],
                    [rs.BearingElement(n=n, kxx=10.1e6, kyy=41.6e6, cxx=3e3) for n in (1, 3)])
    return rotor1, rotor2


@pytest.mark.skipif(not hasattr(rs, "MultiRotor"), reason="ROSS < 3 has no MultiRotor")
def test_multirotor_refused_and_a_gear_of_one_rotor_is_a_disk():
    """ROSS 3's geared MultiRotor (its docstring's example) is refused naming what it is
    and what to do; each of its rotors alone imports, its gear a disk, with ROSS's
    eigenvalues (damped frequency and log decrement) for every lateral mode up to 100 Hz
    to 1e-6 at 0 and 3000 rpm."""
    rotor1, rotor2 = _geared_rotors()
    multi = _quiet(rs.MultiRotor, rotor1, rotor2, coupled_nodes=(4, 0),
                   gear_mesh_stiffness=1e8, orientation_angle=0.0, position="below")
    with pytest.raises(ConfigError, match="MultiRotor .* several shafts coupled by a gear "
                                          "mesh.*import each rotor on its own"):
        from_ross(multi)
    imp = from_ross(rotor1)
    assert len(imp.rig.disk) == 3 and imp.rig.disk[2].mass == pytest.approx(726.4)
    for w in (0.0, 100 * np.pi):
        ref = _ross_eigenvalues(rotor1, w)
        m = closed_loop_modes(imp.rig, None, speed_hz=w / (2 * np.pi), max_hz=100.0)
        assert len(m.poles) >= 4
        for lam in m.poles:
            j = np.argmin(np.abs(ref - lam))
            assert abs(ref[j] - lam) <= 1e-6 * abs(lam)


@pytest.mark.skipif(not _takes(rs.BearingElement, "speed"),
                    reason="ROSS < 3: no coefficient tables over speed and frequency")
def test_tables_over_speed_and_whirl_frequency_equal_ross():
    """ROSS 3 tables over speed and whirl frequency (PCHIP on both axes): an isotropic skew
    seal (K, k, C of both axes) and an anisotropic bearing on ROSS's ``rotor_example``.
    The seal becomes a table at the points of both axes (ROSS's values with whirl frequency
    = speed), the bearing a spring at the import speed; every lateral mode up to 500 Hz and
    its log decrement equal ROSS's synchronous ones to 1e-6 at the import speed and, for
    the seal, at a point of either axis."""
    speed, freq = np.array([100.0, 300.0, 500.0]), np.array([150.0, 400.0])
    grid = np.add.outer(speed, 2 * freq)  # a coefficient that varies along both axes
    seal = rs.BearingElement(n=3, kxx=2e6 + 1e3 * grid, kyy=2e6 + 1e3 * grid,
                             kxy=5e5 + 50 * grid, kyx=-(5e5 + 50 * grid), cxx=80 + 0.1 * grid,
                             cyy=80 + 0.1 * grid, speed=speed, frequency=freq, tag="seal")
    bearings = [rs.BearingElement(n=n, kxx=1e6 + 2e2 * grid, kyy=8e5 + 1e2 * grid,
                                  cxx=150.0 + 0.05 * grid, cyy=90.0 + 0.05 * grid,
                                  speed=speed, frequency=freq, tag=f"B{n}") for n in (0, 6)]
    ex = rs.rotor_example()
    rotor = _quiet(rs.Rotor, ex.shaft_elements, ex.disk_elements, [*bearings, seal])
    imp = from_ross(rotor)
    cfg = imp.rig
    assert [s.name for s in cfg.seal] == ["seal"] and len(cfg.spring) == 2
    assert cfg.seal[0].K.frequency_hz == pytest.approx(
        list(np.unique(np.r_[speed, freq]) / (2 * np.pi)), rel=1e-12)
    _assert_log_decrements_equal_ross(cfg, rotor, cfg.operating.speed_rpm)
    for w in (300.0, 400.0):  # seal tables' points (the springs taken there too)
        at = from_ross(rotor, speed_rpm=w * 30 / np.pi).rig
        _assert_log_decrements_equal_ross(at, rotor, w * 30 / np.pi)


def _rotor8():
    """ROSS's ``rotor8`` as its tests build it: ``rotor_example``'s shaft and disks on two
    bearings whose kxx = kyy and cxx = cyy run linearly from 50 to 5000 rad/s (ROSS 3.1:
    a table over ``speed``; ROSS 2.3: over ``frequency``)."""
    i_d, o_d = 0, 0.05
    shaft = [rs.ShaftElement(0.25, i_d, o_d, material=rs.materials.steel, shear_effects=True,
                             rotary_inertia=True, gyroscopic=True) for _ in range(6)]
    disks = [rs.DiskElement.from_geometry(2, rs.materials.steel, 0.07, 0.05, 0.28),
             rs.DiskElement.from_geometry(4, rs.materials.steel, 0.07, 0.05, 0.35)]
    axis = "speed" if _takes(rs.BearingElement, "speed") else "frequency"
    bearings = [rs.BearingElement(n, kxx=[1e7, 1.5e7], kyy=[1e7, 1.5e7], cxx=[1e3, 1.5e3],
                                  cyy=[1e3, 1.5e3], **{axis: [50, 5000]}) for n in (0, 6)]
    return _quiet(rs.Rotor, shaft, disks, bearings)


@pytest.mark.parametrize("suffix", [".toml", ".json"])
def test_rotor8_equals_ross(tmp_path, suffix):
    """ROSS's ``rotor8`` (its tables over speed in ROSS 3, over frequency in ROSS 2.3),
    saved as TOML and as JSON (ROSS's ``test_save_load``, ``test_save_load_json``) and
    imported at 1000 and 3000 rad/s: two ``[[seal]]`` tables (isotropic bearings) giving
    ROSS's linear values at those speeds, every lateral mode up to 1 kHz with its log
    decrement equal to one of ROSS's eigenvalues there to 1e-6."""
    from ambseal.model import coefficient_value

    rotor = _rotor8()
    src = tmp_path / f"rotor8{suffix}"
    _quiet(rotor.save, src)
    for w in (1000.0, 3000.0):
        cfg = from_ross(load_ross(src), where=str(src), speed_rpm=w * 30 / np.pi).rig
        assert len(cfg.seal) == 2 and cfg.spring == []
        for seal in cfg.seal:  # isotropic skew: seals, tabulated, exact at the speed
            assert coefficient_value(seal.K, 0.0, w / (2 * np.pi)) == pytest.approx(
                1e7 + 5e6 * (w - 50) / 4950, rel=1e-12)
        n = _ross_lateral_count(rotor, w, 1000.0)
        _assert_log_decrements_equal_ross(cfg, rotor, w * 30 / np.pi, 1000.0, n)


def test_ross_test_data_rotor_equals_ross():
    """ROSS's own saved test rotor (``ross/tests/data/rotor.toml``, its ``rotor9``: 55
    layered and plain elements, 7 disks, 14 seals and bearings with coefficient tables,
    written by the installed ROSS's version), imported at the lowest speed every table
    covers: its 8 lateral modes up to 400 Hz and their log decrements equal ROSS's there to
    1e-6."""
    from pathlib import Path

    path = Path(rs.__file__).parent / "tests" / "data" / "rotor.toml"
    if not path.exists():
        pytest.skip(f"ROSS {rs.__version__} ships no tests/data/rotor.toml")
    rotor = _quiet(rs.Rotor.load, path)
    w = max(float(np.min(np.atleast_1d(b.frequency if getattr(b, "speed", None) is None
                                       else b.speed))) for b in rotor.bearing_elements)
    cfg = from_ross(load_ross(path), where=str(path), speed_rpm=w * 30 / np.pi).rig
    assert (len(cfg.shaft), len(cfg.disk), len(cfg.seal) + len(cfg.spring)) == (55, 7, 14)
    _assert_log_decrements_equal_ross(cfg, rotor, w * 30 / np.pi, 400.0, 8)


def test_bearing_with_anisotropic_added_mass_equals_ross():
    """A seal of anisotropic stiffness, damping and added mass (mxx ≠ myy, mxy = myx, as a
    hole-pattern seal's) on ROSS's ``rotor_example`` between its damped bearings: a
    ``[[spring]]`` with the mass terms (before: refused), and the 12 lateral modes up to
    500 Hz with their log decrements equal to ROSS's to 1e-6 at 0 and 4000 rpm."""
    ex = _bearing_rotor()
    seal = rs.BearingElement(n=3, kxx=4e6, kyy=3e6, kxy=1e6, kyx=-8e5, cxx=400.0,
                             cyy=300.0, mxx=2.0, myy=1.2, mxy=0.3, myx=0.3, tag="HP")
    rotor = _quiet(rs.Rotor, ex.shaft_elements, ex.disk_elements, [*ex.bearing_elements, seal])
    cfg = from_ross(rotor).rig
    hp = next(s for s in cfg.spring if s.name == "HP")
    assert (hp.mxx, hp.myy, hp.mxy, hp.myx) == (2.0, 1.2, 0.3, 0.3)
    for speed_rpm in (0.0, 4000.0):
        _assert_log_decrements_equal_ross(cfg, rotor, speed_rpm)


def _coupled_rotor(**link):
    """ROSS's coupled rotor (its ``test_refine_keeps_couplings``: a flexible coupling
    between two shaft elements, on two damped bearings), the coupling's springs and dampers
    ``link``."""
    steel = rs.materials.steel
    coupling = rs.CouplingElement(m_l=10, m_r=10, Ip_l=0.1, Ip_r=0.1, tag="C1", **link)
    shafts = [rs.ShaftElement(L=0.25, idl=0, odl=0.05, material=steel), coupling,
              rs.ShaftElement(L=0.25, idl=0, odl=0.05, material=steel)]
    bearings = [rs.BearingElement(n=n, kxx=1e6, cxx=1e3) for n in (0, 3)]
    return _quiet(rs.Rotor, shafts, bearing_elements=bearings)


def test_coupling_equals_ross(tmp_path):
    """ROSS's coupled rotor with an anisotropic, damped coupling (kt 1e6/8e5 N/m, kr
    2e5/1e5 N·m/rad, ct 50 N·s/m, cr 2 N·m·s/rad, and a torsional stiffness, named as left
    out), saved and imported: a ``coupling``
    section (halves 10 kg, Ip 0.1, Id = Ip/2 as ROSS defaults it), and every lateral mode
    up to 500 Hz with its log decrement equal to ROSS's at 0 and 4000 rpm to 1e-6 (before:
    refused as "2 shafts … a ROSS CoAxialRotor")."""
    rotor = _coupled_rotor(kt_x=1e6, kt_y=8e5, kr_x=2e5, kr_y=1e5, ct_x=50.0, ct_y=50.0,
                           cr_x=2.0, cr_y=2.0, kr_z=3e6)
    src = tmp_path / "coupled.toml"
    _quiet(rotor.save, src)
    imp = from_ross(load_ross(src), where=str(src))
    assert imp.unmapped == ("coupling C1: its axial and torsional springs and dampers (kr_z "
                            "= 3e+06) not imported: no lateral effect",)
    cfg = imp.rig
    c = cfg.shaft[1].coupling
    assert (c.m_left, c.Ip_right, c.Id_left, c.kt_y, c.kr_x) == (10.0, 0.1, 0.05, 8e5, 2e5)
    assert cfg.shaft[0].coupling is None and cfg.shaft[1].length == pytest.approx(0.2)
    ref = _ross_eigenvalues(rotor, 0.0)
    n = int(np.sum((ref.imag > 1.0) & (ref.imag < 2 * np.pi * 500.0)))
    assert n >= 6
    for speed_rpm in (0.0, 4000.0):
        _assert_log_decrements_equal_ross(cfg, rotor, speed_rpm, 500.0, n)
    if not _takes(rs.Rotor, "alpha"):
        return
    # ROSS 3: the rotor's own Rayleigh damping wins over the coupling's dampers, which
    # ROSS then drops: named, not imported, the modes ROSS's
    damped = _quiet(rs.Rotor, rotor.shaft_elements, bearing_elements=rotor.bearing_elements,
                    alpha=3.0)
    imp = from_ross(damped)
    assert imp.rig.shaft[1].coupling.ct_x == 0.0 and imp.rig.rotor.rayleigh_alpha == 3.0
    assert any(u.startswith("the elements' own damping") for u in imp.unmapped)
    _assert_log_decrements_equal_ross(imp.rig, damped, 4000.0, 500.0, n)


def test_elements_ambseal_cannot_take_are_each_named(tmp_path, capsys):
    """A rotor with two elements of a class ambseal does not know (a ROSS disk subclass,
    as a user's or a ROSS extension's element is): one error naming each on a line of its
    own; likewise a support structure (a bearing linked to a housing node, the housing's
    bearing and point mass) beside such an element; saved by ROSS, ``import-ross`` exits
    2 with one line and no traceback. On ROSS 3,
    a rotor with ROSS's induction motor (``motor_example``, which drives the torsional DOF
    only) imports, the motor named once among what was left out."""
    from ambseal.cli import main

    flywheel = type("Flywheel", (rs.DiskElement,), {})
    ex = _bearing_rotor()
    extra = [flywheel(n=n, m=5.0, Id=0.01, Ip=0.02, tag=f"F{n}") for n in (2, 4)]
    rotor = _quiet(rs.Rotor, ex.shaft_elements, [*ex.disk_elements, *extra],
                   ex.bearing_elements)
    with pytest.raises(ConfigError) as info:
        from_ross(rotor, where="fly")
    lines = str(info.value).splitlines()
    assert lines[0] == "fly: 2 item(s) ambseal cannot take (each would change the dynamics):"
    assert [ln.strip() for ln in lines[1:]] == ["Flywheel F2: no ambseal equivalent",
                                                "Flywheel F4: no ambseal equivalent"]
    # one housing behind both bearings (ROSS's support model: a bearing linked to a node
    # with a point mass, on a bearing to ground), a bearing linked to a shaft node and a
    # flywheel: a line each
    housing = [rs.BearingElement(n=0, n_link=7, kxx=1e6, kyy=0.8e6, cxx=150.0, tag="B0"),
               rs.BearingElement(n=6, n_link=7, kxx=1e6, cxx=150.0, tag="B6"),
               rs.BearingElement(n=7, kxx=5e7, cxx=500.0, tag="H"),
               rs.BearingElement(n=2, n_link=4, kxx=1e5, cxx=0.0, tag="L")]
    supported = _quiet(rs.Rotor, ex.shaft_elements, [*ex.disk_elements, extra[0]], housing,
                       point_mass_elements=[rs.PointMass(n=7, m=20.0, tag="P7")])
    with pytest.raises(ConfigError) as info:
        from_ross(supported, where="housing")
    assert [ln.strip() for ln in str(info.value).splitlines()] == [
        "housing: 3 item(s) ambseal cannot take (each would change the dynamics):",
        "bearing 1 (L): linked to node 4, a shaft node: a bearing between two shaft nodes "
        "has no ambseal equivalent",
        "housing node 7: bearings 0 (B0), 2 (B6) share it; an ambseal housing carries one "
        "bearing",
        "Flywheel F2: no ambseal equivalent"]
    src = tmp_path / "fly.toml"
    _quiet(rotor.save, src)
    assert main(["import-ross", str(src), "--out", str(tmp_path / "rig.toml")]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "Traceback" not in err and "Flywheel" in err
    if not hasattr(rs, "MotorElement"):
        return
    from ross.motors.motor_element import motor_example

    driven = _quiet(ex.add_elements, [_quiet(motor_example)])
    imp = from_ross(driven)
    assert sum(u.startswith("motor ") and "no lateral effect" in u for u in imp.unmapped) == 1
    assert imp.rig == from_ross(ex).rig


def _tapered_housing_rotor():
    """ROSS 3.1's ``rotor_tapered_housing`` as its tests build it: a cone 0.1 → 0.2 m with
    its own Rayleigh damping and three cylinders; the left bearing linked to housing node
    5, a 5 kg point mass on a 1e7 N/m support, the right bearing to ground."""
    steel = rs.materials.steel
    shaft = [rs.ShaftElement(L=0.25, idl=0, odl=0.1, idr=0, odr=0.2, material=steel,
                             alpha=1e-4, beta=1e-5)]
    shaft += [rs.ShaftElement(L=0.25, idl=0, odl=0.2, material=steel) for _ in range(3)]
    bearings = [rs.BearingElement(n=0, n_link=5, kxx=1e6, cxx=1e3),
                rs.BearingElement(n=4, kxx=1e6, cxx=1e3),
                rs.BearingElement(n=5, kxx=1e7, cxx=1e3)]
    return _quiet(rs.Rotor, shaft, bearing_elements=bearings,
                  point_mass_elements=[rs.PointMass(n=5, m=5.0)])


def test_tapered_housing_rotor_equals_ross(tmp_path):
    """ROSS's rotor with a housing (``rotor_tapered_housing`` of ROSS 3.1's tests; its
    bearing linked to a housing node, ``n_link``, on ROSS 2.3 as well), saved and
    imported: a ``[[spring]]`` with a ``housing`` of 5 kg on 1e7 N/m, 1e3 N·s/m, the cone's
    Rayleigh damping on its tube, and every lateral mode up to 1 kHz with its log
    decrement equal to one of ROSS's eigenvalues to 1e-6 at 0 and 4000 rpm, as many as
    ROSS's lateral ones, the housing's modes among them."""
    rotor = _tapered_housing_rotor()
    src = tmp_path / "housing.toml"
    _quiet(rotor.save, src)
    imp = from_ross(load_ross(src), where=str(src))
    cfg = imp.rig
    linked = [s for s in cfg.spring if s.housing is not None]
    assert len(cfg.spring) == 2 and len(linked) == 1 and cfg.disk == []
    h = linked[0].housing
    assert (h.mass, h.kxx, h.kyy, h.cxx, h.cyy) == (5.0, 1e7, 1e7, 1e3, 1e3)
    assert cfg.shaft[0].rayleigh_beta == 1e-5
    for speed_rpm in (0.0, 4000.0):
        n = _ross_lateral_count(rotor, speed_rpm * np.pi / 30, 1000.0)
        _assert_log_decrements_equal_ross(cfg, rotor, speed_rpm, 1000.0, n)


def _flags_rotor(shear: bool):
    """ROSS's ``rotor_example_6dof`` shaft (6 elements) with the rotary inertia and
    gyroscopic terms switched off element by element in every combination, two disks, on
    anisotropic damped bearings."""
    ex = _quiet(rs.rotor_example_6dof)
    flags = [(False, True), (True, False), (False, False), (True, True), (False, True),
             (True, False)]
    shafts = [rs.ShaftElement(e.L, e.idl, e.odl, material=e.material, shear_effects=shear,
                              rotary_inertia=ri, gyroscopic=gy)
              for e, (ri, gy) in zip(ex.shaft_elements, flags)]
    b = [rs.BearingElement(n, kxx=1e6, kyy=0.8e6, cxx=150.0, cyy=90.0) for n in (0, 6)]
    return _quiet(rs.Rotor, shafts, ex.disk_elements, b)


def test_rotor_example_6dof_without_rotary_inertia_equals_ross(tmp_path):
    """ROSS's ``rotor_example_6dof`` (E–B elements without rotary inertia, with gyroscopic
    terms), saved and imported: every section has ``rotary_inertia = false``, and its 12
    lateral modes up to 500 Hz at 0 and 100 rad/s equal ROSS's to 1e-6; at 100 rad/s its
    lateral natural frequencies are those ROSS's doctest prints (91.84, 96.36, 274.44 rad/s,
    to its two decimals; ROSS's first, 47.62, is the axial mode on kzz)."""
    rotor = _quiet(rs.rotor_example_6dof)
    path = tmp_path / "6dof.toml"
    _quiet(rotor.save, path)
    cfg = from_ross(load_ross(path), where=str(path)).rig
    assert all(not s.rotary_inertia and s.gyroscopic for s in cfg.shaft)
    assert cfg.rotor.beam == "euler-bernoulli"
    for w in (0.0, 100.0):
        _assert_modes_equal_ross(cfg, rotor, w, 500.0, 12)
    m = closed_loop_modes(cfg, None, speed_hz=100.0 / (2 * np.pi), max_hz=60.0)
    assert np.round(np.abs(m.poles[:3]), 2) == pytest.approx([91.84, 96.36, 274.44])


@pytest.mark.parametrize("shear", [True, False])
def test_rotary_inertia_and_gyroscopic_per_element_equal_ross(shear):
    """Each combination of ROSS's ``rotary_inertia`` and ``gyroscopic`` flags, element by
    element, on Timoshenko and E–B elements: the imported sections carry them, and every
    lateral mode up to 1 kHz (damped frequency and log decrement) equals ROSS's at 0 and
    5000 rpm to 1e-6."""
    rotor = _flags_rotor(shear)
    cfg = from_ross(rotor).rig
    assert [(s.rotary_inertia, s.gyroscopic) for s in cfg.shaft] == [
        (e.rotary_inertia, e.gyroscopic) for e in rotor.shaft_elements]
    for rpm in (0.0, 5000.0):
        _assert_modes_equal_ross(cfg, rotor, rpm * np.pi / 30, 1000.0, 16)


def _loaded_rotor(**load):
    """The rotor of ROSS's ``test_axial_force`` and ``test_torque`` (six 0.25 m Timoshenko
    elements of d = 50 mm, two disks from geometry, bearings of 1e6 N/m), each element
    carrying ``load`` (``axial_force`` in N and/or ``torque`` in N·m)."""
    steel = rs.Material("steel", E=211e9, G_s=81.2e9, rho=7810)
    bearings = [rs.BearingElement(n=n, kxx=1e6, cxx=0, scale_factor=2) for n in (0, 6)]
    disks = [rs.DiskElement.from_geometry(n=n, material=steel, width=0.07, i_d=0.05, o_d=o,
                                          scale_factor="mass")
             for n, o in ((2, 0.28), (4, 0.35))]
    shaft = [rs.ShaftElement(L=0.25, idl=0, odl=0.05, material=steel, **load)
             for _ in range(6)]
    return _quiet(rs.Rotor, shaft_elements=shaft, disk_elements=disks,
                  bearing_elements=bearings)


@pytest.mark.parametrize(("load", "asserted"), [
    ({"axial_force": 100e3}, [93.416071, 95.2335, 267.475281, 309.918575, 634.40757]),
    ({"torque": 100e3}, [81.324905, 84.769077, 242.822862, 286.158147, 591.519983]),
])
def test_axial_force_and_torque_equal_ross(tmp_path, load, asserted):
    """ROSS's ``test_axial_force`` (100 kN) and ``test_torque`` (100 kN·m) rotors, saved and
    imported: every section carries the load, every lateral mode up to 200 Hz equals
    ROSS's to 1e-6 at 0 and 4000 rpm, and at 4000 rpm the damped natural frequencies are
    the five lateral ones ROSS's tests assert (rad/s; ROSS's sixth, 650.41 rad/s, is the
    torsional mode, the same in both and without a load). A compressive force of the same
    size softens the shaft, as ROSS has it too."""
    rotor = _loaded_rotor(**load)
    path = tmp_path / "loaded.toml"
    _quiet(rotor.save, path)
    cfg = from_ross(load_ross(path), where=str(path)).rig
    (key, value), = load.items()
    assert all(getattr(s, key) == value for s in cfg.shaft)
    assert parse_rig(tomllib.loads(dump_rig(cfg))) == cfg
    for rpm in (0.0, 4000.0):
        _assert_modes_equal_ross(cfg, rotor, rpm * np.pi / 30, 200.0, 8)
    m = closed_loop_modes(cfg, None, speed_hz=4000 / 60, max_hz=200.0)
    assert np.sort(m.poles.imag)[:5] == pytest.approx(asserted, rel=1e-6)
    if key == "axial_force":
        soft = _loaded_rotor(axial_force=-value)
        cfg_soft = from_ross(soft).rig
        _assert_modes_equal_ross(cfg_soft, soft, 4000 * np.pi / 30, 200.0, 8)
        low = closed_loop_modes(cfg_soft, None, speed_hz=4000 / 60, max_hz=200.0)
        assert np.sort(low.poles.imag)[0] < 0.85 * asserted[0]


def _conical_rotor(k: float):
    """ROSS's ``rotor_conical`` as ROSS's tests build it (``test_rotor_assembly``): a solid
    cone 0.5 m long from d = 100 mm to 10 mm in four conical elements, on bearings of
    stiffness ``k`` at its ends (ROSS's 1e20 N/m is beyond the rig file's 1e12)."""
    n, odl, odr = 4, 0.1, 0.01
    dd = (odl - odr) / n
    shaft = [rs.ShaftElement(n=i, idl=0.0, odl=odl - i * dd, idr=0.0, odr=odl - (i + 1) * dd,
                             material=rs.materials.steel, L=0.5 / n) for i in range(n)]
    bearings = [rs.BearingElement(n=i, kxx=k, kyy=k, cxx=0) for i in (0, n)]
    return _quiet(rs.Rotor, shaft_elements=shaft, bearing_elements=bearings)


def test_conical_rotor_equals_ross_and_its_asserted_frequencies(tmp_path):
    """ROSS's conical rotor, saved and imported: four tapered sections (Genta & Gugliotta's
    conical element, as ROSS's); on 1e12 N/m bearings every lateral mode up to 5 kHz equals
    ROSS's to 1e-6 at standstill and at 30 000 rpm. Pinned at both ends — the limit of
    ROSS's 1e20 N/m bearings — the imported shaft's natural frequencies are those ROSS's
    ``test_rotor_conical_frequencies`` asserts (1630.75, 9899.54, 21074.45 rad/s, each
    twice) to 1e-7, the spread of ROSS's own pairs. The cone as one section of four
    elements (``outer_diameter_right``, diameters interpolated by the mesh) has the same
    modes to 1e-12."""
    from ambseal.model.rotor import assemble_rotor

    rotor = _conical_rotor(1e12)
    path = tmp_path / "conical.toml"
    _quiet(rotor.save, path)
    cfg = from_ross(load_ross(path), where=str(path)).rig
    assert [s.outer_diameter_right for s in cfg.shaft] == pytest.approx(
        [0.0775, 0.055, 0.0325, 0.01], rel=1e-12)
    for rpm in (0.0, 30000.0):
        _assert_modes_equal_ross(cfg, rotor, rpm * np.pi / 30, 5000.0, 6)
    r = assemble_rotor(cfg)
    n = r.K.shape[0]
    keep = np.array([i for i in range(n) if i not in (0, 1, n - 4, n - 3)])
    w = np.sqrt(sla.eigh(r.K[np.ix_(keep, keep)], r.M[np.ix_(keep, keep)],
                         eigvals_only=True)[:6])
    asserted = [1630.7509182, 1630.75091824, 9899.54379138, 9899.54396231,
                21074.45440319, 21074.45440372]
    assert w == pytest.approx(asserted, rel=1e-7)
    data = cfg.model_dump(exclude_none=True)
    data["shaft"] = [{"length": 0.5, "outer_diameter": 0.1, "outer_diameter_right": 0.01,
                      "material": cfg.shaft[0].material, "elements": 4}]
    one = closed_loop_modes(parse_rig(data), None, speed_hz=0.0, max_hz=5000.0)
    four = closed_loop_modes(cfg, None, speed_hz=0.0, max_hz=5000.0)
    assert one.poles == pytest.approx(four.poles, rel=1e-12)


def test_ross_pinned_conical_rotor_is_imported_with_pins(tmp_path):
    """ROSS's ``rotor_conical`` exactly as ROSS's tests build it, on 1e20 N/m bearings (its
    way of pinning a node), saved and imported: the bearings become springs at the rig
    file's stiffest support, 1e17 N/m, each with a note, and the rotor's natural frequencies
    are those ROSS's ``test_rotor_conical_frequencies`` asserts (1630.75, 9899.54, 21074.45
    rad/s) to 1e-6."""
    rotor = _conical_rotor(1e20)
    path = tmp_path / "pinned.toml"
    _quiet(rotor.save, path)
    imp = from_ross(load_ross(path), where=str(path))
    assert [(sp.kxx, sp.kyy) for sp in imp.rig.spring] == [(1e17, 1e17)] * 2
    assert sum("taken as a pin, 1e+17 N/m" in n for n in imp.notes) == 4
    m = closed_loop_modes(imp.rig, None, speed_hz=0.0, max_hz=5000.0)
    w = np.sort(np.abs(m.poles))
    asserted = [1630.7509182, 1630.75091824, 9899.54379138, 9899.54396231,
                21074.45440319, 21074.45440372]
    assert w == pytest.approx(asserted, rel=1e-6)


@pytest.mark.skipif(not _takes(rs.MagneticBearingElement, "sensor_node"),
                    reason="ROSS < 3: an AMB's sensor is at the bearing (no sensor_node)")
def test_amb_sensor_node_is_the_sensor_position():
    """ROSS 3's AMB rotor (``rotor_example_amb_simple``: AMBs on nodes 1 and 9 of ten
    0.1 m elements) with each sensor one node outboard (``sensor_node`` 0 and 10): the
    imported AMBs keep their actuators at 0.1 and 0.9 m and put their sensors at 0 and
    1.0 m: the model's sensor nodes are ROSS's sensor nodes."""
    from ross.bearings.magnetic.amb_models import rotor_example_amb_simple

    ex = _quiet(rotor_example_amb_simple)
    keys = ("g0", "i0", "ag", "nw", "kp_pid", "kd_pid", "ki_pid", "k_amp", "k_sense")
    mbs = [_quiet(rs.MagneticBearingElement, n=b.n, sensor_node=s, tag=b.tag,
                  **{k: float(np.asarray(getattr(b, k))) for k in keys})
           for b, s in zip(ex.bearing_elements, (0, 10))]
    rotor = _quiet(rs.Rotor, ex.shaft_elements, ex.disk_elements, mbs)
    cfg = from_ross(rotor).rig
    got = [(a.position, a.sensor_position) for a in cfg.amb]
    assert np.asarray(got) == pytest.approx(np.array([(0.1, 0.0), (0.9, 1.0)]), abs=1e-12)
    mesh = build_mesh(cfg)
    assert [(e.bearing_node, e.sensor_node) for e in
            (AmbElement.from_config(a, mesh) for a in cfg.amb)] == [(1, 0), (9, 10)]


@pytest.mark.parametrize("shear", [True, False])
def test_hollow_tapered_elements_with_loads_equal_ross(shear):
    """ROSS's ``rotor_example`` with its shaft made of hollow cones (bore and outside
    tapering, widening and narrowing in turn) carrying an axial force and a torque, on the
    Timoshenko and the E–B element: every lateral mode up to 1 kHz equals ROSS's to 1e-6 at
    0 and 6000 rpm."""
    ex = rs.rotor_example()
    ends = [(0.0, 0.05), (0.01, 0.06), (0.0, 0.045), (0.012, 0.055), (0.005, 0.05),
            (0.0, 0.04), (0.01, 0.05)]
    shafts = [rs.ShaftElement(e.L, ends[i][0], ends[i][1], idr=ends[i + 1][0],
                              odr=ends[i + 1][1], material=e.material, shear_effects=shear,
                              axial_force=2e4, torque=-1e3)
              for i, e in enumerate(ex.shaft_elements)]
    b = [rs.BearingElement(n, kxx=1e6, kyy=0.8e6, cxx=150.0, cyy=90.0) for n in (0, 6)]
    rotor = _quiet(rs.Rotor, shafts, ex.disk_elements, b)
    cfg = from_ross(rotor).rig
    assert all(s.inner_diameter_right is not None for s in cfg.shaft[:5])
    for rpm in (0.0, 6000.0):
        _assert_modes_equal_ross(cfg, rotor, rpm * np.pi / 30, 1000.0, 14)


def test_level1_screening_equals_the_same_sweep_in_ross():
    """API 617 Level I on ROSS's ``rotor_example`` on damped anisotropic bearings, imported:
    the same cross-coupling element (``BearingElement(kxy=Q, kyx=−Q)`` at mid-span, node
    3) added to ROSS's rotor and its eigenvalues at the same speed (ROSS 2.3's own modal
    analysis, side by side). The screened mode's log decrement at Q_A equals ROSS's of
    the same mode to 1 %, and Q_0, where ROSS's mode loses its damping (found here by
    bisection on ROSS's eigenvalues), equals ambseal's to 1 %."""
    from scipy.optimize import brentq

    from ambseal.analysis.signoff.level1 import level1_screening

    rotor = _bearing_rotor()
    doc = tomllib.loads(dump_rig(from_ross(rotor).rig))
    doc["stage"] = [{"position": 0.75, "power": 2.0e4, "impeller_diameter": 0.3,
                     "discharge_width": 0.02, "suction_density": 10.0,
                     "discharge_density": 12.0}]
    doc["operating"] = {"speed_rpm": 4000.0}
    r = level1_screening(parse_rig(doc))
    w = 4000.0 * np.pi / 30

    def ross_mode(Q: float, near: complex) -> complex:
        b = [*rotor.bearing_elements, rs.BearingElement(3, kxx=0.0, cxx=0.0, kyy=0.0,
                                                        kxy=Q, kyx=-Q, tag="Q")]
        lam = _ross_eigenvalues(rs.Rotor(rotor.shaft_elements, rotor.disk_elements, b), w)
        return lam[np.argmin(np.abs(lam - near))]

    def ours(i: int) -> complex:  # the screened pole at grid point i, from (f_d, δ)
        wd = 2 * np.pi * r.frequency_hz[i]
        return complex(-r.log_dec[i] * wd / (2 * np.pi), wd)

    iA = int(np.argmin(np.abs(r.Q - r.Q_A)))
    lam_A = ross_mode(r.Q_A, ours(iA))
    assert r.log_dec_A == pytest.approx(-2 * np.pi * lam_A.real / lam_A.imag, rel=0.01)
    assert r.Q_0 is not None and r.converged
    i0 = int(np.searchsorted(r.Q, r.Q_0))
    a, b = float(r.Q[i0 - 1]), float(r.Q[i0])
    q0_ross = brentq(lambda Q: ross_mode(Q, ours(i0 - 1 if Q - a < b - Q else i0)).real,
                     a, b, xtol=1e-6 * r.Q_A)
    assert r.Q_0 == pytest.approx(q0_ross, rel=0.01)


def _gear_motor_rotor():
    """ROSS 3's ``rotor_example`` with a gear on node 3 (a disk with teeth) and its
    induction motor (no matrices: named, left out), modal damping ratios on it."""
    from ross.motors.motor_element import motor_example

    ex = rs.rotor_example()
    gear = rs.GearElement(n=3, m=8.0, Id=0.03, Ip=0.06, n_teeth=40, pitch_diameter=0.2)
    geared = _quiet(rs.Rotor, ex.shaft_elements, [*ex.disk_elements, gear],
                    ex.bearing_elements, modal_damping_ratio=[0.01, 0.02, 0.03, 0.04, 0.05])
    return _quiet(geared.add_elements, [_quiet(motor_example)])


@pytest.mark.skipif(not _takes(rs.BearingElement, "speed"),
                    reason="ROSS < 3: no ROSS 3 file to read")
def test_ross3_file_read_without_ross_equals_the_ross_import(examples, tmp_path):
    """Every ROSS 3 rotor the importer is checked on against ROSS's modes, saved by ROSS 3
    and read by ambseal's reader of the format (no ROSS: what Python 3.11 with ROSS 2.3
    does), gives the same rig, the same items left out and the same notes as the import
    through ROSS — tables over speed and whirl frequency (pchip, linear, extrapolated), a
    magnetic bearing with a non-collocated sensor, a coupling and a point mass, layered and
    tapered elements with loads, 1e20 N/m pins, a housing, a rotor's Rayleigh damping and
    modal damping ratios — ROSS counts them over its axial and torsional modes too, which
    the reader takes from ROSS's six-DOF model: on a rotor whose first torsional mode lies
    among the modes given a ratio, the lateral ones skip the ratio it took."""
    from ambseal.io.ross_file import read_ross3_file

    speed, freq = np.array([100.0, 300.0, 500.0]), np.array([150.0, 400.0])
    grid = np.add.outer(speed, 2 * freq)
    seal = rs.BearingElement(n=3, kxx=2e6 + 1e3 * grid, kyy=2e6 + 1e3 * grid,
                             kxy=5e5 + 50 * grid, kyx=-(5e5 + 50 * grid), cxx=80 + 0.1 * grid,
                             cyy=80 + 0.1 * grid, speed=speed, frequency=freq, tag="seal")
    ex = rs.rotor_example()
    lin = [rs.BearingElement(n=n, kxx=[1e6, 3e6, 4e6], kyy=[8e5, 1e6, 2e6], cxx=150.0,
                             speed=[50.0, 200.0, 900.0], interpolation=kind, tag=f"B{n}")
           for n, kind in ((0, "linear"), (6, "pchip"))]
    rotors = {
        "tables": _quiet(rs.Rotor, ex.shaft_elements, ex.disk_elements, [*lin, seal]),
        "rayleigh": _quiet(rs.Rotor, ex.shaft_elements, ex.disk_elements,
                           _bearing_rotor().bearing_elements, alpha=3.0, beta=2e-5),
        "coupling": _coupled_rotor(kt_x=1e6, kt_y=8e5, kr_x=2e5, kr_y=1e5, ct_x=50.0,
                                   ct_y=50.0, cr_x=2.0, cr_y=2.0, kr_z=3e6),
        "pinned": _conical_rotor(1e20),
        "housing": _tapered_housing_rotor(),
        "modal": _modal_damping_rotor(modal_damping_ratio=[0.001, 0.001],
                                      default_damping_ratio=0.01),
        # ratios past ROSS's first torsional mode (650 rad/s), which they count too
        "modal_torsion": _modal_damping_rotor(
            modal_damping_ratio=[0.001 * (k + 1) for k in range(14)],
            default_damping_ratio=0.03),
        # overhung: no element on the shaft's last node but the shaft's
        "modal_overhung": _quiet(rs.Rotor, ex.shaft_elements, ex.disk_elements,
                                 [rs.BearingElement(n, kxx=1e6, kyy=0.8e6, cxx=0)
                                  for n in (0, 3)],
                                 modal_damping_ratio=[0.01, 0.02, 0.03, 0.04, 0.05, 0.06],
                                 default_damping_ratio=0.02),
        "compressor": examples["compressor_example"][0],
        "gear_motor": _gear_motor_rotor(),
        "amb": examples["rotor_amb_example"][0],
    }
    for name, rotor in rotors.items():
        path = tmp_path / f"{name}.toml"
        _quiet(rotor.save, path)
        data = tomllib.loads(path.read_text())
        for speed_rpm in (None, 2500.0):
            ross = from_ross(load_ross(path), where=str(path), speed_rpm=speed_rpm)
            own = from_ross(read_ross3_file(path, data), where=str(path), speed_rpm=speed_rpm)
            assert own.rig == ross.rig, name
            assert (own.unmapped, own.notes) == (ross.unmapped, ross.notes), name
        if name == "modal_torsion":  # ROSS's 5th and 14th flexible modes are not lateral
            assert own.rig.rotor.supported_modal_damping.ratios == [
                0.001 * (k + 1) for k in range(14) if k + 1 not in (5, 14)]



def _ross_ucs_wn(rotor, k: float) -> np.ndarray:
    """ROSS's ``run_ucs`` at one stiffness, its own loop body (ROSS 2.3 to 3.1: the shaft's
    proportional damping set to zero, every bearing but the seals and the links
    ``BearingElement(n, kxx=k, cxx=0)``, ``convert_6dof_to_4dof``, the modes at speed 0,
    each pair of |λ| once) with the dense eigen-solve that ``run_modal`` reports, without
    its post-processing (15 s for ``compressor_example`` on ROSS 2.3): its 4 lowest
    (rad/s)."""
    import copy

    from ross.utils import convert_6dof_to_4dof

    shafts = copy.deepcopy(rotor.shaft_elements)
    for sh in shafts:
        sh.alpha = sh.beta = 0
    springs = [rs.BearingElement(b.n, kxx=k, cxx=0) for b in rotor.bearing_elements
               if not isinstance(b, rs.SealElement) and b.n not in rotor.link_nodes]
    r = _quiet(convert_6dof_to_4dof, _quiet(rotor.__class__, shaft_elements=shafts,
                                            disk_elements=rotor.disk_elements,
                                            bearing_elements=springs))
    lam = _ross_eigenvalues(r, 0.0)
    return np.sort(np.abs(lam[lam.imag > 0]))[::2][:4]


def test_undamped_critical_speed_map_equals_ross(examples):
    """API 684's undamped critical speed map of ROSS's ``rotor_example`` and
    ``compressor_example`` (layered shaft, seals, bearing tables), imported, equals ROSS's
    ``run_ucs`` loop on the same rotors (:func:`_ross_ucs_wn`, side by side, ROSS 2.3 or
    3.1; ``run_ucs`` itself in the slow test below). The same definition — every bearing
    but the seals an isotropic spring k, undamped, at standstill, each plane's
    frequencies once, the 4 lowest — at 1e5 to 1e10 N/m, to 1e-6."""
    from ambseal.analysis.signoff.ucs_map import ucs_map

    k = np.logspace(5, 10, 4)
    for name in ("rotor_example", "compressor_example"):
        rotor = examples[name][0]
        ours = ucs_map(from_ross(rotor).rig, stiffness=k)
        ross = np.column_stack([_ross_ucs_wn(rotor, kj) for kj in k])
        np.testing.assert_allclose(ours.critical_hz, ross / (2 * np.pi), rtol=1e-6)


@pytest.mark.slow
def test_undamped_critical_speed_map_equals_ross_run_ucs(examples):
    """As above, against ROSS's ``Rotor.run_ucs`` itself (25 s on ROSS 2.3: its modal
    post-processing compiles with numba, and ``compressor_example`` takes 15 s)."""
    from ambseal.analysis.signoff.ucs_map import ucs_map

    k = np.logspace(5, 10, 6)
    for name in ("rotor_example", "compressor_example"):
        rotor = examples[name][0]
        ross = _quiet(rotor.run_ucs, stiffness_range=(5, 10), num=6)
        ours = ucs_map(from_ross(rotor).rig, stiffness=k)
        np.testing.assert_allclose(ours.stiffness, np.asarray(ross.stiffness_log),
                                   rtol=1e-12)
        np.testing.assert_allclose(ours.critical_hz, np.asarray(ross.wn) / (2 * np.pi),
                                   rtol=1e-6)
