"""The MSC + PF studies: registration, one run's row against the batch runner, the reports."""

from __future__ import annotations

import json
import math
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest
from msc_pf.parameters import MSC_PF_PARAMETERS
from msc_pf.schemes import Scheme
from swarm_experiments.msc_pf_batch import BatchScenario, run_batch
from swarm_experiments.msc_pf_studies import (
    VARIANTS,
    best_msc,
    controller_settings,
    run_msc_pf,
    studies,
)
from swarm_experiments.study import (
    RunSpec,
    StudyRegistry,
    UsageError,
    load_registry,
    make_engine,
    make_specs,
    parse_overrides,
    run_study,
    write_reports,
)

pytestmark = pytest.mark.runtime_independent(reason='batch runs and reports, no node')

NAMES = ('msc_pf-fig4', 'msc_pf-beyond', 'msc_pf-beyond-robots')


def test_the_studies_are_registered_through_the_entry_point():
    registry = load_registry()
    for name in NAMES:
        assert name in registry
    fig4 = registry.get('msc_pf-fig4')
    plan = make_specs(fig4)
    assert len(plan.specs) == 3 * 3 * 40
    assert {s.config['variant'] for s in plan.specs} == {'proposed', 'msc_pf', 'msc'}
    assert {s.config['targets'] for s in plan.specs} == {10, 15, 20}
    smoke = make_specs(fig4, smoke=True)
    assert len(smoke.specs) == 3 * 2
    assert {s.config['t_max_s'] for s in smoke.specs} == {3000.0}


def test_variant_settings_and_changed_parameters_reach_the_controller():
    assert controller_settings('msc-solo', {}) == {'swarm.max_size': 1}
    given = {'swarm': {'max_size': 3, 'comm_range_m': 100.0}, 'msc': {'leader_rule': 'gradient'}}
    # Only values other than the defaults count; the variant's own come first.
    assert controller_settings('msc-gather', given) == {
        'swarm.search_alone': True,
        'swarm.comm_range_m': 100.0,
    }
    with pytest.raises(ValueError, match='unknown variant'):
        controller_settings('pso', {})
    for scheme, settings in VARIANTS.values():
        Scheme(scheme)
        MSC_PF_PARAMETERS.build(dict(settings))  # every variant is a valid configuration


def test_a_studys_parameters_accept_set_with_the_node_names():
    fig4 = next(s for s in studies() if s.name == 'msc_pf-fig4')
    plan = make_specs(fig4, overrides={'controller.msc.leader_rule': 'pbest', 'targets': '10'})
    assert {s.config['controller']['msc']['leader_rule'] for s in plan.specs} == {'pbest'}
    assert controller_settings('msc', plan.specs[0].config['controller']) == {
        'msc.leader_rule': 'pbest'
    }


def small_spec(variant: str, seed: int = 2, t_max_s: float = 1500.0) -> RunSpec:
    fig4 = next(s for s in studies() if s.name == 'msc_pf-fig4')
    config = dict(make_specs(fig4).specs[0].config)
    config.update(variant=variant, targets=2, robots=4, t_max_s=t_max_s)
    return RunSpec(study='msc_pf-fig4', config=config, seed=seed, run_id='x')


@pytest.mark.slow
def test_a_run_reports_the_batch_runners_cct_and_its_breakdown():
    row = run_msc_pf(small_spec('proposed'))
    batch = run_batch(
        BatchScenario(scheme=Scheme.PROPOSED, n_robots=4, n_targets=2, seed=2, max_time_s=1500.0)
    )
    captured = np.sort(batch.capture_times_s[np.isfinite(batch.capture_times_s)])
    assert row['captured'] == len(captured)
    assert row['capture_times_s'] == captured.tolist()
    if row['finished']:
        assert row['cct_s'] == batch.cct_s == captured[-1]
        assert row['last_heard_s'] <= row['cct_s']
        assert row['after_heard_s'] == pytest.approx(row['cct_s'] - row['last_heard_s'])
    else:
        assert row['cct_s'] == 1500.0
    assert row['first_heard_s'] == sorted(row['first_heard_s'])


@pytest.mark.slow
@pytest.mark.parametrize('variant', ['proposed-gather', 'proposed-sweep'])
def test_a_variant_runs_its_own_settings(variant: str):
    spec = small_spec(variant, t_max_s=200.0)
    row = run_msc_pf(spec)
    config = replace(
        MSC_PF_PARAMETERS.build(dict(VARIANTS[variant][1])).controller, scheme=Scheme.PROPOSED
    )
    batch = run_batch(
        BatchScenario(
            scheme=Scheme.PROPOSED,
            n_robots=4,
            n_targets=2,
            seed=2,
            max_time_s=200.0,
            controller=config,
        )
    )
    assert row['capture_times_s'] == sorted(
        batch.capture_times_s[np.isfinite(batch.capture_times_s)].tolist()
    )
    assert row['first_heard_s'] == sorted(
        batch.first_heard_s[np.isfinite(batch.first_heard_s)].tolist()
    )


def test_the_best_msc_is_chosen_on_the_seeds_every_msc_variant_ran():
    import pandas as pd

    rows = pd.DataFrame(
        {
            'config.variant': ['msc', 'msc', 'msc-sweep', 'msc-sweep', 'msc-pbest'],
            'seed': [0, 1, 0, 1, 0],
            'metric.cct_s': [5000.0, 1000.0, 4000.0, 4000.0, 4500.0],
        }
    )
    # On seed 0, the only one all three ran, msc-sweep is lowest (msc's mean over both of
    # its seeds would be lower).
    best, seeds, means = best_msc(rows)
    assert best == 'msc-sweep'
    assert seeds == [0]
    assert means['msc-pbest'] == 4500.0
    assert best_msc(rows[rows['config.variant'] == 'proposed']) == (None, [], None)


@pytest.mark.slow
def test_the_reports_compare_with_the_paper_and_the_best_msc(tmp_path: Path):
    by_name = {s.name: s for s in studies()}
    overrides = {'targets': '1', 'robots': '3', 't_max_s': '60'}
    for name, variants, targets in (
        ('msc_pf-fig4', 'proposed,msc_pf,msc', '1,2'),
        ('msc_pf-beyond', 'proposed,msc,msc-pbest,msc-solo,proposed-sweep', '1'),
    ):
        given = {**overrides, 'variant': variants, 'targets': targets}
        plan = make_specs(by_name[name], runs=2, overrides=given)
        with make_engine('serial') as engine:
            run_study(plan, tmp_path, engine, code_version='v')
    pages = {
        path.parent.name: path.read_text()
        for path in write_reports(tmp_path, StudyRegistry(studies()))
    }
    fig4 = pages['msc_pf-fig4']
    assert 'prints no CCT values' in fig4
    assert "The paper's order, in the means" in fig4
    assert 'CCT minus MSC, paired by seed' in fig4
    assert 'CCT against the number of targets' in fig4
    assert (tmp_path / 'msc_pf-fig4' / 'figures' / 'fig4-cct.png').stat().st_size > 0
    exported = json.loads((tmp_path / 'msc_pf-fig4' / 'results.json').read_text())['tables']
    assert {'cct', 'order', 'rising', 'paired', 'breakdown'} <= set(exported)
    # One row per scheme over the two target counts, each with its two means.
    rising = exported['rising']
    assert len(rising['rows']) == 3
    beyond = pages['msc_pf-beyond']
    assert 'The MSC baseline as a bracket' in beyond
    assert 'MSC configurations on the seeds all of them ran' in beyond
    table = beyond.split('Against the best MSC configuration', 1)[1]
    # The paper-faithful scheme leads, the scheme beyond the paper follows.
    assert table.index('| proposed |') < table.index('| proposed-sweep |')
    assert not math.isnan(float(table.split('proposed-sweep |', 1)[1].split('|')[6]))
    results = json.loads((tmp_path / 'msc_pf-beyond' / 'results.json').read_text())
    assert {'bracket', 'cct', 'msc-screen', 'beyond', 'breakdown'} <= set(results['tables'])


@pytest.mark.parametrize(
    ('setting', 'message'),
    [
        ('t_max_s=-1', r'^t_max_s=-1\.0: must be > 0$'),
        ('robots=-1', r'^robots=-1: must be >= 1$'),
        ('targets=-3', r'^targets=-3: must be >= 1$'),
        ('variant=bogus', r"^variant='bogus': choose one of proposed, msc_pf, msc, "),
        ('loss=5', r'^loss=5\.0: must be <= 1$'),
        ('controller.period_s=0', r'^controller\.period_s: must be > 0 s, got 0 s$'),
        (
            'controller.particle_filter.n_particles=0',
            r'^controller\.particle_filter\.n_particles: must be >= 4, got 0$',
        ),
        (
            'controller.particle_filter.resampling=bogus',
            r"^controller\.particle_filter\.resampling: 'bogus' is not one of systematic",
        ),
    ],
)
@pytest.mark.parametrize('name', NAMES)
def test_a_bad_set_value_is_refused_before_anything_runs(
    name: str, setting: str, message: str
) -> None:
    (study,) = [s for s in studies() if s.name == name]
    with pytest.raises(UsageError, match=message):
        make_specs(study, smoke=True, overrides=parse_overrides([setting]))


def test_a_negative_t_max_never_gives_an_ok_row(tmp_path: Path) -> None:
    (study,) = [s for s in studies() if s.name == 'msc_pf-fig4']
    plan = make_specs(study, smoke=True, runs=1)
    config = {**plan.specs[0].config, 't_max_s': -1.0}
    with pytest.raises(UsageError, match='t_max_s'):
        run_msc_pf(RunSpec(study.name, config, 0, 'id', plan.specs[0].axes))
    bad = replace(plan, specs=(replace(plan.specs[0], config=config),))
    with make_engine('serial') as engine, pytest.raises(UsageError, match='t_max_s'):
        run_study(bad, tmp_path, engine)
    assert not list(tmp_path.iterdir())
