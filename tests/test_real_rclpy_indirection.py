"""Where rclpy is importable, node code gets it and the real message modules, untouched.

The first tests put a stand-in ``rclpy`` and ``std_msgs`` package on the path of a fresh
interpreter (so they hold with or without ROS): the indirection must hand out exactly those
modules and nothing of the built-in runtime. The others need the real rclpy (the rclpy leg
of the suite): the modules handed out are the real ones, the generated interfaces have the
type hashes the built-in runtime computes from the same definitions (so bags and mixed
graphs agree), and a message crosses from one process to another over DDS.
"""

from __future__ import annotations

import os
import subprocess
import sys
import textwrap
from pathlib import Path

import pytest
from swarm_runtime.ros import message_module, using_real_rclpy
from swarm_runtime.testing import NodeTestBed

needs_real_rclpy = pytest.mark.skipif(
    not using_real_rclpy(), reason='needs the real rclpy (SWARM_RUNTIME=rclpy)'
)

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


@needs_real_rclpy
def test_the_real_modules_are_handed_out_in_this_process() -> None:
    import importlib

    from swarm_runtime import ros

    real = importlib.import_module('rclpy')
    assert ros.rclpy is real
    assert ros.Node is importlib.import_module('rclpy.node').Node
    assert ros.rclpy.get_rmw_implementation_identifier() != 'swarm_runtime_builtin'
    for package in ('std_msgs', 'sensor_msgs', 'swarm_interfaces', 'tf2_msgs'):
        assert message_module(package) is importlib.import_module(f'{package}.msg')
    gas = message_module('swarm_interfaces').GasReading
    assert gas.__module__.startswith('swarm_interfaces.msg._'), 'the rosidl-generated class'


def _interface_types() -> list[str]:
    from swarm_runtime.messages.registry import default_registry

    ours = [
        f'swarm_interfaces/msg/{name}' for name in default_registry().type_names('swarm_interfaces')
    ]
    assert len(ours) >= 20
    return [
        *ours,
        'tf2_msgs/msg/TFMessage',
        'tf2_msgs/msg/TF2Error',
        'visualization_msgs/msg/Marker',
        'visualization_msgs/msg/MarkerArray',
        'sensor_msgs/msg/LaserScan',
    ]


@needs_real_rclpy
def test_generated_interfaces_have_the_type_hashes_of_their_definitions() -> None:
    from swarm_runtime.messages import get_typestore

    typestore = get_typestore()
    with NodeTestBed() as bed:
        node = bed.create_node('hashes')
        for typename in _interface_types():
            package, _, name = typename.split('/')
            msg_type = getattr(message_module(package), name)
            topic = f'/hash/{package}/{name}'
            node.create_publisher(msg_type, topic, 1)
            (info,) = node.get_publishers_info_by_topic(topic)
            assert info.topic_type == typename
            assert str(info.topic_type_hash) == typestore.hash_rihs01(typename), typename


PUBLISHER = """
from swarm_runtime.ros import ExternalShutdownException, message_module, rclpy
swarm = message_module('swarm_interfaces')
rclpy.init()
node = rclpy.create_node('gas_sensor')
pub = node.create_publisher(swarm.GasReading, '/xproc/gas', 10)
timer = node.create_timer(0.05, lambda: pub.publish(swarm.GasReading(raw=417, volts=2.5)))
try:
    rclpy.spin(node)
except (KeyboardInterrupt, ExternalShutdownException):
    pass
finally:
    node.destroy_node()
    rclpy.try_shutdown()
"""


@needs_real_rclpy
def test_a_project_message_crosses_processes_over_dds() -> None:
    swarm = message_module('swarm_interfaces')
    child = subprocess.Popen(
        [sys.executable, '-c', PUBLISHER],
        env={**os.environ, 'SWARM_RUNTIME': 'rclpy'},
        stdin=subprocess.DEVNULL,
        stdout=subprocess.DEVNULL,
        stderr=subprocess.PIPE,
        text=True,
    )
    try:
        with NodeTestBed() as bed:
            received = bed.probe.collect('/xproc/gas', swarm.GasReading)
            bed.wait_for_graph(timeout_s=60.0)
            # Data can arrive before the graph cache learns the publisher's node name (Fast
            # DDS sends node names on a topic of their own), so wait for both.
            graph = bed.probe.node

            def heard_and_named() -> bool:
                return len(received) >= 3 and (
                    ('gas_sensor', '/') in graph.get_node_names_and_namespaces()
                )

            bed.spin_until(heard_and_named, timeout_s=30.0)
            names = graph.get_node_names_and_namespaces()
    finally:
        child.terminate()
        _, stderr = child.communicate(timeout=30.0)
    assert len(received) >= 3
    assert ('gas_sensor', '/') in names
    assert received[-1].raw == 417
    assert received[-1].volts == pytest.approx(2.5)
    assert 'Traceback' not in stderr
