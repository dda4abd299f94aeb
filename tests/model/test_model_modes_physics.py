"""Rigid-body modes and unstable poles rest on the physics, not on the stiffest DOF.

A stiff pin, a disk a few micrometres off a node and a finer mesh spread the model's
eigenvalues over more decades; none of them may change which poles count as unstable or
rigid.
"""

import copy
import dataclasses
import tomllib

import numpy as np
import pytest

from ambseal.analysis.judge import unstable_open_loop_poles
from ambseal.config import parse_rig
from ambseal.errors import ModelError
from ambseal.model.modes import _real_part_rounding, classify_poles, modes
from ambseal.model.rig import build_plant, build_system
from ambseal.model.rotor import X, Y, dof

from ..conftest import ROOT

RTOL = 1e-6


@pytest.fixture(scope="module")
def testrig():
    return tomllib.loads((ROOT / "examples" / "testrig.toml").read_text())


def _poles(data: dict, **kw) -> np.ndarray:
    """Unstable poles, then the four lowest modes (the rigid-body modes on the AMBs, the
    lowest near 3.5 Hz) as [Re λ, Im λ] rows."""
    res = modes(build_system(parse_rig(copy.deepcopy(data)), **kw))
    return _with_low_modes(res)


def _with_low_modes(res) -> np.ndarray:
    w = 2 * np.pi * np.asarray(res.natural_frequencies_hz[:4])
    z = np.asarray(res.damping_ratios[:4])
    low = np.c_[-z * w / np.sqrt(1 - z**2), w]
    return np.vstack([np.array(res.unstable_poles).reshape(-1, 2), low])


def _assert_same(poles, ref):
    """Same poles (as sets of complex numbers) within RTOL relative."""
    got = poles[:, 0] + 1j * poles[:, 1]
    want = ref[:, 0] + 1j * ref[:, 1]
    assert got.shape == want.shape
    for a, b in ((got, want), (want, got)):  # each has its twin in the other set
        dist = np.abs(a[:, None] - b[None, :]).min(axis=1)
        assert np.all(dist <= RTOL * np.abs(a)), (dist / np.abs(a)).max()


def test_stiff_pin_equals_the_exactly_pinned_model(testrig):
    """A 1e16 N/m spring at the free end against the exact constraint (the x and y DOFs of
    that node removed from M, C, G, K): the pin's compliance 1e-16 m/N is 1e-8 of the
    shaft's, so both have the same unstable poles to 1e-6. The relative thresholds of old
    counted the +236.8 ± 51.8j rad/s pair as rigid (1e-6·max|λ| = 254 rad/s) and printed
    'no unstable poles'; the four lowest modes agree as well."""
    data = copy.deepcopy(testrig)
    data["spring"].append({"name": "pin", "position": 0.86, "kxx": 1e16, "kyy": 1e16})
    pinned = _poles(data)
    sys = build_system(parse_rig(copy.deepcopy(testrig)))
    last = sys.mesh.n_nodes - 1
    keep = np.setdiff1d(np.arange(sys.n_dof), [dof(last, X), dof(last, Y)])
    sub = {k: getattr(sys, k)[np.ix_(keep, keep)] for k in "MCGK"}
    constrained = dataclasses.replace(sys, **sub, B=sys.B[keep], Cq=sys.Cq[:, keep])
    ref = _with_low_modes(modes(constrained))
    assert len(ref) == 4 + 4
    _assert_same(pinned, ref)
    # the full plant (actuators included) gives the metrics.json open-loop poles the same way
    full = build_plant(parse_rig(copy.deepcopy(data)))
    assert len(unstable_open_loop_poles(full.A)) == 4


def test_off_node_disk_and_fine_mesh_keep_the_poles(testrig):
    """A disk 10 µm off its node (a 10 µm beam element, max|λ| 2e7 rad/s) moves the unstable
    poles by O(δ) only: the mean of the poles at ±10 µm equals the unmodified model's to
    1e-6 (the O(δ) terms cancel; measured 2e-8). A mesh 3× finer gives the unmodified
    model's unstable poles to 1e-6 (the rigid-body motion converges with the mesh). The
    lowest modes (3.5 Hz, dropped by the old threshold 1e-6·max|λ| = 22 rad/s) stay too."""
    ref = _poles(testrig)
    assert len(ref) == 4 + 4 and ref[4, 1] / (2 * np.pi) == pytest.approx(3.48, abs=0.01)
    shifted = []
    for dz in (10e-6, -10e-6):
        data = copy.deepcopy(testrig)
        data["disk"][0]["position"] += dz
        shifted.append(_poles(data))
    _assert_same((shifted[0] + shifted[1]) / 2, ref)
    fine = copy.deepcopy(testrig)
    for sec in fine["shaft"]:
        sec["elements"] *= 3
    _assert_same(_poles(fine), ref)


def test_rigid_body_modes_survive_stiff_elements(testrig):
    """A free–free rotor has 8 eigenvalues at 0 (x, y, α, β, each a double root of λ²;
    Friswell et al. 2010 §5.2) however fine its mesh or short an element; they are not
    reported as modes, and the lowest bending mode stays the unmodified one."""
    free = dict(include_amb=False, include_seals=False, include_springs=False)
    base = modes(build_system(parse_rig(copy.deepcopy(testrig)), **free))
    data = copy.deepcopy(testrig)
    data["disk"][0]["position"] += 10e-6
    res = modes(build_system(parse_rig(data), **free))
    for r in (base, res):
        rigid = classify_poles(r.poles)[0]
        assert rigid.sum() == 8
        assert not r.unstable_poles
    assert res.natural_frequencies_hz[0] == pytest.approx(base.natural_frequencies_hz[0],
                                                          rel=1e-4)


def test_doubtful_conditioning_is_refused():
    """Eigenvalues within √ε·max|λ| of zero cannot be told from rigid-body modes (Moro,
    Burke & Overton 1997: a double zero eigenvalue splits by that much); a model whose
    low modes lie there is refused with the reason."""
    lam = np.array([1e10j, -1e10j, 50 + 10j, 50 - 10j])
    with pytest.raises(ModelError, match="cannot be told from a rigid-body mode"):
        classify_poles(lam, where="x.toml")
    rigid, unstable = classify_poles(np.array([1e-3, 0.1 + 2e3j, 0.1 - 2e3j, -5.0]))
    assert rigid.tolist() == [True, False, False, False]
    assert unstable.tolist() == [False, True, True, False]


def test_a_conservative_gyroscopic_rotor_has_no_unstable_pole():
    """A free–free rotor without damping at speed is conservative: every pole lies on the
    imaginary axis (Friswell et al. 2010, §3.5: M, K symmetric, G skew, no damping). The
    supercritical example's rotor, free at 3 000 rpm, has a slow gyroscopic pole next to its
    rigid-body double zeros that the dense solver puts at Re λ = +4.6e-6 rad/s with one
    BLAS's kernels (Haswell), above the 1e-6 floor, and at −2.5e-6 with another's
    (SkylakeX); within its rounding (κ ≈ 3e5: the first-order bound 1e-2 rad/s) it is
    neutral either way, not a growth, and no positive rounding is left. A rotor with
    a true growth keeps it: cross-coupled springs (kxy = −kyx = 1 kN/m on 1 N·s/m of
    damping) drive a forward mode to Re λ = +0.025 rad/s (a negative damping ratio of
    3e-5, itself marginal), stable without the cross-coupling."""
    d = tomllib.loads((ROOT / "examples" / "supercritical_rotor.toml").read_text())
    free = {k: v for k, v in d.items() if k in ("rotor", "materials", "shaft", "disk")}
    free["rotor"] = {**free["rotor"], "modal_damping": 0.0}
    free["operating"] = {"speed_rpm": 3000.0}
    system = build_system(parse_rig(free))
    res = modes(system)
    assert res.unstable_poles == ()
    slow = res.poles[np.abs(res.poles - 8.12j) < 0.05]
    # neutral: its real part is rounding, of either sign, and not left positive
    bound = _real_part_rounding(system.state_matrices()[0], slow)[0]
    assert slow.size == 1 and -bound <= slow[0].real <= 0.0

    # a weak true growth: a small cross-coupling on a light damper
    L = sum(s["length"] for s in free["shaft"])
    springs = [{"position": z, "kxx": 1e6, "kyy": 1e6, "cxx": 1.0, "cyy": 1.0}
               for z in (0.0, L)]
    free["spring"] = springs
    damped = modes(build_system(parse_rig(free)))
    assert damped.unstable_poles == ()
    free["spring"] = [{**s, "kxy": 1e3, "kyx": -1e3} for s in springs]
    grow = modes(build_system(parse_rig(free)))
    assert grow.unstable_poles and 1e-5 < grow.unstable_poles[0][0] < 1.0
