"""API 617 Level II stability analysis with the AMB loop as it runs.

API 617 (8th ed., 2014), Part 1, Level II: the log decrement of the first forward mode
at the maximum continuous speed with every modelled destabilising source, tabulated
component by component — the rotor on its supports alone, each seal added alone (its
coefficients at the operating pressure drop, ``[operating] pressure_bar``, and the
synchronous frequency), the anticipated aerodynamic cross-coupling added alone (each
stage's q_A of :func:`ambseal.analysis.level1.stage_cross_coupling` as k_xy = q_A,
k_yx = −q_A at the stage), and all of them together. The machine passes when the loop
with every source is stable and its least damped forward mode keeps δ ≥ ``[signoff]
log_dec_min`` (0.1; API 684 (2nd ed., 2005) §2.8's limit, as ROSS's API report tool
tabulates it — the standard's public text could not confirm the clause, so it is a
setting).

With AMBs the supports are the controller: each row's loop is the discrete controller
with its computation delay on the sampled plant
(:func:`ambseal.analysis.campbell.modes_as_run`); a rig on springs alone is analysed as
it is. The screened mode of each row is its least damped forward (not backward) mode
below the bending limit and Nyquist: the first forward mode API 617 names where it is
the least damped, and never a forward mode less damped than the one reported (an AMB
loop's first forward mode by frequency is often an overdamped rigid-body or controller
pole, while a bending mode above it is the one that fails).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from ambseal.analysis.campbell import modes_as_run
from ambseal.analysis.level1 import stage_cross_coupling, stage_position
from ambseal.config import Spring
from ambseal.errors import ConfigError
from ambseal.lti import json_float
from ambseal.model import bending_limit_hz

__all__ = ["Level2Row", "Level2", "level2_analysis"]


@dataclass(frozen=True)
class Level2Row:
    """One line of the Level II table.

    Attributes
    ----------
    component : str
        What the loop holds: ``"rotor and supports"``, ``"+ seal <name>"``,
        ``"+ Q_A at the stages"`` or ``"all sources"``.
    frequency_hz : float
        Damped frequency of its least damped forward mode (Hz; NaN without one).
    log_dec : float
        That mode's log decrement (NaN without one).
    stable : bool
        The loop's verdict (every pole, not the forward modes alone).
    """

    component: str
    frequency_hz: float
    log_dec: float
    stable: bool

    def to_dict(self) -> dict:
        return {"component": self.component, "frequency_hz": json_float(self.frequency_hz),
                "log_dec": json_float(self.log_dec), "stable": self.stable}


@dataclass(frozen=True)
class Level2:
    """The Level II analysis of one controller (module docstring).

    Attributes
    ----------
    controller : str
    speed_hz, pressure_bar : float
        Where it is taken: the maximum continuous speed (Hz) and the seals' pressure drop.
    rows : tuple of Level2Row
        The table; the last row holds every source.
    limit : float
        The least log decrement allowed.
    """

    controller: str
    speed_hz: float
    pressure_bar: float
    rows: tuple
    limit: float

    @property
    def log_dec(self) -> float:
        """δ with every source (the last row)."""
        return self.rows[-1].log_dec

    @property
    def passed(self) -> bool:
        last = self.rows[-1]
        return bool(last.stable and last.log_dec >= self.limit)

    def to_dict(self) -> dict:
        """The ``level2`` block."""
        return {"speed_hz": self.speed_hz, "pressure_bar": self.pressure_bar,
                "log_dec": json_float(self.log_dec), "limit": self.limit,
                "passed": self.passed, "table": [r.to_dict() for r in self.rows]}


def _row(component, cfg, controller, speed_hz, max_hz, p) -> Level2Row:
    m = modes_as_run(cfg, controller, speed_hz=speed_hz, max_hz=max_hz, pressure_bar=p)
    fwd = [k for k in range(m.poles.size) if m.whirl[k] != "backward"]
    if not fwd:
        return Level2Row(component, math.nan, math.nan, m.stable)
    k = min(fwd, key=lambda i: m.log_decrement[i])
    return Level2Row(component, float(m.frequency_hz[k]), float(m.log_decrement[k]),
                     m.stable)


def level2_analysis(cfg, controller=None, *, name: str = "none",
                    pressure_bar: float | None = None, progress=None) -> Level2:
    """API 617 Level II of a rig with one controller as it runs (module docstring).

    Parameters
    ----------
    cfg : RigConfig
        The rig with its ``[[stage]]`` tables (and seals).
    controller : DigitalController or ScheduledDigital, optional
        As it runs; None for a rig on springs alone.
    name : str
        The controller's name in the result.
    pressure_bar : float, optional
        The seals' pressure drop; default ``[operating] pressure_bar``.
    progress : callable, optional
        Called with one line per row.

    Returns
    -------
    Level2

    Raises
    ------
    ConfigError
        No ``[[stage]]`` or a maximum continuous speed of 0.
    """
    if not cfg.stage:
        raise ConfigError("API 617 Level II needs the machine's stages: add a [[stage]] per "
                          "impeller")
    speed_hz = cfg.operating.continuous_hz[1]
    if not speed_hz > 0:
        raise ConfigError("API 617 Level II: the maximum continuous speed must be > 0")
    p = cfg.operating.pressure_bar if pressure_bar is None else float(pressure_bar)
    max_hz = bending_limit_hz(cfg)
    if controller is not None and cfg.amb:
        max_hz = min(max_hz, 0.45 * cfg.controller.sample_rate_hz)
    omega = 2 * math.pi * speed_hz
    aero = [Spring(position=stage_position(cfg, st), kxx=0.0, kyy=0.0, kxy=q, kyx=-q,
                   name=f"api617_qA{i}")
            for i, (st, q) in enumerate(
                (st, stage_cross_coupling(st, cfg.machine.kind, omega)) for st in cfg.stage)]
    variants = [("rotor and supports", {"seal": []})]
    variants += [(f"+ seal {s.name}", {"seal": [s]}) for s in cfg.seal]
    variants += [("+ Q_A at the stages", {"seal": [], "spring": [*cfg.spring, *aero]})]
    variants += [("all sources", {"spring": [*cfg.spring, *aero]})]
    rows = []
    for component, update in variants:
        rows.append(_row(component, cfg.model_copy(update=update), controller, speed_hz,
                         max_hz, p))
        if progress:
            r = rows[-1]
            progress(f"{name}: Level II {component}: δ = {r.log_dec:.3g} at "
                     f"{r.frequency_hz:.4g} Hz{'' if r.stable else ', UNSTABLE'}")
    return Level2(name, speed_hz, p, tuple(rows), cfg.signoff.log_dec_min)
