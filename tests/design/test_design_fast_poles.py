"""What removing a design's fast poles costs it (``design_rise``), on the test rig's μ."""

from __future__ import annotations

import numpy as np
import pytest


def test_the_mu_rise_reads_the_upper_bound_without_computing_a_lower_one(
        monkeypatch, testrig_designs):
    """Reference: the structured singular value's upper bound of the same loop on the same
    grid (``mussv``, whose lower bound does not change it). ``design_rise`` reads only that
    bound, so the power iterations behind the lower bound, whose cost on a mixed structure
    is about that of the upper bound, must not run."""
    import ambseal.robust.mu as mu
    from ambseal.design import design_rise
    from ambseal.robust import mussv

    r = testrig_designs["mu"]
    K_red = r.K  # the rise of the controller itself: μ on the grid against the refined peak
    ref = float(np.max(mussv(r.plant.closed_loop(K_red), r.plant.blocks, r.omega,
                             peak=False).upper))

    def refused(*args, **kw):
        raise AssertionError("design_rise computed μ's lower bound")

    monkeypatch.setattr(mu, "_lower_bound", refused)
    out = design_rise(r, K_red, r.omega)
    assert out["mu"] == pytest.approx(ref, rel=1e-12)
    assert out["mu_full"] == pytest.approx(r.mu, rel=1e-12)
    # the grid's largest bound lies at or below the peak refined between its points
    assert out["rise"] <= 1e-6
