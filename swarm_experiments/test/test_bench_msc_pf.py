"""benchmarks/bench_msc_pf.py: controller settings given on the command line (--set)."""

from __future__ import annotations

import math

import numpy as np
import pytest
from swarm_sim.errors import ConfigurationError


@pytest.fixture
def bench(benchmark_script):
    return benchmark_script('bench_msc_pf')


def test_settings_are_read_as_their_fields_types(bench):
    overrides = bench.controller_overrides(
        [
            'phases.unheard_updates=true',
            'phases.recorded_max_age_s=900',
            'swarm.max_size=4',
            'msc.leader_rule=pbest',
        ]
    )
    config = bench.controller_config(overrides)
    assert config.phases.unheard_updates is True
    assert config.phases.recorded_max_age_s == 900.0
    assert config.swarm.max_size == 4
    assert config.msc.leader_rule == 'pbest'
    assert bench.controller_config(bench.controller_overrides([])) == bench.MscPfConfig()


@pytest.mark.parametrize(
    ('setting', 'message'),
    [
        ('phases.no_such_field=1', 'unknown parameter'),
        ('nowhere.x=1', 'unknown parameter'),
        ('phases.unheard_updates=maybe', 'expected true or false'),
        ('swarm.max_size=three', 'expected an integer'),
        ('scheme=msc', "'scheme' is set by"),
        ('swarm.max_size=0', 'max_size'),
    ],
)
def test_unknown_settings_and_bad_values_are_rejected(bench, setting, message):
    with pytest.raises(ConfigurationError, match=message):
        bench.controller_overrides([setting])


def test_a_bad_setting_stops_the_benchmark_before_any_run(bench, monkeypatch, capsys):
    monkeypatch.setattr(bench, 'run', lambda **_: pytest.fail('a run started'))
    assert bench.main(['--set', 'phases.unheard_updates=maybe']) == 2
    err = capsys.readouterr().err
    assert err.count('\n') == 1
    assert 'expected true or false' in err


def test_search_table_averages_the_seeds_that_reached_each_share(bench):
    from swarm_experiments.msc_pf_batch import SearchCoverage

    results = [
        (0, SearchCoverage((0.5, 1.0), (800.0, 9000.0), 9000.0)),
        (1, SearchCoverage((0.5, 1.0), (1000.0, float('nan')), 20000.0)),
    ]
    table = bench.search_table(results, 15)
    assert '| 50 % | 900 +- 100 | 800 | 1000 | 0 |' in table
    assert '| 100 % | 9000 +- 0 | 9000 | 9000 | 1 |' in table


def test_the_last_first_hearing_and_the_approach_survive_the_csv(bench, tmp_path):
    outcome = bench.RunOutcome(
        'msc', 10, 15, 3, 7000.0, True, 12.0, 2900.0, 11.5, 5100.0, 812.0, 2.375
    )
    path = tmp_path / 'runs.csv'
    path.write_text(bench.CSV_HEADER + bench._csv_row(outcome))
    assert bench.read_outcomes(path) == [outcome]


def test_a_csv_from_before_the_approach_columns_reads_them_as_nan(bench, tmp_path):
    path = tmp_path / 'old.csv'
    path.write_text(
        'scheme,targets,robots,seed,cct_s,finished,wall_s,mean_capture_s,cpu_s,last_heard_s\n'
        'msc,10,15,3,7000,1,12.0,2900,11.5,5100\n'
    )
    (outcome,) = bench.read_outcomes(path)
    assert outcome.last_heard_s == 5100.0
    assert math.isnan(outcome.approach_s)
    assert math.isnan(outcome.approach_ratio)


def test_approach_medians_skip_targets_not_heard_or_not_captured(bench):
    heard = np.array([100.0, 200.0, np.nan, 300.0, 400.0])
    ranges = np.array([250.0, 100.0, np.nan, 290.0, 0.2])
    captured = np.array([600.0, 500.0, 900.0, np.nan, 420.0])
    # Counted: 500 s over 250 m (2.0), 300 s over 100 m (3.0), 20 s over 1 m (floor: 20.0).
    took, ratio = bench.approach_medians(heard, ranges, captured, max_speed_m_s=1.0)
    assert took == 300.0
    assert ratio == 3.0
    took, ratio = bench.approach_medians(heard, ranges, captured, max_speed_m_s=2.0)
    assert ratio == 6.0
    nothing = bench.approach_medians(heard[2:3], ranges[2:3], captured[2:3], 1.0)
    assert all(math.isnan(v) for v in nothing)


def test_approach_table_averages_the_run_medians(bench):
    def run(scheme, seed, took, ratio):
        return bench.RunOutcome(
            scheme, 15, 15, seed, 6000.0, True, 1.0, 1.0, 1.0, 4000.0, took, ratio
        )

    rows = [
        run('proposed', 0, 500.0, 1.5),
        run('proposed', 1, 700.0, 2.5),
        run('msc', 0, 800.0, 2.0),
        run('msc', 1, math.nan, math.nan),
    ]
    table = bench.approach_table(rows, ('proposed', 'msc'))
    assert '| 15 | 600 +- 100 / 2.00 +- 0.50 (n=2) | 800 +- 0 / 2.00 +- 0.00 (n=1) |' in table


def test_search_floor_table_splits_the_cct_at_the_last_first_hearing(bench):
    def run(scheme, seed, cct, heard, finished=True):
        return bench.RunOutcome(scheme, 10, 15, seed, cct, finished, 1.0, 1.0, 1.0, heard)

    rows = [
        run('proposed', 0, 5000.0, 4000.0),
        run('proposed', 1, 7000.0, 4000.0),
        run('proposed', 2, 20000.0, 9000.0, finished=False),
        run('msc', 0, 6000.0, 4500.0),
        run('msc', 1, 8000.0, 5500.0),
    ]
    table = bench.search_floor_table(rows, ('proposed', 'msc'))
    # proposed: heard at 4000 in both finished runs, then 1000 and 3000 s; msc: 1500, 2500 s.
    row = '| 10 | 4000 +- 0 / 2000 / 2000 (n=2) | 5000 +- 500 / 2000 / 2000 (n=2) | 4200 |'
    assert row in table


def test_paired_differences_use_only_the_seeds_both_schemes_ran(bench):
    def run(scheme, seed, cct):
        return bench.RunOutcome(scheme, 10, 15, seed, cct, True, 1.0)

    rows = [
        run('proposed', 0, 5000.0),
        run('proposed', 1, 6000.0),
        run('proposed', 2, 9000.0),
        run('proposed', 3, 1000.0),  # no msc run of seed 3
        run('msc', 0, 7000.0),
        run('msc', 1, 7000.0),
        run('msc', 2, 6000.0),
    ]
    # Gaps 2000, 1000, -3000: mean 0, sample std 2646, standard error 1528; 2 wins of 3.
    mean, error, wins, seeds = bench.paired_difference(rows, 10, 'proposed', 'msc')
    assert mean == 0.0
    assert error == pytest.approx(2645.75 / math.sqrt(3), rel=1e-4)
    assert (wins, seeds) == (2, 3)
    assert bench.paired_difference(rows, 15, 'proposed', 'msc') is None
    table = bench.paired_table(rows, ('proposed', 'msc'))
    assert '| 10 | 0 +- 1528 (2/3) |' in table
    assert bench.paired_table(rows, ('msc',)) == []


def test_the_approach_target_lies_400_to_900_m_from_the_start_by_seed(bench):
    spots = [bench.approach_target(seed) for seed in range(20)]
    distances = [float(np.hypot(*(spot[0] - 1000.0))) for spot in spots]
    assert all(400.0 <= d <= 900.0 for d in distances)
    assert len({round(d, 6) for d in distances}) == 20
    np.testing.assert_array_equal(bench.approach_target(3), spots[3])


def test_the_approach_table_gives_medians_per_scheme(bench):
    results = [('proposed', 0, 300.0, 1.0), ('proposed', 1, 500.0, 2.0), ('msc', 0, 900.0, 3.0)]
    lines = bench.single_target_table(results, 15, (('phases.max_pursuers', 1),))
    assert 'phases.max_pursuers=1' in lines[0]
    assert '| proposed | 2 | 400 | 400 | 1.50 | 300 500 |' in lines
    assert '| msc | 1 | 900 | 900 | 3.00 | 900 |' in lines
