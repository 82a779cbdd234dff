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
    features = extractor.extract(scan_of(box_ranges(5.0, 0.3, 5.0, 0.4)))
    assert features.left.distance_m == pytest.approx(0.3, abs=1e-3)
    assert features.left.angle_rad == pytest.approx(0.0, abs=math.radians(1.0))
    assert features.left.abeam
    assert features.right.distance_m == pytest.approx(0.4, abs=1e-3)
    assert features.right.angle_rad == pytest.approx(0.0, abs=math.radians(1.0))
    assert features.right.abeam


def test_returns_beyond_the_feature_range_are_ignored(extractor) -> None:
    features = extractor.extract(scan_of(box_ranges(1.5, 1.5, 1.5, 1.5)))
    assert features.near_returns == 0
    assert features.front_wall_m == math.inf


def test_side_walls_beyond_capture_range_are_not_followed(extractor) -> None:
    features = extractor.extract(scan_of(box_ranges(5.0, 3.0, 5.0, 3.0)))
    assert not features.left.found
    assert not features.right.found
    assert not features.left.abeam


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
    heard = extractor.extract(scan_of(ranges), np.array([math.pi / 2]))
    # The peer hides the wall beside the robot; its own returns are not a wall.
    assert not heard.left.found
    assert heard.front_robot_m == math.inf, 'a peer abeam is outside the front cone'
    unheard = extractor.extract(scan_of(ranges))
    assert unheard.left.distance_m == pytest.approx(0.18, abs=0.01)


@pytest.mark.parametrize('kernel', [False, True])
def test_a_peer_touching_the_body_ahead_of_abeam_is_a_hit(kernel: bool) -> None:
    from oabug_robot.scan_features_kernel import extract_many

    def features(config: PerceptionConfig, bearing_deg: float) -> float:
        # A peer (radius 0.1 m) touching the body (centres 0.2 m apart); as the RPLidar A1
        # reports it, nearer than its 0.15 m minimum range: -inf.
        direction = math.radians(bearing_deg)
        x, y = 0.2 * math.cos(direction), 0.2 * math.sin(direction)
        ranges = add_disc(box_ranges(3.0, 1.5, 3.0, 1.5), x, y, 0.1)
        ranges = np.where(ranges < 0.15, -np.inf, ranges)
        scan = LaserScanData(
            np.asarray(ranges, dtype=np.float32), -math.pi, 2 * math.pi / RAYS, 0.15, 12.0
        )
        extractor = ScanFeatureExtractor(config)
        bearings = np.array([direction])
        if kernel:
            (result,) = extract_many(extractor, [scan], [(bearings, None)], [0])
        else:
            result = extractor.extract(scan, bearings)
        return result.front_robot_m

    config = PerceptionConfig()
    hit = config.robot_hit_distance_m
    for bearing in (0.0, 70.0, -80.0):  # in the cone, and beside it ahead of abeam
        assert features(config, bearing) <= hit, bearing
    for bearing in (100.0, -120.0, 180.0):  # behind abeam: driving on frees the robot
        assert features(config, bearing) == math.inf, bearing
    off = PerceptionConfig(robot_contact_distance_m=0.0)
    assert features(off, 0.0) <= hit
    assert features(off, 70.0) == math.inf, 'without the rule only the 30 deg cone hits'


@pytest.mark.parametrize('kernel', [False, True])
def test_in_path_the_contact_rule_ignores_a_peer_beside_the_path(kernel: bool) -> None:
    """A peer passed with a 5 cm gap (centre 0.12 m ahead, 0.22 m to the left: its nearest
    returns at 58-60 deg, 0.15-0.16 m) is within the contact sector and distance, but the
    body's path misses it; a peer touching the body ahead of abeam is in the path."""
    from oabug_robot.scan_features_kernel import extract_many

    def front_robot_m(config: PerceptionConfig, x: float, y: float) -> float:
        ranges = add_disc(box_ranges(3.0, 1.5, 3.0, 1.5), x, y, 0.1)
        extractor = ScanFeatureExtractor(config)
        bearings = np.array([math.atan2(y, x)])
        if kernel:
            (result,) = extract_many(extractor, [scan_of(ranges)], [(bearings, None)], [0])
        else:
            result = extractor.extract(scan_of(ranges), bearings)
        return result.front_robot_m

    sector = PerceptionConfig(robot_contact_in_path=False)
    in_path = PerceptionConfig()
    assert in_path.robot_contact_in_path, 'the default'
    hit = sector.robot_hit_distance_m
    assert front_robot_m(sector, 0.12, 0.22) <= sector.robot_contact_distance_m
    assert front_robot_m(in_path, 0.12, 0.22) == math.inf
    assert front_robot_m(in_path, 0.12, -0.22) == math.inf
    for bearing_deg in (0.0, 40.0, -55.0, 70.0):  # touching, ahead of abeam
        direction = math.radians(bearing_deg)
        x, y = 0.2 * math.cos(direction), 0.2 * math.sin(direction)
        assert front_robot_m(in_path, x, y) <= hit, bearing_deg


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


def segment_ranges(segments: list[tuple[float, float, float, float]]) -> np.ndarray:
    """Ranges from the origin to thin wall segments (x0, y0, x1, y1) in the robot frame."""
    c, s = np.cos(ANGLES), np.sin(ANGLES)
    best = np.full(RAYS, np.inf)
    for x0, y0, x1, y1 in segments:
        ex, ey = x1 - x0, y1 - y0
        denom = c * ey - s * ex
        with np.errstate(divide='ignore', invalid='ignore'):
            t = (x0 * ey - y0 * ex) / denom
            u = (x0 * s - y0 * c) / denom
        hit = (np.abs(denom) > 1e-12) & (t > 0) & (u >= 0) & (u <= 1)
        best = np.where(hit & (t < best), t, best)
    return best


@pytest.mark.parametrize('side', [1, -1])
def test_a_wall_converging_ahead_has_the_angle_of_its_direction(extractor, side: int) -> None:
    # The wall runs from 0.4 m beside the robot at x = -0.5 to 0.2 m at x = 0.5.
    tilt = math.atan2(-0.2, 1.0)
    ranges = segment_ranges([(-0.5, side * 0.4, 0.5, side * 0.2)])
    wall = extractor.extract(scan_of(ranges)).side(side)
    assert wall.angle_rad == pytest.approx(side * tilt, abs=math.radians(2.0))
    assert wall.distance_m == pytest.approx(0.3 * math.cos(tilt), abs=0.01)


def test_the_far_jamb_of_a_door_does_not_pull_the_follower_past_it(extractor) -> None:
    # Following a wall on the left that ends 5 cm behind the lidar; a 0.5 m door, then the
    # wall goes on. Nothing beside the robot any more: the corner is passed.
    ranges = segment_ranges([(-1.0, 0.25, -0.05, 0.25), (0.45, 0.25, 1.5, 0.25)])
    features = extractor.extract(scan_of(ranges))
    assert not features.left.abeam
    assert features.left.distance_m == pytest.approx(0.25, abs=0.01), 'the wall just behind'
    before_the_end = extractor.extract(scan_of(segment_ranges([(-1.0, 0.25, 0.1, 0.25)])))
    assert before_the_end.left.abeam


def test_a_perpendicular_wall_behind_is_not_part_of_the_wall_beside(extractor) -> None:
    # Just through a door: the jamb wall on the left, the corridor wall behind, across.
    ranges = segment_ranges([(-0.1, 0.25, 1.0, 0.25), (-0.12, 0.25, -0.12, 1.0)])
    wall = extractor.extract(scan_of(ranges)).left
    assert wall.distance_m == pytest.approx(0.25, abs=0.01)
    assert wall.angle_rad == pytest.approx(0.0, abs=math.radians(2.0))


def test_only_the_requested_side_walls_are_fitted(extractor) -> None:
    scan = scan_of(box_ranges(5.0, 0.3, 5.0, 0.4))
    left_only = extractor.extract(scan, sides=(1,))
    assert left_only.left.distance_m == pytest.approx(0.3, abs=1e-3)
    assert not left_only.right.found
    neither = extractor.extract(scan, sides=())
    assert not neither.left.found
    assert not neither.right.found
    assert neither.front_wall_m == math.inf


def corridor_ranges(half_width_m: float, heading_rad: float) -> np.ndarray:
    """Ranges from the middle of an endless straight corridor, heading at an angle to it."""
    s = np.abs(np.sin(ANGLES + heading_rad))
    with np.errstate(divide='ignore'):
        return np.where(s > 1e-9, half_width_m / s, np.inf)


@pytest.mark.parametrize('heading_deg', [0.0, 30.0, 60.0, 90.0, 120.0, 150.0])
def test_a_robot_can_turn_on_the_spot_in_the_middle_of_a_two_cell_corridor(
    extractor, heading_deg: float
) -> None:
    """Generated sites have 2-cell (0.53 m) corridors, rooms and dead ends; turning round in
    them must not read the side walls as a wall ahead, or the robot spins on the spot."""
    half_width_m = 4.0 / 15.0
    features = extractor.extract(scan_of(corridor_ranges(half_width_m, math.radians(heading_deg))))
    assert features.front_wall_m > PerceptionConfig().wall_hit_distance_m
