"""Pump driver node: drives the scent pump's GPIO from ``pump`` (std_msgs/Bool) safely.

``pump`` carries the level the controller wants, republished on every control tick (OA-Bug
does). The node enforces on its own (see :mod:`hw_drivers.pump_control`): off when commands
are older than ``command_timeout_s``, at most ``max_on_s`` per pulse, at least ``min_off_s``
between pulses. Besides the 50 Hz control timer, every pulse arms an independent
``threading.Timer`` that forces the line off after ``max_on_s`` even if the executor stalls.

The line goes off on every exit path Python can see: normal shutdown (``destroy_node``),
KeyboardInterrupt/ExternalShutdownException, SIGTERM and SIGINT (handlers turn the line off
first), an exception in a callback, and ``atexit``. SIGKILL and power loss cannot be caught:
the hardware gate pull-down and the systemd ``ExecStopPost=`` line (docs/hardware.md) cover
those.

Publishes ``pump/state`` (std_msgs/Bool, the actual output; on every change and once a
second) and /diagnostics.

Run: ``ros2 run hw_drivers pump_node --ros-args -r __ns:=/r0 -p line:=GPIO17``.
"""

from __future__ import annotations

import atexit
import signal
import threading
from collections.abc import Callable
from types import FrameType
from typing import Any

from swarm_runtime.ros import ExternalShutdownException, Node, message_module, rclpy

from hw_drivers.conversions import DiagnosticEntry, pump_state_to_ros
from hw_drivers.errors import FatalDeviceError
from hw_drivers.fakes.gpio import FakePumpOutput
from hw_drivers.node_common import (
    DIAGNOSTICS_TOPIC,
    ParamSpec,
    declare_parameter_table,
    publish_diagnostics,
)
from hw_drivers.pump_control import PumpController, PumpLimits
from hw_drivers.pump_output import GpiodPumpOutput, PumpOutput, SafePumpLine, parse_line_id
from hw_drivers.worker import DiagnosticLevel

__all__ = ['PARAMETERS', 'PumpNode', 'install_signal_handlers', 'main']

std_msgs = message_module('std_msgs')
diagnostic_msgs = message_module('diagnostic_msgs')

PARAMETERS: list[ParamSpec] = [
    ('chip', '/dev/gpiochip0', 'GPIO chip device (Pi 4 40-pin header: /dev/gpiochip0)'),
    ('line', 'GPIO17', "GPIO line name (GPIO17) or offset as a string ('17'); authors: BCM 17"),
    ('active_low', False, 'true if the driver stage is inverting (line low = pump on)'),
    ('max_on_s', 1.0, 'longest pulse the driver allows [s] (paper pulse: 0.5 s)'),
    ('min_off_s', 1.0, 'shortest pause between pulses [s]'),
    ('command_timeout_s', 0.5, 'commands older than this turn the pump off [s]'),
    ('control_rate_hz', 50.0, 'rate of the safety check [Hz]'),
    ('fake_device', False, 'drive a simulated line instead of a GPIO'),
]


class PumpNode(Node):
    """Subscribes ``pump``; drives the GPIO within the safety limits.

    Args:
        output: the pump line to drive (tests pass a fake; by default the GPIO from the
            parameters, or a simulated line with ``fake_device``).

    Raises:
        FatalDeviceError: the GPIO line cannot be requested (busy, permissions, no such line):
            the node refuses to start rather than run blind.
    """

    def __init__(self, *, output: PumpOutput | None = None, **kwargs: Any) -> None:
        super().__init__('pump_node', **kwargs)
        values = declare_parameter_table(self, PARAMETERS)
        self._limits = PumpLimits(
            max_on_s=float(values['max_on_s']),
            min_off_s=float(values['min_off_s']),
            command_timeout_s=float(values['command_timeout_s']),
        )
        self._controller = PumpController(self._limits)
        if output is None:
            if values['fake_device']:
                output = FakePumpOutput()
            else:
                output = GpiodPumpOutput(
                    str(values['chip']),
                    parse_line_id(str(values['line'])),
                    active_low=bool(values['active_low']),
                )
        self.line = SafePumpLine(output)
        self._hardware_id = f'{values["chip"]} {values["line"]}'
        self._guard: threading.Timer | None = None
        self._guard_lock = threading.Lock()
        self.guard_trips = 0
        self._guard_tripped = False
        self._last_logged: tuple[DiagnosticLevel, str] | None = None
        atexit.register(self.line.close)
        self._state_pub = self.create_publisher(std_msgs.Bool, 'pump/state', 10)
        self._diag_pub = self.create_publisher(
            diagnostic_msgs.DiagnosticArray, DIAGNOSTICS_TOPIC, 10
        )
        self.create_subscription(std_msgs.Bool, 'pump', self._on_command, 10)
        self.create_timer(1.0 / float(values['control_rate_hz']), self._on_timer)
        self.create_timer(1.0, self._publish_diagnostics)

    def _now_s(self) -> float:
        return self.get_clock().now().nanoseconds * 1e-9

    def _on_command(self, msg: Any) -> None:
        self._apply(lambda now_s: self._controller.command(bool(msg.data), now_s))

    def _on_timer(self) -> None:
        self._apply(self._controller.update)

    def _apply(self, decide: Callable[[float], bool]) -> None:
        """Decide and drive the line; on any exception the pump goes off first."""
        was_on = self.line.is_on
        try:
            on = decide(self._now_s())
            if not on:
                self._guard_tripped = False
            # After a guard trip the line stays off until the controller itself says off.
            on = on and not self._guard_tripped
            self.line.set(on)
        except BaseException:
            self.line.off()
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
        if self.line.is_on:
            self.guard_trips += 1
            self._guard_tripped = True
            self.line.off()

    def shutdown_pump(self) -> None:
        """Pump off and line released; safe to call from any exit path, repeatedly."""
        self.line.close()
        with self._guard_lock:
            if self._guard is not None:
                self._guard.cancel()

    def _publish_diagnostics(self) -> None:
        """Once a second: diagnostics, and the pump state again for late subscribers."""
        now_ns = self.get_clock().now().nanoseconds
        self._state_pub.publish(pump_state_to_ros(self.line.is_on))
        controller = self._controller
        level, message = DiagnosticLevel.OK, 'pump on' if self.line.is_on else 'pump off'
        if self.line.off_failures:
            level, message = DiagnosticLevel.ERROR, 'failed to drive the pump line off'
        elif controller.forced_stops or self.guard_trips:
            level, message = DiagnosticLevel.WARN, 'pulses were cut at max_on_s'
        values = {
            'pulses': str(controller.pulses),
            'forced_stops': str(controller.forced_stops),
            'stale_command_stops': str(controller.stale_stops),
            'guard_trips': str(self.guard_trips),
            'off_failures': str(self.line.off_failures),
        }
        entry = DiagnosticEntry(
            f'{self.get_fully_qualified_name()}: pump', self._hardware_id, level, message, values
        )
        if (level, message) != self._last_logged and level != DiagnosticLevel.OK:
            self.get_logger().warning(message)
        self._last_logged = (level, message)
        publish_diagnostics(self._diag_pub, [entry], now_ns)

    def destroy_node(self) -> None:
        """Pump off and line released before the node goes."""
        self.shutdown_pump()
        super().destroy_node()


def install_signal_handlers(turn_off: Callable[[], None]) -> None:
    """On SIGTERM/SIGINT: turn the pump off first, then leave ``rclpy.spin`` by an exception.

    A handler installed before ours (e.g. from rclpy) is chained after the pump is off.
    """

    def handler(signum: int, frame: FrameType | None) -> None:
        turn_off()
        previous = previous_handlers.get(signum)
        if callable(previous):
            previous(signum, frame)
        raise KeyboardInterrupt(f'signal {signum}')

    previous_handlers = {}
    for signum in (signal.SIGTERM, signal.SIGINT):
        previous_handlers[signum] = signal.getsignal(signum)
        signal.signal(signum, handler)


def main(args: list[str] | None = None) -> None:
    """Entry point of ``ros2 run hw_drivers pump_node``."""
    rclpy.init(args=args)
    node = None
    try:
        node = PumpNode()
        install_signal_handlers(node.shutdown_pump)
        rclpy.spin(node)
    except (KeyboardInterrupt, ExternalShutdownException):
        pass
    except FatalDeviceError as err:
        rclpy.logging.get_logger('pump_node').fatal(str(err))
        raise SystemExit(1) from err
    finally:
        if node is not None:
            node.shutdown_pump()
            node.destroy_node()
        rclpy.try_shutdown()


if __name__ == '__main__':
    main()
