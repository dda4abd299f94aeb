"""Springs: a flexible coupling (thesis P4 Eq. 4) or a plain bearing at one node.

Given in its own axes u, v, rotated by ``axes_angle_deg`` from x, y ([u, v]ᵀ = R [x, y]ᵀ,
R of :func:`ambseal.model.amb.axes_rotation`), the spring force is

    −f = Rᵀ [kxx kxy; kyx kyy] R q + Rᵀ [cxx cxy; cyx cyy] R q̇ + Rᵀ [mxx mxy; myx myy] R q̈,

q = [x, y] of the node: the change of basis of a 2×2 stiffness (damping, added mass) tensor
given in rotated axes. The cross-coupled damping cxy, cyx (an imported plain bearing's) and
the added mass (a seal's fluid inertia, ROSS's bearing ``mxx`` …) are fixed: not among the
spring's parameters (:data:`KEYS`).

A spring with a ``housing`` joins the node to the housing's mass instead of to ground:
q is then the node's motion relative to the housing's, q − h, and the housing,
m_h ḧ = f + k_h (−h) + c_h (−ḣ) with f the spring's force on it, has two DOFs of its own,
x and y, after the shaft's: a bearing on a flexible pedestal, as ROSS models a support
(a bearing linked, ``n_link``, to a node with a point mass on bearings of its own).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ambseal.config import SPRING_BOUNDS, FrequencyTable, Spring
from ambseal.model.amb import axes_rotation
from ambseal.model.lft import Channel
from ambseal.model.rotor import Mesh, X, Y
from ambseal.model.seal import table_value

__all__ = ["KEYS", "spring_label", "spring_at", "SpringElement"]

KEYS = ("kxx", "kyy", "kxy", "kyx", "cxx", "cyy")
"""The spring's parameters in the order of its channels."""

_ENTRY = {"kxx": (0, 0), "kyy": (1, 1), "kxy": (0, 1), "kyx": (1, 0), "cxx": (0, 0),
          "cyy": (1, 1)}


def spring_label(spring: Spring, index: int) -> str:
    """The spring's name, or ``spring{index}`` for an unnamed ``[[spring]]`` (its index in
    the rig file): the prefix of its channels ``{label}.kxx`` ... and of its housing's DOFs
    ``{label}_housing_x``, ``_y``.

    Parameters
    ----------
    spring : Spring
        The rig file's ``[[spring]]``.
    index : int
        Its index among the rig file's springs.

    Returns
    -------
    str
    """
    return spring.name or f"spring{index}"


def spring_at(spring: Spring, frequency_hz: float) -> Spring:
    """The spring with each tabulated coefficient taken at a frequency (a bearing's
    coefficients over speed, at the synchronous frequency as ROSS's ``run_modal`` and
    unbalance response take them; :func:`ambseal.model.seal.table_value`).

    Parameters
    ----------
    spring : Spring
        The rig file's ``[[spring]]``.
    frequency_hz : float
        The frequency (Hz).

    Returns
    -------
    Spring
        ``spring`` itself where nothing is tabulated, else a copy with numbers.
    """
    if not spring.tabulated:
        return spring
    return spring.model_copy(update={
        k: table_value(v, frequency_hz) for k in SPRING_BOUNDS
        if isinstance(v := getattr(spring, k), FrequencyTable)})


@dataclass(frozen=True)
class SpringElement:
    """A spring at one node.

    Attributes
    ----------
    label : str
        Channel prefix (:func:`spring_label`).
    node : int
        Mesh node.
    R : ndarray, shape (2, 2)
        Rotation from x, y to the spring's axes.
    k : ndarray, shape (2, 2)
        [kxx kxy; kyx kyy] (N/m) in the spring's axes.
    c : ndarray, shape (2, 2)
        [cxx cxy; cyx cyy] (N·s/m) in the spring's axes.
    m : ndarray, shape (2, 2)
        [mxx mxy; myx myy] (kg) in the spring's axes.
    housing : tuple, optional
        The housing behind the spring: (its first DOF, the x one, the y one next; its
        mass in kg; its support stiffness (2, 2) in N/m and damping (2, 2) in N·s/m, in
        x, y).
    """

    label: str
    node: int
    R: np.ndarray
    k: np.ndarray
    c: np.ndarray
    m: np.ndarray
    housing: tuple | None = None

    @classmethod
    def from_config(cls, spring: Spring, mesh: Mesh, index: int,
                    housing_dof: int | None = None, frequency_hz: float = 0.0
                    ) -> "SpringElement":
        """The element of the rig's ``[[spring]]`` number ``index``; ``housing_dof``: the
        first of its housing's two DOFs (a spring with a ``housing``); ``frequency_hz``:
        where its tabulated coefficients are taken (:func:`spring_at`)."""
        spring = spring_at(spring, frequency_hz)
        h = spring.housing
        if (h is None) != (housing_dof is None):
            raise ValueError(f"spring {index}: a housing needs its DOFs and only a housing "
                             "has them")
        house = None if h is None else (
            housing_dof, h.mass, np.array([[h.kxx, h.kxy], [h.kyx, h.kyy]]),
            np.array([[h.cxx, h.cxy], [h.cyx, h.cyy]]))
        return cls(spring_label(spring, index), mesh.node_at(spring.position),
                   axes_rotation(spring.axes_angle_deg),
                   np.array([[spring.kxx, spring.kxy], [spring.kyx, spring.kyy]]),
                   np.array([[spring.cxx, spring.cxy], [spring.cyx, spring.cyy]]),
                   np.array([[spring.mxx, spring.mxy], [spring.myx, spring.myy]]), house)

    def matrices(self) -> tuple[np.ndarray, np.ndarray]:
        """(K, C), each (2, 2) on [x, y] of the node: Rᵀ k R and Rᵀ c R."""
        R = self.R
        return R.T @ self.k @ R, R.T @ self.c @ R

    def assemble(self, M: np.ndarray, C: np.ndarray, K: np.ndarray) -> None:
        """Add the spring (and its housing) to the global M, C and K (n_dof, n_dof), in
        place."""
        Ke, Ce = self.matrices()
        Me = self.R.T @ self.m @ self.R
        T = self._relative()  # (2, n): the node's motion relative to the housing's
        dofs = self._dofs() + self._housing_dofs()
        i = np.ix_(dofs, dofs)
        for glob, local in ((K, Ke), (C, Ce), (M, Me)):
            glob[i] += T.T @ local @ T
        if self.housing is not None:
            j = np.ix_(self._housing_dofs(), self._housing_dofs())
            _, mass, kh, ch = self.housing
            M[j] += mass * np.eye(2)
            K[j] += kh
            C[j] += ch

    def channels(self, n_dof: int) -> list[Channel]:
        """One rank-1 channel per entry of :data:`KEYS`: Δ(kab) changes K by θ d_a d_bᵀ with
        d_a the spring's axis a at the node in global DOFs, less at the housing's where it
        has one (likewise cxx, cyy for C)."""
        d = []
        dofs = self._dofs() + self._housing_dofs()
        for a in range(2):
            v = np.zeros(n_dof)
            v[dofs] = self.R[a] @ self._relative()
            d.append(v)
        out = []
        for key in KEYS:
            a, b = _ENTRY[key]
            kind, unit = ("K", "N/m") if key[0] == "k" else ("C", "N*s/m")
            nominal = float(self.k[a, b] if kind == "K" else self.c[a, b])
            out.append(Channel(f"{self.label}.{key}", nominal, unit, kind,
                               d[a][:, None], d[b][:, None]))
        return out

    def _dofs(self) -> list[int]:
        return [4 * self.node + X, 4 * self.node + Y]

    def _housing_dofs(self) -> list[int]:
        return [] if self.housing is None else [self.housing[0], self.housing[0] + 1]

    def _relative(self) -> np.ndarray:
        """[I] on the node's x, y, or [I, −I] on the node's and the housing's."""
        eye = np.eye(2)
        return eye if self.housing is None else np.hstack([eye, -eye])
