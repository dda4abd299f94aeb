"""MATLAB files are read in a child process (ambseal.identify.records.matlab_file): scipy's compiled
reader ends the whole process with a segmentation fault on some malformed files (found by
the fuzz of controller files: a few bytes changed in a valid file), which must be one
DataError naming the file instead. The child is forked, so a reader replaced here (a crash,
a hang) is the one it runs."""

import os
import signal
import time

import numpy as np
import pytest
import scipy.io

from ambseal.errors import DataError
from ambseal.identify.records.matlab_file import read_matlab


@pytest.fixture
def mat(tmp_path):
    path = tmp_path / "x.mat"
    scipy.io.savemat(path, {"A": np.eye(2), "name": "K", "inputs": np.array(["a", "bc"],
                                                                             dtype=object),
                            "S": {"f": 1.0}})
    return path


def test_plain_values_come_back(mat):
    got = read_matlab(mat, squeeze_me=False, chars_as_strings=True)
    assert got["A"][0] == "array" and np.array_equal(got["A"][1], np.eye(2))
    assert got["name"][0] == "array" and got["name"][1].dtype.kind == "U"
    assert got["inputs"] == ("cells", ["a", "bc"])
    assert got["S"] == ("struct", ["f"])
    assert not any(k.startswith("__") for k in got)


def test_a_reader_that_crashes_is_a_data_error(mat, monkeypatch):
    monkeypatch.setattr(scipy.io, "loadmat",
                        lambda *a, **k: os.kill(os.getpid(), signal.SIGSEGV))
    with pytest.raises(DataError, match=rf"{mat}: .*crashed.*exit code -11"):
        read_matlab(mat)


def test_a_reader_that_hangs_is_a_data_error(mat, monkeypatch):
    monkeypatch.setattr(scipy.io, "loadmat", lambda *a, **k: time.sleep(60))
    t0 = time.perf_counter()
    with pytest.raises(DataError, match=rf"{mat}: .*more than 0.5 s"):
        read_matlab(mat, timeout_s=0.5)
    assert time.perf_counter() - t0 < 10


def test_a_reader_error_names_the_file(tmp_path):
    bad = tmp_path / "bad.mat"
    bad.write_bytes(b"MATLAB 5.0 MAT-file" + b"\0" * 20)
    with pytest.raises(DataError, match=rf"{bad}: not a readable MATLAB file"):
        read_matlab(bad)
