"""Compiled part of the scent field: which puffs reach which sensors.

Simulation only, like :mod:`swarm_sim.raycast_kernel`. :meth:`ScentField.concentration
<swarm_sim.sensors.scent.ScentField.concentration>` needs, for every sensor, the puffs
within the cut-off distance whose vapour path crosses no wall. The numpy version
(:meth:`~swarm_sim.sensors.scent.ScentField.concentration_reference`) builds the full
(sensors x puffs) distance matrix, then the wall candidates of every pair; this kernel
walks the same pairs in the same (row-major) order with the same operations, so the
selected pairs and their squared distances are bit-identical. The concentration itself
(``exp`` of ages and distances, summed per sensor) stays in numpy.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from swarm_sim.raycast_kernel import grid_cell, path_hits

__all__ = ['open_puff_pairs']


@njit(cache=True)
def open_puff_pairs(
    points: np.ndarray,
    puffs: np.ndarray,
    puff_time_s: np.ndarray,
    time_s: float,
    past_only: bool,
    cutoff2: float,
    walls_block: bool,
    grid: tuple,
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:  # pragma: no cover - compiled
    """The (sensor, puff) pairs whose vapour reaches the sensor, in row-major order.

    Args:
        points: (K, 2) sensor positions [m].
        puffs: (P, 2) puff positions [m].
        puff_time_s: (P,) deposit times [s].
        time_s: the query time [s].
        past_only: leave out puffs deposited after ``time_s``.
        cutoff2: squared cut-off distance [m^2].
        walls_block: leave out pairs whose straight path crosses a wall of the grid.
        grid: the wall grid, :meth:`swarm_sim.geometry.WallGrid.kernel_arguments`.

    Returns:
        (L,) sensor indices, (L,) puff indices and (L,) squared distances [m^2].
    """
    origin_x, origin_y, cell_m, shape_x, shape_y, table, q, s = grid
    k_points = points.shape[0]
    p_puffs = puffs.shape[0]
    total = 0
    for k in range(k_points):
        for p in range(p_puffs):
            dx = points[k, 0] - puffs[p, 0]
            dy = points[k, 1] - puffs[p, 1]
            if dx * dx + dy * dy <= cutoff2 and not (past_only and puff_time_s[p] > time_s):
                total += 1
    sensor = np.empty(total, dtype=np.int64)
    puff = np.empty(total, dtype=np.int64)
    dist2 = np.empty(total)
    count = 0
    for k in range(k_points):
        px = points[k, 0]
        py = points[k, 1]
        walls = table[grid_cell(px, py, origin_x, origin_y, cell_m, shape_x, shape_y)]
        for p in range(p_puffs):
            dx = px - puffs[p, 0]
            dy = py - puffs[p, 1]
            d2 = dx * dx + dy * dy
            if not d2 <= cutoff2 or (past_only and puff_time_s[p] > time_s):
                continue
            if walls_block and path_hits(px, py, puffs[p, 0], puffs[p, 1], walls, q, s) != 0:
                continue
            sensor[count] = k
            puff[count] = p
            dist2[count] = d2
            count += 1
    return sensor[:count], puff[:count], dist2[:count]
