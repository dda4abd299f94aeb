"""API 617 Level I stability screening with the AMB loop as it runs.

API 617 (8th ed., 2014), Part 1, the rotor stability analysis (Level I): an *anticipated*
aerodynamic cross-coupling per impeller or stage,

    q_A = B · (P/Ω) · (ρ_d/ρ_s) / (D_c · H_c)      (N/m; compressors, B = 3)
    q_A = B · (P/Ω) / (D_c · H_c)                   (N/m; turbines, B = 1.5)

with P/Ω the stage's torque (rated power over the maximum continuous speed), D_c the
impeller diameter and H_c the smaller of the impeller's discharge and the diffuser's
width; Q_A = Σ q_A. (The standard's US form, q_A = HP·B·C·(ρ_d/ρ_s)/(D_c·H_c·N) with
C = 63, HP in hp, D_c and H_c in inches and N in rpm, is the same number in klbf/in:
63 ≈ 63 025/1000, the torque in klbf·in.)

A cross-coupled stiffness Q (k_xy = Q, k_yx = −Q, destabilising forward whirl) is applied
at mid-span of a between-bearings rotor, or at each overhung stage in proportion to its
q_A (or wholly where ``[signoff] level1_position_m`` puts it: ROSS's ``run_level1`` takes
the node nearest mid-span), at the maximum continuous speed, with the seals left out; Q
runs from 0 to 10·Q_A (at least). The log decrement δ of the forward mode Q destabilises
is taken at each Q. ROSS's ``Rotor.run_level1`` takes the lowest-frequency mode that is
not backward; under an AMB controller that mode is often an overdamped rigid-body mode,
or a controller pole with a small imaginary part that Q hardly moves, and the lowest log
decrement of all would be an undamped bending mode Q does not touch. So the forward (not
backward) modes are followed over the sweep by nearest eigenvalue
(:func:`~ambseal.analysis.campbell.track_modes`), and the screened mode is the one that
loses its damping first; if none does, the one Q takes the most damping from among those
that are a resonance somewhere in the sweep (amplification factor π/δ ≥ 2.5, API 684's
critical speed, :func:`~ambseal.analysis.campbell.resonant`): an overdamped pole's δ of
tens falls by more than a resonance's whole δ while it stays without resonance, and is
no mode API 617 screens (Level II grades the same kind of mode). The loop
counts as lost where a pole within the screened band breaks the stability rule
(:meth:`~ambseal.analysis.campbell.ClosedLoopModes.deciding`); a lossless mesh mode far
above the band, which nothing damps (ROSS's ``compressor_example`` has them at 21–105
kHz, no structural damping) and any Q then drives, is reported apart and decides nothing.
Q_0, where its pole crosses the imaginary axis (δ = 0), is found by Brent's method on the
bracketing interval to a tolerance, not read off the grid; a loop lost by a pole that is
no forward mode has no Q_0 to refine and does not pass.

With AMBs the supports are the controller: each controller is closed as it runs, the
discrete controller with its computation delay on the plant sampled by a zero-order hold
(:func:`ambseal.analysis.campbell.modes_of_sampled_loop`); a rig on springs alone is
screened as it is (controller ``None``).

The screening's outcome (the rule that decides, in this order): δ_A = δ(Q_A) below
``[signoff] log_dec_min`` (0.1) → Level II required; Q_0/Q_A < 2 → Level II required;
2 ≤ Q_0/Q_A < 10 → the critical speed ratio decides: in Region A (CSR on or below the
Region A/B boundary at the average gas density) passed, in Region B Level II required;
Q_0/Q_A ≥ 10 (or no Q_0 up to the sweep's end) → passed. The critical speed ratio CSR is
the maximum continuous speed over the first critical speed on rigid supports; the average
gas density ρ_avg is the mean of the first stage's suction and the last stage's discharge
density (the stages in the rig file's flow order). The boundary is ``[signoff]
csr_boundary``, points (ρ_avg, CSR) joined linearly and held flat beyond; its default,
CSR 2.5 up to 16.53 kg/m³ falling linearly to 2.0 at 60 kg/m³ and 2.0 beyond, is the one
ROSS's API report tool draws (API 684 §SP6.8.5, as ROSS cites it; the standard's figure
could not be confirmed from its public text, so it is a setting).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy.optimize import brentq

from ambseal.analysis.campbell import modes_as_run, poles_as_run, resonant, track_modes
from ambseal.config import MAX_SUPPORT_STIFFNESS, Spring
from ambseal.errors import ConfigError
from ambseal.lti import json_float
from ambseal.model import bending_limit_hz, build_plant

__all__ = ["B_COMPRESSOR", "B_TURBINE", "RATIO_MIN", "RATIO_FREE",
           "Level1", "stage_cross_coupling", "stage_position", "bearing_positions", "csr_boundary",
           "level1_screening"]

#: API 617's factor B of the anticipated cross-coupling: compressors (with the density
#: ratio) and turbines (without it).
B_COMPRESSOR = 3.0
B_TURBINE = 1.5
#: The screening's limits: Q_0/Q_A below 2 requires Level II; Q_0/Q_A of 10 or more
#: passes whatever the critical speed ratio (δ_A's limit: ``[signoff] log_dec_min``).
RATIO_MIN = 2.0
RATIO_FREE = 10.0
#: Brent's method stops when Q_0 is known to this fraction of Q_A.
Q0_XTOL = 1e-4
#: A support this stiff (N/m) is rigid for the critical speed ratio: 1e4 times any AMB's
#: or bearing's stiffness of the machines ambseal models, and 1e5 below the stiffness that
#: makes the eigenvalues doubtful (a 1e16 N/m spring, ambseal.model.modes).
RIGID_SUPPORT = 1e11


@dataclass(frozen=True)
class Level1:
    """The Level I screening of one controller (module docstring).

    Attributes
    ----------
    controller : str
        Its name (``"none"`` for a rig on springs alone).
    speed_hz : float
        The maximum continuous speed the screening runs at (Hz).
    stage_q : tuple of float
        q_A per stage (N/m), in the rig file's order.
    Q_A : float
        Σ q_A (N/m).
    where_m : tuple of (float, float)
        Where Q is applied: (position m, share of Q).
    Q : ndarray, shape (n,)
        The swept cross-coupling (N/m), 0 … ``q_max_factor``·Q_A.
    log_dec : ndarray, shape (n,)
        δ of the screened mode at each Q (NaN where it is no forward mode).
    frequency_hz : ndarray, shape (n,)
        That mode's damped frequency (Hz).
    log_dec_A : float
        δ at Q_A.
    Q_0 : float or None
        Q at δ = 0 (N/m); 0 when the loop is unstable without cross-coupling; None when δ
        stays positive to the sweep's end (Q_0 above it).
    converged : bool
        Brent's method met its tolerance (always true when there was nothing to solve).
    csr : float
        Critical speed ratio: ``speed_hz`` over the first critical speed on rigid supports.
    rigid_critical_hz : float
        That critical speed (Hz).
    passed : bool
        No Level II analysis required.
    rule : str
        The rule that decided, in words.
    rho_avg : float
        Average gas density (kg/m³).
    csr_boundary : float
        The Region A/B boundary's CSR at ``rho_avg``.
    apart_hz : tuple of float
        Damped frequencies (Hz) of poles above the screened band that break the
        stability rule somewhere in the sweep (a lossless mesh mode nothing damps):
        reported, not deciding (module docstring).
    """

    controller: str
    speed_hz: float
    stage_q: tuple
    Q_A: float
    where_m: tuple
    Q: np.ndarray
    log_dec: np.ndarray
    frequency_hz: np.ndarray
    log_dec_A: float
    Q_0: float | None
    converged: bool
    csr: float
    rigid_critical_hz: float
    passed: bool
    rule: str
    rho_avg: float
    csr_boundary: float
    apart_hz: tuple = ()

    @property
    def region(self) -> str:
        """``"A"`` (CSR on or below the boundary) or ``"B"``."""
        return "A" if self.csr <= self.csr_boundary else "B"

    @property
    def ratio(self) -> float:
        """Q_0/Q_A (inf when Q_0 lies beyond the sweep)."""
        return math.inf if self.Q_0 is None else self.Q_0 / self.Q_A

    def to_dict(self) -> dict:
        """The ``level1`` block: SI numbers, JSON-ready (a Q_0 beyond the sweep is
        ``null`` with ``Q_0_above`` the sweep's end)."""
        return {"Q_A": self.Q_A, "Q_0": json_float(self.Q_0),
                "Q_0_above": None if self.Q_0 is not None else float(self.Q[-1]),
                "Q_0_over_Q_A": json_float(self.ratio), "log_dec_A": json_float(self.log_dec_A),
                "CSR": json_float(self.csr), "rigid_critical_hz": json_float(
                    self.rigid_critical_hz),
                "rho_avg": json_float(self.rho_avg), "CSR_boundary": json_float(
                    self.csr_boundary), "region": self.region,
                "passed": self.passed, "rule": self.rule, "converged": self.converged,
                "unstable_apart_hz": [float(f) for f in self.apart_hz],
                "speed_hz": self.speed_hz, "stage_q_A": list(self.stage_q),
                "applied_at": [{"position_m": z, "share": w} for z, w in self.where_m],
                "sweep": {"Q": [float(q) for q in self.Q],
                          "log_dec": [json_float(d) for d in self.log_dec],
                          "frequency_hz": [json_float(f) for f in self.frequency_hz]}}


def stage_cross_coupling(stage, kind: str, speed_rad_s: float) -> float:
    """API 617's anticipated cross-coupling q_A of one stage (N/m; module docstring).

    Parameters
    ----------
    stage : ambseal.config.rig.Stage
        ``power`` (W), ``impeller_diameter``, ``discharge_width`` (m), ``suction_density``,
        ``discharge_density`` (kg/m³).
    kind : {"compressor", "turbine"}
    speed_rad_s : float
        Maximum continuous speed Ω (rad/s), > 0.

    Returns
    -------
    float
        q_A (N/m).

    Raises
    ------
    ConfigError
        A speed that is not positive, or an unknown kind.
    """
    if not speed_rad_s > 0:
        raise ConfigError(f"API 617 Level I: the maximum continuous speed must be > 0, got "
                          f"{speed_rad_s:g} rad/s")
    torque = stage.power / speed_rad_s
    if kind == "compressor":
        q = (B_COMPRESSOR * torque * (stage.discharge_density / stage.suction_density)
             / stage.impeller_diameter / stage.discharge_width)
    elif kind == "turbine":
        q = B_TURBINE * torque / stage.impeller_diameter / stage.discharge_width
    else:
        raise ConfigError(f"machine.kind: expected 'compressor' or 'turbine', got {kind!r}")
    # the screening sweeps to RATIO_FREE·Q_A and applies it as a support's k_xy
    if not (math.isfinite(q) and RATIO_FREE * q <= MAX_SUPPORT_STIFFNESS):
        raise ConfigError(
            f"stage {_stage_label(stage)}: q_A = {q:.4g} N/m from "
            f"power {stage.power:g} W at {speed_rad_s:g} rad/s, impeller_diameter "
            f"{stage.impeller_diameter:g} m, discharge_width {stage.discharge_width:g} m "
            f"and the densities; API 617 Level I sweeps to {RATIO_FREE:g}·Q_A, which must "
            f"stay below {MAX_SUPPORT_STIFFNESS:g} N/m: check these keys")
    return q


def _stage_label(st) -> str:
    """A stage in words: its name, its disk, or where it sits."""
    return (repr(st.name) if st.name else f"on disk {st.disk!r}" if st.disk
            else f"at {st.position:g} m")


def stage_position(cfg, st) -> float:
    """Where a ``[[stage]]`` sits (m): its ``position``, or its ``disk``'s."""
    if st.position is not None:
        return float(st.position)
    return float(next(d.position for d in cfg.disk if d.name == st.disk))


def bearing_positions(cfg) -> list[float]:
    """The bearings' positions (m, ascending): the AMBs (a spring beside them is a coupling
    or a seal), or the springs of a rig without AMBs, but those of ``kind = "seal"``.

    Raises
    ------
    ConfigError
        A rig with neither.
    """
    zs = sorted({a.position for a in cfg.amb}
                or {s.position for s in cfg.spring if s.kind != "seal"})
    if not zs:
        raise ConfigError("API 617: the rig has no [[amb]] or [[spring]] (of kind "
                          "\"bearing\") to carry the rotor")
    return zs


def without_seals(cfg):
    """The rig without its seals: its ``[[seal]]`` and its springs of ``kind = "seal"``
    (API 617 Level I screens the rotor on its bearings alone)."""
    return cfg.model_copy(update={"seal": [], "spring": [s for s in cfg.spring
                                                         if s.kind != "seal"]})


def _applied_at(cfg, q: list[float]) -> tuple:
    """(position, share of Q) pairs: ``[signoff] level1_position_m`` where given (on the
    shaft: the rig's reading checks it), else mid-span between the outermost bearings,
    or the overhung stages in proportion to their q_A."""
    supports = bearing_positions(cfg)
    at = cfg.signoff.level1_position_m
    if at is not None:
        return ((float(at), 1.0),)
    lo, hi = min(supports), max(supports)
    zs = [stage_position(cfg, st) for st in cfg.stage]
    over = [(z, qi) for z, qi in zip(zs, q) if z < lo - 1e-9 or z > hi + 1e-9]
    if not over:
        return ((0.5 * (lo + hi), 1.0),)
    total = sum(qi for _, qi in over)
    return tuple((z, qi / total) for z, qi in over)


def _with_cross_coupling(cfg, where, Q: float):
    """The rig without its seals (Level I), with Q applied as springs ``k_xy = wQ``,
    ``k_yx = −wQ``."""
    springs = [Spring(position=z, kxx=0.0, kyy=0.0, kxy=w * Q, kyx=-w * Q,
                      name=f"api617_Q{i}") for i, (z, w) in enumerate(where)]
    bare = without_seals(cfg)
    return bare.model_copy(update={"spring": [*bare.spring, *springs]})


def _lines(points) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """The modes followed over the sweep: δ, f_d (Hz) and the mode's index per point and
    line (NaN, NaN, −1 where the line has no mode), and which lines whirl forward (not
    backward where they are least damped: at Q = 0 a forward and a backward whirl of an
    isotropic rotor coincide, and their shapes there say nothing)."""
    tr = track_modes(points)
    D = np.full(tr.shape, np.nan)
    F = np.full(tr.shape, np.nan)
    W = np.full(tr.shape, "", dtype=object)
    for i, m in enumerate(points):
        for j, k in enumerate(tr[i]):
            if k >= 0:
                D[i, j], F[i, j], W[i, j] = m.log_decrement[k], m.frequency_hz[k], m.whirl[k]
    forward = np.array([np.isfinite(D[:, j]).any()
                        and W[int(np.nanargmin(D[:, j])), j] != "backward"
                        for j in range(tr.shape[1])], dtype=bool)
    return D, F, tr, forward


def _screened(D: np.ndarray, forward: np.ndarray, iA: int) -> tuple[int, int | None]:
    """(line, first grid index where it has lost its damping or None): the forward line
    that loses its damping first; else, of the forward lines that are a resonance
    somewhere in the sweep (:func:`~ambseal.analysis.campbell.resonant`, AF ≥ 2.5), the
    one Q takes the most damping from (the mode the cross-coupling acts on); else the
    least damped at Q_A."""
    first = None
    for j in np.flatnonzero(forward):
        d = D[:, j]
        down = np.flatnonzero(~(d > 0) & np.isfinite(d))
        if down.size and (first is None or down[0] < first[1]
                          or (down[0] == first[1] and d[down[0]] < D[first[1], first[0]])):
            first = (int(j), int(down[0]))
    if first is not None:
        return first
    # an overdamped pole's δ of tens moves by more than any resonance's whole δ: only a
    # line that is a resonance somewhere in the sweep is screened by its loss
    sharp = resonant(np.where(np.isfinite(D), D, np.inf)).any(axis=0)
    drop = np.where(forward & sharp, D[0] - D[-1], np.nan)
    if np.any(np.isfinite(drop)):
        return int(np.nanargmax(drop)), None
    return int(np.argmin(np.where(forward & np.isfinite(D[iA]), D[iA], np.inf))), None


def csr_boundary(points, rho_avg: float) -> float:
    """The Region A/B boundary's CSR at the average gas density ``rho_avg`` (kg/m³):
    ``points`` ``[(ρ, CSR), …]`` joined linearly, flat beyond (module docstring)."""
    rho, csr = np.array(points, dtype=float).T
    return float(np.interp(rho_avg, rho, csr))


def _rigid_critical_hz(cfg) -> float:
    """The first critical speed on rigid supports (Hz): the first bending mode of the
    shaft and disks pinned at every bearing (:func:`bearing_positions`), at standstill."""
    pins = [Spring(position=z, kxx=RIGID_SUPPORT, kyy=RIGID_SUPPORT, name=f"rigid{i}")
            for i, z in enumerate(bearing_positions(cfg))]
    rig = cfg.model_copy(update={"seal": [], "amb": [], "spring": pins})
    lam = np.linalg.eigvals(np.asarray(build_plant(rig, speed_rpm=0.0).A))
    f = lam.imag[lam.imag > 2 * np.pi * 0.1] / (2 * np.pi)
    return float(f.min()) if f.size else math.nan


def level1_screening(cfg, controller=None, *, name: str = "none", points: int = 11,
                     q_max_factor: float = RATIO_FREE, progress=None) -> Level1:
    """API 617 Level I screening of a rig with one controller as it runs (module
    docstring).

    Parameters
    ----------
    cfg : RigConfig
        The rig with its ``[[stage]]`` tables and ``[machine] kind``.
    controller : DigitalController or ScheduledDigital, optional
        The controller as it runs (its discrete matrices and computation delay); None for
        a rig on springs alone (or to screen the rotor without its AMBs' loop).
    name : str
        The controller's name in the result.
    points : int
        Q values of the sweep, evenly from 0 to ``q_max_factor``·Q_A (≥ 3).
    q_max_factor : float
        The sweep's end in units of Q_A (≥ 10, API 617's "at least 10·Q_A").
    progress : callable, optional
        Called with one line per Q evaluated.

    Returns
    -------
    Level1

    Raises
    ------
    ConfigError
        No ``[[stage]]``, no support, a maximum continuous speed of 0, a continuous
        controller, ``points`` < 3 or ``q_max_factor`` < 10.
    """
    if not cfg.stage:
        raise ConfigError("API 617 Level I needs the machine's stages: add a [[stage]] per "
                          "impeller (position or disk, power, impeller_diameter, "
                          "discharge_width, suction_density, discharge_density)")
    if points < 3 or not q_max_factor >= RATIO_FREE:
        raise ConfigError(f"API 617 Level I: points={points} (≥ 3) and q_max_factor="
                          f"{q_max_factor:g} (≥ {RATIO_FREE:g}) expected")
    speed_hz = cfg.operating.continuous_hz[1]
    q = [stage_cross_coupling(st, cfg.machine.kind, 2 * math.pi * speed_hz)
         for st in cfg.stage]
    Q_A = float(sum(q))
    if not q_max_factor * Q_A <= MAX_SUPPORT_STIFFNESS:
        raise ConfigError(f"API 617 Level I: Q_A = {Q_A:.4g} N/m over the stages; the sweep "
                          f"to {q_max_factor:g}·Q_A must stay below {MAX_SUPPORT_STIFFNESS:g}"
                          " N/m: check the stages' power, impeller_diameter, discharge_width "
                          "and densities")
    where = _applied_at(cfg, q)
    max_hz = bending_limit_hz(cfg)
    if controller is not None and cfg.amb:  # the sampled loop's modes: below Nyquist
        max_hz = min(max_hz, 0.45 * cfg.controller.sample_rate_hz)

    def modes(Q: float):
        m = modes_as_run(_with_cross_coupling(cfg, where, Q), controller,
                         speed_hz=speed_hz, max_hz=max_hz, pressure_bar=0.0)
        if progress:
            state = ("stable" if m.stable else "UNSTABLE" if m.deciding().size
                     else "stable in the screened band")
            progress(f"{name}: Q = {Q:.4g} N/m, {state}")
        return m

    def poles(Q: float):  # the refinement follows one pole: no mode shapes needed
        if progress:
            progress(f"{name}: Q = {Q:.4g} N/m, refining Q_0")
        return poles_as_run(_with_cross_coupling(cfg, where, Q), controller,
                            speed_hz=speed_hz, max_hz=max_hz, pressure_bar=0.0)

    # Q_A is a point of the grid: 0, Q_A/2·k, … (points − 1 intervals to q_max_factor·Q_A)
    grid = np.linspace(0.0, q_max_factor * Q_A, int(points))
    iA = int(np.argmin(np.abs(grid - Q_A)))
    grid[iA] = Q_A
    pts = [modes(float(Q)) for Q in grid]
    D, F, idx, forward = _lines(pts)
    j, lost = _screened(D, forward, iA)
    d, f = D[:, j], F[:, j]
    log_dec_A = float(d[iA])
    # lost where a pole within the screened band breaks the rule, not a lossless mesh
    # mode above it (reported apart)
    unstable = [i for i, m in enumerate(pts) if m.deciding().size]
    band = 2 * math.pi * max_hz
    apart = tuple(sorted({round(abs(p.imag) / (2 * math.pi), 1) for m in pts
                          for p in m.unstable if abs(p.imag) > band}))
    if unstable and (lost is None or unstable[0] < lost):
        # lost first by a pole that is no forward mode: no Q_0 to refine
        Q_0, converged = float(grid[unstable[0]]), False
    elif lost is None:
        Q_0, converged = None, True
    elif lost == 0:
        Q_0, converged = 0.0, True
    else:
        Q_0, converged = _zero(grid, lost, pts[lost - 1].poles[idx[lost - 1, j]],
                               pts[lost].poles[idx[lost, j]], poles, Q_A)
    ratio = math.inf if Q_0 is None else Q_0 / Q_A
    f_rigid = _rigid_critical_hz(cfg)
    csr = speed_hz / f_rigid
    rho_avg = 0.5 * (cfg.stage[0].suction_density + cfg.stage[-1].discharge_density)
    edge = csr_boundary(cfg.signoff.csr_boundary, rho_avg)
    d_min = cfg.signoff.log_dec_min
    if not converged:
        passed, rule = False, (f"the loop is lost at Q = {Q_0:.4g} N/m and Q_0 could not "
                               "be found to its tolerance: not passed")
    elif not log_dec_A >= d_min:
        passed, rule = False, f"δ_A = {log_dec_A:.3g} < {d_min:g}: Level II required"
    elif ratio < RATIO_MIN:
        passed, rule = False, f"Q_0/Q_A = {ratio:.3g} < {RATIO_MIN:g}: Level II required"
    elif ratio < RATIO_FREE:
        region = (f"CSR = {csr:.3g} at ρ_avg = {rho_avg:.3g} kg/m³, boundary "
                  f"{edge:.3g}")
        passed = csr <= edge
        rule = (f"{RATIO_MIN:g} ≤ Q_0/Q_A = {ratio:.3g} < {RATIO_FREE:g} and {region}: "
                + ("Region A, passed" if passed else "Region B, Level II required"))
    else:
        above = "" if Q_0 is not None else f" (δ > 0 up to {grid[-1]:.4g} N/m)"
        passed, rule = True, (f"δ_A = {log_dec_A:.3g} ≥ {d_min:g} and Q_0/Q_A ≥ "
                              f"{RATIO_FREE:g}{above}: passed")
    if apart:
        rule += (f"; modes above the screened band ({max_hz:.4g} Hz) at "
                 f"{', '.join(f'{x:.4g}' for x in apart[:4])}{' …' if len(apart) > 4 else ''}"
                 " Hz are not asymptotically stable (nothing damps them): not screened")
    return Level1(controller=name, speed_hz=speed_hz, stage_q=tuple(q), Q_A=Q_A,
                  where_m=where, Q=grid, log_dec=d, frequency_hz=f, log_dec_A=log_dec_A,
                  Q_0=Q_0, converged=converged, csr=csr, rigid_critical_hz=f_rigid,
                  passed=passed, rule=rule, rho_avg=rho_avg, csr_boundary=edge,
                  apart_hz=apart)


def _zero(grid, i: int, lam0: complex, lam1: complex, poles, Q_A: float
          ) -> tuple[float, bool]:
    """Q_0 in ``[grid[i-1], grid[i]]``, where the screened mode's pole (``lam0`` there,
    ``lam1`` here) crosses the imaginary axis: Brent's method on Re λ(Q), λ(Q) the pole
    of the loop (``poles(Q)``, :func:`~ambseal.analysis.campbell.poles_as_run`) nearest to
    the straight line between them, to :data:`Q0_XTOL`·Q_A."""
    a, b = float(grid[i - 1]), float(grid[i])

    def re(Q: float) -> float:
        if Q == a:
            return float(lam0.real)
        if Q == b:
            return float(lam1.real)
        t = (Q - a) / (b - a)
        guess = (1 - t) * lam0 + t * lam1
        p = poles(Q)
        return float(p[np.argmin(np.abs(p - guess))].real) if p.size else math.nan

    try:
        Q0, res = brentq(re, a, b, xtol=Q0_XTOL * Q_A, maxiter=100, full_output=True)
    except ValueError:  # no sign change of the followed pole: another pole was followed
        return b, False
    return float(Q0), bool(res.converged)
