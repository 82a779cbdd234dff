"""A study on a two-node Dask cluster on localhost loses its worker node and still finishes.

The head node runs the scheduler and one worker; the second node runs one worker (with its
nanny). Once the study is under way and the second node is in the middle of a run, that
node's processes are killed (SIGKILL). The scheduler hands its runs to the head's worker,
and the rows equal a serial run's.
"""

from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
import threading
import time
from pathlib import Path

import pytest
from study_fixtures import studies
from study_helpers import comparable
from swarm_experiments.study import StudyRegistry, make_engine, make_specs, read_rows, run_study
from swarm_experiments.study.cli import main
from swarm_experiments.study.results import done_run_ids

pytestmark = pytest.mark.slow


def _start(*argv: str, node: str, env: dict[str, str]) -> subprocess.Popen[bytes]:
    return subprocess.Popen(
        [sys.executable, '-m', 'dask', *argv],
        env={**env, 'STUDY_TEST_NODE': node},
        stdout=subprocess.DEVNULL,
        stderr=subprocess.DEVNULL,
        start_new_session=True,
    )


def _stop(process: subprocess.Popen[bytes]) -> None:
    if process.poll() is None:
        os.killpg(process.pid, signal.SIGKILL)
    process.wait(timeout=30)


def _wait_for(condition, timeout_s: float, what: str) -> None:
    deadline = time.monotonic() + timeout_s
    while not condition():
        if time.monotonic() > deadline:
            raise TimeoutError(what)
        time.sleep(0.05)


def _worker_args(scheduler_file: Path, name: str) -> list[str]:
    return [
        'worker',
        '--scheduler-file',
        str(scheduler_file),
        '--nworkers',
        '1',
        '--nthreads',
        '1',
        '--host',
        '127.0.0.1',
        '--no-dashboard',
        '--name',
        name,
    ]


def test_the_study_finishes_with_identical_rows_after_a_node_dies(tmp_path: Path) -> None:
    markers = tmp_path / 'markers'
    markers.mkdir()
    scheduler_file = tmp_path / 'scheduler.json'
    env = {**os.environ, 'STUDY_TEST_MARKERS': str(markers), 'DASK_LOGGING__DISTRIBUTED': 'error'}
    registry = StudyRegistry(studies())
    plan = make_specs(registry.get('synthetic-slow'))
    processes = []
    try:
        processes.append(
            _start(
                'scheduler',
                '--host',
                '127.0.0.1',
                '--port',
                '0',
                '--no-dashboard',
                '--scheduler-file',
                str(scheduler_file),
                node='head',
                env=env,
            )
        )
        _wait_for(scheduler_file.exists, 30, 'the scheduler did not start')
        processes.append(_start(*_worker_args(scheduler_file, 'head'), node='head', env=env))
        node = _start(*_worker_args(scheduler_file, 'node2'), node='node2', env=env)
        processes.append(node)
        address = json.loads(scheduler_file.read_text())['address']
        assert address.startswith('tcp://127.0.0.1:')

        from distributed import Client

        with Client(address, timeout='30s') as client:
            _wait_for(
                lambda: len(client.scheduler_info()['workers']) == 2,
                30,
                'the two workers did not join',
            )

        out = tmp_path / 'out'
        study_dir = out / 'synthetic-slow'
        killed: list[str] = []

        def kill_node_mid_run() -> None:
            def on_node() -> tuple[set[str], set[str]]:
                done = done_run_ids(study_dir) if study_dir.is_dir() else set()
                names = [path.name.split('.') for path in markers.iterdir()]
                started = {run for run, where, *_ in names if where == 'node2'}
                return started & done, started - done

            # Once node2 has delivered a row and is in the middle of another run.
            _wait_for(lambda: all(on_node()), 60, 'node2 delivered no row')
            killed.extend(on_node()[1])
            os.killpg(node.pid, signal.SIGKILL)

        killer = threading.Thread(target=kill_node_mid_run, daemon=True)
        killer.start()
        code = main(
            [
                'run',
                'synthetic-slow',
                '--engine',
                'dask',
                '--address',
                address,
                '--out',
                str(out),
                '--batch-rows',
                '1',
                '--quiet',
            ],
            registry=registry,
        )
        killer.join(timeout=60)
        assert code == 0
        assert node.wait(timeout=30) == -signal.SIGKILL, 'the worker node was killed'
        assert killed, 'the kill came while the node ran a study run'
    finally:
        for process in reversed(processes):
            _stop(process)

    rows = read_rows(study_dir)
    assert len(rows) == len(plan.specs)
    assert set(rows['status']) == {'ok'}
    assert len(set(rows['pid'])) == 2, 'both nodes delivered rows'
    executions = [path.name.split('.') for path in markers.iterdir()]
    for run in killed:
        where = [node_name for run_id, node_name, *_ in executions if run_id == run]
        assert where.count('node2') >= 1
        assert 'head' in where, 'the run cut short on node2 ran again on the head'
    with make_engine('serial') as engine:
        serial = run_study(plan, tmp_path / 'serial', engine, code_version=rows['code_version'][0])
    assert comparable(rows) == comparable(read_rows(serial.directory))
