"""The drop run: its event and settings taken as :func:`simulate_drop`'s keywords, its
dynamics integrated and collected (the package's docstring, :mod:`ambseal.analysis.drop`).
"""

from __future__ import annotations

from ambseal.analysis.drop._event import DropEvent
from ambseal.analysis.drop._integrate import CRUSHED, integrate
from ambseal.analysis.drop._model import DropModel, drop_model
from ambseal.analysis.drop._result import DropResult, collect
from ambseal.analysis.drop._rhs import DropDynamics
from ambseal.analysis.drop_loop import AmbLoop, amb_loop

__all__ = ["CRUSHED", "run_drop", "simulate_drop"]


def simulate_drop(cfg, *, speed_rpm: float = 0.0, duration_s: float = 0.5,
                  samples: int = 4001, modes_hz: float | None = None, rtol: float = 1e-8,
                  method: str = "DOP853", model: DropModel | None = None,
                  coast_down: bool = False, drag_torque: float = 0.0,
                  initial: tuple | None = None, unbalance_kgm: float = 0.0,
                  loop: AmbLoop | None = None, loop_state=None, failed=None,
                  overload: tuple | None = None, supports: bool = True,
                  pressure_bar: float | None = None, axial_thrust: float | None = None,
                  progress=None) -> DropResult:
    """Drop the rotor of ``cfg`` onto its touchdown bearings (the package's docstring).

    Parameters
    ----------
    cfg : RigConfig
        With ``[[amb]]`` and ``[[touchdown]]`` tables.
    speed_rpm : float, optional
        Spin speed (rpm) at the drop: held by the drive, or the start of a coast-down;
        negative, the rotor turns the other way (about −z), as ``[operating] speed_rpm``.
    duration_s : float, optional
        Simulated time after the AMBs let go (s), > 0.
    samples : int, optional
        Output samples, evenly spaced over the drop.
    modes_hz : float, optional
        Modes kept (:func:`drop_model`).
    rtol : float, optional
        ``solve_ivp``'s relative tolerance (its absolute one: ``rtol`` times the smallest
        clearance, and that over 1 ms for the speeds).
    method : str, optional
        ``solve_ivp``'s method.
    model : DropModel, optional
        Built by :func:`drop_model` if omitted.
    coast_down : bool, optional
        The drive lets go too: the spin slows under the rings' friction at the journal
        radii and ``drag_torque``, I_p Ω̇ = −Σ F_t R_j − T_d·tanh(Ω/ω_d) (ω_d = 0.1 rad/s),
        the gyroscopic moments at the instantaneous speed.
    drag_torque : float, optional
        The process and windage torque T_d against the spin (N·m), ≥ 0.
    initial : tuple of two ndarray, shape (n_dof,), optional
        The rotor's nodal displacement (m, rad) and velocity (m/s, rad/s) in the drop
        model's DOFs (:attr:`DropModel.z`) when the AMBs let go, projected on the modes
        kept (:attr:`DropModel.projector`); default the levitated equilibrium at rest.
    unbalance_kgm : float, optional
        A static unbalance U (kg·m, ≥ 0) at the node nearest the centre of mass
        (:attr:`DropModel.cg_rows`): the force U·Ω²·(cos θ, sin θ) turning with the spin's
        angle θ (θ = Ω t held; ∫Ω dt coasting, the spin's own slowing by it left out). Its
        work is counted as work from outside (:attr:`DropResult.work`).
    loop : AmbLoop, optional
        The AMB loop (:func:`ambseal.analysis.drop_loop.amb_loop`); default one without a
        controller where every axis fails, else the reference PID's at ``speed_rpm``. A
        digital controller (``loop.sampled``) is updated at t = 0, T_s, 2 T_s, … (each
        sample ends an integration segment) and its output held between.
    loop_state : ndarray, shape (loop.n_states + loop.n_sampled,), optional
        The loop's states at t = 0 (:func:`ambseal.analysis.drop_levitated.
        levitated_state`); default zero, the loop at rest in the levitated equilibrium.
    failed : sequence of str, optional
        The channels (``loop.names``) whose power is lost at t = 0; default every one
        (the AMBs let go). The others run on under the loop's controller.
    overload : tuple (float, array_like of 2 float), optional
        A step force from t = 0: its position z (m; at the nearest node) and its x, y
        components (N). Its work is counted as work from outside.
    supports : bool, optional
        The seals' and springs' forces on the rotor (:func:`support_matrices`: at the
        drop's speed and pressure, held through it); their work is counted as work from
        outside.
    pressure_bar : float, optional
        The pressure drop across the seals (bar); ``[operating] pressure_bar`` if omitted.
    axial_thrust : float, optional
        The residual thrust (N, +z towards the rotor's far end) on the rotor once the
        thrust bearing lets go, with every AMB axis (``failed`` all of them); default
        ``[drop] axial_thrust``. The rotor then moves axially as a rigid body onto the
        planes with an ``axial_clearance`` (the package's docstring); otherwise the thrust bearing
        holds it.
    progress : callable, optional
        ``progress(t_s)`` after each segment.

    Returns
    -------
    DropResult

    Raises
    ------
    ConfigError
        As :func:`drop_model`; a duration or sample count out of range; an ``initial``
        or ``loop_state`` of the wrong shape or not finite; a negative or non-finite
        unbalance; a ``failed`` channel the rig does not have, or axes left running
        without a controller; an overload off the rotor or not finite; a thrust not
        finite; a plane pressed deeper than :data:`CRUSHED` of its journal's radius
        (the package's docstring).
    """
    event = DropEvent(speed_rpm=speed_rpm, duration_s=duration_s, samples=samples,
                      modes_hz=modes_hz, rtol=rtol, method=method, coast_down=coast_down,
                      drag_torque=drag_torque, initial=initial, unbalance_kgm=unbalance_kgm,
                      loop_state=loop_state, failed=None if failed is None else tuple(failed),
                      overload=overload, supports=supports, pressure_bar=pressure_bar,
                      axial_thrust=axial_thrust)
    return run_drop(cfg, event, model=model, loop=loop, progress=progress)


def run_drop(cfg, event: DropEvent, *, model: DropModel | None = None,
             loop: AmbLoop | None = None, progress=None) -> DropResult:
    """Drop the rotor of ``cfg`` by ``event`` (:func:`simulate_drop`, whose keywords are
    the event's fields): its state at the drop, integrated from event to event, and its
    result.

    Parameters
    ----------
    cfg : RigConfig
        With ``[[amb]]`` and ``[[touchdown]]`` tables.
    event : DropEvent
        The event and its settings.
    model : DropModel, optional
        Built by :func:`drop_model` at ``event.modes_hz`` if omitted.
    loop : AmbLoop, optional
        As :func:`simulate_drop`'s.
    progress : callable, optional
        ``progress(t_s)`` after each segment.

    Returns
    -------
    DropResult

    Raises
    ------
    ConfigError
        As :func:`simulate_drop`.
    """
    dm = model or drop_model(cfg, event.modes_hz)
    if loop is None:
        loop = amb_loop(cfg, dm, event.speed_rpm,
                        None if event.failed is not None else "none")
    dyn = DropDynamics(cfg, dm, loop, event)
    run = integrate(dyn, dyn.start(), progress)
    return collect(cfg, dyn, run)
