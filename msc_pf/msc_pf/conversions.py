"""Pure translations between ROS messages and the msc_pf core records.

Every function takes or returns message objects but holds no node state, so each one is
tested by a round trip. Message modules are passed in (``swarm_interfaces`` etc. from
``swarm_runtime.ros.message_module``) so the module imports no ROS at load time.
"""

from __future__ import annotations

import math
from collections.abc import Collection
from typing import Any

import numpy as np
from swarm_common.angles import ODOM_QUATERNION_NORM_TOLERANCE
from swarm_common.angles import yaw_from_odometry_quaternion as odometry_yaw
from swarm_common.stamps import stamp_from_seconds, stamp_to_seconds

from msc_pf.peers import PeerInfo, Phase, Role
from msc_pf.robot import RobotStatus

__all__ = [
    'MAX_PEER_ARRAY_LENGTH',
    'ODOM_QUATERNION_NORM_TOLERANCE',
    'captured_from_ros',
    'peer_from_ros',
    'peer_to_ros',
    'pose_from_odometry',
    'readings_from_ros',
    'robot_id_from_name',
    'stamp_from_ros',
    'stamp_to_ros',
    'status_to_ros',
    'twist_to_ros',
    'yaw_from_odometry_quaternion',
]

#: Longest ``reading_ids`` / ``reading_rssi_dbm`` / ``members`` / ``captured_ids`` array an
#: MscPeer may carry; a longer one drops the message. Every real mission fits (the spawner
#: places at most 100 targets and swarms hold a few robots); the cap bounds what one message
#: can make a receiver allocate.
MAX_PEER_ARRAY_LENGTH = 256


def robot_id_from_name(name: str) -> int:
    """Numeric ID of a robot name such as 'r3' (or '/r3'); raises ValueError otherwise."""
    text = name.strip('/')
    if len(text) < 2 or text[0] != 'r' or not text[1:].isdigit():
        raise ValueError(f"robot name {name!r} is not of the form 'r<number>'")
    return int(text[1:])


def stamp_from_ros(stamp: Any) -> float:
    """builtin_interfaces/Time -> seconds."""
    return stamp_to_seconds(stamp)


def stamp_to_ros(time_s: float, builtin_interfaces: Any) -> Any:
    """Seconds -> builtin_interfaces/Time (rounded to the nanosecond)."""
    return stamp_from_seconds(time_s, builtin_interfaces.Time)


def yaw_from_odometry_quaternion(x: float, y: float, z: float, w: float) -> float:
    """Yaw [rad] of an odometry orientation, normalised when it is not unit
    (:func:`swarm_common.angles.yaw_from_odometry_quaternion`, the nodes' shared policy).

    Raises:
        ValueError: the quaternion is zero or not finite, or its norm is further than
            :data:`~swarm_common.angles.ODOM_QUATERNION_NORM_TOLERANCE` from 1.
    """
    return odometry_yaw(x, y, z, w)


def pose_from_odometry(msg: Any) -> tuple[float, float, float]:
    """nav_msgs/Odometry -> (x [m], y [m], yaw [rad]) in the odometry (world) frame.

    Raises:
        ValueError: the orientation is no rotation (see :func:`yaw_from_odometry_quaternion`).
    """
    p = msg.pose.pose.position
    q = msg.pose.pose.orientation
    yaw = yaw_from_odometry_quaternion(q.x, q.y, q.z, q.w)
    return float(p.x), float(p.y), yaw


def readings_from_ros(
    msg: Any, accepted_ids: Collection[int] | None = None
) -> tuple[dict[int, float], int]:
    """swarm_interfaces/RssiArray -> ({emitter ID: dBm}, number of readings ignored).

    Non-finite values, repeated IDs (the first one is kept) and, when ``accepted_ids`` is
    given, emitters outside it (e.g. peers' tags) are ignored and counted.
    """
    readings: dict[int, float] = {}
    ignored = 0
    for reading in msg.readings:
        emitter, value = int(reading.emitter_id), float(reading.rssi_dbm)
        unknown = accepted_ids is not None and emitter not in accepted_ids
        if unknown or not math.isfinite(value) or emitter in readings:
            ignored += 1
            continue
        readings[emitter] = value
    return readings, ignored


def captured_from_ros(msg: Any) -> list[int]:
    """swarm_interfaces/CapturedTargets -> target IDs."""
    return [int(t) for t in msg.target_ids]


def peer_to_ros(info: PeerInfo, robot_name: str, swarm_interfaces: Any, builtin: Any) -> Any:
    """PeerInfo -> swarm_interfaces/MscPeer."""
    msg = swarm_interfaces.MscPeer()
    msg.header.stamp = stamp_to_ros(info.stamp_s, builtin)
    msg.header.frame_id = 'map'
    msg.robot = robot_name
    msg.robot_id = int(info.robot_id)
    msg.position_x, msg.position_y = (float(v) for v in info.position_m)
    msg.movement_x, msg.movement_y = (float(v) for v in info.movement)
    msg.role = int(info.role)
    msg.leader_id = int(info.leader_id)
    msg.members = [int(m) for m in info.members]
    msg.phase = int(info.phase)
    msg.target_id = int(info.target_id)
    msg.target_rssi_dbm = float(info.target_rssi_dbm)
    msg.evaluation = float(info.evaluation)
    msg.reading_ids = [int(t) for t, _ in info.readings]
    msg.reading_rssi_dbm = [float(v) for _, v in info.readings]
    msg.captured_ids = [int(t) for t in info.captured_ids]
    msg.visited_cell = int(info.visited_cell)
    return msg


def peer_from_ros(msg: Any, accepted_ids: Collection[int] | None = None) -> PeerInfo:
    """swarm_interfaces/MscPeer -> PeerInfo; raises ValueError on inconsistent fields.

    When ``accepted_ids`` is given, readings of emitters outside it are left out (as
    :func:`readings_from_ros` does for the own RSSI). A message with an array longer than
    :data:`MAX_PEER_ARRAY_LENGTH` is rejected.
    """
    for field in ('reading_ids', 'reading_rssi_dbm', 'members', 'captured_ids'):
        length = len(getattr(msg, field))
        if length > MAX_PEER_ARRAY_LENGTH:
            raise ValueError(
                f'peer {msg.robot!r}: {length} {field}, more than {MAX_PEER_ARRAY_LENGTH}'
            )
    if len(msg.reading_ids) != len(msg.reading_rssi_dbm):
        raise ValueError(
            f'peer {msg.robot!r}: {len(msg.reading_ids)} reading IDs but '
            f'{len(msg.reading_rssi_dbm)} values'
        )
    try:
        role, phase = Role(msg.role), Phase(msg.phase)
    except ValueError as err:
        raise ValueError(f'peer {msg.robot!r}: unknown role or phase ({err})') from err
    position = (float(msg.position_x), float(msg.position_y))
    if not all(math.isfinite(v) for v in position):
        raise ValueError(f'peer {msg.robot!r}: non-finite position {position}')
    movement = (float(msg.movement_x), float(msg.movement_y))
    if not all(math.isfinite(v) for v in movement):
        movement = (0.0, 0.0)
    return PeerInfo(
        robot_id=int(msg.robot_id),
        stamp_s=stamp_from_ros(msg.header.stamp),
        position_m=position,
        movement=movement,
        role=role,
        leader_id=int(msg.leader_id),
        members=tuple(int(m) for m in msg.members),
        phase=phase,
        target_id=int(msg.target_id),
        target_rssi_dbm=float(msg.target_rssi_dbm),
        evaluation=float(msg.evaluation),
        readings=tuple(
            (int(t), float(v))
            for t, v in zip(msg.reading_ids, msg.reading_rssi_dbm, strict=True)
            if accepted_ids is None or int(t) in accepted_ids
        ),
        captured_ids=tuple(int(t) for t in msg.captured_ids),
        visited_cell=int(msg.visited_cell),
    )


def status_to_ros(
    status: RobotStatus, robot_name: str, scheme: str, swarm_interfaces: Any, builtin: Any
) -> Any:
    """RobotStatus -> swarm_interfaces/MscPfState."""
    msg = swarm_interfaces.MscPfState()
    msg.header.stamp = stamp_to_ros(status.stamp_s, builtin)
    msg.header.frame_id = 'map'
    msg.robot = robot_name
    msg.scheme = scheme
    msg.phase = int(status.phase)
    msg.role = int(status.role)
    msg.swarm_id = int(status.swarm_id)
    msg.target_id = int(status.target_id)
    msg.target_rssi_dbm = float(status.target_rssi_dbm)
    msg.goal_x, msg.goal_y = (float(v) for v in np.asarray(status.goal_m, dtype=float))
    estimates = []
    for e in status.estimates:
        item = swarm_interfaces.MscTargetEstimate()
        item.target_id = int(e.target_id)
        item.x, item.y = (float(v) for v in e.position_m)
        item.spread_m = float(e.spread_m)
        item.best_particle_x, item.best_particle_y = (float(v) for v in e.best_particle_m)
        item.converged = bool(e.converged)
        item.updates = int(e.n_updates)
        estimates.append(item)
    msg.estimates = estimates
    msg.captured_ids = [int(t) for t in status.captured_ids]
    return msg


def twist_to_ros(speed_m_s: float, yaw_rate_rad_s: float, geometry_msgs: Any) -> Any:
    """(forward speed [m/s], yaw rate [rad/s]) -> geometry_msgs/Twist."""
    msg = geometry_msgs.Twist()
    msg.linear.x = float(speed_m_s)
    msg.angular.z = float(yaw_rate_rad_s)
    return msg
