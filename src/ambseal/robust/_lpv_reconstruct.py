"""Controller reconstruction of the gridded LPV synthesis (:func:`ambseal.robust.lpv.lpvsyn`).

From the LMI solution R, S(Ω) (:mod:`ambseal.robust._lpv_lmi`) the controller is rebuilt at
each speed of a table ``check_density`` times denser than the design grid, with the
linearising change of variables of Scherer, Gahinet & Chilali (1997) (D_K = 0, M = I,
N = I − S R) and Â
eliminated in closed form (:class:`_Reconstructor`); between table speeds the plant's A(Ω)
is interpolated by :func:`interp_A`.
"""

from __future__ import annotations

import time

import cvxpy as cp
import numpy as np

from ambseal.errors import SynthesisError
from ambseal.robust._lpv_lmi import (
    BASES,
    Scaled,
    SolverReport,
    _check_status,
    _solve_quiet,
    _sym,
    _sym_expr,
    basis,
)

__all__ = ["interp_A", "reconstruct_table"]


def reconstruct_table(sc: Scaled, blocks, table: np.ndarray, A_of, R: np.ndarray, S: list,
                      lyapunov: str, nu_s: float, gamma: float, margin: float,
                      solver_options: dict):
    """Physical-time controller matrices at each table speed (synthesis units).

    Parameters
    ----------
    sc : Scaled
        The scaled plant grid.
    blocks : tuple of ndarray
        ``(B1, B2, C1, C2, D11, D12, D21)`` of the scaled plant.
    table : ndarray, shape (n_t,)
        Speeds Ω (rad/s).
    A_of : callable
        Ω → A(Ω) of the (unscaled) generalised plant (:func:`interp_A`).
    R, S : ndarray and list of ndarray
        LMI solution (:func:`ambseal.robust._lpv_lmi.solve_lmis`).
    lyapunov : str
    nu_s : float
        Rate bound in scaled units.
    gamma : float
        γ of the reconstruction LMIs (a little above the design γ).
    margin : float
    solver_options : dict

    Returns
    -------
    AK, BK, CK, DK : ndarray, shapes (n_t, n, n), (n_t, n, ny), (n_t, nu, n), (n_t, nu, ny)
        ``u = K(Ω) y`` in the generalised plant's units (positive feedback).
    report : SolverReport
        Stage ``"reconstruct"``, iterations summed over the table.

    Raises
    ------
    SynthesisError
        A reconstruction SDP not ``optimal``, or I − S R singular.
    """
    B1, B2, C1, C2, D11, D12, D21 = blocks
    nb = BASES[lyapunov]
    ncon, nmeas = B2.shape[1], C2.shape[0]
    AKs, BKs, CKs, DKs = [], [], [], []
    it_sum, t_rec, status = 0, time.perf_counter(), "optimal"
    rec = _Reconstructor(B1, B2, C1, C2, D11, D12, D21, R, gamma, margin,
                         2 if (nb > 1 and nu_s > 0) else 1, solver_options)
    for W in table:
        A_s = sc.to_scaled_A(A_of(W))
        p = float(sc.p_of(W))
        f, df = basis(lyapunov, p)
        Sw = sum(fi * Si for fi, Si in zip(f, S))
        dS = sum(dfi * Si for dfi, Si in zip(df, S)) if nb > 1 else None
        Ak, Bk, Ck, it = rec(A_s, Sw, dS, nu_s)
        it_sum += it
        # undo the scalings: ũ = K̃ ỹ with u = su ũ, ỹ = sy y; time scale ω₀
        AKs.append(sc.w0 * Ak)
        BKs.append(np.sqrt(sc.w0) * Bk * sc.sy[None, :])
        CKs.append(np.sqrt(sc.w0) * sc.su[:, None] * Ck)
        DKs.append(np.zeros((ncon, nmeas)))
    report = SolverReport("reconstruct", status, it_sum, time.perf_counter() - t_rec)
    return np.array(AKs), np.array(BKs), np.array(CKs), np.array(DKs), report


def interp_A(As, dAs, grid):
    """A(Ω) between grid points: cubic Hermite with the given slopes (exact for affine A)."""
    def f(W: float) -> np.ndarray:
        j = int(np.clip(np.searchsorted(grid, W) - 1, 0, len(grid) - 2))
        h = grid[j + 1] - grid[j]
        t = (W - grid[j]) / h
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
    """Controller at one speed from R, S(Ω) (Scherer, Gahinet & Chilali 1997; D_K = 0,
    M = I, N = I − S R), with Â eliminated in closed form.

    The linearised closed-loop bounded-real LMI in (Â, B̂, Ĉ) has rows [x_R; x_S; w; z];
    Â enters only its (x_S, x_R) block, as Â + Aᵀ. With the rows split as 1 = x_R,
    2 = x_S, 3 = (w, z), choosing ``Â + Aᵀ = P23 P33⁻¹ P13ᵀ`` makes the Schur complement
    with respect to P33 ≺ 0 block diagonal, so the LMI holds iff the two small LMIs in
    rows {1, 3} (Ĉ: a state-feedback H∞ LMI with R fixed) and rows {2, 3} (B̂: the
    filter LMI with S(Ω) fixed, for Ṡ = ±ν ∂S/∂Ω) hold — the feasibility of which is what
    the projected LMIs guarantee (Gahinet & Apkarian 1994, elimination lemma). Two SDPs of
    size N + n_w + n_z with N·n_u and N·n_y unknowns replace one of size 2N + n_w + n_z
    with N² more unknowns; and since the w row of the first and the z row of the second
    are constant, their Schur complements (−γI ≺ 0) are taken in closed form, leaving
    exactly equivalent LMIs of size N + n_z and N + n_w (a PSD cone of 406 instead of 666
    entries on the turboexpander: ~3× faster interior-point steps).

    Each minimises the Frobenius norm of its unknown (moderate controller gains) as a
    second-order cone, ‖·‖_F, not as its square: with a dynamic (high-pass) W_u the scaled
    D12 is small (≈ 0.01 of B2, whose weight-state rows carry the control) and the
    minimum-norm Ĉ is ~1e5, so ‖Ĉ‖²_F ~ 1e10 — Clarabel then stops with a false
    "infeasible" certificate although the LMI is feasible (the elimination lemma guarantees
    it; with ‖Ĉ‖_F as objective the same LMI solves "optimal", same minimiser).

    The two SDPs are built once, with the speed-dependent data (A R + R Aᵀ, S A + Aᵀ S
    ± ν ∂S/∂Ω, S B1) as cvxpy parameters entering affinely (DPP): each table speed then
    only re-solves, without re-compiling (the compilation was ~¾ of the reconstruction).
    """

    def __init__(self, B1, B2, C1, C2, D11, D12, D21, R, gamma, margin, n_signs,
                 solver_options):

        N = B1.shape[0]
        nw, nz = B1.shape[1], C1.shape[0]
        nu, ny = B2.shape[1], C2.shape[0]
        self.B1, self.B2, self.C1, self.C2 = B1, B2, C1, C2
        self.D11, self.D12, self.D21, self.R = D11, D12, D21, R
        self.n_signs, self.solver_options = n_signs, solver_options
        self.P33 = np.block([[-gamma * np.eye(nw), D11.T], [D11, -gamma * np.eye(nz)]])
        # Ĉ: rows {x_R, w, z}
        self.AR = cp.Parameter((N, N), symmetric=True)
        self.Ch = cp.Variable((nu, N))
        CR = C1 @ R + D12 @ self.Ch
        g = float(gamma)
        # the w row is free of Ĉ: its Schur complement (−γI ≺ 0) is taken in closed form
        M1 = cp.bmat([[self.AR + B2 @ self.Ch + self.Ch.T @ B2.T + B1 @ B1.T / g,
                       CR.T + B1 @ D11.T / g],
                      [CR + D11 @ B1.T / g, -g * np.eye(nz) + D11 @ D11.T / g]])
        self.p1 = cp.Problem(cp.Minimize(cp.norm(self.Ch, "fro")),
                             [_sym_expr(M1) << -margin * np.eye(M1.shape[0])])
        # B̂: rows {x_S, w, z}, for Ṡ = ±ν ∂S/∂Ω
        self.S22 = [cp.Parameter((N, N), symmetric=True) for _ in range(n_signs)]
        self.SB1 = cp.Parameter((N, nw))
        self.Bh = cp.Variable((N, ny))
        SB = self.SB1 + self.Bh @ D21
        cons = []
        for P in self.S22:  # the z row is free of B̂: Schur complement in closed form
            M2 = cp.bmat([[P + self.Bh @ C2 + C2.T @ self.Bh.T + C1.T @ C1 / g,
                           SB + C1.T @ D11 / g],
                          [SB.T + D11.T @ C1 / g, -g * np.eye(nw) + D11.T @ D11 / g]])
            cons.append(_sym_expr(M2) << -margin * np.eye(M2.shape[0]))
        self.p2 = cp.Problem(cp.Minimize(cp.norm(self.Bh, "fro")), cons)

    def __call__(self, A, S, dS, nu_s):
        """(A_K, B_K, C_K, interior-point iterations) at one speed (scaled units)."""
        R, B1, B2, C1, C2, D12, D21 = (self.R, self.B1, self.B2, self.C1, self.C2,
                                       self.D12, self.D21)
        N = A.shape[0]
        its = 0
        self.AR.value = _sym(A @ R + R @ A.T)
        t0 = time.perf_counter()
        _solve_quiet(self.p1, "reconstruct", self.solver_options)
        its += _check_status(self.p1, "reconstruct", t0).iterations
        base = S @ A + A.T @ S
        sgns = (1.0, -1.0) if self.n_signs == 2 else (0.0,)
        for P, sgn in zip(self.S22, sgns):
            P.value = _sym(base + (sgn * nu_s * dS if sgn else 0.0))
        self.SB1.value = S @ B1
        t0 = time.perf_counter()
        _solve_quiet(self.p2, "reconstruct", self.solver_options)
        its += _check_status(self.p2, "reconstruct", t0).iterations
        Chv, Bhv = np.asarray(self.Ch.value), np.asarray(self.Bh.value)
        P13 = np.hstack([B1, (C1 @ R + D12 @ Chv).T])
        P23 = np.hstack([S @ B1 + Bhv @ D21, C1.T])
        Ahv = -A.T + P23 @ np.linalg.solve(self.P33, P13.T)
        Nm = np.eye(N) - S @ R
        if np.linalg.cond(Nm) > 1e12:
            raise SynthesisError("lpvsyn (reconstruct): I − S R is singular; raise the "
                                 "back-off")
        BK = np.linalg.solve(Nm, Bhv)
        CK = Chv
        AK = np.linalg.solve(Nm, Ahv - Bhv @ C2 @ R - S @ B2 @ Chv - S @ A @ R)
        return AK, BK, CK, its

