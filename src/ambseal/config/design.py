"""The ``[design]`` part of the rig file: what the controllers are asked for.

Every key is optional. A key left out is derived from the machine (its model and the rest
of the rig file) by the rule written next to it in :mod:`ambseal.design.specs`;
``ambseal design RIG --show-defaults`` prints the resolved values with their rules, and
``--set design.mu.orbit_um=8`` overrides any key on the command line (validated by this
schema). Units are SI except where the key names its unit. As in the rest of the rig file,
values are strict (a string is no number and ``"yes"`` no boolean; an integer is a number)
and bounded (the bounds beside each key in the code, with their reasons).

``[design]``
    ``d_e_um`` (µm): D_e, the largest allowed displacement error, scaling of the error
    channels (thesis P5 §3.1.4). ``d_u_a`` (A): D_u, the largest allowed current change,
    scaling of the current channels.
    ``model_states`` (even, ≥ 2): mechanical states of the design model (the lowest modes of
    the supported rotor), or ``model_cutoff_hz``: every mode below this frequency (Hz).
    ``band_hz`` = ``[low, high]`` (Hz): the synthesis band (the μ grid) and the judgement
    band (σ̄(S_o), compliance). ``order_max``: the controller order limit (balanced
    truncation above it). ``pressures_bar`` and ``speeds_hz``: the conditions every
    controller is judged at. ``stability_speeds_hz``: the speeds (Hz) where, at each of
    those pressures, every controller's full-order loop must also be stable (default:
    standstill to the top speed, :mod:`ambseal.design.conditions`).
``[design.unbalance]``
    ``grade_mm_s`` (ISO 21940-11 balance grade G, mm/s), ``mass_kg`` (the mass m of the
    force law), ``law`` (``"iso21940"``, the default: F_u = m·G·Ω²/Ω_max, or
    ``"constant_velocity"``: F_u = m·G·Ω; :mod:`ambseal.analysis.unbalance`),
    ``max_speed_hz`` (the maximum service speed Ω_max/2π at which the grade holds, Hz),
    ``force_at`` (the name of the seal, disk, AMB or spring where the unbalance force and
    the compliance are taken; by default the bearings), ``range_hz`` = ``[low, high]`` (the
    speeds of the unbalance response, Hz; on a machine that runs, the worst orbit is judged
    from standstill to the trip speed as well:
    :func:`ambseal.analysis.judge.unbalance_speeds_hz`), ``plant`` (``"running"``, the
    default: at each speed the plant built at that speed, gyroscopics and seals, under
    forward-turning forces; ``"frozen"``: the plant frozen at the judged condition with
    the forcing swept, the thesis's simplification, P5 §4.4.1;
    :mod:`ambseal.analysis.unbalance`).
``[design.impulse]``
    ``amplitude_a`` (A) and ``duration_s`` (s) of the current impulse of the time-domain
    judgement (P5 §5.1) and of the identification on the virtual facility (P5 §3.3), whose
    PRBS, chirp and stepped sine take the same amplitude
    (:mod:`ambseal.identify.excitation.plan`).
``[[design.uncertainty]]`` (μ)
    ``parameter``: any name of the model's LFT (``<seal>.k``, ``<seal>.K``, ``A.Ks_zeta``,
    ``coupling.kxx``, ...); and either ``relative`` (± that fraction of the nominal value,
    e.g. 1.0 for the thesis's k ± 100 %, P5 §4.1) or ``low`` and ``high`` (SI). Real.
``[design] uncertainty_from_identification`` (μ)
    The ``fit.json`` of an ``ambseal identify`` run (a path relative to the rig file; on
    the command line, to the working folder): the 95 % intervals of its fitted model
    parameters become their ``low``/``high`` ranges (``τ_e`` left out; a fit marked
    "model mismatch" refused), so identified uncertainty flows into μ as the thesis
    intends. Entries of ``[[design.uncertainty]]`` are added to them, and replace the
    range of a parameter both name.
``[design.hinf]``, ``[design.mu]``, ``[design.lpv]``
    The weights of each method (:mod:`ambseal.design.weights`): ``M``, ``omega_b_rad_s``,
    ``A`` (W_p, P5 Eq. 7), ``wu_gain``, ``wu_corner_hz``, ``wu_hf_gain`` (W_u, constant or
    high-pass), ``w1_gain``, ``w1_corner_hz`` (W_1), ``orbit_um`` (the unbalance-orbit demand
    in µm; 0 switches it off) and ``wf_rolloff_hz`` (the roll-off of its force weight W_f);
    ``[design.mu]`` also ``max_iter`` (a cap on the D–K iterations; none by default: they
    end by their stall rule) and ``dk_order`` (D-scale fit order)
    and ``iteration``: ``"dgk"`` (default: D–G–K, the real parameters kept real in the
    synthesis, Young 1996) or ``"dk"`` (complex D–K, every block treated as complex).
``[design.rejection]``
    The unbalance force rejection (:mod:`ambseal.design.synchronous_rejection`): ``enabled``
    (bool, default false) adds to every delivered controller a generalised notch filter at
    the rotational frequency, scheduled on speed over ``[operating] speed_range_hz`` and on
    from its minimum, judged at every condition with it and shown against the controller
    alone; ``rate_fraction`` (ε/Ω, default 0.05: the notch settles in ≈ 6 revolutions),
    ``points`` (that many evenly spaced speeds of its gain table; default: speeds found
    by bisection until the interpolated gain holds the notch's poles within 25 % of their
    placement) and ``runout_um`` (the synchronous
    sensor runout of its check on the virtual facility, µm; default 1 % of the smallest
    air gap or backup clearance, else 5 µm).
``[design] one_speed`` (bool, default false)
    H∞ and μ designed at ``[operating] speed_rpm`` only. By default, on a rig with a speed
    range, a design whose full-order loop loses the rotor at another judged speed is
    designed again with the spin speed a real LFT parameter, uncertain from the lowest to
    the highest judged speed (:mod:`ambseal.design.speed_lft`), and kept where it holds
    every judged condition; else it is designed again at each stability speed from
    standstill up, and the first that holds every judged condition is kept
    (:func:`ambseal.design.recipes.design`).
``[design] synthesis_plant`` (``"continuous"``, the default, or ``"sampled"``)
    The plant H∞ and μ are synthesised on. ``"continuous"``: the design model with the
    target's hold and computation delay as a Padé lag, the controller then discretised
    (:mod:`ambseal.robust.digital`). ``"sampled"``: the design model sampled by ZOH at
    ``[controller] sample_rate_hz`` with ``delay_samples`` of delay, synthesised in the
    w-plane (:mod:`ambseal.robust.w_plane`); the discrete controller is the Tustin
    transform of the one designed, exactly, and the design's own checks close it with the
    sampled full-order plant. For a low rate, where the loop as it runs parts from the
    continuous one the design foresaw. Judged as it runs alone: its w-plane form closed in
    continuous time is no loop that runs (:func:`ambseal.analysis.judge.judge_jobs`).
``[design] tracked`` (bool, default false)
    ``ambseal run`` adds the ``tracked`` controller: scheduled on the first
    seal's k as tracked on line (:mod:`ambseal.design.seal_schedule`), judged at the
    judged pressures frozen at the identified k there, and run on the virtual facility's
    0 → 3× nominal pressure ramp with the other controllers and the tracker
    (:mod:`ambseal.analysis.ramp`). Off by default: its LMI synthesis takes minutes
    (≈ 130 s of CPU on the test rig; cached in ``$AMBSEAL_CACHE_DIR``) and the ramp ≈ 20 s.
"""

from __future__ import annotations

import math
import tomllib
from typing import Annotated, Literal

from pydantic import BaseModel, ConfigDict, Field, model_validator

from ambseal.config._checks import (
    MAX_COEFFICIENT,
    MAX_CURRENT_A,
    MAX_FREQUENCY_HZ,
    MAX_GAP_M,
    MAX_PRESSURE_BAR,
    MAX_REDUCED_STATES,
    MAX_RELATIVE,
    MAX_SPEED_HZ,
)
from ambseal.errors import ConfigError

__all__ = ["Design", "MethodSpec", "MuSpec", "UncertainSpec", "UnbalanceSpec", "ImpulseSpec",
           "check_design_names", "apply_overrides"]


class _Strict(BaseModel):
    # strict as the rest of the rig file: no string or bool taken for a number or a bool
    model_config = ConfigDict(extra="forbid", frozen=True, allow_inf_nan=False, strict=True)


# Bounds of the keys below, beside the rig file's own (ambseal.config._checks):
#: a weight's gain on a scaled signal (D_e, D_u make 1 the largest allowed value): beyond
#: 1e6 (120 dB) either way the weight forbids or frees its signal outright, and the
#: synthesis's Riccati equations meet coefficients 1e12 apart
_GAIN = Field(default=None, ge=1e-6, le=1e6)
#: W_p's high-frequency bound M on |S_o|: ISO 14839-3 judges peaks of 3 to 4; 1000 (60 dB)
#: demands nothing of a loop
MAX_SENSITIVITY = 1e3
#: a frequency or frequency band (Hz)
_HZ = Field(default=None, gt=0, le=MAX_FREQUENCY_HZ)
#: judged conditions: each is a full judgement of every controller (seconds each)
MAX_CONDITIONS = 100
#: ISO 21940-11's coarsest balance quality grade (G 4000, mm/s)
MAX_GRADE_MM_S = 4000.0
#: the unbalance mass m (kg): the rig file's bound of a disk's mass
MAX_MASS_KG = 1e6
#: the longest current impulse in controller samples (the default is 100, P5 §5.1): the
#: judgement simulates 35 impulse lengths at twice the sample rate, 70 000 steps at most
MAX_IMPULSE_SAMPLES = 1000
#: the largest controller order limit: a larger one is no limit (a design model of at most
#: MAX_REDUCED_STATES states and its weights stays far below it)
MAX_ORDER = 10 * MAX_REDUCED_STATES


def _band(r, key: str, top: float = MAX_FREQUENCY_HZ):
    if r is not None and not 0 < r[0] < r[1] <= top:
        raise ValueError(f"{key}: expected [low, high] with 0 < low < high <= {top:g}")
    return r


class MethodSpec(_Strict):
    """Weights of one synthesis method (:class:`ambseal.design.weights.Weights`)."""

    M: float | None = Field(default=None, gt=0, le=MAX_SENSITIVITY)
    omega_b_rad_s: float | None = Field(default=None, gt=0, le=2 * math.pi * MAX_FREQUENCY_HZ)
    A: float | None = Field(default=None, ge=1e-6, lt=1)  # as a gain: 1/A = |W_p(0)|
    wu_gain: float | None = _GAIN
    wu_corner_hz: float | None = _HZ
    wu_hf_gain: float | None = _GAIN
    w1_gain: float | None = _GAIN
    w1_corner_hz: float | None = _HZ
    orbit_um: float | None = Field(default=None, ge=0, le=MAX_GAP_M * 1e6)  # within a gap
    wf_rolloff_hz: float | None = _HZ

    @model_validator(mode="after")
    def _wu(self) -> "MethodSpec":
        if self.wu_hf_gain is not None and self.wu_gain is not None \
                and self.wu_hf_gain <= self.wu_gain:
            raise ValueError("wu_hf_gain: expected a high-frequency gain > wu_gain")
        return self


class MuSpec(MethodSpec):
    """The μ design's weights plus its D–K settings."""

    max_iter: int | None = Field(default=None, ge=1, le=50)
    dk_order: int | None = Field(default=None, ge=0, le=8)
    iteration: Literal["dgk", "dk"] | None = None
    gain_factor: float | None = Field(default=None, ge=0, le=1e6)  # as a weight's gain
    gain_band_hz: tuple[float, float] | None = Field(default=None, strict=False)  # a list

    @model_validator(mode="after")
    def _gain_band(self) -> "MuSpec":
        _band(self.gain_band_hz, "gain_band_hz")
        return self


class UncertainSpec(_Strict):
    """One uncertain LFT parameter: ``relative`` or ``low``/``high`` (SI)."""

    parameter: str = Field(min_length=1)
    relative: float | None = Field(default=None, gt=0, le=MAX_RELATIVE)
    # every uncertain parameter is a force coefficient or factor (the rig file's bound)
    low: float | None = Field(default=None, ge=-MAX_COEFFICIENT, le=MAX_COEFFICIENT)
    high: float | None = Field(default=None, ge=-MAX_COEFFICIENT, le=MAX_COEFFICIENT)

    @model_validator(mode="after")
    def _range(self) -> "UncertainSpec":
        absolute = (self.low, self.high)
        if self.relative is not None and any(v is not None for v in absolute):
            raise ValueError("expected relative or low/high, not both")
        if self.relative is None:
            if None in absolute:
                raise ValueError("expected relative (a fraction, e.g. 1.0 for ±100 %) or "
                                 "both low and high (SI)")
            if not self.high > self.low:
                raise ValueError("expected low < high")
        return self

    @property
    def range(self) -> float | tuple[float, float]:
        """The fraction, or ``(low, high)``, as :func:`ambseal.design.plant.generalized_plant`
        takes it."""
        return self.relative if self.relative is not None else (self.low, self.high)


class UnbalanceSpec(_Strict):
    grade_mm_s: float | None = Field(default=None, gt=0, le=MAX_GRADE_MM_S)
    mass_kg: float | None = Field(default=None, gt=0, le=MAX_MASS_KG)
    law: Literal["iso21940", "constant_velocity"] | None = None
    max_speed_hz: float | None = Field(default=None, gt=0, le=MAX_SPEED_HZ)
    force_at: str | None = Field(default=None, min_length=1)
    range_hz: tuple[float, float] | None = Field(default=None, strict=False)  # a list
    plant: Literal["running", "frozen"] | None = None

    @model_validator(mode="after")
    def _r(self) -> "UnbalanceSpec":
        _band(self.range_hz, "range_hz", MAX_SPEED_HZ)
        return self


class ImpulseSpec(_Strict):
    amplitude_a: float | None = Field(default=None, gt=0, le=MAX_CURRENT_A)
    duration_s: float | None = Field(default=None, gt=0)  # bound: check_design_names


class RejectionSpec(_Strict):
    enabled: bool = False
    rate_fraction: float | None = Field(default=None, gt=0, lt=0.5)  # own poles: < 2/π
    points: int | None = Field(default=None, ge=2, le=MAX_CONDITIONS)
    runout_um: float | None = Field(default=None, gt=0, le=MAX_GAP_M * 1e6)  # within a gap


class Design(_Strict):
    """The ``[design]`` part (module docstring); every key optional."""

    d_e_um: float | None = Field(default=None, gt=0, le=MAX_GAP_M * 1e6)  # within a gap
    d_u_a: float | None = Field(default=None, gt=0, le=MAX_CURRENT_A)
    model_states: int | None = Field(default=None, ge=2, le=MAX_REDUCED_STATES)
    model_cutoff_hz: float | None = _HZ
    band_hz: tuple[float, float] | None = Field(default=None, strict=False)  # a list
    order_max: int | None = Field(default=None, ge=1, le=MAX_ORDER)
    pressures_bar: list[Annotated[float, Field(ge=0, le=MAX_PRESSURE_BAR)]] | None = Field(
        default=None, min_length=1, max_length=MAX_CONDITIONS)
    speeds_hz: list[Annotated[float, Field(ge=0, le=MAX_SPEED_HZ)]] | None = Field(
        default=None, min_length=1, max_length=MAX_CONDITIONS)
    stability_speeds_hz: list[Annotated[float, Field(ge=0, le=MAX_SPEED_HZ)]] | None = Field(
        default=None, min_length=1, max_length=MAX_CONDITIONS)
    unbalance: UnbalanceSpec = UnbalanceSpec()
    impulse: ImpulseSpec = ImpulseSpec()
    uncertainty: list[UncertainSpec] | None = None
    uncertainty_from_identification: str | None = Field(default=None, min_length=1)
    hinf: MethodSpec = MethodSpec()
    mu: MuSpec = MuSpec()
    lpv: MethodSpec = MethodSpec()
    rejection: RejectionSpec = RejectionSpec()
    one_speed: bool = False
    synthesis_plant: Literal["continuous", "sampled"] = "continuous"
    tracked: bool = False

    @model_validator(mode="after")
    def _keys(self) -> "Design":
        if self.model_states is not None and self.model_cutoff_hz is not None:
            raise ValueError("expected model_states or model_cutoff_hz, not both")
        if self.model_states is not None and self.model_states % 2:
            raise ValueError("model_states: expected an even number (a mode has 2 states)")
        _band(self.band_hz, "band_hz")
        names = [u.parameter for u in self.uncertainty or ()]
        if len(set(names)) != len(names):
            raise ValueError("uncertainty: a parameter is listed twice")
        return self


def check_design_names(cfg) -> str | None:
    """The first ``[design]`` name that the rig does not know, as a message (else None).

    Checks ``unbalance.force_at`` against the names of the rig's seals, disks, AMBs and
    springs, and the owner of each uncertain parameter (the part before the last '.')
    against the seals, AMBs and springs (a spring without a name is ``spring<i>``), and
    that ``tracked`` has a seal whose k is affine in the pressure drop, and that the
    impulse lasts at most :data:`MAX_IMPULSE_SAMPLES` controller samples.
    """
    d = cfg.design
    fs = cfg.controller.sample_rate_hz
    if d.impulse.duration_s is not None and d.impulse.duration_s * fs > MAX_IMPULSE_SAMPLES:
        return (f"design.impulse.duration_s: expected at most {MAX_IMPULSE_SAMPLES} controller "
                f"samples ({MAX_IMPULSE_SAMPLES / fs:g} s at {fs:g} Hz), got "
                f"{d.impulse.duration_s:g} s")
    parts = {s.name for s in cfg.seal} | {a.name for a in cfg.amb} | {
        (s.name or f"spring{i}") for i, s in enumerate(cfg.spring)}
    at = d.unbalance.force_at
    known = parts | {x.name for x in cfg.disk if x.name}
    if at is not None and at not in known:
        return (f"design.unbalance.force_at: no component named {at!r} (expected one of: "
                f"{', '.join(sorted(known)) or 'none'})")
    if d.tracked and not any(getattr(s.k, "per_bar", 0.0) for s in cfg.seal):
        return ("design.tracked: expected a [[seal]] whose k follows the pressure drop "
                "(k = { at_zero = ..., per_bar = ... }, per_bar ≠ 0) to schedule on")
    for i, u in enumerate(d.uncertainty or ()):
        owner = u.parameter.rpartition(".")[0]
        if owner not in parts:
            return (f"design.uncertainty[{i}].parameter: {u.parameter!r} names no seal, AMB "
                    f"or spring of the rig (known: {', '.join(sorted(parts)) or 'none'})")
    return None


def apply_overrides(data: dict, overrides, where: str = "--set") -> dict:
    """The rig document with ``design.<key>=<TOML value>`` settings applied (in place).

    Each override names a key of the ``[design]`` part by its dotted path
    (``design.mu.orbit_um=8``, ``design.band_hz=[1, 3000]``,
    ``design.uncertainty=[{parameter = "seal.k", relative = 0.5}]``); the value is read as
    a TOML value, or as a string if it is not one. The result is validated with the rest
    of the rig by :func:`parse_rig`.

    Parameters
    ----------
    data : dict
        The parsed rig document; changed in place.
    overrides : iterable of str
        ``design.<key>=<value>`` settings.
    where : str
        Where the overrides came from, named in errors (the command-line option).

    Returns
    -------
    dict
        ``data`` itself, with the overrides set.

    Raises
    ------
    ConfigError
        An override without ``=``, outside ``design.``, through a key that is not a table,
        or holding a newline or another control character (TOML would read the first line
        only and drop the rest).
    """
    for text in overrides:
        if any(ord(c) < 32 or ord(c) == 127 for c in str(text)):
            raise ConfigError(f"{where} {str(text)[:80]!r}: expected design.<key>=<value> on "
                              "one line, got a newline or another control character")
        key, eq, raw = str(text).partition("=")
        key = key.strip()
        path = key.split(".")
        if not eq or path[0] != "design" or len(path) < 2 or "" in path:
            raise ConfigError(f"{where} {text!r}: expected design.<key>=<value>, e.g. "
                              "design.mu.orbit_um=8")
        try:
            value = tomllib.loads(f"v = {raw.strip()}")["v"]
        except tomllib.TOMLDecodeError:
            value = raw.strip()
        node = data
        for part in path[:-1]:
            node = node.setdefault(part, {})
            if not isinstance(node, dict):
                raise ConfigError(f"{where} {text!r}: {part} is not a table")
        node[path[-1]] = value
    return data
