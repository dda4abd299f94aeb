"""Benchmark: ``ambseal run --no-identify`` on a seeded family of flexible multi-stage
compressors nobody tuned the code for: per method the fraction delivered, and the CPU in
machine references against the time goal.

The generator (:func:`compressor_rig`, one rig per seed, ``numpy.random.default_rng(seed)``)
draws a centrifugal compressor of the process-gas class on two radial AMBs and writes it
as a rig file from the manual's keys alone, as a user would:

* **the impellers**: 3 to 8, in line or back to back (the two sections facing each other,
  split as evenly as the count allows), closed impellers of diameter D from 0.25 to 0.5 m,
  mass 150–200·D³ kg (the b2b example's 16 kg at 450 mm is 176·D³), I_p = 1.1·m(D/2)²/2
  and I_d = 0.53·I_p (a closed impeller's hub included), 0.22·D apart; a back-to-back
  machine has a division-wall sleeve at mid-span;
* **the top speed** (the maximum continuous speed) from an impeller tip speed of 220 to
  320 m/s: N = 60·u/(π·D); the speed range from 0.63 of it (the minimum continuous speed)
  to 1.01 of it;
* **the shaft**: thrust stub, journal of AMB A, body, journal of AMB B, drive stub, the
  journals 0.85 and the stubs 0.68 of the body's diameter; the body's diameter bisected on
  ambseal's own free–free model (:func:`ambseal.model.modes.free_bending_hz`) so that the
  first free–free bending mode lies at 1.2 to 2 times the top speed (drawn); 40 to 60
  elements (drawn), spread over the sections by their length; the thrust collar, the AMBs'
  laminations and a coupling hub as disks;
* **the AMBs**: air gap 0.4–0.6 mm, bias current 5–10 A, current limit twice the bias, Ki
  such that the bias current's linear range Ki·i0 holds 3 to 5 times each bearing's share
  of the weight (drawn), Ks = Ki·i0/s0 (Schweitzer & Maslen 2009, §3.3), the coil's
  inductance Ki·s0/(2·i0·cos 22.5°) of an 8-pole bearing (the b2b example's rule) on a
  300 V amplifier, 0.4 Ω; first-order amplifiers with a cut-off of 1 to 2 kHz; sensors
  collocated or 0.1 m outboard (drawn);
* **the seals**: the division wall (back to back) or the balance piston (in line, beside
  the last impeller), its cross-coupled stiffness k at twice the nominal pressure drop
  drawn from 0.3 to 1 times the AMB's negative stiffness Ks, K = 0.2·k, C from a
  whirl-frequency ratio k/(C·Ω) of 0.5 at the top speed, radial clearance 1.5 mils per
  inch of the body's diameter; impeller-eye labyrinths at a tenth of that; the nominal
  pressure drop from 30 to 60 bar, so the judged map reaches 60 to 120 bar;
* **the stages** for API 617 Level I: 2 to 10 MW in all, discharge widths narrowing from
  0.05·D to 0.03·D, densities from a suction density of 10 to 30 kg/m³ rising 1.3 times
  per stage;
* **the target**: 10 or 20 kHz (drawn), one sample of delay.

Each rig runs as :mod:`bench_family`'s rows do (:func:`bench_family.run_rig`: a child
process, one BLAS thread; serially or on a Dask cluster through the sweep's executor, the
same rows either way): one JSON line per rig with the draw, the exit status, CPU in
machine references and per method ``delivered`` (zone A or B on every axis at every
judged condition, as it runs) or why not; the last line sums the family.

Run from the repository root: ``PYTHONPATH=src python benchmarks/bench_compressors.py
[--seeds 0:12] [--workers N | --scheduler ADDR] [--write-only DIR]``.
"""

from __future__ import annotations

import math
import sys
import tomllib
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
from bench_family import family_parser, run_family  # noqa: E402

STEEL = {"E": 2.11e11, "rho": 7810.0, "nu": 0.3}
GRAVITY = 9.81
RATES_HZ = (10000.0, 20000.0)
#: the half angle between an 8-pole radial bearing's poles and its axis (rad)
POLE_ANGLE = math.radians(22.5)


def _layout(p: dict) -> dict:
    """Axial positions (m from the thrust end) of draw ``p``: shaft sections, impellers,
    bearings, sensors, seals; a fixed fraction of the impeller diameter for each gap."""
    D, n = p["impeller_m"], p["impellers"]
    pitch = 0.22 * D
    stub, journal = 0.1, 0.2 + 0.2 * D
    if p["back_to_back"]:
        n1 = (n + 1) // 2  # at least three impellers: both sections have one
        wall = 1.6 * pitch  # the division wall between the two sections
        body = (n - 2) * pitch + wall + D
        start = stub + journal + 0.5 * D
        imp = [start + i * pitch for i in range(n1)]
        imp += [imp[-1] + wall + i * pitch for i in range(n - n1)]
        main_seal = (imp[n1 - 1] + imp[n1]) / 2
    else:
        body = (n - 1) * pitch + D + 0.6 * pitch  # the balance piston beside the last
        start = stub + journal + 0.5 * D
        imp = [start + i * pitch for i in range(n)]
        main_seal = imp[-1] + 0.6 * pitch
    sections = [stub, journal, body, journal, stub]
    ends = [float(x) for x in np.cumsum(sections)]
    amb = (stub + 0.5 * journal, ends[2] + 0.5 * journal)
    sensors = amb if p["collocated"] else (amb[0] - 0.1, amb[1] + 0.1)
    return {"sections": sections, "length": ends[-1], "impellers": imp,
            "amb": amb, "sensors": sensors, "main_seal": main_seal,
            "eye": imp[-1] if not p["back_to_back"] else imp[len(imp) // 2]}


def _elements(sections, total: int) -> list[int]:
    """``total`` elements spread over the sections by their length, at least two each."""
    L = sum(sections)
    raw = [max(2, round(total * s / L)) for s in sections]
    i = int(np.argmax(raw))
    raw[i] += total - sum(raw)
    return raw


def _rig_text(p: dict, d_body: float) -> str:
    """The rig file of draw ``p`` with the body's diameter ``d_body`` (m)."""
    lay = _layout(p)
    D, m_imp = p["impeller_m"], p["impeller_kg"]
    ip_imp = 1.1 * m_imp * (D / 2) ** 2 / 2
    diam = [0.68 * d_body, 0.85 * d_body, d_body, 0.85 * d_body, 0.68 * d_body]
    out = [f'[rotor]\nname = "compressor family rig {p["seed"]}"\nbeam = "timoshenko"\n'
           'modal_damping = 0.005\n',
           "[materials.steel]\n" + "".join(f"{k} = {v!r}\n" for k, v in STEEL.items())]
    out += [f'[[shaft]]\nlength = {s!r}\nouter_diameter = {d!r}\nmaterial = "steel"\n'
            f'elements = {e}\n'
            for s, d, e in zip(lay["sections"], diam, _elements(lay["sections"],
                                                                p["elements"]))]
    lam_m = 7800 * math.pi / 4 * ((1.6 * diam[1]) ** 2 - diam[1] ** 2) * 0.1
    r_lam = 0.8 * diam[1]
    disks = [("thrust collar", 0.5 * lay["sections"][0], 0.9 * lam_m * 0.6,
              0.5 * 0.9 * lam_m * 0.6 * (1.1 * d_body) ** 2,
              0.25 * 0.9 * lam_m * 0.6 * (1.1 * d_body) ** 2)]
    disks += [(f"AMB {n} laminations", z, lam_m, 0.5 * lam_m * r_lam ** 2,
               0.25 * lam_m * r_lam ** 2 + lam_m * 0.1 ** 2 / 12)
              for n, z in zip("AB", lay["amb"])]
    disks += [(f"impeller {i + 1}", z, m_imp, ip_imp, 0.53 * ip_imp)
              for i, z in enumerate(lay["impellers"])]
    disks.append(("coupling hub", lay["length"] - 0.5 * lay["sections"][-1], 0.4 * m_imp,
                  0.15 * ip_imp, 0.1 * ip_imp))
    if p["back_to_back"]:
        disks.append(("division-wall sleeve", lay["main_seal"], 0.5 * m_imp, 0.13 * ip_imp,
                      0.09 * ip_imp))
    out += [f'[[disk]]\nname = "{n}"\nposition = {z!r}\nmass = {mm!r}\nIp = {a!r}\n'
            f'Id = {b!r}\n' for n, z, mm, a, b in disks]
    mass = p["mass_kg"] = _mass(diam, lay, disks)
    i0, s0 = p["bias_a"], p["air_gap_m"]
    ki = p["load_factor"] * mass * GRAVITY / 2 / i0
    ks = ki * i0 / s0
    induct = ki * s0 / (2 * i0 * math.cos(POLE_ANGLE))
    p.update(ki=ki, ks=ks)
    out += [f'[[amb]]\nname = "{n}"\nposition = {z!r}\nsensor_position = {s!r}\n'
            f'ki = {ki!r}\nks = {ks!r}\nbias_current = {i0!r}\ncurrent_limit = {2 * i0!r}\n'
            f'air_gap = {s0!r}\nsupply_voltage = 300.0\ninductance = {induct!r}\n'
            'resistance = 0.4\n' for n, z, s in zip("AB", lay["amb"], lay["sensors"])]
    out.append(f'[actuator]\nmodel = "first_order"\ncutoff_hz = {p["amplifier_hz"]!r}\n')
    top = p["top_rpm"] / 60.0
    p_nom = p["pressure_bar"]
    k_bar = p["seal_k_per_ks"] * ks / (2 * p_nom)
    c_bar = k_bar / (0.5 * 2 * math.pi * top)
    clearance = 0.0015 * d_body
    name = "division_wall" if p["back_to_back"] else "balance_piston"
    out.append(f'[[seal]]\nname = "{name}"\nposition = {lay["main_seal"]!r}\n'
               f'clearance = {clearance!r}\nK = {{ at_zero = 0.0, per_bar = {0.2 * k_bar!r} }}'
               f'\nk = {{ at_zero = 0.0, per_bar = {k_bar!r} }}\n'
               f'C = {{ at_zero = 100.0, per_bar = {c_bar!r} }}\n')
    out.append(f'[[seal]]\nname = "eye_labyrinths"\nposition = {lay["eye"]!r}\n'
               f'clearance = {clearance * 1.1!r}\n'
               f'k = {{ at_zero = 0.0, per_bar = {0.1 * k_bar!r} }}\n'
               f'C = {{ at_zero = 50.0, per_bar = {0.1 * c_bar!r} }}\n')
    out.append('[machine]\nkind = "compressor"\n')
    n = p["impellers"]
    rho = p["suction_density"]
    for i in range(n):
        width = D * (0.05 - 0.02 * i / max(n - 1, 1))
        out.append(f'[[stage]]\ndisk = "impeller {i + 1}"\npower = {p["power_w"] / n!r}\n'
                   f'impeller_diameter = {D!r}\ndischarge_width = {width!r}\n'
                   f'suction_density = {rho!r}\ndischarge_density = {1.3 * rho!r}\n')
        rho *= 1.3
    out.append(f'[controller]\nsample_rate_hz = {p["rate_hz"]!r}\ndelay_samples = 1\n')
    out.append(f'[operating]\nspeed_rpm = {p["top_rpm"]!r}\npressure_bar = {p_nom!r}\n'
               f'speed_range_hz = [{0.63 * top!r}, {1.01 * top!r}]\n')
    return "\n".join(out)


def _mass(diam, lay: dict, disks) -> float:
    """The rotor's mass (kg): the shaft's sections (outside diameters ``diam``) and the
    disks."""
    shaft = sum(STEEL["rho"] * math.pi / 4 * d ** 2 * s for s, d in zip(lay["sections"], diam))
    return float(shaft + sum(d[2] for d in disks))


def compressor_rig(seed: int) -> tuple[str, dict]:
    """The rig file (TOML text) of one seed of the family and its draw (module docstring).

    Returns
    -------
    (str, dict)
        The rig file's text; the draw with ``body_diameter_m``, ``mass_kg``, ``bending_hz``
        and ``bending_per_top`` as built.
    """
    from ambseal.config import parse_rig
    from ambseal.model.modes import free_bending_hz

    rng = np.random.default_rng(seed)
    D = float(rng.uniform(0.25, 0.5))
    p = {"seed": seed, "impellers": int(rng.integers(3, 9)),
         "back_to_back": bool(rng.integers(2)), "impeller_m": D,
         "impeller_kg": float(rng.uniform(150, 200)) * D ** 3,
         "tip_speed_m_s": float(rng.uniform(220, 320)),
         "bending_per_top": float(rng.uniform(1.2, 2.0)),
         "elements": int(rng.integers(40, 61)),
         "air_gap_m": float(rng.uniform(4e-4, 6e-4)), "bias_a": float(rng.uniform(5, 10)),
         "load_factor": float(rng.uniform(3, 5)),
         "amplifier_hz": float(rng.uniform(1000, 2000)),
         "collocated": bool(rng.integers(2)),
         "pressure_bar": float(rng.uniform(30, 60)),
         "seal_k_per_ks": float(rng.uniform(0.3, 1.0)),
         "power_w": float(rng.uniform(2e6, 1e7)),
         "suction_density": float(rng.uniform(10, 30)),
         "rate_hz": float(rng.choice(RATES_HZ))}
    p["top_rpm"] = 60 * p["tip_speed_m_s"] / (math.pi * D)
    target = p["bending_per_top"] * p["top_rpm"] / 60
    lo, hi = 0.05, 0.6  # m: the bending frequency rises with the diameter
    while hi / lo > 1 + 1e-3:
        mid = math.sqrt(lo * hi)
        text = _rig_text(p, mid)
        f = free_bending_hz(parse_rig(tomllib.loads(text), "compressor.toml"), 1)[0]
        lo, hi = (mid, hi) if f < target else (lo, mid)
    text = _rig_text(p, mid)
    return text, {**p, "body_diameter_m": mid, "bending_hz": f,
                  "bending_per_top": f / (p["top_rpm"] / 60)}


def main(argv=None) -> int:
    args = family_parser(__doc__, "0:12").parse_args(argv)
    a, b = (int(x) for x in args.seeds.split(":"))
    return run_family([compressor_rig(s) for s in range(a, b)], args, "compressor")


if __name__ == "__main__":
    sys.exit(main())
