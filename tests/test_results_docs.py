"""The docs' results sections match the stored study results they are generated from.

scripts/regenerate_results.py writes each region between ``<!-- results:STUDY/TABLE begin -->``
and ``<!-- results:STUDY/TABLE end -->`` from docs/results/STUDY.json; a hand edit of a region,
or a stored file updated without regenerating, fails here.
"""

from __future__ import annotations

import importlib.util
import json
import re
import sys
from pathlib import Path

import pytest

pytestmark = pytest.mark.runtime_independent(reason='reads result files and docs')

REPO = Path(__file__).resolve().parents[1]


def _script():
    spec = importlib.util.spec_from_file_location(
        'regenerate_results', REPO / 'scripts' / 'regenerate_results.py'
    )
    assert spec is not None
    assert spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    sys.modules.setdefault('regenerate_results', module)
    spec.loader.exec_module(module)
    return module


def test_the_generated_results_sections_are_up_to_date(capsys) -> None:
    assert _script().main(['--check']) == 0, capsys.readouterr().out


def test_every_stored_study_is_shown_with_the_commands_that_made_it() -> None:
    pages = '\n'.join(p.read_text(encoding='utf-8') for p in (REPO / 'docs').glob('**/*.md'))
    stored = sorted((REPO / 'docs' / 'results').glob('*.json'))
    assert stored, 'docs/results holds the stored study results'
    for path in stored:
        document = json.loads(path.read_text(encoding='utf-8'))
        assert f'<!-- results:{path.stem}/' in pages, f'{path.name} is not used by any page'
        assert any(c.startswith('swarm_study run ') for c in document['commands']), path.name
        assert document['commands'][-1].startswith('swarm_study report '), path.name


def test_a_hand_edit_of_a_region_is_caught(tmp_path: Path) -> None:
    script = _script()
    pages = script.expected_pages()
    assert pages, 'some docs page has results regions'
    page, text = next(iter(pages.items()))
    start = text.index('| ---')
    edited = text[:start] + text[start:].replace('|', '| 1 |', 1)
    documents = script.load_store(REPO / script.STORE)
    regenerated = script.update_text(edited, documents, page=str(page), store_label=script.STORE)
    assert regenerated == text


def test_the_studies_page_lists_every_registered_study_with_its_size() -> None:
    from swarm_experiments.study import load_registry, make_specs

    text = (REPO / 'docs' / 'studies.md').read_text(encoding='utf-8')
    section = text.split('## The registered studies', 1)[1].split('\n## ', 1)[0]
    listed: dict[str, int] = {}
    for line in section.splitlines():
        cells = [cell.strip() for cell in line.strip().strip('|').split('|')]
        if len(cells) < 3 or not cells[0].startswith('`'):
            continue
        names = re.findall(r'`([^`]+)`', cells[0])
        sizes = [int(size.replace(',', '')) for size in cells[2].split(', ')]
        assert len(names) == len(sizes), line
        listed.update(zip(names, sizes, strict=True))
    registry = load_registry()
    registered = {study.name: len(make_specs(study).specs) for study in registry}
    assert listed == registered
