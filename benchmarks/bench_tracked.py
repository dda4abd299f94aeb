"""Time the synthesis of ``ambseal run``'s tracked controller (the H∞ LPV controller
scheduled on the seal's k over 0–3× nominal, :func:`ambseal.design.seal_schedule.
design_seal_scheduled`) on the rig ``ambseal run`` designs it on — the test rig as
identified on the virtual facility (``tests/data/testrig_identified_seed0.toml``, seed 0;
an eddy-current lag, 32 design-plant states) — and on the embedded rig file.

Ours: the whole design (design plants, the γ SDP by CVXOPT with the structured Schur
complement of :mod:`ambseal.robust._lmi_sdp`, the closed-form controller table and its
frozen check), cache off. Baseline, same run: the same γ SDP — the very LMIs ours solved —
written in cvxpy and solved by Clarabel with the tolerances lpvsyn used with it (gaps 1e-6,
feasibility 1e-8, no chordal decomposition), the former solver.

One JSON line per case on stdout: ``{"case", "design_s", "ours_sdp_s", "ours_objective",
"baseline", "baseline_s", "baseline_objective", "baseline_status", "ratio", "gamma",
"check_gamma_max"}``, times in seconds of CPU (``ratio`` = baseline/ours SDP time; an
objective closer to the optimum is lower).

Run from the repository root with the ``bench`` extra (cvxpy, Clarabel):
``PYTHONPATH=src python benchmarks/bench_tracked.py`` (about 4 minutes of CPU).
"""

from __future__ import annotations

import json
import os
import sys
import time
from pathlib import Path

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")
os.environ.pop("AMBSEAL_CACHE_DIR", None)  # time the synthesis, not a cache read

_CLARABEL = {"tol_gap_abs": 1e-6, "tol_gap_rel": 1e-6, "tol_feas": 1e-8,
             "chordal_decomposition_enable": False}


def _clarabel(lmis, n, n_vars, cost_gamma, cost_trace):
    """The same SDP in cvxpy, solved by Clarabel: (CPU s, objective, status)."""
    import cvxpy as cp
    import numpy as np

    X = [cp.Variable((n, n), symmetric=True) for _ in range(n_vars)]
    g = cp.Variable()
    cons = []
    for lmi in lmis:
        s = lmi.const + (g * lmi.gamma if lmi.gamma is not None else 0)
        for t in lmi.terms:
            PXQ = t.P @ X[t.var] @ t.Q.T
            s = s + PXQ + PXQ.T
        cons.append(0.5 * (s + s.T) >> 0)
    obj = cost_gamma * g + sum(c * cp.trace(Xv) for c, Xv in zip(cost_trace, X))
    prob = cp.Problem(cp.Minimize(obj), cons)
    t0 = time.process_time()
    prob.solve(solver=cp.CLARABEL, **_CLARABEL)
    return time.process_time() - t0, float(np.real(prob.value)), str(prob.status)


def main() -> None:
    sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "src"))
    from ambseal.config import load_rig
    from ambseal.design.seal_schedule import design_seal_scheduled
    from ambseal.design.specs import design_spec
    from ambseal.robust import _lmi_sdp

    root = Path(__file__).resolve().parents[1]
    spec = design_spec(load_rig())
    seen = []
    solve = _lmi_sdp.solve_lmis

    def recording(lmis, n, n_vars, cost_gamma, cost_trace, options):
        t0 = time.process_time()
        sol = solve(lmis, n, n_vars, cost_gamma, cost_trace, options)
        seen.append((lmis, n, n_vars, cost_gamma, cost_trace, sol,
                     time.process_time() - t0))
        return sol

    _lmi_sdp.solve_lmis = recording
    for case, rig in (("tracked_identified", root / "tests/data/testrig_identified_seed0.toml"),
                      ("tracked_rig_file", None)):
        seen.clear()
        t0 = time.process_time()
        d = design_seal_scheduled(load_rig(rig) if rig else load_rig(), spec=spec,
                                  cache_dir=None)
        design_s = time.process_time() - t0
        lmis, n, n_vars, cg, ctr, sol, ours_s = seen[0]
        ours_obj = cg * sol.gamma + sum(c * float(X.trace()) for c, X in zip(ctr, sol.X))
        base_s, base_obj, base_status = _clarabel(lmis, n, n_vars, cg, ctr)
        print(json.dumps({"case": case, "design_s": round(design_s, 2),
                          "ours_sdp_s": round(ours_s, 2), "ours_iterations": sol.iterations,
                          "ours_objective": round(ours_obj, 5),
                          "baseline": "cvxpy + Clarabel, the same LMIs",
                          "baseline_s": round(base_s, 2),
                          "baseline_objective": round(base_obj, 5),
                          "baseline_status": base_status,
                          "ratio": round(base_s / ours_s, 2),
                          "gamma": round(d.gamma, 4),
                          "check_gamma_max": round(float(d.check_gamma.max()), 4)}),
              flush=True)


if __name__ == "__main__":
    main()
