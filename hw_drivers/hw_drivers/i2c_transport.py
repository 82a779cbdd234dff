"""I2C transport shared by the MPU6050 and the gas ADCs.

Drivers talk to an :class:`SMBusLike` (the smbus2 ``SMBus`` methods they use), so tests pass a
register-map fake. :func:`open_smbus` opens a real bus and maps the errors the kernel gives
into the driver's exceptions; :func:`i2c_error` classifies an ``OSError`` from a transfer.
"""

from __future__ import annotations

import errno
from typing import Protocol

from hw_drivers.errors import DeviceTimeoutError, DeviceUnavailableError, FatalDeviceError

__all__ = ['SMBusLike', 'i2c_error', 'open_smbus']


class SMBusLike(Protocol):
    """The part of smbus2.SMBus the drivers use."""

    def read_byte_data(self, i2c_addr: int, register: int) -> int:
        """Read one register byte."""
        ...

    def write_byte_data(self, i2c_addr: int, register: int, value: int) -> None:
        """Write one register byte."""
        ...

    def read_word_data(self, i2c_addr: int, register: int) -> int:
        """Read a 16-bit SMBus word (little-endian on the wire)."""
        ...

    def read_i2c_block_data(self, i2c_addr: int, register: int, length: int) -> list[int]:
        """Read ``length`` bytes starting at ``register``."""
        ...

    def write_i2c_block_data(self, i2c_addr: int, register: int, data: list[int]) -> None:
        """Write bytes starting at ``register``."""
        ...

    def close(self) -> None:
        """Close the bus."""
        ...


def i2c_error(err: OSError, what: str) -> DeviceUnavailableError | DeviceTimeoutError:
    """Turn an OSError of an I2C transfer into a recoverable driver error.

    errno 121 (EREMOTEIO) is a NACK: nothing answers at the address; 110 is a bus timeout;
    anything else (EIO...) is a bus error.
    """
    if err.errno == errno.ETIMEDOUT:
        return DeviceTimeoutError(f'I2C bus timeout while {what}: {err}')
    if err.errno == errno.EREMOTEIO:
        return DeviceUnavailableError(f'no I2C acknowledge (NACK) while {what}: {err}')
    return DeviceUnavailableError(f'I2C bus error while {what}: {err}')


def open_smbus(bus: int) -> SMBusLike:
    """Open /dev/i2c-<bus> with smbus2.

    Raises:
        DeviceUnavailableError: the bus device does not exist (I2C not enabled?).
        FatalDeviceError: permission denied (add the service user to group i2c).
    """
    import smbus2  # imported here so the package imports where smbus2 is missing

    try:
        return smbus2.SMBus(bus)
    except PermissionError as err:
        raise FatalDeviceError(f'permission denied on /dev/i2c-{bus}: {err}') from err
    except OSError as err:
        raise DeviceUnavailableError(f'cannot open /dev/i2c-{bus}: {err}') from err
