"""Annular seals: Childs' linearised seal force, its coefficients and parameter channels.

The seal acts at one node on the lateral displacements q = [x, y] (Childs, *Turbomachinery
Rotordynamics*, 1993, §3.2; thesis P4 Eq. 3):

    −f = [K k; −k K] q + [C c; −c C] q̇ + M q̈,

positive K restores, positive k drives forward whirl. Each coefficient is a number, affine
in the pressure drop (``at_zero + per_bar · pressure_bar``, thesis P5 §4.1) or a table
against excitation frequency (thesis P3 §4, taken at the synchronous frequency Ω/2π unless
told otherwise), interpolated linearly (or by pchip) and held constant (or continued with
its end slope) outside the table (:func:`table_value`).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.interpolate import PchipInterpolator

from ambseal.config import Affine, FrequencyTable, Seal
from ambseal.errors import ModelError
from ambseal.lti import interp_table
from ambseal.model.lft import Channel
from ambseal.model.rotor import Mesh, X, Y

__all__ = ["COEFFICIENTS", "coefficient_value", "table_value", "seal_coefficients",
           "seal_values", "pressure_for_k", "values_following_k", "SealElement"]

COEFFICIENTS = ("K", "k", "C", "c", "M")
"""The seal coefficients in Childs' convention, in the order of the rig file."""

_SKEW = np.array([[0.0, 1.0], [-1.0, 0.0]])
_UNITS = {"K": "N/m", "k": "N/m", "C": "N*s/m", "c": "N*s/m"}


def coefficient_value(c: float | Affine | FrequencyTable, pressure_bar: float,
                      frequency_hz: float | None = None) -> float:
    """The value of one rig coefficient at a pressure drop and excitation frequency.

    Parameters
    ----------
    c : float, Affine or FrequencyTable
        The coefficient as read from the rig file (or a truth file).
    pressure_bar : float
        Pressure drop across the seal (bar); used by an :class:`~ambseal.config.Affine`.
    frequency_hz : float, optional
        Excitation frequency (Hz); required for a
        :class:`~ambseal.config.FrequencyTable`, ignored otherwise.

    Returns
    -------
    float
        ``c``, ``at_zero + per_bar · pressure_bar``, or the table at ``frequency_hz``
        (:func:`table_value`).

    Raises
    ------
    ModelError
        A frequency table without ``frequency_hz``.
    """
    if isinstance(c, Affine):
        return c.at_zero + c.per_bar * pressure_bar
    if isinstance(c, FrequencyTable):
        if frequency_hz is None:
            raise ModelError("a frequency-dependent seal coefficient needs a frequency "
                             "(by default the synchronous one; at standstill the table's "
                             "first value holds)")
        return table_value(c, frequency_hz)
    return float(c)


def table_value(table: FrequencyTable, frequency_hz: float) -> float:
    """A frequency table's value (:class:`~ambseal.config.FrequencyTable`): interpolated
    linearly or by a shape-preserving piecewise cubic Hermite interpolant (``pchip``,
    Fritsch & Carlson, *SIAM J. Numer. Anal.* 17, 1980; SciPy's ``PchipInterpolator``;
    linear between two points), and outside the table held at the end value or continued
    with the end slope (``extrapolation = "linear"``) — ROSS 3.1's
    ``BearingCoefficient`` along one axis is ``pchip`` or ``linear`` with the end slope.

    Parameters
    ----------
    table : FrequencyTable
        The points (Hz), the values, and the laws between and beyond them.
    frequency_hz : float
        The excitation frequency (Hz).

    Returns
    -------
    float
    """
    x = np.asarray(table.frequency_hz, float)
    y = np.asarray(table.value, float)
    if x.size == 1:
        return float(y[0])
    f = float(frequency_hz)
    inside = min(max(f, x[0]), x[-1])
    if table.interpolation == "pchip" and x.size > 2:
        p = PchipInterpolator(x, y)
        value, slope = float(p(inside)), p.derivative()
    else:
        value, slope = interp_table(inside, x, y), None
    if table.extrapolation == "hold" or f == inside:
        return value
    end = 0 if f < inside else -1
    if slope is not None:
        d = float(slope(x[end]))
    else:
        d = float((y[1] - y[0]) / (x[1] - x[0]) if end == 0 else
                  (y[-1] - y[-2]) / (x[-1] - x[-2]))
    return value + (f - inside) * d


def seal_coefficients(seal: Seal, pressure_bar: float,
                      frequency_hz: float | None = None) -> dict[str, float]:
    """Coefficients K, k (N/m), C, c (N·s/m), M (kg) of a seal at a pressure drop (bar)
    and, for tabulated ones, an excitation frequency (Hz); see :func:`coefficient_value`.

    Parameters
    ----------
    seal : Seal
        A rig file's ``[[seal]]`` entry (Childs' convention, thesis P4 Eq. 3).
    pressure_bar : float
        Pressure drop across the seal (bar).
    frequency_hz : float, optional
        Excitation frequency (Hz) at which tabulated coefficients are interpolated.

    Returns
    -------
    dict of str to float
        ``{"K": …, "k": …, "C": …, "c": …, "M": …}`` in SI.

    Raises
    ------
    ModelError
        A tabulated coefficient and no ``frequency_hz``.
    """
    return {n: coefficient_value(getattr(seal, n), pressure_bar, frequency_hz)
            for n in COEFFICIENTS}


def seal_values(seals, pressure_bar: float) -> dict[str, float]:
    """Every constant or pressure-dependent coefficient of every seal at a pressure drop
    (bar), by LFT name (``"<seal>.K"``, ...; SI): e.g. the value a controller scheduled on
    a seal coefficient is frozen at for a judged condition. Tabulated coefficients (they
    need a frequency) are left out.

    Parameters
    ----------
    seals : sequence of Seal
        The rig's ``[[seal]]`` entries.
    pressure_bar : float
        Pressure drop across the seals (bar).

    Returns
    -------
    dict of str to float
        ``{"<seal>.<K|k|C|c|M>": value}``, SI.
    """
    return {f"{s.name}.{n}": coefficient_value(getattr(s, n), pressure_bar)
            for s in seals for n in COEFFICIENTS
            if not isinstance(getattr(s, n), FrequencyTable)}


def pressure_for_k(seals, name: str, value: float) -> float | None:
    """The pressure drop (bar) at which the seal named by ``name`` (``"<seal>.k"``) has the
    cross-coupled stiffness k = ``value`` (N/m), k = k₀ + k'·p affine with k' ≠ 0:
    p = max((k − k₀)/k', 0).

    Parameters
    ----------
    seals : sequence of Seal
        The rig's ``[[seal]]`` entries.
    name : str
        A parameter name; the rule applies to ``"<seal>.k"``.
    value : float
        The cross-coupled stiffness k (N/m).

    Returns
    -------
    float or None
        The pressure drop (bar), ≥ 0; None when ``name`` is no seal's k affine in the
        pressure drop with k' ≠ 0.
    """
    seal_name, _, key = name.rpartition(".")
    seal = next((s for s in seals if s.name == seal_name), None)
    if key != "k" or seal is None or not isinstance(seal.k, Affine) or not seal.k.per_bar:
        return None
    return max((value - seal.k.at_zero) / seal.k.per_bar, 0.0)


def values_following_k(seals, name: str, value: float, known) -> dict[str, float]:
    """``{name: value}`` and, when ``name`` is a seal's cross-coupled stiffness k affine in
    the pressure drop (k = k₀ + k'·p, k' ≠ 0), every other coefficient of every seal at the
    pressure p = max((k − k₀)/k', 0) that gives k (:func:`pressure_for_k`,
    :func:`seal_values`) — the seal model's own structure (thesis §7.4 item 2: the
    coefficients move together with the pressure, and the rig has one pressure drop, which
    every seal's coefficients follow); only those in ``known`` (the plant's parameter
    names) are returned. :func:`values_following` for several tracked values.

    Parameters
    ----------
    seals : sequence of Seal
        The rig's ``[[seal]]`` entries.
    name : str
        A parameter name, ``"<seal>.k"`` for the rule to apply.
    value : float
        Its value (SI).
    known : container of str
        The names that may be returned (the plant's parameter names).

    Returns
    -------
    dict
        Parameter name → value (SI).
    """
    return values_following(seals, {name: value}, known)


def values_following(seals, values: dict, known) -> dict[str, float]:
    """``values`` (name → SI) and the seal coefficients that follow them: every seal's
    coefficients at the pressure that gives the first seal k affine in the pressure among
    ``values`` (:func:`values_following_k`), the other coefficients of each seal whose k is
    in ``values`` at the pressure of its own k; the given values win; only names in
    ``known``.

    Parameters
    ----------
    seals : sequence of Seal
        The rig's ``[[seal]]`` entries.
    values : dict
        Parameter name → value (SI), the tracked or fitted ones.
    known : container of str
        The names that may be returned besides ``values`` (the plant's parameter names).

    Returns
    -------
    dict
        Parameter name → value (SI): ``values`` and the coefficients that follow them.
    """
    pressures = {n: pressure_for_k(seals, n, v) for n, v in values.items()}
    pressures = {n.rpartition(".")[0]: p for n, p in pressures.items() if p is not None}
    if not pressures:
        return dict(values)
    out = {n: v for n, v in seal_values(seals, next(iter(pressures.values()))).items()
           if n in known}
    for seal_name, p in pressures.items():
        out.update({n: v for n, v in seal_values(seals, p).items()
                    if n in known and n.rpartition(".")[0] == seal_name})
    return {**out, **values}


@dataclass(frozen=True)
class SealElement:
    """A seal at one node, with its coefficients evaluated.

    Attributes
    ----------
    name : str
        The seal's name; its channels are ``{name}.K``, ``.k``, ``.C``, ``.c``.
    node : int
        Mesh node of the seal.
    values : dict
        K, k (N/m), C, c (N·s/m), M (kg).
    """

    name: str
    node: int
    values: dict

    @classmethod
    def from_config(cls, seal: Seal, mesh: Mesh, pressure_bar: float,
                    frequency_hz: float | None) -> "SealElement":
        """The element of a rig's ``[[seal]]`` at a pressure drop (bar) and, for tables,
        an excitation frequency (Hz)."""
        return cls(seal.name, mesh.node_at(seal.position),
                   seal_coefficients(seal, pressure_bar, frequency_hz))

    def matrices(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(K, C, M), each (2, 2) on [x, y] of the node: [K k; −k K], [C c; −c C], M·I."""
        v, eye = self.values, np.eye(2)
        return v["K"] * eye + v["k"] * _SKEW, v["C"] * eye + v["c"] * _SKEW, v["M"] * eye

    def assemble(self, M: np.ndarray, C: np.ndarray, K: np.ndarray) -> None:
        """Add the seal to the global matrices (n_dof, n_dof), in place."""
        i = np.ix_(self._dofs(), self._dofs())
        Ke, Ce, Me = self.matrices()
        K[i] += Ke
        C[i] += Ce
        M[i] += Me

    def channels(self, n_dof: int) -> list[Channel]:
        """LFT channels of K, k (ΔK = θ [I; R90]), C and c (ΔC likewise), rank 2 each:
        k and −k are one parameter repeated (thesis P5 §4.1 item 3)."""
        ex, ey = np.zeros(n_dof), np.zeros(n_dof)
        ex[self._dofs()[0]], ey[self._dofs()[1]] = 1.0, 1.0
        eye2 = np.column_stack([ex, ey])
        rot90 = np.column_stack([ey, -ex])
        v = self.values
        return [Channel(f"{self.name}.{key}", v[key], _UNITS[key], kind, eye2, V)
                for key, kind, V in (("K", "K", eye2), ("k", "K", rot90),
                                     ("C", "C", eye2), ("c", "C", rot90))]

    def _dofs(self) -> list[int]:
        return [4 * self.node + X, 4 * self.node + Y]
