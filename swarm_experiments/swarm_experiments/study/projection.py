"""Projected wall time of a study on N cores from measured per-run CPU costs.

The model is the engine's own: tasks are handed out in the order given (or longest first)
to whichever core is free first; each task occupies its core for its CPU cost (times
``cpu_scale``, the target machine's speed relative to the measuring one) plus the engine's
per-task overhead; the scheduler hands out at most one task per ``dispatch_s`` seconds;
the cluster takes ``startup_s`` to come up. The figures to put in come from
``benchmarks/bench_study_engine.py`` (overhead, dispatch, startup) and from the ``cpu_s``
column of measured rows (:func:`costs_for_plan`).
"""

from __future__ import annotations

import heapq
import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any, Literal

import pandas as pd

from .errors import UsageError
from .spec import StudyPlan, flatten

__all__ = [
    'DASK_DISPATCH_S',
    'DASK_OVERHEAD_S',
    'DASK_STARTUP_S',
    'Projection',
    'costs_for_plan',
    'project_wall_time',
]

#: Dask distributed on a local cluster of 2 workers, 2000 tiny tasks
#: (benchmarks/bench_study_engine.py): wall time per task, the core time per task (wall
#: times workers, scheduler and workers sharing the cores) and the cluster's startup.
DASK_DISPATCH_S = 0.0024
DASK_OVERHEAD_S = 0.0048
DASK_STARTUP_S = 0.5


@dataclass(frozen=True)
class Projection:
    """Projected wall time of a set of runs on ``cores`` cores."""

    runs: int
    cores: int
    cpu_s: float
    overhead_s: float
    startup_s: float
    wall_s: float
    lower_bound_s: float

    @property
    def efficiency(self) -> float:
        """Share of the cores' time spent on the runs' own CPU work."""
        if self.wall_s <= 0:
            return 1.0
        return self.cpu_s / (self.cores * self.wall_s)

    def summary(self) -> str:
        return (
            f'{self.runs} runs on {self.cores} cores: {_duration(self.wall_s)} wall '
            f'({_duration(self.cpu_s)} CPU of runs, {_duration(self.overhead_s)} of '
            f'per-task overhead, lower bound {_duration(self.lower_bound_s)}, '
            f'{100 * self.efficiency:.0f} % efficiency)'
        )


def _duration(seconds: float) -> str:
    if seconds < 120:
        return f'{seconds:.1f} s'
    if seconds < 7200:
        return f'{seconds / 60:.1f} min'
    return f'{seconds / 3600:.2f} h'


def project_wall_time(
    run_cpu_s: Sequence[float],
    cores: int,
    *,
    per_task_overhead_s: float = 0.0,
    dispatch_s: float = 0.0,
    startup_s: float = 0.0,
    cpu_scale: float = 1.0,
    order: Literal['given', 'longest_first'] = 'given',
) -> Projection:
    """Simulate list scheduling of runs with the given CPU costs on ``cores`` cores."""
    if cores < 1:
        raise ValueError(f'cores must be >= 1, not {cores}')
    for name, value in (
        ('per_task_overhead_s', per_task_overhead_s),
        ('dispatch_s', dispatch_s),
        ('startup_s', startup_s),
    ):
        if value < 0 or not math.isfinite(value):
            raise ValueError(f'{name} must be a finite value >= 0, not {value}')
    if cpu_scale <= 0:
        raise ValueError(f'cpu_scale must be > 0, not {cpu_scale}')
    costs = [float(cost) * cpu_scale for cost in run_cpu_s]
    if any(cost < 0 or not math.isfinite(cost) for cost in costs):
        raise ValueError('run CPU costs must be finite values >= 0')
    if order == 'longest_first':
        costs.sort(reverse=True)
    elif order != 'given':
        raise ValueError(f'order must be given or longest_first, not {order!r}')
    free_at = [0.0] * min(cores, max(1, len(costs)))
    heapq.heapify(free_at)
    makespan = 0.0
    for index, cost in enumerate(costs):
        start = max(heapq.heappop(free_at), index * dispatch_s)
        finish = start + cost + per_task_overhead_s
        makespan = max(makespan, finish)
        heapq.heappush(free_at, finish)
    total = sum(costs)
    overhead = per_task_overhead_s * len(costs)
    longest = max(costs, default=0.0) + (per_task_overhead_s if costs else 0.0)
    lower = max((total + overhead) / cores, longest, len(costs) * dispatch_s if costs else 0.0)
    return Projection(
        runs=len(costs),
        cores=cores,
        cpu_s=total,
        overhead_s=overhead,
        startup_s=startup_s,
        wall_s=startup_s + makespan,
        lower_bound_s=startup_s + lower,
    )


def _plain(value: Any) -> Any:
    if hasattr(value, 'tolist'):  # numpy scalars and arrays (list columns)
        value = value.tolist()
    if isinstance(value, (list, tuple)):
        return tuple(_plain(item) for item in value)
    return value


def _key(configuration: dict[str, Any]) -> tuple[tuple[str, str], ...]:
    return tuple(sorted((name, repr(_plain(value))) for name, value in configuration.items()))


def costs_for_plan(plan: StudyPlan, rows: pd.DataFrame) -> list[float]:
    """Per-run CPU cost of every spec of ``plan``: the mean ``cpu_s`` of the ``ok`` rows of
    the same configuration (axis values) in ``rows``, e.g. a smaller run of the study.

    A configuration without a measured row is an error naming the first few missing.
    """
    measured: dict[tuple[tuple[str, str], ...], float] = {}
    if len(rows) and 'cpu_s' in rows:
        ok = rows[rows['status'] == 'ok']
        columns = [f'config.{axis}' for axis in plan.axes]
        missing_columns = [column for column in columns if column not in ok.columns]
        if missing_columns:
            raise UsageError(f'the measured rows have no column {missing_columns[0]}')
        if columns:
            for values, group in ok.groupby(columns, dropna=False, sort=False):
                values = values if isinstance(values, tuple) else (values,)
                configuration = dict(zip(plan.axes, values, strict=True))
                measured[_key(configuration)] = float(group['cpu_s'].mean())
        elif len(ok):
            measured[()] = float(ok['cpu_s'].mean())
    costs = []
    missing: list[str] = []
    for spec in plan.specs:
        configuration = flatten(spec.configuration)
        cost = measured.get(_key(configuration))
        if cost is None:
            label = ', '.join(f'{name}={value}' for name, value in configuration.items())
            if label not in missing:
                missing.append(label)
            continue
        costs.append(cost)
    if missing:
        shown = '; '.join(missing[:3]) + (
            f' (+{len(missing) - 3} more)' if len(missing) > 3 else ''
        )
        raise UsageError(f'no measured run for {len(missing)} configurations: {shown}')
    return costs
