"""ISO 14839-2 vibration zones at the AMB sensors.

ISO 14839-2:2004 ("Vibration of rotating machinery equipped with active magnetic
bearings — Part 2: Evaluation of vibration") grades the largest radial displacement at
each AMB sensor, D_max (zero-to-peak, the orbit's largest radius), against the minimum
clearance C_min (the backup bearing's radial clearance): zone A below the A/B boundary,
B below B/C, C below C/D, D above. The boundaries are ``[signoff] iso14839_2_zones``,
fractions of C_min, by default 0.3, 0.4 and 0.5 (the standard's public text could not
confirm them, so they are a setting); zones A and B pass (unrestricted long-term
operation), as ISO 14839-3 grades the sensitivity (:mod:`ambseal.analysis.iso`).

The displacement graded is the API 617 unbalance response's at the sensors
(:mod:`ambseal.analysis.signoff.unbalance_api617`), the largest over its cases, from the minimum
to the maximum continuous speed: the rotor carrying the specification's unbalance. An
AMB without a backup clearance (:meth:`~ambseal.config.RigConfig.backup_clearance`) is
not graded, and says so.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ambseal.analysis.iso import ZONES
from ambseal.lti import json_float

__all__ = ["vibration_zone", "SensorZone", "IsoVibration", "iso14839_2_zones"]


def vibration_zone(d_max: float, c_min: float, boundaries) -> str:
    """ISO 14839-2 zone of a displacement ``d_max`` (m, 0-p) against the clearance
    ``c_min`` (m): boundaries (A/B, B/C, C/D) as fractions of ``c_min``; a value on a
    boundary (to 1e-12 of ``c_min``, the rounding of the ratio) belongs to the upper
    zone."""
    r = d_max / c_min
    for zone, edge in zip(ZONES, boundaries):
        if r < edge - 1e-12:
            return zone
    return ZONES[-1]


@dataclass(frozen=True)
class SensorZone:
    """One AMB's sensor: ``amb``, ``position_m``, ``c_min_m`` (None: no backup clearance),
    ``d_max_m`` (0-p), ``zone`` (None when not graded)."""

    amb: str
    position_m: float
    c_min_m: float | None
    d_max_m: float
    zone: str | None

    def to_dict(self) -> dict:
        return {"amb": self.amb, "position_m": self.position_m, "c_min_m": self.c_min_m,
                "d_max_m": json_float(self.d_max_m),
                "d_max_over_c_min": (None if self.c_min_m is None
                                     else json_float(self.d_max_m / self.c_min_m)),
                "zone": self.zone}


@dataclass(frozen=True)
class IsoVibration:
    """ISO 14839-2 at every AMB sensor of one controller (module docstring).

    Attributes
    ----------
    controller : str
    boundaries : tuple of float
        A/B, B/C, C/D as fractions of C_min.
    sensors : tuple of SensorZone
    """

    controller: str
    boundaries: tuple
    sensors: tuple

    @property
    def graded(self) -> bool:
        return any(s.zone is not None for s in self.sensors)

    @property
    def zone(self) -> str | None:
        """The worst graded zone."""
        zones = [s.zone for s in self.sensors if s.zone is not None]
        return max(zones, key=ZONES.index) if zones else None

    @property
    def passed(self) -> bool:
        """Every graded sensor in zone A or B."""
        return all(s.zone in (None, "A", "B") for s in self.sensors)

    def to_dict(self) -> dict:
        return {"boundaries": list(self.boundaries), "zone": self.zone,
                "passed": self.passed, "sensors": [s.to_dict() for s in self.sensors]}


def iso14839_2_zones(cfg, unbalance) -> IsoVibration:
    """Grade the AMB sensors' displacement of an API 617 unbalance response.

    Parameters
    ----------
    cfg : RigConfig
        The rig (its backup clearances and ``[signoff]``).
    unbalance : ambseal.analysis.signoff.unbalance_api617.Api617Unbalance
        Its responses at the probes.

    Returns
    -------
    IsoVibration
        One :class:`SensorZone` per AMB (none on a rig without AMBs).
    """
    bounds = tuple(cfg.signoff.iso14839_2_zones)
    out = []
    for a in cfg.amb:
        d = 0.0
        for c in unbalance.cases:
            band = (c.speed_hz >= unbalance.min_hz - 1e-9) & (
                c.speed_hz <= unbalance.max_hz + 1e-9)
            p = int(np.argmin(np.abs(np.asarray(c.probe_m) - a.sensor_position)))
            if band.any():
                d = max(d, 0.5e-6 * float(c.probe_um[band, p].max()))
        cm = cfg.backup_clearance(a)
        out.append(SensorZone(a.name, a.sensor_position, cm, d,
                              None if cm is None else vibration_zone(d, cm, bounds)))
    return IsoVibration(unbalance.controller, bounds, tuple(out))
