"""How many robots fit on a departure fan: inside the site, clear of walls, not stacked."""

from __future__ import annotations

import math

import numpy as np
from swarm_sim.departure import DEFAULT_START_RADIUS_M, departure_poses, fan_fits, max_fan_robots

CLEAR = {'robot_radius_m': 0.1, 'wall_clearance_m': 0.1125}
OPEN_FIELD = (np.zeros((0, 4)), (10.0, 10.0))


def test_the_spacing_limit_follows_the_arc_length():
    walls, bounds = OPEN_FIELD
    centre = max_fan_robots((5.0, 5.0), 'center', 0.0, walls, bounds, **CLEAR)
    edge = max_fan_robots((5.0, 5.0), 'edge', 0.0, walls, bounds, **CLEAR)
    # n robots on an arc a of radius r are 2 r sin(a / 2n) apart; at least 0.1 m.
    assert 2 * DEFAULT_START_RADIUS_M * math.sin(math.pi / centre) >= 0.1
    assert 2 * DEFAULT_START_RADIUS_M * math.sin(math.pi / (centre + 1)) < 0.1
    assert 2 * DEFAULT_START_RADIUS_M * math.sin(math.pi / (2 * edge)) >= 0.1
    assert 2 * DEFAULT_START_RADIUS_M * math.sin(math.pi / (2 * (edge + 1))) < 0.1
    assert (centre, edge) == (33, 16)
    poses = departure_poses((5.0, 5.0), 'center', centre + 1, 0.0)
    assert not fan_fits(poses, walls, bounds, **CLEAR)


def test_a_wall_near_the_departure_point_lowers_the_count_and_a_fan_leaving_the_site_fits_none():
    # 0.62 m to the right of the point: a robot of the 0.533 m fan within 17.8 deg of the
    # +x axis would touch it. With the bias pi, odd fans keep their robots at least pi / n
    # from +x, so the largest that fits is 9.
    wall = np.array([[5.62, 0.0, 5.62, 10.0]])
    bounds = (10.0, 10.0)
    near = max_fan_robots((5.0, 5.0), 'center', math.pi, wall, bounds, **CLEAR)
    assert near == 9
    assert fan_fits(departure_poses((5.0, 5.0), 'center', 9, math.pi), wall, bounds, **CLEAR)
    assert not fan_fits(departure_poses((5.0, 5.0), 'center', 10, math.pi), wall, bounds, **CLEAR)
    assert not fan_fits(departure_poses((5.0, 5.0), 'center', 11, math.pi), wall, bounds, **CLEAR)
    corner = max_fan_robots((0.2, 0.2), 'center', math.pi, np.zeros((0, 4)), bounds, **CLEAR)
    assert corner == 0
