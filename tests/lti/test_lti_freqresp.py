"""Tests of ambseal.lti.freqresp against python-control and direct dense solves."""

from __future__ import annotations

import control
import numpy as np
import pytest

import ambseal.lti.freqresp as fr
from ambseal.errors import ModelError
from ..distillation import distillation_rp_plant


def _dense(A, B, C, D, w):
    """Reference: one dense solve of (jωI − A) X = B per frequency."""
    n = A.shape[0]
    return np.array([C @ np.linalg.solve(1j * wk * np.eye(n) - A, B) + D for wk in w])


def _rel(H, R):
    return np.max(np.abs(H - R)) / np.max(np.abs(R))


def _lightly_damped(n=120, seed=1):
    """Block-diagonal modal system (ζ = 1e-4..1e-2, 2..1000 Hz) in mildly mixed coordinates."""
    rng = np.random.default_rng(seed)
    wn = rng.uniform(2 * np.pi * 2, 2 * np.pi * 1000, n // 2)
    z = rng.uniform(1e-4, 1e-2, n // 2)
    A = np.zeros((n, n))
    for i, (w, zz) in enumerate(zip(wn, z)):
        A[2 * i : 2 * i + 2, 2 * i : 2 * i + 2] = [[0.0, w], [-w, -2 * zz * w]]
    T = np.eye(n) + 0.3 * rng.standard_normal((n, n)) / np.sqrt(n)
    A = T @ A @ np.linalg.inv(T)
    B = rng.standard_normal((n, 4))
    C = rng.standard_normal((3, n))
    D = rng.standard_normal((3, 4))
    return A, B, C, D, wn


@pytest.mark.parametrize("method", ["auto", "modal", "hessenberg"])
def test_random_system_matches_python_control(method):
    """Reference: control.frequency_response (python-control 0.10, Laub/TB05AD) on a random
    stable system (seeded control.rss), 1e-9 relative."""
    np.random.seed(3)
    sys = control.rss(12, 3, 2)
    w = np.logspace(-1, 3, 200)
    R = np.moveaxis(control.frequency_response(sys, w, squeeze=False).complex, 2, 0)
    H = fr.freqresp(sys, w, method=method)
    assert H.shape == (200, 3, 2)
    assert _rel(H, R) < 1e-9


@pytest.mark.parametrize("method", ["auto", "modal", "hessenberg"])
def test_lightly_damped_large_system_matches_dense_solves(method):
    """Reference: dense solves C (jωI−A)⁻¹ B + D, including ω exactly at the natural
    frequencies (peaks up to 1/(2ζ) = 5000×), 120 states, 1e-8 relative."""
    A, B, C, D, wn = _lightly_damped()
    w = np.sort(np.concatenate([np.logspace(0, 4, 30), wn[:10]]))
    R = _dense(A, B, C, D, w)
    H = fr.freqresp((A, B, C, D), w, method=method)
    assert _rel(H, R) < 1e-8


def test_numpy_hessenberg_solver_matches_dense(monkeypatch):
    """Reference: dense solves; the pure-numpy vectorised Hessenberg path (slycot disabled),
    with frequency chunks smaller than the grid so the chunking is exercised."""
    A, B, C, D, wn = _lightly_damped(n=60, seed=2)
    monkeypatch.setattr(fr, "_USE_SLYCOT", False)
    monkeypatch.setattr(fr, "_CHUNK_BYTES", 16 * 60 * 60 * 7)  # 7 frequencies per chunk
    w = np.concatenate([np.logspace(0, 4, 40), wn[:5]])
    R = _dense(A, B, C, D, w)
    assert _rel(fr.freqresp((A, B, C, D), w, method="hessenberg"), R) < 1e-9


def test_defective_matrix_falls_back_to_hessenberg():
    """Reference: a 3×3 Jordan block (defective, V singular) has the closed form
    H(s) = 1/(s+1)³ from the last input to the first state; auto must fall back, forced
    modal must raise ModelError."""
    A = np.array([[-1.0, 1.0, 0.0], [0.0, -1.0, 1.0], [0.0, 0.0, -1.0]])
    B = np.array([[0.0], [0.0], [1.0]])
    C = np.array([[1.0, 0.0, 0.0]])
    D = np.zeros((1, 1))
    w = np.linspace(0.0, 10.0, 11)
    H = fr.freqresp((A, B, C, D), w)
    np.testing.assert_allclose(H[:, 0, 0], 1.0 / (1j * w + 1.0) ** 3, rtol=1e-10)
    with pytest.raises(ModelError):
        fr.freqresp((A, B, C, D), w, method="modal")


def test_static_gain_and_bad_input():
    """Reference: a zero-state system is its D matrix at all frequencies; bad grids raise."""
    sys = control.ss(np.zeros((0, 0)), np.zeros((0, 2)), np.zeros((1, 0)), np.array([[2.0, -1.0]]))
    H = fr.freqresp(sys, np.array([0.0, 5.0]))
    np.testing.assert_array_equal(H, np.array([[[2.0, -1.0]]] * 2))
    with pytest.raises(ModelError):
        fr.freqresp(sys, np.array([-1.0]))
    with pytest.raises(ModelError):
        fr.freqresp(sys, np.array([1.0]), method="dense")


def test_fe_rotor_plant_against_direct_solves():
    """The thesis rig's full-order plant ([q; q̇] form, entries from 1 to ~1e12): every method
    within 1e-6 of dense solves of (jωI − A)x = B. Regression for an unbalanced Hessenberg
    reduction that lost three digits on this model (found side by side with ROSS)."""
    from ambseal.config import load_rig
    from ambseal.model.rig import build_plant

    P = build_plant(load_rig())
    w = 2 * np.pi * np.array([3.0, 40.0, 371.6, 557.0, 1500.0])
    ref = np.array([P.C @ np.linalg.solve(1j * x * np.eye(P.n_states) - P.A, P.B) for x in w])
    for method in ("auto", "modal", "hessenberg"):
        H = fr.freqresp((P.A, P.B, P.C, P.D), w, method=method)
        assert np.max(np.abs(H - ref)) <= 1e-6 * np.max(np.abs(ref)), method


def test_a_rotor_plants_inputs_share_one_eigendecomposition(monkeypatch):
    """A rotor plant of a few hundred states (the thesis rig's, 320) is answered for
    every coil current and then for some: one eigendecomposition serves both (as a
    plant's current and force inputs share it).
    Reference: dense solves of (jωI − A)x = B for each input set, within 1e-7 of the
    peak (the modal form of this FE plant keeps about nine digits)."""
    import scipy.linalg
    from ambseal.config import load_rig
    from ambseal.model.rig import build_plant

    P = build_plant(load_rig())
    assert P.n_states < fr.STRUCTURED_STATES
    # kept decompositions follow the content: a plant no other test has decomposed
    A, C = np.array(P.A) * (1.0 + 2.0**-20), np.array(P.C)
    calls = []
    real_eig = scipy.linalg.eig

    def counting_eig(a, *args, **kw):
        calls.append(a.shape[0])
        return real_eig(a, *args, **kw)

    monkeypatch.setattr(scipy.linalg, "eig", counting_eig)
    w = 2 * np.pi * np.array([3.0, 40.0, 371.6, 1500.0])
    n = P.n_states
    cur = list(P.current_inputs())
    for cols in (cur, cur[:2]):  # every coil, then one bearing's
        B = np.array(P.B)[:, cols]
        H = fr.freqresp((A, B, C, np.zeros((C.shape[0], B.shape[1]))), w, method="modal")
        ref = np.array([C @ np.linalg.solve(1j * x * np.eye(n) - A, B) for x in w])
        assert np.max(np.abs(H - ref)) <= 1e-7 * np.max(np.abs(ref))
    assert calls == [n]


@pytest.mark.parametrize("n", [40, fr.STRUCTURED_STATES])
def test_one_or_two_points_are_solved_densely(monkeypatch, n):
    """One or two points are the probes every fast form is checked against: answered by
    dense solves alone, with no eigendecomposition or Hessenberg reduction of the model,
    and as the solves refined in extended precision (to 1e-12 of the peak). A small model
    too: a scheduled controller is a new model at every speed it is evaluated at."""
    import scipy.linalg

    A, B, C, D, wn = _lightly_damped(n=n, seed=7)
    calls = []
    for name in ("eig", "hessenberg"):
        real = getattr(scipy.linalg, name)
        monkeypatch.setattr(scipy.linalg, name, lambda *a, real=real, name=name, **k: (
            calls.append(name), real(*a, **k))[1])
    monkeypatch.setattr(fr, "_USE_SLYCOT", False)
    w = np.sort(wn[:2])
    for H, s in ((fr.freqresp((A, B, C, D), w), 1j * w),
                 (fr.freqresp_at((A, B, C, D), 1j * w[:1] + 3.0), 1j * w[:1] + 3.0)):
        R = _refined(A, B, C, D, s)
        assert np.max(np.abs(H - R)) <= 1e-12 * np.max(np.abs(R))
    assert calls == []


@pytest.mark.parametrize("n", [40, fr.STRUCTURED_STATES])
def test_one_or_two_points_of_a_sampled_plant_are_solved_densely(monkeypatch, n):
    """The sampled plant's response at one or two frequencies, which are their own probes,
    comes from dense solves of the plant sampled by python-control's zero-order hold
    (``control.c2d``), to 1e-9 of the peak, with no eigendecomposition of the plant: at
    one table speed of the unbalance rejection an ``expm`` costs less than a modal form
    and its certification, on a small plant as on a large one. With its inputs in groups
    (control inputs and forces) the answer is the same."""
    import scipy.linalg

    A, B, C, D, wn = _lightly_damped(n=n, seed=5)
    dt = 1e-4
    Pd = control.c2d(control.ss(A, B, C, D), dt, "zoh")
    calls = []
    real = scipy.linalg.eig
    monkeypatch.setattr(scipy.linalg, "eig", lambda *a, **k: (calls.append(1),
                                                               real(*a, **k))[1])
    w = np.sort(wn[:2])
    z = np.exp(1j * w * dt)
    R = np.array([Pd.C @ np.linalg.solve(zk * np.eye(A.shape[0]) - Pd.A, Pd.B) + Pd.D
                  for zk in z])
    for H in (fr.sampled_response_at((A, B, C, D), dt, w),
              fr.sampled_response_at((A, B, C, D), dt, w, groups=([0, 1], [2, 3]))):
        assert np.max(np.abs(H - R)) <= 1e-9 * np.max(np.abs(R))
    one = fr.sampled_response_at((A, B, C, D), dt, w[:1])
    assert np.max(np.abs(one[0] - R[0])) <= 1e-9 * np.max(np.abs(R[0]))
    assert calls == []


def test_a_large_models_cond_v_is_the_2_norm_one_without_an_svd(monkeypatch):
    """From ``STRUCTURED_STATES`` states cond V, which decides whether the modal form is
    tried, is the 2-norm condition number from two largest singular values by Lanczos
    (V and V⁻¹ through its LU): no SVD of V, and the SVD's value to 1e-5 (a well
    conditioned V, and the ill conditioned eigenvectors of the thesis rig's unbalanced
    FE plant at two speeds, block diagonal).
    A singular V has cond V = inf."""
    import scipy.linalg
    from ambseal.config import load_rig
    from ambseal.model.rig import build_plant

    A1, _, C1, _, _ = _lightly_damped(n=fr.STRUCTURED_STATES, seed=11)
    P0, P1 = (build_plant(load_rig(), speed_rpm=r) for r in (0.0, 6000.0))
    calls = []
    real_cond = np.linalg.cond
    monkeypatch.setattr(np.linalg, "cond", lambda *a, **k: (calls.append(1),
                                                             real_cond(*a, **k))[1])
    fe = scipy.linalg.block_diag(P0.A, P1.A), scipy.linalg.block_diag(P0.C, P1.C)
    for A, C in ((A1, C1), fe):
        assert A.shape[0] >= fr.STRUCTURED_STATES
        lam, cond, lu, Cm, sc = fr._eig_form(A, C, 1e8, False)
        assert calls == []
        exact = real_cond(scipy.linalg.eig(A)[1])
        assert cond == pytest.approx(exact, rel=1e-5)
    V = np.eye(fr.STRUCTURED_STATES, dtype=complex)
    V[:, 1] = V[:, 0]
    with pytest.warns(scipy.linalg.LinAlgWarning):  # an exactly zero pivot
        lu = scipy.linalg.lu_factor(V, check_finite=False)
    assert fr._cond_2(V, lu) == np.inf


def test_large_decompositions_are_kept_to_the_byte_budget(monkeypatch):
    """Large models' decompositions are kept while they fit in the memo's byte budget, not
    only its count: eight 500-state systems' (4 MB each, 32 MB in all against 128 MB) are
    all kept, and asked again none is decomposed again."""
    import scipy.linalg

    monkeypatch.setattr(fr, "_EIG", fr.ArrayMemo(keep=6, min_states=fr._EIG_STATES,
                                                 keep_bytes=128 * 2**20))
    systems = [_lightly_damped(n=fr.STRUCTURED_STATES, seed=20 + k)[:3] for k in range(8)]
    for A, B, C in systems:
        fr._modal_form(A, B, C, 1e8)
    calls, real = [], scipy.linalg.eig
    monkeypatch.setattr(scipy.linalg, "eig", lambda *a, **k: (calls.append(1),
                                                               real(*a, **k))[1])
    for A, B, C in systems:
        fr._modal_form(A, B, C, 1e8)
    assert calls == []


def _refined(A, B, C, D, s):
    """Reference: dense solves refined to extended precision (residuals in long double,
    four steps of iterative refinement)."""
    n = A.shape[0]
    out = []
    for sk in s:
        M = sk * np.eye(n) - A
        X = np.linalg.solve(M, B.astype(complex))
        for _ in range(4):
            r = B.astype(np.clongdouble) - M.astype(np.clongdouble) @ X.astype(np.clongdouble)
            X = X + np.linalg.solve(M, r.astype(complex))
        out.append(C @ X + D)
    return np.array(out)


def test_dense_solves_eliminate_the_velocity_identity_rows():
    """Reference: dense solves refined to extended precision. A spring–mass chain in
    [q; q̇] form (stiffnesses over six decades) with an actuator lag before the input and a
    state that feeds back on itself (ẋ = x: not an identity row to eliminate): the rows
    q̇ = v are found and eliminated, and the result is as accurate as the plain dense
    solve at every frequency, from far below the first mode to far above the last."""
    rng = np.random.default_rng(5)
    m = 30
    k = np.geomspace(1e3, 1e9, m + 1)
    K = np.diag(k[:-1] + k[1:]) - np.diag(k[1:-1], 1) - np.diag(k[1:-1], -1)
    M = np.diag(rng.uniform(0.5, 2.0, m))
    Dm = 1e-4 * K + 0.1 * M
    Mi = np.linalg.inv(M)
    n = 2 * m + 2
    A = np.zeros((n, n))
    A[:m, m:2 * m] = np.eye(m)
    A[m:2 * m, :m], A[m:2 * m, m:2 * m] = -Mi @ K, -Mi @ Dm
    A[m:2 * m, 2 * m] = Mi[:, 3]  # the lag's output is a force on mass 3
    A[2 * m, 2 * m] = -2e3
    A[2 * m + 1, 2 * m + 1] = 1.0
    B = np.zeros((n, 2))
    B[2 * m, 0], B[2 * m + 1, 1], B[m + 7, 1] = 2e3, 1.0, 1.0
    C = np.zeros((3, n))
    C[0, 5], C[1, m + 9], C[2, 2 * m + 1] = 1.0, 1.0, 1.0
    D = np.zeros((3, 2))
    I, J = fr._kinematic_rows(A, B)
    assert np.array_equal(np.sort(I), np.arange(m))
    assert np.array_equal(np.sort(J), np.arange(m, 2 * m))
    s = 1j * np.array([1e-2, 3.0, 40.0, 300.0, 1e4, 1e6])
    ref = _refined(A, B, C, D, s)
    H = fr._dense_response(A, B, C, D, s)
    plain = np.array([C @ np.linalg.solve(sk * np.eye(n) - A, B) + D for sk in s])
    for Hk, Pk, Rk in zip(H, plain, ref):
        assert _rel(Hk, Rk) <= max(10 * _rel(Pk, Rk), 1e-12)
    # no identity rows: the plain solve
    A2, B2 = rng.standard_normal((20, 20)) - 5 * np.eye(20), rng.standard_normal((20, 2))
    assert fr._kinematic_rows(A2, B2)[0].size == 0
    np.testing.assert_allclose(fr._dense_response(A2, B2, C[:, :20], D, s),
                               _refined(A2, B2, C[:, :20], D, s), rtol=1e-12, atol=1e-14)


def test_kept_decompositions_follow_the_matrix_content():
    """Reference: C (sI − A)⁻¹ B + D by a dense solve at each point. A large system
    (above ArrayMemo's 64 states) evaluated, changed in place, evaluated again: the kept
    eigendecomposition, Hessenberg form and ZOH belong to the content, not the object."""
    import scipy.linalg

    from ambseal.lti.discrete import zoh

    rng = np.random.default_rng(3)
    n = 80
    A = rng.standard_normal((n, n)) - 12 * np.eye(n)
    B, C, D = rng.standard_normal((n, 2)), rng.standard_normal((3, n)), np.zeros((3, 2))
    s = 1j * np.array([0.5, 3.0, 40.0])
    for method in ("modal", "hessenberg", "modal"):
        for _ in range(2):
            H = fr.freqresp_at((A, B, C, D), s, method=method)
            ref = np.stack([C @ np.linalg.solve(sk * np.eye(n) - A, B) for sk in s])
            np.testing.assert_allclose(H, ref, rtol=1e-9, atol=1e-12)
            Ad, _ = zoh(A, B, 0.01)
            np.testing.assert_allclose(Ad, scipy.linalg.expm(A * 0.01), rtol=1e-9, atol=1e-12)
            A[0, 1] += 0.5  # same array object, new content


def test_auto_keeps_the_modal_form_where_the_balanced_hessenberg_form_fails():
    """Reference: python-control's frequency response (SLICOT TB05AD, unbalanced) and dense
    solves, on the closed loop of the S&P distillation problem with control.hinfsyn's
    controller (a −1.7e8 rad/s controller pole, W_P's −1e-6 rad/s pole, output matrix up to
    9e7). The balanced Hessenberg form is off by 3e4 at 1e-3 rad/s on this loop (its σ̄ is
    1.18 at every frequency); the modal form agrees to 1e-3, and "auto" must use it (it used
    the Hessenberg form whenever the two disagreed: dkpy's controller then had μ 3.2e6 in
    benchmarks/bench_dk.py)."""
    from ambseal.lti.interconnect import lft_lower

    P = distillation_rp_plant()
    K = control.hinfsyn(P, 2, 2)[0]
    cl = lft_lower(P, K, 2, 2)
    w = np.logspace(-3, 3, 25)
    A, B, C, D = (np.asarray(M) for M in (cl.A, cl.B, cl.C, cl.D))
    ref = np.moveaxis(cl(1j * w), -1, 0)
    assert _rel(_dense(A, B, C, D, w), ref) < 1e-3  # the two references agree
    assert _rel(fr.freqresp(cl, w), ref) < 2e-3
    assert _rel(fr.freqresp(cl, w, method="modal"), ref) < 2e-3


def _exact_response(sys, s, dps=40):
    """C (sI − A)⁻¹ B + D in ``dps``-digit arithmetic (mpmath LU), rounded to complex128."""
    import mpmath

    A, B, C, D = (np.asarray(getattr(sys, m), float) for m in "ABCD")
    out = np.empty((len(s), C.shape[0], B.shape[1]), complex)
    with mpmath.workdps(dps):
        Am, Cm = mpmath.matrix(A.tolist()), mpmath.matrix(C.tolist())
        for k, sk in enumerate(s):
            M = mpmath.eye(A.shape[0]) * mpmath.mpc(sk) - Am
            for j in range(B.shape[1]):
                h = Cm * mpmath.lu_solve(M, mpmath.matrix(B[:, j].tolist()))
                out[k, :, j] = [complex(h[i]) for i in range(C.shape[0])]
    return out + D[None]


def test_auto_falls_back_to_dense_solves_where_both_fast_forms_fail():
    """Reference: the response in 40-digit arithmetic (mpmath LU of sI − A) at every tenth
    frequency, and dkpy 0.1.9's own μ (1.03603, its LMI bound on python-control's response)
    of its D–K controller for the S&P distillation problem (22 states, stored from
    benchmarks/bench_dk.py's dkpy run). On that loop the modal form is off by 11 (σ̄ up to
    180) and the balanced Hessenberg form by 1.5e7; "auto" must notice and solve densely (it
    gave μ 8.2 instead of 1.036). python-control's own response is no reference here: with
    numpy 2.4 / slycot 0.7 it is off by 2.8e-3 of the largest entry at 1e-3 rad/s (the
    dense solves by 4.6e-5), and the ill-conditioned low end moves with the LAPACK build."""
    from pathlib import Path

    from ambseal.robust.mu import mussv
    from ambseal.lti.interconnect import lft_lower

    d = np.load(Path(__file__).parents[1] / "data" / "dkpy_distillation_K.npz")
    cl = lft_lower(distillation_rp_plant(), control.ss(d["A"], d["B"], d["C"], d["D"]), 2, 2)
    w = np.logspace(-3, 3, 61)
    H = fr.freqresp(cl, w)[::10]
    ref = _exact_response(cl, 1j * w[::10])
    # per frequency, relative to its largest entry: the module's arbitration tolerance
    assert np.max(np.abs(H - ref).max(axis=(1, 2)) / np.abs(ref).max(axis=(1, 2))) < 1e-4
    mu = mussv(cl, [(1, 1), (1, 1), (2, 2)], w).upper.max()
    assert mu == pytest.approx(float(d["mu_dkpy"]), rel=1e-3)


def test_badly_scaled_states_use_the_modal_form_of_the_balanced_matrix(monkeypatch):
    """Reference: dense solves of (jωI − A) X = B and python-control's response. The lightly
    damped system in states scaled by 1e-5…1e5 (a diagonal similarity, as [q; q̇] of an FE
    rotor with modes up to 100 kHz) has cond V > 1e8 unbalanced; "auto" takes the modal form
    of the balanced system (cond V back near the unscaled one; no Hessenberg solve) and
    agrees with both."""
    A, B, C, D, _ = _lightly_damped(n=60, seed=3)
    t = np.logspace(-5, 5, A.shape[0])
    A, B, C = A * t[None, :] / t[:, None], B / t[:, None], C * t[None, :]
    assert fr._modal_form(A, B, C, 1e8)[2] is None  # cond V > 1e8
    assert fr._modal_form(A, B, C, 1e8, balance=True)[1] < 1e6
    w = np.logspace(0, 4, 50)
    ref = np.moveaxis(control.ss(A, B, C, D)(1j * w), -1, 0)
    dense = _dense(A, B, C, D, w)

    def no_hessenberg(*a):
        raise AssertionError("Hessenberg path taken")

    monkeypatch.setattr(fr, "_hessenberg_response", no_hessenberg)
    H = fr.freqresp((A, B, C, D), w)
    assert _rel(H, dense) < 1e-8
    assert _rel(H, ref) < 1e-6


def _zoh_dense(A, B, C, D, dt, w):
    """Reference: scipy's zero-order hold (``cont2discrete``, one expm of its own) and one
    dense solve of (zI − A_d) X = B_d per frequency, z = e^{jω dt}."""
    from scipy.signal import cont2discrete

    Ad, Bd, *_ = cont2discrete((A, B, C, D), dt, method="zoh")
    n = A.shape[0]
    return np.array([C @ np.linalg.solve(np.exp(1j * wk * dt) * np.eye(n) - Ad, Bd) + D
                     for wk in w])


def test_sampled_response_matches_dense_solves_of_the_zoh_plant(monkeypatch):
    """Reference: scipy's ZOH and dense solves on the unit circle, up to Nyquist — on a
    lightly damped modal system, on one with an integrator (φ(0) = dt) and on the thesis
    rig's full-order plant (entries from 1 to ~1e12, modes far above Nyquist). All three
    by the continuous plant's modal form (the sampled plant's own response refused)."""
    from ambseal.config import load_rig
    from ambseal.model.rig import build_plant

    def refused(*args, **kwargs):
        raise AssertionError("the sampled plant's own response was computed")

    monkeypatch.setattr(fr, "freqresp_at", refused)

    A, B, C, D, _ = _lightly_damped()
    P = build_plant(load_rig())
    integ = (np.array([[0.0, 1.0], [0.0, -30.0]]), np.array([[0.0], [1.0]]),
             np.array([[1.0, 0.0]]), np.zeros((1, 1)))
    for sys, fs in (((A, B, C, D), 5000.0), (integ, 2000.0), ((P.A, P.B, P.C, P.D), 10000.0)):
        dt = 1.0 / fs
        w = 2 * np.pi * np.logspace(0, np.log10(0.999 * fs / 2), 25)
        H = fr.sampled_response_at(sys, dt, w)
        assert _rel(H, _zoh_dense(*sys, dt, w)) <= 1e-6


def test_sampled_response_by_input_groups_is_the_whole_plants():
    """Reference: scipy's ZOH and dense solves, and the response of each group alone. The
    inputs of a 520-state lightly damped system in two groups (its sampled forms certified
    apart, evaluated in one pass) and of a 120-state one (no kept form: group by group)
    give the whole plant's response, the groups' own to rounding; groups that are not a
    partition of the inputs are refused."""
    for n in (520, 120):
        A, B, C, D, _ = _lightly_damped(n=n)
        dt = 1.0 / 5000.0
        w = 2 * np.pi * np.logspace(0, np.log10(0.999 * 2500.0), 25)
        groups = ([2, 0], [3, 1])
        H = fr.sampled_response_at((A, B, C, D), dt, w, groups=groups)
        assert _rel(H, _zoh_dense(A, B, C, D, dt, w)) <= 1e-6
        for g in groups:
            assert _rel(H[:, :, g], fr.sampled_response_at((A, B[:, g], C, D[:, g]), dt, w)) \
                <= 1e-13
    with pytest.raises(ModelError, match="partition"):
        fr.sampled_response_at((A, B, C, D), dt, w, groups=([0, 1], [1, 2, 3]))


def test_sampled_response_of_a_defective_matrix_falls_back():
    """A Jordan block has no modal form: the response is the sampled plant's own (dense
    reference as above); a sample time that is not positive is refused."""
    A = np.array([[-2.0, 1.0], [0.0, -2.0]])
    sys = (A, np.array([[0.0], [1.0]]), np.array([[1.0, 0.0]]), np.zeros((1, 1)))
    w = 2 * np.pi * np.array([1.0, 10.0, 100.0])
    assert _rel(fr.sampled_response_at(sys, 1e-3, w), _zoh_dense(*sys, 1e-3, w)) <= 1e-9
    with pytest.raises(ModelError, match="dt must be a positive"):
        fr.sampled_response_at(sys, 0.0, w)


def test_balanced_modal_form_backward_stable_needs_no_hessenberg_form(monkeypatch, tmp_path):
    """Reference: the normwise backward error (Rigal & Gaches 1967; Higham, *Accuracy and
    Stability of Numerical Algorithms*, Thm 7.1) computed from the balanced plant's own
    eigenvectors, and dense solves refined to extended precision. The embedded rig refined
    to 100 beam elements (848 states): its balanced modal form's backward error at the
    probes, from the kept LU of V, is the one computed with V itself — about ε — so the
    form is taken as good as the Hessenberg form without reducing A to it, and its response
    at the probes is within 10 times the plain dense solves' error of the refined ones. A
    decomposition with its poles off by 1e-9 is not backward stable."""
    import scipy.linalg

    from ambseal.config import load_rig
    from ambseal.model.rig import build_plant

    from ..finemesh import fine_rig_text

    rig = tmp_path / "fine100.toml"
    rig.write_text(fine_rig_text(100), encoding="utf-8")
    P = build_plant(load_rig(rig))
    A, B, C, D = P.A, P.B, P.C, P.D
    n = A.shape[0]
    w = 2 * np.pi * np.logspace(0, np.log10(2000), 50)
    probe = fr._probes(1j * w)
    eta = fr._backward_error(A, B, C, probe, 1e8)
    Ab, (sc, _) = scipy.linalg.matrix_balance(A, permute=False, separate=True)
    lam, V = scipy.linalg.eig(Ab)
    Bb = B / sc[:, None]
    want = 0.0
    for p in probe:
        X = V @ (np.linalg.solve(V, Bb) / (p - lam)[:, None])
        R = p * X - Ab @ X - Bb
        want = max(want, np.linalg.norm(R) / (np.linalg.norm(p * np.eye(n) - Ab)
                                              * np.linalg.norm(X) + np.linalg.norm(Bb)))
    assert eta <= fr._BACKWARD_EPS * np.finfo(float).eps
    assert eta == pytest.approx(want, rel=0.5)

    def no_reduction(A):
        raise AssertionError("the Hessenberg form was computed")

    monkeypatch.setattr(fr, "_hessenberg_form", no_reduction)
    Hd = fr._probe_response(A, B, C, D, probe)
    ref = _refined(A, B, C, D, probe)
    H = fr._balanced_modal_as_good(A, B, C, D, probe, probe, Hd, 1e8)
    assert H is not None and _rel(H, ref) <= 10 * _rel(Hd, ref)
    # a decomposition that is not the plant's (its poles 1e-9 off): not backward stable
    kept = fr._EIG.get((A, C), (1e8, True), no_reduction)
    monkeypatch.setattr(fr._EIG, "get",
                        lambda arrays, extra, compute: (kept[0] * (1 + 1e-9),) + kept[1:])
    assert fr._backward_error_of(A, B, C, probe, 1e8) > fr._BACKWARD_EPS * np.finfo(float).eps
