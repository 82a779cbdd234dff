"""MSC + particle filter benchmark: capture completion time of the three schemes.

Runs the ROS-free batch simulator (:mod:`swarm_experiments.msc_pf_batch`, the same controller
objects the ROS node runs) over seeded runs of the paper's scenario (2000 m x 2000 m field,
targets uniform, robots starting in a 30 m disc at the centre, Table I parameters) and prints:

* main: CCT mean +- std for proposed, msc_pf and msc at 10, 15 and 20 targets with the
  default robot count, the ratios of the means, unfinished runs (CCT > T_max, never dropped:
  they count as T_max in the mean, so the mean is then a lower bound), how many seeds have
  the three CCTs in the paper's order (proposed < msc_pf < msc), CPU and wall time per
  run (CPU time of the process that ran it: the better figure on a shared machine);
* robots: CCT against the robot count (sensitivity);
* search: the eq. (1) search alone (no targets): when 50 / 90 / 99 / 100 % of the field
  first lies within the detection range (about 292 m) of some robot's path, per seed and
  mean +- std (the search decides most of the CCT);
* approach: one target at a seeded bearing, 400-900 m from the start: the time from its
  first hearing to its capture and that over the straight drive at full speed from the
  nearest robot that heard it (per scheme; ``--set`` applies), median and mean over seeds;
* pf: time of one particle-filter step of 20 targets x 5041 particles from one observation
  (the update and the convergence test, median over repeats), and of one fused step of 3
  observers; the filters start on their lattice and take fresh noisy samples every repeat.

A seed fixes target and robot placement, noise and every controller, and runs with the same
seed see the same targets under every scheme. Example::

    python benchmarks/bench_msc_pf.py --runs 10 --workers 2 --out msc_pf_table.md
"""

from __future__ import annotations

import os

for _var in ('OMP_NUM_THREADS', 'OPENBLAS_NUM_THREADS', 'MKL_NUM_THREADS'):
    os.environ.setdefault(_var, '1')

import itertools  # noqa: E402
import math  # noqa: E402
import time  # noqa: E402
from collections.abc import Callable, Iterator, Sequence  # noqa: E402
from dataclasses import dataclass  # noqa: E402
from pathlib import Path  # noqa: E402
from typing import TypeVar  # noqa: E402

import numpy as np  # noqa: E402
from msc_pf.parameters import MSC_PF_PARAMETERS  # noqa: E402
from msc_pf.particle_filter import ParticleFilterBank, resolve_backend  # noqa: E402
from msc_pf.schemes import Scheme  # noqa: E402
from msc_pf.settings import MscPfConfig, ParticleFilterConfig, RadioConfig  # noqa: E402
from swarm_common.cli import EXIT_INTERRUPTED, ToolParser, fail, run_tool  # noqa: E402
from swarm_common.errors import UsageError  # noqa: E402
from swarm_common.jobs import map_jobs  # noqa: E402
from swarm_common.outputs import check_output_file, write_text_atomic  # noqa: E402
from swarm_experiments.msc_pf_batch import (  # noqa: E402
    BatchScenario,
    SearchCoverage,
    run_batch,
    search_coverage,
)
from swarm_experiments.node_overrides import parse_overrides  # noqa: E402

SCHEMES = ('proposed', 'msc_pf', 'msc')
CSV_HEADER = (
    'scheme,targets,robots,seed,cct_s,finished,wall_s,mean_capture_s,cpu_s,last_heard_s,'
    'approach_s,approach_ratio\n'
)
EXPERIMENTS = ('main', 'robots', 'search', 'approach', 'pf')


@dataclass(frozen=True)
class RunOutcome:
    """One run's result."""

    scheme: str
    n_targets: int
    n_robots: int
    seed: int
    cct_s: float
    finished: bool
    wall_time_s: float
    mean_capture_s: float = math.nan
    cpu_time_s: float = math.nan
    last_heard_s: float = math.nan
    """When the last target was first heard by some robot [s]; NaN if one never was."""
    approach_s: float = math.nan
    """Median over the captured targets of the time from first hearing to capture [s]."""
    approach_ratio: float = math.nan
    """Median over the captured targets of that time over the straight drive at full speed
    from the nearest robot that first heard the target (1 = straight there, work included)."""


Overrides = tuple[tuple[str, object], ...]
"""Controller settings changed from the defaults: ('section.field', typed value), sorted."""

Job = tuple[str, int, int, int, float, Overrides]
J = TypeVar('J')
R = TypeVar('R')


def controller_overrides(items: Sequence[str]) -> Overrides:
    """Controller settings from ``SECTION.FIELD=VALUE`` items, typed and checked.

    The names and the checks are those of the msc_pf node's parameters
    (``swarm_experiments.node_overrides``); ``scheme`` comes from ``--schemes``.

    Raises:
        ConfigurationError: a malformed item, an unknown name, ``scheme``, a value of the
            wrong type, or one the controller rejects.
    """
    # The node's own parameters (robot_id, seed, steering) do not reach the batch controller.
    node_only = [p.name for p in MSC_PF_PARAMETERS.parameters if p.path[0] != 'controller']
    values = parse_overrides(items, MSC_PF_PARAMETERS, reserved=('scheme', *node_only))
    return tuple(sorted(values.items()))


def controller_config(overrides: Overrides) -> MscPfConfig:
    """The default controller configuration with typed ``overrides`` applied."""
    return MSC_PF_PARAMETERS.build(dict(overrides)).controller


def _run_one(job: Job) -> RunOutcome:
    scheme, n_targets, n_robots, seed, max_time_s, overrides = job
    controller = controller_config(overrides)
    start_cpu = time.process_time()
    result = run_batch(
        BatchScenario(
            scheme=Scheme(scheme),
            n_robots=n_robots,
            n_targets=n_targets,
            seed=seed,
            max_time_s=max_time_s,
            controller=controller,
        )
    )
    cpu = time.process_time() - start_cpu
    finished = not math.isnan(result.cct_s)
    cct = result.cct_s if finished else max_time_s
    times = np.where(np.isnan(result.capture_times_s), max_time_s, result.capture_times_s)
    mean_capture = float(times.mean()) if times.size else math.nan
    heard = result.first_heard_s
    last_heard = float(heard.max()) if heard.size and not np.isnan(heard).any() else math.nan
    approach_s, approach_ratio = approach_medians(
        result.first_heard_s,
        result.first_heard_range_m,
        result.capture_times_s,
        controller.max_speed_m_s,
    )
    return RunOutcome(
        scheme,
        n_targets,
        n_robots,
        seed,
        cct,
        finished,
        result.wall_time_s,
        mean_capture,
        cpu,
        last_heard,
        approach_s,
        approach_ratio,
    )


def approach_medians(
    first_heard_s: np.ndarray,
    first_heard_range_m: np.ndarray,
    capture_times_s: np.ndarray,
    max_speed_m_s: float,
) -> tuple[float, float]:
    """Median first-hearing-to-capture time [s] and its median ratio to the straight drive.

    Over the targets that were heard and captured; NaN, NaN when there are none. The ratio
    divides each target's time by ``range / max_speed``: the paper's MSC "moves back and
    forth" where the PF schemes head for an estimate, and this is where that shows.
    """
    done = ~np.isnan(first_heard_s) & ~np.isnan(capture_times_s)
    if not done.any():
        return math.nan, math.nan
    took = capture_times_s[done] - first_heard_s[done]
    straight = np.maximum(first_heard_range_m[done], 1.0) / max_speed_m_s
    return float(np.median(took)), float(np.median(took / straight))


def _log(outcome: RunOutcome, csv_path: Path | None) -> RunOutcome:
    if csv_path is not None:
        new = not csv_path.exists()
        with csv_path.open('a') as stream:
            if new:
                stream.write(CSV_HEADER)
            stream.write(_csv_row(outcome))
    status = f'{outcome.cct_s:7.0f} s' if outcome.finished else 'unfinished'
    print(
        f'  {outcome.scheme:8s} {outcome.n_targets:2d} targets {outcome.n_robots:2d} robots '
        f'seed {outcome.seed:2d}: CCT {status}, CPU {outcome.cpu_time_s:5.1f} s, '
        f'wall {outcome.wall_time_s:5.1f} s',
        flush=True,
    )
    return outcome


def _csv_row(o: RunOutcome) -> str:
    return (
        f'{o.scheme},{o.n_targets},{o.n_robots},{o.seed},{o.cct_s:.0f},{o.finished:d},'
        f'{o.wall_time_s:.1f},{o.mean_capture_s:.0f},{o.cpu_time_s:.1f},{o.last_heard_s:.0f},'
        f'{o.approach_s:.0f},{o.approach_ratio:.3f}\n'
    )


def _map(function: Callable[[J], R], jobs: Sequence[J], workers: int) -> Iterator[R]:
    """``function`` over ``jobs`` in order, in ``workers`` processes (here when 1); Ctrl-C
    stops the workers and raises KeyboardInterrupt here."""
    yield from map_jobs(function, jobs, workers=workers)


def _run_all(
    jobs: list[Job], workers: int, csv_path: Path | None, finished: list[RunOutcome]
) -> list[RunOutcome]:
    done: list[RunOutcome] = []
    for outcome in _map(_run_one, jobs, workers):
        done.append(_log(outcome, csv_path))
        finished.append(outcome)
    return done


def _stats(outcomes: list[RunOutcome]) -> tuple[float, float, int, str]:
    cct = np.array([o.cct_s for o in outcomes])
    unfinished = sum(not o.finished for o in outcomes)
    wall = np.mean([o.wall_time_s for o in outcomes])
    cpu = [o.cpu_time_s for o in outcomes if not math.isnan(o.cpu_time_s)]
    cost = f'{np.mean(cpu):.0f}/{wall:.0f}' if cpu else f'-/{wall:.0f}'
    return float(cct.mean()), float(cct.std()), unfinished, cost


SearchJob = tuple[int, int, float, Overrides]
"""(robots, seed, T_max, controller overrides) of one search-coverage run."""


def _search_one(job: SearchJob) -> tuple[int, SearchCoverage]:
    n_robots, seed, max_time_s, overrides = job
    coverage = search_coverage(
        n_robots, seed, max_time_s=max_time_s, controller=controller_config(overrides)
    )
    times = ', '.join('-' if math.isnan(t) else f'{t:.0f}' for t in coverage.times_s)
    print(f'  search {n_robots:2d} robots seed {seed:2d}: {times} s', flush=True)
    return seed, coverage


def search_table(results: list[tuple[int, SearchCoverage]], n_robots: int) -> list[str]:
    """Markdown table: time to each coverage fraction, mean +- std over seeds."""
    fractions = results[0][1].fractions
    lines = [
        f'Search only (no targets), {n_robots} robots, {len(results)} seeds: time until the '
        'given share of the field lies within the detection range of some path [s]',
        '',
        '| covered | mean +- std | min | max | not reached |',
        '|---|---|---|---|---|',
    ]
    for i, fraction in enumerate(fractions):
        times = np.array([coverage.times_s[i] for _, coverage in results])
        reached = times[~np.isnan(times)]
        if reached.size:
            cells = (
                f'{reached.mean():.0f} +- {reached.std():.0f} | {reached.min():.0f} | '
                f'{reached.max():.0f}'
            )
        else:
            cells = '- | - | -'
        lines.append(f'| {100 * fraction:g} % | {cells} | {times.size - reached.size} |')
    return [*lines, '']


ApproachJob = tuple[str, int, int, Overrides]
"""(scheme, robots, seed, controller overrides) of one single-target approach run."""

APPROACH_RANGE_M = (400.0, 900.0)
"""Distance of the approach experiment's target from the start centre [m]."""


def approach_target(seed: int, field_size_m: float = 2000.0) -> np.ndarray:
    """(1, 2) position of the approach experiment's target for ``seed``."""
    rng = np.random.default_rng([seed, 11])
    bearing = rng.uniform(0.0, 2.0 * math.pi)
    distance = rng.uniform(*APPROACH_RANGE_M)
    centre = field_size_m / 2.0
    return np.array(
        [[centre + distance * math.cos(bearing), centre + distance * math.sin(bearing)]]
    )


def _approach_one(job: ApproachJob) -> tuple[str, int, float, float]:
    """(scheme, seed, first hearing to capture [s], that over the straight drive); the time
    is 4000 s when the target was not captured by then."""
    scheme, n_robots, seed, overrides = job
    controller = controller_config(overrides)
    horizon = 4000.0
    result = run_batch(
        BatchScenario(
            scheme=Scheme(scheme),
            n_robots=n_robots,
            n_targets=1,
            seed=seed,
            max_time_s=horizon,
            controller=controller,
            target_positions_m=approach_target(seed, controller.field_size_m),
        )
    )
    heard, captured = float(result.first_heard_s[0]), float(result.capture_times_s[0])
    took = captured - heard if math.isfinite(captured) else horizon
    drive = max(float(result.first_heard_range_m[0]), 1.0) / controller.max_speed_m_s
    print(
        f'  approach {scheme} seed {seed:2d}: {took:.0f} s, {took / drive:.2f} drives', flush=True
    )
    return scheme, seed, took, took / drive


def single_target_table(
    results: list[tuple[str, int, float, float]], n_robots: int, overrides: Overrides
) -> list[str]:
    """Markdown table of the approach experiment, one row per scheme."""
    setting = ', '.join(f'{k}={v}' for k, v in overrides) or 'defaults'
    lines = [
        f'Approach to one target {APPROACH_RANGE_M[0]:.0f}-{APPROACH_RANGE_M[1]:.0f} m from '
        f'the start, {n_robots} robots, settings: {setting}. First hearing to capture [s], '
        'and that over the straight drive at full speed from the nearest robot that heard it '
        '(not captured within 4000 s: counted as 4000 s)',
        '',
        '| scheme | seeds | median [s] | mean [s] | median / straight drive | per seed [s] |',
        '|---|---|---|---|---|---|',
    ]
    for scheme in dict.fromkeys(r[0] for r in results):
        mine = sorted((r for r in results if r[0] == scheme), key=lambda r: r[1])
        took = np.array([r[2] for r in mine])
        ratio = np.array([r[3] for r in mine])
        per_seed = ' '.join(f'{t:.0f}' for t in took)
        lines.append(
            f'| {scheme} | {len(mine)} | {np.median(took):.0f} | {took.mean():.0f} | '
            f'{np.median(ratio):.2f} | {per_seed} |'
        )
    return [*lines, '']


def pf_update_time_ms(
    n_targets: int = 20,
    repeats: int = 200,
    observers: int = 1,
    config: ParticleFilterConfig | None = None,
) -> tuple[float, float, float]:
    """Median wall, median CPU and least CPU time [ms] of one step of ``n_targets`` filters.

    A step is what a robot does with one control period's samples: the (fused) update of
    every filter (Table I's N_p particles each, ``config`` or the defaults) and the
    convergence test. CPU time (this process only) is the better figure on a machine shared
    with other jobs; the least CPU time is the one least disturbed by them.
    """
    radio = RadioConfig()
    rng = np.random.default_rng(0)
    config = ParticleFilterConfig() if config is None else config
    bank = ParticleFilterBank(config, radio, 2000.0, rng, capacity=n_targets)
    targets = rng.uniform(700.0, 1300.0, (n_targets, 2))
    ids = list(range(n_targets))
    where = [np.array([1000.0 + 20.0 * i, 1000.0]) for i in range(observers)]
    for tid in ids:
        bank.track(tid, where[0])

    def observation(point: np.ndarray):
        d = np.hypot(*(targets - point).T)
        return point, ids, radio.rssi_at_1m_dbm - 30.0 * np.log10(d) + rng.normal(0, 1, len(d))

    wall, cpu = [], []
    for i in range(repeats + 5):
        batch = [observation(p) for p in where]
        start, start_cpu = time.perf_counter(), time.process_time()
        bank.update_joint(batch)
        bank.end_step()
        if i >= 5:
            wall.append(time.perf_counter() - start)
            cpu.append(time.process_time() - start_cpu)
    return 1e3 * float(np.median(wall)), 1e3 * float(np.median(cpu)), 1e3 * float(np.min(cpu))


def _cell(outcomes: list[RunOutcome]) -> tuple[str, float, int, str]:
    if not outcomes:
        return '-', math.nan, 0, '-'
    mean, std, late, cost = _stats(outcomes)
    return f'{mean:.0f} +- {std:.0f} (n={len(outcomes)})', mean, late, cost


def _in_order(rows: list[RunOutcome], n_targets: int, schemes: tuple[str, ...]) -> str:
    """'k/m': of the m seeds run with every scheme, k have CCTs strictly in ``schemes`` order."""
    cct = {(o.scheme, o.seed): o.cct_s for o in rows if o.n_targets == n_targets}
    seeds = sorted({seed for _, seed in cct if all((s, seed) in cct for s in schemes)})
    if len(schemes) < 2 or not seeds:
        return '-'
    ordered = sum(
        all(cct[(a, seed)] < cct[(b, seed)] for a, b in itertools.pairwise(schemes))
        for seed in seeds
    )
    return f'{ordered}/{len(seeds)}'


def main_table(outcomes: list[RunOutcome], robots: int, schemes: tuple[str, ...]) -> list[str]:
    """CCT per target count and scheme with the ratios of the means (markdown lines)."""
    rows = [o for o in outcomes if o.n_robots == robots]
    lines = [
        f'## CCT [s], {robots} robots (mean +- std over n seeded runs)',
        '',
        '| targets | '
        + ' | '.join(schemes)
        + ' | proposed/msc | msc_pf/msc | proposed/msc_pf | seeds in order | unfinished'
        + ' | CPU/wall s per run |',
        '|---' * (len(schemes) + 7) + '|',
    ]
    for n in sorted({o.n_targets for o in rows}):
        cells, means, unfinished, costs = [], {}, [], []
        for scheme in schemes:
            text, mean, late, cost = _cell(
                [o for o in rows if o.n_targets == n and o.scheme == scheme]
            )
            means[scheme] = mean
            cells.append(text)
            unfinished.append(f'{scheme}:{late}')
            costs.append(f'{scheme}:{cost}')

        def ratio(a: str, b: str, means: dict[str, float] = means) -> str:
            if a in means and b in means and means[b] > 0:
                return f'{means[a] / means[b]:.2f}'
            return '-'

        lines.append(
            f'| {n} | '
            + ' | '.join(cells)
            + f' | {ratio("proposed", "msc")} | {ratio("msc_pf", "msc")}'
            + f' | {ratio("proposed", "msc_pf")} | {_in_order(rows, n, schemes)}'
            + f' | {" ".join(unfinished)}'
            + f' | {" ".join(costs)} |'
        )
    lines += [
        '',
        '### Mean per-target capture time [s] (uncaptured targets count as T_max)',
        '',
        '| targets | ' + ' | '.join(schemes) + ' |',
        '|---' * (len(schemes) + 1) + '|',
    ]
    for n in sorted({o.n_targets for o in rows}):
        cells = []
        for scheme in schemes:
            values = [
                o.mean_capture_s
                for o in rows
                if o.n_targets == n and o.scheme == scheme and not math.isnan(o.mean_capture_s)
            ]
            cells.append(
                f'{np.mean(values):.0f} +- {np.std(values):.0f} (n={len(values)})'
                if values
                else '-'
            )
        lines.append(f'| {n} | ' + ' | '.join(cells) + ' |')
    return [
        *lines,
        '',
        *paired_table(rows, schemes),
        *search_floor_table(rows, schemes),
        *approach_table(rows, schemes),
    ]


def _table_head(title: str, note: str, columns: Sequence[str]) -> list[str]:
    """Markdown lines of a report table's title, note and header: 'targets', then ``columns``."""
    return [
        f'### {title}',
        '',
        f'({note})',
        '',
        '| targets | ' + ' | '.join(columns) + ' |',
        '|---' * (len(columns) + 1) + '|',
    ]


def paired_difference(
    rows: list[RunOutcome], n_targets: int, better: str, worse: str
) -> tuple[float, float, int, int] | None:
    """CCT of ``worse`` minus that of ``better`` over the seeds both ran at ``n_targets``.

    Returns (mean, standard error of the mean, seeds ``better`` wins, seeds), or None when
    no seed has both. Pairing removes the seed-to-seed spread of the targets' positions,
    which dominates the unpaired standard deviations.
    """
    cct = {(o.scheme, o.seed): o.cct_s for o in rows if o.n_targets == n_targets}
    seeds = sorted(seed for scheme, seed in cct if scheme == better and (worse, seed) in cct)
    if not seeds:
        return None
    gaps = np.array([cct[(worse, seed)] - cct[(better, seed)] for seed in seeds])
    error = float(gaps.std(ddof=1) / math.sqrt(gaps.size)) if gaps.size > 1 else math.nan
    return float(gaps.mean()), error, int((gaps > 0).sum()), gaps.size


def paired_table(rows: list[RunOutcome], schemes: tuple[str, ...]) -> list[str]:
    """Paired CCT differences of the paper's pairs of schemes, per target count (markdown)."""
    pairs = [
        (a, b)
        for a, b in (('proposed', 'msc'), ('msc_pf', 'msc'), ('proposed', 'msc_pf'))
        if a in schemes and b in schemes
    ]
    if not pairs:
        return []
    lines = _table_head(
        'Paired by seed: CCT of the second scheme minus the first [s]',
        'mean +- standard error; the seeds the first scheme wins',
        [f'{a} vs {b}' for a, b in pairs],
    )
    for n in sorted({o.n_targets for o in rows}):
        cells = []
        for a, b in pairs:
            paired = paired_difference(rows, n, a, b)
            if paired is None:
                cells.append('-')
                continue
            mean, error, wins, seeds = paired
            cells.append(f'{mean:.0f} +- {error:.0f} ({wins}/{seeds})')
        lines.append(f'| {n} | ' + ' | '.join(cells) + ' |')
    return [*lines, '']


def _cells_per_target_count(
    rows: list[RunOutcome],
    schemes: tuple[str, ...],
    keep: Callable[[RunOutcome], bool],
    describe: Callable[[list[RunOutcome]], str],
) -> Iterator[tuple[int, list[str]]]:
    """Per target count (ascending), one cell per scheme: ``describe`` of its kept runs, or -."""
    for n in sorted({o.n_targets for o in rows}):
        cells = []
        for scheme in schemes:
            runs = [o for o in rows if o.n_targets == n and o.scheme == scheme and keep(o)]
            cells.append(describe(runs) if runs else '-')
        yield n, cells


def search_floor_table(rows: list[RunOutcome], schemes: tuple[str, ...]) -> list[str]:
    """Where the CCT goes: the last first hearing of a target and the approaches after it.

    A scheme cannot end before its last target is first heard, whatever its approach does;
    the last column compares that floor with the goal proposed <= 0.6 msc (markdown lines).
    """
    lines = _table_head(
        'Where the CCT goes: last target first heard, then the time to the end [s]',
        'mean +- std over the finished runs that recorded it; the end minus the last first'
        ' hearing as mean / median',
        [*(f'{s} heard / then' for s in schemes), '0.6 x msc CCT'],
    )

    def describe(runs: list[RunOutcome]) -> str:
        heard = np.array([o.last_heard_s for o in runs])
        rest = np.array([o.cct_s for o in runs]) - heard
        return (
            f'{heard.mean():.0f} +- {heard.std():.0f} / {rest.mean():.0f} /'
            f' {np.median(rest):.0f} (n={len(runs)})'
        )

    def keep(o: RunOutcome) -> bool:
        return o.finished and not math.isnan(o.last_heard_s)

    for n, cells in _cells_per_target_count(rows, schemes, keep, describe):
        msc = [o.cct_s for o in rows if o.n_targets == n and o.scheme == 'msc']
        goal = f'{0.6 * np.mean(msc):.0f}' if msc else '-'
        lines.append(f'| {n} | ' + ' | '.join(cells) + f' | {goal} |')
    return [*lines, '']


def approach_table(rows: list[RunOutcome], schemes: tuple[str, ...]) -> list[str]:
    """Per-target approach: first hearing to capture, and its ratio to the straight drive.

    Each run contributes its medians over its captured targets; the table gives the mean +-
    std of those over the runs that recorded them (markdown lines).
    """
    lines = _table_head(
        'Per-target approach: first heard to captured [s], and over the straight drive',
        'per run the median over its captured targets; mean +- std of those over the runs',
        [f'{s} time / ratio' for s in schemes],
    )

    def describe(runs: list[RunOutcome]) -> str:
        took = np.array([o.approach_s for o in runs])
        ratio = np.array([o.approach_ratio for o in runs])
        return (
            f'{took.mean():.0f} +- {took.std():.0f} / {ratio.mean():.2f} +-'
            f' {ratio.std():.2f} (n={len(runs)})'
        )

    for n, cells in _cells_per_target_count(
        rows, schemes, lambda o: not math.isnan(o.approach_s), describe
    ):
        lines.append(f'| {n} | ' + ' | '.join(cells) + ' |')
    return [*lines, '']


def robot_table(outcomes: list[RunOutcome], n_targets: int, schemes: tuple[str, ...]) -> list[str]:
    """CCT per robot count and scheme at ``n_targets`` targets (markdown lines)."""
    rows = [o for o in outcomes if o.n_targets == n_targets]
    lines = [
        f'## CCT [s] against robot count, {n_targets} targets',
        '',
        '| robots | ' + ' | '.join(schemes) + ' | unfinished |',
        '|---' * (len(schemes) + 2) + '|',
    ]
    for count in sorted({o.n_robots for o in rows}):
        cells, unfinished = [], []
        for scheme in schemes:
            text, _, late, _ = _cell(
                [o for o in rows if o.n_robots == count and o.scheme == scheme]
            )
            cells.append(text)
            unfinished.append(f'{scheme}:{late}')
        lines.append(f'| {count} | ' + ' | '.join(cells) + f' | {" ".join(unfinished)} |')
    return [*lines, '']


def read_outcomes(path: Path) -> list[RunOutcome]:
    """Outcomes from a CSV written by :func:`run` (e.g. of an interrupted benchmark).

    Columns are found by name; files from before the mean capture time, the CPU time, the
    last first hearing or the approach medians were recorded read those as NaN.
    """
    header, *lines = path.read_text().splitlines()
    names = header.split(',')
    outcomes = []
    for line in lines:
        row = dict(zip(names, line.split(','), strict=True))
        outcomes.append(
            RunOutcome(
                row['scheme'],
                int(row['targets']),
                int(row['robots']),
                int(row['seed']),
                float(row['cct_s']),
                bool(int(row['finished'])),
                float(row['wall_s']),
                float(row.get('mean_capture_s', 'nan')),
                float(row.get('cpu_s', 'nan')),
                float(row.get('last_heard_s', 'nan')),
                float(row.get('approach_s', 'nan')),
                float(row.get('approach_ratio', 'nan')),
            )
        )
    return outcomes


def pf_table(backend: str = 'auto') -> list[str]:
    """Particle-filter step times (markdown lines) with ``particle_filter.backend`` ``backend``."""
    plain = ParticleFilterConfig(backend=backend)
    uncensored = ParticleFilterConfig(censored_likelihood=False, backend=backend)
    cases = [
        ('one observation of 20 targets', pf_update_time_ms(20, config=plain)),
        ('the same, censoring correction off', pf_update_time_ms(20, config=uncensored)),
        ('fused: 3 observers x 20 targets', pf_update_time_ms(20, observers=3, config=plain)),
        ('one observation of 1 target', pf_update_time_ms(1, config=plain)),
        ('fused: 9 observers x 1 target', pf_update_time_ms(1, observers=9, config=plain)),
    ]
    return [
        '## Particle-filter step time (5041 particles per target, '
        f'{resolve_backend(backend)} backend)',
        '',
        '| step (update + convergence test) | wall ms, median | CPU ms, median | CPU ms, least |',
        '|---|---|---|---|',
        *(f'| {name} | {w:.2f} | {c:.2f} | {m:.2f} |' for name, (w, c, m) in cases),
        '',
    ]


def run(
    *,
    experiments: tuple[str, ...] = EXPERIMENTS,
    targets: tuple[int, ...] = (10, 15, 20),
    robots: int = 15,
    robot_counts: tuple[int, ...] = (9, 15, 30),
    sweep_targets: int = 10,
    runs: int = 10,
    sweep_runs: int = 5,
    search_runs: int = 10,
    approach_runs: int = 8,
    schemes: tuple[str, ...] = SCHEMES,
    max_time_s: float = 20000.0,
    first_seed: int = 0,
    workers: int = 1,
    csv_path: Path | None = None,
    pf_backends: tuple[str, ...] = ('auto',),
    overrides: Overrides = (),
    finished: list[RunOutcome] | None = None,
) -> tuple[str, list[RunOutcome]]:
    """Run the experiments; return the report (markdown) and every run's outcome.

    With ``csv_path``, every outcome is appended to that CSV file as soon as it is known,
    and to ``finished`` if given (what is left of a run stopped by Ctrl-C);
    ``overrides`` change controller settings of the main, robots, search and approach
    experiments.
    """
    controller_config(overrides)  # fail before any run on a bad setting
    lines: list[str] = []
    outcomes: list[RunOutcome] = []
    finished = [] if finished is None else finished
    if 'main' in experiments:
        jobs = [
            (scheme, n, robots, first_seed + s, max_time_s, overrides)
            for n in targets
            for s in range(runs)
            for scheme in schemes
        ]
        main = _run_all(jobs, workers, csv_path, finished)
        outcomes += main
        lines += main_table(main, robots, schemes)
    if 'robots' in experiments:
        jobs = [
            (scheme, sweep_targets, count, first_seed + s, max_time_s, overrides)
            for count in robot_counts
            for s in range(sweep_runs)
            for scheme in schemes
        ]
        sweep = _run_all(jobs, workers, csv_path, finished)
        outcomes += sweep
        lines += robot_table(sweep, sweep_targets, schemes)
    if 'search' in experiments:
        search_jobs = [(robots, first_seed + s, max_time_s, overrides) for s in range(search_runs)]
        lines += search_table(list(_map(_search_one, search_jobs, workers)), robots)
    if 'approach' in experiments:
        approach_jobs = [
            (scheme, robots, first_seed + s, overrides)
            for scheme in schemes
            for s in range(approach_runs)
        ]
        results = list(_map(_approach_one, approach_jobs, workers))
        lines += single_target_table(results, robots, overrides)
    if 'pf' in experiments:
        for backend in pf_backends:
            lines += pf_table(backend)
    return '\n'.join(lines), outcomes


def main(argv: Sequence[str] | None = None) -> int:
    """Command-line entry point; exit codes as every tool's (docs/conventions.md);
    130 after Ctrl-C (the finished runs are kept in the CSV and their table printed)."""
    return run_tool('bench_msc_pf', _main, argv)


def _main(argv: list[str]) -> int:
    parser = ToolParser(prog='bench_msc_pf', description=__doc__.split('\n')[0])
    parser.add_argument('--experiments', nargs='+', choices=EXPERIMENTS, default=EXPERIMENTS)
    parser.add_argument('--targets', nargs='+', type=int, default=[10, 15, 20])
    parser.add_argument('--robots', type=int, default=15)
    parser.add_argument('--robot-counts', nargs='+', type=int, default=[9, 15, 30])
    parser.add_argument('--sweep-targets', type=int, default=10)
    parser.add_argument('--runs', type=int, default=10)
    parser.add_argument('--sweep-runs', type=int, default=5)
    parser.add_argument(
        '--search-runs', type=int, default=10, help='seeds of the search experiment'
    )
    parser.add_argument(
        '--approach-runs', type=int, default=8, help='seeds of the approach experiment'
    )
    parser.add_argument('--schemes', nargs='+', choices=SCHEMES, default=list(SCHEMES))
    parser.add_argument('--max-time', type=float, default=20000.0, help='T_max per run [s]')
    parser.add_argument('--first-seed', type=int, default=0)
    parser.add_argument('--workers', type=int, default=1, help='processes (one core each)')
    parser.add_argument(
        '--out', type=Path, help='write the report here and every run to <out>.csv as it ends'
    )
    parser.add_argument(
        '--pf-backend',
        nargs='+',
        choices=('auto', 'numpy', 'numba'),
        default=['auto'],
        help="particle_filter.backend of the pf experiment ('auto': numba if installed)",
    )
    parser.add_argument(
        '--set',
        nargs='+',
        default=[],
        metavar='SECTION.FIELD=VALUE',
        help='controller settings other than the defaults (e.g. phases.unheard_updates=true)',
    )
    parser.add_argument(
        '--table-from', type=Path, help='only print the tables of a CSV of finished runs'
    )
    args = parser.parse_args(argv)
    overrides = controller_overrides(args.set)
    for name in ('runs', 'sweep_runs', 'search_runs', 'approach_runs', 'robots', 'workers'):
        if getattr(args, name) < 1:
            flag = '--' + name.replace('_', '-')
            raise UsageError(f'{flag} must be >= 1, got {getattr(args, name)}')
    if not (math.isfinite(args.max_time) and args.max_time > 0.0):
        raise UsageError(f'--max-time must be a finite number > 0, got {args.max_time}')
    if args.table_from is not None:
        outcomes = read_outcomes(args.table_from)
        schemes = tuple(args.schemes)
        lines = main_table(outcomes, args.robots, schemes)
        if len({o.n_robots for o in outcomes}) > 1:
            lines += robot_table(outcomes, args.sweep_targets, schemes)
        print('\n'.join(lines))
        return 0
    if args.out is not None:
        check_output_file(args.out, option='--out')
        check_output_file(args.out.with_suffix('.csv'), option='--out (its .csv)')
    start = time.perf_counter()
    finished: list[RunOutcome] = []
    try:
        report, outcomes = run(
            experiments=tuple(args.experiments),
            targets=tuple(args.targets),
            robots=args.robots,
            robot_counts=tuple(args.robot_counts),
            sweep_targets=args.sweep_targets,
            runs=args.runs,
            sweep_runs=args.sweep_runs,
            search_runs=args.search_runs,
            approach_runs=args.approach_runs,
            schemes=tuple(args.schemes),
            max_time_s=args.max_time,
            first_seed=args.first_seed,
            workers=args.workers,
            csv_path=args.out.with_suffix('.csv') if args.out is not None else None,
            pf_backends=tuple(args.pf_backend),
            overrides=overrides,
            finished=finished,
        )
    except KeyboardInterrupt:
        schemes = tuple(args.schemes)
        if finished:
            print('\n'.join(main_table(finished, args.robots, schemes)))
        where = f' (kept in {args.out.with_suffix(".csv")})' if args.out is not None else ''
        fail('bench_msc_pf', f'interrupted after {len(finished)} finished runs{where}')
        return EXIT_INTERRUPTED
    report += f'\nTotal wall time: {time.perf_counter() - start:.0f} s'
    if outcomes:
        cpu = sum(o.cpu_time_s for o in outcomes)
        report += f'; CPU time of the {len(outcomes)} runs: {cpu:.0f} s'
    report += '\n'
    print(report)
    if args.out is not None:
        write_text_atomic(args.out, report)
    return 0


if __name__ == '__main__':
    raise SystemExit(main())
