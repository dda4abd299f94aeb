"""The embedded test facility meshed finer: its rig file with the ``[[shaft]]`` sections'
``elements`` raised to a given number of beam elements in all (a long rotor, a mesh
convergence check), and that rotor on plain bearings with its ROSS twin (the ROSS
comparison of tests/io/test_io_ross.py and benchmarks/bench_model.py)."""

import contextlib
import re
import sys
import tomllib
import warnings

from ambseal.config import default_rig_path


def fine_rig_text(total: int) -> str:
    """The embedded rig file's text with ``total`` beam elements in the whole shaft: each
    section but the longest gets its share by length (rounded, at least 1), the longest the
    rest; every other line (comments included) unchanged."""
    text = default_rig_path().read_text(encoding="utf-8")
    lengths = [float(x) for x in re.findall(r"^\[\[shaft\]\]\nlength = ([0-9.eE+-]+)",
                                            text, flags=re.M)]
    share = [max(1, round(total * x / sum(lengths))) for x in lengths]
    longest = lengths.index(max(lengths))
    share[longest] = total - (sum(share) - share[longest])
    counts = iter(share)
    out, n = re.subn(r"^elements = \d+$", lambda m: f"elements = {next(counts)}", text,
                     flags=re.M)
    assert n == len(lengths) == 3, "the embedded rig's [[shaft]] sections changed"
    return out


#: Plain bearings of the fine-mesh comparison with ROSS (anisotropic and damped).
FINE_BEARING = {"kxx": 1.0e6, "kyy": 0.8e6, "cxx": 150.0, "cyy": 90.0}


def fine_bearing_data(total: int) -> dict:
    """The embedded rotor — shaft and disks — meshed with ``total`` beam elements, on two
    plain bearings at its AMBs' positions instead of AMBs, seal and coupling (ROSS's AMB
    model is not the reference), without modal damping (ROSS has none): rig-file data."""
    data = tomllib.loads(fine_rig_text(total))
    data["rotor"]["modal_damping"] = 0.0
    data["spring"] = [{"position": a["position"], "name": f"bearing_{a['name']}",
                       **FINE_BEARING} for a in data.pop("amb")]
    for key in ("seal", "controller", "design"):
        data.pop(key, None)
    return data


def fine_ross_rotor(rs, cfg):
    """The rig ``cfg`` (of :func:`fine_bearing_data`) in ROSS (module ``rs``), element by
    element on ambseal's mesh (Cowper's shear coefficient on both sides): (rotor, number of
    beam elements)."""
    from ambseal.model.rotor import build_mesh

    mesh = build_mesh(cfg)
    (mat,) = cfg.materials.values()
    steel = rs.Material(name="fine_steel", rho=mat.rho, E=mat.E, G_s=mat.shear_modulus)
    shafts = [rs.ShaftElement(L=e.length, idl=e.inner_diameter, odl=e.outer_diameter,
                              material=steel, n=i, shear_method_calc="cowper")
              for i, e in enumerate(mesh.elements)]
    disks = [rs.DiskElement(n=mesh.node_at(d.position), m=d.mass, Id=d.Id, Ip=d.Ip)
             for d in cfg.disk]
    bearings = [rs.BearingElement(mesh.node_at(s.position), **FINE_BEARING, tag=s.name)
                for s in cfg.spring]
    with contextlib.redirect_stdout(sys.stderr), warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return rs.Rotor(shafts, disks, bearings), len(mesh.elements)
