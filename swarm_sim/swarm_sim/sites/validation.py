"""Invariants every site must hold, checked the same way for generated, imported and loaded
sites.

1. Walls and rooms lie within the bounds; rooms do not overlap; doors name one or two
   existing rooms (the entrance may name none) and are at least as wide as a robot.
2. Every departure point has a robot's clearance from every wall (it is not inside a wall)
   and is not walled into a pocket too small to move in.
3. The enclosure is closed except for the entrance: with the entrance sealed, no departure
   point can reach the outside of the bounds; with it open, they can (the entrance is a gap
   in the enclosure).
4. Every room is reachable from every departure point through its doors; a room that cannot
   be reached and is named by no door is reported as a room with no door.

A site without rooms holds these invariants (an imported plan whose only enclosures are
sealed voids, say), but there is nothing to search in it: :func:`require_rooms` is the extra
check of the tools that run or validate a search (coverage would be 0 of 0).

A departure point inside a room is not an error (robots can leave through its door) but a
warning, which says whether the room is *nested* (its doors open only into other rooms).

Reachability is decided on a raster of the free space in which the walls are drawn as
8-connected lines and flooded 4-connected, so no path slips between two wall cells. Sites on
a grid are rasterized at a quarter of their grid spacing with wall lines in the middle of
raster cells, which leaves three free cells across the narrowest (one-cell) passage.
"""

from __future__ import annotations

import math
from typing import Final

import numpy as np
from scipy import ndimage

from swarm_sim.sites.errors import SiteValidationError, SiteWarning
from swarm_sim.sites.model import NO_ROOM, Door, Room, Site, raster_resolution_m

__all__ = [
    'DEFAULT_ROBOT_RADIUS_M',
    'FreeSpaceRaster',
    'departure_room_warnings',
    'free_space_raster',
    'point_segment_distances',
    'require_rooms',
    'validate_site',
]

DEFAULT_ROBOT_RADIUS_M: Final = 0.1
"""Robot body radius the clearance checks assume [m] (the OA-Bug robots are 0.2 m wide)."""

_PAD_CELLS: Final = 2
_SAMPLES_PER_BATCH: Final = 1_000_000
_BOUNDS_TOLERANCE_M: Final = 1e-6


def point_segment_distances(point: tuple[float, float], segments: np.ndarray) -> np.ndarray:
    """(M,) distances [m] from a point to each of the (M, 4) segments x0, y0, x1, y1."""
    p = np.asarray(point, dtype=np.float64)
    a = segments[:, :2]
    ab = segments[:, 2:] - a
    length2 = np.einsum('ij,ij->i', ab, ab)
    with np.errstate(divide='ignore', invalid='ignore'):
        t = np.where(length2 > 0, np.einsum('ij,ij->i', p - a, ab) / length2, 0.0)
    closest = a + np.clip(t, 0.0, 1.0)[:, None] * ab
    return np.hypot(*(closest - p).T)


class FreeSpaceRaster:
    """Walls drawn on a raster covering the bounds plus a margin, and the free areas' labels.

    Attributes:
        resolution_m: cell size [m].
        origin_m: (x, y) of the lower-left corner of cell (0, 0) [m].
        blocked: (ny, nx) bool, True on wall cells.
        labels: (ny, nx) int labels of the 4-connected free areas (0 on walls).
    """

    def __init__(self, segments: np.ndarray, width_m: float, height_m: float, resolution_m: float):
        self.resolution_m = resolution_m
        offset = (_PAD_CELLS + 0.5) * resolution_m
        self.origin_m = (-offset, -offset)
        nx = math.ceil((width_m + 2 * offset) / resolution_m) + 1
        ny = math.ceil((height_m + 2 * offset) / resolution_m) + 1
        blocked = np.zeros((ny, nx), dtype=bool)
        if len(segments):
            lengths = np.hypot(segments[:, 2] - segments[:, 0], segments[:, 3] - segments[:, 1])
            samples = np.ceil(lengths / (0.5 * resolution_m)).astype(np.intp) + 1
            # Sample the walls a batch at a time so long walls do not need one huge array.
            ends = np.cumsum(samples)
            begin = 0
            while begin < len(segments):
                offset_samples = ends[begin] - samples[begin]
                stop = int(np.searchsorted(ends, offset_samples + _SAMPLES_PER_BATCH, 'right'))
                stop = max(stop, begin + 1)
                self._draw(blocked, segments[begin:stop], samples[begin:stop])
                begin = stop
        self.blocked = blocked
        self.labels, _ = ndimage.label(~blocked)

    def _draw(self, blocked: np.ndarray, segments: np.ndarray, samples: np.ndarray) -> None:
        """Mark the cells of ``samples`` points along each of ``segments`` as blocked."""
        ny, nx = blocked.shape
        owner = np.repeat(np.arange(len(segments)), samples)
        first = np.cumsum(samples) - samples
        t = (np.arange(owner.size) - first[owner]) / np.maximum(samples[owner] - 1, 1)
        start = segments[owner, :2]
        points = start + t[:, None] * (segments[owner, 2:] - start)
        cells = self.cells_of(points)
        inside = (cells[:, 0] >= 0) & (cells[:, 0] < nx) & (cells[:, 1] >= 0) & (cells[:, 1] < ny)
        blocked[cells[inside, 1], cells[inside, 0]] = True

    def cells_of(self, points: np.ndarray) -> np.ndarray:
        """(N, 2) int cell indices (ix, iy) of (N, 2) points [m]."""
        scaled = (
            np.asarray(points, dtype=np.float64) - np.asarray(self.origin_m)
        ) / self.resolution_m
        return np.floor(scaled).astype(np.intp)

    def cell_centres(self, cells_ix_iy: np.ndarray) -> np.ndarray:
        """(N, 2) centres [m] of (N, 2) cells (ix, iy)."""
        return np.asarray(self.origin_m) + (cells_ix_iy + 0.5) * self.resolution_m

    def label_at(self, point: tuple[float, float]) -> int:
        """Label of the free area holding ``point`` (0 when the point is on a wall cell)."""
        ix, iy = self.cells_of(np.asarray([point]))[0]
        return int(self.labels[iy, ix])


def free_space_raster(site: Site, *, sealed: bool = True) -> FreeSpaceRaster:
    """The site's free-space raster, with the entrance closed when ``sealed``."""
    resolution = raster_resolution_m(site.grid_m)
    walls = site.sealed_walls if sealed else site.walls
    return FreeSpaceRaster(walls, site.width_m, site.height_m, resolution)


def require_rooms(site: Site, source: str | None = None) -> None:
    """Raise :class:`SiteValidationError` when the site has no room to search.

    Args:
        site: the site.
        source: the file it came from, named in the message instead of the site's name.
    """
    if site.rooms:
        return
    where = source if source is not None else f'site {site.name!r}'
    msg = f'{where}: the site has no rooms; a search needs at least one (coverage would be 0/0)'
    raise SiteValidationError(msg, key_path=('rooms',))


def validate_site(
    site: Site, *, robot_radius_m: float = DEFAULT_ROBOT_RADIUS_M
) -> tuple[SiteWarning, ...]:
    """Check the invariants listed in the module docstring.

    Returns:
        the warnings: departure points that lie inside a room.

    Raises:
        SiteValidationError: the first violated invariant, with the place (metres) and the
            site-file key path of the offending item.
    """
    _check_within_bounds(site)
    if not site.departure_points:
        raise SiteValidationError(
            f'site {site.name!r} has no departure point', key_path=('departure_points',)
        )
    walls = site.sealed_walls
    for name, point in site.departure_points.items():
        key_path = ('departure_points', name)
        x, y = point.xy
        if not (0.0 <= x <= site.width_m and 0.0 <= y <= site.height_m):
            msg = f'departure point {name!r} at ({x:.3f}, {y:.3f}) m lies outside the site bounds'
            raise SiteValidationError(msg, position_m=point.xy, key_path=key_path)
        if len(walls):
            distances = point_segment_distances(point.xy, walls)
            nearest = int(np.argmin(distances))
            if distances[nearest] < robot_radius_m:
                msg = (
                    f'departure point {name!r} at ({x:.3f}, {y:.3f}) m is inside a wall: '
                    f'{distances[nearest]:.3f} m from the wall {_fmt_segment(walls[nearest])}, '
                    f'less than the robot radius {robot_radius_m} m'
                )
                raise SiteValidationError(msg, position_m=point.xy, key_path=key_path)
    _check_door_widths(site, robot_radius_m)
    lookup = site.room_lookup  # raises on overlapping rooms
    raster = free_space_raster(site, sealed=True)
    ring = np.unique(
        np.concatenate(
            [raster.labels[0], raster.labels[-1], raster.labels[:, 0], raster.labels[:, -1]]
        )
    )
    door_rooms = {room_id for door in site.doors for room_id in door.room_ids}
    for name, point in site.departure_points.items():
        x, y = point.xy
        label = raster.label_at(point.xy)
        if label == 0:
            msg = f'departure point {name!r} at ({x:.3f}, {y:.3f}) m is inside a wall'
            raise SiteValidationError(msg, position_m=point.xy, key_path=('departure_points', name))
        if label in ring:
            where = _leak_position(raster, label, site, point.xy)
            msg = (
                f'the enclosure is open: departure point {name!r} reaches the outside of the site '
                f'near ({where[0]:.3f}, {where[1]:.3f}) m'
                + (' (the entrance is sealed for this check)' if site.entrance else '')
            )
            raise SiteValidationError(msg, position_m=where, key_path=('walls',))
        reached = np.argwhere(raster.labels == label)[:, ::-1]
        free_area_m2 = len(reached) * raster.resolution_m**2
        if free_area_m2 < math.pi * (3 * robot_radius_m) ** 2:
            msg = (
                f'departure point {name!r} at ({x:.3f}, {y:.3f}) m is walled in: it can reach '
                f'only {free_area_m2:.2f} m^2 of free space'
            )
            raise SiteValidationError(msg, position_m=point.xy, key_path=('departure_points', name))
        reached_rooms = set(np.unique(lookup.room_ids(raster.cell_centres(reached))).tolist())
        reached_rooms.discard(NO_ROOM)
        for index, room in enumerate(site.rooms):
            if room.room_id in reached_rooms:
                continue
            lx, ly = room.label_point
            named = f'room {room.room_id}' + (f' ({room.label!r})' if room.label else '')
            if room.room_id not in door_rooms and site.doors:
                problem = 'has no door'
            else:
                problem = f'is not reachable from departure point {name!r}'
            msg = f'{named} at ({lx:.3f}, {ly:.3f}) m {problem}'
            raise SiteValidationError(msg, position_m=(lx, ly), key_path=('rooms', index))
    if site.entrance is not None:
        _check_entrance_opens(site, site.entrance)
    return tuple(departure_room_warnings(site))


def departure_room_warnings(site: Site) -> list[SiteWarning]:
    """A warning for every departure point that lies inside a room (robots would start in
    that room, not in a corridor), saying whether the room is nested in other rooms."""
    points = list(site.departure_points.values())
    if not points or not site.rooms:
        return []
    room_ids = site.room_ids_at(np.array([p.xy for p in points], dtype=np.float64))
    warnings = []
    for point, room_id in zip(points, room_ids.tolist(), strict=True):
        if room_id == NO_ROOM:
            continue
        room = site.room(room_id)
        doors = [door for door in site.doors if room_id in door.room_ids]
        outer = sorted({i for door in doors for i in door.room_ids} - {room_id})
        nested = bool(doors) and all(len(door.room_ids) == 2 for door in doors)
        x, y = point.xy
        where = f'departure point {point.name!r} at ({x:.3f}, {y:.3f}) m lies inside '
        if nested:
            into = ', '.join(_room_name(site.room(i)) for i in outer)
            what = f'{_room_name(room)}, a room nested in {into} (its doors open only into rooms)'
        else:
            what = _room_name(room)
        msg = f'{where}{what}: robots start in that room, not in a corridor'
        warnings.append(
            SiteWarning(msg, position_m=point.xy, key_path=('departure_points', point.name))
        )
    return warnings


def _room_name(room: Room) -> str:
    return f'room {room.room_id}' + (f' ({room.label!r})' if room.label else '')


def _check_door_widths(site: Site, robot_radius_m: float) -> None:
    doors: list[tuple[tuple[str | int, ...], Door, str]] = [
        (('doors', i), door, 'door') for i, door in enumerate(site.doors)
    ]
    if site.entrance is not None:
        doors.append((('entrance',), site.entrance, 'the entrance'))
    for key_path, door, what in doors:
        if door.width_m < 2 * robot_radius_m:
            x, y = door.midpoint
            msg = (
                f'{what} at ({x:.3f}, {y:.3f}) m is {door.width_m:.3f} m wide, narrower than a '
                f'robot ({2 * robot_radius_m:.3f} m)'
            )
            raise SiteValidationError(msg, position_m=door.midpoint, key_path=key_path)


def _check_entrance_opens(site: Site, entrance: Door) -> None:
    """With the entrance open, the inside must reach the outside: the entrance is a gap in
    the enclosure, not a segment somewhere else."""
    raster = free_space_raster(site, sealed=False)
    labels = raster.labels
    ring = set(np.concatenate([labels[0], labels[-1], labels[:, 0], labels[:, -1]]).tolist())
    point = next(iter(site.departure_points.values()))
    if raster.label_at(point.xy) not in ring:
        x, y = entrance.midpoint
        msg = f'the entrance at ({x:.3f}, {y:.3f}) m is not a gap in the enclosure'
        raise SiteValidationError(msg, position_m=(x, y), key_path=('entrance',))


def _check_within_bounds(site: Site) -> None:
    tol = _BOUNDS_TOLERANCE_M
    w, h = site.width_m, site.height_m
    walls = site.walls
    if len(walls):
        xs, ys = walls[:, 0::2], walls[:, 1::2]
        outside = np.any((xs < -tol) | (xs > w + tol) | (ys < -tol) | (ys > h + tol), axis=1)
        if np.any(outside):
            index = int(np.argmax(outside))
            msg = f'wall {_fmt_segment(walls[index])} leaves the site bounds {w:.3f} x {h:.3f} m'
            raise SiteValidationError(
                msg,
                position_m=(float(xs[index, 0]), float(ys[index, 0])),
                key_path=('walls', index),
            )
        lengths = np.hypot(walls[:, 2] - walls[:, 0], walls[:, 3] - walls[:, 1])
        if np.any(lengths <= 0.0):
            index = int(np.argmax(lengths <= 0.0))
            msg = f'wall {_fmt_segment(walls[index])} has zero length'
            raise SiteValidationError(
                msg,
                position_m=(float(walls[index, 0]), float(walls[index, 1])),
                key_path=('walls', index),
            )
    known_rooms = set(site.room_ids)
    doors = [('doors', i, door) for i, door in enumerate(site.doors)]
    if site.entrance is not None:
        doors.append(('entrance', -1, site.entrance))
    for key, index, door in doors:
        if key == 'doors' and not door.room_ids:
            x, y = door.midpoint
            msg = f'door at ({x:.3f}, {y:.3f}) m names no room; a door joins one or two rooms'
            raise SiteValidationError(msg, position_m=door.midpoint, key_path=(key, index))
        unknown = sorted(set(door.room_ids) - known_rooms)
        if unknown:
            path = (key,) if index < 0 else (key, index)
            x, y = door.midpoint
            msg = f'door at ({x:.3f}, {y:.3f}) m names unknown rooms {unknown}'
            raise SiteValidationError(msg, position_m=door.midpoint, key_path=path)
    for index, room in enumerate(site.rooms):
        x0, y0, x1, y1 = room.bounding_rect
        if x0 < -tol or y0 < -tol or x1 > w + tol or y1 > h + tol:
            msg = f'room {room.room_id} extends beyond the site bounds {w:.3f} x {h:.3f} m'
            raise SiteValidationError(msg, position_m=room.label_point, key_path=('rooms', index))


def _leak_position(
    raster: FreeSpaceRaster, label: int, site: Site, start: tuple[float, float]
) -> tuple[float, float]:
    """Where the area ``label`` crosses the site bounds: the reached cell inside the bounds next
    to a reached cell outside them, nearest to ``start``."""
    area = raster.labels == label
    iy, ix = np.nonzero(area)
    centres = raster.cell_centres(np.column_stack([ix, iy]))
    outside = (
        (centres[:, 0] < 0)
        | (centres[:, 0] > site.width_m)
        | (centres[:, 1] < 0)
        | (centres[:, 1] > site.height_m)
    )
    outside_grid = np.zeros_like(area)
    outside_grid[iy[outside], ix[outside]] = True
    near_outside = ndimage.binary_dilation(outside_grid) & area & ~outside_grid
    jy, jx = np.nonzero(near_outside)
    if len(jy) == 0:
        return start
    candidates = raster.cell_centres(np.column_stack([jx, jy]))
    best = int(np.argmin(np.hypot(*(candidates - np.asarray(start)).T)))
    return (float(candidates[best, 0]), float(candidates[best, 1]))


def _fmt_segment(segment: np.ndarray) -> str:
    x0, y0, x1, y1 = (float(v) for v in segment)
    return f'({x0:.3f}, {y0:.3f})-({x1:.3f}, {y1:.3f}) m'
