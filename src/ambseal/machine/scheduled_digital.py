"""The scheduled (LPV) controller as it runs on the target: a table interpolated on θ.

The LPV controller of :func:`ambseal.design.lpv_design.design_lpv` is a table of state-space
matrices in one state basis at the speeds of its check grid, linearly interpolated in the
rotor speed Ω between entries and held at the ends (:class:`~ambseal.robust.lpv.LpvController`);
the controller scheduled on a tracked seal coefficient
(:func:`ambseal.design.seal_schedule.design_seal_scheduled`) is the same kind of
table on θ = that coefficient (SI). The target runs the same law on discrete matrices:
every entry is discretised by one method (:mod:`ambseal.robust.digital`, chosen on the
frozen loops), after the fast poles are removed in one basis common to all entries (the
slow/fast split of the middle entry, so that interpolating the reduced entries still makes
sense) or, for the hold equivalents, kept when at every entry they alias nothing
(:func:`~ambseal.robust.digital.hold_keeps`), and the discrete matrices are interpolated
on the measured speed (or the tracked estimate). The tracked controller of the identified
test rig needs the second: its 6.3–6.6 kHz pairs (ζ ≥ 0.998) residualised raised its
σ̄(S_o) peak at 190 Hz from 2.94 to 3.16 (continuous, exact delay; Tustin pre-warped
table 3.10–3.11 as it runs), kept under the triangle hold 2.93.

The interpolation is judged between the grid points: the caller passes plants at values
between table entries, and the chosen method keeps every one of those sampled loops
stable (``candidates``).

The discrete table is at least as dense as the continuous one and has at least
:data:`MIN_TABLE_INTERVALS` intervals (:func:`table_grid`): between two entries of the
continuous table the controller is the interpolated one, exact for the vertex-grid LPV
design, but its sampled matrices (a matrix exponential of them, after a residualisation)
are not linear in Ω: the flywheel's LPV (``examples/flywheel.toml``), tabulated at
standstill and the top speed alone, lost its nutation mode half way with every method,
where the same controller sampled there held it (benchmarks/README.md).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Sequence

import control
import numpy as np

from ambseal.errors import SynthesisError
from ambseal.lti import finite_or_none_tree, interp_table
from ambseal.machine.controller import SPEED, ScheduledController
from ambseal.robust import (
    DISCRETISATIONS,
    FAST_FRACTION,
    HOLDS,
    KEPT,
    DiscreteController,
    check_rate,
    choose_method,
    chosen_error,
    discretize_as,
    hold_keeps,
    is_stable,
    peak_difference,
    prewarp_frequency_hz,
    residualize,
    sampled_plants,
    split_fast,
    with_delay,
)

__all__ = ["ScheduledDigital", "scheduled_digital", "INTERPOLATION", "interpolation_law",
           "table_grid", "MIN_TABLE_INTERVALS"]

#: Fewest intervals of a discrete table (module docstring)
MIN_TABLE_INTERVALS = 8


def table_grid(theta) -> np.ndarray:
    """The θ of a scheduled controller's discrete table: every entry of its continuous
    table ``theta`` (increasing), each interval split evenly so that there are at least
    :data:`MIN_TABLE_INTERVALS` (module docstring).

    Parameters
    ----------
    theta : array_like, shape (n_t,)
        The continuous table's θ, increasing, n_t ≥ 2.

    Returns
    -------
    ndarray, shape (n,)
        n ≥ max(n_t, MIN_TABLE_INTERVALS + 1); the entries of ``theta`` among them.
    """
    W = np.asarray(theta, float)
    split = -(-MIN_TABLE_INTERVALS // max(W.size - 1, 1))
    pieces = [np.linspace(a, b, split + 1)[:-1] for a, b in zip(W[:-1], W[1:])]
    return np.concatenate(pieces + [W[-1:]])


def interpolation_law(parameter: str = SPEED) -> str:
    """The interpolation law on ``parameter``, as written into every export."""
    what = "the rotor speed (rad/s)" if parameter == SPEED else f"{parameter} (SI)"
    return (f"linear in {what} between table entries, held constant outside the table: "
            "M(W) = (1 - t) M[j] + t M[j+1], t = (W - W[j]) / (W[j+1] - W[j])")


#: The interpolation law of a speed-scheduled controller.
INTERPOLATION = interpolation_law()


def _label(parameter: str, value: float) -> str:
    return f"{value / (2 * np.pi):.4g} Hz" if parameter == SPEED else f"{parameter} = {value:.4g}"


def _interp(x: float, grid: np.ndarray, stack: np.ndarray) -> np.ndarray:
    return interp_table(float(x), grid, stack)


@dataclass(frozen=True, eq=False)
class ScheduledDigital(ScheduledController):
    """A scheduled controller and its discrete table, ``i = −K(θ) y``.

    Attributes
    ----------
    grid : ndarray, shape (n_t,)
        θ of each table entry, increasing: speeds Ω (rad/s), or values of ``parameter``
        (SI).
    continuous, reduced, discrete : tuple of 4 ndarray
        ``(A, B, C, D)`` stacks of shapes (n_t, n, n), (n_t, n, ny), (n_t, nu, n),
        (n_t, nu, ny): the designed physical controller (m → A), the one discretised (the
        same with the fast poles removed, or ``continuous`` when they were kept), and its
        discrete equivalent at ``sample_rate_hz``.
    inputs, outputs : tuple of str
    method, prewarp_hz, sample_rate_hz, delay_samples, removed_poles_hz, candidates, choice
        As :class:`~ambseal.robust.digital.DigitalController`.
    name : str
    parameter : str
        θ: :data:`~ambseal.machine.controller.SPEED` or an LFT parameter (``"seal.k"``).
    """

    grid: np.ndarray
    continuous: tuple = field(repr=False)
    reduced: tuple = field(repr=False)
    discrete: tuple = field(repr=False)
    inputs: tuple = ()
    outputs: tuple = ()
    method: str = "zoh"
    prewarp_hz: float | None = None
    sample_rate_hz: float = 1.0
    delay_samples: int = 0
    removed_poles_hz: tuple = ()
    candidates: tuple = ()
    name: str = "K"
    parameter: str = SPEED
    choice: str = ""

    @property
    def schedule(self) -> tuple[float, float]:
        """(θ_min, θ_max) of the table (rad/s for the speed, else SI)."""
        return (float(self.grid[0]), float(self.grid[-1]))

    @property
    def interpolation(self) -> str:
        """The interpolation law (:func:`interpolation_law`)."""
        return interpolation_law(self.parameter)

    @property
    def Ts(self) -> float:
        """Sample time (s)."""
        return 1.0 / self.sample_rate_hz

    def matrices_at(self, value: float) -> tuple[np.ndarray, ...]:
        """The designed physical ``(A_K, B_K, C_K, D_K)`` at θ, interpolated."""
        return tuple(_interp(value, self.grid, X) for X in self.continuous)

    def at(self, value: float, name: str | None = None):
        """The frozen designed controller at θ, continuous ``control.StateSpace``."""

        return control.ss(*self.matrices_at(value), inputs=list(self.inputs),
                          outputs=list(self.outputs), name=name or self.name)

    def discrete_at(self, value: float) -> DiscreteController:
        """The discrete controller the target runs at θ: the interpolated table."""
        mats = [_interp(value, self.grid, X) for X in self.discrete]
        key = "speed_rad_s" if self.parameter == SPEED else self.parameter
        return DiscreteController(*mats, self.Ts, description={
            "type": "state_space", "name": self.name, "discretisation": self.method,
            key: float(value)})

    def statespace_at(self, value: float, delayed: bool = False):
        """:meth:`discrete_at` as a named discrete ``control.StateSpace`` (with the
        computation delay when ``delayed``)."""

        d = self.discrete_at(value)
        mats = (d.A, d.B, d.C, d.D)
        if delayed:
            mats = with_delay(mats, self.delay_samples)
        return control.ss(*mats, self.Ts, inputs=list(self.inputs),
                          outputs=list(self.outputs), name=f"{self.name}_{self.method}")

    def to_dict(self) -> dict:
        """JSON-ready description (no matrices)."""
        return finite_or_none_tree({
                "method": self.method, "choice": self.choice or self.method,
                "prewarp_hz": self.prewarp_hz,
                "sample_rate_hz": self.sample_rate_hz, "Ts": self.Ts,
                "delay_samples": self.delay_samples, "interpolation": self.interpolation,
                **({"table_speeds_hz": (self.grid / (2 * np.pi)).tolist()}
                   if self.parameter == SPEED else
                   {"parameter": self.parameter, "table_values": self.grid.tolist()}),
                "fast_fraction_of_nyquist": FAST_FRACTION,
                "removed_poles_hz": [float(f) for f in self.removed_poles_hz],
                "order": int(self.discrete[0].shape[1]),
                "peak_difference": peak_difference(chosen_error(self), self.method,
                                                   self.removed_poles_hz),
                "candidates": [dict(c) for c in self.candidates]})


def scheduled_digital(K: ScheduledController, grid, sample_rate_hz: float,
                      plants: Sequence[tuple[float, tuple]], *, delay_samples: int = 1,
                      methods: Sequence[str] = DISCRETISATIONS, name: str = "K_lpv"
                      ) -> ScheduledDigital:
    """Tabulate, reduce and discretise a scheduled controller for the target.

    Parameters
    ----------
    K : ScheduledController
        Physical scheduled controller (``matrices_at(θ)``, m → A, ``i = −K y``) on
        ``K.parameter`` (the speed, rad/s, or an LFT parameter, SI).
    grid : array_like, shape (n_t,)
        Table values of θ: those where ``K`` is exact (the LPV check grid), increasing.
    sample_rate_hz : float
    plants : sequence of (θ, (A, B, C, D))
        Full-order continuous plants at the judged conditions (nominal first) and between
        table entries.
    delay_samples, methods
        As :func:`ambseal.robust.digital.digital_controller`.
    name : str

    Returns
    -------
    ScheduledDigital

    Raises
    ------
    ConfigError
        A bad sample rate or delay.
    SynthesisError
        A fast pole that is unstable at some entry, or no method keeps every sampled loop
        stable.
    """
    check_rate(K, sample_rate_hz, delay_samples)
    fs, T = float(sample_rate_hz), 1.0 / float(sample_rate_hz)
    W = np.asarray(grid, float)
    table = [tuple(np.asarray(X, float) for X in K.matrices_at(w)) for w in W]
    reduced, fast, keep = _reduced_table(table, W, fs, K.parameter, name)
    stacks = [tuple(np.stack([m[i] for m in seq]) for i in range(4))
              for seq in (table, reduced)]
    sp = [p[0] for p in plants]
    G = [p[1] for p in plants]
    cont = [tuple(_interp(s, W, X) for X in stacks[0]) for s in sp]
    f_pw = prewarp_frequency_hz(G[:1], cont[0], fs)
    tried = list(methods) + ([f"{m}{KEPT}" for m in HOLDS if m in methods] if keep else [])

    def discrete(m):
        src = table if m.endswith(KEPT) else reduced
        tab = [discretize_as(r, T, m.removesuffix(KEPT), f_pw) for r in src]
        st = tuple(np.stack([t[i] for t in tab]) for i in range(4))
        discrete.tables[m] = st
        return [tuple(_interp(s, W, X) for X in st) for s in sp]

    discrete.tables = {}
    choice, _, cands = choose_method(sampled_plants(G, fs, delay_samples=delay_samples), cont,
                                     discrete, int(delay_samples), tried, f_pw, name)
    m = choice.removesuffix(KEPT)
    if choice.endswith(KEPT):  # the table as designed: nothing removed
        stacks[1], fast = stacks[0], np.zeros(0)
    at = ({"speeds_hz": [s / (2 * np.pi) for s in sp]} if K.parameter == SPEED
          else {"values": [float(s) for s in sp]})
    cands = tuple({**c, **at} for c in cands)
    chans = K.at(float(W[0]))
    return ScheduledDigital(
        grid=W, continuous=stacks[0], reduced=stacks[1], discrete=discrete.tables[choice],
        inputs=tuple(chans.input_labels), outputs=tuple(chans.output_labels), method=m,
        prewarp_hz=f_pw if m == "tustin_prewarp" else None, sample_rate_hz=fs,
        delay_samples=int(delay_samples),
        removed_poles_hz=tuple(sorted(float(abs(p)) / (2 * np.pi) for p in fast)),
        candidates=cands, name=name, parameter=K.parameter, choice=choice)


def _reduced_table(table, W, fs: float, parameter: str, name: str):
    """The entries with their fast poles removed in one basis (module docstring), the
    middle entry's fast poles (rad/s), and whether the hold equivalents may keep them (at
    every entry that has poles above half of Nyquist,
    :func:`~ambseal.robust.digital.hold_keeps`)."""
    f_cut = FAST_FRACTION * fs / 2
    V, k, fast = split_fast(table[len(W) // 2][0], f_cut)
    for w, mats in zip(W, table):
        A22 = np.linalg.solve(V, mats[0] @ V)[k:, k:]
        if not is_stable(np.linalg.eigvals(A22)):
            raise SynthesisError(
                f"controller.sample_rate_hz = {fs:g} Hz: the fast part of {name} at "
                f"{_label(parameter, w)} is not stable and cannot be removed; raise the "
                "sample rate")
    # an entry whose poles all lie below the cut (the fast pair of the middle entry
    # slows down towards an end of the table) has nothing the hold could alias
    above = [x[np.abs(x) > 2 * np.pi * f_cut] for x in (np.linalg.eigvals(m[0]) for m in table)]
    keep = bool(fast.size) and all(not x.size or hold_keeps(x, fs) for x in above)
    return [residualize(m, V, k) for m in table], fast, keep
