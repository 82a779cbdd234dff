"""The ``main()`` of a node executable, as on ROS 2 Jazzy, with a clean exit on every stop.

Every node's console entry point is one line::

    def main(args: list[str] | None = None) -> int:
        return run_node(OABugNode, args, name='oabug', fatal_errors=(ConfigError,))

:func:`run_node` does the Jazzy boilerplate (``rclpy.init``, build the node, ``rclpy.spin``,
``destroy_node``, ``rclpy.try_shutdown``) and makes a stop by Ctrl-C (SIGINT) or SIGTERM exit
with status 0 and no traceback. Catching KeyboardInterrupt and ExternalShutdownException is
not enough on real rclpy:

- rclpy's signal handler shuts the context down from another thread, so a callback that is
  running at that moment fails (a timer that publishes gets ``RCLError: publisher's context
  is invalid``). A failure raised while the context is no longer ok is the stop itself and is
  not reported; a failure while the context is still ok is a real error and propagates.
- For SIGINT rclpy also calls Python's handler, whose KeyboardInterrupt can land anywhere,
  even inside rclpy's executor half-way through building a task, which then prints "Exception
  ignored ... Traceback" when it is collected. So while rclpy's handler is installed, the
  first SIGINT raises nothing in Python: the context shutdown stops the spin. A second
  SIGINT (a stop that hangs), and any SIGINT before ``rclpy.init`` finished or on the built-in
  runtime (which installs no signal handler), raise KeyboardInterrupt as usual.
"""

from __future__ import annotations

import importlib
import signal
from collections.abc import Callable, Sequence
from types import FrameType
from typing import Any

from swarm_runtime.ros import ExternalShutdownException, rclpy, using_real_rclpy

__all__ = ['EXIT_FATAL_ERROR', 'run_node']

# Exit status after one of the ``fatal_errors`` (as the spawners exit on bad arguments).
EXIT_FATAL_ERROR = 2


class _SigintGuard:
    """Python's SIGINT handler while run_node runs: silent for the first SIGINT rclpy handles."""

    def __init__(self) -> None:
        self.rclpy_handles_sigint = False
        self._seen = False
        self._previous = signal.signal(signal.SIGINT, self._on_sigint)

    def check_rclpy_handler(self) -> None:
        """Call after ``rclpy.init``: is rclpy's SIGINT handler (chained to this one) in place?"""
        if not using_real_rclpy():
            return  # the built-in runtime installs no signal handlers
        signals = importlib.import_module('rclpy.signals')
        current = signals.get_current_signal_handlers_options()
        handled = (signals.SignalHandlerOptions.SIGINT, signals.SignalHandlerOptions.ALL)
        self.rclpy_handles_sigint = current in handled

    def _on_sigint(self, signum: int, frame: FrameType | None) -> None:
        if self.rclpy_handles_sigint and not self._seen:
            self._seen = True
            return  # rclpy's handler, which called this one, is shutting the context down
        raise KeyboardInterrupt

    def restore(self) -> None:
        signal.signal(signal.SIGINT, self._previous)


class _Teardown:
    """destroy_node and try_shutdown, each once, even if an interrupt lands in between."""

    def __init__(self) -> None:
        self.node: Any = None
        self._node_done = False
        self._context_done = False

    def run(self) -> None:
        while True:
            try:
                if self.node is not None and not self._node_done:
                    self._node_done = True  # an interrupted destroy is not retried
                    self.node.destroy_node()
                if not self._context_done:
                    self._context_done = True
                    rclpy.try_shutdown()
                return
            except KeyboardInterrupt:
                continue  # the SIGINT that stopped the node arrived late: go on


def run_node(
    node_factory: Callable[[], Any],
    args: Sequence[str] | None = None,
    *,
    name: str,
    fatal_errors: tuple[type[Exception], ...] = (),
) -> int:
    """Initialise rclpy with ``args``, build the node, spin it until stopped; return the status.

    Args:
        node_factory: builds the node (its class, or a function returning it).
        args: command-line arguments (``None``: the process's own, as rclpy reads them).
        name: logger name for errors raised before the node exists (the executable's).
        fatal_errors: the node's own errors that end it with a one-line message instead of a
            traceback (bad parameters, an unusable device): logged, status 2.

    Returns:
        0 after a stop (Ctrl-C, SIGTERM, shutdown by a callback or another thread),
        ``EXIT_FATAL_ERROR`` after one of ``fatal_errors``.

    Raises:
        Exception: whatever the node or a callback raised while the context was still ok.
    """
    guard = _SigintGuard()
    teardown = _Teardown()
    status = 0
    started = False
    try:
        try:
            rclpy.init(args=None if args is None else list(args))
            started = True
            guard.check_rclpy_handler()
            teardown.node = node_factory()
            rclpy.spin(teardown.node)
        except (KeyboardInterrupt, ExternalShutdownException):
            pass
        except fatal_errors as err:
            if rclpy.ok():
                node = teardown.node
                logger = node.get_logger() if node is not None else None
                (logger or rclpy.logging.get_logger(name)).fatal(str(err))
                status = EXIT_FATAL_ERROR
        except Exception:
            if not started or rclpy.ok():
                raise
            # The context was shut down (a signal) while this was running: part of the stop.
        finally:
            teardown.run()
    except KeyboardInterrupt:
        teardown.run()
    finally:
        guard.restore()
    return status
