"""The site generator: deterministic, Table II sizes, and the structure of the authors' sites.

Invariants are checked twice: through validate_site and, independently, by a breadth-first
search over the layout characters in this file.
"""

from __future__ import annotations

from collections import deque

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy import ndimage
from swarm_sim.sites import (
    CELL_M,
    PRESETS,
    GeneratorConfig,
    GeneratorError,
    Layout,
    generate_layout,
    generate_site,
    validate_site,
)
from swarm_sim.sites.generator import with_size

SEEDS = range(8)


def chars(layout: Layout) -> list[str]:
    return layout.to_text().splitlines()


def flood_vertices(lines: list[str], start: tuple[int, int]) -> set[tuple[int, int]]:
    """Vertices reachable from ``start`` through non-wall characters (4-neighbours); the
    entrance on the border counts as closed."""
    h, w = len(lines), len(lines[0])
    seen = {start}
    queue = deque([start])
    while queue:
        r, c = queue.popleft()
        for nr, nc in ((r + 1, c), (r - 1, c), (r, c + 1), (r, c - 1)):
            if not (0 < nr < h - 1 and 0 < nc < w - 1) or (nr, nc) in seen:
                continue
            if lines[nr][nc] != '%':
                seen.add((nr, nc))
                queue.append((nr, nc))
    return seen


def full_corridors(lines: list[str], axis: int) -> int:
    """Number of corridors that run through the whole building along ``axis``."""
    grid = np.array([list(line) for line in lines])[1:-1, 1:-1]
    open_lines = np.all(grid == ' ', axis=1 - axis) if axis == 0 else np.all(grid == ' ', axis=0)
    _, count = ndimage.label(open_lines)
    return int(count)


def test_the_same_seed_gives_the_same_site_and_another_seed_another() -> None:
    first = generate_layout('small', 11).to_text()
    assert generate_layout('small', 11).to_text() == first
    assert generate_layout('small', 12).to_text() != first


@pytest.mark.parametrize('config', ['small', 'medium', 'big'])
def test_table_ii_configurations_have_the_papers_size_and_room_count(config: str) -> None:
    expected = {
        'small': (60, 30, 30, 128.0),
        'medium': (80, 40, 60, 228.0),
        'big': (120, 60, 120, 512.0),
    }
    width, height, rooms, area_m2 = expected[config]
    site = generate_site(config, 3)
    assert len(site.rooms) == rooms
    assert site.width_m == pytest.approx((width - 1) * 4 / 15)
    assert site.height_m == pytest.approx((height - 1) * 4 / 15)
    # Table II's area is width x height cells of (4/15 m)^2, rounded.
    assert width * height * CELL_M**2 == pytest.approx(area_m2, abs=0.5)


@pytest.mark.parametrize('seed', SEEDS)
def test_small_sites_are_valid_and_every_room_is_reachable_from_both_departures(seed: int) -> None:
    layout = generate_layout('small', seed)
    site = generate_site('small', seed)
    validate_site(site)
    lines = chars(layout)
    for name in ('center', 'edge'):
        point = site.departure(name)
        start = (round(len(lines) - 1 - point.y_m / CELL_M), round(point.x_m / CELL_M))
        reached = flood_vertices(lines, start)
        letters = {
            (r, c) for r, line in enumerate(lines) for c, ch in enumerate(line) if ch.isalnum()
        }
        assert letters <= reached, f'{name}: unreachable room cells {sorted(letters - reached)[:5]}'


@pytest.mark.parametrize('seed', SEEDS)
def test_the_enclosure_is_closed_except_one_entrance_in_the_bottom_wall(seed: int) -> None:
    lines = chars(generate_layout('small', seed))
    border = lines[0] + lines[-1] + ''.join(line[0] + line[-1] for line in lines[1:-1])
    assert set(border) == {'%', '/'}
    assert lines[0].count('/') == 0
    bottom = lines[-1]
    assert bottom.strip('%') == '/' * bottom.count('/')  # one run
    # Centred on the central vertical corridor, under the edge departure point.
    gap_cols = [c for c, ch in enumerate(bottom) if ch == '/']
    assert np.mean(gap_cols) == pytest.approx((len(bottom) - 1) / 2)


def test_the_entrance_is_a_real_gap_that_sealed_walls_close() -> None:
    site = generate_site('small', 5)
    assert site.entrance is not None
    assert site.entrance.width_m > 0.4  # wide enough for a 0.2 m robot
    x0, y0, x1, y1 = site.entrance.segment
    assert y0 == y1 == 0.0
    assert x0 < site.departure('edge').x_m < x1


def test_departure_points_follow_the_authors_runner() -> None:
    site = generate_site('small', 0)
    centre, edge = site.departure('center'), site.departure('edge')
    # Small: centre at (29.5, 14.5) cells, edge 2.5 cells above the bottom wall.
    assert (centre.x_m, centre.y_m) == pytest.approx((29.5 * CELL_M, 14.5 * CELL_M))
    assert (edge.x_m, edge.y_m) == pytest.approx((29.5 * CELL_M, 2.5 * CELL_M))
    assert edge.heading_rad == pytest.approx(np.pi / 2)


@pytest.mark.parametrize('seed', SEEDS)
def test_small_sites_have_one_horizontal_and_three_to_five_vertical_corridors(seed: int) -> None:
    lines = chars(generate_layout('small', seed))
    assert full_corridors(lines, axis=0) == 1
    assert 3 <= full_corridors(lines, axis=1) <= 5


def test_rooms_open_off_corridors_and_into_other_rooms() -> None:
    for seed in SEEDS:
        text = generate_layout('small', seed).to_text()
        inner = ''.join(line[1:-1] for line in text.splitlines()[1:-1])
        assert inner.count('/') > 0, 'no room opens off a corridor'
        assert inner.count('#') > 0, 'no nested room'
        assert inner.count('/') + inner.count('#') == 30  # one door per room


def island_count(layout: Layout) -> int:
    """Wall groups that do not touch the outer wall (the paper's isolated islands)."""
    walls, _ = ndimage.label(layout.codes == ord('%'))
    border = set(
        np.unique(np.concatenate([walls[0], walls[-1], walls[:, 0], walls[:, -1]])).tolist()
    )
    return len(set(np.unique(walls).tolist()) - border - {0})


def test_medium_and_big_sites_contain_isolated_islands_and_small_ones_do_not() -> None:
    for seed in range(4):
        assert island_count(generate_layout('medium', seed)) >= 1
        assert island_count(generate_layout('big', seed)) >= 1
        assert island_count(generate_layout('small', seed)) == 0


def test_victims_are_marked_on_the_requested_number_of_rooms() -> None:
    site = generate_site('medium', 2)
    assert sum(room.has_victim for room in site.rooms) == PRESETS['medium'].victims == 10
    labels = [room.label for room in site.rooms if room.has_victim]
    assert all(label.isdigit() for label in labels)


@pytest.mark.parametrize(('width', 'height', 'rooms'), [(40, 20, 12), (50, 50, 40), (90, 24, 25)])
def test_free_sizes_meet_their_room_count_and_are_valid(
    width: int, height: int, rooms: int
) -> None:
    config = with_size(PRESETS['small'], width_cells=width, height_cells=height, rooms=rooms)
    site = generate_site(config, 1)
    assert len(site.rooms) == rooms
    assert site.width_m == pytest.approx((width - 1) * CELL_M)


def test_too_many_rooms_fail_with_a_clear_error() -> None:
    config = GeneratorConfig(20, 20, rooms=200, victims=0, max_attempts=2)
    with pytest.raises(GeneratorError, match=r'could place only \d+ of 200 rooms'):
        generate_layout(config, 0)


def test_impossible_parameters_are_rejected() -> None:
    with pytest.raises(GeneratorError, match='at least 10 x 10 cells'):
        GeneratorConfig(8, 30)
    with pytest.raises(GeneratorError, match='victims <= rooms'):
        GeneratorConfig(rooms=3, victims=5)
    with pytest.raises(GeneratorError, match="unknown site configuration 'huge'"):
        generate_site('huge', 0)


def test_rooms_are_rectangles_spanning_their_wall_lines() -> None:
    site = generate_site('small', 4)
    for room in site.rooms:
        assert room.rects.shape == (1, 4)
        x0, y0, x1, y1 = room.rects[0] / CELL_M
        # Wall lines sit on grid vertices; a room is at least 2 x 2 cells between them.
        assert np.allclose([x0, y0, x1, y1], np.round([x0, y0, x1, y1]))
        assert x1 - x0 >= 2 - 1e-9
        assert y1 - y0 >= 2 - 1e-9


@settings(max_examples=15, deadline=None)
@given(
    width=st.integers(10, 90),
    height=st.integers(10, 60),
    room_density=st.floats(0.0, 1.0),
    seed=st.integers(0, 2**32 - 1),
)
def test_any_size_gives_a_valid_site_with_exactly_the_rooms_asked_for_or_a_clear_error(
    width: int, height: int, room_density: float, seed: int
) -> None:
    rooms = max(1, round(room_density * width * height / 50))
    config = GeneratorConfig(width, height, rooms=rooms, victims=min(rooms, 3), max_attempts=3)
    try:
        site = generate_site(config, seed)
    except GeneratorError as err:
        site, failure = None, str(err)
    if site is None:
        assert f'of {rooms} rooms' in failure
    else:
        assert len(site.rooms) == rooms
        validate_site(site)


def test_sizes_beyond_the_layout_and_site_limits_are_rejected() -> None:
    with pytest.raises(GeneratorError, match='5000 x 40 cells is too large'):
        GeneratorConfig(5000, 40)
    with pytest.raises(GeneratorError, match='1000 x 1000 cells is too large'):
        GeneratorConfig(1000, 1000)
    with pytest.raises(GeneratorError, match='a side may be at most 1000 m'):
        GeneratorConfig(60, 30, cell_m=20.0)
    assert GeneratorConfig(2000, 300, rooms=1, victims=0).width_cells == 2000
