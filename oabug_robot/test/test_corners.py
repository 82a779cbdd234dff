"""Outer corners: the followed wall is no longer beside the body."""

from __future__ import annotations

from oabug_robot.corners import CornerDetector
from oabug_robot.scan_features import SideWall

ABEAM = SideWall(0.25, 0.0, abeam=True)
PASSED = SideWall(0.3, 0.0, abeam=False)
NO_WALL = SideWall()


def feed(detector: CornerDetector, walls: list[SideWall]) -> list[int]:
    return [k for k, wall in enumerate(walls) if detector.update(wall)]


def test_a_wall_beside_the_robot_gives_no_corner() -> None:
    assert feed(CornerDetector(), [ABEAM] * 20) == []


def test_the_wall_ending_beside_the_robot_is_one_outer_corner() -> None:
    assert feed(CornerDetector(), [ABEAM] * 5 + [PASSED] * 5 + [NO_WALL] * 5) == [5]


def test_a_thin_jamb_wrapped_in_two_arcs_is_two_corners() -> None:
    walls = [ABEAM] * 5 + [PASSED] * 3 + [ABEAM] + [PASSED] * 3 + [ABEAM] * 5
    assert feed(CornerDetector(), walls) == [5, 9]


def test_nothing_is_a_corner_before_a_wall_has_been_beside_the_robot() -> None:
    assert feed(CornerDetector(), [NO_WALL] * 3 + [PASSED] * 3) == []


def test_reset_forgets_the_wall() -> None:
    detector = CornerDetector()
    feed(detector, [ABEAM] * 3)
    assert detector.armed
    detector.reset()
    assert not detector.armed
    assert not detector.update(PASSED)
