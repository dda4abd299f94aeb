"""The D and G scalings of a D–G–K step: relaxed, fitted, refined, realised.

Private module behind :func:`ambseal.robust.dgk.musyn_dgk`. A real channel's G scaling is
the all-pass pair (a1, a2) of :func:`ambseal.robust.dgk.fit_g` (``f = (a1 + a2)/2``,
``h = (a1 − a2)/2``, phase difference ψ = 2·arctan ĝ); each channel's D scale a stable,
minimum-phase ``d(s)`` (:func:`ambseal.robust.dk.fit_dscale`). With them the K-step's
plant closes, through the current controller, to ``S = diag(d/β) M diag(f/d) + H``
(``M = F_l(P, K)``; ``H`` the ``−j sin(ψ/2)`` entries of the real channels, ``f`` reduced to
``cos(ψ/2)``: the common phases of d and f leave σ̄ unchanged), and
``σ̄(S(jω)) ≤ 1`` at every ω is the D–G certificate ``μ ≤ β`` of that controller (Young
1996 eq. 7). MATLAB's ``musyn`` reports ``β·max σ̄(S)`` as "DG Fit".

The pointwise scalings of μ's upper bound are unique only where μ(ω) is at its peak β;
elsewhere any scaling that meets the level β does, and the pointwise optimum jumps between
neighbouring frequencies (Barros, Fekri & Athans' spring–mass case, tests/spring_mass.py,
first step: the stiffness channel's D falls from 5.1 to 0.1 and ĝ leaps from −0.5 to
+1000 between 1.05 and 1.67 rad/s, where μ falls to 54 % of its peak). Fitted with
weights towards the peak, such data give scalings that no longer certify the
current controller between the peaks (σ̄(S) 1.28 at 1.2 rad/s), and the K-steps make μ
worse. So, in turn:

* :func:`relax_pointwise` moves each frequency's scalings towards those interpolated from
  the frequencies near the peak, as far as the level allows (the scalings that certify a
  level form a convex set);
* the fits are weighted again, round by round, towards the frequencies where the last
  round's scalings certify least (:func:`ambseal.robust.dgk._dg_step_scalings`), and the
  best round is kept where its peak of σ̄(S) is within 1 % of 1: least squares, which the
  machine's rounding moves by about its own size;
* else the best round's fits are refined to minimise ``max_ω σ̄(S)``
  directly (:func:`refine_scalings`: SLSQP on the epigraph with analytic gradients, whose
  end point follows the rounding; on a grid three times denser than μ's and half a
  decade wider; the H∞ norm of the scaled closed loop,
  AB13DD, adds the frequency of any peak between grid points, a cutting plane, until the
  bound is tight or the cuts stall), once more at the largest orders if that leaves σ̄(S)
  above 1, whose scalings are kept only where they lower the level beyond the norm's
  accuracy;
* the scaled plant realises each all-pass pair once (:func:`scaled_plant_dg`): no
  uncontrollable copies in the K-step's plant and controller.

On the spring–mass case the fits then certify the current controller within 0.3 % at every
step (σ̄(S) 1.000–1.003), and D–G–K reaches μ 0.95 (complex D–K: 1.08).

References: Young, "Controller design for mixed uncertainties using a D-G-K iteration"
(1996); Kraft, "A software package for sequential quadratic programming" (1988, SLSQP);
Kelley, "The cutting-plane method for solving convex programs" (1960).
"""

from __future__ import annotations

from dataclasses import dataclass

import control as ct
import numpy as np
from scipy.optimize import minimize

from ambseal.lti import least_squares_converged
from ambseal.lti.freqresp import freqresp
from ambseal.robust._dscale import (
    FIT_STALL_RTOL, _d_logmag_jac, _d_sections, _d_theta, _diag_sys, _ss, _tf_to_theta,
    _theta_to_tf, untied,
)
from ambseal.robust.hinf import hinfnorm, lft_lower


# --------------------------------------------------------------------------- all-pass pairs
def _ap_phase(x, w, k1, k2):
    """Unwrapped phase (rad) at s = jω of the all-pass Π (p − s)/(p + s) ·
    Π (s² − 2ζω_n s + ω_n²)/(s² + 2ζω_n s + ω_n²), x = [log p (k1), log ω_n, log ζ (k2)]."""
    ph = -2 * np.sum(np.arctan(w[:, None] / np.exp(x[:k1])[None, :]), axis=1)
    for i in range(k2):
        wn, z = np.exp(x[k1 + 2 * i]), np.exp(x[k1 + 2 * i + 1])
        ph = ph - 2 * np.arctan2(2 * z * wn * w, wn ** 2 - w ** 2)
    return ph


def _ap_jac(x, w, k1, k2):
    """d(_ap_phase)/dx, shape (F, k1 + 2 k2), in closed form."""
    J = np.empty((w.size, k1 + 2 * k2))
    r = w[:, None] / np.exp(x[:k1])[None, :]
    J[:, :k1] = 2 * r / (1 + r ** 2)
    for i in range(k2):
        wn, z = np.exp(x[k1 + 2 * i]), np.exp(x[k1 + 2 * i + 1])
        y, q = 2 * z * wn * w, wn ** 2 - w ** 2
        den = q ** 2 + y ** 2
        J[:, k1 + 2 * i] = 2 * y * (wn ** 2 + w ** 2) / den
        J[:, k1 + 2 * i + 1] = -2 * q * y / den
    return J


def _ap_tf(x, k1, k2):
    tf = ct.tf([1.0], [1.0])
    for p in np.exp(x[:k1]):
        tf = tf * ct.tf([-1.0, p], [1.0, p])
    for i in range(k2):
        wn, z = np.exp(x[k1 + 2 * i]), np.exp(x[k1 + 2 * i + 1])
        tf = tf * ct.tf([1.0, -2 * z * wn, wn ** 2], [1.0, 2 * z * wn, wn ** 2])
    return tf


#: (first-order, second-order) sections per all-pass function, tried in this order
_AP_ORDERS = ((1, 0), (0, 1), (2, 0), (1, 1), (0, 2), (2, 2))
#: damping of the all-pass functions' second-order sections
_AP_ZETA = (0.02, 2.0)


def _ap_bounds(w, k1, k2):
    lw = np.log(w)
    lo, hi = lw.min() - np.log(10.0), lw.max() + np.log(10.0)
    lb = np.array(([lo] * k1 + [lo, np.log(_AP_ZETA[0])] * k2) * 2)
    ub = np.array(([hi] * k1 + [hi, np.log(_AP_ZETA[1])] * k2) * 2)
    return lb, ub


def fit_allpass_pair(w, g, wgt, tol, start=None):
    """The all-pass pair whose phase difference fits ψ = 2·arctan ĝ (weighted nonlinear
    least squares, several starts; :func:`ambseal.robust.dgk.fit_g`). Returns
    ``(x, k1, k2, error)``, ``x = [x1, x2]`` of :func:`_ap_phase` (``None`` when no pair
    beats ψ ≡ 0), error the weighted largest |ψ error| in rad.

    ``start``, an earlier ``(x, k1, k2)`` of the same ĝ under other weights (the D–G
    step's reweighting rounds, :func:`ambseal.robust.dgk._dg_step_scalings`): one fit at
    its order from it, in place of the orders and starts; the continuation of that fit
    as its weights move."""
    psi = 2 * np.arctan(g)
    lw = np.log(w)
    sq = np.sqrt(wgt)
    best = (None, 0, 0, float(np.max(np.abs(psi) * wgt / wgt.max())))
    orders = _AP_ORDERS if start is None else ((start[1], start[2]),)
    for k1, k2 in orders:
        n = k1 + 2 * k2
        lb, ub = _ap_bounds(w, k1, k2)

        def resid(x):
            return sq * (_ap_phase(x[n:], w, k1, k2) - _ap_phase(x[:n], w, k1, k2) - psi)

        def jac(x):
            return sq[:, None] * np.hstack([-_ap_jac(x[:n], w, k1, k2), _ap_jac(x[n:], w, k1, k2)])

        def largest(x):
            return float(np.max(np.abs(resid(x)) * sq / wgt.max()))

        starts = (_ap_starts(lw, k1, k2) if start is None
                  else (untied(start[0], _ap_sections(k1, k2)),))
        for x0 in starts:
            res = least_squares_converged(resid, np.clip(x0, lb + 1e-3, ub - 1e-3), jac=jac,
                                          bounds=(lb, ub), stall=largest,
                                          stall_rtol=FIT_STALL_RTOL)
            err = largest(res.x)
            if err < best[3]:
                best = (res.x, k1, k2, err)
        if best[3] <= 2 * np.arctan(tol):
            break
    return best


def _ap_sections(k1, k2):
    """The interchangeable sections of a pair's two all-pass functions (:func:`untied`):
    per function its first-order corners, and its second-order sections (corner, damping)."""
    n = k1 + 2 * k2
    return [[[h + i] for i in range(k1)] for h in (0, n)] + \
        [[[h + k1 + 2 * i, h + k1 + 2 * i + 1] for i in range(k2)] for h in (0, n)]


def _ap_starts(lw, k1, k2):
    """The multistart of :func:`fit_allpass_pair` at one order: the sections' corners
    spread evenly over the grid (log ω ``lw``), shifted by ±0.7 and alternated between
    the pair's two functions."""
    for shift in (0.0, 0.7, -0.7):
        cen = np.linspace(lw.min(), lw.max(), 2 * (k1 + k2) + 2)[1:-1] + shift
        for c1, c2 in ((cen[0::2], cen[1::2]), (cen[1::2], cen[0::2])):
            yield np.r_[[v for v in c1[:k1]], [v for c in c1[k1:] for v in (c, np.log(0.3))],
                        [v for v in c2[:k1]], [v for c in c2[k1:] for v in (c, np.log(0.3))]]


# --------------------------------------------------------------------------- D sections
def _d_bounds(w, order):
    lw = np.log(w)
    lo, hi = lw.min() - np.log(10.0), lw.max() + np.log(10.0)
    sec, first = _d_sections(order)
    lb, ub = np.full(1 + 2 * order, -60.0), np.full(1 + 2 * order, 60.0)
    lb[sec], ub[sec] = 2 * lo, 2 * hi
    # 2ζ of a section: ≥ 0.1 as the fits' (dk._fit_weighted); two real roots a, b paired
    # into one section have 2ζ = (a + b)/√(ab), hence the wide upper bound
    lb[sec + 1], ub[sec + 1] = np.log(0.1), np.log(1e4)
    lb[first], ub[first] = lo, hi
    return lb, ub


# --------------------------------------------------------------------------- pointwise
def block_layout(sblocks):
    """Per block of the scalar structure: the rows (z) and columns (w) of M it reads and
    drives."""
    out, row, col = [], 0, 0
    for blk in sblocks:
        r, c = blk if blk[1] else (abs(blk[0]), abs(blk[0]))
        out.append((np.arange(row, row + c), np.arange(col, col + r)))
        row, col = row + c, col + r
    return out


def _levels(M, layout, real, D, g):
    """√λ_max of the generalised eigenproblem (Mᴴ D_l M + j(G M − Mᴴ Gᴴ), D_r) per
    frequency: the level β at which the scalings ``D`` (F, nb) and ``g`` (F, nb; real blocks
    only) certify μ ≤ β (the performance block's D is 1)."""
    F, n, m = M.shape
    dl, dr = np.ones((F, n)), np.ones((F, m))
    G = np.zeros((F, m, n), complex)
    for j, (rows, cols) in enumerate(layout[:-1]):
        dl[:, rows], dr[:, cols] = D[:, j:j + 1], D[:, j:j + 1]
        if real[j]:
            G[:, cols[0], rows[0]] = g[:, j]
    MH = np.conj(np.swapaxes(M, 1, 2))
    A = MH @ (dl[:, :, None] * M) + 1j * (G @ M - MH @ np.conj(np.swapaxes(G, 1, 2)))
    s = 1 / np.sqrt(dr)
    A = s[:, :, None] * A * s[:, None, :]
    A = 0.5 * (A + np.conj(np.swapaxes(A, 1, 2)))
    return np.sqrt(np.maximum(np.linalg.eigvalsh(A)[:, -1], 0.0))


#: the pointwise scalings are moved while their level stays below max(μ(ω), (1 − RELAX)·β)
#: (measured on the spring–mass case, 100 points over 10⁻²…10³ rad/s: D–G–K ends at μ 0.941,
#: 0.903, 0.917 with 0.01, 0.02, 0.05) ...
RELAX = 0.02
#: ... towards the scalings of the frequencies where μ is within TIGHT of its peak
TIGHT = 0.1


def relax_pointwise(M, sblocks, real, Dl, G, mu, beta, omega):
    """Pointwise D–G scalings made easy to fit: D² and G of each block (normalised by the
    performance block's D²; ``Dl``, ``G`` as :class:`~ambseal.robust.mu.MuResult` holds
    them, ``mu`` its upper bound, ``beta`` its peak, on ``omega``), moved at each frequency
    along the segment towards the scalings interpolated from the frequencies where μ is
    within :data:`TIGHT` of β, as far as their level allows (:data:`RELAX`; the set of
    scalings that certify a level is convex, so the segment stays in it up to the bisected
    point). Returns ``(d, ĝ)``, shape (F, nb) each: ``d = √D²`` and ``ĝ = G/(D² β)`` per
    block but the last."""
    lay = block_layout(sblocks)
    F, nb = M.shape[0], len(lay) - 1
    last = lay[-1][0][0]
    dlast = np.real(Dl[:, last, last]) ** 2
    D, g = np.empty((F, nb)), np.zeros((F, nb))
    for j, (rows, cols) in enumerate(lay[:-1]):
        D[:, j] = np.real(Dl[:, rows[0], rows[0]]) ** 2 / dlast
        if real[j]:
            g[:, j] = np.real(G[:, cols[0], rows[0]]) / dlast
    cap = np.maximum(_levels(M, lay, real, D, g), (1 - RELAX) * beta)
    # target: the scalings of the frequencies where μ is within TIGHT of its peak (there
    # they are nearly unique), interpolated in log ω (log D², ĝ), held beyond the ends
    tight = mu >= (1 - TIGHT) * beta
    lw = np.log(np.asarray(omega, float))
    ghat = g / (D * beta)
    Dt = np.exp(np.column_stack([np.interp(lw, lw[tight], np.log(D[tight, j]))
                                 for j in range(nb)]))
    gt = np.column_stack([np.interp(lw, lw[tight], ghat[tight, j]) for j in range(nb)]) \
        * Dt * beta
    lo, hi = np.zeros(F), np.ones(F)
    for _ in range(24):
        t = 0.5 * (lo + hi)[:, None]
        ok = _levels(M, lay, real, D + t * (Dt - D), g + t * (gt - g)) <= cap
        lo, hi = np.where(ok, t[:, 0], lo), np.where(ok, hi, t[:, 0])
    D, g = D + lo[:, None] * (Dt - D), g + lo[:, None] * (gt - g)
    return np.sqrt(D), g / (D * beta)


# --------------------------------------------------------------------------- the scalings
@dataclass
class _Channel:
    """One scaled block (all but the performance block): its rows (z) and columns (w) of
    M, where its D parameters sit in the vector and, for a real scalar, its G's."""

    rows: np.ndarray
    cols: np.ndarray
    d_at: int
    d_order: int
    g_at: int = -1
    k1: int = 0
    k2: int = 0


class DGScalings:
    """The rational D–G scalings of one D–G–K step as one parameter vector.

    Parameters
    ----------
    sblocks : list of (int, int)
        Scalar structure (:func:`ambseal.robust.dgk._split`); the last block is the
        performance block, unscaled.
    real : list of bool
        Per block of ``sblocks``, whether a real scalar.
    d_fits : list of control.TransferFunction
        The fitted D scale of each block but the last.
    g_fits : dict
        Block index → ``(x, k1, k2)`` of :func:`fit_allpass_pair` (real blocks whose pair
        beats ψ ≡ 0).
    beta : float
        The level β of the scalings (μ peak of the current controller).
    w : ndarray
        μ's frequency grid (rad/s): the parameter bounds are set from it.
    """

    def __init__(self, sblocks, real, d_fits, g_fits, beta, w):
        self.beta = float(beta)
        self._args = (sblocks, real, np.asarray(w, float))
        self.channels: list[_Channel] = []
        x, lb, ub = [], [], []
        row = col = 0
        for j, (blk, is_real) in enumerate(zip(sblocks[:-1], real[:-1])):
            r, c = blk if blk[1] else (abs(blk[0]), abs(blk[0]))
            th, order = _tf_to_theta(d_fits[j])
            xd = np.array(th, float)
            sec, _ = _d_sections(order)
            xd[sec + 1] = th[sec + 1] - 0.5 * th[sec]
            ch = _Channel(np.arange(row, row + c), np.arange(col, col + r), len(x), order)
            x += list(xd)
            b = _d_bounds(w, order)
            lb += list(b[0])
            ub += list(b[1])
            if is_real and j in g_fits:
                xg, ch.k1, ch.k2 = g_fits[j]
                ch.g_at = len(x)
                x += list(xg)
                b = _ap_bounds(w, ch.k1, ch.k2)
                lb += list(b[0])
                ub += list(b[1])
            self.channels.append(ch)
            row, col = row + c, col + r
        self.lb, self.ub = np.array(lb), np.array(ub)
        self.x0 = np.clip(np.array(x, float), self.lb, self.ub)

    def enlarged(self, x):
        """The scalings at ``x`` as parameters of the largest orders (D: 4, all-pass
        pairs: two first- and two second-order sections each), the added sections
        cancelling (a pole on a zero in D, the same section in both all-pass functions): the
        same scalings, with more freedom for :func:`refine_scalings`. None if every block
        is at those orders already."""
        sblocks, real, w = self._args
        mid = float(np.sqrt(w.min() * w.max()))
        fits = self.fits(x)
        d_fits, g_fits, grown = [], {}, False
        for j, (ch, fit) in enumerate(zip(self.channels, fits)):
            d = fit[0]
            for _ in range(ch.d_order, 4):
                d = d * ct.tf([1.0, mid], [1.0, mid])
                grown = True
            d_fits.append(d)
            if ch.g_at < 0:
                continue
            n1 = ch.k1 + 2 * ch.k2
            parts = []
            for xa in (x[ch.g_at:ch.g_at + n1], x[ch.g_at + n1:ch.g_at + 2 * n1]):
                first = list(xa[:ch.k1]) + [np.log(mid)] * (2 - ch.k1)
                second = list(xa[ch.k1:]) + [np.log(mid), np.log(0.5)] * (2 - ch.k2)
                parts.append(first + second)
            grown = grown or (ch.k1, ch.k2) != (2, 2)
            g_fits[j] = (np.array(parts[0] + parts[1]), 2, 2)
        if not grown:
            return None
        return DGScalings(sblocks, real, d_fits, g_fits, self.beta, w)

    def sigma(self, x, M, w, grad: bool = False):
        """σ̄(S(jω)) on ``w`` for the closed loop ``M`` (F, n, m); with ``grad`` also its
        gradient in x, shape (F, len(x)) (top singular pair; one-sided where σ̄ is
        repeated)."""
        F, n, m = M.shape
        L, R = np.full((F, n), 1 / self.beta), np.ones((F, m))
        H = np.zeros((F, n, m), complex)
        parts = []
        for ch in self.channels:
            ld, Jd = _d_logmag_jac(x[ch.d_at:ch.d_at + 1 + 2 * ch.d_order], w, ch.d_order)
            d = np.exp(ld)
            L[:, ch.rows] = (d / self.beta)[:, None]
            R[:, ch.cols] = (1 / d)[:, None]
            psi = Jp = None
            if ch.g_at >= 0:
                n1 = ch.k1 + 2 * ch.k2
                x1, x2 = x[ch.g_at:ch.g_at + n1], x[ch.g_at + n1:ch.g_at + 2 * n1]
                psi = _ap_phase(x2, w, ch.k1, ch.k2) - _ap_phase(x1, w, ch.k1, ch.k2)
                Jp = np.hstack([-_ap_jac(x1, w, ch.k1, ch.k2), _ap_jac(x2, w, ch.k1, ch.k2)])
                R[:, ch.cols[0]] *= np.cos(psi / 2)
                H[:, ch.rows[0], ch.cols[0]] = -1j * np.sin(psi / 2)
            parts.append((ch, d, Jd, psi, Jp))
        T = L[:, :, None] * M * R[:, None, :]
        if not grad:
            return np.linalg.svd(T + H, compute_uv=False)[:, 0]
        U, s, Vh = np.linalg.svd(T + H)
        u, v = U[:, :, 0], np.conj(Vh[:, 0, :])
        Tv = np.einsum("fij,fj->fi", T, v)
        uT = np.einsum("fi,fij->fj", np.conj(u), T)
        G = np.zeros((F, x.size))
        for ch, d, Jd, psi, Jp in parts:
            # ∂S/∂log d: its rows × 1, its columns × −1
            ds = np.real(np.sum(np.conj(u[:, ch.rows]) * Tv[:, ch.rows], axis=1)
                         - np.sum(uT[:, ch.cols] * v[:, ch.cols], axis=1))
            G[:, ch.d_at:ch.d_at + Jd.shape[1]] = ds[:, None] * Jd
            if psi is not None:
                r, c = ch.rows[0], ch.cols[0]
                # ∂S/∂ψ: column c of L M / d times −sin(ψ/2)/2, and H_rc's −j cos(ψ/2)/2
                LMc = L * M[:, :, c] / d[:, None]
                dp = np.real(np.sum(np.conj(u) * LMc, axis=1) * (-np.sin(psi / 2) / 2) * v[:, c]
                             + np.conj(u[:, r]) * (-0.5j * np.cos(psi / 2)) * v[:, c])
                G[:, ch.g_at:ch.g_at + Jp.shape[1]] = dp[:, None] * Jp
        return s[:, 0], G

    def fits(self, x):
        """Per block but the last: ``(d, f, h)`` transfer functions (f, h None for blocks
        without a G scaling)."""
        out = []
        for ch in self.channels:
            num, den = _theta_to_tf(_d_theta(x[ch.d_at:ch.d_at + 1 + 2 * ch.d_order],
                                             ch.d_order), ch.d_order)
            d = ct.tf(num, den)
            if ch.g_at < 0:
                out.append(DGFit(d))
                continue
            n1 = ch.k1 + 2 * ch.k2
            a1 = _ap_tf(x[ch.g_at:ch.g_at + n1], ch.k1, ch.k2)
            a2 = _ap_tf(x[ch.g_at + n1:ch.g_at + 2 * n1], ch.k1, ch.k2)
            out.append(DGFit(d, (a1 + a2) / 2, (a1 - a2) / 2, (a1, a2)))
        return out


def _blockdiag(parts):
    """Block-diagonal state space of (A, B, C, D) tuples (any input/output counts)."""
    n = sum(p[0].shape[0] for p in parts)
    m = sum(p[1].shape[1] for p in parts)
    q = sum(p[2].shape[0] for p in parts)
    A, B, C, D = np.zeros((n, n)), np.zeros((n, m)), np.zeros((q, n)), np.zeros((q, m))
    o = i = r = 0
    for a, b, c, d in parts:
        k, mi, qi = a.shape[0], b.shape[1], c.shape[0]
        A[o:o + k, o:o + k], B[o:o + k, i:i + mi] = a, b
        C[r:r + qi, o:o + k], D[r:r + qi, i:i + mi] = c, d
        o, i, r = o + k, i + mi, r + qi
    return A, B, C, D


class DGFit(tuple):
    """One block's fitted scalings ``(d, f, h)`` (f, h None without a G scaling), with the
    all-pass pair ``(a1, a2)`` behind f and h in ``pair`` (None without)."""

    def __new__(cls, d, f=None, h=None, pair=None):
        obj = super().__new__(cls, (d, f, h))
        obj.pair = pair
        return obj


def _matrices(sys):
    return tuple(np.asarray(M, float) for M in (sys.A, sys.B, sys.C, sys.D))


def _pair_channel(fit):
    """One real channel's input side as one system, input v, outputs ``[(f/d)·v, h·v]``,
    with the all-pass pair's states once: f and h realised apart hold the poles of both
    all-pass functions twice each, as uncontrollable copies that the K-step's controller
    inherits (spring–mass case, first step: 46 states instead of 34)."""
    d = fit[0]
    a1, a2 = (_matrices(ct.ss(a)) for a in fit.pair)
    A, _, C, _ = _blockdiag([a1, a2])
    B = np.vstack([a1[1], a2[1]])
    T = np.array([[0.5, 0.5], [0.5, -0.5]])
    pair = ct.ss(A, B, T @ C, T @ np.vstack([a1[3], a2[3]]))
    one = (np.zeros((0, 0)), np.zeros((0, 1)), np.zeros((1, 0)), np.ones((1, 1)))
    return _matrices(ct.ss(*_blockdiag([_ss(1 / d), one])) * pair)


def scaled_plant_dg(P, sblocks, fits, beta, nmeas, ncon):
    """diag(D/β̄, I) · P · diag(F D⁻¹, I) + [[H, 0], [0, 0]] (module docstring of
    :mod:`ambseal.robust.dgk`), realised as ``[diag(D/β̄, I)·P, E] · W`` with ``W`` the
    input side ``[w, u] → [F D⁻¹ w, u, H-inputs]`` and ``E`` adding the H terms to their
    rows of z."""
    one = (np.zeros((0, 0)), np.zeros((0, 1)), np.zeros((1, 0)), np.ones((1, 1)))
    inv_beta = (np.zeros((0, 0)), np.zeros((0, 1)), np.zeros((1, 0)), np.full((1, 1), 1 / beta))
    left, right, h_rows, row = [], [], [], 0
    for blk, fit in zip(sblocks, list(fits) + [None]):
        r, c = blk if blk[1] else (abs(blk[0]), abs(blk[0]))
        if fit is None:
            left.extend([inv_beta] * c)
            right.extend([(one, False)] * r)
        else:
            d = fit[0]
            left.extend([_ss(d / beta)] * c)
            if getattr(fit, "pair", None) is None:
                right.extend([(_ss(1 / d), False)] * r)
            else:
                right.append((_pair_channel(fit), True))
                h_rows.append(row)
        row += c
    left.extend([one] * nmeas)
    right.extend([(one, False)] * ncon)
    # W: primary outputs (one per input of P) first, the H outputs after them
    A, B, C, D = _blockdiag([p for p, _ in right])
    order = []
    k = 0
    for _, pair in right:
        order.append(k)
        k += 2 if pair else 1
    h_out = [i + 1 for i, (_, pair) in zip(order, right) if pair]
    sel = order + h_out
    W = ct.ss(A, B, C[sel], D[sel])
    Pb = ct.ss(P.A, P.B, P.C, P.D)
    LP = _diag_sys(left) * Pb
    E = np.zeros((LP.noutputs, len(h_rows)))
    E[h_rows, np.arange(len(h_rows))] = 1.0
    front = ct.ss(LP.A, np.hstack([LP.B, np.zeros((LP.nstates, len(h_rows)))]), LP.C,
                  np.hstack([LP.D, E]))
    Ps = front * W
    return ct.ss(Ps.A, Ps.B, Ps.C, Ps.D, inputs=list(P.input_labels),
                 outputs=list(P.output_labels), name="P_dg_scaled")


# --------------------------------------------------------------------------- refinement
#: refinement grid: points per interval of μ's grid, and decades added at both ends
_DENSE, _WIDEN = 3, 0.5
#: cutting planes (H∞ peaks added to the grid) that in a row do not lower the best level
#: by ``_CUT_RTOL`` end a refinement: a stall, as D–G–K's steps end by their patience
_CUT_PATIENCE = 2
#: SLSQP's ``ftol`` of each refinement (:func:`_minimax`)
_SLSQP_FTOL = 1e-6
#: SLSQP's status where its iteration count (SciPy's default, 100) stopped it
_SLSQP_COUNT = 9
#: a peak between grid points this far above the grid's peak is added to the grid; also
#: the gain in the level that counts for the cuts' patience
_CUT_RTOL = 1e-2
#: a round of SciPy's count (100 SLSQP iterations) that lowers the level by less than this
#: fraction of it is a stall and ends the refinement: a tenth of the gain that counts for
#: the cuts. Measured (benchmarks/README.md, "The refinement's rounds end at a tenth of
#: the cuts' gain"): rounds that went on to a gain of 1e-6 took 20–55 s a refinement for
#: the last 0.1–2 % of the level
_ROUND_RTOL = _CUT_RTOL / 10
#: scalings whose level stays this far above 1 are refined once more at the largest orders
_RETRY = 1e-2
#: relative accuracy of the scaled loop's H∞ norm (its level)
_NORM_RTOL = 1e-6


def _dense_grid(w):
    lw = np.log10(w)
    step = float(np.min(np.diff(lw))) / _DENSE if w.size > 1 else 0.1
    step = max(step, (lw.max() - lw.min() + 2 * _WIDEN) / 2000)
    return 10 ** np.arange(lw.min() - _WIDEN, lw.max() + _WIDEN + step / 2, step)


def _minimax(sc: DGScalings, x0, M, w):
    """x minimising max_ω σ̄(S) on ``w`` from x0 (SLSQP on the epigraph, ended by its
    ``ftol`` or a round's stall — a round of SciPy's count that lowers the level by less than
    ``_ROUND_RTOL`` of it — never by its count); never worse than x0."""
    s0 = sc.sigma(x0, M, w)
    p = x0.size

    def cons(z):
        return z[-1] - sc.sigma(z[:-1], M, w)

    def cons_jac(z):
        _, G = sc.sigma(z[:-1], M, w, grad=True)
        return np.hstack([-G, np.ones((w.size, 1))])

    def solve(z0):
        return minimize(lambda z: z[-1], z0, jac=lambda z: np.r_[np.zeros(p), 1.0],
                        method="SLSQP", bounds=list(zip(np.r_[sc.lb, 0.0], np.r_[sc.ub, np.inf])),
                        constraints=[{"type": "ineq", "fun": cons, "jac": cons_jac}],
                        options={"ftol": _SLSQP_FTOL})

    res = solve(np.r_[x0, s0.max()])
    # where SciPy's count stopped SLSQP, it goes on from there until its ftol ends it or a
    # whole round lowers the level by less than _ROUND_RTOL of it: a stall, not a count
    while res.status == _SLSQP_COUNT:
        level = res.fun
        res = solve(res.x)
        if res.status == _SLSQP_COUNT and level - res.fun <= _ROUND_RTOL * level:
            break
    x = np.clip(res.x[:-1], sc.lb, sc.ub)
    return x if np.all(np.isfinite(x)) and sc.sigma(x, M, w).max() < s0.max() else x0


def refine_scalings(sc: DGScalings, P, K, sblocks, nmeas, ncon, w):
    """The scalings' parameters that minimise ``max_ω σ̄(S)`` of the current controller
    (module docstring), and that peak: the lowest H∞ level of the cutting planes' scalings
    (Kelley 1960), each pass ended where the level is within ``_CUT_RTOL`` of the grid's
    peak or ``_CUT_PATIENCE`` cuts in a row have not lowered the pass's best by it; the
    pass at the largest orders is kept only where its level is lower than the first's by
    more than ``_NORM_RTOL``, the norm's accuracy.

    Parameters
    ----------
    sc : DGScalings
        The fitted scalings (their start).
    P, K : control.StateSpace
        Generalised plant and current controller.
    sblocks : list of (int, int)
        Scalar structure of ``sc``.
    nmeas, ncon : int
        Measurements and controls.
    w : ndarray
        μ's grid (rad/s).

    Returns
    -------
    fits : list of (d, f, h)
        As :meth:`DGScalings.fits`.
    level : float
        H∞ norm of the scaled closed loop ``S`` (≥ its grid peak).
    """
    cl = lft_lower(P, K, nmeas, ncon)
    wd = _dense_grid(np.asarray(w, float))
    M = freqresp(cl, wd)
    best = None
    while sc is not None:
        x, here, misses = sc.x0, None, 0
        # Kelley's cutting planes: each H∞ peak between the grid's points joins the grid,
        # until the level is within _CUT_RTOL of the grid's peak (the bound is tight) or
        # _CUT_PATIENCE cuts in a row lower the best level by less than _CUT_RTOL; the
        # best of the cuts' scalings is kept (a cut can raise the level)
        while True:
            x = _minimax(sc, x, M, wd)
            peak = float(sc.sigma(x, M, wd).max())
            fits = sc.fits(x)
            level, w_peak = hinfnorm(lft_lower(scaled_plant_dg(P, sblocks, fits, sc.beta,
                                                              nmeas, ncon), K, nmeas, ncon),
                                     rtol=_NORM_RTOL)
            if here is None or level < here[2] * (1 - _CUT_RTOL):
                misses = 0
            else:
                misses += 1
            if here is None or level < here[2]:
                here = (x, fits, float(level))
            tight = not (np.isfinite(level) and level > peak * (1 + _CUT_RTOL) and w_peak > 0)
            if not tight:  # the peak joins the grid, also for the pass at the largest orders
                wn = w_peak * np.array([0.98, 1.0, 1.02])
                wd = np.r_[wd, wn]
                M = np.concatenate([M, freqresp(cl, wn)])
            if tight or misses >= _CUT_PATIENCE:
                break
        x, fits, level = here
        # the pass at the largest orders is kept only where its level is lower beyond the
        # norm's accuracy: where it ended where the first pass did (its start), the lower
        # of two equal levels followed the rounding, and so did the K step's plant (the
        # overhung compressor's second D–G–K step: 196 states under one kernel set, 220
        # under another, at one level to 1e-6)
        if best is None or level < best[1] * (1 - _NORM_RTOL):
            best = (fits, level)
        # the fitted orders could not reach the pointwise level: once more at the largest
        sc = sc.enlarged(x) if level > 1 + _RETRY else None
    return best
