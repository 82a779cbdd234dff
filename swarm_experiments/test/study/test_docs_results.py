"""Generated results sections: exported tables, recorded commands, regions rewritten."""

from __future__ import annotations

import json
from pathlib import Path

import pytest
from study_fixtures import search_study, studies
from swarm_experiments.study import ReportPage, ResultsError, StudyRegistry, read_rows
from swarm_experiments.study.cli import main
from swarm_experiments.study.docs_results import collect, load_store, update_text
from swarm_experiments.study.report import summary_table


def _hook(page: ReportPage) -> None:
    table = summary_table(page.rows, 'metric.coverage', ['config.variant'])
    page.add_table(table, title='coverage per variant', export='coverage')


def _registry() -> StudyRegistry:
    return StudyRegistry([search_study(report=_hook), *studies()[1:]])


def _run_and_report(tmp_path: Path) -> Path:
    registry = _registry()
    out = tmp_path / 'runs'
    run = ['run', 'synthetic-search', '--engine', 'serial', '--quiet', '--out', str(out)]
    assert main([*run, '--sites', '2', '--set', 'robots=2,4'], registry=registry) == 0
    assert main([*run, '--sites', '3', '--set', 'robots=2,4'], registry=registry) == 0
    assert main(['report', str(out)], registry=registry) == 0
    return out


def test_report_exports_the_hook_tables_with_the_commands_that_ran(tmp_path: Path) -> None:
    out = _run_and_report(tmp_path)
    document = json.loads((out / 'synthetic-search' / 'results.json').read_text())
    assert document['commands'] == [
        f'swarm_study run synthetic-search --engine serial --quiet --out {out} --sites 2 '
        '--set robots=2,4',
        f'swarm_study run synthetic-search --engine serial --quiet --out {out} --sites 3 '
        '--set robots=2,4',
        f'swarm_study report {out}',
    ]
    rows = read_rows(out / 'synthetic-search')
    assert document['runs_ok'] == len(rows) == 3 * 3 * 2
    table = document['tables']['coverage']
    assert table['columns'] == ['variant', 'mean', 'std', 'count']
    means = rows.groupby('config.variant')['metric.coverage'].mean()
    for variant, mean, _std, count in table['rows']:
        assert float(mean) == pytest.approx(means[variant], abs=5e-4)
        assert count == '6'


def test_a_region_is_rewritten_from_the_store_and_check_sees_stale_text(
    tmp_path: Path,
) -> None:
    out = _run_and_report(tmp_path)
    store = tmp_path / 'store'
    (written,) = collect(out, store)
    assert written == store / 'synthetic-search.json'
    documents = load_store(store)
    page = (
        'Intro.\n\n<!-- results:synthetic-search/coverage begin -->\nhand-written, old\n'
        '<!-- results:synthetic-search/coverage end -->\n\nAfter.\n'
    )
    new = update_text(page, documents, page='p.md', store_label='store')
    assert 'hand-written' not in new
    assert new.startswith('Intro.\n\n<!-- results:synthetic-search/coverage begin -->\n')
    assert new.endswith('<!-- results:synthetic-search/coverage end -->\n\nAfter.\n')
    assert f'swarm_study report {out}\n```' in new
    assert '| variant | mean | std | count |' in new
    assert 'from store/synthetic-search.json' in new
    (setup,) = read_rows(out / 'synthetic-search')['blas'].unique()
    assert f'; BLAS {setup}._' in new
    # Regenerating the generated text changes nothing; new rows change it.
    assert update_text(new, documents, page='p.md', store_label='store') == new
    documents['synthetic-search']['tables']['coverage']['rows'][0][1] = '0.000'
    assert update_text(new, documents, page='p.md', store_label='store') != new
    # Results stored before the rows recorded their BLAS name none.
    del documents['synthetic-search']['blas']
    assert 'BLAS' not in update_text(new, documents, page='p.md', store_label='store')


def test_markers_inside_code_blocks_are_examples_not_regions() -> None:
    page = (
        '```markdown\n<!-- results:synthetic-search/coverage begin -->\n'
        '<!-- results:synthetic-search/coverage end -->\n```\n'
    )
    assert update_text(page, {}, page='p.md', store_label='store') == page


@pytest.mark.parametrize(
    ('page', 'message'),
    [
        ('<!-- results:synthetic-search/coverage begin -->\n', 'p.md:1: .* has no end marker'),
        ('x\n<!-- results:synthetic-search/coverage end -->\n', 'p.md:2: .* without its begin'),
        (
            '<!-- results:other-study/coverage begin -->\n'
            '<!-- results:other-study/coverage end -->',
            "no stored results of study 'other-study'",
        ),
        (
            '<!-- results:synthetic-search/nope begin -->\n'
            '<!-- results:synthetic-search/nope end -->',
            "no table 'nope' \\(exported: coverage\\)",
        ),
        (
            '<!-- results:synthetic-search/coverage begin -->\n'
            '<!-- results:synthetic-search/other begin -->\n',
            'begins inside',
        ),
    ],
)
def test_bad_regions_are_precise_errors(page: str, message: str) -> None:
    documents = {
        'synthetic-search': {
            'study': 'synthetic-search',
            'commands': [],
            'tables': {'coverage': {'title': '', 'columns': ['a'], 'numeric': [0], 'rows': []}},
        }
    }
    with pytest.raises(ResultsError, match=message):
        update_text(page, documents, page='p.md', store_label='store')


def test_export_keys_are_checked(tmp_path: Path) -> None:
    def hook(page: ReportPage) -> None:
        table = summary_table(page.rows, 'metric.coverage', ['config.variant'])
        page.add_table(table, export='same')
        page.add_table(table, export='same')

    registry = StudyRegistry([search_study(report=hook)])
    out = tmp_path / 'runs'
    argv = ['run', 'synthetic-search', '--smoke', '--engine', 'serial', '--quiet']
    assert main([*argv, '--out', str(out)], registry=registry) == 0
    assert main(['report', str(out)], registry=registry) == 0  # the hook error is reported
    assert not (out / 'synthetic-search-smoke' / 'results.json').exists()
    assert 'two tables exported' in (out / 'synthetic-search-smoke' / 'report.md').read_text()
