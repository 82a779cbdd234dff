"""RPLidar A1 device I/O: the request/response sequence and the scan session.

:class:`RPLidar` speaks the protocol over an injected :class:`SerialPort` with an injected
motor strategy and sleep function. :class:`RPLidarSession` is what the reconnecting
:class:`~hw_drivers.worker.DeviceWorker` polls: it opens the port, checks health (reset on
Error), reads the device info, spins the motor up, starts the standard scan and then turns
the byte stream into revolutions handed to a callback. Stalls, a high rate of rejected bytes
and an input backlog are handled by restarting the scan or dropping to the latest data.
"""

from __future__ import annotations

import errno
import time
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any, Protocol

from hw_drivers.errors import (
    ConfigurationError,
    DeviceHealthError,
    DeviceTimeoutError,
)
from hw_drivers.rplidar_protocol import (
    DESCRIPTOR_SIZE,
    HEALTH_DESCRIPTOR,
    INFO_DESCRIPTOR,
    SCAN_DESCRIPTOR,
    Command,
    Descriptor,
    DeviceInfo,
    Health,
    HealthStatus,
    Revolution,
    RevolutionAssembler,
    SampleStreamDecoder,
    check_descriptor,
    decode_health,
    decode_info,
    encode_request,
)
from hw_drivers.serial_transport import SerialPort, open_serial_port

__all__ = [
    'DtrMotorControl',
    'MotorControl',
    'RPLidar',
    'RPLidarConfig',
    'RPLidarSession',
    'connect_rplidar',
]


class MotorControl(Protocol):
    """Switches the scan motor of an RPLidar."""

    def set_running(self, port: Any, running: bool) -> None:
        """Start (True) or stop (False) the motor."""
        ...


class DtrMotorControl:
    """A1 motor through the adapter's DTR line.

    Slamtec's SDK runs the motor with DTR de-asserted (``motor_on_dtr=False``); some adapter
    revisions are reported the other way round, hence the parameter.
    A pty has no DTR line (ENOTTY): that is tolerated so the driver runs against fakes.
    """

    def __init__(self, *, motor_on_dtr: bool = False) -> None:
        self.motor_on_dtr = motor_on_dtr

    def set_running(self, port: Any, running: bool) -> None:
        """Set DTR to the level that runs or stops the motor."""
        try:
            port.dtr = self.motor_on_dtr if running else not self.motor_on_dtr
        except OSError as err:
            if err.errno != errno.ENOTTY:
                raise


@dataclass(frozen=True)
class RPLidarConfig:
    """Timing and robustness settings of the RPLidar driver.

    Attributes:
        port: device path or pyserial URL.
        baudrate: serial speed [baud] (A1: 115200).
        motor_on_dtr: DTR level that runs the motor (Slamtec default False).
        response_timeout_s: time allowed for a descriptor or response payload [s].
        stop_settle_s: pause after STOP before flushing [s].
        reset_settle_s: pause after RESET before flushing [s].
        spin_up_s: pause between motor start and SCAN [s].
        read_chunk_bytes: most bytes read per poll.
        min_read_bytes: bytes asked for per poll even when fewer are waiting; the port's read
            timeout bounds the wait, and larger reads keep the per-call decoding cost low.
        stall_timeout_s: no revolution for this long restarts the scan [s].
        max_reject_ratio: rejected bytes / received bytes over one second that restarts the scan.
        max_backlog_bytes: input backlog beyond which unread data is dropped.
        min_points: revolutions with fewer samples are discarded.
    """

    port: str = '/dev/rplidar'
    baudrate: int = 115200
    motor_on_dtr: bool = False
    response_timeout_s: float = 1.0
    stop_settle_s: float = 0.05
    reset_settle_s: float = 2.0
    spin_up_s: float = 1.0
    read_chunk_bytes: int = 4096
    min_read_bytes: int = 512
    stall_timeout_s: float = 1.0
    max_reject_ratio: float = 0.01
    max_backlog_bytes: int = 4000
    min_points: int = 50

    def __post_init__(self) -> None:
        for name in ('response_timeout_s', 'stall_timeout_s'):
            if getattr(self, name) <= 0.0:
                raise ConfigurationError(f'{name} must be > 0, got {getattr(self, name)}')
        for name in ('stop_settle_s', 'reset_settle_s', 'spin_up_s'):
            if getattr(self, name) < 0.0:
                raise ConfigurationError(f'{name} must be >= 0, got {getattr(self, name)}')
        if self.baudrate <= 0 or self.read_chunk_bytes < 5 or self.max_backlog_bytes < 5:
            raise ConfigurationError('baudrate, read_chunk_bytes and max_backlog_bytes too small')
        if not 0.0 < self.max_reject_ratio <= 1.0:
            raise ConfigurationError(
                f'max_reject_ratio must be in (0, 1], got {self.max_reject_ratio}'
            )


class RPLidar:
    """Request/response commands of the RPLidar over an open port.

    Args:
        port: the open serial port (its read timeout bounds each read).
        motor: motor strategy.
        config: timing settings.
        sleep: pause function [s]; injectable for tests.
        clock: monotonic clock [s]; injectable for tests.
    """

    def __init__(
        self,
        port: SerialPort,
        motor: MotorControl,
        config: RPLidarConfig,
        *,
        sleep: Callable[[float], None] = time.sleep,
        clock: Callable[[], float] = time.monotonic,
    ) -> None:
        self.port = port
        self.motor = motor
        self.config = config
        self._sleep = sleep
        self._clock = clock

    def read_exact(self, size: int) -> bytes:
        """Read ``size`` bytes within the response timeout.

        Raises:
            DeviceTimeoutError: fewer bytes arrived in time.
        """
        deadline = self._clock() + self.config.response_timeout_s
        data = bytearray()
        while len(data) < size:
            chunk = self.port.read(size - len(data))
            if chunk:
                data += chunk
            elif self._clock() >= deadline:
                msg = f'timeout: got {len(data)} of {size} bytes from the lidar'
                raise DeviceTimeoutError(msg)
        return bytes(data)

    def stop(self) -> None:
        """Leave scan mode, wait and flush stale bytes."""
        self.port.write(encode_request(Command.STOP))
        self._sleep(self.config.stop_settle_s)
        self.port.reset_input_buffer()

    def reset(self) -> None:
        """Reboot the lidar core, wait and flush its banner."""
        self.port.write(encode_request(Command.RESET))
        self._sleep(self.config.reset_settle_s)
        self.port.reset_input_buffer()

    def _request(self, command: Command, expected: Descriptor) -> bytes:
        self.port.write(encode_request(command))
        check_descriptor(self.read_exact(DESCRIPTOR_SIZE), expected)
        return self.read_exact(expected.length)

    def get_info(self) -> DeviceInfo:
        """Ask model, firmware, hardware revision and serial number."""
        return decode_info(self._request(Command.GET_INFO, INFO_DESCRIPTOR))

    def get_health(self) -> Health:
        """Ask the health status."""
        return decode_health(self._request(Command.GET_HEALTH, HEALTH_DESCRIPTOR))

    def set_motor(self, running: bool) -> None:
        """Start or stop the motor."""
        self.motor.set_running(self.port, running)

    def start_scan(self) -> None:
        """Start the motor, wait for spin-up and start the standard scan."""
        self.set_motor(True)
        self._sleep(self.config.spin_up_s)
        self.port.write(encode_request(Command.SCAN))
        check_descriptor(self.read_exact(DESCRIPTOR_SIZE), SCAN_DESCRIPTOR)

    def ensure_healthy(self) -> Health:
        """Check health; on Error reset once and check again.

        Raises:
            DeviceHealthError: the device still reports Error after a reset.
        """
        health = self.get_health()
        if health.status is HealthStatus.ERROR:
            self.reset()
            self.stop()
            health = self.get_health()
            if health.status is HealthStatus.ERROR:
                msg = f'lidar health Error (code 0x{health.error_code:04X}) persists after reset'
                raise DeviceHealthError(msg)
        return health

    def shutdown(self) -> None:
        """STOP, motor off, close; never raises (used on every exit path)."""
        for action in (
            lambda: self.port.write(encode_request(Command.STOP)),
            lambda: self.set_motor(False),
            self.port.close,
        ):
            try:
                action()
            except OSError:
                continue


class RPLidarSession:
    """A scanning lidar: each poll reads available bytes and emits completed revolutions.

    Args:
        lidar: the initialised device (scan already started).
        on_revolution: receives each completed revolution (called from the worker thread).
        clock: monotonic clock [s].
    """

    def __init__(
        self,
        lidar: RPLidar,
        on_revolution: Callable[[Revolution], None],
        *,
        info: DeviceInfo,
        health: Health,
        clock: Callable[[], float] = time.monotonic,
    ) -> None:
        self.lidar = lidar
        self.info = info
        self.health = health
        self._on_revolution = on_revolution
        self._clock = clock
        self.decoder = SampleStreamDecoder()
        self.assembler = RevolutionAssembler(min_points=lidar.config.min_points)
        now = clock()
        self._last_revolution_s = now
        self._window_start_s = now
        self._window_received = 0
        self._window_rejected_start = 0
        self.scan_restarts = 0
        self.dropped_backlogs = 0
        self.revolutions = 0

    def poll(self) -> bool:
        """Read what the port has (at least one byte, bounded by the read timeout)."""
        port = self.lidar.port
        config = self.lidar.config
        waiting = port.in_waiting
        if waiting > config.max_backlog_bytes:
            port.reset_input_buffer()
            self.decoder.reset()
            self.assembler.reset()
            self.dropped_backlogs += 1
            waiting = 0
        data = port.read(min(max(waiting, config.min_read_bytes), config.read_chunk_bytes))
        now = self._clock()
        produced = False
        if data:
            self._window_received += len(data)
            samples = self.decoder.feed(data)
            for revolution in self.assembler.add(samples, now):
                self.revolutions += 1
                self._last_revolution_s = now
                self._on_revolution(revolution)
                produced = True
        self._check_stream(now)
        return produced

    def _check_stream(self, now: float) -> None:
        config = self.lidar.config
        if now - self._last_revolution_s > config.stall_timeout_s:
            self.restart_scan()
            return
        if now - self._window_start_s >= 1.0:
            rejected = self.decoder.rejected_bytes - self._window_rejected_start
            received = self._window_received
            self._window_start_s = now
            self._window_received = 0
            self._window_rejected_start = self.decoder.rejected_bytes
            if received and rejected / received > config.max_reject_ratio:
                self.restart_scan()

    def restart_scan(self) -> None:
        """STOP, flush, restart motor and scan (stalled motor, noisy stream)."""
        self.scan_restarts += 1
        self.lidar.stop()
        self.lidar.set_motor(False)
        self.decoder.reset()
        self.assembler.reset()
        self.lidar.start_scan()
        now = self._clock()
        self._last_revolution_s = now
        self._window_start_s = now
        self._window_received = 0
        self._window_rejected_start = self.decoder.rejected_bytes

    def close(self) -> None:
        """Stop scanning, motor off, close the port."""
        self.lidar.shutdown()


def connect_rplidar(
    config: RPLidarConfig,
    on_revolution: Callable[[Revolution], None],
    *,
    open_port: Callable[[RPLidarConfig], SerialPort] | None = None,
    motor: MotorControl | None = None,
    sleep: Callable[[float], None] = time.sleep,
    clock: Callable[[], float] = time.monotonic,
) -> RPLidarSession:
    """Open the port and run the init sequence: STOP+flush, health, info, motor, SCAN.

    Raises:
        DeviceUnavailableError, DeviceTimeoutError, ProtocolError, DeviceHealthError,
        FatalDeviceError: see :mod:`hw_drivers.errors`; the port is closed before raising.
    """
    if open_port is None:

        def open_port(cfg: RPLidarConfig) -> SerialPort:
            return open_serial_port(cfg.port, baudrate=cfg.baudrate, timeout_s=0.1)

    port = open_port(config)
    lidar = RPLidar(
        port,
        motor or DtrMotorControl(motor_on_dtr=config.motor_on_dtr),
        config,
        sleep=sleep,
        clock=clock,
    )
    try:
        lidar.set_motor(False)
        lidar.stop()
        health = lidar.ensure_healthy()
        info = lidar.get_info()
        lidar.start_scan()
    except BaseException:
        lidar.shutdown()
        raise
    return RPLidarSession(lidar, on_revolution, info=info, health=health, clock=clock)
