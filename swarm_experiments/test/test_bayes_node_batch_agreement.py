"""The node path and the batch path of Bayes-Swarm run one controller and agree exactly.

The batch runner's world (straight legs at V, samples on the observation clock, decisions on
arrival) drives, once, the RobotController objects directly and, once, real BayesSwarmNode
objects through their messages: odometry, signal samples and peer broadcasts go in as ROS
messages through the node's own subscriptions, the control tick is the node's own timer
callback on a ROS clock set to the world's time, and what the node publishes on peers/out is
what the world relays. The world replaces the follower's unicycle by holonomic legs (its
velocity commands are ignored); everything the robots decide must match bit for bit.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest
from bayes_swarm.controller import ControlOutput, GlowwormBroadcast, RobotController
from bayes_swarm.conversions import (
    glowworm_peer_from_ros,
    glowworm_peer_to_ros,
    peer_update_from_ros,
    peer_update_to_ros,
)
from bayes_swarm.node import BayesSwarmNode
from bayes_swarm.node_settings import BAYES_SWARM_PARAMETERS, NodeSettings
from swarm_experiments.bayes_batch import (
    ControllerLink,
    MissionSpec,
    robot_settings,
    run_events,
    run_mission,
    with_glowworm_clock,
)
from swarm_runtime.messages import get_message_module
from swarm_runtime.ros import Parameter, SingleThreadedExecutor, Time, rclpy, using_real_rclpy
from swarm_sim.signal_fields import get_case

pytestmark = pytest.mark.skipif(using_real_rclpy(), reason='drives the built-in runtime')

nav = get_message_module('nav_msgs')
swarm = get_message_module('swarm_interfaces')


class NodeLink:
    """One BayesSwarmNode driven by the batch world through its messages."""

    def __init__(self, settings: NodeSettings, name: str, probe, executor) -> None:
        values = BAYES_SWARM_PARAMETERS.values_of(settings)
        overrides = [Parameter(k, value=v) for k, v in values.items()]
        overrides.append(Parameter('use_sim_time', value=True))
        self.node = BayesSwarmNode(namespace=f'/{name}', parameter_overrides=overrides)
        self.subs = {s.topic_name: s.callback for s in self.node.subscriptions}
        # The control timer, and the Glowworm timer for a Glowworm robot (the faster one).
        timers = sorted(self.node.timers, key=lambda t: -t.timer_period_ns)
        self.timer = timers[0]
        self.glowworm_timer = timers[1] if len(timers) > 1 else None
        self.name = name
        self.outbox: list = []
        peer_type = swarm.GlowwormPeer if settings.algorithm == 'glowworm' else swarm.BayesSwarmPeer
        probe.create_subscription(peer_type, f'/{name}/peers/out', self.outbox.append, 100)
        self.executor = executor

    def _await_outbox(self) -> None:
        """Spin until what the node published on peers/out has reached the probe."""
        for _ in range(10):
            if self.outbox:
                break
            self.executor.spin_once(timeout_sec=0.0)

    def _clock(self, time_s: float) -> None:
        self.node.get_clock().set_ros_time_override(Time(nanoseconds=round(time_s * 1e9)))

    def pose(self, position_m, yaw_rad, time_s) -> None:
        self._clock(time_s)
        msg = nav.Odometry()
        msg.pose.pose.position.x = float(position_m[0])
        msg.pose.pose.position.y = float(position_m[1])
        msg.pose.pose.orientation.z = float(np.sin(yaw_rad / 2.0))
        msg.pose.pose.orientation.w = float(np.cos(yaw_rad / 2.0))
        self.subs[f'/{self.name}/odom'](msg)

    def signal(self, value, time_s) -> None:
        self._clock(time_s)
        self.subs[f'/{self.name}/signal'](swarm.SignalSample(value=float(value)))

    def peer(self, update, time_s) -> None:
        self._clock(time_s)
        self.subs[f'/{self.name}/peers/in'](peer_update_to_ros(update, time_s))

    def control(self, time_s) -> ControlOutput:
        self._clock(time_s)
        before = len(self.node.decisions)
        self.timer.callback()
        if len(self.node.decisions) == before:
            return ControlOutput(0.0, 0.0)
        self._await_outbox()
        broadcast = peer_update_from_ros(self.outbox.pop()) if self.outbox else None
        return ControlOutput(0.0, 0.0, self.node.decisions[-1], broadcast)

    def glowworm_broadcast(self, time_s):
        # The first half of the node's Glowworm timer tick: its GlowwormPeer on peers/out.
        self._clock(time_s)
        if not self.node._broadcast_glowworm():
            return None
        self._await_outbox()
        sender, index, position, luciferin = glowworm_peer_from_ros(self.outbox.pop())
        assert sender == self.name
        return GlowwormBroadcast(index, position, luciferin)

    def glowworm_move(self, time_s):
        self._clock(time_s)
        return self.node.controller.glowworm_move()

    def glowworm_peer(self, sender, broadcast, time_s) -> None:
        self._clock(time_s)
        msg = glowworm_peer_to_ros(
            sender, broadcast.index, broadcast.position_m, broadcast.luciferin, time_s
        )
        self.subs[f'/{self.name}/peers/in'](msg)


def _spec(case_name: str, **planner: object) -> MissionSpec:
    case = get_case(case_name)
    from swarm_experiments.spawn_bayes_swarm import batch_mission_spec

    spec = batch_mission_spec(case, planner_options=dict(planner))
    return replace(spec, planner=replace(spec.planner, max_mission_time_s=60.0))


class Recorder:
    """Passes a link's calls through and records every Glowworm broadcast and move."""

    def __init__(self, link) -> None:
        self.link = link
        self.steps: list = []

    def __getattr__(self, name):
        return getattr(self.link, name)

    def glowworm_broadcast(self, time_s):
        out = self.link.glowworm_broadcast(time_s)
        if out is not None:
            self.steps.append((time_s, out.index, *out.position_m, out.luciferin))
        return out

    def glowworm_move(self, time_s):
        out = self.link.glowworm_move(time_s)
        if out is not None:
            self.steps.append((time_s, *out))
        return out


def _node_run(spec: MissionSpec, algorithm: str, n: int, seed: int, wrap=lambda link: link):
    glowworm = algorithm == 'glowworm'
    if glowworm:  # run_mission's rule
        spec = with_glowworm_clock(spec)
    rclpy.init(args=[])
    probe = rclpy.create_node('probe')
    executor = SingleThreadedExecutor()
    executor.add_node(probe)
    links = [
        NodeLink(robot_settings(spec, algorithm, n, i, seed), f'r{i}', probe, executor)
        for i in range(n)
    ]
    try:
        return run_events(spec, n, seed, [wrap(link) for link in links], glowworm=glowworm)
    finally:
        executor.shutdown()
        for link in links:
            link.node.destroy_node()
        probe.destroy_node()
        rclpy.try_shutdown()


def _trace(result):
    return [
        [(d.kind, d.decision_index, tuple(d.waypoint_m), d.alpha, d.n_samples) for d in decisions]
        for decisions in result.decisions
    ]


def _assert_same_outcome(nodes, batch) -> None:
    """Same trajectories, finder, detection and end time on both paths."""
    for ours, theirs in zip(nodes.trajectories, batch.trajectories, strict=True):
        np.testing.assert_array_equal(ours, theirs)
    assert (nodes.found, nodes.finder, nodes.end_time_s) == (
        batch.found,
        batch.finder,
        batch.end_time_s,
    )
    assert nodes.found_time_s == batch.found_time_s or (
        np.isnan(nodes.found_time_s) and np.isnan(batch.found_time_s)
    )


@pytest.mark.parametrize(
    ('case_name', 'algorithm', 'robots', 'planner'),
    [
        ('case1', 'bayes_swarm_p', 5, {}),
        ('case1', 'bayes_swarm_o', 3, {'outer_optimizer': 'cobyla', 'inner_optimizer': 'lbfgsb'}),
        ('case1', 'levy', 3, {}),
    ],
)
def test_node_and_batch_paths_take_identical_decisions_on_seeded_runs(
    case_name, algorithm, robots, planner
):
    spec = _spec(case_name, **planner)
    batch = run_mission(spec, algorithm, robots, seed=11)
    nodes = _node_run(spec, algorithm, robots, seed=11)
    assert sum(len(d) for d in batch.decisions) > 3 * robots
    assert _trace(nodes) == _trace(batch)
    _assert_same_outcome(nodes, batch)


def test_glowworm_robots_iterate_identically_on_the_node_and_batch_paths():
    # Glowworm robots iterate on their own 100 Hz clock, not on arrivals: every iteration's
    # broadcast (index, position, luciferin, through the node's GlowwormPeer messages) and the
    # waypoint it sets must match.
    spec = _spec('case1')
    spec = replace(spec, planner=replace(spec.planner, max_mission_time_s=40.0))
    batch_recorders: list[Recorder] = []
    node_recorders: list[Recorder] = []

    def recorded(into):
        def wrap(link):
            into.append(Recorder(link))
            return into[-1]

        return wrap

    glow_spec = with_glowworm_clock(spec)
    controllers = [
        RobotController(robot_settings(glow_spec, 'glowworm', 4, i, 11), f'r{i}') for i in range(4)
    ]
    wrap = recorded(batch_recorders)
    batch = run_events(
        glow_spec, 4, 11, [wrap(ControllerLink(c)) for c in controllers], glowworm=True
    )
    nodes = _node_run(spec, 'glowworm', 4, seed=11, wrap=recorded(node_recorders))
    # The recorded batch run is run_mission's.
    plain = run_mission(spec, 'glowworm', 4, seed=11)
    assert (plain.end_time_s, plain.finder) == (batch.end_time_s, batch.finder)
    for ours, theirs in zip(plain.trajectories, batch.trajectories, strict=True):
        np.testing.assert_array_equal(ours, theirs)
    for ours, theirs in zip(node_recorders, batch_recorders, strict=True):
        assert len(theirs.steps) > 2000  # 100 Hz, two records an iteration, after dispersal
        assert ours.steps == theirs.steps
    _assert_same_outcome(nodes, batch)
