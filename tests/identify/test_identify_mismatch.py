"""Intervals on data the model did not make: fixed parameters off their rig values and a
different rotor discretisation on the virtual facility."""

import json

import numpy as np
import pytest
from scipy.stats import t as student

from ambseal.config import TruthSection
from ambseal.design.pid import reference_controller
from ambseal.identify.excitation.signals import prbs
from ambseal.identify.fitting.stages import acquire, identify

# Ki/Ks of the facility, a few per cent from the rig file's (the fit's start)
TRUE = {"A.Ki_zeta": 205.0, "A.Ki_eta": 201.0, "B.Ki_zeta": 254.0, "B.Ki_eta": 271.0,
        "A.Ks_zeta": 2.45e6, "A.Ks_eta": 2.42e6, "B.Ks_zeta": 3.06e6, "B.Ks_eta": 3.25e6}
NAMES = list(TRUE) + ["tau_e"]
TAU = 2e-4
#: coupling 4 % stiffer than the rig file's 0.40/0.42 MN/m, seal damping 5 % off
OFF = {"coupling.kxx": 0.416e6, "coupling.kyy": 0.4368e6, "seal.C": 105.0, "seal.c": 285.0}
CASES = {
    "matched": {},
    "fixed values off": {"parameters": {**TRUE, **OFF}},
    # the rotor's model form: beam theory, half the shaft elements, 3 % modal damping
    # (the rig file's: Timoshenko, 0.5 %)
    "rotor model form": {"beam": "euler-bernoulli", "mesh_factor": 0.5, "modal_damping": 0.03},
    # a first-order 1 kHz low-pass in every sensor, which the model does not have
    "sensor filter": {"sensor_filter_hz": 1000.0},
}


def _run(cfg, case: str, seeds, duration_s: float, free_lag: bool = False):
    """Per seed: coverage, widths and the model check's findings; with ``free_lag`` also
    each record fitted again with the sensor lag ``tau_s`` freed (``lag_freed``: whether
    its Ki/Ks intervals cover)."""
    kw = dict(parameters=TRUE, tau_e=TAU, noise_fraction=0.01, adc_bits=16)
    kw.update(CASES[case])
    truth = TruthSection(**kw)
    true = np.array([TRUE.get(n, TAU) for n in NAMES])
    inside, inside_noise, width, flagged, dominant, disputed = [], [], [], [], [], []
    residual_flag, lag_flag, lag_freed = [], [], []
    for seed in seeds:
        ex = prbs(amplitude_a=0.05, clock_period_s=1e-3, duration_s=duration_s,
                  sample_rate_hz=1e4, seed=100 + seed)
        rec = acquire(cfg, truth, ex, controller=reference_controller(cfg), pressure_bar=0.0,
                      seed=1000 + seed)
        res = identify(cfg, [rec], NAMES, budget=True)
        inside.append((res.ci95_low <= true) & (true <= res.ci95_high))
        inside_noise.append(np.abs(res.estimate - true)
                            <= student.ppf(0.975, res.dof_noise) * res.std_error_noise)
        width.append(res.ci95_high - res.ci95_low)
        flagged.append(res.mismatch)
        residual_flag.append(bool(res.residuals.failed))
        dominant.append(res.budget.dominant())
        disputed.append(res.budget.disputed())
        lag_flag.append(res.sensor_lag["flagged"])
        if free_lag:
            free = identify(cfg, [rec], NAMES + ["tau_s"], budget=True)
            lag_freed.append((free.ci95_low[:-2] <= true[:-1])
                             & (true[:-1] <= free.ci95_high[:-2]))
    return (np.array(inside), np.array(inside_noise), np.array(width), np.array(flagged),
            dominant, disputed, np.array(residual_flag), np.array(lag_flag),
            np.array(lag_freed))


def test_budget_covers_a_coupling_held_wrong_and_names_it(testrig_cfg):
    """Two seeds, coupling held 4 % off: the noise-only intervals miss A's Ks (a bias of
    several standard errors), the intervals with the fixed-parameter
    budget contain every truth, the budget names the coupling as dominant and the score
    test disputes both coupling values, which marks the fit a model mismatch. Reference: the facility's truth (the rig file's
    coupling is known to be 4 % off)."""
    inside, inside_noise, _, flagged, dominant, disputed, *_ = _run(
        testrig_cfg, "fixed values off", range(2), 0.3)
    assert inside.all(), inside
    assert not inside_noise[:, NAMES.index("A.Ks_zeta")].any()
    assert all({"coupling.kxx", "coupling.kyy"} <= set(d) for d in dominant)
    assert all({"coupling.kxx", "coupling.kyy"} <= set(d) for d in disputed)
    assert flagged.all()  # the model check: a disputed fixed value is a model mismatch


@pytest.mark.slow
def test_coverage_and_model_check_over_20_seeds(testrig_cfg):
    """Over 20 seeds (PRBS and noise both drawn anew), per case:
    coverage of the reported 95 % intervals, their width against matched records, and how
    often the model check flags the fit (residuals correlated with the excitation, a
    fixed value disputed by the score test, or a sensor lag asked for by its score test).
    Matched records: every parameter covered in ≥ 90 % of seeds, flagged in ≤ 10 % (false
    alarms: 4 channels, 4 fixed values and the lag tested at 1 %). Fixed values off by a
    few per cent: ≥ 90 % coverage within 5× the matched width, the coupling named by the
    budget in every seed, disputed and flagged in ≥ 90 %. The rotor's model form: ≥ 90 %
    coverage within 5× the width (the loop, 40–130 Hz, sits far below the first bending
    mode: nothing for a test to flag). A 1 kHz sensor filter the model lacks: τ_e absorbs
    most of it and Ki/Ks move by 0.5–1 %, so the intervals miss; such fits must be
    flagged — asserted: the intervals cover or the fit is flagged in ≥ 90 %
    of seeds, and with ``tau_s`` freed (the check's advice) the Ki/Ks intervals cover
    ≥ 90 %. Reference: the facility's truth;
    90 % is the bar (a binomial 95 % tolerance of nominal 95 % over 20 seeds is
    ±9.6 %, over 180 intervals ±3.2 %)."""
    seeds = range(20)
    out = {}
    runs = {case: _run(testrig_cfg, case, seeds, 0.5, free_lag=case == "sensor filter")
            for case in CASES}
    w0 = np.median(runs["matched"][2], axis=0)
    for case, (inside, inside_noise, width, flagged, dominant, disputed, resid, lag,
               freed) in runs.items():
        out[case] = {"coverage": inside.mean(),
                     "per_parameter": inside.mean(axis=0).round(2).tolist(),
                     "coverage_noise_only": inside_noise.mean(),
                     "noise_only_per_parameter": inside_noise.mean(axis=0).round(2).tolist(),
                     "width_vs_matched": (np.median(width, axis=0) / w0).round(2).tolist(),
                     "flagged": flagged.mean(), "flagged_by_residuals": resid.mean(),
                     "flagged_by_score_test": np.mean([bool(d) for d in disputed]),
                     "coupling_named": np.mean([{"coupling.kxx", "coupling.kyy"} <= set(d)
                                                for d in dominant]),
                     "coupling_disputed": np.mean([bool({"coupling.kxx", "coupling.kyy"}
                                                        & set(d)) for d in disputed]),
                     "flagged_by_lag_test": lag.mean(),
                     "covered_or_flagged": np.mean(inside.all(axis=1) | flagged),
                     **({"lag_freed_ki_ks_coverage": freed.mean(),
                         "lag_freed_per_parameter": freed.mean(axis=0).round(2).tolist()}
                        if freed.size else {})}
    print(json.dumps(out, default=float))
    assert (runs["matched"][0].mean(axis=0) >= 0.90).all()
    assert out["matched"]["flagged"] <= 0.10
    for case in ("fixed values off", "rotor model form"):
        assert out[case]["coverage"] >= 0.90
        assert max(out[case]["width_vs_matched"]) <= 5.0
    off = out["fixed values off"]
    assert off["coupling_named"] == 1.0
    assert off["coupling_disputed"] >= 0.9 and off["flagged"] >= 0.9
    lag = out["sensor filter"]
    assert lag["covered_or_flagged"] >= 0.9
    assert lag["lag_freed_ki_ks_coverage"] >= 0.9


def test_sensor_lag_model_reproduces_the_facility_filter(testrig_cfg):
    """The fit's sensor lag τ_s (``ambseal.identify.fitting.sensor_lag``: y[n] = a y[n−1] +
    (1 − a) x(nT), a = τ_s/(τ_s + T)) against the virtual facility's 1 kHz sensor low-pass
    (its own compiled loop, a = e^{−2π·1000·T}): with τ_s = aT/(1 − a) the model reproduces
    the facility's noise-free record to within a few times the facility's own departure
    from the model without a filter (nonlinear force law, sub-steps), and without τ_s it
    misses by hundreds of times more."""
    from ambseal.identify.fitting.stages import build_models

    kw = dict(parameters=TRUE, tau_e=TAU)
    ex = prbs(amplitude_a=0.05, clock_period_s=1e-3, duration_s=0.1, sample_rate_hz=1e4,
              seed=5)
    K = reference_controller(testrig_cfg)
    a = np.exp(-2 * np.pi * 1000.0 / 1e4)
    err = {}
    for case, lag in (("matched", 0.0), ("filter", a * 1e-4 / (1 - a)), ("filter", 0.0)):
        truth = TruthSection(**kw, sensor_filter_hz=1000.0 if case == "filter" else None)
        rec = acquire(testrig_cfg, truth, ex, controller=K, pressure_bar=0.0, seed=1)
        model = build_models(testrig_cfg, [rec], {**TRUE, "tau_e": TAU, "tau_s": lag})[0]
        y, _ = model.simulate({}, np.asarray(rec.excitation_a))
        err[case, lag > 0] = np.max(np.linalg.norm(y - rec.displacement_m, axis=0)
                                    / np.linalg.norm(rec.displacement_m, axis=0))
    # measured: 0.023 % matched, 0.065 % with the filter and τ_s, 43 % without τ_s
    assert err["filter", True] < 5 * err["matched", False]
    assert err["filter", False] > 100 * err["filter", True]


def test_sensor_lag_score_test_flags_and_the_freed_lag_covers(testrig_cfg):
    """One seed of the slow test's cases. An unmodelled 1 kHz sensor low-pass: the score
    test of a sensor lag flags the fit (|z| > 2.58) and suggests a positive lag; fitting
    ``tau_s`` beside τ_e brings every Ki/Ks interval over the facility's truth (the first
    fit's miss by 0.5–1 %). A matched record: no lag asked for. Reference: the facility's
    truth."""
    truths = {c: TruthSection(parameters=TRUE, tau_e=TAU, noise_fraction=0.01, adc_bits=16,
                              **CASES[c]) for c in ("matched", "sensor filter")}
    ex = prbs(amplitude_a=0.05, clock_period_s=1e-3, duration_s=0.4, sample_rate_hz=1e4,
              seed=100)
    K = reference_controller(testrig_cfg)
    true = np.array([TRUE[n] for n in NAMES[:-1]])
    res = {}
    for c, truth in truths.items():
        rec = acquire(testrig_cfg, truth, ex, controller=K, pressure_bar=0.0, seed=1000)
        res[c] = identify(testrig_cfg, [rec], NAMES, budget=True)
    lag = res["sensor filter"].sensor_lag
    assert lag["flagged"] and lag["suggested_tau_s"] > 0
    check = res["sensor filter"].model_check()
    assert check["mismatch"] and check["sensor_lag"] and "tau_s" in check["verdict"]
    assert not res["matched"].sensor_lag["flagged"]
    freed = identify(testrig_cfg, [rec], NAMES + ["tau_s"], budget=True)
    inside = (freed.ci95_low[:-2] <= true) & (true <= freed.ci95_high[:-2])
    assert inside.all(), inside
    assert freed.sensor_lag is None  # nothing left to test: the lag is fitted
