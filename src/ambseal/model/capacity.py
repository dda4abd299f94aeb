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
differential pair (i_c ≤ i0: neither coil's current below zero), the amplifier's limit on
the control current (i_c ≤ ``current_limit``, the limit the virtual facility clips the
current reference at, :mod:`ambseal.identify.facility`) and the voltage,
R i0 + |R + jωL| i_c ≤ ``supply_voltage``
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

from ambseal.config import Amb, check_coil
from ambseal.errors import ConfigError
from ambseal.model.amb import MU0, amb_factors

__all__ = ["coil_inductance", "force_capacity", "load_capacity", "amplifier_needs",
           "transient_needs", "limits_used", "amplifier_use"]


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
        Per frequency, (ζ, η): Ki·min(i0, current_limit, (V − R i0)/|R + jωL|), the
        limits the rig file does not give left out.

    Raises
    ------
    ConfigError
        No bias current, a Ki that is not known, a negative frequency, a supply voltage at
        or below R·i0 (the amplifier cannot hold the bias), or a supply voltage without an
        inductance to take it through.
    """
    w = _frequencies(amb, omega)
    ki = amb_factors(amb)[0]
    if None in ki:
        raise ConfigError(f"amb {amb.name}: the force capacity needs bias_current (A) and "
                          "Ki (or the geometry)")
    i0, limit, coil = _amplifier(amb)
    bound = np.full(w.shape, i0)
    if limit is not None:
        bound = np.minimum(bound, limit)
    if coil is not None:
        L, R, headroom = coil
        with np.errstate(divide="ignore"):  # R = 0 at ω = 0: no voltage bound (inf)
            bound = np.minimum(bound, headroom / np.hypot(R, w * L))
    return bound[:, None] * np.asarray(ki, float)[None, :]


def amplifier_needs(amb: Amb, omega, current_a, static_a: float = 0.0) -> dict:
    """What the amplifier of an AMB axis must deliver to drive a sinusoidal control current
    (module docstring): the current and the voltage, whatever its limits — the size of the
    smallest amplifier that does.

    Parameters
    ----------
    amb : Amb
        One ``[[amb]]`` of the rig file, with its ``bias_current``.
    omega : array_like, shape (F,)
        Frequencies (rad/s), ≥ 0.
    current_a : array_like, shape (F,)
        The control current's amplitude (A, zero-to-peak) at each frequency.
    static_a : float
        A static control current (A) the sinusoid rides on (a static load's).

    Returns
    -------
    dict
        Arrays of shape (F,): ``current_a`` |i_s| + i_c (A; the smallest
        ``current_limit``) and ``voltage_v`` R (i0 + |i_s|) + |R + jωL| i_c (V; the
        smallest ``supply_voltage``), None where the rig file gives neither ``inductance``
        nor the geometry to derive it (``resistance`` defaults to 0).

    Raises
    ------
    ConfigError
        No bias current, a negative frequency, or as many amplitudes as frequencies not
        given.
    """
    w = _frequencies(amb, omega)
    ic = np.abs(np.asarray(current_a, float))
    if ic.shape != w.shape:
        raise ConfigError(f"amb {amb.name}: amplifier: {ic.shape[0] if ic.ndim else 1} "
                          f"current amplitudes for {w.size} frequencies")
    if amb.bias_current is None:
        raise ConfigError(f"amb {amb.name}: the amplifier's voltage needs bias_current (A)")
    L, R = coil_inductance(amb), float(amb.resistance or 0.0)
    i_s = abs(float(static_a))
    voltage = (None if L is None
               else R * (float(amb.bias_current) + i_s) + np.hypot(R, w * L) * ic)
    return {"current_a": i_s + ic, "voltage_v": voltage}


def transient_needs(amb: Amb, current_a, rate_a_per_s, static_a: float = 0.0) -> dict:
    """What the amplifier of an AMB axis must deliver to drive a control current i(t) (a
    transient: an impulse or step response): the coils carry i0 ± i, so their voltages are
    R(i0 ± i) ± L di/dt, the larger in size R i0 + |R i + L di/dt| (module docstring).

    Parameters
    ----------
    amb : Amb
        One ``[[amb]]`` of the rig file, with its ``bias_current``.
    current_a : array_like, shape (N,)
        The control current i (A) at N instants.
    rate_a_per_s : array_like, shape (N,) or None
        Its rate di/dt (A/s) there; None when the amplifier's current loop is ideal (an
        instantaneous step has no finite voltage): the voltage is then not judged.
    static_a : float
        A static control current (A) under it, of either sign: counted as |i_s| + |i|
        and R (i0 + |i_s|) + |R i + L di/dt|.

    Returns
    -------
    dict
        Arrays of shape (N,): ``current_a`` |i_s| + |i| (A) and ``voltage_v`` (V; None
        without a rate or without the coil's inductance, as in :func:`amplifier_needs`).

    Raises
    ------
    ConfigError
        No bias current, or a rate not of the current's shape.
    """
    i = np.atleast_1d(np.asarray(current_a, float))
    if amb.bias_current is None:
        raise ConfigError(f"amb {amb.name}: the amplifier's voltage needs bias_current (A)")
    L, R = coil_inductance(amb), float(amb.resistance or 0.0)
    i_s = abs(float(static_a))
    if rate_a_per_s is None or L is None:
        return {"current_a": i_s + np.abs(i), "voltage_v": None}
    rate = np.atleast_1d(np.asarray(rate_a_per_s, float))
    if rate.shape != i.shape:
        raise ConfigError(f"amb {amb.name}: amplifier: {rate.size} current rates for "
                          f"{i.size} currents")
    return {"current_a": i_s + np.abs(i),
            "voltage_v": R * (float(amb.bias_current) + i_s) + np.abs(R * i + L * rate)}


def limits_used(amb: Amb, need: dict) -> dict:
    """The fractions of an AMB axis's limits that what its amplifier must deliver uses
    (:func:`amplifier_needs`, :func:`transient_needs`): 1 is the limit, above it the
    amplifier saturates or a coil's current would go below zero.

    Parameters
    ----------
    amb : Amb
        One ``[[amb]]`` of the rig file, with its ``bias_current``.
    need : dict
        ``current_a`` and ``voltage_v`` (arrays of one shape; ``voltage_v`` may be None).

    Returns
    -------
    dict
        Arrays of ``need``'s shape: ``bias_used`` |i_c|/i0 (the differential pair's linear
        range), ``current_used`` |i_c|/``current_limit`` and ``voltage_used``
        (the voltage)/``supply_voltage``; the last two None where the rig file gives no
        such limit (or ``need`` no voltage).

    Raises
    ------
    ConfigError
        As :func:`force_capacity`.
    """
    i0, limit, coil = _amplifier(amb)
    ic, v = need["current_a"], need["voltage_v"]
    return {"bias_used": ic / i0, "current_used": None if limit is None else ic / limit,
            "voltage_used": None if coil is None or v is None else v / amb.supply_voltage}


def amplifier_use(amb: Amb, omega, current_a) -> dict:
    """The fractions of an AMB axis's limits a sinusoidal control current uses
    (:func:`limits_used` of :func:`amplifier_needs`).

    Parameters
    ----------
    amb : Amb
        One ``[[amb]]`` of the rig file, with its ``bias_current``.
    omega : array_like, shape (F,)
        Frequencies (rad/s), ≥ 0.
    current_a : array_like, shape (F,)
        The control current's amplitude (A, zero-to-peak) at each frequency.

    Returns
    -------
    dict
        Arrays of shape (F,): ``bias_used`` i_c/i0, ``current_used`` i_c/``current_limit``
        and ``voltage_used`` (R i0 + |R + jωL| i_c)/``supply_voltage``; the last two None
        where the rig file gives no such limit.

    Raises
    ------
    ConfigError
        As :func:`force_capacity`.
    """
    return limits_used(amb, amplifier_needs(amb, omega, current_a))


def _frequencies(amb: Amb, omega) -> np.ndarray:
    w = np.atleast_1d(np.asarray(omega, float))
    if w.ndim != 1 or not np.all(np.isfinite(w)) or np.any(w < 0):
        raise ConfigError(f"amb {amb.name}: force capacity: expected frequencies ≥ 0 rad/s")
    return w


def _amplifier(amb: Amb) -> tuple:
    """``(i0, current_limit or None, (L, R, V − R i0) or None)`` of an AMB; ConfigError as
    :func:`force_capacity`."""
    where = f"amb {amb.name}"
    if amb.bias_current is None:
        raise ConfigError(f"{where}: the force capacity needs bias_current (A) and Ki (or "
                          "the geometry)")
    i0 = float(amb.bias_current)
    if amb.supply_voltage is None:
        return i0, amb.current_limit, None
    try:  # the rig file's own rule, for an AMB copied without validation
        check_coil(amb)
    except ValueError as exc:
        raise ConfigError(f"{where}: {exc}") from None
    L, R = coil_inductance(amb), float(amb.resistance or 0.0)
    return i0, amb.current_limit, (L, R, amb.supply_voltage - R * i0)


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
