"""Controller reconstruction of the gridded LPV synthesis (:func:`ambseal.robust.lpv.lpvsyn`).

From the LMI solution R, S(θ) (:mod:`ambseal.robust._lpv_lmi`) the controller is rebuilt at
each θ of a table ``check_density`` times denser than the synthesis grid, with the
linearising change of variables of Scherer, Gahinet & Chilali (1997) (D_K = 0, M = I,
N = I − S R), all of it in closed form (:class:`_Reconstructor`); between table points the
plant's A(θ) is interpolated by :func:`interp_A`.
"""

from __future__ import annotations

import time

import numpy as np

from ambseal.errors import SynthesisError
from ambseal.robust._lpv_lmi import BASES, Scaled, SolverReport, _sym, basis

__all__ = ["interp_A", "reconstruct_table"]


def reconstruct_table(sc: Scaled, blocks, table: np.ndarray, A_of, R: np.ndarray, S: list,
                      lyapunov: str, nu_s: float, gamma: float, margin: float):
    """Physical-time controller matrices at each table point θ (synthesis units).

    Parameters
    ----------
    sc : Scaled
        The scaled plant grid.
    blocks : tuple of ndarray
        ``(B1, B2, C1, C2, D11, D12, D21)`` of the scaled plant.
    table : ndarray, shape (n_t,)
        Table values of θ (θ's unit).
    A_of : callable
        θ → A(θ) of the (unscaled) generalised plant (:func:`interp_A`).
    R, S : ndarray and list of ndarray
        LMI solution (:func:`ambseal.robust._lpv_lmi.solve_lmis`).
    lyapunov : str
    nu_s : float
        Rate bound in scaled units.
    gamma : float
        γ of the reconstruction LMIs (a little above the design γ).
    margin : float
        The reconstruction LMIs hold at a table point when their residuals are below −margin.

    Returns
    -------
    AK, BK, CK, DK : ndarray, shapes (n_t, n, n), (n_t, n, ny), (n_t, nu, n), (n_t, nu, ny)
        ``u = K(θ) y`` in the generalised plant's units (positive feedback).
    report : SolverReport
        Stage ``"reconstruct"``, solver ``"closed form"``; status ``"optimal"`` when the
        reconstruction LMIs hold at every table point, else at how many they hold.

    Raises
    ------
    SynthesisError
        ‖D11‖ ≥ γ, or I − S R singular.
    """
    B1, B2, C1, C2, D11, D12, D21 = blocks
    nb = BASES[lyapunov]
    ncon, nmeas = B2.shape[1], C2.shape[0]
    AKs, BKs, CKs, DKs = [], [], [], []
    n_held, t_rec = 0, time.perf_counter()
    rec = _Reconstructor(B1, B2, C1, C2, D11, D12, D21, R, gamma, margin,
                         2 if (nb > 1 and nu_s > 0) else 1)
    for th in table:
        A_s = sc.to_scaled_A(A_of(th))
        p = float(sc.p_of(th))
        f, df = basis(lyapunov, p)
        Sw = sum(fi * Si for fi, Si in zip(f, S))
        dS = sum(dfi * Si for dfi, Si in zip(df, S)) if nb > 1 else None
        Ak, Bk, Ck, held = rec(A_s, Sw, dS, nu_s)
        n_held += held
        # undo the scalings: ũ = K̃ ỹ with u = su ũ, ỹ = sy y; time scale ω₀
        AKs.append(sc.w0 * Ak)
        BKs.append(np.sqrt(sc.w0) * Bk * sc.sy[None, :])
        CKs.append(np.sqrt(sc.w0) * sc.su[:, None] * Ck)
        DKs.append(np.zeros((ncon, nmeas)))
    status = ("optimal" if n_held == len(table)
              else f"LMIs hold at {n_held} of {len(table)} table points")
    report = SolverReport("reconstruct", status, 0, time.perf_counter() - t_rec, "closed form")
    return np.array(AKs), np.array(BKs), np.array(CKs), np.array(DKs), report


def interp_A(As, dAs, grid):
    """A(θ) between grid points: cubic Hermite with the given slopes (exact for affine A)."""
    def f(th: float) -> np.ndarray:
        j = int(np.clip(np.searchsorted(grid, th) - 1, 0, len(grid) - 2))
        h = grid[j + 1] - grid[j]
        t = (th - grid[j]) / h
        if t <= 1e-12:
            return As[j]
        if t >= 1 - 1e-12:
            return As[j + 1]
        h00, h10 = 2 * t**3 - 3 * t**2 + 1, t**3 - 2 * t**2 + t
        h01, h11 = -2 * t**3 + 3 * t**2, t**3 - t**2
        lin = (1 - t) * As[j] + t * As[j + 1]
        herm = h00 * As[j] + h10 * h * dAs[j] + h01 * As[j + 1] + h11 * h * dAs[j + 1]
        # piecewise-linear tables make the Hermite overshoot at kinks: use it only when the
        # end slopes agree with the chord (smooth data), else the linear interpolant
        chord = (As[j + 1] - As[j]) / h
        ok = (np.linalg.norm(dAs[j] - chord) + np.linalg.norm(dAs[j + 1] - chord)
              <= 1e-6 * max(np.linalg.norm(chord), 1e-300))
        return herm if ok else lin
    return f


class _Reconstructor:
    """Controller at one θ from R, S(θ) (Scherer, Gahinet & Chilali 1997; D_K = 0,
    M = I, N = I − S R), with Â eliminated and Ĉ, B̂ in closed form.

    The linearised closed-loop bounded-real LMI in (Â, B̂, Ĉ) has rows [x_R; x_S; w; z];
    Â enters only its (x_S, x_R) block, as Â + Aᵀ. With the rows split as 1 = x_R,
    2 = x_S, 3 = (w, z), choosing ``Â + Aᵀ = P23 P33⁻¹ P13ᵀ`` makes the Schur complement
    with respect to P33 ≺ 0 block diagonal, so the LMI holds iff the two small LMIs in
    rows {1, 3} (Ĉ: a state-feedback H∞ LMI with R fixed) and rows {2, 3} (B̂: the
    filter LMI with S(θ) fixed, for Ṡ = ±ν ∂S/∂θ) hold — the feasibility of which is
    what the projected LMIs guarantee (Gahinet & Apkarian 1994, elimination lemma).

    With D_K = 0 both are quadratic in their unknown with a positive definite leading
    term, so completing the square solves them. Ĉ-side, after the Schur complements of the
    constant w and z rows (Φ = γI − D11 D11ᵀ/γ, E = C1 R + D11 B1ᵀ/γ)::

        L(Ĉ) = L0 + G Ĉ + Ĉᵀ Gᵀ + Ĉᵀ H Ĉ ≺ 0,   H = D12ᵀ Φ⁻¹ D12,   G = B2 + Eᵀ Φ⁻¹ D12,
        L(Ĉ) = L0 − G H⁻¹ Gᵀ + (Ĉ − Ĉ*)ᵀ H (Ĉ − Ĉ*),   Ĉ* = −H⁻¹ Gᵀ,

    so Ĉ* makes L smallest (in the semidefinite order): it is feasible iff any Ĉ is. It is
    the LMI counterpart of the central H∞ state feedback −(D12ᵀD12)⁻¹(B2ᵀX + D12ᵀC1)
    (Doyle, Glover, Khargonekar & Francis 1989), and with R constant it does not depend on
    θ. The B̂-side is the dual (Ψ = γI − D11ᵀD11/γ, F = S B1 + C1ᵀ D11/γ):
    B̂* = −(C2ᵀ + F Ψ⁻¹ D21ᵀ)(D21 Ψ⁻¹ D21ᵀ)⁻¹, the same for both signs of Ṡ, which
    enter only L0. Between synthesis grid points the projected LMIs (quadratic in p with a
    parameter-dependent S) need not hold; there the central solutions are still the best in
    the semidefinite order, and the frozen loops are checked on the table by
    :func:`ambseal.robust.lpv.lpvsyn` as everywhere else, so a violated residual is
    counted (the report's status), not refused: solving the reconstruction LMIs as SDPs
    instead (2 per table point, ≈ 1.5 s each on a 32-state plant) refuses such points as
    "infeasible".
    """

    def __init__(self, B1, B2, C1, C2, D11, D12, D21, R, gamma, margin, n_signs):
        nw, nz = B1.shape[1], C1.shape[0]
        g = float(gamma)
        self.B1, self.B2, self.C1, self.C2 = B1, B2, C1, C2
        self.D12, self.D21, self.R, self.g = D12, D21, R, g
        self.n_signs, self.margin = n_signs, margin
        self.P33 = np.block([[-g * np.eye(nw), D11.T], [D11, -g * np.eye(nz)]])
        Phi = g * np.eye(nz) - D11 @ D11.T / g
        Psi = g * np.eye(nw) - D11.T @ D11 / g
        if min(np.linalg.eigvalsh(Phi).min(), np.linalg.eigvalsh(Psi).min()) <= 0:
            raise SynthesisError("lpvsyn (reconstruct): ‖D11‖ ≥ γ; no controller reaches "
                                 "this γ")
        self.Phi_i, self.Psi_i = np.linalg.inv(Phi), np.linalg.inv(Psi)
        self.F_c = C1.T @ D11 / g
        E = C1 @ R + D11 @ B1.T / g
        H = D12.T @ self.Phi_i @ D12
        G = B2 + E.T @ self.Phi_i @ D12
        self.Ch = -np.linalg.solve(H, G.T)
        #: L0 − G H⁻¹ Gᵀ without the θ-dependent A R + R Aᵀ
        self.QC = B1 @ B1.T / g + E.T @ self.Phi_i @ E - G @ np.linalg.solve(H, G.T)
        self.H2 = D21 @ self.Psi_i @ D21.T

    def _holds(self, Q: np.ndarray) -> bool:
        return bool(np.linalg.eigvalsh(_sym(Q)).max() < -self.margin)

    def __call__(self, A, S, dS, nu_s):
        """(A_K, B_K, C_K, whether both LMIs hold) at one θ (scaled units)."""
        R, B1, B2, C1, C2, D21 = self.R, self.B1, self.B2, self.C1, self.C2, self.D21
        N = A.shape[0]
        holds = self._holds(A @ R + R @ A.T + self.QC)
        F = S @ B1 + self.F_c
        G2 = C2.T + F @ self.Psi_i @ D21.T
        Bhv = -np.linalg.solve(self.H2, G2.T).T
        base = S @ A + A.T @ S + C1.T @ C1 / self.g + F @ self.Psi_i @ F.T \
            - G2 @ np.linalg.solve(self.H2, G2.T)
        sgns = (1.0, -1.0) if self.n_signs == 2 else (0.0,)
        holds &= all(self._holds(base + (sgn * nu_s * dS if sgn else 0.0)) for sgn in sgns)
        Chv = self.Ch
        P13 = np.hstack([B1, (C1 @ R + self.D12 @ Chv).T])
        P23 = np.hstack([S @ B1 + Bhv @ D21, C1.T])
        Ahv = -A.T + P23 @ np.linalg.solve(self.P33, P13.T)
        Nm = np.eye(N) - S @ R
        if np.linalg.cond(Nm) > 1e12:
            raise SynthesisError("lpvsyn (reconstruct): I − S R is singular; raise the "
                                 "back-off")
        BK = np.linalg.solve(Nm, Bhv)
        CK = Chv
        AK = np.linalg.solve(Nm, Ahv - Bhv @ C2 @ R - S @ B2 @ Chv - S @ A @ R)
        return AK, BK, CK, holds
