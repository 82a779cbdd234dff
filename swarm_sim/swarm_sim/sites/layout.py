"""Text ``.lay`` layouts: the OA-Bug authors' floor-plan format, read into a :class:`Site`.

One character per grid vertex, 1 cell = 4/15 m (see :mod:`.lattice` for the geometry):

===========  ================================================================================
``%``        wall vertex; straight runs of them are wall lines
`` ``        free space (corridors, and room interiors in unlabelled plans)
``.``        free space too (the authors' ``layout.lay`` marks floors with it)
``A`` and up interior of a room in a *labelled* layout, one letter per room: any printable
             character from ``A`` on except ``D`` (the authors' generator labels room i with
             chr(65 + i), so past ``Z`` come ``[ \\ ] ^ _ ```` , lower case and beyond).
             In an unlabelled plan a letter means nothing and is read as free space (with
             a warning), as the authors' simulator reads every character but ``%``.
``0``-``9``  interior of a room holding a victim (labelled layouts)
``/``        door to a corridor (labelled); on the outer border: the site's single entrance
``#``        door between two rooms (labelled)
``D``        the departure point, in both kinds of layout (a group of ``D`` marks its centre);
             never a room
===========  ================================================================================

The first and last lines and columns are the enclosure: they hold only ``%``, except one run
of ``/`` marking the entrance.

*Labelled* layouts (the authors' generator output) name every room; each 4-connected group of
one letter is a room, and it must be closed: every vertex around it is a wall or a door mark.
*Unlabelled* layouts (the authors' building plans) only draw walls; rooms are then found as
the areas closed off by door gaps: a free vertex between two wall vertices of a straight
line, with free space on both sides of the line that widens on at least one side (in the
authors' simulator a door is a missing vertex in a wall line; wider gaps, up to
``max_door_cells``, must widen on both sides). A one-cell-wide room whose door leads into
another one-cell-wide room is found merged with it, and a one-cell-wide corridor behind a gap
counts as a room. Auto mode reads a layout as labelled when it has door marks (``/`` or
``#`` inside the enclosure) or victim digits.

Departure points: a ``D`` mark (named ``departure_name``). Without one, labelled layouts
follow the authors' runner: "center" at the middle of the bounds and "edge" 2.5 cells inside
the entrance (or above the middle of the bottom wall when there is no entrance), heading into
the building; unlabelled plans start from the middle of the bounds ("center"), as the
authors' simulator does. A departure point inside a solid block of wall (an island of the
plan) or in an enclosed area cut off from the rooms is an error; inside a room it is a
warning (robots start in that room).

A *sealed void*, an enclosed area with no door that no departure point is in and that holds
no room, is read as solid, with a warning (the authors' building plans have such boxes).
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Mapping
from dataclasses import dataclass
from enum import StrEnum
from functools import cached_property
from pathlib import Path
from typing import Any, Final

import numpy as np
from scipy import ndimage
from swarm_common.outputs import write_text_atomic

from swarm_sim.sites import lattice
from swarm_sim.sites.door_gaps import closing_masks, find_door_gaps
from swarm_sim.sites.errors import LayoutError, SiteValidationError, SiteWarning, format_key_path
from swarm_sim.sites.model import (
    CELL_M,
    NO_ROOM,
    DeparturePoint,
    Door,
    Room,
    Site,
    check_site_size,
)
from swarm_sim.sites.validation import validate_site

__all__ = [
    'CORRIDOR_DOOR',
    'DEPARTURE',
    'FLOOR',
    'FREE',
    'MAX_LAYOUT_CHARACTERS',
    'MAX_LAYOUT_COLUMNS',
    'MAX_LAYOUT_LINES',
    'ROOM_DOOR',
    'WALL',
    'Layout',
    'LayoutImport',
    'LayoutMode',
    'detect_mode',
    'import_layout',
    'is_room_label',
    'layout_to_site',
    'parse_layout',
    'read_layout',
    'write_layout',
]

WALL: Final = ord('%')
FREE: Final = ord(' ')
FLOOR: Final = ord('.')
CORRIDOR_DOOR: Final = ord('/')
ROOM_DOOR: Final = ord('#')
DEPARTURE: Final = ord('D')
_LABEL_FIRST: Final = ord('A')
_DIGIT_FIRST: Final = ord('0')
_DIGIT_LAST: Final = ord('9')
EDGE_INSET_CELLS: Final = 2.5
"""How far inside the entrance the "edge" departure point sits [cells] (authors' runner)."""

MAX_LAYOUT_LINES: Final = 2000
"""Most lines a layout may have (the paper's Big site has 60)."""
MAX_LAYOUT_COLUMNS: Final = 2000
"""Most characters a layout line may have (Big has 120)."""
MAX_LAYOUT_CHARACTERS: Final = 600_000
"""Most characters a layout may have in all (Big has 7200; a site is validated on a raster
of 16 cells per character, which :data:`~swarm_sim.sites.model.MAX_RASTER_CELLS` bounds)."""
_SIZE_LIMITS: Final = (
    f'{MAX_LAYOUT_LINES} lines, {MAX_LAYOUT_COLUMNS} columns and {MAX_LAYOUT_CHARACTERS} characters'
)
_MAX_LAYOUT_BYTES: Final = 4 * MAX_LAYOUT_CHARACTERS + 2 * MAX_LAYOUT_LINES + 4096
"""Largest .lay file read: the limits in 4-byte UTF-8 characters, CR LF line ends and some
trailing blank lines."""

_KNOWN_CHARACTERS = (
    "'%' wall, ' ' and '.' free, 'A'-'z' room letters, '0'-'9' victim rooms, '/' and '#' "
    "doors, 'D' departure"
)
_SIDES: Final = ('top', 'bottom', 'left', 'right')


class LayoutMode(StrEnum):
    """How rooms are given in a layout."""

    AUTO = 'auto'
    """Labelled if the layout has door marks (``/``, ``#``) inside or victim digits."""
    LABELLED = 'labelled'
    """Rooms are letter/digit areas, doors are ``/`` and ``#``."""
    UNLABELLED = 'unlabelled'
    """Only walls; rooms are found behind door gaps; other marks read as free space."""


@dataclass(frozen=True, eq=False)
class Layout:
    """A parsed layout.

    Attributes:
        codes: (H, W) int32 Unicode code points, row 0 = first line of the file (read-only).
        source: where it came from, used in error messages (a file name).
    """

    codes: np.ndarray
    source: str = '<layout>'

    def __post_init__(self) -> None:
        codes = np.array(self.codes, dtype=np.int32, copy=True)
        if codes.ndim != 2 or codes.shape[0] < 3 or codes.shape[1] < 3:
            raise LayoutError(
                self.source,
                None,
                None,
                f'a layout needs at least 3 x 3 characters, got shape {codes.shape}',
            )
        _check_layout_size(self.source, int(codes.shape[0]), int(codes.shape[1]))
        codes.flags.writeable = False
        object.__setattr__(self, 'codes', codes)

    @property
    def shape(self) -> tuple[int, int]:
        """(lines, columns)."""
        return (int(self.codes.shape[0]), int(self.codes.shape[1]))

    def to_text(self) -> str:
        """The layout as file text, one line per row, ending with a newline."""
        return ''.join(''.join(map(chr, row.tolist())) + '\n' for row in self.codes)


@dataclass(frozen=True)
class LayoutImport:
    """Result of importing a layout.

    Attributes:
        site: the validated site; ``site.warnings`` holds the import's warnings.
        mode: the mode used (AUTO resolved).
        rooms_found: number of rooms.
        doors_found: number of doors (the entrance not counted).
        voids_found: sealed voids read as solid.
    """

    site: Site
    mode: LayoutMode
    rooms_found: int
    doors_found: int
    voids_found: int = 0


def is_room_label(code: int) -> bool:
    """Whether a character code can label a room in a labelled layout (``A`` and up except
    the departure mark ``D``, printable, not white space)."""
    char = chr(code)
    return code >= _LABEL_FIRST and code != DEPARTURE and char.isprintable() and not char.isspace()


def _is_label(codes: np.ndarray) -> np.ndarray:
    return (codes >= _LABEL_FIRST) & (codes != DEPARTURE)


def _is_digit(codes: np.ndarray) -> np.ndarray:
    return (codes >= _DIGIT_FIRST) & (codes <= _DIGIT_LAST)


def _check_layout_size(source: str, lines: int, columns: int) -> None:
    """Raise :class:`LayoutError` for a layout larger than the limits (checked before the
    layout is read character by character)."""
    if (
        lines <= MAX_LAYOUT_LINES
        and columns <= MAX_LAYOUT_COLUMNS
        and lines * columns <= MAX_LAYOUT_CHARACTERS
    ):
        return
    msg = (
        f'the layout is {lines} lines of {columns} characters; a layout may have at most '
        f'{_SIZE_LIMITS}'
    )
    raise LayoutError(source, None, None, msg)


def parse_layout(text: str, source: str = '<layout>') -> Layout:
    """Parse layout text. Lines must all have the same length; trailing empty lines are
    ignored; ``\\r\\n`` line ends are accepted.

    Raises:
        LayoutError: ragged lines or an unknown character, with its line and column; a
            layout larger than :data:`MAX_LAYOUT_LINES` lines, :data:`MAX_LAYOUT_COLUMNS`
            columns or :data:`MAX_LAYOUT_CHARACTERS` characters.
    """
    lines = text.replace('\r\n', '\n').split('\n')
    while lines and lines[-1] == '':
        lines.pop()
    if not lines:
        raise LayoutError(source, None, None, 'the layout is empty')
    width = len(lines[0])
    _check_layout_size(source, len(lines), width)
    for number, line in enumerate(lines, start=1):
        if len(line) != width:
            msg = (
                f'line has {len(line)} characters, the first line has {width}; every line of '
                'a layout must be equally long'
            )
            raise LayoutError(source, number, None, msg)
        for column, char in enumerate(line, start=1):
            code = ord(char)
            known = code in (WALL, FREE, FLOOR, CORRIDOR_DOOR, ROOM_DOOR, DEPARTURE) or (
                _DIGIT_FIRST <= code <= _DIGIT_LAST or is_room_label(code)
            )
            if not known:
                msg = f'unknown character {char!r}; a layout uses {_KNOWN_CHARACTERS}'
                raise LayoutError(source, number, column, msg)
    flat = np.frombuffer(''.join(lines).encode('utf-32-le'), dtype='<u4')
    codes = flat.astype(np.int32).reshape(len(lines), width)
    return Layout(codes, source)


def read_layout(path: str | Path) -> Layout:
    """Read and parse a ``.lay`` file.

    Raises:
        LayoutError: an unreadable file, one larger than a layout of
            :data:`MAX_LAYOUT_CHARACTERS` can be, or a malformed layout (see
            :func:`parse_layout`).
    """
    path = Path(path)
    try:
        with path.open('rb') as file:
            data = file.read(_MAX_LAYOUT_BYTES + 1)
    except OSError as err:
        raise LayoutError(str(path), None, None, err.strerror or str(err)) from None
    if len(data) > _MAX_LAYOUT_BYTES:
        msg = (
            f'the file is larger than {_MAX_LAYOUT_BYTES} bytes, more than a layout of at most '
            f'{_SIZE_LIMITS} can take'
        )
        raise LayoutError(str(path), None, None, msg)
    try:
        text = data.decode('utf-8')
    except UnicodeDecodeError as err:
        before = data[: err.start]
        line = before.count(b'\n') + 1
        column = err.start - (before.rfind(b'\n') + 1) + 1
        raise LayoutError(str(path), line, column, 'the file is not UTF-8 text') from None
    return parse_layout(text, str(path))


def write_layout(layout: Layout, path: str | Path) -> None:
    """Write a layout as a ``.lay`` file."""
    write_text_atomic(path, layout.to_text())


def detect_mode(layout: Layout) -> LayoutMode:
    """LABELLED when door marks (``/``, ``#``) or victim digits appear inside the enclosure.

    Every room of a valid labelled layout has a marked door, so a layout without marks is
    read as a plan; its letters, if any, then mean nothing and read as free space.
    """
    inner = layout.codes[1:-1, 1:-1]
    labelled = _is_digit(inner) | (inner == CORRIDOR_DOOR) | (inner == ROOM_DOOR)
    return LayoutMode.LABELLED if bool(np.any(labelled)) else LayoutMode.UNLABELLED


def import_layout(
    path: str | Path,
    *,
    mode: LayoutMode | str = LayoutMode.AUTO,
    cell_m: float = CELL_M,
    name: str | None = None,
    departure_name: str = 'edge',
    departures: Mapping[str, tuple[float, float]] | None = None,
    max_door_cells: int = 1,
) -> LayoutImport:
    """Read a ``.lay`` file and turn it into a validated site (see :func:`layout_to_site`)."""
    layout = read_layout(path)
    return layout_to_site(
        layout,
        mode=mode,
        cell_m=cell_m,
        name=name if name is not None else Path(path).stem,
        departure_name=departure_name,
        departures=departures,
        max_door_cells=max_door_cells,
    )


def layout_to_site(
    layout: Layout,
    *,
    mode: LayoutMode | str = LayoutMode.AUTO,
    cell_m: float = CELL_M,
    name: str | None = None,
    departure_name: str = 'edge',
    departures: Mapping[str, tuple[float, float]] | None = None,
    max_door_cells: int = 1,
    seed: int | None = None,
) -> LayoutImport:
    """Build and validate the site a layout describes.

    Args:
        layout: the parsed layout.
        mode: labelled, unlabelled or auto (see :class:`LayoutMode`).
        cell_m: grid spacing [m]; the paper's 4/15 m by default.
        name: site name; defaults to the layout's source.
        departure_name: name given to the departure point marked ``D``.
        departures: explicit departure points, name -> (line, column) in the file (1-based,
            fractional values allowed: (15.5, 30.5) lies between four characters). They
            replace the ``D`` mark and the automatic ones.
        max_door_cells: widest door gap of an unlabelled plan, in missing vertices (the
            authors' doors miss one; a plan drawn with 0.8 m doors needs 2).
        seed: generator seed to record in the site, if the layout was generated.

    Returns:
        the import; its site's ``warnings`` list what was read leniently, each one line
        starting ``file:line:column:``.

    Raises:
        LayoutError: malformed or invalid layout, naming the line and column.
    """
    mode = LayoutMode(mode)
    if max_door_cells < 1:
        msg = f'max_door_cells must be at least 1, got {max_door_cells}'
        raise LayoutError(layout.source, None, None, msg)
    if not (math.isfinite(cell_m) and cell_m > 0):
        raise LayoutError(
            layout.source, None, None, f'cell size must be positive, got {cell_m!r} m'
        )
    if name is not None and not name:
        raise LayoutError(layout.source, None, None, 'the site name must not be empty')
    lines, columns = layout.shape
    try:
        check_site_size((columns - 1) * cell_m, (lines - 1) * cell_m, cell_m)
    except SiteValidationError as err:
        msg = (
            f'{lines} lines of {columns} characters at {cell_m:g} m per cell: '
            f'{format_key_path(err.key_path)}: {err.message}'
        )
        raise LayoutError(layout.source, None, None, msg) from None
    if mode is LayoutMode.AUTO:
        mode = detect_mode(layout)
    builder = _SiteBuilder(layout, cell_m, mode)
    entrance = builder.entrance()
    explicit = [builder.departure_at(n, line, col) for n, (line, col) in (departures or {}).items()]
    mark = builder.marked_departure_point(departure_name)
    if mode is LayoutMode.LABELLED:
        rooms, doors = builder.labelled_rooms_and_doors()
        points = explicit or ([mark] if mark else builder.runner_departure_points(entrance))
    else:
        points = explicit or [mark if mark else builder.middle_departure_point()]
        rooms, doors = builder.rooms_behind_door_gaps(points[0], max_door_cells)
    voids = builder.sealed_voids(points)
    builder.check_departure_places(points, voids)
    site = Site(
        name=name if name is not None else layout.source,
        width_m=(layout.shape[1] - 1) * cell_m,
        height_m=(layout.shape[0] - 1) * cell_m,
        walls=lattice.wall_segments(builder.wall, cell_m, voids),
        rooms=tuple(rooms),
        doors=tuple(doors),
        entrance=builder.entrance_door(entrance),
        departure_points={p.name: p for p in points},
        grid_m=cell_m,
        seed=seed,
    )
    try:
        checked = validate_site(site)
    except SiteValidationError as err:
        line, column = builder.line_column(err.position_m)
        raise LayoutError(layout.source, line, column, err.message) from err
    warnings = [*builder.warnings, *checked]
    if warnings:
        site = dataclasses.replace(site, warnings=tuple(builder.describe(w) for w in warnings))
    return LayoutImport(
        site=site,
        mode=mode,
        rooms_found=len(rooms),
        doors_found=len(doors),
        voids_found=builder.voids_found,
    )


def _nearest(value: float) -> int:
    """The nearest integer, halves rounded down (a place between two characters is named by
    the first one, whatever its parity)."""
    return math.ceil(value - 0.5)


class _SiteBuilder:
    """The steps of turning a layout into site parts; every error names line and column."""

    def __init__(self, layout: Layout, cell_m: float, mode: LayoutMode) -> None:
        self.layout = layout
        self.cell_m = cell_m
        self.n_rows, self.n_cols = layout.shape
        self.warnings: list[SiteWarning] = []
        self.voids_found = 0
        codes = np.array(layout.codes, copy=True)
        codes[codes == FLOOR] = FREE
        if mode is LayoutMode.UNLABELLED:
            self._free_meaningless_marks(codes)
        self.codes = codes
        self.wall = codes == WALL
        self.square_rooms = np.full((self.n_rows - 1, self.n_cols - 1), NO_ROOM, dtype=np.int64)

    def error(self, row: int | None, col: int | None, message: str) -> LayoutError:
        return LayoutError(
            self.layout.source,
            None if row is None else row + 1,
            None if col is None else col + 1,
            message,
        )

    def warn(self, row: float, col: float, message: str) -> None:
        self.warnings.append(SiteWarning(message, position_m=self.xy(row, col)))

    def describe(self, warning: SiteWarning) -> str:
        """A warning as one line, ``file:line:column: message``."""
        line, column = self.line_column(warning.position_m)
        return str(LayoutError(self.layout.source, line, column, warning.message))

    def xy(self, row: float, col: float) -> tuple[float, float]:
        return lattice.vertex_to_xy(row, col, self.n_rows, self.cell_m)

    def line_column(self, position_m: tuple[float, float] | None) -> tuple[int | None, int | None]:
        """1-based line and column of the vertex nearest to a world position."""
        if position_m is None:
            return (None, None)
        row, col = lattice.xy_to_vertex(position_m[0], position_m[1], self.n_rows, self.cell_m)
        row, col = _nearest(row), _nearest(col)
        return (min(max(row, 0), self.n_rows - 1) + 1, min(max(col, 0), self.n_cols - 1) + 1)

    def _free_meaningless_marks(self, codes: np.ndarray) -> None:
        """In a plan, room letters, digits and inner door marks mean nothing: read them as
        free space, as the authors' simulator does, with one warning per character."""
        inner = np.zeros(codes.shape, dtype=bool)
        inner[1:-1, 1:-1] = True
        marks = inner & (
            _is_label(codes) | _is_digit(codes) | (codes == ROOM_DOOR) | (codes == CORRIDOR_DOOR)
        )
        for code in np.unique(codes[marks]).tolist():
            places = np.argwhere(marks & (codes == code))
            row, col = (int(v) for v in places[0])
            count = len(places)
            msg = (
                f'{chr(code)!r} ({count} place{"s" if count > 1 else ""}) has no meaning in an '
                "unlabelled plan and is read as free space, as in the authors' simulator (a "
                "labelled layout has door marks '/' or '#')"
            )
            self.warn(row, col, msg)
        codes[marks] = FREE

    # Enclosure and entrance -------------------------------------------------------------

    def _border_cells(self) -> list[tuple[int, int]]:
        """Border vertices in order around the enclosure (clockwise from the top-left)."""
        h, w = self.n_rows, self.n_cols
        top = [(0, c) for c in range(w)]
        right = [(r, w - 1) for r in range(1, h)]
        bottom = [(h - 1, c) for c in range(w - 2, -1, -1)]
        left = [(r, 0) for r in range(h - 2, 0, -1)]
        return top + right + bottom + left

    def entrance(self) -> list[tuple[int, int]]:
        """Border vertices marked ``/`` (one straight run, or empty)."""
        ring = self._border_cells()
        corners = {
            (0, 0),
            (0, self.n_cols - 1),
            (self.n_rows - 1, 0),
            (self.n_rows - 1, self.n_cols - 1),
        }
        runs: list[list[tuple[int, int]]] = []
        previous_was_door = False
        for row, col in ring:
            code = int(self.codes[row, col])
            if code == CORRIDOR_DOOR:
                if (row, col) in corners:
                    raise self.error(
                        row, col, 'the entrance cannot be at a corner of the enclosure'
                    )
                if previous_was_door:
                    runs[-1].append((row, col))
                else:
                    runs.append([(row, col)])
                previous_was_door = True
                continue
            previous_was_door = False
            if code != WALL:
                what = 'a gap' if code == FREE else f'{chr(int(self.layout.codes[row, col]))!r}'
                msg = (
                    f'the enclosure is open: the outer wall has {what} here; the first and last '
                    "lines and columns must be '%', except one run of '/' marking the entrance "
                    "(fill the outside of a building that is not rectangular with '%')"
                )
                raise self.error(row, col, msg)
        if len(runs) > 1:
            runs = sorted(sorted(run) for run in runs)
            first = runs[0][0]
            row, col = runs[1][0]
            msg = (
                f'a second entrance; a site has a single entrance (the first is at line '
                f'{first[0] + 1}, column {first[1] + 1})'
            )
            raise self.error(row, col, msg)
        return runs[0] if runs else []

    def entrance_door(self, cells: list[tuple[int, int]]) -> Door | None:
        if not cells:
            return None
        rows = [r for r, _ in cells]
        cols = [c for _, c in cells]
        if len(set(rows)) == 1:  # top or bottom wall
            row = rows[0]
            a, b = self.xy(row, min(cols) - 1), self.xy(row, max(cols) + 1)
            inner_square = (0 if row == 0 else self.n_rows - 2, min(cols))
        else:
            col = cols[0]
            a, b = self.xy(min(rows) - 1, col), self.xy(max(rows) + 1, col)
            inner_square = (min(rows), 0 if col == 0 else self.n_cols - 2)
        room_id = int(self.square_rooms[inner_square])
        return Door((*a, *b), () if room_id == NO_ROOM else (room_id,))

    def _sealed(self) -> np.ndarray:
        """Vertices that block: walls and the entrance (closed for every area check)."""
        sealed = self.wall.copy()
        border = np.ones_like(sealed)
        border[1:-1, 1:-1] = False
        sealed |= border & (self.codes == CORRIDOR_DOOR)
        return sealed

    # Labelled layouts -------------------------------------------------------------------

    def labelled_rooms_and_doors(self) -> tuple[list[Room], list[Door]]:
        codes = self.codes
        inner = np.zeros_like(self.wall)
        inner[1:-1, 1:-1] = True
        interior = (_is_label(codes) | _is_digit(codes)) & inner
        # Rooms are 4-connected groups of one letter; ids follow reading order.
        components, count = ndimage.label(interior)
        index = np.arange(1, count + 1)
        low = np.asarray(ndimage.minimum(codes, components, index), dtype=np.int64)
        high = np.asarray(ndimage.maximum(codes, components, index), dtype=np.int64)
        if np.any(low != high):
            self._report_touching_rooms(components == int(np.argmax(low != high)) + 1)
        vertex_rooms = np.where(components > 0, components, NO_ROOM).astype(np.int64)
        _, first = np.unique(components.ravel(), return_index=True)
        first_cell = {k: divmod(int(first[k]), self.n_cols) for k in range(1, count + 1)}
        self._square_rooms_from_vertices(vertex_rooms)
        rooms = []
        for room_id, where in enumerate(ndimage.find_objects(np.maximum(self.square_rooms, 0)), 1):
            code = int(low[room_id - 1])
            rects = self._room_rects(room_id, where)
            is_digit = _DIGIT_FIRST <= code <= _DIGIT_LAST
            rooms.append(Room(room_id, rects, label=chr(code), has_victim=is_digit))
        self._check_rooms_closed(rooms, components)
        self._check_rooms_have_openings(rooms, first_cell)
        self._warn_room_shaped_departure_mark()
        return rooms, self._marked_doors()

    def _ring(self, inside: np.ndarray) -> np.ndarray:
        """(H, W) vertices around a vertex set: corners of the squares touching it, minus the
        set itself."""
        squares = inside[:-1, :-1] | inside[:-1, 1:] | inside[1:, :-1] | inside[1:, 1:]
        corners = np.zeros_like(inside)
        corners[:-1, :-1] |= squares
        corners[:-1, 1:] |= squares
        corners[1:, :-1] |= squares
        corners[1:, 1:] |= squares
        return corners & ~inside

    def _warn_room_shaped_departure_mark(self) -> None:
        """'D' marks the departure, never a room; a 'D' group walled in like a room (walls
        and a door mark all round) is most likely a room lettered 'D', as the authors'
        generator letters its fourth room."""
        mark = self.codes == DEPARTURE
        if not np.any(mark):
            return
        ring = self._ring(mark)
        doors = (self.codes == CORRIDOR_DOOR) | (self.codes == ROOM_DOOR)
        if np.all((self.wall | doors)[ring]) and np.any(doors[ring]):
            row, col = (int(v) for v in np.argwhere(mark)[0])
            msg = (
                "the departure mark 'D' fills an area walled in like a room; 'D' is never a "
                "room letter here (the authors' generator letters its fourth room 'D'): "
                're-letter the room if it is one'
            )
            self.warn(row, col, msg)

    def _room_rects(self, room_id: int, where: tuple[slice, slice] | None) -> np.ndarray:
        """Rectangles of a room's squares; one rectangle when they fill their bounding box."""
        if where is None:
            return lattice.square_to_rects(self.square_rooms == room_id, self.cell_m)
        rows, cols = where
        if np.all(self.square_rooms[where] == room_id):
            n_square_rows = self.n_rows - 1
            return np.array(
                [
                    [
                        cols.start * self.cell_m,
                        (n_square_rows - rows.stop) * self.cell_m,
                        cols.stop * self.cell_m,
                        (n_square_rows - rows.start) * self.cell_m,
                    ]
                ]
            )
        return lattice.square_to_rects(self.square_rooms == room_id, self.cell_m)

    def _report_touching_rooms(self, group: np.ndarray) -> None:
        """Raise at the first place where one connected letter group changes letter."""
        codes = self.codes
        right = group[:, :-1] & group[:, 1:] & (codes[:, :-1] != codes[:, 1:])
        down = group[:-1, :] & group[1:, :] & (codes[:-1, :] != codes[1:, :])
        places = [(int(r), int(c), int(codes[r, c + 1])) for r, c in np.argwhere(right)]
        places += [(int(r), int(c), int(codes[r + 1, c])) for r, c in np.argwhere(down)]
        row, col, other = min(places)
        labels = sorted({chr(int(codes[row, col])), chr(other)})
        msg = f'rooms {" and ".join(map(repr, labels))} touch without a wall between them'
        raise self.error(row, col, msg)

    def _square_rooms_from_vertices(self, vertex_rooms: np.ndarray) -> None:
        """A square belongs to the room one of its corners is inside of: a room's area spans
        its wall lines."""
        corners = np.stack(
            [
                vertex_rooms[:-1, :-1],
                vertex_rooms[:-1, 1:],
                vertex_rooms[1:, :-1],
                vertex_rooms[1:, 1:],
            ]
        )
        square_rooms = corners.max(axis=0)
        clash = np.any((corners != NO_ROOM) & (corners != square_rooms), axis=0)
        if np.any(clash):
            i, j = (int(v) for v in np.argwhere(clash)[0])
            block = self.codes[i : i + 2, j : j + 2]
            labels = sorted({chr(c) for c in block.ravel().tolist() if c not in (WALL, FREE)})
            msg = f'rooms {" and ".join(map(repr, labels))} touch without a wall between them'
            raise self.error(i, j, msg)
        self.square_rooms = square_rooms

    def _check_rooms_closed(self, rooms: list[Room], components: np.ndarray) -> None:
        """Every vertex around a room's letters is a wall or a door mark: a room open on a
        side would spread its area (which spans its wall lines) over the corridor."""
        closing = self.wall | (self.codes == CORRIDOR_DOOR) | (self.codes == ROOM_DOOR)
        for room in rooms:
            letters = components == room.room_id
            holes = self._ring(letters) & ~closing
            if np.any(holes):
                raise self._open_room_error(room, letters, holes)

    def _open_room_error(self, room: Room, letters: np.ndarray, holes: np.ndarray) -> LayoutError:
        rows, cols = np.nonzero(letters)
        r0, r1, c0, c1 = int(rows.min()), int(rows.max()), int(cols.min()), int(cols.max())
        named = f'room {room.label!r} is not closed'
        what = "neither '%' nor a door mark ('/' or '#')"
        first_row, first_col = (int(v) for v in np.argwhere(holes)[0])
        if not np.all(letters[r0 : r1 + 1, c0 : c1 + 1]):  # not a rectangle
            return self.error(
                first_row, first_col, f'{named}: its wall has an opening here, {what}'
            )
        lines: dict[str, tuple[Any, Any]] = {
            'top': (r0 - 1, slice(c0, c1 + 1)),
            'bottom': (r1 + 1, slice(c0, c1 + 1)),
            'left': (slice(r0, r1 + 1), c0 - 1),
            'right': (slice(r0, r1 + 1), c1 + 1),
        }
        for side in _SIDES:
            row, col = lines[side]
            if np.all(holes[row, col]):
                if isinstance(row, int):
                    span = f'line {row + 1}, columns {c0 + 1}-{c1 + 1}'
                    place = (row, c0)
                else:
                    span = f'column {col + 1}, lines {r0 + 1}-{r1 + 1}'
                    place = (r0, int(col))
                return self.error(*place, f'{named}: its {side} wall ({span}) is missing')
        r, c = first_row, first_col
        sides = [s for s, hit in zip(_SIDES, (r < r0, r > r1, c < c0, c > c1), strict=True) if hit]
        where = f'{sides[0]} wall' if len(sides) == 1 else f'{sides[0]}-{sides[1]} corner'
        return self.error(r, c, f'{named}: its {where} has an opening here, {what}')

    def _check_rooms_have_openings(
        self, rooms: list[Room], first_cell: dict[int, tuple[int, int]]
    ) -> None:
        """A room whose connected free space holds nothing but itself has no door."""
        areas, count = lattice.square_labels(self.wall)
        pairs = np.unique(np.stack([areas.ravel(), self.square_rooms.ravel()]), axis=1)
        closed_area = np.bincount(pairs[0], minlength=count + 1) == 1
        open_rooms = set(np.unique(self.square_rooms[~closed_area[areas]]).tolist())
        for room in rooms:
            if room.room_id not in open_rooms:
                row, col = first_cell[room.room_id]
                raise self.error(row, col, f'room {room.label!r} has no door')

    def _marked_doors(self) -> list[Door]:
        codes = self.codes
        marks = np.zeros_like(self.wall)
        marks[1:-1, 1:-1] = (codes[1:-1, 1:-1] == CORRIDOR_DOOR) | (codes[1:-1, 1:-1] == ROOM_DOOR)
        components, count = ndimage.label(marks)
        doors = []
        for k in range(1, count + 1):
            cells = np.argwhere(components == k)
            rows, cols = cells[:, 0], cells[:, 1]
            r0, c0 = int(rows.min()), int(cols.min())
            r1, c1 = int(rows.max()), int(cols.max())
            wall = self.wall
            horizontal = r0 == r1 and bool(wall[r0, c0 - 1] and wall[r0, c1 + 1])
            vertical = c0 == c1 and bool(wall[r0 - 1, c0] and wall[r1 + 1, c0])
            if horizontal == vertical:
                row, col = (int(v) for v in cells[0])
                msg = (
                    f'door {chr(int(codes[row, col]))!r} is not a gap in a straight wall line '
                    "(it needs '%' on both ends along one line)"
                )
                raise self.error(row, col, msg)
            if horizontal:
                segment = (*self.xy(r0, c0 - 1), *self.xy(r0, c1 + 1))
                sides = (self.square_rooms[r0 - 1, c0], self.square_rooms[r0, c0])
            else:
                segment = (*self.xy(r1 + 1, c0), *self.xy(r0 - 1, c0))
                sides = (self.square_rooms[r0, c0 - 1], self.square_rooms[r0, c0])
            room_ids = tuple(sorted({int(s) for s in sides} - {NO_ROOM}))
            doors.append(Door(segment, room_ids))
        return doors

    def runner_departure_points(self, entrance: list[tuple[int, int]]) -> list[DeparturePoint]:
        """The authors' runner: centre of the bounds, and 2.5 cells inside the entrance."""
        h, w = self.n_rows, self.n_cols
        centre = DeparturePoint('center', *self.xy((h - 1) / 2, (w - 1) / 2))
        if entrance:
            rows = [r for r, _ in entrance]
            cols = [c for _, c in entrance]
            row, col = (min(rows) + max(rows)) / 2, (min(cols) + max(cols)) / 2
        else:
            row, col = h - 1, (w - 1) / 2
        if row == h - 1:
            row, heading = row - EDGE_INSET_CELLS, math.pi / 2
        elif row == 0:
            row, heading = row + EDGE_INSET_CELLS, -math.pi / 2
        elif col == 0:
            col, heading = col + EDGE_INSET_CELLS, 0.0
        else:
            col, heading = col - EDGE_INSET_CELLS, math.pi
        return [centre, DeparturePoint('edge', *self.xy(row, col), heading_rad=heading)]

    def departure_at(self, name: str, line: float, column: float) -> DeparturePoint:
        """A departure point given by 1-based (line, column) in the file."""
        row, col = line - 1, column - 1
        if not (0 <= row <= self.n_rows - 1 and 0 <= col <= self.n_cols - 1):
            msg = (
                f'departure point {name!r} at line {line}, column {column} lies outside the layout'
            )
            raise LayoutError(self.layout.source, None, None, msg)
        return DeparturePoint(name, *self.xy(row, col))

    def marked_departure_point(self, name: str) -> DeparturePoint | None:
        """The point marked ``D`` (the centre of its group), or None without a mark."""
        marks, count = ndimage.label(self.codes == DEPARTURE)
        if count == 0:
            return None
        if count > 1:
            first = np.argwhere(marks == 1)[0]
            row, col = (int(v) for v in np.argwhere(marks == 2)[0])
            msg = (
                "a second departure mark 'D'; the first is at line "
                f'{first[0] + 1}, column {first[1] + 1}'
            )
            raise self.error(row, col, msg)
        cells = np.argwhere(marks == 1)
        row, col = cells.mean(axis=0)
        return DeparturePoint(name, *self.xy(float(row), float(col)))

    def middle_departure_point(self) -> DeparturePoint:
        """A plan without ``D``: the middle of the bounds, where the authors' simulator puts
        its departure point then, named "center"."""
        row, col = (self.n_rows - 1) / 2, (self.n_cols - 1) / 2
        point = DeparturePoint('center', *self.xy(row, col))
        place = f'line {row + 1:g}, column {col + 1:g}'
        squares = self._squares_at(row, col)
        on_wall = len({int(a) for a in self._areas_at(squares)}) != 1
        if on_wall or all(self._solid[s] for s in squares):
            msg = (
                f"the plan has no departure mark 'D' and its middle ({place}), where the "
                "authors' simulator starts then, is in a wall; mark the departure with 'D'"
            )
            raise self.error(_nearest(row), _nearest(col), msg)
        msg = (
            f"no departure mark 'D': departure point 'center' is the middle of the plan "
            f"({place}), as in the authors' simulator"
        )
        self.warn(row, col, msg)
        return point

    # Unlabelled plans -------------------------------------------------------------------

    def rooms_behind_door_gaps(
        self, departure: DeparturePoint, max_door_cells: int
    ) -> tuple[list[Room], list[Door]]:
        blocked = self.codes == DEPARTURE  # a departure mark is never a door
        gaps = find_door_gaps(self.wall, blocked, max_door_cells)
        closed, closed_h, closed_v = closing_masks(gaps, self.wall.shape)
        areas, _ = lattice.square_labels(self._sealed(), closed, closed_h, closed_v)
        row, col = lattice.xy_to_vertex(departure.x_m, departure.y_m, self.n_rows, self.cell_m)
        start_area = int(areas[min(int(row), self.n_rows - 2), min(int(col), self.n_cols - 2)])
        sides: list[tuple[int, int]] = []
        for gap in gaps:
            r, c = gap.row, gap.col
            if gap.horizontal:
                sides.append((int(areas[r - 1, c]), int(areas[r, c])))
            else:
                sides.append((int(areas[r, c - 1]), int(areas[r, c])))
        behind_doors = {a for pair in sides if pair[0] != pair[1] for a in pair} - {start_area}
        ordered = sorted(behind_doors, key=lambda a: int(np.flatnonzero(areas == a)[0]))
        room_of_area = {area: index + 1 for index, area in enumerate(ordered)}
        rooms = []
        for area, room_id in room_of_area.items():
            mask = areas == area
            self.square_rooms[mask] = room_id
            rooms.append(Room(room_id, lattice.square_to_rects(mask, self.cell_m)))
        doors = []
        for gap, (a, b) in zip(gaps, sides, strict=True):
            if a == b:
                continue
            r, c, k = gap.row, gap.col, gap.length
            if gap.horizontal:
                segment = (*self.xy(r, c - 1), *self.xy(r, c + k))
            else:
                segment = (*self.xy(r + k, c), *self.xy(r - 1, c))
            room_ids = tuple(sorted(room_of_area[x] for x in (a, b) if x in room_of_area))
            doors.append(Door(segment, room_ids))
        return rooms, doors

    # Free areas: sealed voids and where the departure points are -------------------------

    @cached_property
    def _solid(self) -> np.ndarray:
        """(H-1, W-1) squares with four wall corners (the entrance counts as wall)."""
        return lattice.solid_squares(self._sealed())

    @cached_property
    def _areas(self) -> np.ndarray:
        """(H-1, W-1) labels of the free areas as the walls close them (doors open)."""
        return lattice.square_labels(self._sealed())[0]

    def _areas_at(self, squares: list[tuple[int, int]]) -> list[int]:
        areas, solid = self._areas, self._solid
        return [int(areas[s]) for s in squares if not solid[s]]

    def _squares_at(self, row: float, col: float) -> list[tuple[int, int]]:
        """The squares whose closed area holds the (fractional) vertex position."""

        def span(value: float, count: int) -> list[int]:
            low = math.floor(value)
            cells = [low - 1, low] if value == low else [low]
            return [i for i in cells if 0 <= i < count]

        rows = span(row, self.n_rows - 1)
        cols = span(col, self.n_cols - 1)
        return [(i, j) for i in rows for j in cols]

    def sealed_voids(self, points: list[DeparturePoint]) -> np.ndarray:
        """(H-1, W-1) squares of the sealed voids: free areas enclosed by walls that hold no
        room and no departure point. They are read as solid, with a warning each."""
        areas, solid = self._areas, self._solid
        keep = set(np.unique(areas[self.square_rooms != NO_ROOM]).tolist())
        for point in points:
            keep.update(self._areas_at(self._point_squares(point)))
        candidates = np.unique(areas[~solid]).tolist()
        voids = np.zeros_like(solid)
        for area in candidates:
            if area in keep:
                continue
            mask = (areas == area) & ~solid
            voids |= mask
            self.voids_found += 1
            rows, cols = np.nonzero(mask)
            row, col = self._area_place(mask)
            size = int(mask.sum())
            span = (
                f'lines {rows.min() + 1}-{rows.max() + 2}, '
                f'columns {cols.min() + 1}-{cols.max() + 2}'
            )
            msg = (
                f'an enclosed area with no door ({size} cell{"s" if size > 1 else ""}, {span}) '
                'holds no room and no departure point; it is read as solid'
            )
            self.warn(row, col, msg)
        return voids

    def _area_place(self, squares: np.ndarray) -> tuple[int, int]:
        """A free corner vertex of an area's first square (in reading order)."""
        i, j = (int(v) for v in np.argwhere(squares)[0])
        corners = ((i, j), (i, j + 1), (i + 1, j), (i + 1, j + 1))
        return next(((r, c) for r, c in corners if not self.wall[r, c]), (i + 1, j + 1))

    def _point_squares(self, point: DeparturePoint) -> list[tuple[int, int]]:
        row, col = lattice.xy_to_vertex(point.x_m, point.y_m, self.n_rows, self.cell_m)
        return self._squares_at(row, col)

    def check_departure_places(self, points: list[DeparturePoint], voids: np.ndarray) -> None:
        """A departure point inside a solid block (an island of the plan), or in an enclosed
        area that no room can be reached from while the plan has rooms, or that is smaller
        than a sealed void, is an error. (One on a wall line is left to the validation,
        which reports it as inside a wall.)"""
        areas, solid = self._areas, self._solid
        has_rooms = bool(np.any(self.square_rooms != NO_ROOM))
        for point in points:
            row, col = lattice.xy_to_vertex(point.x_m, point.y_m, self.n_rows, self.cell_m)
            squares = self._squares_at(row, col)
            place = (_nearest(row), _nearest(col))
            named = f'departure point {point.name!r}'
            if squares and all(solid[s] for s in squares):
                msg = (
                    f'{named} lies inside a solid block of wall (an island of the plan, with '
                    "no free space around it); move it to a corridor, e.g. with a 'D' mark"
                )
                raise self.error(*place, msg)
            held = set(self._areas_at(squares))
            if len(held) != 1:
                continue  # on a wall line
            mine = areas == held.pop()
            size = int(mine.sum())
            if has_rooms and not np.any(self.square_rooms[mine] != NO_ROOM):
                msg = (
                    f'{named} lies in an enclosed area of {size} cells that leads to no room '
                    '(no door in its walls); move it to a corridor'
                )
                raise self.error(*place, msg)
            if np.any(voids):
                void_ids, sizes = np.unique(areas[voids], return_counts=True)
                largest = int(np.argmax(sizes))
                if sizes[largest] > size:
                    i, j = self._area_place((areas == void_ids[largest]) & voids)
                    msg = (
                        f'{named} lies in an enclosed area of {size} cells with no door, cut '
                        f'off from a larger one of {int(sizes[largest])} cells (line {i + 1}, '
                        f'column {j + 1}); move it there'
                    )
                    raise self.error(*place, msg)
