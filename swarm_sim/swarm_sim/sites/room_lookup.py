"""Point -> room id lookup through a raster: O(1) per point, vectorized over (N, 2) points.

The simulator asks "which room is each robot in?" every physics step for every robot, so the
rooms are rasterized once: a cell belongs to the room whose area holds the cell's centre.
Sites drawn on a grid (generated and ``.lay`` sites) are rasterized at their grid spacing,
where the raster is exact because every room edge lies on a grid line. Free-form sites use
``DEFAULT_RESOLUTION_M``.

Coverage: the authors' simulator counts a room as visited once the robot's
body reaches a little past the room's wall line. :meth:`RoomLookup.rooms_reached` answers
that question for a round body by probing the centre and four points ``reach_m`` away along
the axes (doors are gaps in axis-aligned walls, so a body entering a door is caught by the
probe pointing through it).
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING, Final

import numpy as np
from numpy.typing import ArrayLike

from swarm_sim.sites.errors import SiteValidationError
from swarm_sim.sites.model import NO_ROOM, Room

if TYPE_CHECKING:
    from swarm_sim.sites.model import Site

__all__ = ['DEFAULT_RESOLUTION_M', 'RoomLookup', 'points_in_polygon']

DEFAULT_RESOLUTION_M: Final = 0.025
"""Raster cell size for sites not drawn on a grid [m]."""

_PROBE_DIRECTIONS: Final = np.array([[0.0, 0.0], [1.0, 0.0], [-1.0, 0.0], [0.0, 1.0], [0.0, -1.0]])


def points_in_polygon(points: np.ndarray, polygon: np.ndarray) -> np.ndarray:
    """(N,) bool: which of the (N, 2) points lie inside the (P, 2) polygon (even-odd rule)."""
    x = points[:, 0:1]
    y = points[:, 1:2]
    x0, y0 = polygon[:, 0], polygon[:, 1]
    x1, y1 = np.roll(x0, -1), np.roll(y0, -1)
    straddles = (y0 > y) != (y1 > y)
    with np.errstate(divide='ignore', invalid='ignore'):
        x_cross = x0 + (y - y0) * (x1 - x0) / (y1 - y0)
    crossings = np.count_nonzero(straddles & (x < x_cross), axis=1)
    return crossings % 2 == 1


class RoomLookup:
    """Raster of room ids over a site's bounds.

    Attributes:
        resolution_m: cell size [m].
        raster: (ny, nx) int32 room ids, row 0 at y = 0 (read-only); :data:`NO_ROOM` where
            no room is.
    """

    def __init__(
        self, rooms: tuple[Room, ...], width_m: float, height_m: float, resolution_m: float
    ) -> None:
        """Rasterize ``rooms`` over [0, width_m] x [0, height_m].

        Raises:
            SiteValidationError: two rooms claim the same cell (overlapping areas).
        """
        if not resolution_m > 0:
            msg = f'resolution_m must be positive, got {resolution_m!r}'
            raise ValueError(msg)
        self.resolution_m = float(resolution_m)
        nx = max(1, math.ceil(width_m / resolution_m - 1e-9))
        ny = max(1, math.ceil(height_m / resolution_m - 1e-9))
        raster = np.full((ny, nx), NO_ROOM, dtype=np.int32)
        for index, room in enumerate(rooms):
            (j0, i0), claimed = self._room_mask(room, nx, ny)
            window = raster[j0 : j0 + claimed.shape[0], i0 : i0 + claimed.shape[1]]
            clash = claimed & (window != NO_ROOM)
            if np.any(clash):
                iy, ix = np.argwhere(clash)[0] + (j0, i0)
                x, y = self._cell_centre(int(ix), int(iy))
                msg = (
                    f'rooms {int(raster[iy, ix])} and {room.room_id} overlap near '
                    f'({x:.3f}, {y:.3f}) m'
                )
                raise SiteValidationError(msg, position_m=(x, y), key_path=('rooms', index))
            window[claimed] = room.room_id
        raster.flags.writeable = False
        self.raster = raster

    @classmethod
    def for_site(cls, site: Site, resolution_m: float | None = None) -> RoomLookup:
        """Lookup for ``site`` at ``resolution_m``, its grid spacing, or the default."""
        if resolution_m is None:
            resolution_m = site.grid_m if site.grid_m is not None else DEFAULT_RESOLUTION_M
        return cls(site.rooms, site.width_m, site.height_m, resolution_m)

    def room_ids(self, points_m: ArrayLike) -> np.ndarray:
        """(N,) int32 room id of each of the (N, 2) points x, y [m]; NO_ROOM outside rooms
        (corridors, outside the bounds, non-finite points)."""
        points = np.asarray(points_m, dtype=np.float64).reshape(-1, 2)
        with np.errstate(invalid='ignore'):
            scaled = np.floor(points / self.resolution_m)
        ny, nx = self.raster.shape
        valid = np.all(np.isfinite(scaled), axis=1)
        valid &= (scaled[:, 0] >= 0) & (scaled[:, 0] < nx) & (scaled[:, 1] >= 0)
        valid &= scaled[:, 1] < ny
        ids = np.full(len(points), NO_ROOM, dtype=np.int32)
        cells = scaled[valid].astype(np.intp)
        ids[valid] = self.raster[cells[:, 1], cells[:, 0]]
        return ids

    def rooms_reached(self, points_m: ArrayLike, reach_m: float) -> np.ndarray:
        """(N, 5) int32 room ids at each point and at the four points ``reach_m`` away along
        +x, -x, +y, -y: the rooms a round body of that reach touches (NO_ROOM entries for
        probes outside rooms)."""
        points = np.asarray(points_m, dtype=np.float64).reshape(-1, 2)
        probes = points[:, None, :] + reach_m * _PROBE_DIRECTIONS[None, :, :]
        return self.room_ids(probes.reshape(-1, 2)).reshape(len(points), len(_PROBE_DIRECTIONS))

    def _room_mask(self, room: Room, nx: int, ny: int) -> tuple[tuple[int, int], np.ndarray]:
        """The cells of ``room``: the (row, column) of the lower-left cell of the room's
        bounding window in the raster, and the window's bool mask (only the window is
        allocated, so many rooms cost their own area, not the site's each)."""
        res = self.resolution_m
        bx0, by0, bx1, by1 = room.bounding_rect
        wi0 = min(nx, max(0, math.floor(bx0 / res)))
        wj0 = min(ny, max(0, math.floor(by0 / res)))
        wi1 = min(nx, max(wi0, math.ceil(bx1 / res)))
        wj1 = min(ny, max(wj0, math.ceil(by1 / res)))
        mask = np.zeros((wj1 - wj0, wi1 - wi0), dtype=bool)
        for x0, y0, x1, y1 in room.rects:
            # Cells whose centre (k + 0.5) * res lies in [x0, x1).
            i0, i1 = (max(0, math.ceil(v / res - 0.5)) for v in (x0, x1))
            j0, j1 = (max(0, math.ceil(v / res - 0.5)) for v in (y0, y1))
            mask[j0 - wj0 : min(j1, ny) - wj0, i0 - wi0 : min(i1, nx) - wi0] = True
        if room.polygon is not None:
            x0, y0 = room.polygon.min(axis=0)
            x1, y1 = room.polygon.max(axis=0)
            i0, i1 = max(0, math.floor(x0 / res)), min(nx, math.ceil(x1 / res))
            j0, j1 = max(0, math.floor(y0 / res)), min(ny, math.ceil(y1 / res))
            if i1 > i0 and j1 > j0:
                ii, jj = np.meshgrid(np.arange(i0, i1), np.arange(j0, j1))
                centres = np.column_stack([(ii.ravel() + 0.5) * res, (jj.ravel() + 0.5) * res])
                inside = points_in_polygon(centres, room.polygon).reshape(ii.shape)
                mask[j0 - wj0 : j1 - wj0, i0 - wi0 : i1 - wi0] |= inside
        return (wj0, wi0), mask

    def _cell_centre(self, ix: int, iy: int) -> tuple[float, float]:
        return ((ix + 0.5) * self.resolution_m, (iy + 0.5) * self.resolution_m)
