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
instead.

**The plant at the running speed** (:func:`running_unbalance`, the default,
``[design.unbalance] plant = "running"``): an unbalance forces the rotor at the speed it
turns at, so at each speed Ω the plant is the one built at Ω — its gyroscopic coupling ΩG
and its seals at the synchronous frequency (:func:`ambseal.analysis.synchronous.
running_plant`) — closed by the controller as it acts at Ω (scheduled on speed where it
is). And an unbalance's force turns forward with the shaft: at bearing plane k it is
``F_x = c_k``, ``F_y = −j c_k`` (phasors of ``Re{F e^{jΩt}}``), so the bound is taken over
those forces alone, ``Σ|c_k|² = F_u²``: the largest semi-major axis of the orbit at any
sensor plane, ``max_k √λ_max(Re(M_k M_kᴴ))`` with ``M_k`` the plane's two sensors' rows of
``S_o G_f T`` (T the forward forces; the semi-major axis is ``max_d ‖dᵀ M_k c‖`` over real
unit directions d) — a backward-whirling mode, which a forward force on an axisymmetric
rotor does not excite, does not count as it would in σ̄ over every force. On a rotor
without gyroscopics, on isotropic supports, both bounds are ``|g|·F_u``. Gyroscopic
rotors — flywheels, overhung wheels — meet their 1× crossings only this way: with the
plant frozen at one speed their orbit and coil current can be off many times over.

**The thesis's simplification** (``plant = "frozen"``, :func:`unbalance_from_compliance`):
the plant frozen at the judged condition's speed with the forcing frequency swept and the
bound σ̄ over every force distribution, as P5 §4.4.1 and its Fig. 12 take it (harmless
on its near-rigid rig); kept to reproduce the thesis's figures.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from scipy.signal import find_peaks

from ambseal.analysis.loops import ComplianceResponse, Peak, compliance, peak_of
from ambseal.errors import ModelError
from ambseal.lti import as_omega, json_float, json_list

__all__ = ["unbalance_force", "UnbalanceResponse", "unbalance_response", "unbalance_from_compliance",
           "UNBALANCE_LAWS", "forward_forces", "worst_orbit", "running_unbalance"]

#: The force laws of :func:`unbalance_force` (module docstring).
UNBALANCE_LAWS = ("iso21940", "constant_velocity")
#: Speeds of the running unbalance response's first sweep, evenly over its range; each
#: local maximum is then refined :data:`REFINE_ROUNDS` times by :data:`REFINE` speeds
#: between its neighbours (every round narrows the bracket of a peak 4-fold).
SPEED_POINTS = 400
REFINE, REFINE_ROUNDS = 9, 3


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


def forward_forces(forces) -> np.ndarray:
    """The forces of a rotating unbalance at each force position (module docstring).

    Parameters
    ----------
    forces : sequence of str
        The force inputs, ``F<k>_x`` then ``F<k>_y`` per position (as
        :func:`ambseal.model.build_system` names them).

    Returns
    -------
    ndarray of complex, shape (nf, nf // 2)
        T: column k puts ``F_x = 1``, ``F_y = −j`` at position k.

    Raises
    ------
    ModelError
        Forces not in x, y pairs.
    """
    names = list(forces)
    if len(names) % 2 or any(not (a.endswith("_x") and b.endswith("_y") and a[:-2] == b[:-2])
                             for a, b in zip(names[::2], names[1::2])):
        raise ModelError(f"forward_forces: expected x, y pairs of force inputs, got {names}")
    T = np.zeros((len(names), len(names) // 2), complex)
    for k in range(len(names) // 2):
        T[2 * k, k], T[2 * k + 1, k] = 1.0, -1j
    return T


def worst_orbit(H: np.ndarray, outputs) -> np.ndarray:
    """The largest semi-major axis of the orbit at any sensor plane per unit force
    amplitude, over every distribution of the forces (module docstring).

    Parameters
    ----------
    H : ndarray of complex, shape (n_w, ny, n_c)
        Sensors (m) per unit force amplitude of each force pattern (e.g. ``S_o G_f T``).
    outputs : sequence of str
        The sensors, ``y_<amb>_<axis>``: the two axes of one AMB (orthogonal) make a plane;
        a sensor without its pair counts alone (its amplitude).

    Returns
    -------
    ndarray, shape (n_w,)
        ``max_k √λ_max(Re(M_k M_kᴴ))`` (m/N).
    """
    planes: dict = {}
    for i, name in enumerate(outputs):
        planes.setdefault(name.rsplit("_", 1)[0], []).append(i)
    out = np.zeros(H.shape[0])
    for rows in planes.values():
        M = H[:, rows, :]
        R = np.einsum("wic,wjc->wij", M, M.conj()).real
        out = np.maximum(out, np.sqrt(np.maximum(np.linalg.eigvalsh(R)[:, -1], 0.0)))
    return out


def running_unbalance(plant_at, controller_at, range_hz, *, mass_kg: float, grade_mm_s: float,
                      max_speed_rad_s: float | None = None, law: str = "iso21940"
                      ) -> tuple[UnbalanceResponse, np.ndarray, tuple]:
    """The worst-case unbalance orbit over a speed range with the plant at the running
    speed (module docstring), and the current references that hold it.

    The speeds: :data:`SPEED_POINTS` evenly over the range, then around each local maximum
    of the orbit :data:`REFINE` more between its neighbours, :data:`REFINE_ROUNDS` times.

    Parameters
    ----------
    plant_at : callable
        ``plant_at(speeds_hz)`` → :class:`ambseal.analysis.synchronous.RunningPlant`.
    controller_at : callable
        ``controller_at(omega)`` (rad/s, shape (n_w,)) → ``(K_loop, K_current)``, each of
        shape (n_w, nu, ny) in the plant's order: the controller as the loop sees it at each
        speed (continuous: with the delay's lag; as it runs: ``K_d(e^{jΩT})`` times the
        hold's fundamental), and the map from the sensors to the current reference the
        amplifier is given (as it runs: at the samples, ``K_d(e^{jΩT})``).
    range_hz : (float, float)
        The speeds (Hz), ``0 < low < high``.
    mass_kg : float
        Mass m (kg) of the force law, as in :func:`unbalance_force`.
    grade_mm_s : float
        Balance grade G (mm/s).
    max_speed_rad_s : float, optional
        Ω_max (rad/s) of the ``"iso21940"`` law.
    law : {"iso21940", "constant_velocity"}
        The force law of :func:`unbalance_force`.

    Returns
    -------
    response : UnbalanceResponse
        The orbit bound (m) over speed and its peak.
    current_a : ndarray, shape (n_w, nu)
        Per AMB axis, the largest current reference (A, amplitude) over the same forces.
    axes : tuple of str
        The current inputs of ``current_a``.

    Raises
    ------
    ModelError
        A range not ``0 < low < high``, a singular loop at a speed, or as
        :func:`unbalance_force`.
    """
    lo, hi = (float(x) for x in range_hz)
    if not 0 < lo < hi:
        raise ModelError(f"running_unbalance: expected 0 < low < high (Hz), got {range_hz}")
    axes: tuple = ()

    def evaluate(speeds):
        nonlocal axes
        rp = plant_at(speeds)
        axes = rp.inputs
        Kl, Kc = controller_at(2 * np.pi * speeds)
        GfT = rp.Gf @ forward_forces(rp.forces)
        try:
            H = np.linalg.solve(np.eye(rp.Gu.shape[1]) + rp.Gu @ Kl, GfT)
        except np.linalg.LinAlgError:
            raise ModelError("running unbalance: the loop is singular at a speed of "
                             f"{lo:g}–{hi:g} Hz") from None
        return worst_orbit(H, rp.outputs), np.linalg.norm(Kc @ H, axis=2)

    def force(speeds):
        return unbalance_force(mass_kg, grade_mm_s, 2 * np.pi * speeds,
                               max_speed_rad_s=max_speed_rad_s, law=law)

    speeds = np.linspace(lo, hi, SPEED_POINTS)
    orbit, current = evaluate(speeds)
    for _ in range(REFINE_ROUNDS):
        peaks = find_peaks(orbit * force(speeds))[0]
        if not peaks.size:
            break
        extra = np.setdiff1d(np.concatenate([np.linspace(speeds[i - 1], speeds[i + 1],
                                                         REFINE + 2)[1:-1] for i in peaks]),
                             speeds)
        if not extra.size:
            break
        o2, c2 = evaluate(extra)
        order = np.argsort(np.concatenate([speeds, extra]), kind="stable")
        speeds = np.concatenate([speeds, extra])[order]
        orbit, current = np.concatenate([orbit, o2])[order], np.concatenate([current, c2])[order]
    F = force(speeds)
    w = 2 * np.pi * speeds
    resp = orbit * F
    pk = peak_of(resp, w)
    wmax = float(max_speed_rad_s) if law == "iso21940" else None
    return (UnbalanceResponse(w, F, resp, pk.value * 1e6, pk.frequency_hz, float(mass_kg),
                              float(grade_mm_s), law, wmax),
            current * F[:, None], tuple(axes))
