"""Outer-corner detection while following a wall.

The paper's "outer corner" is where the followed wall ends on the following side (a wall
end, a door jamb, the convex corner of a room). The authors' simulator fires it once the
robot's trailing face has passed the wall's end. Here the lidar's abeam strip beside the
body (see :class:`oabug_robot.scan_features.SideWall`) plays that part: the detector arms
while the strip holds a wall return and fires once when it empties. It re-arms only when a
wall is abeam again, so wrapping round a thin door jamb (its 2.5 cm end face is abeam only
for a moment) counts as two corners, as in the authors' grid simulator.
"""

from __future__ import annotations

from oabug_robot.scan_features import SideWall

__all__ = ['CornerDetector']


class CornerDetector:
    """Fires once each time the wall on the followed side ends beside the robot."""

    def __init__(self) -> None:
        self._armed = False

    @property
    def armed(self) -> bool:
        """True while a wall has been abeam since the last corner (or reset)."""
        return self._armed

    def reset(self) -> None:
        """Forget the wall (call when a new wall is taken up or a wrap starts)."""
        self._armed = False

    def update(self, wall: SideWall) -> bool:
        """Feed the followed side's wall of one step; True when an outer corner was passed."""
        if wall.abeam:
            self._armed = True
            return False
        if self._armed:
            self._armed = False
            return True
        return False
