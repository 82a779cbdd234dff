"""``rclpy.utilities``: the default context, ok/shutdown, and ROS-argument removal.

Like rclpy, the process has one *default context*, used whenever a call is not given one;
shutting it down replaces it with a fresh one, so ``init(); ...; shutdown(); init()`` works.
It is the only process-wide state of the runtime.
"""

from __future__ import annotations

import sys
from collections.abc import Sequence

from ._arguments import parse_ros_arguments
from .context import Context

__all__ = [
    'RMW_IMPLEMENTATION_IDENTIFIER',
    'get_available_rmw_implementations',
    'get_default_context',
    'get_rmw_implementation_identifier',
    'ok',
    'remove_ros_args',
    'shutdown',
    'timeout_sec_to_nsec',
    'try_shutdown',
]

#: What ``get_rmw_implementation_identifier()`` reports for the built-in runtime.
RMW_IMPLEMENTATION_IDENTIFIER = 'swarm_runtime_builtin'


class _DefaultContextHolder:
    """Holds the process's default context (rclpy keeps it in a module global too)."""

    def __init__(self) -> None:
        self.context: Context | None = None

    def get(self, *, shutting_down: bool) -> Context:
        context = self.context
        if context is None:
            context = self.context = Context()
        if shutting_down:
            self.context = None
        return context


_default = _DefaultContextHolder()


def get_default_context(*, shutting_down: bool = False) -> Context:
    """Return the default context; with ``shutting_down`` the next call makes a new one."""
    return _default.get(shutting_down=shutting_down)


def ok(*, context: Context | None = None) -> bool:
    """True while the (default) context is initialised and not shut down."""
    return (get_default_context() if context is None else context).ok()


def shutdown(*, context: Context | None = None) -> None:
    """Shut down the (default) context; see :meth:`Context.shutdown` for errors."""
    (get_default_context(shutting_down=True) if context is None else context).shutdown()


def try_shutdown(*, context: Context | None = None) -> None:
    """Shut down the (default) context unless it is shut down already."""
    (get_default_context(shutting_down=True) if context is None else context).try_shutdown()


def remove_ros_args(args: Sequence[str] | None = None) -> list[str]:
    """Return ``args`` (``sys.argv`` when None) without the ROS arguments.

    Raises:
        UnknownROSArgsError: unknown flags after ``--ros-args``.
        RCLInvalidROSArgsError: malformed ROS arguments.
    """
    return list(parse_ros_arguments(list(sys.argv if args is None else args)).non_ros_args)


def get_rmw_implementation_identifier() -> str:
    """Return the name of the middleware in use (the built-in runtime's)."""
    return RMW_IMPLEMENTATION_IDENTIFIER


def get_available_rmw_implementations() -> set[str]:
    """Return the middlewares available (only the built-in runtime's)."""
    return {RMW_IMPLEMENTATION_IDENTIFIER}


def timeout_sec_to_nsec(timeout_sec: float | None) -> int:
    """Seconds to nanoseconds; None or negative means 'forever' (-1)."""
    if timeout_sec is None or timeout_sec < 0:
        return -1
    return int(float(timeout_sec) * 1e9)
