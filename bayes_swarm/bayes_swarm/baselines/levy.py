"""Levy walk search (paper Table 12).

Each leg draws a step from a Pareto law ``l = l0 u^(-1 / (mu - 1))`` (re-drawn above the
truncation) and a heading, uniform for the plain walk or wrapped-Cauchy around the direction
of rising signal for Levy-taxis. A leg that would leave the arena ends at the boundary and
the next heading is drawn from the inward half-plane.
"""

from __future__ import annotations

import math

import numpy as np

from bayes_swarm.settings import Arena, LevyConfig

__all__ = ['LevyWalk', 'pareto_step', 'wrapped_cauchy']

_MAX_REDRAWS = 1000


def pareto_step(u: float, mu: float, min_step_m: float) -> float:
    """Inverse-transform Pareto sample for u in (0, 1]: l0 u^(-1/(mu - 1)) [m]."""
    return min_step_m * u ** (-1.0 / (mu - 1.0))


def wrapped_cauchy(u: float, mean_rad: float, concentration: float) -> float:
    """Wrapped-Cauchy heading for u in (0, 1) around ``mean_rad`` with concentration rho."""
    spread = (1.0 - concentration) / (1.0 + concentration)
    return mean_rad + 2.0 * math.atan(spread * math.tan(math.pi * (u - 0.5)))


class LevyWalk:
    """Waypoint generator of one Levy-walking robot."""

    def __init__(self, config: LevyConfig, arena: Arena, seed: int | None = None) -> None:
        self._cfg = config
        self._arena = arena
        self._rng = np.random.default_rng(seed)
        self._max_step_m = config.max_step_m or arena.diagonal_m
        self._last_start: np.ndarray | None = None
        self._last_signal_start: float | None = None

    def draw_step_m(self) -> float:
        """One truncated Pareto step length [m]."""
        for _ in range(_MAX_REDRAWS):
            u = 1.0 - self._rng.uniform()  # (0, 1]
            step = pareto_step(u, self._cfg.mu, self._cfg.min_step_m)
            if step <= self._max_step_m:
                return step
        return self._max_step_m

    def _heading(self, position: np.ndarray, signal: float | None) -> float:
        cfg = self._cfg
        if cfg.taxis and self._last_start is not None and signal is not None:
            moved = position - self._last_start
            if np.hypot(*moved) > 0.0 and self._last_signal_start is not None:
                mean = math.atan2(moved[1], moved[0])
                if signal < self._last_signal_start:
                    mean += math.pi
                return wrapped_cauchy(self._rng.uniform(), mean, cfg.turning_concentration)
        return self._rng.uniform(0.0, 2.0 * math.pi)

    def _inward_normal(self, position: np.ndarray) -> np.ndarray:
        a = self._arena
        normal = np.zeros(2)
        tol = 1e-9
        normal[0] += float(position[0] <= a.x_min_m + tol) - float(position[0] >= a.x_max_m - tol)
        normal[1] += float(position[1] <= a.y_min_m + tol) - float(position[1] >= a.y_max_m - tol)
        return normal

    def next_waypoint(self, position_m: np.ndarray, signal: float | None = None) -> np.ndarray:
        """Next leg end (2,) [m] from ``position_m``; ``signal`` is the latest sample."""
        position = np.asarray(position_m, dtype=float)
        step = self.draw_step_m()
        normal = self._inward_normal(position)
        heading = self._heading(position, signal)
        for _ in range(_MAX_REDRAWS):
            direction = np.array([math.cos(heading), math.sin(heading)])
            if not np.any(normal) or direction @ normal > 0.0:
                break
            heading = self._rng.uniform(0.0, 2.0 * math.pi)
        self._last_start = position.copy()
        self._last_signal_start = signal
        return self._clip_ray(position, direction, step)

    def _clip_ray(self, start: np.ndarray, direction: np.ndarray, length: float) -> np.ndarray:
        """End of the ray start + t direction, t <= length, stopped at the arena boundary."""
        a = self._arena
        t_max = length
        for axis, lo, hi in ((0, a.x_min_m, a.x_max_m), (1, a.y_min_m, a.y_max_m)):
            d = direction[axis]
            if d > 1e-12:
                t_max = min(t_max, (hi - start[axis]) / d)
            elif d < -1e-12:
                t_max = min(t_max, (lo - start[axis]) / d)
        return a.clip(start + max(t_max, 0.0) * direction)
