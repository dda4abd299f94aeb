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

Example
-------
>>> import numpy as np
>>> from ambseal.identify.youla import coprime_factors, observer_gains
>>> A = np.array([[0.0, 1.0], [100.0, 0.0]]); B = np.array([[0.0], [1.0]])
>>> C = np.array([[1.0, 0.0]]); D = np.zeros((1, 1))
>>> F, L = observer_gains(A, B, C)
>>> cf = coprime_factors(A, B, C, D, F, L)
>>> cf.check_bezout() < 1e-9
True
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field
from typing import Mapping, Sequence

import numpy as np
import scipy.linalg as sla
from scipy.optimize import least_squares

from ..errors import DataError, IdentificationError
from ..model.lft import Plant
from .loop import simulate_lti, zoh

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


# --------------------------------------------------------------------------- helpers
def _ss(A, B, C, D, dt, inputs=None, outputs=None):
    import control

    kw = {}
    if inputs is not None:
        kw["inputs"] = list(inputs)
    if outputs is not None:
        kw["outputs"] = list(outputs)
    return control.ss(A, B, C, D, 0 if dt is None else dt, **kw)


def _is_stable(A: np.ndarray, dt: float | None, margin: float = 0.0) -> bool:
    """All eigenvalues in the open left half plane (dt None) or open unit disc."""
    if A.size == 0:
        return True
    lam = np.linalg.eigvals(A)
    if dt is None:
        return bool(np.all(lam.real < -margin))
    return bool(np.all(np.abs(lam) < 1.0 - margin))


def _freqresp(A, B, C, D, pts: np.ndarray) -> np.ndarray:
    """C (pI − A)⁻¹ B + D at complex points ``pts`` (nf,), vectorised; shape (nf, p, m).

    The realisation is first balanced by a diagonal similarity (``scipy.linalg.
    matrix_balance``): AMB plants in modal coordinates mix O(1) and O(1e6) entries.
    """
    n = A.shape[0]
    if n == 0:
        return np.broadcast_to(D, (len(pts),) + D.shape).astype(complex)
    _, (sc, _) = sla.matrix_balance(A, permute=False, separate=True)
    A, B, C = A * (sc[None, :] / sc[:, None]), B / sc[:, None], C * sc[None, :]
    P = pts[:, None, None] * np.eye(n)[None] - A[None]
    X = np.linalg.solve(P, np.broadcast_to(B, (len(pts),) + B.shape))
    return C[None] @ X + D[None]


def _as_2d(x, name: str, n_cols: int, n_rows: int | None = None) -> np.ndarray:
    a = np.asarray(x, dtype=float)
    if a.ndim == 1 and n_cols == 1:
        a = a[:, None]
    if a.ndim != 2 or a.shape[1] != n_cols or (n_rows is not None and a.shape[0] != n_rows):
        want = f"({n_rows if n_rows is not None else 'N'}, {n_cols})"
        raise DataError(f"{name}: expected an array of shape {want}, got {a.shape}")
    if not np.all(np.isfinite(a)):
        raise DataError(f"{name}: contains NaN or inf")
    return a


# --------------------------------------------------------------------------- gains
def observer_gains(
    A: np.ndarray,
    B: np.ndarray,
    C: np.ndarray,
    *,
    dt: float | None = None,
    output_scale: float = 1.0,
    input_scale: float = 1.0,
    control_weight: float = 1.0,
    noise_ratio: float = 1.0,
    stability_degree: float = 0.0,
) -> tuple[np.ndarray, np.ndarray]:
    """State feedback F and observer gain L from an LQR and its dual (Kalman) Riccati equation.

    Both in the sign convention of the factorisation: A + BF and A + LC stable (continuous
    or, with ``dt``, discrete). Weights are scaled so that y/``output_scale`` and
    u/``input_scale`` are O(1): F minimises Σ ‖C x/y_s‖² + ρ ‖u/u_s‖²; L is the steady Kalman
    gain for process noise B u_s w (w white, unit) and measurement noise of intensity
    ``noise_ratio``·y_s² (a predictor observer in discrete time).

    Parameters
    ----------
    A : ndarray, shape (n, n)
    B : ndarray, shape (n, m)
    C : ndarray, shape (p, n)
    dt : float, optional
        Sample period (s); ``None`` for continuous time.
    output_scale : float
        Typical output size y_s (e.g. 1e-5 m for an AMB sensor).
    input_scale : float
        Typical input size u_s (e.g. 1 A).
    control_weight : float
        ρ > 0; larger gives a gentler, lower-bandwidth state feedback.
    noise_ratio : float
        > 0; larger gives a slower observer.
    stability_degree : float
        α ≥ 0 (rad/s): both designs are made for A + αI (continuous) or A e^{αT} (discrete),
        so every pole of A + BF and A + LC has real part < −α or modulus < e^{−αT}
        (LQR with a prescribed degree of stability, Anderson & Moore 1990, §3.5). With α
        above the plant's unstable poles the loop keeps a stiffness margin: the plain LQR
        with output weighting only mirrors an AMB's unstable poles and is fragile to a
        larger negative stiffness.

    Returns
    -------
    F : ndarray, shape (m, n)
    L : ndarray, shape (n, p)

    Raises
    ------
    IdentificationError
        If a Riccati equation has no stabilising solution ((A, B) not stabilisable or (C, A)
        not detectable) or the resulting A + BF or A + LC is not stable.
    """
    A, B, C = (np.atleast_2d(np.asarray(M, dtype=float)) for M in (A, B, C))
    n, m = B.shape
    p = C.shape[0]
    if control_weight <= 0 or noise_ratio <= 0 or output_scale <= 0 or input_scale <= 0:
        raise IdentificationError("observer_gains: scales and weights must be > 0")
    if stability_degree < 0:
        raise IdentificationError("observer_gains: stability_degree must be >= 0")
    # shifted / scaled-radius model: its stabilising gains give the prescribed margin
    if dt is None:
        A_, B_, shrink = A + stability_degree * np.eye(n), B, 1.0
    else:
        shrink = float(np.exp(-stability_degree * dt))
        A_, B_ = A / shrink, B / shrink
    # scaled coordinates: y' = y/ys, u' = u/us, so B' = B us, C' = C/ys
    Bs, Cs = B_ * input_scale, C / output_scale
    # a small state weight keeps the Riccati equations well posed for modes C cannot see
    eps = 1e-8 * max(1.0, np.linalg.norm(Cs.T @ Cs, 2))
    Q = Cs.T @ Cs + eps * np.eye(n)
    R = control_weight * np.eye(m)
    W = Bs @ Bs.T + eps * np.eye(n)
    V = noise_ratio * np.eye(p)
    try:
        if dt is None:
            P = sla.solve_continuous_are(A_, Bs, Q, R)
            Fs = -np.linalg.solve(R, Bs.T @ P)
            Pd = sla.solve_continuous_are(A_.T, Cs.T, W, V)
            Ls = -Pd @ Cs.T @ np.linalg.inv(V)
        else:
            P = sla.solve_discrete_are(A_, Bs, Q, R)
            Fs = -np.linalg.solve(R + Bs.T @ P @ Bs, Bs.T @ P @ A_)
            Pd = sla.solve_discrete_are(A_.T, Cs.T, W, V)
            # A_ + Ls' C stable in the unit disc  <=>  A + (shrink Ls') C inside e^{-αT}
            Ls = -shrink * (A_ @ Pd @ Cs.T) @ np.linalg.inv(V + Cs @ Pd @ Cs.T)
    except (np.linalg.LinAlgError, ValueError) as exc:
        raise IdentificationError(f"observer_gains: Riccati equation failed ({exc})") from None
    F = input_scale * Fs  # u = us u' = us Fs x
    L = Ls / output_scale  # L (y) = Ls (y/ys)
    if not _is_stable(A + B @ F, dt) or not _is_stable(A + L @ C, dt):
        raise IdentificationError("observer_gains: A + BF or A + LC is not stable")
    assert F.shape == (m, n) and L.shape == (n, p)
    return F, L


# --------------------------------------------------------------------------- factors
@dataclass(frozen=True, eq=False)
class CoprimeFactors:
    """Observer-based doubly coprime factors of a plant and its controller (P1 Eqs. 1–3).

    Attributes
    ----------
    A, B, C, D : ndarray, shapes (n, n), (n, m), (p, n), (p, m)
        Nominal plant G = C (sI − A)⁻¹ B + D (or z for discrete time); SI units (inputs
        typically A, outputs m).
    F : ndarray, shape (m, n)
        State feedback, A + BF stable.
    L : ndarray, shape (n, p)
        Observer gain, A + LC stable.
    dt : float or None
        Sample period (s), ``None`` for continuous time.
    input_names, output_names : tuple of str
        Names of u (m) and y (p).
    output_scale : float
        Size of a typical output relative to a typical input (y_s/u_s, e.g. m/A), used to
        balance the units in :meth:`bezout_error`; the peak gain of N if 0.
    """

    A: np.ndarray
    B: np.ndarray
    C: np.ndarray
    D: np.ndarray
    F: np.ndarray
    L: np.ndarray
    dt: float | None = None
    input_names: tuple[str, ...] = ()
    output_names: tuple[str, ...] = ()
    output_scale: float = 0.0

    @property
    def n_states(self) -> int:
        return self.A.shape[0]

    @property
    def n_inputs(self) -> int:
        return self.B.shape[1]

    @property
    def n_outputs(self) -> int:
        return self.C.shape[0]

    # -- the two block systems of Eq. 3, as matrices
    def right_matrices(self):
        """(A, B, C, D) of [[M, U], [N, V]]: inputs [η (m); ε (p)], outputs [u (m); y (p)]."""
        A, B, C, D, F, L = self.A, self.B, self.C, self.D, self.F, self.L
        m, p = self.n_inputs, self.n_outputs
        Ar = A + B @ F
        Br = np.hstack([B, -L])
        Cr = np.vstack([F, C + D @ F])
        Dr = np.block([[np.eye(m), np.zeros((m, p))], [D, np.eye(p)]])
        return Ar, Br, Cr, Dr

    def left_matrices(self):
        """(A, B, C, D) of [[Ṽ, −Ũ], [−Ñ, M̃]]: inputs [u (m); y (p)], outputs [η; ε]."""
        A, B, C, D, F, L = self.A, self.B, self.C, self.D, self.F, self.L
        m, p = self.n_inputs, self.n_outputs
        Al = A + L @ C
        Bl = np.hstack([-(B + L @ D), L])
        Cl = np.vstack([F, C])
        Dl = np.block([[np.eye(m), np.zeros((m, p))], [-D, np.eye(p)]])
        return Al, Bl, Cl, Dl

    def _block(self, which: str, row: int, col: int, sign: float = 1.0):
        A_, B_, C_, D_ = self.right_matrices() if which == "R" else self.left_matrices()
        m = self.n_inputs
        rs = slice(0, m) if row == 0 else slice(m, None)
        cs = slice(0, m) if col == 0 else slice(m, None)
        return _ss(A_, B_[:, cs], sign * C_[rs], sign * D_[rs, cs], self.dt)

    def M(self):
        """M = [A+BF, B; F, I] (m × m), ``control.StateSpace``."""
        return self._block("R", 0, 0)

    def N(self):
        """N = [A+BF, B; C+DF, D] (p × m)."""
        return self._block("R", 1, 0)

    def U(self):
        """U = [A+BF, −L; F, 0] (m × p)."""
        return self._block("R", 0, 1)

    def V(self):
        """V = [A+BF, −L; C+DF, I] (p × p)."""
        return self._block("R", 1, 1)

    def V_tilde(self):
        """Ṽ = [A+LC, −(B+LD); F, I] (m × m)."""
        return self._block("L", 0, 0)

    def U_tilde(self):
        """Ũ = [A+LC, −L; F, 0] (m × p)."""
        return self._block("L", 0, 1, -1.0)

    def N_tilde(self):
        """Ñ = [A+LC, B+LD; C, D] (p × m)."""
        return self._block("L", 1, 0, -1.0)

    def M_tilde(self):
        """M̃ = [A+LC, L; C, I] (p × p)."""
        return self._block("L", 1, 1)

    def plant(self):
        """The nominal plant G as a ``control.StateSpace`` (named signals if known)."""
        return _ss(self.A, self.B, self.C, self.D, self.dt,
                   self.input_names or None, self.output_names or None)

    def controller(self, feedback: str = "positive"):
        """The observer-based controller K = U V⁻¹ = Ṽ⁻¹ Ũ.

        Parameters
        ----------
        feedback : {"positive", "negative"}
            ``"positive"`` (P1, Zhou): u = K y with K = [A+BF+LC+LDF, −L; F, 0].
            ``"negative"``: the same controller for the project's convention u = −K y
            (as :func:`ambseal.control.pid.pid_controller`), i.e. −K.

        Returns
        -------
        control.StateSpace
            Inputs y (p), outputs u (m).
        """
        if feedback not in ("positive", "negative"):
            raise ValueError(f"feedback: expected 'positive' or 'negative', got {feedback!r}")
        A, B, C, D, F, L = self.A, self.B, self.C, self.D, self.F, self.L
        s = 1.0 if feedback == "positive" else -1.0
        Ak = A + B @ F + L @ C + L @ D @ F
        return _ss(Ak, -L, s * F, np.zeros((self.n_inputs, self.n_outputs)), self.dt,
                   [f"y_{n}" for n in self.output_names] or None,
                   [f"u_{n}" for n in self.input_names] or None)

    def grid(self, n_freq: int = 400) -> np.ndarray:
        """Frequencies (rad/s) for checks: up to Nyquist (discrete) or around the poles."""
        if self.dt is not None:
            wn = np.pi / self.dt
            return np.concatenate([[0.0], np.logspace(np.log10(wn) - 5, np.log10(wn), n_freq - 1)])
        lam = np.abs(np.concatenate([np.linalg.eigvals(self.A + self.B @ self.F),
                                     np.linalg.eigvals(self.A + self.L @ self.C)]))
        lam = lam[lam > 0]
        lo, hi = (lam.min(), lam.max()) if lam.size else (1.0, 1.0)
        return np.concatenate([[0.0], np.logspace(np.log10(lo) - 2, np.log10(hi) + 2, n_freq - 1)])

    def points(self, omega: np.ndarray) -> np.ndarray:
        """s = jω, or z = e^{jωT} in discrete time."""
        omega = np.asarray(omega, dtype=float)
        return 1j * omega if self.dt is None else np.exp(1j * omega * self.dt)

    def bezout_error(self, omega: np.ndarray | None = None) -> float:
        """Largest deviation of both products of Eq. 3 from I on a frequency grid.

        Each of the eight factors is evaluated on its own and assembled into
        L = [[Ṽ, −Ũ], [−Ñ, M̃]] and R = [[M, U], [N, V]]; the error is
        max_ω max(‖T⁻¹(LR − I)T‖₂, ‖T⁻¹(RL − I)T‖₂) with T = diag(I_m, y_s I_p), y_s the
        ``output_scale`` (units balanced so that a dimensionless 1e-9 means something).

        Parameters
        ----------
        omega : ndarray, optional
            Frequencies (rad/s); :meth:`grid` if omitted.

        Returns
        -------
        float
        """
        omega = self.grid() if omega is None else np.asarray(omega, dtype=float)
        pts = self.points(omega)

        def fr(sys):
            return _freqresp(np.asarray(sys.A), np.asarray(sys.B), np.asarray(sys.C),
                             np.asarray(sys.D), pts)

        Mf, Nf, Uf, Vf = fr(self.M()), fr(self.N()), fr(self.U()), fr(self.V())
        Vt, Ut, Nt, Mt = fr(self.V_tilde()), fr(self.U_tilde()), fr(self.N_tilde()), fr(self.M_tilde())
        Lm = np.concatenate([np.concatenate([Vt, -Ut], axis=2),
                             np.concatenate([-Nt, Mt], axis=2)], axis=1)
        Rm = np.concatenate([np.concatenate([Mf, Uf], axis=2),
                             np.concatenate([Nf, Vf], axis=2)], axis=1)
        ys = self.output_scale
        if ys <= 0:
            ys = float(np.max(np.linalg.norm(Nf, ord=2, axis=(1, 2)))) or 1.0
        m, p = self.n_inputs, self.n_outputs
        t = np.concatenate([np.ones(m), np.full(p, ys)])
        eye = np.eye(m + p)
        E1 = (Lm @ Rm - eye) * t[None, None, :] / t[None, :, None]
        E2 = (Rm @ Lm - eye) * t[None, None, :] / t[None, :, None]
        err = max(np.linalg.norm(E1, ord=2, axis=(1, 2)).max(),
                  np.linalg.norm(E2, ord=2, axis=(1, 2)).max())
        return float(err)

    def check_bezout(self, tol: float = 1e-9, omega: np.ndarray | None = None) -> float:
        """:meth:`bezout_error`, raising IdentificationError above ``tol``; see
        :func:`check_bezout`."""
        return check_bezout(self, tol=tol, omega=omega)

    def to_dict(self) -> dict:
        return {
            "type": "observer_coprime_factors",
            "dt": self.dt,
            "input_names": list(self.input_names),
            "output_names": list(self.output_names),
            "output_scale": self.output_scale,
            **{k: np.asarray(getattr(self, k)).tolist() for k in ("A", "B", "C", "D", "F", "L")},
        }


def check_bezout(cf: CoprimeFactors, *, tol: float = 1e-9,
                 omega: np.ndarray | None = None) -> float:
    """Check that the factors are doubly coprime (P1 Eq. 3) and stable.

    Returns
    -------
    float
        The balanced Bezout error of :meth:`CoprimeFactors.bezout_error`.

    Raises
    ------
    IdentificationError
        If A + BF or A + LC is not stable (the factors would not be in RH∞) or the error
        exceeds ``tol``.
    """
    if not _is_stable(cf.A + cf.B @ cf.F, cf.dt):
        raise IdentificationError("coprime factors: A + BF is not stable (M, N, U, V unstable)")
    if not _is_stable(cf.A + cf.L @ cf.C, cf.dt):
        raise IdentificationError("coprime factors: A + LC is not stable (M̃, Ñ, Ũ, Ṽ unstable)")
    err = cf.bezout_error(omega)
    if not np.isfinite(err) or err > tol:
        raise IdentificationError(
            f"coprime factors: double Bezout identity (P1 Eq. 3) violated, "
            f"error {err:.3g} > tol {tol:.3g}")
    return err


def coprime_factors(A, B, C, D, F, L, *, dt: float | None = None,
                    input_names: Sequence[str] = (), output_names: Sequence[str] = (),
                    output_scale: float = 0.0, check: bool = True,
                    tol: float = 1e-9) -> CoprimeFactors:
    """Observer-based doubly coprime factors from a realisation and gains F, L.

    Parameters
    ----------
    A, B, C, D : array_like, shapes (n, n), (n, m), (p, n), (p, m)
        Nominal plant.
    F : array_like, shape (m, n)
    L : array_like, shape (n, p)
    dt : float, optional
        Sample period (s) if the realisation is discrete.
    input_names, output_names : sequence of str
    output_scale : float
        See :class:`CoprimeFactors`.
    check : bool
        Run :func:`check_bezout` with ``tol``.

    Returns
    -------
    CoprimeFactors

    Raises
    ------
    IdentificationError
        Shapes inconsistent, or (with ``check``) the factors fail :func:`check_bezout`.
    """
    A, B, C, D, F, L = (np.atleast_2d(np.asarray(x, dtype=float)) for x in (A, B, C, D, F, L))
    n, m = B.shape
    p = C.shape[0]
    want = {"A": (A, (n, n)), "C": (C, (p, n)), "D": (D, (p, m)), "F": (F, (m, n)),
            "L": (L, (n, p))}
    for k, (arr, shape) in want.items():
        got = arr.shape
        if got != shape:
            raise IdentificationError(f"coprime_factors: {k} has shape {got}, expected {shape}")
    cf = CoprimeFactors(A, B, C, D, F, L, dt, tuple(input_names), tuple(output_names),
                        float(output_scale))
    if check:
        check_bezout(cf, tol=tol)
    return cf


def youla_factorisation(
    plant: Plant,
    *,
    dt: float | None = None,
    F: np.ndarray | None = None,
    L: np.ndarray | None = None,
    output_scale: float = 1e-5,
    input_scale: float = 1.0,
    control_weight: float = 1.0,
    noise_ratio: float = 1.0,
    stability_degree: float = 0.0,
    tol: float = 1e-9,
) -> CoprimeFactors:
    """Coprime factors of a :class:`~ambseal.model.lft.Plant` at its nominal parameters.

    With ``dt`` the plant is sampled with a zero-order hold (the DAC of a digital controller)
    and the factors are discrete. Missing gains come from :func:`observer_gains`.

    Parameters
    ----------
    plant : Plant
        Nominal plant G(0): inputs currents (A), outputs displacements (m).
    dt : float, optional
        Sample period (s), e.g. 1e-3 for P1's 1 kHz.
    F, L : ndarray, optional
        Gains (m, n), (n, p) for the (sampled) realisation; designed if omitted.
    output_scale, input_scale, control_weight, noise_ratio, stability_degree : float
        Passed to :func:`observer_gains`; ``output_scale/input_scale`` also balances the
        Bezout check.
    tol : float
        Bezout tolerance of :func:`check_bezout`.

    Returns
    -------
    CoprimeFactors

    Raises
    ------
    IdentificationError
        No stabilising gains, or the Bezout check fails.
    """
    A, B, C, D = plant.A, plant.B, plant.C, plant.D
    if dt is not None:
        if not dt > 0:
            raise IdentificationError(f"youla_factorisation: dt must be > 0, got {dt}")
        A, B = zoh(A, B, dt)
    if F is None or L is None:
        F0, L0 = observer_gains(A, B, C, dt=dt, output_scale=output_scale,
                                input_scale=input_scale, control_weight=control_weight,
                                noise_ratio=noise_ratio, stability_degree=stability_degree)
        F = F0 if F is None else F
        L = L0 if L is None else L
    return coprime_factors(A, B, C, D, F, L, dt=dt, input_names=plant.input_names,
                           output_names=plant.output_names,
                           output_scale=output_scale / input_scale, tol=tol)


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
    max_nfev: int = 200,
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
    max_nfev : int
        Function evaluations allowed.

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
        sol = least_squares(residuals, x0, bounds=bounds, x_scale=1.0, method="trf",
                            max_nfev=max_nfev, xtol=1e-12, ftol=1e-12, gtol=1e-12)
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
