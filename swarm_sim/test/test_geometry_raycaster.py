"""The lidar ray caster against walls and robots whose ranges are known in closed form."""

import math

import numpy as np
import pytest
from swarm_sim.errors import WorldGeometryError
from swarm_sim.geometry import (
    RayCaster,
    WallGrid,
    count_crossings,
    point_segment_distance,
    wrap_angle,
)

BOX = np.array(
    [
        [[0.0, 0.0], [4.0, 0.0]],
        [[4.0, 0.0], [4.0, 3.0]],
        [[4.0, 3.0], [0.0, 3.0]],
        [[0.0, 3.0], [0.0, 0.0]],
    ]
)


def bin_of(caster: RayCaster, robot_frame_angle_rad: float) -> int:
    return round((robot_frame_angle_rad - caster.angle_min_rad) / caster.angle_increment_rad)


def test_ranges_in_a_box_match_the_distance_to_each_wall_face():
    caster = RayCaster(BOX, wall_thickness_m=0.1, robot_radius_m=0.1, num_bins=360)
    ranges = caster.scan(np.array([[1.0, 1.0, 0.0]]), max_range_m=12.0)[0]
    assert ranges[bin_of(caster, 0.0)] == pytest.approx(3.0 - 0.05)
    assert ranges[bin_of(caster, math.pi / 2)] == pytest.approx(2.0 - 0.05)
    assert ranges[bin_of(caster, -math.pi / 2)] == pytest.approx(1.0 - 0.05)
    assert ranges[bin_of(caster, -math.pi)] == pytest.approx(1.0 - 0.05)
    diagonal = bin_of(caster, math.pi / 4)
    assert ranges[diagonal] == pytest.approx(math.sqrt(2) * 1.95)
    assert np.all(np.isfinite(ranges))


def test_scan_bins_rotate_with_the_robot_heading():
    caster = RayCaster(BOX, wall_thickness_m=0.0, robot_radius_m=0.1, num_bins=360)
    facing_up = caster.scan(np.array([[1.0, 1.0, math.pi / 2]]), 12.0)[0]
    # Straight ahead is now +y (2 m away); the robot's left is -x (1 m away).
    assert facing_up[bin_of(caster, 0.0)] == pytest.approx(2.0)
    assert facing_up[bin_of(caster, math.pi / 2)] == pytest.approx(1.0)


def test_returns_beyond_max_range_are_infinite():
    caster = RayCaster(BOX, wall_thickness_m=0.0, robot_radius_m=0.1, num_bins=360)
    ranges = caster.scan(np.array([[1.0, 1.0, 0.0]]), max_range_m=1.5)[0]
    assert ranges[bin_of(caster, 0.0)] == math.inf
    assert ranges[bin_of(caster, -math.pi / 2)] == pytest.approx(1.0)


def test_rays_hit_other_robots_but_never_the_own_body():
    caster = RayCaster(np.zeros((0, 2, 2)), wall_thickness_m=0.0, robot_radius_m=0.1, num_bins=360)
    poses = np.array([[0.0, 0.0, 0.0], [2.0, 0.0, math.pi]])
    ranges = caster.scan(poses, 12.0)
    assert ranges[0, bin_of(caster, 0.0)] == pytest.approx(1.9)
    assert ranges[1, bin_of(caster, 0.0)] == pytest.approx(1.9)
    assert np.isinf(ranges[0, bin_of(caster, math.pi / 2)])


def test_a_ray_along_a_wall_hits_its_end_face():
    wall = np.array([[[1.0, 0.0], [3.0, 0.0]]])
    caster = RayCaster(wall, wall_thickness_m=0.1, robot_radius_m=0.1, num_bins=360)
    ranges = caster.scan(np.array([[0.0, 0.0, 0.0]]), 12.0)[0]
    assert ranges[bin_of(caster, 0.0)] == pytest.approx(0.95)


def test_caster_agrees_with_pybullet_ray_tests():
    pytest.importorskip('pybullet')
    from swarm_sim.pybullet_scene import PybulletScene

    rng = np.random.default_rng(4)
    walls = []
    for i in range(40):
        x, y, length = rng.uniform(0, 8), rng.uniform(0, 6), rng.uniform(0.3, 2.0)
        walls.append([[x, y], [x + length, y]] if i % 2 else [[x, y], [x, y + length]])
    walls = np.array(walls)
    caster = RayCaster(walls, wall_thickness_m=0.025, robot_radius_m=0.1, num_bins=360)
    poses = np.column_stack([rng.uniform(0, 8, 3), rng.uniform(0, 6, 3), rng.uniform(-3, 3, 3)])
    with PybulletScene(walls, wall_thickness_m=0.025) as scene:
        for pose in poses:
            expected = scene.cast_scan(pose, caster.bin_angles_rad, max_range_m=12.0)
            got = caster.scan(pose[None, :], 12.0)[0]
            assert np.array_equal(np.isinf(got), np.isinf(expected))
            finite = np.isfinite(got)
            assert np.max(np.abs(got[finite] - expected[finite])) < 0.01


def test_malformed_walls_are_rejected_with_the_reason():
    with pytest.raises(WorldGeometryError, match='shape'):
        RayCaster(np.zeros((3, 2)), wall_thickness_m=0.0, robot_radius_m=0.1, num_bins=360)
    with pytest.raises(WorldGeometryError, match='zero length'):
        RayCaster(np.zeros((1, 2, 2)), wall_thickness_m=0.0, robot_radius_m=0.1, num_bins=360)
    with pytest.raises(WorldGeometryError, match='NaN'):
        RayCaster(np.full((1, 2, 2), np.nan), wall_thickness_m=0.0, robot_radius_m=0.1, num_bins=8)


def test_point_segment_distance_uses_the_nearest_end_point_beyond_a_segment():
    d = point_segment_distance(np.array([[5.0, 4.0], [2.0, 1.0]]), BOX[:1])
    assert d[:, 0] == pytest.approx([math.hypot(1.0, 4.0), 1.0])


def test_count_crossings_counts_each_wall_between_two_points():
    starts = np.array([[-1.0, 1.0], [1.0, 1.0]])
    ends = np.array([[5.0, 1.0], [2.0, 2.0]])
    assert count_crossings(starts, ends, BOX).tolist() == [2, 0]


def test_wrap_angle_maps_into_minus_pi_to_pi():
    assert wrap_angle(-math.pi) == pytest.approx(math.pi)
    assert wrap_angle(3 * math.pi / 2) == pytest.approx(-math.pi / 2)


def test_wall_grid_distance_is_exact_within_reach_and_never_too_small():
    rng = np.random.default_rng(3)
    walls = rng.uniform(0.0, 6.0, size=(40, 2, 2))
    grid = WallGrid(walls, cell_m=0.5, reach_m=0.3)
    points = rng.uniform(-0.5, 6.5, size=(2000, 2))
    exact = point_segment_distance(points, walls).min(axis=1)
    nearest = grid.nearest_distance(points)
    within = exact <= 0.3
    assert within.sum() > 100
    assert np.array_equal(nearest[within], exact[within])
    assert np.all(nearest[~within] > 0.3)


def test_wall_grid_crossings_equal_the_full_test_for_short_paths():
    rng = np.random.default_rng(4)
    walls = rng.uniform(0.0, 6.0, size=(40, 2, 2))
    grid = WallGrid(walls, cell_m=0.5, reach_m=0.45)
    starts = rng.uniform(0.0, 6.0, size=(3000, 2))
    angle = rng.uniform(-math.pi, math.pi, 3000)
    length = rng.uniform(0.0, 0.45, 3000)
    ends = starts + length[:, None] * np.column_stack([np.cos(angle), np.sin(angle)])
    crossed = grid.count_crossings(starts, ends)
    assert crossed.sum() > 100
    assert np.array_equal(crossed, count_crossings(starts, ends, walls))


def _random_walls(rng: np.random.Generator, count: int) -> np.ndarray:
    starts = rng.uniform(0.0, 8.0, (count, 2))
    angles = rng.uniform(-math.pi, math.pi, count)
    lengths = rng.uniform(0.2, 3.0, count)
    ends = starts + lengths[:, None] * np.column_stack([np.cos(angles), np.sin(angles)])
    return np.stack([starts, ends], axis=1)


@pytest.mark.parametrize(
    ('thickness', 'num_bins', 'robots'),
    [(0.025, 360, 10), (0.0, 360, 4), (0.1, 100, 6), (0.025, 37, 3), (0.025, 360, 1)],
)
def test_compiled_scan_is_bit_identical_to_the_numpy_reference(thickness, num_bins, robots):
    rng = np.random.default_rng(num_bins + robots)
    for trial in range(40):
        walls = _random_walls(rng, 30)
        caster = RayCaster(walls, wall_thickness_m=thickness, robot_radius_m=0.1, num_bins=num_bins)
        # Some robots crowded together, some near walls, headings anywhere.
        xy = rng.uniform(0.0, 8.0, (robots, 2))
        if trial % 2:
            xy[1:] = xy[0] + rng.normal(0.0, 0.25, (robots - 1, 2))
        if trial % 3 == 0:
            xy[0] = walls[0, 0] + rng.normal(0.0, 0.05, 2)
        poses = np.column_stack([xy, rng.uniform(-4.0, 4.0, robots)])
        for max_range in (12.0, 1.5):
            np.testing.assert_array_equal(
                caster.scan(poses, max_range), caster.scan_reference(poses, max_range)
            )


def test_compiled_scan_is_bit_identical_on_a_generated_site():
    from swarm_sim.departure import place_starts
    from swarm_sim.site_geometry import geometry_from_site
    from swarm_sim.site_loading import load_site

    site = load_site('small')
    walls = geometry_from_site(site).walls
    caster = RayCaster(walls, wall_thickness_m=0.025, robot_radius_m=0.1, num_bins=360)
    rng = np.random.default_rng(7)
    lo, hi = walls.reshape(-1, 2).min(axis=0), walls.reshape(-1, 2).max(axis=0)
    poses = place_starts(site, 'center', 10).poses
    for _ in range(200):
        np.testing.assert_array_equal(caster.scan(poses, 12.0), caster.scan_reference(poses, 12.0))
        poses = np.column_stack(
            [rng.uniform(lo[0], hi[0], 10), rng.uniform(lo[1], hi[1], 10), rng.uniform(-4, 4, 10)]
        )


def test_compiled_scan_handles_no_walls_and_no_robots():
    caster = RayCaster(np.zeros((0, 2, 2)), wall_thickness_m=0.025, robot_radius_m=0.1, num_bins=36)
    poses = np.array([[0.0, 0.0, 0.3], [1.0, 0.0, -2.0]])
    np.testing.assert_array_equal(caster.scan(poses, 12.0), caster.scan_reference(poses, 12.0))
    assert np.isfinite(caster.scan(poses, 12.0)).sum() > 0
    assert caster.scan(np.zeros((0, 3)), 12.0).shape == (0, 36)


def test_compiled_crossing_counts_equal_the_numpy_reference():
    from swarm_sim.geometry import _count_hits, _count_hits_numpy, padded_walls

    rng = np.random.default_rng(5)
    walls = np.concatenate([_random_walls(rng, 40), BOX * 2.0])
    grid = WallGrid(walls, cell_m=0.5, reach_m=1.0)
    q, s = padded_walls(walls)
    starts = rng.uniform(-0.5, 8.5, (4000, 2))
    # Paths of every length, some along a wall or ending on one.
    ends = starts + rng.normal(0.0, 1.0, (4000, 2)) * rng.choice([0.0, 0.1, 1.0, 5.0], (4000, 1))
    ends[:40] = walls[:40, 1]
    starts[40:80] = walls[:40, 0] + 0.3 * (walls[:40, 1] - walls[:40, 0])
    ends[40:80] = walls[:40, 0] + 0.7 * (walls[:40, 1] - walls[:40, 0])
    for candidates in (grid.candidates(starts), np.tile(np.arange(len(walls)), (4000, 1))):
        expected = _count_hits_numpy(
            starts, ends, q[:, 0][candidates], q[:, 1][candidates], s, candidates
        )
        assert expected.sum() > 100
        np.testing.assert_array_equal(_count_hits(starts, ends, q, s, candidates), expected)


def test_compiled_nearest_wall_distance_equals_the_numpy_reference():
    rng = np.random.default_rng(6)
    walls = np.concatenate([_random_walls(rng, 40), BOX * 2.0])
    points = rng.uniform(-2.0, 10.0, (5000, 2))
    points[:40] = walls[:40, 0]
    for grid in (
        WallGrid(walls, cell_m=0.5, reach_m=0.225),
        WallGrid(walls, cell_m=0.3, reach_m=2.0),
        WallGrid(np.zeros((0, 2, 2)), cell_m=0.5, reach_m=0.2),
    ):
        np.testing.assert_array_equal(
            grid.nearest_distance(points), grid.nearest_distance_reference(points)
        )


@pytest.mark.parametrize('dropout', [0.005, 0.0, 0.3])
def test_compiled_lidar_noise_equals_the_numpy_reference(dropout):
    from swarm_sim.sensors.lidar import LidarConfig, LidarModel

    rng = np.random.default_rng(8)
    walls = np.concatenate([_random_walls(rng, 30), BOX * 2.0])
    caster = RayCaster(walls, wall_thickness_m=0.025, robot_radius_m=0.1, num_bins=360)
    config = LidarConfig(dropout_probability=dropout, range_max_m=4.0)
    compiled = LidarModel(caster, config, np.random.default_rng(9))
    reference = LidarModel(caster, config, np.random.default_rng(9))
    for _ in range(30):
        poses = np.column_stack([rng.uniform(0.0, 8.0, (6, 2)), rng.uniform(-4.0, 4.0, 6)])
        got = compiled.measure(poses)
        expected = reference.measure_reference(poses)
        assert np.isneginf(expected).any() or np.isposinf(expected).any()
        np.testing.assert_array_equal(got, expected)


def test_compiled_scan_is_bit_identical_for_special_headings():
    # The rays are the bins' fixed directions rotated by the yaw: headings on and next to the
    # bins, signed zeros, +-pi and large multiples of a turn give the reference's ranges.
    walls = _random_walls(np.random.default_rng(3), 20)
    caster = RayCaster(walls, wall_thickness_m=0.025, robot_radius_m=0.1, num_bins=360)
    yaws = [0.0, -0.0, math.pi, -math.pi, 1e-300, -1e-17, math.pi / 2, 100.0 * math.pi, -57.3]
    yaws += list(np.nextafter(np.float64(math.pi / 180.0), 1.0) * np.arange(-3, 4))
    for k, yaw in enumerate(yaws):
        poses = np.array([[2.0 + 0.3 * k, 3.0, yaw], [2.5, 3.4, -yaw], [6.0, 1.0, yaw + 1.0]])
        np.testing.assert_array_equal(caster.scan(poses, 12.0), caster.scan_reference(poses, 12.0))
