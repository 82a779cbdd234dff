"""Per-robot source-seeking node: Bayes-Swarm-P/-O, Glowworm, Levy walk or exhaustive sweep.

Topics (relative to the robot's namespace, e.g. /r3):

* in: ``odom`` (nav_msgs/Odometry, sensor QoS), ``signal`` (swarm_interfaces/SignalSample,
  sensor QoS), ``peers/in`` (BayesSwarmPeer, or GlowwormPeer for glowworm);
* out: ``cmd_vel`` (geometry_msgs/Twist), ``peers/out`` (same type as peers/in), ``state``
  (swarm_interfaces/BayesSwarmState after every waypoint decision).

A control timer drives the waypoint follower; on arrival the algorithm takes its next
decision and broadcasts it. Each signal sample is paired with the latest odometry pose. When
odometry is older than ``odom_timeout_s`` the node commands zero velocity.

Run: ``ros2 run bayes_swarm bayes_swarm_node --ros-args -r __ns:=/r0 -p robot_index:=0
--params-file config/case1.yaml``. Without a relay, remap both peer topics to one shared topic.
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

from bayes_swarm import conversions
from bayes_swarm.baselines.exhaustive import partition_arena, strip_sweep
from bayes_swarm.baselines.glowworm import GlowwormAgent
from bayes_swarm.baselines.levy import LevyWalk
from bayes_swarm.errors import BayesSwarmError
from bayes_swarm.follower import WaypointFollower
from bayes_swarm.messages import Decision, DecisionKind
from bayes_swarm.node_settings import BAYES_SWARM_PARAMETERS, NODE_NAME, NodeSettings
from bayes_swarm.planner import BayesSwarmPlanner, first_waypoint

__all__ = ['BayesSwarmNode', 'main']

_nav = message_module('nav_msgs')
_geometry = message_module('geometry_msgs')
_swarm = message_module('swarm_interfaces')


class BayesSwarmNode(Node):
    """One robot running a source-seeking algorithm of the Bayes-Swarm-P study."""

    def __init__(self, **node_kwargs: Any) -> None:
        super().__init__(NODE_NAME, **node_kwargs)
        self._declared = declare_config(self, BAYES_SWARM_PARAMETERS, on_change=self._configure)
        self._configure(self._declared.config)
        s = self.settings
        namespace = self.get_namespace().strip('/')
        self.robot_name = namespace.split('/')[-1] if namespace else f'r{s.planner.robot_index}'
        self._pose: tuple[float, float, float] | None = None
        self._pose_time_s = -math.inf
        self._waypoint: np.ndarray | None = None
        self._start_time_s: float | None = None
        self._last_signal: float | None = None
        self._rejected_samples = 0
        self._decisions = 0
        self.decisions: list[Decision] = []

        self._planner: BayesSwarmPlanner | None = None
        self._levy: LevyWalk | None = None
        self._sweep: list[np.ndarray] = []
        self._glow: GlowwormAgent | None = None
        self._glow_peers: dict[str, tuple[int, np.ndarray, float]] = {}
        peer_type = None
        if s.algorithm in ('bayes_swarm_p', 'bayes_swarm_o'):
            self._planner = BayesSwarmPlanner(
                s.planner,
                self.robot_name,
                seed=s.seed,
                fan_index=s.fan_index,
                fan_size=s.fan_size,
                direction_offset_deg=s.initial_direction_offset_deg,
            )
            peer_type = _swarm.BayesSwarmPeer
        elif s.algorithm == 'levy':
            self._levy = LevyWalk(s.levy, s.planner.arena, seed=s.seed)
        elif s.algorithm == 'glowworm':
            self._glow = GlowwormAgent(
                s.glowworm, s.planner.arena, s.planner.velocity_mps, seed=s.seed
            )
            peer_type = _swarm.GlowwormPeer

        self._cmd_pub = self.create_publisher(_geometry.Twist, 'cmd_vel', 10)
        self._state_pub = self.create_publisher(_swarm.BayesSwarmState, 'state', 10)
        self._peer_pub = None
        if peer_type is not None:
            self._peer_pub = self.create_publisher(peer_type, 'peers/out', 10)
            self.create_subscription(peer_type, 'peers/in', self._on_peer, 10)
        self.create_subscription(_nav.Odometry, 'odom', self._on_odom, qos_profile_sensor_data)
        self.create_subscription(
            _swarm.SignalSample, 'signal', self._on_signal, qos_profile_sensor_data
        )
        self.create_timer(1.0 / s.control_rate_hz, self._on_control)
        if self._glow is not None:
            self.create_timer(1.0 / s.glowworm.decision_rate_hz, self._on_glowworm)
        self.get_logger().info(
            f'{s.algorithm} robot {self.robot_name} ({s.planner.robot_index + 1} of '
            f'{s.planner.n_robots}), V {s.planner.velocity_mps:g} m/s, T {s.planner.horizon_s:g} s'
        )

    def _configure(self, settings: NodeSettings) -> None:
        """Take the settings (at start, and the follower's after an accepted change)."""
        self.settings = settings
        self._follower_config = settings.follower
        self._follower = WaypointFollower(self._follower_config)

    @property
    def planner(self) -> BayesSwarmPlanner | None:
        """The Bayes-Swarm planner (None for the baselines)."""
        return self._planner

    # ----------------------------------------------------------------- inputs
    def _now_s(self) -> float:
        return self.get_clock().now().nanoseconds * 1e-9

    def _on_odom(self, msg: Any) -> None:
        pose = conversions.odometry_to_pose(msg)
        if all(math.isfinite(v) for v in pose):
            self._pose = pose
            self._pose_time_s = self._now_s()

    def _on_signal(self, msg: Any) -> None:
        value = float(msg.value)
        if not math.isfinite(value) or self._pose is None:
            self._rejected_samples += 1
            self.get_logger().warning(
                f'dropped signal sample {value!r} '
                f'({"no pose yet" if self._pose is None else "not finite"}; '
                f'{self._rejected_samples} dropped so far)',
                throttle_duration_sec=5.0,
            )
            return
        self._last_signal = value
        if self._planner is not None:
            point = np.array([[self._pose[0], self._pose[1]]])
            self._planner.add_observations(point, np.array([value]))

    def _on_peer(self, msg: Any) -> None:
        if self._planner is not None:
            try:
                update = conversions.peer_update_from_ros(msg)
            except BayesSwarmError as err:
                self.get_logger().warning(f'ignored peer message: {err}')
                return
            self._planner.receive(update)
        elif self._glow is not None:
            sender, index, position, luciferin = conversions.glowworm_peer_from_ros(msg)
            known = self._glow_peers.get(sender)
            if sender != self.robot_name and (known is None or index > known[0]):
                self._glow_peers[sender] = (index, position, luciferin)

    # ---------------------------------------------------------------- control
    def _on_control(self) -> None:
        now = self._now_s()
        if self._pose is None or now - self._pose_time_s > self.settings.odom_timeout_s:
            self._cmd_pub.publish(conversions.twist(0.0, 0.0))
            return
        x, y, yaw = self._pose
        if self._waypoint is None:
            self._start_time_s = now
            self._decide(now)
        cmd = self._follower.command(x, y, yaw, *self._waypoint)
        if cmd.arrived and not self._glowworm_phase():
            self._decide(now)
            cmd = self._follower.command(x, y, yaw, *self._waypoint)
        self._cmd_pub.publish(conversions.twist(cmd.linear_mps, cmd.angular_radps))

    def _glowworm_phase(self) -> bool:
        return self._glow is not None and self._decisions > 0

    def _decide(self, now: float) -> None:
        s = self.settings
        position = np.array(self._pose[:2])
        mission_time = now - (self._start_time_s or now)
        if self._planner is not None:
            decision = self._planner.decide(position, mission_time)
            if decision.kind is DecisionKind.FALLBACK:
                self.get_logger().warning(f'decision {decision.decision_index}: {decision.detail}')
            update = self._planner.broadcast(position)
            self._peer_pub.publish(conversions.peer_update_to_ros(update, now))
        elif self._levy is not None:
            waypoint = self._levy.next_waypoint(position, self._last_signal)
            decision = Decision(waypoint, self._decisions, DecisionKind.RANDOM_JUMP)
        elif s.algorithm == 'exhaustive':
            if self._decisions == 0:
                strip = partition_arena(
                    s.planner.arena, s.planner.n_robots, s.exhaustive.partition
                )[s.planner.robot_index]
                spacing = s.exhaustive.spacing_m(s.planner.detection_radius_m)
                self._sweep = list(strip_sweep(strip, spacing, position))
            waypoint = self._sweep.pop(0) if self._sweep else position
            decision = Decision(waypoint, self._decisions, DecisionKind.ACQUISITION)
        else:
            waypoint = s.planner.arena.clip(
                first_waypoint(
                    position,
                    fan_index=s.fan_index or s.planner.robot_index + 1,
                    fan_size=s.fan_size or s.planner.n_robots,
                    direction_range_deg=s.planner.initial_direction_range_deg,
                    direction_offset_deg=s.initial_direction_offset_deg,
                    leg_m=s.planner.max_leg_m,
                )
            )
            decision = Decision(waypoint, 0, DecisionKind.FIRST)
        self._decisions += 1
        self._waypoint = np.asarray(decision.waypoint_m, dtype=float)
        self.decisions.append(decision)
        self._state_pub.publish(
            conversions.decision_to_state(self.robot_name, s.algorithm, position, decision, now)
        )

    def _on_glowworm(self) -> None:
        s = self.settings
        if self._glow is None or self._pose is None or self._waypoint is None:
            return
        position = np.array(self._pose[:2])
        if self._decisions == 1 and np.hypot(*(self._waypoint - position)) > (
            self._follower_config.arrival_tolerance_m
        ):
            return  # still on the first dispersal leg
        if self._last_signal is None:
            return
        luciferin = self._glow.update_luciferin(self._last_signal)
        now = self._now_s()
        self._peer_pub.publish(
            conversions.glowworm_peer_to_ros(
                self.robot_name, self._decisions, position, luciferin, now
            )
        )
        peers = list(self._glow_peers.values())
        positions = np.array([p[1] for p in peers]).reshape(-1, 2)
        lucs = np.array([p[2] for p in peers])
        target = self._glow.next_waypoint(position, positions, lucs)
        step = target - position
        length = float(np.hypot(*step))
        if length <= 0.0:
            self._waypoint = position  # no brighter neighbour: stay
        else:
            # A GSO step (mm at 100 Hz) is below the follower's arrival tolerance: steer toward
            # a point a few control periods ahead on the same heading, so the robot moves at V.
            follower = self._follower_config
            lookahead = max(
                2.0 * follower.arrival_tolerance_m,
                2.0 * follower.speed_mps / self.settings.control_rate_hz,
            )
            self._waypoint = s.planner.arena.clip(position + step * (lookahead / length))
        self._decisions += 1


def main(args: list[str] | None = None) -> int:
    """Entry point of ``ros2 run bayes_swarm bayes_swarm_node``."""
    return run_node(
        BayesSwarmNode,
        args,
        name=NODE_NAME,
        fatal_errors=(BayesSwarmError,),
        parameters=BAYES_SWARM_PARAMETERS,
    )


if __name__ == '__main__':
    raise SystemExit(main())
