"""Tests of ambseal.identify.fitting.youla: the Youla/dual-Youla (Hansen) identification of thesis P1 §II.

The P1 case (§IV): a 50 % change of one AMB's negative stiffness in one direction (here
``B.Ks_eta`` of the embedded test rig, reduced plant with amplifiers, 0 rpm, no seal
pressure), a PRBS η for 0.5 s at 1 kHz, r1 = r2 = 0; P1 found θ = 0.502 for a true 0.5.

The records are made by :func:`_true_loop`, a plain sample-by-sample loop written here: the
*true* plant (``Plant.with_changes``, sampled with its own expm-based ZOH) in closed loop with
the digital observer-based controller (P1's "standard observer based feedback structure")
with η injected at the Youla point u_c = F x̂ + η of Fig. 2. It shares only the gains F, L
and the nominal sampled matrices with the code under test (they *are* the controller that
ran), none of its signal or S(θ) code.
"""

from __future__ import annotations

import dataclasses
import json

import control
import numpy as np
import pytest
import scipy.linalg as sla

from ambseal.config import load_rig
from ambseal.errors import DataError, IdentificationError
from ambseal.identify.excitation.signals import prbs
from ambseal.identify.fitting.youla import (
    CoprimeFactors,
    check_bezout,
    coprime_factors,
    dual_youla,
    identify_youla,
    observer_gains,
    youla_factorisation,
    youla_signals,
)
from ambseal.model.rig import build_plant

DT = 1e-3  # P1 §IV: time step 0.001 s
PARAM = "B.Ks_eta"
ALPHA = 800.0  # rad/s, prescribed degree of stability of the observer-based controller
NOISE_RATIO = 1e-2


@pytest.fixture(scope="module")
def plant():
    return build_plant(load_rig(), reduced=True, speed_rpm=0.0, pressure_bar=0.0)


@pytest.fixture(scope="module")
def cf(plant):
    return youla_factorisation(plant, dt=DT, stability_degree=ALPHA, noise_ratio=NOISE_RATIO)


@pytest.fixture(scope="module")
def cfc(plant):
    return youla_factorisation(plant, stability_degree=ALPHA, noise_ratio=NOISE_RATIO)


@pytest.fixture(scope="module")
def eta():
    """P1 §IV: a random binary η for 0.5 s at 1 kHz, independent on each of the 4 axes."""
    return prbs(amplitude_a=0.1, clock_period_s=DT, duration_s=0.5, sample_rate_hz=1 / DT,
                seed=3).values_a


def _expm_zoh(A, B, T):
    n, m = B.shape
    E = np.zeros((n + m, n + m))
    E[:n, :n], E[:n, n:] = A * T, B * T
    E = sla.expm(E)
    return E[:n, :n], E[:n, n:]


def _true_loop(plant, cf, theta, eta, noise=None, r1=None, r2=None, changes=None):
    """The true digital closed loop of P1 Fig. 2, sample by sample, from rest.

    Plant G(θ) sampled with a ZOH; controller x̂⁺ = A x̂ + B u_c − L(y_c − C x̂ − D u_c),
    u_c = F x̂ + η; y_c = y + r1 (r1 and the sensor noise both reach the controller),
    u = u_c + r2. θ is the normalised change of ``PARAM``, or ``changes`` (SI) any others.
    Returns the recorded (y_meas, u) with y_meas = y + noise.
    """
    if changes is None:
        changes = {PARAM: theta * plant.parameter(PARAM).nominal}
    pt = plant.with_changes(changes)
    Ad, Bd = _expm_zoh(pt.A, pt.B, DT)
    N, m = eta.shape
    p = pt.C.shape[0]
    zero_p, zero_m = np.zeros((N, p)), np.zeros((N, m))
    noise = zero_p if noise is None else noise
    r1 = zero_p if r1 is None else r1
    r2 = zero_m if r2 is None else r2
    x, xh = np.zeros(Ad.shape[0]), np.zeros(cf.n_states)
    Y, U = np.zeros((N, p)), np.zeros((N, m))
    for k in range(N):
        y = pt.C @ x + noise[k]
        uc = cf.F @ xh + eta[k]
        u = uc + r2[k]
        yc = y + r1[k]
        xh = cf.A @ xh + cf.B @ uc - cf.L @ (yc - cf.C @ xh - cf.D @ uc)
        x = Ad @ x + Bd @ u
        Y[k], U[k] = y, u
    return Y, U


def _fr_solve(sys, pts):
    """Frequency response (nf, p, m) as C (sI − A)⁻¹ B + D by a dense solve per point."""
    A, B, C, D = (np.asarray(X, complex) for X in (sys.A, sys.B, sys.C, sys.D))
    eye = np.eye(A.shape[0])
    return np.stack([C @ np.linalg.solve(s * eye - A, B) + D for s in pts])


def _fr(sys, pts):
    """Frequency response (nf, p, m) of a control.StateSpace at complex points."""
    return np.stack([np.atleast_2d(sys(s)) for s in pts])


# --------------------------------------------------------------------------- factors
def test_bezout_identity_holds_discrete_and_continuous(cf, cfc):
    """Reference: P1 Eq. 3 (double Bezout identity) — [[Ṽ, −Ũ], [−Ñ, M̃]]·[[M, U], [N, V]] = I
    and the reverse product, each of the eight factors evaluated here on its own as
    C (sI − A)⁻¹ B + D by a plain dense solve (python-control's ``sys(s)`` loses ~5 digits
    on these stiff realisations, see below) at 30 points and assembled here, in balanced
    units (outputs scaled by ``output_scale``) to 1e-9; the module's own measure
    bezout_error() agrees (Zhou, Doyle & Glover 1996 Thm 5.9 for the observer-based
    formulas). All eight factors are stable (in RH∞), by python-control poles."""
    for f in (cf, cfc):
        pts = (np.exp(1j * np.linspace(0.01, 0.99 * np.pi, 30)) if f.dt
               else 1j * np.logspace(0, 4, 30))
        M, N, U, V = (_fr_solve(x, pts) for x in (f.M(), f.N(), f.U(), f.V()))
        Vt, Ut, Nt, Mt = (_fr_solve(x, pts) for x in (f.V_tilde(), f.U_tilde(), f.N_tilde(),
                                                       f.M_tilde()))
        Lm = np.concatenate([np.concatenate([Vt, -Ut], 2), np.concatenate([-Nt, Mt], 2)], 1)
        Rm = np.concatenate([np.concatenate([M, U], 2), np.concatenate([N, V], 2)], 1)
        m, p = M.shape[2], N.shape[1]
        t = np.concatenate([np.ones(m), np.full(p, f.output_scale)])
        eye = np.eye(m + p)
        for prod in (Lm @ Rm, Rm @ Lm):
            err = np.abs((prod - eye) * t[None, None, :] / t[None, :, None]).max()
            assert err < 1e-9
        assert f.bezout_error() < 1e-9
        for sys in (f.M(), f.N(), f.U(), f.V(), f.M_tilde(), f.N_tilde(), f.U_tilde(),
                    f.V_tilde()):
            pl = control.poles(sys)
            assert (np.abs(pl).max() < 1) if f.dt else (pl.real.max() < 0)


def test_factors_reproduce_plant_and_controller(cf, plant):
    """Reference: P1 Eqs. 1–2, G = N M⁻¹ = M̃⁻¹ Ñ and K = U V⁻¹ = Ṽ⁻¹ Ũ, against python-control
    run side by side: its ZOH sampling of the plant (control.c2d) and its evaluation of the
    controller's own state space, at 40 frequencies up to Nyquist."""
    pts = np.exp(1j * np.linspace(0.01, 0.99 * np.pi, 40))
    G = _fr(control.c2d(plant.to_statespace(), DT, "zoh"), pts)
    K = _fr(cf.controller(), pts)
    M, N, U, V = (_fr(s, pts) for s in (cf.M(), cf.N(), cf.U(), cf.V()))
    Mt, Nt, Ut, Vt = (_fr(s, pts) for s in (cf.M_tilde(), cf.N_tilde(), cf.U_tilde(),
                                            cf.V_tilde()))
    scale = np.abs(G).max()
    assert np.abs(N @ np.linalg.inv(M) - G).max() < 1e-8 * scale
    assert np.abs(np.linalg.solve(Mt, Nt) - G).max() < 1e-8 * scale
    # K's own realisation is badly conditioned (cond(zI − A_K) ~ 1e10 in modal
    # coordinates), so python-control's evaluation of it is good to ~1e-6 only
    kscale = np.abs(K).max()
    assert np.abs(U @ np.linalg.inv(V) - K).max() < 1e-5 * kscale
    assert np.abs(np.linalg.solve(Vt, Ut) - K).max() < 1e-5 * kscale
    # the project's negative-feedback form is −K
    Kn = _fr(cf.controller("negative"), pts)
    assert np.allclose(Kn, -K, rtol=0, atol=1e-12 * kscale)


def test_controller_stabilises_nominal_and_true_plant(cf, plant):
    """Reference: P1 §II — K must stabilise both G(0) and G(θ); closed-loop poles of the
    sampled loop (python-control feedback, positive sign as in Zhou/P1) inside the unit disc
    for θ = 0 and the P1 case θ = 0.5."""
    nom = plant.parameter(PARAM).nominal
    for theta in (0.0, 0.5):
        G = control.c2d(plant.with_changes({PARAM: theta * nom}).to_statespace(), DT, "zoh")
        cl = control.feedback(G, cf.controller(), sign=+1)
        assert np.abs(control.poles(cl)).max() < 0.99


def test_bezout_check_catches_a_wrong_factor(cf):
    """Reference: P1 Eq. 3 — flipping the sign of Ũ (the usual positive/negative-feedback
    slip) must break the identity and raise IdentificationError; unstable F is refused."""

    class Flipped(CoprimeFactors):
        def U_tilde(self):
            return -super().U_tilde()

    bad = Flipped(**{f.name: getattr(cf, f.name) for f in dataclasses.fields(cf)})
    with pytest.raises(IdentificationError, match="Bezout"):
        check_bezout(bad)
    with pytest.raises(IdentificationError, match="A \\+ BF"):
        coprime_factors(cf.A, cf.B, cf.C, cf.D, np.zeros_like(cf.F), cf.L, dt=DT)


def test_observer_gains_small_example():
    """Reference: closed form — for the unstable 1-DOF magnet ẍ = 100 x + u, y = x, any
    stabilising F, L give A + BF, A + LC Hurwitz; with a prescribed degree of stability α
    the poles lie left of −α (Anderson & Moore 1990 §3.5)."""
    A = np.array([[0.0, 1.0], [100.0, 0.0]])
    B = np.array([[0.0], [1.0]])
    C = np.array([[1.0, 0.0]])
    F, L = observer_gains(A, B, C, stability_degree=20.0)
    assert np.linalg.eigvals(A + B @ F).real.max() < -20.0
    assert np.linalg.eigvals(A + L @ C).real.max() < -20.0
    Fd, Ld = observer_gains(*_expm_zoh(A, B, 1e-2), C, dt=1e-2, stability_degree=20.0)
    Ad, Bd = _expm_zoh(A, B, 1e-2)
    assert np.abs(np.linalg.eigvals(Ad + Bd @ Fd)).max() < np.exp(-20.0 * 1e-2)
    assert np.abs(np.linalg.eigvals(Ad + Ld @ C)).max() < np.exp(-20.0 * 1e-2)


# --------------------------------------------------------------------------- S(θ)
@pytest.mark.parametrize("discrete", [True, False])
def test_dual_youla_eq13_matches_hansen_parametrisation(plant, cf, cfc, discrete):
    """Reference: P1 Eqs. 9–11 — the plant stabilised by K is G(S) = (N + V S)(M + U S)⁻¹
    (the y and u rows of Eq. 11 for input η); with S(θ) from Eq. 13 this must reproduce the
    true plant G(θ) (python-control's c2d of Plant.with_changes in discrete time); S(0) = 0."""
    f = cf if discrete else cfc
    nom = plant.parameter(PARAM).nominal
    Gt = plant.with_changes({PARAM: 0.5 * nom}).to_statespace()
    if discrete:
        Gt = control.c2d(Gt, DT, "zoh")
        pts = np.exp(1j * np.linspace(0.01, 0.99 * np.pi, 30))
    else:
        pts = 1j * np.logspace(0, 4, 30)
    S = dual_youla(f, plant, {PARAM: 0.5 * nom})
    Sf = _fr(S, pts)
    M, N, U, V = (_fr(s, pts) for s in (f.M(), f.N(), f.U(), f.V()))
    GS = (N + V @ Sf) @ np.linalg.inv(M + U @ Sf)
    G = _fr(Gt, pts)
    # continuous: the stiff modal realisation (actuator ω² ~ 1.8e6 next to O(1) entries)
    # costs digits; two evaluations of the same S(θ) realisation (python-control's and a
    # plain solve) already differ by 3e-7 there
    tol = 1e-7 if discrete else 2e-6
    assert np.abs(GS - G).max() < tol * np.abs(G).max()
    assert np.abs(Sf).max() > 1e-3 * np.abs(N).max()  # not trivially zero
    S0 = dual_youla(f, plant, {PARAM: 0.0})
    # zero up to the round-off of evaluating the non-minimal [x; x̂] realisation
    assert np.abs(_fr(S0, pts)).max() < 1e-6 * np.abs(N).max()


def test_s_theta_stable_although_true_plant_unstable(plant, cfc):
    """Reference: P1 §IV Figs. 6–7 — G(θ) has right-half-plane poles, S(θ) has none (K
    stabilises G(θ)), so S(θ) can be identified open loop."""
    nom = plant.parameter(PARAM).nominal
    Gt = plant.with_changes({PARAM: 0.5 * nom})
    assert np.linalg.eigvals(Gt.A).real.max() > 100.0
    S = dual_youla(cfc, plant, {PARAM: 0.5 * nom})
    assert control.poles(S).real.max() < 0.0


# --------------------------------------------------------------------------- signals
def test_signals_recover_eta_and_vanish_for_the_nominal_plant(plant, cf, eta):
    """Reference: P1 Eqs. 8 and 10–11 with S = 0 — when the true plant is the nominal one,
    ε ≡ 0, and η computed from (u, y) equals the injected PRBS."""
    Y, U = _true_loop(plant, cf, 0.0, eta)
    eta_hat, eps = youla_signals(cf, U, Y)
    assert np.abs(eta_hat - eta).max() < 1e-9 * np.abs(eta).max()
    assert np.abs(eps).max() < 1e-9 * np.abs(Y).max()


def test_signals_follow_eq11_with_r1_r2(plant, cf, eta):
    """Reference: P1 Eq. 11 — its y and u rows carry (N + VS)·[Ũ Ṽ 1] and (M + US)·[Ũ Ṽ 1]
    for [r1; r2; η]; the same algebra (ξ = η + Ũ r1 + Ṽ r2, ε = S ξ + M̃ r1 + Ñ r2) gives
    the ε row ε = (M̃ + S Ũ) r1 + (Ñ + S Ṽ) r2 + S η. (P1 prints Ṽ and Ũ swapped in that
    row, which does not even conform in dimension when m ≠ p.) The right side is built from
    the factors by python-control interconnection and simulated with control.forced_response,
    the left side comes from the simulated true loop."""
    nom = plant.parameter(PARAM).nominal
    rng = np.random.default_rng(7)
    N = eta.shape[0]
    r1 = 2e-7 * rng.standard_normal((N, 4))
    r2 = 0.05 * rng.standard_normal((N, 4))
    Y, U = _true_loop(plant, cf, 0.5, eta, r1=r1, r2=r2)
    eta_hat, eps = youla_signals(cf, U, Y, r1=r1, r2=r2)
    S = dual_youla(cf, plant, {PARAM: 0.5 * nom})
    S = control.ss(S.A, S.B, S.C, S.D, DT)
    T1 = control.parallel(cf.M_tilde(), control.series(cf.U_tilde(), S))
    T2 = control.parallel(cf.N_tilde(), control.series(cf.V_tilde(), S))
    t = np.arange(N) * DT

    def run(sys, w):
        return control.forced_response(sys, t, w.T).outputs.T

    expected = run(T1, r1) + run(T2, r2) + run(S, eta)
    assert np.abs(eps - expected).max() < 1e-8 * np.abs(eps).max()
    assert np.abs(eta_hat - eta).max() < 1e-9


# --------------------------------------------------------------------------- P1 case
def test_p1_case_identifies_theta_half_noise_free(plant, cf, eta):
    """Reference: P1 §IV — 50 % change of one bearing's Ks in one direction, PRBS η for
    0.5 s at 1 kHz, r1 = r2 = 0: P1 identified θ = 0.502 for 0.5. With the exact sampled-data
    S(θ) we must do at least as well (P1's |θ̂ − 0.5| = 0.002; here to round-off, 1e-6),
    with η recovered from the record to 1e-9 and a fit of the ε record above 99.9 %."""
    Y, U = _true_loop(plant, cf, 0.5, eta)
    res = identify_youla(cf, plant, [PARAM], u=U, y=Y, eta=eta)
    assert res.converged  # least squares succeeded and the spectral radius is below 1
    assert abs(res.theta_of(PARAM) - 0.5) < 1e-6
    nom = plant.parameter(PARAM).nominal
    assert res.change[0] == pytest.approx(0.5 * nom, rel=1e-6)
    assert res.value[0] == pytest.approx(1.5 * nom, rel=1e-6)
    assert res.eta_mismatch < 1e-9 and res.fit_pct > 99.9
    d = json.loads(json.dumps(res.to_dict()))
    assert d["parameters"][PARAM]["theta"] == pytest.approx(0.5, abs=1e-6)
    # η recovered from the record instead of given: the same answer
    res2 = identify_youla(cf, plant, [PARAM], u=U, y=Y)
    assert abs(res2.theta_of(PARAM) - 0.5) < 1e-6


def test_p1_case_with_measurement_noise(plant, cf, eta):
    """Reference: P1 Eq. 14 — sensor noise enters ε like r1, uncorrelated with η, so the
    estimate stays unbiased: white noise of 1 % of the displacement rms on every sensor
    (seeded; over 20 seeds the spread of θ̂ is 0.004) keeps |θ̂ − 0.5| ≤ 0.02, inside
    4 reported standard errors."""
    Y0, _ = _true_loop(plant, cf, 0.5, eta)
    rng = np.random.default_rng(1)
    noise = 0.01 * Y0.std() * rng.standard_normal(Y0.shape)
    Y, U = _true_loop(plant, cf, 0.5, eta, noise=noise)
    res = identify_youla(cf, plant, [PARAM], u=U, y=Y, eta=eta)
    assert res.converged
    err = abs(res.theta_of(PARAM) - 0.5)
    assert err <= 0.02
    assert err <= 4 * res.theta_std[0]


def test_two_parameters_other_bearing(plant, cf, eta):
    """Reference: P1 §V (several parameters at once, suggested there) — changes of −30 % on
    A.Ks_zeta and +20 % on B.Ks_eta identified together from one noise-free record."""
    pa, pb = plant.parameter("A.Ks_zeta"), plant.parameter(PARAM)
    changes = {"A.Ks_zeta": -0.3 * pa.nominal, PARAM: 0.2 * pb.nominal}
    Y, U = _true_loop(plant, cf, None, eta, changes=changes)
    res = identify_youla(cf, plant, ["A.Ks_zeta", PARAM], u=U, y=Y, eta=eta)
    assert np.allclose(res.theta, [-0.3, 0.2], atol=1e-6)


# --------------------------------------------------------------------------- errors
def test_errors(plant, cf, cfc, eta):
    """Reference: DESIGN.md errors — the project's own exceptions with what was expected."""
    Y, U = _true_loop(plant, cf, 0.0, eta[:50])
    with pytest.raises(IdentificationError, match="discrete"):
        youla_signals(cfc, U, Y)
    with pytest.raises(DataError, match="y"):
        youla_signals(cf, U, Y[:, :3])
    with pytest.raises(DataError, match="NaN"):
        youla_signals(cf, U, np.where(Y == Y[3, 0], np.nan, Y))
    with pytest.raises(IdentificationError, match="scale"):
        identify_youla(cf, plant, ["coupling.kxy"], u=U, y=Y)  # nominal 0: needs scales=
    other = build_plant(load_rig(), reduced=True, speed_rpm=3000.0, pressure_bar=0.0)
    with pytest.raises(IdentificationError, match="not those of this plant"):
        identify_youla(cf, other, [PARAM], u=U, y=Y)
