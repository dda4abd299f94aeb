"""ROSS rotors in: a ``ross.Rotor`` (or ROSS's saved .toml/.json rotor file) as an ambseal rig.

Tested with ross-rotordynamics 2.3 (Python 3.11, ``plotly<7``) on ROSS's own
``rotor_example``, ``compressor_example`` and ``rotor_amb_example``, and with ROSS 3.0
(Python 3.12) and 3.1 (Python 3.13) on the same rotors (its AMB rig:
``ross.bearings.magnetic.amb_models.rotor_example_amb_general_controllers``). The mapping,
element by element (ROSS's DOFs per node are [x, y, z, α, β, θ]; ambseal keeps the lateral
[x, y, α, β], so ROSS's axial and torsional modes have no counterpart):

* ``ShaftElement`` → one ``[[shaft]]`` section per node pair, with its material (ROSS
  ``Material``: ρ, E, G_s; same-named materials with different values are told apart).
  Several elements on one node pair (ROSS's layered elements: a shaft and the sleeves or
  hubs around it, which ROSS assembles by adding their matrices) → the innermost tube is the
  section, the others its ``layers``, each a beam with its own material and shear
  parameter, as ROSS has them. ROSS's Timoshenko element with Cowper's shear coefficient is
  ambseal's ``beam = "timoshenko"``; without shear effects, ``"euler-bernoulli"``.
  ROSS's ``rotary_inertia`` and ``gyroscopic`` flags of each element → the tube's keys of
  the same names, its ``axial_force`` (N) and ``torque`` (N·m) → the tube's keys of the
  same names (their geometric stiffness, :meth:`ambseal.model.fe.BeamElement._geometric`);
  a tapered element (``odr``, ``idr`` differ from ``odl``, ``idl``) → a section with
  ``outer_diameter_right``, ``inner_diameter_right``, whose element is Genta & Gugliotta's
  conical one as ROSS's (:class:`ambseal.model.fe.BeamElement`). Hutchinson's shear
  coefficient has no equivalent: an error. ROSS's Rayleigh damping of a shaft element
  (``alpha``, ``beta``: C = αM + βK) → the tube's ``rayleigh_alpha``, ``rayleigh_beta``;
  a ROSS 3 rotor's own (``Rotor(alpha=..., beta=...)``, which ROSS takes in place of its
  elements') → ``[rotor] rayleigh_alpha``, ``rayleigh_beta``; its modal damping ratios
  (``modal_damping_ratio``, ``default_damping_ratio``) → ``[rotor.supported_modal_damping]``
  with the ratio of each lateral mode read off ROSS's damping matrix (ROSS counts its
  axial and torsional modes among them; an error on a rotor with AMBs, whose modes ROSS
  takes with the AMBs' equivalent stiffness). Whichever damping ROSS drops by its rule
  (the rotor's α, β win; ratios beside elements' damping: neither) is named, not
  imported. Several shafts
  (ROSS's ``CoAxialRotor``, its shafts linked by bearings): an error naming them (an
  ambseal rig has one shaft).
* ``DiskElement`` → ``[[disk]]`` (m, Ip, Id); a ``PointMass`` on a shaft node → a disk
  without inertia; a gear of a single rotor (ROSS 3's ``GearElement``) → a disk (no gear
  mesh acts on it). A ROSS 3 ``MultiRotor`` (rotors joined by a gear mesh): an error
  naming its rotors. A ``CouplingElement`` → a ``[[shaft]]`` section of its length with a
  ``coupling`` (its halves' mass and inertia, lateral springs and dampers; the axial and
  torsional ones have no lateral effect). Any element without an equivalent: an error
  naming each, one line each; ROSS 3's
  ``MotorElement`` (its induction-motor model drives the torsional DOF only): named among
  what is left out.
* ``BearingElement`` and its kinds (``SealElement``, fluid-film, ball, ...): coefficients of
  the isotropic, skew form (kxx = kyy, kxy = −kyx, cxx = cyy, cxy = −cyx, mxx = myy, no cross
  mass) → ``[[seal]]`` with K = kxx, k = kxy, C = cxx, c = cxy, M = mxx (Childs'
  convention); against speed or frequency, a table in Hz (ROSS's rad/s / 2π) evaluated by
  ambseal at the synchronous frequency as ROSS's ``run_modal`` does: ROSS 3's table along
  one axis as it is, with ROSS 3.1's law (``pchip`` or ``linear``, continued with the end
  slopes: the same coefficient at every speed); ROSS 2.3's (a smoothing spline) and ROSS
  3's over speed and frequency both as the values ROSS's interpolant gives at its points
  (and at the operating frequency, when inside), linear between them, held outside. Any
  other
  coefficients → ``[[spring]]`` (kxx, kyy, kxy, kyx, cxx, cyy, cxy, cyx, and the mass terms
  mxx, myy, mxy, myx), of ``kind = "seal"`` for ROSS's seals (``SealElement`` and its
  kinds: the sign-off must not take a balance piston for a bearing); ROSS's
  ``radial_clearance`` (the least of a table, as its ``run_clearance_analysis``) →
  ``clearance`` of either, a close clearance of the sign-off;
  against speed or frequency, each coefficient that changes a table as a seal's (above),
  evaluated at the synchronous frequency at every speed as ROSS's ``run_modal`` and
  unbalance response do. The rig's ``[operating] speed_rpm``: the import speed
  (``speed_rpm``; by default the lowest frequency that every bearing table of ROSS's
  covers). A direct stiffness above the rig
  file's stiffest support (:data:`~ambseal.config.MAX_SUPPORT_STIFFNESS`; ROSS pins a node
  with 1e20 N/m) is taken at that bound, a pin, with a note. A bearing linked to a
  housing node (``n_link``; the node off the shaft, with its point mass and the bearings
  that hold it to ground) → a ``[[spring]]`` with a ``housing`` (their mass and summed
  constant coefficients); a link between shaft nodes, a housing shared by two bearings,
  without mass, of anisotropic mass or on tabulated supports: an error.
* ``MagneticBearingElement`` → ``[[amb]]`` with its geometry (turns, pole area, gap, bias,
  pole angle) and its factors: Ki = ROSS ``ki`` and Ks = −ROSS ``ks`` (ROSS stores the
  negative stiffness with its sign, ambseal the magnitude, P2 Eq. 1), actuator axes at
  ROSS's ``sensors_axis_rotation``, sensor at ROSS 3's ``sensor_node`` (at the bearing
  where it has none: ROSS 2.3's AMB is collocated), no
  amplifier dynamics (``[actuator] model = "none"``). ROSS's PID C(s) = kp + ki/s +
  kd s/(1 + s/n_f), from sensor volts to amplifier volts, is the current per displacement
  k_amp k_sense C(s): → ``[controller.pid]`` (P5 Eq. 6) with Kp = k_amp k_sense kp,
  Ti = kp/ki, Td = kd/kp, ε = kp/(kd n_f) when every AMB has the same and it has that form
  (integral action included); otherwise reported with what it would be. ROSS's
  equivalent-bearing coefficients of the AMB (its closed loop folded into k(ω), c(ω)) are not
  imported: ambseal closes the loop with the controller's dynamics. ROSS 2.3 saves an AMB
  as a ``BearingElement`` table with the AMB's keys and loads it back as a plain bearing;
  :func:`load_ross` rebuilds the ``MagneticBearingElement`` from the table.
"""

from __future__ import annotations

import contextlib
import ctypes
import importlib
import importlib.metadata
import importlib.util
import json
import math
import os
import subprocess
import sys
import tempfile
import tomllib
import warnings
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import scipy.linalg
from pydantic import ValidationError

from ambseal.config import MAX_SUPPORT_STIFFNESS, Pid, RigConfig, dump_rig, parse_rig
from ambseal.errors import AmbsealError, ConfigError
from ambseal.files import claim_file, read_text, stamp_text, write_text
from ambseal.io.ross_file import _AMB_KEYS, _COEFFS, read_ross3_file
from ambseal.model import RIGID_BELOW_RAD_S, build_system

__all__ = ["RossImport", "from_ross", "load_ross", "import_ross_file", "ROSS_TESTED",
           "ROSS_TIMEOUT_S"]

#: The ROSS versions the importer is tested with (2.3 on Python 3.11, 3.0 on 3.12, 3.1 on
#: 3.13).
ROSS_TESTED = ("2.3", "3.0", "3.1")
#: The longest :func:`import_ross_file`'s child process may take (s): importing ROSS takes
#: 10–20 s on a 2-core machine, loading and mapping a rotor of hundreds of elements a few
#: seconds more.
ROSS_TIMEOUT_S = 300.0



@dataclass(frozen=True)
class RossImport:
    """An imported ROSS rotor: the rig, what of ROSS's model it does not hold and what it
    took by a rule.

    Attributes
    ----------
    rig : RigConfig
    unmapped : tuple of str
        One sentence per thing left out (element tag and what).
    notes : tuple of str
        One sentence per value taken by a rule: frequency-dependent coefficients at one
        frequency (which one, and why), ROSS's AMB controller as ``[controller.pid]``.
    """

    rig: RigConfig
    unmapped: tuple[str, ...]
    notes: tuple[str, ...] = ()


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
    for el in shafts:
        mat = getattr(el, "material", None)
        if mat is None or not all(hasattr(mat, a) for a in ("rho", "E", "G_s")):
            raise _bad(where, f"shaft element {el.n} ({el.tag}): missing material (expected a "
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


def _check_element(el, where: str) -> None:
    tag = f"shaft element {el.n} ({el.tag})"
    if el.shear_effects and el.shear_method_calc != "cowper":
        raise _bad(where, f"{tag}: shear_method_calc {el.shear_method_calc!r} is not "
                          "supported (expected 'cowper')")


def _shaft(rotor, where: str, elemental: bool = True) -> tuple[list[dict], dict, str]:
    """``[[shaft]]`` sections (one per node pair, layered elements as ``layers``), the
    materials and the beam type; ``elemental``: each element's Rayleigh damping taken
    (ROSS ignores it where the rotor has its own)."""
    line = sorted(rotor.shaft_elements, key=lambda e: (e.n, getattr(e, "idl", 0.0)))
    couplings = {int(el.n): el for el in line if type(el).__name__ == "CouplingElement"}
    crowded = [n for n in sorted(couplings) if sum(int(e.n) == n for e in line) > 1]
    if crowded:
        raise _bad(where, f"coupling {couplings[crowded[0]].tag}: it shares node pair "
                          f"{crowded[0]} with another element (a coupling spans a node pair "
                          "alone)")
    shafts = [el for el in line if int(el.n) not in couplings]
    pairs: dict[int, list] = {}
    for el in shafts:
        _check_element(el, where)
        pairs.setdefault(int(el.n), []).append(el)
    on = set(pairs) | set(couplings)
    missing = sorted(set(range(max(on, default=-1) + 1)) - on)
    if not pairs or missing:
        raise _bad(where, "shaft elements: expected elements on every node pair from node 0, "
                          f"left to right (none on node pair(s) {missing[:5]} or none at all)")
    mats, keys = _materials(shafts, where)
    key_of = {id(el): k for el, k in zip(shafts, keys)}
    shear = {bool(el.shear_effects) for el in shafts}
    if len(shear) > 1:
        raise _bad(where, "shaft elements mix shear_effects True and False (one beam type "
                          "per rig)")
    out = []
    for n in sorted(on):
        if n in couplings:
            out.append(_coupling(couplings[n], keys[0], elemental))
            continue
        group = pairs[n]
        if not all(math.isclose(e.L, group[0].L, rel_tol=1e-9) for e in group):
            raise _bad(where, f"shaft elements on node pair {n} "
                              f"({', '.join(str(e.tag) for e in group)}): lengths differ "
                              "(layered elements share their nodes)")
        tubes = [{"outer_diameter": float(e.odl), "inner_diameter": float(e.idl),
                  "material": key_of[id(e)], "rotary_inertia": bool(e.rotary_inertia),
                  "gyroscopic": bool(e.gyroscopic), "axial_force": float(e.axial_force),
                  "torque": float(e.torque)}
                 | ({"rayleigh_alpha": float(e.alpha), "rayleigh_beta": float(e.beta)}
                    if elemental and (e.alpha or e.beta) else {})
                 | ({"outer_diameter_right": float(e.odr), "inner_diameter_right": float(e.idr)}
                    if (e.odr, e.idr) != (e.odl, e.idl) else {}) for e in group]
        section = {"length": float(group[0].L), **tubes[0], "elements": 1}
        if len(tubes) > 1:
            section["layers"] = tubes[1:]
        out.append(section)
    beam = "timoshenko" if shear == {True} else "euler-bernoulli"
    return out, mats, beam


def _coupling(el, material: str, elemental: bool = True) -> dict:
    """A ``[[shaft]]`` section of a ROSS ``CouplingElement``: its length and diameter draw
    it (ROSS's ``L``, ``o_d``), its halves and lateral springs and dampers are the
    ``coupling`` (ROSS's ``_l``/``_r`` as ``_left``/``_right``; the dampers where ROSS
    applies the elements' damping, ``elemental``); its axial and torsional ones (``kt_z``,
    ``kr_z``, ``ct_z``, ``cr_z``) have no lateral effect."""
    keys = {f"{a}_{side}": f"{a}_{s}" for a in ("m", "Ip", "Id")
            for s, side in (("l", "left"), ("r", "right"))}
    keys |= {k: k for k in ("kt_x", "kt_y", "kr_x", "kr_y")}
    keys |= {k: k for k in ("ct_x", "ct_y", "cr_x", "cr_y") if elemental}
    return {"length": float(el.L), "outer_diameter": float(el.o_d), "material": material,
            "elements": 1, "coupling": {k: float(getattr(el, v)) for k, v in keys.items()}}


def _isotropic_skew(c: dict[str, np.ndarray]) -> bool:
    def eq(a, b):
        return np.allclose(a, b, rtol=1e-12, atol=0.0)

    return (eq(c["kxx"], c["kyy"]) and eq(c["kxy"], -c["kyx"]) and eq(c["cxx"], c["cyy"])
            and eq(c["cxy"], -c["cyx"]) and eq(c["mxx"], c["myy"])
            and not np.any(c["mxy"]) and not np.any(c["myx"]))


def _kind(el, where: str, i: int) -> tuple[str, bool]:
    """("seal" | "spring", whether its coefficients change with frequency) of a ROSS
    bearing or seal."""
    c = {n: _coef(el, n) for n in _COEFFS}
    varies = not all(np.allclose(v, v[0], rtol=1e-12, atol=0.0) for v in c.values())
    if _isotropic_skew(c):
        plain = not any(np.any(c[n]) for n in ("cxy", "cyx", "mxx", "myy"))
        return ("spring" if plain and not varies else "seal"), varies
    return "spring", varies


def _axis(el) -> np.ndarray:
    """The points (rad/s) at which a bearing's coefficient table is taken: ROSS 2.3's
    ``frequency``; ROSS 3's ``speed`` or ``frequency`` (whirl), or for a table over both
    the points of both axes. ambseal evaluates every table at the synchronous frequency,
    as ROSS's synchronous analyses do (whirl frequency = speed), so ROSS's interpolant
    there is the table's value (:func:`_at`)."""
    axes = [np.atleast_1d(np.asarray(a, float)) for a in
            (getattr(el, "speed", None), getattr(el, "frequency", None)) if a is not None]
    return np.unique(np.concatenate(axes))


def _at(el, name: str, omega: float) -> float:
    """ROSS's own value of a coefficient at ``omega`` (rad/s): the interpolant its
    ``run_modal`` evaluates (ROSS 3: at speed and whirl frequency ``omega``)."""
    f = getattr(el, f"{name}_interpolated", None)
    if f is None:
        return float(_coef(el, name)[0])
    return float(np.asarray(f(omega), float))


def _table(el, name: str, omega: float) -> dict:
    """A coefficient of a ROSS bearing or seal whose coefficients change with speed or
    frequency, as a rig file's table over the synchronous frequency (Hz): ROSS 3's table
    along one axis with its own points and law; otherwise (ROSS 2.3's smoothing spline,
    ROSS 3's table over speed and frequency) ROSS's values at its points and at the
    operating frequency ``omega`` (rad/s) when inside, linear between them, held
    outside."""
    w = sorted({float(x) for x in _axis(el)})
    law = _ross3_law(el)
    if law is None and w[0] < omega < w[-1] and not any(math.isclose(omega, x) for x in w):
        w = sorted(w + [omega])  # exact at the operating speed, too
    out = {"frequency_hz": [x / (2 * math.pi) for x in w],
           "value": [_at(el, name, x) for x in w]}
    return out | ({"interpolation": law, "extrapolation": "linear"} if law else {})


def _spring(el, z: float, i: int, varies: bool, omega: float, notes: list) -> dict:
    names = ("kxx", "kyy", "kxy", "kyx", "cxx", "cyy", "cxy", "cyx", "mxx", "myy", "mxy",
             "myx")
    vals = {n: float(_coef(el, n).ravel()[0]) for n in names}  # constant ones
    if varies:
        vals |= {n: t for n in names if len(set((t := _table(el, n, omega))["value"])) > 1}
    for n in ("kxx", "kyy"):
        v = vals[n]
        top = max(v["value"]) if isinstance(v, dict) else v
        if top > MAX_SUPPORT_STIFFNESS:  # ROSS pins a node with a 1e20 N/m bearing
            notes.append(f"bearing {i} ({el.tag}, node {el.n}): {n} = {top:.3g} N/m "
                         f"taken as a pin, {MAX_SUPPORT_STIFFNESS:.0e} N/m (the rig file's "
                         "stiffest support; the pinned shaft's frequencies to 1e-8)")
            vals[n] = (v | {"value": [min(x, MAX_SUPPORT_STIFFNESS) for x in v["value"]]}
                       if isinstance(v, dict) else MAX_SUPPORT_STIFFNESS)
    return {"name": _name(el.tag, f"bearing{i}"), "position": z, **vals, **_clearance(el)}


def _ross3_law(el) -> str | None:
    """ROSS 3's interpolation of a table along one axis (``"pchip"`` or ``"linear"``, both
    continued with the end slope), which a rig's table reproduces; None for ROSS 2.3's
    smoothing spline and for ROSS 3's tables over speed and frequency both."""
    law = getattr(el, "interpolation", None)
    one_axis = (getattr(el, "speed", None) is None) != (getattr(el, "frequency", None) is None)
    return law if law in ("pchip", "linear") and one_axis else None


def _clearance(el) -> dict:
    """``{"clearance": c}`` of a bearing or seal with ROSS's ``radial_clearance`` (m; the
    least of a table, as ROSS's ``run_clearance_analysis`` takes it), else empty."""
    rc = getattr(el, "radial_clearance", None)
    if rc is None:
        return {}
    c = float(np.min(np.atleast_1d(np.asarray(getattr(rc, "magnitude", rc), float))))
    return {"clearance": c}


def _seal(el, z: float, i: int, varies: bool, omega: float) -> dict:
    keys = {"K": "kxx", "k": "kxy", "C": "cxx", "c": "cxy", "M": "mxx"}
    entry = {"name": _name(el.tag, f"bearing{i}"), "position": z, **_clearance(el)}
    if not varies:
        return entry | {k: float(_coef(el, v)[0]) for k, v in keys.items()}
    return entry | {k: _table(el, v, omega) for k, v in keys.items()}


def _pid(el) -> tuple[dict | None, str]:
    """ROSS's AMB controller as ``[controller.pid]`` keys, or None and why not; and what
    it is, in words."""
    if getattr(el, "controller_transfer_function_num", None) is not None:
        return None, "a controller transfer function (no PID form)"
    gain = np.atleast_1d(np.asarray(el.k_amp, float)) * np.atleast_1d(
        np.asarray(el.k_sense, float))
    kp, ki, kd, nf = (float(el.kp_pid), float(el.ki_pid), float(el.kd_pid), float(el.n_f))
    what = (f"PID kp={kp:g}, ki={ki:g}, kd={kd:g}, n_f={nf:g} rad/s, k_amp·k_sense="
            f"{'/'.join(f'{g:g}' for g in gain)}")
    if not np.allclose(gain, gain[0], rtol=1e-12, atol=0.0):
        return None, f"{what}: k_amp·k_sense differs between the axes"
    if kp <= 0 or ki <= 0:
        return None, (f"{what}: [controller.pid] (P5 Eq. 6) needs kp > 0 and integral action "
                      f"(ki > 0); it would be kp={gain[0] * kp:g} A/m, td="
                      f"{kd / kp if kp > 0 else 0.0:g} s, eps="
                      f"{kp / (kd * nf) if kd > 0 else 1.0:g}")
    # with kd = 0 the filter ε is unused; 1 keeps the key valid
    pid = {"kp": float(gain[0] * kp), "ti": kp / ki, "td": kd / kp,
           "eps": kp / (kd * nf) if kd > 0 else 1.0}
    try:
        Pid.model_validate(pid)
    except ValidationError as exc:
        return None, f"{what}: outside [controller.pid]'s ranges ({exc.errors()[0]['loc']})"
    return pid, what


def _amb(el, nodes: np.ndarray, i: int, where: str) -> tuple[dict, dict | None, str]:
    def pair(v):
        v = np.atleast_1d(np.asarray(v, float))
        return {"zeta": float(v[0]), "eta": float(v[-1])}

    # ROSS 3's sensor_node: a sensor beside the actuator (ROSS 2.3's AMB is collocated)
    sensor = getattr(el, "sensor_node", None)
    sensor = el.n if sensor is None else int(sensor)
    if not 0 <= sensor < len(nodes):
        raise _bad(where, f"magnetic bearing {i} ({el.tag}): sensor_node {sensor} is off "
                          f"the shaft (nodes 0–{len(nodes) - 1})")
    i0 = np.atleast_1d(np.asarray(el.i0, float))
    entry = {"name": _name(el.tag, f"amb{i}"), "position": float(nodes[el.n]),
             "sensor_position": float(nodes[sensor]),
             "axes_angle_deg": math.degrees(float(el.sensors_axis_rotation)),
             "turns": int(round(float(el.nw))), "pole_area": float(el.ag),
             "air_gap": float(el.g0), "bias_current": float(i0.mean()),
             "pole_angle_deg": math.degrees(float(el.alpha)),
             "ki": pair(el.ki), "ks": pair(-np.asarray(el.ks, float))}
    pid, what = _pid(el)
    return entry, pid, what


def _import_speed(freq_tables: list, speed_rpm: float | None) -> tuple[float, float, str]:
    """The rig's operating speed: its synchronous frequency (rad/s), the speed (rpm) and
    the rule that chose it — a point every table of ROSS's covers, where a table written
    as ROSS's values at its points (ROSS 2.3's) is exact."""
    if speed_rpm is not None:
        return abs(speed_rpm) * math.pi / 30, speed_rpm, "the import speed, --speed-rpm"
    if not freq_tables:
        return 0.0, 0.0, ""
    omega = max(float(np.min(f)) for f in freq_tables)
    return omega, omega * 30 / math.pi, ("the lowest frequency every such table of ROSS's "
                                         "covers; choose with --speed-rpm")


def from_ross(rotor, *, name: str | None = None, where: str = "<ross rotor>",
              speed_rpm: float | None = None) -> RossImport:
    """An ambseal rig from a ``ross.Rotor`` (module docstring: the mapping).

    Parameters
    ----------
    rotor : ross.Rotor
    name : str, optional
        ``[rotor] name`` of the rig (default ROSS's ``tag`` or "ROSS rotor").
    where : str
        Name of the source in error messages (e.g. the file).
    speed_rpm : float, optional
        Speed (rpm) at whose synchronous frequency the frequency-dependent coefficients
        that ambseal holds as constants (a ``[[spring]]``'s) are taken, as ROSS's
        ``run_modal(speed)`` takes them; written as ``[operating] speed_rpm``. By default
        the lowest frequency that every such table covers (none: 0 rpm).

    Returns
    -------
    RossImport

    Raises
    ------
    ConfigError
        An element with no ambseal equivalent (named by kind, index, tag and node), or a
        shaft element without a material.
    """
    rotors = getattr(rotor, "rotors", None)
    if isinstance(rotors, dict) and rotors:  # a ROSS 3 MultiRotor: rotors joined by gears
        tags = ", ".join(f"{k} {getattr(r, 'tag', '')!s}" for k, r in rotors.items())
        raise _bad(where, f"a ROSS MultiRotor ({tags}) has several shafts coupled by a "
                          "gear mesh; an ambseal rig has one shaft and no gear mesh: import "
                          "each rotor on its own (its gear becomes a disk)")
    # several shafts first: their linking bearing would otherwise be named as a support
    _one_shaft([int(el.n) for el in getattr(rotor, "shaft_elements", [])], where)
    bearings = list(getattr(rotor, "bearing_elements", []))
    refused, unmapped = _elements(rotor, bearings)
    if refused:
        raise _bad(where, f"{len(refused)} item(s) ambseal cannot take (each would change "
                          "the dynamics):\n" + "\n".join(f"  {r}" for r in refused))
    damping = _rotor_damping(rotor, where, unmapped)
    shaft, mats, beam = _shaft(rotor, where, elemental=_damping_kind(rotor) == "elements")
    nodes = np.concatenate([[0.0], np.cumsum([s["length"] for s in shaft])])
    rig: dict = {"rotor": {"beam": beam, "name": name or str(getattr(rotor, "tag", None)
                                                            or "ROSS rotor"), **damping},
                 "materials": mats, "shaft": shaft, "disk": [], "amb": [], "seal": [],
                 "spring": []}
    last = len(nodes) - 1
    housings = _housing_nodes(bearings, last)
    rig["disk"] = _masses(rotor, nodes, set(housings))
    pids, notes = [], []
    linked = {id(b): h for h, b in housings.items()}
    plan = _supports(bearings, nodes, where, rig, pids)
    one_freq = [_axis(b) for _, b, kind, varies in plan
                if varies and kind == "spring"]
    omega, rpm, rule = _import_speed(one_freq, speed_rpm)
    for i, b, kind, varies in plan:
        z = float(nodes[b.n])
        if kind == "seal" and id(b) not in linked:
            rig["seal"].append(_seal(b, z, i, varies, omega))
            continue
        rig["spring"].append(_spring(b, z, i, varies, omega, notes))
        if "Seal" in type(b).__name__:  # ROSS's SealElement and its kinds: a seal
            rig["spring"][-1]["kind"] = "seal"
            notes.append(f"bearing {i} ({b.tag}, node {b.n}): a seal ({type(b).__name__}) "
                         "whose coefficients have no Childs form (kxx = kyy, kxy = −kyx): "
                         "a [[spring]] of kind = \"seal\", never a bearing in the sign-off")
        if id(b) in linked:
            rig["spring"][-1]["housing"] = _housing(rotor, bearings, linked[id(b)])
    tables = [e["name"] for e in (*rig["seal"], *rig["spring"]) for v in e.values()
              if isinstance(v, dict) and "value" in v and "interpolation" not in v]
    if tables:
        notes.append(f"seal(s) and bearing(s) {', '.join(dict.fromkeys(tables))}: tables "
                     "of ROSS's values at its frequencies; ambseal interpolates linearly "
                     "between them and holds the end values outside, ROSS's spline runs "
                     "between them and extrapolates: the modes agree at the tables' "
                     "frequencies" + (" and at the [operating] speed" if rpm else ""))
    if rpm:
        rig["operating"] = {"speed_rpm": rpm}
    if _damping_kind(rotor) == "modal" and not hasattr(rotor, "C0"):
        rig["rotor"]["supported_modal_damping"] = _modal_damping_by_order(rotor, rig, where)
    if rig["amb"]:
        rig["actuator"] = {"model": "none"}
        unmapped.append("magnetic bearings: ROSS's equivalent-bearing coefficients k(ω), c(ω) "
                        "(its controller folded in at each frequency) not imported: ambseal "
                        "closes the loop with the controller's dynamics")
        _controller(rig, pids, unmapped, notes)
    return RossImport(parse_rig(rig, where), tuple(unmapped), tuple(notes))


#: Element classes imported: a gear of a single rotor is a disk with teeth (its mass and
#: inertias; no gear mesh acts on it).
_IMPORTED = {"ShaftElement", "CouplingElement", "DiskElement", "PointMass", "GearElement",
             "GearElementTVMS"}


def _elements(rotor, bearings: list) -> tuple[list[str], list[str]]:
    """What of the rotor ambseal cannot take: what would change the lateral dynamics
    (refused, one line each: elements without an equivalent, modal damping ratios on a
    rotor with AMBs, a support structure a housing cannot hold, anything else on a node off
    the shaft) and what would not (named, one line each, in ``unmapped``)."""
    refused, unmapped = [], []
    if _damping_kind(rotor) == "modal" and any(type(b).__name__ == "MagneticBearingElement"
                                               for b in bearings):
        refused.append("the rotor's modal damping ratios on a rotor with magnetic bearings: "
                       "ROSS sets them on the modes with its AMBs' equivalent stiffness at "
                       "0 Hz, ambseal on the modes without the AMBs (theirs is the loop's)")
    last = max((int(e.n) + 1 for e in getattr(rotor, "shaft_elements", [])), default=0)
    refused += _housing_refusals(rotor, bearings, last)
    housings = _housing_nodes(bearings, last)
    for i, b in enumerate(bearings):
        if b.n > last and b.n not in housings:
            refused.append(f"bearing {i} ({b.tag}): on node {b.n}, off the shaft (nodes "
                           f"0–{last})")
        ax = {k: np.atleast_1d(np.asarray(_coef(b, k) if hasattr(b, k) else 0.0, float))
              for k in ("kzz", "czz")}
        if any(np.any(v) for v in ax.values()):
            unmapped.append(f"bearing {i} ({b.tag}): its axial terms ("
                            + ", ".join(f"{k} = {float(np.max(np.abs(v))):g}"
                                        for k, v in ax.items() if np.any(v))
                            + ") not imported: no lateral effect")
    for p in getattr(rotor, "point_mass_elements", []):
        if p.n > last and p.n not in housings:
            refused.append(f"point mass {p.tag}: on node {p.n}, off the shaft (a support "
                           f"mass; nodes 0–{last})")
    for el in getattr(rotor, "elements", []):
        kind, tag = type(el).__name__, getattr(el, "tag", "")
        axial = {k: float(getattr(el, k, 0.0) or 0.0) for k in ("kt_z", "kr_z", "ct_z", "cr_z")}
        if kind == "CouplingElement" and any(axial.values()):
            unmapped.append(f"coupling {tag}: its axial and torsional springs and dampers ("
                            + ", ".join(f"{k} = {v:g}" for k, v in axial.items() if v)
                            + ") not imported: no lateral effect")
        if kind in _IMPORTED or any(el is b for b in bearings):
            continue
        if kind == "MotorElement":  # ROSS 3: not a structural element (its docstring)
            unmapped.append(f"motor {tag} (node {getattr(el, 'n', '?')}): ROSS's induction-"
                            "motor model drives the torsional DOF only (no mass, stiffness "
                            "or damping in the rotor's matrices): not imported, no lateral "
                            "effect")
        else:
            refused.append(f"{kind} {tag}: no ambseal equivalent")
    return refused, unmapped


def _housing_nodes(bearings: list, last: int) -> dict[int, object]:
    """The housing nodes (off the shaft) and the bearing linked to each: ROSS's support
    model, a bearing from a shaft node to a node with a point mass on supports of its own
    (``n_link``)."""
    return {int(b.n_link): b for b in bearings
            if getattr(b, "n_link", None) is not None and int(b.n_link) > last}


def _housing_refusals(rotor, bearings: list, last: int) -> list[str]:
    """What of ROSS's support structures ``[[spring]] housing`` cannot hold, one line each:
    a link between shaft nodes, a housing shared or linked on, without mass or with an
    anisotropic one, supported by tabulated coefficients, behind an AMB or a seal."""
    out, linked = [], {}
    for i, b in enumerate(bearings):
        h = getattr(b, "n_link", None)
        if h is None:
            continue
        where = f"bearing {i} ({b.tag}): linked to node {h}"
        linked.setdefault(int(h), []).append(i)
        if int(h) <= last:
            out.append(f"{where}, a shaft node: a bearing between two shaft nodes has no "
                       "ambseal equivalent")
        elif b.n > last:
            out.append(f"{where} from node {b.n}, itself off the shaft: a chain of "
                       "housings has no ambseal equivalent (one housing per bearing)")
        elif type(b).__name__ == "MagneticBearingElement":
            out.append(f"{where}: an AMB on a housing has no ambseal equivalent (its "
                       "actuator and sensor act on the ground)")
    for h, ids in linked.items():
        if h <= last:
            continue
        if len(ids) > 1:
            names = ", ".join(f"{j} ({bearings[j].tag})" for j in ids)
            out.append(f"housing node {h}: bearings {names} share it; an ambseal housing "
                       "carries one bearing")
        masses = [p for p in getattr(rotor, "point_mass_elements", []) if p.n == h]
        mx = [float(getattr(p, "mx", p.m) or 0.0) for p in masses]
        my = [float(getattr(p, "my", p.m) or 0.0) for p in masses]
        if not sum(mx) > 0:
            out.append(f"housing node {h}: no point mass (a housing has a mass)")
        elif not math.isclose(sum(mx), sum(my), rel_tol=1e-12):
            out.append(f"housing node {h}: point mass mx = {sum(mx):g} kg, my = {sum(my):g} "
                       "kg (an ambseal housing's mass is the same in x and y)")
        for j, s in enumerate(bearings):
            if s.n == h and getattr(s, "n_link", None) is None and _kind(s, "", j)[1]:
                out.append(f"bearing {j} ({s.tag}): supports housing node {h} with "
                           "coefficients that change with frequency (a housing's support "
                           "holds constants)")
    return out


def _housing(rotor, bearings: list, h: int) -> dict:
    """``[[spring]] housing`` of housing node ``h``: its point masses and the bearings
    that hold it to ground, summed."""
    mass = sum(float(p.m) for p in getattr(rotor, "point_mass_elements", []) if p.n == h)
    out = {"mass": mass} | {k: 0.0 for k in ("kxx", "kyy", "kxy", "kyx", "cxx", "cyy",
                                             "cxy", "cyx")}
    for s in bearings:
        if s.n == h and getattr(s, "n_link", None) is None:
            for k in out:
                if k != "mass":
                    out[k] += float(_coef(s, k)[0])
    return out


def _damping_kind(rotor) -> str:
    """The rotor damping ROSS 3 assembles (``Rotor._build_base_matrices``): ``"rayleigh"``
    (the rotor's α, β, which win over the others), ``"modal"`` (its modal damping ratios,
    on a rotor without elements' damping), ``"none"`` (ratios and elements' damping both
    given: ROSS drops both) or ``"elements"`` (each element's own, if any)."""
    if float(getattr(rotor, "alpha", 0.0) or 0.0) or float(getattr(rotor, "beta", 0.0) or 0.0):
        return "rayleigh"
    if getattr(rotor, "modal_damping_ratio", None) is None:
        return "elements"
    own = any(_own_damping(e) for e in getattr(rotor, "shaft_elements", []))
    return "none" if own else "modal"


def _own_damping(el) -> bool:
    """Whether a shaft element carries damping of its own (ROSS's ``C()`` not zero): its
    Rayleigh α, β, or a coupling's dampers (disks and point masses have none)."""
    keys = (("ct_x", "ct_y", "ct_z", "cr_x", "cr_y", "cr_z")
            if type(el).__name__ == "CouplingElement" else ("alpha", "beta"))
    return any(float(getattr(el, k, 0.0) or 0.0) for k in keys)


def _rotor_damping(rotor, where: str, unmapped: list) -> dict:
    """``[rotor]`` keys of a ROSS 3 rotor's own damping, the kind ROSS assembles
    (:func:`_damping_kind`): its Rayleigh ``alpha``, ``beta`` (of shaft, disks and point
    masses, as ROSS assembles them), or its modal damping ratios
    (:func:`_supported_modal_damping`); what ROSS itself drops named in ``unmapped``."""
    kind = _damping_kind(rotor)
    ratios = getattr(rotor, "modal_damping_ratio", None)
    default = float(getattr(rotor, "default_damping_ratio", 0.0) or 0.0)
    if kind != "modal" and (ratios is not None or default):
        why = ("its Rayleigh alpha, beta win" if kind == "rayleigh" else "ratios without "
               "modal_damping_ratio are unused" if ratios is None else "with its shaft "
               "elements' own damping ROSS uses neither")
        unmapped.append(f"the rotor's modal damping (modal_damping_ratio={ratios!r}, "
                        f"default_damping_ratio={default:g}): not imported, ROSS does not "
                        f"apply it ({why})")
    if kind in ("none", "rayleigh") and any(_own_damping(e) for e in rotor.shaft_elements):
        unmapped.append("the elements' own damping (shaft elements' alpha, beta, couplings' "
                        "dampers): not imported, ROSS does not apply it beside the rotor's "
                        + ("modal damping ratios" if kind == "none" else "alpha, beta"))
    if kind == "modal":  # a rotor read without ROSS: by the modes' order (from_ross)
        return ({"supported_modal_damping": _supported_modal_damping(rotor, where)}
                if hasattr(rotor, "C0") else {})
    if kind != "rayleigh":
        return {}
    return {"rayleigh_alpha": float(rotor.alpha), "rayleigh_beta": float(rotor.beta)}


def _split_repeated(rotor) -> bool:
    """Whether ROSS's rule gives a repeated mode (an isotropic rotor's x and y) two
    ratios: ROSS's modes at standstill ascending, those below 1 rpm none, then
    ``modal_damping_ratio``, then ``default_damping_ratio`` — which of the two gets which
    then depends on the vectors ROSS's eigensolver returns in their plane."""
    M, K = np.asarray(rotor.M(0), float), np.asarray(rotor.K(0), float)
    w2 = scipy.linalg.eigh((K + K.T) / 2, M, eigvals_only=True)
    w = np.sqrt(w2[w2 >= 0])
    given = list(np.atleast_1d(np.asarray(rotor.modal_damping_ratio, float)))
    rigid = int(np.sum(w < RIGID_BELOW_RAD_S))
    zeta = np.full(len(w), float(rotor.default_damping_ratio or 0.0))
    zeta[:rigid] = 0.0
    zeta[rigid:rigid + len(given)] = given[:max(len(w) - rigid, 0)]
    same = np.diff(w) <= 1e-6 * np.maximum(w[1:], RIGID_BELOW_RAD_S)
    return bool(np.any(same & (np.diff(zeta) != 0)))


#: ROSS 3's DOFs per node are [x, y, z, α, β, θ]: the lateral ones ambseal holds.
_LATERAL = (0, 1, 3, 4)


def _supported_modal_damping(rotor, where: str) -> dict:
    """``[rotor.supported_modal_damping]`` of a ROSS 3 rotor's modal damping: the ratio of
    each lateral mode read off ROSS's own damping matrix (ζ_r = φ_rᵀ C₀ φ_r / 2ω_r on the
    mass-normalised modes of ROSS's M(0), K(0)) — ROSS orders its ratios over all its modes,
    the axial and torsional ones among them, which the lateral ones skip."""
    per = int(getattr(rotor, "number_dof", 6))
    lat = [i for i in range(rotor.ndof) if i % per in _LATERAL]
    sub = np.ix_(lat, lat)
    M = np.asarray(rotor.M(0), float)[sub]
    K = np.asarray(rotor.K(0), float)[sub]
    C0 = np.real(np.asarray(rotor.C0))[sub]  # complex (ROSS's eig), real to round-off
    w2, phi = scipy.linalg.eigh((K + K.T) / 2, M)
    keep = np.flatnonzero(w2 >= RIGID_BELOW_RAD_S ** 2)
    w, phi = np.sqrt(w2[keep]), phi[:, keep]
    modal = phi.T @ C0 @ phi / (2 * w)  # diag: ζ; off it, what one ζ per mode cannot hold
    zeta = np.diag(modal).copy()
    if _split_repeated(rotor) or np.abs(modal - np.diag(zeta)).max(initial=0.0) > 1e-6 * max(
            zeta.max(initial=0), 1e-9):
        raise _bad(where, "the rotor's modal damping ratios differ within a repeated mode "
                          "(the x and y modes of an isotropic rotor): ROSS's damping then "
                          "depends on the eigenvectors its solver returns; give the pair one "
                          "ratio")
    given = [float(z) for z in np.atleast_1d(rotor.modal_damping_ratio)]
    others = float(rotor.default_damping_ratio or 0.0)
    for j, z in enumerate(zeta):  # ROSS's exact values, not their round-off
        near = [g for g in given + [others, 0.0] if math.isclose(z, g, rel_tol=1e-6,
                                                                  abs_tol=1e-12)]
        zeta[j] = near[0] if near else z
    last = max((j for j, z in enumerate(zeta) if z != others), default=0)
    return {"ratios": [float(z) for z in zeta[:last + 1]], "others": others}


def _modal_damping_by_order(rotor, rig: dict, where: str) -> dict:
    """``[rotor.supported_modal_damping]`` of modal damping ratios read without ROSS (the
    rotor of :func:`~ambseal.io.ross_file.read_ross3_file`): ROSS's rule over the modes
    of its rotor at standstill in ascending order — rigid-body ones none, then
    ``modal_damping_ratio``, then ``default_damping_ratio`` — with the lateral modes those
    of the rig's basis (:func:`~ambseal.model.supported_modal_damping`: the rotor on its
    springs and seals at 0 Hz, ROSS's lateral ones) and the axial and torsional ones of
    ROSS's six-DOF model (``rotor.axial_torsional_rad_s()``) among them."""
    sys = build_system(parse_rig(rig, where), speed_rpm=0.0, include_amb=False)
    w2 = scipy.linalg.eigh((sys.K + sys.K.T) / 2, sys.M, eigvals_only=True)
    lateral = np.sqrt(w2[w2 >= RIGID_BELOW_RAD_S ** 2])
    other = rotor.axial_torsional_rad_s()
    other = other[other >= RIGID_BELOW_RAD_S]
    given = [float(z) for z in np.atleast_1d(rotor.modal_damping_ratio)]
    others = float(rotor.default_damping_ratio or 0.0)
    merged = sorted([(w, True) for w in lateral] + [(w, False) for w in other])
    zeta = [given[k] if k < len(given) else others
            for k, (_, is_lateral) in enumerate(merged) if is_lateral]
    if any(b - a <= 1e-6 * b and za != zb
           for a, b, za, zb in zip(lateral, lateral[1:], zeta, zeta[1:])):
        raise _bad(where, "the rotor's modal damping ratios differ within a repeated mode "
                          "(the x and y modes of an isotropic rotor): ROSS's damping then "
                          "depends on the eigenvectors its solver returns; give the pair one "
                          "ratio")
    last = max((j for j, z in enumerate(zeta) if z != others), default=0)
    return {"ratios": zeta[:last + 1] or [others], "others": others}


def _masses(rotor, nodes: np.ndarray, housings: set) -> list[dict]:
    """``[[disk]]`` entries of ROSS's disks and point masses on the shaft (those on
    ``housings`` are their housings')."""
    out = [{"name": str(d.tag), "position": float(nodes[d.n]), "mass": float(d.m),
            "Ip": float(d.Ip), "Id": float(d.Id)} for d in rotor.disk_elements]
    for p in getattr(rotor, "point_mass_elements", []):  # (on the shaft: _elements)
        if p.n not in housings:
            out.append({"name": str(p.tag), "position": float(nodes[p.n]),
                        "mass": float(p.m)})
    return out


def _supports(bearings: list, nodes: np.ndarray, where: str, rig: dict,
              pids: list) -> list[tuple]:
    """ROSS's magnetic bearings into ``rig["amb"]`` (their controllers into ``pids``); the
    other bearings and seals as (index, element, kind, frequency-dependent), to place once
    the import's speed is known."""
    plan = []
    last = len(nodes) - 1
    for i, b in enumerate(bearings):  # (on the shaft or holding a housing: _elements)
        if b.n > last:  # a housing's support: part of its housing (_housing)
            continue
        if type(b).__name__ == "MagneticBearingElement":
            entry, pid, what = _amb(b, nodes, i, where)
            rig["amb"].append(entry)
            pids.append((b.tag, pid, what))
        else:
            plan.append((i, b, *_kind(b, where, i)))
    return plan


def _controller(rig: dict, pids: list, unmapped: list, notes: list) -> None:
    """``[controller.pid]`` from ROSS's AMB controllers when they are one PID, else why not."""
    found = [p for _, p, _ in pids]
    if None not in found and all(all(math.isclose(p[k], found[0][k], rel_tol=1e-12)
                                     for k in p) for p in found):
        rig.setdefault("controller", {})["pid"] = found[0]
        notes.append(f"ROSS's AMB controller ({pids[0][2]}) taken as [controller.pid] "
                     + ", ".join(f"{k}={v:g}" for k, v in found[0].items())
                     + " (Kp = k_amp·k_sense·kp, Ti = kp/ki, Td = kd/kp, eps = kp/(kd n_f))")
        return
    whats = list(dict.fromkeys(what for _, p, what in pids if p is None))
    why = "they differ between the AMBs" if not whats else "; ".join(whats)
    unmapped.append(f"ROSS's AMB controllers not imported ({why}): [controller.pid] is one "
                    "PID for every axis; ambseal designs its own (ambseal design)")


@contextlib.contextmanager
def _stdout_to_stderr():
    """Everything written to stdout — by Python, or by a C library at the file-descriptor
    level, as CoolProp's REFPROP banner when ROSS imports ccp — goes to stderr instead, so
    that a command's stdout holds its result only."""
    sys.stdout.flush()
    saved = os.dup(1)
    try:
        os.dup2(2, 1)
        with contextlib.redirect_stdout(sys.stderr):
            yield
    finally:
        sys.stdout.flush()
        with contextlib.suppress(Exception):  # C's stdio buffers; no libc on some platforms
            ctypes.CDLL(None).fflush(None)
        os.dup2(saved, 1)
        os.close(saved)


@contextlib.contextmanager
def _no_refprop_from_cwd():
    """ccp (imported by ROSS) loads REFPROP's ``librefprop.so`` from ``RPPREFIX``, else from
    the working directory: unless the user set ``RPPREFIX``, point it at an empty folder
    while ccp is imported, so that a library planted in the working directory is not
    loaded (ambseal needs no REFPROP)."""
    if "RPPREFIX" in os.environ or "ccp" in sys.modules:
        yield
        return
    with tempfile.TemporaryDirectory(prefix="ambseal-norefprop-") as empty:
        os.environ["RPPREFIX"] = empty
        try:
            yield
        finally:
            os.environ.pop("RPPREFIX", None)


def _ross():
    """The ``ross`` module, imported with its import chatter kept off stdout and no REFPROP
    library taken from the working directory."""
    with _stdout_to_stderr(), warnings.catch_warnings(), _no_refprop_from_cwd():
        warnings.simplefilter("ignore")
        try:
            import ross  # optional: the [ross] extra
        except ImportError:
            raise ConfigError("ross-rotordynamics is not installed (pip install "
                              "'ambseal[ross]')") from None
    return ross


def load_ross(path: str | Path):
    """``ross.Rotor.load(path)`` with ROSS's import chatter kept off stdout and its AMBs
    restored (ROSS 2.3 saves a ``MagneticBearingElement`` as a bearing table with the AMB's
    keys and loads it back as a plain ``BearingElement``).

    ROSS is imported in this process (with ccp's REFPROP folder away from the working
    directory, :func:`_ross`); :func:`import_ross_file` runs the whole import in a child
    process in an empty folder instead, which is what ``ambseal import-ross`` does.

    Parameters
    ----------
    path : str or Path
        A rotor file saved by ``ross.Rotor.save`` (.toml or .json).

    Returns
    -------
    ross.Rotor

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
    ross = _ross()
    return _load(path, ross, _check_file(path, ross))


def _load(path: Path, ross, data: dict):
    """:func:`load_ross` of a file whose tables ``data`` :func:`_check_file` read."""
    with _stdout_to_stderr(), warnings.catch_warnings(), \
            tempfile.TemporaryDirectory(prefix="ambseal-ross2-") as tmp:
        warnings.simplefilter("ignore")
        try:
            src = path
            if _older_file(data, ross):
                src, data = _converted(path, data, ross, Path(tmp))
            rotor = ross.Rotor.load(src)
            _restore_ambs(rotor, data, ross)
        except ModuleNotFoundError as exc:  # ROSS 2.3's seal models need rossxl
            raise ConfigError(f"{path}: a ROSS {data.get('ross_version', '')} rotor file that "
                              f"the installed ROSS {ross.__version__} cannot load: it needs "
                              f"the package {exc.name!r}, which is not installed (ROSS 3, on "
                              "Python 3.12 or newer, converts and loads it)") from None
        except Exception as exc:  # ROSS raises anything from KeyError to TOML errors
            msg = str(exc).splitlines()[0] if str(exc) else ""
            raise ConfigError(f"{path}: not a ROSS rotor file ({type(exc).__name__}: "
                              f"{msg})") from None
    return rotor


def _older_file(data: dict, ross) -> bool:
    """Whether a rotor file (its tables ``data``) was saved by a ROSS major before the
    installed one, which ships ``ross_2to3`` to convert it (ROSS 3: a ROSS 2 file's seals
    and tables over frequency do not load as they are)."""
    saved, have = _major(data.get("ross_version")), _major(getattr(ross, "__version__", None))
    return (saved is not None and have is not None and saved < have
            and importlib.util.find_spec("ross.ross_2to3") is not None)


def _converted(path: Path, data: dict, ross, folder: Path) -> tuple[Path, dict]:
    """The ROSS 2 file converted by the installed ROSS's own ``ross_2to3`` (written into
    ``folder``, a temporary one) and its tables."""
    conv = importlib.import_module("ross.ross_2to3")  # the installed ROSS's, as ross
    text = conv.convert_model_text(read_text(path, "ROSS rotor file"), path.suffix.lower(),
                                   conv.Report(), path=path, version=ross.__version__)
    if text is None:
        raise ConfigError(f"{path}: a ROSS {data.get('ross_version')} file that ROSS "
                          f"{ross.__version__}'s ross_2to3 does not take for a model")
    out = folder / f"converted{path.suffix.lower()}"
    out.write_text(text, encoding="utf-8")
    return out, (json.loads(text) if path.suffix.lower() == ".json" else tomllib.loads(text))


def _restore_ambs(rotor, data: dict, ross) -> None:
    """Put back the ``MagneticBearingElement`` of every bearing table with the AMB's keys,
    in place of the plain bearing ROSS loaded."""
    for key, table in data.items():
        if not (key.startswith("BearingElement_") and isinstance(table, dict)
                and all(k in table for k in _AMB_KEYS)):
            continue
        mb = ross.MagneticBearingElement.read_toml_data(table)
        for seq in (rotor.bearing_elements, rotor.elements):
            for j, el in enumerate(seq):
                if type(el).__name__ == "BearingElement" and el.tag == mb.tag and el.n == mb.n:
                    for attr in ("dof_global_index", "n_l", "n_r"):  # set by the Rotor
                        if hasattr(el, attr):
                            setattr(mb, attr, getattr(el, attr))
                    seq[j] = mb


def _check_file(path: Path, ross=None) -> dict:
    """The file's tables, with clear errors for what ROSS's own loader reports obscurely:
    not a rotor file, an element class ROSS does not have (checked given ``ross``), a
    shaft element without its material."""

    try:
        text = read_text(path, "ROSS rotor file")
        data = (json.loads(text, object_pairs_hook=_no_repeats)
                if path.suffix.lower() == ".json" else tomllib.loads(text))
    except AmbsealError as exc:
        raise ConfigError(str(exc)) from None
    except RecursionError:
        raise ConfigError(f"{path}: not a ROSS rotor file (nested too deeply to read)"
                          ) from None
    except (OSError, ValueError) as exc:
        raise ConfigError(f"{path}: not a ROSS rotor file ({exc})") from None
    if not isinstance(data, dict) or not isinstance(data.get("parameters"), dict):
        raise ConfigError(f"{path}: not a ROSS rotor file (no 'parameters' table)")
    saved, have = _major(data.get("ross_version")), _major(getattr(ross, "__version__", None))
    if saved is not None and have is not None and saved > have:
        # ROSS 3 changed the file (rotor-level damping, tables against speed): ROSS 2 fails
        # on it with a TypeError or a shape error that names neither version
        raise ConfigError(f"{path}: saved by ROSS {data['ross_version']}, which the installed "
                          f"ROSS {ross.__version__} cannot read: install ROSS {saved} (ROSS 3 "
                          "needs Python 3.12 or newer; ambseal's 'ross' extra picks the ROSS "
                          "of its Python) and import again")
    for key, val in data.items():
        if key in ("parameters", "ross_version") or key.startswith("_"):
            continue
        kind = key.split("_")[0]
        if (ross is not None and not hasattr(ross, kind)) or not isinstance(val, dict):
            raise ConfigError(f"{path}: {key}: unsupported element {kind!r} (not a ROSS "
                              "element class)")
        if kind == "ShaftElement" and not isinstance(val.get("material"), dict):
            raise ConfigError(f"{path}: {key}: missing material (expected a table "
                              f"[\"{key}\".material] with rho, E, G_s)")
    # a coupling sits between shaft elements on a node pair of its own: the shaft runs on
    pairs = [v.get("n") for k, v in data.items()
             if k.startswith(("ShaftElement_", "CouplingElement_"))]
    if pairs and all(isinstance(n, int) and not isinstance(n, bool) for n in pairs):
        _one_shaft(pairs, str(path))
    return data


def _no_repeats(pairs: list) -> dict:
    """A JSON object without a repeated key (JSON's own readers keep the last silently:
    two elements under one key would lose one)."""
    out: dict = {}
    for k, v in pairs:
        if k in out:
            raise ValueError(f"the key {k!r} appears twice")
        out[k] = v
    return out


def _installed_ross() -> str | None:
    """The installed ROSS's version, read from its package metadata (no import), or None."""
    try:
        return importlib.metadata.version("ross-rotordynamics")
    except importlib.metadata.PackageNotFoundError:
        return None


def _major(version) -> int | None:
    """The major number of a version string (``"3.1.0"`` → 3), None if it has none."""
    head = str(version).split(".")[0] if version is not None else ""
    return int(head) if head.isdigit() else None


def _one_shaft(pairs, where: str) -> None:
    """Refuse shaft elements that form several shafts: ROSS numbers the nodes of a
    ``CoAxialRotor``'s shafts one after the other, so its second shaft starts one node past
    the first one's end, and its saved file does not say which shaft an element is on —
    the gap in the node pairs is what tells (ROSS's own loader then fails obscurely)."""
    runs: list[list[int]] = []
    for n in sorted(set(pairs)):
        if runs and n == runs[-1][1]:
            runs[-1][1] = n + 1
        else:
            runs.append([n, n + 1])
    if len(runs) > 1:
        spans = ", ".join(f"nodes {a}–{b}" for a, b in runs[:4]) + (
            ", ..." if len(runs) > 4 else "")
        raise ConfigError(f"{where}: {len(runs)} shafts ({spans}; a ROSS CoAxialRotor): "
                          "several shafts are not supported (an ambseal rig has one shaft)")


def _child() -> None:
    """The ROSS import of :func:`_in_clean_process`, run as the child's program: argv is
    the file (absolute), its name for messages, the speed (JSON) and the result file."""
    path, where, out = Path(sys.argv[1]), sys.argv[2], Path(sys.argv[4])
    try:
        ross = _ross()
        data = _check_file(path, ross)
        rotor = _load(path, ross, data)
        res = from_ross(rotor, where=where, speed_rpm=json.loads(sys.argv[3]))
        notes = list(res.notes)
        if _older_file(data, ross):
            notes.insert(0, f"ROSS {data['ross_version']}'s file, converted by ROSS "
                            f"{ross.__version__}'s own ross_2to3 before it was loaded")
        doc = {"rig": res.rig.model_dump(exclude_none=True), "unmapped": list(res.unmapped),
               "notes": notes, "ross_version": str(ross.__version__)}
    except AmbsealError as exc:  # the user's name of the file, not the absolute one
        doc = {"error": str(exc).replace(str(path), where, 1)}
    out.write_text(json.dumps(doc, allow_nan=False), encoding="utf-8")


def _in_clean_process(path: Path, speed_rpm: float | None) -> dict:
    """Load and map a ROSS file in a child process whose working directory is a new, empty
    folder: importing ROSS imports ccp, which loads ``librefprop.so`` (REFPROP) from the
    working directory — a library planted beside the user's files would run as code.
    The child gets the file's absolute path, no script folder on ``sys.path`` (``-P``) and
    ``RPPREFIX`` (ccp's REFPROP folder) set to the empty folder; its output (ROSS's
    chatter) is dropped. Returns the child's result: the rig as a dict, ``unmapped``,
    ``notes`` and ``ross_version``."""
    root = str(Path(__file__).resolve().parents[2])  # the folder ambseal is imported from
    with tempfile.TemporaryDirectory(prefix="ambseal-ross-") as tmp:
        empty, result = Path(tmp) / "cwd", Path(tmp) / "result.json"
        empty.mkdir()
        env = {**os.environ, "RPPREFIX": str(empty), "OPENBLAS_NUM_THREADS": "1",
               "PYTHONPATH": os.pathsep.join([root] + [p for p in [os.environ.get(
                   "PYTHONPATH")] if p])}
        cmd = [sys.executable, "-P", "-c", "from ambseal.io.ross import _child; _child()",
               str(path.resolve()), str(path), json.dumps(speed_rpm), str(result)]
        try:
            proc = subprocess.run(cmd, cwd=empty, env=env, stdin=subprocess.DEVNULL,
                                  capture_output=True, text=True, errors="replace",
                                  timeout=ROSS_TIMEOUT_S)
        except subprocess.TimeoutExpired:
            raise ConfigError(f"{path}: the ROSS import took more than {ROSS_TIMEOUT_S:g} s"
                              ) from None
        if proc.returncode != 0 or not result.is_file():
            last = (proc.stderr.strip().splitlines() or ["no message"])[-1]
            raise ConfigError(f"{path}: the ROSS import failed (exit status "
                              f"{proc.returncode}: {last[:300]})")
        doc = json.loads(result.read_text(encoding="utf-8"))
    if "error" in doc:
        raise ConfigError(str(doc["error"]))
    return doc


def import_ross_file(path: str | Path, out: str | Path, *,
                     speed_rpm: float | None = None, force: bool = False) -> dict:
    """``ambseal import-ross``: read a ROSS rotor file, write the rig (TOML) to ``out``.

    ROSS is imported in a child process in an empty working directory
    (:func:`_in_clean_process`): nothing in the user's working directory or the file's
    folder is loaded as code. The checks that need no ROSS run first, in this process.

    Parameters
    ----------
    path : str or Path
        The ROSS rotor file (:func:`load_ross`).
    out : str or Path
        The rig file to write: a new file, one this command wrote before and nobody
        changed (its first line's stamp, :func:`ambseal.files.stamp_text`), or any file
        with ``force``.
    speed_rpm : float, optional
        As :func:`from_ross`.
    force : bool
        Replace ``out`` whatever it holds (the user's ``--force``).

    Returns
    -------
    dict
        ``out``, the counts of shaft sections (``shaft_elements``), layers, disks, springs,
        seals and AMBs, ``speed_rpm`` (the rig's operating speed), ``controller_pid``
        (whether ROSS's PID was taken), ``unmapped`` (what was left out) and ``notes``
        (what was taken by a rule), one sentence each.

    Raises
    ------
    ConfigError
        As :func:`load_ross` and :func:`from_ross`, or the child process failed or ran
        past :data:`ROSS_TIMEOUT_S`.
    AmbsealError
        ``out`` exists and is not this command's unchanged output (without ``force``).
    """
    path = Path(path)
    claim_file(out, force=force)  # before any work
    if not path.is_file():
        raise ConfigError(f"{path}: no such ROSS rotor file")
    if path.suffix.lower() not in (".toml", ".json"):
        raise ConfigError(f"{path}: expected a ROSS rotor file (.toml or .json)")
    data = _check_file(path)  # before ROSS's import: no rotor file, a missing material
    saved, have = _major(data.get("ross_version")), _major(_installed_ross())
    if saved == 3 and (have is None or have < saved):
        # a ROSS 3 file where ROSS 3 is not installed (Python 3.11: ROSS 2.3): read the
        # format itself, no ROSS imported
        imp = from_ross(read_ross3_file(path, data), where=str(path), speed_rpm=speed_rpm)
        doc = {"rig": imp.rig.model_dump(exclude_none=True), "unmapped": list(imp.unmapped),
               "notes": list(imp.notes)}
        source = f"ROSS {data['ross_version']}'s file, read without ROSS"
    else:
        doc = _in_clean_process(path, speed_rpm)
        source = f"ROSS {doc['ross_version']}"
    res = RossImport(parse_rig(doc["rig"], str(path)), tuple(doc["unmapped"]),
                     tuple(doc["notes"]))
    header = (f"Imported by ambseal from the ROSS rotor file {path} ({source})"
              + "".join(f"\nnot imported: {n}" for n in res.unmapped)
              + "".join(f"\ntaken: {n}" for n in res.notes))
    write_text(out, stamp_text(dump_rig(res.rig, header)))
    cfg = res.rig
    return {"out": str(out), "shaft_elements": len(cfg.shaft),
            "layers": sum(len(s.layers) for s in cfg.shaft), "disks": len(cfg.disk),
            "springs": len(cfg.spring), "seals": len(cfg.seal), "ambs": len(cfg.amb),
            "speed_rpm": cfg.operating.speed_rpm,
            "controller_pid": cfg.controller.pid is not None,
            "unmapped": list(res.unmapped), "notes": list(res.notes)}
