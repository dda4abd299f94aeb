"""Benchmark: ``ambseal run --no-identify`` on a seeded family of gyroscopic rigs nobody
tuned the code for, per method the fraction delivered and the CPU in machine references.

The generator (:func:`family_rig`, one rig per seed, ``numpy.random.default_rng(seed)``)
draws a machine of the energy-storage flywheel and high-speed motor class and writes it
as a rig file from the manual's keys alone:

* **the rotor**: a hollow steel shaft (bore 0.6 of its outside diameter) of length L, a
  wheel at 0.45 L carrying 60 % of the rotor's mass, a motor rotor at 0.7 L (10 %), and
  the two AMBs' laminations at 0.12 L and 0.88 L (5 % each); mass m from 5 to 30 kg,
  L from 0.25 to 0.6 m;
* **Ip/It** of the whole rotor about its centre of mass drawn from 0.5 to 1.5: the wheel's
  diametral inertia is solved for it (what the shaft, motor and laminations add is
  subtracted), at least a thin disc's Ip/2. So the wheel's polar radius of gyration is
  drawn from 1 to 1.5 times the least that reaches the drawn ratio with a thin disc
  (what the rest of the rotor adds to I_t estimated as point masses), at least 0.1 L;
  the draw is repeated where the shaft the bending frequency asks for adds more;
* **the top speed** from 20 000 to 100 000 rpm, run from a third of it up
  (``speed_range_hz``); **the first free–free bending mode** from 1.2 to 3× the top
  speed: the shaft's outside diameter is bisected on ambseal's own free–free model
  (:func:`ambseal.model.modes.free_bending_hz`), the wheel's Id re-solved at each step;
* **the AMBs**: 0.5 mm air gap, 2.5 A bias, twice that as current limit, Ki sized so that
  the bias current's linear range holds three times each bearing's share of the weight
  plus the G2.5 unbalance force at the top speed (ISO 21940-11: e·Ω = 2.5 mm/s), and
  Ks = Ki·i0/s0 (Schweitzer & Maslen 2009, §3.3); first-order amplifiers at f_s/10;
* **sensors** collocated with the actuators or 0.08 L outboard (non-collocated), drawn;
* **the target**: 10, 20 or 40 kHz (drawn), one sample of delay;
* **the orientation**, horizontal or vertical (``[machine] orientation``), drawn last: a
  vertical rotor's radial AMBs carry no weight, so its Ki is sized on the unbalance
  force alone.

To these the family adds the example flywheel (``examples/flywheel.toml``, as its file
says: no ``[design.rejection]``) at 10, 20 and 40 kHz.

Each rig runs in a child process (``bench_rigs.run_one``'s environment: one BLAS thread,
Agg) serially, or on a Dask cluster through the sweep's executor
(:func:`ambseal.analysis.cases.run_cases`, ``--workers N`` or ``--scheduler ADDR``): the
same rows either way, since each row comes from its own child. One JSON line per rig on
stdout: the draw, the exit status, CPU in machine references and per method
``delivered`` — in ``metrics.json``'s controllers, neither failed nor unable to run on
the target, and ISO 14839-3 zone A or B on every axis (σ̄(S_o) peak per axis below 4, as
it runs: the discrete loop's) at every judged condition and every speed of the range from
standstill to the top speed that the run closes the loop at (``metrics.json``'s
``stability``), and ``why_not`` each other
method is (:func:`why_not`). The last line sums the family:
per method the fraction delivered, the rigs where no method is, and the CPU.

Run from the repository root: ``PYTHONPATH=src python benchmarks/bench_family.py
[--seeds 0:24] [--workers N | --scheduler ADDR] [--no-examples] [--write-only DIR]``.
"""

from __future__ import annotations

import argparse
import json
import math
import subprocess
import sys
import tempfile
import tomllib
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
from bench_suite import child_env, log, machine_reference, timed_child  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]
#: ISO 14839-3 zone B's upper limit of the sensitivity function's peak (Annex A, 12 dB)
ZONE_B_LIMIT = 4.0
METHODS = ("pid", "hinf", "mu", "lpv")
RATES_HZ = (10000.0, 20000.0, 40000.0)
STEEL = {"E": 2.0e11, "rho": 7850.0, "nu": 0.3}
GRAVITY = 9.81
#: ISO 21940-11 balance quality grade G2.5: e·Ω (m/s)
GRADE_M_S = 2.5e-3


def _rig_text(p: dict, d_o: float, id_wheel: float) -> str:
    """The rig file of draw ``p`` with shaft outside diameter ``d_o`` (m) and the wheel's
    diametral inertia ``id_wheel`` (kg·m²)."""
    L, m = p["length_m"], p["mass_kg"]
    amb = (0.12 * L, 0.88 * L)
    sens = amb if p["collocated"] else (amb[0] - 0.08 * L, amb[1] + 0.08 * L)
    disks = [("wheel", 0.45 * L, 0.60 * m, p["ip_wheel"], id_wheel),
             ("motor", 0.70 * L, 0.10 * m, 0.10 * m * (0.25 * p["r_wheel_m"]) ** 2,
              0.10 * m * (0.25 * p["r_wheel_m"]) ** 2),
             ("AMB A laminations", amb[0], 0.05 * m, 0.05 * m * (0.3 * p["r_wheel_m"]) ** 2,
              0.025 * m * (0.3 * p["r_wheel_m"]) ** 2),
             ("AMB B laminations", amb[1], 0.05 * m, 0.05 * m * (0.3 * p["r_wheel_m"]) ** 2,
              0.025 * m * (0.3 * p["r_wheel_m"]) ** 2)]
    ks = p["ki"] * p["bias_a"] / p["air_gap_m"]
    top_hz = p["top_rpm"] / 60.0
    out = [f'[rotor]\nname = "family rig {p["seed"]}"\nbeam = "timoshenko"\n'
           'modal_damping = 0.005\n',
           "[materials.steel]\n" + "".join(f"{k} = {v!r}\n" for k, v in STEEL.items()),
           f'[[shaft]]\nlength = {L!r}\nouter_diameter = {d_o!r}\n'
           f'inner_diameter = {0.6 * d_o!r}\nmaterial = "steel"\nelements = 16\n']
    out += [f'[[disk]]\nname = "{n}"\nposition = {z!r}\nmass = {mm!r}\nIp = {ip!r}\n'
            f'Id = {idd!r}\n' for n, z, mm, ip, idd in disks]
    out += [f'[[amb]]\nname = "{n}"\nposition = {z!r}\nsensor_position = {s!r}\n'
            f'ki = {p["ki"]!r}\nks = {ks!r}\nbias_current = {p["bias_a"]!r}\n'
            f'current_limit = {2 * p["bias_a"]!r}\nair_gap = {p["air_gap_m"]!r}\n'
            for n, z, s in zip("AB", amb, sens)]
    out.append(f'[actuator]\nmodel = "first_order"\ncutoff_hz = {p["rate_hz"] / 10!r}\n')
    out.append(f'[controller]\nsample_rate_hz = {p["rate_hz"]!r}\ndelay_samples = 1\n')
    out.append(f'[machine]\norientation = "{p["orientation"]}"\n')
    out.append(f'[operating]\nspeed_rpm = {p["top_rpm"]!r}\npressure_bar = 0.0\n'
               f'speed_range_hz = [{top_hz / 3!r}, {top_hz!r}]\n')
    return "\n".join(out)


def _inertias(cfg) -> tuple[float, float]:
    """(I_p, I_t about the centre of mass) of the rig's rotor as a rigid body."""
    from ambseal.model.rotor import assemble_rotor

    M, G, _ = assemble_rotor(cfg).rigid()
    m, z_g = M[0, 0], M[0, 2] / M[0, 0]
    return float(abs(G[2, 3])), float(M[2, 2] - m * z_g**2)


def family_rig(seed: int) -> tuple[str, dict]:
    """The rig file (TOML text) of one seed of the family and its draw (module docstring).

    Returns
    -------
    (str, dict)
        The rig file's text; the draw with ``ip_over_it``, ``bending_hz`` and
        ``bending_per_top`` as built.
    """
    from ambseal.config import parse_rig
    from ambseal.model.modes import free_bending_hz

    rng = np.random.default_rng(seed)
    while True:
        p = {"seed": seed, "mass_kg": float(rng.uniform(5, 30)),
             "length_m": float(rng.uniform(0.25, 0.6)),
             "ip_over_it": float(rng.uniform(0.5, 1.5)),
             "top_rpm": float(rng.uniform(20000, 100000)),
             "bending_per_top": float(rng.uniform(1.2, 3.0)),
             "rate_hz": float(rng.choice(RATES_HZ)),
             "collocated": bool(rng.integers(2)),
             "air_gap_m": 5e-4, "bias_a": 2.5}
        # I_t of the motor and laminations about the wheel (point masses): what the wheel's
        # Ip must outweigh, with Id = Ip/2, for Ip/It = q: Ip ≥ q·It_rest/(1 − q/2)
        m, L, q = p["mass_kg"], p["length_m"], p["ip_over_it"]
        rest = m * L**2 * (0.10 * 0.25**2 + 0.05 * (0.33**2 + 0.43**2))
        least = math.sqrt(q * rest / (1 - q / 2) / (0.6 * m))
        p["r_wheel_m"] = max(float(rng.uniform(1.0, 1.5)) * least, 0.1 * L)
        p["ip_wheel"] = 0.6 * m * p["r_wheel_m"] ** 2
        p["orientation"] = str(rng.choice(["horizontal", "vertical"]))
        omega = 2 * math.pi * p["top_rpm"] / 60
        weight = GRAVITY if p["orientation"] == "horizontal" else 0.0
        share = p["mass_kg"] / 2 * (weight + GRADE_M_S * omega)
        p["ki"] = 3 * share / p["bias_a"]
        built = _solve(p, parse_rig, free_bending_hz)
        if built is not None:
            return built


def _solve(p: dict, parse_rig, free_bending_hz):
    """The rig of draw ``p`` with its bending frequency and Ip/It met, or None where the
    wheel would need less than a thin disc's diametral inertia."""

    def build(d_o: float):
        # the wheel's Id for the draw's Ip/It, with this shaft: solved by the linear
        # dependence of I_t on Id (one evaluation at Id = 0 and one at 1)
        cfgs = [parse_rig(tomllib.loads(_rig_text(p, d_o, x)), "family.toml") for x in (0, 1)]
        (ip0, it0), (_, it1) = map(_inertias, cfgs)
        idw = (ip0 / p["ip_over_it"] - it0) / (it1 - it0)
        if idw < p["ip_wheel"] / 2:
            return None
        text = _rig_text(p, d_o, idw)
        return text, parse_rig(tomllib.loads(text), "family.toml")

    target = p["bending_per_top"] * p["top_rpm"] / 60
    lo, hi = 0.01, 0.3  # m: the bending frequency rises with the diameter
    for _ in range(40):
        mid = math.sqrt(lo * hi)
        b = build(mid)
        if b is None:
            return None
        f = free_bending_hz(b[1], 1)[0]
        lo, hi = (mid, hi) if f < target else (lo, mid)
        if hi / lo < 1 + 1e-4:
            break
    text, cfg = b
    ip, it = _inertias(cfg)
    return text, {**p, "outer_diameter_m": mid, "ip_over_it": ip / it,
                  "bending_hz": f, "bending_per_top": f / (p["top_rpm"] / 60)}


def example_rigs() -> list[tuple[str, dict]]:
    """The example flywheel as its file stands, at 10, 20 and 40 kHz."""
    text = (ROOT / "examples" / "flywheel.toml").read_text(encoding="utf-8")
    assert text.count("sample_rate_hz = 20000.0") == 1
    return [(text.replace("sample_rate_hz = 20000.0", f"sample_rate_hz = {fs!r}"),
             {"seed": f"flywheel@{fs / 1000:g}kHz", "rate_hz": fs}) for fs in RATES_HZ]


def delivered(metrics: dict) -> dict[str, bool]:
    """Per method: delivered as it runs, standstill to the top speed, zone A or B on
    every axis (module docstring)."""
    return {m: why is None for m, why in why_not(metrics).items()}


def why_not(metrics: dict) -> dict[str, str | None]:
    """Per method: None where it is delivered (:func:`delivered`), else why not — not
    designed, its failure's or its target's reason, or the worst axis's σ̄(S_o) peak as it
    runs at zone C or D, with its condition."""
    out: dict[str, str | None] = {}
    for m in METHODS:
        if m not in metrics["controllers"]:
            out[m] = "not designed"
        elif m in metrics["failed"]:
            out[m] = f"failed: {metrics['failed'][m]['reason']}"
        elif m in metrics["cannot_run"]:
            out[m] = f"cannot run: {metrics['cannot_run'][m]}"
        else:
            peaks = [(v, axis, c["speed_hz"], c["pressure_bar"])
                     for c in metrics["cases"] + metrics.get("stability", [])
                     if c["controller"] == m
                     for axis, v in (c.get("discrete") or c)["sensitivity_peak_per_axis"]
                     .items()]
            worst = max(peaks, default=None)
            out[m] = ("no judged case" if worst is None else None if worst[0] < ZONE_B_LIMIT
                      else f"zone C/D: σ̄(S_o) {worst[0]:.3g} on {worst[1]} at "
                           f"{worst[2]:g} Hz, {worst[3]:g} bar")
    return out


def run_rig(case: dict, timeout: float) -> dict:
    """One rig's ``ambseal run --no-identify`` in a child process: its row."""
    row = {k: v for k, v in case["draw"].items()}
    with tempfile.TemporaryDirectory(prefix="ambseal-family-") as tmp:
        rig = Path(tmp) / "rig.toml"
        rig.write_text(case["text"], encoding="utf-8")
        cmd = [sys.executable, "-c", "import sys; from ambseal.cli import main; "
               "sys.exit(main(sys.argv[1:]))", "run", str(rig), "--no-identify",
               "--out", str(Path(tmp) / "run")]
        ref0 = machine_reference()
        try:
            wall, code, tail, cpu = timed_child(cmd, Path(tmp), child_env(), timeout)
        except subprocess.TimeoutExpired:
            return {**row, "timed_out": True, "timeout_s": timeout}
        ref = (ref0 + machine_reference()) / 2
        metrics = Path(tmp) / "run" / "metrics.json"
        m = json.loads(metrics.read_text()) if metrics.is_file() else None
        row.update(returncode=code, wall_s=wall, cpu_s=cpu, cpu_per_reference=cpu / ref)
        if m is None:
            row["error"] = (tail.splitlines() or ["no output"])[-1]
        else:
            row["delivered"] = delivered(m)
            row["why_not"] = {k: v for k, v in why_not(m).items() if v is not None}
            row["failed"] = {k: v["reason"] for k, v in m["failed"].items()}
            row["cannot_run"] = m["cannot_run"]
    return row


def summary(rows: list[dict]) -> dict:
    """The family's fractions delivered per method, the rigs with none, and the CPU."""
    ok = [r for r in rows if "delivered" in r]
    return {"case": "family", "rigs": len(rows), "ran": len(ok),
            "delivered_fraction": {m: sum(r["delivered"][m] for r in ok) / max(len(rows), 1)
                                   for m in METHODS},
            "none_delivered": [r["seed"] for r in rows
                               if not any((r.get("delivered") or {}).values())],
            "cpu_per_reference": {"median": float(np.median([r["cpu_per_reference"]
                                                             for r in ok])) if ok else None,
                                  "max": max((r["cpu_per_reference"] for r in ok),
                                             default=None)}}


def family_parser(doc: str, seeds: str) -> argparse.ArgumentParser:
    """The options of a family's benchmark: ``--seeds`` (default ``seeds``), ``--workers``,
    ``--scheduler``, ``--timeout`` and ``--write-only``; described by ``doc``'s first
    paragraph."""
    ap = argparse.ArgumentParser(description=doc.split("\n\n")[0])
    ap.add_argument("--seeds", default=seeds, help=f"a:b, the seeds a … b−1 (default {seeds})")
    ap.add_argument("--workers", type=int, default=1, help="local Dask workers (1: serial)")
    ap.add_argument("--scheduler", default=None, help="a running Dask scheduler's address")
    ap.add_argument("--timeout", type=float, default=3600.0, help="seconds per rig")
    ap.add_argument("--write-only", default=None, metavar="DIR",
                    help="write the rig files to DIR and run nothing")
    return ap


def main(argv=None) -> int:
    ap = family_parser(__doc__, "0:24")
    ap.add_argument("--no-examples", action="store_true",
                    help="leave out the example flywheel at 10, 20 and 40 kHz")
    args = ap.parse_args(argv)
    a, b = (int(x) for x in args.seeds.split(":"))
    rigs = [family_rig(s) for s in range(a, b)] + ([] if args.no_examples else example_rigs())
    return run_family(rigs, args, "family")


def run_family(rigs: list[tuple[str, dict]], args: argparse.Namespace, name: str) -> int:
    """Each rig (its file's text and its draw) written as ``DIR/<name>_<seed>.toml`` with
    ``--write-only DIR``, else run (:func:`run_rig`: serially, or on a Dask cluster) with a
    JSON line per rig and the family's :func:`summary` last."""
    from ambseal.analysis.cases import run_cases

    if args.write_only:
        out = Path(args.write_only)
        out.mkdir(parents=True, exist_ok=True)
        for text, draw in rigs:
            (out / f"{name}_{draw['seed']}.toml").write_text(text, encoding="utf-8")
            print(json.dumps(draw), flush=True)
        return 0
    cases = [{"text": t, "draw": d} for t, d in rigs]
    log(f"{len(cases)} rigs")
    rows = run_cases(run_rig, cases, shared={"timeout": args.timeout}, workers=args.workers,
                     scheduler=args.scheduler, progress=False,
                     on_done=lambda i, r: print(json.dumps(r), flush=True))
    rows = [r if isinstance(r, dict) else {"seed": cases[i]["draw"]["seed"], "error": r.error}
            for i, r in enumerate(rows)]
    print(json.dumps(summary(rows)), flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
