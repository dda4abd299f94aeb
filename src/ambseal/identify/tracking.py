"""On-line tracking of seal coefficients (or any LFT parameter) from closed-loop signals.

Method: a recursive prediction-error method (RPEM; Ljung & Söderström, *Theory and
Practice of Recursive Identification*, 1983, §3.7 and §4.4; Ljung, *System
Identification*, 2nd ed., §11.4) in its Kalman-filter form for parameters that drift as
random walks. The model is the rig's reduced plant with the amplifier and eddy lag in
series (:meth:`ambseal.identify.fitting.fit.ClosedLoopModel.matrices`), driven by the *measured*
current references: the loop is cut at the DAC, so the controller that ran only needs to
have produced the references (it is not simulated), and an unstable open-loop plant is
tracked through the predictor's gain. With x the model state, u = i_ref, y the sensors:

    x̂_{k+1} = A_d(θ̂) x̂_k + B_d(θ̂) u_k + K ε_k,        ε_k = y_k − C x̂_k,
    W_{j,k+1} = (A_d − K C) W_{j,k} + (∂A_d/∂θ_j) x̂_k + (∂B_d/∂θ_j) u_k,   H_k = C W_k,
    θ̂ ← θ̂ + P Hᵀ (H P Hᵀ + Λ)⁻¹ ε,   P ← P − P Hᵀ (H P Hᵀ + Λ)⁻¹ H P + Q_θ,

with A_d(θ) = A_d(θ₀) + Σ_j (∂A_d/∂θ_j)(θ_j − θ₀,j) between re-linearisations (every
``relinearise_s``, where θ₀ ← θ̂ and the steady-state predictor gain K is solved again),
the exact derivative of the matrix exponential from Van Loan's block exponential (Van Loan
1978, Thm. 1), Λ the innovations' running covariance (diagonal; the channels are updated
one after the other, Bierman's scalar form) and Q_θ = (rate·scale)²·T the random walk
whose one-second spread is the expected drift. The standard error at every sample is
√diag P.

Why not an extended Kalman filter on the state augmented by θ: it propagates the full
(n+p)² covariance every sample, ≈ 4(n+p)³ flops (≈ 90 kflop for n = 28, p = 1), against
≈ 2n²(1 + 2p) + 2n·k(1 + p) for this RPEM (≈ 5 kflop): only the latter runs ≥ 10× real
time at 10 kHz in Python (with numba) and fits a controller's sample in generated C. The
fixed-gain predictor is the EKF's steady state at θ̂₀; the price is a sub-optimal state
estimate between re-linearisations, which the innovations' covariance Λ absorbs into the
standard error.

The model must be the identified one. Only the tracked parameters move; every other value
(Ki, Ks, τ_e, the coupling, the seal's other coefficients) is taken as known, so the rig
should be the one identified on site (thesis stages (a)–(c): ``ambseal identify``, or
``identified_rig.toml`` of ``ambseal run``), not the first-principles rig file (why, measured
on the test rig: benchmarks/README.md, "Where the design defaults come from").

When the model is wrong the tracker says so (:meth:`OnlineTracker.consistency`): a score
(Lagrange-multiplier) test, every window of ``check_window_s``, that the coefficients it
holds known — the tracked seal's K, C, c — explain the data (Rao 1948; Engle 1984; the
residual tests of Ljung 1999 §16.6). Their scores cost one sensitivity recursion each
beside the tracked ones and leave the estimate unchanged. A significance test alone is not
a relevance test: with enough data it finds any error, also a harmless one (the test
rig's identified model, ≤ 0.2 % off, failed it at 21.5 s of the ramp with its interval
covering the truth 99.99 % of the time). So a window refuses only when the score is
significant *and* the error matters (:func:`held_error_check`): the coefficient's error
δ_j, one Gauss–Newton step on the efficient score, and the bias it leaves in k̂,
b = I_kk⁻¹ I_kj δ_j (the omitted-variable bias of least squares; Ljung 1999 §8.3, §9.3),
must exceed k̂'s own standard error (``check_bias_se``): the limit is the tracker's stated
accuracy, beyond which its 95 % interval covers < 83 % of the time. The checks on the test
rig and the pump are in benchmarks/README.md ("Where the design defaults come from").
"""

from __future__ import annotations

import time
from dataclasses import dataclass

import numba
from numba.extending import register_jitable
import numpy as np
import scipy.linalg as sla
from scipy import stats

from ambseal.config import RigConfig
from ambseal.errors import DataError, IdentificationError, ModelError
from ambseal.identify.records.data import Measurement
from ambseal.identify.excitation.plan import PRBS_CLOCK_SAMPLES
from ambseal.identify.fitting.fit import _DEFAULT_SCALE, ClosedLoopModel
from ambseal.identify.excitation.signals import prbs
from ambseal.identify.fitting.stages import build_models
from ambseal.model import (
    build_system,
    channel_names,
    mechanical_plant,
    pressure_for_k,
    values_following,
)

__all__ = ["TrackingSettings", "TrackingResult", "track", "flops_per_sample",
           "linearised_model", "rpem_kernel", "OnlineTracker", "score_test", "held_error_check",
           "current_limit",
           "check_excitation", "tracking_excitation"]


@dataclass(frozen=True)
class TrackingSettings:
    """Tuning of the tracker (SI; the rules behind the defaults in each line).

    Attributes
    ----------
    rate_per_s : float
        Expected drift of each parameter, as a fraction of its scale per second (0.1: the
        seal's k from 0 to 3× nominal over 30 s, the main job's pressure ramp); sets the random
        walk Q_θ. Larger tracks faster with a noisier estimate.
    relinearise_s : float
        Period of re-linearisation at θ̂ (s); the predictor gain is solved again only when
        θ̂ has moved by more than ``regain_rel`` of its scale since the last solution.
    regain_rel : float
    sensor_noise_fraction : float
        Sensor noise of the predictor's gain, as a fraction of each displacement channel's
        RMS (0.01, the thesis rig's level, P2 §4).
    process_noise_a : float or None
        Input-referred current disturbance of the predictor's gain (A std); None: 1 % of the
        RMS current reference.
    innovation_time_s : float
        Time constant of the innovations' running covariance Λ (s).
    cutoff_hz : float or None
        Modes kept in the tracker's model; None: the Nyquist frequency of the record (a mode
        above it is not seen in sampled data but aliased).
    initial_rel_std : float
        Initial standard deviation of θ as a fraction of its scale.
    inflation_window_s : float
        Window of the standard error's variance-inflation factor (:func:`_inflation`).
    min_duration_s : float
        Shortest record tracked: the initial transient from the rig's value measured on the
        virtual facility is 0.2–0.5 s.
    follow_pressure : bool
        When a tracked parameter is a seal's k affine in the pressure drop, the model's
        other seal coefficients (that seal's K, C, c and every other seal's) follow the
        pressure that gives k̂ (:func:`ambseal.model.seal.values_following_k`; default);
        False: they stay at the record's pressure. (Measurements: benchmarks/README.md, "Where the
        design defaults come from".)
    check_block_s, check_window_s : float
        The model-consistency test (:meth:`OnlineTracker.consistency`): its batch length
        (longer than the sensitivities' memory, the slowest closed-loop mode's few time
        constants, so that batch sums are nearly independent) and its window (30 batches:
        the Student t's tails close to the normal's).
    check_alpha : float
        False-refusal probability of one window's test of one held-known coefficient; the
        threshold is the F(1, m − 1) quantile at 1 − α/(number of coefficients)
        (Bonferroni). 1e-4: over a 30 s ramp (10 windows, three coefficients) a consistent
        model is refused with probability ≤ 0.3 %.
    check_bias_se : float
        The relevance of a significant window (:func:`held_error_check`): it refuses only
        when a held-known coefficient's error biases the estimate by more than this many
        of its standard errors. 1: a bias of one standard error lowers the coverage of
        the 95 % interval to 83 % (P(|Z + 1| < 1.96)), two to 48 %; below one the
        interval still covers ≥ 83 % and the tracker's stated accuracy holds, so the
        limit is the tracker's own interval, not a number about the rig.
    """

    rate_per_s: float = 0.1
    relinearise_s: float = 0.1
    regain_rel: float = 0.05
    sensor_noise_fraction: float = 0.01
    process_noise_a: float | None = None
    innovation_time_s: float = 0.05
    cutoff_hz: float | None = None
    initial_rel_std: float = 1.0
    inflation_window_s: float = 0.5
    min_duration_s: float = 0.5
    follow_pressure: bool = True
    check_block_s: float = 0.1
    check_window_s: float = 3.0
    check_alpha: float = 1e-4
    check_bias_se: float = 1.0


def _inflation(score: np.ndarray, info: np.ndarray, block: int, window: int) -> np.ndarray:
    """Causal variance-inflation factor ρ ≥ 1 per sample and parameter (N, p): the batch-means
    form of the sandwich covariance (Ljung, *System Identification*, §9.3). Over the blocks
    (``block`` samples) of the last ``window`` samples, ρ = mean (Σ_block score)² /
    mean Σ_block information — 1 for white innovations of the assumed covariance, larger
    when the innovations are coloured or the estimate lags (both leave a correlated score).
    Applied from the block after those it is computed from."""
    N, p = score.shape
    block = max(1, block)
    nb = N // block
    if nb < 2:
        return np.ones((N, p))
    S = score[: nb * block].reshape(nb, block, p).sum(axis=1)
    Inf = info[: nb * block].reshape(nb, block, p).sum(axis=1)
    m = max(1, window // block)
    c2 = np.concatenate([np.zeros((1, p)), np.cumsum(S**2, axis=0)])
    ci = np.concatenate([np.zeros((1, p)), np.cumsum(Inf, axis=0)])
    hi = np.arange(1, nb + 1)
    lo = np.maximum(0, hi - m)
    rho = (c2[hi] - c2[lo]) / np.maximum(ci[hi] - ci[lo], 1e-300)
    rho = np.maximum(np.vstack([np.ones((1, p)), rho[:-1]]), 1.0)  # causal: the past blocks
    out = np.repeat(rho, block, axis=0)
    return np.vstack([out, np.repeat(out[-1:], N - len(out), axis=0)])


@dataclass(frozen=True)
class TrackingResult:
    """The estimate at every sample.

    Attributes
    ----------
    names : tuple of str
    units : tuple of str
        The SI unit of each parameter.
    time_s : ndarray (N,)
    estimate, std_error : ndarray (N, p)
        θ̂ (SI) and its standard error after the update at each sample.
    initial : ndarray (p,)
    n_states : int
        States of the tracker's model.
    flops_per_sample : int
    wall_time_s, cpu_time_s : float
        Time of the recursion (after numba's compilation): elapsed, and this process's CPU
        time (the fair measure on a shared machine).
    """

    names: tuple[str, ...]
    units: tuple[str, ...]
    time_s: np.ndarray
    estimate: np.ndarray
    std_error: np.ndarray
    initial: np.ndarray
    n_states: int
    flops_per_sample: int
    wall_time_s: float
    cpu_time_s: float

    @property
    def realtime_factor(self) -> float:
        """Record duration over the process's CPU time of the recursion."""
        T = self.time_s[1] - self.time_s[0] if len(self.time_s) > 1 else 0.0
        return len(self.time_s) * T / max(self.cpu_time_s, 1e-12)

    def ci95(self) -> tuple[np.ndarray, np.ndarray]:
        """(low, high) of θ̂ ± 1.96 SE, each (N, p)."""
        return self.estimate - 1.96 * self.std_error, self.estimate + 1.96 * self.std_error


def flops_per_sample(n: int, k: int, m: int, p: int) -> int:
    """Multiply-adds ×2 of one RPEM sample: predictor (A_d x̂, B_d u, C x̂, K ε), per
    parameter the sensitivity recursion and ∂A_d x̂, ∂B_d u, H = C W, and the scalar updates
    of θ and P per channel (n states, k sensors, m inputs, p parameters)."""
    pred = 2 * (n * n + n * m + k * n + n * k)
    sens = p * 2 * (2 * n * n + n * m + k * n + n * k)
    upd = k * 2 * (2 * p * p + 2 * p) + 2 * p
    return pred + sens + upd


def _param_matrices(model: ClosedLoopModel, values: dict[str, float], names, dt: float,
                    expand=None, probes=()):
    """A_d, B_d, C at ``values`` and ∂A_d/∂θ_j, ∂B_d/∂θ_j (Van Loan's block exponential:
    expm([[M, E], [0, M]] T) has d expm(M T)/dθ in its upper-right block, M = [[A, B],
    [0, 0]], E = ∂M/∂θ). ``expand`` maps the tracked values to every value the model
    takes (the coefficients that follow a seal's k, :func:`_follower`); default none.
    ``probes``: held-known parameters whose derivatives follow those of ``names`` (taken
    about the expanded values: the score test of :meth:`OnlineTracker.consistency`)."""
    expand = expand or dict
    full = expand(values)
    A, B, C, _, _ = model.matrices(full)
    n, m = B.shape
    M = np.zeros((n + m, n + m))
    M[:n, :n], M[:n, n:] = A, B
    E0 = sla.expm(M * dt)
    dA, dB = [], []
    for name in (*names, *probes):
        if name in probes:
            v0 = float(full.get(name, model.plant.parameter(name).nominal))
            h = 1e-6 * max(abs(v0), 1.0)
            Ap, Bp, _, _, _ = model.matrices({**full, name: v0 + h})
        else:
            h = 1e-6 * max(abs(values[name]), 1.0)
            Ap, Bp, _, _, _ = model.matrices(expand({**values, name: values[name] + h}))
        dM = np.zeros_like(M)
        dM[:n, :n], dM[:n, n:] = (Ap - A) / h, (Bp - B) / h  # exact for an LFT (affine in θ)
        big = np.block([[M, dM], [np.zeros_like(M), M]]) * dt
        D = sla.expm(big)[: n + m, n + m:]
        dA.append(D[:n, :n])
        dB.append(D[:n, n:])
    return E0[:n, :n], E0[:n, n:], C, np.array(dA), np.array(dB)


def _follower(cfg: RigConfig, model: ClosedLoopModel, names):
    """values → the values with the seal coefficients that follow the tracked seal k's
    (:func:`ambseal.model.seal.values_following`; the tracked values themselves win), or
    None when no tracked name is a seal k affine in the pressure."""

    known = model.plant.parameters
    if all(pressure_for_k(cfg.seal, n, 0.0) is None for n in names):
        return None

    def expand(values: dict) -> dict:
        return values_following(cfg.seal, values, known)

    return expand


def score_test(score: np.ndarray, block: int, window: int, alpha: float):
    """The batch-means score test of :meth:`OnlineTracker.consistency` on a score record.

    Parameters
    ----------
    score : ndarray (N, r)
        Per sample, the score of each of r held-known parameters (Hᵀ Λ⁻¹ ε).
    block : int
        Samples per batch.
    window : int
        Batches per window (≥ 2); the windows are consecutive from sample 0, a last
        incomplete one left out.
    alpha : float
        False-refusal probability of one window for one parameter.

    Returns
    -------
    threshold : float
        The F(1, window − 1) quantile at 1 − α/r (Bonferroni over the r parameters).
    windows : list of (int, int, ndarray (r,), bool)
        Per window its first and past-the-end samples, t² = window · mean² / var of its
        batch sums (Student's t² with window − 1 degrees of freedom when the score has
        mean zero and batch sums are independent; source: Student 1908, and the batch
        means of Law & Kelton, *Simulation Modeling and Analysis*, 3rd ed., 2000, §9.5.3)
        and whether any t² exceeds the threshold.
    """
    score = np.asarray(score, float)
    N, r = score.shape
    block, window = max(1, int(block)), max(2, int(window))
    thr = float(stats.f.ppf(1.0 - alpha / max(r, 1), 1, window - 1))
    nb = N // block
    S = score[: nb * block].reshape(nb, block, r).sum(axis=1)
    out = []
    for w in range(nb // window):
        Sw = S[w * window:(w + 1) * window]
        var = np.maximum(np.var(Sw, axis=0, ddof=1), 1e-300)
        t2 = window * np.mean(Sw, axis=0) ** 2 / var
        out.append((w * window * block, (w + 1) * window * block, t2, bool(np.any(t2 > thr))))
    return thr, out


def held_error_check(score: np.ndarray, info: np.ndarray, cross: np.ndarray, se: np.ndarray,
                     block: int, window: int, alpha: float, max_bias_se: float):
    """The consistency test of :meth:`OnlineTracker.consistency`: :func:`score_test`'s
    significance, and the relevance of each held-known coefficient's error.

    In each window (sums over its samples) the error of held-known θ_j is the Gauss–Newton
    step of the model with θ_j freed beside the tracked θ_T, whose score is ≈ 0 at θ̂_T:
    δ_j = s_j / (I_jj − I_jTᵀ I_TT⁻¹ I_Tj), the efficient score over the efficient
    information (Engle 1984, §4; with the profiled information so that δ_j is the joint
    fit's, not the smaller one-at-a-time step). The bias that error leaves in θ̂_T is the
    omitted-variable bias of least squares, b_T = θ̂_T − θ_T = I_TT⁻¹ I_Tj δ_j (Ljung,
    *System Identification*, 2nd ed., 1999, §8.3 and §9.3: the limit of a prediction-
    error estimate under a misspecified model; Greene, *Econometric Analysis*, 7th ed.,
    §4.3.2). The signs: H = ∂ŷ/∂θ, δ_j = true − model.

    Parameters
    ----------
    score, info : ndarray (N, r)
        Per sample, each held-known parameter's score Hᵀ Λ⁻¹ ε and information Hᵀ Λ⁻¹ H.
    cross : ndarray (N, t, t + r)
        Per sample, the information of the t tracked parameters with the tracked ones and
        then with the r held-known ones.
    se : ndarray (N, t)
        The tracked estimates' standard errors; their mean over a window is the scale.
    block, window : int
        Samples per batch and batches per window (:func:`score_test`).
    alpha : float
        False-refusal probability of one window's significance test for one parameter.
    max_bias_se : float
        The largest tolerated |b| of a tracked estimate, in its standard errors.

    Returns
    -------
    threshold : float
        :func:`score_test`'s F quantile.
    windows : list of dict
        Per window ``start``, ``stop`` (samples), ``t2`` (r,) the score statistics,
        ``delta`` (r,) the errors δ_j (SI), ``bias_se`` (r,) the largest |b| over the
        tracked parameters in their standard errors, and ``refused``: some coefficient
        both significant (t² above the threshold) and relevant (``bias_se`` above
        ``max_bias_se``).
    """
    score, info = np.asarray(score, float), np.asarray(info, float)
    cross, se = np.asarray(cross, float), np.asarray(se, float)
    nt = cross.shape[1]
    thr, sig = score_test(score, block, window, alpha)
    out = []
    for a, e, t2, _ in sig:
        S, Ijj, C = score[a:e].sum(axis=0), info[a:e].sum(axis=0), cross[a:e].sum(axis=0)
        coef = np.linalg.pinv(C[:, :nt]) @ C[:, nt:]  # I_TT⁻¹ I_Tj, (t, r)
        eff = Ijj - np.sum(C[:, nt:] * coef, axis=0)
        delta = S / np.maximum(eff, 1e-12 * np.maximum(Ijj, 1e-300))
        scale = np.maximum(np.mean(se[a:e], axis=0), 1e-300)
        bias_se = np.max(np.abs(coef * delta) / scale[:, None], axis=0)
        out.append({"start": a, "stop": e, "t2": t2, "delta": delta, "bias_se": bias_se,
                    "refused": bool(np.any((t2 > thr) & (bias_se > max_bias_se)))})
    return thr, out


def _probes(cfg: RigConfig, model: ClosedLoopModel, names) -> tuple[str, ...]:
    """The coefficients the tracker holds known and checks (:meth:`OnlineTracker.
    consistency`): for each tracked ``<seal>.k`` of a ``[[seal]]``, that seal's K, C, c
    that are parameters of the model and not tracked."""
    seals = {q.name for q in cfg.seal}
    known = model.plant.parameters
    out = []
    for n in names:
        seal, _, coef = n.rpartition(".")
        if coef == "k" and seal in seals:
            out += [f"{seal}.{c}" for c in ("K", "C", "c")
                    if f"{seal}.{c}" in known and f"{seal}.{c}" not in names]
    return tuple(dict.fromkeys(out))


def _scales(cfg: RigConfig, model: ClosedLoopModel, names) -> np.ndarray:
    """Each parameter's scale: the larger |value| in the model and at the rig's operating
    pressure (a seal's k is 0 at zero pressure drop), at least the fit's default scale of
    its unit."""
    op = mechanical_plant(build_system(cfg, pressure_bar=cfg.operating.pressure_bar))
    out = []
    for name in names:
        p = model.plant.parameter(name)
        at_op = abs(op.parameters[name].nominal) if name in op.parameters else 0.0
        out.append(max(abs(p.nominal), at_op, _DEFAULT_SCALE.get(p.unit, 0.0), 1e-12))
    return np.array(out)


def _predictor_gain(Ad, Bd, C, sigma_y, sigma_u):
    """Steady-state Kalman predictor gain K (x̂⁺ = A x̂ + B u + K ε) for input-referred
    process noise σ_u (A) and sensor noise σ_y (m) per channel (DARE)."""
    n = Ad.shape[0]
    Q = Bd @ np.diag(sigma_u**2) @ Bd.T + 1e-9 * np.trace(Bd @ Bd.T) / n * np.eye(n) \
        * float(np.mean(sigma_u**2))
    R = np.diag(sigma_y**2)
    try:
        X = sla.solve_discrete_are(Ad.T, C.T, Q, R)
    except (np.linalg.LinAlgError, ValueError) as exc:
        raise IdentificationError(f"track: no steady-state predictor at this estimate "
                                  f"({exc}); the model is not detectable") from None
    return Ad @ X @ C.T @ np.linalg.inv(C @ X @ C.T + R)


def rpem_kernel(y, u, Ad, Bd, C, K, dA, dB, theta0, x, W, theta, P, lam, q, g,
                est, se, score, info, cross, start, stop):
    """Samples ``start:stop`` of the RPEM recursion (module docstring), in place on x (n,),
    W (p, n), θ (p,), P (p, p), Λ (k,); θ̂, SE, the score Hᵀ Λ⁻¹ ε and the information
    diag(Hᵀ Λ⁻¹ H) written to rows of ``est``, ``se``, ``score``, ``info`` (N, p), and the
    first ``cross.shape[1]`` (= t) rows of the information Hᵀ Λ⁻¹ H to ``cross`` (N, t, p):
    the tracked parameters' information with every parameter (the consistency test's
    relevance, :func:`held_error_check`). Plain loops so that numba compiles it (the
    interpreted form is the benchmark's baseline)."""
    n, k, p = Ad.shape[0], C.shape[0], theta.shape[0]
    nt = cross.shape[1]
    xn = np.empty(n)
    Wn = np.empty((p, n))
    eps = np.empty(k)
    H = np.empty((k, p))
    dx = np.empty((p, n))
    ph = np.empty(p)
    th0 = np.empty(p)
    for t in range(start, stop):
        for j in range(p):
            th0[j] = theta[j]
            score[t, j] = 0.0
            info[t, j] = 0.0
            for a in range(nt):
                cross[t, a, j] = 0.0
        for i in range(k):  # innovation
            s = y[t, i]
            for a in range(n):
                s -= C[i, a] * x[a]
            eps[i] = s
        _predict(u, t, Ad, Bd, C, K, dA, dB, theta0, x, W, theta, eps, dx, xn, H, Wn)
        for i in range(k):  # Λ, then one scalar Kalman update per channel
            _channel_update(i, t, H, eps, lam, g, P, theta, th0, ph, score, info, cross)
        for j in range(p):
            P[j, j] += q[j]
            est[t, j] = theta[j]
            se[t, j] = np.sqrt(P[j, j])
        for a in range(n):
            x[a] = xn[a]
            for j in range(p):
                W[j, a] = Wn[j, a]


@register_jitable
def _predict(u, t, Ad, Bd, C, K, dA, dB, theta0, x, W, theta, eps, dx, xn, H, Wn):
    """Sample ``t``'s prediction (:func:`rpem_kernel`): ∂A x̂ + ∂B u into ``dx``, the
    predictor at θ̂ (first order about θ₀) into ``xn``, H = C W and the sensitivity
    recursion into ``H`` and ``Wn``."""
    n, k, m, p = Ad.shape[0], C.shape[0], Bd.shape[1], theta.shape[0]
    for j in range(p):  # ∂A x̂ + ∂B u
        for a in range(n):
            s = 0.0
            for b in range(n):
                s += dA[j, a, b] * x[b]
            for b in range(m):
                s += dB[j, a, b] * u[t, b]
            dx[j, a] = s
    for a in range(n):  # predictor at θ̂ (first order about θ₀)
        s = 0.0
        for b in range(n):
            s += Ad[a, b] * x[b]
        for b in range(m):
            s += Bd[a, b] * u[t, b]
        for i in range(k):
            s += K[a, i] * eps[i]
        for j in range(p):
            s += (theta[j] - theta0[j]) * dx[j, a]
        xn[a] = s
    for j in range(p):  # H = C W, then the sensitivity recursion
        for i in range(k):
            s = 0.0
            for a in range(n):
                s += C[i, a] * W[j, a]
            H[i, j] = s
        for a in range(n):
            s = dx[j, a]
            for b in range(n):
                s += Ad[a, b] * W[j, b]
            for i in range(k):
                s -= K[a, i] * H[i, j]
            Wn[j, a] = s


@register_jitable
def _channel_update(i, t, H, eps, lam, g, P, theta, th0, ph, score, info, cross):
    """Channel ``i``'s part of sample ``t`` (:func:`rpem_kernel`): its Λ, score,
    information and cross-information, then its scalar Kalman update of θ̂ and P."""
    p, nt = theta.shape[0], cross.shape[1]
    lam[i] += g * (eps[i] * eps[i] - lam[i])
    s = lam[i]
    for j in range(p):
        v = 0.0
        for jj in range(p):
            v += P[j, jj] * H[i, jj]
        ph[j] = v
        s += H[i, j] * v
    for j in range(p):
        score[t, j] += H[i, j] * eps[i] / lam[i]
        info[t, j] += H[i, j] * H[i, j] / lam[i]
        for a in range(nt):
            cross[t, a, j] += H[i, a] * H[i, j] / lam[i]
    r = eps[i]  # the residual at the θ̂ already updated by earlier channels
    for j in range(p):
        r -= H[i, j] * (theta[j] - th0[j])
    for j in range(p):
        theta[j] += ph[j] * r / s
    for j in range(p):
        for jj in range(p):
            P[j, jj] -= ph[j] * ph[jj] / s


_JIT = {}


def _kernel(compiled: bool):
    """The kernel, compiled by numba once per process when ``compiled``."""
    if not compiled:
        return rpem_kernel
    if "k" not in _JIT:
        _JIT["k"] = numba.njit(cache=False, fastmath=False)(rpem_kernel)
    return _JIT["k"]


def linearised_model(cfg: RigConfig, record: Measurement, names, settings: TrackingSettings,
                     source: str = "<data>", controller=None) -> ClosedLoopModel:
    """The tracker's model of ``record``: the rig at its pressure and speed, reduced to
    ``settings.cutoff_hz`` (default the Nyquist frequency), every name checked."""
    fs = 1.0 / float(np.mean(np.diff(record.time_s)))
    cutoff = settings.cutoff_hz or fs / 2
    model = build_models(cfg, [record], cutoff_hz=cutoff, sources=[source],
                         controllers=None if controller is None else [controller])[0]
    for n in names:
        try:
            model.plant.parameter(n)
        except ModelError as exc:
            raise IdentificationError(f"track: {exc} (an LFT parameter of the rig)") from None
    return model


def track(cfg: RigConfig, record: Measurement, names, settings: TrackingSettings | None = None,
          *, initial: dict | None = None, compiled: bool = True, source: str = "<data>",
          controller=None) -> TrackingResult:
    """Track parameters ``names`` through ``record`` (module docstring: the RPEM).

    Parameters
    ----------
    cfg : RigConfig
        The rig; its model at the record's metadata pressure and speed starts the tracker.
    record : Measurement
        Displacements (m) and current references (A) at a constant sample rate.
    names : sequence of str
        LFT parameters of the rig's model, e.g. ``"seal.k"`` (:meth:`Plant.parameter`).
    settings : TrackingSettings, optional
        The tracker's tuning; the defaults of :class:`TrackingSettings` if omitted.
    initial : dict, optional
        Starting values (SI); default the model's values at the record's pressure.
    compiled : bool
        Run the kernel compiled by numba (False: interpreted, the benchmark's baseline).
    source : str
        The record's name (its file), in errors.
    controller : DiscreteController, optional
        The controller that ran; by default from the record's metadata.

    Returns
    -------
    TrackingResult
        The estimate (SI) at every sample with its standard error, and the recursion's
        flops per sample and time.

    Raises
    ------
    IdentificationError
        A name without an LFT channel, a record shorter than the model's settling
        (``min_duration_s``), a non-detectable model.
    """
    s = settings or TrackingSettings()
    names = tuple(names)
    if not names:
        raise IdentificationError("track: no parameter to track (--params NAME,...)")
    t = np.asarray(record.time_s, float)
    if len(t) < 3:
        raise IdentificationError(f"{source}: record too short to track from ({len(t)} samples)")
    dt = float(np.mean(np.diff(t)))
    need = s.min_duration_s
    if len(t) * dt < need:
        raise IdentificationError(f"{source}: record too short to track from: "
                                  f"{len(t) * dt:.3g} s, need at least {need:.3g} s")
    model = linearised_model(cfg, record, names, s, source, controller)
    y = np.ascontiguousarray(record.displacement_m, float)
    u = np.ascontiguousarray(record.current_ref_a, float)
    tr = OnlineTracker(cfg, model, names, dt, y, u, s, initial=initial, compiled=compiled)
    t0, c0 = time.perf_counter(), time.process_time()
    tr.update(y, u, source)
    wall, cpu = time.perf_counter() - t0, time.process_time() - c0
    return tr.result(t, wall, cpu)


class OnlineTracker:
    """The RPEM of :func:`track` fed block by block, as it runs beside a controller (the
    closed-loop pressure ramp): the state x̂, the sensitivities W, θ̂, P and Λ are
    carried from one :meth:`update` to the next, and feeding a record in any blocks gives
    the same estimate as :func:`track` on the whole record.

    Parameters
    ----------
    cfg : RigConfig
        The rig; its model at the operating pressure sets each parameter's scale.
    model : ClosedLoopModel
        The tracker's model (:func:`linearised_model`).
    names : sequence of str
        LFT parameters of the model to track, e.g. ``"seal.k"``.
    dt : float
        Sample time (s).
    y0, u0 : ndarray (N0, k), (N0, m)
        A stretch of displacements (m) and current references (A) that sets the
        predictor's noise levels (their RMS, as in :func:`track`).
    settings : TrackingSettings
        The tracker's tuning.
    initial : dict, optional
        Starting values (SI); default the model's values.
    compiled : bool
        Run the kernel compiled by numba (False: interpreted).
    """

    def __init__(self, cfg: RigConfig, model: ClosedLoopModel, names, dt: float, y0, u0,
                 settings: TrackingSettings, *, initial: dict | None = None,
                 compiled: bool = True):
        s = self.settings = settings
        self.model, self.names, self.dt = model, tuple(names), float(dt)
        self.probes = _probes(cfg, model, self.names)
        self.scale = _scales(cfg, model, self.names)
        p, r = len(self.names), len(self.probes)
        # θ, P and Q_θ carry the probes after the tracked values: θ = θ₀ = 0 and no
        # variance, so they never move and never change the prediction; the kernel
        # still forms their sensitivities and scores (the consistency test).
        self.theta = np.array([float((initial or {}).get(n, model.plant.parameter(n).nominal))
                               for n in self.names] + [0.0] * r)
        self.initial = self.theta[:p].copy()
        sig = s.sensor_noise_fraction * np.sqrt(np.mean(np.asarray(y0) ** 2, axis=0))
        self.sigma_y = np.where(sig > 0, sig, 1e-9)
        self.sigma_u = np.full(np.shape(u0)[1], s.process_noise_a if s.process_noise_a
                               is not None else max(0.01 * float(np.sqrt(np.mean(
                                   np.asarray(u0) ** 2))), 1e-6))
        self.P = np.zeros((p + r, p + r))
        self.P[:p, :p] = np.diag((s.initial_rel_std * self.scale) ** 2)
        self.q = np.r_[(s.rate_per_s * self.scale) ** 2 * dt, np.zeros(r)]
        self.lam = self.sigma_y**2 * 1.0
        self.g = min(1.0, dt / s.innovation_time_s)
        self.chunk = max(1, int(round(s.relinearise_s / dt)))
        self.kern = _kernel(compiled)
        self.expand = _follower(cfg, model, self.names) if s.follow_pressure else None
        self._since = 0  # samples since the last re-linearisation
        self.x = self.W = self.K = self.theta_K = self.mats = None
        self._rows: list = []
        self.refused_at_s: float | None = None
        self.refusal = ""
        if compiled:  # compile outside the timing
            Ad, Bd, C, dA, dB = self._matrices()
            z = np.zeros((1, p + r))
            self.kern(np.zeros((1, C.shape[0])), np.zeros((1, Bd.shape[1])), Ad, Bd, C,
                      np.zeros(C.T.shape), dA, dB, self.theta.copy(), np.zeros(len(Ad)),
                      np.zeros((p + r, len(Ad))), self.theta.copy(), self.P.copy(),
                      self.lam.copy(), self.q, self.g, z.copy(), z.copy(), z.copy(), z.copy(),
                      np.zeros((1, p, p + r)), 0, 0)

    def _matrices(self):
        return _param_matrices(self.model, dict(zip(self.names, self.theta)), self.names,
                               self.dt, self.expand, self.probes)

    def _relinearise(self):
        Ad, Bd, C, dA, dB = self._matrices()
        p = len(self.names)
        if self.x is None:
            self.x, self.W = np.zeros(Ad.shape[0]), np.zeros((len(self.theta), Ad.shape[0]))
        if self.K is None or np.any(np.abs(self.theta[:p] - self.theta_K)
                                    > self.settings.regain_rel * self.scale):
            self.K = _predictor_gain(Ad, Bd, C, self.sigma_y, self.sigma_u)
            self.theta_K = self.theta[:p].copy()
        self.mats = (Ad, Bd, C, self.K, dA, dB, self.theta.copy())

    def update(self, y, u, source: str = "<data>") -> np.ndarray:
        """Run the recursion over ``y`` (N, k) and ``u`` (N, m); returns θ̂ after the last
        sample (p,), and refuses (:attr:`refused_at_s`, :attr:`refusal`) at the first
        window whose consistency test fails (:meth:`consistency`). Raises
        IdentificationError when the estimate diverges."""
        y, u = np.ascontiguousarray(y, float), np.ascontiguousarray(u, float)
        N, p = len(y), len(self.theta)
        rows = [np.empty((N, p)) for _ in range(4)] + [np.empty((N, len(self.names), p))]
        start = 0
        while start < N:
            if self.mats is None or self._since >= self.chunk:
                self._relinearise()
                self._since = 0
            stop = min(N, start + self.chunk - self._since)
            Ad, Bd, C, K, dA, dB, th0 = self.mats
            self.kern(y, u, Ad, Bd, C, K, dA, dB, th0, self.x, self.W, self.theta, self.P,
                      self.lam, self.q, self.g, *rows, start, stop)
            if not np.all(np.isfinite(self.theta)):
                raise IdentificationError(f"{source}: track: the estimate diverged after "
                                          f"{(self.samples + start) * self.dt:.3f} s")
            self._since += stop - start
            start = stop
        self._rows.append(rows)
        if self.refused_at_s is None and self.probes:
            check = self.consistency()
            for w in check["windows"]:
                if w["refused"]:
                    self.refused_at_s = w["end_s"]
                    worst = max(w["bias_se"], key=lambda q: w["bias_se"][q]
                                if w["statistic"][q] > check["threshold"] else -1.0)
                    self.refusal = (
                        f"its model cannot explain the data: the score of the held-known "
                        f"{worst} is {w['statistic'][worst]:.3g} (F test over "
                        f"{w['start_s']:.3g}–{w['end_s']:.3g} s; threshold "
                        f"{check['threshold']:.3g} at α = {self.settings.check_alpha:g}), and "
                        f"its error {w['delta'][worst]:.3g} biases the estimate by "
                        f"{w['bias_se'][worst]:.3g} standard errors (limit "
                        f"{self.settings.check_bias_se:g}): its interval no longer covers")
                    break
        return self.theta[:len(self.names)].copy()

    @property
    def samples(self) -> int:
        """Samples fed so far."""
        return sum(len(r[0]) for r in self._rows)

    def consistency(self) -> dict:
        """The model-consistency test over every complete window fed so far: a Rao score
        (Lagrange-multiplier) test that the coefficients the tracker holds known — the
        tracked seal's K, C, c (:attr:`probes`) — are right.

        Under a right model the score of a held-known coefficient θ_r, s_t = H_rᵀ Λ⁻¹ ε_t
        (H_r = C W_r its output sensitivity, computed by the kernel beside the tracked
        ones), has mean zero (Rao 1948; Engle, *Handbook of Econometrics* II, 1984, ch. 13
        §4; Ljung, *System Identification*, 2nd ed., 1999, §16.6: a model is validated by
        residuals uncorrelated with what they should not depend on). A coefficient that is
        off leaves in ε a part of the response the model cannot make, which the tracked k̂
        absorbs only in part: s_t then has a non-zero mean and k̂ a bias the standard error
        does not show. The innovations are not white (the predictor's gain is fixed between
        re-linearisations), so the score's variance is that of batch means: over a window of
        m batches of ``check_block_s`` with sums S_b, t = √m · mean S / sd S is Student's t
        with m − 1 degrees of freedom under the right model, and the window refuses when
        t² exceeds the F(1, m − 1) quantile at 1 − α/r for any of the r coefficients
        (``check_alpha``, Bonferroni). Windows are consecutive, the first after
        ``min_duration_s`` (the predictor's start).

        A significant score alone does not refuse: with enough data the test finds an error
        of any size, also one too small to matter (the test rig's identified model, its
        coefficients ≤ 0.2 % off, fails it at 21.5 s of the ramp with the estimate's
        interval still covering the truth 99.99 % of the time). A window refuses only
        when the error is also relevant (:func:`held_error_check`): the bias it causes in
        the estimate exceeds ``check_bias_se`` of the estimate's own standard error.

        Returns
        -------
        dict
            ``probes`` (names), ``threshold`` (the F quantile), ``windows``: per window
            ``start_s``, ``end_s``, ``statistic`` (name → t²), ``delta`` (name → the
            coefficient's error, SI), ``bias_se`` (name → the largest bias it causes in a
            tracked estimate, in that estimate's standard errors) and ``refused``.
        """
        s = self.settings
        p, r = len(self.names), len(self.probes)
        b = max(1, int(round(s.check_block_s / self.dt)))
        m = max(2, int(round(s.check_window_s / s.check_block_s)))
        n0 = int(round(s.min_duration_s / self.dt))
        if not self._rows:
            return {"probes": list(self.probes), "threshold": float(
                stats.f.ppf(1.0 - s.check_alpha / max(r, 1), 1, m - 1)), "windows": []}
        score, info = (np.vstack([rows[i][:, p:] for rows in self._rows]) for i in (2, 3))
        cross = np.concatenate([rows[4] for rows in self._rows])
        se = self._standard_error()
        thr, windows = held_error_check(score[n0:], info[n0:], cross[n0:], se[n0:], b, m,
                                        s.check_alpha, s.check_bias_se)
        return {"probes": list(self.probes), "threshold": thr, "windows": [
            {"start_s": (n0 + w["start"]) * self.dt, "end_s": (n0 + w["stop"]) * self.dt,
             "statistic": dict(zip(self.probes, map(float, w["t2"]))),
             "delta": dict(zip(self.probes, map(float, w["delta"]))),
             "bias_se": dict(zip(self.probes, map(float, w["bias_se"]))),
             "refused": w["refused"]} for w in windows]}

    def _standard_error(self) -> np.ndarray:
        """The tracked parameters' standard error at every sample fed (N, p), with the
        causal variance inflation of :func:`_inflation`."""
        p, s = len(self.names), self.settings
        se, score, info = (np.vstack([r[i][:, :p] for r in self._rows]) for i in (1, 2, 3))
        return se * np.sqrt(_inflation(score, info, int(round(s.innovation_time_s / self.dt)),
                                       int(round(s.inflation_window_s / self.dt))))

    def result(self, time_s, wall_s: float = 0.0, cpu_s: float = 0.0) -> TrackingResult:
        """Everything fed so far as a :class:`TrackingResult` (the standard error with the
        causal variance inflation of :func:`_inflation`)."""
        p = len(self.names)
        est = np.vstack([r[0][:, :p] for r in self._rows])
        se = self._standard_error()
        n = self.x.shape[0]
        units = tuple(self.model.plant.parameter(q).unit for q in self.names)
        k, m = self.mats[2].shape[0], self.mats[1].shape[1]
        return TrackingResult(self.names, units, np.asarray(time_s, float), est, se,
                              self.initial, n, flops_per_sample(n, k, m, len(self.theta)),
                              wall_s, cpu_s)


def current_limit(cfg: RigConfig, meta: dict | None = None) -> float | None:
    """The amplifiers' current limit (A): a record's ``current_limit_a``, else the smallest
    ``current_limit`` of the rig's AMBs, else None."""
    if meta and meta.get("current_limit_a"):
        return float(meta["current_limit_a"])
    limits = [a.current_limit for a in cfg.amb if a.current_limit]
    return min(limits) if limits else None


def check_excitation(cfg: RigConfig, record: Measurement, source: str = "<data>") -> None:
    """DataError when the record's excitation exceeds the current limit.

    Parameters
    ----------
    cfg : RigConfig
        The rig (its AMBs' current limits).
    record : Measurement
        The record; its metadata may state the limit.
    source : str, optional
        The record's file, for the message.

    Raises
    ------
    DataError
        A peak excitation current above the limit (none is checked without a limit).
    """
    limit = current_limit(cfg, dict(record.metadata))
    peak = float(np.max(np.abs(record.excitation_a))) if np.size(record.excitation_a) else 0.0
    if limit is not None and peak > limit:
        raise DataError(f"{source}: excitation_a: peak {peak:.3g} A exceeds the current limit "
                        f"{limit:.3g} A")


def tracking_excitation(cfg: RigConfig, duration_s: float, *, amplitude_a: float | None = None,
                        clock_period_s: float | None = None, seed: int = 0):
    """The tracker's persistent excitation: a PRBS on every axis (:func:`signals.prbs`).

    Defaults: amplitude 1 % of the current limit (0.06 A on a 6 A amplifier, the thesis's
    PRBS level of P2 Fig. 5 halved: small against the bias and the limit), clock period ten
    samples (flat spectrum to ≈ 0.044 f_s, past the rigid-body and first bending modes).

    Parameters
    ----------
    cfg : RigConfig
        The rig (its axes, current limit and controller sample rate).
    duration_s : float
        Length of the excitation (s).
    amplitude_a : float, optional
        PRBS amplitude (A).
    clock_period_s : float, optional
        PRBS clock period (s).
    seed : int, optional
        Seed of the sequence.

    Returns
    -------
    Excitation
        The excitation currents on every axis (:func:`ambseal.identify.excitation.signals.prbs`).

    Raises
    ------
    IdentificationError
        An amplitude above the current limit, or no limit and no amplitude.
    """

    fs = cfg.controller.sample_rate_hz
    limit = current_limit(cfg)
    if amplitude_a is None:
        if limit is None:
            raise IdentificationError("track: the rig states no current_limit; give the "
                                      "excitation amplitude (A)")
        amplitude_a = 0.01 * limit
    if limit is not None and amplitude_a > limit:
        raise IdentificationError(f"track: excitation amplitude {amplitude_a:.3g} A exceeds "
                                  f"the current limit {limit:.3g} A")
    return prbs(amplitude_a=amplitude_a,
                clock_period_s=clock_period_s or PRBS_CLOCK_SAMPLES / fs,
                duration_s=duration_s, sample_rate_hz=fs, axes=channel_names(cfg), seed=seed)
