"""Doubly coprime factorisations of a plant and its observer-based controller (thesis P1 Eqs. 1–3).

Observer based (Zhou, Doyle & Glover 1996, Thm 5.9): with F and L such that A + BF and
A + LC are stable,

    [[M, U], [N, V]]     = [A+BF | B, −L;  F | I, 0;  C+DF | D, I]
    [[Ṽ, −Ũ], [−Ñ, M̃]] = [A+LC | −(B+LD), L;  F | I, 0;  C | −D, I],

G = N M⁻¹ = M̃⁻¹ Ñ, K = U V⁻¹ = Ṽ⁻¹ Ũ, and the double Bezout identity is checked
numerically. Used by the Youla (Hansen) identification scheme of :mod:`ambseal.identify.fitting.youla`.

Example
-------
>>> import numpy as np
>>> from ambseal.identify.fitting.coprime import coprime_factors, observer_gains
>>> A = np.array([[0.0, 1.0], [100.0, 0.0]]); B = np.array([[0.0], [1.0]])
>>> C = np.array([[1.0, 0.0]]); D = np.zeros((1, 1))
>>> F, L = observer_gains(A, B, C)
>>> cf = coprime_factors(A, B, C, D, F, L)
>>> cf.check_bezout() < 1e-9
True
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Sequence

import control
import numpy as np
import scipy.linalg as sla

from ambseal.errors import DataError, IdentificationError
from ambseal.lti import freqresp_at, zoh
from ambseal.model import Plant
from ambseal.robust import is_stable

__all__ = ["CoprimeFactors", "observer_gains", "coprime_factors", "youla_factorisation",
           "check_bezout"]


# --------------------------------------------------------------------------- helpers
def _ss(A, B, C, D, dt, inputs=None, outputs=None):
    kw = {}
    if inputs is not None:
        kw["inputs"] = list(inputs)
    if outputs is not None:
        kw["outputs"] = list(outputs)
    return control.ss(A, B, C, D, 0 if dt is None else dt, **kw)


def _is_stable(A: np.ndarray, dt: float | None) -> bool:
    """All eigenvalues of ``A`` stable (continuous for ``dt`` None, else discrete), by the
    package's one rule (:func:`ambseal.robust.stability.is_stable`)."""
    return is_stable(np.linalg.eigvals(A) if A.size else np.zeros(0), dt or 0.0)


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
        Size of a typical output relative to a typical input (y_s/u_s, e.g. m/A), which
        balances the units in :meth:`bezout_error`; the peak gain of N if 0.
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
            (as :func:`ambseal.design.pid.pid_controller`), i.e. −K.

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
            return freqresp_at(sys, pts, method="hessenberg")  # accurate to rounding

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
        State-feedback gain with A + BF stable (e.g. :func:`observer_gains`).
    L : array_like, shape (n, p)
        Observer gain with A + LC stable.
    dt : float, optional
        Sample period (s) if the realisation is discrete.
    input_names, output_names : sequence of str
        Names of u (m) and y (p).
    output_scale : float
        See :class:`CoprimeFactors`.
    check : bool
        Run :func:`check_bezout` with ``tol``.
    tol : float
        Largest accepted balanced Bezout error (with ``check``).

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
