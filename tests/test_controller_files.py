"""Controller files that are not what ambseal writes end in one error type, DataError, naming
the file and the problem, in every supported format (.json, .npz, .mat) — never a
traceback; and a controller holding NaN or inf is not written at all.

The reference is the loader's contract (``ambseal.export.controller_files.load_controller``) and the
CLI's promise: one line on stderr, exit status 2.
"""

import io
import json

import control
import numpy as np
import pytest
import scipy.io

from ambseal.cli import main
from ambseal.config import default_rig_path
from ambseal.export.controller_files import export_controller, load_controller
from ambseal.errors import DataError

RIG = str(default_rig_path())


@pytest.fixture(scope="module")
def files(tmp_path_factory):
    """The reference PID of the embedded rig as ``ambseal design`` writes it, all formats."""
    out = tmp_path_factory.mktemp("ctl")
    assert main(["design", RIG, "--method", "pid", "--out", str(out), "--allow-unstable"]) == 0
    return {ext: out / f"controller_pid.{ext}" for ext in ("json", "npz", "mat")}


def _json(files, edit) -> bytes:
    doc = json.loads(files["json"].read_text())
    edit(doc)
    return json.dumps(doc, allow_nan=True).encode()


def _npz(files, **changes) -> bytes:
    with np.load(files["npz"], allow_pickle=False) as z:
        doc = {k: z[k] for k in z.files}
    buf = io.BytesIO()
    np.savez(buf, **{**doc, **changes})
    return buf.getvalue()


def _mat(files, whole: bool = False, **changes) -> bytes:
    """The .mat file with ``changes``, or (``whole``) saved as one struct ``K``."""
    doc = {k: v for k, v in scipy.io.loadmat(files["mat"]).items() if not k.startswith("__")}
    buf = io.BytesIO()
    scipy.io.savemat(buf, {"K": doc} if whole else {**doc, **changes})
    return buf.getvalue()


#: (name, the file's bytes from the reference files, what the message says)
CASES = [
    ("list.json", lambda f: b"[1, 2, 3]", "JSON object"),
    ("deep.json", lambda f: b"[" * 100000 + b"]" * 100000, "nested too deeply"),
    ("deep_object.json", lambda f: b'{"a":' * 100000 + b"1" + b"}" * 100000,
     "nested too deeply"),
    ("latin1.json", lambda f: b"\xff\xfe{}", "utf-8"),
    ("nan.json", lambda f: _json(f, lambda d: d.update(A=[[float("nan")] * len(d["A"][0])]
                                                       * len(d["A"]))), "A: expected finite"),
    ("inf_delay.json", lambda f: _json(f, lambda d: d.update(delay_samples=1e300)),
     "delay_samples"),
    ("meta_list.json", lambda f: _json(f, lambda d: d.update(discretisation_json="[1]")),
     "JSON object"),
    ("inputs_number.json", lambda f: _json(f, lambda d: d.update(inputs=5)),
     "not a controller file"),
    ("truncated.npz", lambda f: f["npz"].read_bytes()[:200], "not a readable"),
    ("empty.npz", lambda f: b"", "not a readable"),
    ("inf.npz", lambda f: _npz(f, B_c=np.full((8, 4), np.inf)), "B_c: expected finite"),
    ("truncated.mat", lambda f: f["mat"].read_bytes()[:300], "not a readable"),
    ("v73.mat", lambda f: (b"MATLAB 7.3 MAT-file".ljust(116, b" ") + b"\0" * 8 + b"\x00\x02"
                           + b"IM" + b"\0" * 512), "v7.3"),
    ("struct.mat", lambda f: _mat(f, whole=True), "K: a struct"),
    ("field.mat", lambda f: _mat(f, A={"wrong": np.eye(2)}), "A: a struct with fields"),
    ("nan.mat", lambda f: _mat(f, C=np.full((4, 8), np.nan)), "C: expected finite"),
]


@pytest.mark.parametrize("name, make, expect", CASES, ids=[c[0] for c in CASES])
def test_a_bad_controller_file_is_one_clean_error(files, tmp_path, capsys, name, make, expect):
    path = tmp_path / name
    path.write_bytes(make(files))
    with pytest.raises(DataError) as err:
        load_controller(path)
    assert str(path) in str(err.value) and expect in str(err.value), str(err.value)
    capsys.readouterr()
    code = main(["export", RIG, "--controller", str(path), "--out", str(tmp_path / "o")])
    lines = capsys.readouterr().err.strip().splitlines()
    assert code == 2 and len(lines) == 1, lines
    assert lines[0].startswith(f"ambseal: error: {path}: "), lines  # the file, not the rig


def test_the_reference_files_still_load(files):
    """The three formats written by ``ambseal design`` read back to the same controller."""
    Ks = [load_controller(p) for p in files.values()]
    for K in Ks[1:]:
        np.testing.assert_array_equal(K.discrete.A, Ks[0].discrete.A)
        assert K.inputs == Ks[0].inputs and K.delay_samples == Ks[0].delay_samples


@pytest.mark.parametrize("ext", ["json", "npz", "mat"])
def test_a_controller_with_nan_is_not_written(tmp_path, ext):
    """JSON has no NaN (it was written as the invalid token ``NaN``); no format is written
    with one, and nothing is left behind."""
    K = control.ss([[-1.0, np.nan], [0.0, -2.0]], [[1.0], [0.0]], [[1.0, 0.0]], [[0.0]],
                   inputs=["y_A_zeta"], outputs=["i_A_zeta"])
    path = tmp_path / f"K.{ext}"
    with pytest.raises(DataError, match="A: expected finite"):
        export_controller(K, path)
    assert list(tmp_path.iterdir()) == []


def _rewired(doc: dict, order, rename=None) -> dict:
    """``doc`` (a JSON controller document) with its channels listed in ``order`` — the
    same controller, its B columns, C rows and D entries moved with their names — and
    names mapped by ``rename``."""
    out = dict(doc)
    rename = rename or {}
    for key in ("inputs", "outputs"):
        out[key] = [rename.get(doc[key][j], doc[key][j]) for j in order]
    for suf in ("", "_c", "_r"):
        B, C, D = (np.asarray(doc[k + suf]) for k in "BCD")
        out["B" + suf] = B[..., :, order].tolist()
        out["C" + suf] = C[..., order, :].tolist()
        out["D" + suf] = D[..., order, :][..., :, order].tolist()
    return out


def _one_line(capsys, argv, *words) -> str:
    code = main([str(a) for a in argv])
    lines = capsys.readouterr().err.strip().splitlines()
    assert code == 2 and len(lines) == 1, lines
    assert all(w in lines[0] for w in words), lines[0]
    return lines[0]


def test_a_controller_file_is_wired_by_signal_name(files, tmp_path, capsys):
    """Reference: the same controller in another signal order (B before A, η before ζ) is
    the same controller. Loaded for the rig it comes back in the rig's channel order with
    the very matrices of the file in that order, and ``sweep`` judges it alike: the same
    σ̄(S_o) peak, max real pole and log decrement (by position the peaks differ)."""
    import csv

    doc = json.loads(files["json"].read_text())
    moved = tmp_path / "K_moved.json"
    moved.write_text(json.dumps(_rewired(doc, [3, 2, 1, 0])))
    channels = ("A_zeta", "A_eta", "B_zeta", "B_eta")
    a, b = (load_controller(p, channels) for p in (files["json"], moved))
    assert b.inputs == [f"y_{c}" for c in channels] and b.outputs == [f"i_{c}" for c in channels]
    for x, y in ((a.discrete, b.discrete), (a.continuous, b.continuous)):
        for k in "ABCD":
            np.testing.assert_array_equal(getattr(x, k), getattr(y, k))
    rows = []
    for path in (files["json"], moved):
        out = tmp_path / f"sw_{path.stem}"
        assert main(["sweep", RIG, "--pressure-bar", "1", "--controller", str(path),
                     "--workers", "1", "--out", str(out)]) == 0
        rows.append(next(csv.DictReader((out / "sweep.csv").open())))
    capsys.readouterr()
    for key in ("stable", "sensitivity_peak", "max_real_pole", "lowest_log_dec"):
        assert rows[1][key] == rows[0][key], key
    assert 1.0 < float(rows[0]["sensitivity_peak"]) < 10.0


def test_a_controller_for_other_channels_is_refused_by_every_command(files, tmp_path, capsys):
    """Reference: the rig file's [[amb]] channels. A file whose B_eta channel is C_eta, or a
    rig with one AMB for a four-axis controller: ``sweep``, ``campbell``, ``modes`` and
    ``export`` each end in one line naming the file and both sets of signals (exit 2), and
    ``export`` writes no C; ``export`` with a rig file that does not exist is an error too,
    not a C module."""
    import tomllib

    from .toml_text import dump

    doc = json.loads(files["json"].read_text())
    other = tmp_path / "K_other.json"
    other.write_text(json.dumps(_rewired(doc, [0, 1, 2, 3], {"y_B_eta": "y_C_eta",
                                                           "i_B_eta": "i_C_eta"})))
    data = tomllib.loads(open(RIG, encoding="utf-8").read())
    data["amb"] = data["amb"][:1]
    one = tmp_path / "one_amb.toml"
    one.write_text(dump(data))
    c_dir = tmp_path / "c"
    for argv, path in (
            (["sweep", RIG, "--pressure-bar", "1", "--workers", "1", "--out", tmp_path / "s"],
             other),
            (["campbell", RIG, "--speed-hz", "0:10:2", "--out", tmp_path / "cb"], other),
            (["modes", RIG], other),
            (["export", RIG, "--c", c_dir], other),
            (["export", one, "--c", c_dir], files["json"])):
        err = _one_line(capsys, argv + ["--controller", path], str(path), "y_A_zeta")
        assert "its channels are not the rig's" in err
        assert ("y_C_eta" in err) == (path == other) and "y_B_eta" in err
    assert not c_dir.exists()
    _one_line(capsys, ["export", tmp_path / "missing.toml", "--controller", files["json"],
                       "--c", c_dir], "missing.toml")
    assert not c_dir.exists()


def test_a_controller_file_whose_kind_its_matrices_contradict_is_refused(files, tmp_path,
                                                                          capsys):
    """Reference: the file's own statement — its discrete A … D are the ``method``
    discretisation at Ts = 1/sample_rate_hz of its A_r … D_r (what ``ambseal export``
    writes). A continuous controller marked discrete (its continuous matrices as the step
    matrices: spectral radius far above 1), a file whose Ts is not 1/sample_rate_hz and a
    continuous file with Ts ≠ 0 are refused before any C is written; the file as written
    loads."""
    doc = json.loads(files["json"].read_text())
    K = load_controller(files["json"])
    assert np.max(np.abs(np.linalg.eigvals(K.discrete.A))) <= 1.0 + 1e-12  # integrators
    cont = {**doc, **{k: doc[k + "_r"] for k in "ABCD"}}
    assert np.max(np.abs(np.linalg.eigvals(np.asarray(cont["A"])))) > 100.0
    slow = {**doc, "Ts": 2 * doc["Ts"]}
    marked = {k: doc[k + "_c"] for k in "ABCD"} | {
        "kind": "continuous", "Ts": doc["Ts"], "inputs": doc["inputs"],
        "outputs": doc["outputs"]}
    c_dir = tmp_path / "c"
    for name, bad, words in (("cont.json", cont, ("not the", "discretisation",
                                                  "spectral radius")),
                             ("ts.json", slow, ("Ts = ", "1/sample_rate_hz")),
                             ("marked.json", marked, ("continuous", "Ts = 0"))):
        path = tmp_path / name
        path.write_text(json.dumps(bad))
        with pytest.raises(DataError, match="|".join(words)):
            load_controller(path)
        _one_line(capsys, ["export", RIG, "--controller", path, "--c", c_dir], str(path),
                  *words)
    assert not c_dir.exists()
    assert main(["export", RIG, "--controller", str(files["json"]), "--c", str(c_dir),
                 "--allow-unstable"]) == 0  # the test rig's PID loses 4.08 bar
