"""The bridge's transform tree and markers, as a viewer (Foxglove, RViz) receives them.

Each test runs a standalone bridge on the five-room layout with two robots driven by a
cmd_vel publisher, on the built-in runtime or on real rclpy (over DDS on this machine);
tf2_msgs has no wheel for pip installs of real rclpy, so there the tests are skipped unless
it is installed.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
from sim_bridge.bridge_node import SimBridgeNode
from sim_bridge.frames import compose
from swarm_common.angles import yaw_from_quaternion
from swarm_common.stamps import stamp_to_seconds
from swarm_runtime.bag.testing import spin_until
from swarm_runtime.ros import (
    Node,
    Parameter,
    QoSDurabilityPolicy,
    QoSProfile,
    SingleThreadedExecutor,
    message_module,
    qos_profile_sensor_data,
    rclpy,
    using_real_rclpy,
)

try:
    tf2_msgs = message_module('tf2_msgs')
    visualization_msgs = message_module('visualization_msgs')
except ImportError as err:  # real rclpy from pip: no tf2_msgs wheel
    pytest.skip(f'tf2_msgs / visualization_msgs not importable: {err}', allow_module_level=True)

FIVE_ROOMS = Path(__file__).parent / 'data' / 'five_rooms.lay'
ROBOTS = ('r0', 'r1')
# Host-time budget of one wait; on DDS the bridge runs at real_time_factor REAL_TIME_FACTOR.
WAIT_S = 60.0
REAL_TIME_FACTOR = 5.0 if using_real_rclpy() else 1.0
LATCHED = QoSProfile(depth=1, durability=QoSDurabilityPolicy.TRANSIENT_LOCAL)
geometry_msgs = message_module('geometry_msgs')
nav_msgs = message_module('nav_msgs')
sensor_msgs = message_module('sensor_msgs')
swarm = message_module('swarm_interfaces')


@pytest.fixture
def executor():
    # The DDS domain and the discovery range are the test process's (conftest.py).
    rclpy.init()
    executor = SingleThreadedExecutor()
    yield executor
    for node in list(executor.get_nodes()):
        executor.remove_node(node)
        node.destroy_node()
    executor.shutdown()
    rclpy.try_shutdown()


class Recorder(Node):
    """Keeps every message of the given topics; drives both robots along arcs."""

    def __init__(self, topics, *, drive: bool = True) -> None:
        super().__init__('viewer', parameter_overrides=[Parameter('use_sim_time', value=True)])
        self.got = {}
        for topic, msg_type, qos in topics:
            self.got[topic] = []
            self.create_subscription(msg_type, topic, self.got[topic].append, qos)
        if drive:
            self._cmd = [
                self.create_publisher(geometry_msgs.Twist, f'/{r}/cmd_vel', 10) for r in ROBOTS
            ]
            self.create_timer(0.05, self._drive)

    def _drive(self) -> None:
        for i, publisher in enumerate(self._cmd):
            cmd = geometry_msgs.Twist()
            cmd.linear.x = 0.25
            cmd.angular.z = 0.3 if i == 0 else -0.2
            publisher.publish(cmd)


def bridge(**params) -> SimBridgeNode:
    values = {
        'site_file': str(FIVE_ROOMS),
        'robot_count': len(ROBOTS),
        'departure': 'edge',
        'real_time_factor': REAL_TIME_FACTOR,
        **params,
    }
    return SimBridgeNode(parameter_overrides=[Parameter(k, value=v) for k, v in values.items()])


def run_until(executor, node: SimBridgeNode, time_s: float) -> None:
    assert spin_until(executor, lambda: node.sim_time_s >= time_s, timeout_s=WAIT_S)


def pose_of(transform) -> tuple[float, float, float]:
    t, q = transform.translation, transform.rotation
    return t.x, t.y, yaw_from_quaternion(q.x, q.y, q.z, q.w)


def odometry_by_stamp(messages):
    return {(m.header.stamp.sec, m.header.stamp.nanosec): m for m in messages}


def static_tree(messages) -> dict[str, object]:
    """child frame -> TransformStamped of every /tf_static message."""
    return {t.child_frame_id: t for m in messages for t in m.transforms}


TOPICS = [
    ('/tf', tf2_msgs.TFMessage, QoSProfile(depth=100)),
    ('/tf_static', tf2_msgs.TFMessage, QoSProfile(depth=100, durability=LATCHED.durability)),
    ('/r0/odom', nav_msgs.Odometry, qos_profile_sensor_data),
    ('/r1/odom', nav_msgs.Odometry, qos_profile_sensor_data),
    ('/sim/poses', swarm.TruePoseArray, 10),
]


def test_tf_carries_the_published_odometry_and_lands_on_the_true_pose(executor) -> None:
    node = bridge()
    viewer = Recorder(TOPICS)
    for n in (node, viewer):
        executor.add_node(n)
    run_until(executor, node, 6.0)
    got = viewer.got
    assert got['/tf'], 'no /tf message'
    tree = static_tree(got['/tf_static'])
    odometry = {r: odometry_by_stamp(got[f'/{r}/odom']) for r in ROBOTS}
    truth = {
        (m.header.stamp.sec, m.header.stamp.nanosec): {p.robot: (p.x, p.y, p.yaw) for p in m.poses}
        for m in got['/sim/poses']
    }
    compared = matched_truth = 0
    for message in got['/tf']:
        assert [t.child_frame_id for t in message.transforms] == [f'{r}/base_link' for r in ROBOTS]
        for robot, transform in zip(ROBOTS, message.transforms, strict=True):
            assert transform.header.frame_id == f'{robot}/odom'
            stamp = (transform.header.stamp.sec, transform.header.stamp.nanosec)
            odom = odometry[robot].get(stamp)
            if odom is not None:
                # The same numbers as the odometry message of the same stamp.
                assert odom.header.frame_id == transform.header.frame_id
                assert odom.child_frame_id == transform.child_frame_id
                pose = odom.pose.pose
                assert (pose.position.x, pose.position.y, pose.position.z) == (
                    transform.transform.translation.x,
                    transform.transform.translation.y,
                    transform.transform.translation.z,
                )
                assert pose.orientation == transform.transform.rotation
                compared += 1
            if stamp in truth:
                in_map = compose(
                    pose_of(tree[f'{robot}/odom'].transform), pose_of(transform.transform)
                )
                x, y, yaw = truth[stamp][robot]
                assert in_map[:2] == pytest.approx((x, y), abs=1e-9)
                assert math.cos(in_map[2] - yaw) == pytest.approx(1.0, abs=1e-12)
                matched_truth += 1
    assert compared >= 40
    assert matched_truth >= 10
    # The robots did move: the last transform is far from the first.
    first, last = got['/tf'][0].transforms[0], got['/tf'][-1].transforms[0]
    assert math.dist(pose_of(first.transform)[:2], pose_of(last.transform)[:2]) > 0.5


def test_with_odometry_noise_the_tree_follows_the_odometry_and_drifts_from_the_truth(
    executor,
) -> None:
    node = bridge(odom_distance_noise_fraction=0.2, odom_rotation_noise_fraction=0.2)
    viewer = Recorder(TOPICS)
    for n in (node, viewer):
        executor.add_node(n)
    run_until(executor, node, 6.0)
    got = viewer.got
    tree = static_tree(got['/tf_static'])
    odometry = odometry_by_stamp(got['/r0/odom'])
    last_truth = got['/sim/poses'][-1]
    stamp = (last_truth.header.stamp.sec, last_truth.header.stamp.nanosec)
    tf = next(
        t
        for m in reversed(got['/tf'])
        for t in m.transforms
        if t.child_frame_id == 'r0/base_link'
        and (t.header.stamp.sec, t.header.stamp.nanosec) == stamp
    )
    assert odometry[stamp].pose.pose.position.x == tf.transform.translation.x
    believed = compose(pose_of(tree['r0/odom'].transform), pose_of(tf.transform))
    true = next(p for p in last_truth.poses if p.robot == 'r0')
    error_m = math.hypot(believed[0] - true.x, believed[1] - true.y)
    travelled_m = float(node.engine.distance_travelled_m[0])
    # Odometry, not the truth: off by some drift, bounded by the noise on the distance.
    assert 1e-6 < error_m < 0.6 * travelled_m


def test_tf_static_is_latched_for_a_late_subscriber_and_names_the_message_frames(
    executor,
) -> None:
    node = bridge()
    sensors = Recorder(
        [
            ('/r0/scan', sensor_msgs.LaserScan, qos_profile_sensor_data),
            ('/r0/imu', sensor_msgs.Imu, qos_profile_sensor_data),
            ('/r0/gas', swarm.GasReading, qos_profile_sensor_data),
            ('/r0/bearings', swarm.PeerBearingArray, qos_profile_sensor_data),
            ('/r0/odom', nav_msgs.Odometry, qos_profile_sensor_data),
        ]
    )
    for n in (node, sensors):
        executor.add_node(n)
    run_until(executor, node, 2.0)
    late = Recorder([('/tf_static', tf2_msgs.TFMessage, LATCHED)], drive=False)
    volatile = []
    late.create_subscription(tf2_msgs.TFMessage, '/tf_static', volatile.append, 10)
    executor.add_node(late)
    assert spin_until(executor, lambda: late.got['/tf_static'], timeout_s=WAIT_S)
    run_until(executor, node, 3.0)
    assert len(late.got['/tf_static']) == 1
    assert volatile == []  # what a late subscriber gets comes from the latched history
    tree = static_tree(late.got['/tf_static'])
    expected = {}
    for robot in ROBOTS:
        expected[f'{robot}/odom'] = 'map'
        for frame in ('laser', 'imu_link', 'gas_sensor'):
            expected[f'{robot}/{frame}'] = f'{robot}/base_link'
    assert {child: t.header.frame_id for child, t in tree.items()} == expected
    # Every frame a message of r0 names is in the tree (or is its odometry child).
    frames = {m.header.frame_id for topic in sensors.got.values() for m in topic}
    frames |= {m.child_frame_id for m in sensors.got['/r0/odom']}
    assert frames == {'r0/laser', 'r0/imu_link', 'r0/gas_sensor', 'r0/base_link', 'r0/odom'}
    assert frames - {'r0/base_link'} <= set(tree)
    gas = tree['r0/gas_sensor'].transform.translation
    assert (gas.x, gas.y, gas.z) == (node.config.gas.sensor_offset_m, 0.0, 0.0)
    # The simulator's odometry starts on the true start pose: map -> odom is the identity.
    assert pose_of(tree['r0/odom'].transform) == (0.0, 0.0, 0.0)


def test_tf_rate_is_capped_below_a_faster_odometry(executor) -> None:
    node = bridge(physics_rate_hz=20.0, odom_rate_hz=20.0, tf_rate_hz=5.0)
    viewer = Recorder(TOPICS[:1] + TOPICS[2:3])
    for n in (node, viewer):
        executor.add_node(n)
    run_until(executor, node, 4.0)
    odom_stamps = [stamp_to_seconds(m.header.stamp) for m in viewer.got['/r0/odom']]
    tf_stamps = [stamp_to_seconds(m.transforms[0].header.stamp) for m in viewer.got['/tf']]
    assert np.diff(odom_stamps) == pytest.approx(0.05, abs=1e-6)
    assert np.diff(tf_stamps) == pytest.approx(0.2, abs=1e-6)
    assert set(np.round(tf_stamps, 6)) <= set(np.round(odom_stamps, 6))


MARKER_TOPICS = (
    '/sim/markers/site',
    '/sim/markers/rooms',
    '/sim/markers/robots',
    '/sim/markers/paths',
)


def test_markers_latch_the_site_the_rooms_by_coverage_the_robots_and_their_paths(
    executor,
) -> None:
    node = bridge(path_rate_hz=1.0)
    driver = Recorder([])
    # The paths are built while somebody listens: a listener from the start.
    paths = []
    driver.create_subscription(
        visualization_msgs.MarkerArray, MARKER_TOPICS[3], paths.append, LATCHED
    )
    for n in (node, driver):
        executor.add_node(n)
    run_until(executor, node, 8.0)
    late = Recorder(
        [(t, visualization_msgs.MarkerArray, LATCHED) for t in MARKER_TOPICS], drive=False
    )
    executor.add_node(late)
    assert spin_until(executor, lambda: all(late.got.values()), timeout_s=WAIT_S)
    marker = visualization_msgs.Marker
    engine = node.engine
    got = {topic: messages[-1].markers for topic, messages in late.got.items()}

    walls = [m for m in got['/sim/markers/site'] if m.ns == 'walls']
    assert len(walls) == 1
    assert walls[0].type == marker.LINE_LIST
    assert len(walls[0].points) == 2 * len(engine.site.walls)
    labels = [m for m in got['/sim/markers/site'] if m.ns == 'room_labels']
    assert len(labels) == engine.coverage.rooms_total

    rooms = {m.id: m for m in got['/sim/markers/rooms']}
    first = {e.room_index: e.robot_index for e in engine.coverage.entries}
    assert first, 'no room was entered'
    for group in range(len(ROBOTS) + 1):
        count = (
            sum(1 for v in first.values() if v + 1 == group)
            if group
            else (engine.coverage.rooms_total - len(first))
        )
        assert (rooms[group].action == marker.DELETE) == (count == 0)
    visited = rooms[first[min(first)] + 1]
    assert visited.type == marker.TRIANGLE_LIST
    assert len(visited.points) % 3 == 0
    assert visited.header.frame_id == 'map'

    robots = got['/sim/markers/robots']
    assert {m.header.frame_id for m in robots} == {f'{r}/base_link' for r in ROBOTS}
    assert all(m.frame_locked for m in robots)

    strips = {m.id: m for m in got['/sim/markers/paths']}
    assert set(strips) == {0, 1}
    assert all(m.type == marker.LINE_STRIP and m.header.frame_id == 'map' for m in strips.values())
    last_path_s = stamp_to_seconds(strips[0].header.stamp)
    assert last_path_s == pytest.approx(8.0, abs=1.0)
    for i, strip in strips.items():
        end = (strip.points[-1].x, strip.points[-1].y)
        # The path ends where the robot was when it was sent (it moves 0.25 m/s).
        assert (
            math.dist(end, engine.world.poses[i, :2])
            < 0.25 * (node.sim_time_s - last_path_s) + 0.15
        )
        # Simplified: far fewer vertices than the 2 Hz samples of 8 s.
        assert 2 <= len(strip.points) < 16
    assert len(paths) >= 5
