"""The controller a command's ``--controller`` names: designed on the rig, or read from a
file ``ambseal design`` wrote (``modes``, ``campbell``, ``sweep``)."""

from __future__ import annotations

from pathlib import Path

from ambseal.analysis import operating_points
from ambseal.app.commands import digital_for
from ambseal.config import method_names
from ambseal.design import design, design_spec
from ambseal.errors import ConfigError, SynthesisError
from ambseal.export import load_controller
from ambseal.model import channel_names
from ambseal.robust import DigitalController

__all__ = ["controller_for", "runs_as"]


def controller_for(cfg, spec: str | None, pressure_bar: float | None = None):
    """The controller ``spec`` names: ``pid``, ``hinf`` or ``mu`` (designed on the rig by
    :func:`ambseal.design.recipes.design` at ``pressure_bar``), or a controller file of
    ``ambseal design`` (.json, .npz, .mat) — its kind checked and wired to the rig's
    channels by signal name (:func:`~ambseal.export.controller_files.load_controller`);
    ``None`` or ``"none"`` for the open loop.

    A design scheduled on speed (a PID's cross gains, an H∞ scheduled over the speed
    range) is returned scheduled, for the commands to freeze at each speed. A digital
    controller's continuous design is returned, the loop the commands close in
    continuous time; but an H∞ or μ designed on the sampled plant (``[design]
    synthesis_plant = "sampled"``, or a file that records it) exists only as it runs: its
    :class:`~ambseal.robust.DigitalController` is returned (discretised here for a method
    the rig designs, as ``ambseal design`` does), for the commands to close as it runs
    (:attr:`~ambseal.robust.DigitalController.as_runs_only`). Such a design that cannot run
    on the target keeps its w-plane form, the only loop there is."""
    if spec is None or spec == "none":
        return None

    if spec in method_names(fixed=True):
        res = design(cfg, spec, pressure_bar=pressure_bar)
        if getattr(res, "synthesis_plant", "continuous") != "sampled":
            return res.controller  # scheduled on speed where the design is
        try:
            return digital_for(cfg, spec, res.K, res, operating_points(design_spec(cfg)))
        except SynthesisError:
            return res.K
    if Path(spec).suffix.lower() not in (".json", ".npz", ".mat"):
        raise ConfigError(f"--controller: expected {', '.join(method_names(fixed=True))}, "
                          f"none or a controller file "
                          f"(.json, .npz, .mat), got {spec!r}")

    K = load_controller(spec, channel_names(cfg))
    if isinstance(K, DigitalController) and not K.as_runs_only:
        return K.continuous  # a judged digital one: its continuous design
    return K


def runs_as(cfg, spec: str | None):
    """The controller as it runs on the target that ``spec`` names, where it names one: a
    controller file of ``ambseal design`` holding a digital controller or a scheduled
    table (:class:`~ambseal.robust.DigitalController`, ``ScheduledDigital``); None for a
    method designed here (its discretisation is ``ambseal design``'s to choose), a
    continuous file, or the open loop."""
    if spec is None or spec == "none" or spec in method_names(fixed=True):
        return None
    K = load_controller(spec, channel_names(cfg))
    return K if hasattr(K, "statespace_at") or isinstance(K, DigitalController) else None
