"""Bad input is refused with one line naming the file and key, exit 2.

Each case is a value a user may write that must not be accepted silently (coerced,
ignored) nor end in a traceback. The reference is the rig
format (ambseal.config's docstring) and the CLI's promise: one line on stderr, status 2.
"""

import copy
import tomllib

import numpy as np
import pytest

from ambseal.cli import main

from .conftest import ROOT
from .toml_text import dump

RIG = ROOT / "examples" / "testrig.toml"
TRUTH = ROOT / "src" / "ambseal" / "data" / "testrig_truth.toml"
BASE = tomllib.loads(RIG.read_text())


def cli(capsys, *args) -> tuple[int, str]:
    capsys.readouterr()
    try:
        code = main([str(a) for a in args])
    except SystemExit as exc:  # argparse
        code = exc.code
    err = capsys.readouterr().err.strip().splitlines()
    return code, (err[0] if len(err) == 1 else "\n".join(err) or "<none>")


def refused(capsys, args, where: str, *expect: str) -> str:
    code, line = cli(capsys, *args)
    assert code == 2 and "\n" not in line, line
    for part in (where, *expect):
        assert part in line, line
    return line


def test_dump_round_trip():
    """The helper writes the example rig so that it reads back equal."""
    assert tomllib.loads(dump(BASE)) == BASE


def _set(path: str, value):
    def edit(d):
        *head, last = path.split("/")
        for k in head:
            d = d[int(k)] if k.isdigit() else d[k]
        if value is _DEL:
            del d[last]
        elif isinstance(d, list):
            d[int(last)] = value
        else:
            d[last] = value
    return edit


_DEL = object()

RIG_CASES = [
    # §1 silent coercion: strict schema
    ("bool mass", _set("disk/0/mass", True), "disk[0].mass", "expected a number"),
    ("bool elements", _set("shaft/0/elements", True), "shaft[0].elements", "integer"),
    ("string E", _set("materials/steel/E", "1.5"), "materials.steel.E", "str"),
    ("empty M", _set("seal/0/M", {}), "seal[0].M", "empty table"),
    # §1 nonsense
    ("ki zero", _set("amb/0/ki", 0.0), "amb[0]", "Ki > 0"),
    ("ki negative axis", _set("amb/0/ki", {"zeta": -199.0, "eta": 207.0}), "amb[0]",
     "ki.zeta"),
    ("ks negative", _set("amb/0/ks", -2.39e6), "amb[0]", "Ks > 0 the destabilising"),
    ("partial geometry", _set("amb/1/turns", 36), "amb[1]", "partial geometry"),
    ("cutoff with second order", _set("actuator/cutoff_hz", 300.0), "actuator",
     "not used by model = 'second_order'"),
    ("states 100000", _set("reduction/states", 100000), "reduction.states", "<= 200"),
    ("sample rate 1e-6", _set("controller/sample_rate_hz", 1e-6),
     "controller.sample_rate_hz", ">= 100"),
    ("speed outside LPV range", _set("operating/speed_range_hz", [20.0, 300.0]),
     "operating", "extrapolated"),
    ("dot in name", _set("seal/0/name", "seal.1"), "seal[0].name", "ASCII letters, digits"),
    # names become parameter, signal and C names; labels stay on one line
    ("C in an AMB name", _set("amb/1/name", '*/system("x");/*'), "amb[1].name",
     "ASCII letters, digits and '_'"),
    ("dash in a spring name", _set("spring", [{"position": 0.86, "kxx": 1e5, "kyy": 1e5,
                                              "name": "coupling-1"}]), "spring[0].name",
     "does not start with a digit"),
    ("digit first", _set("seal/0/name", "1seal"), "seal[0].name", "ASCII letters"),
    ("space in a material", _set("materials", {"steel x": BASE["materials"]["steel"]}),
     "materials.steel x", "ASCII letters"),
    ("newline in the rotor's name", _set("rotor/name", "rig\n[controller]"), "rotor.name",
     "one line"),
    # §2 extreme but finite
    ("1e308 mass", _set("disk/0/mass", 1e308), "disk[0].mass", "<= 1000000"),
    ("1e-308 diameter", _set("shaft/0/outer_diameter", 1e-308), "shaft[0].outer_diameter",
     ">= 0.0001"),
    ("1e30 elements", _set("shaft/1/elements", 10**18), "shaft[1].elements", "<= 400"),
    ("elements in all", _set("shaft/0/elements", 380), "shaft", "412 beam elements in all"),
    # a layer is a tube around the section's own, not through it
    ("overlapping layer", _set("shaft/1/layers", [{"outer_diameter": 0.12,
                                                   "inner_diameter": 0.08,
                                                   "material": "steel"}]),
     "shaft[1]", "overlap"),
    ("unknown layer material", _set("shaft/1/layers", [{"outer_diameter": 0.12,
                                                        "inner_diameter": 0.10,
                                                        "material": "steal"}]),
     "shaft[1].layers[0].material", "unknown material 'steal'"),
    # §3 nested values
    ("nan in affine", _set("seal/0/K", {"at_zero": float("nan"), "per_bar": 1.0}),
     "seal[0].K.at_zero", "finite"),
    ("typo per_bars", _set("seal/0/K", {"at_zero": 0.0, "per_bars": 1.0}),
     "seal[0].K.per_bars", "unknown key"),
    ("missing eta", _set("amb/0/ki", {"zeta": 199.0}), "amb[0]", "both zeta and eta"),
    ("unsorted table", _set("seal/0/K", {"frequency_hz": [20.0, 10.0], "value": [1.0, 2.0]}),
     "seal[0].K", "strictly increasing"),
    ("length mismatch", _set("seal/0/K", {"frequency_hz": [10.0, 20.0], "value": [1.0]}),
     "seal[0].K", "same length"),
    # every form of a coefficient bounded alike: a table of 1e300 gave "no unstable poles"
    ("1e300 table", _set("seal/0/k", {"frequency_hz": [0.0, 100.0], "value": [1e300, 1e300]}),
     "seal[0].k.value[0]", "<= 1000000000000"),
    ("1e300 table frequency", _set("seal/0/k", {"frequency_hz": [0.0, 1e300],
                                                 "value": [1.0, 2.0]}),
     "seal[0].k.frequency_hz[1]", "<= 10000000"),
    ("1e300 number", _set("seal/0/C", 1e300), "seal[0].C", "<= 1000000000000"),
    ("1e300 factor axis", _set("amb/0/ks", {"zeta": 1e300, "eta": 2.49e6}), "amb[0].ks.zeta",
     "<= 1000000000000"),
    ("delay 1e9 samples", _set("controller/delay_samples", 10**9),
     "controller.delay_samples", "<= 100"),
    ("axes angle 1e300", _set("amb/0/axes_angle_deg", 1e300), "amb[0].axes_angle_deg",
     "<= 360"),
    ("uncertainty 1e300", _set("amb/0/uncertainty", {"Ki": 1e300}), "amb[0].uncertainty.Ki",
     "<= 10"),
    # [design] as strict as the rest of the rig file, and bounded
    ("tracked yes", _set("design/tracked", "yes"), "design.tracked", "true or false"),
    ("d_e_um string", _set("design/d_e_um", "20"), "design.d_e_um", "expected a number"),
    ("band string", _set("design/band_hz", ["1", 2000.0]), "design.band_hz[0]",
     "expected a number"),
    ("design pressures 1e300", _set("design/pressures_bar", [0.0, 1e300]),
     "design.pressures_bar[1]", "<= 10000"),
    ("design speeds nan", _set("design/speeds_hz", [float("nan")]), "design.speeds_hz[0]",
     "finite"),
    ("design M 1e308", _set("design/hinf", {"M": 1e308}), "design.hinf.M", "<= 1000"),
    ("design states 1e9", _set("design/model_states", 10**9), "design.model_states", "<= 200"),
    ("impulse 1e300 s", _set("design/impulse", {"duration_s": 1e300}),
     "design.impulse.duration_s", "controller samples"),
    ("unbalance grade", _set("design/unbalance/grade_mm_s", 1e300),
     "design.unbalance.grade_mm_s", "<= 4000"),
    # what run refuses after its designs, validate refuses before them: a supply that
    # cannot drive the bias current through R, a supply without the coil's inductance, a
    # synchronous rejection on a rotor that does not turn
    ("supply below R i0",
     lambda d: d["amb"][0].update(supply_voltage=2.0, resistance=0.5, inductance=0.02),
     "amb[0]", "does not drive the bias current 6 A through R = 0.5 Ω"),
    ("supply without inductance", _set("amb/1/supply_voltage", 48.0), "amb[1]",
     "supply_voltage needs the coil's inductance"),
    ("rejection at standstill",
     lambda d: (d["operating"].update(speed_rpm=0.0),
                d.setdefault("design", {}).update(rejection={"enabled": True})),
     "design.rejection.enabled", "the rotor must turn"),
    # 11 000 rpm is 183.3333… Hz: the message must not print it as the range's end
    ("speed past a rounded range",
     lambda d: d["operating"].update(speed_rpm=11000.0, speed_range_hz=[116.667, 183.333]),
     "speed_rpm", "183.333333333 Hz lies outside speed_range_hz [116.667, 183.333]"),
]


@pytest.mark.parametrize("label, edit, key, expect", RIG_CASES, ids=[c[0] for c in RIG_CASES])
def test_rig_value_refused(tmp_path, capsys, label, edit, key, expect):
    data = copy.deepcopy(BASE)
    edit(data)
    rig = tmp_path / "rig.toml"
    rig.write_text(dump(data))
    refused(capsys, ["modes", rig, "--n-modes", 1], str(rig), key, expect)


def test_validate_refuses_what_run_refuses_before_its_designs(tmp_path, capsys):
    """A sample rate below twice the reference PID's highest pole (its derivative filter at
    454.7 Hz, P5 Eq. 6): ``run`` refuses it before any stage (it had designed for 27 s
    first), and ``validate`` with the same line, where it had said "valid"."""
    data = copy.deepcopy(BASE)
    data.setdefault("controller", {})["sample_rate_hz"] = 800.0
    rig = tmp_path / "rig.toml"
    rig.write_text(dump(data))
    expect = ("controller.sample_rate_hz = 800 Hz is below twice the highest pole of K_pid "
              "(454.7 Hz)")
    line = refused(capsys, ["validate", rig], str(rig), expect)
    ran = refused(capsys, ["run", rig, "--no-identify", "--out", tmp_path / "out"], str(rig),
                  expect)  # one line: before any stage
    assert ran == line
    # a [design] override run takes, validate takes and refuses alike
    band = ["--set", "design.band_hz=[2000.0, 1.0]"]
    line = refused(capsys, ["validate", RIG, *band], str(RIG), "band_hz", "low < high")
    assert refused(capsys, ["run", RIG, "--no-identify", "--out", tmp_path / "o2", *band],
                   str(RIG), "band_hz") == line


def test_duplicate_seal_and_spring_names(tmp_path, capsys):
    """Their parameter names would collide (seal.k, spring0.kxx)."""
    for kind, extra in (("seal", {}), ("spring", {})):
        data = copy.deepcopy(BASE)
        data[kind].append({**data[kind][0], **extra})
        rig = tmp_path / f"{kind}.toml"
        rig.write_text(dump(data))
        refused(capsys, ["modes", rig], f"{kind}[1].name", "duplicate")
    data = copy.deepcopy(BASE)
    data["spring"] = [{"position": 0.0, "kxx": 1e5, "kyy": 1e5},
                      {"position": 0.86, "kxx": 1e5, "kyy": 1e5, "name": "spring0"}]
    rig = tmp_path / "unnamed.toml"
    rig.write_text(dump(data))
    refused(capsys, ["modes", rig], "spring[1].name", "spring0")


CLI_CASES = [
    (["modes", RIG, "--pressure-bar", "-5"], "--pressure-bar", "[operating] pressure_bar"),
    (["modes", RIG, "--pressure-bar", "nan"], "--pressure-bar", "finite"),
    (["modes", RIG, "--speed-rpm", "1e300"], "--speed-rpm", "finite"),
    (["modes", RIG, "--n-modes", "1e30"], "--n-modes", "whole number"),
    (["identify", RIG, "x.csv", "--params", "A.Ki_zeta", "--out", "o", "--current-weight",
      "-1"], "--current-weight", ">= 0"),
    (["identify", RIG, "x.csv", "--params", "A.Ki_zeta", "--out", "o", "--current-weight",
      "nan"], "--current-weight", "finite"),
    (["acquire", RIG, "--truth", TRUTH, "--excitation", "prbs", "--pressure-bar", "0",
      "--out", "r.csv", "--axes", ""], "--axes", "axis names"),
    (["acquire", RIG, "--truth", TRUTH, "--excitation", "prbs", "--pressure-bar", "0",
      "--out", "r.csv", "--duration-s", "1e9"], "duration_s", "GB"),
    (["run", "--truth", "MISSING.toml", "--out", "o"], "MISSING.toml", "cannot read"),
    (["design", RIG, "--method", "hinf", "--set", "design.hinf.M=1e308", "--out", "o"],
     "design.hinf.M", "<= 1000"),
    (["design", RIG, "--method", "hinf", "--set", "design.tracked=yes", "--out", "o"],
     "design.tracked", "true or false"),
    (["campbell", RIG, "--speed-hz", "0:100:1000000", "--out", "o"], "--speed-hz",
     "count from 1 to 10000"),
    (["campbell", RIG, "--speed-hz", "0:nan:5", "--out", "o"], "--speed-hz", "finite"),
    (["campbell", RIG, "--speed-hz", "inf", "--out", "o"], "--speed-hz", "finite"),
    (["sweep", RIG, "--pressure-bar", "0:4:1000", "--speed-hz", "0:100:1000", "--out", "o"],
     "sweep", "at most 10000"),
    (["sweep", RIG, "--pressure-bar", "0:1e300:3", "--out", "o"], "--pressure-bar", "finite"),
    (["sweep", RIG, "--pressure-bar", "0:2e4:3", "--out", "o"], "--pressure-bar",
     "[operating] pressure_bar"),
    (["sweep", RIG, "--pressure-bar", "0:4:3", "--tol-bar", "-1", "--out", "o"], "--tol-bar",
     "> 0"),
    (["sweep", RIG, "--pressure-bar", "0:4:3", "--tol-bar", "0", "--out", "o"], "--tol-bar",
     "> 0"),
    (["sweep", RIG, "--pressure-bar", "0:4:3", "--max-hz", "-5", "--out", "o"], "--max-hz",
     "> 0"),
    (["sweep", RIG, "--pressure-bar", "0:4:3", "--workers", "100000", "--out", "o"],
     "--workers", "per core"),
    (["sweep", RIG, "--pressure-bar", "0:4:3", "--param", "seal.kk=0:1e6:3", "--out", "o"],
     "unknown parameter 'seal.kk'", "seal.k, seal.C"),
    (["design", RIG, "--method", "pid", "--set", "design.band_hz=[1, 3000]\ndesign.x=1",
      "--out", "o"], "--set", "one line"),
    (["track", RIG, "x.csv", "--params", "seal.k", "--rate-per-s", "-1", "--out", "o"],
     "--rate-per-s", "> 0"),
    (["modes", "/dev/zero"], "/dev/zero", "not a regular file"),
]


@pytest.mark.parametrize("args, where, expect", CLI_CASES,
                         ids=[" ".join(map(str, c[0][:1] + c[0][-2:])) for c in CLI_CASES])
def test_cli_value_refused(tmp_path, capsys, monkeypatch, args, where, expect):
    """The CLI checks its values by the rig file's rules, before any work (a run with a
    missing truth file is refused before the model is built)."""
    monkeypatch.chdir(tmp_path)
    refused(capsys, args, where, expect)
    assert not (tmp_path / "o").exists()


def test_files_that_are_not_utf8_or_too_deep(tmp_path, capsys):
    """Non-UTF-8 rig and truth files are refused as such; a UTF-8 byte-order mark is
    accepted; TOML nested 5 000 deep is refused, not a RecursionError."""
    bad = tmp_path / "latin1.toml"
    bad.write_bytes(dump(BASE).replace("DTU", "DTU \u00e6").encode("latin-1"))
    refused(capsys, ["modes", bad], str(bad), "not UTF-8 text")
    refused(capsys, ["acquire", RIG, "--truth", bad, "--excitation", "prbs", "--pressure-bar",
                     "0", "--out", tmp_path / "r.csv"], str(bad), "not UTF-8")
    bom = tmp_path / "bom.toml"
    bom.write_bytes(b"\xef\xbb\xbf" + RIG.read_bytes())
    assert cli(capsys, "modes", bom, "--n-modes", 1)[0] == 0
    deep = tmp_path / "deep.toml"
    deep.write_text("x = " + "[" * 5000 + "]" * 5000 + "\n")
    refused(capsys, ["modes", deep], str(deep), "nested too deeply")


def test_truth_file_is_strict(tmp_path, capsys):
    t = tmp_path / "truth.toml"
    t.write_text("[truth]\nsubsteps = true\n")
    refused(capsys, ["acquire", RIG, "--truth", t, "--excitation", "prbs", "--pressure-bar",
                     "0", "--out", tmp_path / "r.csv"], str(t), "truth.substeps", "integer")


def test_gains_figure_of_a_one_amb_rig(tmp_path):
    """A rig with one AMB has a 2 × 2 controller: the gains figure draws the pairs it has
    (it raised IndexError after metrics.json was written; `ambseal run` on the test rig with
    AMB B replaced by a bearing spring now exits 0)."""
    import numpy as np

    from ambseal.report.figures import controller_gains_figure

    f = np.logspace(0, 3, 30)
    K = np.ones((30, 2, 2)) * (1 + 1j)
    path = controller_gains_figure(tmp_path / "g.png", [("pid", f, K)], ["A_zeta", "A_eta"])
    assert path.stat().st_size > 1000


def test_input_sizes_are_bounded_before_work(tmp_path, capsys):
    """Reference: the rig format's bounds (ambseal.config._checks): at most MAX_COMPONENTS
    disks and a mesh of at most MAX_ELEMENTS beam elements however the components split it
    (2 000 small disks made a dense model of 16 000 states), each refused in one line
    naming the key, in seconds; an identification file that is a device (``/dev/zero``)
    is refused without reading it."""
    import time

    from ambseal.config import MAX_COMPONENTS, MAX_ELEMENTS

    data = copy.deepcopy(BASE)
    length = sum(s["length"] for s in data["shaft"])
    for n, where, expect in ((2000, "disk", f"at most {MAX_COMPONENTS}"),
                             (MAX_ELEMENTS - 10, "shaft", f"more than {MAX_ELEMENTS} beam")):
        data["disk"] = BASE["disk"] + [{"name": f"d{i}", "position": length * (i + 0.5) / n,
                                        "mass": 0.01} for i in range(n)]
        rig = tmp_path / f"disks{n}.toml"
        rig.write_text(dump(data))
        t0 = time.process_time()
        refused(capsys, ["validate", rig], str(rig), where, expect)
        assert time.process_time() - t0 < 10.0
    data = copy.deepcopy(BASE)
    data.setdefault("design", {})["uncertainty_from_identification"] = "/dev/zero"
    rig = tmp_path / "zero.toml"
    rig.write_text(dump(data))
    refused(capsys, ["design", rig, "--method", "mu", "--out", tmp_path / "o"],
            "uncertainty_from_identification", "/dev/zero", "not a regular file")


def test_a_near_degenerate_mesh_costs_its_size_or_is_refused_naming_it(tmp_path, capsys):
    """Reference: the rig without the short section. A 0.1 mm section cut into 100
    elements of 1 µm (the free–free modal analysis took 91 s, then ended in an ARPACK
    failure) is refused in one line naming the conditioning and where the shortest
    element lies; cut into 10 elements of 10 µm, or kept as one, it is taken and its
    free–free modes are those of the rig without it within 0.2 %."""
    import json

    def rig(n):
        data = copy.deepcopy(BASE)
        data["shaft"].insert(1, {**data["shaft"][0], "length": 1e-4, "elements": n})
        path = tmp_path / f"section{n}.toml"
        path.write_text(dump(data))
        return path

    fine = rig(100)
    z = BASE["shaft"][0]["length"]
    refused(capsys, ["modes", fine, "--free", "--json"], str(fine),
            "cannot be told from a rigid-body mode", "shortest beam element is 1e-06 m",
            f"z = {z:g}–")
    freqs = []
    for path in (RIG, rig(10), rig(1)):
        capsys.readouterr()
        assert main(["modes", str(path), "--free", "--json"]) == 0
        freqs.append(json.loads(capsys.readouterr().out)["natural_frequencies_hz"])
    assert len(freqs[0]) >= 4
    for f in freqs[1:]:
        np.testing.assert_allclose(f, freqs[0], rtol=2e-3)
