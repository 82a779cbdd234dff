"""Progress of a mission: one rich bar over the sim-time budget, or plain lines in a log.

The spawners pass :class:`MissionProgressBar` as the mission's ``progress`` callback. On a
terminal (and without ``--quiet``) it draws a bar on stderr that disappears when the mission
ends; written to a pipe or a log, it prints a plain line on stderr at every tenth of the
budget instead (``lines=True``), so a long run is never silent and stdout holds the report
alone.
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
        lines: when the bar is not drawn, print ``<description>: sim <t>/<budget> s (<p> %),
            <detail>, wall <s> s`` on ``stream`` at every tenth of the budget.
        stream: where the lines go (default: sys.stderr).
    """

    def __init__(
        self,
        description: str,
        budget_s: float,
        *,
        enabled: bool,
        detail: Callable[[MissionProgress], str] | None = None,
        lines: bool = False,
        stream: TextIO | None = None,
    ) -> None:
        self.description = description
        self.budget_s = float(budget_s)
        self.enabled = enabled
        self.detail = detail or _rooms
        self.lines = lines and not enabled
        self.stream = stream
        self._next_line_s = 0.1 * self.budget_s
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
        if self.lines and report.sim_time_s + 1e-9 >= self._next_line_s:
            while self._next_line_s <= report.sim_time_s + 1e-9:
                self._next_line_s += 0.1 * self.budget_s
            share = 100.0 * report.sim_time_s / self.budget_s if self.budget_s > 0 else 100.0
            detail = self.detail(report)
            print(
                f'{self.description}: sim {report.sim_time_s:.0f}/{self.budget_s:.0f} s '
                f'({share:.0f} %), {detail + ", " if detail else ""}'
                f'wall {report.wall_time_s:.1f} s',
                file=self.stream if self.stream is not None else sys.stderr,
                flush=True,
            )
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
