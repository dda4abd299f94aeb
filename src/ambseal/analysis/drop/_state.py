"""The drop's state vector: where each part of it lies, and the scale of each for the
integrator's absolute tolerance (the package's docstring, :mod:`ambseal.analysis.drop`).

In order: the modes and their rates, the turning rings' speeds, the supports' x, y and
rates, the AMB loop's states (the coil's, the controller's), the spin and its angle when
it coasts, the rotor's axial position and speed where it moves axially, each plane's
friction heat (J), the housings' x, y and rates, and last the work done on the rotor from
outside (J): by the drive holding the spin against the rings' friction, the AMBs' and the
seals' forces, the thrust, the unbalance and the overload.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class StateLayout:
    """Where each part of the drop's state lies.

    Attributes
    ----------
    m, planes : int
        Modes kept, touchdown planes.
    races : ndarray of int
        The planes whose ring turns, in the order of their speeds in the state.
    supported : tuple of int
        The planes whose ring sits on a support, in order.
    i_loop, i_spin, i_ax, i_heat, i_house : int
        Where the loop's states, the spin and its angle (coasting), the axial position
        and speed (moving axially), the planes' friction heats and the housings' x, y
        begin.
    n_housing : int
        The housings' coordinates (x and y of each).
    size : int
        The state's length (the work last).
    """

    m: int
    planes: int
    races: np.ndarray
    supported: tuple
    i_loop: int
    i_spin: int
    i_ax: int
    i_heat: int
    i_house: int
    n_housing: int
    size: int

    @classmethod
    def of(cls, m: int, race_inertia: np.ndarray, support: tuple, n_loop: int,
           coast_down: bool, axial: bool, n_housing: int) -> "StateLayout":
        """The layout of ``m`` modes, the planes' rings (turning where ``race_inertia``
        > 0, on a support where ``support`` is not None), ``n_loop`` loop states, and the
        spin, axial motion and housings where they take part."""
        planes = len(race_inertia)
        races = np.flatnonzero(np.asarray(race_inertia) > 0)
        supported = tuple(p for p in range(planes) if support[p] is not None)
        i_loop = 2 * m + races.size + 4 * len(supported)
        i_spin = i_loop + n_loop
        i_ax = i_spin + (2 if coast_down else 0)
        i_heat = i_ax + (2 if axial else 0)
        i_house = i_heat + planes
        return cls(m, planes, races, supported, i_loop, i_spin, i_ax, i_heat, i_house,
                   n_housing, i_house + 2 * n_housing + 1)

    def support_at(self, k: int) -> int:
        """Where the ``k``-th supported ring's x, y begin (its rates two further)."""
        return 2 * self.m + self.races.size + 4 * k

    def unpack(self, y):
        """(η, η̇, the rings' speeds ω_r, the supports' s and ṡ per plane) of ``y``."""
        m, P = self.m, self.planes
        eta, deta = y[:m], y[m:2 * m]
        wr = np.zeros(P)
        wr[self.races] = y[2 * m:2 * m + self.races.size]
        s = np.zeros((P, 2))
        ds = np.zeros((P, 2))
        for k, p in enumerate(self.supported):
            i = self.support_at(k)
            s[p] = y[i:i + 2]
            ds[p] = y[i + 2:i + 4]
        return eta, deta, wr, s, ds


def tolerances(layout: StateLayout, rtol: float, clearance: float, ring_speed: np.ndarray,
               spin: float, fall_energy: float, axial_clearance: float | None,
               loop_scales: np.ndarray) -> np.ndarray:
    """The integrator's absolute tolerance per state, by each state's scale: positions
    the smallest ``clearance`` (m), speeds that over 1 ms, ring speeds the journal's
    surface speed over the ring's radius (``ring_speed``, rad/s, per turning ring), the
    spin its own ``spin`` (rad/s), the work and heats the energy of the fall
    ``fall_energy`` (J), the axial position the smallest ``axial_clearance``, and the
    loop's states ``loop_scales`` (what each adds to a current)."""
    L = layout
    m = L.m
    atol = np.full(L.size, rtol * clearance / 1e-3)
    atol[:m] = rtol * clearance
    atol[2 * m:2 * m + L.races.size] = rtol * (ring_speed + 1.0)
    if L.i_ax > L.i_spin:  # coasting
        atol[L.i_spin] = rtol * (abs(spin) + 1.0)
        atol[L.i_spin + 1] = rtol
    atol[-1] = rtol * fall_energy
    atol[L.i_heat:L.i_heat + L.planes] = atol[-1]
    atol[L.i_house:L.i_house + L.n_housing] = rtol * clearance
    if axial_clearance is not None:
        atol[L.i_ax] = rtol * axial_clearance
    atol[L.i_loop:L.i_spin] = rtol * loop_scales
    for k in range(len(L.supported)):
        atol[L.support_at(k):L.support_at(k) + 2] = rtol * clearance
    return atol
