"""Simulation-only helpers for spawners and tests; node code never uses them.

They drive an executor of the built-in runtime (``swarm_runtime.builtin``) on virtual time
and read that time. Two clocks matter in a simulation:

- the *virtual wall clock* of a context, which the executor advances from one wall-timer
  deadline to the next (:func:`wall_time_s`: seconds since the context was created), and
- *sim time*, the last value published on ``/clock`` in the context (:func:`sim_time_s`),
  which nodes with ``use_sim_time`` follow.

A typical spawner loop::

    executor = SingleThreadedExecutor()
    for node in nodes:
        executor.add_node(node)
    spin_until_time(executor, 60.0)          # one simulated minute
    spin_until(executor, mission.finished, max_wall_time_s=600.0)
"""

from __future__ import annotations

from collections.abc import Callable

from swarm_runtime.builtin.context import Context
from swarm_runtime.builtin.executors import Executor
from swarm_runtime.builtin.utilities import get_default_context

__all__ = ['sim_time_s', 'spin_ready', 'spin_until', 'spin_until_time', 'wall_time_s']


def _builtin_executor(executor: object) -> Executor:
    if not isinstance(executor, Executor):
        msg = (
            'simulation helpers drive an executor of the built-in runtime '
            f'(swarm_runtime.builtin), got {type(executor).__module__}.{type(executor).__name__}'
        )
        raise TypeError(msg)
    return executor


def wall_time_s(context: Context | None = None) -> float:
    """Seconds of virtual wall-clock time since the (default) context was created."""
    context = get_default_context() if context is None else context
    return context._elapsed_ns / 1e9


def sim_time_s(context: Context | None = None) -> float | None:
    """The last time published on ``/clock`` in the (default) context, None before any."""
    context = get_default_context() if context is None else context
    clock_ns = context._graph.clock_ns
    return None if clock_ns is None else clock_ns / 1e9


def spin_until(
    executor: Executor,
    predicate: Callable[[], bool],
    *,
    max_wall_time_s: float | None = None,
) -> bool:
    """Run callbacks one at a time until ``predicate()`` is true; return whether it became so.

    ``predicate`` is checked before the first callback and after each one. With
    ``max_wall_time_s``, give up (return False) once the virtual wall clock has advanced
    that much. Also returns False when the context or the executor is shut down.

    Raises:
        ExecutorStalledError: without ``max_wall_time_s``, nothing can ever run again.
        Exception: whatever a callback raised.
    """
    executor = _builtin_executor(executor)
    context = executor.context
    if predicate():
        return True
    if not context.ok() or executor._is_shutdown:
        return False
    executor._run_callbacks(_wall_limit_ns(context, max_wall_time_s), stop=predicate)
    return predicate()


def _wall_limit_ns(context: Context, max_wall_time_s: float | None) -> int | None:
    """The virtual wall-clock instant [ns] a spin may not pass; None for no limit."""
    if max_wall_time_s is None:
        return None
    return context._elapsed_ns + round(max_wall_time_s * 1e9)


def spin_ready(executor: Executor) -> int:
    """Run every callback that is ready now, without advancing the virtual wall clock.

    Returns:
        How many callbacks ran (work they publish at this instant runs too).
    """
    executor = _builtin_executor(executor)
    context = executor.context
    if not context.ok() or executor._is_shutdown:
        return 0
    return executor._run_callbacks(context._elapsed_ns)


def spin_until_time(
    executor: Executor, sim_time_s: float, *, max_wall_time_s: float | None = None
) -> bool:
    """Spin until ``/clock`` reaches ``sim_time_s``, then run everything due at that instant.

    So after ``spin_until_time(executor, 3.0)`` a 0.5 s sim-time timer has fired at 0.5, 1.0,
    ..., 3.0 and every message published at 3.0 has been delivered.

    Returns:
        False if ``max_wall_time_s`` of virtual wall time passed first, or shutdown.
    """
    executor = _builtin_executor(executor)
    context = executor.context
    graph = context._graph
    target_ns = round(sim_time_s * 1e9)

    def reached() -> bool:
        return graph.clock_ns is not None and graph.clock_ns >= target_ns

    if not reached():
        if not context.ok() or executor._is_shutdown:
            return False
        limit_ns = _wall_limit_ns(context, max_wall_time_s)
        # The executor checks the clock itself after each callback (no predicate call).
        executor._run_callbacks(limit_ns, until_clock_ns=target_ns)
        if not reached():
            return False
    spin_ready(executor)
    return True
