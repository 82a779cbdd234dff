"""Graph introspection of the built-in runtime: endpoint info by topic, topic names and types."""

from __future__ import annotations

from collections.abc import Iterator

import pytest
from swarm_runtime.builtin.duration import Duration, Infinite
from swarm_runtime.builtin.exceptions import InvalidTopicNameException
from swarm_runtime.builtin.node import Node
from swarm_runtime.builtin.qos import (
    DurabilityPolicy,
    HistoryPolicy,
    LivelinessPolicy,
    QoSProfile,
    ReliabilityPolicy,
    qos_profile_sensor_data,
)
from swarm_runtime.builtin.topic_endpoint_info import TopicEndpointInfo, TopicEndpointTypeEnum
from swarm_runtime.builtin.type_hash import TypeHash
from swarm_runtime.messages import get_message_module, get_typestore

from swarm_runtime import builtin as rclpy

std_msgs = get_message_module('std_msgs')

LATCHED = QoSProfile(depth=1, durability=DurabilityPolicy.TRANSIENT_LOCAL)


@pytest.fixture
def ros() -> Iterator[None]:
    rclpy.init(args=['test'])
    yield
    rclpy.try_shutdown()


def _ignore(msg: object) -> None:
    del msg


def test_publishers_info_names_node_type_hash_and_kind(ros: None) -> None:
    node = Node('site', namespace='sim')
    node.create_publisher(std_msgs.String, 'layout', LATCHED)

    (info,) = node.get_publishers_info_by_topic('/sim/layout')

    assert (info.node_name, info.node_namespace) == ('site', '/sim')
    assert info.topic_type == 'std_msgs/msg/String'
    assert info.endpoint_type == TopicEndpointTypeEnum.PUBLISHER
    assert str(info.topic_type_hash) == get_typestore().hash_rihs01('std_msgs/msg/String')
    assert info.topic_type_hash.version == 1


def test_announced_qos_has_the_resolved_policies_and_no_history(ros: None) -> None:
    node = Node('site', namespace='sim')
    node.create_publisher(std_msgs.String, 'layout', LATCHED)
    node.create_publisher(std_msgs.String, 'scan', qos_profile_sensor_data)

    (latched,) = node.get_publishers_info_by_topic('/sim/layout')
    (sensor,) = node.get_publishers_info_by_topic('/sim/scan')

    assert latched.qos_profile.durability == DurabilityPolicy.TRANSIENT_LOCAL
    assert latched.qos_profile.reliability == ReliabilityPolicy.RELIABLE
    assert sensor.qos_profile.reliability == ReliabilityPolicy.BEST_EFFORT
    assert sensor.qos_profile.durability == DurabilityPolicy.VOLATILE
    # DDS discovery carries no history; rmw reports it as UNKNOWN with depth 0.
    assert latched.qos_profile.history == HistoryPolicy.UNKNOWN
    assert latched.qos_profile.depth == 0
    # Unspecified durations and liveliness are reported as the middleware resolved them.
    assert latched.qos_profile.deadline == Infinite
    assert latched.qos_profile.liveliness == LivelinessPolicy.AUTOMATIC


def test_system_default_publisher_qos_is_reported_as_the_middleware_resolves_it(
    ros: None,
) -> None:
    node = Node('talker')
    defaults = QoSProfile(
        depth=1,
        reliability=ReliabilityPolicy.SYSTEM_DEFAULT,
        durability=DurabilityPolicy.SYSTEM_DEFAULT,
        deadline=Duration(seconds=0.5),
    )
    node.create_publisher(std_msgs.String, 'chatter', defaults)

    (info,) = node.get_publishers_info_by_topic('chatter')

    assert info.qos_profile.reliability == ReliabilityPolicy.RELIABLE
    assert info.qos_profile.durability == DurabilityPolicy.VOLATILE
    assert info.qos_profile.deadline == Duration(seconds=0.5)


def test_subscriptions_info_reports_the_reliability_a_best_available_subscription_got(
    ros: None,
) -> None:
    talker = Node('talker')
    listener = Node('listener', namespace='r1')
    talker.create_publisher(std_msgs.String, '/chatter', qos_profile_sensor_data)
    best_available = QoSProfile(depth=1, reliability=ReliabilityPolicy.BEST_AVAILABLE)
    listener.create_subscription(std_msgs.String, '/chatter', _ignore, best_available)
    listener.create_subscription(std_msgs.String, '/chatter', _ignore, 10)

    infos = talker.get_subscriptions_info_by_topic('/chatter')

    assert [info.endpoint_type for info in infos] == [TopicEndpointTypeEnum.SUBSCRIPTION] * 2
    assert [(info.node_name, info.node_namespace) for info in infos] == [('listener', '/r1')] * 2
    assert [info.qos_profile.reliability for info in infos] == [
        ReliabilityPolicy.BEST_EFFORT,
        ReliabilityPolicy.RELIABLE,
    ]
    assert talker.get_publishers_info_by_topic('/nobody') == []


def test_topic_names_are_expanded_and_remapped_as_for_entities(ros: None) -> None:
    node = Node('talker', namespace='r0', cli_args=['--ros-args', '-r', 'chatter:=talk'])
    publisher = node.create_publisher(std_msgs.String, 'chatter', 10)
    assert publisher.topic_name == '/r0/talk'

    assert len(node.get_publishers_info_by_topic('chatter')) == 1
    assert len(node.get_publishers_info_by_topic('talk')) == 1
    assert len(node.get_publishers_info_by_topic('/r0/talk')) == 1
    # The remapping rule applies to the fully qualified name as well.
    assert len(node.get_publishers_info_by_topic('/r0/chatter')) == 1
    assert node.get_publishers_info_by_topic('/talk') == []
    with pytest.raises(InvalidTopicNameException):
        node.get_publishers_info_by_topic('bad name')


def test_no_mangle_takes_the_topic_name_as_given(ros: None) -> None:
    node = Node('talker', namespace='r0')
    node.create_publisher(std_msgs.String, 'chatter', 10)

    assert len(node.get_publishers_info_by_topic('/r0/chatter', no_mangle=True)) == 1
    assert node.get_publishers_info_by_topic('chatter', no_mangle=True) == []


def test_every_endpoint_has_its_own_16_byte_gid(ros: None) -> None:
    first = Node('first')
    second = Node('second')
    first.create_publisher(std_msgs.String, '/chatter', 10)
    second.create_publisher(std_msgs.String, '/chatter', 10)
    first.create_subscription(std_msgs.String, '/chatter', _ignore, 10)

    infos = [
        *first.get_publishers_info_by_topic('/chatter'),
        *first.get_subscriptions_info_by_topic('/chatter'),
    ]

    gids = [tuple(info.endpoint_gid) for info in infos]
    assert all(len(gid) == 16 and all(0 <= byte < 256 for byte in gid) for gid in gids)
    assert len(set(gids)) == 3
    # One DDS participant per context: the GUID prefix is shared, the entity id is not.
    assert len({gid[:12] for gid in gids}) == 1


def test_destroyed_endpoints_leave_the_info_and_the_topic_list(ros: None) -> None:
    node = Node('talker')
    publisher = node.create_publisher(std_msgs.String, '/chatter', 10)
    assert ('/chatter', ['std_msgs/msg/String']) in node.get_topic_names_and_types()

    node.destroy_publisher(publisher)

    assert node.get_publishers_info_by_topic('/chatter') == []
    assert '/chatter' not in dict(node.get_topic_names_and_types())
    node.create_subscription(std_msgs.Int32, '/chatter', _ignore, 10)
    assert dict(node.get_topic_names_and_types())['/chatter'] == ['std_msgs/msg/Int32']


def test_topic_names_and_types_answers_cannot_be_altered_by_the_caller(ros: None) -> None:
    node = Node('talker')
    node.create_publisher(std_msgs.String, '/chatter', 10)
    answer = node.get_topic_names_and_types()
    answer.clear()
    dict(node.get_topic_names_and_types())['/chatter'].append('garbage')
    assert dict(node.get_topic_names_and_types())['/chatter'] == ['std_msgs/msg/String']


def test_endpoint_info_prints_like_ros2_topic_info_verbose(ros: None) -> None:
    node = Node('site', namespace='sim')
    node.create_publisher(std_msgs.String, 'layout', LATCHED)
    (info,) = node.get_publishers_info_by_topic('layout')

    lines = str(info).splitlines()

    assert lines[0] == 'Node name: site'
    assert lines[4] == 'Endpoint type: PUBLISHER'
    assert lines[5] == 'GID: ' + '.'.join(f'{byte:02x}' for byte in info.endpoint_gid)
    assert '  History (Depth): UNKNOWN' in lines
    assert '  Durability: TRANSIENT_LOCAL' in lines
    assert '  Deadline: Infinite' in lines
    keep_last = TopicEndpointInfo(qos_profile=QoSProfile(depth=7))
    assert '  History (Depth): KEEP_LAST (7)' in str(keep_last).splitlines()


def test_endpoint_info_accepts_rmw_dictionaries_and_checks_types() -> None:
    value = bytes(range(32))
    info = TopicEndpointInfo(
        node_name='n',
        topic_type_hash={'version': 1, 'value': value},
        endpoint_type=2,
        endpoint_gid=[1, 2, 3],
        qos_profile={'depth': 3, 'reliability': ReliabilityPolicy.BEST_EFFORT},
    )
    assert info.endpoint_type is TopicEndpointTypeEnum.SUBSCRIPTION
    assert info.topic_type_hash == TypeHash(version=1, value=value)
    assert info.qos_profile.depth == 3
    assert info == TopicEndpointInfo(
        node_name='n',
        topic_type_hash=TypeHash(1, value),
        endpoint_type=TopicEndpointTypeEnum.SUBSCRIPTION,
        endpoint_gid=[1, 2, 3],
        qos_profile=QoSProfile(depth=3, reliability=ReliabilityPolicy.BEST_EFFORT),
    )
    with pytest.raises(AssertionError):
        info.node_name = 3  # type: ignore[assignment]
    with pytest.raises(AssertionError):
        info.endpoint_gid = ['a']  # type: ignore[list-item]


def test_type_hash_text_is_rihs_version_and_hex_or_invalid() -> None:
    value = bytes(range(32))
    assert str(TypeHash(version=1, value=value)) == 'RIHS01_' + value.hex()
    assert str(TypeHash()) == 'INVALID'
    assert TypeHash._from_text('RIHS01_' + value.hex()) == TypeHash(1, value)
    assert TypeHash._from_text('') == TypeHash()
    assert TypeHash._from_text('RIHS01_abc') == TypeHash()


def test_endpoint_info_is_exported_like_rclpy_modules() -> None:
    assert rclpy.topic_endpoint_info.TopicEndpointInfo is TopicEndpointInfo
    assert rclpy.type_hash.TypeHash is TypeHash
