"""The plausibility rules of an identification (ambseal.identify.fitting.plausibility), each checked
against its statement in the module docstring on the embedded rig (A: Ki_ζ 199.2 N/A,
Ks_ζ 2.39e6 N/m; coupling kxx 0.40e6 N/m; the seal's k affine in the pressure drop)."""

import math

import numpy as np
import pytest

from ambseal.config import load_rig, parse_rig
from ambseal.errors import IdentificationError
from ambseal.identify.fitting.plausibility import (RATIO, first_nonfinite, implausible,
                                           require_finite)


@pytest.fixture(scope="module")
def cfg():
    return load_rig()


def _one(cfg, name, v, lo, hi):
    return implausible(cfg, [name], [v], [lo], [hi])


def test_force_factors_within_ten_times_of_the_rig_file(cfg):
    """Ki and Ks: 1/10 … 10× the rig file's value passes, beyond (a unit slip) does not,
    and a sign change is outside the ratio."""
    assert _one(cfg, "A.Ki_zeta", 199.2 * 9.9, 1900, 2040) == []
    assert _one(cfg, "A.Ks_zeta", 2.39e6 / 9.9, 2.2e5, 2.6e5) == []
    (r,) = _one(cfg, "A.Ki_zeta", 199.2 * 1000, 1.9e5, 2.1e5)
    assert r.startswith("A.Ki_zeta:") and "is 1000×" in r and f"{RATIO:g}×" in r
    assert _one(cfg, "A.Ks_eta", -2.49e6, -2.6e6, -2.4e6)
    assert _one(cfg, "coupling.kxx", 0.40e6 * 20, 7.9e6, 8.1e6)  # a support's direct term


def test_an_interval_wider_than_its_estimate(cfg):
    """Width ≥ |estimate|: the records do not determine the value."""
    assert _one(cfg, "A.Ki_zeta", 200.0, 101.0, 299.0) == []
    (r,) = _one(cfg, "A.Ki_zeta", 200.0, 99.0, 301.0)
    assert "wider than the estimate" in r


def test_kinds_without_a_scale_are_judged_for_finiteness_only(cfg):
    """Seal coefficients, cross-coupled support terms and the lags: zero and either sign are
    physical; a Ks of 0 in the rig file gives no scale either."""
    assert _one(cfg, "seal.k", -3.0e3, -9e5, 9e5) == []
    assert _one(cfg, "tau_e", 1e-5, -1e-3, 1e-3) == []
    assert _one(cfg, "seal.k", math.nan, 0.0, 1.0)
    assert _one(cfg, "A.Ki_zeta", 200.0, -math.inf, 300.0)
    data = cfg.model_dump(exclude_none=True)
    data["amb"][0]["ks"] = {"zeta": 0.0, "eta": 2.49e6}
    assert _one(parse_rig(data), "A.Ks_zeta", 5.0, -100.0, 100.0) == []


def test_nonfinite_numbers_are_found_by_their_key():
    tree = {"a": [1.0, {"b": np.float64("nan")}], "c": 2}
    assert first_nonfinite(tree) == "a[1].b"
    assert first_nonfinite({"a": [1.0, None, "x"]}) is None
    with pytest.raises(IdentificationError, match=r"fit: a\[1\]\.b is not a finite number"):
        require_finite(tree, "fit")
    assert require_finite({"a": 1.0}, "fit") == {"a": 1.0}
