"""Glowworm swarm optimisation for source search (paper Table 11), one agent at a time.

One iteration of agent i, from its own signal J(x_i) and its peers' latest broadcasts
(position and luciferin):

1. luciferin  l_i <- (1 - rho) l_i + gamma J(x_i);
2. neighbours N_i = {j != i : |x_j - x_i| <= r_d_i and l_i < l_j};
3. leader j drawn with probability (l_j - l_i) / sum_k (l_k - l_i) (or the brightest
   neighbour in the deterministic variant); no neighbour -> no move;
4. move a step s toward the leader (a move leaving the arena is rejected);
5. r_d_i <- min(r_s, max(0, r_d_i + beta (n_t - |N_i|))).

Peers' luciferins are those they last broadcast, so the swarm's iterations are
asynchronous: every robot runs this on its own timer, in the ROS node and in the batch
runner alike (both through :class:`bayes_swarm.controller.RobotController`).
"""

from __future__ import annotations

import bisect
import math
from collections.abc import Sequence

import numpy as np

from bayes_swarm.settings import Arena, GlowwormConfig

__all__ = ['GlowwormAgent', 'select_leader']


def select_leader(
    position_m: tuple[float, float],
    luciferin: float,
    decision_range_m: float,
    peers: Sequence[tuple[float, float, float]],
    rng: np.random.Generator,
    *,
    deterministic: bool = False,
) -> tuple[int, int]:
    """Steps 2-3 for one agent: the index of its leader in ``peers`` (-1: none) and its
    neighbour count |N_i|.

    ``peers`` holds each peer's latest (x [m], y [m], luciferin). The draw uses one uniform
    number from ``rng`` when there are neighbours (none in the deterministic variant, which
    takes the brightest). A robot hears a handful of peers, so this is a plain loop: it costs
    a few microseconds where numpy's per-call overhead would cost tens.
    """
    x, y = position_m
    neighbours: list[int] = []
    cumulative: list[float] = []
    total = 0.0
    for j, (px, py, lj) in enumerate(peers):
        gain = lj - luciferin
        if gain > 0.0 and math.hypot(px - x, py - y) <= decision_range_m:
            neighbours.append(j)
            total += gain
            cumulative.append(total)
    if not neighbours:
        return -1, 0
    if deterministic:
        return max(neighbours, key=lambda j: peers[j][2]), len(neighbours)
    draw = rng.random() * total
    pick = bisect.bisect_right(cumulative, draw)
    # A draw on the boundary of the last weight (draw == total in rounding) stays in range.
    return neighbours[min(pick, len(neighbours) - 1)], len(neighbours)


class GlowwormAgent:
    """GSO decisions of one robot from its own signal and its neighbours' broadcasts."""

    def __init__(
        self, config: GlowwormConfig, arena: Arena, velocity_mps: float, seed: int | None = None
    ) -> None:
        self._cfg = config
        self._arena = arena
        self._rng = np.random.default_rng(seed)
        self.step_m = min(config.step_m, velocity_mps / config.decision_rate_hz)
        self.luciferin = config.initial_luciferin
        self.decision_range_m = config.sensor_range_m

    def update_luciferin(self, signal: float) -> float:
        """Step 1 with the latest measured signal; returns the new luciferin."""
        cfg = self._cfg
        self.luciferin = (1.0 - cfg.luciferin_decay) * self.luciferin + (
            cfg.luciferin_enhancement * signal
        )
        return self.luciferin

    def next_waypoint(
        self, position_m: np.ndarray, peers: Sequence[tuple[float, float, float]]
    ) -> np.ndarray:
        """Steps 2-5 for this agent, given each peer's latest (x [m], y [m], luciferin);
        returns the (2,) next position [m]."""
        own = np.asarray(position_m, dtype=float).reshape(2)
        x, y = float(own[0]), float(own[1])
        cfg = self._cfg
        leader, count = select_leader(
            (x, y),
            self.luciferin,
            self.decision_range_m,
            peers,
            self._rng,
            deterministic=cfg.deterministic,
        )
        self.decision_range_m = min(
            cfg.sensor_range_m,
            max(0.0, self.decision_range_m + cfg.range_gain * (cfg.desired_neighbours - count)),
        )
        if leader < 0:
            return own.copy()
        dx, dy = peers[leader][0] - x, peers[leader][1] - y
        norm = math.hypot(dx, dy)
        if norm <= 0.0:
            return own.copy()
        target_x = x + self.step_m * dx / norm
        target_y = y + self.step_m * dy / norm
        if not self._arena.contains_point(target_x, target_y):
            return own.copy()
        return np.array([target_x, target_y])
