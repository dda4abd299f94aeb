"""Unbalance force rejection: a generalised notch filter in a controller's input, scheduled
on the rotor speed.

Herzog, Bühler, Gähler & Larsonneur, "Unbalance compensation using generalized notch
filters in the multivariable feedback of magnetic bearings", *IEEE Trans. Control Systems
Technology* 4(5), 1996. The controller K (``i = −K q``) reads ``q = y − w`` instead of its
measurements ``y``; ``w`` is the output of a generalised notch filter fed by ``q``, an
integrator of q's component at the rotational frequency Ω:

    continuous  ż = jΩ z + ε T(Ω) q,                  w = Re z   (z ∈ ℂ^p)
    discrete    z_{k+1} = e^{jΩT_s} (z_k + ε T_s T(Ω) q_k),  w_k = Re z_k

with ε a fixed fraction of Ω (``rate_fraction``),
so ``w = N q`` with ``N(s) = (ε/2)[T/(s − jΩ) + T̄/(s + jΩ)]``, poles at ±jΩ (at
``e^{±jΩT_s}``). K then sees ``(I + N)⁻¹ y``, which is zero at Ω: the controller commands no
current at the rotational frequency, so neither the unbalance's synchronous response nor
a synchronous sensor runout reaches the coils — the rotor turns about its axis of inertia
and the bearings transmit only their negative stiffness's force K_s x.

Closed around the loop the notch sees ``q = S_o (d − w)``, ``S_o = (I + G K)⁻¹``: to first
order in ε its poles lie at ``jΩ − (ε/2) λ_i(T S_o(jΩ))`` (discrete:
``e^{jΩT_s}(1 − (εT_s/2) λ_i)``). With ``T = S_o(jΩ)⁻¹ = I + G(jΩ) K(jΩ)`` (Herzog et al.'s
choice, the sensitivity's inverse) every one lies at ``jΩ − ε/2``, whatever the plant; a
gain table interpolated between speeds keeps them in the left half-plane while
``Re λ(T S_o) > 0`` — a phase error below 90°. The loop is judged at every condition all
the same (:mod:`ambseal.design.synchronous_rejection`).

The rejection is switched on from ``on_rad_s`` (the rotor's minimum continuous speed by
default): at standstill a notch at Ω = 0 would take away the controller's static
stiffness, which the AMB's negative stiffness needs. Below it the controller runs alone.

Realisation (``z = a + jb``, p channels, 2p states)::

    continuous  ȧ = −Ω b + ε T_r q,  ḃ = Ω a + ε T_i q
    discrete    [a; b]' = R(ΩT_s) ([a; b] + ε T_s [T_r; T_i] q),  R the rotation

``w = a``. K with the notch in its input, ``(A_K, B_K, C_K, D_K)`` and ``(A_N, B_N, C_N)``::

    A = [[A_K, −B_K C_N], [0, A_N − B_N C_N]],  B = [[B_K], [B_N]],
    C = [C_K, −D_K C_N],                        D = D_K
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any

import control
import numpy as np

from ambseal.errors import ModelError
from ambseal.lti import interp_table
from ambseal.machine.controller import SPEED, ScheduledController, frozen

__all__ = ["SynchronousNotch", "NotchedController", "NotchedDigital"]


@dataclass(frozen=True, eq=False)
class SynchronousNotch:
    """The generalised notch filter of a controller, scheduled on speed (module docstring).

    Attributes
    ----------
    speeds_rad_s : ndarray, shape (S,)
        The speeds Ω of the gain table (rad/s), increasing, > 0.
    gain_re, gain_im : ndarray, shape (S, p, p)
        Real and imaginary parts of T(Ω) at each, rows and columns in ``inputs``' order.
    rate_fraction : float
        ε/Ω: the notch's poles sit ε/2 left of ±jΩ (its time constant 2/ε), ε a fixed
        fraction of the speed so that it settles in the same number of revolutions at
        every speed (1/(π·rate_fraction)).
    on_rad_s : float
        The speed (rad/s) from which the notch is on; below it the controller runs alone.
    inputs : tuple of str
        The controller's measurement names (``y_<channel>``) the notch acts on, in order.
    dt : float
        0 for a continuous notch, else the sample time (s) of the discrete one, with the
        table's top speed at most the Nyquist frequency (Ω_max·dt ≤ π).

    Raises
    ------
    ModelError
        On construction: speeds not increasing from above 0, gains of another shape,
        ``rate_fraction`` outside (0, 0.5), ``on_rad_s`` ≤ 0, ``dt`` < 0, or a table's top
        speed above the discrete notch's Nyquist frequency.
    """

    speeds_rad_s: np.ndarray
    gain_re: np.ndarray = field(repr=False)
    gain_im: np.ndarray = field(repr=False)
    rate_fraction: float
    on_rad_s: float
    inputs: tuple
    dt: float = 0.0

    def __post_init__(self):
        w = np.asarray(self.speeds_rad_s, float)
        p = len(self.inputs)
        shape = (w.size, p, p)
        if w.ndim != 1 or not w.size or np.any(w <= 0) or np.any(np.diff(w) <= 0):
            raise ModelError("synchronous notch: speeds_rad_s must increase from above 0")
        if np.shape(self.gain_re) != shape or np.shape(self.gain_im) != shape:
            raise ModelError(f"synchronous notch: gains of shape {shape} expected, got "
                             f"{np.shape(self.gain_re)} and {np.shape(self.gain_im)}")
        if not 0 < self.rate_fraction < 0.5 or self.on_rad_s <= 0 or self.dt < 0:
            raise ModelError("synchronous notch: expected 0 < rate_fraction < 0.5, "
                             "on_rad_s > 0 and dt ≥ 0")
        # ε T_s < 2 keeps the notch's own poles inside the unit circle up to Nyquist (Ω T_s
        # ≤ π): rate_fraction < 2/π; the narrow notch the first-order placement needs is
        # far below it. Beyond Nyquist neither holds (a sample time in the wrong unit)
        if self.dt and w[-1] * self.dt > math.pi:
            raise ModelError(f"synchronous notch: Ts = {self.dt:g} s puts the table's top "
                             f"speed {w[-1]:g} rad/s above the Nyquist frequency π/Ts = "
                             f"{math.pi / self.dt:g} rad/s: the notch cannot follow it "
                             "(the sample time in seconds?)")

    @property
    def schedule(self) -> tuple[float, float]:
        """(Ω_min, Ω_max) of the gain table (rad/s), held at its ends outside it."""
        return float(self.speeds_rad_s[0]), float(self.speeds_rad_s[-1])

    def is_on(self, omega: float) -> bool:
        """Whether the notch runs at the speed ``omega`` (rad/s): from ``on_rad_s`` up."""
        return abs(float(omega)) >= self.on_rad_s

    def gain_at(self, omega: float) -> np.ndarray:
        """T(Ω) (complex, shape (p, p)): the table's real and imaginary parts interpolated
        linearly in Ω (rad/s), held at its ends."""
        w = abs(float(omega))
        return (interp_table(w, self.speeds_rad_s, self.gain_re)
                + 1j * interp_table(w, self.speeds_rad_s, self.gain_im))

    def matrices_at(self, omega: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """``(A_N, B_N, C_N)`` of the notch at the speed Ω (rad/s; module docstring),
        shapes (2p, 2p), (2p, p), (p, 2p)."""
        w = abs(float(omega))
        T = self.gain_at(w)
        p = T.shape[0]
        eye, zero = np.eye(p), np.zeros((p, p))
        eps = self.rate_fraction * w
        if self.dt:
            c, s = np.cos(w * self.dt), np.sin(w * self.dt)
            A = np.block([[c * eye, -s * eye], [s * eye, c * eye]])
            B = eps * self.dt * A @ np.vstack([T.real, T.imag])
        else:
            A = np.block([[zero, -w * eye], [w * eye, zero]])
            B = eps * np.vstack([T.real, T.imag])
        return A, B, np.hstack([eye, zero])

    def around(self, K, omega: float):
        """``K`` with the notch at Ω in its input (module docstring); ``K`` itself below
        ``on_rad_s``.

        Parameters
        ----------
        K : control.StateSpace
            The controller at Ω, ``i = −K y``; continuous for a continuous notch, else
            discrete with the notch's sample time. Its inputs are ``inputs``, in order.
        omega : float
            The rotor speed Ω (rad/s).

        Returns
        -------
        control.StateSpace
            ``i = −K (y − w)``, K's signal names and time base, 2p more states.

        Raises
        ------
        ModelError
            A controller of another time base or with other inputs.
        """
        if not self.is_on(omega):
            return K
        dt = float(K.dt or 0.0)
        if not np.isclose(dt, self.dt, rtol=1e-12, atol=0.0):
            raise ModelError(f"synchronous notch: a controller of sample time {dt:g} s "
                             f"for a notch of {self.dt:g} s")
        if tuple(K.input_labels) != tuple(self.inputs):
            raise ModelError(f"synchronous notch: the controller reads {list(K.input_labels)}"
                             f", the notch {list(self.inputs)}")
        Ak, Bk, Ck, Dk = (np.asarray(M, float) for M in (K.A, K.B, K.C, K.D))
        An, Bn, Cn = self.matrices_at(omega)
        n, m = Ak.shape[0], An.shape[0]
        A = np.block([[Ak, -Bk @ Cn], [np.zeros((m, n)), An - Bn @ Cn]])
        B = np.vstack([Bk, Bn])
        C = np.hstack([Ck, -Dk @ Cn])
        return control.ss(A, B, C, Dk, K.dt, inputs=list(K.input_labels),
                          outputs=list(K.output_labels), name=K.name)


@dataclass(frozen=True, eq=False)
class NotchedController(ScheduledController):
    """A designed controller with its continuous notch, scheduled on speed: what the
    judgement's continuous loop takes (:func:`ambseal.machine.controller.frozen`).

    Attributes
    ----------
    base : control.StateSpace or ScheduledController
        The controller without the notch (``i = −K y``), fixed or scheduled on speed.
    notch : SynchronousNotch
        Its continuous notch (``dt`` 0).
    """

    base: Any
    notch: SynchronousNotch
    parameter = SPEED

    @property
    def schedule(self) -> tuple[float, float]:
        """(Ω_min, Ω_max) of the notch's table (rad/s)."""
        return self.notch.schedule

    def at(self, value: float, name: str = "K"):
        """The frozen controller at Ω = ``value`` (rad/s), with the notch when it is on."""
        return self.notch.around(frozen(self.base, value), value)

    def matrices_at(self, value: float) -> tuple[np.ndarray, ...]:
        """``(A_K, B_K, C_K, D_K)`` of :meth:`at`."""
        K = self.at(value)
        return tuple(np.asarray(M, float) for M in (K.A, K.B, K.C, K.D))


@dataclass(frozen=True, eq=False)
class NotchedDigital:
    """A digital controller with its discrete notch, as it runs on the target: what the
    judgement's sampled loop and the sign-off take
    (:func:`ambseal.machine.controller.controller_as_runs`).

    Attributes
    ----------
    base : DigitalController or ScheduledDigital
        The digital controller without the notch.
    notch : SynchronousNotch
        Its discrete notch (``dt`` the controller's sample time).
    """

    base: Any
    notch: SynchronousNotch
    parameter = SPEED

    @property
    def sample_rate_hz(self) -> float:
        """The controller's sample rate (Hz)."""
        return float(self.base.sample_rate_hz)

    @property
    def delay_samples(self) -> int:
        """The computation delay (samples)."""
        return int(self.base.delay_samples)

    @property
    def method(self) -> str:
        """The discretisation of the base controller."""
        return str(self.base.method)

    def theta_at(self, speed_rad_s: float | None = None, values=None) -> float:
        """The speed Ω (rad/s) at a condition, the notch's parameter.

        Parameters
        ----------
        speed_rad_s : float
            The rotor speed Ω (rad/s).
        values : mapping, optional
            Unused: the notch is scheduled on speed alone.

        Returns
        -------
        float

        Raises
        ------
        ModelError
            No speed given.
        """
        if speed_rad_s is None:
            raise ModelError("a synchronous notch runs at a speed (speed_rad_s)")
        return float(speed_rad_s)

    def statespace_at(self, value: float, delayed: bool = False):
        """The discrete controller at Ω = ``value`` (rad/s) with the notch when it is on:
        a named ``control.StateSpace`` (with the computation delay when ``delayed``)."""
        if hasattr(self.base, "statespace_at"):  # a table scheduled on speed
            K = self.base.statespace_at(self.base.theta_at(value), delayed=delayed)
        else:
            K = self.base.statespace(delayed=delayed)
        return self.notch.around(K, value)
