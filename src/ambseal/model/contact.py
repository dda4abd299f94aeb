"""The contact of a landing rotor with a touchdown bearing: the normal force of the journal
on the ring, its damping, and the friction between them.

The normal force on a penetration δ > 0 (m) at the rate δ̇ (m/s) is Hertz's power law with
a damping that vanishes with δ (Hunt & Crossley 1975):

    F = K·δ^n·(1 + D·δ̇),        F = 0 where δ ≤ 0 or where the bracket turns negative,

n = 3/2 for a point contact (Hertz; K = (4/3)·E*·√R*, Johnson, *Contact Mechanics*,
1985, §4.2) and n = 10/9 for a line contact (Palmgren's relation for bearing steel,
δ = 3.84·10⁻⁵·Q^0.9/l^0.8 in mm and N; Harris & Kotzalas, *Rolling Bearing Analysis*,
5th ed., 2007). D (s/m) is the damping factor ζ over the impact's normal speed v₀,
D = ζ/v₀, so that every impact of the law rebounds at the same fraction of its speed.

**The measured restitution.** A mass m striking the law at v₀ obeys m·v·dv/dδ =
−K·δ^n·(1 + D·v), whose variables separate; integrated in and out again
(v₀ → 0 → −e·v₀ while δ goes 0 → δ_max → 0) the two halves store the same
K·δ_max^{n+1}/(n+1), so the coefficient of restitution e of one impact and ζ = D·v₀ are
tied, whatever K, m, v₀ and n, by

    ζ·(1 + e) = ln((1 + ζ)/(1 − e·ζ)),    e = (1 + W₀(−(1 + ζ)·e^{−(1+ζ)}))/ζ,

W₀ Lambert's function (Carvalho & Martins, "Exact restitution and generalizations for
the Hunt–Crossley contact model", *Mech. Mach. Theory* 139, 2019): a measured e gives ζ
(:func:`damping_factor`), and ζ gives the impact's e (:func:`impact_restitution`). Its
rebound stays below 1/D, so the bracket never turns negative in one impact.

**The published laws** approximate that relation by ζ = f(e), their "e" (here
``law_restitution``) then the impact's restitution only near 1 (:data:`DAMPING_LAWS`):

* Hunt & Crossley (1975): ζ = 3(1 − e)/2, derived for e near 1;
* Lankarani & Nikravesh (1990): ζ = 3(1 − e²)/4, the same limit;
* Flores, Machado, Silva & Martins (2011): ζ = 8(1 − e)/(5e).

Integrated through one impact, the three give different restitutions for the same e
away from 1 (at e = 0.5 about 0.66, 0.73 and 0.47; at 0.6, 0.71, 0.76 and 0.58), and
agree near it; :func:`law_restitution` is the e a law needs for a measured one. The
tangential force is Coulomb's, regularised so that a slip speed v below ``v_r`` is not
a discontinuity: F_t = μ·N·tanh(v/v_r).

Without damping an impact of a mass m at v₀ ends where the kinetic energy is stored,
(½)m v₀² = K δ_max^{n+1}/(n+1), and lasts t_c = 2(δ_max/v₀)·∫₀¹(1 − u^{n+1})^{-½}du
(for n = 3/2, t_c = 2.943 δ_max/v₀; Goldsmith, *Impact*, 1960): :func:`hertz_impact`.

The stress inside a rolling touchdown bearing is read from its basic static load rating
C₀ (:func:`rated_contact_stress`): ISO 76:2006 §3.1 defines C₀ as the radial load that
gives 4 200 MPa at the centre of the most heavily loaded ball–raceway contact (4 000 MPa
for rollers); that element's share of the bearing's load is fixed by the bearing's
geometry, and Hertz's contact stress grows with the element's load as Q^{1/3} (point) or
Q^{1/2} (line; Johnson 1985, Eqs. 4.23, 4.45), so a load F gives σ_C₀·(F/C₀)^{1/3}
in a ball bearing and σ_C₀·(F/C₀)^{1/2} in a roller bearing.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy.optimize import brentq
from scipy.special import lambertw

__all__ = ["N_POINT", "N_LINE", "PALMGREN_MM", "DAMPING_LAWS", "effective_modulus",
           "point_stiffness", "line_stiffness", "damping_coefficient", "normal_force",
           "friction_force", "hertz_impact", "damping_factor", "impact_restitution",
           "law_restitution", "rated_contact_stress", "ISO76_STRESS_PA",
           "ContactLaw"]

#: Hertz's exponent of a point contact and Palmgren's of a line contact
N_POINT, N_LINE = 1.5, 10.0 / 9.0
#: Palmgren's line contact of bearing steel: δ = PALMGREN_MM·Q^0.9/l^0.8 (mm, N, mm)
PALMGREN_MM = 3.84e-5
#: ISO 76:2006 §3.1: the contact stress (Pa) at C₀ in a ball and in a roller bearing
#: (4 600 MPa for self-aligning ball bearings, not a touchdown bearing's kind)
ISO76_STRESS_PA = {"ball": 4.2e9, "roller": 4.0e9}
#: the published damping laws, by their rig-file names: ζ = D·v₀ as a function of their e
DAMPING_LAWS = {
    "hunt_crossley": lambda e: 1.5 * (1.0 - e),
    "lankarani_nikravesh": lambda e: 0.75 * (1.0 - e * e),
    "flores": lambda e: 1.6 * (1.0 - e) / e,
}


def effective_modulus(E: float, nu: float) -> float:
    """E* of two bodies of one material: 1/E* = 2(1 − ν²)/E (Johnson 1985, Eq. 4.22).

    Parameters
    ----------
    E : float
        Young's modulus (Pa), > 0.
    nu : float
        Poisson's ratio, in [0, 0.5).

    Returns
    -------
    float
        E* (Pa).
    """
    return E / (2.0 * (1.0 - nu * nu))


def point_stiffness(E: float, nu: float, radius: float) -> float:
    """Hertz's point contact, F = K·δ^{3/2}: K = (4/3)·E*·√R* (Johnson 1985, Eq. 4.23).

    Parameters
    ----------
    E, nu : float
        Both bodies' Young's modulus (Pa) and Poisson's ratio.
    radius : float
        The effective radius R* (m), 1/R* the sum of the principal curvatures (a
        conformal one negative), > 0.

    Returns
    -------
    float
        K (N/m^1.5).
    """
    return 4.0 / 3.0 * effective_modulus(E, nu) * math.sqrt(radius)


def line_stiffness(length: float) -> float:
    """Palmgren's line contact of bearing steel, F = K·δ^{10/9}, from
    δ = 3.84·10⁻⁵·Q^0.9/l^0.8 (δ and l in mm, Q in N; Harris & Kotzalas 2007).

    Parameters
    ----------
    length : float
        The contact's length l (m), > 0.

    Returns
    -------
    float
        K (N/m^{10/9}).
    """
    # Q = (δ_mm · l_mm^0.8 / 3.84e-5)^(1/0.9), δ_mm = 1e3·δ
    return (1e3 * (1e3 * length) ** 0.8 / PALMGREN_MM) ** (1.0 / 0.9)


def damping_coefficient(law: str, restitution: float, impact_speed: float) -> float:
    """D of F = K·δ^n·(1 + D·δ̇) by a published ``law`` at its own e, for an impact at
    ``impact_speed`` (module docstring): the impact's restitution is that e only near 1
    (:func:`damping_factor` gives the D of a measured one).

    Parameters
    ----------
    law : {"hunt_crossley", "lankarani_nikravesh", "flores"}
    restitution : float
        The law's e (``law_restitution``), in (0, 1].
    impact_speed : float
        The normal speed v₀ at the start of the impact (m/s), > 0.

    Returns
    -------
    float
        D (s/m).

    Raises
    ------
    ValueError
        An unknown law, e outside (0, 1], or v₀ ≤ 0.
    """
    if law not in DAMPING_LAWS:
        raise ValueError(f"damping_law: expected one of {', '.join(DAMPING_LAWS)}, got "
                         f"{law!r}")
    if not 0.0 < restitution <= 1.0:
        raise ValueError(f"restitution: expected 0 < e <= 1, got {restitution!r}")
    if not impact_speed > 0.0:
        raise ValueError(f"impact speed: expected > 0 m/s, got {impact_speed!r}")
    return DAMPING_LAWS[law](restitution) / impact_speed


def impact_restitution(factor: float) -> float:
    """The coefficient of restitution of one impact on F = K·δ^n·(1 + D·δ̇) at
    D·v₀ = ``factor`` (module docstring; Carvalho & Martins 2019), for any K, m, v₀, n.

    Parameters
    ----------
    factor : float
        ζ = D·v₀, ≥ 0.

    Returns
    -------
    float
        e, in (0, 1]; 1 at ζ = 0.
    """
    if factor <= 0.0:
        return 1.0
    if factor < 1e-6:  # W₀ near its branch point loses the digits; HC's limit holds
        return 1.0 - 2.0 * factor / 3.0
    x = 1.0 + factor
    return float((1.0 + lambertw(-x * math.exp(-x), 0).real) / factor)


def _excess(factor: float, e: float) -> float:
    """[ζ(1 + e) − ln((1 + ζ)/(1 − eζ))]/ζ², positive below the root, −∞ at ζ = 1/e;
    its series Σ_{k≥2} −((−1)^{k+1} + e^k)·ζ^{k−2}/k where the closed form cancels."""
    if factor < 0.25:
        k = np.arange(2, 60)
        return float(-np.sum(((-1.0) ** (k + 1) + e ** k) * factor ** (k - 2) / k))
    return (factor * (1.0 + e) - math.log1p(factor) + math.log1p(-e * factor)) / factor ** 2


def damping_factor(restitution: float) -> float:
    """ζ = D·v₀ of F = K·δ^n·(1 + D·δ̇) whose impacts rebound at ``restitution`` times
    their speed: the root of ζ(1 + e) = ln((1 + ζ)/(1 − eζ)) in (0, 1/e) (module
    docstring), the same for every K, mass, speed and exponent.

    Parameters
    ----------
    restitution : float
        The measured coefficient of restitution e, in (0, 1].

    Returns
    -------
    float
        ζ ≥ 0 (0 at e = 1; about 1/e as e → 0).

    Raises
    ------
    ValueError
        e outside (0, 1].
    """
    e = restitution
    if not 0.0 < e <= 1.0:
        raise ValueError(f"restitution: expected 0 < e <= 1, got {restitution!r}")
    if e == 1.0:
        return 0.0
    top = (1.0 - 1e-15) / e
    return float(brentq(_excess, 1e-300, top, args=(e,), xtol=1e-15, rtol=1e-13))


def law_restitution(law: str, restitution: float) -> float | None:
    """The e a published ``law`` must be given for its impacts to rebound at the measured
    ``restitution``: its ζ = f(e) solved for :func:`damping_factor` (closed forms).

    Parameters
    ----------
    law : {"hunt_crossley", "lankarani_nikravesh", "flores"}
    restitution : float
        The measured e, in (0, 1].

    Returns
    -------
    float or None
        The law's e, in (0, 1]; None where no e of the law reaches that damping
        (Hunt–Crossley's ζ ≤ 3/2, Lankarani–Nikravesh's ζ ≤ 3/4).
    """
    z = damping_factor(restitution)
    e = {"hunt_crossley": lambda: 1.0 - z / 1.5,
         "lankarani_nikravesh": lambda: math.sqrt(max(1.0 - z / 0.75, 0.0)),
         "flores": lambda: 1.6 / (z + 1.6)}[law]()
    return e if 0.0 < e <= 1.0 else None


def normal_force(delta, delta_rate, stiffness: float, exponent: float, damping: float):
    """F = K·δ^n·(1 + D·δ̇) where δ > 0 and the bracket is positive, else 0 (N).

    Parameters
    ----------
    delta, delta_rate : float or ndarray
        Penetration (m) and its rate (m/s).
    stiffness, exponent, damping : float
        K (N/m^n), n and D (s/m).

    Returns
    -------
    float or ndarray
    """
    if isinstance(delta, float) and isinstance(delta_rate, float):  # one contact (the drop's rhs)
        if not delta > 0.0:
            return 0.0
        return max(stiffness * delta ** exponent * (1.0 + damping * delta_rate), 0.0)
    d = np.maximum(np.asarray(delta, float), 0.0)
    f = stiffness * d ** exponent * (1.0 + damping * np.asarray(delta_rate, float))
    return np.where(np.asarray(delta) > 0.0, np.maximum(f, 0.0), 0.0)


def friction_force(mu: float, normal, slip_speed, velocity: float):
    """The regularised Coulomb force μ·N·tanh(v/v_r) (N), along the slip.

    Parameters
    ----------
    mu : float
        Friction coefficient, ≥ 0.
    normal : float or ndarray
        Normal force N (N), ≥ 0.
    slip_speed : float or ndarray
        Slip speed v of the journal's surface against the ring's (m/s).
    velocity : float
        v_r (m/s), > 0.

    Returns
    -------
    float or ndarray
    """
    if isinstance(normal, float) and isinstance(slip_speed, float):  # one contact (the drop's rhs)
        return mu * normal * math.tanh(slip_speed / velocity)
    return mu * np.asarray(normal, float) * np.tanh(np.asarray(slip_speed, float) / velocity)


def hertz_impact(mass: float, speed: float, stiffness: float,
                 exponent: float = N_POINT) -> tuple[float, float]:
    """An undamped impact of ``mass`` at ``speed`` on F = K·δ^n: the largest penetration
    and the contact time (module docstring; Goldsmith 1960).

    Parameters
    ----------
    mass : float
        kg, > 0.
    speed : float
        Normal speed at contact (m/s), > 0.
    stiffness : float
        K (N/m^n).
    exponent : float, optional
        n (3/2: Hertz).

    Returns
    -------
    (float, float)
        δ_max (m) and t_c (s).
    """
    p = exponent + 1.0
    d_max = (p * mass * speed ** 2 / (2.0 * stiffness)) ** (1.0 / p)
    # ∫₀¹ (1 − u^p)^(−1/2) du = B(1/p, 1/2)/p
    integral = math.gamma(1.0 / p) * math.sqrt(math.pi) / (p * math.gamma(1.0 / p + 0.5))
    return d_max, 2.0 * integral * d_max / speed


def rated_contact_stress(force, static_rating: float, elements: str = "ball"):
    """The largest rolling-element contact stress (Pa) in a rolling bearing carrying a
    radial ``force`` (N), from its basic static load rating (module docstring).

    Parameters
    ----------
    force : float or ndarray
        The bearing's radial load (N), ≥ 0.
    static_rating : float
        C₀ (N, ISO 76), > 0.
    elements : {"ball", "roller"}
        The rolling elements: Hertz's point contact (stress ∝ load^{1/3}) or line contact
        (∝ load^{1/2}).

    Returns
    -------
    float or ndarray
        σ (Pa): ISO76_STRESS_PA[elements] at ``force`` = C₀.

    Raises
    ------
    ValueError
        An unknown ``elements``, or C₀ not positive.
    """
    if elements not in ISO76_STRESS_PA:
        raise ValueError(f"elements: expected one of {sorted(ISO76_STRESS_PA)}, got "
                         f"{elements!r}")
    if not static_rating > 0:
        raise ValueError(f"static_rating: expected > 0 N, got {static_rating!r}")
    power = 1.0 / 3.0 if elements == "ball" else 0.5
    return ISO76_STRESS_PA[elements] * (np.asarray(force, float) / static_rating) ** power


@dataclass(frozen=True)
class ContactLaw:
    """One touchdown bearing's contact (module docstring).

    Attributes
    ----------
    stiffness : float
        K (N/m^n).
    exponent : float
        n.
    factor : float
        ζ = D·v₀ (:func:`damping_factor` of the measured e, or a published law's
        ζ of its own e).
    friction : float
        μ.
    friction_velocity : float
        v_r (m/s).
    """

    stiffness: float
    exponent: float
    factor: float
    friction: float
    friction_velocity: float

    @classmethod
    def of(cls, touchdown) -> "ContactLaw":
        """The law of a ``[[touchdown]]`` table (:class:`ambseal.config.Touchdown`): K as
        given, or from its contact radius (point) or length (line); ζ from the measured
        ``restitution``, else ``damping_law`` at its ``law_restitution``."""
        n = N_POINT if touchdown.contact == "point" else N_LINE
        k = touchdown.contact_stiffness
        if k is None:
            k = (point_stiffness(touchdown.E, touchdown.nu, touchdown.contact_radius)
                 if touchdown.contact == "point" else line_stiffness(touchdown.contact_length))
        if touchdown.restitution is not None:
            factor = damping_factor(touchdown.restitution)
        else:
            factor = DAMPING_LAWS[touchdown.damping_law](touchdown.law_restitution)
        return cls(float(k), n, factor, touchdown.friction, touchdown.friction_velocity)

    @property
    def restitution(self) -> float:
        """The coefficient of restitution of one impact on this law."""
        return impact_restitution(self.factor)

    def damping(self, impact_speed: float) -> float:
        """D = ζ/v₀ (s/m) of an impact that began at ``impact_speed`` (m/s), > 0."""
        return self.factor / impact_speed

    def force(self, delta, delta_rate, impact_speed: float):
        """The normal force (N) at penetration ``delta`` (m) and its rate (m/s), in an
        impact that began at ``impact_speed`` (m/s)."""
        return normal_force(delta, delta_rate, self.stiffness, self.exponent,
                            self.damping(impact_speed))
