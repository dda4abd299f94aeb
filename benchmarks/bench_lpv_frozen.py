"""Time lpvsyn's comparison with the best frozen-point design (``frozen_check``, its default).

One JSON line per case on stdout: ``{"case", "ours_s", "baseline_s", "ratio", "kind",
"gamma", "check_gamma_max", "frozen_best_gamma"}`` — the CPU time of the synthesis with the
comparison (ours) and without it (baseline, ``frozen_check=False``) in the same run, after
one untimed run of each case, what
was delivered (``kind``: the LMIs' scheduled controller or the frozen-point design), the
LMI γ, the delivered controller's worst frozen γ on the check grid and the best
frozen-point design's.

Cases: the LTI family of ``tests/robust/test_robust_lpv.py`` (3 grid points, 11 table
values); the turboexpander's LPV on speed (:func:`ambseal.design.lpv_design.design_lpv`,
7-point vertex grid, 20–300 Hz, rigid-body design model) and on 10 equally spaced points
(5× denser table); the blower's LPV on speed from standstill to 600 Hz on its 24-state
design model (as ``ambseal run`` designs it there).

Run from the repository root: ``PYTHONPATH=src python benchmarks/bench_lpv_frozen.py``.
"""

from __future__ import annotations

import json
import os
import sys
import time
from pathlib import Path

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")
ROOT = Path(__file__).resolve().parents[1]


def _lti_family():
    import control as ct

    from ambseal.robust.lpv import lpvsyn

    mode = ct.ss([[0.0, 1.0], [-4.0, -0.2]], [[0.0], [1.0]], [[1.0, 0.0]], [[0.0]],
                 inputs="u", outputs="x", name="mode")
    We = ct.ss(ct.tf([0.5, 0.5], [1.0, 5e-4]), inputs="e", outputs="z_e", name="We")
    Wu = ct.ss([], [], [], [[0.1]], inputs="u", outputs="z_u", name="Wu")
    err = ct.summing_junction(inputs=["r", "-x"], output="e")
    P = ct.interconnect([mode, We, Wu, err], inplist=["r", "u"], outlist=["z_e", "z_u", "e"])
    return lambda check: lpvsyn([P] * 3, [1.0, 2.0, 3.0], 1, 1, frozen_check=check)


def _rig(name: str, **kw):
    from ambseal.config import load_rig
    from ambseal.design.lpv_design import design_lpv
    from ambseal.design.specs import design_spec

    cfg = load_rig(ROOT / "examples" / f"{name}.toml")
    if kw.pop("standstill", False):
        sp = design_spec(cfg)
        kw.update(speeds_hz=(0.0, max(sp.stability_speeds_hz)), states=sp.model_states,
                  spec=sp)
    return lambda check: design_lpv(cfg, frozen_gamma=False, allow_unstable=True,
                                    frozen_check=check, **kw)


def main() -> None:
    sys.path.insert(0, str(ROOT / "src"))
    cases = {"lti_family": _lti_family(),
             "turboexpander_vertex": _rig("turboexpander"),
             "turboexpander_10pt": _rig("turboexpander", n_grid=10),
             "blower_standstill_to_top": _rig("blower", standstill=True)}
    for case, run in cases.items():
        run(True)  # warm: imports, caches and compiled kernels out of the timings
        times = {}
        for check in (False, True):
            t0 = time.process_time()
            r = run(check)
            times[check] = time.process_time() - t0
        print(json.dumps({"case": case, "ours_s": round(times[True], 3),
                          "baseline_s": round(times[False], 3),
                          "ratio": round(times[True] / times[False], 3), "kind": r.kind,
                          "gamma": r.gamma, "check_gamma_max": float(max(r.check_gamma)),
                          "frozen_best_gamma": r.frozen_best_gamma}), flush=True)


if __name__ == "__main__":
    main()
