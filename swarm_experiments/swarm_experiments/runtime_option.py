"""The spawners' ``--runtime`` and ``--time-scale`` options, and their console entry points.

The ROS runtime is chosen once per process, when ``swarm_runtime.ros`` is first imported
(docs/runtime.md), so ``--runtime`` must be read before a spawner module is imported: the
console scripts ``spawn``, ``spawn_bayes_swarm`` and ``spawn_msc_pf`` start here, set
``SWARM_RUNTIME`` from the option (else keep the environment's, else ``builtin``: the
spawners' default, fast and bit-reproducible, even where real rclpy is installed), then
import the spawner and run its ``main``. This module imports nothing of ROS.

A spawner's ``main`` called in a process that has already chosen a runtime (tests, a
notebook) checks that ``--runtime``, if given, is the one in use (:func:`check_runtime`).
"""

from __future__ import annotations

import argparse
import importlib
import importlib.util
import os
import sys
from collections.abc import Callable, Sequence
from pathlib import Path

from swarm_common.cli import EXIT_USAGE, fail
from swarm_common.errors import SwarmError

__all__ = [
    'DEFAULT_RUNTIME',
    'RUNTIMES',
    'RuntimeOptionError',
    'add_runtime_arguments',
    'check_runtime',
    'chosen_runtime',
    'spawn_bayes_swarm_main',
    'spawn_main',
    'spawn_msc_pf_main',
]

RUNTIMES = ('builtin', 'rclpy')
DEFAULT_RUNTIME = 'builtin'
_ENV_VAR = 'SWARM_RUNTIME'


class RuntimeOptionError(SwarmError, ValueError):
    """``--runtime`` asks for a runtime this process cannot use."""


def add_runtime_arguments(parser: argparse.ArgumentParser) -> None:
    """Add ``--runtime`` and ``--time-scale`` to a spawner's parser."""
    parser.add_argument(
        '--runtime',
        choices=RUNTIMES,
        default=None,
        help='ROS runtime of the in-process mission: builtin (deterministic sim time, as fast '
        'as the CPU allows) or rclpy (real ROS 2 over DDS, in real time); default: '
        'SWARM_RUNTIME if set, else builtin',
    )
    parser.add_argument(
        '--time-scale',
        type=float,
        default=1.0,
        metavar='X',
        help="on real rclpy, the bridge's clock runs X times faster than wall time, as far as "
        'the nodes keep up (the built-in runtime ignores it)',
    )
    parser.add_argument(
        '--processes',
        action='store_true',
        help='one OS process per node (the sim bridge and each robot, started as ros2 run '
        'would) on real rclpy and DDS; this process supervises them (docs/runtime.md)',
    )
    parser.add_argument(
        '--dry-run',
        action='store_true',
        help='with --processes: print the command line of every node, one per line, and exit',
    )
    parser.add_argument(
        '--run-dir',
        type=Path,
        default=None,
        help='with --processes: directory for the mission file, the outcome and the logs of '
        'the nodes (default: a temporary one, removed after a normal end)',
    )


def _option_value(argv: Sequence[str]) -> str | None:
    """The value of the last ``--runtime`` in ``argv`` (None without one)."""
    value = None
    for i, arg in enumerate(argv):
        if arg == '--runtime' and i + 1 < len(argv):
            value = argv[i + 1]
        elif arg.startswith('--runtime='):
            value = arg.split('=', 1)[1]
    return value


def chosen_runtime(argv: Sequence[str], environ: dict[str, str] | None = None) -> str:
    """The runtime a spawner process uses: ``--runtime``, else ``SWARM_RUNTIME``, else builtin.

    An unknown ``--runtime`` value is returned as it is; the spawner's parser rejects it.
    """
    env = os.environ if environ is None else environ
    option = _option_value(argv)
    if option is not None:
        return option
    return env.get(_ENV_VAR, '').strip().lower() or DEFAULT_RUNTIME


def check_runtime(requested: str | None) -> None:
    """Raise :class:`RuntimeOptionError` if ``requested`` is not the runtime in use."""
    if requested is None:
        return
    from swarm_runtime.ros import using_real_rclpy

    in_use = 'rclpy' if using_real_rclpy() else 'builtin'
    if requested != in_use:
        msg = (
            f'--runtime {requested}: this process already runs on the {in_use} runtime '
            f'(start the spawner with --runtime {requested} or SWARM_RUNTIME={requested})'
        )
        raise RuntimeOptionError(msg)


def _entry(module: str) -> Callable[[], int]:
    def main() -> int:
        argv = sys.argv[1:]
        runtime = chosen_runtime(argv)
        processes = '--processes' in argv and '--dry-run' not in argv
        if processes and _option_value(argv) is None:
            runtime = 'rclpy'  # --processes implies real rclpy
        if runtime == 'rclpy' and importlib.util.find_spec('rclpy') is None:
            what = '--processes' if processes else '--runtime rclpy'
            text = f'{what} needs real rclpy (ROS 2 Jazzy or its PyPI wheels), not installed here'
            return fail(module.rsplit('.', 1)[-1], text, EXIT_USAGE)
        if runtime in RUNTIMES:
            os.environ[_ENV_VAR] = runtime
        return int(importlib.import_module(module).main(argv))

    main.__doc__ = f'Console entry point: ``--runtime`` chosen, then ``{module}.main``.'
    return main


spawn_main = _entry('swarm_experiments.spawn')
spawn_bayes_swarm_main = _entry('swarm_experiments.spawn_bayes_swarm')
spawn_msc_pf_main = _entry('swarm_experiments.spawn_msc_pf')
