"""Exceptions of the sites package.

Every error says where the problem is: a file with its line and column (``.lay`` layouts), a
file with its key path and line (site files), or world coordinates in metres (sites built in
code). :class:`SiteError` is the base class, so callers that only care that a site is unusable
catch that one.
"""

from __future__ import annotations

__all__ = [
    'GeneratorError',
    'LayoutError',
    'SiteError',
    'SiteFileError',
    'SiteValidationError',
    'format_key_path',
]


class SiteError(Exception):
    """Base class of every error raised by :mod:`swarm_sim.sites`."""


class SiteValidationError(SiteError):
    """A site violates an invariant (open enclosure, unreachable room, blocked departure...).

    Attributes:
        position_m: (x, y) in metres of the place the problem was found, when there is one.
        key_path: the site-file key path of the offending item (e.g. ``('rooms', 3)``), when
            the problem belongs to one item; the file loader turns it into a line number.
    """

    def __init__(
        self,
        message: str,
        *,
        position_m: tuple[float, float] | None = None,
        key_path: tuple[str | int, ...] = (),
    ) -> None:
        super().__init__(message)
        self.message = message
        self.position_m = position_m
        self.key_path = key_path


class GeneratorError(SiteError):
    """The generator was given parameters it cannot honour (e.g. too many rooms)."""


class LayoutError(SiteError):
    """A ``.lay`` text layout is malformed or describes an invalid site.

    The message reads like a compiler diagnostic, ``plan.lay:12:7: <what is wrong>``, with
    1-based line and column.
    """

    def __init__(self, source: str, line: int | None, column: int | None, message: str) -> None:
        self.source = source
        self.line = line
        self.column = column
        self.message = message
        where = source
        if line is not None:
            where += f':{line}'
            if column is not None:
                where += f':{column}'
        super().__init__(f'{where}: {message}')


class SiteFileError(SiteError):
    """A YAML site file is malformed or describes an invalid site.

    The message names the file, the line (when known) and the key path, e.g.
    ``site.yaml:40: rooms[3].rects[0]: x1 must be greater than x0``.
    """

    def __init__(
        self,
        source: str,
        message: str,
        *,
        key_path: tuple[str | int, ...] = (),
        line: int | None = None,
    ) -> None:
        self.source = source
        self.key_path = key_path
        self.line = line
        self.message = message
        where = source if line is None else f'{source}:{line}'
        path = format_key_path(key_path)
        super().__init__(f'{where}: {path}: {message}' if path else f'{where}: {message}')


def format_key_path(key_path: tuple[str | int, ...]) -> str:
    """Render ``('rooms', 3, 'rects')`` as ``rooms[3].rects``."""
    text = ''
    for key in key_path:
        if isinstance(key, int):
            text += f'[{key}]'
        else:
            text += f'.{key}' if text else key
    return text
