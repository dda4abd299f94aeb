"""Write ROSS 3.1 rotor files and ROSS 3.1's eigenvalues beside them, with which the tests
check ambseal's reader of ROSS 3 files on a Python without ROSS 3 (Python 3.11: ROSS 2.3).

Run with ROSS 3.1 installed (Python 3.13): ``python tests/data/ross3/make.py``. The rotor:
ROSS's ``rotor_example`` on two bearings tabulated over speed (linear and pchip, a
stiffness and a damping beyond the table: ROSS extrapolates) and a seal tabulated over
speed and whirl frequency, with the rotor's own Rayleigh damping; its eigenvalues those of
ROSS's ``Rotor._eigen(speed, sparse=False)`` (the |λ| of ``run_modal(speed).wn``) at 150,
300 and 400 rad/s, points of the seal's table, where ambseal's table of ROSS's values is
exact.
"""

import contextlib
import json
import sys
import warnings
from pathlib import Path

import numpy as np

with contextlib.redirect_stdout(sys.stderr), warnings.catch_warnings():
    warnings.simplefilter("ignore")
    import ross as rs

HERE = Path(__file__).parent
SPEEDS_RAD_S = (150.0, 300.0, 400.0)
#: rotor_seals' labyrinth is tabulated at 523.6 and 837.8 rad/s: below, on, between and
#: beyond its points (ROSS continues it with its end slopes)
SEALS_SPEEDS_RAD_S = (300.0, 523.6, 700.0, 900.0)


def seals_rotor():
    """ROSS's own ROSS 2 test rotor with seals (``tests/data/v2/rotor_seals.toml``: a
    labyrinth seal tabulated at two speeds, a hole-pattern seal with cross mass), as
    ROSS 3.1's ``ross_2to3`` converts it."""
    from ross.ross_2to3 import Report, convert_model_text

    src = Path(rs.__file__).parent / "tests" / "data" / "v2" / "rotor_seals.toml"
    text = convert_model_text(src.read_text(), ".toml", Report(), path=src,
                              version=rs.__version__)
    tmp = HERE / "_seals_converted.toml"
    tmp.write_text(text)
    try:
        return rs.Rotor.load(tmp)
    finally:
        tmp.unlink()


def modal_rotor():
    """ROSS 3.1's ``test_modal_damping`` rotor with 14 modal damping ratios, which ROSS
    counts over its torsional and axial modes too (its 5th flexible mode is torsional)."""
    shaft = [rs.ShaftElement(0.25, 0, 0.05, material=rs.materials.steel, shear_effects=True,
                             rotary_inertia=True, gyroscopic=True) for _ in range(6)]
    disks = [rs.DiskElement.from_geometry(2, rs.materials.steel, 0.07, 0.05, 0.28),
             rs.DiskElement.from_geometry(4, rs.materials.steel, 0.07, 0.05, 0.35)]
    bearings = [rs.BearingElement(n, kxx=1e6, kyy=0.8e6, cxx=0) for n in (0, 6)]
    return rs.Rotor(shaft, disks, bearings,
                    modal_damping_ratio=[0.001 * (k + 1) for k in range(14)],
                    default_damping_ratio=0.03)


def rotor():
    speed, freq = np.array([100.0, 300.0, 500.0]), np.array([150.0, 400.0])
    grid = np.add.outer(speed, 2 * freq)
    seal = rs.BearingElement(n=3, kxx=2e6 + 1e3 * grid, kyy=2e6 + 1e3 * grid,
                             kxy=5e5 + 50 * grid, kyx=-(5e5 + 50 * grid),
                             cxx=80 + 0.1 * grid, cyy=80 + 0.1 * grid, speed=speed,
                             frequency=freq, tag="seal")
    bearings = [rs.BearingElement(n=n, kxx=[1e6, 3e6, 4e6], kyy=[8e5, 1e6, 2e6],
                                  cxx=[150.0, 120.0, 200.0], cyy=90.0,
                                  speed=[50.0, 200.0, 900.0], interpolation=kind,
                                  tag=f"B{n}") for n, kind in ((0, "linear"), (6, "pchip"))]
    ex = rs.rotor_example()
    return rs.Rotor(ex.shaft_elements, ex.disk_elements, [*bearings, seal], alpha=2.0,
                    beta=1e-5)


#: ROSS 3.1's API 617 unbalance placement: its examples at their maximum continuous
#: speed (rpm), the first three forward modes
API617 = {"rotor_example": 9000.0, "compressor_example": 12000.0}


def api617_placements() -> dict:
    """ROSS 3.1's ``api617_unbalance`` of its own examples: per mode the damped frequency
    (rad/s), the unbalances' axial positions (m), magnitudes (kg·m), phases (rad) and the
    loads W (kg); under ``journal_loads`` each example's journal static loads ``[[z m, kg],
    …]`` as ``run_static`` gives them (its bearings' reactions over g)."""
    out = {"ross_version": rs.__version__, "journal_loads": {}}
    for name, rpm in API617.items():
        rotor = getattr(rs, name)()
        out["journal_loads"][name] = [[float(rotor.nodes_pos[n]), w] for n, w in
                                      sorted(rotor._journal_bearing_loads().items())]
        rows = []
        for mode in range(3):
            u = rotor.api617_unbalance(mode, rpm * np.pi / 30, num_modes=24)
            rows.append({"mode_frequency": u["mode_frequency"],
                         "position": [float(rotor.nodes_pos[n]) for n in u["node"]],
                         "magnitude": [float(x) for x in u["unbalance_magnitude"]],
                         "phase": [float(x) for x in u["unbalance_phase"]],
                         "static_load": [float(x) for x in u["static_load"]]})
        out[name] = rows
    return out


#: The Level I screenings: ``rotor_example`` on two damped bearings, screened at 600 rad/s
#: with the cross-coupling at mid-span (node 3), where API 617 applies it for a rotor
#: between bearings; ROSS's ``compressor_example`` at its maximum continuous speed,
#: 12 000 rpm, with its twelve seals left out as API 617 Level I leaves them (ROSS's
#: ``run_level1`` keeps them), the cross-coupling at node 27 (0.806 m), the node nearest
#: mid-span that ROSS takes. Per rotor: (speed rad/s, node, the anticipated Q_A N/m the
#: test's stage gives, the top of Brent's bracket N/m)
LEVEL1 = {"level1": (600.0, 3, 1e4, 1e5),
          "level1_compressor": (400.0 * np.pi, 27, 1e6, 1e7)}


def level1_rotor():
    ex = rs.rotor_example()
    bearings = [rs.BearingElement(n=n, kxx=1e6, kyy=0.8e6, cxx=500.0, cyy=500.0,
                                  tag=f"B{n}") for n in (0, 6)]
    return rs.Rotor(ex.shaft_elements, ex.disk_elements, bearings)


def level1_reference(rotor, speed_rad_s, node, q_a, q_hi, seals=True) -> dict:
    """ROSS 3.1's ``run_level1`` on ``rotor`` (without its ``SealElement``s unless
    ``seals``): the log decrement of the first mode that does not whirl backward with Q
    (``k_xy = Q``, ``k_yx = −Q``) at ``node``, at Q = 0, at ``q_a`` and its zero Q_0
    (Brent's method on ROSS's own evaluation within [0, ``q_hi``], as ``run_level1``
    builds each rotor)."""
    from copy import copy

    from scipy.optimize import brentq

    kept = [b for b in rotor.bearing_elements if seals or not isinstance(b, rs.SealElement)]

    def first(Q):
        bearings = [copy(b) for b in kept]
        bearings.append(rs.BearingElement(n=node, kxx=0, cxx=0, kxy=Q, kyx=-Q))
        r = rotor.__class__(rotor.shaft_elements, rotor.disk_elements, bearings,
                            rotor.point_mass_elements)
        m = r.run_modal(speed=speed_rad_s)
        non_backward = m.whirl_direction() != "Backward"
        return float(m.log_dec[non_backward][0]), float(m.wd[non_backward][0])

    q0 = brentq(lambda q: first(q)[0], 0.0, q_hi, xtol=1e-6, rtol=1e-12)
    return {"ross_version": rs.__version__, "speed_rad_s": speed_rad_s, "node": node,
            "position_m": float(rotor.nodes_pos[node]), "seals": seals,
            "log_dec_at_0": first(0.0)[0], "wd_at_0": first(0.0)[1],
            "Q_A": q_a, "log_dec_A": first(q_a)[0], "Q_0": q0}


if __name__ == "__main__":
    with contextlib.redirect_stdout(sys.stderr), warnings.catch_warnings():
        warnings.simplefilter("ignore")
        for name, r, speeds in (("tables", rotor(), SPEEDS_RAD_S),
                                ("modal", modal_rotor(), SPEEDS_RAD_S),
                                ("seals", seals_rotor(), SEALS_SPEEDS_RAD_S)):
            r.save(HERE / f"{name}.toml")
            out = {"ross_version": rs.__version__}
            for w in speeds:
                lam, _ = r._eigen(w, sparse=False)
                out[f"{w:g}"] = [[float(x.real), float(x.imag)] for x in np.asarray(lam)]
            rows = ",\n".join(f"{json.dumps(k)}: {json.dumps(v)}" for k, v in out.items())
            (HERE / f"{name}_eigenvalues.json").write_text("{\n" + rows + "\n}\n")
        (HERE / "api617_unbalance.json").write_text(
            json.dumps(api617_placements(), indent=1) + "\n")
        for name, r, seals in (("level1", level1_rotor(), True),
                               ("level1_compressor", rs.compressor_example(), False)):
            r.save(HERE / f"{name}.toml")
            (HERE / f"{name}.json").write_text(
                json.dumps(level1_reference(r, *LEVEL1[name], seals=seals), indent=1) + "\n")
