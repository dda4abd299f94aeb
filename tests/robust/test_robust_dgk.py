"""Tests of ambseal.robust.dgk: D–G–K iteration for real parametric uncertainty."""

from __future__ import annotations

from dataclasses import replace

import control as ct
import numpy as np
import pytest

from ambseal.errors import ConfigError
from ambseal.lti.freqresp import freqresp
from ambseal.robust import _dgscale as dg
from ambseal.robust.dgk import fit_g, musyn_dgk
from ambseal.robust.dk import fit_dscale, musyn
from ambseal.robust.hinf import lft_lower
from ambseal.robust.mu import mussv

from ..spring_mass import spring_mass_plant

S = ct.tf("s")
G0 = 10 / ((S + 1) * (S + 10))
R = 0.9  # real gain uncertainty ±90 %
WP = (S / 2 + 3) / (S + 3e-3)
WU = 0.02 * (S + 1) / (S / 100 + 1)


def gain_plant(r: float = R):
    """SISO plant with a real input-gain uncertainty u_act = (1 + r δ) u, output
    disturbance w, performance [W_p y; W_u u]. Inputs [w_Δ, w, u], outputs
    [z_Δ, z_p, z_u, y]; u = K y."""
    g, wp, wu = ct.ss(G0), ct.ss(WP), ct.ss(WU)
    parts = [ct.ss([], [], [], [[0, 0, r]]),
             wp * (g * ct.ss([], [], [], [[1, 0, 1]]) + ct.ss([], [], [], [[0, 1, 0]])),
             wu * ct.ss([], [], [], [[0, 0, 1]]),
             g * ct.ss([], [], [], [[1, 0, 1]]) + ct.ss([], [], [], [[0, 1, 0]])]
    n = sum(p.nstates for p in parts)
    A, B = np.zeros((n, n)), np.zeros((n, 3))
    C, D = np.zeros((4, n)), np.zeros((4, 3))
    o = 0
    for i, p in enumerate(parts):
        k = p.nstates
        A[o:o + k, o:o + k], B[o:o + k], C[i, o:o + k], D[i] = p.A, p.B, p.C, p.D
        o += k
    return ct.minreal(ct.ss(A, B, C, D), verbose=False)


def test_fit_g_all_pass_pair_is_exact_and_recovers_a_known_phase():
    """Reference: ψ(ω) = 2·arctan(ω/1) − 2·arctan(ω/10), the phase difference of the
    all-pass pair (10 − s)/(10 + s), (1 − s)/(1 + s) (closed form); ĝ = tan(ψ/2). The fit
    recovers it, and |f|² + |h|² = 1, Re(h/f) = 0 hold off the grid too (all-pass identity)."""
    w = np.logspace(-2, 3, 80)
    psi = 2 * np.arctan(w) - 2 * np.arctan(w / 10)
    f, h, err = fit_g(w, np.tan(psi / 2))
    assert err < 1e-3
    wd = np.logspace(-4, 5, 400)
    fr, hr = np.asarray(f(1j * wd)).ravel(), np.asarray(h(1j * wd)).ravel()
    np.testing.assert_allclose(np.abs(fr) ** 2 + np.abs(hr) ** 2, 1.0, atol=1e-9)
    np.testing.assert_allclose(np.real(hr / fr), 0.0, atol=1e-7)
    np.testing.assert_allclose(np.imag(hr / fr)[(wd > 1e-2) & (wd < 1e3)],
                               -np.tan((2 * np.arctan(wd) - 2 * np.arctan(wd / 10)) / 2)[
                                   (wd > 1e-2) & (wd < 1e3)], atol=1e-2)
    assert np.all(np.real(f.poles()) < 0) and np.all(np.real(h.poles()) < 0)
    with pytest.raises(ConfigError, match="fit_g"):
        fit_g(w, np.full(3, 0.1))


W_GRID = np.logspace(-2, 3, 60)
BLOCKS = [(-1, 0), (1, 2)]


@pytest.fixture(scope="module")
def complex_dk():
    """Complex D–K of :func:`gain_plant` by its real uncertainty ±r (with musyn's default D
    search, or with ``search=0`` the iteration alone), computed once per case for the tests
    of this module."""
    done = {}

    def at(r: float, search="auto"):
        if (r, search) not in done:
            done[r, search] = musyn(gain_plant(r), BLOCKS, 1, 1, W_GRID, max_iter=6,
                                    search=search)
        return done[r, search]

    return at


@pytest.mark.heavy
def test_dgk_result_holds_by_a_parameter_sweep(complex_dk):
    """D–G–K steps are taken on a real ±90 % gain uncertainty, and the kept controller is
    never worse than complex D–K's (with or without D–K's D search). Reference for the μ
    it reports: the
    main-loop theorem checked by brute force — for every real δ with |δ| ≤ 1/μ the perturbed
    loop, rebuilt from G(1 + Rδ) and K without the LFT, is stable and its performance σ̄ on
    the grid is ≤ μ."""
    P = gain_plant()
    w, blocks = W_GRID, BLOCKS
    dk = complex_dk(R, search=0)
    lines: list[str] = []
    r = musyn_dgk(P, blocks, 1, 1, w, max_iter=6, progress=lines.append)
    assert r.mu < 0.9 * dk.mu and r.mu <= complex_dk(R).mu
    assert "D-G-K" in {h["step"] for h in r.history} <= {"D-K", "D search", "D-G-K"}
    # one progress line per K-step of each phase (a callable gets them, not the terminal)
    for step in ("D-K", "D-G-K"):
        done = sum(h["step"] == step for h in r.history)
        assert sum(ln.startswith(f"{step} ") and "γ =" in ln for ln in lines) == done > 0
    # the reported μ: the peak over the grid it names (W_GRID and the points added at its
    # peaks), not below the grid's
    mu_check = mussv(lft_lower(P, r.K, 1, 1), blocks, r.check_omega).upper
    assert r.mu == pytest.approx(float(np.max(mu_check)), rel=1e-6)
    assert r.mu >= float(np.max(mussv(lft_lower(P, r.K, 1, 1), blocks, w).upper)) * (1 - 1e-6)
    K = r.K
    Kw = np.asarray(K(1j * w)).ravel()
    Gw, Wpw, Wuw = (np.asarray(T(1j * w)).ravel() for T in (G0, WP, WU))
    for d in np.linspace(-1, 1, 21) / r.mu:
        Gd = ct.ss(G0) * (1 + R * d)
        cl = ct.feedback(Gd * K, 1, sign=1)
        assert np.all(np.real(cl.poles()) < 0)
        Sw = 1 / (1 - Gw * (1 + R * d) * Kw)
        perf = np.hypot(np.abs(Wpw * Sw), np.abs(Wuw * Kw * Sw))
        assert np.max(perf) <= r.mu * (1 + 1e-6)


@pytest.mark.heavy
def test_a_target_complex_dk_meets_skips_the_dgk_steps(complex_dk):
    """``target``: complex D–K's result as it is (its controller and μ, no D–G–K step, the
    rule saying why) when its μ is at or below the target; D–G–K steps when above."""
    P, w = gain_plant(), W_GRID
    dk = complex_dk(R)
    kept = musyn_dgk(P, BLOCKS, 1, 1, w, max_iter=6, target=dk.mu * 1.01)
    assert kept.mu == pytest.approx(dk.mu, rel=1e-12)
    assert kept.K.nstates == dk.K.nstates and np.allclose(kept.K.A, dk.K.A)
    assert {h["step"] for h in kept.history} <= {"D-K", "D search"}
    assert kept.stopping["dgk"]["iterations"] == 0 and "target" in kept.stopping["dgk"]["rule"]
    stepped = musyn_dgk(P, BLOCKS, 1, 1, w, max_iter=6, target=dk.mu * 0.5)
    assert "D-G-K" in {h["step"] for h in stepped.history} and stepped.mu < dk.mu


def test_dgk_steps_end_at_the_first_that_meets_the_target():
    """``target`` also ends the D–G–K phase: at the first step whose μ (re-checked) is at
    or below it, whatever ``max_iter`` and ``patience`` allow, the rule saying so.
    Reference: the same design without a target, whose steps go on past that μ (on
    :func:`gain_plant`, complex D–K 1.72, D–G–K 1.653, 1.549, 1.547, 1.544)."""
    P, w = gain_plant(), np.logspace(-2, 3, 6)
    free = musyn_dgk(P, BLOCKS, 1, 1, w, max_iter=4, search=0)
    steps = [h["mu"] for h in free.history if h["step"] == "D-G-K"]
    complex_mu = min(h["mu"] for h in free.history if h["step"] == "D-K")
    assert len(steps) > 1 and steps[0] < complex_mu
    met = musyn_dgk(P, BLOCKS, 1, 1, w, max_iter=4, search=0, target=steps[0] * (1 + 1e-9))
    assert [h["mu"] for h in met.history if h["step"] == "D-G-K"] == [steps[0]]
    assert met.stopping["dgk"]["iterations"] == 1 and "target" in met.stopping["dgk"]["rule"]
    assert met.mu == pytest.approx(steps[0], rel=1e-9) and met.mu > free.mu


@pytest.mark.heavy
def test_dgk_steps_end_by_the_stall_rule_not_a_count(monkeypatch):
    """Without ``max_iter`` the D–G–K phase ends by its stall rule alone, however many
    steps each gain more than ``rtol``: an iteration cap would stop where the path happens
    to be. Fault injection: the re-checked μ of the first 11 steps falls by 3 % a step
    (more than rtol = 1 %) from 1.5, below complex D–K's 1.72, then stays; the phase
    ends ``patience`` steps later, at the 13th step, the rule naming patience, the best
    iterate (the 11th) kept."""
    import ambseal.robust.dgk as dgk

    P, w, real_check, seen = gain_plant(), np.logspace(-2, 3, 6), dgk._check, []

    def check(P_, K, *args):
        pk = real_check(P_, K, *args)
        if len(seen) >= 13:  # the result's own re-check: as it is
            return pk
        seen.append(K)
        return replace(pk, peak=1.5 * 0.97 ** min(len(seen) - 1, 10))

    monkeypatch.setattr(dgk, "_check", check)
    r = musyn_dgk(P, BLOCKS, 1, 1, w, search=0)
    steps = [h for h in r.history if h["step"] == "D-G-K"]
    assert len(steps) == 13 and r.stopping["dgk"]["iterations"] == 13
    assert r.stopping["dgk"]["rule"].startswith("patience=2")
    assert r.best_iteration == steps[10]["iteration"]
    capped = musyn_dgk(P, BLOCKS, 1, 1, w, search=0, max_iter=1)
    assert capped.stopping["dgk"] == {"iterations": 1, "rule": "max_iter=1"}


def test_design_mu_iteration_key_defaults_to_dgk():
    """[design.mu] iteration: "dgk" by default (the rig's real seal parameters), "dk" by
    --set; anything else refused naming the key."""
    from ambseal.config import load_rig
    from ambseal.design.specs import design_spec

    assert design_spec(load_rig()).mu_iteration == "dgk"
    sp = design_spec(load_rig(None, ["design.mu.iteration=dk"]))
    assert sp.mu_iteration == "dk" and 'iteration = "dk"' in sp.to_toml()
    with pytest.raises(ConfigError, match="design.mu.iteration"):
        load_rig(None, ["design.mu.iteration=complex"])


def test_design_mu_has_no_iteration_cap_unless_the_rig_sets_one():
    """[design.mu] max_iter: none by default (each D–K phase ends by its stall rule, the
    specification's TOML says so), a cap where the rig or --set gives one."""
    from ambseal.config import load_rig
    from ambseal.design.specs import design_spec

    sp = design_spec(load_rig())
    assert sp.max_iter is None and "max_iter =" not in sp.to_toml()
    sp = design_spec(load_rig(None, ["design.mu.max_iter=3"]))
    assert sp.max_iter == 3 and "max_iter = 3" in sp.to_toml()


@pytest.mark.slow
def test_dgk_on_the_test_rig_lowers_mixed_mu_below_complex_dk(testrig_cfg, monkeypatch):
    """Reference: complex D–K's mixed μ on the same rig problem, grid and reduction (the μ
    bounds are certificates on the structure as given). The rig's design, made to take
    D–G–K steps (the seal's k is real) although complex D–K already meets μ < 1 (the
    design's own target, which would skip them), must give a controller whose mixed μ is
    below D–K's at full order; the reduction keeps whichever candidate has the lower μ
    at the reduced order (measured: D–G–K 0.909 against D–K 0.917 at full order, 0.940
    against 0.918 at 28 states, so D–K's is kept)."""
    import ambseal.design.recipes as recipes

    dgk = recipes.musyn_dgk
    monkeypatch.setattr(recipes, "musyn_dgk", lambda *a, target=None, **k: dgk(*a, **k))
    r = recipes.design(testrig_cfg, "mu")
    dk_mu = min(h["mu"] for h in r.history if h["step"] == "D-K")
    dgk_mu = min(h["mu"] for h in r.history if h["step"] == "D-G-K")
    assert dgk_mu < dk_mu
    rows = {c["step"]: c for c in r.reduction["candidates"]}
    assert set(rows) == {"D-K", "D-G-K"}
    assert r.reduction["kept"] == min(rows, key=lambda k: rows[k]["mu"])
    assert np.isfinite(rows["D-G-K"]["gamma"])


# --------------------------------------------------------------------------- scalings
W_FIT = np.logspace(-2, 3, 40)
SM_BLOCKS, SM_REAL = [(-1, 0), (1, 0), (2, 2)], [True, False, False]


def test_scaled_plant_dg_is_the_formula_with_each_allpass_pair_realised_once():
    """Reference: the scaled plant's frequency response by its formula,
    ``diag(d1/β, d2/β, 1/β, 1/β, 1) P diag(f/d1, 1/d2, 1, 1, 1) + h E₁₁`` from the
    transfer functions at each ω; its states are P's, the D scales' (left and right) and
    the two all-pass functions' once (f and h apart would hold the pair twice)."""
    P = spring_mass_plant()
    d1, d2 = ct.tf([1.0, 3.0, 2.0], [0.5, 2.0, 8.0]), ct.tf([2.0, 1.0], [1.0, 5.0])
    x1, x2 = np.array([0.0]), np.array([np.log(3.0)])
    a1, a2 = dg._ap_tf(x1, 1, 0), dg._ap_tf(x2, 1, 0)
    fits = [dg.DGFit(d1, (a1 + a2) / 2, (a1 - a2) / 2, (a1, a2)), dg.DGFit(d2)]
    beta = 1.3
    Ps = dg.scaled_plant_dg(P, SM_BLOCKS, fits, beta, 1, 1)
    assert Ps.nstates == P.nstates + 2 * 2 + 2 * 1 + 1 + 1
    w = np.logspace(-2, 3, 25)
    val = lambda tf: np.asarray(tf(1j * w)).ravel()  # noqa: E731
    L = np.stack([val(d1) / beta, val(d2) / beta] + [np.full(w.size, 1 / beta)] * 2
                 + [np.ones(w.size)], axis=1)
    R = np.stack([val((a1 + a2) / 2) / val(d1), 1 / val(d2)] + [np.ones(w.size)] * 3, axis=1)
    ref = L[:, :, None] * freqresp(P, w) * R[:, None, :]
    ref[:, 0, 0] += val((a1 - a2) / 2)
    np.testing.assert_allclose(freqresp(Ps, w), ref, rtol=1e-9, atol=1e-12)


def random_scalings():
    """A random 4×4 M on ``W_FIT`` and fitted D–G scalings of the spring–mass structure:
    two D scales, one all-pass pair, β = 1.2. Returns (scalings, M, d1, d2)."""
    rng = np.random.default_rng(3)
    M = rng.normal(size=(W_FIT.size, 4, 4)) + 1j * rng.normal(size=(W_FIT.size, 4, 4))
    d1, d2 = ct.tf([1.0, 3.0, 2.0], [0.5, 2.0, 8.0]), ct.tf([2.0, 1.0], [1.0, 5.0])
    g_fits = {0: (np.array([np.log(0.5), np.log(2.0), np.log(0.3),
                            np.log(3.0), np.log(0.7), np.log(0.5)]), 1, 1)}
    sc = dg.DGScalings(SM_BLOCKS, SM_REAL, [d1, d2], g_fits, 1.2, W_FIT)
    return sc, M, d1, d2


def test_dg_scalings_sigma_is_the_scaled_matrix_and_its_gradient_is_exact():
    """References: σ̄ of ``diag(d/β) M diag(f/d) + h E₁₁`` from the fitted transfer
    functions at each ω (numpy's SVD), for a random M — the scalings' own evaluation drops
    the common phases of d and f, which must not change σ̄ — and central finite
    differences of it for the analytic gradient."""
    sc, M, d1, d2 = random_scalings()
    x = sc.x0
    (fd1, f, h), (fd2, _, _) = sc.fits(x)
    val = lambda tf: np.asarray(tf(1j * W_FIT)).ravel()  # noqa: E731
    L = np.stack([val(fd1), val(fd2), np.ones(W_FIT.size), np.ones(W_FIT.size)], 1) / 1.2
    R = np.stack([val(f) / val(fd1), 1 / val(fd2), np.ones(W_FIT.size),
                  np.ones(W_FIT.size)], 1)
    S = L[:, :, None] * M * R[:, None, :]
    S[:, 0, 0] += val(h)
    np.testing.assert_allclose(sc.sigma(x, M, W_FIT), np.linalg.svd(S, compute_uv=False)[:, 0],
                               rtol=1e-9)
    s0, G = sc.sigma(x, M, W_FIT, grad=True)
    for i in range(x.size):
        e = np.zeros_like(x)
        e[i] = 1e-6
        fd = (sc.sigma(x + e, M, W_FIT) - sc.sigma(x - e, M, W_FIT)) / 2e-6
        np.testing.assert_allclose(G[:, i], fd, rtol=1e-4, atol=1e-7)


def test_the_refinement_ends_by_slsqps_tolerance_or_a_rounds_stall_not_its_count(
        monkeypatch):
    """Reference: the same refinement with SciPy's default count, which SLSQP's ftol ends
    after 72 iterations. With the count cut to 20 iterations a call, the refinement goes
    on from where each call stopped, and ends at the first call that lowers the level by
    less than ``_ROUND_RTOL`` of it (the third: 0.03 %): a stall, not a count, within
    ``_ROUND_RTOL`` of the reference's level."""
    sc, M, _, _ = random_scalings()
    whole = sc.sigma(dg._minimax(sc, sc.x0, M, W_FIT), M, W_FIT).max()
    ends, minimize = [], dg.minimize

    def cut(*args, **kw):
        res = minimize(*args, **{**kw, "options": {**kw["options"], "maxiter": 20}})
        ends.append((res.status, res.fun))
        return res

    monkeypatch.setattr(dg, "minimize", cut)
    level = sc.sigma(dg._minimax(sc, sc.x0, M, W_FIT), M, W_FIT).max()
    assert len(ends) > 2 and all(st == dg._SLSQP_COUNT for st, _ in ends)
    gains = [(a - b) / a for (_, a), (_, b) in zip(ends, ends[1:])]
    assert all(g > dg._ROUND_RTOL for g in gains[:-1]) and 0 <= gains[-1] <= dg._ROUND_RTOL
    assert abs(level - whole) <= dg._ROUND_RTOL * whole


def _refinement_start(points, tol=0.05):
    """The spring–mass loop of an H∞ controller on μ's grid of ``points`` and the D–G
    step's fits at uniform weights to ``tol``, where the refinement starts: (P, K, w,
    mu_s, sc)."""
    from ambseal.robust.hinf import hinfsyn

    P = spring_mass_plant()
    K = hinfsyn(ct.ss(P.A, P.B[:, 2:], P.C[2:], P.D[2:, 2:]), 1, 1).K
    w = np.logspace(-2, 3, points)
    M = freqresp(lft_lower(P, K, 1, 1), w)
    mu_s = mussv(M, SM_BLOCKS)
    beta = float(mu_s.upper.max())
    ds, gs = dg.relax_pointwise(M, mu_s.blocks, SM_REAL, np.asarray(mu_s.Dl),
                                np.asarray(mu_s.G), mu_s.upper, beta, w)
    x, k1, k2, _ = dg.fit_allpass_pair(w, gs[:, 0], np.ones_like(w), tol)
    sc = dg.DGScalings(mu_s.blocks, SM_REAL, [fit_dscale(w, ds[:, j], tol=tol)[0]
                                              for j in range(2)], {0: (x, k1, k2)}, beta, w)
    return P, K, w, mu_s, sc


@pytest.mark.heavy
def test_the_pass_at_the_largest_orders_is_kept_only_where_it_gains(monkeypatch):
    """The refinement's pass at the largest orders (run where the fitted orders leave the
    level above 1 + ``_RETRY``) is delivered only where it lowers the first pass's level
    beyond the norm's accuracy (``_NORM_RTOL``). On the overhung compressor's second D–G–K
    step both passes ended at one level to six digits, and which was kept — the fitted
    orders (196 states) or the largest (220) — followed the BLAS kernels. Here the
    spring–mass refinement with each pass's H∞ level set: the second pass 1e-9 below the
    first keeps the first's scalings; 2 % below, the second's."""
    P, K, w, mu_s, sc = _refinement_start(27, tol=1.0)  # fits below the largest orders
    hinfnorm = dg.hinfnorm
    for gain, second in ((1e-9, False), (2e-2, True)):
        passes = []

        def level_of(*args, **kw):
            _, w_peak = hinfnorm(*args, **kw)
            passes.append(args[0].nstates)
            # one level a pass (each pass then ends by the cuts' patience)
            return (3.0 if passes.count(passes[0]) == len(passes) else 3.0 * (1 - gain),
                    w_peak)

        monkeypatch.setattr(dg, "hinfnorm", level_of)
        fits, level = dg.refine_scalings(sc, P, K, mu_s.blocks, 1, 1, w)
        assert len(set(passes)) == 2, passes  # the fitted orders, then the largest
        assert level == (3.0 * (1 - gain) if second else 3.0)
        states = lft_lower(dg.scaled_plant_dg(P, mu_s.blocks, fits, sc.beta, 1, 1), K, 1,
                           1).nstates
        assert states == (passes[-1] if second else passes[0]), (states, passes)


@pytest.mark.heavy
def test_the_cutting_planes_end_when_the_bound_is_tight_or_stalls_not_after_a_count(
        monkeypatch):
    """On μ's grids of 27 and 35 points the spring–mass loop of an H∞ controller puts the
    scaled loop's H∞ peaks between the points, and the refinement of the fits (at uniform
    weights) adds cutting planes
    (under one BLAS thread and two, 3–11 H∞ norms a grid; 4 or more on at least one of
    them under every kernel set tried: a count of three would have ended that pass). Each
    pass (the fitted orders, then the largest) ends at the first cut where the H∞ level is
    within ``_CUT_RTOL`` of the grid's peak or where ``_CUT_PATIENCE`` cuts in a row have
    not lowered the pass's best level by ``_CUT_RTOL``, and the refinement delivers the
    first pass's best level, or the second's where it is lower beyond the norm's accuracy.
    Three cuts a pass, keeping each pass's last, broke both: on 27 points under two
    threads it delivered 1.18 where a cut had reached 1.12, under one 3.25 where one had
    reached 1.18."""
    minimax, hinfnorm, counts = dg._minimax, dg.hinfnorm, []
    for points in (27, 35):
        P, K, w, mu_s, sc = _refinement_start(points)
        cuts = []

        def seen_minimax(sc, x0, M, wd):
            x = minimax(sc, x0, M, wd)
            cuts.append([id(sc), float(sc.sigma(x, M, wd).max())])
            return x

        def seen_hinfnorm(*args, **kw):
            level, w_peak = hinfnorm(*args, **kw)
            cuts[-1].append(float(level))
            return level, w_peak

        monkeypatch.setattr(dg, "_minimax", seen_minimax)
        monkeypatch.setattr(dg, "hinfnorm", seen_hinfnorm)
        level = dg.refine_scalings(sc, P, K, mu_s.blocks, 1, 1, w)[1]
        monkeypatch.setattr(dg, "_minimax", minimax)
        monkeypatch.setattr(dg, "hinfnorm", hinfnorm)
        counts.append(len(cuts))
        kept = np.inf  # a later pass's best level is kept where it is lower beyond 1e-6
        for sc in dict.fromkeys(c[0] for c in cuts):
            here = min(c[2] for c in cuts if c[0] == sc)
            kept = here if here < kept * (1 - dg._NORM_RTOL) else kept
        assert level == kept
        for sc in dict.fromkeys(c[0] for c in cuts):
            best, misses, ended = np.inf, 0, []
            for _, peak, lv in (c for c in cuts if c[0] == sc):
                misses = 0 if lv < best * (1 - dg._CUT_RTOL) else misses + 1
                best = min(best, lv)
                ended.append(lv <= peak * (1 + dg._CUT_RTOL) or misses >= dg._CUT_PATIENCE)
            assert ended[-1] and not any(ended[:-1]), (points, ended)
    assert max(counts) >= 4, counts  # where a count of three would have ended a pass


def test_relaxed_pointwise_scalings_keep_their_level_and_vary_less():
    """Reference: the μ upper bound of mussv (its own generalised eigenvalue solver) at the
    pointwise scalings of a spring–mass loop equals the level _levels computes from those
    scalings (an independent evaluation of Mᴴ D M + j(G M − Mᴴ G) ⪯ β² D); the relaxed
    scalings stay within ``max(μ(ω), (1 − RELAX)·β)`` at every ω and vary less over the
    grid (total variation of log D), which is what makes them easy to fit."""
    from ambseal.robust.hinf import hinfsyn

    P = spring_mass_plant()
    K = hinfsyn(ct.ss(P.A, P.B[:, 2:], P.C[2:], P.D[2:, 2:]), 1, 1).K
    M = freqresp(lft_lower(P, K, 1, 1), W_FIT)
    mu_s = mussv(M, SM_BLOCKS, lower=False)
    beta = float(mu_s.upper.max())
    lay = dg.block_layout(SM_BLOCKS)
    last = lay[-1][0][0]
    dlast = np.real(mu_s.Dl[:, last, last]) ** 2
    D = np.stack([np.real(mu_s.Dl[:, i, i]) ** 2 / dlast for i in (0, 1)], 1)
    g = np.stack([np.real(mu_s.G[:, 0, 0]) / dlast, np.zeros(W_FIT.size)], 1)
    np.testing.assert_allclose(dg._levels(M, lay, SM_REAL, D, g), mu_s.upper, rtol=1e-6)
    d, ghat = dg.relax_pointwise(M, SM_BLOCKS, SM_REAL, mu_s.Dl, mu_s.G, mu_s.upper, beta,
                                 W_FIT)
    level = dg._levels(M, lay, SM_REAL, d ** 2, ghat * d ** 2 * beta)
    assert np.all(level <= np.maximum(mu_s.upper, (1 - dg.RELAX) * beta) * (1 + 1e-9))
    tv = lambda y: np.sum(np.abs(np.diff(np.log(y), axis=0)))  # noqa: E731
    assert tv(d) < tv(np.sqrt(D))


# --------------------------------------------------------------------------- published case
def _worst_gain(cl, omega, n_real=21, n_phase=24):
    """Largest σ̄ of the performance channels of ``cl`` (inputs/outputs [Δ(2), perf(2)])
    over the real δ₁ ∈ [−1, 1] and the complex |δ₂| = 1 on ``omega`` (python-control's
    frequency response; the maximum over the disc is on its circle), and whether the loop
    closed by every real pair (δ₁, ±1) is stable."""
    A, B, C, D = (np.asarray(X) for X in (cl.A, cl.B, cl.C, cl.D))
    H = np.moveaxis(ct.frequency_response(cl, omega, squeeze=False).complex, 2, 0)
    M11, M12, M21, M22 = H[:, :2, :2], H[:, :2, 2:], H[:, 2:, :2], H[:, 2:, 2:]
    worst, stable = 0.0, True
    for d1 in np.linspace(-1.0, 1.0, n_real):
        for ph in np.linspace(0.0, 2 * np.pi, n_phase, endpoint=False):
            Dl = np.diag([d1, np.exp(1j * ph)])
            perf = M22 + M21 @ Dl @ np.linalg.solve(np.eye(2) - M11 @ Dl, M12)
            worst = max(worst, float(np.max(np.linalg.svd(perf, compute_uv=False)[:, 0])))
        for d2 in (-1.0, 1.0):
            Dl = np.diag([d1, d2])
            Acl = A + B[:, :2] @ Dl @ np.linalg.solve(np.eye(2) - D[:2, :2] @ Dl, C[:2])
            stable &= bool(np.all(np.linalg.eigvals(Acl).real < 0))
    return worst, stable


@pytest.mark.slow
def test_musyn_dgk_defaults_reach_the_published_mixed_mu_spring_mass_result():
    """Reference: MathWorks, Robust Control Toolbox example "Control of a Spring-Mass-Damper
    System Using Mixed-Mu Synthesis" (after Barros, Fekri & Athans, "Robust mixed-mu
    synthesis performance for mass-spring system with stiffness uncertainty", 2005
    Mediterranean Control Conference): complex μ-synthesis ends with μ > 1, mixed
    μ-synthesis (``MixedMU`` on) with a controller that achieves the robust performance
    (μ < 1); the independent checks are SLICOT AB13MD's mixed μ upper bound (slycot; real
    1×1, complex 1×1 and 2×2 blocks) on python-control's F_l over 701 points log-spaced in
    10⁻³…10⁵ rad/s, and the worst-case performance by brute force over the uncertainty
    (k1 at 21 values of its range, the delay block on its unit circle), which the μ bound
    must cover. Measured: complex D–K 1.082, D–G–K 0.925 (AB13MD agrees to 1e-5), worst
    case 0.925 — the example's worst-case gain of its mixed-μ controller is 0.88 (MATLAB's
    wcgain), not reached."""
    from slycot import ab13md

    P = spring_mass_plant()
    r = musyn_dgk(P, [(-1, 0), (1, 1), (2, 2)], 1, 1)
    complex_mu = min(h["mu"] for h in r.history if h["step"] in ("D-K", "D search"))
    assert complex_mu > 1.0 > r.mu
    cl = P.lft(r.K, nu=1, ny=1)
    assert np.all(cl.poles().real < 0)
    w = np.logspace(-3, 5, 701)
    H = np.moveaxis(ct.frequency_response(cl, w, squeeze=False).complex, 2, 0)
    check = max(ab13md(np.asfortranarray(Hk), np.array([1, 1, 2]), np.array([1, 2, 2]))[0]
                for Hk in H)
    assert check < 1.0 and r.mu == pytest.approx(check, rel=1e-2)
    worst, stable = _worst_gain(cl, w)
    assert stable and worst <= r.mu * (1 + 1e-3)



def test_dgk_keeps_the_iterate_of_the_lowest_rechecked_mu(monkeypatch):
    """Each D–G–K iterate is judged by its μ re-checked around its peaks, the number the
    result reports, not by its grid's peak: a K-step can put a narrow peak between the
    grid's points. Fault injection: the re-check of the last iterate (the lowest on the
    6-point grid, 1.5426 against 1.5451 before it) is made to find such a peak, twice
    its grid's; the controller kept is then the one before it, and its μ is its own
    re-checked bound (reference: :func:`mussv` of the kept loop on 2 000 points)."""
    import ambseal.robust.dgk as dgk

    P, w, max_iter = gain_plant(), np.logspace(-2, 3, 6), 4
    free = musyn_dgk(P, BLOCKS, 1, 1, w, max_iter=max_iter, search=0)
    grid = [h["mu_grid"] for h in free.history if h["step"] == "D-G-K"]
    low = int(np.argmin(grid))
    made, real_check, real_k_step = [], dgk._check, dgk._k_step

    def k_step(*args):
        hr = real_k_step(*args)
        made.append(hr.K)
        return hr

    def check(P_, K, *args):
        pk = real_check(P_, K, *args)
        if len(made) == low + 1 and K is made[-1]:
            return replace(pk, peak=2 * pk.peak)
        return pk

    monkeypatch.setattr(dgk, "_k_step", k_step)
    monkeypatch.setattr(dgk, "_check", check)
    r = musyn_dgk(P, BLOCKS, 1, 1, w, max_iter=max_iter, search=0)
    steps = [h for h in r.history if h["step"] == "D-G-K"]
    assert len(steps) > 1 and [h["mu_grid"] for h in steps] == grid[:len(steps)]
    assert steps[low]["mu"] > 1.9 * steps[low]["mu_grid"]
    others = [h for i, h in enumerate(steps) if i != low]
    assert all(h["mu"] >= h["mu_grid"] * (1 - 1e-9) for h in others)
    kept = min(others, key=lambda h: h["mu"])
    assert r.best_iteration == kept["iteration"] and r.K is made[steps.index(kept)]
    true = float(np.max(mussv(P.lft(r.K, nu=1, ny=1), BLOCKS, np.logspace(-2, 3, 2000)).upper))
    assert r.mu == kept["mu"] and r.mu == pytest.approx(true, rel=1e-3)


@pytest.mark.slow
def test_a_dgk_steps_scalings_do_not_follow_the_rounding_of_its_loop():
    """The first D–G–K step of the overhung compressor example's μ design
    (tests/data/overhung_dgk_step.npz: its generalised plant, D–K's controller and the
    mixed bound's pointwise scalings at β = 1.16), solved as it is and with the plant's A
    perturbed by 1e-13 of each entry (seeded): about what two BLAS kernel sets change.
    The scalings' responses agree to 1e-3 of their largest (measured: 4.7e-4, 3e-5
    before the D fits were continued; 2.0 with them continued through two equal
    all-pass corners, which the rounding parted or not), and the
    scaled loop's H∞ level to 1e-4 (its norm is computed to 1e-6). Reference: the minimax
    of the peak from the first fits (SLSQP), which this step ran before: its scalings
    ended 194 % apart, at levels 1.0149 and 1.0083 (its iterates part threefold per step;
    benchmarks/README.md)."""
    import ambseal.robust.dgk as dgk
    from pathlib import Path
    from types import SimpleNamespace

    d = np.load(Path(__file__).resolve().parents[1] / "data" / "overhung_dgk_step.npz",
                allow_pickle=False)
    mu_s = SimpleNamespace(Dl=d["Dl"], G=d["G"], upper=d["upper"],
                           blocks=tuple(tuple(int(v) for v in b) for b in d["blocks"]))
    K = ct.ss(d["KA"], d["KB"], d["KC"], d["KD"])
    w = d["w"]

    def step(eps):
        rng = np.random.default_rng(0)
        A = d["PA"] * (1 + eps * rng.standard_normal(d["PA"].shape))
        fits, _, level = dgk._dg_step_scalings(
            ct.ss(A, d["PB"], d["PC"], d["PD"]), K, int(d["nmeas"]), int(d["ncon"]), mu_s,
            [bool(r) for r in d["real"]], float(d["beta"]), w, float(d["fit_tol"]))
        resp = np.concatenate([np.ravel(np.asarray(f(1j * w))) for fit in fits
                               for f in fit[:3] if f is not None])
        return level, resp

    (l0, r0), (l1, r1) = step(0.0), step(1e-13)
    assert np.max(np.abs(r0 - r1)) <= 1e-3 * np.max(np.abs(r0))
    assert l1 == pytest.approx(l0, rel=1e-4)


@pytest.mark.slow
def test_the_overhung_compressors_second_dgk_step_meets_mu_whatever_the_rounding():
    """The second D–G–K step of the overhung compressor example's μ design (its design
    with the modes' frequencies uncertain over their speed bands;
    tests/data/overhung_dgk_step4.npz: its generalised plant, the first step's controller
    of order 214 and the mixed bound's pointwise scalings at β = 1.334, dumped under
    Haswell kernels), solved as it is and with the plant's A perturbed by 1e-13 of each
    entry (seeded): about what two BLAS kernel sets change. Every reweighted round peaks
    above 1.01, so the minimax refines the fits. Both steps' K-steps must meet μ < 1 on
    the step's grid, their scaled loops' H∞ levels within 1 % of each other (measured:
    1.0089 and 1.0098, μ 0.802 and 0.818). Reference: the minimax from the first round's
    fits, as the step ran before: levels 1.273 and 1.008, μ 1.303 and 0.789 — met or
    missed as the rounding fell, as the example was under Haswell and SkylakeX kernels
    (benchmarks/README.md, "The minimax from the best reweighted round")."""
    import ambseal.robust.dgk as dgk
    from pathlib import Path
    from types import SimpleNamespace

    d = np.load(Path(__file__).resolve().parents[1] / "data" / "overhung_dgk_step4.npz",
                allow_pickle=False)
    blocks = tuple(tuple(int(v) for v in b) for b in d["blocks"])
    mu_s = SimpleNamespace(Dl=d["Dl"], G=d["G"], upper=d["upper"], blocks=blocks)
    K, w, beta = ct.ss(d["KA"], d["KB"], d["KC"], d["KD"]), d["w"], float(d["beta"])
    nmeas, ncon = int(d["nmeas"]), int(d["ncon"])

    def step(eps):
        rng = np.random.default_rng(0)
        P = ct.ss(d["PA"] * (1 + eps * rng.standard_normal(d["PA"].shape)), d["PB"],
                  d["PC"], d["PD"])
        fits, _, level = dgk._dg_step_scalings(P, K, nmeas, ncon, mu_s,
                                               [bool(r) for r in d["real"]], beta, w,
                                               float(d["fit_tol"]))
        hr = dgk._k_step(dg.scaled_plant_dg(P, blocks, fits, beta, nmeas, ncon), nmeas,
                         ncon, level)
        mu = mussv(freqresp(lft_lower(P, hr.K, nmeas, ncon), w), blocks, lower=False)
        return level, float(np.max(mu.upper))

    (l0, mu0), (l1, mu1) = step(0.0), step(1e-13)
    assert mu0 < 1 and mu1 < 1, (mu0, mu1)
    assert l1 == pytest.approx(l0, rel=1e-2)


def _gain_step():
    """A D–G step's inputs on :func:`gain_plant`'s loop of an H∞ controller (30 points):
    ``(P, K, w, mu_s, real, beta)``, the mixed bound on the scalar structure at its peak."""
    from ambseal.robust import dgk
    from ambseal.robust.hinf import hinfsyn
    from ambseal.robust.mu import check_blocks

    P = gain_plant()
    K = hinfsyn(ct.ss(P.A, P.B[:, 1:], P.C[1:], P.D[1:, 1:]), 1, 1).K
    w = np.logspace(-2, 3, 30)
    sblocks, real = dgk._split(check_blocks(P, BLOCKS, 1, 1))
    mu_s = mussv(freqresp(lft_lower(P, K, 1, 1), w), sblocks)
    return P, K, w, mu_s, real, float(mu_s.upper.max())


def test_a_reweighted_round_continues_each_all_pass_fit_from_the_last_round(monkeypatch):
    """The D–G step's reweighting rounds fit each real channel's all-pass pair once, from
    the last round's pair; the multistart over orders and starts (up to 36 fits) runs in
    the first round only. Reference: the same step with the multistart in every round, on
    :func:`gain_plant`'s loop of an H∞ controller (30 points): the continued fits certify
    the controller at a level (the H∞ norm of the scaled loop) within μ's 2 % tolerance of
    it (measured 1.0082 against 1.0030, at 2.4 s against 6.7 s; benchmarks/README.md,
    "D–G–K's all-pass fits continued")."""
    from ambseal.robust import dgk

    P, K, w, mu_s, real, beta = _gain_step()
    fits, fit_pair, solve = [], dg.fit_allpass_pair, dg.least_squares_converged

    def counted(*args, **kw):
        fits[-1] += 1
        return solve(*args, **kw)

    def pair(*args, **kw):
        fits.append(0)
        return fit_pair(*args, **kw)

    monkeypatch.setattr(dg, "least_squares_converged", counted)
    monkeypatch.setattr(dgk, "fit_allpass_pair", pair)
    level = dgk._dg_step_scalings(P, K, 1, 1, mu_s, real, beta, w, 0.05)[2]
    assert len(fits) >= 2 and fits[0] >= 6 and fits[1:] == [1] * (len(fits) - 1), fits
    monkeypatch.setattr(dgk, "fit_allpass_pair", lambda *a, start=None: fit_pair(*a))
    every = dgk._dg_step_scalings(P, K, 1, 1, mu_s, real, beta, w, 0.05)[2]
    assert level == pytest.approx(every, rel=0.02)


def test_a_reweighted_round_continues_each_d_fit_from_the_last_round(monkeypatch):
    """The D–G step's reweighting rounds fit each channel's D scale once, from the last
    round's fit at its order; the multistart over orders and starts (up to 16 fits) runs
    in the first round only. Reference: the same step with the multistart in every round,
    on :func:`gain_plant`'s loop of an H∞ controller (30 points): the continued fits
    certify the controller at a level (the H∞ norm of the scaled loop) within μ's 2 %
    tolerance of it (measured 1.0000 against 1.0082; benchmarks/README.md, "D–G–K's D fits
    continued")."""
    import ambseal.robust.dk as dk
    from ambseal.robust import dgk

    P, K, w, mu_s, real, beta = _gain_step()
    calls, fit_d, solve = [], dk._fit_dscale, dk.least_squares_converged

    def counted(*args, **kw):
        calls[-1][1] += 1
        return solve(*args, **kw)

    def fit(*args, start=None, **kw):
        calls.append([start, 0])
        out = fit_d(*args, start=start, **kw)
        calls[-1].append(out[3])
        return out

    monkeypatch.setattr(dk, "least_squares_converged", counted)
    monkeypatch.setattr(dgk, "_fit_dscale", fit)
    level = dgk._dg_step_scalings(P, K, 1, 1, mu_s, real, beta, w, 0.05)[2]
    channels = len(real) - 1
    first, later = calls[:channels], calls[channels:]
    assert later and all(s is None for s, _, _ in first)
    assert sum(n for _, n, _ in first) >= 4, first
    for k, (start, n, (x, order)) in enumerate(later):
        last = calls[k][2]
        assert start is last and order == last[1]
        assert n == (1 if order else 0)
    monkeypatch.setattr(dgk, "_fit_dscale", lambda *a, start=None, **kw: fit_d(*a, **kw))
    every = dgk._dg_step_scalings(P, K, 1, 1, mu_s, real, beta, w, 0.05)[2]
    assert level == pytest.approx(every, rel=0.02)


@pytest.mark.heavy
def test_the_minimax_refines_the_best_reweighted_round(monkeypatch):
    """Where no reweighted round of a D–G step comes within ``FIT_REWEIGHT_LEVEL`` of 1,
    the minimax starts from the round whose grid peak is lowest, not from the first
    (uniform weights). On the overhung compressor's second D–G–K step the first round's
    start ended at an H∞ level of 1.047 under SkylakeX kernels and 1.273 under Haswell,
    so μ was met on one and missed on the other; from the best round, 1.043 and 1.009,
    and both steps meet μ ≤ 1 (benchmarks/README.md, "The minimax from the best
    reweighted round"). Here: the spring–mass loop of an H∞ controller, its D–G step
    asked at 0.9 of the pointwise bound, so that every round peaks above 1."""
    from ambseal.robust import dgk
    from ambseal.robust.hinf import hinfsyn

    P = spring_mass_plant()
    K = hinfsyn(ct.ss(P.A, P.B[:, 2:], P.C[2:], P.D[2:, 2:]), 1, 1).K
    w = np.logspace(-2, 3, 27)
    mu_s = mussv(freqresp(lft_lower(P, K, 1, 1), w), SM_BLOCKS)
    rounds, refined = [], []

    class Seen(dgk.DGScalings):
        def sigma(self, x, M, wd):
            s = super().sigma(x, M, wd)
            rounds.append((self, float(s.max())))
            return s

    def refine(sc, *args):
        refined.append(sc)
        return sc.fits(sc.x0), float("nan")

    monkeypatch.setattr(dgk, "DGScalings", Seen)
    monkeypatch.setattr(dgk, "refine_scalings", refine)
    dgk._dg_step_scalings(P, K, 1, 1, mu_s, SM_REAL, 0.9 * float(mu_s.upper.max()), w, 0.05)
    peaks = [p for _, p in rounds]
    assert min(peaks) > 1 + dgk.FIT_REWEIGHT_LEVEL and len(refined) == 1
    best = int(np.argmin(peaks))
    assert best > 0 and refined[0] is rounds[best][0], peaks


def test_equal_sections_are_spread_before_a_continued_fit():
    """Two interchangeable sections of one function within SECTION_TIE in every coordinate
    (a point of symmetry of the fit, which rounding alone would decide to leave or not)
    get corners SECTION_TIE apart about their mean, the first below; sections that differ,
    and other functions' sections, are left as they are."""
    from ambseal.robust._dscale import SECTION_TIE, untied

    x = np.array([4.8076, 4.8081, 7.6, -1.9, 7.6 + 1e-4, -1.9, 3.0, 3.0])
    groups = [[[0], [1]], [[2, 3], [4, 5]], [[6]], [[7]]]
    y = untied(x, groups)
    assert y[0] == pytest.approx(4.80785 - SECTION_TIE / 2, abs=1e-12)
    assert y[1] == pytest.approx(4.80785 + SECTION_TIE / 2, abs=1e-12)
    assert y[2] == pytest.approx(7.60005 - SECTION_TIE / 2, abs=1e-12)
    assert y[4] == pytest.approx(7.60005 + SECTION_TIE / 2, abs=1e-12)
    assert y[3] == y[5] == -1.9 and np.array_equal(y[6:], x[6:])
    far = x.copy()
    far[1] = far[0] + 2 * SECTION_TIE
    far[3] = -1.8
    assert np.array_equal(untied(far, groups)[:6], far[:6])
