"""ROSS 3's rotor file read without ROSS: a ROSS 3 rotor where no ROSS 3 is installed.

ROSS 3 (Python 3.12 or newer) writes a rotor (``Rotor.save``) as a TOML or JSON document:
``ross_version``, a ``parameters`` table (the rotor's ``alpha``, ``beta``,
``modal_damping_ratio``, ``default_damping_ratio``) and one table per element, keyed
``<Class>_<tag>``, holding the element's constructor arguments (a shaft element's material
as a sub-table). ROSS 2.3, the ROSS of Python 3.11, cannot read it (rotor-level damping
and tables against speed are new in ROSS 3). This module reads the document itself and
hands :func:`ambseal.io.ross.from_ross` the rotor as plain objects with the attributes
it reads from ROSS's — so one mapping serves both paths, and ROSS 3's file is read on any
Python (the design: the format is documented by ROSS's own ``save``/``read_toml_data``,
a reader of it needs no ROSS at all).

What the objects reproduce of ROSS 3.1:

* the coefficient tables (``BearingCoefficient``): constant, over ``speed`` or over
  ``frequency`` (whirl) — a shape-preserving piecewise cubic Hermite interpolant
  (``interpolation = "pchip"``, linear with two points) or linear, extrapolated linearly
  with the end slopes — and a 2-D table over both, interpolated along speed first, then
  along frequency;
* a magnetic bearing (a bearing table with ``g0``, ``i0``, ``ag``, ``nw``) with ROSS's
  factors from its geometry, Ki = μ0 N² A i0 cos α / g0² and Ks = −μ0 N² A i0² cos α / g0³
  (μ0 = 4π·10⁻⁷ H/m)
  (Schweitzer & Maslen, *Magnetic Bearings*, 2009, p. 343, as ROSS), and its PID.

* ROSS's axial and torsional modes at standstill (:meth:`_Rotor.axial_torsional_rad_s`),
  over which ROSS counts its modal damping ratios as over the lateral ones: its six-DOF
  elements' z and θ parts — a shaft element's bar and torsion matrices on its mean area
  and second moment (E·A/L, ρAL/6·[2 1; 1 2]; G_s·J/L, ρJL/6·[2 1; 1 2], J = I_l + I_r),
  disks' and couplings' masses and polar inertias, a coupling's ``kt_z``, ``kr_z``, point
  masses' ``mz``, bearings' ``kzz``, ``mzz`` at 0 Hz.

An element class this reader does not know is refused naming it.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import scipy.linalg
from scipy import interpolate

from ambseal.errors import ConfigError

__all__ = ["read_ross3_file"]

_COEFFS = ("kxx", "kyy", "kxy", "kyx", "cxx", "cyy", "cxy", "cyx", "mxx", "myy", "mxy", "myx")
_AMB_KEYS = ("g0", "i0", "ag", "nw")


class _Element:
    """An element of the file: its table's keys as attributes."""

    def __init__(self, table: dict):
        self.__dict__.update(table)
        self.tag = table.get("tag")


def _kind(name: str) -> type:
    # from_ross dispatches on the class name, as it does on ROSS's own classes
    return type(name, (_Element,), {})


ShaftElement, CouplingElement, DiskElement, PointMass, BearingElement, SealElement, \
    MagneticBearingElement, MotorElement = (_kind(n) for n in (
        "ShaftElement", "CouplingElement", "DiskElement", "PointMass", "BearingElement",
        "SealElement", "MagneticBearingElement", "MotorElement"))
#: A gear of a single rotor is a disk with teeth (its mass and inertias in ROSS's matrices)
_DISKS = {name: _kind(name) for name in ("DiskElement", "GearElement", "GearElementTVMS")}


class _Material:
    def __init__(self, table: dict):
        self.name = table.get("name")
        self.rho, self.E, self.G_s = (float(table[k]) for k in ("rho", "E", "G_s"))


class _Axis:
    """ROSS 3.1's interpolation along a table's first axis: pchip (two points: linear) or
    linear, extrapolated linearly with the end slopes."""

    def __init__(self, axis, values, method: str):
        self.axis = np.asarray(axis, float)
        self.values = np.asarray(values, float)
        if len(self.axis) == 1:
            self.f = None
        elif len(self.axis) == 2 or method == "linear":
            self.f = interpolate.interp1d(self.axis, self.values, axis=0, kind="linear",
                                          fill_value="extrapolate")
            self.slopes = None
        else:
            self.f = interpolate.PchipInterpolator(self.axis, self.values, axis=0)
            d = self.f.derivative()
            self.slopes = (d(self.axis[0]), d(self.axis[-1]))

    def __call__(self, x: float):
        if self.f is None:
            return self.values[0]
        if self.slopes is None:
            return self.f(x)
        lo, hi = self.axis[0], self.axis[-1]
        clipped = min(max(x, lo), hi)
        slope = self.slopes[0] if x < lo else self.slopes[1]
        return self.f(clipped) + (x - clipped) * slope


def _interpolant(values, speed, frequency, method: str):
    """A coefficient at (frequency, speed) (rad/s, speed defaulting to the frequency)."""
    values = np.asarray(values, float)
    if speed is not None and frequency is not None:
        rows = _Axis(speed, values, method)
        return lambda w, s=None: float(_Axis(frequency, rows(w if s is None else s),
                                             method)(w))
    axis = speed if speed is not None else frequency
    if axis is None:
        return lambda w, s=None: float(values.ravel()[0])
    along = _Axis(axis, values, method)
    if speed is not None:
        return lambda w, s=None: float(along(w if s is None else s))
    return lambda w, s=None: float(along(w))


#: the keys each element class needs, numbers all (ROSS 3.1's constructors' arguments)
_NEEDS = {"ShaftElement": ("L", "idl", "odl", "idr", "odr", "n"),
          "DiskElement": ("n", "m", "Id", "Ip"), "GearElement": ("n", "m", "Id", "Ip"),
          "GearElementTVMS": ("n", "m", "Id", "Ip"), "PointMass": ("n",),
          "CouplingElement": ("n", "L"), "MotorElement": ("n",), "bearing": ("n",)}
_MATERIAL = ("rho", "E", "G_s")
#: keys each class may hold that must then be finite numbers (ROSS 3.1's constructors'
#: keyword arguments), and those that must be true or false
_MAY = {"ShaftElement": ("axial_force", "torque", "alpha", "beta"),
        "PointMass": ("m", "mx", "my", "mz"),
        "CouplingElement": ("o_d", "m_l", "m_r", "Ip_l", "Ip_r", "Id_l", "Id_r", "kt_x",
                            "kt_y", "kt_z", "kr_x", "kr_y", "kr_z", "ct_x", "ct_y", "ct_z",
                            "cr_x", "cr_y", "cr_z"),
        "bearing": ("scale_factor", "g0", "i0", "ag", "nw", "alpha", "k_amp", "k_sense",
                    "kp_pid", "ki_pid", "kd_pid", "n_f", "sensors_axis_rotation",
                    "radial_clearance")}
_FLAGS = ("shear_effects", "rotary_inertia", "gyroscopic")


def _number(v) -> bool:
    return isinstance(v, (int, float)) and not isinstance(v, bool) and math.isfinite(v)


def _check(key: str, kind: str, table: dict, where: str) -> None:
    """Refuse an element table without the keys its class needs, or with one that is not
    a finite number, naming the element and the key."""
    for name in _NEEDS.get(kind, ()):
        if name not in table:
            raise ConfigError(f"{where}: {key}: missing {name!r} (a {kind} needs "
                              f"{', '.join(_NEEDS[kind])})")
        if not _number(table[name]):
            raise ConfigError(f"{where}: {key}: {name} = {table[name]!r} (expected a finite "
                              "number)")
    for name in _MAY.get(kind, ()):
        v = table.get(name)
        # a bearing's AMB setting may be tabulated like its coefficients (a list)
        flat = np.asarray(v, dtype=object).ravel() if kind == "bearing" and isinstance(
            v, list) else [v]
        if v is not None and not (len(flat) and all(_number(x) for x in flat)):
            raise ConfigError(f"{where}: {key}: {name} = {v!r} (expected a finite number)")
    if kind == "PointMass" and table.get("m") is None and (
            table.get("mx") is None or table.get("mx") != table.get("my")):
        raise ConfigError(f"{where}: {key}: missing 'm' (a PointMass needs its mass m, or "
                          "mx and my equal: ambseal's masses are the same in x and y)")
    for name in _FLAGS:
        if name in table and not isinstance(table[name], bool):
            raise ConfigError(f"{where}: {key}: {name} = {table[name]!r} (expected true or "
                              "false)")
    if kind == "ShaftElement":
        mat = table.get("material")
        for name in _MATERIAL:
            if not isinstance(mat, dict) or not _number(mat.get(name)):
                raise ConfigError(f"{where}: {key}: material {name} = "
                                  f"{(mat or {}).get(name)!r} (expected a finite number)")


def _check_table(key: str, table: dict, where: str) -> None:
    """A bearing's coefficients: finite numbers, one per point of its axis (or one), the
    axis strictly increasing (ROSS's interpolants need it)."""
    axes = [(a, table[a]) for a in ("speed", "frequency") if table.get(a) is not None]
    for a, ax in axes:
        ax = list(np.atleast_1d(ax)) if not isinstance(ax, list) else ax
        if not ax or not all(_number(x) for x in ax):
            raise ConfigError(f"{where}: {key}: {a} = {ax!r} (expected finite numbers)")
        if any(b <= c for c, b in zip(ax, ax[1:])):
            raise ConfigError(f"{where}: {key}: {a} = {ax!r} (expected strictly "
                              "increasing values)")
    shape = tuple(len(np.atleast_1d(ax)) for _, ax in axes)
    for name in _COEFFS + ("kzz", "czz", "mzz"):
        if name not in table:
            continue
        v = np.asarray(table[name], dtype=object)
        flat = list(v.ravel())
        if not flat or not all(_number(x) for x in flat):
            raise ConfigError(f"{where}: {key}: {name} = {table[name]!r} (expected finite "
                              "numbers)")
        if len(flat) > 1 and v.shape != shape:
            raise ConfigError(f"{where}: {key}: {name} has {v.shape} values for the table's "
                              f"{' × '.join(a for a, _ in axes) or 'no axis'} of "
                              f"{shape} points")


def _bearing(table: dict, where: str, seal: str | None = None) -> _Element:
    """A bearing, or a seal of ROSS's class ``seal`` (its saved coefficient tables)."""
    amb = all(k in table for k in _AMB_KEYS)
    kind = (MagneticBearingElement if amb else BearingElement if seal is None
            else SealElement if seal == "SealElement" else _kind(seal))
    el = kind(table)
    el.n_link = table.get("n_link")
    speed, freq = table.get("speed"), table.get("frequency")
    method = table.get("interpolation", "pchip")
    if method not in ("pchip", "linear"):
        raise ConfigError(f"{where}: bearing {el.tag}: interpolation {method!r} (expected "
                          "'pchip' or 'linear')")
    el.interpolation = method  # ROSS 3.1's default where the file names none
    shape = tuple(len(np.atleast_1d(a)) for a in (speed, freq) if a is not None)
    for name in _COEFFS + ("kzz", "mzz"):
        v = np.asarray(table.get(name, [0.0]), float)
        if v.size == 1 and shape:  # one value beside a table's axes: a constant
            v = np.full(shape, float(v.ravel()[0]))
        setattr(el, name, v)
        setattr(el, f"{name}_interpolated", _interpolant(v, speed, freq, method))
    if amb:
        # in ROSS's order of operations: the same factors to the last bit
        i0, g0, cos = np.asarray(el.i0, float), float(el.g0), math.cos(float(el.alpha))
        nw2, ag = float(el.nw) ** 2.0, float(el.ag)
        el.ki = 4.0 * i0 * cos * 4.0 * math.pi * 1e-7 * nw2 * ag / (4.0 * g0**2)
        el.ks = -4.0 * i0**2.0 * cos * 4.0 * math.pi * 1e-7 * nw2 * ag / (4.0 * g0**3)
        el.sensor_node = table.get("sensor_node", el.n)
        el.controller_transfer_function_num = table.get("controller_transfer_function_num")
        for key, default in (("k_amp", 1.0), ("k_sense", 1.0), ("kp_pid", 0.0),
                             ("ki_pid", 0.0), ("kd_pid", 0.0), ("n_f", 10000.0),
                             ("sensors_axis_rotation", 0.0)):
            setattr(el, key, table.get(key, default))
    return el


class _Rotor:
    """The rotor of the file with the attributes :func:`~ambseal.io.ross.from_ross` reads."""

    def __init__(self, data: dict, where: str):
        par = data["parameters"]
        for k in ("alpha", "beta", "default_damping_ratio"):
            if par.get(k) is not None and not _number(par[k]):
                raise ConfigError(f"{where}: parameters: {k} = {par[k]!r} (expected a finite "
                                  "number)")
        ratios = par.get("modal_damping_ratio")
        if ratios is not None and not all(_number(x) for x in np.atleast_1d(
                np.asarray(ratios, dtype=object))):
            raise ConfigError(f"{where}: parameters: modal_damping_ratio = {ratios!r} "
                              "(expected finite numbers)")
        self.tag = par.get("tag") or "Rotor 0"  # ROSS's name of a rotor without a tag
        self.alpha, self.beta = (float(par.get(k, 0.0) or 0.0) for k in ("alpha", "beta"))
        self.modal_damping_ratio = par.get("modal_damping_ratio")
        self.default_damping_ratio = float(par.get("default_damping_ratio", 0.0) or 0.0)
        self.shaft_elements, self.disk_elements, self.point_mass_elements = [], [], []
        self.bearing_elements, unknown, motors = [], [], []
        for key, table in data.items():
            kind = key.split("_")[0]
            if key in ("parameters", "ross_version") or not isinstance(table, dict):
                continue
            if "tag" not in table and "_" in key:  # ROSS's own tag: the key's second part
                table = {**table, "tag": key.split("_", 1)[1]}
            bearing = kind == "BearingElement" or kind.endswith("Seal")
            _check(key, "bearing" if bearing else kind, table, where)
            if bearing:
                _check_table(key, table, where)
            if kind == "ShaftElement":
                el = ShaftElement(table)
                el.material = _Material(table["material"])
                for k, d in (("axial_force", 0.0), ("torque", 0.0), ("alpha", 0.0),
                             ("beta", 0.0), ("shear_method_calc", "cowper"),
                             ("shear_effects", True), ("rotary_inertia", True),
                             ("gyroscopic", True)):  # ROSS 3.1's defaults
                    setattr(el, k, d if table.get(k) is None else table[k])
                self.shaft_elements.append(el)
            elif kind == "CouplingElement":
                self.shaft_elements.append(CouplingElement(table))
            elif kind in _DISKS:
                self.disk_elements.append(_DISKS[kind](table))
            elif kind == "MotorElement":  # no matrices in ROSS's rotor: named, left out
                motors.append(MotorElement(table))
            elif kind == "PointMass":  # ROSS saves m = None where mx and my were given
                self.point_mass_elements.append(PointMass(
                    {**table, "m": table["mx"] if table.get("m") is None else table["m"]}))
            elif kind == "BearingElement":
                self.bearing_elements.append(_bearing(table, where))
            elif kind.endswith("Seal") or kind == "SealElement":
                # a seal of any of ROSS's models (labyrinth, hole-pattern, ...): ROSS 3
                # loads its saved coefficient tables as they are, without its model
                if "kxx" not in table:
                    unknown.append(f"{kind} {table.get('tag', key)} (no coefficients)")
                    continue
                self.bearing_elements.append(_bearing(table, where, kind))
            else:
                unknown.append(f"{kind} {table.get('tag', key)}")
        if unknown:
            raise ConfigError(f"{where}: element(s) this reader of ROSS 3 files does not "
                              f"know: {', '.join(unknown)} (install ROSS 3, on Python 3.12 "
                              "or newer, and import again)")
        self.elements = [*self.shaft_elements, *self.disk_elements,
                         *self.point_mass_elements, *self.bearing_elements, *motors]
        for el in self.elements:
            for attr in ("n", "n_link"):
                n = getattr(el, attr, None)
                if n is not None and not (_number(n) and n == int(n) and n >= 0):
                    raise ConfigError(f"{where}: {type(el).__name__} {el.tag}: {attr} = "
                                      f"{n!r} (expected a node number, an integer ≥ 0)")
                if n is not None:
                    setattr(el, attr, int(n))  # 2.0 is node 2
        last = max([int(el.n) + 1 for el in self.shaft_elements], default=0)
        for el in self.disk_elements:  # a disk sits on the shaft (housings hold masses)
            if int(el.n) > last:
                raise ConfigError(f"{where}: {type(el).__name__} {el.tag}: node {el.n} is "
                                  f"not on the shaft (nodes 0–{last})")

    def axial_torsional_rad_s(self) -> np.ndarray:
        """ROSS's axial and torsional natural frequencies (rad/s) at standstill, ascending:
        the z and θ DOFs of its six per node, which its lateral ones do not couple to
        (module docstring); DOFs without inertia or stiffness (a housing's θ) left out."""
        nodes = 1 + max([int(el.n) + 1 for el in self.shaft_elements]
                        + [int(n) for el in self.elements
                           for n in (el.n, getattr(el, "n_link", None) or 0)])
        M, K = np.zeros((2 * nodes, 2 * nodes)), np.zeros((2 * nodes, 2 * nodes))

        def pair(dof, n, m, k):  # an element on DOF z (0) or θ (1) of nodes n and n + 1:
            # mass m (its 2×2 matrix, or 0), stiffness k [1 −1; −1 1]
            i = [2 * n + dof, 2 * (n + 1) + dof]
            M[np.ix_(i, i)] += m
            K[np.ix_(i, i)] += k * np.array([[1.0, -1.0], [-1.0, 1.0]])

        for el in self.shaft_elements:
            n = int(el.n)
            if type(el).__name__ == "CouplingElement":
                for dof, (a, b) in enumerate((("m_l", "m_r"), ("Ip_l", "Ip_r"))):
                    M[2 * n + dof, 2 * n + dof] += float(getattr(el, a, 0.0))
                    M[2 * n + 2 + dof, 2 * n + 2 + dof] += float(getattr(el, b, 0.0))
                pair(0, n, 0.0, float(getattr(el, "kt_z", 0.0)))
                pair(1, n, 0.0, float(getattr(el, "kr_z", 0.0)))
                continue
            mat, L = el.material, float(el.L)
            area = np.pi * ((el.odl**2 - el.idl**2) + (el.odr**2 - el.idr**2)) / 8
            polar = np.pi * ((el.odl**4 - el.idl**4) + (el.odr**4 - el.idr**4)) / 64
            consistent = np.array([[2.0, 1.0], [1.0, 2.0]]) / 6
            pair(0, n, mat.rho * area * L * consistent, mat.E * area / L)
            pair(1, n, mat.rho * polar * L * consistent, mat.G_s * polar / L)
        for d in self.disk_elements:
            M[2 * d.n, 2 * d.n] += float(d.m)
            M[2 * d.n + 1, 2 * d.n + 1] += float(d.Ip)
        for p in self.point_mass_elements:
            M[2 * p.n, 2 * p.n] += float(getattr(p, "mz", p.m))
        for b in self.bearing_elements:
            k, m = b.kzz_interpolated(0.0), b.mzz_interpolated(0.0)
            i = [2 * b.n] + ([] if b.n_link is None else [2 * int(b.n_link)])
            rel = np.array([[1.0]]) if b.n_link is None else np.array([[1.0, -1.0],
                                                                      [-1.0, 1.0]])
            K[np.ix_(i, i)] += k * rel
            M[np.ix_(i, i)] += m * rel
        keep = np.flatnonzero((np.abs(M).sum(axis=1) > 0) | (np.abs(K).sum(axis=1) > 0))
        M, K = M[np.ix_(keep, keep)], K[np.ix_(keep, keep)]
        w2 = scipy.linalg.eigh(K, M, eigvals_only=True)
        return np.sqrt(w2[w2 >= 0])


def read_ross3_file(path: str | Path, data: dict):
    """The rotor of a ROSS 3 file as plain objects for :func:`ambseal.io.ross.from_ross`.

    Parameters
    ----------
    path : str or Path
        The file (for messages).
    data : dict
        Its tables, as read (TOML or JSON).

    Returns
    -------
    object
        With ``tag``, ``alpha``, ``beta``, ``modal_damping_ratio``,
        ``default_damping_ratio``, ``shaft_elements`` (couplings among them),
        ``disk_elements``, ``point_mass_elements``, ``bearing_elements`` and ``elements``,
        each element with the attributes of ROSS 3.1's of the same class.

    Raises
    ------
    ConfigError
        An element class the reader does not know, or a table interpolation other than
        ROSS's.
    """
    return _Rotor(data, str(path))
