"""Benchmark: the virtual facility's compiled sample loop against the same loop as Python.

Case ``facility_loop_1s_10khz``: the embedded test rig's virtual facility (truth file
``data/testrig_truth.toml``, 4 sub-steps per sample) levitated by the reference PID, a
PRBS current excitation of 1 s at 10 kHz (10 000 samples).

- Ours: :func:`ambseal.identify.facility.facility_loop.facility_loop`, compiled by numba (the
  compilation is done in an untimed warm-up run, as it is cached on disk after the first
  run of ``ambseal``).
- Baseline: the same function's Python source, ``facility_loop.py_func``, run by the
  interpreter on the same arrays — the loop ambseal had before it was compiled. The line
  also gives ``max_rel_diff`` of the recorded displacements (quantisation off, so both
  are the same IEEE arithmetic).

Run: ``PYTHONPATH=src python benchmarks/bench_facility.py [--repeats N]``.
"""

from __future__ import annotations

import argparse
import json
import os
import statistics
import time

for var in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(var, "1")

import numpy as np  # noqa: E402


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--repeats", type=int, default=3)
    opts = ap.parse_args()

    from ambseal.config import load_rig, load_truth
    from ambseal.design.pid import reference_controller
    from ambseal.identify.facility import rig_sim
    from ambseal.identify.facility.facility_loop import facility_loop
    from ambseal.identify.excitation.signals import prbs
    from ambseal.app.pipeline import default_truth_path

    cfg = load_rig()
    truth = load_truth(default_truth_path()).model_copy(update={"adc_bits": 0})
    K = reference_controller(cfg)
    ex = prbs(amplitude_a=0.05, clock_period_s=1e-3, duration_s=1.0,
              sample_rate_hz=1.0 / K.dt, seed=1)
    captured = {}

    def capture(*args):  # record the arguments of the facility's call, then run it
        captured["args"] = args
        return facility_loop(*args)

    rig_sim.facility_loop = capture
    rig_sim.simulate_facility(cfg, truth, ex.values_a, 1.0 / K.dt, K, pressure_bar=0.0,
                              seed=1)  # also the untimed warm-up (compilation)
    rig_sim.facility_loop = facility_loop
    args = captured["args"]

    def timed(fn):
        times, rec = [], None
        for _ in range(opts.repeats):
            rec = [np.empty_like(a) for a in args[-3:]]
            state = [np.zeros_like(a) for a in args[-6:-3]]  # z, xc, yf from rest
            t0 = time.perf_counter()
            fn(*args[:-6], *state, *rec)
            times.append(time.perf_counter() - t0)
        return statistics.median(times), rec

    ours_s, ours = timed(facility_loop)
    base_s, base = timed(facility_loop.py_func)
    diff = float(np.max(np.abs(ours[0] - base[0])) / np.max(np.abs(base[0])))
    print(json.dumps({"case": "facility_loop_1s_10khz", "ours_s": round(ours_s, 4),
                      "baseline": "facility_loop.py_func (interpreted)",
                      "baseline_s": round(base_s, 4), "ratio": round(base_s / ours_s, 1),
                      "max_rel_diff": diff}))


if __name__ == "__main__":
    main()
