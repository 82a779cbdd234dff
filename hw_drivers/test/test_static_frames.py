"""The static frames node: the sensor mounts of a robot on /tf_static, as the simulator has them."""

from __future__ import annotations

import subprocess
import sys

import pytest
from hw_drivers.errors import ConfigurationError
from hw_drivers.parameters import STATIC_FRAMES_PARAMETERS, StaticFramesNodeConfig
from hw_drivers.robot_bringup.cli import BringupOptions, build_plan, driver_parameters
from hw_drivers.static_frames_node import StaticFramesNode, mount_transforms
from swarm_runtime.bag.testing import spin_until
from swarm_runtime.ros import Node, Parameter, SingleThreadedExecutor, message_module, rclpy
from swarm_runtime.tf import tf_static_qos

try:
    tf2_msgs = message_module('tf2_msgs')
except ImportError as err:
    pytest.skip(f'tf2_msgs not importable: {err}', allow_module_level=True)


@pytest.fixture
def executor():
    # The DDS domain and the discovery range are the test process's (conftest.py).
    rclpy.init()
    executor = SingleThreadedExecutor()
    yield executor
    for node in list(executor.get_nodes()):
        executor.remove_node(node)
        node.destroy_node()
    executor.shutdown()
    rclpy.try_shutdown()


def _latched_tree(executor, node_parameters):
    node = StaticFramesNode(
        namespace='r3',
        parameter_overrides=[Parameter(k, value=v) for k, v in node_parameters.items()],
    )
    executor.add_node(node)
    got = []
    viewer = Node('viewer')
    viewer.create_subscription(tf2_msgs.TFMessage, '/tf_static', got.append, tf_static_qos())
    executor.add_node(viewer)
    assert spin_until(executor, lambda: got, timeout_s=20.0)
    return {t.child_frame_id: t for t in got[-1].transforms}


def test_the_bringup_prefix_gives_the_frames_the_drivers_stamp(executor):
    params = driver_parameters('r3')
    tree = _latched_tree(
        executor, {**params['static_frames_node'], 'laser_xyz_m': [0.05, 0.0, 0.2]}
    )
    driver_frames = {
        params[name]['frame_id'] for name in ('rplidar_node', 'gas_adc_node', 'mpu6050_node')
    }
    assert set(tree) == driver_frames == {'r3/laser', 'r3/gas_sensor', 'r3/imu_link'}
    assert {t.header.frame_id for t in tree.values()} == {params['aoa_receiver_node']['frame_id']}
    laser = tree['r3/laser'].transform
    assert (laser.translation.x, laser.translation.y, laser.translation.z) == (0.05, 0.0, 0.2)
    assert (laser.rotation.z, laser.rotation.w) == (0.0, 1.0)


def test_the_defaults_are_the_simulated_robot(executor):
    # The robot install has no simulator: compare where it is installed.
    engine = pytest.importorskip('swarm_sim.engine')
    tree = _latched_tree(executor, {'frame_prefix': 'r3/'})
    offsets = {child: tree[child].transform.translation for child in tree}
    assert offsets['r3/gas_sensor'].x == engine.EngineConfig().gas.sensor_offset_m
    # The simulated lidar and IMU sit at the robot's centre.
    for child in ('r3/laser', 'r3/imu_link'):
        assert (offsets[child].x, offsets[child].y, offsets[child].z) == (0.0, 0.0, 0.0)


@pytest.mark.parametrize('bad', [[0.1, 0.2], [0.0, float('nan'), 0.0]])
def test_an_offset_that_is_not_three_finite_numbers_is_refused(bad):
    defaults = StaticFramesNodeConfig()
    offsets = {n: getattr(defaults, n) for n in ('laser_xyz_m', 'imu_xyz_m', 'gas_sensor_xyz_m')}
    offsets['imu_xyz_m'] = bad
    with pytest.raises(ConfigurationError, match='imu_xyz_m'):
        mount_transforms('r0/', offsets)


def test_bringup_starts_the_static_frames_after_the_pump_with_the_robot_prefix():
    plan = build_plan(BringupOptions(robot='r2', launcher='ros2'))
    names = [spec.name for spec in plan]
    assert names[:2] == ['pump_node', 'static_frames_node']
    command = ' '.join(plan[1].command)
    assert command.startswith('ros2 run hw_drivers static_frames_node')
    assert 'frame_prefix:=r2/' in command
    assert '__ns:=/r2' in command


def test_help_lists_the_mounting_parameters_without_starting_ros():
    result = subprocess.run(
        [sys.executable, '-m', 'hw_drivers.static_frames_node', '--help'],
        capture_output=True,
        text=True,
        timeout=60,
        check=False,
    )
    assert result.returncode == 0, result.stderr
    assert result.stdout.startswith('usage: static_frames_node [--help]')
    for name in STATIC_FRAMES_PARAMETERS.names:
        assert name in result.stdout
