"""The conditions a controller is judged at: pressure drops × speeds, from the rig file.

``[design] pressures_bar`` / ``speeds_hz`` when given; otherwise 0, nominal and 2× nominal
pressure drop (thesis P5 §4; the nominal one alone on a rig judged at speeds) and the
operating speed, or, for a rig whose seals change with speed over a stated range, the
range's ends and middle (P3 §4).
"""

from __future__ import annotations

__all__ = ["judged_conditions"]


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


def _scheduled(cfg) -> bool:
    """Seals that change with speed over a stated speed range (P3 §4): judged at speeds."""
    return cfg.operating.speed_range_hz is not None and any(
        s.frequency_dependent for s in cfg.seal)
