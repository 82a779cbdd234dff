"""Time, clocks and timers of the built-in runtime: virtual wall time and /clock sim time."""

from __future__ import annotations

from collections.abc import Iterator

import pytest
from swarm_runtime.builtin.clock import STEADY_EPOCH_NS, SYSTEM_EPOCH_NS, Clock, ClockType
from swarm_runtime.builtin.duration import Duration
from swarm_runtime.builtin.errors import BuiltinRuntimeUnsupported, ExecutorStalledError
from swarm_runtime.builtin.executors import SingleThreadedExecutor
from swarm_runtime.builtin.node import Node
from swarm_runtime.builtin.parameter import Parameter
from swarm_runtime.builtin.time import Time
from swarm_runtime.messages import get_message_module
from swarm_runtime.simulation import spin_until, spin_until_time, wall_time_s

from swarm_runtime import builtin as rclpy

rosgraph_msgs = get_message_module('rosgraph_msgs')
builtin_interfaces = get_message_module('builtin_interfaces')

SIM_TIME = [Parameter('use_sim_time', value=True)]


@pytest.fixture
def executor() -> Iterator[SingleThreadedExecutor]:
    rclpy.init(args=['test'])
    yield SingleThreadedExecutor()
    rclpy.try_shutdown()


class ClockPublisher(Node):
    """A sim bridge in miniature: publishes /clock from a wall timer."""

    def __init__(self, step_s: float) -> None:
        super().__init__('clock_publisher')
        self._step_ns = round(step_s * 1e9)
        self.sim_ns = 0
        self._pub = self.create_publisher(rosgraph_msgs.Clock, '/clock', 10)
        self.create_timer(step_s, self._tick)

    def _tick(self) -> None:
        self.sim_ns += self._step_ns
        stamp = Time(nanoseconds=self.sim_ns, clock_type=ClockType.ROS_TIME).to_msg()
        self._pub.publish(rosgraph_msgs.Clock(clock=stamp))


class TickRecorder(Node):
    """Records its clock's time at each tick of one timer."""

    def __init__(self, name: str, period_s: float, *, sim_time: bool) -> None:
        super().__init__(name, parameter_overrides=SIM_TIME if sim_time else None)
        self.ticks_ns: list[int] = []
        self.timer = self.create_timer(period_s, self._tick)

    def _tick(self) -> None:
        self.ticks_ns.append(self.get_clock().now().nanoseconds)


def test_time_arithmetic_and_comparison_follow_rclpy() -> None:
    start = Time(seconds=1.5, clock_type=ClockType.ROS_TIME)
    later = start + Duration(seconds=0.25)
    assert later.nanoseconds == 1_750_000_000
    assert (later - start) == Duration(nanoseconds=250_000_000)
    assert later.seconds_nanoseconds() == (1, 750_000_000)
    assert start < later
    with pytest.raises(TypeError, match='different clock types'):
        _ = start < Time(seconds=2)
    with pytest.raises(TypeError):
        _ = start == 1_500_000_000
    with pytest.raises(ValueError, match='negative'):
        Time(seconds=-1)


def test_time_converts_to_and_from_builtin_interfaces_messages() -> None:
    msg = Time(seconds=3, nanoseconds=250).to_msg()
    assert isinstance(msg, builtin_interfaces.Time)
    assert (msg.sec, msg.nanosec) == (3, 250)
    back = Time.from_msg(msg)
    assert back.nanoseconds == 3_000_000_250
    assert back.clock_type is ClockType.ROS_TIME
    with pytest.raises(TypeError, match=r'builtin_interfaces\.msg\.Time'):
        Time.from_msg(builtin_interfaces.Duration(sec=1))


def test_clock_of_type_ros_time_is_a_ros_clock() -> None:
    clock = Clock(clock_type=ClockType.ROS_TIME)
    assert isinstance(clock, rclpy.clock.ROSClock)
    assert clock.ros_time_is_active is False


def test_virtual_clocks_start_at_fixed_epochs_whatever_the_host_time(executor) -> None:
    node = Node('probe')
    assert node.get_clock().now().nanoseconds == SYSTEM_EPOCH_NS
    assert Clock().now().nanoseconds == SYSTEM_EPOCH_NS
    assert Clock(clock_type=ClockType.STEADY_TIME).now().nanoseconds == STEADY_EPOCH_NS


def test_executor_jumps_the_wall_clock_straight_to_the_next_deadline(executor) -> None:
    node = TickRecorder('wall', 0.25, sim_time=False)
    executor.add_node(node)
    for _ in range(4):
        executor.spin_once()
    offsets = [tick - SYSTEM_EPOCH_NS for tick in node.ticks_ns]
    assert offsets == [250_000_000, 500_000_000, 750_000_000, 1_000_000_000]
    assert wall_time_s() == pytest.approx(1.0)


def test_node_with_use_sim_time_reads_zero_until_the_first_clock_message(executor) -> None:
    node = Node('sim', parameter_overrides=SIM_TIME)
    now = node.get_clock().now()
    assert now.nanoseconds == 0
    assert now.clock_type is ClockType.ROS_TIME
    assert node.get_parameter('use_sim_time').value is True


def test_sim_time_timer_fires_exactly_at_its_deadlines_as_clock_advances(executor) -> None:
    bridge = ClockPublisher(step_s=0.1)
    robot = TickRecorder('robot', 0.5, sim_time=True)
    executor.add_node(bridge)
    executor.add_node(robot)
    assert spin_until_time(executor, 3.0)
    assert robot.get_clock().now().nanoseconds == 3_000_000_000
    assert robot.ticks_ns == [k * 500_000_000 for k in range(1, 7)]


def test_sim_time_timer_skips_missed_periods_when_clock_jumps_like_rcl(executor) -> None:
    robot = TickRecorder('robot', 0.5, sim_time=True)
    executor.add_node(robot)
    robot.get_clock().set_ros_time_override(Time(seconds=1.2, clock_type=ClockType.ROS_TIME))
    executor.spin_once(timeout_sec=0)
    executor.spin_once(timeout_sec=0)
    # Due at 0.5; called once at 1.2, the next deadline on the same grid after 1.2 is 1.5.
    assert robot.ticks_ns == [1_200_000_000]
    assert robot.timer.time_until_next_call() == 300_000_000


def test_sim_time_timers_never_fire_without_clock_and_the_executor_says_so(executor) -> None:
    robot = TickRecorder('robot', 0.5, sim_time=True)
    executor.add_node(robot)
    with pytest.raises(ExecutorStalledError, match='block here forever'):
        executor.spin_once()
    assert robot.ticks_ns == []


def test_timeout_advances_the_wall_clock_by_at_most_the_timeout(executor) -> None:
    node = TickRecorder('slow', 10.0, sim_time=False)
    executor.add_node(node)
    executor.spin_once(timeout_sec=0.5)
    assert node.ticks_ns == []
    assert wall_time_s() == pytest.approx(0.5)
    executor.spin_once(timeout_sec=0)
    assert wall_time_s() == pytest.approx(0.5)


def test_timers_due_together_run_in_deadline_then_creation_order(executor) -> None:
    order: list[str] = []
    node = Node('timers')
    node.create_timer(0.2, lambda: order.append('b@0.2'))
    node.create_timer(0.1, lambda: order.append('c@0.1'))
    node.create_timer(0.2, lambda: order.append('d@0.2'))
    executor.add_node(node)
    # Let all become due at once (as after a long callback), then run what is ready.
    executor.context._elapsed_ns = 200_000_000
    for _ in range(4):
        executor.spin_once(timeout_sec=0)
    # c's second deadline (0.2) ties with b and d; c was created before d.
    assert order == ['c@0.1', 'b@0.2', 'c@0.1', 'd@0.2']


def test_canceled_timer_stops_and_reset_restarts_one_period_later(executor) -> None:
    node = TickRecorder('toggle', 1.0, sim_time=False)
    executor.add_node(node)
    executor.spin_once()
    node.timer.cancel()
    assert node.timer.is_canceled()
    assert node.timer.time_until_next_call() is None
    executor.spin_once(timeout_sec=5.0)
    assert len(node.ticks_ns) == 1
    node.timer.reset()
    executor.spin_once()
    assert [tick - SYSTEM_EPOCH_NS for tick in node.ticks_ns] == [1_000_000_000, 7_000_000_000]


def test_timer_created_without_autostart_waits_for_reset(executor) -> None:
    node = Node('lazy')
    calls: list[int] = []
    timer = node.create_timer(0.1, lambda: calls.append(1), autostart=False)
    executor.add_node(node)
    executor.spin_once(timeout_sec=1.0)
    assert calls == []
    timer.reset()
    executor.spin_once(timeout_sec=1.0)
    assert calls == [1]


def test_switching_use_sim_time_on_carries_the_period_over_like_rcl(executor) -> None:
    bridge = ClockPublisher(step_s=0.1)
    robot = TickRecorder('robot', 1.0, sim_time=False)
    executor.add_node(bridge)
    executor.add_node(robot)
    assert spin_until(executor, lambda: bridge.sim_ns >= 2_400_000_000)
    assert [tick - SYSTEM_EPOCH_NS for tick in robot.ticks_ns] == [1_000_000_000, 2_000_000_000]
    # The clock already holds a ROS time when sim time is switched on, 0.6 s before the
    # wall deadline; rcl then schedules the next call at now - 0.6 s + period.
    robot.get_clock().set_ros_time_override(Time(seconds=2.4, clock_type=ClockType.ROS_TIME))
    robot.set_parameters([Parameter('use_sim_time', value=True)])
    assert robot.get_clock().ros_time_is_active
    assert spin_until(executor, lambda: len(robot.ticks_ns) == 3, max_wall_time_s=2.0)
    assert robot.ticks_ns[-1] == 2_800_000_000


def test_activating_sim_time_before_any_clock_keeps_the_wall_deadline_like_rcl(executor) -> None:
    robot = TickRecorder('robot', 1.0, sim_time=False)
    executor.add_node(robot)
    robot.set_parameters([Parameter('use_sim_time', value=True)])
    assert robot.get_clock().now().nanoseconds == 0
    assert robot.timer.time_until_next_call() == SYSTEM_EPOCH_NS + 1_000_000_000


def test_blocking_clock_sleeps_are_refused_with_a_clear_error(executor) -> None:
    clock = Node('sleepy').get_clock()
    with pytest.raises(BuiltinRuntimeUnsupported, match='use a timer'):
        clock.sleep_for(Duration(seconds=1))


def test_jump_callbacks_report_forward_jumps_of_ros_time(executor) -> None:
    node = Node('jumpy', parameter_overrides=SIM_TIME)
    jumps: list[int] = []
    threshold = rclpy.clock.JumpThreshold(min_forward=Duration(seconds=1), min_backward=None)
    handle = node.get_clock().create_jump_callback(
        threshold, post_callback=lambda jump: jumps.append(jump.delta.nanoseconds)
    )
    clock = node.get_clock()
    clock.set_ros_time_override(Time(seconds=0.5, clock_type=ClockType.ROS_TIME))
    clock.set_ros_time_override(Time(seconds=2.0, clock_type=ClockType.ROS_TIME))
    handle.unregister()
    clock.set_ros_time_override(Time(seconds=9.0, clock_type=ClockType.ROS_TIME))
    assert jumps == [1_500_000_000]


def _clock_cdr(sec: int, nanosec: int, *, little_endian: bool = True) -> bytes:
    """A rosgraph_msgs/Clock in CDR, written by hand (header, int32 sec, uint32 nanosec)."""
    order = 'little' if little_endian else 'big'
    header = b'\x00\x01\x00\x00' if little_endian else b'\x00\x00\x00\x00'
    return header + sec.to_bytes(4, order, signed=True) + nanosec.to_bytes(4, order)


@pytest.mark.parametrize('little_endian', [True, False])
def test_sim_time_follows_clock_messages_sent_as_cdr_bytes(
    executor: SingleThreadedExecutor, monkeypatch: pytest.MonkeyPatch, little_endian: bool
) -> None:
    monkeypatch.setenv('SWARM_RUNTIME_CDR_ROUNDTRIP', '1')
    node = Node('follower', parameter_overrides=SIM_TIME)
    publisher = Node('bag_player').create_publisher(rosgraph_msgs.Clock, '/clock', 10)
    executor.add_node(node)
    publisher.publish(_clock_cdr(12, 345, little_endian=little_endian))
    executor.spin_once(timeout_sec=0)
    assert node.get_clock().now().nanoseconds == 12_000_000_345


def test_a_clock_message_that_is_not_cdr_fails_like_any_bad_message(
    executor: SingleThreadedExecutor, monkeypatch: pytest.MonkeyPatch
) -> None:
    from swarm_runtime.messages import DeserializationError

    monkeypatch.setenv('SWARM_RUNTIME_CDR_ROUNDTRIP', '1')
    node = Node('follower', parameter_overrides=SIM_TIME)
    publisher = Node('bag_player').create_publisher(rosgraph_msgs.Clock, '/clock', 10)
    executor.add_node(node)
    with pytest.raises(DeserializationError):
        publisher.publish(b'\x00\x01\x00')
    with pytest.raises(DeserializationError):
        node._time_source._clock_cdr_callback(b'\x00\x01\x00')
    assert node.get_clock().now().nanoseconds == 0


def test_time_to_msg_builds_what_the_constructor_builds_and_fails_where_it_fails() -> None:
    time = Time(nanoseconds=1_700_000_000_123_456_789, clock_type=ClockType.ROS_TIME)
    msg = time.to_msg()
    assert msg == builtin_interfaces.Time(sec=1_700_000_000, nanosec=123_456_789)
    assert msg._check_fields == builtin_interfaces.Time()._check_fields
    beyond_int32 = Time(seconds=2**31, clock_type=ClockType.ROS_TIME)
    if builtin_interfaces.Time()._check_fields:
        with pytest.raises(AssertionError, match="The 'sec' field"):
            beyond_int32.to_msg()
    else:
        assert beyond_int32.to_msg().sec == 2**31
