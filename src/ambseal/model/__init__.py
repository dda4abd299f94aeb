"""ambseal.model: the machine as equations — FE rotor, AMBs, seals, springs, plant, modes.

Each element owns its matrices and parameter channels; the rig only assembles them:

* :class:`BeamElement`, :class:`DiskElement` — Timoshenko shaft elements and rigid disks
  (Nelson 1980; Friswell et al., *Dynamics of Rotating Machines*, 2010, §5.4–5.5);
  :func:`build_mesh`, :func:`assemble_rotor` — the rotor's mesh and matrices;
  :func:`supported_modal_damping` — damping ratios on the modes of the rotor on its
  supports (ROSS 3's modal damping);
* :class:`AmbElement` — the linearised AMB force ``f = Ki·i + Ks·s`` (thesis P2 Eq. 1,
  P5 Eq. 1) on actuator axes rotated from x, y (:func:`axes_rotation`), its factors
  (:func:`amb_factors`) and bias current (:func:`bias_current`, :func:`bias_currents`), the
  amplifier and the eddy-current lag (:func:`actuator_matrices`,
  :func:`eddy_lag_matrices`); what it can deliver: its coil's inductance, force capacity
  against frequency and static load capacity (:func:`coil_inductance`,
  :func:`force_capacity`, :func:`load_capacity`), the current and voltage a control
  current needs (:func:`amplifier_needs`), what a transient needs
  (:func:`transient_needs`) and the fractions of its limits they use
  (:func:`amplifier_use`, :func:`limits_used`);
* :class:`SealElement` — Childs' seal force (P4 Eq. 3), its coefficients against the
  pressure drop (:func:`seal_coefficients`, :func:`seal_values`,
  :func:`coefficient_value`, P5 §4.1), and the coefficients that follow a tracked one
  (:func:`pressure_for_k`, :func:`values_following`, :func:`values_following_k`);
* :class:`SpringElement` — a flexible coupling (P4 Eq. 4) or a plain bearing;
* :func:`build_system` → :class:`SecondOrderSystem` — ``M q̈ + (C + ΩG) q̇ + K q``;
  :func:`build_plant` (:func:`mechanical_plant` before the reduction and the actuators) →
  :class:`Plant` — the state-space plant from current references to
  displacements, physical parameters as LFT channels (:class:`Parameter`,
  :class:`Channel`; P1 Eqs. 46–52);
* :class:`ContactLaw` — a touchdown bearing's contact: Hertz/Palmgren force, its damping
  by a named law, regularised Coulomb friction (:mod:`ambseal.model.contact`;
  :func:`normal_force`, :func:`damping_coefficient`, :func:`friction_force`), and
  :func:`hertz_impact`, the undamped impact's closed form; :func:`rated_contact_stress`,
  a rolling bearing's element stress from its C₀ (ISO 76);
* :func:`gravity_vector`, :func:`gravity_load`, :func:`axial_weight`,
  :func:`inclination` — where gravity acts on the machine as it stands (``[machine]
  orientation``) and its load on the lateral model (:data:`STANDARD_GRAVITY`);
* :func:`modal_reduction` → :class:`ModalReduction` — the small real model (P1 §III.4–6);
* :class:`Modes`, :func:`modes_from_poles`, :func:`classify_poles`, :func:`free_bending_hz`,
  :func:`bending_limit_hz` — damped natural frequencies, damping, unstable poles;
  :func:`poles_near_zero` → :class:`PoleDisk` — the lowest eigenvalues and mode shapes of a
  fine mesh without a dense eigendecomposition.

``modes`` itself is not re-exported: it shares its module's name, and re-exporting it would
hide :mod:`ambseal.model.modes` (``from ambseal.model import modes`` would then give the
function); call :func:`ambseal.model.modes.modes`.

Each name loads its module on first use (PEP 562 ``__getattr__``,
:func:`ambseal.lazy.lazy_face`): ``ambseal modes`` loads the rotor, its supports and their
modes, not the plant's python-control form.

Units are SI throughout (m, kg, s, N, A, rad/s, Pa); node DOFs are ``[x, y, α, β]``.
"""

from ambseal.lazy import lazy_face

#: Each public name (``__all__``) and the module that defines it.
_FROM = {
    "AmbElement": "amb", "actuator_matrices": "amb", "amb_factors": "amb",
    "axes_rotation": "amb", "bias_current": "amb", "bias_currents": "amb",
    "channel_names": "amb", "eddy_lag_matrices": "amb", "coil_inductance": "capacity",
    "force_capacity": "capacity", "load_capacity": "capacity", "amplifier_use": "capacity",
    "amplifier_needs": "capacity", "transient_needs": "capacity", "limits_used": "capacity",
    "AXES": "amb", "axis_label": "amb", "BeamElement": "fe",
    "ContactLaw": "contact", "hertz_impact": "contact", "normal_force": "contact",
    "damping_coefficient": "contact", "friction_force": "contact",
    "rated_contact_stress": "contact",
    "CouplingElement": "fe",
    "DiskElement": "fe", "Channel": "lft", "Parameter": "lft", "Plant": "lft",
    "Modes": "modes", "PoleDisk": "modes", "RIGID_BODY_RAD_S": "modes",
    "bending_limit_hz": "modes", "classify_poles": "modes", "free_bending_hz": "modes",
    "modes_from_poles": "modes", "poles_near_zero": "modes", "ModalReduction": "reduction",
    "modal_reduction": "reduction", "SecondOrderSystem": "rig", "build_plant": "rig",
    "build_system": "rig", "mechanical_plant": "rig", "reduction_size": "rig",
    "Mesh": "rotor",
    "RotorMatrices": "rotor", "assemble_rotor": "rotor", "build_mesh": "rotor",
    "RIGID_BELOW_RAD_S": "rotor", "supported_modal_damping": "rotor", "rigid_basis": "rotor",
    "SealElement": "seal", "coefficient_value": "seal", "table_value": "seal",
    "pressure_for_k": "seal",
    "seal_coefficients": "seal", "seal_values": "seal", "values_following": "seal",
    "values_following_k": "seal", "SpringElement": "spring", "spring_at": "spring",
    "spring_label": "spring", "STANDARD_GRAVITY": "gravity", "inclination": "gravity",
    "gravity_vector": "gravity", "gravity_load": "gravity", "axial_weight": "gravity",
}

__all__ = sorted(_FROM)

__getattr__, __dir__ = lazy_face(__name__, _FROM)
