"""Node names, namespaces, topic name resolution and remapping in the built-in runtime."""

from __future__ import annotations

from collections.abc import Iterator

import pytest
from swarm_runtime.builtin.exceptions import (
    InvalidNamespaceException,
    InvalidNodeNameException,
    InvalidTopicNameException,
)
from swarm_runtime.builtin.node import Node
from swarm_runtime.builtin.utilities import remove_ros_args
from swarm_runtime.messages import get_message_module

from swarm_runtime import builtin as rclpy

std_msgs = get_message_module('std_msgs')


@pytest.fixture
def init() -> Iterator[None]:
    yield None
    rclpy.try_shutdown()


def start(*ros_args: str) -> None:
    rclpy.init(args=['prog', '--ros-args', *ros_args] if ros_args else ['prog'])


def test_namespace_is_made_absolute_and_joins_the_fully_qualified_name(init) -> None:
    start()
    node = Node('a', namespace='r0')
    assert node.get_namespace() == '/r0'
    assert node.get_fully_qualified_name() == '/r0/a'
    assert Node('b').get_fully_qualified_name() == '/b'


@pytest.mark.parametrize(
    ('topic', 'resolved'),
    [
        ('scan', '/r0/scan'),
        ('sensors/scan', '/r0/sensors/scan'),
        ('/clock', '/clock'),
        ('~/debug', '/r0/algo/debug'),
        ('~', '/r0/algo'),
        ('{node}/state', '/r0/algo/state'),
    ],
)
def test_topic_names_resolve_like_rcl(init, topic: str, resolved: str) -> None:
    start()
    node = Node('algo', namespace='/r0')
    assert node.resolve_topic_name(topic) == resolved


def test_private_name_of_a_root_node(init) -> None:
    start()
    assert Node('probe').resolve_topic_name('~/x') == '/probe/x'


def test_publisher_topic_name_is_resolved(init) -> None:
    start()
    publisher = Node('algo', namespace='r2').create_publisher(std_msgs.String, 'cmd_vel', 10)
    assert publisher.topic_name == '/r2/cmd_vel'
    assert publisher.topic == 'cmd_vel'


@pytest.mark.parametrize('bad', ['', 'a b', '1scan', 'scan/', 'a//b', 'x~', '~x', '{unclosed'])
def test_invalid_topic_names_raise(init, bad: str) -> None:
    start()
    node = Node('algo')
    with pytest.raises(InvalidTopicNameException):
        node.create_publisher(std_msgs.String, bad, 10)


def test_invalid_topic_name_error_points_at_the_offending_character(init) -> None:
    start()
    with pytest.raises(InvalidTopicNameException) as error:
        Node('algo').create_subscription(std_msgs.String, 'ok/b@d', lambda m: None, 10)
    assert "'ok/b@d'" in str(error.value)
    assert str(error.value).endswith(' ' * 7 + '^')


@pytest.mark.parametrize('bad', ['', 'my-node', '9lives', 'a/b'])
def test_invalid_node_names_raise(init, bad: str) -> None:
    start()
    with pytest.raises(InvalidNodeNameException):
        Node(bad)


@pytest.mark.parametrize('bad', ['/r0/', '/r0//x', '/0r'])
def test_invalid_namespaces_raise(init, bad: str) -> None:
    start()
    with pytest.raises(InvalidNamespaceException):
        Node('algo', namespace=bad)


def test_unknown_substitution_is_an_invalid_topic_name(init) -> None:
    start()
    with pytest.raises(InvalidTopicNameException, match='unknown substitution'):
        Node('algo').resolve_topic_name('{robot}/scan')


def test_namespace_remap_replaces_the_constructor_namespace(init) -> None:
    start('-r', '__ns:=/r3')
    node = Node('algo', namespace='r0')
    assert node.get_fully_qualified_name() == '/r3/algo'
    assert node.resolve_topic_name('scan') == '/r3/scan'


def test_node_name_remap(init) -> None:
    start('-r', '__node:=renamed')
    node = Node('algo')
    assert node.get_name() == 'renamed'
    assert node.get_logger().name == 'renamed'


def test_topic_remap_applies_to_expanded_names(init) -> None:
    start('-r', 'scan:=lidar', '-r', '/clock:=/sim_clock')
    node = Node('algo', namespace='r0')
    assert node.resolve_topic_name('scan') == '/r0/lidar'
    assert node.resolve_topic_name('/r0/scan') == '/r0/lidar'
    assert node.resolve_topic_name('/clock') == '/sim_clock'
    assert node.resolve_topic_name('scan', only_expand=True) == '/r0/scan'


def test_node_specific_remap_only_applies_to_that_node(init) -> None:
    start('-r', 'talker:chatter:=talk')
    assert Node('talker').resolve_topic_name('chatter') == '/talk'
    assert Node('listener').resolve_topic_name('chatter') == '/chatter'


def test_node_cli_args_remap_before_global_ones(init) -> None:
    start('-r', 'chatter:=global_topic')
    local = Node('a', cli_args=['--ros-args', '-r', 'chatter:=local_topic'])
    assert local.resolve_topic_name('chatter') == '/local_topic'
    unaware = Node('b', cli_args=['--ros-args', '-r', 'x:=y'], use_global_arguments=False)
    assert unaware.resolve_topic_name('chatter') == '/chatter'


def test_remapped_publisher_and_subscription_meet(init) -> None:
    start('-r', 'listener:heard:=chatter')
    talker = Node('talker')
    listener = Node('listener')
    subscription = listener.create_subscription(std_msgs.String, 'heard', lambda m: None, 10)
    publisher = talker.create_publisher(std_msgs.String, 'chatter', 10)
    assert subscription.topic_name == '/chatter'
    assert publisher.get_subscription_count() == 1


def test_logger_name_follows_the_namespace(init) -> None:
    start()
    assert Node('algo', namespace='/r0').get_logger().name == 'r0.algo'


def test_graph_introspection_lists_topics_nodes_and_counts(init) -> None:
    start()
    talker = Node('talker', namespace='r1')
    talker.create_publisher(std_msgs.String, 'chatter', 10)
    Node('listener', namespace='r1').create_subscription(
        std_msgs.String, 'chatter', lambda m: None, 10
    )
    assert ('/r1/chatter', ['std_msgs/msg/String']) in talker.get_topic_names_and_types()
    assert talker.count_publishers('chatter') == 1
    assert talker.count_subscribers('/r1/chatter') == 1
    assert talker.get_fully_qualified_node_names() == ['/r1/talker', '/r1/listener']


def test_remove_ros_args_keeps_only_the_program_arguments() -> None:
    args = ['prog', '--speed', '2', '--ros-args', '-r', '__ns:=/r1', '-p', 'a:=1', '--', 'tail']
    assert remove_ros_args(args) == ['prog', '--speed', '2', 'tail']
