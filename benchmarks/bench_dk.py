"""Benchmark: ambseal's D–K iteration against dkpy and published results on a textbook problem.

Run from the repository root::

    PYTHONPATH=src python benchmarks/bench_dk.py [--max-iter 8] [--search 600] [--skip-dkpy]

The problem: robust performance of the distillation column with input uncertainty of
Skogestad & Postlethwaite (2005), §8.12.4, Table 8.1 — G = 1/(75s+1)·[87.8 −86.4;
108.2 −109.6], W_I = (s+0.2)/(0.5s+1)·I, W_P = 0.5(10s+1)/(10s+1e-5)·I; blocks
[(1, 1), (1, 1), (2, 2)] (two input-uncertainty scalars and the performance block), grid
10⁻³ … 10³ rad/s, 61 points. Published, from the book's own MATLAB script (Table 8.2, μ
toolbox: ``hinfsyn`` with γ tolerance 0.01 between 0.9 and 1.05·γ_prev, D scales fitted by
``musynflp`` at order 4): D–K peak μ 1.1818, 1.0238, 1.0189 after iterations 1–3; and the
μ-optimal controller μ = 0.9737 (eq. 8.144), an H∞ design on ``D P D⁻¹`` with the given
third-order d(s) = 2·10⁻³ (s+1000)(s+0.25)(s+0.054)/((s+0.013)(s²+1.34s+0.7625)) — a
D found outside D–K. The goal (issue 11): within 2 % of that optimum.

Ours: ``musyn(order="auto", backoff=1.001, rtol=2e-3, search=…)``: D–K (D scales fitted
with automatic order weighted near the μ peak, K-step within 0.1 % of γ_opt) until it
stalls, then the direct search over the D-fit parameters for the smallest γ_opt of
``D P D⁻¹``. ``mu_published_D_ours``: our K-step and μ bound with the published d(s), a
check of the problem set-up against the published 0.9737. Baseline: dkpy
(``DkIterFixedOrder`` with SLICOT H∞ synthesis, the LMI μ bound by bisection through cvxpy
and SLICOT D fits of order 4, three iterations: the configuration of dkpy's first example
that runs without MOSEK). Both final controllers are judged by the same μ upper bound
(ours, on the same grid): ``mu_baseline_our_bound`` is our bound of dkpy's controller, to be
compared with ``mu_baseline_own`` (dkpy's LMI bound on python-control's response; they agree
to 1e-5 since ``ambseal.lti.freqresp`` falls back to dense solves on this ill-conditioned loop
— before, its fast forms gave 3.2e6 and then 8.2 there). All μ values are peaks over the
same 61-point grid as the published ones (no refinement between grid points): like is
compared with like. One JSON line.
"""

from __future__ import annotations

import argparse
import json
import time

import numpy as np


def distillation_rp_plant():
    """Generalised plant (inputs [w_Δ(2), w(2), u(2)], outputs [z_Δ(2), z(2), v(2)])."""
    import control as ct

    g = ct.tf([1.0], [75.0, 1.0])
    G0 = np.array([[87.8, -86.4], [108.2, -109.6]])
    G = ct.ss(ct.tf([[list(g.num[0][0] * G0[i, j]) for j in range(2)] for i in range(2)],
                    [[list(g.den[0][0]) for _ in range(2)] for _ in range(2)]),
              inputs=["up0", "up1"], outputs=["yp0", "yp1"], name="G")
    wp = ct.tf([5.0, 0.5], [10.0, 1e-5])
    Wp = ct.ss(ct.tf([[wp.num[0][0], [0.0]], [[0.0], wp.num[0][0]]],
                     [[wp.den[0][0], [1.0]], [[1.0], wp.den[0][0]]]),
               inputs=["e0", "e1"], outputs=["z0", "z1"], name="Wp")
    wi = ct.tf([1.0, 0.2], [0.5, 1.0])
    Wi = ct.ss(ct.tf([[wi.num[0][0], [0.0]], [[0.0], wi.num[0][0]]],
                     [[wi.den[0][0], [1.0]], [[1.0], wi.den[0][0]]]),
               inputs=["u0", "u1"], outputs=["zd0", "zd1"], name="Wi")
    parts = [G, Wp, Wi]
    for k in range(2):
        parts.append(ct.summing_junction(inputs=[f"u{k}", f"wd{k}"], output=f"up{k}",
                                         name=f"sa{k}"))
        parts.append(ct.summing_junction(inputs=[f"yp{k}", f"w{k}"], output=f"e{k}",
                                         name=f"sb{k}"))
        parts.append(ct.ss([], [], [], [[-1.0]], inputs=[f"e{k}"], outputs=[f"v{k}"],
                           name=f"neg{k}"))
    return ct.interconnect(parts, inplist=["wd0", "wd1", "w0", "w1", "u0", "u1"],
                           outlist=["zd0", "zd1", "z0", "z1", "v0", "v1"], name="P")


def _published_optimum(P, blocks, w) -> float:
    """Peak μ on ``w`` of our H∞ design on ``D P D⁻¹`` with S&P's d(s) (eq. 8.144)."""
    import control as ct

    from ambseal.robust.dk import _scaled_plant
    from ambseal.robust.hinf import hinfsyn, lft_lower
    from ambseal.robust.mu import mussv

    d = ct.tf(2e-3 * np.poly([-1000.0, -0.25, -0.054]), np.real(np.poly([-0.013, -0.67 + 0.56j,
                                                                         -0.67 - 0.56j])))
    K = hinfsyn(_scaled_plant(P, blocks, [d, d], 2, 2), 2, 2, backoff=1.001).K
    return float(np.max(mussv(lft_lower(P, K, 2, 2), blocks, w).upper))


def main() -> None:
    import control as ct

    from ambseal.robust.dk import musyn
    from ambseal.robust.hinf import lft_lower
    from ambseal.robust.mu import mussv

    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--max-iter", type=int, default=8)
    ap.add_argument("--search", type=int, default=600,
                    help="γ evaluations of the D search after D–K (0: plain D–K)")
    ap.add_argument("--skip-dkpy", action="store_true")
    args = ap.parse_args()
    P = distillation_rp_plant()
    blocks = [(1, 1), (1, 1), (2, 2)]
    w = np.logspace(-3, 3, 61)
    t0 = time.perf_counter()
    r = musyn(P, blocks, 2, 2, w, order="auto", backoff=1.001, rtol=2e-3,
              max_iter=args.max_iter, search=args.search)
    ours_s = time.perf_counter() - t0
    dk_only = [h["mu"] for h in r.history if h.get("step") != "D search"]
    out = {"case": "skogestad2005_distillation_rp", "ours_s": round(ours_s, 2),
           "mu_ours": round(r.mu, 4), "mu_ours_dk_only": round(min(dk_only), 4),
           "iterations_ours": len(dk_only), "search_evaluations": args.search,
           "order_ours": r.order, "mu_published": 0.9737,
           "mu_published_dk": [1.1818, 1.0238, 1.0189],
           "mu_published_D_ours": round(_published_optimum(P, blocks, w), 4),
           "published": "Skogestad & Postlethwaite (2005) §8.12.4, Table 8.2 and eq. 8.144, "
                        "MATLAB μ toolbox"}
    if not args.skip_dkpy:
        import dkpy

        dk = dkpy.DkIterFixedOrder(
            controller_synthesis=dkpy.HinfSynSlicot(),
            structured_singular_value=dkpy.SsvLmiBisection(n_jobs=1),
            d_scale_fit=dkpy.DScaleFitSlicot(), n_iterations=3, fit_order=4)
        t0 = time.perf_counter()
        K, _, mu_d, _, _ = dk.synthesize(P, 2, 2, w, [dkpy.ComplexFullBlock(1, 1),
                                                     dkpy.ComplexFullBlock(1, 1),
                                                     dkpy.ComplexFullBlock(2, 2)])
        base_s = time.perf_counter() - t0
        cl = lft_lower(P, ct.ss(K), 2, 2)
        out.update({"baseline": "dkpy 0.1.9 (DkIterFixedOrder, 3 iterations, order 4)",
                    "baseline_s": round(base_s, 2), "ratio": round(base_s / ours_s, 2),
                    "mu_baseline_own": round(float(mu_d), 4),
                    "mu_baseline_our_bound": round(float(np.max(mussv(cl, blocks, w).upper)), 4)})
    out["rel_to_published"] = round(r.mu / 0.9737 - 1, 4)
    print(json.dumps(out), flush=True)


if __name__ == "__main__":
    main()
