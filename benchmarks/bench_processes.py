"""In-process against multi-process missions on real DDS: metrics and wall times.

For each mission the same run goes over N seeds three ways, each run a spawner command line
in a process of its own:

- ``builtin``: in process on the built-in runtime (exact sim time: the reference);
- ``rclpy``: in process on real rclpy (``--runtime rclpy``), through Fast DDS, in real time
  scaled by ``--time-scale``;
- ``processes``: one process per node (``--processes``), as on robots.

Missions (``--missions``): ``oabug``, ``bayes_swarm`` and ``msc_pf`` are short runs of each
algorithm on 3-4 robots; ``oabug_demo`` is ``make demo``'s mission (6 robots, a Small site,
until every room is covered or the budget is spent) and ``oabug_10`` the same with 10 robots.
Each mission has its own time scale (``--time-scale`` sets one for all): Bayes-Swarm runs at
1, because with one process per node the clock runs on while a robot decides.

It reports each mission's metric as its spawner prints it (OA-Bug: coverage and the time
the last room was first entered; Bayes-Swarm: tau of the finder and how many seeds found the
source; MSC + PF: targets captured and the CCT where all were) and the wall time of each run
(start-up included), mean and standard deviation over the seeds, and whether each real-rclpy
mode matches the built-in reference within noise (two standard errors of the difference of
the means). Then it sweeps ``--time-scale`` for 10 OA-Bug robots in processes (60 actions)
and finds the fastest scale whose mean coverage still matches the built-in reference.

    nice -n 10 python benchmarks/bench_processes.py                     # everything
    nice -n 10 python benchmarks/bench_processes.py --missions oabug --seeds 3 --no-sweep
"""

from __future__ import annotations

import argparse
import dataclasses
import math
import os
import re
import shlex
import subprocess
import sys
import time
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np

BIN = Path(sys.executable).parent
MODES = ('builtin', 'rclpy', 'processes')


@dataclass(frozen=True)
class Mission:
    """One benchmark mission: a spawner, its options and how to read its metric."""

    name: str
    script: str
    argv: tuple[str, ...]
    time_scale: float


MISSIONS = {
    'oabug': Mission('oabug', 'spawn', ('--robots', '4', '--actions', '60'), 2.0),
    'bayes_swarm': Mission('bayes_swarm', 'spawn_bayes_swarm', ('--robots', '3'), 1.0),
    'msc_pf': Mission(
        'msc_pf',
        'spawn_msc_pf',
        (
            '--robots',
            '4',
            '--targets',
            '2',
            '--target-positions',
            '1000,1060;1060,1000',
            '--t-max',
            '250',
        ),
        10.0,
    ),
    'oabug_demo': Mission('oabug_demo', 'spawn', ('--robots', '6', '--variant', 'gas_sound'), 2.0),
    'oabug_10': Mission('oabug_10', 'spawn', ('--robots', '10', '--variant', 'gas_sound'), 2.0),
}
SWEEP = Mission('oabug', 'spawn', ('--robots', '10', '--actions', '60'), 1.0)


@dataclass(frozen=True)
class RunResult:
    """One run: its metrics (name -> value, NaN when not reached) and wall time [s]."""

    metrics: dict[str, float]
    wall_s: float


def _metrics(name: str, out: str) -> dict[str, float]:
    if name.startswith('oabug'):
        m = re.search(r'Coverage: ([\d.]+) % \((\d+)/(\d+) rooms\)', out)
        if m is None:
            raise RuntimeError(f'no coverage line in:\n{out}')
        metrics = {'coverage_%': float(m.group(1))}
        if name != 'oabug':
            last = re.search(r'last new room entered at ([\d.]+) s', out)
            metrics['last_room_s'] = float(last.group(1)) if last else math.nan
        return metrics
    if name == 'bayes_swarm':
        if not re.search(r'^case \S+, ', out, re.MULTILINE):
            raise RuntimeError(f'no report in:\n{out}')
        m = re.search(r'found by \S+ at t = ([\d.]+) s, tau = ([-\d.]+)', out)
        if m is None:
            return {'found': 0.0, 'tau': math.nan}
        return {'found': 1.0, 'tau': float(m.group(2))}
    if 'CCT:' not in out:
        raise RuntimeError(f'no CCT line in:\n{out}')
    captured = len(re.findall(r'target +\d+ at .*: +[\d.]+ s', out))
    m = re.search(r'CCT: (\d+) s', out)
    return {'captured': float(captured), 'cct_s': float(m.group(1)) if m else math.nan}


def _run(
    mission: Mission, mode: str, seed: int, time_scale: float, env: dict[str, str]
) -> RunResult:
    argv = [str(BIN / mission.script), *mission.argv, '--seed', str(seed)]
    argv += ['--no-plots', '--quiet', '--time-scale', str(time_scale)]
    if mode == 'builtin':
        argv += ['--runtime', 'builtin']
    elif mode == 'rclpy':
        argv += ['--runtime', 'rclpy']
    else:
        argv += ['--processes']
    start = time.perf_counter()
    done = subprocess.run(argv, capture_output=True, text=True, env=env, timeout=900, check=False)
    wall = time.perf_counter() - start
    if done.returncode not in (0, 1):
        raise RuntimeError(f'{shlex.join(argv)} exited {done.returncode}: {done.stderr[-2000:]}')
    return RunResult(_metrics(mission.name, done.stdout), wall)


def _summary(values: Sequence[float]) -> str:
    arr = np.asarray(values, dtype=float)
    finite = arr[np.isfinite(arr)]
    if finite.size == 0:
        return 'n/a'
    if finite.size == 1:
        return f'{finite[0]:.3g}'
    text = f'{finite.mean():.3g} ± {finite.std(ddof=1):.2g}'
    return text if finite.size == arr.size else f'{text} ({finite.size}/{arr.size})'


def _matches(reference: Sequence[float], other: Sequence[float]) -> bool:
    a, b = np.asarray(reference, dtype=float), np.asarray(other, dtype=float)
    if a.size < 2 or b.size < 2:
        return bool(np.isclose(a.mean(), b.mean()))
    se = math.sqrt(a.var(ddof=1) / a.size + b.var(ddof=1) / b.size)
    return abs(a.mean() - b.mean()) <= max(2.0 * se, 1e-9)


def _env() -> dict[str, str]:
    env = dict(os.environ)
    env.setdefault('ROS_AUTOMATIC_DISCOVERY_RANGE', 'LOCALHOST')
    env.setdefault('ROS_DOMAIN_ID', '97')
    return env


def compare(missions: Sequence[Mission], seeds: int, env: dict[str, str]) -> None:
    """The side-by-side table of the three modes."""
    print(
        '| mission | mode | time scale | metric (mean ± sd over seeds) | wall per run [s] '
        '| matches the reference |'
    )
    print('|---|---|---|---|---|---|')
    for mission in missions:
        reference: list[RunResult] = []
        for mode in MODES:
            runs = [_run(mission, mode, seed, mission.time_scale, env) for seed in range(seeds)]
            if mode == 'builtin':
                reference = runs
            names = list(runs[0].metrics)
            metrics = ', '.join(f'{n} {_summary([r.metrics[n] for r in runs])}' for n in names)
            scale = 'n/a' if mode == 'builtin' else f'{mission.time_scale:g}'
            walls = _summary([r.wall_s for r in runs])
            verdict = 'reference' if mode == 'builtin' else _verdict(reference, runs, names)
            print(
                f'| {mission.name} | {mode} | {scale} | {metrics} | {walls} | {verdict} |',
                flush=True,
            )


def _verdict(reference: Sequence[RunResult], runs: Sequence[RunResult], names: list[str]) -> str:
    """Per metric, whether the mean matches the reference's within noise."""
    parts = []
    for name in names:
        ref = [r.metrics[name] for r in reference if math.isfinite(r.metrics[name])]
        other = [r.metrics[name] for r in runs if math.isfinite(r.metrics[name])]
        if not ref or not other:
            parts.append(f'{name} n/a')
            continue
        parts.append(f'{name} {"yes" if _matches(ref, other) else "no"}')
    return ', '.join(parts)


def sweep(scales: Sequence[float], seeds: int, env: dict[str, str]) -> None:
    """Coverage of 10 OA-Bug robots in processes per time scale against the reference."""
    reference = [_run(SWEEP, 'builtin', s, 1.0, env).metrics['coverage_%'] for s in range(seeds)]
    print(
        f'\n10 OA-Bug robots, 60 actions, {seeds} seeds; reference (builtin) coverage '
        f'{_summary(reference)} %'
    )
    print('| time scale | coverage [%] in processes | wall per run [s] | matches |')
    print('|---|---|---|---|')
    fastest = None
    for scale in scales:
        runs = [_run(SWEEP, 'processes', s, scale, env) for s in range(seeds)]
        coverage = [r.metrics['coverage_%'] for r in runs]
        ok = _matches(reference, coverage)
        if ok:
            fastest = scale
        walls = _summary([r.wall_s for r in runs])
        print(
            f'| {scale:g} | {_summary(coverage)} | {walls} | {"yes" if ok else "no"} |', flush=True
        )
    print(f'fastest matching time scale: {fastest if fastest is not None else "none"}')


def main(argv: Sequence[str] | None = None) -> int:
    """Command-line entry point."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument('--seeds', type=int, default=10, help='seeds per algorithm and mode')
    parser.add_argument(
        '--missions',
        '--algorithms',
        nargs='+',
        choices=tuple(MISSIONS),
        default=['oabug', 'bayes_swarm', 'msc_pf'],
        help='missions to compare (default: the three short ones)',
    )
    parser.add_argument('--sweep-seeds', type=int, default=5, help='seeds per time scale')
    parser.add_argument('--scales', type=float, nargs='+', default=[2.0, 4.0, 8.0, 16.0])
    parser.add_argument('--no-sweep', action='store_true', help='skip the time-scale sweep')
    parser.add_argument(
        '--time-scale',
        type=float,
        default=None,
        help="every mission's time scale (default: each its own)",
    )
    args = parser.parse_args(argv)
    print(
        f'# {shlex.join([Path(sys.argv[0]).name, *(argv if argv is not None else sys.argv[1:])])}'
    )
    env = _env()
    start = time.perf_counter()
    missions = [MISSIONS[name] for name in args.missions]
    if args.time_scale is not None:
        missions = [dataclasses.replace(m, time_scale=args.time_scale) for m in missions]
    compare(missions, args.seeds, env)
    if not args.no_sweep:
        sweep(args.scales, args.sweep_seeds, env)
    print(f'\ntotal wall time {time.perf_counter() - start:.0f} s')
    return 0


if __name__ == '__main__':
    sys.exit(main())
