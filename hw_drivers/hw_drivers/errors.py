"""Exceptions of the hardware drivers.

Two families tell a node what to do next:

* :class:`RecoverableDeviceError`: the device is missing, unplugged, silent or sent bytes that
  do not follow its protocol. The worker closes the device, reports it on /diagnostics and
  retries with back-off.
* :class:`FatalDeviceError`: retrying cannot help until a person acts (wrong chip on the bus,
  permissions, an impossible configuration). The worker reports it as an error and retries
  only slowly, so a fixed cable or udev rule is still picked up without a restart.
"""

from __future__ import annotations

__all__ = [
    'CalibrationError',
    'ConfigurationError',
    'DeviceHealthError',
    'DeviceIdentityError',
    'DeviceTimeoutError',
    'DeviceUnavailableError',
    'FatalDeviceError',
    'HwDriverError',
    'ProtocolError',
    'RecoverableDeviceError',
]


class HwDriverError(Exception):
    """Base class of every exception raised by hw_drivers."""


class RecoverableDeviceError(HwDriverError):
    """A fault that closing, waiting and reopening the device may cure."""


class DeviceUnavailableError(RecoverableDeviceError):
    """The device cannot be opened or stopped answering (missing, unplugged, I2C NACK)."""


class DeviceTimeoutError(RecoverableDeviceError):
    """The device did not answer within the allowed time."""


class ProtocolError(RecoverableDeviceError):
    """Bytes from the device do not follow its protocol (bad sync, length, checksum)."""


class DeviceHealthError(RecoverableDeviceError):
    """The device reports an internal fault (e.g. RPLidar health status Error)."""


class CalibrationError(RecoverableDeviceError):
    """A calibration could not be completed (e.g. the robot moved during gyro calibration)."""


class FatalDeviceError(HwDriverError):
    """A fault that needs a person: wrong device, permissions, impossible configuration."""


class DeviceIdentityError(FatalDeviceError):
    """The device at the configured address is not the expected chip (WHO_AM_I mismatch)."""


class ConfigurationError(FatalDeviceError, ValueError):
    """A driver configuration value is out of range or inconsistent."""
