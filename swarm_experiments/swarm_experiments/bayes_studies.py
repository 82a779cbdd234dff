"""The Bayes-Swarm-P paper's studies for ``swarm_study`` (Tables 1-8 and Fig. 4).

Every run is one seeded batch mission (:func:`swarm_experiments.bayes_batch.run_mission`,
the nodes' own controller in the paper's event model). A run's parameters are the axes and
fixed parameters of its study; :func:`run_bayes` understands these names:

* ``case`` (case1, case2, case3, avalanche), ``algorithm``, ``robots`` (0: the paper's swarm
  size of the case), ``profile`` (:data:`bayes_swarm.profiles.PROFILES`);
* ``solvers``: 'OUTER/INNER' (e.g. 'cobyla/lbfgsb', 'pso/lbfgsb', 'grid/newton');
* ``variant``: 'p' (Bayes-Swarm-P), 'o' (Bayes-Swarm-O), 'alpha1' (P with alpha = 1);
* ``source``: 'paper' (the paper's field) or 'random' (field and source moved so that the
  source lies uniformly in the inner 80 % of the arena, drawn from the seed);
* ``comm_level``: 0 unlimited, 1-3 the paper's ranges of the case, longest first;
* ``noise_std`` (absolute), ``noise_fraction`` (std as a fraction of |f|, Table 7),
  ``alpha_t_max_s`` (the T_max of the alpha schedule only, Table 7), ``t_max_s`` (mission
  T_max, 0: the case's), ``baseline_t_max_factor`` (T_max factor for Levy walk and the
  exhaustive sweep, which rarely finish within the paper's T_max),
  ``glowworm_t_max_factor`` (T_max factor for Glowworm: the paper's avalanche Glowworm
  under noise took 583 s against a T_max of 100 s), ``depth_m`` (avalanche
  burial depth, 0: the default), ``seed_offset`` (added to the run's seed, e.g. 101 for the
  held-out seeds 101-...);
* any other name of a :class:`bayes_swarm.settings.BayesSwarmConfig` field is a planner
  option.

Metrics per run: ``found``, ``tau`` (NaN when not found), ``tau_censored`` (tau, or the tau
of the mission time limit when not found, so that failures pair), ``found_time_s``,
``decisions``, and the finder's median decision time (wall and CPU, ms).

The reports put our tau beside the paper's published figures (:data:`PAPER`) and pair
configurations on seeds (Wilcoxon signed rank on ``tau_censored``).
"""

from __future__ import annotations

import dataclasses
import math
import time
from collections.abc import Mapping
from dataclasses import replace
from typing import Any

import numpy as np
from bayes_swarm.messages import DecisionKind
from bayes_swarm.settings import BayesSwarmConfig
from swarm_sim.signal_fields import SignalCase, avalanche_case, get_case

from swarm_experiments.bayes_batch import run_mission
from swarm_experiments.spawn_bayes_swarm import (
    MAX_ROBOTS,
    SpawnSettings,
    batch_mission_spec,
    check_settings,
)
from swarm_experiments.study import ReportPage, RunSpec, Smoke, Study
from swarm_experiments.study.checks import (
    check_choice,
    check_number,
    check_whole,
    settings_error,
)
from swarm_experiments.study.errors import UsageError
from swarm_experiments.study.report import paired_differences, reference_table

__all__ = ['COMM_RANGES_M', 'PAPER', 'PAPER_ROBOTS', 'check_config', 'run_bayes', 'studies']

PAPER_ROBOTS = {'case1': 5, 'case2': 10, 'case3': 48, 'avalanche': 6}
#: comm_level 1-3 of each case (Table 6), longest first.
COMM_RANGES_M = {'case1': (1.0, 0.5, 0.1), 'case2': (20.0, 10.0, 5.0)}
_PLANNER_FIELDS = {f.name for f in dataclasses.fields(BayesSwarmConfig)}
_RUN_KEYS = {
    'case',
    'algorithm',
    'robots',
    'profile',
    'solvers',
    'variant',
    'source',
    'comm_level',
    'noise_std',
    'noise_fraction',
    'alpha_t_max_s',
    't_max_s',
    'baseline_t_max_factor',
    'glowworm_t_max_factor',
    'depth_m',
    'seed_offset',
}

#: The paper's published tau (mean, std) per study and configuration key.
PAPER: dict[str, dict[Any, tuple[float, float]]] = {
    # Table 3 (PSO solvers for Bayes-Swarm-P; Levy walk: 5 best of 9-13 runs).
    'table3': {
        ('case1', 'bayes_swarm_p'): (0.34, 0.02),
        ('case1', 'glowworm'): (1.92, 0.75),
        ('case1', 'levy'): (10.44, 9.39),
        ('case1', 'exhaustive'): (11.16, 0.0),
        ('case2', 'bayes_swarm_p'): (0.39, 0.0),
        ('case2', 'glowworm'): (1.47, 0.18),
        ('case2', 'levy'): (9.16, 11.90),
        ('case2', 'exhaustive'): (42.14, 0.0),
    },
    # Table 4 (COBYLA / L-BFGS-B).
    'table4': {48: (5.18, 0.10), 100: (4.93, 0.11)},
    # Table 5 (PSO solvers, 5 runs).
    'table5': {
        ('case1', 'p'): (0.34, 0.02),
        ('case1', 'o'): (0.35, 0.06),
        ('case2', 'p'): (0.39, 0.0),
        ('case2', 'o'): (0.75, 0.42),
    },
    # Table 6 (COBYLA / L-BFGS-B, 55 runs).
    'table6': {
        ('case1', 0): (0.44, 0.10),
        ('case1', 1): (0.05, 0.01),
        ('case1', 2): (0.05, 0.01),
        ('case1', 3): (0.05, 0.01),
        ('case2', 0): (0.89, 0.45),
        ('case2', 1): (0.96, 0.70),
        ('case2', 2): (1.26, 0.49),
        ('case2', 3): (1.34, 0.78),
    },
    # Table 7 (COBYLA / L-BFGS-B, 55 runs): (case, noise fraction, alpha T_max).
    'table7': {
        ('case1', 0.0, 100.0): (0.44, 0.10),
        ('case1', 0.0, 1000.0): (0.52, 0.13),
        ('case1', 0.02, 100.0): (0.51, 0.35),
        ('case1', 0.02, 1000.0): (0.84, 0.48),
        ('case1', 0.05, 100.0): (1.07, 0.55),
        ('case1', 0.05, 1000.0): (1.35, 0.70),
        ('case1', 0.1, 100.0): (1.22, 0.71),
        ('case1', 0.1, 1000.0): (1.64, 0.79),
        ('case2', 0.0, 100.0): (0.83, 0.49),
        ('case2', 0.0, 1000.0): (0.89, 0.45),
        ('case2', 0.02, 100.0): (0.97, 0.42),
        ('case2', 0.02, 1000.0): (0.83, 0.44),
        ('case2', 0.05, 100.0): (1.58, 0.71),
        ('case2', 0.05, 1000.0): (1.54, 0.81),
        ('case2', 0.1, 100.0): (2.58, 2.13),
        ('case2', 0.1, 1000.0): (2.76, 2.15),
    },
    # Table 8 (COBYLA / L-BFGS-B, 5 runs): (method, noise std).
    'table8': {
        ('bayes_swarm_p', 0.0): (0.19, 0.09),
        ('alpha1', 0.0): (0.12, 0.03),
        ('glowworm', 0.0): (0.62, 0.1),
        ('levy', 0.0): (33.06, 19.99),
        ('exhaustive', 0.0): (14.09, 0.0),
        ('bayes_swarm_p', 0.47): (0.66, 0.47),
        ('glowworm', 0.47): (9.30, 0.86),
    },
}


# ------------------------------------------------------------------------------ runs
def _case(config: Mapping[str, Any]) -> SignalCase:
    name = str(config.get('case', 'case1'))
    depth = float(config.get('depth_m', 0.0) or 0.0)
    return avalanche_case(depth) if name == 'avalanche' and depth > 0.0 else get_case(name)


def _random_source_offset(case: SignalCase, seed: int) -> np.ndarray:
    """Offset that puts the source uniformly in the inner 80 % of the arena (seeded)."""
    x0, x1, y0, y1 = case.arena_m
    rng = np.random.default_rng(np.random.SeedSequence([seed, 0x5EED]))
    margin_x, margin_y = 0.1 * (x1 - x0), 0.1 * (y1 - y0)
    target = np.array(
        [rng.uniform(x0 + margin_x, x1 - margin_x), rng.uniform(y0 + margin_y, y1 - margin_y)]
    )
    return target - np.asarray(case.source_m, dtype=float)


@dataclasses.dataclass(frozen=True)
class _Mission:
    """What :func:`run_bayes` runs: the batch mission spec and how."""

    spec: Any
    algorithm: str
    robots: int
    seed: int
    case: SignalCase
    t_max_s: float
    comm_range_m: float | None


def _mission(config: Mapping[str, Any], run_seed: int) -> _Mission:
    """The mission of one run of ``config`` with the study seed ``run_seed``."""
    config = dict(config)
    seed = run_seed + int(config.get('seed_offset', 0) or 0)
    case = _case(config)
    name = str(config.get('case', 'case1'))
    algorithm = str(config.get('algorithm', 'bayes_swarm_p'))
    variant = str(config.get('variant', 'p'))
    planner: dict[str, Any] = {k: v for k, v in config.items() if k in _PLANNER_FIELDS}
    unknown = sorted(set(config) - _PLANNER_FIELDS - _RUN_KEYS)
    if unknown:
        msg = f'unknown Bayes-Swarm study parameters: {", ".join(unknown)}'
        raise ValueError(msg)
    if algorithm == 'alpha1':
        algorithm, variant = 'bayes_swarm_p', 'alpha1'
    if variant == 'o':
        algorithm = 'bayes_swarm_o' if algorithm == 'bayes_swarm_p' else algorithm
    elif variant == 'alpha1':
        planner['fixed_alpha'] = 1.0
    if config.get('solvers'):
        outer, inner = str(config['solvers']).split('/')
        planner.update(outer_optimizer=outer, inner_optimizer=inner)
    if config.get('alpha_t_max_s'):
        planner['alpha_time_scale'] = float(config['alpha_t_max_s']) / case.max_mission_time_s
    t_max = float(config.get('t_max_s', 0.0) or 0.0) or case.max_mission_time_s
    factor = float(config.get('baseline_t_max_factor', 1.0) or 1.0)
    if algorithm in ('levy', 'exhaustive'):
        t_max *= factor
    elif algorithm == 'glowworm':
        t_max *= float(config.get('glowworm_t_max_factor', 1.0) or 1.0)
    case = replace(case, max_mission_time_s=t_max)
    if config.get('source', 'paper') == 'random':
        case = case.with_source_moved(_random_source_offset(case, seed))
    level = int(config.get('comm_level', 0) or 0)
    comm = COMM_RANGES_M[name][level - 1] if level > 0 else None
    noise = float(config.get('noise_std', 0.0) or 0.0)
    mission = batch_mission_spec(
        case,
        noise_std=noise,
        comm_range_m=comm,
        partition='quadrants' if algorithm == 'exhaustive' else 'strips',
        planner_options=planner,
        profile=str(config.get('profile', 'paper')),
    )
    fraction = float(config.get('noise_fraction', 0.0) or 0.0)
    if fraction > 0.0:
        gp = replace(mission.planner.gp, noise_std=max(mission.planner.gp.noise_std, fraction))
        mission = replace(mission, relative_noise=fraction, planner=replace(mission.planner, gp=gp))
    robots = int(config.get('robots', 0) or 0) or PAPER_ROBOTS[name]
    return _Mission(mission, algorithm, robots, seed, case, t_max, comm)


_CASES = tuple(PAPER_ROBOTS)
_VARIANTS = ('p', 'o', 'alpha1')
_SOURCES = ('paper', 'random')


def check_config(config: Mapping[str, Any]) -> None:
    """Check one configuration before anything runs: the study's own names, then the mission
    built as :func:`run_bayes` builds it, with the checks of the spawner (``swarm_bayes_swarm``)
    and of the planner settings (:class:`~bayes_swarm.settings.BayesSwarmConfig`).

    Raises:
        UsageError: an unknown name or choice, a value out of range, a planner setting the
            settings reject (one line naming the parameter, the value and the rule).
    """
    from bayes_swarm.profiles import PROFILES
    from bayes_swarm.settings import INNER_OPTIMIZERS, OUTER_OPTIMIZERS
    from swarm_common.errors import SwarmError

    from swarm_experiments.bayes_batch import ALGORITHMS

    unknown = sorted(set(config) - _PLANNER_FIELDS - _RUN_KEYS)
    if unknown:
        raise UsageError(f'unknown Bayes-Swarm study parameters: {", ".join(unknown)}')
    present = {name: config[name] for name in _RUN_KEYS if name in config}
    if 'case' in present:
        check_choice(present, 'case', _CASES)
    if 'algorithm' in present:
        check_choice(present, 'algorithm', (*ALGORITHMS, 'alpha1'))
    if 'variant' in present:
        check_choice(present, 'variant', _VARIANTS)
    if 'source' in present:
        check_choice(present, 'source', _SOURCES)
    if 'profile' in present:
        check_choice(present, 'profile', tuple(PROFILES))
    if present.get('solvers') is not None:
        solvers = present['solvers']
        if not isinstance(solvers, str) or solvers.count('/') != 1:
            raise UsageError(f"solvers={solvers!r}: must be 'OUTER/INNER' (e.g. cobyla/lbfgsb)")
        outer, inner = solvers.split('/')
        for part, choices in ((outer, OUTER_OPTIMIZERS), (inner, INNER_OPTIMIZERS)):
            if part not in choices:
                raise UsageError(
                    f'solvers={solvers!r}: {part!r} is not one of {", ".join(choices)}'
                )
    for name in ('robots', 'seed_offset'):
        if name in present:
            check_whole(present, name, minimum=0, allow_none=True)
    if 'comm_level' in present:
        levels = COMM_RANGES_M.get(str(config.get('case', 'case1')), ())
        check_whole(present, 'comm_level', minimum=0, maximum=len(levels), allow_none=True)
    for name in ('noise_std', 'noise_fraction', 'alpha_t_max_s', 't_max_s', 'depth_m'):
        if name in present:
            check_number(present, name, minimum=0.0, allow_none=True)
    for name in ('baseline_t_max_factor', 'glowworm_t_max_factor'):
        if name in present:
            check_number(present, name, minimum=0.0, above=True, allow_none=True)
    try:
        mission = _mission(config, 0)
        if mission.algorithm not in ALGORITHMS:
            msg = f'algorithm {mission.algorithm!r}: choose one of {", ".join(ALGORITHMS)}'
            raise UsageError(msg)
        # The spawner's checks of the same mission (it runs at most MAX_ROBOTS nodes).
        check_settings(
            SpawnSettings(
                algorithm=mission.algorithm,
                case=str(config.get('case', 'case1')),
                robots=min(mission.robots, MAX_ROBOTS),
                comm_range_m=math.inf if mission.comm_range_m is None else mission.comm_range_m,
                noise_std=float(config.get('noise_std', 0.0) or 0.0),
                relative_noise=float(config.get('noise_fraction', 0.0) or 0.0),
                max_mission_time_s=mission.t_max_s,
                profile=str(config.get('profile', 'paper')),
            )
        )
    except UsageError:
        raise
    except (SwarmError, ValueError, TypeError, KeyError) as err:
        raise settings_error(err) from err


def run_bayes(spec: RunSpec) -> dict[str, Any]:
    """One seeded mission of a Bayes-Swarm study (parameter names: module docstring)."""
    check_config(spec.config)
    planned = _mission(spec.config, spec.seed)
    case, t_max, comm = planned.case, planned.t_max_s, planned.comm_range_m
    start = time.process_time()
    result = run_mission(planned.spec, planned.algorithm, planned.robots, planned.seed)
    cpu = time.process_time() - start
    ideal_s = float(np.hypot(*(case.source_m - case.depots_m[0]))) / case.velocity_mps
    decisions = result.decisions[result.finder] if result.found else []
    timed = [d for d in decisions if d.kind is not DecisionKind.FIRST]
    return {
        'found': bool(result.found),
        'tau': float(result.tau),
        'tau_censored': float(result.tau) if result.found else (t_max - ideal_s) / ideal_s,
        'found_time_s': float(result.found_time_s),
        'finder': int(result.finder),
        'decisions': int(sum(len(d) for d in result.decisions)),
        'finder_decision_ms': _median_ms([d.compute_time_s for d in decisions]),
        'finder_decision_cpu_ms': _median_ms([d.cpu_time_s for d in decisions]),
        'finder_gp_decision_cpu_ms': _median_ms([d.cpu_time_s for d in timed]),
        'comm_range_m': math.inf if comm is None else comm,
        'source_x_m': float(case.source_m[0]),
        'source_y_m': float(case.source_m[1]),
        'mission_cpu_s': cpu,
    }


def _median_ms(values: list[float]) -> float:
    return 1e3 * float(np.median(values)) if values else math.nan


# ---------------------------------------------------------------------------- reports
_VARIED = ('param.profile', 'param.seed_offset', 'config.source')


def _with_varied(rows: Any, by: list[str]) -> list[str]:
    """``by`` plus the fixed parameters that differ between the stored runs (``--set``)."""
    extra = [
        c
        for c in _VARIED
        if c not in by and c in rows.columns and rows[c].nunique(dropna=False) > 1
    ]
    return [*extra, *by]


def _paper_first(frame: Any) -> Any:
    """``frame`` with the rows of the ``paper`` profile first (the as-published setting leads
    every table), the other profiles after it in name order; other rows keep their order."""
    column = next((c for c in ('param.profile', 'profile') if c in frame.columns), None)
    if column is None or frame.empty:
        return frame
    rank = frame[column].map(lambda name: (name != 'paper', str(name)))
    order = sorted(range(len(frame)), key=lambda i: rank.iloc[i])
    return frame.iloc[order].reset_index(drop=True)


def _mean_std(rows: Any, by: list[str]) -> Any:
    import pandas as pd

    by = _with_varied(rows, by)
    rows = _paper_first(rows)
    found = rows[rows['metric.found'].astype(bool)]
    table = (
        rows.groupby(by, sort=False)
        .agg(runs=('seed', 'size'), found=('metric.found', 'sum'))
        .reset_index()
    )
    stats = (
        found.groupby(by, sort=False)['metric.tau'].agg(['mean', 'std']).reset_index()
        if len(found)
        else pd.DataFrame(columns=[*by, 'mean', 'std'])
    )
    return table.merge(stats, on=by, how='left')


def _reference_section(page: ReportPage, key: str, by: list[str]) -> None:
    rows = page.rows
    if rows.empty:
        return
    # Beside the paper's figures: the paper profile on the paper's fields, where stored
    # rows hold several profiles or source placements.
    for column in ('param.profile', 'config.source'):
        if column in rows and rows[column].nunique() > 1:
            rows = rows[rows[column] == 'paper']
    found = rows[rows['metric.found'].astype(bool)]
    reference = {k: v[0] for k, v in PAPER[key].items()}
    if len(by) == 1:
        reference = {k[0] if isinstance(k, tuple) else k: v for k, v in reference.items()}
    table = reference_table(found, 'metric.tau', reference, by=by)
    table['paper std'] = [
        PAPER[key].get(tuple(r) if len(by) > 1 else r[0], (math.nan, math.nan))[1]
        for r in table[by].itertuples(index=False)
    ]
    page.add_table(
        _mean_std(page.rows, by),
        title='tau over the successful runs, and how many succeeded',
        export='tau',
    )
    page.add_table(
        table,
        title="tau beside the paper's published figures (paper profile, successful runs)",
        export='paper',
    )


def _paired_section(
    page: ReportPage, by: str, baseline: Any, group_by: list[str], title: str
) -> None:
    rows = page.rows
    if rows.empty or by not in rows.columns or rows[by].nunique() < 2:
        return
    table = paired_differences(
        rows,
        'metric.tau_censored',
        by=by,
        baseline=baseline,
        group_by=_with_varied(rows, group_by),
    )
    table = _paper_first(table)
    page.add_table(table, title=title, export='paired')
    page.add_text(
        'Paired on the seed (the same scenario); tau_censored counts a failed run at the tau '
        'of the mission time limit. mean_diff < 0: the compared configuration is faster.'
    )


def _report_optimizers(page: ReportPage) -> None:
    _reference_section_authors(page)
    _paired_section(
        page,
        'config.solvers',
        'cobyla/lbfgsb',
        ['config.case', 'config.source'],
        "Solvers against the paper's COBYLA / L-BFGS-B, paired by seed",
    )


def _reference_section_authors(page: ReportPage) -> None:
    rows = page.rows
    if rows.empty:
        return
    page.add_table(
        _mean_std(rows, ['config.case', 'config.source', 'config.solvers']),
        title='tau per case, source placement and solvers',
        export='tau',
    )
    page.add_text(
        'Paper, COBYLA / L-BFGS-B (Tables 6 and 7, 55 runs): Case 1 0.44 +- 0.10, Case 2 '
        '0.89 +- 0.45 (Table 7: 0.83 +- 0.49); PSO (Table 3): 0.34 +- 0.02 and 0.39 +- 0.00. '
        "The authors' released code, COBYLA / L-BFGS-B, measured on the same machine: "
        'Case 1 0.45 +- 0.14 (30 runs), Case 2 0.92 +- 0.50 (20 runs).'
    )


def _report_baselines(page: ReportPage) -> None:
    _reference_section(page, 'table3', ['config.case', 'config.algorithm'])
    _paired_section(
        page,
        'config.algorithm',
        'bayes_swarm_p',
        ['config.case'],
        'Baselines against Bayes-Swarm-P, paired by seed',
    )


def _report_case3(page: ReportPage) -> None:
    _reference_section(page, 'table4', ['config.robots'])
    _paired_section(page, 'config.robots', 48, [], '100 against 48 robots, paired by seed')


def _report_penalty(page: ReportPage) -> None:
    _reference_section(page, 'table5', ['config.case', 'config.variant'])
    _paired_section(
        page,
        'config.variant',
        'o',
        ['config.case', 'config.source'],
        'Bayes-Swarm-P against Bayes-Swarm-O, paired by seed (mean_diff < 0: P faster)',
    )


def _report_comm(page: ReportPage) -> None:
    _reference_section(page, 'table6', ['config.case', 'config.comm_level'])
    page.add_text(
        'comm_level 0 is unlimited; 1-3 are 1, 0.5, 0.1 m in Case 1 and 20, 10, 5 m in Case 2.'
    )
    _paired_section(
        page,
        'config.comm_level',
        0,
        ['config.case'],
        'Limited against unlimited communication, paired by seed',
    )


def _report_noise(page: ReportPage) -> None:
    _reference_section(
        page, 'table7', ['config.case', 'config.noise_fraction', 'config.alpha_t_max_s']
    )
    _paired_section(
        page,
        'config.noise_fraction',
        0.0,
        ['config.case', 'config.alpha_t_max_s'],
        'Noise against no noise, paired by seed',
    )


def _report_avalanche(page: ReportPage) -> None:
    _reference_section(page, 'table8', ['config.algorithm', 'config.noise_std'])
    _paired_section(
        page,
        'config.algorithm',
        'bayes_swarm_p',
        ['config.noise_std'],
        'Methods against Bayes-Swarm-P, paired by seed',
    )


def _report_scaling(page: ReportPage) -> None:
    rows = page.rows
    if rows.empty:
        return
    by = ['config.solvers', 'config.robots']
    page.add_table(
        _mean_std(rows, by),
        title='tau per swarm size and solvers (Fig. 4)',
        export='tau',
    )
    page.add_text(
        'Paper Fig. 4 (read from the figure, COBYLA / L-BFGS-B): tau falls steeply up to 20 '
        'robots, then stays flat; the median decision time grows with the swarm, about '
        '0.1-1 s on a 4-core Xeon.'
    )
    cost = (
        rows.groupby(_with_varied(rows, by), sort=False)
        .agg(
            decision_cpu_ms=('metric.finder_decision_cpu_ms', 'median'),
            mission_cpu_s=('metric.mission_cpu_s', 'mean'),
            decisions=('metric.decisions', 'mean'),
        )
        .reset_index()
    )
    page.add_table(
        cost,
        title="cost per swarm size: the finder's median decision CPU time (median over runs), "
        'mission CPU and decisions (means over runs)',
        export='cost',
    )
    _scaling_figure(page, rows)
    _paired_section(
        page,
        'config.solvers',
        'cobyla/lbfgsb',
        ['config.robots'],
        "PSO / L-BFGS-B against the paper's COBYLA / L-BFGS-B, paired by seed",
    )


def _scaling_figure(page: ReportPage, rows: Any) -> None:
    """tau and decision CPU against swarm size, one line per solver pair (as Fig. 4)."""
    from matplotlib.figure import Figure

    figure = Figure(figsize=(9.0, 3.6))
    tau_ax, cpu_ax = figure.subplots(1, 2)
    for solvers, of_solvers in rows.groupby('config.solvers', sort=False):
        found = of_solvers[of_solvers['metric.found'].astype(bool)]
        tau = found.groupby('config.robots')['metric.tau'].agg(['mean', 'std'])
        tau_ax.errorbar(
            tau.index, tau['mean'], yerr=tau['std'], marker='o', capsize=3, label=str(solvers)
        )
        cpu = of_solvers.groupby('config.robots')['metric.finder_decision_cpu_ms'].median()
        cpu_ax.plot(cpu.index, cpu.values, marker='o', label=str(solvers))
    tau_ax.set_xlabel('robots')
    tau_ax.set_ylabel('tau (mean ± std, found runs)')
    cpu_ax.set_xlabel('robots')
    cpu_ax.set_ylabel('median decision CPU [ms]')
    cpu_ax.set_yscale('log')
    for ax in (tau_ax, cpu_ax):
        ax.grid(alpha=0.3)
        ax.legend(fontsize='small')
    figure.suptitle('Bayes-Swarm Fig. 4: Case 2, random sources, swarm size', fontsize='small')
    page.add_figure(figure, 'fig4-scaling', caption='tau and decision CPU against swarm size')


# ---------------------------------------------------------------------------- studies
def studies() -> list[Study]:
    """The Bayes-Swarm-P paper's studies, 55 seeds per configuration by default."""
    common = {'profile': 'paper', 'seed_offset': 0}
    return [
        Study(
            name='bayes-table1-2-optimizers',
            run=run_bayes,
            axes={
                'case': ('case1', 'case2'),
                'source': ('paper', 'random'),
                'solvers': ('cobyla/lbfgsb', 'pso/lbfgsb', 'grid/newton'),
            },
            params=dict(common),
            runs=55,
            description=(
                "Tables 1-2: the paper's solver choices (COBYLA / L-BFGS-B, PSO) and the "
                "project's grid / Newton solvers, on the paper's fields and on randomly placed "
                'sources; tau and decision CPU time.'
            ),
            smoke=Smoke(runs=2, axes={'case': ('case1',), 'solvers': ('cobyla/lbfgsb',)}),
            report=_report_optimizers,
            check=check_config,
        ),
        Study(
            name='bayes-table3-baselines',
            run=run_bayes,
            axes={
                'case': ('case1', 'case2'),
                'algorithm': ('bayes_swarm_p', 'glowworm', 'levy', 'exhaustive'),
            },
            params={**common, 'baseline_t_max_factor': 30.0},
            runs=55,
            description=(
                'Table 3: Bayes-Swarm-P against Glowworm, Levy walk and the exhaustive sweep '
                '(Levy walk and the sweep get 30 times the paper T_max).'
            ),
            smoke=Smoke(
                runs=1,
                axes={'case': ('case1',), 'algorithm': ('bayes_swarm_p', 'exhaustive')},
            ),
            report=_report_baselines,
            check=check_config,
        ),
        Study(
            name='bayes-table4-case3',
            run=run_bayes,
            axes={'robots': (48, 100)},
            params={**common, 'case': 'case3', 't_max_s': 0.0},
            runs=55,
            description='Table 4: Case 3 with 48 and 100 robots from the four corners.',
            smoke=Smoke(runs=1, axes={'robots': (48,)}, params={'t_max_s': 120.0}),
            report=_report_case3,
            check=check_config,
        ),
        Study(
            name='bayes-table5-penalty',
            run=run_bayes,
            axes={
                'case': ('case1', 'case2', 'case3'),
                'source': ('paper', 'random'),
                'variant': ('p', 'o'),
            },
            params=dict(common),
            runs=55,
            description=(
                'Table 5: Bayes-Swarm-P (penalty) against Bayes-Swarm-O, paired, on Cases 1-3 '
                '(Case 3: 48 robots); on the paper fields every seed flies nearly one scenario, '
                'so judge over randomly placed sources.'
            ),
            smoke=Smoke(runs=2, axes={'case': ('case1',), 'source': ('paper',)}),
            report=_report_penalty,
            check=check_config,
        ),
        Study(
            name='bayes-table6-comm',
            run=run_bayes,
            axes={'case': ('case1', 'case2'), 'comm_level': (0, 1, 2, 3)},
            params=dict(common),
            runs=55,
            description='Table 6: limited communication ranges.',
            smoke=Smoke(runs=1, axes={'case': ('case1',), 'comm_level': (0, 3)}),
            report=_report_comm,
            check=check_config,
        ),
        Study(
            name='bayes-table7-noise',
            run=run_bayes,
            axes={
                'case': ('case1', 'case2'),
                'noise_fraction': (0.0, 0.02, 0.05, 0.1),
                'alpha_t_max_s': (100.0, 1000.0),
            },
            params=dict(common),
            runs=55,
            description='Table 7: measurement noise |A|/50, /20, /10 x the alpha T_max.',
            smoke=Smoke(
                runs=1,
                axes={'case': ('case1',), 'noise_fraction': (0.0, 0.1), 'alpha_t_max_s': (100.0,)},
            ),
            report=_report_noise,
            check=check_config,
        ),
        Study(
            name='bayes-table8-avalanche',
            run=run_bayes,
            axes={
                'algorithm': ('bayes_swarm_p', 'alpha1', 'glowworm', 'levy', 'exhaustive'),
                'noise_std': (0.0, 0.47),
            },
            params={
                **common,
                'case': 'avalanche',
                'baseline_t_max_factor': 30.0,
                'glowworm_t_max_factor': 10.0,
            },
            runs=55,
            description=(
                'Table 8: the avalanche beacon, 6 UAVs, without and with noise (Levy walk and '
                'the sweep get 30 times the paper T_max, Glowworm 10 times: the paper reports '
                'it at 583 s under noise).'
            ),
            smoke=Smoke(runs=1, axes={'algorithm': ('bayes_swarm_p',), 'noise_std': (0.47,)}),
            report=_report_avalanche,
            check=check_config,
        ),
        Study(
            name='bayes-fig4-scaling',
            run=run_bayes,
            axes={
                'solvers': ('cobyla/lbfgsb', 'pso/lbfgsb'),
                'robots': (5, 10, 20, 30, 40, 50),
            },
            params={**common, 'case': 'case2', 'source': 'random'},
            runs=55,
            description=(
                'Fig. 4: Case 2 with 5 to 50 robots, both solver choices, sources placed at '
                'random (on the paper field every size repeats one fixed path).'
            ),
            smoke=Smoke(runs=1, axes={'solvers': ('cobyla/lbfgsb',), 'robots': (5, 10)}),
            report=_report_scaling,
            check=check_config,
        ),
    ]
