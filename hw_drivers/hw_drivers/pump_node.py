"""Pump driver node: drives the scent pump's GPIO from ``pump`` (std_msgs/Bool) safely.

``pump`` carries the level the controller wants, republished on every control tick (OA-Bug
does). The node enforces on its own (see :mod:`hw_drivers.pump_control`): off when commands
are older than ``command_timeout_s``, at most ``max_on_s`` per pulse, at least ``min_off_s``
between pulses. Besides the 50 Hz control timer, every pulse arms an independent
``threading.Timer`` that forces the line off after ``max_on_s`` even if the executor stalls.

A missing or failing GPIO is not fatal: the pump stays off, /diagnostics says why, and the
line is requested again with back-off. The line goes off on every exit path Python can see:
normal shutdown (``destroy_node``), KeyboardInterrupt/ExternalShutdownException, SIGTERM and
SIGINT (``main()``'s handlers turn the line off first), an exception in a callback, and
``atexit``.
SIGKILL and power loss cannot be caught:
the hardware gate pull-down and the systemd ``ExecStopPost=`` line (docs/hardware.md) cover
those.

Publishes ``pump/state`` (std_msgs/Bool, the actual output; on every change and once a
second) and /diagnostics.

Run: ``ros2 run hw_drivers pump_node --ros-args -r __ns:=/r0 -p line:=GPIO17``.
"""

from __future__ import annotations

import atexit
import threading
import time
from collections.abc import Callable
from typing import Any

from swarm_runtime.parameters import declare_config
from swarm_runtime.ros import Node, message_module

from hw_drivers.backoff import Backoff, BackoffConfig
from hw_drivers.conversions import DiagnosticEntry, pump_state_to_ros
from hw_drivers.errors import FatalDeviceError, HwDriverError
from hw_drivers.fakes.gpio import FakePumpOutput
from hw_drivers.node_common import (
    DIAGNOSTICS_TOPIC,
    StatusLog,
    TimerGate,
    publish_diagnostics,
    run_driver_node,
)
from hw_drivers.parameters import PUMP_PARAMETERS
from hw_drivers.pump_control import PumpController, PumpLimits
from hw_drivers.pump_output import GpiodPumpOutput, PumpOutput, SafePumpLine, parse_line_id
from hw_drivers.worker import DiagnosticLevel

__all__ = ['PumpNode', 'main']

std_msgs = message_module('std_msgs')
diagnostic_msgs = message_module('diagnostic_msgs')


class PumpNode(Node):
    """Subscribes ``pump``; drives the GPIO within the safety limits.

    The line is requested at start; if that fails (no chip, line busy, no permission) the
    node keeps running with the pump off, reports the fault on /diagnostics and requests the
    line again with back-off (1, 2, 4, 5 ... s; 30 s after a fatal error such as a busy
    line), like the sensor drivers. A line that fails while in use is driven off (as far as
    it still can be), released and requested again the same way.

    Args:
        output: the pump line to drive (tests pass a fake; by default the GPIO from the
            parameters, or a simulated line with ``fake_device``).
        open_output: opens the line; overrides ``output`` and the parameters (tests).
        retry_clock: monotonic clock [s] of the reopen back-off; injectable for tests.
    """

    def __init__(
        self,
        *,
        output: PumpOutput | None = None,
        open_output: Callable[[], PumpOutput] | None = None,
        retry_clock: Callable[[], float] = time.monotonic,
        **kwargs: Any,
    ) -> None:
        super().__init__('pump_node', **kwargs)
        config = declare_config(self, PUMP_PARAMETERS).config
        self._limits = PumpLimits(
            max_on_s=config.max_on_s,
            min_off_s=config.min_off_s,
            command_timeout_s=config.command_timeout_s,
        )
        self._controller = PumpController(self._limits)
        if open_output is None:
            if output is not None:
                given = output

                def open_output() -> PumpOutput:
                    return given
            elif config.fake_device:
                open_output = FakePumpOutput
            else:
                chip, line = config.chip, parse_line_id(config.line)
                active_low = config.active_low

                def open_output() -> PumpOutput:
                    return GpiodPumpOutput(chip, line, active_low=active_low)

        self._open_output = open_output
        self._hardware_id = 'fake' if config.fake_device else f'{config.chip} {config.line}'
        self.line: SafePumpLine | None = None
        self._backoff = Backoff(BackoffConfig())
        self._retry_clock = retry_clock
        self._next_open_s = retry_clock()
        self._line_error = ''
        self._line_fatal = False
        self.line_failures = 0
        self._guard: threading.Timer | None = None
        self._guard_lock = threading.Lock()
        self.guard_trips = 0
        self._guard_tripped = False
        self._log = StatusLog(self.get_logger())
        self._shut_down = False
        atexit.register(self.shutdown_pump)
        self._state_pub = self.create_publisher(std_msgs.Bool, 'pump/state', 10)
        self._diag_pub = self.create_publisher(
            diagnostic_msgs.DiagnosticArray, DIAGNOSTICS_TOPIC, 10
        )
        self.create_subscription(std_msgs.Bool, 'pump', self._on_command, 10)
        self._control_gate = TimerGate(
            self.create_timer(1.0 / config.control_rate_hz, self._on_timer)
        )
        self.create_timer(1.0, self._publish_diagnostics)
        self._try_open()

    @property
    def line_available(self) -> bool:
        """True while the GPIO line is held."""
        return self.line is not None

    def _now_s(self) -> float:
        return self.get_clock().now().nanoseconds * 1e-9

    def _try_open(self) -> None:
        """Request the line if it is not held and a retry is due; the pump starts off."""
        if self.line is not None or self._shut_down or self._retry_clock() < self._next_open_s:
            self._control_gate.update(self.line is not None)
            return
        try:
            output = self._open_output()
        except (HwDriverError, OSError) as err:
            self._line_failed(err)
            return
        self.line = SafePumpLine(output)  # requested with the inactive level: pump off
        self._backoff.reset()
        self._line_error = ''
        self._control_gate.update(True)

    def _line_failed(self, err: BaseException) -> None:
        """The line cannot be requested or driven: pump off, release, retry later."""
        self.line_failures += 1
        line, self.line = self.line, None
        if line is not None:
            line.close()
        self._controller.force_off(self._now_s())
        self._line_fatal = isinstance(err, FatalDeviceError)
        delay_s = self._backoff.next_delay_s(fatal=self._line_fatal)
        self._next_open_s = self._retry_clock() + delay_s
        self._line_error = f'{err}; retrying in {delay_s:.0f} s'
        self._control_gate.update(False)

    def _on_command(self, msg: Any) -> None:
        self._apply(lambda now_s: self._controller.command(bool(msg.data), now_s))

    def _on_timer(self) -> None:
        self._apply(self._controller.update)

    def _apply(self, decide: Callable[[float], bool]) -> None:
        """Decide and drive the line; on any exception the pump goes off first."""
        line = self.line
        if line is None:
            # No line: whatever is commanded, the pump stays off (and a command cannot
            # switch it on the moment the line comes back).
            self._controller.force_off(self._now_s())
            return
        was_on = line.is_on
        try:
            on = decide(self._now_s())
            if not on:
                self._guard_tripped = False
            # After a guard trip the line stays off until the controller itself says off.
            on = on and not self._guard_tripped
            line.set(on)
        except (HwDriverError, OSError) as err:
            self._line_failed(err)
            on = False
        except BaseException:
            line.off()
            self._controller.force_off(self._now_s())
            raise
        if on and not was_on:
            self._arm_guard()
        if on != was_on:
            self._state_pub.publish(pump_state_to_ros(on))

    def _arm_guard(self) -> None:
        with self._guard_lock:
            if self._guard is not None:
                self._guard.cancel()
            self._guard = threading.Timer(self._limits.max_on_s, self._guard_trip)
            self._guard.daemon = True
            self._guard.start()

    def _guard_trip(self) -> None:
        """Runs in the guard thread if a pulse outlives max_on_s in wall time."""
        line = self.line
        if line is not None and line.is_on:
            self.guard_trips += 1
            self._guard_tripped = True
            line.off()

    def shutdown_pump(self) -> None:
        """Pump off and line released; safe to call from any exit path, repeatedly."""
        self._shut_down = True
        line = self.line
        if line is not None:
            line.close()
        with self._guard_lock:
            if self._guard is not None:
                self._guard.cancel()

    def _status(self) -> tuple[DiagnosticLevel, str, dict[str, str]]:
        controller = self._controller
        values = {
            'pulses': str(controller.pulses),
            'forced_stops': str(controller.forced_stops),
            'stale_command_stops': str(controller.stale_stops),
            'guard_trips': str(self.guard_trips),
            'line_failures': str(self.line_failures),
        }
        line = self.line
        if line is None:
            kind = 'fatal error' if self._line_fatal else 'error'
            return (
                DiagnosticLevel.ERROR,
                f'pump line unavailable ({kind}): {self._line_error}',
                values,
            )
        values['off_failures'] = str(line.off_failures)
        if line.off_failures:
            return DiagnosticLevel.ERROR, 'failed to drive the pump line off', values
        if controller.forced_stops or self.guard_trips:
            return DiagnosticLevel.WARN, 'pulses were cut at max_on_s', values
        return DiagnosticLevel.OK, 'pump on' if line.is_on else 'pump off', values

    def _publish_diagnostics(self) -> None:
        """Once a second: retry the line, diagnostics, and the pump state for late joiners."""
        self._try_open()
        now_ns = self.get_clock().now().nanoseconds
        self._state_pub.publish(pump_state_to_ros(self.line is not None and self.line.is_on))
        level, message, values = self._status()
        entry = DiagnosticEntry(
            f'{self.get_fully_qualified_name()}: pump', self._hardware_id, level, message, values
        )
        # 'pump on'/'pump off' alternate with every pulse: log only the other states.
        if level != DiagnosticLevel.OK:
            self._log.report(level, message.split(';')[0], message)
        else:
            self._log.report(level, 'ok', 'pump line ready, pump off')
        publish_diagnostics(self._diag_pub, [entry], now_ns)

    def destroy_node(self) -> None:
        """Pump off and line released before the node goes."""
        self.shutdown_pump()
        super().destroy_node()


def main(args: list[str] | None = None) -> int:
    """Entry point of ``ros2 run hw_drivers pump_node``.

    SIGINT and SIGTERM turn the pump off first (from the signal handler), then stop the
    node; every other exit path turns it off in ``destroy_node`` or ``atexit``.
    """
    return run_driver_node(
        PumpNode,
        'pump_node',
        args,
        summary=__doc__ or '',
        parameters=PUMP_PARAMETERS,
        fatal_errors=(FatalDeviceError,),
        on_signal=PumpNode.shutdown_pump,
    )


if __name__ == '__main__':
    raise SystemExit(main())
