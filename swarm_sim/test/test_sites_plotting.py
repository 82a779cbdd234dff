"""draw_site: walls, room fills (with the caller's colours) and room ids end up on the Axes."""

from __future__ import annotations

import numpy as np
from matplotlib.collections import LineCollection, PatchCollection
from matplotlib.colors import to_rgba
from matplotlib.figure import Figure
from swarm_sim.sites import generate_site
from swarm_sim.sites.plotting import ROOM_FILL, draw_site


def test_draw_site_puts_every_wall_room_and_id_on_the_axes() -> None:
    site = generate_site('small', 8)
    ax = Figure().add_subplot()
    first = site.rooms[0].room_id
    draw_site(ax, site, room_colors={first: 'tab:orange'})
    walls = [c for c in ax.collections if isinstance(c, LineCollection)]
    assert len(walls[0].get_segments()) == len(site.walls)
    rooms = next(c for c in ax.collections if isinstance(c, PatchCollection))
    faces = rooms.get_facecolors()
    assert len(faces) == len(site.rooms)
    np.testing.assert_allclose(faces[0], to_rgba('tab:orange'))
    plain = [i for i, room in enumerate(site.rooms) if not room.has_victim and i > 0]
    np.testing.assert_allclose(faces[plain[0]], to_rgba(ROOM_FILL))
    texts = {t.get_text() for t in ax.texts}
    assert {str(room_id) for room_id in site.room_ids} <= texts
    assert ax.get_xlim()[0] < 0 < site.width_m < ax.get_xlim()[1]


def test_departure_points_are_marked_and_named() -> None:
    site = generate_site('small', 8)
    ax = Figure().add_subplot()
    draw_site(ax, site, show_room_ids=False)
    names = {t.get_text() for t in ax.texts}
    assert {'center', 'edge'} <= names
    assert not any(t.get_text().isdigit() for t in ax.texts)
