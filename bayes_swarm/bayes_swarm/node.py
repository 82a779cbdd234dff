"""Per-robot source-seeking node: Bayes-Swarm-P/-O, Glowworm, Levy walk or exhaustive sweep.

Topics (relative to the robot's namespace, e.g. /r3):

* in: ``odom`` (nav_msgs/Odometry, sensor QoS), ``signal`` (swarm_interfaces/SignalSample,
  sensor QoS), ``peers/in`` (BayesSwarmPeer, or GlowwormPeer for glowworm);
* out: ``cmd_vel`` (geometry_msgs/Twist), ``peers/out`` (same type as peers/in), ``state``
  (swarm_interfaces/BayesSwarmState after every waypoint decision).

A control timer ticks the robot's loop (:class:`bayes_swarm.controller.RobotController`,
shared with the batch runner): the waypoint follower, and on arrival the algorithm's next
decision and its broadcast. Each signal sample is paired with the latest odometry pose. When
odometry is older than ``odom_timeout_s`` the node commands zero velocity. Malformed input
(odometry without an orientation, a peer message with absurd contents) is dropped, counted and
logged (throttled); the rules are the conversions' and the controller's/planner's.

Run: ``ros2 run bayes_swarm bayes_swarm_node --ros-args -r __ns:=/r0 -p robot_index:=0
--params-file config/case1.yaml``. Without a relay, remap both peer topics to one shared topic.
"""

from __future__ import annotations

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
from bayes_swarm.controller import RobotController
from bayes_swarm.errors import BayesSwarmError
from bayes_swarm.messages import Decision, DecisionKind, PeerUpdate
from bayes_swarm.node_settings import BAYES_SWARM_PARAMETERS, NODE_NAME, NodeSettings
from bayes_swarm.planner import BayesSwarmPlanner

__all__ = ['BayesSwarmNode', 'main']

_nav = message_module('nav_msgs')
_geometry = message_module('geometry_msgs')
_swarm = message_module('swarm_interfaces')


class BayesSwarmNode(Node):
    """One robot running a source-seeking algorithm of the Bayes-Swarm-P study.

    The loop itself is :class:`~bayes_swarm.controller.RobotController`; this node converts
    messages to its calls and its outputs to messages.
    """

    def __init__(self, **node_kwargs: Any) -> None:
        super().__init__(NODE_NAME, **node_kwargs)
        self._declared = declare_config(self, BAYES_SWARM_PARAMETERS, on_change=self._configure)
        s: NodeSettings = self._declared.config
        namespace = self.get_namespace().strip('/')
        self.robot_name = namespace.split('/')[-1] if namespace else f'r{s.planner.robot_index}'
        self.controller = RobotController(s, self.robot_name)
        self.rejected_odometry = 0
        self.rejected_peer_messages = 0
        peers = self.controller.uses_peers
        peer_type = {'bayes': _swarm.BayesSwarmPeer, 'glowworm': _swarm.GlowwormPeer}.get(
            peers or ''
        )
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
        if peers == 'glowworm':
            self.create_timer(1.0 / s.glowworm.decision_rate_hz, self._on_glowworm)
        self.get_logger().info(
            f'{s.algorithm} robot {self.robot_name} ({s.planner.robot_index + 1} of '
            f'{s.planner.n_robots}), V {s.planner.velocity_mps:g} m/s, T {s.planner.horizon_s:g} s'
        )

    def _configure(self, settings: NodeSettings) -> None:
        """Take an accepted parameter change (the follower's)."""
        self.controller.configure(settings)

    @property
    def settings(self) -> NodeSettings:
        """The node's validated settings."""
        return self.controller.settings

    @property
    def planner(self) -> BayesSwarmPlanner | None:
        """The Bayes-Swarm planner (None for the baselines)."""
        return self.controller.planner

    @property
    def decisions(self) -> list[Decision]:
        """Every waypoint decision taken so far, in order."""
        return self.controller.decisions

    # ----------------------------------------------------------------- inputs
    def _now_s(self) -> float:
        return self.get_clock().now().nanoseconds * 1e-9

    def _on_odom(self, msg: Any) -> None:
        try:
            reason = ''
            if self.controller.on_pose(conversions.odometry_to_pose(msg), self._now_s()):
                return
        except BayesSwarmError as err:
            reason = str(err)
        self.rejected_odometry += 1
        self.get_logger().warning(
            f'dropped odometry ({reason or "position or yaw not finite"}; '
            f'{self.rejected_odometry} dropped so far)',
            throttle_duration_sec=5.0,
        )

    def _on_signal(self, msg: Any) -> None:
        value = float(msg.value)
        reason = self.controller.on_signal(value)
        if reason:
            self.get_logger().warning(
                f'dropped signal sample {value!r} ({reason}; '
                f'{self.controller.rejected_samples} dropped so far)',
                throttle_duration_sec=5.0,
            )

    def _on_peer(self, msg: Any) -> None:
        if self.controller.uses_peers == 'bayes':
            try:
                update = conversions.peer_update_from_ros(msg)
            except BayesSwarmError as err:
                reason = str(err)
            else:
                planner = self.controller.planner
                if self.controller.on_peer(update) or planner is None:
                    return
                reason = planner.peer_update_defect(update)
                if not reason:
                    return  # own, stale or duplicated: ignored silently
            self.rejected_peer_messages += 1
            self.get_logger().warning(
                f'ignored peer message: {reason} ({self.rejected_peer_messages} so far)',
                throttle_duration_sec=5.0,
            )
        else:
            self.controller.on_glowworm_peer(*conversions.glowworm_peer_from_ros(msg))

    # ---------------------------------------------------------------- control
    def _on_control(self) -> None:
        now = self._now_s()
        out = self.controller.control(now)
        if out.decision is not None:
            self._publish_decision(out.decision, out.broadcast, now)
        self._cmd_pub.publish(conversions.twist(out.linear_mps, out.angular_radps))

    def _publish_decision(
        self, decision: Decision, broadcast: PeerUpdate | None, now: float
    ) -> None:
        if decision.kind is DecisionKind.FALLBACK:
            self.get_logger().warning(f'decision {decision.decision_index}: {decision.detail}')
        if broadcast is not None and self._peer_pub is not None:
            self._peer_pub.publish(conversions.peer_update_to_ros(broadcast, now))
        position = np.array(self.controller.pose_m)
        self._state_pub.publish(
            conversions.decision_to_state(
                self.robot_name, self.settings.algorithm, position, decision, now
            )
        )

    def _on_glowworm(self) -> None:
        """One Glowworm iteration: broadcast the new luciferin, then pick a leader."""
        if self._broadcast_glowworm():
            self.controller.glowworm_move()

    def _broadcast_glowworm(self) -> bool:
        """The iteration's first half and its GlowwormPeer; False if the robot did not iterate."""
        out = self.controller.glowworm_broadcast()
        if out is None:
            return False
        if self._peer_pub is not None:
            self._peer_pub.publish(
                conversions.glowworm_peer_to_ros(
                    self.robot_name, out.index, out.position_m, out.luciferin, self._now_s()
                )
            )
        return True


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
