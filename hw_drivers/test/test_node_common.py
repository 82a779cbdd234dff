"""What drivers share: status logging without a line per retry, timer gating, diagnostics text."""

import time

import pytest
from hw_drivers.aoa_receiver_node import AoaReceiverNode
from hw_drivers.errors import DeviceUnavailableError
from hw_drivers.fakes.clock import FakeClock
from hw_drivers.fakes.locator import FakeLocatorClient, ndjson_payload
from hw_drivers.node_common import DeviceMonitor, StatusLog, TimerGate, driver_help
from hw_drivers.parameters import RPLIDAR_PARAMETERS
from hw_drivers.worker import DeviceWorker, DiagnosticLevel
from swarm_common.params import render_value
from swarm_runtime.ros import Parameter, message_module
from swarm_runtime.testing import NodeTestBed

diagnostic_msgs = message_module('diagnostic_msgs')
OK = diagnostic_msgs.DiagnosticStatus.OK


class Logger:
    def __init__(self):
        self.lines = []

    def info(self, message):
        self.lines.append(('INFO', message))

    def warning(self, message):
        self.lines.append(('WARN', message))

    def error(self, message):
        self.lines.append(('ERROR', message))


def test_a_fault_that_persists_is_logged_once_then_every_30_s():
    clock = FakeClock()
    logger = Logger()
    log = StatusLog(logger, clock=clock)
    for _ in range(100):  # a retry every second for 100 s, always the same failure
        log.report(DiagnosticLevel.ERROR, 'no port', 'lidar: error while opening: no port')
        clock.advance(1.0)
    assert [m for _, m in logger.lines] == [
        'lidar: error while opening: no port',
        'lidar: error while opening: no port (for 30 s)',
        'lidar: error while opening: no port (for 60 s)',
        'lidar: error while opening: no port (for 90 s)',
    ]
    log.report(DiagnosticLevel.OK, 'ok', 'lidar: connected')
    log.report(DiagnosticLevel.OK, 'ok', 'lidar: connected')
    clock.advance(100.0)
    log.report(DiagnosticLevel.OK, 'ok', 'lidar: connected')
    assert logger.lines[-1] == ('INFO', 'lidar: connected')
    assert len(logger.lines) == 5  # an OK state gets no reminders


def test_a_worker_retrying_with_back_off_logs_one_line_not_one_per_attempt():
    clock = FakeClock()
    logger = Logger()

    def connect():
        raise DeviceUnavailableError('could not open port /dev/rplidar')

    worker = DeviceWorker('lidar', connect, clock=clock)
    monitor = DeviceMonitor('lidar', '/dev/rplidar', 1.0, logger)
    monitor.log = StatusLog(logger, clock=clock)
    for second in range(20):
        worker.run_once()
        monitor.entry(second * 10**9, worker)
        clock.advance(1.0)
    assert worker.fault_count >= 5  # 1, 2, 4, 5, 5 ... s apart
    assert len(logger.lines) == 1
    assert logger.lines[0][1].startswith('lidar: error while opening: could not open port')


def test_staleness_is_logged_once_although_its_age_grows():
    clock = FakeClock()
    logger = Logger()
    worker = DeviceWorker('gas', lambda: object(), clock=clock)
    worker.run_once()  # connected, but no data ever comes
    monitor = DeviceMonitor('gas', 'fake', 1.0, logger)
    monitor.log = StatusLog(logger, clock=clock)
    messages = []
    for second in range(1, 20):
        clock.advance(1.0)
        messages.append(monitor.entry(second * 10**9, worker).message)
    assert messages[0] == 'stale: no data yet (gas: connected)'
    assert len(logger.lines) == 1


class FakeTimer:
    def __init__(self):
        self.canceled = False
        self.resets = 0

    def is_canceled(self):
        return self.canceled

    def cancel(self):
        self.canceled = True

    def reset(self):
        self.canceled = False
        self.resets += 1


def test_the_timer_gate_stops_and_restarts_a_timer():
    timer = FakeTimer()
    gate = TimerGate(timer)
    gate.update(True)
    assert timer.resets == 0
    assert gate.running
    gate.update(False)
    gate.update(False)
    assert timer.canceled
    gate.update(True)
    assert gate.running
    assert timer.resets == 1


def test_help_lists_every_parameter_with_its_default():
    text = driver_help('rplidar_node', 'RPLidar A1 driver node.', RPLIDAR_PARAMETERS)
    assert text.startswith('usage: rplidar_node [--help] [--ros-args')
    for p in RPLIDAR_PARAMETERS.parameters:
        line = next(line for line in text.splitlines() if line.startswith(f'  {p.name} '))
        assert p.description_text in line
        assert line.endswith(f'[default: {render_value(p.default)}]')


@pytest.fixture
def bed():
    with NodeTestBed() as bed:
        yield bed


def test_the_aoa_node_says_the_locator_is_missing_not_connected(bed):
    diagnostics = bed.probe.collect('/diagnostics', diagnostic_msgs.DiagnosticArray)
    node = bed.add_node(
        AoaReceiverNode,
        parameter_overrides=[
            Parameter('device_thread', value=False),
            Parameter('listen_port', value=0),
            Parameter('stale_timeout_s', value=1.0),
        ],
    )
    bed.wait_for_graph()
    bed.spin_for(2.5)
    status = diagnostics[-1].status[0]
    assert status.level == diagnostic_msgs.DiagnosticStatus.ERROR
    port = node.server.port
    assert status.message == (
        f'stale: no data yet (locator not connected (listening on 127.0.0.1:{port}))'
    )
    assert 'connected (' not in status.message.replace('not connected (', '')
    client = FakeLocatorClient(port)
    try:
        # Bearings at 10 Hz until the next diagnostics report them (the socket delivers in
        # host time, which the built-in runtime's virtual clock may outrun).
        deadline = time.monotonic() + 20.0
        count = len(diagnostics)
        k = 0
        while len(diagnostics) <= count or diagnostics[-1].status[0].level != OK:
            assert time.monotonic() < deadline, diagnostics[-1].status[0].message
            client.send(ndjson_payload(k, 'AC', 10.0))
            k += 1
            time.sleep(0.005)
            bed.spin_for(0.1)
        status = diagnostics[-1].status[0]
        assert status.message == f'locator connected (listening on 127.0.0.1:{port})'
    finally:
        client.close()
    # Disconnected: first a warning, then, once the last bearing is too old, stale.
    count = len(diagnostics)
    assert bed.spin_until(lambda: len(diagnostics) > count, timeout_s=3.0)
    status = diagnostics[-1].status[0]
    assert status.level == diagnostic_msgs.DiagnosticStatus.WARN
    assert status.message == f'AoA locator not connected (listening on 127.0.0.1:{port})'
    bed.spin_for(2.5)
    status = diagnostics[-1].status[0]
    assert status.level == diagnostic_msgs.DiagnosticStatus.ERROR
    assert status.message.startswith('stale: no data for ')
    assert status.message.endswith(f'(locator not connected (listening on 127.0.0.1:{port}))')
