"""Benchmark: ambseal's hinfsyn against python-control's hinfsyn on two H∞ problems.

Run from the repository root::

    PYTHONPATH=src python benchmarks/bench_hinf.py [--repeats 5]

Cases:

* ``sgc97_example7`` — the 3-state plant of Scherer, Gahinet & Chilali (1997), Example 7
  (p. 907), published γ_opt ≈ 9.5081;
* ``testrig_nominal`` — the nominal H∞ problem of the embedded test rig
  (``design(cfg, "hinf")``'s generalised plant, 24 states).

Ours: ``ambseal.robust.hinf.hinfsyn`` — γ_opt between cheap bounds (Parrott's bound, a
ladder of factors 4; SB10AD's test and its own bisection called through slycot's compiled
wrapper below 7 states, Brent's method on the Riccati margin above), then the controller at
1.01·γ_opt with its closed loop checked stable and its norm recomputed. Baseline:
``control.hinfsyn`` (SB10AD bisection and scan from γ = 1e100). Each line gives the median
CPU times (``time.process_time``: on a shared machine wall times measure the neighbours),
their ratio, both γ's (ours: γ_opt of the search) and their relative difference (goal
≤ 1e-4), and our number of γ tests.
"""

from __future__ import annotations

import argparse
import json
import statistics
import time

import numpy as np


def sgc97():
    import control as ct

    A = [[0.0, 10.0, 2.0], [-1.0, 1.0, 0.0], [0.0, 2.0, -5.0]]
    B = [[1.0, 0.0], [0.0, 1.0], [1.0, 0.0]]
    C = [[1.0, 0.0, 0.0], [0.0, 0.0, 0.0], [0.0, 1.0, 0.0]]
    D = [[0.0, 0.0], [0.0, 1.0], [2.0, 0.0]]
    return ct.ss(A, B, C, D), 1, 1


def testrig():
    from ambseal.config import load_rig
    from ambseal.design.recipes import design

    gp = design(load_rig(), "hinf").plant
    return gp.P_nominal, gp.nmeas, gp.ncon


def _median_time(fn, repeats):
    times, out = [], None
    for _ in range(repeats):
        t0 = time.process_time()
        out = fn()
        times.append(time.process_time() - t0)
    return statistics.median(times), out


def main() -> None:
    import control as ct

    from ambseal.robust.hinf import hinfsyn

    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeats", type=int, default=5)
    ap.add_argument("--baseline-repeats", type=int, default=3)
    args = ap.parse_args()
    for name, make in (("sgc97_example7", sgc97), ("testrig_nominal", testrig)):
        P, nmeas, ncon = make()
        ours_s, r = _median_time(lambda: hinfsyn(P, nmeas, ncon), args.repeats)
        base_s, b = _median_time(lambda: ct.hinfsyn(P, nmeas, ncon), args.baseline_repeats)
        gam_b = float(b[2])
        print(json.dumps({
            "case": name, "ours_s": round(ours_s, 4),
            "baseline": "control.hinfsyn (python-control 0.10, SB10AD from γ=1e100)",
            "baseline_s": round(base_s, 4), "ratio": round(base_s / ours_s, 1),
            "states": int(P.nstates), "gamma_opt_ours": r.gamma_opt, "gamma_baseline": gam_b,
            "gamma_rel_diff": float(abs(r.gamma_opt / gam_b - 1)),
            "gamma_verified_ours": r.gamma, "sb10ad_calls_ours": r.iterations,
            "gamma_published": 9.5081 if name == "sgc97_example7" else None,
            "goal_ratio": 10.0, "goal_rel_diff": 1e-4,
        }), flush=True)


if __name__ == "__main__":
    np.set_printoptions(precision=6)
    main()
