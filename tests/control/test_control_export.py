"""Tests of ambseal.control.export: controller files and discretisation."""

from __future__ import annotations

import json

import numpy as np
import pytest
import control as ct
import scipy.io

from ambseal.control.export import discretize, export_controller


def amb_like_controller():
    """A 4-channel PID controller (thesis Paper 5 eq. 6 form) with a roll-off at 6000 rad/s;
    its fastest pole is at 8000 rad/s (1.3 kHz)."""
    s = ct.tf("s")
    kp, Ti, Td, eps = 2.0, 0.2, 5e-4, 0.25
    c = kp * (1 + 1 / (Ti * s) + Td * s / (eps * Td * s + 1)) * 1 / (s / 6000 + 1)
    K = ct.append(*[ct.ss(c)] * 4)
    K = ct.ss(K.A, K.B, K.C, K.D, inputs=["A_zeta", "A_eta", "B_zeta", "B_eta"],
              outputs=[f"i_{n}" for n in ("A_zeta", "A_eta", "B_zeta", "B_eta")], name="K")
    return K


@pytest.mark.parametrize("method", ["tustin", "zoh"])
def test_discrete_gain_matches_below_tenth_of_nyquist(method):
    """Reference: sampling theory — Tustin and ZOH equivalents reproduce the continuous
    frequency response at frequencies well below Nyquist; here within 1 % up to a tenth of
    Nyquist at fs = 20 kHz for a controller whose poles lie below 1.3 kHz (Franklin, Powell &
    Workman, ch. 6). (ZOH exceeds 1 % when the controller has poles near fs/6.)"""
    K = amb_like_controller()
    fs = 20e3
    Kd = discretize(K, fs, method)
    w = np.logspace(0, np.log10(0.1 * np.pi * fs), 200)  # rad/s up to a tenth of Nyquist
    Gc = ct.frequency_response(K, w).magnitude
    Gd = ct.frequency_response(Kd, w).magnitude
    diag = np.arange(4)
    np.testing.assert_allclose(Gd[diag, diag], Gc[diag, diag], rtol=1e-2)
    assert Kd.dt == pytest.approx(1 / fs)
    assert list(Kd.input_labels) == list(K.input_labels)


@pytest.mark.parametrize("suffix", [".npz", ".mat", ".json"])
def test_roundtrip_and_atomic_write(tmp_path, suffix):
    """Reference: the file content equals the controller matrices and names (definition);
    the stored Tustin and ZOH equivalents equal python-control's control.sample_system of
    the same realisation (run side by side); no temporary file is left in the folder."""
    K = amb_like_controller()
    path = export_controller(K, tmp_path / f"K{suffix}", fs_hz=20e3)
    if suffix == ".npz":
        d = np.load(path)
        inputs = [str(x) for x in d["inputs"]]
    elif suffix == ".mat":
        d = scipy.io.loadmat(path)
        inputs = [str(np.ravel(x)[0]) for x in np.ravel(d["inputs"])]
    else:
        d = {k: (np.array(v) if isinstance(v, list) and k not in ("inputs", "outputs", "states")
                 else v) for k, v in json.loads(path.read_text()).items()}
        inputs = d["inputs"]
    np.testing.assert_allclose(d["A"], K.A)
    np.testing.assert_allclose(np.atleast_2d(d["D"]), K.D)
    Kt = ct.sample_system(K, 1 / 20e3, "tustin")
    Kz = ct.sample_system(K, 1 / 20e3, "zoh")
    for name, ref in (("A_tustin", Kt.A), ("A_zoh", Kz.A), ("B_zoh", Kz.B)):
        np.testing.assert_allclose(d[name], ref, rtol=1e-9, atol=1e-12 * np.abs(ref).max(),
                                   err_msg=name)
    assert inputs == list(K.input_labels)
    assert [p.name for p in tmp_path.iterdir()] == [path.name]


def test_export_bad_input(tmp_path):
    """Reference: unknown formats and non-positive sample rates are rejected, naming them."""
    K = amb_like_controller()
    with pytest.raises(ValueError, match="format"):
        export_controller(K, tmp_path / "K.txt")
    with pytest.raises(ValueError, match="sample rate"):
        export_controller(K, tmp_path / "K.npz", fs_hz=-1.0)
    assert list(tmp_path.iterdir()) == []
