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
    σ̄; here diagonal peaks 2.9/3.2 (A, B) and σ̄ 4.2 (C); unstable → all D."""
    pk = SensitivityPeaks(Peak(4.2, 40.0), (Peak(2.9, 40.0, "A_zeta"), Peak(3.2, 41.0, "B_eta")))
    a = iso.iso_assessment(pk)
    assert a.zone_sigma_max == "C"
    assert a.zones_per_axis == (("A_zeta", "A"), ("B_eta", "B"))
    assert a.zone_per_axis_worst == "B"
    d = a.to_dict()
    assert json.loads(json.dumps(d))["zones_per_axis"] == {"A_zeta": "A", "B_eta": "B"}
    u = iso.iso_assessment(pk, stable=False)
    assert (u.zone_sigma_max, u.zone_per_axis_worst, u.stable) == ("D", "D", False)
    assert u.to_dict()["sigma_max_peak"] == "inf"


@pytest.mark.parametrize(("limit", "lower", "upper"), [(3.0, "A", "B"), (4.0, "B", "C"),
                                                      (5.0, "C", "D")])
def test_a_peak_within_its_accuracy_of_a_limit_is_on_the_boundary(limit, lower, upper):
    """Reference: ISO 14839-3:2006's limits (3, 4, 5) on a peak known to 0.1 % (the grid's
    resolution of a resonance's peak): 0.2 % below a limit is the lower zone, 0.2 % above
    the upper (:func:`iso.iso_zone` as the standard reads), and from 0.09 % below to
    0.09 % above — the limit itself included, and 3.0004 on the A/B limit — the boundary
    of both, so that a peak rounded to either side of the limit on another machine reads
    the same."""
    both = f"{lower}/{upper}"
    assert iso.graded_zone(limit * (1 - 2e-3)) == lower == iso.iso_zone(limit * (1 - 2e-3))
    for x in (limit * (1 - 9e-4), np.nextafter(limit, 0.0), limit, limit * (1 + 9e-4)):
        assert iso.graded_zone(x) == both
    assert iso.graded_zone(limit * (1 + 2e-3)) == upper == iso.iso_zone(limit * (1 + 2e-3))
    pk = SensitivityPeaks(Peak(limit * (1 + 1.3e-4), 40.0),
                          (Peak(limit * (1 - 1e-4), 40.0, "A_zeta"),
                           Peak(limit * 0.5, 40.0, "A_eta")))
    a = iso.iso_assessment(pk)
    assert a.zone_sigma_max == both and a.zones_per_axis[0] == ("A_zeta", both)
    assert a.zone_per_axis_worst == both
    # the worst of several: a boundary is worse than its lower zone, better than its upper
    assert iso.worst_zone([lower, both]) == both and iso.worst_zone([both, upper]) == upper
    assert iso.zone_sides(both) == (lower, upper)
    assert iso.graded_zone(3.0004) == "A/B"
    assert iso.boundary_note("A/B", 3.0004) == " (on the boundary: σ̄ 3.0004 against 3.0)"
    assert iso.boundary_note("B", 3.2) == ""
    assert iso.zone_words("A/B") == ("on the boundary of A (as good as newly commissioned) "
                                     "and B (fit for unrestricted long-term operation)")
