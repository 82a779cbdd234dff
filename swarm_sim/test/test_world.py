"""Robot motion: unicycle integration, drive limits and collisions with walls and robots."""

import math

import numpy as np
import pytest
from swarm_sim.errors import ConfigurationError, WorldGeometryError
from swarm_sim.ground_truth import CoverageTracker
from swarm_sim.world import BodyConfig, World

WALL_AT_X2 = np.array([[[2.0, -5.0], [2.0, 5.0]]])


def test_a_straight_command_moves_the_robot_along_its_heading():
    world = World(np.zeros((0, 2, 2)), np.array([[0.0, 0.0, math.pi / 2]]))
    for _ in range(10):
        world.step(np.array([[0.2, 0.0]]), 0.1)
    assert world.poses[0] == pytest.approx([0.0, 0.2, math.pi / 2], abs=1e-12)


def test_a_constant_turn_follows_the_exact_arc():
    # A quarter circle of radius 0.5 m in 20 steps of 0.1 s.
    world = World(np.zeros((0, 2, 2)), np.array([[0.0, 0.0, 0.0]]))
    for _ in range(20):
        world.step(np.array([[math.pi / 8, math.pi / 4]]), 0.1)
    assert world.poses[0] == pytest.approx([0.5, 0.5, math.pi / 2], abs=1e-9)


def test_commands_are_clipped_to_the_drive_limits():
    body = BodyConfig(max_linear_speed_mps=0.3, max_angular_speed_radps=1.0)
    world = World(np.zeros((0, 2, 2)), np.array([[0.0, 0.0, 0.0]]), body)
    world.step(np.array([[5.0, -9.0]]), 1.0)
    assert world.poses[0, 0] == pytest.approx(0.3 * math.sin(1.0) / 1.0, rel=1e-9)
    assert world.poses[0, 2] == pytest.approx(-1.0)


def test_non_finite_commands_stop_the_robot():
    world = World(np.zeros((0, 2, 2)), np.array([[0.0, 0.0, 0.0]]))
    world.step(np.array([[math.nan, math.inf]]), 1.0)
    assert world.poses[0] == pytest.approx([0.0, 0.0, 0.0])


def test_a_robot_driving_into_a_wall_stops_at_contact_distance():
    body = BodyConfig(robot_radius_m=0.1, wall_thickness_m=0.02)
    world = World(WALL_AT_X2, np.array([[0.0, 0.0, 0.0]]), body)
    for _ in range(100):
        world.step(np.array([[0.5, 0.0]]), 0.05)
    x = world.poses[0, 0]
    assert 2.0 - 0.11 - 0.5 * 0.05 <= x < 2.0 - 0.11
    assert world.collision_count[0] > 0


def test_a_robot_blocked_by_a_wall_can_still_turn_and_back_away():
    world = World(WALL_AT_X2, np.array([[1.885, 0.0, 0.0]]))
    world.step(np.array([[0.5, 1.0]]), 0.1)
    assert world.poses[0, 0] == pytest.approx(1.885)
    assert world.poses[0, 2] == pytest.approx(0.1)
    world.step(np.array([[-0.5, 0.0]]), 0.1)
    assert world.poses[0, 0] < 1.885


def test_robots_do_not_drive_through_each_other():
    poses = np.array([[0.0, 0.0, 0.0], [1.0, 0.0, math.pi]])
    world = World(np.zeros((0, 2, 2)), poses)
    for _ in range(50):
        world.step(np.array([[0.3, 0.0], [0.3, 0.0]]), 0.1)
    gap = np.hypot(*(world.poses[1, :2] - world.poses[0, :2]))
    assert gap >= 2 * world.body.robot_radius_m - 1e-9
    assert gap < 0.25


def test_overlapping_start_poses_may_separate():
    world = World(np.zeros((0, 2, 2)), np.array([[0.0, 0.0, math.pi], [0.1, 0.0, 0.0]]))
    world.step(np.array([[0.2, 0.0], [0.2, 0.0]]), 0.5)
    assert world.poses[1, 0] - world.poses[0, 0] == pytest.approx(0.3)


def test_invalid_poses_and_limits_are_rejected():
    with pytest.raises(WorldGeometryError, match=r'\(N, 3\)'):
        World(np.zeros((0, 2, 2)), np.zeros((2, 2)))
    with pytest.raises(WorldGeometryError, match='NaN'):
        World(np.zeros((0, 2, 2)), np.array([[0.0, math.nan, 0.0]]))
    with pytest.raises(ConfigurationError, match='robot_radius_m'):
        BodyConfig(robot_radius_m=0.0)


def _random_walls(rng: np.random.Generator, count: int) -> np.ndarray:
    starts = rng.uniform(-2.0, 2.0, (count, 2))
    ends = starts + rng.uniform(-1.5, 1.5, (count, 2))
    box = np.array(
        [
            [[-2.5, -2.5], [2.5, -2.5]],
            [[2.5, -2.5], [2.5, 2.5]],
            [[2.5, 2.5], [-2.5, 2.5]],
            [[-2.5, 2.5], [-2.5, -2.5]],
        ]
    )
    return np.concatenate([np.stack([starts, ends], axis=1), box])


@pytest.mark.parametrize(('walls', 'robots'), [(0, 1), (0, 12), (6, 3), (15, 20)])
def test_the_compiled_step_equals_the_numpy_step_bit_for_bit(walls, robots):
    rng = np.random.default_rng(walls * 100 + robots)
    segments = _random_walls(rng, walls) if walls else np.zeros((0, 2, 2))
    # Crowded start poses: robots touch each other and the walls.
    poses = np.column_stack(
        [rng.uniform(-1.0, 1.0, (robots, 2)), rng.uniform(-math.pi, math.pi, robots)]
    )
    compiled = World(segments, poses)
    reference = World(segments, poses)
    collisions = 0
    for step in range(300):
        commands = np.column_stack([rng.uniform(-0.8, 0.8, robots), rng.uniform(-3.0, 3.0, robots)])
        commands[rng.random((robots, 2)) < 0.05] = math.nan
        commands[rng.random((robots, 2)) < 0.03] = math.inf
        commands[rng.random((robots, 2)) < 0.1] = 0.0
        commands[rng.random(robots) < 0.05, 1] = 1e-10  # straight-line branch
        dt = 0.1 if step % 7 else 0.37
        compiled.step(commands, dt)
        reference.step_reference(commands, dt)
        assert np.array_equal(compiled.poses, reference.poses)
        assert np.array_equal(compiled.velocities, reference.velocities)
        assert np.array_equal(compiled.collision_count, reference.collision_count)
        collisions = int(compiled.collision_count.sum())
    if walls or robots > 1:
        assert collisions > 0  # the comparison covered blocked moves
    if walls:
        assert np.array_equal(compiled._wall_clearance(), reference._wall_clearance())


def test_the_compiled_room_test_equals_the_numpy_one():
    rng = np.random.default_rng(5)
    lows = rng.uniform(-3.0, 3.0, (12, 2))
    rects = np.column_stack([lows, lows + rng.uniform(0.1, 2.0, (12, 2))])
    rooms = [rects[:3], rects[3:4], rects[4:8], np.zeros((0, 4)), rects[8:]]
    tracker = CoverageTracker(rooms, 0.1)
    positions = rng.uniform(-4.0, 5.0, (500, 3))
    # Discs exactly touching an edge, and inside corners.
    positions[:12, :2] = rects[:, :2] - [0.1, 0.0]
    positions[12:24, :2] = rects[:, 2:] + [0.0, 0.1]
    compiled = tracker.inside(positions)
    assert np.array_equal(compiled, tracker.inside_reference(positions))
    assert 20 < np.count_nonzero(compiled) < compiled.size
    assert not compiled[:, 3].any()


def test_first_entries_are_those_of_the_numpy_room_test():
    """CoverageTracker.update (the compiled test of the rooms not entered yet) records, step
    by step, the rooms first overlapped by the numpy test and the lowest robot in each."""
    rng = np.random.default_rng(8)
    lows = rng.uniform(-3.0, 3.0, (12, 2))
    rects = np.column_stack([lows, lows + rng.uniform(0.1, 1.0, (12, 2))])
    rooms = [rects[:3], rects[3:4], rects[4:8], np.zeros((0, 4)), rects[8:]]
    tracker = CoverageTracker(rooms, 0.1)
    first = np.full(len(rooms), -1)
    entries = 0
    for step in range(300):
        positions = rng.uniform(-4.0, 5.0, (6, 3))
        new = tracker.update(positions, 0.1 * step)
        hits = tracker.inside_reference(positions)
        expected = [
            (k, int(np.flatnonzero(hits[:, k])[0]))
            for k in range(len(rooms))
            if first[k] < 0 and hits[:, k].any()
        ]
        assert [(e.room_index, e.robot_index) for e in new] == expected
        assert all(e.time_s == 0.1 * step for e in new)
        for k, robot in expected:
            first[k] = robot
        entries += len(expected)
    assert entries == tracker.rooms_covered == len(rooms) - 1  # the empty room never
    assert tracker.update(np.zeros((6, 3)), 99.0) == []
