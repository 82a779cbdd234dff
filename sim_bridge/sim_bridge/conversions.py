"""Pure translations between the engine's numbers and ROS messages (REP 103 / 105 units).

Every function here is stateless: ``*_to_ros`` builds a message from numbers, ``*_from_ros``
reads numbers back. Float fields get Python floats and integer fields Python ints, because
generated message classes with field checks on (ROS_PYTHON_CHECK_FIELDS=1) reject anything
else; numeric sequences are handed over as ``array.array`` of the field's type.
"""

from __future__ import annotations

import array
import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from swarm_common.angles import yaw_from_unit_quaternion, yaw_to_quaternion
from swarm_common.stamps import stamp_from_seconds, stamp_to_seconds
from swarm_runtime.ros import message_module
from swarm_sim.ground_truth import RoomEntry
from swarm_sim.sensors.bearings import PeerBearings
from swarm_sim.sensors.lidar import LidarConfig

__all__ = [
    'RoomVisitRecord',
    'bearings_to_ros',
    'clock_to_ros',
    'coverage_from_ros',
    'coverage_to_ros',
    'gas_to_ros',
    'imu_to_ros',
    'odometry_to_ros',
    'quaternion_to_yaw',
    'scan_to_ros',
    'seconds_to_stamp',
    'stamp_to_seconds',
    'tag_id_for',
    'true_poses_from_ros',
    'true_poses_to_ros',
    'twist_from_ros',
    'yaw_to_quaternion',
]

_builtin = message_module('builtin_interfaces')
_std = message_module('std_msgs')
_sensor = message_module('sensor_msgs')
_nav = message_module('nav_msgs')
_rosgraph = message_module('rosgraph_msgs')
_swarm = message_module('swarm_interfaces')


def seconds_to_stamp(time_s: float) -> object:
    """builtin_interfaces/Time for a time in seconds (rounded to the nanosecond)."""
    return stamp_from_seconds(time_s, _builtin.Time)


def _header(time_s: float, frame_id: str) -> object:
    return _std.Header(stamp=seconds_to_stamp(time_s), frame_id=frame_id)


def quaternion_to_yaw(q: object) -> float:
    """Yaw [rad] of a geometry_msgs/Quaternion (rotation about z only, or its z part)."""
    return yaw_from_unit_quaternion(q.x, q.y, q.z, q.w)


def tag_id_for(robot_name: str) -> str:
    """The AoA tag id a robot carries: its name upper-cased (r3 -> R3)."""
    return robot_name.upper()


def clock_to_ros(time_s: float) -> object:
    """rosgraph_msgs/Clock at ``time_s``."""
    return _rosgraph.Clock(clock=seconds_to_stamp(time_s))


def scan_to_ros(ranges_m: np.ndarray, time_s: float, frame_id: str, config: LidarConfig) -> object:
    """sensor_msgs/LaserScan of one revolution: angle_min -pi, counter-clockwise bins.

    Args:
        ranges_m: (num_bins,) ranges [m]; ``inf`` where there is no valid return.
        time_s: stamp [s] (start of the revolution).
        frame_id: the lidar's frame.
        config: lidar parameters (limits, bins, rate).
    """
    scan_time = 1.0 / config.rate_hz
    return _sensor.LaserScan(
        header=_header(time_s, frame_id),
        angle_min=-math.pi,
        angle_max=math.pi - config.angle_increment_rad,
        angle_increment=config.angle_increment_rad,
        time_increment=scan_time / config.num_bins,
        scan_time=scan_time,
        range_min=float(config.range_min_m),
        range_max=float(config.range_max_m),
        ranges=array.array('f', np.asarray(ranges_m, dtype=np.float32).tobytes()),
    )


def gas_to_ros(raw: int, time_s: float, frame_id: str) -> object:
    """swarm_interfaces/GasReading; ``volts`` is NaN because the model has no voltage."""
    return _swarm.GasReading(
        header=_header(time_s, frame_id), raw=int(raw), volts=math.nan, warming_up=False
    )


def bearings_to_ros(
    report: PeerBearings, robot_names: Sequence[str], time_s: float, frame_id: str
) -> object:
    """swarm_interfaces/PeerBearingArray of one locator cycle."""
    bearings = [
        _swarm.PeerBearing(
            tag_id=tag_id_for(robot_names[int(tag)]),
            azimuth=float(az),
            elevation=float(el),
            distance=float(d),
            quality=_swarm.PeerBearing.QUALITY_OK,
            sequence=int(seq),
        )
        for tag, az, el, d, seq in zip(
            report.tags,
            report.azimuth_rad,
            report.elevation_rad,
            report.distance_m,
            report.sequence,
            strict=True,
        )
    ]
    return _swarm.PeerBearingArray(header=_header(time_s, frame_id), bearings=bearings)


def imu_to_ros(
    yaw_rad: float, yaw_rate_radps: float, time_s: float, frame_id: str, yaw_variance: float
) -> object:
    """sensor_msgs/Imu whose orientation carries the integrated yaw.

    Gravity is along +z of a level robot (linear_acceleration z = 9.80665 m/s^2).
    """
    x, y, z, w = yaw_to_quaternion(yaw_rad)
    msg = _sensor.Imu(header=_header(time_s, frame_id))
    msg.orientation.x, msg.orientation.y, msg.orientation.z, msg.orientation.w = x, y, z, w
    msg.orientation_covariance = [1e-6, 0.0, 0.0, 0.0, 1e-6, 0.0, 0.0, 0.0, float(yaw_variance)]
    msg.angular_velocity.z = float(yaw_rate_radps)
    msg.linear_acceleration.z = 9.80665
    return msg


def odometry_to_ros(
    pose: np.ndarray, twist: np.ndarray, time_s: float, frame_id: str, child_frame_id: str
) -> object:
    """nav_msgs/Odometry from a (3,) pose x, y, yaw and a (2,) body twist v, yaw rate."""
    msg = _nav.Odometry(header=_header(time_s, frame_id), child_frame_id=child_frame_id)
    position = msg.pose.pose.position
    position.x, position.y = float(pose[0]), float(pose[1])
    q = msg.pose.pose.orientation
    q.x, q.y, q.z, q.w = yaw_to_quaternion(float(pose[2]))
    msg.twist.twist.linear.x = float(twist[0])
    msg.twist.twist.angular.z = float(twist[1])
    return msg


def twist_from_ros(msg: object) -> tuple[float, float]:
    """(forward speed [m/s], yaw rate [rad/s]) of a geometry_msgs/Twist; other axes ignored."""
    return float(msg.linear.x), float(msg.angular.z)


def true_poses_to_ros(robot_names: Sequence[str], poses: np.ndarray, time_s: float) -> object:
    """swarm_interfaces/TruePoseArray of every robot's (N, 3) true pose, frame 'world'."""
    return _swarm.TruePoseArray(
        header=_header(time_s, 'world'),
        poses=[
            _swarm.TruePose(robot=name, x=float(p[0]), y=float(p[1]), yaw=float(p[2]))
            for name, p in zip(robot_names, poses, strict=True)
        ],
    )


def true_poses_from_ros(msg: object) -> tuple[float, list[str], np.ndarray]:
    """(stamp [s], robot names, (N, 3) poses) of a TruePoseArray."""
    names = [p.robot for p in msg.poses]
    poses = np.array([[p.x, p.y, p.yaw] for p in msg.poses], dtype=float).reshape(-1, 3)
    return stamp_to_seconds(msg.header.stamp), names, poses


@dataclass(frozen=True)
class RoomVisitRecord:
    """A first room entry as read back from a Coverage message.

    Attributes:
        room_index: index of the room in the site's room list.
        robot: name of the first visitor.
        time_s: sim time of the entry [s].
    """

    room_index: int
    robot: str
    time_s: float


def coverage_to_ros(
    rooms_total: int, entries: Sequence[RoomEntry], robot_names: Sequence[str], time_s: float
) -> object:
    """swarm_interfaces/Coverage listing every first entry so far."""
    return _swarm.Coverage(
        header=_header(time_s, 'world'),
        rooms_total=int(rooms_total),
        visits=[
            _swarm.RoomVisit(
                room_index=int(e.room_index),
                robot=robot_names[e.robot_index],
                stamp=seconds_to_stamp(e.time_s),
            )
            for e in entries
        ],
    )


def coverage_from_ros(msg: object) -> tuple[float, int, list[RoomVisitRecord]]:
    """(stamp [s], rooms total, first entries) of a Coverage message."""
    visits = [
        RoomVisitRecord(int(v.room_index), str(v.robot), stamp_to_seconds(v.stamp))
        for v in msg.visits
    ]
    return stamp_to_seconds(msg.header.stamp), int(msg.rooms_total), visits
