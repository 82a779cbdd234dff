"""Gyro-integrated yaw, as the MPU6050 driver computes it (docs/hardware.md, "Sensor figures").

The measured yaw rate is the true rate plus white noise (the MPU6050's rate noise density is
0.005 deg/s/sqrt(Hz)) plus a residual bias left after the start-up calibration, which may
wander as a random walk (temperature drift). The yaw is integrated from the measured rate, so
it drifts like the real driver's. Set the bias terms to zero for the paper's ideal heading.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from swarm_common.angles import wrap_angle
from swarm_common.params import parameter

from swarm_sim.errors import ConfigurationError
from swarm_sim.sensors_kernel import imu_update_kernel

__all__ = ['GyroYawModel', 'ImuConfig']

GRAVITY_MPS2 = 9.80665


@dataclass(frozen=True)
class ImuConfig:
    """Parameters of the gyro yaw model.

    Attributes:
        rate_hz: output rate [Hz].
        noise_density_radps_per_sqrt_hz: gyro white noise density [rad/s/sqrt(Hz)].
        residual_bias_std_radps: spread of the per-robot residual bias after calibration
            [rad/s] (0.02 deg/s is typical after a warm-up; 0 for an ideal heading).
        bias_random_walk_radps_per_sqrt_s: bias drift rate [rad/s/sqrt(s)].
    """

    rate_hz: float = parameter(10.0, 'IMU output rate.', unit='Hz', gt=0.0)
    noise_density_radps_per_sqrt_hz: float = math.radians(0.005)
    residual_bias_std_radps: float = parameter(
        0.0,
        'Spread of the per-robot gyro bias left after calibration; 0 = ideal heading.',
        unit='rad/s',
        ge=0.0,
        name='gyro_residual_bias_std_radps',
    )
    bias_random_walk_radps_per_sqrt_s: float = parameter(
        0.0,
        'Gyro bias drift.',
        unit='rad/s/sqrt(s)',
        ge=0.0,
        name='gyro_bias_random_walk_radps_per_sqrt_s',
    )

    def __post_init__(self) -> None:
        if not self.rate_hz > 0.0:
            msg = f'rate_hz must be positive, got {self.rate_hz}'
            raise ConfigurationError(msg)
        terms = (
            self.noise_density_radps_per_sqrt_hz,
            self.residual_bias_std_radps,
            self.bias_random_walk_radps_per_sqrt_s,
        )
        if min(terms) < 0.0:
            raise ConfigurationError('IMU noise and bias terms must be >= 0')

    def yaw_variance_rad2(self, elapsed_s: float) -> float:
        """Variance of the integrated yaw after ``elapsed_s`` [rad^2]: the white noise's
        random walk plus the residual bias's drift (what the IMU message reports)."""
        density = self.noise_density_radps_per_sqrt_hz
        bias = self.residual_bias_std_radps
        return density**2 * elapsed_s + (bias * elapsed_s) ** 2


class GyroYawModel:
    """Integrated gyro yaw of N robots."""

    def __init__(
        self, initial_yaw_rad: np.ndarray, config: ImuConfig, rng: np.random.Generator
    ) -> None:
        """Start every robot's yaw estimate at ``initial_yaw_rad`` ((N,) [rad])."""
        self.config = config
        self._rng = rng
        self._yaw = np.array(initial_yaw_rad, dtype=float)
        n = len(self._yaw)
        self._bias = rng.normal(0.0, config.residual_bias_std_radps, n)

    @property
    def yaw_rad(self) -> np.ndarray:
        """(N,) current yaw estimates [rad] in (-pi, pi]."""
        return self._yaw.copy()

    def _draw_rate_noise(self, dt_s: float) -> np.ndarray:
        """Advance the bias random walk over ``dt_s`` and draw the (N,) rate noise
        [rad/s], in this order."""
        cfg = self.config
        n = len(self._yaw)
        if cfg.bias_random_walk_radps_per_sqrt_s > 0.0:
            self._bias += self._rng.normal(
                0.0, cfg.bias_random_walk_radps_per_sqrt_s * math.sqrt(dt_s), n
            )
        noise_std = cfg.noise_density_radps_per_sqrt_hz * math.sqrt(1.0 / dt_s)
        return self._rng.normal(0.0, noise_std, n)

    def update(self, true_yaw_change_rad: np.ndarray, dt_s: float) -> tuple[np.ndarray, np.ndarray]:
        """Integrate one IMU period.

        Args:
            true_yaw_change_rad: (N,) true yaw change over the period [rad].
            dt_s: period length [s].

        Returns:
            (N,) yaw estimates [rad] and (N,) measured, bias-corrected yaw rates [rad/s].
        """
        n = len(self._yaw)
        noise = self._draw_rate_noise(dt_s)
        change = np.asarray(true_yaw_change_rad, dtype=float).reshape(n)
        rate = imu_update_kernel(self._yaw, change, float(dt_s), self._bias, noise)
        return self._yaw.copy(), rate

    def update_reference(
        self, true_yaw_change_rad: np.ndarray, dt_s: float
    ) -> tuple[np.ndarray, np.ndarray]:
        """:meth:`update` in numpy, the reference of the compiled
        :func:`swarm_sim.sensors_kernel.imu_update_kernel` (the same values from the same
        random state)."""
        noise = self._draw_rate_noise(dt_s)
        rate = np.asarray(true_yaw_change_rad, dtype=float) / dt_s
        rate = rate + self._bias + noise
        self._yaw = np.asarray(wrap_angle(self._yaw + rate * dt_s), dtype=float)
        return self._yaw.copy(), rate
