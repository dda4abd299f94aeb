"""ambseal.machine: the controllers a machine runs and the loop they are judged on.

Above the generic core (:mod:`ambseal.robust`, which works on any plant and returns
controllers for the lower LFT ``F_l(P, K)``, ``u = K y``), this layer holds what a
controller on a machine is: negative feedback ``u = −K y`` from its measurements
``y_<channel>`` to its commands, fixed or scheduled on one named parameter θ — the rotor
speed (:data:`SPEED`) or any other (:mod:`ambseal.machine.controller`); the one loop every
verdict is taken on, with the target's hold and computation delay
(:mod:`ambseal.machine.loop`; :func:`loop_matrices` and :func:`sample_time` check a
plant and a controller before they are closed, :func:`sampled_plant` samples a plant as
the controller sees it); and a scheduled controller's table as it runs on the target
(:mod:`ambseal.machine.scheduled_digital`); and the generalised notch filter that rejects
the synchronous force, scheduled on speed, around any of them
(:mod:`ambseal.machine.synchronous_notch`).
"""

from ambseal.machine.controller import (
    SPEED,
    ScheduledController,
    controller_as_runs,
    frozen,
    matrices_at,
)
from ambseal.machine.loop import (
    ClosedLoop,
    JudgedLoop,
    closed_loop,
    judged_loop,
    loop_matrices,
    sample_time,
    sampled_loop_matrix,
    sampled_plant,
)
from ambseal.machine.scheduled_digital import ScheduledDigital, scheduled_digital, table_grid
from ambseal.machine.synchronous_notch import NotchedController, NotchedDigital, SynchronousNotch

__all__ = ["SPEED", "ScheduledController", "controller_as_runs", "frozen", "matrices_at",
           "sampled_loop_matrix", "ClosedLoop",
           "JudgedLoop", "closed_loop", "judged_loop", "loop_matrices", "sample_time",
           "sampled_plant", "ScheduledDigital", "scheduled_digital", "table_grid",
           "SynchronousNotch", "NotchedController", "NotchedDigital"]
