"""Benchmark: ambseal's vectorised μ bounds against a per-frequency cvxpy LMI upper bound.

Run from the repository root::

    PYTHONPATH=src python benchmarks/bench_mu.py [--repeats 5] [--nfreq 500] [--baseline-nfreq 500]
        [--dk-repeats 1] [--only-testrig]

The first two cases are the test-rig μ problem (``testrig_mu_bounds``: upper and lower bound
on ``nfreq`` frequencies for the closed loop of the generalised plant with the μ controller,
goal < 0.5 s; ``testrig_dk_iteration``: the whole ``design(cfg, "mu")``, goal < 60 s).

Prints one JSON line per case::

    {"case": ..., "ours_s": ..., "baseline": ..., "baseline_s": ..., "ratio": ...}

``ours_s`` is the median wall time of ``mussv`` (upper *and* lower bound) on ``nfreq``
frequencies of a test-rig-sized closed loop (8 outputs × 6 inputs, 16 states);
``baseline_s`` the median time of the LMI bound ``min β s.t. Mᴴ D_l M ⪯ β² D_r`` (D
block-diagonal, full Hermitian blocks for repeated scalars; bisection on β² with Clarabel
through cvxpy, upper bound only) on the same frequencies; ``ratio = baseline_s / ours_s``.
``testrig_mu_bounds`` also gives ``ours_cpu_s``, the median CPU time (``time.process_time``)
of the same calls, steadier than wall time on a shared machine; one untimed call first loads
the μ bound's numba kernels (compiled once, ~9 s CPU, then cached in ``__pycache__``).
``max_rel_diff`` compares the two upper bounds where they bound the same quantity (complex
structures; for the mixed case the baseline ignores G, so ours may be lower). If
``--baseline-nfreq`` is below ``--nfreq`` the baseline time is scaled up linearly and
``baseline_extrapolated`` is true.

Needs the ``bench`` extra (cvxpy, clarabel); not imported by the tests.
"""

from __future__ import annotations

import argparse
import json
import statistics
import time

import numpy as np


def rig_sized_system(seed: int = 0):
    """A stable 16-state, 6-input, 8-output system with lightly damped modes (rotor-like)."""
    import control as ct

    rng = np.random.default_rng(seed)
    wn = np.logspace(np.log10(2 * np.pi * 5), np.log10(2 * np.pi * 800), 8)
    zeta = rng.uniform(0.02, 0.3, 8)
    A = np.zeros((16, 16))
    for i, (w, z) in enumerate(zip(wn, zeta)):
        A[2 * i:2 * i + 2, 2 * i:2 * i + 2] = [[0, 1], [-w**2, -2 * z * w]]
    T = rng.standard_normal((16, 16)) * 0.1 + np.eye(16)
    A = np.linalg.solve(T, A @ T)
    B = rng.standard_normal((16, 6)) * 50
    C = rng.standard_normal((8, 16))
    D = rng.standard_normal((8, 6)) * 0.1
    return ct.ss(A, B, C, D)


def lmi_upper(M, blocks, rtol=1e-3):
    """Per-frequency LMI upper bound by bisection on β² (complex D scalings only)."""
    import cvxpy as cp

    n, m = M.shape
    parts_l, parts_r, cons = [], [], []
    for r, c in blocks:
        if c == 0:
            k = abs(r)
            X = cp.Variable((k, k), hermitian=True)
            parts_l.append(X)
            parts_r.append(X)
            cons.append(X >> np.eye(k))
        else:
            d = cp.Variable(nonneg=True)
            parts_l.append(d * np.eye(c))
            parts_r.append(d * np.eye(r))
            cons.append(d >= 1)
    Dl = cp.bmat([[parts_l[i] if i == j else np.zeros((parts_l[i].shape[0], parts_l[j].shape[1]))
                   for j in range(len(parts_l))] for i in range(len(parts_l))])
    Dr = cp.bmat([[parts_r[i] if i == j else np.zeros((parts_r[i].shape[0], parts_r[j].shape[1]))
                   for j in range(len(parts_r))] for i in range(len(parts_r))])
    b2 = cp.Parameter(nonneg=True)
    Mh = M.conj().T
    lhs = Mh @ Dl @ M
    lmi = b2 * Dr - lhs
    cons = cons + [(lmi + lmi.H) / 2 >> 0]
    prob = cp.Problem(cp.Minimize(0), cons)
    lo, hi = 0.0, float(np.linalg.norm(M, 2)) * (1 + 1e-9)
    while hi - lo > rtol * hi:
        mid = 0.5 * (lo + hi)
        b2.value = mid**2
        try:
            prob.solve(solver=cp.CLARABEL)
            ok = prob.status in ("optimal", "optimal_inaccurate")
        except cp.error.SolverError:
            ok = False
        if ok:
            hi = mid
        else:
            lo = mid
    return hi


def testrig_cases(args) -> None:
    """The test-rig μ problem: closed loop of the generalised plant with the μ controller."""
    from ambseal.config import load_rig
    from ambseal.design.recipes import design
    from ambseal.robust.mu import mussv
    from ambseal.lti.freqresp import freqresp

    cfg = load_rig()
    t0 = time.perf_counter()
    r = design(cfg, "mu")
    dk_s = time.perf_counter() - t0
    dk_times = [dk_s]
    for _ in range(max(0, args.dk_repeats - 1)):
        t0 = time.perf_counter()
        design(cfg, "mu")
        dk_times.append(time.perf_counter() - t0)
    gp = r.plant
    cl = gp.closed_loop(r.K)
    blocks = list(gp.blocks)
    cblocks = [(abs(a), b) if b == 0 else (a, b) for a, b in blocks]
    w = np.logspace(np.log10(2 * np.pi * 1), np.log10(2 * np.pi * 2000), args.nfreq)
    mussv(cl, blocks, w)  # compiled kernels loaded (or compiled) before timing
    times, cpu, res = [], [], None
    for _ in range(args.repeats):
        t0, c0 = time.perf_counter(), time.process_time()
        res = mussv(cl, blocks, w)
        times.append(time.perf_counter() - t0)
        cpu.append(time.process_time() - c0)
    ours = statistics.median(times)
    Mw = freqresp(cl, w)
    nb = min(args.baseline_nfreq, args.nfreq)
    idx = np.linspace(0, args.nfreq - 1, nb).round().astype(int)
    t0 = time.perf_counter()
    ub = np.array([lmi_upper(Mw[i], cblocks) for i in idx])
    per_freq = (time.perf_counter() - t0) / nb
    base = per_freq * args.nfreq
    resc = mussv(cl, cblocks, w[idx])
    print(json.dumps({
        "case": "testrig_mu_bounds", "ours_s": round(ours, 4),
        "ours_cpu_s": round(statistics.median(cpu), 4),
        "baseline": "cvxpy+Clarabel LMI (complex D, bisection on β, per frequency)",
        "baseline_s": round(base, 3), "ratio": round(base / ours, 1), "nfreq": args.nfreq,
        "baseline_extrapolated": nb < args.nfreq, "blocks": blocks,
        "peak_upper": round(float(res.upper.max()), 4),
        "max_rel_diff_upper_complex": round(float(np.max(np.abs(resc.upper / ub - 1))), 5),
        "min_lower_over_upper": round(float(np.min(res.lower / res.upper)), 4),
        "goal_s": 0.5,
    }), flush=True)
    # D–K: the baseline is the LMI bound at every frequency of every μ evaluation of the
    # iteration (two per iteration: mixed structure and complexified D-step), i.e. the time the
    # μ steps alone would take with a per-frequency LMI solver
    n_mu = 2 * len(r.history)
    ngrid = 60
    base_dk = per_freq * ngrid * n_mu
    ours_dk = statistics.median(dk_times)
    print(json.dumps({
        "case": "testrig_dk_iteration", "ours_s": round(ours_dk, 3),
        "baseline": f"cvxpy+Clarabel LMI μ bound for the {n_mu} μ evaluations on the "
                    f"{ngrid}-point D–K grid (μ steps only)",
        "baseline_s": round(base_dk, 3), "ratio": round(base_dk / ours_dk, 1),
        "iterations": len(r.history), "mu": round(r.mu, 4), "order": r.order,
        "goal_s": 60.0,
    }), flush=True)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeats", type=int, default=5)
    ap.add_argument("--baseline-repeats", type=int, default=1)
    ap.add_argument("--nfreq", type=int, default=500)
    ap.add_argument("--baseline-nfreq", type=int, default=500)
    ap.add_argument("--dk-repeats", type=int, default=1)
    ap.add_argument("--only-testrig", action="store_true")
    args = ap.parse_args()
    testrig_cases(args)
    if args.only_testrig:
        return

    from ambseal.robust.mu import mussv
    from ambseal.lti.freqresp import freqresp

    sys = rig_sized_system()
    w = np.logspace(np.log10(2 * np.pi * 1), np.log10(2 * np.pi * 2000), args.nfreq)
    Mw = freqresp(sys, w)
    cases = {
        "rep_complex2+full4x6": [(2, 0), (4, 6)],
        "2scalars+full4x6": [(1, 0), (1, 0), (4, 6)],
        "rep_real2+full4x6": [(-2, 0), (4, 6)],
    }
    nb = min(args.baseline_nfreq, args.nfreq)
    idx = np.linspace(0, args.nfreq - 1, nb).round().astype(int)
    for name, blocks in cases.items():
        times, res = [], None
        for _ in range(args.repeats):
            t0 = time.perf_counter()
            res = mussv(sys, blocks, w)
            times.append(time.perf_counter() - t0)
        ours = statistics.median(times)
        cblocks = [(abs(r), c) if c == 0 else (r, c) for r, c in blocks]  # baseline: complex D
        btimes, ub = [], None
        for _ in range(args.baseline_repeats):
            t0 = time.perf_counter()
            ub = np.array([lmi_upper(Mw[i], cblocks) for i in idx])
            btimes.append(time.perf_counter() - t0)
        base = statistics.median(btimes) * (args.nfreq / nb)
        rel = float(np.max(np.abs(res.upper[idx] / ub - 1)))
        print(json.dumps({
            "case": name, "ours_s": round(ours, 4),
            "baseline": "cvxpy+Clarabel LMI (complex D, bisection on β, per frequency)",
            "baseline_s": round(base, 3), "ratio": round(base / ours, 1),
            "nfreq": args.nfreq, "baseline_extrapolated": nb < args.nfreq,
            "max_rel_diff_upper": round(rel, 5),
            "min_lower_over_upper": round(float(np.min(res.lower / res.upper)), 4),
        }), flush=True)


if __name__ == "__main__":
    main()
