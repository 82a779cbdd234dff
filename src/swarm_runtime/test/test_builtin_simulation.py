"""Simulation helpers and whole-simulation properties of the built-in runtime."""

from __future__ import annotations

from typing import Any

import pytest
from swarm_runtime.builtin.clock import ClockType
from swarm_runtime.builtin.context import Context
from swarm_runtime.builtin.executors import SingleThreadedExecutor
from swarm_runtime.builtin.node import Node
from swarm_runtime.builtin.parameter import Parameter
from swarm_runtime.builtin.qos import qos_profile_sensor_data
from swarm_runtime.builtin.time import Time
from swarm_runtime.messages import get_message_module
from swarm_runtime.simulation import (
    sim_time_s,
    spin_ready,
    spin_until,
    spin_until_time,
    wall_time_s,
)

rosgraph_msgs = get_message_module('rosgraph_msgs')
geometry_msgs = get_message_module('geometry_msgs')


class Bridge(Node):
    """Publishes /clock at 100 Hz of wall time and records every cmd_vel it gets."""

    def __init__(self, context: Context, robots: int) -> None:
        super().__init__('sim_bridge', context=context)
        self.sim_ns = 0
        self.trace: list[tuple[int, str, float]] = []
        self._clock_pub = self.create_publisher(rosgraph_msgs.Clock, '/clock', 10)
        for index in range(robots):
            self.create_subscription(
                geometry_msgs.Twist, f'/r{index}/cmd_vel', self._recorder(f'r{index}'), 10
            )
        self.create_timer(0.01, self._tick)

    def _recorder(self, robot: str) -> Any:
        def record(msg: Any) -> None:
            self.trace.append((self.sim_ns, robot, msg.linear.x))

        return record

    def _tick(self) -> None:
        self.sim_ns += 10_000_000
        stamp = Time(nanoseconds=self.sim_ns, clock_type=ClockType.ROS_TIME).to_msg()
        self._clock_pub.publish(rosgraph_msgs.Clock(clock=stamp))


class Robot(Node):
    """A sim-time node publishing cmd_vel at 10 Hz with a speed that depends on its index."""

    def __init__(self, context: Context, index: int) -> None:
        super().__init__(
            'algo',
            namespace=f'r{index}',
            context=context,
            parameter_overrides=[Parameter('use_sim_time', value=True)],
        )
        self._speed = 0.1 * (index + 1)
        self._pub = self.create_publisher(geometry_msgs.Twist, 'cmd_vel', 10)
        self.create_timer(0.1, self._tick)

    def _tick(self) -> None:
        msg = geometry_msgs.Twist()
        msg.linear.x = self._speed * self.get_clock().now().nanoseconds / 1e9
        self._pub.publish(msg)


def run_swarm(robots: int, until_s: float) -> list[tuple[int, str, float]]:
    context = Context()
    context.init(['sim'])
    try:
        bridge = Bridge(context, robots)
        executor = SingleThreadedExecutor(context=context)
        executor.add_node(bridge)
        for index in range(robots):
            executor.add_node(Robot(context, index))
        assert spin_until_time(executor, until_s)
        return bridge.trace
    finally:
        context.shutdown()


def test_bridge_clock_drives_robot_timers_in_every_namespace() -> None:
    trace = run_swarm(robots=3, until_s=1.0)
    assert len(trace) == 30
    assert [robot for _, robot, _ in trace[:3]] == ['r0', 'r1', 'r2']
    last_second = [(robot, speed) for t, robot, speed in trace if t == 1_000_000_000]
    assert last_second == [('r0', pytest.approx(0.1)), ('r1', 0.2), ('r2', pytest.approx(0.3))]


def test_identical_simulations_produce_identical_traces() -> None:
    trace = run_swarm(robots=4, until_s=2.0)
    assert len(trace) == 80  # 4 robots, 10 Hz, 2 s: the comparison is not of empty traces
    assert trace == run_swarm(robots=4, until_s=2.0)


def test_spin_until_time_stops_with_everything_due_at_that_time_done() -> None:
    context = Context()
    context.init(['sim'])
    bridge = Bridge(context, robots=1)
    executor = SingleThreadedExecutor(context=context)
    executor.add_node(bridge)
    executor.add_node(Robot(context, 0))
    assert spin_until_time(executor, 0.5)
    assert sim_time_s(context) == pytest.approx(0.5)
    assert wall_time_s(context) == pytest.approx(0.5)
    assert bridge.trace[-1][0] == 500_000_000
    assert spin_ready(executor) == 0
    context.shutdown()


def test_spin_until_gives_up_after_the_virtual_wall_time_budget() -> None:
    context = Context()
    context.init(['sim'])
    executor = SingleThreadedExecutor(context=context)
    executor.add_node(Bridge(context, robots=0))
    assert not spin_until(executor, lambda: False, max_wall_time_s=0.25)
    assert wall_time_s(context) == pytest.approx(0.25)
    assert not spin_until_time(executor, 100.0, max_wall_time_s=0.5)
    assert sim_time_s(context) == pytest.approx(0.75)
    context.shutdown()


def test_sim_time_is_unknown_before_the_first_clock_message() -> None:
    context = Context()
    context.init(['sim'])
    assert sim_time_s(context) is None
    assert wall_time_s(context) == 0.0
    context.shutdown()


def test_helpers_refuse_executors_of_other_runtimes() -> None:
    with pytest.raises(TypeError, match='built-in runtime'):
        spin_until(object(), lambda: True)  # type: ignore[arg-type]


def test_sensor_streams_survive_a_slow_consumer_up_to_their_depth() -> None:
    context = Context()
    context.init(['sim'])
    node = Node('fast', context=context)
    received: list[Any] = []
    node.create_subscription(rosgraph_msgs.Clock, 'c', received.append, qos_profile_sensor_data)
    publisher = node.create_publisher(rosgraph_msgs.Clock, 'c', qos_profile_sensor_data)
    for _ in range(12):
        publisher.publish(rosgraph_msgs.Clock())
    executor = SingleThreadedExecutor(context=context)
    executor.add_node(node)
    assert spin_ready(executor) == 5
    assert len(received) == 5
    context.shutdown()
