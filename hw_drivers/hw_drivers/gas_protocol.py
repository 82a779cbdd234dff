"""MP503 gas sensor readout: ADC register codecs and the gas microcontroller's JSON replies.

Pure functions only: the TI ADS1115/ADS1015 config and conversion
registers (16-bit, big-endian), the Seeed Grove Base Hat's registers (16-bit little-endian
SMBus words), the Seeed XIAO M0 firmware's JSON reply, and the mapping of a voltage onto the
paper's 10-bit scale (``raw10 = 1023 * V_signal / V_supply``).
"""

from __future__ import annotations

import json
import math
from dataclasses import dataclass
from enum import Enum

from hw_drivers.errors import ConfigurationError, ProtocolError

__all__ = [
    'ADS_CONFIG_REGISTER',
    'ADS_CONVERSION_REGISTER',
    'GROVE_PRODUCT_IDS',
    'MAX_XIAO_REPLY_BYTES',
    'RAW10_MAX',
    'AdsChip',
    'AdsConfig',
    'XiaoSample',
    'ads_config_bytes',
    'ads_config_matches',
    'ads_conversion_done',
    'decode_ads_conversion',
    'decode_ads_word',
    'decode_xiao_reply',
    'encode_ads_config',
    'grove_ratio_register',
    'grove_ratio_to_raw10',
    'grove_voltage_register',
    'volts_to_raw10',
]

RAW10_MAX = 1023
#: Longest gas reply decoded (the firmware's buffer is 96 bytes; the device reader stops at 256).
MAX_XIAO_REPLY_BYTES = 1024
# Characters of an offending value quoted in an error message.
_SHOWN_CHARS = 40

ADS_CONVERSION_REGISTER = 0x00
ADS_CONFIG_REGISTER = 0x01
_ADS_OS_BIT = 0x8000
_ADS_PGA_CODES = {
    6.144: 0b000,
    4.096: 0b001,
    2.048: 0b010,
    1.024: 0b011,
    0.512: 0b100,
    0.256: 0b101,
}
_ADS1115_RATES = {8: 0, 16: 1, 32: 2, 64: 3, 128: 4, 250: 5, 475: 6, 860: 7}
_ADS1015_RATES = {128: 0, 250: 1, 490: 2, 920: 3, 1600: 4, 2400: 5, 3300: 6}

GROVE_PRODUCT_ID_REGISTER = 0x00
GROVE_PRODUCT_IDS = (0x0004, 0x0005)  # Base Hat for Pi, for Pi Zero
_GROVE_VOLTAGE_BASE = 0x20
_GROVE_RATIO_BASE = 0x30
GROVE_RATIO_FULL = 1000  # 0.1 % units


class AdsChip(Enum):
    """TI ADS1x15 variant."""

    ADS1115 = 'ads1115'
    ADS1015 = 'ads1015'


@dataclass(frozen=True)
class AdsConfig:
    """Single-shot, single-ended ADS1x15 conversion settings.

    Attributes:
        chip: ADS1115 (16-bit) or ADS1015 (12-bit).
        channel: input AIN0..AIN3, measured against GND.
        full_scale_v: PGA full-scale range [V] (one of 6.144, 4.096, 2.048, 1.024, 0.512, 0.256).
        data_rate_sps: conversion rate [samples/s], from the chip's table.
    """

    chip: AdsChip = AdsChip.ADS1115
    channel: int = 0
    full_scale_v: float = 4.096
    data_rate_sps: int = 128

    def __post_init__(self) -> None:
        if not 0 <= self.channel <= 3:
            raise ConfigurationError(f'ADS1x15 channel must be 0..3, got {self.channel}')
        if self.full_scale_v not in _ADS_PGA_CODES:
            valid = ', '.join(str(v) for v in _ADS_PGA_CODES)
            raise ConfigurationError(
                f'full_scale_v must be one of {valid}, got {self.full_scale_v}'
            )
        rates = _ADS1115_RATES if self.chip is AdsChip.ADS1115 else _ADS1015_RATES
        if self.data_rate_sps not in rates:
            valid = ', '.join(str(v) for v in rates)
            msg = (
                f'{self.chip.value} data_rate_sps must be one of {valid}, got {self.data_rate_sps}'
            )
            raise ConfigurationError(msg)

    @property
    def conversion_time_s(self) -> float:
        """Duration of one conversion [s]."""
        return 1.0 / self.data_rate_sps


def encode_ads_config(config: AdsConfig, *, start: bool = True) -> int:
    """Config register word: single-shot, AINx vs GND, PGA, data rate, comparator off.

    With ``start`` the OS bit is set, which starts one conversion.
    """
    rates = _ADS1115_RATES if config.chip is AdsChip.ADS1115 else _ADS1015_RATES
    mux = 0b100 + config.channel
    word = mux << 12 | _ADS_PGA_CODES[config.full_scale_v] << 9 | 1 << 8
    word |= rates[config.data_rate_sps] << 5 | 0b11
    return word | (_ADS_OS_BIT if start else 0)


def ads_config_bytes(word: int) -> list[int]:
    """The two bytes to write for a 16-bit register, MSB first."""
    return [word >> 8 & 0xFF, word & 0xFF]


def decode_ads_word(data: list[int] | bytes) -> int:
    """Combine two register bytes (MSB first) into an unsigned 16-bit word."""
    if len(data) != 2:
        raise ProtocolError(f'ADS1x15 register read must return 2 bytes, got {len(data)}')
    return (data[0] & 0xFF) << 8 | (data[1] & 0xFF)


def ads_conversion_done(config_word: int) -> bool:
    """True when the OS bit of a read-back config word says the device is idle."""
    return bool(config_word & _ADS_OS_BIT)


def ads_config_matches(read_back: int, config: AdsConfig) -> bool:
    """True when a read-back config word holds our settings (the OS bit is ignored)."""
    expected = encode_ads_config(config, start=False)
    return (read_back & ~_ADS_OS_BIT & 0xFFFF) == expected


def decode_ads_conversion(data: list[int] | bytes, config: AdsConfig) -> tuple[int, float]:
    """Conversion register bytes to (signed counts, volts); negative readings clamp to 0 V.

    ADS1115: 16-bit two's complement, LSB = FSR/32768. ADS1015: 12-bit left-justified,
    LSB = FSR/2048.
    """
    word = decode_ads_word(data)
    counts = word - 0x10000 if word & 0x8000 else word
    if config.chip is AdsChip.ADS1015:
        counts >>= 4
        full_counts = 2048
    else:
        full_counts = 32768
    volts = max(counts, 0) * config.full_scale_v / full_counts
    return counts, volts


def volts_to_raw10(volts: float, supply_v: float) -> int:
    """Map a sensor voltage onto the paper's 10-bit scale, clamped to 0..1023.

    Raises:
        ConfigurationError: the supply voltage is not positive and finite.
        ProtocolError: the voltage is not finite.
    """
    if not (math.isfinite(supply_v) and supply_v > 0.0):
        raise ConfigurationError(f'supply voltage must be > 0 V, got {supply_v}')
    if not math.isfinite(volts):
        raise ProtocolError(f'sensor voltage is not finite: {volts}')
    return max(0, min(RAW10_MAX, round(RAW10_MAX * volts / supply_v)))


def grove_ratio_register(channel: int) -> int:
    """Register of a Grove Base Hat channel's voltage/supply ratio (0.1 % units)."""
    _check_grove_channel(channel)
    return _GROVE_RATIO_BASE + channel


def grove_voltage_register(channel: int) -> int:
    """Register of a Grove Base Hat channel's voltage [mV]."""
    _check_grove_channel(channel)
    return _GROVE_VOLTAGE_BASE + channel


def _check_grove_channel(channel: int) -> None:
    if not 0 <= channel <= 7:
        raise ConfigurationError(f'Grove Base Hat channel must be 0..7, got {channel}')


def grove_ratio_to_raw10(ratio_permille: int) -> int:
    """Grove ratio register (0..1000, 0.1 % of the supply) to the 10-bit scale.

    Raises:
        ProtocolError: the value is outside 0..1000 (a bus glitch or a wrong register).
    """
    if not 0 <= ratio_permille <= GROVE_RATIO_FULL:
        raise ProtocolError(f'Grove ratio register out of range: {ratio_permille}')
    return round(ratio_permille * RAW10_MAX / GROVE_RATIO_FULL)


@dataclass(frozen=True)
class XiaoSample:
    """One reply of the authors' gas microcontroller firmware.

    Attributes:
        counter: request counter ('timeStamp' in the JSON; not a time), unsigned 32-bit.
        value: 10-bit ADC reading 0..1023.
    """

    counter: int
    value: int


def decode_xiao_reply(data: bytes) -> XiaoSample:
    """Decode one multi-line JSON reply (``{"timeStamp": n, "type": "olfactory", "value": v}``).

    Raises:
        ProtocolError: longer than :data:`MAX_XIAO_REPLY_BYTES`, not UTF-8 JSON (also: nested
            too deeply, an integer of thousands of digits), not an object, wrong type, or
            values out of range.
    """
    if len(data) > MAX_XIAO_REPLY_BYTES:
        raise ProtocolError(f'gas reply longer than {MAX_XIAO_REPLY_BYTES} bytes: {len(data)}')
    try:
        obj = json.loads(data.decode('utf-8'))
    except (ValueError, RecursionError) as err:  # UnicodeDecodeError, JSONDecodeError too
        raise ProtocolError(f'gas reply is not JSON: {data[:80]!r}') from err
    if not isinstance(obj, dict):
        raise ProtocolError(f'gas reply is not a JSON object: {data[:80]!r}')
    if obj.get('type') != 'olfactory':
        kind = _shown(obj.get('type'))
        raise ProtocolError(f'gas reply type is {kind}, expected "olfactory"')
    value = obj.get('value')
    counter = obj.get('timeStamp')
    if isinstance(value, bool) or not isinstance(value, int) or not 0 <= value <= RAW10_MAX:
        raise ProtocolError(f'gas reply value must be an integer 0..1023, got {_shown(value)}')
    if isinstance(counter, bool) or not isinstance(counter, int) or not 0 <= counter < 2**32:
        msg = f'gas reply timeStamp must be an unsigned 32-bit integer, got {_shown(counter)}'
        raise ProtocolError(msg)
    return XiaoSample(counter=counter, value=value)


def _shown(value: object) -> str:
    text = repr(value)
    return text if len(text) <= _SHOWN_CHARS else f'{text[:_SHOWN_CHARS]}... ({len(text)} chars)'
