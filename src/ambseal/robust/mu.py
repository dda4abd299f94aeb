"""Structured singular value μ: upper and lower bounds for mixed real/complex structures.

Block structures follow MATLAB's ``mussv`` notation: a list of pairs ``(r, c)``

* ``(-k, 0)``: repeated real scalar ``δ I_k``, ``δ ∈ ℝ``;
* ``(k, 0)``: repeated complex scalar ``δ I_k``, ``δ ∈ ℂ``;
* ``(r, c)`` with ``c > 0``: full complex ``r × c`` block.

Δ = blockdiag(Δ_1, …) is ``m × n`` for ``M`` of shape ``n × m``: block ``j`` reads ``c_j``
rows of ``M`` (its outputs) and drives ``r_j`` columns (its inputs), so ``Σ c_j = n`` and
``Σ r_j = m``; scalar blocks count ``k`` for both. μ_Δ(M) = 1 / min{σ̄(Δ) : det(I − MΔ) = 0}.
For robust performance Δ̂ = diag(Δ, Δ_P) collects the model uncertainty and the fictitious
performance block; robust performance holds when sup_ω μ < 1 (Skogestad & Postlethwaite
2005, §8.10).

Upper bound
    The D–G bound of Fan, Tits & Doyle (1991) (Young, Newlin & Doyle 1995): μ ≤ β if there
    are D ≻ 0 and G = Gᴴ commuting with the structure such that
    ``Mᴴ D M + j(G M − Mᴴ G) − β² D ⪯ 0``. Non-square full blocks are padded to square ones
    (μ unchanged), D has a full Hermitian block for each repeated scalar, G lives on real
    blocks only. The generalised-eigenvalue problem in (D, G) is solved by the method of
    centres (Boyd & El Ghaoui 1993) with damped Newton steps, vectorised over the stack
    (``robust/_mu_upper.py``); over a frequency grid it runs coarse to fine, each frequency
    starting from the scalings of its solved neighbours. The returned bound is the
    generalised eigenvalue at the returned (D, G): a certificate, whatever the solver's
    accuracy or starting point.
Lower bound
    The mixed power algorithm (Young & Doyle 1990, 1997; Packard & Doyle 1993 §9 for
    complex structures) from several starts — the right singular vector of M, the worst
    direction of the D–G certificate, seeded random vectors and, for real blocks, the
    complex iteration's phases projected on the real axis — then a refinement of the best
    candidates (gradient projection on max |λ| s.t. λ real, ``robust/_mu_lower.py``), each
    stage ended by its own stall rule, not a count. The bound is 1/σ̄(Δ) for a structured Δ
    that makes I − MΔ singular (returned as ``delta``).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Sequence

import numpy as np

from ambseal.errors import ModelError
from ambseal.lti.freqresp import freqresp
from ambseal.robust._mu_lower import lower_bound as _lower_bound
from ambseal.robust._mu_upper import upper_bound as _upper_bound
from ambseal.threads import with_numerics_threads

__all__ = ["MuResult", "MuPeak", "mussv", "mu_peak", "upper_near_peak", "upper_on_grid",
           "lower_on_grid", "parse_blocks", "check_blocks", "PEAK_BAND"]


# --------------------------------------------------------------------------- blocks
@dataclass(frozen=True)
class _Block:
    kind: str  # "real", "complex" (repeated scalars) or "full"
    r: int  # columns of M driven (Δ rows)
    c: int  # rows of M read (Δ columns)

    @property
    def size(self) -> int:
        return max(self.r, self.c)


def parse_blocks(blocks: Sequence[Sequence[int]]) -> tuple[_Block, ...]:
    """Validate a MATLAB-style block structure.

    Parameters
    ----------
    blocks : sequence of (int, int)
        ``(-k, 0)`` repeated real, ``(k, 0)`` repeated complex, ``(r, c)`` full complex.

    Returns
    -------
    tuple of _Block

    Raises
    ------
    ModelError
        Empty structure, non-integer entries, ``k = 0``, a negative size in a full block.
    """
    if blocks is None or len(blocks) == 0:
        raise ModelError("blocks: empty block structure")
    out = []
    for i, b in enumerate(blocks):
        try:
            r, c = (int(v) for v in b)
            if any(float(v) != int(v) for v in b) or len(b) != 2:
                raise ModelError
        except (TypeError, ValueError):
            raise ModelError(f"blocks[{i}]={b!r}: expected a pair of integers (r, c)") from None
        if c == 0:
            if r == 0:
                raise ModelError(f"blocks[{i}]=(0, 0): a block needs a non-zero size")
            out.append(_Block("real" if r < 0 else "complex", abs(r), abs(r)))
        else:
            if r <= 0 or c < 0:
                raise ModelError(f"blocks[{i}]=({r}, {c}): a full block needs r > 0 and c > 0")
            out.append(_Block("full", r, c))
    return tuple(out)


def check_blocks(P, blocks, nmeas: int, ncon: int) -> tuple[_Block, ...]:
    """The block structure of ``F_l(P, K)``: parsed, and checked against P's channels.

    Δ blocks map z to w: ``Σ r`` must equal the number of exogenous inputs and ``Σ c`` the
    number of exogenous outputs of ``P`` (its inputs less ``ncon``, outputs less ``nmeas``).
    The one check used by :func:`ambseal.robust.dk.musyn` and the generalised plant.

    Parameters
    ----------
    P : control.StateSpace
        Generalised plant, inputs ``[w, u]``, outputs ``[z, y]``.
    blocks : sequence of (int, int)
        MATLAB ``mussv`` notation (:func:`parse_blocks`).
    nmeas, ncon : int
        Measurements (last outputs) and controls (last inputs).

    Returns
    -------
    tuple of _Block

    Raises
    ------
    ModelError
        Malformed blocks, or blocks that do not cover the exogenous channels.
    """
    blks = parse_blocks(blocks)
    nw, nz = P.ninputs - ncon, P.noutputs - nmeas
    sr, sc = sum(b.r for b in blks), sum(b.c for b in blks)
    if (sr, sc) != (nw, nz):
        raise ModelError(
            f"blocks {[tuple(b) for b in blocks]}: the structure covers {sr} inputs × {sc} "
            f"outputs, but P has {nw} exogenous inputs and {nz} exogenous outputs (excluding {ncon} "
            f"controls and {nmeas} measurements)")
    return blks


def _dims(blks):
    return sum(b.c for b in blks), sum(b.r for b in blks)


# --------------------------------------------------------------------------- result
@dataclass(frozen=True)
class MuResult:
    """Bounds on μ over a stack of matrices (or over frequency).

    Attributes
    ----------
    upper, lower : ndarray, shape ``stack``
        Upper and lower bounds of μ (dimensionless); ``lower ≤ upper``.
    Dl : ndarray, shape ``stack + (n, n)``
        Left (output-side) scaling, Hermitian positive definite.
    Dr : ndarray, shape ``stack + (m, m)``
        Right (input-side) scaling, with the same block values as ``Dl``; for purely complex
        structures ``σ̄(Dl M Dr⁻¹) ≤ upper``.
    G : ndarray, shape ``stack + (m, n)``
        Real-block scaling: ``Mᴴ Dl² M + j(G M − Mᴴ Gᴴ) ⪯ upper² Dr²`` (zero without real
        blocks).
    dscale : ndarray, shape ``stack + (nblocks,)``
        Scalar D per block (``Dl = blockdiag(dscale_j I)`` for full and 1×1 blocks;
        ``sqrt(tr D_j² / k)`` for repeated scalars), normalised so the last block is 1.
    delta : ndarray, shape ``stack + (m, n)``
        Worst-case perturbation from the lower bound: structured, ``σ̄(Δ) = 1/lower`` and
        ``I − MΔ`` singular (zero where the lower bound is 0).
    omega : ndarray or None
        Frequencies in rad/s when computed over frequency.
    blocks : tuple
        The block structure as given.
    peak : MuPeak or None
        The upper bound's peak refined between the grid points (:func:`mu_peak`) when a
        system was analysed with ``peak=True``: a sharp peak (a real parameter at a lightly
        damped mode) can lie far above every grid point.
    """

    upper: np.ndarray
    lower: np.ndarray
    Dl: np.ndarray = field(repr=False)
    Dr: np.ndarray = field(repr=False)
    G: np.ndarray = field(repr=False)
    dscale: np.ndarray = field(repr=False)
    delta: np.ndarray = field(repr=False)
    omega: np.ndarray | None = None
    blocks: tuple = ()
    peak: "MuPeak | None" = field(default=None, repr=False)

    @property
    def peak_upper(self) -> float:
        """Largest upper bound over the stack, or over frequency between the grid points
        too when :attr:`peak` was refined."""
        grid = float(np.max(self.upper))
        return grid if self.peak is None else max(grid, self.peak.peak)

    @property
    def peak_omega(self) -> float | None:
        """Frequency (rad/s) of :attr:`peak_upper`, or None for a matrix stack."""
        if self.omega is None:
            return None
        if self.peak is not None and self.peak.peak > float(np.max(self.upper)):
            return self.peak.omega_peak
        return float(self.omega[np.argmax(self.upper)])

    def to_dict(self) -> dict:
        """JSON-ready bounds (scalings left out); ``lower`` is None when it was not
        computed (``mussv(..., lower=False)``: NaN is not JSON)."""
        low = np.asarray(self.lower)
        return {
            "upper": np.asarray(self.upper).tolist(),
            "lower": None if np.isnan(low).all() else low.tolist(),
            "peak_upper": self.peak_upper,
            "omega_rad_s": None if self.omega is None else np.asarray(self.omega).tolist(),
            "blocks": [list(b) for b in self.blocks],
        }


# --------------------------------------------------------------------------- helpers
def _herm(X):
    return 0.5 * (X + np.conj(np.swapaxes(X, -1, -2)))


def _ct(X):
    return np.conj(np.swapaxes(X, -1, -2))


def _pad(M, blks):
    """Embed M (…, n, m) into the padded square matrix (…, N, N)."""
    N = sum(b.size for b in blks)
    Mp = np.zeros(M.shape[:-2] + (N, N), complex)
    rows, cols = [], []
    o = 0
    for b in blks:
        rows.extend(range(o, o + b.c))
        cols.extend(range(o, o + b.r))
        o += b.size
    rows, cols = np.array(rows, int), np.array(cols, int)
    Mp[..., rows[:, None], cols[None, :]] = M
    return Mp, rows, cols


# --------------------------------------------------------------------------- lower bound
def _worst_direction(Mp, D, G, cols):
    """Start vectors (b, w) of the power iteration from the upper bound's certificate.

    The top generalised eigenvector x of ``(Mᴴ D M + j(G M − Mᴴ G), D)`` is the direction
    in which the D–G bound is tight (for complex structures the right singular vector of
    the scaled matrix mapped back, b = x); ``w = D x`` is its dual.
    """
    A = _ct(Mp) @ D @ Mp + 1j * (G @ Mp - _ct(Mp) @ G)
    ev, V = np.linalg.eigh(D)
    Dmh = (V / np.sqrt(np.maximum(ev, 1e-300))[:, None, :]) @ _ct(V)
    _, U = np.linalg.eigh(_herm(Dmh @ A @ Dmh))
    x = np.einsum("fij,fj->fi", Dmh, U[:, :, -1])
    return x[:, cols], np.einsum("fij,fj->fi", D, x)[:, cols]


# --------------------------------------------------------------------------- public
_STRIDE = 32  # cold solves on every 32nd frequency, warm starts in between
#: The local maxima of a μ curve refined by :func:`mu_peak`: those within this share of its
#: largest value.
PEAK_BAND = 0.95


@with_numerics_threads
def mussv(M, blocks, omega=None, *, tol: float = 1e-3, max_iter: int | None = None,
          lower_iter: int | None = None, gmax: float = 1e3, seed: int = 0,
          lower: bool = True, peak_tol: float | None = None, peak: bool = True) -> MuResult:
    """Upper and lower bounds of the structured singular value μ_Δ(M).

    Parameters
    ----------
    M : array_like, shape (..., n, m), or control.StateSpace
        A complex matrix or a stack of them; or a continuous-time system evaluated at
        ``s = jω`` for each ``ω`` in ``omega``.
    blocks : sequence of (int, int)
        MATLAB ``mussv`` block structure (see module docstring); ``Σ c_j = n``, ``Σ r_j = m``.
    omega : array_like, optional
        Frequencies in rad/s; required when ``M`` is a state-space system.
    tol : float
        Relative stopping tolerance on ``upper²`` (method-of-centres gap); the bound is a
        certificate either way, ``tol`` only sets how close it gets to the optimal D–G bound
        (measured up to about ``tol`` relative on 500-point grids of 100-state loops). The bounds within
        ``2·tol`` of the largest one — the reported peak μ — are solved again to ``tol·1e-3``,
        then any other bound that still exceeds them, until the largest is a refined one
        (measured on a 108-state loop, 500 frequencies: peak within 3e-10 of a
        ``tol = 1e-6`` solve; refining only the largest, one at a time, had left it 2.6e-4
        above).
    max_iter : int, optional
        A cap on the upper-bound solver's levels (outer iterations) per matrix. None (the
        default): each matrix's solve ends at its own criterion, the gap within ``tol``,
        its interior lost to rounding, or a stall (its bound fell by less than ``tol`` over
        100 levels; ``_mu_upper.STALL_LEVELS``).
    lower_iter : int, optional
        A cap on the lower bound's power iterations per start. None (the default): each
        start's iteration ends at its first checkpoint (every 10 steps) that raises its
        best candidate by no more than 1e-3 of it, and the refinement of a candidate after
        eight steps in a row that raise it by no more than 1e-3 of its bound at the last
        rise, a candidate not yet on the real axis having at least 25 steps to reach it
        (``_mu_lower.POWER_RTOL``, ``REFINE_RTOL``, ``PATIENCE``, ``REACH_STEPS``); the
        cap does not bound the refinement. The bound is a certificate either way.
    gmax : float
        Bound on ‖G‖ relative to the normalised problem (real blocks only).
    seed : int
        Seed of the random starts of the power iteration.
    lower : bool
        Compute the lower bound and the worst-case Δ (default). False: ``lower`` is NaN and
        ``delta`` zero, for callers that read only the upper bound and its scalings (D–K's
        D- and μ-steps: about 15 % of each μ evaluation on a 108-state loop); the upper
        bound does not depend on it.
    peak_tol : float, optional
        Tolerance of the second solve of the bounds near the largest one (default
        ``tol·1e-3``, above); ``peak_tol = tol`` skips it, for callers that re-solve the
        few bounds they keep (:func:`mu_peak`'s exploring rounds).
    peak : bool
        With a system ``M`` on more than one frequency: also refine the upper bound's peak
        between the grid points (:func:`mu_peak` with its defaults: brackets narrowed to
        1e-4 in ln ω or to a top flat within 1e-4 relative),
        in ``MuResult.peak`` and :attr:`MuResult.peak_upper`; ``upper`` stays on ``omega``.
        A grid of 100 points misses a sharp real-μ peak at a lightly damped mode by several
        per cent. False: the grid alone (callers that refine the peaks they keep, such as
        the D–K iteration).

    Returns
    -------
    MuResult
        ``upper``/``lower`` with shape ``M.shape[:-2]`` (or ``(len(omega),)``), scalings,
        worst-case perturbation and the refined peak.

    Raises
    ------
    ModelError
        Malformed blocks, ``tol`` outside (0, 1), ``max_iter`` or ``lower_iter`` (when
        given) not a whole number ≥ 1, dimensions that do not match ``M``, missing
        ``omega``, non-finite entries.

    Notes
    -----
    For one full complex block the upper bound is σ̄(M); for a single repeated complex
    scalar it is ρ(M) (reached in the limit for defective M); for a single repeated real
    scalar it is the largest |real eigenvalue| (Packard & Doyle 1993; Young 1993).

    Examples
    --------
    >>> import numpy as np
    >>> M = np.outer([1, 2j], [3, -1])       # rank one: μ = Σ|a_i||b_i| = 5
    >>> r = mussv(M, [(1, 0), (1, 0)])
    >>> round(float(r.upper), 3), round(float(r.lower), 3)
    (5.0, 5.0)
    """
    blks = parse_blocks(blocks)
    if not (isinstance(tol, (int, float)) and 0.0 < tol < 1.0):
        raise ModelError(f"mussv: tol={tol!r}, expected a relative tolerance in (0, 1)")
    counts = (("max_iter", max_iter), ("lower_iter", lower_iter))
    for name, v in ((k, v) for k, v in counts if v is not None):
        if isinstance(v, bool) or not isinstance(v, (int, np.integer)) or v < 1:
            raise ModelError(f"mussv: {name}={v!r}, expected a whole number ≥ 1")
    Marr, w = _checked_response(M, blks, blocks, omega, "mussv")
    n, m = _dims(blks)
    stack = Marr.shape[:-2]
    Mf = Marr.reshape((-1, n, m))
    F = Mf.shape[0]
    Mp, rows, cols = _pad(Mf, blks)
    # over a frequency grid the scalings vary smoothly: solve coarse to fine (warm starts)
    smooth = w is not None and len(stack) == 1 and w.size > 1 and (
        np.all(np.diff(w) > 0) or np.all(np.diff(w) < 0))
    upper, D, Gp, offs = _upper_bound(Mp, blks, tol, max_iter, gmax,
                                      stride=_STRIDE if smooth else 0, peak_tol=peak_tol)
    if lower:
        lower, delta = _lower_bound(Mf, blks, lower_iter, np.random.default_rng(seed),
                                    upper=upper, starts=[_worst_direction(Mp, D, Gp, cols)])
    else:
        lower, delta = np.full(F, np.nan), np.zeros((F, m, n), complex)

    # scalings back in unpadded coordinates
    w_, V = np.linalg.eigh(D)
    Dh = (V * np.sqrt(np.maximum(w_, 0.0))[:, None, :]) @ _ct(V)
    Dl = Dh[:, rows][:, :, rows]
    Dr = Dh[:, cols][:, :, cols]
    G = Gp[:, cols][:, :, rows]
    ds = np.empty((F, len(blks)))
    for j, b in enumerate(blks):
        blkD = D[:, offs[j]:offs[j + 1], offs[j]:offs[j + 1]]
        ds[:, j] = np.sqrt(np.real(np.trace(blkD, axis1=1, axis2=2)) / b.size)
    ds = ds / ds[:, -1:]
    return MuResult(
        upper=upper.reshape(stack), lower=lower.reshape(stack),
        Dl=Dl.reshape(stack + (n, n)), Dr=Dr.reshape(stack + (m, m)), G=G.reshape(stack + (m, n)),
        dscale=ds.reshape(stack + (len(blks),)), delta=delta.reshape(stack + (m, n)),
        omega=w, blocks=tuple(tuple(int(v) for v in b) for b in blocks),
        peak=(mu_peak(M, blocks, w, upper, tol=tol) if peak and w is not None and w.size > 1
              and np.all(w > 0) else None))


def _complexify(blks):
    """Diagonal-D structure: repeated scalars → independent complex scalars."""
    out = []
    for b in blks:
        out.extend([(b.r, b.c)] if b.kind == "full" else [(1, 1)] * b.r)
    return out


def _checked_response(M, blks, blocks, omega, who: str):
    """``(M(jω) as (..., n, m), ω or None)``: a continuous state-space ``M`` evaluated on
    ``omega``, or a complex matrix (stack) as given; ModelError, naming ``who``, for a
    missing, misplaced or malformed grid, a discrete-time system, a shape that does not
    match ``blocks`` (``blks`` parsed) or non-finite entries."""
    w = None
    if hasattr(M, "A") and hasattr(M, "B"):
        if omega is None:
            raise ModelError(f"{who}: a state-space M needs a frequency grid omega (rad/s)")
        if getattr(M, "dt", 0) not in (0, None):
            raise ModelError(f"{who}: only continuous-time systems (dt = 0) are supported")
        try:
            w = np.atleast_1d(np.asarray(omega, float))
        except (TypeError, ValueError):
            w = np.zeros((0,))
        if w.ndim != 1 or w.size == 0 or not np.all(np.isfinite(w)):
            raise ModelError(f"{who}: omega must be a non-empty 1-D array of finite rad/s "
                             "values")
        Marr = freqresp(M, w)
    else:
        try:
            Marr = np.asarray(M, complex)
        except (TypeError, ValueError) as exc:
            raise ModelError(f"{who}: M must be a complex matrix or stack of them ({exc})"
                             ) from None
        if omega is not None:
            raise ModelError(f"{who}: omega is only used with a state-space M")
    if Marr.ndim < 2:
        raise ModelError(f"{who}: M must be (..., n, m), got shape {Marr.shape}")
    n, m = _dims(blks)
    if Marr.shape[-2:] != (n, m):
        raise ModelError(
            f"{who}: blocks {list(blocks)} need M of shape (..., {n}, {m}) "
            f"(Σc = {n} rows, Σr = {m} columns), got {Marr.shape[-2:]}")
    if not np.all(np.isfinite(Marr)):
        raise ModelError(f"{who}: M has non-finite entries")
    return Marr, w


def upper_on_grid(M, blocks, omega, *, tol: float = 1e-3):
    """The μ upper bound of a system on a frequency grid, a mixed structure solved only
    where it can reach its peak (D–K's μ-step, Balas et al. 1993).

    The structure with every repeated or real scalar made an independent complex scalar
    (diagonal D, the bound whose scalings D–K fits) is solved on the whole grid; where
    ``blocks`` is not that structure, its bound is :func:`upper_near_peak`'s with that
    bound as the cover: the whole grid's peak, at a fraction of the cost of a mixed bound
    at every frequency.

    Parameters
    ----------
    M : control.StateSpace
        Continuous-time system, ``Σ c`` outputs × ``Σ r`` inputs of ``blocks``.
    blocks : sequence of (int, int)
        MATLAB ``mussv`` block structure.
    omega : array_like, shape (F,)
        Increasing frequencies (rad/s).
    tol : float
        :func:`mussv`'s tolerance.

    Returns
    -------
    (MuResult, ndarray of shape (F,))
        :func:`mussv`'s result for the complexified structure (without the lower bound)
        and the upper bound of ``blocks`` on the grid.

    Raises
    ------
    ModelError
        As :func:`mussv`.
    """
    cblocks = _complexify(parse_blocks(blocks))
    mu_c = mussv(M, cblocks, omega, tol=tol, lower=False, peak=False)
    if cblocks == [tuple(b) for b in blocks]:
        return mu_c, np.asarray(mu_c.upper, float)
    return mu_c, upper_near_peak(M, blocks, omega, mu_c.upper, tol=tol)


def upper_near_peak(M, blocks, omega, cover, *, tol: float = 1e-3, chunk: int = 8
                    ) -> np.ndarray:
    """The μ upper bound of a system on a frequency grid where it can reach
    :data:`PEAK_BAND` of its peak, and ``cover`` — an upper bound of it at each frequency,
    such as the bound of the complexified structure — elsewhere.

    A mixed (real and complex) bound costs several times the complex one, and near a peak
    only part of the grid matters. The bound is solved in chunks of ``chunk`` frequencies,
    largest ``cover`` first, while ``cover`` still reaches ``PEAK_BAND`` of the largest
    bound found: the frequencies left cannot hold the peak or a local maximum
    :func:`mu_peak` refines. On a grid solved cold (at most twice the continuation stride,
    e.g. the 60 points of a design grid) the chunks are solved without :func:`mussv`'s peak
    refinement, then the bounds within ``2·tol`` of the largest again in calls that
    refine them as a whole-grid call would, until the largest bound is a refined one (a
    bound solved to ``tol`` alone can lie 0.3 % above its optimum, above the refined
    peak: on a loop of the blower's μ design, 1.1867 where the whole grid gives 1.1853,
    ``tests/data/blower_reduced_mu_loop.npz``): the peak is the whole
    grid's to about 1e-6, each other bound to the solver's tolerance (the method of
    centres runs a stack together, so a subset's bounds differ from the whole grid's by up
    to about 1e-4 relative). On a longer grid every point is solved in one call.

    Parameters
    ----------
    M : control.StateSpace
        Continuous-time system, ``Σ c`` outputs × ``Σ r`` inputs of ``blocks``.
    blocks : sequence of (int, int)
        MATLAB ``mussv`` block structure.
    omega : array_like, shape (F,)
        Increasing frequencies (rad/s).
    cover : array_like, shape (F,)
        An upper bound of the structure's μ at each frequency (dimensionless).
    tol : float
        :func:`mussv`'s tolerance.
    chunk : int
        Frequencies solved per call while searching (≥ 1).

    Returns
    -------
    ndarray, shape (F,)
        Upper bounds: :func:`mussv`'s where solved, ``cover`` elsewhere.

    Raises
    ------
    ModelError
        As :func:`mussv`; ``cover`` not of the grid's length.
    """
    w = np.asarray(omega, float)
    cover = np.asarray(cover, float)
    if cover.shape != w.shape:
        raise ModelError(f"upper_near_peak: cover has shape {cover.shape}, the grid "
                         f"{w.shape}")
    if w.size > 2 * _STRIDE:  # solved by continuation: every point, as mussv would
        return np.asarray(mussv(M, blocks, w, tol=tol, lower=False, peak=False).upper, float)
    out, solved, best = cover.copy(), np.zeros(w.size, bool), -np.inf
    order = np.argsort(-cover, kind="stable")
    for start in range(0, w.size, max(1, int(chunk))):
        idx = np.sort([i for i in order[start:start + chunk] if cover[i] >= PEAK_BAND * best])
        if not idx.size:
            break
        out[idx] = mussv(M, blocks, w[idx], tol=tol, lower=False, peak=False,
                         peak_tol=tol).upper
        solved[idx] = True
        best = max(best, float(out[idx].max()))
    # the refinement of a whole-grid call: the bounds within 2·tol (on μ²) of the largest,
    # until the largest is a refined one (an unrefined bound can lie above the optimum by
    # several times tol, and above the refined peak)
    if not solved.any():
        raise ModelError("upper_near_peak: no frequency solved (an empty grid, or a cover "
                         "that is not finite)")
    refined = np.zeros(w.size, bool)
    while True:
        best = float(out[solved].max())
        top = np.flatnonzero(solved & ~refined & (out ** 2 >= (1.0 - 2.0 * tol) * best ** 2))
        if not top.size:
            return out
        out[top] = mussv(M, blocks, w[top], tol=tol, lower=False, peak=False).upper
        refined[top] = True


@with_numerics_threads
def lower_on_grid(M, blocks, omega, *, seed: int = 0) -> np.ndarray:
    """Certified lower bounds of μ of a system on a frequency grid, without the upper bound.

    :func:`mussv`'s power algorithm alone (module ``_mu_lower``): each bound is
    ``1/σ̄(Δ)`` of a structured Δ that makes ``I − M(jω) Δ`` singular, so μ at that
    frequency — and every upper bound of it, :func:`upper_on_grid`'s included — is at least
    as large. For a caller that needs to know only that a peak exceeds a level: where a
    lower bound does, the upper bound, several times the cost on a mixed structure, is not
    needed (measured: 0.25 s against 4–5 s on a 122-state loop with a repeated real
    block; benchmarks/README.md, "A reduced controller's μ above the band, by its lower
    bound"). Its starts are ``M``'s top right singular vector and one seeded random vector.

    Parameters
    ----------
    M : control.StateSpace
        Continuous-time system, ``Σ c`` outputs × ``Σ r`` inputs of ``blocks``.
    blocks : sequence of (int, int)
        MATLAB ``mussv`` block structure.
    omega : array_like, shape (F,)
        Frequencies (rad/s).
    seed : int
        Seed of the random start.

    Returns
    -------
    ndarray, shape (F,)
        Lower bounds (dimensionless; 0 where no destabilising Δ was found).

    Raises
    ------
    ModelError
        As :func:`mussv` for a state-space ``M``: a missing or malformed grid, a
        discrete-time ``M``, channels that do not match ``blocks``, a non-finite response.
    """
    blks = parse_blocks(blocks)
    if omega is None:  # a matrix stack is mussv's to bound; here a grid is the point
        raise ModelError("lower_on_grid: expected a state-space M and its grid omega (rad/s)")
    Mf, _ = _checked_response(M, blks, blocks, omega, "lower_on_grid")
    lower, _ = _lower_bound(Mf, blks, None, np.random.default_rng(seed))
    return lower


# --------------------------------------------------------------------------- peak
@dataclass(frozen=True)
class MuPeak:
    """Peak over frequency of the μ upper bound, checked between grid points.

    Attributes
    ----------
    peak : float
        Largest upper bound over ``omega`` (dimensionless): the design grid and the points
        added around its local maxima.
    omega_peak : float
        Frequency (rad/s) of ``peak``.
    grid_peak : float
        Largest upper bound on the grid alone (``peak ≥ grid_peak``).
    omega : ndarray
        The frequencies (rad/s) of ``peak``, sorted: the grid and the points added (the best
        ones the search found, solved as precisely as the grid's largest bounds).
    upper : ndarray
        The upper bound at ``omega``.
    added : int
        Number of points added to the grid.
    evaluated : int
        Frequencies the search evaluated (to the solver's tolerance) to find them.
    """

    peak: float
    omega_peak: float
    grid_peak: float
    omega: np.ndarray = field(repr=False)
    upper: np.ndarray = field(repr=False)
    added: int = 0
    evaluated: int = 0

    def describe(self) -> str:
        """One line naming the grid of ``peak`` (for reports and logs)."""
        n = self.omega.size - self.added
        return (f"{n}-point grid {self.omega[0]:.4g}…{self.omega[-1]:.4g} rad/s plus "
                f"{self.added} points at the peaks found between its points by a search over "
                f"{self.evaluated} frequencies; peak at {self.omega_peak:.5g} rad/s")


def mu_peak(M, blocks, omega, upper=None, *, candidates: int = 2, band: float = PEAK_BAND,
            points: int = 4, rounds: int | None = None, xtol: float = 1e-4,
            ftol: float = 1e-4,
            resolve: int = 2, tol: float = 1e-3) -> MuPeak:
    """Peak of the μ upper bound of a system over frequency, refined around the grid's peaks.

    A peak of μ(ω) between two grid points is missed by the largest value on the grid (by
    up to a few per cent on a 10-points-per-decade grid near a lightly damped mode). This
    takes the grid's local maxima within ``band`` of the largest one (at most
    ``candidates`` of them) and narrows a bracket around each: in every round ``points``
    new frequencies, equally spaced in log ω inside the bracket of the best point so far,
    are evaluated together (one :func:`mussv` call for all brackets, bounds to ``tol/10``),
    and the bracket shrinks
    to the best point's neighbours — a grid search that contracts by about
    ``2/(points + 1)`` per round, the derivative-free interval reduction of Kiefer's
    Fibonacci/golden-section search (Kiefer 1953), batched; a new point that repeats one
    the bracket has is left out. A bracket is done when it is narrower than ``xtol`` in
    ln ω, or when its best point's two neighbours are both within ``ftol`` (relative) of
    it: a flat top, on which the peak lies between them. The search ends when every
    bracket is done, which the geometric contraction makes sure of: from two grid spacings
    of a 10-points-per-decade grid (0.46 in ln ω) to ``xtol`` in 10 rounds. ``rounds`` is a
    caller's cap, none by default. (A rule on the rise of the largest value over two rounds
    stopped on sharp resonances where the best point lay closer to the peak than the
    round's points: on a seeded family of lightly damped modes it left 1 in 5 peaks more
    than 1 % low, one at 6 % of its value.) The ``resolve`` best points found are solved
    again to ``tol·1e-3``, as :func:`mussv` does with a grid's largest bounds, and added to
    the grid. The value returned is the largest upper bound on that grid: each is a
    certificate at its own frequency (:func:`mussv`), so the result is an honest lower
    estimate of sup_ω of the bound, exact
    when the grid brackets every peak.

    Parameters
    ----------
    M : control.StateSpace
        Continuous-time system, ``Σ c`` outputs × ``Σ r`` inputs of ``blocks``.
    blocks : sequence of (int, int)
        MATLAB ``mussv`` block structure.
    omega : array_like, shape (F,)
        Grid in rad/s (> 0; sorted here).
    upper : array_like, shape (F,), optional
        The upper bound on ``omega`` when already computed (e.g. by the D-step).
    candidates : int
        Local maxima refined.
    band : float
        Only local maxima at least ``band`` times the grid's largest value are refined.
    points : int
        New frequencies per bracket and round.
    rounds : int, optional
        A cap on the rounds; None (default): the rules above alone end them.
    xtol : float
        Bracket width (in ln ω) below which a bracket is not refined further.
    ftol : float
        Relative difference of the best point's neighbours from it below which a bracket is
        a flat top, not refined further.
    resolve : int
        The best points found that are solved again to ``tol·1e-3`` and added to the grid.
    tol : float
        Tolerance of the bound's solver (:func:`mussv`): the grid's and the added points'
        (``tol/10`` while searching).

    Returns
    -------
    MuPeak

    Raises
    ------
    ModelError
        As :func:`mussv` (blocks that do not match, non-finite response); a grid that is not
        1-D with positive frequencies.

    Examples
    --------
    >>> import control as ct
    >>> G = ct.ss(ct.tf([1.0], [1.0, 0.02, 1.0]))      # resonance at 1 rad/s, peak 50
    >>> p = mu_peak(G, [(1, 1)], np.logspace(-1, 1, 20))    # no grid point at 1 rad/s
    >>> round(p.grid_peak, 2), round(p.peak, 1)
    (4.63, 50.0)
    """
    order = np.argsort(np.asarray(omega, float))
    w = np.asarray(omega, float)[order]
    if w.ndim != 1 or w.size == 0 or not np.all(np.isfinite(w)) or np.any(w <= 0):
        raise ModelError("mu_peak: omega must be a non-empty 1-D grid of positive rad/s values")
    if upper is None:
        u = np.asarray(mussv(M, blocks, w, tol=tol, lower=False, peak=False).upper, float)
    else:
        u = np.asarray(upper, float)[order]
        if u.shape != w.shape:
            raise ModelError("mu_peak: upper must have the shape of omega")
    grid_peak = float(np.max(u))
    lw = np.log(w)
    # local maxima of the grid's curve (ends included), largest first
    left = np.r_[-np.inf, u[:-1]]
    right = np.r_[u[1:], -np.inf]
    idx = np.flatnonzero((u >= left) & (u >= right) & (u >= band * grid_peak))
    idx = idx[np.argsort(-u[idx])][:max(int(candidates), 1)]
    # each bracket: its sample points (ln ω, value), sorted
    brackets = []
    for i in idx:
        lo, hi = max(i - 1, 0), min(i + 1, w.size - 1)
        brackets.append((lw[lo:hi + 1].copy(), u[lo:hi + 1].copy()))
    new_w, new_u = [], []
    done = 0
    while rounds is None or done < int(rounds):
        done += 1
        todo = []
        for k, (x, y) in enumerate(brackets):
            j = int(np.argmax(y))
            lo, hi = max(j - 1, 0), min(j + 1, x.size - 1)
            width = x[hi] - x[lo]
            if width <= xtol or min(y[lo], y[hi]) >= (1.0 - ftol) * y[j]:
                continue
            # the points lie on a lattice of the grid's spacing, so a new one can repeat an
            # old one; a repeated best point would be its own neighbour, and the bracket
            # would lose the side the peak is on
            todo.extend((k, v) for v in np.linspace(x[lo], x[hi], int(points) + 2)[1:-1]
                        if np.min(np.abs(x - v)) > 1e-9 * width)
        if not todo:
            break
        xs = np.array([v for _, v in todo])
        srt = np.argsort(xs)
        vals = np.empty(xs.size)
        vals[srt] = np.asarray(mussv(M, blocks, np.exp(xs[srt]), tol=0.1 * tol, lower=False, peak=False,
                                     peak_tol=0.1 * tol).upper, float)
        for (k, v), val in zip(todo, vals):
            x, y = brackets[k]
            pos = np.searchsorted(x, v)
            brackets[k] = (np.insert(x, pos, v), np.insert(y, pos, val))
        new_w.extend(np.exp(xs))
        new_u.extend(vals)
    new_w, new_u = np.asarray(new_w, float), np.asarray(new_u, float)
    evaluated = int(new_w.size)
    # the rounds solved each bound to tol/10, enough to locate the peak; the best few are
    # solved again like the grid's largest ones (mussv's second solve, tol·1e-3) and only
    # these join the grid. (Bounds solved to tol alone ranked the points wrongly on a problem
    # with four real scalar blocks: they exceeded their second solve by up to 0.4 %.)
    keep = np.argsort(-new_u)[:max(int(resolve), 1)] if new_u.size else np.zeros(0, int)
    keep = keep[np.argsort(new_w[keep])]
    new_w = new_w[keep]
    new_u = np.asarray(mussv(M, blocks, new_w, tol=tol, lower=False,
                                 peak=False).upper, float) \
        if new_w.size else new_u[keep]
    w_all = np.r_[w, new_w]
    u_all = np.r_[u, new_u]
    srt = np.argsort(w_all)
    w_all, u_all = w_all[srt], u_all[srt]
    k = int(np.argmax(u_all))
    return MuPeak(peak=float(u_all[k]), omega_peak=float(w_all[k]), grid_peak=grid_peak,
                  omega=w_all, upper=u_all, added=int(new_w.size), evaluated=evaluated)
