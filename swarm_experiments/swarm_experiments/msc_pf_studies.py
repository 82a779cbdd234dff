"""The MSC + PF studies of ``swarm_study``: the paper's Fig. 4 and the searches beyond it.

Every run is one :func:`swarm_experiments.msc_pf_batch.run_batch` mission (the node's own
loop per robot, equal to the ROS path run for run). A configuration is a *variant* (a scheme
plus controller settings, :data:`VARIANTS`), a target count and a robot count; a seed fixes
targets, starts, noise and controllers, so variants pair by seed.

Per run the rows hold the capture completion time (``metric.cct_s``; T_max when not every
target was captured, with ``metric.finished`` false, so a mean is then a lower bound) and its
breakdown: ``metric.last_heard_s`` (the last target's first hearing: the search),
``metric.after_heard_s`` (what the approaches and work took after it), the per-target
approach medians, and as time series ``series.capture_times_s`` (the k-th capture, ascending)
and ``series.first_heard_s`` (the k-th first hearing, ascending).

Controller settings are the node's parameters (``msc_pf/config/msc_pf.yaml``) under
``controller``: ``swarm_study run msc_pf-fig4 --set controller.msc.leader_rule=pbest``. A
variant's own settings apply first, ``--set`` values that differ from the defaults on top.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from typing import Any

import numpy as np
from msc_pf.parameters import MSC_PF_PARAMETERS
from msc_pf.schemes import Scheme

from swarm_experiments.msc_pf_batch import BatchScenario, run_batch
from swarm_experiments.study import ReportPage, RunSpec, Smoke, Study, paired_differences

__all__ = ['PAPER_FIG4', 'VARIANTS', 'run_msc_pf', 'studies']

# The robots' own settings (ID, seed, steering) and those the variant decides stay out.
_NOT_STUDY_PARAMETERS = ('scheme', 'robot_id', 'seed')

#: The PSO-style personal-best leader rule set up to finish: straight legs ended at their
#: best point (``msc.leader_rule=pbest_turn``). The specification's pbest rule, the best of
#: the last 10 positions, dithers in the noise and captures nothing (docs/msc_pf.md).
PBEST_FINISHING = {'msc.leader_rule': 'pbest_turn'}

#: variant -> (scheme, controller settings on top of the defaults).
VARIANTS: dict[str, tuple[str, dict[str, Any]]] = {
    'proposed': ('proposed', {}),
    'msc_pf': ('msc_pf', {}),
    'msc': ('msc', {}),
    'msc-pbest': ('msc', dict(PBEST_FINISHING)),
    'msc-solo': ('msc', {'swarm.max_size': 1}),
    'msc-gather': ('msc', {'swarm.search_alone': True}),
    'proposed-solo': ('proposed', {'swarm.max_size': 1}),
    'proposed-gather': ('proposed', {'swarm.search_alone': True}),
    'msc-sweep': ('msc', {'swarm.search_alone': True, 'search.mode': 'sector'}),
    'msc-sweep-swarm': ('msc', {'search.mode': 'sector'}),
    'msc-sweep-pbest': (
        'msc',
        {'swarm.search_alone': True, 'search.mode': 'sector', **PBEST_FINISHING},
    ),
    'proposed-sweep': (
        'proposed',
        {
            'swarm.search_alone': True,
            'search.mode': 'sector',
            'search.coverage_prior_weight': 0.05,
            'phases.non_detection_window_s': 120.0,
            'particle_filter.censored_likelihood': False,
            'phases.pursue_memory_s': 30.0,
            'phases.far_aim': 'estimate',
            'phases.near_estimate_spread_m': 15.0,
            'phases.max_pursuers': 2,
            'phases.converged_give_up_m': 200.0,
            'phases.converged_max_age_s': 600.0,
        },
    ),
}

MSC_VARIANTS = tuple(v for v, (scheme, _) in VARIANTS.items() if scheme == 'msc')

#: What the paper publishes for Fig. 4 (Murakami, Yomo and Takizawa, Sec. IV-B): a bar chart
#: of the CCT of MSC, MSC+PF and the proposed scheme at 10, 15 and 20 targets, 15 robots
#: in the project's reading (the paper prints no robot count, no run count and no values).
#: The text states the order and the trend, which the report checks.
PAPER_FIG4 = {
    'claims': (
        'MSC has the largest CCT of the three schemes',
        'MSC+PF is better than MSC, without significant gain',
        'the proposed scheme has the smallest CCT, a significant reduction',
        'CCT increases with the number of targets for all schemes',
    ),
    'values_printed': False,
}


def _controller_defaults() -> dict[str, Any]:
    """Nested {section: {field: default}} of the node's controller parameters."""
    nested: dict[str, Any] = {}
    for parameter in MSC_PF_PARAMETERS.parameters:
        if parameter.path[0] != 'controller' or parameter.name in _NOT_STUDY_PARAMETERS:
            continue
        node = nested
        keys = parameter.name.split('.')
        for key in keys[:-1]:
            node = node.setdefault(key, {})
        default = parameter.default
        node[keys[-1]] = list(default) if isinstance(default, tuple) else default
    return nested


def _flat(mapping: Mapping[str, Any], prefix: str = '') -> dict[str, Any]:
    out: dict[str, Any] = {}
    for key, value in mapping.items():
        name = f'{prefix}{key}'
        if isinstance(value, Mapping):
            out.update(_flat(value, f'{name}.'))
        else:
            out[name] = value
    return out


def _same(a: Any, b: Any) -> bool:
    if isinstance(a, float) and isinstance(b, float) and math.isnan(a) and math.isnan(b):
        return True
    return bool(a == b)


def controller_settings(variant: str, given: Mapping[str, Any]) -> dict[str, Any]:
    """The variant's settings plus the ``given`` ones that differ from the defaults."""
    if variant not in VARIANTS:
        msg = f'unknown variant {variant!r}; choose one of {", ".join(VARIANTS)}'
        raise ValueError(msg)
    settings = dict(VARIANTS[variant][1])
    defaults = _flat(_controller_defaults())
    for name, value in _flat(given).items():
        if name in defaults and not _same(value, defaults[name]):
            settings[name] = tuple(value) if isinstance(value, list) else value
    return settings


def _approach(result: Any, max_speed_m_s: float) -> tuple[float, float]:
    """Medians over the captured targets: first hearing to capture [s], and that over the
    straight drive at full speed from the nearest robot that first heard the target."""
    heard, ranges = result.first_heard_s, result.first_heard_range_m
    captured = result.capture_times_s
    ok = np.isfinite(heard) & np.isfinite(captured) & np.isfinite(ranges)
    if not ok.any():
        return math.nan, math.nan
    took = captured[ok] - heard[ok]
    drive = np.maximum(ranges[ok], 1.0) / max_speed_m_s
    return float(np.median(took)), float(np.median(took / drive))


def run_msc_pf(spec: RunSpec) -> dict[str, Any]:
    """One seeded mission of ``spec.config`` (variant, targets, robots, t_max_s, loss,
    controller); returns the CCT, its breakdown and the capture and hearing series."""
    config = spec.config
    variant = str(config['variant'])
    scheme = VARIANTS[variant][0] if variant in VARIANTS else ''
    settings = controller_settings(variant, config.get('controller', {}))
    controller = MSC_PF_PARAMETERS.build(settings).controller
    t_max = float(config['t_max_s'])
    result = run_batch(
        BatchScenario(
            scheme=Scheme(scheme),
            n_robots=int(config['robots']),
            n_targets=int(config['targets']),
            seed=spec.seed,
            max_time_s=t_max,
            comm_loss=float(config['loss']),
            controller=controller,
        )
    )
    finished = math.isfinite(result.cct_s)
    cct = result.cct_s if finished else t_max
    heard = result.first_heard_s
    last_heard = float(np.max(heard)) if np.isfinite(heard).all() and heard.size else t_max
    approach_s, approach_ratio = _approach(result, controller.max_speed_m_s)
    captures = np.sort(result.capture_times_s[np.isfinite(result.capture_times_s)])
    return {
        'cct_s': float(cct),
        'finished': finished,
        'captured': len(captures),
        'last_heard_s': last_heard,
        'after_heard_s': float(cct - last_heard),
        'mean_capture_s': float(
            np.mean(np.where(np.isfinite(result.capture_times_s), result.capture_times_s, t_max))
        ),
        'approach_s': approach_s,
        'approach_ratio': approach_ratio,
        'capture_times_s': captures.tolist(),
        'first_heard_s': np.sort(heard[np.isfinite(heard)]).tolist(),
    }


# ---------------------------------------------------------------------------------- reports
def _means(rows: Any, metric: str = 'metric.cct_s') -> Any:
    return rows.groupby(['config.targets', 'config.robots', 'config.variant'])[metric].mean()


def _mean_table(page: ReportPage, variants: list[str]) -> Any:
    import pandas as pd

    rows = page.rows
    records = []
    for (targets, robots), group in rows.groupby(['config.targets', 'config.robots']):
        record: dict[str, Any] = {'targets': targets, 'robots': robots}
        for variant in variants:
            mine = group[group['config.variant'] == variant]
            if len(mine):
                cct = mine['metric.cct_s']
                unfinished = int((~mine['metric.finished'].astype(bool)).sum())
                text = f'{cct.mean():.0f} +- {cct.std(ddof=1) if len(cct) > 1 else 0:.0f}'
                text += f' (n={len(cct)}{f", {unfinished} unfinished" if unfinished else ""})'
                record[variant] = text
        records.append(record)
    return pd.DataFrame(records)


def _breakdown_table(page: ReportPage, variants: list[str]) -> Any:
    import pandas as pd

    rows = page.rows
    records = []
    for (targets, robots, variant), group in rows.groupby(
        ['config.targets', 'config.robots', 'config.variant']
    ):
        if variant not in variants:
            continue
        records.append(
            {
                'targets': targets,
                'robots': robots,
                'variant': variant,
                'CCT [s]': group['metric.cct_s'].mean(),
                'last first hearing [s]': group['metric.last_heard_s'].mean(),
                'after it [s]': group['metric.after_heard_s'].mean(),
                'approach median [s]': group['metric.approach_s'].mean(),
                'approach / straight drive': group['metric.approach_ratio'].mean(),
            }
        )
    return pd.DataFrame(records)


def _present(page: ReportPage) -> list[str]:
    found = set(page.rows['config.variant']) if len(page.rows) else set()
    return [v for v in VARIANTS if v in found]


def report_fig4(page: ReportPage) -> None:
    """Fig. 4 beside what the paper publishes, paired differences to MSC by seed."""
    if not len(page.rows):
        return
    variants = _present(page)
    page.add_heading('Fig. 4: capture completion time beside the paper')
    page.add_text(
        'The paper (Sec. IV-B, Fig. 4) prints no CCT values, robot or run counts; it states: '
        + '; '.join(PAPER_FIG4['claims'])
        + '. The table gives the CCT [s], mean +- std over the seeds.'
    )
    page.add_table(_mean_table(page, variants), title='CCT per scheme')
    means = _means(page.rows)
    import pandas as pd

    checks = []
    for (targets, robots), group in means.groupby(level=[0, 1]):
        values = group.droplevel([0, 1])
        if not {'proposed', 'msc_pf', 'msc'} <= set(values.index):
            continue
        checks.append(
            {
                'targets': targets,
                'robots': robots,
                'proposed/msc': values['proposed'] / values['msc'],
                'msc_pf/msc': values['msc_pf'] / values['msc'],
                'MSC largest': values['msc'] >= values[['proposed', 'msc_pf']].max(),
                'proposed smallest': values['proposed'] <= values[['msc', 'msc_pf']].min(),
            }
        )
    if checks:
        page.add_table(pd.DataFrame(checks), title="The paper's order, in the means")
    paired = paired_differences(
        page.rows,
        'metric.cct_s',
        by='config.variant',
        baseline='msc',
        group_by=['config.targets', 'config.robots'],
    )
    page.add_table(
        paired,
        title='CCT minus MSC, paired by seed (wins = the variant is slower; mean_diff < 0 is '
        'faster)',
    )
    page.add_table(_breakdown_table(page, variants), title='Where the CCT goes (means)')


def report_beyond(page: ReportPage) -> None:
    """The paper-faithful row first, then each variant against the best MSC configuration."""
    if not len(page.rows):
        return
    import pandas as pd

    variants = _present(page)
    page.add_table(_mean_table(page, variants), title='CCT per variant')
    rows = page.rows
    records = []
    means = _means(rows)
    for (targets, robots), group in means.groupby(level=[0, 1]):
        values = group.droplevel([0, 1])
        msc = [v for v in MSC_VARIANTS if v in values.index]
        if not msc:
            continue
        best = min(msc, key=lambda v: values[v])
        for variant in [v for v in ('proposed', 'proposed-solo', 'proposed-gather') if v in values]:
            here = rows[(rows['config.targets'] == targets) & (rows['config.robots'] == robots)]
            pair = paired_differences(
                here[here['config.variant'].isin([variant, best])],
                'metric.cct_s',
                by='config.variant',
                baseline=best,
            )
            stats = pair.iloc[0] if len(pair) else None
            records.append(
                {
                    'targets': targets,
                    'robots': robots,
                    'variant': variant,
                    'against': best,
                    'ratio of means': values[variant] / values[best],
                    'vs msc (paper-faithful)': values[variant] / values['msc']
                    if 'msc' in values
                    else math.nan,
                    'pairs': None if stats is None else int(stats['pairs']),
                    'mean diff [s]': None if stats is None else stats['mean_diff'],
                    'se [s]': None if stats is None else stats['se_diff'],
                    'faster in': None if stats is None else int(stats['losses']),
                    'p (Wilcoxon)': None if stats is None else stats['p_wilcoxon'],
                }
            )
    if records:
        page.add_table(
            pd.DataFrame(records),
            title='Against the best MSC configuration (lowest mean CCT of the MSC variants), '
            'paired by seed; goal: ratio <= 0.6',
        )
    page.add_table(_breakdown_table(page, variants), title='Where the CCT goes (means)')


# ---------------------------------------------------------------------------------- studies
def _params(t_max_s: float = 20000.0) -> dict[str, Any]:
    return {'t_max_s': t_max_s, 'loss': 0.0, 'controller': _controller_defaults()}


_SMOKE = Smoke(runs=2, axes={'targets': (2,), 'robots': (6,)}, params={'t_max_s': 3000.0})


def studies() -> list[Study]:
    """The MSC + PF studies (entry point of ``swarm_study``)."""
    return [
        Study(
            name='msc_pf-fig4',
            run=run_msc_pf,
            axes={
                'variant': ('proposed', 'msc_pf', 'msc'),
                'targets': (10, 15, 20),
                'robots': (15,),
            },
            params=_params(),
            runs=40,
            description='MSC + PF paper, Fig. 4: CCT of MSC, MSC+PF and the proposed scheme '
            'at 10/15/20 targets, 15 robots (40 seeds: the paper gives no run count).',
            smoke=_SMOKE,
            report=report_fig4,
        ),
        Study(
            name='msc_pf-baseline-bracket',
            run=run_msc_pf,
            axes={
                'variant': ('msc', 'msc-pbest', 'proposed'),
                'targets': (10, 15, 20),
                'robots': (15,),
            },
            params=_params(),
            runs=40,
            description='Beyond the paper: the MSC baseline as a bracket, gradient leader rule and '
            'a PSO-style pbest rule that finishes, beside the proposed scheme.',
            smoke=_SMOKE,
            report=report_fig4,
        ),
        Study(
            name='msc_pf-gather',
            run=run_msc_pf,
            axes={
                'variant': (
                    'proposed',
                    'msc',
                    'msc-solo',
                    'msc-gather',
                    'proposed-solo',
                    'proposed-gather',
                ),
                'targets': (10, 15, 20),
                'robots': (15,),
            },
            params=_params(),
            runs=40,
            description='Beyond the paper: robots search alone and gather on a '
            'heard target, against the best MSC configuration (MSC given the same searches); '
            'the paper-faithful proposed scheme first.',
            smoke=_SMOKE,
            report=report_beyond,
        ),
        Study(
            name='msc_pf-gather-robots',
            run=run_msc_pf,
            axes={
                'variant': (
                    'proposed',
                    'msc',
                    'msc-solo',
                    'msc-gather',
                    'proposed-solo',
                    'proposed-gather',
                ),
                'targets': (10,),
                'robots': (9, 30),
            },
            params=_params(),
            runs=40,
            description='The search beyond the paper with 9 and 30 robots, 10 targets.',
            smoke=_SMOKE,
            report=report_beyond,
        ),
    ]
