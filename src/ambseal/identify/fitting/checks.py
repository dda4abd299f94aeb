"""Checks of an identified model against data it was not fitted to, and against the truth.

* :func:`frf_checks` — the closed-loop FRF of a chirp record against the identified model
  (P4 Fig. 9), and the unstable plant itself from the PRBS record of stage (a),
  ``T_ye·T_ie⁻¹`` (P1 §II, the indirect method), against the identified plant from coil
  current to displacement (eddy lag, Ki, rotor; no amplifier);
* :func:`truth_errors` — on the virtual facility, each estimate beside its truth: error (%)
  and whether the 95 % interval holds it.
"""

from __future__ import annotations

from dataclasses import dataclass

from scipy.stats import binom, norm

from ambseal.config import Affine
from ambseal.identify.excitation.plan import ExcitationPlan, excitation_plan, welch_segment
from ambseal.identify.fitting.frf import FRF, closed_loop_frf, model_frf, plant_frf
from ambseal.identify.fitting.procedure import ProcedureResult
from ambseal.identify.excitation.signals import chirp
from ambseal.identify.fitting.stages import acquire, build_models
from ambseal.lti import finite_or_none
from ambseal.model import build_plant

__all__ = ["FrfChecks", "frf_checks", "truth_errors", "true_line", "interval_check"]


@dataclass(frozen=True)
class FrfChecks:
    """Measured FRFs beside the identified model's on the same grid.

    Attributes
    ----------
    closed_loop, closed_loop_model : FRF
        Chirp excitation on the ζ axes of the first and last bearing → displacements
        (m/A), over the plan's ``closed_loop_band_hz`` (test rig 2–140 Hz).
    plant, plant_model : FRF
        The plant from coil current to displacement (m/A), over the plan's
        ``plant_band_hz`` (test rig 2–200 Hz), and the output/input pairs worth plotting.
    plant_pairs : tuple of (str, str)
    """

    closed_loop: FRF
    closed_loop_model: FRF
    plant: FRF
    plant_model: FRF
    plant_pairs: tuple


def frf_checks(cfg, truth, res: ProcedureResult, controller, *, seed: int = 99,
               excitation: ExcitationPlan | None = None) -> FrfChecks:
    """Frequency-domain checks of the identified rig (P4 Figs. 9–10).

    Parameters
    ----------
    cfg : RigConfig
        The rig as identified against (its controller ran on the facility).
    truth : TruthSection
        The virtual facility's truth (a linear chirp record at 0 bar: test rig 1–150 Hz,
        4 s, 0.05 A).
    res : ProcedureResult
        The procedure's result (its identified rig and its stage (a) PRBS record).
    controller : DiscreteController
        The controller that levitates the rotor for the chirp record.
    seed : int
        Noise seed of the chirp record.
    excitation : ExcitationPlan, optional
        The chirp, the bands and the amplitude; default
        :func:`~ambseal.identify.excitation.plan.excitation_plan` of ``cfg`` (its rules: the
        chirp to 0.75·f_s/50, the checks to 0.7·f_s/50 and f_s/50, Welch segments a
        quarter of the record).

    Returns
    -------
    FrfChecks

    Raises
    ------
    ConfigError
        No excitation amplitude can be derived (:func:`excitation_plan`).
    """

    axes = res.amb.axes
    fs = cfg.controller.sample_rate_hz
    plan = excitation if excitation is not None else excitation_plan(cfg)
    ex = chirp(f0_hz=plan.chirp_hz[0], f1_hz=plan.chirp_hz[1], duration_s=plan.chirp_s,
               amplitude_a=plan.amplitude_a, sample_rate_hz=fs, axes=axes,
               excited={axes[0]: 1.0, axes[-2]: 1.0})
    rec = acquire(cfg, truth, ex, controller=controller, pressure_bar=0.0, seed=seed)
    measured = closed_loop_frf(rec, nperseg=welch_segment(ex.n_samples),
                               inputs=[axes[0]]).band(*plan.closed_loop_band_hz)
    model = build_models(res.identified, [rec], controllers=[controller])[0].statespace({}, axes)
    mf = model_frf(model[:, [0]] + model[:, [len(axes) - 2]], measured.frequency_hz,
                   input_names=measured.input_names, output_names=measured.output_names)

    rec_a = res.records["a"]  # four axes with independent sequences: MIMO H1
    seg = welch_segment(len(rec_a.time_s))
    T_ye = closed_loop_frf(rec_a, nperseg=seg, method="mimo")
    T_ie = closed_loop_frf(rec_a, nperseg=seg, method="mimo", response="current")
    G = plant_frf(T_ye, T_ie).band(*plan.plant_band_hz)
    bare = res.identified.model_copy(
        update={"actuator": res.identified.actuator.model_copy(update={"model": "none"})})
    Gm = model_frf(build_plant(bare, reduced=True, pressure_bar=0.0).to_statespace(),
                   G.frequency_hz, input_names=G.input_names, output_names=G.output_names)
    pairs = ((G.output_names[0], G.input_names[0]), (G.output_names[-1], G.input_names[-1]),
             (G.output_names[0], G.input_names[-2]))
    return FrfChecks(measured, mf, G, Gm, pairs)


def truth_errors(res: ProcedureResult, seal_name: str | None) -> dict:
    """Each estimate of the procedure beside its truth (the virtual facility's).

    Parameters
    ----------
    res : ProcedureResult
        The identification.
    seal_name : str or None
        The seal whose regressions are compared; None for none.

    Returns
    -------
    dict
        ``{name: {estimate, truth, ci95: [lo, hi], error_pct}}`` for the AMB and coupling
        parameters (``error_pct`` = 100 (estimate/truth − 1), ``None`` without a scalar
        truth), and ``{seal.c: {intercept, slope, …, truth}}`` for the seal regressions
        against pressure (bar).
    """
    out: dict = {}
    for r in [res.amb] + ([res.coupling] if res.coupling else []):
        for i, n in enumerate(r.names):
            t = res.truth.get(n)
            err = None if not isinstance(t, float) or t == 0 else 100 * (r.estimate[i] / t - 1)
            lo, hi = finite_or_none(r.ci95_low[i]), finite_or_none(r.ci95_high[i])
            covered = (None if not isinstance(t, float) or lo is None or hi is None
                       else bool(lo <= t <= hi))
            out[n] = {"estimate": float(r.estimate[i]), "truth": t, "ci95": [lo, hi],
                      "error_pct": err, "covered": covered}
    for c, reg in res.regression.items():
        t = res.truth.get(f"{seal_name}.{c}")
        covered = None
        if isinstance(t, dict):  # the line's 95 % intervals (normal: the points' se known)
            covered = bool(abs(reg.intercept - t["at_zero"]) <= Z95 * reg.intercept_se
                           and abs(reg.slope - t["per_bar"]) <= Z95 * reg.slope_se)
        elif isinstance(t, float):  # a constant truth: the line's intercept, slope 0
            covered = bool(abs(reg.intercept - t) <= Z95 * reg.intercept_se
                           and abs(reg.slope) <= Z95 * reg.slope_se)
        out[f"{seal_name}.{c}"] = {**reg.to_dict(), "truth": t, "covered": covered}
    return out


#: the two-sided 95 % quantile of the normal distribution
Z95 = float(norm.ppf(0.975))


def interval_check(errors: dict) -> dict:
    """The identification's 95 % intervals against the facility's true values.

    On the virtual facility the truth is known: an interval that misses it says the fit
    understates its error — a model mismatch or a held value that is off, whether or not
    the residual tests (:meth:`~ambseal.identify.fitting.fit.FitResult.model_check`) saw it. One
    in twenty intervals misses by chance; the mismatch is more misses than chance makes
    plausible (a binomial tail below 5 % at a 5 % miss rate: 3 of 15) or any miss by more
    than its interval's width.

    Parameters
    ----------
    errors : dict
        :func:`truth_errors` of a procedure.

    Returns
    -------
    dict
        ``checked`` (intervals compared), ``missed`` (names, each with the estimate, the
        interval and the truth in the verdict), ``mismatch`` (bool, the rule above) and
        ``verdict`` (text).
    """
    checked = [n for n, e in errors.items() if e.get("covered") is not None]
    missed = [n for n in checked if not errors[n]["covered"]]

    def far(n):  # the truth lies more than one interval width outside the interval
        e = errors[n]
        if "ci95" not in e:
            return False
        lo, hi = e["ci95"]
        return min(abs(e["truth"] - lo), abs(e["truth"] - hi)) > (hi - lo)

    unlikely = bool(missed) and binom.sf(len(missed) - 1, len(checked), 0.05) < 0.05
    mismatch = unlikely or any(far(n) for n in missed)

    def text(n):
        e = errors[n]
        if "ci95" in e:
            lo, hi = e["ci95"]
            return f"{n} {e['estimate']:.4g} in [{lo:.4g}, {hi:.4g}], truth {e['truth']:.4g}"
        return f"{n}'s line against pressure"
    if not checked:
        verdict = "no truth to compare the intervals with"
    elif not missed:
        verdict = f"every 95 % interval holds the facility's true value ({len(checked)})"
    else:
        verdict = (f"{len(missed)} of {len(checked)} 95 % intervals miss the facility's true "
                   f"value: {'; '.join(text(n) for n in missed)}"
                   + (" — the intervals understate the error: a model mismatch or a held "
                      "value that is off" if mismatch else " (one in twenty may, by chance)"))
    return {"checked": len(checked), "missed": missed, "mismatch": bool(mismatch),
            "verdict": verdict}


def true_line(truth, name: str):
    """The true coefficient against pressure (bar) as a function, or None if not in the truth.

    Parameters
    ----------
    truth : TruthSection
        The facility's truth.
    name : str
        A parameter name (``"<seal>.k"``).

    Returns
    -------
    callable or None
        ``f(pressure_bar) → value`` (SI): the truth's affine law, or its constant.
    """
    v = truth.parameters.get(name)
    if v is None:
        return None
    if isinstance(v, Affine):
        return lambda p: v.at_zero + v.per_bar * p
    return lambda p: float(v)
