#!/usr/bin/env python3
"""Regenerate the docs' results sections from the stored study results in docs/results/.

A docs page embeds a study's exported table between the lines
``<!-- results:STUDY/TABLE begin -->`` and ``<!-- results:STUDY/TABLE end -->``; this script
writes between them the commands that produced the rows, the run count and code version,
and the table, from ``docs/results/STUDY.json`` (a copy of the ``results.json`` that
``swarm_study report`` writes beside each study's report.md).

Usage::

    swarm_study run faults-msc --runs 10 && swarm_study report runs/studies
    python scripts/regenerate_results.py --from runs/studies   # store the studies' results
                                                               # and rewrite the docs
    python scripts/regenerate_results.py                       # rewrite what differs
    python scripts/regenerate_results.py --check               # exit 1 and name what differs

Exit codes: 0 done (or, with --check, nothing differs); 1 --check found a page out of date;
2 a marker without its pair, or a region naming a study or table that docs/results/ lacks.
tests/test_results_docs.py runs the check.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from swarm_experiments.study.docs_results import collect, load_store, markers, update_text
from swarm_experiments.study.errors import ResultsError

REPO = Path(__file__).resolve().parents[1]
STORE = 'docs/results'


def expected_pages(repo: Path = REPO) -> dict[Path, str]:
    """Every docs page with results regions and the text it must have."""
    documents = load_store(repo / STORE)
    pages: dict[Path, str] = {}
    for path in sorted((repo / 'docs').glob('**/*.md')):
        text = path.read_text(encoding='utf-8')
        if not markers(text):
            continue
        relative = path.relative_to(repo).as_posix()
        pages[path] = update_text(text, documents, page=relative, store_label=STORE)
    return pages


def main(argv: list[str] | None = None) -> int:
    """Store results (``--from``), then rewrite (or with ``--check`` compare) the pages."""
    parser = argparse.ArgumentParser(description=__doc__.split('\n\n')[0])
    parser.add_argument('--check', action='store_true', help='only report what differs')
    parser.add_argument(
        '--from',
        dest='sources',
        action='append',
        default=[],
        type=Path,
        metavar='DIR',
        help='first copy the results.json of every study under DIR into docs/results/',
    )
    args = parser.parse_args(argv)
    if args.check and args.sources:
        parser.error('--check compares only; it takes no --from')
    try:
        for source in args.sources:
            for path in collect(source, REPO / STORE):
                print(f'stored {path.relative_to(REPO)}')
        pages = expected_pages()
    except ResultsError as err:
        print(f'regenerate_results: {err}', file=sys.stderr)
        return 2
    stale = [path for path, text in pages.items() if path.read_text(encoding='utf-8') != text]
    for path in stale:
        relative = path.relative_to(REPO)
        if args.check:
            print(f'out of date: {relative} (run python scripts/regenerate_results.py)')
        else:
            path.write_text(pages[path], encoding='utf-8')
            print(f'wrote {relative}')
    return 1 if args.check and stale else 0


if __name__ == '__main__':
    raise SystemExit(main())
