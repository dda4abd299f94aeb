"""ISO 14839-3 stability-margin zones from a sensitivity peak.

ISO 14839-3:2006 ("Vibration of rotating machinery equipped with active magnetic bearings —
Part 3: Evaluation of stability margin") grades the peak of the closed-loop sensitivity
function of each control axis:

====  ==========================  =========================================
Zone  peak sensitivity            meaning
====  ==========================  =========================================
A     below 3     (9.5 dB)        newly commissioned machines, unrestricted
B     3 up to below 4  (12 dB)    unrestricted long-term operation
C     4 up to below 5  (14 dB)    limited period of operation only
D     5 and above                 sufficient to cause damage
====  ==========================  =========================================

A peak exactly on a limit belongs to the upper zone (3 → B, 4 → C, 5 → D) by the standard
(:func:`iso_zone`). A judged peak is a computed number, though, known to the accuracy of its
frequency grid and reproduced between machines to their rounding: within
:data:`ZONE_RTOL` of a limit it is graded *on the boundary*, ``"A/B"``, ``"B/C"`` or
``"C/D"`` (:func:`graded_zone`), and the words name both zones (:func:`boundary_note`,
:func:`zone_words`), so that rounding cannot move it from one zone to the other
(:mod:`ambseal.analysis.tolerance`). The worst of several zones is taken on
:data:`ZONE_SCALE` (:func:`worst_zone`), the boundaries between their zones. The standard
grades each axis (the diagonal elements); the thesis requires the largest singular value of
the full output sensitivity to be below 3 to cover cross-coupling (P5 §4.1 item 4, §4.4.2,
Fig. 13), which is at least as strict since ``σ̄(S) ≥ max_i |S_ii|``.

An unstable loop has no meaningful sensitivity peak; pass ``inf`` (zone D).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from ambseal.analysis.tolerance import ON, side_of
from ambseal.errors import ModelError
from ambseal.lti import json_float

__all__ = ["ZONE_LIMITS", "ZONES", "ZONE_RTOL", "ZONE_SCALE", "zone_limit_db", "iso_zone",
           "graded_zone", "worst_zone", "zone_sides", "boundary_note", "zone_words",
           "IsoAssessment", "iso_assessment"]

#: Upper limits (exclusive) of zones A, B, C on the sensitivity peak (absolute gain).
ZONE_LIMITS: tuple[float, float, float] = (3.0, 4.0, 5.0)
#: Zone letters from best to worst.
ZONES: tuple[str, str, str, str] = ("A", "B", "C", "D")
#: Relative band around each limit of :data:`ZONE_LIMITS` within which a sensitivity peak
#: is graded on the boundary (:func:`graded_zone`): what rounding may not decide. One
#: loop's peaks differ between machines and BLAS kernels far less than this
#: (benchmarks/README.md, "What rounding may not decide"). The grid's own resolution is
#: another matter: :func:`ambseal.analysis.loops.resolved_grid` finds a single
#: resonance's peak to 0.5 % of its height, always from below and the same on every
#: machine, so it lowers a grade's number without making it depend on the machine.
ZONE_RTOL = 1e-3
#: Every grade from best to worst: the zones and the boundaries between them.
ZONE_SCALE: tuple[str, ...] = ("A", "A/B", "B", "B/C", "C", "C/D", "D")
#: What each zone means for the machine, in words (:func:`zone_words`).
_MEANING = {"A": "as good as newly commissioned",
            "B": "fit for unrestricted long-term operation",
            "C": "fit for limited-term operation only",
            "D": "not acceptable (damage likely)"}


def zone_limit_db() -> tuple[float, float, float]:
    """The zone limits in dB: ``(9.54, 12.04, 13.98)`` (the standard rounds to 9.5, 12, 14).

    Returns
    -------
    (float, float, float)
        The A/B, B/C and C/D limits of :data:`ZONE_LIMITS`, dB.
    """
    return tuple(20.0 * math.log10(x) for x in ZONE_LIMITS)  # type: ignore[return-value]


def iso_zone(peak: float) -> str:
    """ISO 14839-3 zone of a sensitivity peak.

    Parameters
    ----------
    peak : float
        Peak of the sensitivity gain (absolute, not dB), ``>= 0``; ``inf`` for an unstable loop.

    Returns
    -------
    str
        ``"A"`` if ``peak < 3``, ``"B"`` if ``3 <= peak < 4``, ``"C"`` if ``4 <= peak < 5``,
        else ``"D"``.

    Raises
    ------
    ModelError
        If ``peak`` is NaN or negative.

    Examples
    --------
    >>> iso_zone(2.99), iso_zone(3.0), iso_zone(4.0), iso_zone(5.0)
    ('A', 'B', 'C', 'D')
    """
    p = float(peak)
    if math.isnan(p) or p < 0:
        raise ModelError(f"iso_zone: sensitivity peak must be >= 0 (absolute gain, not dB), got {peak!r}")
    for zone, limit in zip(ZONES, ZONE_LIMITS):
        if p < limit:
            return zone
    return "D"


def graded_zone(peak: float, rtol: float = ZONE_RTOL) -> str:
    """The zone of a judged sensitivity peak: :func:`iso_zone`'s letter, or the boundary
    (``"A/B"``, ``"B/C"``, ``"C/D"``) where the peak lies within ``rtol`` of its limit.

    Parameters
    ----------
    peak : float
        Peak of the sensitivity gain (absolute, not dB), ``>= 0``; ``inf`` for an unstable
        loop.
    rtol : float
        Relative band around each limit (-), :data:`ZONE_RTOL` by default.

    Returns
    -------
    str
        A name of :data:`ZONE_SCALE`.

    Raises
    ------
    ModelError
        If ``peak`` is NaN or negative.

    Examples
    --------
    >>> graded_zone(2.99), graded_zone(2.9995), graded_zone(3.0004), graded_zone(3.01)
    ('A', 'A/B', 'A/B', 'B')
    """
    zone = iso_zone(peak)
    for lower, upper, limit in zip(ZONES, ZONES[1:], ZONE_LIMITS):
        if side_of(float(peak), limit, rtol) == ON:
            return f"{lower}/{upper}"
    return zone


def zone_sides(zone: str) -> tuple[str, ...]:
    """The zone letters a grade of :data:`ZONE_SCALE` names: ``("A", "B")`` for ``"A/B"``,
    ``("B",)`` for ``"B"``.

    Parameters
    ----------
    zone : str
        A name of :data:`ZONE_SCALE`.

    Returns
    -------
    tuple of str
    """
    return tuple(zone.split("/"))


def worst_zone(zones) -> str | None:
    """The worst of several grades on :data:`ZONE_SCALE` (a boundary between the better
    zone and the one it names), None without a grade; names not on the scale are left out.

    Parameters
    ----------
    zones : iterable of str or None
        Grades (:func:`graded_zone`, or the standard's letters).

    Returns
    -------
    str or None

    Examples
    --------
    >>> worst_zone(["A", "A/B", None]), worst_zone(["A/B", "B"]), worst_zone([])
    ('A/B', 'B', None)
    """
    known = [z for z in zones if z in ZONE_SCALE]
    return max(known, key=ZONE_SCALE.index) if known else None


def boundary_note(zone: str | None, peak: float | None, what: str = "σ̄") -> str:
    """What a grade on a boundary rests on, for the words after it: ``" (on the boundary:
    σ̄ 3.0004 against 3.0)"``; ``""`` for a zone or without a peak.

    Parameters
    ----------
    zone : str or None
        A name of :data:`ZONE_SCALE`.
    peak : float or None
        The peak it was graded from (-).
    what : str
        How the words name the peak (``"σ̄"``, ``"|S| of A ζ"``).

    Returns
    -------
    str
    """
    if zone is None or peak is None or len(zone_sides(zone)) < 2:
        return ""
    limit = ZONE_LIMITS[ZONES.index(zone_sides(zone)[0])]
    return f" (on the boundary: {what} {float(peak):.5g} against {limit:.1f})"


def zone_words(zone: str | None) -> str:
    """What a grade means for the machine: ``"fit for unrestricted long-term operation"``,
    or, on a boundary, both zones' meanings: ``"on the boundary of A (as good as newly
    commissioned) and B (fit for unrestricted long-term operation)"``.

    Parameters
    ----------
    zone : str or None
        A name of :data:`ZONE_SCALE`.

    Returns
    -------
    str
        ``"not graded"`` for None or a name not on the scale.
    """
    if zone not in ZONE_SCALE:
        return "not graded"
    sides = zone_sides(zone)
    if len(sides) == 1:
        return _MEANING[zone]
    return "on the boundary of " + " and ".join(f"{z} ({_MEANING[z]})" for z in sides)


@dataclass(frozen=True)
class IsoAssessment:
    """ISO 14839-3 zones of one closed loop.

    Attributes
    ----------
    zone_sigma_max : str
        Zone of the σ̄ peak of the output sensitivity (thesis criterion, P5 §4.1 item 4), a
        name of :data:`ZONE_SCALE` (:func:`graded_zone`).
    sigma_max_peak : float
        That peak (absolute gain; ``inf`` if the loop is unstable).
    zones_per_axis : tuple of (str, str)
        ``(channel, zone)`` per axis from the diagonal peaks (the standard's criterion),
        each a name of :data:`ZONE_SCALE`.
    zone_per_axis_worst : str
        Worst of the per-axis zones (:func:`worst_zone`).
    stable : bool
        Whether the loop was stable; an unstable loop is zone D everywhere.
    """

    zone_sigma_max: str
    sigma_max_peak: float
    zones_per_axis: tuple[tuple[str, str], ...]
    zone_per_axis_worst: str
    stable: bool = True

    def to_dict(self) -> dict:
        return {
            "zone_sigma_max": self.zone_sigma_max,
            "sigma_max_peak": json_float(self.sigma_max_peak),
            "zones_per_axis": {ch: z for ch, z in self.zones_per_axis},
            "zone_per_axis_worst": self.zone_per_axis_worst,
            "stable": bool(self.stable),
        }


def iso_assessment(peaks, *, stable: bool = True) -> IsoAssessment:
    """Grade S_o peaks by ISO 14839-3, per axis and on σ̄.

    Parameters
    ----------
    peaks : ambseal.analysis.loops.SensitivityPeaks
        From ``loop_responses(G, K, omega).peaks("So")`` or ``sensitivity_peaks``.
    stable : bool
        Stability of the loop (``closed_loop(G, K).stable``); if ``False`` every zone is D and
        the σ̄ peak is reported as ``inf``.

    Returns
    -------
    IsoAssessment
    """
    if not stable:
        per_axis = tuple((p.channel, "D") for p in peaks.diagonal)
        return IsoAssessment("D", float("inf"), per_axis, "D", False)
    per_axis = tuple((p.channel, graded_zone(p.value)) for p in peaks.diagonal)
    worst = worst_zone(z for _, z in per_axis) or "A"
    return IsoAssessment(graded_zone(peaks.sigma_max.value), float(peaks.sigma_max.value),
                         per_axis, worst, True)
