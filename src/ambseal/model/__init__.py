"""ambseal.model: the machine as equations — FE rotor, AMBs, seals, springs, plant, modes.

Each element owns its matrices and parameter channels; the rig only assembles them:

* :class:`BeamElement`, :class:`DiskElement` — Timoshenko shaft elements and rigid disks
  (Nelson 1980; Friswell et al., *Dynamics of Rotating Machines*, 2010, §5.4–5.5);
  :func:`build_mesh`, :func:`assemble_rotor` — the rotor's mesh and matrices;
* :class:`AmbElement` — the linearised AMB force ``f = Ki·i + Ks·s`` (thesis P2 Eq. 1,
  P5 Eq. 1) on actuator axes rotated from x, y (:func:`axes_rotation`), its factors
  (:func:`amb_factors`) and bias current (:func:`bias_current`, :func:`bias_currents`), the
  amplifier and the eddy-current lag (:func:`actuator_matrices`,
  :func:`eddy_lag_matrices`);
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
* :func:`modal_reduction` → :class:`ModalReduction` — the small real model (P1 §III.4–6);
* :class:`Modes`, :func:`modes_from_poles`, :func:`classify_poles`, :func:`free_bending_hz`,
  :func:`bending_limit_hz` — damped natural frequencies, damping, unstable poles;
  :func:`poles_near_zero` → :class:`PoleDisk` — the lowest eigenvalues and mode shapes of a
  fine mesh without a dense eigendecomposition.

``modes`` itself is not re-exported: it shares its module's name, and re-exporting it would
hide :mod:`ambseal.model.modes` (``from ambseal.model import modes`` would then give the
function); call :func:`ambseal.model.modes.modes`.

Units are SI throughout (m, kg, s, N, A, rad/s, Pa); node DOFs are ``[x, y, α, β]``.
"""

from ambseal.model.amb import (
    AmbElement,
    actuator_matrices,
    amb_factors,
    axes_rotation,
    bias_current,
    bias_currents,
    channel_names,
    eddy_lag_matrices,
)
from ambseal.model.fe import BeamElement, DiskElement
from ambseal.model.lft import Channel, Parameter, Plant
from ambseal.model.modes import (
    RIGID_BODY_RAD_S,
    Modes,
    PoleDisk,
    bending_limit_hz,
    classify_poles,
    free_bending_hz,
    modes_from_poles,
    poles_near_zero,
)
from ambseal.model.reduction import ModalReduction, modal_reduction
from ambseal.model.rig import SecondOrderSystem, build_plant, build_system, mechanical_plant
from ambseal.model.rotor import Mesh, RotorMatrices, assemble_rotor, build_mesh
from ambseal.model.seal import (
    SealElement,
    coefficient_value,
    pressure_for_k,
    seal_coefficients,
    seal_values,
    values_following,
    values_following_k,
)
from ambseal.model.spring import SpringElement

__all__ = ["RIGID_BODY_RAD_S", "AmbElement", "BeamElement", "Channel", "DiskElement", "Mesh",
           "ModalReduction", "Modes", "Parameter", "Plant", "PoleDisk", "RotorMatrices",
           "SealElement", "SecondOrderSystem", "SpringElement", "actuator_matrices",
           "amb_factors", "assemble_rotor", "axes_rotation", "bending_limit_hz",
           "bias_current", "bias_currents", "build_mesh", "build_plant", "build_system",
           "channel_names", "classify_poles", "coefficient_value", "eddy_lag_matrices",
           "free_bending_hz", "mechanical_plant", "modal_reduction", "modes_from_poles",
           "poles_near_zero", "pressure_for_k", "seal_coefficients", "seal_values",
           "values_following", "values_following_k"]
