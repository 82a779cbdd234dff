"""benchmarks/bench_msc_pf.py: controller settings given on the command line (--set)."""

from __future__ import annotations

import pytest
from sim_bridge.errors import ConfigurationError


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
    monkeypatch.setattr('sys.argv', ['bench_msc_pf.py', '--set', 'phases.unheard_updates=maybe'])
    with pytest.raises(SystemExit) as exit_info:
        bench.main()
    assert exit_info.value.code == 2
    assert 'expected true or false' in capsys.readouterr().err


def test_search_table_averages_the_seeds_that_reached_each_share(bench):
    from sim_bridge.msc_pf_batch import SearchCoverage

    results = [
        (0, SearchCoverage((0.5, 1.0), (800.0, 9000.0), 9000.0)),
        (1, SearchCoverage((0.5, 1.0), (1000.0, float('nan')), 20000.0)),
    ]
    table = bench.search_table(results, 15)
    assert '| 50 % | 900 +- 100 | 800 | 1000 | 0 |' in table
    assert '| 100 % | 9000 +- 0 | 9000 | 9000 | 1 |' in table


def test_the_last_first_hearing_survives_the_csv(bench, tmp_path):
    outcome = bench.RunOutcome('msc', 10, 15, 3, 7000.0, True, 12.0, 2900.0, 11.5, 5100.0)
    path = tmp_path / 'runs.csv'
    path.write_text(bench.CSV_HEADER + bench._csv_row(outcome))
    assert bench.read_outcomes(path) == [outcome]


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
