"""Conventions of the suite's command-line tools: exit codes and one-line errors.

Exit codes: 0 the tool did what was asked, 1 a mission ran but did not finish (a target not
captured, a mission that could not continue), 2 bad options or input.
"""

from __future__ import annotations

import sys
from typing import TextIO

__all__ = ['EXIT_SUCCESS', 'EXIT_UNFINISHED', 'EXIT_USAGE', 'exit_code_of', 'fail']

EXIT_SUCCESS = 0
EXIT_UNFINISHED = 1
EXIT_USAGE = 2


def exit_code_of(error: BaseException) -> int:
    """The exit code an error asks for (its ``exit_code``), else :data:`EXIT_USAGE`."""
    code = getattr(error, 'exit_code', EXIT_USAGE)
    return code if isinstance(code, int) else EXIT_USAGE


def fail(
    program: str, error: BaseException | str, code: int | None = None, *, file: TextIO | None = None
) -> int:
    """Print ``<program>: <error>`` as one line on stderr and return the exit code.

    Args:
        program: the tool's name.
        error: what went wrong (an exception's message); line breaks become spaces.
        code: the exit code; None takes :func:`exit_code_of` of an exception, else 2.
        file: where to write (default: sys.stderr).
    """
    text = ' '.join(str(error).splitlines())
    print(f'{program}: {text}', file=file if file is not None else sys.stderr)
    if code is not None:
        return code
    return exit_code_of(error) if isinstance(error, BaseException) else EXIT_USAGE
