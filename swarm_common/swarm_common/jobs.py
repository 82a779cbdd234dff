"""Independent jobs in worker processes, stoppable with Ctrl-C without losing finished ones.

:func:`map_jobs` yields each job's result as it finishes. The workers ignore SIGINT, so
Ctrl-C reaches only the parent: there, ``KeyboardInterrupt`` comes out of the iteration
after the workers have been terminated (a job in progress is dropped), and the caller keeps
every result it has received::

    done = []
    try:
        for result in map_jobs(run_one, jobs, workers=2):
            done.append(result)
    except KeyboardInterrupt:
        interrupted = True  # report ``done``, exit 130
"""

from __future__ import annotations

import multiprocessing
import signal
from collections.abc import Callable, Iterable, Iterator, Sequence
from typing import Any, TypeVar

__all__ = ['map_jobs']

J = TypeVar('J')
R = TypeVar('R')


def _start_worker(initializer: Callable[..., None] | None, initargs: Sequence[Any]) -> None:
    signal.signal(signal.SIGINT, signal.SIG_IGN)  # Ctrl-C is the parent's to handle
    if initializer is not None:
        initializer(*initargs)


def map_jobs(
    function: Callable[[J], R],
    jobs: Iterable[J],
    *,
    workers: int = 1,
    ordered: bool = True,
    initializer: Callable[..., None] | None = None,
    initargs: Sequence[Any] = (),
) -> Iterator[R]:
    """``function`` over ``jobs``: here when ``workers <= 1``, else in a 'spawn' pool.

    Args:
        function: a picklable module-level function (for the pool).
        jobs: the inputs.
        workers: worker processes; 1 runs every job in this process.
        ordered: yield results in job order (else as they finish).
        initializer: called with ``initargs`` once in each worker (and once here when
            ``workers <= 1``).

    Raises:
        KeyboardInterrupt: Ctrl-C; the workers are terminated first.
    """
    if workers <= 1:
        if initializer is not None:
            initializer(*initargs)
        for job in jobs:
            yield function(job)
        return
    context = multiprocessing.get_context('spawn')
    pool = context.Pool(workers, _start_worker, (initializer, tuple(initargs)))
    try:
        mapper = pool.imap if ordered else pool.imap_unordered
        yield from mapper(function, jobs, chunksize=1)
        pool.close()
    except BaseException:
        pool.terminate()
        raise
    finally:
        pool.join()
