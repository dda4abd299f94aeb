"""ambseal.model: the machine as equations — FE rotor, AMBs, seals, springs, plant, modes.

Each element owns its matrices and parameter channels; the rig only assembles them:

* :class:`BeamElement`, :class:`DiskElement` — Timoshenko shaft elements and rigid disks
  (Nelson 1980; Friswell et al., *Dynamics of Rotating Machines*, 2010, §5.4–5.5);
  :func:`build_mesh`, :func:`assemble_rotor` — the rotor's mesh and matrices;
* :class:`AmbElement` — the linearised AMB force ``f = Ki·i + Ks·s`` (thesis P2 Eq. 1,
  P5 Eq. 1) on actuator axes rotated from x, y (:func:`axes_rotation`);
* :class:`SealElement` — Childs' seal force (P4 Eq. 3), its coefficients against the
  pressure drop (:func:`seal_coefficients`, :func:`seal_values`, P5 §4.1);
* :class:`SpringElement` — a flexible coupling (P4 Eq. 4) or a plain bearing;
* :func:`build_system` → :class:`SecondOrderSystem` — ``M q̈ + (C + ΩG) q̇ + K q``;
  :func:`build_plant` → :class:`Plant` — the state-space plant from current references to
  displacements, physical parameters as LFT channels (:class:`Parameter`,
  :class:`Channel`; P1 Eqs. 46–52);
* :func:`modal_reduction` → :class:`ModalReduction` — the small real model (P1 §III.4–6);
* :class:`Modes`, :func:`classify_poles`, :func:`free_bending_hz`,
  :func:`bending_limit_hz` — damped natural frequencies, damping, unstable poles;
  :func:`poles_near_zero` → :class:`PoleDisk` — the lowest eigenvalues and mode shapes of a
  fine mesh without a dense eigendecomposition.

``modes`` itself is not re-exported: it shares its module's name, and re-exporting it would
hide :mod:`ambseal.model.modes` (``from ambseal.model import modes`` would then give the
function); call :func:`ambseal.model.modes.modes`.

Units are SI throughout (m, kg, s, N, A, rad/s, Pa); node DOFs are ``[x, y, α, β]``.
"""

from ambseal.model.amb import AmbElement, axes_rotation, channel_names
from ambseal.model.fe import BeamElement, DiskElement
from ambseal.model.lft import Channel, Parameter, Plant
from ambseal.model.modes import (
    Modes,
    PoleDisk,
    bending_limit_hz,
    classify_poles,
    free_bending_hz,
    poles_near_zero,
)
from ambseal.model.reduction import ModalReduction, modal_reduction
from ambseal.model.rig import SecondOrderSystem, build_plant, build_system
from ambseal.model.rotor import Mesh, RotorMatrices, assemble_rotor, build_mesh
from ambseal.model.seal import SealElement, pressure_for_k, seal_coefficients, seal_values
from ambseal.model.spring import SpringElement

__all__ = ["AmbElement", "BeamElement", "Channel", "DiskElement", "Mesh", "ModalReduction",
           "Modes", "Parameter", "Plant", "PoleDisk", "RotorMatrices", "SealElement",
           "SecondOrderSystem", "SpringElement", "assemble_rotor", "axes_rotation",
           "bending_limit_hz", "build_mesh", "build_plant", "build_system", "channel_names",
           "classify_poles", "free_bending_hz", "modal_reduction", "poles_near_zero",
           "pressure_for_k", "seal_coefficients", "seal_values"]
