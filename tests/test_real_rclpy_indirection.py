"""Where rclpy is importable, node code gets it and the real message modules, untouched.

There is no ROS here, so a stand-in ``rclpy`` and ``std_msgs`` package is put on the path of
a fresh interpreter; the indirection must hand out exactly those modules and nothing of the
built-in runtime.
"""

from __future__ import annotations

import os
import subprocess
import sys
import textwrap
from pathlib import Path

import pytest

RCLPY_SUBMODULES = {
    'node': 'class Node:\n    pass\n',
    'executors': (
        'class ExternalShutdownException(Exception):\n    pass\n'
        'class SingleThreadedExecutor:\n    pass\n'
    ),
    'qos': (
        'class QoSProfile:\n    pass\n'
        'class ReliabilityPolicy:\n    pass\n'
        'class HistoryPolicy:\n    pass\n'
        'class DurabilityPolicy:\n    pass\n'
        'qos_profile_sensor_data = object()\n'
        'qos_profile_system_default = object()\n'
    ),
    'parameter': 'class Parameter:\n    pass\n',
    'time': 'class Time:\n    pass\n',
    'duration': 'class Duration:\n    pass\n',
}


def _write_fake_ros(root: Path) -> None:
    package = root / 'rclpy'
    package.mkdir()
    (package / '__init__.py').write_text('STAND_IN = True\n')
    for name, source in RCLPY_SUBMODULES.items():
        (package / f'{name}.py').write_text(source)
    msg = root / 'std_msgs' / 'msg'
    msg.mkdir(parents=True)
    (root / 'std_msgs' / '__init__.py').write_text('')
    (msg / '__init__.py').write_text('class String:\n    STAND_IN = True\n')


def _run(root: Path, choice: str, code: str) -> subprocess.CompletedProcess[str]:
    env = {**os.environ, 'PYTHONPATH': str(root), 'SWARM_RUNTIME': choice}
    return subprocess.run(
        [sys.executable, '-c', textwrap.dedent(code)],
        env=env,
        capture_output=True,
        text=True,
        timeout=60,
        check=False,
    )


@pytest.mark.parametrize('choice', ['auto', 'rclpy'])
def test_real_rclpy_and_message_modules_are_handed_out_unchanged(
    tmp_path: Path, choice: str
) -> None:
    _write_fake_ros(tmp_path)
    result = _run(
        tmp_path,
        choice,
        """
        import sys
        import rclpy, rclpy.node, std_msgs.msg
        from swarm_runtime import ros
        assert ros.using_real_rclpy()
        assert ros.rclpy is rclpy and ros.Node is rclpy.node.Node
        assert ros.qos_profile_sensor_data is rclpy.qos.qos_profile_sensor_data
        assert ros.message_module('std_msgs') is std_msgs.msg
        assert 'swarm_runtime.builtin' not in sys.modules, 'built-in runtime was imported'
        assert 'swarm_runtime.messages' not in sys.modules, 'built-in messages were imported'
        print('ok')
        """,
    )
    assert result.returncode == 0, result.stderr
    assert result.stdout.strip() == 'ok'


def test_builtin_choice_ignores_an_installed_rclpy(tmp_path: Path) -> None:
    _write_fake_ros(tmp_path)
    result = _run(
        tmp_path,
        'builtin',
        """
        from swarm_runtime import ros
        assert not ros.using_real_rclpy()
        assert not hasattr(ros.rclpy, 'STAND_IN')
        assert not hasattr(ros.message_module('std_msgs').String, 'STAND_IN')
        print('ok')
        """,
    )
    assert result.returncode == 0, result.stderr
