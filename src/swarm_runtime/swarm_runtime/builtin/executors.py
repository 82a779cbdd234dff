"""``rclpy.executors``: a deterministic, single-threaded discrete-event executor.

What runs next, in this order:

1. a pending message: messages are delivered one callback at a time in publish order
   across the whole context (FIFO), each to its subscription's callback;
2. a ready timer, earliest deadline first, ties broken by creation order;
3. otherwise the virtual wall clock jumps straight to the next deadline of a timer that runs
   on it (SYSTEM/STEADY clocks, and ROS clocks without sim time), so a simulation runs as
   fast as the callbacks allow and the same inputs give the same run.

Timers on sim time (``use_sim_time``) become ready only when their node receives a ``/clock``
message that reaches their deadline. When nothing can ever become ready and the caller asked
to block (``timeout_sec=None``), real rclpy would wait forever; this executor raises
:class:`~.errors.ExecutorStalledError` instead. With a timeout, the virtual wall clock moves
on by at most that much.
"""

from __future__ import annotations

import heapq
from collections import deque
from collections.abc import Callable
from operator import itemgetter
from typing import TYPE_CHECKING, Any

from .errors import BuiltinRuntimeUnsupported, ExecutorStalledError
from .task import Future
from .utilities import get_default_context

if TYPE_CHECKING:
    from .context import Context
    from .node import Node
    from .subscription import Subscription
    from .timer import Timer

__all__ = [
    'ConditionReachedException',
    'Executor',
    'ExternalShutdownException',
    'ShutdownException',
    'SingleThreadedExecutor',
    'TimeoutException',
]

_by_seq = itemgetter(0)


class ExternalShutdownException(Exception):  # noqa: N818 - the rclpy name
    """The context was shut down (e.g. by another callback or Ctrl-C) while spinning."""


class ShutdownException(Exception):  # noqa: N818 - the rclpy name
    """The executor was shut down."""


class TimeoutException(Exception):  # noqa: N818 - the rclpy name
    """Nothing became ready before the timeout."""


class ConditionReachedException(Exception):  # noqa: N818 - the rclpy name
    """The condition being waited for was reached."""


class Executor:
    """Runs the callbacks of the nodes added to it (see the module docstring for the order)."""

    def __init__(self, *, context: Context | None = None) -> None:
        self._context = get_default_context() if context is None else context
        self._nodes: dict[Node, None] = {}
        # (seq, subscription) notifications, in publish order; stale ones are skipped.
        self._inbox: deque[tuple[int, Subscription]] = deque()
        # (deadline_ns, creation order, generation, timer) of timers that fell due.
        self._ready: list[tuple[int, int, int, Timer]] = []
        self._is_shutdown = False

    @property
    def context(self) -> Context:
        """The context whose nodes this executor runs."""
        return self._context

    def add_node(self, node: Node) -> bool:
        """Add a node (moving it from its previous executor); False if present already.

        Raises:
            ValueError: the node belongs to another context.
        """
        if node in self._nodes:
            return False
        if node.context is not self._context:
            msg = f'{node!r} belongs to another context than this executor'
            raise ValueError(msg)
        previous = node._executor
        if previous is not None:
            previous.remove_node(node)
        self._nodes[node] = None
        node._executor = self
        waiting: list[tuple[int, Subscription]] = []
        for subscription in node._subscriptions:
            subscription._owner = self
            waiting.extend((entry[0], subscription) for entry in subscription._queue)
        if waiting:
            waiting.sort(key=_by_seq)
            merged = list(heapq.merge(self._inbox, waiting, key=_by_seq))
            self._inbox.clear()
            self._inbox.extend(merged)
        for timer in node._timers:
            timer._owner = self
            if not timer._canceled and timer._clock._now_ns() >= timer._next_call_ns:
                timer._notify_ready()
        return True

    def remove_node(self, node: Node) -> None:
        """Remove a node; its queued messages wait for the next executor it is added to."""
        if node not in self._nodes:
            return
        del self._nodes[node]
        node._executor = None
        for subscription in node._subscriptions:
            subscription._owner = None
        for timer in node._timers:
            timer._owner = None

    def get_nodes(self) -> list[Node]:
        """The nodes of this executor, in the order they were added."""
        return list(self._nodes)

    def wake(self) -> None:
        """No-op: nothing ever sleeps in the built-in executor."""

    def shutdown(self, timeout_sec: float | None = None) -> bool:
        """Stop spinning and release the nodes; always True."""
        self._is_shutdown = True
        for node in list(self._nodes):
            self.remove_node(node)
        return True

    def create_task(self, callback: Any, *args: Any, **kwargs: Any) -> Any:
        """Not provided: coroutine tasks are not simulated."""
        raise BuiltinRuntimeUnsupported(
            'Executor.create_task() is not provided by the built-in runtime: call the function '
            'from a timer or subscription callback instead'
        )

    def spin(self) -> None:
        """Run callbacks until the context or the executor is shut down."""
        if not self._is_shutdown and self._context._ok:
            self._run_callbacks(None)

    def spin_once(self, timeout_sec: float | None = None) -> None:
        """Run one callback, advancing virtual time by at most ``timeout_sec`` to find one.

        Raises:
            ExternalShutdownException: the context is shut down.
            ExecutorStalledError: ``timeout_sec`` is None or negative and nothing can run.
            Exception: whatever the callback raised.
        """
        if self._is_shutdown:
            return
        context = self._context
        if not context._ok:
            raise ExternalShutdownException()
        if timeout_sec is None or timeout_sec < 0:
            self._run_callbacks(None, max_callbacks=1)
        else:
            self._run_callbacks(context._elapsed_ns + int(timeout_sec * 1e9), max_callbacks=1)

    def spin_until_future_complete(self, future: Future, timeout_sec: float | None = None) -> None:
        """Spin until ``future`` is done, the timeout (virtual time) expires or shutdown."""
        context = self._context
        if self._is_shutdown or not context._ok or future.done():
            return
        limit_ns = None
        if timeout_sec is not None and timeout_sec >= 0:
            limit_ns = context._elapsed_ns + int(timeout_sec * 1e9)
        self._run_callbacks(limit_ns, stop=future.done)

    def spin_once_until_future_complete(
        self, future: Future, timeout_sec: float | None = None
    ) -> None:
        """Run one callback (like :meth:`spin_once`) unless ``future`` is done already."""
        if not future.done():
            self.spin_once(timeout_sec)

    # The core loop.

    def _run_callbacks(
        self,
        limit_ns: int | None,
        *,
        stop: Callable[[], bool] | None = None,
        max_callbacks: int | None = None,
        until_clock_ns: int | None = None,
    ) -> int:
        """Run callbacks in order until ``stop()`` (checked after each), ``max_callbacks``,
        shutdown, ``/clock`` reaching ``until_clock_ns`` (checked after each, without a call),
        or nothing is left to run before the virtual wall clock reaches ``limit_ns``.

        Returns:
            How many callbacks ran.

        Raises:
            ExecutorStalledError: ``limit_ns`` is None and nothing can ever run.
        """
        inbox = self._inbox
        popleft = inbox.popleft
        ready = self._ready
        context = self._context
        heappop = heapq.heappop
        graph = context._graph
        count = 0
        while True:
            if inbox:
                seq, subscription = popleft()
                queue = subscription._queue
                # Stale notifications (message dropped or taken, node moved) are skipped.
                if not queue or queue[0][0] != seq or subscription._owner is not self:
                    continue
                entry = queue.popleft()
                if subscription._plain:
                    data = entry[1]
                    if type(data) is bytes and subscription._decode_bytes:
                        data = subscription._codec.deserialize(data)
                    subscription._callback(data)
                else:
                    subscription._deliver(entry)
            elif ready:
                _, _, gen, timer = heappop(ready)
                if gen != timer._gen or timer._owner is not self:
                    continue
                timer._call()
            elif self._advance_wall_clock(limit_ns):
                continue
            else:
                return count
            count += 1
            if count == max_callbacks or not context._ok or self._is_shutdown:
                return count
            if stop is not None and stop():
                return count
            if until_clock_ns is not None:
                clock_ns = graph.clock_ns
                if clock_ns is not None and clock_ns >= until_clock_ns:
                    return count

    def _advance_wall_clock(self, limit_ns: int | None) -> bool:
        """Jump to the next wall-timer deadline (not past ``limit_ns``); False if none."""
        context = self._context
        heap = context._wall_heap
        while heap and heap[0][2] != heap[0][3]._gen:
            heapq.heappop(heap)
        now = context._elapsed_ns
        if not heap or (limit_ns is not None and heap[0][0] > limit_ns):
            if limit_ns is None:
                raise ExecutorStalledError(
                    'The executor has nothing to do and nothing can become ready: no message '
                    'is pending, no timer is ready and no timer runs on the wall clock '
                    '(timers on sim time wait for /clock). Real rclpy would block here forever.'
                )
            if limit_ns > now:
                context._elapsed_ns = limit_ns
            return False
        if heap[0][0] > now:
            context._elapsed_ns = now = heap[0][0]
        while heap and heap[0][0] <= now:
            _, _, gen, timer = heapq.heappop(heap)
            if gen == timer._gen:
                timer._notify_ready()
        return True


class SingleThreadedExecutor(Executor):
    """The executor ``rclpy.spin`` uses; in the built-in runtime every executor is one."""


def __getattr__(name: str) -> Any:
    if name == 'MultiThreadedExecutor':
        raise BuiltinRuntimeUnsupported(
            'MultiThreadedExecutor is not provided by the built-in runtime, which is '
            'single-threaded and deterministic; use SingleThreadedExecutor'
        )
    msg = f'module {__name__!r} has no attribute {name!r}'
    raise AttributeError(msg)
