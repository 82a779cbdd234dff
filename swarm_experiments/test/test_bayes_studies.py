"""The Bayes-Swarm-P studies: registered, named for the paper's tables, runs give rows."""

import math

import pytest
from swarm_experiments.bayes_studies import PAPER, run_bayes, studies
from swarm_experiments.study import (
    RunSpec,
    UsageError,
    load_registry,
    make_specs,
    parse_overrides,
)

pytestmark = pytest.mark.runtime_independent(reason='batch runs and reports, no node')

EXPECTED = {
    'bayes-table1-2-optimizers',
    'bayes-table3-baselines',
    'bayes-table4-case3',
    'bayes-table5-penalty',
    'bayes-table6-comm',
    'bayes-table7-noise',
    'bayes-table8-avalanche',
    'bayes-fig4-scaling',
}


def test_every_paper_study_is_registered_through_the_entry_point_with_55_seeds():
    registry = load_registry()
    assert {study.name for study in registry} >= EXPECTED
    for study in studies():
        assert study.runs == 55
        assert study.smoke.runs <= 2
        assert study.params['profile'] == 'paper'
        assert study.params['seed_offset'] == 0


def _spec(config, seed=3):
    return RunSpec('test', config, seed, 'id')


def test_a_run_returns_tau_and_a_censored_tau_that_pairs_failures():
    found = run_bayes(_spec({'case': 'case1', 'robots': 3, 'variant': 'o'}))
    assert found['found']
    assert found['tau'] == found['tau_censored']
    assert found['finder_decision_cpu_ms'] > 0.0
    short = run_bayes(_spec({'case': 'case1', 'robots': 3, 't_max_s': 12.0}))
    assert not short['found']
    assert math.isnan(short['tau'])
    assert short['tau_censored'] == pytest.approx(
        (12.0 - math.sqrt(5) / 0.1) / (math.sqrt(5) / 0.1)
    )


def test_glowworm_gets_its_own_time_limit_factor_and_the_avalanche_study_sets_it():
    # The swarm needs about 155 s to climb to the beacon from the 5 m dispersal fan: it
    # fails within the paper's T_max of 100 s and finds it with a longer limit.
    config = {'case': 'avalanche', 'algorithm': 'glowworm'}
    paper_limit = run_bayes(_spec(config, 0))
    assert not paper_limit['found']
    assert paper_limit['tau_censored'] == pytest.approx((100.0 - 56.5685) / 56.5685, rel=1e-4)
    extended = run_bayes(_spec({**config, 'glowworm_t_max_factor': 3.0}, 0))
    assert extended['found']
    assert 100.0 < extended['found_time_s'] < 300.0
    # The Levy / sweep factor does not reach Glowworm, nor Glowworm's the others.
    unchanged = run_bayes(_spec({**config, 'baseline_t_max_factor': 3.0}, 0))
    assert not unchanged['found']
    avalanche = {study.name: study for study in studies()}['bayes-table8-avalanche']
    assert avalanche.params['glowworm_t_max_factor'] * 100.0 > 583.0  # the paper's 9.30


def test_random_sources_follow_the_seed_and_stay_inside_the_arena():
    a = run_bayes(_spec({'case': 'case1', 'robots': 2, 'source': 'random', 't_max_s': 1.0}, 5))
    b = run_bayes(_spec({'case': 'case1', 'robots': 2, 'source': 'random', 't_max_s': 1.0}, 6))
    assert (a['source_x_m'], a['source_y_m']) != (b['source_x_m'], b['source_y_m'])
    for row in (a, b):
        assert 0.24 <= row['source_x_m'] <= 2.16
        assert 0.24 <= row['source_y_m'] <= 2.16


def test_unknown_parameters_are_refused():
    with pytest.raises(ValueError, match='colour'):
        run_bayes(_spec({'case': 'case1', 'colour': 'red'}))


def test_the_papers_published_numbers_are_written_down_for_every_table():
    assert PAPER['table5'][('case2', 'o')] == (0.75, 0.42)
    assert PAPER['table8'][('bayes_swarm_p', 0.47)] == (0.66, 0.47)
    assert set(PAPER) == {'table3', 'table4', 'table5', 'table6', 'table7', 'table8'}


def test_the_penalty_tables_lead_with_the_paper_profile_and_pair_p_with_o(tmp_path):
    import pandas as pd
    from swarm_experiments.study import ReportPage

    from swarm_experiments import bayes_studies

    records = []
    # The estimated-penalty rows come first in storage; the tables must still lead with paper.
    for profile, p_gain in (('estimated-penalty', 0.1), ('paper', 0.0)):
        for seed in range(6):
            for variant in ('p', 'o'):
                tau = 0.5 + 0.01 * seed - (p_gain if variant == 'p' else 0.0)
                records.append(
                    {
                        'status': 'ok',
                        'seed': seed,
                        'param.profile': profile,
                        'param.seed_offset': 101,
                        'config.case': 'case1',
                        'config.source': 'paper',
                        'config.variant': variant,
                        'metric.found': True,
                        'metric.tau': tau,
                        'metric.tau_censored': tau,
                    }
                )
    page = ReportPage(tmp_path, {'study': 'bayes-table5-penalty'}, pd.DataFrame(records))
    bayes_studies._report_penalty(page)
    tau = page.exports['tau']
    assert [row[0] for row in tau['rows']] == ['paper', 'paper', *['estimated-penalty'] * 2]
    paired = page.exports['paired']
    assert paired['columns'][:2] == ['variant', 'profile']
    by_profile = {row[1]: dict(zip(paired['columns'], row, strict=True)) for row in paired['rows']}
    assert [row[1] for row in paired['rows']] == ['paper', 'estimated-penalty']
    assert by_profile['paper']['ties'] == '6'  # P = O on every seed: no test possible
    assert by_profile['paper']['p_wilcoxon'] == ''
    assert by_profile['estimated-penalty']['losses'] == '6'  # P faster on every seed
    assert float(by_profile['estimated-penalty']['mean_diff']) == -0.1
    assert float(by_profile['estimated-penalty']['p_wilcoxon']) < 0.05


def test_random_source_rows_stay_apart_and_out_of_the_paper_comparison(tmp_path):
    import pandas as pd
    from swarm_experiments.study import ReportPage

    from swarm_experiments import bayes_studies

    records = [
        {
            'status': 'ok',
            'seed': seed,
            'param.profile': 'paper',
            'config.case': 'case2',
            'config.source': source,
            'config.variant': variant,
            'metric.found': True,
            'metric.tau': tau + 0.01 * seed,
            'metric.tau_censored': tau + 0.01 * seed,
        }
        for source, tau in (('paper', 0.5), ('random', 2.0))
        for seed in range(3)
        for variant in ('p', 'o')
    ]
    page = ReportPage(tmp_path, {'study': 'bayes-table5-penalty'}, pd.DataFrame(records))
    bayes_studies._report_penalty(page)
    tau = page.exports['tau']
    assert tau['columns'][:3] == ['source', 'case', 'variant']
    means = {(row[0], row[2]): float(row[5]) for row in tau['rows']}
    assert means == {
        ('paper', 'p'): 0.51,
        ('paper', 'o'): 0.51,
        ('random', 'p'): 2.01,
        ('random', 'o'): 2.01,
    }
    paper = {row[1]: row for row in page.exports['paper']['rows'] if row[0] == 'case2'}
    assert float(paper['p'][2]) == 0.51  # the paper's field only
    assert len(page.exports['paired']['rows']) == 2  # one per source placement


def test_the_optimizers_report_exports_tau_per_solver_and_the_paired_table(tmp_path):
    import pandas as pd
    from swarm_experiments.study import ReportPage

    from swarm_experiments import bayes_studies

    records = [
        {
            'status': 'ok',
            'seed': seed,
            'config.case': 'case1',
            'config.source': 'paper',
            'config.solvers': solvers,
            'metric.found': True,
            'metric.tau': tau + 0.01 * seed,
            'metric.tau_censored': tau + 0.01 * seed,
        }
        for seed in range(4)
        for solvers, tau in (('cobyla/lbfgsb', 0.3), ('pso/lbfgsb', 0.4))
    ]
    page = ReportPage(tmp_path, {'study': 'bayes-table1-2-optimizers'}, pd.DataFrame(records))
    bayes_studies._report_optimizers(page)
    tau = {
        row[2]: dict(zip(page.exports['tau']['columns'], row, strict=True))
        for row in page.exports['tau']['rows']
    }
    assert set(tau) == {'cobyla/lbfgsb', 'pso/lbfgsb'}
    assert float(tau['pso/lbfgsb']['mean']) > float(tau['cobyla/lbfgsb']['mean'])
    assert len(page.exports['paired']['rows']) == 1  # PSO against the paper's solvers


def test_the_scaling_report_exports_tau_cost_and_pso_against_cobyla_per_size(tmp_path):
    import pandas as pd
    from swarm_experiments.study import ReportPage

    from swarm_experiments import bayes_studies

    records = [
        {
            'status': 'ok',
            'seed': seed,
            'config.solvers': solvers,
            'config.robots': robots,
            'metric.found': True,
            'metric.tau': tau / robots + 0.01 * seed,
            'metric.tau_censored': tau / robots + 0.01 * seed,
            'metric.finder_decision_cpu_ms': cpu_ms * robots,
            'metric.mission_cpu_s': 0.1 * robots,
            'metric.decisions': 2 * robots,
        }
        for seed in range(4)
        for robots in (5, 10)
        for solvers, tau, cpu_ms in (('cobyla/lbfgsb', 3.0, 1.0), ('pso/lbfgsb', 4.0, 10.0))
    ]
    page = ReportPage(tmp_path, {'study': 'bayes-fig4-scaling'}, pd.DataFrame(records))
    bayes_studies._report_scaling(page)
    tau = page.exports['tau']
    assert len(tau['rows']) == 4
    columns = page.exports['cost']['columns']
    cost = {
        (str(row[0]), int(row[1])): dict(zip(columns, row, strict=True))
        for row in page.exports['cost']['rows']
    }
    assert float(cost[('pso/lbfgsb', 10)]['decision_cpu_ms']) == pytest.approx(100.0)
    assert float(cost[('cobyla/lbfgsb', 5)]['decision_cpu_ms']) == pytest.approx(5.0)
    # PSO is paired with the paper's solvers once per swarm size.
    assert len(page.exports['paired']['rows']) == 2
    assert (tmp_path / 'figures' / 'fig4-scaling.png').is_file()


@pytest.mark.parametrize(
    ('name', 'setting', 'message'),
    [
        ('bayes-table4-case3', 't_max_s=-1', r'^t_max_s=-1\.0: must be >= 0$'),
        ('bayes-table4-case3', 'robots=-4', r'^robots=-4: must be >= 0$'),
        ('bayes-table6-comm', 'comm_level=5', r'^comm_level=5: must be <= 3$'),
        (
            'bayes-table1-2-optimizers',
            'solvers=bogus/lbfgsb',
            r"^solvers='bogus/lbfgsb': 'bogus' is not one of grid, cobyla, pso$",
        ),
        ('bayes-table1-2-optimizers', 'profile=x', r"^profile='x': choose one of paper"),
        ('bayes-table3-baselines', 'algorithm=foo', r"^algorithm='foo': choose one of "),
        ('bayes-table3-baselines', 'baseline_t_max_factor=-2', r'must be > 0$'),
        ('bayes-table7-noise', 'noise_fraction=-0.1', r'^noise_fraction=-0\.1: must be >= 0$'),
        ('bayes-table8-avalanche', 'noise_std=-1', r'^noise_std=-1\.0: must be >= 0$'),
    ],
)
def test_a_bad_set_value_is_refused_before_anything_runs(name, setting, message):
    (study,) = [s for s in studies() if s.name == name]
    with pytest.raises(UsageError, match=message):
        make_specs(study, smoke=True, overrides=parse_overrides([setting]))


def test_every_bayes_study_has_a_check_its_own_configurations_pass():
    for study in studies():
        assert study.check is not None, study.name
        make_specs(study)


def test_run_bayes_refuses_a_negative_t_max_instead_of_running():
    with pytest.raises(UsageError, match=r'^t_max_s=-5\.0: must be >= 0$'):
        run_bayes(_spec({'case': 'case1', 'robots': 3, 't_max_s': -5.0}))
