"""Exceptions of the sites package.

Every error says where the problem is: a file with its line and column (``.lay`` layouts), a
file with its key path and line (site files), or world coordinates in metres (sites built in
code). :class:`SiteError` is the base class, so callers that only care that a site is unusable
catch that one; it is a :class:`swarm_sim.errors.SimulationError`, so it is rooted at
:class:`swarm_common.errors.SwarmError` like every error the suite raises on purpose.

Problems that leave a usable site (a sealed void read as solid, a departure point inside a
room) are not errors: they are :class:`SiteWarning` items, which the importers turn into the
one-line texts of :attr:`swarm_sim.sites.model.Site.warnings`.
"""

from __future__ import annotations

from dataclasses import dataclass

from swarm_sim.errors import SimulationError

__all__ = [
    'GeneratorError',
    'LayoutError',
    'SiteError',
    'SiteFileError',
    'SiteValidationError',
    'SiteWarning',
    'format_key_path',
]


class SiteError(SimulationError):
    """Base class of every error raised by :mod:`swarm_sim.sites`."""


@dataclass(frozen=True)
class SiteWarning:
    """A problem that leaves the site usable, with the place it was found.

    Attributes:
        message: one line saying what is odd and what the site does about it.
        position_m: (x, y) [m] of the place, when there is one (layout importers turn it
            into a line and column).
        key_path: the site-file key path of the item concerned, when there is one.
    """

    message: str
    position_m: tuple[float, float] | None = None
    key_path: tuple[str | int, ...] = ()


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
