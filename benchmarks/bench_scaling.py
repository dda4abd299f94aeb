"""Benchmark: how ambseal's cost grows with the number of beam elements of the rotor mesh.

The rotor is the embedded test facility with its three ``[[shaft]]`` sections refined to
N beam elements in all (``tests.finemesh.fine_rig_text``; N = 34 is the embedded rig
itself). For each N of ``--elements`` (default 34, 100, 230, 396) and each command of
``--only`` (default all), one JSON line on stdout:

``modes``
    ``ambseal modes RIG --json`` (rotor, AMBs without a controller, seal: dense
    eigenvalues for every unstable pole, the listed modes by shift-invert).
``modes_ross``
    The same mesh on two plain bearings at the AMBs' positions, no seal, coupling or
    modal damping (``tests.finemesh.fine_bearing_data``), at 0 rpm, both sides the same
    work: ours ``ambseal modes PLAIN_RIG --json`` on that rig written out by
    ``ambseal.config.rig.dump_rig``; the baseline ROSS 2.3 on the same elements
    (``tests.finemesh.fine_ross_rotor``) → ``rotor._eigen(0, num_modes=12, sparse=True)``,
    as ``bench_model.py``'s ``fine_ross`` case (its child also imports ambseal's config
    and mesh, which build ROSS's elements). ``max_rel_diff``: largest relative
    difference of our first six listed frequencies to the nearest of ROSS's.
``design``
    ``ambseal design RIG --method mu --out DIR`` (μ, the full-order verdict).
``run``
    ``ambseal run RIG --no-identify --out DIR`` (the judged run: three designs, their
    digital controllers, the judged cases, the report), with its stage lines' times.

Every command is a child process (interpreter start and imports included) with one BLAS
thread and ``MPLBACKEND=Agg`` (``bench_suite.child_env``), measured by ``os.wait4`` on
that child alone: wall time (``ours_s``), CPU time user + system (``ours_cpu_s``) and
peak resident set size (``ours_peak_rss_mib``, the child's ``ru_maxrss``); the baseline's
the same (``baseline_s``, ``baseline_cpu_s``, ``baseline_peak_rss_mib``; ``ratio`` =
``baseline_s / ours_s``, ``ratio_cpu`` likewise). ``modes`` and ``modes_ross`` take the
median of ``--repeats`` runs (the two tools alternate), ``design`` and ``run`` one run.
A line also carries ``n_elements`` (N), ``n_elements_mesh`` (after the splits at the
components) and ``states`` (of the open-loop model; ``modes_ross``: of the plain-bearing
rig), the machine's load and the child's ``returncode``; ``--timeout`` kills a child that
runs longer (``timed_out``). An N whose model ambseal refuses gives one line per command
with ``refused`` (the message) and ``measured: false``: the rig file's bound is 400 beam
elements *after* the splits at the components, so on this rig 400 in the sections (404
after the splits) is refused and 396 (400 after them) is the largest N.

After the cases, one line per command and side with the fitted exponents of
cost ≈ a·N^b (least squares on log–log over the measured N): ``{"case": "fit",
"command", "n_elements", "cpu_exponent", "wall_exponent", "rss_exponent",
"cpu_exponent_last_pair"}`` (the last: the slope between the two largest N, nearer the
asymptote than a fit that includes the import-dominated small meshes).

``--results FILE`` appends every line to FILE as soon as it is measured (a partial table
survives an interrupted run); ``--fit-only`` reads FILE instead of measuring and prints
the fits over its latest line per command and N. Progress and the children's stage lines
go to stderr.

Run from the repository root: ``PYTHONPATH=src python benchmarks/bench_scaling.py
[--elements 34,100,230,396] [--only modes,modes_ross,design,run] [--repeats 3]
[--results /tmp/bench_scaling.jsonl] [--fit-only] [--timeout S]``.
"""

from __future__ import annotations

import argparse
import json
import os
import re
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

for _var in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ[_var] = "1"  # this process too (it builds each rig's model once, untimed)

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
# the fine-mesh rig and its ROSS twin are the tests' (tests/finemesh.py), the children's
# environment bench_suite's
sys.path[:0] = [str(ROOT), str(ROOT / "benchmarks")]
from bench_suite import child_env, log

from tests.finemesh import fine_bearing_data, fine_rig_text

COMMANDS = ("modes", "modes_ross", "design", "run")
N_COMPARED = 6  # modes compared with ROSS's

#: The ROSS child: the plain-bearing twin of N elements, its 12 lowest modes at 0 rpm
#: (``bench_model.py``'s ``fine_ross``); prints the mesh's element count and eigenvalues.
_ROSS_CHILD = """
import json, sys, warnings
sys.path.insert(0, {root!r})
with warnings.catch_warnings():
    warnings.simplefilter("ignore")
    import ross as rs
from ambseal.config import parse_rig
from tests.finemesh import fine_bearing_data, fine_ross_rotor
rotor, n_el = fine_ross_rotor(rs, parse_rig(fine_bearing_data({n})))
with warnings.catch_warnings():
    warnings.simplefilter("ignore")
    lam = rotor._eigen(0.0, num_modes=12, sparse=True)[0]
print(json.dumps({{"version": rs.__version__, "n_elements_mesh": n_el,
                  "eigenvalues": [[float(x.real), float(x.imag)] for x in lam]}}))
"""


def _args(argv: list[str] | None = None) -> argparse.Namespace:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--elements", default="34,100,230,396",
                    help="beam elements in all, comma-separated (default 34,100,230,396: "
                         "396 is the largest the rig file's bound admits on this rig)")
    ap.add_argument("--only", default=",".join(COMMANDS),
                    help=f"commands, comma-separated, of {', '.join(COMMANDS)} (default all)")
    ap.add_argument("--repeats", type=int, default=3,
                    help="runs of modes and modes_ross per N, medians reported (default 3)")
    ap.add_argument("--results", default=None,
                    help="append every JSON line to this file as soon as it is measured")
    ap.add_argument("--fit-only", action="store_true",
                    help="fit the exponents over the lines of --results; measure nothing")
    ap.add_argument("--timeout", type=float, default=None,
                    help="kill a child after this many seconds of wall time")
    args = ap.parse_args(argv)
    args.elements = sorted(int(x) for x in args.elements.split(","))
    args.only = [c.strip() for c in args.only.split(",") if c.strip()]
    bad = sorted(set(args.only) - set(COMMANDS))
    if bad:
        ap.error(f"--only: unknown {', '.join(bad)} (choose from {', '.join(COMMANDS)})")
    if args.fit_only and not args.results:
        ap.error("--fit-only needs --results FILE")
    return args


# ---------------------------------------------------------------- one child, measured
def measure(cmd: list[str], cwd: Path, timeout: float | None = None) -> dict:
    """Run ``cmd`` as a child and measure it alone (``os.wait4``): wall, user + system
    CPU, peak RSS (MiB), return code, stdout, and its ``ambseal:`` stage lines (logged)."""
    with tempfile.TemporaryFile() as out, tempfile.TemporaryFile() as err:
        t0 = time.perf_counter()
        proc = subprocess.Popen(cmd, cwd=cwd, env=child_env(), stdout=out, stderr=err)
        timed_out = False
        while True:
            pid, status, ru = os.wait4(proc.pid, os.WNOHANG)
            if pid:
                break
            if timeout is not None and time.perf_counter() - t0 > timeout:
                proc.kill()
                timed_out = True
                _, status, ru = os.wait4(proc.pid, 0)
                break
            time.sleep(0.05)
        wall = time.perf_counter() - t0
        proc.returncode = os.waitstatus_to_exitcode(status)  # reaped here, not by Popen
        out.seek(0)
        err.seek(0)
        stdout = out.read().decode("utf-8", "replace")
        stderr = err.read().decode("utf-8", "replace")
    stages = {}
    for line in stderr.splitlines():
        if line.startswith("ambseal:"):
            log("  | " + line)
            m = re.match(r"ambseal: (.+?): done in ([0-9.]+) s", line)
            if m:
                stages[m.group(1)] = float(m.group(2))
    if proc.returncode != 0:
        for line in stderr.strip().splitlines()[-10:]:
            log("  ! " + line)
    return {"wall_s": wall, "cpu_s": ru.ru_utime + ru.ru_stime, "user_s": ru.ru_utime,
            "sys_s": ru.ru_stime, "peak_rss_mib": ru.ru_maxrss / 1024.0,
            "returncode": proc.returncode, "timed_out": timed_out, "stdout": stdout,
            "stages_s": stages}


def medians(runs: list[dict], prefix: str) -> dict:
    """The medians of wall, CPU and peak RSS over ``runs`` as ``{prefix}_s`` etc."""
    return {f"{prefix}_s": statistics.median(r["wall_s"] for r in runs),
            f"{prefix}_cpu_s": statistics.median(r["cpu_s"] for r in runs),
            f"{prefix}_peak_rss_mib": statistics.median(r["peak_rss_mib"] for r in runs),
            f"{prefix}_returncode": max((r["returncode"] for r in runs), key=abs)}


def ambseal_cmd(*args: str) -> list[str]:
    return [sys.executable, "-m", "ambseal.cli", *args]


# ---------------------------------------------------------------- the cases
def model_size(cfg) -> dict:
    """Beam elements after the component splits and states of the open-loop model."""
    from ambseal.model.rig import build_system

    s = build_system(cfg)
    return {"n_elements_mesh": len(s.mesh.elements),
            "states": int(s.state_matrices()[0].shape[0])}


def case_modes(rig: Path, tmp: Path, args) -> dict:
    runs = [measure(ambseal_cmd("modes", str(rig), "--json"), tmp, args.timeout)
            for _ in range(args.repeats)]
    rec = medians(runs, "ours")
    rec["returncode"] = rec.pop("ours_returncode")
    if rec["returncode"] == 0:
        hz = json.loads(runs[-1]["stdout"])["natural_frequencies_hz"]
        rec.update(n_listed=len(hz), first_modes_hz=[round(x, 4) for x in hz[:N_COMPARED]])
    return {"call": "ambseal modes RIG --json", **rec, "repeats": args.repeats}


def case_modes_ross(n: int, plain: Path, tmp: Path, args) -> dict:
    ours, base = [], []
    for _ in range(args.repeats):  # alternate: both see the same load
        ours.append(measure(ambseal_cmd("modes", str(plain), "--json"), tmp, args.timeout))
        base.append(measure([sys.executable, "-c", _ROSS_CHILD.format(root=str(ROOT), n=n)],
                            tmp, args.timeout))
    rec = {**medians(ours, "ours"), **medians(base, "baseline")}
    rec.update(ratio=rec["baseline_s"] / rec["ours_s"],
               ratio_cpu=rec["baseline_cpu_s"] / rec["ours_cpu_s"])
    if rec["ours_returncode"] == 0 and rec["baseline_returncode"] == 0:
        hz = np.asarray(json.loads(ours[-1]["stdout"])["natural_frequencies_hz"][:N_COMPARED])
        ross = json.loads(base[-1]["stdout"].strip().splitlines()[-1])
        ref = np.abs(np.array(ross["eigenvalues"])[:, 1]) / (2 * np.pi)
        ref = ref[ref > 1e-6]
        near = ref[np.abs(ref[None, :] - hz[:, None]).argmin(axis=1)]
        rec.update(baseline="ross " + ".".join(ross["version"].split(".")[:2]),
                   max_rel_diff=float(np.max(np.abs(hz - near) / near)),
                   first_modes_hz=[round(float(x), 4) for x in hz],
                   baseline_n_elements_mesh=ross["n_elements_mesh"])
    return {"call": "ambseal modes PLAIN_RIG --json",
            "baseline_call": "fine_ross_rotor(...)._eigen(0, num_modes=12, sparse=True)",
            **rec, "speed_rpm": 0.0, "repeats": args.repeats}


def case_design(rig: Path, tmp: Path, args) -> dict:
    r = measure(ambseal_cmd("design", str(rig), "--method", "mu", "--out",
                            str(tmp / "design")), tmp, args.timeout)
    rec = {"call": "ambseal design RIG --method mu --out DIR", **medians([r], "ours"),
           "timed_out": r["timed_out"]}
    rec["returncode"] = rec.pop("ours_returncode")
    if rec["returncode"] == 0:
        d = json.loads(r["stdout"].strip().splitlines()[-1])
        rec.update(mu=d.get("mu"), mu_full=(d.get("reduction") or {}).get("mu_full"),
                   full_order_stable=(d.get("full_order") or {}).get("stable"),
                   design_elapsed_s=d.get("elapsed_s"))
    return rec


def case_run(rig: Path, tmp: Path, args) -> dict:
    r = measure(ambseal_cmd("run", str(rig), "--no-identify", "--out", str(tmp / "run")),
                tmp, args.timeout)
    rec = {"call": "ambseal run RIG --no-identify --out DIR", **medians([r], "ours"),
           "user_s": r["user_s"], "sys_s": r["sys_s"], "stages_s": r["stages_s"],
           "timed_out": r["timed_out"]}
    rec["returncode"] = rec.pop("ours_returncode")
    return rec


# ---------------------------------------------------------------- the fits
def slope(n, y) -> float | None:
    """b of y ≈ a·n^b by least squares on log–log (None below two points)."""
    if len(n) < 2:
        return None
    return float(np.polyfit(np.log(n), np.log(y), 1)[0])


def fits(records: list[dict]) -> list[dict]:
    """One line per command and side: the exponents over the latest line per N."""
    latest: dict[tuple[str, int], dict] = {}
    for r in records:
        if r.get("case") in COMMANDS and not r.get("timed_out") \
                and r.get("returncode", r.get("ours_returncode")) == 0:
            latest[(r["case"], r["n_elements"])] = r
    out = []
    for case in COMMANDS:
        rows = sorted((r for (c, _), r in latest.items() if c == case),
                      key=lambda r: r["n_elements"])
        sides = ("ours", "baseline") if case == "modes_ross" else ("ours",)
        for side in sides:
            pts = [r for r in rows if f"{side}_cpu_s" in r]
            if len(pts) < 2:
                continue
            n = [r["n_elements"] for r in pts]
            cpu = [r[f"{side}_cpu_s"] for r in pts]
            name = case if side == "ours" else "ross_modes"
            if case == "modes_ross" and side == "ours":
                name = "modes_plain_bearings"
            out.append({"case": "fit", "command": name, "n_elements": n,
                        "model": "cost = a*N^b, least squares on log-log",
                        "cpu_exponent": slope(n, cpu),
                        "wall_exponent": slope(n, [r[f"{side}_s"] for r in pts]),
                        "rss_exponent": slope(n, [r[f"{side}_peak_rss_mib"] for r in pts]),
                        "cpu_exponent_last_pair": slope(n[-2:], cpu[-2:]),
                        "cpu_s": cpu})
    return out


# ---------------------------------------------------------------- main
def main(argv: list[str] | None = None) -> int:
    args = _args(argv)

    def emit(rec: dict) -> None:
        line = json.dumps(rec)
        print(line, flush=True)
        if args.results and not args.fit_only:
            with open(args.results, "a", encoding="utf-8") as f:
                f.write(line + "\n")

    if args.fit_only:
        with open(args.results, encoding="utf-8") as f:
            records = [json.loads(x) for x in f if x.strip()]
        for rec in fits(records):
            emit(rec)
        return 0

    import tomllib

    from ambseal.config import parse_rig
    from ambseal.config.rig import dump_rig
    from ambseal.errors import ConfigError

    records = []
    for n in args.elements:
        with tempfile.TemporaryDirectory(prefix="ambseal-scaling-") as tmpdir:
            tmp = Path(tmpdir)
            rig = tmp / f"testrig_{n}.toml"
            rig.write_text(fine_rig_text(n), encoding="utf-8")
            plain_cfg = parse_rig(fine_bearing_data(n))
            plain = tmp / f"plain_{n}.toml"
            plain.write_text(dump_rig(plain_cfg), encoding="utf-8")
            try:
                common = {"n_elements": n,
                          **model_size(parse_rig(tomllib.loads(fine_rig_text(n))))}
            except ConfigError as exc:  # e.g. the rig file's bound on the mesh
                log(f"{n} elements refused: {exc}")
                for case in (c for c in COMMANDS if c in args.only):
                    emit({"case": case, "n_elements": n, "refused": str(exc),
                          "measured": False})
                continue
            for case in (c for c in COMMANDS if c in args.only):
                log(f"case {case} ({n} elements, {common['states']} states)")
                if case == "modes":
                    rec = case_modes(rig, tmp, args)
                elif case == "modes_ross":
                    # the plain-bearing rig's own mesh and states
                    rec = {**case_modes_ross(n, plain, tmp, args), **model_size(plain_cfg)}
                elif case == "design":
                    rec = case_design(rig, tmp, args)
                else:
                    rec = case_run(rig, tmp, args)
                rec = {"case": case, **common, **rec, "blas_threads": 1,
                       "load_1min": round(os.getloadavg()[0], 2)}
                records.append(rec)
                emit(rec)
    for rec in fits(records):
        emit(rec)
    return 0


if __name__ == "__main__":
    sys.exit(main())
