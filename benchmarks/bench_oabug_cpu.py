"""CPU per OA-Bug run: this suite's batch path against the authors' grid simulator, interleaved.

For each site index the two simulators run the same configuration one after the other in
this one process (grid, then ours), so both see the same machine load; each run's CPU time
is ``time.process_time`` around it. The authors' simulator is imported from a checkout the
user provides (``--simulator DIR``, needs pygame), as in ``reference_oabug_grid.py``. Our
runs are :func:`swarm_experiments.oabug_batch.run_spawn_batch` missions with the site index
as site seed and run seed (the Fig. 4 study's runs). Example (one Small run of 10 robots at
the full budget, 10 sites)::

    python benchmarks/bench_oabug_cpu.py --simulator ../SwarmSearchSimulation --sites 10

``--ours-only`` skips the grid (no checkout needed) and ``--profile FILE`` writes a cProfile
of our runs to FILE. ``--breakdown`` times the parts of our runs instead (``process_time``
around the engine's step and sensor models and the robots' feature extraction, control
loop and controller; cProfile inflates the Python-heavy parts, this does not, but the
timers cost a little of their own). ``--repeat N`` runs every site N times on both
simulators (alternating) and keeps each one's least CPU time: on a machine shared with
other jobs, the least time of a few runs is the one least disturbed by them.

Both simulators end a run when every room is covered, so a configuration whose robots leave a
room unfound longer (or never) runs longer in both and the ratio mixes the simulators' speed
with the robots' search. ``--full-budget`` runs every mission to the end of its budget in
both (the grid's action budget, our sim-time budget, the Table II budget in each) and so
compares the cost of simulating the same mission length.
"""

from __future__ import annotations

import argparse
import cProfile
import gc
import statistics
import sys
import time
from collections.abc import Callable, Sequence
from pathlib import Path
from typing import Any

sys.path.insert(0, str(Path(__file__).resolve().parent))


def _ours(
    site: int,
    config: str,
    variant: str,
    departure: str,
    robots: int,
    profile: str,
    full_budget: bool = False,
):
    import dataclasses

    from swarm_experiments.oabug_batch import run_oabug_batch, run_spawn_batch
    from swarm_experiments.spawn import SpawnSettings, run

    settings = SpawnSettings(
        site=config,
        site_seed=site,
        variant=variant,
        robots=robots,
        departure=departure,
        seed=site,
        profile=profile,
    )
    if not full_budget:
        return run_spawn_batch(settings)

    def whole_budget(spec: Any, **kwargs: Any) -> Any:
        return run_oabug_batch(
            dataclasses.replace(spec, stop_when_all_rooms_covered=False), **kwargs
        )

    return run(settings, runner=whole_budget)


# The parts --breakdown times: (label, module, class or None, function), nested parts
# indented under the part that calls them.
_PARTS = (
    ('engine step (world and sensors)', 'swarm_sim.engine', 'SimEngine', 'step'),
    ('  lidar', 'swarm_sim.sensors.lidar', 'LidarModel', 'measure'),
    ('    near cast', 'swarm_sim.geometry', 'RayCaster', 'scan_near'),
    ('    noise (without the draws)', 'swarm_sim.sensors.lidar', 'LidarModel', '_near_noise'),
    ('  AoA bearings', 'swarm_sim.sensors.bearings', 'BearingModel', 'measure_cycle'),
    ('  scent concentration', 'swarm_sim.sensors.scent', 'ScentField', 'concentration'),
    ('  gas sensors', 'swarm_sim.sensors.gas_sensor', 'Mp503Model', 'update'),
    ('  physics', 'swarm_sim.physics', 'NumpyPhysics', 'step'),
    ('  coverage', 'swarm_sim.ground_truth', 'CoverageTracker', 'update'),
    ('readings to the robots, commands', 'swarm_experiments.oabug_batch', None, '_deliver'),
    ('  scan features', 'swarm_experiments.oabug_batch', None, 'extract_features'),
    ('    features kernel', 'oabug_robot.scan_features_kernel', None, 'features_kernel'),
    ('    select kernel', 'oabug_robot.scan_features_kernel', None, 'select_kernel'),
    ('  control steps', 'oabug_robot.robot_loop', 'RobotLoop', 'command'),
    ('    OA-Bug controller', 'oabug_robot.fsm', 'OABugFsm', 'step'),
)


def _time_parts() -> dict[str, float]:
    """Wrap the :data:`_PARTS` with process_time accumulators; returns the totals [s]."""
    import functools
    import importlib

    totals = {label: 0.0 for label, *_ in _PARTS}
    for label, module_name, class_name, name in _PARTS:
        module = importlib.import_module(module_name)
        owner = getattr(module, class_name) if class_name else module
        original = getattr(owner, name)

        def timed(
            *args: Any, _original: Callable[..., Any] = original, _label: str = label, **kwargs: Any
        ) -> Any:
            start = time.process_time()
            try:
                return _original(*args, **kwargs)
            finally:
                totals[_label] += time.process_time() - start

        setattr(owner, name, functools.wraps(original)(timed))
    return totals


def main(argv: Sequence[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split('\n\n')[0])
    parser.add_argument('--simulator', type=Path, help="the authors' simulator checkout")
    parser.add_argument('--ours-only', action='store_true', help='skip the grid simulator')
    parser.add_argument('--config', choices=('small', 'medium', 'big'), default='small')
    parser.add_argument('--variant', default='gas_sound')
    parser.add_argument('--departure', choices=('center', 'edge'), default='center')
    parser.add_argument('--robots', type=int, default=10)
    parser.add_argument('--sites', type=int, default=10)
    parser.add_argument('--first-site', type=int, default=0)
    parser.add_argument('--oabug-profile', choices=('paper', 'tuned'), default='paper')
    parser.add_argument('--profile', type=Path, help='write a cProfile of our runs here')
    parser.add_argument(
        '--repeat', type=int, default=1, help='runs per site and simulator; the least CPU counts'
    )
    parser.add_argument('--breakdown', action='store_true', help='time the parts of our runs')
    parser.add_argument(
        '--full-budget',
        action='store_true',
        help='run every mission to the end of its budget (no stop when all rooms are covered)',
    )
    args = parser.parse_args(argv)
    if not args.ours_only and args.simulator is None:
        parser.error('give --simulator DIR or --ours-only')
    if args.repeat < 1 or args.sites < 1 or args.robots < 1:
        parser.error('--repeat, --sites and --robots must be at least 1')
    grid = None
    if not args.ours_only:
        from reference_oabug_grid import CONFIGS, GridSimulator, SimulatorMissingError

        try:
            grid = GridSimulator(args.simulator.resolve(), CONFIGS[args.config], 'right')
        except SimulatorMissingError as error:
            parser.error(str(error))
    # Warm-up: imports, numba compilation, caches.
    _ours(0, args.config, args.variant, args.departure, 2, args.oabug_profile)
    if grid is not None:
        grid.run(args.first_site, args.variant, args.departure, 2)
    gc.collect()
    profiler = cProfile.Profile() if args.profile else None
    parts = _time_parts() if args.breakdown else None
    ours_cpu: list[float] = []
    grid_cpu: list[float] = []
    ours_cov: list[float] = []
    ours_sim_s: list[float] = []  # mission length [s of sim time]
    ours_timed = 0.0  # CPU of all our runs, repeats included
    grid_cov: list[float] = []
    grid_actions: list[int] = []  # mission length [actions per robot]
    for site in range(args.first_site, args.first_site + args.sites):
        grid_times: list[float] = []
        ours_times: list[float] = []
        for _ in range(args.repeat):
            if grid is not None:
                start = time.process_time()
                run = grid.run(
                    site, args.variant, args.departure, args.robots, full_budget=args.full_budget
                )
                grid_times.append(time.process_time() - start)
            start = time.process_time()
            if profiler is not None:
                profiler.enable()
            result = _ours(
                site,
                args.config,
                args.variant,
                args.departure,
                args.robots,
                args.oabug_profile,
                args.full_budget,
            )
            if profiler is not None:
                profiler.disable()
            ours_times.append(time.process_time() - start)
        if grid is not None:
            grid_cpu.append(min(grid_times))
            grid_cov.append(run.coverage_pct)
            grid_actions.append(run.actions)
        ours_cpu.append(min(ours_times))
        ours_timed += sum(ours_times)
        ours_cov.append(100.0 * result.coverage)
        ours_sim_s.append(result.mission.sim_time_s)
        line = (
            f'site {site}: ours {ours_cpu[-1]:.3f} CPU s ({ours_cov[-1]:.1f} %, '
            f'{ours_sim_s[-1]:.0f} s)'
        )
        if grid is not None:
            line += (
                f', grid {grid_cpu[-1]:.3f} CPU s ({grid_cov[-1]:.1f} %, '
                f'{grid_actions[-1]} actions)'
            )
        print(line, flush=True)
    what = (
        f'{args.config}, {args.variant}, {args.robots} robots from the {args.departure}, '
        f'{args.sites} sites from {args.first_site}, profile {args.oabug_profile}'
    )
    if args.full_budget:
        what += ', every run to the end of its budget'
    if args.repeat > 1:
        what += f', least CPU of {args.repeat} runs each'
    print(f'\n{what}')
    print(
        f'ours: {statistics.mean(ours_cpu):.3f} CPU s per run (median '
        f'{statistics.median(ours_cpu):.3f}), coverage {statistics.mean(ours_cov):.1f} %, '
        f'{statistics.mean(ours_sim_s):.0f} s of sim time'
    )
    if grid is not None:
        print(
            f'grid: {statistics.mean(grid_cpu):.3f} CPU s per run (median '
            f'{statistics.median(grid_cpu):.3f}), coverage {statistics.mean(grid_cov):.1f} %, '
            f'{statistics.mean(grid_actions):.0f} actions'
        )
        print(
            f'ratio ours / grid: {sum(ours_cpu) / sum(grid_cpu):.2f} (sum of CPU), '
            f'{statistics.median(ours_cpu) / statistics.median(grid_cpu):.2f} (medians)'
        )
    if parts is not None:
        runs = args.sites * args.repeat
        print(f'\nwhere the CPU of our runs went ({ours_timed / runs:.3f} CPU s per timed run):')
        for label, seconds in parts.items():
            print(f'  {label:36s} {seconds / runs:7.3f} s  {100 * seconds / ours_timed:5.1f} %')
    if profiler is not None:
        profiler.dump_stats(str(args.profile))
        print(f'wrote {args.profile}')
    return 0


if __name__ == '__main__':
    sys.exit(main())
