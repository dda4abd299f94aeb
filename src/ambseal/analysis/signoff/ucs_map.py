"""The undamped critical speed map (API 684, 2nd ed., 2005, §2.3): the rotor's critical
speeds against its supports' stiffness, with each AMB's stiffness at 1× as it runs drawn
on it.

The rotor — shaft, disks, couplings — on an isotropic spring of stiffness k at every
bearing (the AMBs; on a rig without AMBs its springs that are not seals), nothing else:
the seals and any other spring left out, no damping, at standstill (no gyroscopic
moment). Its natural frequencies are those of K − ω²M, each plane's once (at standstill
on isotropic springs the x and y planes have the same ones). This is ROSS's
``Rotor.run_ucs`` (ROSS 2.3 to 3.1: bearings replaced by ``BearingElement(n, kxx=k,
cxx=0)``, seals dropped, the shaft's proportional damping set to zero,
``run_modal(speed=0)``, each pair of frequencies once).

On the map each controller's AMBs are curves k_eq(Ω) = Re D(Ω), the direct dynamic
stiffness at the synchronous frequency with the discrete controller, its computation
delay, the hold and the amplifier
(:func:`ambseal.analysis.synchronous.amb_dynamic_stiffness`: K_i Re(K(jΩ)) − K_s for a
continuous one), for speeds up to 1.25 × the trip speed (the range API 617's unbalance
analysis looks for criticals in). Where a curve meets a critical speed line the rotor
has an undamped critical speed with that controller: the speed Ω where the rotor, each
AMB at its own k_eq(Ω) (the mean of its two axes), has a natural frequency Ω. These are
found by Brent's method on the speed, not read off the figure. Where an AMB's k_eq is
not positive (above the controller's bandwidth it tends to −K_s) the rotor has no
undamped critical on it, and the curve leaves the map's logarithmic axis.

The stiffness axis spans three decades either side of the rig's own support stiffness,
as ROSS's default range does around its bearing's: the median of the controllers'
positive k_eq at the maximum continuous speed, else the AMBs' K_s, else the springs' k_xx
at the bearings.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import scipy.linalg as sla
from scipy.optimize import brentq
from scipy.sparse.csgraph import connected_components

from ambseal.analysis.signoff.level1 import bearing_positions
from ambseal.analysis.synchronous import amb_dynamic_stiffness
from ambseal.config import Spring
from ambseal.errors import ModelError
from ambseal.lti import json_float
from ambseal.model import amb_factors, build_system

__all__ = ["UcsCurve", "UcsMap", "ucs_map", "undamped_criticals_hz", "N_CRITICALS",
           "DECADES", "POINTS_PER_DECADE", "SPEED_POINTS", "TOP_PER_TRIP"]

#: Critical speeds drawn (ROSS's ``run_ucs`` default: 16 eigenvalues, 4 frequencies).
N_CRITICALS = 4
#: The stiffness axis: this many decades either side of the rig's support stiffness, and
#: its points per decade.
DECADES, POINTS_PER_DECADE = 3, 5
#: The controllers' curves: speeds from TOP_PER_TRIP × trip speed / SPEED_POINTS to
#: TOP_PER_TRIP × the trip speed.
SPEED_POINTS, TOP_PER_TRIP = 120, 1.25


@dataclass(frozen=True)
class UcsCurve:
    """One controller's AMBs on the map.

    Attributes
    ----------
    controller : str
    ambs : tuple of str
        The AMBs, in the rig file's order.
    k_eq : ndarray, shape (n_amb, n_s)
        Each AMB's equivalent stiffness at 1× (N/m; the mean of its two axes) at the
        map's speeds.
    criticals_hz : tuple of float
        The undamped critical speeds on this controller's stiffness (Hz), ascending.
    """

    controller: str
    ambs: tuple
    k_eq: np.ndarray
    criticals_hz: tuple

    def to_dict(self) -> dict:
        return {"controller": self.controller,
                "k_eq_n_per_m": {a: [json_float(k) for k in row]
                                 for a, row in zip(self.ambs, self.k_eq)},
                "critical_speeds_hz": [float(f) for f in self.criticals_hz]}


@dataclass(frozen=True)
class UcsMap:
    """The undamped critical speed map (module docstring).

    Attributes
    ----------
    stiffness : ndarray, shape (n_k,)
        Support stiffness (N/m), log-spaced.
    critical_hz : ndarray, shape (n_crit, n_k)
        The rotor's critical speeds (Hz) on each stiffness, ascending per column.
    bearings_m : tuple of float
        Where the springs stand (m).
    speeds_hz : ndarray, shape (n_s,)
        The speeds of the controllers' curves (Hz).
    curves : tuple of UcsCurve
        One per controller (none for a rig on springs alone).
    """

    stiffness: np.ndarray
    critical_hz: np.ndarray
    bearings_m: tuple
    speeds_hz: np.ndarray
    curves: tuple

    def to_dict(self) -> dict:
        """The ``ucs_map`` block of ``signoff.json``."""
        return {"stiffness_n_per_m": [float(k) for k in self.stiffness],
                "critical_speeds_hz": [[json_float(f) for f in row]
                                       for row in self.critical_hz],
                "bearings_m": list(self.bearings_m),
                "speeds_hz": [float(f) for f in self.speeds_hz],
                "controllers": [c.to_dict() for c in self.curves]}


def _rotor_alone(cfg):
    """The rig with neither AMBs, seals nor springs (the map's springs are added per
    stiffness), its mass and stiffness matrices being all the map reads."""
    return cfg.model_copy(update={"amb": [], "seal": [], "spring": []})


def _plane(M: np.ndarray, K: np.ndarray) -> np.ndarray:
    """The DOFs coupled to the first node's x (one plane at standstill on isotropic
    springs), or every DOF where the planes are coupled."""
    _, label = connected_components((np.abs(M) + np.abs(K)) > 0, directed=False)
    dofs = np.flatnonzero(label == label[0])
    return dofs if label[1] != label[0] else np.arange(M.shape[0])


def undamped_criticals_hz(cfg, stiffness, *, n: int = N_CRITICALS) -> np.ndarray:
    """The lowest ``n`` natural frequencies of the rotor alone on an isotropic spring at
    each bearing, undamped and at standstill (module docstring).

    Parameters
    ----------
    cfg : RigConfig
        The rig (its AMBs, or its springs that are not seals, say where the bearings are:
        :func:`ambseal.analysis.signoff.level1.bearing_positions`).
    stiffness : float or array_like, shape (n_bearings,)
        The springs' stiffness (N/m): one for all, or one per bearing (ascending
        position), each > 0.
    n : int
        How many.

    Returns
    -------
    ndarray, shape (n,)
        Hz, ascending; NaN past the model's own count.

    Raises
    ------
    ModelError
        A stiffness that is not positive, or of the wrong length.
    """
    zs = bearing_positions(cfg)
    k = np.broadcast_to(np.asarray(stiffness, float), (len(zs),)) \
        if np.ndim(stiffness) == 0 else np.asarray(stiffness, float)
    if k.shape != (len(zs),) or not np.all(k > 0):
        raise ModelError(f"undamped critical speeds: expected {len(zs)} positive support "
                         f"stiffnesses, got {np.asarray(stiffness).tolist()}")
    springs = [Spring(position=z, kxx=float(kj), kyy=float(kj), name=f"ucs{i}")
               for i, (z, kj) in enumerate(zip(zs, k))]
    sys = build_system(_rotor_alone(cfg).model_copy(update={"spring": springs}),
                       speed_rpm=0.0, include_seals=False)
    M, K = np.asarray(sys.M, float), np.asarray(sys.K, float)
    d = _plane(M, K)
    both = d.size == M.shape[0]  # the planes coupled: each frequency twice
    M, K = M[np.ix_(d, d)], K[np.ix_(d, d)]
    w2 = (sla.eigh(K, M, eigvals_only=True) if np.allclose(K, K.T, rtol=0, atol=1e-9 *
                                                           np.abs(K).max())
          else np.sort(sla.eigvals(K, M).real))
    f = np.sqrt(np.clip(w2, 0.0, None)) / (2 * math.pi)
    if both:
        f = f[::2]
    out = np.full(n, np.nan)
    out[:min(n, f.size)] = f[:n]
    return out


def _reference_stiffness(cfg, k_eq_at_top: list[np.ndarray]) -> float:
    """The rig's support stiffness (N/m; module docstring)."""
    pos = np.concatenate([k[k > 0] for k in k_eq_at_top]) if k_eq_at_top else np.array([])
    if pos.size:
        return float(np.median(pos))
    if cfg.amb:
        return float(np.mean([np.mean(amb_factors(a)[1]) for a in cfg.amb]))
    zs = set(bearing_positions(cfg))
    ks = [float(s.kxx) for s in cfg.spring
          if s.position in zs and s.kind != "seal" and isinstance(s.kxx, (int, float))]
    return float(np.median(ks)) if ks and np.median(ks) > 0 else 1e8


def _amb_k_eq(cfg, controller, speeds_hz) -> tuple[tuple[str, ...], np.ndarray]:
    """(AMB names, k_eq per AMB and speed): the mean of its two axes' Re D."""
    axes, D = amb_dynamic_stiffness(cfg, controller, speeds_hz)
    names = tuple(a.name for a in cfg.amb)
    k = np.array([[np.mean(D[s, [j for j, ax in enumerate(axes) if ax.rsplit("_", 1)[0] == a]]
                           .real) for s in range(D.shape[0])] for a in names])
    return names, k


def _by_bearing(cfg, k_amb: np.ndarray) -> np.ndarray:
    """Per bearing position (ascending) the stiffness of the AMBs there (summed)."""
    zs = bearing_positions(cfg)
    return np.array([sum(k for a, k in zip(cfg.amb, k_amb) if a.position == z) for z in zs])


def _crossings(cfg, controller, speeds: np.ndarray, k: np.ndarray) -> tuple:
    """The speeds (Hz) where a critical speed on the AMBs' k_eq(Ω) equals Ω."""
    def crit(f: float, kb=None) -> np.ndarray:
        if kb is None:
            kb = _by_bearing(cfg, _amb_k_eq(cfg, controller, [f])[1][:, 0])
        return (undamped_criticals_hz(cfg, kb) if np.all(kb > 0)
                else np.full(N_CRITICALS, np.nan))

    g = np.array([crit(f, _by_bearing(cfg, k[:, i])) - f for i, f in enumerate(speeds)])
    out = []
    for j in range(N_CRITICALS):
        for i in range(speeds.size - 1):
            a, b = g[i, j], g[i + 1, j]
            if np.isfinite(a) and np.isfinite(b) and a * b <= 0 and a != b:
                try:
                    out.append(brentq(lambda f: crit(f)[j] - f, speeds[i], speeds[i + 1],
                                      xtol=1e-9 * speeds[i + 1]))
                except ValueError:  # NaN inside the interval: read it off the grid
                    out.append(float(speeds[i] + a / (a - b) * (speeds[i + 1] - speeds[i])))
    return tuple(sorted(float(f) for f in out))


def ucs_map(cfg, controllers=(), *, stiffness=None) -> UcsMap:
    """The undamped critical speed map of a rig, with each controller's AMBs on it
    (module docstring).

    Parameters
    ----------
    cfg : RigConfig
        The rig.
    controllers : sequence of (str, controller)
        (name, DigitalController or ScheduledDigital as it runs); a None controller (a rig
        on springs alone) draws no curve.
    stiffness : array_like, optional
        The support stiffnesses (N/m), > 0; default log-spaced over
        ±:data:`DECADES` decades around the rig's own.

    Returns
    -------
    UcsMap

    Raises
    ------
    ConfigError
        A rig without bearings.
    ModelError
        A stiffness that is not positive.
    """
    zs = bearing_positions(cfg)
    top = TOP_PER_TRIP * cfg.operating.trip_hz
    # a rig at standstill (no speed given) has no speed range to draw the AMBs over
    speeds = np.linspace(top / SPEED_POINTS, top, SPEED_POINTS) if top > 0 else np.zeros(0)
    run = [(name, K) for name, K in controllers if K is not None and cfg.amb and top > 0]
    keqs = [_amb_k_eq(cfg, K, speeds) for _, K in run]
    if stiffness is None:
        i_top = int(np.argmin(np.abs(speeds - cfg.operating.continuous_hz[1])))
        e = int(math.log10(_reference_stiffness(cfg, [k[:, i_top] for _, k in keqs])))
        stiffness = np.logspace(e - DECADES, e + DECADES, 2 * DECADES * POINTS_PER_DECADE + 1)
    ks = np.asarray(stiffness, float)
    crit = np.column_stack([undamped_criticals_hz(cfg, k) for k in ks])
    curves = tuple(UcsCurve(name, names, k, _crossings(cfg, K, speeds, k))
                   for (name, K), (names, k) in zip(run, keqs))
    return UcsMap(ks, crit, tuple(float(z) for z in zs), speeds, curves)
