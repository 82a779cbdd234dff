"""Sensor profiles: ``ideal`` (the models as the papers assume them) and ``realistic``.

``ideal`` is the engine's default configuration, unchanged. ``realistic`` makes every sensor
behave as the hardware does indoors, from the parameters of :class:`RealisticSensors`
(each one overridable):

* **AoA bearings** through walls: a non-line-of-sight bias that grows with the walls
  crossed and drifts slowly as the robots move (a per-link first-order Gauss-Markov process),
  multipath outliers (a bearing anywhere on the circle) whose chance grows with the walls
  crossed, and RSSI distances that read long behind walls. Measurements of Bluetooth 5.1
  direction finding put line-of-sight errors at a few degrees: the Silicon Labs BG22 kit
  the paper uses is specified below 5 degrees; Girolami et al. (IEEE WiMob 2022,
  doi:10.1109/WiMob55322.2022.9941619) and Pau et al. (Sensors 21(11):3589, 2021,
  doi:10.3390/s21113589) report that reflections and obstructed paths indoors give errors of
  tens of degrees. The defaults (10 degrees of bias and 10 % more outliers per wall, 2 %
  outliers in line of sight, 3 dB of extra loss per wall at a path-loss exponent of 2) are a
  model chosen within those ranges, not a fit to one measurement;
* **scent**: the puffs evaporate within minutes (ethanol on a floor) instead of outlasting
  the mission;
* **lidar**: range noise and dropouts at the RPLidar A1 datasheet's accuracy (2 % of the
  range beyond 3 m) and the dropouts of dark or glossy surfaces;
* **IMU**: the MPU6050's residual gyro bias after a start-up calibration, and its drift.

The AoA effects run in :class:`AoaRealism`, an engine step hook; the others are values of
the existing sensor models (:func:`apply_sensor_profile`). The hook draws from a random stream
of its own, so the other sensors' draws are those of the ideal profile.
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np
from swarm_common.angles import wrap_angle
from swarm_common.params import parameter, section

from swarm_sim.errors import ConfigurationError
from swarm_sim.geometry import as_segments, count_crossings
from swarm_sim.sensors.bearings import BearingCycle

if TYPE_CHECKING:
    from swarm_sim.engine import EngineConfig, StepOutput

__all__ = [
    'SENSOR_PROFILES',
    'AoaRealism',
    'AoaRealismConfig',
    'RealisticSensors',
    'apply_sensor_profile',
]

SENSOR_PROFILES = ('ideal', 'realistic')
_AOA_KEY = 0xA0A


@dataclass(frozen=True)
class AoaRealismConfig:
    """Non-line-of-sight effects on the AoA bearings (all off by default: ideal).

    Attributes:
        nlos_bias_std_rad_per_wall: standard deviation of the bearing bias per wall crossed.
        nlos_bias_correlation_s: correlation time of that bias [s].
        outlier_probability_los: chance of a multipath outlier in line of sight.
        outlier_probability_per_wall: added chance per wall crossed.
        outlier_probability_max: cap of the outlier chance.
        wall_distance_factor: RSSI distance multiplier per wall crossed (>= 1: reads long).
    """

    nlos_bias_std_rad_per_wall: float = parameter(
        0.0, 'AoA bearing bias std per wall crossed.', unit='rad', ge=0.0
    )
    nlos_bias_correlation_s: float = parameter(
        5.0, 'Correlation time of the AoA wall bias.', unit='s', gt=0.0
    )
    outlier_probability_los: float = parameter(
        0.0, 'Chance of an AoA multipath outlier in line of sight.', ge=0.0, le=1.0
    )
    outlier_probability_per_wall: float = parameter(
        0.0, 'Added AoA outlier chance per wall crossed.', ge=0.0, le=1.0
    )
    outlier_probability_max: float = parameter(
        0.5, 'Cap of the AoA outlier chance.', ge=0.0, le=1.0
    )
    wall_distance_factor: float = parameter(
        1.0, 'AoA RSSI distance factor per wall crossed.', ge=1.0
    )

    def __post_init__(self) -> None:
        if not (self.nlos_bias_std_rad_per_wall >= 0.0 and self.nlos_bias_correlation_s > 0.0):
            raise ConfigurationError('the AoA bias std must be >= 0 and its correlation > 0')
        probabilities = (
            self.outlier_probability_los,
            self.outlier_probability_per_wall,
            self.outlier_probability_max,
        )
        if not all(0.0 <= p <= 1.0 for p in probabilities):
            raise ConfigurationError('AoA outlier probabilities must be in [0, 1]')
        if not self.wall_distance_factor >= 1.0:
            msg = f'wall_distance_factor must be >= 1, got {self.wall_distance_factor}'
            raise ConfigurationError(msg)

    @property
    def active(self) -> bool:
        """True when some effect is on."""
        return (
            self.nlos_bias_std_rad_per_wall > 0.0
            or self.outlier_probability_los > 0.0
            or self.outlier_probability_per_wall > 0.0
            or self.wall_distance_factor != 1.0
        )


@dataclass(frozen=True)
class RealisticSensors:
    """The parameters of the ``realistic`` profile (see the module docstring for sources).

    Attributes:
        aoa: the AoA non-line-of-sight effects.
        aoa_noise_std_rad: line-of-sight AoA azimuth noise [rad].
        scent_decay_time_constant_s: evaporation time constant of a scent puff [s].
        lidar_noise_fraction: lidar range noise std as a fraction of the range.
        lidar_dropout_probability: chance that one lidar sample is lost.
        gyro_residual_bias_std_radps: spread of the gyro bias after calibration [rad/s].
        gyro_bias_random_walk_radps_per_sqrt_s: drift of that bias [rad/s/sqrt(s)].
    """

    aoa: AoaRealismConfig = section(
        lambda: AoaRealismConfig(
            nlos_bias_std_rad_per_wall=math.radians(10.0),
            outlier_probability_los=0.02,
            outlier_probability_per_wall=0.10,
            outlier_probability_max=0.5,
            wall_distance_factor=10.0 ** (3.0 / 20.0),
        ),
        prefix='aoa_',
    )
    aoa_noise_std_rad: float = parameter(
        math.radians(5.0), 'Line-of-sight AoA azimuth noise std.', unit='rad', ge=0.0
    )
    scent_decay_time_constant_s: float = parameter(
        300.0, 'Evaporation time constant of a scent puff.', unit='s', gt=0.0
    )
    lidar_noise_fraction: float = parameter(0.02, 'Lidar range noise std / range.', ge=0.0)
    lidar_dropout_probability: float = parameter(
        0.03, 'Chance that one lidar sample is lost.', ge=0.0, lt=1.0
    )
    gyro_residual_bias_std_radps: float = parameter(
        math.radians(0.05), 'Spread of the gyro bias after calibration.', unit='rad/s', ge=0.0
    )
    gyro_bias_random_walk_radps_per_sqrt_s: float = parameter(
        2e-5, 'Drift of the gyro bias.', unit='rad/s/sqrt(s)', ge=0.0
    )

    def __post_init__(self) -> None:
        values = (
            self.aoa_noise_std_rad,
            self.lidar_noise_fraction,
            self.gyro_residual_bias_std_radps,
            self.gyro_bias_random_walk_radps_per_sqrt_s,
        )
        if not all(math.isfinite(v) and v >= 0.0 for v in values):
            raise ConfigurationError('realistic sensor noise levels must be finite and >= 0')
        if not self.scent_decay_time_constant_s > 0.0:
            raise ConfigurationError('scent_decay_time_constant_s must be positive')
        if not 0.0 <= self.lidar_dropout_probability < 1.0:
            raise ConfigurationError('lidar_dropout_probability must be in [0, 1)')


def apply_sensor_profile(
    config: EngineConfig, profile: str, realistic: RealisticSensors | None = None
) -> EngineConfig:
    """``config`` with the sensors of ``profile``: unchanged for ``ideal``; for
    ``realistic``, the values of ``realistic`` (default: :class:`RealisticSensors`()).

    Raises:
        ConfigurationError: an unknown profile.
    """
    if profile not in SENSOR_PROFILES:
        msg = f'unknown sensor profile {profile!r}; choose one of {", ".join(SENSOR_PROFILES)}'
        raise ConfigurationError(msg)
    if profile == 'ideal':
        return config
    r = realistic or RealisticSensors()
    return dataclasses.replace(
        config,
        aoa=r.aoa,
        bearings=dataclasses.replace(config.bearings, azimuth_noise_std_rad=r.aoa_noise_std_rad),
        scent=dataclasses.replace(
            config.scent, decay_time_constant_s=r.scent_decay_time_constant_s
        ),
        lidar=dataclasses.replace(
            config.lidar,
            range_noise_fraction=r.lidar_noise_fraction,
            dropout_probability=r.lidar_dropout_probability,
        ),
        imu=dataclasses.replace(
            config.imu,
            residual_bias_std_radps=r.gyro_residual_bias_std_radps,
            bias_random_walk_radps_per_sqrt_s=r.gyro_bias_random_walk_radps_per_sqrt_s,
        ),
    )


class AoaRealism:
    """The engine's step hook of :class:`AoaRealismConfig`: bias, outliers and long
    distances on every AoA report, by the walls between receiver and tag.

    Args:
        config: the effects.
        num_robots: N.
        walls: (M, 2, 2) wall segments [m].
        rate_hz: the locator's report rate (the bias process's step) [Hz].
        seed: the world's seed (the hook draws from a stream of its own).
    """

    def __init__(
        self,
        config: AoaRealismConfig,
        num_robots: int,
        walls: np.ndarray,
        rate_hz: float,
        seed: int,
    ) -> None:
        self.config = config
        self._walls = as_segments(walls)
        self._rng = np.random.default_rng(np.random.SeedSequence(seed, spawn_key=(_AOA_KEY,)))
        self._rho = math.exp(-1.0 / (rate_hz * config.nlos_bias_correlation_s))
        # Per ordered pair (receiver, tag), a standard normal Gauss-Markov state.
        self._bias = self._rng.standard_normal((num_robots, num_robots))

    def walls_crossed(self, poses: np.ndarray, rx: np.ndarray, tx: np.ndarray) -> np.ndarray:
        """(K,) walls crossed by the sight lines from robots ``rx`` to robots ``tx``."""
        return count_crossings(poses[rx, :2], poses[tx, :2], self._walls)

    def perturb(
        self,
        poses: np.ndarray,
        rx: np.ndarray,
        tx: np.ndarray,
        azimuth: np.ndarray,
        distance: np.ndarray,
    ) -> tuple[np.ndarray, np.ndarray]:
        """The azimuths [rad] and distances [m] of one cycle's reports after the effects."""
        cfg = self.config
        self._bias = self._rho * self._bias + math.sqrt(1.0 - self._rho**2) * (
            self._rng.standard_normal(self._bias.shape)
        )
        k = len(rx)
        if not k:
            return azimuth, distance
        walls = self.walls_crossed(poses, rx, tx)
        biased = azimuth + cfg.nlos_bias_std_rad_per_wall * walls * self._bias[rx, tx]
        chance = np.minimum(
            cfg.outlier_probability_los + cfg.outlier_probability_per_wall * walls,
            cfg.outlier_probability_max,
        )
        draws = self._rng.random(k)
        spread = self._rng.uniform(-math.pi, math.pi, k)
        azimuth = np.asarray(wrap_angle(np.where(draws < chance, spread, biased)), dtype=float)
        return azimuth, distance * cfg.wall_distance_factor**walls

    def readings(self, out: StepOutput) -> None:
        """Perturb the step's AoA reports in place."""
        if out.bearing_cycle is not None:
            c = out.bearing_cycle
            azimuth, distance = self.perturb(
                out.poses, c.receivers, c.tags, c.azimuth_rad, c.distance_m
            )
            out.bearing_cycle = dataclasses.replace(c, azimuth_rad=azimuth, distance_m=distance)
        if out.bearings is not None:
            flat = _flatten(out.bearings)
            azimuth, distance = self.perturb(
                out.poses, flat.receivers, flat.tags, flat.azimuth_rad, flat.distance_m
            )
            out.bearings = dataclasses.replace(
                flat, azimuth_rad=azimuth, distance_m=distance
            ).reports()

    def actuators(
        self, time_s: float, commands: np.ndarray, pumping: np.ndarray
    ) -> tuple[np.ndarray, np.ndarray]:
        """No effect on the actuators."""
        return commands, pumping


def _flatten(reports: list) -> BearingCycle:
    """The reports of one cycle (one per robot, in robot order) as one flat cycle."""
    n = len(reports)
    counts = [len(r.tags) for r in reports]
    bounds = np.concatenate(([0], np.cumsum(counts))).astype(int).tolist()

    def cat(name: str, dtype: type) -> np.ndarray:
        parts = [np.asarray(getattr(r, name)) for r in reports]
        return np.concatenate(parts).astype(dtype) if n else np.zeros(0, dtype=dtype)

    return BearingCycle(
        receivers=np.repeat(np.arange(n), counts),
        tags=cat('tags', np.int64),
        azimuth_rad=cat('azimuth_rad', float),
        elevation_rad=cat('elevation_rad', float),
        distance_m=cat('distance_m', float),
        sequence=cat('sequence', np.int64),
        bounds=bounds,
    )
