"""The fixed-parameter error budget and the residual tests, against closed forms."""

import numpy as np
import pytest
from scipy.signal import lfilter

from ambseal.config import parse_rig
from ambseal.errors import ConfigError
from ambseal.identify.fitting.budget import DEFAULT_UNCERTAINTY, advice, fixed_uncertainty, propagate
from ambseal.identify.fitting.residuals import residual_tests


def test_sensitivity_to_a_fixed_regressor_closed_form():
    """y = a·x + b·z fitted for a with b held fixed: ∂â/∂b = −(xᵀz)/(xᵀx) (ordinary least
    squares, normal equations), so a relative error σ_b in b adds |b·xᵀz/xᵀx|·σ_b to â's
    standard error."""
    rng = np.random.default_rng(1)
    x, z = rng.standard_normal(500), rng.standard_normal(500) + 0.4
    z = z + 0.6 * x  # correlated regressors
    b, sigma = 3.0, 0.1
    # residual r = y − a x − b z; ∂r/∂a = −x, ∂r/∂(b/b0) = −b z
    bud = propagate(-x[:, None], -b * z[:, None], np.array([1.0]), ["a"], ["b"], [sigma],
                    ["stated"], np.array([0.0]))
    ref = -(x @ z) / (x @ x) * b
    np.testing.assert_allclose(bud.sensitivity[0, 0], ref, rtol=1e-12)
    np.testing.assert_allclose(np.sqrt(bud.covariance[0, 0]), abs(ref) * sigma, rtol=1e-12)
    assert bud.dominant() == ["b"]


def test_correlated_earlier_estimates_monte_carlo():
    """Two-stage least squares as the procedure runs it: (b, c) estimated on a first record
    (correlated regressors, so their errors correlate), then a fitted on a second record with
    b, c held at those estimates. Reference: Monte Carlo over 4000 noise draws of both
    stages — the variance of â equals its noise variance plus the budget G C Gᵀ with C the
    first stage's covariance (correlation included) within 7 % (the Monte Carlo variance's
    own 95 % band is ±4.4 %); with the correlation ignored it is clearly off."""
    rng = np.random.default_rng(3)
    n, s1, s2 = 300, 0.5, 0.2
    z1 = rng.standard_normal(n)
    w1 = 0.9 * z1 + 0.3 * rng.standard_normal(n)
    x = rng.standard_normal(n)
    z, w = 0.5 * x + rng.standard_normal(n), 0.5 * x + rng.standard_normal(n)
    a, b, c = 1.0, 2.0, -1.5
    X1 = np.column_stack([z1, w1])
    cov1 = s1**2 * np.linalg.inv(X1.T @ X1)
    est = []
    for _ in range(4000):
        bc = np.linalg.lstsq(X1, X1 @ [b, c] + s1 * rng.standard_normal(n), rcond=None)[0]
        y2 = a * x + b * z + c * w + s2 * rng.standard_normal(n)
        est.append(x @ (y2 - bc[0] * z - bc[1] * w) / (x @ x))
    sig = np.sqrt(np.diag(cov1)) / np.abs([b, c])
    # correlation of the relative errors Δb/b, Δc/c: c < 0 flips the sign
    rho = cov1[0, 1] / np.sqrt(cov1[0, 0] * cov1[1, 1]) * np.sign(b * c)
    corr = np.array([[1.0, rho], [rho, 1.0]])
    # residual r = y − a x − b z − c w; ∂r/∂(b/b0) = −b z, ∂r/∂(c/c0) = −c w
    args = (-x[:, None], -np.column_stack([b * z, c * w]), np.array([1.0]), ["a"], ["b", "c"],
            sig, ["fit", "fit"], np.array([s2**2 / (x @ x)]))
    with_corr = propagate(*args, correlation=corr, estimated=[True, True])
    total = s2**2 / (x @ x) + with_corr.covariance[0, 0]
    np.testing.assert_allclose(np.var(est), total, rtol=0.07)
    no_corr = s2**2 / (x @ x) + propagate(*args).covariance[0, 0]
    assert abs(no_corr / np.var(est) - 1) > 0.3


def test_rig_file_uncertainty_and_defaults(testrig_cfg):
    """Reference: the documented rule — a stated `uncertainty` wins, else the kind's
    default; `Ks` stands for both axes; an unknown key is refused naming it."""
    data = testrig_cfg.model_dump(exclude_none=True)
    data["spring"][0]["uncertainty"] = {"kxx": 0.02}
    data["amb"][0]["uncertainty"] = {"Ks": 0.01}
    cfg = parse_rig(data)
    names = ["A.Ks_zeta", "A.Ks_eta", "A.Ki_zeta", "coupling.kxx", "coupling.kyy", "seal.k",
             "coupling.cxx", "tau_e"]
    got = fixed_uncertainty(cfg, names, ["A.Ki_zeta"])
    assert "A.Ki_zeta" not in got
    assert got["A.Ks_zeta"][0] == got["A.Ks_eta"][0] == 0.01
    assert got["coupling.kxx"] == (0.02, "spring[coupling].uncertainty")
    assert got["coupling.kyy"][0] == DEFAULT_UNCERTAINTY["spring_stiffness"]
    assert got["coupling.cxx"][0] == DEFAULT_UNCERTAINTY["spring_damping"]
    assert got["seal.k"][0] == DEFAULT_UNCERTAINTY["seal"]
    assert got["tau_e"][0] == DEFAULT_UNCERTAINTY["tau_e"]
    data["seal"][0]["uncertainty"] = {"kk": 0.1}
    with pytest.raises(ConfigError, match=r"seal\[seal\].uncertainty.kk"):
        fixed_uncertainty(parse_rig(data), names, [])


def test_seal_held_fixed_at_pressure_is_told(testrig_cfg):
    """Reference: the error budget's contract — seal coefficients held at their rig values on a record at a
    non-zero pressure drop draw a warning naming them; at 0 bar, or fitted, none."""
    assert any("seal.k" in w and "2.04 bar" in w
               for w in advice(None, testrig_cfg, ["A.Ks_zeta"], [2.04]))
    assert advice(None, testrig_cfg, ["A.Ks_zeta"], [0.0]) == []
    assert advice(None, testrig_cfg, ["seal.K", "seal.k", "seal.C", "seal.c"], [2.04]) == []


def _signals(rng, n=4000):
    """A held random binary excitation (clock 10 samples) and resonant coloured noise
    independent of it."""
    u = np.repeat(rng.choice([-1.0, 1.0], n // 10), 10)[:, None]
    eps = lfilter([1.0], [1.0, -1.9, 0.95], rng.standard_normal(n))
    return eps[:, None], u


def test_residual_tests_size_and_power():
    """Ljung §16.6: for residuals independent of the excitation the statistic is χ²
    distributed, so the 99 % test rejects ≈ 1 % of 200 independent cases (binomial: at
    most 6 at 0.1 % risk); a residual holding a filtered copy of the excitation at a
    fifth of its standard deviation is flagged every time. The coloured residual fails the
    whiteness test, as a closed-loop output-error residual does."""
    rng = np.random.default_rng(7)
    rejected = 0
    for _ in range(200):
        e, u = _signals(rng)
        t = residual_tests([e], [u], ("A",))
        rejected += t.mismatch
    assert rejected <= 6
    assert t.whiteness[0] > t.whiteness_limit[0]
    for _ in range(5):
        e, u = _signals(rng)
        leak = 0.2 * e.std() / lfilter([0.0, 0.3, 0.2], [1.0, -0.9], u[:, 0]).std()
        e_bad = e + leak * lfilter([0.0, 0.3, 0.2], [1.0, -0.9], u[:, 0])[:, None]
        assert residual_tests([e_bad], [u], ("A",)).mismatch


def test_identified_intervals_become_mu_ranges(testrig_cfg, tmp_path):
    """Reference: the interface contract of fit.json — a fit.json's 95 % intervals arrive
    unchanged as the Δ ranges of the generalized plant; tau_e is left out; a fit flagged
    as model mismatch and a missing interval are refused, naming file and key."""
    import json

    from ambseal.design.plant import generalized_plant
    from ambseal.errors import DataError
    from ambseal.identify.fitting.intervals import uncertainty_from_fit

    fit = {"parameters": {"seal.k": {"estimate": 2.2e6, "ci95": [1.9e6, 2.5e6]},
                          "tau_e": {"estimate": 2e-4, "ci95": [1.9e-4, 2.1e-4]}},
           "residual_tests": {"mismatch": False}}
    path = tmp_path / "fit.json"
    path.write_text(json.dumps(fit))
    ranges = uncertainty_from_fit(path)
    assert ranges == {"seal.k": (1.9e6, 2.5e6)}
    gp = generalized_plant(testrig_cfg, 1.0, 1.0, uncertainty=ranges, states=8)
    (q,) = gp.parameters
    assert (q.name, q.low, q.high) == ("seal.k", 1.9e6, 2.5e6)
    fit["residual_tests"]["mismatch"] = True
    path.write_text(json.dumps(fit))
    with pytest.raises(DataError, match="model mismatch"):
        uncertainty_from_fit(path)
    fit["residual_tests"]["mismatch"] = False
    # a disputed fixed value: accepted while its suggested offset lies within the 95 % band
    # of the uncertainty the intervals carry for it (1.96 σ), refused beyond it
    fit["error_budget"] = {"fixed": {"coupling.kxx": {"sigma_rel": 0.05}},
                           "score_test": {"coupling.kxx": {"z": 7.0, "offset_rel": 0.09}},
                           "disputed": ["coupling.kxx"]}
    path.write_text(json.dumps(fit))
    assert uncertainty_from_fit(path) == {"seal.k": (1.9e6, 2.5e6)}
    fit["error_budget"]["score_test"]["coupling.kxx"]["offset_rel"] = -0.11
    path.write_text(json.dumps(fit))
    with pytest.raises(DataError, match=r"error_budget.disputed: model mismatch.*coupling.kxx"):
        uncertainty_from_fit(path)
    del fit["error_budget"]
    fit["parameters"]["seal.k"]["ci95"] = [None, 2.5e6]
    path.write_text(json.dumps(fit))
    with pytest.raises(DataError, match=r"fit.json: parameters.seal.k.ci95"):
        uncertainty_from_fit(path)


def test_facility_model_form_options(testrig_cfg):
    """Reference: the [truth] documentation — the facility's rotor takes the truth's beam
    theory, twice the shaft elements and its modal damping; the rig file stays as it is.
    Euler–Bernoulli (no shear flexibility) gives a higher first free bending mode than
    Timoshenko (Nelson 1980: shear and rotary inertia lower the frequencies)."""
    from ambseal.config import TruthSection
    from ambseal.identify.facility.rig_sim import true_rig
    from ambseal.model.modes import modes
    from ambseal.model.rig import build_system

    truth = TruthSection(beam="euler-bernoulli", mesh_factor=2.0, modal_damping=0.01)
    rig = true_rig(testrig_cfg, truth)
    assert [s.elements for s in rig.shaft] == [2 * s.elements for s in testrig_cfg.shaft]
    assert (rig.rotor.beam, rig.rotor.modal_damping) == ("euler-bernoulli", 0.01)
    assert testrig_cfg.rotor.beam == "timoshenko"

    def first_bending(cfg):
        f = modes(build_system(cfg, include_amb=False, include_seals=False,
                               include_springs=False)).natural_frequencies_hz
        return min(x for x in f if x > 50.0)

    assert first_bending(true_rig(testrig_cfg, TruthSection(beam="euler-bernoulli"))) > \
        first_bending(testrig_cfg)
