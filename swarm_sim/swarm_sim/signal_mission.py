"""Signal-field mission model (Bayes-Swarm-P study): sampling, detection and tau, ROS-free.

:class:`SignalMissionModel` samples the case's field at every robot's true position on the
observation clock (t = k / f_Hz), adds optional Gaussian noise, and detects the source: a
robot within eps of it ends the mission, as does T_max. It also computes tau (Eq. 12) from
the true source and the finder's start position. Detection is checked on the straight
segment between two steps, so it does not depend on the physics rate. The sim bridge's
sim bridge's signal extension publishes what it computes.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from swarm_common.segments import first_entry_fraction

from swarm_sim.point_robots import noisy_samples
from swarm_sim.signal_fields import SignalCase

__all__ = ['SignalMissionModel', 'SignalSampleBatch']

_EPS_T = 1e-9


@dataclass(frozen=True)
class SignalSampleBatch:
    """Samples of one observation tick: time [s] and (N,) values in robot order."""

    time_s: float
    values: np.ndarray


class SignalMissionModel:
    """Sampling, detection and tau of a signal-field mission (no ROS)."""

    def __init__(
        self,
        case: SignalCase,
        *,
        noise_std: float = 0.0,
        relative_noise: float = 0.0,
        seed: int = 0,
        max_mission_time_s: float | None = None,
    ) -> None:
        if noise_std < 0.0 or relative_noise < 0.0:
            msg = 'noise_std and relative_noise must be >= 0'
            raise ValueError(msg)
        self.case = case
        self.noise_std = noise_std
        self.relative_noise = relative_noise
        self.max_mission_time_s = (
            case.max_mission_time_s if max_mission_time_s is None else max_mission_time_s
        )
        self._rng = np.random.default_rng(seed)
        self._period_s = 1.0 / case.observation_rate_hz
        self._next_tick = 0
        self._last_positions: np.ndarray | None = None
        self._last_time_s = 0.0
        self.starts: np.ndarray | None = None
        self.found_time_s = math.nan
        self.finder = -1
        self.time_s = 0.0

    @property
    def found(self) -> bool:
        return self.finder >= 0

    @property
    def done(self) -> bool:
        return self.found or self.time_s >= self.max_mission_time_s - _EPS_T

    def tau(self) -> float:
        """Relative completion time (Eq. 12) of the finder, NaN if not found."""
        if not self.found or self.starts is None:
            return math.nan
        ideal = self.case.ideal_time_s(self.starts[self.finder])
        return (self.found_time_s - ideal) / ideal

    def sample(self, positions_m: np.ndarray) -> np.ndarray:
        """(N,) noisy field values at (N, 2) positions."""
        return noisy_samples(
            self.case.field, positions_m, self.noise_std, self.relative_noise, self._rng
        )

    def step(self, time_s: float, positions_m: np.ndarray) -> SignalSampleBatch | None:
        """Advance to ``time_s`` with the robots at (N, 2) positions; samples if one is due."""
        pos = np.asarray(positions_m, dtype=float)[:, :2]
        if self.starts is None:
            self.starts = pos.copy()
            self._last_positions = pos.copy()
            self._last_time_s = time_s
        if not self.found:
            self._detect(time_s, pos)
        self._last_positions = pos.copy()
        self._last_time_s = time_s
        self.time_s = time_s
        if time_s + _EPS_T >= self._next_tick * self._period_s:
            self._next_tick = math.floor(time_s / self._period_s + _EPS_T) + 1
            return SignalSampleBatch(time_s, self.sample(pos))
        return None

    def _detect(self, time_s: float, pos: np.ndarray) -> None:
        best: tuple[float, int] | None = None
        for i, (p0, p1) in enumerate(zip(self._last_positions, pos, strict=True)):
            s = first_entry_fraction(p0, p1, self.case.source_m, self.case.detection_radius_m)
            if s is not None:
                t_hit = self._last_time_s + s * (time_s - self._last_time_s)
                if best is None or t_hit < best[0]:
                    best = (t_hit, i)
        if best is not None:
            self.found_time_s, self.finder = best
