"""RPLidar A1 model: 360 one-degree bins, 0.15-12 m, range noise and dropouts.

Figures from the A1 datasheet (docs/hardware.md, "Sensor figures"): range 0.15-12 m, angular
resolution about 1 degree, 5.5 Hz rotation in standard mode, distance resolution better than
1 % of the range.
Following REP 117 as the RPLidar driver does: no return within range_max_m and dropped
samples are ``+inf``, returns closer than range_min_m are ``-inf``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Protocol, cast

import numpy as np
from swarm_common.params import parameter

from swarm_sim.errors import ConfigurationError
from swarm_sim.raycast_kernel import EXACT, NO_RETURN, horizon_noise_kernel, lidar_noise_kernel

__all__ = ['LidarConfig', 'LidarModel', 'NearRangeCaster', 'RangeCaster']

# A near cast (LidarModel.measure with a horizon) computes the ranges exactly up to the cut
# from which a ray comes within the horizon only with a noise draw below this many standard
# deviations (a chance of about 1e-15 per ray; its robot is then cast in full).
_CUT_NOISE_SIGMAS = 8.0


class RangeCaster(Protocol):
    """Exact ranges of every bin from every robot: :class:`swarm_sim.geometry.RayCaster`,
    or a physics backend (:class:`swarm_sim.physics.PhysicsBackend`)."""

    num_bins: int

    def scan(self, poses: np.ndarray, max_range_m: float) -> np.ndarray:
        """(N, num_bins) ranges [m] from (N, 3) poses; ``inf`` beyond ``max_range_m``."""
        ...


class NearRangeCaster(RangeCaster, Protocol):
    """A caster that can also give only the ranges up to a cut
    (:meth:`swarm_sim.geometry.RayCaster.scan_near`)."""

    def scan_near(
        self, poses: np.ndarray, max_range_m: float, cut_m: float
    ) -> tuple[np.ndarray, np.ndarray]:
        """(N, num_bins) ranges [m], exact up to ``cut_m``, and the bins' kinds."""
        ...


@dataclass(frozen=True)
class LidarConfig:
    """Parameters of the simulated 2D lidar.

    Attributes:
        num_bins: samples per revolution (360 = one per degree).
        range_min_m: shortest measurable range [m]; closer returns read ``-inf``.
        range_max_m: longest measurable range [m]; no return beyond reads ``inf``.
        rate_hz: revolutions per second (A1 standard mode: 5.5 Hz).
        range_noise_fraction: standard deviation of the range noise as a fraction of the range.
        range_noise_min_m: floor of that standard deviation [m].
        dropout_probability: chance that a sample is lost (reads ``inf``).
    """

    num_bins: int = parameter(360, 'Lidar samples per revolution.', ge=1, name='scan_bins')
    range_min_m: float = parameter(
        0.15, 'Shortest lidar range; closer reads inf.', unit='m', ge=0.0
    )
    range_max_m: float = parameter(
        12.0, 'Longest lidar range; farther reads inf.', unit='m', gt=0.0
    )
    rate_hz: float = parameter(5.5, 'Lidar revolutions per second (A1: 5.5).', unit='Hz', gt=0.0)
    range_noise_fraction: float = parameter(
        0.01, 'Range noise std / range.', ge=0.0, name='scan_noise_fraction'
    )
    range_noise_min_m: float = 0.002
    dropout_probability: float = parameter(0.005, 'Chance a sample is lost.', ge=0.0, le=1.0)

    def __post_init__(self) -> None:
        if self.num_bins < 4:
            msg = f'num_bins must be >= 4, got {self.num_bins}'
            raise ConfigurationError(msg)
        if not (0.0 <= self.range_min_m < self.range_max_m and math.isfinite(self.range_max_m)):
            msg = f'need 0 <= range_min_m < range_max_m, got {self.range_min_m}, {self.range_max_m}'
            raise ConfigurationError(msg)
        if not self.rate_hz > 0.0:
            msg = f'rate_hz must be positive, got {self.rate_hz}'
            raise ConfigurationError(msg)
        if self.range_noise_fraction < 0.0 or self.range_noise_min_m < 0.0:
            raise ConfigurationError('range noise must be >= 0')
        if not 0.0 <= self.dropout_probability < 1.0:
            msg = f'dropout_probability must be in [0, 1), got {self.dropout_probability}'
            raise ConfigurationError(msg)

    @property
    def angle_increment_rad(self) -> float:
        """Angle between consecutive bins [rad]."""
        return 2.0 * math.pi / self.num_bins


class LidarModel:
    """Noisy 360-degree scans of every robot from exact ray-cast ranges."""

    def __init__(self, caster: RangeCaster, config: LidarConfig, rng: np.random.Generator) -> None:
        if caster.num_bins != config.num_bins:
            msg = f'caster has {caster.num_bins} bins, config {config.num_bins}'
            raise ConfigurationError(msg)
        self.config = config
        self._caster = caster
        self._rng = rng

    def measure(self, poses: np.ndarray, horizon_m: float | None = None) -> np.ndarray:
        """Scan from every robot.

        Args:
            poses: (N, 3) true x [m], y [m], yaw [rad].
            horizon_m: when given, ranges beyond it read ``inf``: the readings of the full
                scan (None) that lie within it, the others ``inf``. A caster that can cast
                near rays only (:class:`NearRangeCaster`) then skips the far walls; the
                random draws are the same either way.

        Returns:
            (N, num_bins) ranges [m]; bin k at robot-frame angle -pi + k * angle_increment.
        """
        cfg = self.config
        if horizon_m is not None:
            cut_m = self._cut_m(horizon_m)
            if cut_m is not None and hasattr(self._caster, 'scan_near'):
                return self._measure_near(poses, float(horizon_m), cut_m)
        exact = self._caster.scan(poses, cfg.range_max_m)
        # The same draws as measure_reference, in the same order (``standard_normal`` gives
        # ``normal(0.0, 1.0)``'s values from the same stream, without its per-element scaling).
        normal = self._rng.standard_normal(int(np.count_nonzero(np.isfinite(exact))))
        uniform = self._rng.random(exact.shape) if cfg.dropout_probability > 0.0 else exact
        noisy = lidar_noise_kernel(
            exact,
            normal,
            uniform,
            cfg.range_noise_fraction,
            cfg.range_noise_min_m,
            cfg.dropout_probability,
            cfg.range_min_m,
            cfg.range_max_m,
        )
        if horizon_m is not None:
            noisy[noisy > horizon_m] = np.inf
        return noisy

    def _cut_m(self, horizon_m: float) -> float | None:
        """The cut of a near cast for ``horizon_m`` [m]: from it, a range comes within the
        horizon only with a noise draw below -:data:`_CUT_NOISE_SIGMAS`. None when a near
        cast gains nothing (the cut reaches the maximum range, or the noise is too wide)."""
        cfg = self.config
        shrink = 1.0 - _CUT_NOISE_SIGMAS * cfg.range_noise_fraction
        if not (horizon_m > 0.0 and shrink > 0.0):
            return None
        # Below range_min a range reads -inf, not inf.
        floor_m = max(horizon_m, cfg.range_min_m)
        cut_m = (floor_m + _CUT_NOISE_SIGMAS * cfg.range_noise_min_m) / shrink
        return cut_m if cut_m < cfg.range_max_m else None

    def _measure_near(self, poses: np.ndarray, horizon_m: float, cut_m: float) -> np.ndarray:
        """:meth:`measure` with a horizon, from a near cast up to ``cut_m``: the rays
        beyond the cut draw their noise as in the full scan and read ``inf`` when even their
        nearest possible noisy range lies beyond the horizon; a robot where that is not so
        (an extreme draw) is cast in full."""
        cfg = self.config
        caster = cast(NearRangeCaster, self._caster)
        exact, kind = caster.scan_near(poses, cfg.range_max_m, cut_m)
        normal = self._rng.standard_normal(int(np.count_nonzero(kind)))
        uniform = self._rng.random(exact.shape) if cfg.dropout_probability > 0.0 else exact
        redo = np.zeros(len(exact), dtype=bool)
        noisy = self._near_noise(exact, kind, normal, uniform, horizon_m, cut_m, redo)
        if np.count_nonzero(redo):  # redo.any(), without its Python-level dispatch
            full = caster.scan(poses, cfg.range_max_m)
            exact[redo] = full[redo]
            kind[redo] = np.where(np.isfinite(full[redo]), EXACT, NO_RETURN)
            noisy = self._near_noise(exact, kind, normal, uniform, horizon_m, cut_m, redo)
        return noisy

    def _near_noise(
        self,
        exact: np.ndarray,
        kind: np.ndarray,
        normal: np.ndarray,
        uniform: np.ndarray,
        horizon_m: float,
        cut_m: float,
        redo: np.ndarray,
    ) -> np.ndarray:
        cfg = self.config
        redo[:] = False
        return horizon_noise_kernel(
            exact,
            kind.ravel(),
            normal,
            uniform,
            cfg.range_noise_fraction,
            cfg.range_noise_min_m,
            cfg.dropout_probability,
            cfg.range_min_m,
            cfg.range_max_m,
            horizon_m,
            cut_m,
            redo,
        )

    def measure_reference(self, poses: np.ndarray) -> np.ndarray:
        """:meth:`measure` in numpy, the reference of the compiled noise kernel (the same
        ranges from the same random state)."""
        cfg = self.config
        exact = self._caster.scan(poses, cfg.range_max_m)
        noise_std = np.maximum(cfg.range_noise_fraction * exact, cfg.range_noise_min_m)
        finite = np.isfinite(exact)
        noisy = exact.copy()
        noisy[finite] += self._rng.normal(0.0, 1.0, int(finite.sum())) * noise_std[finite]
        if cfg.dropout_probability > 0.0:
            noisy[self._rng.random(noisy.shape) < cfg.dropout_probability] = np.inf
        noisy[noisy > cfg.range_max_m] = np.inf
        noisy[noisy < cfg.range_min_m] = -np.inf
        return noisy
