"""RPLidar A1 driver node: publishes ``scan`` (sensor_msgs/LaserScan) and /diagnostics.

The device loop (open, health, info, scan, resync, reconnect with back-off) runs in its own
thread; a 20 Hz timer publishes the revolutions it completed. A revolution is published once,
never repeated: when the lidar stalls or is unplugged, ``scan`` goes quiet and /diagnostics
says why.

Run: ``ros2 run hw_drivers rplidar_node --ros-args -r __ns:=/r0 -p port:=/dev/rplidar``.
"""

from __future__ import annotations

import time
from collections import deque
from collections.abc import Callable
from typing import Any

from swarm_runtime.parameters import declare_config
from swarm_runtime.ros import (
    Node,
    message_module,
    qos_profile_sensor_data,
)

from hw_drivers.backoff import BackoffConfig
from hw_drivers.conversions import scan_to_ros
from hw_drivers.fakes.lidar import FakeRPLidar, FakeRPLidarPort
from hw_drivers.node_common import (
    DIAGNOSTICS_TOPIC,
    DeviceMonitor,
    DevicePoller,
    TimerGate,
    no_sleep,
    publish_diagnostics,
    run_driver_node,
    seconds_clock,
)
from hw_drivers.parameters import RPLIDAR_PARAMETERS, RPLidarNodeConfig
from hw_drivers.rplidar_device import RPLidarConfig, RPLidarSession, connect_rplidar
from hw_drivers.rplidar_protocol import HealthStatus, Revolution, ScanBinning, bin_revolution
from hw_drivers.worker import DeviceWorker, DiagnosticLevel

__all__ = ['RPLidarNode', 'main']

sensor_msgs = message_module('sensor_msgs')
diagnostic_msgs = message_module('diagnostic_msgs')


def device_configs(config: RPLidarNodeConfig) -> tuple[RPLidarConfig, ScanBinning]:
    """The device and binning configurations of the node's parameters.

    Raises:
        ConfigurationError: a value the device or binning configuration rejects.
    """
    device = RPLidarConfig(
        port=config.port,
        baudrate=config.baudrate,
        motor_on_dtr=config.motor_on_dtr,
        stall_timeout_s=config.stall_timeout_s,
    )
    binning = ScanBinning(
        bins=config.bins,
        angle_direction=config.angle_direction,
        zero_offset_rad=config.zero_offset_rad,
        range_min_m=config.range_min_m,
        range_max_m=config.range_max_m,
    )
    return device, binning


class RPLidarNode(Node):
    """Publishes the lidar's revolutions as LaserScan on ``scan``."""

    def __init__(self, **kwargs: Any) -> None:
        super().__init__('rplidar_node', **kwargs)
        config = declare_config(self, RPLIDAR_PARAMETERS).config
        self._device_config, self._binning = device_configs(config)
        self._frame_id = config.frame_id
        threaded = config.device_thread
        self._threaded = threaded
        self._device_clock: Callable[[], float] = (
            time.monotonic if threaded else seconds_clock(self)
        )
        self._revolutions: deque[Revolution] = deque(maxlen=2)
        self._fake = FakeRPLidar() if config.fake_device else None
        self._session: RPLidarSession | None = None
        self._connected_note = ''
        self._scan_pub = self.create_publisher(
            sensor_msgs.LaserScan, 'scan', qos_profile_sensor_data
        )
        self._diag_pub = self.create_publisher(
            diagnostic_msgs.DiagnosticArray, DIAGNOSTICS_TOPIC, 10
        )
        hardware_id = 'fake' if self._fake else self._device_config.port
        self._monitor = DeviceMonitor(
            f'{self.get_fully_qualified_name()}: lidar',
            hardware_id,
            config.stale_timeout_s,
            self.get_logger(),
        )
        worker = DeviceWorker(
            'lidar', self._connect, backoff=BackoffConfig(), clock=self._device_clock
        )
        self._poller = DevicePoller(self, worker, threaded=threaded)
        self._scan_gate = TimerGate(
            self.create_timer(1.0 / config.publish_rate_hz, self._publish_scans)
        )
        self.create_timer(1.0, self._publish_diagnostics)

    def _connect(self) -> RPLidarSession:
        open_port = None
        sleep: Callable[[float], None] = time.sleep
        if self._fake is not None:
            fake = self._fake

            def open_port(_cfg: RPLidarConfig) -> FakeRPLidarPort:
                return FakeRPLidarPort(fake, clock=self._device_clock)

            if not self._threaded:
                sleep = no_sleep
        self._session = connect_rplidar(
            self._device_config,
            self._revolutions.append,
            open_port=open_port,
            sleep=sleep,
            clock=self._device_clock,
        )
        info = self._session.info
        # Logged from the diagnostics timer: this runs in the device thread.
        self._connected_note = (
            f'lidar model {info.model} firmware {info.firmware} hardware {info.hardware}'
            f' serial {info.serial_number}'
        )
        return self._session

    def _publish_scans(self) -> None:
        while self._revolutions:
            revolution = self._revolutions.popleft()
            now_ns = self.get_clock().now().nanoseconds
            age_s = max(self._device_clock() - revolution.start_time_s, 0.0)
            ranges, intensities = bin_revolution(revolution, self._binning)
            msg = scan_to_ros(
                ranges,
                intensities,
                stamp_ns=now_ns - round(age_s * 1e9),
                frame_id=self._frame_id,
                binning=self._binning,
                scan_time_s=revolution.period_s,
            )
            self._scan_pub.publish(msg)
            self._monitor.mark_data(now_ns)

    def _publish_diagnostics(self) -> None:
        now_ns = self.get_clock().now().nanoseconds
        if self._connected_note:
            note, self._connected_note = self._connected_note, ''
            self.get_logger().info(note)
        extra: dict[str, str] = {}
        session = self._session
        if session is not None:
            extra = {
                'rejected_bytes': str(session.decoder.rejected_bytes),
                'scan_restarts': str(session.scan_restarts),
                'dropped_backlogs': str(session.dropped_backlogs),
                'dropped_revolutions': str(session.assembler.dropped_revolutions),
                'health': session.health.status.name,
                'firmware': session.info.firmware,
            }
        note = None
        if session is not None and session.health.status is HealthStatus.WARNING:
            code = session.health.error_code
            note = (DiagnosticLevel.WARN, f'lidar reports health Warning (code 0x{code:04X})')
        entry = self._monitor.entry(now_ns, self._poller.worker, extra, note=note)
        publish_diagnostics(self._diag_pub, [entry], now_ns)
        self._scan_gate.update(self._poller.worker.connected or bool(self._revolutions))

    def destroy_node(self) -> None:
        """Stop the device loop (STOP, motor off, close) before the node goes."""
        self._poller.stop()
        super().destroy_node()


def main(args: list[str] | None = None) -> int:
    """Entry point of ``ros2 run hw_drivers rplidar_node``."""
    return run_driver_node(
        RPLidarNode, 'rplidar_node', args, summary=__doc__ or '', parameters=RPLIDAR_PARAMETERS
    )


if __name__ == '__main__':
    raise SystemExit(main())
