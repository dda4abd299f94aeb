"""ROSS rotors in (io/ross.py), side by side with ROSS 2.3 (ross-rotordynamics, the ``ross``
extra). ROSS's eigenvalues are those of ``Rotor._eigen(speed, sparse=False)``, the dense
solve whose results ``run_modal`` reports (``run_modal`` itself adds a numba-compiled orbit
post-processing that takes a minute to compile on first call)."""

from __future__ import annotations

import contextlib
import json
import sys
import tomllib
import warnings

import numpy as np
import pytest

with contextlib.redirect_stdout(sys.stderr), warnings.catch_warnings():
    warnings.simplefilter("ignore")
    rs = pytest.importorskip("ross", reason="ross-rotordynamics (the 'ross' extra) is not "
                                            "installed")

from ambseal.analysis.campbell import closed_loop_modes  # noqa: E402
from ambseal.io.ross import from_ross  # noqa: E402

from ..finemesh import fine_rig_text  # noqa: E402
from ..toml_text import dump  # noqa: E402


def _ross_eigenvalues(rotor, speed_rad_s: float) -> np.ndarray:
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        lam, _ = rotor._eigen(speed_rad_s, sparse=False)
    return np.asarray(lam)


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
    w = speed_rpm * np.pi / 30
    ref = _ross_eigenvalues(rotor, w)
    m = closed_loop_modes(imp.rig, None, speed_hz=speed_rpm / 60, max_hz=500.0)
    assert len(m.poles) == 12
    for lam, dec in zip(m.poles, m.log_decrement):
        j = np.argmin(np.abs(ref - lam))
        assert abs(ref[j] - lam) <= 1e-6 * abs(lam)
        assert dec == pytest.approx(-2 * np.pi * ref[j].real / ref[j].imag, rel=1e-6)


def test_amb_rotor_open_loop_unstable_poles_equal_ross():
    """ROSS's AMB test rig (``rotor_amb_example``): the imported AMBs carry ROSS's Ki and
    −Ks (ROSS's negative-stiffness sign), the controller and the shafts' Rayleigh damping are
    reported as not imported, and the open-loop unstable poles (the AMBs' negative stiffness
    alone) equal ROSS's frequency-domain AMB model with the controller term at zero — ROSS
    bearings of stiffness ks — on the same rotor without Rayleigh damping, to 1e-6."""
    from ambseal.model.amb import amb_factors
    from ambseal.model.rig import build_system

    with contextlib.redirect_stdout(sys.stderr), warnings.catch_warnings():
        warnings.simplefilter("ignore")
        amb = rs.rotor_amb_example()
    imp = from_ross(amb)
    mbs = amb.bearing_elements
    for a, mb in zip(imp.rig.amb, mbs):
        ki, ks = amb_factors(a)
        assert ki == pytest.approx((mb.ki, mb.ki), rel=1e-12)
        assert ks == pytest.approx((-mb.ks, -mb.ks), rel=1e-12) and ks[0] > 0
    assert any("Rayleigh" in n for n in imp.unmapped)
    assert sum("controller" in n for n in imp.unmapped) == 2
    shafts = [rs.ShaftElement(L=e.L, idl=e.idl, odl=e.odl, material=e.material, alpha=0.0,
                              shear_effects=True, rotary_inertia=True, gyroscopic=True)
              for e in amb.shaft_elements]
    springs = [rs.BearingElement(mb.n, kxx=mb.ks, kyy=mb.ks, cxx=0.0) for mb in mbs]
    ref = _ross_eigenvalues(rs.Rotor(shafts, amb.disk_elements, springs), 0.0)
    ref = np.sort(ref[ref.real > 1e-6].real)
    lam = build_system(imp.rig, speed_rpm=0.0).poles()
    got = np.sort(lam[lam.real > 1e-6].real)
    assert len(got) == 4 and np.all(np.abs(lam[lam.real > 1e-6].imag) < 1e-6 * got.max())
    assert got == pytest.approx(ref, rel=1e-6)


def test_import_ross_cli_round_trip_and_bad_files(tmp_path, capsys):
    """``ambseal import-ross`` on ROSS's own saved file writes a rig that loads back to the
    same modes as :func:`from_ross`; a tapered shaft element (unsupported), a shaft element
    without its material and a file that is no ROSS rotor each give one line on stderr and
    exit status 2."""
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
    tapered = [rs.ShaftElement(L=e0.L, idl=0.0, odl=0.05, idr=0.0, odr=0.04,
                               material=e0.material)] + ex.shaft_elements[1:]
    rs.Rotor(tapered, ex.disk_elements, ex.bearing_elements).save(tmp_path / "tapered.toml")
    lines = src.read_text().splitlines()  # drop the first shaft element's material table
    i = next(k for k, ln in enumerate(lines) if ln.endswith('Element 0".material]'))
    j = next(k for k in range(i + 1, len(lines)) if lines[k].startswith("["))
    (tmp_path / "nomat.toml").write_text("\n".join(lines[:i] + lines[j:]))
    (tmp_path / "junk.json").write_text('{"parameters": 1}')
    for name, key in (("tapered.toml", "tapered"), ("nomat.toml", "material"),
                      ("junk.json", "not a ROSS rotor")):
        assert main(["import-ross", str(tmp_path / name), "--out", str(out)]) == 2
        err = capsys.readouterr().err
        assert err.count("\n") == 1 and key in err and "Traceback" not in err


#: Plain bearings of the fine-mesh comparison (anisotropic and damped, as ``_bearing_rotor``'s).
FINE_BEARING = {"kxx": 1.0e6, "kyy": 0.8e6, "cxx": 150.0, "cyy": 90.0}


def _fine_bearing_rig(path, total: int):
    """The embedded rotor — shaft and disks — meshed with ``total`` beam elements, on two
    plain bearings at its AMBs' positions instead of AMBs, seal and coupling (ROSS's AMB
    model is not the reference), without modal damping (ROSS has none)."""
    from ambseal.config import load_rig

    data = tomllib.loads(fine_rig_text(total))
    data["rotor"]["modal_damping"] = 0.0
    data["spring"] = [{"position": a["position"], "name": f"bearing_{a['name']}",
                       **FINE_BEARING} for a in data.pop("amb")]
    for key in ("seal", "controller", "design"):
        data.pop(key, None)
    path.write_text(dump(data), encoding="utf-8")
    return load_rig(path)


def _ross_of(cfg):
    """The same rotor in ROSS, element by element on ambseal's mesh (Cowper's shear
    coefficient on both sides)."""
    from ambseal.model.rotor import build_mesh

    mesh = build_mesh(cfg)
    (mat,) = cfg.materials.values()
    steel = rs.Material(name="fine_steel", rho=mat.rho, E=mat.E, G_s=mat.shear_modulus)
    shafts = [rs.ShaftElement(L=e.length, idl=e.inner_diameter, odl=e.outer_diameter,
                              material=steel, n=i, shear_method_calc="cowper")
              for i, e in enumerate(mesh.elements)]
    disks = [rs.DiskElement(n=mesh.node_at(d.position), m=d.mass, Id=d.Id, Ip=d.Ip)
             for d in cfg.disk]
    bearings = [rs.BearingElement(mesh.node_at(s.position), **FINE_BEARING, tag=s.name)
                for s in cfg.spring]
    with contextlib.redirect_stdout(sys.stderr), warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return rs.Rotor(shafts, disks, bearings), len(mesh.elements)


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
    rotor, n_el = _ross_of(cfg)
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
