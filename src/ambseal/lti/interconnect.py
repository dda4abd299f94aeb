"""Closing loops: the lower linear fractional transformation and negative feedback.

One implementation serves every caller: the H∞/μ/LPV syntheses close ``F_l(P, K)``
(Skogestad & Postlethwaite, *Multivariable Feedback Control*, 2nd ed., Eq. 3.111, with a
general ``D22``), and the negative-feedback loop ``u = −K y + d`` of the analyses and of a
digital loop is the same transformation of an augmented plant
(:func:`feedback_matrices`). The algebra does not depend on the time base, so the same
functions close continuous and discrete loops.

python-control's ``control.lft`` and ``control.feedback`` compute the same systems (tested side
by side); these matrix-level versions exist because the synthesis loops (D–K, LPV checks,
scheduled-controller tables) close thousands of loops and need neither signal bookkeeping nor object
construction, and because ``control.feedback`` has no separate force inputs.

A controller is connected to its plant by signal names (:func:`wired`): its inputs are the
plant's outputs and its outputs the plant's inputs, in whatever order; only systems
without names are connected by position.
"""

from __future__ import annotations

import re
from typing import Any

import control
import numpy as np

from ambseal.errors import ModelError
from ambseal.lti.discrete import zoh
from ambseal.lti.freqresp import STRUCTURED_STATES, modal_form
from ambseal.lti.matrices import labels, ss_matrices
from ambseal.lti.memo import ArrayMemo
from ambseal.lti.modal_loop import modal_loop_poles, modal_loop_response

__all__ = ["lft_lower_matrices", "lft_lower", "feedback_matrices", "feedback_poles",
           "feedback_response", "state_poles", "series_inputs", "wired"]

Matrices = tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]


def lft_lower_matrices(P: Matrices, K: Matrices, nmeas: int, ncon: int) -> Matrices:
    """``F_l(P, K)`` with positive feedback ``u = K y`` (Skogestad & Postlethwaite Eq. 3.111).

    Parameters
    ----------
    P : (A, B, C, D)
        Generalised plant, inputs ``[w, u]`` (``ncon`` last), outputs ``[z, y]`` (``nmeas`` last).
    K : (A_K, B_K, C_K, D_K)
        Controller from ``y`` to ``u``.
    nmeas, ncon : int
        Number of measurements and control inputs.

    Returns
    -------
    (A_cl, B_cl, C_cl, D_cl)
        The loop from ``w`` to ``z``, state ``[x_P; x_K]``.

    Raises
    ------
    ModelError
        If ``I − D22·D_K`` is singular (an ill-posed loop), or the channel counts do not
        fit ``P`` and ``K``.
    """
    A, B, C, D = P
    Ak, Bk, Ck, Dk = K
    counts = [isinstance(v, (int, np.integer)) and not isinstance(v, bool) and v >= 0
              for v in (nmeas, ncon)]
    if not all(counts) or nmeas > C.shape[0] or ncon > B.shape[1] \
            or np.shape(Dk) != (ncon, nmeas):
        raise ModelError(f"F_l(P, K): nmeas={nmeas!r}, ncon={ncon!r} do not fit P "
                         f"({C.shape[0]} outputs, {B.shape[1]} inputs) and K "
                         f"({np.shape(Dk)[0]} outputs, {np.shape(Dk)[1]} inputs)")
    n, nk = A.shape[0], Ak.shape[0]
    nw, nz = B.shape[1] - ncon, C.shape[0] - nmeas
    B1, B2 = B[:, :nw], B[:, nw:]
    C1, C2 = C[:nz], C[nz:]
    D11, D12, D21, D22 = D[:nz, :nw], D[:nz, nw:], D[nz:, :nw], D[nz:, nw:]
    DD = D22 @ Dk
    Rm = np.eye(nmeas) - DD
    if not DD.any():  # a strictly proper plant (the usual case): R = I, its inverse exactly
        Ri = Rm
    elif np.linalg.cond(Rm) > 1e12:
        raise ModelError("the loop is ill-posed: I - D22·D_K is singular")
    else:
        Ri = np.linalg.inv(Rm)
    # y = Ri (C2 x + D22 C_K x_K + D21 w);   u = C_K x_K + D_K y
    Cy = np.hstack([Ri @ C2, Ri @ D22 @ Ck])
    Dy = Ri @ D21
    Cu = np.hstack([np.zeros((ncon, n)), Ck]) + Dk @ Cy
    Du = Dk @ Dy
    Acl = np.zeros((n + nk, n + nk))
    Acl[:n, :n] = A
    Acl[n:, n:] = Ak
    Acl = Acl + np.vstack([B2, np.zeros((nk, ncon))]) @ Cu
    Acl = Acl + np.vstack([np.zeros((n, nmeas)), Bk]) @ Cy
    Bcl = np.vstack([B1 + B2 @ Du, Bk @ Dy])
    Ccl = np.hstack([C1, np.zeros((nz, nk))]) + D12 @ Cu
    Dcl = D11 + D12 @ Du
    return Acl, Bcl, Ccl, Dcl


def lft_lower(P: Any, K: Any, nmeas: int, ncon: int, name: str = "closed_loop"):
    """``F_l(P, K)`` as a ``control.StateSpace`` keeping P's names for ``w`` and ``z``.

    Parameters
    ----------
    P, K : control.StateSpace
        Generalised plant (inputs ``[w, u]``, outputs ``[z, y]``) and controller ``u = K y``,
        of the same time base.
    nmeas, ncon : int
        Number of measurements and of control inputs (the last channels of ``P``).
    name : str
        Name of the returned system.

    Returns
    -------
    control.StateSpace
        Closed loop from ``w`` to ``z``; states ``[x_P, x_K]``.

    Raises
    ------
    ModelError
        If ``I − D22·D_K`` is singular (ill-posed loop).
    """

    mats = lft_lower_matrices(ss_matrices(P, name="P", allow_discrete=True),
                              ss_matrices(K, name="K", allow_discrete=True), nmeas, ncon)
    nw, nz = mats[1].shape[1], mats[2].shape[0]
    inputs = labels(P, "input", nw + ncon, "w")[:nw]
    outputs = labels(P, "output", nz + nmeas, "z")[:nz]
    return control.ss(*mats, getattr(P, "dt", 0) or 0, inputs=list(inputs),
                      outputs=list(outputs), name=name)


def feedback_matrices(G: Matrices, K: Matrices, Gf: tuple[np.ndarray, np.ndarray] | None = None
                      ) -> Matrices:
    """The negative-feedback loop ``u = −K y + d`` (plus external inputs ``f``) as one
    state space.

    Plant ``ẋ = A x + B u + B_f f``, ``y = C x + D u + D_f f``; controller
    ``ẋ_K = A_K x_K + B_K y``, ``i = −(C_K x_K + D_K y)``, ``u = i + d`` (the controller maps
    measurements to commands, negative feedback). Computed as
    :func:`lft_lower_matrices` of the plant augmented with the outputs ``i`` and the
    controller ``−K``; the same as ``control.feedback(G, K, sign=-1)`` on the ``d → y``
    channel.

    Parameters
    ----------
    G : (A, B, C, D)
        Plant, ``nu`` inputs → ``ny`` outputs.
    K : (A_K, B_K, C_K, D_K)
        Controller, ``ny`` inputs → ``nu`` outputs.
    Gf : (B_f, D_f), optional
        Further plant inputs sharing ``A`` and ``C`` (forces, sensor offsets).

    Returns
    -------
    (A_cl, B_cl, C_cl, D_cl)
        Inputs ``[d, f]``, outputs ``[y, i]``, state ``[x; x_K]``.

    Raises
    ------
    ModelError
        If ``I + D·D_K`` is singular (an ill-posed loop).
    """
    A, B, C, D = G
    Ak, Bk, Ck, Dk = K
    ny, nu = D.shape
    Bf, Df = Gf if Gf is not None else (np.zeros((A.shape[0], 0)), np.zeros((ny, 0)))
    nf = Bf.shape[1]
    BP = np.hstack([B, Bf, B])
    CP = np.vstack([C, np.zeros((nu, A.shape[0])), C])
    DP = np.zeros((2 * ny + nu, 2 * nu + nf))
    for rows in (slice(0, ny), slice(ny + nu, None)):
        DP[rows] = np.hstack([D, Df, D])
    DP[ny:ny + nu, nu + nf:] = np.eye(nu)
    return lft_lower_matrices((A, BP, CP, DP), (Ak, Bk, -Ck, -Dk), ny, nu)


# the last closed-loop state matrices decomposed: a design's loops at every judged condition,
# continuous and sampled, are closed again by the judgement. Kept for 256: a design is
# checked at a grid of conditions (21 on a 3 × 7 grid) and the checks of the designs it
# rejected come between its check and its judgement; eigenvalues only, ~10 kB at 600
# states, so 2.5 MB at most
_POLES = ArrayMemo(keep=256)


def state_poles(A: np.ndarray) -> np.ndarray:
    """Eigenvalues of a state matrix ``A`` (rad/s, or z of a discrete system), kept for the
    last few large ones (:class:`~ambseal.lti.memo.ArrayMemo`): a caller asks for the
    poles of the same large loop several times (its stability after a synthesis, a
    discretisation's prewarp frequency and stability screen, a later analysis).

    Parameters
    ----------
    A : numpy.ndarray, shape (n, n)
        The state matrix.

    Returns
    -------
    numpy.ndarray of complex, shape (n,)
        Its eigenvalues; the array is shared, do not modify it in place.
    """
    A = np.asarray(A, float)
    if not A.size:
        return np.zeros(0, dtype=complex)
    return _POLES.get((A,), "eigvals", lambda: np.linalg.eigvals(A))


def feedback_poles(G: Matrices, K: Matrices, *, lag: Matrices | None = None,
                   dt: float | None = None, hold: float | None = None,
                   state_matrix: np.ndarray | None = None) -> np.ndarray:
    """The poles of the loop ``u = −K y`` (rad/s, or z for a discrete loop): of the state
    matrix of :func:`feedback_matrices` ``(G, K)`` by :func:`state_poles`, or, for a large
    continuous plant without feedthrough (``STRUCTURED_STATES`` states or more, closed
    continuous with ``dt=0`` or sampled with ``hold``), from the plant's modal form with a
    certificate (:func:`ambseal.lti.modal_loop.modal_loop_poles`: no dense eigenvalue
    problem of the loop) where that certifies them.

    Parameters
    ----------
    G : (A, B, C, D)
        Plant, ``n`` states, ``nu`` inputs → ``ny`` outputs.
    K : (A_K, B_K, C_K, D_K)
        Controller, ``n_K`` states, ``ny`` inputs → ``nu`` outputs, closed as ``u = −K y``.
    lag : (A_L, B_L, C_L, D_L), optional
        A SISO lag between the controller and every plant input (a hold and computation
        delay), ``n_L`` states; its copies join the controller's states.
    dt : float, optional
        Sample time (s) of a discrete loop, 0 for a continuous one; without it the loop's
        time base is unknown and the dense eigenvalues are taken.
    hold : float, optional
        ``G`` is continuous and runs sampled by a zero-order hold of this sample time (s),
        all its inputs together (:func:`ambseal.lti.discrete.zoh`); ``K`` is discrete on
        it (``dt`` is then ``hold``). Its modal form is ``e^{λT}``, the rows of ``V⁻¹B``
        times ``(e^{λT} − 1)/λ``.
    state_matrix : numpy.ndarray or callable, optional
        The loop's state matrix if the caller has built it (with the lag's states after
        the plant's), or a function of no arguments that builds it (called only where it
        is needed): its eigenvalues are taken where the modal path is not.

    Returns
    -------
    numpy.ndarray of complex, shape (n + n_K + nu·n_L,)
        The closed-loop poles, in no particular order. The array is shared: do not modify
        it in place.

    Raises
    ------
    ModelError
        If ``I + D·D_K`` is singular (an ill-posed loop).
    """
    A, B, C, D = (np.asarray(X, float) for X in G)
    if (dt == 0.0 or hold) and A.shape[0] >= STRUCTURED_STATES and not np.any(D):
        Kf = _lagged(K, lag, B.shape[1]) if lag is not None else \
            tuple(np.asarray(X, float) for X in K)
        poles = _POLES.get((A, B, C) + Kf, ("modal", hold),
                           lambda: _modal_poles(A, B, C, Kf, hold))
        if poles is not None:
            return poles
    if state_matrix is not None:
        return state_poles(state_matrix() if callable(state_matrix) else state_matrix)
    if lag is not None:  # the lag in front of the plant (the same matrix as a delayed plant's)
        A, B, C, D = series_inputs((A, B, C, D), tuple(np.asarray(X, float) for X in lag))[:4]
    if hold:
        A, B = zoh(A, B, hold)
    return state_poles(feedback_matrices((A, B, C, D), K)[0])


def feedback_response(G: Matrices, K: Matrices, d: np.ndarray, h: float, *,
                      lag: Matrices | None = None) -> np.ndarray | None:
    """The loop ``u = −K y + d`` of a large continuous plant without feedthrough
    (``STRUCTURED_STATES`` states or more), ``d`` held over steps of ``h``, from rest, from
    the plant's modal form (:func:`ambseal.lti.modal_loop.modal_loop_response`: the loop
    split along its invariant subspaces, certified; no ``expm`` of the loop), or ``None``
    where that path does not apply or is not certified (the caller then samples the loop's
    state space).

    Parameters
    ----------
    G : (A, B, C, D)
        Continuous plant, ``n`` states, ``nu`` inputs → ``ny`` outputs.
    K : (A_K, B_K, C_K, D_K)
        Continuous controller, ``ny`` inputs → ``nu`` outputs.
    d : numpy.ndarray, shape (N, nu)
        The disturbances added to the controller's outputs, one row per step.
    h : float
        The step (s).
    lag : (A_L, B_L, C_L, D_L), optional
        A SISO lag in front of every plant input, the disturbance included (as
        :func:`series_inputs` of the plant with it).

    Returns
    -------
    numpy.ndarray, shape (N, ny + nu), or None
        The plant's outputs, then the controller's ``−K y``, at ``t = k h``: the samples of
        :func:`ambseal.lti.discrete.simulate_lti` on the loop sampled by
        :func:`ambseal.lti.discrete.zoh`.
    """
    A, B, C, D = (np.asarray(X, float) for X in G)
    if A.shape[0] < STRUCTURED_STATES or np.any(D):
        return None
    form = modal_form(A, B, C)
    if form is None:
        return None
    Ak, Bk, Ck, Dk = (np.atleast_2d(np.asarray(X, float)) for X in K)
    nk, nu = (Ak.shape[0] if Bk.size else 0), B.shape[1]
    Ck = Ck.reshape(nu, nk)
    if lag is None:
        Kl, E = (Ak.reshape(nk, nk), Bk.reshape(nk, -1), Ck, Dk), (np.zeros((nk, nu)), np.eye(nu))
    else:
        # the lag's states in the loop u = −K' y are those of the signal K y: the
        # disturbance, added to −K y, enters them with the opposite sign
        Kl = _lagged(K, lag, nu)
        Bl, Dl = (_repeat_diagonal(np.atleast_2d(np.asarray(X, float)), nu) for X in lag[1::2])
        E = (np.vstack([np.zeros((nk, nu)), -Bl]), Dl)
    F = np.hstack([-Ck, np.zeros((nu, Kl[0].shape[0] - nk))])
    return modal_loop_response(*form, Kl, E, (F, -Dk), np.asarray(d, float), h)


def _modal_poles(A, B, C, K, hold):
    form = modal_form(A, B, C)
    if form is None:
        return None
    lam, Bm, Cm = form
    if not hold:
        return modal_loop_poles(lam, Bm, Cm, K)
    with np.errstate(divide="ignore", invalid="ignore"):
        phi = np.where(lam == 0, hold, np.expm1(lam * hold) / lam)
    return modal_loop_poles(np.exp(lam * hold), Bm * phi[:, None], Cm, K, discrete=True)


def _lagged(K: Matrices, lag: Matrices, nu: int) -> Matrices:
    """``K`` followed by the SISO ``lag`` on each of its ``nu`` outputs."""
    Ak, Bk, Ck, Dk = (np.atleast_2d(np.asarray(X, float)) for X in K)
    Al, Bl, Cl, Dl = (_repeat_diagonal(np.atleast_2d(np.asarray(X, float)), nu) for X in lag)
    nk, nl = Ak.shape[0] if Bk.size else 0, Al.shape[0]
    A = np.zeros((nk + nl, nk + nl))
    A[:nk, :nk] = Ak.reshape(nk, nk)
    A[nk:, :nk] = Bl @ Ck
    A[nk:, nk:] = Al
    return (A, np.vstack([Bk.reshape(nk, -1), Bl @ Dk]), np.hstack([Dl @ Ck, Cl]), Dl @ Dk)


def series_inputs(G: Matrices, block: Matrices, inputs: list[int] | None = None
                  ) -> tuple[np.ndarray, ...]:
    """The same SISO system in front of each of the chosen inputs of ``G`` (an actuator, a
    lag): ``u_j → block → G`` for ``j`` in ``inputs``, the block states appended.

    Parameters
    ----------
    G : (A, B, C, D)
        ``n`` states, ``m`` inputs.
    block : (A_a, B_a, C_a, D_a)
        SISO, ``n_a`` states.
    inputs : list of int, optional
        The inputs that get the block (default: all).

    Returns
    -------
    (A, B, C, D, C_out, D_out)
        The series system (``n + n_a·k`` states, same inputs and outputs), and the blocks'
        outputs (what now enters the old ``B`` columns), ``C_out x + D_out u``, shapes
        ``(k, n + n_a k)`` and ``(k, m)``.
    """
    A, B, C, D = G
    n, m = B.shape
    idx = slice(None) if inputs is None else list(inputs)  # all: a slice, no copy
    k = m if inputs is None else len(idx)
    Ak, Bk, Ck, Dk = (_repeat_diagonal(np.atleast_2d(np.asarray(X, float)), k) for X in block)
    na = Ak.shape[0]
    Bu, Du = np.ascontiguousarray(B[:, idx]), np.ascontiguousarray(D[:, idx])
    A2 = np.zeros((n + na, n + na))
    A2[:n, :n] = A
    A2[:n, n:] = Bu @ Ck
    A2[n:, n:] = Ak
    B2 = np.zeros((n + na, m))
    B2[:n] = B
    B2[:n, idx] = Bu @ Dk
    B2[n:, idx] = Bk
    C2 = np.hstack([C, Du @ Ck])
    D2 = D.copy()
    D2[:, idx] = Du @ Dk
    C_out = np.hstack([np.zeros((k, n)), Ck])
    D_out = np.zeros((k, m))
    D_out[:, idx] = Dk
    return A2, B2, C2, D2, C_out, D_out


def _repeat_diagonal(X: np.ndarray, k: int) -> np.ndarray:
    """``kron(I_k, X)``, ``k`` copies of ``X`` on the block diagonal (the same array; numpy's
    ``kron`` costs more than the products around it for these small blocks)."""
    r, c = X.shape
    out = np.zeros((k * r, k * c))
    for j in range(k):
        out[j * r:(j + 1) * r, j * c:(j + 1) * c] = X
    return out


#: python-control's names of an unnamed system's signals.
_UNNAMED = re.compile(r"[uy]\[\d+\]")


def _named(names) -> bool:
    return not all(_UNNAMED.fullmatch(n) for n in names)


def wired(G: Any, K: Any) -> Any:
    """``K`` with its inputs in the order of ``G``'s outputs and its outputs in the order
    of ``G``'s inputs, matched by signal name.

    Parameters
    ----------
    G : control.StateSpace
        Plant (command inputs → measured outputs), continuous or discrete.
    K : control.StateSpace or (A, B, C, D)
        Controller in the feedback path: inputs are ``G``'s outputs, outputs ``G``'s inputs.

    Returns
    -------
    control.StateSpace or (A, B, C, D)
        ``K`` itself when its names are already in ``G``'s order, or when ``G`` or ``K``
        has no signal names (python-control's ``u[i]``, ``y[i]``, or a tuple of matrices:
        the loop is then wired by position); else ``K`` with its channels permuted (same
        states, time base and name).

    Raises
    ------
    ModelError
        Both are named but the names differ: a missing, extra, repeated or renamed
        channel. The message lists both sets.

    Examples
    --------
    >>> import control
    >>> G = control.ss([[0.0]], [[1.0, 0.0]], [[1.0], [0.0]], [[0.0, 0.0], [0.0, 0.0]],
    ...                inputs=["i_A", "i_B"], outputs=["y_A", "y_B"])
    >>> K = control.ss([], [], [], [[1.0, 0.0], [0.0, 2.0]], inputs=["y_B", "y_A"],
    ...                outputs=["i_B", "i_A"])
    >>> wired(G, K).D.tolist()
    [[2.0, 0.0], [0.0, 1.0]]
    """

    (_, _, _, D), (Ak, Bk, Ck, Dk) = (ss_matrices(X, name=nm, allow_discrete=True)
                                      for X, nm in ((G, "G"), (K, "K")))
    g_out, g_in = labels(G, "output", D.shape[0], "y"), labels(G, "input", D.shape[1], "u")
    k_in, k_out = labels(K, "input", Dk.shape[1], "u"), labels(K, "output", Dk.shape[0], "y")
    if not all(map(_named, (g_out, g_in, k_in, k_out))) or (k_in, k_out) == (g_out, g_in):
        return K
    if not (sorted(k_in) == sorted(g_out) == sorted(set(g_out))
            and sorted(k_out) == sorted(g_in) == sorted(set(g_in))):
        raise ModelError(
            f"controller {getattr(K, 'name', 'K')}: its signals do not match the plant's "
            f"(they are connected by name): inputs {list(k_in)} against the plant's outputs "
            f"{list(g_out)}, outputs {list(k_out)} against the plant's inputs {list(g_in)}")
    i, o = [k_in.index(n) for n in g_out], [k_out.index(n) for n in g_in]
    dt = getattr(K, "dt", 0)
    return control.ss(Ak, Bk[:, i], Ck[o, :], Dk[np.ix_(o, i)], 0 if dt is None else dt,
                      inputs=list(g_out), outputs=list(g_in),
                      states=list(getattr(K, "state_labels", None) or []) or None,
                      name=getattr(K, "name", None))
