"""Filters in series with the reference PID (``[[controller.filter]]``,
:func:`ambseal.design.pid.pid_controller`): each filter's frequency response against its
transfer function built with python-control, the whole PID against the product of P5
Eq. 6 and the filters, and the keys of the rig file carried through the design, the
digital controller's description and a record's metadata."""

from __future__ import annotations

import tomllib

import control
import numpy as np
import pytest

from ambseal.config import default_rig_path, load_rig, parse_rig
from ambseal.design import controller_from_metadata, design, reference_pid
from ambseal.design.pid import filter_matrices, pid_controller, reference_controller
from ambseal.errors import ConfigError, DataError
from ambseal.files import load_toml
from ambseal.model import channel_names

S = control.tf("s")
OMEGA = np.geomspace(1.0, 1e5, 300)  # rad/s
NOTCH = {"kind": "notch", "frequency_hz": 910.0, "width_hz": 120.0, "depth_db": 26.0}
LEAD = {"kind": "lead", "frequency_hz": 300.0, "phase_deg": 40.0}


def _reference(f):
    """The filter's transfer function written from its textbook form (python-control)."""
    w = 2 * np.pi * f["frequency_hz"]
    if f["kind"] == "notch":
        zp = f["width_hz"] / (2 * f["frequency_hz"])
        zz = zp * 10 ** (-f["depth_db"] / 20)
        return (S**2 + 2 * zz * w * S + w**2) / (S**2 + 2 * zp * w * S + w**2)
    if f["kind"] == "lowpass":
        return w**2 / (S**2 + 2 * f["damping"] * w * S + w**2)
    sn = np.sin(np.radians(f["phase_deg"]))
    a = ((1 + sn) / (1 - sn)) ** (1 if f["kind"] == "lead" else -1)
    return (1 + S / (w / np.sqrt(a))) / (1 + S / (w * np.sqrt(a)))


def _response(sys, omega):
    return np.array([complex(np.squeeze(sys(1j * w))) for w in omega])


def _ss_response(a, b, c, d, omega):
    """C (jωI − A)⁻¹ B + D by dense solves (python-control's evaluation of a MIMO state
    space is off by up to 1e-5 on these filters)."""
    return np.array([c @ np.linalg.solve(1j * w * np.eye(a.shape[0]) - a, b) + d
                     for w in omega])


@pytest.mark.parametrize("f", [NOTCH, LEAD, {"kind": "lag", "frequency_hz": 1500.0,
                                             "phase_deg": 30.0},
                               {"kind": "lowpass", "frequency_hz": 2500.0, "damping": 0.5}],
                         ids=lambda f: f["kind"])
def test_each_filter_is_its_transfer_function(f):
    """Reference: the textbook transfer function in python-control, to 1e-12 over five
    decades; the notch's gain at its centre is −depth_db, a lead's (lag's) phase at its
    centre is +phase_deg (−phase_deg) and its largest there."""
    a, b, c, d = filter_matrices(f)
    ours = _ss_response(a, b, c, d, OMEGA)[:, 0, 0]
    ref = _response(_reference(f), OMEGA)
    assert np.max(np.abs(ours / ref - 1)) < 1e-12
    wc = 2 * np.pi * f["frequency_hz"]
    at = (c @ np.linalg.solve(1j * wc * np.eye(a.shape[0]) - a, b) + d)[0, 0]
    if f["kind"] == "notch":
        assert 20 * np.log10(abs(at)) == pytest.approx(-f["depth_db"], abs=1e-9)
    elif f["kind"] in ("lead", "lag"):
        sign = 1 if f["kind"] == "lead" else -1
        assert np.degrees(np.angle(at)) == pytest.approx(sign * f["phase_deg"], abs=1e-9)
        assert np.all(sign * np.angle(ref) <= sign * np.angle(at) + 1e-12)


def test_the_pid_with_filters_is_p5s_pid_times_the_filters():
    """Reference: P5 Eq. 6 times each filter, every axis alike and uncoupled."""
    kp, ti, td, eps = 2.0e4, 0.2, 3.0e-3, 0.05
    K = pid_controller(kp, ti, td, eps, ("A_zeta", "A_eta"), [NOTCH, LEAD])
    assert K.nstates == 2 * (2 + 2 + 1)
    pid = kp * (1 + 1 / (ti * S) + td * S / (eps * td * S + 1))
    ref = _response(pid, OMEGA) * _response(_reference(NOTCH), OMEGA) \
        * _response(_reference(LEAD), OMEGA)
    H = _ss_response(*(np.asarray(getattr(K, m)) for m in "ABCD"), OMEGA)
    assert np.max(np.abs(H[:, 1, 1] / ref - 1)) < 1e-9
    assert np.max(np.abs(H[:, 0, 1])) == 0.0


def _rig_with(text: str):
    """The embedded rig with the ``[controller]`` keys of ``text`` (TOML) added."""
    data = load_toml(default_rig_path(), "rig")
    data.setdefault("controller", {}).update(tomllib.loads(text)["controller"])
    return parse_rig(data, "rig.toml")


def test_rig_file_filters_reach_the_pid_its_description_and_a_records_metadata():
    """``[[controller.filter]]`` given in the rig file: the designed PID carries it (four
    axes × the notch's two states more than the plain PID), the digital controller's
    description names it, and a record's metadata with that description rebuilds the
    same discrete controller."""
    cfg = _rig_with('[[controller.filter]]\nkind = "notch"\nfrequency_hz = 910.0\n'
                    'width_hz = 120.0\n')
    plain = design(load_rig(), "pid").K
    K = design(cfg, "pid").K
    assert K.nstates == plain.nstates + 2 * 4
    assert reference_pid(cfg)["filters"] == [{"kind": "notch", "frequency_hz": 910.0,
                                              "width_hz": 120.0, "depth_db": 20.0,
                                              "damping": 0.7}]
    ctrl = reference_controller(cfg)
    assert ctrl.description["filters"][0]["frequency_hz"] == 910.0
    meta = {"controller": ctrl.description, "sample_rate_hz": cfg.controller.sample_rate_hz}
    back = controller_from_metadata(meta, tuple(channel_names(cfg)))
    for m in "ABCD":
        np.testing.assert_allclose(getattr(back, m), getattr(ctrl, m), rtol=0, atol=0)
    # the PID's own gain at the notch is 20 dB down
    w = [2 * np.pi * 910.0]
    gain = [abs(_ss_response(*(np.asarray(getattr(k, m)) for m in "ABCD"), w)[0, 0, 0])
            for k in (K, plain)]
    assert gain[0] / gain[1] == pytest.approx(0.1, rel=1e-9)


@pytest.mark.parametrize("text, key", [
    ('[[controller.filter]]\nkind = "notch"\nfrequency_hz = 910.0\n', "width_hz"),
    ('[[controller.filter]]\nkind = "lead"\nfrequency_hz = 300.0\nphase_deg = 30.0\n'
     'width_hz = 50.0\n', "width_hz"),
    ('[[controller.filter]]\nkind = "lag"\nfrequency_hz = 300.0\nphase_deg = 95.0\n',
     "phase_deg"),
    ('[[controller.filter]]\nkind = "bandpass"\nfrequency_hz = 300.0\n', "kind"),
])
def test_a_bad_filter_is_refused_naming_its_key(text, key):
    with pytest.raises(ConfigError) as err:
        _rig_with(text)
    msg = str(err.value)
    assert msg.startswith("rig.toml: controller.filter") and key in msg


def test_a_records_bad_filter_is_refused_naming_the_file():
    meta = {"controller": {"type": "pid", "kp": 1e4, "ti": 0.2, "td": 3e-3, "eps": 0.1,
                           "filters": [{"kind": "notch", "frequency_hz": 900.0}]},
            "sample_rate_hz": 10000.0}
    with pytest.raises(DataError, match=r"^rec\.json: metadata\.controller\.filters: .*width_hz"):
        controller_from_metadata(meta, ("A_zeta",), "rec.json")
