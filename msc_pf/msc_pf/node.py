"""ROS 2 node of one msc_pf robot: odom + rssi + peer messages in, cmd_vel + state out.

Topics (relative to the robot's namespace, e.g. /r3):

* ``odom`` (nav_msgs/Odometry, sensor QoS): own pose in the shared world frame (GPS-like);
* ``rssi`` (swarm_interfaces/RssiArray, sensor QoS): beacon RSSI samples;
* ``captured`` (swarm_interfaces/CapturedTargets): task completions reported to this robot;
* ``peers/in`` / ``peers/out`` (swarm_interfaces/MscPeer): neighbours' and own broadcasts;
* ``cmd_vel`` (geometry_msgs/Twist): wheel commands, at ``drive_rate_hz``;
* ``state`` (swarm_interfaces/MscPfState): phase, role, swarm, target, estimates.

The node only translates messages: every input goes to :class:`msc_pf.loop.RobotLoop`
(sample and hold, staleness, timing, steering around :class:`msc_pf.robot.RobotController`,
the loop the batch runner runs too). Every ``period_s`` the loop steps the controller and
the node publishes its broadcast and state; at ``drive_rate_hz`` it publishes the loop's
wheel command (a stop when odometry is older than ``odom_timeout_s`` or the controller has
not run for two periods). Bad input (unknown or non-finite RSSI, out-of-order stamps or stamps
far ahead of the clock, odometry without a valid orientation, malformed or oversized peer
messages, peers' readings of emitters outside ``target_ids``) is ignored and logged; invalid
parameters stop the node at start.

Run on a robot: ``ros2 run msc_pf msc_pf_node --ros-args -r __ns:=/r3 -p scheme:=proposed``
(with ``-r peers/out:=/swarm/peers -r peers/in:=/swarm/peers`` when no relay exists).
"""

from __future__ import annotations

from typing import Any

from swarm_runtime.node_main import run_node
from swarm_runtime.parameters import declare_config
from swarm_runtime.ros import (
    Node,
    message_module,
    qos_profile_sensor_data,
)

from msc_pf import conversions
from msc_pf.errors import ConfigError
from msc_pf.loop import ControlStatus, RobotLoop, Steering
from msc_pf.parameters import MSC_PF_PARAMETERS, NODE_NAME, MscPfNodeConfig
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
        self.config = settings.controller
        robot_id = settings.robot_id
        self.robot_name = self.get_namespace().strip('/') or self.get_name()
        if robot_id < 0:
            try:
                robot_id = conversions.robot_id_from_name(self.robot_name)
            except ValueError as err:
                raise ConfigError(f'robot_id not set and {err}') from err
        self._accepted = settings.accepted_targets
        self.loop = RobotLoop(
            RobotController(robot_id, self.config, settings.seed), self._steering(settings)
        )
        self.controller = self.loop.controller

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

    @staticmethod
    def _steering(settings: MscPfNodeConfig) -> Steering:
        return Steering(
            odom_timeout_s=settings.odom_timeout_s,
            max_yaw_rate_rad_s=settings.max_yaw_rate_rad_s,
            heading_gain=settings.heading_gain,
        )

    def _configure(self, settings: MscPfNodeConfig) -> None:
        """Take the steering settings after an accepted parameter change."""
        loop = getattr(self, 'loop', None)
        if loop is not None:
            loop.steering = self._steering(settings)

    @property
    def last_output(self) -> StepOutput | None:
        """The controller's output of the last control step (None before the first)."""
        return self.loop.last_output

    def _now_s(self) -> float:
        return self.get_clock().now().nanoseconds * 1e-9

    # ------------------------------------------------------------------ inputs
    def _on_odom(self, msg: Any) -> None:
        try:
            pose = conversions.pose_from_odometry(msg)
        except ValueError as err:
            self.get_logger().warning(f'odometry ignored: {err}', throttle_duration_sec=5.0)
            return
        if not self.loop.receive_pose(pose, self._now_s()):
            self.get_logger().warning('non-finite odometry ignored', throttle_duration_sec=5.0)

    def _on_rssi(self, msg: Any) -> None:
        stamp = conversions.stamp_from_ros(msg.header.stamp)
        readings, ignored = conversions.readings_from_ros(msg, self._accepted)
        if not self.loop.receive_rssi(stamp, readings, self._now_s()):
            self.get_logger().warning(
                f'RSSI stamped {stamp:.3f} s ignored: {self.loop.last_rssi_refusal}',
                throttle_duration_sec=5.0,
            )
            return
        if ignored:
            self.get_logger().debug(f'{ignored} RSSI readings ignored (unknown or not finite)')

    def _on_captured(self, msg: Any) -> None:
        self.loop.receive_captured(conversions.captured_from_ros(msg))

    def _on_peer(self, msg: Any) -> None:
        try:
            peer = conversions.peer_from_ros(msg, self._accepted)
        except ValueError as err:
            self.get_logger().warning(f'peer message ignored: {err}', throttle_duration_sec=5.0)
            return
        self.loop.receive_peer(peer)
        ignored = len(msg.reading_ids) - len(peer.readings)
        if ignored:
            self.get_logger().debug(f'{ignored} peer readings ignored (not targets)')

    # ------------------------------------------------------------------ control
    def _on_control(self) -> None:
        result = self.loop.control(self._now_s())
        if result.status is ControlStatus.NO_POSE:
            self.get_logger().warning('no fresh odometry: holding still', throttle_duration_sec=5.0)
            return
        if result.status is ControlStatus.REJECTED or result.output is None:
            self.get_logger().error(f'control step skipped: {result.error}')
            return
        out = result.output
        for event in out.events:
            self.get_logger().info(event)
        for change in out.swarm_changes:
            self.get_logger().debug(change)
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
        speed, yaw_rate = self.loop.command(self._now_s())
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
