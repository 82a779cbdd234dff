"""Outer corners are seen when the followed wall's direction swings towards the rear."""

from __future__ import annotations

import math

import pytest
from oabug_robot.corners import CornerDetector
from oabug_robot.scan_features import SideWall

DT = 0.1


def feed(detector: CornerDetector, steps: list[tuple[float, float]], side: int, t0: float = 0.0):
    """Feed (yaw_deg, bearing_deg) pairs at 10 Hz; return the indices of corner events."""
    events = []
    for k, (yaw_deg, bearing_deg) in enumerate(steps):
        wall = SideWall(0.25, math.radians(bearing_deg))
        if detector.update(t0 + k * DT, math.radians(yaw_deg), side, wall):
            events.append(k)
    return events


@pytest.mark.parametrize('side', [1, -1])
def test_a_straight_wall_gives_no_corner(side: int) -> None:
    detector = CornerDetector()
    assert feed(detector, [(0.0, side * 90.0)] * 50, side) == []


@pytest.mark.parametrize('side', [1, -1])
def test_wrapping_round_a_wall_end_is_one_outer_corner(side: int) -> None:
    detector = CornerDetector()
    straight = [(0.0, side * 90.0)] * 10
    # Circling the wall end: the heading turns towards the wall side by 90 deg while the
    # end stays abeam-to-behind.
    wrap = [(side * a, side * (90.0 + 20.0)) for a in range(0, 91, 6)]
    after = [(side * 90.0, side * 90.0)] * 20
    events = feed(detector, straight + wrap + after, side)
    assert len(events) == 1
    assert len(straight) <= events[0] < len(straight) + len(wrap)


@pytest.mark.parametrize('side', [1, -1])
def test_wrapping_a_thin_jamb_through_180_degrees_is_two_corners(side: int) -> None:
    detector = CornerDetector()
    straight = [(0.0, side * 90.0)] * 10
    wrap = [(side * a, side * 100.0) for a in range(0, 181, 5)]
    after = [(side * 180.0, side * 90.0)] * 20
    assert len(feed(detector, straight + wrap + after, side)) == 2


@pytest.mark.parametrize('side', [1, -1])
def test_an_inner_corner_is_not_an_outer_corner(side: int) -> None:
    detector = CornerDetector()
    straight = [(0.0, side * 90.0)] * 10
    # A wall ahead becomes the nearest return; the robot turns away from its side.
    approach = [(0.0, side * 10.0)] * 3
    turn = [(-side * a, side * (10.0 + a)) for a in range(0, 81, 8)]
    after = [(-side * 90.0, side * 90.0)] * 20
    assert feed(detector, straight + approach + turn + after, side) == []


def test_no_wall_return_gives_no_corner_and_keeps_the_reference() -> None:
    detector = CornerDetector()
    feed(detector, [(0.0, 90.0)] * 10, 1)
    anchor = detector.anchor_rad
    assert not detector.update(2.0, 0.0, 1, SideWall())
    assert detector.anchor_rad == anchor


def test_reset_forgets_the_wall() -> None:
    detector = CornerDetector()
    feed(detector, [(0.0, 90.0)] * 10, 1)
    detector.reset()
    assert detector.anchor_rad is None
