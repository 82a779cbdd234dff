"""The MSC + PF studies of ``swarm_study``: the paper's Fig. 4 and the schemes beyond it.

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

Every configuration is checked before anything runs (:func:`check_config`): ``variant`` one
of :data:`VARIANTS`, ``robots`` and ``targets`` >= 1, ``t_max_s`` > 0, ``loss`` a
probability, as the spawner checks them (``swarm_msc_pf``), and the controller settings as
the node checks its parameters.
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
from swarm_experiments.study.checks import (
    check_choice,
    check_number,
    check_whole,
    settings_error,
)
from swarm_experiments.study.errors import UsageError

__all__ = [
    'BEYOND_VARIANTS',
    'PAPER_FIG4',
    'VARIANTS',
    'best_msc',
    'check_config',
    'run_msc_pf',
    'studies',
]

# The robots' own settings (ID, seed, steering) and those the variant decides stay out.
_NOT_STUDY_PARAMETERS = ('scheme', 'robot_id', 'seed')

#: The PSO-style personal-best leader rule set up to finish: straight legs ended at their
#: best point (``msc.leader_rule=pbest_turn``). The specification's pbest rule, the best of
#: the last 10 positions, dithers in the noise and captures nothing (docs/msc_pf.md).
PBEST_FINISHING = {'msc.leader_rule': 'pbest_turn'}

#: The search beyond the paper for MSC: robots search alone (no swarms until a target is
#: heard) and split the field into sectors, each robot sweeping its own (``search.mode``).
SWEEP = {'swarm.search_alone': True, 'search.mode': 'sector'}

#: The scheme beyond the paper (``proposed-sweep``): the proposed scheme with the sector
#: sweep, and an approach driven by the particle filters, which MSC has not got: a new filter
#: starts on the unsearched side of its ring of distances, folds in the steps the target was
#: not heard (the full observation model, so no censoring correction), is followed through
#: signal gaps at its mean and, near the target, with eq. (8); a robot leaves a target to a
#: louder pursuer and to the robot whose sector holds its estimate, and drops estimates that
#: are silent at 200 m or 600 s stale.
PF_SWEEP = {
    **SWEEP,
    'search.coverage_prior_weight': 0.05,
    'search.sector_reach': 0,
    'particle_filter.censored_likelihood': False,
    'phases.non_detection_window_s': 120.0,
    'phases.pursue_memory_s': 30.0,
    'phases.far_aim': 'estimate',
    'phases.near_estimate_spread_m': 15.0,
    'phases.max_pursuers': 1,
    'phases.converged_give_up_m': 200.0,
    'phases.converged_max_age_s': 600.0,
}

#: variant -> (scheme, controller settings on top of the defaults).
VARIANTS: dict[str, tuple[str, dict[str, Any]]] = {
    'proposed': ('proposed', {}),
    'msc_pf': ('msc_pf', {}),
    'msc': ('msc', {}),
    'msc-pbest': ('msc', dict(PBEST_FINISHING)),
    'msc-solo': ('msc', {'swarm.max_size': 1}),
    'msc-gather': ('msc', {'swarm.search_alone': True}),
    'msc-sweep': ('msc', dict(SWEEP)),
    'msc-sweep-pbest': ('msc', {**SWEEP, **PBEST_FINISHING}),
    'msc-sweep-swarm': ('msc', {'search.mode': 'sector'}),
    'msc-sweep-one': ('msc', {**SWEEP, 'phases.max_pursuers': 1}),
    'proposed-solo': ('proposed', {'swarm.max_size': 1}),
    'proposed-gather': ('proposed', {'swarm.search_alone': True}),
    'proposed-sweep': ('proposed', dict(PF_SWEEP)),
}

MSC_VARIANTS = tuple(v for v, (scheme, _) in VARIANTS.items() if scheme == 'msc')

#: The variants of the beyond-the-paper studies (others run with ``--set variant=...``).
BEYOND_VARIANTS = (
    'proposed',
    'msc',
    'msc-pbest',
    'msc-gather',
    'msc-sweep',
    'msc-sweep-pbest',
    'proposed-sweep',
)

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


def _controller(config: Mapping[str, Any]) -> Any:
    """The controller configuration of a run (the variant's settings, then ``controller``)."""
    settings = controller_settings(str(config['variant']), config.get('controller', {}))
    return MSC_PF_PARAMETERS.build(settings).controller


def check_config(config: Mapping[str, Any]) -> None:
    """Check one configuration as the spawner and the node check theirs (nothing runs).

    Raises:
        UsageError: an unknown variant, a count or time out of range, a loss that is not a
            probability, a controller setting the node rejects (named ``controller.<name>``).
    """
    from swarm_common.errors import SwarmError

    from swarm_experiments.spawn_msc_pf import MAX_ROBOTS, SpawnSettings, check_settings

    check_choice(config, 'variant', VARIANTS)
    check_whole(config, 'robots', minimum=1)
    check_whole(config, 'targets', minimum=1)
    check_number(config, 't_max_s', minimum=0.0, above=True)
    check_number(config, 'loss', minimum=0.0, maximum=1.0)
    try:
        _controller(config)
    except (SwarmError, ValueError, TypeError) as err:
        text = ' '.join(str(err).split())
        if text.startswith('parameter '):
            text = 'controller.' + text.removeprefix('parameter ')
        raise UsageError(text) from err
    try:
        # The spawner's own check (it runs at most MAX_ROBOTS nodes; the batch path more).
        check_settings(
            SpawnSettings(
                scheme=VARIANTS[str(config['variant'])][0],
                robots=min(int(config['robots']), MAX_ROBOTS),
                targets=int(config['targets']),
                max_time_s=float(config['t_max_s']),
                loss_probability=float(config['loss']),
            )
        )
    except SwarmError as err:
        raise settings_error(err) from err


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
    check_config(config)
    scheme = VARIANTS[str(config['variant'])][0]
    controller = _controller(config)
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


def _fig4_claim_tables(page: ReportPage) -> Any:
    """The paper's claims on the means: per target count the order of the three schemes, and
    per scheme whether the CCT rises with the target count."""
    import pandas as pd

    means = _means(page.rows)
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
    rising = []
    for (robots, variant), group in means.groupby(level=[1, 2]):
        if len(group) < 2:
            continue
        by_targets = group.droplevel([1, 2]).sort_index()
        rising.append(
            {
                'robots': robots,
                'variant': variant,
                'targets': ', '.join(str(t) for t in by_targets.index),
                'CCT means [s]': ', '.join(f'{v:.0f}' for v in by_targets.values),
                'rises with targets': bool((by_targets.diff().dropna() > 0).all()),
            }
        )
    return pd.DataFrame(checks), pd.DataFrame(rising)


def _fig4_figure(page: ReportPage, variants: list[str], t_max_s: float) -> None:
    """Mean CCT per scheme and target count as grouped bars (the paper's Fig. 4), with the
    standard error; a run that captured not every target counts as T_max."""
    from matplotlib.figure import Figure

    rows = page.rows
    figure = Figure(figsize=(6.4, 3.8))
    ax = figure.subplots()
    targets = sorted(rows['config.targets'].unique())
    width = 0.8 / max(len(variants), 1)
    for k, variant in enumerate(variants):
        mine = rows[rows['config.variant'] == variant]
        stats = mine.groupby('config.targets')['metric.cct_s'].agg(['mean', 'sem', 'count'])
        stats = stats.reindex(targets)
        x = [i + (k - (len(variants) - 1) / 2) * width for i in range(len(targets))]
        ax.bar(x, stats['mean'], width, yerr=stats['sem'].fillna(0.0), capsize=3, label=variant)
    ax.axhline(t_max_s, color='grey', lw=0.8, ls='--', label='T_max')
    ax.set_xticks(range(len(targets)), [str(t) for t in targets])
    ax.set_xlabel('targets')
    ax.set_ylabel('CCT [s] (mean ± s.e.; unfinished = T_max)')
    ax.grid(axis='y', alpha=0.3)
    ax.legend(fontsize='small')
    robots = ', '.join(str(r) for r in sorted(rows['config.robots'].unique()))
    figure.suptitle(f'MSC + PF Fig. 4: capture completion time, {robots} robots', fontsize='small')
    page.add_figure(figure, 'fig4-cct', caption='CCT per scheme and target count (as Fig. 4)')


def report_fig4(page: ReportPage) -> None:
    """Fig. 4 beside what the paper publishes, paired differences to MSC by seed."""
    if not len(page.rows):
        return
    variants = _present(page)
    page.add_heading('Fig. 4: capture completion time beside the paper')
    page.add_text(
        'The paper (Sec. IV-B, Fig. 4) prints no CCT values, robot or run counts; it states: '
        + '; '.join(PAPER_FIG4['claims'])
        + '. The table gives the CCT [s], mean +- std over the seeds; a run that captured not '
        'every target by T_max counts as T_max (the mean is then a lower bound).'
    )
    page.add_table(_mean_table(page, variants), title='CCT per scheme', export='cct')
    order, rising = _fig4_claim_tables(page)
    if len(order):
        page.add_table(order, title="The paper's order, in the means", export='order')
    if len(rising):
        page.add_table(rising, title='CCT against the number of targets', export='rising')
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
        export='paired',
    )
    page.add_table(
        _breakdown_table(page, variants), title='Where the CCT goes (means)', export='breakdown'
    )
    _fig4_figure(page, variants, float(page.rows['param.t_max_s'].max()))


def _bracket_table(rows: Any) -> Any:
    """MSC with the gradient and with the pbest_turn leader rule (paper search), paired."""
    import pandas as pd

    records = []
    for (targets, robots), group in rows.groupby(['config.targets', 'config.robots']):
        pair = group[group['config.variant'].isin(['msc', 'msc-pbest'])]
        if set(pair['config.variant']) != {'msc', 'msc-pbest'}:
            continue
        stats = paired_differences(pair, 'metric.cct_s', by='config.variant', baseline='msc').iloc[
            0
        ]
        common = _common_seeds(pair, ['msc', 'msc-pbest'])
        mean = _seed_means(pair, common)
        records.append(
            {
                'targets': targets,
                'robots': robots,
                'pairs': int(stats['pairs']),
                'msc (gradient) [s]': mean['msc'],
                'msc-pbest (pbest_turn) [s]': mean['msc-pbest'],
                'pbest_turn / gradient': mean['msc-pbest'] / mean['msc'],
                'mean diff [s]': stats['mean_diff'],
                'se [s]': stats['se_diff'],
                'pbest_turn faster in': int(stats['losses']),
            }
        )
    return pd.DataFrame(records)


def _common_seeds(group: Any, variants: list[str]) -> list[int]:
    """Seeds that every one of ``variants`` ran in ``group``."""
    seeds: set[int] | None = None
    for variant in variants:
        mine = set(group.loc[group['config.variant'] == variant, 'seed'].astype(int))
        seeds = mine if seeds is None else seeds & mine
    return sorted(seeds or ())


def _seed_means(group: Any, seeds: list[int]) -> Any:
    """Mean CCT per variant over ``seeds``."""
    chosen = group[group['seed'].astype(int).isin(seeds)]
    return chosen.groupby('config.variant')['metric.cct_s'].mean()


def best_msc(group: Any) -> tuple[str | None, list[int], Any]:
    """The MSC configuration with the lowest mean CCT over the seeds every MSC variant ran.

    Returns the variant (None without MSC rows), those common seeds and the means there.
    """
    present = [v for v in MSC_VARIANTS if v in set(group['config.variant'])]
    if not present:
        return None, [], None
    seeds = _common_seeds(group, present)
    if not seeds:
        return None, [], None
    means = _seed_means(group, seeds)
    return str(min(present, key=lambda v: means[v])), seeds, means


#: Row order of the comparison with the best MSC: the paper-faithful scheme leads.
_COMPARED = ('proposed', 'proposed-sweep', 'proposed-gather', 'proposed-solo')


def _screen_table(rows: Any) -> Any:
    import pandas as pd

    records = []
    for (targets, robots), group in rows.groupby(['config.targets', 'config.robots']):
        best, seeds, means = best_msc(group)
        if best is None:
            continue
        for variant in [v for v in MSC_VARIANTS if v in means.index]:
            records.append(
                {
                    'targets': targets,
                    'robots': robots,
                    'MSC variant': variant,
                    'seeds': len(seeds),
                    'mean CCT [s]': means[variant],
                    'best': variant == best,
                }
            )
    return pd.DataFrame(records)


def _beyond_table(rows: Any) -> Any:
    import pandas as pd

    records = []
    for (targets, robots), group in rows.groupby(['config.targets', 'config.robots']):
        best, _, _ = best_msc(group)
        if best is None:
            continue
        for variant in [v for v in _COMPARED if v in set(group['config.variant'])]:
            pair = group[group['config.variant'].isin([variant, best])]
            seeds = _common_seeds(pair, [variant, best])
            if not seeds:
                continue
            mean = _seed_means(pair, seeds)
            stats = paired_differences(
                pair, 'metric.cct_s', by='config.variant', baseline=best
            ).iloc[0]
            paper = group[group['config.variant'].isin([variant, 'msc'])]
            paper_seeds = _common_seeds(paper, [variant, 'msc'])
            paper_mean = _seed_means(paper, paper_seeds) if paper_seeds else None
            records.append(
                {
                    'targets': targets,
                    'robots': robots,
                    'variant': variant,
                    'best MSC': best,
                    'pairs': len(seeds),
                    'CCT [s]': mean[variant],
                    'best MSC CCT [s]': mean[best],
                    'ratio of means': mean[variant] / mean[best],
                    'vs msc (paper)': (
                        paper_mean[variant] / paper_mean['msc']
                        if paper_mean is not None
                        else math.nan
                    ),
                    'mean diff [s]': stats['mean_diff'],
                    'se [s]': stats['se_diff'],
                    'faster in': int(stats['losses']),
                    'p (Wilcoxon)': stats['p_wilcoxon'],
                }
            )
    return pd.DataFrame(records)


def report_beyond(page: ReportPage) -> None:
    """The MSC bracket, every variant's CCT, the MSC screening and the comparison with the
    best MSC configuration (the paper-faithful scheme first), and where the CCT goes."""
    if not len(page.rows):
        return
    variants = _present(page)
    rows = page.rows
    bracket = _bracket_table(rows)
    if len(bracket):
        page.add_table(
            bracket,
            title='The MSC baseline as a bracket: gradient and pbest_turn leader rules '
            "(the paper's swarm search), paired by seed",
            export='bracket',
        )
    page.add_table(_mean_table(page, variants), title='CCT per variant', export='cct')
    screen = _screen_table(rows)
    if len(screen):
        page.add_table(
            screen,
            title='MSC configurations on the seeds all of them ran; the best one is the '
            'baseline below',
            export='msc-screen',
        )
    beyond = _beyond_table(rows)
    if len(beyond):
        page.add_table(
            beyond,
            title='Against the best MSC configuration, paired by seed (the paper-faithful '
            'scheme first); goal: ratio of means <= 0.6',
            export='beyond',
        )
    page.add_table(
        _breakdown_table(page, variants), title='Where the CCT goes (means)', export='breakdown'
    )


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
            check=check_config,
        ),
        Study(
            name='msc_pf-beyond',
            run=run_msc_pf,
            axes={
                'variant': BEYOND_VARIANTS,
                'targets': (10, 15, 20),
                'robots': (15,),
            },
            params=_params(),
            runs=40,
            description='Beyond the paper: the MSC bracket (gradient, pbest_turn), MSC given '
            'every search setting, and the sector sweep with the PF-driven approach '
            '(proposed-sweep) against the best MSC; the paper-faithful proposed scheme first.',
            smoke=_SMOKE,
            report=report_beyond,
            check=check_config,
        ),
        Study(
            name='msc_pf-beyond-robots',
            run=run_msc_pf,
            axes={
                'variant': BEYOND_VARIANTS,
                'targets': (10,),
                'robots': (9, 30),
            },
            params=_params(),
            runs=40,
            description='The comparison beyond the paper with 9 and 30 robots, 10 targets.',
            smoke=_SMOKE,
            report=report_beyond,
            check=check_config,
        ),
    ]
