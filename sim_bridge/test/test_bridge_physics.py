"""The bridge's ``physics`` parameter picks the engine's physics backend by name."""

import logging
import sys
from pathlib import Path

import pytest
from sim_bridge.bridge_node import SimBridgeNode
from swarm_runtime.ros import Parameter, SingleThreadedExecutor, rclpy
from swarm_runtime.simulation import spin_until
from swarm_sim.errors import ConfigurationError
from swarm_sim.physics import NumpyPhysics

FIVE_ROOMS = Path(__file__).parent / 'data' / 'five_rooms.lay'


@pytest.fixture
def ros():
    rclpy.init(args=[])
    executor = SingleThreadedExecutor()
    yield executor
    executor.shutdown()
    rclpy.try_shutdown()


def bridge_with(**params):
    overrides = {'site_file': str(FIVE_ROOMS), 'robot_count': 2, 'departure': 'edge'}
    overrides.update(params)
    return SimBridgeNode(parameter_overrides=[Parameter(k, value=v) for k, v in overrides.items()])


def test_the_bridge_runs_numpy_physics_by_default(ros):
    bridge = bridge_with()
    try:
        assert bridge.get_parameter('physics').value == 'numpy'
        assert isinstance(bridge.engine.world, NumpyPhysics)
    finally:
        bridge.destroy_node()


@pytest.mark.builtin_only(reason="steps the bridge with the built-in runtime's sim-time helper")
def test_the_bridge_runs_pybullet_physics_when_asked(ros):
    pytest.importorskip('pybullet', reason='pybullet is not installed (Python > 3.11?)')
    from swarm_sim.pybullet_physics import PybulletPhysics

    bridge = bridge_with(physics='pybullet')
    ros.add_node(bridge)
    world = bridge.engine.world
    assert isinstance(world, PybulletPhysics)
    assert spin_until(ros, lambda: bridge.sim_time_s >= 1.0, max_wall_time_s=20.0)
    ros.remove_node(bridge)
    bridge.destroy_node()
    assert world.client == -1  # the pybullet client is released


def test_an_unknown_physics_backend_is_refused_by_name(ros):
    with pytest.raises(ConfigurationError, match="physics: 'ode' is not one of numpy, pybullet"):
        bridge_with(physics='ode')


def test_the_bridge_exits_2_when_pybullet_physics_is_asked_without_pybullet(
    monkeypatch, caplog, capfd
):
    from sim_bridge.bridge_node import main

    monkeypatch.setitem(sys.modules, 'pybullet', None)  # as on a machine without it
    params = [f'site_file:={FIVE_ROOMS}', 'departure:=edge', 'physics:=pybullet']
    args = ['sim_bridge', '--ros-args', *[a for p in params for a in ('-p', p)]]
    assert main(args) == 2
    # The built-in runtime logs through Python logging, real rclpy through rcutils (stderr).
    errors = [r.getMessage() for r in caplog.records if r.levelno >= logging.ERROR]
    errors += [line for line in capfd.readouterr().err.splitlines() if 'pybullet' in line]
    assert len(errors) == 1
    assert "pybullet is not installed: pip install 'swarm_sim[pybullet]'" in errors[0]
