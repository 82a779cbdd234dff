"""The swap test: the drivers (fake devices) feed the unchanged OA-Bug node on the built-in runtime.

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
    Node,
    Parameter,
    ReliabilityPolicy,
    SingleThreadedExecutor,
    message_module,
    qos_profile_sensor_data,
    rclpy,
)
from swarm_runtime.simulation import spin_until, wall_time_s

oabug_node = pytest.importorskip('oabug_robot.node')

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
    rclpy.init()
    params = driver_parameters(ROBOT, own_tag_id='D2', fake=True)
    timer_mode = {'device_thread': False}
    pump_output = FakePumpOutput(lambda: wall_time_s())
    drivers = [
        PumpNode(
            namespace=ROBOT, output=pump_output, parameter_overrides=_overrides(params['pump_node'])
        ),
        RPLidarNode(
            namespace=ROBOT, parameter_overrides=_overrides(params['rplidar_node'], **timer_mode)
        ),
        GasNode(
            namespace=ROBOT,
            parameter_overrides=_overrides(params['gas_adc_node'], warmup_s=0.5, **timer_mode),
        ),
        Mpu6050Node(
            namespace=ROBOT,
            parameter_overrides=_overrides(params['mpu6050_node'], calibration_s=1.0, **timer_mode),
        ),
        AoaReceiverNode(
            namespace=ROBOT,
            parameter_overrides=_overrides(
                params['aoa_receiver_node'], listen_port=0, **timer_mode
            ),
        ),
    ]
    oabug = oabug_node.OABugNode(
        namespace=ROBOT,
        parameter_overrides=[
            Parameter('variant', value='gas_sound'),
            Parameter('own_tag_id', value='D2'),
            Parameter('robot_count', value=1),
        ],
    )
    probe = Node('probe')
    executor = SingleThreadedExecutor()
    for node in [*drivers, oabug, probe]:
        executor.add_node(node)
    yield executor, drivers, oabug, probe, pump_output
    for node in [*drivers, oabug, probe]:
        node.destroy_node()
    rclpy.try_shutdown()


def _qos_compatible(publisher_qos, subscription_qos):
    """A best-effort publisher cannot serve a reliable subscription (DDS rule)."""
    return not (
        subscription_qos.reliability == ReliabilityPolicy.RELIABLE
        and publisher_qos.reliability == ReliabilityPolicy.BEST_EFFORT
    )


def test_every_topic_oabug_reads_is_published_by_a_driver_with_its_type_and_qos(robot):
    _, drivers, oabug, _, _ = robot
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
    executor, drivers, _, probe, pump_output = robot
    received = {topic: [] for topic in SIM_FRAMES}
    types = {
        'scan': sensor_msgs.LaserScan,
        'gas': swarm_interfaces.GasReading,
        'imu': sensor_msgs.Imu,
        'bearings': swarm_interfaces.PeerBearingArray,
    }
    for topic, msg_type in types.items():
        probe.create_subscription(
            msg_type, f'/r0/{topic}', received[topic].append, qos_profile_sensor_data
        )
    states = []
    commands = []
    probe.create_subscription(swarm_interfaces.OABugState, '/r0/state', states.append, 10)
    probe.create_subscription(geometry_msgs.Twist, '/r0/cmd_vel', commands.append, 10)
    aoa = drivers[-1]
    assert spin_until(executor, lambda: aoa.server is not None, max_wall_time_s=1.0)
    locator = FakeLocatorClient(aoa.server.port)
    try:
        # The robot's own tag and one peer, heard once a second.
        heartbeat = probe.create_timer(
            1.0,
            lambda: locator.send(
                ndjson_payload(int(wall_time_s()), 'D2', 0.0)
                + ndjson_payload(int(wall_time_s()), 'AC', 120.0)
            ),
        )
        moving = spin_until(
            executor,
            lambda: any(c.linear.x != 0.0 or c.angular.z != 0.0 for c in commands),
            max_wall_time_s=5.0,
        )
        assert moving, f'OA-Bug never moved; last state: {states[-1] if states else None}'
        spin_until(executor, lambda: False, max_wall_time_s=0.5)
        # The node publishes its state on every staleness change, so the last one is current.
        assert states, 'OA-Bug published no state'
        assert not states[-1].inputs_stale
        spin_until(executor, lambda: len(pump_output.transitions) >= 2, max_wall_time_s=7.0)
        probe.destroy_timer(heartbeat)
    finally:
        locator.close()
    for topic, frame in SIM_FRAMES.items():
        assert received[topic], f'nothing on {topic}'
        assert {m.header.frame_id for m in received[topic]} == {frame}
    assert all(b.tag_id != 'D2' for m in received['bearings'] for b in m.bearings)
    # The pump pulsed on and off again, within the driver's max on-time.
    (on_s, on), (off_s, off) = pump_output.transitions[:2]
    assert (on, off) == (True, False)
    assert 0.0 < off_s - on_s <= 1.0 + 0.03
