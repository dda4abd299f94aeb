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
from ambseal.design.pid_filters import flexible_mode_filters
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


# The derived filters (ambseal.design.pid_filters) on a two-mode model of one axis: a rigid
# mass m on the AMB's negative stiffness Ks and one bending mode (modal mass m_b, ζ 0.5 %)
# seen at the sensor with the sign of its shape there, the PID of pid_from_rig's rule.
M, KS, KI, MB, FS = 50.0, 1.0e6, 200.0, 20.0, 10000.0
KP = 1.5 * KS / KI
TD = 2 * np.sqrt(0.5 * KS * M) / (KI * KP)
TI, EPS = 0.5, 1 / (2 * np.pi * FS / 10 * TD)
FLOOR = 0.2 * 0.005
RIGID_HZ = np.sqrt(0.5 * KS / M) / (2 * np.pi)


def _two_mode(fb, shape_at_sensor):
    """(A, B, C, D): y = x_r + φ_s q; m ẍ_r = Ks x_r + Ki i, q̈ + 2ζω q̇ + ω² q = φ_a Ki i."""
    wb, phi = 2 * np.pi * fb, 1 / np.sqrt(MB)
    A = np.array([[0, 1, 0, 0], [KS / M, 0, 0, 0], [0, 0, 0, 1],
                  [0, 0, -wb**2, -2 * 0.005 * wb]])
    B = np.array([[0.0], [KI / M], [0.0], [phi * KI]])
    C = np.array([[1.0, 0.0, shape_at_sensor * phi, 0.0]])
    return A, B, C, np.zeros((1, 1))


def _pid_mats(filters):
    K = pid_controller(KP, TI, TD, EPS, ("a",), filters)
    return tuple(np.asarray(getattr(K, m), float) for m in "ABCD")


def _as_it_runs(G, filters):
    """python-control: the plant sampled by its hold, the PID by Tustin with one sample of
    delay, closed u = −K y; its discrete poles."""
    T = 1 / FS
    Gd = control.sample_system(control.ss(*G), T, "zoh")
    Kd = control.sample_system(control.ss(*_pid_mats(filters)), T, "tustin") \
        * control.tf([1], [1, 0], T)
    return control.feedback(Gd, Kd).poles()


def _zeta(z):
    r = np.log(np.abs(z))
    return -r / np.hypot(r, np.angle(z))


@pytest.mark.parametrize("fb, shape, kind", [(1200.0, 1.0, "lead"), (600.0, -1.0, "lag")],
                         ids=["collocated", "non-collocated"])
def test_a_bending_mode_the_pid_drives_gets_its_phase_put_right(fb, shape, kind):
    """Reference: python-control's poles of the sampled loop. A collocated mode above the
    PID's derivative corner, whose phase the hold and delay have taken (the plain PID
    drives it, ζ < 0), gets phase lead; a non-collocated one (sensor and actuator on
    opposite sides of a node), which the PID's lead drives, gets phase lag. With the
    filter every pole lies inside the unit circle with ζ ≥ 0.2 of the structural damping."""
    G = _two_mode(fb, shape)
    plain = _as_it_runs(G, [])
    assert _zeta(plain).min() < 0
    fd = flexible_mode_filters([G], _pid_mats, FS, 1, FLOOR, RIGID_HZ)
    assert fd.kept
    (f,) = fd.filters
    assert f["kind"] == kind and f["frequency_hz"] == pytest.approx(fb, rel=0.1)
    assert fd.modes[0].collocated == (shape > 0)
    poles = _as_it_runs(G, fd.filters)
    assert np.abs(poles).max() < 1 and _zeta(poles).min() >= FLOOR
    # the mode itself: from driven (ζ < 0) to damped beyond the floor
    at = np.argmin(np.abs(np.abs(np.angle(plain)) * FS / (2 * np.pi) - fb))
    assert _zeta(plain[at]) < 0


def test_a_mode_with_a_node_at_the_sensor_needs_no_filter():
    """A bending mode with a node at the sensor is not observed: the loop leaves it at its
    structural damping (python-control's poles: ζ 0.005 at its frequency) and the rule adds
    no filter for it, where the same mode seen at the sensor non-collocated needs one."""
    seen = flexible_mode_filters([_two_mode(600.0, -1.0)], _pid_mats, FS, 1, FLOOR, RIGID_HZ)
    assert seen.filters
    G = _two_mode(600.0, 0.0)
    fd = flexible_mode_filters([G], _pid_mats, FS, 1, FLOOR, RIGID_HZ)
    assert fd.filters == () and fd.modes == () and fd.kept
    poles = _as_it_runs(G, [])
    at = np.argmin(np.abs(np.abs(np.angle(poles)) * FS / (2 * np.pi) - 600.0))
    assert _zeta(poles[at]) == pytest.approx(0.005, rel=1e-3)


def test_a_mode_no_filter_saves_is_named_with_why():
    """A non-collocated mode inside the PID's bandwidth (300 Hz, 19× the rigid-body mode)
    defeats every lead, lag and notch: the result is not kept and names the mode, that it
    is non-collocated and the phase it needed."""
    fd = flexible_mode_filters([_two_mode(300.0, -1.0)], _pid_mats, FS, 1, FLOOR, RIGID_HZ)
    assert not fd.kept
    text = fd.modes[-1].text()
    assert "non-collocated" in text and "° of phase needed" in text


def test_a_lead_above_nyquist_is_left_out_and_named():
    """A collocated mode at 0.15 f_s that the hold and delay drive (ζ < 0 as it runs): the
    rule's leads of 60° and 75° would put their pole at f_c·√α = 3.7 and 7.6 f_c, above
    the Nyquist frequency, where the target cannot run them. Every filter taken has its
    poles (python-control's, of the filter's transfer function) below Nyquist, the mode's
    text names the leads left out and why, and the loop as it runs (python-control's
    poles) keeps the floor."""
    G = _two_mode(1500.0, 1.0)
    assert _zeta(_as_it_runs(G, [])).min() < 0
    fd = flexible_mode_filters([G], _pid_mats, FS, 1, FLOOR, RIGID_HZ)
    assert fd.filters and fd.kept
    for f in fd.filters:
        poles = control.ss(*filter_matrices(f)).poles()
        assert np.abs(poles).max() / (2 * np.pi) <= FS / 2
    text = fd.modes[0].text()
    assert "(left out: lead 75°" in text and "lead 60° at" in text and "lead 45°" not in text
    assert f"above the Nyquist frequency {FS / 2:.4g} Hz" in text
    poles = _as_it_runs(G, fd.filters)
    assert np.abs(poles).max() < 1 and _zeta(poles).min() >= FLOOR


@pytest.mark.heavy
def test_the_derived_pid_chosen_below_the_sample_rate_is_the_full_orders(monkeypatch):
    """The derived PID's corner and flexible-mode filters are chosen on each condition's
    plant reduced to its modes below the sample rate (``CHOICE_MODES_PER_FS``). On a
    generated compressor that needs a filter (``benchmarks/bench_compressors.py`` seed 10,
    20 kHz, 428-state plant), the choice on every mode of the plant, its reference, gives
    the same corner and the same filters, their parameters within 1e-5."""
    import ambseal.design.pid as pid

    from ..benchmark_module import bench_module

    text, _ = bench_module("bench_compressors").compressor_rig(10)
    cfg = parse_rig(tomllib.loads(text))
    monkeypatch.setattr(pid, "_DERIVED", {})
    below = pid.pid_from_rig(cfg)
    monkeypatch.setattr(pid, "_DERIVED", {})
    monkeypatch.setattr(pid, "CHOICE_MODES_PER_FS", 1e6)  # every mode of the FE model
    every = pid.pid_from_rig(cfg)
    assert below["filters"], below["rule"]
    assert below["corner_hz"] == every["corner_hz"]
    assert [f["kind"] for f in below["filters"]] == [f["kind"] for f in every["filters"]]
    for a, b in zip(below["filters"], every["filters"]):
        for key, v in a.items():
            if isinstance(v, float):
                assert v == pytest.approx(b[key], rel=1e-5), key
