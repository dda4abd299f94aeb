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

A peak exactly on a limit belongs to the upper zone (3 → B, 4 → C, 5 → D). The standard
grades each axis (the diagonal elements); the thesis requires the largest singular value of
the full output sensitivity to be below 3 to cover cross-coupling (P5 §4.1 item 4, §4.4.2,
Fig. 13), which is at least as strict since ``σ̄(S) ≥ max_i |S_ii|``.

An unstable loop has no meaningful sensitivity peak; pass ``inf`` (zone D).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from ambseal.errors import ModelError
from ambseal.lti import json_float

__all__ = ["ZONE_LIMITS", "ZONES", "zone_limit_db", "iso_zone", "IsoAssessment", "iso_assessment"]

#: Upper limits (exclusive) of zones A, B, C on the sensitivity peak (absolute gain).
ZONE_LIMITS: tuple[float, float, float] = (3.0, 4.0, 5.0)
#: Zone letters from best to worst.
ZONES: tuple[str, str, str, str] = ("A", "B", "C", "D")


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


@dataclass(frozen=True)
class IsoAssessment:
    """ISO 14839-3 zones of one closed loop.

    Attributes
    ----------
    zone_sigma_max : str
        Zone of the σ̄ peak of the output sensitivity (thesis criterion, P5 §4.1 item 4).
    sigma_max_peak : float
        That peak (absolute gain; ``inf`` if the loop is unstable).
    zones_per_axis : tuple of (str, str)
        ``(channel, zone)`` per axis from the diagonal peaks (the standard's criterion).
    zone_per_axis_worst : str
        Worst of the per-axis zones.
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
    per_axis = tuple((p.channel, iso_zone(p.value)) for p in peaks.diagonal)
    worst = max((z for _, z in per_axis), key=ZONES.index, default="A")
    return IsoAssessment(iso_zone(peaks.sigma_max.value), float(peaks.sigma_max.value), per_axis, worst, True)
