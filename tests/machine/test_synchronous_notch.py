"""The generalised notch filter (machine/synchronous_notch.py) against its closed forms
(Herzog et al., IEEE TCST 1996) and python-control's own interconnection of the same
blocks."""

import math

import control as ct
import numpy as np
import pytest

from ambseal.errors import ModelError
from ambseal.machine import SynchronousNotch

from ..freq_at import at

RNG = np.random.default_rng(7)
P = 3
T_TABLE = RNG.normal(size=(2, P, P)) + 1j * RNG.normal(size=(2, P, P))
SPEEDS = np.array([100.0, 300.0])
NAMES = tuple(f"y_{k}" for k in range(P))


def _notch(dt=0.0, fraction=0.05):
    return SynchronousNotch(SPEEDS, T_TABLE.real, T_TABLE.imag, fraction, 100.0, NAMES, dt)


def _response(mats, points):
    A, B, C = mats
    return np.array([C @ np.linalg.solve(z * np.eye(A.shape[0]) - A, B) for z in points])


@pytest.mark.parametrize("dt", [0.0, 1e-4])
def test_notch_is_the_generalised_notch_filter(dt):
    """N(s) = (ε/2)[T/(s − jΩ) + T̄/(s + jΩ)] continuous and
    N(z) = (εT_s/2)[e^{jθ}T/(z − e^{jθ}) + e^{−jθ}T̄/(z − e^{−jθ})], θ = ΩT_s, discrete, ε =
    0.05 Ω, with T(Ω) interpolated linearly between the table's speeds (here halfway)."""
    n = _notch(dt)
    w = 200.0
    T = 0.5 * (T_TABLE[0] + T_TABLE[1])
    np.testing.assert_allclose(n.gain_at(w), T, rtol=1e-12)
    eps = 0.05 * w
    if dt:
        pts = np.exp(1j * np.array([0.3, 1.1, 2.5]) * w * dt)
        r = np.exp(1j * w * dt)
        ref = [0.5 * eps * dt * (r * T / (z - r) + np.conj(r * T) / (z - np.conj(r)))
               for z in pts]
    else:
        pts = 1j * np.array([0.3, 1.1, 2.5]) * w + 5.0
        ref = [0.5 * eps * (T / (s - 1j * w) + T.conj() / (s + 1j * w)) for s in pts]
    np.testing.assert_allclose(_response(n.matrices_at(w), pts), ref, rtol=1e-10)


@pytest.mark.parametrize("dt", [0.0, 1e-4])
def test_notched_controller_is_k_after_the_notch_loop(dt):
    """Reference: python-control's interconnection of K after the loop q = y − N q, i.e.
    K (I + N)⁻¹ — at speeds away from Ω equal to ours; at Ω itself zero (the notch's poles
    are the controller's zeros); below the speed it is on from, K itself."""
    n = _notch(dt)
    # a controller drawn from a seeded generator (python-control's rss draws from NumPy's
    # global state, which the tests run before it set): poles from 20 to 2 000 rad/s,
    # mapped by exp(sT) when discrete, away from the points it is evaluated at
    rng = np.random.default_rng(11)
    V = rng.normal(size=(4, 4))
    s = -np.array([20.0, 150.0, 600.0, 2000.0])
    A = V @ np.diag(np.exp(s * dt) if dt else s) @ np.linalg.inv(V)
    K = ct.ss(A, rng.normal(size=(4, P)), rng.normal(size=(P, 4)), rng.normal(size=(P, P)),
              dt or 0, inputs=list(NAMES), outputs=[f"i_{k}" for k in range(P)], name="K")
    w = 250.0
    ours = n.around(K, w)
    An, Bn, Cn = n.matrices_at(w)
    N = ct.ss(An, Bn, Cn, np.zeros((P, P)), dt or 0)
    ref = K * ct.feedback(ct.ss([], [], [], np.eye(P), dt or 0), N)
    pts = (np.exp(1j * np.array([0.4, 1.7]) * w * dt) if dt
           else 1j * np.array([0.4, 1.7]) * w)
    for z in pts:
        np.testing.assert_allclose(at(ours, z), at(ref, z), rtol=1e-8, atol=1e-12)
    point = np.exp(1j * w * dt) if dt else 1j * w
    assert np.abs(at(ours, point)).max() < 1e-9 * np.abs(at(K, point)).max()
    assert ours.input_labels == K.input_labels and ours.output_labels == K.output_labels
    assert n.around(K, 99.0) is K


def test_notch_refuses_what_does_not_fit():
    """A controller of another time base or other inputs, a table that is not increasing,
    and a rate the discrete notch cannot run at are each named."""
    n = _notch(1e-4)
    K = ct.ss(np.zeros((1, 1)), np.zeros((1, P)), np.zeros((P, 1)), np.eye(P), 0,
              inputs=list(NAMES), outputs=[f"i_{k}" for k in range(P)])
    with pytest.raises(ModelError, match="sample time"):
        n.around(K, 200.0)
    with pytest.raises(ModelError, match="the controller reads"):
        _notch().around(ct.ss(K.A, K.B, K.C, K.D, inputs=list(reversed(NAMES))), 200.0)
    with pytest.raises(ModelError, match="increase"):
        SynchronousNotch(SPEEDS[::-1], T_TABLE.real, T_TABLE.imag, 0.05, 100.0, NAMES)
    with pytest.raises(ModelError, match="rate_fraction"):
        SynchronousNotch(SPEEDS, T_TABLE.real, T_TABLE.imag, 0.7, 100.0, NAMES)
    assert math.isclose(n.schedule[1], 300.0)
