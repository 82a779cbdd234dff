"""Studies run on every engine with identical rows, resume, and survive interruptions."""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path

import pytest
from study_fixtures import blas_threads_run, dying_run, search_study
from study_helpers import comparable
from swarm_experiments.study import (
    EngineError,
    ResultsError,
    UsageError,
    make_engine,
    make_specs,
    parse_overrides,
    read_rows,
    run_study,
)
from swarm_experiments.study.engines import PoolEngine
from swarm_experiments.study.results import read_manifest

VERSION = 'test-version'


def _serial(plan, out: Path):
    with make_engine('serial') as engine:
        return run_study(plan, out, engine, code_version=VERSION)


@pytest.fixture(scope='module')
def serial_rows(tmp_path_factory: pytest.TempPathFactory) -> list[dict]:
    out = tmp_path_factory.mktemp('serial')
    summary = _serial(make_specs(search_study()), out)
    assert summary.complete
    return comparable(read_rows(summary.directory))


def test_serial_run_stores_one_ok_row_per_spec(tmp_path: Path) -> None:
    plan = make_specs(search_study())
    summary = _serial(plan, tmp_path)
    assert (summary.planned, summary.ok, summary.failed, summary.skipped) == (36, 36, 0, 0)
    rows = read_rows(summary.directory)
    assert sorted(rows['run_id']) == sorted(spec.run_id for spec in plan.specs)
    assert set(rows['status']) == {'ok'}
    assert set(rows['engine']) == {'serial'}


@pytest.mark.parametrize('engine_name', ['pool', 'dask'])
def test_rows_are_identical_on_every_engine(
    engine_name: str, tmp_path: Path, serial_rows: list[dict]
) -> None:
    with make_engine(engine_name, workers=2) as engine:
        summary = run_study(make_specs(search_study()), tmp_path, engine, code_version=VERSION)
    assert summary.complete
    rows = read_rows(summary.directory)
    assert set(rows['engine']) == {engine_name}
    assert len(set(rows['pid'])) >= 1
    assert comparable(rows) == serial_rows


def test_a_second_call_skips_the_stored_runs(tmp_path: Path) -> None:
    plan = make_specs(search_study())
    _serial(make_specs(search_study(), overrides=parse_overrides(['robots=2'])), tmp_path)
    summary = _serial(plan, tmp_path)
    assert (summary.skipped, summary.ok) == (12, 24)
    again = _serial(plan, tmp_path)
    assert (again.skipped, again.ok, again.complete) == (36, 0, True)
    assert len(read_rows(summary.directory)) == 36


def test_the_manifest_holds_what_every_call_planned(tmp_path: Path) -> None:
    first = make_specs(search_study(), overrides=parse_overrides(['robots=2']), runs=2)
    _serial(first, tmp_path)
    second = make_specs(search_study(), overrides=parse_overrides(['robots=4,6']), runs=3)
    summary = _serial(second, tmp_path)
    manifest = read_manifest(summary.directory)
    assert manifest['axes']['robots'] == [2, 4, 6]
    assert manifest['seeds'] == [0, 1, 2]
    planned = {spec.run_id for spec in (*first.specs, *second.specs)}
    assert set(manifest['planned_run_ids']) == planned
    assert manifest['runs'] == len(planned) == 3 * 2 + 3 * 2 * 3
    assert [call['engine'] for call in manifest['history']] == ['serial', 'serial']


def test_failed_runs_are_stored_and_run_again_on_resume(tmp_path: Path) -> None:
    failing = make_specs(search_study(), overrides=parse_overrides(['fail_seeds=[1]']))
    summary = _serial(failing, tmp_path)
    assert (summary.ok, summary.failed, summary.complete) == (27, 9, False)
    rows = read_rows(summary.directory)
    assert set(rows[rows['status'] == 'failed']['seed']) == {1}
    again = _serial(failing, tmp_path)
    assert (again.skipped, again.failed) == (27, 9), 'failed runs are retried, ok ones kept'


def test_an_interruption_keeps_the_rows_received_and_the_study_resumes(
    tmp_path: Path, serial_rows: list[dict]
) -> None:
    plan = make_specs(search_study())
    seen = []

    def interrupt_after_ten(row: dict) -> None:
        seen.append(row['run_id'])
        if len(seen) == 10:
            raise KeyboardInterrupt

    with make_engine('pool', workers=2) as engine:
        summary = run_study(
            plan, tmp_path, engine, code_version=VERSION, batch_rows=4, on_row=interrupt_after_ten
        )
    assert summary.interrupted
    assert not summary.complete
    stored = read_rows(summary.directory)
    assert set(stored['run_id']) == set(seen), 'the rows received were written, no others'
    resumed = _serial(plan, tmp_path)
    assert (resumed.skipped, resumed.ok, resumed.complete) == (10, 26, True)
    assert comparable(read_rows(summary.directory)) == serial_rows


def test_the_pool_replaces_a_dead_worker_and_finishes(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, serial_rows: list[dict]
) -> None:
    markers = tmp_path / 'markers'
    markers.mkdir()
    monkeypatch.setenv('STUDY_TEST_MARKERS', str(markers))
    only = ['variant=gas', 'robots=4']
    plan = make_specs(search_study(), overrides=parse_overrides([*only, 'die_once_seeds=[2]']))
    engine = PoolEngine(2)
    with engine:
        summary = run_study(plan, tmp_path / 'out', engine, code_version=VERSION)
    assert summary.complete
    assert engine.restarts == 1
    (died,) = [spec.run_id for spec in plan.specs if spec.seed == 2]
    executions = [path.name.split('.')[0] for path in markers.iterdir()]
    assert executions.count(died) == 2, 'the run that died ran again'
    rows = read_rows(summary.directory)
    assert len(rows) == 4
    assert set(rows['status']) == {'ok'}
    reference = make_specs(search_study(), overrides=parse_overrides(only))
    _serial(reference, tmp_path / 'serial')
    expected = comparable(read_rows(tmp_path / 'serial' / 'synthetic-search'))

    def by_seed(records: list[dict]) -> list[dict]:
        records = [{**r, 'param.die_once_seeds': [], 'run_id': None} for r in records]
        return sorted(records, key=lambda r: r['seed'])

    assert by_seed(comparable(rows)) == by_seed(expected), (
        'the parameter and run id aside, the rows are those of runs that never died'
    )


def test_the_pool_gives_up_on_a_run_that_always_kills_its_worker(tmp_path: Path) -> None:
    study = search_study(run=dying_run)
    plan = make_specs(study, runs=1, overrides=parse_overrides(['robots=2']))
    engine = PoolEngine(1, max_restarts=1)
    with engine, pytest.raises(EngineError, match='died 2 times in a row; 3 runs left'):
        run_study(plan, tmp_path, engine, code_version=VERSION)


def test_engine_arguments_are_checked() -> None:
    with pytest.raises(EngineError, match='unknown engine'):
        make_engine('spark')
    with pytest.raises(EngineError, match='takes none'):
        make_engine('pool', address='tcp://127.0.0.1:1')
    with pytest.raises(EngineError, match='>= 1'):
        make_engine('pool', workers=0)


def test_a_directory_of_another_study_is_refused(tmp_path: Path) -> None:
    _serial(make_specs(search_study(), runs=1), tmp_path)
    other = search_study(name='other')
    (tmp_path / 'other').symlink_to(tmp_path / 'synthetic-search')
    with pytest.raises(ResultsError, match="holds study 'synthetic-search'"):
        _serial(make_specs(other, runs=1), tmp_path)


def test_a_run_that_keeps_killing_dask_workers_gets_a_failed_row(tmp_path: Path) -> None:
    import dask

    study = search_study(run=dying_run)
    plan = make_specs(study, runs=1, overrides=parse_overrides(['robots=2', 'variant=gas']))
    with (
        dask.config.set({'distributed.scheduler.allowed-failures': 1}),
        make_engine('dask', workers=1) as engine,
    ):
        summary = run_study(plan, tmp_path, engine, code_version=VERSION)
    assert (summary.ok, summary.failed) == (0, 1)
    (row,) = read_rows(summary.directory).to_dict('records')
    assert row['status'] == 'failed'
    assert row['error'].startswith('KilledWorker: ')
    assert row['run_id'] == plan.specs[0].run_id


def test_pool_workers_get_one_blas_thread_unless_the_caller_chose(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    for name in ('OMP_NUM_THREADS', 'OPENBLAS_NUM_THREADS', 'MKL_NUM_THREADS'):
        monkeypatch.delenv(name, raising=False)
    monkeypatch.setenv('MKL_NUM_THREADS', '3')
    study = search_study(run=blas_threads_run)
    plan = make_specs(study, runs=1, overrides=parse_overrides(['robots=2']))
    with PoolEngine(1) as engine:
        run_study(plan, tmp_path, engine, code_version=VERSION)
    rows = read_rows(tmp_path / study.name)
    assert set(rows['metric.omp_num_threads']) == {1}
    assert set(rows['metric.openblas_num_threads']) == {1}
    assert set(rows['metric.mkl_num_threads']) == {3}


def test_run_study_checks_a_plan_made_by_hand_before_it_writes_anything(tmp_path: Path) -> None:
    plan = make_specs(search_study(), smoke=True)
    bad = replace(plan.specs[0], config={**plan.specs[0].config, 'sleep_s': -1.0})
    with pytest.raises(UsageError, match=r'^sleep_s=-1\.0: must be >= 0$'):
        _serial(replace(plan, specs=(bad, *plan.specs[1:])), tmp_path)
    assert not list(tmp_path.iterdir()), 'nothing is created, run or stored'
