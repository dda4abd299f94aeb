"""ambseal.lti.discrete against closed forms and python-control."""

from __future__ import annotations

import control
import numpy as np
import pytest
import scipy.linalg as sla

from ambseal.errors import ModelError
from ambseal.lti.discrete import simulate_lti, simulate_modal_loop, zoh
from ambseal.lti.interconnect import feedback_matrices


def test_zoh_of_a_first_order_lag_is_the_closed_form():
    """ẋ = −a x + b u held over dt: x⁺ = e^{−a dt} x + (1 − e^{−a dt}) b/a u (Franklin,
    Powell & Workman §6.3)."""
    a, b, dt = 250.0, 3.0, 1e-3
    Ad, Bd = zoh(np.array([[-a]]), np.array([[b]]), dt)
    assert Ad[0, 0] == np.float64(np.exp(-a * dt)) or abs(Ad[0, 0] / np.exp(-a * dt) - 1) < 1e-15
    assert abs(Bd[0, 0] / ((1 - np.exp(-a * dt)) * b / a) - 1) < 1e-13


def test_impulse_response_of_a_badly_scaled_hinf_loop_is_well_conditioned(turbo_cfg,
                                                                          turbo_frozen):
    """The turboexpander's H∞ controller (entries of A_K up to 2e7, of C_K up to 8e8) closed
    with the full-order plant at 20 Hz: the impulse peak is a smooth function of A_K, so a
    1e-12 relative change of A_K must move it by < 1e-9. Without the balancing in ``zoh``
    it moved by 5e-5, and the peak was 2.5e-4 off the value scipy's Radau gives at rtol
    1e-11 on the same grid (0.6580906628 µm; with balancing they agree to 1e-11 — too slow
    a reference for the suite: nine minutes)."""
    import control

    from ambseal.analysis.judge import judge, judge_settings, operating_points
    from ambseal.design.specs import design_spec

    K = turbo_frozen.K
    spec = design_spec(turbo_cfg)
    point, settings = operating_points(spec)[0], judge_settings(spec)
    ref = judge(turbo_cfg, K, "hinf", point, settings)[0].impulse_peak_um
    rng = np.random.default_rng(1)
    Kp = control.ss(K.A * (1 + 1e-12 * rng.standard_normal(K.A.shape)), K.B, K.C, K.D,
                    inputs=K.input_labels, outputs=K.output_labels)
    got = judge(turbo_cfg, Kp, "hinf", point, settings)[0].impulse_peak_um
    assert abs(got / ref - 1) < 1e-9, (ref, got)


def test_simulate_lti_equals_the_plain_recursion():
    """The block recursion is the recursion z⁺ = A z + B u written in blocks: equal to a
    step-by-step loop (and to scipy.signal.dlsim) to rounding."""
    from scipy.signal import dlsim

    rng = np.random.default_rng(4)
    n, m, N = 6, 2, 1000
    A = rng.standard_normal((n, n))
    A *= 0.9 / np.max(np.abs(np.linalg.eigvals(A)))
    B = rng.standard_normal((n, m))
    C1, C2 = rng.standard_normal((2, n)), rng.standard_normal((1, n))
    u = rng.standard_normal((N, m))
    y1, y2 = simulate_lti(A, B, [C1, C2], u, block=7)
    _, y_ref, _ = dlsim((A, B, np.vstack([C1, C2]), np.zeros((3, m)), 1.0), u)
    assert np.max(np.abs(np.hstack([y1, y2]) - y_ref)) < 1e-12 * np.max(np.abs(y_ref))
    # from sample `start` on (inside a block, on a block edge, the last sample, none)
    for start in (3, 7, 500, N - 1, N):
        t1, t2 = simulate_lti(A, B, [C1, C2], u, block=7, start=start)
        assert t1.shape == (N - start, 2) and t2.shape == (N - start, 1)
        assert np.max(np.abs(np.hstack([t1, t2]) - y_ref[start:]), initial=0.0) \
            < 1e-12 * np.max(np.abs(y_ref))
    assert sla.norm(y1) > 0


def test_modal_loop_steps_the_real_loop():
    """A real plant with an open-loop unstable pair (``1.05 e^{±0.2j}``) and a damped pair,
    in modal form (``numpy.linalg.eig``), closed by an observer-based controller (discrete
    LQR gain, observer poles placed at 0.5–0.65: stable by the separation principle): over
    3 000 steps the modal recursion equals :func:`simulate_lti` of the loop's dense real
    state space to 1e-10 of the peak (2e-14 measured). A recursion that steps both members
    of each pair and feeds back only ``Re y`` leaves the unstable pair's anti-conjugate
    part without feedback: it ends 4.6e31 times the peak off."""
    def rotation(r, t):
        return r * np.array([[np.cos(t), -np.sin(t)], [np.sin(t), np.cos(t)]])

    S = np.array([[2.0, -2.5, 0.4, -0.6], [-0.5, -0.2, -2.0, -0.2], [-0.9, 3.3, 0.2, -0.4],
                  [-0.3, -0.7, -1.1, -0.4]])
    A = S @ sla.block_diag(rotation(1.05, 0.2), rotation(0.97, 0.9)) @ np.linalg.inv(S)
    B, C = np.array([[0.5], [-0.2], [1.0], [-0.2]]), np.array([[0.0, 1.5, 0.5, -0.5]])
    F, _, _ = control.dlqr(A, B, np.eye(4), np.eye(1))
    L = control.place(A.T, C.T, [0.5, 0.55, 0.6, 0.65]).T
    K = (A - B @ F - L @ C, L, F, np.zeros((1, 1)))  # i = −F x̂
    Acl, Bcl, Ccl, _ = feedback_matrices((A, B, C, np.zeros((1, 1))), K)
    assert np.abs(np.linalg.eigvals(Acl)).max() < 0.66
    d = np.zeros((3000, 1))
    d[5:10] = 1.0
    (ref,) = simulate_lti(Acl, Bcl, [Ccl], d)
    mu, V = np.linalg.eig(A)
    assert np.abs(mu).max() > 1.04
    Bz, Cm = np.linalg.solve(V, B), C @ V
    out = simulate_modal_loop(mu, Bz, Cm, K, d)
    assert np.max(np.abs(out - ref)) < 1e-10 * np.max(np.abs(ref))
    keep = np.argsort(mu.imag)[1:]  # one of a pair dropped: not a real plant's form
    with pytest.raises(ModelError, match="conjugate pairs"):
        simulate_modal_loop(mu[keep], Bz[keep], Cm[:, keep], K, d)
