"""ROSS rotors in: a ``ross.Rotor`` (or ROSS's saved .toml/.json rotor file) as an ambseal rig.

Tested with ross-rotordynamics 2.3 (Python 3.11, ``plotly<7``; ROSS 3 needs Python ≥ 3.12).
The mapping, element by element (ROSS's DOFs per node are [x, y, z, α, β, θ]; ambseal keeps
the lateral [x, y, α, β], so ROSS's axial and torsional modes have no counterpart):

* ``ShaftElement`` → one ``[[shaft]]`` section of one element, node for node, with its
  material (ROSS ``Material``: ρ, E, G_s; same-named materials with different values are
  told apart). ROSS's Timoshenko element with Cowper's shear coefficient is ambseal's
  ``beam = "timoshenko"``; without shear effects, ``"euler-bernoulli"`` (with rotary
  inertia). Tapered or layered elements, elements without rotary inertia or gyroscopic
  terms, and Hutchinson's shear coefficient have no equivalent: an error. ROSS's Rayleigh
  damping of shaft elements (``alpha``, ``beta``) has none either: reported, left out.
* ``DiskElement`` → ``[[disk]]`` (m, Ip, Id); a ``PointMass`` on a shaft node → a disk
  without inertia.
* ``BearingElement`` and its kinds (``SealElement``, fluid-film, ball, ...) with
  coefficients that do not change with frequency and no cross-coupled damping or mass →
  ``[[spring]]`` (kxx, kyy, kxy, kyx, cxx, cyy). Coefficients of the isotropic, skew form
  (kxx = kyy, kxy = −kyx, cxx = cyy, cxy = −cyx, mxx = myy, no cross mass), constant or
  against frequency → ``[[seal]]`` with K = kxx, k = kxy, C = cxx, c = cxy, M = mxx (Childs'
  convention), tables against frequency in Hz (ROSS's rad/s / 2π), evaluated at the
  synchronous frequency as ROSS's ``run_modal`` does. Anything else (frequency-dependent
  anisotropic coefficients, a bearing on a support mass ``n_link``): an error.
* ``MagneticBearingElement`` → ``[[amb]]`` with its geometry (turns, pole area, gap, bias,
  pole angle) and its factors: Ki = ROSS ``ki`` and Ks = −ROSS ``ks`` (ROSS stores the
  negative stiffness with its sign, ambseal the magnitude, P2 Eq. 1), actuator axes at
  ROSS's ``sensors_axis_rotation``, sensor at the bearing (ROSS's AMB is collocated).
  ROSS's AMB controller (PID gains or transfer function, amplifier and sensor gains) is not
  imported — ambseal designs and judges its own (``ambseal design``): reported.
"""

from __future__ import annotations

import contextlib
import json
import math
import sys
import tomllib
import warnings
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ambseal.config import RigConfig, dump_rig, parse_rig
from ambseal.errors import ConfigError
from ambseal.files import write_text

__all__ = ["RossImport", "from_ross", "load_ross", "import_ross_file", "ROSS_TESTED"]

#: The ROSS version the importer is tested with.
ROSS_TESTED = "2.3"


@dataclass(frozen=True)
class RossImport:
    """An imported ROSS rotor: the rig and what of ROSS's model it does not hold.

    Attributes
    ----------
    rig : RigConfig
    unmapped : tuple of str
        One sentence per thing left out (element tag and what).
    """

    rig: RigConfig
    unmapped: tuple[str, ...]


def _bad(where: str, what: str) -> ConfigError:
    return ConfigError(f"{where}: {what}")


def _name(tag, default: str) -> str:
    """A ROSS tag as a rig-file name (letters, digits and ``_``, not starting with a
    digit): ``"Bearing 0"`` → ``Bearing_0``."""
    out = "".join(c if c.isascii() and (c.isalnum() or c == "_") else "_"
                  for c in str(tag or default))
    return "_" + out if not out or out[0].isdigit() else out


def _coef(el, name: str) -> np.ndarray:
    v = getattr(el, name, None)
    return np.zeros(1) if v is None else np.atleast_1d(np.asarray(v, float))


def _materials(shafts, where: str) -> tuple[dict, list[str]]:
    """ROSS materials as ``[materials]`` entries and the key of each shaft element."""
    table: dict[str, dict] = {}
    keys = []
    for i, el in enumerate(shafts):
        mat = getattr(el, "material", None)
        if mat is None or not all(hasattr(mat, a) for a in ("rho", "E", "G_s")):
            raise _bad(where, f"shaft element {i} ({el.tag}): missing material (expected a "
                              "ross.Material with rho, E and G_s)")
        props = {"E": float(mat.E), "rho": float(mat.rho), "G": float(mat.G_s)}
        base = _name(mat.name, "material")
        name, k = base, 1
        while name in table and table[name] != props:
            k += 1
            name = f"{base}_{k}"
        table[name] = props
        keys.append(name)
    return table, keys


def _shaft(rotor, where: str) -> tuple[list[dict], dict, str, list[str]]:
    shafts = sorted(rotor.shaft_elements, key=lambda e: e.n)
    if [e.n for e in shafts] != list(range(len(shafts))):
        raise _bad(where, "shaft elements: expected one element per node pair, left to right "
                          "(layered or linked shaft elements are not supported)")
    mats, keys = _materials(shafts, where)
    shear, notes, out = set(), [], []
    for el, key in zip(shafts, keys):
        tag = f"shaft element {el.n} ({el.tag})"
        if not (math.isclose(el.idl, el.idr) and math.isclose(el.odl, el.odr)):
            raise _bad(where, f"{tag}: tapered element (idl/idr, odl/odr differ) is not "
                              "supported")
        if not (el.rotary_inertia and el.gyroscopic):
            raise _bad(where, f"{tag}: elements without rotary inertia or gyroscopic terms "
                              "are not supported")
        if el.shear_effects and el.shear_method_calc != "cowper":
            raise _bad(where, f"{tag}: shear_method_calc {el.shear_method_calc!r} is not "
                              "supported (expected 'cowper')")
        shear.add(bool(el.shear_effects))
        if el.alpha or el.beta:
            notes.append(f"{tag}: Rayleigh damping alpha={el.alpha:g} 1/s, beta={el.beta:g} s "
                         "left out (no equivalent; [rotor] modal_damping is modal)")
        out.append({"length": float(el.L), "outer_diameter": float(el.odl),
                    "inner_diameter": float(el.idl), "material": key, "elements": 1})
    if len(shear) > 1:
        raise _bad(where, "shaft elements mix shear_effects True and False (one beam type "
                          "per rig)")
    beam = "timoshenko" if shear == {True} else "euler-bernoulli"
    return out, mats, beam, notes


def _isotropic_skew(c: dict[str, np.ndarray]) -> bool:
    def eq(a, b):
        return np.allclose(a, b, rtol=1e-12, atol=0.0)

    return (eq(c["kxx"], c["kyy"]) and eq(c["kxy"], -c["kyx"]) and eq(c["cxx"], c["cyy"])
            and eq(c["cxy"], -c["cyx"]) and eq(c["mxx"], c["myy"])
            and not np.any(c["mxy"]) and not np.any(c["myx"]))


def _bearing(el, z: float, where: str, i: int) -> tuple[str, dict]:
    """("spring" | "seal", entry) of a ROSS bearing or seal."""
    tag = f"bearing {i} ({el.tag}, node {el.n})"
    names = ("kxx", "kyy", "kxy", "kyx", "cxx", "cyy", "cxy", "cyx", "mxx", "myy", "mxy", "myx")
    c = {n: _coef(el, n) for n in names}
    freq = getattr(el, "frequency", None)
    constant = all(np.allclose(v, v[0], rtol=1e-12, atol=0.0) for v in c.values())
    name = _name(el.tag, f"bearing{i}")
    if constant and not any(c[n][0] for n in ("cxy", "cyx", "mxx", "myy", "mxy", "myx")):
        return "spring", {"name": name, "position": z,
                          **{n: float(c[n][0]) for n in ("kxx", "kyy", "kxy", "kyx",
                                                         "cxx", "cyy")}}
    if not _isotropic_skew(c):
        what = ("cross-coupled damping or mass" if constant else
                "frequency-dependent anisotropic coefficients")
        raise _bad(where, f"{tag}: {what} have no ambseal equivalent ([[spring]] takes "
                          "kxx, kyy, kxy, kyx, cxx, cyy; [[seal]] the isotropic skew form)")
    keys = {"K": "kxx", "k": "kxy", "C": "cxx", "c": "cxy", "M": "mxx"}
    if constant:
        return "seal", {"name": name, "position": z,
                        **{k: float(c[v][0]) for k, v in keys.items()}}
    f_hz = [float(w) / (2 * math.pi) for w in np.atleast_1d(freq)]
    return "seal", {"name": name, "position": z,
                    **{k: {"frequency_hz": f_hz, "value": [float(x) for x in c[v]]}
                       for k, v in keys.items()}}


def _amb(el, z: float, i: int) -> tuple[dict, str]:
    def pair(v):
        v = np.atleast_1d(np.asarray(v, float))
        return {"zeta": float(v[0]), "eta": float(v[-1])}

    i0 = np.atleast_1d(np.asarray(el.i0, float))
    name = _name(el.tag, f"amb{i}")
    entry = {"name": name, "position": z, "sensor_position": z,
             "axes_angle_deg": math.degrees(float(el.sensors_axis_rotation)),
             "turns": int(round(float(el.nw))), "pole_area": float(el.ag),
             "air_gap": float(el.g0), "bias_current": float(i0.mean()),
             "pole_angle_deg": math.degrees(float(el.alpha)),
             "ki": pair(el.ki), "ks": pair(-np.asarray(el.ks, float))}
    tf = getattr(el, "controller_transfer_function_num", None) is not None
    ctrl = ("a controller transfer function" if tf else
            f"PID kp={el.kp_pid:g}, ki={el.ki_pid:g}, kd={el.kd_pid:g}, n_f={el.n_f:g}")
    return entry, (f"magnetic bearing {i} ({el.tag}): ROSS's AMB controller ({ctrl}; "
                   f"k_amp={pair(el.k_amp)['zeta']:g}, k_sense={pair(el.k_sense)['zeta']:g}) "
                   "not imported: ambseal designs and judges its own (ambseal design)")


def from_ross(rotor, *, name: str | None = None, where: str = "<ross rotor>") -> RossImport:
    """An ambseal rig from a ``ross.Rotor`` (module docstring: the mapping).

    Parameters
    ----------
    rotor : ross.Rotor
    name : str, optional
        ``[rotor] name`` of the rig (default ROSS's ``tag`` or "ROSS rotor").
    where : str
        Name of the source in error messages (e.g. the file).

    Returns
    -------
    RossImport

    Raises
    ------
    ConfigError
        An element with no ambseal equivalent (named by kind, index, tag and node), or a
        shaft element without a material.
    """
    known = {"ShaftElement", "DiskElement", "PointMass"}
    bearings = list(getattr(rotor, "bearing_elements", []))
    for el in getattr(rotor, "elements", []):
        kind = type(el).__name__
        if kind not in known and el not in bearings:
            raise _bad(where, f"unsupported element {kind} ({getattr(el, 'tag', '')}) with "
                              "no ambseal equivalent")
    shaft, mats, beam, notes = _shaft(rotor, where)
    nodes = np.concatenate([[0.0], np.cumsum([s["length"] for s in shaft])])
    rig: dict = {"rotor": {"beam": beam, "name": name or str(getattr(rotor, "tag", None)
                                                            or "ROSS rotor")},
                 "materials": mats, "shaft": shaft, "disk": [], "amb": [], "seal": [],
                 "spring": []}
    for d in rotor.disk_elements:
        rig["disk"].append({"name": str(d.tag), "position": float(nodes[d.n]),
                            "mass": float(d.m), "Ip": float(d.Ip), "Id": float(d.Id)})
    for p in getattr(rotor, "point_mass_elements", []):
        if p.n >= len(nodes):
            raise _bad(where, f"point mass {p.tag} on node {p.n} off the shaft (a support "
                              "mass) is not supported")
        rig["disk"].append({"name": str(p.tag), "position": float(nodes[p.n]),
                            "mass": float(p.m)})
    for i, b in enumerate(bearings):
        if getattr(b, "n_link", None) is not None:
            raise _bad(where, f"bearing {i} ({b.tag}) linked to node {b.n_link} (support "
                              "structures are not supported)")
        if b.n >= len(nodes):
            raise _bad(where, f"bearing {i} ({b.tag}) on node {b.n} off the shaft")
        if type(b).__name__ == "MagneticBearingElement":
            entry, note = _amb(b, float(nodes[b.n]), i)
            rig["amb"].append(entry)
            notes.append(note)
        else:
            kind, entry = _bearing(b, float(nodes[b.n]), where, i)
            rig[kind].append(entry)
    if rig["amb"]:
        rig["actuator"] = {"model": "none"}
    return RossImport(parse_rig(rig, where), tuple(notes))


def load_ross(path: str | Path):
    """``ross.Rotor.load(path)`` with ROSS's import chatter kept off stdout.

    Raises
    ------
    ConfigError
        ross-rotordynamics is not installed, or the file is missing or not a ROSS rotor.
    """
    path = Path(path)
    if not path.is_file():
        raise ConfigError(f"{path}: no such ROSS rotor file")
    if path.suffix.lower() not in (".toml", ".json"):
        raise ConfigError(f"{path}: expected a ROSS rotor file (.toml or .json)")
    with contextlib.redirect_stdout(sys.stderr):
        try:
            import ross  # optional: the [ross] extra
        except ImportError:
            raise ConfigError("ross-rotordynamics is not installed (pip install "
                              "'ambseal[ross]')") from None

        _check_file(path, ross)
        try:
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                return ross.Rotor.load(path)
        except Exception as exc:  # ROSS raises anything from KeyError to TOML errors
            msg = str(exc).splitlines()[0] if str(exc) else ""
            raise ConfigError(f"{path}: not a ROSS rotor file ({type(exc).__name__}: "
                              f"{msg})") from None


def _check_file(path: Path, ross) -> None:
    """Clear errors for what ROSS's own loader reports obscurely: not a rotor file, an
    element class ROSS does not have, a shaft element without its material."""

    try:
        text = path.read_text(encoding="utf-8")
        data = json.loads(text) if path.suffix.lower() == ".json" else tomllib.loads(text)
    except (OSError, ValueError) as exc:
        raise ConfigError(f"{path}: not a ROSS rotor file ({exc})") from None
    if not isinstance(data, dict) or not isinstance(data.get("parameters"), dict):
        raise ConfigError(f"{path}: not a ROSS rotor file (no 'parameters' table)")
    for key, val in data.items():
        if key in ("parameters", "ross_version") or key.startswith("_"):
            continue
        kind = key.split("_")[0]
        if not hasattr(ross, kind) or not isinstance(val, dict):
            raise ConfigError(f"{path}: {key}: unsupported element {kind!r} (not a ROSS "
                              "element class)")
        if kind == "ShaftElement" and not isinstance(val.get("material"), dict):
            raise ConfigError(f"{path}: {key}: missing material (expected a table "
                              f"[\"{key}\".material] with rho, E, G_s)")


def import_ross_file(path: str | Path, out: str | Path) -> dict:
    """``ambseal import-ross``: read a ROSS rotor file, write the rig (TOML) to ``out``.

    Returns
    -------
    dict
        ``out``, the counts of shaft elements, disks, springs, seals and AMBs, and
        ``unmapped`` (what was left out, one sentence each).

    Raises
    ------
    ConfigError
        As :func:`load_ross` and :func:`from_ross`.
    """
    import ross  # optional: the [ross] extra

    res = from_ross(load_ross(path), where=str(path))
    header = (f"Imported by ambseal from the ROSS rotor file {path} (ROSS {ross.__version__})"
              + "".join(f"\nnot imported: {n}" for n in res.unmapped))
    write_text(out, dump_rig(res.rig, header))
    cfg = res.rig
    return {"out": str(out), "shaft_elements": len(cfg.shaft), "disks": len(cfg.disk),
            "springs": len(cfg.spring), "seals": len(cfg.seal), "ambs": len(cfg.amb),
            "unmapped": list(res.unmapped)}
