"""Engines: where the runs of a study execute.

* ``serial``: one after the other in this process (no extra dependency, easiest to debug);
* ``pool``: local worker processes (:class:`concurrent.futures.ProcessPoolExecutor`, spawn
  start method, one BLAS thread each unless ``OMP_NUM_THREADS`` and the like are set). A
  worker that dies breaks the whole pool, so the engine starts a new pool and resubmits the
  runs without a row; it gives up after ``max_restarts`` breaks in a row without a run
  finishing in between;
* ``dask``: Dask distributed. Without an address it starts a local cluster of ``workers``
  single-threaded worker processes on 127.0.0.1; with one (``tcp://host:8786``) it joins
  that cluster. The scheduler reruns a task whose worker died (up to its
  ``distributed.scheduler.allowed-failures``, 3 by default); a run whose workers kept dying
  gets a ``failed`` row (``KilledWorker``).

Every engine runs :func:`~.results.execute` on each spec, so a row depends only on its spec
and the code, not on the engine (except the columns in ``VOLATILE_COLUMNS``). Run functions
must be importable module-level callables on the workers (the same code installed there).
"""

from __future__ import annotations

import abc
import concurrent.futures
import contextlib
import multiprocessing
import os
import signal
import uuid
from collections.abc import Callable, Iterator, Mapping, Sequence
from concurrent.futures.process import BrokenProcessPool
from typing import Any

from .errors import EngineError
from .results import execute
from .spec import RunSpec

__all__ = ['ENGINES', 'DaskEngine', 'Engine', 'PoolEngine', 'SerialEngine', 'make_engine']

RunFunction = Callable[[RunSpec], Mapping[str, Any]]


class Engine(abc.ABC):
    """Runs specs and yields their rows as they complete (in any order)."""

    name = 'engine'
    #: Worker slots the engine runs on (for progress and projections).
    slots = 1

    @abc.abstractmethod
    def rows(
        self, run: RunFunction, specs: Sequence[RunSpec], code_version: str
    ) -> Iterator[dict[str, Any]]:
        """Run every spec with ``run``; yield one row per spec as it completes."""

    def close(self) -> None:  # noqa: B027 (optional: an engine without processes has none)
        """Release the engine's processes (idempotent)."""

    def __enter__(self) -> Engine:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()


class SerialEngine(Engine):
    name = 'serial'

    def rows(
        self, run: RunFunction, specs: Sequence[RunSpec], code_version: str
    ) -> Iterator[dict[str, Any]]:
        for spec in specs:
            yield execute(run, spec, code_version, self.name)


_BLAS_THREAD_VARIABLES = ('OMP_NUM_THREADS', 'OPENBLAS_NUM_THREADS', 'MKL_NUM_THREADS')


def _ignore_sigint() -> None:
    # Ctrl-C goes to the whole process group: the driver stops the study, workers don't die.
    signal.signal(signal.SIGINT, signal.SIG_IGN)


class PoolEngine(Engine):
    name = 'pool'

    def __init__(self, workers: int | None = None, *, max_restarts: int = 3) -> None:
        self.slots = workers or os.cpu_count() or 1
        if self.slots < 1:
            raise EngineError(f'workers must be >= 1, not {self.slots}')
        self.max_restarts = max_restarts
        self.restarts = 0
        self._executor: concurrent.futures.ProcessPoolExecutor | None = None

    def _start(self) -> concurrent.futures.ProcessPoolExecutor:
        # One BLAS thread per worker unless the caller chose otherwise: the workers already
        # fill the cores, and multi-threaded BLAS on top of them spins for CPU (a Case 1
        # Bayes-Swarm decision took ~60 times the CPU with OpenBLAS's default threads).
        # Spawned workers read these when they import numpy.
        for variable in _BLAS_THREAD_VARIABLES:
            os.environ.setdefault(variable, '1')
        self._executor = concurrent.futures.ProcessPoolExecutor(
            max_workers=self.slots,
            mp_context=multiprocessing.get_context('spawn'),
            initializer=_ignore_sigint,
        )
        return self._executor

    def rows(
        self, run: RunFunction, specs: Sequence[RunSpec], code_version: str
    ) -> Iterator[dict[str, Any]]:
        pending = {spec.run_id: spec for spec in specs}
        breaks_in_a_row = 0
        while pending:
            executor = self._start()
            futures = {
                executor.submit(execute, run, spec, code_version, self.name): run_id
                for run_id, spec in pending.items()
            }
            broken = False
            try:
                for future in concurrent.futures.as_completed(futures):
                    try:
                        row = future.result()
                    except BrokenProcessPool:
                        broken = True
                        break
                    except Exception as exc:
                        raise EngineError(
                            f'the process pool could not run {futures[future]}: '
                            f'{type(exc).__name__}: {exc}'
                        ) from exc
                    del pending[futures[future]]
                    breaks_in_a_row = 0
                    yield row
                if broken:
                    for future, rid in futures.items():
                        if rid in pending and future.done() and future.exception() is None:
                            del pending[rid]
                            breaks_in_a_row = 0
                            yield future.result()
            finally:
                self._stop(terminate=not broken and bool(pending))
            if broken:
                self.restarts += 1
                breaks_in_a_row += 1
                if breaks_in_a_row > self.max_restarts:
                    raise EngineError(
                        f'a worker process died {breaks_in_a_row} times in a row; '
                        f'{len(pending)} runs left without a row'
                    )

    def _stop(self, *, terminate: bool) -> None:
        executor, self._executor = self._executor, None
        if executor is None:
            return
        if terminate:
            # Interrupted: don't wait for the runs in progress (their rows are not wanted).
            for process in list(getattr(executor, '_processes', {}).values()):
                process.terminate()
        executor.shutdown(wait=True, cancel_futures=True)

    def close(self) -> None:
        self._stop(terminate=True)


class DaskEngine(Engine):
    name = 'dask'

    def __init__(
        self,
        workers: int | None = None,
        *,
        address: str | None = None,
        connect_timeout_s: float = 20.0,
    ) -> None:
        try:
            from distributed import Client, LocalCluster
        except ImportError as exc:
            raise EngineError(
                'the dask engine needs the dask and distributed packages (pip install '
                '"dask[distributed]")'
            ) from exc
        self._cluster = None
        self.address = address
        try:
            if address:
                self._client = Client(address, timeout=f'{connect_timeout_s}s')
            else:
                count = workers or os.cpu_count() or 1
                self._cluster = LocalCluster(
                    n_workers=count,
                    threads_per_worker=1,
                    processes=True,
                    host='127.0.0.1',
                    dashboard_address=None,
                )
                self._client = Client(self._cluster)
        except (OSError, TimeoutError) as exc:
            self.close()
            where = address or 'a local cluster'
            raise EngineError(f'cannot reach the Dask scheduler at {where}: {exc}') from exc
        self.slots = max(1, self._nthreads())

    def _nthreads(self) -> int:
        try:
            return sum(self._client.nthreads().values())
        except (OSError, TimeoutError):  # the scheduler went away: one slot, runs go on
            return 1

    def rows(
        self, run: RunFunction, specs: Sequence[RunSpec], code_version: str
    ) -> Iterator[dict[str, Any]]:
        from distributed import as_completed
        from distributed.scheduler import KilledWorker

        if not specs:
            return
        token = uuid.uuid4().hex[:8]
        by_key = {f'run-{spec.run_id}-{token}': spec for spec in specs}
        keys = list(by_key)
        futures = self._client.map(
            execute,
            [run] * len(keys),
            list(by_key.values()),
            [code_version] * len(keys),
            [self.name] * len(keys),
            key=keys,
            pure=False,
        )
        completed = as_completed(futures)
        del futures
        finished: set[str] = set()
        try:
            for future in completed:
                key = future.key
                try:
                    row = future.result()
                except KilledWorker as exc:
                    row = _killed_row(by_key[key], code_version, exc)
                finished.add(key)
                future.release()
                yield row
        finally:
            left = [key for key in keys if key not in finished]
            if left:
                self._cancel(completed)

    def _cancel(self, completed: Any) -> None:
        with contextlib.suppress(Exception):  # the cluster may already be gone
            self._client.cancel(list(completed.futures), force=True)

    def close(self) -> None:
        client = getattr(self, '_client', None)
        if client is not None:
            self._client = None  # type: ignore[assignment]  # closed: never used again
            client.close()
        cluster, self._cluster = self._cluster, None
        if cluster is not None:
            cluster.close()


def _killed_row(spec: RunSpec, code_version: str, exc: BaseException) -> dict[str, Any]:
    def fail(_: RunSpec) -> Mapping[str, Any]:
        raise EngineError(f'every worker that ran it died ({type(exc).__name__})')

    row = execute(fail, spec, code_version, DaskEngine.name)
    row['error'] = f'KilledWorker: {exc}'.splitlines()[0]
    return row


ENGINES = ('serial', 'pool', 'dask')


def make_engine(
    name: str,
    *,
    workers: int | None = None,
    address: str | None = None,
    connect_timeout_s: float = 20.0,
) -> Engine:
    """An engine by name; ``address`` (and its ``connect_timeout_s``) only for ``dask``."""
    if workers is not None and workers < 1:
        raise EngineError(f'workers must be >= 1, not {workers}')
    if address and name != 'dask':
        raise EngineError(f'--address joins a Dask cluster; engine {name!r} takes none')
    if name == 'serial':
        return SerialEngine()
    if name == 'pool':
        return PoolEngine(workers)
    if name == 'dask':
        return DaskEngine(workers, address=address, connect_timeout_s=connect_timeout_s)
    raise EngineError(f'unknown engine {name!r} (choose from {", ".join(ENGINES)})')
