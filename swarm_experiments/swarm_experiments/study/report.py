"""Reports from stored rows: a markdown page per study with tables and PNG plots.

The generic page has the run counts, failures, and per metric a table of mean, standard
deviation and count per configuration with a plot; per time series the mean curve per
configuration. A study's ``report`` hook then adds its own sections through the
:class:`ReportPage` it is given, e.g. its paper's numbers beside ours
(:func:`reference_table`) and paired comparisons (:func:`paired_differences`).
"""

from __future__ import annotations

import json
import math
import os
import re
import sys
from collections.abc import Callable, Mapping, Sequence
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np
import pandas as pd

from .errors import ResultsError, UsageError
from .results import MANIFEST_NAME, read_manifest, read_rows

if TYPE_CHECKING:
    from matplotlib.figure import Figure

    from .definition import StudyRegistry

__all__ = [
    'ReportPage',
    'blas_setups',
    'markdown_table',
    'paired_differences',
    'reference_table',
    'render_cells',
    'results_document',
    'study_directories',
    'summary_table',
    'table_cells',
    'write_reports',
]

#: Most lines (configurations) one plot draws; more are left to the tables.
MAX_LINES = 12
MAX_BARS = 40
#: The exported tables of a study, beside its report.md.
RESULTS_NAME = 'results.json'


def blas_setups(rows: pd.DataFrame) -> list[str]:
    """The distinct ``blas`` values of the rows, sorted (rows from before the column: none)."""
    if 'blas' not in rows:
        return []
    return sorted(str(value) for value in rows['blas'].dropna().unique())


def _short(column: str) -> str:
    for prefix in ('config.', 'metric.', 'series.', 'param.'):
        if column.startswith(prefix):
            return column[len(prefix) :]
    return column


def _format(value: Any, digits: int) -> str:
    if value is None:
        return ''
    if isinstance(value, (float, np.floating)):
        if math.isnan(value):
            return ''
        magnitude = abs(float(value))
        if value != 0 and (magnitude >= 10**6 or magnitude < 10.0 ** (-digits)):
            return f'{value:.{digits}g}'
        return f'{value:.{digits}f}'
    if isinstance(value, (list, tuple, np.ndarray)):
        return '[' + ', '.join(_format(item, digits) for item in value) + ']'
    return str(value).replace('|', '\\|').replace('\n', ' ')


def table_cells(frame: pd.DataFrame, *, digits: int = 3) -> dict[str, Any]:
    """``frame`` as the plain data of a table: column names, which columns are numeric, and
    every cell as the text the markdown table shows (index dropped)."""
    return {
        'columns': [_short(str(name)) for name in frame.columns],
        'numeric': [bool(pd.api.types.is_numeric_dtype(frame[name])) for name in frame.columns],
        'rows': [
            [_format(value, digits) for value in row] for row in frame.itertuples(index=False)
        ],
    }


def render_cells(cells: Mapping[str, Any]) -> str:
    """The GitHub markdown table of :func:`table_cells` data (numbers right-aligned)."""
    if not cells['rows']:
        return '_no rows_'
    lines = [
        '| ' + ' | '.join(cells['columns']) + ' |',
        '| ' + ' | '.join('---:' if flag else '---' for flag in cells['numeric']) + ' |',
    ]
    lines.extend('| ' + ' | '.join(row) + ' |' for row in cells['rows'])
    return '\n'.join(lines)


def markdown_table(frame: pd.DataFrame, *, digits: int = 3) -> str:
    """``frame`` as a GitHub markdown table (index dropped; numbers right-aligned)."""
    if frame.empty:
        return '_no rows_'
    return render_cells(table_cells(frame, digits=digits))


def _axes_columns(rows: pd.DataFrame, axes: Sequence[str]) -> list[str]:
    return [f'config.{axis}' for axis in axes if f'config.{axis}' in rows.columns]


def _numeric_metrics(rows: pd.DataFrame) -> list[str]:
    names = []
    for column in rows.columns:
        if column.startswith('metric.') and (
            pd.api.types.is_numeric_dtype(rows[column]) or pd.api.types.is_bool_dtype(rows[column])
        ):
            names.append(column)
    return names


def summary_table(
    rows: pd.DataFrame,
    metric: str,
    by: Sequence[str],
    *,
    order: Mapping[str, Sequence[Any]] | None = None,
) -> pd.DataFrame:
    """Mean, standard deviation (n - 1) and count of ``metric`` per combination of ``by``.

    Rows come sorted by ``by``, each column in the order of its values in ``order`` when
    given (e.g. the study's declared axis values), else by value.
    """
    values = rows[metric].astype(float)
    if not by:
        return pd.DataFrame(
            {'mean': [values.mean()], 'std': [values.std()], 'count': [int(values.count())]}
        )
    grouped = rows.assign(_value=values).groupby(list(by), sort=True, dropna=False)['_value']
    table = grouped.agg(['mean', 'std', 'count']).reset_index()
    table['count'] = table['count'].astype(int)
    if order:
        ranks = {
            column: {repr(_plain(v)): i for i, v in enumerate(order[column])}
            for column in by
            if column in order
        }
        if ranks:
            keys = [
                table[column].map(lambda v, r=rank: r.get(repr(_plain(v)), len(r)))
                for column, rank in ranks.items()
            ]
            table = (
                table.assign(**{f'_rank{i}': key for i, key in enumerate(keys)})
                .sort_values([f'_rank{i}' for i in range(len(keys))], kind='stable')
                .drop(columns=[f'_rank{i}' for i in range(len(keys))])
                .reset_index(drop=True)
            )
    return table


def _plain(value: Any) -> Any:
    if hasattr(value, 'tolist'):
        value = value.tolist()
    if isinstance(value, (list, tuple)):
        return tuple(_plain(item) for item in value)
    return value


def reference_table(
    rows: pd.DataFrame,
    metric: str,
    reference: Mapping[Any, float],
    *,
    by: Sequence[str],
    label: str = 'paper',
) -> pd.DataFrame:
    """Our mean, std and count of ``metric`` per configuration beside reference numbers.

    ``reference`` maps a configuration (a tuple of values in ``by`` order, or one value when
    ``by`` has one column) to the reference's figure; configurations we have but the
    reference lacks get an empty cell, and those the reference has but we lack a row with
    count 0.
    """
    ours = summary_table(rows, metric, by)
    ours['_key'] = [
        tuple(row) if len(by) > 1 else row[0] for row in ours[list(by)].itertuples(index=False)
    ]
    extra = [key for key in reference if key not in set(ours['_key'])]
    if extra:
        additions = pd.DataFrame(
            [
                dict(zip(by, key if len(by) > 1 else (key,), strict=True))
                | {'mean': np.nan, 'std': np.nan, 'count': 0, '_key': key}
                for key in extra
            ]
        )
        ours = pd.concat([ours, additions], ignore_index=True)
    ours[label] = [reference.get(key, np.nan) for key in ours['_key']]
    ours[f'ours - {label}'] = ours['mean'] - ours[label]
    return ours.drop(columns=['_key'])


def paired_differences(
    rows: pd.DataFrame,
    metric: str,
    *,
    by: str,
    baseline: Any,
    pair_on: Sequence[str] = ('seed',),
    group_by: Sequence[str] = (),
) -> pd.DataFrame:
    """Paired differences ``metric(other) - metric(baseline)`` for each other value of ``by``.

    Runs pair when they agree on every column of ``pair_on`` (the seed, i.e. the site, and
    any axes to hold equal) and of ``group_by`` (one output row per combination). Columns:
    ``by`` (the compared value), the ``group_by`` columns, ``pairs``, ``mean_diff``,
    ``se_diff`` (standard error), ``wins`` / ``ties`` / ``losses`` (other above, equal to,
    below the baseline) and ``p_wilcoxon`` (two-sided signed-rank test; empty with fewer
    than 2 non-zero differences).
    """
    from scipy.stats import wilcoxon

    for column in (metric, by, *pair_on, *group_by):
        if column not in rows.columns:
            raise UsageError(f'paired_differences: no column {column!r}')
    keys = [*group_by, *pair_on]
    if rows.duplicated([*keys, by]).any():
        raise UsageError(
            f'paired_differences: several runs per {", ".join([*keys, by])}; '
            'add the axes that tell them apart to pair_on or group_by'
        )
    base = rows[rows[by] == baseline][[*keys, metric]].rename(columns={metric: '_base'})
    records = []
    others = [value for value in pd.unique(rows[by]) if value != baseline]
    for other in others:
        mine = rows[rows[by] == other][[*keys, metric]]
        paired = mine.merge(base, on=keys, how='inner')
        groups = paired.groupby(list(group_by), sort=True) if group_by else [((), paired)]
        for group_key, group in groups:
            diff = (group[metric].astype(float) - group['_base'].astype(float)).to_numpy()
            record = {by: other}
            group_values = group_key if isinstance(group_key, tuple) else (group_key,)
            record.update(dict(zip(group_by, group_values, strict=True)))
            n = len(diff)
            nonzero = int(np.count_nonzero(diff))
            p_value = np.nan
            if nonzero >= 2:
                p_value = float(wilcoxon(diff, zero_method='wilcox').pvalue)
            record.update(
                pairs=n,
                mean_diff=float(diff.mean()) if n else np.nan,
                se_diff=float(diff.std(ddof=1) / math.sqrt(n)) if n > 1 else np.nan,
                wins=int((diff > 0).sum()),
                ties=int((diff == 0).sum()),
                losses=int((diff < 0).sum()),
                p_wilcoxon=p_value,
            )
            records.append(record)
    columns = [by, *group_by, 'pairs', 'mean_diff', 'se_diff', 'wins', 'ties', 'losses']
    return pd.DataFrame(records, columns=[*columns, 'p_wilcoxon'])


def _slug(text: str) -> str:
    return re.sub(r'[^A-Za-z0-9_.-]+', '_', text).strip('_') or 'plot'


class ReportPage:
    """The markdown page of one study being written; hooks add sections to it.

    ``rows`` holds the ``ok`` rows, ``all_rows`` the failed ones too; ``axes`` the axis
    columns (``config.<axis>``), ``metrics`` and ``series`` the numeric metric and series
    columns present.
    """

    def __init__(
        self,
        directory: Path,
        manifest: Mapping[str, Any],
        all_rows: pd.DataFrame,
    ) -> None:
        self.directory = directory
        self.manifest = dict(manifest)
        self.all_rows = all_rows
        if 'status' in all_rows.columns:
            self.rows = all_rows[all_rows['status'] == 'ok'].reset_index(drop=True)
        else:
            self.rows = all_rows
        declared = dict(self.manifest.get('axes', {}))
        self.axes = _axes_columns(self.rows, list(declared))
        #: Declared values of each axis column, in the study's order.
        self.axis_order = {f'config.{axis}': list(values) for axis, values in declared.items()}
        self.metrics = _numeric_metrics(self.rows)
        self.series = [column for column in self.rows.columns if column.startswith('series.')]
        self.figure_dir = directory / 'figures'
        self._blocks: list[str] = []
        self._figures: list[Path] = []
        #: Tables marked for the docs (``add_table(..., export=KEY)``): KEY -> title and cells.
        self.exports: dict[str, dict[str, Any]] = {}

    @property
    def study(self) -> str:
        return str(self.manifest.get('study', self.directory.name))

    def add_heading(self, text: str, level: int = 2) -> None:
        self._blocks.append(f'{"#" * level} {text}')

    def add_text(self, text: str) -> None:
        self._blocks.append(text.strip())

    def add_table(
        self,
        frame: pd.DataFrame,
        *,
        title: str | None = None,
        digits: int = 3,
        export: str | None = None,
    ) -> None:
        """Add a table; with ``export`` it is also written to ``results.json`` under that key,
        for the docs' generated results sections (scripts/regenerate_results.py)."""
        if title:
            self.add_heading(title, 3)
        self._blocks.append(markdown_table(frame, digits=digits))
        if export is not None:
            if not re.fullmatch(r'[a-z0-9][a-z0-9_-]*', export):
                raise UsageError(f'export key {export!r}: use lower-case letters, digits, - and _')
            if export in self.exports:
                raise UsageError(f'{self.study}: two tables exported as {export!r}')
            self.exports[export] = {'title': title or '', **table_cells(frame, digits=digits)}

    def add_figure(self, figure: Figure, name: str, *, caption: str = '') -> Path:
        """Save ``figure`` as PNG beside the page, link it, and close it if pyplot made it."""
        self.figure_dir.mkdir(parents=True, exist_ok=True)
        path = self.figure_dir / f'{_slug(name)}.png'
        figure.savefig(path, dpi=110, bbox_inches='tight')
        if 'matplotlib.pyplot' in sys.modules:
            sys.modules['matplotlib.pyplot'].close(figure)
        self._figures.append(path)
        self._blocks.append(f'![{caption or name}](figures/{path.name})')
        return path

    def markdown(self) -> str:
        return '\n\n'.join(self._blocks) + '\n'

    @property
    def figures(self) -> list[Path]:
        return list(self._figures)


def _figure() -> tuple[Figure, Any]:
    from matplotlib.figure import Figure  # no pyplot: works without a display

    figure = Figure(figsize=(6.4, 4.0))
    return figure, figure.add_subplot()


def _label(columns: Sequence[str], values: Any) -> str:
    values = values if isinstance(values, tuple) else (values,)
    return ', '.join(f'{_short(c)}={v}' for c, v in zip(columns, values, strict=True))


def _metric_plot(page: ReportPage, metric: str, table: pd.DataFrame) -> None:
    # A configuration without a value (e.g. tau when no run found the source) stays in the
    # table and out of the plot.
    table = table[np.isfinite(table['mean'].to_numpy(dtype=float))]
    if table.empty:
        return
    axes = page.axes
    numeric_axes = [
        axis
        for axis in axes
        if pd.api.types.is_numeric_dtype(table[axis]) and table[axis].nunique() > 1
    ]
    figure, ax = _figure()
    if numeric_axes:
        x_axis = numeric_axes[0]
        others = [axis for axis in axes if axis != x_axis]
        groups = list(table.groupby(others, sort=False)) if others else [((), table)]
        if len(groups) > MAX_LINES:
            return
        for key, group in groups:
            group = group.sort_values(x_axis)
            ax.errorbar(
                group[x_axis],
                group['mean'],
                yerr=group['std'].fillna(0.0),
                marker='o',
                capsize=3,
                label=_label(others, key) if others else None,
            )
        ax.set_xlabel(_short(x_axis))
        if others:
            ax.legend(fontsize='small')
    else:
        if len(table) > MAX_BARS:
            return
        labels = (
            [_label(axes, tuple(row)) for row in table[axes].itertuples(index=False)]
            if axes
            else ['all']
        )
        ax.bar(range(len(table)), table['mean'], yerr=table['std'].fillna(0.0), capsize=3)
        ax.set_xticks(range(len(table)), labels, rotation=30, ha='right', fontsize='small')
    ax.set_ylabel(_short(metric))
    ax.set_title(f'{page.study}: {_short(metric)} (mean ± std)')
    page.add_figure(figure, f'metric-{_short(metric)}', caption=_short(metric))


def _series_plot(page: ReportPage, column: str) -> None:
    rows = page.rows[page.rows[column].notna()]
    if rows.empty:
        return
    groups = list(rows.groupby(page.axes, sort=True)) if page.axes else [((), rows)]
    if len(groups) > MAX_LINES:
        return
    figure, ax = _figure()
    for key, group in groups:
        curves = [np.asarray(values, dtype=float) for values in group[column]]
        length = max(len(curve) for curve in curves)
        padded = np.full((len(curves), length), np.nan)
        for index, curve in enumerate(curves):
            padded[index, : len(curve)] = curve
        with np.errstate(all='ignore'):
            mean = np.nanmean(padded, axis=0)
        ax.plot(np.arange(length), mean, label=_label(page.axes, key) if page.axes else None)
    ax.set_xlabel('sample')
    ax.set_ylabel(_short(column))
    ax.set_title(f'{page.study}: {_short(column)} (mean over runs)')
    if page.axes:
        ax.legend(fontsize='small')
    page.add_figure(figure, f'series-{_short(column)}', caption=_short(column))


def _generic_sections(page: ReportPage) -> None:
    manifest = page.manifest
    all_rows = page.all_rows
    ok = len(page.rows)
    failed = int((all_rows['status'] != 'ok').sum()) if 'status' in all_rows else 0
    # A directory from before manifests kept every call's plan may hold more runs.
    planned = max(int(manifest.get('runs', 0)), ok + failed)
    page.add_heading(f'Study {page.study}' + (' (smoke)' if manifest.get('smoke') else ''), 1)
    if manifest.get('description'):
        page.add_text(str(manifest['description']))
    lines = [
        f'- runs: {ok} ok, {failed} failed, {max(planned - ok - failed, 0)} not run '
        f'of {planned} planned',
    ]
    if ok:
        lines.append(
            f'- CPU time of the ok runs: {page.rows["cpu_s"].sum():.1f} s '
            f'(mean {page.rows["cpu_s"].mean():.3f} s per run)'
        )
        for column, label in (
            ('code_version', 'code versions'),
            ('engine', 'engines'),
            ('host', 'hosts'),
        ):
            if column in page.rows:
                values = sorted(str(v) for v in page.rows[column].dropna().unique())
                lines.append(f'- {label}: {", ".join(values)}')
        setups = blas_setups(page.rows)
        if setups:
            lines.append(f'- BLAS: {" | ".join(setups)}')
        if len(setups) > 1:
            lines.append(
                f'- **the rows ran on {len(setups)} BLAS setups**: another kernel rounds '
                'the last bits of linear algebra differently, and a run that hinges on a '
                'close decision (a Gaussian-process planner) can come out otherwise; give '
                'every worker the same kernel (OPENBLAS_CORETYPE) for rows that must agree'
            )
    axes = manifest.get('axes', {})
    if axes:
        lines.append('- axes: ' + '; '.join(f'{k} = {v}' for k, v in axes.items()))
    seeds = manifest.get('seeds', [])
    if seeds:
        label = manifest.get('seed_label', 'seed')
        lines.append(f'- {label}s: {len(seeds)} ({seeds[0]}..{seeds[-1]})')
    page.add_text('\n'.join(lines))
    if failed:
        failures = all_rows[all_rows['status'] != 'ok']
        columns = ['run_id', *page.axes, 'seed', 'error']
        columns = [column for column in columns if column in failures.columns]
        page.add_table(failures[columns].head(20), title='Failed runs (first 20)')
    if not ok:
        return
    page.add_heading('Metrics per configuration')
    for metric in page.metrics:
        table = summary_table(page.rows, metric, page.axes, order=page.axis_order)
        page.add_table(table, title=_short(metric))
        _metric_plot(page, metric, table)
    if page.series:
        page.add_heading('Time series')
        for column in page.series:
            _series_plot(page, column)


def study_directories(directory: Path) -> list[Path]:
    """``directory`` itself if it is a study directory, else its study subdirectories."""
    directory = Path(directory)
    if not directory.is_dir():
        raise UsageError(f'{directory}: no such directory')
    if (directory / MANIFEST_NAME).is_file():
        return [directory]
    found = sorted(path.parent for path in directory.glob(f'*/{MANIFEST_NAME}'))
    if not found:
        raise UsageError(f'{directory}: no study results here (no */{MANIFEST_NAME})')
    return found


def write_reports(
    directory: str | os.PathLike[str],
    registry: StudyRegistry | None = None,
    *,
    on_hook_error: Callable[[str, Exception], None] | None = None,
    report_command: str | None = None,
) -> list[Path]:
    """Write ``report.md`` (and ``figures/*.png``) in each study directory under ``directory``.

    A study found in ``registry`` adds its ``report`` hook's sections. A hook that raises is
    reported through ``on_hook_error`` (and the page notes it) when given, else re-raised.
    When the page exports tables, ``results.json`` beside it holds them with the commands
    that made them (:func:`results_document`; ``report_command`` is this report's command);
    a page whose hook failed exports nothing (an older ``results.json`` is removed).
    Returns the pages written.
    """
    pages = []
    for study_dir in study_directories(Path(directory)):
        manifest = read_manifest(study_dir)
        rows = read_rows(study_dir)
        page = ReportPage(study_dir, manifest, rows)
        _generic_sections(page)
        study = registry.find(page.study) if registry is not None else None
        hook_failed = False
        if study is not None and study.report is not None and len(page.rows):
            try:
                study.report(page)
            except Exception as exc:
                if on_hook_error is None:
                    raise
                on_hook_error(page.study, exc)
                hook_failed = True
                page.add_text(f"_The study's report hook failed: {type(exc).__name__}: {exc}_")
        path = study_dir / 'report.md'
        try:
            path.write_text(page.markdown())
            results = study_dir / RESULTS_NAME
            if page.exports and not hook_failed:
                document = results_document(page, report_command)
                text = json.dumps(document, indent=1, ensure_ascii=False) + '\n'
                temporary = results.with_name(results.name + '.tmp')
                temporary.write_text(text, encoding='utf-8')
                temporary.replace(results)
            elif results.exists():
                results.unlink()
        except OSError as exc:
            raise ResultsError(f'{path}: cannot write ({exc})') from exc
        pages.append(path)
    return pages


def results_document(page: ReportPage, report_command: str | None = None) -> dict[str, Any]:
    """The data of ``results.json``: the page's exported tables and where they came from.

    ``commands`` lists the distinct ``swarm_study run`` command lines of the study's history
    in the order first given (calls made without a recorded command are left out), then
    ``report_command``.
    """
    commands: list[str] = []
    for call in page.manifest.get('history', []):
        command = call.get('command')
        if command and command not in commands:
            commands.append(command)
    if report_command:
        commands.append(report_command)
    rows = page.rows
    versions = sorted(str(v) for v in rows['code_version'].dropna().unique()) if len(rows) else []
    return {
        'study': page.study,
        'smoke': bool(page.manifest.get('smoke', False)),
        'commands': commands,
        'runs_ok': len(rows),
        'runs_failed': len(page.all_rows) - len(rows),
        'cpu_s': round(float(rows['cpu_s'].sum()), 1) if 'cpu_s' in rows else None,
        'code_versions': versions,
        'blas': blas_setups(rows),
        'tables': page.exports,
    }
