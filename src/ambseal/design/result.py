"""What every design result offers the layers above it: one protocol.

The main job, the remedies, the digital choice, the export and the report take any design
— the reference PID, H∞ and μ (:class:`~ambseal.design.recipes.DesignResult`), an LTI
design at one speed (:class:`~ambseal.design.lpv_design.FrozenDesign`), the LPV on speed
(:class:`~ambseal.design.lpv_design.LpvDesign`, thesis P3 §4) or on a tracked seal
coefficient (:class:`~ambseal.design.seal_schedule.SealScheduledDesign`, Ch. 7) — through
:class:`Design`, never by asking which type it is.
"""

from __future__ import annotations

from typing import Protocol, runtime_checkable

import control

from ambseal.machine import ScheduledController

__all__ = ["Design"]


@runtime_checkable
class Design(Protocol):
    """A designed controller and how it was obtained.

    Attributes
    ----------
    method : str
        Its method's key in :data:`ambseal.config.METHODS` (``"pid"``, ``"hinf"``, ...).
    controller : control.StateSpace or ScheduledController
        What runs: displacements (m) → current references (A), negative feedback
        ``i = −K y`` (:mod:`ambseal.machine.controller`); a scheduled one gives the fixed
        controller at each value of its parameter (``controller.at``).
    full_order : dict or None
        The design's own check on the full-order plant at the judged conditions
        (:func:`ambseal.design.recipes.full_order_check`: ``stable``, and the least stable
        condition and mode); None where the design makes none.
    verdict : str
        One plain line: what the design's bound says and whether its full-order loop is
        stable; empty for a design with neither (the reference PID: the judgement
        decides).
    """

    @property
    def method(self) -> str: ...

    @property
    def controller(self) -> control.StateSpace | ScheduledController: ...

    @property
    def full_order(self) -> dict | None: ...

    @property
    def verdict(self) -> str: ...

    def summary(self) -> dict:
        """The design for ``metrics.json``: JSON-ready numbers and names, no matrices."""
        ...

    def to_dict(self) -> dict:
        """:meth:`summary`, and the controller's matrices where the design exports them."""
        ...
