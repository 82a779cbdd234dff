"""Scent field: ethanol puffs that a pump deposits on the floor, spreading and decaying.

Each puff is a 2D Gaussian of ethanol concentration whose width grows from
``initial_spread_m`` towards ``final_spread_m`` (the liquid spreads and its vapour plume
widens, then the deposit settles) and whose mass evaporates with time constant
``decay_time_constant_s``. Concentration [ppm] at a point is the sum over puffs:

    c(p, t) = sum_k m_k exp(-age_k / tau_decay) / (2 pi s_k^2) exp(-|p - p_k|^2 / (2 s_k^2))
    s_k^2   = s0^2 + (s1^2 - s0^2) (1 - exp(-age_k / tau_spread))

with m_k in ppm m^2. Vapour does not pass through walls: a puff does not contribute at a
point when the straight path between them crosses a wall. The paper's scent marks never
decay; the default decay time is longer than a mission so that trails laid at the start are
still found at the end, while the spread makes a chain of puffs read as one trail.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from swarm_common.params import parameter

from swarm_sim.errors import ConfigurationError
from swarm_sim.geometry import WallGrid, as_segments
from swarm_sim.scent_kernel import (
    open_puff_pairs,
    puff_exponents,
    puff_spread,
    puff_sum,
    pump_release_kernel,
)

__all__ = ['PumpDepositor', 'ScentConfig', 'ScentField']


@dataclass(frozen=True)
class ScentConfig:
    """Parameters of the scent field.

    Attributes:
        deposit_rate_ppm_m2_per_s: ethanol released while the pump runs [ppm m^2 / s].
        deposit_period_s: pump-on time gathered into one puff [s]; a shorter pulse still
            leaves its (smaller) puff when the pump stops.
        initial_spread_m: standard deviation of a fresh puff [m].
        final_spread_m: standard deviation a puff settles at [m].
        spread_time_constant_s: time constant of the spreading [s].
        decay_time_constant_s: evaporation time constant of a puff's mass [s].
        cutoff_sigmas: contributions farther than this many final spreads are ignored.
        walls_block: when True, vapour does not cross walls.
    """

    deposit_rate_ppm_m2_per_s: float = parameter(
        80.0, 'Ethanol released while a pump runs.', unit='ppm m^2/s', ge=0.0
    )
    deposit_period_s: float = 0.25
    initial_spread_m: float = 0.08
    final_spread_m: float = parameter(0.15, 'Settled puff standard deviation.', unit='m', gt=0.0)
    spread_time_constant_s: float = 10.0
    decay_time_constant_s: float = parameter(1800.0, 'Puff evaporation.', unit='s', gt=0.0)
    cutoff_sigmas: float = 3.0
    walls_block: bool = parameter(True, 'True: vapour does not cross walls.')

    def __post_init__(self) -> None:
        positive = (
            'deposit_rate_ppm_m2_per_s',
            'deposit_period_s',
            'initial_spread_m',
            'spread_time_constant_s',
            'decay_time_constant_s',
            'cutoff_sigmas',
        )
        for name in positive:
            value = getattr(self, name)
            if not (math.isfinite(value) and value > 0.0):
                msg = f'{name} must be a positive finite number, got {value!r}'
                raise ConfigurationError(msg)
        if self.final_spread_m < self.initial_spread_m:
            msg = (
                f'final_spread_m ({self.final_spread_m}) must be >= initial_spread_m '
                f'({self.initial_spread_m})'
            )
            raise ConfigurationError(msg)


class ScentField:
    """All puffs deposited so far, and the concentration they produce."""

    def __init__(self, config: ScentConfig, walls: np.ndarray | None = None) -> None:
        self.config = config
        self._walls = as_segments(walls if walls is not None else np.zeros((0, 2, 2)))
        reach = config.cutoff_sigmas * config.final_spread_m
        self._cutoff2 = reach**2
        self._grid = WallGrid(self._walls, cell_m=0.5, reach_m=reach) if len(self._walls) else None
        self._kernel_grid = (
            self._grid or WallGrid(self._walls, cell_m=0.5, reach_m=reach)
        ).kernel_arguments()
        self._xy = np.zeros((256, 2))
        self._time_s = np.zeros(256)
        self._mass = np.zeros(256)
        self._count = 0

    @property
    def num_puffs(self) -> int:
        """Number of puffs deposited so far."""
        return self._count

    @property
    def puffs(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Copies of the puffs: (P, 2) positions [m], (P,) deposit times [s], (P,) masses."""
        n = self._count
        return self._xy[:n].copy(), self._time_s[:n].copy(), self._mass[:n].copy()

    def deposit(self, xy: np.ndarray, time_s: float, mass_ppm_m2: np.ndarray) -> None:
        """Add puffs at (K, 2) positions [m] with (K,) masses [ppm m^2] at ``time_s``."""
        xy = np.atleast_2d(np.asarray(xy, dtype=float))
        mass = np.broadcast_to(np.asarray(mass_ppm_m2, dtype=float), (len(xy),))
        keep = np.isfinite(xy).all(axis=1) & (mass > 0.0)
        self._append(xy[keep], time_s, mass[keep])

    def _append(self, xy: np.ndarray, time_s: float, mass: np.ndarray) -> None:
        """Add (K, 2) puff positions [m] and (K,) masses (finite and positive) at ``time_s``."""
        k = len(xy)
        if k == 0:
            return
        if self._count + k > len(self._mass):
            size = max(2 * len(self._mass), self._count + k)
            self._xy = np.resize(self._xy, (size, 2))
            self._time_s = np.resize(self._time_s, size)
            self._mass = np.resize(self._mass, size)
        sl = slice(self._count, self._count + k)
        self._xy[sl] = xy
        self._time_s[sl] = time_s
        self._mass[sl] = mass
        self._count += k

    def spread_m(self, age_s: np.ndarray) -> np.ndarray:
        """Standard deviation [m] of puffs of the given ages [s]."""
        cfg = self.config
        growth = 1.0 - np.exp(-np.maximum(age_s, 0.0) / cfg.spread_time_constant_s)
        var = cfg.initial_spread_m**2 + (cfg.final_spread_m**2 - cfg.initial_spread_m**2) * growth
        return np.sqrt(var)

    def concentration(self, points: np.ndarray, time_s: float) -> np.ndarray:
        """Ethanol concentration [ppm] at (K, 2) points at ``time_s``; returns (K,).

        The puffs that reach each point come from the compiled
        :func:`swarm_sim.scent_kernel.open_puff_pairs`; the result equals
        :meth:`concentration_reference` bit for bit.
        """
        points = np.atleast_2d(np.asarray(points, dtype=float))
        n = self._count
        if n == 0:
            return np.zeros(len(points))
        q_idx, p_idx, d2 = open_puff_pairs(
            np.ascontiguousarray(points),
            self._xy[:n],
            self._time_s[:n],
            float(time_s),
            bool(self._time_s[n - 1] > time_s),
            self._cutoff2,
            self.config.walls_block and self._grid is not None,
            self._kernel_grid,
        )
        if len(q_idx) == 0:
            return np.zeros(len(points))
        # _puff_values and the sums per sensor, compiled around numpy's exp.
        cfg = self.config
        count = len(p_idx)
        exponents = np.exp(
            puff_exponents(
                p_idx,
                self._time_s,
                float(time_s),
                cfg.spread_time_constant_s,
                cfg.decay_time_constant_s,
            )
        )
        sigma2, gauss = puff_spread(
            exponents[:count],
            cfg.initial_spread_m**2,
            cfg.final_spread_m**2 - cfg.initial_spread_m**2,
            d2,
        )
        return puff_sum(
            q_idx,
            p_idx,
            self._mass,
            exponents[count:],
            sigma2,
            np.exp(gauss),
            2.0 * math.pi,
            len(points),
        )

    def _puff_values(self, p_idx: np.ndarray, d2: np.ndarray, time_s: float) -> np.ndarray:
        """Contributions [ppm] of the puffs ``p_idx`` at squared distances ``d2`` [m^2] (the
        reference's; :meth:`concentration` computes the same in compiled code)."""
        cfg = self.config
        a = time_s - self._time_s[p_idx]
        sigma2 = self.spread_m(a) ** 2
        return (
            self._mass[p_idx]
            * np.exp(-a / cfg.decay_time_constant_s)
            / (2.0 * math.pi * sigma2)
            * np.exp(-d2 / (2.0 * sigma2))
        )

    def concentration_reference(self, points: np.ndarray, time_s: float) -> np.ndarray:
        """:meth:`concentration` in numpy, the reference of the compiled pair search."""
        points = np.atleast_2d(np.asarray(points, dtype=float))
        n = self._count
        if n == 0:
            return np.zeros(len(points))
        cfg = self.config
        xy = self._xy[:n]
        dx = points[:, 0, None] - xy[:, 0]
        dy = points[:, 1, None] - xy[:, 1]
        d2 = dx * dx
        d2 += dy * dy
        near = d2 <= self._cutoff2
        if self._time_s[n - 1] > time_s:
            # Puffs are deposited in time order; only a query of the past sees later ones.
            near &= self._time_s[:n] <= time_s
        q_idx, p_idx = np.nonzero(near)
        if len(q_idx) == 0:
            return np.zeros(len(points))
        if cfg.walls_block and self._grid is not None:
            near_walls = self._grid.candidates(points)[q_idx]
            crossed = self._grid.count_crossings(points[q_idx], xy[p_idx], near_walls)
            open_path = crossed == 0
            q_idx, p_idx = q_idx[open_path], p_idx[open_path]
        value = self._puff_values(p_idx, d2[q_idx, p_idx], time_s)
        # Summed in index order, like np.add.at: the same float result.
        return np.bincount(q_idx, weights=value, minlength=len(points))


class PumpDepositor:
    """Turns per-robot pump on/off states into puffs, one per ``deposit_period_s`` of pumping."""

    def __init__(self, field: ScentField, num_robots: int) -> None:
        self._field = field
        self._on_time_s = np.zeros(num_robots)

    def busy(self, pump_on: np.ndarray) -> bool:
        """False when a :meth:`step` with these pump states would do nothing (no pump runs
        and no puff is pending), so that the caller may skip it."""
        # count_nonzero: what any() tests, without its Python-level dispatch.
        return bool(np.count_nonzero(pump_on) or np.count_nonzero(self._on_time_s))

    def step(self, pump_on: np.ndarray, nozzle_xy: np.ndarray, time_s: float, dt_s: float) -> None:
        """Account ``dt_s`` seconds of pumping and deposit the puffs that are complete.

        Args:
            pump_on: (N,) bool, pump running during the step.
            nozzle_xy: (N, 2) nozzle positions [m] at the end of the step.
            time_s: time at the end of the step [s].
            dt_s: step length [s].
        """
        cfg = self._field.config
        xy, mass = pump_release_kernel(
            self._on_time_s,
            np.asarray(pump_on, dtype=bool),
            np.asarray(nozzle_xy, dtype=float),
            float(dt_s),
            cfg.deposit_period_s - 1e-9,
            float(cfg.deposit_rate_ppm_m2_per_s),
        )
        # What deposit() adds (the kernel keeps only finite places and positive masses).
        self._field._append(xy, time_s, mass)
