"""RobotLoop: sample and hold, staleness, timing and steering around the controller."""

from __future__ import annotations

import math

import numpy as np
import pytest
from msc_pf.loop import MAX_RSSI_STAMP_LEAD_S, ControlStatus, RobotLoop, Steering
from msc_pf.robot import RobotController
from msc_pf.settings import MscPfConfig


def make_loop(**steering: float) -> RobotLoop:
    return RobotLoop(RobotController(0, MscPfConfig(), seed=1), Steering(**steering))


class Recorder(RobotController):
    """A controller that records what each step received."""

    def __init__(self) -> None:
        super().__init__(0, MscPfConfig(), seed=1)
        self.calls: list[tuple[float, tuple[float, ...], dict[int, float], list[int]]] = []

    def step(self, now_s, position_m, readings, peers=(), captured_ids=(), **kwargs):
        self.calls.append((now_s, tuple(position_m), dict(readings), list(captured_ids)))
        return super().step(now_s, position_m, readings, peers, captured_ids, **kwargs)


def test_a_control_step_gets_the_newest_pose_and_the_periods_samples_once():
    recorder = Recorder()
    loop = RobotLoop(recorder)
    loop.receive_pose((10.0, 20.0, 0.0), 0.5)
    loop.receive_pose((11.0, 20.0, 0.0), 0.9)
    assert loop.receive_rssi(0.6, {3: -90.0, 4: -95.0})
    assert loop.receive_rssi(0.8, {3: -88.0})
    loop.receive_captured([7])
    assert loop.control(1.0).status is ControlStatus.STEPPED
    loop.receive_pose((11.5, 20.0, 0.0), 1.9)
    loop.control(2.0)
    (t1, xy1, rssi1, cap1), (t2, xy2, rssi2, cap2) = recorder.calls
    assert (t1, xy1, rssi1, cap1) == (1.0, (11.0, 20.0), {3: -88.0, 4: -95.0}, [7])
    assert (t2, xy2, rssi2, cap2) == (2.0, (11.5, 20.0), {}, [])


def test_out_of_order_rssi_and_non_finite_poses_are_refused():
    loop = make_loop()
    assert loop.receive_rssi(5.0, {1: -90.0})
    assert not loop.receive_rssi(4.0, {1: -80.0})
    assert not loop.receive_pose((math.nan, 0.0, 0.0), 1.0)
    assert loop.pose is None


def test_rssi_stamped_far_ahead_of_the_clock_is_refused_and_does_not_block_later_batches():
    loop = make_loop()
    assert loop.receive_rssi(5.0, {1: -90.0}, now_s=5.1)
    assert not loop.receive_rssi(2.0**31 - 1.0, {1: -50.0}, now_s=5.2)
    assert 'ahead of the clock' in loop.last_rssi_refusal
    assert loop.last_rssi_stamp_s == 5.0
    assert loop.receive_rssi(5.3, {1: -80.0}, now_s=5.3)
    assert loop.receive_rssi(5.4 + MAX_RSSI_STAMP_LEAD_S, {1: -80.0}, now_s=5.4)
    assert not loop.receive_rssi(math.nan, {1: -80.0}, now_s=5.5)
    assert not loop.receive_rssi(5.0, {1: -80.0}, now_s=5.5)
    assert 'arrived after' in loop.last_rssi_refusal


def test_a_stale_pose_skips_the_step_and_stops_the_robot():
    loop = make_loop(odom_timeout_s=1.0)
    assert loop.control(1.0).status is ControlStatus.NO_POSE
    loop.receive_pose((1000.0, 1000.0, 0.0), 1.0)
    assert loop.control(1.5).status is ControlStatus.STEPPED
    assert loop.waypoint_m is not None
    assert loop.command(2.6) == (0.0, 0.0)  # the pose is 1.6 s old
    assert loop.control(2.6).status is ControlStatus.NO_POSE
    assert loop.waypoint_m is None


def test_without_a_control_step_for_two_periods_the_robot_stops():
    loop = make_loop(odom_timeout_s=100.0)
    loop.receive_pose((1000.0, 1000.0, 0.0), 0.0)
    loop.control(1.0)
    for t in (2.0, 2.5, 3.0):
        loop.receive_pose((1000.0, 1000.0, 0.0), t)
    assert loop.command(3.1) == (0.0, 0.0)


def test_the_command_steers_toward_the_waypoint_within_the_limits():
    loop = make_loop(odom_timeout_s=10.0, max_yaw_rate_rad_s=0.5, heading_gain=2.0)
    loop.receive_pose((1000.0, 1000.0, 0.0), 0.0)
    for t in range(1, 40):  # the search starts moving once the swarm has formed
        loop.receive_pose((1000.0, 1000.0, 0.0), float(t))
        loop.control(float(t))
        if loop.waypoint_m != (1000.0, 1000.0):
            break
    x, y = loop.waypoint_m
    speed, yaw_rate = loop.command(float(t))
    heading = math.atan2(y - 1000.0, x - 1000.0)
    assert abs(yaw_rate) <= 0.5 + 1e-12
    assert yaw_rate == pytest.approx(float(np.clip(2.0 * heading, -0.5, 0.5)))
    assert 0.0 <= speed <= 1.0


def test_an_observation_the_controller_rejects_holds_the_robot():
    loop = make_loop(odom_timeout_s=10.0)
    loop.receive_pose((1000.0, 1000.0, 0.0), 1.0)
    assert loop.control(2.0).status is ControlStatus.STEPPED
    result = loop.control(2.0)  # time does not advance
    assert result.status is ControlStatus.REJECTED
    assert 'does not advance' in result.error
    assert loop.waypoint_m is None
    assert loop.command(2.1) == (0.0, 0.0)
