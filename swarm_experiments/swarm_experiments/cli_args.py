"""Command-line pieces shared by the spawners: value types, common options, output checks."""

from __future__ import annotations

import argparse
import dataclasses
import math
from collections.abc import Callable, Sequence
from pathlib import Path

import numpy as np
from swarm_common.outputs import check_new_output, check_output_directory
from swarm_common.params import ParameterSpec
from swarm_sim.engine import EngineConfig
from swarm_sim.errors import ConfigurationError
from swarm_sim.faults import FaultConfig
from swarm_sim.physics import PHYSICS_BACKENDS, RenderConfig
from swarm_sim.sensor_profiles import SENSOR_PROFILES, RealisticSensors, apply_sensor_profile

from swarm_experiments.errors import ExperimentError
from swarm_experiments.mission import RECORD_TOPIC_SETS
from swarm_experiments.node_overrides import parse_overrides

__all__ = [
    'SPAWNER_EXIT_CODES',
    'add_fault_arguments',
    'add_physics_option',
    'add_render_option',
    'add_run_options',
    'add_sensor_arguments',
    'check_finite',
    'check_run_outputs',
    'engine_options',
    'fault_config',
    'points_argument',
    'realistic_sensors',
    'render_config',
]

#: How a ``--fault`` item naming a node crash starts (``crash:r1@60``; --processes only).
NODE_CRASH_PREFIX = 'crash:'

SPAWNER_EXIT_CODES = (
    'exit codes: 0 the mission finished (every room covered, source found, every target '
    'captured); 1 it did not finish within its budget; 2 bad options or input (one line on '
    'stderr, nothing run or written); 130 stopped by Ctrl-C: the mission stops at the next '
    'step, the outcome so far is printed and the bag is closed (a second Ctrl-C stops at '
    'once). --debug adds the traceback of an error.'
)


def points_argument(option: str) -> Callable[[str], np.ndarray]:
    """An argparse ``type`` reading ``'x,y;x,y;...'`` [m] into an (N, 2) float array.

    Args:
        option: the option's name, quoted in the error message (e.g. ``--depots``).
    """

    def parse(text: str) -> np.ndarray:
        msg = f"{option} must look like 'x,y;x,y' with finite numbers, got {text!r}"
        try:
            rows = [[float(v) for v in item.split(',')] for item in text.split(';') if item.strip()]
            points = np.array(rows, dtype=float)
        except ValueError as err:
            raise argparse.ArgumentTypeError(msg) from err
        if points.ndim != 2 or points.shape[1] != 2 or not np.all(np.isfinite(points)):
            raise argparse.ArgumentTypeError(msg)
        return points

    return parse


def add_physics_option(parser: argparse.ArgumentParser) -> None:
    """Add ``--physics NAME``: the engine's physics and ray-casting backend."""
    parser.add_argument(
        '--physics',
        choices=tuple(PHYSICS_BACKENDS),
        default='numpy',
        help='physics and ray casting: numpy (kinematic discs, exact 2D rays, fast) or '
        'pybullet (rigid bodies with real contacts, rayTestBatch; simulation install only); '
        'see docs/simulation.md',
    )


def add_render_option(parser: argparse.ArgumentParser) -> None:
    """Add ``--render gui`` / ``--render frames DIR`` (pybullet physics only)."""
    parser.add_argument(
        '--render',
        nargs='+',
        default=None,
        metavar=('MODE', 'DIR'),
        help="watch the run (needs --physics pybullet): 'gui' opens pybullet's window "
        "(needs a display), 'frames DIR' writes top-down PNG frames and DIR/run.gif",
    )


def render_config(values: Sequence[str] | None) -> RenderConfig:
    """The :class:`RenderConfig` of a ``--render`` option's values (None: no rendering).

    Raises:
        ConfigurationError: not ``gui`` or ``frames DIR``.
    """
    if not values:
        return RenderConfig()
    mode, *rest = values
    if mode == 'gui' and not rest:
        return RenderConfig(mode='gui')
    if mode == 'frames' and len(rest) == 1:
        return RenderConfig(mode='frames', frames_dir=Path(rest[0]))
    msg = f"--render takes 'gui' or 'frames DIR', got {' '.join(values)!r}"
    raise ConfigurationError(msg)


def add_run_options(parser: argparse.ArgumentParser, *, out_default: Path, plots: str) -> None:
    """``--record``, ``--record-topics``, ``--out``, ``--no-plots`` and ``--quiet``, the same
    in every spawner."""
    parser.add_argument(
        '--record',
        type=Path,
        default=None,
        help='write a rosbag2 (MCAP) bag to this new directory; it appears under this name '
        'when the recording is complete',
    )
    parser.add_argument(
        '--record-topics',
        choices=RECORD_TOPIC_SETS,
        default='sensors',
        help="what --record writes: 'sensors' the mission's topics and every topic the robots' "
        "nodes read (a bag BagPlayer can replay into a node), 'mission' the mission's topics "
        "only (smaller, for big studies), 'all' every topic of the graph (docs/bags.md)",
    )
    parser.add_argument('--out', type=Path, default=out_default, help=f'directory for {plots}')
    parser.add_argument('--no-plots', action='store_true', help='do not write plots')
    parser.add_argument(
        '--quiet',
        action='store_true',
        help='no progress on stderr (a bar on a terminal, else a line per tenth of the budget)',
    )


def check_run_outputs(record: Path | None, out_dir: Path | None) -> None:
    """Before a run: the bag directory is new and can be created, the plot directory written.

    Raises:
        swarm_common.errors.OutputError: the option, the path and what is in the way.
    """
    if record is not None:
        check_new_output(record, option='--record', what='bag')
    if out_dir is not None:
        check_output_directory(out_dir, option='--out')


def check_finite(
    name: str,
    value: float,
    *,
    minimum: float | None = None,
    above: bool = False,
    allow_inf: bool = False,
) -> None:
    """Raise :class:`ExperimentError` unless ``value`` is a number (finite unless
    ``allow_inf``) and at least (or, with ``above``, greater than) ``minimum``."""
    ok = not math.isnan(value) and (allow_inf or math.isfinite(value))
    if ok and minimum is not None:
        ok = value > minimum if above else value >= minimum
    if not ok:
        bound = '' if minimum is None else f' {">" if above else ">="} {minimum:g}'
        kind = 'a number' if allow_inf else 'a finite number'
        raise ExperimentError(f'{name} must be {kind}{bound}, got {value}')


def add_fault_arguments(parser: argparse.ArgumentParser) -> None:
    """Add ``--fault NAME=VALUE`` (repeatable): a fault of :class:`swarm_sim.faults.FaultConfig`."""
    parser.add_argument(
        '--fault',
        action='append',
        default=[],
        metavar='NAME=VALUE',
        help='inject a fault (repeatable), e.g. dropout_robots=2 dropout_time_s=60 '
        'stale_lidar_robots=1 comm_loss_probability=0.3; names: docs/simulation.md; with '
        '--processes also crash:r<i>@<time_s>[+<restart_after_s>] (kill robot i at that sim '
        'time, restart it that much later)',
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
    """The :class:`FaultConfig` of ``--fault`` items (node crashes, ``crash:...``, are
    left to the ``--processes`` runner: :func:`swarm_experiments.processes.split_crash_faults`).

    Raises:
        swarm_experiments.node_overrides.OverrideError: a malformed item, an unknown name or
            a bad value (one line naming it).
    """
    spec = ParameterSpec(FaultConfig)
    world = [item for item in items if not item.startswith(NODE_CRASH_PREFIX)]
    return spec.build(parse_overrides(world, spec))


def realistic_sensors(items: Sequence[str]) -> RealisticSensors:
    """The :class:`RealisticSensors` of ``--sensor-param`` items (errors as for
    :func:`fault_config`)."""
    spec = ParameterSpec(RealisticSensors)
    return spec.build(parse_overrides(items, spec))


def engine_options(args: argparse.Namespace, base: EngineConfig) -> EngineConfig:
    """``base`` with the sensor profile and the faults of the parsed options."""
    config = apply_sensor_profile(base, args.sensors, realistic_sensors(args.sensor_param))
    return dataclasses.replace(config, faults=fault_config(args.fault))
