"""Serial transport shared by the serial devices (RPLidar, gas microcontroller).

Drivers talk to a :class:`SerialPort` (the subset of pyserial's ``Serial`` they use), so
tests can pass ``serial_for_url('loop://')``, one end of a pty pair or a plain fake.
:func:`open_serial_port` opens a real port exclusively, with timeouts, and turns pyserial's
errors into the driver's exceptions.
"""

from __future__ import annotations

import errno
from typing import Protocol

import serial

from hw_drivers.errors import DeviceUnavailableError, FatalDeviceError

__all__ = ['SerialPort', 'open_serial_port']


class SerialPort(Protocol):
    """The part of pyserial's Serial the drivers use."""

    @property
    def in_waiting(self) -> int:
        """Bytes waiting in the input buffer."""
        ...

    def read(self, size: int = 1) -> bytes:
        """Read up to ``size`` bytes, waiting at most the port's timeout."""
        ...

    def write(self, data: bytes) -> int | None:
        """Write ``data``."""
        ...

    def reset_input_buffer(self) -> None:
        """Discard unread input."""
        ...

    def close(self) -> None:
        """Close the port."""
        ...


def open_serial_port(url: str, *, baudrate: int, timeout_s: float) -> serial.SerialBase:
    """Open ``url`` (a device path or a pyserial URL such as ``loop://``) exclusively.

    Raises:
        DeviceUnavailableError: the port is missing, busy or vanished (worth retrying).
        FatalDeviceError: access is denied (fix the service user's groups or udev rules).
    """
    try:
        return serial.serial_for_url(
            url,
            baudrate=baudrate,
            timeout=timeout_s,
            write_timeout=timeout_s,
            exclusive=True,
        )
    except serial.SerialException as err:
        cause = err.__context__ if isinstance(err.__context__, OSError) else None
        if isinstance(err.errno, int) and err.errno in (errno.EACCES, errno.EPERM):
            raise FatalDeviceError(f'permission denied opening {url}: {err}') from err
        if cause is not None and cause.errno in (errno.EACCES, errno.EPERM):
            raise FatalDeviceError(f'permission denied opening {url}: {err}') from err
        raise DeviceUnavailableError(f'cannot open {url}: {err}') from err
    except OSError as err:
        if err.errno in (errno.EACCES, errno.EPERM):
            raise FatalDeviceError(f'permission denied opening {url}: {err}') from err
        raise DeviceUnavailableError(f'cannot open {url}: {err}') from err
