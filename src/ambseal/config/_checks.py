"""Rules of the rig file that need more than one key: force factors, actuator model, and the
whole rig (materials, positions, names, model size). Called by the validators of
:mod:`ambseal.config`, which owns the format; duck-typed on its classes.
"""

from __future__ import annotations

from typing import Annotated

from pydantic import Field

from ambseal.errors import LABEL_PATTERN, NAME_PATTERN, ConfigError
# the bound of the target's delay, where the robust layer checks it (a light module)
from ambseal.robust import MAX_DELAY_SAMPLES

__all__ = ["MIN_CURRENT_A", "MIN_TIME_CONSTANT_S", "MAX_ELEMENTS", "MAX_COMPONENTS", "MAX_AMBS", "MAX_LAYERS", "MAX_REDUCED_STATES", "MAX_COEFFICIENT",
           "MAX_FREQUENCY_HZ", "MAX_SPEED_HZ", "MAX_SPEED_RPM", "MAX_PRESSURE_BAR", "MAX_CURRENT_A", "MAX_GAP_M",
           "MAX_DELAY_SAMPLES", "MAX_PID_FILTERS", "MAX_RELATIVE", "BoundedCoefficient",
           "BoundedFrequency", "check_amb", "check_actuator", "cross_check", "Name", "Label",
           "MIN_FRICTION_VELOCITY", "node_tolerance"]

#: Names of AMBs, seals, springs and materials make parameter, signal and C names
#: (``A.Ki_zeta``, ``y_A_zeta``; :data:`ambseal.errors.NAME_PATTERN`), checked once here.
Name = Annotated[str, Field(min_length=1, max_length=64, pattern=NAME_PATTERN)]
#: Labels (the rotor's, a disk's) are free text for reports, on one line.
Label = Annotated[str, Field(min_length=1, max_length=200, pattern=LABEL_PATTERN)]

#: Beam elements in the whole shaft, the most a rig may ask for. What a fine mesh costs: 8
#: states per node, and judging a controller closes loops on every state, each loop's
#: stability by a dense eigenvalue problem (~2.5e-10 s·states³ on one core: ~9 s at 400
#: elements, 3 240 states; memory 8·states² bytes per matrix, 84 MB). Everything that needs
#: only the lowest modes — the design model (a modal reduction of the FE model, P3/P5), the
#: spec's mode counts, the shapes ``ambseal modes`` lists — takes them by shift-invert
#: Arnoldi instead (``ambseal.lti.lowest``, ``ambseal.model.modes.poles_near_zero``):
#: measured at 400 elements ``ambseal modes`` 20 s and a μ design 51 s of CPU, at 230
#: elements 4.6 s and 14 s. 400 elements (L/400 per element) resolve a long rotor's modes
#: of interest and a mesh-convergence check of a shorter one.
MAX_ELEMENTS = 400
#: Shaft sections, disks, seals and springs of a rig, at most of each: every one puts a node
#: (a section at least one element) into the mesh, whose elements in all are bounded by
#: ``MAX_ELEMENTS`` (``ambseal.model.rotor.build_mesh`` checks the mesh they make).
MAX_COMPONENTS = MAX_ELEMENTS
#: Magnetic bearings of a rig, at most: each adds two channels to every controller
#: synthesis and judged loop (H∞ and μ grow with the cube of the channels); machines carry
#: two to five radial AMBs.
MAX_AMBS = 16
#: Concentric layers on one shaft section, at most (a shaft, a sleeve and a hub is three;
#: more only splits one tube into rings).
MAX_LAYERS = 8
#: States of a reduced model for control design, at most (H∞/μ synthesis grows with n³ and
#: beyond ~100 states is numerically fragile).
MAX_REDUCED_STATES = 200

# Bounds of physical values that several tables share. None describes a machine: each is
# far beyond any rotor on AMBs and exists so that a typo (1e300, a unit off by 10⁹) is
# refused naming its key instead of overflowing in the model.
#: A force coefficient (N/m, N·s/m, kg, N/A), in every form (number, affine, table): a
#: bearing or seal stiffer than 1e12 N/m would be a rigid support, not a coefficient.
MAX_COEFFICIENT = 1e12
#: A frequency (Hz): ten times the fastest controller sample rate the rig file accepts
#: (``[controller] sample_rate_hz`` ≤ 1 MHz), so any band a controller acts in fits.
MAX_FREQUENCY_HZ = 1e7
#: A rotational speed (Hz), either sense: the one bound of every speed a rig file or a
#: command line gives (``[operating] speed_rpm``, ``speed_range_hz``, ``trip_speed_hz``,
#: the ``[design]`` speeds; ``--speed-rpm``, ``--speed-hz``). 20 kHz is 1.2e6 rpm, beyond
#: the fastest rotors on AMBs (about 1e6 rpm).
MAX_SPEED_HZ = 2e4
#: :data:`MAX_SPEED_HZ` in rpm, the bound of a speed given in rpm.
MAX_SPEED_RPM = 60.0 * MAX_SPEED_HZ
#: A pressure drop (bar): the bound of ``[operating] pressure_bar`` (1 GPa).
MAX_PRESSURE_BAR = 1e4
#: A current (A): the bound of an AMB's ``bias_current`` and ``current_limit``.
MAX_CURRENT_A = 1e4
#: The least bias current or current limit (A): the smallest AMBs run on tens of mA; below
#: a microampere the force law's gains (∝ 1/i0) overflow the facility's arithmetic.
MIN_CURRENT_A = 1e-6
#: The least non-zero time constant of the facility's lag (s): far below one sample of
#: any controller, and above what makes its rate (1/τ) overflow.
MIN_TIME_CONSTANT_S = 1e-9
#: A displacement inside a bearing (m): the bound of an AMB's ``air_gap``.
MAX_GAP_M = 0.1
#: filters in series with the PID: one or two per flexible mode within its reach
MAX_PID_FILTERS = 16
#: A relative uncertainty (1σ or ± range as a fraction of the value): beyond 10× the value
#: the range says nothing about it.
MAX_RELATIVE = 10.0
#: A support's stiffness (N/m), the bound of a ``[[spring]]``'s kxx, kyy, kxy, kyx: a pin. A
#: node on two springs of 1e17 N/m has the natural frequencies of the pinned shaft to 1e-8
#: (ROSS's conical test rotor), and the eigenvalues stay well conditioned.
MAX_SUPPORT_STIFFNESS = 1e17
#: Rayleigh damping C = α·M + β·K of a shaft tube or the rotor: a mode of ω rad/s gets
#: ζ = α/(2ω) + βω/2, so α = 1e4 1/s overdamps every mode below 800 Hz and β = 1 s every
#: mode above 0.3 Hz: far beyond structural damping (ζ ~ 1e-3 … 1e-2).
MAX_RAYLEIGH_ALPHA = 1e4
MAX_RAYLEIGH_BETA = 1.0
#: The least regularisation speed v_r (m/s) of a touchdown bearing's friction μN·tanh(v/v_r)
#: the drop can integrate. Where the journal sticks to a ring, the friction's slope μN/v_r
#: sets the stiff part of the drop, which its stiff integrator (LSODA) follows by a
#: Jacobian of finite differences, each a step of √ε ≈ 1.5e-8 of the speed it perturbs:
#: of a journal's surface speed, up to some hundred m/s (DN 3e6 mm·rpm, a rolling
#: bearing's limit, is 157 m/s), 1e-6 to 1e-5 m/s of slip, which must stay well below v_r
#: for the Jacobian to see the slope. Measured, a 0.1 s drop of examples/flywheel.toml
#: (173 m/s) rolling on its rings: v_r = 1e-3 m/s (the default) 8–23 s, 1e-4 11 s, 1e-5
#: 19 s, 1e-6 not done in eight minutes; the test rig's 20 ms drop at standstill fails at
#: 1e-10. 1e-4 m/s keeps ten times √ε of a 600 m/s surface, and loses nothing of Coulomb's
#: law: a slip below 0.1 mm/s moves the surfaces 0.1 mm in a second.
MIN_FRICTION_VELOCITY = 1e-4
#: A coefficient of a table against frequency, bounded like a number or the affine form.
BoundedCoefficient = Annotated[float, Field(ge=-MAX_COEFFICIENT, le=MAX_COEFFICIENT)]
#: A frequency of a table (Hz); negative for backward whirl excitation.
BoundedFrequency = Annotated[float, Field(ge=-MAX_FREQUENCY_HZ, le=MAX_FREQUENCY_HZ)]


def node_tolerance(length: float) -> float:
    """The distance within which two positions on a shaft share one node of its mesh.

    :func:`ambseal.model.build_mesh` puts a component this close to a node on it, and the
    rig file refuses two touchdown planes this close (one ring per node).

    Parameters
    ----------
    length : float
        The shaft's length (m).

    Returns
    -------
    float
        1e-6 of the length, at least 1e-6 m.
    """
    return 1e-6 * max(length, 1.0)


def check_amb(self):  # noqa: N805 (the Amb being validated)
    """An AMB's force factors: Ki > 0, Ks >= 0 (ambseal's sign convention), and either the
    whole geometry or both factors (ValueError; pydantic names the AMB)."""
    for key in ("ki", "ks"):
        v = getattr(self, key)
        for axis, x in ((("zeta", v.zeta), ("eta", v.eta)) if hasattr(v, "zeta")
                        else (("", v),)):
            if x is None:
                continue
            if key == "ki" and x <= 0:
                raise ValueError(f"ki{'.' + axis if axis else ''}: expected Ki > 0 (N/A), "
                                 f"got {x:g}")
            if key == "ks" and x < 0:
                raise ValueError(
                    f"ks{'.' + axis if axis else ''}: expected Ks >= 0 (N/m), got {x:g}: "
                    "ambseal's convention is f = Ki i + Ks x, Ks > 0 the destabilising "
                    "negative stiffness of a biased AMB (P2 Eq. 1); give its magnitude")
    geometry = {"turns": self.turns, "pole_area": self.pole_area,
                "air_gap": self.air_gap, "bias_current": self.bias_current}
    given = [k for k, v in geometry.items() if v is not None]
    if len(given) == len(geometry):
        return check_coil(self)
    if given and not (set(given) <= {"air_gap", "bias_current"}
                      and None not in (self.ki, self.ks)):
        # with ki and ks, air_gap and bias_current alone are read by the design defaults
        # (D_e, D_u, the impulse: ambseal.design.specs); other partial geometry is not
        missing = [k for k in geometry if k not in given]
        raise ValueError(f"partial geometry: {', '.join(given)} given without "
                         f"{', '.join(missing)} (give all four, or ki and ks alone)")
    if self.ki is None or self.ks is None:
        raise ValueError(
            "expected either the geometry (turns, pole_area, air_gap, bias_current) "
            "or both ki (N/A) and ks (N/m)"
        )
    for key in ("ki", "ks"):
        v = getattr(self, key)
        if hasattr(v, "zeta") and None in (v.zeta, v.eta):
            raise ValueError(f"{key}: expected both zeta and eta (or the geometry: "
                             "turns, pole_area, air_gap, bias_current)")
    return check_coil(self)


def check_coil(amb):
    """Check an AMB's amplifier supply against its coil (R i0 + |R + jωL| i_c ≤ V,
    :mod:`ambseal.model.capacity`; Schweitzer & Maslen 2009, ch. 3): a supply needs the
    coil's inductance or the geometry that gives it, and must drive the bias current
    through R. Checked when the rig file is read, so that no run ends on it after its
    designs.

    Parameters
    ----------
    amb : Amb
        One ``[[amb]]`` of the rig file (or a copy made without validation).

    Returns
    -------
    Amb
        ``amb``, unchanged.

    Raises
    ------
    ValueError
        ``supply_voltage`` without ``inductance`` or ``turns``, ``pole_area`` and
        ``air_gap``; or R·i0 ≥ ``supply_voltage``.
    """
    if amb.supply_voltage is None:
        return amb
    if amb.inductance is None and None in (amb.turns, amb.pole_area, amb.air_gap):
        raise ValueError("supply_voltage needs the coil's inductance (H) or the geometry "
                         "(turns, pole_area, air_gap) to derive it")
    drop = (amb.resistance or 0.0) * (amb.bias_current or 0.0)
    if amb.bias_current is not None and drop >= amb.supply_voltage:
        raise ValueError(f"supply_voltage = {amb.supply_voltage:g} V does not drive the bias "
                         f"current {amb.bias_current:g} A through R = {amb.resistance:g} Ω "
                         f"(R i0 = {drop:g} V)")
    return amb


def check_actuator(self):  # noqa: N805
    """The actuator model has the keys it needs and no key it would ignore."""
    if self.model == "first_order" and self.cutoff_hz is None:
        raise ValueError("model = 'first_order' expects cutoff_hz")
    if self.model == "second_order" and (
        self.natural_frequency is None or self.damping_ratio is None
    ):
        raise ValueError("model = 'second_order' expects natural_frequency and damping_ratio")
    unused = {"none": ("cutoff_hz", "natural_frequency", "damping_ratio"),
              "first_order": ("natural_frequency", "damping_ratio"),
              "second_order": ("cutoff_hz",)}[self.model]
    ignored = [k for k in unused if getattr(self, k) is not None]
    if ignored:
        raise ValueError(f"{', '.join(ignored)}: not used by model = '{self.model}' "
                         "(remove it, or choose the model that uses it)")
    return self


def cross_check(cfg, where: str) -> None:
    """Checks that need the whole rig: materials exist, components lie on the shaft, the
    mesh stays within ``MAX_ELEMENTS``, names are unique (ConfigError naming the key)."""
    for i, s in enumerate(cfg.shaft):
        for key, tube in [("material", s)] + [(f"layers[{j}].material", t)
                                               for j, t in enumerate(s.layers)]:
            if tube.material not in cfg.materials:
                known = ", ".join(sorted(cfg.materials)) or "none"
                raise ConfigError(
                    f"{where}: shaft[{i}].{key}: unknown material {tube.material!r} "
                    f"(expected one of: {known})"
                )
    length = cfg.length
    tol = 1e-9 * max(length, 1.0)

    def on_shaft(key: str, z: float) -> None:
        if not (-tol <= z <= length + tol):
            raise ConfigError(
                f"{where}: {key}: position {z} m lies outside the shaft "
                f"(expected 0 <= position <= {length:g} m)"
            )

    for kind in ("disk", "seal", "spring", "touchdown"):
        for i, comp in enumerate(getattr(cfg, kind)):
            on_shaft(f"{kind}[{i}].position", comp.position)
    if cfg.signoff.level1_position_m is not None:
        on_shaft("signoff.level1_position_m", cfg.signoff.level1_position_m)
    disks = {d.name for d in cfg.disk if d.name}
    for i, st in enumerate(cfg.stage):
        if st.position is not None:
            on_shaft(f"stage[{i}].position", st.position)
        elif st.disk not in disks:
            known = ", ".join(sorted(disks)) or "no named disk"
            raise ConfigError(f"{where}: stage[{i}].disk: unknown disk {st.disk!r} "
                              f"(expected one of: {known})")
        elif sum(d.name == st.disk for d in cfg.disk) > 1:
            raise ConfigError(f"{where}: stage[{i}].disk: {st.disk!r} names "
                              f"{sum(d.name == st.disk for d in cfg.disk)} disks; give "
                              "them distinct names, or the stage its position (m)")
        # a compressor raises the gas density; API 617's q_A takes the ratio
        if cfg.machine.kind == "compressor" and st.discharge_density < st.suction_density:
            raise ConfigError(f"{where}: stage[{i}]: discharge_density "
                              f"{st.discharge_density:g} kg/m³ below suction_density "
                              f"{st.suction_density:g} kg/m³: a compressor stage raises the "
                              "density (swapped? for an expander set [machine] kind = "
                              "\"turbine\")")
    if cfg.design.rejection.enabled and cfg.operating.continuous_hz[0] <= 0:
        raise ConfigError(f"{where}: design.rejection.enabled: a synchronous rejection "
                          "follows the running speed, and the rotor must turn: set "
                          "[operating] speed_rpm or speed_range_hz above 0 Hz")
    n_elements = sum(s.elements for s in cfg.shaft)
    if n_elements > MAX_ELEMENTS:
        raise ConfigError(
            f"{where}: shaft: {n_elements} beam elements in all (at most {MAX_ELEMENTS}): "
            f"the model would have {8 * (n_elements + 1)} states, about "
            f"{(8 * (n_elements + 1)) ** 3 * 2.5e-10:.0f} s per full-order loop judged on one "
            "core and dozens per run; use fewer elements per section")
    for kind in ("seal", "spring"):
        seen: set[str] = set()
        for i, comp in enumerate(getattr(cfg, kind)):
            name = comp.name or f"spring{i}"
            if name in seen:
                raise ConfigError(f"{where}: {kind}[{i}].name: duplicate {kind} name {name!r} "
                                  "(names make the parameter names, e.g. "
                                  f"{name}.{'k' if kind == 'seal' else 'kxx'})")
            seen.add(name)
    names: set[str] = set()
    for i, a in enumerate(cfg.amb):
        on_shaft(f"amb[{i}].position", a.position)
        on_shaft(f"amb[{i}].sensor_position", a.sensor_position)
        if a.name in names:
            raise ConfigError(f"{where}: amb[{i}].name: duplicate AMB name {a.name!r}")
        # one gap, one number: the touchdown bearing's is the one the drop lands on
        if cfg.touchdown and a.backup_clearance is not None:
            raise ConfigError(f"{where}: amb[{i}].backup_clearance: the rig's [[touchdown]] "
                              "bearings give the backup clearance (their radial_clearance); "
                              "give it there only")
        names.add(a.name)
    _check_touchdowns(cfg, where)
    _check_place_names(cfg, where)


#: The tables whose ``name`` ``ambseal drop --overload-at NAME`` and the drop's results
#: (``TA_peak_force_n``, a plane's or a seal's row) read, in that order.
_PLACE_TABLES = ("seal", "amb", "touchdown", "disk")


def _check_place_names(cfg, where: str) -> None:
    """One name, one place: a name given in two of :data:`_PLACE_TABLES` would make
    ``--overload-at NAME`` pick one of them silently (ConfigError naming both tables).
    Repeats within one table are each table's own rule."""
    first: dict[str, str] = {}
    for kind in _PLACE_TABLES:
        here: dict[str, str] = {}
        for i, comp in enumerate(getattr(cfg, kind)):
            name = getattr(comp, "name", None)
            if not name:
                continue
            if name in first:
                raise ConfigError(f"{where}: {kind}[{i}].name: {name!r} is also the name of "
                                  f"{first[name]}: a component is named by its name "
                                  "(--overload-at NAME, the drop's results); expected "
                                  f"distinct names over [[{']], [['.join(_PLACE_TABLES)}]]")
            here.setdefault(name, f"{kind}[{i}]")
        first.update(here)


def _check_touchdowns(cfg, where: str) -> None:
    """The touchdown bearings among themselves and against the AMBs (ConfigError naming the
    keys): distinct names (each names its bearing's results, ``TA_peak_force_n``),
    distinct planes (two rings on one node would share its motion, and the drop one
    contact onset between them), and every backup clearance — a ``[[touchdown]]``
    ``radial_clearance``, an ``[[amb]]`` ``backup_clearance`` — below every AMB's
    ``air_gap`` and ``sensor_gap``: the backup bearing must catch the rotor before its
    stator or a probe does. (A seal's, a spring's or a disk's clearance is judged by the
    drop, at the rotor's excursion there: a labyrinth may be rubbed on purpose.)"""
    tol = node_tolerance(cfg.length)
    for i, td in enumerate(cfg.touchdown):
        for j, other in enumerate(cfg.touchdown[:i]):
            if td.name == other.name:
                raise ConfigError(f"{where}: touchdown[{i}].name: duplicate touchdown name "
                                  f"{td.name!r}, the name of touchdown[{j}] (each names its "
                                  f"bearing's results, e.g. {td.name}_peak_force_n)")
            if abs(td.position - other.position) <= tol:
                raise ConfigError(
                    f"{where}: touchdown[{i}].position: {td.position:g} m, the plane of "
                    f"touchdown[{j}] ({other.name!r}): two rings at one axial position "
                    f"(expected positions more than {tol:g} m apart; a double-row bearing "
                    "is one [[touchdown]] whose contact_length or contact_stiffness holds "
                    "both rows)")
    backups = [(f"touchdown[{i}].radial_clearance", td.radial_clearance)
               for i, td in enumerate(cfg.touchdown)]
    backups += [(f"amb[{k}].backup_clearance", a.backup_clearance)
                for k, a in enumerate(cfg.amb) if a.backup_clearance is not None]
    gaps = [(f"amb[{k}].{key}", getattr(a, key), what) for k, a in enumerate(cfg.amb)
            for key, what in (("air_gap", "AMB's stator"), ("sensor_gap", "probe"))
            if getattr(a, key) is not None]
    for key, c in backups:
        for gap_key, gap, what in gaps:
            if c >= gap:
                raise ConfigError(
                    f"{where}: {key}: {c:g} m, not below {gap_key} {gap:g} m: a falling "
                    f"rotor would touch the {what} before its backup bearing (expected "
                    "every backup clearance below every AMB's air_gap and sensor_gap)")
