"""Property-based fuzz of the command line: mutated example rigs, truth files
and records end either in exit 2 with one line on stderr naming the file, or in exit 0 with
finite results — never in a traceback.

The CLI's ``main()`` is called in-process (a subprocess per example would cost a second of
imports each). About 40 s by default; ``-m slow`` runs ten times the examples, new random
ones each time (the default set is derandomized, the same in every CI run).
"""

import contextlib
import copy
import io
import json
import math
import tomllib

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from ambseal.cli import main

from .conftest import ROOT
from .toml_text import dump

RIGS = {name: tomllib.loads((ROOT / "examples" / name).read_text())
        for name in ("testrig.toml", "turboexpander.toml")}
TRUTH = tomllib.loads((ROOT / "src" / "ambseal" / "data" / "testrig_truth.toml").read_text())

#: Replacement values: wrong types, non-finite and extreme numbers, empty containers.
ODD = st.sampled_from([True, False, "1.5", "", "x.y", {}, [], [1.0, "a"], math.nan, math.inf,
                       -math.inf, 1e308, -1e308, 1e-308, 0, 0.0, -1, -1.0, 10**30, 2**63,
                       {"at_zero": math.nan}, {"zeta": 1.0}, {"frequency_hz": [1.0, 0.5],
                                                             "value": [1.0, 2.0]}])


def _paths(node, prefix=()):
    """Every path (tuple of keys/indices) to a value inside ``node``."""
    out = []
    items = node.items() if isinstance(node, dict) else (
        enumerate(node) if isinstance(node, list) else ())
    for k, v in items:
        out.append(prefix + (k,))
        out += _paths(v, prefix + (k,))
    return out


@st.composite
def mutated(draw, doc: dict):
    """``doc`` with 1–3 mutations: a key deleted, a value replaced by an odd one, a number
    scaled by a wild factor, or a table duplicated."""
    doc = copy.deepcopy(doc)
    for _ in range(draw(st.integers(1, 3))):
        paths = _paths(doc)
        if not paths:
            break
        path = draw(st.sampled_from(paths))
        parent = doc
        for k in path[:-1]:
            parent = parent[k]
        key, value = path[-1], parent[path[-1]]
        op = draw(st.sampled_from(["delete", "replace", "scale", "duplicate"]))
        if op == "delete":
            del parent[key]
        elif op == "scale" and isinstance(value, (int, float)) and not isinstance(value, bool):
            factor = draw(st.sampled_from([-1.0, 0.0, 1e-12, 1e-3, 1.000001, 1e3, 1e12]))
            parent[key] = type(value)(value * factor) if isinstance(value, float) else (
                int(value * factor))
        elif op == "duplicate" and isinstance(parent, list):
            parent.append(copy.deepcopy(value))
        else:
            parent[key] = copy.deepcopy(draw(ODD))
    return doc


def _garbage(draw, text: str) -> bytes:
    """``text`` as UTF-8 with random bytes spliced in (sometimes none)."""
    data = text.encode()
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
    code, out, err = _call(["modes", str(rig), "--json"])
    _check(code, out, err, [str(rig)])


def _truth_case(tmp_path_factory, data):
    """``ambseal acquire`` with a mutated truth file: refused naming it, or a record of
    finite samples (a 0.02 s PRBS, short to keep the example fast)."""
    doc = data.draw(mutated(TRUTH))
    d = tmp_path_factory.mktemp("fuzz")
    truth = d / "truth.toml"
    truth.write_bytes(_garbage(data.draw, dump(doc)))
    code, out, err = _call(["acquire", str(ROOT / "examples" / "testrig.toml"), "--truth",
                            str(truth), "--excitation", "prbs", "--duration-s", "0.02",
                            "--pressure-bar", "0", "--out", str(d / "r.csv")])
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
    code, out, err = _call(["identify", str(ROOT / "examples" / "testrig.toml"), str(csv),
                            "--params", "A.Ki_zeta", "--no-refine", "--out", str(d / "o")])
    _check(code, out, err, [str(csv), str(d / "o")])


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
