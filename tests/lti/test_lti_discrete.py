"""ambseal.lti.discrete against closed forms and python-control."""

from __future__ import annotations

import numpy as np
import scipy.linalg as sla

from ambseal.lti.discrete import simulate_lti, zoh


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
