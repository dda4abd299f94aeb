"""LPV and frozen-speed controllers for a rig scheduled on the spin speed (thesis P3 §4).

* :func:`design_lpv` — the gridded H∞ LPV controller of :func:`ambseal.robust.lpv.lpvsyn`
  on the rig's LPV plant (:func:`ambseal.design.lpv_plant.lpv_plant`) with the weights of
  P3 Eq. 11, scheduled on Ω over the operating range (20–300 Hz for the turboexpander);
* :func:`design_frozen` — the LTI comparison controller designed at one speed (140 Hz in
  P3 Fig. 11): H∞ (:func:`ambseal.robust.hinf.hinfsyn`) on the same weights, or μ
  (:func:`ambseal.robust.dk.musyn`) with the seal's cross-coupled stiffness uncertain.

Design model (P3 §2.2): the rigid-body modes in one common modal basis (8 mechanical
states) with the first-order actuator in series (P3 Eq. 2): 12 states, plus one W_p and
one W_u state per channel: 20 states in the LMIs, and the controller's hold + computation
delay τ = (``[controller] delay_samples`` + ½)/``sample_rate_hz`` as a first-order Padé lag
on every control channel (:func:`ambseal.robust.delay.design_delay`, as the H∞ and μ
designs carry it), so that the controller is designed for the loop it will run in:
without it the flywheel's (``examples/flywheel.toml``) loses its nutation mode as it runs
at 20 kHz (benchmarks/README.md, "Where the design defaults come from"). The first bending
pair (~1 kHz) is left out of the design model, as in the thesis: the controller built
without it, rolled off by the high-pass W_u, keeps every full-order frozen loop stable
with σ̄(S_o) ≤ 3 over 20–300 Hz (checked in ``tests/control/test_control_lpv.py``).

Weights (P3 Eq. 11): W_p = (s/M + ω_B)/(s + ω_B A) with M = 2 (σ̄(S_o) ≤ Mγ ≈ 2 < 3, the
ISO 14839-3 zone-A limit), ω_B = 2π·50 rad/s (2 % settling of every spin-up step in
≈ 8–10 ms, inside the 20 ms of P3 §3.1) and **A = 1e-2** instead of the thesis' 1e-3: the
W_p pole at ω_B A sets the slowest time scale of the LMIs; 3 rad/s rather than 0.3 rad/s
keeps the SDP conditioned and costs a steady-state error of 1 % instead of 0.1 % of the
scaled disturbance (the force step's steady deflection is 1.4 % of its peak, inside the 2 %
band, so settling is not affected). W_u (P3 §3.3: "a high-pass filter with a crossover
frequency at 1.4 kHz") is derived from the rig (:mod:`ambseal.design.specs`, "LPV
weights"): on the current scaled by D_u = bias/6 (0.42 A), a low-frequency gain that keeps
the controller within 2.5× the reference PID's peak gain (0.037), rising tenfold above its
corner at the actuator bandwidth (1.5 kHz); D_e = air gap/25 (20 µm). Well above the design
bandwidth it leaves the rigid-body loop alone, but it rolls the controller off at the
bending modes left out of the design model: with a static W_u, σ̄(S_o) on the full-order
plant peaked at 4.4–6.7 there (spill-over). The turboexpander's numbers with and
without the rule: benchmarks/README.md ("Where the design defaults come from").

Poles the target can run: the synthesis bounds the controller's poles by the target's
Nyquist frequency π·``sample_rate_hz`` (``pole_bound`` of :func:`lpvsyn`). A pole above it
has no counterpart in the sampled controller (its dynamics alias), and the H∞ central
controller has such poles far outside the design band (the flywheel's at 10 kHz: a pair
at 51 MHz, others at 20 and 44 kHz, against a design model whose fastest pole is 8.3 kHz).
They are removed with their static gain kept where the reduced table holds every frozen
loop within 1 % of the synthesised H∞ norms (on the examples' LPVs no norm rose by more
than 3e-4; benchmarks/README.md); else the controller stays as synthesised and
:attr:`LpvDesign.pole_bound` says why. The discretisation then removes or keeps the poles
between half of Nyquist and Nyquist as for every design
(:mod:`ambseal.robust.digital`).
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field, replace
from typing import Any, ClassVar

import control
import numpy as np

from ambseal.design.lpv_plant import lpv_plant, vertex_grid_hz
from ambseal.design.plant import generalized_plant, physical_controller, physical_matrices
from ambseal.design.recipes import bound_text, full_order_check
from ambseal.design.specs import DesignSpec, design_spec
from ambseal.design.weights import Weights, default_weights
from ambseal.errors import ConfigError, SynthesisError
from ambseal.lti import json_float
from ambseal.machine import SPEED, ScheduledController
from ambseal.robust import (design_delay, design_omega, hinfsyn, lpvsyn, musyn, sdp_shortfall,
                            sdp_status)

__all__ = ["LpvDesign", "FrozenDesign", "axis_rotation", "design_lpv", "design_frozen",
           "lpv_generalized_plants", "check_full_order", "lpv_schedule"]

#: Mechanical states of the design model of an LPV controller on a rig whose seals follow
#: the speed (P3 §4: the rigid-body modes and their actuators)
LPV_SEAL_STATES = 8


def lpv_schedule(cfg, spec) -> tuple[tuple[float, float], int, str]:
    """The speeds an LPV controller of the rig is scheduled over and the states of its
    design model — the one rule of ``ambseal run`` and ``ambseal design --method lpv``.

    A rig whose seals follow the speed over ``[operating] speed_range_hz`` (P3 §4): that
    range, on :data:`LPV_SEAL_STATES` states. Any other: standstill to the top speed (the
    largest of the specification's stability speeds), on the specification's
    ``model_states`` — where the gyroscopic moments move the modes out of what one frozen
    design holds.

    Parameters
    ----------
    cfg : RigConfig
        The rig.
    spec : DesignSpec
        Its design specification (:func:`ambseal.design.specs.design_spec`).

    Returns
    -------
    speeds_hz : (float, float)
    states : int
    rule : str
        The rule in words.

    Raises
    ------
    ConfigError
        A rig with no speed above standstill to schedule on.
    """
    rng = cfg.operating.speed_range_hz
    if rng is not None and any(s.frequency_dependent for s in cfg.seal):
        return ((float(rng[0]), float(rng[1])), LPV_SEAL_STATES,
                "[operating] speed_range_hz, which the seals follow (P3 §4)")
    top = max(spec.stability_speeds_hz)
    if not top > 0:
        raise ConfigError("an LPV controller is scheduled on speed, and the rig runs at "
                          "standstill: set [operating] speed_rpm or speed_range_hz")
    return (0.0, float(top)), int(spec.model_states), "standstill to the top speed"

_TWO_PI = 2.0 * np.pi


@dataclass(frozen=True, eq=False)
class LpvDesign(ScheduledController):
    """A speed-scheduled controller for a rig and how it was obtained.

    Attributes
    ----------
    K : LpvController
        Scheduled controller in synthesis units (``u = K_P(Ω) y``, positive feedback);
        :meth:`controller_at` gives the physical one.
    gamma : float
        LMI γ (upper bound of the L2 gain of the LPV loop over the speed range, for every
        speed trajectory — any rate for ``"constant"``, |Ω̇| ≤ ν otherwise).
    gamma_design : float
        Back-off γ of the controller construction.
    frozen_gamma : ndarray, shape (n_p,)
        Verified H∞ γ of a frozen-point design at each grid speed (NaN if not computed).
    check_gamma : ndarray, shape (n_check,)
        H∞ norm of the frozen LPV closed loops on the check grid (the controller table).
    speeds_hz, check_speeds_hz : ndarray
        Design grid and check grid (Hz).
    lyapunov : str
    rate_bound_hz_per_s : float or None
        |Ω̇|/2π bound (Hz/s).
    weights : Weights
    reports : tuple of SolverReport
        Every SDP solve and the reconstruction (:class:`ambseal.robust.lpv.SolverReport`);
        :attr:`sdp_status` the status each stage ended on, :attr:`sdp_shortfall` those short
        of optimal in words.
    synthesis_s : float
        Wall time of :func:`lpvsyn` (s).
    elapsed_s : float
        Wall time including the model and the frozen γ (s).
    plant : LpvPlant
        The design model (not serialised).
    full_order : dict or None
        :func:`check_full_order` of the controller at the judged conditions.
    delay : DesignDelay or None
        The controller's hold + computation delay the design model carries
        (:func:`ambseal.robust.delay.design_delay`; serialised by its ``to_dict``).
    kind : str
        What :func:`lpvsyn` delivered: ``"lpv"`` (the LMIs' scheduled controller) or
        ``"frozen"`` (the best frozen-point design, better at every frozen speed).
    frozen_best_gamma : float
        That frozen-point design's worst γ on the check grid (NaN if not compared).
    pole_bound : dict or None
        The controller's poles against the target's Nyquist frequency
        (:attr:`ambseal.robust.lpv.LpvSynResult.pole_bound` in Hz): ``bound_hz``,
        ``above_hz`` (the poles above it as synthesised), ``reduced`` (removed, the
        reduced loop certified at ``gamma``) and ``note`` (why they were kept).
    """

    parameter: ClassVar[str] = SPEED
    method: ClassVar[str] = "lpv"
    K: Any = field(repr=False)
    gamma: float
    gamma_design: float
    frozen_gamma: np.ndarray = field(repr=False)
    check_gamma: np.ndarray = field(repr=False)
    speeds_hz: np.ndarray = field(repr=False)
    check_speeds_hz: np.ndarray = field(repr=False)
    lyapunov: str = "constant"
    rate_bound_hz_per_s: float | None = None
    weights: Weights = field(default_factory=lambda: default_weights("lpv"))
    reports: tuple = ()
    synthesis_s: float = 0.0
    elapsed_s: float = 0.0
    plant: Any = field(default=None, repr=False)
    full_order: dict | None = None
    delay: Any = None
    kind: str = "lpv"
    frozen_best_gamma: float = float("nan")
    pole_bound: dict | None = None

    @property
    def order(self) -> int:
        return self.K.order

    @property
    def table_theta(self) -> np.ndarray:
        """θ of the controller's table, where it is exact (SI; rad/s for the speed)."""
        return np.asarray(self.K.theta, float)

    @property
    def schedule(self) -> tuple[float, float]:
        """(Ω_min, Ω_max) of the table (rad/s)."""
        return (_TWO_PI * float(self.speeds_hz[0]), _TWO_PI * float(self.speeds_hz[-1]))

    def at(self, speed_rad_s: float, name: str = "K_lpv"):
        """Frozen physical controller at Ω (rad/s): a ``control.StateSpace``
        from displacements (m) to current references (A), negative feedback ``i = −K y``
        (:mod:`ambseal.machine.controller`; :func:`ambseal.design.plant.physical_controller`)."""
        chans = [n[2:] if n.startswith("y_") else n for n in self.K.input_names]
        return physical_controller(self.K.matrices(float(speed_rad_s)),
                                   self.weights.d_e, self.weights.d_u, chans, name=name)

    def controller_at(self, speed_hz: float, name: str = "K_lpv"):
        """:meth:`at` with the speed in Hz."""
        return self.at(_TWO_PI * float(speed_hz), name)

    def matrices_at(self, speed_rad_s: float) -> tuple[np.ndarray, ...]:
        """Physical (A_K, B_K, C_K, D_K) at Ω (rad/s), i = −(C_K x_K + D_K y)."""
        return physical_matrices(self.K.matrices(speed_rad_s), self.weights.d_e,
                                 self.weights.d_u)

    @property
    def sdp_status(self) -> dict:
        """The status each SDP stage of the synthesis ended on, ``{"gamma": "optimal",
        …}`` (:func:`ambseal.robust.sdp_status`)."""
        return sdp_status(self.reports)

    @property
    def sdp_shortfall(self) -> str:
        """The SDP stages the delivered controller was built from that ended short of
        optimal (at CVXOPT's iteration cap or stalled, their LMIs holding), in words;
        ``""`` where none did or where the delivered controller is the frozen-point design
        (``kind == "frozen"``, not built from them)."""
        return sdp_shortfall(self.reports) if self.kind == "lpv" else ""

    @property
    def controller(self) -> LpvDesign:
        """The design itself: it is the scheduled controller
        (:class:`~ambseal.design.Design`)."""
        return self

    def summary(self) -> dict:
        """:meth:`to_dict` (:class:`~ambseal.design.Design`)."""
        return self.to_dict()

    def to_dict(self) -> dict:
        """JSON-ready summary (no matrices)."""
        fg = [float(x) if np.isfinite(x) else None for x in self.frozen_gamma]
        return {"method": "lpv", "gamma": self.gamma, "gamma_design": self.gamma_design,
                "frozen_gamma": fg,
                "frozen_gamma_max": max((x for x in fg if x is not None), default=None),
                "check_gamma_max": float(np.max(self.check_gamma)),
                "speeds_hz": self.speeds_hz.tolist(), "lyapunov": self.lyapunov,
                "rate_bound_hz_per_s": self.rate_bound_hz_per_s, "order": self.order,
                "weights": self.weights.to_dict(),
                "reports": [r.to_dict() for r in self.reports],
                "synthesis_s": round(self.synthesis_s, 3),
                "elapsed_s": round(self.elapsed_s, 3), "full_order": self.full_order,
                "delay": None if self.delay is None else self.delay.to_dict(),
                "kind": self.kind, "frozen_best_gamma": json_float(self.frozen_best_gamma),
                "sdp_status": self.sdp_status, "sdp_shortfall": self.sdp_shortfall,
                "pole_bound": self.pole_bound, "verdict": self.verdict}

    @property
    def verdict(self) -> str:
        """One plain line: the LMI bound over the scheduled range (and, where an SDP it
        rests on ended short of optimal, that it is a certified bound, not the optimum,
        of a controller that depends on the machine's rounding), the frozen loops (of the
        controller with its poles above the Nyquist frequency removed, where they were),
        and the full-order stability."""
        lo, hi = float(self.speeds_hz.min()), float(self.speeds_hz.max())
        short = self.sdp_shortfall
        # no ";" inside: the run's verdict takes the bound as the line's first clause
        # short: the report's section on the syntheses says what it means
        note = f" — NOT SOLVED TO OPTIMALITY: {short}" if short else ""
        pb = self.pole_bound or {}
        removed = (f" (its {len(pb['above_hz'])} poles above the {pb['bound_hz']:.4g} Hz "
                   "Nyquist frequency removed)" if pb.get("reduced") else "")
        return (f"LPV γ = {bound_text(self.gamma)} over {lo:g}–{hi:g} Hz ({self.lyapunov} "
                f"Lyapunov function{note}), frozen loops γ ≤ "
                f"{float(np.max(self.check_gamma)):.3g}{removed}"
                f"; {_stability_over_speed(self.full_order)}")


def _pole_bound_hz(rec: dict | None) -> dict | None:
    """:attr:`ambseal.robust.lpv.LpvSynResult.pole_bound` with its frequencies in Hz."""
    if rec is None:
        return None
    return {"bound_hz": rec["bound_rad_s"] / _TWO_PI,
            "above_hz": [w / _TWO_PI for w in rec["above_rad_s"]],
            "reduced": rec["reduced"], "note": rec["note"]}


def _stability_over_speed(check: dict | None) -> str:
    """The verdict's words on :func:`check_full_order` of a design judged over speed."""
    if check is None or check["stable"]:
        return "full-order loop stable at every judged condition"
    return (f"FULL-ORDER LOOP UNSTABLE at {check['mode_hz']:.4g} Hz, {check['speed_hz']:g} Hz "
            "speed")


@dataclass(frozen=True, eq=False)
class FrozenDesign:
    """An LTI controller designed at one speed (the P3 Fig. 11 comparison).

    Attributes
    ----------
    K : control.StateSpace
        Physical controller (m → A, negative feedback ``i = −K y``).
    speed_hz : float
    method : str
        ``"hinf"`` or ``"mu"``.
    gamma : float
        Verified H∞ norm (``"hinf"``) or peak μ upper bound (``"mu"``) of the design loop.
    weights : Weights
    elapsed_s : float
    full_order : dict or None
        :func:`check_full_order` of the controller at the judged conditions.
    """

    K: control.StateSpace = field(repr=False)
    speed_hz: float
    method: str
    gamma: float
    weights: Weights = field(default_factory=lambda: default_weights("lpv"))
    elapsed_s: float = 0.0
    full_order: dict | None = None

    @property
    def controller(self) -> control.StateSpace:
        """``K`` (:class:`~ambseal.design.Design`)."""
        return self.K

    @property
    def verdict(self) -> str:
        """One plain line: the design loop's bound at its speed and the full-order
        stability."""
        bound = "H∞ γ" if self.method == "hinf" else "μ"
        return (f"{bound} = {bound_text(self.gamma)} at {self.speed_hz:g} Hz; "
                f"{_stability_over_speed(self.full_order)}")

    def summary(self) -> dict:
        """:meth:`to_dict` (:class:`~ambseal.design.Design`)."""
        return self.to_dict()

    def to_dict(self) -> dict:
        """JSON-ready summary (no matrices)."""
        return {"method": self.method, "speed_hz": self.speed_hz, "gamma": self.gamma,
                "order": int(self.K.nstates), "weights": self.weights.to_dict(),
                "elapsed_s": round(self.elapsed_s, 3), "full_order": self.full_order,
                "verdict": self.verdict}


def check_full_order(cfg, spec, controller_at, name: str, allow_unstable: bool = False
                     ) -> dict:
    """Close a speed-scheduled design with the full-order plant at every judged condition
    (``spec``'s pressures × its judged and stability speeds, standstill to the top speed,
    :func:`ambseal.design.specs.design_spec`):
    at each, the physical controller ``controller_at(speed_hz)`` that runs there
    (:func:`ambseal.design.recipes.full_order_check`), as :func:`~ambseal.design.
    recipes.design` does for H∞ and μ.

    Returns
    -------
    dict
        The least stable condition's :func:`full_order_check` dict.

    Raises
    ------
    SynthesisError
        A loop is unstable (unless ``allow_unstable``): the mode (Hz, ζ), the condition and
        the remedy (the design model keeps the rigid-body modes only, P3 §2.2).
    """

    # where it is judged and wherever the machine runs, standstill to the top speed
    checks = [full_order_check(cfg, controller_at(f), [(p, f)])
              for p in spec.pressures_bar
              for f in sorted({*spec.speeds_hz, *spec.stability_speeds_hz})]
    worst = max(checks, key=lambda c: (not c["stable"], -c["damping"]))
    if not worst["stable"] and not allow_unstable:
        raise SynthesisError(
            f"{name}: the full-order loop is unstable at {worst['pressure_bar']:g} bar, "
            f"{worst['speed_hz']:g} Hz: the mode at {worst['mode_hz']:.4g} Hz has ζ = "
            f"{worst['damping']:.3g}; the LPV design model keeps the rigid-body modes only "
            "(P3 §2.2): a mode it leaves out went unstable; raise W_u's roll-off or accept "
            "it with --allow-unstable")
    return worst


def lpv_generalized_plants(L, weights: Weights, speeds_rad_s=None, delay=None):
    """Generalised plants (P5 Figs. 8–9, nominal: inputs [d_i, d_o, u], outputs
    [z_p, z_u, y]) of the LPV plant ``L`` at its grid speeds (or ``speeds_rad_s``), with
    the controller's ``delay`` (a :class:`~ambseal.robust.delay.DesignDelay`, e.g. an
    :class:`LpvDesign`'s) on every control channel when given.

    Returns a list of :class:`ambseal.design.plant.GeneralizedPlant` in one state basis.
    """

    Wp, Wu = weights.Wp(), weights.Wu()
    W = L.speeds_rad_s if speeds_rad_s is None else np.asarray(speeds_rad_s, float)
    lag = None if delay is None else delay.system
    return [generalized_plant(L.plant_at(w), Wp, Wu, d_e=weights.d_e, d_u=weights.d_u,
                              actuator_delay=lag)
            for w in W]


def _delay(cfg, spec: DesignSpec):
    """The controller's delay as the design models carry it (the H∞ recipe's call)."""
    return design_delay(cfg.controller.sample_rate_hz, cfg.controller.delay_samples,
                        spec.synthesis_band_hz[1], max_order=1)


def axis_rotation(P) -> tuple[np.ndarray, np.ndarray] | None:
    """The 90° turn of a generalised plant's signals: each pair ``<name>_zeta``,
    ``<name>_eta`` of its inputs and of its outputs taken to (−η, ζ), the rotation about
    the spin axis that carries the ζ axis onto the η axis.

    Parameters
    ----------
    P : control.StateSpace
        Named inputs and outputs.

    Returns
    -------
    (T_u, T_y) or None
        Orthogonal maps of the inputs and of the outputs (``lpvsyn``'s ``rotation``);
        None where a signal has no ζ/η partner. Whether the plant is invariant under
        them is the synthesis's to check.
    """
    out = []
    for names in (list(P.input_labels), list(P.output_labels)):
        at = {n: k for k, n in enumerate(names)}
        T = np.zeros((len(names), len(names)))
        for k, n in enumerate(names):
            base = n[:-5] if n.endswith("_zeta") else n[:-4] if n.endswith("_eta") else None
            j = None if base is None else at.get(base + ("_eta" if n.endswith("_zeta")
                                                          else "_zeta"))
            if j is None:
                return None
            T[j, k] = 1.0 if n.endswith("_zeta") else -1.0  # ζ → η, η → −ζ
        out.append(T)
    return out[0], out[1]


def design_lpv(cfg, *, speeds_hz=None, n_grid: int | None = None,
               rate_bound_hz_per_s: float | None = None, lyapunov: str | None = None,
               weights: Weights | None = None, states: int | None = None,
               frozen_gamma: bool = True, allow_unstable: bool = False,
               spec: DesignSpec | None = None, **lpvsyn_kw) -> LpvDesign:
    """Speed-scheduled H∞ LPV controller for a rig (thesis P3 §4).

    Parameters
    ----------
    cfg : ambseal.config.RigConfig
        The rig (the turboexpander: ``examples/turboexpander.toml``).
    speeds_hz : (float, float), optional
        Speed range (Hz) to schedule on. Default: :func:`lpv_schedule`'s, the one
        ``ambseal run`` and ``ambseal design --method lpv`` use (``[operating]
        speed_range_hz`` on a rig whose seals follow the speed, as in P3 §4; else
        standstill to the top speed).
    n_grid : int, optional
        Design grid points, equally spaced over the range (≥ 2). Default: with a constant
        Lyapunov function the vertex grid (:func:`ambseal.design.lpv_plant.vertex_grid_hz`:
        the range's ends and the seal-table points inside it), on which the LMIs hold at
        every speed of the range (A(Ω) is piecewise affine between them); with a
        parameter-dependent one (no such guarantee: S(Ω) multiplies A(Ω)) 10 points.
        On the vertex grid the controller table is the grid itself (``check_density``
        1): with R, S constant the linearised closed-loop LMI of the reconstruction
        (Scherer, Gahinet & Chilali 1997) is affine in (A, Â, B̂, Ĉ) and A_K, B_K, C_K are
        affine in them (M = I, N = I − S R), so the controller interpolated linearly
        between two table speeds is the one of the interpolated variables and meets the
        reconstruction's γ at every speed in between (turboexpander: frozen H∞ norm ≤ 1.080
        at 54 speeds between the 7 table speeds, bound 1.02·γ_d = 1.178).
    rate_bound_hz_per_s : float, optional
        |Ω̇|/2π bound (Hz/s): with it the Lyapunov function S(Ω) is parameter dependent
        (``lyapunov`` defaults to ``"affine"``); without it constant (P3).
    lyapunov : str, optional
        ``"constant"``, ``"affine"`` or ``"quadratic"``; see :func:`lpvsyn`.
    weights : Weights, optional
        The rig's ``[design.lpv]`` weights completed by the specification's rules if
        omitted (module docstring).
    states : int, optional
        Mechanical states of the design model (8: rigid body; 12 adds the first bending
        pair). Default: :func:`lpv_schedule`'s (:data:`LPV_SEAL_STATES` where the seals
        follow the speed, else the specification's ``model_states``).
    frozen_gamma : bool
        Also compute the frozen-point H∞ γ at each grid speed (a lower bound of the LPV γ).
    allow_unstable : bool
        Keep a controller whose full-order loop is unstable at a judged condition
        (:func:`check_full_order`) instead of raising.
    spec : DesignSpec, optional
        The rig's design specification (weights, judged conditions); built from ``cfg``
        by :func:`~ambseal.design.specs.design_spec` when omitted.
    **lpvsyn_kw
        Passed to :func:`ambseal.robust.lpv.lpvsyn` (``backoff``, ``solver_options``, …).
        ``rotation`` defaults to the 90° turn of the plant's ζ and η signals
        (:func:`axis_rotation`): on a rotor the same in both, R and S are sought among the
        matrices that turn leaves invariant, half the unknowns.

    Returns
    -------
    LpvDesign

    Raises
    ------
    ConfigError
        Neither range nor states given and the rig runs at standstill
        (:func:`lpv_schedule`).
    SynthesisError
        From :func:`lpvsyn`: one grid point, a rate bound with a constant Lyapunov
        function, infeasible LMIs, an inaccurate solver status, an unstable frozen loop;
        an unstable full-order loop at a judged condition (:func:`check_full_order`).
    ModelError
        A bad speed range (negative, not increasing).

    Examples
    --------
    >>> from ambseal.config import load_rig
    >>> d = design_lpv(load_rig("examples/turboexpander.toml"))   # doctest: +SKIP
    >>> K = d.controller_at(140.0)                                 # doctest: +SKIP
    """

    t0 = time.perf_counter()
    sp = spec or design_spec(cfg)
    w = weights or sp.weights["lpv"]
    if speeds_hz is None or states is None:  # the run's rule, not one of its own
        rule_speeds, rule_states, _ = lpv_schedule(cfg, sp)
        speeds_hz = rule_speeds if speeds_hz is None else speeds_hz
        states = rule_states if states is None else states
    lo, hi = (float(x) for x in speeds_hz)
    if lyapunov is None:
        lyapunov = "constant" if rate_bound_hz_per_s is None else "affine"
    if n_grid is None and lyapunov == "constant":
        grid = vertex_grid_hz(cfg, (lo, hi))
        # the controller on the vertex grid itself, linear in between: exact (docstring)
        lpvsyn_kw.setdefault("check_density", 1)
    else:
        n_grid = 10 if n_grid is None else int(n_grid)
        if n_grid < 2:
            raise SynthesisError(f"design_lpv: n_grid={n_grid}; the speed grid needs at "
                                 "least 2 points")
        grid = np.linspace(lo, hi, n_grid)
    nu = None if rate_bound_hz_per_s is None else _TWO_PI * float(rate_bound_hz_per_s)
    L = lpv_plant(cfg, grid, states=states)
    dl = _delay(cfg, sp)
    gps = lpv_generalized_plants(L, w, delay=dl)
    P = [g.P_nominal for g in gps]
    nmeas, ncon = gps[0].nmeas, gps[0].ncon
    # dA/dΩ of the generalised plant: the weights do not depend on Ω
    n, N = L.n_states, P[0].nstates
    dA = np.zeros((grid.size, N, N))
    dA[:, :n, :n] = L.dA
    fg = np.full(grid.size, np.nan)
    if frozen_gamma:
        fg = np.array([hinfsyn(p, nmeas, ncon).gamma for p in P])
    # the target cannot run a pole above its Nyquist frequency: the sampled controller
    # aliases it (module docstring, "Poles the target can run")
    lpvsyn_kw.setdefault("pole_bound", np.pi * cfg.controller.sample_rate_hz)
    # R and S centred at the backed-off γ (lpvsyn's stage 2): the γ stage alone leaves the
    # controller where CVXOPT stopped near the LMIs' boundary, which the BLAS kernels'
    # rounding moves (the flywheel's LPV at 10 kHz: other poles, and a sampled loop no
    # discretisation held, under other kernels); centred, those of two kernel sets and two
    # Pythons agree to 0.5 % of their gain (benchmarks/README.md), at 1.6–2.4× the
    # synthesis time
    lpvsyn_kw.setdefault("centre", True)
    # a rotor the same in ζ and η: the SDPs on the matrices a 90° turn leaves invariant,
    # half the unknowns (lpvsyn's `rotation`), where the plant keeps that symmetry
    lpvsyn_kw.setdefault("rotation", axis_rotation(P[0]))
    r = lpvsyn(P, L.speeds_rad_s, nmeas, ncon, dA=dA, lyapunov=lyapunov, rate_bound=nu,
               **lpvsyn_kw)
    d = LpvDesign(K=r.K, gamma=r.gamma, gamma_design=r.gamma_design, frozen_gamma=fg,
                  check_gamma=r.check_gamma, speeds_hz=grid,
                  check_speeds_hz=r.check_grid / _TWO_PI, lyapunov=lyapunov,
                  rate_bound_hz_per_s=None if nu is None else float(rate_bound_hz_per_s),
                  weights=w, reports=r.reports, synthesis_s=r.time_s, plant=L,
                  delay=dl, kind=r.kind, frozen_best_gamma=r.frozen_best_gamma,
                  pole_bound=_pole_bound_hz(r.pole_bound))
    check = check_full_order(cfg, sp, d.controller_at, "lpv", allow_unstable)
    return replace(d, full_order=check, elapsed_s=time.perf_counter() - t0)


def design_frozen(cfg, speed_hz: float | None = None, *, method: str = "hinf",
                  weights: Weights | None = None, states: int = 8,
                  seal_k_uncertainty: float = 0.4, allow_unstable: bool = False,
                  spec: DesignSpec | None = None, **kw) -> FrozenDesign:
    """LTI controller at one speed: the comparison controller of P3 Fig. 11 (designed at
    the operating speed, 140 Hz on the thesis's turboexpander).

    Parameters
    ----------
    cfg : RigConfig
        The rig (its ``[design.lpv]`` weights and its seal).
    speed_hz : float, optional
        Design speed (Hz); default the rig's operating speed.
    method : {"hinf", "mu"}
        ``"hinf"``: :func:`hinfsyn` on the nominal plant with the LPV weights (the same
        performance demand as the LPV design, so the comparison isolates the scheduling).
        ``"mu"``: D–K iteration (:func:`musyn`) with the seal's k ± ``seal_k_uncertainty``
        (P3 §3.1: ±40 %); a few seconds per D–K iteration on the turboexpander.
    weights : Weights, optional
        The rig's ``[design.lpv]`` weights completed by the specification's rules if
        omitted (module docstring).
    states : int
        Mechanical states of the design model (same basis as :func:`design_lpv`).
    seal_k_uncertainty : float
        Relative uncertainty of the first seal's cross-coupled stiffness k (``"mu"`` only;
        0.4: ±40 %, P3 §3.1).
    allow_unstable : bool
        Keep a controller whose full-order loop is unstable at a judged condition
        (:func:`check_full_order`) instead of raising.
    spec : DesignSpec, optional
        The rig's design specification (weights, judged conditions, the μ grid's band);
        built from ``cfg`` by :func:`~ambseal.design.specs.design_spec` when omitted.
    **kw
        Passed to :func:`musyn` (``max_iter``, ``order``, ``omega``).

    Returns
    -------
    FrozenDesign

    Raises
    ------
    ConfigError
        Unknown method; ``"mu"`` on a rig without a seal.
    SynthesisError
        From the synthesis; an unstable full-order loop at a judged condition
        (:func:`check_full_order`).
    """

    if method not in ("hinf", "mu"):
        raise ConfigError(f"design_frozen: method={method!r}, expected 'hinf' or 'mu'")
    t0 = time.perf_counter()
    sp = spec or design_spec(cfg)
    w = weights or sp.weights["lpv"]
    f = float(cfg.operating.speed_rpm / 60.0 if speed_hz is None else speed_hz)
    if method == "hinf":
        L = lpv_plant(cfg, [f, f + 1.0], states=states, reference_speed_hz=f)
        gp = lpv_generalized_plants(L, w, [_TWO_PI * f], delay=_delay(cfg, sp))[0]
        r = hinfsyn(gp.P_nominal, gp.nmeas, gp.ncon)
        K_P, gamma = r.K, float(r.gamma)
    else:
        if not getattr(cfg, "seal", None):
            raise ConfigError("design_frozen(method='mu'): the uncertain parameter is the "
                              "seal's k, but the rig has no [[seal]]")
        # the rig at the design speed (RigConfig is frozen: copy with the speed updated)
        cfg_f = cfg.model_copy(update={
            "operating": cfg.operating.model_copy(update={"speed_rpm": 60.0 * f})})
        gp = generalized_plant(cfg_f, w.Wp(), w.Wu(), states=states,
                               uncertainty={f"{cfg.seal[0].name}.k": seal_k_uncertainty},
                               d_e=w.d_e, d_u=w.d_u, actuator_delay=_delay(cfg, sp).system)
        om = kw.pop("omega", None)
        if om is None:  # the specification's synthesis band: modes at the operating speed
            om = design_omega(*sp.synthesis_band_hz)
        r = musyn(gp.P, gp.blocks, gp.nmeas, gp.ncon, om, **kw)
        K_P, gamma = r.K, float(r.mu)
    K = gp.physical_controller(K_P, name=f"K_{method}_{f:g}Hz")
    check = check_full_order(cfg, sp, lambda _: K, f"{method} at {f:g} Hz", allow_unstable)
    return FrozenDesign(K=K, speed_hz=f, method=method, gamma=gamma, weights=w,
                        elapsed_s=time.perf_counter() - t0, full_order=check)
