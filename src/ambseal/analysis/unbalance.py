"""Unbalance force by balance grade (ISO 21940-11) and worst-case unbalance response.

ISO 21940-11 defines the balance quality grade ``G = e_per · Ω`` (mm/s), the product of the
permissible specific unbalance (mass eccentricity) and the angular speed. The force of the
permissible residual unbalance of a rotor of mass ``m`` is then ``F_u = m · e · Ω² = m · G · Ω``
when the rotor is balanced to grade ``G`` at the speed ``Ω`` itself — the thesis's assumption:
G2.5 on the 69 kg rotor at 500 Hz gives 541.9 N (P5 §4.4.1, Table 1).

If the rotor is balanced once for a maximum service speed ``Ω_max`` (``e = G / Ω_max``),
``F_u(Ω) = m · G · Ω² / Ω_max`` instead (pass ``max_speed_rad_s``); this is smaller below
``Ω_max``.

The worst-case synchronous response is bounded by ``σ̄(S_o G_f (jΩ)) · F_u(Ω)`` (P5 §4.4.1,
Fig. 12): the compliance upper bound times the force amplitude. Gyroscopic effects (speed
dependence of the plant) are neglected, as in the thesis.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from ambseal.analysis._util import json_float, json_list
from ambseal.lti.matrices import as_omega
from ambseal.analysis.loops import ComplianceResponse, Peak, compliance, peak_of
from ambseal.errors import ModelError

__all__ = ["unbalance_force", "UnbalanceResponse", "unbalance_response", "unbalance_from_compliance"]


def unbalance_force(
    mass_kg: float, grade_mm_s: float, omega: Any, *, max_speed_rad_s: float | None = None
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
    max_speed_rad_s : float, optional
        If given, the rotor is balanced for this speed: ``F = m (G/Ω_max) Ω²``. By default
        ``F = m G Ω`` (balanced to grade G at every speed, P5 §4.4.1).

    Returns
    -------
    numpy.ndarray
        Force amplitude (N), same shape as ``omega`` (0-d for a scalar).

    Raises
    ------
    ModelError
        For non-positive mass, grade or maximum speed, or negative speeds.

    Examples
    --------
    >>> round(float(unbalance_force(69.0, 2.5, 2 * np.pi * 500.0)), 1)  # P5 §4.4.1
    541.9
    """
    if not mass_kg > 0 or not np.isfinite(mass_kg):
        raise ModelError(f"unbalance_force: mass_kg must be > 0, got {mass_kg!r}")
    if not grade_mm_s > 0 or not np.isfinite(grade_mm_s):
        raise ModelError(f"unbalance_force: grade_mm_s must be > 0 (e.g. 2.5 for G2.5), got {grade_mm_s!r}")
    w = np.asarray(omega, dtype=float)
    if np.any(~np.isfinite(w)) or np.any(w < 0):
        raise ModelError("unbalance_force: omega (rad/s) must be finite and >= 0")
    g_m_s = grade_mm_s * 1e-3
    if max_speed_rad_s is None:
        return mass_kg * g_m_s * w
    if not max_speed_rad_s > 0:
        raise ModelError(f"unbalance_force: max_speed_rad_s must be > 0, got {max_speed_rad_s!r}")
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
    """

    omega_rad_s: np.ndarray
    force_n: np.ndarray
    response_m: np.ndarray
    peak_um: float
    peak_speed_hz: float
    mass_kg: float
    grade_mm_s: float

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
        }


def unbalance_from_compliance(
    comp: ComplianceResponse, *, mass_kg: float, grade_mm_s: float, max_speed_rad_s: float | None = None
) -> UnbalanceResponse:
    """Worst-case unbalance response from an already computed compliance.

    Parameters
    ----------
    comp : ComplianceResponse
        From :func:`ambseal.analysis.loops.compliance`; its grid is the speed grid.
    mass_kg, grade_mm_s, max_speed_rad_s
        As in :func:`unbalance_force`.

    Returns
    -------
    UnbalanceResponse
    """
    w = comp.omega_rad_s
    F = unbalance_force(mass_kg, grade_mm_s, w, max_speed_rad_s=max_speed_rad_s)
    resp = comp.sigma_max_m_per_n * F
    pk: Peak = peak_of(resp, w)
    return UnbalanceResponse(w, F, resp, pk.value * 1e6, pk.frequency_hz, float(mass_kg), float(grade_mm_s))


def unbalance_response(
    G: Any,
    K: Any,
    Gf: Any,
    omega: Any,
    *,
    mass_kg: float,
    grade_mm_s: float,
    max_speed_rad_s: float | None = None,
) -> UnbalanceResponse:
    """Worst-case unbalance response ``σ̄(S_o G_f (jΩ)) · F_u(Ω)`` over a speed grid.

    Parameters
    ----------
    G, K, Gf : control.StateSpace
        Plant (A → m), controller (m → A), force plant (N → m) with ``G``'s outputs.
    omega : array_like, shape (n_w,)
        Speeds Ω (rad/s); the unbalance excites at Ω (synchronous).
    mass_kg, grade_mm_s, max_speed_rad_s
        As in :func:`unbalance_force`.

    Returns
    -------
    UnbalanceResponse
    """
    return unbalance_from_compliance(
        compliance(G, K, Gf, as_omega(omega)), mass_kg=mass_kg, grade_mm_s=grade_mm_s, max_speed_rad_s=max_speed_rad_s
    )
