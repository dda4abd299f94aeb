"""Time the robust core on the published cases of its tests against python-control and SLICOT.

One JSON line per case on stdout: ``{"case", "source", "published", "ours", "peer",
"ours_s", "peer_s", "ratio"}`` — ``ours`` and ``peer`` the value each computes (γ_opt of
H∞ synthesis, an H∞ norm, a μ upper bound), the best CPU time of three runs of each in the
same process after one untimed run, ``ratio`` = ours/peer. Peers: python-control's
``hinfsyn``/``mixsyn`` (SLICOT SB10AD, its γ bisection from 1e100) for synthesis,
``control.linfnorm`` (SLICOT AB13DD) for norms, slycot's ``ab13md`` (SLICOT AB13MD) for μ.
The μ-synthesis cases (S&P's distillation column, Mackenroth's aircraft, the spring–mass
system) are timed against dkpy by ``bench_dk.py``.

Run from the repository root: ``PYTHONPATH=src python benchmarks/bench_published.py``.
"""

from __future__ import annotations

import json
import os
import sys
import time
import warnings
from pathlib import Path

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")
ROOT = Path(__file__).resolve().parents[1]


def _best(f, n: int = 3):
    f()
    times, out = [], None
    for _ in range(n):
        t0 = time.process_time()
        out = f()
        times.append(time.process_time() - t0)
    return out, min(times)


def _synthesis_cases(ct, np):
    s = ct.tf([1, 0], [1])
    g211 = 200 / (10 * s + 1) / (0.05 * s + 1) ** 2
    wp1 = (s / 1.5 + 10) / (s + 1e-3)
    wp2 = (s / 1.5 ** 0.5 + 10) ** 2 / (s + 1e-3) ** 2

    def wsp(wb, m=1.5, a=1e-4):
        return ct.ss((s / m + wb) / (s + wb * a))

    den = [0.2, 1.2, 1]
    g38 = ct.ss(ct.tf([[[1], [1]], [[2, 1], [2]]], [[den, den], [den, den]]))
    out = [("python-control testHinfsyn", "control/tests/robust_test.py", 0.0,
            ct.ss(-1, [[1, 1]], [[1], [1]], [[0, 1], [1, 0]]), 1, 1),
           ("SGC97 Example 7", "Scherer, Gahinet & Chilali 1997", 9.5081,
            ct.ss([[0.0, 10.0, 2.0], [-1.0, 1.0, 0.0], [0.0, 2.0, -5.0]],
                  [[1.0, 0.0], [0.0, 1.0], [1.0, 0.0]],
                  [[1.0, 0.0, 0.0], [0.0, 0.0, 0.0], [0.0, 1.0, 0.0]],
                  [[0.0, 0.0], [0.0, 1.0], [2.0, 0.0]]), 1, 1),
           ("Glover min ||KS||, a = 1", "Glover 1986 (closed form 2a)", 2.0,
            ct.ss([[1.0]], [[0.0, 1.0]], [[0.0], [1.0]], [[0.0, 1.0], [1.0, 0.0]]), 1, 1),
           ("S&P Ex. 2.11 design 1", "examples/robust_siso.py", None,
            ct.augw(g211, wp1, ct.tf(1, 1)), 1, 1),
           ("S&P Ex. 2.11 design 2", "examples/robust_siso.py", None,
            ct.augw(g211, wp2, ct.tf(1, 1)), 1, 1)]
    for k, (wb, pub) in enumerate((((0.25, 0.25), 2.80), ((0.25, 25.0), 2.92),
                                   ((25.0, 0.25), 6.73)), 1):
        wp = wsp(wb[0]).append(wsp(wb[1]))
        out.append((f"S&P Ex. 3.8 design {k}", "S&P 1st ed.; examples/robust_mimo.py", pub,
                    ct.augw(g38, wp, ct.ss([], [], [], np.eye(2))), 2, 2))
    from tests.robust.test_published_cases import ncf_plant, sb10dd_bilinear_plant

    out.append(("SB10DD example (z = (1+s)/(1−s))", "SLICOT examples", 111.294,
                sb10dd_bilinear_plant(), 2, 2))
    ncf = [([[1.0]], [[1.0]], [[1.0]]), ([[0.0, 1.0], [-1.0, -0.2]], [[0.0], [1.0]], [[1.0, 0.0]]),
           ([[0.0, 1.0, 0.0], [0.0, 0.0, 1.0], [1.0, -2.0, -1.0]], [[0, 0], [1, 0], [0, 1]],
            [[1, 0, 0], [0, 0, 1]])]
    for name, (A, B, C) in zip(("1/(s − 1)", "resonance", "MIMO 3 states"), ncf):
        A, B, C = (np.array(M, float) for M in (A, B, C))
        out.append((f"NCF robust stabilisation, {name}", "McFarlane & Glover 1990; ZDG ch. 18",
                    _ncf_closed_form(np, A, B, C), ncf_plant(A, B, C), C.shape[0], B.shape[1]))
    return out


def _ncf_closed_form(np, A, B, C):
    """√(1 + ρ(XZ)) from the control and filter Riccati equations (SciPy)."""
    from scipy.linalg import solve_continuous_are

    X = solve_continuous_are(A, B, C.T @ C, np.eye(B.shape[1]))
    Z = solve_continuous_are(A.T, C.T, B @ B.T, np.eye(C.shape[0]))
    return float(np.sqrt(1.0 + np.max(np.linalg.eigvals(X @ Z).real)))


def _norm_cases(ct, np):
    A = np.zeros((6, 6))
    for i, (k, c) in enumerate(((0.5, 2e-4), (1.0, 2e-5), (2.0, 2e-6))):
        A[2 * i, 2 * i + 1] = 1.0
        A[2 * i + 1, 2 * i], A[2 * i + 1, 2 * i + 1] = -k, -c
    ab13dd = ct.ss(A, [[1.0], [0.0], [1.0], [0.0], [1.0], [0.0]],
                   [[1.0, 0.0, 1.0, 0.0, 1.0, 0.0]], [[0.0]])
    F = np.array([[246.5, 242.5, 202.5, -197.5], [-252.5, -248.5, -207.5, 202.5],
                  [-302.5, -297.5, -248.5, 242.5], [-307.5, -302.5, -252.5, 246.5]])
    out = [("AB13DD example", "SLICOT examples", 0.5000000001e6, ab13dd),
           ("AB13FD example (1/β)", "SLICOT examples", 1 / 0.39196472317e-2,
            ct.ss(F, np.eye(4), np.eye(4), np.zeros((4, 4))))]
    for z in (0.05, 0.2, 0.5):
        out.append((f"2nd-order peak ζ = {z}", "textbook M_r = 1/(2ζ√(1−ζ²))",
                    1 / (2 * z * np.sqrt(1 - z * z)),
                    ct.ss(ct.tf([49.0], [1.0, 14 * z, 49.0]))))
    return out


def _mu_cases(np):
    from tests.robust.test_published_cases import rank_one_case

    z = [(-1, 6), (2, -3), (3, 8), (3, 8), (-5, -9), (-6, 2), (4, 2), (-2, 5), (-6, -7),
         (-4, 11), (8, -7), (12, -1), (5, -4), (-4, -8), (1, -3), (-6, 14), (2, -5), (4, 16)]
    out = [("AB13MD example", "SLICOT examples", 0.4174753408e2,
            np.array([complex(a, b) for a, b in z * 2]).reshape(6, 6),
            [(-1, 0), (-1, 0), (2, 2), (1, 1), (1, 1)])]
    for kinds in ("rrr", "ccc", "rrcc", "rrrrc"):
        M, blocks, mu = rank_one_case(kinds)
        out.append((f"rank-one μ {kinds}", "Young 1994 closed form", mu, M, blocks))
    rng = np.random.default_rng(3)
    M = rng.standard_normal((5, 5)) + 1j * rng.standard_normal((5, 5))
    out.append(("three full blocks", "Doyle 1982 (no gap)", None, M, [(1, 1), (2, 2), (2, 2)]))
    return out


def _ab13md(np, M, blocks):
    """slycot's AB13MD on MATLAB-style blocks: (−1, 0) real scalar, (k, k) complex full."""
    from slycot import ab13md

    nblock = np.array([abs(r) if c else 1 for r, c in blocks], dtype=np.int64)
    itype = np.array([1 if r < 0 else 2 for r, _ in blocks], dtype=np.int64)
    return float(ab13md(np.asarray(M, complex), nblock, itype)[0])


def main() -> None:
    sys.path.insert(0, str(ROOT / "src"))
    sys.path.insert(0, str(ROOT))
    warnings.simplefilter("ignore", FutureWarning)
    import control as ct
    import numpy as np

    from ambseal.robust import hinfnorm, hinfsyn, mussv

    rows = []
    for name, src, pub, P, nm, nc in _synthesis_cases(ct, np):
        ours, t1 = _best(lambda: hinfsyn(P, nm, nc).gamma_opt)
        peer, t2 = _best(lambda: float(ct.hinfsyn(P, nm, nc)[2]))
        rows.append((name, src, pub, ours, peer, t1, t2))
    for name, src, pub, G in _norm_cases(ct, np):
        ours, t1 = _best(lambda: hinfnorm(G)[0])
        peer, t2 = _best(lambda: float(ct.linfnorm(G)[0]))
        rows.append((name, src, pub, ours, peer, t1, t2))
    for name, src, pub, M, blocks in _mu_cases(np):
        ours, t1 = _best(lambda: float(mussv(M, blocks).upper))
        peer, t2 = _best(lambda: _ab13md(np, M, blocks))
        rows.append((name, src, pub, ours, peer, t1, t2))
    for name, src, pub, ours, peer, t1, t2 in rows:
        print(json.dumps({"case": name, "source": src, "published": pub, "ours": ours,
                          "peer": peer, "ours_s": round(t1, 5), "peer_s": round(t2, 5),
                          "ratio": round(t1 / t2, 3) if t2 > 0 else None}), flush=True)


if __name__ == "__main__":
    main()
