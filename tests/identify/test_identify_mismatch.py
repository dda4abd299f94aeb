"""Intervals on data the model did not make: fixed parameters off their rig values and a
different rotor discretisation on the virtual facility (issue 17)."""

import json

import numpy as np
import pytest
from scipy.stats import t as student

from ambseal.config import TruthSection
from ambseal.control.pid import reference_controller
from ambseal.identify.signals import prbs
from ambseal.identify.stages import acquire, identify

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


def _run(cfg, case: str, seeds, duration_s: float):
    kw = dict(parameters=TRUE, tau_e=TAU, noise_fraction=0.01, adc_bits=16)
    kw.update(CASES[case])
    truth = TruthSection(**kw)
    true = np.array([TRUE.get(n, TAU) for n in NAMES])
    inside, inside_noise, width, flagged, dominant, disputed = [], [], [], [], [], []
    residual_flag = []
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
    return (np.array(inside), np.array(inside_noise), np.array(width), np.array(flagged),
            dominant, disputed, np.array(residual_flag))


def test_budget_covers_a_coupling_held_wrong_and_names_it(testrig_cfg):
    """Two seeds, coupling held 4 % off: the noise-only intervals miss A's Ks (the bias of
    several standard errors the issue reports), the intervals with the fixed-parameter
    budget contain every truth, the budget names the coupling as dominant and the score
    test disputes both coupling values, which marks the fit a model mismatch. Reference: the facility's truth (the rig file's
    coupling is known to be 4 % off)."""
    inside, inside_noise, _, flagged, dominant, disputed, _ = _run(
        testrig_cfg, "fixed values off", range(2), 0.3)
    assert inside.all(), inside
    assert not inside_noise[:, NAMES.index("A.Ks_zeta")].any()
    assert all({"coupling.kxx", "coupling.kyy"} <= set(d) for d in dominant)
    assert all({"coupling.kxx", "coupling.kyy"} <= set(d) for d in disputed)
    assert flagged.all()  # the model check: a disputed fixed value is a model mismatch


@pytest.mark.slow
def test_coverage_and_model_check_over_20_seeds(testrig_cfg):
    """Issue 17 acceptance over 20 seeds (PRBS and noise both drawn anew), per case:
    coverage of the reported 95 % intervals, their width against matched records, and how
    often the model check flags the fit (residuals correlated with the excitation, or a
    fixed value disputed by the score test). Matched records: every parameter covered in
    ≥ 90 % of seeds, flagged in ≤ 10 % (false alarms: 4 channels and 4 fixed values tested
    at 1 %, Bonferroni within each). Fixed values off by a few per cent: ≥ 90 % coverage
    within 5× the matched width, the coupling named by the budget in every seed, disputed
    and flagged in ≥ 90 %. The rotor's model form: ≥ 90 % coverage within 5× the width
    (the loop, 40–130 Hz, sits far below the first bending mode: nothing for a test to
    flag). A 1 kHz sensor filter the model lacks is printed, not asserted: τ_e absorbs it
    (the data cannot tell a sensor lag from an eddy lag). Reference: the facility's truth;
    90 % is the issue's bar (a binomial 95 % tolerance of nominal 95 % over 20 seeds is
    ±9.6 %, over 180 intervals ±3.2 %)."""
    seeds = range(20)
    out = {}
    runs = {case: _run(testrig_cfg, case, seeds, 0.5) for case in CASES}
    w0 = np.median(runs["matched"][2], axis=0)
    for case, (inside, inside_noise, width, flagged, dominant, disputed, resid) in runs.items():
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
                                                        & set(d)) for d in disputed])}
    print(json.dumps(out, default=float))
    assert (runs["matched"][0].mean(axis=0) >= 0.90).all()
    assert out["matched"]["flagged"] <= 0.10
    for case in ("fixed values off", "rotor model form"):
        assert out[case]["coverage"] >= 0.90
        assert max(out[case]["width_vs_matched"]) <= 5.0
    off = out["fixed values off"]
    assert off["coupling_named"] == 1.0
    assert off["coupling_disputed"] >= 0.9 and off["flagged"] >= 0.9
