"""The rig as a linear parameter-varying (LPV) plant scheduled on the spin speed Ω.

Thesis P3 §4: the plant changes with Ω through the gyroscopic term Ω·G and through the
seal coefficients, which are tabulated against excitation frequency and taken at the
synchronous frequency Ω/2π. In full-order state space (:mod:`ambseal.model.rig`)::

    A_f(Ω) = [[0, I], [−M⁻¹(K₀ + K_s(Ω)), −M⁻¹(C₀ + C_s(Ω) + Ω G)]],   B_f, C_f constant

so A_f is piecewise linear in Ω between seal-table points (linear, i.e. affine, when no
coefficient is tabulated). Two representations are built here:

* **gridded**: frozen plants A(Ω_k) on a speed grid plus the derivative dA/dΩ(Ω_k) (central
  finite differences of the full-order model, projected), which the rate-bounded synthesis
  needs (Wu et al. 1996; Apkarian & Adams 1998);
* **affine** A(Ω) = A₀ + Ω A₁ where it is one (no frequency-tabulated seal coefficient):
  :attr:`LpvPlant.affine`.

**Common state basis.** A modal reduction at each speed would give each frozen plant its own
state coordinates, and an LPV Lyapunov function needs one. The full-order model is reduced
once, at a reference speed (:func:`ambseal.model.reduction.modal_reduction` → T_L, T_R), and
every frozen full-order plant is projected with the same T_L, T_R (Petrov–Galerkin,
thesis P1 Eqs. 43–45; P3 Eq. 4 and Eq. 8, where the same transformation reduces the
parameter changes). The actuator (P3 Eq. 2) is then put in series, as in
:func:`ambseal.model.rig.build_plant`.
"""

from __future__ import annotations

from dataclasses import dataclass, field, replace

import numpy as np

from ambseal.config import FrequencyTable
from ambseal.errors import ModelError
from ambseal.model import (
    Plant,
    actuator_matrices,
    build_system,
    coefficient_value,
    eddy_lag_matrices,
    mechanical_plant,
    modal_reduction,
)

__all__ = ["LpvPlant", "lpv_plant", "vertex_grid_hz"]

_TWO_PI = 2.0 * np.pi


@dataclass(frozen=True, eq=False)
class LpvPlant:
    """Frozen plants on a speed grid in one state basis, with dA/dΩ.

    ẋ = A(Ω) x + B u, y = C x + D u; B, C, D do not depend on Ω (the speed enters only
    through stiffness, damping and gyroscopic terms).

    Attributes
    ----------
    speeds_rad_s : ndarray, shape (n_p,)
        Grid of spin speeds Ω (rad/s), strictly increasing.
    A : ndarray, shape (n_p, n, n)
        Frozen state matrices A(Ω_k) (1/s).
    dA : ndarray, shape (n_p, n, n)
        dA/dΩ at the grid points (1/s per rad/s), central differences of the full model.
    B : ndarray, shape (n, m)
        Inputs: coil-current references (A), then force inputs (N) if any.
    C : ndarray, shape (p, n)
        Sensor displacements (m).
    D : ndarray, shape (p, m)
    input_names, output_names, state_names : tuple of str
    reference_speed_rad_s : float
        Speed at which the common basis (modal reduction) was computed.
    affine : tuple of ndarray or None
        ``(A0, A1)`` with A(Ω) = A0 + Ω A1 exactly when no seal coefficient is tabulated
        against frequency; ``None`` otherwise.
    """

    speeds_rad_s: np.ndarray
    A: np.ndarray = field(repr=False)
    dA: np.ndarray = field(repr=False)
    B: np.ndarray = field(repr=False)
    C: np.ndarray = field(repr=False)
    D: np.ndarray = field(repr=False)
    input_names: tuple[str, ...] = ()
    output_names: tuple[str, ...] = ()
    state_names: tuple[str, ...] = ()
    reference_speed_rad_s: float = 0.0
    affine: tuple | None = field(default=None, repr=False)

    @property
    def n_states(self) -> int:
        return self.A.shape[1]

    @property
    def speeds_hz(self) -> np.ndarray:
        """Grid speeds Ω/2π (Hz), shape (n_p,)."""
        return self.speeds_rad_s / _TWO_PI

    def A_at(self, speed_rad_s: float) -> np.ndarray:
        """A(Ω) (n, n): exact for the affine model, else linear between grid points
        (the seal tables are linear between their points; put them on the grid).

        Raises ModelError outside the grid.
        """
        W = float(speed_rad_s)
        g = self.speeds_rad_s
        if not (g[0] - 1e-9 * g[-1] <= W <= g[-1] * (1 + 1e-9)):
            raise ModelError(f"LPV plant: speed {W / _TWO_PI:.4g} Hz outside the grid "
                             f"{g[0] / _TWO_PI:.4g}–{g[-1] / _TWO_PI:.4g} Hz")
        if self.affine is not None:
            return self.affine[0] + W * self.affine[1]
        j = int(np.clip(np.searchsorted(g, W) - 1, 0, len(g) - 2))
        t = (W - g[j]) / (g[j + 1] - g[j])
        return (1 - t) * self.A[j] + t * self.A[j + 1]

    def plant_at(self, speed_rad_s: float):
        """The frozen plant at Ω as an :class:`ambseal.model.lft.Plant` (no LFT channels)."""

        return Plant(A=self.A_at(speed_rad_s), B=self.B, C=self.C, D=self.D,
                     input_names=self.input_names, output_names=self.output_names,
                     state_names=self.state_names)

    def statespace_at(self, speed_rad_s: float):
        """The frozen plant at Ω as a named ``control.StateSpace``."""
        return self.plant_at(speed_rad_s).to_statespace()

    def to_dict(self) -> dict:
        """JSON-ready summary (no matrices)."""
        return {"speeds_hz": self.speeds_hz.tolist(), "states": self.n_states,
                "inputs": list(self.input_names), "outputs": list(self.output_names),
                "reference_speed_hz": self.reference_speed_rad_s / _TWO_PI,
                "affine": self.affine is not None}


def vertex_grid_hz(cfg, speeds_hz) -> np.ndarray:
    """The speed grid on which A(Ω) is exactly piecewise affine: the ends of the range and
    every seal-table frequency strictly inside it (Hz).

    A(Ω) is affine in Ω between consecutive seal-table points (module docstring; the seal
    tables are linear between their points), so it is the convex combination of its values
    at these points. An LMI affine in A(Ω) with Ω-independent variables — the LPV
    conditions with a constant Lyapunov function (:func:`ambseal.robust.lpv.lpvsyn`,
    thesis P3 §4) — that holds at them therefore holds at every speed of the range
    (Apkarian, Gahinet & Becker 1995, polytopic LPV); a finer grid adds only cost. Without
    a frequency table the grid is the two ends.

    Parameters
    ----------
    cfg : ambseal.config.RigConfig
        The rig (its seal tables' frequencies).
    speeds_hz : (float, float)
        Operating speed range (Hz), increasing.

    Returns
    -------
    ndarray, shape (n_p,)
        Strictly increasing speeds (Hz), n_p ≥ 2.
    """

    lo, hi = (float(x) for x in speeds_hz)
    inner = {float(f) for seal in cfg.seal for key in "KkCc"
             if isinstance(c := getattr(seal, key), FrequencyTable)
             for f in c.frequency_hz if lo < f < hi}
    return np.array(sorted(inner | {lo, hi}))


def lpv_plant(cfg, speeds_hz, *, reference_speed_hz: float | None = None,
              states: int | None = None, force_positions: tuple[float, ...] = (),
              fd_step_hz: float = 0.5) -> LpvPlant:
    """Gridded LPV model of a rig on a speed grid, in one reduced state basis.

    Parameters
    ----------
    cfg : ambseal.config.RigConfig
        The rig (seal coefficients may be frequency tables, taken at Ω/2π).
    speeds_hz : array_like, shape (n_p,)
        Spin-speed grid (Hz), strictly increasing, n_p ≥ 2.
    reference_speed_hz : float, optional
        Speed of the modal reduction giving the common basis; default the grid's middle
        (geometric mean of the ends, rounded onto the interval).
    states : int, optional
        Reduced mechanical states (default ``[reduction] states`` or 8: the rigid-body modes,
        thesis P3 §2.2; 12 adds the first bending pair).
    force_positions : tuple of float
        Positions (m) of extra force inputs ``F{k}_x``, ``F{k}_y`` (N), e.g. the AMB A
        position for the step disturbance of P3 Fig. 11.
    fd_step_hz : float
        Step (Hz) of the central differences for dA/dΩ (exact for the gyroscopic term; the
        one-sided slope of a seal table at its own points is averaged).

    Returns
    -------
    LpvPlant

    Raises
    ------
    ModelError
        A grid with fewer than two points, not increasing, or a negative speed; a failing
        modal reduction.

    Notes
    -----
    The full-order model is assembled once, at the reference speed. A(Ω) then follows
    without re-assembly: the projected gyroscopic term (Ω − Ω_ref)·T_L [[0, 0], [0, −M⁻¹G]] T_R
    plus the seal coefficient changes through their projected LFT channels
    Δθ·(T_L B_θ)(C_θ T_R) (P3 Eqs. 7–10) — the same matrices as projecting a rebuilt
    full-order model, at a fraction of the cost.
    """

    f = np.asarray(speeds_hz, float).ravel()
    if f.size < 2:
        raise ModelError(f"LPV plant: the speed grid needs at least 2 points, got {f.size}")
    if np.any(np.diff(f) <= 0) or f[0] < 0 or not np.all(np.isfinite(f)):
        raise ModelError("LPV plant: speeds_hz must be finite, ≥ 0 and strictly increasing")
    ref = float(reference_speed_hz) if reference_speed_hz is not None else 0.5 * (f[0] + f[-1])
    if states is None:
        states = cfg.reduction.states or 8
    for seal in cfg.seal:
        if not isinstance(seal.M, (int, float)) and seal.frequency_dependent:
            if isinstance(seal.M, FrequencyTable):
                raise ModelError(f"LPV plant: seal {seal.name!r} has a frequency-tabulated "
                                 "mass coefficient M, which the LPV model does not support")
    W_ref = _TWO_PI * ref
    sys_ref = build_system(cfg, speed_rpm=W_ref * 60.0 / _TWO_PI,
                           force_positions=tuple(force_positions))
    red = modal_reduction(mechanical_plant(sys_ref), states=states)
    T_L, T_R, mech = red.T_L, red.T_R, red.plant
    # gyroscopic part of A_f per rad/s: [[0, 0], [0, −M⁻¹G]], projected once
    nd = sys_ref.n_dof
    MiG = sys_ref.mass_solve(sys_ref.G)
    A_gyro = -T_L[:, nd:] @ MiG @ T_R[nd:, :]
    # seal coefficients through their (projected) LFT channels: A += Δθ B_θ C_θ
    p_bar = cfg.operating.pressure_bar
    seal_terms = []
    for seal in cfg.seal:
        for key in "KkCc":
            par = mech.parameter(f"{seal.name}.{key}")
            seal_terms.append((seal, key, par.nominal, par.B @ par.C))

    def coeffs(W: float, key_seal) -> float:
        seal, key = key_seal
        return coefficient_value(getattr(seal, key), p_bar, W / _TWO_PI)

    def A_mech(W: float) -> np.ndarray:
        A = mech.A + (W - W_ref) * A_gyro
        for seal, key, nominal, BC in seal_terms:
            A = A + (coeffs(W, (seal, key)) - nominal) * BC
        return A

    n_cur = 2 * len(cfg.amb)
    acts = []
    if cfg.actuator.eddy_time_constant > 0 and n_cur:
        acts.append((eddy_lag_matrices(cfg.actuator.eddy_time_constant), "eddy"))
    if cfg.actuator.model != "none" and n_cur:
        acts.append((actuator_matrices(cfg.actuator), "act"))

    def reduced(W: float):
        p = replace(mech, A=A_mech(W), parameters={})
        for mats, label in acts:
            p = p.series_actuator(*mats, inputs=list(range(n_cur)), label=label)
        return p

    h = _TWO_PI * fd_step_hz
    As, dAs, first = [], [], None
    for fk in f:
        W = _TWO_PI * fk
        p = reduced(W)
        first = first or p
        lo = max(W - h, 0.0)
        dAs.append((reduced(W + h).A - reduced(lo).A) / (W + h - lo))
        As.append(p.A)
    affine = None
    if not any(s.frequency_dependent for s in cfg.seal):
        A1 = dAs[0]
        affine = (As[0] - _TWO_PI * f[0] * A1, A1)
    return LpvPlant(
        speeds_rad_s=_TWO_PI * f, A=np.array(As), dA=np.array(dAs), B=first.B, C=first.C,
        D=first.D, input_names=first.input_names, output_names=first.output_names,
        state_names=first.state_names, reference_speed_rad_s=_TWO_PI * ref, affine=affine,
    )
