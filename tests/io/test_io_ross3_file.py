"""ROSS 3.1 rotor files imported on any Python: through ROSS where ROSS 3 is installed,
else by ambseal's reader of the format (io/ross_file.py; Python 3.11 has ROSS 2.3, which
cannot read them). The files and ROSS 3.1's eigenvalues beside them are written by
``tests/data/ross3/make.py`` with ROSS 3.1."""

from __future__ import annotations

import copy
import importlib.metadata
import json
import re
import shutil
import tempfile
import tomllib
from pathlib import Path

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from ambseal.analysis.campbell import closed_loop_modes
from ambseal.cli import main
from ambseal.config import load_rig
from ambseal.errors import ConfigError

DATA = Path(__file__).resolve().parents[1] / "data" / "ross3"


def _ross_major() -> int | None:
    try:
        return int(importlib.metadata.version("ross-rotordynamics").split(".")[0])
    except importlib.metadata.PackageNotFoundError:
        return None


@pytest.mark.parametrize("name, speed_rad_s", [
    *((n, w) for n in ("tables", "modal") for w in (150.0, 300.0, 400.0)),
    *(("seals", w) for w in (300.0, 523.6, 700.0, 900.0))])
def test_ross3_file_modes_equal_ross_31(tmp_path, capsys, name, speed_rad_s):
    """ROSS 3.1's files, imported by ``ambseal import-ross --speed-rpm``: ``tables``,
    ``rotor_example`` on bearings tabulated over speed (linear and pchip, extrapolated) and
    a seal over speed and whirl frequency, with the rotor's Rayleigh damping; ``modal``,
    ROSS's ``test_modal_damping`` rotor with 14 modal damping ratios, which ROSS counts
    over its torsional and axial modes too (its 5th and 14th flexible ones: the lateral
    modes skip those ratios); ``seals``, ROSS's own ROSS 2 test rotor with a labyrinth seal
    tabulated at 523.6 and 837.8 rad/s and a hole-pattern seal, converted by ROSS 3.1's
    ``ross_2to3`` (their radial clearances imported): below, on, between and beyond the
    labyrinth's points, where ROSS
    continues the table with its end slopes (a table held at its ends put the mode at
    124 Hz at δ 0.009 at 300 rad/s where ROSS has 0.867). Every lateral mode up to 500 Hz
    (damped frequency and log decrement) equals one of ROSS 3.1's eigenvalues at that
    speed to 1e-6; where no ROSS 3 is installed the rig file says it was read without
    ROSS."""
    src = tmp_path / f"{name}.toml"
    shutil.copy(DATA / f"{name}.toml", src)
    out = tmp_path / "rig.toml"
    rpm = speed_rad_s * 30 / np.pi
    assert main(["import-ross", str(src), "--out", str(out), "--speed-rpm", f"{rpm!r}"]) == 0
    capsys.readouterr()
    header = out.read_text().splitlines()[1]
    major = _ross_major()
    assert ("read without ROSS" in header) == (major is None or major < 3)
    rig = load_rig(out)
    if name == "tables":
        assert (rig.rotor.rayleigh_alpha, rig.rotor.rayleigh_beta) == (2.0, 1e-5)
    elif name == "seals":
        law = rig.seal[0].K
        assert (law.interpolation, law.extrapolation) == ("pchip", "linear")
        # ROSS's radial_clearance of both seals (0.3 mm), the hole-pattern one a spring
        assert rig.seal[0].clearance == 3e-4
        assert [s.clearance for s in rig.spring if s.kind == "seal"] == [3e-4]
    else:
        assert rig.rotor.supported_modal_damping.ratios == [
            0.001 * (k + 1) for k in range(14) if k + 1 not in (5, 14)]
    ref = json.loads((DATA / f"{name}_eigenvalues.json").read_text())
    assert tomllib.loads(src.read_text())["ross_version"] == ref["ross_version"]
    lam_ross = np.array([complex(*x) for x in ref[f"{speed_rad_s:g}"]])
    m = closed_loop_modes(rig, None, speed_hz=speed_rad_s / (2 * np.pi), max_hz=500.0)
    assert len(m.poles) >= 8
    for lam, dec in zip(m.poles, m.log_decrement):
        j = np.argmin(np.abs(lam_ross - lam))
        assert abs(lam_ross[j] - lam) <= 1e-6 * abs(lam)
        ref_dec = -2 * np.pi * lam_ross[j].real / lam_ross[j].imag
        assert dec == pytest.approx(ref_dec, rel=1e-6, abs=1e-9)


def test_a_ross2_file_is_read_by_the_installed_ross(tmp_path, capsys):
    """ROSS's own ROSS 2.3 test rotor with seals (``tests/data/ross2_rotor_seals.toml``,
    ROSS's ``tests/data/v2/rotor_seals.toml``). Where ROSS 3 is installed it is converted
    by ROSS 3's own ``ross_2to3`` (said in the rig file) and imported — it had been refused
    as "not a ROSS rotor file (TypeError: LabyrinthSeal…)" — and its modes at 523.6
    rad/s, a point of the labyrinth's table, equal ROSS 3.1's eigenvalues of the converted
    rotor (``seals_eigenvalues.json``) to 1e-6. ROSS 2.3 cannot load its labyrinth
    without the ``rossxl`` package: the refusal says so (exit 2)."""
    src = tmp_path / "rotor_seals.toml"
    shutil.copy(DATA.parent / "ross2_rotor_seals.toml", src)
    out = tmp_path / "rig.toml"
    major = _ross_major()
    code = main(["import-ross", str(src), "--out", str(out), "--speed-rpm", "5000"])
    err = capsys.readouterr().err
    if major is None or major < 3:
        assert code == 2 and "rossxl" in err and "ROSS 3" in err and "Traceback" not in err
        return
    assert code == 0
    assert "converted by ROSS 3" in out.read_text().split("\n[", 1)[0]
    rig = load_rig(out)
    ref = json.loads((DATA / "seals_eigenvalues.json").read_text())
    lam_ross = np.array([complex(*x) for x in ref["523.6"]])
    m = closed_loop_modes(rig, None, speed_hz=523.6 / (2 * np.pi), max_hz=500.0)
    assert len(m.poles) >= 8
    for lam in m.poles:
        assert np.min(np.abs(lam_ross - lam)) <= 1e-6 * abs(lam)


def _mutated(change) -> dict:
    """``tables.toml``'s tables with ``change(data)`` applied."""
    data = tomllib.loads((DATA / "tables.toml").read_text())
    change(data)
    return data


def _set(key_prefix: str, field: str, value, index: int = 0):
    def change(data):
        key = [k for k in data if k.startswith(key_prefix)][index]
        if value is _DROP:
            del data[key][field]
        else:
            data[key][field] = value
    return change


_DROP = object()


@pytest.mark.parametrize("change, message", [
    (_set("BearingElement", "cxx", [150.0, float("nan"), 200.0], 1), "expected finite"),
    (_set("BearingElement", "speed", [900.0, 50.0, 200.0], 1), "strictly increasing"),
    (_set("BearingElement", "speed", [50.0, 50.0, 900.0], 1), "strictly increasing"),
    (_set("BearingElement", "kxx", [1e6, 2e6], 1), "values for the table"),
    (_set("BearingElement", "kxx", "stiff", 1), "expected finite"),
    (_set("DiskElement", "n", -1), "integer ≥ 0"),
    (_set("DiskElement", "n", 2.5), "integer ≥ 0"),
    (_set("DiskElement", "n", 99), "not on the shaft"),
    (_set("DiskElement", "m", _DROP), "missing 'm'"),
    (_set("ShaftElement", "L", _DROP), "missing 'L'"),
    (_set("BearingElement", "n", _DROP), "missing 'n'"),
    (lambda d: d[[k for k in d if k.startswith("ShaftElement")][0]]["material"].pop("E"),
     "material E"),
    (lambda d: d["parameters"].update(alpha="two"), "alpha = 'two'"),
])
def test_the_ross3_reader_refuses_damaged_tables_by_name(change, message):
    """ROSS 3 files damaged as a user's may be: each refused with ambseal's error naming
    the element and the key (ROSS's interpolants had raised SciPy's ValueError, a missing
    key a KeyError, a disk on node −1 went silently to the last node)."""
    from ambseal.io.ross import from_ross
    from ambseal.io.ross_file import read_ross3_file

    data = _mutated(change)
    with pytest.raises(ConfigError, match=re.escape(message)):
        from_ross(read_ross3_file("damaged.toml", data), where="damaged.toml")


def test_the_ross3_reader_names_what_it_leaves_out_and_refuses_unreadable_json(tmp_path,
                                                                               capsys):
    """A bearing's axial kzz, czz is named among what is not imported (it had been dropped
    with ``unmapped`` empty); a JSON file with one element key twice (JSON keeps the last:
    a disk lost) and one nested 100 000 deep (a RecursionError traceback) are refused,
    exit 2, before ROSS is imported."""
    from ambseal.io.ross import from_ross
    from ambseal.io.ross_file import read_ross3_file

    data = _mutated(lambda d: d[[k for k in d if k.startswith("BearingElement")][0]].update(
        kzz=[1e8], czz=[500.0]))
    imp = from_ross(read_ross3_file("axial.toml", data), where="axial.toml")
    assert any("kzz = 1e+08, czz = 500" in u and "not imported" in u for u in imp.unmapped)
    disk = [k for k in data if k.startswith("DiskElement")][0]
    text = json.dumps(data)
    cases = {"repeat.json": text[:-1] + f", {json.dumps(disk)}: {json.dumps(data[disk])}}}",
             "deep.json": '{"parameters": {}, "x": ' + "[" * 100000 + "]" * 100000 + "}"}
    for name, body in cases.items():
        src = tmp_path / name
        src.write_text(body)
        assert main(["import-ross", str(src), "--out", str(tmp_path / "o.toml")]) == 2
        err = capsys.readouterr().err
        assert "Traceback" not in err and ("twice" in err or "nested too deeply" in err)


#: Values a damaged ROSS 3 file may hold where a number, a table or a node was meant.
_ODD = [True, "1.5", "", None, {}, [], [1.0, "a"], [[1.0]], float("nan"), float("inf"),
        -1.0, 0, 0.0, 1e308, 1e-308, 2.5, 10**30, [1.0, 2.0], [2.0, 1.0], [5.0, 5.0],
        {"a": 1.0}]


@st.composite
def _damaged(draw):
    """One of ROSS 3.1's own files (``tables``: bearings over speed and a seal over speed
    and whirl; ``seals``: ROSS's labyrinth and hole-pattern seals) with 1–3 changes over
    its documented layout: a key of an element or of ``parameters`` deleted or given an
    odd value, a table's entry changed, an element copied under a new key, an element's
    class renamed, or a value nested deeper."""
    data = json.loads(json.dumps(tomllib.loads((DATA / f"{draw(_SEEDS)}.toml").read_text())))
    for _ in range(draw(st.integers(1, 3))):
        tables = [k for k, v in data.items() if isinstance(v, dict)]
        key = draw(st.sampled_from(tables))
        table = data[key]
        op = draw(st.sampled_from(["delete", "odd", "entry", "copy", "rename", "nest"]))
        fields = [f for f in table if not isinstance(table[f], dict)]
        if op == "copy":
            data[f"{key.split('_')[0]}_copy{len(data)}"] = json.loads(json.dumps(table))
        elif op == "rename" and key != "parameters":
            data[f"{draw(st.sampled_from(['Bearing', 'DiskElementX', 'PointMass']))}_"
                 f"{key.split('_', 1)[-1]}"] = data.pop(key)
        elif fields:
            field = draw(st.sampled_from(fields))
            if op == "delete":
                del table[field]
            elif op == "entry" and isinstance(table[field], list) and table[field]:
                i = draw(st.integers(0, len(table[field]) - 1))
                table[field][i] = copy.deepcopy(draw(st.sampled_from(_ODD)))
            elif op == "nest":
                table[field] = [table[field]]
            else:
                table[field] = copy.deepcopy(draw(st.sampled_from(_ODD)))
    return data


_SEEDS = st.sampled_from(["tables", "seals"])


@settings(max_examples=150, deadline=None, derandomize=True,
          suppress_health_check=[HealthCheck.too_slow])
@given(_damaged())
def test_the_ross3_reader_refuses_or_accounts_for_every_element(data):
    """Property (hypothesis) over ROSS 3's documented layout: a damaged file is either
    refused with ambseal's own error (ConfigError, naming the file), or imported with every
    element accounted for — each shaft element a shaft section, each disk a disk, each
    bearing or seal a spring, seal or AMB, and nothing else — never a traceback of
    another kind."""
    from ambseal.io.ross import _check_file, from_ross
    from ambseal.io.ross_file import read_ross3_file

    # a folder per example, removed with it: hypothesis runs hundreds
    with tempfile.TemporaryDirectory(prefix="ambseal-test-") as folder:
        src = Path(folder) / "damaged.json"
        src.write_text(json.dumps(data))
        try:
            rotor = read_ross3_file(src, _check_file(src))
            imp = from_ross(rotor, where=str(src))
        except ConfigError as exc:
            assert str(src) in str(exc) or "damaged" in str(exc), exc
            return
        elements = [k for k, v in data.items() if k != "parameters" and isinstance(v, dict)]
        kinds = [k.split("_")[0] for k in elements]
        rig = imp.rig
        masses = kinds.count("PointMass")  # a disk on the shaft, or a housing's mass
        assert len(rig.shaft) == kinds.count("ShaftElement")
        disks = kinds.count("DiskElement")
        assert disks <= len(rig.disk) <= disks + masses
        supports = sum(k == "BearingElement" or k.endswith("Seal") for k in kinds)
        assert len(rig.spring) + len(rig.seal) + len(rig.amb) == supports
        assert len(elements) == (kinds.count("ShaftElement") + kinds.count("DiskElement")
                                 + masses + supports)


#: Level I's references (``make.py``): the test's stage giving ROSS's Q_A, and where Q
#: is applied — API 617's mid-span on ``rotor_example`` (ROSS's node 3), ROSS's node 27 on
#: ``compressor_example`` (2.45 cm from mid-span: ``[signoff] level1_position_m``)
LEVEL1_CASES = {
    # q_A = 3·(P/Ω)·(ρ_d/ρ_s)/(D_c·H_c) = 3·(2800/600)·2/(0.28·0.01) = 1e4 N/m
    "level1": ('[[stage]]\ndisk = "Disk 0"\npower = 2800.0\nimpeller_diameter = 0.28\n'
               "discharge_width = 0.01\nsuction_density = 1.2\ndischarge_density = 2.4\n",
               ((0.75, 1.0),)),
    # 3·(400 000π/400π)·2/(0.3·0.02) = 1e6 N/m at 12 000 rpm
    "level1_compressor": ("[[stage]]\ndisk = \"{disk}\"\npower = 1256637.0614359172\n"
                          "impeller_diameter = 0.3\ndischarge_width = 0.02\n"
                          "suction_density = 1.2\ndischarge_density = 2.4\n",
                          ((0.806, 1.0),)),
}


@pytest.mark.parametrize("name", sorted(LEVEL1_CASES))
def test_level1_q0_equals_ross_31(name, tmp_path, capsys):
    """API 617 Level I against ROSS 3.1's ``run_level1`` (``tests/data/ross3/<name>.json``,
    written by ``make.py``), the ROSS 3 file imported by ambseal's own reader with one
    stage: ``rotor_example`` on two damped bearings, Q at mid-span where API 617 applies
    it between bearings (ROSS's node 3); ``compressor_example`` at 12 000 rpm on its
    bearing tables, its twelve seals left out (Level I; ROSS's ``run_level1`` keeps them,
    so its reference is ROSS's rule on the rotor without them), Q at ROSS's node 27. The
    screened mode's log decrement at Q = 0 (ROSS's first mode that does not whirl
    backward: 15.4 Hz and 106.5 Hz) and at Q_A (δ_A), and Q_0, where it crosses zero
    (Brent's method on ROSS's own evaluation), agree within 1e-4, 1e-4 and 1e-3."""
    from ambseal.analysis import level1_screening

    ref = json.loads((DATA / f"{name}.json").read_text())
    assert ref["seals"] is (name == "level1")
    src = tmp_path / f"{name}.toml"
    shutil.copy(DATA / f"{name}.toml", src)
    out = tmp_path / "rig.toml"
    rpm = ref["speed_rad_s"] * 30 / np.pi
    assert main(["import-ross", str(src), "--out", str(out), "--speed-rpm", f"{rpm!r}"]) == 0
    capsys.readouterr()
    stage, where = LEVEL1_CASES[name]
    disk = load_rig(out).disk[0].name
    text = out.read_text() + "\n" + stage.replace("{disk}", disk)
    if name == "level1_compressor":  # into the [signoff] table import-ross writes
        assert text.count("\n[signoff]\n") == 1
        text = text.replace("\n[signoff]\n", "\n[signoff]\nlevel1_position_m = 0.806\n")
    out.write_text(text)
    res = level1_screening(load_rig(out))
    assert res.Q_A == pytest.approx(ref["Q_A"], rel=1e-12)
    assert [w for p in res.where_m for w in p] == pytest.approx([w for p in where for w in p])
    assert where[0][0] == pytest.approx(ref["position_m"], abs=1e-12)
    assert res.log_dec_A == pytest.approx(ref["log_dec_A"], rel=1e-4)
    sweep = res.to_dict()["sweep"]
    assert sweep["Q"][0] == 0.0
    assert sweep["log_dec"][0] == pytest.approx(ref["log_dec_at_0"], rel=1e-4)
    assert 2 * np.pi * sweep["frequency_hz"][0] == pytest.approx(ref["wd_at_0"], rel=1e-4)
    assert res.Q_0 == pytest.approx(ref["Q_0"], rel=1e-3)
