"""Rows: executing one run into a row, and storing rows as Parquet part files.

Row schema (one row per run; see docs/studies.md):

=================  ==========================================================================
``run_id``         stable id (:func:`~.spec.run_id`)
``study``          study name
``seed``           the run's seed (the site index for site studies)
``config.<axis>``  the run's value of each axis
``param.<name>``   every fixed parameter, nested names joined with ``.``
``metric.<name>``  each scalar the run returned (number, bool or string)
``series.<name>``  each 1-D sequence the run returned, as a list of floats
``status``         ``ok`` or ``failed``
``error``          one line (``Type: message``) for a failed run, else null
``traceback``      the failed run's traceback, else null
``code_version``   ``git describe`` of the code that ran (or the package version)
``blas``           the BLAS libraries and kernels of the process (:func:`~.version.blas_kernels`)
``engine``         ``serial``, ``pool`` or ``dask``
``host`` ``pid``   where it ran
``cpu_s``          CPU seconds of the process during the run
``wall_s``         wall seconds of the run
``started_utc``    when the run started (UTC timestamp)
=================  ==========================================================================

A directory holds one study's rows as ``part-*.parquet`` files, each written to a temporary
name and renamed into place, so a part is either whole or absent. Reading concatenates the
parts (columns missing from one part are null there) and keeps one row per run id: the
``ok`` one if there is one, else the newest.
"""

from __future__ import annotations

import contextlib
import fcntl
import json
import os
import socket
import time
import traceback
import uuid
from collections.abc import Callable, Iterator, Mapping, Sequence
from datetime import UTC, datetime
from pathlib import Path
from typing import Any

import pandas as pd
import pyarrow as pa
import pyarrow.parquet as pq

from .errors import ResultsError, StudyDefinitionError
from .spec import RunSpec, flatten
from .version import blas_kernels

__all__ = [
    'MANIFEST_NAME',
    'VOLATILE_COLUMNS',
    'PartWriter',
    'done_run_ids',
    'execute',
    'read_manifest',
    'read_rows',
    'study_lock',
    'write_manifest',
]

#: Columns that depend on where and when a run executed, not on its spec.
VOLATILE_COLUMNS = (
    'engine',
    'host',
    'pid',
    'cpu_s',
    'wall_s',
    'started_utc',
    'traceback',
    'blas',
)
MANIFEST_NAME = 'study.json'
LOCK_NAME = '.lock'


def _scalar(value: Any) -> Any:
    if hasattr(value, 'item') and callable(value.item) and getattr(value, 'ndim', 0) == 0:
        value = value.item()
    return value


def _split_result(result: Mapping[str, Any]) -> tuple[dict[str, Any], dict[str, list[float]]]:
    """A run's returned mapping as metric and series columns (nested keys dotted)."""
    if not isinstance(result, Mapping):
        raise StudyDefinitionError(
            f'the run function returned {type(result).__name__}, expected a mapping'
        )
    metrics: dict[str, Any] = {}
    series: dict[str, list[float]] = {}
    for key, value in flatten(result).items():
        value = _scalar(value)
        if value is None or isinstance(value, (bool, int, float, str)):
            metrics[f'metric.{key}'] = value
        elif hasattr(value, 'tolist') or isinstance(value, (list, tuple)):
            items = value.tolist() if hasattr(value, 'tolist') else list(value)
            try:
                series[f'series.{key}'] = [float(item) for item in items]
            except (TypeError, ValueError):
                raise StudyDefinitionError(
                    f'the run returned {key!r} with non-numeric items: series must be 1-D '
                    'sequences of numbers'
                ) from None
        else:
            raise StudyDefinitionError(
                f'the run returned {key!r} as {type(value).__name__}: use a number, bool, '
                'string or 1-D sequence of numbers'
            )
    return metrics, series


def _config_columns(spec: RunSpec) -> dict[str, Any]:
    columns: dict[str, Any] = {}
    for key, value in flatten(dict(spec.config)).items():
        top = key.split('.', 1)[0]
        prefix = 'config' if top in spec.axes else 'param'
        columns[f'{prefix}.{key}'] = list(value) if isinstance(value, tuple) else value
    return columns


def execute(
    run: Callable[[RunSpec], Mapping[str, Any]],
    spec: RunSpec,
    code_version: str,
    engine: str,
) -> dict[str, Any]:
    """Run ``spec`` and return its row; an exception in the run gives a ``failed`` row."""
    row: dict[str, Any] = {
        'run_id': spec.run_id,
        'study': spec.study,
        'seed': int(spec.seed),
        **_config_columns(spec),
    }
    started = datetime.now(UTC)
    wall_start = time.perf_counter()
    cpu_start = time.process_time()
    try:
        metrics, series = _split_result(run(spec))
    except Exception as exc:
        row.update(
            status='failed',
            error=f'{type(exc).__name__}: {exc}'.splitlines()[0],
            traceback=traceback.format_exc(),
        )
    else:
        row.update(metrics)
        row.update(series)
        row.update(status='ok', error=None, traceback=None)
    row.update(
        code_version=code_version,
        engine=engine,
        host=socket.gethostname(),
        pid=os.getpid(),
        cpu_s=time.process_time() - cpu_start,
        wall_s=time.perf_counter() - wall_start,
        started_utc=started,
    )
    row['blas'] = blas_kernels()
    return row


def _table(rows: Sequence[Mapping[str, Any]]) -> pa.Table:
    columns: dict[str, None] = {}
    for row in rows:
        columns.update(dict.fromkeys(row))
    data = {}
    for name in columns:
        values = [row.get(name) for row in rows]
        if name.startswith('metric.') and any(isinstance(v, float) for v in values):
            values = [
                float(v) if isinstance(v, int) and not isinstance(v, bool) else v for v in values
            ]
        data[name] = values
    try:
        return pa.Table.from_pydict(data)
    except (pa.ArrowInvalid, pa.ArrowTypeError) as exc:
        raise StudyDefinitionError(f'rows cannot be stored together: {exc}') from exc


class PartWriter:
    """Buffers rows and writes them as Parquet part files (temporary name, then rename)."""

    def __init__(self, directory: Path, *, batch_rows: int = 50, batch_s: float = 30.0) -> None:
        self.directory = Path(directory)
        self.batch_rows = batch_rows
        self.batch_s = batch_s
        self._rows: list[dict[str, Any]] = []
        self._since = time.monotonic()
        self.parts_written = 0
        self.rows_written = 0

    def add(self, row: dict[str, Any]) -> None:
        self._rows.append(row)
        if len(self._rows) >= self.batch_rows or time.monotonic() - self._since >= self.batch_s:
            self.flush()

    def flush(self) -> None:
        if not self._rows:
            self._since = time.monotonic()
            return
        table = _table(self._rows)
        name = f'part-{time.time_ns():020d}-{uuid.uuid4().hex[:8]}.parquet'
        final = self.directory / name
        temporary = self.directory / f'.{name}.tmp'
        pq.write_table(table, temporary)
        with open(temporary, 'rb') as handle:
            os.fsync(handle.fileno())
        os.replace(temporary, final)
        self.parts_written += 1
        self.rows_written += len(self._rows)
        self._rows = []
        self._since = time.monotonic()


def _parts(directory: Path) -> list[Path]:
    return sorted(directory.glob('part-*.parquet'))


#: Columns every stored row has; a part file without them was not written by a study.
REQUIRED_COLUMNS = ('run_id', 'status')


def _read_part(part: Path, columns: list[str] | None = None) -> pa.Table:
    """One part file; a damaged or foreign one is a :class:`ResultsError` that says what to do."""
    try:
        names = pq.read_schema(part).names
        missing = [name for name in REQUIRED_COLUMNS if name not in names]
        if missing:
            raise ResultsError(
                f'{part}: not a part file of a study (no column {" or ".join(missing)}); '
                'move it out of the study directory'
            )
        return pq.read_table(part, columns=columns)
    except (OSError, pa.ArrowInvalid) as exc:
        raise ResultsError(
            f'{part}: unreadable part file ({exc}); move it out of the study directory '
            'and the next run of the study runs its runs again'
        ) from exc


def read_rows(directory: str | os.PathLike[str], *, all_attempts: bool = False) -> pd.DataFrame:
    """The rows stored in a study directory as a DataFrame (one row per run id).

    ``all_attempts`` keeps every stored row, including failed attempts of runs that later
    succeeded.
    """
    directory = Path(directory)
    if not directory.is_dir():
        raise ResultsError(f'{directory}: not a directory')
    tables = []
    for part in _parts(directory):
        tables.append(_read_part(part))
    if not tables:
        return pd.DataFrame(columns=['run_id', 'study', 'seed', 'status'])
    try:
        frame = pa.concat_tables(tables, promote_options='permissive').to_pandas()
    except (pa.ArrowInvalid, pa.ArrowTypeError):
        # Parts disagree on a column's type (a metric returned as text by some runs and as a
        # number by others): such columns become object columns.
        frame = pd.concat([table.to_pandas() for table in tables], ignore_index=True)
    if all_attempts:
        return frame.reset_index(drop=True)
    frame['_ok'] = frame['status'] == 'ok'
    frame['_order'] = range(len(frame))
    frame = frame.sort_values(['_ok', '_order']).drop_duplicates('run_id', keep='last')
    return frame.sort_values('_order').drop(columns=['_ok', '_order']).reset_index(drop=True)


def done_run_ids(directory: Path) -> set[str]:
    """Run ids with an ``ok`` row in ``directory`` (reads only the two columns needed)."""
    done: set[str] = set()
    for part in _parts(directory):
        table = _read_part(part, ['run_id', 'status'])
        for rid, status in zip(
            table.column('run_id').to_pylist(), table.column('status').to_pylist(), strict=True
        ):
            if status == 'ok':
                done.add(rid)
    return done


def write_manifest(directory: Path, manifest: Mapping[str, Any]) -> None:
    """Write ``study.json`` atomically; a study of another name there is an error."""
    path = directory / MANIFEST_NAME
    if path.exists():
        old = read_manifest(directory)
        if old.get('study') != manifest.get('study'):
            raise ResultsError(
                f'{directory} holds study {old.get("study")!r}, not {manifest.get("study")!r}'
            )
    temporary = directory / f'.{MANIFEST_NAME}.tmp'
    temporary.write_text(json.dumps(manifest, indent=2, default=str) + '\n')
    os.replace(temporary, path)


#: The manifest's keys and the JSON types their values must have (others are kept as read).
_MANIFEST_TYPES: dict[str, tuple[type, ...]] = {
    'study': (str,),
    'description': (str,),
    'smoke': (bool,),
    'seed_label': (str,),
    'axes': (dict,),
    'params': (dict,),
    'seeds': (list,),
    'runs': (int,),
    'planned_run_ids': (list,),
    'history': (list,),
}
_JSON_TYPE_NAMES = {str: 'a string', bool: 'true or false', dict: 'an object', list: 'a list'}


def _check_manifest(path: Path, manifest: Any) -> dict[str, Any]:
    """``manifest`` as read from ``path`` if it has the shape :func:`write_manifest` writes.

    Raises:
        ResultsError: not a JSON object, or a known key of the wrong type.
    """
    if not isinstance(manifest, dict):
        raise ResultsError(
            f'{path}: not a study manifest (a JSON object), found {type(manifest).__name__}'
        )
    for key, types in _MANIFEST_TYPES.items():
        value = manifest.get(key)
        if value is None:
            continue
        wrong = not isinstance(value, types) or (types == (int,) and isinstance(value, bool))
        if wrong:
            expected = _JSON_TYPE_NAMES.get(types[0], 'a whole number')
            raise ResultsError(f'{path}: {key!r} must be {expected}, not {value!r}')
    for key in ('seeds', 'planned_run_ids', 'history'):
        items = manifest.get(key) or []
        kind = {'seeds': int, 'planned_run_ids': str, 'history': dict}[key]
        bad = [item for item in items if not isinstance(item, kind) or isinstance(item, bool)]
        if bad:
            raise ResultsError(f'{path}: {key!r} holds {bad[0]!r}, not {kind.__name__} items')
    for axis, values in (manifest.get('axes') or {}).items():
        if not isinstance(values, list):
            raise ResultsError(f'{path}: axis {axis!r} must have a list of values, not {values!r}')
    return manifest


def read_manifest(directory: Path) -> dict[str, Any]:
    """The study manifest (``study.json``) of ``directory``.

    Raises:
        ResultsError: missing, not JSON, or not shaped like a manifest (names the file).
    """
    path = Path(directory) / MANIFEST_NAME
    try:
        manifest = json.loads(path.read_text())
    except FileNotFoundError:
        raise ResultsError(f'{directory}: no {MANIFEST_NAME} (not a study directory)') from None
    except json.JSONDecodeError as exc:
        raise ResultsError(f'{path}: not valid JSON ({exc})') from exc
    except (OSError, UnicodeDecodeError) as exc:
        raise ResultsError(f'{path}: cannot read ({exc})') from exc
    return _check_manifest(path, manifest)


@contextlib.contextmanager
def study_lock(directory: Path) -> Iterator[None]:
    """Hold an exclusive lock on a study directory (released when the process ends)."""
    handle = open(directory / LOCK_NAME, 'a+')  # noqa: SIM115 - held for the block
    try:
        try:
            fcntl.flock(handle.fileno(), fcntl.LOCK_EX | fcntl.LOCK_NB)
        except BlockingIOError:
            raise ResultsError(f'{directory}: another run of this study is writing there') from None
        yield
    finally:
        handle.close()
