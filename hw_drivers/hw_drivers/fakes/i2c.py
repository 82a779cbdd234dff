"""Register-level fakes of the I2C devices and of an smbus2 bus with injectable faults."""

from __future__ import annotations

import errno
import math
from collections.abc import Callable
from typing import Protocol

import numpy as np

__all__ = ['FakeAds1115', 'FakeGroveHat', 'FakeI2CDevice', 'FakeMpu6050', 'FakeSMBus']


class FakeI2CDevice(Protocol):
    """A device on the fake bus: byte reads and writes starting at a register."""

    def read(self, register: int, length: int) -> list[int]:
        """Bytes as they appear on the wire."""
        ...

    def write(self, register: int, data: list[int]) -> None:
        """Bytes as they appear on the wire."""
        ...


class FakeSMBus:
    """An smbus2-compatible bus of fake devices.

    An address without a device NACKs (OSError errno 121). :meth:`fail_next` makes the next
    transfers fail with a chosen errno, e.g. 110 (bus timeout) or 5 (EIO).
    """

    def __init__(self, devices: dict[int, FakeI2CDevice]) -> None:
        self.devices = devices
        self._faults: list[tuple[int, str | None]] = []
        self.closed = False
        self.transfers = 0

    def fail_next(self, err: int = errno.EREMOTEIO, count: int = 1, method: str | None = None):
        """Fail the next ``count`` transfers (of ``method`` only, if given) with ``err``."""
        self._faults += [(err, method)] * count

    def _device(self, address: int, method: str) -> FakeI2CDevice:
        self.transfers += 1
        if self.closed:
            raise OSError(errno.EBADF, 'bus closed')
        for i, (err, only) in enumerate(self._faults):
            if only is None or only == method:
                del self._faults[i]
                raise OSError(err, os_strerror(err))
        device = self.devices.get(address)
        if device is None:
            raise OSError(errno.EREMOTEIO, 'Remote I/O error')
        return device

    def read_byte_data(self, i2c_addr: int, register: int) -> int:
        return self._device(i2c_addr, 'read_byte_data').read(register, 1)[0]

    def write_byte_data(self, i2c_addr: int, register: int, value: int) -> None:
        self._device(i2c_addr, 'write_byte_data').write(register, [value & 0xFF])

    def read_word_data(self, i2c_addr: int, register: int) -> int:
        low, high = self._device(i2c_addr, 'read_word_data').read(register, 2)
        return low | high << 8

    def read_i2c_block_data(self, i2c_addr: int, register: int, length: int) -> list[int]:
        return self._device(i2c_addr, 'read_i2c_block_data').read(register, length)

    def write_i2c_block_data(self, i2c_addr: int, register: int, data: list[int]) -> None:
        self._device(i2c_addr, 'write_i2c_block_data').write(register, list(data))

    def close(self) -> None:
        self.closed = True


def os_strerror(err: int) -> str:
    """Text of an errno, as the kernel reports it."""
    import os

    return os.strerror(err)


class FakeAds1115:
    """ADS1115 register semantics: big-endian registers, single-shot with an OS busy bit.

    ``volts`` is the voltage on every input; a conversion takes ``conversion_time_s``
    (default: one period of the written data rate; 0 for instant) on the injected clock;
    ``never_completes`` keeps OS at 0 forever.
    """

    RESET_CONFIG = 0x8583

    def __init__(
        self,
        clock: Callable[[], float],
        *,
        volts: float = 0.5,
        conversion_time_s: float | None = None,
    ) -> None:
        self._clock = clock
        self.volts = volts
        self.conversion_time_s = conversion_time_s
        self.config = self.RESET_CONFIG
        self.conversion = 0
        self._done_at_s = -math.inf
        self.never_completes = False
        self.conversions_started = 0

    def _full_scale_v(self) -> float:
        code = self.config >> 9 & 0b111
        return (6.144, 4.096, 2.048, 1.024, 0.512, 0.256, 0.256, 0.256)[code]

    def _rate_sps(self) -> int:
        return (8, 16, 32, 64, 128, 250, 475, 860)[self.config >> 5 & 0b111]

    def read(self, register: int, length: int) -> list[int]:
        if register == 0x01:
            busy = self.never_completes or self._clock() < self._done_at_s
            word = (self.config & 0x7FFF) | (0 if busy else 0x8000)
        elif register == 0x00:
            word = self.conversion & 0xFFFF
        else:
            word = 0
        return [word >> 8 & 0xFF, word & 0xFF][:length]

    def write(self, register: int, data: list[int]) -> None:
        if register != 0x01 or len(data) != 2:
            return
        word = data[0] << 8 | data[1]
        self.config = word & 0x7FFF
        if word & 0x8000:
            self.conversions_started += 1
            duration_s = self.conversion_time_s
            if duration_s is None:
                duration_s = 1.0 / self._rate_sps()
            self._done_at_s = self._clock() + duration_s
            counts = round(self.volts / self._full_scale_v() * 32768)
            self.conversion = max(-32768, min(32767, counts))


class FakeGroveHat:
    """Grove Base Hat registers: little-endian words, ratio and voltage of each channel."""

    def __init__(self, *, product_id: int = 0x0004, supply_mv: int = 3300) -> None:
        self.product_id = product_id
        self.supply_mv = supply_mv
        self.channel_mv = [0] * 8

    def read(self, register: int, length: int) -> list[int]:
        if register == 0x00:
            word = self.product_id
        elif 0x20 <= register <= 0x27:
            word = self.channel_mv[register - 0x20]
        elif 0x30 <= register <= 0x37:
            word = round(self.channel_mv[register - 0x30] * 1000 / self.supply_mv)
        elif register == 0x29:
            word = self.supply_mv
        else:
            word = 0
        return [word & 0xFF, word >> 8 & 0xFF][:length]

    def write(self, register: int, data: list[int]) -> None:
        return None


class FakeMpu6050:
    """MPU6050 register map: starts asleep, resets on 0x80, big-endian 14-byte data block.

    The gyro Z rate is ``gyro_z_dps(t)`` in °/s on the injected clock, plus ``bias_dps`` and
    Gaussian noise of ``noise_dps`` (seeded); the accelerometer reads 1 g on Z.
    """

    def __init__(
        self,
        clock: Callable[[], float],
        *,
        who_am_i: int = 0x68,
        gyro_z_dps: Callable[[float], float] = lambda t: 0.0,
        bias_dps: float = 0.0,
        noise_dps: float = 0.0,
        seed: int = 0,
    ) -> None:
        self._clock = clock
        self.who_am_i = who_am_i
        self.gyro_z_dps = gyro_z_dps
        self.bias_dps = bias_dps
        self.noise_dps = noise_dps
        self._rng = np.random.default_rng(seed)
        self.registers = [0] * 0x80
        self.frozen_block: list[int] | None = None
        self.block_reads = 0
        self._reset()

    def _reset(self) -> None:
        self.registers = [0] * 0x80
        self.registers[0x6B] = 0x40  # asleep after power-up
        self.registers[0x75] = self.who_am_i

    def brown_out(self) -> None:
        """Power glitch: registers back to power-up defaults."""
        self._reset()

    def _gyro_lsb_per_dps(self) -> float:
        return (131.0, 65.5, 32.8, 16.4)[self.registers[0x1B] >> 3 & 0b11]

    def _accel_lsb_per_g(self) -> float:
        return (16384.0, 8192.0, 4096.0, 2048.0)[self.registers[0x1C] >> 3 & 0b11]

    def _block(self) -> list[int]:
        if self.frozen_block is not None:
            return list(self.frozen_block)
        if self.registers[0x6B] & 0x40:
            return [0] * 14  # asleep: data registers do not update
        rate = self.gyro_z_dps(self._clock()) + self.bias_dps
        if self.noise_dps:
            rate += float(self._rng.normal(0.0, self.noise_dps))
        words = [
            0,
            0,
            round(self._accel_lsb_per_g()),
            round((25.0 - 36.53) * 340.0),
            0,
            0,
            round(rate * self._gyro_lsb_per_dps()),
        ]
        out: list[int] = []
        for word in words:
            word = max(-32768, min(32767, word)) & 0xFFFF
            out += [word >> 8, word & 0xFF]
        return out

    def read(self, register: int, length: int) -> list[int]:
        if register == 0x3B:
            self.block_reads += 1
            return self._block()[:length]
        return [self.registers[(register + i) & 0x7F] for i in range(length)]

    def write(self, register: int, data: list[int]) -> None:
        for i, value in enumerate(data):
            reg = (register + i) & 0x7F
            if reg == 0x6B and value & 0x80:
                self._reset()
                continue
            if reg != 0x75:
                self.registers[reg] = value & 0xFF
