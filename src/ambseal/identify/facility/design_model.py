"""Design from the identified model (thesis P5 §3): which rig to design on, the truth to
judge on, and impulse responses on the virtual facility beside the identified model's.

The thesis's method: identify on site (P2, P4), design on the identified model (P5 §3),
run on the machine, and compare measured and simulated impulse responses (P5 Figs. 15–16:
"simulated responses are shown as solid lines and experimental responses are marked with
'--'"). Here the machine is the virtual facility, whose truth (full-order FE rotor with the
truth file's values) is also the plant the designs are judged on.

Rule for the design rig (:func:`design_rig`): the controllers are designed on the
identified rig unless every identified value holds the rig file's value inside its 95 %
interval (the identification then found nothing the rig file did not already say, and the
rig file's designs stand: no second design pass).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ambseal.config import Affine, RigConfig, TruthSection, rig_with_values
from ambseal.errors import ModelError
from ambseal.identify.excitation.plan import ExcitationPlan, excitation_plan
from ambseal.identify.fitting.fit import TAU_E, nrmse_fit
from ambseal.identify.fitting.procedure import ProcedureResult
from ambseal.identify.facility.rig_sim import true_rig
from ambseal.identify.excitation.signals import impulse
from ambseal.identify.fitting.stages import acquire, build_models
from ambseal.model import build_system, channel_names, mechanical_plant
from ambseal.robust import DiscreteController

__all__ = ["ImpulseCheck", "outside_intervals", "non_physical", "design_rig", "truth_rig",
           "impulse_checks"]


def outside_intervals(cfg: RigConfig, res: ProcedureResult) -> list[str]:
    """Identified values whose 95 % interval does not hold the rig file's value: the
    stage fits' parameters (Ki, Ks, τ_e, coupling) and the seal regression's intercept and
    slope against pressure (``{seal}.{c}.at_zero``, ``.per_bar``)."""

    plant = mechanical_plant(build_system(cfg, pressure_bar=0.0))
    out = []
    for fit in (res.amb, res.coupling):
        if fit is None:
            continue
        for n, lo, hi in zip(fit.names, fit.ci95_low, fit.ci95_high):
            v = cfg.actuator.eddy_time_constant if n == TAU_E else plant.parameter(n).nominal
            if not lo <= v <= hi:
                out.append(n)
    seal = cfg.seal[0] if cfg.seal else None
    for c, reg in res.regression.items():
        coef = getattr(seal, c)
        at0, slope = (coef.at_zero, coef.per_bar) if isinstance(coef, Affine) else (
            float(coef), 0.0)
        if abs(at0 - reg.intercept) > 1.96 * reg.intercept_se:
            out.append(f"{seal.name}.{c}.at_zero")
        if abs(slope - reg.slope) > 1.96 * reg.slope_se:
            out.append(f"{seal.name}.{c}.per_bar")
    return out


def non_physical(cfg: RigConfig, res: ProcedureResult) -> list[str]:
    """The seal's identified regressions that are not physical over the pressure drops the
    rig runs at (0 to 2× nominal, or to the highest of ``[design] pressures_bar``): direct
    damping C below zero at either end (an affine law is extreme at its ends). Such a line
    extrapolates its tests into a seal that feeds energy by its direct damping, which no
    annular seal does; it is never designed on."""
    if not res.regression or not cfg.seal:
        return []
    top = max(2.0 * cfg.operating.pressure_bar, *(cfg.design.pressures_bar or [0.0]))
    reg = res.regression.get("C")
    if reg is None:
        return []
    low = min(reg.intercept, reg.intercept + reg.slope * top)
    return [f"{cfg.seal[0].name}.C"] if low < 0 else []


def design_rig(cfg: RigConfig, res: ProcedureResult) -> tuple[RigConfig, dict]:
    """The rig to design on (module rule) and a JSON note of the choice; an identified seal
    coefficient that is not physical over the rig's pressures (:func:`non_physical`) is
    replaced by the rig file's, named under ``non_physical``.

    Parameters
    ----------
    cfg : RigConfig
        The rig file.
    res : ProcedureResult
        The identification (its identified rig, intervals and seal regressions).

    Returns
    -------
    rig : RigConfig
        ``cfg`` when every identified value holds the rig file's inside its 95 % interval,
        else the identified rig (with any non-physical seal coefficient the rig file's).
    note : dict
        ``designed_on``, ``reason`` and, as they apply, ``outside_intervals`` and
        ``non_physical`` (JSON-ready).
    """
    differ = outside_intervals(cfg, res)
    if not differ:
        return cfg, {"designed_on": "rig file", "reason": "every identified value holds the "
                     "rig file's inside its 95 % interval"}
    bad = non_physical(cfg, res)
    note = {"designed_on": "identified rig",
            "reason": "identified values differ from the rig file beyond their 95 % intervals",
            "outside_intervals": differ}
    if not bad:
        return res.identified, note
    seal = cfg.seal[0]
    kept = {n: getattr(seal, n.rsplit(".", 1)[1]) for n in bad}
    note.update(non_physical=bad, reason=note["reason"] + "; the rig file's " + ", ".join(bad)
                + " kept: the identified line turns negative within 0–2× nominal pressure")
    return rig_with_values(res.identified, kept), note


def truth_rig(cfg: RigConfig, truth: TruthSection) -> RigConfig:
    """The virtual facility as a rig: the truth's model form and values, τ_e included (the
    full-order plant the designs are judged on).

    Parameters
    ----------
    cfg : RigConfig
        The rig file.
    truth : TruthSection
        The facility's truth.

    Returns
    -------
    RigConfig
    """
    return rig_with_values(true_rig(cfg, truth), {**truth.parameters, TAU_E: truth.tau_e})


@dataclass(frozen=True)
class ImpulseCheck:
    """One controller's impulse response on the facility beside the identified model's.

    Attributes
    ----------
    controller : str
    pressure_bar : float
    time_s : ndarray (N,)
    excitation_a : ndarray (N, k)
    facility_m, model_m : ndarray (N, k)
        Measured (virtual facility) and simulated (identified model) displacements (m).
    axes : tuple of str
    nrmse_fit_pct : dict
        Per axis, the model's NRMSE fit to the facility's response (%).
    error : str or None
        Why there is no response (the rotor left the facility's air gap); the arrays are
        then empty.
    """

    controller: str
    pressure_bar: float
    time_s: np.ndarray
    excitation_a: np.ndarray
    facility_m: np.ndarray
    model_m: np.ndarray
    axes: tuple[str, ...]
    nrmse_fit_pct: dict
    error: str | None = None

    def to_dict(self) -> dict:
        if self.error is not None:
            return {"controller": self.controller, "pressure_bar": self.pressure_bar,
                    "error": self.error}
        return {"controller": self.controller, "pressure_bar": self.pressure_bar,
                "nrmse_fit_pct": self.nrmse_fit_pct,
                "peak_facility_um": float(1e6 * np.abs(self.facility_m).max()),
                "peak_model_um": float(1e6 * np.abs(self.model_m).max())}


def impulse_checks(cfg: RigConfig, identified: RigConfig, truth: TruthSection,
                   controllers: dict[str, DiscreteController], pressures_bar, *,
                   seed: int = 77, excitation: ExcitationPlan | None = None,
                   ) -> list[ImpulseCheck]:
    """P5 Fig. 15 on the virtual facility: the rig's impulse (``excitation``, default
    :func:`~ambseal.identify.excitation.plan.excitation_plan` of ``cfg``; test rig 0.05 A for
    10 ms at 0.05 s in a 0.25 s record) on the first bearing's
    ζ and the last bearing's η at once (orthogonal directions at both ends), each controller
    running on the facility (``cfg`` with ``truth``) and on the identified model, at each
    pressure drop.

    A controller that does not keep the rotor in the facility's air gap gets an
    :class:`ImpulseCheck` with its ``error``.

    Parameters
    ----------
    cfg : RigConfig
        The rig file.
    identified : RigConfig
        The identified rig.
    truth : TruthSection
        The facility's truth.
    controllers : dict of str to DiscreteController or callable
        The controllers checked, by name, at the rig's sample rate; a callable of the
        pressure drop (bar) gives the one that runs there (a scheduled table's entry).
    pressures_bar : iterable of float
        The pressure drops (bar).
    seed : int, optional
        Seed of the facility's noise.
    excitation : ExcitationPlan, optional
        The impulse (default: the rig's).

    Returns
    -------
    list of ImpulseCheck
        One per controller and pressure drop.
    """

    axes = channel_names(cfg)
    fs = cfg.controller.sample_rate_hz
    ambs = [a.name for a in cfg.amb]
    plan = excitation if excitation is not None else excitation_plan(cfg)
    ex = impulse(amplitude_a=plan.amplitude_a, width_s=plan.impulse_s,
                 start_s=plan.impulse_start_s, duration_s=plan.check_record_s,
                 sample_rate_hz=fs, axes=axes,
                 excited={f"{ambs[0]}_zeta": 1.0, f"{ambs[-1]}_eta": 1.0})
    out = []
    for name, K in controllers.items():
        for p in pressures_bar:
            Kd = K(p) if callable(K) else K
            try:
                rec = acquire(cfg, truth, ex, controller=Kd, pressure_bar=p, seed=seed)
            except ModelError as exc:
                e = np.zeros((0, len(axes)))
                out.append(ImpulseCheck(name, float(p), np.zeros(0), e, e, e, axes, {},
                                        str(exc)))
                continue
            model = build_models(identified, [rec], controllers=[Kd])[0]
            y, _ = model.simulate({}, np.asarray(ex.values_a), currents=False)
            fit = nrmse_fit(np.asarray(rec.displacement_m), y)
            out.append(ImpulseCheck(name, float(p), np.asarray(rec.time_s),
                                    np.asarray(ex.values_a), np.asarray(rec.displacement_m), y,
                                    axes, {a: float(v) for a, v in zip(axes, fit)}))
    return out
