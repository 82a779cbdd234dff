"""BagPlayer feeds nodes from a bag on sim time: /clock first, then the messages, in order.

Runs on both runtimes. On real rclpy the replay is paced in real time and the player starts
paused until DDS has matched its publishers with the nodes under test.
"""

from __future__ import annotations

from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pytest
from rosbags.interfaces import Qos, QosDurability, QosHistory, QosLiveliness, QosReliability
from rosbags.interfaces import QosTime as Time
from swarm_runtime.bag import BagPlayer, BagWriter
from swarm_runtime.bag.player import replay_qos
from swarm_runtime.bag.testing import spin_until
from swarm_runtime.messages import get_message_module
from swarm_runtime.ros import (
    Node,
    Parameter,
    QoSDurabilityPolicy,
    QoSProfile,
    ReliabilityPolicy,
    message_module,
    rclpy,
    using_real_rclpy,
)

std_msgs = message_module('std_msgs')
SECOND_NS = 1_000_000_000
REAL = using_real_rclpy()
WAIT_S = 20.0
INFINITE = Time(sec=2147483647, nsec=4294967295)


def _qos(reliability: QosReliability, durability: QosDurability, depth: int = 0) -> Qos:
    history = QosHistory.KEEP_LAST if depth else QosHistory.UNKNOWN
    return Qos(
        history, depth, reliability, durability, INFINITE, INFINITE, QosLiveliness.AUTOMATIC,
        INFINITE, False,
    )  # fmt: skip


LATCHED = _qos(QosReliability.RELIABLE, QosDurability.TRANSIENT_LOCAL)
SENSOR = _qos(QosReliability.BEST_EFFORT, QosDurability.VOLATILE, depth=5)


@pytest.fixture
def ros() -> Iterator[None]:
    """An initialised ROS context for one test (on DDS: the domain of this test process)."""
    rclpy.init()
    yield
    rclpy.try_shutdown()


@pytest.fixture
def bag(tmp_path: Path) -> Path:
    """Two topics, recorded out of order, at 1.0 s ... 3.0 s; /a and /b share 2.0 s."""
    generated = get_message_module('std_msgs')
    path = tmp_path / 'bag'
    with BagWriter(path) as writer:
        writer.add_topic('/b', 'std_msgs/msg/String', offered_qos_profiles=[LATCHED])
        writer.write_message('/b', 2 * SECOND_NS, generated.String(data='b@2'))
        writer.write_message('/a', 1 * SECOND_NS, generated.String(data='a@1'))
        writer.write_message('/a', 2 * SECOND_NS, generated.String(data='a@2'))
        writer.write_message('/a', 3 * SECOND_NS, generated.String(data='a@3'))
    return path


class Listener(Node):
    """Notes (own clock, topic, data) of every message on /a and /b, and its timer ticks."""

    def __init__(self) -> None:
        super().__init__('listener', parameter_overrides=[Parameter('use_sim_time', value=True)])
        self.heard: list[tuple[int, str, str]] = []
        self.ticks: list[int] = []
        latched = QoSProfile(depth=1, durability=QoSDurabilityPolicy.TRANSIENT_LOCAL)
        for topic, qos in (('/a', QoSProfile(depth=10)), ('/b', latched)):
            self.create_subscription(
                std_msgs.String, topic, lambda msg, topic=topic: self._note(topic, msg), qos
            )
        self.create_timer(0.5, lambda: self.ticks.append(self.get_clock().now().nanoseconds))

    def _note(self, topic: str, msg: Any) -> None:
        self.heard.append((self.get_clock().now().nanoseconds, topic, msg.data))


def _executor(*nodes: Node) -> Any:
    executor = rclpy.executors.SingleThreadedExecutor()
    for node in nodes:
        executor.add_node(node)
    return executor


def _wait_matched(executor: Any, player: BagPlayer, *, clock_subscribers: int) -> None:
    """Wait until every replay publisher (and /clock) reaches the nodes under test."""
    assert spin_until(
        executor,
        lambda: (
            all(count >= 1 for count in player.subscription_counts().values())
            and player._clock_publisher.get_subscription_count() >= clock_subscribers
        ),
        timeout_s=WAIT_S,
    )


def _play_to_end(executor: Any, player: BagPlayer, expected_messages: int, heard: Any) -> None:
    player.play()
    assert spin_until(executor, lambda: player.finished, timeout_s=WAIT_S)
    assert spin_until(executor, lambda: len(heard()) >= expected_messages, timeout_s=WAIT_S)
    for _ in range(5):
        executor.spin_once(timeout_sec=0.02)


def test_replay_delivers_in_log_time_order_at_the_bags_time(ros: None, bag: Path) -> None:
    listener = Listener()
    player = BagPlayer(bag, start_paused=True)
    executor = _executor(listener, player)
    _wait_matched(executor, player, clock_subscribers=1)
    _play_to_end(executor, player, 4, lambda: listener.heard)
    expected = [
        (1 * SECOND_NS, 'a@1'),
        (2 * SECOND_NS, 'b@2'),
        (2 * SECOND_NS, 'a@2'),
        (3 * SECOND_NS, 'a@3'),
    ]
    heard = [(t, data) for t, _, data in listener.heard]
    if REAL:
        # DDS keeps the order per topic; messages of one instant on two topics may swap.
        assert sorted(heard) == sorted(expected)
        assert [t for t, _ in heard] == [t for t, _ in expected]
        assert [d for _, d in heard if d.startswith('a')] == ['a@1', 'a@2', 'a@3']
    else:
        assert heard == expected
    assert player.published_count == 4
    assert player.bag_time_ns == 3 * SECOND_NS


def test_sim_time_timers_follow_the_bag_clock(ros: None, bag: Path) -> None:
    listener = Listener()
    player = BagPlayer(bag, start_paused=True)
    executor = _executor(listener, player)
    _wait_matched(executor, player, clock_subscribers=1)
    _play_to_end(executor, player, 4, lambda: listener.heard)
    # /clock jumps from one bag instant to the next, so the 0.5 s timer runs at those instants.
    assert set(listener.ticks) == {1 * SECOND_NS, 2 * SECOND_NS, 3 * SECOND_NS}


def test_topic_filter_limits_what_is_replayed(ros: None, bag: Path) -> None:
    listener = Listener()
    player = BagPlayer(bag, topics=['/b'], start_paused=True)
    assert set(player.subscription_counts()) == {'/b'}
    executor = _executor(listener, player)
    _wait_matched(executor, player, clock_subscribers=1)
    _play_to_end(executor, player, 1, lambda: listener.heard)
    assert [topic for _, topic, _ in listener.heard] == ['/b']


def test_the_player_publishes_with_the_recorded_qos(ros: None, bag: Path) -> None:
    player = BagPlayer(bag, start_paused=True)
    executor = _executor(player)
    assert spin_until(
        executor, lambda: len(player.get_publishers_info_by_topic('/b')) >= 1, timeout_s=WAIT_S
    )
    (endpoint,) = player.get_publishers_info_by_topic('/b')
    assert endpoint.qos_profile.durability == QoSDurabilityPolicy.TRANSIENT_LOCAL
    assert endpoint.qos_profile.reliability == ReliabilityPolicy.RELIABLE
    (endpoint,) = player.get_publishers_info_by_topic('/a')  # recorded without QoS
    assert endpoint.qos_profile.durability == QoSDurabilityPolicy.VOLATILE


def test_a_latched_topic_reaches_a_subscriber_that_joins_after_the_replay(
    ros: None, bag: Path
) -> None:
    player = BagPlayer(bag, topics=['/b'], start_paused=True)
    executor = _executor(player)
    while player.step() is not None:
        pass
    late = Listener()
    executor.add_node(late)
    assert spin_until(executor, lambda: late.heard, timeout_s=WAIT_S)
    assert [data for _, _, data in late.heard] == ['b@2']


def test_replay_qos_adapts_the_recorded_offers() -> None:
    both = replay_qos([LATCHED, SENSOR])
    assert both.reliability == ReliabilityPolicy.BEST_EFFORT
    assert both.durability == QoSDurabilityPolicy.VOLATILE
    assert both.depth == 5
    latched = replay_qos([LATCHED])
    assert (latched.reliability, latched.durability, latched.depth) == (
        ReliabilityPolicy.RELIABLE,
        QoSDurabilityPolicy.TRANSIENT_LOCAL,
        1,
    )
    assert replay_qos([]).depth == 10


def test_rate_scales_the_players_own_clock(ros: None, bag: Path) -> None:
    # The built-in runtime's clock is virtual and exact; real timers fire a little late.
    tolerance_ns = 150_000_000 if REAL else 2
    for rate, expected_ns in ((1.0, 2 * SECOND_NS), (4.0, SECOND_NS // 2)):
        player = BagPlayer(bag, rate=rate, node_name=f'player_{int(rate)}', start_paused=True)
        executor = _executor(player)
        start = player.get_clock().now().nanoseconds
        player.play()
        assert spin_until(executor, lambda player=player: player.finished, timeout_s=WAIT_S)
        elapsed = player.get_clock().now().nanoseconds - start
        assert expected_ns - 2 <= elapsed <= expected_ns + tolerance_ns
        executor.remove_node(player)
        player.destroy_node()


def test_step_publishes_one_instant_at_a_time(ros: None, bag: Path) -> None:
    listener = Listener()
    player = BagPlayer(bag, start_paused=True)
    executor = _executor(listener, player)
    _wait_matched(executor, player, clock_subscribers=1)
    assert player.step() == 1 * SECOND_NS
    assert player.step() == 2 * SECOND_NS
    assert spin_until(executor, lambda: len(listener.heard) >= 3, timeout_s=WAIT_S)
    assert sorted(data for _, _, data in listener.heard) == ['a@1', 'a@2', 'b@2']
    assert player.step() == 3 * SECOND_NS
    assert player.step() is None
    assert player.finished


def test_player_refuses_sim_time_and_bad_rates(ros: None, bag: Path) -> None:
    with pytest.raises(ValueError, match='cannot run on sim time'):
        BagPlayer(bag, parameter_overrides=[Parameter('use_sim_time', value=True)])
    with pytest.raises(ValueError, match='rate must be positive'):
        BagPlayer(bag, rate=0.0)


def test_messages_recorded_after_an_output_are_held_to_just_before_the_next_instant(
    ros: None, tmp_path: Path
) -> None:
    generated = get_message_module('std_msgs')
    path = tmp_path / 'bag'
    with BagWriter(path) as writer:
        writer.add_topic('/b', 'std_msgs/msg/String', offered_qos_profiles=[LATCHED])
        writer.write_message('/a', 1 * SECOND_NS, generated.String(data='a@1'))
        writer.write_message('/out', 1 * SECOND_NS, generated.String(data='output@1'))
        writer.write_message('/b', 1 * SECOND_NS, generated.String(data='b@1'))
        writer.write_message('/a', 3 * SECOND_NS, generated.String(data='a@3'))
    listener = Listener()
    player = BagPlayer(path, topics=['/a', '/b'], outputs=['/out'], start_paused=True)
    assert set(player.subscription_counts()) == {'/a', '/b'}  # outputs are never replayed
    executor = _executor(listener, player)
    _wait_matched(executor, player, clock_subscribers=1)
    assert player.step() == 1 * SECOND_NS
    assert spin_until(executor, lambda: len(listener.heard) >= 1, timeout_s=WAIT_S)
    for _ in range(5):
        executor.spin_once(timeout_sec=0.02 if REAL else 0.0)
    # /b was recorded after the node's output at 1 s: it is not out yet, the timer has run.
    assert [(t, d) for t, _, d in listener.heard] == [(1 * SECOND_NS, 'a@1')]
    assert listener.ticks[-1] == 1 * SECOND_NS
    assert player.step() == 3 * SECOND_NS
    assert spin_until(executor, lambda: len(listener.heard) >= 3, timeout_s=WAIT_S)
    heard = [d for _, _, d in listener.heard]
    assert sorted(heard[1:]) == ['a@3', 'b@1']
    if not REAL:
        # Before the clock of 3 s: the listener got b@1 while its clock still read 1 s.
        assert listener.heard[1] == (1 * SECOND_NS, '/b', 'b@1')
    assert player.finished
    assert player.step() is None


def test_held_messages_of_the_last_instant_go_out_after_it(ros: None, tmp_path: Path) -> None:
    generated = get_message_module('std_msgs')
    path = tmp_path / 'bag'
    with BagWriter(path) as writer:
        writer.write_message('/out', 2 * SECOND_NS, generated.String(data='output@2'))
        writer.write_message('/a', 2 * SECOND_NS, generated.String(data='a@2'))
    listener = Listener()
    player = BagPlayer(path, topics=['/a'], outputs=['/out'], start_paused=True)
    executor = _executor(listener, player)
    _wait_matched(executor, player, clock_subscribers=1)
    _play_to_end(executor, player, 1, lambda: [h for h in listener.heard if h[1] == '/a'])
    # Only /a: on DDS the listener's latched /b may still hear an earlier test's player.
    assert [(t, d) for t, topic, d in listener.heard if topic == '/a'] == [(2 * SECOND_NS, 'a@2')]
    assert player.published_count == 1
