"""Bad inputs to the identification stages end in one clear error or a flagged result."""

import numpy as np
import pytest

from ambseal.config import TruthSection, load_rig, parse_rig, rig_with_values
from ambseal.errors import DataError, IdentificationError, ModelError
from ambseal.identify.fitting.fit import _long_run_covariance, fit_parameters
from ambseal.identify.excitation.signals import prbs
from ambseal.design.pid import controller_from_metadata, reference_controller
from ambseal.identify.fitting.stages import acquire, build_models, identify
from ambseal.model.amb import amb_factors

AXES = ("A_zeta", "A_eta", "B_zeta", "B_eta")


@pytest.fixture(scope="module")
def rig():
    return load_rig()


@pytest.fixture(scope="module")
def record(rig):
    ex = prbs(amplitude_a=0.05, clock_period_s=1e-3, duration_s=0.3, sample_rate_hz=1e4, seed=2)
    return acquire(rig, TruthSection(noise_fraction=0.01), ex,
                   controller=reference_controller(rig), pressure_bar=0.0, seed=2)


def test_long_run_covariance_white_residuals_closed_form():
    """White residuals of variance σ²: Var(Σ J_tᵀ r_t) = σ² JᵀJ (the sandwich's middle term
    reduces to the classical one), within the estimator's sampling error."""
    rng = np.random.default_rng(0)
    N, c, p = 20000, 2, 3
    J = rng.standard_normal((N, c, p)) + 0.5  # includes DC content
    R = 0.3 * rng.standard_normal((N, c))
    S = _long_run_covariance(J, R)
    ref = 0.09 * np.einsum("tcp,tcq->pq", J, J)
    np.testing.assert_allclose(np.diag(S), np.diag(ref), rtol=0.1)


def test_controller_sample_time_must_match_the_record():
    """A state-space controller whose dt differs from the record's rate is refused."""
    meta = {"sample_rate_hz": 1e4, "controller": {
        "type": "state_space", "dt": 2e-4, "A": [], "B": [], "C": [],
        "D": np.eye(4).tolist()}}
    with pytest.raises(DataError, match="dt"):
        controller_from_metadata(meta, AXES)


@pytest.mark.parametrize("ctrl,match", [
    ({"type": "pid", "kp": 1.6e4, "ti": 0.0, "td": 3.5e-3, "eps": 0.1}, "ti > 0"),
    ({"type": "state_space", "dt": 1e-4, "A": [], "B": [], "C": [], "D": [[1.0]]}, "4 inputs"),
    ({"type": "lqg"}, "unknown"),
])
def test_bad_controller_metadata(ctrl, match):
    """Reference: interface contract (DESIGN.md errors) — a PID without integral time, a
    controller of the wrong size and an unknown type raise DataError naming the cause."""
    with pytest.raises(DataError, match=match):
        controller_from_metadata({"sample_rate_hz": 1e4, "controller": ctrl}, AXES)


def test_start_outside_bounds_is_refused(rig, record):
    """Reference: interface contract — a start value outside its bounds is refused, not
    clipped silently."""
    with pytest.raises(IdentificationError, match="outside its bounds"):
        fit_parameters([record], build_models(rig, [record]), ["A.Ks_zeta"],
                       bounds={"A.Ks_zeta": (2.0e6, 2.1e6)})


def test_duplicate_parameter_names(rig, record):
    """Reference: interface contract — a parameter named twice is refused, naming it."""
    with pytest.raises(IdentificationError, match="named twice: A.Ki_zeta"):
        fit_parameters([record], build_models(rig, [record]), ["A.Ki_zeta", "A.Ki_zeta"])


def test_estimate_stopped_at_a_bound_is_not_converged(rig, record):
    """A fit pushed onto a bound is flagged, with the parameter named in the message."""
    res = fit_parameters([record], build_models(rig, [record]), ["A.Ks_zeta"],
                         initial={"A.Ks_zeta": 2.05e6},
                         bounds={"A.Ks_zeta": (2.0e6, 2.1e6)})  # the truth is 2.39e6
    assert not res.converged and "A.Ks_zeta" in res.message


def test_facility_refuses_non_positive_ks(rig):
    """Reference: P2 force model — Ks > 0 (negative stiffness magnitude); a truth with
    Ks = 0 is refused naming the parameter."""
    ex = prbs(amplitude_a=0.05, clock_period_s=1e-3, duration_s=0.05, sample_rate_hz=1e4)
    with pytest.raises(ModelError, match="A.Ks_zeta"):
        acquire(rig, TruthSection(parameters={"A.Ks_zeta": 0.0}), ex,
                controller=reference_controller(rig), pressure_bar=0.0)


def test_identified_factor_of_a_geometry_amb_is_kept(rig):
    """An AMB given by geometry: an identified Ki is written as an explicit ki for its axis,
    which wins over the geometry; the geometry still gives the other factors (amb_factors)."""
    data = rig.model_dump(exclude_none=True)
    a = data["amb"][0]
    del a["ki"], a["ks"]
    a.update(turns=36, pole_area=5.5e-3, air_gap=0.5e-3, bias_current=6.0)
    geo = parse_rig(data)
    out = rig_with_values(geo, {"A.Ki_zeta": 300.0})
    ki, ks = amb_factors(out.amb[0])
    assert ki[0] == 300.0 and ks == amb_factors(geo.amb[0])[1]


def test_identify_wraps_unknown_names(rig, record):
    """Reference: interface contract — an unknown parameter name is one
    IdentificationError."""
    with pytest.raises(IdentificationError, match="unknown parameter"):
        identify(rig, [record], ["A.Kq_zeta"])
