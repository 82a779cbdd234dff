"""OA-Bug benchmark: coverage of the five Table I variants on generated sites, and throughput.

Runs every (site, variant, departure) combination, one run per worker process at a time, and
prints the mean +- std coverage beside the authors' simulator measured on this project's
machines (REFERENCE_OABUG_SIM.md §5), plus CPU and wall seconds per run, robot-metres
simulated per wall second and the projected time of the 1000-run Small sweep. ``--path
batch`` (the default) runs each mission on the batch path (:mod:`swarm_experiments.oabug_batch`:
the same engine and OA-Bug controller without the runtime, equal trajectories); ``--path
ros`` runs the full simulation (sim bridge + OA-Bug nodes on the built-in runtime). Example
(the Small sweep of the closing note, 20 sites, both cores)::

    python benchmarks/bench_oabug.py --config small --sites 20 --workers 2 --out small.md

With ``--out small.md`` every run is also written to ``small.csv`` (one row per site,
departure and variant), so two sweeps on the same sites can be compared run by run.

``--set NAME=VALUE ...`` runs every mission with OA-Bug node parameters other than the
defaults (e.g. ``--set gas_threshold=300 sound_turn_rule=toward``); they are typed and checked
before the first run and printed under the table.
"""

from __future__ import annotations

import argparse
import csv
import gc
import math
import multiprocessing
import sys
import time
from collections import defaultdict
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

VARIANTS = ('random', 'minimum', 'sound', 'gas', 'gas_sound')
DEPARTURES = ('center', 'edge')
PATHS = ('batch', 'ros')
SWEEP_RUNS = 1000


@dataclass(frozen=True)
class ReferenceSweep:
    """The authors' simulator on one configuration and robot count (Table II budget).

    Attributes:
        sites: how many generated sites the figures average over.
        section: where REFERENCE_OABUG_SIM.md gives them.
        coverage: (departure, variant) -> mean and population std of coverage [%].
    """

    sites: int
    section: str
    coverage: dict[tuple[str, str], tuple[float, float]]


def _reference(
    sites: int, section: str, center: Sequence[float], edge: Sequence[float]
) -> ReferenceSweep:
    """A sweep from (mean, std) pairs listed in VARIANTS order per departure."""
    coverage = {}
    for departure, values in (('center', center), ('edge', edge)):
        for i, variant in enumerate(VARIANTS):
            coverage[(departure, variant)] = (values[2 * i], values[2 * i + 1])
    return ReferenceSweep(sites, section, coverage)


# The authors' simulator as measured for this project (REFERENCE_OABUG_SIM.md §5), keyed by
# (configuration, robots). Mean and std of coverage [%] in the order random, minimum, sound,
# gas, gas_sound. Only figures measured at the Table II budget are listed.
REFERENCE: dict[tuple[str, int], ReferenceSweep] = {
    ('small', 10): _reference(
        100,
        '§5.1',
        (15.53, 6.17, 28.17, 7.53, 33.20, 7.70, 96.07, 7.14, 96.27, 5.40),
        (8.10, 4.99, 20.33, 7.36, 25.57, 9.76, 84.17, 21.07, 95.43, 6.64),
    ),
    ('small', 8): _reference(
        30,
        '§5.3',
        (13.4, 5.6, 24.9, 8.5, 27.8, 9.7, 95.7, 7.5, 95.6, 5.3),
        (7.9, 6.1, 16.0, 8.5, 21.1, 9.7, 81.3, 22.3, 94.4, 7.1),
    ),
    ('small', 6): _reference(
        30,
        '§5.3',
        (11.6, 4.3, 19.7, 7.6, 22.2, 7.3, 93.9, 11.6, 92.7, 7.6),
        (7.1, 4.9, 15.3, 7.3, 18.9, 8.5, 75.4, 27.2, 90.7, 9.8),
    ),
    ('small', 4): _reference(
        30,
        '§5.3',
        (7.7, 4.6, 14.6, 8.1, 15.3, 6.2, 93.7, 10.7, 91.3, 8.6),
        (5.8, 4.4, 11.6, 4.8, 13.7, 6.4, 71.3, 22.0, 89.1, 12.9),
    ),
    ('small', 2): _reference(
        30,
        '§5.3',
        (5.8, 3.7, 7.6, 5.2, 7.3, 3.9, 82.2, 15.8, 72.9, 19.3),
        (3.8, 3.6, 6.7, 4.0, 7.1, 4.2, 72.2, 21.5, 59.4, 25.1),
    ),
    ('medium', 10): _reference(
        20,
        '§5.2',
        (14.00, 4.52, 17.25, 4.63, 19.25, 4.55, 93.75, 5.62, 92.25, 4.51),
        (10.75, 3.63, 13.50, 5.05, 13.83, 6.28, 74.75, 27.09, 88.25, 6.66),
    ),
    ('big', 10): _reference(
        10,
        '§5.4',
        (11.58, 3.81, 8.58, 1.40, 10.17, 2.13, 92.75, 3.12, 85.17, 4.39),
        (8.25, 2.78, 5.42, 3.06, 7.00, 2.18, 76.42, 18.37, 80.58, 8.43),
    ),
}


def reference_for(config: str, robots: int, actions: int | None) -> ReferenceSweep | None:
    """The authors' figures comparable with a sweep, or None (other robots or budget)."""
    from swarm_sim.site_loading import site_budget_actions

    if actions is not None and actions != site_budget_actions(config):
        return None
    return REFERENCE.get((config, robots))


@dataclass(frozen=True)
class Job:
    """One simulated run."""

    config: str
    site_seed: int
    variant: str
    departure: str
    robots: int
    actions: int | None
    speed_mps: float
    path: str = 'batch'
    parameters: tuple[tuple[str, object], ...] = ()


@dataclass(frozen=True)
class Outcome:
    """What one run produced."""

    job: Job
    coverage: float
    sim_time_s: float
    wall_time_s: float
    cpu_time_s: float
    robot_metres: float


def quiet_garbage_collector() -> None:
    """Collect cyclic garbage rarely in a sweep process (results do not change).

    A mission allocates many short-lived small objects (readings, commands, features) and
    hardly any reference cycles, so Python's default young-generation threshold of 700
    allocations runs the collector thousands of times per run for nothing; the objects
    alive after the imports are frozen out of every collection.
    """
    gc.collect()
    gc.freeze()
    gc.set_threshold(100_000, 50, 100)


def run_job(job: Job) -> Outcome:
    """Run one job headless (called in a worker process)."""
    from swarm_experiments.oabug_batch import run_spawn_batch
    from swarm_experiments.spawn import SpawnSettings, run

    config = SpawnSettings(
        site=job.config,
        site_seed=job.site_seed,
        variant=job.variant,
        robots=job.robots,
        departure=job.departure,
        seed=job.site_seed,
        actions=job.actions,
        speed_mps=job.speed_mps,
        robot_parameters=dict(job.parameters),
    )
    start = time.perf_counter()
    start_cpu = time.process_time()
    result = run_spawn_batch(config) if job.path == 'batch' else run(config)
    cpu = time.process_time() - start_cpu
    wall = time.perf_counter() - start
    return Outcome(
        job=job,
        coverage=result.coverage,
        sim_time_s=result.mission.sim_time_s,
        wall_time_s=wall,
        cpu_time_s=cpu,
        robot_metres=float(result.mission.distance_travelled_m.sum()),
    )


def _mean_std(values: Sequence[float]) -> tuple[float, float]:
    n = len(values)
    mean = sum(values) / n
    return mean, math.sqrt(sum((v - mean) ** 2 for v in values) / n)


def format_table(outcomes: Sequence[Outcome], reference: ReferenceSweep | None) -> str:
    """Markdown table of coverage (mean +- population std over sites) and throughput.

    ``reference`` fills the authors' column (n/a without one) and a note under the table.
    """
    groups: dict[tuple[str, str], list[Outcome]] = defaultdict(list)
    for o in outcomes:
        groups[(o.job.departure, o.job.variant)].append(o)
    coverage = reference.coverage if reference is not None else {}
    lines = [
        "| departure | variant | runs | coverage % (this suite) | authors' simulator % "
        '| full coverage runs | CPU s/run | wall s/run | robot-m per wall s |',
        '|---|---|---|---|---|---|---|---|---|',
    ]
    for departure in DEPARTURES:
        for variant in VARIANTS:
            runs = groups.get((departure, variant))
            if not runs:
                continue
            mean, std = _mean_std([100.0 * o.coverage for o in runs])
            ref = coverage.get((departure, variant))
            ref_text = f'{ref[0]:.1f} +- {ref[1]:.1f}' if ref else 'n/a'
            full = sum(o.coverage >= 1.0 for o in runs)
            wall = sum(o.wall_time_s for o in runs) / len(runs)
            cpu = sum(o.cpu_time_s for o in runs) / len(runs)
            metres = sum(o.robot_metres for o in runs) / sum(o.wall_time_s for o in runs)
            lines.append(
                f'| {departure} | {variant} | {len(runs)} | {mean:.1f} +- {std:.1f} | {ref_text} '
                f'| {full} | {cpu:.1f} | {wall:.1f} | {metres:.0f} |'
            )
    if reference is None:
        lines.append(
            "\nNo authors' figures were measured for this configuration, robot count and budget."
        )
    else:
        lines.append(
            f"\nAuthors' simulator: the same configuration, robot count and Table II budget, "
            f'{reference.sites} sites (REFERENCE_OABUG_SIM.md {reference.section}).'
        )
    return '\n'.join(lines)


CSV_FIELDS = (
    'config',
    'site_seed',
    'variant',
    'departure',
    'robots',
    'coverage',
    'sim_time_s',
    'wall_time_s',
    'cpu_time_s',
    'robot_metres',
    'parameters',
)


def write_csv(outcomes: Sequence[Outcome], path: Path) -> None:
    """One row per run, sorted by site, departure and variant, for paired comparisons."""
    rows = sorted(
        outcomes, key=lambda o: (o.job.site_seed, o.job.departure, VARIANTS.index(o.job.variant))
    )
    with path.open('w', newline='', encoding='utf-8') as stream:
        writer = csv.writer(stream)
        writer.writerow(CSV_FIELDS)
        for o in rows:
            job = o.job
            settings = ' '.join(f'{k}={v}' for k, v in job.parameters)
            writer.writerow(
                (
                    job.config,
                    job.site_seed,
                    job.variant,
                    job.departure,
                    job.robots,
                    f'{o.coverage:.6f}',
                    f'{o.sim_time_s:.3f}',
                    f'{o.wall_time_s:.3f}',
                    f'{o.cpu_time_s:.3f}',
                    f'{o.robot_metres:.2f}',
                    settings,
                )
            )


def format_footer(outcomes: Sequence[Outcome], total_s: float, args: argparse.Namespace) -> str:
    """Throughput: CPU and wall time per run, robot-metres per wall second, sweep projection."""
    n = len(outcomes)
    cpu = sum(o.cpu_time_s for o in outcomes) / n
    metres = sum(o.robot_metres for o in outcomes)
    sim_s = sum(o.sim_time_s for o in outcomes)
    workers = max(args.workers, 1)
    settings = ''
    if args.set:
        settings = f' OA-Bug parameters other than the defaults: {" ".join(args.set)}.'
    return (
        f'{n} runs ({args.config}, {args.robots} robots, {args.sites} sites, {args.path} path) '
        f'in {total_s:.0f} s wall with {workers} workers: {cpu:.2f} CPU s per run, '
        f'{total_s / n:.2f} wall s per run overall, {metres / total_s:.0f} robot-m and '
        f'{sim_s / total_s:.1f} sim s per wall s. A {SWEEP_RUNS}-run sweep: '
        f'{SWEEP_RUNS * total_s / n / 60:.0f} min at this wall rate, '
        f'{SWEEP_RUNS * cpu / workers / 60:.0f} min from the CPU time on {workers} idle cores.'
        f'{settings}'
    )


def run(
    *,
    config: str = 'small',
    sites: int = 20,
    first_site_seed: int = 0,
    variants: Sequence[str] = VARIANTS,
    departures: Sequence[str] = DEPARTURES,
    robots: int = 10,
    actions: int | None = None,
    speed_mps: float = 0.3,
    workers: int = 2,
    path: str = 'batch',
    parameters: dict[str, object] | None = None,
) -> tuple[list[Outcome], float]:
    """Run the sweep; return the outcomes and the total wall time [s].

    ``parameters`` are OA-Bug node parameters for every robot of every mission.
    """
    settings = tuple(sorted((parameters or {}).items()))
    jobs = [
        Job(config, seed, variant, departure, robots, actions, speed_mps, path, settings)
        for seed in range(first_site_seed, first_site_seed + sites)
        for departure in departures
        for variant in variants
    ]
    start = time.perf_counter()
    if workers <= 1:
        thresholds = gc.get_threshold()
        quiet_garbage_collector()
        try:
            outcomes = [run_job(job) for job in jobs]
        finally:
            gc.unfreeze()
            gc.set_threshold(*thresholds)
    else:
        context = multiprocessing.get_context('spawn')
        # Each worker lives for the whole sweep: a new process pays about 1.5 s of CPU for
        # the imports and the compiled kernels' cache load (docs/simulation.md), once.
        with context.Pool(workers, initializer=quiet_garbage_collector) as pool:
            outcomes = []
            for outcome in pool.imap_unordered(run_job, jobs, chunksize=1):
                outcomes.append(outcome)
                job = outcome.job
                print(
                    f'[{len(outcomes)}/{len(jobs)}] site {job.site_seed} {job.departure} '
                    f'{job.variant}: {100.0 * outcome.coverage:.1f} % '
                    f'in {outcome.wall_time_s:.0f} s wall',
                    file=sys.stderr,
                    flush=True,
                )
    return outcomes, time.perf_counter() - start


def main(argv: Sequence[str] | None = None) -> int:
    """Command line entry point."""
    parser = argparse.ArgumentParser(description=__doc__.split('\n\n')[0])
    parser.add_argument('--config', choices=('small', 'medium', 'big'), default='small')
    parser.add_argument('--sites', type=int, default=20, help='number of generated sites')
    parser.add_argument('--first-site-seed', type=int, default=0)
    parser.add_argument('--variants', nargs='+', choices=VARIANTS, default=list(VARIANTS))
    parser.add_argument('--departures', nargs='+', choices=DEPARTURES, default=list(DEPARTURES))
    parser.add_argument('--robots', type=int, default=10)
    parser.add_argument('--actions', type=int, default=None, help='default: Table II budget')
    parser.add_argument('--speed', type=float, default=0.3, help='robot speed [m/s]')
    parser.add_argument('--workers', type=int, default=2, help='worker processes')
    parser.add_argument(
        '--path',
        choices=PATHS,
        default='batch',
        help='batch: engine + controllers without the runtime (sweeps); ros: the node path',
    )
    parser.add_argument(
        '--out',
        type=Path,
        default=None,
        help='also write the table here, and every run to the same name with .csv',
    )
    parser.add_argument(
        '--set',
        nargs='+',
        default=[],
        metavar='NAME=VALUE',
        help='OA-Bug node parameters other than the defaults (e.g. gas_threshold=300)',
    )
    args = parser.parse_args(argv)
    from swarm_experiments.spawn import oabug_parameter_overrides
    from swarm_sim.errors import ConfigurationError

    try:
        parameters = oabug_parameter_overrides(args.set)
    except ConfigurationError as err:
        parser.error(str(err))
    outcomes, total_s = run(
        config=args.config,
        sites=args.sites,
        first_site_seed=args.first_site_seed,
        variants=args.variants,
        departures=args.departures,
        robots=args.robots,
        actions=args.actions,
        speed_mps=args.speed,
        workers=args.workers,
        path=args.path,
        parameters=parameters,
    )
    table = format_table(outcomes, reference_for(args.config, args.robots, args.actions))
    footer = '\n' + format_footer(outcomes, total_s, args)
    print(table + footer)
    if args.out is not None:
        args.out.write_text(table + '\n' + footer + '\n', encoding='utf-8')
        write_csv(outcomes, args.out.with_suffix('.csv'))
    return 0


if __name__ == '__main__':
    raise SystemExit(main())
