"""Benchmark: the whole sign-off (API 617 Level I and II, unbalance response, ISO 14839-2)
beyond the run, goal 10 s CPU per rig for its delivered controllers.

Per rig: the controllers are designed and discretised as ``ambseal signoff`` does (not
timed: that is the run's work), then :func:`ambseal.analysis.sign_off` of each is timed
in CPU seconds (``time.process_time``, this process, one BLAS thread). One JSON line per
rig: ``{"case": "signoff", "rig", "controllers", "cpu_s", "per_controller_s", "goal_s",
"ratio" (cpu/goal), "meets_goal"}``.

Rigs: the embedded test rig, which the thesis runs at standstill and without impellers,
is given here what a sign-off needs — its maximum continuous speed at the 500 Hz its
unbalance demand is stated for, and one stage of plausible size at its seal — a timing
fixture, not a machine; and every example rig with ``[[stage]]`` tables (``--rig``
repeats to choose).

Run from the repository root: ``OPENBLAS_NUM_THREADS=1 PYTHONPATH=src python
benchmarks/bench_signoff.py [--rig PATH ...] [--method pid,hinf]``.
"""

from __future__ import annotations

import argparse
import json
import sys
import time
from pathlib import Path

GOAL_S = 10.0
EXAMPLES = ("examples/b2b_compressor.toml", "examples/overhung_compressor.toml")


def _embedded():
    from ambseal.config import default_rig_path, load_rig, parse_rig

    cfg = load_rig(default_rig_path())
    seal = cfg.seal[0]
    stage = {"position": seal.position, "power": 50e3, "impeller_diameter": 0.2,
             "discharge_width": 0.01, "suction_density": 1.2, "discharge_density": 2.0}
    data = cfg.model_dump()
    data["stage"] = [stage]
    data["operating"] = {**data["operating"], "speed_rpm": 30000.0}
    return "embedded", parse_rig(data)


def _controllers(cfg, methods):
    from ambseal.analysis import operating_points
    from ambseal.app.commands import digital_for
    from ambseal.design import design, design_spec

    from ambseal.errors import AmbsealError

    spec = design_spec(cfg)
    out = []
    for m in methods:
        try:  # a design that fails is not delivered, so not signed off
            res = design(cfg, m, spec=spec)
        except AmbsealError as exc:
            print(f"bench_signoff: {m} not delivered: {exc}", file=sys.stderr)
            continue
        out.append((m, digital_for(cfg, m, res.K, res, operating_points(spec))))
    return out


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--rig", action="append", default=None)
    ap.add_argument("--method", default="pid")
    args = ap.parse_args(argv)
    from ambseal.analysis import sign_off
    from ambseal.config import load_rig

    rigs = [_embedded()] + [(Path(r).stem, load_rig(r)) for r in (args.rig or EXAMPLES)]
    for name, cfg in rigs:
        ctrl = _controllers(cfg, args.method.split(","))
        per = {}
        for m, K in ctrl:
            t = time.process_time()
            sign_off(cfg, K, name=m)
            per[m] = time.process_time() - t
        cpu = sum(per.values())
        print(json.dumps({"case": "signoff", "rig": name, "controllers": list(per),
                          "cpu_s": round(cpu, 2),
                          "per_controller_s": {k: round(v, 2) for k, v in per.items()},
                          "goal_s": GOAL_S, "ratio": round(cpu / GOAL_S, 3),
                          "meets_goal": cpu <= GOAL_S}), flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
