"""Room coverage of an OA-Bug run: the paper's metric, per-robot credit and the curve.

The numbers come either from a live run (the spawner) or from a recorded bag (the
``/sim/coverage`` messages), and both give the same :class:`CoverageSummary`.
"""

from __future__ import annotations

from collections.abc import Iterable, Sequence
from dataclasses import dataclass

import numpy as np

__all__ = ['CoverageSummary', 'RoomFirstVisit']


@dataclass(frozen=True)
class RoomFirstVisit:
    """The first entry of one room.

    Attributes:
        room_index: index of the room in the site's room list.
        robot: name of the robot that entered first (e.g. r3).
        time_s: sim time of the entry [s].
    """

    room_index: int
    robot: str
    time_s: float


@dataclass(frozen=True)
class CoverageSummary:
    """Coverage at the end of a run.

    Attributes:
        rooms_total: rooms of the site.
        visits: first entries in time order.
        end_time_s: sim time at which the run ended [s].
        robot_names: every robot of the run, in order.
    """

    rooms_total: int
    visits: tuple[RoomFirstVisit, ...]
    end_time_s: float
    robot_names: tuple[str, ...]

    @classmethod
    def build(
        cls,
        rooms_total: int,
        visits: Iterable[RoomFirstVisit],
        end_time_s: float,
        robot_names: Sequence[str],
    ) -> CoverageSummary:
        """Summary with visits sorted by time (and room index for ties)."""
        ordered = tuple(sorted(visits, key=lambda v: (v.time_s, v.room_index)))
        return cls(int(rooms_total), ordered, float(end_time_s), tuple(robot_names))

    @property
    def rooms_covered(self) -> int:
        """Number of rooms entered."""
        return len(self.visits)

    @property
    def coverage(self) -> float:
        """Covered fraction of the rooms (the paper's coverage)."""
        return self.rooms_covered / self.rooms_total if self.rooms_total else 1.0

    @property
    def complete(self) -> bool:
        """True when every room was entered."""
        return self.rooms_covered >= self.rooms_total

    def first_visits_per_robot(self) -> dict[str, int]:
        """Robot name -> rooms it entered first (every robot listed, zeros included)."""
        counts = dict.fromkeys(self.robot_names, 0)
        for visit in self.visits:
            counts[visit.robot] = counts.get(visit.robot, 0) + 1
        return counts

    def first_visitor_by_room(self) -> dict[int, str]:
        """Room index -> name of its first visitor (covered rooms only)."""
        return {v.room_index: v.robot for v in self.visits}

    def curve(self) -> tuple[np.ndarray, np.ndarray]:
        """(times [s], covered fraction) as a step curve from 0 to ``end_time_s``."""
        times = [0.0, *(v.time_s for v in self.visits), self.end_time_s]
        counts = [0, *range(1, self.rooms_covered + 1), self.rooms_covered]
        return np.array(times), np.array(counts, dtype=float) / max(self.rooms_total, 1)

    def coverage_at(self, time_s: float) -> float:
        """Covered fraction at ``time_s`` [s]."""
        covered = sum(1 for v in self.visits if v.time_s <= time_s)
        return covered / self.rooms_total if self.rooms_total else 1.0

    def format_report(self, title: str = 'Coverage') -> str:
        """Plain-text summary: coverage, rooms, time and the per-robot first visits."""
        lines = [
            f'{title}: {100.0 * self.coverage:.1f} % '
            f'({self.rooms_covered}/{self.rooms_total} rooms) after {self.end_time_s:.1f} s',
        ]
        if self.visits:
            lines.append(f'last new room entered at {self.visits[-1].time_s:.1f} s')
        lines.append('rooms first visited per robot:')
        per_robot = self.first_visits_per_robot()
        lines.extend(f'  {name:>4}: {count}' for name, count in per_robot.items())
        return '\n'.join(lines)
