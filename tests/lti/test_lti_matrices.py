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


def test_digest_of_a_frozen_array_is_kept_and_follows_the_content():
    """Reference: hashlib's SHA-256 of the bytes. A frozen array's digest is kept (a second
    lookup hashes nothing) and equals that of a writeable copy of the same content; an
    array whose memory can still be written (a read-only view of a writeable array) is
    hashed at every lookup, so a change in place gives another digest."""
    import hashlib

    import ambseal.lti.memo as mx

    rng = np.random.default_rng(5)
    A = rng.standard_normal((400, 400))  # 1.3 MB: above the kept size
    copy = A.copy()
    view = A.view()
    view.flags.writeable = False  # its owner A stays writeable
    d_view = mx.array_digest((view,))
    A[0, 0] += 1.0
    assert mx.array_digest((view,)) != d_view  # hashed again: the content changed
    assert mx.array_digest((copy,)) == d_view
    frozen = mx.freeze(copy)
    assert frozen is copy and not copy.flags.writeable
    with pytest.raises(ValueError):
        copy[0, 0] = 0.0
    hashed = []
    real = hashlib.sha256

    def counted(*data):
        hashed.append(sum(memoryview(x).nbytes for x in data))
        return real(*data)

    mx.hashlib.sha256 = counted
    try:
        twice = [mx.array_digest((copy,)) for _ in range(2)]
        big = max(hashed)
        hashed.clear()
        mx.array_digest((copy.view(),))  # another view object of the same memory
        kept = max(hashed)
        hashed.clear()
        half = [mx.array_digest((copy[:, :200],)) for _ in range(2)]  # 640 kB: not kept
        small = sorted(hashed)[-2:]
    finally:
        mx.hashlib.sha256 = real
    assert twice == [d_view, d_view] and big == copy.nbytes and kept < 1000
    assert small == [copy.nbytes // 2] * 2
    assert half[0] == half[1] == mx.array_digest((np.ascontiguousarray(copy[:, :200]),))


def test_a_plants_state_matrix_is_frozen():
    """A plant's state matrix is read-only from its construction on (its systems share it
    and the memos keep its digest): a write raises instead of changing them silently."""
    from ambseal.model.lft import Plant

    A = np.array([[0.0, 1.0], [-4.0, -0.4]])
    p = Plant(A, np.array([[0.0], [1.0]]), np.array([[1.0, 0.0]]), np.zeros((1, 1)),
              ("i_x",), ("y_x",), ("q", "v"))
    with pytest.raises(ValueError):
        p.A[0, 0] = 1.0
    assert not A.flags.writeable and np.shares_memory(p.to_statespace().A, A)


def test_memo_keeps_more_than_its_count_within_its_byte_budget():
    """A sweep of 5 inputs repeated (a Level I sweep per controller): with ``keep=2`` alone
    every lookup of the second pass computes again (least recently used goes first); with
    a byte budget for 5 results, none does; a budget for 3 keeps the count's 2 at least
    and no more than 3. An object's ``nbytes`` is its size, numbers, names and None beside
    arrays are counted too; an object without a size is never kept beyond the count."""
    from ambseal.lti.memo import ArrayMemo

    inputs = [np.full((64, 64), float(k)) for k in range(5)]  # 32 kB each

    def sweep(memo, calls):
        for A in inputs:
            memo.get((A,), None, lambda A=A: calls.append(1) or A * 2.0)

    for budget, second_pass in ((0, 5), (5 * inputs[0].nbytes, 0)):
        memo, calls = ArrayMemo(keep=2, keep_bytes=budget), []
        sweep(memo, calls)
        assert len(calls) == 5
        sweep(memo, calls)
        assert len(calls) == 5 + second_pass
    memo, calls = ArrayMemo(keep=2, keep_bytes=3 * inputs[0].nbytes), []
    sweep(memo, calls)
    assert len(memo._kept) == 3
    np.testing.assert_array_equal(memo.get((inputs[4],), None, lambda: None), inputs[4] * 2)

    class Sized:  # a result that states its size (a plant), and one that does not
        nbytes = inputs[0].nbytes

    # arrays with a condition number, signal names and no sampled response beside them
    mixed = (inputs[0], 1.5, 2 + 1j, ["x1", "y1"], None)
    for value, kept in ((Sized(), 5), (mixed, 5), (object(), 2)):
        memo = ArrayMemo(keep=2, keep_bytes=5 * (inputs[0].nbytes + 64))
        for A in inputs:
            memo.get((A,), None, lambda: value)
        assert len(memo._kept) == kept
