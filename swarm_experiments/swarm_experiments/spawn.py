"""OA-Bug spawner: N robots search a site until every room is covered or the budget ends.

Plain script (``ros2 run swarm_experiments spawn`` or ``python -m
swarm_experiments.spawn``). It builds the site, starts the sim bridge and one OA-Bug node
per robot on sim time, shows a progress bar (on a terminal), prints the summary (coverage,
rooms covered/total, time, rooms first visited per robot) and writes two PNGs: the paper's
Fig. 6 view (paths per robot, rooms coloured by first visitor) and coverage over time. With
``--record`` it also writes a rosbag2 (MCAP) bag from which ``swarm_report`` reproduces the
same summary and figures. With ``--processes`` the bridge and every robot node run in
processes of their own on real DDS (:mod:`swarm_experiments.processes`).

The budget follows the paper: max actions per robot (Table II: Small 1000, Medium 2000, Big
4000), one action being a 0.1 m step, so mission time = actions x 0.1 m / robot speed.

Everything is checked before the mission starts: the options, the site, that the robots fit
around the departure point, that ``--record`` is a new bag and ``--out`` can be written.
Exit codes: 0 every room covered, 1 the budget ended first, 2 bad options or input, 130
Ctrl-C (the summary so far is printed and the bag closed).
"""

# ruff: noqa: T201  (main() is a command-line entry point that prints its report)
from __future__ import annotations

import argparse
import contextlib
import dataclasses
import math
import sys
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
from oabug_robot.profiles import PROFILES
from swarm_common.cli import (
    EXIT_INTERRUPTED,
    EXIT_SUCCESS,
    EXIT_UNFINISHED,
    ToolParser,
    fail,
    run_tool,
)
from swarm_sim.departure import free_space_capacity, place_starts
from swarm_sim.engine import EngineConfig
from swarm_sim.errors import ConfigurationError
from swarm_sim.physics import require_backend
from swarm_sim.site_loading import load_site, site_budget_actions
from swarm_sim.sites import PRESETS, Site, require_rooms

from swarm_experiments.cli_args import (
    SPAWNER_EXIT_CODES,
    add_fault_arguments,
    add_physics_option,
    add_render_option,
    add_run_options,
    add_sensor_arguments,
    check_run_outputs,
    engine_options,
    render_config,
)
from swarm_experiments.errors import ExperimentError
from swarm_experiments.mission import (
    VIEWER_TOPICS,
    MissionProgress,
    MissionResult,
    MissionSpec,
    RecordingSpec,
    RobotNodeSpec,
    StopReason,
    recorded_topics,
    run_mission,
)
from swarm_experiments.node_overrides import parse_overrides
from swarm_experiments.processes import DryRunDone, process_runner
from swarm_experiments.progress import MissionProgressBar, progress_wanted
from swarm_experiments.runtime_option import add_runtime_arguments, check_runtime

__all__ = [
    'ACTION_LENGTH_M',
    'DEFAULT_RECORD_TOPICS',
    'MAX_ROBOTS',
    'SENSOR_TOPICS',
    'VARIANTS',
    'OABugRun',
    'SpawnSettings',
    'build_mission',
    'check_site_limits',
    'main',
    'oabug_parameter_overrides',
    'run',
]

#: (package, executable) of the OA-Bug node, for ``--processes``.
OABUG_EXECUTABLE = ('oabug_robot', 'oabug')
VARIANTS = ('random', 'minimum', 'sound', 'gas', 'gas_sound')
ACTION_LENGTH_M = 0.1
DEFAULT_ACTIONS = 1000
#: Largest swarm the command runs: every robot is a node in this one process (the paper
#: reports 2 to 10 robots; oabug_batch runs larger swarms without nodes).
MAX_ROBOTS = 100
DEFAULT_RECORD_TOPICS = ('/clock', '/sim/poses', '/sim/coverage', '/sim/site', *VIEWER_TOPICS)
#: The topics an OA-Bug node subscribes to (oabug_robot.node), per robot: what
#: ``--record-topics sensors`` adds so that a bag replays into a node.
SENSOR_TOPICS = ('scan', 'imu', 'gas', 'bearings')
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


class SiteBudget:
    """The budget of a site mission, mixed into the site spawners' settings (OA-Bug, SGBA):
    ``actions`` per robot (None: the preset's Table II value, else :data:`DEFAULT_ACTIONS`)
    of :data:`ACTION_LENGTH_M` at ``speed_mps``."""

    site: str
    actions: int | None
    speed_mps: float

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
class SpawnSettings(SiteBudget):
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
        record_topics: what the bag holds (:data:`~swarm_experiments.mission.RECORD_TOPIC_SETS`):
            'sensors' adds every robot's :data:`SENSOR_TOPICS` (the lidar scans are about
            8 kB/s per robot), 'mission' leaves them out, 'all' records every topic.
        out_dir: directory for the PNGs, or None for no plots.
        profile: the OA-Bug parameter profile (``oabug_robot.profiles``): 'tuned' (the
            node's defaults) or 'paper' (Table I read literally).
        robot_parameters: extra OA-Bug node parameters for every robot (on top of the
            profile's).
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
    record_topics: str = 'sensors'
    out_dir: Path | None = None
    profile: str = 'tuned'
    robot_parameters: dict[str, object] = field(default_factory=dict)
    engine: EngineConfig = field(default_factory=EngineConfig)
    time_scale: float = 1.0

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
            msg = f'speed_mps must be positive and finite, got {self.speed_mps}'
            raise ConfigurationError(msg)
        if self.seed < 0 or self.site_seed < 0:
            msg = f'seeds must be >= 0, got seed {self.seed}, site seed {self.site_seed}'
            raise ConfigurationError(msg)
        if self.profile not in PROFILES:
            msg = f'unknown profile {self.profile!r}; choose one of {", ".join(PROFILES)}'
            raise ConfigurationError(msg)


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


def check_site_limits(config: SpawnSettings, site: Site, *, max_robots: int | None = None) -> None:
    """Check the run against its site before anything is placed or started.

    Raises:
        swarm_sim.sites.SiteValidationError: the site has no rooms (nothing to search).
        ConfigurationError: no such departure point, more robots than its free space could
            hold (:func:`swarm_sim.departure.free_space_capacity`, quick for any count), or
            more than ``max_robots``.
    """
    require_rooms(site, None if config.site.lower() in PRESETS else config.site)
    capacity = free_space_capacity(site, config.departure, body=config.engine.body)
    if config.robots > capacity.max_robots:
        msg = (
            f'{config.robots} robots do not fit around departure point {capacity.departure!r} '
            f'of site {site.name!r}: its {capacity.area_m2:.0f} m^2 of free space hold at most '
            f'{capacity.max_robots} robots of radius {config.engine.body.robot_radius_m} m'
        )
        raise ConfigurationError(msg)
    if max_robots is not None and config.robots > max_robots:
        msg = (
            f'--robots must be in 1..{max_robots} (one node per robot in this process; '
            f'oabug_batch runs larger swarms), got {config.robots}'
        )
        raise ConfigurationError(msg)


def build_mission(
    config: SpawnSettings, *, max_robots: int | None = None
) -> tuple[MissionSpec, float]:
    """The mission spec of ``config`` and the heading bias it uses.

    Raises:
        ConfigurationError: an unknown site or departure point, or more robots than fit
            around the departure point (:func:`check_site_limits`) or than ``max_robots``.
        swarm_sim.sites.SiteError: the site file or layout is invalid or has no rooms.
    """
    site = load_site(config.site, seed=config.site_seed)
    check_site_limits(config, site, max_robots=max_robots)
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
        params.update(PROFILES[config.profile])
        params.update(config.robot_parameters)
        robots.append(RobotNodeSpec(factory, params, executable=OABUG_EXECUTABLE))
    recording = None
    if config.record is not None:
        topics = list(DEFAULT_RECORD_TOPICS)
        if config.record_robot_topics:
            for i in range(config.robots):
                topics += [f'/r{i}/state', f'/r{i}/cmd_vel', f'/r{i}/pump']
        sensors = [f'/r{i}/{name}' for i in range(config.robots) for name in SENSOR_TOPICS]
        recording = RecordingSpec(
            Path(config.record),
            recorded_topics(config.record_topics, mission=topics, sensors=sensors),
        )
    engine = dataclasses.replace(config.engine, seed=int(config.seed))
    spec = MissionSpec(
        site=site,
        initial_poses=poses,
        robots=robots,
        max_sim_time_s=config.budget_s,
        engine_config=engine,
        recording=recording,
        progress_period_s=min(10.0, max(1.0, config.budget_s / 100.0)),
        time_scale=config.time_scale,
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
    if result.stop_reason == StopReason.INTERRUPTED:
        title += ' (interrupted)'

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
    result = OABugRun(settings=config, mission=mission, heading_bias_rad=bias)
    if config.out_dir is not None:
        result = dataclasses.replace(result, plots=write_run_plots(result, Path(config.out_dir)))
    return result


def write_run_plots(result: OABugRun, out_dir: Path) -> tuple[Path, ...]:
    """Write the PNGs of a run into ``out_dir`` (see :func:`write_plots`)."""
    config = result.settings
    mission = result.mission
    stem = f'oabug_{config.variant}_{config.departure}_{mission.site.name}_seed{config.seed}'
    return write_plots(mission, out_dir, stem)


def _parser() -> argparse.ArgumentParser:
    parser = ToolParser(
        prog='spawn',
        description=(
            'Run an OA-Bug swarm search in the simulator until every room is covered '
            'or the action budget ends; print the coverage summary and write the plots.'
        ),
        epilog=SPAWNER_EXIT_CODES,
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
        '--profile',
        choices=tuple(PROFILES),
        default='tuned',
        help="OA-Bug parameters: 'paper' (Table I read literally) or 'tuned' (the defaults; "
        'departures in docs/oabug.md); --param values apply on top',
    )
    parser.add_argument(
        '--actions',
        type=int,
        default=None,
        help='max actions (0.1 m steps) per robot; default: the preset budget (Small 1000)',
    )
    parser.add_argument('--speed', type=float, default=0.3, help='robot cruise speed [m/s]')
    add_run_options(parser, out_default=Path('oabug_results'), plots='the PNGs')
    parser.add_argument(
        '--param',
        action='append',
        default=[],
        metavar='NAME=VALUE',
        help='set an OA-Bug node parameter for every robot (repeatable), e.g. '
        'gas_threshold=300 or sound_turn_rule=toward; names and defaults: docs/oabug.md',
    )
    add_physics_option(parser)
    add_render_option(parser)
    add_runtime_arguments(parser)
    add_sensor_arguments(parser)
    add_fault_arguments(parser)
    return parser


def main(argv: Sequence[str] | None = None) -> int:
    """Command line entry point; returns the process exit code (module docstring)."""
    return run_tool('spawn', _main, argv)


def _main(argv: list[str]) -> int:
    args = _parser().parse_args(argv)
    config = SpawnSettings(
        robot_parameters=oabug_parameter_overrides(args.param),
        site=args.site,
        site_seed=args.site_seed,
        variant=args.variant,
        robots=args.robots,
        departure=args.departure,
        seed=args.seed,
        profile=args.profile,
        actions=args.actions,
        speed_mps=args.speed,
        record=args.record,
        record_topics=args.record_topics,
        out_dir=None if args.no_plots else args.out,
        time_scale=args.time_scale,
        engine=engine_options(
            args, EngineConfig(physics=args.physics, render=render_config(args.render))
        ),
    )
    require_backend(args.physics)
    check_runtime(args.runtime)
    runner = process_runner(args) or run_mission
    if args.dry_run:
        spec, _ = build_mission(config, max_robots=MAX_ROBOTS)
        with contextlib.suppress(DryRunDone):
            runner(spec)
        return EXIT_SUCCESS
    check_run_outputs(config.record, config.out_dir)
    spec, bias = build_mission(config, max_robots=MAX_ROBOTS)
    for warning in spec.site.warnings:
        print(f'spawn: warning: {warning}', file=sys.stderr, flush=True)
    print(
        f'OA-Bug {config.variant}: {config.robots} robots, site {spec.site.name}, '
        f'{config.departure} departure, budget {config.budget_actions} actions '
        f'= {config.budget_s:.0f} s at {config.speed_mps} m/s',
        flush=True,
    )
    if args.sensors != 'ideal' or config.engine.faults.active:
        print(f'sensors {args.sensors}; faults: {config.engine.faults.describe()}', flush=True)
    if config.robot_parameters:
        settings = ', '.join(f'{k}={v}' for k, v in sorted(config.robot_parameters.items()))
        print(f'OA-Bug parameters other than the defaults: {settings}', flush=True)
    bar = MissionProgressBar(
        f'OA-Bug {config.variant}',
        spec.max_sim_time_s,
        enabled=progress_wanted(args.quiet),
        lines=not args.quiet,
    )
    with bar:
        mission = runner(spec, progress=bar)
    result = OABugRun(settings=config, mission=mission, heading_bias_rad=bias)
    print(format_summary(result), flush=True)
    if mission.bag_path is not None:
        print(f'recorded {mission.bag_path}', flush=True)
    if config.out_dir is not None:
        for path in write_run_plots(result, Path(config.out_dir)):
            print(f'wrote {path}')
    frames = config.engine.render.frames_dir
    if config.engine.render.mode == 'frames' and frames is not None:
        print(f'wrote the frames to {frames} and {frames / "run.gif"}')
    if mission.stop_reason == StopReason.INTERRUPTED:
        fail(
            'spawn',
            f'interrupted at sim time {mission.sim_time_s:.1f} s; the summary covers '
            'the run so far',
        )
        return EXIT_INTERRUPTED
    return EXIT_SUCCESS if mission.coverage >= 1.0 else EXIT_UNFINISHED


if __name__ == '__main__':
    sys.exit(main())
