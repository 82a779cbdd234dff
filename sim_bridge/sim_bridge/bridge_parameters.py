"""The bridge node's ROS parameters and how they map onto :class:`EngineConfig`.

One table, :data:`ENGINE_PARAMETERS`, names each parameter, the config field it sets and its
description; the node declares them from it and builds the frozen config back from the
values, so the parameter list, the YAML file (config/sim_bridge.yaml) and the dataclass
defaults cannot drift apart.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

from swarm_sim.engine import EngineConfig
from swarm_sim.errors import ConfigurationError

__all__ = ['ENGINE_PARAMETERS', 'EngineParameter', 'config_from_values', 'values_from_config']


@dataclass(frozen=True)
class EngineParameter:
    """One ROS parameter of the bridge that sets one engine config field.

    Attributes:
        name: parameter name.
        path: attribute path into EngineConfig, e.g. ('lidar', 'rate_hz').
        description: what it means, with units.
    """

    name: str
    path: tuple[str, ...]
    description: str


def _p(name: str, path: str, description: str) -> EngineParameter:
    return EngineParameter(name, tuple(path.split('.')), description)


ENGINE_PARAMETERS: tuple[EngineParameter, ...] = (
    _p('seed', 'seed', 'Seed of every random draw in the world; equal seeds give equal runs.'),
    _p('physics_rate_hz', 'physics_rate_hz', 'Physics steps per second of sim time [Hz].'),
    _p('cmd_vel_timeout_s', 'cmd_vel_timeout_s', 'A robot stops when cmd_vel is older [s].'),
    _p('pump_timeout_s', 'pump_timeout_s', 'A pump stops when its last "on" is older [s].'),
    _p('pump_offset_m', 'pump_offset_m', 'Pump nozzle distance behind the robot centre [m].'),
    _p('ground_truth_rate_hz', 'ground_truth_rate_hz', 'Rate of /sim/poses [Hz].'),
    _p('robot_radius_m', 'body.robot_radius_m', 'Radius of every robot disc [m].'),
    _p('wall_thickness_m', 'body.wall_thickness_m', 'Thickness of every wall [m].'),
    _p('max_linear_speed_mps', 'body.max_linear_speed_mps', 'Forward speed limit [m/s].'),
    _p('max_angular_speed_radps', 'body.max_angular_speed_radps', 'Yaw rate limit [rad/s].'),
    _p('scan_rate_hz', 'lidar.rate_hz', 'Lidar revolutions per second [Hz] (A1: 5.5).'),
    _p('scan_bins', 'lidar.num_bins', 'Lidar samples per revolution.'),
    _p('scan_range_min_m', 'lidar.range_min_m', 'Shortest lidar range [m]; closer reads inf.'),
    _p('scan_range_max_m', 'lidar.range_max_m', 'Longest lidar range [m]; farther reads inf.'),
    _p('scan_noise_fraction', 'lidar.range_noise_fraction', 'Range noise std / range.'),
    _p('scan_dropout_probability', 'lidar.dropout_probability', 'Chance a sample is lost.'),
    _p('gas_rate_hz', 'gas.rate_hz', 'Gas sensor sample rate [Hz].'),
    _p('gas_rise_time_constant_s', 'gas.rise_time_constant_s', 'MP503 rise lag [s].'),
    _p('gas_fall_time_constant_s', 'gas.fall_time_constant_s', 'MP503 fall lag [s].'),
    _p('gas_baseline_raw', 'gas.baseline_raw', 'Clean-air reading on the 10-bit scale.'),
    _p('gas_noise_std_raw', 'gas.noise_std_raw', 'Gas reading noise std [counts].'),
    _p('gas_sensor_offset_m', 'gas.sensor_offset_m', 'Gas sensor distance ahead of centre [m].'),
    _p(
        'scent_deposit_rate_ppm_m2_per_s',
        'scent.deposit_rate_ppm_m2_per_s',
        'Ethanol released while a pump runs [ppm m^2/s].',
    ),
    _p('scent_final_spread_m', 'scent.final_spread_m', 'Settled puff standard deviation [m].'),
    _p('scent_decay_time_constant_s', 'scent.decay_time_constant_s', 'Puff evaporation [s].'),
    _p('scent_walls_block', 'scent.walls_block', 'True: vapour does not cross walls.'),
    _p('bearings_rate_hz', 'bearings.rate_hz', 'AoA locator report rate [Hz].'),
    _p('bearing_range_m', 'bearings.range_m', 'AoA line-of-sight range [m] (paper: 30-50).'),
    _p('bearing_wall_range_factor', 'bearings.wall_range_factor', 'Range factor per wall.'),
    _p(
        'bearing_azimuth_noise_std_rad',
        'bearings.azimuth_noise_std_rad',
        'AoA azimuth error std [rad].',
    ),
    _p('bearing_dropout_probability', 'bearings.dropout_probability', 'Chance a report is lost.'),
    _p('imu_rate_hz', 'imu.rate_hz', 'IMU output rate [Hz].'),
    _p(
        'gyro_residual_bias_std_radps',
        'imu.residual_bias_std_radps',
        'Spread of the per-robot gyro bias left after calibration [rad/s]; 0 = ideal heading.',
    ),
    _p(
        'gyro_bias_random_walk_radps_per_sqrt_s',
        'imu.bias_random_walk_radps_per_sqrt_s',
        'Gyro bias drift [rad/s/sqrt(s)].',
    ),
    _p('odom_rate_hz', 'odometry.rate_hz', 'Odometry output rate [Hz].'),
    _p(
        'odom_distance_noise_fraction',
        'odometry.distance_noise_fraction',
        'Odometry distance error std per increment, as a fraction.',
    ),
)


def _get(config: Any, path: tuple[str, ...]) -> Any:
    for part in path:
        config = getattr(config, part)
    return config


def values_from_config(config: EngineConfig) -> dict[str, Any]:
    """Parameter name -> value of ``config`` (the defaults the node declares)."""
    return {p.name: _get(config, p.path) for p in ENGINE_PARAMETERS}


def config_from_values(values: Mapping[str, Any], base: EngineConfig | None = None) -> EngineConfig:
    """Build an EngineConfig from parameter values (missing names keep ``base``'s values).

    Raises:
        ConfigurationError: an unknown name, a value of the wrong type, or a value the
            config rejects.
    """
    known = {p.name: p for p in ENGINE_PARAMETERS}
    unknown = sorted(set(values) - set(known))
    if unknown:
        msg = f'unknown bridge parameters: {", ".join(unknown)}'
        raise ConfigurationError(msg)
    config = base or EngineConfig()
    nested: dict[str, dict[str, Any]] = {}
    top: dict[str, Any] = {}
    for name, value in values.items():
        path = known[name].path
        current = _get(config, path)
        if isinstance(current, bool) != isinstance(value, bool):
            msg = f'parameter {name} must be a bool, got {value!r}'
            raise ConfigurationError(msg)
        if isinstance(current, float) and isinstance(value, int):
            value = float(value)
        if type(value) is not type(current):
            msg = f'parameter {name} must be of type {type(current).__name__}, got {value!r}'
            raise ConfigurationError(msg)
        if len(path) == 1:
            top[path[0]] = value
        else:
            nested.setdefault(path[0], {})[path[1]] = value
    try:
        for group, changes in nested.items():
            top[group] = dataclasses.replace(getattr(config, group), **changes)
        return dataclasses.replace(config, **top)
    except ConfigurationError:
        raise
    except (TypeError, ValueError) as err:
        raise ConfigurationError(str(err)) from err
