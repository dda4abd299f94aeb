"""Tests of ambseal.analysis.iso: ISO 14839-3 zone limits, exactly at the boundaries."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest

from ambseal.analysis import iso
from ambseal.analysis.loops import Peak, SensitivityPeaks
from ambseal.errors import ModelError


@pytest.mark.parametrize(
    ("peak", "zone"),
    [(0.0, "A"), (1.0, "A"), (np.nextafter(3.0, 0.0), "A"), (3.0, "B"), (3.5, "B"),
     (np.nextafter(4.0, 0.0), "B"), (4.0, "C"), (np.nextafter(5.0, 0.0), "C"), (5.0, "D"),
     (50.0, "D"), (math.inf, "D")],
)
def test_zone_boundaries(peak, zone):
    """Reference: ISO 14839-3:2006 Table (A < 3, B < 4, C < 5, D ≥ 5), cited in P5 §4.1 item 4
    and §4.3; a peak exactly on a limit belongs to the upper zone."""
    assert iso.iso_zone(peak) == zone


def test_zone_limits_in_db():
    """Reference: ISO 14839-3 quotes the limits as 9.5, 12 and 14 dB (P5 §4.3: '3 (or 9.5 dB)')."""
    np.testing.assert_allclose(iso.zone_limit_db(), [9.5, 12.0, 14.0], atol=0.05)


@pytest.mark.parametrize("bad", [-0.1, float("nan")])
def test_invalid_peaks_raise(bad):
    """Reference: a sensitivity peak is a non-negative gain; NaN or negative (dB passed by
    mistake) must raise ModelError."""
    with pytest.raises(ModelError):
        iso.iso_zone(bad)


def test_assessment_per_axis_and_sigma_max():
    """Reference: P5 §4.1 item 4 — the standard grades each diagonal element, the thesis grades
    σ̄; here diagonal peaks 2.9/3.0 (A, B) and σ̄ 4.0 (C); unstable → all D."""
    pk = SensitivityPeaks(Peak(4.0, 40.0), (Peak(2.9, 40.0, "A_zeta"), Peak(3.0, 41.0, "B_eta")))
    a = iso.iso_assessment(pk)
    assert a.zone_sigma_max == "C"
    assert a.zones_per_axis == (("A_zeta", "A"), ("B_eta", "B"))
    assert a.zone_per_axis_worst == "B"
    d = a.to_dict()
    assert json.loads(json.dumps(d))["zones_per_axis"] == {"A_zeta": "A", "B_eta": "B"}
    u = iso.iso_assessment(pk, stable=False)
    assert (u.zone_sigma_max, u.zone_per_axis_worst, u.stable) == ("D", "D", False)
    assert u.to_dict()["sigma_max_peak"] == "inf"
