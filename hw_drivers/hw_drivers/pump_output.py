"""The pump's GPIO output: a small interface, a libgpiod v2 backend and a fail-safe wrapper.

:class:`GpiodPumpOutput` requests the line with an explicit inactive initial value (no glitch
at start) and polarity from ``active_low``. :class:`SafePumpLine` serialises access from the
executor and the independent max-on guard thread, and its :meth:`SafePumpLine.off` never
raises, so every exit path can call it.
"""

from __future__ import annotations

import errno
import threading
from typing import Protocol

from hw_drivers.errors import DeviceUnavailableError, FatalDeviceError

__all__ = ['GpiodPumpOutput', 'PumpOutput', 'SafePumpLine', 'parse_line_id']


class PumpOutput(Protocol):
    """A digital output that drives the pump (True = pump running)."""

    def set(self, on: bool) -> None:
        """Drive the pump on or off."""
        ...

    def close(self) -> None:
        """Drive off and release the line."""
        ...


def parse_line_id(line: str) -> int | str:
    """'17' -> 17 (offset), 'GPIO17' -> 'GPIO17' (line name)."""
    text = line.strip()
    return int(text) if text.isdigit() else text


class GpiodPumpOutput:
    """libgpiod v2 (PyPI ``gpiod`` 2.x) output line.

    Args:
        chip_path: GPIO chip device (Pi 4 header: /dev/gpiochip0).
        line: line offset (17) or name ('GPIO17').
        active_low: True if the driver stage is inverting.
        consumer: label shown by gpioinfo.

    Raises:
        DeviceUnavailableError: the chip does not exist (not plugged, wrong path): the node
            retries with back-off and keeps the pump off meanwhile.
        FatalDeviceError: the line does not exist, is busy (EBUSY: another process holds
            it), access is denied or the bindings are missing: retried only slowly.
    """

    def __init__(
        self,
        chip_path: str = '/dev/gpiochip0',
        line: int | str = 17,
        *,
        active_low: bool = False,
        consumer: str = 'swarm-pump',
    ) -> None:
        try:
            import gpiod
            from gpiod.line import Direction, Value
        except ImportError as err:
            raise FatalDeviceError(f'libgpiod v2 Python bindings missing: {err}') from err
        self._active = Value.ACTIVE
        self._inactive = Value.INACTIVE
        self._line = line
        settings = gpiod.LineSettings(
            direction=Direction.OUTPUT, output_value=Value.INACTIVE, active_low=active_low
        )
        try:
            self._request = gpiod.request_lines(
                chip_path, consumer=consumer, config={line: settings}
            )
        except PermissionError as err:
            msg = f'permission denied on {chip_path} (add the service user to group gpio): {err}'
            raise FatalDeviceError(msg) from err
        except FileNotFoundError as err:
            raise DeviceUnavailableError(f'no GPIO chip {chip_path}: {err}') from err
        except OSError as err:
            reason = 'busy (held by another process)' if err.errno == errno.EBUSY else str(err)
            raise FatalDeviceError(f'cannot request {chip_path} line {line}: {reason}') from err
        except ValueError as err:
            raise FatalDeviceError(f'no line {line!r} on {chip_path}: {err}') from err

    def set(self, on: bool) -> None:
        """Drive the line active (pump on) or inactive."""
        self._request.set_value(self._line, self._active if on else self._inactive)

    def close(self) -> None:
        """Drive inactive, then release the line."""
        try:
            self._request.set_value(self._line, self._inactive)
        finally:
            self._request.release()


class SafePumpLine:
    """Thread-safe wrapper that remembers the level and makes "off" infallible."""

    def __init__(self, output: PumpOutput) -> None:
        self._output = output
        self._lock = threading.Lock()
        self.is_on = False
        self.closed = False
        self.off_failures = 0

    def set(self, on: bool) -> None:
        """Apply a level; errors propagate (the caller then calls :meth:`off`)."""
        with self._lock:
            if self.closed:
                return
            if on != self.is_on:
                self._output.set(on)
                self.is_on = on

    def off(self) -> None:
        """Drive off; never raises."""
        with self._lock:
            if self.closed:
                return
            try:
                self._output.set(False)
                self.is_on = False
            except Exception:  # an exit path must not be interrupted by the line
                self.off_failures += 1

    def close(self) -> None:
        """Drive off and release; idempotent, never raises."""
        self.off()
        with self._lock:
            if self.closed:
                return
            self.closed = True
            try:
                self._output.close()
            except Exception:  # as in off(): shutdown continues whatever the line does
                self.off_failures += 1
