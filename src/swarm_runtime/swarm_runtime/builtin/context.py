"""``rclpy.context``: the init/shutdown lifecycle, and what one simulated ROS graph shares.

Besides what rclpy's Context holds (the parsed global ROS arguments, the domain id, the
shutdown callbacks), a built-in context owns the simulated world its nodes live in:

- the topic graph (publishers, subscriptions, matching; see :mod:`._graph`),
- the virtual wall clock (``_elapsed_ns`` since the context was created) read by SYSTEM
  and STEADY clocks and by ROS clocks without sim time, and
- the heap of timers that run on that wall clock, which executors advance through.

Nodes of different contexts do not see each other.
"""

from __future__ import annotations

import os
import sys
from collections.abc import Callable, Sequence
from typing import TYPE_CHECKING, Any

from ._arguments import RosArguments, parse_ros_arguments
from ._graph import Graph
from .errors import RCLError
from .logging import LoggingSeverity, initialize, set_logger_level

if TYPE_CHECKING:
    from .executors import Executor
    from .timer import Timer

__all__ = ['Context']


class Context:
    """An rclpy context: ``init()`` once, ``shutdown()`` once; not reusable."""

    def __init__(self) -> None:
        self._initialized = False
        self._ok = False
        self._arguments = RosArguments()
        self._domain_id = 0
        self._shutdown_callbacks: list[Callable[[], Any]] = []
        self._elapsed_ns = 0
        self._wall_heap: list[tuple[int, int, int, Timer]] = []
        self._graph = Graph()
        self._global_executor: Executor | None = None

    def init(
        self,
        args: Sequence[str] | None = None,
        *,
        initialize_logging: bool = True,
        domain_id: int | None = None,
    ) -> None:
        """Initialise with command-line arguments (``sys.argv`` when None).

        Raises:
            RuntimeError: the context was initialised before.
            UnknownROSArgsError: unknown flags after ``--ros-args``.
            RCLInvalidROSArgsError: malformed ROS arguments or parameter file.
        """
        if self._initialized:
            raise RuntimeError('Context.init() must only be called once')
        argv = list(sys.argv if args is None else args)
        if not all(isinstance(arg, str) for arg in argv):
            raise TypeError('args must be a list of str')
        self._arguments = parse_ros_arguments(argv)
        if domain_id is None:
            domain_id = int(os.environ.get('ROS_DOMAIN_ID', '0') or 0)
        if domain_id < 0:
            msg = f'domain_id must be non-negative, got {domain_id}'
            raise ValueError(msg)
        self._domain_id = domain_id
        if initialize_logging:
            initialize()
            for rule in self._arguments.log_levels:
                set_logger_level(rule.logger_name or '', LoggingSeverity(rule.severity))
        self._initialized = True
        self._ok = True

    @property
    def handle(self) -> Context | None:
        """The underlying context (the context itself once initialised)."""
        return self if self._initialized else None

    def ok(self) -> bool:
        """True between ``init()`` and ``shutdown()``."""
        return self._ok

    def shutdown(self) -> None:
        """Shut down and run the on-shutdown callbacks.

        Raises:
            RuntimeError: the context was never initialised.
            RCLError: it was shut down already.
        """
        if not self._initialized:
            raise RuntimeError('Context must be initialized before it can be shutdown')
        if not self._ok:
            raise RCLError('failed to shutdown: rcl_shutdown already called on the given context')
        self._ok = False
        callbacks, self._shutdown_callbacks = self._shutdown_callbacks, []
        for callback in callbacks:
            callback()

    def try_shutdown(self) -> None:
        """Shut down if initialised and not shut down yet."""
        if self._initialized and self._ok:
            self.shutdown()

    def on_shutdown(self, callback: Callable[[], Any]) -> None:
        """Call ``callback()`` at shutdown (at once if the context is already shut down)."""
        if not callable(callback):
            msg = f'callback should be a callable, got {type(callback)}'
            raise TypeError(msg)
        if self._initialized and not self._ok:
            callback()
            return
        self._shutdown_callbacks.append(callback)

    def get_domain_id(self) -> int:
        """The ROS domain id (recorded only: there is no network)."""
        return self._domain_id

    def destroy(self) -> None:
        """Release the context (shuts it down if needed)."""
        self.try_shutdown()

    def __enter__(self) -> Context:
        self.init()
        return self

    def __exit__(self, *exc_info: object) -> None:
        self.try_shutdown()
