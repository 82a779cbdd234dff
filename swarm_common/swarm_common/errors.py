"""The base of the errors the suite raises on purpose."""

from __future__ import annotations

from swarm_common.cli import EXIT_USAGE

__all__ = ['SwarmError']


class SwarmError(Exception):
    """An error with a precise one-line message, raised on purpose.

    A command-line tool that stops on it prints the message as one line
    (:func:`swarm_common.cli.fail`) and exits with ``exit_code``: :data:`EXIT_USAGE` for bad
    options or input unless a subclass says otherwise.
    """

    exit_code: int = EXIT_USAGE
