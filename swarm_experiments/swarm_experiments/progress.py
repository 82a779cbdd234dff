"""Progress of a mission on the terminal: one rich bar over the sim-time budget.

The spawners pass :class:`MissionProgressBar` as the mission's ``progress`` callback. It draws
on stderr only when stderr is a terminal and ``--quiet`` was not given, so logs, pipes and
tests get the report alone; the bar disappears when the mission ends.
"""

from __future__ import annotations

import sys
from collections.abc import Callable
from types import TracebackType
from typing import Any, TextIO

from swarm_experiments.mission import MissionProgress

__all__ = ['MissionProgressBar', 'progress_wanted']


def progress_wanted(quiet: bool, stream: TextIO | None = None) -> bool:
    """Draw progress: not ``quiet`` and the stream (default stderr) is a terminal."""
    stream = sys.stderr if stream is None else stream
    isatty = getattr(stream, 'isatty', None)
    return not quiet and bool(isatty and isatty())


class MissionProgressBar:
    """A context manager and a ``progress`` callback: a bar from 0 to ``budget_s`` sim time.

    Args:
        description: what runs (left of the bar).
        budget_s: the mission's sim-time budget [s].
        enabled: draw at all (see :func:`progress_wanted`); when False every call is a no-op.
        detail: text right of the bar for a report (default: rooms covered).
    """

    def __init__(
        self,
        description: str,
        budget_s: float,
        *,
        enabled: bool,
        detail: Callable[[MissionProgress], str] | None = None,
    ) -> None:
        self.description = description
        self.budget_s = float(budget_s)
        self.enabled = enabled
        self.detail = detail or _rooms
        self._progress: Any = None
        self._task: Any = None

    def __enter__(self) -> MissionProgressBar:
        if not self.enabled:
            return self
        from rich.console import Console
        from rich.progress import (
            BarColumn,
            Progress,
            TaskProgressColumn,
            TextColumn,
            TimeElapsedColumn,
        )

        self._progress = Progress(
            TextColumn('{task.description}'),
            BarColumn(),
            TaskProgressColumn(),
            TextColumn('sim {task.completed:.0f}/{task.total:.0f} s'),
            TextColumn('{task.fields[detail]}'),
            TimeElapsedColumn(),
            console=Console(stderr=True),
            transient=True,
        )
        self._progress.start()
        self._task = self._progress.add_task(self.description, total=self.budget_s, detail='')
        return self

    def __call__(self, report: MissionProgress) -> None:
        if self._progress is None:
            return
        self._progress.update(
            self._task, completed=min(report.sim_time_s, self.budget_s), detail=self.detail(report)
        )

    def __exit__(
        self,
        exc_type: type[BaseException] | None,
        exc: BaseException | None,
        traceback: TracebackType | None,
    ) -> None:
        if self._progress is not None:
            self._progress.stop()
            self._progress = None


def _rooms(report: MissionProgress) -> str:
    return f'rooms {report.rooms_covered}/{report.rooms_total}'
