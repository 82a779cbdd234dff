"""Layout import on plans of kinds not seen before: the departure mark in labelled layouts,
rooms that are not closed, sealed voids, departure points in islands and nested rooms, and
the features of the authors' published building plans (each reproduced by a small plan)."""

from __future__ import annotations

import os
import re
from pathlib import Path

import numpy as np
import pytest
from swarm_common.errors import SwarmError
from swarm_sim.sites import (
    CELL_M,
    NO_ROOM,
    LayoutError,
    LayoutImport,
    LayoutMode,
    SiteError,
    generate_layout,
    import_layout,
)
from swarm_sim.sites.layout import parse_layout


def write(tmp_path: Path, text: str, name: str = 'plan.lay') -> Path:
    path = tmp_path / name
    path.write_text(text)
    return path


def import_text(tmp_path: Path, text: str, **kwargs: object) -> LayoutImport:
    return import_layout(write(tmp_path, text), **kwargs)  # type: ignore[arg-type]


def all_warnings(result: LayoutImport) -> str:
    return '\n'.join(result.site.warnings)


# --- 'D' in labelled layouts --------------------------------------------------------------

# Rooms A, B, C (nested in B) and the victim room 3; the departure marked in the corridor.
LABELLED_WITH_D = """\
%%%%%%%%%%%%%%%%
%AAAA%    %BB#C%
%AAAA%    /BB%C%
%%/%%%    %%%%%%
%      D       %
%              %
%%%/%%    %%%%%%
%3333%    %%%%%%
%3333%    %%%%%%
%%%%%%%//%%%%%%%
"""


def test_d_marks_the_departure_of_a_labelled_layout_and_makes_no_room(tmp_path: Path) -> None:
    result = import_text(tmp_path, LABELLED_WITH_D)
    assert result.mode is LayoutMode.LABELLED
    assert sorted(room.label for room in result.site.rooms) == ['3', 'A', 'B', 'C']
    # The mark replaces the runner's centre and edge points.
    assert list(result.site.departure_points) == ['edge']
    assert result.site.departure('edge').xy == pytest.approx((7 * CELL_M, 5 * CELL_M))
    assert result.site.room_ids_at(np.array([result.site.departure('edge').xy]))[0] == NO_ROOM
    assert result.site.warnings == ()
    named = import_text(tmp_path, LABELLED_WITH_D, departure_name='start').site
    assert list(named.departure_points) == ['start']


def test_a_d_group_walled_in_like_a_room_is_a_departure_with_a_warning(tmp_path: Path) -> None:
    # The authors' generator letters its fourth room 'D'; here 'D' is the departure mark.
    text = LABELLED_WITH_D.replace('      D       ', '              ').replace('C%', 'D%')
    result = import_text(tmp_path, text)
    assert sorted(room.label for room in result.site.rooms) == ['3', 'A', 'B']
    assert re.search(
        r"plan\.lay:2:15: the departure mark 'D' fills an area walled in like a room",
        all_warnings(result),
    )


def test_the_generator_never_letters_a_room_d() -> None:
    for config, seed in (('small', 0), ('medium', 1), ('big', 2)):
        inner = generate_layout(config, seed).codes[1:-1, 1:-1]
        assert not np.any(inner == ord('D'))


# --- rooms must be closed -------------------------------------------------------------------


def test_a_room_missing_a_whole_wall_side_is_rejected_naming_room_and_side(
    tmp_path: Path,
) -> None:
    text = LABELLED_WITH_D.replace('%AAAA%', '%AAAA ')  # A's right wall gone
    with pytest.raises(
        LayoutError,
        match=r"plan\.lay:2:6: room 'A' is not closed: its right wall \(column 6, lines 2-3\) "
        r'is missing',
    ) as info:
        import_text(tmp_path, text)
    assert (info.value.line, info.value.column) == (2, 6)
    text = LABELLED_WITH_D.replace('%%%/%%    %%%%%%', '%    %    %%%%%%')
    with pytest.raises(
        LayoutError,
        match=r"plan\.lay:7:2: room '3' is not closed: its top wall \(line 7, columns 2-5\) is "
        r'missing',
    ):
        import_text(tmp_path, text)


def test_an_unmarked_opening_in_a_room_wall_is_rejected_at_its_place(tmp_path: Path) -> None:
    text = LABELLED_WITH_D.replace('%AAAA%    %BB', '%AAAA     %BB')  # line 2 only
    with pytest.raises(
        LayoutError,
        match=r"plan\.lay:2:6: room 'A' is not closed: its right wall has an opening here, "
        r"neither '%' nor a door mark",
    ):
        import_text(tmp_path, text)


def test_a_room_that_is_not_a_rectangle_must_be_closed_too(tmp_path: Path) -> None:
    plan = """\
%%%%%%%%%%%%
%AAAA%     %
%AA%%%     %
%AA%       %
%%/%%      %
%          %
%%%%%//%%%%%
"""
    assert import_text(tmp_path, plan).rooms_found == 1
    with pytest.raises(
        LayoutError, match=r":4:4: room 'A' is not closed: its wall has an opening here"
    ):
        import_text(tmp_path, plan.replace('%AA%       %', '%AA        %'))


# --- sealed voids ---------------------------------------------------------------------------


def test_a_sealed_empty_box_in_a_labelled_layout_is_read_as_solid(tmp_path: Path) -> None:
    text = LABELLED_WITH_D.replace(
        '%%%/%%    %%%%%%\n%3333%    %%%%%%\n%3333%    %%%%%%',
        '%%%/%%    %%%%%%\n%3333%    %    %\n%3333%    %%%%%%',
    )
    result = import_text(tmp_path, text)
    assert result.voids_found == 1
    assert re.search(
        r'plan\.lay:8:12: an enclosed area with no door \(10 cells, lines 7-9, columns 11-16\) '
        r'holds no room and no departure point; it is read as solid',
        all_warnings(result),
    )
    assert len(result.site.rooms) == 4


# The authors' building plans: doors two characters wide, boxes drawn with no door.
AUTHORS_KIND = """\
%%%%%%%%%%%%%%%%%%%%%%
%         %     %    %
%         %%%%%%%    %
%  D                 %
%                    %
%                    %
%%%%%%  %%%%%%%  %%%%%
%    %  %     %  %   %
%       %     %      %
%       %     %      %
%    %  %     %  %   %
%%%%%%%%%%%%%%%%%%%%%%
"""


def test_a_building_plan_with_wide_doors_and_sealed_boxes_imports(tmp_path: Path) -> None:
    result = import_text(tmp_path, AUTHORS_KIND, max_door_cells=2)
    assert result.rooms_found == 2
    assert result.voids_found == 2
    warnings = all_warnings(result)
    assert 'plan.lay:2:12: an enclosed area with no door (12 cells, lines 1-3, columns 11-17)' in (
        warnings
    )
    assert 'plan.lay:8:10: an enclosed area with no door (30 cells, lines 7-12, columns 9-15)' in (
        warnings
    )
    site = result.site
    left_room, right_room = (1.0, 1.0), (5.0, 1.0)
    ids = site.room_ids_at(np.array([left_room, right_room, site.departure('edge').xy]))
    assert NO_ROOM not in ids[:2]
    assert ids[2] == NO_ROOM
    box_inside = np.array([[3.5, 2.75], [3.0, 0.8]])
    assert site.room_ids_at(box_inside).tolist() == [NO_ROOM, NO_ROOM]


def test_a_sealed_void_gives_the_walls_of_a_filled_block(tmp_path: Path) -> None:
    plan = """\
%%%%%%%%%
%   %%%%%
%   %% %%
%   %%%%%
%D      %
%%%%%%%%%
"""
    result = import_text(tmp_path, plan)
    assert result.voids_found == 1
    filled = import_text(tmp_path, plan.replace('%% %%', '%%%%%')).site
    # The walls between the void and the solid block around it are gone, as inside a block.
    np.testing.assert_array_equal(result.site.walls, filled.walls)


# --- where the departure point lies --------------------------------------------------------

# The runner's centre and edge both fall in room C, which opens only into B.
NESTED = """\
%%%%%%%%%%%%%%%%%%%
%                 %
%   %%%%%%%%%%%   %
%   %BBB#CCCCC%   %
%   /BBB%CCCCC%   %
%   %BBB%CCCCC%   %
%   %%%%%%%%%%%   %
%                 %
%%%%%%%%//%%%%%%%%%
"""


def test_runner_points_in_a_nested_room_are_flagged_with_the_room(tmp_path: Path) -> None:
    result = import_text(tmp_path, NESTED)
    warnings = all_warnings(result)
    for name in ('center', 'edge'):
        assert re.search(
            rf"plan\.lay:\d+:\d+: departure point '{name}' at .* lies inside room 2 \('C'\), a "
            r"room nested in room 1 \('B'\) \(its doors open only into rooms\): robots start in "
            r'that room',
            warnings,
        )


def test_a_departure_in_a_room_with_a_corridor_door_is_flagged_without_nesting(
    tmp_path: Path,
) -> None:
    result = import_text(tmp_path, NESTED, departures={'in_b': (5, 7)})
    (warning,) = result.site.warnings
    assert re.search(
        r"plan\.lay:5:7: departure point 'in_b' .* lies inside room 1 \('B'\): ", warning
    )


def test_runner_centre_in_a_closed_island_is_an_error(tmp_path: Path) -> None:
    plan = """\
%%%%%%%%%%%%%%%%%%%
%AAAA%            %
%AAAA/  %%%%%%%   %
%%%%%%  %     %   %
%       %     %   %
%       %%%%%%%   %
%                 %
%                 %
%%%%%%%%//%%%%%%%%%
"""
    with pytest.raises(
        LayoutError,
        match=r"plan\.lay:5:10: departure point 'center' lies in an enclosed area of 18 cells "
        r'that leads to no room',
    ):
        import_text(tmp_path, plan)


def test_a_mark_in_a_box_cut_off_from_a_larger_hall_is_an_error(tmp_path: Path) -> None:
    plan = """\
%%%%%%%%%%%%%%
%            %
%            %
%   %%%%     %
%   %DD%     %
%   %%%%     %
%            %
%            %
%%%%%%%%%%%%%%
"""
    with pytest.raises(
        LayoutError,
        match=r"plan\.lay:5:6: departure point 'edge' lies in an enclosed area of 6 cells with "
        r'no door, cut off from a larger one of 98 cells \(line 2, column 2\)',
    ):
        import_text(tmp_path, plan)


def test_a_departure_inside_a_solid_block_is_an_island_error(tmp_path: Path) -> None:
    plan = """\
%%%%%%%%%%%%
%     %%%%%%
%  D  %%%%%%
%     %%%%%%
%%%%%%%%%%%%
"""
    with pytest.raises(LayoutError, match=r":3:9: departure point 'x' lies inside a solid block"):
        import_text(tmp_path, plan, departures={'x': (3, 9.5)})


# --- characters of the authors' plans -------------------------------------------------------

# A maze like the authors' layout.lay: '.' floors, 'P' marks, no departure mark.
MAZE = """\
%%%%%%%%%%%%%
%P....%....P%
%.%%%.%.%%%.%
%...........%
%.%%%.%.%%%.%
%P....%....P%
%%%%%%%%%%%%%
"""


def test_dots_are_free_space_and_letters_in_a_plan_are_read_as_free_with_a_warning(
    tmp_path: Path,
) -> None:
    result = import_text(tmp_path, MAZE)
    assert result.mode is LayoutMode.UNLABELLED
    plain = import_text(tmp_path, MAZE.replace('.', ' ').replace('P', ' '), departure_name='x')
    np.testing.assert_array_equal(result.site.walls, plain.site.walls)
    warnings = all_warnings(result)
    assert "plan.lay:2:2: 'P' (4 places) has no meaning in an unlabelled plan" in warnings
    assert "plan.lay:4:7: no departure mark 'D': departure point 'center' is the middle" in warnings
    assert '.' not in ''.join(re.findall(r"'(.)' \(", warnings))


def test_a_plan_of_closed_boxes_whose_middle_is_a_wall_gets_a_precise_error(
    tmp_path: Path,
) -> None:
    boxes = """\
%%%%%%%%%
%   %   %
%   %   %
%%%%%%%%%
%   %   %
%   %   %
%%%%%%%%%
"""
    with pytest.raises(
        LayoutError,
        match=r"plan\.lay:4:5: the plan has no departure mark 'D' and its middle \(line 4, "
        r'column 5\), where the authors\' simulator starts then, is in a wall',
    ):
        import_text(tmp_path, boxes)


def test_an_empty_room_without_mark_imports_with_no_rooms(tmp_path: Path) -> None:
    result = import_text(tmp_path, '%%%%%%\n%    %\n%    %\n%    %\n%%%%%%')  # no final newline
    assert result.rooms_found == 0
    assert list(result.site.departure_points) == ['center']


def test_site_errors_are_swarm_errors() -> None:
    assert issubclass(LayoutError, SiteError)
    assert issubclass(SiteError, SwarmError)
    with pytest.raises(SwarmError):
        parse_layout('%%%\n%@%\n%%%\n')


# --- the authors' published plans, when a checkout is given ---------------------------------

CHECKOUT = os.environ.get('OABUG_SIM_CHECKOUT')
# What each plan of SwarmSearchSimulation (commit 9d16ebb) gives: rooms, sealed voids.
AUTHORS_PLANS = {
    'empty_room.lay': (1, 0, 0),
    'layout.lay': (1, 15, 0),
    'newmainbuilding.lay': (2, 21, 13),
    'newmainbuildinghalf.lay': (2, 1, 22),
    'newmainbuildinghalfhalf.lay': (2, 0, 13),
}


@pytest.mark.skipif(
    not CHECKOUT, reason='set OABUG_SIM_CHECKOUT to a SwarmSearchSimulation checkout'
)
def test_every_plan_of_the_authors_checkout_imports_or_gets_a_precise_error() -> None:
    plans = sorted((Path(str(CHECKOUT)) / 'assets').glob('*.lay'))
    assert plans, f'no .lay files under {CHECKOUT}/assets'
    for path in plans:
        if path.name == 'test.lay':  # closed boxes, no door, no mark: not a site
            with pytest.raises(LayoutError, match=r'test\.lay:9:12: the plan has no departure'):
                import_layout(path)
            continue
        door_cells, rooms, voids = AUTHORS_PLANS.get(path.name, (2, None, None))
        result = import_layout(path, max_door_cells=door_cells)
        if rooms is not None:
            assert (result.rooms_found, result.voids_found) == (rooms, voids), path.name
        for warning in result.site.warnings:
            assert re.match(rf'{re.escape(str(path))}:\d+:\d+: ', warning), warning
