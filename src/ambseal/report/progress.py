"""Progress of a long job, stage by stage: bars on a terminal, plain log lines elsewhere.

Python's :mod:`logging` is underneath, on the ``"ambseal"`` logger, so a library user
routes it like any other: each finished stage is one INFO record (``"judge: done in
41.2 s (40.9 s CPU), elapsed 75.3 s"``: wall and this process's CPU time, which
``benchmarks/bench_rigs.py`` reads per stage) and each step within a stage one DEBUG
record. With
``display=True`` (the CLI on a terminal) rich shows one bar per stage as it starts, each with
its own clock; a bar only fills, and a stage's bar is full when the next one starts.
"""

from __future__ import annotations

import logging
import time
from typing import Mapping

from rich.console import Console
from rich.progress import BarColumn, MofNCompleteColumn, Progress, TextColumn, TimeElapsedColumn

__all__ = ["StageProgress", "LOGGER"]

#: The logger of every stage line.
LOGGER = logging.getLogger("ambseal")


class StageProgress:
    """Stages of a job, begun in order; use as a context manager.

    Parameters
    ----------
    totals : mapping of str to int or None
        Steps per stage name; ``None`` when the count is not known in advance (the bar
        then pulses until the stage ends).
    display : bool
        Show rich's live display on stderr (only sensible on a terminal).
    begun : (str, float, float), optional
        A stage begun before this object was made: its name and its start by
        ``time.perf_counter()`` and ``time.process_time()``. The first :meth:`begin` ends
        it, and logs it, as it ends any stage, and the elapsed time counts from its start.
    """

    def __init__(self, totals: Mapping[str, int | None], *, display: bool = False,
                 begun: tuple[str, float, float] | None = None):
        self._totals = dict(totals)
        self._display = display
        self._progress = None
        self._task = None
        self._name: str | None = None
        self._steps = 0
        self._t0 = self._t_stage = time.perf_counter()
        self._cpu_stage = time.process_time()
        if begun is not None:
            self._name, self._t_stage, self._cpu_stage = begun
            self._t0 = self._t_stage

    def __enter__(self) -> "StageProgress":
        if self._display:
            self._progress = Progress(
                TextColumn("{task.description:<15}"), BarColumn(bar_width=30),
                MofNCompleteColumn(), TimeElapsedColumn(),
                TextColumn("[dim]{task.fields[detail]}"),
                console=Console(stderr=True), transient=False)
            self._progress.start()
        return self

    def __exit__(self, *exc) -> None:
        if exc[0] is None:
            self._end_stage()
        if self._progress is not None:
            self._progress.stop()

    def begin(self, name: str, detail: str = "") -> None:
        """End the current stage (its bar full) and start ``name``."""
        self._end_stage()
        self._name, self._steps = name, 0
        self._t_stage, self._cpu_stage = time.perf_counter(), time.process_time()
        total = self._totals.get(name)
        if self._progress is not None:
            self._task = self._progress.add_task(name, total=total, detail=detail)
        if detail:
            LOGGER.debug("%s: %s", name, detail)

    def step(self, detail: str = "", steps: int = 1) -> None:
        """``steps`` steps of the current stage done; ``detail`` says what comes next."""
        self._steps += steps
        if self._progress is not None and self._task is not None:
            task = self._progress.tasks[-1]
            total = task.total
            # never past the end: a stage with more steps than announced stays full
            adv = steps if total is None else max(0, min(steps, total - task.completed))
            self._progress.update(self._task, advance=adv, detail=detail)
        if detail:
            LOGGER.debug("%s: %s", self._name, detail)

    def _end_stage(self) -> None:
        if self._name is None:
            return
        now, cpu = time.perf_counter(), time.process_time()
        if self._progress is not None and self._task is not None:
            total = self._totals.get(self._name) or max(self._steps, 1)
            self._progress.update(self._task, total=total, completed=total, detail="")
            self._progress.stop_task(self._task)
        LOGGER.info("%s: done in %.1f s (%.1f s CPU), elapsed %.1f s", self._name,
                    now - self._t_stage, cpu - self._cpu_stage, now - self._t0)
        self._name, self._task = None, None
