"""Benchmark: the closed-loop output-error fit against the naive approach, in one process.

Case ``fit_9_params_1s_10khz``: one PRBS record of 1 s at 10 kHz from the virtual test
facility (1 % sensor noise); fit the eight Ki/Ks and τ_e.

- Ours: :func:`ambseal.identify.fitting.fit.fit_parameters` on the reduced model with the
  parameters in its LFT channels, exact ZOH discretisation, block-recursive closed-loop
  simulation (``ours_s``; ``ours_identify_s`` adds model building and the refinement pass).
- Baseline ("naive"): ``scipy.optimize.least_squares`` with finite differences over
  ``control.forced_response`` of the full-order closed loop (plant rebuilt for every
  evaluation, digital PID discretised as on the rig), on the same data. It is run with a
  budget of ``--naive-nfev`` evaluations and its time per evaluation is reported; the
  ratio compares our whole fit with the naive fit's time for the same number of
  evaluations ours needed (``baseline_s`` = naive time per evaluation × our evaluations,
  flagged ``"baseline_extrapolated": true``).

Run: ``PYTHONPATH=src python benchmarks/bench_fit.py [--naive-nfev N]``.
"""

from __future__ import annotations

import argparse
import json
import os
import sys
import time

for var in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(var, "1")

import numpy as np  # noqa: E402


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--naive-nfev", type=int, default=12, help="evaluations of the naive fit")
    ap.add_argument("--repeats", type=int, default=3)
    args = ap.parse_args()

    import control
    from scipy.optimize import least_squares

    from ambseal.config import TruthSection, load_rig, rig_with_values
    from ambseal.design.pid import pid_controller
    from ambseal.identify.fitting.fit import fit_parameters
    from ambseal.robust.digital_loop import closed_loop_matrices, discrete_controller
    from ambseal.lti.discrete import zoh
    from ambseal.identify.excitation.signals import prbs
    from ambseal.design.pid import reference_controller
    from ambseal.identify.fitting.stages import acquire, build_models, identify
    from ambseal.model.rig import build_plant

    cfg = load_rig()
    true = {"A.Ki_zeta": 205.0, "A.Ki_eta": 201.0, "B.Ki_zeta": 254.0, "B.Ki_eta": 271.0,
            "A.Ks_zeta": 2.45e6, "A.Ks_eta": 2.42e6, "B.Ks_zeta": 3.06e6, "B.Ks_eta": 3.25e6}
    names = list(true) + ["tau_e"]
    truth = TruthSection(parameters=true, tau_e=2e-4, noise_fraction=0.01, adc_bits=16)
    ex = prbs(amplitude_a=0.05, clock_period_s=1e-3, duration_s=1.0, sample_rate_hz=1e4, seed=1)
    print("acquiring 1 s at 10 kHz from the virtual facility ...", file=sys.stderr)
    rec = acquire(cfg, truth, ex, controller=reference_controller(cfg), pressure_bar=0.0, seed=1)

    times, ident_times = [], []
    for _ in range(args.repeats):
        models = build_models(cfg, [rec])
        t0 = time.perf_counter()
        res = fit_parameters([rec], models, names)
        times.append(time.perf_counter() - t0)
        t0 = time.perf_counter()
        identify(cfg, [rec], names)
        ident_times.append(time.perf_counter() - t0)
    ours = float(np.median(times))

    # naive: rebuild the full-order plant per evaluation, forced_response of the closed loop
    pid = cfg.controller.pid
    axes = rec.axes
    Kd = discrete_controller(pid_controller(pid.kp, pid.ti, pid.td, pid.eps, axes), 1e-4)
    e = np.asarray(rec.excitation_a)
    y = np.asarray(rec.displacement_m)
    sy = y.std(axis=0)
    plant = build_models(cfg, [rec])[0].plant
    x0 = np.array([plant.parameter(n).nominal for n in names[:-1]] + [1e-4])  # rig values

    def naive_residual(x):
        values = dict(zip(names, x))
        c = rig_with_values(cfg, values)
        P = build_plant(c, pressure_bar=0.0)
        Ad, Bd = zoh(P.A, P.B, 1e-4)
        Acl, Bcl, Cy, _, _ = closed_loop_matrices(Ad, Bd, P.C, Kd)
        sys_ = control.ss(Acl, Bcl, Cy, np.zeros((4, 4)), 1e-4)
        ys = control.forced_response(sys_, T=rec.time_s, U=e.T).outputs.T
        return ((ys - y) / sy).ravel()

    print("naive fit (full order, forced_response, finite differences) ...", file=sys.stderr)
    t0 = time.perf_counter()
    naive = least_squares(naive_residual, x0, x_scale=np.abs(x0), max_nfev=args.naive_nfev)
    naive_time = time.perf_counter() - t0
    per_eval = naive_time / max(naive.nfev * (len(names) + 1), 1)
    baseline = per_eval * res.iterations * (len(names) + 1)
    print(json.dumps({
        "case": "fit_9_params_1s_10khz", "ours_s": ours,
        "ours_identify_s": float(np.median(ident_times)), "ours_nfev": res.iterations,
        "converged": res.converged, "baseline": f"naive least_squares + control.forced_response "
        f"(python-control {control.__version__})", "baseline_s": baseline,
        "baseline_extrapolated": True, "baseline_eval_s": per_eval,
        "baseline_run_s": naive_time, "baseline_nfev": int(naive.nfev),
        "ratio": baseline / ours}))


if __name__ == "__main__":
    main()
