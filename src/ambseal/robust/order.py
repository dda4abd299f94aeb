"""Controller order reduction with the cost in γ (and μ) reported.

Balanced truncation of the stable part of the controller, the unstable part (poles with
``Re ≥ -α``) kept exactly: SLICOT AB09MD (square-root balance & truncate, stable/unstable
split; Varga 1991), via slycot. Reference: Zhou, Doyle & Glover (1996) ch. 7;
Skogestad & Postlethwaite (2005) §11.4. μ and D–K controllers are of high order (the
plant's, the weights' and the D scales' states); reduction should cost little in γ or μ — this module says
how much.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any, Sequence

import control as ct
import numpy as np
from slycot import ab09md

from ambseal.errors import ConfigError, ModelError
from ambseal.lti import ss_matrices
from ambseal.robust.hinf import hinfnorm, lft_lower
from ambseal.robust.mu import lower_on_grid, upper_on_grid

__all__ = ["ReductionResult", "balred_controller", "reduce_controller"]


def balred_controller(K, order: int, alpha: float | None = None):
    """Balanced truncation of K to ``order`` states, keeping its unstable part.

    Parameters
    ----------
    K : control.StateSpace
        Continuous-time controller with ``n`` states.
    order : int
        Target number of states (≥ number of poles with ``Re ≥ alpha``).
    alpha : float, optional
        Stability boundary; poles with ``Re < alpha`` form the stable part (default:
        ``-1e-8·max(1, |λ|max)``, so integrators stay in the kept part).

    Returns
    -------
    Kr : control.StateSpace
        Reduced controller with K's channel names.
    hsv : ndarray
        Hankel singular values of the stable part (descending).

    Raises
    ------
    ModelError
        ``K`` is no continuous state-space system, or has a NaN or infinite entry.
    ConfigError
        ``order`` negative, above ``n`` or below the number of unstable poles.
    """
    if not isinstance(K, ct.StateSpace):
        raise ModelError(f"balred_controller: K is a {type(K).__name__}, not a "
                         "control.StateSpace")
    A, B, C, D = ss_matrices(K, name="balred_controller: K", finite=True)
    n = A.shape[0]
    if not isinstance(order, (int, np.integer)) or order < 0 or order > n:
        raise ConfigError(f"order={order!r}: must be an integer between 0 and {n}")
    lam = np.linalg.eigvals(A) if n else np.zeros(0)
    if alpha is None:
        # not a stability verdict (that is ambseal.robust.stability's): the split of the
        # balanced truncation, whose Gramians of nearly marginal poles are ill-conditioned,
        # so slow poles within 1e-8 of the fastest are kept exactly with the unstable ones
        alpha = -1e-8 * max(1.0, float(np.max(np.abs(lam))) if n else 1.0)
    nu = int(np.sum(lam.real >= alpha))
    if order < nu:
        raise ConfigError(f"order={order} is below the {nu} unstable/marginal poles of K, "
                          "which are kept exactly")
    names = dict(inputs=list(K.input_labels), outputs=list(K.output_labels), name=f"{K.name}_r")
    if order == n:
        return ct.ss(A, B, C, D, **names), np.zeros(0)

    m, p = B.shape[1], C.shape[0]
    Nr, Ar, Br, Cr, Ns, hsv = ab09md("C", "B", "N", n, m, p, A, B, C, alpha=alpha,
                                    nr=order, tol=0.0)
    Kr = ct.ss(Ar[:Nr, :Nr], Br[:Nr], Cr[:, :Nr], D, **names)
    return Kr, np.asarray(hsv[:Ns], float)


@dataclass(frozen=True)
class ReductionResult:
    """Result of :func:`reduce_controller`.

    Attributes
    ----------
    K : control.StateSpace
        Reduced controller.
    order_full, order : int
        States before and after.
    gamma_full, gamma : float
        ‖F_l(P, K)‖_∞ with the full and the reduced controller (``inf`` if the reduced loop
        is unstable).
    mu_full, mu : float or None
        Peak μ upper bounds on ``omega`` when ``blocks`` were given
        (:func:`~ambseal.robust.mu.upper_on_grid`), or ``mu`` a certified lower bound
        (``mu_is_lower``).
    hsv : ndarray
        Hankel singular values of the controller's stable part.
    mu_is_lower : bool
        ``mu`` is a certified lower bound above the ``mu_above`` :func:`reduce_controller`
        was given, not the peak: the reduced loop's μ is known to exceed that level.
    """

    K: Any
    order_full: int
    order: int
    gamma_full: float
    gamma: float
    mu_full: float | None = None
    mu: float | None = None
    hsv: np.ndarray = field(default_factory=lambda: np.zeros(0), repr=False)
    mu_is_lower: bool = False

    @property
    def gamma_rise(self) -> float:
        """Relative rise of γ, ``gamma / gamma_full - 1``."""
        return self.gamma / self.gamma_full - 1.0

    def to_dict(self) -> dict:
        """JSON-ready summary."""
        return {"order_full": self.order_full, "order": self.order,
                "gamma_full": self.gamma_full, "gamma": self.gamma,
                "gamma_rise": self.gamma_rise, "mu_full": self.mu_full, "mu": self.mu,
                "hsv": np.asarray(self.hsv).tolist()}


def reduce_controller(P, K, order: int, nmeas: int, ncon: int, *,
                      blocks: Sequence[Sequence[int]] | None = None, omega=None,
                      alpha: float | None = None, full: tuple | None = None,
                      mu_above: float | None = None) -> ReductionResult:
    """Reduce K and report what it costs in closed-loop γ (and peak μ).

    Parameters
    ----------
    P : control.StateSpace
        Generalised plant (inputs ``[w, u]``, outputs ``[z, y]``).
    K : control.StateSpace
        Controller from the ``nmeas`` measurements to the ``ncon`` control inputs.
    order : int
        Target controller order.
    nmeas, ncon : int
        Channel counts of ``y`` and ``u``.
    blocks : sequence of (int, int), optional
        Block structure for μ (then ``omega`` is required).
    omega : array_like, optional
        Frequencies in rad/s for μ.
    alpha : float, optional
        Stability boundary for the stable/unstable split (see :func:`balred_controller`).
    full : (float or None, float or None), optional
        γ and peak μ of the full-order loop when already known (a search over orders
        reduces the same controller several times; a μ design knows its μ on the same
        grid); each one omitted or None is computed.
    mu_above : float, optional
        For a search over orders that asks only whether the reduced loop's μ exceeds this
        level: where a certified lower bound on the grid already does
        (:func:`~ambseal.robust.mu.lower_on_grid`), ``mu`` is that lower bound
        (``mu_is_lower``) and the upper bound, which can only be larger, is not computed.
        None: the upper bound.

    Returns
    -------
    ReductionResult

    Raises
    ------
    ConfigError
        Bad order; ``blocks`` without ``omega``.
    """
    if blocks is not None and omega is None:
        raise ConfigError("reduce_controller: blocks given without a frequency grid omega")
    Kr, hsv = balred_controller(K, order, alpha)
    g_full, mu_full = full if full is not None else (None, None)
    if g_full is None:
        g_full = hinfnorm(lft_lower(P, K, nmeas, ncon))[0]
    g_red, _ = hinfnorm(lft_lower(P, Kr, nmeas, ncon))
    mu_red, mu_is_lower = None, False
    if blocks is not None:
        # the peak on the grid: a mixed structure solved only where it can reach it
        if mu_full is None:
            mu_full = float(np.max(upper_on_grid(lft_lower(P, K, nmeas, ncon), blocks,
                                                 omega)[1]))
        mu_red = float("inf")
        if np.isfinite(g_red):
            loop = lft_lower(P, Kr, nmeas, ncon)
            if mu_above is not None:
                low = float(np.max(lower_on_grid(loop, blocks, omega)))
                mu_is_lower = low > mu_above
            mu_red = low if mu_is_lower else float(np.max(upper_on_grid(loop, blocks,
                                                                        omega)[1]))
    return ReductionResult(K=Kr, order_full=int(K.nstates), order=int(Kr.nstates),
                           gamma_full=float(g_full), gamma=float(g_red), mu_full=mu_full,
                           mu=mu_red, hsv=hsv, mu_is_lower=mu_is_lower)
