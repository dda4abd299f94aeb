"""What ``ambseal run`` tries before it reports a designed controller failed.

The H∞ and μ recipes (:func:`ambseal.design.recipes.design`) design at the rig's operating
pressure. When the judgement finds a condition where the controller's full-order loop is
unstable (continuous with the delay, or sampled and delayed as it runs), the run tries, in
this order, and judges each attempt at every condition like the first design:

1. **the worst condition**: the same recipe designed at the pressure of the failing case
   whose loop is least stable (largest closed-loop real part; for a loop unstable only as
   it runs, largest |z|) — the plant the design missed is the one it is designed for;
2. **a wider margin**: that design with the performance weight's bandwidth ω_B halved — the
   controller asks for less and leaves more phase margin to the seal-driven modes it
   does not see exactly (Skogestad & Postlethwaite 2005, §2.8 and §3.4.6: a lower ω_B
   trades performance for robustness).

The first attempt that holds at every judged condition replaces the design, its summary
saying so (``remedy``). When none holds, the failure line lists what was tried; the μ
controller, robust to the specification's uncertainty (thesis P5 §4), is the run's robust
one. A speed-scheduled rig's designs (frozen at a speed, or scheduled on it) get no
remedy here: their schedule is the remedy.

**A loop lost only as it runs** — the continuous loop with the delay holds at every
judged condition and stability speed, but the discrete controller's sampled loop does
not, or no discretisation runs it at all — is a gap between the loop designed and the
loop that runs, which neither remedy above closes: the design is made again on the
sampled, delayed plant in the w-plane (:func:`on_the_sampled_plant`, ``[design]
synthesis_plant = "sampled"``), whose discrete controller is its Tustin transform
exactly, and replaces the first where it holds at every judged condition and stability
speed as it runs, the only loop it has (:func:`ambseal.analysis.judge.judge_jobs`;
benchmarks/README.md, "The sampled design as the run's remedy for a loop lost only as it
runs" and "A design on the sampled plant judged as it runs").

**An H∞ or μ over the speed range that holds the loop beyond ISO 14839-3 zone B** — a
fixed design whose loops all hold from standstill to the top speed, but whose σ̄(S_o) on
an axis as it runs reaches zone C or D somewhere — is designed again scheduled on the
spin speed
(:func:`scheduled_on_speed`, :func:`ambseal.design.recipes.design` with
``scheduled_on_speed``): each table entry is the central controller of the plant at its
own speed, not one controller stretched over the range. It replaces the first where it
holds every judged condition and stability speed at a better worst zone. Measured on the
gyroscopic family (benchmarks/README.md, "The schedule as the remedy for a zone beyond
B"): seed 9's fixed H∞ reached σ̄(S_o) 8.22 at standstill, its schedule 2.56 (zone A).

**An H∞ or μ whose loops hold but that needs more current than the amplifier has to hold
the unbalance** — at a judged speed from the minimum continuous one up (below it, through a
critical speed, the run's notch switches on instead: :func:`ambseal.analysis.amplifier.
switch_on_hz`) its synchronous current reference uses more than
the bias current's linear range, the current limit or the supply
(:func:`ambseal.analysis.amplifier.used_by_speed`) — is designed again with the
amplifier's limit in its control weight (:func:`within_the_amplifier`): W_u gets a
synchronous peak (:func:`ambseal.design.weights.peak_weight`) at the speed where the
current is largest, h times the weight there, so the synthesis itself bounds
``|K S_o|`` at that frequency; the synchronous current is ``K S_o G_f F_u``. Each
redesign multiplies the height by the fraction its design before used over
:data:`AMPLIFIER_TARGET`, and at least by :data:`AMPLIFIER_STEP` (a peak below the
bound the rest of the loop sets moves little: on the rigid gyroscopic rotor of
tests/test_amplifier_remedy.py μ's synchronous current at the trip speed fell 3 % with
a peak of 2, 26 % with 8 and 55 % with 32, H∞'s 23 % with 4; benchmarks/README.md, "The
amplifier's limit inside the design"), until the
current fits (the redesign replaces the first where its loops all hold within ISO
14839-3 zone B, or no worse than the first's, its unbalance orbit within the rig's
clearances and its current impulse within the amplifier), or a step lowers it by less than
1 − :data:`AMPLIFIER_STALL`: then the first design stays, and the run's unbalance force
rejection (Herzog et al., IEEE TCST 4(5), 1996) is what is left. The current cannot
always be bought: where the rotor's synchronous compliance is large (a disc whose
I_p is near I_t resists a conical whirl at Ω with (I_p − I_t)Ω² only), the loop's gain
at Ω stays high whatever the weight, T_i ≈ 1 and the bearings carry the unbalance; less
current there is a larger orbit (the flywheel example's rig without its notch: μ needs
1.21× the bias range at the trip speed with and without the peak, and H∞'s peak that
fits its amplifier lets the orbit reach 765 µm against a 250 µm backup clearance).
A μ redesign is by complex D–K (``mu_iteration = "dk"``, its real parameters taken as
complex: μ is then a conservative upper bound of the mixed μ): the peak is a demand beyond
the specification, which can lift μ above 1, and there D–G–K's steps, whose all-pass
fits of the real parameters' G scalings take most of their time, cost 25× the complex
design (the test rig with a 1 V supply, W_u × 16: 206 s against 7.6 s; benchmarks/
README.md, "The amplifier's redesign of μ by complex D–K"); what a redesign must meet
to replace the first is judged on its full-order loops whatever its μ.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, replace

import numpy as np

from ambseal.analysis import (
    ZONE_SCALE,
    FailedController,
    JudgedCase,
    case_label,
    loop_failure,
    worst_zone,
)
from ambseal.app.commands import Designed, digitals_for
from ambseal.config import method_label, method_names
from ambseal.design import design, uncertainty_at
from ambseal.errors import ConfigError, SynthesisError

__all__ = ["Remedied", "on_the_sampled_plant", "remedy", "scheduled_on_speed",
           "within_the_amplifier", "worst_case", "worst_zone_as_runs", "AMPLIFIER_TARGET",
           "AMPLIFIER_STALL", "AMPLIFIER_STEP"]

#: Factor on the performance weight's bandwidth ω_B in the second attempt.
OMEGA_B_FACTOR = 0.5

#: The fraction of its amplifier a redesign within it aims at: the judged speeds are a
#: grid, and the current between two of them and the held value's harmonics take a share.
AMPLIFIER_TARGET = 0.8

#: A redesign within the amplifier that leaves more than this fraction of the current of
#: the one before has stalled: a higher peak no longer buys current (the loop needs its
#: gain at that frequency).
AMPLIFIER_STALL = 0.95

#: The least factor by which each redesign within the amplifier raises its peak.
AMPLIFIER_STEP = 4.0


@dataclass(frozen=True)
class Remedied:
    """A design that holds at every judged condition after a remedy.

    Attributes
    ----------
    design : Designed
        The new design (its summary has ``remedy``: what was done and why).
    digital : object
        Its digital controller.
    jobs, judged : list
        Its judged cases, as the run's judgement makes them.
    """

    design: Designed
    digital: object
    jobs: list
    judged: list


def worst_case(cases: list[JudgedCase]) -> JudgedCase:
    """The least stable failing case: the largest continuous closed-loop real part among
    the continuously unstable ones, else the largest |z| among those unstable as they run.

    Parameters
    ----------
    cases : list of JudgedCase or StabilityCase
        Judged cases of one controller (``stable``, ``max_real_pole``, ``discrete``), at
        least one failing.

    Returns
    -------
    JudgedCase or StabilityCase

    Raises
    ------
    ValueError
        No case fails.
    """
    cont = [c for c in cases if not c.stable]
    if cont:
        return max(cont, key=lambda c: c.max_real_pole)
    disc = [c for c in cases if c.discrete is not None and not c.discrete.stable]
    if not disc:
        raise ValueError("worst_case: no failing case")
    return max(disc, key=lambda c: c.discrete.max_abs_pole_z)


def remedy(method: str, failure: FailedController, cases: list[JudgedCase], design_cfg, spec,
           points, judge: Callable, say: Callable[[str], None], *,
           speed_in_labels: bool = False) -> tuple[Remedied | None, FailedController]:
    """Try the remedies of the module docstring for one failed design.

    Parameters
    ----------
    method : {"hinf", "mu"}
    failure : FailedController
        Its failure as judged.
    cases : list of JudgedCase
        Its judged cases.
    design_cfg : RigConfig
        The rig the run designs on (the identified one after identification).
    spec : DesignSpec
        The rig's design specification (weights, design model, grids).
    points : list of OperatingPoint
        The judged conditions.
    judge : callable
        ``judge(designs, digitals) -> (jobs, judged)``: the run's judgement of designs
        (:func:`ambseal.analysis.judge.judge_jobs` and the cases' curves).
    say : callable
        Progress lines.
    speed_in_labels : bool
        The run judges the speed range besides points labelled by their pressure drop
        alone: the words name each condition by pressure drop and speed
        (:func:`~ambseal.analysis.delivery.case_label`).

    Returns
    -------
    (Remedied or None, FailedController)
        The first design that holds and the original failure, or None and the failure with
        the remedies tried added to its reason.
    """
    def named(conditions, judged_cases) -> str:
        # each condition as the line names it; "; " since one named with its speed holds
        # a comma itself
        by_label = {case_label(c): case_label(c, speed_in_labels) for c in judged_cases}
        return "; ".join(by_label.get(c, c) for c in conditions)

    worst = worst_case(cases)
    p = float(worst.pressure_bar)
    base = spec.weights[method]
    wider = replace(base, omega_b=base.omega_b * OMEGA_B_FACTOR)
    # named by the pressure it is designed at: the worst condition's speed, where its
    # label holds one, is not where it is designed
    attempts = [(f"designed at {p:g} bar", base),
                (f"designed there with ω_B × {OMEGA_B_FACTOR:g} ({wider.omega_b:.3g} rad/s)",
                 wider)]
    tried = []
    # the specification's uncertainty, a relative range of a coefficient that is 0 there (a
    # seal at 0 bar) kept at the width it has where the specification was made
    try:
        ranges = uncertainty_at(design_cfg, spec.uncertainty, p, spec.nominal_pressure_bar)
    except ConfigError as exc:
        return None, replace(failure, reason=f"{failure.reason}. Not tried: {exc}")
    for label, w in attempts:
        say(f"{method}: remedy — {label}")
        try:
            res = design(design_cfg, method, pressure_bar=p, weights=w, spec=spec,
                         uncertainty=ranges, allow_unstable=True)
        except (SynthesisError, ConfigError) as exc:
            tried.append(f"{label} (the design failed: {exc})")
            continue
        d = Designed(res, {**res.summary(), "remedy": (
            f"{label}: the design at the operating point lost the loop at "
            f"{named(failure.conditions, cases)}")})
        digitals, cannot = digitals_for(design_cfg, [d], points)
        if method not in digitals:
            tried.append(f"{label} (cannot run on the target: {cannot.get(method, '')})")
            continue
        jobs, judged = judge([d], digitals)
        again = loop_failure(method, judged, designed=True,
                             as_runs_only=d.synthesis_plant == "sampled")
        if again is None:
            say(f"{method}: {label} holds at every judged condition")
            return Remedied(d, digitals[method], jobs, judged), failure
        tried.append(f"{label} (still unstable at "
                     f"{named(again.conditions, [c for c, _ in judged])})")
    why = "; ".join(tried)
    return None, replace(failure, reason=f"{failure.reason}. Tried: {why}"
                         + ("" if method in method_names(robust=True) else
                            f"; {' and '.join(map(method_label, method_names(robust=True)))} "
                            "is the robust controller"))


def on_the_sampled_plant(method: str, why: str, design_cfg, spec, points, judge: Callable,
                         stability: Callable, say: Callable[[str], None]
                         ) -> tuple[Remedied | None, list, str]:
    """``method`` designed again on the sampled plant (module docstring), for a design whose
    loop is lost only as it runs.

    Parameters
    ----------
    method : {"hinf", "mu"}
    why : str
        Why the first design is redesigned (its summary's ``remedy`` says so).
    design_cfg, spec, points, judge, say
        As for :func:`remedy`.
    stability : callable
        ``stability(designs, digitals) -> [(case, curves)]``: the run's stability cases at
        the speed range's conditions not judged in full (:func:`ambseal.analysis.
        stability_case`); empty where there are none.

    Returns
    -------
    (Remedied or None, list, str)
        The new design where it holds at every judged condition and stability speed, and
        its stability cases; else None, [] and what was tried, for the failure's line.
    """
    cfg = design_cfg.model_copy(update={"design": design_cfg.design.model_copy(
        update={"synthesis_plant": "sampled"})})
    label = "designed on the sampled plant (w-plane, its Tustin transform the discrete design)"
    got, words = _redesigned(method, label, why, cfg, points, judge, stability, say,
                             lambda: design(cfg, method, spec=spec, allow_unstable=True),
                             as_runs_only=True)
    if got is None:
        return None, [], words
    d, digital, jobs, judged, cases, lost = got
    if not lost:
        say(f"{method}: {label} holds at every judged condition")
        return Remedied(d, digital, jobs, judged), [c for c, _ in cases], ""
    # each failure's own words (which loop, where, the least stable mode), not its head
    return None, [], f"{label}: " + "; ".join(f.reason.split(" — ", 1)[-1] for f in lost)


def worst_zone_as_runs(cases) -> str | None:
    """The worst ISO 14839-3 grade on any axis of judged cases, each as it runs where it
    was judged so (its ``discrete`` loop), else as judged in continuous time.

    ISO 14839-3:2006 grades the sensitivity function of each control axis
    (:mod:`ambseal.analysis.iso`), as the run's delivery does; the thesis's σ̄(S_o) over
    all axes together (P5 §4.1 item 4), stricter where the axes couple, stands in only for
    a case judged without per-axis grades. On family seed 17 the design on the sampled
    plant is zone A on every axis while σ̄(S_o) is 5.8: a redesign is not called for.

    Parameters
    ----------
    cases : iterable of JudgedCase
        Judged cases (:func:`ambseal.analysis.judge.judge_jobs`, or the speed range's
        stability cases).

    Returns
    -------
    str or None
        A name of :data:`ambseal.analysis.ZONE_SCALE`; None where no case has a grade.
    """
    loops = [c.discrete if c.discrete is not None else c for c in cases]
    return worst_zone(z for c in loops
                      for z in ((c.iso_zone_per_axis or {}).values() or [c.iso_zone]))


def scheduled_on_speed(method: str, zone: str, design_cfg, spec, points, judge: Callable,
                       stability: Callable, say: Callable[[str], None]
                       ) -> tuple[Remedied | None, list, str]:
    """``method`` (H∞ or μ) designed again scheduled on the spin speed (module docstring),
    for a fixed design over the speed range whose loops hold at worst grade ``zone``.

    Parameters
    ----------
    method : {"hinf", "mu"}
    zone : str
        The first design's worst grade as it runs (:func:`worst_zone_as_runs`), beyond B.
    design_cfg, spec, points, judge, stability, say
        As for :func:`on_the_sampled_plant`.

    Returns
    -------
    (Remedied or None, list, str)
        The new design where it holds at every judged condition and stability speed at a
        better worst grade than ``zone``, and its stability cases; else None, [] and what
        was tried, for the design's notes.
    """
    label = "designed scheduled on the spin speed"
    why = f"the fixed design over the speed range reaches ISO 14839-3 zone {zone} as it runs"
    got, words = _redesigned(method, label, why, design_cfg, points, judge, stability, say,
                             lambda: design(design_cfg, method, spec=spec,
                                            scheduled_on_speed=True))
    if got is None:
        return None, [], words
    d, digital, jobs, judged, cases, lost = got
    if lost:
        return None, [], f"{label}: " + "; ".join(f.reason.split(" — ", 1)[-1] for f in lost)
    again = worst_zone_as_runs([c for c, _ in judged] + [c for c, _ in cases])
    if again is None or ZONE_SCALE.index(again) >= ZONE_SCALE.index(zone):
        return None, [], f"{label}: zone {again} as it runs, no better"
    say(f"{method}: {label} holds at every judged condition, zone {again} as it runs")
    return Remedied(d, digital, jobs, judged), [c for c, _ in cases], ""


def _redesigned(method: str, label: str, why: str, cfg, points, judge: Callable,
                stability: Callable, say: Callable[[str], None], make: Callable, *,
                as_runs_only: bool = False):
    """A redesign of ``method`` (``make()``, a DesignResult) judged as the run judges its
    first: ``((design, digital, jobs, judged, stability cases, failures), "")``, the
    failures of its judged conditions and stability speeds (empty where it holds); or
    ``(None, words)`` where it has no design or cannot run on the target."""
    say(f"{method}: {why}: {label}")
    try:
        res = make()
    except (SynthesisError, ConfigError) as exc:
        return None, f"{label}: the design failed: {exc}"
    d = Designed(res, {**res.summary(), "remedy": f"{label}: {why}"})
    digitals, cannot = digitals_for(cfg, [d], points)
    if method not in digitals:
        return None, f"{label}: cannot run on the target: {cannot.get(method, '')}"
    jobs, judged = judge([d], digitals)
    cases = stability([d], digitals)
    lost = [f for f in (loop_failure(method, judged, designed=True, as_runs_only=as_runs_only),
                        loop_failure(method, cases, designed=True, as_runs_only=as_runs_only)
                        if cases else None)
            if f is not None]
    return (d, digitals[method], jobs, judged, cases, lost), ""


def within_the_amplifier(first, used: tuple, zone: str | None, design_cfg, spec, points,
                         judge: Callable, stability: Callable, amplifier: Callable,
                         beyond: Callable, say: Callable[[str], None]
                         ) -> tuple[Remedied | None, list, str]:
    """An H∞ or μ designed again with the amplifier's limit in its control weight (module
    docstring), for a design whose loops hold but whose unbalance current exceeds its
    amplifier.

    Parameters
    ----------
    first : Designed
        The design (its weights, its synthesis plant, whether scheduled on the spin speed;
        a redesign takes the same route).
    used : (ndarray, ndarray)
        Its judged speeds (Hz) and the largest fraction of an amplifier limit it uses at
        each (:func:`ambseal.analysis.amplifier.used_by_speed`), above 1 somewhere.
    design_cfg, spec, points, judge, stability, say
        As for :func:`on_the_sampled_plant`.
    amplifier : callable
        ``amplifier(jobs, judged) -> (speeds_hz, used)``: the same for a redesign's judged
        cases.
    beyond : callable
        ``beyond(jobs, judged) -> str or None``: what else of the delivery a redesign's
        judged cases fail, in words (the run's: an unbalance orbit beyond a clearance,
        :func:`ambseal.analysis.delivery.clearance_exceeded`, where less current at Ω is
        a larger orbit; an amplifier the current impulse saturates).

    Returns
    -------
    (Remedied or None, list, str)
        The redesign whose current fits, that fails nothing ``beyond`` names and whose
        loops hold at every judged condition and stability speed within zone B (or no
        worse than ``first``), and its stability cases; else None, [] and what was tried, for
        the design's notes.

    Raises
    ------
    ValueError
        ``used`` nowhere above 1.
    """
    method, res = first.method, first.result
    speeds, fraction = (np.asarray(x, float) for x in used)
    if not np.max(fraction) > 1:
        raise ValueError("within_the_amplifier: the design fits its amplifier")
    peak_hz = float(speeds[np.argmax(fraction)])
    cfg = design_cfg.model_copy(update={"design": design_cfg.design.model_copy(
        update={"synthesis_plant": res.synthesis_plant})})
    # a redesign may trade grade for current down to zone B, never below the first's
    allowed = max(ZONE_SCALE.index("B"), ZONE_SCALE.index(zone) if zone else 0)
    base = spec.weights[method]
    height, ratio, tried = 1.0, float(np.max(fraction)), []
    by = {"mu_iteration": "dk"} if method == "mu" else {}  # module docstring
    why = (f"it needs {ratio:.3g}× its amplifier to hold the unbalance at {peak_hz:.4g} Hz")
    while True:
        height *= max(ratio / AMPLIFIER_TARGET, AMPLIFIER_STEP)
        # the specification's weights with the peak: the recipe then adds what it adds to
        # its own (H∞'s orbit demand where it is scheduled on the spin speed)
        peaked = replace(spec, weights={**spec.weights, method: replace(
            base, wu_peak_hz=peak_hz, wu_peak_gain=height)}, **by)
        label = (f"designed with W_u × {height:.3g} at {peak_hz:.4g} Hz"
                 + (" by complex D–K" if by else ""))
        got, words = _redesigned(
            method, label, why, cfg, points, judge, stability, say,
            lambda peaked=peaked: design(cfg, method, spec=peaked,
                                         scheduled_on_speed=res.scheduled is not None),
            as_runs_only=res.synthesis_plant == "sampled")
        if got is None:
            return None, [], "; ".join([*tried, words])
        d, digital, jobs, judged, cases, lost = got
        if lost:
            return None, [], "; ".join([*tried, f"{label}: " + "; ".join(
                f.reason.split(" — ", 1)[-1] for f in lost)])
        grade = worst_zone_as_runs([c for c, _ in judged] + [c for c, _ in cases])
        if grade is not None and ZONE_SCALE.index(grade) > allowed:
            return None, [], "; ".join([*tried, f"{label}: zone {grade} as it runs"])
        other = beyond(jobs, judged)
        if other is not None:
            return None, [], "; ".join([*tried, f"{label}: {other}"])
        again = float(np.max(amplifier(jobs, judged)[1], initial=0.0))
        if again <= 1:
            say(f"{method}: {label} holds at every judged condition within its amplifier "
                f"({again:.3g}× at most), zone {grade} as it runs")
            if first.summary.get("remedy"):  # the way the first came, then this
                d.summary["remedy"] = f"{first.summary['remedy']}; then {d.summary['remedy']}"
            return Remedied(d, digital, jobs, judged), [c for c, _ in cases], ""
        tried.append(f"{label}: {again:.3g}× its amplifier")
        if again > AMPLIFIER_STALL * ratio:
            return None, [], "; ".join(tried) + " (no lower)"
        ratio = again
