"""Drawing a site with matplotlib, for site previews and Fig.-6-like mission plots.

:func:`draw_site` draws onto any Axes (the mission plots add robot paths on top);
:func:`render_site` writes a PNG without pyplot, so it works headless under any backend.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from pathlib import Path
from typing import Any, Final

import numpy as np
from matplotlib.axes import Axes
from matplotlib.collections import LineCollection, PatchCollection
from matplotlib.colors import ListedColormap
from matplotlib.figure import Figure
from matplotlib.patches import Polygon, Rectangle
from scipy import ndimage

from swarm_sim.sites.model import Site
from swarm_sim.sites.validation import free_space_raster

__all__ = ['ROOM_FILL', 'SOLID_FILL', 'VICTIM_FILL', 'draw_site', 'render_site']

ROOM_FILL: Final = '#ececec'
"""Fill of rooms without a colour of their own."""
VICTIM_FILL: Final = '#f6d8d8'
"""Fill of rooms holding a victim, when no colour is given for them."""
SOLID_FILL: Final = '#9a9a9a'
"""Fill of areas no robot can reach (solid wall blocks)."""
_ENTRANCE_COLOUR: Final = '#2a9d3a'
_DEPARTURE_COLOUR: Final = '#1f5fbf'


def draw_site(
    ax: Axes,
    site: Site,
    *,
    room_colors: Mapping[int, Any] | None = None,
    show_room_ids: bool = True,
    show_doors: bool = False,
    show_departures: bool = True,
    shade_solid: bool = True,
    wall_width_pt: float = 1.2,
) -> None:
    """Draw ``site`` onto ``ax`` in metres, equal aspect.

    Args:
        ax: the matplotlib Axes to draw on.
        site: the site.
        room_colors: room id -> any matplotlib colour, e.g. the colour of the robot that
            entered the room first (as in the paper's Fig. 6); other rooms get a grey fill.
        show_room_ids: write each room's id in it.
        show_doors: mark door gaps with a dotted line.
        show_departures: mark departure points (with an arrow for their heading).
        shade_solid: shade the areas no departure point can reach (the solid wall blocks of
            generated sites), so they are not mistaken for rooms.
        wall_width_pt: wall line width [pt].
    """
    if shade_solid and site.departure_points:
        _shade_unreachable(ax, site)
    colours = dict(room_colors or {})
    patches = []
    faces = []
    for room in site.rooms:
        face = colours.get(room.room_id, VICTIM_FILL if room.has_victim else ROOM_FILL)
        for x0, y0, x1, y1 in room.rects:
            patches.append(Rectangle((x0, y0), x1 - x0, y1 - y0))
            faces.append(face)
        if room.polygon is not None:
            patches.append(Polygon(room.polygon, closed=True))
            faces.append(face)
    if patches:
        ax.add_collection(PatchCollection(patches, facecolors=faces, edgecolors='none', zorder=1))
    if len(site.walls):
        ax.add_collection(
            LineCollection(
                site.walls.reshape(-1, 2, 2), colors='black', linewidths=wall_width_pt, zorder=3
            )
        )
    if show_doors and site.doors:
        segments = np.array([door.segment for door in site.doors]).reshape(-1, 2, 2)
        ax.add_collection(
            LineCollection(segments, colors='#888888', linewidths=0.6, linestyles=':', zorder=2)
        )
    if site.entrance is not None:
        entrance = np.asarray(site.entrance.segment).reshape(1, 2, 2)
        ax.add_collection(
            LineCollection(
                entrance, colors=_ENTRANCE_COLOUR, linewidths=2 * wall_width_pt, zorder=3
            )
        )
    if show_room_ids:
        size = 7 if len(site.rooms) <= 40 else 5
        for room in site.rooms:
            x, y = room.label_point
            ax.text(x, y, str(room.room_id), ha='center', va='center', fontsize=size, zorder=4)
    if show_departures:
        arrow_m = 0.04 * max(site.width_m, site.height_m)
        for point in site.departure_points.values():
            ax.plot(
                point.x_m, point.y_m, marker='o', color=_DEPARTURE_COLOUR, markersize=5, zorder=5
            )
            if point.heading_rad is not None:
                dx = arrow_m * math.cos(point.heading_rad)
                dy = arrow_m * math.sin(point.heading_rad)
                ax.annotate(
                    '',
                    xy=(point.x_m + dx, point.y_m + dy),
                    xytext=point.xy,
                    arrowprops={'arrowstyle': '->', 'color': _DEPARTURE_COLOUR},
                    zorder=5,
                )
            ax.annotate(
                point.name,
                point.xy,
                xytext=(4, -10),
                textcoords='offset points',
                fontsize=7,
                color=_DEPARTURE_COLOUR,
                zorder=5,
            )
    margin = 0.02 * max(site.width_m, site.height_m)
    ax.set_xlim(-margin, site.width_m + margin)
    ax.set_ylim(-margin, site.height_m + margin)
    ax.set_aspect('equal')
    ax.set_xlabel('x [m]')
    ax.set_ylabel('y [m]')


def render_site(
    site: Site,
    path: str | Path,
    *,
    room_colors: Mapping[int, Any] | None = None,
    title: str | None = None,
    dpi: int = 150,
) -> None:
    """Write a PNG of ``site`` (rooms labelled with their ids) to ``path``."""
    width_in = min(16.0, max(6.0, site.width_m * 0.6))
    height_in = width_in * site.height_m / site.width_m + 0.8
    figure = Figure(figsize=(width_in, height_in), layout='constrained')
    ax = figure.add_subplot()
    draw_site(ax, site, room_colors=room_colors, show_doors=True)
    ax.set_title(title if title is not None else _default_title(site))
    figure.savefig(path, dpi=dpi)


def _shade_unreachable(ax: Axes, site: Site) -> None:
    raster = free_space_raster(site, sealed=True)
    labels = raster.labels
    keep = [raster.label_at(point.xy) for point in site.departure_points.values()]
    keep += [labels[0, 0], labels[-1, -1]]  # the outside of the building
    shade = (labels > 0) & ~np.isin(labels, keep)
    shade |= ndimage.binary_dilation(shade) & (labels == 0)  # cover the wall cells around
    ny, nx = shade.shape
    x0, y0 = raster.origin_m
    extent = (x0, x0 + nx * raster.resolution_m, y0, y0 + ny * raster.resolution_m)
    image = np.where(shade, 1.0, np.nan)
    ax.imshow(
        image,
        origin='lower',
        extent=extent,
        cmap=ListedColormap([SOLID_FILL]),
        zorder=0,
        interpolation='nearest',
    )


def _default_title(site: Site) -> str:
    title = f'{site.name}: {len(site.rooms)} rooms, {site.width_m:.1f} x {site.height_m:.1f} m'
    return title if site.seed is None else f'{title}, seed {site.seed}'
