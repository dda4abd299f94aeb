"""The unbalance force rejection judged: its loops at every judged condition and what it
does to the synchronous response over the speed range
(:mod:`ambseal.design.synchronous_rejection`, Herzog et al., IEEE TCST 4(5), 1996).

- **Stability**: at each judged condition where the notch is on (its speed at or above
  the notch's ``on`` speed), the full-order plant closed by the controller with its notch
  at that speed, continuous (with the judgement's delay lag) and as it runs (the plant
  sampled by a zero-order hold, the discrete controller with its delay and notch)
  (:func:`ambseal.machine.judged_loop`); below it the controller runs alone, judged as
  such by :func:`ambseal.analysis.judge.judge`.
- **Effect**: the synchronous response (:func:`ambseal.analysis.synchronous.
  synchronous_response`) over the speed range with and without the notch, as the
  controller runs: each AMB axis's coil current and transmitted force, and the orbit at
  the sensors, the largest over the axes (positions) and two unbalance distributions over
  the judgement's force planes (the bearings by default) — in phase (static) and in
  alternating phase (couple) — of the ISO 21940-11 permissible residual unbalance
  U = m·G/Ω_max of the judged grade.
- **On the virtual facility** (:func:`facility_rejection`): the time simulation of
  :mod:`ambseal.identify.facility` (nonlinear force law, amplifier limits, the controller
  as it runs) at a constant speed with a synchronous sensor runout — each sensor reading
  r·cos(Ωt) (ζ) or r·sin(Ωt) (η) more than the shaft's position, a runout track turning
  with the shaft — first with the controller alone until its loop has settled, then with
  the notch switched on: the coil currents' synchronous part (its amplitude over each
  revolution, a least-squares fit of a sinusoid at Ω and an offset) before and after. The runout is
  :data:`RUNOUT_FRACTION` of the smallest air gap (a clearance the rig file gives; else
  :data:`RUNOUT_M`): the check is linear in it while the currents stay within the
  amplifier's limits. And a speed step (:func:`facility_speed_step`): the facility's
  plant steps from one speed to another (its speed schedule), the runout's frequency with
  it, each controller alone and with its notch (rescheduled at the step): the synchronous
  coil current and orbit — the shaft's displacement at the sensors, the reading less the
  runout — settling at the new speed.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy.optimize import minimize_scalar

from ambseal.analysis.synchronous import Unbalance, synchronous_evaluator
from ambseal.config import TruthSection
from ambseal.errors import ModelError
from ambseal.identify import at_speed, prepare_facility
from ambseal.machine import controller_as_runs, judged_loop
from ambseal.model import build_plant
from ambseal.robust import DiscreteController, loop_delay

__all__ = ["rejection_stability", "lost_conditions", "rejection_effect",
           "facility_rejection", "FacilityRejection", "facility_speed_step", "SpeedStep",
           "EFFECT_SPEEDS", "RUNOUT_FRACTION", "RUNOUT_M"]

#: Speeds of the synchronous response over the speed range.
EFFECT_SPEEDS = 61
#: The facility's runout as a fraction of the smallest air gap (module docstring).
RUNOUT_FRACTION = 0.01
#: The runout (m) of a rig file without an air gap or backup clearance.
RUNOUT_M = 5e-6
#: Time constants of a loop (its slowest pole's) or of the notch (2/ε) a phase lasts: its
#: transient down to e^{-7} < 1e-3 of its start.
SETTLE_TIME_CONSTANTS = 7.0
#: The longest a phase lasts (s): a loop with a mode that decays slower than this does not
#: hold the synchronous part's estimate back (the mode is not at Ω).
MAX_PHASE_S = 5.0


def rejection_stability(cfg, rejection, points, *, as_runs_only: bool = False) -> list[dict]:
    """The loops of a controller with its notch at the judged conditions (module
    docstring).

    Parameters
    ----------
    cfg : RigConfig
        The rig.
    rejection : SynchronousRejection
        The controller with its notch (:func:`ambseal.design.design_rejection`); its
        ``digital`` is judged as it runs where given.
    points : iterable of OperatingPoint
        The judged conditions.
    as_runs_only : bool
        The controller was designed on the sampled plant (:func:`ambseal.analysis.judge.
        judge_jobs`): with a ``digital``, its loop as it runs is its only one, and
        ``stable`` and ``max_real_pole`` are that loop's too (ln max|z| / T).

    Returns
    -------
    list of dict
        Per condition where the notch is on: ``condition``, ``speed_hz``, ``pressure_bar``,
        ``stable`` and ``max_real_pole`` (1/s) of the continuous loop, and
        ``stable_as_runs`` and ``max_abs_pole_z`` of the sampled one (None without a
        digital controller).
    """
    fs, nd = cfg.controller.sample_rate_hz, cfg.controller.delay_samples
    lag = loop_delay(fs, nd).system
    out = []
    for pt in points:
        w = 2 * math.pi * pt.speed_rpm / 60.0
        if not rejection.controller.notch.is_on(w):
            continue
        plant = build_plant(cfg, pressure_bar=pt.pressure_bar, speed_rpm=pt.speed_rpm)
        P, cur = plant.to_statespace(), plant.current_inputs()
        runs = None if rejection.digital is None else judged_loop(
            P, rejection.digital.statespace_at(w, delayed=True), cur).loop
        cont = runs if as_runs_only and runs is not None else judged_loop(
            P, rejection.controller.at(w), cur, delay=lag).loop
        row = {"condition": pt.label, "speed_hz": pt.speed_rpm / 60.0,
               "pressure_bar": float(pt.pressure_bar), "stable": bool(cont.stable),
               "max_real_pole": float(cont.max_real_pole), "stable_as_runs": None,
               "max_abs_pole_z": None}
        if runs is not None:
            row.update(stable_as_runs=bool(runs.stable),
                       max_abs_pole_z=float(np.abs(runs.poles).max()))
        out.append(row)
    return out


def lost_conditions(rows) -> list[str]:
    """The conditions of :func:`rejection_stability`'s ``rows`` where a loop with the notch
    is lost (continuous, or as it runs), each named by its pressure drop and speed —
    ``"<p> bar, <f> Hz"`` — whatever the label its point came with: the judged points
    of a rig at one speed leave the speed out of their labels (``"<p> bar"``), and beside
    the stability speeds' such a list would not say which speed was lost. In the rows'
    order, each once. Join them with ``"; "``: a condition holds a comma itself.

    Parameters
    ----------
    rows : list of dict
        :func:`rejection_stability`'s rows.

    Returns
    -------
    list of str
    """
    out = []
    for r in rows:
        if not r["stable"] or r["stable_as_runs"] is False:
            words = f"{r['pressure_bar']:g} bar, {r['speed_hz']:g} Hz"
            if words not in out:
                out.append(words)
    return out


def rejection_effect(cfg, digital, rejection, settings, *, pressure_bar=None) -> dict:
    """The synchronous response with and without the notch over the speed range (module
    docstring).

    Parameters
    ----------
    cfg : RigConfig
        The rig.
    digital : DigitalController or ScheduledDigital
        The controller as it runs, alone.
    rejection : SynchronousRejection
        The same with its notch (its ``digital``).
    settings : JudgeSettings
        The judgement's unbalance: grade, mass, Ω_max and force planes.
    pressure_bar : float, optional
        The seals' pressure drop (default: the one the notch was made at).

    Returns
    -------
    dict
        ``speed_hz`` (shape (S,), over the notch's table range: :data:`EFFECT_SPEEDS`
        evenly spaced, and each peak of either orbit located between them), and per
        quantity
        ``current_a``, ``force_n``, ``orbit_um`` a dict ``{"without", "with"}`` of arrays of
        shape (S,): the largest coil current amplitude (A), transmitted force (N) and orbit
        semi-major axis at the sensors (µm) over the axes and the two distributions.
    """
    lo, hi = (float(f) for f in rejection.speeds_hz[[0, -1]])
    speeds = np.linspace(lo, hi, EFFECT_SPEEDS) if hi > lo else np.array([lo])
    s = settings
    U = s.unbalance_mass_kg * s.unbalance_grade_mm_s * 1e-3 / (
        2 * math.pi * s.unbalance_max_speed_hz)
    planes = tuple(s.force_positions_m)
    per = U / len(planes)
    cases = [[Unbalance(z, per) for z in planes],
             [Unbalance(z, per, 180.0 * (k % 2)) for k, z in enumerate(planes)]]
    sensors = sorted({a.sensor_position for a in cfg.amb})
    p = rejection.pressure_bar if pressure_bar is None else float(pressure_bar)
    pairs = (("without", digital), ("with", rejection.digital))

    # each controller's loop assembled once, for the grid and the peaks' searches
    loops = {key: synchronous_evaluator(cfg, K, cases, sensors, pressure_bar=p)
             for key, K in pairs}

    def at(f: np.ndarray) -> dict:
        res = {}
        for key, _ in pairs:
            r = loops[key](f)
            res[key] = (r.current_a.max(axis=(0, 2)), r.force_n.max(axis=(0, 2)),
                        1e6 * r.amplitude_m.max(axis=(0, 2)))
        return res

    grid = at(speeds)
    # the orbit's peaks between the grid's speeds: with the notch on through a critical
    # speed the rotor's resonance is as sharp as its own damping, far narrower than the grid
    # (the supercritical example's: 213 µm on the grid, 331 µm at its peak)
    extra = sorted({f for key, _ in pairs for f in _peaks(
        lambda f, key=key: 1e6 * float(loops[key]([f]).amplitude_m.max()),
        speeds, grid[key][2])} - set(speeds.tolist()))
    if extra:
        more = at(np.array(extra))
        order = np.argsort(np.r_[speeds, extra], kind="stable")
        speeds = np.r_[speeds, extra][order]
        grid = {key: tuple(np.r_[a, b][order] for a, b in zip(grid[key], more[key]))
                for key in grid}
    out: dict = {"speed_hz": speeds, "current_a": {}, "force_n": {}, "orbit_um": {}}
    for key, (current, force, orbit) in grid.items():
        out["current_a"][key], out["force_n"][key], out["orbit_um"][key] = \
            current, force, orbit
    return out


#: The tolerance, relative to the top speed, to which :func:`rejection_effect` locates an
#: orbit's peak between its grid's speeds.
PEAK_XTOL = 1e-7


def _peaks(orbit_at, speeds: np.ndarray, orbit: np.ndarray) -> list[float]:
    """The speeds (Hz) of the local maxima of ``orbit`` on the grid ``speeds``, each
    located between its grid neighbours by bounded Brent (SciPy's ``minimize_scalar``) on
    ``orbit_at`` to :data:`PEAK_XTOL` of the top speed: a peak between two grid speeds
    lies between the neighbours of the larger of them."""
    n, out = speeds.size, []
    for k in range(n):
        left = orbit[k - 1] if k else -np.inf
        right = orbit[k + 1] if k + 1 < n else -np.inf
        if n < 2 or not (orbit[k] > left and orbit[k] >= right):
            continue
        r = minimize_scalar(lambda f: -orbit_at(f), method="bounded",
                            bounds=(float(speeds[max(k - 1, 0)]),
                                    float(speeds[min(k + 1, n - 1)])),
                            options={"xatol": PEAK_XTOL * float(speeds[-1])})
        if -r.fun > orbit[k]:
            out.append(float(r.x))
    return out


@dataclass(frozen=True)
class FacilityRejection:
    """The notch switched on under a synchronous sensor runout on the virtual facility
    (:func:`facility_rejection`).

    Attributes
    ----------
    speed_hz : float
        The constant speed (Hz).
    runout_m : float
        The runout's amplitude (m).
    on_s : float
        When the notch was switched on (s).
    time_s : ndarray, shape (R,)
        The end of each revolution-long window (s).
    current_a : ndarray, shape (R,)
        The largest synchronous coil-current amplitude of the AMB axes over each window
        (A).
    before_a, after_a : float
        That amplitude over the last window before the switch and the last of the run.
    """

    speed_hz: float
    runout_m: float
    on_s: float
    time_s: np.ndarray
    current_a: np.ndarray
    before_a: float
    after_a: float

    def to_dict(self) -> dict:
        """JSON-ready: speed (Hz), runout (µm), switch time (s), the amplitudes before and
        after (A) and their ratio."""
        return {"speed_hz": self.speed_hz, "runout_um": 1e6 * self.runout_m,
                "on_s": self.on_s, "before_a": self.before_a, "after_a": self.after_a,
                "ratio": self.after_a / self.before_a if self.before_a > 0 else None}


def facility_rejection(cfg, digital, rejection, speed_hz: float, *,
                       runout_m: float | None = None) -> FacilityRejection:
    """The notch switched on under a synchronous sensor runout on the virtual facility
    (module docstring).

    Parameters
    ----------
    cfg : RigConfig
        The rig; the facility is its own model (no noise, no quantisation, its
        ``[actuator]`` eddy lag), at the pressure the notch was made at.
    digital : DigitalController or ScheduledDigital
        The controller as it runs, alone.
    rejection : SynchronousRejection
        The same with its notch.
    speed_hz : float
        The constant speed (Hz), where the notch is on.
    runout_m : float, optional
        The runout's amplitude (m); default: module docstring.

    Returns
    -------
    FacilityRejection

    Raises
    ------
    ModelError
        The notch is off at that speed, or the rotor left the air gap.
    """
    w = 2 * math.pi * float(speed_hz)
    notch = rejection.digital.notch
    if not notch.is_on(w):
        raise ModelError(f"facility rejection: the notch is off at {speed_hz:g} Hz (on from "
                         f"{notch.on_rad_s / (2 * math.pi):g} Hz)")
    fs = cfg.controller.sample_rate_hz
    truth = TruthSection(tau_e=cfg.actuator.eddy_time_constant)
    fac = prepare_facility(at_speed(cfg, float(speed_hz)), truth, fs,
                           pressure_bar=rejection.pressure_bar)
    K0, Kn = (_as_run(K, fs) for K in (controller_as_runs(digital, w),
                                       rejection.digital.statespace_at(w, delayed=True)))
    runout_m = _runout(cfg) if runout_m is None else runout_m
    # phase lengths: the controller's loop settles, then the notch's
    rev = max(1, int(round(fs / float(speed_hz))))  # samples of a revolution
    n1 = _whole(_loop_settle_s(fac, K0) * fs, rev, fs)
    n2 = _whole(_notch_settle_s(notch, w) * fs, rev, fs)
    t = np.arange(n1 + n2) / fs
    runout = _runout_signal(fac.axes, runout_m, w * t)
    zero = np.zeros_like(runout)
    xc = np.zeros(K0.A.shape[0])
    _, i1, _ = fac.run(K0, xc, zero[:n1], runout[:n1], zero[:n1])
    xn = np.concatenate([xc, np.zeros(Kn.A.shape[0] - xc.size)])
    _, i2, _ = fac.run(Kn, xn, zero[n1:], runout[n1:], zero[n1:])
    coil = np.vstack([i1, i2])
    # amplitude at Ω over each revolution-long window
    ends = np.arange(rev, n1 + n2 + 1, rev)
    amp = np.array([_synchronous(coil[e - rev:e], t[e - rev:e], w) for e in ends])
    before = amp[ends <= n1][-1]
    return FacilityRejection(float(speed_hz), float(runout_m), n1 / fs, t[ends - 1], amp,
                             float(before), float(amp[-1]))


@dataclass(frozen=True)
class SpeedStep:
    """A speed step on the virtual facility under a sensor runout, each controller alone
    and with its notch (:func:`facility_speed_step`).

    Attributes
    ----------
    from_hz, to_hz : float
        The speeds before and after the step (Hz).
    step_s : float
        When the speed steps (s).
    runout_m : float
        The runout's amplitude (m).
    time_s : ndarray, shape (R,)
        The end of each revolution-long window (s).
    current_a, orbit_m : dict
        ``{"without", "with"}``: arrays of shape (R,), the largest synchronous coil
        current (A) and orbit (m, the shaft at the sensors) of the axes over each window,
        at the speed of the window.
    """

    from_hz: float
    to_hz: float
    step_s: float
    runout_m: float
    time_s: np.ndarray
    current_a: dict
    orbit_m: dict

    def to_dict(self) -> dict:
        """JSON-ready: the speeds (Hz), the step time (s), and per quantity (``current_a``
        in A, ``orbit_um`` in µm) ``without`` and ``with`` the notch: the largest after
        the step and the last."""
        def ends(d, scale=1.0):
            after = self.time_s > self.step_s
            return {k: {"largest_after_step": scale * float(v[after].max()),
                        "last": scale * float(v[-1])} for k, v in d.items()}
        return {"from_hz": self.from_hz, "to_hz": self.to_hz, "step_s": self.step_s,
                "runout_um": 1e6 * self.runout_m, "current_a": ends(self.current_a),
                "orbit_um": ends(self.orbit_m, 1e6)}


def facility_speed_step(cfg, digital, rejection, from_hz: float, to_hz: float, *,
                        runout_m: float | None = None) -> SpeedStep:
    """A speed step on the virtual facility under a synchronous sensor runout (module
    docstring): the loop settles at ``from_hz`` (the notch too, from rest), then the
    plant, the runout and the controller step to ``to_hz``.

    Parameters
    ----------
    cfg : RigConfig
        The rig; the facility as in :func:`facility_rejection`.
    digital : DigitalController or ScheduledDigital
        The controller as it runs, alone.
    rejection : SynchronousRejection
        The same with its notch.
    from_hz, to_hz : float
        The speeds (Hz) before and after the step; the notch on at both.
    runout_m : float, optional
        The runout's amplitude (m); default as :func:`facility_rejection`.

    Returns
    -------
    SpeedStep

    Raises
    ------
    ModelError
        The notch is off at either speed, or the rotor left the air gap.
    """
    notch = rejection.digital.notch
    w1, w2 = 2 * math.pi * float(from_hz), 2 * math.pi * float(to_hz)
    if not (notch.is_on(w1) and notch.is_on(w2)):
        raise ModelError(f"facility speed step: the notch is off at {from_hz:g} or "
                         f"{to_hz:g} Hz (on from {notch.on_rad_s / (2 * math.pi):g} Hz)")
    fs = cfg.controller.sample_rate_hz
    truth = TruthSection(tau_e=cfg.actuator.eddy_time_constant)
    runout_m = _runout(cfg) if runout_m is None else runout_m
    base = at_speed(cfg, float(from_hz))
    probe = prepare_facility(base, truth, fs, pressure_bar=rejection.pressure_bar)
    K = {(key, w): _as_run(S, fs) for w in (w1, w2) for key, S in (
        ("without", controller_as_runs(digital, w)),
        ("with", rejection.digital.statespace_at(w, delayed=True)))}
    loop_s = _loop_settle_s(probe, K["with", w1])
    revs = [max(1, int(round(fs / f))) for f in (from_hz, to_hz)]
    n1, n2 = (_whole(max(loop_s, _notch_settle_s(notch, w)) * fs, r, fs)
              for w, r in ((w1, revs[0]), (w2, revs[1])))
    t = np.arange(n1 + n2) / fs
    angle = np.where(t < n1 / fs, w1 * t, w1 * n1 / fs + w2 * (t - n1 / fs))
    runout = _runout_signal(probe.axes, runout_m, angle)
    zero = np.zeros_like(runout)
    ends = np.concatenate([np.arange(revs[0], n1 + 1, revs[0]),
                           n1 + np.arange(revs[1], n2 + 1, revs[1])])
    current, orbit = {}, {}
    for key in ("without", "with"):
        fac = prepare_facility(base, truth, fs, pressure_bar=rejection.pressure_bar,
                               speed_schedule=[(n1 / fs, float(to_hz))])
        xc = np.zeros(K[key, w1].A.shape[0])
        rec = [fac.run(K[key, w], xc, zero[a:b], runout[a:b], zero[a:b])
               for w, a, b in ((w1, 0, n1), (w2, n1, n1 + n2))]
        y, i = (np.vstack([r[j] for r in rec]) for j in (0, 1))
        shaft = y - runout

        def amplitudes(x):
            return np.array([_synchronous(x[e - r:e], t[e - r:e], w) for e, r, w in zip(
                ends, np.where(ends <= n1, revs[0], revs[1]), np.where(ends <= n1, w1, w2))])
        current[key], orbit[key] = amplitudes(i), amplitudes(shaft)
    return SpeedStep(float(from_hz), float(to_hz), n1 / fs, float(runout_m), t[ends - 1],
                     current, orbit)


def _runout(cfg) -> float:
    """The facility's runout amplitude (m; module docstring)."""
    gaps = [g for a in cfg.amb for g in (a.air_gap, cfg.backup_clearance(a)) if g]
    return RUNOUT_FRACTION * min(gaps) if gaps else RUNOUT_M


def _as_run(K, fs: float) -> DiscreteController:
    """A discrete ``control.StateSpace`` as the facility runs it."""
    return DiscreteController(*(np.asarray(getattr(K, m), float) for m in "ABCD"), 1.0 / fs)


def _loop_settle_s(fac, K: DiscreteController) -> float:
    """:data:`SETTLE_TIME_CONSTANTS` of the facility's loop with ``K`` (its slowest pole's),
    at most :data:`MAX_PHASE_S`."""
    decay = -math.log(float(np.abs(fac.loop_poles(K)).max())) / fac.T
    return min(SETTLE_TIME_CONSTANTS / decay, MAX_PHASE_S) if decay > 0 else MAX_PHASE_S


def _notch_settle_s(notch, w: float) -> float:
    """:data:`SETTLE_TIME_CONSTANTS` of the notch at Ω = ``w`` (its time constant 2/ε)."""
    return SETTLE_TIME_CONSTANTS * 2.0 / (notch.rate_fraction * w)


def _runout_signal(axes, runout_m: float, angle: np.ndarray) -> np.ndarray:
    """The runout at each sample (m, shape (N, k)): r cos θ on the ζ axes, r sin θ on η."""
    return np.column_stack([runout_m * (np.cos(angle) if ax.endswith("zeta")
                                        else np.sin(angle)) for ax in axes])


def _whole(samples: float, rev: int, fs: float) -> int:
    """``samples`` rounded up to whole revolutions of ``rev`` samples, at least two and at
    most :data:`MAX_PHASE_S`."""
    return rev * max(2, int(math.ceil(min(samples, MAX_PHASE_S * fs) / rev)))


def _synchronous(x: np.ndarray, t: np.ndarray, w: float) -> float:
    """The largest amplitude at ``w`` (rad/s) of the columns of ``x`` over the window
    ``t``: each column fitted by least squares with a cos ωt + b sin ωt + c (exact for a
    sinusoid whatever the window's length in periods), amplitude √(a² + b²)."""
    basis = np.column_stack([np.cos(w * t), np.sin(w * t), np.ones_like(t)])
    coef = np.linalg.lstsq(basis, x, rcond=None)[0]
    return float(np.hypot(coef[0], coef[1]).max())
