"""Property-based fuzz of the command line: mutated example rigs, truth files,
records, controller files and ranges end either in exit 2 with one line on stderr naming
the file, or in exit 0 with finite results — never in a traceback (only the project's own
errors), never in a hang (each case runs under a deadline), and never changing a file
outside the command's output (each case runs in a folder of its own, compared before and
after).

The CLI's ``main()`` is called in-process (a subprocess per example would cost a second of
imports each). About 15 s by default; ``-m slow`` runs ten times the examples, new random
ones each time (the default set is derandomized, the same in every CI run).
"""

import contextlib
import copy
import csv
import io
import json
import math
import os
import signal
import tomllib
from pathlib import Path

import numpy as np
import scipy.io

import pytest
from hypothesis import HealthCheck, example, given, settings
from hypothesis import strategies as st

from ambseal.cli import main
from ambseal.config import parse_rig

from .conftest import ROOT
from .mutations import mutated, paths
from .test_cli_drop import _rig_text
from .toml_text import dump

RIGS = {name: tomllib.loads((ROOT / "examples" / name).read_text())
        for name in ("testrig.toml", "turboexpander.toml")}
TRUTH = tomllib.loads((ROOT / "src" / "ambseal" / "data" / "testrig_truth.toml").read_text())

def _garbage(draw, text: str) -> bytes:
    """``text`` as UTF-8 with random bytes spliced in (sometimes none)."""
    return _spliced(draw, text.encode())


def _spliced(draw, data: bytes) -> bytes:
    """``data`` with random bytes spliced in (sometimes none)."""
    if draw(st.booleans()):
        return data
    at = draw(st.integers(0, len(data)))
    return data[:at] + draw(st.binary(min_size=1, max_size=8)) + data[at:]


def _call(args: list[str]) -> tuple[int, str, str]:
    out, err = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
        try:
            code = main(args)
        except SystemExit as exc:  # argparse
            code = exc.code
    return code, out.getvalue(), err.getvalue()


class Hang(BaseException):
    """A case ran past its deadline (a BaseException: no ``except Exception`` swallows it)."""


@contextlib.contextmanager
def _deadline(seconds: float):
    """Raise :class:`Hang` in the main thread after ``seconds`` (SIGALRM, POSIX)."""
    def fire(signum, frame):
        raise Hang(f"still running after {seconds:g} s")

    old = signal.signal(signal.SIGALRM, fire)
    signal.setitimer(signal.ITIMER_REAL, seconds)
    try:
        yield
    finally:
        signal.setitimer(signal.ITIMER_REAL, 0)
        signal.signal(signal.SIGALRM, old)


def _tree(folder: Path, outputs: list[Path]) -> dict:
    """Every file under ``folder`` but the ``outputs`` (files or folders) → (size, mtime)."""
    skip = [o.resolve() for o in outputs]
    found = {}
    for root, _, names in os.walk(folder):
        for n in names:
            p = Path(root, n).resolve()
            if not any(p == o or o in p.parents for o in skip):
                st = p.stat()
                found[str(p)] = (st.st_size, st.st_mtime_ns)
    return found


def _sandboxed(folder: Path, args: list, outputs: list[Path], seconds: float = 60.0):
    """``main(args)`` with ``folder`` as the working folder, under a deadline; asserts that
    no file of ``folder`` outside ``outputs`` changed and that nothing appeared beside it."""
    before, beside = _tree(folder, outputs), set(os.listdir(folder.parent))
    cwd = os.getcwd()
    os.chdir(folder)
    try:
        with _deadline(seconds):
            result = _call([str(a) for a in args])
    finally:
        os.chdir(cwd)
    assert _tree(folder, outputs) == before, (args, "a file outside the output changed")
    assert set(os.listdir(folder.parent)) == beside, (args, "a file appeared beside it")
    return result


def _finite(obj) -> bool:
    if isinstance(obj, float):
        return math.isfinite(obj)
    if isinstance(obj, dict):
        return all(_finite(v) for v in obj.values())
    if isinstance(obj, list):
        return all(_finite(v) for v in obj)
    return True


def _check(code: int, out: str, err: str, names: list[str]) -> None:
    lines = err.strip().splitlines()
    if code == 2:
        assert len(lines) == 1 and lines[0].startswith("ambseal: error: "), err
        assert any(n in lines[0] for n in names), (names, lines[0])
    else:
        assert code == 0, (code, err)
        assert _finite(json.loads(out)), out




def fuzz(n: int, slow: bool = False):
    """``n`` examples, no per-example deadline; derandomized (CI sees the same cases) unless
    ``slow`` (the ``-m slow`` variants: ten times as many, new ones each run)."""
    return settings(max_examples=10 * n if slow else n, deadline=None, derandomize=not slow,
                    suppress_health_check=list(HealthCheck))


def _rig_case(tmp_path_factory, data):
    """``ambseal modes --json`` on a mutated example rig (the parse, every validation and
    the model build, the dense eigenvalues and their classification)."""
    name = data.draw(st.sampled_from(sorted(RIGS)))
    doc = data.draw(mutated(RIGS[name]))
    rig = tmp_path_factory.mktemp("fuzz") / name
    rig.write_bytes(_garbage(data.draw, dump(doc)))
    code, out, err = _sandboxed(rig.parent, ["modes", rig, "--json"], [])
    _check(code, out, err, [str(rig)])


def _truth_case(tmp_path_factory, data):
    """``ambseal acquire`` with a mutated truth file: refused naming it, or a record of
    finite samples (a 0.02 s PRBS, short to keep the example fast)."""
    doc = data.draw(mutated(TRUTH))
    d = tmp_path_factory.mktemp("fuzz")
    truth = d / "truth.toml"
    truth.write_bytes(_garbage(data.draw, dump(doc)))
    code, out, err = _sandboxed(d, ["acquire", ROOT / "examples" / "testrig.toml", "--truth",
                                    truth, "--excitation", "prbs", "--duration-s", "0.02",
                                    "--pressure-bar", "0", "--out", d / "r.csv"],
                                [d / "r.csv", d / "r.csv.json"])
    _check(code, out, err, [str(truth), "r.csv"])


@pytest.fixture(scope="module")
def record(tmp_path_factory):
    """A short PRBS record of the test rig (CSV + sidecar) to mutate."""
    path = tmp_path_factory.mktemp("rec") / "prbs.csv"
    code, _, err = _call(["acquire", str(ROOT / "examples" / "testrig.toml"), "--truth",
                          str(ROOT / "src" / "ambseal" / "data" / "testrig_truth.toml"),
                          "--excitation", "prbs", "--duration-s", "0.03", "--pressure-bar",
                          "0", "--out", str(path), "--seed", "2"])
    assert code == 0, err
    return path


def _record_case(tmp_path_factory, record, data):
    """``ambseal identify`` on a record with a mutated sidecar (keys deleted, odd values)
    or CSV (cells replaced, rows dropped, garbage bytes): refused naming the record or its
    sidecar, or a fit with finite numbers (or refused as failed, naming the fit file)."""
    d = tmp_path_factory.mktemp("fuzz")
    csv, side = d / "r.csv", d / "r.csv.json"
    meta = json.loads(record.with_name(record.name + ".json").read_text())
    lines = record.read_text().splitlines()
    if data.draw(st.booleans()):
        meta = data.draw(mutated(meta))
    else:
        row = data.draw(st.integers(0, len(lines) - 1))
        cells = lines[row].split(",")
        col = data.draw(st.integers(0, len(cells) - 1))
        cells[col] = data.draw(st.sampled_from(["nan", "inf", "1e300", "", "x", "-0", "1e-320"]))
        lines[row] = ",".join(cells)
        if data.draw(st.booleans()):
            del lines[data.draw(st.integers(1, len(lines) - 1))]
    csv.write_bytes(_garbage(data.draw, "\n".join(lines) + "\n"))
    side.write_bytes(_garbage(data.draw, json.dumps(meta, allow_nan=True)))
    code, out, err = _sandboxed(d, ["identify", ROOT / "examples" / "testrig.toml", csv,
                                    "--params", "A.Ki_zeta", "--no-refine", "--out", d / "o"],
                                [d / "o"])
    _check(code, out, err, [str(csv), str(d / "o")])


@pytest.fixture(scope="module")
def controller(tmp_path_factory):
    """The document of the reference PID as ``ambseal design`` writes it (JSON form)."""
    d = tmp_path_factory.mktemp("ctl")
    code, _, err = _call(["design", str(ROOT / "examples" / "testrig.toml"), "--method", "pid",
                          "--out", str(d), "--allow-unstable"])
    assert code == 0, err
    return json.loads((d / "controller_pid.json").read_text())


def _write_controller(doc: dict, path: Path) -> None:
    """``doc`` in the format of ``path``'s suffix: JSON as is; .npz and .mat with each value
    as numpy makes it (a list of mixed types becomes an object array, which .npz pickles
    and the loader must refuse)."""
    if path.suffix == ".json":
        path.write_text(json.dumps(doc, allow_nan=True))
        return
    arrays = {}
    for k, v in doc.items():
        try:
            arrays[k] = np.asarray(v)
        except ValueError:  # ragged
            arrays[k] = np.asarray(v, dtype=object)
    with open(path, "wb") as fh:
        if path.suffix == ".npz":
            np.savez(fh, **arrays)
        else:
            scipy.io.savemat(fh, {k: (np.nan if v is None else v) for k, v in doc.items()})


def _controller_case(tmp_path_factory, controller, data):
    """``ambseal export --controller FILE``: a mutated controller document in any of the
    three formats, sometimes with garbage bytes or truncated: refused naming the file, or
    the C module written inside ``--out``."""
    d = tmp_path_factory.mktemp("fuzz")
    ext = data.draw(st.sampled_from([".json", ".npz", ".mat"]))
    path = d / f"K{ext}"
    doc = data.draw(mutated(controller))
    try:
        _write_controller(doc, path)
    except Exception:  # a value numpy or scipy cannot write: the JSON form instead
        path = d / "K.json"
        _write_controller(doc, path)
    raw = path.read_bytes()
    cut = data.draw(st.sampled_from([None] * 4 + [0, 7, len(raw) // 2, len(raw) - 1]))
    path.write_bytes(_spliced(data.draw, raw) if cut is None else raw[:cut])
    code, out, err = _sandboxed(d, ["export", ROOT / "examples" / "testrig.toml",
                                    "--controller", path, "--out", d / "o"], [d / "o"])
    _check(code, out, err, [str(path), str(d / "o")])
    if code == 0:
        assert all(Path(f).resolve().is_relative_to((d / "o").resolve())
                   for f in json.loads(out)["files"])


#: Pieces of a range ``a:b:n``: numbers a user might type, non-finite ones, huge counts.
_ENDS = st.sampled_from(["0", "-1", "1e300", "-1e300", "nan", "inf", "-inf", "2e5", "", "x",
                         "1e-320"])
_ODD_ENDS = st.sampled_from(["1e300", "-1e300", "nan", "inf", "-inf", "2e5", "", "x"])
_COUNTS = st.sampled_from(["0", "-3", "2.5", "1e6", "1000000", "10001", "", "x", "nan",
                           str(2**63)])


def _range_case(tmp_path_factory, data):
    """``ambseal campbell --speed-hz RANGE`` with a range that is not one to run (non-finite,
    beyond the speed bound, no count or too many points): refused at once — before any
    model or design — naming the argument."""
    d = tmp_path_factory.mktemp("fuzz")
    parts = [data.draw(_ODD_ENDS)] if data.draw(st.booleans()) else [
        data.draw(_ENDS), data.draw(_ENDS), data.draw(_COUNTS)]
    text = ":".join(parts)
    code, out, err = _sandboxed(d, ["campbell", ROOT / "examples" / "testrig.toml",
                                    "--controller", "none", f"--speed-hz={text}",
                                    "--out", d / "o"], [d / "o"], seconds=10.0)
    assert code == 2, (text, code, err)
    _check(code, out, err, ["--speed-hz"])
    assert not (d / "o").exists()


#: Rig-file keys that are physics of the closed loop ``ambseal modes --controller pid``
#: sees at 100 Hz (the rotor, its supports, the AMBs with their actuator and sensors, the
#: seals at the operating pressure, the reference PID; spinning, so that the polar inertia
#: acts): changing one must change the modes or be refused. Keys outside it (names,
#: [design], [reduction], bounds such as current_limit, the touchdown bearings, out of
#: contact while the rotor levitates) are not physics of that loop.
PHYSICS = {"modal_damping", "E", "rho", "nu", "length", "outer_diameter", "inner_diameter",
           "mass", "Ip", "Id", "position", "sensor_position", "axes_angle_deg", "ki", "ks",
           "natural_frequency", "damping_ratio", "K", "k", "C", "c", "M", "at_zero",
           "per_bar", "kxx", "kyy", "kp", "ti", "td", "pressure_bar"}
_MODES = ["modes", None, "--json", "--controller", "pid", "--speed-rpm", "6000"]
_baseline: dict = {}


def _physics_paths(doc: dict) -> list[tuple]:
    """Paths to the non-zero numbers under a :data:`PHYSICS` key, and to the value list of
    a tabulated coefficient as a whole (one entry far from the operating speed does not
    reach the loop there; the table's frequencies are its grid, not a coefficient)."""
    out = set()
    # the pressure drop reaches the model only through coefficients affine in it
    pressure_driven = "per_bar" in json.dumps(doc.get("seal", []))
    for p in paths(doc):
        if p[0] in ("design", "reduction", "touchdown") or "frequency_hz" in p:
            continue
        if p == ("operating", "pressure_bar") and not pressure_driven:
            continue
        if "value" in p:
            out.add(p[:p.index("value") + 1])
        elif (any(k in PHYSICS for k in p if isinstance(k, str))
              and isinstance(_at(doc, p), (int, float)) and not isinstance(_at(doc, p), bool)
              and _at(doc, p) != 0):
            out.add(p)
    return sorted(out, key=str)


def _at(doc, path):
    for k in path:
        doc = doc[k]
    return doc


def _physics_case(tmp_path_factory, data):
    """One physical value scaled by a plausible factor: ``modes --controller pid`` either
    refuses the rig naming it, or its modes differ from the unmutated rig's (a value that
    is read but not used would leave them as they were)."""
    name = data.draw(st.sampled_from(sorted(RIGS)))
    doc = copy.deepcopy(RIGS[name])
    path = data.draw(st.sampled_from(_physics_paths(doc)))
    factor = data.draw(st.sampled_from([0.5, 0.9, 1.1, 1.5, 3.0]))
    parent = _at(doc, path[:-1])
    value = parent[path[-1]]
    parent[path[-1]] = [v * factor for v in value] if isinstance(value, list) else (
        value * factor)
    d = tmp_path_factory.mktemp("fuzz")
    if name not in _baseline:
        (d / "base.toml").write_text(dump(RIGS[name]))
        _baseline[name] = _sandboxed(d, [a or d / "base.toml" for a in _MODES], [])
    rig = d / name
    rig.write_text(dump(doc))
    code, out, err = _sandboxed(d, [a or rig for a in _MODES], [])
    _check(code, out, err, [str(rig)])
    if code == 0:
        base = json.loads(_baseline[name][1])
        new = json.loads(out)
        keys = ("natural_frequencies_hz", "damping_ratios", "unstable_poles")
        assert any(new.get(k) != base.get(k) for k in keys), (path, factor)


#: The drop's rig: the rigid rotor on two rings of test_cli_drop, a seal at mid-span whose
#: cross-coupled stiffness grows with its pressure drop as the test rig's does (a surge of
#: thousands of bar drives a whirl into the rings).
DROP_RIG = tomllib.loads(_rig_text() + '[[seal]]\nname = "mid"\nposition = 0.2\n'
                         "clearance = 3.0e-4\nk = { per_bar = 1.0e6 }\n"
                         "C = { at_zero = 100.0, per_bar = 50.0 }\n"
                         "[drop]\naxial_thrust = 0.0\n")
#: Keys a [[touchdown]] or [drop] table may add, with values inside, at and beyond their
#: bounds and their rules (a support stiffness without its mass, a friction velocity below
#: what the drop resolves).
_ADDED = {"touchdown": {"support_stiffness": [1e7, 1e13, 1e-3], "support_mass": [0.5, 0.0],
                        "support_damping": [2e3, 1e9], "friction_velocity": [1e-15, 1e-4,
                                                                              10.0],
                        "axial_clearance": [1e-4, 0.1], "race_mass": [0.05],
                        "static_rating": [1e4, 1.0], "race_drag_torque": [1e5]},
          "drop": {"axial_thrust": [2e3, -1e8, 1e8], "force_ratio": [1e-9, 100.0],
                   "race_temperature_rise": [1e-3]}}
#: Values of the drop's options: plausible, at the bounds of their keys and beyond.
_SPEEDS = [["--speed-rpm", v] for v in ("0", "-3000", "3000", "6e4", "1e6", "3e6")] + [
    ["--speed-hz", v] for v in ("-500", "50", "5e4", "2e5")] + [
    ["--at", v] for v in ("standstill", "max-continuous", "trip")] + [[]]
_EVENTS = [[], ["--event", "one-axis"], ["--event", "one-axis", "--axis", "B_zeta"],
           ["--event", "overload", "--overload-n", "1500"],
           ["--event", "overload", "--overload-n", "1e8"],
           ["--event", "overload", "--surge-bar", "3000", "--unbalance-kgm", "1e-4"],
           ["--event", "overload", "--surge-bar", "1e4"],
           ["--event", "overload", "--surge-bar", "1e5"],
           ["--event", "overload", "--surge-bar", "-1"], ["--axial-thrust-n", "2000"],
           ["--axial-thrust-n", "1e9"], ["--coast-down", "--drag-torque", "2"],
           ["--unbalance-kgm", "2e-3", "--start", "rest"], ["--pressure-bar", "1e5"]]
_SCATTER = [["--friction", "3:5"], ["--friction", "0:2"], ["--friction", "0.1:0.3"],
            ["--clearance-tol-um", "150"], ["--clearance-tol-um", "500"],
            ["--support-damping", "0.5:2"], ["--support-damping", "1:1e12"],
            ["--unbalance-kgm", "0:1e-4"]]


@st.composite
def _drop_args(draw) -> list:
    """Options of ``ambseal drop``: a speed, an event, and sometimes Monte-Carlo ranges
    with ``--runs 1`` (short drops: 2 to 10 ms)."""
    args = [*draw(st.sampled_from(_SPEEDS)), *draw(st.sampled_from(_EVENTS)),
            "--duration-s", draw(st.sampled_from(["0.002", "0.005", "0.01"]))]
    if draw(st.booleans()):
        args += ["--runs", "1", "--workers", "1", *draw(st.sampled_from(_SCATTER))]
    return args


@st.composite
def _drop_rigs(draw) -> dict:
    """:data:`DROP_RIG` with its ``[[touchdown]]`` and ``[drop]`` tables mutated (keys
    deleted, odd values, numbers scaled, a bearing duplicated) and keys of
    :data:`_ADDED` added."""
    doc = copy.deepcopy(DROP_RIG)
    if draw(st.booleans()):
        doc = draw(mutated(doc, under=("touchdown", "drop")))
    for _ in range(draw(st.integers(0, 2))):
        table = draw(st.sampled_from(sorted(_ADDED)))
        key = draw(st.sampled_from(sorted(_ADDED[table])))
        value = draw(st.sampled_from(_ADDED[table][key]))
        tables = {"drop": [doc.get("drop")], "touchdown": doc.get("touchdown")}[table]
        tables = [t for t in tables if isinstance(t, dict)] if isinstance(
            tables, list) else []
        if tables:
            draw(st.sampled_from(tables))[key] = value
    return doc


def _drop_case(tmp_path_factory, doc: dict, args: list):
    """``ambseal drop`` of a rig ``doc`` (:func:`_drop_rigs`) with the options ``args``
    (:func:`_drop_args`): refused in one line naming the rig or an option, or dropped
    within the deadline to finite results — one plane per bearing, at a speed and
    pressure the rig file accepts, each Monte-Carlo draw a rig the rig file accepts — in
    which the energy the drop dissipated is never negative: what the rotor's energy
    gained came from the work done on it (the drive, the AMBs, the seals, a force), as
    the drop accounts it (:attr:`ambseal.analysis.drop.DropResult.work`)."""
    d = tmp_path_factory.mktemp("fuzz")
    rig = d / "rig.toml"
    rig.write_text(dump(doc))
    code, out, err = _sandboxed(d, ["--quiet", "drop", rig, *args, "--out", d / "o",
                                    "--json"], [d / "o"], seconds=60.0)
    options = [a for a in args if a.startswith("--")]
    _check(code if code != 1 else 0, out, err, [str(rig), str(d / "o"), *options])
    if code == 2:
        return
    if "--runs" in args:
        _check_draws(doc, d / "o" / "drop_scatter.csv")
        return
    result = json.loads(out)
    names = [t["name"] for t in doc["touchdown"]]
    assert [p["name"] for p in result["planes"]] == names, names
    # the speed and the pressure it dropped at are ones the rig file accepts
    parse_rig({**doc, "operating": {**doc.get("operating", {}),
                                    "speed_rpm": result["speed_rpm"],
                                    "pressure_bar": result["pressure_bar"]}}, "as dropped")
    scale = max(abs(result["external_work_j"]), 1e-3)
    assert result["energy_dissipated_j"] >= -1e-4 * scale, (
        args, result["energy_dissipated_j"], result["external_work_j"])


def _check_draws(doc: dict, table: Path) -> None:
    """Each Monte-Carlo run of the rig ``doc`` keeps a column set per bearing, and its
    draws make a rig the rig file accepts."""
    with open(table, newline="") as fh:
        rows = list(csv.DictReader(fh))
    names = [t["name"] for t in doc["touchdown"]]
    assert sum(k.endswith("_peak_force_n") for k in rows[0]) == len(names), rows[0]
    for row in rows:
        if row.get("error"):
            continue
        drawn = copy.deepcopy(doc)
        for td in drawn["touchdown"]:
            td.update({k: float(row[f"{td['name']}_{c}"]) for k, c in (
                ("friction", "friction"), ("radial_clearance", "clearance_m"),
                ("support_damping", "support_damping"))})
        parse_rig(drawn, f"run {row['run']}")


@fuzz(150)
@given(data=st.data())
def test_fuzz_rig_files(tmp_path_factory, data):
    _rig_case(tmp_path_factory, data)


@fuzz(25)
@given(data=st.data())
def test_fuzz_truth_files(tmp_path_factory, data):
    _truth_case(tmp_path_factory, data)


@fuzz(40)
@given(data=st.data())
def test_fuzz_records(tmp_path_factory, record, data):
    _record_case(tmp_path_factory, record, data)


@fuzz(120)
@given(data=st.data())
def test_fuzz_controller_files(tmp_path_factory, controller, data):
    _controller_case(tmp_path_factory, controller, data)


@fuzz(60)
@given(data=st.data())
def test_fuzz_ranges(tmp_path_factory, data):
    _range_case(tmp_path_factory, data)


@pytest.mark.heavy
@fuzz(40)
@given(data=st.data())
def test_fuzz_physics_changes_show(tmp_path_factory, data):
    _physics_case(tmp_path_factory, data)


#: Inputs the drop once answered wrongly, tried on every run: two bearings of one name
#: (one set of columns in the Monte-Carlo table), a friction drawn beyond its key's bound,
#: a speed in Hz beyond the bound of one in rpm, a seal surge that crawled for minutes.
_TWINS = tomllib.loads(dump(DROP_RIG).replace('name = "TB"', 'name = "TA"'))
_SHORT = ["--duration-s", "0.005"]


@pytest.mark.heavy
@fuzz(8)
@given(doc=_drop_rigs(), args=_drop_args())
@example(doc=_TWINS, args=["--runs", "1", "--workers", "1", *_SHORT])
@example(doc=DROP_RIG, args=["--runs", "1", "--workers", "1", "--friction", "3:5", *_SHORT])
@example(doc=DROP_RIG, args=["--speed-hz", "5e4", *_SHORT])
@example(doc=DROP_RIG, args=["--event", "overload", "--surge-bar", "1e4", "--duration-s",
                             "0.05"])
def test_fuzz_drops(tmp_path_factory, doc, args):
    _drop_case(tmp_path_factory, doc, args)


def test_the_fuzz_harness_sees_a_hang_and_a_stray_file(tmp_path):
    """The deadline stops a case that runs too long and the sandbox sees a file written
    outside the output (so the fuzz tests above can fail)."""
    with pytest.raises(Hang):
        with _deadline(0.2):
            while True:
                pass
    (tmp_path / "in.txt").write_text("x")
    before = _tree(tmp_path, [tmp_path / "o"])
    (tmp_path / "o").mkdir()
    (tmp_path / "o" / "fine.txt").write_text("y")
    assert _tree(tmp_path, [tmp_path / "o"]) == before
    (tmp_path / "in.txt").write_text("changed")
    assert _tree(tmp_path, [tmp_path / "o"]) != before


@pytest.mark.slow
@fuzz(150, slow=True)
@given(data=st.data())
def test_fuzz_rig_files_long(tmp_path_factory, data):
    _rig_case(tmp_path_factory, data)


@pytest.mark.slow
@fuzz(25, slow=True)
@given(data=st.data())
def test_fuzz_truth_files_long(tmp_path_factory, data):
    _truth_case(tmp_path_factory, data)


@pytest.mark.slow
@fuzz(40, slow=True)
@given(data=st.data())
def test_fuzz_records_long(tmp_path_factory, record, data):
    _record_case(tmp_path_factory, record, data)


@pytest.mark.slow
@fuzz(120, slow=True)
@given(data=st.data())
def test_fuzz_controller_files_long(tmp_path_factory, controller, data):
    _controller_case(tmp_path_factory, controller, data)


@pytest.mark.slow
@fuzz(40, slow=True)
@given(data=st.data())
def test_fuzz_physics_changes_show_long(tmp_path_factory, data):
    _physics_case(tmp_path_factory, data)


@pytest.mark.slow
@fuzz(60, slow=True)
@given(data=st.data())
def test_fuzz_ranges_long(tmp_path_factory, data):
    _range_case(tmp_path_factory, data)


@pytest.mark.slow
@fuzz(8, slow=True)
@given(doc=_drop_rigs(), args=_drop_args())
def test_fuzz_drops_long(tmp_path_factory, doc, args):
    _drop_case(tmp_path_factory, doc, args)
