"""Pure translations between ROS messages and the bayes_swarm core records.

Nothing here holds state or algorithm logic; every function is tested by round trip.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np
from swarm_common.angles import (
    ODOM_QUATERNION_NORM_TOLERANCE,
    UNIT_QUATERNION_NORM_SQ_TOLERANCE,
    yaw_from_odometry_quaternion,
)
from swarm_common.stamps import stamp_from_seconds, stamp_to_seconds
from swarm_runtime.ros import message_module

from bayes_swarm.errors import ObservationError
from bayes_swarm.messages import Decision, PeerUpdate

__all__ = [
    'ODOM_QUATERNION_NORM_TOLERANCE',
    'UNIT_QUATERNION_NORM_SQ_TOLERANCE',
    'decision_to_state',
    'glowworm_peer_from_ros',
    'glowworm_peer_to_ros',
    'odometry_to_pose',
    'peer_update_from_ros',
    'peer_update_to_ros',
    'seconds_to_stamp',
    'stamp_to_seconds',
    'twist',
]

_builtin = message_module('builtin_interfaces')
_geometry = message_module('geometry_msgs')
_swarm = message_module('swarm_interfaces')


def seconds_to_stamp(time_s: float) -> Any:
    """builtin_interfaces/Time for a non-negative time [s]."""
    return stamp_from_seconds(time_s, _builtin.Time)


def _floats(values: np.ndarray) -> list[float]:
    return [float(v) for v in np.asarray(values, dtype=float).reshape(-1)]


def peer_update_to_ros(update: PeerUpdate, time_s: float, frame_id: str = 'map') -> Any:
    """swarm_interfaces/BayesSwarmPeer carrying ``update``."""
    msg = _swarm.BayesSwarmPeer()
    msg.header.stamp = seconds_to_stamp(time_s)
    msg.header.frame_id = frame_id
    msg.robot = update.sender
    msg.decision_index = int(update.decision_index)
    msg.position_x, msg.position_y = (float(v) for v in update.position_m)
    msg.waypoint_x, msg.waypoint_y = (float(v) for v in update.waypoint_m)
    pts = np.asarray(update.sample_points_m, dtype=float).reshape(-1, 2)
    msg.sample_x = _floats(pts[:, 0])
    msg.sample_y = _floats(pts[:, 1])
    msg.sample_value = _floats(update.sample_values)
    weak = np.asarray(update.weaker_sources_m, dtype=float).reshape(-1, 2)
    msg.weaker_x = _floats(weak[:, 0])
    msg.weaker_y = _floats(weak[:, 1])
    return msg


def peer_update_from_ros(msg: Any) -> PeerUpdate:
    """PeerUpdate from a swarm_interfaces/BayesSwarmPeer.

    Raises:
        ObservationError: if the sample or weaker-source arrays differ in length.
    """
    n = len(msg.sample_x)
    if len(msg.sample_y) != n or len(msg.sample_value) != n:
        msg_text = (
            f'peer message from {msg.robot!r} has {n} sample_x, {len(msg.sample_y)} sample_y '
            f'and {len(msg.sample_value)} sample_value entries'
        )
        raise ObservationError(msg_text)
    if len(msg.weaker_x) != len(msg.weaker_y):
        msg_text = f'peer message from {msg.robot!r} has mismatched weaker_x/weaker_y'
        raise ObservationError(msg_text)
    points = np.column_stack([np.asarray(msg.sample_x, float), np.asarray(msg.sample_y, float)])
    weaker = np.column_stack([np.asarray(msg.weaker_x, float), np.asarray(msg.weaker_y, float)])
    return PeerUpdate(
        sender=msg.robot,
        decision_index=int(msg.decision_index),
        position_m=np.array([msg.position_x, msg.position_y], dtype=float),
        waypoint_m=np.array([msg.waypoint_x, msg.waypoint_y], dtype=float),
        sample_points_m=points.reshape(-1, 2),
        sample_values=np.asarray(msg.sample_value, dtype=float),
        weaker_sources_m=weaker.reshape(-1, 2),
    )


def decision_to_state(
    robot: str,
    algorithm: str,
    position_m: np.ndarray,
    decision: Decision,
    time_s: float,
    frame_id: str = 'map',
) -> Any:
    """swarm_interfaces/BayesSwarmState describing ``decision`` taken at ``position_m``."""
    msg = _swarm.BayesSwarmState()
    msg.header.stamp = seconds_to_stamp(time_s)
    msg.header.frame_id = frame_id
    msg.robot = robot
    msg.algorithm = algorithm
    msg.decision_index = int(decision.decision_index)
    msg.decision_kind = decision.kind.value
    msg.position_x, msg.position_y = (float(v) for v in position_m)
    msg.waypoint_x, msg.waypoint_y = (float(v) for v in decision.waypoint_m)
    expected = decision.expected_source_m
    if expected is None:
        msg.expected_source_x = msg.expected_source_y = math.nan
    else:
        msg.expected_source_x, msg.expected_source_y = (float(v) for v in expected)
    msg.alpha = float(decision.alpha)
    msg.n_samples = int(decision.n_samples)
    msg.decision_time_s = float(decision.compute_time_s)
    return msg


def glowworm_peer_to_ros(
    robot: str, decision_index: int, position_m: np.ndarray, luciferin: float, time_s: float
) -> Any:
    """swarm_interfaces/GlowwormPeer for one GSO broadcast."""
    msg = _swarm.GlowwormPeer()
    msg.header.stamp = seconds_to_stamp(time_s)
    msg.header.frame_id = 'map'
    msg.robot = robot
    msg.decision_index = int(decision_index)
    msg.position_x, msg.position_y = (float(v) for v in position_m)
    msg.luciferin = float(luciferin)
    return msg


def glowworm_peer_from_ros(msg: Any) -> tuple[str, int, np.ndarray, float]:
    """(sender, decision index, (2,) position [m], luciferin) of a GlowwormPeer."""
    position = np.array([msg.position_x, msg.position_y], dtype=float)
    return msg.robot, int(msg.decision_index), position, float(msg.luciferin)


def odometry_to_pose(msg: Any) -> tuple[float, float, float]:
    """(x [m], y [m], yaw [rad]) of a nav_msgs/Odometry (planar yaw from the quaternion).

    A quaternion whose squared norm is off 1 by more than
    :data:`UNIT_QUATERNION_NORM_SQ_TOLERANCE` is read as if normalised, as long as its norm
    is within :data:`ODOM_QUATERNION_NORM_TOLERANCE` of 1 (the MSC node reads odometry the
    same way).

    Raises:
        ObservationError: the quaternion is zero (including one whose squared norm underflows)
            or not finite, so it has no orientation, or its norm is further than
            :data:`ODOM_QUATERNION_NORM_TOLERANCE` from 1 (a broken publisher).
    """
    p = msg.pose.pose.position
    q = msg.pose.pose.orientation
    try:
        yaw = yaw_from_odometry_quaternion(q.x, q.y, q.z, q.w)
    except ValueError as err:
        raise ObservationError(f'odometry {err}') from err
    return float(p.x), float(p.y), yaw


def twist(linear_mps: float, angular_radps: float) -> Any:
    """geometry_msgs/Twist with forward speed [m/s] and yaw rate [rad/s]."""
    msg = _geometry.Twist()
    msg.linear.x = float(linear_mps)
    msg.angular.z = float(angular_radps)
    return msg
