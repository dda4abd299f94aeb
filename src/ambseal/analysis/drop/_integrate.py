"""The drop's integration: from event to event (each plane's contact onset and end, a
digital controller's samples), the explicit method handing over to the stiff one where it
crawls, the peaks read between the integrator's steps, and the refusal of a crushed ring
(the package's docstring, :mod:`ambseal.analysis.drop`)."""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy.integrate import solve_ivp

from ambseal.analysis.drop._rhs import DropDynamics
from ambseal.errors import ConfigError
from ambseal.model import normal_force

#: integration segments (one per contact onset or end) after which a drop is refused:
#: a contact chattering at the integrator's resolution
MAX_SEGMENTS = 100_000
#: an explicit method gives way to STIFF_METHOD for the rest of the drop when a segment,
#: past CRAWL_EVALUATIONS right-hand sides, advances less than one period of the highest
#: mode kept per CYCLE_EVALUATIONS of them (the package's docstring)
EXPLICIT = ("RK23", "RK45", "DOP853")
STIFF_METHOD = "LSODA"
CRAWL_EVALUATIONS = 20_000
CYCLE_EVALUATIONS = 1000
#: the points in each integrator step at which the peak force and penetration are read
PEAK_POINTS = 8
#: the penetration, as a fraction of the journal's radius, that ends a drop with a
#: refusal (the package's docstring): Hertz's and Palmgren's laws are those of a contact
#: small against the bodies' radii (Johnson, Contact Mechanics, 1985, §4.2: the
#: half-space premise), and a penetration δ = a²/R of 1 % of the radius is a contact a
#: tenth as wide as the radius, where the premise ends (steel yields far earlier: ISO 76's
#: C₀)
CRUSHED = 0.01


class _Crawling(Exception):
    """An explicit integration step size collapsed (the friction's stick is stiff)."""


@dataclass
class Trajectory:
    """What the integration leaves: the output samples and the peaks between them.

    Attributes
    ----------
    t : list of float
        Output sample times (s), from 0.
    y : list of ndarray
        The state at each.
    peak_force, peak_delta, first_peak, peak_ax_force, peak_ax_delta : ndarray, shape (p,)
        Each plane's largest normal force (N) and penetration (m) read at the
        integrator's steps, its first contact's largest force, and the axial ones.
    impacts : int
        Contact onsets, radial and axial.
    integrator : str
        The method, and where it gave way to the stiff one.
    """

    t: list
    y: list
    peak_force: np.ndarray
    peak_delta: np.ndarray
    first_peak: np.ndarray
    peak_ax_force: np.ndarray
    peak_ax_delta: np.ndarray
    impacts: int = 0
    integrator: str = ""


def crushed(dyn: DropDynamics, t: float, k: int) -> ConfigError:
    """The refusal of a drop whose plane (radial k < P, else the k − P-th axial stop) was
    pressed :data:`CRUSHED` × its journal's radius deep at t."""
    dm, P = dyn.dm, dyn.P
    p, law, how = ((k, dm.laws[k], "") if k < P else
                   (dyn.stops[k - P], dm.axial_laws[dyn.stops[k - P]], "axial "))
    delta = CRUSHED * dm.journal[p]
    return ConfigError(
        f"drop: at t = {1e3 * t:.4g} ms the journal is pressed {1e6 * delta:.4g} µm "
        f"into the {how}ring of {dm.names[p]} ({100 * CRUSHED:g} % of its "
        f"{1e3 * dm.journal[p]:.4g} mm radius) under "
        f"{law.stiffness * delta ** law.exponent:.3g} N, where the elastic contact "
        "law ends (a contact a tenth as wide as the radius) and long after steel "
        "yields: loads that crush the rings — a seal surge, an overload, the thrust — "
        "leave no drop to simulate")


def contact_events(dyn: DropDynamics, touching: list) -> list:
    """Each plane's radial contact onset or end, then each axial stop's (``touching``:
    the radial planes' flags, then the stops'), then each plane's and stop's penetration
    reaching :data:`CRUSHED` of its journal's radius (the drop's end)."""
    dm, L, P = dyn.dm, dyn.layout, dyn.P
    evs = []
    for deep in (0.0, CRUSHED):
        for p in range(P):
            def g(t, y, p=p, deep=deep):
                eta, _, _, s, _ = L.unpack(y)
                r = dm.planes[p] @ eta - s[p]
                return math.hypot(r[0], r[1]) - dm.clearance[p] - deep * dm.journal[p]
            g.terminal = True
            g.direction = -1.0 if not deep and touching[p] else 1.0
            evs.append(g)
        for k, p in enumerate(dyn.stops if dyn.axial else ()):
            def g(t, y, p=p, deep=deep):
                return abs(y[L.i_ax]) - dyn.c_ax[p] - deep * dm.journal[p]
            g.terminal = True
            g.direction = -1.0 if not deep and touching[P + k] else 1.0
            evs.append(g)
    return evs


def paced(fn, start: float, pace: float):
    """``fn``, counting its evaluations: past CRAWL_EVALUATIONS, a segment advancing less
    than ``pace`` (s) per evaluation raises _Crawling."""
    count = [0]

    def f(t, y):
        count[0] += 1
        if count[0] > CRAWL_EVALUATIONS and t - start < pace * count[0]:
            raise _Crawling
        return fn(t, y)
    return f


def _read_peaks(dyn: DropDynamics, r, run: Trajectory, touching, first_over) -> None:
    """The peaks between the integrator's own steps of segment ``r`` (PEAK_POINTS in
    each, from its dense output): a contact shorter than the output's sampling is not
    missed."""
    dm, L, m = dyn.dm, dyn.layout, dyn.m
    steps = np.asarray(r.t, float)
    frac = np.linspace(0.0, 1.0, PEAK_POINTS + 1)[:-1]
    tf = np.append((steps[:-1, None] + np.diff(steps)[:, None] * frac).ravel(), steps[-1])
    Yf = np.asarray(r.sol(tf)).reshape(L.size, -1)
    for p in range(dyn.P):
        rel = dm.planes[p] @ Yf[:m]
        vel = dm.planes[p] @ Yf[m:2 * m]
        if p in L.supported:
            k = L.support_at(L.supported.index(p))
            rel, vel = rel - Yf[k:k + 2], vel - Yf[k + 2:k + 4]
        d = np.hypot(rel[0], rel[1])
        delta = d - dm.clearance[p]
        rate = np.einsum("ij,ij->j", rel, vel) / np.where(d > 0, d, 1.0)
        law = dm.laws[p]
        N = normal_force(delta, rate, law.stiffness, law.exponent, law.damping(dyn.v0[p]))
        run.peak_force[p] = max(run.peak_force[p], float(N.max()))
        if touching[p] and not first_over[p]:
            run.first_peak[p] = max(run.first_peak[p], float(N.max()))
        run.peak_delta[p] = max(run.peak_delta[p], float(delta.max()))
    i_ax = L.i_ax
    for p in dyn.stops if dyn.axial else ():
        d_ax = np.abs(Yf[i_ax]) - dyn.c_ax[p]
        law = dm.axial_laws[p]
        N = normal_force(d_ax, np.sign(Yf[i_ax]) * Yf[i_ax + 1], law.stiffness,
                         law.exponent, law.damping(dyn.v0_ax[p]))
        run.peak_ax_force[p] = max(run.peak_ax_force[p], float(N.max()))
        run.peak_ax_delta[p] = max(run.peak_ax_delta[p], float(d_ax.max()))


def _onset(dyn: DropDynamics, k: int, y) -> None:
    """A radial contact's onset at plane ``k`` (else the ``k − P``-th axial stop's): its
    impact speed v₀, at least the floor's (the package's docstring)."""
    P, dm = dyn.P, dyn.dm
    if k >= P:
        p = dyn.stops[k - P]
        dyn.v0_ax[p] = max(abs(float(y[dyn.layout.i_ax + 1])), dyn.floor_ax[p])
        return
    eta, deta, _, s, ds = dyn.layout.unpack(y)
    rel = dm.planes[k] @ eta - s[k]
    n = rel / max(math.hypot(*rel), 1e-300)
    dyn.v0[k] = max(float(n @ (dm.planes[k] @ deta - ds[k])), dyn.floor[k])


def integrate(dyn: DropDynamics, y: np.ndarray, progress=None) -> Trajectory:
    """Integrate the drop from the state ``y`` at t = 0 to the event's duration, segment
    by segment (the package's docstring); ``progress(t_s)`` after each segment.

    Raises
    ------
    ConfigError
        A ring crushed (:func:`crushed`), a contact chattering past
        :data:`MAX_SEGMENTS`, or the integration failing.
    """
    event, P, loop = dyn.event, dyn.P, dyn.loop
    duration_s, rtol, method = event.duration_s, event.rtol, event.method
    grid = np.linspace(0.0, duration_s, event.samples)
    atol = dyn.tolerances()
    pace = 1.0 / (CYCLE_EVALUATIONS * dyn.dm.modes_hz)  # the slowest progress per rhs
    # a start in contact (an ``initial`` state on a ring) waits for the contact's end
    start = dyn.contacts(0.0, y)
    touching = [c[1] > 0 for c in start] + [False] * (len(dyn.stops) if dyn.axial else 0)
    for p, c in enumerate(start):
        if c[1] >= CRUSHED * dyn.dm.journal[p]:
            raise crushed(dyn, 0.0, p)
    run = Trajectory([0.0], [y.copy()], *(np.zeros(P) for _ in range(5)),
                     integrator=method)
    first_over = [False] * P  # each plane's first contact ended
    t0, segments = 0.0, 0
    n_sample = 1  # the next sample of a digital controller
    while t0 < duration_s:
        if segments > MAX_SEGMENTS:
            raise ConfigError(f"drop: more than {MAX_SEGMENTS} contact onsets and ends by "
                              f"t = {t0:.6g} s (a contact chattering); lower rtol")
        # a digital controller's segments end at its samples
        t_end = (min(duration_s, n_sample * loop.sampled[4]) if dyn.digital
                 else duration_s)
        # a trial step far too long may overflow in the contact's power law; the
        # integrator rejects it (its error estimate is not finite) and halves the step
        with np.errstate(over="ignore", invalid="ignore"):
            try:
                r = solve_ivp(paced(dyn.rhs, t0, pace) if method in EXPLICIT else dyn.rhs,
                              (t0, t_end), y, method=method, dense_output=True,
                              events=contact_events(dyn, touching), rtol=rtol, atol=atol)
            except _Crawling:  # stiff: from here on, the stiff method (the package's docstring)
                method = STIFF_METHOD
                run.integrator += f" → {method} from {t0:.6g} s"
                r = solve_ivp(dyn.rhs, (t0, t_end), y, method=method, dense_output=True,
                              events=contact_events(dyn, touching), rtol=rtol, atol=atol)
        if not r.success or not np.isfinite(r.y).all():
            raise ConfigError(f"drop: the integration failed at t = {r.t[-1]:.6g} s "
                              f"({r.message}); lower rtol or modes_hz")
        sel = grid[(grid > t0) & (grid <= r.t[-1])]
        if sel.size:
            run.t.extend(sel.tolist())
            run.y.extend(np.asarray(r.sol(sel)).T)
        _read_peaks(dyn, r, run, touching, first_over)
        hit = [k for k, te in enumerate(r.t_events) if te.size]
        if not hit:
            if t_end >= duration_s:
                break
            t0, y = t_end, r.y[:, -1].copy()  # a sample instant
            dyn.sample(t0, y)
            n_sample += 1
            continue
        segments += 1
        k = min(hit, key=lambda k: r.t_events[k][0])
        t0 = float(r.t_events[k][0])
        if k >= len(touching):
            raise crushed(dyn, t0, k - len(touching))
        y = r.y_events[k][0].copy()
        touching[k] = not touching[k]
        if k < P:
            first_over[k] = first_over[k] or not touching[k]
        if touching[k]:
            run.impacts += 1
            _onset(dyn, k, y)
        if progress is not None:
            progress(t0)
    return run
