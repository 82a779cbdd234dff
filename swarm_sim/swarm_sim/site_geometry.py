"""Turn a :class:`swarm_sim.sites.model.Site` into the engine's :class:`SiteGeometry`."""

from __future__ import annotations

from typing import Any

import numpy as np

from swarm_sim.engine import SiteGeometry

__all__ = ['ROOM_ENTRY_INSET_M', 'geometry_from_site']

# How far past a room's wall lines a robot's body must reach for the room to count as
# entered: the authors' simulator insets room rectangles by 3 px (about 2.5 cm).
ROOM_ENTRY_INSET_M = 0.025


def geometry_from_site(site: Any, inset_m: float = ROOM_ENTRY_INSET_M) -> SiteGeometry:
    """Walls (entrance sealed) and inset room interiors of ``site``.

    Rectangles too small to inset stay as they are. Rooms that also have a polygon are
    additionally found through the site's point -> room lookup.
    """
    walls = np.asarray(site.sealed_walls, dtype=float).reshape(-1, 2, 2)
    rects = []
    for room in site.rooms:
        r = np.array(room.rects, dtype=float).reshape(-1, 4)
        inset = r + np.array([inset_m, inset_m, -inset_m, -inset_m])
        ok = (inset[:, 2] > inset[:, 0]) & (inset[:, 3] > inset[:, 1])
        r[ok] = inset[ok]
        rects.append(r)
    lookup = None
    if any(room.polygon is not None for room in site.rooms):
        index_of = {room.room_id: i for i, room in enumerate(site.rooms)}

        def lookup(points: np.ndarray) -> np.ndarray:
            ids = np.asarray(site.room_ids_at(np.asarray(points, dtype=float)[:, :2]))
            return np.array([index_of.get(int(i), -1) for i in ids], dtype=int)

    return SiteGeometry(walls=walls, room_rects=tuple(rects), name=site.name, room_index_at=lookup)
