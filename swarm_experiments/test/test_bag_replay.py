"""A spawner's bag replays into a fresh algorithm node: the node runs on the bag's /clock and
drives cmd_vel from the recorded sensor topics.

Per algorithm (OA-Bug, Bayes-Swarm, MSC + PF), a short 2-robot mission is recorded with the
default ``--record-topics sensors``; then robot r0's inputs are replayed by ``BagPlayer`` into
a new node with r0's parameters, on sim time. On the built-in runtime the replayed node
commands exactly the cmd_vel sequence the recorded one did. On real rclpy (DDS, real-time
pacing, no such determinism) the node runs on the replayed clock and publishes.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Callable, Iterator
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import pytest
from swarm_experiments.mission import run_mission
from swarm_runtime.bag import BagPlayer, read_bag_info, read_messages
from swarm_runtime.bag.testing import spin_until
from swarm_runtime.ros import (
    Node,
    Parameter,
    SingleThreadedExecutor,
    message_module,
    rclpy,
    using_real_rclpy,
)

REAL = using_real_rclpy()
# On DDS the missions run faster than real time (as far as the nodes keep up) and the
# replay likewise, so the tests stay short; the built-in runtime runs as fast as it can.
TIME_SCALE = 4.0 if REAL else 1.0
WAIT_S = 60.0
geometry_msgs = message_module('geometry_msgs')
STREAMS = {'scan', 'imu', 'gas', 'bearings', 'odom', 'signal', 'rssi'}


@dataclass
class Recorded:
    """A recorded mission and how to build a fresh node like its robot r0."""

    bag: Path
    new_r0: Callable[[list[Any]], Any]
    r0_parameters: dict[str, Any]
    inputs: tuple[str, ...]


def _oabug(tmp: Path) -> Recorded:
    from swarm_experiments.spawn import SENSOR_TOPICS, SpawnSettings, build_mission

    config = SpawnSettings(
        site='small', robots=2, seed=1, record=tmp / 'bag', time_scale=TIME_SCALE
    )
    spec, _ = build_mission(config)
    run_mission(dataclasses.replace(spec, max_sim_time_s=12.0 if REAL else 30.0))
    robot = spec.robots[0]

    def new_r0(overrides: list[Any]) -> Any:
        return robot.factory(namespace='/r0', parameter_overrides=overrides)

    return Recorded(
        config.record, new_r0, dict(robot.parameters), tuple(f'/r0/{t}' for t in SENSOR_TOPICS)
    )


def _bayes(tmp: Path) -> Recorded:
    from bayes_swarm.node import BayesSwarmNode
    from swarm_experiments.spawn_bayes_swarm import (
        SENSOR_TOPICS,
        SpawnSettings,
        check_settings,
        node_parameters,
        run,
    )

    settings = SpawnSettings(
        robots=2,
        max_mission_time_s=8.0 if REAL else 20.0,
        record=tmp / 'bag',
        time_scale=TIME_SCALE,
    )
    run(settings)
    case = check_settings(settings)

    def new_r0(overrides: list[Any]) -> Any:
        return BayesSwarmNode(namespace='/r0', parameter_overrides=overrides)

    return Recorded(
        settings.record,
        new_r0,
        node_parameters(case, settings, 2, 0),
        tuple(t.replace('/r*/', '/r0/') for t in SENSOR_TOPICS),
    )


def _msc(tmp: Path) -> Recorded:
    from msc_pf.node import MscPfNode
    from swarm_experiments.spawn_msc_pf import SENSOR_TOPICS, SpawnSettings, node_parameters, run

    settings = SpawnSettings(
        robots=2,
        targets=1,
        seed=3,
        max_time_s=10.0 if REAL else 30.0,
        record=tmp / 'bag',
        time_scale=TIME_SCALE,
    )
    run(settings)

    def new_r0(overrides: list[Any]) -> Any:
        return MscPfNode(namespace='/r0', parameter_overrides=overrides)

    return Recorded(
        settings.record,
        new_r0,
        node_parameters(settings, 0),
        tuple(t.replace('/r*/', '/r0/') for t in SENSOR_TOPICS),
    )


ALGORITHMS = {'oabug': _oabug, 'bayes_swarm': _bayes, 'msc_pf': _msc}


@pytest.fixture(scope='module', params=sorted(ALGORITHMS))
def recorded(request: pytest.FixtureRequest, tmp_path_factory: pytest.TempPathFactory) -> Recorded:
    return ALGORITHMS[request.param](tmp_path_factory.mktemp(request.param))


@dataclass
class Replay:
    commands: list[tuple[float, float]]
    node_times_ns: list[int]
    bag_start_ns: int
    bag_end_ns: int


@pytest.fixture
def ros() -> Iterator[None]:
    rclpy.init()
    yield
    rclpy.try_shutdown()


def _replay(recorded: Recorded) -> Replay:
    overrides = [Parameter('use_sim_time', value=True)]
    overrides += [Parameter(k, value=v) for k, v in recorded.r0_parameters.items()]
    node = recorded.new_r0(overrides)
    probe = Node('cmd_vel_probe')
    commands: list[tuple[float, float]] = []
    node_times: list[int] = []

    def on_cmd(msg: Any) -> None:
        commands.append((msg.linear.x, msg.angular.z))
        node_times.append(node.get_clock().now().nanoseconds)

    probe.create_subscription(geometry_msgs.Twist, '/r0/cmd_vel', on_cmd, 100)
    player = BagPlayer(
        recorded.bag,
        topics=recorded.inputs,
        outputs=['/r0/*'],
        start_paused=True,
        rate=TIME_SCALE,
    )
    executor = SingleThreadedExecutor()
    for each in (node, probe, player):
        executor.add_node(each)
    try:
        assert spin_until(
            executor,
            lambda: (
                min(player.subscription_counts().values()) >= 1
                and probe.count_publishers('/r0/cmd_vel') >= 1
            ),
            timeout_s=WAIT_S,
        )
        first = next(read_messages(recorded.bag, topics=list(recorded.inputs), raw=True))
        start_ns = first.log_time_ns
        player.play()
        assert spin_until(executor, lambda: player.finished, timeout_s=WAIT_S * 4)
        end_ns = player.bag_time_ns
        # Deliver what the last instant caused.
        for _ in range(50):
            executor.spin_once(timeout_sec=0.01 if REAL else 0.0)
    finally:
        for each in (player, probe, node):
            executor.remove_node(each)
            each.destroy_node()
        executor.shutdown()
    return Replay(commands, node_times, start_ns, end_ns)


def test_the_bag_holds_every_topic_the_robots_node_reads(recorded: Recorded) -> None:
    info = read_bag_info(recorded.bag)
    assert set(recorded.inputs) <= set(info.topics)
    for topic in recorded.inputs:
        # Events (MSC's captures) need not occur in a short run; the sensors stream.
        if topic.rsplit('/', 1)[-1] in STREAMS:
            assert info.topics[topic].message_count > 0, topic
    assert info.topics['/r0/cmd_vel'].message_count > 0


def test_a_fresh_node_replays_the_bag_on_its_clock_and_commands(recorded: Recorded, ros) -> None:
    replay = _replay(recorded)
    assert len(replay.commands) >= 5
    # The node's clock is the bag's: every command was sent inside the recorded span.
    assert replay.node_times_ns[0] >= replay.bag_start_ns
    assert replay.node_times_ns[-1] <= replay.bag_end_ns
    assert any(x != 0.0 or w != 0.0 for x, w in replay.commands)


@pytest.mark.builtin_only(reason='bit-exact replay needs the deterministic single process')
def test_the_replayed_node_commands_exactly_what_the_recorded_one_did(
    recorded: Recorded, ros
) -> None:
    replay = _replay(recorded)
    live = [
        (m.message.linear.x, m.message.angular.z)
        for m in read_messages(recorded.bag, topics=['/r0/cmd_vel'])
    ]
    assert len(live) >= 5
    assert replay.commands == live


def test_the_recorded_sensor_topics_are_what_the_node_subscribes_to(
    recorded: Recorded, ros
) -> None:
    overrides = [Parameter('use_sim_time', value=True)]
    overrides += [Parameter(k, value=v) for k, v in recorded.r0_parameters.items()]
    node = recorded.new_r0(overrides)
    executor = SingleThreadedExecutor()
    executor.add_node(node)
    system = {'/clock', '/parameter_events'}

    def subscribed() -> set[str]:
        return {
            topic
            for topic, _ in node.get_topic_names_and_types()
            if topic not in system
            and any(
                info.node_namespace == '/r0' and info.node_name == node.get_name()
                for info in node.get_subscriptions_info_by_topic(topic)
            )
        }

    try:
        assert spin_until(executor, lambda: subscribed() >= set(recorded.inputs), timeout_s=WAIT_S)
        assert subscribed() == set(recorded.inputs)
    finally:
        executor.remove_node(node)
        node.destroy_node()
        executor.shutdown()
