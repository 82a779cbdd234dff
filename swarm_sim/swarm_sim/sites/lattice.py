"""Geometry of sites drawn on a grid of vertices, as the OA-Bug authors' layouts are.

A layout is an (H, W) array of characters, one per grid *vertex*: vertex (r, c) sits at
x = c * cell_m, y = (H - 1 - r) * cell_m (row 0 is the top line of the file, the world's y
axis points up). Walls run between 4-adjacent wall vertices, so a straight run of ``%`` is a
wall line and a single missing vertex in it is a door gap two cells wide (as the layout
module of the authors' simulator, SwarmSearchSimulation, builds them). The free space is
made of the (H-1, W-1) unit *squares* between vertices; square (i, j) has corners (i, j) ..
(i+1, j+1). Two neighbouring squares are connected unless the edge between them is a wall.

A square whose four corners are walls is *solid*: the authors' uncarved blocks are meshes
of such squares that no robot can enter. Walls between two solid squares can never be seen
or touched, so :func:`wall_segments` leaves them out.
"""

from __future__ import annotations

import numpy as np
from scipy import ndimage

__all__ = [
    'edge_walls',
    'runs',
    'solid_squares',
    'square_labels',
    'square_to_rects',
    'vertex_to_xy',
    'wall_segments',
    'xy_to_vertex',
]


def vertex_to_xy(row: float, col: float, n_rows: int, cell_m: float) -> tuple[float, float]:
    """World position [m] of (possibly fractional) vertex coordinates (row, col)."""
    return (col * cell_m, (n_rows - 1 - row) * cell_m)


def xy_to_vertex(x_m: float, y_m: float, n_rows: int, cell_m: float) -> tuple[float, float]:
    """Fractional vertex coordinates (row, col) of a world position [m]."""
    return (n_rows - 1 - y_m / cell_m, x_m / cell_m)


def edge_walls(wall: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Wall edges of an (H, W) bool vertex mask.

    Returns:
        horizontal: (H, W-1) bool, edge between vertices (r, j) and (r, j+1) is a wall; it
            separates squares (r-1, j) and (r, j).
        vertical: (H-1, W) bool, edge between vertices (i, c) and (i+1, c) is a wall; it
            separates squares (i, c-1) and (i, c).
    """
    return wall[:, :-1] & wall[:, 1:], wall[:-1, :] & wall[1:, :]


def solid_squares(wall: np.ndarray) -> np.ndarray:
    """(H-1, W-1) bool: squares whose four corners are wall vertices."""
    return wall[:-1, :-1] & wall[:-1, 1:] & wall[1:, :-1] & wall[1:, 1:]


def runs(mask: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Maximal runs of True along the rows of a 2-D bool array.

    Returns:
        (rows, starts, stops) int arrays, one entry per run; a run covers columns
        starts[k] .. stops[k] - 1 of row rows[k]. Ordered row by row, left to right.
    """
    padded = np.zeros((mask.shape[0], mask.shape[1] + 2), dtype=np.int8)
    padded[:, 1:-1] = mask
    step = np.diff(padded, axis=1)
    rows, starts = np.nonzero(step == 1)
    _, stops = np.nonzero(step == -1)
    return rows, starts, stops


def wall_segments(
    wall: np.ndarray, cell_m: float, extra_solid: np.ndarray | None = None
) -> np.ndarray:
    """(M, 4) wall segments x0, y0, x1, y1 [m] of an (H, W) bool vertex mask.

    Collinear wall edges are merged into maximal segments; edges with a solid square on both
    sides are dropped. ``extra_solid`` ((H-1, W-1) bool) counts more squares as solid (sealed
    voids read as solid). Horizontal segments come first, each with x0 < x1; then vertical
    ones with y0 < y1.
    """
    n_rows = wall.shape[0]
    horizontal, vertical = edge_walls(wall)
    solid = solid_squares(wall)
    if extra_solid is not None:
        solid = solid | extra_solid
    horizontal = horizontal.copy()
    vertical = vertical.copy()
    horizontal[1:-1] &= ~(solid[:-1] & solid[1:])
    vertical[:, 1:-1] &= ~(solid[:, :-1] & solid[:, 1:])
    rows, starts, stops = runs(horizontal)
    y = (n_rows - 1 - rows) * cell_m
    h_segments = np.column_stack([starts * cell_m, y, stops * cell_m, y])
    cols, starts, stops = runs(vertical.T)
    x = cols * cell_m
    v_segments = np.column_stack(
        [x, (n_rows - 1 - stops) * cell_m, x, (n_rows - 1 - starts) * cell_m]
    )
    return np.vstack([h_segments, v_segments]).astype(np.float64)


def square_labels(
    wall: np.ndarray,
    closed_vertices: np.ndarray | None = None,
    closed_horizontal: np.ndarray | None = None,
    closed_vertical: np.ndarray | None = None,
) -> tuple[np.ndarray, int]:
    """Connected areas of squares: (H-1, W-1) int labels 1..n and n.

    Squares connect across every edge that is not a wall. ``closed_*`` add virtual walls (to
    close door gaps when looking for rooms): vertices (H, W), horizontal edges (H, W-1) and
    vertical edges (H-1, W), indexed as in :func:`edge_walls`.
    """
    n_rows, n_cols = wall.shape
    horizontal, vertical = edge_walls(wall)
    blocked_vertex = wall if closed_vertices is None else wall | closed_vertices
    if closed_horizontal is not None:
        horizontal = horizontal | closed_horizontal
    if closed_vertical is not None:
        vertical = vertical | closed_vertical
    # One grid holding vertices, edges and squares: a square connects to its neighbour
    # through the edge cell between them, so 4-connected labelling follows the walls exactly.
    fine = np.ones((2 * n_rows - 1, 2 * n_cols - 1), dtype=bool)
    fine[0::2, 0::2] = ~blocked_vertex
    fine[0::2, 1::2] = ~horizontal
    fine[1::2, 0::2] = ~vertical
    labels, count = ndimage.label(fine)
    return labels[1::2, 1::2], int(count)


def square_to_rects(mask: np.ndarray, cell_m: float) -> np.ndarray:
    """(K, 4) rectangles x0, y0, x1, y1 [m] whose union is the (H-1, W-1) square mask.

    Runs of squares along each row are merged with identical runs in the rows below, so a
    rectangular area gives one rectangle.
    """
    n_square_rows = mask.shape[0]
    rows, starts, stops = runs(mask)
    rects: list[tuple[int, int, int, int]] = []  # first row, last row, start col, stop col
    open_runs: dict[tuple[int, int], int] = {}
    for row, start, stop in zip(rows.tolist(), starts.tolist(), stops.tolist(), strict=True):
        key = (start, stop)
        index = open_runs.get(key)
        if index is not None and rects[index][1] == row - 1:
            first, _, _, _ = rects[index]
            rects[index] = (first, row, start, stop)
        else:
            open_runs[key] = len(rects)
            rects.append((row, row, start, stop))
    result = np.empty((len(rects), 4), dtype=np.float64)
    for k, (first, last, start, stop) in enumerate(rects):
        result[k] = (
            start * cell_m,
            (n_square_rows - 1 - last) * cell_m,
            stop * cell_m,
            (n_square_rows - first) * cell_m,
        )
    return result
