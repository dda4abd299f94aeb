"""Systems sharing a state matrix (:func:`ambseal.lti.select_inputs`,
:func:`ambseal.lti.shared_ss`) against python-control's own copies."""

from __future__ import annotations

import control
import numpy as np
import pytest

from ambseal.lti import select_inputs, shared_ss


def test_select_inputs_equals_python_controls_indexing():
    """Reference: python-control's ``P[:, idx]`` (a copy). The same matrices, time base,
    input, output and state names; ``A`` a read-only view of the plant's, not a copy."""
    rng = np.random.default_rng(3)
    P = control.ss(rng.standard_normal((6, 6)), rng.standard_normal((6, 4)),
                   rng.standard_normal((3, 6)), rng.standard_normal((3, 4)), 0.01,
                   inputs=["i_x", "i_y", "F_x", "F_y"], outputs=["s1", "s2", "s3"],
                   states=[f"q{k}" for k in range(6)])
    for idx in ([0, 1], [3, 2], [2]):
        got, want = select_inputs(P, idx), P[:, idx]
        for m in "ABCD":
            np.testing.assert_array_equal(getattr(got, m), getattr(want, m))
        assert got.dt == want.dt
        assert (got.input_labels, got.output_labels, got.state_labels) == \
            (want.input_labels, want.output_labels, P.state_labels)
        assert np.shares_memory(got.A, P.A) and not got.A.flags.writeable
        with pytest.raises(ValueError):
            got.A[0, 0] = 1.0


def test_shared_ss_is_control_ss_without_the_copy():
    """Reference: ``control.ss`` of the same matrices and names."""
    rng = np.random.default_rng(4)
    A, B, C, D = (rng.standard_normal(s) for s in ((5, 5), (5, 2), (1, 5), (1, 2)))
    got = shared_ss(A, B, C, D, inputs=["u1", "u2"], outputs=["y"])
    want = control.ss(A, B, C, D, inputs=["u1", "u2"], outputs=["y"])
    for m in "ABCD":
        np.testing.assert_array_equal(getattr(got, m), getattr(want, m))
    assert (got.input_labels, got.output_labels) == (want.input_labels, want.output_labels)
    assert np.shares_memory(got.A, A)
    np.testing.assert_allclose(control.evalfr(got, 2j), control.evalfr(want, 2j), rtol=1e-15)
