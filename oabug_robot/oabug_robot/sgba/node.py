"""The SGBA robot node: scan, imu, odom and bearings in, cmd_vel out.

Subscribes (relative names, so the robot's namespace applies): ``scan``
(sensor_msgs/LaserScan), ``imu`` (sensor_msgs/Imu), ``odom`` (nav_msgs/Odometry) and
``bearings`` (swarm_interfaces/PeerBearingArray, the peers' tags with their RSSI-based
distances). Publishes ``cmd_vel`` (geometry_msgs/Twist) at ``control_rate_hz``.

The node only translates: the loop is :class:`oabug_robot.sgba.loop.SgbaLoop`, the same one
the batch runner drives, and every decision is in
:class:`oabug_robot.sgba.controller.SgbaController`. While the scan, the IMU or the odometry
has not been heard for ``stale_timeout_s`` it publishes a zero cmd_vel.

Run: ``ros2 run oabug_robot sgba --ros-args -r __ns:=/r0 -p robot_index:=0
-p robot_count:=10 -p own_tag_id:=R0``.
"""

from __future__ import annotations

import math
from typing import Any

from swarm_runtime.node_main import run_node
from swarm_runtime.parameters import declare_config
from swarm_runtime.ros import Node, message_module, qos_profile_sensor_data

from oabug_robot.conversions import scan_from_ros, yaw_from_imu
from oabug_robot.errors import ConfigError, ScanError
from oabug_robot.sgba.conversions import (
    command_to_twist,
    peers_from_ros,
    position_from_odometry,
    stop_twist,
)
from oabug_robot.sgba.loop import SgbaLoop
from oabug_robot.sgba.settings import NODE_NAME, SGBA_PARAMETERS, SgbaNodeConfig

__all__ = ['SgbaNode', 'main']

sensor_msgs = message_module('sensor_msgs')
geometry_msgs = message_module('geometry_msgs')
nav_msgs = message_module('nav_msgs')
swarm_interfaces = message_module('swarm_interfaces')

WARN_PERIOD_S = 2.0


class SgbaNode(Node):
    """One SGBA robot: reads its sensor topics, drives cmd_vel."""

    def __init__(self, node_name: str = NODE_NAME, **kwargs: Any) -> None:
        super().__init__(node_name, **kwargs)
        self._loop: SgbaLoop[Any] | None = None
        try:
            self._declared = declare_config(self, SGBA_PARAMETERS, on_change=self._configure)
        except ConfigError as err:
            self.get_logger().fatal(f'invalid configuration: {err}')
            raise
        settings = self._declared.config
        self._loop = SgbaLoop(settings, decode_scan=scan_from_ros)
        self._last_warning_s: dict[str, float] = {}
        self._cmd_pub = self.create_publisher(geometry_msgs.Twist, 'cmd_vel', 10)
        qos = qos_profile_sensor_data
        self.create_subscription(sensor_msgs.LaserScan, 'scan', self._on_scan, qos)
        self.create_subscription(sensor_msgs.Imu, 'imu', self._on_imu, qos)
        self.create_subscription(nav_msgs.Odometry, 'odom', self._on_odom, qos)
        self.create_subscription(
            swarm_interfaces.PeerBearingArray, 'bearings', self._on_bearings, qos
        )
        self._timer = self.create_timer(self._loop.control_period_s, self._on_control)
        config = self._loop.config
        self.get_logger().info(
            f'SGBA: robot {config.robot_index} of {config.robot_count}, preferred heading '
            f'{math.degrees(self.loop.controller.preferred_heading_rad):.1f} deg'
        )

    def _configure(self, settings: SgbaNodeConfig) -> None:
        if self._loop is not None:
            self._loop.configure(settings)

    @property
    def loop(self) -> SgbaLoop[Any]:
        """The robot's control loop."""
        assert self._loop is not None
        return self._loop

    def _now_s(self) -> float:
        return self.get_clock().now().nanoseconds * 1e-9

    def _warn(self, key: str, text: str, *, warn: bool = True) -> None:
        now = self._now_s()
        last = self._last_warning_s.get(key)
        if last is None or now - last >= WARN_PERIOD_S or now < last:
            self._last_warning_s[key] = now
            if warn:
                self.get_logger().warning(text)
            else:
                self.get_logger().info(text)

    def _on_scan(self, msg: Any) -> None:
        self.loop.hold_scan(msg, self._now_s())

    def _on_imu(self, msg: Any) -> None:
        try:
            yaw = yaw_from_imu(msg)
        except ValueError as err:
            self._warn('imu', f'ignoring IMU message: {err}')
            return
        self.loop.hold_yaw(yaw, self._now_s())

    def _on_odom(self, msg: Any) -> None:
        try:
            position = position_from_odometry(msg)
        except ValueError as err:
            self._warn('odom', f'ignoring odometry: {err}')
            return
        self.loop.hold_position(*position, self._now_s())

    def _on_bearings(self, msg: Any) -> None:
        self.loop.hold_peers(*peers_from_ros(msg), self._now_s())

    def _on_control(self) -> None:
        now_s = self._now_s()
        try:
            self.loop.update_ranges()
        except ScanError as err:
            self._warn('scan', f'ignoring laser scan: {err}')
        output = self.loop.step(now_s)
        if output.stale:
            self._cmd_pub.publish(stop_twist())
            never = [name for name in output.stale if name not in self.loop.heard]
            if never:
                self._warn(
                    'waiting', f'waiting for the first {", ".join(never)} message', warn=False
                )
            else:
                self._warn('stale', f'holding still, no fresh {", ".join(output.stale)}')
            return
        self._cmd_pub.publish(command_to_twist(output.command))


def main(args: list[str] | None = None) -> int:
    """Console entry point: ``ros2 run oabug_robot sgba``."""
    return run_node(
        SgbaNode,
        args,
        name=NODE_NAME,
        fatal_errors=(ConfigError,),
        describe_fatal=lambda _: None,
        parameters=SGBA_PARAMETERS,
    )


if __name__ == '__main__':
    raise SystemExit(main())
