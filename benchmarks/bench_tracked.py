"""Time the synthesis of ``ambseal run``'s tracked controller (the H∞ LPV controller
scheduled on the seal's k over 0–3× nominal, :func:`ambseal.design.seal_schedule.
design_seal_scheduled`) on the embedded test rig and on the rig ``ambseal run`` designs it
on: the test rig as identified on the virtual facility (``tests/data/
testrig_identified_seed0.toml``, seed 0; identified seal coefficients and an eddy-current lag,
32 design-plant states instead of 28).

One JSON line per case on stdout: ``{"case", "ours_s", "baseline", "baseline_s", "ratio",
"gamma", "check_gamma_max", "table"}`` — the CPU time of the whole design (design plants,
the γ SDP, the controller table's reconstruction SDPs and its frozen check) with the cache
off (``$AMBSEAL_CACHE_DIR`` unset, no ``cache_dir``): the default design grid against the
previous default of 5 design points (baseline, same run, ``ratio`` = ours/baseline). Both
tabulate the controller at the same 21 values of k, where its frozen loops are checked.

Run from the repository root: ``PYTHONPATH=src python benchmarks/bench_tracked.py``
(about 3–4 minutes of CPU).
"""

from __future__ import annotations

import json
import os
import sys
import time
from pathlib import Path

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")
os.environ.pop("AMBSEAL_CACHE_DIR", None)  # time the synthesis, not a cache read


def main() -> None:
    sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "src"))
    from ambseal.config import load_rig
    from ambseal.design.seal_schedule import design_seal_scheduled
    from ambseal.design.specs import design_spec

    cfg = load_rig()
    spec = design_spec(cfg)
    root = Path(__file__).resolve().parents[1]
    t0 = time.process_time()
    d = design_seal_scheduled(load_rig(root / "tests" / "data" / "testrig_identified_seed0.toml"),
                              spec=spec, cache_dir=None)
    print(json.dumps({"case": "tracked_identified", "ours_s": round(time.process_time() - t0, 2),
                      "gamma": round(d.gamma, 4),
                      "check_gamma_max": round(float(d.check_gamma.max()), 4),
                      "table": int(d.check_grid.size)}), flush=True)
    base = None
    for case, kw in (("tracked_5pt", {"n_grid": 5, "check_density": 5}),
                     ("tracked_default", {})):
        t0 = time.process_time()
        d = design_seal_scheduled(cfg, spec=spec, cache_dir=None, **kw)
        dt = time.process_time() - t0
        base = dt if base is None else base
        ours = case == "tracked_default"
        print(json.dumps({"case": case, "grid_k_nom": (d.grid / (d.grid[-1] / 3)).round(3).tolist(),
                          "ours_s": round(dt, 2),
                          "baseline": "tracked_5pt" if ours else None,
                          "baseline_s": round(base, 2) if ours else None,
                          "ratio": round(dt / base, 3) if ours else None,
                          "gamma": round(d.gamma, 4),
                          "check_gamma_max": round(float(d.check_gamma.max()), 4),
                          "table": int(d.check_grid.size)}), flush=True)


if __name__ == "__main__":
    main()
