"""Driver nodes with fake devices on the built-in runtime: topics, types, QoS, faults."""

import math

import pytest
from hw_drivers.aoa_receiver_node import AoaReceiverNode
from hw_drivers.errors import ConfigurationError
from hw_drivers.fakes.locator import FakeLocatorClient, authors_payload, ndjson_payload
from hw_drivers.gas_node import GasNode
from hw_drivers.mpu6050_node import Mpu6050Node
from hw_drivers.rplidar_node import RPLidarNode
from swarm_runtime.ros import (
    Node,
    Parameter,
    SingleThreadedExecutor,
    message_module,
    qos_profile_sensor_data,
    rclpy,
)
from swarm_runtime.simulation import spin_until, wall_time_s

from hw_drivers import gas_node

sensor_msgs = message_module('sensor_msgs')
swarm_interfaces = message_module('swarm_interfaces')
diagnostic_msgs = message_module('diagnostic_msgs')

FAKE_TIMER_MODE = [Parameter('fake_device', value=True), Parameter('device_thread', value=False)]


@pytest.fixture
def ros():
    rclpy.init()
    executor = SingleThreadedExecutor()
    probe = Node('probe')
    executor.add_node(probe)
    nodes = []

    def add(node):
        nodes.append(node)
        executor.add_node(node)
        return node

    yield executor, probe, add
    for node in nodes:
        node.destroy_node()
    probe.destroy_node()
    rclpy.try_shutdown()


def _collect(probe, msg_type, topic, qos=qos_profile_sensor_data):
    received = []
    probe.create_subscription(msg_type, topic, received.append, qos)
    return received


def _statuses(diagnostics, name_part):
    return [s for array in diagnostics for s in array.status if name_part in s.name]


def test_lidar_node_publishes_rep103_scans_and_recovers_from_an_unplug(ros):
    executor, probe, add = ros
    scans = _collect(probe, sensor_msgs.LaserScan, '/r0/scan')
    diagnostics = _collect(probe, diagnostic_msgs.DiagnosticArray, '/diagnostics', 10)
    node = add(
        RPLidarNode(
            namespace='r0',
            parameter_overrides=[*FAKE_TIMER_MODE, Parameter('frame_id', value='r0/laser')],
        )
    )
    assert spin_until(executor, lambda: len(scans) >= 3, max_wall_time_s=5.0)
    scan = scans[-1]
    assert scan.header.frame_id == 'r0/laser'
    assert len(scan.ranges) == 360
    assert scan.angle_min == pytest.approx(-math.pi)
    assert scan.angle_increment == pytest.approx(2 * math.pi / 360)
    # The fake room: 1 m behind the device's 0 deg mark, i.e. 1 m straight ahead of laser +x.
    assert scan.ranges[180] == pytest.approx(1.0, abs=0.01)
    assert scan.scan_time == pytest.approx(0.18, abs=0.02)
    assert spin_until(executor, lambda: _statuses(diagnostics, 'lidar'), max_wall_time_s=2.0)
    assert _statuses(diagnostics, 'lidar')[-1].level == diagnostic_msgs.DiagnosticStatus.OK

    node._session.lidar.port.unplugged = True
    count = len(scans)
    spin_until(executor, lambda: False, max_wall_time_s=0.5)
    assert len(scans) <= count + 1  # at most the revolution already read
    stalled = len(scans)
    spin_until(executor, lambda: False, max_wall_time_s=0.6)
    assert len(scans) == stalled
    assert _statuses(diagnostics, 'lidar')[-1].level == diagnostic_msgs.DiagnosticStatus.ERROR
    # Reconnected after the 1 s back-off: scans flow again, diagnostics recover.
    assert spin_until(executor, lambda: len(scans) >= stalled + 3, max_wall_time_s=5.0)
    assert spin_until(
        executor,
        lambda: _statuses(diagnostics, 'lidar')[-1].level == diagnostic_msgs.DiagnosticStatus.OK,
        max_wall_time_s=3.0,
    )


def test_gas_node_flags_warm_up_then_reports_the_background(ros):
    executor, probe, add = ros
    readings = _collect(probe, swarm_interfaces.GasReading, '/r0/gas')
    add(
        GasNode(
            namespace='r0',
            parameter_overrides=[*FAKE_TIMER_MODE, Parameter('warmup_s', value=1.0)],
        )
    )
    assert spin_until(executor, lambda: len(readings) >= 20, max_wall_time_s=5.0)
    assert readings[0].warming_up
    assert not readings[-1].warming_up
    assert 70 <= readings[-1].raw <= 90  # 0.26 V of a 3.3 V supply
    assert readings[-1].volts == pytest.approx(0.26, abs=0.002)
    assert readings[-1].header.frame_id == 'gas_sensor'


@pytest.mark.parametrize('backend', ['ads1015', 'grove_hat', 'xiao_serial'])
def test_gas_node_runs_every_backend(ros, backend):
    executor, probe, add = ros
    readings = _collect(probe, swarm_interfaces.GasReading, '/gas')
    add(GasNode(parameter_overrides=[*FAKE_TIMER_MODE, Parameter('backend', value=backend)]))
    assert spin_until(executor, lambda: len(readings) >= 3, max_wall_time_s=3.0)
    assert 70 <= readings[-1].raw <= 90


def test_gas_node_refuses_an_unknown_backend(ros):
    _, _, _add = ros
    with pytest.raises(ConfigurationError, match='backend must be one of'):
        GasNode(parameter_overrides=[Parameter('backend', value='pcf8591')])


def test_imu_node_publishes_only_after_calibration(ros):
    executor, probe, add = ros
    messages = _collect(probe, sensor_msgs.Imu, '/r0/imu')
    diagnostics = _collect(probe, diagnostic_msgs.DiagnosticArray, '/diagnostics', 10)
    add(
        Mpu6050Node(
            namespace='r0',
            parameter_overrides=[*FAKE_TIMER_MODE, Parameter('calibration_s', value=2.0)],
        )
    )
    spin_until(executor, lambda: False, max_wall_time_s=1.5)
    assert messages == []
    assert 'calibrating' in _statuses(diagnostics, 'imu')[-1].message
    assert spin_until(executor, lambda: len(messages) >= 50, max_wall_time_s=3.0)
    msg = messages[-1]
    q = msg.orientation
    assert q.x * q.x + q.y * q.y + q.z * q.z + q.w * q.w == pytest.approx(1.0)
    assert abs(2 * math.atan2(q.z, q.w)) < math.radians(0.5)  # still robot: no drift yet
    assert msg.linear_acceleration.z == pytest.approx(9.80665, abs=0.05)
    assert msg.orientation_covariance[8] > 0.0
    assert msg.header.frame_id == 'imu_link'


def test_aoa_node_publishes_peer_bearings_and_rssi_from_a_locator(ros):
    executor, probe, add = ros
    bearings = _collect(probe, swarm_interfaces.PeerBearingArray, '/r0/bearings')
    rssi = _collect(probe, swarm_interfaces.RssiArray, '/r0/rssi')
    node = add(
        AoaReceiverNode(
            namespace='r0',
            parameter_overrides=[
                Parameter('device_thread', value=False),
                Parameter('listen_port', value=0),
                Parameter('own_tag_id', value='D2'),
            ],
        )
    )
    assert spin_until(executor, lambda: node.server is not None, max_wall_time_s=1.0)
    client = FakeLocatorClient(node.server.port)
    try:
        client.send(authors_payload(1, 'D2', 10.0) + authors_payload(1, 'AC', 90.0))
        client.send(ndjson_payload(5, 'C3', -45.0, rssi=-61.5))
        assert spin_until(
            executor,
            lambda: {b.tag_id for m in bearings for b in m.bearings} == {'AC', 'C3'},
            max_wall_time_s=2.0,
        )
        assert spin_until(executor, lambda: bool(rssi), max_wall_time_s=1.0)
    finally:
        client.close()
    by_tag = {b.tag_id: b for m in bearings for b in m.bearings}
    assert by_tag['AC'].azimuth == pytest.approx(math.pi / 2)
    assert by_tag['C3'].azimuth == pytest.approx(-math.pi / 4)
    assert by_tag['AC'].elevation == pytest.approx(math.radians(10.0))
    assert rssi[-1].readings[0].emitter_id == 0xC3
    assert rssi[-1].readings[0].rssi_dbm == pytest.approx(-61.5)
    # Silence publishes nothing (no repeated old bearings).
    count = len(bearings)
    spin_until(executor, lambda: False, max_wall_time_s=1.0)
    assert len(bearings) == count


def test_aoa_node_reports_a_missing_locator_as_stale(ros):
    executor, probe, add = ros
    diagnostics = _collect(probe, diagnostic_msgs.DiagnosticArray, '/diagnostics', 10)
    add(
        AoaReceiverNode(
            parameter_overrides=[
                Parameter('device_thread', value=False),
                Parameter('listen_port', value=0),
                Parameter('stale_timeout_s', value=1.0),
            ]
        )
    )
    spin_until(executor, lambda: False, max_wall_time_s=2.5)
    status = _statuses(diagnostics, 'aoa')[-1]
    assert status.level == diagnostic_msgs.DiagnosticStatus.ERROR
    assert 'stale' in status.message
    assert wall_time_s() > 2.0


def test_main_exits_with_status_2_on_invalid_parameters():
    assert gas_node.main(['--ros-args', '-p', 'backend:=pcf8591']) == 2
