"""Scan features: front wall, peers told from walls by their bearings, side walls, bad ranges."""

from __future__ import annotations

import math

import numpy as np
import pytest
from oabug_robot.errors import ScanError
from oabug_robot.scan_features import LaserScanData, ScanFeatureExtractor
from oabug_robot.settings import PerceptionConfig

RAYS = 360
ANGLES = -math.pi + np.arange(RAYS) * (2 * math.pi / RAYS)


def scan_of(ranges: np.ndarray, range_max: float = 12.0) -> LaserScanData:
    return LaserScanData(
        ranges_m=np.asarray(ranges, dtype=np.float32),
        angle_min_rad=-math.pi,
        angle_increment_rad=2 * math.pi / RAYS,
        range_min_m=0.05,
        range_max_m=range_max,
    )


def box_ranges(ahead_m: float, left_m: float, behind_m: float, right_m: float) -> np.ndarray:
    """Ranges seen from inside an axis-aligned rectangular room (walls at these distances)."""
    c, s = np.cos(ANGLES), np.sin(ANGLES)
    with np.errstate(divide='ignore'):
        tx = np.where(c > 0, ahead_m / c, np.where(c < 0, -behind_m / c, np.inf))
        ty = np.where(s > 0, left_m / s, np.where(s < 0, -right_m / s, np.inf))
    return np.minimum(tx, ty)


def add_disc(ranges: np.ndarray, x: float, y: float, radius: float) -> np.ndarray:
    """Ranges with a disc (a peer robot) centred at (x, y) in the robot frame."""
    c, s = np.cos(ANGLES), np.sin(ANGLES)
    proj = c * x + s * y
    perp_sq = x * x + y * y - proj**2
    hit = (perp_sq <= radius**2) & (proj > 0)
    t = proj - np.sqrt(np.maximum(radius**2 - perp_sq, 0.0))
    return np.where(hit & (t < ranges), t, ranges)


@pytest.fixture
def extractor() -> ScanFeatureExtractor:
    return ScanFeatureExtractor(PerceptionConfig())


def test_wall_ahead_is_measured_along_the_driving_corridor(extractor) -> None:
    features = extractor.extract(scan_of(box_ranges(0.6, 1.0, 2.0, 1.0)))
    assert features.front_wall_m == pytest.approx(0.6, abs=1e-3)
    assert features.front_robot_m == math.inf


def test_side_walls_are_found_abeam_at_their_distance(extractor) -> None:
    features = extractor.extract(scan_of(box_ranges(5.0, 0.3, 5.0, 0.5)))
    assert features.left.distance_m == pytest.approx(0.3, abs=1e-3)
    assert features.left.bearing_rad == pytest.approx(math.pi / 2, abs=math.radians(1.5))
    assert features.right.distance_m == pytest.approx(0.5, abs=1e-3)
    assert features.right.bearing_rad == pytest.approx(-math.pi / 2, abs=math.radians(1.5))


def test_returns_beyond_the_feature_range_are_ignored(extractor) -> None:
    features = extractor.extract(scan_of(box_ranges(1.5, 1.5, 1.5, 1.5)))
    assert features.near_returns == 0
    assert features.front_wall_m == math.inf


def test_side_walls_beyond_capture_range_are_not_followed(extractor) -> None:
    features = extractor.extract(scan_of(box_ranges(5.0, 3.0, 5.0, 3.0)))
    assert not features.left.found
    assert not features.right.found
    assert math.isnan(features.left.bearing_rad)


def test_a_peer_ahead_is_a_robot_not_a_wall_when_its_bearing_is_heard(extractor) -> None:
    ranges = add_disc(box_ranges(3.0, 1.5, 3.0, 1.5), 0.4, 0.0, 0.12)
    heard = extractor.extract(scan_of(ranges), np.array([math.radians(3.0)]))
    assert heard.front_robot_m == pytest.approx(0.28, abs=0.01)
    assert heard.front_wall_m > 1.0, 'the peer hides the wall; its own returns are no wall'
    assert heard.peer_returns > 0
    unheard = extractor.extract(scan_of(ranges))
    assert unheard.front_wall_m == pytest.approx(0.28, abs=0.01)
    assert unheard.front_robot_m == math.inf


def test_a_wall_behind_a_peer_stays_a_wall(extractor) -> None:
    # The peer ahead-left hides part of the wall; the rest of the corridor sees the wall.
    ranges = add_disc(box_ranges(0.7, 1.5, 3.0, 1.5), 0.35, 0.15, 0.12)
    features = extractor.extract(scan_of(ranges), np.array([math.atan2(0.15, 0.35)]))
    assert features.front_robot_m == pytest.approx(math.hypot(0.35, 0.15) - 0.12, abs=0.01)
    assert features.front_wall_m == pytest.approx(0.7, abs=0.01)


def test_a_peer_beside_the_followed_wall_is_not_taken_for_the_wall(extractor) -> None:
    ranges = add_disc(box_ranges(5.0, 0.6, 5.0, 3.0), 0.0, 0.3, 0.12)
    features = extractor.extract(scan_of(ranges), np.array([math.pi / 2]))
    # The nearest left return is the wall just beside the peer's shadow, not the peer.
    assert features.left.distance_m >= 0.6
    assert abs(features.left.bearing_rad - math.pi / 2) < math.radians(30.0)
    assert features.front_robot_m == math.inf, 'a peer abeam is outside the front cone'


def test_bearings_with_nan_azimuth_mask_nothing(extractor) -> None:
    ranges = add_disc(box_ranges(3.0, 1.5, 3.0, 1.5), 0.4, 0.0, 0.12)
    features = extractor.extract(scan_of(ranges), np.array([math.nan]))
    assert features.peer_returns == 0


def test_nan_ranges_are_ignored(extractor) -> None:
    ranges = box_ranges(0.6, 1.0, 2.0, 1.0).astype(np.float32)
    ranges[::2] = np.nan
    features = extractor.extract(scan_of(ranges))
    whole = extractor.extract(scan_of(box_ranges(0.6, 1.0, 2.0, 1.0)))
    assert features.front_wall_m == pytest.approx(0.6, abs=0.01)
    assert 0 < features.near_returns < whole.near_returns


def test_positive_infinity_is_free_space_and_negative_infinity_an_obstacle(extractor) -> None:
    ranges = np.full(RAYS, np.inf)
    free = extractor.extract(scan_of(ranges))
    assert free.front_wall_m == math.inf
    assert free.near_returns == 0
    ranges[RAYS // 2] = -np.inf  # straight ahead, closer than range_min
    blocked = extractor.extract(scan_of(ranges))
    assert blocked.front_wall_m == pytest.approx(0.05)


def test_ranges_outside_the_valid_interval_are_ignored(extractor) -> None:
    ranges = box_ranges(0.6, 1.0, 2.0, 1.0)
    ranges[RAYS // 2 - 20 : RAYS // 2 + 20] = 0.01  # below range_min: a bad echo
    features = extractor.extract(scan_of(ranges))
    assert features.front_wall_m > 0.5


def test_all_nan_scan_gives_no_features_instead_of_failing(extractor) -> None:
    features = extractor.extract(scan_of(np.full(RAYS, np.nan)))
    assert features.near_returns == 0
    assert features.front_wall_m == math.inf
    assert not features.left.found


def test_an_empty_scan_is_rejected(extractor) -> None:
    with pytest.raises(ScanError, match='at least one range'):
        extractor.extract(scan_of(np.zeros(0)))


def test_non_finite_scan_angles_are_rejected(extractor) -> None:
    scan = LaserScanData(np.ones(10), math.nan, 0.1, 0.05, 10.0)
    with pytest.raises(ScanError, match='finite'):
        extractor.extract(scan)


def test_lidar_yaw_offset_rotates_the_scan_into_the_robot_frame() -> None:
    rotated = ScanFeatureExtractor(PerceptionConfig(lidar_yaw_offset_rad=math.pi))
    # Lidar mounted backwards: what it sees "behind" (0.6 m) is ahead of the robot.
    features = rotated.extract(scan_of(box_ranges(3.0, 1.0, 0.6, 1.0)))
    assert features.front_wall_m == pytest.approx(0.6, abs=1e-3)


def test_a_partial_scan_uses_its_own_angles(extractor) -> None:
    angles = np.linspace(-math.pi / 2, math.pi / 2, 181)
    ranges = np.where(np.abs(angles) < 0.1, 0.5, 4.0)
    scan = LaserScanData(ranges, -math.pi / 2, math.pi / 180, 0.05, 12.0)
    features = extractor.extract(scan)
    assert features.front_wall_m == pytest.approx(0.5 * math.cos(0.0), abs=0.01)
