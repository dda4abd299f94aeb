"""Time the gridded LPV synthesis on the turboexpander (issue 5; thesis P3 §4).

One JSON line per case on stdout: ``{"case", "ours_s", "gamma", "iterations", "status",
"check_gamma_max"}`` — the wall time of :func:`ambseal.control.lpv_design.design_lpv` for a
10-point 20–300 Hz grid (goal: under 60 s), with the γ stage's interior-point iterations.
No baseline: SCS on the same LMIs is not accurate enough here (issue 5).

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
    from ambseal.control.lpv_design import design_lpv

    cfg = load_rig(Path(__file__).resolve().parents[1] / "examples" / "turboexpander.toml")
    for case, kw in (("lpv_constant_10pt", {}),
                     ("lpv_affine_rate280_10pt", {"rate_bound_hz_per_s": 280.0})):
        t0 = time.perf_counter()
        d = design_lpv(cfg, n_grid=10, frozen_gamma=False, **kw)
        dt = time.perf_counter() - t0
        print(json.dumps({"case": case, "ours_s": round(dt, 3), "baseline": None,
                          "baseline_s": None, "ratio": None, "gamma": d.gamma,
                          "iterations": d.reports[0].iterations,
                          "reconstruct_iterations": d.reports[-1].iterations,
                          "status": [r.status for r in d.reports],
                          "stage_s": {r.stage: round(r.time_s, 3) for r in d.reports},
                          "check_gamma_max": float(d.check_gamma.max())}), flush=True)


if __name__ == "__main__":
    main()
