"""The w-plane image of a sampled, delayed generalised plant (ambseal.robust.w_plane),
against SciPy's discretisations and python-control's discrete H∞ norm (SLICOT AB13DD)."""

import control as ct
import numpy as np
import pytest
from scipy.signal import cont2discrete

from ambseal.errors import ConfigError, SynthesisError
from ambseal.robust import hinfnorm, hinfsyn, lft_lower, w_plane_plant


def _plant(seed=0):
    rng = np.random.default_rng(seed)
    A = rng.normal(size=(4, 4)) - 2.0 * np.eye(4)
    return ct.ss(A, rng.normal(size=(4, 3)), rng.normal(size=(3, 4)), rng.normal(size=(3, 3)))


def _response(mats, z):
    A, B, C, D = mats
    return C @ np.linalg.solve(z * np.eye(A.shape[0]) - A, B) + D


@pytest.mark.parametrize("nd", [0, 1, 2])
def test_its_tustin_transform_is_the_zoh_plant_with_its_delay(nd):
    # SciPy's bilinear map of the w-plane plant against SciPy's ZOH of the plant, its two
    # command columns delayed by nd samples: the same discrete system
    P, fs = _plant(), 200.0
    T = 1.0 / fs
    Pw = w_plane_plant(P, 2, fs, nd)
    assert Pw.nstates == 4 + 2 * nd
    assert list(Pw.input_labels) == list(P.input_labels)
    tust = cont2discrete((Pw.A, Pw.B, Pw.C, Pw.D), T, method="bilinear")[:4]
    zoh = cont2discrete((P.A, P.B, P.C, P.D), T, method="zoh")[:4]
    for f in (0.0, 3.0, 31.0, 77.0, 99.0):
        z = np.exp(2j * np.pi * f * T)
        expected = _response(zoh, z)
        expected[:, 1:] *= z ** -nd
        np.testing.assert_allclose(_response(tust, z), expected, rtol=1e-9, atol=1e-12)


def test_a_w_plane_design_is_the_discrete_design_and_keeps_its_norm():
    # a mixed-sensitivity problem on a lightly damped plant sampled at 5 rad/s per sample
    # with one sample of delay: γ of the w-plane design is the H∞ norm of the sampled loop
    # closed by its Tustin transform, by python-control's discrete norm
    G = ct.tf([1.0], [1.0, 0.1, 1.0])
    W1 = ct.tf([0.5, 0.5], [1.0, 0.01])
    W2 = ct.tf([0.1], [1.0])
    P = ct.ss(ct.augw(G, W1, W2))
    fs, nd = 5.0, 1
    T = 1.0 / fs
    Pw = w_plane_plant(P, 1, fs, nd)
    r = hinfsyn(Pw, 1, 1)
    Kd = ct.sample_system(ct.ss(r.K.A, r.K.B, r.K.C, r.K.D), T, method="tustin")
    Pd = ct.sample_system(P, T, method="zoh")
    delay = ct.ss([[0.0]], [[1.0]], [[1.0]], [[0.0]], T)  # z⁻¹ on the command
    Pdel = Pd * ct.append(ct.ss([], [], [], np.eye(Pd.ninputs - 1), T), delay)
    cl = Pdel.lft(Kd, 1, 1)
    assert np.all(np.abs(cl.poles()) < 1.0)
    g_w = hinfnorm(lft_lower(Pw, r.K, 1, 1))[0]
    assert ct.norm(cl, "inf") == pytest.approx(g_w, rel=1e-6)
    assert g_w <= r.gamma * (1 + 1e-9)


def test_an_undamped_mode_at_nyquist_has_no_w_plane_image():
    fs = 100.0
    w = np.pi * fs  # e^{AT} = −I
    P = ct.ss([[0.0, w], [-w, 0.0]], [[0.0], [1.0]], [[1.0, 0.0]], [[0.0]])
    with pytest.raises(SynthesisError, match="z = -1"):
        w_plane_plant(P, 1, fs, 0)


@pytest.mark.parametrize("kw, key", [({"ncon": 0}, "ncon"), ({"ncon": 4}, "ncon"),
                                     ({"sample_rate_hz": 0.0}, "sample_rate_hz"),
                                     ({"delay_samples": 1.5}, "delay_samples")])
def test_bad_arguments_are_refused_by_name(kw, key):
    args = {"ncon": 1, "sample_rate_hz": 100.0, "delay_samples": 1, **kw}
    with pytest.raises(ConfigError, match=key):
        w_plane_plant(_plant(), **args)
