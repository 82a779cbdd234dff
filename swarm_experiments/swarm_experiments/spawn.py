"""OA-Bug spawner: N robots search a site until every room is covered or the budget ends.

Plain script, no launch file (``ros2 run swarm_experiments spawn`` or ``python -m
swarm_experiments.spawn``). It builds the site, starts the sim bridge and one OA-Bug node
per robot on sim time, shows progress, prints the summary (coverage, rooms covered/total,
time, rooms first visited per robot) and writes two PNGs: the paper's Fig. 6 view (paths per
robot, rooms coloured by first visitor) and coverage over time. With ``--record`` it also
writes a rosbag2 (MCAP) bag from which ``python -m swarm_analysis.oabug_report`` reproduces
the same summary and figures.

The budget follows the paper: max actions per robot (Table II: Small 1000, Medium 2000, Big
4000), one action being a 0.1 m step, so mission time = actions x 0.1 m / robot speed.
"""

# ruff: noqa: T201  (main() is a command-line entry point that prints its report)
from __future__ import annotations

import argparse
import dataclasses
import math
import sys
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
from swarm_common.cli import EXIT_SUCCESS, fail
from swarm_common.errors import SwarmError
from swarm_sim.departure import place_starts
from swarm_sim.engine import EngineConfig
from swarm_sim.errors import ConfigurationError
from swarm_sim.site_loading import load_site, site_budget_actions

from swarm_experiments.cli_args import add_fault_arguments, add_sensor_arguments, engine_options
from swarm_experiments.errors import ExperimentError
from swarm_experiments.mission import (
    VIEWER_TOPICS,
    MissionProgress,
    MissionResult,
    MissionSpec,
    RecordingSpec,
    RobotNodeSpec,
    run_mission,
)
from swarm_experiments.node_overrides import parse_overrides

__all__ = [
    'ACTION_LENGTH_M',
    'DEFAULT_RECORD_TOPICS',
    'VARIANTS',
    'OABugRun',
    'SpawnSettings',
    'main',
    'oabug_parameter_overrides',
    'run',
]

VARIANTS = ('random', 'minimum', 'sound', 'gas', 'gas_sound')
ACTION_LENGTH_M = 0.1
DEFAULT_ACTIONS = 1000
DEFAULT_RECORD_TOPICS = ('/clock', '/sim/poses', '/sim/coverage', '/sim/site', *VIEWER_TOPICS)
# OA-Bug node parameters the spawner sets from its own options (see build_mission).
SPAWNER_PARAMETERS = (
    'variant',
    'robot_index',
    'robot_count',
    'departure',
    'heading_bias_deg',
    'forward_speed_mps',
    'own_tag_id',
    'seed',
)


@dataclass(frozen=True)
class SpawnSettings:
    """One OA-Bug run.

    Attributes:
        site: 'small' / 'medium' / 'big' (generated from ``site_seed``), a .lay layout or a
            site file.
        site_seed: seed of the generated site.
        variant: random, minimum, sound, gas or gas_sound.
        robots: number of robots.
        departure: name of the site's departure point ('center' or 'edge' on generated
            sites). A point with a heading into the site gets the paper's edge fan (half
            circle), any other the centre fan (full circle).
        seed: seed of the run (world noise and the fan's random bias).
        actions: max actions per robot; None takes the preset's Table II value (else 1000).
        speed_mps: the robots' cruise speed [m/s].
        record: bag directory to write, or None.
        record_robot_topics: also record each robot's state, cmd_vel and pump topics.
        record_scans: also record each robot's lidar scans (``/r<i>/scan``, about 8 kB/s
            per robot; off by default, the viewers' scan displays show them when present).
        out_dir: directory for the PNGs, or None for no plots.
        robot_parameters: extra OA-Bug node parameters for every robot.
        engine: world configuration (its seed is replaced by ``seed``).
    """

    site: str = 'small'
    site_seed: int = 0
    variant: str = 'gas_sound'
    robots: int = 10
    departure: str = 'center'
    seed: int = 0
    actions: int | None = None
    speed_mps: float = 0.3
    record: Path | None = None
    record_robot_topics: bool = True
    record_scans: bool = False
    out_dir: Path | None = None
    robot_parameters: dict[str, object] = field(default_factory=dict)
    engine: EngineConfig = field(default_factory=EngineConfig)

    def __post_init__(self) -> None:
        if self.variant not in VARIANTS:
            msg = f'unknown variant {self.variant!r}; choose one of {", ".join(VARIANTS)}'
            raise ConfigurationError(msg)
        if self.robots < 1:
            msg = f'robots must be >= 1, got {self.robots}'
            raise ConfigurationError(msg)
        if self.actions is not None and self.actions < 1:
            msg = f'actions must be >= 1, got {self.actions}'
            raise ConfigurationError(msg)
        if not (math.isfinite(self.speed_mps) and self.speed_mps > 0.0):
            msg = f'speed_mps must be positive, got {self.speed_mps}'
            raise ConfigurationError(msg)
        if self.seed < 0 or self.site_seed < 0:
            raise ConfigurationError('seeds must be >= 0')

    @property
    def budget_actions(self) -> int:
        """Max actions per robot of this run."""
        if self.actions is not None:
            return self.actions
        return site_budget_actions(self.site) or DEFAULT_ACTIONS

    @property
    def budget_s(self) -> float:
        """Mission time [s]: actions x 0.1 m / speed."""
        return self.budget_actions * ACTION_LENGTH_M / self.speed_mps


@dataclass(frozen=True)
class OABugRun:
    """A finished run.

    Attributes:
        settings: what was run.
        mission: the mission runner's result.
        heading_bias_rad: the fan's common bias used [rad].
        plots: PNG files written.
    """

    settings: SpawnSettings
    mission: MissionResult
    heading_bias_rad: float
    plots: tuple[Path, ...] = ()

    @property
    def coverage(self) -> float:
        """Covered fraction of the rooms."""
        return self.mission.coverage


def oabug_parameter_overrides(items: Sequence[str]) -> dict[str, object]:
    """OA-Bug node parameters from ``NAME=VALUE`` items, typed and checked before a run.

    Every parameter the node declares may be set except those the spawner derives from its
    own options (:data:`SPAWNER_PARAMETERS`: use ``--variant``, ``--speed``, ...).

    Raises:
        ConfigurationError: a malformed item, an unknown or spawner-set name, a value of the
            wrong type, or one the controller rejects (e.g. a negative distance).
        ExperimentError: the OA-Bug package cannot be imported.
    """
    try:
        from oabug_robot.node_settings import OABUG_PARAMETERS
    except ImportError as err:
        msg = f'the OA-Bug node (package oabug_robot) cannot be imported: {err}'
        raise ExperimentError(msg) from err
    return parse_overrides(items, OABUG_PARAMETERS, reserved=SPAWNER_PARAMETERS)


def _oabug_factory() -> Callable[..., object]:
    try:
        from oabug_robot.node import OABugNode
    except ImportError as err:
        msg = f'the OA-Bug node (package oabug_robot) cannot be imported: {err}'
        raise ExperimentError(msg) from err
    return OABugNode


def build_mission(config: SpawnSettings) -> tuple[MissionSpec, float]:
    """The mission spec of ``config`` and the heading bias it uses."""
    site = load_site(config.site, seed=config.site_seed)
    starts = place_starts(
        site, config.departure, config.robots, seed=config.seed, body=config.engine.body
    )
    fan, bias, poses = starts.fan, starts.bias_rad, starts.poses
    factory = _oabug_factory()
    robots = []
    for i in range(config.robots):
        params: dict[str, object] = {
            'variant': config.variant,
            'robot_index': i,
            'robot_count': config.robots,
            'departure': fan,
            'heading_bias_deg': math.degrees(bias),
            'forward_speed_mps': float(config.speed_mps),
            'own_tag_id': f'R{i}',
            'seed': int(config.seed * 1000 + i),
        }
        params.update(config.robot_parameters)
        robots.append(RobotNodeSpec(factory, params))
    recording = None
    if config.record is not None:
        topics = list(DEFAULT_RECORD_TOPICS)
        if config.record_robot_topics:
            for i in range(config.robots):
                topics += [f'/r{i}/state', f'/r{i}/cmd_vel', f'/r{i}/pump']
        if config.record_scans:
            topics += [f'/r{i}/scan' for i in range(config.robots)]
        recording = RecordingSpec(Path(config.record), tuple(topics))
    engine = dataclasses.replace(config.engine, seed=int(config.seed))
    spec = MissionSpec(
        site=site,
        initial_poses=poses,
        robots=robots,
        max_sim_time_s=config.budget_s,
        engine_config=engine,
        recording=recording,
    )
    return spec, bias


def write_plots(result: MissionResult, out_dir: Path, stem: str) -> tuple[Path, ...]:
    """Write the Fig.-6 PNG and the coverage-over-time PNG of a run; return their paths."""
    from swarm_analysis.plots import plot_coverage_curves, plot_site_paths

    out_dir.mkdir(parents=True, exist_ok=True)
    site = result.site
    first = {e.room_index: result.robot_names[e.robot_index] for e in result.room_entries}
    title = (
        f'{stem}: {100.0 * result.coverage:.1f} % '
        f'({result.rooms_covered}/{result.rooms_total} rooms) in {result.sim_time_s:.0f} s'
    )
    paths = plot_site_paths(
        out_dir / f'{stem}_paths.png',
        walls=np.asarray(site.sealed_walls),
        room_rects=[room.rects for room in site.rooms],
        robot_names=result.robot_names,
        trajectories=result.trajectories[:, :, :2],
        first_visitor=first,
        title=title,
    )
    curve = plot_coverage_curves(out_dir / f'{stem}_coverage.png', {stem: result.coverage_curve()})
    return paths, curve


def format_summary(result: OABugRun) -> str:
    """The text summary printed at the end of a run."""
    from swarm_analysis.coverage import CoverageSummary, RoomFirstVisit

    mission = result.mission
    visits = [
        RoomFirstVisit(e.room_index, mission.robot_names[e.robot_index], e.time_s)
        for e in mission.room_entries
    ]
    summary = CoverageSummary.build(
        mission.rooms_total, visits, mission.sim_time_s, mission.robot_names
    )
    cfg = result.settings
    head = (
        f'{cfg.variant}, {cfg.robots} robots from the {cfg.departure}, site {cfg.site} '
        f'(seed {cfg.site_seed}), run seed {cfg.seed}: stopped by {mission.stop_reason} '
        f'after {mission.sim_time_s:.1f} s sim / {mission.wall_time_s:.1f} s wall'
    )
    return head + '\n' + summary.format_report()


def run(
    config: SpawnSettings,
    *,
    progress: Callable[[MissionProgress], None] | None = None,
    runner: Callable[..., MissionResult] = run_mission,
) -> OABugRun:
    """Run one OA-Bug mission headless and return its result (no printing).

    ``runner`` runs the mission spec: the node path :func:`swarm_experiments.mission.run_mission`,
    or the batch path :func:`swarm_experiments.oabug_batch.run_oabug_batch` for sweeps.
    """
    spec, bias = build_mission(config)
    mission = runner(spec, progress=progress)
    plots: tuple[Path, ...] = ()
    if config.out_dir is not None:
        stem = f'oabug_{config.variant}_{config.departure}_{mission.site.name}_seed{config.seed}'
        plots = write_plots(mission, Path(config.out_dir), stem)
    return OABugRun(settings=config, mission=mission, heading_bias_rad=bias, plots=plots)


def _parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(
        prog='spawn',
        description=(
            'Run an OA-Bug swarm search in the pybullet simulation until every room is covered '
            'or the action budget ends; print the coverage summary and write the plots.'
        ),
        formatter_class=argparse.ArgumentDefaultsHelpFormatter,
    )
    parser.add_argument(
        '--site',
        default='small',
        help="'small', 'medium' or 'big' (generated, Table II), a .lay layout or a site file",
    )
    parser.add_argument('--site-seed', type=int, default=0, help='seed of the generated site')
    parser.add_argument('--variant', choices=VARIANTS, default='gas_sound', help='algorithm')
    parser.add_argument('--robots', type=int, default=10, help='number of robots')
    parser.add_argument(
        '--departure',
        default='center',
        help="the site's departure point: 'center' or 'edge' on generated sites",
    )
    parser.add_argument('--seed', type=int, default=0, help='seed of the run')
    parser.add_argument(
        '--actions',
        type=int,
        default=None,
        help='max actions (0.1 m steps) per robot; default: the preset budget (Small 1000)',
    )
    parser.add_argument('--speed', type=float, default=0.3, help='robot cruise speed [m/s]')
    parser.add_argument('--record', type=Path, default=None, help='write a rosbag2 bag here')
    parser.add_argument(
        '--record-scans', action='store_true', help="also record the robots' lidar scans"
    )
    parser.add_argument(
        '--out', type=Path, default=Path('oabug_results'), help='directory for the PNGs'
    )
    parser.add_argument('--no-plots', action='store_true', help='do not write PNGs')
    parser.add_argument('--quiet', action='store_true', help='no progress lines')
    parser.add_argument(
        '--param',
        action='append',
        default=[],
        metavar='NAME=VALUE',
        help='set an OA-Bug node parameter for every robot (repeatable), e.g. '
        'gas_threshold=300 or sound_turn_rule=toward; names and defaults: docs/oabug.md',
    )
    add_sensor_arguments(parser)
    add_fault_arguments(parser)
    return parser


def main(argv: Sequence[str] | None = None) -> int:
    """Command line entry point; returns the process exit code."""
    args = _parser().parse_args(argv)
    try:
        config = SpawnSettings(
            robot_parameters=oabug_parameter_overrides(args.param),
            site=args.site,
            site_seed=args.site_seed,
            variant=args.variant,
            robots=args.robots,
            departure=args.departure,
            seed=args.seed,
            actions=args.actions,
            speed_mps=args.speed,
            record=args.record,
            record_scans=args.record_scans,
            out_dir=None if args.no_plots else args.out,
            engine=engine_options(args, EngineConfig()),
        )
        site_warnings = load_site(config.site, seed=config.site_seed).warnings
    except SwarmError as err:
        return fail('spawn', err)
    for warning in site_warnings:
        print(f'spawn: warning: {warning}', file=sys.stderr, flush=True)

    def show(p: MissionProgress) -> None:
        print(
            f'  t = {p.sim_time_s:6.1f} s  coverage {100.0 * p.coverage:5.1f} % '
            f'({p.rooms_covered}/{p.rooms_total})  wall {p.wall_time_s:5.1f} s',
            flush=True,
        )

    print(
        f'OA-Bug {config.variant}: {config.robots} robots, site {config.site}, '
        f'{config.departure} departure, budget {config.budget_actions} actions '
        f'= {config.budget_s:.0f} s at {config.speed_mps} m/s',
        flush=True,
    )
    if args.sensors != 'ideal' or config.engine.faults.active:
        print(f'sensors {args.sensors}; faults: {config.engine.faults.describe()}', flush=True)
    if config.robot_parameters:
        settings = ', '.join(f'{k}={v}' for k, v in sorted(config.robot_parameters.items()))
        print(f'OA-Bug parameters other than the defaults: {settings}', flush=True)
    try:
        result = run(config, progress=None if args.quiet else show)
    except SwarmError as err:
        return fail('spawn', err)
    print(format_summary(result))
    for path in result.plots:
        print(f'wrote {path}')
    if result.mission.bag_path is not None:
        print(f'recorded {result.mission.bag_path}')
    return EXIT_SUCCESS


if __name__ == '__main__':
    sys.exit(main())
