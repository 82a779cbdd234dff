"""Outer-corner detection while following a wall, from the lidar and the IMU yaw.

The paper's "outer corner" is where the followed wall ends on the following side (a wall
end, a door jamb, the convex corner of a room). While the robot follows a straight wall,
the nearest wall return on the following side points the same way in the yaw frame: along
the wall's normal. Where the wall ends, the robot wraps round the end and that direction
turns with it, towards the travel direction. Once it has turned by ``trigger_rad`` from the
settled wall normal, that is an outer corner. The reference then moves on by 90 deg, so a
thin door jamb wrapped through 180 deg counts as two corners, as in the authors' grid
simulator. An inner corner turns the direction the other way and only re-anchors it.

The reference re-settles on the measured normal whenever the robot has held its heading
for ``settle_s`` with the wall abeam, which absorbs walls that are not at right angles.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from oabug_robot.heading import angle_difference, wrap_angle
from oabug_robot.scan_features import SideWall

__all__ = ['CornerDetector', 'CornerDetectorConfig']


@dataclass(frozen=True)
class CornerDetectorConfig:
    """Thresholds of :class:`CornerDetector`.

    Attributes:
        trigger_rad: turn of the wall direction, past the settled normal, that is a corner.
        settle_s: heading held this long with the wall abeam settles the reference [s].
        settle_yaw_change_rad: heading changes below this count as "held" [rad].
        abeam_tolerance_rad: the wall counts as abeam within this of +-90 deg [rad].
    """

    trigger_rad: float = math.radians(45.0)
    settle_s: float = 0.5
    settle_yaw_change_rad: float = math.radians(5.0)
    abeam_tolerance_rad: float = math.radians(20.0)


class CornerDetector:
    """Fires once per outer corner passed while following a wall on one side."""

    def __init__(self, config: CornerDetectorConfig | None = None) -> None:
        self._config = config or CornerDetectorConfig()
        self._anchor_rad: float | None = None
        self._held_yaw_rad = 0.0
        self._held_since_s = 0.0

    @property
    def anchor_rad(self) -> float | None:
        """The settled wall-normal direction in the yaw frame [rad], None before any wall."""
        return self._anchor_rad

    def reset(self) -> None:
        """Forget the wall (call when a new wall is taken up)."""
        self._anchor_rad = None

    def update(self, time_s: float, yaw_rad: float, side: int, wall: SideWall) -> bool:
        """Feed one control step; return True when an outer corner has just been passed.

        Args:
            time_s: current time [s].
            yaw_rad: current heading [rad].
            side: the followed side, +1 left or -1 right.
            wall: the nearest wall return on that side.
        """
        cfg = self._config
        if abs(angle_difference(yaw_rad, self._held_yaw_rad)) > cfg.settle_yaw_change_rad:
            self._held_yaw_rad = yaw_rad
            self._held_since_s = time_s
        if not wall.found:
            return False
        direction = wrap_angle(yaw_rad + wall.bearing_rad)
        if self._anchor_rad is None:
            self._anchor_rad = direction
            return False
        abeam = (
            abs(angle_difference(wall.bearing_rad, side * math.pi / 2)) <= cfg.abeam_tolerance_rad
        )
        if abeam and time_s - self._held_since_s >= cfg.settle_s:
            self._anchor_rad = direction
            return False
        progress = side * angle_difference(direction, self._anchor_rad)
        if progress >= cfg.trigger_rad:
            self._anchor_rad = wrap_angle(self._anchor_rad + side * math.pi / 2)
            return True
        if progress <= -cfg.trigger_rad:
            self._anchor_rad = direction
        return False
