"""Closed-loop identification through the Youla/dual-Youla (Hansen) scheme, thesis P1 §II.

An AMB rotor is open-loop unstable, so its parameters must be found in closed loop. P1
(after Niemann 2003 and Hansen's scheme) turns that into an open-loop problem for a *stable*
system:

1. Factorise the nominal plant G = G(0) and a controller K that stabilises both G and the
   true plant G(θ) into doubly coprime factors (P1 Eqs. 1–3),

       G = N M⁻¹ = M̃⁻¹ Ñ,   K = U V⁻¹ = Ṽ⁻¹ Ũ,
       [[Ṽ, −Ũ], [−Ñ, M̃]] [[M, U], [N, V]] = I = [[M, U], [N, V]] [[Ṽ, −Ũ], [−Ñ, M̃]].

   Here they are observer based (Zhou, Doyle & Glover 1996, Thm 5.9; the "standard observer
   based feedback structure" of P1 §V): with F and L such that A + BF and A + LC are stable,

       [[M, U], [N, V]]     = [A+BF | B, −L;  F | I, 0;  C+DF | D, I]
       [[Ṽ, −Ũ], [−Ñ, M̃]] = [A+LC | −(B+LD), L;  F | I, 0;  C | −D, I].

   K is the observer-based controller x̂⁺ = A x̂ + B u_c − L(y_c − C x̂ − D u_c),
   u_c = F x̂ + η, in *positive* feedback u_c = K y_c + Ṽ⁻¹ η (P1 Eqs. 4–6 with the
   loop of Q opened; the project's PID convention u = −K y is the negative of this K).

2. The signals of P1 Fig. 2 follow from what the controller reads and writes, y_c and u_c:

       [η; ε] = [[Ṽ, −Ũ], [−Ñ, M̃]] [u_c; y_c],

   i.e. η = u_c − F x̂ (the injected excitation, recovered) and ε = y_c − C x̂ − D u_c (the
   observer's innovation). The external signals of Eq. 10 enter as y_c = y + r1 (added to the
   measurement the controller reads) and u = u_c + r2 (added to the plant input); with these
   definitions the closed loop is Eq. 11: with ξ = η + Ũ r1 + Ṽ r2, y = (N + VS) ξ,
   u = (M + US) ξ and ε = S ξ + M̃ r1 + Ñ r2 = (M̃ + SŨ) r1 + (Ñ + SṼ) r2 + S η. (P1 prints
   Ṽ and Ũ swapped in the ε row, which does not conform in dimension when m ≠ p.)

3. ε = S(θ) η + … (Eqs. 8, 14) with the dual-Youla parameter S(θ) of Eq. 13,

       S(θ) = F_l([[0, M̃ G_yw], [G_zu M, G_zw + G_zu U M̃ G_yw]], Θ),

   stable whenever K stabilises G(θ), zero for θ = 0; conversely G(θ) = (N + VS)(M + US)⁻¹
   (Eq. 9, printed garbled in P1 as (M + SU)⁻¹(N + SV)⁻¹; the form here is the one Eq. 11's
   y and u rows imply). Its realisation here is the nominal
   plant with the parameter channels (w into the state, z out) and the observer-based
   controller, state [x; e] with e = x − x̂: the block from w to ε is M̃ G_yw (the observer error
   e = x − x̂ obeys e⁺ = (A + LC) e + B_w w), from η to z it is G_zu M and from w to z the
   nominal closed loop G_zw + G_zu (I − K G)⁻¹ K G_yw = G_zw + G_zu U M̃ G_yw.

4. θ is the least-squares fit of ε ≈ S(θ) η (Eqs. 14–15) by ``scipy.optimize.least_squares``
   (P1 used MATLAB's ``fminsearch``).

Continuous or discrete time
---------------------------
The factorisation works in either (``dt=None`` or the sample period). In continuous time Θ is
θ·I_r on the plant's LFT channels (B_θ, C_θ, D_θ) of :mod:`ambseal.model.lft`, literally
Eq. 13. A digital controller at sample period T sees the zero-order-hold sampled plant
G_d(θ) = (e^{A(θ)T}, ∫₀ᵀ e^{A(θ)τ}dτ B(θ)), in which θ does not enter affinely; Eq. 13 is then
used with the exact sampled change Θ_d = [A_d(θ) − A_d(0), B_d(θ) − B_d(0)] as the LFT block
(B_w = I, z = [x; u]), so S_d(θ) is exact for sampled data and the fit is unbiased. Measured
records are sampled, so :func:`youla_signals` and :func:`identify_youla` need discrete
factors; :func:`youla_factorisation` with ``dt`` builds them.

Parameters are *normalised* as in P1 ("θ = 1 corresponds to a 100 % change"): the change in
SI is θ·scale, the scale being |nominal| by default. P1 §IV: a 50 % change of one bearing's
Ks in one direction, θ = 0.5, identified as 0.502.

The factorisation itself, with a runnable example, is in :mod:`ambseal.identify.fitting.coprime`.
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field
from typing import Mapping, Sequence

import numpy as np
from scipy.optimize import least_squares

from ambseal.errors import IdentificationError
from ambseal.identify.fitting.coprime import (
    CoprimeFactors,
    _as_2d,
    _ss,
    check_bezout,
    coprime_factors,
    observer_gains,
    youla_factorisation,
)
from ambseal.lti import least_squares_converged, simulate_lti, zoh
from ambseal.model import Plant

__all__ = [
    "CoprimeFactors",
    "YoulaResult",
    "observer_gains",
    "coprime_factors",
    "youla_factorisation",
    "check_bezout",
    "youla_signals",
    "dual_youla_matrices",
    "dual_youla",
    "identify_youla",
]




# --------------------------------------------------------------------------- signals
def youla_signals(
    cf: CoprimeFactors,
    u: np.ndarray,
    y: np.ndarray,
    r1: np.ndarray | None = None,
    r2: np.ndarray | None = None,
) -> tuple[np.ndarray, np.ndarray]:
    """η and ε of P1 Fig. 2 from sampled closed-loop signals: [η; ε] = [[Ṽ, −Ũ], [−Ñ, M̃]] [u_c; y_c].

    Parameters
    ----------
    cf : CoprimeFactors
        Discrete factors at the record's sample period (the controller that ran).
    u : ndarray, shape (N, m)
        Plant input (A) at the samples, held between them.
    y : ndarray, shape (N, p)
        Measured output (m) at the samples, as the controller read it.
    r1 : ndarray, shape (N, p), optional
        Known signal added to the measurement the controller reads, y_c = y + r1.
    r2 : ndarray, shape (N, m), optional
        Known signal added at the plant input, u = u_c + r2.

    Returns
    -------
    eta : ndarray, shape (N, m)
        η = u_c − F x̂ (A): the Youla input, equal to the injected excitation.
    eps : ndarray, shape (N, p)
        ε = y_c − C x̂ − D u_c (m): the observer innovation; S(θ) η plus Eq. 14's terms.

    Raises
    ------
    IdentificationError
        If ``cf`` is continuous (sampled data need discrete factors).
    DataError
        Wrong shapes or non-finite samples.

    Notes
    -----
    The observer starts at x̂ = 0 (the record starts at rest).
    """
    if cf.dt is None:
        raise IdentificationError(
            "youla_signals: sampled records need discrete factors (youla_factorisation(dt=...))")
    m, p = cf.n_inputs, cf.n_outputs
    u = _as_2d(u, "u", m)
    N = u.shape[0]
    y = _as_2d(y, "y", p, N)
    uc = u - (_as_2d(r2, "r2", m, N) if r2 is not None else 0.0)
    yc = y + (_as_2d(r1, "r1", p, N) if r1 is not None else 0.0)
    Al, Bl, Cl, Dl = cf.left_matrices()
    w = np.hstack([uc, yc])
    (out,) = simulate_lti(Al, Bl, [Cl], w)
    out = out + w @ Dl.T
    return out[:, :m], out[:, m:]


# --------------------------------------------------------------------------- S(θ)
def _channels(cf: CoprimeFactors, plant: Plant, names: Sequence[str]):
    """(B_w, C_z, D_zu) of the LFT block: plant channels (continuous) or [I; (x, u)] (discrete)."""
    n, m = cf.n_states, cf.n_inputs
    if cf.dt is None:
        return plant.channels(list(names))
    return np.eye(n), np.vstack([np.eye(n), np.zeros((m, n))]), np.vstack([np.zeros((n, m)), np.eye(m)])


def _theta_block(cf: CoprimeFactors, plant: Plant, changes: Mapping[str, float]) -> np.ndarray:
    """Θ: diag(θ_i I_{r_i}) (continuous) or [A_d(θ) − A_d, B_d(θ) − B_d] (discrete), SI."""
    names = list(changes)
    if cf.dt is None:
        blocks = [np.full(plant.parameter(k).repeats, float(changes[k])) for k in names]
        return np.diag(np.concatenate(blocks)) if blocks else np.zeros((0, 0))
    pt = plant.with_changes({k: float(v) for k, v in changes.items()})
    Ad, Bd = zoh(pt.A, pt.B, cf.dt)
    return np.hstack([Ad - cf.A, Bd - cf.B])


def _check_plant(cf: CoprimeFactors, plant: Plant) -> None:
    """The factors must be those of this plant's nominal (sampled) realisation."""
    A, B = plant.A, plant.B
    if cf.dt is not None:
        A, B = zoh(A, B, cf.dt)
    ok = (A.shape == cf.A.shape and B.shape == cf.B.shape and plant.C.shape == cf.C.shape
          and np.allclose(A, cf.A, rtol=1e-9, atol=1e-12 * max(1.0, np.abs(A).max()))
          and np.allclose(B, cf.B, rtol=1e-9, atol=1e-12 * max(1.0, np.abs(B).max()))
          and np.allclose(plant.C, cf.C, rtol=1e-12, atol=0.0))
    if not ok:
        raise IdentificationError(
            "dual_youla: the factors are not those of this plant's nominal realisation "
            "(build them with youla_factorisation(plant, dt=...))")


def dual_youla_matrices(cf: CoprimeFactors, Bw: np.ndarray, Cz: np.ndarray, Dzu: np.ndarray):
    """Realisation of the matrix of P1 Eq. 13, J_S = [[0, M̃ G_yw], [G_zu M, G_zw + G_zu U M̃ G_yw]].

    The plant's parameter channels are x⁺ = A x + B u + B_w w, z = C_z x + D_zu u (y has no
    direct w term). State [x; e] of the plant and the observer error e = x − x̂ of the
    observer-based controller.

    Parameters
    ----------
    cf : CoprimeFactors
    Bw : ndarray, shape (n, r)
    Cz : ndarray, shape (r_z, n)
    Dzu : ndarray, shape (r_z, m)

    Returns
    -------
    (A, B, C, D) : ndarrays
        Inputs [η (m); w (r)], outputs [ε (p); z (r_z)]; A is (2n, 2n) with the eigenvalues
        of A + BF and A + LC, so J_S is stable; D_zw = 0, so every F_l(J_S, Θ) is well posed.
    """
    A, B, C, F, L = cf.A, cf.B, cf.C, cf.F, cf.L
    n, m, p = cf.n_states, cf.n_inputs, cf.n_outputs
    r, rz = Bw.shape[1], Cz.shape[0]
    # state [x; e], e = x − x̂:  u = F(x − e) + η,
    #   x⁺ = (A + BF) x − BF e + B η + B_w w,   e⁺ = (A + LC) e + B_w w,
    #   ε = C e  (= M̃ G_yw w),   z = (C_z + D_zu F) x − D_zu F e + D_zu η
    # block triangular, so η → ε is structurally zero and J_S is stable by construction
    AJ = np.block([[A + B @ F, -B @ F], [np.zeros((n, n)), A + L @ C]])
    BJ = np.block([[B, Bw], [np.zeros((n, m)), Bw]])
    CJ = np.block([[np.zeros((p, n)), C], [Cz + Dzu @ F, -Dzu @ F]])
    DJ = np.block([[np.zeros((p, m)), np.zeros((p, r))], [Dzu, np.zeros((rz, r))]])
    return AJ, BJ, CJ, DJ


def _close(cf, JS, Theta):
    """F_l(J_S, Θ) with D_zw = 0: (A_S, B_S, C_S, D_S)."""
    AJ, BJ, CJ, DJ = JS
    m, p = cf.n_inputs, cf.n_outputs
    Bn, Bw = BJ[:, :m], BJ[:, m:]
    Ce, Cz = CJ[:p], CJ[p:]
    Den, Dew = DJ[:p, :m], DJ[:p, m:]
    Dzn = DJ[p:, :m]
    return (AJ + Bw @ Theta @ Cz, Bn + Bw @ Theta @ Dzn, Ce + Dew @ Theta @ Cz,
            Den + Dew @ Theta @ Dzn)


def dual_youla(cf: CoprimeFactors, plant: Plant, changes: Mapping[str, float]):
    """The dual-Youla parameter S(θ) of P1 Eq. 13 for parameter changes θ (SI).

    S(θ) maps η to ε (Eq. 8); S(0) = 0, and S(θ) is stable iff K stabilises G(θ), even where
    G(θ) is unstable (P1 Figs. 6–7).

    Parameters
    ----------
    cf : CoprimeFactors
        Factors of ``plant``'s nominal realisation (continuous, or sampled at ``cf.dt``).
    plant : Plant
        Nominal plant with its LFT parameter channels.
    changes : mapping {name: θ}
        Absolute changes (SI, e.g. N/m), as :meth:`Plant.with_changes`.

    Returns
    -------
    control.StateSpace
        S(θ), m inputs (η, A), p outputs (ε, m); 2n states [x; x − x̂]; continuous or at
        ``cf.dt``.

    Raises
    ------
    IdentificationError
        ``cf`` is not the factorisation of ``plant``.
    ModelError
        Unknown parameter name.
    """
    _check_plant(cf, plant)
    names = list(changes)
    JS = dual_youla_matrices(cf, *_channels(cf, plant, names))
    AS, BS, CS, DS = _close(cf, JS, _theta_block(cf, plant, changes))
    return _ss(AS, BS, CS, DS, cf.dt,
               [f"eta_{k}" for k in cf.input_names] or None,
               [f"eps_{k}" for k in cf.output_names] or None)


# --------------------------------------------------------------------------- fit
@dataclass(frozen=True, eq=False)
class YoulaResult:
    """Parameters identified through the dual-Youla parameter S(θ) (P1 Eqs. 14–15).

    Attributes
    ----------
    names : tuple of str
        Parameter names, e.g. ``("B.Ks_eta",)``.
    theta : ndarray, shape (k,)
        Normalised changes (-): θ = 1 is a 100 % change (P1 §III-7).
    theta_std : ndarray, shape (k,)
        Standard errors of θ (-) from σ̂²(JᵀJ)⁻¹; ε's residual is coloured, so indicative.
    scale : ndarray, shape (k,)
        SI value of θ = 1 (|nominal| by default).
    change : ndarray, shape (k,)
        θ·scale (SI).
    nominal, value : ndarray, shape (k,)
        Nominal value and nominal + change (SI).
    theta0 : ndarray, shape (k,)
        Starting point (-).
    cost : float
        ½ Σ (ε − S(θ̂)η)² / ε_s², ε_s the rms of ε.
    fit_pct : float
        100·(1 − ‖ε − S(θ̂)η‖/‖ε‖): share of ε explained by S(θ̂)η.
    spectral_radius : float
        Of S(θ̂)'s state matrix (< 1: S(θ̂) stable, K stabilises the identified plant).
    eta_mismatch : float
        max|η_from_signals − η_given| / max|η_given| (0 if η was not given): checks that the
        records and the factors belong together.
    converged : bool
    message : str
    nfev : int
    n_samples : int
    dt : float
        Sample period (s).
    wall_time_s : float
    """

    names: tuple[str, ...]
    theta: np.ndarray
    theta_std: np.ndarray
    scale: np.ndarray
    change: np.ndarray
    nominal: np.ndarray
    value: np.ndarray
    theta0: np.ndarray
    cost: float
    fit_pct: float
    spectral_radius: float
    eta_mismatch: float
    converged: bool
    message: str
    nfev: int
    n_samples: int
    dt: float
    wall_time_s: float = field(default=0.0)

    def theta_of(self, name: str) -> float:
        """Normalised θ of ``name``."""
        return float(self.theta[self.names.index(name)])

    def to_dict(self) -> dict:
        def f(x):
            return [float(v) if np.isfinite(v) else None for v in np.ravel(x)]

        return {
            "method": "youla",
            "parameters": {
                n: {"theta": f([self.theta[i]])[0], "theta_std": f([self.theta_std[i]])[0],
                    "scale": float(self.scale[i]), "change": float(self.change[i]),
                    "nominal": float(self.nominal[i]), "value": float(self.value[i]),
                    "theta0": float(self.theta0[i])}
                for i, n in enumerate(self.names)
            },
            "cost": float(self.cost),
            "fit_pct": float(self.fit_pct),
            "spectral_radius": float(self.spectral_radius),
            "eta_mismatch": float(self.eta_mismatch),
            "converged": self.converged,
            "message": self.message,
            "nfev": self.nfev,
            "n_samples": self.n_samples,
            "dt": self.dt,
            "wall_time_s": self.wall_time_s,
        }


def identify_youla(
    cf: CoprimeFactors,
    plant: Plant,
    names: Sequence[str],
    *,
    u: np.ndarray,
    y: np.ndarray,
    eta: np.ndarray | None = None,
    r1: np.ndarray | None = None,
    r2: np.ndarray | None = None,
    theta0: Sequence[float] | None = None,
    scales: Mapping[str, float] | None = None,
    bounds: tuple[float, float] = (-np.inf, np.inf),
    max_nfev: int | None = None,
) -> YoulaResult:
    """Identify normalised parameter changes θ from a closed-loop record (P1 §II, Eqs. 13–15).

    ε and η are computed from the record (:func:`youla_signals`), S(θ) from Eq. 13
    (:func:`dual_youla`), and θ minimises ½ Σ_k ‖ε_k − (S(θ) η)_k‖² (Eq. 15) with
    ``scipy.optimize.least_squares`` (trust-region reflective, finite-difference Jacobian).

    Parameters
    ----------
    cf : CoprimeFactors
        Discrete factors of ``plant`` at the record's sample period; K built from them ran.
    plant : Plant
        Nominal plant (continuous) with its LFT channels.
    names : sequence of str
        Parameters to identify, e.g. ``["B.Ks_eta"]``.
    u : ndarray, shape (N, m)
        Plant input (A).
    y : ndarray, shape (N, p)
        Measured output (m) as the controller read it.
    eta : ndarray, shape (N, m), optional
        The injected excitation (A). If omitted, the η recovered from (u, y) is used.
    r1, r2 : ndarray, optional
        External signals of Eq. 10 (see :func:`youla_signals`); uncorrelated with η, they only
        add noise to Eq. 14.
    theta0 : sequence of float, optional
        Start (normalised), zeros (the nominal plant) by default.
    scales : mapping {name: float}, optional
        SI size of θ = 1 per parameter; |nominal| by default.
    bounds : (float, float)
        Bounds on every normalised θ.
    max_nfev : int, optional
        A cap on function evaluations. None (the default): the fit ends at its tolerances
        (:func:`ambseal.lti.least_squares.least_squares_converged`), never at a count.

    Returns
    -------
    YoulaResult

    Raises
    ------
    IdentificationError
        Continuous or foreign factors, a zero scale, or the optimiser failing.
    DataError
        Records of wrong shape or with NaN/inf.
    ModelError
        Unknown parameter name.
    """
    t_start = time.perf_counter()
    names = list(names)
    if not names:
        raise IdentificationError("identify_youla: no parameter names given")
    if cf.dt is None:
        raise IdentificationError("identify_youla: needs discrete factors (youla_factorisation(dt=...))")
    _check_plant(cf, plant)
    params = [plant.parameter(n) for n in names]
    scales = dict(scales or {})
    scale = np.array([float(scales.get(p.name, abs(p.nominal))) for p in params])
    if np.any(~np.isfinite(scale)) or np.any(scale == 0):
        bad = [n for n, s in zip(names, scale) if not np.isfinite(s) or s == 0]
        raise IdentificationError(f"identify_youla: zero or invalid scale for {bad}; pass scales=")
    k = len(names)
    x0 = np.zeros(k) if theta0 is None else np.asarray(theta0, dtype=float).reshape(k)

    eta_sig, eps = youla_signals(cf, u, y, r1, r2)
    N = eps.shape[0]
    if eta is None:
        eta_fit, mismatch = eta_sig, 0.0
    else:
        eta_fit = _as_2d(eta, "eta", cf.n_inputs, N)
        ref = np.abs(eta_fit).max()
        mismatch = float(np.abs(eta_sig - eta_fit).max() / ref) if ref > 0 else 0.0
    eps_scale = float(np.sqrt(np.mean(eps**2))) or 1.0

    JS = dual_youla_matrices(cf, *_channels(cf, plant, names))

    def predict(x):
        changes = {n: float(xi * s) for n, xi, s in zip(names, x, scale)}
        AS, BS, CS, DS = _close(cf, JS, _theta_block(cf, plant, changes))
        (e,) = simulate_lti(AS, BS, [CS], eta_fit)
        return e + eta_fit @ DS.T, AS

    def residuals(x):
        e, _ = predict(x)
        r = ((eps - e) / eps_scale).ravel()
        # an unstable candidate S(θ) (K does not stabilise G(θ)) blows up: keep it finite
        return np.clip(np.nan_to_num(r, nan=1e10, posinf=1e10, neginf=-1e10), -1e10, 1e10)

    try:
        opts = dict(bounds=bounds, x_scale=1.0, method="trf", xtol=1e-12, ftol=1e-12,
                    gtol=1e-12)
        sol = (least_squares_converged(residuals, x0, **opts) if max_nfev is None
               else least_squares(residuals, x0, max_nfev=max_nfev, **opts))
    except (ValueError, np.linalg.LinAlgError) as exc:
        raise IdentificationError(f"identify_youla: least squares failed ({exc})") from None
    theta = sol.x
    e_hat, AS = predict(theta)
    res = eps - e_hat
    dof = max(res.size - k, 1)
    sigma2 = float(np.sum(sol.fun**2)) / dof
    try:
        cov = sigma2 * np.linalg.inv(sol.jac.T @ sol.jac)
        std = np.sqrt(np.clip(np.diag(cov), 0.0, None))
    except np.linalg.LinAlgError:
        std = np.full(k, np.nan)
    rho = float(np.max(np.abs(np.linalg.eigvals(AS))))
    norm_eps = np.linalg.norm(eps)
    fit = 100.0 * (1.0 - np.linalg.norm(res) / norm_eps) if norm_eps > 0 else float("nan")
    nominal = np.array([p.nominal for p in params])
    return YoulaResult(
        names=tuple(names), theta=theta, theta_std=std, scale=scale, change=theta * scale,
        nominal=nominal, value=nominal + theta * scale, theta0=x0, cost=float(sol.cost),
        fit_pct=float(fit), spectral_radius=rho, eta_mismatch=mismatch,
        converged=bool(sol.success) and rho < 1.0, message=str(sol.message), nfev=int(sol.nfev),
        n_samples=N, dt=float(cf.dt), wall_time_s=time.perf_counter() - t_start,
    )
