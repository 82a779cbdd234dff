"""History-based search, eq. (1): ``v = v_r + alpha S + k_s v_s + k_o v_o`` (spec 1.2).

v_r is a random unit direction kept for ``random_period_s``; v_s and v_o are unit vectors
pointing away from the cells already searched by the robot's own swarm and by other robots
within radio range; S is the collision-avoidance vector (:mod:`msc_pf.mobility`). A field-edge
repulsion keeps robots inside the field.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np

from msc_pf.settings import SearchConfig

__all__ = ['CoverageHistory', 'HistorySearch', 'repulsions', 'unit', 'wall_repulsion']


def unit(vector: np.ndarray) -> np.ndarray:
    """``vector`` scaled to length 1, or zeros when it is (numerically) zero."""
    norm = float(np.hypot(vector[0], vector[1]))
    if norm < 1e-12:
        return np.zeros(2)
    return np.asarray(vector, dtype=np.float64) / norm


class CoverageHistory:
    """Visit counts on a square grid of cells covering the field."""

    def __init__(self, field_size_m: float, cell_size_m: float) -> None:
        """Create an empty history of ``ceil(field / cell)``^2 cells."""
        self.cell_size_m = float(cell_size_m)
        self.cells_per_side = max(1, math.ceil(field_size_m / cell_size_m))
        self.counts = np.zeros((self.cells_per_side, self.cells_per_side), dtype=np.float64)
        self._centres_m = (np.arange(self.cells_per_side) + 0.5) * self.cell_size_m

    def cell_of(self, position_m: np.ndarray) -> int:
        """Flat index (row = y cell, column = x cell) of the cell holding ``position_m``."""
        n = self.cells_per_side
        col = min(max(int(position_m[0] // self.cell_size_m), 0), n - 1)
        row = min(max(int(position_m[1] // self.cell_size_m), 0), n - 1)
        return row * n + col

    def visit(self, cell: int, count: float = 1.0) -> None:
        """Add ``count`` visits to the cell with flat index ``cell``; invalid cells are ignored."""
        n = self.cells_per_side
        if 0 <= cell < n * n:
            self.counts[cell // n, cell % n] += count

    def repulsion(self, position_m: np.ndarray, radius_m: float) -> np.ndarray:
        """Unit vector away from visited cells closer than ``radius_m`` (zero if none).

        Sum over visited cells c of ``h(c) (x - p_c) / |x - p_c|^2``; the distance is floored
        at one cell edge so the cell the robot stands in does not dominate.
        """
        return repulsions((self,), position_m, radius_m)[0]


def repulsions(
    histories: Sequence[CoverageHistory], position_m: np.ndarray, radius_m: float
) -> list[np.ndarray]:
    """:meth:`CoverageHistory.repulsion` of several histories on the same grid.

    The cell geometry around ``position_m`` is computed once for all of them.
    """
    grid = histories[0]
    n, size = grid.cells_per_side, grid.cell_size_m
    reach = math.ceil(radius_m / size)
    px, py = float(position_m[0]), float(position_m[1])
    col = min(max(int(px // size), 0), n - 1)
    row = min(max(int(py // size), 0), n - 1)
    r0, r1 = max(row - reach, 0), min(row + reach + 1, n)
    c0, c1 = max(col - reach, 0), min(col + reach + 1, n)
    windows = [history.counts[r0:r1, c0:c1] for history in histories]
    visited = [bool(window.any()) for window in windows]
    if not any(visited):
        return [np.zeros(2) for _ in histories]
    dx = px - grid._centres_m[None, c0:c1]
    dy = py - grid._centres_m[r0:r1, None]
    d2 = dx * dx + dy * dy
    near = d2 < radius_m * radius_m
    floored = np.maximum(d2, size * size)
    vectors = []
    for window, any_visit in zip(windows, visited, strict=True):
        if not any_visit:
            vectors.append(np.zeros(2))
            continue
        weight = np.where(near, window / floored, 0.0)
        vectors.append(unit(np.array([np.sum(weight * dx), np.sum(weight * dy)])))
    return vectors


def wall_repulsion(position_m: np.ndarray, field_size_m: float, margin_m: float) -> np.ndarray:
    """Unit vector away from field edges closer than ``margin_m``: sum of n_wall / dist^2."""
    x, y = float(position_m[0]), float(position_m[1])
    push = np.zeros(2)
    for distance, normal in (
        (x, (1.0, 0.0)),
        (field_size_m - x, (-1.0, 0.0)),
        (y, (0.0, 1.0)),
        (field_size_m - y, (0.0, -1.0)),
    ):
        if distance < margin_m:
            push += np.asarray(normal) / max(distance, 0.5) ** 2
    return unit(push)


class HistorySearch:
    """Eq. (1) for one robot, with its swarm's and its neighbours' search histories."""

    def __init__(self, config: SearchConfig, field_size_m: float, rng: np.random.Generator):
        """Create empty histories; ``rng`` draws the random direction v_r."""
        self._cfg = config
        self._field_size_m = float(field_size_m)
        self._rng = rng
        self.swarm_history = CoverageHistory(field_size_m, config.cell_size_m)
        self.others_history = CoverageHistory(field_size_m, config.cell_size_m)
        self._random_direction = np.zeros(2)
        self._next_draw_s = -math.inf

    def record_swarm_visit(self, cell: int) -> None:
        """Count a visit by this robot or a member of its swarm (feeds v_s)."""
        self.swarm_history.visit(cell)

    def record_other_visit(self, cell: int) -> None:
        """Count a visit by a robot outside the swarm (feeds v_o)."""
        self.others_history.visit(cell)

    def random_direction(self, now_s: float) -> np.ndarray:
        """v_r: a uniform random unit vector, redrawn every ``random_period_s``."""
        if now_s >= self._next_draw_s:
            theta = self._rng.uniform(0.0, 2.0 * math.pi)
            self._random_direction = np.array([math.cos(theta), math.sin(theta)])
            self._next_draw_s = now_s + self._cfg.random_period_s
        return self._random_direction

    def vector(self, now_s: float, position_m: np.ndarray, avoidance: np.ndarray) -> np.ndarray:
        """Movement vector of eq. (1) plus the field-edge repulsion (metres, unscaled)."""
        cfg = self._cfg
        v_s, v_o = repulsions(
            (self.swarm_history, self.others_history), position_m, cfg.history_radius_m
        )
        v_w = wall_repulsion(position_m, self._field_size_m, cfg.wall_margin_m)
        return (
            self.random_direction(now_s)
            + cfg.alpha_outside * avoidance
            + cfg.k_s * v_s
            + cfg.k_o * v_o
            + cfg.effective_wall_weight * v_w
        )
