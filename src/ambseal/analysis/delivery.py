"""Which controllers of a run failed, and why, in one plain line each.

``ambseal run`` judges every controller it could design and reports all of them; a
controller whose judged loop (:func:`ambseal.machine.loop.judged_loop`, the continuous loop
with the target's delay or the discrete loop as it runs) is unstable at a judged condition,
or that could not be designed at all, is *failed*. A designed controller that failed is not
delivered (no controller files are written for it unless the user asks with
``--allow-unstable``); the reference PID, given by the rig file rather than designed, is
marked the same way but is the user's own controller (or the one derived for them from the
rig), judged for comparison.

The verdict is the judged cases' own (``stable`` of each case and of its ``discrete``
block); the line names the least stable closed-loop mode of each failed condition by its
damped frequency and damping ratio ζ = −Re λ/|λ| (negative: growing), and, given the
means to (``kind_of``), by its kind: rigid cylindrical or conical, bending, its whirl
(:mod:`ambseal.analysis.mode_naming`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from ambseal.analysis.amplifier import capacity_words, saturates
from ambseal.config import method_label
from ambseal.design import machine

__all__ = ["FailedController", "case_label", "loop_failure", "saturation_failure",
           "synthesis_failure", "also_failed", "rig_clearances_um", "worst_orbit_um",
           "notched_orbit_um", "clearance_exceeded", "clearance_failure", "CLEARANCE_WORDS"]

#: How a sentence names each clearance of :func:`rig_clearances_um`.
CLEARANCE_WORDS = {"air gap": "the air gap", "backup bearing": "the backup bearing's clearance"}

#: Between a failure's head (the controller, delivered or not) and why.
_SEP = " — "


@dataclass(frozen=True)
class FailedController:
    """A controller of the run that failed.

    Attributes
    ----------
    reason : str
        One plain line: the controller, "not delivered" (or "reference PID"), and why.
    designed : bool
        True for a controller the run designed (H∞, μ, LPV, ...); False for the reference
        PID given by the rig file.
    judged : bool
        True when the controller exists and was judged (its cases are in ``cases``); False
        when its synthesis failed.
    conditions : list of str
        The judged conditions at which its loop is unstable (empty when not judged).
    """

    reason: str
    designed: bool
    judged: bool
    conditions: list[str] = field(default_factory=list)


def _name(method: str) -> str:
    return method_label(method)


def _head(method: str, designed: bool, kept: bool = False, derived: bool = False) -> str:
    if not designed:
        source = "derived from the rig" if derived else "given by the rig file"
        return f"{_name(method)} (reference, {source}): fails"
    return (f"{_name(method)}: delivered as asked (allow_unstable) but fails" if kept else
            f"{_name(method)}: not delivered")


def _least_stable(poles, discrete_dt: float | None = None) -> complex | None:
    """The least stable of closed-loop poles as a rate (rad/s): 's' poles, or 'z' poles
    of a loop sampled at ``discrete_dt`` (s), mapped to s by λ = ln z / dt."""
    lam = np.asarray(poles, complex).ravel()
    if discrete_dt:
        lam = np.log(lam[np.abs(lam) > 0]) / discrete_dt
    return complex(lam[int(np.argmax(lam.real))]) if lam.size else None


def _mode_text(z: complex | None) -> str:
    """``"mode at f Hz, ζ = …"`` of a pole (rad/s)."""
    if z is None:
        return ""
    zeta = -z.real / max(abs(z), 1e-300)
    return f"mode at {abs(z.imag) / (2 * math.pi):.4g} Hz, ζ = {zeta:.2g}".replace("-", "−")


#: Unstable conditions a failure names one by one; beyond them it lists the conditions and
#: names the least stable one's mode.
_NAMED = 4


def _listed(found: list[tuple], kind=None) -> str:
    """``(label, mode text, rank, case, pole)`` of each unstable condition as one phrase:
    each with its mode, or, beyond :data:`_NAMED`, the labels and the mode of the highest
    rank (the rightmost pole's real part, or max |z|); each named mode with its kind when
    ``kind(case, pole)`` gives one."""
    def mode(f):
        k = kind(f[3], f[4]) if kind is not None and f[4] is not None else None
        return f"{f[1]}, {k}" if k else f[1]

    if len(found) <= _NAMED:
        return " and ".join(f"{f[0]} ({mode(f)})" for f in found)
    worst = max(found, key=lambda f: -math.inf if f[2] is None or isinstance(f[2], str)
                else f[2])
    return (f"{len(found)} conditions: {'; '.join(f[0] for f in found)} "
            f"(the least stable {worst[0]}: {mode(worst)})")


def case_label(case, with_speed: bool = False) -> str:
    """A judged case's condition in words: its label (its pressure drop where it has
    none), or with ``with_speed`` its pressure drop and speed (``"<p> bar, <f> Hz"``, as
    the stability speeds are labelled) where the label leaves the speed out.

    Parameters
    ----------
    case : JudgedCase or StabilityCase
        ``label``, ``pressure_bar`` and ``speed_hz``.
    with_speed : bool
        Name the speed too: where a run judges other speeds besides a point labelled by
        its pressure alone, "<p> bar" would not say at which speed.

    Returns
    -------
    str
    """
    label = case.label or f"{case.pressure_bar:g} bar"
    if with_speed and not label.endswith(" Hz"):
        return f"{case.pressure_bar:g} bar, {case.speed_hz:g} Hz"
    return label


def loop_failure(method: str, judged: list[tuple[dict, dict]], designed: bool,
                 kept: bool = False, derived: bool = False,
                 kind_of=None, speed_in_labels: bool = False,
                 as_runs_only: bool = False) -> FailedController | None:
    """The failure of one controller from its judged cases, or None when every judged
    loop (continuous and, where judged, discrete) is stable.

    Parameters
    ----------
    method : str
        The controller's method (``"pid"``, ``"hinf"``, ...).
    judged : list of (case, curves)
        Its cases — :class:`~ambseal.analysis.judge.JudgedCase` or
        :class:`~ambseal.analysis.speed_range.StabilityCase`: ``label``, ``pressure_bar``,
        ``stable``, ``max_real_pole`` and ``discrete`` (None, or with ``stable``,
        ``max_abs_pole_z`` and ``sample_rate_hz``) — with the curves of
        :func:`ambseal.analysis.judge.judge` (``poles``: closed-loop poles, rad/s; the
        discrete loop's under ``curves["discrete"]["poles"]``, z).
    designed : bool
        False for the reference PID of the rig file.
    kept : bool
        True when the run delivers it all the same (``allow_unstable``): said in the line.
    derived : bool
        The reference PID was derived from the rig (no ``[controller.pid]``), not given
        by it: said in the line.
    kind_of : callable, optional
        ``kind_of(case, pole) → str or None``: the kind of the mode of ``pole`` (rad/s) at
        that case's condition (:func:`ambseal.analysis.mode_naming.failing_mode_kind`),
        asked only for the modes the line names.
    speed_in_labels : bool
        In the line, name each condition whose label leaves its speed out by pressure drop
        and speed (``"<p> bar, <f> Hz"``, as the stability speeds are named): a rig
        judged in full at one speed labels those points by pressure alone, and where the
        run judges other speeds as well, "unstable at <p> bar" would not say at which. The
        failure's ``conditions`` keep the cases' labels.
    as_runs_only : bool
        The controller is judged as it runs alone (a design on the sampled plant,
        :func:`ambseal.analysis.judge.judge_jobs`): a case's loop is then the one as it
        runs, and its loss is said so, with its largest ``|z|``.

    Returns
    -------
    FailedController or None
    """

    cont, pade_only, disc_parts, where = [], [], [], []
    for case, curves in judged:
        label = case_label(case)
        said = case_label(case, speed_in_labels)
        if not case.stable and not (as_runs_only and case.discrete is not None):
            z = _least_stable(curves.get('poles', ()))
            # the delay's Padé approximation can lose a mode the loop as it runs keeps:
            # still a failure (a margin of nothing), said as what it is
            held = case.discrete is not None and case.discrete.stable
            (pade_only if held else cont).append(
                (said, _mode_text(z), case.max_real_pole, case, z))
            where.append(label)
            continue
        disc = case.discrete
        if disc is not None and not disc.stable:
            z = _least_stable((curves.get("discrete") or {}).get("poles", ()),
                              1.0 / disc.sample_rate_hz)
            disc_parts.append((said, f"{_mode_text(z)}, max |z| = {disc.max_abs_pole_z:.5f}",
                               disc.max_abs_pole_z, case, z))
            where.append(label)
    parts = ([f"the full-order loop is unstable at {_listed(cont, kind_of)}"] if cont else []
             ) + ([f"the full-order loop with the delay as its Padé approximation is unstable "
                   f"at {_listed(pade_only, kind_of)}, though as it runs on the target "
                   f"(sampled, delayed) it holds there"] if pade_only else []
             ) + ([f"as it runs on the target (sampled, delayed) the loop is unstable at "
                   f"{_listed(disc_parts, kind_of)}"] if disc_parts else [])
    if not parts:
        return None
    return FailedController(f"{_head(method, designed, kept, derived)}{_SEP}" + "; ".join(parts),
                            designed, True, where)


def saturation_failure(method: str, capacity: dict | None, designed: bool,
                       kept: bool = False, derived: bool = False) -> FailedController | None:
    """The failure of a controller whose amplifiers saturate holding the judged unbalance
    (:func:`ambseal.analysis.amplifier.saturates`), or None.

    Parameters
    ----------
    method : str
        The controller's method.
    capacity : dict or None
        Its :func:`~ambseal.analysis.amplifier.capacity_block`.
    designed, kept, derived : bool
        As :func:`loop_failure`.

    Returns
    -------
    FailedController or None
        Judged; its condition the one where the largest fraction is used.
    """
    if not saturates(capacity):
        return None
    worst = max(capacity["worst"], key=lambda q: capacity[q])
    where = capacity["worst"][worst]["condition"]
    return FailedController(f"{_head(method, designed, kept, derived)}{_SEP}"
                            f"{capacity_words(capacity)}", designed, True, [where])


def rig_clearances_um(cfg) -> dict[str, float]:
    """Clearances (µm) the unbalance orbit is judged against: the nominal AMB air gap
    (:func:`ambseal.design.specs.machine`: ``air_gap``, or Ki·i0/Ks) and the smallest
    backup-bearing clearance (:meth:`~ambseal.config.RigConfig.backup_clearance`), those
    the rig gives.

    Parameters
    ----------
    cfg : RigConfig
        The rig.

    Returns
    -------
    dict of str to float
        ``"air gap"`` and ``"backup bearing"`` (µm), those the rig gives.
    """

    out = {}
    gap = machine(cfg).air_gap_m if cfg.amb else None
    if gap:
        out["air gap"] = gap * 1e6
    backup = [g for g in map(cfg.backup_clearance, cfg.amb) if g]
    if backup:
        out["backup bearing"] = min(backup) * 1e6
    return out


def worst_orbit_um(cases) -> float | None:
    """The largest worst-case unbalance orbit of a controller's judged cases.

    Parameters
    ----------
    cases : sequence of mapping
        Its judged cases, ``metrics.json`` form: each stable loop's ``unbalance_peak_um``
        and its ``discrete`` block's (the loop as it runs) count.

    Returns
    -------
    float or None
        The orbit (µm); None where no case has one.
    """
    vals = [v for c in cases for v in (c.get("unbalance_peak_um") if c.get("stable") else None,
                                       (c.get("discrete") or {}).get("unbalance_peak_um"))
            if v is not None]
    return max(vals) if vals else None


def notched_orbit_um(curves, on_hz: float, with_um: float) -> float:
    """The worst unbalance orbit of a controller delivered with its unbalance force
    rejection: the controller alone below the speed its notch switches on at, the notch's
    orbit from there up. The same controller's orbit alone over every speed
    (:func:`worst_orbit_um`) is not what runs where the notch is on: through a critical
    speed the notch lets the rotor turn about its inertia axis, with a larger orbit.

    Parameters
    ----------
    curves : iterable of (ndarray, ndarray)
        The controller alone, each judged loop that holds (continuous and as it runs): its
        unbalance response's speeds (Hz, shape (S,)) and worst orbit (µm, shape (S,)).
    on_hz : float
        The speed (Hz) the notch is on from.
    with_um : float
        The largest orbit (µm) with the notch on, over the speeds it is on at
        (:func:`ambseal.analysis.rejection.rejection_effect`'s ``orbit_um["with"]``).

    Returns
    -------
    float
        The orbit (µm, zero-to-peak).
    """
    below = [np.asarray(r, float)[np.asarray(s, float) < on_hz] for s, r in curves]
    return max([float(with_um), *(float(b.max()) for b in below if b.size)])


def clearance_exceeded(orbit_um: float | None,
                       clearances_um: dict | None) -> tuple[str, float] | None:
    """The smallest clearance the unbalance orbit exceeds: an orbit larger than the backup
    bearing's clearance runs the rotor on its backup bearings, one larger than the air gap
    into the stator.

    Parameters
    ----------
    orbit_um : float or None
        The worst unbalance orbit (µm, zero-to-peak), :func:`worst_orbit_um`.
    clearances_um : mapping of str to float or None
        :func:`rig_clearances_um` of the rig (µm).

    Returns
    -------
    (str, float) or None
        The clearance's name and size (µm); None where the orbit exceeds none.
    """
    over = [(c, n) for n, c in (clearances_um or {}).items()
            if c and orbit_um is not None and orbit_um > c]
    if not over:
        return None
    c, n = min(over)
    return n, c


def clearance_failure(method: str, cases, clearances_um: dict | None, designed: bool,
                      kept: bool = False, derived: bool = False) -> FailedController | None:
    """The failure of a controller whose worst unbalance orbit (:func:`worst_orbit_um`)
    exceeds a clearance of the rig (:func:`clearance_exceeded`), or None.

    Parameters
    ----------
    method : str
        The controller's method.
    cases : sequence of dict
        Its judged cases, ``metrics.json`` form.
    clearances_um : dict or None
        :func:`rig_clearances_um` of the rig.
    designed, kept, derived : bool
        As :func:`loop_failure`.

    Returns
    -------
    FailedController or None
        Judged; its conditions those whose orbit exceeds the clearance.
    """
    orbit = worst_orbit_um(cases)
    over = clearance_exceeded(orbit, clearances_um)
    if over is None:
        return None
    name, c = over
    where = [c_["label"] for c_ in cases if (worst_orbit_um([c_]) or 0.0) > c]
    return FailedController(f"{_head(method, designed, kept, derived)}{_SEP}the worst unbalance "
                            f"orbit, {orbit:.3g} µm, exceeds {CLEARANCE_WORDS.get(name, name)} "
                            f"({c:.3g} µm)", designed, True, where)


def synthesis_failure(method: str, why: str) -> FailedController:
    """The failure of a controller whose design raised (``why``: the error's message).

    Parameters
    ----------
    method : str
        The controller method (a key of :data:`ambseal.config.METHODS`).
    why : str
        The synthesis error's message.

    Returns
    -------
    FailedController
        Designed, not judged.
    """
    return FailedController(f"{_head(method, True)}{_SEP}the design failed: {why}", True, False)


def also_failed(first: FailedController | None, more: FailedController) -> FailedController:
    """One controller's failure with what another judgement found added: ``more``'s reason
    (without its head) and conditions after ``first``'s; ``more`` when ``first`` is None.

    Parameters
    ----------
    first : FailedController or None
        The failure found first (with any remedies tried in its reason).
    more : FailedController
        The same controller's failure at further conditions (:func:`loop_failure`).

    Returns
    -------
    FailedController
    """
    if first is None:
        return more
    why = more.reason.split(_SEP, 1)[-1]
    return FailedController(f"{first.reason}; {why}", first.designed, first.judged,
                            [*first.conditions, *more.conditions])
