"""Message delivery of the built-in runtime: order, QoS depth and matching, latching, CDR."""

from __future__ import annotations

import logging
from collections.abc import Iterator
from typing import Any

import pytest
from swarm_runtime.builtin.exceptions import InvalidHandle
from swarm_runtime.builtin.executors import SingleThreadedExecutor
from swarm_runtime.builtin.node import Node
from swarm_runtime.builtin.qos import (
    DurabilityPolicy,
    HistoryPolicy,
    QoSCompatibility,
    QoSProfile,
    ReliabilityPolicy,
    qos_check_compatible,
    qos_profile_sensor_data,
    qos_profile_system_default,
)
from swarm_runtime.messages import get_message_module, serialize_cdr
from swarm_runtime.simulation import sim_time_s, spin_ready

from swarm_runtime import builtin as rclpy

std_msgs = get_message_module('std_msgs')
sensor_msgs = get_message_module('sensor_msgs')

RELIABLE_10 = QoSProfile(depth=10)
BEST_EFFORT_10 = QoSProfile(depth=10, reliability=ReliabilityPolicy.BEST_EFFORT)
LATCHED = QoSProfile(depth=3, durability=DurabilityPolicy.TRANSIENT_LOCAL)


@pytest.fixture
def executor() -> Iterator[SingleThreadedExecutor]:
    rclpy.init(args=['test'])
    yield SingleThreadedExecutor()
    rclpy.try_shutdown()


def recorder(node: Node, msg_type: type, topic: str, qos: Any, *, raw: bool = False) -> list[Any]:
    """Subscribe and return the list the callback appends to."""
    received: list[Any] = []
    node.create_subscription(msg_type, topic, received.append, qos, raw=raw)
    return received


def test_qos_presets_match_rclpy() -> None:
    assert qos_profile_sensor_data.reliability == ReliabilityPolicy.BEST_EFFORT
    assert qos_profile_sensor_data.history == HistoryPolicy.KEEP_LAST
    assert qos_profile_sensor_data.depth == 5
    depth_only = QoSProfile(depth=10)
    assert depth_only.reliability == ReliabilityPolicy.RELIABLE
    assert depth_only.history == HistoryPolicy.KEEP_LAST
    assert depth_only.durability == DurabilityPolicy.VOLATILE


def test_qos_profile_needs_history_or_depth() -> None:
    with pytest.raises(rclpy.qos.InvalidQoSProfileException, match='History and/or depth'):
        QoSProfile()
    with pytest.raises(AssertionError, match='Invalid arguments'):
        QoSProfile(depth=1, bogus=2)


def test_integer_qos_gives_a_reliable_keep_last_publisher(executor) -> None:
    publisher = Node('talker').create_publisher(std_msgs.String, 'chatter', 7)
    assert publisher.qos_profile.reliability == ReliabilityPolicy.RELIABLE
    assert publisher.qos_profile.depth == 7


def test_messages_are_delivered_in_publish_order_across_topics(executor) -> None:
    node = Node('fan')
    log: list[str] = []
    node.create_subscription(std_msgs.String, 'a', lambda m: log.append('a:' + m.data), 10)
    node.create_subscription(std_msgs.String, 'b', lambda m: log.append('b:' + m.data), 10)
    pub_a = node.create_publisher(std_msgs.String, 'a', 10)
    pub_b = node.create_publisher(std_msgs.String, 'b', 10)
    executor.add_node(node)
    for index, publisher in enumerate([pub_a, pub_b, pub_b, pub_a, pub_b]):
        publisher.publish(std_msgs.String(data=str(index)))
    spin_ready(executor)
    assert log == ['a:0', 'b:1', 'b:2', 'a:3', 'b:4']


def test_messages_published_in_callbacks_follow_in_publish_order(executor) -> None:
    node = Node('relay')
    log: list[str] = []
    relay = node.create_publisher(std_msgs.String, 'out', 10)

    def forward(msg: Any) -> None:
        log.append('in:' + msg.data)
        relay.publish(std_msgs.String(data=msg.data))

    node.create_subscription(std_msgs.String, 'in', forward, 10)
    node.create_subscription(std_msgs.String, 'out', lambda m: log.append('out:' + m.data), 10)
    source = node.create_publisher(std_msgs.String, 'in', 10)
    executor.add_node(node)
    source.publish(std_msgs.String(data='1'))
    source.publish(std_msgs.String(data='2'))
    spin_ready(executor)
    assert log == ['in:1', 'in:2', 'out:1', 'out:2']


def test_keep_last_subscription_drops_the_oldest_beyond_its_depth(executor) -> None:
    node = Node('slow_reader')
    shallow = recorder(node, std_msgs.String, 'burst', QoSProfile(depth=3))
    deep = recorder(node, std_msgs.String, 'burst', QoSProfile(depth=10))
    publisher = node.create_publisher(std_msgs.String, 'burst', 10)
    executor.add_node(node)
    for index in range(6):
        publisher.publish(std_msgs.String(data=str(index)))
    spin_ready(executor)
    assert [m.data for m in shallow] == ['3', '4', '5']
    assert [m.data for m in deep] == ['0', '1', '2', '3', '4', '5']


def test_keep_all_subscription_keeps_everything(executor) -> None:
    node = Node('hoarder')
    everything = recorder(
        node, std_msgs.String, 'burst', QoSProfile(history=HistoryPolicy.KEEP_ALL)
    )
    publisher = node.create_publisher(std_msgs.String, 'burst', 10)
    executor.add_node(node)
    for index in range(50):
        publisher.publish(std_msgs.String(data=str(index)))
    spin_ready(executor)
    assert len(everything) == 50


def test_reliable_subscription_gets_nothing_from_a_best_effort_publisher(executor, caplog) -> None:
    node = Node('strict')
    with caplog.at_level(logging.WARNING):
        reliable = recorder(node, std_msgs.String, 'scan', RELIABLE_10)
        best_effort = recorder(node, std_msgs.String, 'scan', BEST_EFFORT_10)
        publisher = node.create_publisher(std_msgs.String, 'scan', qos_profile_sensor_data)
    executor.add_node(node)
    publisher.publish(std_msgs.String(data='x'))
    spin_ready(executor)
    assert reliable == []
    assert [m.data for m in best_effort] == ['x']
    assert publisher.get_subscription_count() == 1
    assert 'incompatible QoS' in caplog.text
    assert 'RELIABILITY' in caplog.text


def test_best_effort_subscription_receives_from_a_reliable_publisher(executor) -> None:
    node = Node('lenient')
    received = recorder(node, std_msgs.String, 'cmd', qos_profile_sensor_data)
    node.create_publisher(std_msgs.String, 'cmd', RELIABLE_10).publish(std_msgs.String(data='go'))
    executor.add_node(node)
    spin_ready(executor)
    assert [m.data for m in received] == ['go']


def test_qos_check_compatible_reports_durability_mismatch() -> None:
    publisher = QoSProfile(depth=1)
    subscription = QoSProfile(depth=1, durability=DurabilityPolicy.TRANSIENT_LOCAL)
    compatibility, reason = qos_check_compatible(publisher, subscription)
    assert compatibility == QoSCompatibility.ERROR
    assert 'transient local' in reason
    assert qos_check_compatible(subscription, publisher)[0] == QoSCompatibility.OK


def test_system_default_subscription_is_best_effort_like_dds(executor) -> None:
    node = Node('defaults')
    received = recorder(node, std_msgs.String, 't', qos_profile_system_default)
    node.create_publisher(std_msgs.String, 't', BEST_EFFORT_10).publish(std_msgs.String(data='y'))
    executor.add_node(node)
    spin_ready(executor)
    assert [m.data for m in received] == ['y']


def test_transient_local_publisher_latches_its_last_messages_for_late_subscribers(
    executor,
) -> None:
    node = Node('site')
    publisher = node.create_publisher(std_msgs.String, '/sim/site', LATCHED)
    for index in range(5):
        publisher.publish(std_msgs.String(data=str(index)))
    late = recorder(node, std_msgs.String, '/sim/site', LATCHED)
    volatile_late = recorder(node, std_msgs.String, '/sim/site', RELIABLE_10)
    executor.add_node(node)
    spin_ready(executor)
    assert [m.data for m in late] == ['2', '3', '4']
    assert volatile_late == []


def test_publishing_the_wrong_message_type_raises_type_error(executor) -> None:
    publisher = Node('typo').create_publisher(std_msgs.String, 'chatter', 10)
    with pytest.raises(TypeError, match='Expected'):
        publisher.publish(std_msgs.Bool(data=True))
    with pytest.raises(TypeError, match='Expected'):
        publisher.publish('hello')


def test_subscriptions_of_another_type_on_the_topic_are_not_connected(executor, caplog) -> None:
    node = Node('mixed')
    strings = recorder(node, std_msgs.String, 'x', 10)
    with caplog.at_level(logging.WARNING):
        node.create_publisher(std_msgs.Bool, 'x', 10).publish(std_msgs.Bool(data=True))
    executor.add_node(node)
    spin_ready(executor)
    assert strings == []
    assert 'std_msgs/msg/Bool' in caplog.text


def test_raw_subscription_receives_the_cdr_bytes(executor) -> None:
    node = Node('recorder')
    raw = recorder(node, std_msgs.String, 'chatter', 10, raw=True)
    message = std_msgs.String(data='Hello World: 1')
    node.create_publisher(std_msgs.String, 'chatter', 10).publish(message)
    executor.add_node(node)
    spin_ready(executor)
    assert raw == [serialize_cdr(message)]


def test_publishing_cdr_bytes_reaches_typed_subscribers_as_messages(executor) -> None:
    node = Node('player')
    typed = recorder(node, std_msgs.String, 'chatter', 10)
    publisher = node.create_publisher(std_msgs.String, 'chatter', 10)
    publisher.publish(serialize_cdr(std_msgs.String(data='from a bag')))
    executor.add_node(node)
    spin_ready(executor)
    assert [m.data for m in typed] == ['from a bag']


def test_cdr_round_trip_gives_each_subscriber_its_own_float32_rounded_copy(
    executor, monkeypatch
) -> None:
    monkeypatch.setenv('SWARM_RUNTIME_CDR_ROUNDTRIP', '1')
    node = Node('lidar')
    first = recorder(node, sensor_msgs.LaserScan, 'scan', qos_profile_sensor_data)
    second = recorder(node, sensor_msgs.LaserScan, 'scan', qos_profile_sensor_data)
    scan = sensor_msgs.LaserScan(angle_increment=0.0174, ranges=[1.0, 2.5])
    node.create_publisher(sensor_msgs.LaserScan, 'scan', qos_profile_sensor_data).publish(scan)
    executor.add_node(node)
    spin_ready(executor)
    assert first[0].angle_increment == pytest.approx(0.017400000244379044, abs=0.0)
    assert first[0] is not scan
    assert first[0] is not second[0]
    assert list(first[0].ranges) == [1.0, 2.5]


def test_without_cdr_round_trip_subscribers_get_the_published_object(executor, monkeypatch) -> None:
    monkeypatch.setenv('SWARM_RUNTIME_CDR_ROUNDTRIP', '0')
    node = Node('lidar')
    received = recorder(node, sensor_msgs.LaserScan, 'scan', qos_profile_sensor_data)
    scan = sensor_msgs.LaserScan(angle_increment=0.0174)
    node.create_publisher(sensor_msgs.LaserScan, 'scan', qos_profile_sensor_data).publish(scan)
    executor.add_node(node)
    spin_ready(executor)
    assert received[0] is scan


def test_cdr_switch_is_read_when_the_publisher_is_created(executor, monkeypatch) -> None:
    monkeypatch.setenv('SWARM_RUNTIME_CDR_ROUNDTRIP', '0')
    node = Node('lidar')
    received = recorder(node, std_msgs.String, 'x', 10)
    publisher = node.create_publisher(std_msgs.String, 'x', 10)
    monkeypatch.setenv('SWARM_RUNTIME_CDR_ROUNDTRIP', '1')
    message = std_msgs.String(data='same object')
    publisher.publish(message)
    executor.add_node(node)
    spin_ready(executor)
    assert received[0] is message


def test_two_argument_callbacks_get_message_info(executor) -> None:
    node = Node('informed')
    infos: list[dict[str, int]] = []
    node.create_subscription(std_msgs.String, 'x', lambda msg, info: infos.append(info), 10)
    publisher = node.create_publisher(std_msgs.String, 'x', 10)
    publisher.publish(std_msgs.String(data='a'))
    publisher.publish(std_msgs.String(data='b'))
    executor.add_node(node)
    spin_ready(executor)
    assert [info['publication_sequence_number'] for info in infos] == [1, 2]
    assert [info['reception_sequence_number'] for info in infos] == [1, 2]
    with pytest.raises(RuntimeError, match='one argument'):
        node.create_subscription(std_msgs.String, 'x', lambda a, b, c: None, 10)


def test_messages_wait_for_a_node_that_joins_an_executor_later(executor) -> None:
    talker = Node('talker')
    listener = Node('listener')
    heard = recorder(listener, std_msgs.String, 'chatter', 10)
    publisher = talker.create_publisher(std_msgs.String, 'chatter', 10)
    executor.add_node(talker)
    publisher.publish(std_msgs.String(data='early'))
    spin_ready(executor)
    assert heard == []
    executor.add_node(listener)
    spin_ready(executor)
    assert [m.data for m in heard] == ['early']


def test_destroyed_publisher_refuses_to_publish(executor) -> None:
    node = Node('gone')
    publisher = node.create_publisher(std_msgs.String, 'x', 10)
    assert node.destroy_publisher(publisher)
    assert not node.destroy_publisher(publisher)
    with pytest.raises(InvalidHandle):
        publisher.publish(std_msgs.String())
    assert node.count_publishers('x') == 0


def test_destroyed_subscription_gets_no_queued_messages(executor) -> None:
    node = Node('quitter')
    received = []
    subscription = node.create_subscription(std_msgs.String, 'x', received.append, 10)
    node.create_publisher(std_msgs.String, 'x', 10).publish(std_msgs.String(data='late'))
    node.destroy_subscription(subscription)
    executor.add_node(node)
    spin_ready(executor)
    assert received == []


def test_a_clock_topic_of_another_type_is_just_a_topic(executor) -> None:
    node = Node('odd')
    received = recorder(node, std_msgs.String, '/clock', 10)
    node.create_publisher(std_msgs.String, '/clock', 10).publish(std_msgs.String(data='tick'))
    executor.add_node(node)
    spin_ready(executor)
    assert [m.data for m in received] == ['tick']
    assert sim_time_s() is None
