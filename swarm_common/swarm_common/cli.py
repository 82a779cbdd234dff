"""Conventions of the suite's command-line tools: exit codes, one-line errors, ``--debug``.

Exit codes (the same for every tool; each tool's ``--help`` repeats them):

- 0 (:data:`EXIT_SUCCESS`): the tool did what was asked;
- 1 (:data:`EXIT_UNFINISHED`): a mission ran but did not finish (a target not captured, a
  mission that could not continue), some runs of a batch failed, or an unexpected error
  (a bug: ``--debug`` shows where);
- 2 (:data:`EXIT_USAGE`): bad options or input (a file, a value, an output in the way);
  nothing was run, nothing was written;
- 130 (:data:`EXIT_INTERRUPTED`): stopped by Ctrl-C (SIGINT); what was finished is kept.

An entry point is ``run_tool(program, body, argv)``: ``body`` parses with
:class:`ToolParser` (argparse that raises :class:`swarm_common.errors.UsageError` instead of
printing the usage) and raises the library's precise exceptions; :func:`run_tool` prints each
as one line, ``<program>: <what is wrong>``, on stderr, with the traceback only under
``--debug``.
"""

from __future__ import annotations

import argparse
import sys
import traceback
from collections.abc import Callable, Sequence
from typing import Any, NoReturn, TextIO

__all__ = [
    'EXIT_CODES_HELP',
    'EXIT_INTERRUPTED',
    'EXIT_SUCCESS',
    'EXIT_UNFINISHED',
    'EXIT_USAGE',
    'ToolParser',
    'describe_os_error',
    'exit_code_of',
    'fail',
    'run_tool',
]

EXIT_SUCCESS = 0
EXIT_UNFINISHED = 1
EXIT_USAGE = 2
EXIT_INTERRUPTED = 130

EXIT_CODES_HELP = (
    'exit codes: 0 done; 1 the mission did not finish (or an unexpected error); '
    '2 bad options or input, nothing run; 130 interrupted (Ctrl-C), finished work kept. '
    'Errors are one line on stderr; --debug adds the traceback.'
)


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
    text = ' '.join(str(error).split()) or type(error).__name__
    print(f'{program}: {text}', file=file if file is not None else sys.stderr, flush=True)
    if code is not None:
        return code
    return exit_code_of(error) if isinstance(error, BaseException) else EXIT_USAGE


def describe_os_error(error: OSError) -> str:
    """``<file>: <reason>`` of an operating-system error (``runs/x: Permission denied``)."""
    reason = error.strerror or str(error) or type(error).__name__
    if error.filename is None:
        return reason
    where = str(error.filename)
    if getattr(error, 'filename2', None) is not None:
        where += f' -> {error.filename2}'
    return f'{where}: {reason}'


class ToolParser(argparse.ArgumentParser):
    """argparse for the suite's tools: errors raise, ``--debug`` and the exit codes built in.

    A malformed command line raises :class:`swarm_common.errors.UsageError` with argparse's
    one-line message (``argument --robots: invalid int value: 'x'``) instead of printing the
    usage and exiting, so :func:`run_tool` reports it like any other bad input. The epilog
    lists the exit codes unless one is given. Options are never abbreviated, so a misspelt
    option is an error rather than another option. Sub-command parsers are ToolParsers too and
    accept ``--debug`` after the sub-command.
    """

    def __init__(self, *args: object, debug_option: bool = True, **kwargs: object) -> None:
        kwargs.setdefault('epilog', EXIT_CODES_HELP)
        kwargs.setdefault('allow_abbrev', False)  # '--robot 3' is an error, not --robots
        super().__init__(*args, **kwargs)  # type: ignore[arg-type]
        if debug_option:
            self.add_argument('--debug', action='store_true', help='show the traceback of an error')

    def add_subparsers(self, **kwargs: Any) -> Any:
        kwargs.setdefault('parser_class', _SubcommandParser)
        return super().add_subparsers(**kwargs)

    def error(self, message: str) -> NoReturn:
        from swarm_common.errors import UsageError

        raise UsageError(f'{message} (see {self.prog} --help)')


class _SubcommandParser(ToolParser):
    """A sub-command's parser: ``--debug`` may follow the sub-command, default left alone."""

    def __init__(self, *args: object, **kwargs: object) -> None:
        super().__init__(*args, debug_option=False, **kwargs)
        self.add_argument(
            '--debug',
            action='store_true',
            default=argparse.SUPPRESS,
            help='show the traceback of an error',
        )


def _debug_requested(argv: Sequence[str]) -> bool:
    for item in argv:
        if item == '--':
            return False
        if item == '--debug':
            return True
    return False


def run_tool(
    program: str,
    body: Callable[[list[str]], int | None],
    argv: Sequence[str] | None = None,
    *,
    stderr: TextIO | None = None,
) -> int:
    """Run a tool's ``body(argv)`` and turn whatever it raises into one line and an exit code.

    - :class:`swarm_common.errors.SwarmError`: its message, its ``exit_code`` (2 unless the
      error says otherwise);
    - ``OSError`` not wrapped by the library: ``<file>: <reason>``, exit code 2;
    - ``KeyboardInterrupt``: ``interrupted``, exit code 130;
    - ``SystemExit`` (argparse's ``--help``): its code;
    - anything else is a bug: ``unexpected error: <type>: <message>``, exit code 1.

    With ``--debug`` in ``argv`` (before a ``--``) the traceback is printed first.

    Returns:
        the exit code (``body``'s return value, None meaning 0).
    """
    from swarm_common.errors import SwarmError

    args = list(sys.argv[1:] if argv is None else argv)
    debug = _debug_requested(args)
    err = stderr if stderr is not None else sys.stderr

    def report(error: BaseException, text: str | BaseException, code: int | None) -> int:
        if debug:
            traceback.print_exception(error, file=err)
        return fail(program, text, code, file=err)

    try:
        code = body(args)
    except SystemExit as stop:
        if stop.code is None or isinstance(stop.code, int):
            return int(stop.code or 0)
        return fail(program, str(stop.code), EXIT_USAGE, file=err)
    except KeyboardInterrupt as stop:
        return report(stop, 'interrupted', EXIT_INTERRUPTED)
    except SwarmError as error:
        return report(error, error, None)
    except OSError as error:
        return report(error, describe_os_error(error), EXIT_USAGE)
    except Exception as error:
        hint = '' if debug else ' (run with --debug for the traceback)'
        text = f'unexpected error: {type(error).__name__}: {error}{hint}'
        return report(error, text, EXIT_UNFINISHED)
    return EXIT_SUCCESS if code is None else int(code)
