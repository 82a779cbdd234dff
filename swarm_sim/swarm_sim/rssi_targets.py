"""RSSI-emitting targets with a task load: the world model of the MSC + PF mission.

Pure numpy and seeded (spec sections 0.1-0.2, the paper's Table I):

* each target emits a beacon; a robot at distance d receives
  ``P = P_tx - PL0 - 10 K log10(max(d, 1 m)) + n``, ``n ~ N(0, sigma^2)`` drawn independently
  per (robot, target, sample), and detects it when ``P >= gamma_D``;
* targets are placed uniformly in the square field;
* a robot that stands still within D_th of an uncaptured target works on it at R_w load/s;
  the target is captured when its load W is used up, and the robots working on it at that
  moment learn its ID.

The sim bridge's RSSI extension and the batch simulator
(:mod:`swarm_experiments.msc_pf_batch`) both drive this model.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from swarm_sim.errors import SimulationError

__all__ = ['Capture', 'RadioModel', 'RssiTargetConfig', 'RssiTargetField', 'place_robots']


class RssiTargetError(SimulationError, ValueError):
    """Invalid RSSI-target configuration or input."""


@dataclass(frozen=True)
class RadioModel:
    """Log-distance path loss and receiver noise (Table I)."""

    tx_power_dbm: float = 13.0
    reference_loss_db: float = 40.046
    path_loss_exponent: float = 3.0
    noise_std_db: float = 1.0
    detection_threshold_dbm: float = -101.0

    def mean_rssi_dbm(self, distance_m: np.ndarray) -> np.ndarray:
        """Noise-free RSSI [dBm] at ``distance_m`` (any shape); below 1 m counts as 1 m."""
        d = np.maximum(np.asarray(distance_m, dtype=np.float64), 1.0)
        power = self.tx_power_dbm - self.reference_loss_db
        return power - 10.0 * self.path_loss_exponent * np.log10(d)


@dataclass(frozen=True)
class RssiTargetConfig:
    """The mission: field, targets and task (paper Sec. IV-A, Table I).

    Attributes:
        n_targets: number of targets.
        field_size_m: edge of the square field [m].
        work_load: W, load of one task.
        work_rate_per_s: R_w, load worked per second by one robot.
        task_area_m: D_th, robots closer than this can work [m].
        still_speed_m_s: a robot slower than this counts as standing still (working) [m/s].
        radio: the radio model.
    """

    n_targets: int = 10
    field_size_m: float = 2000.0
    work_load: float = 100.0
    work_rate_per_s: float = 5.0
    task_area_m: float = 5.0
    still_speed_m_s: float = 0.05
    radio: RadioModel = RadioModel()

    def __post_init__(self) -> None:
        if self.n_targets < 0:
            raise RssiTargetError('n_targets must be non-negative')
        for name in ('field_size_m', 'work_load', 'work_rate_per_s', 'task_area_m'):
            value = getattr(self, name)
            if not (math.isfinite(value) and value > 0.0):
                raise RssiTargetError(f'{name} must be a positive number, got {value}')


@dataclass(frozen=True)
class Capture:
    """A target was captured.

    Attributes:
        target_id: index of the target.
        time_s: capture time [s].
        robot_indices: indices of the robots working on it at that moment.
    """

    target_id: int
    time_s: float
    robot_indices: tuple[int, ...]


def place_robots(
    n_robots: int, center_m: tuple[float, float], radius_m: float, rng: np.random.Generator
) -> np.ndarray:
    """(n_robots, 2) positions uniform in the disc of ``radius_m`` around ``center_m`` [m]."""
    r = radius_m * np.sqrt(rng.random(n_robots))
    theta = rng.uniform(0.0, 2.0 * math.pi, n_robots)
    return np.column_stack([center_m[0] + r * np.cos(theta), center_m[1] + r * np.sin(theta)])


class RssiTargetField:
    """Targets, their remaining loads, and the RSSI robots receive from them."""

    def __init__(self, config: RssiTargetConfig, positions_m: np.ndarray) -> None:
        """Targets at ``positions_m`` ((n_targets, 2) [m]); IDs are the row indices."""
        positions = np.asarray(positions_m, dtype=np.float64).reshape(-1, 2)
        if positions.shape[0] != config.n_targets:
            raise RssiTargetError(
                f'{positions.shape[0]} target positions for n_targets={config.n_targets}'
            )
        if not np.all(np.isfinite(positions)):
            raise RssiTargetError('target positions must be finite')
        self.config = config
        self.positions_m = positions
        self.remaining_load = np.full(config.n_targets, config.work_load)
        self.capture_time_s = np.full(config.n_targets, np.nan)

    @classmethod
    def random(cls, config: RssiTargetConfig, rng: np.random.Generator) -> RssiTargetField:
        """Targets placed uniformly in the field."""
        return cls(config, rng.uniform(0.0, config.field_size_m, (config.n_targets, 2)))

    @property
    def captured(self) -> np.ndarray:
        """(n_targets,) bool: load used up."""
        return self.remaining_load <= 0.0

    @property
    def all_captured(self) -> bool:
        """True when every target is captured (the CCT is reached)."""
        return bool(np.all(self.captured))

    def distances_m(self, robot_positions_m: np.ndarray) -> np.ndarray:
        """(R, T) distances from each robot to each target [m]."""
        robots = np.asarray(robot_positions_m, dtype=np.float64).reshape(-1, 2)
        diff = robots[:, None, :] - self.positions_m[None, :, :]
        return np.hypot(diff[..., 0], diff[..., 1])

    def sample_rssi(self, robot_positions_m: np.ndarray, rng: np.random.Generator) -> np.ndarray:
        """(R, T) sampled RSSI [dBm]; NaN where undetectable or captured."""
        radio = self.config.radio
        mean = radio.mean_rssi_dbm(self.distances_m(robot_positions_m))
        sample = mean + rng.normal(0.0, radio.noise_std_db, mean.shape)
        hidden = (sample < radio.detection_threshold_dbm) | self.captured[None, :]
        sample[hidden] = np.nan
        return sample

    def work(
        self, robot_positions_m: np.ndarray, robot_speeds_m_s: np.ndarray, dt_s: float, now_s: float
    ) -> list[Capture]:
        """Let still robots within D_th work for ``dt_s``; return the captures it completes."""
        cfg = self.config
        still = np.asarray(robot_speeds_m_s, dtype=np.float64) < cfg.still_speed_m_s
        if not still.any():
            return []  # nobody works while moving
        near = self.distances_m(robot_positions_m) < cfg.task_area_m
        workers = near & still[:, None] & ~self.captured[None, :]
        before = self.captured.copy()
        self.remaining_load -= cfg.work_rate_per_s * dt_s * workers.sum(axis=0)
        captures = []
        for target in np.flatnonzero(self.captured & ~before):
            self.capture_time_s[target] = now_s
            robots = tuple(int(r) for r in np.flatnonzero(workers[:, target]))
            captures.append(Capture(int(target), float(now_s), robots))
        return captures
