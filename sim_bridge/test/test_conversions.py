"""Message translations: typed fields, REP 103 conventions and round trips."""

import math

import numpy as np
import pytest
from swarm_runtime.messages import cdr_roundtrip
from swarm_sim.ground_truth import RoomEntry
from swarm_sim.sensors.bearings import PeerBearings
from swarm_sim.sensors.lidar import LidarConfig

from sim_bridge import conversions


def test_stamps_round_trip_to_the_nanosecond():
    stamp = conversions.seconds_to_stamp(12.3456789012)
    assert (stamp.sec, stamp.nanosec) == (12, 345678901)
    assert conversions.stamp_to_seconds(stamp) == pytest.approx(12.345678901)


@pytest.mark.parametrize('yaw', [0.0, 1.0, -2.5, math.pi])
def test_yaw_quaternion_round_trip(yaw):
    msg = conversions.imu_to_ros(yaw, 0.0, 1.0, 'imu', 0.0)
    assert math.cos(conversions.quaternion_to_yaw(msg.orientation) - yaw) == pytest.approx(1.0)


def test_scan_message_follows_rep_103_and_survives_serialization():
    config = LidarConfig()
    ranges = np.full(config.num_bins, np.inf)
    ranges[180] = 1.5  # straight ahead
    msg = cdr_roundtrip(conversions.scan_to_ros(ranges, 2.0, 'r0/laser', config))
    assert msg.angle_min == pytest.approx(-math.pi)
    assert msg.angle_min + 180 * msg.angle_increment == pytest.approx(0.0, abs=1e-6)
    assert msg.range_min == pytest.approx(0.15)
    assert msg.range_max == pytest.approx(12.0)
    assert msg.scan_time == pytest.approx(1 / 5.5, rel=1e-6)
    assert msg.ranges[180] == pytest.approx(1.5)
    assert math.isinf(msg.ranges[0])


def test_bearings_carry_upper_case_tags_and_typed_fields():
    report = PeerBearings(
        receiver=0,
        tags=np.array([2]),
        azimuth_rad=np.array([0.5]),
        elevation_rad=np.array([0.01]),
        distance_m=np.array([3.0]),
        sequence=np.array([7]),
    )
    msg = cdr_roundtrip(conversions.bearings_to_ros(report, ['r0', 'r1', 'r2'], 1.0, 'r0/base'))
    (bearing,) = msg.bearings
    assert bearing.tag_id == 'R2'
    assert bearing.azimuth == pytest.approx(0.5)
    assert bearing.sequence == 7


def test_coverage_round_trips_with_robot_names():
    entries = [RoomEntry(3, 1, 4.5), RoomEntry(0, 0, 9.0)]
    msg = cdr_roundtrip(conversions.coverage_to_ros(5, entries, ['r0', 'r1'], 10.0))
    stamp_s, total, visits = conversions.coverage_from_ros(msg)
    assert (stamp_s, total) == (10.0, 5)
    assert [(v.room_index, v.robot, v.time_s) for v in visits] == [(3, 'r1', 4.5), (0, 'r0', 9.0)]


def test_true_poses_round_trip():
    poses = np.array([[1.0, 2.0, 0.5], [3.0, -1.0, -2.0]])
    msg = cdr_roundtrip(conversions.true_poses_to_ros(['r0', 'r1'], poses, 3.5))
    t, names, back = conversions.true_poses_from_ros(msg)
    assert t == 3.5
    assert names == ['r0', 'r1']
    assert np.allclose(back, poses)


def test_odometry_and_twist_conversions():
    odom = conversions.odometry_to_ros(
        np.array([1.0, 2.0, 0.3]), np.array([0.2, -0.1]), 1.0, 'r0/odom', 'r0/base_link'
    )
    odom = cdr_roundtrip(odom)
    assert odom.child_frame_id == 'r0/base_link'
    assert conversions.quaternion_to_yaw(odom.pose.pose.orientation) == pytest.approx(0.3)
    assert conversions.twist_from_ros(odom.twist.twist) == pytest.approx((0.2, -0.1))
