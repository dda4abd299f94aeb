"""The virtual test facility: a stand-in for the real rig whose truth is known.

A time-domain simulation of

- the FE rotor with its coupling and the seal at the given pressure drop, the true
  parameter values applied exactly through the LFT channels in full order, then every
  mode below ``max_mode_hz`` kept (10 kHz by default: the rigid-body modes and the
  flexible modes far past the control bandwidth; what is dropped only adds a static
  flexibility of order (f_max/f)² below 10⁻²);
- the nonlinear AMB force law of each actuator axis (Schweitzer & Maslen 2009, Eq. 3.27)

      f = k [(i0 + i)² / (s0 − x)² − (i0 − i)² / (s0 + x)²],

  with k and s0 chosen so that its linearisation has the true Ki, Ks at the bias i0
  (Ki = 4 k i0 / s0², Ks = 4 k i0² / s0³ ⇒ s0 = i0 Ki / Ks, k = Ki s0² / (4 i0));
- the amplifier of ``[actuator]`` with current limits, then the eddy-current-like lag
  1/(τ_e s + 1) between coil current and force (thesis P2 §4, Fig. 2);
- sensor noise and ADC quantisation, and the controller sampled at the rig's rate
  (:mod:`ambseal.robust.digital_loop` for the timing);
- on request, a facility that differs from the rig file in model form (``[truth]`` ``beam``,
  ``mesh_factor``, ``modal_damping``, ``sensor_filter_hz``: :func:`true_rig`), so a fit can be
  tried on data its model did not make.

The linear part (including Ki i + Ks x) is integrated exactly (zero-order hold over
``substeps`` sub-steps of each sample, in physical coordinates: a modal diagonalisation
of the nearly repeated x/y modes proved to drift in closed loop); the small nonlinear remainder
f − (Ki i + Ks x) enters as a force held over each sub-step.
"""

from __future__ import annotations

from collections import OrderedDict
from dataclasses import dataclass

import numpy as np

from ambseal.config import MAX_ELEMENTS, RigConfig, TruthSection
from ambseal.errors import ConfigError, ModelError
from ambseal.identify.facility.facility_loop import facility_loop
from ambseal.lti import series_inputs, zoh
from ambseal.model import (
    actuator_matrices,
    bias_current,
    build_system,
    coefficient_value,
    eddy_lag_matrices,
    mechanical_plant,
    modal_reduction,
)
from ambseal.robust import DiscreteController, closed_loop_matrices, is_stable, unstable_poles

__all__ = ["FacilityRecord", "Facility", "prepare_facility", "simulate_facility", "true_rig",
           "reduced_plant", "facility_bias_current", "pressure_values"]


@dataclass(frozen=True)
class FacilityRecord:
    """What the virtual facility's data acquisition records, one row per sample.

    Attributes
    ----------
    time_s : ndarray (N,)
    excitation_a, current_ref_a, current_a : ndarray (N, k)
        Excitation, current reference (after the limit) and measured coil current (A).
    displacement_m : ndarray (N, k)
        Measured sensor displacement (m), with noise and quantisation.
    axes : tuple of str
    noise_std_m : ndarray (k,)
        The sensor-noise standard deviation used per channel (m).
    """

    time_s: np.ndarray
    excitation_a: np.ndarray
    current_ref_a: np.ndarray
    current_a: np.ndarray
    displacement_m: np.ndarray
    axes: tuple[str, ...]
    noise_std_m: np.ndarray



def facility_bias_current(cfg: RigConfig, truth: TruthSection) -> float:
    """The virtual facility's bias current i0 (A): the truth file's ``bias_current``, else
    the rig's own (:func:`ambseal.model.amb.bias_current`: its AMBs' bias, or half their
    current limit).

    Parameters
    ----------
    cfg : RigConfig
    truth : TruthSection

    Returns
    -------
    float

    Raises
    ------
    ConfigError
        Neither the truth file nor the rig gives a bias current.
    """
    i0 = truth.bias_current if truth.bias_current is not None else bias_current(cfg)
    if i0 is None:
        raise ConfigError("truth: bias_current: the rig's [[amb]] give neither bias_current "
                          "nor current_limit; set [truth] bias_current (A)")
    return float(i0)

def true_rig(cfg: RigConfig, truth: TruthSection) -> RigConfig:
    """The rig as the facility builds it: the rig file with the truth's model-form changes
    (beam theory, shaft elements × ``mesh_factor``, rotor modal damping).

    Parameters
    ----------
    cfg : RigConfig
        The rig file.
    truth : TruthSection
        The facility's truth.

    Returns
    -------
    RigConfig
    """
    rotor = {}
    if truth.beam is not None:
        rotor["beam"] = truth.beam
    if truth.modal_damping is not None:
        rotor["modal_damping"] = truth.modal_damping
    update = {"rotor": cfg.rotor.model_copy(update=rotor)} if rotor else {}
    if truth.mesh_factor != 1.0:
        update["shaft"] = [s.model_copy(update={"elements": max(1, round(s.elements *
                                                                        truth.mesh_factor))})
                           for s in cfg.shaft]
        n = sum(s.elements for s in update["shaft"])
        if n > MAX_ELEMENTS:  # the rig file's own limit, for the same reason
            raise ConfigError(f"truth.mesh_factor: {truth.mesh_factor:g} makes {n} beam "
                              f"elements (at most {MAX_ELEMENTS} in all, as in a rig file)")
    return cfg.model_copy(update=update) if update else cfg


def _sensor_filter(truth: TruthSection, T: float, k: int):
    """(a, b) of the sensors' discrete first-order low-pass y_f ← a y_f + b y (exact for a
    signal held over the sample), or None."""
    if truth.sensor_filter_hz is None:
        return None
    a = float(np.exp(-2 * np.pi * truth.sensor_filter_hz * T))
    return a, 1.0 - a


def _force_law(plant, names, i0: float):
    """(Ki, Ks, s0, k) per axis of the nonlinear force law whose linearisation at the bias
    ``i0`` has the plant's (true) Ki, Ks (module docstring); ModelError unless Ki, Ks > 0."""
    ki = np.array([plant.parameter(f"{m}.Ki_{ax}").nominal for m, ax in names])
    ks = np.array([plant.parameter(f"{m}.Ks_{ax}").nominal for m, ax in names])
    bad = [f"{m}.{q}_{ax}" for (m, ax), a, b in zip(names, ki, ks)
           for q, v in (("Ki", a), ("Ks", b)) if not v > 0]
    if bad:
        raise ModelError(f"the virtual facility needs Ki > 0 and Ks > 0 for its force law "
                         f"(differential driving at a bias current); not so for {', '.join(bad)}")
    s0 = i0 * ki / ks
    return ki, ks, s0, ki * s0**2 / (4 * i0)


#: The last reduced plants built by :func:`reduced_plant`, least recently used first.
_PLANTS: OrderedDict = OrderedDict()
_PLANTS_KEPT = 16


def reduced_plant(cfg: RigConfig, pressure_bar: float, speed_rpm: float | None,
                   values: dict, cutoff_hz: float):
    """The rig's mechanical plant at one condition with parameter ``values`` (SI) applied
    exactly in full order, reduced to the modes below ``cutoff_hz`` (Hz).

    The thesis procedure acquires several records and fits many windows (stepped-sine
    frequencies) at one condition with the same values; the full-order model and its
    eigendecomposition are built once for them: the result is kept, keyed on the rig's
    content (not its identity) and the arguments, for the last ``_PLANTS_KEPT`` calls.
    Plants are immutable, so sharing them is safe.

    Parameters
    ----------
    cfg : RigConfig
        The rig.
    pressure_bar : float
        Pressure drop across the seals (bar).
    speed_rpm : float or None
        Rotor speed (rpm); None for the rig's operating speed.
    values : dict
        Parameter name → value (SI), applied to the full-order plant.
    cutoff_hz : float
        The modes kept lie below it (Hz).

    Returns
    -------
    Plant
        The reduced plant, shared between calls (immutable).

    Raises
    ------
    ModelError
        A value names a parameter the rig has no channel for; no mode below the cut-off.
    """
    return _reduction(cfg, pressure_bar, speed_rpm, values, cutoff_hz).plant


def _full_plant(cfg: RigConfig, pressure_bar: float, speed_rpm: float, values: dict):
    full = mechanical_plant(build_system(cfg, pressure_bar=pressure_bar, speed_rpm=speed_rpm))
    return full.with_values(values) if values else full


def _reduction(cfg: RigConfig, pressure_bar: float, speed_rpm: float | None, values: dict,
               cutoff_hz: float):
    """:func:`reduced_plant`'s modal reduction (its plant and transformation), kept."""
    if speed_rpm is None:  # the rig's speed, as build_system takes it: one key for both
        speed_rpm = cfg.operating.speed_rpm
    key = (cfg.model_dump_json(), pressure_bar, speed_rpm, tuple(sorted(values.items())),
           cutoff_hz)
    if key in _PLANTS:
        _PLANTS.move_to_end(key)
        return _PLANTS[key]
    red = _PLANTS[key] = modal_reduction(_full_plant(cfg, pressure_bar, speed_rpm, values),
                                         cutoff_hz=cutoff_hz)
    if len(_PLANTS) > _PLANTS_KEPT:
        _PLANTS.popitem(last=False)
    return red


def pressure_values(cfg: RigConfig, truth: TruthSection, plant, pressure_bar: float) -> dict:
    """The facility's parameter values at a pressure drop, for a segment of a pressure
    schedule: every seal coefficient of the rig's model, then the truth's values over them.

    Parameters
    ----------
    cfg : RigConfig
        The rig (its seals' coefficient laws).
    truth : TruthSection
        The facility's truth (its parameter values or laws).
    plant : ambseal.model.lft.Plant
        The facility's plant; only the seal coefficients it has as parameters are set.
    pressure_bar : float
        Pressure drop (bar).

    Returns
    -------
    dict
        Parameter name → value (SI).
    """
    out = {}
    for seal in cfg.seal:
        for key in ("K", "k", "C", "c"):
            name = f"{seal.name}.{key}"
            if name in plant.parameters:
                out[name] = coefficient_value(getattr(seal, key), pressure_bar)
    out.update({k: coefficient_value(v, pressure_bar) for k, v in truth.parameters.items()})
    return out


@dataclass
class Facility:
    """The virtual facility prepared for a run: its sampled linear part per pressure
    segment, force law, sensors and limits (built by :func:`prepare_facility`), and the
    state of the linear part and of the sensors' low-pass, carried from one :meth:`run`
    to the next so that a run can go on block by block (a controller switched between
    blocks)."""

    T: float
    axes: tuple
    seg_start: np.ndarray  # first sample of each pressure segment
    Phi: np.ndarray
    Gam: np.ndarray
    mats: tuple  # C_all, D_coil, D_ieff
    law: tuple  # lsb, limit, i0, s0, kf, ki, ks, substeps, lp_a
    z: np.ndarray
    yf: np.ndarray
    n: int = 0  # samples run so far (after a loss: the sample where the rotor left)

    def run(self, controller: DiscreteController, xc: np.ndarray, e, noise, inoise):
        """Run ``len(e)`` samples from the carried state with ``controller`` (its state
        ``xc`` updated in place); returns the records ``(y, i, i_ref)``, each (N, k).

        Raises
        ------
        ModelError
            The rotor left the air gap (the loop went unstable).
        """
        N, k = np.shape(e)
        n0, n1 = self.n, self.n + N
        first = max(int(np.searchsorted(self.seg_start, n0, side="right")) - 1, 0)
        last = max(int(np.searchsorted(self.seg_start, n1 - 1, side="right")), first + 1)
        starts = np.maximum(self.seg_start[first:last] - n0, 0).astype(np.int64)
        rec = [np.empty((N, k)) for _ in range(3)]
        Km = [np.ascontiguousarray(M, dtype=float) for M in
              (controller.A, controller.B, controller.C, controller.D)]
        left = facility_loop(self.Phi[first:last], self.Gam[first:last], starts, *self.mats,
                             *Km, np.ascontiguousarray(e, dtype=float), noise, inoise,
                             *self.law, self.z, xc, self.yf, *rec)
        if left >= 0:
            self.n = n0 + left  # where it stopped
            raise ModelError(
                f"the rotor left the air gap at t = {(n0 + left) * self.T:.4f} s (loop "
                "unstable or excitation too strong)")
        self.n = n1
        return rec

    def loop_poles(self, controller: DiscreteController) -> np.ndarray:
        """Poles z of the facility's sampled loop linearised at the bias (the force law's
        remainder zero) with ``controller``, every pressure segment: the linear part held
        over one sample (its sub-step transition to the power ``substeps``), the sensors'
        low-pass and the controller, as :meth:`run` integrates them."""
        k, s, lp_a = len(self.axes), self.law[7], self.law[8]
        C_y = self.mats[0][:k]
        out = []
        for Phi, Gam in zip(self.Phi, self.Gam):
            P, G = np.eye(Phi.shape[0]), np.zeros((Phi.shape[0], k))
            for _ in range(s):  # Σ_j Φ^j Γ_i and Φ^s
                G = G + P @ Gam[:, :k]
                P = Phi @ P
            # sensors: y[n] = (1 − a) C z[n] + a w[n], w[n + 1] = y[n] (w: the filter's state)
            A = np.block([[P, np.zeros((P.shape[0], k))],
                          [(1 - lp_a) * C_y, lp_a * np.eye(k)]])
            B = np.vstack([G, np.zeros((k, k))])
            C = np.hstack([(1 - lp_a) * C_y, lp_a * np.eye(k)])
            out.append(np.linalg.eigvals(closed_loop_matrices(A, B, C, controller)[0]))
        return np.concatenate(out)


def prepare_facility(cfg: RigConfig, truth: TruthSection, sample_rate_hz: float, *,
                     pressure_bar: float,
                     pressure_schedule: list[tuple[float, float]] | None = None,
                     speed_schedule: list[tuple[float, float]] | None = None) -> Facility:
    """The virtual facility at rest, ready to run.

    Parameters
    ----------
    cfg : RigConfig
        The rig (its nominal values are replaced by the truth where the truth names them).
    truth : TruthSection
        True values, noise, ADC, τ_e, bias and limit.
    sample_rate_hz : float
        The controller and acquisition rate (Hz).
    pressure_bar : float
        Pressure drop across the seals (bar).
    pressure_schedule : list of (start_s, pressure_bar), optional
        A piecewise-constant pressure drop (bar) from each start time (s) on, as in
        :func:`simulate_facility`.
    speed_schedule : list of (start_s, speed_hz), optional
        A piecewise-constant rotor speed (Hz) from each start time (s) on (the rig's
        operating speed before the first): each segment's plant is the full-order plant
        at its speed (gyroscopics, seals) projected on the modal basis of the first
        (a Galerkin projection on the modes below ``max_mode_hz``), so that the state
        carries over a speed step. Not with a pressure schedule.

    Returns
    -------
    Facility
        The sampled linear part per pressure segment, the nonlinear force law, sensors and
        limits, with its state at rest.

    Raises
    ------
    ModelError
        Unknown truth parameters, a force law without Ki, Ks > 0.
    """
    T = 1.0 / sample_rate_hz
    if pressure_schedule and speed_schedule:
        raise ModelError("the virtual facility takes a pressure schedule or a speed "
                         "schedule, not both")
    values = {k: coefficient_value(v, pressure_bar) for k, v in truth.parameters.items()}
    # raises ModelError naming an unknown parameter
    cfg_t = true_rig(cfg, truth)
    red = _reduction(cfg_t, pressure_bar, None, values, truth.max_mode_hz)
    plant = red.plant
    segments = [(0, plant.A)]
    for start_s, p_bar in sorted(pressure_schedule or []):
        segments.append((int(round(start_s * sample_rate_hz)),
                         plant.with_values(pressure_values(cfg_t, truth, plant, p_bar)).A))
    for start_s, f_hz in sorted(speed_schedule or []):
        full = _full_plant(cfg_t, pressure_bar, 60.0 * f_hz, values)
        segments.append((int(round(start_s * sample_rate_hz)),
                         red.T_L @ np.asarray(full.A, float) @ red.T_R))
    axes = plant.axes
    k = len(axes)
    names = [a.rsplit("_", 1) for a in axes]
    i0 = facility_bias_current(cfg, truth)
    ki, ks, s0, kf = _force_law(plant, names, i0)
    limits = [a.current_limit for a in cfg.amb for _ in range(2)]
    limit = truth.current_limit or (min(x for x in limits if x) if any(limits) else np.inf)

    # continuous linear part: mechanics ← eddy lag ← amplifier; inputs [i_ref, f_rem]
    A, B, C = plant.A, plant.B, plant.C
    Fdir = np.hstack([plant.parameter(f"{m}.Ks_{ax}").B for m, ax in names])  # unit forces
    Cb = np.vstack([plant.parameter(f"{m}.Ks_{ax}").C for m, ax in names])  # bearing disp.
    n_mech = A.shape[0]
    C = np.vstack([C, Cb])
    A, B, C, _, C_eff, D_eddy = series_inputs((A, B, C, np.zeros((C.shape[0], k))),
                                              eddy_lag_matrices(truth.tau_e))
    C = np.vstack([C, C_eff])
    A, B, C, _, C_coil, D_coil = series_inputs((A, B, C, np.zeros((C.shape[0], k))),
                                               actuator_matrices(cfg.actuator))
    A_of = []  # per pressure segment: the mechanics' block of A replaced
    for n0, A_m in segments:
        A_s = A.copy()
        A_s[:n_mech, :n_mech] = A_m
        A_of.append((n0, A_s))
    # coil current i_c = C_coil z + D_coil i_ref; force current i_eff = C_eff z + D_eddy i_c
    C_y, C_b = C[:k], C[k:2 * k]
    C_ieff = C[2 * k:] + D_eddy @ C_coil
    D_ieff = D_eddy @ D_coil
    F = np.vstack([Fdir, np.zeros((A.shape[0] - n_mech, k))])
    steps = [(n0, *zoh(A_s, np.hstack([B, F]), T / truth.substeps)) for n0, A_s in A_of]
    C_all = np.vstack([C_y, C_b, C_ieff, C_coil])
    lowpass = _sensor_filter(truth, T, k)
    lp_a = 0.0 if lowpass is None else lowpass[0]  # a = 0: y_f = y exactly
    lsb = truth.adc_range_m / 2**truth.adc_bits if truth.adc_bits else 0.0
    seg_start = np.array([n0 for n0, _, _ in steps], dtype=np.int64)
    Phi, Gam = np.stack([P for _, P, _ in steps]), np.stack([G for _, _, G in steps])
    mats = tuple(np.ascontiguousarray(M, dtype=float) for M in (C_all, D_coil, D_ieff))
    law = (float(lsb), float(limit), float(i0), s0, kf, ki, ks, int(truth.substeps), lp_a)
    return Facility(T, tuple(axes), seg_start, np.ascontiguousarray(Phi),
                    np.ascontiguousarray(Gam), mats, law, np.zeros(A.shape[0]), np.zeros(k))


def simulate_facility(
    cfg: RigConfig,
    truth: TruthSection,
    excitation_a: np.ndarray,
    sample_rate_hz: float,
    controller: DiscreteController,
    *,
    pressure_bar: float,
    seed: int | None = 0,
    pressure_schedule: list[tuple[float, float]] | None = None,
) -> FacilityRecord:
    """Run the virtual facility with an excitation added to the current references.

    Parameters
    ----------
    cfg : RigConfig
        The rig (its nominal values are replaced by the truth where the truth names them).
    truth : TruthSection
        True values, noise, ADC, τ_e, bias and limit.
    excitation_a : ndarray (N, k)
        Excitation current per actuator axis (A), one row per sample.
    sample_rate_hz : float
        The controller and acquisition rate (Hz); must match ``controller.dt``.
    controller : DiscreteController
        The digital controller that levitates the rotor.
    pressure_bar : float
        Pressure drop across the seals (bar).
    seed : int, optional
        Seed of the sensor and current noise.
    pressure_schedule : list of (start_s, pressure_bar), optional
        A piecewise-constant pressure drop (bar) from each start time (s) on, for tracking
        tests (``pressure_bar`` before the first start). Each segment's plant is the reduced
        plant at ``pressure_bar`` with the seal coefficients (then the truth's values) at
        its pressure through the LFT channels: the full-order change projected on one modal
        basis, so the state carries over a pressure step.

    Returns
    -------
    FacilityRecord
        Time, excitation, current reference, coil current (A) and measured displacement (m)
        per axis, one row per sample.

    Raises
    ------
    ModelError
        Mismatched sizes or rates, unknown truth parameters, a controller that does not
        stabilise the facility's loop linearised at the bias (checked before the run: a
        pole |z| ≥ 1 at any pressure segment, named with the truth's departures from the
        rig file), or a rotor that leaves the air gap.
    """
    T = 1.0 / sample_rate_hz
    if abs(controller.dt - T) > 1e-9 * T:
        raise ModelError(f"controller dt = {controller.dt} s but the sample rate is {sample_rate_hz} Hz")
    fac = prepare_facility(cfg, truth, sample_rate_hz, pressure_bar=pressure_bar,
                           pressure_schedule=pressure_schedule)
    k = len(fac.axes)
    if controller.B.shape[1] == k and controller.C.shape[0] == k:
        _refuse_unstable(fac, controller, cfg, truth, pressure_bar)
    e = np.asarray(excitation_a, dtype=float)
    if e.ndim != 2 or e.shape[1] != k:
        raise ModelError(f"excitation has shape {e.shape}; expected (N, {k}) for axes {fac.axes}")
    if controller.B.shape[1] != k or controller.C.shape[0] != k:
        raise ModelError(f"the controller must have {k} inputs and outputs")
    rng = np.random.default_rng(seed)

    def run(noise_std):
        N = e.shape[0]
        noise = rng.standard_normal((N, k)) * noise_std
        inoise = rng.standard_normal((N, k)) * truth.current_noise_a
        fac.z[:], fac.yf[:], fac.n = 0.0, 0.0, 0
        return fac.run(controller, np.zeros(controller.A.shape[0]), e, noise, inoise)

    noise_std = np.full(k, truth.sensor_noise_m)
    if truth.noise_fraction > 0:
        y0, _, _ = run(np.zeros(k))
        noise_std = noise_std + truth.noise_fraction * np.sqrt(np.mean(y0**2, axis=0))
    y, i, ref = run(noise_std)
    t = np.arange(e.shape[0]) * T
    return FacilityRecord(t, e.copy(), ref, i, y, tuple(fac.axes), noise_std)


def _refuse_unstable(fac: Facility, controller: DiscreteController, cfg: RigConfig,
                     truth: TruthSection, pressure_bar: float) -> None:
    """ModelError when ``controller`` does not stabilise the facility's linearised loop
    (:meth:`Facility.loop_poles`), naming the least stable pole and the truth's departures
    from the rig file a controller designed on that file did not see. Such a loop either
    loses the rotor (after a slow growth: |z| = 1.001 at 10 kHz e-folds in 0.1 s) or, before
    that, records a growing oscillation that no stable model fits — neither is data."""
    z = fac.loop_poles(controller)
    if is_stable(z, fac.T):
        return
    worst = unstable_poles(z, fac.T)[0]
    s = np.log(complex(worst)) / fac.T
    f_hz, zeta = abs(s.imag) / (2 * np.pi), -s.real / abs(s)
    # a controller that loses the rig file's own model too is not the truth's to blame
    own = prepare_facility(cfg, TruthSection(tau_e=cfg.actuator.eddy_time_constant),
                           1.0 / fac.T, pressure_bar=pressure_bar)
    if not is_stable(own.loop_poles(controller), own.T):
        raise ModelError(
            f"the controller does not stabilise the virtual facility at {pressure_bar:g} bar: "
            f"its sampled loop has a pole |z| = {abs(worst):.5f} at {f_hz:.4g} Hz (ζ = "
            f"{zeta:.2g}), and it loses the rig file's own model there too (the controller, "
            "not the truth's departures from the rig file, is at fault)")
    seen = []
    if truth.tau_e != cfg.actuator.eddy_time_constant:
        seen.append(f"tau_e = {truth.tau_e * 1e3:.3g} ms (the rig file's actuator: "
                    f"{cfg.actuator.eddy_time_constant * 1e3:.3g} ms)")
    if truth.sensor_filter_hz is not None:
        seen.append(f"sensor_filter_hz = {truth.sensor_filter_hz:g}")
    if truth.parameters:
        seen.append(f"{len(truth.parameters)} parameter value(s)")
    raise ModelError(
        f"the controller does not stabilise the virtual facility at {pressure_bar:g} bar: its "
        "sampled loop has a pole "
        f"|z| = {abs(worst):.5f} at {f_hz:.4g} Hz (ζ = {zeta:.2g}), so the rotor would be "
        "lost or the record a growing oscillation"
        + (f"; the truth departs from the rig file in {'; '.join(seen)} (a controller "
           "designed on the rig file did not see these)" if seen else ""))
