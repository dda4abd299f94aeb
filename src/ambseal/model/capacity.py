"""What a magnetic bearing can deliver: its coil, its amplifier's limits and its load
capacity.

An AMB axis is a differentially driven pair of magnets (:mod:`ambseal.model.amb`); each
magnet's coil of ``turns`` N over two air gaps s0 of pole area A has the inductance

    L = μ0 N² A / (2 s0)

(iron and fringing neglected), which is the force law's by virtual work: f = ½ i² |dL/ds|
cos α = μ0 N² A i² cos α / (4 s²), the k of :func:`ambseal.model.amb.amb_factors_from_geometry`
(Schweitzer & Maslen, *Magnetic Bearings*, 2009, Eqs. 3.27–3.30). A ``[[amb]]`` may give
``inductance`` itself; it then wins.

The force amplitude an axis can hold at a frequency ω (rad/s) is Ki times the largest
control-current amplitude i_c its amplifier can drive there: the linear range of the
differential pair (i_c ≤ i0: neither coil's current below zero), the current limit
(i0 + i_c ≤ ``current_limit``) and the voltage, R i0 + |R + jωL| i_c ≤ ``supply_voltage``
— at high frequency i_c ≤ V/(ωL), the amplifier's slew rate di/dt ≤ V/L, so the force
capacity falls as Ki V/(L ω) (Maslen's force slew-rate limit; Schweitzer & Maslen 2009).
A limit the rig file does not give does not bound it.

The static load capacity is one magnet at the saturation flux density B_sat with its
opposite off: B = μ0 N i / (2 s0) in the gaps, so f = B_sat² A cos α / μ0
(Schweitzer & Maslen 2009). ``saturation_flux_density`` defaults to 1.2 T, a usable flux of
silicon-iron laminations; the public texts give no one value, so it is a setting.
"""

from __future__ import annotations

import math

import numpy as np

from ambseal.config import Amb
from ambseal.errors import ConfigError
from ambseal.model.amb import MU0, amb_factors

__all__ = ["coil_inductance", "force_capacity", "load_capacity"]


def coil_inductance(amb: Amb) -> float | None:
    """The inductance (H) of one magnet's coil of an AMB axis (module docstring).

    Parameters
    ----------
    amb : Amb
        One ``[[amb]]`` of the rig file.

    Returns
    -------
    float or None
        ``inductance`` when given, else μ0 N² A / (2 s0) from ``turns``, ``pole_area`` and
        ``air_gap``; None when neither is given.
    """
    if amb.inductance is not None:
        return float(amb.inductance)
    if None in (amb.turns, amb.pole_area, amb.air_gap):
        return None
    return MU0 * amb.turns ** 2 * amb.pole_area / (2.0 * amb.air_gap)


def force_capacity(amb: Amb, omega) -> np.ndarray:
    """The largest force amplitude (N) each actuator axis of an AMB can hold against a
    sinusoid of frequency ω (module docstring).

    Parameters
    ----------
    amb : Amb
        One ``[[amb]]`` of the rig file, with its ``bias_current``.
    omega : array_like, shape (F,)
        Frequencies (rad/s), ≥ 0.

    Returns
    -------
    numpy.ndarray, shape (F, 2)
        Per frequency, (ζ, η): Ki·min(i0, current_limit − i0, (V − R i0)/|R + jωL|), the
        limits the rig file does not give left out.

    Raises
    ------
    ConfigError
        No bias current, a Ki that is not known, a negative frequency, a current limit at
        or below the bias or a supply voltage at or below R·i0 (the amplifier cannot hold
        the bias), or a supply voltage without an inductance to take it through.
    """
    w = np.atleast_1d(np.asarray(omega, float))
    where = f"amb {amb.name}"
    if w.ndim != 1 or not np.all(np.isfinite(w)) or np.any(w < 0):
        raise ConfigError(f"{where}: force capacity: expected frequencies ≥ 0 rad/s")
    ki = amb_factors(amb)[0]
    if amb.bias_current is None or None in ki:
        raise ConfigError(f"{where}: the force capacity needs bias_current (A) and Ki (or "
                          "the geometry)")
    i0 = float(amb.bias_current)
    bound = np.full(w.shape, i0)
    if amb.current_limit is not None:
        if amb.current_limit <= i0:
            raise ConfigError(f"{where}: current_limit = {amb.current_limit:g} A is not above "
                              f"the bias current {i0:g} A")
        bound = np.minimum(bound, amb.current_limit - i0)
    if amb.supply_voltage is not None:
        L, R = coil_inductance(amb), float(amb.resistance or 0.0)
        if L is None:
            raise ConfigError(f"{where}: supply_voltage needs the coil's inductance (H) or "
                              "the geometry (turns, pole_area, air_gap) to derive it")
        headroom = amb.supply_voltage - R * i0
        if headroom <= 0:
            raise ConfigError(f"{where}: supply_voltage = {amb.supply_voltage:g} V does not "
                              f"drive the bias current through R = {R:g} Ω")
        with np.errstate(divide="ignore"):  # R = 0 at ω = 0: no voltage bound (inf)
            bound = np.minimum(bound, headroom / np.hypot(R, w * L))
    return bound[:, None] * np.asarray(ki, float)[None, :]


def load_capacity(amb: Amb) -> float | None:
    """The static load capacity (N) of an AMB axis: B_sat² A cos α / μ0 (module
    docstring).

    Parameters
    ----------
    amb : Amb
        One ``[[amb]]`` of the rig file.

    Returns
    -------
    float or None
        None when the rig file gives no ``pole_area``.
    """
    if amb.pole_area is None:
        return None
    return (amb.saturation_flux_density ** 2 * amb.pole_area
            * math.cos(math.radians(amb.pole_angle_deg)) / MU0)
