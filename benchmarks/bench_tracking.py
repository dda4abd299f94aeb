"""On-line tracker of seal coefficients (issue 14 §1): real-time factor at the rig's rate.

A record of the virtual test facility (the embedded rig at its operating pressure, 1 %
sensor noise, the tracker's default PRBS), then ``ambseal.identify.tracking.track`` on it
tracking ``seal.k``. Ours: the RPEM kernel compiled by numba (compilation outside the
timing). Baseline: the same kernel interpreted by CPython, on the first ``--baseline-s`` of
the record and extrapolated to the whole record (``baseline_extrapolated``). Prints one JSON
line: ``realtime_factor`` = record length / CPU time of the recursion (this process's CPU
time: on a shared machine elapsed time measures the other jobs), ``realtime_factor_wall``
the same on elapsed time, the goal ≥ 10, and the flops per sample.

    PYTHONPATH=src python benchmarks/bench_tracking.py [--duration-s 3] [--rig RIG]

``--ramp RUN_DIR``: instead, the tracked scheme's closed-loop 0 → 3× nominal ramp
(:func:`ambseal.analysis.ramp.ramp_simulation`) over ``--seeds`` seeds, from the output of
one ``ambseal run RIG --truth TRUTH --set design.tracked=true`` (its identified rig, the
tracked controller's table and the μ controller, the fallback) and the tracked design
from ``--design-cache`` (the run's ``$AMBSEAL_CACHE_DIR`` file; read without its key
check, as the synthesis takes minutes). Prints one JSON line per seed: the 95 %
interval's coverage of the true k, the largest error, and whether the tracker refused
(its consistency test) and when the μ controller took over.

    PYTHONPATH=src python benchmarks/bench_tracking.py --rig examples/pump.toml \
        --truth tests/data/pump_truth.toml --ramp OUT --design-cache CACHE.json --seeds 20
"""

from __future__ import annotations

import argparse
import json
import os
import sys
from dataclasses import replace

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")
os.environ.setdefault("OMP_NUM_THREADS", "1")


def main() -> None:
    import numpy as np

    from ambseal.config import TruthSection, load_rig
    from ambseal.design.pid import reference_controller
    from ambseal.identify.fitting.stages import acquire
    from ambseal.identify.tracking import TrackingSettings, track, tracking_excitation

    ap = argparse.ArgumentParser()
    ap.add_argument("--rig", default=None)
    ap.add_argument("--param", default=None, help="default: the first seal's k")
    ap.add_argument("--duration-s", type=float, default=3.0)
    ap.add_argument("--baseline-s", type=float, default=0.02)
    ap.add_argument("--ramp", default=None, help="an `ambseal run` output folder")
    ap.add_argument("--truth", default=None)
    ap.add_argument("--design-cache", default=None)
    ap.add_argument("--seeds", type=int, default=20)
    ap.add_argument("--first-seed", type=int, default=0)
    args = ap.parse_args()
    if args.ramp:
        return ramp(args)
    cfg = load_rig(args.rig)
    name = args.param or f"{cfg.seal[0].name}.k"
    print(f"recording {args.duration_s} s on the virtual facility ...", file=sys.stderr)
    truth = TruthSection(noise_fraction=0.01, tau_e=cfg.actuator.eddy_time_constant)
    rec = acquire(cfg, truth, tracking_excitation(cfg, args.duration_s, seed=1),
                  controller=reference_controller(cfg),
                  pressure_bar=cfg.operating.pressure_bar, seed=1)
    res = track(cfg, rec, [name])
    n = int(round(args.baseline_s * cfg.controller.sample_rate_hz))
    short = replace(rec, **{f: getattr(rec, f)[:n] for f in
                            ("time_s", "excitation_a", "current_ref_a", "current_a",
                             "displacement_m")})
    print(f"interpreted baseline on {n} samples ...", file=sys.stderr)
    quick = TrackingSettings(min_duration_s=0.0)
    base = track(cfg, short, [name], quick, compiled=False)
    base_s = base.cpu_time_s * len(rec.time_s) / n
    same = track(cfg, short, [name], quick)  # the same numbers, compiled
    np.testing.assert_allclose(base.estimate[:, 0], same.estimate[:, 0], rtol=1e-9)
    print(json.dumps({
        "case": f"track_{name}", "samples": len(rec.time_s),
        "sample_rate_hz": cfg.controller.sample_rate_hz, "n_states": res.n_states,
        "flops_per_sample": res.flops_per_sample,
        "ours_s": res.cpu_time_s, "ours_wall_s": res.wall_time_s,
        "baseline": "same RPEM kernel interpreted (no numba)", "baseline_s": base_s,
        "baseline_extrapolated": True, "ratio": base_s / res.cpu_time_s,
        "realtime_factor": res.realtime_factor,
        "realtime_factor_wall": rec.time_s[-1] / res.wall_time_s,
        "goal_realtime_factor": 10.0}))


def ramp(args) -> None:
    import time
    from pathlib import Path

    from ambseal.analysis.judge import judge_settings
    from ambseal.analysis.ramp import ramp_simulation
    from ambseal.config import load_rig, load_truth
    from ambseal.design.seal_schedule import _read_cache
    from ambseal.design.specs import design_spec
    from ambseal.export.controller_files import load_controller

    run = Path(args.ramp)
    cfg, truth = load_rig(args.rig), load_truth(args.truth)
    ident = load_rig(run / "identified_rig.toml")
    cache = Path(args.design_cache)
    tracked = _read_cache(cache, json.loads(cache.read_text())["key"])
    table = load_controller(run / "controllers" / "controller_tracked.npz")
    mu = load_controller(run / "controllers" / "controller_mu.npz").discrete
    judgement = judge_settings(design_spec(cfg))
    for seed in range(args.first_seed, args.first_seed + args.seeds):
        t0 = time.process_time()
        r = ramp_simulation(cfg, truth, {"mu": mu}, tracked, model_cfg=ident,
                            tracked_digital=table, delay_samples=cfg.controller.delay_samples,
                            judgement=judgement, seed=seed)
        t = r.tracking
        print(json.dumps({"seed": seed, "coverage": t["coverage"],
                          "max_error_rel": t["max_error_rel"], "refused": t["refused"],
                          "refused_at_s": t["refused_at_s"], "fallback": t["fallback"],
                          "fallback_from_s": t["fallback_from_s"],
                          "check_largest": t["check_largest"],
                          "check_largest_bias_se": t["check_largest_bias_se"],
                          "threshold": t["check_threshold"],
                          "tracked_lost_at_s": r.runs["tracked"].lost_at_s,
                          "mu_lost_at_s": r.runs["mu"].lost_at_s,
                          "cpu_s": time.process_time() - t0}), flush=True)


if __name__ == "__main__":
    main()
