"""Node code written like the ros2/demos (jazzy) talker and listener runs unchanged.

The node classes and ``main`` below are plain rclpy 7.1 code; only the import lines pick the
built-in runtime. ``main`` is run whole, including its Jazzy shutdown idiom, with Ctrl-C
simulated by a log handler that raises KeyboardInterrupt on the third message.
"""

from __future__ import annotations

import logging
from collections.abc import Iterator

import pytest
from swarm_runtime.builtin.executors import ExternalShutdownException, SingleThreadedExecutor
from swarm_runtime.builtin.node import Node
from swarm_runtime.messages import get_message_module
from swarm_runtime.simulation import spin_until

from swarm_runtime import builtin as rclpy

String = get_message_module('std_msgs').String


class Talker(Node):
    def __init__(self) -> None:
        super().__init__('talker')
        self.i = 0
        self.pub = self.create_publisher(String, 'chatter', 10)
        self.tmr = self.create_timer(1.0, self.timer_callback)

    def timer_callback(self) -> None:
        msg = String()
        msg.data = f'Hello World: {self.i}'
        self.i += 1
        self.get_logger().info(f'Publishing: "{msg.data}"')
        self.pub.publish(msg)


class Listener(Node):
    def __init__(self) -> None:
        super().__init__('listener')
        self.sub = self.create_subscription(String, 'chatter', self.chatter_callback, 10)

    def chatter_callback(self, msg: String) -> None:
        self.get_logger().info(f'I heard: [{msg.data}]')


def talker_main(args: list[str] | None = None) -> None:
    rclpy.init(args=args)
    node = Talker()
    try:
        rclpy.spin(node)
    except (KeyboardInterrupt, ExternalShutdownException):
        pass
    finally:
        node.destroy_node()
        rclpy.try_shutdown()


class CtrlCAfter(logging.Handler):
    """Raises KeyboardInterrupt at the n-th record, as Ctrl-C during a callback would."""

    def __init__(self, count: int) -> None:
        super().__init__()
        self.messages: list[str] = []
        self.count = count

    def emit(self, record: logging.LogRecord) -> None:
        self.messages.append(record.getMessage())
        if len(self.messages) == self.count:
            raise KeyboardInterrupt


@pytest.fixture
def ctrl_c_on_third_talker_message() -> Iterator[CtrlCAfter]:
    handler = CtrlCAfter(3)
    logger = logging.getLogger('ros.talker')
    logger.addHandler(handler)
    yield handler
    logger.removeHandler(handler)
    rclpy.try_shutdown()


def test_talker_main_runs_until_ctrl_c_then_shuts_down_cleanly(
    ctrl_c_on_third_talker_message,
) -> None:
    talker_main(args=['talker'])
    assert ctrl_c_on_third_talker_message.messages == [
        'Publishing: "Hello World: 0"',
        'Publishing: "Hello World: 1"',
        'Publishing: "Hello World: 2"',
    ]
    assert not rclpy.ok()


def test_talker_main_accepts_ros_arguments(ctrl_c_on_third_talker_message, monkeypatch) -> None:
    topics: list[list[tuple[str, list[str]]]] = []
    original = Talker.timer_callback

    def observe(self: Talker) -> None:
        topics.append(self.get_topic_names_and_types())
        original(self)

    monkeypatch.setattr(Talker, 'timer_callback', observe)
    talker_main(args=['talker', '--ros-args', '-r', 'chatter:=news'])
    assert ('/news', ['std_msgs/msg/String']) in topics[0]


def test_listener_hears_every_talker_message(caplog) -> None:
    rclpy.init(args=['demo'])
    try:
        talker, listener = Talker(), Listener()
        executor = SingleThreadedExecutor()
        executor.add_node(talker)
        executor.add_node(listener)

        def heard() -> list[str]:
            return [r.getMessage() for r in caplog.records if r.name == 'ros.listener']

        with caplog.at_level(logging.INFO):
            assert spin_until(executor, lambda: len(heard()) == 3)
        assert heard() == [f'I heard: [Hello World: {index}]' for index in range(3)]
    finally:
        rclpy.try_shutdown()
