"""Benchmark: what a user sees of every example rig, compared between two codes or two
machines, against the tolerance stated for each number.

Each *side* is a git revision of this repository, an OpenBLAS kernel set and a BLAS
thread count (``REV@CORETYPE:THREADS``; ``REV`` alone keeps this environment's kernels
and one thread, ``REV@:2`` its kernels and two threads: ambseal's thread policy,
``AMBSEAL_BLAS_THREADS``, and the BLAS variables). For each side the revision is
exported (``git archive``) to a temporary folder, and ``ambseal run RIG --no-identify``
runs on every example rig with that tree's ``src`` first on PYTHONPATH, in a child
process. The first side is the reference; every other side's ``metrics.json``
is compared with it as ``tests/kernel_compare.py`` states (the same comparison as the
kernel tests): the delivered set, every ISO 14839-3 zone and every verdict's words
exactly, each number within its relative tolerance (``RTOL``: μ and γ 2 %, σ̄(S_o) peaks,
orbits and currents 5 %).

One JSON line per rig and side on stdout (exit status, CPU, the delivered set), then one
per rig and compared side: the lines beyond tolerance counted by kind (``delivered``,
``zones``, ``words``, ``numbers``) and, for each toleranced key, the largest relative
change found, within tolerance or not. The last line is a Markdown table of the latter.

Run from the repository root: ``PYTHONPATH=src python benchmarks/bench_tolerances.py
--side REV[@CORETYPE[:THREADS]] --side … [--side …] [--rigs NAME …] [--workers N]
[--keep DIR [--resume]]``. The runs go serially, or on a Dask cluster through the sweep's executor
(``--workers N``): each row comes from its own child either way.
"""

from __future__ import annotations

import argparse
import json
import subprocess
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "benchmarks"))
sys.path.insert(0, str(ROOT))
from bench_suite import child_env, log, machine_reference, timed_child  # noqa: E402

from tests.kernel_compare import RTOL, delivered, differences  # noqa: E402

#: The kinds a line of :func:`tests.kernel_compare.differences` belongs to, by what it
#: names, the first that matches: a sentence (a verdict's, or a failed or unrunnable
#: controller's reason), the delivered set (and which controllers failed or cannot run),
#: a zone, else a number or a table's shape.
KINDS = (("words", ("words differ",)), ("delivered", ("delivered:", "failed:", "cannot_run:")),
         ("zones", ("iso_zone",)))


def kind(line: str) -> str:
    """Which of ``delivered``, ``zones``, ``words`` or ``numbers`` a difference is."""
    head = line.split("\n", 1)[0]
    for name, marks in KINDS:
        if any(m in head for m in marks):
            return name
    return "numbers"


def parse_side(side: str) -> tuple[str, str, int]:
    """``REV@CORETYPE:THREADS`` as ``(rev, coretype or "", threads)`` (one by default)."""
    rev, _, rest = side.partition("@")
    core, _, threads = rest.partition(":")
    return rev, core, int(threads or 1)


def export(rev: str, into: Path) -> Path:
    """The tree of ``rev`` written under ``into`` (``git archive``); its folder."""
    sha = subprocess.run(["git", "rev-parse", "--verify", f"{rev}^{{commit}}"], cwd=ROOT,
                         capture_output=True, text=True, check=True).stdout.strip()
    tree = into / sha[:12]
    if not tree.is_dir():
        tree.mkdir(parents=True)
        archive = subprocess.run(["git", "archive", "--format=tar", sha], cwd=ROOT,
                                 capture_output=True, check=True).stdout
        subprocess.run(["tar", "-x", "-C", str(tree)], input=archive, check=True)
    return tree


def run_side(case: dict, timeout: float) -> dict:
    """One rig's ``ambseal run --no-identify`` on one side: its row (the metrics kept in
    ``case["out"]``)."""
    env = child_env()
    env["PYTHONPATH"] = str(Path(case["tree"]) / "src")
    if case["coretype"]:
        env["OPENBLAS_CORETYPE"] = case["coretype"]
    # the policy's variable too: without it ambseal's numerics run on one BLAS thread
    # whatever the BLAS variables say (ambseal.threads), and the sides would not differ
    for var in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS",
                "AMBSEAL_BLAS_THREADS"):
        env[var] = str(case["threads"])
    out = Path(case["out"])
    cmd = [sys.executable, "-c", "import sys; from ambseal.cli import main; "
           "sys.exit(main(sys.argv[1:]))", "run", case["rig"], "--no-identify",
           "--out", str(out)]
    row = {"case": "run", "rig": Path(case["rig"]).stem, "side": case["side"]}
    ref0 = machine_reference()
    try:
        wall, code, tail, cpu = timed_child(cmd, out.parent, env, timeout)
    except subprocess.TimeoutExpired:
        return {**row, "timed_out": True, "timeout_s": timeout}
    ref = (ref0 + machine_reference()) / 2
    row.update(returncode=code, wall_s=wall, cpu_s=cpu, cpu_per_reference=cpu / ref)
    metrics = out / "metrics.json"
    if metrics.is_file():
        row["delivered"] = delivered(json.loads(metrics.read_text()))
    else:
        row["error"] = (tail.splitlines() or ["no output"])[-1]
    return row


def compare(rig: str, reference: str, side: str, a: dict, b: dict) -> dict:
    """The row of one rig's ``side`` against its ``reference``: the differences beyond
    tolerance by kind, the largest change per toleranced key, the first lines."""
    seen: dict[str, float] = {}
    diff = differences(a, b, seen)
    counts = {name: 0 for name in ("delivered", "zones", "words", "numbers")}
    for line in diff:
        counts[kind(line)] += 1
    return {"case": "compare", "rig": rig, "reference": reference, "side": side,
            "beyond": counts, "largest": {k: round(v, 6) for k, v in sorted(seen.items())},
            "lines": diff[:12]}


def table(rows: list[dict]) -> str:
    """The compared rows as a Markdown table: per rig and side, the lines beyond tolerance
    by kind, and the largest change of each toleranced key in % (its tolerance in the
    header)."""
    keys = [k for k in RTOL if any(k in r["largest"] for r in rows)]
    head = ["rig", "against", "delivered", "zones", "words", "numbers beyond"] + [
        f"{k} ({100 * RTOL[k]:g} %)" for k in keys]
    out = ["| " + " | ".join(head) + " |", "|" + "---|" * len(head)]
    for r in rows:
        cells = [r["rig"], f"{r['side']} vs {r['reference']}",
                 *(str(r["beyond"][k]) for k in ("delivered", "zones", "words", "numbers")),
                 *(f"{100 * r['largest'][k]:.2f}" if k in r["largest"] else "–"
                   for k in keys)]
        out.append("| " + " | ".join(cells) + " |")
    return "\n".join(out)


def _args(argv=None) -> argparse.Namespace:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--side", action="append", required=True,
                    help="REV[@CORETYPE[:THREADS]]; the first is the reference (at least two)")
    ap.add_argument("--rigs", nargs="*", default=None,
                    help="example rig names (default: every examples/*.toml)")
    ap.add_argument("--workers", type=int, default=1)
    ap.add_argument("--timeout", type=float, default=3600.0)
    ap.add_argument("--keep", type=Path, default=None,
                    help="keep the trees and runs in this folder (default: a temporary one)")
    ap.add_argument("--resume", action="store_true",
                    help="with --keep: a run whose metrics.json is there already is not run "
                         "again (its row says so)")
    args = ap.parse_args(argv)
    if len(args.side) < 2:
        ap.error("--side: give at least two")
    if args.resume and args.keep is None:
        ap.error("--resume: needs --keep")
    return args


def main(argv=None) -> int:
    from ambseal.analysis.cases import run_cases

    args = _args(argv)
    names = args.rigs or sorted(p.stem for p in (ROOT / "examples").glob("*.toml"))
    with tempfile.TemporaryDirectory(prefix="ambseal-tolerances-") as tmp:
        work = args.keep or Path(tmp)
        work.mkdir(parents=True, exist_ok=True)
        sides = [(s, *parse_side(s)) for s in args.side]
        trees = {rev: export(rev, work / "trees") for _, rev, _, _ in sides}
        cases = []
        for name in names:
            for side, rev, core, threads in sides:
                out = work / "runs" / side.replace("/", "_") / name / "out"
                out.parent.mkdir(parents=True, exist_ok=True)
                cases.append({"rig": str(ROOT / "examples" / f"{name}.toml"), "side": side,
                              "tree": str(trees[rev]), "coretype": core, "threads": threads,
                              "out": str(out)})
        log(f"{len(cases)} runs: {len(names)} rigs × {len(sides)} sides")
        done = [c for c in cases if args.resume and (Path(c["out"]) / "metrics.json").is_file()]
        todo = [c for c in cases if c not in done]
        rows = [{"case": "run", "rig": Path(c["rig"]).stem, "side": c["side"], "resumed": True}
                for c in done]
        rows += run_cases(run_side, todo, shared={"timeout": args.timeout},
                          workers=args.workers, description="runs") if todo else []
        compared = []
        for row in rows:
            print(json.dumps(row), flush=True)
        # only what this call ran or resumed: a run that wrote nothing leaves an earlier
        # run's metrics.json in a kept folder
        fresh = {(r["rig"], r["side"]) for r in rows if "delivered" in r or r.get("resumed")}
        for name in names:
            runs = {c["side"]: Path(c["out"]) / "metrics.json" for c in cases
                    if Path(c["rig"]).stem == name and (name, c["side"]) in fresh}
            ref = sides[0][0]
            if ref not in runs:
                continue
            a = json.loads(runs[ref].read_text())
            for side, *_ in sides[1:]:
                if side in runs:
                    row = compare(name, ref, side, a, json.loads(runs[side].read_text()))
                    compared.append(row)
                    print(json.dumps(row), flush=True)
        print(json.dumps({"case": "table", "markdown": table(compared)}))
    return 0


if __name__ == "__main__":
    sys.exit(main())
