"""benchmarks/bench_oabug.py: OA-Bug node parameters given on the command line (--set)."""

from __future__ import annotations

import pytest


@pytest.fixture
def bench(benchmark_script):
    return benchmark_script('bench_oabug')


def test_set_parameters_reach_every_mission(bench, monkeypatch):
    pytest.importorskip('oabug_robot.node')
    import swarm_experiments.oabug_batch

    seen = []

    def fake_run(config):
        seen.append(config)
        raise RuntimeError('stop here')

    monkeypatch.setattr(swarm_experiments.oabug_batch, 'run_spawn_batch', fake_run)
    job = bench.Job('small', 3, 'gas_sound', 'edge', 4, 10, 0.3, 'batch', (('gas_threshold', 300),))
    with pytest.raises(RuntimeError, match='stop here'):
        bench.run_job(job)
    assert seen[0].robot_parameters == {'gas_threshold': 300}
    assert (seen[0].site_seed, seen[0].variant, seen[0].robots) == (3, 'gas_sound', 4)


def test_bad_set_parameters_stop_the_benchmark_before_any_run(bench, capsys, monkeypatch):
    pytest.importorskip('oabug_robot.node')
    monkeypatch.setattr(bench, 'run', lambda **_: pytest.fail('a run started'))
    with pytest.raises(SystemExit) as exit_info:
        bench.main(['--set', 'gas_threshold=high'])
    assert exit_info.value.code == 2
    assert 'gas_threshold' in capsys.readouterr().err


def _outcome(bench, departure, variant, robots, coverage):
    job = bench.Job('small', 0, variant, departure, robots, None, 0.3)
    return bench.Outcome(job, coverage, 300.0, 1.0, 1.0, 100.0)


def test_authors_figures_follow_the_robot_count(bench):
    ten = bench.reference_for('small', 10, None)
    four = bench.reference_for('small', 4, None)
    assert ten.sites == 100
    assert four.sites == 30
    assert ten.coverage[('edge', 'gas')] == (84.17, 21.07)
    assert four.coverage[('edge', 'gas_sound')] == (89.1, 12.9)
    assert four.coverage[('center', 'random')] == (7.7, 4.6)
    assert bench.reference_for('medium', 10, None).coverage[('center', 'gas')] == (93.75, 5.62)


def test_every_reference_lists_each_variant_from_both_departures(bench):
    for sweep in bench.REFERENCE.values():
        assert set(sweep.coverage) == {
            (departure, variant) for departure in bench.DEPARTURES for variant in bench.VARIANTS
        }
        for mean, std in sweep.coverage.values():
            assert 0.0 <= mean <= 100.0
            assert std >= 0.0


def test_no_authors_figures_for_other_robot_counts_or_budgets(bench):
    assert bench.reference_for('small', 5, None) is None
    assert bench.reference_for('medium', 4, None) is None
    assert bench.reference_for('small', 10, 500) is None
    assert bench.reference_for('small', 10, 1000) is not None


def test_table_puts_the_matching_authors_figure_beside_each_row(bench):
    outcomes = [
        _outcome(bench, 'edge', 'gas', 4, 0.9),
        _outcome(bench, 'edge', 'gas', 4, 0.8),
    ]
    table = bench.format_table(outcomes, bench.reference_for('small', 4, None))
    row = next(line for line in table.splitlines() if line.startswith('| edge | gas |'))
    assert '| 85.0 +- 5.0 | 71.3 +- 22.0 |' in row
    assert '30 sites' in table
    bare = bench.format_table(outcomes, None)
    assert '| 85.0 +- 5.0 | n/a |' in bare
    assert "No authors' figures" in bare
