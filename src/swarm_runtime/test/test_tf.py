"""Transforms without tf2: the message types, their Jazzy hashes and the two publishers.

Runs on the built-in runtime and on real rclpy (over DDS on this machine); pip installs of
real rclpy have no tf2_msgs, and there the module is skipped.
"""

from __future__ import annotations

import math
from collections.abc import Iterator
from typing import Any

import pytest
from swarm_runtime.bag.testing import spin_until
from swarm_runtime.ros import Node, SingleThreadedExecutor, message_module, rclpy
from swarm_runtime.tf import (
    TF_STATIC_TOPIC,
    TF_TOPIC,
    PlanarTransform,
    StaticTransformPublisher,
    TransformPublisher,
    tf_message,
    tf_static_qos,
    transform_stamped,
)

try:
    tf2_msgs = message_module('tf2_msgs')
    visualization_msgs = message_module('visualization_msgs')
except ImportError as err:
    pytest.skip(f'tf2_msgs / visualization_msgs not importable: {err}', allow_module_level=True)

WAIT_S = 20.0
# RIHS01 hashes of the ROS 2 Jazzy definitions: TFMessage as `ros2 topic info --verbose`
# reports it on Jazzy, the others from the type descriptions installed with Jazzy's
# geometry_msgs and visualization_msgs 5.3 (share/<pkg>/msg/<Type>.json).
JAZZY_HASHES = {
    'tf2_msgs/msg/TFMessage': (
        'RIHS01_e369d0f05a23ae52508854b66f6aa0437f3449d652e8cbf22d5abe85d020f087'
    ),
    'geometry_msgs/msg/TransformStamped': (
        'RIHS01_0a241f87d04668d94099cbb5ba11691d5ad32c2f29682e4eb5653424bd275206'
    ),
    'visualization_msgs/msg/Marker': (
        'RIHS01_45b13ccf791f225962bf74e746f9644518855d783a6f42ba0cc14fde2b4f3ce0'
    ),
    'visualization_msgs/msg/MarkerArray': (
        'RIHS01_86cb8800b6fb05b5eff1abd7a56f62a5641d3ae9a1c29e78e67e704f1d067dcf'
    ),
}


@pytest.fixture
def executor() -> Iterator[Any]:
    # The DDS domain and the discovery range are the test process's (conftest.py).
    rclpy.init()
    executor = SingleThreadedExecutor()
    yield executor
    for node in list(executor.get_nodes()):
        executor.remove_node(node)
        node.destroy_node()
    executor.shutdown()
    rclpy.try_shutdown()


@pytest.mark.parametrize('typename', sorted(JAZZY_HASHES))
def test_the_runtime_advertises_the_jazzy_type_hash(executor: Any, typename: str) -> None:
    package, _, name = typename.split('/')
    node = Node('hash_probe')
    executor.add_node(node)
    topic = f'/probe_{name.lower()}'
    node.create_publisher(getattr(message_module(package), name), topic, 10)
    assert spin_until(executor, lambda: node.get_publishers_info_by_topic(topic), timeout_s=WAIT_S)
    (info,) = node.get_publishers_info_by_topic(topic)
    assert info.topic_type == typename
    assert str(info.topic_type_hash) == JAZZY_HASHES[typename]


def test_a_planar_transform_becomes_a_transform_stamped() -> None:
    msg = transform_stamped(PlanarTransform('r0/odom', 'r0/base_link', 1.5, -2.0, 0.1, 0.5), 12.25)
    assert (msg.header.frame_id, msg.child_frame_id) == ('r0/odom', 'r0/base_link')
    assert (msg.header.stamp.sec, msg.header.stamp.nanosec) == (12, 250_000_000)
    t, q = msg.transform.translation, msg.transform.rotation
    assert (t.x, t.y, t.z) == (1.5, -2.0, 0.1)
    assert (q.x, q.y) == (0.0, 0.0)
    assert 2.0 * math.atan2(q.z, q.w) == pytest.approx(0.5)
    whole = tf_message([PlanarTransform('a', 'b'), PlanarTransform('b', 'c', x_m=1.0)], 1.0)
    assert [m.child_frame_id for m in whole.transforms] == ['b', 'c']
    assert whole.transforms[0].transform.rotation.w == 1.0


def test_static_transforms_are_latched_as_one_growing_set(executor: Any) -> None:
    node = Node('static_owner')
    executor.add_node(node)
    static = StaticTransformPublisher(node)
    static.send([PlanarTransform('base', 'laser', x_m=0.1)], 0.0)
    static.send([PlanarTransform('base', 'imu', z_m=0.05)], 0.0)
    static.send([PlanarTransform('base', 'laser', x_m=0.2)], 0.0)  # replaces the laser
    assert static.child_frames == ('laser', 'imu')
    late = Node('late')
    got: list[Any] = []
    late.create_subscription(tf2_msgs.TFMessage, TF_STATIC_TOPIC, got.append, tf_static_qos())
    executor.add_node(late)
    assert spin_until(executor, lambda: got, timeout_s=WAIT_S)
    spin_until(executor, lambda: len(got) > 1, timeout_s=0.5)
    # Depth 1: a late subscriber gets the latest, complete set once.
    assert len(got) == 1
    frames = {t.child_frame_id: t.transform.translation for t in got[0].transforms}
    assert set(frames) == {'laser', 'imu'}
    assert frames['laser'].x == 0.2
    assert frames['imu'].z == 0.05
    (info,) = late.get_publishers_info_by_topic(TF_STATIC_TOPIC)
    assert info.qos_profile.durability == tf_static_qos().durability


def test_moving_frames_go_out_on_tf_only_to_subscribers(executor: Any) -> None:
    node = Node('mover')
    executor.add_node(node)
    tf = TransformPublisher(node)
    assert not tf.wanted()
    got: list[Any] = []
    listener = Node('listener')
    listener.create_subscription(tf2_msgs.TFMessage, TF_TOPIC, got.append, 100)
    executor.add_node(listener)
    assert spin_until(executor, tf.wanted, timeout_s=WAIT_S)
    tf.send([PlanarTransform('r0/odom', 'r0/base_link', 1.0, 2.0, 0.0, 1.0)], 3.0)
    assert spin_until(executor, lambda: got, timeout_s=WAIT_S)
    (transform,) = got[0].transforms
    assert transform.header.stamp.sec == 3
    assert (transform.transform.translation.x, transform.transform.translation.y) == (1.0, 2.0)
