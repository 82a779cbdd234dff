"""MPU6050 device I/O and the heading session.

:class:`Mpu6050` initialises and reads the chip over an injected SMBus. :class:`ImuSession`
polls it at a fixed rate: bounded retries per cycle, detection of stuck data and brown-outs
(config read back once a second), start-up bias calibration while the robot is still, then
yaw integration. Bias and yaw live in a :class:`HeadingState` owned by the caller, so a
reconnect continues the heading instead of starting again at zero.
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable
from dataclasses import dataclass, field
from enum import Enum

from hw_drivers.errors import (
    CalibrationError,
    ConfigurationError,
    DeviceIdentityError,
    DeviceUnavailableError,
    ProtocolError,
    RecoverableDeviceError,
)
from hw_drivers.heading import (
    BiasCalibrator,
    CalibrationConfig,
    StillnessDetector,
    YawIntegrator,
    ZuptConfig,
    track_bias,
)
from hw_drivers.i2c_transport import SMBusLike, i2c_error
from hw_drivers.mpu6050_protocol import (
    DATA_BLOCK_LENGTH,
    PWR_RESET,
    PWR_WAKE_PLL_X,
    ImuRaw,
    ImuSample,
    Mpu6050Config,
    Register,
    config_writes,
    decode_data_block,
    scale_sample,
)

__all__ = ['HeadingState', 'ImuReading', 'ImuSession', 'Mounting', 'Mpu6050']


class Mounting(Enum):
    """How the board sits on the robot."""

    Z_UP = 'z_up'
    Z_DOWN = 'z_down'  # upside down: rotated 180° about x, so y and z flip sign

    def apply(self, xyz: tuple[float, float, float]) -> tuple[float, float, float]:
        """Rotate a chip-frame vector into the robot frame."""
        x, y, z = xyz
        return (x, y, z) if self is Mounting.Z_UP else (x, -y, -z)


class Mpu6050:
    """Register access to one MPU6050.

    Args:
        bus: open SMBus.
        config: chip configuration.
        sleep: pause function [s]; injectable.
    """

    def __init__(
        self,
        bus: SMBusLike,
        config: Mpu6050Config,
        *,
        sleep: Callable[[float], None] = time.sleep,
    ) -> None:
        self.bus = bus
        self.config = config
        self._sleep = sleep

    def read_register(self, register: int) -> int:
        """Read one byte (I2C faults become recoverable driver errors)."""
        try:
            return self.bus.read_byte_data(self.config.address, register)
        except OSError as err:
            raise i2c_error(err, f'reading MPU6050 register 0x{register:02X}') from err

    def write_register(self, register: int, value: int) -> None:
        """Write one byte."""
        try:
            self.bus.write_byte_data(self.config.address, register, value)
        except OSError as err:
            raise i2c_error(err, f'writing MPU6050 register 0x{register:02X}') from err

    def initialise(self) -> None:
        """Identity check, reset, wake with the PLL clock, configure and verify.

        Raises:
            DeviceUnavailableError: nothing answers at the address (NACK) or bus error.
            DeviceIdentityError: WHO_AM_I is not an accepted value.
            ProtocolError: a configuration register did not read back as written.
        """
        who_am_i = self.read_register(Register.WHO_AM_I)
        if who_am_i not in self.config.accepted_who_am_i:
            accepted = ', '.join(f'0x{v:02X}' for v in self.config.accepted_who_am_i)
            msg = (
                f'WHO_AM_I at 0x{self.config.address:02X} is 0x{who_am_i:02X}, expected'
                f' {accepted} (MPU-6500 answers 0x70, MPU-9250 0x71; add it to'
                ' accepted_who_am_i if this clone is intended)'
            )
            raise DeviceIdentityError(msg)
        self.write_register(Register.PWR_MGMT_1, PWR_RESET)
        self._sleep(0.1)
        self.write_register(Register.PWR_MGMT_1, PWR_WAKE_PLL_X)
        self._sleep(0.05)
        for register, value in config_writes(self.config):
            self.write_register(register, value)
        if not self.config_intact():
            raise ProtocolError('MPU6050 configuration did not read back as written')

    def config_intact(self) -> bool:
        """True when power and configuration registers hold what was written.

        A brown-out leaves the chip asleep with default configuration.
        """
        expected = [(Register.PWR_MGMT_1, PWR_WAKE_PLL_X), *config_writes(self.config)]
        return all(self.read_register(reg) == value for reg, value in expected)

    def read_raw(self) -> ImuRaw:
        """One burst read of the 14-byte data block."""
        try:
            data = self.bus.read_i2c_block_data(
                self.config.address, Register.ACCEL_XOUT_H, DATA_BLOCK_LENGTH
            )
        except OSError as err:
            raise i2c_error(err, 'reading the MPU6050 data block') from err
        return decode_data_block(data)

    def close(self) -> None:
        """Close the bus."""
        self.bus.close()


@dataclass
class HeadingState:
    """Calibration and yaw that outlive a reconnect."""

    calibration: CalibrationConfig = field(default_factory=CalibrationConfig)
    stillness: StillnessDetector = field(default_factory=lambda: StillnessDetector(ZuptConfig()))
    zupt_updates: int = 0
    integrator: YawIntegrator | None = None
    calibrator: BiasCalibrator | None = None
    calibration_failures: int = 0
    last_calibration_error: str = ''

    @property
    def calibrated(self) -> bool:
        """True once a bias is known and yaw is being integrated."""
        return self.integrator is not None


@dataclass(frozen=True)
class ImuReading:
    """A calibrated sample in the robot frame, ready to publish.

    Attributes:
        time_s: monotonic read time [s].
        accel_mps2: linear acceleration incl. gravity [m/s²], (x, y, z).
        gyro_radps: bias-corrected angular rate [rad/s], (x, y, z).
        yaw_rad: integrated yaw, REP 103 (counter-clockwise), (-pi, pi].
        yaw_variance: variance of the yaw [rad²], growing with time.
        saturated: an axis hit the end of its range.
    """

    time_s: float
    accel_mps2: tuple[float, float, float]
    gyro_radps: tuple[float, float, float]
    yaw_rad: float
    yaw_variance: float
    saturated: bool


class ImuSession:
    """Poll an initialised MPU6050 at ``rate_hz``: calibrate, then integrate and report.

    Args:
        device: the initialised chip.
        heading: calibration and yaw state (kept by the caller across reconnects).
        on_reading: receives each calibrated reading.
        rate_hz: polling rate [Hz].
        mounting: board orientation.
        retries: failed reads tolerated per cycle before the fault is raised.
        stuck_limit: identical data blocks in a row treated as a stuck sensor.
        check_period_s: how often the configuration is read back [s].
    """

    def __init__(
        self,
        device: Mpu6050,
        heading: HeadingState,
        on_reading: Callable[[ImuReading], None],
        *,
        rate_hz: float = 100.0,
        mounting: Mounting = Mounting.Z_UP,
        retries: int = 3,
        stuck_limit: int = 10,
        check_period_s: float = 1.0,
        sleep: Callable[[float], None] = time.sleep,
        clock: Callable[[], float] = time.monotonic,
    ) -> None:
        if not (math.isfinite(rate_hz) and rate_hz > 0.0):
            raise ConfigurationError(f'rate_hz must be > 0, got {rate_hz}')
        self.device = device
        self.heading = heading
        self._on_reading = on_reading
        self.period_s = 1.0 / rate_hz
        self.mounting = mounting
        self.retries = retries
        self.stuck_limit = stuck_limit
        self.check_period_s = check_period_s
        self._sleep = sleep
        self._clock = clock
        self._next_s = clock()
        self._next_check_s = clock() + check_period_s
        self._last_raw: ImuRaw | None = None
        self._same_count = 0
        self.read_errors = 0
        self.saturations = 0
        if heading.calibrator is None:
            heading.calibrator = BiasCalibrator(heading.calibration)

    def _read_with_retries(self) -> ImuRaw:
        failures = 0
        while True:
            try:
                return self.device.read_raw()
            except RecoverableDeviceError:
                self.read_errors += 1
                failures += 1
                if failures > self.retries:
                    raise

    def poll(self) -> bool:
        """Wait for the next sample instant, read one block, update the heading."""
        wait_s = self._next_s - self._clock()
        if wait_s > 0.0:
            self._sleep(min(wait_s, self.period_s))
            return False
        self._next_s = max(self._next_s + self.period_s, self._clock())
        now = self._clock()
        if now >= self._next_check_s:
            self._next_check_s = now + self.check_period_s
            if not self.device.config_intact():
                raise DeviceUnavailableError('MPU6050 lost its configuration (brown-out?)')
        raw = self._read_with_retries()
        self._check_stuck(raw)
        sample = scale_sample(raw, self.device.config)
        if sample.saturated:
            self.saturations += 1
        return self._integrate(now, sample)

    def _check_stuck(self, raw: ImuRaw) -> None:
        if raw == self._last_raw:
            self._same_count += 1
            if self._same_count >= self.stuck_limit:
                if not self.device.config_intact():
                    raise DeviceUnavailableError('MPU6050 lost its configuration (brown-out?)')
                msg = f'MPU6050 data identical for {self._same_count + 1} reads (stuck sensor)'
                raise ProtocolError(msg)
        else:
            self._same_count = 0
        self._last_raw = raw

    def _integrate(self, now: float, sample: ImuSample) -> bool:
        gyro = self.mounting.apply(sample.gyro_radps)
        heading = self.heading
        if heading.integrator is None:
            assert heading.calibrator is not None
            try:
                result = heading.calibrator.add(now, gyro[2])
            except CalibrationError as err:
                heading.calibration_failures += 1
                heading.last_calibration_error = str(err)
                return False
            if result is None:
                return False
            heading.integrator = YawIntegrator(result.bias_radps, nominal_dt_s=self.period_s)
        integrator = heading.integrator
        if heading.stillness.still(now) and track_bias(
            integrator, gyro[2], self.period_s, heading.stillness.config
        ):
            heading.zupt_updates += 1
        yaw = integrator.update(now, gyro[2])
        corrected = (gyro[0], gyro[1], gyro[2] - integrator.bias_radps)
        self._on_reading(
            ImuReading(
                time_s=now,
                accel_mps2=self.mounting.apply(sample.accel_mps2),
                gyro_radps=corrected,
                yaw_rad=yaw,
                yaw_variance=integrator.yaw_variance,
                saturated=sample.saturated,
            )
        )
        return True

    def close(self) -> None:
        """Close the bus."""
        self.device.close()
