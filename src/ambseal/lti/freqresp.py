"""Fast frequency response of large continuous-time state-space models.

``H(jω) = C (jωI − A)⁻¹ B + D`` is evaluated without a dense ``O(n³)`` solve per frequency:

* **modal** (default when the eigenvector matrix is well conditioned): with
  ``A = V diag(λ) V⁻¹`` once, ``H(jω) = (C V) diag(1/(jω − λ)) (V⁻¹ B) + D``, vectorised over ω
  (``O(n · ny · nu)`` per frequency);
* **hessenberg** (fallback, or on request): ``A = Q Hs Qᵀ`` once (``scipy.linalg.hessenberg``),
  then ``(jωI − Hs) X = Qᵀ B`` is solved by Gaussian elimination with adjacent-row partial
  pivoting, which on an upper Hessenberg matrix costs ``O(n²)`` per frequency (the method of
  Laub, "Efficient multivariable frequency response computations", IEEE TAC 26(2), 1981,
  which SLICOT ``TB05AD`` also uses). The elimination is vectorised over chunks of frequencies.

The modal result is checked against the Hessenberg result at three probe frequencies; if the
relative difference exceeds ``rtol``, dense LU solves at the probes decide: the modal form of
the balanced system if it agrees with them to ``rtol`` (FE plants in [q; q̇] form), else the one
of the two closer to them is used for the whole grid if it agrees with them to 1e-4, else
dense solves at every frequency; if ``cond(V) > max_cond``, the modal form of the balanced
system if it agrees with dense solves at the probes to ``rtol`` or is as close to them as
the Hessenberg form (a spectrum over many decades, where neither meets ``rtol``), else the
Hessenberg path. Above 1 000 states the balanced system's modal form is tried first, under
the same checks (a fine FE mesh: its own eigenvectors are never well enough conditioned).
So neither a (nearly) defective ``A`` nor a badly balanced Hessenberg form silently spoils
the answer.

Lightly damped, open-loop unstable FE models of a few hundred to a few thousand states are
the intended use.

If a frequency coincides with a pole on the imaginary axis (e.g. ω = 0 with an integrator),
the corresponding entries are ``inf``/``nan``; no error is raised.
"""

from __future__ import annotations

import math
from typing import Any, Literal

import numpy as np
import scipy.linalg
from scipy.sparse.linalg import ArpackError, LinearOperator, svds
from slycot import tb05ad

from ambseal.errors import ModelError
from ambseal.lti.discrete import zoh
from ambseal.lti.matrices import as_omega, ss_matrices
from ambseal.lti.memo import ArrayMemo

__all__ = ["eigenvalues", "freqresp", "freqresp_at", "modal_form", "sampled_modal_form",
           "sampled_response_at", "STRUCTURED_STATES"]

_MAX_COND = 1e8  # the default max_cond of the functions here: the kept decompositions' key
_EPS = float(np.finfo(float).eps)
_CHUNK_BYTES = 32 * 2**20  # memory budget of one chunk (complex n×n per frequency)
#: ... of the modal form's chunk (complex n per frequency) of a large model
#: (``STRUCTURED_STATES`` states or more): a judgement's peak memory is reached there, and
#: the product with W is faster on chunks that stay in cache (3 000 points of 1 888
#: states: 0.096 s in chunks of 32 MB, 0.057 s of 2 MB). Smaller models keep
#: ``_CHUNK_BYTES``: the chunking decides the product's rounding, and a D–G–K iteration,
#: which follows its loops' responses to the last bit, takes another path on another one.
_LARGE_MODAL_CHUNK_BYTES = 4 * 2**20
_USE_SLYCOT = True  # set False (tests) to force the pure-numpy Hessenberg solver
_MODAL = ArrayMemo()  # (λ, cond V, V⁻¹B, CV) of the last large (A, B, C)
#: States above which cond V is LAPACK's 1-norm estimate from the LU of V (``gecon``, O(n²)
#: after the LU that V⁻¹B needs anyway) instead of the 2-norm (by an SVD below
#: ``STRUCTURED_STATES`` states, from there by Lanczos, :func:`_cond_2`): at 3 248 states
#: (an FE model of 400 beam elements) the SVD took 25.6 s, more than the eig itself
#: (18 s), the LU and the estimate 2.3 s. The two norms' condition numbers lie within a
#: factor n of each other (Higham, *Accuracy and Stability of Numerical Algorithms*, 2nd
#: ed., 2002, §15.3); cond V only decides whether the modal form is tried — ``"auto"``
#: then checks it against the Hessenberg form or the dense solves at the probes.
_SVD_COND_STATES = 1000
_BALANCED = ArrayMemo()  # the same of the balanced system (:func:`_arbitrated`)
#: (λ, cond V, LU of V, CV, balancing) of the last large (A, C), balanced or not: one
#: eigendecomposition per plant whatever its inputs (the LU of V is n² complex numbers,
#: 57 MB at 1 888 states; a loop is judged with a few plants at once). Systems of fewer
#: than _EIG_STATES states (a design's loops, rebuilt at every iteration) are kept by
#: (A, B, C) in _MODAL and _BALANCED only; from there up, the inputs of a plant answered
#: for one group of them and then another share its eigendecomposition (16 repeated
#: ones in a run on a 468-state plant).
_EIG_STATES = 128
#: States from which a plant's eigendecomposition is kept per (A, C) and serves every use of
#: that plant: its responses, the poles of the loops closed on it
#: (:func:`ambseal.lti.interconnect.feedback_poles`) and its sampled form
#: (:func:`sampled_modal_form`) — a dense eigenvalue problem or ``expm`` of a 500-state
#: matrix costs 0.1 s, of a 1 888-state one 2–3.5 s (benchmarks/README.md).
STRUCTURED_STATES = 500
#: More than six while they fit in 128 MB: a design's full-order check closes its loops on
#: the plants of every judged condition (21 on a 3 × 7 grid), and the later checks close
#: theirs on the same plants again; at 540 states an entry is 4.7 MB, so
#: all of them are kept, at 1 888 states (114 MB) six
_EIG = ArrayMemo(keep=6, min_states=_EIG_STATES, keep_bytes=128 * 2**20)
_SAMPLED = ArrayMemo(keep=8, min_states=STRUCTURED_STATES)  # sampled_modal_form's results
_PROBED = ArrayMemo(keep=64)  # C (sI − A)⁻¹ B + D at single probes s of large (A, B, C)
#: Spread (largest over smallest) of the diagonal balancing of ``A`` above which
#: ``"auto"`` tries the balanced modal form first, checked against dense solves at the
#: probes (:func:`_balanced_modal`): entries over that many decades are an FE plant's
#: [q; q̇] form (spread 3e10 on a 336-state plant), whose own modal form fails its check
#: and ends in the balanced one anyway, after an eigendecomposition for nothing.
_SPREAD_BALANCED_FIRST = 1e6
#: The Hessenberg reduction of the last large ``A`` (:func:`_hessenberg_form`): a plant's grid
#: and probe responses, whatever its inputs and outputs, share one (an n² matrix: 28 MB at
#: 1 888 states); a loop is judged at three operating points, on a plant each. Those from
#: ``STRUCTURED_STATES`` states are kept apart from the smaller ones, which a design
#: reduces by the dozen between a plant's first probes and its judgement (a 250-state
#: form costs 10 ms, a 1 888-state one 1.1 s).
_HESSENBERG = ArrayMemo(keep=3)
_HESSENBERG_LARGE = ArrayMemo(keep=3, min_states=STRUCTURED_STATES)


def freqresp(
    sys: Any,
    omega: Any,
    *,
    method: Literal["auto", "modal", "hessenberg"] = "auto",
    max_cond: float = 1e8,
    rtol: float = 1e-8,
) -> np.ndarray:
    """Frequency response of a continuous-time state-space model.

    Parameters
    ----------
    sys : control.StateSpace or tuple (A, B, C, D)
        Continuous-time system with ``n`` states, ``nu`` inputs, ``ny`` outputs. Anything
        ``control.ss`` accepts (e.g. a transfer function) is converted.
    omega : array_like, shape (n_w,)
        Angular frequencies in rad/s (finite, ``>= 0``).
    method : {"auto", "modal", "hessenberg"}
        ``"auto"`` uses the modal form when it is well conditioned and agrees with the
        Hessenberg form at three probe frequencies; where they disagree, the one that agrees
        with dense solves at the probes, or dense solves everywhere if neither does; else the
        Hessenberg form. One or two frequencies are their own probes and are solved
        densely. ``"modal"`` forces the modal form (raises if ``A`` is numerically
        defective), ``"hessenberg"`` forces the Hessenberg form.
    max_cond : float
        Largest accepted condition number of the eigenvector matrix ``V`` (the 2-norm one;
        above 1 000 states LAPACK's estimate of the 1-norm one, which costs no SVD).
    rtol : float
        Largest accepted relative difference between modal and Hessenberg results at the
        probe frequencies (``"auto"`` only).

    Returns
    -------
    numpy.ndarray of complex, shape (n_w, ny, nu)
        ``H(jω_k)`` for each frequency, in the units of outputs per unit input.

    Raises
    ------
    ModelError
        If ``omega`` is not a valid grid, the system is not continuous-time, ``method`` is
        unknown, or ``method="modal"`` is forced on a numerically defective ``A``.

    Notes
    -----
    Cost: one ``eig`` (or ``hessenberg``) of ``A`` — ``O(n³)`` once — plus ``O(n·ny·nu)``
    (modal) or ``O(n²·nu)`` (Hessenberg) per frequency. Cross-checked in the tests against
    ``control.frequency_response`` and direct dense solves.

    Examples
    --------
    >>> import control, numpy as np
    >>> H = freqresp(control.ss([[-1.0]], [[1.0]], [[1.0]], [[0.0]]), np.array([0.0, 1.0]))
    >>> H.shape, complex(H[0, 0, 0])
    ((2, 1, 1), (1+0j))
    """
    w = as_omega(omega)
    A, B, C, D = ss_matrices(sys)
    return _response(A, B, C, D, 1j * w, method, max_cond, rtol)


def freqresp_at(
    sys: Any,
    points: Any,
    *,
    method: Literal["auto", "modal", "hessenberg"] = "auto",
    max_cond: float = 1e8,
    rtol: float = 1e-8,
) -> np.ndarray:
    """``C (pI − A)⁻¹ B + D`` at arbitrary complex points ``p``, by the method of :func:`freqresp`.

    For a discrete-time model pass ``p = exp(jω dt)`` (the unit circle); for a continuous
    one ``p = jω`` (what :func:`freqresp` does) or any ``s`` off the imaginary axis.

    Parameters
    ----------
    sys : control.StateSpace (continuous or discrete) or tuple (A, B, C, D)
        ``n`` states, ``nu`` inputs, ``ny`` outputs.
    points : array_like of complex, shape (n_p,)
        Evaluation points (finite).
    method : {"auto", "modal", "hessenberg"}
        As for :func:`freqresp`.
    max_cond : float
        As for :func:`freqresp`.
    rtol : float
        As for :func:`freqresp`.

    Returns
    -------
    numpy.ndarray of complex, shape (n_p, ny, nu)
        ``C (p_k I − A)⁻¹ B + D`` for each point, in the units of outputs per unit input.

    Raises
    ------
    ModelError
        Non-finite points or inconsistent shapes.
    """
    pts = np.atleast_1d(np.asarray(points, dtype=complex))
    if pts.ndim != 1 or not np.all(np.isfinite(pts)):
        raise ModelError("freqresp_at: expected a 1-D array of finite complex points")
    A, B, C, D = ss_matrices(sys, allow_discrete=True)
    return _response(A, B, C, D, pts, method, max_cond, rtol)


def sampled_response_at(sys: Any, dt: float, omega: Any, *, groups: Any = None,
                        max_cond: float = 1e8, rtol: float = 1e-6) -> np.ndarray:
    """The zero-order-hold sampled plant's response ``G_d(e^{jω dt})``, from the continuous
    plant's modal form.

    With ``A = V diag(λ) V⁻¹`` the sampled plant (:func:`ambseal.lti.discrete.zoh`) is
    ``A_d = V diag(e^{λ dt}) V⁻¹``, ``B_d = V diag(φ(λ)) V⁻¹ B`` with
    ``φ(λ) = (e^{λ dt} − 1)/λ`` (``dt`` at λ = 0), so
    ``G_d(z) = C V diag(φ(λ)/(z − e^{λ dt})) V⁻¹ B + D`` (Franklin, Powell & Workman,
    *Digital Control of Dynamic Systems*, 3rd ed., §6.3): the modal form of the continuous
    plant (kept for its other responses) serves the sampled one too, with no
    eigendecomposition of ``A_d``. At one or two frequencies, which are their own probes,
    the dense solves of ``(zI − A_d) X = B_d`` are the answer (one ``expm``, 0.3 s at 840
    states, against an eigendecomposition and its certification, 0.6–0.8 s). Elsewhere,
    from ``STRUCTURED_STATES`` states, that form is :func:`sampled_modal_form`'s,
    certified on the continuous plant (no ``expm``). Else, or where that is not
    certified, the form — the balanced one first above
    ``_SVD_COND_STATES`` states, as :func:`freqresp` — is taken where it is within ``rtol``
    of dense solves of ``(zI − A_d) X = B_d`` at three probe frequencies; else
    :func:`freqresp_at` of ``(A_d, B_d, C, D)``.

    Parameters
    ----------
    sys : control.StateSpace or tuple (A, B, C, D)
        The continuous plant; ``n`` states, ``nu`` inputs, ``ny`` outputs.
    dt : float
        Sample time (s), > 0.
    omega : array_like of float, shape (n_w,)
        Frequencies (rad/s).
    groups : sequence of sequences of int, optional
        Input indices whose sampled forms are certified and kept apart, each input in
        one group (a plant's control inputs and its force inputs: the loop closed on the
        control inputs shares their form); by default one group of all. The response is
        the same; where the groups' forms share the plant's decomposition it is
        evaluated in one pass over the modes.
    max_cond, rtol : float
        As for :func:`freqresp_at`.

    Returns
    -------
    numpy.ndarray of complex, shape (n_w, ny, nu)

    Raises
    ------
    ModelError
        Non-finite frequencies, inconsistent shapes, ``dt`` not positive, or ``groups``
        not a partition of the inputs.
    """
    if not (np.isfinite(dt) and dt > 0):
        raise ModelError(f"sampled_response_at: dt must be a positive sample time, got {dt!r}")
    A, B, C, D = ss_matrices(sys)
    w = np.atleast_1d(np.asarray(omega, float))
    if w.ndim != 1 or not np.all(np.isfinite(w)):
        raise ModelError("sampled_response_at: expected a 1-D array of finite frequencies")
    z = np.exp(1j * w * dt)
    groups = [list(range(B.shape[1]))] if groups is None else [list(g) for g in groups if len(g)]
    if sorted(j for g in groups for j in g) != list(range(B.shape[1])):
        raise ModelError(f"sampled_response_at: groups {groups} are not a partition of the "
                         f"{B.shape[1]} inputs")
    if w.size < 3:
        # one or two points are their own probes (as in freqresp_at): dense solves of the
        # plant sampled by one expm, the reference every sampled form is certified
        # against, cost less than the eigendecomposition of the form
        Ad, Bd = zoh(A, B, dt)
        return _probe_response(Ad, Bd, C, D, z)
    if len(groups) > 1:
        return _grouped(A, B, C, D, dt, w, groups, max_cond, rtol)
    n = A.shape[0]
    if n >= STRUCTURED_STATES:
        form = sampled_modal_form(A, B, C, D, dt, max_cond=max_cond, rtol=rtol)
        if form is not None:
            return _modal_eval(*form, D, z)
    Ad, Bd = zoh(A, B, dt)
    if n == 0:
        return freqresp_at((Ad, Bd, C, D), z)
    probe = _probes(z)
    Hd = _probe_response(Ad, Bd, C, D, probe)
    for lam, Bm, Cm in _modal_forms(A, B, C, max_cond):
        mu, Bz = _sampled(lam, Bm, dt)
        if _error(_modal_eval(mu, Bz, Cm, D, probe), Hd) <= rtol:
            return _modal_eval(mu, Bz, Cm, D, z)
    return freqresp_at((Ad, Bd, C, D), z, rtol=rtol)


def _grouped(A, B, C, D, dt, w, groups, max_cond, rtol) -> np.ndarray:
    """:func:`sampled_response_at` of each input group; the groups' certified forms in one
    :func:`_modal_eval` where they share ``e^{λ dt}`` and ``C V`` (one decomposition)."""
    H = np.empty((w.size, C.shape[0], B.shape[1]), dtype=complex)
    if A.shape[0] >= STRUCTURED_STATES:
        forms = [sampled_modal_form(A, B[:, g], C, D[:, g], dt, max_cond=max_cond, rtol=rtol)
                 for g in groups]
        if all(f is not None and np.array_equal(f[0], forms[0][0])
               and np.array_equal(f[2], forms[0][2]) for f in forms):
            order = np.concatenate(groups)
            H[:, :, order] = _modal_eval(forms[0][0], np.hstack([f[1] for f in forms]),
                                         forms[0][2], D[:, order], np.exp(1j * w * dt))
            return H
    for g in groups:
        H[:, :, g] = sampled_response_at((A, B[:, g], C, D[:, g]), dt, w, max_cond=max_cond,
                                         rtol=rtol)
    return H


def sampled_modal_form(A: np.ndarray, B: np.ndarray, C: np.ndarray, D: np.ndarray,
                       dt: float, *, max_cond: float = 1e8, rtol: float = 1e-6):
    """The plant sampled by a zero-order hold at ``dt`` in modal form, without sampling
    ``A`` itself: ``(e^{λ dt}, rows of V⁻¹B times φ(λ), CV)`` (:func:`sampled_response_at`)
    from the continuous plant's modal form, or ``None`` where that form is not certified.

    The form — balanced first where :func:`freqresp` would try that first — is certified
    when ``C V diag(1/(s − λ)) V⁻¹ B + D`` is within ``rtol`` (relative to the largest
    entry) of dense LU solves of ``(sI − A) X = B`` at ``s = jω``, ``ω = π/dt`` times
    1e-3, √(1e-3 · 0.999) and 0.999 (the band of the sampled plant, and its geometric
    middle). The sampled form shares ``V`` and ``λ``, so an error of the eigendecomposition
    shows in both; no ``expm`` of the ``n``-state plant and no dense solve of the sampled
    plant is needed (2–3.5 s each at 1 888 states). The result is kept for the last large
    plants.

    Parameters
    ----------
    A, B, C, D : numpy.ndarray
        The continuous plant, ``n`` states, ``nu`` inputs, ``ny`` outputs.
    dt : float
        Sample time (s), > 0.
    max_cond, rtol : float
        As for :func:`freqresp_at`.

    Returns
    -------
    tuple (μ (n,), B_z (n, nu), C_m (ny, n)) of complex arrays, or None
        ``G_d(z) = C_m diag(1/(z − μ)) B_z + D``. Shared arrays: do not modify them in
        place.
    """
    def certified():
        probe = 1j * (np.pi / dt) * np.array([1e-3, np.sqrt(1e-3 * 0.999), 0.999])
        Hd = _probe_response(A, B, C, D, probe)
        for lam, Bm, Cm in _modal_forms(A, B, C, max_cond):
            if _error(_modal_eval(lam, Bm, Cm, D, probe), Hd) <= rtol:
                return (*_sampled(lam, Bm, dt), Cm)
        return None

    return _SAMPLED.get((A, B, C, D), (float(dt), max_cond, rtol), certified)


def _modal_forms(A, B, C, max_cond):
    """The modal forms ``(λ, V⁻¹B, CV)`` of ``A`` and of the balanced system that exist
    (``cond V ≤ max_cond``), in the order :func:`freqresp` tries them (lazily)."""
    order = (True, False) if _balanced_first(A) else (False, True)
    for balance in order:
        memo = _BALANCED if balance else _MODAL
        lam, _, Bm, Cm = memo.get((A, B, C), max_cond,
                                  lambda b=balance: _modal_form(A, B, C, max_cond, balance=b))
        if Bm is not None:
            yield lam, Bm, Cm


def _sampled(lam, Bm, dt):
    """``(e^{λ dt}, rows of Bm times φ(λ))``, ``φ(λ) = (e^{λ dt} − 1)/λ`` (``dt`` at 0)."""
    with np.errstate(divide="ignore", invalid="ignore"):
        phi = np.where(lam == 0, dt, np.expm1(lam * dt) / lam)
    return np.exp(lam * dt), Bm * phi[:, None]


def _response(A, B, C, D, s, method, max_cond, rtol) -> np.ndarray:
    """The evaluation shared by :func:`freqresp` and :func:`freqresp_at` at points ``s``."""
    if method not in ("auto", "modal", "hessenberg"):
        raise ModelError(f"freqresp: method must be 'auto', 'modal' or 'hessenberg', got {method!r}")
    n = A.shape[0]
    if n == 0:
        return np.broadcast_to(D.astype(complex), (s.size, *D.shape)).copy()
    if method == "hessenberg":
        return _hessenberg_response(A, B, C, D, s)
    if method == "auto" and s.size < 3:
        # one or two points are their own probes (:func:`_probes`): the dense solves every
        # fast form is checked against there are the answer, without the eigendecomposition
        # of the model for a point (0.4–1 s at 840 states against 0.03 s a point), nor the
        # Hessenberg form each check takes (a controller scheduled on a parameter is a
        # new model at each of the ~200 values it is evaluated at, kept by no memo)
        return _probe_response(A, B, C, D, s)
    if method == "auto" and n > _SVD_COND_STATES:
        H = _balanced_modal_checked(A, B, C, D, s, max_cond, rtol)  # large: balanced first
        if H is not None:
            return H
    elif method == "auto" and _balanced_first(A):
        probe = _probes(s)
        H = _balanced_modal(A, B, C, D, s, probe, _probe_response(A, B, C, D, probe),
                            max_cond, rtol)
        if H is not None:
            return H

    lam, cond, Bm, Cm = _MODAL.get((A, B, C), max_cond, lambda: _modal_form(A, B, C, max_cond))
    if not np.isfinite(cond) or cond > max_cond:
        if method == "modal":
            raise ModelError(
                f"freqresp: eigenvector matrix is ill conditioned (cond={cond:.3g} > {max_cond:.3g});"
                " use method='hessenberg'"
            )
        if method == "auto":
            H = _balanced_modal_checked(A, B, C, D, s, max_cond, rtol)
            if H is not None:
                return H
        return _hessenberg_response(A, B, C, D, s)
    if method == "auto":
        probe = _probes(s)
        Hm = _modal_eval(lam, Bm, Cm, D, probe)
        Hh = _hessenberg_response(A, B, C, D, probe)
        with np.errstate(invalid="ignore"):
            scale = np.max(np.abs(Hh), axis=(1, 2))
            err = np.max(np.abs(Hm - Hh), axis=(1, 2))
            ok = np.isfinite(scale) & np.isfinite(err)
            if ok.any() and np.any(err[ok] > rtol * np.maximum(scale[ok], np.finfo(float).tiny)):
                return _arbitrated(A, B, C, D, s, probe, Hh, Hm, (lam, Bm, Cm), max_cond,
                                   rtol)
    return _modal_eval(lam, Bm, Cm, D, s)


#: Largest relative error against dense solves at the probes accepted from the modal or the
#: Hessenberg form once the two disagree; above it the whole grid is solved densely.
_ARBITER_RTOL = 1e-4


def _arbitrated(A, B, C, D, s, probe, Hh, Hm, modal, max_cond, rtol) -> np.ndarray:
    """The response on ``s`` when the modal and the Hessenberg form disagree at the probes:
    the modal form of the balanced system if it is within ``rtol`` of dense LU solves of
    ``(sI − A) X = B`` there (partial pivoting, unbalanced: backward stable on sI − A
    itself); else the one of the two fast forms closer to the dense solves if it is within
    ``_ARBITER_RTOL`` of them, else dense solves on the whole grid.

    The balanced modal form is what FE plants in [q; q̇] form need: on a 320-state
    FE plant cond V falls from 5.6e7 to 1.8e4 and the modal error against the dense
    solves from 4e-8 to 1.2e-9 of the peak (the Hessenberg form: 9e-10), so the grid costs
    ``O(n)`` per frequency instead of TB05AD's ``O(n²)`` (three such plants, 400 points
    each: 1.3 → 0.6 s). It is not the first choice because
    balancing is also what spoils both balanced forms on the loop below, where only the
    comparison with the dense solves notices it.

    Neither fast form is right on every model: the balancing before the Hessenberg
    reduction keeps FE plants with entries from 1 to 1e12 accurate, but on a loop whose
    output matrix is large and cancels near an integrator-like weight pole (S&P's
    distillation problem: W_P pole −1e-6 rad/s, controller poles to −1.7e8 rad/s, C to 9e7)
    it loses every digit at low frequency, and the modal form can lose them too (dkpy's
    22-state controller there: error 11 on σ̄ 180, the dense solves agree with
    python-control's TB05AD to 4e-6 relative)."""
    Hd = _probe_response(A, B, C, D, probe)
    H = _balanced_modal(A, B, C, D, s, probe, Hd, max_cond, rtol)
    if H is not None:
        return H
    eh, em = _error(Hh, Hd), _error(Hm, Hd)
    if np.isfinite(eh) and eh <= _ARBITER_RTOL and not em < eh:
        return _hessenberg_response(A, B, C, D, s)
    if np.isfinite(em) and em <= _ARBITER_RTOL:
        return _modal_eval(*modal, D, s)
    return _dense_response(A, B, C, D, s)


def _balanced_first(A: np.ndarray) -> bool:
    """Whether the balanced system's modal form is tried first: above
    ``_SVD_COND_STATES`` states, or where the diagonal balancing of ``A`` spreads over more
    than :data:`_SPREAD_BALANCED_FIRST` (O(n²); only for the models :class:`ArrayMemo`
    keeps)."""
    if A.shape[0] > _SVD_COND_STATES:
        return True
    if A.shape[0] < _MODAL.min_states:
        return False
    _, (sc, _) = scipy.linalg.matrix_balance(A, permute=False, separate=True)
    return bool(sc.max() > _SPREAD_BALANCED_FIRST * sc.min())


def _probes(s: np.ndarray) -> np.ndarray:
    """The probe points of ``s`` at which the forms are checked: the first, the last and
    one between. On the imaginary axis (``jω``) or the unit circle (``e^{jωT}``) the one
    between is at the geometric mean of the ends' frequencies, on the grid or not, so that
    grids with the same ends (one plant's responses on grids refined around different
    loops' poles) share their probes (:data:`_PROBED`); elsewhere the middle point. At
    least three points: one or two are their own probes and are solved as such."""
    a, b = s[0], s[-1]
    with np.errstate(all="ignore"):
        if np.all(s.real == 0) and a.imag > 0 and b.imag > 0:
            mid = 1j * np.sqrt(a.imag * b.imag)
        elif np.allclose(np.abs(s), 1.0, rtol=0, atol=1e-12) and np.angle(a) > 0 \
                and np.angle(b) > 0:
            mid = np.exp(1j * np.sqrt(np.angle(a) * np.angle(b)))
        else:
            mid = s[s.size // 2]
    return np.array([a, mid, b])


def _error(H: np.ndarray, Hd: np.ndarray) -> float:
    """Largest error of ``H`` against the dense solves ``Hd`` at the probes, relative to the
    largest entry of ``Hd`` at each probe (``nan`` where either is not finite)."""
    with np.errstate(all="ignore"):
        scale = np.maximum(np.max(np.abs(Hd), axis=(1, 2)), np.finfo(float).tiny)
        return float(np.max(np.max(np.abs(H - Hd), axis=(1, 2)) / scale))


def _balanced_modal(A, B, C, D, s, probe, Hd, max_cond, rtol) -> np.ndarray | None:
    """The response on ``s`` by the modal form of the balanced system if it is within
    ``rtol`` of the dense solves ``Hd`` at ``probe``; else None. Used where the modal form of
    ``A`` is ill conditioned, and by :func:`_arbitrated`.

    cond V depends on the state scaling: a 268-state second-order plant ([q; q̇] with
    modes up to 280 kHz) has cond V 5.8e8 > 1e8, balanced 1.1e4, and its balanced modal
    response agrees with the dense solves to 5e-9 at the probes of its frequency grid
    (TB05AD point by point instead: ~26 s of a 45 s analysis of that plant).
    Checked against the dense solves, not the Hessenberg form: both balanced forms share the
    scaling (see :func:`_arbitrated`)."""
    lam, _, Bb, Cb = _BALANCED.get((A, B, C), max_cond,
                                   lambda: _modal_form(A, B, C, max_cond, balance=True))
    if Bb is None or not _error(_modal_eval(lam, Bb, Cb, D, probe), Hd) <= rtol:
        return None
    return _modal_eval(lam, Bb, Cb, D, s)


def _balanced_modal_checked(A, B, C, D, s, max_cond, rtol) -> np.ndarray | None:
    """The response on ``s`` by the modal form of the balanced system if it agrees with
    dense solves at the probes to ``rtol`` (:func:`_balanced_modal`) or is as close to them
    as the Hessenberg form (:func:`_balanced_modal_as_good`); else None.

    Where ``cond V`` of ``A`` itself is too large, and first of all on a large model
    (above ``_SVD_COND_STATES`` states): an FE plant in [q; q̇] form there has cond V far
    above ``max_cond`` unbalanced (3e9 at 1 888 states, 230 beam
    elements), so trying ``A``'s own eigenvectors first cost an eig of the whole model for
    nothing (18 s at 3 248 states)."""
    probe = _probes(s)
    Hd = _probe_response(A, B, C, D, probe)
    H = _balanced_modal(A, B, C, D, s, probe, Hd, max_cond, rtol)
    return H if H is not None else _balanced_modal_as_good(A, B, C, D, s, probe, Hd, max_cond)


#: The balanced modal form is taken instead of the Hessenberg form when its error against
#: the dense solves at the probes is at most this factor times the Hessenberg form's
#: (:func:`_balanced_modal_as_good`).
_AS_GOOD = 2.0
#: ... or when its normwise backward error at the probes is at most this many ε: that of a
#: backward-stable solve such as the Hessenberg form's (as ``eig``'s residual in
#: :func:`ambseal.lti.modal_loop._inverse_iteration`). The kept decompositions of the test
#: facility on 100 and 230 beam elements show 0.9 and 1.5 ε; the same with every pole
#: moved by 1e-9 relative, 258 and 81 ε.
_BACKWARD_EPS = 64


def _balanced_modal_as_good(A, B, C, D, s, probe, Hd, max_cond) -> np.ndarray | None:
    """The response on ``s`` by the modal form of the balanced system when it misses
    ``rtol`` against the dense solves ``Hd`` at ``probe`` but is as good as the Hessenberg
    form (within ``_ARBITER_RTOL`` of them, and backward stable — :func:`_backward_error`
    at most ``_BACKWARD_EPS`` ε at every probe — or else within ``_AS_GOOD`` times the
    Hessenberg form's own error); else None.

    Where the spectrum spans many decades neither fast form meets 1e-8: an FE model
    of 230 beam elements (1 888 states, eigenvalues from 39 Hz to 1.1 MHz) has the balanced modal
    form 2.78e-8 and the Hessenberg form 2.76e-8 of the peak from the dense solves refined
    in extended precision (the plain dense solves 1e-9). They are equally good — both the
    exact responses of the balanced plant perturbed by a few ε (the modal form's backward
    error 3e-16 at each probe): the error is the balanced problem's conditioning, not the
    method's —, but the Hessenberg form costs an O(n³) reduction (1.1 s at 1 888 states)
    and O(n²) per point (TB05AD: 17 ms, 314 s of an analysis of that model) against O(n)
    for the modal one."""
    lam, _, Bb, Cb = _BALANCED.get((A, B, C), max_cond,
                                   lambda: _modal_form(A, B, C, max_cond, balance=True))
    if Bb is None:
        return None
    eb = _error(_modal_eval(lam, Bb, Cb, D, probe), Hd)
    if not eb <= _ARBITER_RTOL:
        return None
    if _backward_error(A, B, C, probe, max_cond) <= _BACKWARD_EPS * _EPS:
        return _modal_eval(lam, Bb, Cb, D, s)
    eh = _error(_probe_response(A, B, C, D, probe, "hessenberg"), Hd)
    if not (np.isfinite(eh) and eb <= _AS_GOOD * eh):
        return None
    return _modal_eval(lam, Bb, Cb, D, s)


def _backward_error(A, B, C, probe, max_cond) -> float:
    """The largest normwise backward error (Rigal & Gaches 1967; Higham, *Accuracy and
    Stability of Numerical Algorithms*, 2nd ed., 2002, Thm 7.1) of the balanced modal form's
    state response at the probes: ``‖(sI − A_b) X − B_b‖_F / (‖sI − A_b‖_F ‖X‖_F + ‖B_b‖_F)``,
    ``X = V diag(1/(s − λ)) V⁻¹ B_b``, ``A_b = T⁻¹ A T``, ``B_b = T⁻¹ B`` (the kept
    decomposition of a large ``(A, C)``, :func:`_eig_form`; ``inf`` below
    ``STRUCTURED_STATES`` states, where none is kept). O(n² m) a probe: ``V`` from its kept
    LU factors, no n × n product."""
    if A.shape[0] < STRUCTURED_STATES:
        return np.inf
    return _BACKWARD.get((A, B, C), (max_cond, tuple(complex(p) for p in probe)),
                         lambda: _backward_error_of(A, B, C, probe, max_cond))


#: :func:`_backward_error` of the last large systems: the grids of one plant's responses,
#: refined around different loops' poles, share their probes (:func:`_probes`)
_BACKWARD = ArrayMemo(keep=16, min_states=STRUCTURED_STATES)


def _backward_error_of(A, B, C, probe, max_cond) -> float:
    lam, _, lu, _, sc = _EIG.get((A, C), (max_cond, True),
                                 lambda: _eig_form(A, C, max_cond, True))
    if lu is None:
        return np.inf
    LU, piv = lu
    n = A.shape[0]
    perm = np.arange(n)  # LAPACK's interchanges as one permutation: V = Pᵀ L U
    for i, j in enumerate(piv):
        perm[i], perm[j] = perm[j], perm[i]
    trmm = scipy.linalg.get_blas_funcs("trmm", (LU,))
    Bs = B / sc[:, None]
    Bm = scipy.linalg.lu_solve(lu, Bs.astype(LU.dtype), check_finite=False)
    # ‖sI − A_b‖²_F = ‖A_b‖²_F − 2 Re(s̄ tr A_b) + n |s|²
    normA2 = sum(float(np.sum(np.square(A[k:k + 256] * sc[None, :] / sc[k:k + 256, None])))
                 for k in range(0, n, 256))
    worst = 0.0
    for p in probe:
        LUY = trmm(1.0, LU, trmm(1.0, LU, Bm / (p - lam)[:, None]), lower=1, diag=1)
        X = np.empty_like(LUY)
        X[perm] = LUY
        TX = sc[:, None] * X
        AX = (A @ TX.real + 1j * (A @ TX.imag)) / sc[:, None]
        res = np.linalg.norm(p * X - AX - Bs)
        normS = np.sqrt(max(normA2 - 2 * (np.conj(p) * np.trace(A)).real + n * abs(p) ** 2,
                            0.0))
        worst = max(worst, res / (normS * np.linalg.norm(X) + np.linalg.norm(Bs)))
    return float(worst)


def _probe_response(A, B, C, D, probe, form: str = "dense") -> np.ndarray:
    """``C (sI − A)⁻¹ B + D`` at the probe points by dense solves (:func:`_dense_response`)
    or by the Hessenberg form (``form="hessenberg"``), each point
    kept for the last large systems (:data:`_PROBED`): the grids of one plant's responses
    share their probes (:func:`_probes`)."""
    solve = _dense_response if form == "dense" else _hessenberg_response
    computed: list = []

    def at(k):  # a miss computes every probe at once (one Hessenberg form, not three)
        if not computed:
            computed.append(solve(A, B, C, D, probe))
        return computed[0][k]

    out = np.empty((probe.size, C.shape[0], B.shape[1]), dtype=complex)
    digest = _PROBED.digest((A, B, C, D))
    for k, p in enumerate(probe):
        out[k] = _PROBED.get_digested(digest, (form, complex(p)), lambda k=k: at(k))
    return out


def _dense_response(A, B, C, D, s) -> np.ndarray:
    """``C (sI − A)⁻¹ B + D`` by one LU solve per point (stacked); ``nan`` where singular.

    Rows of ``A`` that only say ``ẋ_i = x_j`` (one entry, 1, off the diagonal; no input) —
    the ``q̇ = v`` half of a second-order model's ``[q; v]`` form — are eliminated first
    (:func:`_kinematic_rows`): ``s x_i = x_j`` puts ``x_j = s x_i`` into the other rows,
    which leaves one complex LU of ``n − k`` unknowns per point instead of ``n`` (the
    second-order form ``(s²M + sD + K) q = f`` after ``M⁻¹``; with half the states such
    rows, 1/8 of the LU's work and 1/4 of its memory)."""
    I, J = _kinematic_rows(A, B)
    n, k = A.shape[0], I.size
    E = np.setdiff1d(np.arange(n), I)  # the equations kept
    R = np.setdiff1d(E, J)  # the unknowns kept besides x_I
    pos = np.empty(n, dtype=int)
    pos[E] = np.arange(E.size)
    A_EI, A_EJ, A_ER = (A[np.ix_(E, X)] for X in (I, J, R))
    Bc = B[E].astype(complex)
    rows_J, rows_R = pos[J], pos[R]
    out = np.empty((s.size, C.shape[0], B.shape[1]), dtype=complex)
    step = max(1, _CHUNK_BYTES // (16 * E.size * E.size))
    with np.errstate(all="ignore"):
        for i in range(0, s.size, step):
            sk = s[i:i + step, None, None]
            M = np.empty((sk.shape[0], E.size, E.size), dtype=complex)
            M[:, :, :k] = -A_EI - sk * A_EJ
            M[:, rows_J, np.arange(k)] += sk[:, :, 0] ** 2
            M[:, :, k:] = -A_ER
            M[:, rows_R, k + np.arange(R.size)] += sk[:, :, 0]
            for m, X in enumerate(_stacked_solve(M, Bc)):  # x_J = s x_I
                out[i + m] = (C[:, I] + s[i + m] * C[:, J]) @ X[:k] + C[:, R] @ X[k:] + D
    return out


def _stacked_solve(M: np.ndarray, R: np.ndarray) -> np.ndarray:
    """``M_k⁻¹ R`` for each ``k`` (one LAPACK call for the stack); ``nan`` where ``M_k`` is
    singular (a point on a pole)."""
    try:
        return np.linalg.solve(M, R)
    except np.linalg.LinAlgError:  # one at a time
        X = np.full((M.shape[0], *R.shape), np.nan + 0j)
        for k, Mk in enumerate(M):
            try:
                X[k] = np.linalg.solve(Mk, R)
            except np.linalg.LinAlgError:
                pass
        return X


def _kinematic_rows(A: np.ndarray, B: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """``(I, J)``: the rows ``i ∈ I`` of ``A`` whose only entry is ``A[i, j] = 1`` with
    ``j ∉ I`` and ``B[i] = 0`` (``ẋ_i = x_j``), each ``j ∈ J`` once; empty where there are
    none. O(n²)."""
    nz = A != 0
    cand = np.flatnonzero((nz.sum(axis=1) == 1) & ~np.any(B != 0, axis=1))
    j = np.argmax(nz[cand], axis=1)
    ok = A[cand, j] == 1.0
    cand, j = cand[ok], j[ok]
    _, first = np.unique(j, return_index=True)  # each x_j replaced once
    cand, j = cand[first], j[first]
    keep = ~np.isin(j, cand)
    return cand[keep], j[keep]


def eigenvalues(A: np.ndarray, C: np.ndarray | None = None) -> np.ndarray:
    """Eigenvalues of ``A``; with ``C`` and from ``STRUCTURED_STATES`` states, those of the
    balanced eigendecomposition kept for ``(A, C)`` — the one the system's frequency
    responses, its loops' poles and its sampled form share — so that a system whose
    eigenvalues are asked first is decomposed once, not twice.

    Parameters
    ----------
    A : numpy.ndarray, shape (n, n)
        State matrix.
    C : numpy.ndarray, shape (p, n), optional
        The system's output matrix (names the kept decomposition).

    Returns
    -------
    numpy.ndarray of complex, shape (n,)
        In no particular order; shared with the kept decomposition: do not modify it.
    """
    A = np.asarray(A, float)
    if C is None or A.shape[0] < STRUCTURED_STATES:
        return np.linalg.eigvals(A)
    C = np.asarray(C, float)
    return _EIG.get((A, C), (_MAX_COND, True), lambda: _eig_form(A, C, _MAX_COND, True))[0]


def modal_form(A: np.ndarray, B: np.ndarray, C: np.ndarray, *, max_cond: float = 1e8):
    """``(λ, V⁻¹B, CV)`` of the balanced system (``A, B, C`` → ``T⁻¹AT, T⁻¹B, CT``, ``T``
    diagonal; the eigendecomposition kept per ``(A, C)`` and shared with the frequency
    responses), or ``None`` when ``cond V > max_cond``.

    Parameters
    ----------
    A : numpy.ndarray, shape (n, n)
        State matrix.
    B : numpy.ndarray, shape (n, m)
        Input matrix.
    C : numpy.ndarray, shape (p, n)
        Output matrix.
    max_cond : float
        Largest accepted condition number of ``V`` (as for :func:`freqresp`).

    Returns
    -------
    tuple (λ (n,), V⁻¹B (n, m), CV (p, n)) of complex arrays, or None
        Shared arrays: do not modify them in place.
    """
    lam, _, Bm, Cm = _modal_form(A, B, C, max_cond, balance=True)
    return None if Bm is None else (lam, Bm, Cm)


def _modal_form(A, B, C, max_cond, balance: bool = False):
    """(λ, cond V, V⁻¹B, CV) of ``A = V diag(λ) V⁻¹``; ``V⁻¹B``, ``CV`` None when
    ``cond V > max_cond`` (not used then). ``balance``: of the system balanced first
    (``A, B, C`` → ``T⁻¹AT, T⁻¹B, CT`` with ``T`` diagonal, as for the Hessenberg form).
    The eigendecomposition (λ, the LU of V, CV) is kept for the last large ``(A, C)``
    (:data:`_EIG`): the plant with its current inputs and with its force inputs too shares
    one."""
    lam, cond, lu, Cm, sc = _EIG.get((A, C), (max_cond, balance),
                                     lambda: _eig_form(A, C, max_cond, balance))
    if lu is None:
        return lam, cond, None, None
    B = B / sc[:, None] if balance else B
    return lam, cond, scipy.linalg.lu_solve(lu, B.astype(lu[0].dtype), check_finite=False), Cm


def _eig_form(A, C, max_cond, balance):
    """(λ, cond V, LU of V, CV, balancing scale) of :func:`_modal_form`; the LU and CV
    None when ``cond V > max_cond``."""
    sc = np.ones(A.shape[0])
    if balance:
        A, (sc, _) = scipy.linalg.matrix_balance(A, permute=False, separate=True)
        C = C * sc
    lam, V = scipy.linalg.eig(A, overwrite_a=balance)  # (the balanced A is a copy)
    Cm, norm, n = C @ V, np.linalg.norm(V, 1), V.shape[0]
    cond = np.linalg.cond(V) if n < STRUCTURED_STATES else None
    lanczos = cond is None and n <= _SVD_COND_STATES
    lu = scipy.linalg.lu_factor(V, overwrite_a=not lanczos, check_finite=False)
    if lanczos:
        cond = _cond_2(V, lu)
    elif cond is None:
        gecon, = scipy.linalg.get_lapack_funcs(("gecon",), (lu[0],))
        rcond, info = gecon(lu[0], norm, norm="1")
        cond = 1.0 / rcond if info == 0 and rcond > 0 else np.inf
    if not np.isfinite(cond) or cond > max_cond:
        return lam, cond, None, None, sc
    return lam, cond, lu, Cm, sc


#: Relative tolerance of the largest singular values :func:`_cond_2` finds
_COND_RTOL = 1e-6


def _cond_2(V: np.ndarray, lu) -> float:
    """cond₂ V = σ_max(V) σ_max(V⁻¹), each largest singular value by ARPACK's implicitly
    restarted Lanczos iteration on ``XᴴX`` (SciPy's ``svds``, to :data:`_COND_RTOL`, from a
    seeded start), ``V⁻¹`` applied through the LU of V: O(n²) a step instead of the SVD's
    O(n³) (an FE plant's V: 0.08–0.09 s against 0.31 s at 840 states, 0.04 s against
    0.06 s at 500; the same seven digits).
    ``inf`` where the LU is singular; the SVD where ARPACK does not converge."""
    if not np.all(np.diagonal(lu[0])):
        return np.inf
    n, dtype = V.shape[0], np.result_type(V.dtype, np.complex64)
    start = np.random.default_rng(0).standard_normal(n).astype(dtype)
    ops = (LinearOperator((n, n), dtype=dtype, matvec=lambda x: V @ x,
                          rmatvec=lambda x: (x.conj() @ V).conj()),  # Vᴴx, V not copied
           LinearOperator((n, n), dtype=dtype,
                          matvec=lambda x: scipy.linalg.lu_solve(lu, x, check_finite=False),
                          rmatvec=lambda x: scipy.linalg.lu_solve(lu, x, trans=2,
                                                                  check_finite=False)))
    try:
        with np.errstate(all="ignore"):
            cond = math.prod(float(svds(op, k=1, v0=start, tol=_COND_RTOL,
                                        return_singular_vectors=False)[0]) for op in ops)
    except ArpackError:  # ArpackNoConvergence among them
        return float(np.linalg.cond(V))
    return cond if np.isfinite(cond) else np.inf


def _modal_eval(lam: np.ndarray, Bm: np.ndarray, Cm: np.ndarray, D: np.ndarray, s: np.ndarray) -> np.ndarray:
    """``Cm diag(1/(s-λ)) Bm + D`` for each s, as one matrix product ``R W`` with
    ``R[k, i] = 1/(s_k − λ_i)`` and ``W[i, (a, b)] = Cm[a, i] Bm[i, b]`` (a GEMM instead of
    an (n_s, ny, n) temporary times Bm: 4× faster at 336 states, 4×6 channels, equal to
    1e-15 of the peak); chunks keep R small."""
    ny, n = Cm.shape
    nu = Bm.shape[1]
    W = (Cm.T[:, :, None] * Bm[:, None, :]).reshape(n, ny * nu)
    out = np.empty((s.size, ny, nu), dtype=complex)
    budget = _CHUNK_BYTES if n < STRUCTURED_STATES else _LARGE_MODAL_CHUNK_BYTES
    step = max(1, budget // (16 * max(1, n)))
    with np.errstate(divide="ignore", invalid="ignore"):
        for i in range(0, s.size, step):
            r = s[i : i + step, None] - lam[None, :]  # (k, n)
            np.divide(1.0, r, out=r)
            out[i : i + step] = (r @ W).reshape(-1, ny, nu) + D
    return out


def _hessenberg_response(A: np.ndarray, B: np.ndarray, C: np.ndarray, D: np.ndarray,
                         s: np.ndarray) -> np.ndarray:
    """``C (sI − A)⁻¹ B + D`` via one Hessenberg reduction and O(n²) solves per s.

    ``A`` is balanced first (diagonal similarity, ``scipy.linalg.matrix_balance``; Parlett &
    Reinsch 1969): FE models in [q; q̇] form have entries from 1 to 1e12 and lose several
    digits without it. The orthogonal reduction to upper Hessenberg form (LAPACK
    ``dgehrd``, as SLICOT ``TB05AD`` does it) is kept for the last large ``A``
    (:data:`_HESSENBERG`; any ``B``, ``C``). The solves use ``TB05AD`` (job ``'NH'``)
    through slycot when it is installed (Fortran loop, the routine python-control also
    uses), else the vectorised :func:`hessenberg_solve`.
    """
    memo = _HESSENBERG_LARGE if A.shape[0] >= STRUCTURED_STATES else _HESSENBERG
    Hs, Bh, Ch = _hessenberg_system(memo.get((A,), None, lambda: _hessenberg_form(A)), B, C)
    if _USE_SLYCOT:
        try:
            return _slycot_response(Hs, Bh, Ch, D, s)
        except ImportError:
            pass
    n = Hs.shape[0]
    out = np.empty((s.size, Ch.shape[0], Bh.shape[1]), dtype=complex)
    step = max(1, _CHUNK_BYTES // (16 * n * n))
    with np.errstate(divide="ignore", invalid="ignore"):
        for i in range(0, s.size, step):
            X = hessenberg_solve(Hs, Bh, s[i : i + step])
            out[i : i + step] = Ch @ X + D
    return out


def _hessenberg_form(A):
    """``(R, τ, sc)``: LAPACK ``dgehrd`` of the balanced ``T⁻¹AT`` (``T = diag(sc)``) —
    ``H = Qᵀ T⁻¹AT Q`` on and above the first subdiagonal of ``R``, ``Q``'s Householder
    vectors below it — without forming ``Q`` (``dorghr``: a quarter of the work and an
    n × n matrix more to keep)."""
    A, (sc, _) = scipy.linalg.matrix_balance(A, permute=False, separate=True)
    n = A.shape[0]
    if n < 3:  # nothing to reduce
        return A, np.zeros(max(n - 1, 0)), sc
    gehrd, gehrd_lwork = scipy.linalg.get_lapack_funcs(("gehrd", "gehrd_lwork"), (A,))
    work, _ = gehrd_lwork(n, lo=0, hi=n - 1)
    lwork = int(np.real(work))
    R, tau, info = gehrd(A, lo=0, hi=n - 1, lwork=lwork, overwrite_a=1)
    if info != 0:
        raise ModelError(f"freqresp: the Hessenberg reduction failed (LAPACK dgehrd info={info})")
    return R, tau, sc


def _hessenberg_system(form, B, C):
    """``(H, QᵀT⁻¹B, CTQ)`` from :func:`_hessenberg_form`'s ``form``: ``Q = diag(1, Q₁)`` with
    ``Q₁`` the product of the reflectors stored as a QR factorisation's in ``R[1:, :n−1]``,
    applied by ``dormqr``."""
    R, tau, sc = form
    n = R.shape[0]
    Bt, Ct = B / sc[:, None], C * sc[None, :]
    if n < 3:
        return R, Bt, Ct
    ormqr, = scipy.linalg.get_lapack_funcs(("ormqr",), (R,))
    V = R[1:, :n - 1]
    Bh, Ch = Bt.copy(), Ct.copy()
    for side, trans, X, rows in (("L", "T", Bh, np.s_[1:, :]), ("R", "N", Ch, np.s_[:, 1:])):
        if X.size:
            part = X[rows]
            _, work, _ = ormqr(side, trans, V, tau, part, -1)  # the workspace query
            out, _, info = ormqr(side, trans, V, tau, part, int(np.real(work[0])))
            if info != 0:
                raise ModelError(f"freqresp: applying the Hessenberg reflectors failed "
                                 f"(LAPACK dormqr info={info})")
            X[rows] = out
    return np.triu(R, -1), Bh, Ch


def _slycot_response(Hs: np.ndarray, Bh: np.ndarray, Ch: np.ndarray, D: np.ndarray, s: np.ndarray) -> np.ndarray:
    """TB05AD with job 'NH' (A given in upper Hessenberg form): O(n²) per frequency."""

    n, m = Bh.shape
    p = Ch.shape[0]
    out = np.empty((s.size, p, m), dtype=complex)
    At, Bt, Ct = (np.array(x, dtype=float, order="F") for x in (Hs, Bh, Ch))
    for k, sk in enumerate(s):
        try:
            g = tb05ad(n, m, p, sk, At, Bt, Ct, job="NH")[0]
        except Exception:  # slycot raises when s_k is (numerically) a pole: singular sI - A
            g = np.full((p, m), np.nan + 1j * np.nan)
        out[k] = g + D
    return out


def hessenberg_solve(Hs: np.ndarray, R: np.ndarray, s: np.ndarray) -> np.ndarray:
    """Solve ``(s_k I − Hs) X_k = R`` for every ``s_k`` with ``Hs`` upper Hessenberg.

    Gaussian elimination with partial pivoting between the two candidate rows of each column
    (Golub & Van Loan, *Matrix Computations*, 4th ed., §4.3.4 / Laub 1981), vectorised over
    ``s``: ``n`` Python-level steps, each ``O(len(s)·n)``.

    Parameters
    ----------
    Hs : ndarray, shape (n, n)
        Upper Hessenberg matrix (entries below the first subdiagonal are ignored).
    R : ndarray, shape (n, m)
        Right-hand sides.
    s : ndarray of complex, shape (k,)
        Shifts.

    Returns
    -------
    ndarray of complex, shape (k, n, m)
    """
    n = Hs.shape[0]
    k = s.size
    M = np.broadcast_to(-np.triu(Hs, -1).astype(complex), (k, n, n)).copy()
    idx = np.arange(n)
    M[:, idx, idx] += s[:, None]
    X = np.broadcast_to(R.astype(complex), (k, n, R.shape[1])).copy()
    for j in range(n - 1):
        swap = np.abs(M[:, j + 1, j]) > np.abs(M[:, j, j])
        if swap.any():
            top = M[swap, j, j:].copy()
            M[swap, j, j:] = M[swap, j + 1, j:]
            M[swap, j + 1, j:] = top
            top = X[swap, j, :].copy()
            X[swap, j, :] = X[swap, j + 1, :]
            X[swap, j + 1, :] = top
        lmul = M[:, j + 1, j] / M[:, j, j]
        M[:, j + 1, j:] -= lmul[:, None] * M[:, j, j:]
        X[:, j + 1, :] -= lmul[:, None] * X[:, j, :]
    # back substitution on the upper triangular factor
    X[:, n - 1, :] /= M[:, n - 1, n - 1, None]
    for j in range(n - 2, -1, -1):
        X[:, j, :] -= np.einsum("kj,kjm->km", M[:, j, j + 1 :], X[:, j + 1 :, :])
        X[:, j, :] /= M[:, j, j, None]
    return X
