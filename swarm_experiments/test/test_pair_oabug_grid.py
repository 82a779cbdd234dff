"""benchmarks/pair_oabug_grid.py: the study's runs paired site by site with the grid's CSV."""

from __future__ import annotations

import csv
from pathlib import Path

import pandas as pd
import pytest


@pytest.fixture
def pair(benchmark_script):
    return benchmark_script('pair_oabug_grid')


def _study_rows(coverage: dict[int, float], *, robots: int = 4) -> pd.DataFrame:
    records = []
    for site, value in coverage.items():
        for profile in ('paper', 'tuned'):
            records.append(
                {
                    'seed': site,
                    'status': 'ok',
                    'param.profile': profile,
                    'param.actions': None,
                    'config.site': 'small',
                    'config.robots': robots,
                    'config.variant': 'gas_sound',
                    'config.departure': 'edge',
                    # The tuned rows must not be paired: make them far off.
                    'metric.coverage_pct': value if profile == 'paper' else -1000.0,
                }
            )
    return pd.DataFrame(records)


def _grid_csv(path: Path, coverage: dict[int, float]) -> Path:
    with path.open('w', newline='') as handle:
        writer = csv.writer(handle)
        writer.writerow(['site', 'variant', 'departure', 'robot_hit_turn', 'coverage_pct'])
        for site, value in coverage.items():
            writer.writerow([site, 'gas_sound', 'edge', 'right', value])
            writer.writerow([site, 'gas', 'edge', 'right', 0.0])
    return path


def test_runs_pair_on_the_site_index_and_only_on_shared_sites(pair, tmp_path):
    ours = _study_rows({0: 90.0, 1: 80.0, 2: 70.0, 3: 60.0, 7: 10.0})
    grid = _grid_csv(tmp_path / 'g.csv', {0: 85.0, 1: 80.0, 2: 75.0, 3: 50.0, 9: 99.0})
    table = pair.paired_with_grid(
        ours, [pair.GridFile('small', 4, grid)], profile='paper', variants=['gas_sound']
    )
    (row,) = table.to_dict('records')
    assert row['pairs'] == 4  # sites 7 and 9 have no partner
    assert row['mean_diff'] == pytest.approx((5.0 + 0.0 - 5.0 + 10.0) / 4)
    assert (row['wins'], row['ties'], row['losses']) == (2, 1, 1)
    assert row['config.robots'] == 4


def test_a_configuration_the_study_did_not_run_is_an_error(pair, tmp_path):
    grid = _grid_csv(tmp_path / 'g.csv', {0: 85.0})
    with pytest.raises(ValueError, match='no paper runs on small with 6 robots'):
        pair.paired_with_grid(
            _study_rows({0: 90.0}),
            [pair.GridFile('small', 6, grid)],
            profile='paper',
            variants=['gas_sound'],
        )


@pytest.mark.parametrize(
    ('text', 'message'),
    [
        ('small_4.csv', 'expected SITE:ROBOTS=FILE'),
        ('huge:4=a.csv', 'site must be one of'),
        ('small:x=a.csv', 'whole number'),
        ('small:4=', 'expected SITE:ROBOTS=FILE'),
    ],
)
def test_malformed_grid_arguments_are_one_line_errors(pair, text, message):
    with pytest.raises(ValueError, match=message):
        pair.parse_grid_argument(text)


def test_a_csv_without_the_grid_columns_names_its_line(pair, tmp_path):
    bad = tmp_path / 'bad.csv'
    bad.write_text('site,variant\n0,gas\n')
    with pytest.raises(ValueError, match=r'bad.csv:2: expected the columns'):
        pair.read_grid(pair.GridFile('small', 4, bad))


def test_the_command_line_turns_bad_input_into_one_line(pair, tmp_path, capsys):
    grid = _grid_csv(tmp_path / 'g.csv', {0: 85.0})
    code = pair.main(['--study', str(tmp_path / 'missing'), '--grid', f'small:4={grid}'])
    err = capsys.readouterr().err.strip()
    assert code == 2
    assert len(err.splitlines()) == 1
    assert err.startswith('pair_oabug_grid: ')
