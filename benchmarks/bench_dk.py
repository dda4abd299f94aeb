"""Benchmark: ambseal's μ-synthesis with its defaults against published results, dkpy and an
independent μ check (SLICOT AB13MD).

Run from the repository root::

    PYTHONPATH=src python benchmarks/bench_dk.py [--only CASE] [--skip-dkpy]

One JSON line per case (``case, ours_s, baseline, baseline_s, ratio`` and the μ values):

``skogestad2005_distillation_defaults``
    The robust-performance distillation problem of Skogestad & Postlethwaite (2005),
    §8.12.4, Table 8.1 — G = 1/(75s+1)·[87.8 −86.4; 108.2 −109.6], W_I = (s+0.2)/(0.5s+1)·I,
    W_P = 0.5(10s+1)/(10s+1e-5)·I; blocks [(1, 1), (1, 1), (2, 2)] — designed by
    ``musyn(P, blocks, 2, 2)`` with every default (its own frequency grid, D search). ``mu_ab13md_301``: the peak of SLICOT AB13MD's μ upper bound (slycot, on
    python-control's frequency response of ``P.lft(K)``) on 301 points log-spaced over
    10⁻³…10³ rad/s, an independent check of the controller; ``mu_reported``: the μ musyn
    states (its upper bound re-checked around the peaks); ``rel_reported_to_ab13md``.
    Published: S&P's D–K after three iterations 1.0189 (Table 8.2 script, MATLAB μ toolbox)
    and their μ-optimal controller 0.9737 (eq. 8.144); MATLAB's ``musyn`` 1.0207 and
    dkpy 1.036 as measured by the project (not rerun here).
``skogestad2005_distillation_61``
    The same problem on the published 61-point grid 10⁻³…10³ rad/s, like with like against
    the published values (every μ the peak over that grid; ``mu_published_D_ours``: our
    K-step with the published d(s) of eq. 8.144, a check of the set-up). Baseline: dkpy
    (``DkIterFixedOrder``: SLICOT H∞, the cvxpy LMI μ bound, order-4 SLICOT D fits, three
    iterations), its controller judged by our bound (``mu_baseline_our_bound``) and by its
    own (``mu_baseline_own``).
``mackenroth2004_aircraft_lateral``
    The lateral dynamics of an aircraft of Mackenroth (2004), §14.1: airframe (β, p, φ, r),
    second-order actuators (40 rad/s, ζ = 0.7), input multiplicative uncertainty
    (0.25s + 0.05)/(0.125s + 1), roll-angle tracking with wind gusts and sensor noise;
    blocks [(2, 2), (7, 8)], 100 points log-spaced over 0.01…100 Hz. Published: μ 0.9824
    by dkpy's documented example of this problem (``DkIterListOrder``, order-4 fits, LMI
    H∞ and μ with MOSEK). ``mu_ab13md_301``: AB13MD on 301 points over the same band (the
    7×8 performance block padded to 8×8 with a zero column, which leaves μ unchanged).
    Baseline: dkpy as above (without MOSEK: SLICOT H∞, LMI μ by Clarabel).
``barros2005_spring_mass_mixed``
    Two masses, the coupling spring k1 ∈ [1.2, 2.8] real and 0.06 s of actuator delay as a
    complex 1×1 block with weight 2.6s/(s + 40) (Barros, Fekri & Athans 2005, as in MATLAB's
    example "Control of a Spring-Mass-Damper System Using Mixed-Mu Synthesis"); blocks
    [(-1, 0), (1, 1), (2, 2)]. ``musyn_dgk`` with every default (its own grid). Published
    (MATLAB's example text): complex μ-synthesis ends above 1, mixed μ-synthesis below 1;
    the worst-case gain (``wcgain``) of its mixed-μ controller 0.88, of its complex one 2.2.
    ``mu_ab13md_701``: SLICOT AB13MD's mixed bound (real, complex, complex blocks) on 701
    points over 10⁻³…10⁵ rad/s; ``worst_gain``: the performance σ̄ maximised by brute force
    over k1 (21 values) and the delay block (24 phases on its unit circle) on those points,
    for ours and for complex D–K's controller.

Times: ``ours_s`` is wall time, ``ours_cpu_s`` the process's CPU time (one BLAS thread).
"""

from __future__ import annotations

import argparse
import json
import os
import sys
import time
from pathlib import Path

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")
os.environ.setdefault("OMP_NUM_THREADS", "1")
os.environ.setdefault("MKL_NUM_THREADS", "1")

import control as ct
import numpy as np

# the spring–mass plant is the tests' (tests/spring_mass.py), imported from the repository root
sys.path.insert(0, str(Path(__file__).resolve().parents[1]))
from tests.spring_mass import spring_mass_plant  # noqa: E402


# --------------------------------------------------------------------------- plants
def distillation_rp_plant():
    """S&P §8.12.4 (inputs [w_Δ(2), w(2), u(2)], outputs [z_Δ(2), z(2), v(2)])."""
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


def aircraft_lateral_plant():
    """Mackenroth (2004) §14.1: inputs [w_Δ(2), φ_ref, noise(4), gusts(2), ζ_c, ξ_c] (11),
    outputs [z_Δ(2), performance(4), effort(4), φ_ref, φ, β, p, r measured] (15)."""
    A = np.array([[-0.0869, 0.0, 0.039, -1.0], [-4.424, -1.184, 0.0, 0.335],
                  [0.0, 1.0, 0.0, 0.0], [2.148, -0.021, 0.0, -0.228]])
    Bw = np.array([[0.0869, 0.0], [4.424, 1.184], [0.0, -1.0], [-2.148, 0.021]])
    Bu = np.array([[0.0223, 0.0], [0.547, 2.12], [0.0, 0.0], [-1.169, 0.065]])
    air = ct.ss(A, np.hstack([Bw, Bu]), np.eye(4), np.zeros((4, 4)),
                inputs=["beta_w", "p_w", "zeta", "xi"], outputs=["beta", "p", "phi", "r"],
                name="air")
    act1 = ct.ss([[0.0, 1.0], [-1600.0, -56.0]], [[0.0], [1600.0]], np.eye(2),
                 np.zeros((2, 1)))
    act = ct.ss(ct.append(act1, act1), inputs=["zeta_a", "xi_a"],
                outputs=["zeta", "zeta_rate", "xi", "xi_rate"], name="act")
    w_angle = ct.ss(ct.tf([1.0, 1.5], [1.5, 0.015]))
    w_rate = ct.ss(ct.tf([1.0, 1.5], [10.0, 20.0]))
    perf = ct.ss(ct.append(w_angle, w_angle, w_rate, w_rate),
                 inputs=["e_phi", "beta", "p", "r"], outputs=[f"zp{i}" for i in range(4)],
                 name="perf")
    effort = ct.ss([], [], [], np.diag([1 / 20, 1 / 20, 1 / 60, 1 / 60]),
                   inputs=["zeta_c", "xi_c", "zeta_rate", "xi_rate"],
                   outputs=[f"zu{i}" for i in range(4)], name="effort")
    ref = ct.ss(ct.tf([2.25], [1.0, 2.1, 2.25]), inputs=["r_n"], outputs=["phi_ref"],
                name="ref")
    wn = ct.ss(0.0005 * ct.tf([50.0, 1.0], [1.0, 1.0]))
    noise = ct.ss(ct.append(wn, wn, wn, wn), inputs=[f"n_n{i}" for i in range(4)],
                  outputs=[f"n{i}" for i in range(4)], name="noise")
    wu = ct.ss(ct.tf([0.25, 0.05], [0.125, 1.0]))
    unc = ct.ss(ct.append(wu, wu), inputs=["zeta_c", "xi_c"], outputs=["zd0", "zd1"],
                name="unc")
    parts = [air, act, perf, effort, ref, noise, unc,
             ct.summing_junction(inputs=["zeta_c", "wd0"], output="zeta_a"),
             ct.summing_junction(inputs=["xi_c", "wd1"], output="xi_a"),
             ct.summing_junction(inputs=["phi_ref", "-phi"], output="e_phi"),
             ct.ss([], [], [], [[1.0]], inputs=["beta_wn"], outputs=["beta_w"]),
             ct.ss([], [], [], [[1.0]], inputs=["p_wn"], outputs=["p_w"]),
             ct.ss([], [], [], [[1.0]], inputs=["r_in"], outputs=["r_n"])]
    meas = []
    for i, y in enumerate(["phi", "beta", "p", "r"]):
        parts.append(ct.summing_junction(inputs=[y, f"n{i}"], output=f"m_{y}"))
        meas.append(f"m_{y}")
    P = ct.interconnect(parts, inplist=["wd0", "wd1", "r_in", "n_n0", "n_n1", "n_n2", "n_n3",
                                        "beta_wn", "p_wn", "zeta_c", "xi_c"],
                        outlist=["zd0", "zd1"] + [f"zp{i}" for i in range(4)]
                        + [f"zu{i}" for i in range(4)] + ["r_n"] + meas)
    return ct.minreal(P, verbose=False)


# --------------------------------------------------------------------------- checks
def mu_ab13md(cl, omega, sizes, pad_cols: int = 0) -> float:
    """Peak over ``omega`` of SLICOT AB13MD's μ upper bound for square complex blocks of
    ``sizes`` on python-control's frequency response of ``cl`` (``pad_cols`` zero columns
    appended to square a non-square last block; μ is unchanged)."""
    from slycot import ab13md

    H = np.moveaxis(ct.frequency_response(cl, omega, squeeze=False).complex, 2, 0)
    if pad_cols:
        H = np.concatenate([H, np.zeros(H.shape[:2] + (pad_cols,), complex)], axis=2)
    nb = np.array(sizes)
    return max(ab13md(np.asfortranarray(Hk), nb, np.full(nb.size, 2))[0] for Hk in H)


def _published_optimum(P, blocks, w) -> float:
    """Peak μ on ``w`` of our H∞ design on ``D P D⁻¹`` with S&P's d(s) (eq. 8.144)."""
    from ambseal.robust._dscale import _scaled_plant
    from ambseal.robust.hinf import hinfsyn, lft_lower
    from ambseal.robust.mu import mussv

    d = ct.tf(2e-3 * np.poly([-1000.0, -0.25, -0.054]),
              np.real(np.poly([-0.013, -0.67 + 0.56j, -0.67 - 0.56j])))
    K = hinfsyn(_scaled_plant(P, blocks, [d, d], 2, 2), 2, 2, backoff=1.001).K
    return float(np.max(mussv(lft_lower(P, K, 2, 2), blocks, w).upper))


def _timed(fn):
    t0, c0 = time.perf_counter(), time.process_time()
    out = fn()
    return out, round(time.perf_counter() - t0, 2), round(time.process_time() - c0, 2)


def _dkpy(P, nmeas, ncon, w, blocks, iterations=3, order=4):
    """dkpy's fixed-order D–K (SLICOT H∞, LMI μ by bisection, SLICOT D fits)."""
    import dkpy

    dk = dkpy.DkIterFixedOrder(
        controller_synthesis=dkpy.HinfSynSlicot(),
        structured_singular_value=dkpy.SsvLmiBisection(n_jobs=1),
        d_scale_fit=dkpy.DScaleFitSlicot(), n_iterations=iterations, fit_order=order)
    (K, _, mu, _, _), wall, _ = _timed(lambda: dk.synthesize(
        P, nmeas, ncon, w, [dkpy.ComplexFullBlock(*b) for b in blocks]))
    return ct.ss(K), float(mu), wall


def _history(r):
    return [[h.get("step", "D-K"), round(h["mu"], 4)] for h in r.history]


# --------------------------------------------------------------------------- cases
def case_distillation_defaults(skip_dkpy: bool) -> dict:
    from ambseal.robust.dk import musyn

    P, blocks = distillation_rp_plant(), [(1, 1), (1, 1), (2, 2)]
    r, wall, cpu = _timed(lambda: musyn(P, blocks, 2, 2))
    w301 = np.logspace(-3, 3, 301)
    check = mu_ab13md(P.lft(r.K, nu=2, ny=2), w301, [1, 1, 2])
    return {"case": "skogestad2005_distillation_defaults", "ours_s": wall, "ours_cpu_s": cpu,
            "baseline": "published: S&P D-K 1.0189 (3 iterations), mu-optimal 0.9737; "
                        "MATLAB musyn 1.0207 and dkpy 1.036 (project measurements)",
            "baseline_s": None, "ratio": None,
            "mu_ab13md_301": round(float(check), 4), "mu_reported": round(r.mu, 4),
            "rel_reported_to_ab13md": round(r.mu / check - 1, 5),
            "mu_check": r.check, "order": r.order, "history": _history(r)}


def case_distillation_61(skip_dkpy: bool) -> dict:
    from ambseal.robust.dk import musyn
    from ambseal.robust.hinf import lft_lower
    from ambseal.robust.mu import mussv

    P, blocks = distillation_rp_plant(), [(1, 1), (1, 1), (2, 2)]
    w = np.logspace(-3, 3, 61)
    r, wall, cpu = _timed(lambda: musyn(P, blocks, 2, 2, w))
    out = {"case": "skogestad2005_distillation_61", "ours_s": wall, "ours_cpu_s": cpu,
           "mu_ours_grid": round(r.mu_grid, 4), "mu_reported": round(r.mu, 4),
           "mu_published": 0.9737, "mu_published_dk": [1.1818, 1.0238, 1.0189],
           "mu_published_D_ours": round(_published_optimum(P, blocks, w), 4),
           "order": r.order, "history": _history(r),
           "baseline": None, "baseline_s": None, "ratio": None}
    if not skip_dkpy:
        K, mu_own, base_s = _dkpy(P, 2, 2, w, [(1, 1), (1, 1), (2, 2)])
        out.update(baseline="dkpy 0.1.9 (DkIterFixedOrder, 3 iterations, order 4)",
                   baseline_s=base_s, ratio=round(base_s / wall, 2),
                   mu_baseline_own=round(mu_own, 4),
                   mu_baseline_our_bound=round(float(np.max(
                       mussv(lft_lower(P, K, 2, 2), blocks, w).upper)), 4))
    return out


def case_aircraft(skip_dkpy: bool) -> dict:
    from ambseal.robust.dk import musyn
    from ambseal.robust.hinf import lft_lower
    from ambseal.robust.mu import mussv

    P, blocks = aircraft_lateral_plant(), [(2, 2), (7, 8)]
    w = 2 * np.pi * np.logspace(-2, 2, 100)
    r, wall, cpu = _timed(lambda: musyn(P, blocks, 5, 2, w))
    w301 = 2 * np.pi * np.logspace(-2, 2, 301)
    check = mu_ab13md(P.lft(r.K, nu=2, ny=5), w301, [2, 8], pad_cols=1)
    out = {"case": "mackenroth2004_aircraft_lateral", "ours_s": wall, "ours_cpu_s": cpu,
           "mu_reported": round(r.mu, 4), "mu_ours_grid": round(r.mu_grid, 4),
           "mu_ab13md_301": round(float(check), 4), "mu_published": 0.9824,
           "published": "dkpy documentation, example 'D-K iteration for non-square "
                        "perturbation' (Mackenroth 2004 §14.1), order-4 fits, MOSEK",
           "order": r.order, "history": _history(r),
           "baseline": None, "baseline_s": None, "ratio": None}
    if not skip_dkpy:
        K, mu_own, base_s = _dkpy(P, 5, 2, w, [(2, 2), (7, 8)])
        out.update(baseline="dkpy 0.1.9 (DkIterFixedOrder, 3 iterations, order 4, "
                            "SLICOT H-inf, LMI mu by Clarabel)",
                   baseline_s=base_s, ratio=round(base_s / wall, 2),
                   mu_baseline_own=round(mu_own, 4),
                   mu_baseline_our_bound=round(float(np.max(
                       mussv(lft_lower(P, K, 5, 2), blocks, w).upper)), 4))
    return out


def _worst_gain(cl, omega, n_real=21, n_phase=24) -> float:
    """Largest σ̄ of the performance channels of ``cl`` (inputs/outputs [Δ(2), perf(2)])
    over the real δ₁ ∈ [−1, 1] and the complex |δ₂| = 1 on ``omega``."""
    H = np.moveaxis(ct.frequency_response(cl, omega, squeeze=False).complex, 2, 0)
    M11, M12, M21, M22 = H[:, :2, :2], H[:, :2, 2:], H[:, 2:, :2], H[:, 2:, 2:]
    worst = 0.0
    for d1 in np.linspace(-1.0, 1.0, n_real):
        for ph in np.linspace(0.0, 2 * np.pi, n_phase, endpoint=False):
            D = np.diag([d1, np.exp(1j * ph)])
            perf = M22 + M21 @ D @ np.linalg.solve(np.eye(2) - M11 @ D, M12)
            worst = max(worst, float(np.max(np.linalg.svd(perf, compute_uv=False)[:, 0])))
    return worst


def case_spring_mass(skip_dkpy: bool) -> dict:
    from slycot import ab13md

    from ambseal.robust.dgk import musyn_dgk

    P = spring_mass_plant()
    r, wall, cpu = _timed(lambda: musyn_dgk(P, [(-1, 0), (1, 1), (2, 2)], 1, 1))
    w701 = np.logspace(-3, 5, 701)
    cl = P.lft(r.K, nu=1, ny=1)
    H = np.moveaxis(ct.frequency_response(cl, w701, squeeze=False).complex, 2, 0)
    check = max(ab13md(np.asfortranarray(Hk), np.array([1, 1, 2]), np.array([1, 2, 2]))[0]
                for Hk in H)
    complex_steps = [h for h in r.history if h.get("step", "D-K") in ("D-K", "D search")]
    K_dk = r.alternatives[0]["K"] if r.alternatives else r.K
    return {"case": "barros2005_spring_mass_mixed", "ours_s": wall, "ours_cpu_s": cpu,
            "mu_reported": round(r.mu, 4), "mu_ab13md_701": round(float(check), 4),
            "mu_complex_dk": round(min(h["mu"] for h in complex_steps), 4),
            "worst_gain": round(_worst_gain(cl, w701), 4),
            "worst_gain_complex_dk": round(_worst_gain(P.lft(K_dk, nu=1, ny=1), w701), 4),
            "published": "MATLAB example: complex mu > 1, mixed mu < 1; wcgain 0.88 (mixed "
                         "controller), 2.2 (complex)",
            "order": r.order, "history": _history(r),
            "baseline": None, "baseline_s": None, "ratio": None}


CASES = {"distillation_defaults": case_distillation_defaults,
         "distillation_61": case_distillation_61,
         "aircraft": case_aircraft,
         "spring_mass": case_spring_mass}


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--only", choices=sorted(CASES), action="append")
    ap.add_argument("--skip-dkpy", action="store_true")
    args = ap.parse_args()
    for name in args.only or list(CASES):
        print(json.dumps(CASES[name](args.skip_dkpy)), flush=True)


if __name__ == "__main__":
    main()
