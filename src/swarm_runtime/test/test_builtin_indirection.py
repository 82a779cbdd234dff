"""swarm_runtime.ros hands out the built-in runtime where it is asked for or rclpy is missing."""

from __future__ import annotations

import importlib
import importlib.util
from collections.abc import Iterator
from types import ModuleType

import pytest
import swarm_runtime.ros

from swarm_runtime import builtin

REAL_RCLPY_AVAILABLE = importlib.util.find_spec('rclpy') is not None


@pytest.fixture
def reload_ros(monkeypatch) -> Iterator[object]:
    """Reload swarm_runtime.ros under a patched environment; restore it afterwards."""

    def reload(choice: str) -> ModuleType:
        monkeypatch.setenv('SWARM_RUNTIME', choice)
        return importlib.reload(swarm_runtime.ros)

    yield reload
    monkeypatch.undo()
    importlib.reload(swarm_runtime.ros)


def test_builtin_choice_hands_out_the_builtin_runtime(reload_ros) -> None:
    ros = reload_ros('builtin')
    assert ros.rclpy is builtin
    assert not ros.using_real_rclpy()
    assert ros.Node is builtin.node.Node
    assert ros.qos_profile_sensor_data is builtin.qos.qos_profile_sensor_data
    assert ros.message_module('std_msgs').String.__name__ == 'String'


@pytest.mark.skipif(REAL_RCLPY_AVAILABLE, reason='real rclpy is installed here')
def test_auto_choice_falls_back_to_builtin_without_rclpy(reload_ros) -> None:
    assert reload_ros('auto').rclpy is builtin


@pytest.mark.skipif(REAL_RCLPY_AVAILABLE, reason='real rclpy is installed here')
def test_insisting_on_rclpy_without_it_fails_clearly(reload_ros) -> None:
    with pytest.raises(ImportError, match='SWARM_RUNTIME=rclpy but rclpy cannot be imported'):
        reload_ros('rclpy')


def test_unknown_choice_is_rejected(reload_ros) -> None:
    with pytest.raises(ImportError, match='is not one of'):
        reload_ros('ros1')
