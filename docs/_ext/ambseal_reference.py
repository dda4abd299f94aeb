"""The manual's generated references, as reStructuredText, from the code itself.

* :func:`rig_keys_rst` — every key of the rig file and the truth file, walked from the
  pydantic models of :mod:`ambseal.config` (type, default and bounds from the models; the
  derived ``[design]`` defaults and their rules from :func:`ambseal.design.specs.design_spec`
  on the embedded rig; unit and meaning from :data:`KEY_DOCS`, which must name exactly the
  models' fields — a field without an entry, or an entry without a field, stops the build);
* :func:`cli_rst` — every command and option of ``ambseal``, from :mod:`ambseal.cli`'s
  argparse parser;
* :func:`json_schema_rst` — a JSON Schema file rendered as a table of its properties, or a
  note that it is not shipped yet.

Pure Python (no Sphinx import), so that the tests can compare the pages with the code.
"""

from __future__ import annotations

import argparse
import json
import re
import tomllib
import types
import typing
from dataclasses import dataclass, field
from pathlib import Path

from pydantic import BaseModel

# ---------------------------------------------------------------------------------------
# Rig-file keys
# ---------------------------------------------------------------------------------------

#: Unit and meaning of every field of the configuration models, keyed ``Class.field``
#: (inherited fields under the class that declares them). The only hand-written part of
#: the key reference; :func:`missing_key_docs` checks it against the models.
KEY_DOCS: dict[str, tuple[str, str]] = {
    # [rotor]
    "Rotor.beam": ("", "beam theory of the shaft elements: Timoshenko (shear deformation) "
                       "or Euler–Bernoulli (none); their rotary inertia is each section's "
                       "rotary_inertia"),
    "Rotor.name": ("", "the machine's name, in every output and the report header"),
    "Rotor.modal_damping": ("", "damping ratio ζ given to every free–free bending mode of "
                                "shaft and disks (structural damping)"),
    "Rotor.supported_modal_damping": ("", "damping ratios of the modes of the rotor on "
                                          "its supports, instead of modal_damping (ROSS "
                                          "3's modal damping): a table below"),
    "SupportedModalDamping.ratios": ("", "ζ of the lowest modes of the rotor on its "
                                         "springs and seals (their stiffness and mass at 0 "
                                         "Hz and the [operating] pressure; AMBs left out: "
                                         "theirs is the loop's) at standstill, in ascending "
                                         "frequency, each plane's mode counted; modes below "
                                         "1 rpm (rigid-body) get none and are not counted "
                                         "(ROSS 3's modal_damping_ratio)"),
    "SupportedModalDamping.others": ("", "ζ of every mode above those of ratios (ROSS 3's "
                                         "default_damping_ratio)"),
    "Rotor.rayleigh_alpha": ("1/s", "Rayleigh damping α·M of shaft and disks (a mode of ω "
                                    "rad/s gets ζ = α/(2ω); ROSS 3's rotor ``alpha``)"),
    "Rotor.rayleigh_beta": ("s", "Rayleigh damping β·K of shaft and disks (ζ = βω/2; ROSS "
                                 "3's rotor ``beta``)"),
    # [materials.NAME]
    "Material.E": ("Pa", "Young's modulus"),
    "Material.rho": ("kg/m³", "density"),
    "Material.G": ("Pa", "shear modulus; give G or nu (both: they must agree within 1 %)"),
    "Material.nu": ("", "Poisson's ratio; give G or nu"),
    # [[shaft]]
    "ShaftSection.length": ("m", "length of the section; sections follow each other from "
                                 "the shaft's left end (z = 0)"),
    "ShaftSection.outer_diameter": ("m", "outer diameter"),
    "ShaftSection.inner_diameter": ("m", "bore (0: solid); less than outer_diameter"),
    "ShaftSection.material": ("", "a NAME of ``[materials.NAME]``"),
    "ShaftSection.elements": ("", "beam elements in the section (at most 400 in the whole "
                                  "shaft)"),
    "ShaftSection.rotary_inertia": ("", "the rotary inertia of the section's elements "
                                        "(false: their mass matrices are the translational "
                                        "ones only; ROSS's ``rotary_inertia=False``)"),
    "ShaftSection.gyroscopic": ("", "the gyroscopic matrices of the section's elements "
                                    "(false: none; ROSS's ``gyroscopic=False``); "
                                    "independent of rotary_inertia"),
    "ShaftSection.axial_force": ("N", "axial force in the section's tube (tension "
                                      "positive, ROSS's ``axial_force``): the geometric "
                                      "stiffness P∫w'² of each element (tension stiffens, "
                                      "compression softens)"),
    "ShaftSection.torque": ("N·m", "torque the section's tube carries (ROSS's "
                                   "``torque``): its geometric stiffness, which couples the "
                                   "two bending planes (not symmetric)"),
    "ShaftSection.outer_diameter_right": ("m", "outer diameter at the section's right "
                                               "end: a tapered (conical) section, its "
                                               "diameters linear from end to end, each "
                                               "element Genta & Gugliotta's exact conical "
                                               "element (ROSS's); default outer_diameter"),
    "ShaftSection.inner_diameter_right": ("m", "bore at the right end; less than "
                                               "outer_diameter_right (default "
                                               "inner_diameter)"),
    "ShaftSection.rayleigh_alpha": ("1/s", "the section's tube's own Rayleigh damping "
                                           "α·M (ROSS's shaft element ``alpha``)"),
    "ShaftSection.rayleigh_beta": ("s", "the section's tube's own Rayleigh damping β·K "
                                        "(ROSS's shaft element ``beta``)"),
    "ShaftSection.coupling": ("", "the section is a flexible coupling (ROSS's "
                                  "``CouplingElement``), not a beam: its halves' inertia on its "
                                  "end nodes, joined by the springs and dampers below; one "
                                  "element, no layers, nothing placed inside it; its "
                                  "diameter and material only draw it"),
    "ShaftCoupling.m_left": ("kg", "mass of the coupling's left half, on the left node"),
    "ShaftCoupling.m_right": ("kg", "mass of the right half, on the right node"),
    "ShaftCoupling.Ip_left": ("kg·m²", "polar inertia of the left half (gyroscopics)"),
    "ShaftCoupling.Ip_right": ("kg·m²", "polar inertia of the right half"),
    "ShaftCoupling.Id_left": ("kg·m²", "diametral inertia of the left half"),
    "ShaftCoupling.Id_right": ("kg·m²", "diametral inertia of the right half"),
    "ShaftCoupling.kt_x": ("N/m", "translational stiffness between the halves, x"),
    "ShaftCoupling.kt_y": ("N/m", "translational stiffness between the halves, y"),
    "ShaftCoupling.kr_x": ("N·m/rad", "rotational (angular misalignment) stiffness about x"),
    "ShaftCoupling.kr_y": ("N·m/rad", "rotational stiffness about y"),
    "ShaftCoupling.ct_x": ("N·s/m", "translational damping between the halves, x"),
    "ShaftCoupling.ct_y": ("N·s/m", "translational damping between the halves, y"),
    "ShaftCoupling.cr_x": ("N·m·s/rad", "rotational damping about x"),
    "ShaftCoupling.cr_y": ("N·m·s/rad", "rotational damping about y"),
    "ShaftSection.layers": ("", "concentric tubes on the section's nodes, in parallel with "
                                "its own (a sleeve, a hub; ROSS's layered elements)"),
    "ShaftLayer.outer_diameter": ("m", "outer diameter of the layer"),
    "ShaftLayer.inner_diameter": ("m", "its bore; at least the outer diameter of the tube "
                                       "inside it (tubes do not overlap)"),
    "ShaftLayer.material": ("", "a NAME of ``[materials.NAME]``"),
    "ShaftLayer.rotary_inertia": ("", "the layer's rotary inertia (false: its mass matrix "
                                      "is the translational one only)"),
    "ShaftLayer.gyroscopic": ("", "the layer's gyroscopic matrix (false: none)"),
    "ShaftLayer.axial_force": ("N", "axial force the layer carries (tension positive): its "
                                    "geometric stiffness"),
    "ShaftLayer.torque": ("N·m", "torque the layer carries: its geometric stiffness"),
    "ShaftLayer.outer_diameter_right": ("m", "outer diameter at the section's right end "
                                             "(a tapered layer; default outer_diameter)"),
    "ShaftLayer.inner_diameter_right": ("m", "bore at the right end (default "
                                             "inner_diameter)"),
    "ShaftLayer.rayleigh_alpha": ("1/s", "the layer's Rayleigh damping α·M"),
    "ShaftLayer.rayleigh_beta": ("s", "the layer's Rayleigh damping β·K"),
    # [[disk]]
    "Disk.position": ("m", "axial position from the shaft's left end"),
    "Disk.mass": ("kg", "mass of the rigid disk (impeller, lamination stack, sleeve, hub)"),
    "Disk.Ip": ("kg·m²", "polar moment of inertia (gyroscopics)"),
    "Disk.Id": ("kg·m²", "diametral (transverse) moment of inertia"),
    "Disk.name": ("", "a name for outputs and for ``[design.unbalance] force_at``"),
    "Disk.clearance": ("m", "the disk's radial clearance to its casing (an impeller's "
                            "shroud or tip), judged by ``ambseal drop`` (left out: not "
                            "judged)"),
    # [[amb]]
    "Amb.name": ("", "the bearing's name: it names the channels (``A_zeta``) and the "
                     "parameters (``A.Ki_zeta``); no '.', ',' or spaces"),
    "Amb.position": ("m", "axial position of the actuator"),
    "Amb.sensor_position": ("m", "axial position of its displacement sensors (non-"
                                 "collocated when it differs from position)"),
    "Amb.axes_angle_deg": ("°", "actuator axes ζ, η rotated from x, y by this angle"),
    "Amb.turns": ("", "windings per pole (geometry)"),
    "Amb.pole_area": ("m²", "pole face area (geometry)"),
    "Amb.air_gap": ("m", "nominal air gap (geometry); also sets the design scaling D_e"),
    "Amb.bias_current": ("A", "bias current (geometry); also sets D_u, the impulse and the "
                               "identification excitations' amplitude"),
    "Amb.pole_angle_deg": ("°", "half the angle between the two poles of a pole pair "
                               "(8-pole heteropolar bearing: 22.5)"),
    "Amb.ki": ("N/A", "current gain Ki, a number or ``{ zeta, eta }``; wins over the "
                      "geometry's; Ki > 0"),
    "Amb.ks": ("N/m", "negative-stiffness magnitude Ks (f = Ki i + Ks x), a number or "
                      "``{ zeta, eta }``; Ks ≥ 0"),
    "Amb.current_limit": ("A", "amplifier current limit (clipping check, orbit against "
                               "force capacity)"),
    "Amb.supply_voltage": ("V", "the amplifier's supply: with the coil's inductance it "
                                "bounds the force amplitude at high frequency, Ki·V/(Lω) "
                                "(ambseal.model.capacity)"),
    "Amb.inductance": ("H", "one magnet's coil inductance; default μ0 N² A/(2 s0) from the "
                            "geometry"),
    "Amb.resistance": ("Ω", "one magnet's coil resistance (R·i0 takes supply voltage; "
                            "default 0)"),
    "Amb.saturation_flux_density": ("T", "usable flux density of the iron: the static load "
                                         "capacity B_sat² A cos α / μ0 (default 1.2, a "
                                         "setting: no one published value)"),
    "Amb.backup_clearance": ("m", "radial clearance of the backup bearing beside the AMB; "
                                  "the report sets the unbalance orbit against it. On a "
                                  "rig with ``[[touchdown]]`` bearings it is refused: "
                                  "the nearest one's ``radial_clearance`` is the gap. "
                                  "Below every AMB's ``air_gap`` and ``sensor_gap``"),
    "Amb.sensor_gap": ("m", "the displacement probe's radial gap to its target, judged "
                            "by ``ambseal drop`` (left out: not judged)"),
    "Amb.uncertainty": ("", "``{ key = σ }``: relative 1σ uncertainty of a value the fit "
                            "holds fixed (e.g. ``ki = 0.02``)"),
    # { zeta, eta }
    "AxisPair.zeta": ("as the key", "value on the ζ axis"),
    "AxisPair.eta": ("as the key", "value on the η axis"),
    # [actuator]
    "Actuator.model": ("", "amplifier and coil from current reference to current"),
    "Actuator.cutoff_hz": ("Hz", "corner of the first-order model (first_order only)"),
    "Actuator.natural_frequency": ("rad/s", "ω_n of the second-order model (second_order "
                                            "only)"),
    "Actuator.damping_ratio": ("", "ζ of the second-order model (second_order only)"),
    "Actuator.eddy_time_constant": ("s", "τ_e: first-order lag 1/(τ_e s + 1) between coil "
                                         "current and force (eddy currents, P2 §4)"),
    "Actuator.uncertainty": ("", "``{ key = σ }``: relative 1σ uncertainty of a value the "
                                 "fit holds fixed"),
    # [[seal]]
    "Seal.name": ("", "the seal's name: it names its parameters (``seal.k``)"),
    "Seal.position": ("m", "axial position"),
    "Seal.K": ("N/m", "direct stiffness (Childs: −f = [K k; −k K] q + [C c; −c C] q̇ + M q̈)"),
    "Seal.k": ("N/m", "cross-coupled stiffness: the destabilising term"),
    "Seal.C": ("N·s/m", "direct damping"),
    "Seal.c": ("N·s/m", "cross-coupled damping"),
    "Seal.M": ("kg", "direct added mass"),
    "Seal.uncertainty": ("", "``{ key = σ }``: relative 1σ uncertainty of a value the fit "
                             "holds fixed"),
    # { at_zero, per_bar }
    "Affine.at_zero": ("as the key", "value at zero pressure drop"),
    "Affine.per_bar": ("as the key, per bar", "rise per bar of pressure drop"),
    # { frequency_hz, value }
    "FrequencyTable.frequency_hz": ("Hz", "excitation frequencies, strictly increasing"),
    "FrequencyTable.value": ("as the key", "the coefficient at each frequency; "
                                           "evaluated at the synchronous frequency"),
    "FrequencyTable.interpolation": ("", "``linear`` (default) or ``pchip`` (shape-"
                                         "preserving cubic, ROSS 3.1's) between points"),
    "FrequencyTable.extrapolation": ("", "``hold`` (default: the end value) or ``linear`` "
                                         "(the end slope, ROSS 3.1's) outside"),
    # [[spring]]
    "Spring.position": ("m", "axial position (coupling, plain bearing, support)"),
    "Spring.kxx": ("N/m", "direct stiffness in the spring's x axis; this and every "
                          "coefficient below a number or a frequency table (below), taken "
                          "at the synchronous frequency"),
    "Spring.kyy": ("N/m", "direct stiffness in the spring's y axis"),
    "Spring.kxy": ("N/m", "cross-coupled stiffness"),
    "Spring.kyx": ("N/m", "cross-coupled stiffness"),
    "Spring.cxx": ("N·s/m", "direct damping"),
    "Spring.cyy": ("N·s/m", "direct damping"),
    "Spring.cxy": ("N·s/m", "cross-coupled damping (fixed: not a parameter to identify)"),
    "Spring.cyx": ("N·s/m", "cross-coupled damping (fixed: not a parameter to identify)"),
    "Spring.mxx": ("kg", "added mass in the spring's x axis (a seal's fluid inertia; "
                         "fixed)"),
    "Spring.myy": ("kg", "added mass in the spring's y axis"),
    "Spring.mxy": ("kg", "cross-coupled added mass"),
    "Spring.myx": ("kg", "cross-coupled added mass"),
    "Spring.axes_angle_deg": ("°", "the axes the coefficients are given in, rotated from "
                                   "x, y"),
    "Spring.housing": ("", "a housing behind the spring (a table below): the spring joins "
                           "the shaft to the housing's mass instead of to ground"),
    "SpringHousing.mass": ("kg", "the housing's mass, in x and y (its own DOFs)"),
    "SpringHousing.kxx": ("N/m", "the housing's support stiffness to ground, x"),
    "SpringHousing.kyy": ("N/m", "the housing's support stiffness to ground, y"),
    "SpringHousing.kxy": ("N/m", "cross-coupled support stiffness"),
    "SpringHousing.kyx": ("N/m", "cross-coupled support stiffness"),
    "SpringHousing.cxx": ("N·s/m", "the housing's support damping, x"),
    "SpringHousing.cyy": ("N·s/m", "the housing's support damping, y"),
    "SpringHousing.cxy": ("N·s/m", "cross-coupled support damping"),
    "SpringHousing.cyx": ("N·s/m", "cross-coupled support damping"),
    "Spring.name": ("", "names its parameters (``coupling.kxx``); unnamed: ``spring<i>``"),
    "Spring.clearance": ("m", "radial running clearance of the bearing or seal: a close "
                              "clearance of the API 617 unbalance response"),
    "Spring.kind": ("", "``bearing`` (default) or ``seal``: a seal whose coefficients have "
                        "no Childs form (kxy = kyx); the sign-off treats it as a seal — a "
                        "source, left out of Level I, no bearing, no journal load, no probe"),
    "Spring.uncertainty": ("", "``{ key = σ }``: relative 1σ uncertainty of a value the fit "
                               "holds fixed"),
    # [controller], [controller.pid]
    "Controllers.pid": ("", "the reference PID; without it, derived from the rig "
                            "(``ambseal.design.pid.pid_from_rig``)"),
    "Controllers.sample_rate_hz": ("Hz", "the digital controller's sample rate f_s"),
    "Controllers.delay_samples": ("samples", "computation delay of the target in whole "
                                             "samples (1: output of sample k applied at "
                                             "k + 1)"),
    "Pid.kp": ("A/m", "proportional gain (thesis P5 Eq. 6), per actuator axis"),
    "Pid.ti": ("s", "integral time T_i"),
    "Pid.td": ("s", "derivative time T_d"),
    "Pid.eps": ("", "derivative filter ε: the filter's time constant is ε T_d"),
    "Pid.cross_kp": ("A/m", "cross-axis proportional gain between the two axes of a "
                            "bearing (default 0)"),
    "Pid.cross_kd": ("A·s/m", "cross-axis derivative gain, through the derivative's filter "
                              "(default 0)"),
    "Pid.cross_speed_rpm": ("rpm", "the speed the cross gains are given at: with it they "
                                   "scale with the speed (K_c Ω/Ω_ref, the PID scheduled "
                                   "on speed); left out, constant"),
    "Controllers.filter": ("", "filters in series with the PID on every axis; left out, "
                               "a derived PID carries its derived filters and a given PID "
                               "none (``filter = []``: none)"),
    "PidFilter.kind": ("", "``notch``, ``lead``, ``lag`` or ``lowpass``"),
    "PidFilter.frequency_hz": ("Hz", "centre of a notch, largest phase change of a lead "
                                     "or lag, corner of a low-pass"),
    "PidFilter.width_hz": ("Hz", "a notch's width between its −3 dB points"),
    "PidFilter.depth_db": ("dB", "a notch's attenuation at its centre"),
    "PidFilter.phase_deg": ("°", "phase a lead adds (a lag takes) at ``frequency_hz``; "
                                 "gain 1 at zero frequency"),
    "PidFilter.damping": ("", "a low-pass filter's damping ratio ζ"),
    # [operating]
    "Stage.name": ("", "label in the sign-off's tables"),
    "Stage.position": ("m", "axial position of the impeller or stage (or ``disk``)"),
    "Stage.disk": ("", "the ``[[disk]]`` (by ``name``) the impeller or stage is (or "
                       "``position``)"),
    "Stage.power": ("W", "rated power of the stage (API 617's P; P/Ω its torque)"),
    "Stage.impeller_diameter": ("m", "impeller diameter D_c"),
    "Stage.discharge_width": ("m", "H_c: the smaller of the impeller's discharge width and "
                                   "the diffuser's width"),
    "Stage.suction_density": ("kg/m³", "gas density at the stage's suction ρ_s"),
    "Stage.discharge_density": ("kg/m³", "gas density at the stage's discharge ρ_d"),
    "Machine.kind": ("", "``compressor`` or ``turbine``: API 617's anticipated "
                         "cross-coupling (B = 3 with the density ratio, or 1.5 without)"),
    "Machine.orientation": ("", "how the machine stands, where gravity acts: "
                                "``horizontal`` (default; along −y), ``vertical`` (along "
                                "−z: the end positions start from at the bottom; the radial "
                                "AMBs carry no weight, a thrust bearing carries it) or "
                                "``inclined`` (with inclination_deg)"),
    "Machine.inclination_deg": ("deg", "with orientation = ``inclined`` only: the rotor "
                                       "axis's angle above the horizontal, +z rising (−90 to "
                                       "90; gravity g·(0, −cos θ, −sin θ))"),
    "Signoff.csr_boundary": ("kg/m³, −", "API 617 Level I's Region A/B boundary: points "
                             "``[ρ_avg, CSR]``, linear between, flat beyond (ρ_avg: the "
                             "first stage's suction and the last stage's discharge density, "
                             "averaged; ROSS's report tool, API 684 §SP6.8.5)"),
    "Signoff.log_dec_min": ("", "least log decrement: Level I's δ_A and Level II"),
    "Signoff.unbalance_factor": ("", "the API 617 unbalance in units of U_r = 6350·W/N g·mm "
                                     "(default 2: API 617 9th ed. 6.8.2.7, U = 2 U_r, as "
                                     "ROSS 3.1's ``api617_unbalance``; another edition's "
                                     "factor, e.g. 4, here)"),
    "Signoff.analysis_top_ratio": ("", "the unbalance response is analysed from 0 to this "
                                       "times the trip speed"),
    "Signoff.vibration_limit_cap_um": ("µm", "cap of A_vl = 25.4 √(12000/N) µm p-p "
                                            "(default 25.4: API 617 9th ed. 6.8.2.10, "
                                            "A_vl = min(25.4, 25.4 √(12000/N)), as ROSS "
                                            "3.1's ``run_clearance_analysis``)"),
    "Signoff.scale_factor_limits": ("", "``[low, high]`` bounds of the scale factor "
                                        "S_c = A_vl/A_probe (default [0.5, 6], API 617 "
                                        "8th ed. Part 1 §4.8.2.11; ROSS 3.1: [0, 6])"),
    "Signoff.probes": ("", "the unbalance response's probes, ``[{ position, angle_deg "
                           "}]``, each reading x cos θ + y sin θ; left out, the orbit's "
                           "semi-major axis at the AMB sensors (the springs without AMBs)"),
    "Signoff.level1_position_m": ("m", "where Level I applies the whole cross-coupling Q; "
                                       "left out, mid-span between the outermost bearings "
                                       "or the overhung stages in proportion to their q_A "
                                       "(API 617); ROSS 3.1's ``run_level1`` takes the "
                                       "node nearest mid-span"),
    "Touchdown.name": ("", "the touchdown bearing's name, its own (it names the bearing's "
                           "results)"),
    "Touchdown.position": ("m", "axial position of its plane, each bearing's its own"),
    "Touchdown.radial_clearance": ("m", "radial clearance between the journal and the "
                                        "ring (ISO 14839-5's C_min is the smallest); "
                                        "below every AMB's ``air_gap`` and "
                                        "``sensor_gap``"),
    "Touchdown.axial_clearance": ("m", "axial clearance, where the bearing also takes "
                                       "thrust (left out: radial only)"),
    "Touchdown.kind": ("", "``deep_groove``, ``angular_contact_pair``, "
                           "``full_complement`` (rolling) or ``sleeve``"),
    "Touchdown.contact": ("", "``point`` (Hertz, n = 3/2) or ``line`` (Palmgren, "
                              "n = 10/9): F = K·δ^n"),
    "Touchdown.contact_stiffness": ("N/m^n", "K of F = K·δ^n; left out, from the geometry "
                                             "(``contact_radius`` or ``contact_length``)"),
    "Touchdown.contact_radius": ("m", "a point contact's effective radius R* "
                                      "(1/R* = Σ curvatures): K = (4/3)·E*·√R*"),
    "Touchdown.contact_length": ("m", "a line contact's length: Palmgren's "
                                      "K = (l^0.8/3.84e-5)^(10/9) in N, mm, bearing steel"),
    "Touchdown.E": ("Pa", "Young's modulus of both contacting bodies (default: AISI 52100 "
                          "bearing steel, Harris & Kotzalas 2007)"),
    "Touchdown.nu": ("", "Poisson's ratio of both bodies (default: 52100 steel)"),
    "Touchdown.damping_law": ("", "the published law ``law_restitution`` is read by, "
                                  "F = K·δ^n·(1 + D·δ̇): ``hunt_crossley`` "
                                  "D = 3(1 − e)/(2v₀), ``lankarani_nikravesh`` "
                                  "3(1 − e²)/(4v₀), ``flores`` 8(1 − e)/(5e·v₀) (default), "
                                  "v₀ the impact's normal speed; only with "
                                  "``law_restitution``"),
    "Touchdown.restitution": ("", "the measured coefficient of restitution e of one impact "
                                  "(rebound over approach normal speed); the damping "
                                  "D = ζ/v₀ is solved for it exactly, "
                                  "ζ(1 + e) = ln((1 + ζ)/(1 − eζ)) (Carvalho & Martins "
                                  "2019); this or ``law_restitution`` is required"),
    "Touchdown.law_restitution": ("", "the e of ``damping_law``'s own formula, as its "
                                      "paper uses it (an impact rebounds at it only near "
                                      "1: Hunt–Crossley's e = 0.6 at 0.71, "
                                      "Lankarani–Nikravesh's at 0.76); instead of "
                                      "``restitution``"),
    "Touchdown.friction": ("", "Coulomb friction coefficient μ of the journal on the ring "
                               "(required)"),
    "Touchdown.friction_velocity": ("m/s", "slip speed of the regularised Coulomb law "
                                           "μN·tanh(v/v_r); at least 1e-4, the slip the "
                                           "drop's stiff integrator resolves (its "
                                           "finite-difference Jacobian steps √ε of a "
                                           "surface speed)"),
    "Touchdown.race_inertia": ("kg·m²", "the ring's (inner race's) polar inertia; left "
                                        "out, the ring does not turn (a sleeve)"),
    "Touchdown.race_drag_torque": ("N·m", "the drag torque resisting the ring's spin"),
    "Touchdown.support_stiffness": ("N/m", "the bearing's support stiffness (left out: "
                                           "rigid); needs ``support_mass``"),
    "Touchdown.support_damping": ("N·s/m", "the support's damping"),
    "Touchdown.support_mass": ("kg", "the support's moving mass (needs a stiffness)"),
    "Touchdown.static_rating": ("N", "the bearing's basic static load rating C₀ (ISO 76); "
                                     "left out, the drop's peak force is not graded"),
    "Touchdown.axial_contact_stiffness": ("N/m^n", "K of the axial contact (left out: "
                                                   "the radial law's); needs "
                                                   "``axial_clearance``"),
    "Touchdown.static_factors": ("", "ISO 76's [X₀, Y₀]: P₀ = max(F_r, X₀F_r + Y₀F_a) "
                                     "graded against C₀ (left out: 0.6, 0.5 deep groove; "
                                     "1, 0.52 a 40° angular-contact pair)"),
    "Touchdown.race_mass": ("kg", "the ring's mass: the drop's friction heat reported as "
                                  "its temperature rise (left out: heat in J only)"),
    "Touchdown.race_specific_heat": ("J/(kg·K)", "the ring's specific heat (default 475: "
                                                 "through-hardened bearing steel)"),
    "DropLimits.force_ratio": ("", "largest peak contact force over C₀ that passes "
                                   "(default 1: ISO 76's static rating)"),
    "DropLimits.axial_thrust": ("N", "the residual thrust on the rotor (+z towards its far "
                                     "end) when the thrust bearing lets go (default 0)"),
    "DropLimits.penetration_ratio": ("", "the deepest penetration of a touchdown ring over "
                                         "its clearance (radial, or axial) within which the "
                                         "contact law is taken to hold; beyond it the "
                                         "verdict says the drop left its model's range, "
                                         "where and from when, and fails (default 0.5; "
                                         "``--penetration-ratio``)"),
    "DropLimits.race_temperature_rise": ("K", "largest temperature rise of a ring with a "
                                              "``race_mass`` that passes (left out: not "
                                              "graded)"),
    "Probe.position": ("m", "the probe's axial position (a node of the rotor)"),
    "Probe.angle_deg": ("°", "the direction it reads, from x towards y (default 0)"),
    "Signoff.scale_factor_speeds": ("", "where A_probe is taken: ``to_trip`` (default, "
                                        "standstill to the trip speed) or ``continuous`` "
                                        "(minimum to maximum continuous, ROSS 3.1's)"),
    "Signoff.journal_load": ("", "API 617's journal static load W (U_r = 6350·W/N) on a "
                                 "machine that does not lie horizontal: ``as_horizontal`` "
                                 "(default: the rotor's weight apportioned to its bearings "
                                 "by static equilibrium as if it lay horizontal, API 684 2nd "
                                 "ed.'s reading for vertical machines, not confirmed in the "
                                 "public text) or ``as_acting`` (the lateral part of gravity "
                                 "as the machine stands; refused on a vertical rotor, whose "
                                 "journals carry none); the same on a horizontal one"),
    "Signoff.clearance_fraction": ("", "the scaled response's allowed fraction of each "
                                       "close clearance (diametral)"),
    "Signoff.iso14839_2_zones": ("", "ISO 14839-2 zone boundaries A/B, B/C, C/D as "
                                     "fractions of the backup bearing's clearance"),
    "Seal.clearance": ("m", "radial running clearance: a close clearance of the API 617 "
                            "unbalance response"),
    "Seal.static_eccentricity": ("m", "the rotor's static offset in the seal (its "
                                      "misalignment): the seal's static load, −[K k; −k K] "
                                      "times it, that the AMBs carry in every judged "
                                      "condition"),
    "Operating.trip_speed_hz": ("Hz", "trip speed (default 1.05 × the maximum continuous "
                                      "speed, the top of ``speed_range_hz`` or the "
                                      "operating speed): the worst unbalance orbit is "
                                      "judged up to it from standstill"),
    "Operating.speed_rpm": ("rpm", "operating speed; negative, the rotor turns the other "
                                   "way (about −z)"),
    "Operating.pressure_bar": ("bar", "nominal pressure drop across the seals"),
    "Operating.speed_range_hz": ("Hz", "``[low, high]`` operating speed range: schedules "
                                       "the LPV controller and sets the unbalance band; it "
                                       "must hold speed_rpm"),
    # [reduction]
    "Reduction.states": ("", "states of the reduced model (give states or cutoff_hz; "
                             "neither: 8)"),
    "Reduction.cutoff_hz": ("Hz", "keep the modes below this frequency instead"),
    # [design]
    "Design.d_e_um": ("µm", "D_e: largest allowed displacement error, scales the error "
                            "channels (P5 §3.1.4)"),
    "Design.d_u_a": ("A", "D_u: largest allowed current change, scales the current "
                          "channels"),
    "Design.model_states": ("", "mechanical states of the design model (even)"),
    "Design.model_cutoff_hz": ("Hz", "or: every mode below this frequency"),
    "Design.band_hz": ("Hz", "``[low, high]``: synthesis (μ grid) and judgement band"),
    "Design.order_max": ("", "controller order limit (balanced truncation above it); "
                             "left out: the design model's states plus W_p's and W_u's, "
                             "raised by one per channel while the reduction costs more "
                             "than 10 % of γ or μ"),
    "Design.pressures_bar": ("bar", "pressure drops every controller is judged at"),
    "Design.speeds_hz": ("Hz", "speeds every controller is judged at"),
    "Design.stability_speeds_hz": ("Hz", "speeds where every controller's full-order loop "
                                   "must be stable at each judged pressure (default: "
                                   "standstill to the top speed in quarters)"),
    "Design.unbalance": ("", "the unbalance force (table below)"),
    "Design.impulse": ("", "the current impulse of the time response (table below)"),
    "Design.uncertainty": ("", "real uncertain parameters of μ (array of tables below)"),
    "Design.uncertainty_from_identification": ("", "path of a ``fit.json`` of ``ambseal "
                                                   "identify`` (relative to the rig file): "
                                                   "its 95 % intervals become μ ranges"),
    "Design.hinf": ("", "H∞ weights (table below)"),
    "Design.mu": ("", "μ weights and D–K settings (table below)"),
    "Design.lpv": ("", "LPV weights (table below)"),
    "Design.rejection": ("", "the unbalance force rejection (table below)"),
    "RejectionSpec.enabled": ("", "``ambseal run`` adds to every delivered controller a "
                                  "generalised notch at the rotational frequency, scheduled "
                                  "on speed over ``speed_range_hz``, judged and shown"),
    "RejectionSpec.rate_fraction": ("", "ε/Ω of the notch (default 0.05: it settles in "
                                        "≈ 6 revolutions)"),
    "RejectionSpec.points": ("", "that many evenly spaced speeds of its gain table over "
                                 "the speed range (default: speeds found by bisection "
                                 "until the interpolated gain holds the notch's poles "
                                 "within 25 % of their placement)"),
    "RejectionSpec.runout_um": ("µm", "the synchronous sensor runout of its check on the "
                                      "virtual facility (default 1 % of the smallest air "
                                      "gap or backup clearance, else 5 µm)"),
    "Design.one_speed": ("", "H∞ and μ designed at the operating speed alone (default "
                             "false: on a rig with a speed range, a design that loses the "
                             "rotor at another judged speed is designed again with the "
                             "spin speed uncertain over the judged speeds, else at each "
                             "stability speed from standstill up, the first that holds "
                             "every judged condition kept)"),
    "Design.synthesis_plant": ("", "``continuous`` (default): H∞ and μ synthesised on the "
                                   "design model with the delay as a Padé lag, then "
                                   "discretised; ``sampled``: on the design model sampled "
                                   "with its delay, in the w-plane, the discrete controller "
                                   "its Tustin transform"),
    "Design.tracked": ("", "``ambseal run`` adds the controller scheduled on the tracked "
                           "seal k (LMI synthesis: minutes)"),
    "UnbalanceSpec.grade_mm_s": ("mm/s", "ISO 21940-11 balance grade G"),
    "UnbalanceSpec.mass_kg": ("kg", "mass m of the force law (left out: the assembled "
                                    "rotor mass)"),
    "UnbalanceSpec.law": ("", "``iso21940``: F = m G Ω²/Ω_max; ``constant_velocity``: "
                              "F = m G Ω"),
    "UnbalanceSpec.max_speed_hz": ("Hz", "maximum service speed Ω_max/2π at which the "
                                         "grade holds"),
    "UnbalanceSpec.force_at": ("", "seal, disk, AMB or spring where the force acts and the "
                                   "compliance is taken"),
    "UnbalanceSpec.range_hz": ("Hz", "``[low, high]`` speeds of the unbalance response "
                                     "(on a machine that runs, judged from standstill to "
                                     "the trip speed as well)"),
    "UnbalanceSpec.plant": ("", "``running`` (default): at each speed the plant built at "
                                "that speed, forward-turning forces; ``frozen``: the plant "
                                "at the judged condition, the forcing swept (the thesis's "
                                "simplification, P5 §4.4.1)"),
    "ImpulseSpec.amplitude_a": ("A", "current impulse amplitude (P5 §5.1); also the "
                                     "amplitude of every identification excitation"),
    "ImpulseSpec.duration_s": ("s", "current impulse duration (judgement and identification)"),
    "UncertainSpec.parameter": ("", "an LFT parameter name: ``<seal>.k``, ``A.Ks_zeta``, "
                                    "``coupling.kxx``, …"),
    "UncertainSpec.relative": ("", "± this fraction of the nominal value (1.0: ± 100 %)"),
    "UncertainSpec.low": ("SI", "lower end (with high, instead of relative)"),
    "UncertainSpec.high": ("SI", "upper end"),
    "MethodSpec.M": ("", "W_p: high-frequency bound of the sensitivity (P5 Eq. 7)"),
    "MethodSpec.omega_b_rad_s": ("rad/s", "W_p: bandwidth ω_B"),
    "MethodSpec.A": ("", "W_p: low-frequency sensitivity bound (integral action)"),
    "MethodSpec.wu_gain": ("", "W_u: gain on the scaled current"),
    "MethodSpec.wu_corner_hz": ("Hz", "W_u: corner of a high-pass W_u"),
    "MethodSpec.wu_hf_gain": ("", "W_u: high-frequency gain (> wu_gain)"),
    "MethodSpec.w1_gain": ("", "W_1: input-disturbance weight"),
    "MethodSpec.w1_corner_hz": ("Hz", "W_1: corner frequency"),
    "MethodSpec.orbit_um": ("µm", "unbalance-orbit demand (0: off)"),
    "MethodSpec.wf_rolloff_hz": ("Hz", "roll-off of the unbalance-force weight W_f"),
    "MuSpec.max_iter": ("", "a cap on each D–K phase's iterations (none: its stall rule "
                            "ends it)"),
    "MuSpec.dk_order": ("", "order of the fitted D scales"),
    "MuSpec.iteration": ("", "``dgk``: D–G–K, real parameters kept real (Young 1996); "
                             "``dk``: complex D–K as the thesis"),
    "MuSpec.gain_factor": ("", "W_K: controller gain within this factor × 3 × the PID's "
                               "over gain_band_hz (0: off)"),
    "MuSpec.gain_band_hz": ("Hz", "``[low, high]`` band of the gain demand W_K"),
    # truth file
    "TruthSection.parameters": ("SI", "true values of model parameters (``A.Ki_zeta``, "
                                      "``seal.k``, …): a number or ``{ at_zero, per_bar }``"),
    "TruthSection.tau_e": ("s", "true eddy-current lag"),
    "TruthSection.bias_current": ("A", "bias current of the nonlinear force law"),
    "TruthSection.current_limit": ("A", "amplifier saturation (default the AMBs')"),
    "TruthSection.sensor_noise_m": ("m", "sensor noise standard deviation"),
    "TruthSection.noise_fraction": ("", "or: noise std as a fraction of each channel's RMS"),
    "TruthSection.current_noise_a": ("A", "current measurement noise std"),
    "TruthSection.adc_bits": ("bits", "ADC resolution of the displacement sensors"),
    "TruthSection.adc_range_m": ("m", "ADC range: quantisation step range/2^bits"),
    "TruthSection.substeps": ("", "integration steps per controller sample"),
    "TruthSection.max_mode_hz": ("Hz", "modes kept in the simulation"),
    "TruthSection.beam": ("", "model-form difference: the facility's beam theory"),
    "TruthSection.mesh_factor": ("", "model-form difference: elements per section × this"),
    "TruthSection.modal_damping": ("", "model-form difference: the rotor's ζ"),
    "TruthSection.sensor_filter_hz": ("Hz", "model-form difference: a first-order low-pass "
                                            "in every sensor, absent from the model"),
}


@dataclass
class KeyRow:
    """One key of one table of the file."""

    table: str          # "[[amb]]", "[design.mu]", "{ zeta, eta }", ...
    key: str
    type: str
    default: str
    unit: str
    meaning: str
    bounds: str = ""
    rule: str = ""


@dataclass
class Section:
    table: str
    model: type
    intro: str = ""
    rows: list[KeyRow] = field(default_factory=list)


def _models():
    from ambseal.config import rig as r
    from ambseal.config import design as d

    return r, d


def _is_model(t) -> bool:
    return isinstance(t, type) and issubclass(t, BaseModel)


def _args(ann) -> tuple:
    """The members of a union (``X | Y``, ``Optional``, ``Annotated`` unwrapped)."""
    origin = typing.get_origin(ann)
    if origin is typing.Annotated:
        return _args(typing.get_args(ann)[0])
    if origin in (typing.Union, types.UnionType):
        out = ()
        for a in typing.get_args(ann):
            out += _args(a)
        return out
    return (ann,)


def _type_text(ann) -> str:
    """A TOML reader's name for an annotation."""
    r, _ = _models()
    names = []
    for a in _args(ann):
        if a is type(None):
            continue
        origin = typing.get_origin(a)
        if a is float:
            names.append("number")
        elif a is int:
            names.append("integer")
        elif a is bool:
            names.append("true/false")
        elif a is str:
            names.append("string")
        elif origin is typing.Literal:
            names.append(" | ".join(f'``"{v}"``' for v in typing.get_args(a)))
        elif origin is tuple:
            names.append("``[low, high]``")
        elif origin is list:
            inner = typing.get_args(a)[0]
            names.append("array of tables" if _is_model(inner) else "array of numbers")
        elif origin is dict:
            val = typing.get_args(a)[1]
            names.append("``{ name = table }``" if _is_model(val) else "``{ key = number }``")
        elif a is r.AxisPair:
            names.append("``{ zeta, eta }``")
        elif a is r.Affine:
            names.append("``{ at_zero, per_bar }``")
        elif a is r.FrequencyTable:
            names.append("``{ frequency_hz, value }``")
        elif _is_model(a):
            names.append("table")
        else:  # pragma: no cover - a new kind of annotation: say so in the build
            raise TypeError(f"rig-key reference: no name for the annotation {a!r}")
    return " or ".join(names)


def _num(x) -> str:
    if isinstance(x, bool):
        return "true" if x else "false"
    if isinstance(x, float):
        return f"{x:g}".replace("e+0", "e").replace("e+", "e").replace("e-0", "e-")
    return str(x)


def _bounds(info) -> str:
    out = []
    for m in info.metadata:
        for attr, sym in (("ge", "≥"), ("gt", ">"), ("le", "≤"), ("lt", "<")):
            v = getattr(m, attr, None)
            if v is not None and not (isinstance(v, (int, float)) and abs(v) >= 1e12):
                out.append(f"{sym} {_num(v)}")
        if getattr(m, "min_length", None) is not None and m.min_length > 1:
            out.append(f"at least {m.min_length} items")
        if getattr(m, "pattern", None):
            out.append("no '.', ',' or spaces")
    return ", ".join(out)


def _default(info) -> str:
    if info.is_required():
        return "required"
    d = info.default
    if d is None:
        return "none"
    if _is_model(type(d)):
        return "—"
    if isinstance(d, (list, dict)) and not d:
        return "none"
    return f"``{_num(d)}``" if not isinstance(d, str) else f'``"{d}"``'


def _doc(cls, name: str) -> tuple[str, str]:
    for c in cls.__mro__:
        key = f"{c.__name__}.{name}"
        if key in KEY_DOCS:
            return KEY_DOCS[key]
    raise KeyError(f"{cls.__name__}.{name}")


def _sections() -> list[Section]:
    """The tables of a rig file and of a truth file, in the order a file has them."""
    r, d = _models()
    return [
        Section("[rotor]", r.Rotor),
        Section("[materials.NAME]", r.Material, "One table per material; NAME is what "
                "``[[shaft]] material`` refers to."),
        Section("[[shaft]]", r.ShaftSection, "One table per shaft section, left to right; "
                "at least one."),
        Section("[[disk]]", r.Disk, "Rigid disks: impellers, lamination stacks, sleeves, "
                "hubs."),
        Section("[[amb]]", r.Amb, "One table per radial bearing: either the geometry "
                "(``turns``, ``pole_area``, ``air_gap``, ``bias_current``) or both ``ki`` "
                "and ``ks`` (a factor given explicitly wins over the geometry's; with ki "
                "and ks, ``air_gap`` and ``bias_current`` alone set the design scalings)."),
        Section("[actuator]", r.Actuator, "Amplifier, coil and eddy currents, the same for "
                "every axis."),
        Section("[[seal]]", r.Seal, "Each coefficient is a number, ``{ at_zero, per_bar }`` "
                "(affine in the pressure drop) or ``{ frequency_hz, value }`` (a table "
                "against excitation frequency, evaluated at the synchronous frequency)."),
        Section("[[spring]]", r.Spring, "Couplings, plain bearings, supports."),
        Section("[[stage]]", r.Stage, "One table per impeller or stage: what API 617's "
                "Level I stability screening needs (``ambseal signoff``); ``position`` or "
                "``disk``, one of them."),
        Section("[[touchdown]]", r.Touchdown, "One table per touchdown (backup) bearing "
                "plane: its clearance, contact law and damping, friction, ring and support "
                "(``ambseal.model.contact``)."),
        Section("[drop]", r.DropLimits, "The rotor drop's pass criteria (``ambseal "
                "drop``)."),
        Section("[machine]", r.Machine),
        Section("[signoff]", r.Signoff, "The sign-off's limits that the standards' public "
                "text could not confirm; every key optional, its default shown."),
        Section("[[signoff.probes]]", r.Probe, "The unbalance response's probes, "
                "directional, at any node (optional)."),
        Section("[controller]", r.Controllers),
        Section("[controller.pid]", r.Pid, "All four keys, or leave the table out."),
        Section("[[controller.filter]]", r.PidFilter, "A notch, lead, lag or low-pass "
                "filter in series with the PID (``ambseal.design.pid.pid_controller``), "
                "with the keys of its kind only."),
        Section("[operating]", r.Operating),
        Section("[reduction]", r.Reduction, "The reduced model of ``validate`` and the "
                "identification; the design model is ``[design] model_states``."),
        Section("[design]", d.Design, "What the controllers are asked for. Every key is "
                "optional: a key left out is derived from the machine by the rule shown "
                "(the value is the embedded test facility's with no ``[design]`` part)."),
        Section("[design.unbalance]", d.UnbalanceSpec),
        Section("[design.impulse]", d.ImpulseSpec),
        Section("[[design.uncertainty]]", d.UncertainSpec, "Real uncertain parameters of "
                "the μ design: ``relative``, or ``low`` and ``high``."),
        Section("[design.hinf]", d.MethodSpec, "The same keys in ``[design.lpv]``, and in "
                "``[design.mu]`` with the μ keys below."),
        Section("[design.mu]", d.MuSpec, "Every key of ``[design.hinf]``, and:"),
        Section("[design.rejection]", d.RejectionSpec, "The unbalance force rejection "
                "(Herzog et al., IEEE TCST 1996): a generalised notch filter in each "
                "controller's input, on from the minimum continuous speed (lower where the "
                "controller alone saturates its amplifier through a critical on the way "
                "there; later where a notch from there does not hold, see the run's "
                "``rejection`` block in :doc:`/getting-started`)."),
        Section("{ zeta, eta }", r.AxisPair, "A value per actuator axis (``ki``, ``ks``); "
                "with the geometry one axis may be left out."),
        Section("{ at_zero, per_bar }", r.Affine, "A coefficient affine in the pressure "
                "drop p (bar): at_zero + per_bar · p."),
        Section("{ outer_diameter, inner_diameter, material }", r.ShaftLayer, "A layer of "
                "a ``[[shaft]]`` section (``layers = [{ ... }, ...]``): a tube of its own "
                "material and shear parameter whose beam matrices add to the section's."),
        Section("{ m_left, m_right, kt_x, kr_x, ... }", r.ShaftCoupling, "The ``coupling`` "
                "of a ``[[shaft]]`` section that is a flexible coupling (``coupling = "
                "{ ... }``): each half's inertia on its end node, the halves joined by "
                "springs and dampers."),
        Section("{ mass, kxx, kyy, cxx, ... }", r.SpringHousing, "The ``housing`` of a "
                "``[[spring]]`` (``housing = { ... }``): a mass of two DOFs, x and y, between "
                "the spring and ground (ROSS's bearing linked to a housing node, ``n_link``, "
                "with its point mass and supports). Its coefficients are in x, y; the "
                "spring's own act on the shaft's motion relative to the housing."),
        Section("[rotor.supported_modal_damping]", r.SupportedModalDamping, "Modal "
                "damping on the modes of the rotor on its supports, C = M Φ diag(2ζω) Φᵀ M "
                "with Φ those mass-normalised modes (Craig & Kurdila 2006, §10.2), as ROSS "
                "3's ``Rotor(modal_damping_ratio=..., default_damping_ratio=...)``."),
        Section("{ frequency_hz, value }", r.FrequencyTable, "A seal coefficient tabulated "
                "against excitation frequency, of equal lengths."),
        Section("[truth]", r.TruthSection, "The truth file of the virtual test facility "
                "(``ambseal acquire --truth``, ``ambseal run --truth``): a file of its own "
                "that a fit never reads."),
    ]


def _design_defaults() -> tuple[dict, dict]:
    """Resolved ``[design]`` values and rules of the embedded rig without a ``[design]``
    part: ``({"mu.orbit_um": 10.0, ...}, {"mu.orbit_um": "0.5 D_e", ...})``."""
    from ambseal.config import default_rig_path, parse_rig
    from ambseal.design.specs import design_spec

    data = tomllib.loads(default_rig_path().read_text(encoding="utf-8"))
    data.pop("design", None)
    spec = design_spec(parse_rig(data, "<embedded rig without [design]>"))
    doc = tomllib.loads(spec.to_toml())["design"]
    values: dict = {}

    def flat(prefix, node):
        for k, v in node.items():
            if isinstance(v, dict):
                flat(f"{prefix}{k}.", v)
            else:
                values[f"{prefix}{k}"] = v
    flat("", doc)
    return values, dict(spec.sources)


_SHARED = {"MethodSpec"}  # classes whose section stands for several tables
#: ``[design]`` tables and the prefixes of their keys in the resolved specification;
#: the section of ``[design.hinf]`` stands for ``[design.lpv]`` and ``[design.mu]`` too.
_DESIGN_PREFIXES = {"[design]": ("",), "[design.unbalance]": ("unbalance.",),
                    "[design.impulse]": ("impulse.",), "[design.hinf]": ("hinf.", "mu.", "lpv."),
                    "[design.mu]": ("mu.",)}
_METHOD = {"hinf.": "H∞", "mu.": "μ", "lpv.": "LPV"}


def _derived(prefixes, name, values, rules) -> tuple[str, str]:
    """(default, rule) of a ``[design]`` key from the resolved specification."""
    defaults, rule_texts = [], []
    for pre in prefixes:
        key = f"{pre}{name}"
        v = values.get(key)
        label = f"{_METHOD[pre]} " if len(prefixes) > 1 else ""
        if v is not None and not (isinstance(v, list) and v and isinstance(v[0], dict)):
            defaults.append(f"{label}``{_num(v)}``")
        rule = rules.get(key) or rules.get(pre.rstrip(".")) if pre else rules.get(key)
        if rule and rule != "set":
            rule_texts.append(f"{label}{rule}")
    return ", ".join(defaults), "; ".join(dict.fromkeys(rule_texts))


def rig_key_sections(design_defaults: bool = True) -> list[Section]:
    """Every table with its keys (own fields only for a subclass shown after its base)."""
    values, rules = _design_defaults() if design_defaults else ({}, {})
    out = []
    for sec in _sections():
        inherited = set()
        for base in sec.model.__mro__[1:]:
            if _is_model(base) and base.__name__ in _SHARED:
                inherited |= set(base.model_fields)
        for name, info in sec.model.model_fields.items():
            if name in inherited:
                continue
            unit, meaning = _doc(sec.model, name)
            default, rule = _default(info), ""
            prefixes = _DESIGN_PREFIXES.get(sec.table)
            if prefixes and not _is_model(type(info.default)):
                value, rule = _derived(prefixes, name, values, rules)
                if value:
                    default = value
                elif rule and info.default is None:
                    default = "derived"
            sec.rows.append(KeyRow(sec.table, name, _type_text(info.annotation), default,
                                   unit, meaning, _bounds(info), rule))
        out.append(sec)
    return out


def model_keys() -> set[tuple[str, str]]:
    """``(table, key)`` of every field of every model of a rig or truth file, walked from
    :class:`~ambseal.config.RigConfig` and :class:`~ambseal.config.TruthSection`
    independently of :func:`rig_key_sections` (the test compares the two)."""
    r, d = _models()
    keys: set[tuple[str, str]] = set()
    seen: set[type] = set()

    def walk(model):
        if model in seen:
            return
        seen.add(model)
        for name, info in model.model_fields.items():
            keys.add((model.__name__, name))
            for a in _args(info.annotation):
                for b in (a, *typing.get_args(a)):
                    for c in _args(b):
                        if _is_model(c):
                            walk(c)
    walk(r.RigConfig)
    walk(r.TruthSection)
    # RigConfig's own fields are the tables themselves, each a section of its own
    return {k for k in keys if k[0] != "RigConfig"}


def missing_key_docs() -> tuple[list[str], list[str]]:
    """(fields without a :data:`KEY_DOCS` entry, entries without a field)."""
    r, d = _models()
    have = set()
    for cls_name, name in model_keys():
        cls = getattr(r, cls_name, None) or getattr(d, cls_name)
        for c in cls.__mro__:
            if name in getattr(c, "__annotations__", {}):
                have.add(f"{c.__name__}.{name}")
                break
    return sorted(have - set(KEY_DOCS)), sorted(set(KEY_DOCS) - have)


def _cell(text: str) -> list[str]:
    return (text or " ").splitlines() or [" "]


def rig_keys_rst(design_defaults: bool = True) -> str:
    """The key reference: one list-table per table of the file."""
    missing, stale = missing_key_docs()
    if missing or stale:
        raise ValueError(f"docs/_ext/ambseal_reference.py KEY_DOCS: fields without an "
                         f"entry {missing}, entries without a field {stale}")
    lines: list[str] = []
    for sec in rig_key_sections(design_defaults):
        title = sec.table
        lines += [title, "~" * len(title), ""]
        if sec.intro:
            lines += [sec.intro, ""]
        lines += [".. list-table::", "   :header-rows: 1", "   :widths: 22 30 48",
                  "   :class: rig-keys", "",
                  "   * - key", "     - type, default", "     - unit, meaning, rule"]
        for row in sec.rows:
            unit = f"[{row.unit}] " if row.unit else ""
            more = f" Bounds: {row.bounds}." if row.bounds else ""
            rule = f" Rule: {row.rule}." if row.rule else ""
            text = f"{unit}{row.meaning}.{more}{_rst_escape(rule)}".replace("..", ".")
            lines += [f"   * - ``{row.key}``", f"     - {row.type}; {row.default}",
                      f"     - {text}"]
        lines.append("")
    return "\n".join(lines)


def page_keys(rst: str) -> set[tuple[str, str]]:
    """``(table, key)`` pairs listed by :func:`rig_keys_rst`'s text (for the tests)."""
    r, d = _models()
    table_model = {s.table: s.model.__name__ for s in _sections()}
    keys, table = set(), None
    text = rst.splitlines()
    for i, line in enumerate(text):
        if i + 1 < len(text) and set(text[i + 1]) == {"~"} and line in table_model:
            table = table_model[line]
        elif line.startswith("   * - ``") and table:
            keys.add((table, line.split("``")[1]))
    # a subclass's section lists its own keys; the inherited ones are its base's
    for sec in _sections():
        for base in sec.model.__mro__[1:]:
            if _is_model(base) and base.__name__ in _SHARED:
                keys |= {(sec.model.__name__, k) for t, k in set(keys) if t == base.__name__}
    return keys


# ---------------------------------------------------------------------------------------
# Command line
# ---------------------------------------------------------------------------------------

def _parser() -> argparse.ArgumentParser:
    from ambseal.cli import _parser as p  # the one parser `ambseal` runs

    return p()


def _subparsers(parser) -> dict[str, argparse.ArgumentParser]:
    for a in parser._actions:
        if isinstance(a, argparse._SubParsersAction):
            return dict(a.choices)
    return {}


def _help_of(parser) -> dict[str, str]:
    for a in parser._actions:
        if isinstance(a, argparse._SubParsersAction):
            return {c.dest: c.help or "" for c in a._choices_actions}
    return {}


def _option_rows(parser) -> list[tuple[str, str]]:
    rows = []
    for a in parser._actions:
        if isinstance(a, (argparse._HelpAction, argparse._SubParsersAction)):
            continue
        if a.option_strings:
            meta = ""
            if a.nargs != 0:
                meta = " " + (a.metavar or (("{" + ",".join(map(str, a.choices)) + "}")
                                            if a.choices else a.dest.upper()))
                if a.nargs == "?":
                    meta = f" [{meta.strip()}]"
            name = ", ".join(f"{o}{meta}" for o in a.option_strings)
        else:
            name = a.metavar or a.dest
            name = {"?": f"[{name}]", "+": f"{name} ...", "*": f"[{name} ...]"}.get(
                str(a.nargs), name)
        text = _rst_escape((a.help or "").replace("%(default)s", str(a.default)))
        extra = []
        if a.required and a.option_strings:
            extra.append("required")
        if a.default not in (None, False, [], argparse.SUPPRESS) \
                and not isinstance(a, argparse._VersionAction):
            extra.append(f"default: ``{a.default}``")
        if extra:
            text = f"{text} ({'; '.join(extra)})" if text else "; ".join(extra)
        rows.append((name, text))
    return rows


def _rst_escape(text: str) -> str:
    return text.replace("\\", "\\\\").replace("*", "\\*").replace("`", "\\`").replace(
        "|", "\\|").replace("_ ", "\\_ ")


def cli_rst() -> str:
    """Every command of ``ambseal`` with its usage, description and options."""
    p = _parser()
    subs, helps = _subparsers(p), _help_of(p)
    usage = " ".join(p.format_usage().replace("usage: ", "").split())
    usage = re.sub(r"\{[^}]*\} \.\.\.$", "COMMAND ...", usage)  # the command list is below
    lines = ["Global options", "~~~~~~~~~~~~~~", "", "::", ""]
    lines += ["   " + u for u in _wrap_usage(usage)] + [""]
    lines += _option_list(_option_rows(p))
    lines += ["Commands", "~~~~~~~~", ""]
    lines += [".. list-table::", "   :header-rows: 1", "   :widths: 25 75", "",
              "   * - command", "     - what it does"]
    for name in subs:
        lines += [f"   * - :ref:`ambseal {name} <cli-{name}>`",
                  f"     - {_rst_escape(helps.get(name, ''))}"]
    lines.append("")
    for name, sp in subs.items():
        title = f"ambseal {name}"
        lines += [f".. _cli-{name}:", "", title, "~" * len(title), ""]
        usage = sp.format_usage().strip().replace("usage: ", "")
        lines += ["::", ""] + ["   " + u for u in _wrap_usage(usage)] + [""]
        desc = sp.description or helps.get(name, "")
        if desc:
            lines += [_rst_escape(" ".join(desc.split())), ""]
        lines += _option_list(_option_rows(sp))
    return "\n".join(lines)


def _wrap_usage(usage: str, width: int = 72) -> list[str]:
    words, out, cur = usage.split(), [], ""
    for w in words:
        if cur and len(cur) + 1 + len(w) > width:
            out.append(cur)
            cur = "    " + w
        else:
            cur = f"{cur} {w}" if cur else w
    return out + [cur]


def _option_list(rows) -> list[str]:
    lines = []
    for name, text in rows:
        lines += [f"``{name}``", f"   {text or 'no help text'}", ""]
    return lines


def cli_commands() -> set[str]:
    """The commands of the parser (for the tests)."""
    return set(_subparsers(_parser()))


# ---------------------------------------------------------------------------------------
# JSON Schema
# ---------------------------------------------------------------------------------------

def json_schema_rst(path: Path, shown_as: str, include_as: str | None = None) -> str:
    """A JSON Schema file as a table of its properties (nested with dotted names, ``[]``
    for array items, ``<name>`` for maps; local ``$ref`` resolved) and a link to the file;
    if the file does not exist, a note saying that it is not shipped yet. ``include_as``:
    the file's path relative to the page."""
    if not path.is_file():
        return "\n".join([
            ".. note::", "",
            f"   **Not shipped yet.** The JSON Schema of ``metrics.json`` will be "
            f"``{shown_as}`` in the package; this page renders it from that file once it "
            "exists. Until then :doc:`/getting-started` lists the keys.", ""])
    schema = json.loads(path.read_text(encoding="utf-8"))
    rows: list[tuple[str, str, str]] = []

    def deref(node):
        seen = 0
        while isinstance(node, dict) and isinstance(node.get("$ref"), str) and seen < 20:
            ref, seen = node["$ref"], seen + 1
            if not ref.startswith("#/"):
                break
            target = schema
            for part in ref[2:].split("/"):
                target = target.get(part, {}) if isinstance(target, dict) else {}
            node = {**target, **{k: v for k, v in node.items() if k != "$ref"}}
        return node

    def variants(node):
        node = deref(node)
        alts = node.get("anyOf") or node.get("oneOf")
        return [deref(a) for a in alts] if isinstance(alts, list) else [node]

    def type_of(node) -> str:
        names = []
        for v in variants(node):
            t = v.get("type", "object" if "properties" in v else "")
            for one in (t if isinstance(t, list) else [t]):
                if one == "array" and isinstance(v.get("items"), dict):
                    inner = type_of(v["items"])
                    one = f"array of {inner}" if inner else "array"
                if one and one not in names:
                    names.append(one)
        return " or ".join(names)

    def walk(node, prefix, depth):
        if depth > 8:
            return
        for v in variants(node):
            req = set(v.get("required", ()))
            for k, sub in (v.get("properties") or {}).items():
                if not isinstance(sub, dict):
                    continue
                d = deref(sub)
                desc = d.get("description", "") or sub.get("description", "")
                rows.append((f"{prefix}{k}", type_of(sub) + (" (required)" if k in req
                                                             else ""), desc))
                walk(sub, f"{prefix}{k}.", depth + 1)
                for w in variants(sub):
                    if isinstance(w.get("items"), dict):
                        walk(w["items"], f"{prefix}{k}[].", depth + 1)
                    if isinstance(w.get("additionalProperties"), dict):
                        walk(w["additionalProperties"], f"{prefix}{k}.<name>.", depth + 1)
    walk(schema, "", 0)
    title = schema.get("title") or ""
    lines = [f"From ``{shown_as}``" + (f" ({title})" if title else "") + ".", ""]
    if schema.get("description"):
        lines += [_prose(schema["description"]), ""]
    lines += [".. list-table::", "   :header-rows: 1", "   :widths: 40 18 42",
              "   :class: schema-keys", "",
              "   * - key", "     - type", "     - meaning"]
    for k, t, desc in rows:
        lines += [f"   * - ``{k}``", f"     - {_rst_escape(t) or ' '}",
                  f"     - {_prose(desc) or ' '}"]
    lines += ["", f"The file itself: :download:`{path.name} <{include_as or path}>`.", ""]
    return "\n".join(lines)


def _prose(text: str) -> str:
    """A schema description on one line: its ``literals`` kept, cross-references to the
    code as literals (the page is strict, the code's private names are not in it), bars
    outside literals escaped."""
    text = re.sub(r":[a-z]+:`~?([^`]+)`", r"``\1``", " ".join(str(text).split()))
    parts = re.split(r"(``.+?``)", text)
    return "".join(p if k % 2 else p.replace("|", "\\|") for k, p in enumerate(parts))


__all__ = ["KEY_DOCS", "cli_commands", "cli_rst", "json_schema_rst", "missing_key_docs",
           "model_keys", "page_keys", "rig_key_sections", "rig_keys_rst"]
