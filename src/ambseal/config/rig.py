"""The rig file: a TOML description of a rotor on AMBs, validated with pydantic.

This is the only module that knows the file format. Positions are in metres from the
shaft's left end, everything else in SI, except the keys with a unit in their name
(``speed_rpm``, ``pressure_bar``, ``cutoff_hz``, ``axes_angle_deg``, ``pole_angle_deg``).
Values are strict (no string or boolean is taken for a number) and bounded: every physical
value, in each form it may take (a number, an affine law, a table), within a range far
beyond any machine (:mod:`ambseal.config._checks`), so a typo is refused naming its key.

Tables and keys (see ``examples/testrig.toml`` for a complete, commented file):

``[rotor]``
    ``beam`` = ``"timoshenko"`` (default) or ``"euler-bernoulli"``; ``name`` (optional);
    ``modal_damping`` (ζ of every free–free bending mode of shaft and disks, default 0) or
    ``[rotor.supported_modal_damping]`` ``ratios`` (ζ of the lowest modes of the rotor on
    its springs and seals at standstill, ascending) and ``others`` (ζ of the modes above,
    default 0): ROSS 3's modal damping;
    ``rayleigh_alpha`` (1/s), ``rayleigh_beta`` (s): Rayleigh damping α·M + β·K of shaft
    and disks (default 0; ROSS 3's rotor ``alpha``, ``beta``).
``[materials.NAME]``
    ``E`` (Pa), ``rho`` (kg/m³) and either ``G`` (Pa) or ``nu`` (-).
``[[shaft]]`` (left to right)
    ``length``, ``outer_diameter``, ``inner_diameter`` (default 0) in m, ``material`` (a
    NAME of ``[materials]``), ``elements`` (beam elements in the section, default 1),
    ``layers`` (optional concentric tubes ``{ outer_diameter, inner_diameter, material }``
    on the same nodes, each a beam of its own whose matrices add to the section's);
    per tube (section and layer) ``rotary_inertia`` and ``gyroscopic`` (default true: the
    element's rotary-inertia and gyroscopic matrices, either may be left out),
    ``axial_force`` (N, tension positive) and ``torque`` (N·m): their geometric stiffness;
    ``outer_diameter_right``, ``inner_diameter_right`` (m, default: the left end's): a
    tapered (conical) tube, its diameters linear along the section; ``rayleigh_alpha``
    (1/s), ``rayleigh_beta`` (s): the tube's own Rayleigh damping α·M + β·K (default 0;
    ROSS's shaft element ``alpha``, ``beta``); ``coupling`` (a table ``{ m_left, m_right,
    Ip_left, Ip_right, Id_left, Id_right, kt_x, kt_y, kr_x, kr_y, ct_x, ct_y, cr_x, cr_y }``
    in kg, kg·m², N/m, N·m/rad, N·s/m, N·m·s/rad): the section is a flexible coupling, its
    halves' inertia on its end nodes joined by those springs and dampers, instead of a
    beam (one element, no layers; its diameters and material only draw it).
``[[disk]]``
    ``position`` (m), ``mass`` (kg), ``Ip``, ``Id`` (kg·m²), ``name`` (optional).
``[[amb]]``
    ``name``, ``position``, ``sensor_position`` (m), ``axes_angle_deg`` (actuator axes ζ, η
    rotated from x, y) and either the geometry ``turns``, ``pole_area`` (m²), ``air_gap`` (m),
    ``bias_current`` (A), ``pole_angle_deg`` (default 22.5, half the angle between the two
    poles of a pole pair of an 8-pole heteropolar bearing) or ``ki`` (N/A) and ``ks`` (N/m),
    each a number or ``{ zeta = ..., eta = ... }``; with the geometry, a factor given
    explicitly (also for one axis only) wins over the geometry's
    (:func:`ambseal.model.amb.amb_factors`). Also optional ``current_limit`` (A, the
    amplifier's limit on the control current) and
    ``backup_clearance`` (m, radial clearance of the backup bearing beside the AMB, on a
    rig without ``[[touchdown]]`` bearings, whose clearances replace it:
    :meth:`RigConfig.backup_clearance`); the report sets the worst unbalance orbit
    against it and against ``air_gap``. The amplifier
    and coil (:mod:`ambseal.model.capacity`): ``supply_voltage`` (V), ``inductance`` (H,
    default from the geometry), ``resistance`` (Ω) and ``saturation_flux_density`` (T,
    default 1.2).
``[actuator]``
    ``model`` = ``"none"`` | ``"first_order"`` (``cutoff_hz``) | ``"second_order"``
    (``natural_frequency`` in rad/s, ``damping_ratio``); ``eddy_time_constant`` τ_e (s,
    default 0): a first-order lag 1/(τ_e s + 1) between coil current and force (P2 §4).
``[[seal]]``
    ``name``, ``position``, ``K``, ``k`` (N/m), ``C``, ``c`` (N·s/m), ``M`` (kg), each a number,
    ``{ at_zero = ..., per_bar = ... }`` (affine in the pressure drop) or
    ``{ frequency_hz = [...], value = [...] }`` (a table against excitation frequency,
    evaluated at the synchronous frequency, thesis P3 §4; optional ``interpolation`` =
    ``"linear"`` | ``"pchip"`` and ``extrapolation`` = ``"hold"`` | ``"linear"``, see
    :func:`ambseal.model.seal.coefficient_value`); Childs' convention
    −f = [K k; −k K] q + [C c; −c C] q̇ + M q̈.
``[[spring]]``
    ``position``, ``kxx``, ``kyy`` and optional ``kxy``, ``kyx`` (N/m), ``cxx``, ``cyy``,
    ``cxy``, ``cyx`` (N·s/m), ``mxx``, ``myy``, ``mxy``, ``myx`` (kg: added mass, e.g. a
    hole-pattern seal's), each a number or a table ``{ frequency_hz = [...], value = [...]
    }`` taken at the synchronous frequency at each speed (a bearing's coefficients over
    speed; as a seal's table, without a housing), ``axes_angle_deg`` (the axes the
    coefficients are given in, default 0), ``housing`` (optional
    ``{ mass, kxx, kyy, kxy, kyx, cxx, cyy, cxy, cyx }`` in kg, N/m, N·s/m: the spring
    joins the shaft to this mass, which its own springs and dampers hold to ground in x,
    y), ``name`` (optional), ``kind`` (``"bearing"``, the
    default, or ``"seal"``: a seal whose coefficients have no Childs form — the sign-off
    then treats it as a seal, a source, never a bearing), ``clearance`` (m, optional: the
    radial running clearance of the bearing or seal, a close clearance of the API 617
    unbalance response, as a ``[[seal]]``'s).
``[controller.pid]``
    ``kp`` (A/m), ``ti`` (s), ``td`` (s), ``eps`` (-): thesis P5 Eq. 6, per actuator axis;
    ``cross_kp`` (A/m) and ``cross_kd`` (A·s/m), default 0: cross-axis gains between the
    two axes of each bearing, i_ζ = −(K y_ζ + K_c y_η), i_η = −(K y_η − K_c y_ζ) with
    K_c = cross_kp + cross_kd·s/(ε T_d s + 1) — the cross feedback that damps a gyroscopic
    rotor's whirl (:func:`ambseal.design.pid.pid_controller`); ``cross_speed_rpm``
    (optional): the speed those gains are given at, and with it they scale with the speed,
    K_c(Ω) = K_c·Ω/Ω_ref, as the gyroscopic moments do (the PID is then scheduled on
    speed, :class:`ambseal.design.pid.ScheduledPid`); without it they are constant.
``[[controller.filter]]``
    Filters in series with the PID on every axis (:class:`PidFilter`): ``kind`` =
    ``"notch"`` (``frequency_hz``, ``width_hz``, ``depth_db`` default 20), ``"lead"`` or
    ``"lag"`` (``frequency_hz``, ``phase_deg``), ``"lowpass"`` (``frequency_hz``,
    ``damping`` default 0.7). Left out, a PID derived from the rig carries the filters
    derived with it and a given PID none; ``filter = []`` asks for none.
``[controller]``
    ``sample_rate_hz``: the rate of the digital controller (default 10 kHz);
    ``delay_samples``: the target's computation delay in whole samples (default 1: output
    from sample k applied at k + 1; :mod:`ambseal.robust.delay`).
``[operating]``
    ``speed_rpm``, ``pressure_bar`` (the nominal pressure drop across the seals),
    ``speed_range_hz`` (optional ``[low, high]``: the operating speed range, e.g. for a
    controller scheduled on speed).
``[reduction]``
    ``states`` (the number of states kept, default 8) or ``cutoff_hz``.
``[design]``
    What the controllers are asked for, every key optional (:mod:`ambseal.config.design`).
"""

from __future__ import annotations

import hashlib
import math
from pathlib import Path
from typing import Annotated, Literal

from pydantic import (
    BaseModel,
    ConfigDict,
    Field,
    ValidationError,
    field_validator,
    model_validator,
)

from ambseal.config._checks import (
    MAX_AMBS,
    MAX_COMPONENTS,
    MAX_CURRENT_A,
    MAX_DELAY_SAMPLES,
    MAX_ELEMENTS,
    MAX_FREQUENCY_HZ,
    MAX_GAP_M,
    MAX_LAYERS,
    MAX_PID_FILTERS,
    MAX_RAYLEIGH_ALPHA,
    MAX_RAYLEIGH_BETA,
    MAX_REDUCED_STATES,
    MAX_PRESSURE_BAR,
    MAX_RELATIVE,
    MAX_SPEED_HZ,
    MAX_SPEED_RPM,
    MAX_SUPPORT_STIFFNESS,
    MIN_CURRENT_A,
    MIN_FRICTION_VELOCITY,
    MIN_TIME_CONSTANT_S,
    BoundedCoefficient,
    BoundedFrequency,
    Label,
    Name,
    check_actuator,
    check_amb,
    cross_check,
)
from ambseal.config.design import Design, apply_overrides, check_design_names
from ambseal.errors import PRIMITIVE_TAGS, AmbsealError, ConfigError, describe_validation_error
from ambseal.files import load_toml

__all__ = [
    "RigConfig",
    "load_rig",
    "parse_rig",
    "check_operating",
    "apply_overrides",
    "default_rig_path",
    "Coefficient",
    "Affine",
    "FrequencyTable",
    "SPRING_BOUNDS",
    "TruthSection",
    "load_truth",
    "rig_with_values",
    "rig_parameter_names",
    "dump_rig",
    "toml_string",
]


_Big = BoundedCoefficient  # plausible bound of a force coefficient (config._checks)


class _Strict(BaseModel):
    # strict: no bool → number, no string → number, no float → int
    model_config = ConfigDict(extra="forbid", frozen=True, allow_inf_nan=False, strict=True)


#: ``uncertainty = { key = σ }`` beside a component's values: the relative 1σ uncertainty
#: (fraction) of each named value, used when an identification holds it fixed
#: (:mod:`ambseal.identify.fitting.budget` reads the keys and their defaults).
Uncertainty = dict[str, Annotated[float, Field(ge=0, le=MAX_RELATIVE)]] | None


class Material(_Strict):
    """Linear elastic isotropic material: ``E`` (Pa), ``rho`` (kg/m³), ``G`` (Pa) or ``nu``."""

    # plausible: a mass-only layer to a rigid-shaft idealisation (ROSS models a sleeve or
    # hub that adds mass but no stiffness with E = G = 1 psi = 6.9 kPa)
    E: float = Field(ge=1e3, le=1e18)
    rho: float = Field(ge=1.0, le=1e5)
    G: float | None = Field(default=None, ge=1e3, le=1e18)
    nu: float | None = Field(default=None, gt=-1, lt=0.5)

    @model_validator(mode="after")
    def _g_or_nu(self) -> "Material":
        if self.G is None and self.nu is None:
            raise ValueError("expected either G (Pa) or nu")
        if self.G is not None and self.nu is not None:
            if abs(self.E / (2 * (1 + self.nu)) / self.G - 1) > 0.01:
                raise ValueError("G and nu disagree (expected G = E/(2(1+nu)) within 1 %; "
                                 "give one of them)")
        return self

    @property
    def shear_modulus(self) -> float:
        """Shear modulus G (Pa), from ``G`` or from E/(2(1+ν))."""
        return self.G if self.G is not None else self.E / (2.0 * (1.0 + self.nu))

    @property
    def poisson(self) -> float:
        """Poisson's ratio ν, from ``nu`` or from E/(2G) − 1."""
        return self.nu if self.nu is not None else self.E / (2.0 * self.G) - 1.0


class SupportedModalDamping(_Strict):
    """Damping ratios of the rotor's modes on its supports (ROSS 3's ``modal_damping_ratio``
    and ``default_damping_ratio``): ``ratios`` of the lowest modes in ascending frequency,
    ``others`` of every mode above them."""

    # a mode per plane: 4 DOFs per node of at most 400 elements
    ratios: list[Annotated[float, Field(ge=0, lt=1)]] = Field(min_length=1, max_length=1604)
    others: float = Field(default=0.0, ge=0, lt=1)


class Rotor(_Strict):
    beam: Literal["timoshenko", "euler-bernoulli"] = "timoshenko"
    name: Label = "rotor"
    modal_damping: float = Field(default=0.0, ge=0, lt=1)
    supported_modal_damping: SupportedModalDamping | None = None
    rayleigh_alpha: float = Field(default=0.0, ge=0, le=MAX_RAYLEIGH_ALPHA)
    rayleigh_beta: float = Field(default=0.0, ge=0, le=MAX_RAYLEIGH_BETA)

    @model_validator(mode="after")
    def _one_modal_basis(self) -> "Rotor":
        if self.modal_damping and self.supported_modal_damping is not None:
            raise ValueError("modal_damping (free–free modes) and supported_modal_damping "
                             "(modes on the supports) both given: expected one of them")
        return self


class ShaftLayer(_Strict):
    """A concentric tube on its section's nodes, in parallel with the section's own tube (a
    sleeve, a shrink-fitted hub; ROSS's layered shaft elements): its own material and shear
    parameter, its element matrices added to the section's."""

    outer_diameter: float = Field(ge=1e-4, le=10.0)
    inner_diameter: float = Field(default=0.0, ge=0)
    material: str
    rotary_inertia: bool = True
    gyroscopic: bool = True
    # plausible: a tie bolt's preload or a turbine shaft's thrust is up to some MN, its
    # torque some MN·m; 1e9 N and 1e8 N·m keep a typo out without bounding any machine
    axial_force: float = Field(default=0.0, ge=-1e9, le=1e9)
    torque: float = Field(default=0.0, ge=-1e8, le=1e8)
    outer_diameter_right: float | None = Field(default=None, ge=1e-4, le=10.0)
    inner_diameter_right: float | None = Field(default=None, ge=0)
    rayleigh_alpha: float = Field(default=0.0, ge=0, le=MAX_RAYLEIGH_ALPHA)
    rayleigh_beta: float = Field(default=0.0, ge=0, le=MAX_RAYLEIGH_BETA)

    @model_validator(mode="after")
    def _bore(self) -> "ShaftLayer":
        _check_bore(self)
        return self


def _right_end(tube) -> tuple[float, float]:
    """(outer, inner) diameter (m) at a tube's right end: the ``_right`` keys, else the
    left end's (a uniform tube)."""
    return (tube.outer_diameter if tube.outer_diameter_right is None
            else tube.outer_diameter_right,
            tube.inner_diameter if tube.inner_diameter_right is None
            else tube.inner_diameter_right)


def _check_bore(tube) -> None:
    if tube.inner_diameter >= tube.outer_diameter:
        raise ValueError("expected inner_diameter < outer_diameter")
    do_r, di_r = _right_end(tube)
    if di_r >= do_r:
        raise ValueError(f"expected inner_diameter_right ({di_r:g} m) < "
                         f"outer_diameter_right ({do_r:g} m) (a tapered tube's right end)")


class ShaftCoupling(_Strict):
    """A flexible coupling in place of a section's beam (ROSS's ``CouplingElement``): a
    rigid body of each half on the section's end nodes (mass, polar and diametral inertia)
    joined by springs and dampers between the two nodes, translational in x and y and
    rotational about x (α) and y (β)."""

    m_left: float = Field(default=0.0, ge=0, le=1e6)
    m_right: float = Field(default=0.0, ge=0, le=1e6)
    Ip_left: float = Field(default=0.0, ge=0, le=1e6)
    Ip_right: float = Field(default=0.0, ge=0, le=1e6)
    Id_left: float = Field(default=0.0, ge=0, le=1e6)
    Id_right: float = Field(default=0.0, ge=0, le=1e6)
    kt_x: float = Field(default=0.0, ge=0, le=MAX_SUPPORT_STIFFNESS)
    kt_y: float = Field(default=0.0, ge=0, le=MAX_SUPPORT_STIFFNESS)
    kr_x: float = Field(default=0.0, ge=0, le=MAX_SUPPORT_STIFFNESS)
    kr_y: float = Field(default=0.0, ge=0, le=MAX_SUPPORT_STIFFNESS)
    ct_x: float = Field(default=0.0, ge=0, le=1e12)
    ct_y: float = Field(default=0.0, ge=0, le=1e12)
    cr_x: float = Field(default=0.0, ge=0, le=1e12)
    cr_y: float = Field(default=0.0, ge=0, le=1e12)


class ShaftSection(_Strict):
    length: float = Field(ge=1e-4, le=100.0)
    outer_diameter: float = Field(ge=1e-4, le=10.0)
    inner_diameter: float = Field(default=0.0, ge=0)
    material: str
    elements: int = Field(default=1, ge=1, le=MAX_ELEMENTS)
    layers: list[ShaftLayer] = Field(default=[], max_length=MAX_LAYERS)
    rotary_inertia: bool = True
    gyroscopic: bool = True
    # plausible: a tie bolt's preload or a turbine shaft's thrust is up to some MN, its
    # torque some MN·m; 1e9 N and 1e8 N·m keep a typo out without bounding any machine
    axial_force: float = Field(default=0.0, ge=-1e9, le=1e9)
    torque: float = Field(default=0.0, ge=-1e8, le=1e8)
    outer_diameter_right: float | None = Field(default=None, ge=1e-4, le=10.0)
    inner_diameter_right: float | None = Field(default=None, ge=0)
    rayleigh_alpha: float = Field(default=0.0, ge=0, le=MAX_RAYLEIGH_ALPHA)
    rayleigh_beta: float = Field(default=0.0, ge=0, le=MAX_RAYLEIGH_BETA)
    coupling: ShaftCoupling | None = None

    @model_validator(mode="after")
    def _bore(self) -> "ShaftSection":
        _check_bore(self)
        if self.coupling is not None and (self.elements != 1 or self.layers):
            raise ValueError("coupling: a coupling section is one element without layers "
                             f"(got elements = {self.elements}, {len(self.layers)} layers)")
        # the diameters run linearly from end to end: tubes apart at both ends are apart
        # everywhere between
        for end, ends in (("left", [(t.outer_diameter, t.inner_diameter)
                                    for t in (self, *self.layers)]),
                          ("right", [_right_end(t) for t in (self, *self.layers)])):
            tubes = sorted(ends, key=lambda t: t[1])
            for (ao, ai), (bo, bi) in zip(tubes, tubes[1:]):
                if bi < ao * (1 - 1e-12):
                    raise ValueError(
                        f"layers: the tubes {ai:g}–{ao:g} m and {bi:g}–{bo:g} m overlap "
                        f"at the {end} end (expected concentric tubes, each layer's inner "
                        "diameter >= the outer diameter of the tube inside it)")
        return self


class Disk(_Strict):
    position: float = Field(ge=0)
    mass: float = Field(ge=0, le=1e6)
    Ip: float = Field(default=0.0, ge=0, le=1e6)
    Id: float = Field(default=0.0, ge=0, le=1e6)
    name: Label | None = None
    # radial clearance of the disk (an impeller's shroud or tip, a wheel's) to its casing:
    # what a landing rotor must not close (ambseal drop)
    clearance: float | None = Field(default=None, ge=1e-6, le=0.1)


class AxisPair(_Strict):
    """A value per actuator axis: ``zeta`` and ``eta`` (one may be left out when the AMB's
    geometry gives it)."""

    zeta: float | None = Field(default=None, ge=-1e12, le=1e12)
    eta: float | None = Field(default=None, ge=-1e12, le=1e12)

    @model_validator(mode="after")
    def _one(self) -> "AxisPair":
        if self.zeta is None and self.eta is None:
            raise ValueError("expected zeta and/or eta")
        return self


class Amb(_Strict):
    name: Name
    position: float = Field(ge=0)
    sensor_position: float = Field(ge=0)
    axes_angle_deg: float = Field(default=0.0, ge=-360, le=360)
    turns: int | None = Field(default=None, gt=0, le=100000)
    pole_area: float | None = Field(default=None, gt=0, le=1.0)
    air_gap: float | None = Field(default=None, ge=1e-6, le=0.1)
    bias_current: float | None = Field(default=None, ge=MIN_CURRENT_A, le=MAX_CURRENT_A)
    pole_angle_deg: float = Field(default=22.5, ge=0, lt=90)
    ki: _Big | AxisPair | None = None
    ks: _Big | AxisPair | None = None
    current_limit: float | None = Field(default=None, ge=MIN_CURRENT_A, le=MAX_CURRENT_A)
    # the amplifier and the coil (ambseal.model.capacity): plausible up to a 100 kV supply,
    # a 10 H coil and 10 kΩ; saturation of soft magnetic iron lies below 2.5 T
    supply_voltage: float | None = Field(default=None, gt=0, le=1e5)
    inductance: float | None = Field(default=None, gt=0, le=10.0)
    resistance: float | None = Field(default=None, ge=0, le=1e4)
    saturation_flux_density: float = Field(default=1.2, gt=0, le=2.5)
    backup_clearance: float | None = Field(default=None, gt=0, le=1.0)
    # the displacement probe's radial gap to its target: what a landing rotor must not
    # close (ambseal drop)
    sensor_gap: float | None = Field(default=None, ge=1e-6, le=0.1)
    uncertainty: Uncertainty = None

    @model_validator(mode="after")
    def _geometry_or_factors(self) -> "Amb":
        return check_amb(self)


class Actuator(_Strict):
    model: Literal["none", "first_order", "second_order"] = "none"
    cutoff_hz: float | None = Field(default=None, gt=0, le=1e7)
    natural_frequency: float | None = Field(default=None, gt=0, le=1e8)
    damping_ratio: float | None = Field(default=None, gt=0, le=100.0)
    eddy_time_constant: float = Field(default=0.0, ge=0, le=1.0)
    uncertainty: Uncertainty = None

    @model_validator(mode="after")
    def _needs(self) -> "Actuator":
        return check_actuator(self)


class Affine(_Strict):
    """A coefficient affine in the pressure drop: ``at_zero + per_bar · pressure_bar``."""

    at_zero: float = Field(default=0.0, ge=-1e12, le=1e12)
    per_bar: float = Field(default=0.0, ge=-1e12, le=1e12)

    @model_validator(mode="before")
    @classmethod
    def _not_empty(cls, data):
        if isinstance(data, dict) and not data:
            raise ValueError("expected at_zero and/or per_bar, got an empty table")
        return data


class FrequencyTable(_Strict):
    """A coefficient tabulated against excitation frequency (Hz):
    ``{ frequency_hz = [...], value = [...] }``, interpolated by ``interpolation`` —
    ``"linear"`` (the default) or ``"pchip"`` (a shape-preserving piecewise cubic, Fritsch
    & Carlson 1980; linear between two points) — and beyond its ends by ``extrapolation``:
    ``"hold"`` (the default: the end value) or ``"linear"`` (the end slope). ROSS 3.1
    evaluates its bearing and seal tables as ``pchip``/``linear``
    (:func:`ambseal.model.seal.table_value`)."""

    frequency_hz: list[BoundedFrequency] = Field(min_length=1, max_length=10000)
    value: list[_Big] = Field(min_length=1, max_length=10000)
    interpolation: Literal["linear", "pchip"] = "linear"
    extrapolation: Literal["hold", "linear"] = "hold"

    @model_validator(mode="after")
    def _table(self) -> "FrequencyTable":
        if len(self.frequency_hz) != len(self.value):
            raise ValueError("expected frequency_hz and value of the same length")
        if any(b <= a for a, b in zip(self.frequency_hz, self.frequency_hz[1:])):
            raise ValueError("expected frequency_hz strictly increasing")
        return self


# bounded alike in every form: a number, the affine form's terms, a table's values
Coefficient = _Big | Affine
SealCoefficient = _Big | Affine | FrequencyTable


class Seal(_Strict):
    name: Name
    position: float = Field(ge=0)
    K: SealCoefficient = 0.0
    k: SealCoefficient = 0.0
    C: SealCoefficient = 0.0
    c: SealCoefficient = 0.0
    M: SealCoefficient = 0.0
    # radial running clearance: API 617's close clearances; a seal's is 10 µm to 10 mm
    clearance: float | None = Field(default=None, ge=1e-6, le=0.1)
    # the rotor's static offset in the seal (its misalignment against the bearings' axis):
    # within any clearance
    static_eccentricity: float = Field(default=0.0, ge=0, le=0.1)
    uncertainty: Uncertainty = None

    @property
    def frequency_dependent(self) -> bool:
        """Whether any coefficient is tabulated against frequency."""
        return any(isinstance(getattr(self, n), FrequencyTable) for n in "KkCcM")

    @model_validator(mode="after")
    def _offset(self) -> "Seal":
        if self.clearance is not None and self.static_eccentricity >= self.clearance:
            raise ValueError(f"static_eccentricity: expected less than the clearance "
                             f"{self.clearance:g} m, got {self.static_eccentricity:g} m")
        return self


#: ISO 76:2006's static equivalent radial load of a radial ball bearing, P₀ = X₀F_r + Y₀F_a
#: and not less than F_r (§3.4 defines it), by kind: a single-row deep-groove bearing
#: (0.6, 0.5), a pair of 40° angular-contact bearings (1, 0.52), as the bearing makers'
#: catalogues (SKF) state them. A full-complement bearing or a sleeve gives its own
#: (``static_factors``), or its axial force is not graded.
STATIC_FACTORS = {"deep_groove": (0.6, 0.5), "angular_contact_pair": (1.0, 0.52)}


class Touchdown(_Strict):
    """A touchdown (backup, auxiliary) bearing in one plane: the ring the rotor lands on
    when the AMBs let it go (ISO 14839-5:2022's touch-down bearing). ``radial_clearance``
    (m) between the journal and the ring; ``kind`` of bearing; the contact law
    F = K·δ^n (:mod:`ambseal.model.contact`): ``contact`` ``"point"`` (n = 3/2, Hertz)
    or ``"line"`` (n = 10/9, Palmgren), K as ``contact_stiffness`` (N/m^n) or from the
    geometry — a point contact's effective radius ``contact_radius`` (m) with ``E`` and
    ``nu`` of both bodies, a line contact's ``contact_length`` (m; Palmgren's relation,
    bearing steel); the contact damping solved for the measured coefficient of
    ``restitution`` e (rebound over approach speed of one impact), or a published
    ``damping_law`` at its own ``law_restitution`` (one of the two); regularised
    Coulomb ``friction`` with ``friction_velocity`` (m/s, at least
    :data:`~ambseal.config._checks.MIN_FRICTION_VELOCITY`: the slip the drop's stiff
    integrator resolves); the ring's ``race_inertia`` (kg·m²) and
    ``race_drag_torque`` (N·m); the support's ``support_stiffness`` (N/m; left out,
    rigid) with its ``support_mass`` (kg, required with it) and ``support_damping``
    (N·s/m); the bearing's basic ``static_rating`` C₀ (N, ISO 76) the drop's
    peak force is graded against, as the static equivalent load of the peak radial and
    axial forces with ``static_factors`` (X₀, Y₀; ``STATIC_FACTORS``). Where an
    ``axial_clearance`` (m) is given the bearing also stops the rotor axially, with the
    radial law's K or ``axial_contact_stiffness``. With ``race_mass`` (kg) the friction
    heat of the drop is reported as the ring's temperature rise at
    ``race_specific_heat``. The restitution and ``friction`` have no default: no
    public source gives one for every pair of surfaces. Across the rig
    (:func:`~ambseal.config._checks.cross_check`): each bearing's ``name`` its own, each
    its own plane, and every ``radial_clearance`` below every AMB's ``air_gap`` and
    ``sensor_gap``."""

    name: Name
    position: float = Field(ge=0)
    radial_clearance: float = Field(gt=0, le=0.1)
    axial_clearance: float | None = Field(default=None, gt=0, le=0.1)
    kind: Literal["deep_groove", "angular_contact_pair", "full_complement",
                  "sleeve"] = "deep_groove"
    contact: Literal["point", "line"] = "line"
    contact_stiffness: float | None = Field(default=None, gt=0, le=1e16)
    contact_radius: float | None = Field(default=None, gt=0, le=10.0)
    contact_length: float | None = Field(default=None, gt=0, le=10.0)
    # AISI 52100 bearing steel (Harris & Kotzalas, Rolling Bearing Analysis, 5th ed., 2007)
    E: float = Field(default=2.075e11, gt=1e8, le=1e13)
    nu: float = Field(default=0.3, ge=0, lt=0.5)
    # Flores et al. (2011): the one law valid from plastic-like to elastic impacts
    damping_law: Literal["hunt_crossley", "lankarani_nikravesh", "flores"] = "flores"
    # the coefficient of restitution of one impact, as measured: the damping is solved
    # for it exactly (ambseal.model.contact.damping_factor), whichever damping_law
    restitution: float | None = Field(default=None, gt=0, le=1.0)
    # the e of damping_law's own formula, as its paper gives it: an impact then rebounds
    # at that e only near 1 (kept to reproduce a published model)
    law_restitution: float | None = Field(default=None, gt=0, le=1.0)
    friction: float = Field(ge=0, le=2.0)
    # the slip speed below which friction grows in proportion to it (the regularisation):
    # small against a landing rotor's surface speed, tens of m/s; at least what the drop's
    # stiff integrator resolves (MIN_FRICTION_VELOCITY, with its measurements)
    friction_velocity: float = Field(default=1e-3, ge=MIN_FRICTION_VELOCITY, le=10.0)
    race_inertia: float | None = Field(default=None, gt=0, le=1e3)
    race_drag_torque: float = Field(default=0.0, ge=0, le=1e5)
    support_stiffness: float | None = Field(default=None, gt=0, le=1e13)
    support_damping: float = Field(default=0.0, ge=0, le=1e9)
    support_mass: float = Field(default=0.0, ge=0, le=1e5)
    # the basic static load rating C0 (ISO 76) the drop's peak force is graded against
    static_rating: float | None = Field(default=None, gt=0, le=1e9)
    # the axial contact's K (N/m^n) where an axial_clearance is given; left out, the
    # radial law's: the same rolling elements carry the axial load
    axial_contact_stiffness: float | None = Field(default=None, gt=0, le=1e16)
    # ISO 76's X0, Y0 of the static equivalent load P0 = max(Fr, X0 Fr + Y0 Fa); left
    # out, by kind (STATIC_FACTORS)
    static_factors: tuple[float, float] | None = Field(default=None, strict=False)
    # the ring's mass (kg) and specific heat (J/(kg K)): the drop's friction heat as its
    # temperature rise; 475 J/(kg K) is through-hardened bearing steel's
    race_mass: float | None = Field(default=None, gt=0, le=1e4)
    race_specific_heat: float = Field(default=475.0, gt=0, le=1e5)

    @model_validator(mode="after")
    def _stiffness(self) -> "Touchdown":
        if (self.restitution is None) == (self.law_restitution is None):
            raise ValueError("restitution: give the measured coefficient of restitution e "
                             "(restitution) or damping_law's own e (law_restitution), "
                             "one of the two" + (", not both" if self.restitution else ""))
        # a default written back by dump_rig is no key of the user's
        if (self.law_restitution is None
                and self.damping_law != type(self).model_fields["damping_law"].default):
            raise ValueError("damping_law: it reads law_restitution; with the measured "
                             "restitution the damping is solved for it, whatever the law "
                             "- leave damping_law out or give law_restitution")
        if self.contact_stiffness is None:
            if self.contact == "point" and self.contact_radius is None:
                raise ValueError("contact_radius: a point contact without "
                                 "contact_stiffness takes K from its effective radius (m)")
            if self.contact == "line" and self.contact_length is None:
                raise ValueError("contact_length: a line contact without "
                                 "contact_stiffness takes K from its length (m)")
            steel = tuple(type(self).model_fields[k].default for k in ("E", "nu"))
            if self.contact == "line" and (self.E, self.nu) != steel:
                raise ValueError("contact_stiffness: a line contact's K from its length is "
                                 "Palmgren's relation for bearing steel; for another E or "
                                 "nu give contact_stiffness (N/m^(10/9))")
        if self.kind == "sleeve" and self.race_inertia is not None:
            raise ValueError("race_inertia: a sleeve does not turn; leave it out, or give "
                             "the rolling bearing's kind")
        if self.support_mass > 0 and self.support_stiffness is None:
            raise ValueError("support_mass: a rigid support (no support_stiffness) moves "
                             "no mass; give support_stiffness or leave support_mass out")
        if self.support_stiffness is not None and self.support_mass == 0:
            # the ring on its spring is a body of its own in the drop: without a mass its
            # motion would have no inertia to integrate
            raise ValueError("support_stiffness: a flexible support needs its moving mass: "
                             "give support_mass (kg), or leave support_stiffness out for a "
                             "rigid support")
        if self.axial_contact_stiffness is not None and self.axial_clearance is None:
            raise ValueError("axial_contact_stiffness: the axial contact needs the "
                             "axial_clearance (m) at which it closes")
        if self.static_factors is not None and not all(
                0 <= f <= 10 for f in self.static_factors):
            raise ValueError("static_factors: expected [X0, Y0] of ISO 76, each 0 to 10")
        return self

    @property
    def iso76_factors(self) -> tuple[float, float] | None:
        """ISO 76's (X₀, Y₀): ``static_factors``, else ``STATIC_FACTORS`` by
        ``kind``; None where neither gives them."""
        given = self.static_factors
        return tuple(given) if given is not None else STATIC_FACTORS.get(self.kind)


class SpringHousing(_Strict):
    """The housing behind a ``[[spring]]`` (ROSS's bearing linked to a housing node that
    carries a point mass and its own supports): a mass on the spring's far end, held to
    ground by its own springs and dampers in x, y."""

    mass: float = Field(gt=0, le=1e6)
    kxx: float = Field(ge=-MAX_SUPPORT_STIFFNESS, le=MAX_SUPPORT_STIFFNESS)
    kyy: float = Field(ge=-MAX_SUPPORT_STIFFNESS, le=MAX_SUPPORT_STIFFNESS)
    kxy: float = Field(default=0.0, ge=-MAX_SUPPORT_STIFFNESS, le=MAX_SUPPORT_STIFFNESS)
    kyx: float = Field(default=0.0, ge=-MAX_SUPPORT_STIFFNESS, le=MAX_SUPPORT_STIFFNESS)
    cxx: float = Field(default=0.0, ge=-1e12, le=1e12)
    cyy: float = Field(default=0.0, ge=-1e12, le=1e12)
    cxy: float = Field(default=0.0, ge=-1e12, le=1e12)
    cyx: float = Field(default=0.0, ge=-1e12, le=1e12)


_SupportK = Annotated[float, Field(ge=-MAX_SUPPORT_STIFFNESS, le=MAX_SUPPORT_STIFFNESS)]
_SupportC = Annotated[float, Field(ge=-1e12, le=1e12)]
# added (fluid) mass of a seal or bearing, kg: far below any rotor's 1e6 kg bound
_SupportM = Annotated[float, Field(ge=-1e6, le=1e6)]
#: a spring coefficient's bounds, whether a number or a table's values
SPRING_BOUNDS = {**{k: MAX_SUPPORT_STIFFNESS for k in ("kxx", "kyy", "kxy", "kyx")},
                 **{k: 1e12 for k in ("cxx", "cyy", "cxy", "cyx")},
                 **{k: 1e6 for k in ("mxx", "myy", "mxy", "myx")}}


class Spring(_Strict):
    position: float = Field(ge=0)
    # each a number or a table over the synchronous frequency (a bearing's coefficients
    # that change with speed)
    kxx: _SupportK | FrequencyTable  # up to a pin
    kyy: _SupportK | FrequencyTable
    kxy: _SupportK | FrequencyTable = 0.0
    kyx: _SupportK | FrequencyTable = 0.0
    cxx: _SupportC | FrequencyTable = 0.0
    cyy: _SupportC | FrequencyTable = 0.0
    cxy: _SupportC | FrequencyTable = 0.0
    cyx: _SupportC | FrequencyTable = 0.0
    mxx: _SupportM | FrequencyTable = 0.0
    myy: _SupportM | FrequencyTable = 0.0
    mxy: _SupportM | FrequencyTable = 0.0
    myx: _SupportM | FrequencyTable = 0.0
    axes_angle_deg: float = Field(default=0.0, ge=-360, le=360)
    housing: SpringHousing | None = None
    name: Name | None = None
    uncertainty: Uncertainty = None
    # a seal whose coefficients have no Childs form (kxy = kyx, a balance piston's): the
    # sign-off must not take it for a bearing
    kind: Literal["bearing", "seal"] = "bearing"
    # radial running clearance of a plain bearing or seal: API 617's close clearances, as
    # a [[seal]]'s
    clearance: float | None = Field(default=None, ge=1e-6, le=0.1)

    @model_validator(mode="after")
    def _tables(self) -> "Spring":
        for key, bound in SPRING_BOUNDS.items():
            v = getattr(self, key)
            if isinstance(v, FrequencyTable) and max(abs(x) for x in v.value) > bound:
                raise ValueError(f"{key}: expected table values within ±{bound:g}")
        if self.housing is not None and self.tabulated:
            raise ValueError("housing: a spring with a housing takes constant coefficients "
                             "(no frequency table)")
        return self

    @property
    def tabulated(self) -> bool:
        """Whether a coefficient is a frequency table."""
        return any(isinstance(getattr(self, k), FrequencyTable) for k in SPRING_BOUNDS)


class Stage(_Strict):
    """One impeller (compressor) or stage (turbine) as API 617 (8th ed., 2014) needs it
    for the anticipated cross-coupling of its Level I stability screening: where it sits
    (``position`` in m, or the ``disk`` it is), its rated ``power`` (W), the impeller
    diameter D_c and the discharge width H_c (m, the smaller of the impeller's discharge
    and the diffuser's width), and the gas densities at its suction and discharge
    (kg/m³)."""

    name: Label | None = None
    position: float | None = Field(default=None, ge=0)
    disk: Label | None = None
    # a single stage of a large compressor train or turbine: up to 100 MW; a micro-turbine's
    # 10 mm wheel with a 0.1 mm passage at the small end
    power: float = Field(gt=0, le=1e8)
    impeller_diameter: float = Field(ge=1e-2, le=5.0)
    discharge_width: float = Field(ge=1e-4, le=1.0)
    # from vacuum service (1e-6 kg/m³) to dense CO2 and liquids at the limit
    suction_density: float = Field(ge=1e-6, le=2000.0)
    discharge_density: float = Field(ge=1e-6, le=2000.0)

    @model_validator(mode="after")
    def _where(self) -> "Stage":
        if (self.position is None) == (self.disk is None):
            raise ValueError("expected exactly one of position (m) and disk (a [[disk]] "
                             "name)")
        return self


class Machine(_Strict):
    """What the machine is, for the standards' rules: ``kind`` = ``"compressor"`` or
    ``"turbine"`` (API 617's anticipated cross-coupling differs); and how it stands, which
    sets where gravity acts (:mod:`ambseal.model.gravity`): ``orientation`` =
    ``"horizontal"`` (gravity along −y), ``"vertical"`` (along −z: the rotor's left end,
    where positions start, at the bottom) or ``"inclined"`` with ``inclination_deg``, the
    rotor axis's angle above the horizontal (+z rising; −90 to 90, the y axis in the
    vertical plane through the rotor axis)."""

    kind: Literal["compressor", "turbine"] = "compressor"
    orientation: Literal["horizontal", "vertical", "inclined"] = "horizontal"
    inclination_deg: float | None = Field(default=None, ge=-90, le=90)

    @model_validator(mode="after")
    def _inclination(self) -> "Machine":
        if (self.orientation == "inclined") != (self.inclination_deg is not None):
            raise ValueError("inclination_deg: expected the rotor axis's angle above the "
                             "horizontal (deg, -90 to 90) with orientation = \"inclined\", "
                             "and only then (\"horizontal\" is 0, \"vertical\" 90)")
        return self


class Probe(_Strict):
    """A displacement probe of the sign-off: its axial ``position`` (m) and the direction
    it reads, ``angle_deg`` from x towards y (a proximity probe reads x cos θ + y sin θ)."""

    position: float = Field(ge=0)
    angle_deg: float = Field(default=0.0, ge=-360, le=360)


#: The default largest penetration of a touchdown ring over its clearance: Hertz's and
#: Palmgren's laws are elastic ones, and a bearing at its static rating C₀ deforms a few
#: micrometres (ISO 76: a permanent 1e-4 of the rolling element's diameter), a small part
#: of a touchdown clearance of tenths of a millimetre; half the clearance is far past
#: that, where the journal digs into the ring. A setting, not a standard's number.
PENETRATION_RATIO = 0.5


class DropLimits(_Strict):
    """The rotor drop's pass criteria that no public text fixes, as settings
    (:func:`ambseal.analysis.drop.drop_verdict`): the largest ``force_ratio`` of a
    touchdown bearing's peak force to its ``static_rating`` C₀ (default 1: C₀ is the load
    ISO 76 lets a rolling bearing carry at rest without harmful permanent deformation);
    the largest ``race_temperature_rise`` (K) of a ring with a ``race_mass`` (no default:
    the ring's steel and its ambient decide it; not graded without it); the
    ``penetration_ratio``, the deepest penetration of a ring over its clearance within
    which the contact law is taken to hold (default :data:`PENETRATION_RATIO`, 0.5;
    beyond it the verdict says the drop left its model's range); and the
    ``axial_thrust`` (N) the thrust bearing carries until the AMBs let go (default 0)."""

    force_ratio: float = Field(default=1.0, gt=0, le=100.0)
    # the residual thrust (N, +z towards the rotor's far end) the thrust bearing carries
    # at the drop: on the rotor when it lets go
    axial_thrust: float = Field(default=0.0, ge=-1e8, le=1e8)
    # the largest temperature rise (K) of a touchdown ring from the drop's friction heat
    race_temperature_rise: float | None = Field(default=None, gt=0, le=1e4)
    # the deepest penetration, over the ring's clearance, within which the elastic contact
    # law is taken to hold (PENETRATION_RATIO)
    penetration_ratio: float = Field(default=PENETRATION_RATIO, gt=0, le=10.0)


class Signoff(_Strict):
    """The sign-off's limits that the standards' public text does not confirm, as
    settings with documented defaults (:mod:`ambseal.analysis.signoff`): API 617's CSR
    Region A/B boundary ``csr_boundary`` (points ``[ρ_avg kg/m³, CSR]``, linear between,
    flat beyond), the least log decrement ``log_dec_min`` (Level I's δ_A and Level II),
    the unbalance ``unbalance_factor`` × U_r, the analysed speeds up to
    ``analysis_top_ratio`` × the trip speed, the vibration limit's cap
    ``vibration_limit_cap_um`` (µm p-p), the scale factor's ``scale_factor_limits`` and
    ``scale_factor_speeds`` (``"to_trip"`` or ``"continuous"``), the journal static
    load W of a machine that does not lie horizontal ``journal_load``
    (``"as_horizontal"`` or ``"as_acting"``), the
    close clearances' allowed ``clearance_fraction``, and ISO 14839-2's zone boundaries
    ``iso14839_2_zones`` (fractions of the backup bearing's clearance C_min); and the
    unbalance response's ``probes`` (``[{ position, angle_deg }]``, directional; left out,
    the orbit at the AMB sensors or the springs); and where Level I applies its
    cross-coupling, ``level1_position_m`` (left out, API 617's place)."""

    csr_boundary: list[Annotated[list[float], Field(min_length=2, max_length=2)]] = Field(
        default=[[16.53, 2.5], [60.0, 2.0]], min_length=1, max_length=100)
    log_dec_min: float = Field(default=0.1, gt=0, le=10.0)
    unbalance_factor: float = Field(default=2.0, gt=0, le=100.0)
    analysis_top_ratio: float = Field(default=1.25, ge=1.0, le=5.0)
    vibration_limit_cap_um: float = Field(default=25.4, gt=0, le=1e4)
    scale_factor_limits: tuple[float, float] = Field(default=(0.5, 6.0), strict=False)
    # the speeds over which A_1 of S_c = A_vl/A_1 is taken (API 617 8th ed. Part 1
    # §4.8.2.11 as read: standstill to trip; ROSS 3.1: minimum to maximum continuous)
    scale_factor_speeds: Literal["to_trip", "continuous"] = "to_trip"
    # API 617's journal static load W on a machine that does not lie horizontal: its
    # weight apportioned to the bearings as if it did (API 684 2nd ed.'s reading for
    # vertical machines; the public text could not confirm it), or gravity's lateral part
    journal_load: Literal["as_horizontal", "as_acting"] = "as_horizontal"
    clearance_fraction: float = Field(default=0.75, gt=0, le=1.0)
    iso14839_2_zones: tuple[float, float, float] = Field(default=(0.3, 0.4, 0.5),
                                                         strict=False)
    # the API 617 unbalance response's probes: directional, at any node; left out, the
    # orbit's semi-major axis at the AMB sensors (the springs of a rig without AMBs)
    probes: list[Probe] | None = Field(default=None, min_length=1, max_length=100)
    # where Level I applies the whole cross-coupling Q (m); left out, mid-span between
    # the outermost bearings, or the overhung stages (API 617); ROSS's run_level1 takes
    # the node nearest mid-span
    level1_position_m: float | None = Field(default=None, ge=0, le=1e3)

    @model_validator(mode="after")
    def _ordered(self) -> "Signoff":
        rho = [r for r, _ in self.csr_boundary]
        if any(b <= a for a, b in zip(rho, rho[1:])) or any(
                not (0 <= r <= 2000 and 0 < c <= 100) for r, c in self.csr_boundary):
            raise ValueError("csr_boundary: expected [density kg/m³, CSR] points with "
                             "densities increasing within 0–2000 and CSR within (0, 100]")
        lo, hi = self.scale_factor_limits
        if not 0 <= lo <= hi <= 100 or hi == 0:
            raise ValueError("scale_factor_limits: expected [low, high] with 0 <= low <= "
                             "high <= 100, high > 0 (low 0: no lower bound)")
        z = self.iso14839_2_zones
        if not 0 < z[0] < z[1] < z[2] <= 1:
            raise ValueError("iso14839_2_zones: expected A/B < B/C < C/D within (0, 1] "
                             "(fractions of the backup clearance)")
        return self


class Pid(_Strict):
    kp: float = Field(gt=0, le=1e9)
    ti: float = Field(gt=0, le=1e4)
    td: float = Field(ge=0, le=100.0)
    eps: float = Field(gt=0, le=1e3)
    # cross-axis gains between the two axes of one bearing: either sign (the sense of
    # whirl they act on), bounded as kp and kp·td are
    cross_kp: float = Field(default=0.0, ge=-1e9, le=1e9)
    cross_kd: float = Field(default=0.0, ge=-1e11, le=1e11)
    # the speed the cross gains are given at: with it they scale with the speed, as the
    # gyroscopic moments do; without it they are constant
    cross_speed_rpm: float | None = Field(default=None, gt=0, le=MAX_SPEED_RPM)

    @model_validator(mode="after")
    def _cross(self) -> "Pid":
        if self.cross_kd != 0 and self.td == 0:
            raise ValueError("cross_kd: a cross-axis derivative takes the derivative's "
                             "filter, and td = 0 has none; set td > 0 or cross_kd = 0")
        if self.cross_speed_rpm is not None and not (self.cross_kp or self.cross_kd):
            raise ValueError("cross_speed_rpm: schedules the cross-axis gains on speed, and "
                             "cross_kp = cross_kd = 0; set a cross gain or leave it out")
        return self


class PidFilter(_Strict):
    """A filter in series with the reference PID on every axis (the commissioning
    engineer's gain or phase stabilisation of a flexible mode, Schweitzer & Maslen 2009
    on flexible rotors; :func:`ambseal.design.pid.pid_controller`): ``kind`` = ``"notch"``
    (``frequency_hz``, ``width_hz`` between the −3 dB points of a deep notch,
    ``depth_db``), ``"lead"`` or ``"lag"`` (``phase_deg``, the phase added, or taken, at
    ``frequency_hz``, unity gain at zero frequency) or ``"lowpass"`` (second order,
    ``frequency_hz``, ``damping``)."""

    kind: Literal["notch", "lead", "lag", "lowpass"]
    frequency_hz: float = Field(gt=0, le=MAX_FREQUENCY_HZ)
    width_hz: float | None = Field(default=None, gt=0, le=MAX_FREQUENCY_HZ)
    # a notch deeper than 60 dB removes the mode's frequency outright; a phase filter of
    # 80° or more has corner frequencies more than 130× apart
    depth_db: float = Field(default=20.0, gt=0, le=60.0)
    phase_deg: float | None = Field(default=None, gt=0, lt=80.0)
    damping: float = Field(default=0.7, gt=0, le=10.0)

    @model_validator(mode="after")
    def _keys(self) -> "PidFilter":
        need, may = {"notch": (("width_hz",), ("depth_db",)),
                     "lead": (("phase_deg",), ()), "lag": (("phase_deg",), ()),
                     "lowpass": ((), ("damping",))}[self.kind]
        for key in need:
            if getattr(self, key) is None:
                raise ValueError(f"a {self.kind} filter needs {key}")
        # a default written back by dump_rig is no key of the user's
        other = sorted(k for k in self.model_fields_set - {"kind", "frequency_hz", *need, *may}
                       if getattr(self, k) != type(self).model_fields[k].default)
        if other:
            raise ValueError(f"{other[0]}: not a key of a {self.kind} filter (expected "
                             f"{', '.join(('frequency_hz', *need, *may))})")
        if self.kind == "notch" and self.width_hz >= 2 * self.frequency_hz:
            raise ValueError("width_hz: expected less than twice frequency_hz (a notch, "
                             "not a band-stop over every frequency below it)")
        return self


class Controllers(_Strict):
    pid: Pid | None = None
    # None: a PID derived from the rig gets the filters derived with it, a given one none
    filter: list[PidFilter] | None = Field(default=None, max_length=MAX_PID_FILTERS)
    # plausible digital AMB controllers: 100 Hz to 1 MHz
    sample_rate_hz: float = Field(default=10000.0, ge=100.0, le=1e6)
    delay_samples: int = Field(default=1, ge=0, le=MAX_DELAY_SAMPLES)


#: The trip speed over the maximum continuous speed when ``trip_speed_hz`` is left out:
#: API 617's value for a variable-speed motor or gas-turbine drive (105 %), the lowest
#: of a turbine-driven machine's; not confirmed from the standard's public text.
TRIP_RATIO = 1.05


class Operating(_Strict):
    # one bound for every speed, in rpm or Hz (MAX_SPEED_HZ)
    speed_rpm: float = Field(default=0.0, ge=-MAX_SPEED_RPM, le=MAX_SPEED_RPM)
    pressure_bar: float = Field(default=0.0, ge=0, le=MAX_PRESSURE_BAR)
    speed_range_hz: tuple[float, float] | None = Field(default=None, strict=False)  # a list
    trip_speed_hz: float | None = Field(default=None, gt=0, le=MAX_SPEED_HZ)

    @property
    def continuous_hz(self) -> tuple[float, float]:
        """(minimum, maximum) continuous speed (Hz): ``speed_range_hz``, else the operating
        speed for both."""
        r = self.speed_range_hz
        f = abs(self.speed_rpm) / 60.0
        return (float(r[0]), float(r[1])) if r is not None else (f, f)

    @property
    def trip_hz(self) -> float:
        """The trip speed (Hz): ``trip_speed_hz``, else :data:`TRIP_RATIO` × the maximum
        continuous speed."""
        return (self.trip_speed_hz if self.trip_speed_hz is not None
                else TRIP_RATIO * self.continuous_hz[1])

    @model_validator(mode="after")
    def _range(self) -> "Operating":
        r = self.speed_range_hz
        if self.trip_speed_hz is not None and self.trip_speed_hz < self.continuous_hz[1]:
            raise ValueError(f"trip_speed_hz: {self.trip_speed_hz:g} Hz lies below the "
                             f"maximum continuous speed {self.continuous_hz[1]:g} Hz")
        if r is not None and not 0 < r[0] < r[1] <= MAX_SPEED_HZ:
            raise ValueError(f"speed_range_hz: expected [low, high] with 0 < low < high "
                             f"<= {MAX_SPEED_HZ:g} Hz ({MAX_SPEED_RPM:g} rpm, the bound of "
                             "speed_rpm)")
        if r is not None and not r[0] <= abs(self.speed_rpm) / 60 <= r[1]:
            # every digit: 11 000 rpm is 183.3333… Hz, outside a range written to 183.333
            raise ValueError(f"speed_rpm: {self.speed_rpm:.12g} rpm = "
                             f"{abs(self.speed_rpm) / 60:.12g} Hz lies outside speed_range_hz "
                             f"[{r[0]:.12g}, {r[1]:.12g}]: a controller scheduled over that "
                             "range would be extrapolated")
        return self


class Reduction(_Strict):
    states: int | None = Field(default=None, ge=1, le=MAX_REDUCED_STATES)
    cutoff_hz: float | None = Field(default=None, gt=0, le=1e7)

    @model_validator(mode="after")
    def _one(self) -> "Reduction":
        if self.states is not None and self.cutoff_hz is not None:
            raise ValueError("expected states or cutoff_hz, not both")
        return self


class RigConfig(_Strict):
    """A whole rig: rotor, materials, shaft, components, controller and operating point."""

    rotor: Rotor = Rotor()
    materials: dict[Name, Material]
    shaft: list[ShaftSection] = Field(min_length=1, max_length=MAX_COMPONENTS)
    disk: list[Disk] = Field(default=[], max_length=MAX_COMPONENTS)
    amb: list[Amb] = Field(default=[], max_length=MAX_AMBS)
    actuator: Actuator = Actuator()
    seal: list[Seal] = Field(default=[], max_length=MAX_COMPONENTS)
    spring: list[Spring] = Field(default=[], max_length=MAX_COMPONENTS)
    stage: list[Stage] = Field(default=[], max_length=MAX_COMPONENTS)
    touchdown: list[Touchdown] = Field(default=[], max_length=MAX_COMPONENTS)
    machine: Machine = Machine()
    signoff: Signoff = Signoff()
    drop: DropLimits = DropLimits()
    controller: Controllers = Controllers()
    operating: Operating = Operating()
    reduction: Reduction = Reduction()
    design: Design = Design()

    @property
    def length(self) -> float:
        """Shaft length (m)."""
        return sum(s.length for s in self.shaft)

    @property
    def speed(self) -> float:
        """Rotational speed Ω (rad/s)."""
        return self.operating.speed_rpm * 2.0 * math.pi / 60.0

    def digest(self) -> bytes:
        """SHA-256 of the validated rig's JSON form (32 bytes): the key under which what
        the rig alone determines (its plants, their responses, its scheduled designs) is
        kept; two rigs that validate to the same values share it, whatever their files'
        layout."""
        return hashlib.sha256(self.model_dump_json().encode()).digest()

    def backup_clearance(self, amb: Amb) -> float | None:
        """The radial clearance (m) of the backup bearing beside an AMB: on a rig with
        ``[[touchdown]]`` bearings, the ``radial_clearance`` of the one nearest the AMB
        along the shaft (the first of two equally near); else the AMB's own
        ``backup_clearance``, None where neither is given. A rig gives the gap in one of
        the two places (:func:`~ambseal.config.parse_rig` refuses both)."""
        if self.touchdown:
            return min(self.touchdown, key=lambda t: abs(t.position - amb.position)
                       ).radial_clearance
        return amb.backup_clearance


def _union_tags() -> set[str]:
    """The branch names pydantic puts into an error's location: our model classes and the
    primitive types of the unions."""
    tags, todo = set(PRIMITIVE_TAGS), [_Strict]
    while todo:
        cls = todo.pop()
        tags.add(cls.__name__)
        todo += cls.__subclasses__()
    return tags


def _describe(exc: ValidationError) -> str:
    return describe_validation_error(exc, _union_tags())


def parse_rig(data: dict, where: str = "<rig>") -> RigConfig:
    """Validate a rig given as a dict (as read from TOML).

    Parameters
    ----------
    data : dict
        The parsed TOML document.
    where : str
        Name of the source used in error messages (usually the file path).

    Returns
    -------
    RigConfig
        The validated, frozen configuration.

    Raises
    ------
    ConfigError
        One line naming ``where``, the key path and what was expected.
    """
    try:
        cfg = RigConfig.model_validate(data)
    except ValidationError as exc:
        raise ConfigError(f"{where}: {_describe(exc)}") from None
    cross_check(cfg, where)
    bad = check_design_names(cfg)
    if bad:
        raise ConfigError(f"{where}: {bad}")
    return cfg


def check_operating(values: dict, arg_names: dict[str, str]) -> None:
    """Validate command-line operating values by the rig file's own rules (``[operating]``).

    Parameters
    ----------
    values : dict
        ``{key: value}`` of :class:`Operating` keys (``pressure_bar``, ``speed_rpm``); None
        values are skipped.
    arg_names : dict
        The command-line argument of each key, named in the error.

    Raises
    ------
    ConfigError
        ``--pressure-bar: ...`` with what the rig format expects.
    """
    for key, value in values.items():
        if value is None:
            continue
        try:
            Operating.model_validate({key: value})
        except ValidationError as exc:
            msg = _describe(exc).split(": ", 1)[1]
            raise ConfigError(f"{arg_names.get(key, key)}: {msg} (the rule of [operating] "
                              f"{key} in a rig file)") from None


def check_below_trip(operating: Operating, speed_rpm: float, arg_name: str) -> None:
    """Refuse a speed above the rig's trip speed (:attr:`Operating.trip_hz`): the machine
    trips before it, so nothing run there (a drop) describes it. A rig that states no
    speed at all (``speed_rpm`` 0, no ``speed_range_hz``, no ``trip_speed_hz``) has no
    trip speed and bounds nothing.

    Parameters
    ----------
    operating : Operating
        The rig's ``[operating]`` table.
    speed_rpm : float
        The speed asked for (rpm; its sign the sense of rotation).
    arg_name : str
        What the user wrote, named in the error (``"--speed-hz 2000"``).

    Raises
    ------
    ConfigError
        ``<arg_name>: ... above the rig's trip speed ...``.
    """
    trip = operating.trip_hz
    f = abs(speed_rpm) / 60.0
    if trip > 0 and f > trip * (1.0 + 1e-12):
        given = ("[operating] trip_speed_hz" if operating.trip_speed_hz is not None else
                 f"{TRIP_RATIO:g} × the maximum continuous speed, no trip_speed_hz given")
        raise ConfigError(f"{arg_name}: {f:.6g} Hz lies above the rig's trip speed "
                          f"{trip:.6g} Hz = {60.0 * trip:.6g} rpm ({given}); the machine "
                          "trips before it: give a speed up to the trip speed (--at trip), "
                          "or the rig's trip_speed_hz")


def drop_limits_with(drop: DropLimits, key: str, value, arg_name: str) -> DropLimits:
    """``[drop]`` with one key set from the command line, by the rig file's own rule.

    Parameters
    ----------
    drop : DropLimits
        The rig's ``[drop]`` table.
    key : str
        A key of it (``"penetration_ratio"``).
    value : object
        Its value.
    arg_name : str
        The command-line option, named in the error.

    Returns
    -------
    DropLimits

    Raises
    ------
    ConfigError
        ``<arg_name>: ...`` with what the rig format expects.
    """
    try:
        return DropLimits.model_validate({**drop.model_dump(), key: value})
    except ValidationError as exc:
        msg = _describe(exc).split(": ", 1)[1]
        raise ConfigError(f"{arg_name}: {msg} (the rule of [drop] {key} in a rig file)"
                          ) from None


def load_rig(path: str | Path | None = None, overrides=()) -> RigConfig:
    """Read and validate a rig file (TOML).

    Parameters
    ----------
    path : str or Path, optional
        The rig file; the embedded thesis test facility when omitted.
    overrides : iterable of str
        ``design.<key>=<value>`` settings (:func:`apply_overrides`), validated with the file.

    Returns
    -------
    RigConfig
        The validated, frozen configuration.

    Raises
    ------
    ConfigError
        The file is missing, is not valid TOML, does not match the rig format, or an
        override is malformed or invalid (named with the file).
    """
    p = Path(path) if path is not None else default_rig_path()
    data = _load_toml(p, "rig file")
    design = data.get("design")
    fit = design.get("uncertainty_from_identification") if isinstance(design, dict) else None
    if isinstance(fit, str) and fit and not Path(fit).is_absolute():
        design["uncertainty_from_identification"] = str(p.parent / fit)  # beside the rig
    if overrides:
        return parse_rig(apply_overrides(data, overrides), f"{p} (with --set)")
    return parse_rig(data, str(p))


def _load_toml(path: Path, what: str) -> dict:
    """TOML of a rig or truth file; ConfigError naming the file when it cannot be read, is
    not UTF-8 text (a byte-order mark is accepted), not TOML or nested too deeply."""

    try:
        return load_toml(path, what)
    except AmbsealError as exc:
        raise ConfigError(str(exc)) from None


def default_rig_path() -> Path:
    """Path of the embedded thesis test facility (``ambseal/data/testrig.toml``).

    Returns
    -------
    pathlib.Path
        The file inside the installed package.
    """
    return Path(__file__).resolve().parents[1] / "data" / "testrig.toml"


class TruthSection(_Strict):
    """The virtual test facility's true values, in a file of their own that a fit never reads.

    ``parameters`` maps model parameter names (``A.Ki_zeta``, ``A.Ks_zeta``,
    ``coupling.kxx``, ``seal.k``, ...) to a number or ``{ at_zero, per_bar }`` (values at a
    pressure drop: :func:`ambseal.model.seal.coefficient_value`).
    """

    parameters: dict[str, Coefficient] = {}
    tau_e: float = Field(default=0.0, ge=0, le=1.0)
    bias_current: float | None = Field(default=None, ge=MIN_CURRENT_A, le=MAX_CURRENT_A)
    current_limit: float | None = Field(default=None, ge=MIN_CURRENT_A, le=MAX_CURRENT_A)
    sensor_noise_m: float = Field(default=0.0, ge=0, le=MAX_GAP_M)
    noise_fraction: float = Field(default=0.0, ge=0, le=MAX_RELATIVE)
    current_noise_a: float = Field(default=0.0, ge=0, le=MAX_CURRENT_A)
    adc_bits: int | None = Field(default=None, ge=2, le=32)
    adc_range_m: float = Field(default=1.0e-3, gt=0, le=MAX_GAP_M)  # LSB = range / 2**bits
    substeps: int = Field(default=4, ge=1, le=100)
    max_mode_hz: float = Field(default=10000.0, gt=0, le=MAX_FREQUENCY_HZ)
    # model-form mismatch of the facility against the rig file (None/1: as the rig file)
    beam: Literal["timoshenko", "euler-bernoulli"] | None = None
    mesh_factor: float = Field(default=1.0, gt=0, le=MAX_ELEMENTS)  # in all: rig_sim.true_rig
    modal_damping: float | None = Field(default=None, ge=0, lt=1)
    sensor_filter_hz: float | None = Field(default=None, gt=0, le=MAX_FREQUENCY_HZ)

    @field_validator("tau_e")
    @classmethod
    def _lag(cls, v: float) -> float:
        if 0 < v < MIN_TIME_CONSTANT_S:
            raise ValueError(f"expected 0 (no lag) or at least {MIN_TIME_CONSTANT_S:g} s")
        return v


class TruthConfig(_Strict):
    truth: TruthSection


def load_truth(path: str | Path) -> TruthSection:
    """Read a truth file (TOML with a ``[truth]`` table); ConfigError on any fault.

    Keys of ``[truth]``: ``tau_e`` (s), ``bias_current`` (A, default the rig's:
    :func:`ambseal.model.amb.bias_current`), ``current_limit`` (A, default the AMBs'
    ``current_limit``), ``sensor_noise_m`` (std, m) or ``noise_fraction`` (std as
    a fraction of each displacement channel's RMS), ``current_noise_a`` (std, A),
    ``adc_bits`` and ``adc_range_m`` (quantisation step range/2^bits; the sensor does not
    saturate: the rotor stops the run if it leaves the gap), ``substeps`` (integration steps
    per controller sample), ``max_mode_hz`` (modes kept in the simulation, default 10 kHz),
    and ``[truth.parameters]``. Model-form differences from the rig file (to test a fit on
    data its model did not make): ``beam`` (``"timoshenko"`` or ``"euler-bernoulli"``),
    ``mesh_factor`` (shaft elements per section × this, rounded, at least 1),
    ``modal_damping`` (the rotor's, in place of the rig file's) and ``sensor_filter_hz`` (a
    first-order low-pass in every displacement sensor, which the model does not have).

    Parameters
    ----------
    path : str or Path
        The truth file.

    Returns
    -------
    TruthSection
        The validated ``[truth]`` table.

    Raises
    ------
    ConfigError
        The file cannot be read, is not TOML or does not match the format (named).
    """
    p = Path(path)
    data = _load_toml(p, "truth file")
    try:
        return TruthConfig.model_validate(data).truth
    except ValidationError as exc:
        raise ConfigError(f"{p}: {_describe(exc)}") from None


def rig_parameter_names(cfg: RigConfig) -> tuple[str, ...]:
    """The names :func:`rig_with_values` accepts for this rig, in the rig file's order.

    Parameters
    ----------
    cfg : RigConfig
        The rig.

    Returns
    -------
    tuple of str
        ``{amb}.Ki_zeta``, ``{amb}.Ki_eta``, ``{amb}.Ks_zeta``, ``{amb}.Ks_eta`` per AMB,
        ``{spring}.kxx`` … ``{spring}.cyy`` per spring, ``{seal}.K``, ``.k``, ``.C``, ``.c``
        per seal, and ``tau_e``.
    """
    names = [f"{a.name}.{k}_{ax}" for a in cfg.amb for k in ("Ki", "Ks")
             for ax in ("zeta", "eta")]
    names += [f"{s.name or f'spring{i}'}.{k}" for i, s in enumerate(cfg.spring)
              for k in _SPRING_KEYS]
    names += [f"{s.name}.{k}" for s in cfg.seal for k in _SEAL_KEYS]
    return (*names, "tau_e")


_SPRING_KEYS = ("kxx", "kyy", "kxy", "kyx", "cxx", "cyy")
_SEAL_KEYS = ("K", "k", "C", "c")


def rig_with_values(cfg: RigConfig, values: dict[str, Coefficient]) -> RigConfig:
    """The rig with named model parameters set (SI), e.g. identified values.

    Names are those of the model's LFT channels — ``{amb}.Ki_{zeta|eta}``,
    ``{amb}.Ks_{zeta|eta}``, ``{spring}.{kxx|kyy|kxy|kyx|cxx|cyy}`` (a spring without a
    ``name`` is ``spring{i}``), ``{seal}.{K|k|C|c}`` (a number or an :class:`Affine` in the
    pressure drop) — and ``tau_e`` (the actuator's eddy-current lag).

    Parameters
    ----------
    cfg : RigConfig
        The rig.
    values : dict
        ``{name: value}``, SI (a seal coefficient may be an :class:`Affine`).

    Returns
    -------
    RigConfig
        A new, validated configuration; ``cfg`` is unchanged.

    Raises
    ------
    ConfigError
        An unknown parameter name, or a value the rig format does not accept.
    """
    data = cfg.model_dump(exclude_none=True)
    ambs = {a["name"]: a for a in data.get("amb", [])}
    springs = {(s.get("name") or f"spring{i}"): s for i, s in enumerate(data.get("spring", []))}
    seals = {s["name"]: s for s in data.get("seal", [])}
    for name, v in values.items():
        v = v.model_dump() if isinstance(v, Affine) else float(v)
        owner, _, key = name.rpartition(".")
        if name == "tau_e":
            data.setdefault("actuator", {})["eddy_time_constant"] = v
        elif owner in ambs and key[:3] in ("Ki_", "Ks_") and key[3:] in ("zeta", "eta"):
            # per axis; an AMB given by its geometry keeps the geometry's other factors
            amb, slot = ambs[owner], key[:2].lower()
            if not isinstance(amb.get(slot), dict):
                old = amb.get(slot)
                amb[slot] = {} if old is None else {"zeta": old, "eta": old}
            amb[slot][key[3:]] = v
        elif owner in springs and key in _SPRING_KEYS:
            springs[owner][key] = v
        elif owner in seals and key in _SEAL_KEYS:
            seals[owner][key] = v
        else:
            raise ConfigError(f"rig parameters: unknown parameter {name!r} (expected one of "
                              f"{', '.join(rig_parameter_names(cfg))})")
    return parse_rig(data, "<identified rig>")


def toml_string(text: str) -> str:
    """``text`` as a TOML basic string: quoted, its backslashes, quotes and control
    characters escaped (TOML 1.0, §String).

    Parameters
    ----------
    text : str
        Any text (a name from the rig file).

    Returns
    -------
    str
        E.g. ``'"Impeller \\"A\\" C:\\\\stage"'`` for ``Impeller "A" C:\\stage``.
    """
    out = []
    for ch in text:
        if ch in ('"', "\\"):
            out.append("\\" + ch)
        elif ord(ch) < 0x20 or ord(ch) == 0x7F:
            out.append(f"\\u{ord(ch):04X}")
        else:
            out.append(ch)
    return '"' + "".join(out) + '"'


def _toml_value(v) -> str:
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, (int, float)):
        return repr(v) if isinstance(v, int) or math.isfinite(v) else "nan"
    if isinstance(v, str):
        return toml_string(v)
    if isinstance(v, dict):
        return "{ " + ", ".join(f"{k} = {_toml_value(x)}" for k, x in v.items()) + " }"
    if isinstance(v, (list, tuple)):
        return "[" + ", ".join(_toml_value(x) for x in v) + "]"
    raise TypeError(f"cannot write {type(v).__name__} to TOML")


def _toml_table(name: str, val: dict, lines: list[str]) -> None:
    """``[name]`` with its scalar keys, then its sub-tables and arrays of tables."""
    def is_tables(x) -> bool:
        return isinstance(x, list) and bool(x) and all(isinstance(i, dict) for i in x)

    plain = {k: x for k, x in val.items() if not (isinstance(x, dict) or is_tables(x))}
    if plain:
        lines += ["", f"[{name}]"] + [f"{k} = {_toml_value(x)}" for k, x in plain.items()]
    for k, x in val.items():
        if isinstance(x, dict) and x:
            _toml_table(f"{name}.{k}", x, lines)
        elif is_tables(x):
            for item in x:
                lines += ["", f"[[{name}.{k}]]"]
                lines += [f"{j} = {_toml_value(y)}" for j, y in item.items()]


#: The options of a shaft tube (section or layer) and their defaults, which
#: :func:`dump_rig` leaves out (the right end's diameters: None, left out as any None).
_TUBE_DEFAULTS = {"rotary_inertia": True, "gyroscopic": True, "axial_force": 0.0,
                  "torque": 0.0, "rayleigh_alpha": 0.0, "rayleigh_beta": 0.0}


def dump_rig(cfg: RigConfig, header: str = "") -> str:
    """The rig as TOML text that :func:`load_rig` reads back to the same configuration.

    Parameters
    ----------
    cfg : RigConfig
        The rig.
    header : str
        Text written first as ``#`` comment lines (none if empty).

    Returns
    -------
    str
        The TOML document, ending with a newline.
    """
    data = cfg.model_dump(exclude_none=True)
    # the per-tube options at their defaults are left out: most rigs use none of them
    for sec in data.get("shaft", []):
        for tube in (sec, *sec.get("layers", [])):
            for k, default in _TUBE_DEFAULTS.items():
                if k in tube and tube[k] == default:
                    del tube[k]
    lines = [f"# {line}" for line in header.splitlines()]
    for key, val in data.items():
        if isinstance(val, list):
            for item in val:
                lines += ["", f"[[{key}]]"]
                # an empty list is its key's default (a section's layers)
                lines += [f"{k} = {_toml_value(x)}" for k, x in item.items() if x != []]
        else:
            _toml_table(key, val, lines)
    return "\n".join(lines).lstrip("\n") + "\n"
