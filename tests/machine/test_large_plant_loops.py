"""Loops on a large plant (the embedded rig at 100 beam elements, 848 states) judged from
the plant's modal form, without ``expm`` of the plant or of the loop. The discrete loop:
the sampled plant's response, the loop's poles and its impulse response
(:func:`ambseal.lti.freqresp.sampled_modal_form`), against independent references — the
plant sampled by SciPy's ``cont2discrete`` (zero-order hold, Franklin, Powell & Workman,
*Digital Control of Dynamic Systems*, 3rd ed., §6.3) with dense solves, and the dense
closed loop of that sampled plant stepped by :func:`ambseal.lti.discrete.simulate_lti`.
The references sample the plant diagonally balanced first (``scipy.linalg.matrix_balance``,
the same transfer function): the FE plant's entries span 1 to 1e9, and ``expm`` of the
unbalanced matrix loses up to 7 digits (an impulse response off by 20 % of its peak).
The continuous loop with the delay lag: its impulse response from its split along the
plant's modal form (:func:`ambseal.lti.modal_loop.modal_loop_response`) against the dense
loop sampled by :func:`ambseal.lti.discrete.zoh`. ``expm`` of anything plant-sized is made
to fail while the structured paths run, so these tests also prove that no dense
``expm`` is taken there."""

from __future__ import annotations

import control
import numpy as np
import pytest
import scipy.linalg
from scipy.signal import cont2discrete

import ambseal.lti.freqresp as fr
import ambseal.lti.modal_loop as ml
from ambseal.analysis.response import impulse_response_of
from ambseal.config import load_rig
from ambseal.lti import (
    STRUCTURED_STATES,
    feedback_matrices,
    feedback_response,
    sampled_response_at,
    simulate_lti,
    ss_matrices,
    wired,
    zoh,
)
from ambseal.machine.loop import closed_loop, delayed_plant, judged_loop
from ambseal.model.rig import build_plant
from ambseal.robust.delay import loop_delay

from ..finemesh import fine_rig_text


@pytest.fixture(scope="module")
def fine_plant(tmp_path_factory):
    """The 100-element rig's full-order plant: currents, and a force at the first AMB."""
    rig = tmp_path_factory.mktemp("fine") / "fine100.toml"
    rig.write_text(fine_rig_text(100), encoding="utf-8")
    cfg = load_rig(rig)
    plant = build_plant(cfg, force_positions=(cfg.amb[0].position,))
    P = plant.to_statespace()
    assert P.nstates >= STRUCTURED_STATES
    return P, list(plant.current_inputs()), 1.0 / cfg.controller.sample_rate_hz, cfg


def _refuse(*args, **kwargs):
    """In place of ``expm``: a path that samples the plant fails."""
    raise AssertionError("the plant was sampled (expm called)")


_expm = scipy.linalg.expm


def _small_expm(M, *args, **kwargs):
    """``expm`` of small matrices only (a controller-sized block); plant-sized ones fail."""
    if np.shape(M)[0] >= 200:
        raise AssertionError(f"expm of a {np.shape(M)[0]}-state matrix")
    return _expm(M, *args, **kwargs)


def _mats(S, inputs=None):
    B, D = np.asarray(S.B, float), np.asarray(S.D, float)
    if inputs is not None:
        B, D = B[:, inputs], D[:, inputs]
    return np.asarray(S.A, float), B, np.asarray(S.C, float), D


def _balanced_zoh(G, T):
    """``(A_d, B_d, C, D)``: ``G`` balanced by a diagonal ``S`` (``S⁻¹AS, S⁻¹B, CS``) and
    sampled by SciPy."""
    A, B, C, D = G
    Ab, (sc, _) = scipy.linalg.matrix_balance(A, permute=False, separate=True)
    Ad, Bd, Cd, Dd, _ = cont2discrete((Ab, B / sc[:, None], C * sc, D), T, method="zoh")
    return Ad, Bd, Cd, Dd


def _dense_sampled_response(G, T, w):
    Ad, Bd, C, D = _balanced_zoh(G, T)
    z = np.exp(1j * w * T)
    eye = np.eye(Ad.shape[0])
    return np.array([C @ np.linalg.solve(zk * eye - Ad, Bd) + D for zk in z])


def test_sampled_response_from_the_modal_form_equals_the_sampled_plant(fine_plant, monkeypatch):
    """``G_d(e^{jωT})`` of the plant's current inputs on a grid from 1 Hz to Nyquist, with
    ``expm`` refused: within 1e-6 of the largest entry at each frequency of dense solves
    of the plant sampled by SciPy (the check the modal form passes is at rtol 1e-6)."""
    P, cur, T, _ = fine_plant
    G = _mats(P, cur)
    w = 2 * np.pi * np.logspace(0, np.log10(0.999 / (2 * T)), 60)
    with monkeypatch.context() as m:
        m.setattr(scipy.linalg, "expm", _refuse)
        H = sampled_response_at(G, T, w)
    ref = _dense_sampled_response(G, T, w)
    err = np.max(np.abs(H - ref), axis=(1, 2)) / np.max(np.abs(ref), axis=(1, 2))
    assert err.max() < 1e-6


def test_a_wrong_modal_form_is_not_certified(fine_plant, monkeypatch):
    """Modal input rows off by 1e-4 (relative) fail the check against the dense probes:
    ``sampled_modal_form`` gives None, and the response is still the sampled plant's (the
    dense path, ``expm`` allowed)."""
    P, cur, T, _ = fine_plant
    G = _mats(P, cur)
    forms = fr._modal_forms

    def spoiled(*args):
        for lam, Bm, Cm in forms(*args):
            yield lam, Bm * (1 + 1e-4 * np.cos(np.arange(Bm.shape[0])))[:, None], Cm

    monkeypatch.setattr(fr, "_modal_forms", spoiled)
    T2 = T / 2  # not a kept result of the test above
    assert fr.sampled_modal_form(*G, T2) is None
    w = 2 * np.pi * np.logspace(1, np.log10(0.999 / (2 * T2)), 5)
    ref = _dense_sampled_response(G, T2, w)
    H = sampled_response_at(G, T2, w)
    assert np.max(np.abs(H - ref)) < 1e-6 * np.max(np.abs(ref))


def test_judged_discrete_loop_on_a_large_plant_equals_the_dense_loop(fine_plant, testrig_digital,
                                                                     monkeypatch):
    """The default mesh's digital H∞ controller (its computation delay among its states)
    on the 100-element plant with a force input, judged with ``expm`` refused: stable as
    the dense loop of the plant sampled by SciPy, the same names, and an impulse response
    (a current pulse of 10 samples on the first and last axes) within 1e-8 of the dense
    loop's peak at every sample, its peak and settling time equal to 1e-8."""
    P, cur, T, _ = fine_plant
    Kd = testrig_digital["hinf"].statespace(delayed=True)
    assert abs(float(Kd.dt) - T) < 1e-15
    with monkeypatch.context() as m:
        m.setattr(scipy.linalg, "expm", _refuse)
        judged = judged_loop(P, Kd, cur)
        loop = judged.loop
        assert loop._modal_from is not None
        args = dict(channels=(loop.inputs[0][2:], loop.inputs[len(cur) - 1][2:]),
                    amplitude_a=0.5, duration_s=10 * T, t_impulse_s=20 * T, t_end_s=0.2,
                    dt_s=T)
        fast = impulse_response_of(loop, **args)
    Pd = control.ss(*_balanced_zoh(_mats(P), T), T, inputs=list(P.input_labels),
                    outputs=list(P.output_labels))
    rest = [j for j in range(P.ninputs) if j not in cur]
    dense = closed_loop(Pd[:, cur], Kd, Pd[:, rest])
    assert loop.stable and dense.stable
    assert (loop.inputs, loop.outputs) == (tuple(dense.system.input_labels),
                                          tuple(dense.system.output_labels))
    ref = impulse_response_of(dense, **args)
    scale = np.max(np.abs(ref.displacement_m))
    assert np.max(np.abs(fast.displacement_m - ref.displacement_m)) < 1e-8 * scale
    assert np.max(np.abs(fast.current_a - ref.current_a)) < 1e-8 * np.max(np.abs(ref.current_a))
    assert fast.peak_displacement_um == pytest.approx(ref.peak_displacement_um, rel=1e-8)
    assert fast.settling_time_s == pytest.approx(ref.settling_time_s, rel=1e-8)
    # the dense system is still there when asked for: the loop of the sampled plant
    assert np.allclose(np.sort_complex(np.linalg.eigvals(loop.system.A)),
                       np.sort_complex(np.linalg.eigvals(dense.system.A)), rtol=0, atol=1e-9)


def _impulse_args(loop, T, cur):
    return dict(channels=(loop.inputs[0][2:], loop.inputs[len(cur) - 1][2:]),
                amplitude_a=0.5, duration_s=10 * T, t_impulse_s=20 * T, t_end_s=0.2,
                dt_s=T / 2)


# H∞ continuous is in the whole judged case of tests/analysis/test_judge_fine_mesh.py too
@pytest.mark.parametrize("method", ["pid", pytest.param("hinf", marks=pytest.mark.slow)])
def test_judged_continuous_loop_on_a_large_plant_equals_the_dense_loop(fine_plant,
                                                                       testrig_designs,
                                                                       monkeypatch, method):
    """The default mesh's PID (a feedthrough) and H∞ controllers on the 100-element plant
    with the delay lag, judged as the run judges them: the impulse response from the
    loop's split along the plant's modal form, ``expm`` of plant-sized matrices refused,
    within 1e-7 of each channel's peak of the dense loop's (the delayed plant closed by
    :func:`closed_loop`, sampled by ``zoh``; measured 1e-8), peak and settling time to
    1e-7 relative."""
    P, cur, T, cfg = fine_plant
    K = testrig_designs[method].K
    lag = loop_delay(cfg.controller.sample_rate_hz, cfg.controller.delay_samples).system
    with monkeypatch.context() as m:
        m.setattr(scipy.linalg, "expm", _small_expm)
        loop = judged_loop(P, K, cur, delay=lag).loop
        args = _impulse_args(loop, T, cur)
        d = np.zeros((round(args["t_end_s"] / args["dt_s"]) + 1, len(cur)))
        assert loop.modal_response(d, args["dt_s"]) is not None
        fast = impulse_response_of(loop, **args)
    rest = [j for j in range(P.ninputs) if j not in cur]
    Pd = delayed_plant(P, cur, lag)
    dense = closed_loop(Pd[:, cur], K, Pd[:, rest])
    assert loop.stable and dense.stable
    ref = impulse_response_of(dense, **args)
    for got, want in ((fast.displacement_m, ref.displacement_m),
                      (fast.current_a, ref.current_a)):
        assert np.all(np.max(np.abs(got - want), axis=0)
                      <= 1e-7 * np.max(np.abs(want), axis=0))
    assert fast.peak_displacement_um == pytest.approx(ref.peak_displacement_um, rel=1e-7)
    assert fast.settling_time_s == pytest.approx(ref.settling_time_s, rel=1e-7)


def test_a_wrong_split_is_not_certified(fine_plant, testrig_designs, monkeypatch):
    """The strong part's matrix off by 1e-6 (relative) in one entry: its transfer misses
    the loop's at the probes, and the modal response is refused (None), not returned."""
    P, cur, T, cfg = fine_plant
    lag = loop_delay(cfg.controller.sample_rate_hz, cfg.controller.delay_samples).system
    loop = judged_loop(P, testrig_designs["hinf"].K, cur, delay=lag).loop
    d = np.zeros((50, len(cur)))
    d[5:10, 0] = 1.0
    assert loop.modal_response(d, T / 2) is not None
    block = ml._Loop.strong_block

    def spoiled(self, solved):
        M, C1 = block(self, solved)
        M = M.copy()
        M[0, 0] *= 1 + 1e-6
        return M, C1

    monkeypatch.setattr(ml._Loop, "strong_block", spoiled)
    assert loop.modal_response(d, T / 2) is None


def test_continuous_loop_without_lag_equals_the_dense_loop(fine_plant, testrig_designs):
    """``feedback_response`` without a lag (the disturbance added to the controller's
    output straight at the plant): the μ controller on the 100-element plant, a pulse on
    two axes, within 1e-7 of each channel's peak of the dense loop sampled by ``zoh``."""
    P, cur, T, _ = fine_plant
    G = _mats(P, cur)
    K = ss_matrices(wired(P[:, cur], testrig_designs["mu"].K))
    d = np.zeros((2001, len(cur)))
    d[40:60, 0], d[40:60, -1] = 0.5, -0.3
    fast = feedback_response(G, K, d, T / 2)
    assert fast is not None
    A, B, C, _ = feedback_matrices(G, K)
    Ad, Bd = zoh(A, B, T / 2, keep=False)
    (ref,) = simulate_lti(Ad, Bd, [C], d)
    assert np.all(np.max(np.abs(fast - ref), axis=0) <= 1e-7 * np.max(np.abs(ref), axis=0))


def _arrays(obj, depth=6, seen=None):
    """The NumPy arrays reachable from ``obj``: attributes, containers, closures' cells
    and defaults (what a judged loop keeps alive)."""
    seen = set() if seen is None else seen
    if id(obj) in seen or depth < 0:
        return []
    seen.add(id(obj))
    if isinstance(obj, np.ndarray):
        return [obj]
    if isinstance(obj, dict):
        items = list(obj.values())
    elif isinstance(obj, (list, tuple, set)):
        items = list(obj)
    elif callable(obj) and hasattr(obj, "__code__"):
        items = [c.cell_contents for c in obj.__closure__ or ()] + list(obj.__defaults__ or ())
    elif hasattr(obj, "__dict__"):
        items = list(vars(obj).values())
    else:
        return []
    return [a for x in items for a in _arrays(x, depth - 1, seen)]


def test_judged_loop_keeps_no_copy_of_the_plant(fine_plant, testrig_designs):
    """A judged loop with the delay lag, as the run keeps one per design and condition:
    no array of the plant's size reachable from it but the plant's own ``A``, shared
    read-only; its ``system``, made when asked for, equals the delayed plant closed by
    :func:`closed_loop` with python-control's own selections (``P[:, idx]``), matrices and
    signal names."""
    P, cur, _, cfg = fine_plant
    lag = loop_delay(cfg.controller.sample_rate_hz, cfg.controller.delay_samples).system
    judged = judged_loop(P, testrig_designs["hinf"].K, cur, delay=lag)
    big = [a for a in _arrays(judged) if a.size >= P.nstates ** 2]
    assert big and all(np.shares_memory(a, P.A) for a in big)
    assert not any(a.flags.writeable for a in big if a is not P.A)
    rest = [j for j in range(P.ninputs) if j not in cur]
    Pd = delayed_plant(P, cur, lag)
    dense = closed_loop(Pd[:, cur], testrig_designs["hinf"].K, Pd[:, rest]).system
    got = judged.loop.system
    for m in "ABCD":
        np.testing.assert_array_equal(getattr(got, m), getattr(dense, m))
    assert (got.input_labels, got.output_labels) == (dense.input_labels, dense.output_labels)
