"""Room coverage ground truth: which robot entered which room first, and when.

A room is covered once a robot's disc overlaps the room's interior rectangle, that is once the
body has passed through the doorway (the authors' simulator counts a room when the robot's
box overlaps the room rectangle inset 3 px, about 2.5 cm, from the wall lines).
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass

import numpy as np

from swarm_sim.errors import WorldGeometryError
from swarm_sim.world_kernel import rooms_entered_kernel, rooms_touched_kernel

__all__ = ['CoverageTracker', 'RoomEntry']


@dataclass(frozen=True)
class RoomEntry:
    """The first entry of a room.

    Attributes:
        room_index: index of the room in the site's room list.
        robot_index: index of the robot that entered first.
        time_s: sim time of the entry [s].
    """

    room_index: int
    robot_index: int
    time_s: float


class CoverageTracker:
    """Records the first robot to enter each room."""

    def __init__(
        self,
        room_rects: Sequence[np.ndarray] | np.ndarray,
        robot_radius_m: float,
        room_index_at: Callable[[np.ndarray], np.ndarray] | None = None,
    ) -> None:
        """Track coverage of K rooms.

        Args:
            room_rects: per room, a (Ki, 4) array of interior rectangles x_min, y_min, x_max,
                y_max [m] (a room may be a union of rectangles; Ki may be 0 for a room that
                only ``room_index_at`` knows). A (K, 4) array means one rectangle per room.
            robot_radius_m: radius of the robot discs [m].
            room_index_at: optional lookup from (N, 2) points to (N,) room indices (-1 outside
                every room), for rooms that are not rectangles: a robot is in such a room
                when its centre is.
        """
        per_room = [np.asarray(r, dtype=float).reshape(-1, 4) for r in room_rects]
        rects = np.concatenate(per_room) if per_room else np.zeros((0, 4))
        if np.any(rects[:, 2] <= rects[:, 0]) or np.any(rects[:, 3] <= rects[:, 1]):
            raise WorldGeometryError('every room rectangle needs x_max > x_min and y_max > y_min')
        self._rects = rects
        rect_room = np.repeat(np.arange(len(per_room)), [len(r) for r in per_room])
        self._rect_room = rect_room.astype(np.int64)
        # (R, K) 0/1 matrix: rectangle r belongs to room k.
        self._membership = np.zeros((len(rects), len(per_room)), dtype=np.int32)
        self._membership[np.arange(len(rects)), rect_room] = 1
        self._num_rooms = len(per_room)
        self._room_index_at = room_index_at
        self._radius_m = float(robot_radius_m)
        self._first_robot = np.full(self._num_rooms, -1, dtype=int)
        self._entries: list[RoomEntry] = []

    @property
    def rooms_total(self) -> int:
        """Number of rooms K."""
        return self._num_rooms

    @property
    def rooms_covered(self) -> int:
        """Number of rooms entered so far."""
        return len(self._entries)

    @property
    def entries(self) -> tuple[RoomEntry, ...]:
        """Every first entry so far, in order."""
        return tuple(self._entries)

    @property
    def fraction(self) -> float:
        """Covered rooms / total rooms (1.0 for a site without rooms)."""
        return self.rooms_covered / self.rooms_total if self.rooms_total else 1.0

    @property
    def complete(self) -> bool:
        """True once every room is covered."""
        return self.rooms_covered == self.rooms_total

    def inside(self, positions: np.ndarray) -> np.ndarray:
        """(N, K) bool: robot disc i overlaps the interior of room k (compiled rectangle
        test, equal to :meth:`inside_reference`)."""
        xy = np.asarray(positions, dtype=float)[:, :2]
        result = rooms_touched_kernel(
            np.ascontiguousarray(xy),
            self._rects,
            self._rect_room,
            self._num_rooms,
            self._radius_m**2,
        )
        return self._add_room_lookup(xy, result)

    def _add_room_lookup(self, xy: np.ndarray, result: np.ndarray) -> np.ndarray:
        if self._room_index_at is not None:
            index = np.asarray(self._room_index_at(xy), dtype=int)
            robots = np.flatnonzero((index >= 0) & (index < self._num_rooms))
            result[robots, index[robots]] = True
        return result

    def inside_reference(self, positions: np.ndarray) -> np.ndarray:
        """:meth:`inside` in numpy, the reference of the compiled test."""
        xy = np.asarray(positions, dtype=float)[:, :2]
        r = self._rects
        x, y = xy[:, None, 0], xy[:, None, 1]
        dx = np.maximum(np.maximum(r[None, :, 0] - x, x - r[None, :, 2]), 0.0)
        dy = np.maximum(np.maximum(r[None, :, 1] - y, y - r[None, :, 3]), 0.0)
        in_rect = dx * dx + dy * dy < self._radius_m**2
        result = (in_rect.astype(np.int32) @ self._membership) > 0
        return self._add_room_lookup(xy, result)

    def update(self, positions: np.ndarray, time_s: float) -> list[RoomEntry]:
        """Record first entries at ``time_s`` from (N, 2+) robot positions; return the new ones.

        When several robots enter the same room in the same step, the lowest index wins
        (robots move in index order).
        """
        if self.complete:
            return []
        new: list[RoomEntry] = []
        if self._room_index_at is None:
            # Rectangle rooms only: the compiled test of the rooms not entered yet.
            entering = rooms_entered_kernel(
                np.asarray(positions, dtype=float),
                self._rects,
                self._rect_room,
                self._radius_m**2,
                self._first_robot,
            )
            if not len(entering):
                return new
            rooms = np.flatnonzero(entering >= 0).tolist()
            robots = entering[rooms].tolist()
        else:
            hits = self.inside(positions)
            rooms = np.flatnonzero((self._first_robot < 0) & hits.any(axis=0)).tolist()
            robots = [int(np.flatnonzero(hits[:, k])[0]) for k in rooms]
        for k, robot in zip(rooms, robots, strict=True):
            self._first_robot[k] = robot
            entry = RoomEntry(room_index=k, robot_index=robot, time_s=float(time_s))
            self._entries.append(entry)
            new.append(entry)
        return new
