"""Start poses: the paper's fan, a seeded bias, and places in free space."""

from __future__ import annotations

import math

import numpy as np
import pytest
from swarm_sim.departure import (
    departure_poses,
    fan_bias_rad,
    place_starts,
    preferred_directions,
)
from swarm_sim.errors import ConfigurationError
from swarm_sim.sites import Site, generate_site
from swarm_sim.sites.layout import layout_to_site, parse_layout
from swarm_sim.sites.model import NO_ROOM
from swarm_sim.sites.validation import free_space_raster, point_segment_distances
from swarm_sim.world import BodyConfig

# A corridor two cells (0.53 m) wide between rooms; the nominal fan around 'D' reaches into
# the rooms above and below, which open onto the corridor further along.
CORRIDOR = """\
%%%%%%%%%%%%%%%%%%%%%%%%%
%           %           %
%           %           %
%%%%%% %%%%%%%%%%%% %%%%%
%          D            %
%%%%%% %%%%%%%%%%%% %%%%%
%           %           %
%           %           %
%%%%%%%%%%%%%%%%%%%%%%%%%
"""


def corridor_site() -> Site:
    return layout_to_site(parse_layout(CORRIDOR, 'corridor.lay')).site


def assert_in_free_space(site: Site, name: str, poses: np.ndarray, body: BodyConfig) -> None:
    clearance = body.robot_radius_m + 0.5 * body.wall_thickness_m
    for x, y, _ in poses:
        assert point_segment_distances((x, y), site.sealed_walls).min() >= clearance - 1e-9
    gaps = np.hypot(*(poses[:, None, :2] - poses[None, :, :2]).transpose(2, 0, 1))
    np.fill_diagonal(gaps, np.inf)
    assert gaps.min() >= 2 * body.robot_radius_m - 1e-9
    raster = free_space_raster(site)
    start = raster.label_at(site.departure(name).xy)
    assert all(raster.label_at((x, y)) == start for x, y, _ in poses)


@pytest.mark.parametrize('seed', range(4))
def test_centre_starts_of_generated_sites_stay_on_the_nominal_fan(seed: int) -> None:
    site = generate_site('small', seed)
    starts = place_starts(site, 'center', 10, seed=seed)
    assert starts.fan == 'center'
    assert starts.moved == ()
    nominal = departure_poses(site.departure('center').xy, 'center', 10, starts.bias_rad)
    np.testing.assert_array_equal(starts.poses, nominal)


@pytest.mark.parametrize(('config', 'seed'), [('small', 0), ('small', 5), ('medium', 1)])
def test_edge_starts_keep_clear_of_walls_and_of_each_other(config: str, seed: int) -> None:
    site = generate_site(config, seed)
    starts = place_starts(site, 'edge', 10, seed=seed)
    assert starts.fan == 'edge'
    # The nominal half circle of 10 robots overlaps neighbours (0.17 m apart): some move.
    assert 0 < len(starts.moved) < 10
    assert_in_free_space(site, 'edge', starts.poses, BodyConfig())
    np.testing.assert_allclose(
        starts.poses[:, 2], preferred_directions('edge', 10, starts.bias_rad), atol=1e-12
    )


def test_the_fan_fits_a_narrow_corridor_and_never_starts_behind_a_wall() -> None:
    site = corridor_site()
    body = BodyConfig()
    starts = place_starts(site, 'edge', 6, seed=1, body=body)
    nominal = departure_poses(site.departure('edge').xy, 'center', 6, starts.bias_rad)
    assert np.any(site.room_ids_at(nominal[:, :2]) != NO_ROOM)  # the fan reaches into rooms
    assert np.all(site.room_ids_at(starts.poses[:, :2]) == NO_ROOM)
    corridor_y = site.departure('edge').y_m
    assert np.all(np.abs(starts.poses[:, 1] - corridor_y) <= 2 * 4 / 15 / 2 - 0.1125 + 1e-9)
    assert_in_free_space(site, 'edge', starts.poses, body)


def test_the_robot_radius_comes_from_the_body_config() -> None:
    site = generate_site('small', 2)
    body = BodyConfig(robot_radius_m=0.2, wall_thickness_m=0.05)
    starts = place_starts(site, 'edge', 8, seed=2, body=body)
    assert_in_free_space(site, 'edge', starts.poses, body)
    default = place_starts(site, 'edge', 8, seed=2)
    assert not np.array_equal(starts.poses, default.poses)


def test_the_edge_bias_is_seeded_and_keeps_every_direction_into_the_building() -> None:
    n = 10
    inward = math.pi / 2
    biases = [fan_bias_rad('edge', n, seed, inward) for seed in range(60)]
    assert len(set(biases)) == 60
    assert fan_bias_rad('edge', n, 7, inward) == biases[7]
    offsets = np.array(biases) - (inward - math.pi / 2)
    assert np.all(np.abs(offsets) <= math.pi / (2 * n))
    assert offsets.min() < -0.8 * math.pi / (2 * n)
    assert offsets.max() > 0.8 * math.pi / (2 * n)
    for bias in biases:
        phi = preferred_directions('edge', n, bias)
        assert np.all(np.abs(np.angle(np.exp(1j * (phi - inward)))) <= math.pi / 2 + 1e-12)


def test_edge_starts_of_a_site_follow_the_run_seed() -> None:
    site = generate_site('small', 3)
    first = place_starts(site, 'edge', 10, seed=1)
    again = place_starts(site, 'edge', 10, seed=1)
    other = place_starts(site, 'edge', 10, seed=2)
    np.testing.assert_array_equal(first.poses, again.poses)
    assert first.bias_rad != other.bias_rad
    assert not np.allclose(first.poses[:, 2], other.poses[:, 2])


def test_the_centre_bias_is_uniform_over_the_circle() -> None:
    biases = np.array([fan_bias_rad('center', 10, seed) for seed in range(200)])
    assert np.all((biases >= -math.pi) & (biases < math.pi))
    assert np.histogram(biases, bins=4, range=(-math.pi, math.pi))[0].min() > 30


def test_a_given_bias_is_used_as_it_is() -> None:
    site = generate_site('small', 0)
    starts = place_starts(site, 'center', 4, bias_rad=0.25)
    assert starts.bias_rad == 0.25
    np.testing.assert_allclose(starts.poses[:, 2], preferred_directions('center', 4, 0.25))


def test_too_many_robots_for_the_space_is_a_precise_error() -> None:
    pocket = parse_layout('%%%%%%%\n%     %\n%  D  %\n%     %\n%%%%%%%\n', 'pocket.lay')
    site = layout_to_site(pocket).site
    assert len(place_starts(site, 'edge', 3).poses) == 3
    with pytest.raises(
        ConfigurationError,
        match=r"50 robots of radius 0\.1 m do not fit around departure point 'edge' at "
        r'\(0\.800, 0\.533\) m without touching a wall or each other',
    ):
        place_starts(site, 'edge', 50)


def test_an_unknown_departure_point_is_a_configuration_error() -> None:
    with pytest.raises(
        ConfigurationError, match=r"has no departure point 'door' \(it has: center, edge\)"
    ):
        place_starts(generate_site('small', 0), 'door', 3)
