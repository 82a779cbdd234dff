"""Yaw from a z gyro: start-up bias calibration and integration.

Pure numerics, no device: fed with (time, rate) pairs by the MPU6050 session.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from hw_drivers.errors import CalibrationError, ConfigurationError

__all__ = [
    'BiasCalibrator',
    'CalibrationConfig',
    'CalibrationResult',
    'StillnessDetector',
    'YawIntegrator',
    'ZuptConfig',
    'track_bias',
    'wrap_pi',
]


def wrap_pi(angle_rad: float) -> float:
    """Wrap an angle to (-pi, pi] [rad]."""
    wrapped = math.remainder(angle_rad, 2.0 * math.pi)
    return math.pi if wrapped == -math.pi else wrapped


@dataclass(frozen=True)
class CalibrationConfig:
    """Start-up gyro-Z bias calibration.

    Attributes:
        duration_s: how long the robot must stay still [s] (3–5 s recommended).
        max_std_radps: standard deviation above which the robot moved [rad/s]
            (0.3 °/s ≈ 0.0052 rad/s).
        min_samples: fewest samples for a usable mean.
    """

    duration_s: float = 4.0
    max_std_radps: float = math.radians(0.3)
    min_samples: int = 50

    def __post_init__(self) -> None:
        if self.duration_s <= 0.0 or self.max_std_radps <= 0.0 or self.min_samples < 2:
            raise ConfigurationError('calibration needs duration_s > 0, max_std > 0, >= 2 samples')


@dataclass(frozen=True)
class CalibrationResult:
    """Bias [rad/s], its sample standard deviation [rad/s] and the sample count."""

    bias_radps: float
    std_radps: float
    samples: int


class BiasCalibrator:
    """Collect gyro-Z while still; the mean is the bias, a large spread means motion."""

    def __init__(self, config: CalibrationConfig | None = None) -> None:
        self.config = config or CalibrationConfig()
        self._rates: list[float] = []
        self._start_s: float | None = None

    def add(self, time_s: float, rate_radps: float) -> CalibrationResult | None:
        """Add one sample; return the result once ``duration_s`` is covered.

        Raises:
            CalibrationError: the spread exceeds ``max_std_radps`` (the robot moved); the
                calibrator restarts itself so the caller may simply keep feeding it.
        """
        if self._start_s is None:
            self._start_s = time_s
        self._rates.append(rate_radps)
        if time_s - self._start_s < self.config.duration_s:
            return None
        if len(self._rates) < self.config.min_samples:
            count = len(self._rates)
            self.restart()
            msg = f'only {count} gyro samples in {self.config.duration_s} s of calibration'
            raise CalibrationError(msg)
        rates = np.asarray(self._rates)
        result = CalibrationResult(float(rates.mean()), float(rates.std(ddof=1)), rates.size)
        self.restart()
        if result.std_radps > self.config.max_std_radps:
            msg = (
                f'robot moved during gyro calibration: std {math.degrees(result.std_radps):.3f}'
                f' deg/s > {math.degrees(self.config.max_std_radps):.3f} deg/s'
            )
            raise CalibrationError(msg)
        return result

    def restart(self) -> None:
        """Drop collected samples."""
        self._rates = []
        self._start_s = None


class YawIntegrator:
    """Trapezoidal integration of the bias-corrected z rate into yaw in (-pi, pi].

    Args:
        bias_radps: gyro-Z bias [rad/s].
        nominal_dt_s: expected sample spacing [s]; steps longer than ``max_dt_factor`` times
            it are integrated over the capped step only and counted in :attr:`dt_outliers`.
        yaw_rate_variance: growth of the yaw variance per second [rad²/s] (drift model).
    """

    def __init__(
        self,
        bias_radps: float,
        *,
        nominal_dt_s: float = 0.01,
        max_dt_factor: float = 5.0,
        yaw_rate_variance: float = math.radians(0.05) ** 2,
        initial_yaw_rad: float = 0.0,
    ) -> None:
        self.bias_radps = bias_radps
        self.nominal_dt_s = nominal_dt_s
        self.max_dt_s = nominal_dt_s * max_dt_factor
        self.yaw_rate_variance = yaw_rate_variance
        self.yaw_rad = wrap_pi(initial_yaw_rad)
        self.yaw_variance = 0.0
        self.dt_outliers = 0
        self._last: tuple[float, float] | None = None

    def update(self, time_s: float, rate_radps: float) -> float:
        """Integrate one sample taken at ``time_s`` [s]; return the yaw [rad]."""
        corrected = rate_radps - self.bias_radps
        if self._last is not None:
            last_time_s, last_rate = self._last
            dt = time_s - last_time_s
            if dt > self.max_dt_s:
                self.dt_outliers += 1
                dt = self.max_dt_s
            if dt > 0.0:
                self.yaw_rad = wrap_pi(self.yaw_rad + 0.5 * (corrected + last_rate) * dt)
                self.yaw_variance += self.yaw_rate_variance * dt
        self._last = (time_s, corrected)
        return self.yaw_rad


@dataclass(frozen=True)
class ZuptConfig:
    """Zero-velocity bias tracking : while the robot is commanded to stand
    still, the gyro-Z bias slowly follows the measured rate, removing warm-up drift.

    Attributes:
        enabled: track the bias at all.
        hold_s: the zero command must have lasted this long [s].
        max_rate_radps: only rates this close to the bias count (a push is not a bias).
        time_constant_s: time constant of the exponential bias average [s].
        command_timeout_s: commands older than this do not prove stillness [s].
    """

    enabled: bool = True
    hold_s: float = 1.0
    max_rate_radps: float = math.radians(0.5)
    time_constant_s: float = 20.0
    command_timeout_s: float = 0.5

    def __post_init__(self) -> None:
        if min(self.hold_s, self.max_rate_radps, self.time_constant_s) <= 0.0:
            raise ConfigurationError('ZUPT hold, rate limit and time constant must be > 0')
        if self.command_timeout_s <= 0.0:
            raise ConfigurationError('ZUPT command_timeout_s must be > 0')


class StillnessDetector:
    """Whether velocity commands say the robot stands still.

    The executor records commands, the device thread asks; the state is one tuple that is
    replaced, never mutated, so a reader always sees a consistent pair.
    """

    def __init__(self, config: ZuptConfig) -> None:
        self.config = config
        self._state: tuple[float, float] | None = None  # (last command time, zero since)

    def command(self, time_s: float, moving: bool) -> None:
        """Record a velocity command received at ``time_s``."""
        state = self._state
        if moving:
            zero_since_s = math.inf
        elif state is None or math.isinf(state[1]):
            zero_since_s = time_s
        else:
            zero_since_s = state[1]
        self._state = (time_s, zero_since_s)

    def still(self, time_s: float) -> bool:
        """True when a fresh zero command has held for ``hold_s``."""
        state = self._state
        if state is None or not self.config.enabled:
            return False
        last_s, zero_since_s = state
        fresh = 0.0 <= time_s - last_s <= self.config.command_timeout_s
        return fresh and time_s - zero_since_s >= self.config.hold_s


def track_bias(
    integrator: YawIntegrator, rate_radps: float, dt_s: float, config: ZuptConfig
) -> bool:
    """Move the integrator's bias toward ``rate_radps`` (robot known still); True if updated."""
    if abs(rate_radps - integrator.bias_radps) > config.max_rate_radps or dt_s <= 0.0:
        return False
    weight = min(dt_s / config.time_constant_s, 1.0)
    integrator.bias_radps += weight * (rate_radps - integrator.bias_radps)
    return True
