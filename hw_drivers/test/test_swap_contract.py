"""The swap test: the drivers (fake devices) feed the unchanged OA-Bug node, on either runtime.

It proves the algorithm gets the same contract from the drivers as from the sim bridge: the
topics it subscribes are published by the drivers with the same types and compatible QoS,
frames follow the simulator's naming (``<robot>/laser``... as in sim_bridge's bridge node),
and the closed loop runs: OA-Bug leaves its stale-input hold, drives, and its pump commands
reach the pump driver, which pulses the (fake) line.
"""

import pytest
from hw_drivers.aoa_receiver_node import AoaReceiverNode
from hw_drivers.fakes.gpio import FakePumpOutput
from hw_drivers.fakes.locator import FakeLocatorClient, ndjson_payload
from hw_drivers.gas_node import GasNode
from hw_drivers.mpu6050_node import Mpu6050Node
from hw_drivers.pump_node import PumpNode
from hw_drivers.robot_bringup.cli import driver_parameters
from hw_drivers.rplidar_node import RPLidarNode
from swarm_runtime.ros import (
    Parameter,
    ReliabilityPolicy,
    message_module,
    qos_profile_sensor_data,
    using_real_rclpy,
)
from swarm_runtime.testing import NodeTestBed

oabug_node = pytest.importorskip('oabug_robot.node')

# How late the pump may cut a pulse: a control tick on the virtual clock, more on a loaded
# host in real time.
LATE_S = 0.2 if using_real_rclpy() else 0.03

sensor_msgs = message_module('sensor_msgs')
geometry_msgs = message_module('geometry_msgs')
swarm_interfaces = message_module('swarm_interfaces')

ROBOT = 'r0'
# The simulator's frame ids for robot r0 (sim_bridge/bridge_node.py).
SIM_FRAMES = {
    'scan': 'r0/laser',
    'gas': 'r0/gas_sensor',
    'imu': 'r0/imu_link',
    'bearings': 'r0/base_link',
}


def _overrides(values, **extra):
    merged = {**values, **extra}
    return [Parameter(name, value=value) for name, value in merged.items()]


@pytest.fixture
def robot():
    with NodeTestBed() as bed:
        params = driver_parameters(ROBOT, own_tag_id='D2', fake=True)
        timer_mode = {'device_thread': False}
        pump_output = FakePumpOutput(bed.wall_time_s)
        drivers = [
            bed.add_node(
                PumpNode,
                namespace=ROBOT,
                output=pump_output,
                parameter_overrides=_overrides(params['pump_node']),
            ),
            bed.add_node(
                RPLidarNode,
                namespace=ROBOT,
                parameter_overrides=_overrides(params['rplidar_node'], **timer_mode),
            ),
            bed.add_node(
                GasNode,
                namespace=ROBOT,
                parameter_overrides=_overrides(params['gas_adc_node'], warmup_s=0.5, **timer_mode),
            ),
            bed.add_node(
                Mpu6050Node,
                namespace=ROBOT,
                parameter_overrides=_overrides(
                    params['mpu6050_node'], calibration_s=1.0, **timer_mode
                ),
            ),
            bed.add_node(
                AoaReceiverNode,
                namespace=ROBOT,
                parameter_overrides=_overrides(
                    params['aoa_receiver_node'], listen_port=0, **timer_mode
                ),
            ),
        ]
        oabug = bed.add_node(
            oabug_node.OABugNode,
            namespace=ROBOT,
            parameter_overrides=[
                Parameter('variant', value='gas_sound'),
                Parameter('own_tag_id', value='D2'),
                Parameter('robot_count', value=1),
            ],
        )
        yield bed, drivers, oabug, pump_output


def _qos_compatible(publisher_qos, subscription_qos):
    """A best-effort publisher cannot serve a reliable subscription (DDS rule)."""
    return not (
        subscription_qos.reliability == ReliabilityPolicy.RELIABLE
        and publisher_qos.reliability == ReliabilityPolicy.BEST_EFFORT
    )


def test_every_topic_oabug_reads_is_published_by_a_driver_with_its_type_and_qos(robot):
    _, drivers, oabug, _ = robot
    publishers = {
        p.topic_name: p for node in drivers for p in node.publishers if p.topic_name != '/rosout'
    }
    inputs = [s for s in oabug.subscriptions if not s.topic_name.startswith('/parameter')]
    assert {s.topic_name for s in inputs} >= {'/r0/scan', '/r0/imu', '/r0/gas', '/r0/bearings'}
    for subscription in inputs:
        publisher = publishers.get(subscription.topic_name)
        assert publisher is not None, f'no driver publishes {subscription.topic_name}'
        assert publisher.msg_type is subscription.msg_type
        assert _qos_compatible(publisher.qos_profile, subscription.qos_profile)
        if subscription.topic_name != '/r0/pump':
            # Sensor streams: the sensor-data profile on both sides, as the sim bridge does.
            assert publisher.qos_profile.reliability == qos_profile_sensor_data.reliability
    pump_sub = next(s for n in drivers for s in n.subscriptions if s.topic_name == '/r0/pump')
    oabug_pump = next(p for p in oabug.publishers if p.topic_name == '/r0/pump')
    assert pump_sub.msg_type is oabug_pump.msg_type
    assert _qos_compatible(oabug_pump.qos_profile, pump_sub.qos_profile)


def test_oabug_runs_on_the_drivers_and_its_pump_pulses_reach_the_line(robot):
    bed, drivers, _, pump_output = robot
    types = {
        'scan': sensor_msgs.LaserScan,
        'gas': swarm_interfaces.GasReading,
        'imu': sensor_msgs.Imu,
        'bearings': swarm_interfaces.PeerBearingArray,
    }
    received = {
        topic: bed.probe.collect(f'/r0/{topic}', msg_type, qos_profile_sensor_data)
        for topic, msg_type in types.items()
    }
    states = bed.probe.collect('/r0/state', swarm_interfaces.OABugState, 10)
    commands = bed.probe.collect('/r0/cmd_vel', geometry_msgs.Twist, 10)
    bed.wait_for_graph()
    aoa = drivers[-1]
    assert bed.spin_until(lambda: aoa.server is not None, timeout_s=5.0)
    locator = FakeLocatorClient(aoa.server.port)
    try:
        # The robot's own tag and one peer, heard once a second.
        heartbeat = bed.probe.node.create_timer(
            1.0,
            lambda: locator.send(
                ndjson_payload(int(bed.wall_time_s()), 'D2', 0.0)
                + ndjson_payload(int(bed.wall_time_s()), 'AC', 120.0)
            ),
        )
        moving = bed.spin_until(
            lambda: any(c.linear.x != 0.0 or c.angular.z != 0.0 for c in commands),
            timeout_s=30.0,
        )
        assert moving, f'OA-Bug never moved; last state: {states[-1] if states else None}'
        bed.spin_for(0.5)
        # The node publishes its state on every staleness change, so the last one is current.
        assert states, 'OA-Bug published no state'
        assert not states[-1].inputs_stale
        bed.spin_until(lambda: len(pump_output.transitions) >= 2, timeout_s=20.0)
        bed.probe.node.destroy_timer(heartbeat)
    finally:
        locator.close()
    for topic, frame in SIM_FRAMES.items():
        assert received[topic], f'nothing on {topic}'
        assert {m.header.frame_id for m in received[topic]} == {frame}
    assert all(b.tag_id != 'D2' for m in received['bearings'] for b in m.bearings)
    # The pump pulsed on and off again, within the driver's max on-time.
    (on_s, on), (off_s, off) = pump_output.transitions[:2]
    assert (on, off) == (True, False)
    assert 0.0 < off_s - on_s <= 1.0 + LATE_S
