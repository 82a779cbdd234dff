"""The Site model: immutable, structurally checked, with a sealed-entrance view and lookups."""

from __future__ import annotations

import math

import numpy as np
import pytest
from swarm_sim.sites import NO_ROOM, DeparturePoint, Door, Room, Site, SiteError


def make_box_site(**overrides: object) -> Site:
    """A 4 x 3 m building: entrance in the bottom wall, one room in the upper right corner
    with a door in its left wall."""
    fields: dict[str, object] = {
        'name': 'box',
        'width_m': 4.0,
        'height_m': 3.0,
        'walls': [
            (0.0, 0.0, 1.8, 0.0),
            (2.2, 0.0, 4.0, 0.0),
            (4.0, 0.0, 4.0, 3.0),
            (0.0, 3.0, 4.0, 3.0),
            (0.0, 0.0, 0.0, 3.0),
            (2.5, 1.5, 4.0, 1.5),
            (2.5, 1.5, 2.5, 1.9),
            (2.5, 2.5, 2.5, 3.0),
        ],
        'rooms': (Room(1, [(2.5, 1.5, 4.0, 3.0)], label='A'),),
        'doors': (Door((2.5, 1.9, 2.5, 2.5), (1,)),),
        'entrance': Door((1.8, 0.0, 2.2, 0.0)),
        'departure_points': {
            'center': DeparturePoint('center', 1.0, 1.5),
            'edge': DeparturePoint('edge', 2.0, 0.5, heading_rad=math.pi / 2),
        },
    }
    fields.update(overrides)
    return Site(**fields)  # type: ignore[arg-type]


def test_site_arrays_are_read_only_copies() -> None:
    walls = np.array([[0.0, 0.0, 1.0, 0.0]])
    site = make_box_site(walls=walls)
    walls[0, 0] = 9.0
    assert site.walls[0, 0] == 0.0
    with pytest.raises(ValueError, match='read-only'):
        site.walls[0, 0] = 5.0
    with pytest.raises(ValueError, match='read-only'):
        site.rooms[0].rects[0, 0] = 5.0


def test_site_rejects_walls_that_are_not_four_columns() -> None:
    with pytest.raises(SiteError, match=r'\(M, 4\)'):
        make_box_site(walls=[(0.0, 0.0, 1.0)])


def test_site_rejects_duplicate_room_ids() -> None:
    rooms = (Room(1, [(0, 0, 1, 1)]), Room(1, [(2, 0, 3, 1)]))
    with pytest.raises(SiteError, match=r'duplicated: \[1\]'):
        make_box_site(rooms=rooms)


def test_room_rejects_inverted_rectangles_and_empty_areas() -> None:
    with pytest.raises(SiteError, match='x0 < x1'):
        Room(2, [(1.0, 0.0, 0.5, 1.0)])
    with pytest.raises(SiteError, match='no area'):
        Room(2, np.empty((0, 4)))


def test_departure_lookup_names_the_known_points_when_missing() -> None:
    site = make_box_site()
    assert site.departure('edge').heading_rad == pytest.approx(math.pi / 2)
    with pytest.raises(SiteError, match=r"has no departure point 'north' \(it has: center, edge\)"):
        site.departure('north')


def test_departure_points_mapping_cannot_be_changed() -> None:
    site = make_box_site()
    with pytest.raises(TypeError):
        site.departure_points['x'] = DeparturePoint('x', 1.0, 1.0)  # type: ignore[index]


def test_sealed_walls_close_the_entrance_and_plain_walls_leave_it_open() -> None:
    site = make_box_site()
    assert len(site.sealed_walls) == len(site.walls) + 1
    np.testing.assert_allclose(site.sealed_walls[-1], (1.8, 0.0, 2.2, 0.0))
    closed = make_box_site(entrance=None)
    assert len(closed.sealed_walls) == len(closed.walls)


def test_room_area_counts_rectangles_and_polygon() -> None:
    room = Room(3, [(0.0, 0.0, 2.0, 1.0)], polygon=[(2.0, 0.0), (3.0, 0.0), (2.0, 1.0)])
    assert room.area_m2 == pytest.approx(2.0 + 0.5)
    assert room.bounding_rect == (0.0, 0.0, 3.0, 1.0)


def test_room_ids_at_points_uses_the_room_areas() -> None:
    site = make_box_site()
    ids = site.room_ids_at(np.array([[3.0, 2.0], [1.0, 1.0], [5.0, 5.0]]))
    assert ids.tolist() == [1, NO_ROOM, NO_ROOM]
    assert site.room_index(1) == 0
    with pytest.raises(SiteError, match='no room 7'):
        site.room(7)


def test_door_reports_width_and_midpoint() -> None:
    door = Door((2.5, 1.9, 2.5, 2.5), (1,))
    assert door.width_m == pytest.approx(0.6)
    assert door.midpoint == pytest.approx((2.5, 2.2))
    with pytest.raises(SiteError, match='four finite'):
        Door((0.0, math.nan, 1.0, 1.0))


def test_room_bounding_rects_follow_the_room_order() -> None:
    rooms = (Room(4, [(0.0, 0.0, 1.0, 1.0), (1.0, 0.0, 2.0, 0.5)]), Room(2, [(3.0, 1.0, 3.5, 2.0)]))
    site = make_box_site(rooms=rooms, doors=())
    np.testing.assert_allclose(
        site.room_bounding_rects, [[0.0, 0.0, 2.0, 1.0], [3.0, 1.0, 3.5, 2.0]]
    )
    assert make_box_site(rooms=()).room_bounding_rects.shape == (0, 4)


def test_a_site_prints_as_a_short_summary() -> None:
    text = repr(make_box_site())
    assert text == (
        "Site('box', 4.00 x 3.00 m, 1 rooms, 1 doors, 8 walls, entrance=yes, "
        'departure points: center, edge, seed=None)'
    )
