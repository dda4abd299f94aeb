"""FE rotor against closed forms."""

import tomllib

import numpy as np
import pytest
import scipy.linalg as sla

from ambseal.config import parse_rig
from ambseal.model.modes import modes
from ambseal.model.rig import build_system
from ambseal.model.rotor import assemble_rotor

E, RHO, NU = 2.1e11, 7850.0, 0.3


def beam_rig(beam, length=1.0, d=0.02, n=20, **extra):
    data = {
        "rotor": {"beam": beam},
        "materials": {"steel": {"E": E, "rho": RHO, "nu": NU}},
        "shaft": [{"length": length, "outer_diameter": d, "material": "steel", "elements": n}],
    }
    data.update(extra)
    return parse_rig(data)


def undamped_hz(K, M, keep=None):
    if keep is not None:
        K, M = K[np.ix_(keep, keep)], M[np.ix_(keep, keep)]
    w2 = sla.eigh(K, M, eigvals_only=True)
    return np.sqrt(np.clip(w2, 0, None)) / (2 * np.pi)


def eb_hz(beta_l, length, d):
    area, inertia = np.pi * d**2 / 4, np.pi * d**4 / 64
    return np.asarray(beta_l) ** 2 / (2 * np.pi * length**2) * np.sqrt(E * inertia / (RHO * area))


def test_euler_bernoulli_free_free():
    """Uniform free–free E–B beam, 20 elements: β_nL = 4.7300, 7.8532, 10.9956
    (Blevins, *Formulas for Natural Frequency and Mode Shape*, Table 8-1) within 0.5 %."""
    r = assemble_rotor(beam_rig("euler-bernoulli"))
    f = undamped_hz(r.K, r.M)
    assert np.all(f[:4] < 1e-2)  # 2 planes x (translation, tilt) rigid-body modes
    fe = f[4::2][:3]  # each bending mode appears once per plane
    ref = eb_hz([4.7300407, 7.8532046, 10.9956078], 1.0, 0.02)
    np.testing.assert_allclose(fe, ref, rtol=5e-3)
    np.testing.assert_allclose(f[5::2][:3], fe, rtol=1e-10)  # x and y planes alike


def test_euler_bernoulli_pinned_pinned():
    """Pinned–pinned E–B beam: f_n = (nπ)²/(2πL²)·√(EI/ρA) (Blevins Table 8-1) within 0.5 %."""
    r = assemble_rotor(beam_rig("euler-bernoulli"))
    n = r.K.shape[0]
    keep = [i for i in range(n) if i not in (0, 1, n - 4, n - 3)]
    f = undamped_hz(r.K, r.M, keep)[::2][:3]
    np.testing.assert_allclose(f, eb_hz(np.pi * np.arange(1, 4), 1.0, 0.02), rtol=5e-3)


def timoshenko_pinned_hz(n, length, d):
    """Simply supported Timoshenko beam, mode n: the lower root of
    (κGAk² − ρAω²)(ρIω² − EIk² − κGA) + (κGAk)² = 0, k = nπ/L
    (Timoshenko 1921; Han, Benaroya & Wei, J. Sound Vib. 225 (1999), Eq. 52)."""
    G = E / (2 * (1 + NU))
    kappa = 6 * (1 + NU) / (7 + 6 * NU)
    area, inertia = np.pi * d**2 / 4, np.pi * d**4 / 64
    k = n * np.pi / length
    kga = kappa * G * area
    # a ω⁴ + b ω² + c = 0 in ω²
    a = -RHO * area * RHO * inertia
    b = kga * k**2 * RHO * inertia + RHO * area * (E * inertia * k**2 + kga)
    c = -(kga * k**2) * (E * inertia * k**2 + kga) + kga**2 * k**2
    w2 = np.roots([a, b, c])
    return np.sqrt(np.min(w2.real)) / (2 * np.pi)


def test_timoshenko_pinned_pinned_stubby():
    """A stubby (L/D = 5) pinned beam: Timoshenko FE within 0.5 % of the exact Timoshenko
    frequencies, while Euler–Bernoulli is more than 2 % (mode 1) and 5 % (mode 2) high:
    shear matters, so the test tells the two beams apart."""
    length, d = 0.5, 0.1
    ref = [timoshenko_pinned_hz(n, length, d) for n in (1, 2)]
    for beam, ok in (("timoshenko", True), ("euler-bernoulli", False)):
        r = assemble_rotor(beam_rig(beam, length=length, d=d, n=20))
        n = r.K.shape[0]
        keep = [i for i in range(n) if i not in (0, 1, n - 4, n - 3)]
        f = undamped_hz(r.K, r.M, keep)[::2][:2]
        err = np.abs(f / ref - 1)
        if ok:
            assert np.all(err < 5e-3), err
        else:
            assert err[0] > 2e-2 and err[1] > 5e-2, err


def test_gyroscopic_whirl_rigid_rotor():
    """Rigid rotor on two isotropic springs k at ±a from its centre, spinning at Ω:
    cylindrical mode ω = √(2k/m) independent of Ω; conical modes solve
    I_d ω² ∓ I_p Ω ω − 2ka² = 0 (forward +, backward −) (Friswell et al. 2010, §3.5)."""
    length, d, k, a = 0.4, 0.05, 1.0e6, 0.2
    disk = {"position": 0.2, "mass": 20.0, "Ip": 0.4, "Id": 0.2}
    springs = [{"position": z, "kxx": k, "kyy": k} for z in (0.0, 0.4)]
    data = {
        "materials": {"rigid": {"E": 2.1e17, "rho": RHO, "nu": NU}},
        "shaft": [{"length": length, "outer_diameter": d, "material": "rigid", "elements": 4}],
        "disk": [disk],
        "spring": springs,
    }
    cfg = parse_rig(data)
    ms = RHO * np.pi * d**2 / 4 * length
    m = ms + disk["mass"]
    Ip = ms * d**2 / 8 + disk["Ip"]
    Id = ms * (3 * (d / 2) ** 2 + length**2) / 12 + disk["Id"]
    omega_spin = 3000.0
    sys_ = build_system(cfg, speed_rpm=omega_spin * 60 / (2 * np.pi))
    lam = sys_.poles()
    low = np.sort(lam[(lam.imag > 0) & (np.abs(lam) < 1e4)].imag)
    wc = np.sqrt(2 * k / m)
    wf = (Ip * omega_spin + np.sqrt((Ip * omega_spin) ** 2 + 8 * Id * k * a**2)) / (2 * Id)
    wb = (-Ip * omega_spin + np.sqrt((Ip * omega_spin) ** 2 + 8 * Id * k * a**2)) / (2 * Id)
    ref = np.sort([wb, wc, wc, wf])
    np.testing.assert_allclose(low, ref, rtol=1e-5)
    assert wf > 2 * wb  # the gyroscopic split is large: the test can tell the sign


def test_mesh_has_nodes_at_components_and_boundaries():
    """Every component position and section boundary is a node (issue contract)."""
    data = {
        "materials": {"s": {"E": E, "rho": RHO, "G": E / 2.6}},
        "shaft": [
            {"length": 0.3, "outer_diameter": 0.05, "material": "s", "elements": 3},
            {"length": 0.2, "outer_diameter": 0.04, "material": "s", "elements": 2},
        ],
        "disk": [{"position": 0.123, "mass": 1.0}],
        "amb": [{"name": "A", "position": 0.05, "sensor_position": 0.4321,
                 "ki": 100.0, "ks": 1e5}],
    }
    cfg = parse_rig(data)
    sys_ = build_system(cfg)
    z = sys_.mesh.z
    for p in (0.0, 0.3, 0.5, 0.123, 0.05, 0.4321):
        assert np.min(np.abs(z - p)) < 1e-12
    assert np.all(np.diff(z) > 0)


def test_modal_damping_sets_bending_mode_damping():
    """[rotor] modal_damping gives each free–free bending mode exactly that ζ."""
    cfg = beam_rig("timoshenko", d=0.05, n=10, rotor={"modal_damping": 0.02})
    res = modes(build_system(cfg))
    np.testing.assert_allclose(res.damping_ratios[:6], 0.02, rtol=1e-6)


def test_supported_modal_damping_sets_each_supported_mode():
    """[rotor.supported_modal_damping] gives the modes of the rotor on its springs and
    seals (stiffness and mass at 0 Hz, the [operating] pressure) the listed ζ in ascending
    order and ``others`` above, to 1e-8 at standstill (classical damping: each undamped
    mode keeps its shape, Craig & Kurdila 2006 §10.2); the matrix is the same at another
    pressure; it reads back from the dumped TOML; with modal_damping as well, an error."""
    from ambseal.config import dump_rig
    from ambseal.errors import ConfigError

    ratios, others = [0.01, 0.03, 0.05, 0.002], 0.02
    seal = {"name": "S", "position": 0.6, "K": {"at_zero": 2e5, "per_bar": 4e4},
            "k": 0.0, "C": 0.0, "c": 0.0, "M": 0.5}
    springs = [{"name": f"B{i}", "position": z, "kxx": 1e6, "kyy": 6e5}
               for i, z in enumerate((0.0, 1.0))]
    extra = dict(disk=[{"position": 0.3, "mass": 4.0, "Ip": 0.02, "Id": 0.01}],
                 spring=springs, seal=[seal], operating={"pressure_bar": 5.0})
    cfg = beam_rig("timoshenko", d=0.05, n=10, rotor={"supported_modal_damping": {
        "ratios": ratios, "others": others}}, **extra)
    bare = build_system(beam_rig("timoshenko", d=0.05, n=10, **extra), speed_rpm=0.0)
    w = np.sort(2 * np.pi * undamped_hz(bare.K, bare.M))
    lam = build_system(cfg, speed_rpm=0.0).poles()
    lam = lam[lam.imag > 0]
    zeta = np.array(ratios + [others] * (len(w) - len(ratios)))
    for wr, z in zip(w[:8], zeta[:8]):
        j = np.argmin(np.abs(np.abs(lam) - wr))
        assert abs(lam[j]) == pytest.approx(wr, rel=1e-8)
        assert -lam[j].real / abs(lam[j]) == pytest.approx(z, rel=1e-8)
    other_p = build_system(cfg, speed_rpm=0.0, pressure_bar=20.0)
    np.testing.assert_allclose(other_p.C, build_system(cfg, speed_rpm=0.0).C, rtol=0,
                               atol=1e-12 * np.abs(other_p.C).max())
    assert parse_rig(tomllib.loads(dump_rig(cfg))) == cfg
    with pytest.raises(ConfigError, match="modal_damping .*supported_modal_damping"):
        beam_rig("timoshenko", rotor={"modal_damping": 0.01, "supported_modal_damping": {
            "ratios": [0.01]}})


@pytest.mark.parametrize(("alpha", "beta"), [(3.0, 0.0), (0.0, 2e-5), (3.0, 2e-5)])
def test_rayleigh_damping_closed_form_and_per_tube(alpha, beta):
    """Rayleigh damping C = αM + βK of a free–free rotor (shaft and a disk) gives each
    bending mode ζ = α/(2ω) + βω/2, ω its undamped frequency (Craig & Kurdila 2006 §10.2),
    to 1e-6; on a layered shaft alone, the same α, β on every tube (section and layer)
    instead of the rotor add up to the same C: the same poles to 1e-9."""
    disk = [{"position": 0.3, "mass": 4.0, "Ip": 0.02, "Id": 0.01}]
    cfg = beam_rig("timoshenko", d=0.05, n=10, disk=disk,
                   rotor={"rayleigh_alpha": alpha, "rayleigh_beta": beta})
    plain = beam_rig("timoshenko", d=0.05, n=10, disk=disk)
    r0 = assemble_rotor(plain)
    w = 2 * np.pi * undamped_hz(r0.K, r0.M)
    w = w[w > 1.0][:6]
    res = modes(build_system(cfg))
    np.testing.assert_allclose(res.damping_ratios[:6], alpha / (2 * w) + beta * w / 2,
                               rtol=1e-6)
    def layered(rotor, tube):
        layer = {"outer_diameter": 0.05, "inner_diameter": 0.04, "material": "steel", **tube}
        shaft = [{"length": 0.5, "outer_diameter": 0.04, "material": "steel", "elements": 5,
                  "layers": [layer], **tube} for _ in range(2)]
        return build_system(parse_rig({
            "rotor": {"beam": "timoshenko", **rotor},
            "materials": {"steel": {"E": E, "rho": RHO, "nu": NU}},
            "shaft": shaft}))

    damping = {"rayleigh_alpha": alpha, "rayleigh_beta": beta}
    a, b = layered(damping, {}).poles(), layered({}, damping).poles()
    bend = [x[np.abs(x.imag) > 1.0] for x in (a, b)]
    x, y = (p[np.argsort(p.imag, kind="stable")] for p in bend)
    np.testing.assert_allclose(y, x, rtol=1e-9)
    # rigid-body (0, −α) and overdamped modes: real
    real = [np.sort(x[np.abs(x.imag) <= 1.0].real) for x in (a, b)]
    np.testing.assert_allclose(real[1], real[0], rtol=1e-9, atol=1e-9 * np.abs(a).max())


def test_coupling_element_two_body_frequencies_and_nothing_inside():
    """A flexible coupling alone (two rigid halves m1, m2, Id1, Id2 joined by kt_x, kt_y,
    kr_x, kr_y) has the two-body frequencies ω² = k(1/m1 + 1/m2) in x and y and
    ω² = kr(1/Id1 + 1/Id2) about x and y, besides four rigid-body zeros; a rig with a disk
    inside a coupling section is refused naming it, and a rig with a coupling reads back
    from its dumped TOML unchanged."""
    from ambseal.config import dump_rig
    from ambseal.errors import ConfigError
    from ambseal.model.fe import CouplingElement

    c = CouplingElement(0.2, m_left=3.0, m_right=5.0, Id_left=0.02, Id_right=0.04,
                        kt_x=1e6, kt_y=4e5, kr_x=3e4, kr_y=1e4)
    w = np.sort(np.sqrt(np.clip(sla.eigh(c.K(), c.M(), eigvals_only=True), 0, None)))
    ref = np.sort(np.concatenate([np.zeros(4), np.sqrt([
        1e6 * (1 / 3 + 1 / 5), 4e5 * (1 / 3 + 1 / 5), 3e4 * (1 / 0.02 + 1 / 0.04),
        1e4 * (1 / 0.02 + 1 / 0.04)])]))
    np.testing.assert_allclose(w, ref, rtol=1e-10, atol=1e-4)  # (zeros to rounding)
    coupling = {"m_left": 3.0, "m_right": 5.0, "Ip_left": 0.04, "kt_x": 1e6, "kt_y": 1e6,
                "kr_x": 3e4, "kr_y": 3e4}
    shaft = [{"length": 0.3, "outer_diameter": 0.05, "material": "steel", "elements": 3},
             {"length": 0.2, "outer_diameter": 0.08, "material": "steel",
              "coupling": coupling},
             {"length": 0.3, "outer_diameter": 0.05, "material": "steel", "elements": 3}]
    data = {"materials": {"steel": {"E": E, "rho": RHO, "nu": NU}}, "shaft": shaft}
    cfg = parse_rig(data)
    assert parse_rig(__import__("tomllib").loads(dump_rig(cfg))) == cfg
    assert assemble_rotor(cfg).mass == pytest.approx(cfg.shaft[0].length * 2 * RHO * np.pi
                                                     * 0.05 ** 2 / 4 + 8.0, rel=1e-12)
    with pytest.raises(ConfigError, match=r"shaft\[1\]\.coupling: a component at z = 0.4 m"):
        build_system(parse_rig({**data, "disk": [{"position": 0.4, "mass": 1.0}]}))


def test_seal_cross_coupling_destabilises_forward_whirl():
    """Childs' convention (−f = [K k; −k K] q + ...): a positive k pushes the rotor round in
    the direction of rotation, so it takes damping from the forward-whirl mode and gives it
    to the backward one (Childs, *Turbomachinery Rotordynamics*, 1993, §3.2). The seal sits
    at the disk of a symmetric rotor: the cylindrical pair, whose whirl direction is read
    from the eigenvector at the disk (forward: y lags x by 90°, v_y/v_x = −j)."""
    springs = [{"position": z, "kxx": 1e6, "kyy": 1e6, "cxx": 300.0, "cyy": 300.0}
               for z in (0.0, 0.4)]
    data = {
        "materials": {"s": {"E": 2.1e11, "rho": RHO, "nu": NU}},
        "shaft": [{"length": 0.4, "outer_diameter": 0.05, "material": "s", "elements": 4}],
        "disk": [{"position": 0.2, "mass": 20.0, "Ip": 0.4, "Id": 0.2}],
        "spring": springs,
        "seal": [{"name": "s", "position": 0.2, "k": 0.0}],
    }

    def cylindrical(k):
        data["seal"][0]["k"] = k
        sys_ = build_system(parse_rig(data), speed_rpm=1000.0)
        node = sys_.mesh.node_at(0.2)
        lam, V = np.linalg.eig(sys_.state_matrices()[0])
        out = {}
        for i in np.nonzero((lam.imag > 100) & (lam.imag < 500))[0]:
            ratio = V[4 * node + 1, i] / V[4 * node, i]
            out["forward" if ratio.imag < 0 else "backward"] = lam[i]
        return out

    base, pushed = cylindrical(0.0), cylindrical(2e5)
    assert set(base) == set(pushed) == {"forward", "backward"}
    assert pushed["forward"].real > base["forward"].real + 5.0
    assert pushed["backward"].real < base["backward"].real - 5.0


def test_layers_add_like_one_tube_for_euler_bernoulli():
    """Reference: for Euler–Bernoulli beams (Φ = 0) the element matrices are linear in EI,
    ρA and ρI, so a core and a sleeve of one material touching at d = 60 mm are the single
    tube 0–80 mm: the same modes to 1e-9, round-off (a layer's matrices add to its
    section's)."""
    base = {"rotor": {"beam": "euler-bernoulli"},
            "materials": {"s": {"E": E, "rho": RHO, "nu": NU}},
            "spring": [{"position": 0.0, "kxx": 1e7, "kyy": 2e7},
                       {"position": 0.6, "kxx": 1e7, "kyy": 2e7}]}
    layered = parse_rig(base | {"shaft": [{
        "length": 0.6, "outer_diameter": 0.06, "material": "s", "elements": 6,
        "layers": [{"outer_diameter": 0.08, "inner_diameter": 0.06, "material": "s"}]}]})
    solid = parse_rig(base | {"shaft": [{"length": 0.6, "outer_diameter": 0.08,
                                          "material": "s", "elements": 6}]})
    a, b = (np.sort(build_system(c).poles().imag) for c in (layered, solid))
    assert len(a) == 56 and a == pytest.approx(b, rel=1e-9)


def test_rotary_inertia_off_is_the_bernoulli_beam_and_gyroscopic_off_has_no_split():
    """A pinned–pinned stubby shaft (L/D = 10) of E–B elements: with ``rotary_inertia =
    false`` the FE frequencies converge from above to Bernoulli's (nπ)²/(2πL²)·√(EI/ρA)
    (Rayleigh–Ritz with consistent mass; within 1e-4 on 20 elements); with it, Rayleigh's
    beam lies below Bernoulli's (f/f_B ≈ 1 − (nπ r_g/L)²/2, r_g² = I/A = D²/16). At
    6000 rpm the gyroscopic matrix splits each pair into backward and forward whirl;
    ``gyroscopic = false`` leaves the pairs whole."""
    length, d = 0.5, 0.05
    f_b = eb_hz(np.pi * np.arange(1, 4), length, d)

    def hz(**opts):
        r = assemble_rotor(beam_rig("euler-bernoulli", length=length, d=d, n=20,
                                    shaft=[{"length": length, "outer_diameter": d,
                                            "material": "steel", "elements": 20, **opts}]))
        n = r.K.shape[0]
        keep = [i for i in range(n) if i not in (0, 1, n - 4, n - 3)]
        return undamped_hz(r.K, r.M, keep)[::2][:3], r

    bare, r_bare = hz(rotary_inertia=False)
    assert np.all(bare >= f_b) and bare == pytest.approx(f_b, rel=1e-4)
    rayleigh, _ = hz()
    shift = 1 - rayleigh / f_b
    expected = 0.5 * (np.pi * np.arange(1, 4) * d / 4 / length) ** 2
    assert shift == pytest.approx(expected, rel=0.05)
    assert np.any(r_bare.G)  # the spin's polar inertia stays without the diametral one

    def split(**opts):
        cfg = beam_rig("euler-bernoulli", length=length, d=d,
                       shaft=[{"length": length, "outer_diameter": d, "material": "steel",
                               "elements": 10, **opts}],
                       spring=[{"position": z, "kxx": 1e8, "kyy": 1e8} for z in (0, length)])
        w = np.sort(build_system(cfg, speed_rpm=6000.0).poles().imag)
        w = w[w > 1.0][:2]
        return w[1] - w[0]

    assert split() > 1.0 and split(gyroscopic=False) < 1e-3


def test_axial_force_shifts_the_pinned_modes_and_torque_is_circulatory():
    """Pinned–pinned E–B shaft under an axial force P: f_n = f_n0 √(1 + P/P_n), P_n =
    (nπ)²EI/L² (Blevins Table 8-1, beam with axial load; Euler's load for n = 1), within
    1e-3 on 20 elements, in tension and in compression. Under torque alone the matrix has
    the circulatory skew part (±T/2 between the rotations) that makes the shaft's
    stiffness non-symmetric; the structural damping, set on the conservative part, stays
    symmetric."""
    length, d = 1.0, 0.02
    inertia = np.pi * d**4 / 64
    p_n = (np.pi * np.arange(1, 4)) ** 2 * E * inertia / length**2
    f0 = eb_hz(np.pi * np.arange(1, 4), length, d)
    for frac in (0.5, -0.5):
        P = frac * p_n[0]
        r = assemble_rotor(beam_rig("euler-bernoulli", shaft=[{
            "length": length, "outer_diameter": d, "material": "steel", "elements": 20,
            "rotary_inertia": False, "axial_force": P}]))
        n = r.K.shape[0]
        keep = [i for i in range(n) if i not in (0, 1, n - 4, n - 3)]
        f = undamped_hz(r.K, r.M, keep)[::2][:3]
        assert f == pytest.approx(f0 * np.sqrt(1 + P / p_n), rel=1e-3)
    twisted = assemble_rotor(beam_rig("timoshenko", shaft=[{
        "length": length, "outer_diameter": d, "material": "steel", "elements": 4,
        "torque": 50.0}], rotor={"modal_damping": 0.01}))
    skew = twisted.K - twisted.K.T
    assert np.abs(skew).max() == pytest.approx(50.0, rel=1e-12)  # ±T/2 on both sides
    assert np.allclose(twisted.C, twisted.C.T)


def test_conical_element_is_the_frustum_and_converges_with_stepped_uniform_elements():
    """Genta & Gugliotta's conical element: its mass is the frustum's ρπL/12·(D₁² + D₁D₂ +
    D₂²) to 1e-14; as the taper vanishes its matrices become the uniform element's
    closed forms (to 1e-6 at a taper of 1e-6). A steep pinned cone (100 mm to 10 mm over
    0.5 m, Timoshenko): 256 conical elements and 256 uniform steps of the mid-element
    diameter, two different discretisations of the same shaft, give its first three
    natural frequencies within 3e-4 of each other; four conical elements (ROSS's mesh of
    this cone) lie 4–7 % above — the interpolation's error, not the geometry's."""
    from ambseal.model.fe import BeamElement

    cone = BeamElement(0.5, 0.1, 0.02, E, E / 2.6, RHO, outer_diameter_right=0.04,
                       inner_diameter_right=0.01)
    frustum = RHO * np.pi * 0.5 / 12 * ((0.1**2 + 0.1 * 0.04 + 0.04**2)
                                        - (0.02**2 + 0.02 * 0.01 + 0.01**2))
    assert cone.tapered and cone.mass == pytest.approx(frustum, rel=1e-14)
    uniform = BeamElement(0.3, 0.05, 0.01, E, E / 2.6, RHO)
    nearly = BeamElement(0.3, 0.05, 0.01, E, E / 2.6, RHO,
                         outer_diameter_right=0.05 * (1 + 1e-6))
    for f in ("M", "K", "G"):
        a, b = getattr(uniform, f)(), getattr(nearly, f)()
        assert np.abs(a - b).max() <= 4e-6 * np.abs(a).max()

    def pinned(shaft):
        r = assemble_rotor(parse_rig({"materials": {"s": {"E": E, "rho": RHO, "nu": NU}},
                                      "shaft": shaft}))
        n = r.K.shape[0]
        keep = [i for i in range(n) if i not in (0, 1, n - 4, n - 3)]
        return undamped_hz(r.K, r.M, keep)[::2][:3]

    def conical(n):
        return pinned([{"length": 0.5, "outer_diameter": 0.1, "outer_diameter_right": 0.01,
                        "material": "s", "elements": n}])

    steps = (0.1 + (0.01 - 0.1) * (np.arange(256) + 0.5) / 256).tolist()
    stepped = pinned([{"length": 0.5 / 256, "outer_diameter": d, "material": "s"}
                      for d in steps])
    fine = conical(256)
    assert fine == pytest.approx(stepped, rel=3e-4)
    assert np.all(conical(4) / fine - 1 > 0.03) and np.all(conical(4) / fine - 1 < 0.07)


@pytest.mark.parametrize(("extra", "words"), [
    ({"inner_diameter": 0.03, "outer_diameter_right": 0.02}, "inner_diameter_right"),
    ({"outer_diameter_right": 0.0}, "shaft[0].outer_diameter_right"),
    ({"axial_force": 1e12}, "shaft[0].axial_force"),
    ({"torque": True}, "shaft[0].torque"),
    ({"rotary_inertia": 1}, "shaft[0].rotary_inertia"),
    ({"outer_diameter_right": 0.03, "layers": [{"outer_diameter": 0.06,
      "inner_diameter": 0.05, "inner_diameter_right": 0.02, "material": "steel"}]},
     "overlap at the right end"),
])
def test_bad_tube_options_are_refused_naming_the_key(extra, words):
    """A bore wider than the outside at the tapered end, a zero diameter, a force beyond
    the bound, a boolean for a number or a number for a flag, layers that cross at the
    right end: one error that names the key."""
    from ambseal.errors import ConfigError

    with pytest.raises(ConfigError) as info:
        beam_rig("timoshenko", shaft=[{"length": 1.0, "outer_diameter": 0.05,
                                       "material": "steel", **extra}])
    assert words in str(info.value) and "\n" not in str(info.value)


def test_spring_housing_two_mass_closed_form():
    """A near-rigid rotor (E = 1e15 Pa) on two springs k1, each to a housing of mass m_h
    held by k2 to ground (``[[spring]] housing``): its bouncing modes in x are those of
    two masses, m_r and 2 m_h, joined by 2 k1 with 2 k2 to ground (closed form of the 2×2
    problem) to 1e-5 (the shaft's flexibility, (ω/ω_bending)², and the eigensolver's
    rounding, ε·λ_max/λ, together about 1e-6 there), and y's likewise with the y
    stiffnesses;
    without the housings, each spring to ground, the rig's modes are those of the rotor on
    k1 alone; each journal carries half the rotor's weight; the housing's DOFs follow
    the shaft's in the plant's states; a rig with a housing reads back from its TOML."""
    from ambseal.analysis.signoff.unbalance_api617 import journal_loads
    from ambseal.config import dump_rig
    from ambseal.model.rig import mechanical_plant

    k1 = {"x": 2e6, "y": 1.2e6}
    k2 = {"x": 5e6, "y": 3e6}
    m_h = 7.0
    house = {"mass": m_h, "kxx": k2["x"], "kyy": k2["y"], "cxx": 0.0}
    data = {
        "rotor": {"beam": "timoshenko"},
        "materials": {"rigid": {"E": 1e15, "rho": RHO, "nu": NU}},
        "shaft": [{"length": 0.6, "outer_diameter": 0.08, "material": "rigid", "elements": 6}],
        "spring": [{"name": f"B{i}", "position": z, "kxx": k1["x"], "kyy": k1["y"],
                    "housing": house} for i, z in enumerate((0.0, 0.6))],
    }
    cfg = parse_rig(data)
    sys_ = build_system(cfg, speed_rpm=0.0)
    m_r = assemble_rotor(cfg).mass
    assert sys_.n_dof == sys_.mesh.n_dof + 4
    w = 2 * np.pi * undamped_hz(sys_.K, sys_.M)
    for axis in ("x", "y"):
        a, b = 2 * k1[axis], 2 * k2[axis]
        two = sla.eigh(np.array([[a, -a], [-a, a + b]]), np.diag([m_r, 2 * m_h]),
                       eigvals_only=True)
        for w_ref in np.sqrt(two):
            assert np.min(np.abs(w - w_ref)) <= 1e-5 * w_ref
    bare = parse_rig({**data, "spring": [{k: v for k, v in s.items() if k != "housing"}
                                         for s in data["spring"]]})
    sys_bare = build_system(bare, speed_rpm=0.0)
    w = 2 * np.pi * undamped_hz(sys_bare.K, sys_bare.M)
    for axis in ("x", "y"):
        w_ref = np.sqrt(2 * k1[axis] / m_r)
        assert np.min(np.abs(w - w_ref)) <= 1e-5 * w_ref
    # statics: each journal carries half the rotor's weight, the housings' their own
    assert [w for _, w in journal_loads(cfg)] == pytest.approx([m_r / 2] * 2, rel=1e-6)
    states = mechanical_plant(sys_).state_names
    assert states[sys_.mesh.n_dof:sys_.n_dof] == (
        "B0_housing_x", "B0_housing_y", "B1_housing_x", "B1_housing_y")
    assert parse_rig(tomllib.loads(dump_rig(cfg))) == cfg
