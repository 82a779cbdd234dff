"""MSC + PF spawner: N robots search for and capture RSSI-emitting targets.

Plain script (``ros2 run swarm_experiments spawn_msc_pf`` or
``python -m swarm_experiments.spawn_msc_pf``). It builds the paper's scenario (Sec. IV-A): an
obstacle-free 2000 m x 2000 m field, targets placed uniformly, robots starting uniformly in a
30 m disc at the centre; starts the sim bridge with the RSSI-target extension and one
``msc_pf`` node per robot on sim time (scheme msc, msc_pf or proposed), relays peer messages
within ``--comm-range`` with ``--loss``, and runs until every target is captured or T_max.
It prints the capture completion time (CCT) and each target's capture time and writes PNGs:
the field with every robot's path and the targets coloured by capture time, and the error of
the robots' PF estimates over time. With ``--record`` it writes a rosbag2 (MCAP) bag from
which ``swarm_analysis.cct.cct_from_bag`` recomputes the CCT.

Example: ``spawn_msc_pf --scheme proposed --robots 15 --targets 10 --seed 1 --out runs/p1``;
``--param msc.leader_rule=pbest --param phases.unheard_updates=true`` changes any other msc_pf
node parameter for every robot (names: ``msc_pf/config/msc_pf.yaml``).

Options, target positions (inside the field) and outputs are checked before the run; a
progress bar shows on a terminal. The capture times are printed before the plots are
written. Exit codes: 0 every target captured, 1 not all by T_max, 2 bad options or input,
130 Ctrl-C (the captures so far are printed and the bag closed).
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
from typing import Any

import numpy as np
from sim_bridge.mission_file import rssi_entry
from sim_bridge.rssi_extension import RssiExtension
from swarm_common.cli import (
    EXIT_INTERRUPTED,
    EXIT_SUCCESS,
    EXIT_UNFINISHED,
    ToolParser,
    fail,
    run_tool,
)
from swarm_common.errors import UsageError
from swarm_sim.engine import EngineConfig, SiteGeometry
from swarm_sim.faults import FaultConfig
from swarm_sim.physics import require_backend
from swarm_sim.rssi_targets import RssiTargetField

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
    MissionProgress,
    MissionResult,
    MissionSpec,
    RecordingSpec,
    RobotNodeSpec,
    StopReason,
    recorded_topics,
    run_mission,
)
from swarm_experiments.msc_pf_batch import scenario_start
from swarm_experiments.node_overrides import parse_overrides
from swarm_experiments.open_field import point_robot_engine_config
from swarm_experiments.processes import DryRunDone, process_runner
from swarm_experiments.progress import MissionProgressBar, progress_wanted
from swarm_experiments.runtime_option import (
    add_runtime_arguments,
    check_runtime,
)

__all__ = ['SCHEMES', 'MscPfRun', 'SpawnSettings', 'controller_parameter_overrides', 'main', 'run']

# msc_pf node parameters the spawner sets from its own options (see node_parameters).
SPAWNER_PARAMETERS = ('scheme', 'seed', 'robot_id', 'field_size_m', 'swarm.comm_range_m')

SCHEMES = ('proposed', 'msc_pf', 'msc')
PEER_TYPE = 'swarm_interfaces/msg/MscPeer'
#: (package, executable) of the MSC + PF node, for ``--processes``.
MSC_PF_EXECUTABLE = ('msc_pf', 'msc_pf_node')
DEFAULT_RECORD_TOPICS = (
    '/clock',
    '/sim/poses',
    '/sim/targets',
    '/r*/state',
    '/r*/cmd_vel',
    '/r*/peers/out',
    *VIEWER_TOPICS,
)
#: The topics the robots' nodes subscribe to (msc_pf.node): what ``--record-topics sensors``
#: adds so that a bag replays into a node.
SENSOR_TOPICS = ('/r*/odom', '/r*/rssi', '/r*/captured', '/r*/peers/in')
#: Largest swarm the spawner runs: every robot is a node in this one process (the paper's
#: sweep goes to 30; msc_pf_batch runs larger swarms without nodes).
MAX_ROBOTS = 100
#: Most targets the spawner places: every robot's node keeps a particle filter per target
#: (the paper's largest scenario has 20; msc_pf_batch has no such limit).
MAX_TARGETS = 100


@dataclass(frozen=True)
class SpawnSettings:
    """One run.

    Attributes:
        scheme: proposed, msc_pf or msc.
        robots: number of robots.
        targets: number of targets (placed uniformly unless ``target_positions_m``).
        seed: seed of targets, robot starts, receiver noise and every controller.
        field_size_m: edge of the square field [m].
        start_radius_m: robots start uniformly in this disc at the centre [m].
        comm_range_m: peer relay range [m] (Table I: 150).
        loss_probability: chance that one relayed peer message is lost.
        max_time_s: T_max [s].
        physics_rate_hz: simulation step rate [Hz].
        target_positions_m: (targets, 2) fixed target positions, or None.
        record: bag directory to write, or None.
        record_topics: what the bag holds
            (:data:`~swarm_experiments.mission.RECORD_TOPIC_SETS`): 'sensors' adds the
            :data:`SENSOR_TOPICS`, 'mission' leaves them out, 'all' records every topic.
        out_dir: where the PNGs go (None: no plots).
        faults: faults injected on purpose (robot dropouts and link faults act through
            the bridge: a dropped robot stops and its peer messages are lost).
        extra_parameters: further msc_pf node parameters (name -> value).
        physics: the engine's physics backend ('numpy' or 'pybullet').
        time_scale: on real rclpy, sim seconds per wall second (MissionSpec.time_scale).
    """

    scheme: str = 'proposed'
    robots: int = 15
    targets: int = 10
    seed: int = 0
    field_size_m: float = 2000.0
    start_radius_m: float = 30.0
    comm_range_m: float = 150.0
    loss_probability: float = 0.0
    max_time_s: float = 30000.0
    physics_rate_hz: float = 10.0
    target_positions_m: np.ndarray | None = None
    record: Path | None = None
    record_topics: str = 'sensors'
    out_dir: Path | None = None
    extra_parameters: dict[str, Any] = field(default_factory=dict)
    physics: str = 'numpy'
    time_scale: float = 1.0
    faults: FaultConfig = field(default_factory=FaultConfig)


@dataclass
class MscPfRun:
    """Outcome of a spawned run.

    Attributes:
        settings: what was run.
        cct_s: capture completion time [s] (NaN if not every target was captured).
        capture_times_s: (targets,) capture time of each target [s] (NaN if not captured).
        target_positions_m: (targets, 2) target positions [m].
        estimate_log: rows (time [s], robot index, target ID, x, y, spread [m], converged).
        mission: the mission runner's result (trajectories, timing).
        robot_nodes: the msc_pf nodes (for inspection).
        plots: PNG files written.
    """

    settings: SpawnSettings
    cct_s: float
    capture_times_s: np.ndarray
    target_positions_m: np.ndarray
    estimate_log: np.ndarray
    mission: Any
    robot_nodes: list[Any]
    plots: list[Path]


def check_settings(settings: SpawnSettings) -> None:
    """Check every setting before a run.

    Raises:
        ExperimentError: an unknown scheme, a count or value out of range, a target position
            outside the field.
    """
    if settings.scheme not in SCHEMES:
        msg = f'unknown scheme {settings.scheme!r}; choose one of {", ".join(SCHEMES)}'
        raise ExperimentError(msg)
    if not 1 <= settings.robots <= MAX_ROBOTS:
        msg = (
            f'--robots must be in 1..{MAX_ROBOTS} (one node per robot in this process; '
            f'msc_pf_batch runs larger swarms), got {settings.robots}'
        )
        raise ExperimentError(msg)
    if not 1 <= settings.targets <= MAX_TARGETS:
        msg = (
            f'--targets must be in 1..{MAX_TARGETS} (a particle filter per target in every '
            f'robot node), got {settings.targets}'
        )
        raise ExperimentError(msg)
    if settings.seed < 0:
        raise ExperimentError(f'--seed must be >= 0, got {settings.seed}')
    for name, value in (
        ('--comm-range', settings.comm_range_m),
        ('--t-max', settings.max_time_s),
        ('field_size_m', settings.field_size_m),
        ('physics_rate_hz', settings.physics_rate_hz),
        ('start_radius_m', settings.start_radius_m),
    ):
        check_finite(name, value, minimum=0.0, above=True)
    if not 0.0 <= settings.loss_probability <= 1.0:
        msg = f'--loss must be a probability in [0, 1], got {settings.loss_probability}'
        raise ExperimentError(msg)
    if settings.target_positions_m is not None:
        positions = np.asarray(settings.target_positions_m, dtype=float).reshape(-1, 2)
        size = settings.field_size_m
        outside = ~np.all((positions >= 0.0) & (positions <= size), axis=1)
        if np.any(outside):
            x, y = positions[int(np.argmax(outside))]
            msg = (
                f'--target-positions: target {int(np.argmax(outside))} at ({x:g}, {y:g}) m lies '
                f'outside the {size:g} m x {size:g} m field (0..{size:g} m on both axes)'
            )
            raise ExperimentError(msg)


def _engine_config(settings: SpawnSettings) -> EngineConfig:
    return point_robot_engine_config(
        physics_rate_hz=settings.physics_rate_hz,
        seed=settings.seed,
        max_linear_speed_mps=1.05,
        physics=settings.physics,
    )


def controller_parameter_overrides(items: Sequence[str]) -> dict[str, Any]:
    """msc_pf controller parameters from ``NAME=VALUE`` items, typed and checked before a run.

    Names are the node's flat ``<section>.<field>`` parameters (``msc.leader_rule``,
    ``phases.unheard_updates``, ...) except those the spawner derives from its own options
    (:data:`SPAWNER_PARAMETERS`: use ``--scheme``, ``--seed``, ``--comm-range``).

    Raises:
        ConfigurationError: a malformed item, an unknown or spawner-set name, a value of the
            wrong type, or one the controller rejects.
    """
    from msc_pf.parameters import MSC_PF_PARAMETERS

    return parse_overrides(items, MSC_PF_PARAMETERS, reserved=SPAWNER_PARAMETERS)


def node_parameters(settings: SpawnSettings, index: int) -> dict[str, Any]:
    """Parameters of robot ``index``'s msc_pf node."""
    params: dict[str, Any] = {
        'scheme': settings.scheme,
        'seed': int(settings.seed),
        'robot_id': index,
        'field_size_m': float(settings.field_size_m),
        'swarm.comm_range_m': float(settings.comm_range_m),
    }
    params.update(settings.extra_parameters)
    return params


def scenario(settings: SpawnSettings) -> tuple[RssiTargetField, np.ndarray]:
    """Targets and (robots, 3) start poses of a run; the same seed gives the same scenario
    (the batch runner's :func:`~swarm_experiments.msc_pf_batch.scenario_start`)."""
    return scenario_start(
        settings.targets,
        settings.seed,
        field_size_m=settings.field_size_m,
        start_radius_m=settings.start_radius_m,
        n_robots=settings.robots,
        target_positions_m=settings.target_positions_m,
    )


def run(
    settings: SpawnSettings,
    progress: Any = None,
    *,
    runner: Callable[..., MissionResult] = run_mission,
) -> MscPfRun:
    """Run one mission; raises a SwarmError on bad settings or a failed run.

    ``runner`` runs the mission spec: :func:`~swarm_experiments.mission.run_mission` (in
    process) or a :mod:`swarm_experiments.processes` runner (one process per node; the
    estimate log, which needs the nodes, is then empty).
    """
    from msc_pf.node import MscPfNode

    check_settings(settings)
    targets, poses = scenario(settings)
    extension = RssiExtension(targets, seed=settings.seed)
    nodes: list[Any] = []
    log: list[tuple[float, ...]] = []

    def factory(**kwargs: Any) -> Any:
        node = MscPfNode(**kwargs)
        nodes.append(node)
        return node

    def on_progress(report: MissionProgress) -> None:
        for index, node in enumerate(nodes):
            out = node.last_output
            if out is None:
                continue
            for e in out.status.estimates:
                x, y = e.position_m
                log.append((report.sim_time_s, index, e.target_id, x, y, e.spread_m, e.converged))
        if progress is not None:
            progress(report)

    recording = None
    if settings.record is not None:
        recording = RecordingSpec(
            Path(settings.record),
            recorded_topics(
                settings.record_topics, mission=DEFAULT_RECORD_TOPICS, sensors=SENSOR_TOPICS
            ),
        )
    site = SiteGeometry(
        walls=np.zeros((0, 2, 2)),
        room_rects=(np.array([[0.0, 0.0, settings.field_size_m, settings.field_size_m]]),),
        name='msc_pf field',
    )
    spec = MissionSpec(
        site=site,
        initial_poses=poses,
        robots=[
            RobotNodeSpec(factory, node_parameters(settings, i), executable=MSC_PF_EXECUTABLE)
            for i in range(len(poses))
        ],
        max_sim_time_s=settings.max_time_s,
        engine_config=dataclasses.replace(_engine_config(settings), faults=settings.faults),
        bridge_parameters={
            'peer_msg_type': PEER_TYPE,
            'comm_range_m': float(settings.comm_range_m),
            'peer_loss_probability': float(settings.loss_probability),
        },
        time_scale=settings.time_scale,
        extensions=[extension],
        extension_entries=[rssi_entry(targets, seed=settings.seed)],
        stop_when_all_rooms_covered=False,
        recording=recording,
        progress_period_s=10.0,
    )
    mission = runner(spec, progress=on_progress)
    times = targets.capture_time_s.copy()
    for outcome in mission.extension_outcomes:  # the bridge ran in a process of its own
        if outcome.get('kind') == 'rssi':
            times = np.array(
                [math.nan if t is None else float(t) for t in outcome['capture_times_s']]
            )
    result = MscPfRun(
        settings=settings,
        cct_s=float(np.max(times)) if np.all(np.isfinite(times)) else math.nan,
        capture_times_s=times,
        target_positions_m=targets.positions_m.copy(),
        estimate_log=np.array(log, dtype=float).reshape(-1, 7),
        mission=mission,
        robot_nodes=nodes,
        plots=[],
    )
    if settings.out_dir is not None:
        result.plots = write_plots(result, Path(settings.out_dir))
    return result


def _save(fig: Any, path: Path) -> None:
    from swarm_common.outputs import atomic_output

    with atomic_output(path) as partial:  # no half-written PNG under the final name
        fig.savefig(partial, dpi=120, bbox_inches='tight')


def write_plots(result: MscPfRun, out_dir: Path) -> list[Path]:
    """Field with paths and targets coloured by capture time; PF estimate errors over time."""
    import matplotlib

    matplotlib.use('Agg')
    import matplotlib.pyplot as plt

    out_dir.mkdir(parents=True, exist_ok=True)
    settings = result.settings
    paths: list[Path] = []

    fig, ax = plt.subplots(figsize=(6.4, 5.6))
    traj = result.mission.trajectories
    for i in range(traj.shape[1]):
        ax.plot(traj[:, i, 0], traj[:, i, 1], lw=0.7, alpha=0.8)
    times = result.capture_times_s
    end = result.mission.sim_time_s
    colours = np.where(np.isnan(times), end, times)
    dots = ax.scatter(
        result.target_positions_m[:, 0],
        result.target_positions_m[:, 1],
        c=colours,
        cmap='plasma',
        vmin=0.0,
        vmax=max(end, 1.0),
        marker='*',
        s=160,
        edgecolors='k',
        zorder=3,
    )
    missed = np.isnan(times)
    if missed.any():
        ax.plot(*result.target_positions_m[missed].T, 'kx', ms=12, label='not captured')
        ax.legend(loc='lower right', fontsize=7)
    fig.colorbar(dots, ax=ax, label='capture time [s]')
    cct = f'CCT {result.cct_s:.0f} s' if not math.isnan(result.cct_s) else 'not all captured'
    if result.mission.stop_reason == StopReason.INTERRUPTED:
        cct += f' (interrupted at {end:.0f} s)'
    ax.set_title(f'{settings.scheme}, {traj.shape[1]} robots, {len(times)} targets: {cct}')
    ax.set_xlim(0.0, settings.field_size_m)
    ax.set_ylim(0.0, settings.field_size_m)
    ax.set_xlabel('x [m]')
    ax.set_ylabel('y [m]')
    ax.set_aspect('equal')
    path = out_dir / 'field_paths.png'
    _save(fig, path)
    plt.close(fig)
    paths.append(path)

    log = result.estimate_log
    if len(log):
        fig, ax = plt.subplots(figsize=(6.4, 4.0))
        for target in np.unique(log[:, 2]).astype(int):
            rows = log[log[:, 2] == target]
            truth = result.target_positions_m[target]
            error = np.hypot(rows[:, 3] - truth[0], rows[:, 4] - truth[1])
            ax.plot(rows[:, 0], error, '.', ms=2, label=f'target {target}')
        ax.set_yscale('log')
        ax.set_xlabel('time [s]')
        ax.set_ylabel('estimate error [m] (every robot)')
        ax.set_title('PF estimates over time')
        ax.legend(fontsize=6, ncol=2)
        path = out_dir / 'pf_estimates.png'
        _save(fig, path)
        plt.close(fig)
        paths.append(path)
    return paths


def build_parser() -> argparse.ArgumentParser:
    """Command-line options of ``spawn_msc_pf``."""
    parser = ToolParser(
        prog='spawn_msc_pf', description=__doc__.split('\n\n')[0], epilog=SPAWNER_EXIT_CODES
    )
    parser.add_argument('--scheme', choices=SCHEMES, default='proposed')
    parser.add_argument('--robots', type=int, default=15)
    parser.add_argument(
        '--targets', type=int, default=None, help='(default 10, or as many as --target-positions)'
    )
    parser.add_argument(
        '--target-positions',
        type=points_argument('--target-positions'),
        default=None,
        help="'x,y;x,y' [m]",
    )
    parser.add_argument('--seed', type=int, default=0)
    parser.add_argument('--comm-range', type=float, default=150.0, help='[m]')
    parser.add_argument('--loss', type=float, default=0.0, help='peer message loss probability')
    parser.add_argument('--t-max', type=float, default=30000.0, help='T_max [s]')
    add_run_options(parser, out_default=Path('msc_pf_run'), plots='the PNGs')
    parser.add_argument(
        '--param',
        action='append',
        default=[],
        metavar='NAME=VALUE',
        help='set an msc_pf controller parameter for every robot (repeatable), e.g. '
        'msc.leader_rule=pbest; names and defaults: msc_pf/config/msc_pf.yaml',
    )
    add_physics_option(parser)
    add_runtime_arguments(parser)
    add_fault_arguments(parser)
    return parser


def main(argv: Sequence[str] | None = None) -> int:
    """Entry point of ``spawn_msc_pf``; returns the exit status (module docstring)."""
    return run_tool('spawn_msc_pf', _main, argv)


def _main(argv: list[str]) -> int:
    args = build_parser().parse_args(argv)
    if args.target_positions is None:
        targets = 10 if args.targets is None else args.targets
    else:
        targets = len(args.target_positions)
        if args.targets is not None and args.targets != targets:
            msg = f'--targets {args.targets} but --target-positions gives {targets} positions'
            raise UsageError(msg)
    require_backend(args.physics)
    check_runtime(args.runtime)
    faults = fault_config(args.fault)
    extra = controller_parameter_overrides(args.param)
    settings = SpawnSettings(
        faults=faults,
        extra_parameters=extra,
        scheme=args.scheme,
        robots=args.robots,
        targets=targets,
        seed=args.seed,
        comm_range_m=args.comm_range,
        loss_probability=args.loss,
        max_time_s=args.t_max,
        target_positions_m=args.target_positions,
        record=args.record,
        record_topics=args.record_topics,
        physics=args.physics,
        time_scale=args.time_scale,
    )
    check_settings(settings)
    runner = process_runner(args) or run_mission
    if args.dry_run:
        with contextlib.suppress(DryRunDone):
            run(settings, runner=runner)
        return EXIT_SUCCESS
    out_dir = None if args.no_plots else args.out
    check_run_outputs(settings.record, out_dir)
    bar = MissionProgressBar(
        f'{settings.scheme}, {settings.robots} robots',
        settings.max_time_s,
        enabled=progress_wanted(args.quiet),
        lines=not args.quiet,
        detail=lambda report: '',
    )
    with bar:
        result = run(settings, progress=bar, runner=runner)
    mission = result.mission
    interrupted = mission.stop_reason == StopReason.INTERRUPTED
    print(
        f'scheme {settings.scheme}, {settings.robots} robots, {targets} targets, seed {args.seed}'
    )
    for target, (pos, t) in enumerate(
        zip(result.target_positions_m, result.capture_times_s, strict=True)
    ):
        when = f'{t:8.0f} s' if not math.isnan(t) else 'not captured'
        print(f'  target {target:2d} at ({pos[0]:6.0f}, {pos[1]:6.0f}) m: {when}')
    if not math.isnan(result.cct_s):
        print(f'CCT: {result.cct_s:.0f} s  (wall {mission.wall_time_s:.1f} s)')
    elif interrupted:
        print(f'CCT: not every target captured by t = {mission.sim_time_s:.0f} s (interrupted)')
    else:
        print(f'CCT: not every target captured by T_max = {settings.max_time_s:.0f} s')
    if settings.record is not None:
        print(f'bag: {settings.record}')
    sys.stdout.flush()
    if out_dir is not None:
        for path in write_plots(result, Path(out_dir)):
            print(f'wrote {path}')
    if math.isnan(result.cct_s) and interrupted:
        fail('spawn_msc_pf', f'interrupted at sim time {mission.sim_time_s:.1f} s')
        return EXIT_INTERRUPTED
    return EXIT_UNFINISHED if math.isnan(result.cct_s) else EXIT_SUCCESS


if __name__ == '__main__':
    sys.exit(main())
