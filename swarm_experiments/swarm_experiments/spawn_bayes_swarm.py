"""Bayes-Swarm spawner: N robots seek the strongest source of a signal field.

Plain script (``ros2 run swarm_experiments spawn_bayes_swarm`` or
``python -m swarm_experiments.spawn_bayes_swarm``). It builds an obstacle-free arena for the chosen
case (the paper's Cases 1-3 or the avalanche field), starts the sim bridge with the signal
extension and one ``bayes_swarm`` node per robot on sim time, relays peer messages within
``--comm-range`` with ``--loss``, and runs until a robot is within eps of the source or T_max.
It prints found or not, tau (Eq. 12) and decision-time statistics, and writes two PNGs: the
signal field with every robot's path, and one robot's GP mean with its waypoints. With
``--record`` it writes a rosbag2 (MCAP) bag from which ``swarm_analysis.tau.tau_from_bag``
recomputes tau.

Example: ``spawn_bayes_swarm --case case1 --robots 5 --seed 1 --out runs/case1``;
``--param horizon_s=20`` changes any other bayes_swarm node parameter for every robot,
including those the case sets.

Options and outputs are checked before the run; a progress bar shows on a terminal. Exit
codes: 0 source found, 1 not found within T_max, 2 bad options or input, 130 Ctrl-C (the
outcome so far is printed and the bag closed).
"""

# ruff: noqa: T201  (main() is a command-line entry point that prints its report)
from __future__ import annotations

import argparse
import contextlib
import dataclasses
import math
import sys
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Any

import numpy as np
from bayes_swarm.controller import robot_seed
from bayes_swarm.planner import first_heading_rad
from bayes_swarm.profiles import PROFILES, profile_options
from bayes_swarm.settings import GlowwormConfig
from sim_bridge.mission_file import signal_entry
from sim_bridge.signal_extension import SignalExtension
from swarm_common.cli import (
    EXIT_INTERRUPTED,
    EXIT_SUCCESS,
    EXIT_UNFINISHED,
    ToolParser,
    fail,
    run_tool,
)
from swarm_sim.engine import EngineConfig, SiteGeometry
from swarm_sim.faults import FaultConfig
from swarm_sim.physics import require_backend
from swarm_sim.signal_fields import CASE_NAMES, SignalCase, UnknownCaseError, get_case
from swarm_sim.signal_mission import SignalMissionModel

from swarm_experiments.bayes_batch import MissionSpec as BatchMissionSpec
from swarm_experiments.bayes_batch import depot_fan
from swarm_experiments.cli_args import (
    SPAWNER_EXIT_CODES,
    add_fault_arguments,
    add_physics_option,
    add_run_options,
    check_finite,
    check_run_outputs,
    fault_config,
    points_argument,
)
from swarm_experiments.errors import ExperimentError
from swarm_experiments.mission import (
    VIEWER_TOPICS,
    MissionResult,
    MissionSpec,
    RecordingSpec,
    RobotNodeSpec,
    StopReason,
    recorded_topics,
    run_mission,
)
from swarm_experiments.node_overrides import parse_overrides
from swarm_experiments.open_field import point_robot_engine_config
from swarm_experiments.processes import DryRunDone, process_runner
from swarm_experiments.progress import MissionProgressBar, progress_wanted
from swarm_experiments.runtime_option import (
    add_runtime_arguments,
    check_runtime,
)

__all__ = [
    'ALGORITHMS',
    'BayesSwarmRun',
    'SpawnSettings',
    'batch_mission_spec',
    'main',
    'node_parameter_overrides',
    'run',
]

# bayes_swarm node parameters the spawner sets from its own options (see node_parameters);
# the ones it takes from the case (arena, speed, horizon, ...) may be overridden.
SPAWNER_PARAMETERS = (
    'algorithm',
    'robot_index',
    'n_robots',
    'seed',
    'noise_std',
)

ALGORITHMS = ('bayes_swarm_p', 'bayes_swarm_o', 'glowworm', 'levy', 'exhaustive')
DEFAULT_RECORD_TOPICS = (
    '/clock',
    '/sim/poses',
    '/sim/source_search',
    '/r*/state',
    '/r*/cmd_vel',
    '/r*/peers/out',
    *VIEWER_TOPICS,
)
#: The topics the robots' nodes subscribe to (bayes_swarm.node): what ``--record-topics sensors``
#: adds so that a bag replays into a node.
SENSOR_TOPICS = ('/r*/odom', '/r*/signal', '/r*/peers/in')
#: Largest swarm the spawner runs: every robot is a node in this one process. The papers'
#: largest swarm is 100 (Case 3); bayes_batch runs larger ones without nodes.
MAX_ROBOTS = 100
#: (package, executable) of the Bayes-Swarm node, for ``--processes``.
BAYES_SWARM_EXECUTABLE = ('bayes_swarm', 'bayes_swarm_node')


@dataclass(frozen=True)
class SpawnSettings:
    """One run.

    Attributes:
        algorithm: one of :data:`ALGORITHMS`.
        case: one of the signal-field cases.
        robots: swarm size (None: the paper's size for the case).
        depots: (d, 2) start points (None: the case's depots).
        seed: seed of the world and of every robot.
        comm_range_m: peer relay range [m] (inf: unlimited).
        loss_probability: chance one relayed peer message is lost.
        noise_std: additive Gaussian measurement noise std.
        relative_noise: measurement noise std as a fraction of |f|.
        max_mission_time_s: T_max (None: the case's).
        profile: Bayes-Swarm settings profile (:data:`bayes_swarm.profiles.PROFILES`:
            'paper', the as-published solvers, or 'grid', the project's).
        record: bag directory to write, or None.
        record_topics: what the bag holds
            (:data:`~swarm_experiments.mission.RECORD_TOPIC_SETS`): 'sensors' adds the
            :data:`SENSOR_TOPICS`, 'mission' leaves them out, 'all' records every topic.
        out_dir: where the PNGs go (None: no plots).
        faults: faults injected on purpose (robot dropouts and link faults act through
            the bridge: a dropped robot stops and its peer messages are lost).
        extra_parameters: further node parameters (name -> value).
        physics: the engine's physics backend ('numpy' or 'pybullet').
        time_scale: on real rclpy, sim seconds per wall second (MissionSpec.time_scale).
    """

    algorithm: str = 'bayes_swarm_p'
    case: str = 'case1'
    robots: int | None = None
    depots: np.ndarray | None = None
    seed: int = 0
    comm_range_m: float = math.inf
    loss_probability: float = 0.0
    noise_std: float = 0.0
    relative_noise: float = 0.0
    max_mission_time_s: float | None = None
    profile: str = 'paper'
    record: Path | None = None
    record_topics: str = 'sensors'
    out_dir: Path | None = None
    extra_parameters: dict[str, Any] = field(default_factory=dict)
    physics: str = 'numpy'
    time_scale: float = 1.0
    faults: FaultConfig = field(default_factory=FaultConfig)


@dataclass
class BayesSwarmRun:
    """Outcome of a spawned run."""

    case: SignalCase
    settings: SpawnSettings
    found: bool
    found_time_s: float
    finder: str
    tau: float
    decision_times_s: dict[str, list[float]]
    robot_nodes: list[Any]
    mission: Any
    plots: list[Path]

    def finder_decision_times_s(self) -> np.ndarray:
        """Decision times of the finder (all robots if none found) [s]."""
        if self.finder:
            return np.array(self.decision_times_s.get(self.finder, []))
        return np.array([t for ts in self.decision_times_s.values() for t in ts])


def _check(settings: SpawnSettings) -> SignalCase:
    if settings.algorithm not in ALGORITHMS:
        msg = f'unknown algorithm {settings.algorithm!r}; choose one of {", ".join(ALGORITHMS)}'
        raise ExperimentError(msg)
    if settings.profile not in PROFILES:
        msg = f'unknown profile {settings.profile!r}; choose one of {", ".join(PROFILES)}'
        raise ExperimentError(msg)
    try:
        case = get_case(settings.case)
    except UnknownCaseError as err:
        raise ExperimentError(str(err)) from err
    if settings.robots is not None and not 1 <= settings.robots <= MAX_ROBOTS:
        msg = (
            f'--robots must be in 1..{MAX_ROBOTS} (one node per robot in this process; '
            f'bayes_batch runs larger swarms), got {settings.robots}'
        )
        raise ExperimentError(msg)
    if settings.seed < 0:
        raise ExperimentError(f'--seed must be >= 0, got {settings.seed}')
    check_finite('--noise', settings.noise_std, minimum=0.0)
    check_finite('--relative-noise', settings.relative_noise, minimum=0.0)
    check_finite('--comm-range', settings.comm_range_m, minimum=0.0, above=True, allow_inf=True)
    if not 0.0 <= settings.loss_probability <= 1.0:
        msg = f'--loss must be a probability in [0, 1], got {settings.loss_probability}'
        raise ExperimentError(msg)
    if settings.max_mission_time_s is not None:
        check_finite('--t-max', settings.max_mission_time_s, minimum=0.0, above=True)
    if settings.depots is not None:
        depots = np.asarray(settings.depots, dtype=float).reshape(-1, 2)
        x0, x1, y0, y1 = case.arena_m
        inside = (depots[:, 0] >= x0) & (depots[:, 0] <= x1)
        inside &= (depots[:, 1] >= y0) & (depots[:, 1] <= y1)
        if not np.all(inside):
            msg = f'depots {depots.tolist()} must lie inside the arena {case.arena_m}'
            raise ExperimentError(msg)
        case = replace(case, depots_m=depots, depot_direction_offsets_deg=(0.0,))
    if settings.max_mission_time_s is not None:
        case = replace(case, max_mission_time_s=float(settings.max_mission_time_s))
    return case


def _arena_site(case: SignalCase) -> SiteGeometry:
    x0, x1, y0, y1 = case.arena_m
    return SiteGeometry(
        walls=np.zeros((0, 2, 2)),
        room_rects=(np.array([[x0, y0, x1, y1]]),),
        name=f'{case.name} arena',
    )


def _engine_config(case: SignalCase, seed: int, physics: str = 'numpy') -> EngineConfig:
    return point_robot_engine_config(
        physics_rate_hz=20.0,
        seed=seed,
        max_linear_speed_mps=1.05 * case.velocity_mps,
        physics=physics,
    )


def _robot_layout(case: SignalCase, n: int) -> list[tuple[np.ndarray, int, int, float]]:
    """Start, first-decision fan index (1-based), fan size and offset of every robot."""
    return [depot_fan(case.depots_m, case.depot_direction_offsets_deg, n, i) for i in range(n)]


def node_parameter_overrides(items: Sequence[str]) -> dict[str, Any]:
    """bayes_swarm node parameters from ``NAME=VALUE`` items, typed and checked before a run.

    Raises:
        ConfigurationError: a malformed item, an unknown or spawner-set name
            (:data:`SPAWNER_PARAMETERS`: use ``--algorithm``, ``--robots``, ``--seed``,
            ``--noise``), a value of the wrong type, or one the node
            rejects.
    """
    from bayes_swarm.node_settings import BAYES_SWARM_PARAMETERS

    return parse_overrides(items, BAYES_SWARM_PARAMETERS, reserved=SPAWNER_PARAMETERS)


def node_parameters(case: SignalCase, settings: SpawnSettings, n: int, i: int) -> dict[str, Any]:
    """Parameters of robot ``i``'s bayes_swarm node for this case."""
    _, fan_index, fan_size, offset = _robot_layout(case, n)[i]
    x0, x1, y0, y1 = case.arena_m
    params: dict[str, Any] = {
        'algorithm': settings.algorithm,
        'robot_index': i,
        'n_robots': n,
        'seed': robot_seed(settings.seed, i),
        'arena_x_min_m': float(x0),
        'arena_x_max_m': float(x1),
        'arena_y_min_m': float(y0),
        'arena_y_max_m': float(y1),
        'velocity_mps': float(case.velocity_mps),
        'horizon_s': float(case.horizon_s),
        'observation_rate_hz': float(case.observation_rate_hz),
        'detection_radius_m': float(case.detection_radius_m),
        'max_mission_time_s': float(case.max_mission_time_s),
        'initial_direction_range_deg': float(case.direction_range_deg),
        'initial_direction_offset_deg': float(offset),
        'fan_index': int(fan_index),
        'fan_size': int(fan_size),
        'signal_scale': float(case.signal_scale),
        'max_signal': float(case.max_signal),
        'lipschitz': float(case.lipschitz),
        'noise_std': float(max(1e-3, settings.noise_std / case.signal_scale)),
        'dimensionless_acquisition': case.dimensionless_acquisition,
    }
    params.update(profile_options(settings.profile))
    params.update(settings.extra_parameters)
    return params


def batch_mission_spec(
    case: SignalCase,
    *,
    noise_std: float = 0.0,
    comm_range_m: float | None = None,
    partition: str = 'strips',
    planner_options: dict[str, Any] | None = None,
    profile: str = 'paper',
) -> Any:
    """The case as a spec of the ROS-free batch simulator (:mod:`swarm_experiments.bayes_batch`).

    The planners get the case's settings (arena, V, T, f_Hz, eps, T_max, delta theta, the
    signal scale, M, L), never its source; the ``profile``'s options and then
    ``planner_options`` override BayesSwarmConfig fields. With measurement noise the GP noise
    term is raised to it (over the signal scale) unless ``planner_options`` sets ``gp``.
    """
    from bayes_swarm.settings import Arena, BayesSwarmConfig, ExhaustiveConfig

    planner = BayesSwarmConfig(
        arena=Arena(*case.arena_m),
        velocity_mps=case.velocity_mps,
        horizon_s=case.horizon_s,
        observation_rate_hz=case.observation_rate_hz,
        detection_radius_m=case.detection_radius_m,
        max_mission_time_s=case.max_mission_time_s,
        initial_direction_range_deg=case.direction_range_deg,
        signal_scale=case.signal_scale,
        max_signal=case.max_signal,
        lipschitz=case.lipschitz,
        dimensionless_acquisition=case.dimensionless_acquisition,
    )
    options = {**profile_options(profile), **(planner_options or {})}
    if noise_std > 0.0:
        # The GP's noise is in the belief's units (the signal over signal_scale).
        scale = float(options.get('signal_scale', planner.signal_scale))
        options.setdefault(
            'gp', replace(planner.gp, noise_std=max(noise_std / scale, planner.gp.noise_std))
        )
    return BatchMissionSpec(
        field=case.field,
        source_m=case.source_m,
        depots_m=case.depots_m,
        planner=replace(planner, **options),
        depot_direction_offsets_deg=case.depot_direction_offsets_deg,
        noise_std=noise_std,
        comm_range_m=comm_range_m,
        exhaustive=ExhaustiveConfig(partition=partition),
    )


def _initial_yaw(case: SignalCase, fan_index: int, fan_size: int, offset: float) -> float:
    """The robot starts facing its first leg (the planner's TAKEFIRSTDECISION heading)."""
    return first_heading_rad(
        fan_index=fan_index,
        fan_size=fan_size,
        direction_range_deg=case.direction_range_deg,
        direction_offset_deg=offset,
    )


def check_settings(settings: SpawnSettings) -> SignalCase:
    """The case of ``settings`` once every setting is checked (nothing runs).

    Raises:
        ExperimentError: an unknown algorithm or case, a value out of range, a depot outside
            the arena.
    """
    return _check(settings)


def run(
    settings: SpawnSettings,
    progress: Any = None,
    *,
    runner: Callable[..., MissionResult] = run_mission,
) -> BayesSwarmRun:
    """Run one mission; raises a SwarmError on bad settings or a failed run.

    ``runner`` runs the mission spec: :func:`~swarm_experiments.mission.run_mission` (in
    process) or a :mod:`swarm_experiments.processes` runner (one process per node; the
    decision times, which need the nodes, are then empty).
    """
    from bayes_swarm.node import BayesSwarmNode

    case = _check(settings)
    if settings.algorithm == 'glowworm':
        # Glowworm nodes decide at their decision rate (100 Hz, the paper's observation
        # frequency) on fresh samples: the signal is published at that rate.
        case = replace(case, observation_rate_hz=GlowwormConfig().decision_rate_hz)
    n = settings.robots or case.default_robots
    layout = _robot_layout(case, n)
    poses = np.array(
        [[s[0], s[1], _initial_yaw(case, fi, fs, off)] for s, fi, fs, off in layout], dtype=float
    )
    model = SignalMissionModel(
        case,
        noise_std=settings.noise_std,
        relative_noise=settings.relative_noise,
        seed=settings.seed,
    )
    nodes: list[Any] = []

    def factory(**kwargs: Any) -> Any:
        node = BayesSwarmNode(**kwargs)
        nodes.append(node)
        return node

    peer_type = {
        'bayes_swarm_p': 'swarm_interfaces/msg/BayesSwarmPeer',
        'bayes_swarm_o': 'swarm_interfaces/msg/BayesSwarmPeer',
        'glowworm': 'swarm_interfaces/msg/GlowwormPeer',
    }.get(settings.algorithm, '')
    bridge_parameters: dict[str, Any] = {'peer_msg_type': peer_type}
    if peer_type:
        bridge_parameters['comm_range_m'] = float(settings.comm_range_m)
        bridge_parameters['peer_loss_probability'] = float(settings.loss_probability)
    recording = None
    if settings.record is not None:
        recording = RecordingSpec(
            Path(settings.record),
            recorded_topics(
                settings.record_topics, mission=DEFAULT_RECORD_TOPICS, sensors=SENSOR_TOPICS
            ),
        )
    spec = MissionSpec(
        site=_arena_site(case),
        initial_poses=poses,
        robots=[
            RobotNodeSpec(
                factory, node_parameters(case, settings, n, i), executable=BAYES_SWARM_EXECUTABLE
            )
            for i in range(n)
        ],
        max_sim_time_s=case.max_mission_time_s + 2.0,
        engine_config=dataclasses.replace(
            _engine_config(case, settings.seed, settings.physics), faults=settings.faults
        ),
        bridge_parameters=bridge_parameters,
        time_scale=settings.time_scale,
        extensions=[SignalExtension(model)],
        extension_entries=[
            signal_entry(
                case,
                noise_std=settings.noise_std,
                relative_noise=settings.relative_noise,
                seed=settings.seed,
            )
        ],
        stop_when_all_rooms_covered=False,
        recording=recording,
        progress_period_s=max(1.0, case.max_mission_time_s / 20.0),
    )
    mission = runner(spec, progress=progress)
    names = tuple(f'r{i}' for i in range(n))
    times = {
        name: [d.compute_time_s for d in node.decisions]
        for name, node in zip(names, nodes, strict=False)
    }
    found, found_time_s, finder, tau = model.found, model.found_time_s, model.finder, model.tau()
    for outcome in mission.extension_outcomes:  # the bridge ran in a process of its own
        if outcome.get('kind') == 'signal':
            found, finder = bool(outcome['found']), int(outcome['finder'])
            found_time_s = _float(outcome['found_time_s'])
            tau = _float(outcome['tau'])
    result = BayesSwarmRun(
        case=case,
        settings=settings,
        found=found,
        found_time_s=found_time_s,
        finder=names[finder] if found else '',
        tau=tau,
        decision_times_s=times,
        robot_nodes=nodes,
        mission=mission,
        plots=[],
    )
    if settings.out_dir is not None:
        result.plots = write_plots(result, Path(settings.out_dir))
    return result


def _float(value: float | None) -> float:
    return math.nan if value is None else float(value)


def _save(fig: Any, path: Path) -> None:
    from swarm_common.outputs import atomic_output

    with atomic_output(path) as partial:  # no half-written PNG under the final name
        fig.savefig(partial, dpi=120, bbox_inches='tight')


def write_plots(result: BayesSwarmRun, out_dir: Path) -> list[Path]:
    """Signal field with paths, and one robot's GP mean with its waypoints (PNG files)."""
    import matplotlib

    matplotlib.use('Agg')
    import matplotlib.pyplot as plt

    out_dir.mkdir(parents=True, exist_ok=True)
    case = result.case
    x0, x1, y0, y1 = case.arena_m
    gx, gy = np.meshgrid(np.linspace(x0, x1, 120), np.linspace(y0, y1, 120))
    grid = np.column_stack([gx.ravel(), gy.ravel()])
    field_values = np.asarray(case.field(grid)).reshape(gx.shape)
    paths: list[Path] = []

    fig, ax = plt.subplots(figsize=(6, 5.4))
    contour = ax.contourf(gx, gy, field_values, levels=30, cmap='viridis')
    fig.colorbar(contour, ax=ax, label='signal')
    traj = result.mission.trajectories
    for i in range(traj.shape[1]):
        ax.plot(traj[:, i, 0], traj[:, i, 1], lw=1.2, label=f'r{i}' if i < 10 else None)
    ax.plot(*case.source_m, marker='*', color='red', ms=14, ls='none', label='source')
    ax.plot(case.depots_m[:, 0], case.depots_m[:, 1], 'ks', ms=6, label='depot')
    status = f'tau = {result.tau:.2f}' if result.found else 'not found'
    if result.mission.stop_reason == StopReason.INTERRUPTED:
        status += f' (interrupted at {result.mission.sim_time_s:.0f} s)'
    ax.set_title(f'{case.name}, {result.settings.algorithm}, {traj.shape[1]} robots: {status}')
    ax.set_xlabel('x [m]')
    ax.set_ylabel('y [m]')
    ax.set_aspect('equal')
    ax.legend(fontsize=7, loc='lower right')
    path = out_dir / 'field_paths.png'
    _save(fig, path)
    plt.close(fig)
    paths.append(path)

    index = int(result.finder[1:]) if result.finder else 0
    # With one process per node the nodes are not here: no GP plot.
    node = result.robot_nodes[index] if index < len(result.robot_nodes) else None
    planner = getattr(node, 'planner', None)
    if planner is not None and planner.gp.n_samples:
        mean, _ = planner.gp.predict(grid)
        fig, ax = plt.subplots(figsize=(6, 5.4))
        contour = ax.contourf(gx, gy, mean.reshape(gx.shape), levels=30, cmap='magma')
        fig.colorbar(contour, ax=ax, label='GP mean')
        pts = planner.gp.training_inputs
        ax.plot(pts[:, 0], pts[:, 1], 'k.', ms=2, label='observations')
        wps = np.array([d.waypoint_m for d in node.decisions])
        ax.plot(wps[:, 0], wps[:, 1], 'cs-', ms=5, lw=1, label='waypoints')
        ax.plot(*case.source_m, marker='*', color='lime', ms=14, ls='none', label='source')
        ax.set_title(f'r{index}: GP mean at its last decision')
        ax.set_aspect('equal')
        ax.legend(fontsize=7, loc='lower right')
        path = out_dir / f'r{index}_gp_mean.png'
        _save(fig, path)
        plt.close(fig)
        paths.append(path)
    return paths


def build_parser() -> argparse.ArgumentParser:
    """Command-line options of ``spawn_bayes_swarm``."""
    parser = ToolParser(
        prog='spawn_bayes_swarm', description=__doc__.split('\n\n')[0], epilog=SPAWNER_EXIT_CODES
    )
    parser.add_argument('--algorithm', choices=ALGORITHMS, default='bayes_swarm_p')
    parser.add_argument('--case', choices=CASE_NAMES, default='case1')
    parser.add_argument('--robots', type=int, default=None, help='swarm size (paper default)')
    parser.add_argument(
        '--depots', type=points_argument('--depots'), default=None, help="'x,y;x,y' [m]"
    )
    parser.add_argument('--seed', type=int, default=0)
    parser.add_argument('--comm-range', type=float, default=math.inf, help='[m], default inf')
    parser.add_argument('--loss', type=float, default=0.0, help='peer message loss probability')
    parser.add_argument('--noise', type=float, default=0.0, help='measurement noise std')
    parser.add_argument('--relative-noise', type=float, default=0.0, help='noise std / |f|')
    parser.add_argument('--t-max', type=float, default=None, help='T_max [s] (case default)')
    parser.add_argument(
        '--profile', choices=tuple(PROFILES), default='paper', help='Bayes-Swarm settings profile'
    )
    add_run_options(parser, out_default=Path('bayes_swarm_run'), plots='the PNGs')
    parser.add_argument(
        '--param',
        action='append',
        default=[],
        metavar='NAME=VALUE',
        help='set a bayes_swarm node parameter for every robot (repeatable), e.g. '
        'horizon_s=20; names and defaults: ros2 param describe, or bayes_swarm.node_settings',
    )
    add_physics_option(parser)
    add_runtime_arguments(parser)
    add_fault_arguments(parser)
    return parser


def main(argv: Sequence[str] | None = None) -> int:
    """Entry point of ``spawn_bayes_swarm``; returns the exit status (module docstring)."""
    return run_tool('spawn_bayes_swarm', _main, argv)


def _main(argv: list[str]) -> int:
    args = build_parser().parse_args(argv)
    require_backend(args.physics)
    check_runtime(args.runtime)
    faults = fault_config(args.fault)
    extra = node_parameter_overrides(args.param)
    settings = SpawnSettings(
        faults=faults,
        extra_parameters=extra,
        algorithm=args.algorithm,
        case=args.case,
        robots=args.robots,
        depots=args.depots,
        seed=args.seed,
        comm_range_m=args.comm_range,
        loss_probability=args.loss,
        noise_std=args.noise,
        relative_noise=args.relative_noise,
        max_mission_time_s=args.t_max,
        profile=args.profile,
        record=args.record,
        record_topics=args.record_topics,
        physics=args.physics,
        time_scale=args.time_scale,
    )
    case = check_settings(settings)
    runner = process_runner(args) or run_mission
    if args.dry_run:
        with contextlib.suppress(DryRunDone):
            run(settings, runner=runner)
        return EXIT_SUCCESS
    out_dir = None if args.no_plots else args.out
    check_run_outputs(settings.record, out_dir)
    bar = MissionProgressBar(
        f'{settings.algorithm} {case.name}',
        case.max_mission_time_s,
        enabled=progress_wanted(args.quiet),
        lines=not args.quiet,
        detail=lambda report: '',
    )
    with bar:
        result = run(settings, progress=bar, runner=runner)
    mission = result.mission
    times = result.finder_decision_times_s()
    print(f'case {result.case.name}, {result.settings.algorithm}, seed {settings.seed}')
    if result.found:
        print(
            f'found by {result.finder} at t = {result.found_time_s:.2f} s, tau = {result.tau:.3f}'
        )
    elif mission.stop_reason == StopReason.INTERRUPTED:
        print(f'not found by t = {mission.sim_time_s:.1f} s (interrupted)')
    else:
        print(f'not found within T_max = {result.case.max_mission_time_s:g} s')
    if times.size:
        who = result.finder or 'all robots'
        print(
            f'decision time ({who}, {times.size} decisions): '
            f'median {np.median(times) * 1e3:.1f} ms, mean {np.mean(times) * 1e3:.1f} ms, '
            f'max {np.max(times) * 1e3:.1f} ms'
        )
    if settings.record is not None:
        print(f'recorded {settings.record}')
    sys.stdout.flush()
    if out_dir is not None:
        for path in write_plots(result, Path(out_dir)):
            print(f'wrote {path}')
    if mission.stop_reason == StopReason.INTERRUPTED and not result.found:
        fail('spawn_bayes_swarm', f'interrupted at sim time {mission.sim_time_s:.1f} s')
        return EXIT_INTERRUPTED
    return EXIT_SUCCESS if result.found else EXIT_UNFINISHED


if __name__ == '__main__':
    sys.exit(main())
