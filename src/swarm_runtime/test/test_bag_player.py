"""BagPlayer feeds nodes from a bag on sim time: /clock first, then the messages, in order."""

from __future__ import annotations

from collections.abc import Iterator
from pathlib import Path

import pytest
from swarm_runtime.bag import BagPlayer, BagWriter
from swarm_runtime.ros import Node, Parameter, message_module, rclpy

std_msgs = message_module('std_msgs')
SECOND_NS = 1_000_000_000


@pytest.fixture
def ros() -> Iterator[None]:
    """An initialised ROS context for one test."""
    rclpy.init()
    yield
    rclpy.try_shutdown()


@pytest.fixture
def bag(tmp_path: Path) -> Path:
    """Two topics, recorded out of order, at 1.0 s ... 3.0 s; /a and /b share 2.0 s."""
    path = tmp_path / 'bag'
    with BagWriter(path) as writer:
        writer.write_message('/b', 2 * SECOND_NS, std_msgs.String(data='b@2'))
        writer.write_message('/a', 1 * SECOND_NS, std_msgs.String(data='a@1'))
        writer.write_message('/a', 2 * SECOND_NS, std_msgs.String(data='a@2'))
        writer.write_message('/a', 3 * SECOND_NS, std_msgs.String(data='a@3'))
    return path


class Listener(Node):
    """Notes (own clock, topic, data) of every message on /a and /b, and its timer ticks."""

    def __init__(self) -> None:
        super().__init__('listener', parameter_overrides=[Parameter('use_sim_time', value=True)])
        self.heard: list[tuple[int, str, str]] = []
        self.ticks: list[int] = []
        for topic in ('/a', '/b'):
            self.create_subscription(
                std_msgs.String, topic, lambda msg, topic=topic: self._note(topic, msg), 10
            )
        self.create_timer(0.5, lambda: self.ticks.append(self.get_clock().now().nanoseconds))

    def _note(self, topic: str, msg: object) -> None:
        self.heard.append((self.get_clock().now().nanoseconds, topic, msg.data))


def _play_to_end(player: BagPlayer, *nodes: Node) -> None:
    executor = rclpy.executors.SingleThreadedExecutor()
    for node in (*nodes, player):
        executor.add_node(node)
    while not player.finished:
        executor.spin_once(timeout_sec=10.0)
    for _ in range(20):
        executor.spin_once(timeout_sec=0.0)


def test_replay_delivers_in_log_time_order_at_the_bags_time(ros: None, bag: Path) -> None:
    listener = Listener()
    player = BagPlayer(bag)
    _play_to_end(player, listener)
    assert [(t, data) for t, _, data in listener.heard] == [
        (1 * SECOND_NS, 'a@1'),
        (2 * SECOND_NS, 'b@2'),
        (2 * SECOND_NS, 'a@2'),
        (3 * SECOND_NS, 'a@3'),
    ]
    assert player.published_count == 4
    assert player.bag_time_ns == 3 * SECOND_NS


def test_sim_time_timers_follow_the_bag_clock(ros: None, bag: Path) -> None:
    listener = Listener()
    _play_to_end(BagPlayer(bag), listener)
    # /clock jumps from one bag instant to the next, so the 0.5 s timer runs at those instants.
    assert set(listener.ticks) == {1 * SECOND_NS, 2 * SECOND_NS, 3 * SECOND_NS}


def test_topic_filter_limits_what_is_replayed(ros: None, bag: Path) -> None:
    listener = Listener()
    _play_to_end(BagPlayer(bag, topics=['/b']), listener)
    assert [topic for _, topic, _ in listener.heard] == ['/b']


def test_rate_scales_the_players_own_clock(ros: None, bag: Path) -> None:
    for rate, expected_ns in ((1.0, 2 * SECOND_NS), (4.0, SECOND_NS // 2)):
        player = BagPlayer(bag, rate=rate, node_name=f'player_{int(rate)}')
        start = player.get_clock().now().nanoseconds
        _play_to_end(player)
        assert player.get_clock().now().nanoseconds - start == pytest.approx(expected_ns, abs=2)
        player.destroy_node()


def test_step_publishes_one_instant_at_a_time(ros: None, bag: Path) -> None:
    listener = Listener()
    player = BagPlayer(bag, start_paused=True)
    executor = rclpy.executors.SingleThreadedExecutor()
    executor.add_node(listener)
    executor.add_node(player)
    assert player.step() == 1 * SECOND_NS
    assert player.step() == 2 * SECOND_NS
    for _ in range(10):
        executor.spin_once(timeout_sec=0.0)
    assert [data for _, _, data in listener.heard] == ['a@1', 'b@2', 'a@2']
    assert player.step() == 3 * SECOND_NS
    assert player.step() is None
    assert player.finished


def test_player_refuses_sim_time_and_bad_rates(ros: None, bag: Path) -> None:
    with pytest.raises(ValueError, match='cannot run on sim time'):
        BagPlayer(bag, parameter_overrides=[Parameter('use_sim_time', value=True)])
    with pytest.raises(ValueError, match='rate must be positive'):
        BagPlayer(bag, rate=0.0)
