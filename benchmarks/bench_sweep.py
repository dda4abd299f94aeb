"""Time a pressure × speed stability map serial against a 2-worker local Dask cluster (issue 12).

One JSON line on stdout: ``{"case", "ours_s", "baseline", "baseline_s", "ratio",
"same_numbers", ...}`` — ``ours_s`` the 21 × 16 sweep of :func:`ambseal.analysis.sweep.sweep`
(reference PID, 0 … 4.08 bar × 0 … 150 Hz) on a ``dask.distributed`` LocalCluster of 2
processes with one BLAS thread each (cluster start-up included), ``baseline_s`` the same
sweep serially in this process; ``ratio`` = baseline_s / ours_s (goal ≥ 1.7 on 2 free cores)
and ``same_numbers`` whether the two tables are identical. ``--quick`` sweeps 7 × 4.

Run from the repository root: ``PYTHONPATH=src python benchmarks/bench_sweep.py``.
"""

from __future__ import annotations

import argparse
import json
import os
import sys
import time
from pathlib import Path

for _v in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(_v, "1")


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--quick", action="store_true")
    args = ap.parse_args()
    sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "src"))
    import numpy as np

    from ambseal.analysis.sweep import stability_boundary, sweep
    from ambseal.config import load_rig
    from ambseal.analysis.judge import judge_settings
    from ambseal.design.recipes import design
    from ambseal.design.specs import design_spec

    cfg = load_rig()
    K = {"pid": design(cfg, "pid").K}
    n_p, n_s = (7, 4) if args.quick else (21, 16)
    pressures, speeds = np.linspace(0.0, 4.08, n_p), np.linspace(0.0, 150.0, n_s)
    t0 = time.perf_counter()
    settings = judge_settings(design_spec(cfg))
    serial = sweep(cfg, K, pressures, speeds, workers=1, settings=settings)
    t_serial = time.perf_counter() - t0
    t0 = time.perf_counter()
    dask = sweep(cfg, K, pressures, speeds, workers=2, settings=settings)
    t_dask = time.perf_counter() - t0
    edge = [e["boundary_pressure_bar"] for e in stability_boundary(dask)]
    print(json.dumps({"case": f"sweep_{n_p}x{n_s}_pid", "ours": "dask LocalCluster 2 workers",
                      "ours_s": round(t_dask, 2), "baseline": "serial",
                      "baseline_s": round(t_serial, 2), "ratio": round(t_serial / t_dask, 3),
                      "same_numbers": json.dumps(serial) == json.dumps(dask),
                      "failed": sum(r.get("error") is not None for r in dask),
                      "boundary_bar_min_max": [min(edge), max(edge)],
                      "cpu_count": os.cpu_count()}), flush=True)


if __name__ == "__main__":
    main()
