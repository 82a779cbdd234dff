"""A run becomes one row; rows are stored as whole Parquet parts and read back."""

from __future__ import annotations

import os
import platform
import subprocess
import sys
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
from study_fixtures import search_study
from swarm_experiments.study import (
    VOLATILE_COLUMNS,
    ResultsError,
    RunSpec,
    make_specs,
    read_rows,
)
from swarm_experiments.study.results import (
    PartWriter,
    done_run_ids,
    execute,
    read_manifest,
    study_lock,
)
from swarm_experiments.study.version import blas_kernels


def _spec(**config_changes: object) -> RunSpec:
    spec = make_specs(search_study(), runs=1).specs[0]
    if not config_changes:
        return spec
    return RunSpec(spec.study, {**spec.config, **config_changes}, spec.seed, 'x', spec.axes)


def test_a_row_has_the_config_params_metrics_series_and_bookkeeping() -> None:
    spec = _spec()
    row = execute(search_study().run, spec, 'v1', 'serial')
    assert row['run_id'] == spec.run_id
    assert row['study'] == 'synthetic-search'
    assert row['seed'] == 0
    assert row['config.variant'] == 'gas'
    assert row['config.robots'] == 2
    assert row['param.sim.steps'] == 60
    assert row['param.fail_seeds'] == []
    assert isinstance(row['metric.coverage'], float)
    assert row['metric.found'] is False
    assert row['metric.actions'] == 120
    assert row['metric.first_90_step'] is None
    assert row['metric.energy.total_j'] > 0
    assert len(row['series.coverage_every_10']) == 6
    assert all(isinstance(v, float) for v in row['series.coverage_every_10'])
    assert row['status'] == 'ok'
    assert row['error'] is None
    assert row['code_version'] == 'v1'
    assert row['engine'] == 'serial'
    assert row['pid'] == os.getpid()
    assert row['cpu_s'] >= 0
    assert row['wall_s'] >= 0


def test_a_row_records_the_blas_kernels_of_its_process_as_a_volatile_column() -> None:
    row = execute(search_study().run, _spec(), 'v1', 'serial')
    assert row['blas'] == blas_kernels()
    assert row['blas'] != 'unknown', 'numpy links a BLAS'
    assert 'blas' in VOLATILE_COLUMNS


def _kernels_in_a_process(environment: dict[str, str]) -> str:
    code = 'from swarm_experiments.study.version import blas_kernels; print(blas_kernels())'
    return subprocess.run(
        [sys.executable, '-c', code],
        env={**os.environ, **environment},
        capture_output=True,
        text=True,
        check=True,
        timeout=120,
    ).stdout.strip()


def test_the_blas_column_names_the_kernel_openblas_was_made_to_use() -> None:
    if 'openblas' not in blas_kernels() or platform.machine() != 'x86_64':
        pytest.skip('needs the dynamic-architecture OpenBLAS of the x86-64 numpy wheels')
    forced = _kernels_in_a_process({'OPENBLAS_CORETYPE': 'Nehalem'})
    entries = forced.split('; ')
    assert all(entry.startswith('openblas ') for entry in entries), forced
    assert all(entry.endswith(' Nehalem') for entry in entries), forced


def test_an_exception_in_the_run_gives_a_failed_row_with_one_line() -> None:
    spec = _spec(fail_seeds=[0])
    row = execute(search_study().run, spec, 'v1', 'serial')
    assert row['status'] == 'failed'
    assert row['error'] == 'ValueError: seed 0 fails on purpose'
    assert 'Traceback' in row['traceback']
    assert 'metric.coverage' not in row


@pytest.mark.parametrize(
    ('returned', 'message'),
    [
        ([1, 2], 'returned list, expected a mapping'),
        ({'grid': np.zeros((2, 2))}, 'non-numeric items'),
        ({'what': object()}, "returned 'what' as object"),
    ],
)
def test_a_run_returning_something_unstorable_fails_with_the_reason(
    returned: object, message: str
) -> None:
    row = execute(lambda spec: returned, _spec(), 'v1', 'serial')
    assert row['status'] == 'failed'
    assert message in row['error']


def test_numpy_scalars_and_arrays_become_plain_values() -> None:
    row = execute(
        lambda spec: {'a': np.float32(0.5), 'b': np.int64(3), 'c': np.arange(3)},
        _spec(),
        'v',
        'serial',
    )
    assert row['metric.a'] == 0.5
    assert type(row['metric.a']) is float
    assert row['metric.b'] == 3
    assert type(row['metric.b']) is int
    assert row['series.c'] == [0.0, 1.0, 2.0]


def test_parts_are_written_whole_and_read_back_with_mixed_columns(tmp_path: Path) -> None:
    writer = PartWriter(tmp_path, batch_rows=2, batch_s=1e9)
    base = {'study': 's', 'seed': 0, 'status': 'ok'}
    writer.add({**base, 'run_id': 'a', 'metric.m': 1, 'series.s': [1.0, 2.0]})
    assert not list(tmp_path.iterdir()), 'nothing written before the batch is full'
    writer.add({**base, 'run_id': 'b', 'metric.m': 2.5, 'series.s': [3.0]})
    writer.add({**base, 'run_id': 'c', 'metric.other': 'x'})
    writer.flush()
    assert writer.parts_written == 2
    assert writer.rows_written == 3
    names = sorted(path.name for path in tmp_path.iterdir())
    assert all(name.startswith('part-') and name.endswith('.parquet') for name in names)
    rows = read_rows(tmp_path).set_index('run_id')
    assert rows.loc['a', 'metric.m'] == 1.0
    assert rows.loc['b', 'metric.m'] == 2.5
    assert pd.isna(rows.loc['c', 'metric.m'])
    assert rows.loc['c', 'metric.other'] == 'x'
    assert list(rows.loc['a', 'series.s']) == [1.0, 2.0]
    assert done_run_ids(tmp_path) == {'a', 'b', 'c'}


def test_reading_keeps_the_ok_row_of_a_run_that_failed_before(tmp_path: Path) -> None:
    writer = PartWriter(tmp_path, batch_rows=1)
    base = {'study': 's', 'seed': 0}
    writer.add({**base, 'run_id': 'a', 'status': 'failed', 'error': 'boom'})
    writer.add({**base, 'run_id': 'a', 'status': 'ok', 'metric.m': 1.0})
    writer.add({**base, 'run_id': 'b', 'status': 'ok', 'metric.m': 2.0})
    writer.add({**base, 'run_id': 'b', 'status': 'failed', 'error': 'later'})
    writer.add({**base, 'run_id': 'c', 'status': 'failed', 'error': 'first'})
    writer.add({**base, 'run_id': 'c', 'status': 'failed', 'error': 'second'})
    rows = read_rows(tmp_path).set_index('run_id')
    assert rows.loc['a', 'status'] == 'ok'
    assert rows.loc['b', 'status'] == 'ok'
    assert rows.loc['c', 'error'] == 'second'
    assert len(read_rows(tmp_path, all_attempts=True)) == 6
    assert done_run_ids(tmp_path) == {'a', 'b'}


def test_a_leftover_temporary_file_is_not_read(tmp_path: Path) -> None:
    (tmp_path / '.part-1.parquet.tmp').write_bytes(b'half a file')
    assert read_rows(tmp_path).empty


def test_a_corrupt_part_is_a_one_line_error_and_set_aside_its_runs_run_again(
    tmp_path: Path,
) -> None:
    writer = PartWriter(tmp_path, batch_rows=1)
    writer.add({'study': 's', 'seed': 0, 'run_id': 'a', 'status': 'ok', 'metric.m': 1.0})
    writer.add({'study': 's', 'seed': 1, 'run_id': 'b', 'status': 'ok', 'metric.m': 2.0})
    damaged = sorted(tmp_path.glob('part-*.parquet'))[-1]
    damaged.write_bytes(damaged.read_bytes()[:100])  # a copy cut short
    for read in (read_rows, done_run_ids):
        with pytest.raises(ResultsError, match='unreadable part file') as error:
            read(tmp_path)
        assert '\n' not in str(error.value)
        assert 'move it out of the study directory' in str(error.value)
    damaged.rename(tmp_path / 'damaged.parquet.bak')
    assert done_run_ids(tmp_path) == {'a'}
    assert list(read_rows(tmp_path)['run_id']) == ['a']


def test_the_directory_lock_admits_one_writer(tmp_path: Path) -> None:
    with study_lock(tmp_path), pytest.raises(ResultsError, match='another run'):  # noqa: SIM117
        with study_lock(tmp_path):
            pass
    with study_lock(tmp_path):
        pass


def test_parts_that_disagree_on_a_type_still_read(tmp_path: Path) -> None:
    writer = PartWriter(tmp_path, batch_rows=1)
    base = {'study': 's', 'seed': 0, 'status': 'ok'}
    writer.add({**base, 'run_id': 'a', 'param.f': [], 'metric.x': None})
    writer.add({**base, 'run_id': 'b', 'param.f': [1, 2], 'metric.x': 2})
    writer.add({**base, 'run_id': 'c', 'param.f': [1.5], 'metric.x': 3.5})
    rows = read_rows(tmp_path).set_index('run_id')
    assert rows['metric.x'].dtype == float
    assert list(rows.loc['b', 'param.f']) == [1.0, 2.0]
    writer.add({**base, 'run_id': 'd', 'metric.x': 'text'})
    rows = read_rows(tmp_path).set_index('run_id')
    assert rows.loc['d', 'metric.x'] == 'text'
    assert rows.loc['c', 'metric.x'] == 3.5


def test_a_part_file_of_something_else_is_a_one_line_error_naming_it(tmp_path: Path) -> None:
    writer = PartWriter(tmp_path, batch_rows=1)
    writer.add({'study': 's', 'seed': 0, 'run_id': 'a', 'status': 'ok', 'metric.m': 1.0})
    foreign = tmp_path / 'part-9-foreign.parquet'
    pd.DataFrame({'x': [1, 2]}).to_parquet(foreign)
    for read in (read_rows, done_run_ids):
        with pytest.raises(ResultsError, match='not a part file of a study') as error:
            read(tmp_path)
        assert str(error.value).startswith(f'{foreign}: ')
        assert 'no column run_id or status' in str(error.value)
        assert '\n' not in str(error.value)


@pytest.mark.parametrize(
    ('text', 'message'),
    [
        ('[1, 2]', 'not a study manifest (a JSON object), found list'),
        ('"study"', 'not a study manifest (a JSON object), found str'),
        ('{"study": "s", "runs": "2"}', "'runs' must be a whole number, not '2'"),
        ('{"study": "s", "axes": [1]}', "'axes' must be an object, not [1]"),
        (
            '{"study": "s", "axes": {"robots": 2}}',
            "axis 'robots' must have a list of values, not 2",
        ),
        ('{"study": "s", "history": [1]}', "'history' holds 1, not dict items"),
    ],
)
def test_a_manifest_of_the_wrong_shape_is_a_one_line_error_naming_the_file(
    tmp_path: Path, text: str, message: str
) -> None:
    (tmp_path / 'study.json').write_text(text)
    with pytest.raises(ResultsError) as error:
        read_manifest(tmp_path)
    assert str(error.value) == f'{tmp_path / "study.json"}: {message}'
