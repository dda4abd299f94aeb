"""Springs: a flexible coupling (thesis P4 Eq. 4) or a plain bearing at one node.

Given in its own axes u, v, rotated by ``axes_angle_deg`` from x, y ([u, v]ᵀ = R [x, y]ᵀ,
R of :func:`ambseal.model.amb.axes_rotation`), the spring force is

    −f = Rᵀ [kxx kxy; kyx kyy] R q + Rᵀ [cxx cxy; cyx cyy] R q̇ + Rᵀ [mxx mxy; myx myy] R q̈,

q = [x, y] of the node: the change of basis of a 2×2 stiffness (damping, added mass) tensor
given in rotated axes. The cross-coupled damping cxy, cyx (an imported plain bearing's) and
the added mass (a seal's fluid inertia, ROSS's bearing ``mxx`` …) are fixed: not among the
spring's parameters (:data:`KEYS`).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ambseal.config import Spring
from ambseal.model.amb import axes_rotation
from ambseal.model.lft import Channel
from ambseal.model.rotor import Mesh, X, Y

__all__ = ["KEYS", "spring_label", "SpringElement"]

KEYS = ("kxx", "kyy", "kxy", "kyx", "cxx", "cyy")
"""The spring's parameters in the order of its channels."""

_ENTRY = {"kxx": (0, 0), "kyy": (1, 1), "kxy": (0, 1), "kyx": (1, 0), "cxx": (0, 0),
          "cyy": (1, 1)}


def spring_label(spring: Spring, index: int) -> str:
    """The spring's name, or ``spring{index}`` for an unnamed ``[[spring]]`` (its index in
    the rig file): the prefix of its channels ``{label}.kxx`` ..."""
    return spring.name or f"spring{index}"


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
    """

    label: str
    node: int
    R: np.ndarray
    k: np.ndarray
    c: np.ndarray
    m: np.ndarray

    @classmethod
    def from_config(cls, spring: Spring, mesh: Mesh, index: int) -> "SpringElement":
        """The element of the rig's ``[[spring]]`` number ``index``."""
        return cls(spring_label(spring, index), mesh.node_at(spring.position),
                   axes_rotation(spring.axes_angle_deg),
                   np.array([[spring.kxx, spring.kxy], [spring.kyx, spring.kyy]]),
                   np.array([[spring.cxx, spring.cxy], [spring.cyx, spring.cyy]]),
                   np.array([[spring.mxx, spring.mxy], [spring.myx, spring.myy]]))

    def matrices(self) -> tuple[np.ndarray, np.ndarray]:
        """(K, C), each (2, 2) on [x, y] of the node: Rᵀ k R and Rᵀ c R."""
        R = self.R
        return R.T @ self.k @ R, R.T @ self.c @ R

    def assemble(self, M: np.ndarray, C: np.ndarray, K: np.ndarray) -> None:
        """Add the spring to the global M, C and K (n_dof, n_dof), in place."""
        i = np.ix_(self._dofs(), self._dofs())
        Ke, Ce = self.matrices()
        K[i] += Ke
        C[i] += Ce
        M[i] += self.R.T @ self.m @ self.R

    def channels(self, n_dof: int) -> list[Channel]:
        """One rank-1 channel per entry of :data:`KEYS`: Δ(kab) changes K by θ d_a d_bᵀ with
        d_a the spring's axis a at the node in global DOFs (likewise cxx, cyy for C)."""
        d = []
        for a in range(2):
            v = np.zeros(n_dof)
            v[self._dofs()] = self.R[a]
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
