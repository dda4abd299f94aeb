"""The filters a commissioning engineer adds to a flexible rotor's PID: a phase lead or lag,
or a notch, per flexible mode the PID's loop leaves under-damped as it runs.

A decentralised PID (thesis P5 Eq. 6) is tuned on the rigid-body modes; on a flexible rotor
its derivative action, the target's hold and computation delay and the actuator decide
the phase the controller has at each bending mode, and the mode's shapes at the sensors
and actuators decide which phase damps it (Schweitzer & Maslen, *Magnetic Bearings*, 2009,
the control of flexible rotors): a mode whose sensor and actuator move together (collocated) is damped by
phase lead, one whose sensor and actuator lie on opposite sides of a node (non-collocated)
by phase lag, and a mode whose phase cannot be put right within a filter's reach is
gain-stabilised by a notch. A mode with a node at the sensors or actuators is neither
observed nor driven: the loop leaves it at its structural damping and it needs no filter.

The rule (:func:`flexible_mode_filters`), on the plants of every judged condition
(pressures × speeds from standstill to the top speed), each closed with the PID discretised
as it runs (Tustin, the target's delay, the plant sampled by its hold):

1. Where the PID loses a rigid-body pole (ζ ≤ 0 below twice the rigid-body frequency)
   no filter of a flexible mode saves it, and the judgement says so; that condition's
   flexible poles still count (no filter is chosen at all where every condition loses
   one). The least-damped pole below the floor ζ ≥ ``floor`` above twice the rigid-body
   frequency is the mode to treat; its band is the spread of the under-damped poles within
   a factor :data:`BAND_FACTOR` of its frequency over the conditions (the gyroscopic split
   with speed, the seals' shift with pressure).
2. Its first-order shift under the loop, Δλ = −k(λ)·r with r = w*ᵀ B C v the mode's residue
   summed over the axes (v, w its right and left eigenvectors, k the PID with its filters
   and the delay e^(−λτ), τ = (delay + ½)/f_s), damps it when |arg(k r)| < 90°: the phase
   the mode needs is −arg(k r) (Re(j r) > 0: collocated).
3. Candidates, in this order: a lead or lag (the sign of the needed phase) of each of
   :data:`PHASE_STEPS_DEG` at the band's centre, the smallest that covers the need first;
   then notches of :data:`NOTCH_DEPTHS_DB` over the band. A candidate with a pole above
   the Nyquist frequency f_s/2 is left out, and the mode's text says so: the target
   cannot run it (a lead's pole lies at f_c·√α, 2.4× its centre at 45°; a lag's and a
   notch's at or below their centre, which is below Nyquist). Each is judged on every
   condition; the first that keeps the floor at every condition is taken, else the one
   with the most conditions kept and then the largest least damping, if it betters the
   loop without it.
   Where none betters it (a notch's phase lag below its centre upsets a mode below), the
   best :data:`LOOKAHEAD` are each tried with the best filter for the mode they upset,
   and the first pair that betters the loop is taken.
4. Repeat on the next under-damped mode, at most :data:`MAX_FILTERS` filters.

The result names each mode, its band, whether it is collocated, the phase it needed and
the filter taken, or the mode that defeats every candidate and why.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from ambseal.lti import feedback_matrices, zoh
from ambseal.robust import discretize_as, with_delay

__all__ = ["ModeFilter", "FilterDesign", "flexible_mode_filters", "MAX_FILTERS",
           "PHASE_STEPS_DEG", "NOTCH_DEPTHS_DB", "BAND_FACTOR"]

#: filters at most: one per treated mode
MAX_FILTERS = 4
#: the lead or lag phases tried (°): past 75° the corner frequencies lie 50× apart and the
#: filter's gain change reaches the rigid-body crossover
PHASE_STEPS_DEG = (30.0, 45.0, 60.0, 75.0)
#: the notch depths tried (dB)
NOTCH_DEPTHS_DB = (20.0, 40.0)
#: under-damped poles within this factor of the treated mode's frequency are its band
BAND_FACTOR = 1.25
#: a notch's width: the band widened by this factor, at least this fraction of its centre
NOTCH_WIDEN, NOTCH_MIN_WIDTH = 1.5, 0.1
#: the most a filter may lower the least damping ratio of the rigid-body poles
RIGID_COST = 0.02
#: where no single filter betters the loop, the best this many are tried with a second
#: filter for the mode they upset
LOOKAHEAD = 3


@dataclass(frozen=True)
class ModeFilter:
    """One treated mode: its frequency and band (Hz), least damping before and after,
    whether it is collocated, the phase it needed (°) and the filter taken (None if no
    candidate helped)."""

    frequency_hz: float
    band_hz: tuple
    zeta_before: float
    zeta_after: float
    collocated: bool
    needed_phase_deg: float
    filter: dict | None
    #: the candidates left out because a pole lies above the Nyquist frequency, and it (Hz)
    left_out: tuple = ()
    nyquist_hz: float = float("inf")

    def text(self) -> str:
        where = "collocated" if self.collocated else "non-collocated"
        head = (f"{self.frequency_hz:.4g} Hz mode ({where}, ζ {self.zeta_before:.2g}, "
                f"{self.needed_phase_deg:+.0f}° of phase needed)")
        if self.filter is None:
            text = head + ": no lead, lag or notch keeps it damped"
        else:
            f = self.filter
            text = f"{head}: {_name(f)} at {f['frequency_hz']:.4g} Hz → ζ {self.zeta_after:.2g}"
        if self.left_out:
            text += (" (left out: " + ", ".join(
                f"{_name(c)} at {c['frequency_hz']:.4g} Hz, its pole at {_pole_hz(c):.4g} Hz"
                for c in self.left_out)
                + f" above the Nyquist frequency {self.nyquist_hz:.4g} Hz, which the "
                  "target cannot run)")
        return text


def _name(f: dict) -> str:
    return (f"notch {f['depth_db']:g} dB, {f['width_hz']:.3g} Hz wide" if f["kind"] == "notch"
            else f"{f['kind']} {f['phase_deg']:g}°")


def _pole_hz(f: dict) -> float:
    """The highest pole (Hz) of a lead, lag or notch of :func:`_candidates` (the formulas
    of :func:`ambseal.design.pid.filter_matrices`): a lead's at f_c·√α, a lag's at
    f_c/√α, a notch's at f_c (its width is below twice its centre: complex poles of
    modulus ω_c)."""
    if f["kind"] in ("lead", "lag"):
        s = np.sin(np.radians(f["phase_deg"]))
        root = np.sqrt((1 + s) / (1 - s))
        return float(f["frequency_hz"] * (root if f["kind"] == "lead" else 1 / root))
    return float(f["frequency_hz"])


@dataclass(frozen=True)
class FilterDesign:
    """The filters (``[[controller.filter]]`` dicts, in order), the modes treated, and
    whether every condition keeps the floor as it runs."""

    filters: tuple
    modes: tuple
    kept: bool
    least_zeta: float


def _zeta_z(z: np.ndarray) -> np.ndarray:
    """Damping ratios of discrete poles z (of s = ln z / T); z ≈ 0 counts as ζ = 1."""
    r = np.log(np.maximum(np.abs(z), 1e-300))
    return -r / np.maximum(np.hypot(r, np.angle(z)), 1e-300)


def flexible_mode_filters(plants, pid_matrices, fs: float, delay: int, floor: float,
                          rigid_hz: float) -> FilterDesign:
    """The filters of the rule (module docstring) for a PID on the given plants.

    Parameters
    ----------
    plants : sequence of (A, B, C, D)
        Continuous plants from the current references (A) to the displacements (m), one
        per judged condition, square (one input per output axis); a modal reduction up to
        the Nyquist frequency is enough to choose (the run judges the full order).
    pid_matrices : callable
        ``filters → (A_K, B_K, C_K, D_K)``: the continuous PID with those filters in
        series, inputs and outputs as the plants' outputs and inputs (u = −K y).
    fs : float
        Sample rate (Hz).
    delay : int
        Computation delay (samples).
    floor : float
        Least damping ratio kept as it runs (-).
    rigid_hz : float
        The PID's rigid-body mode (Hz): poles below twice it are no filter's to treat.

    Returns
    -------
    FilterDesign
    """

    T = 1.0 / fs
    sampled = [((*zoh(np.asarray(A, float), np.asarray(B, float), T), C, D), (A, B, C, D))
               for A, B, C, D in plants]

    def judge(filters):
        """Per condition: (every flexible pole ζ ≥ floor, their least ζ, the least ζ of the
        rigid-body poles, the under-damped flexible poles (f, ζ), all flexible poles)."""
        Kd = with_delay(discretize_as(pid_matrices(filters), T, "tustin"), delay)
        rows = []
        for Gd, _ in sampled:
            z = np.linalg.eigvals(feedback_matrices(Gd, Kd)[0])
            zeta = _zeta_z(z)
            f = np.abs(np.angle(z)) * fs / (2 * np.pi)
            flex = f > 2 * rigid_hz
            low = flex & (zeta < floor)
            rows.append((not low.any(), float(zeta[flex].min(initial=1.0)),
                         float(zeta[~flex].min(initial=1.0)),
                         list(zip(f[low].tolist(), zeta[low].tolist())),
                         list(zip(f[flex].tolist(), zeta[flex].tolist()))))
        return rows

    def score(rows):
        return (sum(r[0] for r in rows), min(r[1] for r in rows))

    def rigid(rows):
        return min(r[2] for r in rows)

    def treat(filters, rows):
        """The mode to treat next (least ζ, frequency, band, condition) and its candidate
        filters judged (those that spare the rigid-body modes), or None."""
        bad = [(z, f, k) for k, r in enumerate(rows) for f, z in r[3]]
        if not bad:
            return None
        z0, f0, k0 = min(bad)
        band = [f for z, f, _ in bad if f0 / BAND_FACTOR <= f <= f0 * BAND_FACTOR]
        lo, hi = min(band), max(band)
        need, collocated = _needed_phase(sampled[k0][1], pid_matrices(filters), f0, fs, delay)
        cands = _candidates(float(np.sqrt(lo * hi)), lo, hi, need)
        # a filter the target cannot run is no candidate: the PID must run at f_s
        runs = [c for c in cands if _pole_hz(c) <= fs / 2]
        judged = [(c, judge(filters + [c])) for c in runs]
        # a filter for a flexible mode must not take the rigid-body modes' damping
        judged = [(c, r) for c, r in judged if rigid(r) >= rigid(rows) - RIGID_COST]
        left = tuple(c for c in cands if _pole_hz(c) > fs / 2)
        return ModeFilter(f0, (lo, hi), z0, z0, collocated, need, None, left, fs / 2), judged

    def mode_after(m, c, r):
        lo, hi = m.band_hz
        after = min([zz for x in r for f, zz in x[4]
                     if lo / BAND_FACTOR <= f <= hi * BAND_FACTOR] or [np.nan])
        return replace(m, filter=c, zeta_after=float(after))

    filters: list[dict] = []
    modes: list[ModeFilter] = []
    rows = judge(filters)
    # where the PID loses a rigid-body mode no filter of a flexible mode saves the loop
    # (the judgement says so); its flexible modes still count, since a filter chosen
    # without them may drive them (a lead taken at standstill drove a bending mode at
    # the top speed, where a precession was lost without it and held with it)
    if not any(r[2] > 0 for r in rows):
        return FilterDesign((), (), False, float("nan"))
    while len(filters) < MAX_FILTERS:
        found = treat(filters, rows)
        if found is None:
            break
        mode, judged = found
        done = [(c, r) for c, r in judged if all(x[0] for x in r)]
        ranked = sorted(judged, key=lambda cr: score(cr[1]), reverse=True)
        if done:
            steps = [(mode, *done[0])]
        elif ranked and score(ranked[0][1]) > score(rows):
            steps = [(mode, *ranked[0])]
        else:
            # a filter that treats this mode may upset the next one (a notch's phase lag
            # below its centre): the pair that betters the loop, the best first ones tried
            steps = []
            for c, r in ranked[:LOOKAHEAD] if len(filters) + 2 <= MAX_FILTERS else ():
                nxt = treat(filters + [c], r)
                better = [(c2, r2) for c2, r2 in (nxt[1] if nxt else ())
                          if score(r2) > score(rows)]
                if better:
                    c2, r2 = max(better, key=lambda cr: score(cr[1]))
                    steps = [(mode, c, r), (nxt[0], c2, r2)]
                    break
            if not steps:
                modes.append(mode)
                break
        for m, c, r in steps:
            filters.append(c)
            modes.append(mode_after(m, c, steps[-1][2]))
        rows = steps[-1][2]
    return FilterDesign(tuple(filters), tuple(modes), all(r[0] for r in rows),
                        min(r[1] for r in rows))


def _needed_phase(G, K, f0: float, fs: float, delay: int) -> tuple[float, bool]:
    """The phase (°) the controller needs at the plant mode nearest ``f0`` Hz for its
    first-order shift to damp it, and whether the mode is collocated (module docstring,
    step 2)."""
    A, B, C, _ = (np.asarray(X, float) for X in G)
    lam, V = np.linalg.eig(A)
    k = int(np.argmin(np.abs(lam - 2j * np.pi * f0)))
    w = np.linalg.solve(V.T, np.eye(A.shape[0])[k])  # the k-th row of V⁻¹
    r = complex(w @ B @ C @ V[:, k])
    s = lam[k]
    Ak, Bk, Ck, Dk = (np.asarray(X, float) for X in K)
    kk = Ck @ np.linalg.solve(s * np.eye(Ak.shape[0]) - Ak, Bk) + Dk
    # every axis has the same PID: its diagonal entry, delayed by the hold and the target
    ks = complex(kk[0, 0]) * np.exp(-s * (delay + 0.5) / fs)
    phase = -np.degrees(np.angle(ks * r))
    return float(phase), bool((1j * r).real > 0)


def _candidates(centre: float, lo: float, hi: float, need: float) -> list[dict]:
    """The filters tried for a mode (module docstring, step 3), in the rule's order."""
    kind = "lead" if need > 0 else "lag"
    steps = sorted(PHASE_STEPS_DEG, key=lambda p: (p < abs(need), p if p >= abs(need) else -p))
    out = [{"kind": kind, "frequency_hz": centre, "phase_deg": p} for p in steps]
    width = min(max(NOTCH_WIDEN * (hi - lo), NOTCH_MIN_WIDTH * centre), 1.9 * centre)
    out += [{"kind": "notch", "frequency_hz": centre, "width_hz": width, "depth_db": d}
            for d in NOTCH_DEPTHS_DB]
    return out
