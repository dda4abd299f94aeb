"""The report's first screen and its tables, for people: one verdict per controller.

ISO 14839-3 grades the sensitivity of each axis (its zones A–D: A newly commissioned,
B unrestricted long-term operation, C limited-term operation, D damage likely), so the
headline zone of a controller is the worst zone of any axis at any judged condition, an
unstable loop counting as D; σ̄(S_o) of the whole MIMO loop, graded on the same limits, is
shown beside it. The orbit is the worst-case unbalance response against the rig's
clearances (the AMBs' nominal air gap, the backup bearings' clearance) when the rig file
gives them.

Everything here formats numbers computed by :mod:`ambseal.analysis.judge`; nothing is
computed anew. The same rows feed ``report.html`` and the terminal summary.
"""

from __future__ import annotations

import html as _html
import math
from dataclasses import dataclass
from typing import Any, Mapping, Sequence

from rich import box
from rich.console import Group
from rich.table import Table
from rich.text import Text

from ambseal.analysis import (CLEARANCE_WORDS, SEPARATION_RTOL, ZONE_SCALE, boundary_note,
                               capacity_words, clearance_exceeded, first_largest, saturates,
                               side_of, worst_orbit_um, worst_zone, zone_sides, zone_words)
from ambseal.model import axis_label
from ambseal.robust import PEAK_TOLERANCE

__all__ = ["ZONE_COLOURS", "ZONE_WORDS", "Verdict", "verdicts", "condition_label",
           "verdict_table_html", "verdict_table_rich", "detail_table_html", "sig",
           "axis_label", "target_difference"]

#: Zone colours (green → red) of every table and figure.
ZONE_COLOURS = {"A": "#1a9850", "B": "#91cf60", "C": "#fc8d59", "D": "#d73027"}
#: What each ISO 14839-3 zone means for the machine, in words.
ZONE_WORDS = {z: zone_words(z) for z in "ABCD"}
_TERMINAL_ZONE = {"A": "green", "B": "bright_green", "C": "yellow", "D": "red"}
#: Unstable conditions a verdict sentence names before it counts the rest.
_NAMED = 4


def sig(v: Any, digits: int = 3) -> str:
    """A number for people: ``digits`` significant figures, ``—`` when absent."""
    if v is None or (isinstance(v, float) and math.isnan(v)):
        return "—"
    if isinstance(v, bool):
        return "yes" if v else "no"
    if isinstance(v, float) and math.isinf(v):
        return "∞" if v > 0 else "−∞"
    if isinstance(v, (int, float)):
        x = float(v)
        if x == 0:
            return "0"
        text = f"{x:.{digits}g}"
        if "e" in text:
            m, e = text.split("e")
            return f"{m}·10^{int(e)}"
        return text
    return str(v)


def _speed_varies(cases: Sequence[Mapping]) -> bool:
    return len({c.get("speed_hz") for c in cases}) > 1


def condition_label(case: Mapping, by_speed: bool) -> str:
    """``"2.04 bar"`` or, when the judged conditions differ in speed, ``"140 Hz"``."""
    return f"{case['speed_hz']:g} Hz" if by_speed else f"{case['pressure_bar']:.4g} bar"


@dataclass(frozen=True)
class Verdict:
    """One controller over all judged conditions (the report's first screen).

    Attributes
    ----------
    controller : str
    conditions, stable_at, unstable_at : tuple of str
        Judged conditions (``"<p> bar"``, or ``"<f> Hz"`` where they differ in speed),
        those with a stable loop, the rest (named ``"<p> bar, <f> Hz"`` where the speed
        range was judged too and the judged conditions share one speed: beside
        ``speed_unstable``).
    zone_axis, zone_sigma : str or None
        Worst per-axis ISO 14839-3 zone (unstable → D), and the zone of σ̄(S_o), over
        every graded loop: the judged conditions, continuous and as it runs, and the
        speed range's (standstill to the top speed) where they are graded. A zone or the
        boundary of two (``"A/B"``, :func:`ambseal.analysis.iso.graded_zone`), the worst
        on :data:`ambseal.analysis.iso.ZONE_SCALE`.
    sigma_peak : float or None
        Largest σ̄(S_o) peak over those loops where stable (-).
    orbit_um, impulse_peak_um, impulse_settling_s : float or None
        Worst unbalance orbit (µm), impulse peak (µm) and 2 % settling time (s; None where
        a judged response did not settle: ``impulse_settling_note`` says why). The orbit
        is the one that runs: with an unbalance force rejection delivered, the controller
        alone below the speed its notch is on from and the notch's orbit from there up (the
        rejection block's ``orbit_delivered_um``, :func:`ambseal.analysis.delivery.
        notched_orbit_um`).
    clearances_um : dict
        Clearances the orbit is set against, e.g. ``{"air gap": 500.0}`` (µm).
    target_difference : float or None
        Largest relative difference between the σ̄(S_o) peak of the controller as it runs
        (the cases' ``discrete`` blocks) and the continuous one, over the conditions where
        both loops are stable (-); None without discrete blocks.
    speed_checked, speed_unstable : int, tuple of str
        How many conditions of the speed range (standstill to the top speed, stability
        only: ``metrics["stability"]``) were checked, and those where the loop, continuous
        or as it runs, is unstable (``"0 bar, 0 Hz"``).
    design_bound : str or None
        The design's own bound: ``"H∞ γ = <γ> on the nominal design model"`` or
        ``"robust performance met: μ = <μ> ≤ 1 on the design model"``, or ``"… on its
        boundary: …"`` within 2 % of 1 (its summary's verdict, up to the full-order
        check); None for the PID.
    worst_axis : str or None
        The axis and condition of the largest per-axis sensitivity peak over those loops,
        e.g. ``"A ζ at 4.08 bar"`` or ``"B η at 40 bar, 500 Hz, as it runs"``; None
        without per-axis peaks.
    worst_axis_peak : float or None
        That peak (-), which :attr:`zone_axis` is graded from.
    notch_on_hz : float or None
        The speed (Hz) the delivered unbalance force rejection is on from, where the orbit
        counts it; None without one.
    synthesis_shortfall : str
        Where the design's synthesis stopped short of its optimum (an LPV design whose SDP
        ended "feasible" at CVXOPT's iteration cap or stalled: the design summary's
        ``sdp_shortfall``), in words; ``""`` where it did not.
    axes_alike : bool
        Every axis is in the same zone at every stable condition.
    capacity : dict or None
        The amplifier's limits the unbalance uses (the design summary's ``capacity``,
        :func:`ambseal.analysis.amplifier.capacity_block`); None without one.
    speeds_hz : tuple of float
        Every speed (Hz) the loop was judged at, in full or for stability only, sorted:
        what the verdict may claim of the speed range (standstill only if 0 is among them).
    range_hz : tuple of float
        The speeds (Hz) of the speed-range conditions alone (``metrics["stability"]``),
        sorted.
    criticals : tuple of dict
        The loop's critical speeds inside the continuous speed range or within API 617's
        separation margin (the cases' ``critical_speeds``, continuous and as it runs, one
        per speed to 3 digits, the largest AF kept), by speed.
    speed_graded : bool
        The speed range's loops were graded by ISO 14839-3 too (not stability alone): the
        zone is then over the judged conditions and the speed range.
    impulse_settling_note : str or None
        Why the impulse response of a stable judged loop has no settling time (the
        case's ``impulse_settling_note``, with its condition when several were judged);
        None where every one settled.
    """

    controller: str
    conditions: tuple[str, ...]
    stable_at: tuple[str, ...]
    unstable_at: tuple[str, ...]
    zone_axis: str | None
    zone_sigma: str | None
    sigma_peak: float | None
    orbit_um: float | None
    impulse_peak_um: float | None
    impulse_settling_s: float | None
    clearances_um: dict
    target_difference: float | None = None
    speed_checked: int = 0
    speed_unstable: tuple[str, ...] = ()
    design_bound: str | None = None
    worst_axis: str | None = None
    axes_alike: bool = True
    capacity: dict | None = None
    speeds_hz: tuple[float, ...] = ()
    range_hz: tuple[float, ...] = ()
    criticals: tuple = ()
    speed_graded: bool = False
    impulse_settling_note: str | None = None
    worst_axis_peak: float | None = None
    synthesis_shortfall: str = ""
    notch_on_hz: float | None = None

    def critical_text(self) -> str:
        """The critical speeds in words, ``""`` without any: ``"a critical speed (1×
        crossing, AF ≥ 2.5) at 950 Hz (AF 12) inside the continuous speed range"``."""
        parts = []
        for c in self.criticals:
            af = c.get("af")
            af = math.inf if af is None or isinstance(af, str) else af  # "inf" in JSON
            head = f"{c['speed_hz']:.4g} Hz (AF {sig(af, 2)})"
            if not c["margin_pct"]:
                parts.append(f"{head} inside the continuous speed range")
            elif side_of(c["margin_pct"], c["required_pct"], SEPARATION_RTOL) == "on":
                # the margin is not known to meet the requirement or not: both sides said
                parts.append(f"{head} {c['margin_pct']:.4g} % from the continuous speed "
                             f"range, on the boundary of the {c['required_pct']:.4g} % API "
                             "617 requires (met or not met within the judgement's accuracy)")
            else:
                parts.append(f"{head} {sig(c['margin_pct'], 2)} % from the continuous speed "
                             f"range where API 617 requires {sig(c['required_pct'], 2)} %")
        if not parts:
            return ""
        what = "a critical speed" if len(parts) == 1 else "critical speeds"
        return f"{what} (1× crossing, AF ≥ 2.5) at " + "; ".join(parts)

    def speed_span(self, speeds_hz: tuple[float, ...] | None = None) -> str:
        """The judged speeds (or ``speeds_hz``) in words: ``"standstill to 1000 Hz"``, or
        ``"333–1000 Hz (standstill not judged)"`` when 0 Hz was not among them."""
        speeds_hz = self.speeds_hz if speeds_hz is None else speeds_hz
        if not speeds_hz:
            return "the judged speeds"
        lo, hi = speeds_hz[0], speeds_hz[-1]
        if lo == 0:
            return f"standstill to {hi:g} Hz"
        return f"{lo:g}–{hi:g} Hz (standstill not judged)"

    @property
    def judged_range(self) -> str:
        """``"<low>–<high> bar"`` when stable at every judged condition, else the stable ones, or
        ``none``."""
        if not self.stable_at:
            return "none"
        if not self.unstable_at and len(self.conditions) > 1:
            return f"{self.conditions[0].split()[0]}–{self.conditions[-1]}"
        return ", ".join(self.stable_at)

    @property
    def stable_range(self) -> str:
        """:attr:`judged_range`, with the speed range: ``"…, standstill to top speed"``, or
        how many of its conditions the loop is unstable at (also after ``"none"``: a loop
        lost at every judged condition may still hold some of the speed range, and says
        where: ``"none; stable at its 5 speed-range conditions (standstill to 394 Hz)"``)."""
        text = self.judged_range
        if text == "none" and not self.speed_unstable:
            if not self.speed_checked:
                return text
            n = self.speed_checked
            return (f"{text}; stable at {'its' if n > 1 else 'the'} {n} speed-range "
                    f"condition{'s' if n > 1 else ''} ({self.speed_span(self.range_hz)})")
        if self.speed_unstable:
            text += (f"; unstable at {len(self.speed_unstable)} of {self.speed_checked} "
                     f"speed-range conditions")
        elif self.speed_checked:
            text += f", {self.speed_span()}"
        return text

    def orbit_text(self) -> str:
        """``"3.1 µm (0.6 % of the air gap)"``, and ``"; its notch on from 102 Hz"`` in the
        brackets where the orbit counts a delivered unbalance force rejection."""
        if self.orbit_um is None:
            return "—"
        rel = "; ".join([f"{100 * self.orbit_um / c:.2g} % of the {n}"
                         for n, c in self.clearances_um.items() if c]
                        + ([] if self.notch_on_hz is None
                           else [f"its notch on from {sig(self.notch_on_hz)} Hz"]))
        return f"{sig(self.orbit_um)} µm" + (f" ({rel})" if rel else "")

    def amplifier_text(self) -> str:
        """What holding the unbalance asks of the amplifier, in words
        (:func:`ambseal.analysis.amplifier.capacity_words`); ``""`` without limits."""
        return capacity_words(self.capacity)

    def words(self) -> str:
        """The verdict in one sentence; a design whose synthesis stopped short of its
        optimum says so at its end, whatever the verdict: its numbers are where the solver
        stopped, and another machine's rounding stops it elsewhere."""
        text = self._judged_words()
        if self.synthesis_shortfall:
            # what stopped short is in the design bound's cell and the syntheses' section
            text = (f"{text[:-1]}; NOT SOLVED TO OPTIMALITY: its numbers may differ on "
                    "another machine.")
        return text

    def _judged_words(self) -> str:
        """The verdict on the judged loops, in one sentence."""
        if self.unstable_at or self.speed_unstable:
            bad = [*self.unstable_at, *self.speed_unstable]
            where = "; ".join(bad[:_NAMED]) + (f" and {len(bad) - _NAMED} more"
                                               if len(bad) > _NAMED else "")
            tail = (f"; stable only at {', '.join(self.stable_at)}" if self.stable_at
                    and self.unstable_at else "")
            run = " (where the machine runs up)" if self.speed_unstable else ""
            return f"Not acceptable: the loop is unstable at {where}{run}{tail}."
        if saturates(self.capacity):
            return f"Not acceptable: {self.amplifier_text()}."
        over = clearance_exceeded(self.orbit_um, self.clearances_um)
        if over is not None:
            return (f"Not acceptable: the worst unbalance orbit, {sig(self.orbit_um)} µm, "
                    f"exceeds {CLEARANCE_WORDS.get(over[0], over[0])} ({sig(over[1])} µm).")
        z = self.zone_axis or "?"
        where = ("on every axis" if self.axes_alike or self.worst_axis is None else
                 f"on its worst axis ({self.worst_axis})")
        # a zone on the boundary of two says the peak and the limit it lies on
        z += boundary_note(self.zone_axis, self.worst_axis_peak, "|S_o|")
        over = self.judged_range
        if self.speed_checked and self.speed_graded:  # the zone covers the speed range
            # judged at speeds already, the span says it all ("standstill to 300 Hz")
            over = (self.speed_span() if over.endswith(" Hz")
                    else f"{over} and {self.speed_span()}")
        text = f"Zone {z} {where} over {over}"
        # σ̄(S_o) bounds every axis's peak from above, so its zone is never the better one;
        # where it is worse, the words follow it: the loop is judged as the MIMO loop it is
        worse = (self.zone_sigma if self.zone_sigma in ZONE_SCALE
                 and ZONE_SCALE.index(self.zone_sigma)
                 > ZONE_SCALE.index(self.zone_axis if self.zone_axis in ZONE_SCALE else "A")
                 else None)
        if worse is not None:
            text += (f", but σ̄(S_o) over all axes reaches zone {worse}"
                     + (boundary_note(worse, self.sigma_peak) or
                        f" (peak {sig(self.sigma_peak)})"))
        text += f": {zone_words(worse or self.zone_axis)}"
        if self.speed_checked and not self.speed_graded:
            span = self.speed_span()
            text += (f"; stable from {span}" if span.startswith("standstill")
                     else f"; stable at every judged speed, {span}")
        gap = [(c, n) for n, c in self.clearances_um.items() if c]
        if self.orbit_um is not None and gap and self.orbit_um > 0.5 * min(gap)[0]:
            c, n = min(gap)
            text += (f"; the unbalance orbit, {sig(self.orbit_um)} µm, uses "
                     f"{100 * self.orbit_um / c:.0f} % of {CLEARANCE_WORDS.get(n, n)} "
                     f"({sig(c)} µm)")

        crit = self.critical_text()
        if crit:
            text += f"; but {crit}"
        amp = self.amplifier_text()
        if amp:
            text += f"; {amp}"
        if self.impulse_settling_note:
            text += f"; its impulse response is {self.impulse_settling_note}"
        if self.target_difference is not None and self.target_difference > PEAK_TOLERANCE:
            text += (f"; as it runs on the target its σ̄(S_o) peak differs from the continuous "
                     f"one by {100 * self.target_difference:.0f} % (see “On the target”)")
        return text + "."


def target_difference(cs: Sequence[Mapping]) -> float | None:
    """Largest |discrete − continuous| / continuous σ̄(S_o) peak over the cases (their
    ``discrete`` blocks), None without a pair.

    Parameters
    ----------
    cs : sequence of mapping
        Cases of ``metrics.json`` (their ``sensitivity_peak`` and ``discrete`` blocks).

    Returns
    -------
    float or None
        The relative difference (-).
    """
    pairs = [(c["sensitivity_peak"], (c.get("discrete") or {}).get("sensitivity_peak"))
             for c in cs if c.get("sensitivity_peak")]
    diffs = [abs(d - x) / x for x, d in pairs if d is not None]
    return max(diffs) if diffs else None


def _unstable(case: Mapping) -> bool:
    """The loop of a stability case is unstable, continuous or as it runs."""
    return not case.get("stable") or not (case.get("discrete") or {}).get("stable", True)


def verdicts(cases: Sequence[Mapping], clearances_um: Mapping[str, float] | None = None,
             stability: Sequence[Mapping] = (),
             designs: Mapping[str, Mapping] | None = None) -> list[Verdict]:
    """One :class:`Verdict` per controller of ``metrics["cases"]`` (in order of appearance),
    with its ``metrics["stability"]`` cases (the speed range) counted in and its design's
    bound from ``metrics["controllers"]`` (``designs``).

    Parameters
    ----------
    cases : sequence of mapping
        ``metrics["cases"]``.
    clearances_um : mapping of str to float, optional
        The rig's clearances (µm) the unbalance orbit is set against.
    stability : sequence of mapping, optional
        ``metrics["stability"]``: the loops over the speed range.
    designs : mapping of str to mapping, optional
        ``metrics["controllers"]``: each design's bound.

    Returns
    -------
    list of Verdict
        One per controller, in order of appearance.
    """
    by_speed = _speed_varies(cases)
    names = list(dict.fromkeys(c["controller"] for c in cases))
    return [_verdict(name, [c for c in cases if c["controller"] == name], by_speed,
                     [c for c in stability if c["controller"] == name], clearances_um,
                     (designs or {}).get(name, {}))
            for name in names]


def _verdict(name: str, cs: list, by_speed: bool, sc: list,
             clearances_um: Mapping[str, float] | None, design: Mapping) -> Verdict:
    """The verdict of one controller from its judged cases ``cs``, its speed-range cases
    ``sc`` and its design's summary."""
    label = [condition_label(c, by_speed) for c in cs]
    ok = [c for c in cs if c.get("stable")]

    def peak(key, among=ok):
        vals = [c[key] for c in among if c.get(key) is not None]
        return max(vals) if vals else None

    # every stable loop graded: the judged ones, continuous and as they run, and those of
    # the speed range (standstill to the top speed), each by its condition
    graded = [(lb, c) for lb, c in zip(label, ok)] + [
        (f"{lb}, as it runs", c["discrete"]) for lb, c in zip(label, cs)
        if (c.get("discrete") or {}).get("stable") and c["discrete"].get("iso_zone")] + [
        (c["label"], c) for c in sc if c.get("stable") and c.get("iso_zone")] + [
        (f"{c['label']}, as it runs", c["discrete"]) for c in sc
        if (c.get("discrete") or {}).get("stable") and c["discrete"].get("iso_zone")]
    loops = [g for _, g in graded]
    stable_zones = {z for g in loops for z in (g.get("iso_zone_per_axis") or {}).values()}
    speed_bad = tuple(c["label"] for c in sc if _unstable(c))
    # an unstable loop, judged or at a speed of the range, is zone D: for σ̄(S_o) too, so
    # that the two zone cells of one row never disagree on it
    lost = ["D" for c in cs if not c.get("stable")] + (["D"] if speed_bad else [])
    axis_zones = [z for c in [*cs, *loops[len(ok):]]
                  for z in (c.get("iso_zone_per_axis") or {}).values()] + lost
    top = _worst_axis([lb for lb, _ in graded], loops)
    # a response that did not settle is the worst settling: no time, and why
    unsettled = [(lb, c["impulse_settling_note"]) for lb, c in zip(label, cs)
                 if c.get("stable") and c.get("impulse_settling_note")]
    note = None if not unsettled else unsettled[0][1] + (
        f" (at {unsettled[0][0]})" if len(cs) > 1 else "")
    # with a delivered notch the orbit that runs is the notch's where it is on
    notched = (design.get("rejection") or {}).get("orbit_delivered_um")
    return Verdict(
        controller=name, conditions=tuple(label),
        stable_at=tuple(lb for lb, c in zip(label, cs) if c.get("stable")),
        # beside the speed range's conditions a judged one is named with its speed too
        unstable_at=tuple(lb if by_speed or not sc else f"{lb}, {c['speed_hz']:g} Hz"
                          for lb, c in zip(label, cs) if not c.get("stable")),
        zone_axis=worst_zone(axis_zones),
        zone_sigma=worst_zone([c.get("iso_zone") for c in [*cs, *loops[len(ok):]]] + lost),
        sigma_peak=peak("sensitivity_peak", loops),
        orbit_um=worst_orbit_um(cs) if notched is None else notched,
        impulse_peak_um=peak("impulse_peak_um"),
        impulse_settling_s=None if unsettled else peak("impulse_settling_s"),
        impulse_settling_note=note,
        clearances_um=dict(clearances_um or {}), target_difference=target_difference(cs),
        speed_checked=len(sc), speed_unstable=speed_bad,
        design_bound=(design.get("verdict") or "").split(";")[0] or None,
        worst_axis=None if top is None else f"{axis_label(top[1])} at {top[2]}",
        worst_axis_peak=None if top is None else top[0],
        axes_alike=len(stable_zones) <= 1, capacity=design.get("capacity"),
        speeds_hz=tuple(sorted({float(c["speed_hz"]) for c in [*cs, *sc]
                                if c.get("speed_hz") is not None})),
        range_hz=tuple(sorted({float(c["speed_hz"]) for c in sc
                               if c.get("speed_hz") is not None})),
        criticals=_criticals(cs), speed_graded=any(c.get("iso_zone") for c in sc),
        synthesis_shortfall=design.get("sdp_shortfall") or "",
        notch_on_hz=None if notched is None else design["rejection"]["on_from_hz"])


def _criticals(cs: list) -> tuple:
    """The critical speeds of a controller's judged cases (continuous and as it runs), one
    per speed to 3 significant digits (the largest AF), by speed."""
    found: dict = {}
    for c in cs:
        for block in (c, c.get("discrete") or {}):
            if not block.get("stable"):
                continue
            for k in block.get("critical_speeds") or ():
                key = float(f"{k['speed_hz']:.3g}")
                af = k.get("af")
                af = math.inf if af is None or isinstance(af, str) else af
                old = found.get(key)
                if old is None or af > old[0]:
                    found[key] = (af, k)
    return tuple(found[key][1] for key in sorted(found))


def _worst_axis(labels: list[str], cs: list) -> tuple | None:
    """(σ̄ peak, axis, condition label) of the highest per-axis σ̄(S_o) peak among the
    stable cases, or None. Peaks within :data:`ambseal.analysis.TIE_RTOL` of the highest are
    the same peak (the ζ and η axes of a symmetric bearing, equal but for rounding): the
    first of them wins, in the order of the cases and, within a case, the rig's channel
    order, so that the name does not follow the machine's rounding
    (:func:`ambseal.analysis.first_largest`)."""
    return first_largest(((pk, a, lb) for lb, c in zip(labels, cs) if c.get("stable")
                          for a, pk in (c.get("sensitivity_peak_per_axis") or {}).items()
                          if pk is not None), key=lambda t: t[0])


def _settling_text(settling_s: float | None, note: str | None) -> str:
    """A settling time in ms for a table cell; ``"not settled"`` where a note says why
    there is none (the verdict and the notes under the detail table give the reason),
    ``—`` where none was judged."""
    if settling_s is None and note:
        return "not settled"
    return sig(None if settling_s is None else settling_s * 1e3)


def _esc(s: Any) -> str:
    return _html.escape(str(s), quote=True)


def _zone_background(z: str) -> str:
    """A zone's colour; the boundary of two, both colours side by side."""
    sides = [ZONE_COLOURS.get(s, "#eee") for s in zone_sides(z)]
    if len(sides) == 1:
        return sides[0]
    return f"linear-gradient(90deg,{sides[0]} 50%,{sides[1]} 50%)"


def _zone_cell(z: str | None, extra: str = "", label: str = "") -> str:
    lab = f' data-label="{_esc(label)}"' if label else ""
    if z is None:
        return f"<td{lab}>—</td>"
    return (f'<td class="zone"{lab} style="background:{_zone_background(z)}">'
            f"{_esc(z)}{extra}</td>")


def verdict_table_html(vs: Sequence[Verdict]) -> str:
    """The first-screen table: one row per controller, zones coloured."""
    head = ("<tr><th>Controller</th><th>Stable over</th><th>ISO 14839-3 zone<br>worst axis"
            "</th><th>zone of<br>σ̄(S_o)</th><th>σ̄(S_o) peak (–)</th><th>Worst unbalance "
            "orbit</th><th>Impulse peak (µm)</th><th>Settling 2 % (ms)</th>"
            "<th class=\"text\">Design bound (γ, μ)</th><th class=\"text\">Verdict</th></tr>")
    rows = []
    for v in vs:
        st = v.impulse_settling_s
        # data-label: the column's name, shown beside each value when a narrow screen
        # stacks the row (the page's CSS)
        cells = [f'<td class="text" data-label="Controller"><b>{_esc(v.controller)}</b></td>',
                 f'<td class="text" data-label="Stable over">{_esc(v.stable_range)}</td>',
                 _zone_cell(v.zone_axis, label="ISO 14839-3 zone, worst axis"),
                 _zone_cell(v.zone_sigma, label="zone of σ̄(S_o)"),
                 f'<td data-label="σ̄(S_o) peak">{sig(v.sigma_peak)}</td>',
                 f'<td class="text" data-label="Worst unbalance orbit">'
                 f"{_esc(v.orbit_text())}</td>",
                 f'<td data-label="Impulse peak (µm)">{sig(v.impulse_peak_um)}</td>',
                 f'<td data-label="Settling 2 % (ms)">'
                 f"{_settling_text(st, v.impulse_settling_note)}</td>",
                 f'<td class="text" data-label="Design bound">'
                 f'{_esc(v.design_bound or "—")}</td>',
                 f'<td class="text verdict" data-label="Verdict">{_esc(v.words())}</td>']
        rows.append(f'<tr class="{"unstable" if v.unstable_at or v.speed_unstable else "ok"}">'
                    + "".join(cells) + "</tr>")
    return (f'<table class="verdict" id="verdict"><thead>{head}</thead>'
            f"<tbody>{''.join(rows)}</tbody></table>")


def detail_table_html(cases: Sequence[Mapping]) -> str:
    """Every judged case: units in the headers, 3–4 significant figures, per-axis values
    as sub-columns; unstable rows shaded, their missing values shown as ``—``; an impulse
    response that did not settle is ``not settled``, the reason in a line under the table."""
    if not cases:
        return "<p>No cases.</p>"
    by_speed = _speed_varies(cases)
    axes = list(dict.fromkeys(a for c in cases for a in (c.get("iso_zone_per_axis") or {})))
    n = len(axes)
    cond = "Speed (Hz)" if by_speed else "Pressure (bar)"
    head1 = (f'<tr><th rowspan="2">Controller</th><th rowspan="2">{cond}</th>'
             '<th rowspan="2">Stable</th><th rowspan="2">max Re(pole) (1/s)</th>'
             f'<th colspan="{n + 1}">σ̄(S_o) peak (–)</th>'
             f'<th colspan="{n + 1}">ISO 14839-3 zone</th>'
             '<th rowspan="2">Compliance peak (µm/N)</th><th rowspan="2">Unbalance orbit (µm)'
             '</th><th rowspan="2">Impulse peak (µm)</th><th rowspan="2">Settling 2 % (ms)</th>'
             "</tr>")
    sub = "".join(f"<th>{_esc(axis_label(a))}</th>" for a in axes)
    head2 = f"<tr><th>all</th>{sub}<th>σ̄</th>{sub}</tr>"
    rows = []
    for c in cases:
        per_s = c.get("sensitivity_peak_per_axis") or {}
        per_z = c.get("iso_zone_per_axis") or {}
        x = c["speed_hz"] if by_speed else c["pressure_bar"]
        comp = c.get("compliance_peak_m_per_n")
        st = c.get("impulse_settling_s")
        cells = ([f'<td class="text">{_esc(c["controller"])}</td>', f"<td>{x:g}</td>",
                  f"<td>{'yes' if c.get('stable') else 'no'}</td>",
                  f"<td>{sig(c.get('max_real_pole'), 4)}</td>",
                  f"<td>{sig(c.get('sensitivity_peak'))}</td>"]
                 + [f"<td>{sig(per_s.get(a))}</td>" for a in axes]
                 + [_zone_cell(c.get("iso_zone"))] + [_zone_cell(per_z.get(a)) for a in axes]
                 + [f"<td>{sig(None if comp is None else comp * 1e6)}</td>",
                    f"<td>{sig(c.get('unbalance_peak_um'))}</td>",
                    f"<td>{sig(c.get('impulse_peak_um'))}</td>",
                    f"<td>{_settling_text(st, c.get('impulse_settling_note'))}</td>"])
        cls = "" if c.get("stable") else ' class="unstable"'
        rows.append(f"<tr{cls}>{''.join(cells)}</tr>")
    notes = "".join(f"<p>{_esc(c['controller'])} at {_esc(condition_label(c, by_speed))}: "
                    f"the impulse response is {_esc(c['impulse_settling_note'])}.</p>"
                    for c in cases if c.get("stable") and c.get("impulse_settling_note"))
    return (f'<table class="detail"><thead>{head1}{head2}</thead>'
            f"<tbody>{''.join(rows)}</tbody></table>{notes}")


def verdict_table_rich(vs: Sequence[Verdict]):
    """The first screen for a terminal: a compact ``rich`` table (zones coloured, fits 80
    columns; the orbit against the first clearance the rig gives) and one line per
    controller with its verdict in words.

    Parameters
    ----------
    vs : sequence of Verdict
        :func:`verdicts` of the run.

    Returns
    -------
    rich.console.Group
        The table and the lines, for ``rich.console.Console.print``.
    """

    gap = next(iter(vs[0].clearances_um.items()), None) if vs else None
    title = "Verdict — ISO 14839-3 zone: worst axis / σ̄" + (
        f"; orbit: µm (% of the {gap[0]})" if gap else "")
    t = Table(title=title, title_justify="left", box=box.SIMPLE_HEAD, pad_edge=False)
    orbit = "orbit"
    for col in ("controller", "stable over", "zone", "σ̄ peak", orbit, "impulse µm",
                "settle ms"):
        t.add_column(col, justify="left" if col in ("controller", "stable over") else "right",
                     no_wrap=col in ("controller", "zone", orbit))

    def zone(z):  # named colours: also right on a 16-colour terminal; a boundary, the worse's
        if z is None:
            return "—"
        return f"[bold black on {_TERMINAL_ZONE.get(zone_sides(z)[-1], 'white')}] {z} [/]"

    for v in vs:
        st = v.impulse_settling_s
        orb = sig(v.orbit_um)
        if gap and v.orbit_um is not None:
            orb += f" ({sig(100 * v.orbit_um / gap[1], 2)} %)"
        t.add_row(v.controller, v.stable_range, f"{zone(v.zone_axis)}/{zone(v.zone_sigma)}",
                  sig(v.sigma_peak), orb, sig(v.impulse_peak_um),
                  _settling_text(st, v.impulse_settling_note),
                  style="red" if v.unstable_at else None)
    lines = [Text.assemble((f"{v.controller}: ", "bold"), v.words()
                           + (f" Design: {v.design_bound}." if v.design_bound else ""))
             for v in vs]
    return Group(t, *lines)
