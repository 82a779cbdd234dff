"""The OA-Bug robot node: sensor topics in, cmd_vel / pump / state out.

Subscribes (relative names, so the robot's namespace applies): ``scan``
(sensor_msgs/LaserScan), ``imu`` (sensor_msgs/Imu), ``gas`` (swarm_interfaces/GasReading),
``bearings`` (swarm_interfaces/PeerBearingArray). Publishes ``cmd_vel``
(geometry_msgs/Twist), ``pump`` (std_msgs/Bool) and ``state`` (swarm_interfaces/OABugState)
at ``control_rate_hz`` (the state at ``state_rate_hz``, and at every event).

The node only translates: the control loop (sample and hold, staleness, scan features, the
controller step) is :class:`oabug_robot.robot_loop.RobotLoop`, the same loop the batch
runner of the sweeps drives, and every decision is in :class:`oabug_robot.fsm.OABugFsm`. If
the scan or the IMU (and, for the gas variants, the gas sensor) has not been heard for
``stale_timeout_s``, it publishes a zero cmd_vel and pump off until the input is back.

Run: ``ros2 run oabug_robot oabug --ros-args -r __ns:=/r0 -p variant:=gas_sound
-p robot_index:=0 -p robot_count:=10``.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import Any

from swarm_runtime.node_main import run_node
from swarm_runtime.parameters import declare_config
from swarm_runtime.ros import (
    Node,
    message_module,
    qos_profile_sensor_data,
)

from oabug_robot.conversions import (
    command_to_pump,
    command_to_twist,
    gas_from_ros,
    peer_arrays_from_ros,
    scan_from_ros,
    state_to_ros,
    stop_twist,
    yaw_from_imu,
)
from oabug_robot.errors import ConfigError, ScanError
from oabug_robot.fsm import Event, OABugFsm
from oabug_robot.node_settings import NODE_NAME, OABUG_PARAMETERS, OABugNodeConfig
from oabug_robot.robot_loop import RobotLoop

__all__ = ['OABugNode', 'main']

sensor_msgs = message_module('sensor_msgs')
geometry_msgs = message_module('geometry_msgs')
std_msgs = message_module('std_msgs')
swarm_interfaces = message_module('swarm_interfaces')

# Seconds between two repetitions of the same warning.
WARN_PERIOD_S = 2.0


class OABugNode(Node):
    """One OA-Bug robot: reads its sensor topics, drives cmd_vel and the pump."""

    def __init__(self, node_name: str = NODE_NAME, **kwargs: Any) -> None:
        super().__init__(node_name, **kwargs)
        self._loop: RobotLoop[Any] | None = None
        try:
            self._declared = declare_config(self, OABUG_PARAMETERS, on_change=self._configure)
        except ConfigError as err:
            self.get_logger().fatal(f'invalid configuration: {err}')
            raise
        settings = self._declared.config
        self._loop = RobotLoop(settings, decode_scan=scan_from_ros)
        self._config = self._loop.config
        self._configure(settings)
        self._last_warning_s: dict[str, float] = {}
        self._last_state_s = -math.inf
        self._last_state_stale: bool | None = None

        self._cmd_pub = self.create_publisher(geometry_msgs.Twist, 'cmd_vel', 10)
        self._pump_pub = self.create_publisher(std_msgs.Bool, 'pump', 10)
        self._state_pub = self.create_publisher(swarm_interfaces.OABugState, 'state', 10)
        sensor_qos = qos_profile_sensor_data
        self.create_subscription(sensor_msgs.LaserScan, 'scan', self._on_scan, sensor_qos)
        self.create_subscription(sensor_msgs.Imu, 'imu', self._on_imu, sensor_qos)
        self.create_subscription(swarm_interfaces.GasReading, 'gas', self._on_gas, sensor_qos)
        self.create_subscription(
            swarm_interfaces.PeerBearingArray, 'bearings', self._on_bearings, sensor_qos
        )
        self._timer = self.create_timer(self._loop.control_period_s, self._on_control)
        self.get_logger().info(
            f'OA-Bug {self._config.variant.value}: robot {self._config.robot_index} of '
            f'{self._config.robot_count}, {self._config.departure.value} departure, '
            f'preferred direction {math.degrees(self.fsm.memory.preferred_direction_rad):.1f} deg'
        )

    def _configure(self, settings: OABugNodeConfig) -> None:
        """Take the settings a running node may change (at start and on a parameter change)."""
        self._stale_timeout_s = settings.stale_timeout_s
        self._state_period_s = 1.0 / settings.state_rate_hz
        self._own_tag_id = settings.own_tag_id
        if self._loop is not None:
            self._loop.configure(settings)

    @property
    def loop(self) -> RobotLoop[Any]:
        """The robot's control loop (held readings, staleness, controller)."""
        assert self._loop is not None
        return self._loop

    @property
    def fsm(self) -> OABugFsm:
        """The controller (for inspection in tests and tools)."""
        return self.loop.fsm

    def _now_s(self) -> float:
        return self.get_clock().now().nanoseconds * 1e-9

    def _log_once_per_period(self, key: str, text: str, *, warn: bool = True) -> None:
        """Log ``text`` at most once per WARN_PERIOD_S for each key (warning or info)."""
        now = self._now_s()
        last = self._last_warning_s.get(key)
        if last is None or now - last >= WARN_PERIOD_S or now < last:
            self._last_warning_s[key] = now
            if warn:
                self.get_logger().warning(text)
            else:
                self.get_logger().info(text)

    # Sensor callbacks: hand the reading to the loop with the time it arrived (node clock).

    def _on_scan(self, msg: Any) -> None:
        self.loop.hold_scan(msg, self._now_s())

    def _on_imu(self, msg: Any) -> None:
        try:
            yaw = yaw_from_imu(msg)
        except ValueError as err:
            self._log_once_per_period('imu', f'ignoring IMU message: {err}')
            return
        self.loop.hold_yaw(yaw, self._now_s())

    def _on_gas(self, msg: Any) -> None:
        self.loop.hold_gas(gas_from_ros(msg), self._now_s())

    def _on_bearings(self, msg: Any) -> None:
        azimuths, distances = peer_arrays_from_ros(msg, self._own_tag_id)
        self.loop.hold_bearings(azimuths, distances, self._now_s())

    # Control loop.

    def _on_control(self) -> None:
        now = self.get_clock().now()
        now_s = now.nanoseconds * 1e-9
        stamp = now.to_msg()
        loop = self.loop
        try:
            loop.update_features(now_s)
        except ScanError as err:
            self._log_once_per_period('scan', f'ignoring laser scan: {err}')
        output = loop.step(now_s)
        if output.stale:
            self._hold_stopped(now_s, stamp, output.stale)
            return
        command = output.command
        self._cmd_pub.publish(command_to_twist(command))
        self._pump_pub.publish(command_to_pump(command.pump_on))
        self._publish_state(now_s, stamp, pump_on=command.pump_on, stale=False)

    def _hold_stopped(self, now_s: float, stamp: Any, stale: Sequence[str]) -> None:
        """Fail safe: zero velocity and pump off while an input is missing or stale."""
        self._cmd_pub.publish(stop_twist())
        self._pump_pub.publish(command_to_pump(False))
        self._publish_state(now_s, stamp, pump_on=False, stale=True)
        never = [name for name in stale if name not in self.loop.heard]
        if never:
            self._log_once_per_period(
                'waiting', f'waiting for the first {", ".join(never)} message', warn=False
            )
        else:
            self._log_once_per_period(
                'stale',
                f'holding still, no fresh {", ".join(stale)} within {self._stale_timeout_s:.2f} s',
            )

    def _publish_state(self, now_s: float, stamp: Any, *, pump_on: bool, stale: bool) -> None:
        """Publish the state at ``state_rate_hz``, and at once on an event or a stale change.

        ``stamp`` is the control step's time (the time ``now_s`` in seconds) as a message.
        """
        due = not 0.0 <= now_s - self._last_state_s < self._state_period_s
        changed = stale != self._last_state_stale
        event = not stale and self.fsm.memory.event is not Event.NONE
        if not (due or changed or event):
            return
        self._last_state_s = now_s
        self._last_state_stale = stale
        loop = self.loop
        self._state_pub.publish(
            state_to_ros(
                self.fsm.memory,
                self._config,
                stamp=stamp,
                heading_rad=loop.yaw_rad,
                pump_on=pump_on,
                gas_raw=loop.gas_raw,
                scent_detected=self.fsm.scent_detected(now_s),
                inputs_stale=stale,
            )
        )


def main(args: list[str] | None = None) -> int:
    """Console entry point: ``ros2 run oabug_robot oabug``."""
    # The node logs its configuration errors itself (describe_fatal None: no second line).
    return run_node(
        OABugNode,
        args,
        name=NODE_NAME,
        fatal_errors=(ConfigError,),
        describe_fatal=lambda _: None,
        parameters=OABUG_PARAMETERS,
    )


if __name__ == '__main__':
    raise SystemExit(main())
