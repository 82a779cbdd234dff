"""When a simulated mission ends, and when its trajectory is sampled.

One set of rules for every runner of :class:`~swarm_sim.engine.SimEngine`: the sim bridge
node (which ends a mission itself when asked to), the in-process mission runner and the
batch runners. Times compare with a tolerance of :data:`TIME_TOLERANCE_S`, so a step that
lands on a boundary up to float rounding counts as reaching it.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np

from swarm_sim.engine import SimEngine

__all__ = [
    'ALL_ROOMS_COVERED',
    'BUDGET',
    'EXTENSION_DONE',
    'TIME_TOLERANCE_S',
    'TrajectorySampler',
    'end_reason',
]

ALL_ROOMS_COVERED = 'all_rooms_covered'
EXTENSION_DONE = 'extension_done'
BUDGET = 'budget'
TIME_TOLERANCE_S = 1e-9


def end_reason(
    engine: SimEngine,
    *,
    stop_when_all_rooms_covered: bool,
    max_sim_time_s: float,
    extensions_done: Callable[[], bool] | None = None,
) -> str:
    """Why the mission ends after the engine's latest step, '' while it goes on.

    In this order: every room covered (when ``stop_when_all_rooms_covered``), the mission's
    extensions done (``extensions_done`` is asked only when the rooms do not end it), the
    time budget ``max_sim_time_s`` reached.
    """
    if stop_when_all_rooms_covered and engine.coverage.complete:
        return ALL_ROOMS_COVERED
    if extensions_done is not None and extensions_done():
        return EXTENSION_DONE
    if engine.time_s + TIME_TOLERANCE_S >= max_sim_time_s:
        return BUDGET
    return ''


@dataclass
class TrajectorySampler:
    """The robots' poses at the start and then every ``period_s`` of simulated time.

    A step is kept when it reaches the next sample time; the one after is a period later
    (not a period after the kept step), so the samples do not drift with the step size.
    """

    period_s: float
    times_s: list[float] = field(default_factory=list)
    poses: list[np.ndarray] = field(default_factory=list)
    next_sample_s: float = 0.0

    @classmethod
    def starting_at(cls, poses: np.ndarray, period_s: float) -> TrajectorySampler:
        """A sampler holding the poses at time 0."""
        return cls(period_s, [0.0], [poses], period_s)

    def offer(self, time_s: float, poses: np.ndarray) -> None:
        """One step's poses at ``time_s``; kept if a sample is due."""
        if time_s + TIME_TOLERANCE_S >= self.next_sample_s:
            self.times_s.append(time_s)
            self.poses.append(poses)
            self.next_sample_s += self.period_s
