"""The design specification of a rig: its ``[design]`` part, every missing key derived from
the machine by a stated rule.

:func:`design_spec` reads the rig's ``[design]`` part (:mod:`ambseal.config.design`) and
fills each key the user left out from the rig and its model. The rules (each reproduces
the value the thesis used on its test facility, P5, where it names one):

* **Machine facts.** Rotor mass m: the assembled mass matrix (shaft and disks). First
  bending mode f_b: the lowest non-zero natural frequency of the free–free rotor at
  standstill. Actuator bandwidth f_a: the first-order cut-off, the second-order natural
  frequency, the eddy-current corner 1/(2πτ_e) if lower, or a tenth of the controller's
  sample rate without an actuator model. Bias current i0: the AMBs' ``bias_current``,
  else half their ``current_limit``. Air gap s0: ``air_gap``, else the linearisation's
  own ratio s0 = Ki·i0/Ks (Schweitzer & Maslen 2009), the smallest over AMBs and axes.
* **Scalings** (P5 §3.1.4: D_e = 20 µm, D_u = 1 A on a 0.5 mm gap and a 6 A bias):
  D_e = s0/25 (4 % of the gap) and D_u = i0/6, each rounded to two significant digits.
* **Design model**: every mode of the supported rotor below min(3 f_a, f_s/4) (the
  controller cannot act far above its actuator, nor near the Nyquist frequency), at least
  the 8 rigid-body states (2 translations and 2 tilts). Test rig: 3 × 216 Hz = 649 Hz keeps
  the 557 Hz bending pair: 12 states.
* **Band**: the top f_hi is 10 f_a rounded down to the 1–2–5 series, at most f_s/2 and at
  least 1.25× the highest kept mode; the judgement band is f_hi/4000 … f_hi, the μ
  synthesis grid 60 points from an octave higher to f_hi (test rig: 0.5 Hz–2 kHz and
  1 Hz–2 kHz).
* **Unbalance**: the speeds of ``[operating] speed_range_hz``, else up to 1.2× the
  operating speed (over-speed margin), else (a rig at standstill with no range) up to
  f_b/2 with a note (the band of the μ design's W_f; the judged worst orbit covers
  standstill to the trip speed too, :func:`ambseal.analysis.judge.unbalance_speeds_hz`);
  grade G2.5 (ISO 21940-11, precision machines); mass m; the ISO 21940-11 law
  F_u = m·G·Ω²/Ω_max with the maximum service speed Ω_max the top of
  ``[operating] speed_range_hz``, else the operating speed, else the top of the unbalance
  range (test rig: ``max_speed_hz = 500`` set, "balanced according to the G2.5 norm at
  500 Hz", P5 §4.4.1); the force at the bearings, where P5 §4.4.1 takes the compliance
  (the reason is in :mod:`ambseal.analysis.unbalance`); at each speed the plant built at
  that speed (``plant = "running"``; ``"frozen"`` is the thesis's simplification).
* **H∞ and μ weights** (P5 Eq. 7, §4.1 objective 1, §4.3): ω_B = 1/T_i of the reference
  PID (:func:`ambseal.design.pid.reference_pid`), so the
  integral time is the PID's ("tuned to achieve an integral time close to the reference
  controller of 0.2 s"; test rig 5 rad/s): the direct gains then stay within 2× the
  PID's from 1 Hz to 200 Hz (P5 Fig. 10). μ: W_u a
  constant (P5 §4.3) = D_u/(3 D_e Kp (1 + 1/ε)), so that where S_o ≈ 1 the controller
  gain stays below 3× the reference PID's peak Kp (1 + 1/ε) (P5 Fig. 10's bound; test rig
  0.095, |K| ≤ 2.1–2.5× the PID's peak below Nyquist, where a high-pass W_u of 0.02 gave
  7.6×), and beside it the gain demand W_K (:meth:`ambseal.design.weights.Weights.Wk`):
  ``|K S_o| ≤ 2·3 |K_PID|`` over 0.75–1.1× the top of the unbalance band (test rig
  150–220 Hz), i.e. the direct gain within 2× the PID's where |S_o| nears its zone-A
  bound 3, the phase lead above the band left free (the trials behind ω_B, W_u and W_K:
  benchmarks/README.md, "Where the design defaults come from"). The orbit demand 0.5 D_e (test rig
  10 µm: the demand adds its force channel to the design, the thesis's 8 µm is met with
  margin, 4.6 µm); W_f rolls off at 1.3× the top of the unbalance band, at most f_b/2
  (both from the rig and its model). The other weights are the method's
  tuning on the scaled plant (:func:`ambseal.design.weights.default_weights`). H∞ has no
  orbit demand unless ``[design.hinf] orbit_um`` is set, or it is scheduled on the spin
  speed (:func:`ambseal.design.recipes.design`, which then demands μ's); its W_f roll-off
  follows the same rule.
* **LPV weights** (P3 Eq. 11, §3.3): the same D_e and D_u; W_u a high-pass whose
  low-frequency gain is D_u/(2.5 D_e Kp (1 + 1/ε)) (μ's form, above, before W_K made μ's
  3×: the LPV designs have no W_K) and which rises tenfold above its corner
  at the actuator bandwidth f_a, rolling the controller off at the bending modes the
  rigid-body LPV design model leaves out (turboexpander: D_u 0.42 A, W_u 0.037 → 0.37 at
  1.5 kHz, where P3 §3.3 puts the crossover at 1.4 kHz) — or lower, at 1/(8τ), where the
  controller's hold + computation delay τ = (n_d + ½)/f_s lags by 45° as the actuator
  does at f_a: beyond it the sampled controller no longer acts as the continuous one it
  was designed as (the flywheel's, 20 kHz with one sample: 1.6 kHz, not f_a = 2 kHz;
  benchmarks/README.md). M = 2, ω_B = 2π·50 rad/s and
  A = 1e-2 stay the method's tuning (P3's 20 ms settling; :mod:`ambseal.design.lpv_design`).
* **Uncertainty** (μ): the cross-coupled stiffness k ± 100 % of every seal, by its own
  name (P5 §4.1); a seal with k = 0 at the design pressure, or a rig without a seal, has
  none (a note says so, and μ then designs for robust performance on the nominal plant).
* **Controller order**: the design model's states plus those of W_p and W_u (the order of
  an H∞ controller on the design model; the D-scales and W_f are truncated).
* **Impulse**: i0/120 for 100 controller samples (test rig: 0.05 A for 10 ms, P5 §5.1);
  the rule is the identification excitation's (:mod:`ambseal.identify.excitation.plan`), written
  there once.
* **Judged conditions**: pressure drops 0, nominal and 2× nominal (P5 §4); the operating
  speed, or, for a rig whose seals change with speed over a range, its ends and middle.
  Stability is also required from standstill to the top speed (the top of the speed range,
  else the operating speed) in quarters, at each judged pressure.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import asdict, dataclass, field, fields, replace
from types import MappingProxyType

import numpy as np

from ambseal.config import MAX_GAP_M, toml_string
from ambseal.design.conditions import judged_conditions, stability_speeds
from ambseal.design.pid import reference_pid
from ambseal.design.weights import default_weights
from ambseal.errors import ConfigError, DataError
from ambseal.identify import (
    BIAS_PER_AMPLITUDE,
    SAMPLES_PER_IMPULSE,
    impulse_amplitude,
    impulse_length,
    uncertainty_from_fit,
)
from ambseal.model import (
    amb_factors,
    assemble_rotor,
    bias_current,
    bias_currents,
    build_system,
    coefficient_value,
    modes_from_poles,
    poles_near_zero,
)

__all__ = ["Machine", "DesignSpec", "air_gaps", "design_spec", "design_states_at", "machine",
           "round_125", "judged_conditions"]

RIGID_STATES = 8  # 2 translations and 2 tilts of a rigid rotor, 2 states each
#: ω_B·T_i of the H∞ and μ performance weights (module docstring, "H∞ and μ weights")
OMEGA_B_TIMES_TI = 1.0
#: 1/W_u in multiples of the reference PID's peak gain, LPV and μ (module docstring)
WU_PID_PEAKS, MU_WU_PID_PEAKS = 2.5, 3.0
#: μ's gain demand W_K: |K| within 2× the PID's (P5 Fig. 10) over 0.75–1.1× the top of
#: the unbalance band (module docstring)
GAIN_FACTOR, GAIN_BAND = 2.0, (0.75, 1.1)
#: μ's orbit demand in multiples of D_e (module docstring)
ORBIT_PER_DE = 0.5
#: the LPV design's W_u: high-frequency over low-frequency gain, and its corner's delay
#: bound 1/(8τ), where the delay τ lags by 45° (module docstring)
LPV_WU_RISE, LPV_WU_DELAY_PER_TAU = 10.0, 8.0


def round_125(x: float) -> float:
    """The largest number of the 1–2–5 series (…, 1, 2, 5, 10, 20, …) not above ``x`` > 0."""
    e = math.floor(math.log10(x))
    return max(m * 10.0**e for m in (1, 2, 5) if m * 10.0**e <= x * (1 + 1e-12))


def _sig2(x: float) -> float:
    return float(f"{x:.2g}")


def _floor2(x: float) -> float:
    """``x`` > 0 rounded down to two significant digits (a bound stays a bound)."""
    e = math.floor(math.log10(x)) - 1
    return math.floor(x / 10.0**e * (1 + 1e-12)) * 10.0**e


@dataclass(frozen=True)
class Machine:
    """What the defaults are derived from (SI, Hz where named).

    Attributes
    ----------
    mass_kg : float
    first_bending_hz : float or None
        None when the free–free rotor has no bending mode below the model's top.
    actuator_hz : float
    bias_current_a, air_gap_m : float or None
        None when the rig gives neither (then D_e, D_u and the impulse need keys).
    sample_rate_hz : float
    delay_s : float
        The digital controller's hold + computation delay τ = (n_d + ½)/f_s (s).
    """

    mass_kg: float
    first_bending_hz: float | None
    actuator_hz: float
    bias_current_a: float | None
    air_gap_m: float | None
    sample_rate_hz: float
    delay_s: float


def air_gaps(cfg, biases=None) -> list[float | None]:
    """Each AMB's nominal radial air gap s0 (m): its ``air_gap``, else the smallest over its
    axes of the linearisation's own ratio Ki·i0/Ks (Schweitzer & Maslen 2009); None where
    neither is known (no bias current, Ks = 0, or a ratio beyond an ``air_gap``'s bound).

    Parameters
    ----------
    cfg : RigConfig
        The rig, with its ``[[amb]]`` tables.
    biases : list of float or None, optional
        Each AMB's bias current (A), as :func:`ambseal.model.bias_currents` gives them.

    Returns
    -------
    list of float or None
        One per ``[[amb]]``, in their order.
    """
    out = []
    for a, b in zip(cfg.amb, bias_currents(cfg) if biases is None else biases):
        ratios = [] if b is None else [k_i * b / k_s for k_i, k_s in zip(*amb_factors(a))
                                       if k_i * b <= MAX_GAP_M * k_s]
        out.append(a.air_gap if a.air_gap is not None else min(ratios) if ratios else None)
    return out


def machine(cfg) -> Machine:
    """The machine facts of a rig (module docstring, "Machine facts").

    Parameters
    ----------
    cfg : RigConfig
        The rig.

    Returns
    -------
    Machine
    """

    free = build_system(cfg, speed_rpm=0.0, include_amb=False, include_seals=False,
                        include_springs=False)
    disk = poles_near_zero(free, oscillating=1)  # a fine mesh: its lowest modes only
    fb = [f for f in modes_from_poles(disk.poles, disk.w_max).natural_frequencies_hz if f > 0]
    act = cfg.actuator
    fs = cfg.controller.sample_rate_hz
    fa = {"first_order": act.cutoff_hz,
          "second_order": (act.natural_frequency or 0) / (2 * math.pi)}.get(act.model, fs / 10)
    if act.eddy_time_constant > 0:
        fa = min(fa, 1 / (2 * math.pi * act.eddy_time_constant))
    biases = bias_currents(cfg)
    i0 = bias_current(cfg)
    gaps = [g for g in air_gaps(cfg, biases) if g is not None]
    s0 = min(gaps) if gaps else None
    return Machine(float(assemble_rotor(cfg).mass), fb[0] if fb else None, float(fa), i0,
                   s0, float(fs), (cfg.controller.delay_samples + 0.5) / float(fs))


@dataclass(frozen=True)
class DesignSpec:
    """A rig's resolved design specification (module docstring for the rules).

    Attributes
    ----------
    machine : Machine
    d_e, d_u : float or None
        Scalings (m, A); None when the rig gives no way to derive them (a note says so).
    model_states : int
        Mechanical states of the design model.
    model_cutoff_hz : float
        The frequency below which the design model keeps every mode (Hz).
    band_hz : (float, float)
        Judgement band (Hz); the μ grid spans ``synthesis_band_hz``.
    synthesis_band_hz : (float, float)
    order_max : int or None
        Controller order limit; None: the rule of :func:`ambseal.design.recipes.design`.
    pressures_bar, speeds_hz : tuple of float
        Judged conditions.
    stability_speeds_hz : tuple of float
        Speeds (Hz, standstill to the top) where the full-order loop must be stable at
        every judged pressure (:func:`ambseal.design.conditions.stability_speeds`).
    nominal_pressure_bar, nominal_speed_hz : float
        The rig's operating point (``[operating]``): the judged conditions are named low,
        nominal or high against it.
    unbalance_grade_mm_s, unbalance_mass_kg : float
    unbalance_law : str
        ``"iso21940"`` or ``"constant_velocity"`` (:mod:`ambseal.analysis.unbalance`).
    unbalance_max_speed_hz : float
        Maximum service speed Ω_max/2π (Hz) of the ISO law.
    force_at : str or None
        Component name of the unbalance force (None: the bearings).
    force_positions_m : tuple of float
        Axial positions (m) of the force inputs: the AMBs', or the named component's.
    unbalance_range_hz : (float, float)
    impulse_a, impulse_s : float or None
    uncertainty : Mapping
        ``{parameter: fraction or (low, high)}`` (read-only).
    weights : Mapping
        ``{"hinf" | "mu" | "lpv": Weights}`` (read-only).
    max_iter : int or None
        ``[design.mu] max_iter``, a cap on each D–K / D–G–K phase's iterations; None (the
        default): each phase ends by its stall rule or the target μ of 1
        (:func:`~ambseal.robust.dgk.musyn_dgk`).
    dk_order : int
    mu_iteration : {"dgk", "dk"}
        μ synthesis: D–G–K (real parameters kept real, Young 1996; its steps taken only
        where complex D–K leaves μ above 1) or complex D–K.
    unbalance_plant : {"running", "frozen"}
        The plant of the judged unbalance response (:mod:`ambseal.analysis.unbalance`): at
        each speed the one built at that speed, or frozen at the judged condition (the
        thesis's simplification).
    sources : Mapping
        ``{key: "set" | rule text}``: where each value came from (read-only).
    notes : tuple of str
    """

    machine: Machine
    d_e: float | None
    d_u: float | None
    model_states: int
    model_cutoff_hz: float
    band_hz: tuple
    synthesis_band_hz: tuple
    order_max: int | None
    pressures_bar: tuple
    speeds_hz: tuple
    stability_speeds_hz: tuple
    nominal_pressure_bar: float
    nominal_speed_hz: float
    unbalance_grade_mm_s: float
    unbalance_mass_kg: float
    unbalance_law: str
    unbalance_max_speed_hz: float
    force_at: str | None
    force_positions_m: tuple
    unbalance_range_hz: tuple
    impulse_a: float | None
    impulse_s: float
    uncertainty: Mapping
    weights: Mapping = field(repr=False)
    max_iter: int | None = None
    dk_order: int = 2
    mu_iteration: str = "dgk"
    unbalance_plant: str = "running"
    sources: Mapping = field(default_factory=dict, repr=False)
    notes: tuple = ()

    def to_dict(self) -> dict:
        """JSON-ready: the values (units in the keys), their sources and the notes."""
        d = {f.name: getattr(self, f.name) for f in fields(self)
             if f.name not in ("weights", "machine")}
        d["sources"] = dict(self.sources)
        d["machine"] = asdict(self.machine)
        d["weights"] = {m: w.to_dict() for m, w in self.weights.items()}
        d["uncertainty"] = {k: (list(v) if isinstance(v, tuple) else v)
                            for k, v in self.uncertainty.items()}
        d["d_e_m"], d["d_u_a"] = d.pop("d_e"), d.pop("d_u")
        d["notes"] = list(self.notes)
        return d

    def to_toml(self) -> str:
        """The resolved ``[design]`` part as TOML a rig file accepts, each value followed
        by where it came from (``set`` or its rule), the machine facts and notes as
        comments (``ambseal design --show-defaults``)."""
        src = self.sources
        m = self.machine
        fmt = _toml_num

        def line(key, value, rule_key=None):
            rule = src.get(rule_key or key, "")
            return f"{key} = {value}" + (f"  # {rule}" if rule else "")

        out = [f"# machine: mass {m.mass_kg:.4g} kg, first free-free bending mode "
               f"{fmt(m.first_bending_hz)} Hz, actuator bandwidth f_a {m.actuator_hz:.4g} Hz, "
               f"bias current {fmt(m.bias_current_a)} A, air gap {fmt(m.air_gap_m)} m, "
               f"sample rate f_s {m.sample_rate_hz:g} Hz"]
        out += [f"# note: {n}" for n in self.notes]
        out += ["[design]",
                line("d_e_um", fmt(self.d_e * 1e6)) if self.d_e else "# d_e_um: needs a value",
                line("d_u_a", fmt(self.d_u)) if self.d_u else "# d_u_a: needs a value",
                line("model_states", self.model_states),
                line("band_hz", f"[{fmt(self.band_hz[0])}, {fmt(self.band_hz[1])}]"),
                line("order_max", self.order_max) if self.order_max else
                "# order_max: design model states + W_p and W_u states (H∞ order)",
                f"pressures_bar = [{', '.join(fmt(x) for x in self.pressures_bar)}]",
                f"speeds_hz = [{', '.join(fmt(x) for x in self.speeds_hz)}]",
                line("stability_speeds_hz",
                     f"[{', '.join(fmt(x) for x in self.stability_speeds_hz)}]"),
                "", "[design.unbalance]",
                f"grade_mm_s = {fmt(self.unbalance_grade_mm_s)}",
                f"mass_kg = {fmt(self.unbalance_mass_kg)}  # assembled rotor mass",
                line("law", toml_string(self.unbalance_law), "unbalance.law"),
                line("max_speed_hz", fmt(self.unbalance_max_speed_hz), "unbalance.max_speed_hz"),
                *([line("force_at", toml_string(self.force_at), "unbalance.force_at")]
                  if self.force_at else ["# force_at: none (the bearings, P5 §4.4.1)"]),
                line("range_hz", f"[{fmt(self.unbalance_range_hz[0])}, "
                     f"{fmt(self.unbalance_range_hz[1])}]", "unbalance.range_hz"),
                line("plant", toml_string(self.unbalance_plant), "unbalance.plant"),
                "", "[design.impulse]",
                *([line("amplitude_a", fmt(self.impulse_a), "impulse")] if self.impulse_a
                  else ["# amplitude_a: no bias current, none"]),
                f"duration_s = {fmt(self.impulse_s)}"]
        for name, rng in self.uncertainty.items():
            r = f"relative = {fmt(rng)}" if np.isscalar(rng) else \
                f"low = {fmt(rng[0])}\nhigh = {fmt(rng[1])}"
            out += ["", "[[design.uncertainty]]  # " + src.get("uncertainty", ""),
                    f"parameter = {toml_string(name)}", r]
        for method, w in self.weights.items():
            out += ["", f"[design.{method}]"] + _weight_lines(method, w, src)
            if method == "mu":
                out += ([f"max_iter = {self.max_iter}"] if self.max_iter is not None
                        else ["# max_iter: none, each D–K phase ends by its stall rule"])
                out += [f"dk_order = {self.dk_order}",
                        f"iteration = {toml_string(self.mu_iteration)}"]
        return "\n".join(out) + "\n"


def _toml_num(x) -> str:
    return "nan" if x is None else f"{float(x):.6g}"


def _weight_lines(method: str, w, src: dict) -> list[str]:
    keys = ("M", "omega_b", "A", "wu_gain", "wu_corner_hz", "wu_hf_gain", "w1_gain",
            "w1_corner_hz", "orbit_um", "wf_rolloff_hz") \
        + (("gain_factor", "gain_band_hz") if method == "mu" else ())
    out = []
    for k in keys:
        v = getattr(w, k)
        name = "omega_b_rad_s" if k == "omega_b" else k
        if v is None:
            out.append(f"# {name}: none")
            continue
        rule = src.get(f"{method}.{name}", "")
        val = (f"[{_toml_num(v[0])}, {_toml_num(v[1])}]" if isinstance(v, tuple)
               else _toml_num(v))
        out.append(f"{name} = {val}" + (f"  # {rule}" if rule else ""))
    return out


def _need(value, key: str, what: str):
    if value is None:
        raise ConfigError(f"design.{key}: cannot be derived ({what}); set it in [design] "
                          f"or with --set design.{key}=...")
    return value


def _scalings(d, mach: Machine, rules: dict, notes: list):
    """D_e (m) and D_u (A): set, or from the air gap and the bias current (None, with a
    note, when the rig gives neither: only a design needs them)."""
    d_e = d_u = None
    if d.d_e_um is not None:
        d_e, rules["d_e_um"] = d.d_e_um * 1e-6, "set"
    elif mach.air_gap_m is not None:
        d_e, rules["d_e_um"] = _sig2(mach.air_gap_m / 25), "air gap / 25, 2 significant digits"
    else:
        notes.append("D_e cannot be derived (no air_gap, bias_current or current_limit): "
                     "H∞ and μ need design.d_e_um")
    if d.d_u_a is not None:
        d_u, rules["d_u_a"] = float(d.d_u_a), "set"
    elif mach.bias_current_a is not None:
        d_u = _sig2(mach.bias_current_a / 6)
        rules["d_u_a"] = "bias current / 6, 2 significant digits"
    else:
        notes.append("D_u cannot be derived (no bias_current or current_limit): H∞ and μ "
                     "need design.d_u_a")
    return d_e, d_u


def _design_model(cfg, d, mach: Machine, rules: dict) -> tuple[int, float, float]:
    """States and cut-off (Hz) of the design model (module docstring, "Design model"), and
    the highest mode it keeps (Hz); from the supported rotor's lowest eigenvalues only
    (:func:`~ambseal.model.modes.poles_near_zero`: a fine mesh has thousands)."""

    sys = build_system(cfg)
    if d.model_states is not None:
        rules["model_states"] = "set"
        n = int(d.model_states)
        lam = np.abs(poles_near_zero(sys, count=n).poles) / (2 * math.pi)
        top = float(lam[min(n, lam.size) - 1])
        return n, top, top
    if d.model_cutoff_hz is not None:
        rules["model_states"] = "set (model_cutoff_hz)"
        cut = float(d.model_cutoff_hz)
    else:
        cut = min(3 * mach.actuator_hz, mach.sample_rate_hz / 4)
        rules["model_states"] = (f"every mode below min(3 f_a, f_s/4) = {cut:.4g} Hz, "
                                 f"at least the {RIGID_STATES} rigid-body states")
    n, lam = _below(sys, cut)
    return n, cut, float(lam[min(n, lam.size) - 1])


def _below(sys, cut: float) -> tuple[int, np.ndarray]:
    """The design model's states under the cut-off rule — every mode of ``sys`` below
    ``cut`` Hz, at least :data:`RIGID_STATES` — and the frequencies (Hz) it looked at."""
    lam = np.abs(poles_near_zero(sys, count=RIGID_STATES,
                                 radius_rad_s=2 * math.pi * cut).poles) / (2 * math.pi)
    return max(RIGID_STATES, int(np.sum(lam < cut))), lam


def design_states_at(cfg, spec: "DesignSpec", speed_hz: float) -> int:
    """The design model's states for a design at ``speed_hz`` (Hz): ``spec``'s rule
    applied to the rig's model at that speed — every mode below ``spec.model_cutoff_hz``,
    at least :data:`RIGID_STATES` — or ``spec.model_states`` where the user set that
    count (``[design] model_states``).

    The count ``spec`` holds was taken at the operating speed, where the gyroscopic
    moments split each whirl pair; at standstill an axisymmetric rotor's ζ and η modes
    are a repeated pair, and that count can fall between them, which no modal reduction
    can keep (:func:`ambseal.model.modal_reduction`). The same cut-off at the design
    speed counts whole pairs."""
    if spec.sources.get("model_states") == "set":
        return int(spec.model_states)
    at = cfg.model_copy(update={"operating": cfg.operating.model_copy(
        update={"speed_rpm": 60.0 * float(speed_hz)})})
    return _below(build_system(at), spec.model_cutoff_hz)[0]


def _bands(d, mach: Machine, top_mode_hz: float, rules: dict):
    if d.band_hz is not None:
        rules["band_hz"] = "set"
        lo, hi = (float(x) for x in d.band_hz)
        return (lo, hi), (lo, hi)
    hi = min(round_125(10 * mach.actuator_hz), mach.sample_rate_hz / 2)
    hi = max(hi, 1.25 * top_mode_hz)
    rules["band_hz"] = ("10 f_a rounded down to 1-2-5, at most f_s/2, at least 1.25× the "
                        "highest kept mode; judged from f_hi/4000, synthesised from an octave higher")
    return (hi / 4e3, hi), (2 * hi / 4e3, hi)


def _unbalance(cfg, d, mach: Machine, rules: dict, notes: list):
    u = d.unbalance
    if u.range_hz is not None:
        rng, rules["unbalance.range_hz"] = tuple(u.range_hz), "set"
    elif cfg.operating.speed_range_hz is not None:
        rng = tuple(cfg.operating.speed_range_hz)
        rules["unbalance.range_hz"] = "[operating] speed_range_hz"
    elif cfg.operating.speed_rpm > 0:
        f = cfg.operating.speed_rpm / 60.0
        rng = (f / 100, 1.2 * f)
        rules["unbalance.range_hz"] = "up to 1.2× the operating speed"
    else:
        top = _need(mach.first_bending_hz, "unbalance.range_hz", "no speed and no bending mode")
        rng = (top / 500, top / 2)
        rules["unbalance.range_hz"] = "standstill, no speed range: up to f_b/2"
        notes.append(f"the rig states no speed: the unbalance response is judged up to "
                     f"f_b/2 = {top / 2:.4g} Hz (set [operating] speed_range_hz)")
    at = u.force_at
    parts = {x.name: x.position for x in (*cfg.seal, *cfg.disk, *cfg.amb, *cfg.spring)
             if getattr(x, "name", None)}
    pos = (float(parts[at]),) if at is not None else tuple(float(a.position) for a in cfg.amb)
    if not pos:
        pos = (cfg.length / 2,)
    rules["unbalance.force_at"] = "set" if at else "the bearings (P5 §4.4.1), else mid-span"
    law = u.law or "iso21940"
    rules["unbalance.law"] = "set" if u.law else "ISO 21940-11: F = m G Ω²/Ω_max"
    rules["unbalance.plant"] = ("set" if u.plant else "at each speed the plant built at that "
                                "speed (gyroscopics, seals), forward-turning forces")
    if u.max_speed_hz is not None:
        top, rules["unbalance.max_speed_hz"] = float(u.max_speed_hz), "set"
    elif cfg.operating.speed_range_hz is not None:
        top = float(cfg.operating.speed_range_hz[1])
        rules["unbalance.max_speed_hz"] = "top of [operating] speed_range_hz"
    elif cfg.operating.speed_rpm > 0:
        top = cfg.operating.speed_rpm / 60.0
        rules["unbalance.max_speed_hz"] = "the operating speed"
    else:
        top, rules["unbalance.max_speed_hz"] = float(rng[1]), "top of the unbalance range"
    return rng, at, pos, law, top


def _uncertainty(cfg, d, rules: dict, notes: list, pressure_bar: float) -> dict:
    if d.uncertainty_from_identification is not None or d.uncertainty is not None:
        out: dict = {}
        if d.uncertainty_from_identification is not None:
            try:
                out = dict(uncertainty_from_fit(d.uncertainty_from_identification))
            except DataError as exc:
                raise ConfigError(f"design.uncertainty_from_identification: {exc}") from None
        out.update({u.parameter: u.range for u in d.uncertainty or ()})
        rules["uncertainty"] = " + ".join(
            ([f"95 % intervals of {d.uncertainty_from_identification}"]
             if d.uncertainty_from_identification else []) + (["set"] if d.uncertainty else []))
        return out

    out = {}
    for s in cfg.seal:
        if coefficient_value(s.k, pressure_bar, cfg.speed / (2 * math.pi)) != 0:
            out[f"{s.name}.k"] = 1.0
        else:
            notes.append(f"seal {s.name!r} has k = 0 at {pressure_bar:g} bar: no uncertainty "
                         "on it")
    if not cfg.seal:
        notes.append("the rig has no seal: μ is designed without seal uncertainty (robust "
                     "performance on the nominal plant)")
    rules["uncertainty"] = "k ± 100 % of every seal (P5 §4.1)"
    return out


def _weights(d, method: str, mach: Machine, d_e: float, d_u: float, band_hi: float,
             unb_range, rules: dict, pid: dict):

    spec = getattr(d, method)
    w = default_weights(method)
    if d_e is not None and d_u is not None:
        w = replace(w, d_e=d_e, d_u=d_u)
    if method in ("mu", "lpv") and d_e is not None and d_u is not None:
        k_peak = pid["kp"] * (1 + 1 / pid["eps"])  # P5 Eq. 6 at high frequency
        peaks = MU_WU_PID_PEAKS if method == "mu" else WU_PID_PEAKS
        w = replace(w, wu_gain=_sig2(d_u / (peaks * d_e * k_peak)))
        rules[f"{method}.wu_gain"] = (f"D_u/({peaks:g} D_e Kp (1 + 1/ε)): |K| ≤ {peaks:g}× "
                                      "the reference PID's peak where S_o ≈ 1")
    if method == "lpv":
        f_tau = 1.0 / (LPV_WU_DELAY_PER_TAU * mach.delay_s)  # τ ≥ half a sample
        w = replace(w, wu_hf_gain=LPV_WU_RISE * w.wu_gain,
                    wu_corner_hz=min(mach.actuator_hz, _floor2(f_tau)))
        rules["lpv.wu_hf_gain"] = f"{LPV_WU_RISE:g}× wu_gain (P3 §3.3: a high-pass W_u)"
        rules["lpv.wu_corner_hz"] = (
            "the lower of the actuator bandwidth f_a (P3 §3.3: 1.4 kHz, f_a 1.5 kHz) and "
            f"1/({LPV_WU_DELAY_PER_TAU:g} τ) rounded down to 2 digits, where the controller's "
            "hold + computation delay τ lags 45° as the actuator does at f_a")
    else:
        w = replace(w, omega_b=OMEGA_B_TIMES_TI / pid["ti"])
        rules[f"{method}.omega_b_rad_s"] = (f"{OMEGA_B_TIMES_TI:g}/T_i of the reference PID "
                                            "(integral time the PID's, P5 §4.3)")
    if method in ("hinf", "mu") and d_e is not None:
        # H∞'s too, though its orbit demand is off by default: a user who sets
        # design.hinf.orbit_um, and H∞ scheduled on speed (which turns it on), need W_f
        roll = 1.3 * unb_range[1]
        if mach.first_bending_hz is not None:
            roll = min(roll, mach.first_bending_hz / 2)
        w = replace(w, wf_rolloff_hz=roll)
        rules[f"{method}.wf_rolloff_hz"] = "1.3× the top of the unbalance band, at most f_b/2"
    if method == "mu" and d_e is not None:
        w = replace(w, orbit_um=ORBIT_PER_DE * d_e * 1e6)
        rules["mu.orbit_um"] = f"{ORBIT_PER_DE:g} D_e"
        w = replace(w, gain_factor=GAIN_FACTOR, gain_band_hz=tuple(b * unb_range[1] for b in
                    GAIN_BAND), pid_reference=tuple(pid[k] for k in ("kp", "ti", "td", "eps")))
        rules["mu.gain_factor"] = f"{GAIN_FACTOR:g} (P5 Fig. 10: within 2× the PID's)"
        rules["mu.gain_band_hz"] = (f"[{GAIN_BAND[0]:g}, {GAIN_BAND[1]:g}]× the top of the "
                                    "unbalance band")
    keys = {"omega_b_rad_s": "omega_b"}
    changes = {keys.get(k, k): (tuple(v) if isinstance(v, list) else v)
               for k, v in spec.model_dump(exclude_none=True).items()
               if k not in ("max_iter", "dk_order", "iteration")}
    if changes.get("orbit_um") == 0:
        changes["orbit_um"] = None
    for k in changes:
        rules[f"{method}.{k}"] = "set"
    return replace(w, **changes)


def design_spec(cfg, pressure_bar: float | None = None) -> DesignSpec:
    """The rig's resolved ``[design]`` part (module docstring for the rules).

    Parameters
    ----------
    cfg : RigConfig
        The rig; its ``[design]`` part wins over every rule.
    pressure_bar : float, optional
        Design pressure drop (bar) for the default uncertainty; ``[operating]`` if omitted.

    Returns
    -------
    DesignSpec

    Raises
    ------
    ConfigError
        A default that cannot be derived (no bias current and no ``current_limit``, say),
        naming the ``[design]`` key to set.
    """
    d = cfg.design
    mach = machine(cfg)
    rules: dict = {}
    notes: list = []
    p = cfg.operating.pressure_bar if pressure_bar is None else float(pressure_bar)
    d_e, d_u = _scalings(d, mach, rules, notes)
    n, cut, top_mode = _design_model(cfg, d, mach, rules)
    band, synth = _bands(d, mach, top_mode, rules)
    rng, at, pos, law, top = _unbalance(cfg, d, mach, rules, notes)
    pid = reference_pid(cfg)
    weights = {m: _weights(d, m, mach, d_e, d_u, band[1], rng, rules, pid)
               for m in ("hinf", "mu", "lpv")}
    grade = d.unbalance.grade_mm_s or 2.5
    mass = d.unbalance.mass_kg or mach.mass_kg
    weights = {m: (replace(w, unbalance_law=law, max_speed_rad_s=2 * math.pi * top,
                           unbalance_grade_mm_s=grade, unbalance_mass_kg=mass,
                           force_positions_m=w.force_positions_m or pos)
                   if m != "lpv" else w) for m, w in weights.items()}
    if mach.bias_current_a is None and d.impulse.amplitude_a is None:
        notes.append("no bias current: the impulse amplitude needs design.impulse.amplitude_a")
    imp_a, imp_s = impulse_amplitude(cfg), impulse_length(cfg)  # the identification's too
    rules["impulse"] = (f"bias current / {BIAS_PER_AMPLITUDE} for {SAMPLES_PER_IMPULSE} "
                        "controller samples")
    pressures, speeds = judged_conditions(cfg, p)
    stability, rules["stability_speeds_hz"] = stability_speeds(cfg)
    mu = d.mu
    return DesignSpec(
        machine=mach, d_e=d_e, d_u=d_u, model_states=n, model_cutoff_hz=cut,
        band_hz=band, synthesis_band_hz=synth, order_max=d.order_max,
        pressures_bar=pressures, speeds_hz=speeds, stability_speeds_hz=stability,
        nominal_pressure_bar=float(cfg.operating.pressure_bar),
        nominal_speed_hz=float(cfg.operating.speed_rpm) / 60.0,
        unbalance_grade_mm_s=grade, unbalance_mass_kg=mass, unbalance_law=law,
        unbalance_max_speed_hz=top, force_at=at, force_positions_m=pos, unbalance_range_hz=rng, impulse_a=imp_a, impulse_s=imp_s,
        # read-only: one specification is shared by every stage of a run
        uncertainty=MappingProxyType(_uncertainty(cfg, d, rules, notes, p)),
        weights=MappingProxyType(weights),
        max_iter=mu.max_iter, dk_order=mu.dk_order if mu.dk_order is not None else 2,
        mu_iteration=mu.iteration or "dgk",
        unbalance_plant=d.unbalance.plant or "running",
        sources=MappingProxyType(rules), notes=tuple(notes))
