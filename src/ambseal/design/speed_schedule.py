"""H∞ and μ scheduled on the spin speed: the design for a gyroscopic rotor that no fixed
controller holds from standstill to the top speed.

A fixed H∞ controller designed at the top speed leans on the gyroscopic stiffening of the
conical mode and loses it at standstill; one designed at standstill loses the nutation or
a bending whirl once the gyroscopic moments split them; the design with the speed an
uncertain parameter certifies nothing where Ω_top·I_p is large (benchmarks/README.md, "H∞
over the speed range on the family"). The gyroscopic matrix Ω·G is known where the
controller runs — an AMB controller reads the speed — so the H∞ design is scheduled on it
(classical gain scheduling, Rugh & Shamma, Automatica 36(10), 2000):

- the design model is the H∞ recipe's generalised plant with the spin speed as its LFT
  parameter (:func:`ambseal.design.speed_lft.with_speed`; thesis P3 Eqs. 4–10, the LPV
  model), one state basis for every speed;
- the table's speeds are the judged speeds (standstill to the top speed in
  :data:`~ambseal.design.conditions.STABILITY_STEPS` steps, and the operating speed): the
  plant frozen at each (:func:`ambseal.design.speed_lft.at_speed`), its central H∞
  controller at one γ (:func:`ambseal.robust.scheduled_hinf.hinf_scheduled`), so every
  judged loop runs a table entry exactly;
- between entries the controller is interpolated linearly, as the LPV's is; the design
  rule (:func:`ambseal.design.recipes.design`) checks the full-order loop at every entry
  the target's discrete table adds and half way along its intervals, and makes a speed
  whose loop is lost there an entry of its own; the run judges it between entries as it
  runs too (:func:`ambseal.app.commands.digital_for`);
- the weights are the H∞ recipe's with μ's unbalance-orbit demand (its force channel):
  on S_o and K S_o alone the central controllers cancel the nutation, which follows the
  speed, rather than damp it.

μ is scheduled the same way (``scalings``): the K-step of D–K (Zhou, Doyle & Glover 1996
§11.3) on the frozen plants with one set of D scales, so the entries keep one state basis;
the uncertain parameters other than the speed stay channels of the frozen plants, and
each entry's μ is the peak of its frozen loop's upper bound (:func:`mu_by_speed`).

Unlike the LPV (P3), no LMI certifies the loop between the table's speeds or while the
speed changes: the design is kept only where the full-order loop holds at every judged
condition and at those speeds between entries.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any, ClassVar

import control
import numpy as np

from ambseal.design.plant import physical_controller, physical_matrices
from ambseal.design.speed_lft import SPEED as SPEED_PARAMETER
from ambseal.design.speed_lft import at_speed
from ambseal.errors import ModelError
from ambseal.machine import SPEED, ScheduledController
from ambseal.robust import dscaled_plant, hinf_scheduled, lft_lower, mu_peak

__all__ = ["SpeedScheduledHinf", "frozen_structure", "mu_by_speed", "schedule_hinf"]

_TWO_PI = 2.0 * np.pi


@dataclass(frozen=True, eq=False)
class SpeedScheduledHinf(ScheduledController):
    """An H∞ controller scheduled on the spin speed (module docstring).

    Attributes
    ----------
    K : LpvController
        The central controllers in synthesis units (``u = K_P(Ω) y``), Ω in rad/s.
    d_e, d_u : float
        The generalised plant's scalings (m, A).
    channels : tuple of str
        The AMB axes.
    gamma : float
        The γ every entry was built at.
    gamma_opt : ndarray, shape (n_t,)
        γ_opt of the plant frozen at each table speed.
    backoff : float
        ``gamma`` over the largest ``gamma_opt``.
    name : str
    """

    parameter: ClassVar[str] = SPEED
    K: Any = field(repr=False)
    d_e: float
    d_u: float
    channels: tuple
    gamma: float
    gamma_opt: np.ndarray = field(repr=False)
    backoff: float = 1.0
    name: str = "K_hinf"

    @property
    def order(self) -> int:
        return self.K.order

    @property
    def table_theta(self) -> np.ndarray:
        """The table's speeds (rad/s), where the controller is a central H∞ design."""
        return np.asarray(self.K.theta, float)

    @property
    def speeds_hz(self) -> np.ndarray:
        """The table's speeds (Hz)."""
        return self.table_theta / _TWO_PI

    @property
    def schedule(self) -> tuple[float, float]:
        """(Ω_min, Ω_max) of the table (rad/s), held outside it."""
        return (float(self.table_theta[0]), float(self.table_theta[-1]))

    def at(self, speed_rad_s: float, name: str | None = None):
        """The frozen physical controller at Ω (rad/s): a ``control.StateSpace``, m → A,
        ``i = −K y``."""
        return physical_controller(self.K.matrices(float(speed_rad_s)), self.d_e, self.d_u,
                                   self.channels, name=name or self.name)

    def matrices_at(self, speed_rad_s: float) -> tuple[np.ndarray, ...]:
        """Physical ``(A_K, B_K, C_K, D_K)`` at Ω (rad/s), ``i = −(C_K x_K + D_K y)``."""
        return physical_matrices(self.K.matrices(float(speed_rad_s)), self.d_e, self.d_u)


def schedule_hinf(gp, speeds_hz, scalings=None, name: str = "K_hinf") -> SpeedScheduledHinf:
    """The H∞ controller scheduled on speed over a table of speeds (module docstring); with
    ``scalings``, μ's: each frozen plant's uncertainty channels D-scaled (the K-step of
    D–K on the frozen plants with one set of D scales, :func:`frozen_structure`).

    Parameters
    ----------
    gp : GeneralizedPlant
        The recipe's generalised plant with the spin speed as an LFT parameter
        (:func:`ambseal.design.plant.generalized_plant` with ``speed_range_hz``); any
        other parameters (μ's uncertain ones) stay as channels of the frozen plants.
    speeds_hz : sequence of float
        The table's speeds (Hz), within the parameter's range; sorted and made unique.
    scalings : sequence, optional
        One D scale per uncertainty block of the frozen plants
        (:func:`ambseal.robust.dscaled_plant`); None: the plants as they are, which needs
        the spin speed as the only parameter.
    name : str
        The controller's name.

    Returns
    -------
    SpeedScheduledHinf

    Raises
    ------
    ModelError
        A plant without the spin speed as an LFT parameter, other parameters without
        ``scalings``, or a speed outside its range.
    SynthesisError
        A frozen plant without an H∞ controller at the table's γ.
    """
    names = [q.name for q in gp.parameters]
    if SPEED_PARAMETER not in names or (scalings is None and len(names) > 1):
        raise ModelError(f"schedule_hinf: the generalised plant's LFT parameters are {names}, "
                         f"expected the spin speed ({SPEED_PARAMETER!r}), and alone "
                         "without D scales")
    speeds = np.unique(np.asarray(speeds_hz, float))
    plants = [at_speed(gp, _TWO_PI * f) for f in speeds]
    if scalings is not None:
        plants = [dscaled_plant(P, frozen_structure(gp), scalings, gp.nmeas, gp.ncon)
                  for P in plants]
    r = hinf_scheduled(plants, _TWO_PI * speeds, gp.nmeas, gp.ncon)
    return SpeedScheduledHinf(K=r.K, d_e=gp.d_e, d_u=gp.d_u, channels=tuple(gp.channels),
                              gamma=r.gamma, gamma_opt=r.gamma_opt, backoff=r.backoff,
                              name=name)


def frozen_structure(gp) -> tuple:
    """The block structure of ``gp`` frozen at a speed (:func:`~ambseal.design.speed_lft.
    at_speed`): its blocks without the spin speed's (one block per LFT parameter, in
    their order, then the performance block)."""
    k = [q.name for q in gp.parameters].index(SPEED_PARAMETER)
    return tuple(b for i, b in enumerate(gp.blocks) if i != k)


def mu_by_speed(gp, sched: SpeedScheduledHinf, omega) -> list:
    """The μ upper bound's peak (:func:`ambseal.robust.mu_peak`) of each table entry's
    loop: ``F_l(P(Ω_i), K(Ω_i))`` with the structure of the frozen plant, the uncertain
    parameters and the performance block (robust performance at that speed, thesis P5
    §4.4).

    Parameters
    ----------
    gp : GeneralizedPlant
        The generalised plant ``sched`` was designed on.
    sched : SpeedScheduledHinf
    omega : array_like
        Frequency grid (rad/s) the peaks are searched from.

    Returns
    -------
    list of MuPeak
        One per table speed, in the table's order.
    """
    return [mu_peak(lft_lower(at_speed(gp, th), control.ss(*sched.K.matrices(float(th))),
                              gp.nmeas, gp.ncon), frozen_structure(gp), omega)
            for th in sched.table_theta]
