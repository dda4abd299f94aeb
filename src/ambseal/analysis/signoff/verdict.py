"""A machine's sign-off: every criterion of API 617 and ISO 14839-2 per controller.

Per controller as it runs (the discrete controller with its computation delay; ``None``
for a rig on springs alone):

============================  ==========================================  ==============
criterion                     limit                                       source
============================  ==========================================  ==============
stability, Level I            δ_A ≥ 0.1, Q_0/Q_A ≥ 2; ≥ 10 or Region A    API 617 (8th ed., 2014) Part 1, Level I; API 684 (2nd ed.) SP6.8.5
stability, Level II           δ ≥ 0.1 with every source                   API 617 (8th ed.) Part 1, Level II
separation margins            each critical's SM ≥ the required           API 617 (8th ed.) Part 1 §4.8.2 (lateral analysis)
vibration at the probes       ≤ A_vl from minimum to trip speed           API 617 (8th ed.) Part 1 §4.8.2
close clearances              S_c·response ≤ 75 % of the clearance        API 617 (8th ed.) Part 1 §4.8.2.11 (S_c)
vibration zone                zone A or B at every AMB sensor             ISO 14839-2:2004
============================  ==========================================  ==============

A machine without ``[[stage]]`` (a flywheel, a motor, a pump without an aerodynamic
cross-coupling of its own) has no Level I; its Level II, on the rig's own sources (its
seals), decides, and the unbalance response and ISO 14839-2 are judged as for any other.
The stability holds when Level I passes and the loop with every source is stable, or,
where Level I asks for it, Level II passes: a machine whose loop with every source is
unstable at the maximum continuous speed is never signed off, whichever level found it
(Level I leaves the seals out). Each criterion is passed, failed or not graded (with
why: no close clearance or backup clearance given; the unbalance criteria on a loop
that is unstable, where no steady response exists), one :attr:`Criterion.outcome` for
the command line and the report alike; the machine passes when every controller meets
every criterion that counts and is graded. The clause numbers are
those ROSS's API report tool cites; where a limit could not be confirmed from the
standards' public text it is a ``[signoff]`` setting (:class:`ambseal.config.rig.Signoff`).
The modules: :mod:`~ambseal.analysis.signoff.level1`, :mod:`~ambseal.analysis.signoff.level2`,
:mod:`~ambseal.analysis.signoff.unbalance_api617`, :mod:`~ambseal.analysis.signoff.iso_vibration`.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

from ambseal.analysis.campbell import AF_CRITICAL
from ambseal.analysis.signoff.iso_vibration import iso14839_2_zones
from ambseal.analysis.signoff.level1 import RATIO_FREE, RATIO_MIN, level1_screening
from ambseal.analysis.signoff.level2 import level2_analysis
from ambseal.analysis.signoff.unbalance_api617 import api617_unbalance, journal_loads

__all__ = ["Criterion", "SignOff", "sign_off", "verdict_line", "critical_speeds_hz", "CLAUSES",
           "CRITICAL_SAME"]

#: The source of each criterion (module docstring).
CLAUSES = {
    "level1": "API 617 (8th ed., 2014) Part 1, stability Level I; API 684 (2nd ed.) SP6.8.5",
    "level2": "API 617 (8th ed., 2014) Part 1, stability Level II",
    "separation": "API 617 (8th ed., 2014) Part 1 §4.8.2, unbalance response",
    "vibration": "API 617 (8th ed., 2014) Part 1 §4.8.2, A_vl",
    "clearance": "API 617 (8th ed., 2014) Part 1 §4.8.2.11, scale factor S_c",
    "iso14839_2": "ISO 14839-2:2004, vibration zones",
}


@dataclass(frozen=True)
class Criterion:
    """One line of the sign-off: ``name``, its ``value`` and ``limit`` in words,
    ``source`` (edition and clause), ``passed``, whether it ``counts`` for the verdict
    (the stability is Level I's where it passes and the loop with every source is stable,
    else Level II's), and whether it was ``graded`` at all (``value`` then says why not;
    ``passed`` is False)."""

    name: str
    value: str
    limit: str
    source: str
    passed: bool
    counts: bool = True
    graded: bool = True

    @property
    def outcome(self) -> str:
        """``"passed"``, ``"FAILED"`` or ``"not graded"``; a stability level that does not
        count: ``"not needed"`` (Level II where Level I decides) or ``"Level II
        decides"`` (a Level I that asks for it)."""
        if not self.graded:
            return "not graded"
        if self.counts:
            return "passed" if self.passed else "FAILED"
        return "not needed" if self.name.endswith("II") else "Level II decides"

    def to_dict(self) -> dict:
        return {"criterion": self.name, "value": self.value, "limit": self.limit,
                "source": self.source, "passed": self.passed, "counts": self.counts,
                "graded": self.graded, "outcome": self.outcome}


@dataclass(frozen=True)
class SignOff:
    """Every sign-off analysis of one controller and its criteria (module docstring).

    Attributes
    ----------
    controller : str
    level1 : ambseal.analysis.signoff.level1.Level1 or None
        None for a machine without ``[[stage]]`` (Level I does not apply).
    level2 : ambseal.analysis.signoff.level2.Level2
    unbalance : ambseal.analysis.signoff.unbalance_api617.Api617Unbalance
    iso14839_2 : ambseal.analysis.signoff.iso_vibration.IsoVibration
    criteria : tuple of Criterion
    """

    controller: str
    level1: object
    level2: object
    unbalance: object
    iso14839_2: object
    criteria: tuple

    @property
    def passed(self) -> bool:
        return all(c.passed for c in self.criteria if c.counts and c.graded)

    @property
    def failed(self) -> list[str]:
        return [c.name for c in self.criteria if c.counts and c.graded and not c.passed]

    def to_dict(self) -> dict:
        """The controller's sign-off block: ``passed``, ``criteria`` and each analysis."""
        return {"passed": self.passed, "criteria": [c.to_dict() for c in self.criteria],
                "level1": None if self.level1 is None else self.level1.to_dict(),
                "level2": self.level2.to_dict(),
                "unbalance": self.unbalance.to_dict(),
                "iso14839_2": self.iso14839_2.to_dict()}


#: Peaks of the probes' responses within this relative distance are one critical speed
CRITICAL_SAME = 0.01


def critical_speeds_hz(criticals) -> list[float]:
    """The distinct critical speeds (Hz) among the peaks every probe and unbalance case
    found: the same resonance seen at two probes or under two placements is one critical
    speed (peaks within :data:`CRITICAL_SAME` of each other, relative), the mean of each
    group.

    Parameters
    ----------
    criticals : sequence of Critical
        :class:`ambseal.analysis.signoff.unbalance_api617.Critical` of every case and probe.

    Returns
    -------
    list of float
        Increasing.
    """
    groups: list[list[float]] = []
    for f in sorted(k.speed_hz for k in criticals):
        if groups and f <= groups[-1][0] * (1 + CRITICAL_SAME):
            groups[-1].append(f)
        else:
            groups.append([f])
    return [sum(g) / len(g) for g in groups]


def _criteria(cfg, l1, l2, unb, iso) -> tuple:
    d_min = cfg.signoff.log_dec_min
    limit1 = f"δ_A ≥ {d_min:g}, Q_0/Q_A ≥ {RATIO_MIN:g}; ≥ {RATIO_FREE:g} or Region A"
    if l1 is None:  # API 617's anticipated cross-coupling is an impeller's or a stage's
        rows = [Criterion("stability, Level I", "not applicable: no [[stage]] (no "
                          "impeller or stage whose anticipated cross-coupling to screen); "
                          "Level II decides with the rig's own sources", limit1,
                          CLAUSES["level1"], False, counts=False, graded=False)]
    else:
        q0 = "none up to 10·Q_A" if l1.Q_0 is None else f"Q_0/Q_A = {l1.ratio:.3g}"
        rows = [Criterion("stability, Level I",
                          f"δ_A = {l1.log_dec_A:.3g}, {q0}, CSR {l1.csr:.3g} (Region "
                          f"{l1.region})", limit1, CLAUSES["level1"], l1.passed,
                          counts=l1.passed)]
    passed1 = l1 is not None and l1.passed
    last = l2.rows[-1]
    rows.append(Criterion("stability, Level II",
                          f"δ = {last.log_dec:.3g} at {last.frequency_hz:.4g} Hz"
                          + (f" ({last.kind})" if last.kind else "")
                          + ("" if last.stable else ", loop UNSTABLE"),
                          f"δ ≥ {d_min:g} with every source", CLAUSES["level2"], l2.passed,
                          counts=not (passed1 and last.stable)))
    crit = [k for c in unb.cases for k in c.criticals]
    sharp = [k for k in crit if k.af >= AF_CRITICAL]
    worst = min(sharp, key=lambda k: k.actual_margin_pct - k.required_margin_pct,
                default=None)
    speeds = critical_speeds_hz(crit)
    found = (f"{len(speeds)} critical speed{'s' if len(speeds) > 1 else ''} ("
             f"{', '.join(f'{f:.4g}' for f in speeds)} Hz)")
    if not crit:
        value = f"no critical speed up to {unb.top_hz:.4g} Hz"
    elif worst is None:
        value = (f"{found}, none with AF ≥ {AF_CRITICAL:g} (largest AF "
                 f"{max(k.af for k in crit):.3g}): no margin required")
    else:
        value = (f"{found}; tightest at {worst.speed_hz:.4g} Hz: AF "
                 f"{worst.af:.3g}, SM {worst.actual_margin_pct:.3g} % (required "
                 f"{worst.required_margin_pct:.3g} %)")
    rows.append(Criterion(
        "separation margins", value,
        "SM ≥ required (none below AF 2.5)", CLAUSES["separation"], unb.separation_passed))
    rows.append(Criterion("vibration at the probes",
                          f"{unb.probe_max_um:.3g} µm p-p", f"≤ A_vl = "
                          f"{unb.vibration_limit_um:.3g} µm p-p", CLAUSES["vibration"],
                          unb.vibration_passed))
    clear = [(k, c.scale_factor) for c in unb.cases for k in c.clearances]
    if clear:
        k, sc = max(clear, key=lambda t: t[0].scaled_um / t[0].allowed_um)
        value = (f"{k.name}: {k.scaled_um:.3g} µm p-p (S_c = {sc:.3g}) of "
                 f"{k.diametral_um:.3g} µm")
    else:
        value = ("no close clearance given ([[seal]] clearance, [[touchdown]] "
                 "radial_clearance)")
    rows.append(Criterion("close clearances", value,
                          f"≤ {100 * cfg.signoff.clearance_fraction:.3g} % of the diametral "
                          "clearance", CLAUSES["clearance"], bool(clear) and unb.clearance_passed,
                          graded=bool(clear)))
    if iso.graded:
        s = max((s for s in iso.sensors if s.zone), key=lambda s: s.d_max_m / s.c_min_m)
        value = (f"zone {iso.zone}: AMB {s.amb} {1e6 * s.d_max_m:.3g} µm 0-p = "
                 f"{s.d_max_m / s.c_min_m:.3g}·C_min")
    else:
        value = "no backup clearance given ([[touchdown]] radial_clearance)"
    rows.append(Criterion("vibration zone", value,
                          f"zone A or B (A/B {iso.boundaries[0]:g}, B/C {iso.boundaries[1]:g}"
                          f", C/D {iso.boundaries[2]:g}·C_min)", CLAUSES["iso14839_2"],
                          iso.graded and iso.passed, graded=iso.graded))
    if not unb.loop_stable:  # no steady unbalance response on an unstable loop
        why = (f"the loop with the seals at {cfg.operating.pressure_bar:g} bar is unstable "
               f"at {unb.max_hz:.4g} Hz: no steady unbalance response")
        rows[2:] = [replace(c, value=why, passed=False, graded=False) for c in rows[2:]]
    return tuple(rows)


def sign_off(cfg, controller=None, *, name: str = "none", progress=None) -> SignOff:
    """Every sign-off analysis of one controller as it runs (module docstring).

    Parameters
    ----------
    cfg : RigConfig
        The rig with its ``[[stage]]`` tables (without them Level I is not applicable and
        Level II decides on the rig's own sources), ``[operating]`` speeds and
        ``[signoff]``.
    controller : DigitalController or ScheduledDigital, optional
        As it runs; None for a rig on springs alone.
    name : str
        The controller's name.
    progress : callable, optional
        Called with one line per step.

    Returns
    -------
    SignOff

    Raises
    ------
    ConfigError
        Fewer than two supports or supports that do not hold the rotor,
        a maximum continuous speed of 0, a stage whose q_A no support can carry, or a
        continuous controller.
    """
    journal_loads(cfg)  # a rotor its supports cannot hold is refused before the analyses
    l1 = (level1_screening(cfg, controller, name=name, progress=progress) if cfg.stage
          else None)
    l2 = level2_analysis(cfg, controller, name=name, progress=progress)
    unb = api617_unbalance(cfg, controller, name=name, progress=progress)
    iso = iso14839_2_zones(cfg, unb)
    return SignOff(name, l1, l2, unb, iso, _criteria(cfg, l1, l2, unb, iso))


def verdict_line(results) -> str:
    """The one line a manager reads first: passed, or which controller failed what.

    Parameters
    ----------
    results : sequence of SignOff
        One per controller.

    Returns
    -------
    str
        ``Sign-off PASSED: …`` (naming the criteria not graded) or ``Sign-off NOT passed —
        <controller>: <criteria>; …``.
    """
    if all(r.passed for r in results):
        left = list(dict.fromkeys(c.name for r in results for c in r.criteria
                                  if not c.graded))
        return ("Sign-off PASSED: every controller meets API 617 (stability, unbalance "
                "response) and ISO 14839-2" + (f" (not graded: {', '.join(left)})"
                                               if left else ""))
    bad = "; ".join(f"{r.controller}: {', '.join(r.failed)}" for r in results if not r.passed)
    return f"Sign-off NOT passed — {bad}"
