"""The thesis's identification procedure as one stage (P2 §5, P4 §3.4–3.5, P5 §3.3).

(a) the eight Ki/Ks and τ_e from a PRBS run at zero pressure; (b) the coupling stiffness
(on a rig with a ``[[spring]]``) from a second PRBS run, with (a) known, then both jointly on both records; (a') Ki by
static loading (P2 §5, :mod:`.static_load`) joined with that fit; (c) the seal's K, k, C, c
per pressure drop from impulse runs (0.05 A for 10 ms on both bearings in ζ, P5 §3.3) at a
quarter to 1.25× the nominal pressure drop (:func:`seal_test_pressures`) with
regression lines against pressure (P5 Fig. 7; a pressure where the controller does not
hold the rotor is skipped and told — the facility refuses an unstable loop), then per excitation frequency from a stepped
sine of balanced forward and backward whirl (:mod:`.seal_test`, balanced on the model with
the regression's seal) at the nominal pressure, with a zero-pressure run as the bias
reference (P4 Fig. 12); (d) the identified rig.

Every excitation's amplitude, clock and length follow from the rig (its bias current and
sample rate, :mod:`ambseal.identify.excitation.plan`): the thesis's 0.05 A, 1 ms PRBS clock and
10 ms impulse on its test rig.

Every fit adds the error budget of the values it holds (:mod:`ambseal.identify.fitting.budget`):
an earlier stage's estimates with that stage's standard errors and correlations, anything
else (the seal in stages (a)–(b)) with its stated or default uncertainty; its model check
says when the data dispute a held value.

Records come from the virtual test facility here; on a real rig, the same stages take the
measured files (``ambseal identify``).
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from typing import Callable

import numpy as np

from ambseal.config import Affine, RigConfig, TruthSection, rig_with_values
from ambseal.errors import ConfigError, IdentificationError, ModelError
from ambseal.identify.excitation.plan import ExcitationPlan, excitation_plan
from ambseal.identify.fitting.fit import TAU_E, FitResult
from ambseal.identify.fitting.seal_test import fit_reliability, seal_frequency_test
from ambseal.identify.excitation.signals import impulse, prbs
from ambseal.identify.fitting.stages import acquire, identify
from ambseal.identify.fitting.static_load import (
    programme_repeats,
    static_ki,
    virtual_static_load,
    with_static,
)
from ambseal.identify.fitting.stats import linear_regression
from ambseal.model import channel_names
from ambseal.robust import DiscreteController

__all__ = ["ProcedureResult", "thesis_procedure", "seal_test_pressures", "SEAL_COEFFICIENTS",
           "SEAL_TEST_STEPS"]

SEAL_COEFFICIENTS = ("K", "k", "C", "c")


@dataclass(frozen=True)
class ProcedureResult:
    """Every stage's fit, the seal's coefficient curves and the identified rig.

    Attributes
    ----------
    amb : FitResult
        Stage (a): Ki, Ks per axis and τ_e.
    coupling : FitResult or None
        Stage (b); None on a rig without a ``[[spring]]`` (nothing to identify).
    seal_vs_frequency : dict
        ``{pressure_bar: [(frequency_hz, FitResult), ...]}`` for the nominal pressure and
        the zero-pressure reference.
    seal_vs_pressure : list of (float, FitResult)
        Impulse fits per pressure drop (bar).
    regression : dict
        ``{coefficient: Regression}`` against pressure (bar).
    identified : RigConfig
    truth : dict
        True values (SI) of every identified parameter, for the report.
    records : dict
        The PRBS records of stages (a) and (b) (``"a"``, ``"b"``), for FRF checks.
    static_load : dict or None
        Stage (a'): Ki by static loading (:mod:`.static_load`), and the Ki–Ks correlations
        of the closed-loop fit alone and joined with it; ``amb`` is the joined estimate.
    skipped : list of (float, str)
        Impulse pressures (bar) the facility refused, with why: the controller does not
        hold the rotor there (P5 §4: the PID "turns unstable for high pressures").
    """

    amb: FitResult
    coupling: FitResult | None
    seal_vs_frequency: dict
    seal_vs_pressure: list
    regression: dict
    identified: RigConfig
    truth: dict
    records: dict
    static_load: dict | None = None
    skipped: list = ()

    def to_dict(self) -> dict:
        def fit(r: FitResult) -> dict:
            return r.to_dict()

        return {
            "amb": fit(self.amb),
            "coupling": None if self.coupling is None else fit(self.coupling),
            "seal_vs_frequency": {
                str(p): [{"frequency_hz": f, **fit(r), "unreliable": fit_reliability(r)}
                         for f, r in rows]
                for p, rows in self.seal_vs_frequency.items()
            },
            "seal_vs_pressure": [{"pressure_bar": p, **fit(r)} for p, r in self.seal_vs_pressure],
            "regression": {k: v.to_dict() for k, v in self.regression.items()},
            "truth": self.truth,
            **({"static_load": self.static_load} if self.static_load else {}),
            **({"seal_pressures_skipped": [{"pressure_bar": p, "reason": why}
                                           for p, why in self.skipped]}
               if self.skipped else {}),
        }


def _subset(res: FitResult, names: list[str]) -> FitResult:
    """The part of a joint fit that concerns ``names`` (estimates, errors, correlation)."""
    idx = [res.names.index(n) for n in names]
    noise = None if res.std_error_noise is None else res.std_error_noise[idx]
    dof = None if res.dof_noise is None else res.dof_noise[idx]
    return replace(res, names=tuple(names), estimate=res.estimate[idx],
                   initial=res.initial[idx], std_error=res.std_error[idx],
                   std_error_noise=noise, dof_noise=dof,
                   ci95_low=res.ci95_low[idx], ci95_high=res.ci95_high[idx],
                   correlation=res.correlation[np.ix_(idx, idx)])


#: The seal's impulse tests run at the nominal pressure drop × k/SEAL_TEST_STEPS for
#: k = 1 … SEAL_TEST_STEPS + 1: from a quarter of the nominal to 1.25× it, the span the
#: thesis covered on its rig (0.5–2.5 bar at a nominal 2.04 bar, P5 §3.3) on any rig.
SEAL_TEST_STEPS = 4


def seal_test_pressures(cfg: RigConfig) -> tuple[float, ...]:
    """The pressure drops (bar) of the seal's impulse tests: :data:`SEAL_TEST_STEPS` + 1
    steps of a quarter of the rig's nominal pressure drop (``[operating] pressure_bar``,
    else the highest of ``[design] pressures_bar``), the nominal among them.

    Parameters
    ----------
    cfg : RigConfig

    Returns
    -------
    tuple of float

    Raises
    ------
    ConfigError
        A rig with a seal but no pressure drop to test it at.
    """
    p = cfg.operating.pressure_bar or max(cfg.design.pressures_bar or [0.0])
    if not p > 0:
        raise ConfigError("identification (c): the seal is tested at pressure drops "
                          "around the nominal one; set [operating] pressure_bar (bar)")
    return tuple(p * k / SEAL_TEST_STEPS for k in range(1, SEAL_TEST_STEPS + 2))


def thesis_procedure(
    cfg: RigConfig,
    truth: TruthSection,
    controller: DiscreteController,
    *,
    seed: int = 0,
    sine_frequencies_hz: tuple[float, ...] | None = None,
    impulse_pressures_bar: tuple[float, ...] | None = None,
    excitation: ExcitationPlan | None = None,
    amb_speed_hz: float | None = 0.0,
    progress: Callable[[str], None] | None = None,
) -> ProcedureResult:
    """Run stages (a)–(d) on the virtual facility of ``cfg`` with ``truth``.

    Parameters
    ----------
    cfg : RigConfig
        The rig as modelled (its values are the fit's start).
    truth : TruthSection
        The facility's true values (never read by a fit).
    controller : DiscreteController
        The digital controller that levitates the rotor in every run (the rig's reference
        PID as it runs on the target: :func:`ambseal.app.commands.target_pid`).
    seed : int
        Seed of excitations and noise.
    sine_frequencies_hz : tuple of float, optional
        Frequencies (Hz) of the balanced-whirl stepped sines of stage (c) (P4 §3.5.1);
        default the rig's (:func:`~ambseal.identify.excitation.plan.excitation_plan`: 10, 20,
        40, …, 200 Hz on the thesis rig).
    impulse_pressures_bar : tuple of float, optional
        Pressure drops (bar) of the impulse runs of stage (c) (P5 §3.3); the facility must
        hold the rotor at three of them at least. Default :func:`seal_test_pressures`.
    excitation : ExcitationPlan, optional
        Amplitudes, clock and lengths of the excitations; default
        :func:`~ambseal.identify.excitation.plan.excitation_plan` of ``cfg``.
    amb_speed_hz : float or None
        Spin speed (Hz) of the zero-pressure PRBS runs of stages (a) and (b)
        (:func:`~ambseal.identify.fitting.stages.at_speed`): default standstill, where the AMBs
        are commissioned before the machine spins and no gyroscopic coupling enters; None:
        the operating speed. The seal's runs are at the operating speed, where its
        coefficients matter.
    progress : callable, optional
        Called with a short description before each stage.

    Returns
    -------
    ProcedureResult
        Every stage's fit, the seal's regression against pressure and its coefficients
        against frequency, the skipped pressures, the identified rig and the true values.

    Raises
    ------
    IdentificationError
        Fewer than three impulse pressures at which the controller holds the rotor, or a
        fit that cannot start.
    ConfigError
        No excitation amplitude can be derived (:func:`excitation_plan`).
    """
    say = progress or (lambda _msg: None)
    fs = cfg.controller.sample_rate_hz
    axes = channel_names(cfg)
    ambs = [a.name for a in cfg.amb]
    seal = cfg.seal[0].name if cfg.seal else None
    spring = (cfg.spring[0].name or "spring0") if cfg.spring else None
    p_nom = cfg.operating.pressure_bar
    plan = excitation if excitation is not None else excitation_plan(cfg)
    if sine_frequencies_hz is None:
        sine_frequencies_hz = plan.sine_hz

    say("identification (a): Ki, Ks and tau_e from PRBS at 0 bar"
        + ("" if amb_speed_hz is None else f", {amb_speed_hz:g} Hz"))
    ex = prbs(amplitude_a=plan.amplitude_a, clock_period_s=plan.prbs_clock_s,
              duration_s=plan.prbs_duration_s, sample_rate_hz=fs, axes=axes, seed=seed)
    rec_a = acquire(cfg, truth, ex, controller=controller, pressure_bar=0.0, seed=seed,
                    speed_hz=amb_speed_hz)
    names_a = [f"{m}.{q}_{x}" for m in ambs for q in ("Ki", "Ks") for x in ("zeta", "eta")]
    names_a.append(TAU_E)
    amb = identify(cfg, [rec_a], names_a, budget=True)
    known, known_fit = dict(zip(amb.names, amb.estimate)), amb

    coupling = None
    records = {"a": rec_a}
    if spring is not None:
        say("identification (b): coupling stiffness from a second PRBS run")
        ex = prbs(amplitude_a=plan.amplitude_a, clock_period_s=plan.prbs_clock_s,
                  duration_s=plan.prbs_duration_s, sample_rate_hz=fs, axes=axes,
                  seed=seed + 1)
        rec_b = acquire(cfg, truth, ex, controller=controller, pressure_bar=0.0, seed=seed + 1,
                        speed_hz=amb_speed_hz)
        records["b"] = rec_b
        names_b = [f"{spring}.kxx", f"{spring}.kyy"]
        coupling = identify(cfg, [rec_b], names_b, known=known, known_fit=amb, budget=True)
        # (a) assumed the nominal coupling, which sits beside AMB A: its error goes into
        # A's Ks, and (b) then inherits that bias. A joint fit of (a)'s and (b)'s parameters
        # on both records, started from the sequential estimates, removes it.
        say("identification (a)+(b): joint fit on both records")
        start = {**known, **dict(zip(coupling.names, coupling.estimate))}
        joint = identify(cfg, [rec_a, rec_b], names_a + names_b, known=start, budget=True)
        amb = _subset(joint, names_a)
        coupling = _subset(joint, names_b)
        known, known_fit = dict(zip(joint.names, joint.estimate)), joint

    say("identification (a'): Ki by static loading, joined with the closed-loop fit")
    amb, static = _with_static_load(cfg, truth, amb, known, seed)
    known.update(zip(amb.names, amb.estimate))

    seal_freq: dict = {}
    seal_press: list = []
    skipped: list = []
    regression: dict = {}
    if seal is not None:
        names_s = [f"{seal}.{c}" for c in SEAL_COEFFICIENTS]
        seal_press, skipped, regression = _seal_by_impulse(
            cfg, truth, controller, names_s,
            seal_test_pressures(cfg) if impulse_pressures_bar is None else impulse_pressures_bar,
            plan, known, known_fit, seed, say)
        for p in (0.0, p_nom):
            say(f"identification (c): seal coefficients by balanced-whirl stepped sine at "
                f"{p:g} bar")
            at = {n: regression[c].intercept + regression[c].slope * p
                  for n, c in zip(names_s, SEAL_COEFFICIENTS)}
            seal_freq[p] = seal_frequency_test(cfg, truth, controller, seal, p,
                                               sine_frequencies_hz, known=known,
                                               seal_values=at, seed=seed + 2,
                                               amplitude_a=plan.amplitude_a,
                                               known_fit=known_fit, budget=True)

    say("identification (d): the identified rig")
    values: dict = dict(known)
    for c, reg in regression.items():
        values[f"{seal}.{c}"] = Affine(at_zero=reg.intercept, per_bar=reg.slope)
    identified = rig_with_values(cfg, values)

    return ProcedureResult(amb, coupling, seal_freq, seal_press, regression, identified,
                           _true_values(values, truth), records, static, skipped)


def _seal_by_impulse(cfg: RigConfig, truth: TruthSection, controller: DiscreteController,
                     names_s: list[str], pressures_bar, plan: ExcitationPlan, known: dict,
                     known_fit: FitResult, seed: int, say) -> tuple[list, list, dict]:
    """Stage (c), impulses: the seal's K, k, C, c fitted at each pressure where the
    controller holds the rotor, and their regressions on the pressure (P5 §3.3). Returns
    ([(p, fit)], [(p, why skipped)], {coefficient: regression}); raises
    IdentificationError with fewer than three pressures held."""
    axes = channel_names(cfg)
    zeta = {f"{a.name}_zeta": 1.0 for a in cfg.amb}
    seal_press, skipped = [], []
    for i, p in enumerate(pressures_bar):
        say(f"identification (c): seal coefficients by impulse at {p:g} bar")
        ex = impulse(amplitude_a=plan.amplitude_a, width_s=plan.impulse_s,
                     start_s=plan.impulse_start_s, duration_s=plan.impulse_record_s,
                     sample_rate_hz=cfg.controller.sample_rate_hz, axes=axes, excited=zeta)
        try:
            rec = acquire(cfg, truth, ex, controller=controller, pressure_bar=p,
                          seed=seed + 10 + i)
        except ModelError as exc:  # the controller does not hold the rotor there
            skipped.append((p, str(exc)))
            say(f"identification (c): {p:g} bar skipped: {exc}")
            continue
        seal_press.append((p, identify(cfg, [rec], names_s, known=known, refine=False,
                                       known_fit=known_fit, budget=True)))
    if len(seal_press) < 3:
        raise IdentificationError(
            f"identification (c): the facility held the rotor at {len(seal_press)} of the "
            f"impulse pressures {list(pressures_bar)} bar; the seal's regression "
            f"needs three ({'; '.join(f'{p:g} bar: {w}' for p, w in skipped)})")
    regression = {c: linear_regression([p for p, _ in seal_press],
                                       [r.estimate[j] for _, r in seal_press],
                                       [r.std_error[j] for _, r in seal_press])
                  for j, c in enumerate(SEAL_COEFFICIENTS)}
    return seal_press, skipped, regression


def _true_values(values: dict, truth: TruthSection) -> dict:
    """The facility's true value of each identified name (SI; an affine one as its dict)."""
    true = {}
    for name in values:
        if name == TAU_E:
            true[name] = truth.tau_e
        elif name in truth.parameters:
            v = truth.parameters[name]
            true[name] = v.model_dump() if isinstance(v, Affine) else float(v)
    return true


def _with_static_load(cfg: RigConfig, truth: TruthSection, amb: FitResult, known: dict,
                      seed: int) -> tuple[FitResult, dict]:
    """Stage (a'): static-load Ki on the virtual facility (P2 §5) joined with the
    closed-loop fit ``amb``; the joined fit and a summary with both Ki–Ks correlations.
    The programme runs P2's five times, then, as long as :func:`programme_repeats` asks for
    more (a static Ki twice as precise as the closed-loop fit's; at most three rounds), once
    more at the length it asks for."""
    repeats, static = 0, None
    for round_ in range(4):
        more = 5 if static is None else programme_repeats(amb, static, repeats)
        if more <= repeats:
            break
        repeats = more
        static = static_ki(cfg, *virtual_static_load(cfg, truth, seed=seed + 5 + round_,
                                                     repeats=repeats), values=known)
    joined, summary = with_static(amb, static)
    return joined, {**summary, "repeats": repeats}
