"""Site <-> swarm_interfaces/Site: correctly typed fields, and a lossless round trip through CDR."""

from __future__ import annotations

import math

import numpy as np
import pytest
from sim_bridge.site_msgs import site_from_ros, site_to_ros
from swarm_runtime.messages import cdr_roundtrip
from swarm_sim.sites import DeparturePoint, Door, Room, Site, SiteError, generate_site


def assert_same_site(a: Site, b: Site) -> None:
    assert (a.name, a.seed, a.grid_m) == (b.name, b.seed, b.grid_m)
    assert (a.width_m, a.height_m) == (b.width_m, b.height_m)
    np.testing.assert_array_equal(a.walls, b.walls)
    assert [r.room_id for r in a.rooms] == [r.room_id for r in b.rooms]
    assert [(r.label, r.has_victim) for r in a.rooms] == [(r.label, r.has_victim) for r in b.rooms]
    for ra, rb in zip(a.rooms, b.rooms, strict=True):
        np.testing.assert_array_equal(ra.rects, rb.rects)
        assert (ra.polygon is None) == (rb.polygon is None)
    assert a.doors == b.doors
    assert a.entrance == b.entrance
    assert dict(a.departure_points) == dict(b.departure_points)


def test_a_generated_site_survives_a_cdr_round_trip_unchanged() -> None:
    site = generate_site('small', 6)
    received = cdr_roundtrip(site_to_ros(site, time_s=12.25, frame_id='world'))
    assert received.header.stamp.sec == 12
    assert received.header.stamp.nanosec == 250_000_000
    assert received.header.frame_id == 'world'
    assert len(received.rooms) == 30
    assert_same_site(site_from_ros(received), site)


def test_a_free_form_site_without_seed_grid_or_entrance_round_trips() -> None:
    site = Site(
        name='hall',
        width_m=3.0,
        height_m=2.0,
        walls=[(0.0, 0.0, 3.0, 0.0)],
        rooms=(
            Room(
                5, np.empty((0, 4)), polygon=[(0.0, 0.0), (1.0, 0.0), (0.0, 1.0)], has_victim=True
            ),
        ),
        doors=(Door((1.0, 0.0, 1.5, 0.0), ()),),
        departure_points={'center': DeparturePoint('center', 1.5, 1.0)},
    )
    msg = site_to_ros(site)
    assert msg.seed == -1
    assert msg.grid_m == 0.0
    assert len(msg.entrance) == 0
    assert math.isnan(msg.departure_points[0].heading)
    again = site_from_ros(cdr_roundtrip(msg))
    assert_same_site(again, site)
    np.testing.assert_array_equal(again.room(5).polygon, site.room(5).polygon)


def test_room_order_in_the_message_is_the_room_index() -> None:
    site = generate_site('small', 2)
    msg = site_to_ros(site)
    assert [room.id for room in msg.rooms] == list(site.room_ids)
    assert site.room_index(msg.rooms[4].id) == 4


def test_a_message_with_a_broken_walls_array_is_rejected() -> None:
    msg = site_to_ros(generate_site('small', 0))
    msg.walls = [0.0, 1.0, 2.0]
    with pytest.raises(SiteError, match='not a multiple of 4'):
        site_from_ros(msg)
