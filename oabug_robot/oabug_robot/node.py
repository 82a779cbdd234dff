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
from oabug_robot.scan_features import ScanFeatureExtractor, ScanFeatures
from oabug_robot.settings import (
    Departure,
    MotionConfig,
    OABugConfig,
    PerceptionConfig,
    SoundMemory,
    SoundTurnRule,
    SoundWallSide,
    SoundWeighting,
    TurnDirection,
    Variant,
)
from oabug_robot.sound import PeerBearings

__all__ = ['OABugNode', 'main']

sensor_msgs = message_module('sensor_msgs')
geometry_msgs = message_module('geometry_msgs')
std_msgs = message_module('std_msgs')
swarm_interfaces = message_module('swarm_interfaces')
rcl_interfaces = message_module('rcl_interfaces')

# Seconds between two repetitions of the same warning.
WARN_PERIOD_S = 2.0
_DEFAULTS = OABugConfig()
_PERCEPTION = PerceptionConfig()
_MOTION = MotionConfig()

# name, default, description. Declared read-only: the controller is built once at start.
PARAMETERS: tuple[tuple[str, Any, str], ...] = (
    ('variant', _DEFAULTS.variant.value, 'random, minimum, sound, gas or gas_sound (Table I)'),
    ('robot_index', 0, 'i: this robot index in the swarm, 0..robot_count-1'),
    ('robot_count', 1, 'n: number of robots that depart together'),
    ('departure', 'center', 'center (full-circle fan) or edge (half-circle fan)'),
    (
        'heading_bias_deg',
        0.0,
        'bias of the preferred directions [deg] in the IMU yaw frame; for edge departure, '
        'the direction into the building minus 90',
    ),
    ('control_rate_hz', 10.0, 'control loop rate [Hz]'),
    (
        'state_rate_hz',
        2.0,
        'state topic rate [Hz]; a step with an event or a change of staleness is always published',
    ),
    ('stale_timeout_s', 1.0, 'stop when scan, imu (or gas, gas variants) is older [s]'),
    ('gas_threshold', _DEFAULTS.gas_threshold, 'raw 10-bit gas reading that means scent'),
    ('scent_window_s', _DEFAULTS.scent_window_s, 'scent counts at a corner for this long [s]'),
    ('revisit_flip_count', _DEFAULTS.revisit_flip_count, 'revisits before the 180 deg flip'),
    (
        'visit_count_resets_on_fresh_corner',
        _DEFAULTS.visit_count_resets_on_fresh_corner,
        'an unscented outer corner resets the revisit count (count revisits in a row)',
    ),
    (
        'inner_corner_resumes_following',
        _DEFAULTS.inner_corner_resumes_following,
        'an inner corner after a revisit returns to Following Wall (paper Fig. 3)',
    ),
    (
        'wall_end_face_m',
        _DEFAULTS.wall_end_face_m,
        'an outer corner this soon after a wrap is the same wall end: keep wrapping [m]',
    ),
    ('fixed_turn', _DEFAULTS.fixed_turn.value, 'left or right: turn at a wall without sound'),
    (
        'robot_hit_turn',
        _DEFAULTS.robot_hit_turn.value,
        'left or right: 90 deg turn after hitting another robot (paper: right)',
    ),
    (
        'robot_hit_repeat_s',
        _DEFAULTS.robot_hit_repeat_s,
        'a robot hit this soon after the previous one turns to a random heading [s]',
    ),
    (
        'sound_turn_rule',
        _DEFAULTS.sound_turn_rule.value,
        'wall side from the sound: away (towards theta_opp, paper) or toward the peers',
    ),
    (
        'sound_wall_side',
        _DEFAULTS.sound_wall_side.value,
        'Sound variant: wall contacts whose side the sound picks: every_contact (paper), '
        'first_contact or never (fixed_turn)',
    ),
    (
        'gas_sound_wall_side',
        _DEFAULTS.gas_sound_wall_side.value,
        'Gas+Sound: the same; first_contact (the paper discussion), every_contact '
        '(Table I) or never',
    ),
    (
        'sound_side_deadband_deg',
        math.degrees(_DEFAULTS.sound_side_deadband_rad),
        'Sound variant: theta_opp this close to straight ahead or behind picks no side, '
        'fixed_turn is taken (paper: 0) [deg]',
    ),
    (
        'gas_sound_side_deadband_deg',
        math.degrees(_DEFAULTS.gas_sound_side_deadband_rad),
        'Gas+Sound: the same [deg]',
    ),
    ('sound_weighting', _DEFAULTS.sound_weighting.value, 'distance (paper) or unit'),
    (
        'sound_memory',
        _DEFAULTS.sound_memory.value,
        "once (authors' simulator) or stored (paper wording)",
    ),
    (
        'sound_updates_at_corner',
        _DEFAULTS.sound_updates_at_corner,
        'Sound variant updates phi from the bearings at outer corners (paper)',
    ),
    ('pump_on_s', _DEFAULTS.pump_on_s, 'pump burst length [s]'),
    ('pump_period_s', _DEFAULTS.pump_period_s, 'time between pump bursts [s]'),
    (
        'pump_min_speed_mps',
        _DEFAULTS.pump_min_speed_mps,
        'a burst starts only at this forward speed or faster (0: plain clock) [m/s]',
    ),
    ('bearing_timeout_s', _DEFAULTS.bearing_timeout_s, 'bearings older than this are unused [s]'),
    ('own_tag_id', '', 'own AoA tag id, ignored in the bearings ("" keeps all)'),
    ('seed', -1, 'seed of the Random variant; -1 uses robot_index'),
    ('robot_radius_m', _PERCEPTION.robot_radius_m, 'robot body radius [m]'),
    ('wall_hit_distance_m', _PERCEPTION.wall_hit_distance_m, 'wall this close ahead is hit [m]'),
    (
        'robot_hit_distance_m',
        _PERCEPTION.robot_hit_distance_m,
        'peer this close in the front cone is hit [m]',
    ),
    ('lidar_yaw_offset_deg', 0.0, 'yaw of the lidar zero ray in the robot frame [deg]'),
    ('forward_speed_mps', _MOTION.forward_speed_mps, 'cruise speed [m/s]'),
    ('turn_rate_radps', _MOTION.turn_rate_radps, 'largest yaw rate [rad/s]'),
    ('wall_distance_m', _MOTION.wall_distance_m, 'distance kept from the followed wall [m]'),
    ('random_step_m', _MOTION.random_step_m, 'Random variant: distance per random draw [m]'),
)


def _parse(enum_type: Any, name: str, text: str) -> Any:
    try:
        return enum_type(text.strip().lower())
    except ValueError:
        choices = ', '.join(e.value for e in enum_type)
        msg = f'parameter {name}={text!r} is not one of {choices}'
        raise ConfigError(msg) from None


def config_from_parameters(values: dict[str, Any]) -> OABugConfig:
    """Build the controller configuration from the node's parameter values.

    Raises:
        ConfigError: a value is unknown or out of range.
    """
    seed = int(values['seed'])
    perception = PerceptionConfig(
        robot_radius_m=float(values['robot_radius_m']),
        wall_hit_distance_m=float(values['wall_hit_distance_m']),
        robot_hit_distance_m=float(values['robot_hit_distance_m']),
        lidar_yaw_offset_rad=math.radians(float(values['lidar_yaw_offset_deg'])),
    )
    motion = MotionConfig(
        forward_speed_mps=float(values['forward_speed_mps']),
        turn_rate_radps=float(values['turn_rate_radps']),
        min_turn_rate_radps=min(_MOTION.min_turn_rate_radps, float(values['turn_rate_radps'])),
        wall_distance_m=float(values['wall_distance_m']),
        random_step_m=float(values['random_step_m']),
    )
    return OABugConfig(
        variant=Variant.parse(str(values['variant'])),
        robot_index=int(values['robot_index']),
        robot_count=int(values['robot_count']),
        departure=Departure.parse(str(values['departure'])),
        heading_bias_rad=math.radians(float(values['heading_bias_deg'])),
        gas_threshold=int(values['gas_threshold']),
        scent_window_s=float(values['scent_window_s']),
        revisit_flip_count=int(values['revisit_flip_count']),
        visit_count_resets_on_fresh_corner=bool(values['visit_count_resets_on_fresh_corner']),
        inner_corner_resumes_following=bool(values['inner_corner_resumes_following']),
        wall_end_face_m=float(values['wall_end_face_m']),
        fixed_turn=_parse(TurnDirection, 'fixed_turn', str(values['fixed_turn'])),
        robot_hit_turn=_parse(TurnDirection, 'robot_hit_turn', str(values['robot_hit_turn'])),
        robot_hit_repeat_s=float(values['robot_hit_repeat_s']),
        sound_turn_rule=_parse(SoundTurnRule, 'sound_turn_rule', str(values['sound_turn_rule'])),
        sound_wall_side=_parse(SoundWallSide, 'sound_wall_side', str(values['sound_wall_side'])),
        gas_sound_wall_side=_parse(
            SoundWallSide, 'gas_sound_wall_side', str(values['gas_sound_wall_side'])
        ),
        sound_side_deadband_rad=math.radians(float(values['sound_side_deadband_deg'])),
        gas_sound_side_deadband_rad=math.radians(float(values['gas_sound_side_deadband_deg'])),
        sound_weighting=_parse(SoundWeighting, 'sound_weighting', str(values['sound_weighting'])),
        sound_memory=_parse(SoundMemory, 'sound_memory', str(values['sound_memory'])),
        sound_updates_at_corner=bool(values['sound_updates_at_corner']),
        pump_on_s=float(values['pump_on_s']),
        pump_period_s=float(values['pump_period_s']),
        pump_min_speed_mps=float(values['pump_min_speed_mps']),
        bearing_timeout_s=float(values['bearing_timeout_s']),
        seed=seed if seed >= 0 else int(values['robot_index']),
        perception=perception,
        motion=motion,
    )


class OABugNode(Node):
    """One OA-Bug robot: reads its sensor topics, drives cmd_vel and the pump."""

    def __init__(self, node_name: str = 'oabug', **kwargs: Any) -> None:
        super().__init__(node_name, **kwargs)
        values = {}
        for name, default, description in PARAMETERS:
            descriptor = rcl_interfaces.ParameterDescriptor(description=description, read_only=True)
            values[name] = self.declare_parameter(name, default, descriptor).value
        try:
            self._config = config_from_parameters(values)
            rate_hz = float(values['control_rate_hz'])
            self._stale_timeout_s = float(values['stale_timeout_s'])
            if not (math.isfinite(rate_hz) and rate_hz > 0.0):
                raise ConfigError(f'control_rate_hz must be > 0, got {rate_hz}')
            if not (math.isfinite(self._stale_timeout_s) and self._stale_timeout_s > 0.0):
                raise ConfigError(f'stale_timeout_s must be > 0, got {self._stale_timeout_s}')
            state_rate_hz = float(values['state_rate_hz'])
            if not (math.isfinite(state_rate_hz) and state_rate_hz > 0.0):
                raise ConfigError(f'state_rate_hz must be > 0, got {state_rate_hz}')
            self._state_period_s = 1.0 / state_rate_hz
        except ConfigError as err:
            self.get_logger().fatal(f'invalid configuration: {err}')
            raise
        self._own_tag_id = str(values['own_tag_id'])
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
        self._timer = self.create_timer(1.0 / rate_hz, self._on_control)
        self.get_logger().info(
            f'OA-Bug {self._config.variant.value}: robot {self._config.robot_index} of '
            f'{self._config.robot_count}, {self._config.departure.value} departure, '
            f'preferred direction {math.degrees(self._fsm.memory.preferred_direction_rad):.1f} deg'
        )

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
        OABugNode, args, name='oabug', fatal_errors=(ConfigError,), describe_fatal=lambda _: None
    )


if __name__ == '__main__':
    raise SystemExit(main())
