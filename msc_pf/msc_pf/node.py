"""ROS 2 node of one msc_pf robot: odom + rssi + peer messages in, cmd_vel + state out.

Topics (relative to the robot's namespace, e.g. /r3):

* ``odom`` (nav_msgs/Odometry, sensor QoS): own pose in the shared world frame (GPS-like);
* ``rssi`` (swarm_interfaces/RssiArray, sensor QoS): beacon RSSI samples;
* ``captured`` (swarm_interfaces/CapturedTargets): task completions reported to this robot;
* ``peers/in`` / ``peers/out`` (swarm_interfaces/MscPeer): neighbours' and own broadcasts;
* ``cmd_vel`` (geometry_msgs/Twist): wheel commands, at ``drive_rate_hz``;
* ``state`` (swarm_interfaces/MscPfState): phase, role, swarm, target, estimates.

Every ``period_s`` the node hands the latest pose, the RSSI samples since the last period
and the peer messages received to :class:`msc_pf.robot.RobotController`, publishes its
broadcast and state, and steers toward the displacement it returned until the next period.
It stops the robot when odometry is older than ``odom_timeout_s`` or the controller has not
run for two periods. Bad input (unknown or non-finite RSSI, out-of-order stamps, malformed
peer messages) is ignored and logged; invalid parameters stop the node at start.

Run on a robot: ``ros2 run msc_pf msc_pf_node --ros-args -r __ns:=/r3 -p scheme:=proposed``
(with ``-r peers/out:=/swarm/peers -r peers/in:=/swarm/peers`` when no relay exists).
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np
from swarm_runtime.node_main import run_node
from swarm_runtime.ros import (
    Node,
    message_module,
    qos_profile_sensor_data,
)

from msc_pf import conversions
from msc_pf.drive import unicycle_command
from msc_pf.errors import ConfigError, ObservationError
from msc_pf.parameters import config_from_parameters, parameter_defaults, parameter_descriptions
from msc_pf.peers import PeerInfo
from msc_pf.robot import RobotController, StepOutput

__all__ = ['MscPfNode', 'main']

_swarm = message_module('swarm_interfaces')
_nav = message_module('nav_msgs')
_geometry = message_module('geometry_msgs')
_builtin = message_module('builtin_interfaces')
_rcl = message_module('rcl_interfaces')

NODE_PARAMETERS: dict[str, tuple[Any, str]] = {
    'robot_id': (-1, 'Numeric robot ID; -1 takes it from the namespace (r3 -> 3).'),
    'seed': (0, 'Seed of the robot controller (random search direction, PF, MSC draws).'),
    'drive_rate_hz': (10.0, 'Rate of cmd_vel while steering toward the period waypoint [Hz].'),
    'max_yaw_rate_rad_s': (2.0, 'Yaw-rate limit of the base [rad/s].'),
    'heading_gain': (2.0, 'Yaw rate per radian of heading error [1/s].'),
    'odom_timeout_s': (1.0, 'Stop when the last odometry is older than this [s].'),
    'target_ids': ([-1], 'Emitter IDs that are targets; [-1] accepts every emitter.'),
}


class MscPfNode(Node):
    """One robot running MSC, MSC+PF or the proposed swarm control."""

    def __init__(self, **kwargs: Any) -> None:
        """Declare parameters, build the controller and the topics (kwargs go to Node)."""
        super().__init__('msc_pf', **kwargs)
        describe = _rcl.ParameterDescriptor
        descriptions = parameter_descriptions()
        for name, default in parameter_defaults().items():
            self.declare_parameter(name, default, describe(description=descriptions[name]))
        for name, (default, text) in NODE_PARAMETERS.items():
            self.declare_parameter(name, default, describe(description=text))
        try:
            self.config = config_from_parameters(
                {name: self.get_parameter(name).value for name in parameter_defaults()}
            )
            self._check_node_parameters()
        except ConfigError as err:
            self.get_logger().fatal(f'invalid parameters: {err}')
            raise
        robot_id = int(self.get_parameter('robot_id').value)
        self.robot_name = self.get_namespace().strip('/') or self.get_name()
        if robot_id < 0:
            try:
                robot_id = conversions.robot_id_from_name(self.robot_name)
            except ValueError as err:
                raise ConfigError(f'robot_id not set and {err}') from err
        ids = [int(t) for t in self.get_parameter('target_ids').value]
        self._accepted = None if ids == [-1] else frozenset(ids)
        self.controller = RobotController(
            robot_id, self.config, int(self.get_parameter('seed').value)
        )

        self._pose: tuple[float, float, float] | None = None
        self._pose_time_s = -math.inf
        self._readings: dict[int, float] = {}
        self._rssi_stamp_s = -math.inf
        self._inbox: list[PeerInfo] = []
        self._captured: list[int] = []
        self._waypoint: tuple[float, float] | None = None
        self._deadline_s = -math.inf
        self._last_step_s = -math.inf
        self.last_output: StepOutput | None = None

        sensor = qos_profile_sensor_data
        self.create_subscription(_nav.Odometry, 'odom', self._on_odom, sensor)
        self.create_subscription(_swarm.RssiArray, 'rssi', self._on_rssi, sensor)
        self.create_subscription(_swarm.CapturedTargets, 'captured', self._on_captured, 10)
        self.create_subscription(_swarm.MscPeer, 'peers/in', self._on_peer, 10)
        self._cmd_pub = self.create_publisher(_geometry.Twist, 'cmd_vel', 10)
        self._peer_pub = self.create_publisher(_swarm.MscPeer, 'peers/out', 10)
        self._state_pub = self.create_publisher(_swarm.MscPfState, 'state', 10)
        self.create_timer(self.config.period_s, self._on_control)
        self.create_timer(1.0 / float(self.get_parameter('drive_rate_hz').value), self._on_drive)
        self.get_logger().info(
            f'{self.robot_name} (id {robot_id}) runs {self.config.scheme.value}, '
            f'period {self.config.period_s:g} s'
        )

    def _check_node_parameters(self) -> None:
        for name in ('drive_rate_hz', 'max_yaw_rate_rad_s', 'heading_gain', 'odom_timeout_s'):
            value = float(self.get_parameter(name).value)
            if not (math.isfinite(value) and value > 0.0):
                raise ConfigError(f'{name} must be a positive number, got {value}')

    def _now_s(self) -> float:
        return self.get_clock().now().nanoseconds * 1e-9

    # ------------------------------------------------------------------ inputs
    def _on_odom(self, msg: Any) -> None:
        pose = conversions.pose_from_odometry(msg)
        if not all(math.isfinite(v) for v in pose):
            self.get_logger().warning('non-finite odometry ignored', throttle_duration_sec=5.0)
            return
        self._pose = pose
        self._pose_time_s = self._now_s()

    def _on_rssi(self, msg: Any) -> None:
        stamp = conversions.stamp_from_ros(msg.header.stamp)
        if stamp < self._rssi_stamp_s:
            self.get_logger().warning(
                f'RSSI stamped {stamp:.3f} s arrived after {self._rssi_stamp_s:.3f} s: ignored',
                throttle_duration_sec=5.0,
            )
            return
        self._rssi_stamp_s = stamp
        readings, ignored = conversions.readings_from_ros(msg, self._accepted)
        if ignored:
            self.get_logger().debug(f'{ignored} RSSI readings ignored (unknown or not finite)')
        self._readings.update(readings)

    def _on_captured(self, msg: Any) -> None:
        self._captured.extend(conversions.captured_from_ros(msg))

    def _on_peer(self, msg: Any) -> None:
        try:
            self._inbox.append(conversions.peer_from_ros(msg))
        except ValueError as err:
            self.get_logger().warning(f'peer message ignored: {err}', throttle_duration_sec=5.0)

    # ------------------------------------------------------------------ control
    def _on_control(self) -> None:
        now = self._now_s()
        timeout = float(self.get_parameter('odom_timeout_s').value)
        if self._pose is None or now - self._pose_time_s > timeout:
            self._waypoint = None
            self.get_logger().warning('no fresh odometry: holding still', throttle_duration_sec=5.0)
            return
        readings, self._readings = self._readings, {}
        inbox, self._inbox = self._inbox, []
        captured, self._captured = self._captured, []
        position = np.array(self._pose[:2])
        try:
            out = self.controller.step(now, position, readings, inbox, captured)
        except ObservationError as err:
            self.get_logger().error(f'control step skipped: {err}')
            self._waypoint = None
            return
        for event in out.events:
            self.get_logger().info(event)
        for change in out.swarm_changes:
            self.get_logger().debug(change)
        self.last_output = out
        self._last_step_s = now
        self._waypoint = (
            float(position[0] + out.displacement_m[0]),
            float(position[1] + out.displacement_m[1]),
        )
        self._deadline_s = now + self.config.period_s
        self._peer_pub.publish(
            conversions.peer_to_ros(out.broadcast, self.robot_name, _swarm, _builtin)
        )
        self._state_pub.publish(
            conversions.status_to_ros(
                out.status, self.robot_name, self.config.scheme.value, _swarm, _builtin
            )
        )
        self._on_drive()

    def _on_drive(self) -> None:
        now = self._now_s()
        timeout = float(self.get_parameter('odom_timeout_s').value)
        stale = self._pose is None or now - self._pose_time_s > timeout
        late = now - self._last_step_s > 2.0 * self.config.period_s
        if stale or late or self._waypoint is None:
            self._cmd_pub.publish(conversions.twist_to_ros(0.0, 0.0, _geometry))
            return
        speed, yaw_rate = unicycle_command(
            self._pose,
            self._waypoint,
            self._deadline_s - now,
            max_speed_m_s=self.config.max_speed_m_s,
            max_yaw_rate_rad_s=float(self.get_parameter('max_yaw_rate_rad_s').value),
            heading_gain=float(self.get_parameter('heading_gain').value),
        )
        self._cmd_pub.publish(conversions.twist_to_ros(speed, yaw_rate, _geometry))


def main(args: list[str] | None = None) -> int:
    """Entry point of ``ros2 run msc_pf msc_pf_node``."""
    return run_node(MscPfNode, args, name='msc_pf', fatal_errors=(ConfigError,))


if __name__ == '__main__':
    raise SystemExit(main())
