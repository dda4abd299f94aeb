"""An H∞ LPV controller scheduled on a tracked seal coefficient.

The thesis closes (Ch. 7, §7.4 item 2) with the idea of following the seal coefficients
instead of being robust to all of them at once. With the estimate θ̂ of a seal coefficient
from :mod:`ambseal.identify.tracking`, the plant is an LPV system in θ: the coefficient
enters through its LFT channel, A(θ) = A₀ + B_θ θ C_θ (thesis P1 Eqs. 46–52), so only A
depends on θ and dA/dθ = B_θ C_θ exactly. The gridded LMI synthesis of
:func:`ambseal.robust.lpv.lpvsyn` (Apkarian & Adams 1998; Wu et al. 1996; thesis P3 §4)
then gives a controller scheduled on θ, with the parameter-dependent Lyapunov function
S(θ) = S₀ + p S₁ and the rate bound |θ̇| ≤ ν from the expected pressure ramp.

Defaults (each a rule on the rig): θ over [0, 3]× its value at the rig's operating
pressure (the main job's ramp to 3× nominal), 3 design grid points (the range's ends and
its middle), ν = 0.1× that value per second (0 → 3× nominal in 30 s). The controller is
reconstructed and its frozen design loops checked (stable, H∞ norm) on a table of
:data:`TABLE_INTERVALS` + 1 values of θ whatever the design grid, stability also between
table entries. 3 design points instead of the former 5 (measured on the test rig, rig file,
cache off, same run, ``benchmarks/bench_tracked.py``): the γ SDP has 29 interior-point
iterations either way but each costs 3/5 of the LMIs, CPU 77.6 → 48.8 s; γ 1.5066 →
1.5092 and the largest checked H∞ norm on the 21-entry table 1.4882 → 1.4890 (+0.05 %):
the Lyapunov function found on 3 points holds on the denser table (those times were with the
former SDP solver, Clarabel). When θ is a seal's k affine in the pressure drop, every other
seal coefficient in each design plant is the one at the pressure that gives θ
(:func:`ambseal.model.seal.values_following_k`).

Design model: the specification's (:func:`ambseal.design.specs.design_spec`: every mode
below min(3 f_a, f_s/4); on the test rig the rigid-body modes and the 557 Hz bending pair,
12 mechanical states). A rigid-body design model (8 states) is not enough: the seal's
cross-coupled k at mid-span drives the first bending mode, and a controller that does not
see it loses it on the full-order plant from 2× nominal pressure (measured: the 554.7 Hz
pair at Re λ = +0.72 1/s at 2×, +8.8 1/s at 3×).

Weights: the nominal H∞ design's (the specification's ``hinf`` weights, P5 §4.4) with the
W_p peak M = 2 of the LPV weights (P3 Eq. 11) instead of 2.5, ω_B = 60 rad/s (P5 §4.4) and
a tenth of its current weight, W_u = 0.02 instead of 0.2. The design model carries the
controller's hold + computation delay in its actuator path, as the H∞/μ designs do
(:func:`ambseal.robust.delay.design_delay`, the same call as
:func:`ambseal.design.recipes.design`): without it the tracked controller as it runs
(one sample of delay at 10 kHz) peaked at σ̄(S_o) = 4.06–4.2 per axis on the test rig
against 2.74 designed for. Measured with the delay (test rig, rig file, 21 frozen k over
0–3× nominal, every loop with the delay): the former W_u = 0.1 gave γ = 2.02 and σ̄(S_o)
3.21 (M = 1.8: 3.15), W_u = 0.05 2.99, W_u = 0.02 γ = 1.51 and 2.81; the specification's
ω_B (5 rad/s, the PID's 1/T_i) gave 2.88 with W_u = 0.1 and 2.75 with 0.07, but its LMI
reconstruction (then an SDP per table entry) failed with W_u = 0.05 on the test rig and
with W_u = 0.1 on examples/pump.toml. examples/pump.toml with these weights: γ = 1.35,
σ̄(S_o) ≤ 2.27 at 21 frozen k over 0–60 bar.

Synthesis is the γ SDP (``benchmarks/README.md``, bench_tracked; the reconstruction is in
closed form): on the rig the main job identifies (its eddy-current lag: 32 design-plant
states) about 3 s, 0.1 s per interior-point iteration. lpvsyn's trace penalty stays at its
default 1e-4: at 1e-5 the identified test rig's σ̄(S_o) fell from 3.01 to 2.70, but the
identified pump's tracked loop lost stability at 3× nominal pressure on its facility truth
(a 301 Hz mode, ζ = −0.004), where the identified model is poor (``benchmarks/README.md``).
:func:`design_seal_scheduled` keeps each result in a cache folder keyed on the rig, the
arguments, the package version and :data:`SYNTHESIS_VERSION` (``cache_dir``;
:data:`CACHE_ENV`). A cache entry is plain JSON (numbers and names, never code): an entry
that does not parse, does not match its key or version, or does not make a consistent
design is ignored and the design recomputed.
"""

from __future__ import annotations

import hashlib
import json
import math
import os
import time
import warnings
from dataclasses import asdict, dataclass, field, fields, replace
from pathlib import Path
from typing import Any, ClassVar

import numpy as np

from ambseal import __version__
from ambseal.design.plant import generalized_plant, physical_controller, physical_matrices
from ambseal.design.recipes import bound_text
from ambseal.design.specs import DesignSpec, design_spec
from ambseal.design.weights import Weights
from ambseal.errors import AmbsealError, ModelError, SynthesisError
from ambseal.files import write_json
from ambseal.machine import ScheduledController
from ambseal.model import build_plant, values_following_k
from ambseal.robust import LpvController, design_delay, lpvsyn

__all__ = ["SealScheduledDesign", "design_seal_scheduled", "CACHE_ENV"]

#: Environment variable naming the cache folder of :func:`design_seal_scheduled` (used when
#: no ``cache_dir`` is given; unset: no cache).
CACHE_ENV = "AMBSEAL_CACHE_DIR"

#: The W_p peak, bandwidth (rad/s) and the W_u gain of the scheduled design (module
#: docstring; P3 Eq. 11).
M_TRACKED, OMEGA_B_TRACKED, WU_TRACKED = 2.0, 60.0, 0.02

#: Intervals of the controller table over the schedule (21 entries: every 0.15× nominal over
#: 0–3×, the former 5-point grid's 5× denser table), whatever the design grid.
TABLE_INTERVALS = 20


@dataclass(frozen=True, eq=False)
class SealScheduledDesign(ScheduledController):
    """A controller scheduled on a seal coefficient θ (SI), ``i = −K(θ) y``
    (:class:`~ambseal.machine.controller.ScheduledController` on ``parameter``).

    Attributes
    ----------
    parameter : str
        The scheduling parameter, e.g. ``"seal.k"``.
    K : LpvController
        The table in synthesis units, its ``theta`` holding the parameter's values (SI).
    gamma, gamma_design : float
        LMI γ and the back-off γ of the construction.
    grid, check_grid : ndarray
        Design grid and the table/check grid of θ (SI; :data:`TABLE_INTERVALS` + 1 values
        by default).
    check_gamma : ndarray
        H∞ norm of each frozen closed loop of the design model on the check grid.
    rate_bound : float
        ν ≥ |θ̇| (SI per s).
    weights : Weights
    synthesis_s : float
        Wall time of the synthesis (s).
    design_states : int
        Mechanical states of the design model.
    range_factor : (float, float)
        The schedule as multiples of θ at the operating pressure.
    delay : dict
        The controller's hold + computation delay in the design model's actuator path
        (:meth:`ambseal.robust.delay.DesignDelay.to_dict`).
    """

    method: ClassVar[str] = "tracked"
    parameter: str
    K: Any = field(repr=False)
    gamma: float
    gamma_design: float
    grid: np.ndarray = field(repr=False)
    check_grid: np.ndarray = field(repr=False)
    check_gamma: np.ndarray = field(repr=False)
    rate_bound: float
    weights: Weights = field(repr=False)
    synthesis_s: float = 0.0
    design_states: int = 0
    range_factor: tuple = (0.0, 3.0)
    delay: dict = field(default_factory=dict)

    @property
    def table_theta(self) -> np.ndarray:
        """θ of the controller's table, where it is exact (SI; rad/s for the speed)."""
        return np.asarray(self.K.theta, float)

    @property
    def schedule(self) -> tuple[float, float]:
        """(θ_min, θ_max) of the table (SI)."""
        return (float(self.grid[0]), float(self.grid[-1]))

    @property
    def order(self) -> int:
        return self.K.order

    def matrices_at(self, theta: float) -> tuple[np.ndarray, ...]:
        """Physical (A_K, B_K, C_K, D_K) at θ (held at the ends of the table)."""
        return physical_matrices(self.K.matrices(float(theta)), self.weights.d_e,
                                 self.weights.d_u)

    def at(self, theta: float, name: str = "K_tracked"):  # noqa: D102 (base class)
        """The frozen physical controller at θ: m → A, ``i = −K y``, named signals."""
        chans = [n[2:] if n.startswith("y_") else n for n in self.K.input_names]
        return physical_controller(self.K.matrices(float(theta)), self.weights.d_e,
                                   self.weights.d_u, chans, name=name)

    @property
    def controller(self) -> SealScheduledDesign:
        """The design itself: it is the scheduled controller
        (:class:`~ambseal.design.Design`)."""
        return self

    @property
    def full_order(self) -> None:
        """None: the design makes no full-order check of its own (the main job judges it
        over its schedule, :func:`ambseal.analysis.judge.points_for`)."""
        return None

    @property
    def verdict(self) -> str:
        """One plain line: the LMI bound over the schedule."""
        lo, hi = self.schedule
        return (f"LPV on {self.parameter} γ = {bound_text(self.gamma)} over {lo:.4g}–{hi:.4g}"
                f" (SI), frozen loops γ ≤ {float(np.max(self.check_gamma)):.3g}")

    def summary(self) -> dict:
        """:meth:`to_dict` (:class:`~ambseal.design.Design`)."""
        return self.to_dict()

    def to_dict(self) -> dict:
        """JSON-ready summary (no matrices)."""
        return {"method": "tracked", "parameter": self.parameter, "gamma": self.gamma,
                "gamma_design": self.gamma_design, "grid": self.grid.tolist(),
                "check_gamma_max": float(np.max(self.check_gamma)),
                "rate_bound_per_s": self.rate_bound, "order": self.K.order,
                "design_states": self.design_states,
                "range_factor": list(self.range_factor), "delay": self.delay,
                "weights": self.weights.to_dict(), "synthesis_s": round(self.synthesis_s, 3)}


def design_seal_scheduled(cfg, parameter: str | None = None, *,
                          range_factor: tuple[float, float] = (0.0, 3.0), n_grid: int = 3,
                          rate_factor_per_s: float = 0.1, weights: Weights | None = None,
                          states: int | None = None, cache_dir: str | os.PathLike | None = None,
                          spec: DesignSpec | None = None, **lpvsyn_kw) -> SealScheduledDesign:
    """H∞ LPV controller scheduled on a seal coefficient (module docstring).

    Parameters
    ----------
    cfg : RigConfig
        The rig, at its ``[operating]`` pressure and speed.
    parameter : str, optional
        An LFT parameter of the rig; default the first seal's cross-coupled stiffness k.
    range_factor : (float, float)
        The scheduling range as multiples of θ at the operating pressure.
    n_grid : int
        Design grid points (≥ 2), equally spaced over the range; the controller table and
        its check have :data:`TABLE_INTERVALS` + 1 entries (``check_density`` of
        :func:`~ambseal.robust.lpv.lpvsyn` ⌈TABLE_INTERVALS/(n_grid − 1)⌉ unless given).
    rate_factor_per_s : float
        ν as a multiple of θ at the operating pressure per second.
    weights : Weights, optional
        Default: the specification's ``hinf`` weights (its scalings) with M, ω_B and W_u
        of :data:`M_TRACKED`, :data:`OMEGA_B_TRACKED`, :data:`WU_TRACKED`.
    states : int, optional
        Mechanical states of the design model (default the specification's).
    cache_dir : path, optional
        Folder of cached designs (default ``$AMBSEAL_CACHE_DIR``; neither: no cache).
    spec : DesignSpec, optional
        The rig's design specification (weights, design model, band); built from ``cfg`` by
        :func:`~ambseal.design.specs.design_spec` when omitted.
    **lpvsyn_kw
        Passed to :func:`ambseal.robust.lpv.lpvsyn`.

    Returns
    -------
    SealScheduledDesign

    Raises
    ------
    ModelError
        No seal, a parameter without a channel, a zero scale.
    SynthesisError
        From :func:`lpvsyn` (infeasible LMIs, an unstable frozen loop), or ``n_grid`` < 2.
    """

    if parameter is None:
        if not cfg.seal:
            raise ModelError("design_seal_scheduled: the rig has no [[seal]] to schedule on")
        parameter = f"{cfg.seal[0].name}.k"
    if int(n_grid) < 2:
        raise SynthesisError(f"design_seal_scheduled: n_grid={n_grid}; needs at least 2")
    sp = spec or design_spec(cfg)
    n = int(states or sp.model_states)
    plant = build_plant(cfg, reduced=True, pressure_bar=cfg.operating.pressure_bar, states=n)
    scale = abs(plant.parameter(parameter).nominal)  # ModelError naming the known ones
    if not scale > 0:
        raise ModelError(f"design_seal_scheduled: {parameter} is 0 at the operating "
                         "pressure; no scale for its range")
    w = weights or replace(sp.weights["hinf"], M=M_TRACKED, omega_b=OMEGA_B_TRACKED,
                           wu_gain=WU_TRACKED)
    lpvsyn_kw.setdefault("check_density", -(-TABLE_INTERVALS // (int(n_grid) - 1)))
    dl = design_delay(cfg.controller.sample_rate_hz, cfg.controller.delay_samples,
                      sp.synthesis_band_hz[1], max_order=1)
    args = (parameter, tuple(map(float, range_factor)), int(n_grid), float(rate_factor_per_s),
            w, n, sorted(lpvsyn_kw.items()), dl.to_dict())
    folder = cache_dir or os.environ.get(CACHE_ENV)
    key = _key(cfg, args)
    path = Path(folder) / f"seal_scheduled-{key}.json" if folder else None
    cached = _read_cache(path, key) if path is not None else None
    if cached is not None:
        return cached
    d = _synthesise(cfg, plant, args, scale, dl, lpvsyn_kw)
    if path is not None:
        _write_cache(path, key, d)
    return d


#: The version of what a cached design depends on besides the rig and the arguments (this
#: recipe, its weights and plant, :func:`~ambseal.robust.lpv.lpvsyn`): raise it with any
#: change that moves a scheduled design's numbers, and every cached design is recomputed.
SYNTHESIS_VERSION = 2


def _key(cfg, args) -> str:
    """Cache key: the rig, the arguments, the package version and
    :data:`SYNTHESIS_VERSION`."""

    h = hashlib.sha256(cfg.digest())
    h.update(f"ambseal {__version__} synthesis {SYNTHESIS_VERSION}".encode())
    h.update(repr(args).encode())
    return h.hexdigest()[:20]


_TABLE = ("AK", "BK", "CK", "DK")


def _write_cache(path: Path, key: str, d: SealScheduledDesign) -> None:
    """Keep ``d`` as JSON at ``path`` (the key and version inside); a design with a
    non-finite number is not kept (strict JSON has none), nor one the folder cannot take
    (a warning names it)."""
    K = d.K
    doc = {"key": key, "ambseal_version": __version__, "parameter": d.parameter,
           "gamma": d.gamma, "gamma_design": d.gamma_design, "rate_bound": d.rate_bound,
           "synthesis_s": d.synthesis_s, "design_states": d.design_states,
           "range_factor": list(d.range_factor), "delay": d.delay,
           "weights": asdict(d.weights), "grid": d.grid.tolist(),
           "check_grid": d.check_grid.tolist(), "check_gamma": d.check_gamma.tolist(),
           "K": {"theta": K.theta.tolist(),
                 **{k: np.asarray(getattr(K, k)).tolist() for k in _TABLE},
                 "input_names": list(K.input_names), "output_names": list(K.output_names)}}
    try:
        path.parent.mkdir(parents=True, exist_ok=True)
        write_json(path, doc)
    except ValueError:  # a NaN, which strict JSON cannot hold: the design is still returned
        pass
    except (OSError, AmbsealError) as exc:  # a read-only cache: the run goes on without it
        warnings.warn(f"design cache {str(path.parent)!r}: the design is not kept "
                      f"({exc})", stacklevel=3)


def _floats(x, ndim: int) -> np.ndarray:
    """A finite float array of ``ndim`` dimensions from JSON lists, else ValueError."""
    a = np.asarray(x, dtype=float)
    if a.ndim != ndim or not np.all(np.isfinite(a)):
        raise ValueError(f"expected a finite {ndim}-d array")
    return a


def _read_cache(path: Path, key: str) -> SealScheduledDesign | None:
    """The design kept at ``path`` for ``key``, or None when there is none or it is not a
    consistent entry of this key and package version (it is then recomputed)."""
    try:
        if not path.is_file() or path.stat().st_size > 64 * 2**20:
            return None
        doc = json.loads(path.read_text(encoding="utf-8"))
        if doc["key"] != key or doc["ambseal_version"] != __version__:
            return None
        K, w = _cached_controller(doc["K"]), _cached_weights(doc["weights"])
        if K is None or w is None:
            return None
        scalars = [float(doc[f]) for f in ("gamma", "gamma_design", "rate_bound",
                                           "synthesis_s")]
        rf = tuple(float(x) for x in doc["range_factor"])
        if not all(map(math.isfinite, scalars + list(rf))) or len(rf) != 2 or \
                not isinstance(doc["delay"], dict):
            return None
        return SealScheduledDesign(
            str(doc["parameter"]), K, scalars[0], scalars[1], _floats(doc["grid"], 1),
            _floats(doc["check_grid"], 1), _floats(doc["check_gamma"], 1), scalars[2], w,
            scalars[3],
            int(doc["design_states"]), rf, dict(doc["delay"]))
    except (OSError, ValueError, TypeError, KeyError, IndexError, AttributeError,
            RecursionError):
        return None


def _cached_controller(k: dict) -> LpvController | None:
    """The controller table of a cache entry, or None where its shapes disagree."""
    W, (A, B, C, D) = _floats(k["theta"], 1), (_floats(k[n], 3) for n in _TABLE)
    n_t, n = W.size, A.shape[1]
    ins, outs = [str(s) for s in k["input_names"]], [str(s) for s in k["output_names"]]
    if not (A.shape == (n_t, n, n) and B.shape == (n_t, n, len(ins))
            and C.shape == (n_t, len(outs), n) and D.shape == (n_t, len(outs), len(ins))):
        return None
    return LpvController(W, A, B, C, D, tuple(ins), tuple(outs))


def _cached_weights(wd: Any) -> Weights | None:
    """The weights of a cache entry: every field of :class:`Weights` and nothing else, each
    a number, a string, a list of numbers or null; None otherwise."""
    if not isinstance(wd, dict) or set(wd) != {f.name for f in fields(Weights)} or not all(
            v is None or isinstance(v, (int, float, str)) and not isinstance(v, bool)
            or isinstance(v, list) and all(isinstance(x, (int, float)) for x in v)
            for v in wd.values()):
        return None
    return Weights(**{f: (tuple(v) if isinstance(v, list) else v) for f, v in wd.items()})


def _synthesise(cfg, plant, args, scale: float, dl, lpvsyn_kw) -> SealScheduledDesign:
    """lpvsyn over the grid of θ (the design model at each grid value, the controller's
    delay ``dl`` in its actuator path)."""

    parameter, rf, n_grid, rate, w, n = args[:6]
    t0 = time.perf_counter()
    grid = np.linspace(rf[0] * scale, rf[1] * scale, n_grid)
    gps = [generalized_plant(plant.with_values(values_following_k(
        cfg.seal, parameter, th, plant.parameters)), w.Wp(), w.Wu(), d_e=w.d_e, d_u=w.d_u,
        actuator_delay=dl.system) for th in grid]
    nu = rate * scale
    r = lpvsyn([g.P_nominal for g in gps], grid, gps[0].nmeas, gps[0].ncon,
               lyapunov="affine", rate_bound=nu, **lpvsyn_kw)
    return SealScheduledDesign(parameter, r.K, r.gamma, r.gamma_design, grid,
                               r.check_grid, r.check_gamma, nu, w,
                               time.perf_counter() - t0, n, rf, dl.to_dict())
