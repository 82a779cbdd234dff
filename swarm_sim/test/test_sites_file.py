"""YAML site files (swarm_site/1): round trip, example files, and errors with line and key."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from swarm_sim.sites import SiteFileError, generate_site
from swarm_sim.sites.site_file import (
    FORMAT,
    MAX_FILE_BYTES,
    dump_site,
    load_site,
    parse_site,
    save_site,
)

CONFIG_DIR = Path(__file__).resolve().parents[1] / 'config' / 'sites'

MINIMAL = """\
format: swarm_site/1
name: box
bounds: {width_m: 4.0, height_m: 3.0}
departure_points:
  center: {x_m: 1.0, y_m: 1.5}
  edge: {x_m: 2.0, y_m: 0.5, heading_rad: 1.5708}
entrance: {segment: [1.8, 0.0, 2.2, 0.0]}
walls:
  - [0.0, 0.0, 1.8, 0.0]
  - [2.2, 0.0, 4.0, 0.0]
  - [4.0, 0.0, 4.0, 3.0]
  - [0.0, 3.0, 4.0, 3.0]
  - [0.0, 0.0, 0.0, 3.0]
  - [2.5, 1.5, 4.0, 1.5]
  - [2.5, 1.5, 2.5, 1.9]
  - [2.5, 2.5, 2.5, 3.0]
rooms:
  - id: 1
    label: A
    rects: [[2.5, 1.5, 4.0, 3.0]]
doors:
  - {segment: [2.5, 1.9, 2.5, 2.5], rooms: [1]}
"""


def test_a_departure_point_inside_a_room_is_a_warning_naming_line_and_key() -> None:
    text = MINIMAL.replace('  edge: {x_m: 2.0', '  inside: {x_m: 3.2, y_m: 2.2}\n  edge: {x_m: 2.0')
    site = parse_site(text, 'box.yaml')
    (warning,) = site.warnings
    assert warning.startswith("box.yaml:6: departure_points.inside: departure point 'inside'")
    assert "lies inside room 1 ('A'): robots start in that room" in warning
    assert parse_site(MINIMAL, 'box.yaml').warnings == ()


def test_a_minimal_site_file_loads_into_the_site_it_describes() -> None:
    site = parse_site(MINIMAL, 'box.yaml')
    assert site.name == 'box'
    assert (site.width_m, site.height_m) == (4.0, 3.0)
    assert site.walls.shape == (8, 4)
    assert site.room(1).label == 'A'
    assert site.departure('edge').heading_rad == pytest.approx(1.5708)
    assert site.entrance is not None
    assert site.doors[0].room_ids == (1,)
    assert site.seed is None
    assert site.grid_m is None


def test_a_generated_site_round_trips_through_a_file(tmp_path: Path) -> None:
    site = generate_site('medium', 4)
    path = tmp_path / 'medium.yaml'
    save_site(site, path)
    loaded = load_site(path)
    assert loaded.name == site.name
    assert loaded.seed == 4
    assert loaded.grid_m == site.grid_m
    np.testing.assert_allclose(loaded.walls, site.walls, atol=1e-6)
    assert [r.room_id for r in loaded.rooms] == [r.room_id for r in site.rooms]
    assert [r.label for r in loaded.rooms] == [r.label for r in site.rooms]
    assert [r.has_victim for r in loaded.rooms] == [r.has_victim for r in site.rooms]
    for a, b in zip(loaded.rooms, site.rooms, strict=True):
        np.testing.assert_allclose(a.rects, b.rects, atol=1e-6)
    assert [d.room_ids for d in loaded.doors] == [d.room_ids for d in site.doors]
    assert dict(loaded.departure_points).keys() == dict(site.departure_points).keys()
    # The room lookup of the loaded site agrees with the original's.
    rng = np.random.default_rng(1)
    points = rng.uniform((0, 0), (site.width_m, site.height_m), size=(2000, 2))
    np.testing.assert_array_equal(loaded.room_ids_at(points), site.room_ids_at(points))


def test_polygon_rooms_and_victims_survive_a_round_trip() -> None:
    text = MINIMAL.replace(
        '    rects: [[2.5, 1.5, 4.0, 3.0]]',
        '    victim: true\n    polygon: [[2.5, 1.5], [4.0, 1.5], [4.0, 3.0], [2.5, 3.0]]',
    )
    site = parse_site(text)
    again = parse_site(dump_site(site))
    assert again.room(1).has_victim
    np.testing.assert_allclose(again.room(1).polygon, site.room(1).polygon)
    assert len(again.room(1).rects) == 0


def test_the_example_site_file_is_valid_and_starts_with_the_format() -> None:
    path = CONFIG_DIR / 'small_seed1.yaml'
    text = path.read_text()
    assert f'format: {FORMAT}' in text
    site = load_site(path)
    assert len(site.rooms) == 30
    assert set(site.departure_points) == {'center', 'edge'}


@pytest.mark.parametrize(
    ('old', 'new', 'expected'),
    [
        (
            'format: swarm_site/1',
            'format: swarm_site/2',
            r'box\.yaml:1: format: unsupported format',
        ),
        ('name: box\n', '', r"box\.yaml:1: missing required key 'name'"),
        ('bounds:', 'bound:', r'box\.yaml:3: bound: unknown key'),
        ('width_m: 4.0', 'width_m: -4.0', r'box\.yaml:3: bounds\.width_m: expected a positive'),
        (
            '  - [4.0, 0.0, 4.0, 3.0]',
            '  - [4.0, 0.0, 4.0]',
            r'box\.yaml:11: walls\[2\]: expected 4',
        ),
        (
            '  - [0.0, 3.0, 4.0, 3.0]',
            '  - [0.0, three, 4.0, 3.0]',
            r'box\.yaml:12: walls\[3\]\[1\]: expected a number',
        ),
        (
            'rects: [[2.5, 1.5, 4.0, 3.0]]',
            'rects: [[4.0, 1.5, 2.5, 3.0]]',
            r'box\.yaml:20: rooms\[0\]\.rects\[0\]: a rectangle needs x0 < x1',
        ),
        (
            '    label: A\n',
            '    label: A\n    size: 3\n',
            r'box\.yaml:20: rooms\[0\]\.size: unknown key',
        ),
        (
            'rooms: [1]}',
            'rooms: [7]}',
            r'box\.yaml:22: doors\[0\]: door at \(2\.500, 2\.200\) m names unknown rooms \[7\]',
        ),
        (
            'edge: {x_m: 2.0, y_m: 0.5',
            'edge: {x_m: 2.5, y_m: 1.6',
            r"box\.yaml:6: departure_points\.edge: departure point 'edge' .* is inside a wall",
        ),
        (
            '  - [2.5, 1.5, 2.5, 1.9]\n',
            '  - [2.5, 1.5, 2.5, 3.0]\n',
            r"box\.yaml:18: rooms\[0\]: room 1 \('A'\) .* not reachable",
        ),
        ('  - [2.2, 0.0, 4.0, 0.0]\n', '', r'box\.yaml:8: walls: the enclosure is open'),
        (
            '  center: {x_m: 1.0, y_m: 1.5}',
            '  center: [1.0, 1.5]',
            r'box\.yaml:5: departure_points\.center: expected a mapping',
        ),
    ],
)
def test_bad_site_files_name_the_line_and_key(old: str, new: str, expected: str) -> None:
    assert old in MINIMAL
    with pytest.raises(SiteFileError, match=expected):
        parse_site(MINIMAL.replace(old, new, 1), 'box.yaml')


def test_a_duplicate_room_id_names_both_places() -> None:
    text = MINIMAL.replace('doors:', '  - id: 1\n    rects: [[0.5, 2.5, 1.0, 3.0]]\ndoors:')
    with pytest.raises(
        SiteFileError,
        match=r'box\.yaml:21: rooms\[1\]\.id: room id 1 is used twice \(first at line 18\)',
    ):
        parse_site(text, 'box.yaml')


def test_broken_yaml_and_empty_files_are_reported_with_the_file() -> None:
    with pytest.raises(SiteFileError, match=r'box\.yaml:3: not valid YAML'):
        parse_site('format: swarm_site/1\nname: [box\nbounds: {', 'box.yaml')
    with pytest.raises(SiteFileError, match=r'box\.yaml: the file is empty'):
        parse_site('', 'box.yaml')
    with pytest.raises(SiteFileError, match=r'box\.yaml:1: expected a mapping'):
        parse_site('- 1\n- 2\n', 'box.yaml')


@pytest.mark.parametrize(
    ('old', 'new', 'expected'),
    [
        (
            'width_m: 4.0',
            'width_m: 10000.0',
            r'box\.yaml:3: bounds\.width_m: 10000 m is larger than the 1000 m a site side may be',
        ),
        (
            'height_m: 3.0',
            'height_m: 1.0e+308',
            r'box\.yaml:3: bounds\.height_m: 1e\+308 m is larger than the 1000 m',
        ),
        (
            'width_m: 4.0, height_m: 3.0',
            'width_m: 900.0, height_m: 900.0',
            r'box\.yaml:3: bounds: 900 x 900 m is too large to check: .* more than the 10,000,000',
        ),
        (
            'name: box\n',
            'name: box\ngrid_m: 0.00001\n',
            r'box\.yaml:4: bounds: .*a quarter of grid_m 1e-05 m.* more than the 10,000,000',
        ),
    ],
)
def test_bounds_too_large_to_simulate_are_refused_before_anything_is_built(
    old: str, new: str, expected: str
) -> None:
    assert old in MINIMAL
    with pytest.raises(SiteFileError, match=expected):
        parse_site(MINIMAL.replace(old, new, 1), 'box.yaml')


def test_walls_longer_in_total_than_the_raster_allows_are_refused() -> None:
    many = '  - [0.0, 0.0, 0.0, 1000.0]\n' * 300
    text = MINIMAL.replace('walls:\n', 'walls:\n' + many, 1)
    with pytest.raises(
        SiteFileError, match=r'box\.yaml:8: walls: the walls are 300016 m long in total'
    ):
        parse_site(text, 'box.yaml')


def test_a_recursive_alias_is_a_site_file_error_not_a_crash() -> None:
    with pytest.raises(SiteFileError, match=r'box\.yaml:1: a\[0\]: .*recursive alias'):
        parse_site('a: &a [*a]\n', 'box.yaml')
    text = MINIMAL.replace('walls:\n', 'walls: &w\n  - *w\n', 1)
    with pytest.raises(SiteFileError, match=r'box\.yaml:8: walls\[0\]: .*recursive alias'):
        parse_site(text, 'box.yaml')


def test_deep_nesting_is_a_site_file_error_not_a_crash() -> None:
    with pytest.raises(SiteFileError, match=r'box\.yaml:1: .*nested more than 32 levels deep'):
        parse_site('[' * 5000 + ']' * 5000, 'box.yaml')


def test_an_alias_used_many_times_is_read_once() -> None:
    bomb = 'a: &a [x, x, x, x, x, x, x, x, x]\n' + ''.join(
        f'{b}: &{b} [{", ".join([f"*{a}"] * 9)}]\n'
        for a, b in zip('abcdefgh', 'bcdefghi', strict=True)
    )
    with pytest.raises(SiteFileError, match=r'box\.yaml:1: a: unknown key'):
        parse_site(bomb, 'box.yaml')


def test_a_duplicate_key_names_both_lines() -> None:
    text = MINIMAL + 'name: again\n'
    with pytest.raises(
        SiteFileError, match=r"box\.yaml:23: name: duplicate key 'name' \(first at line 2\)"
    ):
        parse_site(text, 'box.yaml')
    nested = MINIMAL.replace('{x_m: 1.0, y_m: 1.5}', '{x_m: 1.0, y_m: 1.5, x_m: 2.0}')
    with pytest.raises(SiteFileError, match=r'box\.yaml:5: departure_points\.center\.x_m: dup'):
        parse_site(nested, 'box.yaml')


def test_a_door_must_name_a_room_but_the_entrance_need_not() -> None:
    for door in ('{segment: [2.5, 1.9, 2.5, 2.5], rooms: []}', '{segment: [2.5, 1.9, 2.5, 2.5]}'):
        text = MINIMAL.replace('{segment: [2.5, 1.9, 2.5, 2.5], rooms: [1]}', door)
        with pytest.raises(SiteFileError, match=r'box\.yaml:22: doors\[0\].*a door joins rooms'):
            parse_site(text, 'box.yaml')
    text = MINIMAL.replace(
        'entrance: {segment: [1.8, 0.0, 2.2, 0.0]}',
        'entrance: {segment: [1.8, 0.0, 2.2, 0.0], rooms: []}',
    )
    assert parse_site(text, 'box.yaml').entrance is not None


def test_a_file_larger_than_a_site_file_may_be_is_refused_unread(tmp_path: Path) -> None:
    path = tmp_path / 'big.yaml'
    path.write_text(MINIMAL + '#' * MAX_FILE_BYTES)
    with pytest.raises(SiteFileError, match=r'big\.yaml: the file is larger than the 16 MiB'):
        load_site(path)
