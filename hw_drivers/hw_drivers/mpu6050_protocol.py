"""MPU6050 registers and the 14-byte data block; pure functions only."""

from __future__ import annotations

import math
from dataclasses import dataclass

from hw_drivers.errors import ConfigurationError, ProtocolError

__all__ = [
    'ACCEL_LSB_PER_G',
    'DATA_BLOCK_LENGTH',
    'GYRO_LSB_PER_DPS',
    'STANDARD_GRAVITY_MPS2',
    'ImuRaw',
    'ImuSample',
    'Mpu6050Config',
    'Register',
    'config_writes',
    'decode_data_block',
    'scale_sample',
]

STANDARD_GRAVITY_MPS2 = 9.80665
DATA_BLOCK_LENGTH = 14
GYRO_LSB_PER_DPS = (131.0, 65.5, 32.8, 16.4)
ACCEL_LSB_PER_G = (16384.0, 8192.0, 4096.0, 2048.0)
SATURATED = 32767


class Register:
    """Register addresses used by the driver."""

    SMPLRT_DIV = 0x19
    CONFIG = 0x1A
    GYRO_CONFIG = 0x1B
    ACCEL_CONFIG = 0x1C
    INT_ENABLE = 0x38
    ACCEL_XOUT_H = 0x3B
    PWR_MGMT_1 = 0x6B
    PWR_MGMT_2 = 0x6C
    WHO_AM_I = 0x75


PWR_RESET = 0x80
PWR_WAKE_PLL_X = 0x01


@dataclass(frozen=True)
class Mpu6050Config:
    """Chip configuration; the defaults suit a slow ground robot (42 Hz, 100 Hz, +-250 deg/s).

    Attributes:
        address: I2C address (0x68 with AD0 low, 0x69 with AD0 high).
        accepted_who_am_i: WHO_AM_I values accepted (0x68 genuine; clones differ).
        dlpf_cfg: digital low-pass setting 0..6 (3 = 42 Hz gyro bandwidth).
        sample_rate_div: SMPLRT_DIV; rate = gyro output rate / (1 + div).
        gyro_fs_sel: 0..3 (±250, ±500, ±1000, ±2000 °/s).
        accel_afs_sel: 0..3 (±2, ±4, ±8, ±16 g).
    """

    address: int = 0x68
    accepted_who_am_i: tuple[int, ...] = (0x68,)
    dlpf_cfg: int = 3
    sample_rate_div: int = 9
    gyro_fs_sel: int = 0
    accel_afs_sel: int = 0

    def __post_init__(self) -> None:
        if self.address not in (0x68, 0x69):
            raise ConfigurationError(f'MPU6050 address must be 0x68 or 0x69, got {self.address}')
        if not 0 <= self.dlpf_cfg <= 6:
            raise ConfigurationError(f'dlpf_cfg must be 0..6, got {self.dlpf_cfg}')
        if not 0 <= self.sample_rate_div <= 255:
            raise ConfigurationError(f'sample_rate_div must be 0..255, got {self.sample_rate_div}')
        if not (0 <= self.gyro_fs_sel <= 3 and 0 <= self.accel_afs_sel <= 3):
            raise ConfigurationError('gyro_fs_sel and accel_afs_sel must be 0..3')
        if not self.accepted_who_am_i:
            raise ConfigurationError('accepted_who_am_i must name at least one value')

    @property
    def sample_rate_hz(self) -> float:
        """Internal sample rate [Hz]."""
        base_hz = 8000.0 if self.dlpf_cfg in (0, 7) else 1000.0
        return base_hz / (1 + self.sample_rate_div)


def config_writes(config: Mpu6050Config) -> list[tuple[int, int]]:
    """(register, value) pairs to write after wake-up; each is read back to verify."""
    return [
        (Register.CONFIG, config.dlpf_cfg),
        (Register.SMPLRT_DIV, config.sample_rate_div),
        (Register.GYRO_CONFIG, config.gyro_fs_sel << 3),
        (Register.ACCEL_CONFIG, config.accel_afs_sel << 3),
    ]


@dataclass(frozen=True)
class ImuRaw:
    """Signed 16-bit readings of one data block (accel x/y/z, temperature, gyro x/y/z)."""

    accel: tuple[int, int, int]
    temperature: int
    gyro: tuple[int, int, int]

    @property
    def saturated(self) -> bool:
        """True if any accel or gyro axis sits at the end of its range."""
        return any(abs(v) >= SATURATED for v in (*self.accel, *self.gyro))


@dataclass(frozen=True)
class ImuSample:
    """One sample in SI units, chip axes.

    Attributes:
        accel_mps2: linear acceleration incl. gravity [m/s²], (x, y, z).
        gyro_radps: angular rate [rad/s], (x, y, z), not bias-corrected.
        temperature_c: die temperature [°C].
        saturated: an axis hit the end of its range.
    """

    accel_mps2: tuple[float, float, float]
    gyro_radps: tuple[float, float, float]
    temperature_c: float
    saturated: bool


def _signed(high: int, low: int) -> int:
    word = (high & 0xFF) << 8 | (low & 0xFF)
    return word - 0x10000 if word & 0x8000 else word


def decode_data_block(data: list[int] | bytes) -> ImuRaw:
    """Decode the 14 bytes read from ACCEL_XOUT_H (big-endian words).

    Raises:
        ProtocolError: the block does not have 14 bytes.
    """
    if len(data) != DATA_BLOCK_LENGTH:
        raise ProtocolError(f'MPU6050 data block must be 14 bytes, got {len(data)}')
    words = [_signed(data[i], data[i + 1]) for i in range(0, DATA_BLOCK_LENGTH, 2)]
    return ImuRaw(
        accel=(words[0], words[1], words[2]),
        temperature=words[3],
        gyro=(words[4], words[5], words[6]),
    )


def scale_sample(raw: ImuRaw, config: Mpu6050Config) -> ImuSample:
    """Convert raw counts with the configured full-scale ranges."""
    g_per_count = STANDARD_GRAVITY_MPS2 / ACCEL_LSB_PER_G[config.accel_afs_sel]
    rad_per_count = math.radians(1.0) / GYRO_LSB_PER_DPS[config.gyro_fs_sel]
    ax, ay, az = (v * g_per_count for v in raw.accel)
    gx, gy, gz = (v * rad_per_count for v in raw.gyro)
    return ImuSample(
        accel_mps2=(ax, ay, az),
        gyro_radps=(gx, gy, gz),
        temperature_c=raw.temperature / 340.0 + 36.53,
        saturated=raw.saturated,
    )
