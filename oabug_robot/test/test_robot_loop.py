"""The ROS-free control loop that the node and the batch runner share."""

from __future__ import annotations

import math

import numpy as np
import pytest
from oabug_robot.errors import ScanError
from oabug_robot.node_settings import OABUG_PARAMETERS
from oabug_robot.robot_loop import STOP, ControlTimer, RobotLoop, extract_features
from oabug_robot.scan_features import LaserScanData

RAYS = 360


def scan(fill: float = math.inf) -> LaserScanData:
    return LaserScanData(np.full(RAYS, fill), -math.pi, 2 * math.pi / RAYS, 0.15, 12.0)


def loop_of(**parameters: object) -> RobotLoop:
    return RobotLoop(OABUG_PARAMETERS.build(parameters))


def test_the_timer_fires_on_the_period_grid_and_skips_missed_deadlines():
    timer = ControlTimer(0.1)
    assert timer.period_ns == 100_000_000
    assert not timer.due(99_999_999)
    assert timer.due(100_000_000)
    assert not timer.due(150_000_000)
    # Three deadlines missed: one step, then the grid goes on after now.
    assert timer.due(520_000_000)
    assert timer.next_ns == 600_000_000


def test_the_loop_stops_until_every_input_is_fresh_and_names_the_stale_ones():
    loop = loop_of(variant='gas')
    out = loop.control(0.1)
    assert out.command == STOP
    assert set(out.stale) == {'scan', 'imu', 'gas'}
    loop.hold_yaw(0.0, 0.1)
    loop.hold_scan(scan(), 0.1)
    out = loop.control(0.1)
    assert out.stale == ('gas',)
    loop.hold_gas(100, 0.2)
    moving = loop.control(0.2)
    assert moving.stale == ()
    assert moving.command.linear_mps > 0.0
    # The scan's features are as old as the scan: stale after the timeout.
    out = loop.control(0.1 + loop.stale_timeout_s + 0.05)
    assert out.command == STOP
    assert 'scan' in out.stale


def test_a_scan_waits_for_the_first_yaw_and_a_bad_scan_is_dropped():
    loop = loop_of(variant='minimum')
    loop.hold_scan(scan(), 0.1)
    assert loop.pending_scan() is None  # no yaw yet: the scan stays held
    loop.hold_yaw(0.0, 0.1)
    assert loop.pending_scan() is not None
    loop.update_features(0.1)
    assert loop.pending_scan() is None
    assert 'scan' in loop.heard
    bad = LaserScanData(np.zeros(0), -math.pi, 0.01, 0.15, 12.0)
    loop.hold_scan(bad, 0.2)
    with pytest.raises(ScanError):
        loop.update_features(0.2)
    assert loop.pending_scan() is None
    # The features of the earlier scan still drive the robot.
    assert loop.step(0.2).stale == ()


def test_features_of_many_loops_equal_each_loops_own():
    rng = np.random.default_rng(3)
    batch = [loop_of(variant='gas_sound', robot_index=i, robot_count=4) for i in range(4)]
    single = [loop_of(variant='gas_sound', robot_index=i, robot_count=4) for i in range(4)]
    for a, b in zip(batch, single, strict=True):
        ranges = rng.uniform(0.2, 3.0, RAYS)
        for loop in (a, b):
            loop.hold_yaw(0.3, 0.1)
            loop.hold_bearings(np.array([0.5, -2.0]), np.array([0.4, math.nan]), 0.1)
            loop.hold_scan(
                LaserScanData(ranges.copy(), -math.pi, 2 * math.pi / RAYS, 0.15, 12.0), 0.1
            )
    extract_features(batch, 0.1)
    for a, b in zip(batch, single, strict=True):
        b.update_features(0.1)
        assert a.step(0.2).command == b.step(0.2).command
        assert a.fsm.memory == b.fsm.memory


def test_the_batch_command_is_the_control_steps_command():
    """command() (the batch runner's call) gives control()'s command, STOP while an input
    is stale, and steps the controller the same way."""
    rng = np.random.default_rng(4)
    a, b = loop_of(variant='gas'), loop_of(variant='gas')
    commands = []
    for step in range(1, 120):
        now = 0.1 * step
        ranges = rng.uniform(0.2, 3.0, RAYS)
        gas = int(rng.integers(50, 300))
        for loop in (a, b):
            if step % 7:  # now and then no IMU reading: the yaw goes stale
                loop.hold_yaw(0.01 * step, now)
            if step > 3:
                loop.hold_gas(gas, now)
            if step % 2:
                loop.hold_scan(
                    LaserScanData(ranges.copy(), -math.pi, 2 * math.pi / RAYS, 0.15, 12.0), now
                )
        commands.append(a.command(now))
        assert commands[-1] == b.control(now).command
        assert a.fsm.memory == b.fsm.memory
    # Stopped while the gas was missing, driving later.
    assert commands[0] == STOP
    assert any(command.linear_mps > 0.0 for command in commands)
