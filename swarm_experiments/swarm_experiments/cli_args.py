"""Command-line value types shared by the spawners."""

from __future__ import annotations

import argparse
import dataclasses
from collections.abc import Callable, Sequence

import numpy as np
from swarm_common.params import ParameterSpec
from swarm_sim.engine import EngineConfig
from swarm_sim.faults import FaultConfig
from swarm_sim.sensor_profiles import SENSOR_PROFILES, RealisticSensors, apply_sensor_profile

from swarm_experiments.node_overrides import parse_overrides

__all__ = [
    'add_fault_arguments',
    'add_sensor_arguments',
    'engine_options',
    'fault_config',
    'points_argument',
    'realistic_sensors',
]


def points_argument(option: str) -> Callable[[str], np.ndarray]:
    """An argparse ``type`` reading ``'x,y;x,y;...'`` [m] into an (N, 2) float array.

    Args:
        option: the option's name, quoted in the error message (e.g. ``--depots``).
    """

    def parse(text: str) -> np.ndarray:
        msg = f"{option} must look like 'x,y;x,y', got {text!r}"
        try:
            rows = [[float(v) for v in item.split(',')] for item in text.split(';') if item.strip()]
            points = np.array(rows, dtype=float)
        except ValueError as err:
            raise argparse.ArgumentTypeError(msg) from err
        if points.ndim != 2 or points.shape[1] != 2:
            raise argparse.ArgumentTypeError(msg)
        return points

    return parse


def add_fault_arguments(parser: argparse.ArgumentParser) -> None:
    """Add ``--fault NAME=VALUE`` (repeatable): a fault of :class:`swarm_sim.faults.FaultConfig`."""
    parser.add_argument(
        '--fault',
        action='append',
        default=[],
        metavar='NAME=VALUE',
        help='inject a fault (repeatable), e.g. dropout_robots=2 dropout_time_s=60 '
        'stale_lidar_robots=1 comm_loss_probability=0.3; names: docs/simulation.md',
    )


def add_sensor_arguments(parser: argparse.ArgumentParser) -> None:
    """Add ``--sensors ideal|realistic`` and ``--sensor-param NAME=VALUE`` (repeatable)."""
    parser.add_argument(
        '--sensors',
        choices=SENSOR_PROFILES,
        default='ideal',
        help='sensor profile: ideal (the papers) or realistic (NLOS AoA, evaporating scent, '
        'noisy lidar, gyro drift)',
    )
    parser.add_argument(
        '--sensor-param',
        action='append',
        default=[],
        metavar='NAME=VALUE',
        help='set a parameter of the realistic profile (repeatable), e.g. '
        'scent_decay_time_constant_s=600; names: docs/simulation.md',
    )


def fault_config(items: Sequence[str]) -> FaultConfig:
    """The :class:`FaultConfig` of ``--fault`` items.

    Raises:
        swarm_experiments.node_overrides.OverrideError: a malformed item, an unknown name or
            a bad value (one line naming it).
    """
    spec = ParameterSpec(FaultConfig)
    return spec.build(parse_overrides(items, spec))


def realistic_sensors(items: Sequence[str]) -> RealisticSensors:
    """The :class:`RealisticSensors` of ``--sensor-param`` items (errors as for
    :func:`fault_config`)."""
    spec = ParameterSpec(RealisticSensors)
    return spec.build(parse_overrides(items, spec))


def engine_options(args: argparse.Namespace, base: EngineConfig) -> EngineConfig:
    """``base`` with the sensor profile and the faults of the parsed options."""
    config = apply_sensor_profile(base, args.sensors, realistic_sensors(args.sensor_param))
    return dataclasses.replace(config, faults=fault_config(args.fault))
