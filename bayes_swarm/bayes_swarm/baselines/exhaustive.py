"""Exhaustive partitioned boustrophedon sweep (the paper's exhaustive baseline).

The arena is cut into equal vertical strips, one per robot ('strips'), or into quadrants
that are shared out among the robots and then cut into strips ('quadrants', the paper's
10-robot allocation 3/2/3/2). In its strip a robot sweeps lanes parallel to the strip's long
side, ``lane_spacing_m`` apart, the first lane half a spacing from the edge; it first travels
straight to the strip corner nearest to it.
"""

from __future__ import annotations

import math

import numpy as np

from bayes_swarm.settings import Arena

__all__ = ['partition_arena', 'strip_sweep', 'sweep_paths']


def partition_arena(arena: Arena, n_robots: int, partition: str = 'strips') -> list[Arena]:
    """Sub-arenas of equal area per robot (list of length ``n_robots``)."""
    if partition == 'strips':
        return _strips(arena, n_robots)
    xm = 0.5 * (arena.x_min_m + arena.x_max_m)
    ym = 0.5 * (arena.y_min_m + arena.y_max_m)
    quarters = [
        Arena(xm, arena.x_max_m, ym, arena.y_max_m),
        Arena(arena.x_min_m, xm, ym, arena.y_max_m),
        Arena(arena.x_min_m, xm, arena.y_min_m, ym),
        Arena(xm, arena.x_max_m, arena.y_min_m, ym),
    ]
    counts = [n_robots // 4] * 4
    for quarter in (0, 2, 1, 3)[: n_robots % 4]:  # extra robots: 1st, 3rd, 2nd quarter
        counts[quarter] += 1
    parts: list[Arena] = []
    for quarter, count in zip(quarters, counts, strict=True):
        if count:
            parts.extend(_strips(quarter, count))
    return parts


def _strips(arena: Arena, n: int) -> list[Arena]:
    edges = np.linspace(arena.x_min_m, arena.x_max_m, n + 1)
    return [
        Arena(float(edges[i]), float(edges[i + 1]), arena.y_min_m, arena.y_max_m) for i in range(n)
    ]


def strip_sweep(strip: Arena, lane_spacing_m: float, start_m: np.ndarray) -> np.ndarray:
    """Waypoints (k, 2) [m] of a boustrophedon sweep of ``strip`` entered near ``start_m``.

    Lanes run along y; the corner nearest to ``start_m`` is where the sweep begins.
    """
    width = strip.x_max_m - strip.x_min_m
    n_lanes = max(1, math.ceil(width / lane_spacing_m - 1e-9))
    offsets = strip.x_min_m + lane_spacing_m * (0.5 + np.arange(n_lanes))
    offsets = np.minimum(offsets, strip.x_max_m)
    start = np.asarray(start_m, dtype=float)
    if abs(start[0] - strip.x_max_m) < abs(start[0] - strip.x_min_m):
        offsets = offsets[::-1]
    y_first, y_second = strip.y_min_m, strip.y_max_m
    if abs(start[1] - strip.y_max_m) < abs(start[1] - strip.y_min_m):
        y_first, y_second = y_second, y_first
    points = []
    for lane, x in enumerate(offsets):
        ys = (y_first, y_second) if lane % 2 == 0 else (y_second, y_first)
        points.append((x, ys[0]))
        points.append((x, ys[1]))
    return np.array(points, dtype=float)


def sweep_paths(
    arena: Arena,
    starts_m: np.ndarray,
    lane_spacing_m: float,
    partition: str = 'strips',
) -> list[np.ndarray]:
    """Waypoint list (k_i, 2) of every robot starting at (m, 2) ``starts_m``."""
    starts = np.asarray(starts_m, dtype=float).reshape(-1, 2)
    parts = partition_arena(arena, starts.shape[0], partition)
    return [
        strip_sweep(part, lane_spacing_m, start) for part, start in zip(parts, starts, strict=True)
    ]
