"""init/shutdown, spinning, destruction and unsupported features of the built-in runtime."""

from __future__ import annotations

from collections.abc import Iterator

import pytest
from swarm_runtime.builtin.context import Context
from swarm_runtime.builtin.errors import BuiltinRuntimeUnsupported, ExecutorStalledError, RCLError
from swarm_runtime.builtin.exceptions import InvalidHandle, NotInitializedException
from swarm_runtime.builtin.executors import ExternalShutdownException, SingleThreadedExecutor
from swarm_runtime.builtin.node import Node
from swarm_runtime.builtin.task import Future
from swarm_runtime.messages import get_message_module
from swarm_runtime.simulation import spin_ready

from swarm_runtime import builtin as rclpy

std_msgs = get_message_module('std_msgs')


@pytest.fixture
def init() -> Iterator[None]:
    rclpy.init(args=['prog'])
    yield None
    rclpy.try_shutdown()


def test_init_shutdown_and_ok_follow_rclpy() -> None:
    assert not rclpy.ok()
    rclpy.init(args=['prog'])
    assert rclpy.ok()
    with pytest.raises(RuntimeError, match='only be called once'):
        rclpy.init(args=['prog'])
    rclpy.shutdown()
    assert not rclpy.ok()
    rclpy.init(args=['prog'])
    rclpy.try_shutdown()
    rclpy.try_shutdown()
    assert not rclpy.ok()


def test_shutting_down_twice_is_an_error() -> None:
    context = Context()
    context.init(['prog'])
    context.shutdown()
    with pytest.raises(RCLError, match='already called'):
        context.shutdown()


def test_creating_a_node_before_init_raises() -> None:
    with pytest.raises(NotInitializedException, match='cannot create node'):
        Node('early')


def test_shutdown_callbacks_run_once(init) -> None:
    calls: list[str] = []
    rclpy.get_default_context().on_shutdown(lambda: calls.append('bye'))
    rclpy.shutdown()
    assert calls == ['bye']


def test_nodes_of_separate_contexts_do_not_see_each_other() -> None:
    first, second = Context(), Context()
    first.init(['prog'])
    second.init(['prog'])
    publisher = Node('a', context=first).create_publisher(std_msgs.String, 'x', 10)
    Node('b', context=second).create_subscription(std_msgs.String, 'x', lambda m: None, 10)
    assert publisher.get_subscription_count() == 0
    first.shutdown()
    second.shutdown()


def test_spin_returns_when_a_callback_shuts_the_context_down(init) -> None:
    node = Node('stopper')
    ticks: list[int] = []

    def tick() -> None:
        ticks.append(1)
        if len(ticks) == 3:
            rclpy.try_shutdown()

    node.create_timer(0.1, tick)
    rclpy.spin(node)
    assert len(ticks) == 3
    assert not rclpy.ok()


def test_spinning_after_an_external_shutdown_raises_external_shutdown_exception(init) -> None:
    node = Node('late')
    executor = SingleThreadedExecutor()
    executor.add_node(node)
    rclpy.try_shutdown()
    with pytest.raises(ExternalShutdownException):
        executor.spin_once()


def test_keyboard_interrupt_in_a_callback_propagates_out_of_spin(init) -> None:
    node = Node('interrupted')

    def press_ctrl_c() -> None:
        raise KeyboardInterrupt

    node.create_timer(1.0, press_ctrl_c)
    with pytest.raises(KeyboardInterrupt):
        rclpy.spin(node)
    assert node.executor is None


def test_callback_exceptions_propagate_out_of_spin_once(init) -> None:
    node = Node('broken')
    node.create_timer(0.1, lambda: 1 / 0)
    with pytest.raises(ZeroDivisionError):
        rclpy.spin_once(node)


def test_spin_with_nothing_that_can_ever_run_raises_instead_of_hanging(init) -> None:
    node = Node('idle')
    node.create_subscription(std_msgs.String, 'nobody_publishes', lambda m: None, 10)
    with pytest.raises(ExecutorStalledError):
        rclpy.spin(node)


def test_destroy_node_removes_its_entities_from_the_graph(init) -> None:
    node = Node('doomed')
    observer = Node('observer')
    node.create_publisher(std_msgs.String, 'x', 10)
    node.create_subscription(std_msgs.String, 'x', lambda m: None, 10)
    timer = node.create_timer(1.0, lambda: None)
    node.destroy_node()
    node.destroy_node()
    assert observer.count_publishers('x') == 0
    assert observer.count_subscribers('x') == 0
    assert '/doomed' not in observer.get_fully_qualified_node_names()
    with pytest.raises(InvalidHandle):
        timer.is_ready()
    with pytest.raises(InvalidHandle):
        node.create_publisher(std_msgs.String, 'y', 10)


def test_destroyed_node_receives_nothing_that_was_queued(init) -> None:
    listener = Node('listener')
    heard: list[object] = []
    listener.create_subscription(std_msgs.String, 'x', heard.append, 10)
    talker = Node('talker')
    talker.create_publisher(std_msgs.String, 'x', 10).publish(std_msgs.String(data='a'))
    executor = SingleThreadedExecutor()
    executor.add_node(listener)
    executor.add_node(talker)
    listener.destroy_node()
    spin_ready(executor)
    assert heard == []
    assert executor.get_nodes() == [talker]


def test_rclpy_spin_once_adds_and_removes_the_node(init) -> None:
    node = Node('once')
    calls: list[int] = []
    node.create_timer(0.5, lambda: calls.append(1))
    rclpy.spin_once(node, timeout_sec=1.0)
    assert calls == [1]
    assert node.executor is None


def test_spin_until_future_complete(init) -> None:
    node = Node('waiter')
    future = Future()
    node.create_timer(0.2, lambda: future.done() or future.set_result('ready'))
    rclpy.spin_until_future_complete(node, future)
    assert future.result() == 'ready'
    pending = Future()
    rclpy.spin_until_future_complete(node, pending, timeout_sec=1.0)
    assert not pending.done()


def test_executor_add_node_moves_the_node_from_its_previous_executor(init) -> None:
    node = Node('nomad')
    first, second = SingleThreadedExecutor(), SingleThreadedExecutor()
    assert first.add_node(node)
    assert not first.add_node(node)
    second.add_node(node)
    assert node.executor is second
    assert first.get_nodes() == []


@pytest.mark.parametrize('name', ['action', 'callback_groups', 'client', 'serialization'])
def test_unprovided_rclpy_modules_raise_a_clear_error(name: str) -> None:
    with pytest.raises(BuiltinRuntimeUnsupported, match=f'rclpy.{name} is not provided'):
        getattr(rclpy, name)


def test_unprovided_node_methods_and_executors_raise_a_clear_error(init) -> None:
    node = Node('limited')
    with pytest.raises(BuiltinRuntimeUnsupported, match='create_service'):
        node.create_service(object, 'srv', lambda request, response: response)
    with pytest.raises(BuiltinRuntimeUnsupported, match='MultiThreadedExecutor'):
        _ = rclpy.executors.MultiThreadedExecutor
    with pytest.raises(AttributeError, match='no attribute'):
        _ = node.no_such_method
