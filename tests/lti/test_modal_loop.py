"""Tests of ambseal.lti.modal_loop: the poles of loops closed around large plants from the
plant's modal form, against the dense eigenvalues of the same loops (with and without the
delay lag) on the default mesh and on 100 beam elements, and against the roots of the
characteristic equation ``det(I + K G) = 0`` by Newton with dense solves of the plant.

The dense QR eigenvalues are not exact: on the 100-element loop of the H∞ design a pair at
−311 ± 40j rad/s is 2.2e-6 (relative) from the roots, the modal poles 4e-9. So the dense
comparison allows 1e-5, and the roots decide where the two differ most."""

from __future__ import annotations

import control
import numpy as np
import pytest
from scipy.optimize import linear_sum_assignment

import ambseal.lti.modal_loop as ml
from ambseal.config import load_rig
from ambseal.lti import feedback_matrices, feedback_poles, series_inputs, zoh
from ambseal.lti.freqresp import modal_form
from ambseal.lti.memo import ArrayMemo
from ambseal.machine.loop import loop_matrices
from ambseal.model.rig import build_plant
from ambseal.robust.delay import loop_delay

from ..finemesh import fine_rig_text


@pytest.fixture(scope="module", params=["default", "100 elements"])
def plant(request, tmp_path_factory, testrig_cfg):
    """The rig's plant at its operating point, current inputs only (``control.StateSpace``)."""
    cfg = testrig_cfg
    if request.param != "default":
        rig = tmp_path_factory.mktemp("fine") / "fine100.toml"
        rig.write_text(fine_rig_text(100), encoding="utf-8")
        cfg = load_rig(rig)
    P = build_plant(cfg).select_inputs(
        [n for n in build_plant(cfg).input_names if n.startswith("i_")]).to_statespace()
    return P, cfg


#: the structured path's own choice of where it is cheaper, read before any test widens it
DEFAULT_FRACTION = ml._MAX_STRONG_FRACTION


@pytest.fixture(autouse=True)
def any_strong_part(monkeypatch):
    """The structured path at strong parts up to half the loop: its poles must be right
    whatever part it takes on (the default quarter, ``_MAX_STRONG_FRACTION``, is a choice
    of cost), and the default mesh's loops have strong parts of just over a quarter."""
    monkeypatch.setattr(ml, "_MAX_STRONG_FRACTION", 0.5)
    monkeypatch.setattr(ml, "_SOLVED", ArrayMemo())


def test_a_strong_part_over_a_quarter_of_the_loop_goes_dense(plant, testrig_designs,
                                                             monkeypatch):
    """At the default fraction a loop whose strong part (plant modes and controller) is
    more than a quarter of its order is left to the dense eigenvalues (``None``): the H∞
    loop on the default mesh, 88 of its 348 states; on 100 elements, 88 of 876, it is
    certified."""
    P, _ = plant
    G, K = loop_matrices(P, testrig_designs["hinf"].K)
    form = modal_form(*G[:3])
    monkeypatch.setattr(ml, "_MAX_STRONG_FRACTION", DEFAULT_FRACTION)
    poles = ml.modal_loop_poles(*form, K)
    assert (poles is None) == (P.nstates < 400)


def _mats(S):
    return tuple(np.asarray(getattr(S, m), float) for m in "ABCD")


def _pairs(p, ref):
    """(p, ref, relative distance) paired to minimise the distances."""
    assert p.size == ref.size
    D = np.abs(p[:, None] - ref[None, :])
    r, c = linear_sum_assignment(D)
    return p[r], ref[c], D[r, c] / np.maximum(np.abs(ref[c]), 1.0)


def _matched_error(p, ref):
    """Largest |p − ref| / max(|ref|, 1) over the pairing that minimises the distances."""
    return float(np.max(_pairs(p, ref)[2]))


@pytest.mark.parametrize("method", ["pid", "hinf", "mu"])
def test_loop_poles_equal_the_dense_eigenvalues(plant, testrig_designs, method):
    """Each design closed on the plant, without and with the delay lag: certified (not
    ``None``), every pole within 1e-5 of the dense eigenvalues (pole by pole, relative to
    max(|p|, 1 rad/s): the dense ones' own error, module docstring); the PID has a
    feedthrough, the H∞ and μ controllers none."""
    P, cfg = plant
    G, K = loop_matrices(P, testrig_designs[method].K)
    form = modal_form(*G[:3])
    assert form is not None
    poles = ml.modal_loop_poles(*form, K)
    assert poles is not None
    assert _matched_error(poles, np.linalg.eigvals(feedback_matrices(G, K)[0])) < 1e-5
    lag = _mats(loop_delay(cfg.controller.sample_rate_hz, cfg.controller.delay_samples).system)
    delayed = series_inputs(G, lag)[:4]
    ref = np.linalg.eigvals(feedback_matrices(delayed, K)[0])
    assert _matched_error(feedback_poles(G, K, lag=lag, dt=0.0), ref) < 1e-5


def test_sampled_loop_poles_equal_the_dense_eigenvalues(plant, testrig_digital):
    """The plant sampled by a zero-order hold in modal form (``z = e^{λT}``, rows of
    ``V⁻¹B`` times ``(e^{λT} − 1)/λ``) closed with the digital controller (its computation
    delay among its states): certified, within 1e-5 of the dense eigenvalues of ``expm``'s
    sampled loop, the boundary the circle ``|z| = ρ``."""
    P, _ = plant
    Kd = testrig_digital["hinf"].statespace(delayed=True)
    T = float(Kd.dt)
    G, K = loop_matrices(P, control.ss(Kd.A, Kd.B, Kd.C, Kd.D, inputs=Kd.input_labels,
                                       outputs=Kd.output_labels))
    lam, Bm, Cm = modal_form(*G[:3])
    poles = ml.modal_loop_poles(np.exp(lam * T), Bm * (np.expm1(lam * T) / lam)[:, None], Cm, K,
                                discrete=True)
    assert poles is not None
    Ad, Bd = zoh(G[0], G[1], T)
    ref = np.linalg.eigvals(feedback_matrices((Ad, Bd, G[2], G[3]), K)[0])
    assert _matched_error(poles, ref) < 1e-5


@pytest.mark.parametrize("method", ["hinf", pytest.param("mu", marks=pytest.mark.slow)])
def test_poles_solve_the_characteristic_equation(plant, testrig_designs, method):
    """The eight poles where the modal and the dense eigenvalues differ most, refined by
    Newton's method on ``det(I + K(s) G(s))`` with ``G(s)`` by dense LU solves of the
    plant: each modal pole is within 1e-7 (relative) of its root and no farther from it
    than the dense eigenvalue."""
    P, _ = plant
    G, K = loop_matrices(P, testrig_designs[method].K)
    A, B, C, _ = G
    Ak, Bk, Ck, Dk = K
    modal, dense, rel = _pairs(ml.modal_loop_poles(*modal_form(A, B, C), K),
                               np.linalg.eigvals(feedback_matrices(G, K)[0]))

    def f(s):
        Gs = C @ np.linalg.solve(s * np.eye(A.shape[0]) - A, B)
        Ks = Ck @ np.linalg.solve(s * np.eye(Ak.shape[0]) - Ak, Bk) + Dk
        return np.linalg.det(np.eye(B.shape[1]) + Ks @ Gs)

    for k in np.argsort(-rel)[:8]:
        r = modal[k]
        for _ in range(4):
            h = 1e-7 * abs(r)
            r = r - f(r) / ((f(r + h) - f(r - h)) / (2 * h))
        assert abs(modal[k] - r) <= max(1e-7 * abs(r), abs(dense[k] - r))
        assert abs(modal[k] - r) <= 1e-7 * abs(r)


def test_a_lost_pole_is_not_certified(plant, testrig_designs, monkeypatch):
    """A strong pole replaced by a copy of another (what a wrong cluster matching would
    give) breaks the trace identity: the result is refused, not returned."""
    P, _ = plant
    G, K = loop_matrices(P, testrig_designs["hinf"].K)
    form = modal_form(*G[:3])
    refine = ml._StrongPart.refine

    def lossy(self, *args):
        p = refine(self, *args)
        k = int(np.argmin(np.abs(p)))
        p = p.copy()
        p[k] = p[np.argsort(np.abs(p))[-1]]
        return p

    assert ml.modal_loop_poles(*form, K) is not None
    monkeypatch.setattr(ml._StrongPart, "refine", lossy)
    monkeypatch.setattr(ml, "_SOLVED", ArrayMemo())  # not the split kept from above
    assert ml.modal_loop_poles(*form, K) is None


def test_a_bound_no_band_proves_gives_up_within_a_dense_eigenvalue_problems_work(
        plant, testrig_designs, monkeypatch):
    """A small-gain bound that no bisection proves (as when a weak mode sits close to a
    strong pole) ends the certificate, ``None``, once its bands have cost about what the
    dense eigenvalues of the loop cost (Golub & Van Loan §7.5.6: ~10 N³ flops, N states):
    every band and point of the bound counted, at most N³ band points (~40 flops each),
    where bisecting each band 17 times evaluated 512·(2¹⁸ − 1) bands, 10⁴–10⁵ times more."""
    P, _ = plant
    G, K = loop_matrices(P, testrig_designs["hinf"].K)
    form = modal_form(*G[:3])
    n = form[0].size + K[0].shape[0]
    spent = []

    def never(lo, hi, boundary, mu, terms, heads, dq, lamT, aT):
        rays = np.isinf(lo) | np.isinf(hi)  # the line's two ends proved: the bands are not
        spent.append(np.count_nonzero(~rays) * (lamT.size + mu.size * len(terms)))
        return rays

    monkeypatch.setattr(ml, "_bands_ok", never)
    monkeypatch.setattr(ml, "_SOLVED", ArrayMemo())
    assert ml.modal_loop_poles(*form, K) is None
    assert spent and sum(spent) <= n**3


def test_nearest_subspace_is_the_invariant_subspace_of_the_nearest_eigenvalues():
    """Reference: a matrix built from known eigenvectors and eigenvalues — a pair 1e-9
    apart (two planes nearly symmetric), others far — scaled over six decades as a strong
    part is, and balanced as strong_block balances it. The inverse iteration's basis spans
    the known eigenvectors of the pair (its largest principal angle to them at rounding,
    1.4e-13; eig's 1.6e-13), of a single eigenvalue too; a shift exactly on an eigenvalue
    of a diagonal matrix (``S − pI`` singular) still gives that eigenvalue's vector."""
    import scipy.linalg

    rng = np.random.default_rng(11)
    n = 40
    lam = rng.standard_normal(n) * 50 + 1j * rng.uniform(1, 1e3, n)
    lam[1] = lam[0] + 1e-9 * abs(lam[0])
    V = np.diag(np.geomspace(1, 1e6, n)) @ (np.eye(n) + 0.3 * rng.standard_normal((n, n)))
    S, (sc, _) = scipy.linalg.matrix_balance(V @ np.diag(lam) @ np.linalg.inv(V),
                                             permute=False, separate=True)
    V = V / sc[:, None]
    for idx in ([0, 1], [5]):
        X = ml._nearest_subspace(S, complex(np.mean(lam[idx])), len(idx))
        assert np.max(scipy.linalg.subspace_angles(X, V[:, idx])) < 1e-11
    D = np.diag(np.arange(1.0, 7.0)) + 0j
    X = ml._nearest_subspace(D, 3.0, 1)
    assert np.allclose(np.abs(X[:, 0]), np.eye(6)[2])
