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
from swarm_runtime.parameters import declare_config
from swarm_runtime.ros import (
    Node,
    message_module,
    qos_profile_sensor_data,
)

from msc_pf import conversions
from msc_pf.drive import unicycle_command
from msc_pf.errors import ConfigError, ObservationError
from msc_pf.parameters import MSC_PF_PARAMETERS, NODE_NAME, MscPfNodeConfig
from msc_pf.peers import PeerInfo
from msc_pf.robot import RobotController, StepOutput

__all__ = ['MscPfNode', 'main']

_swarm = message_module('swarm_interfaces')
_nav = message_module('nav_msgs')
_geometry = message_module('geometry_msgs')
_builtin = message_module('builtin_interfaces')


class MscPfNode(Node):
    """One robot running MSC, MSC+PF or the proposed swarm control."""

    def __init__(self, **kwargs: Any) -> None:
        """Declare parameters, build the controller and the topics (kwargs go to Node)."""
        super().__init__(NODE_NAME, **kwargs)
        try:
            self._declared = declare_config(self, MSC_PF_PARAMETERS, on_change=self._configure)
        except ConfigError as err:
            self.get_logger().fatal(f'invalid parameters: {err}')
            raise
        settings = self._declared.config
        self._configure(settings)
        self.config = settings.controller
        robot_id = settings.robot_id
        self.robot_name = self.get_namespace().strip('/') or self.get_name()
        if robot_id < 0:
            try:
                robot_id = conversions.robot_id_from_name(self.robot_name)
            except ValueError as err:
                raise ConfigError(f'robot_id not set and {err}') from err
        self._accepted = settings.accepted_targets
        self.controller = RobotController(robot_id, self.config, settings.seed)

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
        self.create_timer(1.0 / settings.drive_rate_hz, self._on_drive)
        self.get_logger().info(
            f'{self.robot_name} (id {robot_id}) runs {self.config.scheme.value}, '
            f'period {self.config.period_s:g} s'
        )

    def _configure(self, settings: MscPfNodeConfig) -> None:
        """Take the steering settings (at start and after an accepted parameter change)."""
        self._odom_timeout_s = settings.odom_timeout_s
        self._max_yaw_rate_rad_s = settings.max_yaw_rate_rad_s
        self._heading_gain = settings.heading_gain

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
        if self._pose is None or now - self._pose_time_s > self._odom_timeout_s:
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
        stale = self._pose is None or now - self._pose_time_s > self._odom_timeout_s
        late = now - self._last_step_s > 2.0 * self.config.period_s
        if stale or late or self._waypoint is None:
            self._cmd_pub.publish(conversions.twist_to_ros(0.0, 0.0, _geometry))
            return
        speed, yaw_rate = unicycle_command(
            self._pose,
            self._waypoint,
            self._deadline_s - now,
            max_speed_m_s=self.config.max_speed_m_s,
            max_yaw_rate_rad_s=self._max_yaw_rate_rad_s,
            heading_gain=self._heading_gain,
        )
        self._cmd_pub.publish(conversions.twist_to_ros(speed, yaw_rate, _geometry))


def main(args: list[str] | None = None) -> int:
    """Entry point of ``ros2 run msc_pf msc_pf_node``."""
    return run_node(
        MscPfNode,
        args,
        name=NODE_NAME,
        fatal_errors=(ConfigError,),
        parameters=MSC_PF_PARAMETERS,
    )


if __name__ == '__main__':
    raise SystemExit(main())
