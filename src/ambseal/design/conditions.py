"""The conditions a controller is judged at: pressure drops × speeds, from the rig file.

``[design] pressures_bar`` / ``speeds_hz`` when given; otherwise 0, nominal and 2× nominal
pressure drop (thesis P5 §4; the nominal one alone on a rig judged at speeds) and the
operating speed, or, for a rig whose seals change with speed over a stated range, the
range's ends and middle (P3 §4).

A machine on AMBs levitates at standstill and runs up through every speed to its top, so
every controller must also hold the rotor there: ``[design] stability_speeds_hz`` when
given, else standstill, the operating speed, the ends of ``[operating] speed_range_hz`` and
the top speed in quarters (:data:`STABILITY_STEPS`) — the speeds where, at each judged
pressure, the full-order loop (continuous with the target's delay, and as it runs, sampled)
must be stable. The top speed is the top of the speed range, else the operating speed.
"""

from __future__ import annotations

__all__ = ["judged_conditions", "stability_speeds", "STABILITY_STEPS"]

#: The top speed in this many equal steps from standstill: the speeds a run-up passes
#: through, at a spacing over which the gyroscopic splitting of the modes, smooth in speed,
#: moves them little.
STABILITY_STEPS = 4


def judged_conditions(cfg, pressure_bar: float | None = None) -> tuple[tuple, tuple]:
    """The judged pressures (bar) and speeds (Hz): ``[design] pressures_bar``/``speeds_hz``,
    else 0, nominal and 2× nominal pressure (the nominal one alone on a rig judged at
    speeds) and :func:`_speeds` (module docstring, "Judged conditions")."""
    d = cfg.design
    p = cfg.operating.pressure_bar if pressure_bar is None else float(pressure_bar)
    if d.pressures_bar is not None:
        pressures = tuple(d.pressures_bar)
    elif _scheduled(cfg):
        pressures = (cfg.operating.pressure_bar,)
    else:
        pressures = (0.0, p, 2 * p) if p > 0 else (0.0,)
    return pressures, tuple(d.speeds_hz) if d.speeds_hz is not None else _speeds(cfg)


def _speeds(cfg) -> tuple:
    """Judged speeds (Hz): the operating speed, or the ends and middle of the speed range of
    a rig whose seals change with speed (P3 §4)."""
    f = cfg.operating.speed_rpm / 60.0
    if _scheduled(cfg):
        lo, hi = cfg.operating.speed_range_hz
        return tuple(sorted({lo, f, hi}))
    return (f,)


def stability_speeds(cfg) -> tuple[tuple, str]:
    """The speeds (Hz) every controller must be stable at, and the rule that gave them
    (module docstring)."""
    d = cfg.design
    if d.stability_speeds_hz is not None:
        return tuple(sorted(set(d.stability_speeds_hz))), "set"
    op = cfg.operating.speed_rpm / 60.0
    rng = cfg.operating.speed_range_hz
    top = float(rng[1]) if rng is not None else op
    speeds = {0.0, op, *(top * k / STABILITY_STEPS for k in range(1, STABILITY_STEPS + 1))}
    if rng is not None:
        speeds.add(float(rng[0]))
    rule = (f"standstill, the operating speed{', the speed range' if rng else ''} and the "
            f"top speed ({'top of [operating] speed_range_hz' if rng else 'the operating speed'})"
            f" in {STABILITY_STEPS} steps")
    return tuple(sorted(speeds)), rule


def _scheduled(cfg) -> bool:
    """Seals that change with speed over a stated speed range (P3 §4): judged at speeds."""
    return cfg.operating.speed_range_hz is not None and any(
        s.frequency_dependent for s in cfg.seal)
