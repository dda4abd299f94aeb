"""The rotor drop's report page: the verdict first (each criterion passed, FAILED or not
graded, with its value and limit), the event and each AMB axis (lost or running on, its
peak current against its limit, saturated or not), then per touchdown bearing what the
engineer judges —
peak force, deepest penetration, largest orbit against the clearance, regime, whirl
frequency and onset, the ring's spin-up and final speed —, the largest excursion at each
AMB and seal, the energy the drop took, the coast-down, and the figures
(:mod:`ambseal.report.drop_figures`). One self-contained page
(:func:`ambseal.report.html.write_report`); every string from the rig is escaped."""

from __future__ import annotations

import html
import math
import os
from pathlib import Path

from ambseal.report.html import write_report

__all__ = ["write_drop_report"]

_OUTCOME_COLOUR = {"passed": "#d5f5d5", "FAILED": "#fde8e8", "not graded": "#f0f0f0"}


def _cell(value, text: bool = False) -> str:
    cls = ' class="text"' if text else ""
    return f"<td{cls}>{html.escape('—' if value is None else str(value))}</td>"


def _num(x, scale: float = 1.0, fmt: str = ".4g"):
    return None if x is None else format(scale * x, fmt)


def _table(head: list[str], rows: list[str]) -> str:
    th = "".join(f"<th>{html.escape(h)}</th>" for h in head)
    return f"<table><thead><tr>{th}</tr></thead><tbody>{''.join(rows)}</tbody></table>"


def write_drop_report(path: str | os.PathLike, doc: dict, figures, *, title: str,
                      meta: str | None = None) -> Path:
    """Write the drop's ``drop.html``.

    Parameters
    ----------
    path : path-like
        The page to write (its folder must exist).
    doc : dict
        What ``ambseal drop`` writes to ``drop.json``: :func:`ambseal.analysis.
        drop_verdict`'s ``verdict`` and ``criteria`` with :meth:`ambseal.analysis.
        DropResult.to_dict`, and each plane's ``radial_clearance_m``.
    figures : sequence of (str, path-like)
        Caption and PNG of each figure, in order.
    title : str
        The page's title (escaped).
    meta : str, optional
        A line under the title (escaped): the rig and the command.

    Returns
    -------
    Path
        The page written.
    """
    colour = _OUTCOME_COLOUR
    crit = [f'<tr><td class="text">{html.escape(c["name"])}</td>'
            f'<td style="background:{colour[c["outcome"]]};text-align:center">'
            f'{html.escape(c["outcome"])}</td>{_cell(c["value"])}{_cell(c["limit"])}</tr>'
            for c in doc["criteria"]]
    axial = doc.get("max_axial_m") is not None  # the thrust bearing let go
    planes = []
    for p in doc["planes"]:
        c = p.get("radial_clearance_m")
        orbit = _num(p["max_orbit_m"], 1e6)
        if c and p["max_orbit_m"] is not None:
            orbit += f" ({p['max_orbit_m'] / c:.3g} c)"
        planes.append(
            f'<tr><td class="text">{html.escape(p["name"])}</td>'
            + _cell(_num(p["peak_force_n"])) + _cell(_num(p["max_penetration_m"], 1e6))
            + _cell(orbit) + _cell(p["regime"], text=True) + _cell(_num(p["whirl_hz"]))
            + _cell(_num(p["whirl_onset_s"], 1e3)) + _cell(_num(p["race_spin_up_s"], 1e3))
            + _cell(_num(p["final_race_speed_rad_s"], 60 / (2 * math.pi), ".5g"))
            + (_cell(_num(p["peak_axial_force_n"]))
               + _cell(_num(p["max_axial_penetration_m"], 1e6)) if axial else "")
            + _cell(_num(p["friction_heat_j"])) + "</tr>")
    gaps = doc.get("gaps_m", {})
    watched = []
    for k, v in doc["watched_max_m"].items():
        gap = gaps.get(k)
        watched.append(f'<tr><td class="text">{html.escape(k)}</td>{_cell(_num(v, 1e6))}'
                       + _cell(_num(gap, 1e6))
                       + _cell(f"{v / gap:.3g}" if gap and v is not None else "—")
                       + "</tr>")
    stop = doc.get("coast_down_s")
    stop_text = ("held by the drive" if stop is None and doc["final_speed_rad_s"]
                 == doc["speed_rad_s"] else "not slowing" if stop is None else
                 f"{stop:.4g} s" + (" (extrapolated from the drop's last half)"
                                    if doc.get("coast_down_extrapolated") else ""))
    ambs = [f'<tr><td class="text">{html.escape(a["channel"])}</td>'
            + _cell("lost" if a["failed"] else "runs on", text=True)
            + _cell(_num(a["peak_current_a"])) + _cell(_num(a["current_limit_a"]))
            + _cell("yes" if a["saturated"] else "no", text=True) + "</tr>"
            for a in doc.get("amb", [])]
    runs = doc.get("controller_runs")
    event = (f"<p>{html.escape(doc['event_summary'])}; the loop's controller: "
             f"{html.escape(str(doc.get('controller', 'reference PID')))}"
             + (f" ({html.escape(runs)})" if runs else "") + ".</p>"
             if "event_summary" in doc else "")
    sections = [
        {"title": "Verdict", "html": f"<p><b>{html.escape(doc['verdict'])}</b></p>"
         + (f"<p>{html.escape(doc['orientation_note'])}.</p>"
            if "orientation_note" in doc else "")
         + _table(["criterion", "outcome", "value", "limit"], crit)},
        {"title": "The event and the AMB axes", "html": event + _table(
            ["axis", "power", "peak current (A)", "limit (A)", "saturated"], ambs)},
        {"title": "Touchdown bearings", "html": _table(
            ["plane", "peak force (N)", "max penetration (µm)", "max orbit (µm)",
             "regime", "whirl (Hz)", "whirl onset (ms)", "ring spin-up (ms)",
             "ring speed at the end (rpm)",
             *(("peak axial force (N)", "max axial penetration (µm)") if axial else ()),
             "friction heat (J)"], planes)},
        {"title": "Largest excursion at the AMBs, sensors, seals and disks",
         "html": _table(["plane", "excursion (µm)", "gap (µm)", "excursion / gap"],
                        watched)},
        {"title": "Energy and speed",
         "text": f"{doc['impacts']} contact onsets in {doc['duration_s']:.4g} s; the "
                 f"contacts, drag and structure dissipated {doc['energy_dissipated_j']:.4g} J "
                 f"(the drive, the AMBs, the seals and springs, the unbalance and any "
                 f"overload did "
                 f"{doc['external_work_j']:.4g} J of work on "
                 f"the rotor); the rotor's spin from "
                 f"{doc['speed_rad_s'] * 60 / (2 * math.pi):.6g} rpm, "
                 f"standstill: {stop_text}; {doc['n_modes']} free–free modes up to "
                 f"{doc['modes_hz']:.4g} Hz"
                 + (f"; the thrust bearing let go under {doc['axial_thrust_n']:.4g} N of "
                    f"thrust, the rotor moving up to {1e6 * doc['max_axial_m']:.4g} µm "
                    "axially" if axial else "") + "."},
        *({"title": caption, "figure": png} for caption, png in figures),
    ]
    return write_report(path, title=title, meta=meta, sections=sections)
