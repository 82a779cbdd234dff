"""Node loggers of the built-in runtime: names, levels, filters, Python logging underneath."""

from __future__ import annotations

import logging
from collections.abc import Iterator

import pytest
from swarm_runtime.builtin.executors import SingleThreadedExecutor
from swarm_runtime.builtin.logging import LoggingSeverity, get_logger
from swarm_runtime.builtin.node import Node

from swarm_runtime import builtin as rclpy


@pytest.fixture
def init() -> Iterator[None]:
    yield None
    rclpy.try_shutdown()
    logging.getLogger('ros').setLevel(logging.NOTSET)
    logging.getLogger('ros.r0.algo').setLevel(logging.NOTSET)


def test_node_logs_go_to_python_logging_under_the_rcl_logger_name(init, caplog) -> None:
    rclpy.init(args=['prog'])
    node = Node('algo', namespace='r0')
    with caplog.at_level(logging.INFO):
        assert node.get_logger().info('Publishing: "hello"')
    [record] = caplog.records
    assert record.name == 'ros.r0.algo'
    assert record.getMessage() == 'Publishing: "hello"'
    assert record.funcName == 'test_node_logs_go_to_python_logging_under_the_rcl_logger_name'


def test_default_severity_is_info_and_log_level_argument_changes_it(init, caplog) -> None:
    rclpy.init(args=['prog', '--ros-args', '--log-level', 'r0.algo:=debug'])
    node = Node('algo', namespace='r0')
    other = Node('other')
    caplog.set_level(logging.NOTSET)
    assert node.get_logger().debug('visible')
    assert not other.get_logger().debug('hidden')
    assert other.get_logger().get_effective_level() == LoggingSeverity.INFO
    assert [r.getMessage() for r in caplog.records] == ['visible']


def test_once_and_skip_first_filter_repeated_calls(init, caplog) -> None:
    rclpy.init(args=['prog'])
    logger = Node('chatty').get_logger()
    with caplog.at_level(logging.INFO):
        for index in range(3):
            logger.info(f'once {index}', once=True)
            logger.warning(f'skip {index}', skip_first=True)
    assert [r.getMessage() for r in caplog.records] == ['once 0', 'skip 1', 'skip 2']


def test_throttle_uses_the_given_clock(init, caplog) -> None:
    rclpy.init(args=['prog'])
    node = Node('throttled')
    executor = SingleThreadedExecutor()
    executor.add_node(node)

    def report() -> None:
        node.get_logger().info('tick', throttle_duration_sec=1.0)

    node.create_timer(0.25, report)
    with caplog.at_level(logging.INFO):
        for _ in range(8):
            executor.spin_once()
    # Calls at 0.25 s steps of virtual time; at most one message per virtual second.
    assert len(caplog.records) == 2


def test_unknown_logging_options_and_non_string_messages_raise(init) -> None:
    rclpy.init(args=['prog'])
    logger = Node('strict').get_logger()
    with pytest.raises(TypeError, match='recognized logging options'):
        logger.info('x', exc_info=True)
    with pytest.raises(TypeError, match='str'):
        logger.info(42)


def test_child_loggers_extend_the_name_and_levels_are_hierarchical(init, caplog) -> None:
    parent = get_logger('r0')
    child = parent.get_child('algo')
    assert child.name == 'r0.algo'
    parent.set_level(LoggingSeverity.ERROR)
    assert not child.is_enabled_for(LoggingSeverity.WARN)
    assert child.is_enabled_for(LoggingSeverity.FATAL)
    parent.set_level(LoggingSeverity.UNSET)


def test_log_can_name_another_logger(init, caplog) -> None:
    rclpy.init(args=['prog'])
    logger = Node('algo').get_logger()
    with caplog.at_level(logging.INFO):
        assert logger.log('elsewhere', LoggingSeverity.INFO, name='algo.planner')
    assert [r.name for r in caplog.records] == ['ros.algo.planner']
