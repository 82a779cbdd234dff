"""Pieces every driver node shares: parameter tables, device polling, diagnostics.

* :func:`declare_parameter_table` declares each ``(name, default, description)`` once with a
  read-only ParameterDescriptor and returns the values (the same tables are mirrored in
  ``config/*.yaml`` and checked by a test).
* :class:`DevicePoller` runs a :class:`~hw_drivers.worker.DeviceWorker` in its own thread
  (robots) or from a node timer (deterministic tests on the built-in runtime).
* :class:`DeviceMonitor` turns the worker's status plus data freshness into one
  diagnostic_msgs/DiagnosticStatus and logs status changes once.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping, Sequence
from typing import Any

from swarm_runtime.ros import ExternalShutdownException, message_module, rclpy

from hw_drivers.conversions import DiagnosticEntry, diagnostics_to_ros
from hw_drivers.errors import ConfigurationError
from hw_drivers.worker import DeviceWorker, DiagnosticLevel

__all__ = [
    'DIAGNOSTICS_TOPIC',
    'DeviceMonitor',
    'DevicePoller',
    'ParamSpec',
    'declare_parameter_table',
    'no_sleep',
    'publish_diagnostics',
    'run_driver_node',
    'seconds_clock',
]

ParamSpec = tuple[str, Any, str]
DIAGNOSTICS_TOPIC = '/diagnostics'


def declare_parameter_table(node: Any, table: Sequence[ParamSpec]) -> dict[str, Any]:
    """Declare every parameter of ``table`` (read-only, described); return name -> value."""
    descriptor_class = message_module('rcl_interfaces').ParameterDescriptor
    values: dict[str, Any] = {}
    for name, default, description in table:
        descriptor = descriptor_class(description=description, read_only=True)
        values[name] = node.declare_parameter(name, default, descriptor).value
    return values


class DevicePoller:
    """Drive a worker: in a thread (``threaded``), or from a timer of ``node``.

    The timer form polls until the worker has nothing more to do, at most ``max_polls``
    times per tick, so device fakes run in step with the node's (virtual) clock.
    """

    def __init__(
        self,
        node: Any,
        worker: DeviceWorker,
        *,
        threaded: bool,
        poll_period_s: float = 0.01,
        max_polls: int = 20,
    ) -> None:
        self.worker = worker
        self.threaded = threaded
        self._max_polls = max_polls
        self._timer = None
        if threaded:
            worker.start()
        else:
            self._timer = node.create_timer(poll_period_s, self._tick)

    def _tick(self) -> None:
        for _ in range(self._max_polls):
            if not self.worker.run_once():
                break

    def stop(self) -> None:
        """Stop the thread (if any) and close the device."""
        self.worker.stop()


class DeviceMonitor:
    """Freshness of one device's data plus its worker status, as a DiagnosticEntry.

    Args:
        name: diagnostic name, e.g. '/r0/rplidar_node: lidar'.
        hardware_id: device path or address.
        stale_timeout_s: data older than this makes the entry an ERROR ("stale").
        logger: the node's logger, for one line per status change.
    """

    def __init__(self, name: str, hardware_id: str, stale_timeout_s: float, logger: Any) -> None:
        self.name = name
        self.hardware_id = hardware_id
        self.stale_timeout_s = stale_timeout_s
        self._logger = logger
        self._last_data_ns: int | None = None
        self._last_logged: tuple[DiagnosticLevel, str] | None = None
        self.published = 0

    def mark_data(self, now_ns: int) -> None:
        """Record that fresh data was published at ``now_ns``."""
        self._last_data_ns = now_ns
        self.published += 1

    def is_stale(self, now_ns: int) -> bool:
        """True when no data was published within the stale timeout."""
        if self._last_data_ns is None:
            return True
        return (now_ns - self._last_data_ns) * 1e-9 > self.stale_timeout_s

    def entry(
        self,
        now_ns: int,
        worker: DeviceWorker,
        extra: Mapping[str, str] | None = None,
        *,
        note: tuple[DiagnosticLevel, str] | None = None,
        quiet_reason: str = '',
    ) -> DiagnosticEntry:
        """Build the entry: the worst of worker status, staleness and an optional note.

        ``quiet_reason`` explains an expected silence (e.g. calibration): it is reported as a
        WARN instead of the stale ERROR.
        """
        status = worker.status
        level, message = status.level, status.message
        if quiet_reason and status.level < DiagnosticLevel.ERROR:
            level, message = DiagnosticLevel.WARN, quiet_reason
        elif self.is_stale(now_ns) and status.level < DiagnosticLevel.ERROR:
            if self._last_data_ns is None:
                age = 'no data yet'
            else:
                age = f'no data for {(now_ns - self._last_data_ns) * 1e-9:.1f} s'
            level, message = DiagnosticLevel.ERROR, f'stale: {age} ({status.message})'
        if note is not None and note[0] > level:
            level, message = note
        values = {**status.values, 'published': str(self.published), **(extra or {})}
        entry = DiagnosticEntry(self.name, self.hardware_id, level, message, values)
        self._log_change(entry)
        return entry

    def _log_change(self, entry: DiagnosticEntry) -> None:
        key = (entry.level, entry.message.split(';')[0])
        if key == self._last_logged:
            return
        self._last_logged = key
        if entry.level == DiagnosticLevel.OK:
            self._logger.info(entry.message)
        elif entry.level == DiagnosticLevel.WARN:
            self._logger.warning(entry.message)
        else:
            self._logger.error(entry.message)


def publish_diagnostics(publisher: Any, entries: Sequence[DiagnosticEntry], now_ns: int) -> None:
    """Publish one DiagnosticArray."""
    publisher.publish(diagnostics_to_ros(entries, stamp_ns=now_ns))


def no_sleep(_duration_s: float) -> None:
    """A sleep that returns at once: fakes polled from a timer must not block the executor."""


def seconds_clock(node: Any) -> Callable[[], float]:
    """The node clock in seconds, as a device clock for fakes polled from timers."""
    return lambda: node.get_clock().now().nanoseconds * 1e-9


def run_driver_node(node_factory: Callable[[], Any], name: str, args: list[str] | None) -> None:
    """The body of a sensor driver's ``main()``: init, spin until shutdown, clean up.

    Invalid parameters end the process with exit code 2 and a fatal log line naming them;
    Ctrl-C and an external shutdown end it normally. The node is destroyed in every case.
    """
    rclpy.init(args=args)
    node = None
    try:
        node = node_factory()
        rclpy.spin(node)
    except (KeyboardInterrupt, ExternalShutdownException):
        pass
    except ConfigurationError as err:
        rclpy.logging.get_logger(name).fatal(f'invalid parameters: {err}')
        raise SystemExit(2) from err
    finally:
        if node is not None:
            node.destroy_node()
        rclpy.try_shutdown()
