"""Tests of ambseal.analysis.loops: closed-form SISO loops and python-control side by side."""

from __future__ import annotations

import json
from pathlib import Path

import control
import numpy as np
import pytest

from ambseal.analysis import loops
from ambseal.machine.loop import closed_loop
from ambseal.errors import ModelError

from .amb_test_plants import NAMES, mass_1dof, rigid_rotor

W = np.logspace(0, 4.5, 600)
ROOT_RIG = Path(__file__).resolve().parents[2] / "examples" / "testrig.toml"


def _static(D):
    """A zero-state python-control system with feedthrough D."""
    D = np.atleast_2d(np.asarray(D, dtype=float))
    return control.ss(np.zeros((0, 0)), np.zeros((0, D.shape[1])), np.zeros((D.shape[0], 0)), D)


def test_1dof_poles_and_sensitivity_closed_form():
    """Reference: closed form for the 1-DOF AMB axis with PD control (P5 Eq. 1, 6):
    poles = roots(denG·denK + numG·numK), S = 1/(1 + G K) with G, K as polynomials in jω."""
    G, K, (nG, dG), (nK, dK) = mass_1dof()
    cl = closed_loop(G, K)
    ref_poles = np.roots(np.polyadd(np.polymul(dG, dK), np.polymul(nG, nK)))
    np.testing.assert_allclose(np.sort_complex(cl.poles), np.sort_complex(ref_poles), rtol=1e-8)
    assert cl.stable and cl.max_real_pole == pytest.approx(ref_poles.real.max(), rel=1e-8)
    s = 1j * W
    S_ref = 1.0 / (1.0 + np.polyval(nG, s) / np.polyval(dG, s) * np.polyval(nK, s) / np.polyval(dK, s))
    lr = loops.loop_responses(G, K, W)
    np.testing.assert_allclose(lr.So[:, 0, 0], S_ref, rtol=1e-9)
    np.testing.assert_allclose(lr.Si[:, 0, 0], S_ref, rtol=1e-9)  # SISO: S_i = S_o
    np.testing.assert_allclose(lr.To[:, 0, 0], 1.0 - S_ref, rtol=1e-8, atol=1e-12)
    pk = lr.peaks("So")
    k = int(np.argmax(np.abs(S_ref)))
    assert pk.sigma_max.value == pytest.approx(abs(S_ref[k]), rel=1e-9)
    assert pk.sigma_max.frequency_hz == pytest.approx(W[k] / (2 * np.pi))
    assert pk.diagonal[0].channel == "A_zeta" and pk.diagonal[0].value == pytest.approx(abs(S_ref[k]))


def test_unstable_when_gain_below_negative_stiffness():
    """Reference: with kp·ki < ks the net static stiffness is negative, so a real closed-loop
    pole is positive (Routh: constant term of m s² + ... + (kp ki − ks) < 0)."""
    G, K, _, _ = mass_1dof(kp_factor=0.5)
    cl = closed_loop(G, K)
    assert not cl.stable and cl.max_real_pole > 0
    d = cl.to_dict()
    json.dumps(d)
    assert d["stable"] is False


def test_rigid_rotor_matches_python_control_feedback():
    """Reference: python-control run side by side: control.feedback(G, K, sign=-1) poles and
    d→y response; S_o = feedback(I, G K) and S_i = feedback(I, K G), K S_o, T_o = G K S_o, all by
    control.frequency_response; rigid rotor on two AMBs with a cross-coupled seal."""
    G, Gf, K = rigid_rotor()
    cl = closed_loop(G, K, Gf)
    ref = control.feedback(G, K, sign=-1)
    np.testing.assert_allclose(np.sort_complex(cl.poles), np.sort_complex(ref.poles()), rtol=1e-7)
    assert cl.stable
    assert list(cl.system.input_labels) == [f"d_{n}" for n in NAMES] + ["Fx", "Fy"]
    assert list(cl.system.output_labels) == NAMES + [f"i_{n}" for n in NAMES]
    w = np.logspace(0, 4, 300)

    def fresp(sys):
        return np.moveaxis(control.frequency_response(sys, w, squeeze=False).complex, 2, 0)

    ours_dy = fresp(cl.system)[:, :4, :4]
    np.testing.assert_allclose(ours_dy, fresp(ref), rtol=1e-6, atol=1e-12 * np.abs(fresp(ref)).max())
    I4 = _static(np.eye(4))
    lr = loops.loop_responses(G, K, w)
    refs = {"So": control.feedback(I4, G * K), "Si": control.feedback(I4, K * G)}
    refs["To"] = G * K * refs["So"]
    refs["KS"] = K * refs["So"]
    for key, sysref in refs.items():
        R = fresp(sysref)
        np.testing.assert_allclose(getattr(lr, key), R, rtol=1e-6, atol=1e-9 * np.abs(R).max(), err_msg=key)
    sm = lr.sigma_max("So")
    R = fresp(refs["So"])
    np.testing.assert_allclose(sm, np.linalg.svd(R, compute_uv=False)[:, 0], rtol=1e-7)
    pk = lr.peaks("So")
    assert [p.channel for p in pk.diagonal] == NAMES
    assert pk.sigma_max.value >= pk.max_diagonal.value - 1e-12  # σ̄ bounds every element
    json.dumps(lr.to_dict())


def test_compliance_matches_python_control():
    """Reference: python-control side by side: compliance built as
    S_o·Gf = feedback(I, G K) * Gf (P5 §4.4.1); and the closed loop's own Fx, Fy → y channels."""
    G, Gf, K = rigid_rotor()
    w = np.logspace(0, 4, 300)
    comp = loops.compliance(G, K, Gf, w)
    ref = control.feedback(_static(np.eye(4)), G * K) * Gf
    R = np.moveaxis(control.frequency_response(ref, w, squeeze=False).complex, 2, 0)
    np.testing.assert_allclose(comp.H_m_per_n, R, rtol=1e-6, atol=1e-9 * np.abs(R).max())
    cl = closed_loop(G, K, Gf)
    R2 = np.moveaxis(control.frequency_response(cl.system, w, squeeze=False).complex, 2, 0)[:, :4, 4:]
    np.testing.assert_allclose(comp.H_m_per_n, R2, rtol=1e-6, atol=1e-9 * np.abs(R).max())
    sm = np.linalg.svd(R, compute_uv=False)[:, 0]
    assert comp.peak.value == pytest.approx(sm.max(), rel=1e-6)
    assert comp.force_names == ("Fx", "Fy")
    d = comp.to_dict()
    json.dumps(d)
    assert d["peak_m_per_n"] == pytest.approx(sm.max(), rel=1e-6)


def test_dimension_and_state_checks():
    """Reference: interface contract — K must be ny→nu, Gf must share A and C with G; a grid
    point on an integrator pole (ω = 0, PI action as in P5 Eq. 6) is rejected, not turned into
    an infinite 'peak'."""
    G, Gf, K = rigid_rotor()
    with pytest.raises(ModelError):
        closed_loop(G, _static(np.eye(2)))
    G2, Gf2, _ = rigid_rotor(k_seal=0.0)
    with pytest.raises(ModelError):
        closed_loop(G, K, Gf2)
    with pytest.raises(ModelError):
        loops.loop_responses(G, K, W).peaks("S")
    integ = control.ss(control.tf([1.0, 5.0], [1.0, 0.0]))  # PI-like factor, pole at s = 0
    KI = control.append(integ, integ, integ, integ) * K
    with pytest.raises(ModelError, match="imaginary axis"):
        loops.loop_responses(G, KI, np.array([0.0, 1.0, 10.0]))


def test_peak_and_sigma_helpers():
    """Reference: definitions — σ̄ of diag(a, b) is max(|a|, |b|); Peak.value_db = 20 log10."""
    F = np.zeros((3, 2, 2), dtype=complex)
    F[:, 0, 0] = [1, 3, 2]
    F[:, 1, 1] = [2j, 1, 4]
    np.testing.assert_allclose(loops.sigma_max(F), [2, 3, 4])
    p = loops.peak_of(loops.sigma_max(F), 2 * np.pi * np.array([1.0, 2.0, 3.0]))
    assert (p.value, p.frequency_hz) == (4.0, pytest.approx(3.0))
    assert loops.Peak(10.0, 1.0).value_db == pytest.approx(20.0)


def test_resolved_grid_catches_a_lightly_damped_peak():
    """A 0.5 %-damped resonance between two log-grid points: the plain grid misses its
    peak 1/(2ζ) = 100 (closed form for a unit-DC second-order system), the resolved grid
    finds it within 0.2 %."""
    import numpy as np

    from ambseal.analysis.loops import resolved_grid

    wn, z = 2 * np.pi * 557.3, 0.005
    poles = np.roots([1, 2 * z * wn, wn**2])
    w = 2 * np.pi * np.logspace(0, 3.3, 300)

    def gain(w):
        s = 1j * w
        return np.abs(wn**2 / (s**2 + 2 * z * wn * s + wn**2))

    exact = 1 / (2 * z * np.sqrt(1 - z**2))
    assert gain(w).max() < 0.8 * exact
    assert gain(resolved_grid(w, poles)).max() == pytest.approx(exact, rel=2e-3)


def test_controller_wired_by_names_not_by_position():
    """Reference: the same loop closed by python-control (control.feedback) on the plant
    as named. A controller whose channels come in another order (B before A, η before ζ)
    gives the same poles and per-axis S_o as in the plant's order; a renamed channel is an
    error naming both sets; unnamed systems are wired by position."""
    G, Gf, K = rigid_rotor()
    K = control.ss(K.A, K.B, np.diag([1.0, 1.2, 1.5, 1.7]) @ K.C,
                   np.diag([1.0, 1.2, 1.5, 1.7]) @ K.D, inputs=NAMES, outputs=NAMES)
    order = [3, 2, 1, 0]
    Kp = control.ss(K.A, K.B[:, order], K.C[order, :], K.D[np.ix_(order, order)],
                    inputs=[NAMES[j] for j in order], outputs=[NAMES[j] for j in order])
    ref = control.feedback(G, K, sign=-1)
    cl = closed_loop(G, Kp, Gf)
    np.testing.assert_allclose(np.sort_complex(cl.poles), np.sort_complex(ref.poles()),
                               rtol=1e-7)
    p0, p1 = (loops.loop_responses(G, k, W).peaks("So") for k in (K, Kp))
    assert [(p.channel, p.value) for p in p1.diagonal] == [(p.channel, p.value)
                                                            for p in p0.diagonal]
    c0, c1 = (loops.compliance(G, k, Gf, W).peak.value for k in (K, Kp))
    assert c1 == pytest.approx(c0, rel=1e-12)
    renamed = control.ss(K.A, K.B, K.C, K.D, inputs=["A_zeta", "A_eta", "B_zeta", "C_eta"],
                         outputs=NAMES)
    with pytest.raises(ModelError, match=r"C_eta.*B_eta"):
        closed_loop(G, renamed)
    unnamed = control.ss(K.A, K.B, K.C, K.D)
    np.testing.assert_allclose(np.sort_complex(closed_loop(G, unnamed).poles),
                               np.sort_complex(ref.poles()), rtol=1e-7)


def _swapped_rig(tmp_path):
    """The embedded rig file with its [[amb]] B listed before A."""
    import tomllib

    from ..toml_text import dump

    data = tomllib.loads(ROOT_RIG.read_text())
    assert [a["name"] for a in data["amb"]] == ["A", "B"]
    data["amb"] = data["amb"][::-1]
    path = tmp_path / "swapped.toml"
    path.write_text(dump(data))
    return path


def test_loaded_controller_judged_alike_whatever_the_amb_order(testrig_cfg, tmp_path, capsys):
    """A controller file (the reference PID with B's gains 1.2× A's, so that its channels
    differ) judged on the rig and on the same rig with [[amb]] B listed first: the same
    closed-loop poles, per-axis S_o peaks by axis name and compliance (the judged loop),
    and `ambseal modes --controller` gives the same modes. By position the swapped rig
    would run A's axes with B's gains. Reference: the original order, where names and
    positions agree."""
    from ambseal.analysis.judge import judge, judge_settings, operating_points
    from ambseal.design.specs import design_spec
    from ambseal.cli import main
    from ambseal.config import load_rig
    from ambseal.export.controller_files import export_controller, load_controller
    from ambseal.design.recipes import design

    K0 = design(testrig_cfg, "pid").K
    g = np.diag([1.2 if n.startswith("i_B") else 1.0 for n in K0.output_labels])
    K = control.ss(K0.A, K0.B, g @ K0.C, g @ K0.D, inputs=list(K0.input_labels),
                   outputs=list(K0.output_labels), name="K_uneven")
    path = export_controller(K, tmp_path / "K.json")
    loaded = load_controller(path)
    rig = _swapped_rig(tmp_path)
    swapped = load_rig(rig)
    assert [a.name for a in swapped.amb] == ["B", "A"]
    spec = design_spec(testrig_cfg)
    point = operating_points(spec)[1]
    cases = [judge(c, loaded, "K", point, judge_settings(spec), impulse=False)[0].to_dict()
             for c in (testrig_cfg, swapped)]
    for key in ("stable", "max_real_pole", "sensitivity_peak", "compliance_peak_m_per_n"):
        assert cases[1][key] == pytest.approx(cases[0][key], rel=1e-6), key
    per_axis = [c["sensitivity_peak_per_axis"] for c in cases]
    assert set(per_axis[1]) == set(per_axis[0])
    for axis, value in per_axis[0].items():
        assert per_axis[1][axis] == pytest.approx(value, rel=1e-6), axis
    modes = []
    for r in (ROOT_RIG, rig):
        assert main(["modes", str(r), "--controller", str(path), "--json"]) == 0
        modes.append(json.loads(capsys.readouterr().out)["natural_frequencies_hz"])
    np.testing.assert_allclose(modes[1], modes[0], rtol=1e-7)


def test_loaded_controller_with_a_renamed_channel_is_refused(tmp_path, capsys):
    """A controller file whose input B_eta was renamed: `modes` refuses it with one line
    listing the controller's and the plant's signals (exit 2); a file without signal names
    is connected by position and says so in a warning."""
    from ambseal.cli import main

    K = control.ss([], [], [], -np.eye(4) * 2e4,
                   inputs=[f"y_{n}" for n in NAMES[:3]] + ["y_C_eta"],
                   outputs=[f"i_{n}" for n in NAMES], name="K")
    from ambseal.export.controller_files import export_controller

    path = export_controller(K, tmp_path / "K.json")
    assert main(["modes", str(ROOT_RIG), "--controller", str(path)]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "y_C_eta" in err[0] and "y_B_eta" in err[0], err
    doc = json.loads(path.read_text())
    del doc["inputs"], doc["outputs"]
    path.write_text(json.dumps(doc))
    with pytest.warns(UserWarning, match="by position"):
        from ambseal.export.controller_files import load_controller

        load_controller(path)


def test_resolved_peaks_finds_the_resolved_grids_peaks_on_fewer_frequencies():
    """Forty lightly damped resonances (ζ 0.3–2 %) of unit-DC second-order systems, one of
    them four times as high as the others. Graded one by one, every resonance's peak is
    the resolved grid's and within 0.5 % of the closed form 1/(2ζ√(1 − ζ²)); graded by
    their largest, the peak is the highest one's, on under half of the resolved grid's
    frequencies."""
    import numpy as np

    from ambseal.analysis.loops import resolved_grid, resolved_peaks

    rng = np.random.default_rng(7)
    wn = 2 * np.pi * np.sort(rng.uniform(50.0, 5e3, 40))
    zeta = rng.uniform(0.003, 0.02, 40)
    zeta[17] = 0.25 * zeta.min()
    exact = 1 / (2 * zeta * np.sqrt(1 - zeta**2))
    poles = np.concatenate([np.roots([1, 2 * z * w, w**2]) for w, z in zip(wn, zeta)])
    base = 2 * np.pi * np.logspace(1, 4, 600)
    full = resolved_grid(base, poles)

    def evaluate(w):  # one column per resonance
        s = 1j * w[:, None]
        return (wn**2 / (s**2 + 2 * zeta * wn * s + wn**2),)

    on_full = np.abs(evaluate(full)[0])
    w, (H,) = resolved_peaks(base, poles, evaluate, np.abs)
    assert np.all(np.isin(w, full)) and np.all(np.diff(w) > 0)
    np.testing.assert_array_equal(np.abs(H).max(axis=0), on_full.max(axis=0))
    np.testing.assert_allclose(np.abs(H).max(axis=0), exact, rtol=5e-3)

    w, (H,) = resolved_peaks(base, poles, evaluate,
                             lambda H: np.abs(H).max(axis=1, keepdims=True))
    assert np.abs(H).max() == on_full.max() == pytest.approx(exact[17], rel=5e-3)
    assert w.size < 0.5 * full.size
