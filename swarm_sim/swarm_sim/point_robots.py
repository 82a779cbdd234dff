"""Point robots on straight legs in an obstacle-free field, sampling a signal: the motion model
of the Bayes-Swarm paper's simulations.

Every robot flies toward its target at the common speed V; a move of a time interval either
reaches the target or stops short of it. Detection is continuous: the first instant any robot
comes within ``detection_radius_m`` of the source along its straight leg ends the run, with
every robot moved to where it was at that instant. Samples are the field's values with
optional additive and relative Gaussian noise (:func:`noisy_samples`).
"""

from __future__ import annotations

import math
from collections.abc import Callable

import numpy as np
from swarm_common.segments import first_entry_fraction

__all__ = ['FieldFunction', 'PointRobotField', 'noisy_samples']

FieldFunction = Callable[[np.ndarray], np.ndarray]


def noisy_samples(
    field: FieldFunction,
    points_m: np.ndarray,
    noise_std: float,
    relative_noise: float,
    rng: np.random.Generator,
) -> np.ndarray:
    """(N,) values of ``field`` at (N, 2) points with Gaussian noise of std
    ``noise_std + relative_noise * |f|`` (no random draw when that is zero everywhere)."""
    values = np.asarray(field(points_m), dtype=float)
    std = noise_std + relative_noise * np.abs(values)
    if np.any(std > 0.0):
        values = values + std * rng.standard_normal(values.shape)
    return values


class PointRobotField:
    """N point robots in a signal field: positions, straight-leg moves, samples, detection.

    Attributes:
        starts: (N, 2) start positions [m].
        positions: (N, 2) current positions [m].
        trajectories: per robot, the positions recorded by the caller (the start first).
        found_time_s: time of the detection [s] (NaN before).
        finder: index of the robot that reached the source first (-1 before).
    """

    def __init__(
        self,
        starts_m: np.ndarray,
        field: FieldFunction,
        source_m: np.ndarray,
        detection_radius_m: float,
        rng: np.random.Generator,
        *,
        noise_std: float = 0.0,
        relative_noise: float = 0.0,
    ) -> None:
        self.field = field
        self.source_m = source_m
        self.detection_radius_m = detection_radius_m
        self.noise_std = noise_std
        self.relative_noise = relative_noise
        self.rng = rng
        self.starts = np.asarray(starts_m)
        self.positions = self.starts.copy()
        self.trajectories: list[list[np.ndarray]] = [[p.copy()] for p in self.starts]
        self.found_time_s = math.nan
        self.finder = -1

    def sample(self, points_m: np.ndarray) -> np.ndarray:
        """(N,) noisy field values at (N, 2) points."""
        return noisy_samples(self.field, points_m, self.noise_std, self.relative_noise, self.rng)

    def move(self, targets_m: np.ndarray, t0_s: float, t1_s: float, speed_mps: float) -> bool:
        """Move every robot toward its target for t1 - t0 seconds; True on detection."""
        budget = speed_mps * (t1_s - t0_s)
        best: tuple[float, int] | None = None
        new_positions = self.positions.copy()
        for i, (p, target) in enumerate(zip(self.positions, targets_m, strict=True)):
            delta = target - p
            dist = float(np.hypot(*delta))
            if dist <= 0.0 or budget <= 0.0:
                end = p
            else:
                end = target if dist <= budget + 1e-12 else p + delta * (budget / dist)
            frac = first_entry_fraction(p, end, self.source_m, self.detection_radius_m)
            if frac is not None:
                travelled = frac * float(np.hypot(*(end - p)))
                t_hit = t0_s + travelled / speed_mps
                if best is None or t_hit < best[0]:
                    best = (t_hit, i)
            new_positions[i] = end
        if best is not None:
            self.found_time_s, self.finder = best
            hit_budget = speed_mps * (best[0] - t0_s)
            for i, (p, target) in enumerate(zip(self.positions, targets_m, strict=True)):
                delta = target - p
                dist = float(np.hypot(*delta))
                step = min(dist, hit_budget)
                self.positions[i] = p if dist <= 0 else p + delta * (step / dist)
            return True
        self.positions = new_positions
        return False
