"""The OA-Bug Fig. 4 study for ``swarm_study``: every configuration of the paper's Fig. 4.

Axes as in the paper (Sec. III-B): the site configuration (Small, Medium, Big of Table II),
the five Table I variants (the full OA-Bug and its four ablations), 2/4/6/8/10 robots and
the centre or edge departure, each on 100 generated sites (the seed is the site index; the
same index gives the same site in every configuration, so results pair by site). Each run is
one :func:`swarm_experiments.oabug_batch.run_spawn_batch` mission at the Table II budget,
and records the coverage every 100 actions per robot as the paper's time series.

Fixed parameters (``--set NAME=VALUE``) use the spawner's names: ``actions`` (None: the
Table II budget), ``speed`` [m/s], ``profile`` (``paper``, the default, or ``tuned``: see
:mod:`oabug_robot.profiles`), and every OA-Bug node parameter the spawner's ``--param``
takes (None: the profile's value). They are typed and checked as the spawner checks them
before anything runs.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from typing import TYPE_CHECKING, Any

import numpy as np
import pandas as pd

from swarm_experiments.oabug_reference import (
    AUTHORS_SIM_COVERAGE,
    AUTHORS_SIM_CURVE,
    AUTHORS_SIM_SITES,
    PAPER_BEST_COVERAGE_PCT,
    VARIANT_ORDER,
)
from swarm_experiments.study import RunSpec, Smoke, Study
from swarm_experiments.study.errors import UsageError

if TYPE_CHECKING:
    from swarm_experiments.mission import MissionResult
    from swarm_experiments.study.report import ReportPage

__all__ = [
    'ACTIONS_PER_SAMPLE',
    'FIG4',
    'coverage_every',
    'coverage_metrics',
    'run_fig4',
    'studies',
]

FIG4 = 'oabug-fig4'
#: The paper records coverage every 100 actions (of 0.1 m) per robot.
ACTIONS_PER_SAMPLE = 100
SITES = ('small', 'medium', 'big')
ROBOTS = (2, 4, 6, 8, 10)
DEPARTURES = ('center', 'edge')
PROFILE_ORDER = ('paper', 'tuned')


def _node_parameter_names() -> tuple[str, ...]:
    from oabug_robot.node_settings import OABUG_PARAMETERS

    from swarm_experiments.spawn import SPAWNER_PARAMETERS

    return tuple(name for name in OABUG_PARAMETERS.names if name not in SPAWNER_PARAMETERS)


def _robot_parameters(config: Mapping[str, Any]) -> dict[str, Any]:
    return {
        name: config[name]
        for name in _node_parameter_names()
        if name in config and config[name] is not None
    }


def _settings(config: Mapping[str, Any], seed: int) -> Any:
    from swarm_experiments.spawn import SpawnSettings

    return SpawnSettings(
        site=str(config['site']),
        site_seed=int(seed),
        variant=str(config['variant']),
        robots=int(config['robots']),
        departure=str(config['departure']),
        seed=int(seed),
        actions=None if config['actions'] is None else int(config['actions']),
        speed_mps=float(config['speed']),
        profile=str(config['profile']),
        robot_parameters=_robot_parameters(config),
    )


def check_config(config: Mapping[str, Any]) -> None:
    """Check one configuration's parameters as the spawner does (before any run).

    Raises:
        UsageError: a value the spawner or the OA-Bug node would reject.
    """
    from oabug_robot.node_settings import OABUG_PARAMETERS
    from oabug_robot.profiles import PROFILES
    from swarm_common.errors import SwarmError
    from swarm_common.params import ParameterError

    overrides = _robot_parameters(config)
    try:
        for name, value in overrides.items():
            OABUG_PARAMETERS.check(name, value)
        # build() takes the values as given (e.g. 'toward'), as the run passes them on.
        settings = _settings(config, 0)
        OABUG_PARAMETERS.build(
            {
                'variant': settings.variant,
                'robot_count': settings.robots,
                **PROFILES[settings.profile],
                **overrides,
            }
        )
    except (ParameterError, SwarmError, ValueError, TypeError) as err:
        raise UsageError(' '.join(str(err).split())) from err


def coverage_every(
    entry_times_s: np.ndarray, rooms_total: int, period_s: float, samples: int
) -> list[float]:
    """Covered fraction of the rooms at ``period_s``, ``2 period_s``, ... (``samples`` values),
    from the times of the first entries into each room (a run that ended early keeps its
    final coverage)."""
    times = np.sort(np.asarray(entry_times_s, dtype=float))
    marks = period_s * np.arange(1, samples + 1)
    covered = np.searchsorted(times, marks + 1e-9, side='right')
    return (covered / max(rooms_total, 1)).tolist()


def coverage_metrics(
    mission: MissionResult, budget_actions: int, speed_mps: float
) -> dict[str, Any]:
    """The Fig. 4 metrics of a finished site mission: coverage, rooms, time, robot metres and
    the coverage every :data:`ACTIONS_PER_SAMPLE` actions of ``budget_actions`` at
    ``speed_mps``."""
    from swarm_experiments.spawn import ACTION_LENGTH_M

    samples = max(1, budget_actions // ACTIONS_PER_SAMPLE)
    period_s = ACTIONS_PER_SAMPLE * ACTION_LENGTH_M / speed_mps
    entries = np.array([entry.time_s for entry in mission.room_entries], dtype=float)
    return {
        'coverage_pct': 100.0 * mission.coverage,
        'rooms_covered': int(mission.rooms_covered),
        'rooms_total': int(mission.rooms_total),
        'all_covered': bool(mission.rooms_covered == mission.rooms_total),
        'sim_time_s': float(mission.sim_time_s),
        'robot_m': float(mission.distance_travelled_m.sum()),
        'coverage_pct_every_100_actions': [
            100.0 * value
            for value in coverage_every(entries, mission.rooms_total, period_s, samples)
        ],
    }


def run_fig4(spec: RunSpec) -> dict[str, Any]:
    """One Fig. 4 run: the mission on the batch path, its coverage and the coverage curve."""
    from swarm_experiments.oabug_batch import run_spawn_batch

    settings = _settings(spec.config, spec.seed)
    result = run_spawn_batch(settings)
    return coverage_metrics(result.mission, settings.budget_actions, settings.speed_mps)


def _fixed_parameters() -> dict[str, Any]:
    params: dict[str, Any] = {'actions': None, 'speed': 0.3, 'profile': 'paper'}
    params.update(dict.fromkeys(_node_parameter_names()))
    return params


def studies() -> list[Study]:
    """The OA-Bug studies (entry point ``swarm_experiments.studies``)."""
    return [
        Study(
            name=FIG4,
            run=run_fig4,
            axes={
                'site': SITES,
                'variant': VARIANT_ORDER,
                'robots': ROBOTS,
                'departure': DEPARTURES,
            },
            params=_fixed_parameters(),
            runs=100,
            seed_label='site',
            description=(
                'OA-Bug paper Fig. 4: coverage of the five Table I variants on Small, Medium '
                'and Big sites, 2-10 robots, centre and edge departure, 100 sites each; '
                'coverage every 100 actions.'
            ),
            smoke=Smoke(
                runs=2, axes={'site': ('small',), 'robots': (2, 10)}, params={'actions': 300}
            ),
            report=report_fig4,
            check=check_config,
        )
    ]


# The report.


def _profiles(rows: pd.DataFrame) -> list[str]:
    present = [str(v) for v in pd.unique(rows['param.profile'])]
    return [p for p in PROFILE_ORDER if p in present] + sorted(set(present) - set(PROFILE_ORDER))


def _pm(mean: float, std: float) -> str:
    if not math.isfinite(mean):
        return ''
    return f'{mean:.1f} ± {std:.1f}' if math.isfinite(std) else f'{mean:.1f}'


def _coverage_table(rows: pd.DataFrame, site: str, *, reference: bool) -> pd.DataFrame:
    records = []
    for departure in DEPARTURES:
        for variant in VARIANT_ORDER:
            record: dict[str, Any] = {'departure': departure, 'variant': variant}
            for robots in ROBOTS:
                runs = rows[
                    (rows['config.departure'] == departure)
                    & (rows['config.variant'] == variant)
                    & (rows['config.robots'] == robots)
                ]['metric.coverage_pct']
                if not len(runs):
                    continue
                record[f'{robots} robots'] = f'{_pm(runs.mean(), runs.std(ddof=0))} (n={len(runs)})'
                ref = AUTHORS_SIM_COVERAGE.get((site, robots, departure, variant))
                if reference and ref is not None:
                    sites = AUTHORS_SIM_SITES[(site, robots)]
                    record[f"{robots} robots, authors' sim."] = f'{_pm(*ref)} (n={sites})'
            if len(record) > 2:
                records.append(record)
    return pd.DataFrame(records)


def _paired_table(rows: pd.DataFrame) -> pd.DataFrame:
    from swarm_experiments.study.report import paired_differences

    comparisons = (
        ('gas_sound', 'gas'),
        ('gas', 'minimum'),
        ('sound', 'minimum'),
        ('minimum', 'random'),
    )
    frames = []
    for other, baseline in comparisons:
        subset = rows[rows['config.variant'].isin((other, baseline))]
        if subset['config.variant'].nunique() < 2:
            continue
        table = paired_differences(
            subset,
            'metric.coverage_pct',
            by='config.variant',
            baseline=baseline,
            group_by=('config.robots', 'config.departure'),
        )
        table.insert(0, 'comparison', f'{other} - {baseline}')
        frames.append(table.drop(columns=['config.variant']))
    if not frames:
        return pd.DataFrame()
    return pd.concat(frames, ignore_index=True)


def _curve_figure(page: ReportPage, rows: pd.DataFrame, site: str, profile: str) -> None:
    from matplotlib.figure import Figure

    robots_present = [r for r in ROBOTS if (rows['config.robots'] == r).any()]
    if not robots_present:
        return
    figure = Figure(figsize=(max(3.0 * len(robots_present), 5.5), 5.6))
    axes = figure.subplots(2, len(robots_present), squeeze=False, sharey=True)
    for row, departure in enumerate(DEPARTURES):
        for col, robots in enumerate(robots_present):
            ax = axes[row][col]
            for index, variant in enumerate(VARIANT_ORDER):
                runs = rows[
                    (rows['config.departure'] == departure)
                    & (rows['config.variant'] == variant)
                    & (rows['config.robots'] == robots)
                ]['series.coverage_pct_every_100_actions']
                if not len(runs):
                    continue
                curves = np.array([np.asarray(c, dtype=float) for c in runs])
                x = ACTIONS_PER_SAMPLE * np.arange(1, curves.shape[1] + 1)
                color = f'C{index}'
                ax.plot(x, curves.mean(axis=0), color=color, label=variant)
                ref = AUTHORS_SIM_CURVE.get((site, robots, departure, variant))
                if ref is not None:
                    rx = ACTIONS_PER_SAMPLE * np.arange(1, len(ref) + 1)
                    ax.plot(rx, ref, color=color, linestyle=':', linewidth=1)
            ax.set_title(f'{departure}, {robots} robots', fontsize='small')
            ax.set_ylim(0, 100)
            ax.grid(alpha=0.3)
            if row == 1:
                ax.set_xlabel('actions per robot')
            if col == 0:
                ax.set_ylabel('coverage %')
    axes[0][0].legend(fontsize='x-small', loc='lower right')
    figure.suptitle(
        f'OA-Bug Fig. 4, {site}, profile {profile}: mean coverage against actions '
        "(dotted: the authors' simulator)",
        fontsize='small',
    )
    page.add_figure(
        figure, f'fig4-{site}-{profile}', caption=f'coverage against actions, {site}, {profile}'
    )


def report_fig4(page: ReportPage) -> None:
    """The Fig. 4 sections: per site and profile (the as-published one first) the coverage
    table beside the authors' simulator, the curves as the paper draws them, the paired
    comparisons of the variants on the same sites, and tuned against paper when both ran."""
    rows = page.rows
    if 'param.profile' not in rows:
        return
    page.add_heading('OA-Bug Fig. 4')
    page.add_text(
        'Coverage % (mean ± population std over sites, n sites) at the end of the search, '
        "beside the authors' simulator where it was measured. The paper publishes Fig. 4 "
        f"only as a plot; its one number is the abstract's best coverage, "
        f'{PAPER_BEST_COVERAGE_PCT} %. Profiles: `paper` is Table I read literally and leads; '
        '`tuned` is the node defaults (departures in docs/oabug.md). Curves carry a run that '
        'covered every room forward at its final coverage.'
    )
    for profile in _profiles(rows):
        of_profile = rows[rows['param.profile'] == profile]
        for site in SITES:
            of_site = of_profile[of_profile['config.site'] == site]
            if of_site.empty:
                continue
            # The authors' figures are at the Table II budget and 0.3 m/s.
            table_budget = bool(
                of_site['param.actions'].isna().all() and (of_site['param.speed'] == 0.3).all()
            )
            page.add_table(
                _coverage_table(of_site, site, reference=table_budget),
                title=f'{site}, profile {profile}: coverage %',
                export=f'{site}-{profile}',
            )
            if not table_budget:
                page.add_text(
                    "_Not at the Table II budget: the authors' figures are left out (their "
                    'curves in the plot are per action and still comparable)._'
                )
            _curve_figure(page, of_site, site, profile)
            paired = _paired_table(of_site)
            if not paired.empty:
                page.add_table(
                    paired,
                    title=f'{site}, profile {profile}: paired differences on the same sites '
                    '(coverage points)',
                    digits=2,
                    export=f'{site}-{profile}-paired',
                )
    profiles = _profiles(rows)
    if 'paper' in profiles and len(profiles) > 1:
        from swarm_experiments.study.report import paired_differences

        table = paired_differences(
            rows,
            'metric.coverage_pct',
            by='param.profile',
            baseline='paper',
            group_by=('config.site', 'config.variant', 'config.robots', 'config.departure'),
        )
        page.add_table(
            table,
            title='Profiles against paper on the same sites (coverage points)',
            digits=2,
            export='profiles-paired',
        )
