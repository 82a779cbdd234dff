"""Checks for node programs that run as processes of their own (``ros2 run``, console scripts).

On the built-in runtime every process is a world of its own: a node started alone there has
nobody to talk to, its timers run on a virtual clock as fast as the CPU allows, and whatever
it logs per tick floods the terminal. Simulations and tests start their nodes in one process
and opt in to that runtime explicitly; a node started by hand on a machine without ROS should
say so and stop instead of falling back silently.

    problem = standalone_runtime_problem()
    if problem:
        sys.stderr.write(f'rplidar_node: {problem}\\n')
        raise SystemExit(2)
"""

from __future__ import annotations

import importlib.util
import os

__all__ = [
    'BUILTIN_OPT_IN',
    'builtin_runtime_requested',
    'rclpy_available',
    'runtime_missing_reason',
    'standalone_runtime_problem',
]

#: The value of ``SWARM_RUNTIME`` that asks for the built-in runtime explicitly.
BUILTIN_OPT_IN = 'builtin'
# Same name as swarm_runtime.ros.RUNTIME_ENV_VAR; not imported from there, so that this
# module can be used (e.g. by a launcher) without importing rclpy or the built-in runtime.
_RUNTIME_ENV_VAR = 'SWARM_RUNTIME'


def builtin_runtime_requested() -> bool:
    """True when ``SWARM_RUNTIME=builtin`` asks for the built-in runtime explicitly."""
    return os.environ.get(_RUNTIME_ENV_VAR, '').strip().lower() == BUILTIN_OPT_IN


def runtime_missing_reason() -> str:
    """The one-line explanation used when rclpy is missing and nobody opted in."""
    return (
        'ROS 2 (rclpy) is not importable: source /opt/ros/jazzy/setup.bash first;'
        f' {_RUNTIME_ENV_VAR}={BUILTIN_OPT_IN} runs on the built-in runtime instead, where a'
        ' process can talk to no other process'
    )


def rclpy_available() -> bool:
    """True when rclpy can be imported in this interpreter (without importing it)."""
    try:
        return importlib.util.find_spec('rclpy') is not None
    except (ImportError, ValueError):
        return False


def standalone_runtime_problem() -> str | None:
    """Why a standalone node process should not start, or None when it may.

    It may on real rclpy, and on the built-in runtime only when ``SWARM_RUNTIME=builtin``
    asks for it (tests, a simulation started process by process).
    """
    from swarm_runtime.ros import using_real_rclpy

    if using_real_rclpy() or builtin_runtime_requested():
        return None
    return runtime_missing_reason()
