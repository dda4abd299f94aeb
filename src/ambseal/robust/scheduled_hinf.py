"""H∞ scheduled on a parameter: the central controllers of frozen plants at one γ, in the
plants' common state basis, interpolated linearly.

Classical gain scheduling (Rugh & Shamma, "Research on gain scheduling", Automatica
36(10), 2000, §3): the plant frozen at table values θ_i, one LTI design at each, the
controller interpolated between them. Interpolating state-space matrices means something
only where the controllers share a state basis. The central H∞ controller (Glover & Doyle,
Syst. Control Lett. 11, 1988; Zhou, Doyle & Glover, *Robust and Optimal Control*, 1996,
Thm 16.4) is observer-based — its state estimates the plant's — so plants written in one
state basis give controllers in that basis, whose matrices move continuously with θ as
the two Riccati solutions do (Stilwell & Rugh, "Interpolation of observer state feedback
controllers for gain scheduling", IEEE TAC 44(6), 1999). Every entry is built at one γ,
:data:`BACKOFF` times the largest γ_opt of the table, so that no entry sits at its own
optimum, where (I − γ⁻² Y X)⁻¹ is singular and the controller jumps with the plant.

Nothing certifies the loop between table values or while θ changes: the caller judges the
interpolated controller where it runs (frozen at each judged θ and between entries).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import control as ct
import numpy as np

from ambseal.errors import ConfigError, ModelError
from ambseal.robust.hinf import _Sb10, check_plant, regularise_plant
from ambseal.robust.lpv import LpvController
from ambseal.threads import with_numerics_threads

__all__ = ["BACKOFF", "ScheduledHinfResult", "hinf_scheduled"]

#: γ of every entry over the table's largest γ_opt: each entry 10 % from its own optimum,
#: where the central controller is well conditioned (measured on 27 tables of frozen
#: plants, benchmarks/README.md: 1.01 and 1.1 give loops that hold alike).
BACKOFF = 1.1

#: Relative tolerance of each entry's γ_opt (that of :func:`~ambseal.robust.hinf.hinfsyn`).
GAMMA_RTOL = 1e-6


@dataclass(frozen=True)
class ScheduledHinfResult:
    """Central H∞ controllers of a table of frozen plants.

    Attributes
    ----------
    K : LpvController
        The controllers tabulated on θ (``u = K(θ) y``, the lower LFT's positive
        feedback), in the plants' state basis, interpolated linearly.
    gamma : float
        The γ every entry was built at (:data:`BACKOFF` × max ``gamma_opt``).
    gamma_opt : ndarray, shape (n_t,)
        γ_opt of each frozen plant.
    gamma_entries : ndarray, shape (n_t,)
        The verified H∞ norm of each entry's closed loop F_l(P_i, K_i) (≤ ``gamma``).
    backoff : float
        ``gamma`` over the largest ``gamma_opt``.
    """

    K: LpvController = field(repr=False)
    gamma: float
    gamma_opt: np.ndarray = field(repr=False)
    gamma_entries: np.ndarray = field(repr=False)
    backoff: float = BACKOFF


@with_numerics_threads
def hinf_scheduled(plants, theta, nmeas: int, ncon: int, *,
                   backoff: float = BACKOFF) -> ScheduledHinfResult:
    """Central H∞ controllers of the frozen plants ``plants[i] = P(θ_i)`` at one γ, as a
    controller table on θ (module docstring).

    Parameters
    ----------
    plants : sequence of control.StateSpace
        Continuous generalised plants, inputs ``[w, u]``, outputs ``[z, y]``, all with
        the same channels and states **in one state basis** (e.g. one LFT closed at each
        θ_i): the controllers share that basis only if the plants do.
    theta : array_like, shape (n_t,)
        The table's θ (any unit), strictly increasing; one per plant.
    nmeas, ncon : int
        Measurements (last outputs) and controls (last inputs).
    backoff : float
        γ over the largest γ_opt (≥ 1, finite).

    Returns
    -------
    ScheduledHinfResult

    Raises
    ------
    ConfigError
        θ not strictly increasing or not one per plant, a back-off below 1.
    ModelError
        Plants of different sizes (:func:`~ambseal.robust.hinf.check_plant` for each).
    SynthesisError
        A plant without an H∞ controller, or none at the common γ.
    """
    th = np.asarray(theta, float)
    plants = list(plants)
    if th.ndim != 1 or th.size != len(plants) or th.size == 0 \
            or not np.all(np.isfinite(th)) or np.any(np.diff(th) <= 0):
        raise ConfigError(f"hinf_scheduled: theta {th.tolist()}: expected one strictly "
                          f"increasing value per plant ({len(plants)})")
    if not (math.isfinite(backoff) and backoff >= 1.0):
        raise ConfigError(f"hinf_scheduled: backoff={backoff!r}, expected a finite number ≥ 1")
    shapes = {(P.nstates, P.ninputs, P.noutputs) for P in plants}
    if len(shapes) != 1:
        raise ModelError(f"hinf_scheduled: the plants differ in (states, inputs, outputs): "
                         f"{sorted(shapes)}")
    sbs = []
    for P in plants:  # each regularised as hinfsyn does (ε relative to the plant's size)
        Pr = regularise_plant(P, nmeas, ncon)[0] if 0 < ncon < P.ninputs \
            and 0 < nmeas < P.noutputs else P
        check_plant(Pr, nmeas, ncon)
        sbs.append(_Sb10(Pr, nmeas, ncon))
    gopt = np.array([sb.gamma_opt(GAMMA_RTOL, confirm=False)[0] for sb in sbs])
    g = float(backoff * gopt.max())
    tables, achieved = [], []
    for sb in sbs:
        att = sb.controller(g)
        # the controller's state estimates the balanced plant's, x̃ = x / t: back to x
        t = np.asarray(sb.t, float)
        Ak, Bk, Ck, Dk = (np.asarray(M, float) for M in att.K)
        tables.append((t[:, None] * Ak / t[None, :], t[:, None] * Bk, Ck / t[None, :], Dk))
        achieved.append(att.gamma)
    P0 = plants[0]
    nw, nz = P0.ninputs - ncon, P0.noutputs - nmeas
    K = LpvController(th, *(np.stack([T[k] for T in tables]) for k in range(4)),
                      input_names=tuple(P0.output_labels[nz:]),
                      output_names=tuple(P0.input_labels[nw:]))
    return ScheduledHinfResult(K=K, gamma=g, gamma_opt=gopt, gamma_entries=np.array(achieved),
                               backoff=float(backoff))
