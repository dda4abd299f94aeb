"""The spin speed Ω as a real parameter of the design model's LFT.

A rotor's plant changes with its spin speed through the gyroscopic term Ω·G (and through
seal coefficients tabulated against the synchronous frequency). On the design model — the
modal reduction at the design speed, thesis P1 §III.4–6 — the change is

    A(Ω) = A(Ω₀) + (Ω − Ω₀)·A₁,    A₁ = T_L [[0, 0], [0, −M⁻¹G]] T_R

(thesis P3 Eqs. 4–10: the LPV model of :func:`ambseal.design.lpv_plant.lpv_plant`, in the
same basis). Written as an LFT channel of rank r = rank A₁ (A₁ = B_Ω C_Ω by its singular
value decomposition), Ω is one real parameter repeated r times, like a seal's k (thesis P1
Eqs. 46–52). With Ω uncertain over standstill to the top speed, a μ design whose bound is
below 1 holds every plant of the speed range; an H∞ design on the same generalised plant,
at constant D scalings of the speed channel, does where its γ is below 1, by the
small-gain theorem (the D-scaled upper
bound of μ: Packard & Doyle, "The complex structured singular value", Automatica 29(1),
1993).

Frequency-tabulated seal coefficients change along the speed range too; they enter by the
secant of A(Ω) over the range, which equals A₁ where A is affine in Ω (no tabulated seal).
Every design is judged on the full-order plant at each judged speed all the same
(:func:`ambseal.design.recipes.full_order_check`).
"""

from __future__ import annotations

from dataclasses import replace

import control
import numpy as np
from scipy.optimize import linear_sum_assignment

from ambseal.design.modal_bands import TRACK_POINTS
from ambseal.design.specs import RIGID_STATES
from ambseal.errors import ModelError
from ambseal.model import (
    Parameter, Plant, build_system, mechanical_plant, modal_reduction, poles_near_zero,
    reduction_size,
)

__all__ = ["SPEED", "at_speed", "whole_pair_states", "with_speed"]

_TWO_PI = 2.0 * np.pi

#: The LFT parameter's name (rad/s).
SPEED = "rotor.speed"

#: Singular values of A₁ below this fraction of the largest are left out of the channel:
#: they change A by less than 1e-4 of what the gyroscopic term changes over the range
#: (the projected term of the design models measured falls by four decades after its
#: conical and bending pairs), and each kept one is a repeat of the real block.
RANK_TOL = 1e-4


#: Eigenvalues at standstill this close (relative to |λ|) are one whirl pair: an
#: axisymmetric rotor's ζ and η modes repeat, up to the eigensolver's rounding.
PAIR_RTOL = 1e-6

#: A pole of the next tracked speed is the same mode's only where it moved by less than
#: this share of |λ| in one step (1/30 of the range), or by less than :data:`GYRO_RATIO`
#: times the step in Ω; a pole farther off has entered the tracked disk from outside it
#: and starts a mode of its own.
STEP_RTOL = 0.25

#: The most a whirl frequency moves per unit of spin speed: a thin disc's Ip/It is 2
#: (the perpendicular-axis theorem), and its forward conical whirl tends to Ip/It·Ω.
GYRO_RATIO = 2.0


def whole_pair_states(cfg, states: int, *, pressure_bar: float) -> int:
    """The largest count of the design model's states, at most ``states``, that keeps each
    whirl pair whole over the speed range.

    A rotor's ζ and η modes at standstill are one pair of equal |λ|; the gyroscopic
    moments split it with speed, the forward whirl up and the backward whirl down. The
    design model at the design speed keeps the lowest ``states`` by |λ| there, and a
    cut-off between the two branches keeps the backward one and drops its forward twin.
    With the speed an LFT parameter (:func:`with_speed`), A₁ then moves a branch whose twin
    is missing: its singular values no longer come in equal pairs, the speed channel's
    scalings cannot be tied pairwise, and the model cannot represent the pair's split.
    Measured (benchmarks/README.md, "Whole whirl pairs in the speed-range design model"):
    two rigs of the generated family hold over the speed range only on whole pairs; the
    expander-generator example's μ holds only on its split model, so whole pairs are the
    second try (:func:`ambseal.design.recipes.design`).

    The rule: the rig's eigenvalues are followed from standstill to the design speed
    (``cfg``'s ``[operating] speed_rpm``) on
    :data:`~ambseal.design.modal_bands.TRACK_POINTS` speeds, each matched to its nearest
    at the next speed (a move beyond :data:`STEP_RTOL` of |λ| and :data:`GYRO_RATIO` times
    the step in Ω starts a mode of its own); the eigenvalues of equal |λ| at standstill
    (:data:`PAIR_RTOL`) are a group. The count kept is the largest k ≤
    ``states`` whose k lowest eigenvalues at the design speed hold every group they touch
    whole and do not end inside a tie of |λ|; ``states`` where none of at least
    :data:`~ambseal.design.specs.RIGID_STATES` does, and on a rig whose supports make
    no pair repeat at standstill (each group one eigenvalue).

    Parameters
    ----------
    cfg : RigConfig
        The rig at the design speed.
    states : int
        The design model's mechanical states at the design speed (its cut-off's count).
    pressure_bar : float
        The seals' pressure drop (bar) the design model is built at.

    Returns
    -------
    int
        The count, ``RIGID_STATES ≤ k ≤ states`` or ``states``.

    Raises
    ------
    ModelError
        A rig whose eigenvalues cannot be found (its mass matrix not positive definite).
    """
    f0 = cfg.operating.speed_rpm / 60.0
    if f0 <= 0 or states <= RIGID_STATES:
        return int(states)
    count = 2 * int(states) + RIGID_STATES  # a partner leaving the kept set is followed out
    step = _TWO_PI * f0 / (TRACK_POINTS - 1)

    def lowest(f_hz: float) -> np.ndarray:
        return poles_near_zero(build_system(cfg, pressure_bar=pressure_bar,
                                            speed_rpm=60.0 * f_hz), count=count).poles[:count]

    lam = lowest(0.0)
    mag = np.abs(lam)
    label = np.cumsum(np.r_[0, np.diff(mag) > PAIR_RTOL * mag[1:]])
    size = dict(zip(*np.unique(label, return_counts=True)))  # group → its eigenvalues
    fresh = int(label[-1]) + 1  # the next unused label
    for f in np.linspace(0.0, f0, TRACK_POINTS)[1:]:
        nxt = lowest(f)
        rows, cols = linear_sum_assignment(np.abs(lam[:, None] - nxt[None, :]))
        moved = np.abs(lam[rows] - nxt[cols]) <= np.maximum(
            STEP_RTOL * np.abs(nxt[cols]), GYRO_RATIO * step)
        new = np.arange(fresh, fresh + nxt.size)  # a mode of its own unless matched
        new[cols[moved]] = label[rows[moved]]
        size.update((int(x), 1) for x in new if x >= fresh)
        lam, label, fresh = nxt, new, fresh + nxt.size
    mag = np.abs(lam)  # sorted by |λ| (poles_near_zero)
    for k in range(min(int(states), lam.size - 1), RIGID_STATES - 1, -1):
        kept, n_kept = np.unique(label[:k], return_counts=True)
        whole = all(size[int(x)] == c for x, c in zip(kept, n_kept))
        if whole and mag[k] - mag[k - 1] > PAIR_RTOL * mag[k]:
            return k
    return int(states)


def with_speed(plant: Plant, cfg, *, range_hz: tuple[float, float],
               states: int | None, pressure_bar: float,
               force_positions: tuple[float, ...] = ()) -> tuple[Plant, dict]:
    """The design model with the spin speed as a real LFT parameter.

    Parameters
    ----------
    plant : ambseal.model.lft.Plant
        The design model: :func:`ambseal.model.rig.build_plant` of ``cfg`` reduced to
        ``states`` at ``pressure_bar`` with ``force_positions``, at the rig's
        ``[operating] speed_rpm`` (the design speed).
    cfg : RigConfig
        The rig at the design speed.
    range_hz : (float, float)
        The speed range the design holds (Hz), low < high.
    states : int or None
        Mechanical states of the design model (None: the rig's default,
        :func:`ambseal.model.rig.reduction_size`).
    pressure_bar : float
        Its pressure drop (bar).
    force_positions : tuple of float
        Its force inputs' positions (m).

    Returns
    -------
    plant : Plant
        The same A, B, C, D and a parameter :data:`SPEED` (rad/s, nominal the design
        speed) repeated as often as A₁ has singular values above :data:`RANK_TOL`.
    ranges : dict
        ``{SPEED: (2π·low, 2π·high)}`` for :func:`ambseal.design.plant.generalized_plant`.

    Raises
    ------
    ModelError
        A range that is not increasing or below zero; a design model that is not the
        rig's modal reduction (a plant built otherwise).
    """
    lo, hi = (float(x) for x in range_hz)
    if not (0.0 <= lo < hi and np.isfinite(hi)):
        raise ModelError(f"with_speed: speed range {lo}–{hi} Hz, expected 0 ≤ low < high")
    fpos = tuple(force_positions)
    # the design model's own reduction (build_plant's arguments), for its basis T_L, T_R
    red = modal_reduction(mechanical_plant(build_system(
        cfg, pressure_bar=pressure_bar, force_positions=fpos)), **reduction_size(cfg, states))
    nr = red.plant.A.shape[0]
    if not np.allclose(red.plant.A, plant.A[:nr, :nr], rtol=0.0,
                       atol=1e-9 * np.abs(plant.A).max()):
        raise ModelError("with_speed: the design model is not the rig's modal reduction at "
                         f"{cfg.operating.speed_rpm:g} rpm and {pressure_bar:g} bar")

    def full_a(f_hz: float) -> np.ndarray:
        return build_system(cfg, pressure_bar=pressure_bar, speed_rpm=60.0 * f_hz,
                            force_positions=fpos).state_matrices()[0]

    # the secant over the range: A₁ itself where A is affine in Ω; the actuator's states,
    # after the mechanical ones, do not change with Ω
    A1 = np.zeros_like(plant.A)
    A1[:nr, :nr] = red.T_L @ ((full_a(hi) - full_a(lo)) / (_TWO_PI * (hi - lo))) @ red.T_R
    U, s, Vt = np.linalg.svd(A1)
    r = int(np.sum(s > RANK_TOL * s[0])) if s.size and s[0] > 0 else 0
    if r == 0:
        return plant, {}
    root = np.sqrt(s[:r])
    params = dict(plant.parameters)
    params[SPEED] = Parameter(SPEED, cfg.speed, "rad/s", B=U[:, :r] * root,
                              C=root[:, None] * Vt[:r], D=np.zeros((r, plant.B.shape[1])))
    return replace(plant, parameters=params), {SPEED: (_TWO_PI * lo, _TWO_PI * hi)}


def at_speed(gp, speed_rad_s: float):
    """The generalised plant frozen at a spin speed: its speed channel closed,
    ``F_u(P, δ·I_r)`` with δ the speed's normalised value (thesis P1 Eqs. 46–52).

    Parameters
    ----------
    gp : GeneralizedPlant
        A generalised plant with the :data:`SPEED` LFT parameter
        (:func:`ambseal.design.plant.generalized_plant` with ``speed_range_hz``); its
        other parameters (μ's uncertain ones) stay channels of the frozen plant.
    speed_rad_s : float
        Ω (rad/s), within the parameter's range.

    Returns
    -------
    control.StateSpace
        ``gp.P`` without the speed's r channels: the same states (one state basis at
        every speed) and the other channels' names, in their order.

    Raises
    ------
    ModelError
        No speed parameter, or Ω outside its range.
    """
    names = [q.name for q in gp.parameters]
    if SPEED not in names:
        raise ModelError(f"at_speed: the generalised plant has no {SPEED!r} LFT parameter "
                         f"({names})")
    k = names.index(SPEED)
    q = gp.parameters[k]
    delta = q.delta(float(speed_rad_s))
    if not -1.0 - 1e-9 <= delta <= 1.0 + 1e-9:
        raise ModelError(f"at_speed: {speed_rad_s:g} rad/s lies outside the speed range "
                         f"{q.low:g}–{q.high:g} rad/s")
    P = gp.P
    first = sum(p.repeats for p in gp.parameters[:k])
    sp = np.arange(first, first + q.repeats)  # the speed's channels, in and out alike
    o_in = np.setdiff1d(np.arange(P.ninputs), sp)
    o_out = np.setdiff1d(np.arange(P.noutputs), sp)
    A, B, C, D = (np.asarray(M, float) for M in (P.A, P.B, P.C, P.D))
    # w_Δ = δ z_Δ: solved for the loop through D_ΔΔ
    M = delta * np.linalg.inv(np.eye(q.repeats) - delta * D[np.ix_(sp, sp)])
    Bs, Cs = B[:, sp], C[sp]
    return control.ss(A + Bs @ M @ Cs, B[:, o_in] + Bs @ M @ D[np.ix_(sp, o_in)],
                      C[o_out] + D[np.ix_(o_out, sp)] @ M @ Cs,
                      D[np.ix_(o_out, o_in)] + D[np.ix_(o_out, sp)] @ M @ D[np.ix_(sp, o_in)],
                      inputs=[str(n) for n in np.asarray(P.input_labels)[o_in]],
                      outputs=[str(n) for n in np.asarray(P.output_labels)[o_out]],
                      states=list(P.state_labels), name=P.name)
