"""Benchmark: ``ambseal run --no-identify`` on rigs nobody tuned the code for — every example
rig at its own mesh and at a finer one — stage by stage, in machine references.

For each rig (``examples/*.toml``, or each ``--rig PATH``) and each mesh:

``own``
    The rig file as written.
``finer``
    Every ``[[shaft]]`` section's ``elements`` times ``--factor`` (default 1.3, the
    issue's "elements × 1.2–1.5"), rounded up: a user who refines the mesh a little. A
    rig whose finer mesh the rig file's bound refuses (400 beam elements) is reported
    ``refused``.

one JSON line on stdout: ``rig``, ``mesh``, ``elements``, ``states`` (the open-loop
model's, from ``metrics.json``), ``returncode``, ``cpu_s`` (the child's user + system
CPU, interpreter start and imports included) and ``cpu_per_reference`` against the goal
``goal_references`` (113: 60 s at the developers' machine reference of 0.53 s) with
``meets_goal``; per stage of the run
(``model``, ``design``, ``judge``, ``speed-range``, ``sampled-redesign`` where a design is
lost only as it runs, ``spin-up``, ``report``, the sign-off
where the run has one) its CPU time (s, the stage line's own process CPU) and references
(``stages``); the design time of each method (``design_s``, its ``elapsed_s``); and the
limit each stage's cost is held to — the judged conditions (judged cases and speed-range
cases of ``metrics.json``) times one dense eigendecomposition of the loop (``eig_s``:
``numpy.linalg.eig`` with vectors of a random matrix of the open-loop states plus 40
controller states, the best of three, in this process) — as ``limit_s`` and
``limit_references``.

Every run is a child process with one BLAS thread and ``MPLBACKEND=Agg``
(``bench_suite.child_env``); the machine reference (``bench_suite.machine_reference``,
python-control's ``hinfsyn`` on a fixed problem) is taken before and after each run and
averaged, so a line compares across machines and days.

Run from the repository root: ``PYTHONPATH=src python benchmarks/bench_rigs.py
[--rig PATH ...] [--mesh own,finer] [--factor 1.3] [--timeout S]``.
"""

from __future__ import annotations

import argparse
import json
import math
import re
import resource
import subprocess
import sys
import tempfile
import time
import tomllib
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
from bench_suite import child_env, log, machine_reference  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]
#: ``ambseal run --no-identify``'s goal, in machine references (60 s at 0.53 s).
GOAL_REFERENCES = 113.0
#: Controller states added to the open loop's for the limit's eigendecomposition (the
#: largest design order the examples deliver is below it).
CONTROLLER_STATES = 40
_STAGE = re.compile(r"ambseal: ([a-z-]+): done in ([0-9.]+) s \(([0-9.]+) s CPU\)")


def _meshes(text: str) -> list[str]:
    """``--mesh``: the meshes to run, in order; ``both`` is ``own,finer``."""
    names = ["own", "finer"] if text == "both" else text.split(",")
    if any(n not in ("own", "finer") for n in names):
        raise argparse.ArgumentTypeError(f"expected own, finer, both, or a comma list of "
                                         f"own and finer; got {text!r}")
    return names


def _args(argv=None) -> argparse.Namespace:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--rig", action="append", default=None,
                    help="a rig file (repeatable); default every examples/*.toml")
    ap.add_argument("--mesh", type=_meshes, default="own,finer",
                    help="own, finer, both, or a comma list of own and finer")
    ap.add_argument("--factor", type=float, default=1.3,
                    help="the finer mesh's elements per section, × this, rounded up")
    ap.add_argument("--timeout", type=float, default=1800.0, help="seconds per run")
    return ap.parse_args(argv)


def finer_rig(text: str, factor: float) -> tuple[str, int]:
    """The rig file's text with every ``[[shaft]]`` section's ``elements`` times
    ``factor``, rounded up, and the number of elements in all."""
    doc = tomllib.loads(text)
    counts = [math.ceil(factor * s.get("elements", 1)) for s in doc["shaft"]]
    lines, i, out = text.splitlines(), 0, []
    in_shaft = False
    for line in lines:
        head = line.strip()
        if head.startswith("["):
            in_shaft = head == "[[shaft]]"
            if in_shaft:
                i += 1
        m = re.match(r"(\s*elements\s*=\s*)(\d+)(.*)$", line)
        if in_shaft and m:
            line = f"{m.group(1)}{counts[i - 1]}{m.group(3)}"
        out.append(line)
    if sum(1 for s in doc["shaft"] if "elements" in s) != sum(
            1 for ln in out if re.match(r"\s*elements\s*=", ln)):
        raise ValueError("a [[shaft]] section without an `elements` line")
    return "\n".join(out) + "\n", sum(counts)


def eig_seconds(n: int) -> float:
    """The best of three dense eigendecompositions (with vectors) of an n × n matrix."""
    a = np.random.default_rng(0).standard_normal((n, n))
    best = math.inf
    for _ in range(3):
        t0 = time.process_time()
        np.linalg.eig(a)
        best = min(best, time.process_time() - t0)
    return best


def run_one(rig: Path, mesh: str, factor: float, timeout: float) -> dict:
    """One ``ambseal run --no-identify`` of ``rig`` at ``mesh``: its JSON line."""
    text = rig.read_text()
    doc = tomllib.loads(text)
    elements = sum(s.get("elements", 1) for s in doc["shaft"])
    row = {"case": "run", "rig": rig.name, "mesh": mesh}
    with tempfile.TemporaryDirectory(prefix="ambseal-bench-") as tmp:
        path = rig.resolve()
        if mesh == "finer":
            text, elements = finer_rig(text, factor)
            path = Path(tmp) / rig.name
            path.write_text(text)
            row["factor"] = factor
        row["elements"] = elements
        cmd = [sys.executable, "-c", "import sys; from ambseal.cli import main; "
               "sys.exit(main(sys.argv[1:]))", "run", str(path), "--no-identify",
               "--out", str(Path(tmp) / "run")]
        log(f"$ ambseal run {rig.name} --no-identify ({mesh}, {elements} elements)")
        ref0 = machine_reference()
        before = resource.getrusage(resource.RUSAGE_CHILDREN)
        t0 = time.perf_counter()
        try:
            proc = subprocess.Popen(cmd, cwd=tmp, env=child_env(), stdout=subprocess.DEVNULL,
                                    stderr=subprocess.PIPE, text=True)
            _, err = proc.communicate(timeout=timeout)
        except subprocess.TimeoutExpired:
            proc.kill()
            proc.communicate()
            return {**row, "timed_out": True, "timeout_s": timeout}
        wall = time.perf_counter() - t0
        after = resource.getrusage(resource.RUSAGE_CHILDREN)
        cpu = (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
        ref = (ref0 + machine_reference()) / 2
        stages = {m.group(1): {"wall_s": float(m.group(2)), "cpu_s": float(m.group(3)),
                               "references": float(m.group(3)) / ref}
                  for m in map(_STAGE.match, err.splitlines()) if m}
        refused = [ln for ln in err.splitlines() if ln.startswith("ambseal: error")]
        metrics = Path(tmp) / "run" / "metrics.json"
        m = json.loads(metrics.read_text()) if metrics.is_file() else None
    row.update(returncode=proc.returncode, wall_s=wall, cpu_s=cpu, reference_cpu_s=ref,
               cpu_per_reference=cpu / ref, goal_references=GOAL_REFERENCES,
               meets_goal=bool(m is not None and cpu / ref <= GOAL_REFERENCES),
               stages=stages)
    if refused:
        row["refused"] = refused[-1]
    if m is not None:
        states = int(m["open_loop"]["n_states_full"])
        conditions = len(m.get("cases", [])) + len(m.get("stability", []))
        eig = eig_seconds(states + CONTROLLER_STATES)
        row.update(states=states, judged_conditions=conditions, eig_s=eig,
                   limit_s=conditions * eig, limit_references=conditions * eig / ref,
                   design_s={k: v.get("elapsed_s") for k, v in m["controllers"].items()})
    return row


def main(argv=None) -> int:
    args = _args(argv)
    rigs = [Path(r) for r in args.rig] if args.rig else sorted((ROOT / "examples").glob(
        "*.toml"))
    for rig in rigs:
        for mesh in args.mesh:
            print(json.dumps(run_one(rig, mesh, args.factor, args.timeout)), flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
