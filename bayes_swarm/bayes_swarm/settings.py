"""Frozen configuration records of the planners, with the papers' values as defaults.

Every field carries its unit in its name. ``validate()`` is called from ``__post_init__`` so a
record that exists is a valid one; invalid values raise :class:`~bayes_swarm.errors.ConfigError`
with the offending field named.

Defaults follow the Bayes-Swarm-P paper (Case 1 settings, Table 3 caption and Sec. 3.1) and, for
the baselines, Tables 11 and 12 of the paper (docs/bayes_swarm.md). The authors' code departs
from the paper in a few places; those departures are available as switches, all off by default
(see docs/bayes_swarm.md):

* ``authors_negated_m``: M replaced by the negated GP maximum, which makes the penalty inert.
* ``authors_origin_paths``: path points generated from the origin instead of the path start.
* ``authors_floor_downsampling``: downsampling factor floor(n / N_max) on x-sorted data.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Literal

import numpy as np
from swarm_common.params import parameter, section

from bayes_swarm.errors import ConfigError

__all__ = [
    'COBYLA_LIBRARIES',
    'INNER_OPTIMIZERS',
    'OUTER_OPTIMIZERS',
    'Arena',
    'BayesSwarmConfig',
    'ExhaustiveConfig',
    'GlowwormConfig',
    'GpConfig',
    'LevyConfig',
]

OUTER_OPTIMIZERS = ('grid', 'cobyla', 'pso')
INNER_OPTIMIZERS = ('newton', 'lbfgsb')
COBYLA_LIBRARIES = ('nlopt', 'scipy')
OuterOptimizer = Literal['grid', 'cobyla', 'pso']


def _require(condition: bool, message: str) -> None:
    if not condition:
        raise ConfigError(message)


def _finite(name: str, value: float) -> None:
    _require(math.isfinite(value), f'{name} must be finite, got {value!r}')


def _positive(name: str, value: float) -> None:
    _finite(name, value)
    _require(value > 0.0, f'{name} must be > 0, got {value!r}')


@dataclass(frozen=True)
class Arena:
    """Axis-aligned rectangular search area in the world frame [m]."""

    x_min_m: float = parameter(description='arena lower x bound', unit='m')
    x_max_m: float = parameter(description='arena upper x bound', unit='m')
    y_min_m: float = parameter(description='arena lower y bound', unit='m')
    y_max_m: float = parameter(description='arena upper y bound', unit='m')

    def __post_init__(self) -> None:
        for name in ('x_min_m', 'x_max_m', 'y_min_m', 'y_max_m'):
            _finite(name, getattr(self, name))
        _require(self.x_max_m > self.x_min_m, 'arena x_max_m must exceed x_min_m')
        _require(self.y_max_m > self.y_min_m, 'arena y_max_m must exceed y_min_m')

    @property
    def lower(self) -> np.ndarray:
        """(2,) array of the lower-left corner [m]."""
        return np.array([self.x_min_m, self.y_min_m])

    @property
    def upper(self) -> np.ndarray:
        """(2,) array of the upper-right corner [m]."""
        return np.array([self.x_max_m, self.y_max_m])

    @property
    def diagonal_m(self) -> float:
        """Length of the arena diagonal [m]."""
        return float(np.hypot(self.x_max_m - self.x_min_m, self.y_max_m - self.y_min_m))

    def clip(self, points: np.ndarray) -> np.ndarray:
        """Clip (..., 2) points into the arena."""
        return np.clip(points, self.lower, self.upper)

    def contains_point(self, x_m: float, y_m: float, tolerance_m: float = 1e-9) -> bool:
        """One point inside the arena (boundary included); :meth:`contains` for one point."""
        return (
            self.x_min_m - tolerance_m <= x_m <= self.x_max_m + tolerance_m
            and self.y_min_m - tolerance_m <= y_m <= self.y_max_m + tolerance_m
        )

    def contains(self, points: np.ndarray, tolerance_m: float = 1e-9) -> np.ndarray:
        """Boolean mask (...,) of points inside the arena (boundary included)."""
        pts = np.asarray(points, dtype=float)
        return np.all((pts >= self.lower - tolerance_m) & (pts <= self.upper + tolerance_m), -1)


@dataclass(frozen=True)
class GpConfig:
    """Gaussian-process belief settings (paper Appendix A; authors' code, REFERENCE §1.2).

    The kernel is ``signal_variance * exp(-|x - x'|^2 / (2 length_scale^2))`` plus
    ``noise_std^2`` on the diagonal. Hyperparameters are fitted by maximum marginal likelihood
    within the bounds, at every decision as in the paper (``refit_growth_factor`` 1; a larger
    factor refits only once the data set has grown by it since the last fit), on at most
    ``max_fit_points`` samples, with at most ``max_fit_iterations`` likelihood evaluations.
    """

    noise_std: float = parameter(1e-3, 'GP observation noise std (signal / signal_scale)', gt=0.0)
    length_scale_bounds_m: tuple[float, float] = (1e-3, 500.0)
    signal_variance_bounds: tuple[float, float] = (1e-5, 1e5)
    initial_length_scale_m: float = 1.0
    initial_signal_variance: float = 1.0
    max_fit_points: int = 80
    max_fit_iterations: int = 30
    refit_growth_factor: float = 1.0
    max_jitter: float = 1e-2

    def __post_init__(self) -> None:
        _positive('noise_std', self.noise_std)
        lo, hi = self.length_scale_bounds_m
        _require(0.0 < lo < hi, f'length_scale_bounds_m must satisfy 0 < lo < hi, got {lo}, {hi}')
        lo, hi = self.signal_variance_bounds
        _require(0.0 < lo < hi, f'signal_variance_bounds must satisfy 0 < lo < hi, got {lo}, {hi}')
        _positive('initial_length_scale_m', self.initial_length_scale_m)
        _positive('initial_signal_variance', self.initial_signal_variance)
        _require(self.max_fit_points >= 2, 'max_fit_points must be >= 2')
        _require(self.max_fit_iterations >= 1, 'max_fit_iterations must be >= 1')
        _require(self.refit_growth_factor >= 1.0, 'refit_growth_factor must be >= 1')
        _positive('max_jitter', self.max_jitter)


@dataclass(frozen=True)
class BayesSwarmConfig:
    """Settings of one robot's Bayes-Swarm-P (or -O) planner.

    Defaults are the paper's Case 1 (V = 0.1 m/s, T = 10 s, eps = 0.05 m, T_max = 100 s,
    M = 1.2, L = 2, delta theta = 90 deg, f = 1 Hz, N_max = 1000, l_robot = 0.1 m).
    ``robot_index`` is 0-based; the first decision uses r = robot_index + 1 as in Algorithm 1.
    ``fixed_alpha`` replaces Algorithm 2 by a constant (the paper's 'alpha = 1' variant).
    ``signal_scale`` is the unit of the belief: samples are divided by it before the GP sees
    them, so M, L (and the GP noise std) are in units of the signal over ``signal_scale``;
    the avalanche case reads the paper's M = 1.2 and L = 2 for the beacon signal over its
    known peak (47).
    ``dimensionless_acquisition`` (not in the paper) measures Omega's distances in leg lengths
    V T and divides Sigma by the prior std times V T, so both terms lie in [0, 1]; with the
    paper's units Sigma dwarfs Omega on a field of large values (the avalanche, up to 47) and
    Omega is flat far from the expected source on a large arena.
    """

    arena: Arena = section(lambda: Arena(0.0, 2.4, 0.0, 2.4), prefix='arena_')
    robot_index: int = parameter(0, '0-based index of this robot in the swarm', ge=0)
    n_robots: int = parameter(5, 'Swarm size m', ge=1)
    velocity_mps: float = parameter(0.1, 'nominal speed V', unit='m/s', gt=0.0)
    horizon_s: float = parameter(
        10.0, 'decision horizon T; legs are at most V T long', unit='s', gt=0.0
    )
    observation_rate_hz: float = parameter(
        1.0, 'signal observation frequency f_Hz', unit='Hz', gt=0.0
    )
    detection_radius_m: float = parameter(0.05, 'detection radius eps', unit='m', gt=0.0)
    max_mission_time_s: float = parameter(100.0, 'T_max of the alpha schedule', unit='s', gt=0.0)
    initial_direction_range_deg: float = parameter(
        90.0, 'Delta theta of the first decision', unit='deg', gt=0.0, le=360.0
    )
    signal_scale: float = parameter(
        1.0,
        'samples are divided by it before they enter the belief; M, L and noise_std are in '
        'these units (avalanche: the beacon peak 47)',
        gt=0.0,
    )
    max_signal: float = parameter(1.2, 'M, the maximum signal strength of the penalty')
    lipschitz: float = parameter(
        2.0, 'L, the Lipschitz constant of the penalty', unit='signal/m', gt=0.0
    )
    penalty_enabled: bool = True
    penalty_estimate: bool = parameter(
        False, 'L and M of the penalty estimated from the belief GP each decision (not in paper)'
    )
    penalty_log_space: bool = parameter(
        False,
        'maximise log(acquisition) + sum log(penalty factors), as GPyOpt (not in the paper)',
    )
    robot_size_m: float = parameter(0.1, 'l_robot of Algorithm 2', unit='m', gt=0.0)
    weaker_source_within_eps: bool = parameter(
        False,
        'alpha = 0.1 only when the expected source lies within eps of a known weaker source, '
        'the disc its robot searched (not in the paper: squared distance < 2 l_robot)',
    )
    n_max: int = parameter(1000, 'N_max: observations kept for the GP after downsampling', ge=1)
    alpha_time_scale: float = parameter(
        1.0, 'Factor on T_max in the alpha schedule (code: 0.1)', gt=0.0
    )
    fixed_alpha: float | None = parameter(
        None,
        'constant alpha in [0, 1] instead of Algorithm 2 (-1.0: Algorithm 2)',
        ge=0.0,
        le=1.0,
        none=-1.0,
    )
    dimensionless_acquisition: bool = parameter(
        False, 'Omega in leg lengths and Sigma over prior std x leg (not in the paper)'
    )
    outer_optimizer: OuterOptimizer = parameter(
        'cobyla', 'solver of Eq. 1 (paper: cobyla)', choices=OUTER_OPTIMIZERS
    )
    inner_optimizer: Literal['newton', 'lbfgsb'] = parameter(
        'lbfgsb', 'solver of Eq. 5 (paper: lbfgsb)', choices=INNER_OPTIMIZERS
    )
    n_candidate_headings: int = 24
    n_inner_starts: int = 2
    cobyla_max_iterations: int = parameter(
        1000, 'iteration limit of COBYLA (scipy default, as the authors)', ge=1
    )
    cobyla_library: Literal['nlopt', 'scipy'] = parameter(
        'nlopt',
        "COBYLA implementation: nlopt (compiled Powell COBYLA, as the authors' scipy) or scipy",
        choices=COBYLA_LIBRARIES,
    )
    pso_particles: int = 40
    pso_iterations: int = 40
    max_peer_path_points: int = 400
    penalty_std_floor: float = 1e-3
    gp: GpConfig = section(GpConfig, prefix='')
    authors_negated_m: bool = parameter(False, "Authors' defect: M = -max(mu) (inert penalty)")
    authors_origin_paths: bool = parameter(False, "Authors' defect: paths measured from (0, 0)")
    authors_floor_downsampling: bool = parameter(False, "Authors' defect: floor(n / N_max)")

    def __post_init__(self) -> None:
        _require(self.n_robots >= 1, f'n_robots must be >= 1, got {self.n_robots}')
        _require(
            0 <= self.robot_index < self.n_robots,
            f'robot_index must be in [0, n_robots), got {self.robot_index} of {self.n_robots}',
        )
        for name in (
            'velocity_mps',
            'horizon_s',
            'observation_rate_hz',
            'detection_radius_m',
            'max_mission_time_s',
            'lipschitz',
            'robot_size_m',
            'alpha_time_scale',
            'penalty_std_floor',
            'signal_scale',
        ):
            _positive(name, getattr(self, name))
        _finite('max_signal', self.max_signal)
        if self.fixed_alpha is not None:
            _require(0.0 <= self.fixed_alpha <= 1.0, 'fixed_alpha must be in [0, 1] or None')
        _require(
            0.0 < self.initial_direction_range_deg <= 360.0,
            'initial_direction_range_deg must be in (0, 360]',
        )
        _require(self.n_max >= 1, f'n_max (N_max) must be >= 1, got {self.n_max}')
        _require(
            self.outer_optimizer in OUTER_OPTIMIZERS,
            f'outer_optimizer must be one of {", ".join(OUTER_OPTIMIZERS)}, '
            f'got {self.outer_optimizer!r}',
        )
        _require(
            self.inner_optimizer in INNER_OPTIMIZERS,
            f'inner_optimizer must be one of {", ".join(INNER_OPTIMIZERS)}, '
            f'got {self.inner_optimizer!r}',
        )
        _require(self.n_candidate_headings >= 4, 'n_candidate_headings must be >= 4')
        _require(self.n_inner_starts >= 1, 'n_inner_starts must be >= 1')
        _require(self.cobyla_max_iterations >= 1, 'cobyla_max_iterations must be >= 1')
        _require(
            self.cobyla_library in COBYLA_LIBRARIES,
            f'cobyla_library must be one of {", ".join(COBYLA_LIBRARIES)}, '
            f'got {self.cobyla_library!r}',
        )
        _require(self.pso_particles >= 2, 'pso_particles must be >= 2')
        _require(self.pso_iterations >= 1, 'pso_iterations must be >= 1')
        _require(self.max_peer_path_points >= 0, 'max_peer_path_points must be >= 0')

    @property
    def step_m(self) -> float:
        """Distance travelled between two observations, V / f_Hz [m]."""
        return self.velocity_mps / self.observation_rate_hz

    @property
    def max_leg_m(self) -> float:
        """Longest allowed leg, V * T [m] (Eq. 2)."""
        return self.velocity_mps * self.horizon_s


@dataclass(frozen=True)
class GlowwormConfig:
    """Glowworm swarm optimisation (paper Table 11; docs/bayes_swarm.md).

    ``step_m`` is the GSO step s; per decision a robot moves min(step_m, V / decision_rate_hz).
    """

    luciferin_decay: float = 0.4
    luciferin_enhancement: float = 0.6
    range_gain: float = 0.08
    sensor_range_m: float = parameter(20.0, 'Glowworm sensor range r_s', unit='m', gt=0.0)
    step_m: float = 0.03
    desired_neighbours: int = 5
    initial_luciferin: float = 5.0
    decision_rate_hz: float = parameter(100.0, 'Glowworm decisions per second', unit='Hz', gt=0.0)
    deterministic: bool = False

    def __post_init__(self) -> None:
        _require(0.0 < self.luciferin_decay < 1.0, 'luciferin_decay must be in (0, 1)')
        _positive('luciferin_enhancement', self.luciferin_enhancement)
        _positive('range_gain', self.range_gain)
        _positive('sensor_range_m', self.sensor_range_m)
        _positive('step_m', self.step_m)
        _require(self.desired_neighbours >= 1, 'desired_neighbours must be >= 1')
        _finite('initial_luciferin', self.initial_luciferin)
        _positive('decision_rate_hz', self.decision_rate_hz)


@dataclass(frozen=True)
class LevyConfig:
    """Levy walk (paper Table 12; docs/bayes_swarm.md).

    Steps follow a Pareto law with exponent ``mu`` and minimum ``min_step_m``, truncated at
    ``max_step_m`` (None: the arena diagonal). With ``taxis`` the heading is wrapped-Cauchy
    around the direction of rising signal with concentration ``turning_concentration``.
    """

    mu: float = parameter(2.0, 'Levy walk exponent mu', gt=1.0, le=3.0)
    min_step_m: float = parameter(0.5, 'Levy walk minimum step l0', unit='m', gt=0.0)
    max_step_m: float | None = None
    turning_concentration: float = 0.2
    taxis: bool = False

    def __post_init__(self) -> None:
        _require(1.0 < self.mu <= 3.0, f'mu must be in (1, 3], got {self.mu}')
        _positive('min_step_m', self.min_step_m)
        if self.max_step_m is not None:
            _positive('max_step_m', self.max_step_m)
            _require(self.max_step_m > self.min_step_m, 'max_step_m must exceed min_step_m')
        _require(0.0 <= self.turning_concentration < 1.0, 'turning_concentration must be in [0, 1)')


@dataclass(frozen=True)
class ExhaustiveConfig:
    """Partitioned boustrophedon sweep (docs/bayes_swarm.md).

    ``lane_spacing_m`` None means :meth:`spacing_m` of the detection radius: 2 eps, less a
    hair (0.1 %) so that a source exactly midway between two lanes is still detected.
    ``partition`` is 'strips' (m equal vertical strips) or 'quadrants' (the paper's
    allocation: robots spread over the four quarters, each quarter cut into equal strips).
    """

    lane_spacing_m: float | None = None
    partition: Literal['strips', 'quadrants'] = parameter('strips', 'sweep partition of the arena')

    def __post_init__(self) -> None:
        if self.lane_spacing_m is not None:
            _positive('lane_spacing_m', self.lane_spacing_m)
        _require(
            self.partition in ('strips', 'quadrants'),
            f"partition must be 'strips' or 'quadrants', got {self.partition!r}",
        )

    def spacing_m(self, detection_radius_m: float) -> float:
        """Lane spacing [m] for a detection radius eps [m]."""
        return self.lane_spacing_m or 2.0 * detection_radius_m * (1.0 - 1e-3)
