"""Output-error fit of physical parameters in closed loop (thesis P2 Eqs. 9–10, P4 Eq. 14).

θ is any subset of the model's named parameters — Ki and Ks per axis, the coupling
stiffness per axis, a seal's K, k, C, c — and ``tau_e``, the eddy-current lag of P2 §4.
The cost J(θ) = ‖y_meas − y(θ)‖² runs over the displacements (each channel scaled by its
standard deviation), optionally with the coil currents weighted in (P4 §3.4 suggests this
lowers the Ki–Ks correlation), and is minimised by ``scipy.optimize.least_squares`` within
bounds.

The model is the reduced plant with the parameters entering through its LFT channels
(A + B_θ θ C_θ, no rebuild per iteration), the amplifier and the τ_e lag in series, exactly
discretised with a zero-order hold at the data's sample rate and closed with the digital
controller that ran (:mod:`ambseal.identify.loop`).

Uncertainty: the covariance of θ̂ from the Jacobian at the optimum. Closed-loop residuals
are coloured (sensor noise runs through the loop), so the sandwich form
(JᵀJ)⁻¹ S (JᵀJ)⁻¹ is used, with S = Var(Jᵀr) from the residuals' cross-spectrum
(:func:`_long_run_covariance`); with white residuals it reduces to σ̂²(JᵀJ)⁻¹. Two
small-sample corrections keep the intervals from being narrow when the Jacobian's weight
sits on a few lightly damped resonances: the residual spectrum is corrected for the fit's
leverage (the HC3 form of MacKinnon & White 1985, per frequency: the residuals are
orthogonal to J, so their periodogram is short by about the leverage where J is large),
and the 95 % intervals take Student's t with the Satterthwaite effective degrees of
freedom of S (how many independent spectral ordinates carry it) instead of 1.96. The
correlation matrix is the normalised covariance (P4 Tables 2 and 4).
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field

import numpy as np
from scipy.optimize import least_squares

from ..errors import IdentificationError
from ..model.amb import eddy_lag_matrices
from ..model.lft import Plant
from ..lti.discrete import simulate_lti, zoh
from ..lti.interconnect import series_inputs
from .budget import ErrorBudget, propagate
from .loop import DiscreteController, closed_loop_matrices
from .stats import jacobian_correlation
from .residuals import MISMATCH, ResidualTests, residual_tests

__all__ = ["FitResult", "ClosedLoopModel", "fit_parameters", "default_bounds", "nrmse_fit"]

TAU_E = "tau_e"
_DEFAULT_SCALE = {"N/m": 1e5, "N/A": 50.0, "N*s/m": 1e2, "s": 1e-3}


def nrmse_fit(y: np.ndarray, yhat: np.ndarray) -> np.ndarray:
    """NRMSE fit per channel (%): 100·(1 − ‖y − ŷ‖/‖y − mean(y)‖) (P2 Table 2)."""
    y, yhat = np.atleast_2d(y.T).T, np.atleast_2d(yhat.T).T
    num = np.linalg.norm(y - yhat, axis=0)
    den = np.linalg.norm(y - y.mean(axis=0), axis=0)
    return 100.0 * (1.0 - num / np.where(den > 0, den, np.nan))


@dataclass
class ClosedLoopModel:
    """The simulated closed loop of one record: y(θ), i(θ) for an excitation e.

    Parameters
    ----------
    plant : Plant
        Reduced mechanical plant: inputs the force currents (A), outputs displacements (m),
        with the LFT channels of every named parameter.
    actuator : (A, B, C, D)
        Amplifier of one axis (:func:`ambseal.model.amb.actuator_matrices`).
    controller : DiscreteController
        The controller that ran, at the data's sample period.
    tau_e : float
        Nominal eddy-current lag (s).
    """

    plant: Plant
    actuator: tuple
    controller: DiscreteController
    tau_e: float = 0.0
    _cache: dict = field(default_factory=dict, repr=False)

    def matrices(self, values: dict[str, float]):
        """Continuous (A, B, C, C_i, D_i) of amplifier → lag → plant for parameter values:
        displacements y = C x, coil current i = C_i x + D_i i_ref."""
        changes = {n: v - self.plant.parameter(n).nominal for n, v in values.items()
                   if n != TAU_E}
        p = self.plant.with_changes(changes) if changes else self.plant
        tau = values.get(TAU_E, self.tau_e)
        A, B, C = p.A, p.B, p.C
        for blocks in (eddy_lag_matrices(tau), self.actuator):
            A, B, C, _, Cout, Dout = series_inputs((A, B, C, np.zeros((C.shape[0], B.shape[1]))),
                                                   blocks)
        return A, B, C, Cout, Dout

    def statespace(self, values: dict[str, float], axes: tuple[str, ...]):
        """The discrete closed loop from excitation (A) to displacement (m) as a
        ``control.StateSpace`` at the controller's sample time (for FRF checks)."""
        import control

        A, B, C, _, _ = self.matrices(values)
        Ad, Bd = zoh(A, B, self.controller.dt)
        Acl, Bcl, Cy, _, _ = closed_loop_matrices(Ad, Bd, C, self.controller)
        return control.ss(Acl, Bcl, Cy, np.zeros((Cy.shape[0], Bcl.shape[1])),
                          self.controller.dt, inputs=[f"excitation_{a}" for a in axes],
                          outputs=[f"displacement_{a}" for a in axes])

    def simulate(self, values: dict[str, float], e: np.ndarray,
                 start: int = 0) -> tuple[np.ndarray, np.ndarray]:
        """Displacements and coil currents (N − start, k) for excitation ``e`` (N, k),
        simulated from rest at sample 0 and returned from sample ``start`` on."""
        A, B, C, Ci, Di = self.matrices(values)
        Ad, Bd = zoh(A, B, self.controller.dt)
        Acl, Bcl, Cy, Cref, _ = closed_loop_matrices(Ad, Bd, C, self.controller)
        nc = self.controller.A.shape[0]
        Ci_cl = np.hstack([Ci, np.zeros((Ci.shape[0], nc))])
        # coil current = C_i x + D_i i_ref, i_ref = C_ref z + e
        y, x_i, iref = simulate_lti(Acl, Bcl, [Cy, Ci_cl, Cref], e, start=start)
        return y, x_i + (iref + e[start:]) @ Di.T


@dataclass(frozen=True)
class FitResult:
    """Identified parameters with their uncertainty and the quality of the fit.

    Attributes
    ----------
    names : tuple of str
    estimate, initial, std_error, ci95_low, ci95_high : ndarray (p,)
        SI values.
    correlation : ndarray (p, p)
    nrmse_fit_pct : dict
        NRMSE fit (%) per displacement channel (and ``current_...`` when currents are used).
    converged : bool
    message : str
    iterations : int
        Function evaluations of the optimiser.
    wall_time_s : float
    time_s, y_meas, y_sim : ndarray
        For the measured-against-simulated figure (first record).
    axes : tuple of str
    std_error_noise : ndarray (p,) or None
        The noise part of ``std_error`` (sandwich covariance); ``std_error`` adds the fixed
        parameters' budget to it.
    budget : ErrorBudget or None
        What the fixed parameters' uncertainty adds (:mod:`ambseal.identify.budget`).
    residuals : ResidualTests or None
        Whiteness and independence tests (:mod:`ambseal.identify.residuals`).
    dof_noise : ndarray (p,) or None
        Effective degrees of freedom of the noise variance (Satterthwaite); the intervals
        take Student's t with these, combined with the budget's (known, infinite) part.
    correlation_jacobian : ndarray (p, p) or None
        Correlation of (JᵀJ)⁻¹ at the optimum: "calculated based on the Jacobian matrix"
        (P4 Tables 2, 4), the experiment's design alone; ``correlation`` carries the misfit.
    """

    names: tuple[str, ...]
    estimate: np.ndarray
    initial: np.ndarray
    std_error: np.ndarray
    ci95_low: np.ndarray
    ci95_high: np.ndarray
    correlation: np.ndarray
    nrmse_fit_pct: dict
    converged: bool
    message: str
    iterations: int
    wall_time_s: float
    time_s: np.ndarray
    y_meas: np.ndarray
    y_sim: np.ndarray
    axes: tuple[str, ...]
    std_error_noise: np.ndarray | None = None
    budget: ErrorBudget | None = None
    residuals: ResidualTests | None = None
    dof_noise: np.ndarray | None = None
    correlation_jacobian: np.ndarray | None = None

    @property
    def mismatch(self) -> bool:
        """Whether the model check fails (:meth:`model_check`)."""
        return self.model_check()["mismatch"]

    def model_check(self) -> dict:
        """The fit's verdict on its own model: a mismatch when the residuals correlate with
        the excitation (:mod:`ambseal.identify.residuals`, Ljung §16.6) or the data dispute
        a value the fit held fixed (score test, :mod:`ambseal.identify.budget`) — the two
        see different faults: unmodelled dynamics, and a wrong value of a modelled one.

        Returns
        -------
        dict
            ``residuals_correlated`` (channels), ``disputed`` (fixed values), ``mismatch``
            (bool) and ``verdict`` (text).
        """
        failed = self.residuals.failed if self.residuals is not None else []
        disputed = self.budget.disputed() if self.budget is not None else []
        parts = ([f"residuals correlate with the excitation on {', '.join(failed)}"]
                 if failed else [])
        if disputed:
            parts.append(f"the data dispute the fixed value of {', '.join(disputed)} (score "
                         "test); the intervals hold only as far as its stated uncertainty does")
        return {"residuals_correlated": list(failed), "disputed": disputed,
                "mismatch": bool(parts),
                "verdict": f"{MISMATCH} ({'; '.join(parts)})" if parts else
                "no mismatch found: residuals independent of the excitation"
                + (", no fixed value disputed" if self.budget is not None else "")}

    def value(self, name: str) -> float:
        return float(self.estimate[self.names.index(name)])

    def to_dict(self) -> dict:
        def f(x):
            return [float(v) if np.isfinite(v) else None for v in np.ravel(x)]

        noise = self.std_error if self.std_error_noise is None else self.std_error_noise
        out = {
            "parameters": {
                n: {"estimate": float(self.estimate[i]), "initial": float(self.initial[i]),
                    "std_error": f([self.std_error[i]])[0],
                    "std_error_noise": f([noise[i]])[0],
                    **({"dof_noise": f([self.dof_noise[i]])[0]}
                       if self.dof_noise is not None else {}),
                    "ci95": f([self.ci95_low[i], self.ci95_high[i]])}
                for i, n in enumerate(self.names)
            },
            "correlation": [f(row) for row in self.correlation],
            "nrmse_fit_pct": dict(zip(self.nrmse_fit_pct, f(list(self.nrmse_fit_pct.values())))),
            "converged": self.converged,
            "message": self.message,
            "iterations": self.iterations,
            "wall_time_s": self.wall_time_s,
        }
        if self.budget is not None:
            out["error_budget"] = self.budget.to_dict()
        if self.residuals is not None:
            out["residual_tests"] = self.residuals.to_dict()
            out["model_check"] = self.model_check()
        if self.correlation_jacobian is not None:
            out["correlation_jacobian"] = [f(row) for row in self.correlation_jacobian]
        return out


def _long_run_covariance(J: np.ndarray, R: np.ndarray, smooth: int = 2,
                         Hinv: np.ndarray | None = None):
    """Var(Σ_t J_tᵀ r_t) for residuals r that are a stationary coloured process.

    Frequency-domain form of the sandwich's middle term (Ljung, *System Identification*,
    2nd ed., §9.3): Σ_f J(f)ᴴ Φ_r(f) J(f) / L with Φ_r the residuals' cross-spectral
    matrix across channels, estimated by the periodogram R(f)R(f)ᴴ/N averaged over
    2·``smooth``+1 neighbouring bins (Daniell window), and L = 2N (zero padding, no wrap).
    Closed-loop residuals ring at the loop's lightly damped resonances, where the Jacobian
    is also largest; a lag-window (Newey–West) estimate smooths those peaks away and
    understates the variance, this one keeps them.

    With ``Hinv`` = (JᵀJ)⁻¹ of the whole fit, the periodogram is first corrected for the
    fit's leverage: the residuals are orthogonal to J, so R(f) lacks about h(f) = w J(f)
    (JᵀJ)⁻¹ J(f)ᴴ / L of the noise where J is large (Σ_f tr h = p); P ← (I − h)⁻¹ P (I − h)⁻ᴴ,
    the HC3 form (MacKinnon & White, J. Econometrics 29, 1985; Long & Ervin, Am. Stat. 54,
    2000, recommend it for small samples), eigenvalues of I − h floored at 0.1.

    Parameters
    ----------
    J : ndarray (N, c, p)
        Jacobian per sample and channel.
    R : ndarray (N, c)
        Residuals.
    Hinv : ndarray (p, p), optional
        (JᵀJ)⁻¹ of the fit (all records).

    Returns
    -------
    S : ndarray (p, p)
        Without ``Hinv``.
    (S, b) : with ``Hinv``, also b (F, p): each frequency bin's share of the variance of
        (JᵀJ)⁻¹Jᵀr per parameter, spread by the smoothing window (for the effective
        degrees of freedom, :func:`_covariance`).
    """
    N, c, p = J.shape
    L = 2 * N
    # no demeaning: a correct model leaves zero-mean residuals, and removing the mean would
    # zero the DC bin where slow (e.g. impulse-response) sensitivities have their weight
    Rf = np.fft.rfft(R, n=L, axis=0)  # (F, c)
    Jf = np.fft.rfft(J, n=L, axis=0)  # (F, c, p)
    P = Rf[:, :, None] * Rf[:, None, :].conj() / N  # (F, c, c) periodogram
    w = np.full(P.shape[0], 2.0)
    w[0] = 1.0
    w[-1] = 1.0
    JfH = np.conj(np.swapaxes(Jf, 1, 2))  # (F, p, c)
    # contractions as batched matrix products (a 4-operand einsum loops naively)
    if Hinv is not None:
        h = (w / L)[:, None, None] * ((Jf @ Hinv) @ JfH)
        lam, V = np.linalg.eigh(np.eye(c) - h)
        M = (V / np.clip(lam, 0.1, None)[:, None, :]) @ np.conj(np.swapaxes(V, 1, 2))
        P = M @ P @ np.conj(np.swapaxes(M, 1, 2))
    kernel = np.ones(2 * smooth + 1) / (2 * smooth + 1)
    if smooth > 0:
        flat = P.reshape(P.shape[0], -1)
        pad = np.concatenate([flat[smooth:0:-1].conj(), flat, flat[-2:-smooth - 2:-1].conj()])
        flat = np.apply_along_axis(lambda x: np.convolve(x, kernel, mode="valid"), 0, pad)
        P = flat.reshape(P.shape)
    S = np.real(np.sum(w[:, None, None] * (JfH @ (P @ Jf)), axis=0)) / L
    if Hinv is None:
        return S
    G = Jf @ Hinv  # (F, c, p): each parameter's combination of the Jacobian's columns
    q = w[:, None] * np.real(np.sum(G.conj() * (P @ G), axis=1)) / L
    return S, np.apply_along_axis(lambda x: np.convolve(x, kernel, mode="same"), 0, q)


def default_bounds(model: ClosedLoopModel, names) -> dict[str, tuple[float, float]]:
    """Default bounds (SI) around a model's values: [0.2, 5]× for positive force factors and
    spring stiffnesses, [0, 0.05] s for τ_e, none otherwise."""
    out = {}
    for n in names:
        if n == TAU_E:
            out[n] = (0.0, 0.05)
            continue
        v = model.plant.parameter(n).nominal
        positive = any(t in n for t in (".Ki_", ".Ks_", ".kxx", ".kyy")) and v > 0
        out[n] = (0.2 * v, 5 * v) if positive else (-np.inf, np.inf)
    return out


def fit_parameters(
    records: list,
    models: list[ClosedLoopModel],
    names: list[str],
    *,
    initial: dict[str, float] | None = None,
    bounds: dict[str, tuple[float, float]] | None = None,
    current_weight: float = 0.0,
    max_nfev: int = 200,
    window: tuple[int, int | None] = (0, None),
    fixed: dict[str, tuple[float, str]] | None = None,
    fixed_correlation: tuple[tuple[str, ...], np.ndarray] | None = None,
) -> FitResult:
    """Fit parameters ``names`` to one or more closed-loop records.

    Parameters
    ----------
    records : list
        Records with ``time_s`` (N,), ``excitation_a`` (N, k), ``displacement_m`` (N, k),
        ``current_a`` (N, k) and ``axes`` (e.g. :class:`ambseal.identify.data.Measurement`).
    models : list of ClosedLoopModel
        One per record (its pressure, its controller), sharing parameter names.
    names : list of str
        Parameters to fit (model names, or ``"tau_e"``).
    initial, bounds : dict, optional
        Start values and (low, high) bounds in SI; default start the model's nominal
        values, default bounds [0.2, 5]× nominal for positive factors (Ki, Ks, spring
        stiffness), [0, 0.05] s for τ_e, unbounded otherwise.
    current_weight : float
        Weight of the coil-current residuals relative to the displacements (0: off).
    max_nfev : int
        Budget of model evaluations; exhausting it flags the result as not converged.
    window : (start, stop)
        Samples of each record in the cost (e.g. one frequency of a stepped sine); the
        simulation always starts at rest at sample 0.
    fixed : dict, optional
        ``{name: (σ relative, source)}`` of parameters held at the models' values
        (:func:`ambseal.identify.budget.fixed_uncertainty`); their error budget is added to
        the covariance and the intervals. None: the noise covariance alone.
    fixed_correlation : (names, R), optional
        Fixed values that an earlier fit estimated together, and the correlation (m, m) of
        those estimates (their σ in ``fixed`` are its relative standard errors).

    Raises
    ------
    IdentificationError
        No parameter, an unknown name, a record shorter than the parameters, or a model
        that cannot be simulated at the start values.
    """
    if not names:
        raise IdentificationError("fit: no parameter to fit (expected --params NAME,...)")
    dup = sorted({n for n in names if list(names).count(n) > 1})
    if dup:
        raise IdentificationError(f"fit: parameter(s) named twice: {', '.join(dup)}")
    t0 = time.perf_counter()
    init, scale, lo, hi = _start(models[0], names, initial, bounds)
    start, stop = window
    data = [_record_data(rec, window, len(names)) for rec in records]

    def values(x):
        return dict(zip(names, init + x * scale))  # x: scaled change from the start

    def residual_blocks(x, moved: tuple[str, float] | None = None):
        """Per record an (N, c) array: scaled displacement (and current) residuals; with
        ``moved = (name, h)`` a fixed parameter scaled by 1 + h in every model."""
        out = []
        for model, (e, y, sy, i, si) in zip(models, data):
            v = values(x)
            if moved is not None:
                v[moved[0]] = _nominal(model, moved[0]) * (1.0 + moved[1])
            ys, is_ = model.simulate(v, e, start)
            R = (ys - y) / sy
            if current_weight > 0:
                R = np.hstack([R, current_weight * (is_ - i) / si])
            out.append(R)
        return out

    def residuals(x):
        r = np.concatenate([R.ravel() for R in residual_blocks(x)])
        if not np.all(np.isfinite(r)):
            return np.full_like(r, 1e6)
        return r

    r0 = residuals(np.zeros(len(names)))
    if np.all(r0 == 1e6):
        raise IdentificationError("fit: the model cannot be simulated at the start values")
    lb, ub = (lo - init) / scale, (hi - init) / scale
    # scipy's default tolerances: 1e-10 took 35 % more evaluations, moved estimates < 1e-3 SE
    sol = least_squares(residuals, np.zeros(len(names)), bounds=(lb, ub), method="trf",
                        x_scale=1.0, max_nfev=max_nfev, xtol=1e-8, ftol=1e-8, gtol=1e-8)
    est = init + sol.x * scale
    converged = bool(sol.status > 0)
    message = str(sol.message)
    width = np.where(np.isfinite(hi - lo), hi - lo, np.inf)
    at_bound = [n for n, v, a, b, w in zip(names, est, lo, hi, width)
                if np.isfinite(w) and min(v - a, b - v) <= 1e-6 * w]
    if at_bound:  # an estimate stopped by its bound is not an optimum of J(θ)
        converged = False
        message = f"estimate at its bound: {', '.join(at_bound)}"

    blocks = residual_blocks(sol.x)
    cov, dof = _covariance(sol.jac, sol.fun, blocks, len(names))
    converged = converged and bool(np.all(np.isfinite(cov)))
    cov = cov * np.outer(scale, scale)
    se_noise = np.sqrt(np.diag(cov))
    budget = _budget(sol.jac, scale, names, fixed, models, residual_blocks, sol.x,
                     se_noise**2, sol.fun, blocks, fixed_correlation)
    if budget is not None:
        cov = cov + budget.covariance
    se = np.sqrt(np.diag(cov))
    half = _t_quantile(se_noise**2, se**2, dof) * se
    k = len(records[0].axes)
    tests = residual_tests([R[:, :k] for R in blocks],
                           [np.asarray(d[0])[start:] for d in data], tuple(records[0].axes))
    with np.errstate(invalid="ignore", divide="ignore"):
        corr = cov / np.outer(se, se)
    e0, y0 = data[0][0], data[0][1]
    ys, is_ = models[0].simulate(dict(zip(names, est)), e0)
    fits = {f"{a}": v for a, v in zip(records[0].axes, nrmse_fit(y0, ys[start:]))}
    bad_fit = [a for a, v in fits.items() if not np.isfinite(v) or v < 0]
    if bad_fit and converged:  # worse than the mean: the model does not describe the data
        converged = False
        message = f"NRMSE fit below 0 % on {', '.join(bad_fit)}"
    if current_weight > 0:
        fi = nrmse_fit(data[0][3], is_[start:])
        fits.update({f"current_{a}": v for a, v in zip(records[0].axes, fi)})
    return FitResult(
        names=tuple(names), estimate=est, initial=init, std_error=se,
        ci95_low=est - half, ci95_high=est + half, correlation=corr,
        nrmse_fit_pct=fits, converged=converged, message=message,
        iterations=int(sol.nfev), wall_time_s=time.perf_counter() - t0,
        time_s=np.asarray(records[0].time_s)[start:stop], y_meas=y0, y_sim=ys[start:],
        axes=tuple(records[0].axes), std_error_noise=se_noise, budget=budget,
        residuals=tests, dof_noise=dof,
        correlation_jacobian=jacobian_correlation(sol.jac),
    )


def _t_quantile(var_noise, var_total, dof_noise) -> np.ndarray:
    """Student's t 97.5 % quantile of each interval: the noise variance has ``dof_noise``
    degrees of freedom, the budget's part is taken as known, so ν = v_total² / (v_noise² /
    ν_noise) (Satterthwaite); 1.96 where ν is not finite."""
    from scipy.stats import t

    with np.errstate(invalid="ignore", divide="ignore"):
        nu = np.asarray(var_total) ** 2 / (np.asarray(var_noise) ** 2 / np.asarray(dof_noise))
    ok = np.isfinite(nu) & (nu > 0)
    return np.where(ok, t.ppf(0.975, np.where(ok, nu, 1.0)), 1.96)


def _nominal(model: ClosedLoopModel, name: str) -> float:
    return model.tau_e if name == TAU_E else model.plant.parameter(name).nominal


def _budget(J, scale, names, fixed, models, residual_blocks, x, noise_var, r, blocks,
            correlated=None) -> ErrorBudget | None:
    """The fixed parameters' error budget by forward differences of the residuals in each
    fixed value (relative step 10⁻³, every model alike; central ones cost twice), with each fixed value's score test
    (:func:`_score_test`) and the correlation of those an earlier fit estimated together
    (``correlated`` = (names, R)); None without fixed values."""
    use = [(n, s, src) for n, (s, src) in (fixed or {}).items()
           if s > 0 and any(_nominal(m, n) != 0 for m in models)]
    if not use:
        return None
    h = 1e-3
    r0 = np.concatenate([R.ravel() for R in blocks])
    cols = []
    for n, _, _ in use:
        up = np.concatenate([R.ravel() for R in residual_blocks(x, (n, h))])
        cols.append((up - r0) / h)
    Jf = np.column_stack(cols)
    fixed_names = [u[0] for u in use]
    corr, estimated = np.eye(len(use)), np.zeros(len(use), bool)
    if correlated is not None:
        where = {n: i for i, n in enumerate(correlated[0])}
        idx = [(j, where[n]) for j, n in enumerate(fixed_names) if n in where]
        for j, a in idx:
            estimated[j] = True
            for k, b in idx:
                corr[j, k] = correlated[1][a, b] if j != k else 1.0
    return propagate(J, Jf, scale, names, fixed_names, [u[1] for u in use],
                     [u[2] for u in use], noise_var, score=_score_test(J, Jf, r, blocks),
                     correlation=np.nan_to_num(corr), estimated=estimated)


def _split(M: np.ndarray, blocks_at_optimum: list) -> list:
    """Rows of a stacked (n, m) array per record as (N, c, m) arrays (sample-major)."""
    out, off = [], 0
    for R in blocks_at_optimum:
        n_s, c = R.shape
        out.append(M[off:off + n_s * c].reshape(n_s, c, M.shape[1]))
        off += n_s * c
    return out


def _score_test(J, Jf, r, blocks_at_optimum):
    """Score (Lagrange-multiplier) test of each fixed value against the data: the cost's
    gradient in φ_j/φ_j0 at the optimum, with θ free (J_φ projected off J), over its
    standard deviation from the residuals' long-run covariance (as the sandwich's middle
    term); N(0, 1) when the fixed value is right (Rao's score test; Ljung §16.6 relates it
    to testing an extended model structure without fitting it). Returns (z, one-step
    estimate of the relative offset φ/φ0 − 1 the data suggest, its standard error)."""
    Jp = Jf - J @ np.linalg.lstsq(J, Jf, rcond=None)[0]
    g = Jp.T @ r
    V = sum(_long_run_covariance(Jb, rb[..., 0]) for Jb, rb in
            zip(_split(Jp, blocks_at_optimum), _split(r[:, None], blocks_at_optimum)))
    sd = np.sqrt(np.clip(np.diag(V), 0, None))
    h = np.einsum("ij,ij->j", Jp, Jp)
    with np.errstate(invalid="ignore", divide="ignore"):
        return g / sd, -g / h, sd / h


def _start(m0: ClosedLoopModel, names, initial, bounds):
    """Start values, scales and bounds (SI) of the fitted parameters; raises
    IdentificationError for an unknown name or a start outside its bounds."""
    nominal, scale = [], []
    for n in names:
        if n == TAU_E:
            # start inside the bounds: τ_e = 0 (no lag modelled) sits on the lower bound
            nominal.append(m0.tau_e if m0.tau_e > 0 else 0.1 * _DEFAULT_SCALE["s"])
            scale.append(_DEFAULT_SCALE["s"])
            continue
        try:
            p = m0.plant.parameter(n)
        except Exception as exc:
            raise IdentificationError(f"fit: {exc}") from None
        nominal.append(p.nominal)
        scale.append(abs(p.nominal) if p.nominal != 0 else _DEFAULT_SCALE.get(p.unit, 1.0))
    nominal, scale = np.array(nominal), np.array(scale)
    init = np.array([(initial or {}).get(n, v) for n, v in zip(names, nominal)])
    defaults = default_bounds(m0, names)
    lo = np.array([(bounds or {}).get(n, defaults[n])[0] for n in names], dtype=float)
    hi = np.array([(bounds or {}).get(n, defaults[n])[1] for n in names], dtype=float)
    outside = [n for n, v, a, b in zip(names, init, lo, hi) if not a <= v <= b]
    if outside:
        raise IdentificationError(f"fit: start value of {', '.join(outside)} outside its bounds")
    return np.clip(init, lo + 1e-12 * scale, hi - 1e-12 * scale), scale, lo, hi


def _record_data(rec, window, n_params: int):
    """(excitation up to the window's end, y, σ_y, i, σ_i) of one record in ``window``."""
    start, stop = window
    y = np.asarray(rec.displacement_m)[start:stop]
    if y.shape[0] <= n_params:
        raise IdentificationError(f"fit: {y.shape[0]} samples for {n_params} parameters")
    sy = y.std(axis=0)
    sy[sy == 0] = 1.0
    i = np.asarray(rec.current_a)[start:stop]
    si = i.std(axis=0)
    si[si == 0] = 1.0
    return np.asarray(rec.excitation_a)[:stop], y, sy, i, si


def _covariance(J: np.ndarray, r: np.ndarray, blocks_at_optimum: list, p: int
                ) -> tuple[np.ndarray, np.ndarray]:
    """Sandwich covariance of the scaled estimate, (JᵀJ)⁻¹ S (JᵀJ)⁻¹ with S the residuals'
    long-run covariance per record, leverage-corrected (:func:`_long_run_covariance`), and
    each parameter's effective degrees of freedom ν = (Σ b)² / Σ b² over the frequency bins
    of every record (Satterthwaite, *Biometrics Bull.* 2, 1946: S is a weighted sum of
    periodogram ordinates, each complex ordinate χ²₂ and two bins of the 2N-point transform
    per independent one); ``inf`` covariance and NaN ν when JᵀJ is singular. Rows of the
    stacked residual vector are sample-major per record."""
    blocks = list(zip(_split(J, blocks_at_optimum),
                      [b[..., 0] for b in _split(r[:, None], blocks_at_optimum)]))
    H = J.T @ J
    try:
        if np.linalg.cond(H) > 1e14:
            raise np.linalg.LinAlgError
        Hinv = np.linalg.inv(H)
        parts = [_long_run_covariance(Jb, rb, Hinv=Hinv) for Jb, rb in blocks]
        cov = Hinv @ sum(S for S, _ in parts) @ Hinv
        b = np.concatenate([b for _, b in parts])
        with np.errstate(invalid="ignore", divide="ignore"):
            dof = b.sum(axis=0) ** 2 / (b**2).sum(axis=0)
    except np.linalg.LinAlgError:
        cov, dof = np.full((p, p), np.inf), np.full(p, np.nan)
    return cov, dof
