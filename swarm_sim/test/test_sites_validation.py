"""validate_site: closed enclosure, reachable rooms with doors, departure points clear of walls."""

from __future__ import annotations

import math

import pytest
from swarm_sim.sites import (
    DeparturePoint,
    Door,
    Room,
    Site,
    SiteValidationError,
    require_rooms,
    validate_site,
)

OUTER_WALLS = [
    (0.0, 0.0, 1.8, 0.0),
    (2.2, 0.0, 4.0, 0.0),
    (4.0, 0.0, 4.0, 3.0),
    (0.0, 3.0, 4.0, 3.0),
    (0.0, 0.0, 0.0, 3.0),
]
ROOM_WALLS = [(2.5, 1.5, 4.0, 1.5), (2.5, 1.5, 2.5, 1.9), (2.5, 2.5, 2.5, 3.0)]
CLOSED_ROOM_WALLS = [(2.5, 1.5, 4.0, 1.5), (2.5, 1.5, 2.5, 3.0)]


def box_site(**overrides: object) -> Site:
    """4 x 3 m building, entrance at the bottom, room 1 in the upper right with a door."""
    fields: dict[str, object] = {
        'name': 'box',
        'width_m': 4.0,
        'height_m': 3.0,
        'walls': OUTER_WALLS + ROOM_WALLS,
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


def test_a_closed_building_with_reachable_rooms_is_valid() -> None:
    validate_site(box_site())


def test_a_gap_that_is_not_the_entrance_is_an_open_enclosure_named_by_position() -> None:
    site = box_site(entrance=None)
    with pytest.raises(SiteValidationError, match='enclosure is open') as info:
        validate_site(site)
    x, y = info.value.position_m
    assert 1.8 <= x <= 2.2
    assert y == pytest.approx(0.0, abs=0.1)


def test_a_missing_wall_far_from_the_entrance_is_reported_there() -> None:
    walls = [w for w in OUTER_WALLS if w != (4.0, 0.0, 4.0, 3.0)] + [(4.0, 0.0, 4.0, 1.0)]
    with pytest.raises(SiteValidationError, match='enclosure is open') as info:
        validate_site(box_site(walls=walls + ROOM_WALLS))
    x, y = info.value.position_m
    assert x == pytest.approx(4.0, abs=0.1)
    assert 1.0 <= y <= 1.5  # the first gap a robot starting at the centre would leave through


def test_a_room_without_door_is_reported_with_its_key_path() -> None:
    site = box_site(
        walls=OUTER_WALLS + CLOSED_ROOM_WALLS,
        rooms=(Room(1, [(2.5, 1.5, 4.0, 3.0)], label='A'), Room(2, [(0.0, 0.0, 1.0, 1.0)])),
        doors=(Door((0.5, 1.0, 1.0, 1.0), (2,)),),
    )
    with pytest.raises(SiteValidationError, match=r"room 1 \('A'\) .* has no door") as info:
        validate_site(site)
    assert info.value.key_path == ('rooms', 0)


def test_a_room_listed_in_a_door_but_walled_off_is_unreachable() -> None:
    site = box_site(walls=OUTER_WALLS + CLOSED_ROOM_WALLS)
    with pytest.raises(SiteValidationError, match="not reachable from departure point 'center'"):
        validate_site(site)


def test_a_departure_point_inside_a_wall_is_rejected() -> None:
    points = {'center': DeparturePoint('center', 2.5, 1.7)}
    with pytest.raises(
        SiteValidationError, match=r"'center' at \(2\.500, 1\.700\) m is inside a wall"
    ) as info:
        validate_site(box_site(departure_points=points))
    assert info.value.key_path == ('departure_points', 'center')


def test_a_departure_point_closer_to_a_wall_than_the_robot_radius_is_rejected() -> None:
    points = {'edge': DeparturePoint('edge', 1.0, 0.05)}
    validate_site(box_site(departure_points=points), robot_radius_m=0.04)
    with pytest.raises(SiteValidationError, match=r'less than the robot radius 0\.1 m'):
        validate_site(box_site(departure_points=points))


def test_a_departure_point_outside_the_bounds_is_rejected() -> None:
    points = {'edge': DeparturePoint('edge', 2.0, -0.5)}
    with pytest.raises(SiteValidationError, match='outside the site bounds'):
        validate_site(box_site(departure_points=points))


def test_a_site_without_departure_points_is_rejected() -> None:
    with pytest.raises(SiteValidationError, match='no departure point'):
        validate_site(box_site(departure_points={}))


def test_overlapping_rooms_are_rejected() -> None:
    rooms = (Room(1, [(2.5, 1.5, 4.0, 3.0)]), Room(2, [(3.0, 2.0, 3.5, 2.5)]))
    with pytest.raises(SiteValidationError, match='rooms 1 and 2 overlap'):
        validate_site(box_site(rooms=rooms))


def test_walls_outside_the_bounds_are_rejected() -> None:
    with pytest.raises(SiteValidationError, match='leaves the site bounds') as info:
        validate_site(box_site(walls=[*OUTER_WALLS, *ROOM_WALLS, (1.0, 1.0, 5.0, 1.0)]))
    assert info.value.key_path == ('walls', len(OUTER_WALLS) + len(ROOM_WALLS))


def test_a_door_narrower_than_the_robot_is_rejected() -> None:
    doors = (Door((2.5, 1.9, 2.5, 2.05), (1,)),)
    with pytest.raises(
        SiteValidationError, match=r'door at .* is 0\.150 m wide, narrower than a robot'
    ) as info:
        validate_site(box_site(doors=doors))
    assert info.value.key_path == ('doors', 0)


def test_an_entrance_that_is_not_a_gap_in_the_enclosure_is_rejected() -> None:
    walls = [(0.0, 0.0, 4.0, 0.0), *OUTER_WALLS[2:], *ROOM_WALLS]
    with pytest.raises(
        SiteValidationError, match=r'the entrance at \(2\.000, 0\.000\) m is not a gap'
    ):
        validate_site(box_site(walls=walls))


def test_a_site_without_rooms_is_valid_but_not_searchable() -> None:
    empty = box_site(rooms=(), doors=())
    validate_site(empty)
    with pytest.raises(SiteValidationError, match="site 'box': the site has no rooms") as info:
        require_rooms(empty)
    assert info.value.key_path == ('rooms',)
    with pytest.raises(SiteValidationError, match=r'^box\.yaml: the site has no rooms'):
        require_rooms(empty, 'box.yaml')
    require_rooms(box_site())


def test_a_door_that_names_no_room_is_rejected_but_an_entrance_may() -> None:
    with pytest.raises(SiteValidationError, match=r'door at .* names no room') as caught:
        validate_site(box_site(doors=(Door((2.5, 1.9, 2.5, 2.5)),)))
    assert caught.value.key_path == ('doors', 0)
    site = box_site()
    assert site.entrance is not None
    assert site.entrance.room_ids == ()
    validate_site(site)


def test_a_site_too_large_to_rasterize_is_rejected_when_it_is_built() -> None:
    with pytest.raises(SiteValidationError, match='larger than the 1000 m') as caught:
        box_site(width_m=1e6)
    assert caught.value.key_path == ('bounds', 'width_m')
    with pytest.raises(SiteValidationError, match='too large to check') as caught:
        box_site(grid_m=1e-6)
    assert caught.value.key_path == ('bounds',)
