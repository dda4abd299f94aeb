"""Benchmark: ambseal's thread policy against the BLAS variables a user does not set.

Each case runs one command in a child process and prints one JSON line on stdout:

``design_hinf``
    ``ambseal design --method hinf --out <temporary folder>`` on the embedded rig.
``run``
    ``ambseal run --out <temporary folder>`` on the embedded rig (identification included).

in three environments:

``default``
    A user's environment: no BLAS variable set; ambseal's policy (one thread, `ambseal.threads`).
``inherit``
    The same with ``AMBSEAL_BLAS_THREADS=inherit``: the BLAS threads the library picks
    itself (as many as cores), which is what ambseal ran with before it had a policy.
``one_thread``
    The baseline: ``OPENBLAS_NUM_THREADS`` = ``OMP_NUM_THREADS`` = ``MKL_NUM_THREADS`` = 1.

each quiet and beside ``--hogs`` busy processes (pure-Python loops, default 1). A line reads
``{"case", "env", "load", "ours_s", "cpu_s", "baseline", "baseline_s", "ratio",
"returncode"}``: ``ours_s`` the child's wall time, ``cpu_s`` its user + system CPU time,
``baseline_s`` the wall time of ``one_thread`` under the same load and ``ratio``
``ours_s / baseline_s``. Every child starts after a warm-up run (numba's caches compiled).

Run from the repository root: ``python benchmarks/bench_threads.py [--jobs design_hinf,run]
[--hogs 1] [--repeat 1]``.
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import tempfile
import time
from contextlib import contextmanager
from pathlib import Path

JOBS = {"design_hinf": ["design", "--method", "hinf"], "run": ["run"]}
BLAS_VARS = ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS",
             "BLIS_NUM_THREADS", "VECLIB_MAXIMUM_THREADS", "NUMEXPR_NUM_THREADS",
             "OPENBLAS_CORETYPE", "OPENBLAS_L2_SIZE", "AMBSEAL_BLAS_THREADS")


def env_for(kind: str) -> dict[str, str]:
    """The child's environment: the caller's without any BLAS variable, then ``kind``'s."""
    env = {k: v for k, v in os.environ.items() if k not in BLAS_VARS}
    env["MPLBACKEND"] = "Agg"
    if kind == "inherit":
        env["AMBSEAL_BLAS_THREADS"] = "inherit"
    elif kind == "one_thread":
        env.update({v: "1" for v in BLAS_VARS[:3]})
    return env


def timed(job: str, kind: str) -> tuple[float, float, int]:
    """Wall time, user + system CPU time (s) and return code of one command."""
    with tempfile.TemporaryDirectory() as tmp:
        cmd = [sys.executable, "-m", "ambseal.cli", "-q", *JOBS[job], "--out",
               str(Path(tmp) / "out")]
        t0 = time.perf_counter()
        proc = subprocess.Popen(cmd, env=env_for(kind), stdout=subprocess.DEVNULL,
                                stderr=subprocess.PIPE, text=True)
        _, err = proc.communicate()
        wall = time.perf_counter() - t0
    if proc.returncode not in (0, 1):
        print(err, file=sys.stderr)
    return wall, _children_cpu_since(), proc.returncode


_cpu_mark = [0.0]


def _children_cpu_since() -> float:
    """CPU time (user + system, s) of the children reaped since the last call."""
    import resource

    r = resource.getrusage(resource.RUSAGE_CHILDREN)
    total = r.ru_utime + r.ru_stime
    out, _cpu_mark[0] = total - _cpu_mark[0], total
    return out


@contextmanager
def hogs(n: int):
    """``n`` busy processes (pure Python, no BLAS) for the duration."""
    procs = [subprocess.Popen([sys.executable, "-c", "while True: pass"]) for _ in range(n)]
    try:
        yield
    finally:
        for p in procs:
            p.kill()
            p.wait()
        _children_cpu_since()  # the hogs' CPU is not a case's


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--jobs", default="design_hinf,run",
                    help="comma-separated cases: " + ", ".join(JOBS))
    ap.add_argument("--hogs", type=int, default=1, help="busy processes beside the loaded runs")
    ap.add_argument("--repeat", type=int, default=1, help="runs per case (median reported)")
    a = ap.parse_args(argv)
    jobs = [j for j in a.jobs.split(",") if j]
    for j in jobs:
        if j not in JOBS:
            ap.error(f"--jobs: unknown case {j!r}; expected some of {', '.join(JOBS)}")
    for job in jobs:
        print(f"warm-up: {job}", file=sys.stderr)
        timed(job, "one_thread")
        for load in ("quiet", "loaded"):
            rows = {}
            for kind in ("one_thread", "default", "inherit"):
                runs = []
                for _ in range(a.repeat):
                    if load == "loaded":
                        with hogs(a.hogs):
                            _children_cpu_since()
                            runs.append(timed(job, kind))
                    else:
                        _children_cpu_since()
                        runs.append(timed(job, kind))
                runs.sort()
                rows[kind] = runs[len(runs) // 2]
            base = rows["one_thread"][0]
            for kind, (wall, cpu, rc) in rows.items():
                print(json.dumps({"case": job, "env": kind, "load": load,
                                  "hogs": a.hogs if load == "loaded" else 0,
                                  "ours_s": round(wall, 2), "cpu_s": round(cpu, 2),
                                  "baseline": "one_thread", "baseline_s": round(base, 2),
                                  "ratio": round(wall / base, 3), "returncode": rc}),
                      flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
