"""BagRecorder on both runtimes: topic selection, discovery, offered QoS, latching, sim time.

The same tests run on the built-in runtime and on real rclpy over DDS
(``SWARM_RUNTIME=rclpy``); on DDS they wait for the graph instead of assuming immediate
discovery. Tests of exact delivery timing hold only on the built-in runtime and are skipped
on DDS with the reason.
"""

from __future__ import annotations

from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pytest
import yaml
from swarm_runtime.bag import BagRecorder, TruncatedBagWarning, read_bag_info, read_messages
from swarm_runtime.bag.recorder import SYSTEM_TOPICS
from swarm_runtime.bag.testing import spin_until
from swarm_runtime.ros import (
    Node,
    Parameter,
    QoSDurabilityPolicy,
    QoSProfile,
    ReliabilityPolicy,
    message_module,
    qos_profile_sensor_data,
    rclpy,
    using_real_rclpy,
)

std_msgs = message_module('std_msgs')
REAL = using_real_rclpy()
# Host-time budget for one wait; DDS discovery on a loaded machine can take a few seconds.
WAIT_S = 20.0
builtin_only = pytest.mark.builtin_only(
    reason='exact delivery timing: the built-in runtime delivers without discovery delay'
)


@pytest.fixture
def ros() -> Iterator[None]:
    """An initialised ROS context for one test (on DDS: the domain of this test process)."""
    rclpy.init()
    yield
    rclpy.try_shutdown()


@pytest.fixture
def executor(ros: None) -> Iterator[Any]:
    """A single-threaded executor; its nodes are destroyed after the test."""
    executor = rclpy.executors.SingleThreadedExecutor()
    yield executor
    for node in list(executor.get_nodes()):
        executor.remove_node(node)
        node.destroy_node()


def _add(executor: Any, *nodes: Node) -> None:
    for node in nodes:
        executor.add_node(node)


def _finish(executor: Any, recorder: BagRecorder) -> None:
    executor.remove_node(recorder)
    recorder.destroy_node()


class Counter(Node):
    """Publishes its count on ``count`` every 0.1 s of its clock (sensor-data QoS)."""

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


class SitePublisher(Node):
    """Latches a site layout on /sim/site, as the sim bridge does."""

    def __init__(self, name: str = 'site_publisher') -> None:
        super().__init__(name)
        latched = QoSProfile(depth=1, durability=QoSDurabilityPolicy.TRANSIENT_LOCAL)
        self.publisher = self.create_publisher(std_msgs.String, '/sim/site', latched)
        self.publisher.publish(std_msgs.String(data='site layout'))


def _metadata_qos(bag: Path, topic: str) -> list[dict[str, Any]]:
    """The offered_qos_profiles of ``topic`` as written in metadata.yaml."""
    metadata = yaml.safe_load((bag / 'metadata.yaml').read_text())
    for entry in metadata['rosbag2_bagfile_information']['topics_with_message_count']:
        if entry['topic_metadata']['name'] == topic:
            return entry['topic_metadata']['offered_qos_profiles']
    msg = f'{topic} is not in the metadata'
    raise AssertionError(msg)


def _data(bag: Path, topic: str | None = None) -> list[Any]:
    return [m.message.data for m in read_messages(bag) if topic is None or m.topic == topic]


def test_records_chosen_topics_with_sim_time_stamps(executor: Any, tmp_path: Path) -> None:
    nodes = [SimClock(), Counter('r0', use_sim_time=True), Counter('r1', use_sim_time=True)]
    recorder = BagRecorder(tmp_path / 'bag', topics=['/r0/*'], use_sim_time=True)
    _add(executor, *nodes, recorder)
    assert spin_until(executor, lambda: recorder.message_count >= 8, timeout_s=WAIT_S)
    _finish(executor, recorder)

    info = read_bag_info(tmp_path / 'bag')
    assert set(info.topics) == {'/r0/count'}
    read = list(read_messages(tmp_path / 'bag'))
    values = [m.message.data for m in read]
    assert values == list(range(values[0], values[0] + len(values)))
    # Counter n is published at sim time (n + 1) * 0.1 s: the stamps are the recorder's sim
    # time, on DDS within one /clock step of it (the two topics arrive independently).
    tolerance_ns = 50_000_000 if REAL else 0
    for message in read:
        expected = 100_000_000 * (message.message.data + 1)
        assert abs(message.log_time_ns - expected) <= tolerance_ns


def test_default_skips_system_topics_and_names_can_ask_for_them(
    executor: Any, tmp_path: Path
) -> None:
    counter = Counter('r0')
    hidden = counter.create_publisher(std_msgs.Int32, '_internal/state', 10)
    everything = BagRecorder(tmp_path / 'all', node_name='all_topics')
    patterns = BagRecorder(tmp_path / 'patterns', topics=['/*', '/r0/*'], node_name='patterns')
    _add(executor, counter, everything, patterns)
    hidden.publish(std_msgs.Int32(data=1))
    assert spin_until(
        executor,
        lambda: everything.message_count >= 3 and patterns.message_count >= 3,
        timeout_s=WAIT_S,
    )
    _finish(executor, everything)
    _finish(executor, patterns)
    # /rosout and /parameter_events exist on real DDS (and the latter on the built-in
    # runtime): neither None nor a pattern records them, nor the hidden topic.
    assert set(read_bag_info(tmp_path / 'all').topics) == {'/r0/count'}
    assert set(read_bag_info(tmp_path / 'patterns').topics) == {'/r0/count'}


def test_a_system_topic_named_exactly_is_recorded(executor: Any, tmp_path: Path) -> None:
    assert '/parameter_events' in SYSTEM_TOPICS
    counter = Counter('r0')
    recorder = BagRecorder(tmp_path / 'bag', topics=['/parameter_events'])
    _add(executor, counter, recorder)
    assert spin_until(
        executor, lambda: '/parameter_events' in recorder.recorded_topics, timeout_s=WAIT_S
    )
    executor.spin_once(timeout_sec=0.1)
    counter.set_parameters([Parameter('use_sim_time', value=False)])
    assert spin_until(executor, lambda: recorder.message_count >= 1, timeout_s=WAIT_S)
    _finish(executor, recorder)
    assert set(read_bag_info(tmp_path / 'bag').topics) == {'/parameter_events'}


def test_topics_that_appear_later_are_discovered(executor: Any, tmp_path: Path) -> None:
    recorder = BagRecorder(tmp_path / 'bag', topics=['/late/*'], discovery_period_s=0.5)
    _add(executor, recorder)
    for _ in range(3):
        executor.spin_once(timeout_sec=0.05)
    late = Counter('late')
    _add(executor, late)
    assert spin_until(executor, lambda: recorder.message_count >= 10, timeout_s=WAIT_S)
    _finish(executor, recorder)
    values = _data(tmp_path / 'bag')
    assert values == list(range(values[0], values[0] + len(values)))
    # Discovery polls every 0.5 s (plus DDS discovery on real ROS): only the first few are lost.
    assert values[0] <= (20 if REAL else 5)


def test_latched_message_published_before_the_recorder_started_is_recorded_with_its_qos(
    executor: Any, tmp_path: Path
) -> None:
    site = SitePublisher()
    _add(executor, site)
    for _ in range(3):
        executor.spin_once(timeout_sec=0.05)
    recorder = BagRecorder(tmp_path / 'bag', topics=['/sim/site'])
    _add(executor, recorder)
    assert spin_until(executor, lambda: recorder.message_count >= 1, timeout_s=WAIT_S)
    assert recorder.subscription_qos('/sim/site').durability == QoSDurabilityPolicy.TRANSIENT_LOCAL
    _finish(executor, recorder)

    assert _data(tmp_path / 'bag') == ['site layout']
    (profile,) = _metadata_qos(tmp_path / 'bag', '/sim/site')
    assert profile['durability'] == 'transient_local'
    assert profile['reliability'] == 'reliable'


def test_a_latched_topic_published_in_another_process_before_recording_is_recorded(
    tmp_path: Path, ros: None
) -> None:
    """The DDS case of the bug report: publisher in another process, latched, earlier."""
    if not REAL:
        pytest.skip('other processes only exist on DDS; the built-in case is the test above')
    import subprocess
    import sys

    script = (
        'import rclpy, sys\n'
        'from rclpy.qos import QoSProfile, DurabilityPolicy\n'
        'from std_msgs.msg import String\n'
        'rclpy.init()\n'
        "node = rclpy.create_node('latcher')\n"
        'qos = QoSProfile(depth=1, durability=DurabilityPolicy.TRANSIENT_LOCAL)\n'
        "pub = node.create_publisher(String, '/sim/site', qos)\n"
        "pub.publish(String(data='from another process'))\n"
        "print('published', flush=True)\n"
        'sys.stdin.read()  # DDS serves the history from its own threads until stdin closes\n'
        'rclpy.try_shutdown()\n'
    )
    process = subprocess.Popen(
        [sys.executable, '-c', script],
        stdin=subprocess.PIPE,
        stdout=subprocess.PIPE,
        text=True,
    )
    try:
        assert process.stdout is not None
        assert process.stdout.readline().strip() == 'published'
        executor = rclpy.executors.SingleThreadedExecutor()
        recorder = BagRecorder(tmp_path / 'bag', topics=['/sim/site'])
        executor.add_node(recorder)
        assert spin_until(executor, lambda: recorder.message_count >= 1, timeout_s=WAIT_S)
        executor.remove_node(recorder)
        recorder.destroy_node()
    finally:
        assert process.stdin is not None
        process.stdin.close()
        process.wait(timeout=30)
    assert _data(tmp_path / 'bag') == ['from another process']
    (profile,) = _metadata_qos(tmp_path / 'bag', '/sim/site')
    assert profile['durability'] == 'transient_local'


def test_each_publishers_offered_qos_is_recorded_and_the_subscription_matches_all(
    executor: Any, tmp_path: Path
) -> None:
    site = SitePublisher()
    volatile = Node('volatile_site')
    volatile_publisher = volatile.create_publisher(std_msgs.String, '/sim/site', 10)
    recorder = BagRecorder(tmp_path / 'bag', topics=['/sim/site'])
    _add(executor, site, volatile, recorder)
    assert spin_until(
        executor,
        lambda: volatile_publisher.get_subscription_count() >= 1 and recorder.recorded_topics,
        timeout_s=WAIT_S,
    )
    volatile_publisher.publish(std_msgs.String(data='live'))
    assert spin_until(executor, lambda: recorder.message_count >= 1, timeout_s=WAIT_S)
    for _ in range(5):
        executor.spin_once(timeout_sec=0.05)
    _finish(executor, recorder)

    durabilities = sorted(p['durability'] for p in _metadata_qos(tmp_path / 'bag', '/sim/site'))
    assert durabilities == ['transient_local', 'volatile']
    # One publisher is volatile, so the recorder cannot ask for history (it would not match
    # that publisher). On the built-in runtime the discovery saw both publishers at once.
    if not REAL:
        assert _data(tmp_path / 'bag') == ['live']
    else:
        assert 'live' in _data(tmp_path / 'bag')


def test_a_publisher_that_appears_later_adds_its_offered_qos(executor: Any, tmp_path: Path) -> None:
    first = Counter('r0')
    recorder = BagRecorder(tmp_path / 'bag', topics=['/r0/count'])
    _add(executor, first, recorder)
    assert spin_until(executor, lambda: recorder.message_count >= 2, timeout_s=WAIT_S)
    second = Node('second_counter', namespace='r0')
    reliable = second.create_publisher(std_msgs.Int32, 'count', 10)
    _add(executor, second)
    assert spin_until(
        executor,
        lambda: len(recorder._recording['/r0/count'].publisher_gids) >= 2,
        timeout_s=WAIT_S,
    )
    reliable.publish(std_msgs.Int32(data=-1))
    assert spin_until(executor, lambda: -1 in _recorded_so_far(recorder), timeout_s=WAIT_S)
    _finish(executor, recorder)
    reliabilities = sorted(p['reliability'] for p in _metadata_qos(tmp_path / 'bag', '/r0/count'))
    assert reliabilities == ['best_effort', 'reliable']


def _recorded_so_far(recorder: BagRecorder) -> list[int]:
    recorder._flush()
    with pytest.warns(TruncatedBagWarning):
        return [m.message.data for m in read_messages(recorder.path, allow_truncated=True)]


@builtin_only
def test_topics_created_after_the_recorder_started_are_recorded_from_the_next_discovery(
    executor: Any, tmp_path: Path
) -> None:
    recorder = BagRecorder(tmp_path / 'bag', topics=['/late/*', '/sim/*'])
    _add(executor, recorder)
    for _ in range(3):
        executor.spin_once(timeout_sec=1.0)
    late = Counter('late')
    site = SitePublisher()
    _add(executor, late, site)
    for _ in range(30):
        executor.spin_once(timeout_sec=1.0)
    _finish(executor, recorder)

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
    executor: Any, tmp_path: Path
) -> None:
    recorder = BagRecorder(tmp_path / 'bag', topics=['/lazy/*'])
    lazy = LazyPublisher(QoSProfile(depth=1, durability=QoSDurabilityPolicy.TRANSIENT_LOCAL))
    _add(executor, recorder, lazy)
    assert spin_until(executor, lambda: recorder.message_count >= 1, timeout_s=WAIT_S)
    assert spin_until(
        executor, lambda: lazy.publisher.get_subscription_count() >= 1, timeout_s=WAIT_S
    )
    lazy.publisher.publish(std_msgs.String(data='second'))
    assert spin_until(executor, lambda: recorder.message_count >= 2, timeout_s=WAIT_S)
    _finish(executor, recorder)
    assert _data(tmp_path / 'bag') == ['first', 'second']


@builtin_only
def test_a_volatile_message_published_as_its_topic_is_created_is_missed_like_ros2_bag_record(
    executor: Any, tmp_path: Path
) -> None:
    recorder = BagRecorder(tmp_path / 'bag', topics=['/lazy/*'])
    lazy = LazyPublisher(QoSProfile(depth=10))
    _add(executor, recorder, lazy)
    for _ in range(10):
        executor.spin_once(timeout_sec=1.0)
    lazy.publisher.publish(std_msgs.String(data='second'))
    for _ in range(3):
        executor.spin_once(timeout_sec=1.0)
    _finish(executor, recorder)
    # Nobody was subscribed when 'first' went out; recording starts at the next discovery.
    assert _data(tmp_path / 'bag') == ['second']


def test_declared_qos_is_used_where_the_runtime_cannot_report_publishers(
    executor: Any, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    def unsupported(self: Node, topic_name: str, no_mangle: bool = False) -> list[Any]:
        raise RuntimeError('no endpoint info here')

    monkeypatch.setattr(BagRecorder, 'get_publishers_info_by_topic', unsupported)
    counter = Counter('r0')
    recorder = BagRecorder(
        tmp_path / 'bag', topics=['/r0/count'], offered_qos={'/r0/*': qos_profile_sensor_data}
    )
    _add(executor, counter, recorder)
    assert spin_until(executor, lambda: recorder.message_count >= 2, timeout_s=WAIT_S)
    _finish(executor, recorder)
    (profile,) = read_bag_info(tmp_path / 'bag').topics['/r0/count'].offered_qos_profiles
    assert profile.reliability.name == 'BEST_EFFORT'
    assert profile.depth == qos_profile_sensor_data.depth


def test_declared_qos_applies_to_a_topic_that_has_no_publisher_yet(
    executor: Any, tmp_path: Path
) -> None:
    latched = QoSProfile(depth=1, durability=QoSDurabilityPolicy.TRANSIENT_LOCAL)
    listener = Node('listener')
    listener.create_subscription(std_msgs.String, '/sim/site', lambda msg: None, latched)
    recorder = BagRecorder(tmp_path / 'bag', topics=['/sim/site'], offered_qos={'/sim/*': latched})
    _add(executor, listener, recorder)
    assert spin_until(executor, lambda: '/sim/site' in recorder.recorded_topics, timeout_s=WAIT_S)
    site = SitePublisher()
    _add(executor, site)
    assert spin_until(executor, lambda: recorder.message_count >= 1, timeout_s=WAIT_S)
    for _ in range(5):
        executor.spin_once(timeout_sec=0.1)
    _finish(executor, recorder)
    assert _data(tmp_path / 'bag') == ['site layout']
    # The declared profile stood in until the publisher appeared; then its own replaced it.
    (profile,) = read_bag_info(tmp_path / 'bag').topics['/sim/site'].offered_qos_profiles
    assert profile.durability.name == 'TRANSIENT_LOCAL'
    assert profile.reliability.name == 'RELIABLE'


def test_a_topic_without_publishers_or_declared_qos_waits_for_a_publisher(
    executor: Any, tmp_path: Path
) -> None:
    listener = Node('listener')
    listener.create_subscription(std_msgs.String, '/sim/site', lambda msg: None, 10)
    recorder = BagRecorder(tmp_path / 'bag', topics=['/sim/site'])
    _add(executor, listener, recorder)
    for _ in range(10):
        executor.spin_once(timeout_sec=0.05)
    assert recorder.recorded_topics == {}
    site = SitePublisher()
    _add(executor, site)
    # Subscribed only now, transient-local as the publisher offers: the latched message comes.
    assert spin_until(executor, lambda: recorder.message_count >= 1, timeout_s=WAIT_S)
    _finish(executor, recorder)
    assert _data(tmp_path / 'bag') == ['site layout']


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


def test_flushed_messages_survive_a_recorder_that_never_closed(
    executor: Any, tmp_path: Path
) -> None:
    counter = Counter('r0')
    recorder = BagRecorder(tmp_path / 'bag', topics=['/r0/count'], flush_period_s=0.3)
    _add(executor, counter, recorder)
    assert spin_until(executor, lambda: recorder.message_count >= 8, timeout_s=WAIT_S)
    for _ in range(int(0.4 / 0.02) + 1):
        executor.spin_once(timeout_sec=0.02)  # past the next flush
    # The process "dies" here: no destroy_node(), so no summary and no metadata.yaml.
    with pytest.warns(TruncatedBagWarning):
        recovered = [m.message.data for m in read_messages(tmp_path / 'bag', allow_truncated=True)]
    assert len(recovered) >= 3
    assert recovered == list(range(recovered[0], recovered[0] + len(recovered)))
    _finish(executor, recorder)


def test_recorder_refuses_an_existing_output(ros: None, tmp_path: Path) -> None:
    from swarm_runtime.bag import BagWriteError

    (tmp_path / 'bag').mkdir()
    with pytest.raises(BagWriteError, match='exists already'):
        BagRecorder(tmp_path / 'bag')
