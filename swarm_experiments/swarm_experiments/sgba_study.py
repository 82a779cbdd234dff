"""The SGBA comparison for ``swarm_study``: SGBA beside OA-Bug on the same sites and seeds.

Study ``sgba-vs-oabug``: the OA-Bug paper's Fig. 4 setting (Small and Medium sites at the Table
II budget, 2-10 robots, centre and edge departure, coverage every 100 actions), with the method
as an axis: OA-Bug's Gas+Sound and Gas in the as-published profile (``profile=paper``, the rows
that lead), then SGBA (:mod:`oabug_robot.sgba`) with the authors' parameters (``sgba``) and
with its distances halved for the sites' doors (``sgba_scaled``). The seed is the site index,
so every method runs on the same sites and starts and results pair by site. Fixed parameters:
``actions`` (None: the Table II budget), ``speed`` [m/s], ``profile`` (OA-Bug's), and
``sgba.<name>`` for every SGBA node parameter (None: its default).
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import TYPE_CHECKING, Any

import pandas as pd

from swarm_experiments.study import RunSpec, Smoke, Study
from swarm_experiments.study.errors import UsageError

if TYPE_CHECKING:
    from swarm_experiments.study.report import ReportPage

__all__ = ['SGBA_VS_OABUG', 'run_comparison', 'studies']

SGBA_VS_OABUG = 'sgba-vs-oabug'
#: The methods in table order: OA-Bug as published first, then SGBA.
METHODS = ('gas_sound', 'gas', 'sgba', 'sgba_scaled')
#: SGBA parameters of each SGBA method (``sgba.<name>`` settings win): ``sgba`` keeps the
#: authors' distances; ``sgba_scaled`` halves them for the sites' 0.53 m doors.
SGBA_METHODS: dict[str, dict[str, Any]] = {'sgba': {}, 'sgba_scaled': {'geometry_scale': 0.5}}


def _sgba_parameter_names() -> tuple[str, ...]:
    from oabug_robot.sgba.settings import SGBA_PARAMETERS

    from swarm_experiments.sgba_batch import MISSION_PARAMETERS

    return tuple(name for name in SGBA_PARAMETERS.names if name not in MISSION_PARAMETERS)


def _sgba_overrides(config: Mapping[str, Any]) -> dict[str, Any]:
    given = config.get('sgba') or {}
    chosen = {name: value for name, value in given.items() if value is not None}
    return {**SGBA_METHODS.get(str(config['method']), {}), **chosen}


def _sgba_settings(config: Mapping[str, Any], seed: int) -> Any:
    from swarm_experiments.sgba_batch import SgbaSettings

    return SgbaSettings(
        site=str(config['site']),
        site_seed=int(seed),
        robots=int(config['robots']),
        departure=str(config['departure']),
        seed=int(seed),
        actions=None if config['actions'] is None else int(config['actions']),
        speed_mps=float(config['speed']),
        robot_parameters=_sgba_overrides(config),
    )


def check_config(config: Mapping[str, Any]) -> None:
    """Check one configuration before anything runs.

    Raises:
        UsageError: an unknown method, or a value SGBA or OA-Bug would reject.
    """
    from oabug_robot.sgba.settings import SGBA_PARAMETERS
    from swarm_common.errors import SwarmError
    from swarm_common.params import ParameterError

    from swarm_experiments.oabug_study import check_config as check_oabug

    method = config['method']
    if method not in METHODS:
        raise UsageError(f'unknown method {method!r}; choose one of {", ".join(METHODS)}')
    if method not in SGBA_METHODS:
        check_oabug({**config, 'variant': method})
        return
    unknown = sorted(set(config.get('sgba') or {}) - set(_sgba_parameter_names()))
    if unknown:
        raise UsageError(f'unknown SGBA parameters: {", ".join(unknown)}')
    try:
        overrides = _sgba_overrides(config)
        for name, value in overrides.items():
            SGBA_PARAMETERS.check(name, value)
        # build() takes the values as given (e.g. 'authors'), as the run passes them on.
        settings = _sgba_settings(config, 0)
        SGBA_PARAMETERS.build({'robot_count': settings.robots, **overrides})
    except (ParameterError, SwarmError, ValueError, TypeError) as err:
        raise UsageError(' '.join(str(err).split())) from err


def run_comparison(spec: RunSpec) -> dict[str, Any]:
    """One run: OA-Bug (``method`` a Table I variant) through the Fig. 4 run function, or
    SGBA on its batch path; the same metrics and coverage curve either way."""
    from swarm_experiments.oabug_study import coverage_metrics, run_fig4
    from swarm_experiments.sgba_batch import run_sgba

    config = spec.config
    if config['method'] not in SGBA_METHODS:
        oabug = {k: v for k, v in config.items() if k not in ('method', 'sgba')}
        return run_fig4(
            RunSpec(spec.study, {**oabug, 'variant': config['method']}, spec.seed, spec.run_id)
        )
    settings = _sgba_settings(config, spec.seed)
    mission = run_sgba(settings)
    return coverage_metrics(mission, settings.budget_actions, settings.speed_mps)


def studies() -> list[Study]:
    """The SGBA studies (entry point ``swarm_experiments.studies``)."""
    from swarm_experiments.oabug_study import _fixed_parameters

    params = _fixed_parameters()
    params['sgba'] = dict.fromkeys(_sgba_parameter_names())
    return [
        Study(
            name=SGBA_VS_OABUG,
            run=run_comparison,
            axes={
                'site': ('small', 'medium'),
                'method': METHODS,
                'robots': (2, 4, 6, 8, 10),
                'departure': ('center', 'edge'),
            },
            params=params,
            runs=20,
            seed_label='site',
            description=(
                'SGBA (McGuire et al. 2019) beside OA-Bug Gas+Sound and Gas (paper profile) on '
                "the same sites: room coverage and its curve, the OA-Bug paper's Fig. 4 setting."
            ),
            smoke=Smoke(
                runs=1, axes={'site': ('small',), 'robots': (10,)}, params={'actions': 100}
            ),
            report=report_comparison,
            check=check_config,
        )
    ]


def report_comparison(page: ReportPage) -> None:
    """Coverage per method (OA-Bug first), and SGBA minus each OA-Bug method paired by site."""
    from swarm_experiments.study.report import paired_differences

    rows = page.rows
    if 'config.method' not in rows:
        return
    page.add_heading('SGBA beside OA-Bug')
    records = []
    site_order = {'small': 0, 'medium': 1, 'big': 2}
    groups = sorted(
        rows.groupby(['config.site', 'config.departure', 'config.robots'], sort=False),
        key=lambda item: (site_order.get(str(item[0][0]), 3), str(item[0][0]), *item[0][1:]),
    )
    for (site, departure, robots), group in groups:
        for method in METHODS:
            runs = group[group['config.method'] == method]['metric.coverage_pct']
            if len(runs):
                records.append(
                    {
                        'site': site,
                        'robots': robots,
                        'departure': departure,
                        'method': method,
                        'coverage %': f'{runs.mean():.1f} ± {runs.std(ddof=0):.1f}',
                        'sites': len(runs),
                    }
                )
    page.add_table(
        pd.DataFrame(records), title='Coverage % (mean ± std over sites)', export='coverage'
    )
    frames = []
    for baseline in ('gas_sound', 'gas'):
        subset = rows[rows['config.method'].isin((baseline, *SGBA_METHODS))]
        if subset['config.method'].nunique() < 2:
            continue
        table = paired_differences(
            subset,
            'metric.coverage_pct',
            by='config.method',
            baseline=baseline,
            group_by=('config.site', 'config.robots', 'config.departure'),
        )
        table.insert(0, 'comparison', table['config.method'] + f' - {baseline}')
        frames.append(table.drop(columns=['config.method']))
    if frames:
        page.add_table(
            pd.concat(frames, ignore_index=True),
            title='SGBA minus OA-Bug on the same sites (coverage points)',
            digits=2,
            export='paired',
        )
