"""The unbalance force rejection of a controller: its generalised notch's gain table over
the speed range, on the full-order plant (Herzog et al., IEEE TCST 4(5), 1996;
:mod:`ambseal.machine.synchronous_notch`).

At each speed Ω of a grid over the rig's continuous speed range the gain is the inverse of
the output sensitivity, ``T(Ω) = S_o⁻¹ = I + G K``, of the loop the controller runs in:

- continuous: ``G(jΩ)`` the full-order plant at that speed (gyroscopics, seals at the
  rig's operating pressure) with the hold-and-computation-delay lag the judgement puts in
  every continuous loop (:func:`ambseal.robust.delay.loop_delay`), ``K(jΩ)`` the designed
  controller (frozen at Ω when it is scheduled);
- as it runs: ``G_d(e^{jΩT_s})`` the plant sampled by a zero-order hold, ``K_d(e^{jΩT_s})``
  the discrete controller with its computation delay.

Rules, each a parameter:

- the speeds: ``[operating] speed_range_hz`` (the minimum to the maximum continuous
  speed), else the operating speed alone. The table is interpolated linearly between its
  speeds, and the first-order poles stay in the left half-plane while the interpolated
  gain's phase error stays below 90° (the judgement checks every condition). Its speeds
  are found by bisection: from the range's ends, an interval is split at a speed that is
  evaluated and kept, and both parts are split again while, there, the interpolated gain
  T̃ misses the evaluated T by ‖(T̃ − T) T⁻¹‖₂ > :data:`INTERP_RTOL`, in the continuous
  or in the sampled loop. The split is the dyadic speed f_top·k/2^j of the coarsest
  level inside the interval (f_top the range's top; the midpoint where its ends are
  neighbouring such speeds): each controller's table starts at its own switch-on speed, and splits
  that do not depend on that start let the tables of one rig share their speeds and so
  their plants (an ``expm`` each, 0.3 s at 840 states). The notch's first-order poles
  are placed by the eigenvalues of T̃ T⁻¹ = I + E, which lie within ‖E‖ of 1: at 0.25
  each pole keeps at least 75 % of its distance ε/2 from the axis, and the notch settles
  in at most 4/3 of its designed time. An interval no wider than that distance (in Hz:
  ``rate_fraction``/2 of its lower end) is not split: the notch does not resolve the gain
  finer than its own bandwidth. Where ``[design.rejection] points`` is given, that many
  evenly spaced speeds instead (16 evenly spaced speeds on the turboexpander example put
  ‖E‖ at 0.31 between two of them; the bisection 15 speeds, 0.07 at most on 257 of
  them);
- on from the lowest of them: below the minimum continuous speed the rotor passes its
  critical speeds on the feedback alone, and at standstill a notch at 0 Hz would take the
  controller's static stiffness — unless the run passes a lower start (``speeds_hz``):
  where the controller alone saturates the amplifier through a critical below the
  continuous speeds (:func:`ambseal.analysis.amplifier.switch_on_hz`);
- ε = :data:`RATE_FRACTION` × Ω: a narrow notch, its poles ε/2 from the imaginary axis,
  settling (time constant 2/ε) in 1/(π·0.05) ≈ 6 revolutions at every speed — slow
  against the rotation it tracks, as the first-order placement needs.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from ambseal.errors import ConfigError
from ambseal.lti import ArrayMemo, freqresp_at, sampled_response_at
from ambseal.machine import (
    NotchedController,
    NotchedDigital,
    SynchronousNotch,
    controller_as_runs,
    frozen,
)
from ambseal.model import build_plant
from ambseal.robust import loop_delay

__all__ = ["SynchronousRejection", "design_rejection", "INTERP_RTOL", "RATE_FRACTION"]

#: ‖(T̃ − T) T⁻¹‖₂ at an interval's midpoint, the interpolated gain T̃ against the
#: evaluated T, above which the interval is halved (module docstring).
INTERP_RTOL = 0.25
#: ε as a fraction of the speed Ω, both in rad/s (module docstring).
RATE_FRACTION = 0.05


@dataclass(frozen=True, eq=False)
class SynchronousRejection:
    """A controller with its unbalance force rejection (module docstring).

    Attributes
    ----------
    controller : NotchedController
        The designed controller with its continuous notch.
    digital : NotchedDigital or None
        The digital controller with its discrete notch, as it runs; None when no digital
        controller was given.
    pressure_bar : float
        The pressure drop the table was made at.
    """

    controller: NotchedController
    digital: NotchedDigital | None
    pressure_bar: float

    @property
    def speeds_hz(self) -> np.ndarray:
        """The speeds of the gain table (Hz), shape (S,)."""
        return self.controller.notch.speeds_rad_s / (2 * math.pi)

    def to_dict(self) -> dict:
        """JSON-ready description: the table's speeds (Hz), ε/Ω, the speed it is on from
        (Hz) and the pressure drop (bar)."""
        n = self.controller.notch
        return {"table_speeds_hz": [float(f) for f in self.speeds_hz],
                "rate_fraction": float(n.rate_fraction),
                "on_from_hz": float(n.on_rad_s / (2 * math.pi)),
                "pressure_bar": float(self.pressure_bar)}


def design_rejection(cfg, controller, digital=None, *, pressure_bar: float | None = None,
                     speeds_hz: tuple[float, float] | None = None,
                     points: int | None = None,
                     rate_fraction: float = RATE_FRACTION) -> SynchronousRejection:
    """A controller's unbalance force rejection over the speed range (module docstring).

    Parameters
    ----------
    cfg : RigConfig
        The rig.
    controller : control.StateSpace or ScheduledController
        The designed controller, ``i = −K y`` (scheduled on speed, or fixed).
    digital : DigitalController or ScheduledDigital, optional
        The controller as it runs; its notch is designed on the sampled loop.
    pressure_bar : float, optional
        The seals' pressure drop (default ``[operating] pressure_bar``).
    speeds_hz : (float, float), optional
        The speed range (Hz), default ``[operating]``'s continuous speeds.
    points : int, optional
        That many evenly spaced speeds over a range (≥ 2); default: the speeds the
        bisection of the module docstring finds.
    rate_fraction : float
        ε/Ω, in (0, 0.5).

    Returns
    -------
    SynchronousRejection

    Raises
    ------
    ConfigError
        A rig that does not rotate (lowest speed 0), fewer than 2 points, or a fraction
        outside (0, 0.5).
    """
    lo, hi = (cfg.operating.continuous_hz if speeds_hz is None
              else (float(speeds_hz[0]), float(speeds_hz[1])))
    if not lo > 0 or hi < lo:
        raise ConfigError("synchronous rejection: the rotor must turn — [operating] "
                          f"speed_rpm or speed_range_hz above 0 Hz (got {lo:g}–{hi:g} Hz)")
    if (points is not None and int(points) < 2) or not 0 < rate_fraction < 0.5:
        raise ConfigError("synchronous rejection: expected points ≥ 2 and a rate fraction "
                          "in (0, 0.5)")
    p = cfg.operating.pressure_bar if pressure_bar is None else float(pressure_bar)
    fs, nd = cfg.controller.sample_rate_hz, cfg.controller.delay_samples
    lag = loop_delay(fs, nd).system
    names: dict = {}
    rig, sampled = cfg.digest(), digital is not None

    def gains_at(f: float) -> dict:
        """T = I + G K at speed f (Hz), continuous ("c") and as it runs ("d")."""
        w = 2 * math.pi * f
        outputs, inputs, Hc, Hd = _PLANT_AT.get_digested(
            rig, (p, f, fs, nd, sampled),
            lambda: _plant_at(cfg, p, f, lag, fs if sampled else None))
        loops = [("c", frozen(controller, w), 1j * w, Hc)]
        if sampled:
            loops.append(("d", controller_as_runs(digital, w), np.exp(1j * w / fs), Hd))
        out = {}
        for key, Kx, point, H in loops:
            rows = [outputs.index(n) for n in Kx.input_labels]
            cols = [inputs.index(n) for n in Kx.output_labels]
            G = H[np.ix_(rows, cols)]
            out[key] = np.eye(len(rows)) + G @ freqresp_at(Kx, np.array([point]))[0]
            names[key] = tuple(Kx.input_labels), float(Kx.dt or 0.0)
        return out

    if hi == lo:
        table = {lo: gains_at(lo)}
    elif points is not None:
        table = {float(f): gains_at(float(f)) for f in np.linspace(lo, hi, int(points))}
    else:
        table = _bisected(lo, hi, gains_at, rate_fraction)
    grid = np.array(sorted(table))
    w_grid = 2 * math.pi * grid

    def notch(key):
        T = np.array([table[f][key] for f in grid])
        inputs, dt = names[key]
        return SynchronousNotch(w_grid, T.real, T.imag, rate_fraction, w_grid[0], inputs, dt)

    return SynchronousRejection(
        controller=NotchedController(controller, notch("c")),
        digital=None if digital is None else NotchedDigital(digital, notch("d")),
        pressure_bar=p)


def _bisected(lo: float, hi: float, gains_at, rate_fraction: float) -> dict:
    """The table's gains by speed (Hz) over ``lo``–``hi``, its speeds found by bisection
    on the dyadic speeds of ``hi`` (:func:`dyadic_split`, module docstring):
    ``gains_at(f)`` gives each loop's T at f."""
    table = {lo: gains_at(lo), hi: gains_at(hi)}
    todo = [(lo, hi)]
    while todo:
        a, b = todo.pop()
        if b - a <= 0.5 * rate_fraction * a:  # within the notch's bandwidth
            continue
        m = dyadic_split(a, b, hi)
        table[m] = gains_at(m)
        t = (m - a) / (b - a)
        if max(np.linalg.norm(np.linalg.solve(
                T.T, ((1 - t) * table[a][k] + t * table[b][k] - T).T), 2) > INTERP_RTOL
               for k, T in table[m].items()):
            todo += [(a, m), (m, b)]
    return table


def dyadic_split(a: float, b: float, top: float) -> float:
    """The speed ``top·k/2^j`` of the smallest ``j`` strictly between ``a`` and ``b``
    (0 ≤ a < b ≤ top): unique (of two neighbours at level j one is at level j − 1), the
    midpoint where ``a`` and ``b`` are neighbouring dyadic speeds of ``top``. Tables with the
    same top speed split every interval they share at the same speed, whatever speed each
    starts from, so their plants are shared (:data:`_PLANT_AT`)."""
    j = 0
    while True:  # ends: at the level whose step is below b − a, the next speed is inside
        k = math.floor(math.ldexp(a / top, j)) + 1
        m = math.ldexp(top * k, -j)
        if m <= a:  # a is that level's speed, and a/top was rounded below it
            m = math.ldexp(top * (k + 1), -j)
        if m < b:
            return m
        j += 1


#: The plant's responses at the last tables' speeds, by rig and speed: every controller's
#: notch is designed on the same plants where their speeds coincide (at 840 states each
#: costs an expm of the plant, about 0.3 s)
_PLANT_AT = ArrayMemo(keep=256)


def _plant_at(cfg, p: float, f: float, lag: Any, fs: float | None) -> tuple:
    """The full-order plant at speed ``f`` (Hz) and pressure drop ``p`` (bar) at its
    synchronous frequency: its outputs' and inputs' names, ``G(jΩ)`` with the delay lag on
    the current inputs, and ``G_d(e^{jΩ/fs})`` sampled by a zero-order hold (None without
    ``fs``)."""
    w = 2 * math.pi * f
    plant = build_plant(cfg, pressure_bar=p, speed_rpm=60.0 * f)
    P = plant.to_statespace()
    cur = plant.current_inputs()
    rest = [j for j in range(P.ninputs) if j not in cur]
    Hc = freqresp_at(P, np.array([1j * w]))[0] * _lag_on(lag, 1j * w, P.ninputs, cur)
    Hd = None if fs is None else sampled_response_at(P, 1.0 / fs, np.array([w]),
                                                      groups=(cur, rest))[0]
    return list(P.output_labels), list(P.input_labels), Hc, Hd


def _lag_on(lag: Any, s: complex, n_inputs: int, cur) -> np.ndarray:
    """A row of ones with the delay lag's ``lag(s)`` on the control inputs ``cur``."""
    row = np.ones(n_inputs, dtype=complex)
    row[list(cur)] = freqresp_at(lag, np.array([s]))[0, 0, 0]
    return row
