"""Reliability studies: each algorithm under injected faults, OA-Bug under both sensor profiles.

Registered with ``swarm_study`` (entry point ``swarm_experiments.studies``):

* ``faults-oabug``: OA-Bug Gas+Sound on Small sites (10 robots, both departures), one row per
  fault scenario: room coverage, and whether the survivors kept working (the longest time a
  working robot stood still) and the robots with a dead lidar stopped;
* ``faults-bayes``: Bayes-Swarm-P, case 1, on the batch runner: tau and the detection rate;
* ``faults-msc``: MSC + PF, the proposed scheme (15 robots, 10 targets): the capture
  completion time (CCT) and the share of runs that capture every target;
* ``sensors-oabug``: every OA-Bug variant on Small sites from both departures, under the
  ``ideal`` and the ``realistic`` sensor profile.

A fault scenario is one string of ``--fault`` items (``'dropout_robots=2'``,
``'comm_loss_probability=0.5,comm_range_m=150'``; ``'none'``): the study's ``fault`` axis.
The fault onset is a fixed parameter (``fault_time_s``: dropouts and sensor faults both start
then). Everything is deterministic from the seed (for OA-Bug, the site index).
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np
import pandas as pd
from swarm_sim.engine import EngineConfig
from swarm_sim.faults import FaultConfig, FaultPlan
from swarm_sim.sensor_profiles import apply_sensor_profile

from swarm_experiments.cli_args import fault_config
from swarm_experiments.study import ReportPage, RunSpec, Smoke, Study

__all__ = [
    'parse_fault',
    'run_bayes_fault',
    'run_msc_fault',
    'run_oabug_fault',
    'run_oabug_sensors',
    'still_time_s',
    'studies',
]

OABUG_FAULTS = (
    'none',
    'dropout_robots=2',
    'dropout_robots=5',
    'dropout_robots=8',
    'stale_lidar_robots=2',
    'stuck_gas_robots=3',
    'drifting_gas_robots=3',
    'imu_drift_robots=3',
    'bearing_dropout_probability=0.9',
)
BAYES_FAULTS = (
    'none',
    'dropout_robots=1',
    'dropout_robots=2',
    'dropout_robots=4',
    'comm_loss_probability=0.5',
    'comm_loss_probability=0.9',
    'comm_range_m=0.5',
)
MSC_FAULTS = (
    'none',
    'dropout_robots=3',
    'dropout_robots=7',
    'comm_loss_probability=0.5',
    'comm_range_m=75',
)
# A robot that stood still longer than this while it should work counts as stuck [s].
STUCK_LIMIT_S = 20.0


def parse_fault(scenario: str, onset_s: float) -> FaultConfig:
    """The faults of a scenario string (comma-separated ``--fault`` items, or ``'none'``),
    with dropouts and sensor faults starting at ``onset_s``."""
    items = [] if scenario == 'none' else [i for i in scenario.split(',') if i.strip()]
    items += [f'dropout_time_s={onset_s}', f'sensor_time_s={onset_s}']
    return fault_config(items)


def still_time_s(
    times_s: np.ndarray, positions_m: np.ndarray, *, tolerance_m: float = 0.05
) -> float:
    """The longest interval [s] over which a robot's (T, 2) sampled positions stayed within
    ``tolerance_m`` of where the interval began (0 for a robot that never stood still)."""
    longest = 0.0
    anchor = 0
    for k in range(1, len(times_s)):
        if np.hypot(*(positions_m[k] - positions_m[anchor])) > tolerance_m:
            anchor = k
        else:
            longest = max(longest, float(times_s[k] - times_s[anchor]))
    return longest


def _oabug(spec: RunSpec, engine: EngineConfig, variant: str, departure: str) -> Any:
    from swarm_experiments.oabug_batch import run_spawn_batch
    from swarm_experiments.spawn import SpawnSettings

    cfg = spec.config
    settings = SpawnSettings(
        site=cfg['site'],
        site_seed=spec.seed,
        seed=spec.seed,
        variant=variant,
        robots=int(cfg['robots']),
        departure=departure,
        engine=engine,
    )
    return run_spawn_batch(settings).mission


def run_oabug_fault(spec: RunSpec) -> dict[str, Any]:
    """One OA-Bug run of the ``faults-oabug`` study."""
    cfg = spec.config
    onset = float(cfg['fault_time_s'])
    faults = parse_fault(cfg['fault'], onset)
    mission = _oabug(spec, EngineConfig(faults=faults), cfg['variant'], cfg['departure'])
    n = len(mission.robot_names)
    plan = FaultPlan(faults, n, spec.seed)
    # The robots expected to keep driving: all but the dropped and the lidar-less ones.
    idle = plan.mask('dropout') | plan.mask('stale_lidar')
    times = mission.trajectory_times_s
    still = [still_time_s(times, mission.trajectories[:, i, :2]) for i in range(n) if not idle[i]]
    # A lidar-less robot must stop within the stale timeout (0.5 s) plus a control period.
    late = times >= onset + 2.0
    stopped_moves = [
        float(np.hypot(*np.diff(mission.trajectories[late, i, :2], axis=0).T).sum())
        for i in np.flatnonzero(plan.mask('stale_lidar'))
    ]
    return {
        'coverage': 100.0 * mission.coverage,
        'complete': bool(mission.rooms_covered == mission.rooms_total),
        'sim_time_s': float(mission.sim_time_s),
        'survivors': int(n - plan.mask('dropout').sum()),
        'max_still_s': max(still, default=0.0),
        'stuck_survivors': int(sum(s > STUCK_LIMIT_S for s in still)),
        'faulty_moved_m': max(stopped_moves, default=0.0),
    }


def run_oabug_sensors(spec: RunSpec) -> dict[str, Any]:
    """One OA-Bug run of the ``sensors-oabug`` study."""
    cfg = spec.config
    engine = apply_sensor_profile(EngineConfig(), cfg['profile'])
    mission = _oabug(spec, engine, cfg['variant'], cfg['departure'])
    return {
        'coverage': 100.0 * mission.coverage,
        'complete': bool(mission.rooms_covered == mission.rooms_total),
        'sim_time_s': float(mission.sim_time_s),
    }


def run_bayes_fault(spec: RunSpec) -> dict[str, Any]:
    """One Bayes-Swarm run of the ``faults-bayes`` study."""
    from swarm_sim.signal_fields import get_case

    from swarm_experiments.bayes_batch import run_mission
    from swarm_experiments.spawn_bayes_swarm import batch_mission_spec

    cfg = spec.config
    case = get_case(cfg['case'])
    mission = batch_mission_spec(
        case,
        noise_std=float(cfg['noise_std']),
        planner_options={'outer_optimizer': cfg['outer_optimizer']},
    )
    mission = dataclasses.replace(
        mission, faults=parse_fault(cfg['fault'], float(cfg['fault_time_s']))
    )
    robots = int(cfg['robots']) or case.default_robots
    result = run_mission(mission, cfg['algorithm'], robots, spec.seed)
    return {
        'found': bool(result.found),
        'tau': float(result.tau) if result.found else math.nan,
        'end_time_s': float(result.end_time_s),
    }


def run_msc_fault(spec: RunSpec) -> dict[str, Any]:
    """One MSC + PF run of the ``faults-msc`` study."""
    from swarm_experiments.msc_pf_batch import BatchScenario, run_batch

    cfg = spec.config
    scenario = BatchScenario(
        scheme=cfg['scheme'],
        n_robots=int(cfg['robots']),
        n_targets=int(cfg['targets']),
        seed=spec.seed,
        max_time_s=float(cfg['max_time_s']),
        faults=parse_fault(cfg['fault'], float(cfg['fault_time_s'])),
    )
    result = run_batch(scenario)
    captured = np.isfinite(result.capture_times_s)
    return {
        'cct_s': float(result.cct_s),
        'all_captured': bool(captured.all()),
        'captured': int(captured.sum()),
        'duration_s': float(result.duration_s),
    }


def _planned(page: ReportPage, order: Sequence[str]) -> pd.DataFrame:
    """The rows of the seeds of the last plan and, when ``order`` is given, of the fault
    scenarios the study declares now (rows of older plans stay stored but are left out)."""
    rows = page.rows
    if rows.empty:
        return rows
    seeds = page.manifest.get('seeds')
    if seeds:
        rows = rows[rows['seed'].isin(seeds)]
    if order and 'config.fault' in rows.columns:
        rows = rows[rows['config.fault'].isin(order)]
    return rows.reset_index(drop=True)


def _summary(
    rows: pd.DataFrame, by: Sequence[str], metrics: Mapping[str, str], order: Sequence[str]
) -> pd.DataFrame:
    """Mean +- std (and count) of each metric per configuration, faults in study order."""
    out = []
    for key, group in rows.groupby(list(by), sort=False):
        key = key if isinstance(key, tuple) else (key,)
        row = {b.removeprefix('config.'): k for b, k in zip(by, key, strict=True)}
        row['runs'] = len(group)
        for column, label in metrics.items():
            values = pd.to_numeric(group[column], errors='coerce').astype(float)
            finite = values.dropna()
            if not len(finite):
                row[label] = 'n/a'
            elif label.startswith('runs ') and label.endswith('%'):  # a share of runs
                row[label] = f'{finite.mean():.0f}'
            elif label.startswith('runs with'):  # a count over the runs
                row[label] = f'{int((finite > 0).sum())}'
            else:
                spread = finite.std(ddof=1) if len(finite) > 1 else 0.0
                row[label] = f'{finite.mean():.3g} ± {spread:.2g}'
            if label.endswith('(complete runs)'):
                row[label] += f' ({len(finite)})'

        out.append(row)
    frame = pd.DataFrame(out)
    if 'fault' in frame.columns:
        rank = {f: i for i, f in enumerate(order)}
        frame = frame.sort_values('fault', key=lambda s: s.map(rank), kind='stable')
    return frame.reset_index(drop=True)


def _report_oabug_faults(page: ReportPage) -> None:
    rows = _planned(page, OABUG_FAULTS)
    if rows.empty:
        return
    rows = rows.assign(**{'metric.complete_pct': 100.0 * rows['metric.complete'].astype(float)})
    table = _summary(
        rows,
        ['config.departure', 'config.fault'],
        {
            'metric.coverage': 'coverage %',
            'metric.complete_pct': 'runs covering all rooms %',
            'metric.max_still_s': 'longest still survivor s',
            'metric.stuck_survivors': 'runs with a stuck survivor',
            'metric.faulty_moved_m': 'lidar-less robot moved m',
        },
        OABUG_FAULTS,
    )
    page.add_table(table, title='Reliability: OA-Bug Gas+Sound, Small, 10 robots', export='faults')


def _report_bayes_faults(page: ReportPage) -> None:
    rows = _planned(page, BAYES_FAULTS)
    if rows.empty:
        return
    rows = rows.assign(**{'metric.found_pct': 100.0 * rows['metric.found'].astype(float)})
    table = _summary(
        rows,
        ['config.fault'],
        {'metric.tau': 'tau (complete runs)', 'metric.found_pct': 'runs finding the source %'},
        BAYES_FAULTS,
    )
    page.add_table(table, title='Reliability: Bayes-Swarm-P, case 1', export='faults')


def _report_msc_faults(page: ReportPage) -> None:
    rows = _planned(page, MSC_FAULTS)
    if rows.empty:
        return
    rows = rows.assign(**{'metric.all_pct': 100.0 * rows['metric.all_captured'].astype(float)})
    table = _summary(
        rows,
        ['config.fault'],
        {
            'metric.cct_s': 'CCT s (complete runs)',
            'metric.all_pct': 'runs capturing all %',
            'metric.captured': 'targets captured',
        },
        MSC_FAULTS,
    )
    page.add_table(
        table, title='Reliability: MSC + PF (proposed), 15 robots, 10 targets', export='faults'
    )


def _report_sensors(page: ReportPage) -> None:
    rows = _planned(page, ())
    if rows.empty:
        return
    rows = rows.assign(**{'metric.complete_pct': 100.0 * rows['metric.complete'].astype(float)})
    table = _summary(
        rows,
        ['config.variant', 'config.departure', 'config.profile'],
        {'metric.coverage': 'coverage %', 'metric.complete_pct': 'runs covering all rooms %'},
        (),
    )
    page.add_table(
        table,
        title='OA-Bug variants under both sensor profiles, Small, 10 robots',
        export='sensors',
    )


def studies() -> list[Study]:
    """The reliability and sensor-profile studies."""
    return [
        Study(
            name='faults-oabug',
            run=run_oabug_fault,
            axes={'departure': ('center', 'edge'), 'fault': OABUG_FAULTS},
            params={'site': 'small', 'robots': 10, 'variant': 'gas_sound', 'fault_time_s': 60.0},
            runs=3,
            seed_label='site',
            description='OA-Bug Gas+Sound coverage under injected faults (onset at 60 s).',
            smoke=Smoke(
                runs=1, axes={'departure': ('center',), 'fault': ('none', 'dropout_robots=5')}
            ),
            report=_report_oabug_faults,
        ),
        Study(
            name='faults-bayes',
            run=run_bayes_fault,
            axes={'fault': BAYES_FAULTS},
            params={
                'case': 'case1',
                'algorithm': 'bayes_swarm_p',
                'robots': 0,
                'noise_std': 0.0,
                'outer_optimizer': 'grid',
                'fault_time_s': 10.0,
            },
            runs=3,
            description='Bayes-Swarm-P tau under injected faults (onset at 10 s).',
            smoke=Smoke(runs=1, axes={'fault': ('none', 'dropout_robots=2')}),
            report=_report_bayes_faults,
        ),
        Study(
            name='faults-msc',
            run=run_msc_fault,
            axes={'fault': MSC_FAULTS},
            params={
                'scheme': 'proposed',
                'robots': 15,
                'targets': 10,
                'max_time_s': 30000.0,
                'fault_time_s': 500.0,
            },
            runs=2,
            description='MSC + PF capture completion time under injected faults (onset 500 s).',
            smoke=Smoke(
                runs=1,
                axes={'fault': ('none', 'dropout_robots=7')},
                params={'targets': 3, 'max_time_s': 3000.0},
            ),
            report=_report_msc_faults,
        ),
        Study(
            name='sensors-oabug',
            run=run_oabug_sensors,
            axes={
                'variant': ('random', 'minimum', 'sound', 'gas', 'gas_sound'),
                'departure': ('center', 'edge'),
                'profile': ('ideal', 'realistic'),
            },
            params={'site': 'small', 'robots': 10},
            runs=3,
            seed_label='site',
            description='Every OA-Bug variant under the ideal and the realistic sensor profile.',
            smoke=Smoke(runs=1, axes={'variant': ('gas_sound',), 'departure': ('center',)}),
            report=_report_sensors,
        ),
    ]
