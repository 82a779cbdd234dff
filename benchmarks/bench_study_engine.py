"""Choosing the distributed engine of the study machinery: Ray against Dask distributed.

Four figures per engine, with the plain local process pool (``concurrent.futures``) as the
no-dependency baseline:

* **install size**: megabytes the engine adds to a fresh virtualenv (``pip install`` of the
  versions pinned in constraints.txt, measured as the growth of site-packages);
* **startup**: seconds from nothing to the first result of a local cluster with ``--workers``
  worker processes (and the time to shut it down again);
* **per-task overhead**: many tiny tasks (each returns its argument) submitted at once; the
  wall time per task, and the same times the number of workers (the core time a task costs
  the cluster beyond its own work, the figure the wall-time projection uses);
* **failure handling**: ``--failure-tasks`` tasks of ``--failure-task-s`` seconds each; the
  worker process running the first task is killed (SIGKILL) once it has started. Reported:
  whether every task still returned, how many executions were started in all (more than the
  task count means tasks were retried) and the wall time.

Each engine runs in its own virtualenv so the install sizes and imports do not mix::

    python benchmarks/bench_study_engine.py --venv-dir /tmp/engines         # create + measure
    python benchmarks/bench_study_engine.py --venv-dir /tmp/engines --reuse # venvs kept
    python benchmarks/bench_study_engine.py --measure pool --json           # one engine, here

The venvs are created with the interpreter running this script (``--python`` to choose).
"""

from __future__ import annotations

import argparse
import concurrent.futures
import json
import os
import re
import shlex
import signal
import subprocess
import sys
import tempfile
import time
from dataclasses import asdict, dataclass
from pathlib import Path
from typing import Any

REPO = Path(__file__).resolve().parents[1]
#: Packages each engine needs (versions come from constraints.txt).
ENGINE_PACKAGES = {'ray': ['ray'], 'dask': ['dask', 'distributed']}


@dataclass
class EngineFigures:
    engine: str
    version: str
    workers: int
    startup_s: float
    shutdown_s: float
    tasks: int
    tasks_wall_s: float
    overhead_per_task_ms: float
    core_overhead_per_task_ms: float
    failure_tasks: int
    failure_completed: int
    failure_executions: int
    failure_wall_s: float
    failure_note: str


# --------------------------------------------------------------------------------------------
# Task bodies (module level so that every engine can pickle them by reference).


def tiny_task(value: int) -> int:
    return value


def failure_task(index: int, marker_dir: str, duration_s: float) -> tuple[int, int]:
    """Leave a marker naming this execution, sleep, return the index and the worker's pid."""
    pid = os.getpid()
    Path(marker_dir, f'{index}.{pid}.{time.monotonic_ns()}').touch()
    time.sleep(duration_s)
    return index, pid


def _kill_first_runner(marker_dir: Path, timeout_s: float = 60.0) -> int:
    """Wait for the first execution marker and SIGKILL the process that wrote it."""
    deadline = time.monotonic() + timeout_s
    while time.monotonic() < deadline:
        markers = sorted(marker_dir.iterdir())
        if markers:
            pid = int(markers[0].name.split('.')[1])
            time.sleep(0.2)
            os.kill(pid, signal.SIGKILL)
            return pid
        time.sleep(0.02)
    raise TimeoutError('no failure task started')


def _executions(marker_dir: Path) -> int:
    return len(list(marker_dir.iterdir()))


# --------------------------------------------------------------------------------------------
# Engines: each measures startup, tiny-task overhead and one failure round.


def _measure_pool(args: argparse.Namespace) -> EngineFigures:
    start = time.perf_counter()
    pool = concurrent.futures.ProcessPoolExecutor(max_workers=args.workers)
    pool.submit(tiny_task, 0).result()
    startup = time.perf_counter() - start
    start = time.perf_counter()
    futures = [pool.submit(tiny_task, i) for i in range(args.tasks)]
    results = [future.result() for future in futures]
    wall = time.perf_counter() - start
    assert results == list(range(args.tasks))
    start = time.perf_counter()
    pool.shutdown()
    shutdown = time.perf_counter() - start

    with tempfile.TemporaryDirectory() as tmp:
        marker_dir = Path(tmp)
        pool = concurrent.futures.ProcessPoolExecutor(max_workers=args.workers)
        start = time.perf_counter()
        futures = [
            pool.submit(failure_task, i, tmp, args.failure_task_s)
            for i in range(args.failure_tasks)
        ]
        _kill_first_runner(marker_dir)
        completed = 0
        errors = set()
        for future in futures:
            try:
                future.result()
                completed += 1
            except Exception as exc:  # the pool breaks as a whole
                errors.add(type(exc).__name__)
        failure_wall = time.perf_counter() - start
        pool.shutdown()
        executions = _executions(marker_dir)
    return _figures(
        'pool',
        'stdlib',
        args,
        startup,
        shutdown,
        wall,
        completed,
        executions,
        failure_wall,
        f'failed: {", ".join(sorted(errors))}' if errors else 'all returned',
    )


def _measure_dask(args: argparse.Namespace) -> EngineFigures:
    import distributed
    from distributed import Client, LocalCluster

    start = time.perf_counter()
    cluster = LocalCluster(
        n_workers=args.workers,
        threads_per_worker=1,
        processes=True,
        dashboard_address=None,
    )
    client = Client(cluster)
    client.submit(tiny_task, 0, pure=False).result()
    startup = time.perf_counter() - start
    start = time.perf_counter()
    futures = client.map(tiny_task, range(args.tasks), pure=False)
    results = client.gather(futures)
    wall = time.perf_counter() - start
    assert results == list(range(args.tasks))

    with tempfile.TemporaryDirectory() as tmp:
        marker_dir = Path(tmp)
        start = time.perf_counter()
        futures = [
            client.submit(failure_task, i, tmp, args.failure_task_s, pure=False)
            for i in range(args.failure_tasks)
        ]
        _kill_first_runner(marker_dir)
        completed, errors = _collect(lambda future: future.result(timeout=120), futures)
        failure_wall = time.perf_counter() - start
        executions = _executions(marker_dir)
    start = time.perf_counter()
    client.close()
    cluster.close()
    shutdown = time.perf_counter() - start
    return _figures(
        'dask',
        distributed.__version__,
        args,
        startup,
        shutdown,
        wall,
        completed,
        executions,
        failure_wall,
        f'failed: {", ".join(sorted(errors))}' if errors else 'all returned',
    )


def _measure_ray(args: argparse.Namespace) -> EngineFigures:
    import ray

    start = time.perf_counter()
    ray.init(num_cpus=args.workers, include_dashboard=False, log_to_driver=False)
    remote_tiny = ray.remote(num_cpus=1)(tiny_task)
    ray.get(remote_tiny.remote(0))
    startup = time.perf_counter() - start
    start = time.perf_counter()
    results = ray.get([remote_tiny.remote(i) for i in range(args.tasks)])
    wall = time.perf_counter() - start
    assert results == list(range(args.tasks))

    remote_failure = ray.remote(num_cpus=1)(failure_task)
    with tempfile.TemporaryDirectory() as tmp:
        marker_dir = Path(tmp)
        start = time.perf_counter()
        refs = [
            remote_failure.remote(i, tmp, args.failure_task_s) for i in range(args.failure_tasks)
        ]
        _kill_first_runner(marker_dir)
        completed, errors = _collect(lambda ref: ray.get(ref, timeout=120), refs)
        failure_wall = time.perf_counter() - start
        executions = _executions(marker_dir)
    start = time.perf_counter()
    ray.shutdown()
    shutdown = time.perf_counter() - start
    return _figures(
        'ray',
        ray.__version__,
        args,
        startup,
        shutdown,
        wall,
        completed,
        executions,
        failure_wall,
        f'failed: {", ".join(sorted(errors))}' if errors else 'all returned',
    )


def _collect(get: Any, handles: list[Any]) -> tuple[int, set[str]]:
    completed = 0
    errors: set[str] = set()
    for handle in handles:
        try:
            get(handle)
            completed += 1
        except Exception as exc:
            errors.add(type(exc).__name__)
    return completed, errors


def _figures(
    engine: str,
    version: str,
    args: argparse.Namespace,
    startup: float,
    shutdown: float,
    wall: float,
    completed: int,
    executions: int,
    failure_wall: float,
    note: str,
) -> EngineFigures:
    per_task_ms = 1000.0 * wall / args.tasks
    return EngineFigures(
        engine=engine,
        version=version,
        workers=args.workers,
        startup_s=round(startup, 3),
        shutdown_s=round(shutdown, 3),
        tasks=args.tasks,
        tasks_wall_s=round(wall, 3),
        overhead_per_task_ms=round(per_task_ms, 3),
        core_overhead_per_task_ms=round(per_task_ms * args.workers, 3),
        failure_tasks=args.failure_tasks,
        failure_completed=completed,
        failure_executions=executions,
        failure_wall_s=round(failure_wall, 3),
        failure_note=note,
    )


MEASURES = {'pool': _measure_pool, 'dask': _measure_dask, 'ray': _measure_ray}


# --------------------------------------------------------------------------------------------
# Virtualenvs: install size and the per-engine measuring processes.


def _pins() -> dict[str, str]:
    pins = {}
    for line in (REPO / 'constraints.txt').read_text().splitlines():
        match = re.match(r'^([A-Za-z0-9_.-]+)==(\S+)', line.strip())
        if match:
            pins[match.group(1).lower()] = match.group(2)
    return pins


def _site_packages_mb(venv: Path) -> float:
    (site,) = venv.glob('lib/python*/site-packages')
    total = sum(path.stat().st_size for path in site.rglob('*') if path.is_file())
    return total / 1e6


def _venv_python(venv: Path) -> Path:
    return venv / 'bin' / 'python'


def _prepare_venv(venv: Path, python: str, packages: list[str], reuse: bool) -> None:
    if reuse and _venv_python(venv).exists():
        return
    subprocess.run([python, '-m', 'venv', '--clear', str(venv)], check=True)
    if packages:
        subprocess.run(
            [
                str(_venv_python(venv)),
                '-m',
                'pip',
                'install',
                '-q',
                '-c',
                str(REPO / 'constraints.txt'),
                *packages,
            ],
            check=True,
        )


def _run_in(python: Path, engine: str, args: argparse.Namespace) -> EngineFigures:
    command = [
        str(python),
        str(Path(__file__).resolve()),
        '--measure',
        engine,
        '--json',
        '--workers',
        str(args.workers),
        '--tasks',
        str(args.tasks),
        '--failure-tasks',
        str(args.failure_tasks),
        '--failure-task-s',
        str(args.failure_task_s),
    ]
    output = subprocess.run(command, check=True, capture_output=True, text=True).stdout
    return EngineFigures(**json.loads(output.strip().splitlines()[-1]))


def _report(
    figures: list[EngineFigures], sizes: dict[str, float], command: str, failure_task_s: float
) -> str:
    lines = [
        f'`{command}` (workers: {figures[0].workers}, tiny tasks: {figures[0].tasks}, '
        f'failure round: {figures[0].failure_tasks} x {failure_task_s:g} s)',
        '',
        '| engine | version | added install MB | startup s | shutdown s | ms/task (wall) '
        '| core ms/task | failure: returned / tasks | executions | failure wall s | note |',
        '| --- | --- | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | --- |',
    ]
    for fig in figures:
        size = sizes.get(fig.engine)
        lines.append(
            f'| {fig.engine} | {fig.version} | {"-" if size is None else f"{size:.0f}"} '
            f'| {fig.startup_s:.2f} | {fig.shutdown_s:.2f} | {fig.overhead_per_task_ms:.3f} '
            f'| {fig.core_overhead_per_task_ms:.3f} '
            f'| {fig.failure_completed} / {fig.failure_tasks} | {fig.failure_executions} '
            f'| {fig.failure_wall_s:.2f} | {fig.failure_note} |'
        )
    return '\n'.join(lines)


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split('\n', 1)[0])
    parser.add_argument('--measure', choices=sorted(MEASURES), help='measure one engine here')
    parser.add_argument('--json', action='store_true', help='print the figures as JSON')
    parser.add_argument('--venv-dir', type=Path, help='where the per-engine venvs live')
    parser.add_argument('--reuse', action='store_true', help='keep existing venvs')
    parser.add_argument('--python', default=sys.executable, help='interpreter for the venvs')
    parser.add_argument('--engines', nargs='+', default=['pool', 'dask', 'ray'])
    parser.add_argument('--workers', type=int, default=2)
    parser.add_argument('--tasks', type=int, default=2000)
    parser.add_argument('--failure-tasks', type=int, default=8)
    parser.add_argument('--failure-task-s', type=float, default=2.0)
    args = parser.parse_args(argv)

    if args.measure:
        figures = MEASURES[args.measure](args)
        print(
            json.dumps(asdict(figures))
            if args.json
            else _report([figures], {}, 'here', args.failure_task_s)
        )
        return 0
    if args.venv_dir is None:
        parser.error('give --venv-dir (or --measure ENGINE for this interpreter)')

    pins = _pins()
    for engine in args.engines:
        for package in ENGINE_PACKAGES.get(engine, []):
            if package not in pins:
                parser.error(f'{package} has no pin in constraints.txt')
    args.venv_dir.mkdir(parents=True, exist_ok=True)
    base = args.venv_dir / 'base'
    _prepare_venv(base, args.python, [], args.reuse)
    base_mb = _site_packages_mb(base)
    sizes: dict[str, float] = {}
    figures = []
    for engine in args.engines:
        packages = ENGINE_PACKAGES.get(engine, [])
        venv = args.venv_dir / engine if packages else base
        _prepare_venv(venv, args.python, packages, args.reuse)
        if packages:
            sizes[engine] = _site_packages_mb(venv) - base_mb
        figures.append(_run_in(_venv_python(venv), engine, args))
    command = shlex.join(['python', 'benchmarks/bench_study_engine.py', *sys.argv[1:]])
    print(_report(figures, sizes, command, args.failure_task_s))
    return 0


if __name__ == '__main__':
    sys.exit(main())
