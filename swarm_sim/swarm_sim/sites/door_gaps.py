"""Door gaps in plans that draw only walls (unlabelled ``.lay`` layouts).

In the authors' layouts a door is a missing vertex in a wall line. Reading walls alone, a
gap is a run of 1..max_cells free vertices between two wall vertices of a straight line, with
free vertices on both sides of every one of them, where the space beside the line widens
beyond the run's ends: on at least one side for a single vertex (so the door of a
one-cell-wide room is found), on both sides for longer runs (so the mouth of a narrow
corridor is not taken for a door). A free vertex that is itself a gap in a line across does
not widen anything. Closing every gap splits the free space into the areas the rooms are.

Arrays are (H, W) vertex masks indexed as in :mod:`.lattice`.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

__all__ = ['DoorGap', 'closing_masks', 'find_door_gaps']


@dataclass(frozen=True, order=True)
class DoorGap:
    """A run of missing vertices in a wall line.

    Attributes:
        row: row of the first missing vertex.
        col: column of the first missing vertex.
        length: number of missing vertices.
        horizontal: the wall line runs along a row (the run covers columns col ..
            col + length - 1); otherwise along a column (rows row .. row + length - 1).
    """

    row: int
    col: int
    length: int
    horizontal: bool


def find_door_gaps(wall: np.ndarray, blocked: np.ndarray, max_cells: int) -> list[DoorGap]:
    """Every door gap of the (H, W) wall mask, sorted by position; vertices in ``blocked``
    are never part of a gap."""
    gaps = [DoorGap(r, c, k, True) for r, c, k in _row_gaps(wall, blocked, max_cells)]
    gaps += [DoorGap(r, c, k, False) for c, r, k in _row_gaps(wall.T, blocked.T, max_cells)]
    return sorted(gaps)


def closing_masks(
    gaps: list[DoorGap], shape: tuple[int, int]
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Virtual walls that close ``gaps``: (H, W) vertices, (H, W-1) horizontal edges and
    (H-1, W) vertical edges, as :func:`.lattice.square_labels` takes them."""
    n_rows, n_cols = shape
    vertices = np.zeros(shape, dtype=bool)
    horizontal = np.zeros((n_rows, n_cols - 1), dtype=bool)
    vertical = np.zeros((n_rows - 1, n_cols), dtype=bool)
    for gap in gaps:
        r, c, k = gap.row, gap.col, gap.length
        if gap.horizontal:
            vertices[r, c : c + k] = True
            horizontal[r, c - 1 : c + k] = True
        else:
            vertices[r : r + k, c] = True
            vertical[r - 1 : r + k, c] = True
    return vertices, horizontal, vertical


def _row_gaps(wall: np.ndarray, blocked: np.ndarray, max_cells: int) -> list[tuple[int, int, int]]:
    """(row, first column, length) of the door gaps in the rows' wall lines (see the
    module docstring)."""
    n_cols = wall.shape[1]
    free = ~wall
    in_vertical_gap = np.zeros_like(wall)
    in_vertical_gap[1:-1] = wall[:-2] & wall[2:]
    widens = free & ~in_vertical_gap
    found: list[tuple[int, int, int]] = []
    for length in range(1, max_cells + 1):
        starts = n_cols - length - 1  # first columns 1 .. n_cols - length - 1
        if starts < 1:
            break
        left, right = slice(0, starts), slice(length + 1, n_cols)
        ok = wall[1:-1, left] & wall[1:-1, right]
        for offset in range(length):
            run = slice(1 + offset, 1 + offset + starts)
            ok &= free[1:-1, run] & free[:-2, run] & free[2:, run] & ~blocked[1:-1, run]
        above = widens[:-2, left] | widens[:-2, right]
        below = widens[2:, left] | widens[2:, right]
        ok &= (above | below) if length == 1 else (above & below)
        rows, cols = np.nonzero(ok)
        found += [(int(r) + 1, int(c) + 1, length) for r, c in zip(rows, cols, strict=True)]
    return found
