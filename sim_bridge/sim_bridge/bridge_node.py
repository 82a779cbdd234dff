"""The sim bridge node: publishes every robot's sensor topics from the simulated world.

Per robot ``<name>`` (r0, r1, ...) it publishes ``/<name>/scan``, ``gas``, ``bearings``,
``imu`` and ``odom`` (sensor-data QoS; only the sensors of the engine configuration's
``sensors``, all by default) and subscribes ``/<name>/cmd_vel`` and ``pump``;
swarm-wide it publishes ``/clock`` and the ground truth ``/sim/poses``, ``/sim/coverage``
(and ``/sim/site`` when the site model can be converted). With ``peer_msg_type`` set it
relays ``/<name>/peers/out`` to the other robots' ``peers/in`` within ``comm_range_m``.
For viewers it publishes the REP 105 transform tree on ``/tf`` and ``/tf_static`` and the
site, rooms, robots and paths as ``/sim/markers/...`` (:mod:`sim_bridge.visualization`).

The node holds no simulation logic: :class:`swarm_sim.engine.SimEngine` does the work and
:mod:`sim_bridge.conversions` builds the messages. It steps the engine on a wall timer of one
physics period divided by ``real_time_factor``; in the built-in runtime that timer runs on a
virtual clock, so a headless simulation goes as fast as the machine allows.

Standalone: ``ros2 run sim_bridge sim_bridge --ros-args -p site_file:=site.yaml
-p robot_count:=6 -p departure:=center``, or with ``-p mission_file:=mission.json`` (site,
start poses, sensors and extensions: :mod:`sim_bridge.mission_file`), as the spawners'
``--processes`` mode starts it; the mission runner (:mod:`swarm_experiments.mission`)
builds it in-process with a site object and start poses instead. With ``max_sim_time_s``,
``stop_when_all_rooms_covered`` or ``outcome_file`` set, the bridge ends the mission itself:
it stops stepping, writes the outcome file and exits 0.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Callable, Sequence
from typing import Any

import numpy as np
from swarm_runtime.node_main import run_node
from swarm_runtime.parameters import declare_config
from swarm_runtime.ros import (
    Node,
    QoSDurabilityPolicy,
    QoSProfile,
    message_module,
    qos_profile_sensor_data,
)
from swarm_sim.departure import place_starts
from swarm_sim.engine import EngineConfig, SimEngine, SiteGeometry, StepOutput
from swarm_sim.errors import ConfigurationError, SimulationError
from swarm_sim.mission_rules import TrajectorySampler, end_reason
from swarm_sim.peer_relay import RelayConfig, RelayModel, parse_message_type
from swarm_sim.site_geometry import geometry_from_site

from sim_bridge import conversions
from sim_bridge.bridge_parameters import BRIDGE_PARAMETERS, NODE_NAME, BridgeNodeConfig
from sim_bridge.extensions import RobotStates, SimExtension
from sim_bridge.mission_file import extension_outcome, load_mission, write_outcome
from sim_bridge.visualization import BridgeVisualization

__all__ = ['SimBridgeNode', 'main']

_geometry = message_module('geometry_msgs')
_std = message_module('std_msgs')
_sensor = message_module('sensor_msgs')
_nav = message_module('nav_msgs')
_rosgraph = message_module('rosgraph_msgs')
_swarm = message_module('swarm_interfaces')

_LATCHED = QoSProfile(depth=1, durability=QoSDurabilityPolicy.TRANSIENT_LOCAL)


class SimBridgeNode(Node):
    """Simulated world of N robots behind the robots' own topic contract."""

    def __init__(
        self,
        *,
        site: Any = None,
        initial_poses: np.ndarray | None = None,
        engine_config: EngineConfig | None = None,
        extensions: Sequence[SimExtension] = (),
        **node_kwargs: Any,
    ) -> None:
        """Build the bridge.

        Args:
            site: a :class:`swarm_sim.sites.model.Site` or a :class:`SiteGeometry`; None
                loads the ``site_file`` parameter.
            initial_poses: (N, 3) start poses; None places ``robot_count`` robots on the
                ``departure`` fan of the site.
            engine_config: defaults of the engine parameters (parameter overrides win).
            extensions: mission-specific world parts, attached in order.
            node_kwargs: passed to rclpy's Node (namespace, parameter_overrides, ...).
        """
        super().__init__(NODE_NAME, **node_kwargs)
        base = BridgeNodeConfig(engine=engine_config or EngineConfig())
        self._declared = declare_config(self, BRIDGE_PARAMETERS, base=base, on_change=self._retime)
        self.settings: BridgeNodeConfig = self._declared.config
        self.config = self.settings.engine
        if site is None and self.settings.mission_file:
            mission = load_mission(self.settings.mission_file, site_seed=self.config.seed)
            site = mission.site
            if initial_poses is None:
                initial_poses = mission.initial_poses
            if not extensions:
                extensions = mission.extensions
            if mission.sensors is not None:
                self.config = dataclasses.replace(self.config, sensors=mission.sensors)
        self._site_model = site if site is not None and not isinstance(site, SiteGeometry) else None
        geometry = self._resolve_site(site)
        poses = self._resolve_poses(initial_poses)
        self.engine = SimEngine(geometry, poses, self.config)
        n = self.engine.num_robots
        self.robot_names: tuple[str, ...] = tuple(f'r{i}' for i in range(n))
        self.step_listeners: list[Callable[[StepOutput], None]] = []

        self._clock_pub = self.create_publisher(_rosgraph.Clock, '/clock', 10)
        self._poses_pub = self.create_publisher(_swarm.TruePoseArray, '/sim/poses', 10)
        self._coverage_pub = self.create_publisher(_swarm.Coverage, '/sim/coverage', _LATCHED)
        sensor_qos = qos_profile_sensor_data
        sensors = self.engine.sensors
        # Per robot, a publisher of each sensor the mission runs (None: not simulated).
        self._scan_pubs: list[Any] = []
        self._gas_pubs: list[Any] = []
        self._bearing_pubs: list[Any] = []
        self._imu_pubs: list[Any] = []
        self._odom_pubs: list[Any] = []
        topics = (
            ('scan', self._scan_pubs, _sensor.LaserScan),
            ('gas', self._gas_pubs, _swarm.GasReading),
            ('bearings', self._bearing_pubs, _swarm.PeerBearingArray),
            ('imu', self._imu_pubs, _sensor.Imu),
            ('odometry', self._odom_pubs, _nav.Odometry),
        )
        for i, name in enumerate(self.robot_names):
            for sensor, pubs, msg_type in topics:
                topic = f'/{name}/{"odom" if sensor == "odometry" else sensor}'
                pubs.append(
                    self.create_publisher(msg_type, topic, sensor_qos)
                    if sensor in sensors
                    else None
                )
            self.create_subscription(
                _geometry.Twist, f'/{name}/cmd_vel', self._make_cmd_callback(i), 10
            )
            self.create_subscription(_std.Bool, f'/{name}/pump', self._make_pump_callback(i), 10)
        self._publish_site()
        self._relay = self._setup_relay()
        self._visualization = self._setup_visualization()

        self.extensions = tuple(extensions)
        for ext in self.extensions:
            ext.attach(self, self.robot_names)

        coverage_rate = self.settings.coverage_rate_hz
        self._coverage_every = max(1, round(self.config.physics_rate_hz / coverage_rate))
        self._stop_reason = ''
        # The bridge ends a mission itself only when asked to (the in-process runner ends it).
        self._ends_mission = bool(
            self.settings.outcome_file
            or self.settings.stop_when_all_rooms_covered
            or math.isfinite(self.settings.max_sim_time_s)
        )
        self._outcome_written = False
        self._trajectory = TrajectorySampler.starting_at(
            self.engine.world.poses, self.settings.trajectory_period_s
        )
        self._timer: Any = None
        self._grace_until_ns: int | None = None
        if self.settings.start_after_clock_subscribers > 0:
            self._wait_timer: Any = self.create_timer(0.05, self._wait_for_subscribers)
        else:
            self._start_physics()
        self._publish_coverage()
        self.get_logger().info(
            f'simulating {n} robots in {geometry.name!r} '
            f'({len(self.engine.world.walls)} walls, {self.engine.coverage.rooms_total} rooms), '
            f'{self.config.physics} physics at {self.config.physics_rate_hz:g} Hz, '
            f'seed {self.config.seed}'
        )

    def _retime(self, settings: BridgeNodeConfig) -> None:
        """Apply an accepted parameter change (only ``real_time_factor`` may change)."""
        self.settings = settings
        if self._timer is not None:
            period_s = self.config.physics_period_s / settings.real_time_factor
            self._timer.timer_period_ns = round(period_s * 1e9)

    def _start_physics(self) -> None:
        rtf = self.settings.real_time_factor
        self._timer = self.create_timer(self.config.physics_period_s / rtf, self._on_tick)

    def _wait_for_subscribers(self) -> None:
        """Before the first step: wait for ``start_after_clock_subscribers`` subscribers of
        /clock, then one more wall second for their other topics to match."""
        now_ns = self.get_clock().now().nanoseconds
        if self._grace_until_ns is None:
            wanted = self.settings.start_after_clock_subscribers
            if self._clock_pub.get_subscription_count() < wanted:
                return
            self._grace_until_ns = now_ns + 1_000_000_000
            return
        if now_ns < self._grace_until_ns:
            return
        self._wait_timer.cancel()
        self.get_logger().info('every expected node is up: the simulation starts')
        self._start_physics()

    # Set-up helpers -------------------------------------------------------------------

    def _resolve_site(self, site: Any) -> SiteGeometry:
        if isinstance(site, SiteGeometry):
            return site
        if site is None:
            path = self.settings.site_file
            if not path:
                raise ConfigurationError('no site given: set the site_file parameter')
            from swarm_sim.site_loading import load_site

            site = load_site(path, seed=self.config.seed)
            self._site_model = site
        for warning in getattr(site, 'warnings', ()):
            self.get_logger().warning(f'site: {warning}')
        return geometry_from_site(site)

    def _resolve_poses(self, initial_poses: np.ndarray | None) -> np.ndarray:
        if initial_poses is not None:
            return np.asarray(initial_poses, dtype=float)
        if self._site_model is None:
            raise ConfigurationError('initial_poses are required when the site is a geometry')
        count = self.settings.robot_count
        name = self.settings.departure
        bias = self.settings.heading_bias_rad
        starts = place_starts(self._site_model, name, count, bias_rad=bias, body=self.config.body)
        if starts.moved:
            self.get_logger().info(
                f'{len(starts.moved)} of {count} starts moved off the nominal fan into free '
                f'space (at most {float(starts.moved_by_m.max()):.3f} m)'
            )
        return starts.poses

    def _publish_site(self) -> None:
        if self._site_model is None:
            return
        try:
            from sim_bridge.site_msgs import site_to_ros
        except ImportError:
            self.get_logger().warning('no Site message conversion available: /sim/site is off')
            return
        msg = site_to_ros(self._site_model)
        self._site_pub = self.create_publisher(type(msg), '/sim/site', _LATCHED)
        self._site_pub.publish(msg)

    def _setup_visualization(self) -> BridgeVisualization:
        return BridgeVisualization(
            self,
            self.engine,
            self.robot_names,
            self._site_model,
            tf_rate_hz=self.settings.tf_rate_hz,
            path_rate_hz=self.settings.path_rate_hz,
        )

    def _setup_relay(self) -> RelayModel | None:
        config = RelayConfig(
            msg_type=self.settings.peer_msg_type,
            comm_range_m=self.settings.comm_range_m,
            loss_probability=self.settings.peer_loss_probability,
        )
        if not config.enabled:
            return None
        package, name = parse_message_type(config.msg_type)
        try:
            msg_class = getattr(message_module(package), name)
        except (ImportError, AttributeError, LookupError) as err:
            msg = f'unknown peer message type {config.msg_type!r}'
            raise ConfigurationError(msg) from err
        # Injected link faults limit the relay further.
        relay = RelayModel.for_mission(config, self.config.seed, self.engine.fault_plan)
        self._peer_in_pubs = [
            self.create_publisher(msg_class, f'/{name}/peers/in', 10) for name in self.robot_names
        ]
        for i, robot in enumerate(self.robot_names):
            self.create_subscription(
                msg_class, f'/{robot}/peers/out', self._make_relay_callback(i), 10
            )
        return relay

    # Callbacks --------------------------------------------------------------------------

    def _make_cmd_callback(self, robot: int) -> Callable[[Any], None]:
        def on_cmd_vel(msg: Any) -> None:
            speed, yaw_rate = conversions.twist_from_ros(msg)
            if not (math.isfinite(speed) and math.isfinite(yaw_rate)):
                self.get_logger().warning(
                    f'{self.robot_names[robot]}: non-finite cmd_vel ignored, robot stops',
                    throttle_duration_sec=5.0,
                )
            self.engine.set_velocity_command(robot, speed, yaw_rate)

        return on_cmd_vel

    def _make_pump_callback(self, robot: int) -> Callable[[Any], None]:
        def on_pump(msg: Any) -> None:
            self.engine.set_pump(robot, bool(msg.data))

        return on_pump

    def _make_relay_callback(self, sender: int) -> Callable[[Any], None]:
        def on_peer_out(msg: Any) -> None:
            assert self._relay is not None
            plan = self.engine.fault_plan  # dropped robots neither send nor receive
            dropped = None if plan is None else plan.dropped(self.engine.time_s)
            if dropped is not None and dropped[sender]:
                return
            for receiver in self._relay.receivers(sender, self.engine.world.poses):
                if dropped is None or not dropped[receiver]:
                    self._peer_in_pubs[int(receiver)].publish(msg)

        return on_peer_out

    def _on_tick(self) -> None:
        out = self.engine.step()
        t = out.time_s
        self._clock_pub.publish(conversions.clock_to_ros(t))
        names = self.robot_names
        cfg = self.config
        # Messages are built only for topics somebody subscribes to (the engine still
        # computes every reading, so runs do not depend on who listens).
        if out.scans is not None:
            for i, name in enumerate(names):
                if self._scan_pubs[i].get_subscription_count() and out.published('scan', i):
                    msg = conversions.scan_to_ros(out.scans[i], t, f'{name}/laser', cfg.lidar)
                    self._scan_pubs[i].publish(msg)
        if out.gas_raw is not None:
            for i, name in enumerate(names):
                if self._gas_pubs[i].get_subscription_count() and out.published('gas', i):
                    self._gas_pubs[i].publish(
                        conversions.gas_to_ros(int(out.gas_raw[i]), t, f'{name}/gas_sensor')
                    )
        if out.bearings is not None:
            for i, name in enumerate(names):
                if self._bearing_pubs[i].get_subscription_count():
                    self._bearing_pubs[i].publish(
                        conversions.bearings_to_ros(out.bearings[i], names, t, f'{name}/base_link')
                    )
        if out.imu is not None:
            yaw, rate = out.imu
            yaw_variance = cfg.imu.yaw_variance_rad2(t)
            for i, name in enumerate(names):
                if self._imu_pubs[i].get_subscription_count() and out.published('imu', i):
                    self._imu_pubs[i].publish(
                        conversions.imu_to_ros(
                            float(yaw[i]), float(rate[i]), t, f'{name}/imu_link', yaw_variance
                        )
                    )
        if out.odometry is not None:
            poses, twists = out.odometry
            for i, name in enumerate(names):
                if self._odom_pubs[i].get_subscription_count():
                    self._odom_pubs[i].publish(
                        conversions.odometry_to_ros(
                            poses[i], twists[i], t, f'{name}/odom', f'{name}/base_link'
                        )
                    )
        self._visualization.on_step(out)
        if out.ground_truth_due:
            self._poses_pub.publish(conversions.true_poses_to_ros(names, out.poses, t))
        if out.new_room_entries or self.engine.step_index % self._coverage_every == 0:
            self._publish_coverage()
        if self.extensions:
            states = RobotStates(names, out.poses, self.engine.world.velocities)
            for ext in self.extensions:
                ext.on_step(t, states)
        for listener in self.step_listeners:
            listener(out)
        if self.settings.outcome_file:
            self._trajectory.offer(t, out.poses)
        reason = self._mission_end_reason() if self._ends_mission else ''
        if reason:
            self._end_mission(reason)

    def _mission_end_reason(self) -> str:
        """The stop reason once the mission's end condition holds ('' before)."""
        return end_reason(
            self.engine,
            stop_when_all_rooms_covered=self.settings.stop_when_all_rooms_covered,
            max_sim_time_s=self.settings.max_sim_time_s,
            extensions_done=self.extensions_done if self.extensions else None,
        )

    def _end_mission(self, reason: str) -> None:
        """Stop stepping, write the outcome file and shut the context down (exit 0)."""
        self.pause()
        self._stop_reason = reason
        self.write_outcome()
        self.get_logger().info(f'mission ended ({reason}) at sim time {self.engine.time_s:.2f} s')
        self.context.try_shutdown()

    def outcome(self) -> dict[str, Any]:
        """The mission's outcome so far as JSON values (see :mod:`sim_bridge.mission_file`)."""
        times = list(self._trajectory.times_s)
        poses = list(self._trajectory.poses)
        if times[-1] < self.engine.time_s:
            times.append(self.engine.time_s)
            poses.append(self.engine.world.poses)
        cov = self.engine.coverage
        return {
            'stop_reason': self._stop_reason or 'interrupted',
            'sim_time_s': float(self.engine.time_s),
            'robot_names': list(self.robot_names),
            'rooms_total': int(cov.rooms_total),
            'room_entries': [[e.room_index, e.robot_index, e.time_s] for e in cov.entries],
            'trajectory_times_s': [float(v) for v in times],
            'trajectories': np.stack(poses).tolist(),
            'distance_travelled_m': self.engine.distance_travelled_m.tolist(),
            'extensions': [extension_outcome(ext) for ext in self.extensions],
        }

    def write_outcome(self) -> None:
        """Write the outcome to ``outcome_file`` (once; nothing without one)."""
        if not self.settings.outcome_file or self._outcome_written:
            return
        self._outcome_written = True
        write_outcome(self.settings.outcome_file, self.outcome())

    def _publish_coverage(self) -> None:
        cov = self.engine.coverage
        self._coverage_pub.publish(
            conversions.coverage_to_ros(
                cov.rooms_total, cov.entries, self.robot_names, self.engine.time_s
            )
        )

    def destroy_node(self) -> None:
        """Release the engine's physics backend, then destroy the node."""
        engine = getattr(self, 'engine', None)
        if engine is not None:
            if hasattr(self, '_outcome_written'):
                self.write_outcome()  # a stop before the end: the outcome so far
            engine.close()
        super().destroy_node()

    def pause(self) -> None:
        """Stop stepping the world (the physics timer is cancelled); messages already
        published are still delivered."""
        if self._timer is not None:
            self._timer.cancel()

    @property
    def sim_time_s(self) -> float:
        """Sim time of the last physics step [s]."""
        return self.engine.time_s

    def extensions_done(self) -> bool:
        """True when some extension reports its mission's stop condition."""
        return any(ext.is_done() for ext in self.extensions)


def main(args: list[str] | None = None) -> int:
    """Entry point of ``ros2 run sim_bridge sim_bridge``."""
    return run_node(
        SimBridgeNode,
        args,
        name=NODE_NAME,
        fatal_errors=(SimulationError,),
        parameters=BRIDGE_PARAMETERS,
    )


if __name__ == '__main__':
    raise SystemExit(main())
