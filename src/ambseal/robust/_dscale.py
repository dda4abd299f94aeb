"""The fitted D scales of D–K as parameters: realisation, scaled plant, direct search.

Private module behind :func:`ambseal.robust.dk.musyn`. A fitted D scale is
``k·Π N_i(s)/Π D_i(s)`` with first- and second-order sections whose coefficients are kept
positive (exp-parametrised), so every pole and zero lies in the open left half plane
(:func:`_logmag`, :func:`_theta_to_tf`; fitted by :func:`ambseal.robust.dk.fit_dscale`).
Here: the state spaces of D and D⁻¹ (:func:`_realize`), the scaled plant
``diag(D, I) P diag(D⁻¹, I)`` of a K-step (:func:`_scaled_plant`), the parameters read back
from a transfer function (:func:`_tf_to_theta`), and the direct search over those
parameters for the smallest γ_opt of the scaled plant (:func:`_search_dscales`,
:func:`_search_step`): D–K stalls where each D-step's pointwise-optimal D of the current K
is not the best D for the next K-step.

References: Balas, Doyle, Glover, Packard & Smith, μ-Analysis and Synthesis Toolbox (1993);
Lagarias, Reeds, Wright & Wright, SIAM J. Optim. 9 (1998) 112–147 (Nelder–Mead); Kelley,
Iterative Methods for Optimization (1999) §8.1 (restarts).
"""

from __future__ import annotations

import control as ct
import numpy as np
from scipy.optimize import minimize
from scipy.signal import tf2ss

from ambseal.errors import ModelError, SynthesisError
from ambseal.robust.hinf import hinf_gamma_opt, hinfsyn, lft_lower
from ambseal.robust.mu import mussv

#: Relative tolerance of each γ_opt a Nelder–Mead search over D scales evaluates
#: (:func:`_balance_channels`, :func:`_search_dscales`). The γ search returns the top of a
#: bracket of this relative width, so the value jumps by up to the tolerance where rounding
#: moves one of its steps across it: at 1e-4 such jumps exceed the differences the simplex
#: ranks its vertices by (``fatol`` 1e-5), and the search's path — its D and the μ reached
#: — depended on the BLAS kernels (distillation column: μ 0.9810 with OpenBLAS's SkylakeX
#: kernels, 0.9839 with Haswell's). At 1e-8 the γ values of different kernels agree to
#: rounding (1e-8), the same path is taken and the same μ reached (to 1e-6), at about 10 %
#: more time (Brent's method converges superlinearly: one or two more margins per γ).
SEARCH_GAMMA_RTOL = 1e-8

#: Stall test of the D scales' weighted least-squares fits (:func:`ambseal.robust.dk.
#: fit_dscale`, :func:`ambseal.robust._dgscale.fit_allpass_pair`), which run until SciPy's
#: tolerances end them (:func:`ambseal.lti.least_squares.least_squares_converged`) or a
#: round of SciPy's default count (100 evaluations per parameter) lowers the fit's largest
#: weighted error by less than this fraction of it. The largest error is what the order
#: choice reads, and it prefers a higher order only for a 10 % lower error: a round that
#: moves it by a tenth of that step cannot change the choice by itself. Where a tolerance
#: ends the fit within its first round the test is never reached.
FIT_STALL_RTOL = 0.01


#: Log-frequency spacing (0.1 %) at which two interchangeable sections of one fitted
#: function count as equal: :func:`untied` spreads them to it.
SECTION_TIE = 1e-3


def untied(x, groups):
    """The fit's coordinates x with its equal sections spread apart: ``groups`` lists, per
    rational function, its interchangeable sections as index lists into x (the corner's
    log-frequency first); two sections of a group within :data:`SECTION_TIE` in every
    coordinate get corners :data:`SECTION_TIE` apart about their mean, the first below.

    Equal sections are a point of symmetry of a fit (swapping them changes nothing), where
    its gradient cannot part them: a fit continued from there (D–G–K's reweighting rounds,
    :func:`ambseal.robust.dgk._dg_step_scalings`) leaves it, or not, by the machine's
    rounding, and then ends in another basin (measured on the overhung compressor
    example's first D–G–K step: two equal all-pass corners, scalings 2.0 apart under a
    1e-13 perturbation; benchmarks/README.md, "D–G–K's D fits continued"). Spread, the
    fit leaves it the same way on every machine."""
    x = np.array(x, float)
    for group in groups:
        for i, a in enumerate(group):
            for b in group[i + 1:]:
                if np.all(np.abs(x[a] - x[b]) < SECTION_TIE):
                    mid = 0.5 * (x[a[0]] + x[b[0]])
                    x[a[0]], x[b[0]] = mid - 0.5 * SECTION_TIE, mid + 0.5 * SECTION_TIE
    return x


def _logmag(theta, w, order):
    """log|W(jω)| for W = k Π(num sections)/Π(den sections), all roots in the LHP."""
    lk, rest = theta[0], theta[1:]
    n2, n1 = divmod(order, 2)
    out = np.full_like(w, lk)
    i = 0
    for sign in (1.0, -1.0):
        for _ in range(n2):
            b0, b1 = np.exp(rest[i]), np.exp(rest[i + 1])
            out += sign * 0.5 * np.log((b0 - w**2) ** 2 + (b1 * w) ** 2)
            i += 2
        for _ in range(n1):
            a = np.exp(rest[i])
            out += sign * 0.5 * np.log(w**2 + a**2)
            i += 1
    return out


def _d_sections(order):
    """Indices in θ (:func:`~ambseal.robust._dscale._logmag`) of the second-order
    sections' log ω_n², of their log 2ζω_n (index + 1), and of the first-order log a."""
    n2, n1 = divmod(order, 2)
    sec = np.array([1 + 2 * i + off * (2 * n2 + n1) for off in (0, 1) for i in range(n2)], int)
    first = np.array([1 + 2 * n2 + i + off * (2 * n2 + n1) for off in (0, 1)
                      for i in range(n1)], int)
    return sec, first


def _d_theta(x, order):
    """θ of :func:`~ambseal.robust._dscale._logmag` from x, where x holds log 2ζ in place
    of log 2ζω_n (so that the damping can be bounded)."""
    th = np.array(x, float)
    sec, _ = _d_sections(order)
    th[sec + 1] = x[sec + 1] + 0.5 * x[sec]
    return th


def _logmag_jac(theta, w, order):
    """:func:`_logmag` and its gradient in θ, shapes (F,) and (F, 1 + 2·order)."""
    th = np.asarray(theta, float)
    sec, first = _d_sections(order)
    half = sec.size // 2, first.size // 2
    w2 = w ** 2
    val = np.full(w.size, th[0])
    J = np.zeros((w.size, th.size))
    J[:, 0] = 1.0
    for k, i in enumerate(sec):
        sign = 1.0 if k < half[0] else -1.0
        b0, b1 = np.exp(th[i]), np.exp(th[i + 1])
        q = (b0 - w2) ** 2 + (b1 * w) ** 2
        val += sign * 0.5 * np.log(q)
        J[:, i] = sign * b0 * (b0 - w2) / q
        J[:, i + 1] = sign * (b1 * w) ** 2 / q
    for k, i in enumerate(first):
        sign = 1.0 if k < half[1] else -1.0
        a2 = np.exp(2 * th[i])
        val += sign * 0.5 * np.log(w2 + a2)
        J[:, i] = sign * a2 / (w2 + a2)
    return val, J


def _d_logmag_jac(x, w, order):
    """log|d(jω)| and its gradient in x (:func:`_d_theta`), shapes (F,) and (F, 1 + 2·order)."""
    val, J = _logmag_jac(_d_theta(x, order), w, order)
    sec, _ = _d_sections(order)
    J[:, sec] += 0.5 * J[:, sec + 1]  # chain rule of θ[i + 1] = x[i + 1] + x[i]/2
    return val, J


def _theta_to_tf(theta, order):
    k = np.exp(theta[0])
    n2, n1 = divmod(order, 2)
    polys, i = [], 0
    for _ in range(2):
        p = np.array([1.0])
        for _ in range(n2):
            p = np.polymul(p, [1.0, np.exp(theta[1 + i + 1]), np.exp(theta[1 + i])])
            i += 2
        for _ in range(n1):
            p = np.polymul(p, [1.0, np.exp(theta[1 + i])])
            i += 1
        polys.append(p)
    return k * polys[0], polys[1]


def _ss(tf):
    s = ct.ss(tf)
    return np.asarray(s.A, float), np.asarray(s.B, float), np.asarray(s.C, float), np.asarray(s.D, float)


def _diag_sys(parts):
    """Block-diagonal state space of SISO (A, B, C, D) tuples."""
    n = sum(p[0].shape[0] for p in parts)
    k = len(parts)
    A = np.zeros((n, n)); B = np.zeros((n, k)); C = np.zeros((k, n)); D = np.zeros((k, k))
    o = 0
    for i, (a, b, c, d) in enumerate(parts):
        m = a.shape[0]
        A[o:o + m, o:o + m] = a; B[o:o + m, i:i + 1] = b; C[i:i + 1, o:o + m] = c
        D[i, i] = d[0, 0]
        o += m
    return ct.ss(A, B, C, D)


def _realize(theta, order):
    """State spaces (A, B, C, D) of the D scale of section parameters ``theta``
    (:func:`_theta_to_tf`) and of its inverse, by numpy alone (for the D search)."""
    if order == 0:
        a, b, c, d = np.zeros((0, 0)), np.zeros((0, 1)), np.zeros((1, 0)), \
            np.exp(theta[:1]).reshape(1, 1)
    else:
        a, b, c, d = tf2ss(*_theta_to_tf(theta, order))
    di = 1.0 / d
    return (a, b, c, d), (a - b @ di @ c, b @ di, -di @ c, di)


def _scaled_plant(P, cblocks, fits, nmeas, ncon):
    """diag(D_l(s), I) · P · diag(D_r(s)⁻¹, I) for fitted scalars (last block: 1); each fit
    a transfer function or its :func:`_realize` pair."""
    left, right = [], []
    one = (np.zeros((0, 0)), np.zeros((0, 1)), np.zeros((1, 0)), np.ones((1, 1)))
    for (r, c), f in zip(cblocks, list(fits) + [None]):
        if f is None:
            lf = rf = one
        elif isinstance(f, tuple):
            lf, rf = f
        else:
            lf = _ss(f)
            rf = _ss(1 / f)
        left.extend([lf] * c)
        right.extend([rf] * r)
    left.extend([one] * nmeas)
    right.extend([one] * ncon)
    Pb = ct.ss(P.A, P.B, P.C, P.D)
    Ps = _diag_sys(left) * Pb * _diag_sys(right)
    names_in, names_out = list(P.input_labels), list(P.output_labels)
    return ct.ss(Ps.A, Ps.B, Ps.C, Ps.D, inputs=names_in, outputs=names_out, name="P_scaled")


def _balance_channels(P, cblocks, nmeas, ncon, w, evals=0):
    """The uncertainty channels of ``P`` in balanced units: ``(P_b, b, evaluations, rule)``
    with ``P_b = diag(b, I) · P · diag(b⁻¹, I)``, one constant ``b_j > 0`` per block of the
    complexified structure but the last (performance) block.

    μ is unchanged by such a D (Packard & Doyle 1993: μ(DMD⁻¹) = μ(M) for D commuting
    with Δ), but D–K is not: its first K-step is H∞ at D = I, and a start in other units
    ends elsewhere. Two steps, each the same in any units of the channels:

    1. ``b_j² = c_j / r_j``, with ``r_j`` the RMS over ``w`` of the Frobenius norm of
       block j's z_Δ rows of P(jω) into the non-Δ inputs ``[w, u]`` and ``c_j`` the same of
       its w_Δ columns seen at the non-Δ outputs ``[z, y]`` (a block with no such path
       keeps 1): channels in other units (z_Δ·a, w_Δ/a) scale r_j by a and c_j by 1/a.
    2. From there, Nelder–Mead over log b for the smallest γ_opt of ``P_b`` (the best
       constant D of the H∞ problem), until its simplex has converged (1 % in log b) or
       by the D search's stall rule (:class:`_StallWatch`: the best γ fell by less than
       0.1 % over the last 30 evaluations per parameter) or, where ``evals`` is a number,
       at most that many γ evaluations (0: none): translation in log b, the change of
       units, leaves the search unchanged. ``rule`` names what ended it. Channels that
       are mirror images (:func:`_mirror_groups`: the same RMS norms, as in a plant that
       an exchange of two sets of its inputs and outputs leaves as it is) share one
       parameter: the search runs in fewer dimensions, where Nelder–Mead's evaluations
       grow faster than the dimension (Gao & Han 2012, Comput. Optim. Appl. 51,
       259–277). On two measured plants of 8 and 10 such channels it ended lower in a
       third of the evaluations (benchmarks/README.md, "The best constant D over
       mirror-image channels").
    """
    nzd = sum(c for _, c in cblocks[:-1])
    nwd = sum(r for r, _ in cblocks[:-1])
    H = np.moveaxis(ct.frequency_response(ct.ss(P.A, P.B, P.C, P.D), w,
                                          squeeze=False).complex, 2, 0)
    H = H[np.all(np.isfinite(H), axis=(1, 2))]

    def rms(block):
        return float(np.sqrt(np.mean(np.sum(np.abs(block) ** 2, axis=(1, 2))))) \
            if block.size else 0.0

    zs, ws, logb, norms = [], [], [], []
    zo = wo = 0
    for r, c in cblocks[:-1]:
        rj, cj = rms(H[:, zo:zo + c, nwd:]), rms(H[:, nzd:, wo:wo + r])
        ok = rj > 0 and cj > 0 and np.isfinite(cj / rj)
        logb.append(0.5 * np.log(cj / rj) if ok else 0.0)
        norms.append(_signature(H, zo, wo, r, c, nzd, nwd) if ok else None)
        zs.append(slice(zo, zo + c))
        ws.append(slice(wo, wo + r))
        zo, wo = zo + c, wo + r
    tie = _mirror_groups(norms)  # (scales,): the search's parameter of each scale

    def scaled(x):
        left, right = np.ones(P.noutputs), np.ones(P.ninputs)
        for z, v, xj in zip(zs, ws, x):
            left[z], right[v] = np.exp(xj), np.exp(-xj)
        return ct.ss(P.A, P.B * right, left[:, None] * P.C, left[:, None] * P.D * right,
                     inputs=list(P.input_labels), outputs=list(P.output_labels),
                     name=P.name)

    x = np.array(logb, float)
    y0 = np.array([x[list(tie).index(k)] for k in range(int(tie.max()) + 1)]) \
        if x.size else x
    near = [None]
    watch = _StallWatch(y0.size)
    rule = "RMS balance"

    def gamma(y):
        try:
            g = hinf_gamma_opt(scaled(y[tie]), nmeas, ncon, rtol=SEARCH_GAMMA_RTOL,
                               near=near[0])
        except (SynthesisError, ModelError, ValueError, np.linalg.LinAlgError):
            g = np.inf
        else:
            near[0] = g if near[0] is None else min(near[0], g)
        watch.record(y, g)
        return g

    if x.size and (evals is None or evals > y0.size + 1):
        # first simplex: each log b moved by 1 (a factor e): the RMS balance is a start,
        # not the optimum, which lies a decade or two away on plants with integrators.
        # It ends where the simplex has converged (1 % in log b, 1e-4 in γ), by the
        # stall rule, or at a caller's count; SciPy's default bound (200 evaluations per
        # scale) does not end it
        g0 = gamma(y0)
        options = {"xatol": 1e-2, "fatol": 1e-4, "maxfev": np.inf, "maxiter": np.inf,
                   "initial_simplex": np.vstack([y0, y0 + np.eye(y0.size)])}
        if evals is not None:
            options["maxfev"] = int(evals) - 1
        try:
            minimize(gamma, y0, method="Nelder-Mead", options=options)
            rule = ("RMS balance, then the best constant D: its simplex converged"
                    if evals is None else
                    f"RMS balance, then the best constant D in at most {evals} γ evaluations")
        except _Stalled:
            rule = f"RMS balance, then the best constant D: {watch.rule()}"
        if y0.size < x.size:
            rule += (f" (over {y0.size} parameter{'s' * (y0.size > 1)}: the scales of "
                     f"mirror-image channels kept equal)")
        if watch.best_g < g0:
            x = watch.best_x[tie]
    return scaled(x), [float(np.exp(v)) for v in x], len(watch.trail), rule


#: Two uncertainty channels of one shape whose signatures (:func:`_signature`) agree to
#: this share of their largest entry are taken for mirror images (a plant that their
#: exchange, with the other channels', leaves as it is) and keep one scale in the search
#: for the best constant D.
MIRROR_RTOL = 1e-6


def _signature(H, zo, wo, r, c, nzd, nwd):
    """A channel's signature, the same for mirror images: its shape, and the RMS over the
    grid of each entry of its rows of ``H`` (F, outputs, inputs) into the non-Δ inputs and
    of its columns seen at the non-Δ outputs, each set sorted (an exchange of channels
    permutes them)."""
    def entries(block):
        return np.sort(np.sqrt(np.mean(np.abs(block) ** 2, axis=0)).ravel())

    return (r, c), np.concatenate([entries(H[:, zo:zo + c, nwd:]),
                                   entries(H[:, nzd:, wo:wo + r])])


def _mirror_groups(norms) -> np.ndarray:
    """The search parameter of each scale (ints, first appearance order): scales whose
    channels' signatures (:func:`_signature`) have the same shape and entries within
    :data:`MIRROR_RTOL` of their largest share one (a channel without norms, None, keeps
    its own). Equal row and column norms alone do not make mirror images: with
    G = [[100, 60], [0, 80]] under input uncertainty both channels have them, but the
    entries of their columns (100 and 0, 60 and 80) tell them apart."""
    out, reps = [], []
    for nj in norms:
        k = next((i for i, rep in enumerate(reps) if nj is not None and rep is not None
                  and nj[0] == rep[0] and np.max(np.abs(nj[1] - rep[1]), initial=0.0)
                  <= MIRROR_RTOL * np.max(np.abs(rep[1]), initial=0.0)), None)
        if k is None:
            k = len(reps)
            reps.append(nj)
        out.append(k)
    return np.array(out, int)


def _unbalanced_fit(fit, b):
    """A D scale fitted on :func:`_balance_channels`' plant, in ``P``'s units: ``b·D``
    (a transfer function, or the ``(D, D⁻¹)`` realisation pair of :func:`_realize`)."""
    if not isinstance(fit, tuple):
        return fit * b
    (a, bb, c, d), (ai, bi, ci, di) = fit
    return (a, bb, c * b, d * b), (ai, bi, ci / b, di / b)


def _tf_to_theta(tf):
    """Section parameters (:func:`_logmag`) of a fitted D scale and its order: the inverse
    of :func:`_theta_to_tf` (complex root pairs first, then real roots paired by size)."""
    num, den = (np.asarray(p, float) for p in (tf.num[0][0], tf.den[0][0]))
    order = den.size - 1
    th = [np.log(abs(num[0] / den[0]))]
    for poly in (num, den):
        r = np.roots(poly)
        secs = [np.real(np.poly([x, np.conj(x)])) for x in r if x.imag > 1e-12 * abs(x)]
        real = sorted((x.real for x in r if abs(x.imag) <= 1e-12 * abs(x)), key=abs)
        while len(secs) < order // 2:
            secs.append(np.poly([real.pop(0), real.pop(0)]))
        th += [v for sec in secs for v in (np.log(sec[2]), np.log(sec[1]))]
        th += [np.log(-a) for a in real]
    return np.array(th), order


#: D search's work estimate, in Nelder–Mead evaluations per parameter of the fitted D
#: scales, by which ``search="auto"`` decides whether to start it (``SEARCH_WORK``). On
#: Skogestad & Postlethwaite's distillation problem (18 parameters, D–K started from the
#: balanced channels; ``musyn(search=N)``) 450 γ evaluations reached μ 1.002, 700 0.986,
#: 900 0.970 and 1200 0.962, below the published optimum 0.9737.
SEARCH_EVALS_PER_PARAMETER = 50
#: D search's stall rule: it ends when its best γ_opt fell by less than
#: ``SEARCH_STALL_RTOL`` over the last ``SEARCH_STALL_EVALS_PER_PARAMETER`` evaluations per
#: parameter — D–K's own rule (``rtol`` within ``patience`` steps) with a simplex's
#: evaluations as the steps. Measured on the best γ of three published problems searched
#: to 5 000 evaluations (benchmarks/README.md, "The D search ends by its stall rule"): the
#: aircraft's first simplex descent runs about 15 per parameter without a gain, so a window
#: of 10 or 20 ends it there (γ 0.981, against 0.9754 at 5 000); 0.1 % over 30 ends it at
#: 0.9756, and the distillation column's search near 2 000 evaluations at γ 0.9587, 0.06 %
#: above where 5 000 reach.
SEARCH_STALL_RTOL = 1e-3
SEARCH_STALL_EVALS_PER_PARAMETER = 30
#: D search: the first simplex moves each parameter (a logarithm) by this much, a factor e,
#: as the best-constant-D start moves its log D (:func:`_balance_channels`): a D–K stall
#: leaves the best D's sections a fair way from the fitted ones, and a small simplex spends
#: the evaluations crawling towards them. On the distillation problem, 900 evaluations
#: from a first simplex of 0.3 reached μ 0.985, of 0.6 0.986, of 0.8 … 1.2 0.979 … 0.962,
#: of 1.5 0.999 and of 2 0.984.
SEARCH_SIMPLEX_STEP = 1.0
#: The work ``search="auto"`` may expect to spend, counted in γ evaluations × n³, n the
#: states of the scaled plant: a γ evaluation (Riccati equations and Hamiltonian
#: eigenvalues of the scaled plant) costs ∝ n³. The search starts when its estimate,
#: ``SEARCH_EVALS_PER_PARAMETER`` evaluations per parameter, is within it: a decision by
#: the problem's size, not a clock, so the same problem gets the same search on every
#: machine, quiet or loaded. The distillation column's estimate is 900 × 22³ ≈ 9.6·10⁶;
#: on a 92-state scaled plant (10 parameters) it would be 500 × 92³ ≈ 3.9·10⁸, at a
#: K-step of 0.4 s minutes for a μ 0.1 % lower (benchmarks/README.md, bench_dk): the
#: limit lies between.
SEARCH_WORK = 1e8


class _Stalled(Exception):
    """Raised inside a Nelder–Mead objective to end the search by its stall rule."""


class _StallWatch:
    """The best γ after each evaluation of a search over ``n_parameters`` parameters, and
    its stall rule: :meth:`record` raises :class:`_Stalled` once the best γ fell by less
    than ``SEARCH_STALL_RTOL`` over the last ``SEARCH_STALL_EVALS_PER_PARAMETER``
    evaluations per parameter. The rule ends every search: γ is bounded below (by 0), so
    the best γ can fall by that fraction only finitely often, and an infinite γ (no
    controller) never counts as a fall."""

    def __init__(self, n_parameters: int):
        self.window = SEARCH_STALL_EVALS_PER_PARAMETER * int(n_parameters)
        self.trail: list[float] = []
        self.best_x, self.best_g = None, np.inf

    def record(self, x, g: float) -> None:
        if g < self.best_g:
            self.best_x, self.best_g = np.array(x, float), float(g)
        self.trail.append(self.best_g)
        t = self.trail
        if len(t) > self.window and not t[-1] < t[-1 - self.window] * (1 - SEARCH_STALL_RTOL):
            raise _Stalled

    def rule(self) -> str:
        return (f"stalled: the best γ fell by less than {SEARCH_STALL_RTOL:g} over the last "
                f"{self.window} evaluations")


def _search_dscales(P, cblocks, fits, nmeas, ncon, evals=None):
    """Direct search (Nelder–Mead) over the section parameters of the fitted D scales for
    the smallest γ_opt of ``D P D⁻¹`` (γ to ``SEARCH_GAMMA_RTOL``).

    D–K stalls above the μ-optimum because each D-step fits the pointwise-optimal D of the
    *current* K; this searches the same rational D's for the best K-step directly. Every
    parameter vector is a stable, minimum-phase D (:func:`_logmag`), and γ_opt of the scaled
    problem bounds μ of its optimal controller at every frequency. The search ends by its
    stall rule (``SEARCH_STALL_RTOL`` over ``SEARCH_STALL_EVALS_PER_PARAMETER`` evaluations
    per parameter), or when a restart lowers γ by less than 1e-4: when Nelder–Mead
    converges it restarts from its best point with a fresh simplex, since a converged
    simplex in a dozen dimensions has often collapsed onto a subspace (Lagarias et al.
    1998; the restart is the classical remedy, Kelley 1999). Both rules end it: γ_opt is
    bounded below. A Nelder–Mead run that reaches SciPy's own bound (its default of 200
    evaluations per parameter) is restarted like a converged one, so that bound ends no
    search. ``evals``: None (no cap), or at most that many γ evaluations, a caller's
    cap. Returns ``(fits, γ_opt, evaluations, rule)``, with ``fits`` None when no
    better D was found and ``rule`` the one that ended the search.
    """
    parts = [_tf_to_theta(f) for f in fits]
    cuts = np.cumsum([0] + [th.size for th, _ in parts])

    def sections(x):
        return [(x[a:b], od) for (_, od), a, b in zip(parts, cuts[:-1], cuts[1:])]

    watch = _StallWatch(cuts[-1])

    def gamma(x):
        try:
            Ps = _scaled_plant(P, cblocks, [_realize(*t) for t in sections(x)], nmeas, ncon)
            g = hinf_gamma_opt(Ps, nmeas, ncon, rtol=SEARCH_GAMMA_RTOL, near=near[0])
        except (SynthesisError, ModelError, ValueError, np.linalg.LinAlgError):
            g = np.inf
        else:
            near[0] = g if near[0] is None else min(near[0], g)
        watch.record(x, g)
        return g

    x0 = np.concatenate([th for th, _ in parts])
    near = [None]
    g0 = gamma(x0)
    x = x0
    while True:
        options = {"adaptive": True, "xatol": 1e-3, "fatol": 1e-5,
                   "initial_simplex": np.vstack([x, x + SEARCH_SIMPLEX_STEP * np.eye(x.size)])}
        if evals is not None:
            left = int(evals) - len(watch.trail)
            if left <= x.size + 1:
                rule = f"the cap of {int(evals)} evaluations reached"
                break
            options["maxfev"] = left
        g_start = watch.best_g
        try:
            minimize(gamma, x, method="Nelder-Mead", options=options)
        except _Stalled:
            rule = watch.rule()
            break
        if not watch.best_g < g_start * (1 - 1e-4):
            rule = "converged: a restart lowered γ by less than 1e-4"
            break
        x = watch.best_x
    n = len(watch.trail)
    if not watch.best_g < g0:
        return None, g0, n, rule
    return [ct.tf(*_theta_to_tf(*t)) for t in sections(watch.best_x)], float(watch.best_g), \
        n, rule


def _search_evals(search, fits, n_states: int) -> tuple[int | None, str]:
    """The γ evaluations granted to the D search on a scaled plant of ``n_states``
    states — 0: no search, None: no cap, it ends by its own rules — and the rule that
    granted them; see :func:`musyn`."""
    if not fits:
        return 0, "no D scales fitted"
    if search == 0:
        return 0, "search=0"
    n = sum(_tf_to_theta(f)[0].size for f in fits)
    if search != "auto":
        return int(search), f"search={int(search)}"
    estimate = SEARCH_EVALS_PER_PARAMETER * n
    work = estimate * float(n_states) ** 3
    if work <= SEARCH_WORK:
        return None, f"auto: {n} parameters, no cap"
    return 0, (f"auto: not started, an estimated {estimate} evaluations on a {n_states}-state "
               f"plant exceed the work limit ({work:.2g} > {SEARCH_WORK:.0e} evaluations × "
               f"states³)")


#: The best-constant-D start's work estimate, in Nelder–Mead evaluations per scale (a
#: search in one to a few dimensions from the RMS balance, converged to 1 % in log D
#: within about 20), by which ``search="auto"`` decides whether to start it.
START_EVALS_PER_SCALE = 20
#: The work the best-constant-D start may expect to spend (γ evaluations × n³). It pays
#: where the RMS balance is far off, on small plants with near-integrating weights
#: (Skogestad & Postlethwaite's column: D–K ends at μ 1.11 from the RMS balance, 0.98
#: from the best constant D); on the back-to-back compressor's 94-state plant its 80
#: evaluations took 9.4 s for a first synthesis at μ 0.4850 instead of 0.4872 and the same
#: delivered design.
START_WORK = 1e7


def _start_evals(search, cblocks, n_states: int) -> int | None:
    """γ evaluations granted to :func:`_balance_channels`' search for the best constant D:
    0 (none) when ``search`` is 0 or its estimate (``START_EVALS_PER_SCALE`` per scale) ×
    ``n_states``³ exceeds ``START_WORK``; else None with ``"auto"`` (no cap: it ends
    where its simplex has converged or by its stall rule), and a number ``search`` caps
    it."""
    estimate = START_EVALS_PER_SCALE * (len(cblocks) - 1)
    if search == 0 or estimate * float(n_states) ** 3 > START_WORK:
        return 0
    return None if search == "auto" else int(search)


def _search_step(P, blocks, cblocks, nmeas, ncon, w, best, evals, backoff, history,
                 console):
    """:func:`_search_dscales` from the best D–K iteration's fits. Returns the finalist
    ``(μ on the grid, index, HinfResult, MuResult, fits)`` of its controller, recorded in
    ``history`` (None when the search found no D with a lower γ_opt), and
    ``{"evaluations", "rule"}``: the γ evaluations made and the rule that ended it."""
    fits, _, n, rule = _search_dscales(P, cblocks, best[4], nmeas, ncon, evals)
    done = {"evaluations": int(n), "rule": rule}
    if fits is None:
        return None, dict(done, rule=f"{rule}; no D with a lower γ_opt found")
    try:
        hr = hinfsyn(_scaled_plant(P, cblocks, fits, nmeas, ncon), nmeas, ncon,
                     backoff=backoff)
    except SynthesisError:
        return None, dict(done, rule=f"{rule}; its K-step failed")
    mu = mussv(lft_lower(P, hr.K, nmeas, ncon), blocks, w, lower=False, peak=False)
    peak = float(np.max(mu.upper))
    history.append({"iteration": len(history), "gamma": hr.gamma, "mu": peak,
                    "order": hr.order, "step": "D search", "evaluations": n})
    if console is not None:
        console.print(f"D search ({n} γ evaluations): γ = {hr.gamma:.4g}, μ = {peak:.4g}")
    return (peak, len(history) - 1, hr, np.asarray(mu.upper, float), tuple(fits)), done
