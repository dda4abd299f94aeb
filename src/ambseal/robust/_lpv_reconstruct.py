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
from ambseal.robust._lpv_lmi import Scaled, SolverReport, _sym, basis_at

__all__ = ["interp_A", "reconstruct_table"]


def reconstruct_table(sc: Scaled, blocks, table: np.ndarray, A_of, R: list, S: list,
                      lyapunov, nu_s: float, gamma: float, margin: float,
                      lyapunov_r="constant"):
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
    R, S : list of ndarray
        LMI solution: the coefficients of R(θ) and S(θ)
        (:func:`ambseal.robust._lpv_lmi.solve_lmis`).
    lyapunov, lyapunov_r : str or callable
        The bases of S(θ) and R(θ).
    nu_s : float
        Rate bound in scaled units.
    gamma : float
        γ of the reconstruction LMIs (a little above the design γ).
    margin : float
        The reconstruction LMIs hold at a table point when their residuals are below −margin.

    Returns
    -------
    AK, AK_rate, BK, CK, DK : ndarray
        Shapes (n_t, n, n), (n_t, n, n), (n_t, n, ny), (n_t, nu, n), (n_t, nu, ny):
        ``u = K(θ, θ̇) y`` in the generalised plant's units (positive feedback) with
        A_K(θ, θ̇) = AK(θ) + θ̇·AK_rate(θ) (θ̇ in θ's unit per second; AK_rate = 0 when R
        is constant).
    report : SolverReport
        Stage ``"reconstruct"``, solver ``"closed form"``; status ``"optimal"`` when the
        reconstruction LMIs hold at every table point, else at how many they hold.

    Raises
    ------
    SynthesisError
        ‖D11‖ ≥ γ, or I − S R singular.
    """
    ncon, nmeas = blocks[1].shape[1], blocks[3].shape[0]
    out = {k: [] for k in ("AK", "AK_rate", "BK", "CK")}
    n_held, t_rec = 0, time.perf_counter()
    rec = _Reconstructor(*blocks, gamma, margin)
    for th in table:
        A_s = sc.to_scaled_A(A_of(th))
        (g, dg), (f, df) = basis_at(lyapunov_r, th, sc), basis_at(lyapunov, th, sc)
        Rw = sum(gi * Ri for gi, Ri in zip(g, R))
        dR = sum(dgi * Ri for dgi, Ri in zip(dg, R))
        Sw = sum(fi * Si for fi, Si in zip(f, S))
        dS = sum(dfi * Si for dfi, Si in zip(df, S))
        Ak, Ak_rate, Bk, Ck, held = rec(A_s, Rw, dR, Sw, dS, nu_s)
        n_held += held
        # undo the scalings: ũ = K̃ ỹ with u = su ũ, ỹ = sy y; time scale ω₀ (the rate
        # term is per dp/dt' = θ̇·dp/dθ/ω₀, so per θ̇ it carries dp/dθ only)
        out["AK"].append(sc.w0 * Ak)
        out["AK_rate"].append(sc.dp_dtheta * Ak_rate)
        out["BK"].append(np.sqrt(sc.w0) * Bk * sc.sy[None, :])
        out["CK"].append(np.sqrt(sc.w0) * sc.su[:, None] * Ck)
    status = ("optimal" if n_held == len(table)
              else f"LMIs hold at {n_held} of {len(table)} table points")
    report = SolverReport("reconstruct", status, 0, time.perf_counter() - t_rec, "closed form")
    DK = np.zeros((len(table), ncon, nmeas))
    return (*(np.array(out[k]) for k in ("AK", "AK_rate", "BK", "CK")), DK, report)


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
    """Controller at one θ from R(θ), S(θ) (Scherer, Gahinet & Chilali 1997; D_K = 0,
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
    (Doyle, Glover, Khargonekar & Francis 1989). The B̂-side is the dual
    (Ψ = γI − D11ᵀD11/γ, F = S B1 + C1ᵀ D11/γ):
    B̂* = −(C2ᵀ + F Ψ⁻¹ D21ᵀ)(D21 Ψ⁻¹ D21ᵀ)⁻¹. The rates −Ṙ and +Ṡ enter only the
    L0 of their side, so Ĉ* and B̂* are the same for both signs of θ̇.

    A parameter-dependent R adds −(S Ṙ + N Ṁᵀ) = −S Ṙ (M = I) to the (x_S, x_R) block
    (the derivative of the congruence [R I; Mᵀ 0] of the closed-loop Lyapunov matrix;
    Apkarian & Adams 1998 §3.2), which Â absorbs: Â = Â_frozen + S Ṙ, so
    A_K = A_K(θ) + θ̇ N⁻¹ S ∂R/∂θ — the controller takes θ̇ (as Wu et al. 1996's and
    LPVTools'); with R constant it does not.

    Between synthesis grid points the projected LMIs (quadratic in p with a
    parameter-dependent S) need not hold; there the central solutions are still the best in
    the semidefinite order, and the frozen loops are checked on the table by
    :func:`ambseal.robust.lpv.lpvsyn` as everywhere else, so a violated residual is
    counted (the report's status), not refused.
    """

    def __init__(self, B1, B2, C1, C2, D11, D12, D21, gamma, margin):
        nw, nz = B1.shape[1], C1.shape[0]
        g = float(gamma)
        self.B1, self.B2, self.C1, self.C2 = B1, B2, C1, C2
        self.D11, self.D12, self.D21, self.g = D11, D12, D21, g
        self.margin = margin
        self.P33 = np.block([[-g * np.eye(nw), D11.T], [D11, -g * np.eye(nz)]])
        Phi = g * np.eye(nz) - D11 @ D11.T / g
        Psi = g * np.eye(nw) - D11.T @ D11 / g
        if min(np.linalg.eigvalsh(Phi).min(), np.linalg.eigvalsh(Psi).min()) <= 0:
            raise SynthesisError("lpvsyn (reconstruct): ‖D11‖ ≥ γ; no controller reaches "
                                 "this γ")
        self.Phi_i, self.Psi_i = np.linalg.inv(Phi), np.linalg.inv(Psi)
        self.F_c = C1.T @ D11 / g
        self.H = D12.T @ self.Phi_i @ D12
        self.H2 = D21 @ self.Psi_i @ D21.T

    def _holds(self, Q: np.ndarray) -> bool:
        return bool(np.linalg.eigvalsh(_sym(Q)).max() < -self.margin)

    def c_side(self, R):
        """(Ĉ*, L0 − G H⁻¹ Gᵀ without the θ-dependent A R + R Aᵀ) for R."""
        E = self.C1 @ R + self.D11 @ self.B1.T / self.g
        G = self.B2 + E.T @ self.Phi_i @ self.D12
        Ch = -np.linalg.solve(self.H, G.T)
        return Ch, self.B1 @ self.B1.T / self.g + E.T @ self.Phi_i @ E + G @ Ch

    def __call__(self, A, R, dR, S, dS, nu_s):
        """(A_K, A_K per dp/dt', B_K, C_K, whether both LMIs hold) at one θ (scaled
        units)."""
        B1, B2, C1, C2, D21 = self.B1, self.B2, self.C1, self.C2, self.D21
        N = A.shape[0]
        Chv, QC = self.c_side(R)
        base_c = A @ R + R @ A.T + QC
        F = S @ B1 + self.F_c
        G2 = C2.T + F @ self.Psi_i @ D21.T
        Bhv = -np.linalg.solve(self.H2, G2.T).T
        base_b = S @ A + A.T @ S + C1.T @ C1 / self.g + F @ self.Psi_i @ F.T \
            - G2 @ np.linalg.solve(self.H2, G2.T)
        holds = all(self._holds(base_c - sgn * nu_s * dR) and
                    self._holds(base_b + sgn * nu_s * dS) for sgn in (1.0, -1.0))
        P13 = np.hstack([B1, (C1 @ R + self.D12 @ Chv).T])
        P23 = np.hstack([S @ B1 + Bhv @ D21, C1.T])
        Ahv = -A.T + P23 @ np.linalg.solve(self.P33, P13.T)
        Nm = np.eye(N) - S @ R
        if np.linalg.cond(Nm) > 1e12:
            raise SynthesisError("lpvsyn (reconstruct): I − S R is singular; raise the "
                                 "back-off")
        BK = np.linalg.solve(Nm, Bhv)
        AK = np.linalg.solve(Nm, Ahv - Bhv @ C2 @ R - S @ B2 @ Chv - S @ A @ R)
        AK_rate = np.linalg.solve(Nm, S @ dR)
        return AK, AK_rate, BK, Chv, holds
