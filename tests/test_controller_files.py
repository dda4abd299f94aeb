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
