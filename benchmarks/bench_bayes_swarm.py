"""Bayes-Swarm-P benchmark: tau and decision time on the paper's cases, against the baselines.

Runs the batch runner (:mod:`swarm_experiments.bayes_batch`, the same planner objects the
ROS node uses) over seeded runs and prints one table row per experiment: runs, failures
(never dropped), tau mean +- std over the successful runs, and the median compute time per
decision of the robot that found the source (median over its decisions, the first trivial
one included as in the authors' measurement, then median over runs; 'GP' is the same
without the first decision; 'CPU' is the process CPU time per decision, which a contended
machine inflates far less than wall-clock time).

Experiments (``--experiments``, default all):

* main: Case 1 with 5 robots and Case 2 with 10 robots (Bayes-Swarm-P);
* shifted: the same with the field and its source moved by a seeded offset (up to 0.3 m in
  Case 1, 3 m in Case 2), to show how much a result hinges on the exact source position;
* penalty: Bayes-Swarm-O on the same cases, also moved (Table 5: P against O);
* comm: limited communication ranges (Experiment 5, Table 6);
* authors: the authors' code options (inert penalty, origin paths, floor downsampling,
  alpha on 0.1 T_max, COBYLA) for comparison;
* baselines: Glowworm, Levy walk and exhaustive search (Table 3);
* scaling: Case 2 with 5 to 50 robots (Fig. 4); scaling_shifted: the same, source moved;
* case3: Case 3 with 48 and 100 robots (Table 4);
* avalanche: the avalanche field, 6 UAVs, without and with noise (Table 8).

Decision timings are wall-clock, one BLAS thread per process. Example::

    python benchmarks/bench_bayes_swarm.py --experiments main --runs 20 --out table.md
"""

from __future__ import annotations

import os

for _var in ('OMP_NUM_THREADS', 'OPENBLAS_NUM_THREADS', 'MKL_NUM_THREADS'):
    os.environ.setdefault(_var, '1')

import math  # noqa: E402
import sys  # noqa: E402
import time  # noqa: E402
from dataclasses import dataclass, field, replace  # noqa: E402
from pathlib import Path  # noqa: E402
from typing import Any  # noqa: E402

import numpy as np  # noqa: E402
from bayes_swarm.messages import DecisionKind  # noqa: E402
from swarm_common.cli import EXIT_INTERRUPTED, ToolParser, fail, run_tool  # noqa: E402
from swarm_common.errors import UsageError  # noqa: E402
from swarm_common.jobs import map_jobs  # noqa: E402
from swarm_common.outputs import check_output_file, write_text_atomic  # noqa: E402
from swarm_experiments.bayes_batch import MissionSpec, run_mission  # noqa: E402
from swarm_experiments.spawn_bayes_swarm import batch_mission_spec  # noqa: E402
from swarm_sim.signal_fields import avalanche_case, get_case  # noqa: E402

EXPERIMENTS = (
    'main',
    'shifted',
    'penalty',
    'authors',
    'comm',
    'baselines',
    'scaling',
    'scaling_shifted',
    'case3',
    'avalanche',
)
AUTHORS_OPTIONS = {
    'authors_negated_m': True,
    'authors_origin_paths': True,
    'authors_floor_downsampling': True,
    'alpha_time_scale': 0.1,
    'outer_optimizer': 'cobyla',
}


@dataclass(frozen=True)
class Job:
    """One configuration to run over seeds."""

    experiment: str
    label: str
    case: str
    algorithm: str
    robots: int
    runs: int
    planner: dict[str, Any] = field(default_factory=dict)
    noise_std: float = 0.0
    max_mission_time_s: float | None = None
    partition: str = 'strips'
    comm_range_m: float | None = None
    source_shift_m: float = 0.0
    avalanche_depth_m: float | None = None


@dataclass(frozen=True)
class RunOutcome:
    found: bool
    tau: float
    median_decision_s: float
    median_gp_decision_s: float
    median_cpu_decision_s: float
    decisions: int
    wall_s: float


def mission_spec(job: Job, seed: int = 0) -> MissionSpec:
    """Batch-simulator spec of the job's case with the paper's settings.

    A job with ``source_shift_m`` moves the field and its source by an offset drawn
    uniformly from [-shift, shift]^2 with the run's seed.
    """
    case = (
        get_case(job.case)
        if job.avalanche_depth_m is None
        else avalanche_case(job.avalanche_depth_m)
    )
    if job.max_mission_time_s is not None:
        case = replace(case, max_mission_time_s=job.max_mission_time_s)
    if job.source_shift_m > 0.0:
        rng = np.random.default_rng(seed)
        case = case.with_source_moved(rng.uniform(-job.source_shift_m, job.source_shift_m, 2))
    return batch_mission_spec(
        case,
        noise_std=job.noise_std,
        comm_range_m=job.comm_range_m,
        partition=job.partition,
        planner_options=job.planner,
    )


def run_one(job: Job, seed: int) -> RunOutcome:
    """One seeded run of a job."""
    start = time.perf_counter()
    result = run_mission(mission_spec(job, seed), job.algorithm, job.robots, seed)
    wall = time.perf_counter() - start
    decisions = result.decisions[result.finder] if result.found else []
    times = [d.compute_time_s for d in decisions]
    gp_times = [d.compute_time_s for d in decisions if d.kind is not DecisionKind.FIRST]
    cpu_times = [d.cpu_time_s for d in decisions]
    return RunOutcome(
        found=result.found,
        tau=result.tau,
        median_decision_s=float(np.median(times)) if times else math.nan,
        median_gp_decision_s=float(np.median(gp_times)) if gp_times else math.nan,
        median_cpu_decision_s=float(np.median(cpu_times)) if cpu_times else math.nan,
        decisions=sum(len(d) for d in result.decisions),
        wall_s=wall,
    )


def _run_job(args: tuple[int, Job, int]) -> tuple[int, Job, int, RunOutcome]:
    index, job, seed = args
    return index, job, seed, run_one(job, seed)


def plan_jobs(experiments: list[str], runs: int, baseline_runs: int, large_runs: int) -> list[Job]:
    """The jobs of the chosen experiments."""
    jobs: list[Job] = []
    if 'main' in experiments:
        jobs += [
            Job('main', 'Case 1, 5 robots, Bayes-Swarm-P', 'case1', 'bayes_swarm_p', 5, runs),
            Job('main', 'Case 2, 10 robots, Bayes-Swarm-P', 'case2', 'bayes_swarm_p', 10, runs),
        ]
    shifts = (('case1', 5, 0.3), ('case2', 10, 3.0))
    if 'shifted' in experiments:
        for case, m, shift in shifts:
            jobs.append(
                Job(
                    'shifted',
                    f'Case {case[-1]}, {m} robots, Bayes-Swarm-P, source moved <= {shift:g} m',
                    case,
                    'bayes_swarm_p',
                    m,
                    runs,
                    source_shift_m=shift,
                )
            )
    if 'penalty' in experiments:
        jobs += [
            Job('penalty', 'Case 1, 5 robots, Bayes-Swarm-O', 'case1', 'bayes_swarm_o', 5, runs),
            Job('penalty', 'Case 2, 10 robots, Bayes-Swarm-O', 'case2', 'bayes_swarm_o', 10, runs),
        ]
        for case, m, shift in shifts:
            jobs.append(
                Job(
                    'penalty',
                    f'Case {case[-1]}, {m} robots, Bayes-Swarm-O, source moved <= {shift:g} m',
                    case,
                    'bayes_swarm_o',
                    m,
                    runs,
                    source_shift_m=shift,
                )
            )
    if 'authors' in experiments:
        for case, m in (('case1', 5), ('case2', 10)):
            jobs.append(
                Job(
                    'authors',
                    f"{case.title()[:-1]} {case[-1]}, {m} robots, authors' options",
                    case,
                    'bayes_swarm_p',
                    m,
                    runs,
                    dict(AUTHORS_OPTIONS),
                )
            )
    if 'comm' in experiments:
        for case, m, ranges in (('case1', 5, (0.1, 0.5, 1.0)), ('case2', 10, (5.0, 10.0, 20.0))):
            for comm in ranges:
                jobs.append(
                    Job(
                        'comm',
                        f'Case {case[-1]}, {m} robots, comm range {comm:g} m',
                        case,
                        'bayes_swarm_p',
                        m,
                        runs,
                        comm_range_m=comm,
                    )
                )
    if 'baselines' in experiments:
        for case, m in (('case1', 5), ('case2', 10)):
            name = f'Case {case[-1]}, {m} robots'
            jobs += [
                Job('baselines', f'{name}, Glowworm', case, 'glowworm', m, baseline_runs),
                Job('baselines', f'{name}, Levy walk', case, 'levy', m, baseline_runs),
                Job(
                    'baselines',
                    f'{name}, Levy walk, T_max x30',
                    case,
                    'levy',
                    m,
                    baseline_runs,
                    max_mission_time_s=30 * get_case(case).max_mission_time_s,
                ),
            ]
        jobs += [
            Job(
                'baselines',
                'Case 1, 10 robots, exhaustive (quadrants), T_max x30',
                'case1',
                'exhaustive',
                10,
                1,
                max_mission_time_s=3000.0,
                partition='quadrants',
            ),
            Job(
                'baselines',
                'Case 2, 10 robots, exhaustive (quadrants), T_max x30',
                'case2',
                'exhaustive',
                10,
                1,
                max_mission_time_s=30000.0,
                partition='quadrants',
            ),
        ]
    for experiment, shift in (('scaling', 0.0), ('scaling_shifted', 3.0)):
        if experiment not in experiments:
            continue
        moved = f', source moved <= {shift:g} m' if shift else ''
        for m in (5, 10, 20, 30, 40, 50):
            jobs.append(
                Job(
                    experiment,
                    f'Case 2, {m} robots, Bayes-Swarm-P{moved}',
                    'case2',
                    'bayes_swarm_p',
                    m,
                    large_runs,
                    source_shift_m=shift,
                )
            )
    if 'case3' in experiments:
        for m in (48, 100):
            jobs.append(
                Job(
                    'case3',
                    f'Case 3, {m} robots, Bayes-Swarm-P',
                    'case3',
                    'bayes_swarm_p',
                    m,
                    large_runs,
                )
            )
    if 'avalanche' in experiments:
        noise = 47.0 / 100.0
        av = 'Avalanche, 6 UAVs'
        dimensionless = {'dimensionless_acquisition': True}
        rows: list[tuple[str, str, dict[str, Any], float, float | None, float | None]] = [
            ('Bayes-Swarm-P', 'bayes_swarm_p', {}, 0.0, None, None),
            ('Bayes-Swarm-O', 'bayes_swarm_o', {}, 0.0, None, None),
            ('Bayes-Swarm-P (alpha = 1)', 'bayes_swarm_p', {'fixed_alpha': 1.0}, 0.0, None, None),
            ('Bayes-Swarm-P, dimensionless Eq. 1', 'bayes_swarm_p', dimensionless, 0.0, None, None),
            ('Glowworm', 'glowworm', {}, 0.0, None, None),
            ('Levy walk', 'levy', {}, 0.0, None, None),
            ('noise 0.47, Bayes-Swarm-P', 'bayes_swarm_p', {}, noise, None, None),
            ('noise 0.47, Bayes-Swarm-O', 'bayes_swarm_o', {}, noise, None, None),
            ('noise 0.47, Glowworm', 'glowworm', {}, noise, None, None),
            ('beacon 5 m deep, Bayes-Swarm-P', 'bayes_swarm_p', {}, 0.0, None, 5.0),
            ('beacon 5 m deep, noise 0.47, Bayes-Swarm-P', 'bayes_swarm_p', {}, noise, None, 5.0),
        ]
        for label, algorithm, options, noise_std, t_max, depth in rows:
            jobs.append(
                Job(
                    'avalanche',
                    f'{av}, {label}',
                    'avalanche',
                    algorithm,
                    6,
                    baseline_runs,
                    options,
                    noise_std=noise_std,
                    max_mission_time_s=t_max,
                    avalanche_depth_m=depth,
                )
            )
        jobs.append(
            Job(
                'avalanche',
                f'{av}, exhaustive, T_max x30',
                'avalanche',
                'exhaustive',
                6,
                1,
                max_mission_time_s=3000.0,
            )
        )
    return jobs


def _fmt_ms(values: list[float]) -> str:
    finite = [v for v in values if math.isfinite(v)]
    return f'{1e3 * float(np.median(finite)):.1f}' if finite else '-'


def summarize(job: Job, outcomes: list[RunOutcome]) -> dict[str, str]:
    """One table row."""
    taus = np.array([o.tau for o in outcomes if o.found])
    fails = sum(not o.found for o in outcomes)
    tau = f'{taus.mean():.2f} +- {taus.std():.2f}' if taus.size else '-'
    return {
        'experiment': job.label,
        'runs': str(len(outcomes)),
        'fails': str(fails),
        'tau': tau,
        'decision ms': _fmt_ms([o.median_decision_s for o in outcomes]),
        'GP decision ms': _fmt_ms([o.median_gp_decision_s for o in outcomes]),
        'CPU decision ms': _fmt_ms([o.median_cpu_decision_s for o in outcomes]),
        'wall s/run': f'{np.mean([o.wall_s for o in outcomes]):.1f}',
    }


def format_table(rows: list[dict[str, str]]) -> str:
    """Markdown table of the rows."""
    if not rows:
        return ''
    keys = list(rows[0])
    lines = ['| ' + ' | '.join(keys) + ' |', '|' + '---|' * len(keys)]
    lines += ['| ' + ' | '.join(row[k] for k in keys) + ' |' for row in rows]
    return '\n'.join(lines)


def run(
    experiments: list[str],
    runs: int = 20,
    baseline_runs: int = 5,
    large_runs: int = 3,
    processes: int = 1,
    first_seed: int = 0,
    progress: bool = True,
) -> list[dict[str, str]]:
    """Run the experiments and return the table rows (one per job).

    Raises:
        Interrupted: Ctrl-C; its ``rows`` summarize the runs that finished.
    """
    jobs = plan_jobs(experiments, runs, baseline_runs, large_runs)
    tasks = [(i, job, first_seed + s) for i, job in enumerate(jobs) for s in range(job.runs)]
    results: list[list[RunOutcome]] = [[] for _ in jobs]

    def rows() -> list[dict[str, str]]:
        return [
            summarize(job, outcomes)
            for job, outcomes in zip(jobs, results, strict=True)
            if outcomes
        ]

    try:
        for index, job, seed, outcome in map_jobs(_run_job, tasks, workers=processes):
            results[index].append(outcome)
            if progress:
                _report(job, seed, outcome)
    except KeyboardInterrupt:
        raise Interrupted(rows(), sum(len(r) for r in results), len(tasks)) from None
    return rows()


class Interrupted(KeyboardInterrupt):
    """Ctrl-C during :func:`run`; ``rows`` summarize the ``done`` of ``planned`` runs."""

    def __init__(self, rows: list[dict[str, str]], done: int, planned: int) -> None:
        super().__init__()
        self.rows = rows
        self.done = done
        self.planned = planned


def _report(job: Job, seed: int, outcome: RunOutcome) -> None:
    status = f'tau {outcome.tau:.3f}' if outcome.found else 'not found'
    print(
        f'  {job.label} seed {seed}: {status}, median decision '
        f'{1e3 * outcome.median_decision_s:.1f} ms, wall {outcome.wall_s:.1f} s',
        file=sys.stderr,
        flush=True,
    )


def main(argv: list[str] | None = None) -> int:
    """Command-line entry point; exit codes as every tool's (docs/conventions.md);
    130 after Ctrl-C with the table of the finished runs printed and written."""
    return run_tool('bench_bayes_swarm', _main, argv)


def _main(argv: list[str]) -> int:
    parser = ToolParser(prog='bench_bayes_swarm', description=__doc__.split('\n\n')[0])
    parser.add_argument('--experiments', nargs='+', choices=EXPERIMENTS, default=list(EXPERIMENTS))
    parser.add_argument('--runs', type=int, default=20, help='seeds per Bayes-Swarm row')
    parser.add_argument('--baseline-runs', type=int, default=5, help='seeds per baseline row')
    parser.add_argument('--large-runs', type=int, default=3, help='seeds per scaling/Case 3 row')
    parser.add_argument('--processes', type=int, default=1, choices=(1, 2))
    parser.add_argument('--first-seed', type=int, default=0)
    parser.add_argument('--out', type=Path, default=None, help='also write the table here')
    parser.add_argument('--quiet', action='store_true', help='no per-run progress on stderr')
    args = parser.parse_args(argv)
    for name in ('runs', 'baseline_runs', 'large_runs'):
        if getattr(args, name) < 1:
            flag = '--' + name.replace('_', '-')
            raise UsageError(f'{flag} must be >= 1, got {getattr(args, name)}')
    if args.first_seed < 0:
        raise UsageError(f'--first-seed must be >= 0, got {args.first_seed}')
    if args.out is not None:
        check_output_file(args.out, option='--out')
    interrupted = None
    try:
        rows = run(
            args.experiments,
            runs=args.runs,
            baseline_runs=args.baseline_runs,
            large_runs=args.large_runs,
            processes=args.processes,
            first_seed=args.first_seed,
            progress=not args.quiet,
        )
    except Interrupted as stop:
        interrupted, rows = stop, stop.rows
    table = format_table(rows)
    print(table)
    if args.out is not None:
        write_text_atomic(args.out, table + '\n')
    if interrupted is not None:
        fail(
            'bench_bayes_swarm',
            f'interrupted: the table covers the {interrupted.done} of {interrupted.planned} '
            'runs that finished',
        )
        return EXIT_INTERRUPTED
    return 0


if __name__ == '__main__':
    sys.exit(main())
