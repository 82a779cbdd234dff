"""The ``main()`` of a node executable, as on ROS 2 Jazzy, with a clean exit on every stop.

Every node's console entry point is one call::

    def main(args: list[str] | None = None) -> int:
        return run_node(
            OABugNode, args, name='oabug', fatal_errors=(ConfigError,), parameters=OABUG_PARAMETERS
        )

:func:`run_node` checks the parameter arguments against the node's spec, then does the
Jazzy boilerplate (``rclpy.init``, build the node, spin it,
``destroy_node``, ``rclpy.try_shutdown``) and makes a stop by Ctrl-C (SIGINT) or SIGTERM
exit with status 0 and no traceback, on real rclpy and on the built-in runtime. Catching
KeyboardInterrupt and ExternalShutdownException is not enough on real rclpy:

- rclpy's signal handler shuts the context down from another thread, so a callback that is
  running at that moment fails (a timer that publishes gets ``RCLError: publisher's context
  is invalid``; a node still being built, ``rcl node's context is invalid``). A failure
  raised while the context is no longer ok is the stop itself and is not reported; a
  failure while the context is still ok is a real error and propagates.
- For SIGINT rclpy also calls Python's handler, whose KeyboardInterrupt can land anywhere,
  even inside rclpy's executor half-way through building a task, which then prints
  "Exception ignored ... Traceback" when it is collected.

So Python-level handlers for SIGINT and SIGTERM are installed before ``rclpy.init`` (which
chains its own handlers to them). Each first calls ``on_signal(node)`` if given (e.g. the
pump driver turns its pump off at once, before anything else). Then, if rclpy handles that
signal, the first stop raises nothing in Python: the context shutdown ends the spin. A
second stop signal (a stop that hangs), a signal before ``rclpy.init`` finished, and any
signal on the built-in runtime (which installs no handlers) raise KeyboardInterrupt, which
unwinds into the same teardown.
"""

from __future__ import annotations

import contextlib
import importlib
import re
import signal
from collections.abc import Callable, Sequence
from types import FrameType
from typing import Any, TypeVar

from swarm_common.cli import fail
from swarm_common.params import ParameterSpec

from swarm_runtime.parameters import ParameterFileError, check_parameter_arguments
from swarm_runtime.ros import ExternalShutdownException, rclpy, using_real_rclpy

__all__ = ['EXIT_FATAL_ERROR', 'STOP_SIGNALS', 'describe_init_error', 'run_node']

NodeT = TypeVar('NodeT')

#: Exit status after one of the ``fatal_errors`` (bad parameters, an unusable device).
EXIT_FATAL_ERROR = 2
#: The signals that stop a node cleanly.
STOP_SIGNALS = (signal.SIGINT, signal.SIGTERM)


class _StopSignals:
    """Python's SIGINT / SIGTERM handlers while run_node runs (see the module docstring)."""

    def __init__(self, on_signal: Callable[[], None]) -> None:
        self._on_signal = on_signal
        self._rclpy_handles: set[int] = set()
        self._stopping = False
        self._previous = {signum: signal.signal(signum, self._handle) for signum in STOP_SIGNALS}

    def check_rclpy_handlers(self) -> None:
        """Call after ``rclpy.init``: which of the signals do rclpy's handlers (chained) take?"""
        if not using_real_rclpy():
            return  # the built-in runtime installs no signal handlers
        signals = importlib.import_module('rclpy.signals')
        options = signals.SignalHandlerOptions
        current = signals.get_current_signal_handlers_options()
        if current in (options.SIGINT, options.ALL):
            self._rclpy_handles.add(signal.SIGINT)
        if current in (options.SIGTERM, options.ALL):
            self._rclpy_handles.add(signal.SIGTERM)

    def _handle(self, signum: int, _frame: FrameType | None) -> None:
        # The teardown runs the same hook again and reports its failures; here it must not
        # raise into whatever code the signal interrupted.
        with contextlib.suppress(Exception):
            self._on_signal()
        first = not self._stopping
        self._stopping = True
        if first and signum in self._rclpy_handles:
            return  # rclpy's handler, which called this one, is shutting the context down
        raise KeyboardInterrupt(f'signal {signum}')

    def restore(self) -> None:
        for signum, handler in self._previous.items():
            signal.signal(signum, handler)


# rcl appends where in its C sources an error arose (", at /path/src/rcl/arguments.c:352").
_RCL_SOURCE_LOCATION = re.compile(r', at \S+\.c:\d+')


def describe_init_error(error: RuntimeError) -> str:
    """The one line for a failed ``rclpy.init``: malformed or unknown ROS arguments, mostly.

    Real rclpy raises ``RCLError`` ("failed to initialize rcl: Couldn't parse remap rule:
    '-r foo'. Error: ..., at .../arguments.c:380") or ``UnknownROSArgsError``
    ("['--bogus']"); the built-in runtime raises their mirrors. The rcl source locations
    and the "failed to initialize rcl" prefix are dropped, unknown flags listed as typed.
    """
    if type(error).__name__ == 'UnknownROSArgsError':
        text = str(error)
        flags = re.findall(r"'([^']*)'", text)  # the message is the list: "['--bogus']"
        return f'unknown ROS arguments after --ros-args: {" ".join(flags) if flags else text}'
    text = _RCL_SOURCE_LOCATION.sub('', ' '.join(str(error).split()))
    text = text.removeprefix('failed to initialize rcl: ')
    return f'cannot start ROS: {text}'


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
                continue  # a second stop signal arrived during the teardown: go on


def run_node(
    node_factory: Callable[[], NodeT],
    args: Sequence[str] | None = None,
    *,
    name: str,
    fatal_errors: tuple[type[Exception], ...] = (),
    describe_fatal: Callable[[Exception], str | None] = str,
    on_signal: Callable[[NodeT], None] | None = None,
    spin: Callable[[NodeT], None] | None = None,
    parameters: ParameterSpec | None = None,
) -> int:
    """Initialise rclpy with ``args``, build the node, spin it until stopped; return the status.

    Args:
        node_factory: builds the node (its class, or a function returning it).
        args: command-line arguments (``None``: the process's own, as rclpy reads them).
        name: logger name for errors raised before the node exists (the executable's).
        fatal_errors: the node's own errors that end it with a one-line fatal log instead of
            a traceback (bad parameters, an unusable device), with status 2.
        describe_fatal: the log line for one of ``fatal_errors`` (None: the node has logged
            it already).
        on_signal: called with the node (once it exists) as soon as SIGINT or SIGTERM
            arrives, before the stop begins; e.g. to switch an actuator off.
        spin: runs the node until the context shuts down (default ``rclpy.spin``).
        parameters: the node's parameter spec; its ``--params-file`` files and ``-p`` values
            (for the node named ``name``) are checked before ``rclpy.init``, and a bad one
            ends the process with one line on stderr naming the file and the parameter.

    Returns:
        0 after a stop (Ctrl-C, SIGTERM, shutdown by a callback or another thread),
        ``EXIT_FATAL_ERROR`` after one of ``fatal_errors``, a bad parameter argument or
        malformed ROS arguments (one line on stderr, e.g. a ``-p`` without ``name:=value``).

    Raises:
        Exception: whatever the node or a callback raised while the context was still ok.
    """
    if parameters is not None:
        try:
            check_parameter_arguments(parameters, name, args)
        except ParameterFileError as err:
            return fail(name, err, EXIT_FATAL_ERROR)
    teardown = _Teardown()

    def signalled() -> None:
        if on_signal is not None and teardown.node is not None:
            on_signal(teardown.node)

    stop_signals = _StopSignals(signalled)
    status = 0
    started = False
    try:
        try:
            try:
                rclpy.init(args=None if args is None else list(args))
            except RuntimeError as err:  # rclpy's RCLError, UnknownROSArgsError, mirrors
                return fail(name, describe_init_error(err), EXIT_FATAL_ERROR)
            started = True
            stop_signals.check_rclpy_handlers()
            teardown.node = node_factory()
            (spin or rclpy.spin)(teardown.node)
        except (KeyboardInterrupt, ExternalShutdownException):
            pass
        except fatal_errors as err:
            if rclpy.ok():
                status = EXIT_FATAL_ERROR
                line = describe_fatal(err)
                if line is not None:
                    node = teardown.node
                    logger = node.get_logger() if node is not None else None
                    (logger or rclpy.logging.get_logger(name)).fatal(line)
        except Exception:
            if not started or rclpy.ok():
                raise
            # The context was shut down (a signal) while this was running: part of the stop.
        finally:
            teardown.run()
    except KeyboardInterrupt:
        teardown.run()
    finally:
        stop_signals.restore()
    return status
