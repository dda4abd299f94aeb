"""μ-synthesis for mixed real/complex uncertainty by D–G–K iteration (Young 1996).

Complex D–K (:func:`ambseal.robust.dk.musyn`) treats a real parameter — a stiffness, a
gain known only within bounds — as if it could also be complex: its phase is free, which
makes the design conservative. D–G–K keeps the G scalings of the mixed μ upper bound
(Fan, Tits & Doyle 1991) in the synthesis (Young 1996, "Controller design for mixed
uncertainties using a D-G-K iteration"; the scheme of MATLAB's ``musyn`` for ureal blocks):

With D ≻ 0, G = Gᴴ from the mixed bound at a level β̄,
``Mᴴ D M + j(G M − Mᴴ G) ⪯ β̄² D``; with ``D̂ = D^½``, ``N = D̂ M D̂⁻¹/β̄`` and
``Ĝ = D̂⁻¹ G D̂⁻¹/β̄`` this is, after completing the square (Young 1996 eq. 7),

    σ̄((N − jĜ)(I + Ĝ²)^-½) ≤ 1.

So the D–G step, per scalar channel i (repeated scalars split into independent ones,
real ones stay real, so D and G are diagonal), takes the pointwise scalings of the mixed
bound at the current controller, relaxed where μ(ω) is below its peak towards those of the
frequencies where it is near it (they are not unique there, and the optimum jumps between
neighbouring frequencies), fits ``d_i(s)`` stable minimum-phase with ``|d_i| ≈ D̂_ii``
(:func:`~ambseal.robust.dk.fit_dscale`) and, for real channels, the pair
``f_i = (a1 + a2)/2``, ``h_i = (a1 − a2)/2`` of two stable all-pass functions whose phase
difference ψ fits ``2·arctan ĝ_i(ω)`` (:func:`fit_g`): then ``|f|² + |h|² = 1`` and
``h/f = −j tan(ψ/2)`` hold exactly, i.e. ``f = (1 + ĝ²)^-½`` and ``h = −jĝ f`` for the
fitted ĝ — Young's stable fit of jG in a form whose scaled problem is a valid D–G
certificate whatever the fit error. The fits are weighted again, round by round, towards
the frequencies where the current controller's scaled closed loop peaks (MATLAB's "DG
Fit"), and refined by a minimax of that peak only where they stay above it by more than
1 % (``_dg_step_scalings``; the private module ``_dgscale`` says why). The K-step is
H∞ synthesis on

    P_s = diag(D(s)/β̄, I) · P · diag(F(s) D(s)⁻¹, I) + [[H(s), 0], [0, 0]],

whose closed loop is ``(N − jĜ) F``. If it reaches γ ≤ 1 the new controller has
μ ≤ γ·β̄ on the scalar structure (the fitted (D, G) certify it:
Nᴴ N + j(Ĝ N − Nᴴ Ĝ) ⪯ γ² I; above 1 nothing is certified). μ of every controller is then
computed on the structure as given (mixed, repeated): the fits only steer the design, the
reported μ does not rely on them. The iteration starts from complex D–K's best controller
and keeps the best; given a target μ (robust performance: 1), it ends at the first
controller that meets it.

Measured (benchmarks/bench_dk.py, tests/robust/test_robust_dgk.py): on the mixed-μ
spring–mass case of Barros, Fekri & Athans (2005), as MathWorks' Robust Control Toolbox
example "Control of a Spring-Mass-Damper System Using Mixed-Mu Synthesis" states it,
complex D–K ends at μ 1.082 and D–G–K, with every default, at 0.925 (SLICOT AB13MD's mixed
bound agrees to 1e-5), below 1 as the example's mixed μ-synthesis; the worst-case gain over
k1 ∈ [1.2, 2.8] and the delay is 0.925 against the example's 0.88 for MATLAB's controller.
On a 92-state problem with one real parameter (±100 %) two D–G–K steps lower μ from 0.919
to 0.910 (0.920 → 0.911 after reduction) for about 6 s more CPU (benchmarks/README.md).
"""

from __future__ import annotations

import itertools
import time
from dataclasses import replace
from typing import Any, Sequence

import control as ct
import numpy as np

from ambseal.errors import ConfigError, SynthesisError
from ambseal.lti.freqresp import freqresp
from ambseal.robust._dgscale import (
    DGScalings,
    _ap_tf,
    fit_allpass_pair,
    refine_scalings,
    relax_pointwise,
    scaled_plant_dg,
)
from ambseal.robust.dk import (
    MusynResult,
    _check,
    _fit_dscale,
    default_omega,
    musyn,
    progress_printer,
)
from ambseal.robust.hinf import hinfnorm, hinfsyn, lft_lower
from ambseal.robust.mu import check_blocks, mussv
from ambseal.threads import with_numerics_threads

__all__ = ["musyn_dgk", "fit_g"]

#: back-off of D–G–K's K-steps from γ_opt. Nearer γ_opt the controller follows the
#: machine's rounding of the scalings it is built on: at 1.001 the blower example's first
#: step gave μ 0.7439 against 0.7447 under two BLAS kernel sets (Haswell, SkylakeX), and its
#: reduced controller's σ̄(S_o) peaks 2.7 % apart; at 1.003, 0.7356 against 0.7359 and
#: 1.1 %. Further away each step gives more of μ back: at 1.01 (complex D–K's back-off)
#: the spring–mass case (tests/spring_mass.py) no longer reaches μ < 1 (1.004 at best), at
#: 1.003 it ends at 0.945 (benchmarks/README.md, "D–G–K ends where the target is met")
DGK_BACKOFF = 1.003


def _split(blks):
    """Scalar structure: repeated scalars → independent scalars of the same kind (real stays
    real); full blocks kept. Returns the MATLAB-style blocks and, per block, whether real."""
    out, real = [], []
    for b in blks:
        if b.kind == "full":
            out.append((b.r, b.c))
            real.append(False)
        else:
            out.extend([(-1, 0) if b.kind == "real" else (1, 0)] * b.r)
            real.extend([b.kind == "real"] * b.r)
    return out, real


def fit_g(omega, g, weight=None, *, tol: float = 0.05):
    """The G scaling of one real scalar as two stable all-pass functions (f, h).

    With ``a1``, ``a2`` stable all-pass and ``f = (a1 + a2)/2``, ``h = (a1 − a2)/2``:
    ``|f|² + |h|² = 1`` and ``h/f = −j tan(ψ/2)``, ψ = arg a2 − arg a1, exactly on the whole
    imaginary axis. Fitting ψ(ω) ≈ 2·arctan ĝ(ω) therefore gives ``f ≈ (1 + ĝ²)^-½`` and
    ``h ≈ −jĝ f`` whose scaled problem is a valid D–G certificate for *every* fitted ψ —
    the fit error only costs optimality, never validity (Young 1996's stable fit of jG;
    the all-pass form is ours). ``a1`` and ``a2`` have the same first- and second-order
    sections count, the smallest in ``_AP_ORDERS`` whose weighted largest phase error is
    below ``2·arctan(tol)`` (weighted nonlinear least squares on log pole frequencies and
    damping, several starts).

    Parameters
    ----------
    omega : array_like, shape (F,)
        Frequencies in rad/s (> 0).
    g : array_like, shape (F,)
        Normalised real-block scaling ĝ(ω) (real).
    weight : array_like, shape (F,), optional
        Non-negative weights (uniform by default).
    tol : float
        Tolerance on tan of the half phase error.

    Returns
    -------
    f, h : control.TransferFunction
        Stable, proper; ``f`` scales the real channel's input, ``h`` is its jG term.
    error : float
        Weighted largest |ψ − 2 arctan ĝ| (rad) of the fit.

    Raises
    ------
    ConfigError
        Mismatched or non-finite inputs.
    """
    w, g = np.asarray(omega, float), np.asarray(g, float)
    if w.ndim != 1 or w.shape != g.shape or np.any(w <= 0) or not np.all(np.isfinite(g)):
        raise ConfigError("fit_g: omega and g must be 1-D, equal-length, finite, ω > 0")
    wgt = np.ones_like(w) if weight is None else np.maximum(np.asarray(weight, float), 1e-6)
    x, k1, k2, err = fit_allpass_pair(w, g, wgt, tol)
    if x is None:
        return ct.tf([1.0], [1.0]), ct.tf([0.0], [1.0]), err
    n = k1 + 2 * k2
    a1, a2 = _ap_tf(x[:n], k1, k2), _ap_tf(x[n:], k1, k2)
    return (a1 + a2) / 2, (a1 - a2) / 2, err


#: The D–G step's fits, reweighted: each round multiplies every frequency's weight by
#: ``max(σ̄(S)/median σ̄(S), 1)`` to this power, σ̄(S) being the scaled closed loop of
#: the last round's fits, so that the next fits follow the pointwise scalings most where
#: the last ones certified least.
FIT_REWEIGHT_POWER = 4
#: The reweighting ends where :data:`FIT_REWEIGHT_PATIENCE` rounds in a row lower the
#: grid's peak of σ̄(S) by less than this share of the best; the best round is kept.
FIT_REWEIGHT_RTOL = 1e-3
FIT_REWEIGHT_PATIENCE = 2
#: Reweighted fits whose peak of σ̄(S) on μ's grid is within this share of 1 are kept
#: (between the grid's points the scaled loop can peak higher: the K-step reads its H∞
#: norm); others are refined by the minimax of the peak
#: (:func:`~ambseal.robust._dgscale.refine_scalings`) from the best round's fits.
FIT_REWEIGHT_LEVEL = 1e-2


def _dg_step_scalings(P, K, nmeas, ncon, mu_s, real, beta, w, fit_tol):
    """The D–G step's rational scalings: the pointwise scalings of ``mu_s`` (the mixed bound
    of ``F_l(P, K)`` on the scalar structure at level ``beta``) relaxed
    (:func:`~ambseal.robust._dgscale.relax_pointwise`); per scalar/full block (all but the
    last) ``d`` fitted to their D (:func:`~ambseal.robust.dk.fit_dscale`) and, for real
    scalars, the all-pass pair fitted to their ĝ (as :func:`fit_g`), both in the first
    round; in each later round each fit continued from the last round's at its order, the
    fits weighted again round by round towards the frequencies where the scaled closed loop
    of ``K`` peaks (:data:`FIT_REWEIGHT_POWER`) until the grid's peak stalls
    (:data:`FIT_REWEIGHT_RTOL`, :data:`FIT_REWEIGHT_PATIENCE`). Where the best round's peak
    is within :data:`FIT_REWEIGHT_LEVEL` of 1 its fits are kept; else they are refined
    against the scaled closed loop of ``K`` (:func:`~ambseal.robust._dgscale.
    refine_scalings`). Returns the ``(d, f, h)`` per block
    (f, h None without a G scaling), the largest ψ error (rad) of the fit to the relaxed ĝ
    and the H∞ norm of the scaled closed loop of ``K``.

    The fits are least squares, which the machine's rounding moves by about its own
    size. The refinement's minimax (SLSQP) ends where the rounding takes it: on the
    overhung compressor example its iterates part threefold per step, and its scalings 3.0
    apart under two BLAS kernel sets, where the reweighted fits agree to 1e-9 in their
    peak (benchmarks/README.md, "D–G–K's refinement amplifies rounding"). On the
    spring–mass case (tests/spring_mass.py) the fits cannot follow the pointwise
    scalings' jumps (peak 1.16–1.21), and the refinement is what brings μ below 1."""
    M = freqresp(lft_lower(P, K, nmeas, ncon), w)
    ds, gs = relax_pointwise(M, mu_s.blocks, real, np.asarray(mu_s.Dl), np.asarray(mu_s.G),
                             mu_s.upper, beta, w)
    wgt, rounds, stall, g_fits, d_at = np.ones_like(w), [], 0, {}, {}
    while stall < FIT_REWEIGHT_PATIENCE:
        # a reweighted round is the last one's problem with its weights moved: its D fits
        # and all-pass pairs continue from the last round's, the multistart over orders
        # and starts runs once, at uniform weights (it was most of a D–G–K step's time;
        # benchmarks/README.md, "D–G–K's all-pass fits continued", "D–G–K's D fits
        # continued")
        d_fits, g_last, g_fits, jg_err = [], g_fits, {}, 0.0
        d_last, d_at = d_at, {}
        for j, is_real in enumerate(real[:-1]):
            fit, *_, d_at[j] = _fit_dscale(w, ds[:, j], wgt, tol=fit_tol, start=d_last.get(j))
            d_fits.append(fit)
            if is_real:
                x, k1, k2, e = fit_allpass_pair(w, gs[:, j], wgt, fit_tol,
                                                start=g_last.get(j))
                jg_err = max(jg_err, e)
                if x is not None:
                    g_fits[j] = (x, k1, k2)
        sc = DGScalings(mu_s.blocks, real, d_fits, g_fits, beta, w)
        sigma = sc.sigma(sc.x0, M, w)
        peak = float(sigma.max())
        best = min(r[0] for r in rounds) if rounds else np.inf
        stall = 0 if peak < best * (1 - FIT_REWEIGHT_RTOL) else stall + 1
        rounds.append((peak, sc, jg_err))
        wgt = wgt * np.maximum(sigma / np.median(sigma), 1.0) ** FIT_REWEIGHT_POWER
        wgt = wgt / wgt.max()
    peak, sc, jg_err = min(rounds, key=lambda r: r[0])
    if peak <= 1 + FIT_REWEIGHT_LEVEL:
        fits = sc.fits(sc.x0)
        level, _ = hinfnorm(lft_lower(scaled_plant_dg(P, mu_s.blocks, fits, beta, nmeas,
                                                      ncon), K, nmeas, ncon), rtol=1e-6)
        return fits, jg_err, float(level)
    # the minimax starts from the best round, the nearest to its end: from the first
    # round's fits (uniform weights) the overhung compressor's second D–G–K step ended at
    # 1.047 under SkylakeX kernels and 1.273 under Haswell, μ met on one only; from the
    # best round at 1.043 and 1.009, μ met on both (benchmarks/README.md, "The minimax
    # from the best reweighted round")
    fits, level = refine_scalings(sc, P, K, mu_s.blocks, nmeas, ncon, w)
    return fits, jg_err, level


def _k_step(Ps, nmeas, ncon, level):
    """H∞ controller of the D–G-scaled plant at ``DGK_BACKOFF·γ_opt``; if its verified
    norm is above ``level`` — the norm the current controller already achieves on this
    plant, so γ_opt ≤ level — SB10AD's controllers near its γ_opt were not what they were
    built for (spring–mass case, first step: γ_opt 0.956, the controllers built at
    0.93–1.00 have norms of 4.8–31), and the controller built at γ = ``level`` is kept if
    its norm is lower."""
    hr = hinfsyn(Ps, nmeas, ncon, backoff=DGK_BACKOFF)
    if np.isfinite(level) and hr.gamma > level * (1 + 1e-6):
        try:
            at = hinfsyn(Ps, nmeas, ncon, gamma=level)
        except SynthesisError:
            return hr
        if at.gamma < hr.gamma:
            return at
    return hr


@with_numerics_threads
def musyn_dgk(P, blocks: Sequence[Sequence[int]], nmeas: int, ncon: int, omega=None, *,
              order: int | str = "auto", max_iter: int | None = None, rtol: float = 1e-2,
              patience: int = 2, backoff: float = 1.01, fit_tol: float = 0.05,
              search: int | str = "auto", search_backoff: float = 1.001,
              target: float | None = None, progress: Any = False) -> MusynResult:
    """μ-synthesis by D–G–K iteration for mixed real/complex structures (Young 1996).

    Complex D–K (:func:`~ambseal.robust.dk.musyn`) first, then D–G–K steps from its best
    controller (each: the D–G scalings of the closed loop on the scalar structure, relaxed,
    fitted and refined, and an H∞ K-step on the scaled plant, module docstring) until μ
    stops improving. Each iterate is judged by the μ the result reports, its upper bound
    re-checked around the peaks (:func:`~ambseal.robust.mu.mu_peak`), not by the grid's
    peak: a K-step can put a narrow peak between the grid's points (a 168-state
    controller of a lightly damped plant with two uncertain mode frequencies: 0.580 on a
    60-point grid, 0.665 re-checked, where the iterate before it had 0.582 on both). The
    best controller over both phases is returned, so its μ is never above complex
    D–K's.

    Parameters
    ----------
    P : control.StateSpace
        Generalised plant, inputs ``[w_Δ, w, u]``, outputs ``[z_Δ, z, y]``.
    blocks : sequence of (int, int)
        MATLAB-style structure (``(-k, 0)`` real, ``(k, 0)`` complex repeated scalars, full
        blocks); the last block is the full complex performance block.
    nmeas, ncon : int
        Number of measurements and control inputs.
    omega : array_like, optional
        Frequency grid in rad/s (default: :func:`~ambseal.robust.dk.default_omega`).
    order : int or "auto"
        D-scale fit order (0–4) of the D–K phase, as in :func:`~ambseal.robust.dk.musyn`;
        the D–G–K phase selects its orders automatically.
    max_iter : int, optional
        A cap on the number of iterations of each phase, for a caller who wants one. None
        (default): each phase ends by its stall rule (``rtol``, ``patience``), or the
        target; the stall rule always ends it, μ being bounded below (the published
        spring–mass case, no target: eight D–G–K steps, the best μ 0.925).
    rtol : float
        Relative improvement of peak μ below which an iteration counts as no progress.
    patience : int
        Stop a phase after this many iterations without progress.
    backoff : float
        K-steps of the D–K phase: the controller is built at ``backoff·γ_opt`` (those of the
        D–G–K phase at ``DGK_BACKOFF·γ_opt``).
    fit_tol : float
        Relative magnitude tolerance of the automatic scaling fit orders.
    search, search_backoff : int or "auto", float
        The D search of the D–K phase, as in :func:`~ambseal.robust.dk.musyn`.
    target : float, optional
        A μ level the design asks for (1: robust performance): when complex D–K's μ is at
        or below it, its result is returned without D–G–K steps, which would only lower a
        bound already met; otherwise the D–G–K phase ends at the first step whose μ is at
        or below it. None: D–G–K until its stall rule. The steps after
        the target is met follow the machine's rounding: no K-step of the D–G-scaled plant
        reaches the norm 1 that certifies its level (the fitted ĝ puts the norm's floor
        within 0.1 % of 1), each lands where its H∞ synthesis near γ_opt and its scalings'
        local refinement put it, and a 1e-3 difference at the first step had become 6 %
        of μ six steps later (the blower example: 0.587 against 0.621 under two BLAS
        kernel sets; benchmarks/README.md, "D–G–K ends where the target is met").
    progress : bool or callable
        As in :func:`~ambseal.robust.dk.musyn`.

    Returns
    -------
    MusynResult
        The controller with the lowest mixed μ upper bound (on ``blocks`` as given),
        re-checked around the peaks as in :func:`~ambseal.robust.dk.musyn` (``mu``,
        ``check_omega``; ``mu_grid`` on ``omega`` alone). ``history`` has one entry per
        K-step with ``step`` ``"D-K"``, ``"D search"`` or ``"D-G-K"`` (the latter also
        ``beta``, the level of its scalings, ``jg_fit_error``, the ψ error of the G fit,
        ``fit_level``, the H∞ norm of the previous controller's loop on the scaled plant:
        1 when the fits certify it at β, and ``mu_grid``, its μ peak on ``omega`` alone,
        its ``mu`` being re-checked around the peaks as the result's); ``scalings`` holds
        the fits of the best iteration
        (D–G–K: ``(d, f, h)`` per block); ``alternatives`` the best complex D–K controller
        when D–G–K's is better at full order. Without real blocks, complex D–K's result.

    Raises
    ------
    ModelError, ConfigError
        Blocks that do not match P's channels or no performance block (ModelError); bad grid
        or order (ConfigError).
    SynthesisError
        If the first K-step (plain H∞) fails.
    """
    t0 = time.process_time()
    w = default_omega(P) if omega is None else np.asarray(omega, float)
    dk = musyn(P, blocks, nmeas, ncon, w, order=order, max_iter=max_iter, rtol=rtol,
               patience=patience, backoff=backoff, fit_tol=fit_tol, search=search,
               search_backoff=search_backoff, progress=progress)
    blks = check_blocks(P, blocks, nmeas, ncon)
    if not any(b.kind == "real" for b in blks):
        return dk
    history = [dict(h, step=h.get("step", "D-K")) for h in dk.history]
    if target is not None and dk.mu <= target:
        stopping = dict(dk.stopping, dgk={"iterations": 0, "rule": f"complex D-K's μ "
                                          f"{dk.mu:.4g} ≤ target={target:g}"})
        return replace(dk, history=tuple(history), stopping=stopping)
    sblocks, real = _split(blks)
    console = progress_printer(progress)
    # iterates compared by the μ reported, re-checked around their peaks: a K-step can
    # put a narrow peak between the grid's points
    best = (dk.mu, dk.best_iteration, dk.K, dk.gamma, np.asarray(dk.mu_curve), dk.scalings)
    K, stall, rule = dk.K, 0, f"max_iter={max_iter}"
    first = len(history)
    for it in (itertools.count(first) if max_iter is None else range(first, first + max_iter)):
        mu_s = mussv(lft_lower(P, K, nmeas, ncon), sblocks, w, lower=False, peak=False)
        beta = float(np.max(mu_s.upper))
        if console is not None:
            console.print(f"D-G-K {it}: fitting the D and G scalings at β = {beta:.4g}")
        fits, jg_err, level = _dg_step_scalings(P, K, nmeas, ncon, mu_s, real, beta, w,
                                                fit_tol)
        try:
            hr = _k_step(scaled_plant_dg(P, sblocks, fits, beta, nmeas, ncon), nmeas, ncon,
                         level)
        except SynthesisError as exc:
            rule = f"K-step {it} failed ({exc})"
            break
        mu_true = mussv(lft_lower(P, hr.K, nmeas, ncon), blocks, w, lower=False,
                        peak=False)
        peak = _check(P, hr.K, blocks, nmeas, ncon, w, mu_true.upper).peak
        history.append({"iteration": it, "gamma": hr.gamma, "mu": peak, "order": hr.order,
                        "step": "D-G-K", "beta": beta, "jg_fit_error": jg_err,
                        "fit_level": level, "mu_grid": float(np.max(mu_true.upper))})
        if console is not None:
            console.print(f"D-G-K {it}: γ = {hr.gamma:.4g} at β = {beta:.4g}, μ = {peak:.4g}, "
                          f"order {hr.order}")
        stall = 0 if peak < best[0] * (1 - rtol) else stall + 1
        if peak < best[0]:
            best = (peak, it, hr.K, hr.gamma, np.asarray(mu_true.upper), tuple(fits))
        if target is not None and best[0] <= target:
            rule = f"μ {best[0]:.4g} ≤ target={target:g}"
            break
        if stall >= patience:
            rule = f"patience={patience}: {stall} iterations without a μ gain of rtol={rtol:g}"
            break
        K = hr.K
    stopping = dict(dk.stopping, dgk={"iterations": len(history) - first, "rule": rule})
    if best[2] is dk.K:
        return replace(dk, history=tuple(history), stopping=stopping,
                       elapsed_s=time.process_time() - t0)
    _, it_best, K, gamma, curve, fits_best = best
    pk = _check(P, K, blocks, nmeas, ncon, w, curve)
    if pk.peak >= dk.mu:  # complex D–K's controller is better once both are re-checked
        return replace(dk, history=tuple(history), stopping=stopping,
                       elapsed_s=time.process_time() - t0)
    alt = ({"step": "D-K", "K": dk.K, "mu": dk.mu, "gamma": dk.gamma},)
    return MusynResult(K=K, mu=pk.peak, mu_omega=pk.omega_peak, mu_curve=curve, omega=w,
                       gamma=gamma, history=tuple(history), best_iteration=it_best,
                       scalings=fits_best, alternatives=alt, mu_grid=pk.grid_peak,
                       check_omega=pk.omega, check_mu=pk.upper, check=pk.describe(),
                       elapsed_s=time.process_time() - t0, stopping=stopping,
                       closed_loop=lft_lower(P, K, nmeas, ncon))
