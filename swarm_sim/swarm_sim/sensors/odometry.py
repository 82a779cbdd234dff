"""Wheel odometry of the robot base: integrated travelled distance and rotation.

The odometry frame coincides with the world frame at the start (a shared frame, as the
Bayes-Swarm and MSC papers assume). Optional proportional noise on each increment makes it
drift like wheel odometry; by default it is exact.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from swarm_common.angles import wrap_angle
from swarm_common.params import parameter

from swarm_sim.errors import ConfigurationError

__all__ = ['OdometryConfig', 'WheelOdometry']


@dataclass(frozen=True)
class OdometryConfig:
    """Parameters of the odometry model.

    Attributes:
        rate_hz: output rate [Hz].
        distance_noise_fraction: std of the travelled-distance error per increment, as a
            fraction of the increment.
        rotation_noise_fraction: std of the rotation error per increment, as a fraction.
    """

    rate_hz: float = parameter(10.0, 'Odometry output rate.', unit='Hz', gt=0.0)
    distance_noise_fraction: float = parameter(
        0.0, 'Odometry distance error std per increment, as a fraction.', ge=0.0
    )
    rotation_noise_fraction: float = 0.0

    def __post_init__(self) -> None:
        if not self.rate_hz > 0.0:
            msg = f'rate_hz must be positive, got {self.rate_hz}'
            raise ConfigurationError(msg)
        if min(self.distance_noise_fraction, self.rotation_noise_fraction) < 0.0:
            raise ConfigurationError('odometry noise fractions must be >= 0')


class WheelOdometry:
    """Dead-reckoned poses of N robots."""

    def __init__(
        self, initial_poses: np.ndarray, config: OdometryConfig, rng: np.random.Generator
    ) -> None:
        """Start at the (N, 3) true poses x [m], y [m], yaw [rad]."""
        self.config = config
        self._rng = rng
        self._pose = np.array(initial_poses, dtype=float)
        self._last_true = np.array(initial_poses, dtype=float)

    @property
    def poses(self) -> np.ndarray:
        """(N, 3) odometry poses x [m], y [m], yaw [rad] now (a copy)."""
        return self._pose.copy()

    def update(self, true_poses: np.ndarray, dt_s: float) -> tuple[np.ndarray, np.ndarray]:
        """Integrate the motion since the last update.

        Args:
            true_poses: (N, 3) current true poses.
            dt_s: time since the last update [s].

        Returns:
            (N, 3) odometry poses and (N, 2) body-frame speed [m/s] and yaw rate [rad/s].
        """
        cfg = self.config
        true_poses = np.asarray(true_poses, dtype=float)
        last = self._last_true
        delta_x = true_poses[:, 0] - last[:, 0]
        delta_y = true_poses[:, 1] - last[:, 1]
        heading = last[:, 2]
        cos_h, sin_h = np.cos(heading), np.sin(heading)
        forward = delta_x * cos_h + delta_y * sin_h
        lateral = -delta_x * sin_h + delta_y * cos_h
        dyaw = np.asarray(wrap_angle(true_poses[:, 2] - heading), dtype=float)
        n = len(true_poses)
        if cfg.distance_noise_fraction > 0.0:
            forward = forward * (1.0 + self._rng.normal(0.0, cfg.distance_noise_fraction, n))
        if cfg.rotation_noise_fraction > 0.0:
            dyaw = dyaw * (1.0 + self._rng.normal(0.0, cfg.rotation_noise_fraction, n))
        pose = self._pose
        yaw = pose[:, 2]
        cos_y, sin_y = np.cos(yaw), np.sin(yaw)
        pose[:, 0] += forward * cos_y - lateral * sin_y
        pose[:, 1] += forward * sin_y + lateral * cos_y
        pose[:, 2] = wrap_angle(yaw + dyaw)
        self._last_true = true_poses.copy()
        twist = np.empty((n, 2))
        twist[:, 0] = forward / dt_s
        twist[:, 1] = dyaw / dt_s
        return pose.copy(), twist
