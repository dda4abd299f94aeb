"""The rotor drop: the FE rotor released by its AMBs onto its touchdown bearings.

ISO 14839-5:2022 asks for the analysis of the events that land a rotor on its touch-down
bearings. Here the events are the loss of AMB axes — every one, or some while the loop
runs the others — and a step force, from the levitated state at the operating speed: the
AMB loop runs inside the drop (:mod:`ambseal.analysis.drop_loop`: each axis's force
linearised about the levitated equilibrium, its current reference clipped at its limit,
a lost axis's force decaying with the square of its coil's current, e^{−2t R/L}), and the
rotor falls through the clearance onto the rings. Gravity acts as the machine stands
(``[machine] orientation``, :func:`ambseal.model.gravity_vector`): its part across the
axis loads the rotor's modes (:func:`ambseal.model.gravity_load`; none for a vertical
rotor), held in the levitated state by the AMBs as the statics share it
(:func:`ambseal.analysis.statics.support_forces`), and its part along the axis, the axial
weight m·g_z, falls the rotor axially once the thrust bearing lets go. So a standing
rotor lands on its axial touchdown face, and only its unbalance, its whirl and the face's
friction bring it to its radial rings. Where every axis is lost the thrust
bearing lets go too: the rotor, rigid along its axis (its axial modes lie far above the
drop's), moves under the residual thrust (``[drop] axial_thrust``) and its axial weight
onto the planes with an ``axial_clearance``, m z̈ = F_a + m·g_z − Σ sign(z)·N_a(|z| − c_a),
N_a the plane's contact law (its own K with ``axial_contact_stiffness``; a plane stops the
rotor either way) damped as the radial one by the onset's axial speed, at least that of a
fall through c_a under F_a + m·g_z or standard gravity, whichever is larger; its
friction μN_a·tanh(v_s/v_r) at the ring's bore radius R_r against the slip
(Ω − ω_r)·R_r brakes the spin and spins the ring up. Each plane's friction heat
∫F_t v_s dt, radial and axial, is kept.

The rotor: the free FE rotor of the rig (:func:`ambseal.model.assemble_rotor`, a node at
every touchdown plane) in the mass-normalised real modes of its free–free
non-rotating form up to ``modes_hz`` (rigid-body modes included), M q̈ + (C + ΩG) q̇ + K q
= f at the spin speed Ω, held by the drive or coasting down under the rings' friction
and a drag torque (``coast_down``), the gyroscopic moments at the instantaneous speed;
the seals' and springs' forces (:func:`support_matrices`) at the drop's speed and pressure
drop.
The default ``modes_hz`` is :data:`MODES_PER_CONTACT` (4) times the contact's own
frequency 1/t_c (:func:`ambseal.model.hertz_impact`) for a fall through the smallest
clearance, the shortest over the planes, each an impact of the rotor's mass shared among
the touchdown planes on the ring's support mass where it has one (their reduced mass: a
light ring on a soft mount makes the contact far shorter than the rotor's share does).
Twice as many hertz moves the first impact's peak force by under 2 % on the example rigs
(benchmarks/README.md); the later impacts of a drop depend on its whole history, and
their peaks do not converge as the first does.

Each touchdown plane (:class:`ambseal.config.Touchdown`; :class:`ambseal.model.
ContactLaw`): the journal's centre r relative to the ring's (the ring on its support
where ``support_mass`` is given), penetration δ = |r| − c, normal n = r/|r|, tangent
t = ẑ × n. The normal force N on δ and δ̇ with the damping of the impact's normal speed
v₀ at the contact's onset, at least the free-fall speed over the clearance √(2 g c) under
standard gravity g, however the machine stands (a floor on v₀, not the rotor's own fall:
a standing rotor does not fall radially, yet touches its rings through its whirl): a
slower onset — a grazing contact, or the ring's support meeting the journal — is damped
as a fall through the clearance would be, not by the D ∝ 1/v₀ a near-zero v₀ would give
(which would put a damping force many times the elastic one into a slow contact);
friction μN·tanh(v_s/v_r) against
the slip v_s = t·ṙ + Ω R_j − ω_r R_r of the journal's surface on the ring's (R_j the
shaft's outer radius there, R_r = R_j + c); a ring with ``race_inertia`` J spins up,
J ω̇_r = F_t R_r − T_d·tanh(ω_r/ω_d), ω_d = v_r/R_r; without it the ring stands still.

Integration: scipy's ``solve_ivp`` from event to event (each plane's contact onset and
end are events that end a segment: the onset sets v₀), to relative tolerance ``rtol``,
by DOP853 (explicit: an impact's and the flexible modes' oscillations at the least cost)
until it crawls: a ring rolling on the journal without slip meets the friction's
regularised slope μN/v_r on the ring's small inertia, a time constant of nanoseconds, and
where a segment advances less than one period of the highest mode kept per
:data:`CYCLE_EVALUATIONS` evaluations (judged past :data:`CRAWL_EVALUATIONS`) the drop
goes on with LSODA, which switches to its stiff method there. A plane pressed deeper
than :data:`CRUSHED` (1 %) of its journal's radius (radially, or axially on a stop) ends
the drop with a refusal: the contact laws are those of a contact small against the
bodies (a drop presses a few micrometres), and a load that crushes the rings — a seal
surge of thousands of bar, say, whose cross-coupled stiffness drives a whirl growing at
thousands per second into the rings with meganewtons — has no answer in them (and such a
contact's friction makes the drop crawl even with LSODA: the test rig's seal surging to
1e4 bar had not dropped 10 ms in 200 s). On the expander-generator
example DOP853 takes a 1 s drop in 40 s and LSODA in 190 s; on the flywheel rolling
on its rings DOP853 does not finish 0.1 s in ten minutes and LSODA takes 11 s
(benchmarks/README.md). The switch counts evaluations, not time: the same drop switches
at the same point on every machine.

The package: :mod:`~ambseal.analysis.drop._model` (the modal rotor, its contacts and
supports), :mod:`~ambseal.analysis.drop._event` (the event and its settings, one object),
:mod:`~ambseal.analysis.drop._state` (the state's layout), :mod:`~ambseal.analysis.drop.
_rhs` (the right-hand side, one method per force), :mod:`~ambseal.analysis.drop.
_integrate` (the events and the integrator's hand-over), :mod:`~ambseal.analysis.drop.
_result` (the result) and :mod:`~ambseal.analysis.drop._verdict` (its judgement).
"""

from __future__ import annotations

from scipy.constants import g as GRAVITY

from ambseal.analysis.drop._event import DropEvent
from ambseal.analysis.drop._integrate import (
    CRAWL_EVALUATIONS,
    CRUSHED,
    CYCLE_EVALUATIONS,
    EXPLICIT,
    MAX_SEGMENTS,
    PEAK_POINTS,
    STIFF_METHOD,
)
from ambseal.analysis.drop._model import (
    MODES_PER_CONTACT,
    DropModel,
    drop_model,
    journal_radius,
    support_matrices,
)
from ambseal.analysis.drop._result import BOUNCING_BELOW, DropResult
from ambseal.analysis.drop._simulate import run_drop, simulate_drop
from ambseal.analysis.drop._verdict import drop_verdict

__all__ = ["GRAVITY", "DropEvent", "DropModel", "DropResult", "drop_model", "simulate_drop",
           "run_drop", "journal_radius", "drop_verdict", "support_matrices",
           "BOUNCING_BELOW", "CRAWL_EVALUATIONS", "CRUSHED", "CYCLE_EVALUATIONS", "EXPLICIT",
           "MAX_SEGMENTS", "MODES_PER_CONTACT", "PEAK_POINTS", "STIFF_METHOD"]
