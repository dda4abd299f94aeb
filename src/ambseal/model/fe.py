"""Finite-element matrices of shaft (beam) elements and rigid disks.

Node DOF order is [x, y, α, β] (α rotation about x, β about y), see :mod:`ambseal.model.rotor`.
With z the rotor axis, β = ∂x/∂z and α = −∂y/∂z. The element matrices below are first
written in *plane coordinates* — per bending plane [w1, φ1, w2, φ2] with φ the slope
(x–z plane: w = x, φ = β; y–z plane: w = y, φ = −α) — and then mapped to node DOFs.

Sources: Nelson, "A finite rotating shaft element using Timoshenko beam theory", J. Mech.
Des. 102 (1980); Friswell, Penny, Garvey & Lees, *Dynamics of Rotating Machines*, CUP 2010,
§5.4–5.5 (Timoshenko element matrices with the shear parameter Φ = 12EI/(κGAL²)); the
shear coefficient of a hollow circular section from Hutchinson (2001).
Every element owns its ``M()``, ``K()``, ``G()``, ``C()`` and DOF mapping; the rotor only
assembles.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

__all__ = ["BeamElement", "CouplingElement", "LayeredBeam", "DiskElement", "shear_coefficient"]

# Node-DOF index of each plane coordinate: x-plane (x, β) and y-plane (y, −α).
_X, _Y, _A, _B = 0, 1, 2, 3
# Element DOFs (8) in node order [x1 y1 α1 β1 x2 y2 α2 β2]; plane coords -> node DOF + sign
_PX = np.array([_X, _B, 4 + _X, 4 + _B])
_PY = np.array([_Y, _A, 4 + _Y, 4 + _A])
_SX = np.array([1.0, 1.0, 1.0, 1.0])
_SY = np.array([1.0, -1.0, 1.0, -1.0])
# The same map for [x-plane, y-plane] (8, 8) matrices, built once: index grid and signs.
_IDX8 = np.ix_(np.concatenate([_PX, _PY]), np.concatenate([_PX, _PY]))
_SGN8 = np.outer(np.concatenate([_SX, _SY]), np.concatenate([_SX, _SY]))


def shear_coefficient(nu: float, inner_diameter: float, outer_diameter: float) -> float:
    """Timoshenko shear coefficient κ of a (hollow) circular section.

    κ = 6(1+ν)(1+m²)² / [(7+6ν)(1+m²)² + (20+12ν)m²], m = d_i/d_o
    (Cowper 1966 / Hutchinson 2001; κ = 6(1+ν)/(7+6ν) for a solid section).
    """
    m2 = (inner_diameter / outer_diameter) ** 2
    return 6 * (1 + nu) * (1 + m2) ** 2 / ((7 + 6 * nu) * (1 + m2) ** 2 + (20 + 12 * nu) * m2)


#: 5-point Gauss–Legendre rule on [0, 1]: exact for polynomials up to degree 9, which the
#: products of the element's cubic interpolation (and a section's quartic I(z)) stay below.
_GAUSS = ((np.polynomial.legendre.leggauss(5)[0] + 1) / 2,
          np.polynomial.legendre.leggauss(5)[1] / 2)


def _shape(xi: np.ndarray, L: float, p: float) -> tuple[np.ndarray, ...]:
    """The Timoshenko element's interpolation at ξ = z/L (Nelson 1980; Friswell et al. 2010
    §5.4.4), rows per point, columns the plane coordinates [w1, φ1, w2, φ2]: N_w, ∂N_w/∂z,
    N_ψ (the section rotation), ∂N_ψ/∂z. Φ = 0 gives the Hermite cubics with ψ = w'."""
    xi = np.asarray(xi, float)[:, None]
    o, x2, x3 = np.ones_like(xi), xi**2, xi**3
    k = 1 / (1 + p)
    nw = np.hstack([1 - 3 * x2 + 2 * x3 + p * (1 - xi),
                    L * (xi - 2 * x2 + x3 + p / 2 * (xi - x2)),
                    3 * x2 - 2 * x3 + p * xi,
                    L * (-x2 + x3 - p / 2 * (xi - x2))]) * k
    dnw = np.hstack([(-6 * xi + 6 * x2 - p) / L,
                     1 - 4 * xi + 3 * x2 + p / 2 * (1 - 2 * xi),
                     (6 * xi - 6 * x2 + p) / L,
                     -2 * xi + 3 * x2 - p / 2 * (1 - 2 * xi)]) * k
    npsi = np.hstack([6 * (x2 - xi) / L, 1 - 4 * xi + 3 * x2 + p * (1 - xi),
                      -6 * (x2 - xi) / L, -2 * xi + 3 * x2 + p * xi]) * k
    dnpsi = np.hstack([6 * (2 * xi - 1) / L**2, (-4 + 6 * xi - p) / L,
                       -6 * (2 * xi - 1) / L**2, (-2 + 6 * xi + p) / L]) * k
    return nw, dnw, npsi, dnpsi + 0 * o


def _to_nodes(plane: np.ndarray, coupled: bool = False) -> np.ndarray:
    """Map plane-coordinate matrices to the 8 element DOFs.

    ``plane`` is (4, 4) applied to both planes, or for ``coupled`` an (8, 8) matrix on
    [x-plane, y-plane] coordinates.
    """
    out = np.zeros((8, 8))
    if coupled:
        full = plane
    else:
        full = np.zeros((8, 8))
        full[:4, :4] = plane
        full[4:, 4:] = plane
    out[_IDX8] = full * _SGN8
    return out


@dataclass(frozen=True)
class BeamElement:
    """A circular (hollow) shaft element between two nodes: uniform or conical.

    A uniform element has the closed-form matrices of Friswell et al. (2010) §5.4. A conical
    one (``outer_diameter_right`` / ``inner_diameter_right`` differ from the left end's) is
    Genta & Gugliotta's element ("A conical element for finite element rotor dynamics",
    J. Sound Vib. 120 (1988) 175–182): the uniform Timoshenko element's interpolation, with
    Φ and κ of the section at mid-length, integrated exactly against the section's A(z)
    (quadratic in z) and I(z) (quartic): M = ρ∫A N_wᵀN_w + ρ∫I N_ψᵀN_ψ, K = E∫I N_ψ'ᵀN_ψ' +
    κG∫A γᵀγ (γ = w' − ψ), G from 2ρ∫I N_ψᵀN_ψ. So a conical element is exact in its
    geometry, not a stepped approximation; the integrals are taken by a 5-point Gauss rule,
    exact for these polynomials (degree ≤ 8). ROSS 2.3's ``ShaftElement`` is the same
    element: the matrices agree to round-off.

    Parameters
    ----------
    length : float
        Element length L (m).
    outer_diameter, inner_diameter : float
        Diameters (m), at the left end (node 1) of a conical element.
    E, shear_modulus, rho : float
        Young's modulus (Pa), shear modulus (Pa), density (kg/m³).
    timoshenko : bool
        Shear deformation on (Timoshenko, Φ > 0) or off (Euler–Bernoulli with rotary
        inertia, Φ = 0).
    rotary_inertia : bool
        The rotary inertia of the section in :meth:`M` (Friswell et al. 2010, Eq. 5.63);
        off, M is the translational mass matrix alone (Rayleigh's beam without its rotary
        term, as ROSS's ``rotary_inertia=False``).
    gyroscopic : bool
        The gyroscopic matrix :meth:`G` (Friswell Eq. 5.64); off, G = 0 (ROSS's
        ``gyroscopic=False``). Independent of ``rotary_inertia``: a section may spin with
        its polar inertia while its diametral rotary inertia is left out, as in ROSS.
    axial_force : float
        Axial force P (N), tension positive: its geometric stiffness in :meth:`K`
        (:meth:`_geometric`).
    torque : float
        Torque T (N·m) the element carries: its geometric stiffness in :meth:`K`, which
        couples the bending planes and is not symmetric (:meth:`_geometric`).
    outer_diameter_right, inner_diameter_right : float, optional
        Diameters (m) at the right end (node 2); None: the left end's (uniform).
    rayleigh_alpha, rayleigh_beta : float
        Rayleigh (proportional) damping of the element, :meth:`C` = α·M + β·K: α in 1/s,
        β in s (ROSS's ``ShaftElement`` ``alpha``, ``beta``). A mode of a uniform free beam
        damped this way has ζ = α/(2ω) + βω/2 (Rayleigh 1877; Craig & Kurdila 2006 §10.2).
    """

    length: float
    outer_diameter: float
    inner_diameter: float
    E: float
    shear_modulus: float
    rho: float
    timoshenko: bool = True
    rotary_inertia: bool = True
    gyroscopic: bool = True
    axial_force: float = 0.0
    torque: float = 0.0
    outer_diameter_right: float | None = None
    inner_diameter_right: float | None = None
    rayleigh_alpha: float = 0.0
    rayleigh_beta: float = 0.0

    def _diameters(self, xi) -> tuple[np.ndarray, np.ndarray]:
        """Outer and inner diameter (m) at ξ = z/L: linear between the ends."""
        do_r = self.outer_diameter if self.outer_diameter_right is None else (
            self.outer_diameter_right)
        di_r = self.inner_diameter if self.inner_diameter_right is None else (
            self.inner_diameter_right)
        xi = np.asarray(xi, float)
        return (self.outer_diameter + (do_r - self.outer_diameter) * xi,
                self.inner_diameter + (di_r - self.inner_diameter) * xi)

    @property
    def tapered(self) -> bool:
        """Whether the element is conical (its ends' diameters differ)."""
        do, di = self._diameters(1.0)
        return bool(do != self.outer_diameter or di != self.inner_diameter)

    def _area_at(self, xi) -> np.ndarray:
        do, di = self._diameters(xi)
        return np.pi / 4 * (do**2 - di**2)

    def _inertia_at(self, xi) -> np.ndarray:
        do, di = self._diameters(xi)
        return np.pi / 64 * (do**4 - di**4)

    @property
    def area(self) -> float:
        """Cross-section area A (m²); of a conical element, at mid-length (Φ's)."""
        return float(self._area_at(0.5))

    @property
    def inertia(self) -> float:
        """Diametral second moment of area I (m⁴), at mid-length of a conical element; the
        polar one is 2I."""
        return float(self._inertia_at(0.5))

    @property
    def mass(self) -> float:
        """Element mass (kg): ρ∫A dz (a conical element's frustum)."""
        if not self.tapered:
            return self.rho * self.area * self.length
        x, w = _GAUSS
        return float(self.rho * self.length * w @ self._area_at(x))

    def _rotary(self) -> np.ndarray:
        """∫ I N_ψᵀ N_ψ dz (m⁵) in plane coordinates: the rotary inertia per unit ρ."""
        if not self.tapered:
            return self._rotary_plane() * self.inertia
        x, w = _GAUSS
        npsi = _shape(x, self.length, self.phi)[2]
        return self.length * (npsi.T * (w * self._inertia_at(x))) @ npsi

    def _conical_mass(self) -> np.ndarray:
        """ρ∫A N_wᵀ N_w dz (plane coordinates) of a conical element."""
        x, w = _GAUSS
        nw = _shape(x, self.length, self.phi)[0]
        return self.rho * self.length * (nw.T * (w * self._area_at(x))) @ nw

    def _conical_stiffness(self) -> np.ndarray:
        """E∫I N_ψ'ᵀN_ψ' dz + κG∫A γᵀγ dz (plane coordinates) of a conical element, κG
        from Φ = 12EI/(κGAL²) at mid-length."""
        x, w = _GAUSS
        L, p = self.length, self.phi
        _, dnw, npsi, dnpsi = _shape(x, L, p)
        k = self.E * L * (dnpsi.T * (w * self._inertia_at(x))) @ dnpsi
        if p > 0:
            gamma = dnw - npsi  # constant along the element
            kappa_g = 12 * self.E * self.inertia / (p * self.area * L**2)
            k += kappa_g * L * (gamma.T * (w * self._area_at(x))) @ gamma
        return k

    def _geometric(self) -> np.ndarray:
        """Geometric stiffness (8, 8) of the axial force P and the torque T (N/m, N, N·m).

        Axial force: the work of P through the slopes, ½ P ∫ (∂w/∂z)² dz per bending plane,
        with the element's own interpolation of w (the Timoshenko one, Φ > 0, or the
        Hermite cubics, Φ = 0): K_P = P ∫ N_w'ᵀ N_w' dz, which for Φ = 0 is the classical
        P/(30L)·[36, 3L, 4L², −L²] matrix (Przemieniecki, *Theory of Matrix Structural
        Analysis*, 1968) and with shear P/(30L(1+Φ)²)·[36+60Φ+30Φ², 3L, (4+5Φ+2.5Φ²)L²,
        −(1+5Φ+2.5Φ²)L²]. P > 0 is tension (it stiffens the shaft), as in ROSS.

        Torque: T carried along the bent axis couples the two planes. With displacements and
        section rotations (ψ_x = β, ψ_y = −α) interpolated linearly over the element, its
        virtual work gives K_T = T ∫ [y'ψ_x' − x'ψ_y'] (both ways, symmetric) + T ∫ [ψ_x ψ_y'
        (row ψ_x) − ψ_y ψ_x' (row ψ_y)] dz: entries ±T/L between a displacement and the
        other plane's rotation, ±T/2 between the rotations; the latter part is not
        symmetric (a circulatory term). This is ROSS 2.3's torque term, for which ROSS cites
        no source; Zorzi & Nelson, "The dynamics of rotor-bearing systems with axial torque
        — a finite element approach", J. Mech. Des. 102 (1980), derive the consistent
        (cubic) counterpart. T in N·m, positive along +z.
        """
        out = np.zeros((8, 8))
        L, P, T = self.length, self.axial_force, self.torque
        if P:
            x, wts = _GAUSS
            dn = _shape(x, L, self.phi)[1]
            out += _to_nodes(P * L * (dn.T * wts) @ dn)
        if T:
            # plane coordinates [x, ψx, x2, ψx2 | y, ψy, y2, ψy2], linear interpolation
            c = np.zeros((8, 8))
            d = np.array([-1.0, 1.0])  # ∫ N_i' N_j' dz · L  and  ∫ N_i N_j' dz · 2
            tw = np.outer(d, d) / L  # T ∫ N_i' N_j' dz per unit T
            rr = np.outer([1.0, 1.0], d) / 2  # ∫ N_i N_j' dz
            wx, px, wy, py = [0, 2], [1, 3], [4, 6], [5, 7]
            c[np.ix_(wy, px)] += tw
            c[np.ix_(px, wy)] += tw
            c[np.ix_(wx, py)] -= tw
            c[np.ix_(py, wx)] -= tw
            c[np.ix_(px, py)] += rr
            c[np.ix_(py, px)] -= rr
            out += _to_nodes(T * c, coupled=True)
        return out

    @property
    def phi(self) -> float:
        """Shear parameter Φ = 12EI/(κGAL²) (Friswell et al. 2010, Eq. 5.60); 0 for E–B."""
        if not self.timoshenko:
            return 0.0
        nu = self.E / (2 * self.shear_modulus) - 1
        do, di = self._diameters(0.5)
        kappa = shear_coefficient(nu, float(di), float(do))
        return 12 * self.E * self.inertia / (kappa * self.shear_modulus * self.area * self.length**2)

    def _rotary_plane(self) -> np.ndarray:
        """Rotary-inertia matrix in plane coordinates per unit ρI (Friswell Eq. 5.63)."""
        L, p = self.length, self.phi
        m7 = 6 / 5
        m8 = 1 / 10 - p / 2
        m9 = 2 / 15 + p / 6 + p**2 / 3
        m10 = 1 / 30 + p / 6 - p**2 / 6
        return np.array(
            [
                [m7, m8 * L, -m7, m8 * L],
                [m8 * L, m9 * L**2, -m8 * L, -m10 * L**2],
                [-m7, -m8 * L, m7, -m8 * L],
                [m8 * L, -m10 * L**2, -m8 * L, m9 * L**2],
            ]
        ) / (L * (1 + p) ** 2)

    def M(self) -> np.ndarray:
        """Mass matrix (8, 8) in kg, kg·m, kg·m²: translational plus rotary inertia (the
        latter without ``rotary_inertia``)."""
        L, p = self.length, self.phi
        if self.tapered:
            mt = self._conical_mass()
            return _to_nodes(mt + self.rho * self._rotary() if self.rotary_inertia else mt)
        m1 = 13 / 35 + 7 * p / 10 + p**2 / 3
        m2 = 11 / 210 + 11 * p / 120 + p**2 / 24
        m3 = 9 / 70 + 3 * p / 10 + p**2 / 6
        m4 = 13 / 420 + 3 * p / 40 + p**2 / 24
        m5 = 1 / 105 + p / 60 + p**2 / 120
        m6 = 1 / 140 + p / 60 + p**2 / 120
        mt = np.array(
            [
                [m1, m2 * L, m3, -m4 * L],
                [m2 * L, m5 * L**2, m4 * L, -m6 * L**2],
                [m3, m4 * L, m1, -m2 * L],
                [-m4 * L, -m6 * L**2, -m2 * L, m5 * L**2],
            ]
        ) * (self.rho * self.area * L / (1 + p) ** 2)
        if not self.rotary_inertia:
            return _to_nodes(mt)
        mr = self._rotary_plane() * (self.rho * self.inertia)
        return _to_nodes(mt + mr)

    def K(self) -> np.ndarray:
        """Stiffness matrix (8, 8) in N/m, N, N·m (Friswell Eq. 5.61; a conical element's
        by Genta & Gugliotta 1988), with the geometric stiffness of the axial force and the
        torque."""
        if self.tapered:
            return _to_nodes(self._conical_stiffness()) + self._geometric()
        L, p = self.length, self.phi
        k = np.array(
            [
                [12, 6 * L, -12, 6 * L],
                [6 * L, (4 + p) * L**2, -6 * L, (2 - p) * L**2],
                [-12, -6 * L, 12, -6 * L],
                [6 * L, (2 - p) * L**2, -6 * L, (4 + p) * L**2],
            ]
        ) * (self.E * self.inertia / (L**3 * (1 + p)))
        return _to_nodes(k) + self._geometric()

    def G(self) -> np.ndarray:
        """Gyroscopic matrix (8, 8), skew-symmetric, per unit spin speed (kg·m², ...).

        The polar inertia per length is 2ρI, so in plane coordinates G = [[0, 2M_R],
        [−2M_R, 0]] with M_R the rotary-inertia matrix (Friswell Eq. 5.64); the sign follows
        from H = I_p Ω (β, −α, 1) for a spinning section: I_d α̈ + I_p Ω β̇ = M_x.
        Zero without ``gyroscopic``.
        """
        if not self.gyroscopic:
            return np.zeros((8, 8))
        mr = self._rotary() * (2 * self.rho)
        g = np.zeros((8, 8))
        g[:4, 4:] = mr
        g[4:, :4] = -mr
        return _to_nodes(g, coupled=True)

    def C(self) -> np.ndarray:
        """Damping matrix (8, 8) in N·s/m, N·s, N·m·s: α·M + β·K (Rayleigh damping; K with
        its geometric stiffness, as ROSS's ``ShaftElement.C``); zero without it."""
        if not (self.rayleigh_alpha or self.rayleigh_beta):
            return np.zeros((8, 8))
        return self.rayleigh_alpha * self.M() + self.rayleigh_beta * self.K()


@dataclass(frozen=True)
class LayeredBeam:
    """Concentric tubes between the same two nodes, in parallel: their matrices add.

    Each tube is a :class:`BeamElement` of its own material and its own shear parameter Φ,
    as ROSS assembles shaft elements that share a node pair (its layered elements).

    Parameters
    ----------
    tubes : tuple of BeamElement
        The tubes, all of one length.
    """

    tubes: tuple[BeamElement, ...]

    @property
    def length(self) -> float:
        """Element length L (m)."""
        return self.tubes[0].length

    @property
    def mass(self) -> float:
        """Element mass (kg), all tubes."""
        return sum(t.mass for t in self.tubes)

    def M(self) -> np.ndarray:
        """Mass matrix (8, 8): the sum of the tubes'."""
        return sum(t.M() for t in self.tubes)

    def K(self) -> np.ndarray:
        """Stiffness matrix (8, 8): the sum of the tubes'."""
        return sum(t.K() for t in self.tubes)

    def G(self) -> np.ndarray:
        """Gyroscopic matrix (8, 8) per unit spin speed: the sum of the tubes'."""
        return sum(t.G() for t in self.tubes)

    def C(self) -> np.ndarray:
        """Damping matrix (8, 8): the sum of the tubes' Rayleigh damping."""
        return sum(t.C() for t in self.tubes)


@dataclass(frozen=True)
class CouplingElement:
    """A flexible coupling between two nodes (ROSS's ``CouplingElement``): each half a rigid
    body on its node (mass, diametral and polar inertia, as :class:`DiskElement`), the two
    nodes joined by springs and dampers, translational in x, y and rotational about x (α)
    and y (β): K = [[k, −k], [−k, k]] with k = diag(kt_x, kt_y, kr_x, kr_y), C alike.

    Parameters
    ----------
    length : float
        Distance between its nodes (m); no stiffness depends on it.
    m_left, m_right, Ip_left, Ip_right, Id_left, Id_right : float
        Each half's mass (kg) and polar and diametral inertia (kg·m²).
    kt_x, kt_y, kr_x, kr_y : float
        Translational (N/m) and rotational (N·m/rad) stiffness between the nodes.
    ct_x, ct_y, cr_x, cr_y : float
        The same dampers (N·s/m, N·m·s/rad).
    """

    length: float
    m_left: float = 0.0
    m_right: float = 0.0
    Ip_left: float = 0.0
    Ip_right: float = 0.0
    Id_left: float = 0.0
    Id_right: float = 0.0
    kt_x: float = 0.0
    kt_y: float = 0.0
    kr_x: float = 0.0
    kr_y: float = 0.0
    ct_x: float = 0.0
    ct_y: float = 0.0
    cr_x: float = 0.0
    cr_y: float = 0.0

    @property
    def mass(self) -> float:
        """Both halves' mass (kg)."""
        return self.m_left + self.m_right

    def _halves(self, f) -> np.ndarray:
        out = np.zeros((8, 8))
        out[:4, :4] = f(DiskElement(self.m_left, self.Ip_left, self.Id_left))
        out[4:, 4:] = f(DiskElement(self.m_right, self.Ip_right, self.Id_right))
        return out

    @staticmethod
    def _link(k) -> np.ndarray:
        d = np.diag(k)
        return np.block([[d, -d], [-d, d]])

    def M(self) -> np.ndarray:
        """Mass matrix (8, 8): the halves' on their nodes."""
        return self._halves(DiskElement.M)

    def G(self) -> np.ndarray:
        """Gyroscopic matrix (8, 8) per unit spin speed: the halves' polar inertia."""
        return self._halves(DiskElement.G)

    def K(self) -> np.ndarray:
        """Stiffness matrix (8, 8) between the nodes' x, y, α, β."""
        return self._link([self.kt_x, self.kt_y, self.kr_x, self.kr_y])

    def C(self) -> np.ndarray:
        """Damping matrix (8, 8) between the nodes' x, y, α, β."""
        return self._link([self.ct_x, self.ct_y, self.cr_x, self.cr_y])


@dataclass(frozen=True)
class DiskElement:
    """A rigid disk on one node: mass m (kg), polar Ip and diametral Id inertia (kg·m²).

    M = diag(m, m, Id, Id) and G with Ip coupling α and β so that
    Id α̈ + Ω Ip β̇ = M_x and Id β̈ − Ω Ip α̇ = M_y (Friswell et al. 2010, Eq. 3.70).

    Attributes
    ----------
    mass : float
        Mass m (kg).
    Ip : float
        Polar moment of inertia (kg·m²), the gyroscopic coupling.
    Id : float
        Diametral (transverse) moment of inertia (kg·m²).
    """

    mass: float
    Ip: float
    Id: float

    def M(self) -> np.ndarray:
        """Mass matrix (4, 4)."""
        return np.diag([self.mass, self.mass, self.Id, self.Id])

    def G(self) -> np.ndarray:
        """Gyroscopic matrix (4, 4) per unit spin speed."""
        g = np.zeros((4, 4))
        g[_A, _B] = self.Ip
        g[_B, _A] = -self.Ip
        return g
