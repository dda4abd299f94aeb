"""What the judged unbalance response asks of each AMB's amplifier.

The judgement bounds the synchronous orbit over every distribution of an unbalance force
of amplitude F_u over the bearing planes (:mod:`ambseal.analysis.unbalance`): by default
forward-turning forces f = T c on the loop at the running speed Ω, else (the thesis's
frozen plant) every force f. The control current the loop commands for that force is
i = −K S_o G_f f, so the current reference of axis a, over the same forces, is at most

    i_ref,a(Ω) = ‖(K S_o G_f T)(jΩ)_a,:‖₂ · F_u(Ω)      (T = I for every force)

(the row's Euclidean norm: the worst distribution for that axis), and its coil current
i_c = |H_a(jΩ)|·i_ref with H_a the amplifier's current loop (``[actuator]``,
:func:`ambseal.model.amb.actuator_matrices`). Set against the bearing's limits
(:func:`ambseal.model.capacity.amplifier_use`: the linear range i0, ``current_limit``,
``supply_voltage`` through R and L) this is the fraction of each limit the controller uses to
hold the unbalance; above 1 the amplifier saturates (Schweitzer & Maslen, *Magnetic
Bearings*, 2009, ch. 5 and 15). The largest current and voltage over the judged conditions
(:func:`ambseal.model.capacity.amplifier_needs`) are the smallest amplifier that holds it,
per AMB: its sizing. A discrete loop's current is taken at its samples (the
held value's fundamental is sinc(ΩT/2π) ≤ 1 of it: the fractions err on the safe side).

The judged current-impulse response (P5 §5.1) is held to the same limits: the amplifier
drives the current reference −K y plus the injected impulse, held over each step of the
response; its coil current i and rate di/dt follow from the current loop H_a integrated
exactly over each step (at a step's start, where a held input makes |di/dt| largest), and
the coils need R i0 + |R i + L di/dt| (:func:`ambseal.model.capacity.transient_needs`). An
ideal current loop (``[actuator] model = "none"``) steps the current instantly: the
impulse's current is judged, its voltage not.

A seal the rotor runs offset in (``static_eccentricity``) loads the bearings statically:
the loop holds it with a static control current i_s per axis
(:func:`ambseal.analysis.judge.static_currents`, the worst over the offset's direction),
on which the unbalance's and the impulse's currents ride: the amplifier drives
|i_s| + i_c and its coils need R (i0 + |i_s|) plus the dynamic voltage — the static load
takes its share of the bias's linear range, the current limit and the supply.

A controller that runs with its unbalance force rejection (``[design.rejection]``,
:mod:`ambseal.design.synchronous_rejection`) holds the unbalance with the synchronous
current its notch leaves wherever the notch is on (:func:`notched_currents`): the notch
removes the synchronous component from the control current, the rotor then turns about its
axis of inertia (Herzog et al., IEEE TCST 4(5), 1996; Schweitzer & Maslen 2009, ch. 15),
and the run's effect of the notch (:func:`ambseal.analysis.rejection.rejection_effect`)
gives what is left. Below the notch's speed the controller alone holds it.
"""

from __future__ import annotations

import numpy as np

from ambseal.analysis.tolerance import beyond
from ambseal.lti import freqresp_at, zoh
from ambseal.model import (AXES, actuator_matrices, amb_factors, amplifier_needs,
                           axis_label, coil_inductance, limits_used, transient_needs)

__all__ = ["unbalance_currents", "notched_currents", "impulse_coil_currents", "force_demand",
           "capacity_block", "capacity_words", "saturates", "used_by_speed", "switch_on_hz",
           "later_switch_on_hz", "SWITCH_ON_FRACTION"]

#: The largest fraction of its amplifier the controller alone may use where an unbalance
#: force rejection switches on below the continuous speeds (:func:`switch_on_hz`).
SWITCH_ON_FRACTION = 0.5

#: Why a sizing has no supply voltage (``supply_voltage_note``, :func:`capacity_block`).
NO_COIL = ("the rig file gives neither the coil's inductance nor its geometry (turns, "
           "pole_area, air_gap)")
IDEAL_LOOP = ("only the current impulse was judged, on an ideal current loop ([actuator] "
              "model = \"none\"), whose step no finite voltage drives")
#: The fractions of :func:`ambseal.model.capacity.amplifier_use`, as metrics.json names them,
#: and what each is a fraction of, in words.
QUANTITIES = ("current_used", "voltage_used", "bias_used")
_LIMITS = {"voltage_used": "the supply voltage", "current_used": "the current limit",
           "bias_used": "the bias current's linear range"}
#: What the controller holds in each judged response :func:`capacity_block` takes, in words.
_HOLDING = {"unbalance": "holding the unbalance", "impulse": "in the current impulse"}


def unbalance_currents(Kw: np.ndarray, H: np.ndarray, force_n: np.ndarray) -> np.ndarray:
    """The current reference (A, amplitude) each axis commands against the worst-case
    unbalance (module docstring).

    Parameters
    ----------
    Kw : ndarray of complex, shape (F, nu, ny)
        The controller at each speed (``jΩ`` or ``e^{jΩT}``).
    H : ndarray of complex, shape (F, ny, nf)
        ``S_o G_f`` at the same points (the compliance, m/N).
    force_n : ndarray, shape (F,)
        The unbalance force amplitude F_u (N) at each speed.

    Returns
    -------
    ndarray, shape (F, nu)
    """
    return np.linalg.norm(Kw @ H, axis=2) * np.asarray(force_n, float)[:, None]


def notched_currents(entries, on_hz: float, left_a: float):
    """The unbalance's current references of :func:`capacity_block`'s ``entries`` with an
    unbalance force rejection on from ``on_hz`` up (module docstring): at those speeds every
    axis's reference is ``left_a``, below them the controller's alone.

    Parameters
    ----------
    entries : iterable of (str, ndarray, ndarray, sequence of str, dict or None)
        As :func:`capacity_block`'s, the controller alone.
    on_hz : float
        The speed (Hz) the notch is on from.
    left_a : float
        The synchronous current (A, amplitude) the notch leaves, the largest over the
        speeds it is on at (:func:`ambseal.analysis.rejection.rejection_effect`'s
        ``current_a["with"]``), ≥ 0.

    Yields
    ------
    tuple
        Each entry with its current references replaced where the notch is on.
    """
    for label, speed_hz, i_ref, names, static in entries:
        i_ref = np.array(i_ref, float)
        i_ref[np.asarray(speed_hz, float) >= on_hz] = float(left_a)
        yield label, speed_hz, i_ref, names, static


def used_by_speed(cfg, entries) -> tuple[np.ndarray, np.ndarray]:
    """The largest fraction of an amplifier limit the controller uses to hold the unbalance
    at each judged speed, over every condition, AMB axis and limit (:func:`capacity_block`'s
    fractions, speed by speed).

    Parameters
    ----------
    cfg : RigConfig
        The rig: its ``[[amb]]`` limits (each with its ``bias_current``) and
        ``[actuator]``.
    entries : iterable of (str, ndarray, ndarray, sequence of str, dict or None)
        As :func:`capacity_block`'s.

    Returns
    -------
    speeds_hz : ndarray, shape (F,)
        Every speed of the entries (Hz), increasing.
    used : ndarray, shape (F,)
        The largest fraction at each (1 is a limit).
    """
    by_axis = {f"i_{amb.name}_{ax}": amb for amb in cfg.amb for ax in AXES}
    act = actuator_matrices(cfg.actuator)
    most: dict[float, float] = {}
    for _, speed_hz, i_ref, names, static in entries:
        f = np.asarray(speed_hz, float)
        gain = np.abs(freqresp_at(act, 2j * np.pi * f)[:, 0, 0])
        for a, name in enumerate(names):
            amb = by_axis[name]
            need = amplifier_needs(amb, 2 * np.pi * f, gain * np.asarray(i_ref)[:, a],
                                   static_a=(static or {}).get(name, 0.0))
            use = np.max([v for v in limits_used(amb, need).values() if v is not None],
                         axis=0)
            for fk, uk in zip(f.tolist(), use.tolist()):
                most[fk] = max(most.get(fk, 0.0), uk)
    speeds = np.array(sorted(most))
    return speeds, np.array([most[s] for s in speeds.tolist()])


def switch_on_hz(speeds_hz, used, continuous_hz: float) -> float:
    """The speed an unbalance force rejection switches on at: the minimum continuous speed,
    or below it where the controller alone saturates the amplifier on the way there.

    A rotor that runs up through a critical speed below its continuous speeds may need
    more current than its amplifier has to hold the unbalance there, whatever its
    controller: at the critical the bearings must balance the mode's share of the
    unbalance force (the supercritical example needs 1.34× the bias current's linear range
    at its 106 Hz bending critical under each of its three controllers). With the notch on
    the bearings let the rotor turn about its axis of inertia instead (Herzog et al.,
    IEEE TCST 4(5), 1996); whether that orbit fits the clearances and the notched loops
    hold is judged as at every other speed. The notch then switches on at the highest
    judged speed below the first saturated one where the controller alone uses at most
    :data:`SWITCH_ON_FRACTION` of its amplifier: a run-up that passes the switch-on speed
    faster than the notch settles (2/ε, ≈ 6 revolutions) leaves it the other half for
    the transient. Where no judged speed below it is that quiet, the lowest turning one.

    Parameters
    ----------
    speeds_hz, used : array_like, shape (F,)
        :func:`used_by_speed` of the controller alone.
    continuous_hz : float
        The minimum continuous speed (Hz, > 0), where the notch is on otherwise.

    Returns
    -------
    float
        The switch-on speed (Hz), at most ``continuous_hz``.
    """
    f, u = np.asarray(speeds_hz, float), np.asarray(used, float)
    first, quiet = _before_saturation(f, u, 0.0)
    if first is None or first >= continuous_hz:
        return float(continuous_hz)
    return quiet if quiet is not None else float(f[f > 0].min())


def later_switch_on_hz(speeds_hz, used, on_hz: float) -> float | None:
    """A later speed for an unbalance force rejection to switch on at, where on from
    ``on_hz`` it loses a loop or whirls the rotor beyond a clearance: the highest judged
    speed above ``on_hz`` and below the first one above it where the controller alone
    saturates the amplifier, at which the controller alone uses at most
    :data:`SWITCH_ON_FRACTION` of it (the rule of :func:`switch_on_hz`).

    Below it the controller alone holds the unbalance, and the notch is spared the speeds
    where it cannot run. A notch makes the bearings transparent at the rotational
    frequency, so there a rigid rotor turns on the AMBs' negative stiffness alone: its
    tilt φ = θ_ζ + jθ_η obeys It φ̈ − j Ip Ω φ̇ − κ φ = 0 (κ = Σ k_s,b (z_b − z_g)² > 0),
    and a synchronous whirl φ = e^{jΩt} solves it where (Ip − It) Ω² = κ. A disc-like
    rotor (Ip > It) meets that critical at a finite speed, and a notch on from the
    bottom of its range can meet it too (family seed 2 of ``benchmarks/bench_family.py``:
    Ip/It 1.09, κ/(Ip − It) at 163 Hz for the rigid rotor: its notch on from 191 Hz lost
    the loop at 191 Hz).

    Parameters
    ----------
    speeds_hz, used : array_like, shape (F,)
        :func:`used_by_speed` of the controller alone.
    on_hz : float
        The speed (Hz) the notch was on from.

    Returns
    -------
    float or None
        The later switch-on speed (Hz), or None where the controller alone saturates
        nowhere above ``on_hz`` (no notch is needed there) or uses more than
        :data:`SWITCH_ON_FRACTION` at every speed between.
    """
    return _before_saturation(np.asarray(speeds_hz, float), np.asarray(used, float),
                              float(on_hz))[1]


def _before_saturation(f: np.ndarray, u: np.ndarray, above: float):
    """``(first, quiet)``: the lowest speed above ``above`` (Hz) where ``u > 1``, and the
    highest speed between the two where ``u ≤`` :data:`SWITCH_ON_FRACTION`; None for
    either where there is none."""
    turning = f > above
    saturated = f[turning & (u > 1)]
    if not saturated.size:
        return None, None
    first = float(saturated.min())
    quiet = f[turning & (f < first) & (u <= SWITCH_ON_FRACTION)]
    return first, float(quiet.max()) if quiet.size else None


def impulse_coil_currents(act, impulse) -> tuple[np.ndarray, np.ndarray | None]:
    """The coil currents and their rates through the amplifier's current loop in a judged
    current-impulse response (module docstring).

    Parameters
    ----------
    act : Actuator
        The rig's ``[actuator]`` (:func:`ambseal.model.amb.actuator_matrices`).
    impulse : ImpulseResponse
        The judged response (:func:`ambseal.analysis.response.impulse_response_of`): its
        current reference ``current_a + disturbance_a`` held over each ``dt_s``.

    Returns
    -------
    current : ndarray, shape (n_t, nu)
        The control current i of each coil pair (A), at each step's start.
    rate : ndarray, shape (n_t, nu) or None
        di/dt there (A/s), the input of that step applied; None for an ideal current loop.
    """
    ref = np.asarray(impulse.current_a + impulse.disturbance_a, float)
    A, B, C, D = actuator_matrices(act)
    if A.shape[0] == 0:
        return ref * float(D[0, 0]), None
    Ad, Bd = zoh(A, B, float(impulse.dt_s), keep=False)
    x = np.zeros((A.shape[0], ref.shape[1]))  # each axis's amplifier at rest
    current, rate = np.empty_like(ref), np.empty_like(ref)
    for k, r in enumerate(ref):
        current[k] = (C @ x)[0] + D[0, 0] * r
        rate[k] = (C @ (A @ x + B * r))[0]
        x = Ad @ x + Bd * r
    return current, rate


def force_demand(cfg, entries) -> dict[str, tuple[np.ndarray, np.ndarray]]:
    """The force amplitude (N) each AMB delivers to hold the judged unbalance, Ki·|H_a(jΩ)|·
    i_ref per axis (module docstring): the largest over the AMB's axes and a controller's
    judged conditions, to set against :func:`ambseal.model.capacity.force_capacity`.

    Parameters
    ----------
    cfg : RigConfig
        The rig: its ``[[amb]]`` (Ki) and ``[actuator]``.
    entries : iterable of (str, ndarray, ndarray, sequence of str)
        As :func:`capacity_block`'s.

    Returns
    -------
    dict
        Per AMB name, ``(speed_hz, force_n)``: arrays of shape (S,) on the union of the
        conditions' speeds (each condition's curve linearly interpolated there); an AMB
        without Ki is left out.
    """
    act = actuator_matrices(cfg.actuator)
    ki = {f"i_{amb.name}_{ax}": (amb.name, k)
          for amb in cfg.amb for ax, k in zip(AXES, amb_factors(amb)[0]) if k is not None}
    curves: dict = {}
    for _, speed_hz, i_ref, names, *_ in entries:
        f = np.asarray(speed_hz, float)
        gain = np.abs(freqresp_at(act, 2j * np.pi * f)[:, 0, 0])
        for a, name in enumerate(names):
            if name in ki:
                amb, k = ki[name]
                curves.setdefault(amb, []).append((f, k * gain * i_ref[:, a]))
    out = {}
    for amb, cs in curves.items():
        grid = np.unique(np.concatenate([f for f, _ in cs]))
        out[amb] = (grid, np.max([np.interp(grid, f, y) for f, y in cs], axis=0))
    return out


def capacity_block(cfg, entries, impulses=()) -> dict | None:
    """The largest fraction of each amplifier limit a controller uses over its judged
    conditions (module docstring), as ``metrics.json`` writes it.

    Parameters
    ----------
    cfg : RigConfig
        The rig: its ``[[amb]]`` limits and ``[actuator]``.
    entries : iterable of (str, ndarray, ndarray, sequence of str, dict or None)
        Per judged condition of the controller: its label, the speeds Ω/2π (Hz, shape
        (F,)), the current references (A, shape (F, nu), :func:`unbalance_currents`), the
        axes' input names (``i_<amb>_<axis>``) and the static currents (A) by axis name
        (module docstring; None without a static load).
    impulses : iterable of (str, float, ImpulseResponse, dict or None)
        Per judged condition: its label, its speed (Hz), the judged current-impulse
        response (:func:`impulse_coil_currents`) and the static currents by axis.

    Returns
    -------
    dict or None
        ``current_used``, ``voltage_used``, ``bias_used`` (the largest fraction, None where
        no AMB gives the limit), ``current_a`` (the largest coil current, static and
        amplitude, A),
        ``worst`` (per quantity: ``condition``, ``speed_hz``, ``axis`` and ``response``,
        ``"unbalance"`` or ``"impulse"``), ``static_a`` (the largest static current, A;
        None without a static load), ``per_amb`` (per AMB the same three fractions over
        its axes: each bearing's margin) and ``sizing``: per AMB the smallest amplifier
        that holds every judged condition, ``current_limit_a`` (the largest control
        current of its axes, A) and ``supply_voltage_v`` (the largest voltage its coils
        need, V; None where none was computed, and then ``supply_voltage_note`` says why:
        the rig file gives neither the coil's inductance nor its geometry, or only an
        ideal current loop's impulse was judged, whose step no finite voltage drives),
        :func:`ambseal.model.capacity.amplifier_needs` and
        :func:`~ambseal.model.capacity.transient_needs`; None when no condition was judged
        stable or the rig's AMBs give no bias current.
    """
    by_axis = {f"i_{amb.name}_{ax}": amb for amb in cfg.amb for ax in AXES}
    if not cfg.amb or any(a.bias_current is None for a in cfg.amb):
        return None
    act = actuator_matrices(cfg.actuator)
    best: dict = {q: (None, None) for q in (*QUANTITIES, "current_a")}
    sizing: dict = {}
    per_amb: dict = {}
    unknown: dict = {}  # AMB → why a need's voltage was not computed

    def account(label, speed_hz, name, need, response):
        amb = by_axis[name]
        row = sizing.setdefault(amb.name, {"current_limit_a": 0.0, "supply_voltage_v": None})
        row["current_limit_a"] = max(row["current_limit_a"],
                                     float(need["current_a"].max(initial=0.0)))
        if need["voltage_v"] is not None:
            row["supply_voltage_v"] = max(row["supply_voltage_v"] or 0.0,
                                          float(need["voltage_v"].max(initial=0.0)))
        else:
            unknown.setdefault(amb.name, set()).add(
                NO_COIL if coil_inductance(amb) is None else IDEAL_LOOP)
        use = limits_used(amb, need)
        use["current_a"] = need["current_a"]
        margins = per_amb.setdefault(amb.name, dict.fromkeys(QUANTITIES))
        for q, v in use.items():
            if v is None or not v.size:
                continue
            if q in margins:
                margins[q] = max(margins[q] or 0.0, float(v.max()))
            k = int(np.argmax(v))
            # the axes of a symmetric bearing need the same, but for rounding: the first
            # of them in the rig's channel order is named on every machine
            if best[q][0] is None or beyond(float(v[k]), best[q][0]):
                best[q] = (float(v[k]), {"condition": label, "speed_hz": float(speed_hz[k]),
                                         "axis": name.removeprefix("i_"),
                                         "response": response})

    statics = []
    for label, speed_hz, i_ref, names, static in entries:
        w = 2 * np.pi * np.asarray(speed_hz, float)
        gain = np.abs(freqresp_at(act, 1j * w)[:, 0, 0])
        for a, name in enumerate(names):
            i_s = (static or {}).get(name, 0.0)
            statics.append(i_s)
            account(label, speed_hz, name,
                    amplifier_needs(by_axis[name], w, gain * i_ref[:, a], static_a=i_s),
                    "unbalance")
    for label, speed_hz, imp, static in impulses:
        current, rate = impulse_coil_currents(cfg.actuator, imp)
        at = np.full(current.shape[0], float(speed_hz))
        for a, name in enumerate(imp.input_names):
            need = transient_needs(by_axis[name], current[:, a],
                                   None if rate is None else rate[:, a],
                                   static_a=(static or {}).get(name, 0.0))
            account(label, at, name, need, "impulse")
    if best["current_a"][0] is None:
        return None
    for name, row in sizing.items():
        if row["supply_voltage_v"] is None:  # the coil's reason first: it holds for all
            row["supply_voltage_note"] = (NO_COIL if NO_COIL in unknown[name]
                                          else IDEAL_LOOP)
    return {**{q: best[q][0] for q in (*QUANTITIES, "current_a")},
            "worst": {q: best[q][1] for q in QUANTITIES if best[q][1] is not None},
            "static_a": float(max(statics)) if any(statics) else None, "per_amb": per_amb,
            "sizing": sizing}


def saturates(block: dict | None) -> bool:
    """A :func:`capacity_block` with a fraction above 1: the amplifier cannot deliver the
    current the loop commands to hold the unbalance (or a coil's current would go below
    zero, out of the linear force law the loop was designed on).

    Parameters
    ----------
    block : dict or None
        A :func:`capacity_block`.

    Returns
    -------
    bool
    """
    return any((block or {}).get(q) is not None and block[q] > 1 for q in QUANTITIES)


def capacity_words(block: dict | None) -> str:
    """A :func:`capacity_block` in words: ``"holding the unbalance it uses 64 % of the
    supply voltage (A ζ at 11 000 rpm, 0 bar)"`` (``"in the current impulse"`` where the
    impulse response uses more), the largest of the voltage and current fractions; when a
    fraction is above 1, ``"the amplifier saturates holding the unbalance: it needs 1.5×
    the current limit (…)"``; ``""`` without a limit to set it against. A block of a
    controller that runs with its unbalance force rejection (``without_rejection``: the
    fractions of the controller alone, :func:`notched_currents`) says so, and what the
    controller alone would need: ``"…; without its unbalance force rejection, holding the
    unbalance would take 1.09× the bias current's linear range"``; one whose rejection the
    run switched on by itself (``rejection_automatic``: the controller alone saturates the
    amplifier and the rig file leaves ``[design.rejection]`` off) says that too.

    Parameters
    ----------
    block : dict or None
        A :func:`capacity_block`, with ``without_rejection`` where the notch holds it.

    Returns
    -------
    str
    """
    c = block or {}
    used = [(c[q], _LIMITS[q], c["worst"][q]) for q in QUANTITIES
            if c.get(q) is not None and (q != "bias_used" or c[q] > 1)]
    if not used:
        return ""
    over = [u for u in used if u[0] > 1]
    v, what, w = max(over or used, key=lambda u: u[0])
    rpm = f"{60 * w['speed_hz']:,.0f}".replace(",", " ")
    at = f"{axis_label(w['axis'])} at {rpm} rpm, {w['condition']}"
    holding = _HOLDING[w.get("response", "unbalance")]
    if c.get("static_a"):
        holding += " and the seals' static load"
    alone = c.get("without_rejection")
    if alone is not None and w.get("response", "unbalance") == "unbalance":
        holding += (" (its unbalance force rejection on, switched on by the run: the "
                    "controller alone saturates the amplifier)" if c.get("rejection_automatic")
                    else " (its unbalance force rejection on)")
    text = (f"the amplifier saturates {holding}: it needs {v:.3g}× {what} ({at})" if over
            else f"{holding} it uses {100 * v:.0f} % of {what} ({at})")
    known = [q for q in QUANTITIES if (alone or {}).get(q) is not None]
    if known:
        q = max(known, key=alone.get)
        text += (f"; without its unbalance force rejection, holding the unbalance would take "
                 f"{alone[q]:.3g}× {_LIMITS[q]}")
    return text

