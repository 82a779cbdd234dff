"""Pieces every driver node shares: parameter tables, device polling, diagnostics, main().

* The parameters of each driver are a spec in :mod:`hw_drivers.parameters`, declared with
  :func:`swarm_runtime.parameters.declare_config`; ``--help`` lists them and
  :func:`run_driver_node` checks the parameter files of the command line.
* :class:`DevicePoller` runs a :class:`~hw_drivers.worker.DeviceWorker` in its own thread
  (robots) or from a node timer (deterministic tests on the built-in runtime).
* :class:`DeviceMonitor` turns the worker's status plus data freshness into one
  diagnostic_msgs/DiagnosticStatus; :class:`StatusLog` logs a status once when it changes and
  then a reminder every 30 s while it stays bad, never a line per retry.
* :class:`TimerGate` pauses a node's fast publishing timer while its device is missing, so
  an unplugged driver idles.
* :func:`run_driver_node` is the body of every driver's ``main()``: ``--help``, the runtime
  check, the parameter-file check, line-buffered output, then
  :func:`swarm_runtime.node_main.run_node` (init, spin, clean stop on SIGINT / SIGTERM).
"""

from __future__ import annotations

import os
import sys
import time
from collections.abc import Callable, Mapping, Sequence
from typing import Any, TypeVar

from swarm_common.params import ParameterSpec, render_value
from swarm_runtime.node_main import run_node
from swarm_runtime.ros import rclpy, using_real_rclpy
from swarm_runtime.standalone import standalone_runtime_problem

from hw_drivers.conversions import DiagnosticEntry, diagnostics_to_ros
from hw_drivers.errors import ConfigurationError
from hw_drivers.worker import DeviceWorker, DiagnosticLevel

__all__ = [
    'DIAGNOSTICS_TOPIC',
    'REMINDER_PERIOD_S',
    'DeviceMonitor',
    'DevicePoller',
    'StatusLog',
    'TimerGate',
    'driver_help',
    'no_sleep',
    'publish_diagnostics',
    'run_driver_node',
    'seconds_clock',
    'spin_node',
    'start_driver_process',
]

NodeT = TypeVar('NodeT')
DIAGNOSTICS_TOPIC = '/diagnostics'
#: While a status stays WARN or worse, it is logged again this often [s].
REMINDER_PERIOD_S = 30.0


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


class StatusLog:
    """Log a status when it changes; while it stays WARN or worse, remind every ``reminder_s``.

    ``key`` identifies a status for this purpose: a retry that fails the same way again, or a
    staleness whose age grows, keeps its key and is not logged again until the reminder is
    due. Reminders run on the monotonic wall clock, whatever clock the node uses.
    """

    def __init__(
        self,
        logger: Any,
        *,
        reminder_s: float = REMINDER_PERIOD_S,
        clock: Callable[[], float] = time.monotonic,
    ) -> None:
        self._logger = logger
        self._reminder_s = reminder_s
        self._clock = clock
        self._key: object = None
        self._since_s = 0.0
        self._logged_s = 0.0
        self.lines = 0

    def report(self, level: DiagnosticLevel, key: object, message: str) -> None:
        """Log ``message`` if ``key`` differs from the last one or a reminder is due."""
        now = self._clock()
        if key != self._key:
            self._key, self._since_s, self._logged_s = key, now, now
            self._log(level, message)
        elif level >= DiagnosticLevel.WARN and now - self._logged_s >= self._reminder_s:
            self._logged_s = now
            self._log(level, f'{message} (for {now - self._since_s:.0f} s)')

    def _log(self, level: DiagnosticLevel, message: str) -> None:
        self.lines += 1
        if level == DiagnosticLevel.OK:
            self._logger.info(message)
        elif level == DiagnosticLevel.WARN:
            self._logger.warning(message)
        else:
            self._logger.error(message)


class TimerGate:
    """Cancels a timer while its input is missing and resets it when the input is back.

    A driver whose device is unplugged has nothing to publish; its fast publishing timer
    (20-100 Hz) would still wake the executor. The 1 Hz diagnostics callback calls
    :meth:`update`; the timer then restarts at most a second after the device is back.
    """

    def __init__(self, timer: Any) -> None:
        self._timer = timer

    @property
    def running(self) -> bool:
        """True while the timer is not cancelled."""
        return not self._timer.is_canceled()

    def update(self, needed: bool) -> None:
        """Run the timer when ``needed``, cancel it otherwise."""
        if needed and not self.running:
            self._timer.reset()
        elif not needed and self.running:
            self._timer.cancel()


class DeviceMonitor:
    """Freshness of one device's data plus its worker status, as a DiagnosticEntry.

    Args:
        name: diagnostic name, e.g. '/r0/rplidar_node: lidar'.
        hardware_id: device path or address.
        stale_timeout_s: data older than this makes the entry an ERROR ("stale").
        logger: the node's logger, for one line per status change (see :class:`StatusLog`).
    """

    def __init__(self, name: str, hardware_id: str, stale_timeout_s: float, logger: Any) -> None:
        self.name = name
        self.hardware_id = hardware_id
        self.stale_timeout_s = stale_timeout_s
        self.log = StatusLog(logger)
        self._last_data_ns: int | None = None
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
        state: str = '',
    ) -> DiagnosticEntry:
        """Build the entry: the worst of worker status, staleness and an optional note.

        ``quiet_reason`` explains an expected silence (e.g. calibration): it is reported as a
        WARN instead of the stale ERROR. ``state`` describes a healthy device in the node's
        words (e.g. 'locator connected'); it replaces the worker's generic 'connected'.
        """
        status = worker.status
        described = state or status.message
        if status.level >= DiagnosticLevel.ERROR:
            level, message = status.level, status.message
            key: object = ('fault', status.message.split(';')[0])
        elif quiet_reason:
            level, message, key = DiagnosticLevel.WARN, quiet_reason, ('quiet', quiet_reason)
        elif self._last_data_ns is None and worker.connect_count == worker.fault_count == 0:
            # Still starting: the first connection attempt has not finished.
            level, message, key = DiagnosticLevel.WARN, described, ('starting', described)
        elif self.is_stale(now_ns):
            if self._last_data_ns is None:
                age = 'no data yet'
            else:
                age = f'no data for {(now_ns - self._last_data_ns) * 1e-9:.1f} s'
            level, message = DiagnosticLevel.ERROR, f'stale: {age} ({described})'
            key = ('stale', described)
        else:
            level, message, key = status.level, described, ('ok', described)
        if note is not None and note[0] > level:
            level, message = note
            key = ('note', note[1])
        values = {**status.values, 'published': str(self.published), **(extra or {})}
        entry = DiagnosticEntry(self.name, self.hardware_id, level, message, values)
        self.log.report(level, key, message)
        return entry


def publish_diagnostics(publisher: Any, entries: Sequence[DiagnosticEntry], now_ns: int) -> None:
    """Publish one DiagnosticArray."""
    publisher.publish(diagnostics_to_ros(entries, stamp_ns=now_ns))


def no_sleep(_duration_s: float) -> None:
    """A sleep that returns at once: fakes polled from a timer must not block the executor."""


def seconds_clock(node: Any) -> Callable[[], float]:
    """The node clock in seconds, as a device clock for fakes polled from timers."""
    return lambda: node.get_clock().now().nanoseconds * 1e-9


def driver_help(name: str, summary: str, parameters: ParameterSpec) -> str:
    """The ``--help`` text of a driver: usage, what it does, its parameters.

    ``summary`` is the module docstring; its first paragraph is used.
    """
    lines = [
        f'usage: {name} [--help] [--ros-args -r __ns:=/<robot> -p <name>:=<value> ...]',
        '',
        summary.strip().split('\n\n')[0],
        '',
        'parameters (-p name:=value, or --params-file):',
    ]
    width = max((len(p.name) for p in parameters.parameters), default=0)
    for p in parameters.parameters:
        default = render_value(p.default)
        lines.append(f'  {p.name:<{width}}  {p.description_text} [default: {default}]')
    lines += [
        '',
        'Without its device the driver reports an error on /diagnostics and retries with',
        'back-off; it logs the fault once and then every 30 s.',
    ]
    return '\n'.join(lines)


def _own_arguments(args: Sequence[str] | None) -> list[str]:
    """The arguments before ``--ros-args`` (those after it belong to ROS)."""
    argv = list(sys.argv[1:] if args is None else args)
    return argv[: argv.index('--ros-args')] if '--ros-args' in argv else argv


def _line_buffered_output() -> None:
    """Logs reach a pipe (journald, a bringup, ``| tee``) line by line, not in blocks."""
    os.environ.setdefault('RCUTILS_LOGGING_BUFFERED_STREAM', '1')
    for stream in (sys.stdout, sys.stderr):
        reconfigure = getattr(stream, 'reconfigure', None)
        if reconfigure is not None:
            reconfigure(line_buffering=True)


def spin_node(node: Any, *, tick_s: float = 0.05) -> None:
    """``rclpy.spin(node)``; on the built-in runtime paced to the real clock.

    The built-in executor runs timers on a virtual clock as fast as the CPU allows, which
    suits a simulation in one process; a driver process started alone on it (explicitly, with
    ``SWARM_RUNTIME=builtin``) would burn a core and run its timers far ahead of its device
    thread. Here it advances the virtual clock only as far as real time has passed.
    """
    if using_real_rclpy():
        rclpy.spin(node)
        return
    from swarm_runtime.simulation import spin_until, wall_time_s

    executor = rclpy.executors.SingleThreadedExecutor()
    executor.add_node(node)
    start_s = time.monotonic() - wall_time_s()
    while rclpy.ok():
        behind_s = time.monotonic() - start_s - wall_time_s()
        if behind_s > 0.0:
            spin_until(executor, lambda: False, max_wall_time_s=behind_s)
        time.sleep(tick_s)


def start_driver_process(
    name: str, args: Sequence[str] | None, *, summary: str, parameters: ParameterSpec
) -> None:
    """What every driver's ``main()`` does before ``rclpy.init``.

    ``--help`` prints the help and exits 0 without touching ROS; on the built-in runtime
    without an explicit ``SWARM_RUNTIME=builtin`` the process exits 2 with a one-line
    reason; otherwise output becomes line-buffered.
    """
    own = _own_arguments(args)
    if '-h' in own or '--help' in own:
        sys.stdout.write(driver_help(name, summary, parameters) + '\n')
        raise SystemExit(0)
    problem = standalone_runtime_problem()
    if problem is not None:
        sys.stderr.write(f'{name}: {problem}\n')
        raise SystemExit(2)
    _line_buffered_output()


def run_driver_node(
    node_factory: Callable[[], NodeT],
    name: str,
    args: list[str] | None,
    *,
    summary: str = '',
    parameters: ParameterSpec,
    fatal_errors: tuple[type[Exception], ...] = (ConfigurationError,),
    on_signal: Callable[[NodeT], None] | None = None,
) -> int:
    """The body of a driver's ``main()``: checks, init, spin until stopped, clean up.

    See :func:`start_driver_process` for ``--help`` and the runtime check, and
    :func:`swarm_runtime.node_main.run_node` for the stop: Ctrl-C, SIGTERM and an external
    shutdown end the process with status 0 and no traceback (``on_signal`` runs first);
    ``fatal_errors`` (invalid parameters) with status 2 and one fatal log line naming them,
    and so does a bad parameter file or ``-p`` value (one line naming the file and the
    parameter, before ``rclpy.init``).
    The node is destroyed in every case. On the built-in runtime the node is paced to the
    real clock (:func:`spin_node`).
    """
    start_driver_process(name, args, summary=summary, parameters=parameters)
    return run_node(
        node_factory,
        args,
        name=name,
        fatal_errors=fatal_errors,
        describe_fatal=lambda err: f'invalid parameters: {err}',
        on_signal=on_signal,
        spin=spin_node,
        parameters=parameters,
    )
