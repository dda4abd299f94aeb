"""Time the gridded LPV synthesis on the turboexpander (issue 5; thesis P3 §4).

One JSON line per case on stdout: ``{"case", "ours_s", "gamma", "iterations", "status",
"check_gamma_max"}`` — the CPU time of :func:`ambseal.design.lpv_design.design_lpv` over
20–300 Hz, with the γ stage's interior-point iterations: the default constant-Lyapunov
design on the vertex grid (the range's ends and the seal-table points, 7 speeds; issue 9)
against the 10-point equally spaced grid it replaced (baseline, same run, ``ratio`` =
ours/baseline), and the rate-bounded design on 10 points. SCS on the same LMIs is not
accurate enough to be a baseline solver here (issue 5).

Run from the repository root: ``PYTHONPATH=src python benchmarks/bench_lpv.py``.
"""

from __future__ import annotations

import json
import os
import sys
import time
from pathlib import Path

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")


def main() -> None:
    sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "src"))
    from ambseal.config import load_rig
    from ambseal.design.lpv_design import design_lpv

    cfg = load_rig(Path(__file__).resolve().parents[1] / "examples" / "turboexpander.toml")
    base = None
    for case, kw in (("lpv_constant_10pt", {"n_grid": 10}),
                     ("lpv_constant_vertex", {}),
                     ("lpv_affine_rate280_10pt", {"rate_bound_hz_per_s": 280.0})):
        t0 = time.process_time()
        d = design_lpv(cfg, frozen_gamma=False, **kw)
        dt = time.process_time() - t0
        base = dt if case == "lpv_constant_10pt" else base
        vertex = case == "lpv_constant_vertex"
        print(json.dumps({"case": case, "grid_hz": d.speeds_hz.round(2).tolist(),
                          "ours_s": round(dt, 3),
                          "baseline": "lpv_constant_10pt" if vertex else None,
                          "baseline_s": round(base, 3) if vertex else None,
                          "ratio": round(dt / base, 3) if vertex else None, "gamma": d.gamma,
                          "iterations": d.reports[0].iterations,
                          "reconstruct_iterations": d.reports[-1].iterations,
                          "status": [r.status for r in d.reports],
                          "stage_s": {r.stage: round(r.time_s, 3) for r in d.reports},
                          "check_gamma_max": float(d.check_gamma.max())}), flush=True)

if __name__ == "__main__":
    main()
