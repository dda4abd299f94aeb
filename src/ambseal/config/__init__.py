"""ambseal.config: the rig file — its TOML format, validated with pydantic (strict).

The one place that knows the file format (:mod:`ambseal.config.rig`: rotor, AMBs, seals,
springs, controllers, operating points, the facility truth) and its ``[design]`` part
(:mod:`ambseal.config.design`) with the controller methods it names
(:mod:`ambseal.config.methods`); rules that need more than one key live in
:mod:`ambseal.config._checks`, with the bounds of the values (``MAX_*``, each with its
reason there), which the other layers' checks of the same quantities share. Every other
layer receives the typed models from here.
"""

from ambseal.config._checks import (
                                    MAX_AMBS,
                                    MAX_COEFFICIENT,
                                    MAX_COMPONENTS,
                                    MAX_CURRENT_A,
                                    MAX_DELAY_SAMPLES,
                                    MAX_ELEMENTS,
                                    MAX_FREQUENCY_HZ,
                                    MAX_GAP_M,
                                    MAX_PRESSURE_BAR,
                                    MAX_SPEED_HZ,
                                    MAX_SPEED_RPM,
                                    MAX_SUPPORT_STIFFNESS,
                                    MIN_FRICTION_VELOCITY,
                                    check_coil,
                                    node_tolerance,
)
from ambseal.config.methods import METHODS, Method, method, method_label, method_names
from ambseal.config.rig import (
                                    Actuator,
                                    Affine,
                                    Amb,
                                    AxisPair,
                                    Coefficient,
                                    FrequencyTable,
                                    Machine,
                                    Pid,
                                    PidFilter,
                                    SPRING_BOUNDS,
                                    RigConfig,
                                    Seal,
                                    Signoff,
                                    Spring,
                                    Stage,
                                    Touchdown,
                                    TruthSection,
                                    apply_overrides,
                                    check_below_trip,
                                    check_operating,
                                    default_rig_path,
                                    drop_limits_with,
                                    dump_rig,
                                    load_rig,
                                    load_truth,
                                    parse_rig,
                                    rig_parameter_names,
                                    rig_with_values,
                                    toml_string,
)

__all__ = ["MAX_AMBS", "MAX_COEFFICIENT", "MAX_COMPONENTS", "MAX_CURRENT_A", "MAX_DELAY_SAMPLES", "MAX_ELEMENTS",
           "MAX_FREQUENCY_HZ", "MAX_GAP_M", "MAX_PRESSURE_BAR", "MAX_SPEED_HZ", "MAX_SPEED_RPM", "MAX_SUPPORT_STIFFNESS", "METHODS",
           "SPRING_BOUNDS",
           "Method", "method", "method_label", "method_names",
           "Actuator", "Affine", "Amb", "AxisPair", "Coefficient", "FrequencyTable",
           "Machine", "Pid", "PidFilter", "RigConfig", "Seal", "Signoff", "Spring", "Stage",
           "Touchdown",
           "TruthSection", "apply_overrides",
           "MIN_FRICTION_VELOCITY", "check_below_trip", "check_coil", "check_operating", "node_tolerance",
           "default_rig_path", "drop_limits_with", "dump_rig", "load_rig",
           "load_truth",
           "parse_rig", "rig_parameter_names", "rig_with_values", "toml_string"]
