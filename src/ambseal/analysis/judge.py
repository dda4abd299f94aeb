"""Judge one controller on the full-order plant at one operating point: the main job's case.

What ``ambseal run`` reports per (controller, operating point), thesis P5 §4–5:
closed-loop stability, σ̄(S_o) with the ISO 14839-3 zones (overall and per axis),
compliance at the seal, the worst-case unbalance response and the current-impulse response.
Every number is taken on the full-order plant (flexible modes included), whatever model
the controller was designed on; peaks on frequency grids refined around the lightly damped
closed-loop poles (:func:`ambseal.analysis.loops.resolved_grid`).

The operating points (:func:`operating_points`) are 0, nominal and 2× nominal pressure drop
for pressure-driven seals, or the ends and the middle of the speed range for rigs whose
seals change with speed over a stated range (P3 §4).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

__all__ = ["JudgeSettings", "OperatingPoint", "judge", "judge_case", "judge_spinup",
           "operating_points", "speed_scheduled", "unstable_open_loop_poles", "force_position"]


@dataclass(frozen=True)
class JudgeSettings:
    """Grids and disturbances of the judgement.

    Attributes
    ----------
    freq_hz : (float, float, int)
        Log grid of the loop analysis (Hz): start, end, points; refined around every lightly
        damped closed-loop pole.
    unbalance_grade_mm_s : float
        Balance grade G (mm/s) of the worst-case unbalance, thesis P5 §4.4.1.
    unbalance_range_hz : (float, float)
        Speed range (Hz) of the unbalance response (400 points, refined).
    impulse_a, impulse_s : float
        The thesis's current impulse (P5 §5.1): amplitude (A) and length (s), started at
        ``impulse_start_s`` in a window of ``impulse_end_s`` sampled every ``impulse_dt_s``.
    """

    freq_hz: tuple[float, float, int] = (0.5, 2000.0, 1200)
    unbalance_grade_mm_s: float = 2.5
    unbalance_range_hz: tuple[float, float] = (1.0, 200.0)
    impulse_a: float = 0.05
    impulse_s: float = 0.01
    impulse_start_s: float = 0.05
    impulse_end_s: float = 0.35
    impulse_dt_s: float = 5e-5


@dataclass(frozen=True)
class OperatingPoint:
    """A judged condition: pressure drop (bar), speed (rpm) and its label."""

    pressure_bar: float
    speed_rpm: float
    label: str


def speed_scheduled(cfg) -> bool:
    """Whether the rig's seals change with speed over a stated speed range (P3 §4): its
    controllers are then judged at frozen speeds rather than at pressure drops."""
    return cfg.operating.speed_range_hz is not None and any(
        s.frequency_dependent for s in cfg.seal)


def operating_points(cfg) -> list[OperatingPoint]:
    """Where every controller is judged: 0, nominal and 2× nominal pressure drop (P5 §4), or
    the ends and the middle (operating speed) of the speed range (P3 §4)."""
    p, rpm = cfg.operating.pressure_bar, cfg.operating.speed_rpm
    if speed_scheduled(cfg):
        lo, hi = cfg.operating.speed_range_hz
        return [OperatingPoint(p, f * 60.0, f"{f:g} Hz") for f in sorted({lo, rpm / 60.0, hi})]
    pressures = [0.0, p, 2 * p] if p > 0 else [0.0]
    return [OperatingPoint(q, rpm, f"{q:g} bar") for q in pressures]


def force_position(cfg) -> float:
    """Where compliance and unbalance forces act (m): the first seal, else mid-span."""
    return cfg.seal[0].position if cfg.seal else cfg.length / 2


def unstable_open_loop_poles(A: np.ndarray) -> np.ndarray:
    """Eigenvalues of ``A`` with a positive real part, most unstable first (rad/s).

    Unstable and refused as doubtful by :func:`ambseal.model.modes.classify_poles`
    (absolute thresholds in rad/s, not relative to the stiffest mode).

    Raises
    ------
    ModelError
        The model's conditioning makes the stability doubtful."""
    from ..model.modes import classify_poles

    lam = np.linalg.eigvals(A)
    lam = lam[classify_poles(lam, where="open-loop plant")[1]]
    return lam[np.argsort(-lam.real)]


def _finite(x: float) -> float | None:
    return float(x) if math.isfinite(x) else None


def judge(cfg, controller, name: str, point: OperatingPoint,
          settings: JudgeSettings = JudgeSettings(), *, impulse: bool = True
          ) -> tuple[dict, dict]:
    """Judge one physical controller on the full-order plant at one operating point.

    Parameters
    ----------
    cfg : RigConfig
    controller : control.StateSpace
        Displacement (m) → current reference (A), negative feedback ``i = −K y``.
    name : str
        The controller's name in the case.
    point : OperatingPoint
    settings : JudgeSettings
    impulse : bool
        Set False to leave out the impulse response (the sweeps of
        :mod:`ambseal.analysis.sweep`); ``impulse_*`` are then ``None``.

    Returns
    -------
    case : dict
        The ``metrics.json`` case (values an unstable loop does not have are ``None``).
    curves : dict
        ``So``, ``compliance``, ``unbalance`` (frequency Hz, values) and ``impulse``
        (:class:`~ambseal.analysis.response.ImpulseResponse`) for the figures, and
        ``poles`` (the closed-loop poles, rad/s).
    """
    from ..model.rig import build_plant
    from ..model.rotor import assemble_rotor
    from .iso import iso_assessment
    from ..lti.freqresp import freqresp
    from .loops import (closed_loop, compliance_from, loop_responses_from, resolved_grid,
                        sigma_max)
    from .response import impulse_response_of
    from .unbalance import unbalance_from_compliance

    s = settings
    plant = build_plant(cfg, pressure_bar=point.pressure_bar, speed_rpm=point.speed_rpm,
                        force_positions=(force_position(cfg),))
    cur = plant.current_inputs()
    force = [j for j in range(len(plant.input_names)) if j not in cur]
    G = plant.select_inputs([plant.input_names[j] for j in cur]).to_statespace()
    Gf = plant.select_inputs([plant.input_names[j] for j in force]).to_statespace()
    loop = closed_loop(G, controller, Gf)
    case = {"controller": name, "pressure_bar": point.pressure_bar,
            "speed_hz": point.speed_rpm / 60.0, "stable": loop.stable,
            "max_real_pole": loop.max_real_pole}
    w = 2 * np.pi * np.logspace(math.log10(s.freq_hz[0]), math.log10(s.freq_hz[1]), s.freq_hz[2])
    w = resolved_grid(w, loop.poles)  # a 0.5 %-damped bending mode must not slip through
    wu = resolved_grid(2 * np.pi * np.linspace(*s.unbalance_range_hz, 400), loop.poles)
    # the plant (currents and force share its A) and the controller evaluated once, on both
    # grids: one eigendecomposition each instead of one per loop function
    Pw, Kw = (freqresp(X, np.concatenate([w, wu])) for X in (plant.to_statespace(), controller))
    Gw, Gfw = Pw[:, :, cur], Pw[:, :, force]
    ny_names, nu_names, f_names = G.output_labels, G.input_labels, Gf.input_labels
    resp = loop_responses_from(Gw[:w.size], Kw[:w.size], w, ny_names, nu_names)
    iso = iso_assessment(resp.peaks("So"), stable=loop.stable)
    curves: dict = {"So": (w / (2 * np.pi), sigma_max(resp.So)), "poles": loop.poles}
    case.update(
        sensitivity_peak=_finite(iso.sigma_max_peak),
        sensitivity_peak_per_axis={ax.removeprefix("y_"): (p.value if loop.stable else None)
                                   for ax, p in zip(ny_names, resp.peaks("So").diagonal)},
        iso_zone=iso.zone_sigma_max,
        iso_zone_per_axis={ax.removeprefix("y_"): z for ax, z in iso.zones_per_axis},
    )
    if not loop.stable:
        case.update(compliance_peak_m_per_n=None, unbalance_peak_um=None,
                    impulse_peak_um=None, impulse_settling_s=None)
        return case, curves
    c, cu = (compliance_from(Gw[sl], Kw[sl], Gfw[sl], grid, ny_names, f_names)
             for sl, grid in ((slice(0, w.size), w), (slice(w.size, None), wu)))
    curves["compliance"] = (w / (2 * np.pi), c.sigma_max_m_per_n)
    unb = unbalance_from_compliance(cu, mass_kg=assemble_rotor(cfg).mass,
                                    grade_mm_s=s.unbalance_grade_mm_s)
    curves["unbalance"] = (unb.speed_hz, unb.response_um)
    case.update(compliance_peak_m_per_n=c.peak.value, unbalance_peak_um=unb.peak_um)
    if not impulse:
        case.update(impulse_peak_um=None, impulse_settling_s=None)
        return case, curves
    # the thesis's impulse axes A_ζ and B_η (P5 §5.1): first AMB's ζ, last AMB's η
    channels = (G.input_labels[0], G.input_labels[-1])
    imp = impulse_response_of(loop, channels=channels, amplitude_a=s.impulse_a,
                              duration_s=s.impulse_s, t_impulse_s=s.impulse_start_s,
                              t_end_s=s.impulse_end_s, dt_s=s.impulse_dt_s)
    curves["impulse"] = imp
    case.update(
        impulse_peak_um=imp.peak_displacement_um,
        impulse_settling_s=_finite(imp.settling_time_s),
    )
    return case, curves


def judge_case(case: dict, cfg, settings: JudgeSettings = JudgeSettings()) -> tuple[dict, dict]:
    """:func:`judge` of ``case = {"controller", "name", "point"}``: the main job's cases as
    run by :func:`ambseal.analysis.sweep.run_cases`."""
    return judge(cfg, case["controller"], case["name"], case["point"], settings)


def judge_spinup(cfg, controllers: dict) -> tuple[dict, list, list]:
    """The speed-scheduled rig's time and frequency judgement (P3 §4, Figs. 11–12).

    A spin-up over ``[operating] speed_range_hz`` in 1 s with alternating 100 N force and
    2 µm output steps on the first actuator axis, on the LPV design model (29 grid speeds,
    12 states, the force at the first AMB), and σ̄(S_o) on the full-order plant at 8 frozen
    speeds across the range.

    Parameters
    ----------
    cfg : RigConfig
        A rig with ``[operating] speed_range_hz``.
    controllers : dict
        ``{name: control.StateSpace or ScheduledController}``.

    Returns
    -------
    (summary, spin-ups, frozen sensitivities)
        ``{name: {...spin-up, "frozen_sensitivity": {...}}}`` for ``metrics.json``, and the
        :class:`~ambseal.analysis.spinup.SpinupResult` and
        :class:`~ambseal.analysis.spinup.FrozenSensitivity` of each controller in order.
    """
    from ..control.lpv_plant import lpv_plant
    from .spinup import frozen_sensitivity, spinup

    lo, hi = cfg.operating.speed_range_hz
    L = lpv_plant(cfg, np.linspace(lo, hi, 29), states=12,
                  force_positions=(cfg.amb[0].position,))
    speeds = np.linspace(lo, hi, 8)
    cache: dict = {}
    sims = [spinup(L, K, name=n, speeds_hz=(lo, hi)) for n, K in controllers.items()]
    sens = [frozen_sensitivity(cfg, K, speeds, name=n, plants=cache)
            for n, K in controllers.items()]
    summary = {n: {**s.to_dict(), "frozen_sensitivity": f.to_dict()}
               for n, s, f in zip(controllers, sims, sens)}
    return summary, sims, sens
