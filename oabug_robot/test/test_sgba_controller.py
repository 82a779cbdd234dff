"""SGBA's controller and loop: headings, wall following, peers, determinism."""

from __future__ import annotations

import math

import numpy as np
import pytest
from oabug_robot.errors import ConfigError
from oabug_robot.scan_features import LaserScanData
from oabug_robot.settings import Departure
from oabug_robot.sgba.controller import (
    Peer,
    Ranges,
    SgbaController,
    SgbaInputs,
    SgbaState,
    WallState,
    initial_heading,
    ranges_from_scan,
    rssi_from_distance,
)
from oabug_robot.sgba.loop import SgbaLoop, has_right_of_way
from oabug_robot.sgba.settings import SGBA_PARAMETERS, HeadingScheme, SgbaConfig

FAR = 12.0


def ranges(front=FAR, left=FAR, right=FAR, back=FAR, front_left=None, front_right=None) -> Ranges:
    return Ranges(
        front_m=front,
        left_m=left,
        right_m=right,
        back_m=back,
        front_left_m=front_left if front_left is not None else min(FAR, left / math.sqrt(0.5)),
        front_right_m=front_right if front_right is not None else min(FAR, right / math.sqrt(0.5)),
    )


def step(c: SgbaController, r: Ranges, yaw=0.0, pos=(0.0, 0.0), peer=None, t=0.0):
    return c.step(SgbaInputs(time_s=t, yaw_rad=yaw, ranges=r, position_m=pos, peer=peer))


def test_headings_spread_over_the_swarm() -> None:
    centre = [initial_heading(SgbaConfig(robot_index=i, robot_count=4)) for i in range(4)]
    assert np.allclose(centre, [0.0, math.pi / 2, math.pi, -math.pi / 2])
    edge = [
        initial_heading(SgbaConfig(robot_index=i, robot_count=2, departure=Departure.EDGE))
        for i in range(2)
    ]
    assert np.allclose(edge, [math.pi / 4, 3 * math.pi / 4])
    authors = [
        initial_heading(
            SgbaConfig(robot_index=i, robot_count=5, heading_scheme=HeadingScheme.AUTHORS)
        )
        for i in range(5)
    ]
    assert np.allclose(authors, [0.8, 0.8, -2.4, -0.8, 2.4])


def test_it_turns_to_its_heading_then_goes_forward() -> None:
    c = SgbaController(SgbaConfig(robot_index=1, robot_count=4))  # heading +90 deg
    command = step(c, ranges())
    assert c.memory.state is SgbaState.ROTATE_TO_GOAL
    assert command.linear_mps == 0.0
    assert command.angular_radps == pytest.approx(0.5)
    command = step(c, ranges(), yaw=math.pi / 2 - 0.05)
    assert c.memory.state is SgbaState.FORWARD
    assert command.linear_mps == pytest.approx(0.3)
    assert command.angular_radps == 0.0


def test_a_wall_ahead_starts_wall_following_on_the_nearer_side() -> None:
    c = SgbaController(SgbaConfig())
    step(c, ranges())
    step(c, ranges())
    assert c.memory.state is SgbaState.FORWARD
    command = step(c, ranges(front=0.5, left=0.8, right=3.0), pos=(1.0, 2.0))
    assert c.memory.state is SgbaState.WALL_FOLLOWING
    assert c.memory.direction == -1, 'the nearer wall is on the left'
    assert c.memory.hit_position_m == (1.0, 2.0)
    # Turning to find the wall: rotate away from the left wall, on the spot.
    assert command.linear_mps == 0.0
    assert command.angular_radps < 0.0


def test_it_follows_a_wall_at_the_set_distance_and_leaves_it_at_an_outer_corner() -> None:
    c = SgbaController(SgbaConfig())  # preferred heading 0
    step(c, ranges())
    step(c, ranges())
    step(c, ranges(front=0.5, right=0.9))  # hit: wall ahead, right side nearer
    assert c.memory.direction == 1
    # Turned left by 90 deg: the wall is on the right at 0.5 m, the way ahead is clear.
    command = step(c, ranges(right=0.5), yaw=math.pi / 2)
    assert c.memory.wall_state is WallState.ALONG_WALL
    assert command.linear_mps > 0.0
    assert command.angular_radps < 0.0, 'too far: closes in'
    command = step(c, ranges(right=0.3), yaw=math.pi / 2)
    assert command.angular_radps > 0.0, 'too close: moves away'
    command = step(c, ranges(right=0.4), yaw=math.pi / 2)
    assert command.angular_radps == pytest.approx(0.0, abs=1e-9)
    # The wall ends on the right: round the corner; the preferred heading (0) lies 90 deg
    # to the right, on the wall's side, so the robot stays on the wall.
    step(c, ranges(right=2.0), yaw=math.pi / 2)
    assert c.memory.wall_state is WallState.AROUND_CORNER
    assert c.memory.state is SgbaState.WALL_FOLLOWING
    # Rounded on to a heading of -30 deg, the preferred heading (0) is 30 deg to the left,
    # on the free side (the wall is on the right): it leaves the wall.
    step(c, ranges(right=2.0), yaw=-math.radians(30))
    assert c.memory.state is SgbaState.ROTATE_TO_GOAL
    assert 'leave_wall' in c.memory.events


def test_a_looping_robot_follows_the_next_wall_the_other_way() -> None:
    c = SgbaController(SgbaConfig())  # preferred heading 0
    step(c, ranges())
    step(c, ranges())
    step(c, ranges(front=0.5, right=0.9), pos=(5.0, 0.0))
    assert c.memory.direction == 1
    # Seen from the hit point, the robot is now behind it (opposite the preferred heading).
    step(c, ranges(right=0.4), yaw=math.pi, pos=(4.0, 0.1))
    assert c.memory.reverse_next_hit
    c.memory.state = SgbaState.FORWARD
    step(c, ranges(front=0.5, right=0.9), pos=(4.0, 0.1))
    assert c.memory.direction == -1, 'reversed, although the right wall is nearer'
    assert not c.memory.reverse_next_hit


def _following(config: SgbaConfig) -> SgbaController:
    c = SgbaController(config)
    c.memory.state = SgbaState.WALL_FOLLOWING
    c.memory.wall_state = WallState.ALONG_WALL
    c._started = True
    return c


def test_a_close_peer_with_right_of_way_changes_the_preferred_heading_away_from_it() -> None:
    config = SgbaConfig(robot_index=1, robot_count=8)  # heading +45 deg
    c = _following(config)
    heading = c.preferred_heading_rad
    assert heading == pytest.approx(math.pi / 4)
    # Peer at -58 dBm + 3: within the heading threshold, not the collision one; it lies
    # ahead-left (+60 deg), so the mirrored heading (-45 deg) points farther away from it.
    peer = Peer(rssi_dbm=-55.0, bearing_rad=math.radians(60), has_way=True)
    step(c, ranges(right=0.4), peer=peer)
    assert c.preferred_heading_rad == pytest.approx(-math.pi / 4)
    assert c.memory.state is SgbaState.WALL_FOLLOWING
    assert 'heading_change' in c.memory.events
    # A peer without right of way, or a far one, changes nothing.
    for other in (
        Peer(rssi_dbm=-55.0, bearing_rad=math.radians(-60), has_way=False),
        Peer(rssi_dbm=-70.0, bearing_rad=math.radians(-60), has_way=True),
    ):
        step(c, ranges(right=0.4), peer=other)
        assert c.preferred_heading_rad == pytest.approx(-math.pi / 4)
    # A peer behind the mirror image: the heading stays.
    step(c, ranges(right=0.4), peer=Peer(-55.0, math.radians(120), True))
    assert c.preferred_heading_rad == pytest.approx(-math.pi / 4)


def test_a_very_close_peer_with_right_of_way_makes_the_robot_wait_until_it_has_passed() -> None:
    c = _following(SgbaConfig())
    command = step(c, ranges(right=0.4, front=0.5), peer=Peer(-45.0, 0.0, True))
    assert c.memory.state is SgbaState.MOVE_OUT_OF_WAY
    assert command.linear_mps < 0.0, 'backs off the obstacle ahead'
    command = step(c, ranges(right=0.4), peer=Peer(-45.0, 0.0, True))
    assert command.linear_mps == 0.0
    assert command.angular_radps == 0.0
    step(c, ranges(right=0.4), peer=Peer(-53.0, 0.0, True))
    assert c.memory.state is SgbaState.ROTATE_TO_GOAL


def test_rssi_model_and_right_of_way() -> None:
    config = SgbaConfig()
    assert rssi_from_distance(1.0, config) == pytest.approx(-48.0)
    assert rssi_from_distance(10.0, config) == pytest.approx(-68.0)
    assert has_right_of_way('R0', 'R1')
    assert not has_right_of_way('R2', 'R1')
    assert has_right_of_way('R5', '')
    with pytest.raises(ConfigError):
        SgbaConfig(rssi_heading_dbm=-40.0, rssi_collision_dbm=-50.0)
    with pytest.raises(ConfigError):
        SgbaConfig(robot_index=3, robot_count=3)


def test_ranges_from_a_scan_take_the_nearest_return_per_direction() -> None:
    bins = 360
    values = np.full(bins, np.inf)
    values[180] = 2.0  # ahead (angle 0 at bin 180 for angle_min -pi)
    values[270] = 0.5  # left
    values[91] = -np.inf  # right, too close
    r = ranges_from_scan(values, -math.pi, 2 * math.pi / bins, 0.15, 12.0, math.radians(2))
    assert (r.front_m, r.left_m, r.right_m, r.back_m) == (2.0, 0.5, 0.0, 12.0)


def _scan(front_m: float) -> LaserScanData:
    values = np.full(360, 5.0)
    values[175:186] = front_m
    return LaserScanData(values, -math.pi, 2 * math.pi / 360, 0.15, 12.0)


def _drive(seed: int) -> list[tuple[float, float]]:
    """A loop fed a seeded random sequence of readings."""
    rng = np.random.default_rng(seed)
    settings = SGBA_PARAMETERS.build({'robot_index': 2, 'robot_count': 5, 'own_tag_id': 'R2'})
    loop: SgbaLoop[LaserScanData] = SgbaLoop(settings)
    out = []
    yaw = 0.0
    for k in range(300):
        t = 0.1 * (k + 1)
        loop.hold_scan(_scan(float(rng.uniform(0.3, 3.0))), t)
        loop.hold_yaw(yaw, t)
        loop.hold_position(float(rng.normal()), float(rng.normal()), t)
        loop.hold_peers(['R0', 'R4'], rng.uniform(-3, 3, 2), rng.uniform(0.5, 4.0, 2), t)
        command = loop.control(t).command
        yaw += 0.1 * command.angular_radps
        out.append((command.linear_mps, command.angular_radps))
    return out


def test_the_loop_is_deterministic_from_its_readings() -> None:
    assert _drive(7) == _drive(7)
    assert _drive(7) != _drive(8)


def test_the_loop_stops_while_an_input_is_stale() -> None:
    loop: SgbaLoop[LaserScanData] = SgbaLoop(SGBA_PARAMETERS.build({}))
    loop.hold_scan(_scan(5.0), 0.0)
    loop.hold_yaw(0.0, 0.0)
    output = loop.control(0.1)
    assert output.stale == ('odom',)
    assert output.command.linear_mps == 0.0
    assert output.command.angular_radps == 0.0
    loop.hold_position(0.0, 0.0, 0.1)
    assert loop.control(0.2).stale == ()
    assert set(loop.control(1.5).stale) == {'scan', 'imu', 'odom'}


def test_the_geometry_scale_scales_every_distance_and_the_rssi_distance() -> None:
    half = SgbaConfig(geometry_scale=0.5)
    c = SgbaController(half)
    assert c.geometry.wall_m == pytest.approx(0.2)
    assert c.geometry.hit_m == pytest.approx(0.3)
    assert c.geometry.side_check_m == pytest.approx(1.0)
    step(c, ranges())
    step(c, ranges())
    step(c, ranges(front=0.5))
    assert c.memory.state is SgbaState.FORWARD, '0.5 m ahead is no wall at half scale'
    step(c, ranges(front=0.25))
    assert c.memory.state is SgbaState.WALL_FOLLOWING
    # A peer at 0.5 m reads as one at 1 m of the authors' scale.
    assert rssi_from_distance(0.5, half) == pytest.approx(rssi_from_distance(1.0, SgbaConfig()))
