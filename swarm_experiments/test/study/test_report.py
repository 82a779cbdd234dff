"""Reports: tables computed from the rows, PNG plots, hooks, paired and reference tables."""

from __future__ import annotations

import json
import math
import warnings
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
from study_fixtures import search_study, synthetic_run
from swarm_experiments.study import (
    ReportPage,
    StudyRegistry,
    UsageError,
    make_engine,
    make_specs,
    paired_differences,
    read_rows,
    reference_table,
    run_study,
    write_reports,
)
from swarm_experiments.study.report import markdown_table, summary_table

PNG = b'\x89PNG\r\n\x1a\n'


def _study_dir(tmp_path: Path, **changes: object) -> Path:
    study = search_study(**changes)
    with make_engine('serial') as engine:
        summary = run_study(make_specs(study), tmp_path, engine, code_version='v')
    return summary.directory


def _table_after(page: str, heading: str) -> list[list[str]]:
    lines = page.split(f'### {heading}\n', 1)[1].strip().splitlines()
    table = []
    for line in lines[2:]:
        if not line.startswith('|'):
            break
        table.append([cell.strip() for cell in line.strip('|').split('|')])
    return table


def test_the_page_tables_mean_std_count_per_configuration(tmp_path: Path) -> None:
    directory = _study_dir(tmp_path)
    (page_path,) = write_reports(tmp_path)
    assert page_path == directory / 'report.md'
    page = page_path.read_text()
    assert '- runs: 36 ok, 0 failed, 0 not run of 36 planned' in page
    rows = read_rows(directory)
    expected = rows.groupby(['config.variant', 'config.robots'])['metric.coverage'].agg(
        ['mean', 'std', 'count']
    )
    table = _table_after(page, 'coverage')
    assert [(r[0], r[1]) for r in table[:4]] == [
        ('gas', '2'),
        ('gas', '4'),
        ('gas', '6'),
        ('sound', '2'),
    ], 'declared axis order'
    for variant, robots, mean, std, count in table:
        row = expected.loc[(variant, int(robots))]
        assert float(mean) == pytest.approx(row['mean'], abs=5e-4)
        assert float(std) == pytest.approx(row['std'], abs=5e-4)
        assert int(count) == row['count'] == 4
    figures = sorted(path.name for path in (directory / 'figures').iterdir())
    assert 'metric-coverage.png' in figures
    assert 'series-coverage_every_10.png' in figures
    for name in figures:
        assert (directory / 'figures' / name).read_bytes().startswith(PNG)
        assert f'(figures/{name})' in page


def test_the_page_names_the_blas_setups_and_warns_when_the_rows_mix_them(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    kernel = ['openblas 0.3.30 Haswell']
    monkeypatch.setattr('swarm_experiments.study.results.blas_kernels', lambda: kernel[0])

    def export(page: ReportPage) -> None:  # results.json holds studies that export a table
        table = summary_table(page.rows, 'metric.coverage', ['config.variant'])
        page.add_table(table, title='coverage', export='coverage')

    study = search_study(report=export)
    with make_engine('serial') as engine:
        run_study(make_specs(study, runs=2), tmp_path, engine, code_version='v')
    page = write_reports(tmp_path)[0].read_text()
    assert '- BLAS: openblas 0.3.30 Haswell\n' in page
    assert 'BLAS setups' not in page
    # The study resumed where OpenBLAS picked another kernel for the CPU.
    kernel[0] = 'openblas 0.3.30 Sandybridge'
    with make_engine('serial') as engine:
        run_study(make_specs(study, runs=3), tmp_path, engine, code_version='v')
    (page_path,) = write_reports(tmp_path, StudyRegistry([study]))
    page = page_path.read_text()
    assert '- BLAS: openblas 0.3.30 Haswell | openblas 0.3.30 Sandybridge\n' in page
    assert '**the rows ran on 2 BLAS setups**' in page
    document = json.loads((page_path.parent / 'results.json').read_text())
    assert document['blas'] == ['openblas 0.3.30 Haswell', 'openblas 0.3.30 Sandybridge']


def test_a_hook_adds_its_own_sections_with_paper_numbers(tmp_path: Path) -> None:
    seen: list[ReportPage] = []

    def hook(page: ReportPage) -> None:
        seen.append(page)
        paper = {'gas': 0.9, 'sound': 0.8, 'random': 0.6}
        table = reference_table(page.rows, 'metric.coverage', paper, by=['config.variant'])
        page.add_table(table, title='Coverage beside the paper')
        import matplotlib.pyplot as plt

        figure, ax = plt.subplots()
        ax.plot([0, 1], [0, 1])
        page.add_figure(figure, 'custom plot')

    study = search_study(report=hook)
    _study_dir(tmp_path, report=hook)
    (page_path,) = write_reports(tmp_path, StudyRegistry([study]))
    page = page_path.read_text()
    assert len(seen) == 1
    assert len(seen[0].rows) == 36
    assert seen[0].axes == ['config.variant', 'config.robots']
    table = _table_after(page, 'Coverage beside the paper')
    assert [row[0] for row in table] == ['gas', 'random', 'sound']
    assert [row[4] for row in table] == ['0.900', '0.600', '0.800']
    assert '(figures/custom_plot.png)' in page


def test_a_failing_hook_is_reported_and_the_page_still_written(tmp_path: Path) -> None:
    def hook(page: ReportPage) -> None:
        raise KeyError('metric.nothing')

    study = search_study(report=hook)
    _study_dir(tmp_path, report=hook)
    errors = []
    (page_path,) = write_reports(
        tmp_path, StudyRegistry([study]), on_hook_error=lambda s, e: errors.append((s, e))
    )
    assert errors[0][0] == 'synthetic-search'
    assert "report hook failed: KeyError: 'metric.nothing'" in page_path.read_text()
    with pytest.raises(KeyError):
        write_reports(tmp_path, StudyRegistry([study]))


def test_reports_need_a_study_directory(tmp_path: Path) -> None:
    with pytest.raises(UsageError, match='no study results here'):
        write_reports(tmp_path)


def _paired_rows() -> pd.DataFrame:
    seeds = np.arange(6)
    base = 10.0 + seeds
    return pd.DataFrame(
        {
            'seed': np.concatenate([seeds] * 3),
            'config.variant': ['a'] * 6 + ['b'] * 6 + ['c'] * 6,
            'metric.t': np.concatenate([base, base + np.array([1, 2, 3, -1, 0, 1]), base]),
        }
    )


def test_paired_differences_pair_by_seed() -> None:
    table = paired_differences(
        _paired_rows(), 'metric.t', by='config.variant', baseline='a'
    ).set_index('config.variant')
    b = table.loc['b']
    assert b['pairs'] == 6
    assert b['mean_diff'] == pytest.approx(1.0)
    diffs = np.array([1, 2, 3, -1, 0, 1], dtype=float)
    assert b['se_diff'] == pytest.approx(diffs.std(ddof=1) / np.sqrt(6))
    assert (b['wins'], b['ties'], b['losses']) == (4, 1, 1)
    from scipy.stats import wilcoxon

    assert b['p_wilcoxon'] == pytest.approx(wilcoxon(diffs).pvalue)
    c = table.loc['c']
    assert (c['mean_diff'], c['ties']) == (0.0, 6)
    assert np.isnan(c['p_wilcoxon'])


def test_paired_differences_refuse_ambiguous_pairs() -> None:
    rows = pd.concat([_paired_rows(), _paired_rows()])
    with pytest.raises(UsageError, match='several runs per'):
        paired_differences(rows, 'metric.t', by='config.variant', baseline='a')


def test_paired_differences_group_by_another_axis() -> None:
    rows = pd.concat(
        [_paired_rows().assign(**{'config.robots': n}) for n in (2, 4)], ignore_index=True
    )
    rows.loc[(rows['config.robots'] == 4) & (rows['config.variant'] == 'b'), 'metric.t'] -= 5
    table = paired_differences(
        rows, 'metric.t', by='config.variant', baseline='a', group_by=['config.robots']
    )
    b = table[table['config.variant'] == 'b'].set_index('config.robots')['mean_diff']
    assert b.to_dict() == pytest.approx({2: 1.0, 4: -4.0})


def test_reference_table_lists_configurations_only_the_reference_has() -> None:
    rows = _paired_rows()
    table = reference_table(rows, 'metric.t', {'a': 12.0, 'z': 1.0}, by=['config.variant'])
    table = table.set_index('config.variant')
    assert table.loc['a', 'ours - paper'] == pytest.approx(12.5 - 12.0)
    assert np.isnan(table.loc['b', 'paper'])
    assert table.loc['z', 'count'] == 0


def test_markdown_tables_align_numbers_and_escape_pipes() -> None:
    frame = pd.DataFrame({'config.name': ['a|b'], 'mean': [0.12345]})
    assert markdown_table(frame) == '| name | mean |\n| --- | ---: |\n| a\\|b | 0.123 |'
    assert summary_table(frame.assign(v=[1.0]), 'v', [])['count'].tolist() == [1]


def _unlimited_range_run(spec):
    # A metric that is infinite in some configurations, as an unlimited radio range is.
    row = dict(synthetic_run(spec))
    row['range_m'] = math.inf if spec.config['variant'] == 'random' else 30.0
    return row


def test_a_configuration_without_a_finite_value_stays_in_the_table_and_out_of_the_plot(
    tmp_path: Path,
) -> None:
    # One robot count: the metric is drawn as bars, one per variant.
    axes = {'variant': ('gas', 'sound', 'random'), 'robots': (6,)}
    directory = _study_dir(tmp_path, axes=axes, run=_unlimited_range_run)
    with warnings.catch_warnings():
        warnings.simplefilter('error', RuntimeWarning)  # matplotlib's, on an infinite bar
        (page_path,) = write_reports(tmp_path)
    assert (directory / 'figures' / 'metric-range_m.png').read_bytes().startswith(PNG)
    table = _table_after(page_path.read_text(), 'range_m')
    assert {row[0] for row in table} == {'gas', 'sound', 'random'}
