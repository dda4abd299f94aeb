"""API 617 Level II stability analysis with the AMB loop as it runs.

API 617 (8th ed., 2014), Part 1, Level II: the log decrement of the first forward mode
at the maximum continuous speed with every modelled destabilising source, tabulated
component by component — the rotor on its supports alone, each seal added alone (its
coefficients at the operating pressure drop, ``[operating] pressure_bar``, and the
synchronous frequency), the anticipated aerodynamic cross-coupling added alone (each
stage's q_A of :func:`ambseal.analysis.signoff.level1.stage_cross_coupling` as k_xy = q_A,
k_yx = −q_A at the stage), and all of them together. The machine passes when the loop
with every source is stable and the graded mode (below) keeps δ ≥ ``[signoff]
log_dec_min`` (0.1; API 684 (2nd ed., 2005) §2.8's limit, as ROSS's API report tool
tabulates it — the standard's public text could not confirm the clause, so it is a
setting).

With AMBs the supports are the controller: each row's loop is the discrete controller
with its computation delay on the sampled plant
(:func:`ambseal.analysis.campbell.modes_as_run`); a rig on springs alone is analysed as
it is. The graded mode is API 617's first forward mode, a *resonant* one: a mode whose
amplification factor AF ≈ π/δ is at least 2.5, the factor from which API 684 (2nd ed.,
2005, §1.3.3) and API 617 count a resonance as a critical speed — δ ≤ π/2.5 = 1.257,
ζ ≤ 0.2 (:func:`ambseal.analysis.campbell.resonant`). An AMB controller damps the rigid-
body modes near ζ = 1: such an overdamped pole, whose small imaginary part makes it the
lowest "mode" by frequency, has no resonance and is never graded (its δ of tens would
pass any limit while a lightly damped nutation above it went ungraded). The forward
modes of the loop without sources are followed to the loop with every source (by nearest
eigenvalue, :func:`ambseal.analysis.campbell.track_modes`); of those forward and
resonant with every source, the graded one is, in this order:

1. the least damped with every source among those the sources take damping from (more
   than :data:`LOST_SHARE` of their δ): the mode the sources act on, as Level I screens
   the mode the cross-coupling destabilises;
2. if the sources take none (a machine without sources: a pump, a flywheel), the lowest
   in frequency: API 617's first forward resonant mode at the maximum continuous speed;
3. if the loop has no forward resonant mode up to the band's top, the least damped
   forward mode (δ > 1.257, far above any limit), reported as not resonant.

Each row reports that mode, followed from the loop without sources, with its kind
(:func:`ambseal.analysis.mode_naming.mode_kind`: rigid cylindrical or conical, or
bending, with its whirl). A bending mode the sources leave alone, with a structural δ of
a few hundredths, is not what Level II judges where the sources act on another; a mode
they leave at δ 0.06 is. A row's loop is unstable where a pole within the band of
modes it reads breaks the stability rule; a lossless mesh mode far above, which nothing
damps, does not decide it (:meth:`ambseal.analysis.campbell.ClosedLoopModes.deciding`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from ambseal.analysis.campbell import modes_as_run, resonant, track_modes
from ambseal.analysis.mode_naming import mode_kind, support_span_m
from ambseal.analysis.signoff.level1 import stage_cross_coupling, stage_position, without_seals
from ambseal.config import Spring
from ambseal.errors import ConfigError
from ambseal.lti import json_float
from ambseal.model import bending_limit_hz

__all__ = ["Level2Row", "Level2", "level2_analysis", "LOST_SHARE"]

#: The sources act on a mode when they take more than this share of its log decrement.
LOST_SHARE = 0.01


@dataclass(frozen=True)
class Level2Row:
    """One line of the Level II table.

    Attributes
    ----------
    component : str
        What the loop holds: ``"rotor and supports"``, ``"+ seal <name>"``,
        ``"+ Q_A at the stages"`` or ``"all sources"``.
    frequency_hz : float
        Damped frequency of the screened mode (Hz; NaN where it is not followed).
    log_dec : float
        That mode's log decrement (NaN without one).
    stable : bool
        The loop's verdict (every pole, not the forward modes alone).
    kind : str
        The mode's kind and whirl (:func:`ambseal.analysis.mode_naming.mode_kind`, e.g.
        ``"rigid conical, forward whirl: the nutation"``), with ``", not resonant"`` where
        the loop has no forward resonant mode; ``""`` where it is not followed.
    """

    component: str
    frequency_hz: float
    log_dec: float
    stable: bool
    kind: str = ""

    def to_dict(self) -> dict:
        return {"component": self.component, "frequency_hz": json_float(self.frequency_hz),
                "log_dec": json_float(self.log_dec), "stable": self.stable,
                "kind": self.kind}


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
    def kind(self) -> str:
        """The graded mode's kind with every source (the last row)."""
        return self.rows[-1].kind

    @property
    def passed(self) -> bool:
        last = self.rows[-1]
        return bool(last.stable and last.log_dec >= self.limit)

    def to_dict(self) -> dict:
        """The ``level2`` block."""
        return {"speed_hz": self.speed_hz, "pressure_bar": self.pressure_bar,
                "log_dec": json_float(self.log_dec), "limit": self.limit,
                "passed": self.passed, "mode": self.kind,
                "table": [r.to_dict() for r in self.rows]}


def _screened(base, last) -> tuple[int | None, bool]:
    """(the mode of ``base``, the rotor on its supports, that Level II grades; whether it
    is resonant): of the forward modes followed from ``base`` to ``last`` (every source),
    those resonant in ``last``; of them the least damped in ``last`` among those the
    sources take damping from, else the lowest in frequency, API 617's first; without a
    resonant one the least damped forward mode (module docstring). None without a
    forward mode."""
    tr = track_modes([base, last])
    # forward with every source: without them an isotropic rotor's forward and backward
    # whirl coincide, and their shapes there say nothing
    lines = [j for j in range(tr.shape[1]) if tr[0, j] >= 0 and tr[1, j] >= 0
             and last.whirl[tr[1, j]] != "backward"]
    if not lines:
        return None, False
    d0 = {j: base.log_decrement[tr[0, j]] for j in lines}
    d1 = {j: last.log_decrement[tr[1, j]] for j in lines}
    sharp = [j for j in lines if resonant(d1[j])]
    hit = [j for j in sharp if d1[j] < d0[j] - LOST_SHARE * abs(d0[j])]
    if hit:
        j = min(hit, key=lambda i: d1[i])
    elif sharp:  # no source acts (none, or none takes damping): API 617's first
        j = min(sharp, key=lambda i: last.frequency_hz[tr[1, i]])
    else:  # no resonance to grade: the least damped, δ above any limit
        j = min(lines, key=lambda i: d1[i])
    return int(tr[0, j]), bool(sharp)


def _row(component, m, base, k0, span, sharp: bool) -> Level2Row:
    """The row of the loop ``m``: the mode followed from ``base``'s mode ``k0``, named
    by its shape over the bearing ``span`` (``", not resonant"`` unless ``sharp``);
    stable unless a pole within the band of modes it reads breaks the rule
    (:meth:`~ambseal.analysis.campbell.ClosedLoopModes.deciding`)."""
    stable = not m.deciding().size
    if k0 is None:
        return Level2Row(component, math.nan, math.nan, stable)
    tr = track_modes([base, m])
    j = next((j for j in range(tr.shape[1]) if tr[0, j] == k0), None)
    k = None if j is None else int(tr[1, j])
    if k is None or k < 0:
        return Level2Row(component, math.nan, math.nan, stable)
    kind = mode_kind(m.shapes[k], m.node_z_m, span, m.whirl[k], m.speed_hz)
    return Level2Row(component, float(m.frequency_hz[k]), float(m.log_decrement[k]),
                     stable, kind if sharp else f"{kind}, not resonant")


def level2_analysis(cfg, controller=None, *, name: str = "none",
                    pressure_bar: float | None = None, progress=None) -> Level2:
    """API 617 Level II of a rig with one controller as it runs (module docstring).

    Parameters
    ----------
    cfg : RigConfig
        The rig with its ``[[stage]]`` tables (and seals); without stages (a flywheel, a
        motor, a pump) the rows leave out Q_A, the seals are every source.
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
        A maximum continuous speed of 0.
    """
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
    bearings = without_seals(cfg).spring  # a spring may be a seal
    variants = [("rotor and supports", {"seal": [], "spring": bearings})]
    variants += [(f"+ seal {s.name}", {"seal": [s], "spring": bearings}) for s in cfg.seal]
    variants += [(f"+ seal {s.name or f'spring{i}'}", {"seal": [], "spring": [*bearings, s]})
                 for i, s in enumerate(cfg.spring) if s.kind == "seal"]
    if aero:  # a machine without stages (a flywheel, a motor, a pump) has no Q_A
        variants += [("+ Q_A at the stages", {"seal": [], "spring": [*bearings, *aero]})]
    variants += [("all sources", {"spring": [*cfg.spring, *aero]})]
    loops = [modes_as_run(cfg.model_copy(update=update), controller, speed_hz=speed_hz,
                          max_hz=max_hz, pressure_bar=p) for _, update in variants]
    k0, sharp = _screened(loops[0], loops[-1])
    span = support_span_m(cfg)
    rows = []
    for (component, _), m in zip(variants, loops):
        rows.append(_row(component, m, loops[0], k0, span, sharp))
        if progress:
            r = rows[-1]
            progress(f"{name}: Level II {component}: δ = {r.log_dec:.3g} at "
                     f"{r.frequency_hz:.4g} Hz ({r.kind}){'' if r.stable else ', UNSTABLE'}")
    return Level2(name, speed_hz, p, tuple(rows), cfg.signoff.log_dec_min)
