"""ROS messages <-> the SGBA loop's inputs and outputs (the node's only translations)."""

from __future__ import annotations

import math
from typing import Any

import numpy as np
from swarm_runtime.ros import message_module

from oabug_robot.sgba.controller import SgbaCommand

__all__ = ['command_to_twist', 'peers_from_ros', 'position_from_odometry', 'stop_twist']

geometry_msgs = message_module('geometry_msgs')


def peers_from_ros(msg: Any) -> tuple[list[str], np.ndarray, np.ndarray]:
    """swarm_interfaces/PeerBearingArray -> tag ids (upper case), azimuths [rad], distances [m]."""
    bearings = list(msg.bearings)
    return (
        [b.tag_id.strip().upper() for b in bearings],
        np.array([b.azimuth for b in bearings], dtype=float),
        np.array([b.distance for b in bearings], dtype=float),
    )


def position_from_odometry(msg: Any) -> tuple[float, float]:
    """nav_msgs/Odometry -> (x, y) [m] of its pose.

    Raises:
        ValueError: the position is not finite (the message is dropped; odometry goes stale).
    """
    position = msg.pose.pose.position
    x, y = float(position.x), float(position.y)
    if not (math.isfinite(x) and math.isfinite(y)):
        msg_text = f'odometry position ({x}, {y}) is not finite'
        raise ValueError(msg_text)
    return x, y


def command_to_twist(command: SgbaCommand) -> Any:
    """The command as geometry_msgs/Twist (forward speed and yaw rate)."""
    twist = geometry_msgs.Twist()
    twist.linear.x = float(command.linear_mps)
    twist.angular.z = float(command.angular_radps)
    return twist


def stop_twist() -> Any:
    """A zero geometry_msgs/Twist."""
    return geometry_msgs.Twist()
