"""``ambseal run``'s ``tracked`` controller (``[design] tracked = true``).

Wiring only, beside :mod:`ambseal.app.commands`: the controller scheduled on the first seal's
cross-coupled stiffness k (:func:`ambseal.design.seal_schedule.design_seal_scheduled`,
designed on the rig the robust controllers are designed on), its value at each judged
condition (the design rig's k at that pressure: the identified k when the run identified
the rig), and the closed-loop pressure ramp on the virtual facility with every controller
that runs on the target and the tracked scheme (:func:`ambseal.analysis.ramp.
ramp_simulation`; the tracker's model is the identified rig).
"""

from __future__ import annotations

import time
from pathlib import Path

from ambseal.analysis import points_for, ramp_simulation, speed_scheduled
from ambseal.app.commands import Designed, digitals_for
from ambseal.design import design_seal_scheduled
from ambseal.errors import ConfigError
from ambseal.report import ramp_figure

__all__ = ["tracked_designs", "tracked_ramp", "refusal_sentence"]


def refusal_sentence(tracking: dict) -> str:
    """The report's words on the tracker's consistency test (``ramp.tracking``): empty when
    it did not refuse, else that k cannot be tracked on this rig, why, and which
    controller ran instead (:func:`ambseal.analysis.ramp.ramp_simulation`)."""
    if not tracking.get("refused"):
        return ""
    name = {"mu": "μ", "hinf": "H∞"}.get(tracking.get("fallback"), tracking.get("fallback"))
    ran = (f"the {name} controller ran instead from "
           f"{tracking['fallback_from_s']:.3g} s" if tracking.get("fallback")
           else "no fallback controller ran: the scheduled one kept the biased estimate")
    return (f" The tracker cannot track k on this rig: at {tracking['refused_at_s']:.3g} s "
            f"{tracking['refusal']}; {ran}.")


def tracked_designs(cfg, design_cfg, spec, points, say, digitals: dict, cannot_run: dict
                    ) -> list:
    """``[design] tracked``: ``[]`` when off, else the tracked controller as a design of the
    main job (:class:`ambseal.app.commands.Designed`), designed on ``design_cfg`` to the
    rig's design specification ``spec`` (as the robust controllers are), with its digital table
    (:func:`ambseal.app.commands.digitals_for`: discretisation chosen on the sampled full-order
    loops with the target's delay at the judged pressures and between table entries) put
    in ``digitals``, or the reason it cannot run in ``cannot_run``. Its table is chosen and
    checked over its whole schedule (:func:`ambseal.analysis.judge.points_for`: ``points``
    and the pressures at the schedule's ends), where it is judged.

    Raises
    ------
    ConfigError
        A rig whose seal forces follow the speed (its LPV controller is the scheduled one)
        or that has no seal.
    """

    if not cfg.design.tracked:
        return []
    if speed_scheduled(cfg) or not cfg.seal:
        raise ConfigError("design.tracked: needs a rig whose [[seal]] k follows the pressure "
                          "drop (this one " + ("is scheduled on speed)" if cfg.seal
                                               else "has no [[seal]])"))
    say("designing tracked (LPV on the seal's k)", 0)
    t0 = time.perf_counter()
    d = design_seal_scheduled(design_cfg, spec=spec)
    # elapsed_s is this run's design time, as for every controller (a cache hit: its read)
    summary = {**d.to_dict(), "elapsed_s": round(time.perf_counter() - t0, 3)}
    say("tracked designed", 1)
    out = [Designed(d, summary)]
    more, cannot = digitals_for(design_cfg, out, points_for(d, points, design_cfg),
                                lambda m: say(m, 0))
    digitals.update(more)
    cannot_run.update(cannot)
    return out


def tracked_ramp(cfg, truth, designs, digitals: dict, ident, settings, out: Path, say
                 ) -> tuple[dict, tuple[str, Path]]:
    """The 0 → 3× nominal ramp on the virtual facility, the tracker's model the rig
    identified by ``ident`` (``commands.Identified``), its impulses those of the judgement
    ``settings``: ``metrics.json``'s ``ramp`` and the report's figure (caption, path); one
    step of ``say(message, steps)`` at the end. When the tracker refuses (its consistency
    test), the μ controller runs the rest of the ramp in the tracked run and the caption
    and the progress line say so (:func:`refusal_sentence`)."""

    tracked = next(d.controller for d in designs if d.method == "tracked")
    fixed = {m: g.discrete for m, g in digitals.items() if m != "tracked"}
    r = ramp_simulation(cfg, truth, fixed, tracked, model_cfg=ident.result.identified,
                        tracked_digital=digitals.get("tracked"),
                        delay_samples=cfg.controller.delay_samples, judgement=settings,
                        progress=lambda line: say(line, 0))
    t = r.tracking
    if t.get("refused"):
        say("ramp:" + refusal_sentence(t), 0)
    caption = (f"Pressure ramp 0 → {r.pressure_bar.max():.3g} bar in {r.time_s[-1]:.0f} s on "
               "the virtual facility with a current impulse every 2 s: true and tracked "
               f"{r.parameter} (largest error after 1 s "
               f"{100 * (t.get('max_error_rel') or float('nan')):.1f} % of nominal, 95 % "
               f"interval coverage {100 * (t.get('coverage') or float('nan')):.1f} %), "
               "displacement and current of every controller, impulse peaks and settling "
               "times." + refusal_sentence(t))
    fig = ramp_figure(out / "ramp.png", r)
    say("ramp done", 1)
    return r.to_dict(), (caption, fig)
