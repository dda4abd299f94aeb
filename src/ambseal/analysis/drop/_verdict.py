"""The drop judged: its pass criteria and the range of its model (the package's
docstring, :mod:`ambseal.analysis.drop`)."""

from __future__ import annotations

import numpy as np

from ambseal.analysis.drop._model import _disk_label
from ambseal.analysis.drop._result import DropResult
from ambseal.design import air_gaps
from ambseal.lti import json_float
from ambseal.model import rated_contact_stress, spring_label


def drop_verdict(cfg, result: DropResult) -> dict:
    """The drop judged, verdict first: each criterion passed, FAILED, or not graded (with
    why) — no contact outside the touchdown bearings (the largest excursion at each AMB
    against its air gap, :func:`ambseal.design.air_gaps`, at each seal, each
    ``[[spring]]`` and each disk with a ``clearance`` against it, at each AMB's sensor
    with a ``sensor_gap`` against it), each touchdown
    bearing's peak force against ``[drop] force_ratio`` × its ``static_rating`` C₀ (with
    the most loaded ball's contact stress that force gives in a rolling bearing,
    :func:`ambseal.model.rated_contact_stress`: the rig's kinds are ball bearings) — where
    it also stopped the rotor axially, ISO 76's static equivalent load of the peak radial
    and axial forces, P₀ = max(F_r, X₀F_r + Y₀F_a) (:attr:`ambseal.config.Touchdown.
    iso76_factors`; the two peaks combined whether or not they coincide, an upper bound),
    not graded without X₀, Y₀ —, each ring's temperature rise from the friction heat,
    all of it taken into the ring (an upper bound: none into the journal, none conducted
    away), against ``[drop] race_temperature_rise`` where the ring's ``race_mass`` is
    given, each ring's deepest penetration (radial, and axial where it stopped the rotor)
    within ``[drop] penetration_ratio`` × its clearance, and no backward whirl sustained
    over the last half of the drop. A penetration beyond that share, or the rotor through
    a gap where the drop has no contact, leaves the drop model's range: the verdict says
    so first, with where and from when (the first output sample past it), and fails.

    Parameters
    ----------
    cfg : RigConfig
        The rig dropped.
    result : DropResult
        Its drop.

    Returns
    -------
    dict
        ``passed`` (bool: nothing failed), ``verdict`` (one line), ``beyond_range``
        (where and when the drop left its model's range, one line each), ``criteria``
        (``name``, ``outcome`` — ``"passed"``, ``"FAILED"`` or ``"not graded"`` —,
        ``value``, ``limit``), ``gaps_m`` (each watched plane's gap, m, as
        :attr:`DropResult.watched` names it; None where none is given) and
        ``orientation_note`` (:func:`drop_orientation`).
    """
    rows = []

    def row(name, ok, value, limit):
        rows.append({"name": name, "outcome": ("not graded" if ok is None else
                                               "passed" if ok else "FAILED"),
                     "value": value, "limit": limit})

    gaps = {f"amb:{a.name}": s0 for a, s0 in zip(cfg.amb, air_gaps(cfg))}
    gaps.update({f"seal:{s.name}": s.clearance for s in cfg.seal})
    gaps.update({f"spring:{spring_label(s, i)}": s.clearance
                 for i, s in enumerate(cfg.spring) if s.clearance is not None})
    gaps.update({f"sensor:{a.name}": a.sensor_gap for a in cfg.amb
                 if a.sensor_gap is not None})
    gaps.update({f"disk:{_disk_label(d, i)}": d.clearance for i, d in enumerate(cfg.disk)
                 if d.clearance is not None})
    beyond = []  # where and when the drop left its model's range
    for key, gap in gaps.items():
        radius = np.hypot(*result.watched[key].T)
        worst = float(radius.max())
        what = {"amb": "air gap", "sensor": "sensor gap"}.get(key.split(":")[0],
                                                             "clearance")
        where = key.split(":", 1)[1]
        value = f"{1e6 * worst:.4g} µm"
        if gap is not None and worst >= gap:
            when = _first_time(result.t, radius >= gap)
            value += f", through the gap from {when}"
            beyond.append(f"the rotor through the {what} at {where} from {when}, where "
                          "the drop has no contact")
        row(f"no contact at {where} ({what})",
            None if gap is None else worst < gap, value,
            f"{1e6 * gap:.4g} µm" if gap else f"no {what} given")
    share = cfg.drop.penetration_ratio
    for p, td in enumerate(cfg.touchdown):
        for how, c, deepest, depth in (
                ("", td.radial_clearance, float(result.peak_penetration[p]),
                 result.penetration[p]),
                ("axial ", td.axial_clearance, float(result.peak_axial_penetration[p]),
                 None if result.axial_position is None else
                 np.abs(result.axial_position) - (td.axial_clearance or 0.0))):
            if c is None or (how and not deepest > 0):
                continue
            ok = deepest <= share * c
            value = f"{1e6 * deepest:.4g} µm ({deepest / c:.3g} × the clearance)"
            if not ok:
                when = _first_time(result.t, np.asarray(depth) > share * c)
                value += f", beyond from {when}"
                beyond.append(f"{td.name}'s {how}ring pressed {1e6 * deepest:.4g} µm deep "
                              f"({deepest / c:.3g} × its {1e6 * c:.4g} µm {how}clearance) "
                              f"from {when}, where the Hertz contact law no longer holds")
            row(f"{how}penetration within the contact law's range at {td.name}", ok, value,
                f"{share:g} × the {how}clearance = {1e6 * share * c:.4g} µm "
                "([drop] penetration_ratio)")
    ratio, rise_limit = cfg.drop.force_ratio, cfg.drop.race_temperature_rise
    for p, td in enumerate(cfg.touchdown):
        peak = f_r = float(result.peak_force[p])
        f_a = float(result.peak_axial_force[p])
        c0, factors = td.static_rating, td.iso76_factors
        text = f"{f_r:.4g} N"
        if f_a > 0:
            text = f"radial {f_r:.4g} N, axial {f_a:.4g} N"
            if factors is not None:
                peak = max(f_r, factors[0] * f_r + factors[1] * f_a)
                text += f": P₀ = {peak:.4g} N (X₀ {factors[0]:g}, Y₀ {factors[1]:g})"
        axial_open = f_a > 0 and factors is None
        stress = ""
        if c0 and td.kind != "sleeve" and not axial_open:
            stress = (f", {1e-6 * float(rated_contact_stress(peak, c0, 'ball')):.4g} MPa "
                      "at the most loaded ball")
        row(f"peak force at {td.name}",
            None if c0 is None or axial_open else peak <= ratio * c0,
            text + (f" ({peak / c0:.3g} C₀{stress})" if c0 and not axial_open else ""),
            (f"no static_factors (X₀, Y₀) for a {td.kind} bearing's axial force"
             if c0 and axial_open else
             f"{ratio:g} C₀ = {ratio * c0:.4g} N" if c0 else "no static_rating given"))
        if td.race_mass is not None:
            rise = float(result.friction_heat[p, -1]) / (td.race_mass * td.race_specific_heat)
            row(f"ring temperature rise at {td.name}",
                None if rise_limit is None else rise <= rise_limit,
                f"{rise:.3g} K ({float(result.friction_heat[p, -1]):.4g} J of friction heat, "
                "all into the ring)",
                f"{rise_limit:g} K" if rise_limit is not None
                else "no [drop] race_temperature_rise given")
        regime, hz = result.regime(p)
        row(f"no backward whirl at {td.name}", regime != "backward whirl",
            f"{regime}" + (f" at {hz:.3g} Hz" if regime.endswith("whirl") else ""),
            "no sustained backward whirl")
    failed = [r["name"] for r in rows if r["outcome"] == "FAILED"]
    skipped = [r["name"] for r in rows if r["outcome"] == "not graded"]
    line = (f"Drop FAILED: {'; '.join(failed)}" if failed else
            "Drop PASSED" + (f" on what was graded (not graded: {'; '.join(skipped)})"
                             if skipped else ""))
    if beyond:  # its forces past that point are not the machine's: said first
        line = (f"Drop FAILED, beyond the drop model's range: {'; '.join(beyond)} — its "
                f"results from then on do not describe the machine ({line})")
    return {"passed": not failed, "verdict": line, "criteria": rows, "beyond_range": beyond,
            "gaps_m": {k: json_float(g) if g is not None else None for k, g in gaps.items()},
            "orientation_note": drop_orientation(cfg, result)}


def drop_orientation(cfg, result: DropResult) -> str:
    """How the machine stands in the drop, one line: where its weight takes the rotor —
    across its axis onto its radial rings, along it onto its axial touchdown faces (once
    the thrust bearing lets go), or both (inclined) — and, for a standing rotor, what is
    left to bring it to its rings radially.

    Parameters
    ----------
    cfg : RigConfig
        The rig dropped (its ``[machine]``).
    result : DropResult
        Its drop.

    Returns
    -------
    str
    """
    machine = cfg.machine
    head = (f"{machine.orientation} machine"
            + (f" ({machine.inclination_deg:g}° above the horizontal)"
               if machine.orientation == "inclined" else ""))
    w = abs(result.axial_weight)
    if w == 0.0:
        return f"{head}: its weight takes the rotor across its axis onto its radial rings"
    if result.axial_position is not None:
        axial = (f"its weight along the axis, {w:.4g} N, takes the rotor onto its axial "
                 "touchdown face once the thrust bearing lets go")
    else:
        axial = (f"its weight along the axis, {w:.4g} N, stays on the thrust bearing "
                 "(it holds in this event, or no touchdown plane has an "
                 "axial_clearance)")
    radial = ("across the axis nothing pulls the rotor to its rings: only the unbalance, "
              "the whirl and the axial face's friction do" if machine.orientation ==
              "vertical" else "the rest of it across the axis, onto its radial rings")
    return f"{head}: {axial}; {radial}"


def _first_time(t: np.ndarray, over: np.ndarray) -> str:
    """``"t = 12.3 ms"``: the first output sample where ``over`` holds, or where none does
    (a peak read between the samples), ``"between the output samples"``."""
    k = np.flatnonzero(over)
    return f"t = {1e3 * float(t[k[0]]):.4g} ms" if k.size else "between the output samples"
