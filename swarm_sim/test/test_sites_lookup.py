"""Point -> room id lookup: exact on grid sites, vectorized, safe on bad points."""

from __future__ import annotations

import numpy as np
import pytest
from swarm_sim.sites import NO_ROOM, Room, RoomLookup, SiteValidationError, generate_site
from swarm_sim.sites.room_lookup import points_in_polygon


def brute_force_room_ids(rooms: tuple[Room, ...], points: np.ndarray) -> np.ndarray:
    ids = np.full(len(points), NO_ROOM)
    for room in rooms:
        for x0, y0, x1, y1 in room.rects:
            inside = (
                (points[:, 0] >= x0)
                & (points[:, 0] < x1)
                & (points[:, 1] >= y0)
                & (points[:, 1] < y1)
            )
            ids[inside] = room.room_id
    return ids


def test_lookup_on_a_generated_site_agrees_with_the_room_rectangles() -> None:
    site = generate_site('small', 9)
    rng = np.random.default_rng(0)
    points = rng.uniform((0, 0), (site.width_m, site.height_m), size=(5000, 2))
    expected = brute_force_room_ids(site.rooms, points)
    np.testing.assert_array_equal(site.room_ids_at(points), expected)
    assert np.count_nonzero(expected != NO_ROOM) > 1000  # the sample does land in rooms


def test_every_room_is_found_at_its_label_point() -> None:
    site = generate_site('medium', 1)
    points = np.array([room.label_point for room in site.rooms])
    assert site.room_ids_at(points).tolist() == list(site.room_ids)


def test_points_outside_the_bounds_or_not_finite_are_in_no_room() -> None:
    lookup = RoomLookup((Room(4, [(0.0, 0.0, 1.0, 1.0)]),), 2.0, 2.0, 0.1)
    points = [[0.5, 0.5], [-0.5, 0.5], [0.5, 2.5], [np.nan, 0.5], [np.inf, 0.2], [1.5, 1.5]]
    assert lookup.room_ids(points).tolist() == [4, NO_ROOM, NO_ROOM, NO_ROOM, NO_ROOM, NO_ROOM]


def test_polygon_rooms_are_rasterized() -> None:
    triangle = Room(7, np.empty((0, 4)), polygon=[(0.0, 0.0), (2.0, 0.0), (0.0, 2.0)])
    lookup = RoomLookup((triangle,), 2.0, 2.0, 0.02)
    ids = lookup.room_ids([[0.3, 0.3], [1.5, 1.5], [0.9, 0.9], [1.1, 1.1]])
    assert ids.tolist() == [7, NO_ROOM, 7, NO_ROOM]


def test_overlapping_rooms_are_rejected_with_the_place() -> None:
    rooms = (Room(1, [(0.0, 0.0, 1.0, 1.0)]), Room(2, [(0.5, 0.5, 1.5, 1.5)]))
    with pytest.raises(SiteValidationError, match=r'rooms 1 and 2 overlap near \(0\.5'):
        RoomLookup(rooms, 2.0, 2.0, 0.1)


def test_rooms_reached_sees_a_body_reaching_through_a_door() -> None:
    lookup = RoomLookup((Room(3, [(1.0, 0.0, 2.0, 1.0)]),), 2.0, 1.0, 0.05)
    centre_outside = [[0.95, 0.5]]  # 5 cm left of the room's wall line
    assert 3 in lookup.rooms_reached(centre_outside, reach_m=0.075)[0]
    assert 3 not in lookup.rooms_reached(centre_outside, reach_m=0.02)[0]
    assert lookup.rooms_reached(centre_outside, reach_m=0.075).shape == (1, 5)


def test_lookup_accepts_a_single_point_and_returns_int32() -> None:
    site = generate_site('small', 2)
    room = site.rooms[0]
    ids = site.room_ids_at(np.asarray(room.label_point))
    assert ids.dtype == np.int32
    assert ids.tolist() == [room.room_id]


def test_rooms_fill_only_their_own_cells_of_the_raster() -> None:
    triangle = np.array([(2.0, 0.0), (3.0, 0.0), (2.0, 1.1)])
    rooms = (
        Room(4, [(0.5, 0.5, 1.0, 1.0), (2.5, 1.5, 3.0, 2.0)]),
        Room(7, np.empty((0, 4)), polygon=triangle),
    )
    lookup = RoomLookup(rooms, 3.0, 2.0, 0.25)
    iy, ix = np.mgrid[0:8, 0:12]
    centres = np.column_stack([(ix.ravel() + 0.5) * 0.25, (iy.ravel() + 0.5) * 0.25])
    expected = brute_force_room_ids(rooms[:1], centres)
    expected[points_in_polygon(centres, triangle)] = 7
    np.testing.assert_array_equal(lookup.raster, expected.reshape(8, 12))
    assert np.count_nonzero(lookup.raster == 4) == 8
