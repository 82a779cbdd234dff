"""The site model: walls, rooms, doors, entrance and departure points of one building.

ROS-free and immutable. Coordinates are metres in the site's world frame: origin at the
lower-left corner of the site's bounds, x to the right, y up (``docs/conventions.md``). Sites
come from the generator (:mod:`.generator`), from a text layout (:mod:`.layout`) or from a
YAML site file (:mod:`.site_file`); :func:`.validation.validate_site` checks the invariants.

Walls are zero-thickness segments (a simulator gives them whatever thickness its bodies
need). The entrance is a real gap in the enclosure: ``walls`` leaves it open, as the plan
shows it, and :attr:`Site.sealed_walls` closes it for a simulation in which robots must stay
inside the building, as in the OA-Bug authors' simulator.
"""

from __future__ import annotations

import math
from collections.abc import Iterable, Mapping
from dataclasses import dataclass, field
from functools import cached_property
from types import MappingProxyType
from typing import TYPE_CHECKING, Final

import numpy as np

from swarm_sim.sites.errors import SiteError, SiteValidationError

if TYPE_CHECKING:
    from swarm_sim.sites.room_lookup import RoomLookup

__all__ = [
    'CELL_M',
    'MAX_RASTER_CELLS',
    'MAX_SIDE_M',
    'NO_ROOM',
    'RASTER_RESOLUTION_M',
    'DeparturePoint',
    'Door',
    'Room',
    'Site',
    'check_site_size',
    'raster_resolution_m',
]

CELL_M: Final = 4.0 / 15.0
"""Grid spacing of the OA-Bug sites [m]: the paper's unit, 1 cell = 4/15 m (Table II)."""

NO_ROOM: Final = -1
"""Room id returned for points that lie in no room (corridors, walls, outside)."""

MAX_SIDE_M: Final = 1000.0
"""Longest side a site's bounds may have [m]. The paper's largest site, Big, is 31.7 x 15.7 m;
the simulator rasterizes a site to check and look it up, so the size is bounded before
anything is allocated."""

RASTER_RESOLUTION_M: Final = 0.025
"""Cell size of the validation raster of a site without ``grid_m`` [m]; a site on a grid is
rasterized at a quarter of its grid spacing (see :mod:`.validation`)."""

MAX_RASTER_CELLS: Final = 10_000_000
"""Most cells a site's validation raster may have (about 90 bytes of memory each while a
site is validated): 12 times a free-form site of Big's size, 85 times Big on its grid. It
bounds a site without ``grid_m`` to about 79 x 79 m, a grid site to about 790 x 790 grid
cells."""


def raster_resolution_m(grid_m: float | None) -> float:
    """Cell size [m] of the raster a site is validated on: a quarter of its grid spacing, or
    :data:`RASTER_RESOLUTION_M` without one."""
    return grid_m / 4.0 if grid_m is not None else RASTER_RESOLUTION_M


def check_site_size(
    width_m: float, height_m: float, grid_m: float | None, wall_length_m: float = 0.0
) -> None:
    """Raise :class:`~swarm_sim.sites.errors.SiteValidationError` when a site of these bounds
    is larger than the simulator handles: a side longer than :data:`MAX_SIDE_M`, a validation
    raster of more than :data:`MAX_RASTER_CELLS` cells, or walls that together cross more
    raster cells than that. Cheap: call it before building anything of that size.

    Args:
        width_m: extent along x [m] (positive, finite).
        height_m: extent along y [m] (positive, finite).
        grid_m: grid spacing [m], or None.
        wall_length_m: total length of the walls [m].
    """
    for key, side in (('width_m', width_m), ('height_m', height_m)):
        if side > MAX_SIDE_M:
            msg = f'{side:g} m is larger than the {MAX_SIDE_M:g} m a site side may be'
            raise SiteValidationError(msg, key_path=('bounds', key))
    resolution = raster_resolution_m(grid_m)
    # FreeSpaceRaster adds 2.5 cells of margin on each side and one more cell.
    nx = width_m / resolution + 6.0
    ny = height_m / resolution + 6.0
    if nx * ny > MAX_RASTER_CELLS:
        spacing = (
            f'a quarter of grid_m {grid_m:g} m'
            if grid_m is not None
            else 'for a site without grid_m'
        )
        hint = '' if grid_m is not None else '; a grid_m above 0.1 m makes the raster coarser'
        msg = (
            f'{width_m:g} x {height_m:g} m is too large to check: at {resolution:g} m per raster '
            f'cell ({spacing}) it needs {nx * ny:.3g} cells, more than the '
            f'{MAX_RASTER_CELLS:,} a site may have{hint}'
        )
        raise SiteValidationError(msg, key_path=('bounds',))
    if wall_length_m / resolution > MAX_RASTER_CELLS:
        msg = (
            f'the walls are {wall_length_m:.6g} m long in total, {wall_length_m / resolution:.3g} '
            f'raster cells of {resolution:g} m: more than the {MAX_RASTER_CELLS:,} a site may have'
        )
        raise SiteValidationError(msg, key_path=('walls',))


def _readonly(array: np.ndarray) -> np.ndarray:
    array = np.array(array, dtype=np.float64, copy=True)
    array.flags.writeable = False
    return array


@dataclass(frozen=True)
class DeparturePoint:
    """A named place robots set off from ("center", "edge", ...).

    Attributes:
        name: the name missions refer to it by.
        x_m: x position [m].
        y_m: y position [m].
        heading_rad: direction into the building [rad, counter-clockwise from +x], or None
            when the point has no preferred direction (e.g. the centre).
    """

    name: str
    x_m: float
    y_m: float
    heading_rad: float | None = None

    def __post_init__(self) -> None:
        if not self.name:
            raise SiteError('a departure point needs a non-empty name')
        values = (self.x_m, self.y_m) + (() if self.heading_rad is None else (self.heading_rad,))
        if not all(math.isfinite(v) for v in values):
            msg = f'departure point {self.name!r} has a non-finite coordinate'
            raise SiteError(msg)

    @property
    def xy(self) -> tuple[float, float]:
        """(x, y) [m]."""
        return (self.x_m, self.y_m)


@dataclass(frozen=True)
class Door:
    """A door gap: the segment across the opening and the rooms it joins.

    Attributes:
        segment: (x0, y0, x1, y1) [m], the gap between the two wall ends.
        room_ids: ids of the rooms on either side; empty for a gap between two corridor
            areas, one id for a door between a room and a corridor, two for a door between
            rooms (and for the entrance: the room or corridor behind it, if any).
    """

    segment: tuple[float, float, float, float]
    room_ids: tuple[int, ...] = ()

    def __post_init__(self) -> None:
        segment = tuple(float(v) for v in self.segment)
        if len(segment) != 4 or not all(math.isfinite(v) for v in segment):
            msg = f'a door segment needs four finite coordinates, got {self.segment!r}'
            raise SiteError(msg)
        object.__setattr__(self, 'segment', segment)
        room_ids = tuple(int(i) for i in self.room_ids)
        if len(room_ids) > 2:
            msg = f'a door joins at most two rooms, got {room_ids}'
            raise SiteError(msg)
        object.__setattr__(self, 'room_ids', room_ids)

    @property
    def width_m(self) -> float:
        """Width of the opening [m]."""
        x0, y0, x1, y1 = self.segment
        return math.hypot(x1 - x0, y1 - y0)

    @property
    def midpoint(self) -> tuple[float, float]:
        """Centre of the opening (x, y) [m]."""
        x0, y0, x1, y1 = self.segment
        return (0.5 * (x0 + x1), 0.5 * (y0 + y1))


@dataclass(frozen=True, eq=False)
class Room:
    """One room: an id, a label and its area.

    The area is the union of axis-aligned rectangles (the usual case: rooms of generated and
    ``.lay`` sites are one rectangle spanning the room's wall lines) and, optionally, one
    polygon (free-form site files).

    Attributes:
        room_id: non-negative integer id, unique in the site.
        rects: (K, 4) float array of x0, y0, x1, y1 [m] with x0 < x1 and y0 < y1.
        label: the room's letter in a labelled layout, or any short name; may be empty.
        has_victim: the room holds a victim (a digit in the authors' layouts). Victim rooms
            are ordinary rooms for coverage.
        polygon: (P, 2) float array of x, y [m] (P >= 3) outlining a non-rectangular area,
            or None.
    """

    room_id: int
    rects: np.ndarray
    label: str = ''
    has_victim: bool = False
    polygon: np.ndarray | None = None

    def __post_init__(self) -> None:
        if int(self.room_id) < 0:
            msg = f'room ids must be non-negative, got {self.room_id}'
            raise SiteError(msg)
        object.__setattr__(self, 'room_id', int(self.room_id))
        rects = _readonly(np.asarray(self.rects, dtype=np.float64).reshape(-1, 4))
        polygon = None
        if self.polygon is not None:
            polygon = _readonly(np.asarray(self.polygon, dtype=np.float64).reshape(-1, 2))
            if len(polygon) < 3:
                msg = f'room {self.room_id}: a polygon needs at least 3 vertices'
                raise SiteError(msg)
        if len(rects) == 0 and polygon is None:
            msg = f'room {self.room_id} has no area (no rectangle and no polygon)'
            raise SiteError(msg)
        if not np.all(np.isfinite(rects)) or (
            polygon is not None and not np.all(np.isfinite(polygon))
        ):
            msg = f'room {self.room_id} has a non-finite coordinate'
            raise SiteError(msg)
        if np.any(rects[:, 2] <= rects[:, 0]) or np.any(rects[:, 3] <= rects[:, 1]):
            msg = f'room {self.room_id}: every rectangle needs x0 < x1 and y0 < y1'
            raise SiteError(msg)
        object.__setattr__(self, 'rects', rects)
        object.__setattr__(self, 'polygon', polygon)

    @property
    def area_m2(self) -> float:
        """Area [m^2] (rectangles and polygon are assumed not to overlap)."""
        area = float(
            np.sum((self.rects[:, 2] - self.rects[:, 0]) * (self.rects[:, 3] - self.rects[:, 1]))
        )
        if self.polygon is not None:
            x, y = self.polygon[:, 0], self.polygon[:, 1]
            area += 0.5 * abs(float(np.dot(x, np.roll(y, -1)) - np.dot(y, np.roll(x, -1))))
        return area

    @property
    def bounding_rect(self) -> tuple[float, float, float, float]:
        """(x0, y0, x1, y1) [m] of the smallest rectangle holding the whole area."""
        points = [self.rects[:, :2], self.rects[:, 2:]]
        if self.polygon is not None:
            points.append(self.polygon)
        stacked = np.concatenate(points)
        x0, y0 = stacked.min(axis=0)
        x1, y1 = stacked.max(axis=0)
        return (float(x0), float(y0), float(x1), float(y1))

    @property
    def label_point(self) -> tuple[float, float]:
        """A point inside the room where a plot puts its id (centre of its largest part) [m]."""
        if len(self.rects):
            areas = (self.rects[:, 2] - self.rects[:, 0]) * (self.rects[:, 3] - self.rects[:, 1])
            x0, y0, x1, y1 = self.rects[int(np.argmax(areas))]
            return (0.5 * float(x0 + x1), 0.5 * float(y0 + y1))
        assert self.polygon is not None
        centre = self.polygon.mean(axis=0)
        return (float(centre[0]), float(centre[1]))


@dataclass(frozen=True, eq=False, repr=False)
class Site:
    """A building to search: enclosure and inner walls, rooms, doors, departure points.

    Construct it with any iterables; ``__post_init__`` turns them into read-only arrays,
    tuples and a read-only mapping. Structural problems (wrong shapes, duplicate ids) raise
    :class:`SiteError` here, a site too large to simulate (:func:`check_site_size`) a
    :class:`~swarm_sim.sites.errors.SiteValidationError`; geometric invariants are checked by
    :func:`swarm_sim.sites.validation.validate_site`.

    Attributes:
        name: short name for logs and plots.
        width_m: extent of the site's bounds along x [m]; the bounds start at the origin.
        height_m: extent along y [m].
        walls: (M, 4) float array of wall segments x0, y0, x1, y1 [m]. The entrance is left
            open; use :attr:`sealed_walls` for a world robots cannot leave.
        rooms: the rooms; their order is the room index used by coverage messages.
        doors: door gaps between rooms and corridors (the entrance is not among them).
        entrance: the single gap in the enclosure, or None for a closed building.
        departure_points: name -> :class:`DeparturePoint` (generated sites have "center"
            and "edge").
        grid_m: spacing of the grid the site was drawn on (4/15 m for generated and ``.lay``
            sites), or None for free-form sites. Room lookups use it as their resolution.
        seed: seed of the generator run that produced the site, or None.
        warnings: one-line notes on problems the site was made usable despite (a sealed void
            read as solid, a departure point inside a room, characters read as free space),
            each naming its place; set by the importers and the site-file loader, logged by
            the command-line tools. Not written to site files.
    """

    name: str
    width_m: float
    height_m: float
    walls: np.ndarray
    rooms: tuple[Room, ...] = ()
    doors: tuple[Door, ...] = ()
    entrance: Door | None = None
    departure_points: Mapping[str, DeparturePoint] = field(default_factory=dict)
    grid_m: float | None = None
    seed: int | None = None
    warnings: tuple[str, ...] = ()

    def __post_init__(self) -> None:
        width, height = float(self.width_m), float(self.height_m)
        if not (math.isfinite(width) and math.isfinite(height) and width > 0 and height > 0):
            msg = f'site bounds must be positive and finite, got {width!r} x {height!r} m'
            raise SiteError(msg)
        object.__setattr__(self, 'width_m', width)
        object.__setattr__(self, 'height_m', height)
        walls = np.asarray(self.walls, dtype=np.float64)
        if walls.size == 0:
            walls = walls.reshape(0, 4)
        if walls.ndim != 2 or walls.shape[1] != 4:
            msg = f'walls must be an (M, 4) array of x0, y0, x1, y1, got shape {walls.shape}'
            raise SiteError(msg)
        if not np.all(np.isfinite(walls)):
            raise SiteError('walls contain a non-finite coordinate')
        grid = None
        if self.grid_m is not None:
            grid = float(self.grid_m)
            if not (math.isfinite(grid) and grid > 0):
                msg = f'grid_m must be positive, got {self.grid_m!r}'
                raise SiteError(msg)
            object.__setattr__(self, 'grid_m', grid)
        wall_length = float(np.sum(np.hypot(walls[:, 2] - walls[:, 0], walls[:, 3] - walls[:, 1])))
        check_site_size(width, height, grid, wall_length)
        object.__setattr__(self, 'walls', _readonly(walls))
        rooms = tuple(self.rooms)
        ids = [room.room_id for room in rooms]
        if len(set(ids)) != len(ids):
            duplicates = sorted({i for i in ids if ids.count(i) > 1})
            msg = f'room ids must be unique, duplicated: {duplicates}'
            raise SiteError(msg)
        object.__setattr__(self, 'rooms', rooms)
        object.__setattr__(self, 'doors', tuple(self.doors))
        points = self.departure_points
        if not isinstance(points, Mapping):
            points = _departures_by_name(points)
        for key, point in points.items():
            if key != point.name:
                msg = f'departure point stored under {key!r} is named {point.name!r}'
                raise SiteError(msg)
        object.__setattr__(self, 'departure_points', MappingProxyType(dict(points)))
        if self.seed is not None:
            object.__setattr__(self, 'seed', int(self.seed))
        warnings = self.warnings
        if isinstance(warnings, str) or not all(isinstance(w, str) for w in warnings):
            raise SiteError('warnings must be a sequence of strings')
        object.__setattr__(self, 'warnings', tuple(warnings))

    def __repr__(self) -> str:
        points = ', '.join(self.departure_points)
        return (
            f'Site({self.name!r}, {self.width_m:.2f} x {self.height_m:.2f} m, '
            f'{len(self.rooms)} rooms, {len(self.doors)} doors, {len(self.walls)} walls, '
            f'entrance={"yes" if self.entrance else "no"}, departure points: {points}, '
            f'seed={self.seed})'
        )

    @property
    def bounds(self) -> tuple[float, float, float, float]:
        """(x_min, y_min, x_max, y_max) of the site [m]."""
        return (0.0, 0.0, self.width_m, self.height_m)

    @property
    def room_ids(self) -> tuple[int, ...]:
        """Ids of the rooms, in room-index order."""
        return tuple(room.room_id for room in self.rooms)

    @property
    def room_bounding_rects(self) -> np.ndarray:
        """(K, 4) x0, y0, x1, y1 [m] of each room's bounding rectangle, in room-index order
        (the room itself for the one-rectangle rooms of generated and labelled sites)."""
        rects = np.array([room.bounding_rect for room in self.rooms], dtype=np.float64)
        return rects.reshape(-1, 4)

    @property
    def sealed_walls(self) -> np.ndarray:
        """(M', 4) walls with the entrance closed by one more segment: what robots collide with
        in a simulation of the paper's closed sites."""
        if self.entrance is None:
            return self.walls
        return _readonly(np.vstack([self.walls, np.asarray(self.entrance.segment)[None, :]]))

    def departure(self, name: str) -> DeparturePoint:
        """The departure point called ``name``; :class:`SiteError` lists the known names."""
        try:
            return self.departure_points[name]
        except KeyError:
            known = ', '.join(sorted(self.departure_points)) or 'none'
            msg = f'site {self.name!r} has no departure point {name!r} (it has: {known})'
            raise SiteError(msg) from None

    def room(self, room_id: int) -> Room:
        """The room with id ``room_id``."""
        for room in self.rooms:
            if room.room_id == room_id:
                return room
        msg = f'site {self.name!r} has no room {room_id}'
        raise SiteError(msg)

    def room_index(self, room_id: int) -> int:
        """Position of room ``room_id`` in :attr:`rooms` (the index coverage messages use)."""
        for index, room in enumerate(self.rooms):
            if room.room_id == room_id:
                return index
        msg = f'site {self.name!r} has no room {room_id}'
        raise SiteError(msg)

    @cached_property
    def room_lookup(self) -> RoomLookup:
        """The site's point -> room id raster, built on first use."""
        from swarm_sim.sites.room_lookup import RoomLookup

        return RoomLookup.for_site(self)

    def room_ids_at(self, points_m: np.ndarray) -> np.ndarray:
        """(N,) int32 room id of each of the (N, 2) points [m]; :data:`NO_ROOM` outside rooms."""
        return self.room_lookup.room_ids(points_m)


def _departures_by_name(points: Iterable[DeparturePoint]) -> dict[str, DeparturePoint]:
    result: dict[str, DeparturePoint] = {}
    for point in points:
        if point.name in result:
            msg = f'two departure points are named {point.name!r}'
            raise SiteError(msg)
        result[point.name] = point
    return result
