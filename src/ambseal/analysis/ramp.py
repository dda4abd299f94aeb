"""A pressure ramp on the virtual facility with fixed controllers and the tracked scheme: the on-line estimator and the controller scheduled on its estimate running
together in the sampled, nonlinear loop.

The facility (:mod:`ambseal.identify.facility.rig_sim`: nonlinear AMB forces, amplifier limits,
eddy lag, sensor noise, ADC, the digital controller at the rig's rate) runs a
piecewise-constant pressure drop from 0 to ``top_factor``× nominal in ``step_s`` steps;
the same excitation — the tracker's PRBS (:func:`~ambseal.identify.tracking.
tracking_excitation`) plus the thesis's current impulse (P5 §5.1, the specification's
amplitude and length on the first actuator axis) every ``impulse_every_s`` — and the same
noise sequence go into every run, so the runs differ only by their controller.

The tracked scheme runs in blocks of ``block_s``: at the start of each block the
controller that runs is the digital table (:class:`~ambseal.machine.scheduled_digital.
ScheduledDigital`, ``tracked_digital``: the exported, judged discretisation) interpolated
at the scheduling value, or without a table the scheduled controller frozen there and
discretised by zero-order hold (Tustin made every frozen discrete loop of the test rig's
design unstable, |z| = 1.0008–1.0017 without delay, and lost the rotor at 1.36× even
scheduled on the true k); the controller state is carried across the switch, the block is
run, and the tracker
(:class:`~ambseal.identify.tracking.OnlineTracker`, started at the model's value at the
starting pressure) is fed the block's displacements and current references. The
scheduling value follows the estimate at the end of the previous block (causal, as on the
target) within the design's rate bound ν and its schedule: the LPV guarantee holds only
for |θ̇| ≤ ν, and an estimate jumps (at an impulse) faster than that. The tracker's model
is built from ``model_cfg``, the identified rig: on the test rig's ramp (seeds 0, 1, 2)
the estimate is then within 0.028–0.030 k_nom of the truth after 1 s and its 95 %
interval covers the truth 99.9 % of the time; built from the rig file (τ_e = 0, Ki, Ks a
few per cent off) 0.60 k_nom and 88 % (:mod:`ambseal.identify.tracking`, "The model must
be the identified one").

The tracker checks its own model as it runs (:meth:`~ambseal.identify.tracking.
OnlineTracker.consistency`: a score test, every 3 s window, that the seal's held-known K,
C, c explain the data). When it refuses, its estimate is biased beyond its interval, so
the tracked run hands over to the ``fallback`` fixed controller (μ) at the next block,
from rest, for the rest of the ramp; the tracker keeps running so that its accuracy is
still reported. ``tracking`` then says ``refused``, ``refused_at_s``, ``refusal`` (why),
``fallback`` and ``fallback_from_s``, with the test's ``check_threshold``, each
coefficient's largest statistic ``check_largest`` and the largest bias its error causes in
k̂, in k̂'s standard errors, ``check_largest_bias_se`` (a window refuses when both exceed
their limits).

Every controller runs with ``delay_samples`` of computation delay (the target's,
``[controller] delay_samples``; 0: the facility's own timing, output in the sample its
input was read).

Per impulse: the peak |y| on the impulse axis within 30 impulse lengths, and the settling
time, after which |y| stays inside max(2 % of the peak, 3× the std of the 50 ms before
the impulse: noise and the PRBS's response); None when it never does within the window,
and None ("n/a", ``impulse_above_background`` False) when |y| never leaves that band: the
impulse's response is then not told apart from the background and has no settling time
(not 0 s).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ambseal.analysis.judge import JudgeSettings, OperatingPoint, judge
from ambseal.errors import ModelError
from ambseal.identify import (
    ClosedLoopModel,
    OnlineTracker,
    TrackingSettings,
    prepare_facility,
    pressure_values,
    reduced_plant,
    tracking_excitation,
    true_rig,
)
from ambseal.model import actuator_matrices, build_plant
from ambseal.robust import DiscreteController, discretize_as, with_delay

__all__ = ["RampRun", "RampResult", "pressure_ramp", "ramp_simulation", "frozen_cases"]


@dataclass(frozen=True)
class RampRun:
    """One controller along the ramp (records decimated to ``RampResult.time_s``).

    Attributes
    ----------
    name : str
    displacement_um, current_a : ndarray (n, k)
        Measured displacement (µm) and current reference (A) per axis; NaN after a loss.
    lost_at_s : float or None
        When the rotor left 90 % of the air gap (the loop went unstable), else None.
    impulse_peak_um, impulse_settling_s : list
        Per impulse (None after a loss, or a settling never reached in the window, or
        not measurable: see ``impulse_above_background``).
    estimate, ci95_low, ci95_high : ndarray (n,) or None
        The tracked scheme's k̂ and its 95 % interval (SI).
    impulse_above_background : list of bool
        Per impulse: its response left the background band (module docstring); False: its
        settling time is n/a.
    """

    name: str
    displacement_um: np.ndarray = field(repr=False)
    current_a: np.ndarray = field(repr=False)
    lost_at_s: float | None
    impulse_peak_um: list
    impulse_settling_s: list
    estimate: np.ndarray | None = field(default=None, repr=False)
    ci95_low: np.ndarray | None = field(default=None, repr=False)
    ci95_high: np.ndarray | None = field(default=None, repr=False)
    impulse_above_background: list = field(default_factory=list)


@dataclass(frozen=True)
class RampResult:
    """The ramp and every run; ``time_s``, ``pressure_bar`` and ``k_true`` decimated to
    ``record_hz``; ``tracking`` the estimator's accuracy (``max_error_rel`` of the nominal
    k after ``transient_s``, ``coverage`` of the 95 % interval).

    Attributes
    ----------
    parameter : str
        The seal parameter that follows the pressure, e.g. ``"seal.k"``.
    time_s : ndarray (n,)
        Record times (s).
    pressure_bar : ndarray (n,)
        Pressure drop along the ramp (bar).
    k_true : ndarray (n,)
        The facility's true value of ``parameter`` along the ramp (SI).
    k_nominal : float
        Its magnitude at the rig's operating pressure (SI), the scale of the errors.
    impulse_times_s : list of float
        Start of every current impulse (s).
    axes : tuple of str
        The actuator axes of the records.
    runs : dict of str to RampRun
        Every controller's run, ``"tracked"`` for the scheduled one with the estimator.
    tracking : dict
        The estimator's accuracy; empty without a tracked controller.
    """

    parameter: str
    time_s: np.ndarray = field(repr=False)
    pressure_bar: np.ndarray = field(repr=False)
    k_true: np.ndarray = field(repr=False)
    k_nominal: float
    impulse_times_s: list
    axes: tuple
    runs: dict
    tracking: dict

    def to_dict(self) -> dict:
        """JSON-ready summary (no time series)."""
        return {"parameter": self.parameter, "k_nominal": self.k_nominal,
                "duration_s": float(self.time_s[-1]) if self.time_s.size else 0.0,
                "pressure_top_bar": float(np.max(self.pressure_bar)),
                "impulse_times_s": self.impulse_times_s, "tracking": self.tracking,
                "runs": {n: {"lost_at_s": r.lost_at_s, "impulse_peak_um": r.impulse_peak_um,
                             "impulse_settling_s": r.impulse_settling_s,
                             "impulse_above_background": r.impulse_above_background}
                         for n, r in self.runs.items()}}


def pressure_ramp(p_nominal_bar: float, duration_s: float, *, top_factor: float = 3.0,
                  step_s: float = 0.05) -> list[tuple[float, float]]:
    """A linear ramp 0 → ``top_factor``·p_nominal over ``duration_s`` as
    ``[(start_s, pressure_bar), ...]`` steps of ``step_s`` (2× nominal at 2/3 of the way
    for the default 3×).

    Parameters
    ----------
    p_nominal_bar : float
        The rig's nominal pressure drop (bar).
    duration_s : float
        Length of the ramp (s).
    top_factor : float
        The pressure drop at the end, as a multiple of ``p_nominal_bar``.
    step_s : float
        Time between steps (s).

    Returns
    -------
    list of (float, float)
        ``(start_s, pressure_bar)`` of each step, the first at ``step_s``, the last at
        ``duration_s`` (a ``pressure_schedule`` of
        :func:`ambseal.identify.facility.rig_sim.simulate_facility`).
    """
    t = np.arange(step_s, duration_s + 0.5 * step_s, step_s)
    return [(float(a), float(top_factor * p_nominal_bar * a / duration_s)) for a in t]


def _excitation(cfg, N: int, fs: float, every_s: float, amplitude_a: float, n_len: int,
                seed: int):
    """(excitation (N, k), impulse start samples): the tracker's PRBS and the impulse train
    on axis 0 added to it."""

    e = tracking_excitation(cfg, (N + 1) / fs, seed=seed).values_a[:N].copy()
    step = int(round(every_s * fs))
    starts = list(range(step, N - 35 * n_len, step))
    for n0 in starts:
        e[n0:n0 + n_len, 0] += amplitude_a
    return e, starts


def _impulse_metrics(y: np.ndarray, starts, fs: float, n_len: int, lost_n: int | None):
    """Peak |y| (µm), settling time (s) and whether the response left the background band,
    per impulse (module docstring)."""
    peaks, settle, seen = [], [], []
    pre = int(round(0.05 * fs))
    for n0 in starts:
        end = n0 + 30 * n_len
        if lost_n is not None and end >= lost_n:
            peaks.append(None)
            settle.append(None)
            seen.append(False)
            continue
        w = np.abs(y[n0:end])
        band = max(0.02 * float(np.max(w)), 3.0 * float(np.std(y[max(0, n0 - pre):n0])))
        peaks.append(float(np.max(w)) * 1e6)
        above = np.nonzero(w > band)[0]
        seen.append(bool(above.size))
        settle.append(float((above[-1] + 1) / fs) if above.size and above[-1] < w.size - 1
                      else None)
    return peaks, settle, seen


def ramp_simulation(cfg, truth, controllers: dict, tracked=None, *, duration_s: float = 30.0,
                    top_factor: float = 3.0, step_s: float = 0.05, block_s: float = 0.05,
                    impulse_every_s: float = 2.0, transient_s: float = 1.0,
                    record_hz: float = 1000.0, seed: int = 0, settings=None,
                    model_cfg=None, tracked_digital=None, delay_samples: int = 0,
                    judgement: JudgeSettings, fallback: str | None = "mu",
                    progress=None) -> RampResult:
    """Run the pressure ramp with each fixed controller and the tracked scheme.

    Parameters
    ----------
    cfg : RigConfig
        The rig file the facility is built from (with ``truth``).
    truth : TruthSection
        The facility's truth (noise, ADC, limits; ``noise_fraction`` sets the sensor noise
        as a fraction of the RMS displacement of a noise-free run).
    controllers : dict
        ``{name: DiscreteController}`` at the rig's sample rate (no computation delay, as
        the facility runs them).
    tracked : SealScheduledDesign, optional
        The scheduled controller, run as ``"tracked"`` with the on-line estimator.
    duration_s, top_factor, step_s : float
        The ramp (:func:`pressure_ramp`) from 0 bar.
    block_s : float
        The tracked scheme's switching period (s).
    impulse_every_s : float
        Period of the current impulses (s), the first after one period.
    transient_s : float
        The estimator's initial transient left out of its accuracy (s).
    record_hz : float
        Rate of the returned records (Hz).
    seed : int
        Seed of the excitation and the noise.
    settings : TrackingSettings, optional
        The on-line estimator's settings (default ``TrackingSettings()``).
    model_cfg : RigConfig, optional
        The rig the tracker's model is built from: the identified rig (Ki, Ks, τ_e, the
        seal's coefficient curves; thesis stages (a)–(c)); default ``cfg`` (module
        docstring).
    tracked_digital : ScheduledDigital, optional
        The tracked controller's digital table (:func:`ambseal.app.commands.digital_for`);
        default: the frozen controller discretised by ZOH at every switch.
    delay_samples : int
        Computation delay of every controller (samples; module docstring).
    judgement : JudgeSettings
        The rig's judgement settings (:func:`ambseal.analysis.judge.judge_settings`): the
        current impulse's amplitude and length.
    fallback : str or None
        The fixed controller (a key of ``controllers``) the tracked scheme switches to when
        the tracker refuses (:meth:`~ambseal.identify.tracking.OnlineTracker.consistency`;
        module docstring); None, or a name not in ``controllers``: the scheduled
        controller keeps running on the refused estimate.
    progress : callable, optional
        Called with one line per run.

    Returns
    -------
    RampResult

    Raises
    ------
    ModelError
        A rig without a seal, or without the parameter named by ``tracked.parameter``.
    """

    fs = cfg.controller.sample_rate_hz
    N = int(round(duration_s * fs))
    sched = pressure_ramp(cfg.operating.pressure_bar, duration_s, top_factor=top_factor,
                          step_s=step_s)
    n_len = max(1, int(round(judgement.impulse_s * fs)))
    e, starts = _excitation(cfg, N, fs, impulse_every_s, judgement.impulse_a, n_len, seed)
    fac0 = prepare_facility(cfg, truth, fs, pressure_bar=0.0, pressure_schedule=sched)
    k = len(fac0.axes)
    rng = np.random.default_rng(seed)
    white, iwhite = rng.standard_normal((N, k)), rng.standard_normal((N, k))
    if tracked is None and not cfg.seal:
        raise ModelError("ramp: the rig has no [[seal]] whose pressure could ramp")
    param = tracked.parameter if tracked is not None else f"{cfg.seal[0].name}.k"
    cfg_t = true_rig(cfg, truth)
    base = reduced_plant(cfg_t, 0.0, None, {}, truth.max_mode_hz)
    if param not in base.parameters:
        raise ModelError(f"ramp: the rig has no parameter {param!r}")
    p_of_n = np.zeros(N)
    k_of_n = np.full(N, pressure_values(cfg_t, truth, base, 0.0).get(param, 0.0))
    for t0, p in sched:
        n0 = int(round(t0 * fs))
        p_of_n[n0:], k_of_n[n0:] = p, pressure_values(cfg_t, truth, base, p)[param]
    k_nom = abs(pressure_values(cfg_t, truth, base, cfg.operating.pressure_bar)[param])
    run_as = _runner(tracked, tracked_digital, 1.0 / fs, delay_samples)
    controllers = {n: run_as(K) for n, K in controllers.items()}
    noise_std = _noise_std(cfg, truth, controllers, tracked, e, fs, run_as)
    noise, inoise = white * noise_std, iwhite * truth.current_noise_a
    dec = max(1, int(round(fs / record_hz)))
    runs = {}
    for name, Kd in controllers.items():
        fac = prepare_facility(cfg, truth, fs, pressure_bar=0.0, pressure_schedule=sched)
        runs[name] = _run_fixed(name, fac, Kd, e, noise, inoise, fs, starts, n_len, dec,
                                block_s)
        if progress:
            lost = runs[name].lost_at_s
            progress(f"ramp: {name} " + ("kept the rotor" if lost is None
                                         else f"lost the rotor at {lost:.2f} s"))
    tracking = {}
    if tracked is not None:
        fac = prepare_facility(cfg, truth, fs, pressure_bar=0.0, pressure_schedule=sched)
        back = (fallback, controllers[fallback]) if fallback in controllers else None
        runs["tracked"], tracking = _run_tracked(model_cfg or cfg, fac, tracked, run_as, e,
                                                 noise, inoise, fs, starts, n_len, dec,
                                                 block_s, k_of_n, float(k_nom), transient_s,
                                                 settings, back)
        if progress:
            progress(f"ramp: tracked {tracking}")
    t = np.arange(N)[::dec] / fs
    return RampResult(param, t, p_of_n[::dec], k_of_n[::dec], float(k_nom),
                      [n0 / fs for n0 in starts], tuple(fac0.axes), runs, tracking)


def _noise_std(cfg, truth, controllers, tracked, e, fs, run_as):
    """Sensor noise std per axis: the truth's floor plus ``noise_fraction`` × the RMS of a
    noise-free first second at 0 bar with the tracked controller (else the first one)."""

    k = e.shape[1]
    std = np.full(k, truth.sensor_noise_m)
    if truth.noise_fraction <= 0:
        return std
    Kd = run_as(tracked.schedule[0]) if tracked is not None else next(iter(
        controllers.values()))
    n = min(len(e), int(round(fs)))
    fac = prepare_facility(cfg, truth, fs, pressure_bar=0.0)
    y, _, _ = fac.run(Kd, np.zeros(Kd.A.shape[0]), e[:n], np.zeros((n, k)), np.zeros((n, k)))
    return std + truth.noise_fraction * np.sqrt(np.mean(y**2, axis=0))


def _runner(tracked, table, T: float, delay: int):
    """``run_as(K)``: the DiscreteController that runs, with ``delay`` samples of delay, for
    a fixed DiscreteController ``K`` or for the tracked controller at θ = ``K`` (a number:
    the table at θ, or without a table the design frozen at θ and discretised by ZOH)."""

    def run_as(K):
        if not isinstance(K, DiscreteController):
            K = (table.discrete_at(K) if table is not None else
                 DiscreteController(*discretize_as(tracked.matrices_at(K), T, "zoh"), T))
        return DiscreteController(*with_delay((K.A, K.B, K.C, K.D), delay), T)

    return run_as


def _records(N: int, k: int):
    return np.full((N, k), np.nan), np.full((N, k), np.nan)


def _run_fixed(name, fac, Kd, e, noise, inoise, fs, starts, n_len, dec, block_s) -> RampRun:
    """One fixed controller over the ramp, in blocks (the records up to a loss kept)."""
    N, k = e.shape
    y, ref = _records(N, k)
    xc, lost, nb = np.zeros(Kd.A.shape[0]), None, max(1, int(round(block_s * fs)))
    for a in range(0, N, nb):
        b = min(N, a + nb)
        try:
            y[a:b], _, ref[a:b] = fac.run(Kd, xc, e[a:b], noise[a:b], inoise[a:b])
        except ModelError:
            lost = (a, fac.n)
            break
    return _run(name, y, ref, lost, fs, starts, dec, n_len)


def _run(name, y, ref, lost, fs, starts, dec, n_len, **extra) -> RampRun:
    """The run's record; ``lost`` = (first sample not recorded, sample of the loss)."""
    peaks, settle, seen = _impulse_metrics(y[:, 0], starts, fs, n_len,
                                           None if lost is None else lost[0])
    return RampRun(name, y[::dec] * 1e6, ref[::dec], None if lost is None else lost[1] / fs,
                   peaks, settle, **extra, impulse_above_background=seen)


def _run_tracked(cfg, fac, tracked, run_as, e, noise, inoise, fs, starts, n_len, dec,
                 block_s, k_true, k_nom, transient_s, settings, fallback=None):
    """The tracked scheme over the ramp (module docstring); its run and the estimator's
    accuracy. ``fallback``: (name, DiscreteController that runs) after a refusal."""

    N, k = e.shape
    T = 1.0 / fs
    s = settings or TrackingSettings()
    plant = reduced_plant(cfg, 0.0, None, {}, s.cutoff_hz or fs / 2)
    theta = float(plant.parameter(tracked.parameter).nominal)
    Kd = run_as(theta)
    model = ClosedLoopModel(plant, actuator_matrices(cfg.actuator), Kd,
                            tau_e=cfg.actuator.eddy_time_constant)
    y, ref = _records(N, k)
    xc, lost, tr, nb = np.zeros(Kd.A.shape[0]), None, None, max(1, int(round(block_s * fs)))
    switched = None
    for a in range(0, N, nb):
        b = min(N, a + nb)
        if switched is None and fallback is not None and tr is not None \
                and tr.refused_at_s is not None:
            switched = a / fs  # the fallback starts from rest: no state to carry across
            xc = np.zeros(fallback[1].A.shape[0])
        Kd = run_as(theta) if switched is None else fallback[1]
        try:
            y[a:b], _, ref[a:b] = fac.run(Kd, xc, e[a:b], noise[a:b], inoise[a:b])
        except ModelError:
            lost = (a, fac.n)
            break
        if tr is None:
            tr = OnlineTracker(cfg, model, [tracked.parameter], T, y[a:b], ref[a:b], s)
        est, step = float(tr.update(y[a:b], ref[a:b])[0]), tracked.rate_bound * (b - a) * T
        theta = float(np.clip(theta + np.clip(est - theta, -step, step), *tracked.schedule))
    if tr is None:  # lost in the first block: nothing tracked
        return _run("tracked", y, ref, lost, fs, starts, dec, n_len), {}
    res = tr.result(np.arange(tr.samples) * T)
    est = res.estimate[:, 0]
    lo, hi = (c[:, 0] for c in res.ci95())
    n = len(est)
    after = slice(int(round(transient_s * fs)), n)
    kt = k_true[:n]
    check = tr.consistency()
    acc = {"max_error_rel": None, "coverage": None, "transient_s": transient_s,
           "refused": tr.refused_at_s is not None, "refused_at_s": tr.refused_at_s,
           "refusal": tr.refusal or None,
           "fallback": fallback[0] if switched is not None else None,
           "fallback_from_s": switched, "check_threshold": check["threshold"],
           "check_largest": {q: max((w["statistic"][q] for w in check["windows"]),
                                    default=None) for q in check["probes"]},
           "check_largest_bias_se": {q: max((w["bias_se"][q] for w in check["windows"]),
                                            default=None) for q in check["probes"]}}
    if n > after.start:
        acc["max_error_rel"] = float(np.max(np.abs(est[after] - kt[after])) / k_nom)
        acc["coverage"] = float(np.mean((lo[after] <= kt[after]) & (kt[after] <= hi[after])))
    pad = np.full(N - n, np.nan)
    run = _run("tracked", y, ref, lost, fs, starts, dec, n_len,
               estimate=np.r_[est, pad][::dec], ci95_low=np.r_[lo, pad][::dec],
               ci95_high=np.r_[hi, pad][::dec])
    return run, acc


def frozen_cases(cfg, design, *, settings: JudgeSettings, impulse: bool = False
                 ) -> list[dict]:
    """The scheduled controller judged on the full-order plant at frozen pressures: the
    design's range (``range_factor`` × the operating pressure) at as many equally spaced
    pressures as its controller table has entries (``check_grid``: 21 by default), the controller frozen at the rig model's value of its parameter at
    each pressure (:func:`ambseal.analysis.judge.judge`; each case also has ``"value"``,
    θ in SI).

    Parameters
    ----------
    cfg : RigConfig
    design : SealScheduledDesign
    settings : JudgeSettings
        :func:`ambseal.analysis.judge.judge_settings` of the rig's design specification.
    impulse : bool
        Include the impulse response (off: the frequency-domain numbers only).

    Returns
    -------
    list of dict
    """

    s = settings
    p0, rpm = cfg.operating.pressure_bar, cfg.operating.speed_rpm
    lo, hi = design.range_factor
    cases = []
    for p in np.linspace(lo * p0, hi * p0, len(design.check_grid)):
        theta = float(build_plant(cfg, pressure_bar=p).parameter(design.parameter).nominal)
        case, _ = judge(cfg, design.at(theta), "tracked",
                        OperatingPoint(float(p), rpm, f"{p:.3g} bar"), s, impulse=impulse)
        cases.append({**case.to_dict(), "value": theta})
    return cases
