"""Running a study plan: skip the runs already stored, execute the rest, store the rows."""

from __future__ import annotations

import os
from collections.abc import Callable, Mapping, Set
from dataclasses import dataclass
from datetime import UTC, datetime
from pathlib import Path
from typing import Any

from .engines import Engine
from .errors import ResultsError
from .results import PartWriter, done_run_ids, read_manifest, study_lock, write_manifest
from .spec import StudyPlan, check_config
from .version import code_version as current_code_version

__all__ = ['RunSummary', 'merged_manifest', 'run_study']


@dataclass(frozen=True)
class RunSummary:
    """What one call of :func:`run_study` did."""

    study: str
    directory: Path
    planned: int
    skipped: int
    ok: int
    failed: int
    interrupted: bool

    @property
    def unfinished(self) -> int:
        return self.planned - self.skipped - self.ok - self.failed

    @property
    def complete(self) -> bool:
        """Every planned run has an ``ok`` row."""
        return not self.interrupted and self.failed == 0 and self.unfinished == 0


class _Progress:
    """A rich progress bar with counts, failures and the time remaining (or nothing)."""

    def __init__(self, enabled: bool, label: str, total: int) -> None:
        self._progress: Any = None
        if not enabled or total == 0:
            return
        from rich.console import Console
        from rich.progress import (
            BarColumn,
            MofNCompleteColumn,
            Progress,
            TextColumn,
            TimeElapsedColumn,
            TimeRemainingColumn,
        )

        self._progress = Progress(
            TextColumn('{task.description}'),
            BarColumn(),
            MofNCompleteColumn(),
            TextColumn('{task.fields[failed]} failed'),
            TimeElapsedColumn(),
            TextColumn('ETA'),
            TimeRemainingColumn(),
            console=Console(stderr=True),
            transient=False,
        )
        self._task = self._progress.add_task(label, total=total, failed=0)
        self._failed = 0
        self._progress.start()

    def advance(self, failed: bool) -> None:
        if self._progress is None:
            return
        self._failed += int(failed)
        self._progress.update(self._task, advance=1, failed=self._failed)

    def stop(self) -> None:
        if self._progress is not None:
            self._progress.stop()


def merged_manifest(old: Mapping[str, Any], plan: StudyPlan, done: Set[str]) -> dict[str, Any]:
    """The manifest of a study directory after one more ``run`` call: all that was planned.

    A directory collects the runs of every call (each may restrict axes or seeds), so the
    manifest holds the union: every axis value and seed planned so far, and the ids of
    every planned run (``planned_run_ids``; ``runs`` is their number). A directory written
    before the ids were kept counts its stored runs as planned. Fixed parameters are those
    of the latest call (the rows keep each run's own).
    """
    manifest = plan.manifest()
    old_axes = old.get('axes', {})
    axes: dict[str, list[Any]] = {}
    for axis, values in manifest['axes'].items():
        merged = list(old_axes.get(axis, []))
        merged += [value for value in values if value not in merged]
        axes[axis] = merged
    manifest['axes'] = axes
    manifest['seeds'] = sorted({*old.get('seeds', []), *manifest['seeds']})
    planned = set(old.get('planned_run_ids', ())) | set(done)
    planned.update(spec.run_id for spec in plan.specs)
    manifest['planned_run_ids'] = sorted(planned)
    manifest['runs'] = len(planned)
    return manifest


def run_study(
    plan: StudyPlan,
    out_dir: str | os.PathLike[str],
    engine: Engine,
    *,
    progress: bool = False,
    batch_rows: int = 50,
    batch_s: float = 30.0,
    code_version: str | None = None,
    on_row: Callable[[dict[str, Any]], None] | None = None,
    command: str | None = None,
) -> RunSummary:
    """Execute the plan's runs that have no ``ok`` row in ``out_dir/<study>`` yet.

    Rows are written in part files of up to ``batch_rows`` rows (or every ``batch_s``
    seconds); on Ctrl-C (KeyboardInterrupt) the rows received so far are written, the engine
    is stopped and the summary says ``interrupted``. Calling it again resumes.

    Every configuration of the plan is checked by the study's ``check`` hook first (as
    :func:`~.spec.make_specs` does), so a plan put together by hand with a bad value stops
    here, before the directory is created or anything runs.

    Raises:
        UsageError: the study's check rejects a configuration.
        ResultsError: the directory cannot be created, is locked or holds another study.
    """
    checked: set[int] = set()  # make_specs gives a configuration's seeds one config object
    for spec in plan.specs:
        if id(spec.config) not in checked:
            check_config(plan.study, spec.config)
            checked.add(id(spec.config))
    directory = Path(out_dir) / plan.directory_name
    try:
        directory.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise ResultsError(f'{directory}: cannot create ({exc})') from exc
    version = code_version if code_version is not None else current_code_version()
    with study_lock(directory):
        now = datetime.now(UTC).isoformat(timespec='seconds')
        old: dict[str, Any] = {}
        if (directory / 'study.json').exists():
            old = read_manifest(directory)
        done = done_run_ids(directory)
        manifest = merged_manifest(old, plan, done)
        call: dict[str, Any] = {'started_utc': now, 'engine': engine.name, 'code_version': version}
        if command is not None:
            call['command'] = command
        manifest['history'] = [*old.get('history', []), call]
        write_manifest(directory, manifest)

        todo = [spec for spec in plan.specs if spec.run_id not in done]
        skipped = len(plan.specs) - len(todo)
        writer = PartWriter(directory, batch_rows=batch_rows, batch_s=batch_s)
        bar = _Progress(progress, plan.directory_name, len(todo))
        ok = failed = 0
        interrupted = False
        rows = engine.rows(plan.study.run, todo, version)
        try:
            for row in rows:
                writer.add(row)
                if row['status'] == 'ok':
                    ok += 1
                else:
                    failed += 1
                bar.advance(row['status'] != 'ok')
                if on_row is not None:
                    on_row(row)
        except KeyboardInterrupt:
            interrupted = True
        finally:
            close = getattr(rows, 'close', None)
            if close is not None:
                close()
            bar.stop()
            writer.flush()
    return RunSummary(
        study=plan.study.name,
        directory=directory,
        planned=len(plan.specs),
        skipped=skipped,
        ok=ok,
        failed=failed,
        interrupted=interrupted,
    )
