"""The lowest-modes path ``modes(sys, n_modes=n)`` (shift-invert ARPACK) against a dense
``scipy.linalg.eig`` of the same pencil, on the embedded test rig and the turboexpander,
supported and free–free, at standstill and at speed."""

from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest
import scipy.linalg as sla

from ambseal.config import default_rig_path, load_rig
from ambseal.errors import ModelError
from ambseal.model import modes as modes_mod
from ambseal.model.modes import lowest_eigenvalues, modes
from ambseal.model.rig import build_system

TURBO = Path(__file__).resolve().parents[2] / "examples" / "turboexpander.toml"
N = 8
FREE = {"include_amb": False, "include_seals": False, "include_springs": False}
# The sparse path's contract: the modes asked for equal the dense ones "to ~1e-8 relative".
RTOL = 1e-8


@pytest.fixture(scope="module")
def rigs():
    return {"testrig": load_rig(default_rig_path()), "turbo": load_rig(TURBO)}


def dense_eigenvalues(sys) -> np.ndarray:
    """Reference: every eigenvalue of the first-order form, dense (LAPACK geev, balanced),
    built here from M, C, G, K independently of ``SecondOrderSystem.poles``."""
    n = sys.n_dof
    D = sys.C + sys.speed * sys.G
    A = np.block([[np.zeros((n, n)), np.eye(n)],
                  [-np.linalg.solve(sys.M, sys.K), -np.linalg.solve(sys.M, D)]])
    lam = sla.eigvals(A)
    return lam[np.argsort(np.abs(lam), kind="stable")]


def lowest_oscillating(lam: np.ndarray, n: int, rigid: float) -> np.ndarray:
    """The ``n`` eigenvalues with Im λ > 0 of smallest |λ|, rigid-body ones (|λ| < rigid)
    left out, then sorted by Im λ (the order of ``Modes``)."""
    osc = lam[(lam.imag > rigid) & (np.abs(lam) >= rigid)]
    osc = osc[np.argsort(np.abs(osc), kind="stable")][:n]
    return osc[np.argsort(osc.imag)]


def backward_error_and_condition(sys, lam: complex) -> tuple[float, float]:
    """η and κ of λ as an eigenvalue of Q(λ) = λ²M + λD + K (Tisseur, "Backward error and
    condition of polynomial eigenvalue problems", Linear Algebra Appl. 309 (2000)), with
    s = |λ|²‖M‖ + |λ|‖D‖ + ‖K‖: the normwise backward error η = σ_min(Q(λ))/s and the
    relative condition number κ = s ‖x‖‖y‖/(|λ| |y* Q'(λ) x|), x, y the right and left
    null vectors of Q(λ) (its last singular vectors)."""
    D = sys.C + sys.speed * sys.G
    norms = [np.linalg.norm(X, 2) for X in (sys.M, D, sys.K)]
    s = abs(lam) ** 2 * norms[0] + abs(lam) * norms[1] + norms[2]
    U, sv, Vh = np.linalg.svd(lam**2 * sys.M + lam * D + sys.K)
    x, y = Vh[-1].conj(), U[:, -1]
    return float(sv[-1] / s), float(s / (abs(lam) * abs(y.conj() @ (2 * lam * sys.M + D) @ x)))


def assert_same_eigenvalues(sys, lam: np.ndarray, ref: np.ndarray) -> None:
    """Each λ is an eigenvalue to the accuracy the shift rule promises, and agrees with the
    dense one to 1e-8 relative or, for an ill-conditioned eigenvalue, to the first-order
    perturbation bound κ(λ)·η (Tisseur 2000) that two backward-stable solvers meet.

    The backward error bound u·10⁶ follows from ``lowest_eigenvalues``'s shift: the shifted
    dynamic stiffness has a condition number near (ω_ref/σ)² = 10⁶.
    """
    u = np.finfo(float).eps
    for a, b in zip(lam, ref):
        eta, _ = backward_error_and_condition(sys, a)
        assert eta < 1e6 * u, (a, eta)
        eta_ref, kappa = backward_error_and_condition(sys, b)
        rel = abs(a - b) / abs(b)
        assert rel <= max(RTOL, 10 * kappa * max(eta, eta_ref)), (a, b, rel, kappa)


CASES = [
    ("testrig", {"speed_rpm": 0.0}),
    ("testrig", {"speed_rpm": 6000.0}),
    ("testrig", {"speed_rpm": 0.0, **FREE}),
    ("testrig", {"speed_rpm": 6000.0, **FREE}),
    ("turbo", {"speed_rpm": 0.0}),
    ("turbo", {}),  # [operating] speed_rpm = 8400
    ("turbo", {"speed_rpm": 0.0, **FREE}),
    ("turbo", {**FREE}),
]


@pytest.mark.parametrize("name, kw", CASES)
def test_lowest_modes_equal_dense(rigs, name, kw):
    """Reference: dense eig of the same pencil. The n lowest oscillating modes (by |λ|)
    are the same eigenvalues (``assert_same_eigenvalues``: 1e-8 relative unless
    ill-conditioned), hence the same frequencies and damping ratios; both twins of a
    double eigenvalue (axisymmetric rotor at standstill) are found; the rigid-body modes
    of the free–free rotor are left out."""
    sys = build_system(rigs[name], **kw)
    lam_ref = dense_eigenvalues(sys)
    rigid = 1e-6 * np.abs(lam_ref).max()
    ref = lowest_oscillating(lam_ref, N, rigid)
    res = modes(sys, n_modes=N)

    assert len(res.natural_frequencies_hz) == N
    w = 2 * np.pi * np.asarray(res.natural_frequencies_hz)
    zeta = np.asarray(res.damping_ratios)
    lam = -zeta * w / np.sqrt(1 - zeta**2) + 1j * w
    assert_same_eigenvalues(sys, lam, ref)
    if kw.get("include_amb") is False:
        assert w.min() > 1.0  # the rigid-body modes at 0 are not modes


@pytest.mark.parametrize("name, kw", [("testrig", {}), ("turbo", {}), ("turbo", FREE)])
def test_poles_and_unstable_match_dense(rigs, name, kw):
    """Reference: dense eig. ``poles`` holds every dense eigenvalue up to the n-th mode's
    |λ| (none missed, none extra) and ``unstable_poles`` are the dense unstable poles
    among them (the AMB rotors are open-loop unstable, P1 §III); the dense path's
    ``modes(sys)`` lists the same lowest frequencies (lightly damped modes)."""
    sys = build_system(rigs[name], **kw)
    lam_ref = dense_eigenvalues(sys)
    res = modes(sys, n_modes=N)
    cut = np.abs(res.poles).max()
    inside = lam_ref[np.abs(lam_ref) <= cut * (1 + 1e-9)]
    assert len(res.poles) == len(inside)
    flexible = res.poles[np.abs(res.poles) > 1.0]  # rigid-body ones are defective zeros
    nearest = inside[np.abs(inside[:, None] - flexible[None, :]).argmin(axis=0)]
    assert_same_eigenvalues(sys, flexible, nearest)
    dense = modes(sys)
    np.testing.assert_allclose(res.natural_frequencies_hz, dense.natural_frequencies_hz[:N],
                               rtol=RTOL)
    want = [p for p in dense.unstable_poles if abs(complex(*p)) <= cut * (1 + 1e-9)]
    assert len(res.unstable_poles) == len(want)
    np.testing.assert_allclose(sorted(res.unstable_poles), sorted(want), rtol=RTOL)
    if name != "turbo" or kw:
        return
    assert res.unstable_poles  # the turboexpander's AMB rotor is open-loop unstable


def test_sparse_lu_branch_undamped_rotor(rigs, monkeypatch):
    """Reference: dense eig. Without modal damping the dynamic stiffness is banded and
    factored by the sparse LU; forcing the dense LU gives the same modes (both against
    dense eig to 1e-8)."""
    cfg = rigs["testrig"]
    cfg = cfg.model_copy(update={"rotor": cfg.rotor.model_copy(update={"modal_damping": 0.0})})
    sys = build_system(cfg, speed_rpm=3000.0)
    Z = sys.K + sys.M
    assert np.count_nonzero(Z) < modes_mod.SPARSE_FILL * Z.size  # the sparse branch runs
    ref = lowest_oscillating(dense_eigenvalues(sys), N, 1e-6)
    sparse_lu = np.asarray(modes(sys, n_modes=N).natural_frequencies_hz)
    monkeypatch.setattr(modes_mod, "SPARSE_FILL", 0.0)
    dense_lu = np.asarray(modes(sys, n_modes=N).natural_frequencies_hz)
    np.testing.assert_allclose(2 * np.pi * sparse_lu, ref.imag, rtol=RTOL)
    np.testing.assert_allclose(2 * np.pi * dense_lu, ref.imag, rtol=RTOL)


def test_many_modes_fall_back_to_dense(rigs):
    """Reference: the dense path. Asking for more modes than ARPACK can give (k ≥ n_state
    − 1) returns the dense result itself, every oscillating mode."""
    sys = build_system(rigs["turbo"], **FREE)
    res = modes(sys, n_modes=sys.n_dof)
    dense = modes(sys)
    assert res.natural_frequencies_hz == dense.natural_frequencies_hz
    lam, _ = lowest_eigenvalues(sys, sys.n_dof)
    assert len(lam) == 2 * sys.n_dof


def test_bad_requests(rigs):
    """n_modes must be a positive integer, and M positive definite (as in the dense path)."""
    sys = build_system(rigs["turbo"])
    for bad in (0, -1, 2.5):
        with pytest.raises(ModelError, match="n_modes"):
            modes(sys, n_modes=bad)
    with pytest.raises(ModelError, match="positive definite"):
        modes(replace(sys, M=-sys.M), n_modes=N)


@pytest.mark.parametrize("name, kw", [("testrig", {}), ("testrig", {"speed_rpm": 6000.0}),
                                      ("turbo", {}), ("turbo", FREE)])
def test_poles_near_zero_sparse_equal_dense(rigs, monkeypatch, name, kw):
    """Reference: dense eig. ``poles_near_zero`` on its shift-invert path (forced on these
    small models) returns exactly the dense eigenvalues inside its disk — none missed,
    none extra, the same to the accuracy of ``assert_same_eigenvalues`` — with at least
    the count, radius and oscillating modes asked for, and each shape q is a null vector
    of Q(λ) = λ²M + λD + K: ‖Q(λ)q‖ / (s‖q‖) < 1e-8 with s of
    ``backward_error_and_condition`` (measured ≤ 3e-10 at the disk's edge, where ARPACK's
    Ritz vectors are least accurate; the shapes feed the whirl and the plots)."""
    sys = build_system(rigs[name], **kw)
    lam_ref = dense_eigenvalues(sys)
    monkeypatch.setattr(modes_mod, "DENSE_STATES", 0)
    D = sys.C + sys.speed * sys.G
    for ask in ({"count": 14}, {"radius_rad_s": 2 * np.pi * 1500.0}, {"oscillating": 5}):
        disk = modes_mod.poles_near_zero(sys, vectors=True, **ask)
        assert np.isfinite(disk.radius_rad_s) and disk.poles.size < 2 * sys.n_dof - 1
        inside = lam_ref[np.abs(lam_ref) < disk.radius_rad_s * (1 - 1e-9)]
        assert disk.poles.size == inside.size
        assert disk.poles.size >= ask.get("count", 0)
        assert disk.radius_rad_s > ask.get("radius_rad_s", 0.0)
        assert np.count_nonzero(disk.poles.imag >= modes_mod.RIGID_BODY_RAD_S) \
            >= ask.get("oscillating", 0)
        flexible = disk.poles[np.abs(disk.poles) > 1.0]  # rigid-body ones are defective
        nearest = inside[np.abs(inside[:, None] - flexible[None, :]).argmin(axis=0)]
        assert_same_eigenvalues(sys, flexible, nearest)
        for lam, q in zip(disk.poles, disk.shapes.T):
            s = abs(lam) ** 2 * np.linalg.norm(sys.M, 2) + abs(lam) * np.linalg.norm(D, 2) \
                + np.linalg.norm(sys.K, 2)
            r = np.linalg.norm((lam**2 * sys.M + lam * D + sys.K) @ q) / (s * np.linalg.norm(q))
            assert r < 1e-8, (lam, r)


@pytest.mark.parametrize("speed_rpm", [0.0, 6000.0])
def test_open_loop_modes_sparse_equal_dense(rigs, monkeypatch, speed_rpm):
    """Reference: the dense eig with eigenvectors of the state matrix
    (``modes_of_state_matrix``, what ``ambseal modes`` computed before). The modes of the
    shift-invert path (forced) are the same modes: frequencies (1e-8) and damping (1e-6),
    whirl, and the normalised |shapes| to 1e-4 (the x–z and y–z bending twins lie 0.03 Hz
    apart at 1464 Hz, a relative gap of 2e-5, and two backward-stable solvers' vectors of
    such twins differ by about their backward error over the gap, Stewart & Sun 1990
    Ch. V; measured 4e-6), with the verdict of every pole."""
    from ambseal.analysis.campbell import modes_of_state_matrix, open_loop_modes

    sys = build_system(rigs["testrig"], speed_rpm=speed_rpm)
    kw = {"speed_hz": speed_rpm / 60, "pressure_bar": 2.04, "max_hz": 3000.0}
    ref = modes_of_state_matrix(sys.state_matrices()[0], sys.mesh, **kw)
    monkeypatch.setattr(modes_mod, "DENSE_STATES", 0)
    got = open_loop_modes(sys, judged_poles=sys.poles(), **kw)
    assert len(got.poles) == len(ref.poles) >= 10
    np.testing.assert_allclose(got.frequency_hz, ref.frequency_hz, rtol=1e-8)
    np.testing.assert_allclose(got.damping_ratio, ref.damping_ratio, rtol=1e-6)
    assert got.whirl == ref.whirl
    np.testing.assert_allclose(np.abs(got.shapes), np.abs(ref.shapes), atol=1e-4)
    assert got.stable == ref.stable is False and got.max_real_pole == pytest.approx(
        ref.max_real_pole, rel=1e-8)


def test_open_loop_modes_take_the_disk_the_judged_poles_ask(rigs, monkeypatch):
    """Reference: the dense eig with eigenvectors (``modes_of_state_matrix``). Below 4 Hz
    the test rig has two heavily damped pairs (ζ ≈ 0.998, |λ| ≈ 320 rad/s), outside the
    disk of 2π·4 Hz: once the judged poles show them the disk is enlarged, and they are
    listed as the dense path lists them — the same with the judged poles as an array or as
    a callable (``ambseal modes`` computes them in another thread meanwhile), called once;
    without judged poles they are not seen."""
    from ambseal.analysis.campbell import modes_of_state_matrix, open_loop_modes

    monkeypatch.setattr(modes_mod, "DENSE_STATES", 0)
    monkeypatch.setattr(modes_mod, "EXTRA_EIGENVALUES", 2)  # a first disk of 4 eigenvalues
    sys = build_system(rigs["testrig"])
    kw = {"speed_hz": 0.0, "pressure_bar": 2.04, "max_hz": 4.0}
    ref = modes_of_state_matrix(sys.state_matrices()[0], sys.mesh, **kw)
    assert ref.poles.size == 2 and np.all(np.abs(ref.poles) > 10 * 2 * np.pi * 4.0)
    calls = []

    def every_pole():
        calls.append(1)
        return sys.poles()

    got = open_loop_modes(sys, judged_poles=every_pole, **kw)
    assert calls == [1]
    np.testing.assert_allclose(got.frequency_hz, ref.frequency_hz, rtol=1e-8)
    np.testing.assert_allclose(got.damping_ratio, ref.damping_ratio, rtol=1e-6)
    np.testing.assert_array_equal(
        open_loop_modes(sys, judged_poles=sys.poles(), **kw).poles, got.poles)
    assert open_loop_modes(sys, **kw).poles.size == 0
