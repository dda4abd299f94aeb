"""The unbalance force rejection as it is exported (export/notch_files.py and its C in
export/codegen.py): the file read back is the notch that was judged; the compiled C99
module computes what the notch's own matrices compute, sample by sample, over a speed
ramp through its on speed and its whole table; bad files are refused naming the key."""

import json

import numpy as np
import pytest

from ambseal.errors import DataError
from ambseal.export.codegen import write_notch_c
from ambseal.export.notch_files import export_notch, load_notch
from ambseal.machine import SynchronousNotch
from .robust.test_robust_digital import _compile_and_run

RNG = np.random.default_rng(11)
P = 4
SPEEDS = 2 * np.pi * np.array([20.0, 60.0, 110.0])
T = RNG.normal(size=(3, P, P)) + 1j * RNG.normal(size=(3, P, P))
NAMES = tuple(f"y_{a}_{x}" for a in "AB" for x in ("zeta", "eta"))
# NumPy scalars as a design gives them: the C must print them as numbers
NOTCH = SynchronousNotch(SPEEDS, T.real, T.imag, np.float64(0.05), SPEEDS[0], NAMES, 1e-4)


def test_notch_file_round_trip(tmp_path):
    """The document read back is the notch written: its matrices at table speeds, between
    them and beyond the ends equal to the bit."""
    back = load_notch(export_notch(NOTCH, tmp_path / "rejection_mu.json", "K_mu"))
    assert back.inputs == NAMES and back.dt == NOTCH.dt and back.on_rad_s == NOTCH.on_rad_s
    for w in (SPEEDS[0], 0.3 * SPEEDS[0] + 0.7 * SPEEDS[1], 1.2 * SPEEDS[-1]):
        for X, Y in zip(back.matrices_at(w), NOTCH.matrices_at(w)):
            np.testing.assert_array_equal(X, Y)


@pytest.mark.parametrize(("edit", "match"), [
    ({"kind": "controller"}, "synchronous_notch"),
    ({"inputs": ["y_A */ x", "y_B", "y_C", "y_D"]}, "inputs"),
    ({"Ts": 0.0}, "Ts"),
    ({"rate_fraction": "fast"}, "rate_fraction"),
    ({"gain_re": [[1.0]]}, "gain_re"),
    ({"speeds_rad_s": [3.0, 2.0, 1.0]}, "increase"),
    # a typo for 1e-4: the table's speeds far above Nyquist, ε·Ts ≈ 3.5e5, and the state
    # would reach 1e307 within 60 samples
    ({"Ts": 1e4}, "Ts.*Nyquist"),
    ({"gain_re": np.vectorize(str)(T.real).tolist()}, "gain_re.*numbers"),
    ({"gain_im": (T.imag > 0).tolist()}, "gain_im.*numbers"),
    ({"speeds_rad_s": ["125.6", 377.0, 691.1]}, "speeds_rad_s.*numbers"),
    # hand-edited tables with rows of unequal length (NumPy's ValueError "setting an array
    # element with a sequence"): the row named
    ({"gain_re": [T.real[0].tolist(), T.real[1].tolist(),
                  [T.real[2, 0].tolist(), T.real[2, 1, :3].tolist(), *T.real[2, 2:].tolist()]]},
     r"n.json: gain_re\[2\]\[1\]: expected 4 numbers, got 3"),
    ({"gain_im": [T.imag[0].tolist(), T.imag[1].tolist(), [1.0, *T.imag[2, 1:].tolist()]]},
     r"n.json: gain_im\[2\]\[0\]: expected a list of 4, got a number"),
    ({"speeds_rad_s": [125.6, [377.0], 691.1]},
     r"n.json: speeds_rad_s\[1\]: expected a number, got a list"),
])
def test_bad_notch_files_are_refused_naming_the_key(tmp_path, edit, match):
    path = export_notch(NOTCH, tmp_path / "n.json")
    doc = {**json.loads(path.read_text()), **edit}
    path.write_text(json.dumps(doc))
    with pytest.raises(DataError, match=match):
        load_notch(path)


def test_notch_c_runs_like_its_matrices(tmp_path):
    """Reference: the notch's own discrete matrices (``matrices_at``, the ones judged)
    stepped in Python at each sample's speed — q = y − C_N x, x ← A_N x + B_N q, and
    below the on speed q = y with the state cleared — over a ramp from half the on speed
    to past the table's top on 6 000 samples of a random sensor signal: the compiled C
    module's q within 1e-9 of its peak."""
    n = 6000
    y = 1e-6 * RNG.standard_normal((n, P))
    speeds = np.linspace(0.5 * SPEEDS[0], 1.1 * SPEEDS[-1], n)
    x = np.zeros(2 * P)
    ref = np.empty((n, P))
    for k in range(n):
        if not NOTCH.is_on(speeds[k]):
            x[:] = 0.0
            ref[k] = y[k]
            continue
        A, B, C = NOTCH.matrices_at(speeds[k])
        ref[k] = y[k] - C @ x
        x = A @ x + B @ ref[k]
    files = write_notch_c(NOTCH, tmp_path / "c", "amb_notch")
    assert "np." not in files[0].read_text() + files[1].read_text()  # plain C numbers
    got = _compile_and_run(tmp_path, files, "amb_notch", y, "double", speeds=speeds,
                           outputs="NY")
    assert np.max(np.abs(got - ref)) < 1e-9 * np.max(np.abs(ref))
