"""The performance level a robustness requirement leaves: the largest α at which the
scaled H∞ bound still certifies it.

A generalised plant with uncertainty channels ``(w_Δ, z_Δ)`` and performance channels
``(w_p, z_p)`` asks for robust stability and performance at once. Where the uncertain set
is wide (a parameter known only over a wide interval), no controller may meet both at
the weights as given, yet one that holds every plant of the set exists. Scaling the
performance outputs ``z_p`` by α ∈ (0, 1] relaxes the performance asked for and leaves
the robustness asked for as it is; the largest α whose scaled γ is below 1 is the
performance level the set leaves (Skogestad & Postlethwaite, *Multivariable Feedback
Control*, 2nd ed. 2005, §8.10.3: the performance weight scaled until μ = 1; Zhou, Doyle &
Glover, *Robust and Optimal Control*, 1996, §11.3: the scaled H∞ problem). A γ below 1
certifies, by the small-gain theorem, stability for every plant of the set and the
performance weights met at level α.

Each level is evaluated in an equivalent form that leaves the control and measurement
channels as they are: with the uncertainty inputs ``w_Δ`` scaled by 1/α instead,

    ‖diag(D, α I) M diag(D⁻¹, I)‖ = α ‖diag(D', I) M diag(D'⁻¹/α, I)‖,  D' = D/α,

so the bound at level α is α times the scaled γ of that plant, over every constant D
alike. Scaling ``z_p`` itself shrinks the control-effort rows the H∞ synthesis needs of
full rank (D₁₂), and its γ search slows by an order of magnitude at α = 0.01.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, Sequence

import control as ct
import numpy as np

from ambseal.errors import ConfigError
from ambseal.robust.mu import parse_blocks

__all__ = ["LevelResult", "performance_level", "scaled_performance", "LEVEL_FLOOR",
           "LEVEL_RTOL"]

#: The lowest level tried: the performance outputs two decades below the weights as given
#: hardly shape the controller (the design is nearly one for robust stability alone), so
#: a set not certified there is not certified by relaxing performance further.
LEVEL_FLOOR = 1e-2

#: The bisection on log α stops when the certified and the refused levels are within this
#: relative distance (a convergence criterion, not a count).
LEVEL_RTOL = 0.1


@dataclass(frozen=True)
class LevelResult:
    """What :func:`performance_level` found.

    Attributes
    ----------
    level : float or None
        The certified level α; None where even the floor is not certified.
    gamma : float or None
        The bound at that level (α times ``result.gamma``), below 1; None with it.
    result : object or None
        ``synthesise``'s result at that level (on the plant with ``w_Δ`` scaled by 1/α:
        its controller closes the same ``u`` and ``y`` as one on ``P``); None with it.
    tried : tuple of (float, float)
        Every (α, bound) evaluated, in order.
    """

    level: float | None
    gamma: float | None
    result: Any
    tried: tuple


def _channels(blocks) -> tuple[int, int]:
    """(w_Δ inputs, z_Δ outputs) of ``blocks`` less its last (performance) block."""
    if len(blocks) < 2:
        raise ConfigError("performance_level: blocks has no uncertainty block before the "
                          "performance block")
    parsed = parse_blocks(blocks)[:-1]
    return sum(b.r for b in parsed), sum(b.c for b in parsed)


def scaled_performance(P, blocks: Sequence[Sequence[int]], nmeas: int, ncon: int,
                       level: float):
    """``P`` with its performance outputs (after the uncertainty outputs of ``blocks``,
    before the last ``nmeas``) multiplied by ``level``: the plant a design at that level
    (μ, say) is made on.

    Parameters
    ----------
    P : control.StateSpace
        Generalised plant, inputs ``[w_Δ, w_p, u]``, outputs ``[z_Δ, z_p, y]``.
    blocks : sequence of (int, int)
        The uncertainty structure, its last block the performance block.
    nmeas, ncon : int
        Measurements and controls.
    level : float
        The performance level α, 0 < α ≤ 1.

    Returns
    -------
    control.StateSpace
        The same plant, its ``z_p`` rows of C and D times α.

    Raises
    ------
    ConfigError
        ``level`` not in (0, 1], or ``blocks`` without an uncertainty block.
    """
    if not 0 < level <= 1:
        raise ConfigError(f"scaled_performance: level={level!r}, expected 0 < level ≤ 1")
    _, nzd = _channels(blocks)
    C, D = np.array(P.C, float), np.array(P.D, float)
    nz = C.shape[0] - nmeas
    C[nzd:nz] *= level
    D[nzd:nz] *= level
    return ct.ss(np.asarray(P.A, float), np.asarray(P.B, float), C, D)


def _enlarged(P, nwd: int, level: float):
    """``P`` with its first ``nwd`` inputs (w_Δ) multiplied by 1/``level``."""
    B, D = np.array(P.B, float), np.array(P.D, float)
    B[:, :nwd] /= level
    D[:, :nwd] /= level
    return ct.ss(np.asarray(P.A, float), B, np.asarray(P.C, float), D)


def performance_level(P, blocks: Sequence[Sequence[int]], nmeas: int, ncon: int,
                      synthesise, *, refused: float | None = None,
                      rtol: float = LEVEL_RTOL, floor: float = LEVEL_FLOOR) -> LevelResult:
    """The largest performance level α ∈ [``floor``, 1] at which ``synthesise`` certifies
    the uncertainty of ``blocks``, by bisection on log α.

    Parameters
    ----------
    P : control.StateSpace
        Generalised plant, inputs ``[w_Δ, w_p, u]``, outputs ``[z_Δ, z_p, y]``.
    blocks : sequence of (int, int)
        The uncertainty structure (:func:`ambseal.robust.mu.mussv`); every block but the
        last (the performance block) is an uncertainty channel.
    nmeas, ncon : int
        Measurements and controls.
    synthesise : callable
        ``synthesise(P_alpha)`` → a result with ``gamma``, a constant-scaled H∞ bound
        (:func:`ambseal.robust.dk.scaled_hinfsyn`, say), for ``P`` with its
        uncertainty inputs scaled by 1/α; the bound at level α is α·``gamma``.
    refused : float, optional
        A level in (``floor``, 1] the caller already found not certified (bound ≥ 1
        there): the bisection's upper end, not evaluated again. None: α = 1 is evaluated
        first.
    rtol : float
        Relative width of the final bracket on α.
    floor : float
        The lowest level tried (:data:`LEVEL_FLOOR`).

    Returns
    -------
    LevelResult
        α = 1 where the weights as given are certified; else the highest certified level
        of the bisection; None where ``floor`` is not certified either.

    Raises
    ------
    ConfigError
        ``rtol`` not positive, ``floor`` not in (0, 1), ``refused`` not in (``floor``, 1],
        or no uncertainty block.
    """
    if not rtol > 0 or not 0 < floor < 1:
        raise ConfigError(f"performance_level: rtol={rtol!r} must be > 0 and floor={floor!r} "
                          "in (0, 1)")
    if refused is not None and not floor < refused <= 1:
        raise ConfigError(f"performance_level: refused={refused!r}, expected a level in "
                          f"({floor:g}, 1]")
    nwd, _ = _channels(blocks)
    tried = []

    def at(a):
        r = synthesise(_enlarged(P, nwd, a))
        tried.append((float(a), a * float(r.gamma)))
        return r, tried[-1][1]

    if refused is None:
        r, g = at(1.0)
        if g < 1:
            return LevelResult(1.0, g, r, tuple(tried))
    lo, hi = floor, 1.0 if refused is None else float(refused)
    best, g_best = at(lo)
    if not g_best < 1:
        return LevelResult(None, None, None, tuple(tried))
    while hi / lo > 1 + rtol:
        a = float(np.sqrt(lo * hi))
        r, g = at(a)
        if g < 1:
            lo, best, g_best = a, r, g
        else:
            hi = a
    return LevelResult(lo, g_best, best, tuple(tried))
