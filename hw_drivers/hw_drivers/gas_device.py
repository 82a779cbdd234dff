"""MP503 gas sensor I/O: three ADC backends behind one interface.

* :class:`AdsGasBackend`: TI ADS1115/ADS1015 on I2C, single-shot conversions, averaged.
* :class:`GroveHatGasBackend`: the Seeed Grove Base Hat's ratio register.
* :class:`XiaoGasBackend`: the authors' setup, a Seeed XIAO M0 on USB serial that answers
  each received byte with one multi-line JSON object.

Every backend returns a :class:`GasSample` on the paper's 10-bit scale. :class:`GasSession`
polls a backend at a fixed rate and tracks the heater warm-up.
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable
from dataclasses import dataclass
from typing import Protocol

from hw_drivers.errors import (
    ConfigurationError,
    DeviceIdentityError,
    DeviceTimeoutError,
    ProtocolError,
)
from hw_drivers.gas_protocol import (
    ADS_CONFIG_REGISTER,
    ADS_CONVERSION_REGISTER,
    GROVE_PRODUCT_IDS,
    AdsConfig,
    ads_config_bytes,
    ads_config_matches,
    ads_conversion_done,
    decode_ads_conversion,
    decode_ads_word,
    decode_xiao_reply,
    encode_ads_config,
    grove_ratio_register,
    grove_ratio_to_raw10,
    grove_voltage_register,
    volts_to_raw10,
)
from hw_drivers.i2c_transport import SMBusLike, i2c_error
from hw_drivers.serial_transport import SerialPort

_MAX_OS_POLLS = 50

__all__ = [
    'AdsGasBackend',
    'GasBackend',
    'GasSample',
    'GasSession',
    'GroveHatGasBackend',
    'WarmUp',
    'XiaoGasBackend',
]


@dataclass(frozen=True)
class GasSample:
    """One gas reading.

    Attributes:
        raw10: sensor output on the paper's 10-bit scale, 0..1023.
        volts: sensor output voltage [V] (NaN when the backend cannot know it).
        native: the backend's own reading (ADC counts, permille or the 10-bit value).
        pinned: True when the reading sits at 0 or full scale (open or shorted signal).
    """

    raw10: int
    volts: float
    native: int
    pinned: bool = False


class GasBackend(Protocol):
    """Reads one gas sample from an opened device."""

    def read(self) -> GasSample:
        """Return a fresh sample; raise a RecoverableDeviceError on device faults."""
        ...

    def close(self) -> None:
        """Release the device."""
        ...


class AdsGasBackend:
    """ADS1115/ADS1015 single-shot readout with averaging and config verification.

    Args:
        bus: open SMBus.
        address: I2C address (0x48..0x4B).
        config: conversion settings.
        supply_v: sensor supply voltage [V] used for the 10-bit normalisation.
        averaging: conversions averaged per sample.
        sleep: pause function [s]; injectable for tests.
        clock: monotonic clock [s]; injectable for tests.
    """

    def __init__(
        self,
        bus: SMBusLike,
        *,
        address: int = 0x48,
        config: AdsConfig | None = None,
        supply_v: float = 3.3,
        averaging: int = 4,
        sleep: Callable[[float], None] = time.sleep,
        clock: Callable[[], float] = time.monotonic,
    ) -> None:
        if averaging < 1:
            raise ConfigurationError(f'averaging must be >= 1, got {averaging}')
        self.bus = bus
        self.address = address
        self.config = config or AdsConfig()
        self.supply_v = supply_v
        self.averaging = averaging
        self._sleep = sleep
        self._clock = clock
        self._full_counts = 32767 if self.config.chip.value == 'ads1115' else 2047
        self.verify()

    def _read_register(self, register: int, what: str) -> list[int]:
        try:
            return self.bus.read_i2c_block_data(self.address, register, 2)
        except OSError as err:
            raise i2c_error(err, what) from err

    def _write_config(self, start: bool) -> None:
        word = encode_ads_config(self.config, start=start)
        try:
            self.bus.write_i2c_block_data(self.address, ADS_CONFIG_REGISTER, ads_config_bytes(word))
        except OSError as err:
            raise i2c_error(err, 'writing the ADS1x15 config') from err

    def verify(self) -> None:
        """Write the config without starting a conversion and read it back.

        Raises:
            DeviceIdentityError: the read-back differs (another chip at this address).
        """
        self._write_config(start=False)
        read_back = decode_ads_word(self._read_register(ADS_CONFIG_REGISTER, 'reading config'))
        if not ads_config_matches(read_back, self.config):
            expected = encode_ads_config(self.config, start=False)
            msg = (
                f'ADS1x15 at 0x{self.address:02X}: config read back 0x{read_back:04X},'
                f' wrote 0x{expected:04X} (not an ADS1x15, or a bus fault)'
            )
            raise DeviceIdentityError(msg)

    def convert_once(self) -> tuple[int, float]:
        """Start one conversion, wait for OS = idle (at most 10 conversion times), read it.

        Raises:
            DeviceTimeoutError: the conversion never completed.
        """
        self._write_config(start=True)
        deadline = self._clock() + 10.0 * self.config.conversion_time_s + 0.01
        self._sleep(self.config.conversion_time_s)
        # Bounded by time and by count, so a clock that does not move cannot hang the loop.
        for _ in range(_MAX_OS_POLLS):
            word = decode_ads_word(self._read_register(ADS_CONFIG_REGISTER, 'polling OS'))
            if ads_conversion_done(word):
                break
            if self._clock() > deadline:
                break
            self._sleep(self.config.conversion_time_s / 4.0)
        else:
            word = 0
        if not ads_conversion_done(word):
            raise DeviceTimeoutError('ADS1x15 conversion did not complete (OS stayed 0)')
        data = self._read_register(ADS_CONVERSION_REGISTER, 'reading the conversion')
        return decode_ads_conversion(data, self.config)

    def read(self) -> GasSample:
        """Average ``averaging`` conversions into one sample."""
        readings = [self.convert_once() for _ in range(self.averaging)]
        counts = round(sum(c for c, _ in readings) / len(readings))
        volts = sum(v for _, v in readings) / len(readings)
        pinned = counts <= 0 or counts >= self._full_counts
        return GasSample(volts_to_raw10(volts, self.supply_v), volts, counts, pinned)

    def close(self) -> None:
        """Close the bus."""
        self.bus.close()


class GroveHatGasBackend:
    """Seeed Grove Base Hat: the channel's voltage/supply ratio is the 10-bit value.

    Args:
        bus: open SMBus.
        address: I2C address (0x04).
        channel: ADC channel (slot A0 -> 0).
    """

    def __init__(self, bus: SMBusLike, *, address: int = 0x04, channel: int = 0) -> None:
        self.bus = bus
        self.address = address
        self.channel = channel
        self._ratio_register = grove_ratio_register(channel)
        self._voltage_register = grove_voltage_register(channel)
        product = self._word(0x00, 'reading the product id')
        if product not in GROVE_PRODUCT_IDS:
            msg = f'device at 0x{address:02X} has product id 0x{product:04X}, not a Grove Base Hat'
            raise DeviceIdentityError(msg)

    def _word(self, register: int, what: str) -> int:
        try:
            return self.bus.read_word_data(self.address, register)
        except OSError as err:
            raise i2c_error(err, what) from err

    def read(self) -> GasSample:
        """Read ratio (0.1 % of supply) and voltage (mV) of the channel."""
        ratio = self._word(self._ratio_register, 'reading the channel ratio')
        millivolts = self._word(self._voltage_register, 'reading the channel voltage')
        raw10 = grove_ratio_to_raw10(ratio)
        return GasSample(raw10, millivolts / 1000.0, ratio, ratio in (0, 1000))

    def close(self) -> None:
        """Close the bus."""
        self.bus.close()


class XiaoGasBackend:
    """The authors' gas microcontroller: one request byte, one JSON reply ending in CR LF.

    Args:
        port: open serial port (its read timeout bounds each read).
        reference_v: the microcontroller's ADC reference [V] for the volts estimate.
        reply_timeout_s: time allowed for a complete reply [s].
        max_reply_bytes: longer replies are garbage (the firmware's buffer is 96 bytes).
        clock: monotonic clock [s].
    """

    REQUEST = b' '

    def __init__(
        self,
        port: SerialPort,
        *,
        reference_v: float = 3.3,
        reply_timeout_s: float = 0.2,
        max_reply_bytes: int = 256,
        clock: Callable[[], float] = time.monotonic,
    ) -> None:
        self.port = port
        self.reference_v = reference_v
        self.reply_timeout_s = reply_timeout_s
        self.max_reply_bytes = max_reply_bytes
        self._clock = clock
        self._last_counter: int | None = None
        self.duplicates = 0

    def _read_reply(self) -> bytes:
        deadline = self._clock() + self.reply_timeout_s
        reply = bytearray()
        while b'\r' not in reply:
            if len(reply) > self.max_reply_bytes:
                raise ProtocolError(f'gas reply longer than {self.max_reply_bytes} bytes')
            chunk = self.port.read(max(1, self.port.in_waiting))
            if chunk:
                reply += chunk
            elif self._clock() >= deadline:
                raise DeviceTimeoutError(f'gas microcontroller silent for {self.reply_timeout_s} s')
        return bytes(reply[: reply.index(b'\r')])

    def read(self) -> GasSample:
        """Flush, request, read until CR, decode; a repeated counter is a stale duplicate.

        Raises:
            ProtocolError: garbage, truncated reply or a duplicate counter.
            DeviceTimeoutError: no complete reply in time.
        """
        self.port.reset_input_buffer()
        self.port.write(self.REQUEST)
        sample = decode_xiao_reply(self._read_reply())
        if self._last_counter is not None and sample.counter == self._last_counter:
            self.duplicates += 1
            raise ProtocolError(f'gas reply repeats counter {sample.counter}')
        self._last_counter = sample.counter
        volts = sample.value * self.reference_v / 1023.0
        return GasSample(sample.value, volts, sample.value, sample.value in (0, 1023))

    def close(self) -> None:
        """Close the port."""
        self.port.close()


@dataclass
class WarmUp:
    """Heater warm-up: readings are flagged for ``duration_s`` after the first sample."""

    duration_s: float = 120.0
    started_s: float | None = None

    def warming_up(self, now_s: float) -> bool:
        """True until ``duration_s`` after the first call."""
        if self.started_s is None:
            self.started_s = now_s
        return now_s - self.started_s < self.duration_s


class GasSession:
    """Poll a gas backend at ``rate_hz``; hand (sample, warming_up) to a callback.

    A single bad reply (garbage, duplicate) is counted and skipped; a run of
    ``max_consecutive_errors`` raises, so the worker reopens the device.
    """

    def __init__(
        self,
        backend: GasBackend,
        on_sample: Callable[[GasSample, bool], None],
        *,
        rate_hz: float = 10.0,
        warm_up: WarmUp | None = None,
        max_consecutive_errors: int = 5,
        sleep: Callable[[float], None] = time.sleep,
        clock: Callable[[], float] = time.monotonic,
    ) -> None:
        if not (math.isfinite(rate_hz) and rate_hz > 0.0):
            raise ConfigurationError(f'rate_hz must be > 0, got {rate_hz}')
        self.backend = backend
        self._on_sample = on_sample
        self.period_s = 1.0 / rate_hz
        self.warm_up = warm_up or WarmUp()
        self.max_consecutive_errors = max_consecutive_errors
        self._sleep = sleep
        self._clock = clock
        self._next_s = clock()
        self.consecutive_errors = 0
        self.skipped = 0

    def poll(self) -> bool:
        """Wait for the next sampling instant, read, and hand the sample on."""
        wait_s = self._next_s - self._clock()
        if wait_s > 0.0:
            self._sleep(min(wait_s, self.period_s))
            return False
        self._next_s = max(self._next_s + self.period_s, self._clock())
        try:
            sample = self.backend.read()
        except ProtocolError:
            self.skipped += 1
            self.consecutive_errors += 1
            if self.consecutive_errors >= self.max_consecutive_errors:
                raise
            return False
        self.consecutive_errors = 0
        self._on_sample(sample, self.warm_up.warming_up(self._clock()))
        return True

    def close(self) -> None:
        """Close the backend."""
        self.backend.close()
