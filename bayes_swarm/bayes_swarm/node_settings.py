"""The node's ROS parameters and their translation into the core's frozen settings.

Pure Python (no ROS): :data:`PARAMETERS` lists every parameter once with its default and
description, and :func:`settings_from_values` validates a ``{name: value}`` dict into a
:class:`NodeSettings`. The node declares the parameters from this table, and
``config/*.yaml`` mirrors the defaults.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

from bayes_swarm.errors import ConfigError
from bayes_swarm.follower import FollowerConfig
from bayes_swarm.settings import (
    Arena,
    BayesSwarmConfig,
    ExhaustiveConfig,
    GlowwormConfig,
    GpConfig,
    LevyConfig,
)

__all__ = ['ALGORITHMS', 'PARAMETERS', 'NodeSettings', 'ParameterSpec', 'settings_from_values']

ALGORITHMS = ('bayes_swarm_p', 'bayes_swarm_o', 'glowworm', 'levy', 'exhaustive')


@dataclass(frozen=True)
class ParameterSpec:
    """One ROS parameter: name, default (its type is the parameter type) and description."""

    name: str
    default: Any
    description: str


PARAMETERS: tuple[ParameterSpec, ...] = (
    ParameterSpec('algorithm', 'bayes_swarm_p', f'One of {", ".join(ALGORITHMS)}.'),
    ParameterSpec('robot_index', 0, '0-based index of this robot in the swarm.'),
    ParameterSpec('n_robots', 5, 'Swarm size m.'),
    ParameterSpec('seed', 0, "Seed of this robot's random draws."),
    ParameterSpec('arena_x_min_m', 0.0, 'Arena lower x bound [m].'),
    ParameterSpec('arena_x_max_m', 2.4, 'Arena upper x bound [m].'),
    ParameterSpec('arena_y_min_m', 0.0, 'Arena lower y bound [m].'),
    ParameterSpec('arena_y_max_m', 2.4, 'Arena upper y bound [m].'),
    ParameterSpec('velocity_mps', 0.1, 'Nominal speed V [m/s].'),
    ParameterSpec('horizon_s', 10.0, 'Decision horizon T [s]; legs are at most V T long.'),
    ParameterSpec('observation_rate_hz', 1.0, 'Signal observation frequency f_Hz [Hz].'),
    ParameterSpec('detection_radius_m', 0.05, 'Detection radius eps [m].'),
    ParameterSpec('max_mission_time_s', 100.0, 'T_max of the alpha schedule [s].'),
    ParameterSpec('initial_direction_range_deg', 90.0, 'Delta theta of the first decision [deg].'),
    ParameterSpec('initial_direction_offset_deg', 0.0, 'Heading the first-decision fan starts at.'),
    ParameterSpec('fan_index', -1, 'Position r in the first-decision fan (-1: robot_index + 1).'),
    ParameterSpec('fan_size', -1, 'Robots sharing the fan (-1: n_robots).'),
    ParameterSpec('max_signal', 1.2, 'M, the maximum signal strength of the penalty.'),
    ParameterSpec('lipschitz', 2.0, 'L, the Lipschitz constant of the penalty [signal/m].'),
    ParameterSpec('robot_size_m', 0.1, 'l_robot of Algorithm 2 [m].'),
    ParameterSpec('n_max', 1000, 'N_max: observations kept for the GP after downsampling.'),
    ParameterSpec('noise_std', 1e-3, 'GP observation noise std (signal units).'),
    ParameterSpec('alpha_time_scale', 1.0, 'Factor on T_max in the alpha schedule (code: 0.1).'),
    ParameterSpec(
        'fixed_alpha', -1.0, 'Constant alpha in [0, 1] instead of Algorithm 2 (-1: off).'
    ),
    ParameterSpec('outer_optimizer', 'grid', 'Eq. 1 solver: grid, cobyla or pso.'),
    ParameterSpec(
        'dimensionless_acquisition',
        False,
        'Omega in leg lengths and Sigma over prior std x leg (not in the paper).',
    ),
    ParameterSpec('authors_negated_m', False, "Authors' defect: M = -max(mu) (inert penalty)."),
    ParameterSpec('authors_origin_paths', False, "Authors' defect: paths measured from (0, 0)."),
    ParameterSpec('authors_floor_downsampling', False, "Authors' defect: floor(n / N_max)."),
    ParameterSpec('levy_min_step_m', 0.5, 'Levy walk minimum step l0 [m].'),
    ParameterSpec('levy_mu', 2.0, 'Levy walk exponent mu.'),
    ParameterSpec('glowworm_decision_rate_hz', 100.0, 'Glowworm decisions per second [Hz].'),
    ParameterSpec('glowworm_sensor_range_m', 20.0, 'Glowworm sensor range r_s [m].'),
    ParameterSpec('exhaustive_partition', 'strips', "Sweep partition: 'strips' or 'quadrants'."),
    ParameterSpec('control_rate_hz', 20.0, 'Waypoint follower rate [Hz].'),
    ParameterSpec('arrival_tolerance_m', 0.01, 'Distance at which a waypoint is reached [m].'),
    ParameterSpec('max_turn_rate_radps', 2.0, 'Yaw-rate limit of the follower [rad/s].'),
    ParameterSpec('odom_timeout_s', 0.5, 'Stop when odometry is older than this [s].'),
)


@dataclass(frozen=True)
class NodeSettings:
    """Everything the node needs, validated."""

    algorithm: str
    seed: int
    planner: BayesSwarmConfig
    fan_index: int | None
    fan_size: int | None
    direction_offset_deg: float
    levy: LevyConfig
    glowworm: GlowwormConfig
    exhaustive: ExhaustiveConfig
    follower: FollowerConfig
    control_rate_hz: float
    odom_timeout_s: float


def settings_from_values(values: dict[str, Any]) -> NodeSettings:
    """Validate parameter values (missing names take their defaults).

    Raises:
        ConfigError: with the offending parameter named.
    """
    known = {p.name for p in PARAMETERS}
    unknown = set(values) - known
    if unknown:
        msg = f'unknown parameters: {", ".join(sorted(unknown))}'
        raise ConfigError(msg)
    v = {p.name: values.get(p.name, p.default) for p in PARAMETERS}
    if v['algorithm'] not in ALGORITHMS:
        msg = f'algorithm must be one of {", ".join(ALGORITHMS)}, got {v["algorithm"]!r}'
        raise ConfigError(msg)
    for name in ('control_rate_hz', 'odom_timeout_s'):
        if not (math.isfinite(v[name]) and v[name] > 0.0):
            msg = f'{name} must be > 0, got {v[name]!r}'
            raise ConfigError(msg)
    arena = Arena(v['arena_x_min_m'], v['arena_x_max_m'], v['arena_y_min_m'], v['arena_y_max_m'])
    planner = BayesSwarmConfig(
        arena=arena,
        robot_index=int(v['robot_index']),
        n_robots=int(v['n_robots']),
        velocity_mps=float(v['velocity_mps']),
        horizon_s=float(v['horizon_s']),
        observation_rate_hz=float(v['observation_rate_hz']),
        detection_radius_m=float(v['detection_radius_m']),
        max_mission_time_s=float(v['max_mission_time_s']),
        initial_direction_range_deg=float(v['initial_direction_range_deg']),
        max_signal=float(v['max_signal']),
        lipschitz=float(v['lipschitz']),
        penalty_enabled=v['algorithm'] == 'bayes_swarm_p',
        robot_size_m=float(v['robot_size_m']),
        n_max=int(v['n_max']),
        alpha_time_scale=float(v['alpha_time_scale']),
        fixed_alpha=None if float(v['fixed_alpha']) < 0.0 else float(v['fixed_alpha']),
        outer_optimizer=v['outer_optimizer'],
        dimensionless_acquisition=bool(v['dimensionless_acquisition']),
        gp=GpConfig(noise_std=float(v['noise_std'])),
        authors_negated_m=bool(v['authors_negated_m']),
        authors_origin_paths=bool(v['authors_origin_paths']),
        authors_floor_downsampling=bool(v['authors_floor_downsampling']),
    )
    fan_index = int(v['fan_index'])
    fan_size = int(v['fan_size'])
    return NodeSettings(
        algorithm=v['algorithm'],
        seed=int(v['seed']),
        planner=planner,
        fan_index=fan_index if fan_index >= 1 else None,
        fan_size=fan_size if fan_size >= 1 else None,
        direction_offset_deg=float(v['initial_direction_offset_deg']),
        levy=LevyConfig(mu=float(v['levy_mu']), min_step_m=float(v['levy_min_step_m'])),
        glowworm=GlowwormConfig(
            decision_rate_hz=float(v['glowworm_decision_rate_hz']),
            sensor_range_m=float(v['glowworm_sensor_range_m']),
        ),
        exhaustive=ExhaustiveConfig(partition=v['exhaustive_partition']),
        follower=FollowerConfig(
            speed_mps=float(v['velocity_mps']),
            arrival_tolerance_m=float(v['arrival_tolerance_m']),
            max_turn_rate_radps=float(v['max_turn_rate_radps']),
            slow_down_m=2.0 * float(v['velocity_mps']) / float(v['control_rate_hz']),
        ),
        control_rate_hz=float(v['control_rate_hz']),
        odom_timeout_s=float(v['odom_timeout_s']),
    )
