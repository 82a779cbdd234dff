"""Importing the authors' ASCII .lay layouts: labelled, unlabelled, and bad input."""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np
import pytest
from swarm_sim.sites import (
    CELL_M,
    NO_ROOM,
    Layout,
    LayoutError,
    LayoutImport,
    LayoutMode,
    Room,
    generate_layout,
    import_layout,
    layout_to_site,
)
from swarm_sim.sites.door_gaps import DoorGap, closing_masks, find_door_gaps
from swarm_sim.sites.layout import (
    MAX_LAYOUT_COLUMNS,
    MAX_LAYOUT_LINES,
    parse_layout,
    read_layout,
    write_layout,
)

CONFIG_DIR = Path(__file__).resolve().parents[1] / 'config' / 'sites'

# Four rooms: A and the victim room 3 open off the corridors, B opens off the vertical
# corridor and C opens only into B (a nested room). Entrance at the bottom.
LABELLED = """\
%%%%%%%%%%%%%%%%
%AAAA%    %BB#C%
%AAAA%    /BB%C%
%%/%%%    %%%%%%
%              %
%              %
%%%/%%    %%%%%%
%3333%    %%%%%%
%3333%    %%%%%%
%%%%%%%//%%%%%%%
"""

# The same kind of building drawn as a plan: walls only, door gaps, a departure mark.
UNLABELLED = """\
%%%%%%%%%%%%%%%%%%
%    %     %     %
%    %           %
%% %%%%% %%%%%%%%%
%                %
%  DD            %
%%%%%%%%% %%%%%%%%
%                %
%                %
%%%%%%%%%%%%%%%%%%
"""

# Doors two vertices (0.8 m) wide; a two-cell-wide corridor leads down to a hall.
WIDE_DOORS = """\
%%%%%%%%%%%%%%%%%%%%%%
%      %      %      %
%      %      %      %
%      %      %      %
%%%  %%%%%  %%%%  %%%%
%                    %
% DD                 %
%                    %
%%%%%%%%%%%%%%%%%  %%%
%%%%%%%%%%%%%%%%%  %%%
%                    %
%                    %
%%%%%%%%%%%%%%%%%%%%%%
"""


def write(tmp_path: Path, text: str, name: str = 'plan.lay') -> Path:
    path = tmp_path / name
    path.write_text(text)
    return path


def room_by_label(result: LayoutImport, label: str) -> Room:
    return next(room for room in result.site.rooms if room.label == label)


def test_labelled_layout_gives_one_room_per_letter_group_with_its_doors(tmp_path: Path) -> None:
    result = import_layout(write(tmp_path, LABELLED))
    assert result.mode is LayoutMode.LABELLED
    assert sorted(room.label for room in result.site.rooms) == ['3', 'A', 'B', 'C']
    assert result.doors_found == 4
    a = room_by_label(result, 'A')
    # A's interior is lines 2-3, columns 2-5; its area spans the wall lines around it.
    np.testing.assert_allclose(a.rects, [[0.0, 6 * CELL_M, 5 * CELL_M, 9 * CELL_M]])
    victim = room_by_label(result, '3')
    assert victim.has_victim
    assert not a.has_victim


def test_labelled_doors_join_the_right_rooms(tmp_path: Path) -> None:
    result = import_layout(write(tmp_path, LABELLED))
    ids = {room.label: room.room_id for room in result.site.rooms}
    joined = sorted(door.room_ids for door in result.site.doors)
    expected = sorted([(ids['A'],), (ids['3'],), (ids['B'],), tuple(sorted((ids['B'], ids['C'])))])
    assert joined == expected
    for door in result.site.doors:
        assert door.width_m == pytest.approx(2 * CELL_M)  # one missing vertex


def test_labelled_layout_gets_the_runners_departure_points_and_the_entrance(
    tmp_path: Path,
) -> None:
    site = import_layout(write(tmp_path, LABELLED)).site
    assert site.departure('center').xy == pytest.approx((7.5 * CELL_M, 4.5 * CELL_M))
    assert site.departure('edge').xy == pytest.approx((7.5 * CELL_M, 2.5 * CELL_M))
    assert site.entrance is not None
    assert site.entrance.segment == pytest.approx((6 * CELL_M, 0.0, 9 * CELL_M, 0.0))
    assert site.name == 'plan'
    assert site.grid_m == pytest.approx(CELL_M)


def test_unlabelled_plan_finds_rooms_behind_door_gaps_and_says_how_many(tmp_path: Path) -> None:
    result = import_layout(write(tmp_path, UNLABELLED), departure_name='center')
    assert result.mode is LayoutMode.UNLABELLED
    # Top: three rooms, the right one opening only into the middle one; bottom: one.
    assert result.rooms_found == 4
    site = result.site
    assert site.departure('center').xy == pytest.approx((3.5 * CELL_M, 4.0 * CELL_M))
    corridor_point = (10 * CELL_M, 4.5 * CELL_M)
    top_left = (2 * CELL_M, 7.5 * CELL_M)
    top_middle = (8 * CELL_M, 7.5 * CELL_M)
    top_right = (14 * CELL_M, 7.5 * CELL_M)
    bottom = (4 * CELL_M, 1.5 * CELL_M)
    ids = site.room_ids_at(np.array([corridor_point, top_left, top_middle, top_right, bottom]))
    assert ids[0] == NO_ROOM
    assert len(set(ids[1:].tolist())) == 4
    assert NO_ROOM not in ids[1:]


def test_unlabelled_doors_connect_rooms_and_corridor(tmp_path: Path) -> None:
    site = import_layout(write(tmp_path, UNLABELLED)).site
    room_doors = [door for door in site.doors if len(door.room_ids) == 2]
    corridor_doors = [door for door in site.doors if len(door.room_ids) == 1]
    assert len(room_doors) == 1  # between the top middle and top right rooms
    assert len(corridor_doors) == 3


def test_wider_door_gaps_are_found_when_allowed_and_a_narrow_corridor_is_no_door(
    tmp_path: Path,
) -> None:
    path = write(tmp_path, WIDE_DOORS)
    assert import_layout(path).rooms_found == 0  # one-vertex doors only: no room closed off
    result = import_layout(path, max_door_cells=2)
    assert result.rooms_found == 3
    assert [door.width_m for door in result.site.doors] == pytest.approx([3 * CELL_M] * 3)
    hall = (10 * CELL_M, 1.5 * CELL_M)
    assert result.site.room_ids_at(np.array([hall])).tolist() == [NO_ROOM]
    with pytest.raises(LayoutError, match='max_door_cells must be at least 1'):
        import_layout(path, max_door_cells=0)


def test_the_example_office_plan_imports_with_its_nested_and_island_rooms() -> None:
    result = import_layout(CONFIG_DIR / 'office_plan.lay')
    assert result.mode is LayoutMode.UNLABELLED
    assert result.rooms_found == 10
    assert result.site.entrance is not None


def strip_labels(layout: Layout) -> Layout:
    """The generated building as the authors' plans draw it: walls only, and a 'D' in the
    middle of the corridor cross."""
    codes = layout.codes.copy()
    inner = codes[1:-1, 1:-1]
    inner[inner != ord('%')] = ord(' ')
    h, w = codes.shape
    codes[h // 2 - 1 : h // 2 + 1, w // 2 - 1 : w // 2 + 1] = ord('D')
    return Layout(codes, 'stripped')


@pytest.mark.parametrize('seed', range(6))
def test_unlabelled_import_of_a_generated_building_recovers_its_rooms(seed: int) -> None:
    layout = generate_layout('small', seed)
    truth = layout_to_site(layout, mode='labelled').site
    found = layout_to_site(strip_labels(layout), mode='unlabelled').site
    h, w = layout.shape
    xs, ys = np.meshgrid((np.arange(w - 1) + 0.5) * CELL_M, (np.arange(h - 1) + 0.5) * CELL_M)
    squares = np.column_stack([xs.ravel(), ys.ravel()])
    true_ids, found_ids = truth.room_ids_at(squares), found.room_ids_at(squares)
    # Never a corridor counted as room or a room lost to the corridor, never a room split.
    np.testing.assert_array_equal(true_ids == NO_ROOM, found_ids == NO_ROOM)
    for room_id in truth.room_ids:
        assert len(np.unique(found_ids[true_ids == room_id])) == 1
    # Only one-cell-wide rooms opening into each other can merge.
    assert len(found.rooms) >= 0.85 * len(truth.rooms)


def test_generated_layout_round_trips_through_a_lay_file(tmp_path: Path) -> None:
    layout = generate_layout('medium', 3)
    path = tmp_path / 'medium.lay'
    write_layout(layout, path)
    assert read_layout(path).to_text() == layout.to_text()
    again = import_layout(path).site
    original = layout_to_site(layout, mode='labelled').site
    np.testing.assert_allclose(again.walls, original.walls)
    assert [r.label for r in again.rooms] == [r.label for r in original.rooms]


def test_explicit_departure_points_replace_the_automatic_ones(tmp_path: Path) -> None:
    site = import_layout(write(tmp_path, LABELLED), departures={'hall': (5.5, 3.0)}).site
    assert list(site.departure_points) == ['hall']
    assert site.departure('hall').xy == pytest.approx((2 * CELL_M, 4.5 * CELL_M))


def test_windows_line_ends_are_accepted() -> None:
    layout = parse_layout(LABELLED.replace('\n', '\r\n'))
    assert layout.shape == (10, 16)


# Bad input: every error names the file, line and column.


def replace_char(text: str, line: int, column: int, char: str) -> str:
    lines = text.splitlines()
    row = lines[line - 1]
    lines[line - 1] = row[: column - 1] + char + row[column:]
    return '\n'.join(lines) + '\n'


def import_text(tmp_path: Path, text: str, **kwargs: object) -> LayoutImport:
    return import_layout(write(tmp_path, text), **kwargs)  # type: ignore[arg-type]


def test_an_open_enclosure_is_reported_at_the_gap(tmp_path: Path) -> None:
    text = replace_char(LABELLED, 5, 1, ' ')
    with pytest.raises(LayoutError, match=r'plan\.lay:5:1: the enclosure is open') as info:
        import_text(tmp_path, text)
    assert (info.value.line, info.value.column) == (5, 1)


def test_a_second_entrance_is_reported(tmp_path: Path) -> None:
    text = replace_char(LABELLED, 1, 8, '/')
    with pytest.raises(LayoutError, match=r':10:8: a second entrance.*line 1, column 8'):
        import_text(tmp_path, text)


def test_an_entrance_in_a_corner_is_reported(tmp_path: Path) -> None:
    with pytest.raises(LayoutError, match=r':10:1: the entrance cannot be at a corner'):
        import_text(tmp_path, replace_char(LABELLED, 10, 1, '/'))


def test_a_labelled_room_without_door_is_reported_at_its_first_cell(tmp_path: Path) -> None:
    text = replace_char(LABELLED, 4, 3, '%')  # A's door
    with pytest.raises(LayoutError, match=r":2:2: room 'A' has no door"):
        import_text(tmp_path, text)


def test_an_enclosed_area_without_a_gap_in_a_plan_is_a_sealed_void_read_as_solid(
    tmp_path: Path,
) -> None:
    text = replace_char(UNLABELLED, 7, 10, '%')  # close the bottom room's gap
    result = import_text(tmp_path, text)
    assert result.rooms_found == 3
    assert result.voids_found == 1
    (warning,) = result.site.warnings
    assert re.search(
        r'plan\.lay:8:2: an enclosed area with no door \(51 cells, lines 7-10, '
        r'columns 1-18\) .* read as solid',
        warning,
    )
    # Read as solid: no room there.
    bottom = (4 * CELL_M, 1.5 * CELL_M)
    assert result.site.room_ids_at(np.array([bottom])).tolist() == [NO_ROOM]


def test_a_departure_point_on_a_wall_is_inside_a_wall(tmp_path: Path) -> None:
    with pytest.raises(LayoutError, match=r":4:4: departure point 'edge' .* is inside a wall"):
        import_text(tmp_path, UNLABELLED, departures={'edge': (4, 4)})


def test_a_runner_departure_point_in_a_wall_block_is_reported_with_its_place(
    tmp_path: Path,
) -> None:
    text = LABELLED
    for line, column in ((5, 8), (5, 9), (6, 8), (6, 9)):
        text = replace_char(text, line, column, '%')
    with pytest.raises(
        LayoutError, match=r":5:8: departure point 'center' lies inside a solid block of wall"
    ):
        import_text(tmp_path, text)


def test_unknown_characters_are_reported_with_line_and_column(tmp_path: Path) -> None:
    with pytest.raises(LayoutError, match=r":4:7: unknown character '@'"):
        import_text(tmp_path, replace_char(LABELLED, 4, 7, '@'))
    with pytest.raises(LayoutError, match=r":4:7: unknown character '\\t'"):
        import_text(tmp_path, replace_char(LABELLED, 4, 7, '\t'))


def test_labels_past_z_as_the_authors_generator_writes_them_are_rooms(tmp_path: Path) -> None:
    text = LABELLED.replace('AAAA', '^^^^').replace('BB', 'ÀÀ')
    result = import_text(tmp_path, text)
    assert sorted(room.label for room in result.site.rooms) == ['3', 'C', '^', 'À']


def test_non_printable_characters_and_broken_encodings_are_reported(tmp_path: Path) -> None:
    with pytest.raises(LayoutError, match=r":3:5: unknown character '\\xa0'"):
        import_text(tmp_path, replace_char(LABELLED, 3, 5, '\u00a0'))
    path = tmp_path / 'latin1.lay'
    path.write_bytes(replace_char(LABELLED, 3, 5, 'é').encode('latin-1'))
    with pytest.raises(LayoutError, match=r':3:5: the file is not UTF-8 text'):
        import_layout(path)


def test_ragged_lines_are_reported(tmp_path: Path) -> None:
    lines = LABELLED.splitlines()
    lines[6] = lines[6][:-1]
    with pytest.raises(LayoutError, match=r':7: line has 15 characters, the first line has 16'):
        import_text(tmp_path, '\n'.join(lines) + '\n')


def test_a_door_that_is_not_in_a_wall_line_is_reported(tmp_path: Path) -> None:
    with pytest.raises(LayoutError, match=r":5:5: door '#' is not a gap in a straight wall"):
        import_text(tmp_path, replace_char(LABELLED, 5, 5, '#'))


def test_rooms_touching_without_a_wall_are_reported(tmp_path: Path) -> None:
    text = replace_char(LABELLED, 2, 14, 'B')  # B and C now share no wall
    text = replace_char(text, 3, 14, 'B')
    with pytest.raises(LayoutError, match=r"rooms 'B' and 'C' touch without a wall"):
        import_text(tmp_path, text)


def test_a_plan_without_departure_mark_starts_in_its_middle_and_says_so(tmp_path: Path) -> None:
    # The authors' simulator starts from the middle of a plan without 'D'.
    site = import_text(tmp_path, UNLABELLED.replace('D', ' ')).site
    assert list(site.departure_points) == ['center']
    assert site.departure('center').xy == pytest.approx((8.5 * CELL_M, 4.5 * CELL_M))
    assert any(
        "no departure mark 'D': departure point 'center' is the middle of the plan (line 5.5, "
        'column 9.5)' in w
        for w in site.warnings
    )


def test_a_second_departure_mark_is_reported(tmp_path: Path) -> None:
    with pytest.raises(LayoutError, match=r":8:3: a second departure mark 'D'"):
        import_text(tmp_path, replace_char(UNLABELLED, 8, 3, 'D'))
    text = replace_char(replace_char(LABELLED, 5, 3, 'D'), 5, 9, 'D')
    with pytest.raises(LayoutError, match=r":5:9: a second departure mark 'D'"):
        import_text(tmp_path, text)


def test_room_letters_in_a_plan_forced_unlabelled_read_as_free_space_with_a_warning(
    tmp_path: Path,
) -> None:
    result = import_text(tmp_path, LABELLED, mode='unlabelled', departures={'hall': (5.5, 8)})
    assert result.mode is LayoutMode.UNLABELLED
    warnings = '\n'.join(result.site.warnings)
    assert re.search(
        r"plan\.lay:2:2: 'A' \(8 places\) has no meaning in an unlabelled plan", warnings
    )
    assert "plan.lay:8:2: '3' (8 places)" in warnings
    assert "plan.lay:2:14: '#' (1 place)" in warnings
    # The door marks read as gaps, so the rooms are still found behind them.
    assert result.rooms_found == 4


def test_an_empty_or_tiny_layout_is_reported(tmp_path: Path) -> None:
    with pytest.raises(LayoutError, match='the layout is empty'):
        import_text(tmp_path, '\n\n')
    with pytest.raises(LayoutError, match='at least 3 x 3'):
        import_text(tmp_path, '%%\n%%\n')


def test_door_gaps_are_missing_vertices_in_wall_lines_not_narrow_passages() -> None:
    # Doors at line 4, columns 3 and 7; the second leads into a one-cell-wide room whose
    # interior vertices lie between two walls as well but are no doors.
    plan = parse_layout(
        """\
%%%%%%%%%
%   %% %%
%   %% %%
%% %%% %%
%       %
%       %
%%%%%%%%%
"""
    )
    wall = plan.codes == ord('%')
    gaps = find_door_gaps(wall, np.zeros_like(wall), max_cells=1)
    assert gaps == [DoorGap(3, 2, 1, True), DoorGap(3, 6, 1, True)]
    closed, closed_h, closed_v = closing_masks(gaps, wall.shape)
    assert closed[3, 2]
    assert closed_h[3, 1:3].all()
    assert not closed_v.any()


def test_a_layout_larger_than_the_limits_is_refused_before_it_is_read(tmp_path: Path) -> None:
    wide = '%' * (MAX_LAYOUT_COLUMNS + 1) + '\n'
    with pytest.raises(LayoutError, match=r'^plan\.lay: the layout is 3 lines of 2001 characters'):
        parse_layout(wide * 3, 'plan.lay')
    with pytest.raises(LayoutError, match=r'^plan\.lay: the layout is 2001 lines of 3'):
        parse_layout('%%%\n' * (MAX_LAYOUT_LINES + 1), 'plan.lay')
    square = ('%' * 1000 + '\n') * 1000
    with pytest.raises(LayoutError, match=r'at most 2000 lines, 2000 columns and 600000 char'):
        parse_layout(square, 'plan.lay')
    huge = tmp_path / 'huge.lay'
    huge.write_text(('%' * 3000 + '\n') * 3000)
    with pytest.raises(LayoutError, match=r'huge\.lay: the file is larger than'):
        read_layout(huge)


def test_a_cell_size_that_makes_the_site_too_large_is_refused(tmp_path: Path) -> None:
    with pytest.raises(
        LayoutError, match=r'plan\.lay: .* bounds\.width_m: .* larger than the 1000'
    ):
        import_text(tmp_path, LABELLED, cell_m=100.0)


def test_an_empty_site_name_is_refused(tmp_path: Path) -> None:
    with pytest.raises(LayoutError, match='the site name must not be empty'):
        import_text(tmp_path, LABELLED, name='')
