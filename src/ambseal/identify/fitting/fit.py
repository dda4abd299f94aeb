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
controller that ran (:mod:`ambseal.robust.digital_loop`).

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

import control
import numpy as np
from scipy.optimize import least_squares

from ambseal.errors import IdentificationError
from ambseal.identify.fitting.budget import ErrorBudget, propagate
from ambseal.identify.fitting.residuals import MISMATCH, ResidualTests, residual_tests
from ambseal.identify.fitting.sandwich import _covariance, _long_run_covariance, _score_test, _t_quantile  # noqa: F401
from ambseal.identify.fitting.sensor_lag import TAU_S, lag_test_dict, with_sensor_lag
from ambseal.identify.fitting.stats import jacobian_correlation
from ambseal.lti import least_squares_converged, series_inputs, simulate_lti, zoh
from ambseal.model import Plant, eddy_lag_matrices
from ambseal.robust import DiscreteController, closed_loop_matrices
from ambseal.threads import with_numerics_threads

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
    tau_s : float
        Sensor lag (s) of the displacement sensors' low-pass, 0 for none
        (:mod:`ambseal.identify.fitting.sensor_lag`).
    """

    plant: Plant
    actuator: tuple
    controller: DiscreteController
    tau_e: float = 0.0
    tau_s: float = 0.0
    _cache: dict = field(default_factory=dict, init=False, repr=False, compare=False)

    def matrices(self, values: dict[str, float]):
        """Continuous (A, B, C, C_i, D_i) of amplifier → lag → plant for parameter values:
        displacements y = C x, coil current i = C_i x + D_i i_ref."""
        A, B, C = self._lft(values)
        tau = values.get(TAU_E, self.tau_e)
        for blocks in (eddy_lag_matrices(tau), self.actuator):
            A, B, C, _, Cout, Dout = series_inputs((A, B, C, np.zeros((C.shape[0], B.shape[1]))),
                                                   blocks)
        return A, B, C, Cout, Dout

    def _lft(self, values: dict[str, float]):
        """The plant's (A, B, C) with ``values`` applied through its LFT channels: the
        arithmetic of :meth:`~ambseal.model.lft.Plant.with_changes`, with each channel's
        products B_θC_θ, B_θD_θ formed once per model, not once per evaluation."""
        p = self.plant
        A, B = p.A, p.B
        changes = [(n, v) for n, v in values.items() if n not in (TAU_E, TAU_S)]
        if changes:
            A, B = A.copy(), B.copy()
        for name, v in changes:
            par = p.parameter(name)
            if name not in self._cache:
                self._cache[name] = (par.B @ par.C, par.B @ par.D)
            BC, BD = self._cache[name]
            theta = v - par.nominal
            A += theta * BC
            B += theta * BD
        return A, B, p.C

    def _sampled(self, values: dict[str, float]):
        """(A_d, B_d, C, C_i, D_i) sampled by ZOH at the controller's period, the sensors'
        lag on the displacements."""
        A, B, C, Ci, Di = self.matrices(values)
        Ad, Bd = zoh(A, B, self.controller.dt)
        return (*with_sensor_lag(Ad, Bd, C, Ci, values.get(TAU_S, self.tau_s),
                                 self.controller.dt), Di)

    def statespace(self, values: dict[str, float], axes: tuple[str, ...]):
        """The discrete closed loop from excitation (A) to displacement (m) as a
        ``control.StateSpace`` at the controller's sample time (for FRF checks)."""

        Ad, Bd, C, _, _ = self._sampled(values)
        Acl, Bcl, Cy, _, _ = closed_loop_matrices(Ad, Bd, C, self.controller)
        return control.ss(Acl, Bcl, Cy, np.zeros((Cy.shape[0], Bcl.shape[1])),
                          self.controller.dt, inputs=[f"excitation_{a}" for a in axes],
                          outputs=[f"displacement_{a}" for a in axes])

    def simulate(self, values: dict[str, float], e: np.ndarray, start: int = 0,
                 currents: bool = True) -> tuple[np.ndarray, np.ndarray | None]:
        """Displacements and coil currents (N − start, k; currents None unless asked) for
        excitation ``e`` (N, k), simulated from rest at sample 0, from sample ``start`` on."""
        Ad, Bd, C, Ci, Di = self._sampled(values)
        Acl, Bcl, Cy, Cref, _ = closed_loop_matrices(Ad, Bd, C, self.controller)
        if not currents:
            return simulate_lti(Acl, Bcl, [Cy], e, start=start)[0], None
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
        What the fixed parameters' uncertainty adds (:mod:`ambseal.identify.fitting.budget`).
    residuals : ResidualTests or None
        Whiteness and independence tests (:mod:`ambseal.identify.fitting.residuals`).
    dof_noise : ndarray (p,) or None
        Effective degrees of freedom of the noise variance (Satterthwaite); the intervals
        take Student's t with these, combined with the budget's (known, infinite) part.
    correlation_jacobian : ndarray (p, p) or None
        Correlation of (JᵀJ)⁻¹ at the optimum: "calculated based on the Jacobian matrix"
        (P4 Tables 2, 4), the experiment's design alone; ``correlation`` carries the misfit.
    sensor_lag : dict or None
        Score test of a sensor lag the model lacks (:mod:`ambseal.identify.fitting.sensor_lag`);
        None when ``tau_s`` is fitted.
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
    sensor_lag: dict | None = None

    @property
    def mismatch(self) -> bool:
        """Whether the model check fails (:meth:`model_check`)."""
        return self.model_check()["mismatch"]

    def model_check(self) -> dict:
        """The fit's verdict on its own model: a mismatch when the residuals correlate with
        the excitation (:mod:`ambseal.identify.fitting.residuals`, Ljung §16.6), the data dispute
        a value the fit held fixed (score test, :mod:`ambseal.identify.fitting.budget`), or they
        ask for a sensor lag the model lacks (score test,
        :mod:`ambseal.identify.fitting.sensor_lag`) — unmodelled dynamics in general, a wrong value
        of a modelled parameter, and the one unmodelled element τ_e would otherwise absorb.

        Returns
        -------
        dict
            ``residuals_correlated`` (channels), ``disputed`` (fixed values),
            ``sensor_lag`` (bool), ``mismatch`` (bool) and ``verdict`` (text).
        """
        failed = self.residuals.failed if self.residuals is not None else []
        disputed = self.budget.disputed() if self.budget is not None else []
        parts = ([f"residuals correlate with the excitation on {', '.join(failed)}"]
                 if failed else [])
        if disputed:
            parts.append(f"the data dispute the fixed value of {', '.join(disputed)} (score "
                         "test); the intervals hold only as far as its stated uncertainty does")
        lag = bool(self.sensor_lag and self.sensor_lag["flagged"])
        if lag:
            tau, se = (self.sensor_lag[k] * 1e6 for k in ("suggested_tau_s",
                                                          "suggested_tau_s_se"))
            parts.append(f"the data ask for a sensor lag of {tau:.3g} ± {se:.2g} µs the model "
                         + ("lacks (score test), which a wrong held value can also make: fit "
                            f"the disputed values first, then {TAU_S} if it remains"
                            if disputed else
                            f"lacks (score test); fit {TAU_S} beside tau_e (Ki, Ks then hold; "
                            "read tau_e + tau_s, not each)"))
        return {"residuals_correlated": list(failed), "disputed": disputed, "sensor_lag": lag,
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
        if self.sensor_lag is not None:
            out["sensor_lag_test"] = self.sensor_lag
        return out


def default_bounds(model: ClosedLoopModel, names) -> dict[str, tuple[float, float]]:
    """Default bounds (SI) around a model's values: [0.2, 5]× for positive force factors and
    spring stiffnesses, [0, 0.05] s for τ_e and τ_s, none otherwise."""
    out = {}
    for n in names:
        if n in (TAU_E, TAU_S):
            out[n] = (0.0, 0.05)
            continue
        v = model.plant.parameter(n).nominal
        positive = any(t in n for t in (".Ki_", ".Ks_", ".kxx", ".kyy")) and v > 0
        out[n] = (0.2 * v, 5 * v) if positive else (-np.inf, np.inf)
    return out


@with_numerics_threads
def fit_parameters(
    records: list,
    models: list[ClosedLoopModel],
    names: list[str],
    *,
    initial: dict[str, float] | None = None,
    bounds: dict[str, tuple[float, float]] | None = None,
    current_weight: float = 0.0,
    max_nfev: int | None = None,
    window: tuple[int, int | None] = (0, None),
    fixed: dict[str, tuple[float, str]] | None = None,
    fixed_correlation: tuple[tuple[str, ...], np.ndarray] | None = None,
) -> FitResult:
    """Fit parameters ``names`` to one or more closed-loop records.

    Parameters
    ----------
    records : list
        Records with ``time_s`` (N,), ``excitation_a`` (N, k), ``displacement_m`` (N, k),
        ``current_a`` (N, k) and ``axes`` (e.g. :class:`ambseal.identify.records.data.Measurement`).
    models : list of ClosedLoopModel
        One per record (its pressure, its controller), sharing parameter names.
    names : list of str
        Parameters to fit (model names, ``"tau_e"``, or ``"tau_s"``: a sensor lag the rig
        file does not state, :mod:`ambseal.identify.fitting.sensor_lag`).
    initial, bounds : dict, optional
        Start values and (low, high) bounds in SI; default start the model's nominal
        values, default bounds [0.2, 5]× nominal for positive factors (Ki, Ks, spring
        stiffness), [0, 0.05] s for τ_e, unbounded otherwise.
    current_weight : float
        Weight of the coil-current residuals relative to the displacements (0: off).
    max_nfev : int, optional
        A cap on model evaluations; exhausting it flags the result as not converged. None
        (the default): the fit ends at its tolerances
        (:func:`ambseal.lti.least_squares.least_squares_converged`), never at a count.
    window : (start, stop)
        Samples of each record in the cost (e.g. one frequency of a stepped sine); the
        simulation always starts at rest at sample 0.
    fixed : dict, optional
        ``{name: (σ relative, source)}`` of parameters held at the models' values
        (:func:`ambseal.identify.fitting.budget.fixed_uncertainty`); their error budget is added to
        the covariance and the intervals. None: the noise covariance alone.
    fixed_correlation : (names, R), optional
        Fixed values that an earlier fit estimated together, and the correlation (m, m) of
        those estimates (their σ in ``fixed`` are its relative standard errors).

    Returns
    -------
    FitResult
        Estimates (SI) with sandwich standard errors, 95 % intervals (Student's t) and
        correlations, the NRMSE fit per channel, convergence, the error budget of ``fixed``
        and the residual tests.

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

    def residual_blocks(x, moved: tuple | None = None):
        """Per record an (N, c) array: scaled displacement (and current) residuals; with
        ``moved = (name, f)`` a fixed parameter set to f(its value) in every model."""
        out = []
        for model, (e, y, sy, i, si) in zip(models, data):
            v = values(x)
            if moved is not None:
                v[moved[0]] = moved[1](_nominal(model, moved[0]))
            ys, is_ = model.simulate(v, e, start, currents=current_weight > 0)
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

    x0 = np.zeros(len(names))
    r0 = residuals(x0)
    if np.all(r0 == 1e6):
        raise IdentificationError("fit: the model cannot be simulated at the start values")
    sol = _solve(residuals, x0, r0, ((lo - init) / scale, (hi - init) / scale), max_nfev)
    est = init + sol.x * scale
    converged, message = _stopped(sol, names, est, lo, hi)

    blocks = _blocks_at(sol, residual_blocks, [(d[1].shape[0], d[1].shape[1] *
                                                (2 if current_weight > 0 else 1)) for d in data])
    cov, dof = _covariance(sol.jac, sol.fun, blocks, len(names))
    converged = converged and bool(np.all(np.isfinite(cov)))
    cov = cov * np.outer(scale, scale)
    se_noise = np.sqrt(np.diag(cov))
    budget = _budget(sol.jac, scale, names, fixed, models, residual_blocks, sol.x,
                     se_noise**2, sol.fun, blocks, fixed_correlation)
    lag = None if TAU_S in names else _lag_test(sol.jac, sol.fun, blocks, residual_blocks, sol.x)
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
    ys, is_ = models[0].simulate(dict(zip(names, est)), e0, start, currents=current_weight > 0)
    fits = {f"{a}": v for a, v in zip(records[0].axes, nrmse_fit(y0, ys))}
    bad_fit = [a for a, v in fits.items() if not np.isfinite(v) or v < 0]
    if bad_fit and converged:  # worse than the mean: the model does not describe the data
        converged, message = False, f"NRMSE fit below 0 % on {', '.join(bad_fit)}"
    if current_weight > 0:
        fits.update({f"current_{a}": v for a, v in zip(records[0].axes,
                                                        nrmse_fit(data[0][3], is_))})
    return FitResult(
        names=tuple(names), estimate=est, initial=init, std_error=se,
        ci95_low=est - half, ci95_high=est + half, correlation=corr,
        nrmse_fit_pct=fits, converged=converged, message=message,
        iterations=int(sol.nfev), wall_time_s=time.perf_counter() - t0,
        time_s=np.asarray(records[0].time_s)[start:stop], y_meas=y0, y_sim=ys,
        axes=tuple(records[0].axes), std_error_noise=se_noise, budget=budget,
        residuals=tests, dof_noise=dof,
        correlation_jacobian=jacobian_correlation(sol.jac), sensor_lag=lag,
    )


def _stopped(sol, names, est, lo, hi) -> tuple[bool, str]:
    """(converged, message) of the optimiser's stop: not converged where it says so or
    where an estimate sits on its bound (then not an optimum of J(θ))."""
    width = np.where(np.isfinite(hi - lo), hi - lo, np.inf)
    at_bound = [n for n, v, a, b, w in zip(names, est, lo, hi, width)
                if np.isfinite(w) and min(v - a, b - v) <= 1e-6 * w]
    if at_bound:
        return False, f"estimate at its bound: {', '.join(at_bound)}"
    return bool(sol.status > 0), str(sol.message)


def _solve(residuals, x0, r0, bounds, max_nfev: int | None):
    """``scipy.optimize.least_squares`` (trf) from ``x0``, whose residuals ``r0`` are known:
    its first evaluation, at the start, takes them instead of simulating again."""
    first = {x0.tobytes(): r0}

    def cost(x):
        r = first.pop(np.asarray(x, float).tobytes(), None)
        return residuals(x) if r is None else r.copy()

    # scipy's default tolerances: 1e-10 took 35 % more evaluations, moved estimates < 1e-3 SE
    try:
        opts = dict(bounds=bounds, method="trf", x_scale=1.0, xtol=1e-8, ftol=1e-8,
                    gtol=1e-8)
        return (least_squares_converged(cost, x0, **opts) if max_nfev is None
                else least_squares(cost, x0, max_nfev=max_nfev, **opts))
    except ValueError as exc:  # residuals so large that their differences overflow
        raise IdentificationError(
            f"fit: the residuals' Jacobian is not finite ({exc}): the records' closed-loop "
            "model cannot follow them (a record whose controller does not hold its rotor, "
            "or implausible values)") from None


def _blocks_at(sol, residual_blocks, shapes) -> list:
    """The residual blocks at the optimum: ``sol.fun`` is least_squares's copy of the
    residual vector it evaluated at ``sol.x`` (trf keeps the accepted evaluation), split
    into the records' ``shapes``; evaluated again only where that vector is the fill of a
    model that could not be simulated."""
    if np.all(sol.fun == 1e6):
        return residual_blocks(sol.x)
    ends = np.cumsum([r * c for r, c in shapes])[:-1]
    return [b.reshape(shape) for b, shape in zip(np.split(sol.fun, ends), shapes)]


def _nominal(model: ClosedLoopModel, name: str) -> float:
    if name in (TAU_E, TAU_S):
        return model.tau_e if name == TAU_E else model.tau_s
    return model.plant.parameter(name).nominal


def _lag_test(J, r, blocks, residual_blocks, x) -> dict:
    """Score test of a sensor lag at τ_s = 0 (:mod:`ambseal.identify.fitting.sensor_lag`): the
    residuals' derivative in τ_s by a forward step of 1 µs (a = 0.01 at 10 kHz; y moves by
    a·(x[n] − x[n−1]), linear in the step)."""
    h = 1e-6
    r0 = np.concatenate([R.ravel() for R in blocks])
    up = np.concatenate([R.ravel() for R in residual_blocks(x, (TAU_S, lambda v: v + h))])
    z, off, se = (float(q[0]) for q in _score_test(J, ((up - r0) / h)[:, None], r, blocks))
    return lag_test_dict(-z, off, se)  # a lag the data ask for: positive


def _budget(J, scale, names, fixed, models, residual_blocks, x, noise_var, r, blocks,
            correlated=None) -> ErrorBudget | None:
    """The fixed parameters' error budget by forward differences of the residuals in each
    fixed value (relative step 10⁻³, every model alike; central ones cost twice), with each
    fixed value's score test (:func:`_score_test`) and the correlation of those an earlier
    fit estimated together (``correlated`` = (names, R)); None without fixed values."""
    use = [(n, s, src) for n, (s, src) in (fixed or {}).items()
           if s > 0 and any(_nominal(m, n) != 0 for m in models)]
    if not use:
        return None
    h = 1e-3
    r0 = np.concatenate([R.ravel() for R in blocks])
    cols = []
    for n, _, _ in use:
        up = np.concatenate([R.ravel() for R in residual_blocks(x, (n, lambda v: v * (1 + h)))])
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


def _start(m0: ClosedLoopModel, names, initial, bounds):
    """Start values, scales and bounds (SI) of the fitted parameters; raises
    IdentificationError for an unknown name or a start outside its bounds."""
    nominal, scale = [], []
    for n in names:
        if n in (TAU_E, TAU_S):
            # start inside the bounds: no lag modelled sits on the lower bound
            tau = _nominal(m0, n)
            nominal.append(tau if tau > 0 else 0.1 * _DEFAULT_SCALE["s"])
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
