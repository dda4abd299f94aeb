"""Controller design for a rig: the reference PID, nominal H∞ and robust μ (thesis P5 §4).

``design(cfg, method)`` builds the design model (the modal reduction of the rig with the
actuator in series, P5 §3.1.4 and Fig. 8), the generalised plant of
:mod:`ambseal.design.plant` with the weights of :mod:`ambseal.design.weights`, and
synthesises:

* ``"pid"`` — the decentralised reference PID of ``[controller.pid]`` (P5 Eq. 6, §4.2);
* ``"hinf"`` — H∞ on the nominal plant at ``pressure_bar`` (P5 §4.4: "designed using the
  nominal plant representation");
* ``"mu"`` — μ synthesis on the perturbed plant with the uncertain parameters of
  the design specification (default: every seal's cross-coupled stiffness k ± 100 % of its
  value at ``pressure_bar``, one δ shared by k and −k, P5 §4.1 items 2–3, i.e. 0 … 2× the
  nominal pressure drop); the unbalance force (ISO 21940-11, P5 §4.4.1) enters as a
  weighted disturbance so that the worst-case orbit is part of the robust-performance
  demand (:meth:`~ambseal.design.weights.Weights.Wf`). The parameters are real: by
  default D–G–K (:func:`~ambseal.robust.dgk.musyn_dgk`, Young 1996) keeps them real in the
  synthesis; ``[design.mu] iteration = "dk"`` uses complex D–K
  (:func:`~ambseal.robust.dk.musyn`) alone.

Every default (weights, scalings, design model, grid, order limit, uncertainty) comes from
the rig's ``[design]`` part, completed from the machine by
:func:`ambseal.design.specs.design_spec`.

Every controller is returned in the project's convention: a continuous
``control.StateSpace`` from the displacements (m) to the current references (A), used in
negative feedback ``i = −K y`` (:mod:`ambseal.analysis.loops`). Synthesis itself works on
the scaled plant with the LFT's positive feedback ``u = K_P e``; the conversion
``K = −(D_u/D_e) K_P`` is :meth:`GeneralizedPlant.physical_controller`.

The design model carries the digital controller's hold + computation delay,
τ = (``[controller] delay_samples`` + ½)/``sample_rate_hz`` (150 µs on the test rig), as a
first-order Padé lag on every control channel (:mod:`ambseal.robust.delay`): first order
because its pole, 2/τ (2.1 kHz), must stay below half of Nyquist, above which controller
poles are removed before discretisation (a second-order lag's poles, √12/τ = 3.7 kHz,
came back as controller poles and were removed); its phase is within 0.5° of the delay's
up to 500 Hz and 3.5° up to 1 kHz. The full-order check below closes the loop with it.

Design model versus judgement: the design model keeps every mode the controller can reach
(the specification's rule; on the test rig the rigid-body modes and the first bending pair,
12 states). After synthesis the controller is closed with the full-order plant at every
judged condition (:func:`full_order_check`); an unstable loop enlarges the design model to
keep the mode that went unstable, or, where the model keeps that mode, lowers its damping
in the design model by a margin the controller must add (:func:`margin_for`), and designs
again, a bounded number of times, each step reported; it is refused as a
:class:`~ambseal.errors.SynthesisError` naming the mode and the key to set if it stays
unstable (unless ``allow_unstable``).
"""

from __future__ import annotations

import copy
import json
import re
import time
from dataclasses import dataclass, field, replace
from functools import partial
from typing import Any, Mapping

import control
import numpy as np

from ambseal.config import method_names
from ambseal.design.modal_bands import bands_near, mode_bands
from ambseal.design.pid import pid_of, reference_pid, scheduled_pid
from ambseal.design.plant import (
    LIGHT_DAMPING,
    MARGIN_BAND,
    generalized_plant,
    less_damped,
)
from ambseal.design.specs import ORBIT_PER_DE, design_spec, design_states_at
from ambseal.design.speed_lft import at_speed, whole_pair_states
from ambseal.design.speed_schedule import frozen_structure, mu_by_speed, schedule_hinf
from ambseal.design.weights import Weights
from ambseal.errors import ConfigError, ModelError, SynthesisError
from ambseal.lti import lft_lower
from ambseal.lti.freqresp import freqresp
from ambseal.machine import frozen, judged_loop, table_grid
from ambseal.model import build_plant, build_system, channel_names, poles_near_zero
from ambseal.robust import (
    LEVEL_FLOOR,
    LEVEL_RTOL,
    design_delay,
    design_omega,
    discretize_as,
    hinfsyn,
    loop_delay,
    musyn,
    musyn_dgk,
    performance_level,
    reduce_controller,
    result_scalings,
    scaled_hinfsyn,
    scaled_performance,
    unstable_poles,
    w_plane_plant,
    with_delay,
)
from ambseal.threads import with_numerics_threads

__all__ = ["DesignResult", "design", "full_order_check", "full_order_words", "bound_text"]

#: A design's μ within this share of 1 lies on the robust-performance boundary, and its
#: verdict names both sides: the tolerance stated for a delivered μ (benchmarks/README.md,
#: "bench_tolerances.py"), above what the machine's rounding moves a D–G–K design by where
#: its scalings are refined by the minimax (benchmarks/README.md, "D–G–K's refinement
#: amplifies rounding"). Within it, "met" and "NOT met" would follow the machine the
#: design ran on; a design whose D–G–K path parts further is beyond this rule.
MU_BOUNDARY_RTOL = 0.02

#: The automatic controller order keeps μ (H∞: γ) of the design loop within this fraction
#: of the full-order controller's (:func:`design`, ``reduce_to="auto"``): half the
#: tolerance stated for a delivered μ and γ. Which order is first inside the band is a
#: step function of μ, so on either side of its edge two machines whose full-order
#: designs differ by rounding take different orders; a band no wider than half the
#: tolerance keeps the μ either delivers within the tolerance of the other. At 10 % the
#: overhung compressor's delivered μ moved 7.4 % when its full-order μ moved 0.9 %
#: (benchmarks/README.md, "The controller order within half μ's tolerance").
ORDER_RISE = MU_BOUNDARY_RTOL / 2


@dataclass(frozen=True, eq=False)
class DesignResult:
    """A designed controller and how it was obtained (a :class:`~ambseal.design.Design`).

    Attributes
    ----------
    method : str
        ``"pid"``, ``"hinf"`` or ``"mu"``.
    K : control.StateSpace
        Continuous controller, inputs ``y_<axis>`` (m), outputs ``u_<axis>`` (A), negative
        feedback ``i = −K y``.
    pressure_bar : float
        Design (nominal) pressure drop (bar).
    gamma : float or None
        Verified H∞ norm of the (nominal, or best D-scaled) closed loop (-).
    mu : float or None
        Peak μ upper bound of ``F_l(P, K_P)`` on the design grid (μ design only).
    order : int
        States of ``K``.
    order_full : int
        States before order reduction.
    history : tuple of dict
        D–K / D–G–K iterations (``iteration``, ``gamma``, ``mu``, ``order``; with D–G–K
        also ``step``); empty otherwise.
    weights : Weights or None
    uncertainty : dict
        ``{parameter: (low, high)}`` in SI units.
    elapsed_s : float
        Wall time of the synthesis (s).
    reduction : dict or None
        :class:`~ambseal.robust.order.ReductionResult` summary when reduced; with D–G–K
        also ``candidates`` (its controller's and complex D–K's μ before and after the
        reduction) and ``kept`` (the step whose reduced controller has the lower μ).
    plant : GeneralizedPlant or None
        The generalised plant (not serialised).
    design_states : int
        Mechanical states of the design model the controller was made on.
    full_order : dict or None
        :func:`full_order_check` of the delivered controller.
    scheduled : ScheduledPid or None
        The PID scheduled on speed (its cross gains ∝ Ω), of which ``K`` is the one at
        ``[operating] speed_rpm``; None for a fixed controller (not serialised).
    kept_unstable : bool
        True when the design's own full-order loop is unstable and it was returned all
        the same because the caller passed ``allow_unstable`` (the main job does, so that
        its judgement can mark the design failed); not the user's flag.
    delay : dict or None
        The controller's hold + computation delay the design model carries
        (:meth:`ambseal.robust.delay.DesignDelay.to_dict`; on the sampled plant, exact:
        ``delay_s`` ≈ (delay_samples + ½)/rate and ``sampled``, the rate and the delay in
        samples); None for the PID.
    steps : tuple of str
        The automatic design-loop steps taken (model enlargements, damping margins).
    omega : ndarray or None
        The μ design's frequency grid (rad/s), on which its μ is stated (not serialised);
        None for H∞ and the PID.
    notes : tuple of str
        The specification's notes (no seal, ...).
    design_speed_hz : float or None
        The speed (Hz) an H∞ or μ design over the speed range was designed at, where the
        design at ``[operating] speed_rpm`` lost the rotor at another judged speed
        (:func:`design`); None for a design at the operating speed.
    speed_range_hz : (float, float) or None
        The speed range (Hz) over which an H∞ or μ design took the spin speed as an
        uncertain parameter of its LFT (:mod:`ambseal.design.speed_lft`), where the design
        at ``[operating] speed_rpm`` alone lost the rotor at another judged speed; None
        otherwise.
    synthesis_plant : {"continuous", "sampled"}
        The plant H∞ or μ was synthesised on (``[design] synthesis_plant``): ``"sampled"``,
        the sampled, delayed design model in the w-plane (:mod:`ambseal.robust.w_plane`),
        ``K`` the w-plane controller whose Tustin transform is the discrete design;
        ``"continuous"`` for every other design.
    stopping : dict or None
        Why the synthesis stopped: μ, the rule that ended each phase, its iterations and
        the D search's γ evaluations (:attr:`ambseal.robust.dk.MusynResult.stopping`);
        H∞, ``hinf``: SB10AD calls and the tolerance; None for the PID.
    verdict : str
        One plain line: robust performance met or not (H∞: γ), and the full-order
        stability; the PID's says it has no design bound (it is given, not synthesised),
        the full-order stability added where it is checked
        (:func:`ambseal.app.commands.design_files`).
    """

    method: str
    K: control.StateSpace = field(repr=False)
    pressure_bar: float
    gamma: float | None = None
    mu: float | None = None
    order: int = 0
    order_full: int = 0
    history: tuple = ()
    weights: Weights | None = None
    uncertainty: dict = field(default_factory=dict)
    elapsed_s: float = 0.0
    reduction: dict | None = None
    plant: Any = field(default=None, repr=False)
    design_states: int | None = None
    full_order: dict | None = None
    kept_unstable: bool = False
    delay: dict | None = None
    steps: tuple = ()
    notes: tuple = ()
    verdict: str = ""
    omega: Any = field(default=None, repr=False)
    stopping: dict | None = None
    scheduled: Any = field(default=None, repr=False)
    design_speed_hz: float | None = None
    speed_range_hz: tuple | None = None
    synthesis_plant: str = "continuous"

    @property
    def controller(self):
        """The controller that runs (:class:`~ambseal.design.Design`): ``scheduled`` where
        the design is scheduled on speed (a PID's cross gains, :class:`ScheduledPid`),
        else ``K``."""
        return self.K if self.scheduled is None else self.scheduled

    def summary(self) -> dict:
        """Short JSON-ready summary (no matrices)."""
        return {"method": self.method, "pressure_bar": self.pressure_bar, "gamma": self.gamma,
                "mu": self.mu, "order": self.order, "order_full": self.order_full,
                "elapsed_s": round(self.elapsed_s, 3),
                "weights": self.weights.to_dict() if self.weights else None,
                "uncertainty": {k: list(v) for k, v in self.uncertainty.items()},
                "iterations": len(self.history), "reduction": self.reduction,
                "design_states": self.design_states, "full_order": self.full_order,
                "kept_unstable": self.kept_unstable, "delay": self.delay,
                "steps": list(self.steps),
                "notes": list(self.notes), "verdict": self.verdict,
                "stopping": self.stopping,
                "speed_range_hz": None if self.speed_range_hz is None
                else list(self.speed_range_hz), "synthesis_plant": self.synthesis_plant}

    def to_dict(self) -> dict:
        """Summary plus the controller matrices (lists) and the D–K history."""
        d = self.summary()
        d["history"] = [dict(h) for h in self.history]
        d["controller"] = {
            "inputs": list(self.K.input_labels), "outputs": list(self.K.output_labels),
            "input_unit": "m", "output_unit": "A", "feedback": "negative: i = -K y",
            **{k: np.asarray(getattr(self.K, k), float).tolist() for k in ("A", "B", "C", "D")}}
        return d


def _pid(cfg, p):
    d = reference_pid(cfg)
    notes = (f"PID designed from the rig (no [controller.pid]): {d['rule']}",) \
        if "rule" in d else ()
    K = pid_of(d, channel_names(cfg))
    sched = scheduled_pid(cfg)
    if sched is not None:
        notes += (f"cross-axis gains scheduled on speed, ∝ Ω from standstill to "
                  f"{sched.top / (2 * np.pi):.4g} Hz (cross_kp {sched.gains['cross_kp']:.4g} "
                  f"A/m, cross_kd {sched.gains['cross_kd']:.4g} A·s/m at "
                  f"{cfg.controller.pid.cross_speed_rpm:.6g} rpm)",)
    return DesignResult("pid", K, p, order=int(K.nstates), order_full=int(K.nstates),
                        notes=notes, scheduled=sched, verdict=_pid_verdict(d))


def full_order_check(cfg, K, conditions, *, first_loss: bool = False,
                     sampled: bool = False) -> dict:
    """Close a physical controller with the full-order plant at each condition, as the
    main job judges it (:func:`ambseal.machine.loop.judged_loop`: the target's hold and
    computation delay as :func:`ambseal.robust.delay.loop_delay`'s lag), or, with
    ``sampled``, as it runs: its Tustin transform with the computation delay on the plant
    sampled at ``[controller] sample_rate_hz`` (a design on the sampled plant,
    :mod:`ambseal.robust.w_plane`, whose discrete controller that transform is).

    Parameters
    ----------
    cfg : RigConfig
        The rig; its full-order plant is built at each condition.
    K : control.StateSpace or ScheduledController
        Displacements (m) → current references (A), negative feedback ``i = −K y``; a
        controller scheduled on speed is frozen at each condition's speed
        (:func:`ambseal.machine.frozen`).
    conditions : iterable of (pressure_bar, speed_hz)
        The judged conditions: pressure drop (bar) and speed (Hz).
    first_loss : bool
        Take the speeds farthest from the design speed (``[operating] speed_rpm``) first
        and stop after the first speed with an unstable loop, every pressure at it
        checked: for a design about to be corrected, whose lost modes matter and not
        every condition's verdict. The gyroscopic moments move a frozen design's modes
        the more the farther the speed, so the farthest speed loses the modes first.
    sampled : bool
        Judge the loop as it runs (above); its poles z are taken to s by λ = ln z / T.

    Returns
    -------
    dict
        ``stable`` (bool: every judged loop stable by
        :func:`ambseal.robust.stability.is_stable`) and, for the least stable condition,
        ``pressure_bar``, ``speed_hz``, ``max_real_pole`` (1/s) and its mode: ``mode_hz``
        (damped frequency) and ``damping`` (ζ = −Re λ/|λ|, negative when unstable);
        ``unstable``: every pole in the right half-plane at every condition, as
        ``{"mode_hz", "speed_hz", "pressure_bar"}`` (empty when stable); ``checked``: the
        number of conditions checked (fewer than given only with ``first_loss``).
    """

    fs, nd = cfg.controller.sample_rate_hz, cfg.controller.delay_samples
    L = loop_delay(fs, nd).system
    if sampled:
        mats = with_delay(discretize_as(tuple(np.asarray(getattr(K, x), float)
                                              for x in "ABCD"), 1.0 / fs, "tustin"), nd)
        K = control.ss(*mats, 1.0 / fs, inputs=list(K.input_labels),
                       outputs=list(K.output_labels), name=K.name)
    conditions = list(conditions)
    if first_loss:
        f0 = cfg.operating.speed_rpm / 60.0
        conditions.sort(key=lambda c: -abs(c[1] - f0))  # (stable: pressures keep their order)
    worst, lost, checked = None, [], 0
    for p, f in conditions:
        if first_loss and lost and f != lost[-1]["speed_hz"]:
            break
        checked += 1
        plant = build_plant(cfg, pressure_bar=p, speed_rpm=60.0 * f)
        judged = judged_loop(plant.to_statespace(), frozen(K, 2 * np.pi * f),
                             plant.current_inputs(), delay=L)
        lam = judged.loop.poles
        if sampled:  # the delay's poles at z = 0 have no s image (infinitely fast)
            lam = np.log(lam[np.abs(lam) > 0].astype(complex)) * fs
        lost += [{"mode_hz": float(x.imag / (2 * np.pi)), "speed_hz": float(f),
                  "pressure_bar": float(p)} for x in unstable_poles(lam) if x.imag >= 0]
        z = lam[int(np.argmax(lam.real))]
        rank = (not judged.stable, z.real / np.abs(lam).max())
        if worst is None or rank > worst[0]:
            worst = (rank, p, f, z)
    (unstable, _), p, f, z = worst
    return {"stable": not unstable, "pressure_bar": float(p), "speed_hz": float(f),
            "max_real_pole": float(z.real), "mode_hz": float(abs(z.imag) / (2 * np.pi)),
            "damping": float(-z.real / max(abs(z), 1e-300)), "unstable": lost,
            "checked": checked}


def on_sampled_plant(cfg) -> bool:
    """Whether the rig's H∞ and μ are synthesised on the sampled, delayed plant.

    Parameters
    ----------
    cfg : RigConfig
        The rig; ``[design] synthesis_plant`` decides.

    Returns
    -------
    bool
        True for ``"sampled"``: the design model sampled with its delay, in the w-plane
        (:mod:`ambseal.robust.w_plane`); the full-order checks then close the loop as it
        runs (:func:`full_order_check`), and the discrete controller is the Tustin
        transform of the one designed (:func:`ambseal.robust.digital.digital_controller`
        with ``w_plane``).
    """
    return cfg.design.synthesis_plant == "sampled"


@with_numerics_threads
def design(
    cfg,
    method: str = "mu",
    *,
    pressure_bar: float | None = None,
    weights: Weights | None = None,
    uncertainty: Mapping[str, Any] | None = None,
    states: int | None = None,
    omega: Any = None,
    reduce_to: int | str | None = "auto",
    max_iter: int | None = None,
    dk_order: int | None = None,
    allow_unstable: bool = False,
    spec: Any = None,
    progress: Any = None,
    enlarge: int = 2,
    trials: dict | None = None,
    scheduled_on_speed: bool = False,
) -> DesignResult:
    """Design a controller for a rig (thesis P5 §4).

    Parameters
    ----------
    cfg : RigConfig
        The rig (``ambseal.config.load_rig()``).
    method : {"pid", "hinf", "mu"}
        Reference PID, nominal H∞, or μ (D–K) robust to the specification's uncertainty.
    pressure_bar : float, optional
        Design pressure drop (bar); ``[operating] pressure_bar`` if omitted.
    weights : Weights, optional
        Weights and scalings; the specification's for the method if omitted.
    uncertainty : mapping, optional
        μ only: ``{parameter: fraction or (low, high)}`` as in
        :func:`~ambseal.design.plant.generalized_plant`; the specification's if omitted
        (every seal's k ± 100 %, P5 §4.1). Ignored by ``"hinf"``.
    states : int, optional
        Mechanical states of the design model; the specification's if omitted.
    omega : array_like, optional
        μ frequency grid (rad/s); 60 points over the specification's synthesis band.
    reduce_to : int, "auto" or None
        Reduce the controller to this order (balanced truncation,
        :func:`~ambseal.robust.order.reduce_controller`); the rise of γ/μ is reported in
        ``reduction``. ``"auto"``: ``[design] order_max``, else the design model's states
        plus those of W_p and W_u (the force weight W_f and the D and G scales of D–G–K
        raise the order, not kept), raised by one
        state per control channel while the reduced controller does not stabilise the
        design loop or raises its μ (H∞: γ) by more than ``ORDER_RISE`` = 1 %. With D–G–K
        both its controller and complex D–K's are reduced and the one with the lower μ is
        delivered. ``None``: none.
    max_iter, dk_order : int, optional
        D–K iterations and D-scale fit order (μ only); the specification's if omitted.
    allow_unstable : bool
        Deliver a controller whose full-order loop is unstable at a judged condition
        (marked in the result) instead of raising.
    spec : DesignSpec, optional
        The resolved specification (:func:`ambseal.design.specs.design_spec`).
    progress : callable, optional
        Called with one line per automatic design step.
    enlarge : int
        Automatic design steps when the full-order loop is unstable: the design model
        enlarged to keep a mode it left out, or a damping margin on a lightly damped mode
        it keeps (:func:`margin_for`, :func:`ambseal.design.plant.less_damped`).
    trials : dict, optional
        Shared by the designs of one rig and specification (the main job's): the H∞
        designs tried over the speed range (with the speed uncertain, or at another
        stability speed) are kept in it by their inputs, and the next design that tries
        the same one takes it from there instead of designing it again — μ tries H∞'s,
        which H∞'s own design has just made. The same result either way; None: nothing
        kept.
    scheduled_on_speed : bool
        H∞ or μ: designed scheduled on the spin speed over the judged speeds
        (:func:`_scheduled_over_speed`) without trying a fixed design over the speed range
        first — the run's remedy where a fixed design holds the loop but not its ISO
        14839-3 zone as it runs (:mod:`ambseal.app.remedies`). Needs ``[operating]
        speed_range_hz`` and the continuous synthesis plant.

    Returns
    -------
    DesignResult

    Raises
    ------
    ConfigError
        Unknown method, bad weights or uncertainty ranges, ``reduce_to`` not an int,
        ``"pid"`` on a rig without ``[controller.pid]``, ``scheduled_on_speed`` for the
        PID, on a rig without a speed range or on the sampled synthesis plant.
    SynthesisError
        If synthesis fails, the reduced controller no longer stabilises the design loop, or
        the full-order loop is unstable at a judged condition (naming the mode, its
        frequency and damping, and the key that keeps it in the design model).

    Examples
    --------
    >>> from ambseal.config import load_rig
    >>> r = design(load_rig(), "hinf")              # doctest: +SKIP
    >>> r.K.ninputs, r.K.noutputs                    # doctest: +SKIP
    (4, 4)
    """

    if method not in method_names(fixed=True):
        raise ConfigError(f"design: method={method!r}, expected one of "
                          f"{method_names(fixed=True)}")
    p = float(cfg.operating.pressure_bar if pressure_bar is None else pressure_bar)
    if scheduled_on_speed and (method == "pid" or cfg.operating.speed_range_hz is None
                               or on_sampled_plant(cfg)):
        raise ConfigError("design: scheduled_on_speed is for H∞ and μ on the continuous "
                          "synthesis plant of a rig with [operating] speed_range_hz")
    if method == "pid":
        return _pid(cfg, p)
    if isinstance(reduce_to, str) and reduce_to != "auto":
        raise ConfigError(f"design: reduce_to={reduce_to!r}, expected an int, 'auto' or None")
    sp = spec or design_spec(cfg, pressure_bar)
    if weights is None and (sp.d_e is None or sp.d_u is None):
        key = "d_e_um" if sp.d_e is None else "d_u_a"
        raise ConfigError(f"design.{key}: cannot be derived (the rig gives no air_gap, "
                          f"bias_current or current_limit); set it in [design] or with "
                          f"--set design.{key}=...")
    w = weights or sp.weights[method]
    unc = dict(uncertainty) if uncertainty is not None else dict(sp.uncertainty)
    dl = design_delay(cfg.controller.sample_rate_hz, cfg.controller.delay_samples,
                      sp.synthesis_band_hz[1], max_order=1)
    steps: list[str] = []
    t0 = time.perf_counter()

    def synthesise(c, into: list, m: str = method, speed=None, n_speed=None, level=None,
                   n_start=None):
        args = (c, m, p, w if m == method else sp.weights[m], unc, sp,
                states if n_speed is None else n_speed,
                None if omega is None else np.asarray(omega, float), reduce_to,
                max_iter or sp.max_iter, sp.dk_order if dk_order is None else dk_order, dl,
                enlarge if speed is None else 0)
        if trials is None or m != "hinf" or (speed is None and c is cfg):  # not a trial
            return _synthesise_enlarging(*args, into, progress, speed, level, n_start)
        return _tried(trials, args + (speed, level, n_start),
                      lambda: _synthesise_enlarging(*args, into, progress, speed, level,
                                                    n_start))

    r, check, n = synthesise(cfg, steps)
    moved = over = lost = None
    if not cfg.design.one_speed or scheduled_on_speed:
        scheduled = (None if method == "pid" or on_sampled_plant(cfg) else
                     partial(_scheduled_over_speed, cfg, method, p,
                             w if weights is not None or method != "hinf"
                             else _with_orbit_demand(w, sp), unc, sp, dl))
        (r, check, n), moved, over, lost = _over_speed(cfg, method, p, sp, (r, check, n),
                                                       synthesise, steps, progress,
                                                       fixed=states is not None,
                                                       schedule=scheduled,
                                                       schedule_only=scheduled_on_speed)
    if not check["stable"] and not allow_unstable:
        raise SynthesisError(_unstable_message(method, check, n, steps, _top_mode_hz(cfg, p, n),
                                               lost or _lost_by(cfg, r.K, check, p),
                                               _outside(cfg, r.gp.parameters, check, p)))
    return DesignResult(
        method, r.K, p, gamma=r.gamma, mu=r.mu, order=int(r.K.nstates),
        order_full=r.order_full, history=tuple(r.history), weights=w,
        uncertainty={q.name: (q.low, q.high) for q in r.gp.parameters},
        elapsed_s=time.perf_counter() - t0, reduction=r.reduction, plant=r.gp,
        design_states=n, full_order=check, kept_unstable=not check["stable"],
        delay=({"delay_s": (cfg.controller.delay_samples + 0.5) / cfg.controller.sample_rate_hz,
                "sampled": {"sample_rate_hz": cfg.controller.sample_rate_hz,
                            "delay_samples": cfg.controller.delay_samples}}
               if on_sampled_plant(cfg) else dl.to_dict()),
        steps=tuple(steps), notes=tuple(sp.notes),
        verdict=_verdict(method, r, check), omega=r.omega, stopping=r.stopping,
        design_speed_hz=moved, speed_range_hz=over,
        synthesis_plant="sampled" if on_sampled_plant(cfg) else "continuous",
        scheduled=r.scheduled)


def _tried(trials: dict, inputs: tuple, make):
    """``make()``'s result (or the SynthesisError or ModelError it raised) kept in
    ``trials`` under its synthesis ``inputs``, taken from there when they were tried
    before. The key spells the inputs out — the rig as its JSON, the weights and
    uncertainty as their dicts, the frequency grid as its values; the specification by
    identity (one per run), and with it the design delay, which the rig's rate and the
    specification's band fix."""
    cfg, m, p, w, unc, sp, n, om, reduce_to, max_iter, dk_order, _, *rest = inputs
    key = (cfg.model_dump_json(), m, p, json.dumps(w.to_dict(), sort_keys=True, default=str),
           json.dumps(unc, sort_keys=True, default=str), id(sp), n,
           None if om is None else tuple(np.asarray(om, float).tolist()),
           reduce_to, max_iter, dk_order, repr(rest))
    if key not in trials:
        try:
            trials[key] = make()
        except (SynthesisError, ModelError) as exc:
            trials[key] = exc
    got = trials[key]
    if isinstance(got, Exception):
        raise got
    return copy.deepcopy(got)  # the next design may amend its check; this one's stays


def _synthesise_enlarging(cfg, method, p, w, unc, sp, states, om, reduce_to, max_iter,
                          dk_order, dl, enlarge, steps, progress, speed=None, level=None,
                          n_start=None):
    """:func:`_synthesise` on the specification's design model, corrected (at most
    ``enlarge`` times) while the full-order loop is unstable: enlarged (unless ``states``
    fixes it) to keep a mode the model left out, or, where the model keeps the mode,
    given a damping margin on it (:func:`margin_for`), or, for μ and a mode lost away from
    the design speed, its frequency (and those of the sweeping modes below it) made
    uncertain over the band it sweeps (:mod:`ambseal.design.modal_bands`); if no margin
    holds it, the last design without margins is returned. A least stable loss that none
    of these reaches — a mode below every band with ζ ≤ −``LIGHT_DAMPING``, the conical
    mode at standstill of a design that leaned on the gyroscopic stiffening — ends the
    corrections: the bands of the modes above it leave its cause as it was (the example
    flywheel, benchmarks/README.md, "μ's corrections end at a loss no mode band reaches"),
    and :func:`_over_speed` is what can hold it. Each correction is appended to ``steps`` and
    reported to ``progress``. With ``speed`` (Hz) the spin speed is uncertain over that
    range, the performance weights at ``level`` (:func:`_synthesise`). ``n_start``: the
    design model's states to start from where ``states`` does not fix them (default the
    specification's). Returns (synthesis, full-order check, design states)."""
    n = int(states or n_start or sp.model_states)
    # held where it is judged and wherever the machine runs, standstill to the top speed
    conditions = [(q, f) for q in sp.pressures_bar
                  for f in sorted({*sp.speeds_hz, *sp.stability_speeds_hz})]
    margins: dict[float, float] = {}
    bands: list = []  # modes whose frequency μ takes as uncertain over their speed band
    swept = None  # (states, every band) of the design model, found when first needed
    plain = None  # the last design without margins: delivered if no margin holds the loop
    for attempt in range(enlarge + 1):
        r = _synthesise(cfg, method, p, w, unc, n, om, sp, reduce_to, max_iter, dk_order, dl,
                        tuple(margins.items()),
                        progress and (lambda line: progress(f"{method}: {line}")), tuple(bands),
                        speed, level)
        # a design that can still be corrected is checked until it loses a mode
        check = full_order_check(cfg, r.K, conditions, first_loss=attempt < enlarge,
                                 sampled=on_sampled_plant(cfg))
        if not margins:
            plain = (r, check, n)
        if check["stable"] or attempt == enlarge:
            break
        n_new = n if states is not None else _states_to_keep(cfg, p, check["mode_hz"])
        new, f0 = [], cfg.operating.speed_rpm / 60.0
        if (n_new <= n and method in method_names(robust=True)
                and abs(check["speed_hz"] - f0) > 1e-9):
            # every mode lost away from the design speed, not only the least stable one:
            # one design step for all the bands they call for
            swept = _swept(cfg, conditions, n, f0, swept)
            if -check["damping"] < LIGHT_DAMPING or bands_near(swept[1], check["mode_hz"]):
                away = {c["mode_hz"] for c in check["unstable"]
                        if abs(c["speed_hz"] - f0) > 1e-9}
                new = sorted({b for f in away for b in bands_near(swept[1], f)} - set(bands),
                             key=lambda b: b.f_hz)
            # else the least stable loss lies below every band and far from stable: bands
            # of the modes above it leave its cause as it was, and no margin holds it
            # (below), so the corrections end (docstring)
        if n_new > n:
            steps.append(f"{method}: full-order loop unstable at {check['mode_hz']:.4g} Hz "
                         f"(ζ = {check['damping']:.3g}, {check['pressure_bar']:g} bar); design "
                         f"model enlarged from {n} to {n_new} states")
            n = n_new
            top = 1.5 * check["mode_hz"]
            if om is None and top > sp.synthesis_band_hz[1]:
                om = design_omega(sp.synthesis_band_hz[0], top)
        elif new:
            # the design speed's plant puts the mode elsewhere than the speed that lost it:
            # μ holds the band the mode sweeps when its frequency is uncertain over it
            bands += new
            steps.append(f"{method}: full-order loop unstable at {check['mode_hz']:.4g} Hz "
                         f"(ζ = {check['damping']:.3g}, {check['pressure_bar']:g} bar, "
                         f"{check['speed_hz']:g} Hz), where the gyroscopic moments move a mode "
                         "the design model keeps: its frequency made uncertain over the band it "
                         "sweeps with speed, " + ", ".join(b.text() for b in new))
        else:
            # a lightly damped mode the model keeps, barely damped by the design: a margin
            # on it (a rigid-body mode the loop no longer holds is no such mode)
            f, dz = margin_for(check, margins)
            if -check["damping"] >= LIGHT_DAMPING or not _margin_reaches(cfg, p, n, f, dz):
                break
            margins[f] = dz
            steps.append(f"{method}: full-order loop unstable at {check['mode_hz']:.4g} Hz "
                         f"(ζ = {check['damping']:.3g}, {check['pressure_bar']:g} bar, "
                         f"{check['speed_hz']:g} Hz), a mode the design model keeps: its "
                         f"damping there lowered by {dz:.3g} (ζ) so the controller adds it")
        if progress:
            progress(steps[-1])
    if not check["stable"] and margins:
        # the margins asked for damping this design could not give without losing the
        # loop elsewhere: the design as the weights ask it, with the steps tried reported
        steps.append(f"{method}: no damping margin held the full-order loop; the design "
                     "without margins is delivered")
        r, check, n = plain
    if check["checked"] < len(conditions):
        # the design delivered, or refused, is judged at every condition
        check = full_order_check(cfg, r.K, conditions, sampled=on_sampled_plant(cfg))
    return r, check, n


def _over_speed(cfg, method: str, p: float, sp, first, synthesise, steps: list,
                progress, fixed: bool = False, schedule=None, schedule_only: bool = False):
    """The design over the speed range: where ``first`` (synthesis, full-order check,
    states), designed at the operating speed and pressure ``p`` (bar), loses the rotor at
    another judged speed, and the speed is what loses it (:func:`_lost_by`: at ``p`` that
    speed's loop is lost too; where only another pressure loses it, the design speed's
    loop at that pressure is lost as well, and no design speed holds it),

    1. the design with the spin speed a real parameter of the LFT, uncertain from the
       lowest to the highest judged speed (:mod:`ambseal.design.speed_lft`; H∞ at the
       speed channel's constant scalings, μ by its D–K with the speed's block), on
       ``first``'s design model: kept where its full-order loop holds every judged
       condition. μ, whose D–K steps cost a hundred H∞ designs, is tried only where the
       H∞ design with the speed channel holds. Where none holds and the design model
       keeps one whirl of a pair and not its twin, the same is tried on the model of
       whole pairs (:func:`~ambseal.design.speed_lft.whole_pair_states`), unless the user
       fixed its states (``fixed``, or ``[design] model_states``): measured, family seeds
       7 and 13 hold only on whole pairs, the expander-generator example's μ only on the
       split model (benchmarks/README.md, "Whole whirl pairs in the speed-range design
       model");
    2. else the design at another of the specification's stability speeds: the first
       whose full-order loop holds at every judged condition. H∞ tries each in turn from
       standstill up (the gyroscopic moments change the plant monotonically with speed,
       so the loss moves with the design speed); μ is designed once more, at the speed
       that search finds for H∞ (``synthesise(cfg, steps, "hinf")``), where there is one;
    3. else, given ``schedule`` (H∞ or μ on the continuous plant), the method scheduled
       on the spin speed (:mod:`ambseal.design.speed_schedule`; ``schedule(range_hz,
       states, tried)``, :func:`_scheduled_over_speed`; H∞ with μ's orbit demand,
       :func:`_with_orbit_demand`), kept where its full-order loop holds every judged
       condition and between its entries: the gyroscopic moments are known where the
       controller runs, and a fixed controller over the range is the simpler one to run,
       so it is tried first. Measured on the gyroscopic family (benchmarks/README.md, "H∞
       scheduled on the spin speed"): with it the run delivers H∞ on 22 of 27 rigs, 9
       without;
    4. else ``first``, with a step that names what was tried and how each lost the
       rotor (or why there was no design), so the user sees the range was tried.

    Returns (the design, the speed in Hz it was designed at for 2, the speed range in Hz
    for 1; None where not; and, where ``first`` is returned after :func:`_lost_by` was
    asked of it, that answer, else None: a refusal's message reuses it). Measured
    on the seeded gyroscopic family (benchmarks/README.md, bench_family.py): a design at
    the top speed leans on the gyroscopic stiffening of the conical mode and loses it at
    standstill, one at standstill can lose the nutation or a bending mode at the top
    speed; the design with the speed uncertain holds both on rotors whose gyroscopic
    coupling a fixed controller can span (tests/data/gyro_wheel_rig.toml, Ip/It 0.54:
    H∞ γ 2.1, μ 0.79), where the frozen search can only find a speed in between.
    ``[design] one_speed`` turns it off. ``schedule_only`` goes to 3 directly, whatever
    ``first`` held, and raises :class:`SynthesisError` where the schedule holds nothing."""
    r, check, n = first
    f0 = cfg.operating.speed_rpm / 60.0
    judged = sorted({*sp.speeds_hz, *sp.stability_speeds_hz})
    rng = (judged[0], judged[-1])
    if schedule_only:
        tried: list[str] = []
        held = schedule(rng, n, tried)
        if held is None:
            raise SynthesisError(f"{method}: not scheduled on the spin speed: "
                                 + "; ".join(tried))
        steps.append(f"{method}: designed {_schedule_words(held[0], rng)} holds every "
                     "judged condition (asked for without a fixed design over the range)")
        if progress:
            progress(steps[-1])
        return held, None, rng, None
    if check["stable"] or cfg.operating.speed_range_hz is None \
            or abs(check["speed_hz"] - f0) <= 1e-9 * max(f0, 1.0):
        return first, None, None, None
    lost_by = _lost_by(cfg, r.K, check, p)
    if not lost_by[1]:
        return first, None, None, lost_by
    lost = (f"the design at the operating speed ({f0:g} Hz) lost the rotor at "
            f"{check['speed_hz']:g} Hz (mode at {check['mode_hz']:.4g} Hz, ζ = "
            f"{check['damping']:.3g})")

    def step(line: str) -> None:
        steps.append(f"{method}: designed {line} holds every judged condition; {lost}")
        if progress:
            progress(steps[-1])

    tried: list[str] = []
    held, model = _held_over_speed(cfg, method, rng, n, synthesise, tried), ""
    if held is None and not (fixed or sp.sources.get("model_states") == "set"):
        n_whole = whole_pair_states(cfg, n, pressure_bar=p)
        if n_whole != n:
            model = f" on {n_whole} states (the {n} of the operating speed split a whirl pair)"
            held = _held_over_speed(cfg, method, rng, n_whole, synthesise, tried, model)
    if held is not None:
        step(f"with the spin speed uncertain over {rng[0]:g}–{rng[1]:g} Hz (a real LFT "
             f"parameter){model}{_level_words(held[0].level)}, which")
        return held, None, rng, None
    speeds = [f for f in sorted(set(sp.stability_speeds_hz))
              if abs(f - f0) > 1e-9 * max(f0, 1.0)]
    if method != "hinf":
        found = _first_held(cfg, speeds, lambda c, n_f: synthesise(c, [], "hinf", n_start=n_f),
                            sp, tried, "H∞ ")
        speeds = [] if found is None else [found[0]]
    found = _first_held(cfg, speeds, lambda c, n_f: synthesise(c, [], n_start=n_f), sp, tried)
    if found is None and schedule is not None:
        held = schedule(rng, n, tried)
        if held is not None:
            step(f"{_schedule_words(held[0], rng)}, which")
            return held, None, rng, None
    if found is None:
        steps.append(f"{method}: no design over the speed range held every judged "
                     f"condition, so the design at the operating speed stays; {lost}; "
                     f"tried: {'; '.join(tried)}")
        if progress:
            progress(steps[-1])
        return first, None, None, lost_by
    f, out = found
    step(f"at {f:g} Hz, the first stability speed from standstill whose "
         f"{'H∞ ' if method != 'hinf' else ''}design")
    return out, f, None, None


def _schedule_words(r: _Synthesis, rng) -> str:
    """H∞ or μ scheduled on the spin speed over ``rng`` (Hz), in the words of a design
    step."""
    (method, stop), = r.stopping.items()
    orbit = stop.get("orbit_um")
    demand = "" if orbit is None else f" with an unbalance-orbit demand of {orbit:.3g} µm"
    if method != "hinf":
        demand = (f" of μ's weights{demand}"
                  + (f", at the D scales of its D–K at {rng[1]:g} Hz" if stop["d_scales"]
                     else "") + f", μ {r.mu:.3g} at the worst entry")
    added = len(stop["added_speeds_hz"])
    table = (f"its {r.scheduled.table_theta.size} judged speeds" if not added
             else f"its {r.scheduled.table_theta.size - added} judged speeds and {added} "
                  "between them where the interpolated loop was lost")
    return (f"as a controller scheduled on the spin speed over {rng[0]:g}–{rng[1]:g} Hz "
            f"(the central H∞ controllers{demand}, at γ {r.gamma:.3g}, of the plants frozen "
            f"at {table}, interpolated linearly)")


def _with_orbit_demand(w: Weights, sp) -> Weights:
    """H∞'s weights ``w`` with μ's unbalance-orbit demand (ORBIT_PER_DE·D_e and its force
    channel W_f, :mod:`ambseal.design.specs`) where the user left ``[design.hinf]
    orbit_um`` unset (0 switches it off): the weights of H∞ scheduled on the spin speed.
    Weighted on S_o and K S_o alone, the central controllers cancel the forward nutation,
    which follows the speed: measured on the flywheel example, the schedule held every
    judged speed with that mode at ζ 0.0008 just above the synchronous line and an orbit
    of 2.2 mm through it at the trip speed; with the force channel, 36 µm at zone A
    (benchmarks/README.md, "H∞ scheduled on the spin speed")."""
    if sp.sources.get("hinf.orbit_um") == "set" or w.wf_rolloff_hz is None or w.d_e is None:
        return w
    return replace(w, orbit_um=ORBIT_PER_DE * w.d_e * 1e6)


def _scheduled_over_speed(cfg, method: str, p: float, w, unc, sp, dl, rng, n: int,
                          tried: list):
    """H∞ or μ scheduled on the spin speed over ``rng`` (Hz) on the n-state design model at
    ``p`` bar (:func:`~ambseal.design.speed_schedule.schedule_hinf`), as ``(synthesis,
    full-order check, n)`` where its full-order loop holds every judged condition and,
    at each judged pressure, every speed between table entries the target's table will
    run (:func:`_between_entries_hz`), else None with the loss (or why there is no design)
    appended to ``tried``.

    The table starts at the judged speeds. A speed between entries whose loop is lost
    becomes an entry (its plant's central controller, every entry again at the common
    γ), until every speed between entries holds: the stopping rule. A loss at an entry,
    or between entries closer than :data:`MIN_TABLE_STEP` of the range, ends it with no
    design. Measured on the flywheel example: its six judged speeds held, but the
    interpolated controller half way from standstill to the first judged speed lost the
    slow precession (|z| 1.0002 as exported).

    μ's table is the K-step of D–K on the frozen plants with one set of D scales: those of
    μ's D–K (:func:`~ambseal.robust.musyn`) on the plant frozen at the top judged speed,
    where the gyroscopic moments and the seal's speed-dependent forces are largest; its
    uncertain parameters stay uncertain at every speed, and its μ is the largest of the
    entries' peaks (:func:`~ambseal.design.speed_schedule.mu_by_speed`). On a rig whose
    only uncertainty is the speed, the frozen structure is the performance block alone and
    the table is H∞'s with μ's weights. Measured on family seed 9 (no seal): every fixed
    μ lost the rotor at standstill; the schedule holds every judged speed at μ ≤ 0.96."""
    what = "scheduled on the spin speed"
    speeds = sorted({*sp.speeds_hz, *sp.stability_speeds_hz})
    judged = list(speeds)
    robust = method in method_names(robust=True)
    try:
        gp = _generalised(cfg, method, p, w, unc, n, sp, dl, speed=rng)
        om = design_omega(*sp.synthesis_band_hz)
        scalings = None
        if robust and len(frozen_structure(gp)) > 1:
            top = musyn(at_speed(gp, 2 * np.pi * speeds[-1]), frozen_structure(gp),
                        gp.nmeas, gp.ncon, om, order=sp.dk_order, max_iter=sp.max_iter)
            scalings = result_scalings(top)
        elif robust:
            scalings = ()
    except (SynthesisError, ModelError) as exc:
        tried.append(_tried_words(what, error=exc))
        return None
    while True:
        try:
            sched = schedule_hinf(gp, speeds, scalings, name=f"K_{method}")
        except (SynthesisError, ModelError) as exc:
            tried.append(_tried_words(what, error=exc))
            return None
        between = _between_entries_hz(speeds)
        check = full_order_check(cfg, sched, [(q, f) for q in sp.pressures_bar
                                               for f in sorted({*speeds, *between})])
        if check["stable"]:
            break
        lost = sorted({u["speed_hz"] for u in check["unstable"]})
        step = MIN_TABLE_STEP * (speeds[-1] - speeds[0])
        if any(f in speeds or min(abs(f - e) for e in speeds) < step for f in lost):
            tried.append(_tried_words(what, check))
            return None
        speeds = sorted({*speeds, *lost})
    f0 = cfg.operating.speed_rpm / 60.0
    added = [f for f in speeds if f not in judged]
    peaks = mu_by_speed(gp, sched, om) if robust else None
    mu = None if peaks is None else max(pk.peak for pk in peaks)
    rule = ("the central H∞ controller of the plant frozen at each table speed"
            + (", its uncertainty channels at the D scales of μ's D–K at the top speed"
               if scalings else "")
            + f", at γ = {sched.backoff:g} × the largest γ_opt (each γ_opt bisected to "
              "rtol=1e-06); a speed between entries whose loop was lost made an entry, "
              "until every one held")
    r = _Synthesis(sched.at(2 * np.pi * f0), sched.gamma, mu, (), sched.order, None, gp,
                   stopping={method: {
                       "rule": rule,
                       "table_speeds_hz": [float(f) for f in speeds],
                       "added_speeds_hz": [float(f) for f in added],
                       "orbit_um": w.orbit_um,
                       "gamma_opt": [float(g) for g in sched.gamma_opt],
                       **({} if peaks is None else {
                           "mu_by_speed": [float(pk.peak) for pk in peaks],
                           "d_scales": len(scalings)})}},
                   scheduled=sched)
    return r, check, n


#: The closest two entries of H∞'s table on speed may come, as a fraction of its range
#: (:func:`_scheduled_over_speed`): finer than that, a loss between them is the design's,
#: not the interpolation's.
MIN_TABLE_STEP = 1.0 / 64.0


def _between_entries_hz(speeds_hz) -> list[float]:
    """The speeds between the entries of a table on speed at which its loop is judged: the
    entries the target's discrete table adds (:func:`ambseal.machine.table_grid`) and the
    midpoints of the discrete table's intervals, none of them an entry.

    Parameters
    ----------
    speeds_hz : sequence of float
        The table's speeds (Hz), increasing, at least two.

    Returns
    -------
    list of float
        Increasing speeds (Hz), strictly between the first and the last entry.
    """
    grid = table_grid(np.asarray(speeds_hz, float))
    mids = (grid[:-1] + grid[1:]) / 2
    return sorted({float(f) for f in (*grid, *mids)} - {float(f) for f in speeds_hz})


def _held_over_speed(cfg, method: str, rng, n: int, synthesise, tried: list,
                     model: str = ""):
    """``synthesise``'s design with the speed uncertain over ``rng`` (Hz) on the n-state
    design model, where its full-order loop holds every judged condition, else None; each
    design that did not hold is appended to ``tried`` in words (:func:`_tried_words`).

    H∞ is designed first at the performance weights as given; where its loop does not
    hold, at the largest performance level whose constant-scaled γ certifies the speed
    range (:func:`ambseal.robust.level.performance_level`): measured on a rigid rotor of
    Ip/It 1.2 over 0–400 Hz (tests/design/test_design_over_speed.py), the weights as given
    ask for a γ of 2.5 and the loop is lost at standstill; at 8.7 % of them γ is 0.99 and
    the rotor is held at zone A at every speed. μ is designed where H∞'s loop holds, at
    H∞'s level. ``model`` says in words where n is not the operating speed's count."""
    held = None
    head = f"with the spin speed uncertain over {rng[0]:g}–{rng[1]:g} Hz{model}"
    for level in (None, "auto"):
        what = head + (" at the weights as given" if level is None else
                       " at the largest performance level that certifies it")
        try:
            out = synthesise(cfg, [], "hinf", speed=rng, n_speed=n, level=level)
        except (SynthesisError, ModelError) as e:
            tried.append(_tried_words(f"H∞ {what}" if method != "hinf" else what, error=e))
            continue
        if out[1]["stable"]:
            held = out
            break
        tried.append(_tried_words(f"H∞ {what}" if method != "hinf" else what, out[1]))
        if out[0].gamma < 1:  # certified at the weights as given: relaxing them adds nothing
            break
    if held is None or method == "hinf":
        return held
    what = head + _level_words(held[0].level)
    try:
        out = synthesise(cfg, [], method, speed=rng, n_speed=n, level=held[0].level)
    except (SynthesisError, ModelError) as e:
        tried.append(_tried_words(what, error=e))
        return None
    if out[1]["stable"]:
        return out
    tried.append(_tried_words(what, out[1]))
    return None


def _tried_words(what: str, check: Mapping | None = None, error: Exception | None = None
                 ) -> str:
    """A design over the speed range that did not hold, in words: ``what`` it was, then
    where its full-order ``check`` lost the rotor, or the ``error`` that left no design."""
    if error is not None:
        return f"{what}: no design ({re.sub(r'^(hinf|mu): ', '', str(error)).rstrip('.')})"
    return (f"{what}: lost at {check['speed_hz']:g} Hz (mode at {check['mode_hz']:.4g} Hz, "
            f"ζ = {check['damping']:.3g})")


def _first_held(cfg, speeds, synthesise, sp, tried: list, kind: str = ""):
    """``(f, synthesise(rig at f Hz, design states))`` for the first speed in ``speeds``
    whose design's full-order loop holds at every judged condition, or None; each design
    before it is appended to ``tried`` in words (``kind``: the method's name where it is not
    the one designed). The design model at f starts from ``sp``'s rule applied at f
    (:func:`~ambseal.design.specs.design_states_at`): the operating speed's count can split
    a whirl pair that the gyroscopic moments no longer separate."""
    for f in speeds:
        at = cfg.model_copy(update={"operating": cfg.operating.model_copy(
            update={"speed_rpm": 60.0 * f})})
        try:
            out = synthesise(at, design_states_at(cfg, sp, f))
        except (SynthesisError, ModelError) as e:  # no design at that speed: the next one
            tried.append(_tried_words(f"{kind}designed at {f:g} Hz", error=e))
            continue
        if out[1]["stable"]:
            return f, out
        tried.append(_tried_words(f"{kind}designed at {f:g} Hz", out[1]))
    return None


def _swept(cfg, conditions, n: int, f0: float, swept):
    """``(n, bands)``: every mode band of the n-state design model, designed at ``f0`` Hz,
    over the judged speeds (:func:`ambseal.design.modal_bands.mode_bands`), ``swept`` again
    if it is for n states already; no bands where the LPV model cannot be made."""
    if swept is not None and swept[0] == n:
        return swept
    try:
        bands = mode_bands(cfg, [f for _, f in conditions], design_speed_hz=f0, states=n)
    except ModelError:
        bands = ()
    return n, bands


#: The damping-ratio margin a lost kept mode gets first (on top of twice the damping the
#: full-order loop lacked), doubled on each further loss of the same mode: 0.5 %, the
#: structural damping of a built-up rotor, so the controller at least doubles it.
MARGIN_ZETA = 0.005


def margin_for(check: dict, margins: dict) -> tuple[float, float]:
    """The damping margin (f_hz, Δζ) for the mode a full-order check lost: Δζ =
    :data:`MARGIN_ZETA` + 2·(−ζ) of the lost mode, or twice the margin already given to
    a mode within :data:`ambseal.design.plant.MARGIN_BAND` of it (which it replaces)."""
    f, zeta = check["mode_hz"], check["damping"]
    for g, dz in margins.items():
        if g / MARGIN_BAND < f < g * MARGIN_BAND:
            return g, 2.0 * dz
    return f, MARGIN_ZETA + 2.0 * max(-zeta, 0.0)


@dataclass(frozen=True, eq=False)
class _Synthesis:
    K: Any
    gamma: float
    mu: float | None
    history: tuple
    order_full: int
    reduction: dict | None
    gp: Any
    K_P: Any = None
    mu_omega: float | None = None
    omega: Any = None
    stopping: dict | None = None
    bands: tuple = ()
    level: float | None = None
    scheduled: Any = None


def _level_words(level: float | None) -> str:
    """``", at 5 % of the performance weights"`` where a speed design relaxed them."""
    return "" if level is None or level >= 1 else \
        f", at {100 * level:.2g} % of the performance weights (the largest level at which H∞ " \
        "at constant scalings certifies the speed range)"


def _synthesise(cfg, method, p, w, unc, n, om, sp, reduce_to, max_iter, dk_order, dl,
                margins=(), progress=None, bands=(), speed=None, level=None):
    """One synthesis on an n-state design model (with ``margins``, see
    :func:`ambseal.design.plant.less_damped`; μ with ``bands`` of uncertain mode frequency,
    :func:`ambseal.design.modal_bands.with_modal_frequencies`; with ``speed``, a range in
    Hz, the spin speed uncertain over it, :func:`ambseal.design.speed_lft.with_speed`,
    and its performance outputs scaled by ``level``: None for the weights as given,
    ``"auto"`` for the largest level H∞ at constant scalings certifies,
    :func:`ambseal.robust.level.performance_level`, asked for where the weights as given
    are not certified), reduced, as a physical controller;
    ``progress(line)`` gets μ's iterations.

    H∞ over a speed range is the K-step of D–K at constant scalings
    (:func:`~ambseal.robust.dk.scaled_hinfsyn`): the H∞ synthesis on
    ``D P D⁻¹`` with D–K's starting constant D (the smallest γ_opt where its search runs),
    whose γ < 1 would certify every plant of the range by the small-gain theorem (Zhou,
    Doyle & Glover, *Robust and Optimal Control*, 1996, §11.3: scaled H∞); a controller of
    the nominal H∞'s order."""

    robust = method in method_names(robust=True)  # against the uncertain parameters
    sampled = on_sampled_plant(cfg)
    gp = _generalised(cfg, method, p, w, unc, n, sp, dl, margins, bands, speed)
    mu_omega = None

    def scaled_hinf(P):  # H∞ at the constant scalings of the speed channel
        return scaled_hinfsyn(P, gp.blocks, gp.nmeas, gp.ncon,
                              design_omega(*sp.synthesis_band_hz))

    P, tried, found = gp.P, (), None
    if speed is None:
        level = None
    elif level == "auto":
        # asked for where the weights as given were not certified (or gave no design)
        found = performance_level(gp.P, gp.blocks, gp.nmeas, gp.ncon, scaled_hinf,
                                  refused=1.0)
        if found.level is None:
            raise SynthesisError(
                f"{method}: no performance level down to {LEVEL_FLOOR:g} of the weights "
                f"certifies the speed range {speed[0]:g}–{speed[1]:g} Hz at constant "
                f"scalings (γ {found.tried[-1][1]:.3g} there)")
        level, tried = found.level, found.tried
    if level is not None and (robust or found is None):
        P = scaled_performance(gp.P, gp.blocks, gp.nmeas, gp.ncon, level)
    if not robust and speed is not None:
        if found is not None:  # designed at the level with the same u and y
            K_P, gamma = found.result.K, float(found.gamma)
        else:
            r = scaled_hinf(P)
            K_P, gamma = r.K, float(r.gamma)
        mu, hist = None, ()
        stopping = {"hinf": {"rule": "the constant scalings of the speed channel of the "
                                     "smallest γ_opt (D–K's start), then γ_opt bisected to "
                                     "rtol=1e-06 and the controller built at backoff·γ_opt",
                             "speed_range_hz": list(speed)}}
        P_red, blocks = gp.P_nominal, None
    elif not robust:  # nominal H∞
        r = hinfsyn(gp.P_nominal, gp.nmeas, gp.ncon)
        K_P, gamma, mu, hist = r.K, float(r.gamma), None, ()
        stopping = {"hinf": {"iterations": r.iterations,
                             "rule": "γ_opt bisected to rtol=1e-06; the controller built at "
                                     "backoff·γ_opt and its closed-loop norm verified"}}
        P_red, blocks = gp.P_nominal, None
    else:
        if om is None:
            om = design_omega(*sp.synthesis_band_hz)
        # D–G–K only where complex D–K leaves robust performance unmet (μ > 1)
        syn = (partial(musyn_dgk, target=1.0) if sp.mu_iteration == "dgk" else musyn)
        r = syn(P, gp.blocks, gp.nmeas, gp.ncon, om, order=dk_order, max_iter=max_iter,
                progress=progress or False)
        K_P, gamma, mu, hist = r.K, float(r.gamma), float(r.mu), r.history
        stopping = r.stopping
        P_red, blocks, mu_omega = P, gp.blocks, float(r.mu_omega)
    if level is not None:
        stopping = {**(stopping or {}), "performance_level": {
            "level": level, "tried": [list(t) for t in tried],
            "rule": f"log α bisected to rtol={LEVEL_RTOL:g} between {LEVEL_FLOOR:g} and 1"}}
    order_full = int(K_P.nstates)
    if reduce_to == "auto":
        reduce_to = sp.order_max or (gp.design_plant.A.shape[0] + gp.ncon * (
            gp.Wp.nstates + gp.Wu.nstates
            + (cfg.controller.delay_samples if sampled else dl.system.nstates)))
        auto = not sp.order_max
    else:
        auto = False
    red = None
    if reduce_to is not None and reduce_to < order_full:
        cands = [{"step": hist[r.best_iteration].get("step", "D-K") if hist else "H-inf",
                  "K": K_P, "mu": mu, "gamma": gamma}]
        cands += list(getattr(r, "alternatives", ()) if robust else ())
        K_P, red, gamma, mu = _reduce_best(P_red, cands, int(reduce_to), auto, gp, blocks,
                                           om if robust else None)
        order_full = red["order_full"]
    K = gp.physical_controller(K_P, name=f"K_{method}")
    return _Synthesis(K, gamma, mu, tuple(hist), order_full, red, gp, K_P, mu_omega,
                      om if robust else None, stopping, tuple(bands) if robust else (),
                      level)


def _generalised(cfg, method, p, w, unc, n, sp, dl, margins=(), bands=(), speed=None):
    """The generalised plant of one synthesis (:func:`_synthesise`'s arguments): the
    recipe's weights on the n-state design model at ``p`` bar, μ's uncertainty, the spin
    speed uncertain over ``speed`` (Hz) where given, and on a sampled rig the w-plane
    image of the sampled plant."""
    robust = method in method_names(robust=True)
    Wf = w.Wf()
    fpos = tuple(w.force_positions_m or sp.force_positions_m) if Wf is not None else ()
    sampled = on_sampled_plant(cfg)
    gp = generalized_plant(cfg, w.Wp(), w.Wu(), uncertainty=unc if robust else None,
                           pressure_bar=p, states=n, input_disturbance=w.W1(),
                           force_disturbance=Wf, force_positions=fpos, d_e=w.d_e, d_u=w.d_u,
                           actuator_delay=None if sampled else dl.system,
                           gain_weight=w.Wk(), damping_margins=margins,
                           modal_bands=bands if robust else (), speed_range_hz=speed)
    if sampled:  # the plant as the discrete controller sees it, in the w-plane
        fs, nd = cfg.controller.sample_rate_hz, cfg.controller.delay_samples
        gp = replace(gp, P=w_plane_plant(gp.P, gp.ncon, fs, nd),
                     P_nominal=w_plane_plant(gp.P_nominal, gp.ncon, fs, nd))
    return gp


def _reduce_best(P, cands, order: int, auto: bool, gp, blocks, omega):
    """Balanced truncation of each candidate controller (:func:`reduce_controller`); the
    one with the lowest μ after reduction (γ for H∞) is kept. ``cands``: dicts ``{"step",
    "K", "mu", "gamma"}`` (D–G–K's controller and complex D–K's may swap places: the
    D–G–K one has more states and can lose more in the truncation). With ``auto`` the order
    steps up by one state per control channel until the reduced loop is stable and keeps
    its μ (H∞: γ) within ``ORDER_RISE`` of the full-order controller's.

    Returns ``(K, reduction dict, γ, μ)`` of the kept candidate; the dict lists every
    candidate's μ before and after (``candidates``) and the kept one (``kept``)."""

    rows, best = [], None
    for c in cands:
        # a candidate's μ is the peak on this loop, structure and grid (musyn's, musyn_dgk's)
        n, full = order, (None, c["mu"] if blocks is not None else None)
        while True:
            # an order the scan would step past only needs to be known above the band: a
            # certified lower bound of its μ there ends it without the upper bound
            above = (1.0 + ORDER_RISE) * full[1] if (
                auto and full[1] is not None and n < c["K"].nstates) else None
            rr = reduce_controller(P, c["K"], min(n, int(c["K"].nstates)), gp.nmeas, gp.ncon,
                                   blocks=blocks, omega=omega, full=full, mu_above=above)
            full = (rr.gamma_full, rr.mu_full)
            rise = rr.mu / rr.mu_full - 1 if rr.mu is not None else rr.gamma_rise
            if (np.isfinite(rr.gamma) and rise <= ORDER_RISE and not rr.mu_is_lower) \
                    or not auto \
                    or n >= c["K"].nstates:
                break
            n += gp.ncon
        score = rr.mu if rr.mu is not None else rr.gamma
        rows.append({"step": c["step"], "order_full": rr.order_full, "order": rr.order,
                     "mu_full": rr.mu_full, "mu": rr.mu, "gamma": rr.gamma})
        if np.isfinite(rr.gamma) and (best is None or score < best[0]):
            best = (score, rr, c)
    if best is None:
        raise SynthesisError(
            f"design: the order-{order} controller does not stabilise the design loop "
            f"(full order {cands[0]['K'].nstates}); set a larger design.order_max")
    _, rr, c = best
    red = rr.to_dict()
    red.pop("hsv", None)
    if len(rows) > 1:
        red.update(candidates=rows, kept=c["step"])
    gamma = float(rr.gamma) if rr.mu is None else float(c["gamma"])
    return rr.K, red, gamma, (float(rr.mu) if rr.mu is not None else None)


def _top_mode_hz(cfg, p: float, n: int) -> float:
    """The highest mode (Hz) an n-state design model keeps."""

    lam = np.abs(poles_near_zero(build_system(cfg, pressure_bar=p), count=n).poles)
    return float(lam[min(n, lam.size) - 1] / (2 * np.pi))


def _margin_reaches(cfg, p: float, n: int, f_hz: float, dz: float) -> bool:
    """Whether a damping margin ``(f_hz, dz)`` lowers a lightly damped mode of the n-state
    design model at pressure ``p`` (bar): the plant the synthesis takes the margin on
    (:func:`~ambseal.design.plant.generalized_plant`'s reduced model,
    :func:`~ambseal.design.plant.less_damped`), not the full-order one, whose modes above
    the design model's would answer yes for a margin that leaves the next design as it
    was."""
    model = build_plant(cfg, reduced=True, pressure_bar=p, states=n)
    return less_damped(model, [(f_hz, dz)]) is not model


def _states_to_keep(cfg, p: float, mode_hz: float) -> int:
    """Design-model states that keep every mode of the supported rotor up to 1.1× mode_hz."""

    disk = poles_near_zero(build_system(cfg, pressure_bar=p), radius_rad_s=2.2 * np.pi * mode_hz)
    return int(np.sum(np.abs(disk.poles) / (2 * np.pi) < 1.1 * mode_hz))


def _lost_by(cfg, K, check, p: float) -> tuple[bool, bool, float]:
    """Whether the pressure and whether the speed lost the loop at ``check``'s condition:
    the loop, closed at the design pressure ``p`` and that speed, and at that pressure and
    the design speed, is unstable there too (a full-order check each, where the condition
    differs from the design point in both); and the design speed (Hz)."""
    f0 = cfg.operating.speed_rpm / 60.0
    other_p = abs(check["pressure_bar"] - p) > 1e-9
    other_f = abs(check["speed_hz"] - f0) > 1e-9
    if not (other_p and other_f):
        return other_p, other_f, f0
    lost = [not full_order_check(cfg, K, [c], sampled=on_sampled_plant(cfg))["stable"]
            for c in ((check["pressure_bar"], f0), (p, check["speed_hz"]))]
    return lost[0] or not lost[1], lost[1], f0


def _outside(cfg, params, check, p: float) -> list[str]:
    """What the design was not robust to at ``check``'s condition: each uncertain
    parameter whose value there lies outside its range, and each parameter the design took
    as fixed whose value there differs from the design point's (pressure ``p`` bar, the
    design speed) by more than 1 %, one phrase each."""
    there = build_plant(cfg, pressure_bar=check["pressure_bar"],
                        speed_rpm=60.0 * check["speed_hz"]).parameters
    design_point = build_plant(cfg, pressure_bar=p).parameters
    ranges = {q.name: q for q in params}
    out = []
    for name, par in there.items():
        v, q = par.nominal, ranges.get(name)
        if q is not None and not q.low <= v <= q.high:
            out.append(f"{name} = {v:.4g} {par.unit} there, outside its range "
                       f"{q.low:.4g}–{q.high:.4g}")
        elif q is None and name in design_point and abs(
                v - (v0 := design_point[name].nominal)) > 0.01 * max(abs(v), abs(v0)):
            out.append(f"{name} = {v:.4g} {par.unit} there against {v0:.4g} in the design, "
                       "and not uncertain in it")
    return out


def _unstable_message(method, check, n, steps, cut_hz, lost=(True, False, 0.0),
                      outside=()) -> str:
    """The refusal's one line; ``lost`` = (by the pressure, by the speed, design speed Hz)
    of :func:`_lost_by`; ``outside``: :func:`_outside` of the design's parameters."""
    tried = f" after {len(steps)} automatic design step(s)" if steps else ""
    head = (f"design({method}): the controller destabilises the full-order plant{tried}: the "
            f"mode at {check['mode_hz']:.4g} Hz has damping ζ = {check['damping']:.3g} at "
            f"{check['pressure_bar']:g} bar, {check['speed_hz']:g} Hz; ")
    by_pressure, by_speed, f0 = lost
    if check["mode_hz"] < cut_hz and by_speed:
        # the gyroscopic moments move the mode with speed, which no seal range covers
        speed = (f"the design model keeps that mode as it is at the design speed "
                 f"({f0:.6g} Hz), and the gyroscopic moments move it at "
                 f"{check['speed_hz']:g} Hz: a controller scheduled on speed holds it over "
                 "the range (ambseal design --method lpv, with [operating] speed_range_hz; "
                 "ambseal run adds it)" + (
                     ", or μ, which takes the mode's frequency as uncertain over the band it "
                     "sweeps (ambseal design --method mu)" if method == "hinf" else ""))
        if not by_pressure:
            return head + speed + ", or pass --allow-unstable"
        return head + speed + (f"; the loop is lost at {check['pressure_bar']:g} bar at the "
                               "design speed too: that pressure needs the μ design with it in "
                               "[[design.uncertainty]]; or pass --allow-unstable")
    if check["mode_hz"] < cut_hz and method == "hinf":
        return head + (f"the design model keeps that mode; H∞ is designed on the nominal plant "
                       f"only ({check['pressure_bar']:g} bar is another plant): the μ design "
                       "with that condition in [[design.uncertainty]] is the robust one, or "
                       "pass --allow-unstable")
    if check["mode_hz"] < cut_hz and outside:
        return head + ("the design model keeps that mode, and the plant there is outside what "
                       "the design was robust to: " + "; ".join(outside) + ": a range in "
                       "[[design.uncertainty]] that covers it holds it, or pass "
                       "--allow-unstable")
    if check["mode_hz"] < cut_hz:
        # robust to every parameter there: what the design model leaves out lost it
        return head + ("the design model keeps that mode and the plant there is within every "
                       "uncertain range, so what the design model leaves out (the sampling, "
                       "the modes it truncates) took its damping: a lower bandwidth holds it "
                       f"(a smaller [design.{method}] omega_b_rad_s), or more design-model "
                       "states (design.model_states); or pass --allow-unstable")
    return head + (f"the design model ({n} states) should keep it: set "
                   f"design.model_cutoff_hz above {check['mode_hz']:.4g} (or "
                   "design.model_states), or pass --allow-unstable")


def full_order_words(check: Mapping) -> str:
    """The full-order check of a controller (:func:`full_order_check`) in the words of a
    design's verdict.

    Parameters
    ----------
    check : mapping
        :func:`full_order_check`'s result: ``stable``, and the least stable condition's
        ``mode_hz`` and ``pressure_bar``.

    Returns
    -------
    str
        ``"full-order loop stable at every judged condition"``, or ``"FULL-ORDER LOOP
        UNSTABLE at <f> Hz, <p> bar"``.
    """
    return ("full-order loop stable at every judged condition" if check["stable"] else
            f"FULL-ORDER LOOP UNSTABLE at {check['mode_hz']:.4g} Hz, "
            f"{check['pressure_bar']:g} bar")


def _pid_verdict(d: Mapping) -> str:
    """The reference PID's verdict: it is given (or derived by a rule), not synthesised
    against a bound, so it has none; its loop is judged as every controller's is."""
    what = ("a PID derived from the rig by its rule (no [controller.pid])" if "rule" in d
            else "the rig's reference PID ([controller.pid], P5 Eq. 6), given")
    return f"no design bound (γ, μ): {what}, not synthesised against one"


def _verdict(method, r: _Synthesis, check) -> str:
    """One plain line: robust performance met, on its boundary (μ within
    :data:`MU_BOUNDARY_RTOL` of 1) or not met, and the full-order stability."""
    stab = full_order_words(check)
    relaxed = _level_words(r.level)
    if method == "hinf":
        if r.scheduled is not None:
            return (f"H∞ γ = {r.gamma:.3g} on the design model frozen at each of its "
                    f"{r.scheduled.table_theta.size} table speeds, scheduled on speed (no "
                    f"bound between them); {stab}")
        if relaxed:
            return (f"H∞ γ = {r.gamma:.3g} on the design model with the spin speed uncertain"
                    f"{relaxed}; {stab}")
        return f"H∞ γ = {r.gamma:.3g} on the nominal design model; {stab}"
    # what the design model was robust to beyond [[design.uncertainty]]: the mode bands
    swept = (f", with the modes at {', '.join(b.text() for b in r.bands)} uncertain in "
             "frequency over the speed range" if r.bands else "") + relaxed
    if r.scheduled is not None:  # the worst entry's μ
        swept += (f" frozen at each of its {r.scheduled.table_theta.size} table speeds, "
                  "scheduled on speed (no bound between them)")
    # the band's edges as written: |0.98 − 1| is 0.020000000000000018 in binary
    if r.mu is not None and 1 - MU_BOUNDARY_RTOL <= r.mu <= 1 + MU_BOUNDARY_RTOL:
        return (f"robust performance on its boundary: μ = {bound_text(r.mu)}, within "
                f"{100 * MU_BOUNDARY_RTOL:g} % of 1 on the design model, met or missed as the "
                f"machine's rounding falls{swept}; {stab}")
    if r.mu is not None and r.mu <= 1:
        return (f"robust performance met: μ = {bound_text(r.mu)} ≤ 1 on the design model"
                f"{swept}; {stab}")
    by = "" if r.scheduled is not None else _dominant_weight(r)
    return (f"robust performance NOT met: μ = {bound_text(r.mu)} > 1: missed by "
            f"{100 * (r.mu - 1):.2g} %{by}{swept}; {stab}")


def bound_text(x: float) -> str:
    """A bound compared with 1 (μ, γ) in enough digits to be true on its side of 1:
    1.004 and 0.9995, never "1 > 1"."""
    gap = abs(x - 1.0)
    digits = 3 if gap >= 0.05 else 4 if gap >= 5e-3 else 5 if gap >= 5e-4 else 7
    return f"{x:.{digits}g}"


def _dominant_weight(r: _Synthesis) -> str:
    """Which weighted output (W_p, W_u) and input (W_1, W_2, W_f) carry the closed loop's
    largest gain at the μ peak frequency (a guide to which weight to relax)."""
    if r.mu_omega is None or r.K_P is None:
        return ""

    gp = r.gp
    cl = lft_lower(gp.P, r.K_P, gp.nmeas, gp.ncon)
    H = freqresp(cl, np.array([r.mu_omega]))[0]
    nd = gp.n_delta
    outs = [lab for lab in gp.P.output_labels[nd:] if not lab.startswith("y_")]
    ins = [lab for lab in gp.P.input_labels[nd:] if not lab.startswith("u_")]
    rows = {"W_p": [i for i, lab in enumerate(outs) if lab.startswith("zp_")],
            "W_u": [i for i, lab in enumerate(outs) if lab.startswith("zu_")]}
    cols = {"W_1": [j for j, lab in enumerate(ins) if lab.startswith("di_")],
            "W_2": [j for j, lab in enumerate(ins) if lab.startswith("do_")],
            "W_f": [j for j, lab in enumerate(ins) if lab.startswith("df_")]}
    Hp = H[nd:nd + len(outs), nd:nd + len(ins)]
    gain = {(a, b): np.linalg.norm(Hp[np.ix_(ri, cj)], 2)
            for a, ri in rows.items() for b, cj in cols.items() if ri and cj}
    a, b = max(gain, key=gain.get)
    return f"; at the peak ({r.mu_omega / (2 * np.pi):.4g} Hz) {a} on the {b} input dominates"
