"""The base of the errors the suite raises on purpose, and the two every tool shares."""

from __future__ import annotations

from swarm_common.cli import EXIT_USAGE

__all__ = ['OutputError', 'SwarmError', 'UsageError']


class SwarmError(Exception):
    """An error with a precise one-line message, raised on purpose.

    A command-line tool that stops on it prints the message as one line
    (:func:`swarm_common.cli.fail`) and exits with ``exit_code``: :data:`EXIT_USAGE` for bad
    options or input unless a subclass says otherwise.
    """

    exit_code: int = EXIT_USAGE


class UsageError(SwarmError, ValueError):
    """A command line that cannot be parsed: an unknown option, a malformed value."""


class OutputError(SwarmError, OSError):
    """An output (a directory, a file, a bag) cannot be written where the user asked."""
