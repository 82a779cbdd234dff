"""Each effect of the realistic sensor profile alone, on one OA-Bug variant, paired by site.

The ``sensors-oabug`` study compares the ``ideal`` and the ``realistic`` sensor profile as a
whole. This script takes the realistic profile apart: every run uses the ideal engine with
one effect of :class:`swarm_sim.sensor_profiles.RealisticSensors` switched on (its default
values), and reports the coverage against the ideal run on the same site (site index = site
seed = run seed, as in the Fig. 4 and sensor studies, so the ``ideal`` and ``realistic`` rows
equal that study's). ``aoa-random`` is a control, not part of the profile: every bearing is
a multipath outlier, i.e. uniformly random. Example (the Sound variant from the centre)::

    python benchmarks/sensor_effects_oabug.py --variant sound --sites 100 --workers 2

``--trace`` adds where the robots went (from the true trajectories): their mean distance
from the departure over the second half of the run, the share of those poses within
``RIM_M`` of the outer bounds of all poses (the site's rim), and how many distinct 1 m cells
the swarm visited.

Effects: ideal, realistic (all at once), aoa-nlos (the AoA non-line-of-sight model: wall
bias, outliers and long distances together), aoa-bias, aoa-outliers, aoa-distances,
aoa-los-noise (the line-of-sight azimuth noise), scent (evaporation), lidar (range noise and
dropouts), imu (gyro bias and drift), aoa-random.
"""

from __future__ import annotations

import argparse
import dataclasses
import math
import statistics
from collections.abc import Sequence
from concurrent.futures import ProcessPoolExecutor
from typing import Any, NamedTuple

import numpy as np
from swarm_sim.engine import EngineConfig
from swarm_sim.sensor_profiles import AoaRealismConfig, RealisticSensors, apply_sensor_profile


def effect_configs(ideal: EngineConfig | None = None) -> dict[str, EngineConfig]:
    """The engine configuration of every effect: ``ideal`` with that effect switched on."""
    base = ideal if ideal is not None else EngineConfig()
    r = RealisticSensors()
    real = apply_sensor_profile(base, 'realistic', r)
    replace = dataclasses.replace
    return {
        'ideal': base,
        'realistic': real,
        'aoa-nlos': replace(base, aoa=r.aoa),
        'aoa-bias': replace(
            base,
            aoa=replace(
                r.aoa,
                outlier_probability_los=0.0,
                outlier_probability_per_wall=0.0,
                wall_distance_factor=1.0,
            ),
        ),
        'aoa-outliers': replace(
            base, aoa=replace(r.aoa, nlos_bias_std_rad_per_wall=0.0, wall_distance_factor=1.0)
        ),
        'aoa-distances': replace(
            base,
            aoa=replace(
                r.aoa,
                nlos_bias_std_rad_per_wall=0.0,
                outlier_probability_los=0.0,
                outlier_probability_per_wall=0.0,
            ),
        ),
        'aoa-los-noise': replace(base, bearings=real.bearings),
        'scent': replace(base, scent=real.scent),
        'lidar': replace(base, lidar=real.lidar),
        'imu': replace(base, imu=real.imu),
        'aoa-random': replace(
            base, aoa=AoaRealismConfig(outlier_probability_los=1.0, outlier_probability_max=1.0)
        ),
    }


EFFECTS = tuple(effect_configs())


RIM_M = 1.5


class Outcome(NamedTuple):
    """One run: its room coverage and where its robots went (:func:`trace_metrics`)."""

    coverage_pct: float
    distance_m: float
    rim_share: float
    cells: int


def trace_metrics(trajectories: np.ndarray) -> tuple[float, float, int]:
    """Where the robots of (T, N, >=2) true poses went: the mean distance [m] from the
    robots' mean start over the second half of the samples, the share of those poses within
    :data:`RIM_M` of the bounding box of all poses, and the distinct 1 m cells visited."""
    xy = np.asarray(trajectories, dtype=float)[:, :, :2]
    late = xy[len(xy) // 2 :]
    distance = np.hypot(*(late - xy[0].mean(axis=0)).transpose(2, 0, 1))
    low, high = xy.reshape(-1, 2).min(axis=0), xy.reshape(-1, 2).max(axis=0)
    to_rim = np.minimum(late - low, high - late).min(axis=2)
    cells = np.unique(np.floor(xy.reshape(-1, 2)).astype(np.int64), axis=0)
    return float(distance.mean()), float((to_rim < RIM_M).mean()), len(cells)


def _outcome(job: tuple[EngineConfig, int, dict[str, Any]]) -> Outcome:
    """One run: (engine configuration, site index, SpawnSettings fields)."""
    from swarm_experiments.oabug_batch import run_spawn_batch
    from swarm_experiments.spawn import SpawnSettings

    engine, site, fields = job
    settings = SpawnSettings(site_seed=site, seed=site, engine=engine, **fields)
    mission = run_spawn_batch(settings).mission
    return Outcome(100.0 * mission.coverage, *trace_metrics(mission.trajectories))


def table(coverage: dict[str, list[float]]) -> list[str]:
    """Markdown rows: each effect's coverage and its difference from ``ideal`` by site (the
    studies' :func:`~swarm_experiments.study.report.paired_differences`)."""
    import pandas as pd
    from swarm_experiments.study.report import paired_differences

    rows = pd.DataFrame(
        [
            {'sensors': effect, 'seed': index, 'coverage': value}
            for effect, values in coverage.items()
            for index, value in enumerate(values)
        ]
    )
    paired = paired_differences(rows, 'coverage', by='sensors', baseline='ideal')
    lines = [
        '| sensors | runs | coverage % | minus ideal (± s.e.) | more / same / less '
        '| p (Wilcoxon) |',
        '| --- | ---: | --- | --- | --- | ---: |',
    ]
    for effect, values in coverage.items():
        spread = statistics.stdev(values) if len(values) > 1 else 0.0
        row = f'| {effect} | {len(values)} | {statistics.fmean(values):.1f} ± {spread:.1f} |'
        if effect == 'ideal':
            lines.append(row + ' | | |')
            continue
        d = paired[paired['sensors'] == effect].iloc[0]
        se = 0.0 if math.isnan(d.se_diff) else d.se_diff
        # The signed-rank test needs two differing sites; identical runs everywhere is p 1.
        p = 'n/a' if math.isnan(d.p_wilcoxon) else f'{d.p_wilcoxon:.2g}'
        if d.ties == d.pairs:
            p = '1'
        row += f' {d.mean_diff:+.1f} ± {se:.1f} | {d.wins} / {d.ties} / {d.losses} | {p} |'
        lines.append(row)
    return lines


def run(
    effects: Sequence[str],
    sites: Sequence[int],
    fields: dict[str, Any],
    workers: int,
) -> dict[str, list[Outcome]]:
    """Every effect's runs (``ideal`` first) on every site, on ``workers`` local processes."""
    names = ['ideal', *(e for e in effects if e != 'ideal')]
    configs = effect_configs()
    jobs = [(configs[effect], site, fields) for effect in names for site in sites]
    if workers == 1:
        values = [_outcome(job) for job in jobs]
    else:
        with ProcessPoolExecutor(workers) as pool:
            values = list(pool.map(_outcome, jobs))
    n = len(sites)
    return {name: values[i * n : (i + 1) * n] for i, name in enumerate(names)}


def trace_table(outcomes: dict[str, list[Outcome]]) -> list[str]:
    """Markdown rows: where each effect's robots went (means over the sites)."""
    lines = [
        f'| sensors | distance from the start, 2nd half m | poses within {RIM_M} m of the rim '
        '| 1 m cells visited |',
        '| --- | ---: | ---: | ---: |',
    ]
    for effect, runs in outcomes.items():
        distance = statistics.fmean(o.distance_m for o in runs)
        rim = statistics.fmean(o.rim_share for o in runs)
        cells = statistics.fmean(o.cells for o in runs)
        lines.append(f'| {effect} | {distance:.2f} | {100.0 * rim:.0f} % | {cells:.1f} |')
    return lines


def main(argv: Sequence[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split('\n\n')[0])
    parser.add_argument('--config', choices=('small', 'medium', 'big'), default='small')
    parser.add_argument(
        '--variant', choices=('random', 'minimum', 'sound', 'gas', 'gas_sound'), default='sound'
    )
    parser.add_argument('--departure', choices=('center', 'edge'), default='center')
    parser.add_argument('--robots', type=int, default=10)
    parser.add_argument('--sites', type=int, default=20)
    parser.add_argument('--first-site', type=int, default=0)
    parser.add_argument('--profile', choices=('paper', 'tuned'), default='paper')
    parser.add_argument(
        '--effects',
        default=','.join(EFFECTS),
        help=f'comma-separated, from: {", ".join(EFFECTS)} (ideal is always run)',
    )
    parser.add_argument('--workers', type=int, default=1, help='local processes')
    parser.add_argument('--trace', action='store_true', help='also where the robots went')
    args = parser.parse_args(argv)
    effects = [e.strip() for e in args.effects.split(',') if e.strip()]
    unknown = sorted(set(effects) - set(EFFECTS))
    if unknown:
        parser.error(f'unknown effect {", ".join(unknown)}; choose from {", ".join(EFFECTS)}')
    if min(args.sites, args.robots, args.workers) < 1 or args.first_site < 0:
        parser.error('--sites, --robots and --workers must be at least 1, --first-site >= 0')
    fields = {
        'site': args.config,
        'variant': args.variant,
        'robots': args.robots,
        'departure': args.departure,
        'profile': args.profile,
    }
    sites = range(args.first_site, args.first_site + args.sites)
    outcomes = run(effects, sites, fields, args.workers)
    print(
        f'{args.config}, {args.variant}, {args.robots} robots from the {args.departure}, '
        f'profile {args.profile}, sites {sites.start}-{sites.stop - 1}'
    )
    print('\n'.join(table({k: [o.coverage_pct for o in v] for k, v in outcomes.items()})))
    if args.trace:
        print('\n'.join(trace_table(outcomes)))
    return 0


if __name__ == '__main__':
    raise SystemExit(main())
