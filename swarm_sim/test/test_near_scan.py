"""The near cast (ranges exact up to a cut) and the lidar's horizon against the full scan."""

import math

import numpy as np
import pytest
from swarm_sim.errors import WorldGeometryError
from swarm_sim.geometry import RayCaster
from swarm_sim.raycast_kernel import BEYOND_CUT, EXACT, NO_RETURN
from swarm_sim.sensors.lidar import LidarConfig, LidarModel

BOX = np.array(
    [
        [[0.0, 0.0], [4.0, 0.0]],
        [[4.0, 0.0], [4.0, 3.0]],
        [[4.0, 3.0], [0.0, 3.0]],
        [[0.0, 3.0], [0.0, 0.0]],
    ]
)


def _random_walls(rng: np.random.Generator, count: int, size: float = 8.0) -> np.ndarray:
    starts = rng.uniform(0.0, size, (count, 2))
    angles = rng.uniform(-math.pi, math.pi, count)
    lengths = rng.uniform(0.2, 3.0, count)
    ends = starts + lengths[:, None] * np.column_stack([np.cos(angles), np.sin(angles)])
    return np.stack([starts, ends], axis=1)


def assert_near_scan_agrees(
    caster: RayCaster, poses: np.ndarray, max_range_m: float, cut_m: float
) -> np.ndarray:
    """scan_near's kinds and exact ranges against scan; returns the kinds."""
    full = caster.scan(poses, max_range_m)
    ranges, kind = caster.scan_near(poses, max_range_m, cut_m)
    exact = kind == EXACT
    np.testing.assert_array_equal(ranges[exact], full[exact])
    assert exact[full <= cut_m].all()
    beyond = kind == BEYOND_CUT
    assert (full[beyond] > cut_m).all()
    assert np.isfinite(full[beyond]).all()
    np.testing.assert_array_equal(kind == NO_RETURN, np.isinf(full))
    return kind


def _moves(rng: np.random.Generator, poses: np.ndarray, steps: int) -> list[np.ndarray]:
    """The poses drifting a few centimetres and degrees per step (the certificates of
    one step serve the next), with now and then a robot jumping elsewhere."""
    frames = []
    poses = poses.copy()
    for step in range(steps):
        poses[:, :2] += rng.normal(0.0, 0.05, (len(poses), 2))
        poses[:, 2] += rng.normal(0.0, 0.2, len(poses))
        if step % 7 == 6:
            poses[rng.integers(len(poses))] = [*rng.uniform(-1.0, 9.0, 2), rng.uniform(-4, 4)]
        frames.append(poses.copy())
    return frames


@pytest.mark.parametrize(
    ('thickness', 'num_bins', 'robots', 'walls', 'max_range', 'cut'),
    [
        (0.025, 360, 10, 30, 12.0, 1.1),
        (0.0, 360, 4, 30, 12.0, 1.1),
        (0.1, 100, 6, 30, 5.0, 0.6),
        (0.025, 37, 3, 30, 12.0, 2.5),
        (0.025, 360, 1, 30, 12.0, 1.1),
        # Sparse walls: many rays end nowhere, or only on a far robot.
        (0.025, 360, 8, 4, 6.0, 1.1),
        (0.025, 360, 5, 0, 12.0, 1.1),
        # A cut close to the maximum range.
        (0.025, 360, 6, 30, 3.0, 2.9),
    ],
)
def test_near_scan_equals_the_full_scan_on_random_scenes(
    thickness, num_bins, robots, walls, max_range, cut
):
    rng = np.random.default_rng(num_bins + robots + walls)
    kinds = np.zeros(3, dtype=int)
    for trial in range(12):
        segments = _random_walls(rng, walls) if walls else np.zeros((0, 2, 2))
        caster = RayCaster(
            segments, wall_thickness_m=thickness, robot_radius_m=0.1, num_bins=num_bins
        )
        # Some robots crowded together, some on a wall's end, some far outside the walls.
        xy = rng.uniform(-1.0, 9.0, (robots, 2))
        if trial % 2 and robots > 1:
            xy[1:] = xy[0] + rng.normal(0.0, 0.25, (robots - 1, 2))
        if trial % 3 == 0 and walls:
            xy[0] = segments[0, 0] + rng.normal(0.0, 0.05, 2)
        if trial % 4 == 1:
            xy[-1] = [30.0, -20.0]
        poses = np.column_stack([xy, rng.uniform(-4.0, 4.0, robots)])
        for frame in _moves(rng, poses, 15):
            kind = assert_near_scan_agrees(caster, frame, max_range, cut)
            kinds += np.bincount(kind.ravel(), minlength=3)
    # Every kind of bin occurred (no returns: not with walls all round every robot).
    assert kinds[EXACT] > 0
    assert kinds[BEYOND_CUT] > 0
    assert kinds[NO_RETURN] > 0


def test_near_scan_equals_the_full_scan_on_a_generated_site():
    from swarm_sim.site_geometry import geometry_from_site
    from swarm_sim.site_loading import load_site

    site = load_site('medium')
    walls = geometry_from_site(site).walls
    caster = RayCaster(walls, wall_thickness_m=0.025, robot_radius_m=0.1, num_bins=360)
    rng = np.random.default_rng(11)
    lo, hi = walls.reshape(-1, 2).min(axis=0), walls.reshape(-1, 2).max(axis=0)
    kinds = np.zeros(3, dtype=int)
    for _ in range(30):
        poses = np.column_stack(
            [rng.uniform(lo[0], hi[0], 10), rng.uniform(lo[1], hi[1], 10), rng.uniform(-4, 4, 10)]
        )
        for frame in _moves(rng, poses, 10):
            kind = assert_near_scan_agrees(caster, frame, 12.0, 1.1)
            kinds += np.bincount(kind.ravel(), minlength=3)
    assert kinds.min() > 0


def test_near_scan_rays_ending_on_a_far_robot_or_nowhere():
    # No walls: a ray returns only where it meets another robot, up to the maximum range.
    caster = RayCaster(
        np.zeros((0, 2, 2)), wall_thickness_m=0.025, robot_radius_m=0.1, num_bins=360
    )
    poses = np.array([[0.0, 0.0, 0.0], [0.5, 0.0, 0.0], [5.0, 0.0, 1.0], [0.0, 20.0, 0.0]])
    kind = assert_near_scan_agrees(caster, poses, 12.0, 1.1)
    assert kind[0, 180] == EXACT  # the robot 0.5 m ahead
    assert kind[1, 180] == BEYOND_CUT  # from there, the robot 4.5 m ahead
    assert kind[0, 90] == NO_RETURN  # straight left: the robot 20 m away is out of range


def test_near_scan_of_special_headings_and_sizes():
    walls = np.concatenate([_random_walls(np.random.default_rng(3), 20), BOX * 2.0])
    caster = RayCaster(walls, wall_thickness_m=0.025, robot_radius_m=0.1, num_bins=360)
    yaws = [0.0, -0.0, math.pi, -math.pi, 1e-300, -1e-17, math.pi / 2, 100.0 * math.pi, -57.3]
    for k, yaw in enumerate(yaws):
        poses = np.array([[2.0 + 0.3 * k, 3.0, yaw], [2.5, 3.4, -yaw], [6.0, 1.0, yaw + 1.0]])
        assert_near_scan_agrees(caster, poses, 12.0, 1.1)
        # Fewer robots than the certificates were kept for, then more.
        assert_near_scan_agrees(caster, poses[:1], 12.0, 1.1)
    ranges, kind = caster.scan_near(np.zeros((0, 3)), 12.0, 1.1)
    assert ranges.shape == kind.shape == (0, 360)
    for cut in (0.0, 12.0, math.nan):
        with pytest.raises(WorldGeometryError, match='cut_m'):
            caster.scan_near(np.zeros((1, 3)), 12.0, cut)


@pytest.mark.parametrize(
    ('horizon', 'config'),
    [
        (1.001, LidarConfig()),
        (1.001, LidarConfig(dropout_probability=0.3)),
        (2.5, LidarConfig(dropout_probability=0.0, range_noise_fraction=0.05)),
        (0.5, LidarConfig(range_min_m=0.6)),
        # A horizon at or beyond the maximum range: the full scan.
        (4.0, LidarConfig(range_max_m=4.0)),
        (11.5, LidarConfig()),
    ],
)
def test_lidar_horizon_reads_the_full_scan_within_it_and_inf_beyond(horizon, config):
    rng = np.random.default_rng(12)
    walls = np.concatenate([_random_walls(rng, 30), BOX * 2.0])
    caster = RayCaster(walls, wall_thickness_m=0.025, robot_radius_m=0.1, num_bins=360)
    full = LidarModel(caster, config, np.random.default_rng(13))
    near = LidarModel(caster, config, np.random.default_rng(13))
    seen = 0
    for _ in range(40):
        poses = np.column_stack([rng.uniform(0.0, 8.0, (6, 2)), rng.uniform(-4.0, 4.0, 6)])
        expected = full.measure(poses)
        expected[expected > horizon] = np.inf
        got = near.measure(poses, horizon)
        np.testing.assert_array_equal(got, expected)
        seen += np.count_nonzero(got != np.inf)  # returns within the horizon, -inf too
    assert seen > 0
    # Both drew the same numbers: the streams are at the same place.
    assert full._rng.random() == near._rng.random()


class _ExtremeNormals:
    """A random stream whose normal draws include some far beyond any real draw."""

    def __init__(self, seed: int) -> None:
        self._rng = np.random.default_rng(seed)

    def standard_normal(self, size: int) -> np.ndarray:
        values = self._rng.standard_normal(size)
        values[::50] = -60.0
        return values

    def random(self, shape: tuple[int, ...]) -> np.ndarray:
        return self._rng.random(shape)


def test_lidar_horizon_casts_in_full_when_a_far_ray_could_come_within_it():
    # Draws of -60 standard deviations pull ranges to 40 %: rays from beyond the cut of a
    # 1.5 m horizon (1.65 m) come within it, so their robots are cast in full, and the
    # readings are still the full scan's.
    config = LidarConfig(dropout_probability=0.0)
    caster = RayCaster(BOX * 2.0, wall_thickness_m=0.025, robot_radius_m=0.1, num_bins=360)
    full = LidarModel(caster, config, _ExtremeNormals(4))  # type: ignore[arg-type]
    near = LidarModel(caster, config, _ExtremeNormals(4))  # type: ignore[arg-type]
    poses = np.array([[2.0, 2.0, 0.0], [6.0, 4.0, 1.0]])
    expected = full.measure(poses)
    expected[expected > 1.5] = np.inf
    np.testing.assert_array_equal(near.measure(poses, 1.5), expected)
    pulled_in = np.isfinite(expected) & (caster.scan(poses, 12.0) > 1.7)
    assert pulled_in.sum() > 5
