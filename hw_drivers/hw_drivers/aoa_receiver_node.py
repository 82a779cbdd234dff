"""BG22 AoA locator receiver node: publishes ``bearings`` (swarm_interfaces/PeerBearingArray),
``rssi`` (swarm_interfaces/RssiArray, when the locator reports RSSI) and /diagnostics.

The node is the TCP server the locator host connects to (127.0.0.1:8080 by default, the
authors' setting); start it before the locator. It accepts the authors' multi-line JSON and
NDJSON, drops the robot's own tag (``own_tag_id``), duplicated and old reports, and maps the
azimuth into the robot frame (``azimuth_sign``, ``azimuth_offset_rad``). Each publish carries
the latest bearing of every tag heard since the previous one; silence publishes nothing.

Run: ``ros2 run hw_drivers aoa_receiver_node --ros-args -r __ns:=/r0 -p own_tag_id:=D2``.
"""

from __future__ import annotations

import ipaddress
import time
from collections.abc import Callable
from typing import Any

from swarm_runtime.parameters import declare_config
from swarm_runtime.ros import (
    Node,
    message_module,
    qos_profile_sensor_data,
)

from hw_drivers.aoa_bearings import BearingCollector
from hw_drivers.aoa_protocol import AngleReport, AzimuthMapping
from hw_drivers.aoa_server import LocatorServer
from hw_drivers.backoff import BackoffConfig
from hw_drivers.conversions import bearings_to_ros, rssi_to_ros
from hw_drivers.errors import ConfigurationError
from hw_drivers.node_common import (
    DIAGNOSTICS_TOPIC,
    DeviceMonitor,
    DevicePoller,
    TimerGate,
    publish_diagnostics,
    run_driver_node,
    seconds_clock,
)
from hw_drivers.parameters import AOA_RECEIVER_PARAMETERS
from hw_drivers.worker import DeviceWorker, DiagnosticLevel

__all__ = ['AoaReceiverNode', 'main']

swarm_interfaces = message_module('swarm_interfaces')
diagnostic_msgs = message_module('diagnostic_msgs')


class AoaReceiverNode(Node):
    """Receives the locator's angle reports and publishes peer bearings."""

    def __init__(self, **kwargs: Any) -> None:
        super().__init__('aoa_receiver_node', **kwargs)
        config = declare_config(self, AOA_RECEIVER_PARAMETERS).config
        self._host = config.listen_host
        self._port = config.listen_port
        if not 0 <= self._port <= 65535:
            raise ConfigurationError(f'listen_port must be 0..65535, got {self._port}')
        if not _is_loopback(self._host):
            self.get_logger().warning(
                f'listening on {self._host}: the locator input is reachable from the network'
            )
        self._collector = BearingCollector(
            own_tag_id=config.own_tag_id,
            mapping=AzimuthMapping(sign=config.azimuth_sign, offset_rad=config.azimuth_offset_rad),
        )
        self._max_buffer_bytes = config.max_buffer_bytes
        self._frame_id = config.frame_id
        threaded = config.device_thread
        self._threaded = threaded
        self._device_clock: Callable[[], float] = (
            time.monotonic if threaded else seconds_clock(self)
        )
        self.server: LocatorServer | None = None
        self._bearings_pub = self.create_publisher(
            swarm_interfaces.PeerBearingArray, 'bearings', qos_profile_sensor_data
        )
        self._rssi_pub = self.create_publisher(
            swarm_interfaces.RssiArray, 'rssi', qos_profile_sensor_data
        )
        self._diag_pub = self.create_publisher(
            diagnostic_msgs.DiagnosticArray, DIAGNOSTICS_TOPIC, 10
        )
        self._monitor = DeviceMonitor(
            f'{self.get_fully_qualified_name()}: aoa locator',
            f'tcp://{self._host}:{self._port}',
            config.stale_timeout_s,
            self.get_logger(),
        )
        worker = DeviceWorker(
            'aoa', self._listen, backoff=BackoffConfig(), clock=self._device_clock
        )
        self._poller = DevicePoller(self, worker, threaded=threaded)
        self._bearing_gate = TimerGate(
            self.create_timer(1.0 / config.publish_rate_hz, self._publish_bearings)
        )
        self.create_timer(1.0, self._publish_diagnostics)

    def _listen(self) -> LocatorServer:
        # In a thread the select may wait; polled from a timer it must not block.
        select_timeout_s = 0.05 if self._threaded else 0.0
        self.server = LocatorServer(
            self._host,
            self._port,
            self._on_report,
            max_buffer_bytes=self._max_buffer_bytes,
            select_timeout_s=select_timeout_s,
        )
        return self.server

    def _on_report(self, report: AngleReport) -> None:
        self._collector.add(report, self._device_clock())

    def _publish_bearings(self) -> None:
        bearings = self._collector.take()
        if not bearings:
            return
        now_ns = self.get_clock().now().nanoseconds
        newest_s = max(b.time_s for b in bearings)
        stamp_ns = now_ns - round(max(self._device_clock() - newest_s, 0.0) * 1e9)
        self._bearings_pub.publish(
            bearings_to_ros(bearings, stamp_ns=stamp_ns, frame_id=self._frame_id)
        )
        rssi = rssi_to_ros(bearings, stamp_ns=stamp_ns, frame_id=self._frame_id)
        if rssi is not None:
            self._rssi_pub.publish(rssi)
        self._monitor.mark_data(now_ns)

    def _publish_diagnostics(self) -> None:
        now_ns = self.get_clock().now().nanoseconds
        server = self.server
        if server is not None and server.closed:
            # The worker closed it after a fault and will listen again after its back-off;
            # its status tells why. A closed socket must not be touched.
            server = None
        collector = self._collector
        extra = {
            'own_tag_reports': str(collector.own_reports),
            'degraded_reports': str(collector.degraded_reports),
            'duplicate_reports': str(collector.sequence_filter.duplicates),
            'old_reports': str(collector.sequence_filter.old),
        }
        note = None
        state = ''
        if server is not None:
            extra.update(
                {
                    'locator_connected': str(server.client_connected),
                    'connections': str(server.connections),
                    'replaced_clients': str(server.replaced_clients),
                    'invalid_reports': str(server.invalid_reports),
                    'malformed_json': str(server.decoder.malformed),
                    'buffer_overflows': str(server.decoder.overflows),
                }
            )
            listening = f'listening on {self._host}:{server.port}'
            if server.client_connected:
                state = f'locator connected ({listening})'
            else:
                state = f'locator not connected ({listening})'
                note = (DiagnosticLevel.WARN, f'AoA {state}')
        for tag, age_s in sorted(collector.ages_s(self._device_clock()).items()):
            extra[f'tag {tag} age_s'] = f'{age_s:.1f}'
        entry = self._monitor.entry(now_ns, self._poller.worker, extra, note=note, state=state)
        publish_diagnostics(self._diag_pub, [entry], now_ns)
        self._bearing_gate.update(
            (server is not None and server.client_connected) or self._collector.pending
        )

    def destroy_node(self) -> None:
        """Close the server before the node goes."""
        self._poller.stop()
        super().destroy_node()


def _is_loopback(host: str) -> bool:
    if host == 'localhost':
        return True
    try:
        return ipaddress.ip_address(host).is_loopback
    except ValueError:
        return False


def main(args: list[str] | None = None) -> int:
    """Entry point of ``ros2 run hw_drivers aoa_receiver_node``."""
    return run_driver_node(
        AoaReceiverNode,
        'aoa_receiver_node',
        args,
        summary=__doc__ or '',
        parameters=AOA_RECEIVER_PARAMETERS,
    )


if __name__ == '__main__':
    raise SystemExit(main())
