"""Unbalance force by balance grade (ISO 21940-11) and worst-case unbalance response.

ISO 21940-11 defines the balance quality grade ``G = e_per · Ω_max`` (mm/s): the permissible
specific unbalance (mass eccentricity) ``e_per`` times the **maximum service speed**
``Ω_max``. A rotor of mass ``m`` balanced to grade ``G`` carries the residual unbalance
``U = m · G / Ω_max`` (kg·m) at every speed, so its force at the speed ``Ω`` is

* ``law = "iso21940"`` (the default): ``F_u = U · Ω² = m · G · Ω² / Ω_max`` — the standard's
  law. Thesis P5 §4.4.1: "balanced according to the G2.5 norm at 500 Hz results in a
  maximum unbalance force of 541 N at 500 Hz" (69 kg: 541.9 N at 500 Hz, 2.5× less at
  200 Hz, 12.5× less at 40 Hz);
* ``law = "constant_velocity"``: ``F_u = m · G · Ω``, as if the rotor were re-balanced to
  grade G at each speed (the same force at ``Ω_max``, larger below it). A conservative
  option, kept for comparison with designs that used it.

**Where the force acts: at the bearings.** P5 §4.4.1 defines the compliance as "the relation
between rotor lateral displacements at bearing locations A and B and external perturbation
forces" and bounds it by σ̄ of the plant ``G_f``, whose inputs are the force inputs at the
AMB nodes (P5 Fig. 3: "the red dots mark the input/output locations", Appendix A's 4-input
B); Fig. 12 is that compliance times the force. ISO 21940-11 (§7) likewise allocates the
permissible residual unbalance to the bearing planes. The worst-case synchronous response
is therefore ``σ̄(S_o G_f(jΩ)) · F_u(Ω)`` with ``G_f`` from forces at the bearings to the
sensors, a bound over every distribution of a force of amplitude ``F_u`` (Euclidean norm)
over the bearing planes. It also reproduces the thesis's finding that the H∞ and μ
controllers, not the PID, keep the orbit below 8 µm (P5 §4.4.1; on the embedded rig over
0–4.08 bar: H∞ 5.1, μ 4.6, the PID 10 µm; a force at the seal would put every controller,
the PID too, below 5 µm). ``[design.unbalance] force_at`` puts it at a named component
instead. Gyroscopic effects (speed dependence of the plant) are neglected, as in the
thesis.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from ambseal.analysis.loops import ComplianceResponse, Peak, compliance, peak_of
from ambseal.errors import ModelError
from ambseal.lti import as_omega, json_float, json_list

__all__ = ["unbalance_force", "UnbalanceResponse", "unbalance_response", "unbalance_from_compliance",
           "UNBALANCE_LAWS"]

#: The force laws of :func:`unbalance_force` (module docstring).
UNBALANCE_LAWS = ("iso21940", "constant_velocity")


def unbalance_force(
    mass_kg: float, grade_mm_s: float, omega: Any, *, max_speed_rad_s: float | None = None,
    law: str = "iso21940",
) -> np.ndarray:
    """Force (N) of the permissible residual unbalance for an ISO 21940-11 balance grade.

    Parameters
    ----------
    mass_kg : float
        Rotor mass (kg), ``> 0``.
    grade_mm_s : float
        Balance quality grade G in mm/s (e.g. 2.5 for G2.5), ``> 0``.
    omega : float or array_like
        Rotational speed(s) Ω (rad/s), ``>= 0``.
    max_speed_rad_s : float
        Maximum service speed Ω_max (rad/s) at which the grade holds; needed by the
        ``"iso21940"`` law, unused by ``"constant_velocity"``.
    law : {"iso21940", "constant_velocity"}
        ``F = m (G/Ω_max) Ω²`` (ISO 21940-11, the default) or ``F = m G Ω`` (module
        docstring).

    Returns
    -------
    numpy.ndarray
        Force amplitude (N), same shape as ``omega`` (0-d for a scalar).

    Raises
    ------
    ModelError
        For non-positive mass, grade or maximum speed, negative speeds, an unknown law, or
        the ``"iso21940"`` law without ``max_speed_rad_s``.

    Examples
    --------
    >>> w500 = 2 * np.pi * 500.0  # G2.5 at 500 Hz on the 69 kg rotor, P5 §4.4.1
    >>> round(float(unbalance_force(69.0, 2.5, w500, max_speed_rad_s=w500)), 1)
    541.9
    >>> round(float(unbalance_force(69.0, 2.5, 2 * np.pi * 200.0, max_speed_rad_s=w500)), 1)
    86.7
    """
    if not mass_kg > 0 or not np.isfinite(mass_kg):
        raise ModelError(f"unbalance_force: mass_kg must be > 0, got {mass_kg!r}")
    if not grade_mm_s > 0 or not np.isfinite(grade_mm_s):
        raise ModelError(f"unbalance_force: grade_mm_s must be > 0 (e.g. 2.5 for G2.5), got {grade_mm_s!r}")
    w = np.asarray(omega, dtype=float)
    if np.any(~np.isfinite(w)) or np.any(w < 0):
        raise ModelError("unbalance_force: omega (rad/s) must be finite and >= 0")
    g_m_s = grade_mm_s * 1e-3
    if law == "constant_velocity":
        return mass_kg * g_m_s * w
    if law != "iso21940":
        raise ModelError(f"unbalance_force: law {law!r} unknown (expected one of {UNBALANCE_LAWS})")
    if max_speed_rad_s is None or not (np.isfinite(max_speed_rad_s) and max_speed_rad_s > 0):
        raise ModelError("unbalance_force: the iso21940 law needs max_speed_rad_s > 0 (the maximum "
                         f"service speed), got {max_speed_rad_s!r}")
    return mass_kg * (g_m_s / max_speed_rad_s) * w**2


@dataclass(frozen=True, eq=False)
class UnbalanceResponse:
    """Worst-case unbalance response ``σ̄(S_o G_f) · F_u`` over speed (P5 Fig. 12).

    Attributes
    ----------
    omega_rad_s : ndarray, shape (n_w,)
        Rotational speeds = excitation frequencies (rad/s).
    force_n : ndarray, shape (n_w,)
        Unbalance force amplitude (N).
    response_m : ndarray, shape (n_w,)
        Upper bound of the displacement amplitude (m).
    peak_um : float
        Peak of ``response_m`` in µm.
    peak_speed_hz : float
        Speed of that peak (Hz = rev/s).
    mass_kg, grade_mm_s : float
        Inputs, for the record.
    law : str
        The force law (:data:`UNBALANCE_LAWS`).
    max_speed_rad_s : float or None
        Ω_max of the ``"iso21940"`` law (rad/s).
    """

    omega_rad_s: np.ndarray
    force_n: np.ndarray
    response_m: np.ndarray
    peak_um: float
    peak_speed_hz: float
    mass_kg: float
    grade_mm_s: float
    law: str = "iso21940"
    max_speed_rad_s: float | None = None

    @property
    def speed_hz(self) -> np.ndarray:
        """Speeds (Hz), shape (n_w,)."""
        return self.omega_rad_s / (2 * np.pi)

    @property
    def response_um(self) -> np.ndarray:
        """Response bound (µm), shape (n_w,)."""
        return self.response_m * 1e6

    def to_dict(self) -> dict:
        return {
            "speed_hz": json_list(self.speed_hz),
            "force_n": json_list(self.force_n),
            "response_um": json_list(self.response_um),
            "peak_um": json_float(self.peak_um),
            "peak_speed_hz": json_float(self.peak_speed_hz),
            "mass_kg": json_float(self.mass_kg),
            "grade_mm_s": json_float(self.grade_mm_s),
            "law": self.law,
            "max_speed_hz": (json_float(self.max_speed_rad_s / (2 * np.pi))
                             if self.max_speed_rad_s is not None else None),
        }


def unbalance_from_compliance(
    comp: ComplianceResponse, *, mass_kg: float, grade_mm_s: float, max_speed_rad_s: float | None = None,
    law: str = "iso21940",
) -> UnbalanceResponse:
    """Worst-case unbalance response from an already computed compliance.

    Parameters
    ----------
    comp : ComplianceResponse
        From :func:`ambseal.analysis.loops.compliance`; its grid is the speed grid.
    mass_kg, grade_mm_s, max_speed_rad_s, law
        As in :func:`unbalance_force`.

    Returns
    -------
    UnbalanceResponse

    Raises
    ------
    ModelError
        As :func:`unbalance_force`.
    """
    w = comp.omega_rad_s
    F = unbalance_force(mass_kg, grade_mm_s, w, max_speed_rad_s=max_speed_rad_s, law=law)
    resp = comp.sigma_max_m_per_n * F
    pk: Peak = peak_of(resp, w)
    wmax = float(max_speed_rad_s) if law == "iso21940" else None
    return UnbalanceResponse(w, F, resp, pk.value * 1e6, pk.frequency_hz, float(mass_kg),
                             float(grade_mm_s), law, wmax)


def unbalance_response(
    G: Any,
    K: Any,
    Gf: Any,
    omega: Any,
    *,
    mass_kg: float,
    grade_mm_s: float,
    max_speed_rad_s: float | None = None,
    law: str = "iso21940",
) -> UnbalanceResponse:
    """Worst-case unbalance response ``σ̄(S_o G_f (jΩ)) · F_u(Ω)`` over a speed grid.

    Parameters
    ----------
    G, K, Gf : control.StateSpace
        Plant (A → m), controller (m → A), force plant (N → m) with ``G``'s outputs (the
        forces at the bearings, module docstring).
    omega : array_like, shape (n_w,)
        Speeds Ω (rad/s); the unbalance excites at Ω (synchronous).
    mass_kg : float
        Rotor mass (kg), ``> 0``, as in :func:`unbalance_force`.
    grade_mm_s : float
        Balance quality grade G (mm/s), ``> 0``.
    max_speed_rad_s : float, optional
        Maximum service speed Ω_max (rad/s); needed by the ``"iso21940"`` law.
    law : {"iso21940", "constant_velocity"}
        The force law of :func:`unbalance_force` (ISO 21940-11 by default).

    Returns
    -------
    UnbalanceResponse
        The force (N) and the response bound (m) per speed, and its peak (µm) and where.

    Raises
    ------
    ModelError
        As :func:`unbalance_force` and :func:`~ambseal.analysis.loops.compliance`.
    """
    return unbalance_from_compliance(
        compliance(G, K, Gf, as_omega(omega)), mass_kg=mass_kg, grade_mm_s=grade_mm_s,
        max_speed_rad_s=max_speed_rad_s, law=law,
    )
