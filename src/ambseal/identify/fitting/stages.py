"""Identification stages: acquire a record, build the models a fit needs, fit and refine.

These wire :mod:`~ambseal.identify.facility.rig_sim`, :mod:`~ambseal.identify.records.data` and
:mod:`~ambseal.identify.fitting.fit` to a rig description; the CLI and the pipeline call them.
"""

from __future__ import annotations

import math

import numpy as np

from ambseal.config import RigConfig, TruthSection
from ambseal.errors import ConfigError, DataError, IdentificationError, ModelError
from ambseal.identify.fitting.budget import fixed_uncertainty
from ambseal.identify.records.data import Measurement, validate_measurement
from ambseal.identify.fitting.fit import TAU_E, ClosedLoopModel, FitResult, default_bounds, fit_parameters
from ambseal.identify.facility.rig_sim import facility_bias_current, reduced_plant, simulate_facility
from ambseal.identify.fitting.sensor_lag import TAU_S
from ambseal.identify.excitation.signals import Excitation
from ambseal.model import actuator_matrices
from ambseal.robust import DiscreteController

__all__ = ["state_space_from_metadata", "check_controller", "sample_rate_of",
           "check_record_metadata", "acquire", "at_speed", "build_models", "identify", "record_spread",
           "FIT_CUTOFF_HZ"]

#: Modes kept in the fit's reduced model (Hz). The rigid-body modes alone (8 states, P2 §3.2)
#: bias Ki/Ks by ~0.5 % on the test rig through the static flexibility of the dropped bending
#: modes; a 3 kHz cut-off leaves ~0.02 %; 10 kHz, the virtual facility's own, ~0.005 %.
FIT_CUTOFF_HZ = 10000.0


def state_space_from_metadata(meta: dict, axes: tuple[str, ...], source: str = "<data>"
                              ) -> DiscreteController:
    """The digital controller that ran, from the state space in a record's ``controller``
    metadata.

    ``{"type": "state_space", A, B, C, D, dt}``, or any description (e.g. the PID of
    ``ambseal acquire``) carrying these under ``"state_space"``. A description without its
    matrices (``{"type": "pid", kp, ti, td, eps}`` from a real rig) is turned into them by
    :func:`ambseal.design.pid.controller_from_metadata`, which the ``identify`` command
    calls: the identification stage takes the controller, it does not design one.

    Parameters
    ----------
    meta : dict
        A record's metadata (its ``controller`` and ``sample_rate_hz``).
    axes : tuple of str
        The rig's actuator axes (:func:`ambseal.model.amb.channel_names`).
    source : str, optional
        The record's file, for the messages.

    Returns
    -------
    DiscreteController
        One input and output per axis, at the record's sample time.

    Raises
    ------
    DataError
        Missing or malformed controller metadata, naming the file.
    """
    c = meta.get("controller")
    fs = sample_rate_of(meta, source)
    if not isinstance(c, dict) or "type" not in c:
        raise DataError(f"{source}: metadata.controller: expected a dict with 'type' "
                        "('pid' or 'state_space')")
    if c["type"] != "state_space" and not isinstance(c.get("state_space"), dict):
        raise DataError(f"{source}: metadata.controller.type: {c['type']!r} is unknown here, "
                        "or a description without its state space; pass the controller "
                        "(ambseal.design.pid.controller_from_metadata builds a PID's, as "
                        "`ambseal identify` does)")
    try:
        ctrl = DiscreteController.from_dict(c)
    except (KeyError, TypeError, ValueError) as exc:
        raise DataError(f"{source}: metadata.controller: {exc}") from None
    return check_controller(ctrl, axes, fs, source)


def check_controller(ctrl: DiscreteController, axes: tuple[str, ...], fs: float,
                     source: str = "<data>") -> DiscreteController:
    """``ctrl`` if it has one input and output per axis and runs at ``fs`` (Hz), else a
    DataError naming ``source``.

    Parameters
    ----------
    ctrl : DiscreteController
        The controller of a record.
    axes : tuple of str
        The rig's actuator axes.
    fs : float
        The record's sample rate (Hz).
    source : str, optional
        The record's file, for the message.

    Returns
    -------
    DiscreteController
        ``ctrl`` itself.

    Raises
    ------
    DataError
        Another number of inputs or outputs, or another sample time.
    """
    k = len(axes)
    if ctrl.B.shape[1] != k or ctrl.D.shape != (k, k):
        raise DataError(f"{source}: metadata.controller: expected {k} inputs and outputs "
                        f"(axes {', '.join(axes)}), got D of shape {ctrl.D.shape}")
    if abs(ctrl.dt * fs - 1.0) > 1e-6:
        raise DataError(f"{source}: metadata.controller.dt: {ctrl.dt} s, but the record is "
                        f"sampled at {fs} Hz (expected dt = {1 / fs} s)")
    return ctrl


def sample_rate_of(meta: dict, source: str = "<data>") -> float:
    """A record's ``sample_rate_hz`` metadata (Hz), or a DataError naming ``source``.

    Parameters
    ----------
    meta : dict
        A record's metadata.
    source : str, optional
        The record's file, for the message.

    Returns
    -------
    float
        The sample rate (Hz), finite and positive.

    Raises
    ------
    DataError
        A missing, non-numeric, non-finite or non-positive ``sample_rate_hz``.
    """
    return _positive(meta, "sample_rate_hz", source)


def check_record_metadata(meta: dict, source: str) -> None:
    """The operating point of a record's metadata within the rig format's ranges:
    ``pressure_drop_pa`` at most 1e9 Pa (1e4 bar) and ``speed_rad_s`` at most 1.05e5 rad/s
    (1e6 rpm); a DataError naming ``source`` otherwise.

    Parameters
    ----------
    meta : dict
        A record's metadata; absent keys are not checked.
    source : str
        The record's file, for the message.

    Raises
    ------
    DataError
        A value that is not a finite number ≥ 0, or one beyond its bound.
    """
    for key, high in (("pressure_drop_pa", 1e9), ("speed_rad_s", 1e6 * 2 * np.pi / 60)):
        if meta.get(key) is not None and _positive(meta, key, source, default=0.0) > high:
            raise DataError(f"{source}: metadata.{key}: {meta[key]!r} is beyond the plausible "
                            f"{high:.3g}")


def _positive(meta: dict, key: str, source: str, default: float | None = None) -> float:
    """A finite metadata number (>= 0; > 0 without a default), or a DataError naming it."""
    v = meta.get(key, default)
    try:
        x = float(v)
    except (TypeError, ValueError):
        raise DataError(f"{source}: metadata.{key}: expected a number, got {v!r}") from None
    if not np.isfinite(x) or x < 0 or (default is None and x == 0):
        raise DataError(f"{source}: metadata.{key}: expected a finite positive number, "
                        f"got {v!r}")
    return x


def at_speed(cfg: RigConfig, speed_hz: float | None, what: str = "speed_hz") -> RigConfig:
    """``cfg`` with its rotor spinning at ``speed_hz`` (the operating speed's direction), for
    a test at a speed the machine runs; ``cfg`` itself when ``speed_hz`` is None.

    The speeds a rig runs are standstill up to the top of ``[operating] speed_range_hz``
    (without a range, up to the operating speed): every AMB machine levitates at rest
    before it spins, and no test runs it faster than it is built for.

    Parameters
    ----------
    cfg : RigConfig
        The rig.
    speed_hz : float or None
        Spin speed (Hz), ≥ 0.
    what : str
        The option or key that gave it, for the message.

    Returns
    -------
    RigConfig

    Raises
    ------
    ConfigError
        A speed that is not finite or outside 0 … the rig's top speed.
    """
    if speed_hz is None:
        return cfg
    op = cfg.operating
    top = op.speed_range_hz[1] if op.speed_range_hz else abs(op.speed_rpm) / 60.0
    f = float(speed_hz)
    if not math.isfinite(f) or f < 0 or f > top * (1 + 1e-12):
        raise ConfigError(f"{what}: {speed_hz!r} Hz; the rig runs from standstill to "
                          f"{top:g} Hz ([operating] speed_range_hz, else its speed_rpm)")
    rpm = math.copysign(60.0 * f, op.speed_rpm if op.speed_rpm else 1.0)
    # a test speed may lie outside the range the machine operates in (standstill below it):
    # the copy keeps the rig's validated range and takes the test's speed
    return cfg.model_copy(update={"operating": op.model_copy(update={"speed_rpm": rpm})})


def acquire(cfg: RigConfig, truth: TruthSection, excitation: Excitation, *,
            controller: DiscreteController, pressure_bar: float, seed: int = 0,
            pressure_schedule: list[tuple[float, float]] | None = None,
            speed_hz: float | None = None) -> Measurement:
    """Run the virtual facility with ``controller`` levitating the rotor and return the
    record as a :class:`Measurement` (the controller in its metadata; a
    ``pressure_schedule`` of :func:`~ambseal.identify.facility.rig_sim.simulate_facility` in it as
    ``pressure_schedule_bar`` [[start_s, bar], ...]).

    Parameters
    ----------
    cfg : RigConfig
        The rig as modelled.
    truth : TruthSection
        The facility's true values, noise, ADC, τ_e, bias and current limit.
    excitation : Excitation
        The excitation currents (A) per actuator axis and their sample rate (Hz).
    controller : DiscreteController
        The digital controller that levitates the rotor, at the excitation's sample rate.
    pressure_bar : float
        Pressure drop across the seals (bar).
    seed : int
        Seed of the sensor and current noise.
    pressure_schedule : list of (start_s, pressure_bar), optional
        A piecewise-constant pressure drop (bar) from each start time (s) on.
    speed_hz : float, optional
        Spin speed of the run (Hz, :func:`at_speed`); default the rig's operating speed.
        The record's metadata carries it (``speed_rad_s``), and the fit takes its model
        there.

    Returns
    -------
    Measurement
        The record in the measurement-file format, with the rig, sample rate, bias, pressure
        drop (Pa), speed (rad/s), controller, excitation and current limit in its metadata.

    Raises
    ------
    DataError
        A controller that does not fit the axes or the excitation's sample rate.
    ModelError
        See :func:`~ambseal.identify.facility.rig_sim.simulate_facility`.
    ConfigError
        A speed the rig does not run (:func:`at_speed`).
    """
    cfg = at_speed(cfg, speed_hz)
    axes = excitation.axes
    meta = {
        "rig": cfg.rotor.name,
        "sample_rate_hz": excitation.sample_rate_hz,
        "bias_current_a": facility_bias_current(cfg, truth),
        "pressure_drop_pa": pressure_bar * 1e5,
        "speed_rad_s": cfg.speed,
        "controller": controller.to_dict(),
        "excitation": excitation.params,
        "source": "virtual test facility",
    }
    if pressure_schedule:
        meta["pressure_schedule_bar"] = [[float(t), float(p)] for t, p in pressure_schedule]
    limits = [a.current_limit for a in cfg.amb if a.current_limit]
    limit = truth.current_limit or (min(limits) if limits else None)
    if limit:
        meta["current_limit_a"] = limit
    Kd = check_controller(controller, axes, excitation.sample_rate_hz, "acquire: controller")
    rec = simulate_facility(cfg, truth, np.asarray(excitation.values_a), excitation.sample_rate_hz,
                            Kd, pressure_bar=pressure_bar, seed=seed,
                            pressure_schedule=pressure_schedule)
    meas = Measurement(time_s=rec.time_s, excitation_a=rec.excitation_a,
                       current_ref_a=rec.current_ref_a, current_a=rec.current_a,
                       displacement_m=rec.displacement_m, axes=axes, metadata=meta)
    validate_measurement(meas, source="virtual facility record", axes=axes,
                         current_limit_a=None)
    return meas


def _pressure_bar(meas: Measurement, source: str = "<data>") -> float:
    return _positive(dict(meas.metadata), "pressure_drop_pa", source, default=0.0) / 1e5


def build_models(cfg: RigConfig, records: list[Measurement], values: dict | None = None,
                 cutoff_hz: float = FIT_CUTOFF_HZ, controllers: list | None = None,
                 sources: list[str] | None = None) -> list[ClosedLoopModel]:
    """One closed-loop model per record: the rig at the record's pressure and speed, with
    parameter ``values`` (SI) applied exactly in full order, reduced to the modes below
    ``cutoff_hz``, the amplifier and τ_e lag in series (and a sensor lag ``tau_s`` if
    ``values`` has one) and the controller that ran
    (``controllers``, one per record, or each record's metadata). ``sources`` name the
    records' files in errors."""
    values = dict(values or {})
    tau = values.pop(TAU_E, cfg.actuator.eddy_time_constant)
    lag = values.pop(TAU_S, 0.0)  # a sensor lag is no rig-file value (sensor_lag.py)
    models = []
    sources = sources or [f"record {i + 1}" for i in range(len(records))]
    if controllers is None:
        controllers = [state_space_from_metadata(dict(r.metadata), r.axes, src)
                       for r, src in zip(records, sources)]
    for rec, Kd, src in zip(records, controllers, sources):
        meta = dict(rec.metadata)
        speed = None if meta.get("speed_rad_s") is None else _positive(
            meta, "speed_rad_s", src, default=0.0)
        plant = reduced_plant(cfg, _pressure_bar(rec, src),
                              None if speed is None else speed * 60 / (2 * np.pi), values,
                              cutoff_hz)
        models.append(ClosedLoopModel(plant, actuator_matrices(cfg.actuator), Kd, tau_e=tau,
                                      tau_s=lag))
    return models


def identify(cfg: RigConfig, records: list[Measurement], names: list[str], *,
             known: dict | None = None, current_weight: float = 0.0, refine: bool = True,
             window: tuple[int, int | None] = (0, None), controllers: list | None = None,
             budget: bool = False, sources: list[str] | None = None,
             known_fit: FitResult | None = None) -> FitResult:
    """Fit ``names`` to closed-loop records (P2 Eqs. 9–10, P4 Eq. 14).

    Parameters
    ----------
    cfg : RigConfig
        The rig; its model, at each record's pressure and speed, is the fit's start.
    records : list of Measurement
        Closed-loop records (metadata: pressure drop, speed, controller, sample rate).
    names : list of str
        Parameters to fit: LFT names of the model (``"A.Ki_zeta"``, ``"seal.k"``, ...),
        ``"tau_e"`` or ``"tau_s"`` (:func:`~ambseal.identify.fitting.fit.fit_parameters`).
    known : dict, optional
        Values found in earlier stages (e.g. Ki/Ks when fitting the coupling, P4 §3.5).
    current_weight : float
        Weight of the coil-current residuals relative to the displacements (0: off; P4 §3.4
        suggests currents lower the Ki–Ks correlation).
    refine : bool
        Fit again on a model re-reduced at the first estimate: the reduced LFT is exact only
        at the point of reduction (P2 §4.1 assumes it holds nearby), so the second pass
        removes that approximation from the estimate.
    window : (int, int or None)
        Samples ``[start, stop)`` of each record in the cost; the simulation always starts
        at rest at sample 0.
    controllers : list of DiscreteController, optional
        The controller that ran for each record; by default from the records' metadata.
    budget : bool
        Add the error budget of every parameter held fixed to the intervals: values neither
        fitted nor ``known`` with the uncertainty the rig file states or the defaults of
        :mod:`ambseal.identify.fitting.budget`; ``known`` values that ``known_fit`` estimated with
        its standard errors and correlations; other ``known`` values as exact.
    sources : list of str, optional
        The records' file names, for errors.
    known_fit : FitResult, optional
        The earlier fit that found (some of) the ``known`` values.

    Returns
    -------
    FitResult
        Estimates (SI), standard errors, 95 % intervals and correlations, the fit per
        channel and the residual tests; the refined pass when it converged.

    Raises
    ------
    ConfigError
        An ``uncertainty`` key that names no value (with ``budget``).
    IdentificationError
        A name without a channel or bounds, or a fit that cannot start
        (:func:`~ambseal.identify.fitting.fit.fit_parameters`).
    DataError
        A record whose metadata lacks what the model needs (named with ``sources``).
    """
    known = dict(known or {})
    models = build_models(cfg, records, known, controllers=controllers, sources=sources)
    try:
        bounds = default_bounds(models[0], names)
    except ModelError as exc:
        raise IdentificationError(f"fit: {exc}") from None
    fixed, corr = None, None
    if budget:
        params = list(models[0].plant.parameters) + ([TAU_E] if models[0].tau_e > 0 else [])
        fixed = fixed_uncertainty(cfg, params, list(names) + list(known))
        if known_fit is not None:
            fixed, corr = _with_estimates(fixed, known, known_fit, names)
    try:
        res = fit_parameters(records, models, names, current_weight=current_weight,
                             window=window, bounds=bounds, fixed=fixed, fixed_correlation=corr)
    except IdentificationError as exc:  # the records' controllers are part of the model
        raise IdentificationError(f"{', '.join(sources)}: {exc}" if sources else str(exc)
                                  ) from None
    if refine and res.converged:
        est = dict(zip(names, res.estimate))
        models = build_models(cfg, records, {**known, **est}, controllers=controllers,
                              sources=sources)
        res2 = fit_parameters(records, models, names, current_weight=current_weight,
                              window=window, bounds=bounds, fixed=fixed,
                              fixed_correlation=corr)
        if res2.converged:
            res = res2
    return res


def _with_estimates(fixed: dict, known: dict, fit: FitResult, names) -> tuple[dict, tuple]:
    """``fixed`` plus the ``known`` values ``fit`` estimated, each with its relative standard
    error (source ``"estimate (earlier fit)"``), and (names, correlation) of those."""
    take = [n for n in fit.names if n in known and n not in names]
    idx = [fit.names.index(n) for n in take]
    out = dict(fixed)
    for n, i in zip(take, idx):
        v = abs(float(known[n]))
        if v > 0 and np.isfinite(fit.std_error[i]):
            out[n] = (float(fit.std_error[i]) / v, "estimate (earlier fit)")
    sign = np.sign([float(known[n]) for n in take])  # of the relative errors Δφ/φ
    return out, (tuple(take), np.asarray(fit.correlation)[np.ix_(idx, idx)]
                 * np.outer(sign, sign))


def record_spread(cfg: RigConfig, records: list[Measurement], names: list[str],
                  pooled: FitResult, *, controllers: list | None = None,
                  sources: list[str] | None = None) -> dict | None:
    """Each record fitted alone, and the spread of those estimates beside the pooled fit.

    The thesis judges its identification by the relative standard deviation over repeated
    tests (P2 Table 2, 1.1–2.4 %): a spread wider than the pooled interval claims says the
    records differ by more than their noise (model error, drift). Single-record fits take
    one pass (no refinement) from the rig's values.

    Parameters
    ----------
    cfg : RigConfig
        The rig the records were taken on.
    records : list of Measurement
        The records of the pooled fit.
    names : list of str
        The fitted parameters.
    pooled : FitResult
        The fit of all records together.
    controllers : list, optional
        The controller of each record, where its metadata does not carry it.
    sources : list of str, optional
        The records' files, for the messages (default ``record 1``, …).

    Returns
    -------
    dict or None
        ``{name: {per_record, mean, sd, rsd_pct, pooled, pooled_std_error}}`` (SI); None
        when the records are not of one condition (pressure drop, speed).
    """
    cond = {(round(_pressure_bar(r), 9), dict(r.metadata).get("speed_rad_s")) for r in records}
    if len(cond) > 1 or len(records) < 2:
        return None
    sources = sources or [f"record {i + 1}" for i in range(len(records))]
    est = []
    for i, rec in enumerate(records):
        r = identify(cfg, [rec], names, refine=False, sources=[sources[i]],
                     controllers=None if controllers is None else [controllers[i]])
        est.append(r.estimate)
    est = np.array(est)
    mean, sd = est.mean(axis=0), est.std(axis=0, ddof=1)
    return {n: {"per_record": est[:, j].tolist(), "mean": float(mean[j]), "sd": float(sd[j]),
                "rsd_pct": float(100 * sd[j] / abs(mean[j])) if mean[j] else None,
                "pooled": float(pooled.estimate[j]),
                "pooled_std_error": float(pooled.std_error[j])}
            for j, n in enumerate(names)}
