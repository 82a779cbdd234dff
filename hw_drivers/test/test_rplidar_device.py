"""RPLidar device layer against loop://, a fake port with a fake clock, and a pty."""

import os
import threading
import time

import pytest
import serial
from hw_drivers.backoff import BackoffConfig
from hw_drivers.errors import (
    DeviceHealthError,
    DeviceTimeoutError,
    DeviceUnavailableError,
    ProtocolError,
)
from hw_drivers.fakes.clock import FakeClock
from hw_drivers.fakes.lidar import FakeRPLidar, FakeRPLidarPort
from hw_drivers.rplidar_device import (
    DtrMotorControl,
    RPLidar,
    RPLidarConfig,
    connect_rplidar,
)
from hw_drivers.rplidar_protocol import Command, HealthStatus
from hw_drivers.serial_transport import open_serial_port
from hw_drivers.worker import DeviceWorker, DiagnosticLevel

FAST = RPLidarConfig(port='fake', reset_settle_s=0.01, spin_up_s=0.01, stop_settle_s=0.001)


def test_requests_reach_the_wire_byte_exact_on_loop_url():
    port = serial.serial_for_url('loop://', timeout=0.05)
    lidar = RPLidar(port, DtrMotorControl(), FAST, sleep=lambda s: None)
    lidar.port.write(b'\xa5\x50')
    assert port.read(2) == b'\xa5\x50'
    lidar.stop()  # writes STOP and flushes: the echo is gone
    assert port.in_waiting == 0


def test_motor_polarity_sets_dtr_on_loop_url():
    port = serial.serial_for_url('loop://', timeout=0.05)
    DtrMotorControl(motor_on_dtr=False).set_running(port, True)
    assert port.dtr is False
    DtrMotorControl(motor_on_dtr=True).set_running(port, True)
    assert port.dtr is True
    DtrMotorControl(motor_on_dtr=True).set_running(port, False)
    assert port.dtr is False


def test_silent_port_times_out_instead_of_hanging():
    port = serial.serial_for_url('loop://', timeout=0.01)
    lidar = RPLidar(port, DtrMotorControl(), RPLidarConfig(response_timeout_s=0.05))
    with pytest.raises(DeviceTimeoutError, match='0 of 7 bytes'):
        lidar.read_exact(7)


def _session(device=None, clock=None, revolutions=None, **config):
    clock = clock or FakeClock()
    device = device or FakeRPLidar()
    port = FakeRPLidarPort(device, clock=clock)
    cfg = RPLidarConfig(**{**FAST.__dict__, **config})
    received = [] if revolutions is None else revolutions
    session = connect_rplidar(
        cfg, received.append, open_port=lambda _: port, sleep=clock.sleep, clock=clock
    )
    return session, port, clock, received


def test_connect_runs_stop_health_info_and_scan_and_streams_revolutions():
    session, port, clock, received = _session()
    assert port.device.requests[:4] == [
        Command.STOP,
        Command.GET_HEALTH,
        Command.GET_INFO,
        Command.SCAN,
    ]
    assert session.info.firmware == '1.29'
    assert port.dtr is False  # motor running with Slamtec's polarity
    for _ in range(100):
        clock.advance(0.01)
        session.poll()
    # 1 s at 2000 samples/s with 360 per revolution: 5 complete revolutions, minus the first.
    assert len(received) in (4, 5)
    assert all(len(r) == 360 for r in received)
    assert received[1].period_s == pytest.approx(0.18, abs=0.011)


def test_health_error_resets_the_device_then_continues():
    device = FakeRPLidar(health_status=HealthStatus.ERROR)
    session, _port, _, _ = _session(device)
    assert Command.RESET in device.requests
    assert session.health.status is HealthStatus.GOOD


def test_persistent_health_error_is_reported_and_the_port_closed():
    device = FakeRPLidar(health_status=HealthStatus.ERROR, error_until_reset=False)
    port = FakeRPLidarPort(device, clock=FakeClock())
    with pytest.raises(DeviceHealthError, match='persists after reset'):
        connect_rplidar(FAST, print, open_port=lambda _: port, sleep=lambda s: None)
    assert port.closed
    assert port.dtr is True  # motor stopped


def test_wrong_descriptor_is_a_protocol_error():
    device = FakeRPLidar()
    port = FakeRPLidarPort(device, clock=FakeClock())
    original = device._respond

    def garbled(command):
        answer = original(command)
        return answer.replace(b'\x06', b'\x07') if command == Command.GET_HEALTH else answer

    device._respond = garbled
    with pytest.raises(ProtocolError, match='unexpected descriptor'):
        connect_rplidar(FAST, print, open_port=lambda _: port, sleep=lambda s: None)


def test_noisy_stream_above_one_percent_restarts_the_scan():
    session, port, clock, received = _session()
    port.inject = lambda chunk: chunk + b'\xff' * (len(chunk) // 20 + 1)
    for _ in range(150):
        clock.advance(0.01)
        session.poll()
    assert session.scan_restarts >= 1
    assert received  # samples keep flowing through the resync


def test_stalled_stream_restarts_motor_and_scan():
    session, port, clock, _ = _session()
    port.device.scanning = False  # motor stalled: no more samples
    for _ in range(150):
        clock.advance(0.01)
        session.poll()
    assert session.scan_restarts >= 1
    assert port.device.requests.count(Command.SCAN) >= 2


def test_backlog_beyond_the_limit_drops_to_the_latest_data():
    session, _port, clock, received = _session(max_backlog_bytes=2000)
    clock.advance(1.0)  # 10000 bytes pile up while the reader is blocked
    session.poll()
    assert session.dropped_backlogs == 1
    for _ in range(60):
        clock.advance(0.01)
        session.poll()
    assert received


def test_unplugged_lidar_is_reopened_with_backoff_by_the_worker():
    clock = FakeClock()
    device = FakeRPLidar()
    ports = []
    plugged = {'in': True}
    received = []

    def open_port(_cfg):
        if not plugged['in']:
            raise serial.SerialException(2, 'could not open port /dev/rplidar')
        ports.append(FakeRPLidarPort(device, clock=clock))
        return ports[-1]

    worker = DeviceWorker(
        'lidar',
        lambda: connect_rplidar(
            FAST, received.append, open_port=open_port, sleep=clock.sleep, clock=clock
        ),
        clock=clock,
    )
    worker.run_once()
    assert worker.connected
    ports[-1].unplugged = True
    plugged['in'] = False
    clock.advance(0.01)
    worker.run_once()
    assert not worker.connected
    assert worker.status.level is DiagnosticLevel.ERROR
    assert 'retrying in 1.0 s' in worker.status.message
    clock.advance(1.0)
    worker.run_once()  # still missing: the next delay doubles
    assert 'retrying in 2.0 s' in worker.status.message
    plugged['in'] = True
    clock.advance(2.0)
    worker.run_once()
    assert worker.connected
    assert worker.connect_count == 2
    before = len(received)
    for _ in range(60):
        clock.advance(0.01)
        worker.run_once()
    assert len(received) > before


def _fake_lidar_on_pty(master_fd: int, device: FakeRPLidar, stop: threading.Event) -> None:
    """Master side of a pty: answer requests and stream samples in real time."""
    os.set_blocking(master_fd, False)
    while not stop.is_set():
        try:
            request = os.read(master_fd, 64)
        except BlockingIOError:
            request = b''
        except OSError:
            return
        reply = device.handle(request) + device.scan_bytes(20)
        if reply:
            try:
                os.write(master_fd, reply)
            except OSError:
                return
        stop.wait(0.01)


def test_driver_reads_revolutions_from_a_fake_lidar_on_a_pty():
    master, slave = os.openpty()
    device = FakeRPLidar(samples_per_revolution=120)
    stop = threading.Event()
    thread = threading.Thread(target=_fake_lidar_on_pty, args=(master, device, stop))
    thread.start()
    received = []
    try:
        config = RPLidarConfig(
            port=os.ttyname(slave), reset_settle_s=0.0, spin_up_s=0.0, stop_settle_s=0.02
        )
        session = connect_rplidar(config, received.append)
        for _ in range(400):
            session.poll()
            if len(received) >= 2:
                break
        session.close()
    finally:
        stop.set()
        thread.join(2.0)
        os.close(master)
        os.close(slave)
    assert len(received) >= 2
    assert all(len(r) == 120 for r in received)


def test_worker_thread_streams_and_stops_cleanly_in_real_time():
    device = FakeRPLidar(samples_per_revolution=120)
    ports = []
    received = []

    def open_port(_cfg):
        ports.append(FakeRPLidarPort(device, samples_per_s=4000.0))
        return ports[-1]

    worker = DeviceWorker(
        'lidar', lambda: connect_rplidar(FAST, received.append, open_port=open_port)
    )
    worker.start()
    deadline = time.monotonic() + 5.0
    while len(received) < 3 and time.monotonic() < deadline:
        time.sleep(0.01)
    worker.stop()
    assert len(received) >= 3
    assert ports[-1].closed
    assert ports[-1].dtr is True  # motor stopped on the way out


def test_worker_thread_outlives_a_driver_bug_and_reports_it():
    calls = []

    class Buggy:
        def poll(self):
            calls.append('poll')
            raise KeyError('driver bug')

        def close(self):
            calls.append('close')

    worker = DeviceWorker('buggy', Buggy, backoff=BackoffConfig(initial_s=0.01, max_s=0.02))
    worker.start()
    deadline = time.monotonic() + 5.0
    while calls.count('close') < 2 and time.monotonic() < deadline:
        time.sleep(0.01)
    worker.stop()
    assert calls.count('close') >= 2  # reconnected after each failure
    assert 'unexpected' in worker.status.message
    assert 'driver bug' in worker.status.message


def test_missing_serial_device_is_a_recoverable_error():
    with pytest.raises(DeviceUnavailableError, match='cannot open /dev/no-such-lidar'):
        open_serial_port('/dev/no-such-lidar', baudrate=115200, timeout_s=0.1)
