"""The OA-Bug robot node: sensor topics in, cmd_vel / pump / state out.

Subscribes (relative names, so the robot's namespace applies): ``scan``
(sensor_msgs/LaserScan), ``imu`` (sensor_msgs/Imu), ``gas`` (swarm_interfaces/GasReading),
``bearings`` (swarm_interfaces/PeerBearingArray). Publishes ``cmd_vel``
(geometry_msgs/Twist), ``pump`` (std_msgs/Bool) and ``state`` (swarm_interfaces/OABugState)
at ``control_rate_hz`` (the state at ``state_rate_hz``, and at every event).

The node only translates; every decision is in :class:`oabug_robot.fsm.OABugFsm`. If the scan
or the IMU (and, for the gas variants, the gas sensor) has not been heard for
``stale_timeout_s``, it publishes a zero cmd_vel and pump off until the input is back.

Run: ``ros2 run oabug_robot oabug --ros-args -r __ns:=/r0 -p variant:=gas_sound
-p robot_index:=0 -p robot_count:=10``.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import Any

import numpy as np
from swarm_runtime.node_main import run_node
from swarm_runtime.parameters import declare_config
from swarm_runtime.ros import (
    Node,
    message_module,
    qos_profile_sensor_data,
)

from oabug_robot.conversions import (
    bearings_from_ros,
    command_to_pump,
    command_to_twist,
    gas_from_ros,
    scan_from_ros,
    state_to_ros,
    stop_twist,
    yaw_from_imu,
)
from oabug_robot.errors import ConfigError, ScanError
from oabug_robot.fsm import Event, OABugFsm, SensorSnapshot
from oabug_robot.node_settings import NODE_NAME, OABUG_PARAMETERS, OABugNodeConfig
from oabug_robot.scan_features import ScanFeatureExtractor, ScanFeatures
from oabug_robot.sound import PeerBearings

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
        try:
            self._declared = declare_config(self, OABUG_PARAMETERS, on_change=self._configure)
        except ConfigError as err:
            self.get_logger().fatal(f'invalid configuration: {err}')
            raise
        settings = self._declared.config
        self._config = settings.controller_config()
        self._configure(settings)
        self._fsm = OABugFsm(self._config)
        self._extractor = ScanFeatureExtractor(self._config.perception)

        self._scan_msg: Any = None
        self._scan_time_s: float | None = None
        self._features: ScanFeatures | None = None
        self._features_time_s: float | None = None
        self._yaw_rad = math.nan
        self._imu_time_s: float | None = None
        self._gas_raw: int | None = None
        self._gas_time_s: float | None = None
        self._bearings: PeerBearings | None = None
        self._last_warning_s: dict[str, float] = {}
        self._last_state_s = -math.inf
        self._last_state_stale: bool | None = None
        self._heard: set[str] = set()

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
        self._timer = self.create_timer(1.0 / settings.control_rate_hz, self._on_control)
        self.get_logger().info(
            f'OA-Bug {self._config.variant.value}: robot {self._config.robot_index} of '
            f'{self._config.robot_count}, {self._config.departure.value} departure, '
            f'preferred direction {math.degrees(self._fsm.memory.preferred_direction_rad):.1f} deg'
        )

    def _configure(self, settings: OABugNodeConfig) -> None:
        """Take the settings a running node may change (at start and on a parameter change)."""
        self._stale_timeout_s = settings.stale_timeout_s
        self._state_period_s = 1.0 / settings.state_rate_hz
        self._own_tag_id = settings.own_tag_id

    @property
    def fsm(self) -> OABugFsm:
        """The controller (for inspection in tests and tools)."""
        return self._fsm

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

    # Sensor callbacks: store the latest value and when it arrived (node clock).

    def _on_scan(self, msg: Any) -> None:
        self._scan_msg = msg
        self._scan_time_s = self._now_s()

    def _on_imu(self, msg: Any) -> None:
        try:
            self._yaw_rad = yaw_from_imu(msg)
        except ValueError as err:
            self._log_once_per_period('imu', f'ignoring IMU message: {err}')
            return
        self._imu_time_s = self._now_s()
        self._heard.add('imu')

    def _on_gas(self, msg: Any) -> None:
        self._gas_raw = gas_from_ros(msg)
        self._gas_time_s = self._now_s()
        self._heard.add('gas')

    def _on_bearings(self, msg: Any) -> None:
        yaw = self._yaw_rad if math.isfinite(self._yaw_rad) else 0.0
        self._bearings = bearings_from_ros(msg, self._own_tag_id, self._now_s(), yaw)

    # Control loop.

    def _stale_inputs(self, now_s: float) -> list[str]:
        required: list[tuple[str, float | None]] = [
            ('scan', self._features_time_s),
            ('imu', self._imu_time_s),
        ]
        if self._config.variant.uses_scent:
            required.append(('gas', self._gas_time_s))
        return [
            name
            for name, stamp in required
            if stamp is None or not 0.0 <= now_s - stamp <= self._stale_timeout_s
        ]

    def _near_peers(self, now_s: float) -> tuple[np.ndarray, np.ndarray]:
        """Fresh bearings [rad] (robot frame now) and distances [m] of peers that may be near."""
        bearings = self._bearings
        if bearings is None or now_s - bearings.stamp_s > self._config.bearing_timeout_s:
            return np.zeros(0), np.zeros(0)
        return bearings.near_peers_now(
            self._yaw_rad, self._config.perception.peer_bearing_max_distance_m
        )

    def _update_features(self, now_s: float) -> None:
        if self._scan_msg is None:
            return
        scan_time, msg = self._scan_time_s, self._scan_msg
        self._scan_msg = None
        try:
            # Only the wall being followed matters for the next step (a wall taken up in
            # that step is first turned to, which needs no side wall).
            side = self._fsm.memory.wall_side
            self._features = self._extractor.extract(
                scan_from_ros(msg), *self._near_peers(now_s), sides=(side,) if side else ()
            )
        except ScanError as err:
            self._log_once_per_period('scan', f'ignoring laser scan: {err}')
            return
        self._features_time_s = scan_time
        self._heard.add('scan')

    def _on_control(self) -> None:
        now_s = self._now_s()
        if math.isfinite(self._yaw_rad):
            self._update_features(now_s)
        stale = self._stale_inputs(now_s)
        features = self._features
        if stale or features is None:
            self._hold_stopped(now_s, stale or ['scan'])
            return
        snapshot = SensorSnapshot(
            time_s=now_s,
            yaw_rad=self._yaw_rad,
            scan=features,
            gas_raw=self._gas_raw,
            bearings=self._bearings,
        )
        command = self._fsm.step(snapshot)
        self._cmd_pub.publish(command_to_twist(command))
        self._pump_pub.publish(command_to_pump(command.pump_on))
        self._publish_state(now_s, pump_on=command.pump_on, stale=False)

    def _hold_stopped(self, now_s: float, stale: Sequence[str]) -> None:
        """Fail safe: zero velocity and pump off while an input is missing or stale."""
        self._cmd_pub.publish(stop_twist())
        self._pump_pub.publish(command_to_pump(False))
        self._publish_state(now_s, pump_on=False, stale=True)
        never = [name for name in stale if name not in self._heard]
        if never:
            self._log_once_per_period(
                'waiting', f'waiting for the first {", ".join(never)} message', warn=False
            )
        else:
            self._log_once_per_period(
                'stale',
                f'holding still, no fresh {", ".join(stale)} within {self._stale_timeout_s:.2f} s',
            )

    def _publish_state(self, now_s: float, *, pump_on: bool, stale: bool) -> None:
        """Publish the state at ``state_rate_hz``, and at once on an event or a stale change."""
        due = not 0.0 <= now_s - self._last_state_s < self._state_period_s
        changed = stale != self._last_state_stale
        event = not stale and self._fsm.memory.event is not Event.NONE
        if not (due or changed or event):
            return
        self._last_state_s = now_s
        self._last_state_stale = stale
        self._state_pub.publish(
            state_to_ros(
                self._fsm.memory,
                self._config,
                stamp=self.get_clock().now().to_msg(),
                heading_rad=self._yaw_rad,
                pump_on=pump_on,
                gas_raw=self._gas_raw,
                scent_detected=self._fsm.scent_detected(now_s),
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
