"""Pair the OA-Bug Fig. 4 study's runs with the authors' grid simulator, site by site.

``benchmarks/reference_oabug_grid.py --out FILE`` writes one CSV row per run of the authors'
simulator (site index, variant, departure, coverage); the ``oabug-fig4`` study stores one row
per run with the site index as its seed. Both use the same site indices, so each of our runs
has a grid run on the same site. This script joins them on (variant, departure, site) for
each ``--grid SITE:ROBOTS=FILE`` and prints, per configuration, our coverage minus the
grid's: mean and standard error in points, the sites where ours is above / equal / below,
and the two-sided Wilcoxon signed-rank p (``swarm_experiments.study.paired_differences``).
Example::

    python benchmarks/reference_oabug_grid.py --simulator CHECKOUT --config small --robots 4 \\
        --sites 100 --out small_4.csv
    python benchmarks/pair_oabug_grid.py --study runs/studies/oabug-fig4 \\
        --grid small:4=small_4.csv --variants gas gas_sound
"""

from __future__ import annotations

import csv
import sys
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

import pandas as pd
from swarm_common.cli import ToolParser, run_tool
from swarm_common.errors import UsageError

VARIANTS = ('random', 'minimum', 'sound', 'gas', 'gas_sound')
SITES = ('small', 'medium', 'big')


@dataclass(frozen=True)
class GridFile:
    """One CSV of the authors' simulator: its site configuration and robot count."""

    site: str
    robots: int
    path: Path


def parse_grid_argument(text: str) -> GridFile:
    """``SITE:ROBOTS=FILE`` -> :class:`GridFile` (:class:`UsageError` naming what is wrong)."""
    key, separator, path = text.partition('=')
    site, colon, robots = key.partition(':')
    if not separator or not colon or not path:
        raise UsageError(f'--grid {text!r}: expected SITE:ROBOTS=FILE, e.g. small:4=small_4.csv')
    if site not in SITES:
        raise UsageError(f'--grid {text!r}: site must be one of {", ".join(SITES)}')
    if not robots.isdigit() or int(robots) < 1:
        raise UsageError(f'--grid {text!r}: ROBOTS must be a whole number >= 1')
    return GridFile(site, int(robots), Path(path))


def read_grid(grid: GridFile) -> pd.DataFrame:
    """The grid runs of one file as rows shaped like the study's (``source`` = ``grid``)."""
    with grid.path.open(newline='', encoding='utf-8') as handle:  # OSError: one line
        records = list(csv.DictReader(handle))
    rows = []
    for line, record in enumerate(records, start=2):
        try:
            rows.append(
                {
                    'seed': int(record['site']),
                    'config.variant': record['variant'],
                    'config.departure': record['departure'],
                    'metric.coverage_pct': float(record['coverage_pct']),
                }
            )
        except (KeyError, TypeError, ValueError):
            raise UsageError(
                f'{grid.path}:{line}: expected the columns site, variant, departure and '
                'coverage_pct of reference_oabug_grid.py --out'
            ) from None
    frame = pd.DataFrame(rows)
    frame['config.site'] = grid.site
    frame['config.robots'] = grid.robots
    frame['source'] = 'grid'
    return frame


def paired_with_grid(
    study_rows: pd.DataFrame, grids: Sequence[GridFile], *, profile: str, variants: Sequence[str]
) -> pd.DataFrame:
    """Ours minus the grid per (site, robots, variant, departure) on the shared site indices."""
    from swarm_experiments.study import paired_differences

    ours = study_rows[
        (study_rows['status'] == 'ok')
        & (study_rows['param.profile'] == profile)
        & (study_rows['param.actions'].isna())
        & (study_rows['config.variant'].isin(variants))
    ]
    columns = [
        'seed',
        'config.site',
        'config.robots',
        'config.variant',
        'config.departure',
        'metric.coverage_pct',
    ]
    parts = []
    for grid in grids:
        mine = ours[(ours['config.site'] == grid.site) & (ours['config.robots'] == grid.robots)]
        if mine.empty:
            raise UsageError(
                f'the study has no {profile} runs on {grid.site} with {grid.robots} robots'
            )
        theirs = read_grid(grid)
        parts.append(mine[columns].assign(source='ours'))
        parts.append(theirs[theirs['config.variant'].isin(variants)])
    rows = pd.concat(parts, ignore_index=True)
    return paired_differences(
        rows,
        'metric.coverage_pct',
        by='source',
        baseline='grid',
        group_by=('config.site', 'config.robots', 'config.variant', 'config.departure'),
    )


def main(argv: Sequence[str] | None = None) -> int:
    """Command line entry point; exit codes as every tool's (docs/conventions.md)."""
    return run_tool('pair_oabug_grid', _main, argv)


def _main(argv: list[str]) -> int:
    from swarm_experiments.study import read_rows
    from swarm_experiments.study.report import markdown_table

    parser = ToolParser(prog='pair_oabug_grid', description=__doc__.splitlines()[0])
    parser.add_argument('--study', type=Path, required=True, help='the oabug-fig4 study directory')
    parser.add_argument(
        '--grid',
        action='append',
        required=True,
        metavar='SITE:ROBOTS=FILE',
        help='a CSV of reference_oabug_grid.py --out and its configuration (repeatable)',
    )
    parser.add_argument('--profile', default='paper', help='the robot profile of our runs')
    parser.add_argument('--variants', nargs='+', choices=VARIANTS, default=list(VARIANTS))
    args = parser.parse_args(argv)
    grids = [parse_grid_argument(text) for text in args.grid]
    table = paired_with_grid(
        read_rows(args.study), grids, profile=args.profile, variants=args.variants
    )
    print(f"ours ({args.profile} profile) minus the authors' grid, coverage points:")
    print(markdown_table(table, digits=2))
    return 0


if __name__ == '__main__':
    sys.exit(main())
