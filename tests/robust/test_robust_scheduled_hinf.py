"""H∞ scheduled on a parameter (:func:`ambseal.robust.hinf_scheduled`): each table entry is
the central H∞ controller of its frozen plant at the table's one γ, in the plants' own
state basis. Reference: SLICOT SB10FD (through slycot) on the unbalanced plant at the
same γ — the same matrices, not only the same transfer function — and python-control's
closed loop."""

from __future__ import annotations

import control
import numpy as np
import pytest
from slycot import sb10fd

from ambseal.errors import ConfigError
from ambseal.robust import hinf_scheduled


def _plant(theta: float):
    """Mixed sensitivity (python-control's ``augw``) of an unstable mass on a negative
    stiffness whose damping is θ: the state basis is the same for every θ."""
    G = control.ss([[0.0, 1.0], [1.0, -theta]], [[0.0], [1.0]], [[1.0, 0.0]], [[0.0]])
    W1 = control.ss(control.tf([0.5, 5.0], [1.0, 0.05]))
    W2 = control.ss(control.tf([0.1], [1.0]))
    W3 = control.ss(control.tf([1.0, 0.1], [0.01, 1.0]))
    return control.augw(G, W1, W2, W3)


THETA = (-0.5, 0.0, 1.0, 2.0)


def test_each_entry_is_slicots_central_controller_in_the_plants_own_basis():
    plants = [_plant(t) for t in THETA]
    r = hinf_scheduled(plants, THETA, 1, 1)
    assert r.gamma == pytest.approx(r.backoff * r.gamma_opt.max(), rel=1e-12)
    assert r.backoff == 1.1
    for t, P in zip(THETA, plants):
        n, m, p = P.nstates, P.ninputs, P.noutputs
        ref = sb10fd(n, m, p, 1, 1, r.gamma, P.A, P.B, P.C, P.D)[:4]
        got = r.K.matrices(t)
        for a, b in zip(got, ref):
            np.testing.assert_allclose(a, b, rtol=1e-6, atol=1e-6 * np.abs(b).max())
        # python-control's loop: stable, and its norm within the table's γ
        K = control.ss(*got)
        cl = P.lft(K, 1, 1)
        assert cl.poles().real.max() < 0
        H = cl(1j * np.logspace(-3, 4, 2000))  # (outputs, inputs, frequencies)
        peak = np.linalg.norm(np.moveaxis(H, -1, 0), 2, axis=(1, 2)).max()
        assert peak <= r.gamma * (1 + 1e-6)


def test_between_entries_the_controller_is_interpolated_linearly():
    r = hinf_scheduled([_plant(t) for t in THETA], THETA, 1, 1)
    mid = r.K.matrices(0.5)
    for a, b, c in zip(mid, r.K.matrices(0.0), r.K.matrices(1.0)):
        np.testing.assert_allclose(a, (b + c) / 2, rtol=1e-12, atol=1e-12)


def test_a_table_not_one_theta_per_plant_is_refused():
    plants = [_plant(t) for t in THETA]
    with pytest.raises(ConfigError, match="strictly increasing"):
        hinf_scheduled(plants, THETA[::-1], 1, 1)
    with pytest.raises(ConfigError, match="one strictly increasing value per plant"):
        hinf_scheduled(plants, THETA[:2], 1, 1)
    with pytest.raises(ConfigError, match="backoff"):
        hinf_scheduled(plants, THETA, 1, 1, backoff=0.9)
