"""swarm_runtime.ros hands out the built-in runtime where it is asked for or rclpy is missing."""

from __future__ import annotations

import importlib
import os
import subprocess
import sys
from collections.abc import Iterator
from types import ModuleType

import pytest
import swarm_runtime.ros

from swarm_runtime import builtin


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


# A machine without ROS, in a fresh interpreter: an import hook hides any installed rclpy.
_WITHOUT_RCLPY = """
import sys

class NoRclpy:
    def find_spec(self, name, path=None, target=None):
        if name == 'rclpy' or name.startswith('rclpy.'):
            raise ModuleNotFoundError(f'No module named {name!r}', name=name)
        return None

sys.meta_path.insert(0, NoRclpy())
"""


def _run_without_rclpy(choice: str, code: str) -> subprocess.CompletedProcess[str]:
    env = {**os.environ, 'SWARM_RUNTIME': choice}
    return subprocess.run(
        [sys.executable, '-c', _WITHOUT_RCLPY + code],
        env=env,
        capture_output=True,
        text=True,
        timeout=120,
    )


def test_auto_choice_falls_back_to_builtin_without_rclpy() -> None:
    result = _run_without_rclpy(
        'auto',
        'from swarm_runtime import builtin, ros\n'
        'assert ros.rclpy is builtin and not ros.using_real_rclpy()\n',
    )
    assert result.returncode == 0, result.stderr


def test_insisting_on_rclpy_without_it_fails_clearly() -> None:
    result = _run_without_rclpy('rclpy', 'import swarm_runtime.ros\n')
    assert result.returncode != 0
    assert 'SWARM_RUNTIME=rclpy but rclpy cannot be imported' in result.stderr


def test_unknown_choice_is_rejected(reload_ros) -> None:
    with pytest.raises(ImportError, match='is not one of'):
        reload_ros('ros1')
