"""Pure translations between ROS messages and the OA-Bug core's types.

Every message field is filled with the exact Python type rosidl expects (float, int, bool,
str), so the node publishes correctly under ROS_PYTHON_CHECK_FIELDS=1.
"""

from __future__ import annotations

import array
import math
from typing import Any

import numpy as np
from swarm_runtime.ros import message_module

from oabug_robot.fsm import Command, Event, FsmMemory
from oabug_robot.heading import yaw_from_quaternion
from oabug_robot.scan_features import LaserScanData, check_scan_frame
from oabug_robot.settings import OABugConfig

__all__ = [
    'EVENT_NAMES',
    'STALE_EVENT',
    'command_to_pump',
    'command_to_twist',
    'gas_from_ros',
    'peer_arrays_from_ros',
    'scan_from_ros',
    'state_to_ros',
    'stop_twist',
    'yaw_from_imu',
]

geometry_msgs = message_module('geometry_msgs')
std_msgs = message_module('std_msgs')
swarm_interfaces = message_module('swarm_interfaces')

EVENT_NAMES: dict[Event, str] = {event: event.name.lower() for event in Event}
STALE_EVENT = 'stale_inputs'


def _float_array(values: Any) -> np.ndarray:
    """Return a float array view of a rosidl float sequence (array.array or list)."""
    if isinstance(values, array.array) and values.typecode == 'f' and len(values) > 0:
        return np.frombuffer(values, dtype=np.float32)
    return np.asarray(values, dtype=float).reshape(-1)


def scan_from_ros(msg: Any) -> LaserScanData:
    """sensor_msgs/LaserScan -> :class:`LaserScanData` (ranges are not copied when possible).

    Raises:
        ScanError: the scan's frame is unusable
            (:func:`~oabug_robot.scan_features.check_scan_frame`).
    """
    scan = LaserScanData(
        ranges_m=_float_array(msg.ranges),
        angle_min_rad=float(msg.angle_min),
        angle_increment_rad=float(msg.angle_increment),
        range_min_m=float(msg.range_min),
        range_max_m=float(msg.range_max),
    )
    check_scan_frame(scan, float(msg.angle_max))
    return scan


def yaw_from_imu(msg: Any) -> float:
    """sensor_msgs/Imu -> yaw [rad] of its orientation.

    Raises:
        ValueError: the orientation is zero or not finite (e.g. a driver that publishes no
            orientation).
    """
    q = msg.orientation
    yaw = yaw_from_quaternion(float(q.x), float(q.y), float(q.z), float(q.w))
    if not math.isfinite(yaw):
        msg_text = 'IMU orientation is not finite'
        raise ValueError(msg_text)
    return yaw


def gas_from_ros(msg: Any) -> int | None:
    """swarm_interfaces/GasReading -> raw 10-bit reading, or None while the heater warms up."""
    if msg.warming_up:
        return None
    return int(msg.raw)


def peer_arrays_from_ros(msg: Any, own_tag_id: str) -> tuple[np.ndarray, np.ndarray]:
    """swarm_interfaces/PeerBearingArray -> the peers' azimuths [rad] and distances [m]
    without the own tag (``own_tag_id`` case-insensitive; '' keeps every tag)."""
    own = own_tag_id.strip().upper()
    peers = [b for b in msg.bearings if not own or b.tag_id.strip().upper() != own]
    return (
        np.array([b.azimuth for b in peers], dtype=float),
        np.array([b.distance for b in peers], dtype=float),
    )


def command_to_twist(command: Command) -> Any:
    """Core command -> geometry_msgs/Twist (linear.x and angular.z)."""
    twist = geometry_msgs.Twist()
    twist.linear.x = float(command.linear_mps)
    twist.angular.z = float(command.angular_radps)
    return twist


def stop_twist() -> Any:
    """A zero geometry_msgs/Twist: the fail-safe command."""
    return geometry_msgs.Twist()


def command_to_pump(pump_on: bool) -> Any:
    """Pump state -> std_msgs/Bool."""
    return std_msgs.Bool(data=bool(pump_on))


def state_to_ros(
    memory: FsmMemory,
    config: OABugConfig,
    *,
    stamp: Any,
    heading_rad: float,
    pump_on: bool,
    gas_raw: int | None,
    scent_detected: bool,
    inputs_stale: bool,
) -> Any:
    """The controller's state -> swarm_interfaces/OABugState.

    Args:
        memory: the FSM's state after the step.
        config: its configuration (for the variant name).
        stamp: builtin_interfaces/Time of the step.
        heading_rad: the IMU heading used in the step [rad] (NaN when unknown).
        pump_on: the pump command published with it.
        gas_raw: latest gas reading, None when there is none.
        scent_detected: whether scent is within the scent window.
        inputs_stale: whether the robot is held stopped for stale inputs.
    """
    msg = swarm_interfaces.OABugState()
    msg.header.stamp = stamp
    msg.variant = config.variant.value
    msg.state = int(memory.state.value)
    msg.mode = int(memory.mode.value)
    msg.event = STALE_EVENT if inputs_stale else EVENT_NAMES[memory.event]
    msg.wall_side = int(memory.wall_side)
    msg.preferred_direction = float(memory.preferred_direction_rad)
    msg.target_heading = float(memory.target_yaw_rad)
    msg.heading = float(heading_rad)
    msg.leave_at_next_corner = bool(memory.leave_at_next_corner)
    msg.visit_count = int(memory.visit_count)
    msg.flip_count = int(memory.flip_count)
    msg.wall_hits = int(memory.counts.get(Event.HIT_WALL, 0))
    msg.robot_hits = int(memory.counts.get(Event.HIT_ROBOT, 0))
    msg.outer_corners = int(
        sum(
            memory.counts.get(e, 0)
            for e in (Event.OUTER_CORNER, Event.REVISIT, Event.LEAVE_WALL, Event.FLIP)
        )
    )
    msg.pump = bool(pump_on)
    msg.gas_raw = int(min(max(gas_raw or 0, 0), 1023))
    msg.scent_detected = bool(scent_detected)
    msg.inputs_stale = bool(inputs_stale)
    return msg
