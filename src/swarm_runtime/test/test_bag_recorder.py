"""BagRecorder on the built-in runtime: discovery, topic selection, sim-time stamps, clean close."""

from __future__ import annotations

from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pytest
import yaml
from swarm_runtime.bag import BagRecorder, TruncatedBagWarning, read_bag_info, read_messages
from swarm_runtime.builtin.errors import BuiltinRuntimeUnsupported
from swarm_runtime.ros import (
    Node,
    Parameter,
    QoSDurabilityPolicy,
    QoSProfile,
    ReliabilityPolicy,
    message_module,
    qos_profile_sensor_data,
    rclpy,
)

std_msgs = message_module('std_msgs')


@pytest.fixture
def ros() -> Iterator[None]:
    """An initialised ROS context for one test."""
    rclpy.init()
    yield
    rclpy.try_shutdown()


class Counter(Node):
    """Publishes its count on ``count`` every 0.1 s of its clock."""

    def __init__(self, namespace: str, *, use_sim_time: bool = False) -> None:
        super().__init__(
            'counter',
            namespace=namespace,
            parameter_overrides=[Parameter('use_sim_time', value=use_sim_time)],
        )
        self.publisher = self.create_publisher(std_msgs.Int32, 'count', qos_profile_sensor_data)
        self.count = 0
        self.create_timer(0.1, self._tick)

    def _tick(self) -> None:
        self.publisher.publish(std_msgs.Int32(data=self.count))
        self.count += 1


class SimClock(Node):
    """Publishes /clock in 50 ms steps of wall time, starting at 50 ms."""

    def __init__(self) -> None:
        super().__init__('sim_clock')
        self.publisher = self.create_publisher(message_module('rosgraph_msgs').Clock, '/clock', 10)
        self.now_ns = 0
        self.create_timer(0.05, self._tick)

    def _tick(self) -> None:
        self.now_ns += 50_000_000
        stamp = message_module('builtin_interfaces').Time(
            sec=self.now_ns // 1_000_000_000, nanosec=self.now_ns % 1_000_000_000
        )
        self.publisher.publish(message_module('rosgraph_msgs').Clock(clock=stamp))


def _spin(executor: object, turns: int) -> None:
    for _ in range(turns):
        executor.spin_once(timeout_sec=1.0)


def test_records_chosen_topics_with_sim_time_stamps(ros: None, tmp_path: Path) -> None:
    executor = rclpy.executors.SingleThreadedExecutor()
    nodes = [SimClock(), Counter('r0', use_sim_time=True), Counter('r1', use_sim_time=True)]
    recorder = BagRecorder(tmp_path / 'bag', topics=['/r0/*'], use_sim_time=True)
    for node in [*nodes, recorder]:
        executor.add_node(node)
    _spin(executor, 150)
    recorder.destroy_node()

    info = read_bag_info(tmp_path / 'bag')
    assert set(info.topics) == {'/r0/count'}
    read = list(read_messages(tmp_path / 'bag'))
    assert [m.message.data for m in read] == list(range(len(read)))
    assert len(read) >= 5
    # Counter publishes at sim times 0.1 s, 0.2 s, ...: the stamps are sim time.
    assert [m.log_time_ns for m in read] == [100_000_000 * (i + 1) for i in range(len(read))]


def test_records_every_visible_topic_by_default_and_skips_excluded_and_hidden(
    ros: None, tmp_path: Path
) -> None:
    executor = rclpy.executors.SingleThreadedExecutor()
    counter = Counter('r0')
    hidden = counter.create_publisher(std_msgs.Int32, '_internal/state', 10)
    recorder = BagRecorder(tmp_path / 'bag', exclude=['/parameter_events'])
    executor.add_node(counter)
    executor.add_node(recorder)
    hidden.publish(std_msgs.Int32(data=1))
    _spin(executor, 30)
    recorder.destroy_node()
    assert set(read_bag_info(tmp_path / 'bag').topics) == {'/r0/count'}


def test_topics_that_appear_later_are_discovered(ros: None, tmp_path: Path) -> None:
    executor = rclpy.executors.SingleThreadedExecutor()
    recorder = BagRecorder(tmp_path / 'bag', topics=['/late/*'], discovery_period_s=0.5)
    executor.add_node(recorder)
    _spin(executor, 3)
    late = Counter('late')
    executor.add_node(late)
    _spin(executor, 60)
    recorder.destroy_node()
    read = list(read_messages(tmp_path / 'bag'))
    assert read
    assert {m.topic for m in read} == {'/late/count'}
    # Discovery runs every 0.5 s, so at most the first few counts are missed.
    assert read[0].message.data <= 5
    assert [m.message.data for m in read] == list(range(read[0].message.data, late.count))


def _metadata_qos(bag: Path, topic: str) -> list[dict[str, Any]]:
    """The offered_qos_profiles of ``topic`` as written in metadata.yaml."""
    metadata = yaml.safe_load((bag / 'metadata.yaml').read_text())
    for entry in metadata['rosbag2_bagfile_information']['topics_with_message_count']:
        if entry['topic_metadata']['name'] == topic:
            return entry['topic_metadata']['offered_qos_profiles']
    msg = f'{topic} is not in the metadata'
    raise AssertionError(msg)


class SitePublisher(Node):
    """Latches a site layout on /sim/site, as the sim bridge does."""

    def __init__(self) -> None:
        super().__init__('site_publisher')
        latched = QoSProfile(depth=1, durability=QoSDurabilityPolicy.TRANSIENT_LOCAL)
        self.publisher = self.create_publisher(std_msgs.String, '/sim/site', latched)
        self.publisher.publish(std_msgs.String(data='site layout'))


def test_latched_message_published_before_the_recorder_started_is_recorded_with_its_qos(
    ros: None, tmp_path: Path
) -> None:
    executor = rclpy.executors.SingleThreadedExecutor()
    site = SitePublisher()
    executor.add_node(site)
    _spin(executor, 3)
    recorder = BagRecorder(tmp_path / 'bag', topics=['/sim/site'])
    executor.add_node(recorder)
    _spin(executor, 5)
    recorder.destroy_node()

    assert [m.message.data for m in read_messages(tmp_path / 'bag')] == ['site layout']
    (profile,) = _metadata_qos(tmp_path / 'bag', '/sim/site')
    assert profile['durability'] == 'transient_local'
    assert profile['reliability'] == 'reliable'
    assert profile['history'] == 'unknown'


def test_each_publishers_offered_qos_is_recorded_and_the_subscription_matches_all(
    ros: None, tmp_path: Path
) -> None:
    executor = rclpy.executors.SingleThreadedExecutor()
    site = SitePublisher()
    volatile = Node('volatile_site')
    volatile_publisher = volatile.create_publisher(std_msgs.String, '/sim/site', 10)
    recorder = BagRecorder(tmp_path / 'bag', topics=['/sim/site'])
    for node in (site, volatile, recorder):
        executor.add_node(node)
    volatile_publisher.publish(std_msgs.String(data='live'))
    _spin(executor, 3)
    recorder.destroy_node()

    # One publisher is volatile, so the recorder cannot ask for history (it would not match
    # that publisher): the latched message before the recorder started is not recorded.
    assert [m.message.data for m in read_messages(tmp_path / 'bag')] == ['live']
    durabilities = [p['durability'] for p in _metadata_qos(tmp_path / 'bag', '/sim/site')]
    assert durabilities == ['transient_local', 'volatile']


def test_topics_created_after_the_recorder_started_are_recorded_from_the_next_discovery(
    ros: None, tmp_path: Path
) -> None:
    executor = rclpy.executors.SingleThreadedExecutor()
    recorder = BagRecorder(tmp_path / 'bag', topics=['/late/*', '/sim/*'])
    executor.add_node(recorder)
    _spin(executor, 3)
    late = Counter('late')
    site = SitePublisher()
    executor.add_node(late)
    executor.add_node(site)
    _spin(executor, 30)
    recorder.destroy_node()

    read = list(read_messages(tmp_path / 'bag'))
    counts = [m.message.data for m in read if m.topic == '/late/count']
    # The counter publishes every 0.1 s and discovery polls every 0.1 s: nothing is missed
    # (but the last count, if the spinning stopped right after it was published).
    assert counts == list(range(len(counts)))
    assert len(counts) >= late.count - 1 >= 5
    assert [m.message.data for m in read if m.topic == '/sim/site'] == ['site layout']


class LazyPublisher(Node):
    """Creates its publisher in a timer callback and publishes right away (same step)."""

    def __init__(self, qos: QoSProfile) -> None:
        super().__init__('lazy')
        self._qos = qos
        self.publisher: Any = None
        self._timer = self.create_timer(0.25, self._start)

    def _start(self) -> None:
        self.destroy_timer(self._timer)
        self.publisher = self.create_publisher(std_msgs.String, '/lazy/status', self._qos)
        self.publisher.publish(std_msgs.String(data='first'))


def test_a_latched_message_published_as_its_topic_is_created_is_recorded(
    ros: None, tmp_path: Path
) -> None:
    executor = rclpy.executors.SingleThreadedExecutor()
    recorder = BagRecorder(tmp_path / 'bag', topics=['/lazy/*'])
    lazy = LazyPublisher(QoSProfile(depth=1, durability=QoSDurabilityPolicy.TRANSIENT_LOCAL))
    executor.add_node(recorder)
    executor.add_node(lazy)
    _spin(executor, 10)
    lazy.publisher.publish(std_msgs.String(data='second'))
    _spin(executor, 3)
    recorder.destroy_node()
    assert [m.message.data for m in read_messages(tmp_path / 'bag')] == ['first', 'second']


def test_a_volatile_message_published_as_its_topic_is_created_is_missed_like_ros2_bag_record(
    ros: None, tmp_path: Path
) -> None:
    executor = rclpy.executors.SingleThreadedExecutor()
    recorder = BagRecorder(tmp_path / 'bag', topics=['/lazy/*'])
    lazy = LazyPublisher(QoSProfile(depth=10))
    executor.add_node(recorder)
    executor.add_node(lazy)
    _spin(executor, 10)
    lazy.publisher.publish(std_msgs.String(data='second'))
    _spin(executor, 3)
    recorder.destroy_node()
    # Nobody was subscribed when 'first' went out; recording starts at the next discovery.
    assert [m.message.data for m in read_messages(tmp_path / 'bag')] == ['second']


def test_declared_qos_is_used_where_the_runtime_cannot_report_publishers(
    ros: None, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    def unsupported(self: Node, topic_name: str, no_mangle: bool = False) -> list[Any]:
        raise BuiltinRuntimeUnsupported('no endpoint info here')

    monkeypatch.setattr(BagRecorder, 'get_publishers_info_by_topic', unsupported)
    executor = rclpy.executors.SingleThreadedExecutor()
    counter = Counter('r0')
    recorder = BagRecorder(
        tmp_path / 'bag', topics=['/r0/count'], offered_qos={'/r0/*': qos_profile_sensor_data}
    )
    executor.add_node(counter)
    executor.add_node(recorder)
    _spin(executor, 10)
    recorder.destroy_node()
    (profile,) = read_bag_info(tmp_path / 'bag').topics['/r0/count'].offered_qos_profiles
    assert profile.reliability.name == 'BEST_EFFORT'
    assert profile.depth == qos_profile_sensor_data.depth


def test_declared_qos_applies_to_a_topic_that_has_no_publisher_yet(
    ros: None, tmp_path: Path
) -> None:
    latched = QoSProfile(depth=1, durability=QoSDurabilityPolicy.TRANSIENT_LOCAL)
    executor = rclpy.executors.SingleThreadedExecutor()
    listener = Node('listener')
    listener.create_subscription(std_msgs.String, '/sim/site', lambda msg: None, latched)
    recorder = BagRecorder(tmp_path / 'bag', topics=['/sim/site'], offered_qos={'/sim/*': latched})
    executor.add_node(listener)
    executor.add_node(recorder)
    _spin(executor, 2)
    site = SitePublisher()
    executor.add_node(site)
    _spin(executor, 5)
    recorder.destroy_node()
    read = list(read_messages(tmp_path / 'bag'))
    assert [m.message.data for m in read] == ['site layout']
    (profile,) = read_bag_info(tmp_path / 'bag').topics['/sim/site'].offered_qos_profiles
    assert profile.durability.name == 'TRANSIENT_LOCAL'


def test_subscription_qos_matches_every_offered_profile() -> None:
    reliable = QoSProfile(depth=10)
    best_effort = QoSProfile(depth=5, reliability=ReliabilityPolicy.BEST_EFFORT)
    assert (
        BagRecorder._subscription_qos([reliable, reliable]).reliability
        == ReliabilityPolicy.RELIABLE
    )
    assert (
        BagRecorder._subscription_qos([reliable, best_effort]).reliability
        == ReliabilityPolicy.BEST_EFFORT
    )
    assert BagRecorder._subscription_qos([]).reliability == ReliabilityPolicy.BEST_EFFORT


def test_flushed_messages_survive_a_recorder_that_never_closed(ros: None, tmp_path: Path) -> None:
    executor = rclpy.executors.SingleThreadedExecutor()
    counter = Counter('r0')
    recorder = BagRecorder(tmp_path / 'bag', topics=['/r0/count'], flush_period_s=0.5)
    executor.add_node(counter)
    executor.add_node(recorder)
    _spin(executor, 60)
    # The process "dies" here: no destroy_node(), so no summary and no metadata.yaml.
    with pytest.warns(TruncatedBagWarning):
        recovered = [m.message.data for m in read_messages(tmp_path / 'bag', allow_truncated=True)]
    assert len(recovered) >= 5
    assert recovered == list(range(len(recovered)))
    recorder.destroy_node()


def test_recorder_refuses_an_existing_output(ros: None, tmp_path: Path) -> None:
    from swarm_runtime.bag import BagWriteError

    (tmp_path / 'bag').mkdir()
    with pytest.raises(BagWriteError, match='exists already'):
        BagRecorder(tmp_path / 'bag')
