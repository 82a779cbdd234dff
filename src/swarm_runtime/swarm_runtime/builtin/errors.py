"""Exceptions of the built-in runtime that real rclpy does not define in ``rclpy.exceptions``.

Two groups live here:

- errors that only the built-in runtime can raise (:class:`BuiltinRuntimeUnsupported`,
  :class:`ExecutorStalledError`), and
- stand-ins for the exceptions real rclpy raises from its C extension
  (``rclpy._rclpy_pybind11.RCLError`` and friends), with the same base classes, so node code
  that catches ``RuntimeError`` behaves the same on both runtimes.
"""

from __future__ import annotations

__all__ = [
    'BuiltinRuntimeError',
    'BuiltinRuntimeUnsupported',
    'ExecutorStalledError',
    'RCLError',
    'RCLInvalidROSArgsError',
    'UnknownROSArgsError',
]


class BuiltinRuntimeError(RuntimeError):
    """Base class of the errors that only the built-in runtime raises."""


class BuiltinRuntimeUnsupported(BuiltinRuntimeError):  # noqa: N818 - the agreed name
    """Node code used a part of rclpy that the built-in runtime does not provide.

    The message names the feature and says what to do instead (usually: run on real ROS 2,
    or use the listed alternative). Nothing is silently emulated.
    """


class ExecutorStalledError(BuiltinRuntimeError):
    """The executor was asked to block, but nothing can ever become ready.

    No message is pending, no timer is ready and no timer runs on the (virtual) wall clock,
    so real rclpy would block forever here; the built-in runtime says so instead.
    """


class RCLError(RuntimeError):
    """Mirror of ``rclpy._rclpy_pybind11.RCLError``: an rcl call failed."""


class RCLInvalidROSArgsError(RCLError):
    """Mirror of ``rclpy._rclpy_pybind11.RCLInvalidROSArgsError``: malformed ROS arguments."""


class UnknownROSArgsError(RuntimeError):
    """Mirror of ``rclpy._rclpy_pybind11.UnknownROSArgsError``: unknown flags after --ros-args."""
