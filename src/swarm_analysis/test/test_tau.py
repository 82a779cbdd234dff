"""Relative completion time (Eq. 12), live and from a recorded bag."""

import math

import numpy as np
import pytest
from swarm_analysis.tau import (
    TauError,
    first_detection,
    relative_completion_time,
    tau_from_bag,
    tau_from_tracks,
)
from swarm_runtime.bag import BagWriter
from swarm_runtime.messages import get_message_module

SOURCE = np.array([1.0, 2.0])


def test_tau_is_zero_for_a_straight_run_at_nominal_speed():
    ideal = math.sqrt(5.0) / 0.1
    assert relative_completion_time(ideal, [0, 0], SOURCE, 0.1) == pytest.approx(0.0)
    assert relative_completion_time(1.5 * ideal, [0, 0], SOURCE, 0.1) == pytest.approx(0.5)


def test_tau_rejects_a_start_at_the_source():
    with pytest.raises(TauError):
        relative_completion_time(3.0, SOURCE, SOURCE, 0.1)


def test_detection_is_interpolated_between_pose_samples():
    times = np.array([0.0, 10.0])
    positions = np.array([[[0.0, 2.0], [5.0, 5.0]], [[2.0, 2.0], [5.0, 5.0]]])
    hit = first_detection(times, positions, SOURCE, 0.5)
    assert hit == (pytest.approx(2.5), 0)  # x reaches 0.5 at a quarter of the way


def test_no_detection_gives_a_failed_result():
    result = tau_from_tracks(np.array([0.0, 1.0]), np.zeros((2, 1, 2)), ['r0'], SOURCE, 0.05, 0.1)
    assert not result.found
    assert math.isnan(result.tau)


def write_mission_bag(path, found_time_s):
    swarm = get_message_module('swarm_interfaces')
    builtin = get_message_module('builtin_interfaces')
    with BagWriter(path) as bag:
        bag.add_topic('/sim/source_search', 'swarm_interfaces/msg/SourceSearchStatus')
        bag.add_topic('/sim/poses', 'swarm_interfaces/msg/TruePoseArray')
        status = swarm.SourceSearchStatus(
            case_name='case1',
            source_x=1.0,
            source_y=2.0,
            detection_radius_m=0.05,
            velocity_mps=0.1,
            max_mission_time_s=100.0,
            robots=['r0', 'r1'],
            start_x=[0.0, 0.0],
            start_y=[0.0, 0.0],
        )
        bag.write_message('/sim/source_search', 0, status)
        # r1 flies straight at the source at V; r0 stays at the depot.
        direction = SOURCE / np.hypot(*SOURCE)
        for k in range(0, 61):
            t = 0.5 * k
            travelled = min(t * 0.1, np.hypot(*SOURCE))
            poses = [
                swarm.TruePose(robot='r0', x=0.0, y=0.0, yaw=0.0),
                swarm.TruePose(
                    robot='r1',
                    x=float(direction[0] * travelled),
                    y=float(direction[1] * travelled),
                    yaw=0.0,
                ),
            ]
            msg = swarm.TruePoseArray(poses=poses)
            msg.header.stamp = builtin.Time(sec=int(t), nanosec=round((t % 1) * 1e9))
            bag.write_message('/sim/poses', int(t * 1e9), msg)
        status.found, status.finder = True, 'r1'
        status.found_time_s, status.tau = found_time_s, -0.0224
        bag.write_message('/sim/source_search', int(30e9), status)


def test_tau_from_a_bag_recomputes_the_detection_from_true_poses(tmp_path):
    write_mission_bag(tmp_path / 'mission', found_time_s=21.86)
    result = tau_from_bag(tmp_path / 'mission')
    ideal = math.sqrt(5.0) / 0.1
    expected_time = (math.sqrt(5.0) - 0.05) / 0.1
    assert result.found
    assert result.finder == 'r1'
    assert result.found_time_s == pytest.approx(expected_time, abs=1e-6)
    assert result.tau == pytest.approx((expected_time - ideal) / ideal, abs=1e-6)
    assert result.reported_tau == pytest.approx(-0.0224)


def test_a_bag_without_the_mission_status_is_rejected(tmp_path):
    with BagWriter(tmp_path / 'empty') as bag:
        bag.add_topic('/sim/poses', 'swarm_interfaces/msg/TruePoseArray')
    with pytest.raises(TauError, match='source_search'):
        tau_from_bag(tmp_path / 'empty')
