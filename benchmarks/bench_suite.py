"""Benchmark: the goals of the main job and the test suite — ``ambseal run`` under 30 s
(30 s CPU warm, 45 s on its first run), ``pytest`` under 5 min.

Cases (one JSON line each on stdout; progress and the children's output go to stderr):

``ambseal_run``
    The main job, ``ambseal run [RIG] --out <temporary folder>`` (identification
    included), on the embedded test rig or on ``--rig PATH``. Goal 30 s.
``ambseal_run_flexible``
    With ``--no-identify``: ``ambseal run RIG --no-identify`` on a flexible rotor of 50–60
    elements (e.g. ``--rig examples/b2b_compressor.toml``). Goal 60 s (CPU too).
``pytest``
    The test suite, ``python -m pytest -q -p no:cacheprovider [ARGS]`` from the
    repository root (``--pytest-args`` replaces the default run: the suite without the
    tests marked ``slow`` or ``heavy``). Goal 300 s.

Each is a child process (wall time, interpreter start and imports included) with one BLAS
thread (``OPENBLAS_NUM_THREADS`` = ``OMP_NUM_THREADS`` = ``MKL_NUM_THREADS`` = 1) and
``MPLBACKEND=Agg``; the goals are for a 2-core machine. A line reads
``{"case", "ours_s", "goal_s", "ratio" (ours/goal), "meets_goal", "returncode", "cpu_s",
...}`` (``cpu_s``: the child's user + system CPU); a case whose child fails does not meet
its goal.

``--env default`` runs the children as a user's shell does: no BLAS variable set
(ambseal's own thread policy, :mod:`ambseal.threads`). ``--cold`` gives the main job an
empty numba cache (``NUMBA_CACHE_DIR``), as on the first run after an install. The main
job's CPU goals: 30 s warm, 45 s cold (``cpu_goal_s``, ``meets_cpu_goal``). Beside the main
job, a fixed peer workload (``_REFERENCE``: python-control's ``hinfsyn`` on a 3-state
problem, the best of five batches of 20 calls) gives the machine's speed,
``reference_cpu_s`` (the mean of one before and one after the run: a shared machine's
speed drifts), and the run's CPU in its units, ``cpu_per_reference``: the same code
measures about the same ratio on a slower machine.

The child finds ambseal the way this script does: the package this interpreter imports
(an installed one, or ``src/`` on ``PYTHONPATH``) — the script puts that folder first on
the child's ``PYTHONPATH``.

Run from the repository root:
``PYTHONPATH=src python benchmarks/bench_suite.py [--only run|pytest] [--rig PATH]
[--env one-thread|default] [--cold] [--pytest-args "tests/model"]``.
"""

from __future__ import annotations

import argparse
import json
import os
import resource
import shlex
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
GOALS_S = {"ambseal_run": 30.0, "ambseal_run_flexible": 60.0, "pytest": 300.0}


def _args(argv: list[str] | None = None) -> argparse.Namespace:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--only", choices=["run", "pytest"], default=None,
                    help="time only `ambseal run` or only the test suite")
    ap.add_argument("--rig", default=None,
                    help="rig file for `ambseal run` (default: the embedded test rig)")
    ap.add_argument("--no-identify", action="store_true",
                    help="`ambseal run --no-identify`: the goal of a flexible rotor of "
                         "50–60 elements, 60 s CPU (no identification stage)")
    ap.add_argument("--env", choices=["one-thread", "default"], default="one-thread",
                    help="the children's environment: BLAS variables set to 1, or none "
                         "set (a user's default environment)")
    ap.add_argument("--cold", action="store_true",
                    help="the main job with an empty numba cache (first run after install)")
    ap.add_argument("--pytest-args", default=None,
                    help="arguments for pytest instead of the default run, e.g. "
                         "'tests/model/test_model_fe.py'")
    return ap.parse_args(argv)


#: the main job's CPU goals (s): with numba's caches warm, and on the first run; and
#: without identification on a flexible rotor of 50–60 elements (500–600 states)
CPU_GOALS_S = {"warm": 30.0, "cold": 45.0, "flexible": 60.0}
_BLAS_VARS = ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS",
              "AMBSEAL_BLAS_THREADS")


def child_env(default: bool = False) -> dict[str, str]:
    """The environment of the children: one BLAS thread (``default``: no BLAS variable),
    Agg, and the ambseal this interpreter imports first on PYTHONPATH."""
    import ambseal

    env = dict(os.environ)
    for var in _BLAS_VARS:
        env.pop(var, None)
        if not default and var != "AMBSEAL_BLAS_THREADS":
            env[var] = "1"
    env["MPLBACKEND"] = "Agg"
    pkg_parent = str(Path(ambseal.__file__).resolve().parents[1])
    paths = [pkg_parent] + [p for p in env.get("PYTHONPATH", "").split(os.pathsep) if p]
    env["PYTHONPATH"] = os.pathsep.join(dict.fromkeys(paths))
    return env


def timed_child(cmd: list[str], cwd: Path, env: dict[str, str] | None = None,
                timeout: float | None = None) -> tuple[float, int, str, float]:
    """Wall time (s), return code, the last lines of output and the CPU time (s, user +
    system) of a child process; ``subprocess.TimeoutExpired`` after ``timeout`` s."""
    log("$ " + shlex.join(cmd))
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    t0 = time.perf_counter()
    proc = subprocess.run(cmd, cwd=cwd, env=env or child_env(), stdout=subprocess.PIPE,
                          stderr=subprocess.STDOUT, text=True, timeout=timeout)
    elapsed = time.perf_counter() - t0
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    cpu = (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
    tail = proc.stdout.strip().splitlines()[-15:]
    for line in tail:
        log("  | " + line)
    return elapsed, proc.returncode, "\n".join(tail), cpu


def case_run(rig: str | None, default: bool = False, cold: bool = False,
             no_identify: bool = False) -> dict:
    """Time `ambseal run` (the whole main job, or without identification) into a
    temporary output folder."""
    with tempfile.TemporaryDirectory(prefix="ambseal-bench-") as out, \
            tempfile.TemporaryDirectory(prefix="ambseal-numba-") as cache:
        cmd = [sys.executable, "-c", "import sys; from ambseal.cli import main; "
               "sys.exit(main(sys.argv[1:]))", "run"]
        if rig is not None:
            cmd.append(str(Path(rig).resolve()))
        cmd += ["--out", str(Path(out) / "run")] + (["--no-identify"] if no_identify else [])
        env = child_env(default)
        if cold:
            env["NUMBA_CACHE_DIR"] = cache
        before = machine_reference()
        elapsed, rc, _, cpu = timed_child(cmd, Path(out), env)
        ref = (before + machine_reference()) / 2
    goal = CPU_GOALS_S["flexible" if no_identify else "cold" if cold else "warm"]
    return record("ambseal_run_flexible" if no_identify else "ambseal_run", elapsed, rc, cpu,
                  reference_cpu_s=ref,
                  cpu_per_reference=cpu / ref, rig=rig or "embedded test rig",
                  blas_threads="default" if default else 1, numba_cache="empty" if cold
                  else "as found", cpu_goal_s=goal, meets_cpu_goal=rc == 0 and cpu <= goal)


#: A fixed peer workload that tells this machine's speed: python-control's ``hinfsyn``
#: (SLICOT SB10AD's γ bisection from 1e100) on Scherer, Gahinet & Chilali's Example 7, the
#: baseline of ``bench_hinf.py``: the least CPU time of five batches of 20 calls, in a child
#: with one BLAS thread. A run's
#: ``cpu_per_reference`` compares machines and days that the seconds alone cannot.
_REFERENCE = """
import control as ct
P = ct.ss([[0.0, 10.0, 2.0], [-1.0, 1.0, 0.0], [0.0, 2.0, -5.0]],
          [[1.0, 0.0], [0.0, 1.0], [1.0, 0.0]],
          [[1.0, 0.0, 0.0], [0.0, 0.0, 0.0], [0.0, 1.0, 0.0]],
          [[0.0, 0.0], [0.0, 1.0], [2.0, 0.0]])
ct.hinfsyn(P, 1, 1)
import resource
def cpu():
    r = resource.getrusage(resource.RUSAGE_SELF)
    return r.ru_utime + r.ru_stime
best = float("inf")
for _ in range(5):
    t0 = cpu()
    for _ in range(20):
        ct.hinfsyn(P, 1, 1)
    best = min(best, cpu() - t0)
print(best)
"""


def machine_reference() -> float:
    """CPU seconds (user + system) of the peer workload ``_REFERENCE`` on this machine."""
    with tempfile.TemporaryDirectory(prefix="ambseal-bench-") as cwd:
        proc = subprocess.run([sys.executable, "-c", _REFERENCE], cwd=cwd, env=child_env(),
                              stdout=subprocess.PIPE, stderr=subprocess.DEVNULL, text=True,
                              check=True)
    return float(proc.stdout.split()[-1])


def case_pytest(pytest_args: str | None) -> dict:
    """Time the test suite (or the given pytest arguments) from the repository root."""
    args = shlex.split(pytest_args) if pytest_args else []
    cmd = [sys.executable, "-m", "pytest", "-q", "-p", "no:cacheprovider", *args]
    elapsed, rc, tail, cpu = timed_child(cmd, ROOT)
    summary = tail.splitlines()[-1] if tail else ""
    return record("pytest", elapsed, rc, cpu, args=args or "default run", summary=summary)


def record(case: str, elapsed: float, rc: int, cpu: float, **extra) -> dict:
    goal = GOALS_S[case]
    return {"case": case, "ours_s": elapsed, "goal_s": goal, "ratio": elapsed / goal,
            "meets_goal": rc == 0 and elapsed <= goal, "returncode": rc, "cpu_s": cpu,
            "blas_threads": 1, **extra}


def log(msg: str) -> None:
    print(msg, file=sys.stderr, flush=True)


def main(argv: list[str] | None = None) -> int:
    args = _args(argv)
    cases = []
    if args.only in (None, "run"):
        cases.append(lambda: case_run(args.rig, args.env == "default", args.cold,
                                      args.no_identify))
    if args.only in (None, "pytest"):
        cases.append(lambda: case_pytest(args.pytest_args))
    for case in cases:
        print(json.dumps(case()), flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
