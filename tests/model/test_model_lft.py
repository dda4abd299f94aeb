"""LFT channels, modal reduction and the AMB linearisation."""

import math

import numpy as np
import pytest

from ambseal.config import load_rig, parse_rig
from ambseal.model.amb import amb_factors_from_geometry
from ambseal.errors import ModelError
from ambseal.model.reduction import modal_reduction
from ambseal.model.rig import build_plant, build_system, mechanical_plant


@pytest.fixture(scope="module")
def rig():
    return load_rig()


def _edit(cfg, **changes):
    """Rebuild the rig with some values changed (dict path -> value)."""
    data = cfg.model_dump(exclude_none=True)
    for path, value in changes.items():
        node = data
        keys = path.split(".")
        for k in keys[:-1]:
            node = node[int(k)] if k.isdigit() else node[k]
        node[keys[-1]] = value
    return parse_rig(data)


CASES = [
    # parameter, change, rebuilt-config edit
    ("A.Ks_zeta", 0.3e6, {"amb.0.ks": {"zeta": 2.39e6 + 0.3e6, "eta": 2.49e6}}),
    ("B.Ki_eta", -20.0, {"amb.1.ki": {"zeta": 260.8, "eta": 265.8 - 20.0}}),
    ("coupling.kxx", 1.0e5, {"spring.0.kxx": 0.5e6}),
    ("seal.K", 4.0e5, {"seal.0.K": 4.0e5}),
    ("seal.k", 2.0e6, {"seal.0.k": 2.0e6}),
    ("seal.C", 500.0, {"seal.0.C": 500.0}),
    ("seal.c", -300.0, {"seal.0.c": -300.0}),
]


@pytest.mark.parametrize("name,theta,edit", CASES)
def test_lft_equals_rebuilt_full_order(rig, name, theta, edit):
    """A + B_θ θ C_θ (and B + B_θ θ D_θ) equals the model rebuilt with the changed value,
    to rounding (thesis P1 Eqs. 46–50, P4 Eqs. 7–13), with the actuator in series."""
    base = _edit(rig, **{"seal.0.K": 0.0, "seal.0.k": 0.0, "seal.0.C": 0.0, "seal.0.c": 0.0})
    plant = build_plant(base, pressure_bar=0.0)
    changed = plant.with_changes({name: theta})
    rebuilt = build_plant(_edit(base, **edit), pressure_bar=0.0)
    err = change = 0.0
    for a, b, a0 in ((changed.A, rebuilt.A, plant.A), (changed.B, rebuilt.B, plant.B)):
        assert np.linalg.norm(a - b) <= 1e-12 * np.linalg.norm(b)
        err += np.linalg.norm(a - b)
        change += np.linalg.norm(a - a0)
    np.testing.assert_array_equal(changed.C, rebuilt.C)
    assert change > 1e4 * err  # the change is real and the LFT reproduces it


def test_seal_k_is_one_repeated_parameter(rig):
    """k and −k share one parameter, θ·I₂ (thesis P5 §4.1 item 3, Appendix A)."""
    p = build_plant(rig).parameter("seal.k")
    assert p.repeats == 2
    assert p.nominal == pytest.approx(1.1e6 * 2.04)


def test_reduction_is_exact_on_kept_modes(rig):
    """T_L T_R = I, and the reduced poles are the selected full poles (P1 Eqs. 39–45)."""
    full = mechanical_plant(build_system(rig))
    red = modal_reduction(full, states=8)
    np.testing.assert_allclose(red.T_L @ red.T_R, np.eye(8), atol=1e-9)
    lam_full = np.linalg.eigvals(full.A)
    lam_full = lam_full[np.argsort(np.abs(lam_full))][:8]
    lam_red = np.linalg.eigvals(red.plant.A)
    for lam in lam_full:
        assert np.min(np.abs(lam_red - lam)) <= 1e-7 * abs(lam)
    assert np.isrealobj(red.plant.A) and red.plant.n_states == 8
    # the rigid-body modes are the open-loop unstable ones and sit far below bending
    assert np.max(np.abs(red.poles)) < 0.2 * 2 * np.pi * 550


def test_reduced_model_matches_full_at_low_frequency(rig):
    """The 8-state model has the full model's DC gain and low-frequency response to within
    a few per cent: the residual flexible modes only add a small static correction."""
    full = mechanical_plant(build_system(rig))
    red = modal_reduction(full, states=8).plant
    for w in (0.0, 2 * np.pi * 20):
        hf = full.C @ np.linalg.solve(1j * w * np.eye(full.n_states) - full.A, full.B)
        hr = red.C @ np.linalg.solve(1j * w * np.eye(8) - red.A, red.B)
        assert np.linalg.norm(hr - hf) <= 0.05 * np.linalg.norm(hf)


def test_reduced_lft_tracks_rebuilt_model(rig):
    """The reduced LFT (B_θ = T_L B_θf, C_θ = C_θf T_R, P4 Eqs. 11–13) moves the reduced
    poles as a rebuild does: P2 §4.1's assumption, within 1 % for a 20 % Ks change."""
    red = build_plant(rig, reduced=True)
    lft = red.with_changes({"A.Ks_zeta": 0.2 * 2.39e6})
    rebuilt = build_plant(_edit(rig, **{"amb.0.ks": {"zeta": 1.2 * 2.39e6, "eta": 2.49e6}}),
                          reduced=True)
    p1 = np.sort_complex(np.linalg.eigvals(lft.A))
    p2 = np.sort_complex(np.linalg.eigvals(rebuilt.A))
    assert np.max(np.abs(p1 - p2) / np.abs(p2)) < 0.01
    assert np.max(np.abs(p1 - np.sort_complex(np.linalg.eigvals(red.A)))) > 1.0


def test_reduction_refuses_split_pair(rig):
    """A count that splits modes of equal |λ| is refused, naming the fix."""
    full = mechanical_plant(build_system(rig, pressure_bar=2.04))
    with pytest.raises(ModelError, match="keep one state more or less"):
        modal_reduction(full, states=9)


def test_amb_factors_from_geometry_match_nonlinear_force_law():
    """Ki, Ks of Schweitzer & Maslen (2009) equal the derivatives at (i, x) = (0, 0) of
    f = k[(i0+i)²/(s0−x)² − (i0−i)²/(s0+x)²], k = μ0N²A cos α/4, by central differences."""
    N, A, s0, i0, alpha = 36, 5.5e-3, 0.5e-3, 6.0, 22.5
    k = 4e-7 * math.pi * N**2 * A * math.cos(math.radians(alpha)) / 4

    def f(i, x):
        return k * ((i0 + i) ** 2 / (s0 - x) ** 2 - (i0 - i) ** 2 / (s0 + x) ** 2)

    ki, ks = amb_factors_from_geometry(N, A, s0, i0, alpha)
    hi, hx = 1e-4, 1e-9
    assert ki == pytest.approx((f(hi, 0) - f(-hi, 0)) / (2 * hi), rel=1e-6)
    assert ks == pytest.approx((f(0, hx) - f(0, -hx)) / (2 * hx), rel=1e-6)
    # and P2 Table 2's Ks at 6 A is reproduced by this pole area
    assert ks == pytest.approx(2.39e6, rel=0.01)


def test_amb_axes_rotated_45_degrees(rig):
    """A current on A_zeta pushes along (cos 45°, sin 45°) in x, y (P2 Fig. 1b)."""
    sys_ = build_system(rig)
    node = sys_.mesh.node_at(0.17)
    b = sys_.B[4 * node: 4 * node + 2, 0]
    np.testing.assert_allclose(b / np.linalg.norm(b), [math.sqrt(0.5)] * 2, rtol=1e-12)


def test_reduction_keeps_a_defective_mode_by_its_invariant_subspace():
    """Reference: the closed form of a plant built as S J S⁻¹ with J block diagonal — a
    Jordan block at λ = −2 (defective: one eigenvector for a double eigenvalue), a
    lightly damped pair at |λ| = 5, then faster modes. Keeping the four slowest states
    (the Jordan block and the pair), the reduced plant is the kept blocks' transfer
    C S_k (sI − J_k)⁻¹ (S⁻¹)_k B exactly (1e-9), T_L T_R = I, and its states are named
    as the Schur basis they are."""
    from ambseal.model.lft import Plant

    rng = np.random.default_rng(5)
    J = np.zeros((7, 7))
    J[:2, :2] = [[-2.0, 1.0], [0.0, -2.0]]
    J[2:4, 2:4] = [[-0.3, 4.99], [-4.99, -0.3]]
    J[4:, 4:] = np.diag([-40.0, -60.0, -90.0])
    S = np.eye(7) + 0.3 * rng.standard_normal((7, 7))
    Si = np.linalg.inv(S)
    B, C = rng.standard_normal((7, 2)), rng.standard_normal((3, 7))
    plant = Plant(A=S @ J @ Si, B=B, C=C, D=np.zeros((3, 2)), input_names=("u0", "u1"),
                  output_names=("y0", "y1", "y2"),
                  state_names=tuple(f"x{i}" for i in range(7)))
    red = modal_reduction(plant, states=4)
    np.testing.assert_allclose(red.T_L @ red.T_R, np.eye(4), atol=1e-10)
    assert red.plant.state_names == ("schur0", "schur1", "schur2", "schur3")
    for s in (0.0, 1j, 3.0 + 2j, 20j):
        want = C @ S[:, :4] @ np.linalg.solve(s * np.eye(4) - J[:4, :4], Si[:4] @ B)
        got = red.plant.C @ np.linalg.solve(s * np.eye(4) - red.plant.A, red.plant.B)
        np.testing.assert_allclose(got, want, rtol=1e-9, atol=1e-9 * np.abs(want).max())


def test_reduction_keeps_a_complex_pair_whose_imaginary_part_is_tiny():
    """Reference: the closed form of a plant S J S⁻¹ whose slowest pair 200 ± 0.006j 1/s
    (a whirl split by weak gyroscopic coupling) has an imaginary part below 1e-9 of its
    spectrum (a stiff mode at −1e7 1/s): kept as the pair it is, in real modal
    coordinates (the block [[σ, ω], [−ω, σ]] of P1 Eq. 32), with the kept blocks'
    transfer exactly (1e-9). Taken for two real eigenvalues, the pair gave one real line
    twice and the reduction fell back to the Schur form."""
    from ambseal.model.lft import Plant

    rng = np.random.default_rng(7)
    J = np.zeros((5, 5))
    J[:2, :2] = [[200.0, 0.006], [-0.006, 200.0]]
    J[2:, 2:] = np.diag([-900.0, -4e5, -1e7])
    S = np.eye(5) + 0.3 * rng.standard_normal((5, 5))
    Si = np.linalg.inv(S)
    B, C = rng.standard_normal((5, 2)), rng.standard_normal((2, 5))
    plant = Plant(A=S @ J @ Si, B=B, C=C, D=np.zeros((2, 2)), input_names=("u0", "u1"),
                  output_names=("y0", "y1"), state_names=tuple(f"x{i}" for i in range(5)))
    red = modal_reduction(plant, states=2)
    assert red.plant.state_names == ("mode0_re", "mode0_im")
    # to the rounding of a spectrum of 1e7 1/s
    np.testing.assert_allclose(red.plant.A, [[200.0, 0.006], [-0.006, 200.0]], atol=1e-6)
    for s in (0.0, 1j, 3.0 + 2j, 300j):
        want = C @ S[:, :2] @ np.linalg.solve(s * np.eye(2) - J[:2, :2], Si[:2] @ B)
        got = red.plant.C @ np.linalg.solve(s * np.eye(2) - red.plant.A, red.plant.B)
        np.testing.assert_allclose(got, want, rtol=1e-9, atol=1e-9 * np.abs(want).max())


def test_a_symmetric_rotor_at_standstill_reduces_to_a_symmetric_model():
    """Reference: the rotor's symmetry about its axis. The example flywheel at standstill
    has its cylindrical and conical modes twice over (ζ and η; the eigensolver gives the
    conical twins as a conjugate pair 264.44 ± 5e-9j 1/s). Its 12-state design model is
    in real modal coordinates and keeps the symmetry in its responses, G_ζζ = G_ηη and
    G_ζη = −G_ηζ at both bearings, to 1e-9 (1e-11 measured; the Schur form it fell back
    to kept them to 9e-6, with entries of 1.3e8 in its A)."""
    from pathlib import Path

    cfg = load_rig(Path(__file__).resolve().parents[2] / "examples" / "flywheel.toml")
    red = modal_reduction(mechanical_plant(build_system(cfg, pressure_bar=0.0,
                                                        speed_rpm=0.0)), states=12)
    p = red.plant
    assert not any(n.startswith("schur") for n in p.state_names)
    w = 2 * np.pi * np.logspace(0, 4, 40)
    H = np.array([p.C @ np.linalg.solve(1j * x * np.eye(12) - p.A, p.B) for x in w])
    i, o = list(p.input_names), list(p.output_names)
    for b in ("A", "B"):
        zz = H[:, o.index(f"y_{b}_zeta"), i.index(f"i_{b}_zeta")]
        ee = H[:, o.index(f"y_{b}_eta"), i.index(f"i_{b}_eta")]
        ze = H[:, o.index(f"y_{b}_zeta"), i.index(f"i_{b}_eta")]
        ez = H[:, o.index(f"y_{b}_eta"), i.index(f"i_{b}_zeta")]
        scale = np.abs(zz).max()
        assert np.abs(zz - ee).max() <= 1e-9 * scale
        assert np.abs(ze + ez).max() <= 1e-9 * scale
