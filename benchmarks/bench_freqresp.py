"""Benchmark: the judged frequency response of a full-order plant, modal vs Hessenberg (issue 9).

One JSON line per example rig on stdout: ``{"case", "ours_s", "baseline", "baseline_s",
"ratio", "states", "cond_v_balanced", "cond_v_unbalanced", "modal_form",
"max_rel_diff"}`` — the CPU time of :func:`ambseal.lti.freqresp.freqresp_at`
(``method="auto"``: the modal form of A, or of the balanced A when only that one's
eigenvector matrix is well conditioned, checked at three probes) against
``method="hessenberg"`` (the Hessenberg reduction and SLICOT TB05AD per point, the
fallback that the unbalanced modal form's cond V > 1e8 forced on the blower), on the
full-order plant of the rig's nominal operating point (currents and the judgement's force
inputs) over its judgement grid (``judge_settings(design_spec(cfg)).freq_hz``), each from a cold cache,
medians of 3. ``modal_form``: ``"plain"`` (cond V ≤ 1e8 unbalanced), ``"balanced"`` (only
after balancing) or null.
``max_rel_diff``: largest |ΔH| over max |H| per frequency.

Run from the repository root: ``PYTHONPATH=src python benchmarks/bench_freqresp.py``.
"""

from __future__ import annotations

import json
import os
import statistics
import sys
import time
from pathlib import Path

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")
ROOT = Path(__file__).resolve().parents[1]


def _timed(fn, repeats: int = 3):
    from ambseal.lti import freqresp as F

    times, out = [], None
    for _ in range(repeats):
        F._MODAL._kept.clear()
        F._BALANCED._kept.clear()
        F._HESSENBERG._kept.clear()
        t0 = time.process_time()
        out = fn()
        times.append(time.process_time() - t0)
    return statistics.median(times), out


def main() -> None:
    sys.path.insert(0, str(ROOT / "src"))
    import numpy as np

    from ambseal.analysis.judge import judge_settings
    from ambseal.design.specs import design_spec
    from ambseal.config import load_rig
    from ambseal.lti import freqresp as F
    from ambseal.lti.freqresp import freqresp_at
    from ambseal.model.rig import build_plant

    for rig in ("blower", "turboexpander", "pump", "testrig"):
        cfg = load_rig(ROOT / "examples" / f"{rig}.toml")
        s = judge_settings(design_spec(cfg))
        P = build_plant(cfg, pressure_bar=cfg.operating.pressure_bar,
                        speed_rpm=cfg.operating.speed_rpm,
                        force_positions=tuple(s.force_positions_m)).to_statespace()
        A, B, C, D = (np.asarray(getattr(P, m), float) for m in "ABCD")
        pts = 2j * np.pi * np.logspace(np.log10(s.freq_hz[0]), np.log10(s.freq_hz[1]),
                                       int(s.freq_hz[2]))
        ours_s, H = _timed(lambda: freqresp_at((A, B, C, D), pts))
        base_s, Hh = _timed(lambda: freqresp_at((A, B, C, D), pts, method="hessenberg"))
        _, cond_u, Bm, _ = F._modal_form(A, B, C, 1e8)
        _, cond_b, Bb, _ = F._modal_form(A, B, C, 1e8, balance=True)
        err = np.max(np.abs(H - Hh), axis=(1, 2)) / np.max(np.abs(Hh), axis=(1, 2))
        print(json.dumps({"case": f"judge_grid_{rig}", "ours_s": round(ours_s, 4),
                          "baseline": "hessenberg (TB05AD)", "baseline_s": round(base_s, 4),
                          "ratio": round(ours_s / base_s, 4), "states": int(A.shape[0]),
                          "points": int(pts.size), "cond_v_balanced": float(cond_b),
                          "cond_v_unbalanced": float(cond_u),
                          "modal_form": ("plain" if Bm is not None else
                                         "balanced" if Bb is not None else None),
                          "max_rel_diff": float(np.max(err))}), flush=True)


if __name__ == "__main__":
    main()
