"""Bluetooth AoA bearings: every robot's locator hears the other robots' tags.

Silicon Labs BG22 direction finding reports azimuth (and elevation) of each tag in range with
an error of a few degrees (the paper: < 5 degrees) and a coarse RSSI-based distance. The paper
measured about 50 m of range with no wall and 30 m through 4 walls; walls attenuate the
signal, which the model expresses as a shorter range: each wall between two robots multiplies
the line-of-sight range by ``wall_range_factor``. The defaults are the paper's figures:
50 m, and (30 / 50) ** (1 / 4) = 0.88 per wall (about 1.1 dB of extra loss per wall under
free-space decay).
"""

from __future__ import annotations

import itertools
import math
from dataclasses import dataclass

import numpy as np
from swarm_common.angles import wrap_angle
from swarm_common.params import parameter

from swarm_sim.errors import ConfigurationError
from swarm_sim.geometry import as_segments, count_crossings, padded_walls
from swarm_sim.raycast_kernel import sight_lines_kernel
from swarm_sim.sensors_kernel import heard_pairs_kernel, wrap_sum_kernel

__all__ = ['BearingConfig', 'BearingCycle', 'BearingModel', 'PeerBearings']


@dataclass(frozen=True)
class BearingConfig:
    """Parameters of the AoA bearing model.

    Attributes:
        rate_hz: locator report rate [Hz].
        range_m: line-of-sight range [m].
        wall_range_factor: range multiplier per wall crossed, in (0, 1].
        azimuth_noise_std_rad: azimuth error standard deviation [rad].
        elevation_noise_std_rad: elevation error standard deviation [rad] (robots share a plane).
        distance_noise_fraction: lognormal spread of the RSSI distance (0.3 = about 30 %).
        dropout_probability: chance that one report of one tag is lost.
    """

    rate_hz: float = parameter(
        5.0, 'AoA locator report rate.', unit='Hz', gt=0.0, name='bearings_rate_hz'
    )
    range_m: float = parameter(50.0, 'AoA line-of-sight range (paper: 30-50).', unit='m', gt=0.0)
    wall_range_factor: float = parameter(0.88, 'Range factor per wall.', ge=0.0, le=1.0)
    azimuth_noise_std_rad: float = parameter(
        math.radians(3.0), 'AoA azimuth error std.', unit='rad', ge=0.0
    )
    elevation_noise_std_rad: float = math.radians(3.0)
    distance_noise_fraction: float = 0.3
    dropout_probability: float = parameter(0.02, 'Chance a report is lost.', ge=0.0, le=1.0)

    def __post_init__(self) -> None:
        if not (self.rate_hz > 0.0 and self.range_m > 0.0):
            raise ConfigurationError('rate_hz and range_m must be positive')
        if not 0.0 < self.wall_range_factor <= 1.0:
            msg = f'wall_range_factor must be in (0, 1], got {self.wall_range_factor}'
            raise ConfigurationError(msg)
        noises = (
            self.azimuth_noise_std_rad,
            self.elevation_noise_std_rad,
            self.distance_noise_fraction,
        )
        if min(noises) < 0.0:
            raise ConfigurationError('noise levels must be >= 0')
        if not 0.0 <= self.dropout_probability < 1.0:
            msg = f'dropout_probability must be in [0, 1), got {self.dropout_probability}'
            raise ConfigurationError(msg)


@dataclass(frozen=True)
class PeerBearings:
    """What one robot's locator reports in one cycle (K tags heard).

    Attributes:
        receiver: index of the receiving robot.
        tags: (K,) indices of the robots whose tags were heard.
        azimuth_rad: (K,) azimuth in the receiver's base frame, REP 103, in (-pi, pi].
        elevation_rad: (K,) elevation [rad].
        distance_m: (K,) coarse distance [m].
        sequence: (K,) per-tag report counters (wrap at 65536).
    """

    receiver: int
    tags: np.ndarray
    azimuth_rad: np.ndarray
    elevation_rad: np.ndarray
    distance_m: np.ndarray
    sequence: np.ndarray


@dataclass(frozen=True)
class BearingCycle:
    """One locator cycle of every robot in flat arrays: the fields of the
    :class:`PeerBearings` reports laid end to end in receiver order (T entries).

    Attributes:
        receivers: (T,) index of the receiving robot, ascending.
        tags: (T,) indices of the robots whose tags were heard.
        azimuth_rad: (T,) azimuth in the receiver's base frame, REP 103, in (-pi, pi].
        elevation_rad: (T,) elevation [rad].
        distance_m: (T,) coarse distance [m].
        sequence: (T,) per-tag report counters (wrap at 65536).
        bounds: N + 1 slice bounds: robot i's report is entries ``bounds[i]:bounds[i + 1]``.
    """

    receivers: np.ndarray
    tags: np.ndarray
    azimuth_rad: np.ndarray
    elevation_rad: np.ndarray
    distance_m: np.ndarray
    sequence: np.ndarray
    bounds: list[int]

    def reports(self) -> list[PeerBearings]:
        """One :class:`PeerBearings` per robot, in robot order."""
        return [
            PeerBearings(
                receiver=i,
                tags=self.tags[lo:hi],
                azimuth_rad=self.azimuth_rad[lo:hi],
                elevation_rad=self.elevation_rad[lo:hi],
                distance_m=self.distance_m[lo:hi],
                sequence=self.sequence[lo:hi],
            )
            for i, (lo, hi) in enumerate(itertools.pairwise(self.bounds))
        ]


class BearingModel:
    """Noisy, range-limited bearings between all robots."""

    def __init__(
        self,
        num_robots: int,
        config: BearingConfig,
        rng: np.random.Generator,
        walls: np.ndarray | None = None,
    ) -> None:
        self.config = config
        self._rng = rng
        self._walls = as_segments(walls if walls is not None else np.zeros((0, 2, 2)))
        self._sequence = np.zeros((num_robots, num_robots), dtype=np.int64)
        q, s = padded_walls(self._walls)
        self._padded_walls = (q, s, np.arange(len(self._walls), dtype=np.int64))
        self._reach_table = np.zeros(0)

    def effective_range_m(self, walls_crossed: np.ndarray) -> np.ndarray:
        """Range [m] left after crossing the given numbers of walls."""
        return self.config.range_m * self.config.wall_range_factor ** np.asarray(walls_crossed)

    def measure(self, poses: np.ndarray) -> list[PeerBearings]:
        """One locator cycle for every robot.

        Args:
            poses: (N, 3) true x [m], y [m], yaw [rad].

        Returns:
            N reports, one per receiving robot, in robot order.
        """
        return self.measure_cycle(poses).reports()

    def measure_cycle(self, poses: np.ndarray) -> BearingCycle:
        """:meth:`measure` with the reports in flat arrays (the same values and draws as
        :meth:`measure_reference`): the sight lines and the selection of the heard ones in
        compiled code, the transcendental functions in numpy."""
        cfg = self.config
        poses = np.ascontiguousarray(poses, dtype=float)
        rx, tx, delta, dist, walls = sight_lines_kernel(poses, cfg.range_m, *self._padded_walls)
        uniform = dist
        if cfg.dropout_probability > 0.0:
            uniform = self._rng.random(len(rx))
        rx, tx, dy, dx, dist, rx_yaw, sequence, bounds = heard_pairs_kernel(
            rx,
            tx,
            delta,
            dist,
            walls,
            self._reach_table_for(walls),
            cfg.range_m,
            uniform,
            cfg.dropout_probability,
            self._sequence,
            poses[:, 2],
        )
        k = len(rx)
        azimuth = np.arctan2(dy, dx) - rx_yaw
        azimuth = wrap_sum_kernel(azimuth, self._rng.normal(0.0, cfg.azimuth_noise_std_rad, k))
        elevation = self._rng.normal(0.0, cfg.elevation_noise_std_rad, k)
        distance = dist * np.exp(self._rng.normal(0.0, cfg.distance_noise_fraction, k))
        return BearingCycle(
            receivers=rx,
            tags=tx,
            azimuth_rad=azimuth,
            elevation_rad=elevation,
            distance_m=distance,
            sequence=sequence,
            bounds=bounds.tolist(),
        )

    def _reach_table_for(self, walls_crossed: np.ndarray) -> np.ndarray:
        """:meth:`effective_range_m` of 0, 1, ... walls, at least up to the most in
        ``walls_crossed``: the same numpy values as for the counts themselves (numpy's power
        of an element does not depend on the array around it)."""
        top = int(walls_crossed.max(initial=0))
        if top >= len(self._reach_table):
            self._reach_table = self.effective_range_m(np.arange(max(top + 1, 16)))
        return self._reach_table

    def measure_reference(self, poses: np.ndarray) -> list[PeerBearings]:
        """:meth:`measure` with the sight lines in numpy, the reference of the compiled
        :func:`~swarm_sim.raycast_kernel.sight_lines_kernel` (the same reports from the
        same random state)."""
        n = len(poses)
        rx, tx = np.nonzero(~np.eye(n, dtype=bool))
        delta = poses[tx, :2] - poses[rx, :2]
        dist = np.hypot(delta[:, 0], delta[:, 1])
        in_los_range = dist <= self.config.range_m
        walls = np.zeros(len(rx), dtype=int)
        if len(self._walls) and in_los_range.any():
            idx = np.flatnonzero(in_los_range)
            walls[idx] = count_crossings(poses[rx[idx], :2], poses[tx[idx], :2], self._walls)
        return self._cycle(poses, rx, tx, delta, dist, walls).reports()

    def _cycle(
        self,
        poses: np.ndarray,
        rx: np.ndarray,
        tx: np.ndarray,
        delta: np.ndarray,
        dist: np.ndarray,
        walls: np.ndarray,
    ) -> BearingCycle:
        """The reports from the sight lines: receivers, transmitters, offsets [m],
        distances [m] and walls crossed of every ordered pair."""
        cfg = self.config
        n = len(poses)
        in_los_range = dist <= cfg.range_m
        heard = in_los_range & (dist <= self.effective_range_m(walls))
        if cfg.dropout_probability > 0.0:
            heard &= self._rng.random(len(rx)) >= cfg.dropout_probability
        rx, tx, delta, dist = rx[heard], tx[heard], delta[heard], dist[heard]
        k = len(rx)
        azimuth = np.arctan2(delta[:, 1], delta[:, 0]) - poses[rx, 2]
        azimuth = wrap_angle(azimuth + self._rng.normal(0.0, cfg.azimuth_noise_std_rad, k))
        elevation = self._rng.normal(0.0, cfg.elevation_noise_std_rad, k)
        distance = dist * np.exp(self._rng.normal(0.0, cfg.distance_noise_fraction, k))
        self._sequence[rx, tx] = (self._sequence[rx, tx] + 1) % 65536
        sequence = self._sequence[rx, tx]
        azimuth = np.atleast_1d(azimuth)
        # rx is sorted (np.nonzero order), so each receiver's reports are one slice.
        bounds = np.searchsorted(rx, np.arange(n + 1)).tolist()
        return BearingCycle(
            receivers=rx,
            tags=tx,
            azimuth_rad=azimuth,
            elevation_rad=elevation,
            distance_m=distance,
            sequence=sequence,
            bounds=bounds,
        )
