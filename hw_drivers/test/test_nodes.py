"""Driver nodes with fake devices, through their topics: types, frames, QoS, faults.

The same tests run on the built-in runtime (virtual time) and on real rclpy over DDS (real
time): a probe node collects what the drivers publish; the fakes are polled from the nodes'
timers (``device_thread`` false), so they run on the nodes' clock either way.
"""

import math
import os

import pytest
from hw_drivers.aoa_receiver_node import AoaReceiverNode
from hw_drivers.errors import ConfigurationError
from hw_drivers.fakes.locator import FakeLocatorClient, authors_payload, ndjson_payload
from hw_drivers.gas_node import GasNode
from hw_drivers.mpu6050_node import Mpu6050Node
from hw_drivers.rplidar_node import RPLidarNode
from swarm_runtime.ros import Parameter, message_module, qos_profile_sensor_data
from swarm_runtime.testing import NodeTestBed

from hw_drivers import gas_node

sensor_msgs = message_module('sensor_msgs')
swarm_interfaces = message_module('swarm_interfaces')
diagnostic_msgs = message_module('diagnostic_msgs')

FAKE_TIMER_MODE = [Parameter('fake_device', value=True), Parameter('device_thread', value=False)]


@pytest.fixture
def bed():
    with NodeTestBed() as bed:
        yield bed


def _collect(bed, msg_type, topic, qos=qos_profile_sensor_data):
    return bed.probe.collect(topic, msg_type, qos)


def _statuses(diagnostics, name_part):
    return [s for array in diagnostics for s in array.status if name_part in s.name]


def _level(bed, diagnostics, name_part):
    statuses = _statuses(diagnostics, name_part)
    return statuses[-1].level if statuses else None


def test_lidar_node_publishes_rep103_scans_and_recovers_from_an_unplug(bed):
    scans = _collect(bed, sensor_msgs.LaserScan, '/r0/scan')
    diagnostics = _collect(bed, diagnostic_msgs.DiagnosticArray, '/diagnostics', 10)
    node = bed.add_node(
        RPLidarNode,
        namespace='r0',
        parameter_overrides=[*FAKE_TIMER_MODE, Parameter('frame_id', value='r0/laser')],
    )
    bed.wait_for_graph()
    assert bed.spin_until(lambda: len(scans) >= 3, timeout_s=10.0)
    scan = scans[-1]
    assert scan.header.frame_id == 'r0/laser'
    assert len(scan.ranges) == 360
    assert scan.angle_min == pytest.approx(-math.pi)
    assert scan.angle_increment == pytest.approx(2 * math.pi / 360)
    # The fake room: 1 m behind the device's 0 deg mark, i.e. 1 m straight ahead of laser +x.
    assert scan.ranges[180] == pytest.approx(1.0, abs=0.01)
    # One revolution at the fake's 5.5 Hz, timed on the node's clock (polled every 10 ms).
    assert scan.scan_time == pytest.approx(0.18, abs=0.03)
    ok = diagnostic_msgs.DiagnosticStatus.OK
    assert bed.spin_until(lambda: _level(bed, diagnostics, 'lidar') == ok, timeout_s=5.0)

    node._session.lidar.port.unplugged = True
    count = len(scans)
    bed.spin_for(0.5)
    assert len(scans) <= count + 2  # at most the revolution already read, and one in flight
    stalled = len(scans)
    bed.spin_for(0.6)
    assert len(scans) == stalled
    error = diagnostic_msgs.DiagnosticStatus.ERROR
    assert bed.spin_until(lambda: _level(bed, diagnostics, 'lidar') == error, timeout_s=3.0)
    # Reconnected after the 1 s back-off: scans flow again, diagnostics recover.
    assert bed.spin_until(lambda: len(scans) >= stalled + 3, timeout_s=10.0)
    assert bed.spin_until(lambda: _level(bed, diagnostics, 'lidar') == ok, timeout_s=5.0)


def test_gas_node_flags_warm_up_then_reports_the_background(bed):
    readings = _collect(bed, swarm_interfaces.GasReading, '/r0/gas')
    bed.add_node(
        GasNode,
        namespace='r0',
        parameter_overrides=[*FAKE_TIMER_MODE, Parameter('warmup_s', value=1.0)],
    )
    bed.wait_for_graph()
    assert bed.spin_until(lambda: readings and not readings[-1].warming_up, timeout_s=10.0)
    assert readings[0].warming_up
    assert 70 <= readings[-1].raw <= 90  # 0.26 V of a 3.3 V supply
    assert readings[-1].volts == pytest.approx(0.26, abs=0.002)
    assert readings[-1].header.frame_id == 'gas_sensor'


@pytest.mark.parametrize('backend', ['ads1015', 'grove_hat', 'xiao_serial'])
def test_gas_node_runs_every_backend(bed, backend):
    readings = _collect(bed, swarm_interfaces.GasReading, '/gas')
    bed.add_node(
        GasNode, parameter_overrides=[*FAKE_TIMER_MODE, Parameter('backend', value=backend)]
    )
    bed.wait_for_graph()
    assert bed.spin_until(lambda: len(readings) >= 3, timeout_s=10.0)
    assert 70 <= readings[-1].raw <= 90


def test_gas_node_refuses_an_unknown_backend(bed):
    with pytest.raises(ConfigurationError, match="backend: 'pcf8591' is not one of ads1115"):
        bed.add_node(GasNode, parameter_overrides=[Parameter('backend', value='pcf8591')])


def test_imu_node_publishes_only_after_calibration(bed):
    messages = _collect(bed, sensor_msgs.Imu, '/r0/imu')
    diagnostics = _collect(bed, diagnostic_msgs.DiagnosticArray, '/diagnostics', 10)
    bed.add_node(
        Mpu6050Node,
        namespace='r0',
        parameter_overrides=[*FAKE_TIMER_MODE, Parameter('calibration_s', value=2.0)],
    )
    bed.wait_for_graph()
    start_s = bed.now_s()
    assert bed.spin_until(lambda: bool(_statuses(diagnostics, 'imu')), timeout_s=5.0)
    assert 'calibrating' in _statuses(diagnostics, 'imu')[-1].message
    assert bed.spin_until(lambda: len(messages) >= 50, timeout_s=10.0)
    first_s = messages[0].header.stamp.sec + messages[0].header.stamp.nanosec * 1e-9
    assert first_s - start_s >= 2.0 - 0.1, 'nothing is published while calibrating'
    msg = messages[-1]
    q = msg.orientation
    assert q.x * q.x + q.y * q.y + q.z * q.z + q.w * q.w == pytest.approx(1.0)
    assert abs(2 * math.atan2(q.z, q.w)) < math.radians(0.5)  # still robot: no drift yet
    assert msg.linear_acceleration.z == pytest.approx(9.80665, abs=0.05)
    assert msg.orientation_covariance[8] > 0.0
    assert msg.header.frame_id == 'imu_link'


def test_aoa_node_publishes_peer_bearings_and_rssi_from_a_locator(bed):
    bearings = _collect(bed, swarm_interfaces.PeerBearingArray, '/r0/bearings')
    rssi = _collect(bed, swarm_interfaces.RssiArray, '/r0/rssi')
    node = bed.add_node(
        AoaReceiverNode,
        namespace='r0',
        parameter_overrides=[
            Parameter('device_thread', value=False),
            Parameter('listen_port', value=0),
            Parameter('own_tag_id', value='D2'),
        ],
    )
    bed.wait_for_graph()
    assert bed.spin_until(lambda: node.server is not None, timeout_s=5.0)
    client = FakeLocatorClient(node.server.port)
    try:
        client.send(authors_payload(1, 'D2', 10.0) + authors_payload(1, 'AC', 90.0))
        client.send(ndjson_payload(5, 'C3', -45.0, rssi=-61.5))
        assert bed.spin_until(
            lambda: {b.tag_id for m in bearings for b in m.bearings} == {'AC', 'C3'},
            timeout_s=5.0,
        )
        assert bed.spin_until(lambda: bool(rssi), timeout_s=5.0)
    finally:
        client.close()
    by_tag = {b.tag_id: b for m in bearings for b in m.bearings}
    assert by_tag['AC'].azimuth == pytest.approx(math.pi / 2)
    assert by_tag['C3'].azimuth == pytest.approx(-math.pi / 4)
    assert by_tag['AC'].elevation == pytest.approx(math.radians(10.0))
    assert rssi[-1].readings[0].emitter_id == 0xC3
    assert rssi[-1].readings[0].rssi_dbm == pytest.approx(-61.5)
    # Silence publishes nothing (no repeated old bearings).
    bed.spin_for(0.3)
    count = len(bearings)
    bed.spin_for(1.0)
    assert len(bearings) == count


def _value(diagnostics, name_part, key):
    statuses = _statuses(diagnostics, name_part)
    values = {kv.key: kv.value for kv in statuses[-1].values} if statuses else {}
    return values.get(key)


def test_aoa_node_counts_a_garbled_report_and_outlives_a_failed_read(bed):
    diagnostics = _collect(bed, diagnostic_msgs.DiagnosticArray, '/diagnostics', 10)
    bearings = _collect(bed, swarm_interfaces.PeerBearingArray, '/bearings')
    node = bed.add_node(
        AoaReceiverNode,
        parameter_overrides=[
            Parameter('device_thread', value=False),
            Parameter('listen_port', value=0),
        ],
    )
    bed.wait_for_graph()
    assert bed.spin_until(lambda: node.server is not None, timeout_s=5.0)
    server = node.server
    client = FakeLocatorClient(server.port)
    try:
        # An azimuth too large for a float: one invalid report, the connection stays.
        client.send(b'{"tagId":"D2","azimuth":' + b'9' * 400 + b'}')
        assert bed.spin_until(lambda: server.invalid_reports == 1, timeout_s=5.0)
        assert bed.spin_until(
            lambda: _value(diagnostics, 'aoa', 'invalid_reports') == '1', timeout_s=3.0
        )
        client.send(ndjson_payload(1, 'AC', 30.0))
        assert bed.spin_until(lambda: bool(bearings), timeout_s=5.0)
        assert server.client_connected
    finally:
        client.close()

    # A failed read: the worker closes the server; diagnostics must not touch its socket.
    def failing_poll():
        raise OSError('connection reset (test)')

    server.poll = failing_poll
    assert bed.spin_until(lambda: server.closed, timeout_s=3.0)
    seen = len(_statuses(diagnostics, 'aoa'))
    assert bed.spin_until(
        lambda: any(
            'connection reset (test)' in status.message
            for status in _statuses(diagnostics, 'aoa')[seen:]
        ),
        timeout_s=5.0,
    )
    # ... and listens again after its back-off.
    assert bed.spin_until(lambda: node.server is not server, timeout_s=5.0)
    assert not node.server.closed


def test_aoa_node_reports_a_missing_locator_as_stale(bed):
    diagnostics = _collect(bed, diagnostic_msgs.DiagnosticArray, '/diagnostics', 10)
    bed.add_node(
        AoaReceiverNode,
        parameter_overrides=[
            Parameter('device_thread', value=False),
            Parameter('listen_port', value=0),
            Parameter('stale_timeout_s', value=1.0),
        ],
    )
    bed.wait_for_graph()
    bed.spin_for(2.5)
    status = _statuses(diagnostics, 'aoa')[-1]
    assert status.level == diagnostic_msgs.DiagnosticStatus.ERROR
    assert 'stale' in status.message


def test_main_exits_with_status_2_on_invalid_parameters(monkeypatch):
    # Without rclpy (a robot test run with no ROS sourced) a driver runs on the built-in
    # runtime only when asked to; the test legs set SWARM_RUNTIME themselves.
    if 'SWARM_RUNTIME' not in os.environ:
        monkeypatch.setenv('SWARM_RUNTIME', 'builtin')
    assert gas_node.main(['--ros-args', '-p', 'backend:=pcf8591']) == 2
