"""Element modules of the model: seal, AMB and spring matrices, channels and tables."""

import math

import numpy as np
import pytest

from ambseal.config import load_rig, parse_rig
from ambseal.errors import ConfigError, ModelError
from ambseal.model.amb import MU0, AmbElement, amb_factors, channel_names
from ambseal.model.rig import build_system
from ambseal.model.rotor import build_mesh
from ambseal.lti.tables import interp_table
from ambseal.model.seal import SealElement, coefficient_value
from ambseal.model.spring import SpringElement

TABLE = {"frequency_hz": [20.0, 50.0, 100.0], "value": [6.0e6, 7.5e6, 10.0e6]}


def _rig(**extra):
    data = {
        "materials": {"steel": {"E": 2.1e11, "rho": 7850.0, "nu": 0.3}},
        "shaft": [{"length": 0.5, "outer_diameter": 0.05, "material": "steel",
                   "elements": 5}],
    }
    data.update(extra)
    return parse_rig(data)


def _reconstruct(channels, n, kind):
    """Σ θ U Vᵀ over the channels of one kind: the matrix the LFT channels describe."""
    out = np.zeros((n, n))
    for ch in channels:
        if ch.kind == kind:
            out += ch.nominal * ch.U @ ch.V.T
    return out


# ----------------------------------------------------------------------------- seal

def test_seal_force_on_forward_whirl_matches_childs():
    """Reference: Childs, *Turbomachinery Rotordynamics* (1993), §3.2 — on a circular
    forward whirl q = r(cos ωt, sin ωt) the seal force −f = [K k; −k K] q + [C c; −c C] q̇
    + M q̈ has radial part f_r = −(K + cω − Mω²) r and tangential part f_t = (k − Cω) r.
    Coefficients: K from a frequency table at 35 Hz (6.75 MN/m by hand), k affine
    (1.1 MN/m/bar at 2 bar), C, c, M plain numbers."""
    cfg = _rig(seal=[{"name": "s", "position": 0.2, "K": TABLE,
                      "k": {"at_zero": 1.0e5, "per_bar": 1.1e6}, "C": 3.0e3, "c": -4.0e2,
                      "M": 2.5}])
    mesh = build_mesh(cfg)
    el = SealElement.from_config(cfg.seal[0], mesh, pressure_bar=2.0, frequency_hz=35.0)
    K, k, C, c, M = 6.75e6, 1.0e5 + 2.2e6, 3.0e3, -4.0e2, 2.5
    Ke, Ce, Me = el.matrices()
    w, r = 2 * math.pi * 35.0, 1e-5
    for t in np.linspace(0.0, 0.03, 7):
        er = np.array([math.cos(w * t), math.sin(w * t)])
        et = np.array([-math.sin(w * t), math.cos(w * t)])
        q, dq, ddq = r * er, r * w * et, -r * w**2 * er
        f = -(Ke @ q + Ce @ dq + Me @ ddq)
        assert f @ er == pytest.approx(-(K + c * w - M * w**2) * r, rel=1e-12)
        assert f @ et == pytest.approx((k - C * w) * r, rel=1e-12)


def test_seal_channels_rebuild_its_matrices():
    """Reference: thesis P1 Eqs. 48–50 — the LFT channels θ U Vᵀ of K, k (C, c) sum to the
    element's stiffness (damping) at the nominal values; k and −k share one channel of
    rank 2 (P5 §4.1 item 3)."""
    cfg = _rig(seal=[{"name": "s", "position": 0.2, "K": 4e5, "k": 2e6, "C": 500.0,
                      "c": -300.0}])
    mesh = build_mesh(cfg)
    el = SealElement.from_config(cfg.seal[0], mesh, 0.0, None)
    n, node = mesh.n_dof, mesh.node_at(0.2)
    i = np.ix_([4 * node, 4 * node + 1], [4 * node, 4 * node + 1])
    ch = el.channels(n)
    assert [c.name for c in ch] == ["s.K", "s.k", "s.C", "s.c"]
    assert all(c.U.shape == (n, 2) for c in ch)
    Kc, Cc = _reconstruct(ch, n, "K"), _reconstruct(ch, n, "C")
    np.testing.assert_array_equal(Kc[i], [[4e5, 2e6], [-2e6, 4e5]])
    np.testing.assert_array_equal(Cc[i], [[500.0, -300.0], [300.0, 500.0]])
    assert np.count_nonzero(Kc) == 4 and np.count_nonzero(Cc) == 4


# ------------------------------------------------------------------------ tables

def test_frequency_table_interpolation_by_hand():
    """Reference: linear interpolation worked by hand on (20, 6), (50, 7.5), (100, 10)
    MN/m; held at the end values outside the table (the rig format's rule)."""
    cfg = _rig(seal=[{"name": "s", "position": 0.2, "K": TABLE}])
    K = cfg.seal[0].K
    for f, want in [(20.0, 6.0e6), (50.0, 7.5e6), (100.0, 10.0e6),  # table points
                    (35.0, 6.75e6), (75.0, 8.75e6),  # 6 + 15/30·1.5, 7.5 + 25/50·2.5
                    (0.0, 6.0e6), (10.0, 6.0e6), (500.0, 10.0e6)]:  # outside: held
        assert coefficient_value(K, 3.0, f) == pytest.approx(want, rel=1e-15)
    # the same table of matrices (a stack along axis 0), e.g. a scheduled controller
    A = np.array([[1.0, -2.0], [0.5, 3.0]])
    stack = np.array(TABLE["value"])[:, None, None] * A
    for f, want in [(35.0, 6.75e6), (50.0, 7.5e6), (-1.0, 6.0e6), (1e3, 10.0e6)]:
        np.testing.assert_allclose(interp_table(f, TABLE["frequency_hz"], stack), want * A,
                                   rtol=1e-15)


def test_frequency_table_pchip_and_end_slopes_as_scipy_and_ross_31():
    """Reference: SciPy's ``PchipInterpolator`` (Fritsch–Carlson) inside the table and its
    end derivative continued linearly outside (ROSS 3.1's ``_AxisInterpolator``); with
    ``interpolation = "linear"`` and ``extrapolation = "linear"`` the end segments'
    slopes by hand: (7.5 − 6)/30 MN/m per Hz below, (10 − 7.5)/50 above."""
    from scipy.interpolate import PchipInterpolator

    cfg = _rig(seal=[{"name": "s", "position": 0.2,
                      "K": {**TABLE, "interpolation": "pchip", "extrapolation": "linear"},
                      "C": {**TABLE, "extrapolation": "linear"}}])
    K, C = cfg.seal[0].K, cfg.seal[0].C
    p = PchipInterpolator(TABLE["frequency_hz"], TABLE["value"])
    for f in (20.0, 27.0, 50.0, 64.0, 99.0):
        assert coefficient_value(K, 0.0, f) == pytest.approx(float(p(f)), rel=1e-14)
    d = p.derivative()
    for f, end in ((5.0, 20.0), (180.0, 100.0)):
        want = float(p(end)) + (f - end) * float(d(end))
        assert coefficient_value(K, 0.0, f) == pytest.approx(want, rel=1e-14)
    assert coefficient_value(C, 0.0, 5.0) == pytest.approx(6.0e6 - 15 * 1.5e6 / 30, rel=1e-14)
    assert coefficient_value(C, 0.0, 180.0) == pytest.approx(10.0e6 + 80 * 2.5e6 / 50,
                                                             rel=1e-14)
    with pytest.raises(ConfigError, match="interpolation"):
        _rig(seal=[{"name": "s", "position": 0.2, "K": {**TABLE, "interpolation": "cubic"}}])


def test_a_cross_added_mass_is_solved_as_it_is():
    """A spring's cross added mass (mxy = −myx, as ROSS's hole-pattern seals carry) makes
    M non-symmetric: the poles are the generalised eigenvalues of the pencil
    [[0, I], [−K, −D]] x = λ diag(I, M) x (SciPy's QZ, Tisseur & Meerbergen 2001), and both
    of ambseal's solvers agree with them (a Cholesky factor of M had read one triangle)."""
    import scipy.linalg as sla

    from ambseal.model.modes import modes

    cfg = _rig(spring=[{"position": 0.0, "kxx": 1e6, "kyy": 1e6},
                       {"position": 0.5, "kxx": 1e6, "kyy": 1e6, "cxx": 200.0, "cyy": 200.0,
                        "mxx": 0.5, "myy": 0.5, "mxy": 0.8, "myx": -0.8}])
    sys = build_system(cfg, speed_rpm=3000.0)
    assert not np.array_equal(sys.M, sys.M.T)
    n = sys.n_dof
    A = np.block([[np.zeros((n, n)), np.eye(n)], [-sys.K, -(sys.C + sys.speed * sys.G)]])
    B = sla.block_diag(np.eye(n), sys.M)
    want = sla.eig(A, B, right=False)
    want = want[np.isfinite(want)]
    got = sys.poles()
    for lam in got:
        assert np.min(np.abs(want - lam)) <= 1e-6 * max(abs(lam), 1.0)
    low = modes(sys, 4).poles
    for lam in low:
        assert np.min(np.abs(want - lam)) <= 1e-6 * max(abs(lam), 1.0)


def test_affine_and_plain_coefficients_and_missing_frequency():
    """Reference: the rig format — ``at_zero + per_bar · pressure_bar`` (by hand:
    100 + 50·4.08 = 304), a plain number as is; a table without a frequency is refused."""
    cfg = _rig(seal=[{"name": "s", "position": 0.2, "C": {"at_zero": 100.0, "per_bar": 50.0},
                      "K": TABLE, "M": 1.5}])
    s = cfg.seal[0]
    assert coefficient_value(s.C, 4.08, 77.0) == pytest.approx(304.0, rel=1e-15)
    assert coefficient_value(s.M, 4.08) == 1.5
    with pytest.raises(ModelError, match="needs a frequency"):
        coefficient_value(s.K, 0.0)


def test_every_seal_follows_the_pressure_that_gives_a_tracked_k():
    """Reference: examples/pump.toml's affine laws by hand. The balance drum's k = 4e4 N/m
    per bar: k = 1.2 MN/m is 30 bar, where its K = 6e4·30 = 1.8 MN/m, C = 12 kN·s/m, c =
    1.8 kN·s/m, and the impeller-eye labyrinth (the rig's one pressure drop acts on both
    seals) has k = 1e4·30 = 0.3 MN/m and C = 50 + 10·30 = 350 N·s/m. Tracking both k's,
    each seal follows its own k, a seal without a tracked k the first one's pressure; a
    name that is no seal k follows nothing."""
    from pathlib import Path

    from ambseal.model.seal import values_following, values_following_k

    seals = load_rig(Path(__file__).parents[2] / "examples" / "pump.toml").seal
    known = {f"{s}.{q}" for s in ("balance_drum", "eye_labyrinth") for q in "KkCc"}
    v = values_following_k(seals, "balance_drum.k", 1.2e6, known)
    want = {"balance_drum.K": 1.8e6, "balance_drum.k": 1.2e6, "balance_drum.C": 1.2e4,
            "balance_drum.c": 1.8e3, "eye_labyrinth.K": 0.0, "eye_labyrinth.k": 3e5,
            "eye_labyrinth.C": 350.0, "eye_labyrinth.c": 0.0}
    assert v.keys() == want.keys()
    for n, x in want.items():
        assert v[n] == pytest.approx(x, rel=1e-12, abs=1e-9), n
    both = values_following(seals, {"balance_drum.k": 1.2e6, "eye_labyrinth.k": 1e5}, known)
    assert both["balance_drum.K"] == pytest.approx(1.8e6)
    assert both["eye_labyrinth.k"] == 1e5 and both["eye_labyrinth.C"] == pytest.approx(150.0)
    assert values_following_k(seals, "balance_drum.C", 1.0, known) == {"balance_drum.C": 1.0}


# ----------------------------------------------------------------------------- AMB

def _force(N, A, s0, i0, alpha_deg, x, i):
    """Two opposing pole pairs of an 8-pole bearing, differential driving (Schweitzer &
    Maslen 2009, Eq. 3.27): f = k[(i0+i)²/(s0−x)² − (i0−i)²/(s0+x)²], k = μ0N²A cos α/4."""
    k = MU0 * N**2 * A * math.cos(math.radians(alpha_deg)) / 4
    return k * ((i0 + i) ** 2 / (s0 - x) ** 2 - (i0 - i) ** 2 / (s0 + x) ** 2)


def test_amb_element_is_the_linearised_force_law():
    """Reference: central finite differences of the nonlinear force law of
    :func:`_force` at x = i = 0 give Ks = ∂f/∂x and Ki = ∂f/∂i; the element must add
    −Rᵀ diag(Ks) R to K (45° axes, R written out by hand), Ki r_a as input columns at
    the bearing node and r_aᵀ as sensor rows at the sensor node (thesis P2 Eq. 1)."""
    N, A, s0, i0, alpha = 36, 5.5e-3, 0.5e-3, 6.0, 22.5
    cfg = _rig(amb=[{"name": "A", "position": 0.1, "sensor_position": 0.0,
                     "axes_angle_deg": 45.0, "turns": N, "pole_area": A, "air_gap": s0,
                     "bias_current": i0, "pole_angle_deg": alpha}])
    mesh = build_mesh(cfg)
    el = AmbElement.from_config(cfg.amb[0], mesh)
    hx, hi = 1e-4 * s0, 1e-4 * i0
    ks = (_force(N, A, s0, i0, alpha, hx, 0) - _force(N, A, s0, i0, alpha, -hx, 0)) / (2 * hx)
    ki = (_force(N, A, s0, i0, alpha, 0, hi) - _force(N, A, s0, i0, alpha, 0, -hi)) / (2 * hi)
    h = math.sqrt(0.5)
    R = np.array([[h, h], [-h, h]])  # ζ = (x + y)/√2, η = (−x + y)/√2
    np.testing.assert_allclose(el.stiffness(), -ks * (R.T @ R), rtol=1e-7, atol=1e-9 * ks)
    n, nb, ns = mesh.n_dof, mesh.node_at(0.1), mesh.node_at(0.0)
    cols, rows = el.input_columns(n), el.sensor_rows(n)
    for a in range(2):
        want = np.zeros(n)
        want[[4 * nb, 4 * nb + 1]] = ki * R[a]
        np.testing.assert_allclose(cols[a], want, rtol=1e-7, atol=0)
        want = np.zeros(n)
        want[[4 * ns, 4 * ns + 1]] = R[a]
        np.testing.assert_allclose(rows[a], want, rtol=1e-15, atol=0)
    # anisotropic factors: −Rᵀ diag(kζ, kη) R = −½[[kζ + kη, kζ − kη], [kζ − kη, kζ + kη]]
    kz, ke = 2.39e6, 2.49e6
    cfg = _rig(amb=[{"name": "A", "position": 0.1, "sensor_position": 0.0,
                     "axes_angle_deg": 45.0, "ki": 200.0, "ks": {"zeta": kz, "eta": ke}}])
    el = AmbElement.from_config(cfg.amb[0], mesh)
    want = -0.5 * np.array([[kz + ke, kz - ke], [kz - ke, kz + ke]])
    np.testing.assert_allclose(el.stiffness(), want, rtol=1e-14)
    ch = el.channels(n, first_input=2)
    assert [c.name for c in ch] == ["A.Ks_zeta", "A.Ki_zeta", "A.Ks_eta", "A.Ki_eta"]
    assert [int(c.V[0, 0]) for c in ch if c.kind == "B"] == [2, 3]
    Kc = _reconstruct(ch, n, "K")
    np.testing.assert_allclose(Kc[4 * nb:4 * nb + 2, 4 * nb:4 * nb + 2], want, rtol=1e-14)


def test_explicit_factor_wins_per_axis_over_geometry():
    """Reference: the rig format — with the geometry, an explicit factor (even for one axis)
    wins, the others come from the geometry; without geometry both axes are required."""
    geo = {"name": "A", "position": 0.1, "sensor_position": 0.0, "turns": 36,
           "pole_area": 5.5e-3, "air_gap": 0.5e-3, "bias_current": 6.0}
    (ki0, _), (ks0, _) = amb_factors(_rig(amb=[geo]).amb[0])
    ki, ks = amb_factors(_rig(amb=[{**geo, "ki": {"zeta": 300.0}, "ks": 1e6}]).amb[0])
    assert ki == (300.0, ki0) and ks == (1e6, 1e6) and ks0 != 1e6
    plain = {"name": "A", "position": 0.1, "sensor_position": 0.0, "ks": 1e6}
    with pytest.raises(ConfigError, match="ki: expected both zeta and eta"):
        _rig(amb=[{**plain, "ki": {"zeta": 300.0}}])
    with pytest.raises(ConfigError, match=r"amb\[0\]\.ki"):
        _rig(amb=[{**plain, "ki": {}}])


def test_channel_names_of_the_thesis_rig():
    """Reference: DESIGN.md's convention — A_zeta, A_eta, B_zeta, B_eta on the thesis rig;
    the system's current inputs are i_<axis>, its sensor outputs y_<axis>."""
    cfg = load_rig()
    names = channel_names(cfg)
    assert names == ("A_zeta", "A_eta", "B_zeta", "B_eta")
    sys = build_system(cfg)
    assert sys.input_names == tuple(f"i_{n}" for n in names)
    assert sys.output_names == tuple(f"y_{n}" for n in names)


# --------------------------------------------------------------------------- spring

def test_spring_rotated_45_degrees_by_hand():
    """Reference: Rᵀ k R at 45° written out by hand (c = s = 1/√2):
    K11 = (kxx − kxy − kyx + kyy)/2, K12 = (kxx + kxy − kyx − kyy)/2,
    K21 = (kxx − kxy + kyx − kyy)/2, K22 = (kxx + kxy + kyx + kyy)/2; and physically a
    spring kxx along u = (x + y)/√2 alone restores only along u."""
    kxx, kyy, kxy, kyx, cxx, cyy = 4.0e5, 4.2e5, 3.0e4, -1.0e4, 50.0, 80.0
    cfg = _rig(spring=[{"position": 0.0, "kxx": kxx, "kyy": kyy, "kxy": kxy, "kyx": kyx,
                        "cxx": cxx, "cyy": cyy, "axes_angle_deg": 45.0},
                       {"position": 0.5, "kxx": kxx, "kyy": 0.0, "axes_angle_deg": 45.0}])
    mesh = build_mesh(cfg)
    el = SpringElement.from_config(cfg.spring[0], mesh, 0)
    K, C = el.matrices()
    want = 0.5 * np.array([[kxx - kxy - kyx + kyy, kxx + kxy - kyx - kyy],
                           [kxx - kxy + kyx - kyy, kxx + kxy + kyx + kyy]])
    np.testing.assert_allclose(K, want, rtol=1e-14)
    np.testing.assert_allclose(C, 0.5 * np.array([[cxx + cyy, cxx - cyy],
                                                  [cxx - cyy, cxx + cyy]]), rtol=1e-14)
    n = mesh.n_dof
    ch = el.channels(n)
    assert [c.name for c in ch] == [f"spring0.{k}" for k in
                                    ("kxx", "kyy", "kxy", "kyx", "cxx", "cyy")]
    np.testing.assert_allclose(_reconstruct(ch, n, "K")[:2, :2], K, rtol=1e-14)
    np.testing.assert_allclose(_reconstruct(ch, n, "C")[:2, :2], C, rtol=1e-14)
    Ku = SpringElement.from_config(cfg.spring[1], mesh, 1).matrices()[0]
    u, v = np.array([1.0, 1.0]) / math.sqrt(2), np.array([-1.0, 1.0]) / math.sqrt(2)
    np.testing.assert_allclose(Ku @ u, kxx * u, rtol=1e-14)
    np.testing.assert_allclose(Ku @ v, 0.0, atol=1e-10 * kxx)
