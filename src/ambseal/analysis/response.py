"""Closed-loop time response to the thesis's current impulse (input disturbance).

P5 §5.1 (Fig. 14) and §3.3: a rectangular current disturbance of 0.05 A lasting 10 ms is added
to the controller output (current set point) on ``A_ζ`` and ``B_η`` at once; the responses are
the rotor displacements at the sensors and the controller currents ("control action").

The loop ``u = −K y + d`` is closed by :func:`ambseal.analysis.loops.closed_loop` and simulated
**exactly** for the piecewise-constant disturbance: the closed loop is discretised once with a
zero-order hold and run by :func:`ambseal.lti.discrete.simulate_lti` (``zoh`` of the single
input column, Franklin, Powell & Workman, *Digital Control of Dynamic Systems*, §6.3), then
``x[k+1] = A_d x[k] + b_d d[k]``.

Settling time (2 % criterion): a stable loop's response to a pulse of finite duration decays to
its final value 0, so the settling time is the last time any displacement leaves the band
``|y| ≤ 0.02 · peak`` (``peak`` = largest displacement over all channels and times), measured
from the impulse start; the crossing is linearly interpolated between samples. It is ``inf``
(and ``settled`` is False) if the response is outside the band at the end of the window, and
``inf`` for an unstable loop (flagged by ``stable``; no error is raised);
:attr:`ImpulseResponse.settling_note` then says which, with the window and the loop's slowest
pole.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any, Sequence

import numpy as np

from ambseal.errors import ModelError
from ambseal.lti import json_float, simulate_lti, zoh
from ambseal.machine import ClosedLoop, closed_loop

__all__ = ["ImpulseResponse", "impulse_response", "impulse_response_of", "settling_time"]

_BLOWUP = 1e150  # an unstable loop's response is cut (NaN) beyond this output


@dataclass(frozen=True, eq=False)
class ImpulseResponse:
    """Closed-loop response to a rectangular current disturbance (P5 §5.1, Fig. 14).

    Attributes
    ----------
    time_s : ndarray, shape (n_t,)
        Time (s), from 0 with step ``dt_s``.
    displacement_m : ndarray, shape (n_t, ny)
        Sensor displacements (m); ``nan`` after an unstable response blew up.
    current_a : ndarray, shape (n_t, nu)
        Controller output ``−K y`` (A), the control action of P5 Fig. 14.
    disturbance_a : ndarray, shape (n_t, nu)
        The injected current disturbance ``d`` (A); the plant current is ``current_a + d``.
    output_names, input_names : tuple of str
    peak_displacement_um : float
        ``max |y|`` over channels and time (µm).
    peak_current_a : float
        ``max |−K y|`` over channels and time (A).
    settling_time_s : float
        2 % settling time from the impulse start (s), ``inf`` if unstable or not settled.
    settling_per_channel_s : tuple of (str, float)
        Per displacement channel, each against 2 % of its own peak (``0.0`` for a channel that
        never moves).
    settled : bool
        Whether ``settling_time_s`` is finite.
    stable : bool
        Closed-loop stability (all poles in the open left half plane).
    max_real_pole : float
        Largest real part of the closed-loop poles (1/s).
    amplitude_a, duration_s, t_impulse_s, dt_s : float
        Disturbance amplitude (A), duration (s), start (s) and the simulation step (s).
    channels : tuple of str
        Disturbed plant inputs.
    """

    time_s: np.ndarray
    displacement_m: np.ndarray
    current_a: np.ndarray
    disturbance_a: np.ndarray
    output_names: tuple[str, ...]
    input_names: tuple[str, ...]
    peak_displacement_um: float
    peak_current_a: float
    settling_time_s: float
    settling_per_channel_s: tuple[tuple[str, float], ...]
    settled: bool
    stable: bool
    max_real_pole: float
    amplitude_a: float
    duration_s: float
    t_impulse_s: float
    dt_s: float
    channels: tuple[str, ...]

    @property
    def time_ms(self) -> np.ndarray:
        """Time (ms), shape (n_t,)."""
        return self.time_s * 1e3

    @property
    def displacement_um(self) -> np.ndarray:
        """Displacements (µm), shape (n_t, ny)."""
        return self.displacement_m * 1e6

    @property
    def settling_note(self) -> str | None:
        """Why ``settling_time_s`` is not finite, in words (None where it is): a stable
        loop's response still outside the 2 % band at the end of the simulated window,
        with the window and the loop's slowest pole σ, which decays to 2 % in ln 50/|σ| —
        beyond the window when that is longer than it; or an unstable loop."""
        if self.settled:
            return None
        if not self.stable:
            return "no settling: the loop is unstable"
        window = float(self.time_s[-1]) - self.t_impulse_s
        text = f"not settled within the {_duration(window)} simulated after the impulse"
        sigma = float(self.max_real_pole)
        if not sigma < 0:
            return text
        decay = math.log(50.0) / -sigma  # e^{σ t} = 2 %
        pole = (f"its slowest pole, at {sigma:.3g} rad/s".replace("-", "−")
                + f", decays to 2 % in {_duration(decay)}")
        return f"{text}: {pole}, beyond that window" if decay > window else f"{text} ({pole})"

    def to_dict(self) -> dict:
        """JSON-safe scalars (no time series); ``inf`` settling is the string ``"inf"``."""
        return {
            "peak_displacement_um": json_float(self.peak_displacement_um),
            "peak_current_a": json_float(self.peak_current_a),
            "settling_time_s": json_float(self.settling_time_s),
            "settling_per_channel_s": {ch: json_float(t) for ch, t in self.settling_per_channel_s},
            "settled": bool(self.settled),
            "stable": bool(self.stable),
            "max_real_pole": json_float(self.max_real_pole),
            "amplitude_a": json_float(self.amplitude_a),
            "duration_s": json_float(self.duration_s),
            "t_impulse_s": json_float(self.t_impulse_s),
            "dt_s": json_float(self.dt_s),
            "channels": list(self.channels),
            "output_names": list(self.output_names),
        }


def settling_time(t: np.ndarray, y: np.ndarray, *, band: float = 0.02, t0: float = 0.0, final: float = 0.0,
                  peak: float | None = None) -> float:
    """Last time ``y`` leaves the band ``|y − final| ≤ band · peak``, measured from ``t0``.

    Parameters
    ----------
    t : ndarray, shape (n_t,)
        Time (s), increasing.
    y : ndarray, shape (n_t,) or (n_t, p)
        Response; with several columns the band must hold for all of them.
    band : float
        Relative band (0.02 for the 2 % criterion).
    t0 : float
        Reference time (s), e.g. the impulse start.
    final : float
        Final value (0 for a stable loop after a pulse).
    peak : float, optional
        Reference amplitude; default ``max |y − final|``.

    Returns
    -------
    float
        Settling time (s) with the exit crossing linearly interpolated between samples;
        ``0.0`` if ``y`` never leaves the band; ``inf`` if it is outside at the last sample
        or non-finite.
    """
    e = np.abs(np.asarray(y, dtype=float) - final)
    if e.ndim == 1:
        e = e[:, None]
    if not np.all(np.isfinite(e)):
        return float("inf")
    ref = float(np.max(e)) if peak is None else float(peak)
    if ref <= 0:
        return 0.0
    lim = band * ref
    excess = np.max(e, axis=1) - lim
    out = np.flatnonzero(excess > 0)
    if out.size == 0:
        return 0.0
    j = int(out[-1])
    if j == t.size - 1:
        return float("inf")
    # linear interpolation of the crossing between samples j (outside) and j+1 (inside)
    a, b = excess[j], excess[j + 1]
    frac = a / (a - b) if a != b else 1.0
    return float(t[j] + frac * (t[j + 1] - t[j]) - t0)


def impulse_response(G: Any, K: Any, **kwargs) -> ImpulseResponse:
    """Response of the loop ``u = −K y + d`` to the thesis's current impulse (P5 §5.1):
    :func:`impulse_response_of` of ``closed_loop(G, K)``.

    Parameters
    ----------
    G, K : control.StateSpace
        Plant (A → m) and controller (m → A), negative feedback.
    **kwargs
        ``channels``, ``amplitude_a``, ``duration_s``, ``t_impulse_s``, ``t_end_s``,
        ``dt_s``, ``band`` as for :func:`impulse_response_of`.

    Returns
    -------
    ImpulseResponse
        Displacements (m) and currents (A) over time, peaks, settling times and the loop's
        stability (:func:`impulse_response_of`).

    Raises
    ------
    ModelError
        As :func:`impulse_response_of`, or if ``G`` and ``K`` do not fit together.
    """
    return impulse_response_of(closed_loop(G, K), **kwargs)


def _duration(t_s: float) -> str:
    """A duration for people: ``"30 ms"``, ``"21 s"``."""
    return f"{t_s * 1e3:.3g} ms" if t_s < 1.0 else f"{t_s:.3g} s"


def _steps(x: float, dt: float, what: str) -> int:
    k = int(round(x / dt))
    if abs(k * dt - x) > 1e-9 * max(dt, abs(x)) + 1e-15:
        raise ModelError(f"impulse_response: {what}={x!r} s is not a multiple of dt_s={dt!r} s")
    return k


def impulse_response_of(
    loop: ClosedLoop,
    *,
    channels: Sequence[str | int] = ("i_A_zeta", "i_B_eta"),
    amplitude_a: float = 0.05,
    duration_s: float = 0.01,
    t_impulse_s: float = 0.0,
    t_end_s: float = 0.2,
    dt_s: float = 1e-5,
    band: float = 0.02,
) -> ImpulseResponse:
    """Response of a closed loop (:func:`~ambseal.analysis.loops.closed_loop`) to the
    thesis's current impulse (P5 §5.1).

    Parameters
    ----------
    loop : ClosedLoop
        The loop ``u = −K y + d`` of a plant (A → m) and a controller (m → A).
    channels : sequence of str or int
        Plant inputs receiving the disturbance (names of the plant's inputs, or indices).
        Default ``("i_A_zeta", "i_B_eta")`` as in P5 Fig. 14/15.
    amplitude_a : float
        Disturbance amplitude (A), 0.05 in the thesis.
    duration_s : float
        Pulse length (s), 0.01 in the thesis; must be a multiple of ``dt_s``.
    t_impulse_s : float
        Pulse start (s); a multiple of ``dt_s``. The thesis plots start it at 0.05 s.
    t_end_s : float
        End of the simulated window (s).
    dt_s : float
        Step of the exact ZOH discretisation (s); 1e-5 resolves modes up to ~10 kHz. A
        discrete loop (``loop.dt > 0``, e.g. the sampled plant with the controller that
        runs) is stepped at its own sample time, which ``dt_s`` must equal.
    band : float
        Relative settling band (0.02).

    Returns
    -------
    ImpulseResponse

    Raises
    ------
    ModelError
        If a channel is unknown, or the times are not multiples of ``dt_s`` or do not fit
        in the window.
    """
    if not (dt_s > 0 and duration_s > 0 and t_end_s > 0 and t_impulse_s >= 0):
        raise ModelError("impulse_response: dt_s, duration_s, t_end_s must be > 0 and t_impulse_s >= 0")
    if loop.dt and abs(dt_s - loop.dt) > 1e-12 * loop.dt:
        raise ModelError(f"impulse_response: dt_s={dt_s!r} s, but the discrete loop runs at "
                         f"{loop.dt!r} s")
    nu, ny = loop.n_plant_inputs, loop.n_plant_outputs
    u_names = tuple(str(s)[2:] for s in loop.inputs[:nu])  # strip "d_"
    y_names = tuple(str(s) for s in loop.outputs[:ny])
    d_vec = np.zeros(nu)
    chosen = []
    for ch in channels:
        if isinstance(ch, (int, np.integer)):
            if not 0 <= int(ch) < nu:
                raise ModelError(f"impulse_response: channel index {ch} out of range 0..{nu - 1}")
            idx = int(ch)
        elif ch in u_names:
            idx = u_names.index(ch)
        else:
            raise ModelError(f"impulse_response: unknown channel {ch!r}; plant inputs are {list(u_names)}")
        d_vec[idx] = amplitude_a
        chosen.append(u_names[idx])

    n_end = _steps(t_end_s, dt_s, "t_end_s")
    k0 = _steps(t_impulse_s, dt_s, "t_impulse_s")
    k1 = k0 + _steps(duration_s, dt_s, "duration_s")
    if k1 > n_end:
        raise ModelError("impulse_response: the pulse does not fit in the window (t_impulse_s + duration_s > t_end_s)")
    t = np.arange(n_end + 1) * dt_s
    pulse = np.zeros((n_end + 1, 1))
    pulse[k0:k1] = 1.0
    dk = pulse * d_vec
    Y = loop.modal_response(dk, dt_s)  # a large plant: from its modal form, no expm
    if Y is None:
        sys = loop.system
        A = np.asarray(sys.A, dtype=float)
        b = np.asarray(sys.B, dtype=float)[:, :nu] @ d_vec
        C = np.asarray(sys.C, dtype=float)
        D = np.asarray(sys.D, dtype=float)[:, :nu]
        # exact for the piecewise-constant pulse: the ZOH equivalent of its single input column
        Ad, bd = (A, b[:, None]) if loop.dt else zoh(A, b[:, None], dt_s, keep=False)
        (Y,) = simulate_lti(Ad, bd, [C], pulse)
        Y = Y + dk @ D.T
    blew_up_at = None
    bad = ~np.all(np.isfinite(Y), axis=1) | (np.max(np.abs(Y), axis=1) > _BLOWUP)
    if bad.any():
        blew_up_at = int(np.argmax(bad))
        Y[blew_up_at:] = np.nan
    disp, cur = Y[:, :ny], Y[:, ny : ny + nu]

    finite = np.isfinite(disp).all(axis=1)
    peak_m = float(np.max(np.abs(disp[finite]))) if finite.any() else float("nan")
    peak_i = float(np.nanmax(np.abs(cur))) if np.isfinite(cur).any() else float("nan")
    t0 = k0 * dt_s
    if loop.stable and blew_up_at is None:
        ts = settling_time(t, disp, band=band, t0=t0)
        per = tuple((nm, settling_time(t, disp[:, i], band=band, t0=t0)) for i, nm in enumerate(y_names))
    else:
        ts = float("inf")
        per = tuple((nm, float("inf")) for nm in y_names)
    return ImpulseResponse(
        time_s=t, displacement_m=disp, current_a=cur, disturbance_a=dk,
        output_names=y_names, input_names=u_names,
        peak_displacement_um=peak_m * 1e6, peak_current_a=peak_i,
        settling_time_s=ts, settling_per_channel_s=per, settled=bool(np.isfinite(ts)),
        stable=loop.stable, max_real_pole=loop.max_real_pole,
        amplitude_a=float(amplitude_a), duration_s=float(duration_s), t_impulse_s=float(t0), dt_s=float(dt_s),
        channels=tuple(chosen),
    )
