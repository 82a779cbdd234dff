"""Each node declares its spec, and applies the parameters it allows to change while running."""

from __future__ import annotations

import pytest
from swarm_runtime.ros import Parameter, rclpy


@pytest.fixture
def ros():
    rclpy.init(args=[])
    yield
    rclpy.try_shutdown()


def _oabug():
    from oabug_robot.node import OABugNode
    from oabug_robot.node_settings import OABUG_PARAMETERS

    return OABugNode(namespace='/r0'), OABUG_PARAMETERS


def _sgba():
    from oabug_robot.sgba.node import SgbaNode
    from oabug_robot.sgba.settings import SGBA_PARAMETERS

    return SgbaNode(namespace='/r0'), SGBA_PARAMETERS


def _bayes():
    from bayes_swarm.node import BayesSwarmNode
    from bayes_swarm.node_settings import BAYES_SWARM_PARAMETERS

    return BayesSwarmNode(namespace='/r0'), BAYES_SWARM_PARAMETERS


def _msc():
    from msc_pf.node import MscPfNode
    from msc_pf.parameters import MSC_PF_PARAMETERS

    return MscPfNode(namespace='/r0'), MSC_PF_PARAMETERS


def _bridge():
    from sim_bridge.bridge_node import SimBridgeNode
    from sim_bridge.bridge_parameters import BRIDGE_PARAMETERS

    return SimBridgeNode(parameter_overrides=[Parameter('site_file', value='small')]), (
        BRIDGE_PARAMETERS
    )


def _lidar():
    from hw_drivers.parameters import RPLIDAR_PARAMETERS
    from hw_drivers.rplidar_node import RPLidarNode

    overrides = [Parameter('fake_device', value=True), Parameter('device_thread', value=False)]
    return RPLidarNode(namespace='/r0', parameter_overrides=overrides), RPLIDAR_PARAMETERS


NODES = {
    'oabug': _oabug,
    'sgba': _sgba,
    'bayes': _bayes,
    'msc': _msc,
    'bridge': _bridge,
    'lidar': _lidar,
}


@pytest.mark.parametrize('kind', sorted(NODES))
def test_the_node_declares_its_spec_with_descriptions_and_read_only_flags(ros, kind) -> None:
    node, spec = NODES[kind]()
    try:
        for definition in spec.parameters:
            descriptor = node.describe_parameter(definition.name)
            assert descriptor.description == definition.description_text
            assert descriptor.read_only == definition.read_only, definition.name
        read_only = next(p for p in spec.parameters if p.read_only)
        [result] = node.set_parameters([Parameter(read_only.name, value=read_only.default)])
        assert not result.successful
        assert 'read-only' in result.reason
    finally:
        node.destroy_node()


def test_oabug_takes_a_new_stale_timeout_and_refuses_a_bad_one(ros) -> None:
    node, _ = _oabug()
    [result] = node.set_parameters([Parameter('stale_timeout_s', value=2.5)])
    assert result.successful
    assert node._stale_timeout_s == 2.5
    # Out of the descriptor's range: ROS refuses it; at the range's open end: the spec does.
    [result] = node.set_parameters([Parameter('stale_timeout_s', value=-1.0)])
    assert not result.successful
    assert 'Parameter stale_timeout_s out of range' in result.reason
    [result] = node.set_parameters([Parameter('stale_timeout_s', value=0.0)])
    assert not result.successful
    assert 'parameter stale_timeout_s: must be > 0 s, got 0 s' in result.reason
    assert node._stale_timeout_s == 2.5
    node.destroy_node()


def test_msc_pf_steers_with_a_new_heading_gain(ros) -> None:
    node, _ = _msc()
    assert node.loop.steering.heading_gain == 2.0
    [result] = node.set_parameters([Parameter('heading_gain', value=4.0)])
    assert result.successful
    assert node.loop.steering.heading_gain == 4.0
    node.destroy_node()


def test_bayes_swarm_rebuilds_its_follower_after_a_change(ros) -> None:
    node, _ = _bayes()
    [result] = node.set_parameters([Parameter('arrival_tolerance_m', value=0.05)])
    assert result.successful
    assert node.controller.follower_config.arrival_tolerance_m == 0.05
    assert node.controller.follower_config.speed_mps == node.settings.planner.velocity_mps
    node.destroy_node()


def test_the_bridge_paces_its_physics_timer_by_a_new_real_time_factor(ros) -> None:
    node, _ = _bridge()
    period_ns = node._timer.timer_period_ns
    [result] = node.set_parameters([Parameter('real_time_factor', value=2.0)])
    assert result.successful
    assert node._timer.timer_period_ns == period_ns // 2
    node.destroy_node()
